"""PROTO interfaces and instantiation: every field type and declaration kind, accepted values,
defaults and type checks at file:line:col, IS at any depth of four nested PROTOs, slots (with a
PROTO as a slot's default), DEF/USE scopes per instance, cycles, derived PROTOs, in-world PROTO
definitions, what an instance is (its base node), where nodes come from."""

from __future__ import annotations

from pathlib import Path

import pytest
from _protos import expanded, nodes_of, proto_file, world_file

from sensorium.schemas import world as wm
from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.proto import ProtoError
from sensorium.server.world.proto.interface import FIELD_TYPES, read_proto_file


def test_every_field_type_and_declaration_kind(tmp_path: Path) -> None:
    p = proto_file(tmp_path, "All", """[
  field SFBool b TRUE  vrmlField SFInt32 i 0x10  hiddenField SFFloat f -1.5e-3  deprecatedField SFVec2f v2 1 2
  unconnectedField SFVec3f v3 1 2 3  field SFRotation r 0 0 1 0  field SFColor c 1 0.5 0
  field SFString s "x"  field SFNode n NULL  field MFBool mb [ TRUE, FALSE ]  field MFInt32 mi [ 1 2 ]
  field MFFloat mf 1.5  field MFVec2f m2 [ 1 2, 3 4 ]  field MFVec3f m3 [ ]  field MFRotation mr [ 0 0 1 1 ]
  field MFColor mc [ 1 1 1 ]  field MFString ms "one"  field MFNode mn [ Box { } ]
  hidden translation_1 0 0 0
]
{ Group { } }""")
    proto = read_proto_file(p, str(p), ProtoLimits())
    kinds = {f.name: (f.kind, f.type) for f in proto.fields.values()}
    assert {t for _, t in kinds.values()} == set(FIELD_TYPES)
    assert kinds["i"] == ("vrmlField", "SFInt32") and kinds["f"] == ("hiddenField", "SFFloat")
    assert kinds["v2"] == ("deprecatedField", "SFVec2f") and kinds["v3"] == ("unconnectedField", "SFVec3f")
    assert kinds["translation_1"] == ("hidden", "SFVec3f")
    d = {k: v.default for k, v in proto.fields.items()}
    assert d["i"] == 16.0 and d["f"] == -0.0015 and d["mb"] == [True, False] and d["mf"] == [1.5]
    assert d["m2"] == [1.0, 2.0, 3.0, 4.0] and d["m3"] == [] and d["ms"] == ["one"] and d["mn"][0].type == "Box"
    assert d["n"] is None and d["c"] == (1.0, 0.5, 0.0)


@pytest.mark.parametrize("given, where, what", [
    ("count 1.5", "4:10", "Part.count: SFInt32 expects a 32-bit integer, got 1.5"),
    ("count 3000000000", "4:10", "Part.count: SFInt32 expects a 32-bit integer"),
    ("size 1 2", "4:10", "Part.size: SFVec3f expects 3 numbers, got 2 numbers"),
    ('on "yes"', "4:10", "Part.on: SFBool expects TRUE or FALSE, got 'yes'"),
    ("label 12", "4:10", "Part.label: SFString expects a string, got 12.0"),
    ("shape 1", "4:10", "Part.shape: SFNode expects a node or NULL, got 1.0"),
    ("pts [ 1 2 ]", "4:10", "Part.pts: MFVec3f expects groups of 3 numbers, got 2 numbers"),
    ("kids [ Box { } 1 ]", "4:10", "Part.kids: MFNode expects nodes, got 1.0"),
    ('mode "fast"', "4:10", "Part.mode: 'fast' is not an accepted value (one of: \"slow\", \"steady\")"),
    ("level 0.7", "4:10", "Part.level: 0.7 is not an accepted value (one of: 0.25, 0.5)"),
    ("shape Sphere { }", "4:10", "Part.shape: a Sphere node is not an accepted value (one of: Box, Cylinder)"),
    ("colour 1 1 1", "4:10", "Part.colour: not a field of PROTO Part (its fields: count, size, on, label, shape, pts, "
                             "kids, mode, level)"),
])
def test_instance_values_are_checked_at_their_line(tmp_path: Path, given: str, where: str, what: str) -> None:
    proto_file(tmp_path, "Part", """[
  field SFInt32 count 1  field SFVec3f size 1 1 1  field SFBool on TRUE  field SFString label ""
  field SFNode{Box {}, Cylinder {}} shape NULL  field MFVec3f pts []  field MFNode kids []
  field SFString{"slow", "steady"} mode "slow"  field SFFloat{0.25, 0.5} level 0.5
]
{ Group { } }""")
    w = world_file(tmp_path, f"Group {{ children [\n  Part {{ {given} }}\n] }}\n", ["Part.proto"])
    with pytest.raises(WorldError) as exc:
        load_world(w)
    assert str(exc.value).startswith(f"{w}: line {where.replace(':', ', column ')}: {what}"), str(exc.value)


