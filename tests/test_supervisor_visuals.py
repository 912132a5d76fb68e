"""A Supervisor importing visual nodes at the root (Webots' draw-trail pattern; tests/worlds/visual_trail.wbt
explains the scene): a Shape holding an IndexedLineSet is imported, its nodes are Supervisor nodes (ids,
DEFs inside it, types, fields read back as written or Webots' defaults), its points and indices are set,
inserted and removed, and no sensor sees it; a Box Shape imported is seen by the lidar and the range finder
bit for bit as the same Shape written in the world file, and vanishes when removed. Python and C
controllers do the whole pattern for 50 steps."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _serve import run_controller, sensorium
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_c_client import sanitized_controller
from test_multiprocess import REPO

from sensorium.server.daemon import supervisor as sv
from sensorium.server.daemon import visuals
from sensorium.server.sim.imports import ImportRefused
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "visual_trail.wbt"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
N = 5
TRAIL = ("DEF TRAIL Shape { appearance Appearance { material Material { diffuseColor 0 1 0 emissiveColor 0 1 0 } } "
         "geometry DEF TRAIL_LINE_SET IndexedLineSet { coord Coordinate { point [ " + ", ".join(["0 0 0"] * N)
         + " ] } coordIndex [ " + " ".join(["0 0 -1"] * N) + " ] } }")
BOX = "DEF BLOCK Shape { appearance PBRAppearance { baseColor 1 0 0 } geometry Box { size 0.2 1 0.6 } }"


def _sim(path: Path = WORLD) -> Simulation:
    sim = Simulation(load_world(path))
    sim.device("drawer/lidar").enable(16)
    sim.device("drawer/depth").enable(16)
    return sim


def _readings(sim: Simulation) -> tuple[np.ndarray, np.ndarray]:
    sim.run(1)
    return (np.array(sim.device("drawer/lidar").range_image, dtype=np.float64),
            np.array(sim.device("drawer/depth").range_image, dtype=np.float64))


def _import(sim: Simulation, text: str) -> int:
    (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, text)
    return node


def field(sim: Simulation, node: int, name: str):
    return sv.get_field(sim, sv.node_by_id(sim, node), name)["value"]


def change(sim: Simulation, node: int, name: str, op: str, index: int, value=None) -> None:
    sv.change_item(sim, sv.node_by_id(sim, node), name, op, index, value)


def test_a_trail_shape_and_its_nodes_are_supervisor_nodes_read_as_written():
    sim = _sim()
    root = _import(sim, TRAIL)
    trail = sv.find_node(sim, "TRAIL")
    line_set = sv.find_node(sim, "TRAIL_LINE_SET")
    assert trail is not None and line_set is not None
    assert (trail.id, trail.type, trail.def_name) == (root, "Shape", "TRAIL")
    assert sv.find_node(sim, "TRAIL.TRAIL_LINE_SET") == line_set          # a dotted path through its fields
    assert line_set.type == "IndexedLineSet" and line_set.id >= visuals.FIRST_ID
    assert sv.node_ref(sim, line_set)["parent"] == root
    assert root in [n.id for n in sv.root_children(sim)]
    appearance = field(sim, root, "appearance")
    material = field(sim, appearance, "material")
    assert sv.node_by_id(sim, material).type == "Material"
    assert field(sim, material, "diffuseColor") == [0.0, 1.0, 0.0]        # as written
    assert field(sim, material, "emissiveColor") == [0.0, 1.0, 0.0]
    assert field(sim, material, "shininess") == pytest.approx(0.2)         # Webots' default
    assert field(sim, root, "castShadows") is True
    coord = field(sim, line_set.id, "coord")
    assert field(sim, coord, "point") == [[0.0, 0.0, 0.0]] * N
    assert field(sim, line_set.id, "coordIndex") == [0, 0, -1] * N
    assert field(sim, line_set.id, "color") == 0                           # NULL
    assert sv.get_field(sim, trail, "translation") == {"type": "", "value": [], "absent": True}    # Webots' neither


def test_points_and_indices_are_set_inserted_removed_and_read_back_and_no_sensor_sees_them():
    sim = _sim()
    before = _readings(sim)
    root = _import(sim, TRAIL)
    line_set = sv.find_node(sim, "TRAIL_LINE_SET").id
    coord = field(sim, line_set, "coord")
    change(sim, coord, "point", "set", 1, [0.5, -0.25, 3.0])
    change(sim, coord, "point", "set", -1, [1.0, 2.0, 3.0])               # negative: from the end
    change(sim, coord, "point", "insert", 0, [9.0, 8.0, 7.0])
    change(sim, coord, "point", "insert", -1, [4.0, 4.0, 4.0])            # -1: after the last
    change(sim, coord, "point", "remove", 2)
    assert field(sim, coord, "point") == [[9.0, 8.0, 7.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                                          [1.0, 2.0, 3.0], [4.0, 4.0, 4.0]]
    change(sim, line_set, "coordIndex", "set", 0, 3)
    change(sim, line_set, "coordIndex", "remove", -1)
    assert field(sim, line_set, "coordIndex") == [3, 0, -1] + [0, 0, -1] * (N - 2) + [0, 0]
    lidar, depth = _readings(sim)
    assert np.array_equal(lidar, before[0]) and np.array_equal(depth, before[1])
    assert root in [n.id for n in sv.root_children(sim)]


@pytest.mark.parametrize("name, op, index, value, expected", [
    ("point", "set", 5, [0, 0, 0], "out-of-bound index 5 (should be between -5 and 4)"),
    ("point", "insert", 7, [0, 0, 0], "out-of-bound index 7 (should be between -6 and 5)"),
    ("point", "remove", -6, None, "out-of-bound index -6"),
    ("point", "set", 0, [0, 0], "takes 3 numbers"),
    ("point", "set", 0, [0, math.nan, 0], "must be finite"),
    ("point", "set", 0, [0, 1e9, 0], "within"),
    ("point", "set", 0, 3, "takes 3 numbers"),
])
def test_bad_item_changes_are_one_line_and_change_nothing(name, op, index, value, expected):
    sim = _sim()
    _import(sim, TRAIL)
    coord = field(sim, sv.find_node(sim, "TRAIL_LINE_SET").id, "coord")
    was = field(sim, coord, name)
    with pytest.raises(ValueError) as err:
        change(sim, coord, name, op, index, value)
    assert expected in str(err.value) and "\n" not in str(err.value)
    assert field(sim, coord, name) == was


def test_other_fields_are_read_only_with_one_line():
    sim = _sim()
    root = _import(sim, TRAIL)
    line_set = sv.find_node(sim, "TRAIL_LINE_SET")
    material = field(sim, field(sim, root, "appearance"), "material")
    for node, name, value in ((material, "diffuseColor", [1.0, 0.0, 0.0]), (line_set.id, "colorPerVertex", False)):
        with pytest.raises(ValueError, match="read-only here") as err:
            sv.set_field(sim, sv.node_by_id(sim, node), name, value)
        assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="an index is a whole number from -1"):
        change(sim, line_set.id, "coordIndex", "set", 0, -2)
    assert field(sim, line_set.id, "coordIndex")[0] == 0
    with pytest.raises(ValueError, match="only the node at the root"):
        sv.remove_node(sim, sv.node_by_id(sim, material))
    with pytest.raises(ValueError, match="read-only"):        # the root's own list: Webots' skyColor's way
        sv.change_item(sim, sv.ROOT, "children", "remove", 0, None)


def test_an_imported_box_shape_is_seen_as_the_same_shape_in_the_world_file(tmp_path):
    bare = _sim()
    nothing = _readings(bare)
    written = tmp_path / "written.wbt"
    written.write_text(WORLD.read_text() + BOX + "\n")
    want = _readings(_sim(written))
    assert float(want[1][3, 4]) == pytest.approx(1.9, abs=1e-6)             # the face at x = -0.1, 1.9 m ahead
    assert not np.array_equal(want[0], nothing[0])
    node = _import(bare, BOX)
    got = _readings(bare)
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])      # bit for bit
    assert sv.find_node(bare, "BLOCK").type == "Shape"
    assert field(bare, field(bare, node, "geometry"), "size") == [0.2, 1.0, 0.6]
    sv.remove_node(bare, sv.node_by_id(bare, node))
    gone = _readings(bare)
    assert np.array_equal(gone[0], nothing[0]) and np.array_equal(gone[1], nothing[1])
    assert sv.find_node(bare, "BLOCK") is None
    with pytest.raises(ValueError, match="was removed"):
        sv.node_by_id(bare, node)


def test_a_group_of_shapes_is_imported_and_a_group_of_shapes_and_a_light_is_not():
    sim = _sim()
    node = _import(sim, "DEF G Group { children [ Shape { geometry Box { size 0.2 1 0.6 } } "
                        "DEF P Pose { translation 0 0 1 children [ Shape { geometry PointSet { coord Coordinate { "
                        "point [ 1 2 3 ] } } } ] } ] }")
    assert sv.node_by_id(sim, node).type == "Group"
    inner = field(sim, node, "children")
    assert [sv.node_by_id(sim, i).type for i in inner] == ["Shape", "Pose"]
    assert field(sim, inner[1], "translation") == [0.0, 0.0, 1.0]
    assert float(_readings(sim)[1][3, 4]) == pytest.approx(1.9, abs=1e-6)
    with pytest.raises(ImportRefused, match="not importable here"):
        sim.import_nodes("Group { children [ Shape { geometry Box { } } PointLight { } ] }")


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.sampled_from(["set", "insert", "remove"]), st.sampled_from(["point", "coordIndex"]),
                          st.integers(-12, 12),
                          st.one_of(st.none(), st.integers(-3, 2**31), st.floats(allow_nan=True),
                                    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4))),
                max_size=25))
def test_fuzzed_item_changes_keep_the_lists_well_formed(ops):
    sim = _sim()
    _import(sim, TRAIL)
    line_set = sv.find_node(sim, "TRAIL_LINE_SET").id
    coord = field(sim, line_set, "coord")
    for op, name, index, value in ops:
        node = coord if name == "point" else line_set
        was = field(sim, node, name)
        try:
            change(sim, node, name, op, index, value)
        except ValueError as exc:
            assert "\n" not in str(exc)
            assert field(sim, node, name) == was                    # nothing changed
    for p in field(sim, coord, "point"):
        assert len(p) == 3 and all(math.isfinite(v) for v in p)
    assert all(isinstance(i, int) and -1 <= i < 2**31 for i in field(sim, line_set, "coordIndex"))


def _expected_lines(lines: list[str]) -> None:
    steps = 50
    assert lines[0] == "nodes Shape IndexedLineSet Coordinate 1 60 180"
    assert lines[1] == "material Material 0 1 0 0.2"
    assert lines[2] == "same 1 1"
    values = [float(v) for v in lines[3].split()[1:]]
    want = [x for k in range(steps) for x in (math.cos(0.1 * k), 3 + math.sin(0.1 * k), 0.1)]
    assert values == pytest.approx(want, abs=1e-12)
    indices = [int(v) for v in lines[4].split()[1:]]
    assert indices == [x for k in range(1, steps) for x in (k - 1, k, -1)] + [0, 0, -1]
    assert lines[5:] == ["edited 60 9 8 7 1 3 0.1 181 5", "kept 60 0", "removed 1 1"]


@pytest.mark.slow
def test_a_python_supervisor_draws_a_trail() -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "visual_trail.py")), robot="drawer")
    _expected_lines(lines)
    assert err.count("Error:") == 2, err                       # the two bad requests, one line each


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "visual_trail.c")


@pytest.mark.slow
def test_a_c_supervisor_draws_the_same_trail(c_controller: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [c_controller], env=SAN_ENV, robot="drawer")
    assert "Sanitizer" not in err and "runtime error" not in err, err
    _expected_lines(lines)
    assert err.count("Error:") == 2, err


def test_a_simulation_reset_removes_an_imported_trail_with_the_nodes_inside_it():
    sim = _sim()
    _import(sim, TRAIL)
    inner = sv.find_node(sim, "TRAIL_LINE_SET").id
    sim.reset()
    assert sv.find_node(sim, "TRAIL") is None and sv.find_node(sim, "TRAIL_LINE_SET") is None
    assert sv.node_from_id(sim, inner) is None
    again = _import(sim, TRAIL)                            # new ids, never the removed ones
    assert sv.find_node(sim, "TRAIL").id == again and sv.find_node(sim, "TRAIL_LINE_SET").id > inner


def test_an_imported_shapes_colour_is_set_as_the_world_files_shapes_are(tmp_path):
    """Through the appearance path: the PBRAppearance's baseColor set, the camera sees the box as if the
    string had said the new colour (bit for bit against the world file with it)."""
    sim = _sim()
    sim.device("drawer/cam").enable(16)
    node = _import(sim, BOX)
    sim.run(1)
    red = sim.device("drawer/cam").image.copy()
    pbr = field(sim, node, "appearance")
    assert field(sim, pbr, "baseColor") == [1.0, 0.0, 0.0]
    sv.set_field(sim, sv.node_by_id(sim, pbr), "baseColor", [0.2, 0.4, 0.6])
    assert field(sim, pbr, "baseColor") == [0.2, 0.4, 0.6]
    sim.run(1)
    got = sim.device("drawer/cam").image.copy()
    written = tmp_path / "written.wbt"
    written.write_text(WORLD.read_text() + BOX.replace("baseColor 1 0 0", "baseColor 0.2 0.4 0.6") + "\n")
    ref = _sim(written)
    ref.device("drawer/cam").enable(16)
    ref.run(1)
    want = ref.device("drawer/cam").image
    assert not np.array_equal(got, red) and np.array_equal(got, want)
    with pytest.raises(ValueError, match=r"must be in \[0, 1\]"):
        sv.set_field(sim, sv.node_by_id(sim, pbr), "baseColor", [2.0, 0.0, 0.0])
    assert field(sim, pbr, "baseColor") == [0.2, 0.4, 0.6]
