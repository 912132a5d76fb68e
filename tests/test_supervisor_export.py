"""exportString, worldSave and removeSF (daemon/export.py, supervisor.remove_sf) on our own worlds.

tests/worlds/export_world.wbt: the robot "probe" at the origin looks along +x with a distance sensor 0.05 m
ahead of its origin (lookup 0..5 m -> 0..5); the 0.2 m box BOX stands at x = 2 (its near face at 1.9 unturned).
A moved box, a robot set where a Supervisor put it, a light's field set: each export writes the value now; a
field set back to Webots' default is left out; an export imported again is a node with the same fields; a
saved world loads again and gives the readings the running world gives."""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import pytest
from test_multiprocess import run_paused
from test_supervisor_import import _wbt_world

from sensorium.server.daemon import supervisor as sv
from sensorium.server.daemon.export import NotExported, node_string, world_string
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world
from sensorium.server.world.wbt.parser import parse_wbt

REPO = Path(__file__).resolve().parent.parent
WORLD = REPO / "tests" / "worlds" / "export_world.wbt"
HEADER = "#VRML_SIM R2023b utf8\n"


def _sim(world: Path = WORLD) -> Simulation:
    return Simulation(load_world(world))


def _node(sim: Simulation, name: str) -> sv.Node:
    node = sv.find_node(sim, name)
    assert node is not None, name
    return node


def _read(text: str):
    """The one node of an exported string, parsed as a world file's top-level node."""
    (node,) = parse_wbt(HEADER + text).nodes
    return node


def _ds(sim: Simulation) -> float:
    return _ds_of(sim, "probe/ds")


def _ds_of(sim: Simulation, device: str = "r/ds") -> float:
    ds = sim.device(device)
    ds.enable(16)
    sim.step()
    return float(ds.value)


def test_an_unmoved_solid_exports_as_written():
    sim = _sim()
    got = _read(node_string(sim, _node(sim, "BOX")))
    assert (got.def_name, got.type) == ("BOX", "Solid")
    assert got.fields["translation"] == (2.0, 0.0, 0.1) and got.fields["rotation"] == (0.0, 0.0, 1.0, 0.5)
    assert got.fields["name"] == "box" and got.fields["boundingObject"].fields["size"] == (0.2, 0.2, 0.2)
    shape, pose = got.fields["children"]
    assert pose.fields["children"][0].fields["appearance"] is shape.fields["appearance"]    # USE BLUE read back


def test_a_moved_solid_exports_its_pose_now_and_a_default_pose_is_left_out():
    sim = _sim()
    box = _node(sim, "BOX")
    sv.set_field(sim, box, "translation", [1.25, -0.5, 0.1])
    sv.set_field(sim, box, "rotation", [0.0, 0.0, 1.0, 1.0])
    got = _read(node_string(sim, box))
    assert got.fields["translation"] == (1.25, -0.5, 0.1)
    assert got.fields["rotation"] == pytest.approx((0.0, 0.0, 1.0, 1.0), abs=1e-15)
    sv.set_field(sim, box, "translation", [0.0, 0.0, 0.0])
    sv.set_field(sim, box, "rotation", [0.0, 0.0, 1.0, 0.0])
    got = _read(node_string(sim, box))
    assert "translation" not in got.fields and "rotation" not in got.fields, got.fields


def test_a_robot_and_a_light_export_the_values_a_supervisor_set():
    sim = _sim()
    probe, lamp = _node(sim, "PROBE"), _node(sim, "LAMP")
    sv.set_field(sim, probe, "translation", [0.5, 0.25, 0.0])
    sv.set_field(sim, probe, "customData", "set")
    sv.set_field(sim, lamp, "on", False)
    sv.set_field(sim, lamp, "intensity", 1.0)              # Webots' default: not written
    robot = _read(node_string(sim, probe))
    assert list(robot.fields)[:2] == ["translation", "name"]       # a pose field not written goes first
    assert robot.fields["translation"] == (0.5, 0.25, 0.0) and robot.fields["customData"] == "set"
    assert robot.fields["children"][0].fields["lookupTable"] == [0.0, 0.0, 0.0, 5.0, 5.0, 0.0]
    light = _read(node_string(sim, lamp))
    assert light.fields == {"location": (0.0, 0.0, 3.0), "on": False}


