"""exportString of nodes inside robots and solids (daemon/export.py), on our own worlds.

tests/worlds/export_nested.wbt: the robot "arm" at the origin holds the distance sensor EYE and the SHOULDER hinge
about z through its origin, whose end point LINK stands at (0.5, 0, 0) holding TOOL at (0.1, 0, 0) in LINK's frame;
the solid TABLE holds the shape TOP (appearance PAINT, baseColor 1 0 0) and the solid LEG. Turned a quarter turn,
LINK stands at (0, 0.5, 0) turned pi/2 about z (closed form), TOOL unchanged in LINK's frame.
tests/worlds/proto/supervisor_proto_def.wbt: the PROTO instance ROVER holds GIVEN in its extensionSlot field; EYE,
ARM and TOOL are its body's (Rover.proto), BOARD the body's of SHELF (Shelf.proto)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.daemon import supervisor as sv
from sensorium.server.daemon.export import NotExported, node_string, world_string
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world
from sensorium.server.world.wbt.parser import Node, parse_wbt

REPO = Path(__file__).resolve().parent.parent
WORLD = REPO / "tests" / "worlds" / "export_nested.wbt"
PROTOS = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_def.wbt"
HEADER = "#VRML_SIM R2023b utf8\n"


def _sim(world: Path = WORLD) -> Simulation:
    return Simulation(load_world(world))


def _node(sim: Simulation, name: str) -> sv.Node:
    node = sv.find_node(sim, name)
    assert node is not None, name
    return node


def _read(text: str) -> Node:
    (node,) = parse_wbt(HEADER + text).nodes
    return node


def _as_written(world: Path, def_name: str) -> Node:
    """The node of that DEF as the world file writes it (our parser on the file itself)."""
    return _find_def(list(parse_wbt(world.read_text(), str(world)).nodes), def_name)


def _find_def(todo: list, def_name: str) -> Node:
    """The node of DEF ``def_name`` among the parsed nodes ``todo`` and everything under them."""
    while todo:
        v = todo.pop()
        if isinstance(v, Node):
            if v.def_name == def_name:
                return v
            todo.extend(v.fields.values())
        elif isinstance(v, list):
            todo.extend(v)
    raise AssertionError(def_name)


def _save(sim: Simulation, folder: Path) -> Path:
    """worldSave's text written in ``folder``, its EXTERNPROTO url made absolute."""
    saved = folder / "saved.wbt"
    saved.write_text(world_string(sim).replace('"../protos/', f'"{REPO / "tests" / "protos"}/'))
    return saved


def _same_tree(a: Node, b: Node) -> bool:
    """Two parsed nodes with the same type, DEF and fields, nodes inside compared alike."""
    def same(x, y) -> bool:
        if isinstance(x, Node) and isinstance(y, Node):
            return _same_tree(x, y)
        if isinstance(x, list) and isinstance(y, list):
            return len(x) == len(y) and all(same(p, q) for p, q in zip(x, y))
        return bool(x == y)
    return (a.type, a.def_name, list(a.fields)) == (b.type, b.def_name, list(b.fields)) and all(
        same(a.fields[k], b.fields[k]) for k in a.fields)


@pytest.mark.parametrize("name", ["EYE", "SHOULDER", "LINK", "TOOL", "TOP", "PAINT", "LEG"])
def test_a_nested_node_unchanged_exports_as_the_file_writes_it(name):
    sim = _sim()
    got = _read(node_string(sim, _node(sim, name)))
    assert _same_tree(got, _as_written(WORLD, name)), node_string(sim, _node(sim, name))


def test_a_device_inside_a_robot_exports_its_fields():
    sim = _sim()
    got = _read(node_string(sim, _node(sim, "EYE")))
    assert (got.type, got.def_name, got.fields) == ("DistanceSensor", "EYE", {"translation": (0.05, 0.0, 0.1),
                                                                               "name": "eye"})


def _parameters(sim: Simulation) -> sv.Node:
    return sv.node_by_id(sim, sv.get_field(sim, _node(sim, "SHOULDER"), "jointParameters")["value"])


