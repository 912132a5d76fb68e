"""A PROTO instance's own fields through the Supervisor, as in Webots (README "Supervisor"): on a PROTO
instance ``getField`` answers its PROTO's interface fields (the values written in the instance, else
the PROTO's defaults), ``getBaseNodeField`` its base node's (read-only), ``getProto()`` its PROTO (name,
``isDerived``, ``getParent`` for a PROTO built on a PROTO, its fields by name and index), and the node's
``getNumberOfFields``/``getFieldByIndex`` count the interface fields. An interface field whose value passes
straight through IS to a base-node field Sensorium sets (a top-level solid's ``translation``) reads that
field now and sets it; another field of a top-level solid builds it again (tests/test_supervisor_proto_regen.py);
any other is read-only here (a robot's: Webots regenerates the node), refused with one line naming node and
field, nothing changed.

Sensorium's own PROTOs (tests/protos/supervisor: Crate, BigCrate on Crate, Boss, Keeper with most field
types and a slot holding a Tag) on tests/worlds/proto/supervisor_protos.wbt and
supervisor_proto_fields.wbt; the last tests run a Webots-style Python controller and the same sequence
from C (the library built with AddressSanitizer and UBSan) through ``sensorium serve``."""

from __future__ import annotations

import sys

import pytest
from _protos import HEADER
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world

WORLD = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_fields.wbt"
PROTOS = REPO / "tests" / "worlds" / "proto" / "supervisor_protos.wbt"
KEEPER, CRATE, BIG, BOX = range(1, 5)                  # the robot, then the top-level solids in file order
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}


def _live(world=WORLD, robot: str = "keeper") -> tuple[Live, str]:
    lv = Live(Simulation(load_world(world)))
    lv.ok(A, "attach", {"robot": robot})
    return lv, robot


def call(lv_robot: tuple[Live, str], item: str, args: dict) -> dict:
    lv, robot = lv_robot
    return lv.ok(A, f"/{robot}/robot/{item}", args)


def refused(lv_robot: tuple[Live, str], item: str, args: dict) -> str:
    lv, robot = lv_robot
    return lv.err(A, f"/{robot}/robot/{item}", args, ErrorCode.INVALID_ARGUMENT)


def field(lv_robot, node: int, name: str, level: int | None = None) -> dict:
    return call(lv_robot, "get_field", {"node": node, "field": name, **({} if level is None else {"level": level})})


def test_a_proto_instance_answers_its_interface_fields_as_written_else_the_protos_defaults():
    lv = _live()
    got = {name: field(lv, KEEPER, name) for name in
           ("translation", "reach", "level", "active", "footprint", "color", "gains", "waypoints", "tags", "ids",
            "flags")}
    assert got == {
        "translation": {"type": "SFVec3f", "value": [0.5, 0.0, 0.0]},       # written in the instance
        "reach": {"type": "SFFloat", "value": 0.75},
        "level": {"type": "SFInt32", "value": 3},                          # the PROTO's defaults
        "active": {"type": "SFBool", "value": True},
        "footprint": {"type": "SFVec2f", "value": [0.1, 0.2]},
        "color": {"type": "SFColor", "value": [1.0, 0.5, 0.0]},
        "gains": {"type": "MFFloat", "value": [4.0, 5.0]},                  # written
        "waypoints": {"type": "MFVec3f", "value": [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]},
        "tags": {"type": "MFString", "value": ["x"]},
        "ids": {"type": "MFInt32", "value": [7, -2]},
        "flags": {"type": "MFBool", "value": [True, False]}}
    assert field(lv, CRATE, "size") == {"type": "SFVec3f", "value": [0.2, 0.2, 0.2]}        # Crate's default
    # a slot (a node-typed field that does not pass straight to a base-node field): typed, its value not served
    slot = field(lv, KEEPER, "bodySlot")
    assert slot["type"] == "MFNode" and slot["value"] == []
    assert slot["note"] == ("field 'bodySlot' (MFNode) of PROTO Keeper (Robot 'KEEPER' (node 1)): a node-typed PROTO "
                            "field is not served here unless it passes straight through IS to the base node's field")