def test_an_export_imported_again_is_a_node_with_the_same_fields():
    sim = _sim()
    box = _node(sim, "BOX")
    sv.set_field(sim, box, "translation", [1.0, 0.0, 0.1])
    sv.set_field(sim, box, "rotation", [0.0, 0.0, 1.0, 0.0])
    text = node_string(sim, box)
    assert _ds(sim) == pytest.approx(0.85, abs=1e-9)           # its face at x = 0.9, the sensor at 0.05
    sv.remove_node(sim, box)
    assert _ds(sim) == pytest.approx(5.0, abs=1e-9)            # nothing in range
    (new,) = sv.import_nodes(sim, sv.ROOT, "children", -1, text)
    clone = sv.node_by_id(sim, new)
    assert (clone.type, clone.def_name, clone.name) == ("Solid", "BOX", "box(1)")    # a removed solid's name stays taken
    for field in ("translation", "rotation", "model", "radarCrossSection"):
        assert sv.get_field(sim, clone, field)["value"] == _value_of(text, field)
    assert _ds(sim) == pytest.approx(0.85, abs=1e-9)
    again = _read(node_string(sim, clone))                   # the clone exports as the node it came from, renamed
    assert {**again.fields, "name": "box"}.keys() == _read(text).fields.keys() and again.fields["name"] == "box(1)"


def _value_of(text: str, field: str):
    written = _read(text).fields.get(field)
    default = {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 1.0, 0.0], "model": "", "radarCrossSection": 0.0}
    return list(written) if isinstance(written, tuple) else default[field] if written is None else written


def test_a_saved_world_loads_again_and_gives_the_same_readings(tmp_path):
    sim = _sim()
    box = _node(sim, "BOX")
    sv.set_field(sim, box, "translation", [1.5, 0.0, 0.1])
    sv.set_field(sim, box, "rotation", [0.0, 0.0, 1.0, math.pi / 2])
    sv.import_nodes(sim, sv.ROOT, "children", -1,
                    'DEF POST Solid { translation 3 0 0.1 name "post" boundingObject Box { size 0.2 2 0.2 } }')
    sv.remove_node(sim, _node(sim, "LAMP"))
    saved = tmp_path / "saved.wbt"
    saved.write_text(world_string(sim))
    again = _sim(saved)
    assert [(n.type, n.def_name) for n in sv.root_children(again)] == \
        [(n.type, n.def_name) for n in sv.root_children(sim)] == \
        [("WorldInfo", ""), ("Viewpoint", ""), ("Robot", "PROBE"), ("Solid", "BOX"), ("Solid", "POST")]
    assert _ds(again) == pytest.approx(_ds(sim), abs=1e-12)
    assert _ds(again) == pytest.approx(1.35, abs=1e-9)     # the turned cube's face at x = 1.4
    assert sv.get_field(again, _node(again, "BOX"), "translation")["value"] == [1.5, 0.0, 0.1]
    assert world_string(again) == world_string(sim)