def test_accepted_values_take_matching_values_and_proto_base_types(tmp_path: Path) -> None:
    proto_file(tmp_path, "Lamp", "[ ] { Solid { name \"lamp\" } }")
    proto_file(tmp_path, "Holder", """[
  field MFNode{Solid {}, Pose {}} parts []
  field SFColor{0 0 0, 1 1 1} tint 1 1 1
]
{ Solid { children IS parts } }""")
    w = world_file(tmp_path, 'Holder { tint 0 0 0 parts [ Lamp { } Pose { } Solid { name "s" } ] }\n',
                   ["Lamp.proto", "Holder.proto"])
    (holder,) = expanded(w).nodes
    assert [(n.type, n.proto) for n in holder.fields["children"]] == [("Solid", "Lamp"), ("Pose", None), ("Solid", None)]


def test_is_at_any_depth_of_four_nested_protos(tmp_path: Path) -> None:
    """Outer → Middle → Inner → Leaf: a value given to the outermost instance reaches the leaf's
    Box through three IS hops, each inside nested base nodes; defaults fill what is not given."""
    proto_file(tmp_path, "Leaf", """[ field SFVec3f boxSize 0.1 0.1 0.1 field SFString leafName "leaf" ]
{ Solid { name IS leafName children [ Pose { children [ Shape { geometry Box { size IS boxSize } } ] } ] } }""")
    proto_file(tmp_path, "Inner", """[ field SFVec3f size 0.2 0.2 0.2 field SFString n "inner" ]
{ Pose { children [ Group { children [ Leaf { boxSize IS size leafName IS n } ] } ] } }""",
               header='EXTERNPROTO "Leaf.proto"\n')
    proto_file(tmp_path, "Middle", """[ field SFVec3f size 0.3 0.3 0.3 field SFString n "middle" ]
{ Group { children [ Inner { size IS size n IS n } ] } }""", header='EXTERNPROTO "Inner.proto"\n')
    proto_file(tmp_path, "Outer", """[ field SFVec3f size 0.4 0.4 0.4 field SFString name "outer" ]
{ Solid { name "shell" children [ Middle { size IS size n IS name } ] } }""", header='EXTERNPROTO "Middle.proto"\n')
    w = world_file(tmp_path, 'Outer { size 1 2 3 name "given" }\nOuter { }\n', ["Outer.proto"])
    given, default = expanded(w).nodes
    (box,) = nodes_of(given, "Box")
    assert box.fields["size"] == (1.0, 2.0, 3.0)
    assert [s.fields["name"] for s in nodes_of(given, "Solid")] == ["shell", "given"]
    assert nodes_of(default, "Box")[0].fields["size"] == (0.4, 0.4, 0.4)
    assert [s.fields["name"] for s in nodes_of(default, "Solid")] == ["shell", "outer"]
    # the leaf's nodes come from Leaf.proto, the instance root from Outer.proto's body
    assert box.source == str(tmp_path / "Leaf.proto") and given.source == str(tmp_path / "Outer.proto")
    assert given.proto == "Outer" and given.instance_at == (str(w), 3, 1) and default.instance_at == (str(w), 4, 1)
    leaf = nodes_of(given, "Solid")[1]
    assert leaf.proto == "Leaf" and leaf.instance_at[0] == str(tmp_path / "Inner.proto")
    assert not [n for n in nodes_of(given, "Leaf") + nodes_of(given, "Inner")]     # base nodes only