def test_getfield_on_a_proto_instance_knows_only_its_interface_and_getbasenodefield_its_base_node():
    lv = _live()
    # the Robot's controller is no field of Keeper's interface: Webots' NULL, without a line
    assert field(lv, KEEPER, "controller") == {"type": "", "value": [], "absent": True}
    assert field(lv, KEEPER, "controller", level=0) == {"type": "SFString", "value": "<extern>"}
    assert field(lv, KEEPER, "supervisor", level=0) == {"type": "SFBool", "value": True}
    assert field(lv, KEEPER, "reach", level=0) == {"type": "", "value": []}      # the Robot has no reach
    # a base node: getField is its own field, as before; it has no PROTO
    assert field(lv, BOX, "translation") == field(lv, BOX, "translation", level=0) == \
        {"type": "SFVec3f", "value": [-1.0, 0.0, 0.1]}
    assert call(lv, "get_proto", {"node": BOX}) == {"type_name": "", "derived": False, "fields": []}
    assert call(lv, "get_proto", {"node": 0}) == {"type_name": "", "derived": False, "fields": []}


def test_getproto_names_the_proto_its_fields_and_the_proto_it_is_built_on():
    lv = _live()
    assert call(lv, "get_proto", {"node": KEEPER}) == {"type_name": "Keeper", "derived": False, "fields": [
        "translation", "rotation", "name", "reach", "level", "active", "footprint", "color", "gains", "waypoints",
        "tags", "ids", "flags", "bodySlot"]}
    # BigCrate's body is a Crate: BigCrate is derived, its parent is Crate with the values BigCrate gives it
    assert call(lv, "get_proto", {"node": BIG}) == {"type_name": "BigCrate", "derived": True,
                                                    "fields": ["translation", "name"]}
    assert call(lv, "get_proto", {"node": BIG, "level": 2}) == {"type_name": "Crate", "derived": False,
                                                                "fields": ["translation", "name", "size"]}
    assert call(lv, "get_proto", {"node": BIG, "level": 3})["type_name"] == ""
    assert field(lv, BIG, "size", level=2) == {"type": "SFVec3f", "value": [0.4, 0.4, 0.4]}   # BigCrate's body
    assert field(lv, BIG, "name", level=2) == {"type": "SFString", "value": "big crate"}       # BigCrate's default
    assert field(lv, BIG, "size") == {"type": "", "value": [], "absent": True}    # not BigCrate's field
    assert field(lv, BIG, "translation", level=2) == {"type": "SFVec3f", "value": [2.0, 0.0, 0.2]}


def test_a_proto_field_passing_through_is_to_the_base_translation_moves_the_solid():
    lv = _live()
    call(lv, "set_field", {"node": CRATE, "field": "translation", "value": [1.5, -0.25, 0.1]})
    assert call(lv, "get_node_pose", {"node": CRATE})["position"] == [1.5, -0.25, 0.1]
    assert field(lv, CRATE, "translation")["value"] == [1.5, -0.25, 0.1]
    assert field(lv, CRATE, "translation", level=0)["value"] == [1.5, -0.25, 0.1]
    # BigCrate's translation reaches the Solid through Crate's: both levels read the solid now
    call(lv, "set_field", {"node": BIG, "field": "translation", "value": [3.0, 0.0, 0.2]})
    assert field(lv, BIG, "translation", level=2)["value"] == [3.0, 0.0, 0.2]
    assert call(lv, "get_node_pose", {"node": BIG})["position"] == [3.0, 0.0, 0.2]


