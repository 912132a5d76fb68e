"""A Supervisor's importMFNodeFromString into the children of a top-level Solid and of a Pose inside it
(tests/worlds/nested_import.wbt): the nodes become part of the solid, seen where the world file written with
them puts them and moving with it, Supervisor nodes like its others (found by DEF, their translation set,
removable, exported), placed at Webots' position in the children, kept by saveState/loadState and taken out by
simulationReset; one line and nothing changed for what is refused.

Closed forms (the world file's comment places everything): the probe's distance sensor (bounding objects) and
lidar (shapes) look along +x from the origin; the Pose HOLD sits at BASE's translation + (0.5, 0, -1), so a
0.2 m box at HOLD's origin has its near face at x = 2.4 on the ray."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_multiprocess import REPO
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "nested_import.wbt"
BOX = ("DEF BOX Pose { children [ DEF BODY Solid { name \"body\" boundingObject Box { size 0.2 0.2 0.2 } "
       "children [ Shape { geometry Box { size 0.2 0.2 0.2 } } ] } ] }")
NOTHING = (10.0, float("inf"))      # the sensor's range end; the lidar's beam hitting nothing


def _live(path=WORLD) -> Live:
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "probe"})
    bot = lv.sim.robot("probe")
    bot.device("ds").enable(8)
    bot.device("lidar").enable(8)
    return lv


def call(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/probe/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return call(lv, "get_from_def", {"name": name})["node"]


def get(lv: Live, n: int, field: str):
    return call(lv, "get_field", {"node": n, "field": field})["value"]


def put(lv: Live, n: int, field: str, value) -> None:
    call(lv, "set_field", {"node": n, "field": field, "value": value})


def imported(lv: Live, n: int, text: str, position: int = -1) -> list[int]:
    return call(lv, "import_node_from_string", {"node": n, "field": "children", "position": position,
                                                "node_string": text})["value"]


def readings(lv: Live) -> tuple[float, float]:
    lv.step(A, "probe")
    bot = lv.sim.robot("probe")
    return bot.device("ds").value, float(np.asarray(bot.device("lidar").range_image).reshape(-1)[0])


def test_a_box_imported_into_a_pose_is_seen_moved_removed_and_reset():
    lv = _live()
    base, hold, cap = node(lv, "BASE"), node(lv, "HOLD"), node(lv, "CAP")
    assert readings(lv) == NOTHING
    (box,) = imported(lv, hold, BOX)
    assert node(lv, "BOX") == box and node(lv, "BASE.HOLD.BOX") == box
    body = node(lv, "BOX.BODY")
    assert call(lv, "get_from_id", {"id": box})["parent"] == hold and get(lv, hold, "children") == [box]
    assert get(lv, box, "children") == [body] and get(lv, body, "name") == "body"
    assert node(lv, "CAP") == cap and node(lv, "HOLD") == hold      # the solid's other nodes keep their ids
    ds, lidar = readings(lv)
    assert ds == pytest.approx(2.4, abs=1e-12) and lidar == pytest.approx(2.4, abs=1e-6)
    assert call(lv, "get_node_pose", {"node": box})["position"] == pytest.approx([2.5, 0.0, 0.0], abs=1e-15)
    # its translation set: the box 0.3 m back, its face at 2.1
    put(lv, box, "translation", [-0.3, 0.0, 0.0])
    assert get(lv, box, "translation") == [-0.3, 0.0, 0.0]
    ds, lidar = readings(lv)
    assert ds == pytest.approx(2.1, abs=1e-12) and lidar == pytest.approx(2.1, abs=1e-6)
    # it rides its solid: BASE 1 m nearer, the face at 1.1
    put(lv, base, "translation", [1.0, 0.0, 1.0])
    ds, lidar = readings(lv)
    assert ds == pytest.approx(1.1, abs=1e-12) and lidar == pytest.approx(1.1, abs=1e-6)
    assert "DEF BOX Pose {\n          translation -0.3 0 0\n" in call(lv, "node_export_string", {"node": base})["value"]
    # the world file written with it reads the same
    text = WORLD.read_text().replace("  translation 2 0 1\n", "  translation 1 0 1\n").replace(
        "      translation 0.5 0 -1\n", "      translation 0.5 0 -1\n      children [ "
        + BOX.replace("DEF BOX Pose {", "DEF BOX Pose { translation -0.3 0 0") + " ]\n")
    twin_path = WORLD.parent / "_nested_import_twin.wbt"
    try:
        twin_path.write_text(text)
        assert readings(_live(twin_path)) == readings(lv)
    finally:
        twin_path.unlink()
    # removed: nothing on the ray again; its id and its solid's read as removed
    call(lv, "remove_node", {"node": box})
    assert readings(lv) == NOTHING and get(lv, hold, "children") == [] and node(lv, "BOX") == 0
    message = lv.err(A, "/probe/robot/get_field", {"node": body, "field": "name"}, ErrorCode.INVALID_ARGUMENT)
    assert "removed" in message and "\n" not in message
    # imported again, then simulationReset takes it out and BASE back where it loaded
    (again,) = imported(lv, hold, BOX)
    assert again > body and readings(lv)[0] == pytest.approx(1.4, abs=1e-12)
    put(lv, hold, "translation", [0.7, 0.0, -1.0])
    assert readings(lv)[0] == pytest.approx(1.6, abs=1e-12)
    call(lv, "simulation_reset")
    assert readings(lv) == NOTHING and get(lv, hold, "children") == [] and node(lv, "BOX") == 0
    assert get(lv, hold, "translation") == [0.5, 0.0, -1.0] and get(lv, base, "children") == [cap, hold]
    (third,) = imported(lv, hold, BOX)                # a reset solid takes imports again
    assert readings(lv)[0] == pytest.approx(2.4, abs=1e-12) and third > again


def test_the_position_places_them_among_the_children_as_in_webots():
    lv = _live()
    base, hold, cap = node(lv, "BASE"), node(lv, "HOLD"), node(lv, "CAP")

    def shape(name: str, x: float) -> str:
        return f"DEF {name} Pose {{ translation {x} 0 -1 children [ Shape {{ geometry Box {{ size 0.2 0.2 0.2 }} }} ] }}"

    (a,) = imported(lv, base, shape("A", 3.0), -1)        # after the last
    (b,) = imported(lv, base, shape("B", 2.0), -2)        # before the last
    (c, d) = imported(lv, base, shape("C", 1.0) + "\n" + shape("D", 4.0), 0)     # first, in the string's order
    (e,) = imported(lv, base, shape("E", 5.0), 99)        # past the end: the end
    assert get(lv, base, "children") == [c, d, cap, hold, b, a, e]
    assert [node(lv, n) for n in "ABCDE"] == [a, b, c, d, e]
    text = call(lv, "node_export_string", {"node": base})["value"]
    assert [text.index(f"DEF {n} ") for n in "CD"] + [text.index("DEF CAP"), text.index("DEF HOLD")] + \
        [text.index(f"DEF {n} ") for n in "BAE"] == sorted(text.index(f"DEF {n} ") for n in
                                                           ["C", "D", "CAP", "HOLD", "B", "A", "E"])
    # the nearest of them on the ray: C at BASE's x + 1, its face at 2.9
    assert readings(lv)[1] == pytest.approx(2.9, abs=1e-6)


def test_save_and_load_state_keep_them_at_their_saved_translation():
    lv = _live()
    base, hold = node(lv, "BASE"), node(lv, "HOLD")
    (box,) = imported(lv, hold, BOX)
    call(lv, "save_node_state", {"node": base, "state": "s"})
    put(lv, box, "translation", [-0.3, 0.0, 0.0])
    assert readings(lv)[0] == pytest.approx(2.1, abs=1e-12)
    call(lv, "load_node_state", {"node": base, "state": "s"})
    assert get(lv, hold, "children") == [box] and get(lv, box, "translation") == [0.0, 0.0, 0.0]
    assert readings(lv)[0] == pytest.approx(2.4, abs=1e-12)


@pytest.mark.parametrize("target, field, text, expected", [
    ("HOLD", "children", "Pose { children [ Shape { geometry Box { size 1 1 } ] }",
     "nothing imported: node string:1:"),                                      # does not read
    ("HOLD", "children", "Box { size 0.2 0.2 0.2 }", "node string:1:1: Box is no node"),   # not a child node
    ("HOLD", "children", "# nothing", "nothing imported: node string: no node in it"),
    ("HOLD", "translation", BOX, "field 'translation' of Pose"),             # an SF field, not MFNode
    ("CAP", "children", BOX, "field 'children' of Shape"),                   # a Shape has none
    ("PROBE", "children", BOX, "node string:1:9: a Pose is not imported into a robot here"),  # (it holds a solid)
    ("PROBE", "children", "Solid { boundingObject Box { } }", "a Solid is not imported into a robot here"),
    ("PROBE", "children", "PointLight { }", "a PointLight is not imported into a robot here"),
])
def test_what_is_refused_is_one_line_and_changes_nothing(target, field, text, expected):
    lv = _live()
    (box,) = imported(lv, node(lv, "HOLD"), BOX)
    children = {n: get(lv, node(lv, n), "children") for n in ("BASE", "HOLD")}
    before = readings(lv)
    message = lv.err(A, "/probe/robot/import_node_from_string",
                     {"node": node(lv, target), "field": field, "position": -1, "node_string": text},
                     ErrorCode.INVALID_ARGUMENT)
    assert expected in message and "\n" not in message and "Traceback" not in message, message
    assert {n: get(lv, node(lv, n), "children") for n in ("BASE", "HOLD")} == children
    assert readings(lv) == before and node(lv, "BOX") == box


def test_a_value_corrected_as_webots_corrects_it_is_logged_where_the_string_writes_it():
    lv = _live()
    hold = sv.node_by_id(lv.sim, node(lv, "HOLD"))
    corrected: list[str] = []
    (ball,) = sv.import_nodes(lv.sim, hold, "children", -1,
                              "Pose {\n  children [ Shape { geometry Sphere { radius -1 } } ]\n}", corrected)
    assert corrected == ["node string:2:40: Sphere.radius: -1 is not > 0; using 1 (as Webots does)"]
    # the unit ball at HOLD's origin: its near side at x = 1.5
    assert get(lv, node(lv, "HOLD"), "children") == [ball] and readings(lv)[1] == pytest.approx(1.5, abs=1e-6)


ROVER_WORLD = REPO / "tests" / "worlds" / "nested_nodes.wbt"     # tests/test_supervisor_nested.py's rover
W, R, DT = 2.0, 0.05, 0.032                 # wheel speed (rad/s), radius, basic step (s)
AXLE = 2 * math.hypot(0.1, 0.05)            # Webots' kinematic rule: the wheels' distances from the origin
MARKER = ("DEF MK Transform { translation 0.3 0 0.5 children [ Shape { appearance Appearance { material Material { "
          "diffuseColor 1 0 0 } } geometry Box { size 0.1 0.1 0.1 } } ] }")


def _rover() -> Live:
    lv = Live(Simulation(load_world(ROVER_WORLD)))
    lv.ok(A, "attach", {"robot": "rover"})
    return lv


def rover(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/rover/robot/{item}", args)


def drive(lv: Live, left: float, right: float, steps: int) -> None:
    bot = lv.sim.robot("rover")
    for name, speed in (("left wheel", left), ("right wheel", right)):
        bot.motor(name).set_position(math.inf)
        bot.motor(name).set_velocity(speed)
    for _ in range(steps):
        lv.step(A, "rover")


def test_a_marker_imported_into_its_own_robots_children_rides_it_and_moves_in_its_frame():
    """radar_target_tracker's calls: the robot imports a marker Transform into its own children, finds it as the
    last child, and sets its translation (in the robot's frame) as the robot drives."""
    lv = _rover()
    me = rover(lv, "get_self")["node"]
    before = rover(lv, "get_field", {"node": me, "field": "children"})["value"]
    (mk,) = rover(lv, "import_node_from_string", {"node": me, "field": "children", "position": -1,
                                                  "node_string": MARKER})["value"]
    assert rover(lv, "get_field", {"node": me, "field": "children"})["value"] == [*before, mk]
    found = rover(lv, "get_from_def", {"name": "MK"})
    assert (found["node"], found["parent"]) == (mk, me)
    assert rover(lv, "get_field", {"node": mk, "field": "translation"})["value"] == [0.3, 0.0, 0.5]

    def where() -> list[float]:
        return rover(lv, "get_node_pose", {"node": mk})["position"]

    # the robot at (1, 2) turned a quarter turn: its +x is the world's +y
    assert where() == pytest.approx([1.0, 2.3, 0.5], abs=1e-12)
    drive(lv, W, W, 10)                         # straight ahead W·R·t
    d = W * R * 10 * DT
    assert where() == pytest.approx([1.0, 2.3 + d, 0.5], abs=1e-12)
    drive(lv, -W, W, 5)                         # on the spot: the marker on a circle of 0.3 m about the origin
    yaw = math.pi / 2 + 2 * W * R / AXLE * 5 * DT
    assert where() == pytest.approx([0.3 * math.cos(yaw) + 1.0, 0.3 * math.sin(yaw) + 2.0 + d, 0.5], abs=1e-12)
    # its translation set in the robot's frame, kept there as the robot turns on
    rover(lv, "set_field", {"node": mk, "field": "translation", "value": [0.0, -0.4, 1.0]})
    assert rover(lv, "get_field", {"node": mk, "field": "translation"})["value"] == [0.0, -0.4, 1.0]
    drive(lv, -W, W, 5)
    yaw += 2 * W * R / AXLE * 5 * DT
    assert where() == pytest.approx([0.4 * math.sin(yaw) + 1.0, -0.4 * math.cos(yaw) + 2.0 + d, 1.0], abs=1e-12)
    # removed: out of its robot's children; simulationReset takes another one out too
    rover(lv, "remove_node", {"node": mk})
    assert rover(lv, "get_field", {"node": me, "field": "children"})["value"] == before
    (again,) = rover(lv, "import_node_from_string", {"node": me, "field": "children", "position": 0,
                                                     "node_string": MARKER})["value"]
    assert rover(lv, "get_field", {"node": me, "field": "children"})["value"] == [again, *before]
    rover(lv, "simulation_reset")
    assert rover(lv, "get_field", {"node": me, "field": "children"})["value"] == before
    assert rover(lv, "get_from_def", {"name": "MK"})["node"] == 0


def test_the_robots_camera_sees_its_marker_as_the_world_file_writing_it_there(tmp_path):
    """A robot's own shapes are seen by its camera (Webots); the marker is as one written in its children."""
    written = MARKER.replace("translation 0.3 0 0.5", "translation 0.15 0.6 0.3").replace("diffuse", "emissive")
    text = ROVER_WORLD.read_text()
    assert text.count("  children [\n    DEF MAST Pose {") == 1
    (tmp_path / "twin.wbt").write_text(text.replace("  children [\n    DEF MAST Pose {",
                                                    f"  children [\n    {written}\n    DEF MAST Pose {{"))
    images = []
    for path, imports in ((ROVER_WORLD, True), (tmp_path / "twin.wbt", False)):
        lv = Live(Simulation(load_world(path)))
        lv.ok(A, "attach", {"robot": "rover"})
        if imports:
            rover(lv, "import_node_from_string", {"node": rover(lv, "get_self")["node"], "field": "children",
                                                  "position": -1, "node_string": written})
        lv.sim.robot("rover").device("cam").enable(32)
        drive(lv, W, W, 3)
        images.append(np.asarray(lv.sim.robot("rover").device("cam").image).copy())
    blank = _camera_without_marker()
    assert not np.array_equal(images[1], blank)       # the marker is in view
    assert np.array_equal(images[0], images[1])


def _camera_without_marker() -> np.ndarray:
    lv = _rover()
    lv.sim.robot("rover").device("cam").enable(32)
    drive(lv, W, W, 3)
    return np.asarray(lv.sim.robot("rover").device("cam").image).copy()


def test_a_colour_set_stays_with_its_shape_when_an_import_goes_before_it():
    lv = _live()
    base = node(lv, "BASE")

    def marker(name: str, x: float) -> str:
        return (f"DEF {name} Pose {{ translation {x} 0 -1 children [ Shape {{ appearance Appearance {{ material "
                f"DEF {name}_LOOK Material {{ diffuseColor 1 0 0 }} }} geometry Box {{ size 0.2 0.2 0.2 }} }} ] }}")

    imported(lv, base, marker("M1", 1.0))
    put(lv, node(lv, "M1_LOOK"), "diffuseColor", [0.0, 0.0, 1.0])
    imported(lv, base, marker("M2", 3.0), 0)          # before every shape of the solid
    assert get(lv, node(lv, "M1_LOOK"), "diffuseColor") == [0.0, 0.0, 1.0]
    assert get(lv, node(lv, "M2_LOOK"), "diffuseColor") == [1.0, 0.0, 0.0]
    put(lv, node(lv, "HOLD"), "translation", [0.5, 0.0, -2.0])      # a Pose's set keeps them too
    call(lv, "remove_node", {"node": node(lv, "M2")})
    assert get(lv, node(lv, "M1_LOOK"), "diffuseColor") == [0.0, 0.0, 1.0]


def test_a_nested_solids_children_take_nodes_too():
    """tests/worlds/solid_poses.wbt: the solid INNER, inside TABLE's Transform T, stands at (2.1, 0.5, 0); a box
    imported 0.5 m along its -y sits on the probe's lidar beam, its near face at x = 2.0."""
    from test_supervisor_solid_poses import _live as poses_live
    from test_supervisor_solid_poses import readings as poses_readings

    lv = poses_live()
    inner = node(lv, "INNER")
    was = get(lv, inner, "children")
    (box,) = imported(lv, inner, "DEF NB Pose { translation 0 -0.5 0 children [ Shape { geometry Box { size 0.2 0.2 "
                                 "0.2 } } ] }")
    assert get(lv, inner, "children") == [*was, box] and node(lv, "INNER.NB") == box
    assert poses_readings(lv)[0] == pytest.approx(1.8, abs=1e-6)       # MARKER's face, nearer, still first
    put(lv, node(lv, "TOP"), "translation", [0.0, 0.0, 3.0])            # the marker off the beam
    assert poses_readings(lv)[0] == pytest.approx(2.0, abs=1e-6)
    call(lv, "remove_node", {"node": box})
    assert get(lv, inner, "children") == was and math.isinf(poses_readings(lv)[0])


def test_get_from_def_walks_the_worlds_nodes_a_fixed_number_of_times_whatever_the_robots(tmp_path, monkeypatch) -> None:
    """The robots' riding markers are looked for only where a robot has some: getFromDef in a world of 2 or 40
    robots without markers lists the world's nodes as many times (it listed them once per robot: 66× slower
    at 200 robots)."""
    calls = []
    listed = sv._nodes
    monkeypatch.setattr(sv, "_nodes", lambda sim: calls.append(1) or listed(sim))

    def walks(robots: int) -> int:
        path = tmp_path / f"r{robots}.wbt"
        path.write_text("#VRML_SIM R2025a utf8\nWorldInfo { basicTimeStep 16 }\n" + "".join(
            f'DEF R{i} Robot {{ translation {i} 0 0 name "r{i}" controller "<none>" }}\n' for i in range(robots))
            + 'DEF LAST Solid { name "last" }\n')
        sim = Simulation.from_file(str(path), precision="fast")
        calls.clear()
        assert sv._first_def(sim, "LAST").def_name == "LAST"
        return len(calls)

    assert walks(40) == walks(2)