def test_a_joint_a_supervisor_turned_exports_its_position_and_its_end_points_pose_now():
    sim = _sim()
    sv.set_field(sim, _parameters(sim), "position", math.pi / 2)
    parameters = _read(node_string(sim, _parameters(sim)))
    assert parameters.type == "HingeJointParameters"
    assert parameters.fields == {"axis": (0.0, 0.0, 1.0), "position": math.pi / 2}
    link = _read(node_string(sim, _node(sim, "LINK")))
    assert list(link.fields)[:2] == ["translation", "rotation"]       # Webots' order, the rotation added
    assert link.fields["translation"] == pytest.approx((0.0, 0.5, 0.0), abs=1e-15)
    assert link.fields["rotation"] == pytest.approx((0.0, 0.0, 1.0, math.pi / 2), abs=1e-15)
    tool = link.fields["children"][0]
    assert tool.fields["translation"] == (0.1, 0.0, 0.0)               # rides in LINK's frame: as written
    assert _read(node_string(sim, _node(sim, "TOOL"))).fields["translation"] == (0.1, 0.0, 0.0)
    robot = _read(node_string(sim, _node(sim, "ARM")))                 # the robot's text holds them too
    joint = robot.fields["children"][1]
    assert joint.fields["jointParameters"].fields["position"] == math.pi / 2
    assert joint.fields["endPoint"].fields["translation"] == pytest.approx((0.0, 0.5, 0.0), abs=1e-15)


def test_a_joint_turned_back_exports_as_written():
    sim = _sim()
    sv.set_field(sim, _parameters(sim), "position", 1.0)
    sv.set_field(sim, _parameters(sim), "position", 0.0)
    assert _same_tree(_read(node_string(sim, _node(sim, "LINK"))), _as_written(WORLD, "LINK"))
    assert _read(node_string(sim, _parameters(sim))).fields == {"axis": (0.0, 0.0, 1.0)}     # 0: Webots' default


def test_a_saved_world_loads_the_arm_as_it_stood(tmp_path):
    sim = _sim()
    sv.set_field(sim, _parameters(sim), "position", 0.75)
    again = _sim(_save(sim, tmp_path))
    assert sv.get_field(again, _parameters(again), "position")["value"] == 0.75
    for name in ("LINK", "TOOL"):
        now, loaded = sv.node_pose(sim, _node(sim, name)), sv.node_pose(again, _node(again, name))
        assert np.allclose(now["position"], loaded["position"], rtol=0, atol=1e-15), name
        assert np.allclose(now["orientation"], loaded["orientation"], rtol=0, atol=1e-15), name
    c, s = math.cos(0.75), math.sin(0.75)                              # TOOL at 0.6 m along the turned x
    assert sv.node_pose(again, _node(again, "TOOL"))["position"] == pytest.approx([0.6 * c, 0.6 * s, 0.0], abs=1e-15)


def test_a_shape_in_a_solids_children_exports_the_colour_a_supervisor_set():
    sim = _sim()
    sv.set_field(sim, _node(sim, "PAINT"), "baseColor", [0.0, 1.0, 0.0])
    top = _read(node_string(sim, _node(sim, "TOP")))
    assert top.fields["appearance"].fields == {"baseColor": (0.0, 1.0, 0.0), "roughness": 0.5}
    assert top.fields["geometry"].fields == {"size": (1.0, 1.0, 0.05)}
    assert _read(node_string(sim, _node(sim, "PAINT"))).fields["baseColor"] == (0.0, 1.0, 0.0)
    table = _read(node_string(sim, _node(sim, "TABLE")))
    assert table.fields["children"][0].fields["appearance"].fields["baseColor"] == (0.0, 1.0, 0.0)
    assert _same_tree(table.fields["children"][1], _as_written(WORLD, "LEG"))


def test_a_node_in_a_proto_instances_field_exports_as_written():
    sim = _sim(PROTOS)
    got = _read(node_string(sim, _node(sim, "GIVEN")))
    assert (got.type, got.def_name, got.fields) == ("Solid", "GIVEN", {"translation": (0.0, 0.1, 0.0), "name": "given"})