def test_a_proto_field_sensorium_cannot_apply_is_refused_with_one_line_and_nothing_changes():
    lv = _live()
    msg = refused(lv, "set_field", {"node": KEEPER, "field": "reach", "value": 0.5})
    assert msg == ("set_field: field 'reach' (SFFloat) of PROTO Keeper (Robot 'keeper') is read-only here: Webots "
                   "regenerates the node when such a PROTO field is set; Sensorium builds again only a top-level "
                   "solid (a robot's controller, devices and lockstep slot are built once here: a robot is not "
                   "rebuilt) and otherwise sets only the PROTO fields that pass straight through IS to a field it "
                   "sets (a top-level robot's or solid's translation and rotation, a light's fields); nothing changed")
    assert field(lv, KEEPER, "reach")["value"] == 0.75
    assert refused(lv, "set_field", {"node": CRATE, "field": "name", "value": "box"}) == (
        "set_field: field 'name' (SFString) of PROTO Crate (Solid 'crate') is read-only here: it passes to the base "
        "node's 'name', which is read-only here; nothing changed")
    assert refused(lv, "set_field", {"node": CRATE, "field": "translation", "value": [0, 0, 1], "level": 0}) == (
        "set_field: field 'translation' of Solid 'crate' is a PROTO internal field (getBaseNodeField), read-only as "
        "in Webots: set the field of PROTO Crate instead")
    assert refused(lv, "set_field", {"node": BIG, "field": "translation", "value": [0, 0, 1], "level": 2}) == (
        "set_field: field 'translation' of Solid 'big crate' belongs to PROTO Crate, which PROTO BigCrate is built "
        "on: read-only, as in Webots")
    assert call(lv, "get_node_pose", {"node": CRATE})["position"] == [1.0, 0.0, 0.1]
    assert call(lv, "get_node_pose", {"node": BIG})["position"] == [2.0, 0.0, 0.2]


def test_a_proto_instance_inside_a_robot_answers_its_interface():
    lv = _live()
    tag = call(lv, "get_from_def", {"name": "TAG"})          # written in the world, passed into Keeper's slot
    assert (tag["type"], tag["proto"], tag["name"]) == ("Solid", "Tag", "front tag")
    assert call(lv, "get_proto", {"node": tag["node"]}) == {"type_name": "Tag", "derived": False,
                                                            "fields": ["translation", "name", "weight"]}
    assert field(lv, tag["node"], "weight") == {"type": "SFFloat", "value": 0.25}
    assert field(lv, tag["node"], "translation") == {"type": "SFVec3f", "value": [0.0, 0.0, 0.1]}
    assert refused(lv, "set_field", {"node": tag["node"], "field": "translation", "value": [0, 0, 0.2]}) == (
        "set_field: field 'translation' (SFVec3f) of PROTO Tag (Solid 'front tag') is read-only here: it passes to "
        "the base node's 'translation', which is read-only here; nothing changed")


def test_the_interface_of_the_robot_proto_follows_the_robot():
    lv = _live(PROTOS, "boss")
    boss = 1
    call(lv, "set_field", {"node": boss, "field": "translation", "value": [0.3, 0.2, 0.0]})
    assert field(lv, boss, "translation")["value"] == [0.3, 0.2, 0.0]
    assert call(lv, "get_node_pose", {"node": boss})["position"] == [0.3, 0.2, 0.0]
    assert field(lv, boss, "name") == {"type": "SFString", "value": "boss"}


def test_an_imported_proto_instance_answers_its_interface():
    lv = _live()
    (crate,) = call(lv, "import_node_from_string", {"node": 0, "field": "children", "position": -1,
                                                    "node_string": 'Crate { translation 0 2 0.1 size 0.1 0.3 0.1 }'})["value"]
    assert call(lv, "get_proto", {"node": crate})["fields"] == ["translation", "name", "size"]
    assert field(lv, crate, "size") == {"type": "SFVec3f", "value": [0.1, 0.3, 0.1]}
    assert field(lv, crate, "name") == {"type": "SFString", "value": "crate(1)"}      # renamed, as Webots does
    call(lv, "set_field", {"node": crate, "field": "translation", "value": [0.0, 2.5, 0.1]})
    assert call(lv, "get_node_pose", {"node": crate})["position"] == [0.0, 2.5, 0.1]


