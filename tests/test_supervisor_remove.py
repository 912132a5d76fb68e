"""A Supervisor's ``node.remove()`` (Webots' ``wb_supervisor_node_remove``) for top-level solids and
lights, against the closed forms tests/worlds/supervisor_remove.yaml explains: every ray kind
(distance sensor, lidar, range finder, camera recognition, light occlusion) and kinematic contact
stop seeing a removed solid from the next step, light sensors stop counting a removed light; node
ids stay stable (a removed one answers NULL and is never reused); robots and the root are refused;
``simulationReset`` does not bring removed nodes back (Webots' reset matrix: only a world reload does)."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "supervisor_remove.yaml"
BOSS, ROVER, WALL, CRATE, GATE, LAMP, BULB = range(1, 8)      # node ids: robots, solids, lights in world order
# then the nodes Webots always has, which a YAML world gets by default (world/top_nodes.py), at the root's
# children's first two places
WORLD_INFO, VIEWPOINT = 8, 9
SCENERY = [WORLD_INFO, VIEWPOINT]
NULL = {"node": 0, "type": "", "name": "", "def_name": "", "parent": -1, "proto": ""}


def _live(precision: str = "exact", **kw) -> Live:
    """The world in process with the boss attached and its devices enabled (``kw``: Simulation's)."""
    lv = Live(Simulation(load_world(WORLD), precision=precision, **kw))
    lv.ok(A, "attach", {"robot": "boss"})
    for name in ("ds", "lidar", "depth", "cam", "eye", "shaded"):
        lv.sim.device(f"boss/{name}").enable(16)
    lv.sim.device("boss/cam").recognition_enable(16)
    return lv


def boss(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/boss/robot/{item}", args)


def readings(lv: Live) -> dict:
    lv.step(A, "boss", {"duration": 16})
    dev = lv.sim.device
    return {"ds": dev("boss/ds").value, "lidar": np.asarray(dev("boss/lidar").range_image, dtype=np.float64)[0],
            "depth": float(dev("boss/depth").range_image[3, 4]), "eye": dev("boss/eye").value,
            "shaded": dev("boss/shaded").value, "seen": [o.id for o in dev("boss/cam").objects]}


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_every_sensor_stops_seeing_a_removed_solid_at_the_next_step(precision):
    lv = _live(precision)
    before = readings(lv)
    assert before["ds"] == pytest.approx(1.0, abs=1e-9)
    assert before["lidar"][2] == pytest.approx(1.0, abs=1e-6)
    assert before["depth"] == pytest.approx(1.0, abs=1e-6)
    assert before["seen"] == [CRATE]
    assert (before["eye"], before["shaded"]) == (pytest.approx(7.0), pytest.approx(4.0))   # the lamp behind the crate
    assert boss(lv, "remove_node", {"node": CRATE}) == {"success": True}
    after = readings(lv)
    assert after["ds"] == pytest.approx(3.0, abs=1e-9)                    # the wall behind it
    np.testing.assert_allclose(after["lidar"], 3.0 * before["lidar"], rtol=1e-6)
    assert after["depth"] == pytest.approx(3.0, abs=1e-6)
    assert after["seen"] == []                                           # the wall has no recognition colour
    assert (after["eye"], after["shaded"]) == (pytest.approx(7.0), pytest.approx(7.0))   # the lamp now in sight


def test_a_removed_light_is_no_longer_counted():
    lv = _live()
    boss(lv, "remove_node", {"node": CRATE})
    assert readings(lv)["eye"] == pytest.approx(7.0)
    boss(lv, "remove_node", {"node": BULB})                   # its term: 1 / 0.5^2 = 4
    got = readings(lv)
    assert (got["eye"], got["shaded"]) == (pytest.approx(3.0), pytest.approx(3.0))
    boss(lv, "remove_node", {"node": LAMP})
    assert readings(lv)["eye"] == 0.0


def test_ids_stay_stable_and_a_removed_node_answers_null():
    lv = _live()
    children = boss(lv, "get_field", {"node": 0, "field": "children"})["value"]
    assert children == [*SCENERY, BOSS, ROVER, WALL, CRATE, GATE, LAMP, BULB]
    boss(lv, "remove_node", {"node": CRATE})
    boss(lv, "remove_node", {"node": LAMP})
    assert boss(lv, "get_field", {"node": 0, "field": "children"})["value"] == [*SCENERY, BOSS, ROVER, WALL, GATE, BULB]
    assert boss(lv, "get_from_id", {"id": CRATE}) == NULL
    assert boss(lv, "get_from_id", {"id": LAMP}) == NULL
    assert boss(lv, "get_from_def", {"name": "CRATE"}) == NULL
    assert boss(lv, "get_from_def", {"name": "crate"}) == NULL
    assert boss(lv, "get_from_def", {"name": "lamp"}) == NULL
    gate, bulb = boss(lv, "get_from_def", {"name": "GATE"}), boss(lv, "get_from_id", {"id": BULB})
    assert (gate["node"], gate["name"], bulb["node"], bulb["name"]) == (GATE, "gate", BULB, "bulb")
    assert boss(lv, "get_field", {"node": GATE, "field": "translation"})["value"] == [1.1, -2.0, 0.25]
    # the removed node's id: every request on it is one line naming it
    msg = lv.err(A, "/boss/robot/get_field", {"node": CRATE, "field": "translation"}, ErrorCode.INVALID_ARGUMENT)
    assert msg == "get_field: node 4 (Solid 'crate') was removed"
    msg = lv.err(A, "/boss/robot/remove_node", {"node": CRATE}, ErrorCode.INVALID_ARGUMENT)
    assert msg == "remove_node: node 4 (Solid 'crate') was removed"
    assert lv.sim.scene.solid_poses.keys() == {"wall", "gate"}      # what the topics and scene views publish


def test_robots_and_the_root_cannot_be_removed():
    lv = _live()
    msg = lv.err(A, "/boss/robot/remove_node", {"node": ROVER}, ErrorCode.INVALID_ARGUMENT)
    assert msg == ("remove_node: robot 'rover' (node 2) cannot be removed here: only top-level solids and lights can "
                   "(a departure from Webots, which removes robots too)")
    lv.err(A, "/boss/robot/remove_node", {"node": BOSS}, ErrorCode.INVALID_ARGUMENT)
    assert lv.err(A, "/boss/robot/remove_node", {"node": 0}, ErrorCode.INVALID_ARGUMENT) == \
        "remove_node: the root node cannot be removed"
    assert boss(lv, "get_field", {"node": 0, "field": "children"})["value"] == [*SCENERY, *range(1, 8)]


def test_a_robot_blocked_by_a_box_drives_through_once_it_is_removed():
    lv = _live()
    rover = lv.sim.robot("rover")
    for m in rover.motors.values():
        m.target_position, m.velocity = math.inf, 5.0                     # 0.5 m/s along +x
    for _ in range(150):                                                  # 2.4 s: 1.2 m, the gate at 0.8
        lv.step(A, "boss", {"duration": 16})
    assert rover.pose.translation[0] == pytest.approx(0.8, abs=1e-9)
    boss(lv, "remove_node", {"node": GATE})
    for _ in range(300):                                                  # 4.8 s more: to the wall
        lv.step(A, "boss", {"duration": 16})
    assert rover.pose.translation[0] == pytest.approx(2.8, abs=1e-9)
    assert rover.pose.translation[1] == pytest.approx(-2.0, abs=1e-9)


def test_simulation_reset_does_not_bring_removed_nodes_back():
    lv = _live()
    boss(lv, "set_field", {"node": GATE, "field": "translation", "value": [1.1, -3.0, 0.25]})
    boss(lv, "set_field", {"node": LAMP, "field": "intensity", "value": 5.0})
    boss(lv, "remove_node", {"node": CRATE})
    boss(lv, "remove_node", {"node": BULB})
    assert readings(lv)["eye"] == pytest.approx(5.0)
    boss(lv, "simulation_reset")
    got = readings(lv)
    assert got["ds"] == pytest.approx(3.0, abs=1e-9)                      # the crate stays removed
    assert got["eye"] == pytest.approx(3.0)                               # lamp's intensity as loaded, no bulb
    assert boss(lv, "get_field", {"node": GATE, "field": "translation"})["value"] == [1.1, -2.0, 0.25]
    assert boss(lv, "get_field", {"node": 0, "field": "children"})["value"] == [*SCENERY, BOSS, ROVER, WALL, GATE, LAMP]
    assert boss(lv, "get_from_id", {"id": CRATE}) == NULL


def test_a_moved_solid_can_be_removed():
    """A solid a supervisor moved is in the movers' tier, not the static one: removal takes it out there."""
    lv = _live()
    boss(lv, "set_field", {"node": CRATE, "field": "translation", "value": [2.1, 0.0, 0.25]})
    assert readings(lv)["ds"] == pytest.approx(2.0, abs=1e-9)
    boss(lv, "remove_node", {"node": CRATE})
    assert readings(lv)["ds"] == pytest.approx(3.0, abs=1e-9)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_controller_removes_a_solid_and_a_light(tmp_path):
    """tests/controllers/supervisor_remove.py through ``sensorium serve``: ``node.remove()`` as in Webots."""
    ctl = run_paused(WORLD, tmp_path, "supervisor_remove.py", "boss")
    out = json.loads(ctl.out[-1])
    assert out["before"] == [pytest.approx(1.0, abs=1e-9), pytest.approx(7.0), 9]
    assert out["after"] == [pytest.approx(3.0, abs=1e-9), pytest.approx(3.0), 7]
    assert out["gone"] == [True, True, GATE, True]
    nan = [math.nan] * 3                                 # the removed crate, the refused intensity: no traceback
    assert out["refused"] == [pytest.approx(nan, nan_ok=True), pytest.approx(nan[:2], nan_ok=True),
                              pytest.approx(nan[:2], nan_ok=True), None, 3.0, [1.1, -2.0, 0.25], 0]
    assert out["moved"] == [[3.2, 0.0, 0.25], [3.2, 0.0, 0.25], 7, 7, "SFVec3f"]
    assert out["stale"] == ["", "", 0, "", None, -1, "Solid"]    # it answered "Solid", "Solid", 24, "CRATE", root, 4
    for func in ("get_type_name", "get_base_type_name", "get_type", "get_def", "get_parent_node", "get_id"):
        assert f"Error: wb_supervisor_node_{func}() called with a NULL or invalid 'node' argument." in ctl.stderr()
    assert "Error: Field.value: the MFNode field 'children' cannot be set as a whole." in ctl.stderr()
    assert "Error: wb_supervisor_field_set_sf_vec3f(): expected 3 numbers, got 2." in ctl.stderr()
    assert "Error: wb_supervisor_field_set_sf_rotation(): expected 4 numbers, got '0 0 1 0'." in ctl.stderr()
    assert "Error: wb_supervisor_node_get_position(): get_node_pose: node 4 (Solid 'crate') was removed." in ctl.stderr()
    assert ("Error: wb_supervisor_field_set_sf_float(): set_field: PointLight intensity: must be >= 0, got -1.0."
            in ctl.stderr())
    assert ("Error: wb_supervisor_node_remove(): remove_node: robot 'rover' (node 2) cannot be removed here: only "
            "top-level solids and lights can (a departure from Webots, which removes robots too).") in ctl.stderr()


def _top_fields(data: bytes) -> list[tuple[int, bytes]]:
    """A protobuf message's top-level length-delimited fields (number, payload): enough to tell a
    SceneUpdate's deletions (field 1) from its entities (field 2) without a protobuf library."""
    out, i = [], 0

    def varint() -> int:
        nonlocal i
        v = shift = 0
        while True:
            b = data[i]
            i += 1
            v |= (b & 0x7F) << shift
            shift += 7
            if b < 0x80:
                return v

    while i < len(data):
        key = varint()
        assert key & 7 == 2, key                      # SceneUpdate's fields are all messages
        n = varint()
        out.append((key >> 3, data[i:i + n]))
        i += n
    return out


def test_the_foxglove_scene_drops_and_deletes_a_removed_solid():
    """The live viewer's scene (serve --foxglove: scene_update with the simulation's solid poses): a
    removed solid or light is not drawn and is deleted from a viewer that drew it; the others are still drawn."""
    from sensorium.server.recording.frames import bodies
    from sensorium.server.recording.scene3d import scene_update

    sim = Simulation(load_world(WORLD))

    def scene() -> tuple[list[bytes], list[bytes]]:
        fields = _top_fields(scene_update(sim.world, sim.loaded.base_dir, 0, dict(sim.scene.solid_poses),
                                          sim.scene.removed_lights).encode())
        return [p for f, p in fields if f == 1], [p for f, p in fields if f == 2]

    deletions, entities = scene()
    assert deletions == [] and sum(b"solid/crate" in e for e in entities) == 1
    sim.remove_solid("crate")
    deletions, entities = scene()
    assert len(deletions) == 1 and b"solid/crate" in deletions[0]
    assert not any(b"solid/crate" in e for e in entities)
    assert sum(b"solid/wall" in e for e in entities) == 1 and sum(b"solid/gate" in e for e in entities) == 1
    assert [b.entity_id for b in bodies(sim.world, dict(sim.scene.solid_poses))] == [
        "solid/wall", "solid/gate", "robot/rover"]
    assert sum(b"light/bulb" in e for e in entities) == 1
    sim.remove_light(1)                                     # bulb
    deletions, entities = scene()
    assert len(deletions) == 2 and b"solid/crate" in deletions[0] and b"light/bulb" in deletions[1]
    assert not any(b"light/bulb" in e for e in entities) and sum(b"light/lamp" in e for e in entities) == 1


def test_in_process_removal_names_what_is_wrong():
    sim = Simulation(load_world(WORLD))
    sim.remove_solid("crate")
    sim.remove_light(1)
    with pytest.raises(KeyError, match="no solid 'crate'"):
        sim.remove_solid("crate")
    with pytest.raises(KeyError, match=r"no top-level light 1 \(the world has 2; removed: \[1\]\)"):
        sim.remove_light(1)
    with pytest.raises(KeyError, match="no top-level light 2"):
        sim.remove_light(2)
    sim.reset()                                        # removed nodes stay removed
    assert set(sim.scene.solid_poses) == {"wall", "gate"} and sim.scene.removed_lights == {1}


def test_the_live_viewer_resends_the_scene_when_a_node_is_removed():
    """serve --foxglove: removing a solid, then a light, broadcasts the scene again each time."""
    from test_foxglove_viewer import scene_sends  # (skips this test without foxglove-sdk)

    sim = Simulation(load_world(WORLD), precision="fast")
    with scene_sends(sim) as (bridge, pass_, sent):
        first = bridge.scene_bytes()
        bridge._subscribed(7, "/scene", +1)
        pass_()
        expected: list[int | None] = [7]
        for remove in (lambda: sim.remove_solid("crate"), lambda: sim.remove_light(1)):
            remove()
            expected.append(None)
            pass_(len(expected))
            assert sent == expected                    # the subscriber's own copy, then a broadcast each
        assert b"solid/crate" in first and b"light/bulb" in first
        pass_()
        assert sent == expected and not bridge._scene_for     # nothing removed since: nothing resent
        assert len(bridge.scene_bytes()) < len(first)
