"""importSFNodeFromString (C wb_supervisor_field_import_sf_node_from_string) where an SFNode field is empty and
the node would be served: an imported line or point set's coord (a Coordinate) and color (a Color), as written,
then edited item by item as any imported set's lists; a full field, a node of another type, a field not served
here (a Shape's appearance, a joint's endPoint) and a string that does not read are one line, nothing changed.
Python and C (AddressSanitizer, UBSan) on tests/worlds/visual_trail.wbt print the same."""

from __future__ import annotations

import sys

import pytest
from test_multiprocess import REPO, run_paused

from sensorium.server.daemon import supervisor as sv
from sensorium.server.daemon import visuals
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "visual_trail.wbt"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
EXPECTED = ["empty 1 1", "coord Coordinate DOT_POINTS 1 1 3 7 8 9", "color Color 1 0 0.5 3"]


def _dots(sim: Simulation) -> sv.Node:
    sv.import_nodes(sim, sv.ROOT, "children", -1, "DEF DOTS Shape { geometry DEF DOT_SET PointSet { } }")
    node = sv.find_node(sim, "DOT_SET")
    assert node is not None
    return node


def test_an_empty_coord_takes_a_coordinate_read_back_and_edited_as_written():
    sim = Simulation(load_world(WORLD))
    dots = _dots(sim)
    assert sv.get_field(sim, dots, "coord")["value"] == 0
    (coord,) = sv.import_nodes(sim, dots, "coord", 0, "DEF P Coordinate { point [ 1 2 3, 4 5 6 ] }")
    assert coord >= visuals.FIRST_ID and sv.get_field(sim, dots, "coord")["value"] == coord
    node = sv.node_by_id(sim, coord)
    assert (node.type, node.def_name, sv.node_ref(sim, node)["parent"]) == ("Coordinate", "P", dots.id)
    assert sv.find_node(sim, "P") == node and sv.find_node(sim, "DOTS.DOT_SET.P") == node
    assert sv.get_field(sim, node, "point")["value"] == [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
    sv.change_item(sim, node, "point", "set", 0, [0.5, 0.5, 0.5])
    assert sv.get_field(sim, node, "point")["value"][0] == [0.5, 0.5, 0.5]


@pytest.mark.parametrize("target, field, text, words", [
    ("DOT_SET", "coord", "Coordinate { }", "is not empty"),
    ("DOT_SET", "color", "Coordinate { }", "takes a Color node here, got 'Coordinate'"),
    ("DOTS", "appearance", "Appearance { }", "read-only here"),
    ("DOT_SET", "color", "Color { color [ 1 0", "node string:"),
    ("DOT_SET", "color", "Color { } Color { }", "exactly one node"),
    ("DOT_SET", "color", "Color { color [ 2 0 0 ] }", "[0, 1]"),
    ("DOT_SET", "color", "Color { color [ " + "0 0 0, " * 100_001 + "] }", "100,000"),
])
def test_what_is_not_imported_is_one_line_and_changes_nothing(target, field, text, words):
    sim = Simulation(load_world(WORLD))
    dots = _dots(sim)
    sv.import_nodes(sim, dots, "coord", 0, "Coordinate { }")
    node = sv.find_node(sim, target)
    assert node is not None
    before = sv.get_field(sim, node, field)["value"]
    count, next_id = len(sv._visuals(sim).nodes), sv._visuals(sim).next_id
    with pytest.raises(ValueError) as err:
        sv.import_nodes(sim, node, field, 0, text)
    line = str(err.value)
    assert words in line and "\n" not in line, line
    assert sv.get_field(sim, node, field)["value"] == before
    assert (len(sv._visuals(sim).nodes), sv._visuals(sim).next_id) == (count, next_id)


def test_a_robots_joint_end_point_is_read_only_here():
    sim = Simulation(load_world(REPO / "tests" / "worlds" / "nested_nodes.wbt"))
    joint = next(sv.node_by_id(sim, c) for c in sv.get_field(sim, sv.find_node(sim, "ROVER"), "children")["value"]
                 if sv.node_by_id(sim, c).type == "HingeJoint")
    with pytest.raises(ValueError, match="read-only here"):
        sv.import_nodes(sim, joint, "endPoint", 0, "Solid { }")


def _check(err: str) -> None:
    assert "not served" not in err and "Sanitizer" not in err and "runtime error" not in err, err
    lines = [x for x in err.splitlines() if x.startswith("Error: wb_supervisor_field_import_sf_node_from_string(): ")]
    assert len(lines) == 4 and err.count("Error:") == 4, err
    assert "is not empty" in lines[0] and "takes a Color node" in lines[1] and "read-only here" in lines[2], err
    assert "node string:1:" in lines[3], err


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_imports_into_an_empty_slot(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "supervisor_sf_import.py", "drawer")
    assert ctl.out == EXPECTED
    _check(ctl.stderr())


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_imports_the_same(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_sf_import.c")
    ctl = run_paused(WORLD, tmp_path, exe, "drawer", env=SAN_ENV)
    assert ctl.out == EXPECTED
    _check(ctl.stderr())