def test_a_long_value_is_not_kept_and_its_field_says_so(tmp_path):
    (tmp_path / "Long.proto").write_text(HEADER + "PROTO Long [\n  field MFFloat samples [ ]\n  field SFFloat k 2\n]\n"
                                         "{\n  Solid { name \"long\" }\n}\n")
    world = tmp_path / "long.wbt"
    world.write_text(HEADER + 'EXTERNPROTO "Long.proto"\n'
                     f"Long {{ samples [ {' '.join(['0.5'] * 4097)} ] }}\n"
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = _live(world, "boss")
    long_ = 2
    got = field(lv, long_, "samples")
    assert (got["type"], got["value"]) == ("MFFloat", [])
    assert got["note"] == "field 'samples' (MFFloat) of PROTO Long (Solid 'long' (node 2)): its value is over 4096 " \
                          "items, not kept here"
    assert field(lv, long_, "k") == {"type": "SFFloat", "value": 2.0}


EXPECTED = """proto Keeper 0 14
node_count 14
reach SFFloat 0.75
level 3
active 1
footprint 0.10000000000000001 0.20000000000000001
color 1 0.5 0
gains 2 4 5
waypoints 2 1 0 0
tags 1 x
ids 2 7 -2
flags 2 1 0
slot MFNode -1
byindex reach MFNode
base <extern> 1
none null
big BigCrate 1 2
parent Crate 0 3 0.40000000000000002 0.40000000000000002 0.40000000000000002
grand null
crate 0.20000000000000001 0.20000000000000001 0.20000000000000001
box null
tag Tag 0.25 0 0 0.10000000000000001
set 1.5 0 0.10000000000000001 1 1 1""".splitlines()


def _check_lines(err: str) -> None:
    assert "field 'bodySlot' (MFNode) of PROTO Keeper" in err and "of PROTO Crate" not in err, err
    assert "not served by Sensorium" not in err and "Sanitizer" not in err and "runtime error" not in err, err
    assert err.count("Error:") == 1, err


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_python_supervisor_reads_proto_fields(tmp_path):
    """tests/controllers/supervisor_proto_fields.py through ``sensorium serve``."""
    ctl = run_paused(WORLD, tmp_path, "supervisor_proto_fields.py", "keeper")
    assert ctl.out == EXPECTED
    _check_lines(ctl.stderr())


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_reads_the_same_proto_fields(tmp_path, tmp_path_factory):
    """tests/c/supervisor_proto_fields.c (the library with AddressSanitizer and UBSan)."""
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_proto_fields.c")
    ctl = run_paused(WORLD, tmp_path, exe, "keeper", env=SAN_ENV)
    assert ctl.out == EXPECTED
    _check_lines(ctl.stderr())


def test_a_set_at_a_level_past_the_proto_chain_is_one_line_and_nothing_changes():
    lv = _live()
    for node, chain in ((BOX, "none, it is no PROTO instance"), (CRATE, "Crate"), (BIG, "BigCrate > Crate")):
        what = {BOX: "Solid 'BOX' (node 4)", CRATE: "Solid 'CRATE' (node 2)", BIG: "Solid 'BIG' (node 3)"}[node]
        assert refused(lv, "set_field", {"node": node, "field": "translation", "value": [0, 0, 1], "level": 3}) == (
            f"set_field: {what} has no PROTO at level 3 (its PROTO chain: {chain})")
    assert call(lv, "get_node_pose", {"node": CRATE})["position"] == [1.0, 0.0, 0.1]
    assert call(lv, "get_node_pose", {"node": BOX})["position"] == [-1.0, 0.0, 0.1]


def test_a_proto_parameter_beyond_the_worlds_number_bounds_loads_when_nothing_simulates_it(tmp_path):
    """A PROTO parameter of 1e12 or 1e-40 that no simulated field takes is read back as written; one that
    reaches a simulated field through IS is still refused, naming that field."""
    (tmp_path / "Wide.proto").write_text(HEADER + "PROTO Wide [\n  field SFFloat big 1e12\n  field MFFloat tiny [ 1e-40 ]\n"
                                         "  field SFVec3f translation 0 0 0\n]\n"
                                         "{\n  Solid { translation IS translation name \"wide\" }\n}\n")
    world = tmp_path / "wide.wbt"
    world.write_text(HEADER + 'EXTERNPROTO "Wide.proto"\nWide { big -1.5e300 }\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    lv = _live(world, "boss")
    assert field(lv, 2, "big") == {"type": "SFFloat", "value": -1.5e300}
    assert field(lv, 2, "tiny") == {"type": "MFFloat", "value": [1e-40]}
    world.write_text(HEADER + 'EXTERNPROTO "Wide.proto"\nWide { translation 1e12 0 0 }\n')
    with pytest.raises(WorldError, match=r"translation.*the magnitude of 1e\+12 exceeds the limit"):
        load_world(world)


def _deep_chain(folder, n: int = 18):
    """P{n-1} built on P{n-2} ... on P0, a Solid; the world: one P{n-1} (DEF DEEP) and a supervisor robot."""
    (folder / "P0.proto").write_text(HEADER + "PROTO P0 [ field SFVec3f translation 0 0 0 ] "
                                     "{ Solid { translation IS translation name \"deep\" } }\n")
    for k in range(1, n):
        (folder / f"P{k}.proto").write_text(HEADER + f'EXTERNPROTO "P{k - 1}.proto"\nPROTO P{k} [ field SFVec3f '
                                            f"translation 0 0 0 ] {{ P{k - 1} {{ translation IS translation }} }}\n")
    world = folder / "deep.wbt"
    world.write_text(HEADER + f'EXTERNPROTO "P{n - 1}.proto"\nDEF DEEP P{n - 1} {{ translation 1 2 3 }}\n'
                     'Robot { name "boss" supervisor TRUE controller "<extern>" }\n')
    return world


CHAIN = [f"P{k} 1 1" for k in range(17, 1, -1)] + ["end"]
CHAIN_REFUSAL = "/boss/robot/get_proto: argument 'level': Input should be less than or equal to 16 (got 17)"


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_walking_a_chain_longer_than_16_protos_ends_with_one_line_in_python_and_c(tmp_path, tmp_path_factory):
    """getParent() from P17 down: 16 PROTOs, each derived, then one line and NULL (the chain is kept to 16)."""
    from test_c_client import sanitized_controller

    world = _deep_chain(tmp_path)
    (tmp_path / "py").mkdir()
    (tmp_path / "c").mkdir()
    py = run_paused(world, tmp_path / "py", "supervisor_proto_chain.py", "boss")
    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_proto_chain.c")
    c = run_paused(world, tmp_path / "c", exe, "boss", env=SAN_ENV)
    func = "Error: wb_supervisor_proto_get_parent(): "      # each client relays a refusal as it does any other
    for ctl, line in ((py, f"{func}{CHAIN_REFUSAL}."), (c, f"{func}INVALID_ARGUMENT: {CHAIN_REFUSAL}")):
        assert ctl.out == CHAIN
        assert [x for x in ctl.stderr().splitlines() if x.startswith("Error")] == [line], ctl.stderr()


def test_a_chain_longer_than_the_16_protos_kept_still_says_its_last_kept_proto_is_derived(tmp_path):
    """P17 built on P16 ... on P0: getProto() and 15 getParent() reach P2, which is derived (built on P1,
    past the 16 PROTOs kept); the translation passes through all of them to the Solid."""
    world = _deep_chain(tmp_path)
    lv = _live(world, "boss")
    deep = 2
    for level in range(1, 17):
        assert call(lv, "get_proto", {"node": deep, "level": level}) == {
            "type_name": f"P{18 - level}", "derived": True, "fields": ["translation"]}
        assert field(lv, deep, "translation", level=level)["value"] == [1.0, 2.0, 3.0]
    call(lv, "set_field", {"node": deep, "field": "translation", "value": [0.5, 0.0, 0.0]})
    assert field(lv, deep, "translation", level=16)["value"] == [0.5, 0.0, 0.0]


HARDEN = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_harden.wbt"
EXPECTED_HARDEN = """nullnode 1
nullproto [] 0 -1 1 1 1
foreign [] -1 1
nullfield -1 0 nan 1
foreignfield -1 nan 1
basenull 1 -1
proto Lengthy 7
index -1 1 1
index 7 1 1
index 2147483647 1 1
index -2147483648 1 1
last label
names 1 1 1 1
long SFFloat 0.125 0.125
unknown 1
none 0 nan
corner0 1 2
corner-1 -0 4.9406564584124654e-324
corner-2 1 2
corner-3 -999 -999 null
corner2 -999 -999 null
cornermin -999 -999 null
turn 0 0 1 -3.5
size2 -1.0000000000000001e+300 1e-300
label [a "quoted" back\\slash é中] -1
wrong nan 0 0 1 1 1 1 [] 1
moved 1 1 0.10000000000000001
moved 0.25 -0.5 0.10000000000000001
kept 2
parent Crate 1
box 1 6 0
me 14""".splitlines()
FOREIGN_FIELD = "foreignfield -1 nan 1"       # C only: a WbFieldRef the library never gave


def _check_harden_lines(err: str) -> None:
    assert "Sanitizer" not in err and "runtime error" not in err and "Traceback" not in err, err
    for line in ("Error: wb_supervisor_proto_get_parent() called with a NULL or invalid 'proto' argument.",
                 "Error: wb_supervisor_field_get_count() called with NULL 'field' argument.",
                 "Error: wb_supervisor_proto_get_field_by_index() called with an invalid 'index' argument: -2147483648 "
                 "(the PROTO has 7 fields).",
                 "Error: wb_supervisor_field_get_mf_vec2f() called with an out-of-bound index: -3 (should be "
                 "between -2 and 1).",
                 "Error: wb_supervisor_field_get_mf_float() called on an empty list.",
                 "Error: wb_supervisor_field_get_mf_rotation() called with wrong field type: SFVec2f.",
                 "Error: wb_supervisor_field_set_sf_vec3f() called with a NaN or infinite value."):
        assert line in err.splitlines(), (line, err)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_careless_python_supervisor_gets_one_line_and_no_value_for_each_bad_call(tmp_path):
    """tests/controllers/supervisor_proto_harden.py: None refs, indexes both ways out of range, the wrong
    getter, names empty, of 84 and 100000 characters, NaN and infinite values set through IS."""
    ctl = run_paused(HARDEN, tmp_path, "supervisor_proto_harden.py", "keeper")
    assert ctl.out == [line for line in EXPECTED_HARDEN if line != FOREIGN_FIELD]
    _check_harden_lines(ctl.stderr())
    # a NULL proto twice (type name, number of fields, ...), the foreign one and six bogus tuples: one line each
    named = [x for x in ctl.stderr().splitlines() if x.startswith("Error: wb_supervisor_proto_get_type_name()")]
    assert named == ["Error: wb_supervisor_proto_get_type_name() called with a NULL or invalid 'proto' argument."] * 8


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_careless_c_supervisor_gets_webots_lines_and_no_sanitizer_report(tmp_path, tmp_path_factory):
    """tests/c/supervisor_proto_harden.c under ASan and UBSan: the same, and refs the library never gave."""
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_proto_harden.c")
    ctl = run_paused(HARDEN, tmp_path, exe, "keeper", env=SAN_ENV)
    assert ctl.out == EXPECTED_HARDEN
    err = ctl.stderr()
    _check_harden_lines(err)
    assert "Error: wb_supervisor_field_get_count() called with invalid 'field' argument." in err.splitlines(), err