def test_a_field_bound_by_is_keeps_its_parameter_when_the_node_gives_it_again(tmp_path: Path) -> None:
    """A body node giving one field twice, once ``IS`` a parameter (Webots' PandaHand: ``name IS
    name`` then ``name "hand"``): Webots keeps the field bound to the parameter whichever comes
    first (the value read later leaves the binding, which instantiation follows); two plain values:
    the last; two bindings: the last."""
    proto_file(tmp_path, "Hand", """[ field SFString name "panda hand" field SFString other "o" ]
{ Solid { name IS name children [
  Solid { name "first" name IS name }
  Solid { name "a" name "b" }
  Solid { name IS other name IS name }
] name "hand" } }""")
    w = world_file(tmp_path, 'Hand { }\nHand { name "given" }\n', ["Hand.proto"])
    default, given = expanded(w).nodes
    assert [s.fields["name"] for s in nodes_of(default, "Solid")] == ["panda hand", "panda hand", "b", "panda hand"]
    assert [s.fields["name"] for s in nodes_of(given, "Solid")] == ["given", "given", "b", "given"]
    assert [s.name for s in load_world(w).world.solids] == ["panda hand", "given"]


def test_slots_filled_from_the_world_keep_their_file_and_a_proto_default(tmp_path: Path) -> None:
    sensors = tmp_path / "sensors"
    proto_file(sensors, "MySensor", "[ field SFString name \"my sensor\" ] { DistanceSensor { name IS name } }")
    proto_file(tmp_path, "Bot", """[
  field SFString name "bot"
  field MFNode extensionSlot [ MySensor { } ]
  field MFNode bodySlot [ ]
  field SFNode turretSlot NULL
]
{ Robot { name IS name children [ Pose { children IS extensionSlot } Group { children IS bodySlot } ] } }""",
               header='EXTERNPROTO "sensors/MySensor.proto"\n')
    w = world_file(tmp_path, """Bot { name "a" }
Bot { name "b" extensionSlot [ MySensor { name "front" } LightSensor { name "eye" } ] bodySlot [ MySensor { name "back" } ] }
""", ["Bot.proto", "sensors/MySensor.proto"])
    a, b = load_world(w).world.robots
    assert [d.name for d in a.devices] == ["my sensor"]            # the slot's default, itself a PROTO
    assert [(d.name, d.device) for d in b.devices] == [("front", "DistanceSensor"), ("eye", "LightSensor"),
                                                        ("back", "DistanceSensor")]
    nodes = expanded(w).nodes
    eye = nodes_of(nodes[1], "LightSensor")[0]
    assert eye.source == str(w)                                    # passed in: keeps the world's file


def test_slot_instances_resolve_through_the_file_they_are_written_in(tmp_path: Path) -> None:
    """The world's MySensor and the PROTO's MySensor are different files with the same name."""
    proto_file(tmp_path / "world_protos", "MySensor", "[ ] { LightSensor { name \"world's\" } }")
    proto_file(tmp_path / "lib", "MySensor", "[ ] { DistanceSensor { name \"library's\" } }")
    proto_file(tmp_path / "lib", "Bot", "[ field MFNode slot [ ] ] { Robot { children [ MySensor { } Group { children IS slot } ] } }",
               header='EXTERNPROTO "MySensor.proto"\n')
    w = world_file(tmp_path, "Bot { slot [ MySensor { } ] }\n", ["lib/Bot.proto", "world_protos/MySensor.proto"])
    (robot,) = load_world(w).world.robots
    assert [d.name for d in robot.devices] == ["library's", "world's"]