def test_shapes_outside_any_solid_are_saved_as_written_and_a_robot_without_controller_stays_so(tmp_path):
    world = tmp_path / "shapes.wbt"
    world.write_text(HEADER + "WorldInfo {\n}\nShape {\n  geometry Box {\n    size 0.2 4 1\n  }\n}\n"
                     'Robot {\n  translation -1 0 0\n  name "r"\n  children [\n    DistanceSensor {\n      name "ds"\n'
                     "      lookupTable [\n        0 0 0\n        5 5 0\n      ]\n    }\n  ]\n}\n")
    sim = _sim(world)
    assert [(n.type, n.name) for n in sv.root_children(sim)][2:] == [("Shape", ""), ("Robot", "r"), ("Solid", "shapes")]
    text = world_string(sim)
    assert text == HEADER + "\n" + world.read_text()[len(HEADER):].replace("WorldInfo {\n}\n", "WorldInfo {\n}\nViewpoint {\n}\n")
    saved = tmp_path / "saved.wbt"
    saved.write_text(text)
    again = _sim(saved)
    assert _ds_of(again) == _ds_of(sim) == 5.0     # a shape without boundingObject: no distance sensor meets it (Webots)
    with pytest.raises(NotExported, match="shapes outside any solid"):
        node_string(sim, sv.root_children(sim)[-1])


def test_a_proto_instance_exports_as_the_instance_with_its_fields_now(tmp_path):
    sim = _sim(_wbt_world(tmp_path))
    sv.import_nodes(sim, sv.ROOT, "children", -1, "DEF C Crate { translation 1.6 0 0.25 }")
    crate = _node(sim, "C")
    sv.set_field(sim, crate, "translation", [1.0, 0.5, 0.25])
    got = _read(node_string(sim, crate))
    assert (got.type, got.fields) == ("Crate", {"translation": (1.0, 0.5, 0.25)})
    text = world_string(sim)
    assert text.startswith(HEADER + 'IMPORTABLE EXTERNPROTO "protos/Crate.proto"\nEXTERNPROTO "protos/Drone.proto"\n')
    saved = tmp_path / "saved.wbt"
    saved.write_text(text)
    assert sv.get_field(_sim(saved), _node(_sim(saved), "C"), "translation")["value"] == [1.0, 0.5, 0.25]


def test_the_root_is_not_exported_one_line():
    sim = _sim()
    with pytest.raises(NotExported, match="^the root node is not exported: worldSave writes the whole world$"):
        node_string(sim, sv.ROOT)


def test_a_yaml_world_has_no_wbt_text():
    sim = _sim(REPO / "tests" / "worlds" / "supervisor_remove.yaml")
    with pytest.raises(NotExported, match=r"the world was not loaded from a \.wbt file"):
        world_string(sim)
    with pytest.raises(NotExported, match=r"has no \.wbt text here: the world was not loaded from a \.wbt file"):
        node_string(sim, sv.root_children(sim)[-1])


# ---------------------------------------------------------------------- removeSF

TRAIL = REPO / "tests" / "worlds" / "visual_trail.wbt"


def test_remove_sf_empties_a_point_sets_coord_and_it_takes_a_node_again():
    sim = _sim(TRAIL)
    sv.import_nodes(sim, sv.ROOT, "children", -1, "DEF DOTS Shape { geometry DEF SET PointSet { } }")
    dots = _node(sim, "SET")
    (coord,) = sv.import_nodes(sim, dots, "coord", 0, "DEF P Coordinate { point [ 1 2 3 ] }")
    sv.remove_sf(sim, dots, "coord")
    assert sv.get_field(sim, dots, "coord")["value"] == 0 and sv.find_node(sim, "P") is None
    with pytest.raises(ValueError, match=f"^node {coord} was removed$"):
        sv.node_by_id(sim, coord)
    sv.remove_sf(sim, dots, "coord")                        # empty: nothing happens (Webots)
    (again,) = sv.import_nodes(sim, dots, "coord", 0, "Coordinate { point [ 4 5 6 ] }")
    assert again > coord and sv.get_field(sim, sv.node_by_id(sim, again), "point")["value"] == [[4.0, 5.0, 6.0]]