@pytest.mark.parametrize("instance, name, proto", [
    ("ROVER", "EYE", "Rover"), ("ROVER", "ARM", "Rover"), ("ROVER", "TOOL", "Rover"), ("ROVER", "PAINT", "Rover"),
    ("ROVER", "CHASSIS", "Rover"), ("SHELF", "BOARD", "Shelf"), ("SHELF", "WOOD", "Shelf"), ("BIG", "BOARD", "Shelf"),
])
def test_a_node_a_proto_body_made_exports_as_the_body_writes_it(instance, name, proto):
    # Webots writes a PROTO's internal node as that node: here the bodies have no IS in these nodes and no
    # template, so the text is the PROTO file's node; a PROTO instance in a body (ARM) as that instance
    sim = _sim(PROTOS)
    node, why = sv.from_proto_def(sim, _node(sim, instance), name)
    assert node is not None, why
    got = _read(node_string(sim, node))
    assert _same_tree(got, _in_body(REPO / "tests" / "protos" / "protodef" / f"{proto}.proto", name))


def _in_body(proto: Path, def_name: str) -> Node:
    """The node of that DEF as the PROTO file's body writes it (our parser on the body's text)."""
    from sensorium.server.world.wbt.parser import Parser, Tokens

    text = proto.read_text()
    body = text[text.index("\n]\n{") + 4:text.rindex("}")]
    return _find_def([Parser(Tokens(body, str(proto)), str(proto), proto_body=True).node(0)], def_name)


BODY = REPO / "tests" / "worlds" / "export_body.wbt"


def _made(sim: Simulation, instance: str, name: str) -> sv.Node:
    node, why = sv.from_proto_def(sim, _node(sim, instance), name)
    assert node is not None, why
    return node


@pytest.mark.parametrize("instance, height, color", [("TALL", 2.0, (0.0, 0.0, 1.0)), ("SHORT", 1.0, (1.0, 0.0, 0.0))])
def test_a_template_bodys_node_names_the_values_its_instance_made(instance, height, color):
    # Post's body (tests/protos/export/Post.proto): CAP at z = height, its sphere height/10, its paint the
    # instance's color through IS, BASE a Holder instance of side height/4 (its other fields at their defaults)
    sim = _sim(BODY)
    cap = _read(node_string(sim, _made(sim, instance, "CAP")))
    assert (cap.type, cap.def_name) == ("Solid", "CAP")
    assert cap.fields["translation"] == (0.0, 0.0, height) and cap.fields["name"] == "cap"
    (shape,) = cap.fields["children"]
    assert shape.fields["appearance"].def_name == "CAP_PAINT"
    assert shape.fields["appearance"].fields == {"baseColor": color, "roughness": 1.0}
    assert (shape.fields["geometry"].type, shape.fields["geometry"].fields) == ("Sphere", {"radius": height / 10})
    paint = _read(node_string(sim, _made(sim, instance, "CAP_PAINT")))
    assert (paint.type, paint.fields) == ("PBRAppearance", {"baseColor": color, "roughness": 1.0})
    base = _read(node_string(sim, _made(sim, instance, "BASE")))
    assert (base.type, base.def_name, base.fields) == ("Holder", "BASE", {"side": height / 4})


def test_a_body_nodes_export_writes_what_a_supervisor_set_inside_it():
    sim = _sim(BODY)
    paint = _made(sim, "TALL", "CAP_PAINT")
    sv.set_field(sim, paint, "baseColor", [0.0, 1.0, 0.0])
    cap = _read(node_string(sim, _made(sim, "TALL", "CAP")))
    assert cap.fields["children"][0].fields["appearance"].fields["baseColor"] == (0.0, 1.0, 0.0)
    assert _read(node_string(sim, paint)).fields["baseColor"] == (0.0, 1.0, 0.0)
    short = _read(node_string(sim, _made(sim, "SHORT", "CAP_PAINT")))      # the other instance's: its own
    assert short.fields["baseColor"] == (1.0, 0.0, 0.0)