def test_def_use_is_scoped_per_instance(tmp_path: Path) -> None:
    proto_file(tmp_path, "Twin", """[ field SFFloat r 0.1 ]
{ Solid { children [ DEF SHAPE Shape { geometry Sphere { radius IS r } } Pose { translation 1 0 0 children [ USE SHAPE ] } ] } }""")
    w = world_file(tmp_path, "DEF SHAPE Shape { geometry Box { } }\nTwin { r 0.5 }\nTwin { }\n"
                             "Solid { name \"mine\" children [ USE SHAPE ] }\n", ["Twin.proto"])
    nodes = expanded(w).nodes
    first, second = nodes[1], nodes[2]
    assert [s.fields["geometry"].fields["radius"] for s in nodes_of(first, "Shape")] == [0.5, 0.5]
    assert [s.fields["geometry"].fields["radius"] for s in nodes_of(second, "Shape")] == [0.1, 0.1]
    assert nodes[3].fields["children"][0].fields["geometry"].type == "Box"     # the world's SHAPE, not the PROTO's
    # a PROTO body cannot USE the world's DEF names
    proto_file(tmp_path, "Peek", "[ ] { Solid { children [ USE SHAPE ] } }")
    w = world_file(tmp_path, "DEF SHAPE Shape { geometry Box { } }\nPeek { }\n", ["Peek.proto"])
    with pytest.raises(WorldError, match=r"Peek.proto:2:41: USE SHAPE: no DEF SHAPE before this point"):
        load_world(w)


def test_def_use_of_an_instance_in_the_world(tmp_path: Path) -> None:
    proto_file(tmp_path, "Ball", "[ field SFFloat r 0.1 ] { Shape { geometry Sphere { radius IS r } } }")
    w = world_file(tmp_path, 'Solid { name "a" children [ DEF B Ball { r 0.3 } ] }\nSolid { name "b" children [ USE B ] }\n',
                   ["Ball.proto"])
    a, b = load_world(w).world.solids
    assert a.shapes[0].geometry.radius == b.shapes[0].geometry.radius == 0.3


@pytest.mark.parametrize("files, chain", [
    ({"Self": "[ ] { Group { children [ Self { } ] } }"}, "Self → Self"),
    ({"A": "[ ] { Group { children [ B { } ] } }", "B": "[ ] { Pose { children [ C { } ] } }",
      "C": "[ ] { Solid { children [ A { } ] } }"}, "A → B → C → A"),
    ({"A": "[ field SFNode slot B { } ] { Group { children IS slot } }", "B": "[ ] { Group { children [ A { } ] } }"},
     "A → B → A"),                                   # through a field's default value
])
def test_cycles_are_refused_with_the_chain(tmp_path: Path, files: dict[str, str], chain: str) -> None:
    decls = "".join(f'EXTERNPROTO "{other}.proto"\n' for other in files)
    for name, body in files.items():
        proto_file(tmp_path, name, body, header=decls)
    first = next(iter(files))
    w = world_file(tmp_path, f"{first} {{ }}\n", [f"{first}.proto"])
    with pytest.raises(ProtoError) as exc:
        expanded(w)
    assert f"instantiates itself: {chain}" in str(exc.value) and "\n" not in str(exc.value)


def test_a_world_passing_an_instance_into_the_same_proto_is_not_a_cycle(tmp_path: Path) -> None:
    proto_file(tmp_path, "Box2", "[ field MFNode inside [ ] ] { Solid { children IS inside } }")
    w = world_file(tmp_path, "Box2 { inside [ Box2 { inside [ Box2 { } ] } ] }\n", ["Box2.proto"])
    (outer,) = expanded(w).nodes
    assert len(nodes_of(outer, "Solid")) == 3


def test_derived_proto(tmp_path: Path) -> None:
    proto_file(tmp_path, "Base", "[ field SFString name \"base\" field SFFloat h 1 ] "
                                 "{ Solid { name IS name children [ Shape { geometry Cylinder { height IS h } } ] } }")
    proto_file(tmp_path, "Tall", "[ field SFString name \"tall\" ] { Base { name IS name h 5 } }",
               header='EXTERNPROTO "Base.proto"\n')
    w = world_file(tmp_path, "DEF T Tall { }\n", ["Tall.proto"])
    (solid,) = load_world(w).world.solids
    assert solid.name == "tall" and solid.shapes[0].geometry.height == 5.0 and solid.def_name == "T"
    (root,) = expanded(w).nodes
    assert root.type == "Solid" and root.proto == "Tall"