@pytest.mark.parametrize("target, field, words", [
    ("DOTS", "appearance", "is read-only here: removeSF takes the node out of the coord or color"),
    ("DOTS", "castShadows", "(SFBool) of Shape 'DOTS'"),
    ("DOTS", "nothing", "removeSF takes an SFNode field"),
])
def test_remove_sf_elsewhere_is_one_line_and_changes_nothing(target, field, words):
    sim = _sim(TRAIL)
    sv.import_nodes(sim, sv.ROOT, "children", -1,
                    "DEF DOTS Shape { appearance Appearance { } geometry DEF SET PointSet { } }")
    node = _node(sim, target)
    before, count = sv.get_field(sim, node, field), len(sv._visuals(sim).nodes)
    with pytest.raises(ValueError) as err:
        sv.remove_sf(sim, node, field)
    assert words in str(err.value) and "\n" not in str(err.value), str(err.value)
    assert sv.get_field(sim, node, field) == before and len(sv._visuals(sim).nodes) == count


def test_remove_sf_on_a_robots_joint_end_point_is_read_only_here():
    sim = _sim(REPO / "tests" / "worlds" / "nested_nodes.wbt")
    joint = next(sv.node_by_id(sim, c) for c in sv.get_field(sim, _node(sim, "ROVER"), "children")["value"]
                 if sv.node_by_id(sim, c).type == "HingeJoint")
    with pytest.raises(ValueError, match="read-only here"):
        sv.remove_sf(sim, joint, "endPoint")


# ---------------------------------------------------------------------- the clients (processes)

EXPECTED_HEAD = ["DEF BOX Solid {", "  translation 1 0 0.1"]
CLIENT_LINES = ["clone BOX box(1) 1 0 0.1", "save 0 0 1", "removed 1", "again 2", "inside DistanceSensor {"]


def _client_check(ctl, saved: Path) -> None:
    out, err = ctl.out, ctl.stderr()
    assert out[:2] == EXPECTED_HEAD and "  rotation" not in out[2] and out[-5:] == CLIENT_LINES, out
    assert "  children [" in out and '  name "box"' in out
    errors = [line for line in err.splitlines() if line.startswith("Error")]
    assert errors == [
        "Error: wb_supervisor_world_save(): the world file is not overwritten here: name the file to write (a departure "
        "from Webots, which overwrites the world file it loaded).",
        "Error: the target file given to wb_supervisor_world_save() should have the '.wbt' extension.",
        errors[2], errors[3]], err
    # (the C library writes the server's error code before its line)
    assert errors[2].startswith("Error: wb_supervisor_field_remove_sf(): ") and "field_remove_sf: field 'appearance' " \
        "(SFNode) of Shape 'DOTS'" in errors[2] and "is read-only here" in errors[2], err
    assert errors[3] == "Error: wb_supervisor_field_remove_sf() called with wrong field type: SFVec3f.", err
    again = _sim(saved)
    assert [n.name for n in sv.root_children(again) if n.type == "Solid"] == ["box", "box(1)"]
    assert sv.get_field(again, _node(again, "BOX"), "translation")["value"] == [1.0, 0.0, 0.1]
    assert _ds(again) == pytest.approx(0.85, abs=1e-9)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_exports_saves_and_removes_sf(tmp_path):
    saved = tmp_path / "saved.wbt"
    ctl = run_paused(WORLD, tmp_path, "supervisor_export.py", "probe", env={**os.environ, "EXPORT_SAVE": str(saved)})
    _client_check(ctl, saved)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_does_the_same(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_export.c")
    saved = tmp_path / "saved.wbt"
    ctl = run_paused(WORLD, tmp_path, exe, "probe", env={**os.environ, "EXPORT_SAVE": str(saved),
                                                        "ASAN_OPTIONS": "detect_leaks=1:exitcode=86",
                                                        "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"})
    _client_check(ctl, saved)
    py = tmp_path / "py"
    py.mkdir()
    assert ctl.out == run_paused(WORLD, py, "supervisor_export.py", "probe",
                                 env={**os.environ, "EXPORT_SAVE": str(py / "saved.wbt")}).out
    assert saved.read_text() == (py / "saved.wbt").read_text()