def test_exported_proto_instances_read_again_make_the_same_world(tmp_path):
    # the instances as written (their PROTO and fields), in a world of their own, load to the same solids
    sim = _sim(BODY)
    text = "\n".join(node_string(sim, _node(sim, name)) for name in ("TALL", "SHORT"))
    assert text.startswith("DEF TALL Post {\n  translation 1 0 0\n  name \"tall\"\n  height 2\n  color 0 0 1\n}")
    again = tmp_path / "again.wbt"
    again.write_text(f'{HEADER}EXTERNPROTO "{REPO / "tests" / "protos" / "export" / "Post.proto"}"\n'
                     f"WorldInfo {{\n  basicTimeStep 16\n}}\n{text}\n")
    was, now = load_world(BODY).world, load_world(again).world

    def plain(solid) -> object:
        def strip(v):
            if isinstance(v, dict):
                return {k: strip(x) for k, x in v.items() if k != "written_at"}     # (its lines differ)
            return [strip(x) for x in v] if isinstance(v, list) else v
        return strip(solid.model_dump(mode="json"))

    assert len(now.solids) == len(was.solids) == 2
    assert [plain(s) for s in now.solids] == [plain(s) for s in was.solids]
    cap = _read(node_string(Simulation(load_world(again)), _made(Simulation(load_world(again)), "TALL", "CAP")))
    assert cap.fields["translation"] == (0.0, 0.0, 2.0)


def test_a_node_inside_an_imported_solid_exports_as_its_string_writes_it():
    sim = _sim()
    sv.import_nodes(sim, sv.ROOT, "children", -1,
                    'DEF IMP Solid { children [ DEF INNER Solid { translation 0 0 1 name "inner" } ] name "imp" }')
    got = _read(node_string(sim, _node(sim, "INNER")))
    assert (got.def_name, got.fields) == ("INNER", {"translation": (0.0, 0.0, 1.0), "name": "inner"})


def test_a_nested_node_of_a_yaml_world_is_one_line():
    sim = _sim(REPO / "tests" / "worlds" / "supervisor_remove.yaml")
    inside = next(n for n in (sv.node_by_id(sim, i) for i in range(1 << 24, (1 << 24) + 64)
                              if sv.node_from_id(sim, i) is not None) if n.nested)
    with pytest.raises(NotExported, match=r"has no \.wbt text here: the world was not loaded from a \.wbt file$"):
        node_string(sim, inside)


def test_a_robots_material_a_supervisor_set_is_exported_and_saved(tmp_path):
    sim = _sim()
    sv.set_field(sim, _node(sim, "STEEL"), "diffuseColor", [0.25, 0.5, 0.75])
    shape = _read(node_string(sim, _node(sim, "LINK_SHAPE")))
    assert shape.fields["appearance"].fields["material"].fields == {"diffuseColor": (0.25, 0.5, 0.75)}
    assert _read(node_string(sim, _node(sim, "STEEL"))).fields == {"diffuseColor": (0.25, 0.5, 0.75)}
    again = _sim(_save(sim, tmp_path))
    assert sv.get_field(again, _node(again, "STEEL"), "diffuseColor")["value"] == [0.25, 0.5, 0.75]


def test_a_node_in_a_proto_instances_field_exports_as_written_after_the_instance_is_built_again():
    sim = _sim()
    assert _same_tree(_read(node_string(sim, _node(sim, "POST"))), _as_written(WORLD, "POST"))
    holder = _node(sim, "HOLDER")
    sv.set_field(sim, holder, "side", 0.5)                     # the instance built again (a new POST node)
    post = _node(sim, "POST")
    assert _same_tree(_read(node_string(sim, post)), _as_written(WORLD, "POST"))
    assert sv.node_pose(sim, post)["position"] == pytest.approx([-2.0, 0.0, 0.8], abs=1e-15)
    instance = _read(node_string(sim, holder))
    assert instance.fields["side"] == 0.5 and _same_tree(instance.fields["slot"][0], _as_written(WORLD, "POST"))