def test_what_an_instance_is_follows_its_base_node(tmp_path: Path) -> None:
    proto_file(tmp_path, "Geo", "[ field SFFloat r 0.25 ] { Sphere { radius IS r } }")
    proto_file(tmp_path, "Look", "[ field SFColor c 1 0 0 ] { PBRAppearance { baseColor IS c roughness 1 } }")
    proto_file(tmp_path, "Lit", "[ ] { PointLight { location 0 0 1 } }")
    proto_file(tmp_path, "Eye", "[ field SFString name \"eye\" ] { LightSensor { name IS name } }")
    proto_file(tmp_path, "Thing", "[ ] { Solid { name \"thing\" children [ Shape { appearance Look { c 0 1 0 } geometry Geo { } } ] } }",
               header='EXTERNPROTO "Geo.proto"\nEXTERNPROTO "Look.proto"\n')
    w = world_file(tmp_path, "Thing { }\nLit { }\nRobot { name \"r\" children [ Eye { } ] }\n",
                   ["Thing.proto", "Lit.proto", "Eye.proto"])
    world = load_world(w).world
    (thing,) = world.solids
    assert thing.shapes[0].geometry == wm.Sphere(type="sphere", radius=0.25)
    assert thing.shapes[0].appearance.base_color == (0.0, 1.0, 0.0)
    assert [light.type for light in world.lights] == ["PointLight"]
    assert [d.name for d in world.robots[0].devices] == ["eye"]


def test_proto_definitions_inside_the_world(tmp_path: Path) -> None:
    w = world_file(tmp_path, """PROTO Post [ field SFVec3f translation 0 0 0 field SFFloat height 1 ]
{
  Solid { translation IS translation name "post" children [ Shape { geometry Box { size 0.1 0.1 %<= fields.height.value >% } } ] }
}
PROTO Pair [ ] { Group { children [ Post { } Post { translation 1 0 0 height 2 } ] } }
Pair { }
""")
    a, b = load_world(w).world.solids
    assert (a.name, b.name) == ("post", "post(1)")
    assert (a.shapes[0].geometry.size, b.shapes[0].geometry.size) == ((0.1, 0.1, 1.0), (0.1, 0.1, 2.0))


def test_several_proto_definitions_in_one_world_keep_their_own_bodies(tmp_path: Path) -> None:
    # two PROTOs written in the world file, plain and templated alike: each instance is its own
    # PROTO's body (the second PROTO was read as the first one's body, a cube becoming a ball)
    w = world_file(tmp_path, """PROTO Ball [ field SFVec3f translation 0 0 0 ] { Solid { translation IS translation name "ball" children [ Shape { geometry Sphere { radius 0.5 } } ] } }
PROTO Cube [ field SFVec3f translation 0 0 0 ] { Solid { translation IS translation name "cube" children [ Shape { geometry Box { size 1 1 1 } } ] } }
PROTO Dot [ field SFFloat k 0.25 ] { Solid { name "dot" children [ Shape { geometry Sphere { radius %<= fields.k.value >% } } ] } }
PROTO Bar [ field SFFloat k 0.25 ] { Solid { name "bar" children [ Shape { geometry Box { size %<= fields.k.value >% 1 1 } } ] } }
Ball { translation 1 0 0 }
Cube { translation 2 0 0 }
Dot { }
Bar { }
""")
    loaded = load_world(w)
    assert not loaded.report.warnings
    ball, cube, dot, bar = loaded.world.solids
    assert [s.name for s in (ball, cube, dot, bar)] == ["ball", "cube", "dot", "bar"]
    assert ball.shapes[0].geometry == wm.Sphere(type="sphere", radius=0.5)
    assert cube.shapes[0].geometry == wm.Box(type="box", size=(1.0, 1.0, 1.0))
    assert cube.pose.translation == (2.0, 0.0, 0.0)
    assert dot.shapes[0].geometry == wm.Sphere(type="sphere", radius=0.25)
    assert bar.shapes[0].geometry == wm.Box(type="box", size=(0.25, 1.0, 1.0))


