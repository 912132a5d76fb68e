"""A top-level DEF Pose (or Transform) holding only shapes is a target a Supervisor moves, as Webots'
curriculum supervisors move a ball for a robot's camera to follow: it is kept as a solid without a
boundingObject, so ``getField("translation")``/``"rotation"`` read its values and setting them moves
its shapes for the sensors (here a lidar's middle beam along the x axis, which reads its range)."""

from __future__ import annotations

import pytest
from test_multiprocess import REPO
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "wbt" / "supervisor_marker.wbt"
RADIUS = 0.1


def watcher(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/watcher/robot/{item}", args)


def distance(lv: Live) -> float:
    lv.step(A, "watcher")
    return float(lv.sim.robot("watcher").device("lidar").range_image[0, 1])


def test_a_supervisor_reads_and_moves_a_top_level_pose_and_the_sensor_sees_it_move():
    lv = Live(Simulation(load_world(WORLD)))
    lv.ok(A, "attach", {"robot": "watcher"})
    lv.ok(A, "/watcher/lidar/enable", {"value": 16})
    ball = watcher(lv, "get_from_def", {"name": "BALL"})
    field = {"node": ball["node"], "field": "translation"}
    assert watcher(lv, "get_field", field)["value"] == [1.0, 0.0, 0.05]
    assert distance(lv) == pytest.approx(1.0 - RADIUS, abs=1e-6)
    watcher(lv, "set_field", {**field, "value": [2.5, 0.0, 0.05]})
    assert watcher(lv, "get_field", field)["value"] == [2.5, 0.0, 0.05]
    assert distance(lv) == pytest.approx(2.5 - RADIUS, abs=1e-6)
    watcher(lv, "set_field", {**field, "value": [2.5, 1.0, 0.05]})     # out of the beam: nothing seen
    assert distance(lv) == float("inf")


HEAD = "#VRML_SIM R2023b utf8\nWorldInfo { }\n"


@pytest.mark.parametrize("node, is_solid", [
    ("DEF M Pose { children [ Shape { geometry Box { size 1 1 1 } } ] }", True),
    ("DEF M Transform { children [ Pose { children [ Group { children [ Shape { geometry Sphere { } } ] } ] } ] }",
     True),
    ("DEF M Pose { }", True),                                      # a waypoint a Supervisor reads
    ("Pose { children [ Shape { geometry Sphere { } } ] }", False),  # no DEF: part of the world's shapes
    ("DEF M Transform { scale 2 2 2 children [ Shape { geometry Sphere { } } ] }", False),   # scaled
    ("DEF M Pose { children [ Solid { name \"s\" } ] }", False),     # a solid inside: that solid is the node
    ("DEF M Pose { children [ PointLight { } ] }", False),           # a light inside: the light is
])
def test_which_top_level_poses_become_a_node_of_their_own(node: str, is_solid: bool, tmp_path):
    (tmp_path / "m.wbt").write_text(HEAD + node + "\n")
    world = load_world(tmp_path / "m.wbt")
    assert any(s.def_name == "M" for s in world.world.solids) is is_solid