def test_a_shape_a_supervisor_removed_is_left_out_of_the_text_and_of_a_saved_world(tmp_path):
    # TOP out of TABLE's children (LEG stays, as written); LINK_SHAPE out of LINK's (TOOL stays); LINK's
    # children then hold TOOL only, and a list a removal empties is Webots' default: not written
    sim = _sim()
    paint = _node(sim, "PAINT")
    sv.remove_node(sim, _node(sim, "TOP"))
    sv.remove_node(sim, _node(sim, "LINK_SHAPE"))
    table = _read(node_string(sim, sv.find_node(sim, "TABLE")))
    assert len(table.fields["children"]) == 1 and _same_tree(table.fields["children"][0], _as_written(WORLD, "LEG"))
    link = _read(node_string(sim, _node(sim, "LINK")))
    assert [c.def_name for c in link.fields["children"]] == ["TOOL"]
    arm = _read(node_string(sim, _node(sim, "ARM")))
    assert "LINK_SHAPE" not in node_string(sim, _node(sim, "ARM")) and arm.fields["name"] == "arm"
    saved = _save(sim, tmp_path).read_text()
    assert "DEF TOP" not in saved and "LINK_SHAPE" not in saved and "DEF LEG" in saved and "DEF TOOL" in saved
    with pytest.raises(ValueError, match=rf"^node {paint.id} \(PBRAppearance 'PAINT'\) was removed$"):
        sv.node_by_id(sim, paint.id)
    # a solid whose only Shape was removed: its emptied children not written (Webots' default)
    world = tmp_path / "one.wbt"
    world.write_text(HEADER + "DEF ONE Solid {\n  translation 1 0 0\n  children [\n    DEF S Shape {\n      geometry "
                     "Box {\n        size 1 1 1\n      }\n    }\n  ]\n  name \"one\"\n}\n")
    one = _sim(world)
    sv.remove_node(one, _node(one, "S"))
    assert node_string(one, _node(one, "ONE")) == 'DEF ONE Solid {\n  translation 1 0 0\n  name "one"\n}'


def test_a_body_node_of_a_solid_built_again_or_imported_names_its_new_values():
    # a set of TALL's height builds it again (sim/regenerate.py): its CAP at the new height; an imported
    # Post's CAP at the height its node string gives
    sim = _sim(BODY)
    assert sv.set_field(sim, _node(sim, "TALL"), "height", 3.0, 1) == []
    cap = _read(node_string(sim, _made(sim, "TALL", "CAP")))
    assert cap.fields["translation"] == (0.0, 0.0, 3.0)
    assert cap.fields["children"][0].fields["geometry"].fields == {"radius": 0.3}
    sv.import_nodes(sim, sv.ROOT, "children", -1, 'DEF IMP Post { translation 0 5 0 name "imp" height 4 }')
    cap = _read(node_string(sim, _made(sim, "IMP", "CAP")))
    assert cap.fields["translation"] == (0.0, 0.0, 4.0)
    assert cap.fields["children"][0].fields["appearance"].fields["baseColor"] == (1.0, 0.0, 0.0)


def test_a_body_node_whose_proto_file_is_gone_since_the_load_is_one_line(tmp_path):
    # the PROTOs are read again from their files for such an export: one gone is one line naming it
    (tmp_path / "protos").mkdir()
    for name in ("Post.proto", "Holder.proto"):
        (tmp_path / "protos" / name).write_text((REPO / "tests" / "protos" / "export" / name).read_text())
    world = tmp_path / "body.wbt"
    world.write_text(BODY.read_text().replace("../protos/export/Post.proto", "protos/Post.proto"))
    sim = _sim(world)
    cap = _made(sim, "TALL", "CAP")
    (tmp_path / "protos" / "Post.proto").unlink()
    with pytest.raises(NotExported) as err:
        node_string(sim, cap)
    line = str(err.value)
    assert line.startswith("Solid 'cap'") and "made by the body of PROTO Post" in line and "Post.proto" in line
    assert "\n" not in line