def test_instances_are_counted_where_they_sit_in_the_world(tmp_path: Path) -> None:
    # a sub-PROTO written once in a PROTO body, or as a slot's default, is one instance per robot
    # (it was counted once: its expansion is shared), a derived PROTO counts its base, a USE counts
    proto_file(tmp_path, "Glass", "[ ] { Shape { geometry Sphere { radius 0.01 } } }")
    proto_file(tmp_path, "Eye", "[ field SFString name \"eye\" ] { DistanceSensor { name IS name children [ Glass { } ] } }",
               header='EXTERNPROTO "Glass.proto"\n')
    proto_file(tmp_path, "Base", "[ field SFString name \"b\" field MFNode slot [ Eye { } ] ] "
                                 "{ Robot { name IS name children [ Eye { name \"front\" } Group { children IS slot } ] } }",
               header='EXTERNPROTO "Eye.proto"\n')
    proto_file(tmp_path, "Bot", "[ field SFString name \"bot\" ] { Base { name IS name } }", header='EXTERNPROTO "Base.proto"\n')
    w = world_file(tmp_path, 'Bot { name "a" }\nBot { name "b" }\nDEF C Bot { name "c" }\n'
                             'Pose { translation 1 0 0 children [ USE C ] }\n', ["Bot.proto"])
    uses = {u.name: u.instances for u in expanded(w).protos}
    assert uses == {"Bot": 4, "Base": 4, "Eye": 8, "Glass": 8}
    assert sum(len(r.devices) for r in load_world(w).world.robots) == 8
    # built-in stand-ins (their files not found) are counted too (they were x0)
    w = world_file(tmp_path / "stand", 'WoodenBox { }\nDEF B WoodenBox { translation 1 0 0.3 }\nPose { children [ USE B ] }\n'
                                       'RectangleArena { }\n', ["webots://projects/objects/factory/containers/protos/"
                                                                 "WoodenBox.proto", "webots://projects/objects/floors/"
                                                                                   "protos/RectangleArena.proto"])
    uses = {u.name: (u.instances, u.builtin) for u in expanded(w).protos}
    assert uses == {"WoodenBox": (3, True), "RectangleArena": (1, True)}


def test_a_cycle_between_protos_defined_in_the_world_names_its_chain(tmp_path: Path) -> None:
    w = world_file(tmp_path, "PROTO A [ ] { B { } }\nPROTO B [ ] { A { } }\nA { }\n")
    with pytest.raises(ProtoError) as exc:
        expanded(w)
    assert str(exc.value) == f"{w}:3:15: PROTO A instantiates itself: A → B → A"


@pytest.mark.parametrize("body, where, what", [
    ("[ field SFFloat a 1 ] { Solid { name IS b } }", "Bad.proto:2:51",
     "IS b: PROTO Bad has no field b (its fields: a)"),
    ("[ field SFBogus a 1 ] { Group { } }", "Bad.proto:2:19", "PROTO Bad: unknown field type 'SFBogus'"),
    ("[ field SFVec3f a 1 2 ] { Group { } }", "Bad.proto:2:29", "PROTO Bad.a: default value: SFVec3f expects 3 numbers"),
    ("[ field SFFloat a 1 ] { }", "Bad.proto:2:1", "PROTO Bad: the body holds no node"),
    ("[ field SFFloat a 1 ] { Group { } Group { } }", "Bad.proto:2:45",
     "PROTO Bad: the body holds more than one node"),
    ("[ field SFFloat a 1 ", "Bad.proto:3:1", "end of file inside the interface of PROTO Bad"),
])
def test_proto_file_errors(tmp_path: Path, body: str, where: str, what: str) -> None:
    proto_file(tmp_path, "Bad", body)
    w = world_file(tmp_path, "Bad { }\n", ["Bad.proto"])
    with pytest.raises(ProtoError) as exc:
        expanded(w)
    msg = str(exc.value)
    assert msg.startswith(f"{tmp_path / where}: ") and what in msg and "\n" not in msg, msg


def test_proto_name_must_match_its_file(tmp_path: Path) -> None:
    (tmp_path / "Good.proto").write_text('#VRML_SIM R2023b utf8\nPROTO Other [ ] { Group { } }\n')
    w = world_file(tmp_path, "Good { }\n", ["Good.proto"])
    with pytest.raises(ProtoError, match=r"Good.proto:2:1: PROTO Other: the name does not match the file name Good.proto"):
        expanded(w)


def test_licences_are_collected(tmp_path: Path) -> None:
    proto_file(tmp_path, "Lic", "[ ] { Group { } }", header="# license: Apache License 2.0\n"
                                                               "# license url: https://www.apache.org/licenses/LICENSE-2.0\n")
    proto_file(tmp_path, "Free", "[ ] { Group { } }")
    w = world_file(tmp_path, "Lic { }\nLic { }\nFree { }\n", ["Lic.proto", "Free.proto"])
    uses = {u.name: u for u in expanded(w).protos}
    assert (uses["Lic"].license, uses["Lic"].license_url, uses["Lic"].instances) == (
        "Apache License 2.0", "https://www.apache.org/licenses/LICENSE-2.0", 2)
    assert uses["Lic"].path == str(tmp_path / "Lic.proto") and uses["Free"].license is None


def test_nodes_keep_their_positions_in_the_proto_file(tmp_path: Path) -> None:
    proto_file(tmp_path, "Where", "[ ]\n{\n  Solid {\n    children [\n      Shape { geometry Box { } }\n    ]\n  }\n}")
    (solid,) = expanded(world_file(tmp_path, "Where { }\n", ["Where.proto"])).nodes
    box = nodes_of(solid, "Box")[0]
    assert (box.source, box.line, box.col) == (str(tmp_path / "Where.proto"), 6, 24)
    assert solid.field_pos["children"] == (5, 5)


def test_unknown_hidden_state_in_instances_is_dropped(tmp_path: Path) -> None:
    proto_file(tmp_path, "Wheelie", "[ field SFVec3f translation 0 0 0 ] { Solid { translation IS translation } }")
    w = world_file(tmp_path, "Wheelie { hidden position_0_0 0.5 hidden rotation_1 0 0 1 0 translation 1 2 3 }\n",
                   ["Wheelie.proto"])
    assert load_world(w).world.solids[0].pose.translation == (1.0, 2.0, 3.0)


def test_a_bare_null_for_an_mfnode_is_no_nodes(tmp_path: Path) -> None:
    """Webots' Hinge2JointWithBacklash declares ``field MFNode{...} startPoint NULL`` and Webots loads
    it: a bare NULL for a whole MFNode (default or instance value) is no nodes. It was refused ("MFNode
    expects nodes, got NULL") and every world using the PROTO failed. NULL inside brackets stays an error."""
    proto_file(tmp_path, "Holder", """[
  field MFNode{Group{}, Transform{}, Shape{}} extra NULL  field MFNode more [ ]
]
{ Group { children [ Group { children IS extra } Group { children IS more } ] } }""")
    w = world_file(tmp_path, "Holder { }\nHolder { more NULL extra [ Shape { } ] }\n", ["Holder.proto"])
    first, second = expanded(w).nodes
    kids = [[len(g.fields["children"]) for g in n.fields["children"]] for n in (first, second)]
    assert kids == [[0, 0], [1, 0]]
    bad = world_file(tmp_path, "Holder { more [ NULL ] }\n", ["Holder.proto"], name="bad.wbt")
    with pytest.raises(WorldError, match="Holder.more: MFNode expects nodes, got NULL"):
        load_world(bad)
