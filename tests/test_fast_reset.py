"""FAST precision: a world put back where it loaded reads as the freshly loaded world, bit for bit.

The ray engine bakes a static body's shapes into its world-frame tier and casts a body that moved in
its own frame (rays turned into it in float32); the two frames' float32 answers differ by an ulp.
A body added static that is put back on the pose it was added at reads from the static tier again,
so a ``simulationReset``, a ``loadState("__init__")`` or a Supervisor's set of the loaded pose leaves
no trace in the readings: lidar, range finder, camera, infra-red, sonar and laser distance sensors
(tests/test_supervisor_transparency.py's world: a wall, a block and a ball before a robot)."""

from __future__ import annotations

import numpy as np
import pytest
from test_fuzz_today_transparency import _reset
from test_supervisor_transparency import _sim, readings, same, world

from sensorium.server.daemon import supervisor as sv
from sensorium.server.raycast.engine import Precision, RayEngine, ShapeEntry
from sensorium.server.world.geometry import Box, Pose


def _fresh() -> dict:
    sim = _sim(world(0.0, "block"), "fast")
    sim.run(1)
    return readings(sim)


def _moved(sim) -> None:
    """The robot turned and moved, the block and the ball moved by a Supervisor, a step taken there."""
    sim.robot("r").set_pose([0.3, -0.2, 0.0], [0, 0, 1, 0.4])
    sv.set_field(sim, sv.find_node(sim, "block"), "translation", [1.3, 0.2, 0.0])
    sv.set_field(sim, sv.find_node(sim, "ball"), "rotation", [0, 1, 0, 0.7])
    sim.run(1)


def _load_init(sim) -> None:
    for name in ("r", "block", "ball"):
        node = sv.find_node(sim, name)
        sv._states(sim).load(sim, node.id, sv.state_scope(sim, node), "__init__")


def _put_back(sim) -> None:
    """The loaded poses set again field by field, as a Supervisor would."""
    sim.robot("r").set_pose([0.0, 0.0, 0.0], [0, 0, 1, 0.0])
    sv.set_field(sim, sv.find_node(sim, "block"), "translation", [1.0, 0.0, 0.0])
    sv.set_field(sim, sv.find_node(sim, "ball"), "rotation", [0, 0, 1, 0.0])


@pytest.mark.parametrize("back", [_reset, _load_init, _put_back], ids=["reset", "load_init", "set_back"])
def test_moved_and_put_back_reads_as_the_fresh_world_under_fast(back):
    fresh = _fresh()
    sim = _sim(world(0.0, "block"), "fast")
    sim.run(1)
    assert same(readings(sim), fresh) == []
    for _ in range(2):                        # twice: the second round trip too
        _moved(sim)
        moved = readings(sim)
        assert {"rf", "lidar", "ir", "laser"} <= set(same(moved, fresh))   # it did move
        back(sim)
        sim.run(1)
        assert same(readings(sim), fresh) == []


HOME = Pose.from_axis_angle((0.3, 0.2, 1.0), 0.37, translation=(3.0, 0.1, 0.2))
AWAY = Pose(HOME.rotation, HOME.translation + (1.0, 0.0, 0.0))
HALF = np.array([0.1, 0.5, 0.5])


def _slab(pose: Pose, o: np.ndarray, d: np.ndarray) -> float:
    """The entry distance of the ray o + t d into the box (half sizes HALF) at ``pose``, in float64."""
    o_box, d_box = pose.rotation.T @ (o - pose.translation), pose.rotation.T @ d
    with np.errstate(divide="ignore"):
        t1, t2 = (-HALF - o_box) / d_box, (HALF - o_box) / d_box
    return float(np.max(np.minimum(t1, t2)))


def test_engine_static_body_moved_and_back_casts_the_static_bits():
    """A turned box about 3 m ahead, rays from the origin fanned across it: the axis ray enters
    where the box's slabs say (float32-close); moved 1 m further it enters 1 m later; back at its
    pose (a new, equal Pose) every ray reads the bits the never-moved box gave."""
    rng = np.random.default_rng(5)
    D = rng.normal([1.0, 0.0, 0.0], 0.05, size=(64, 3))
    D[0] = (1.0, 0.0, 0.0)
    D /= np.linalg.norm(D, axis=1)[:, None]
    O = np.zeros_like(D)
    eng = RayEngine(Precision.FAST)
    body = eng.add_body([ShapeEntry(Box((0.2, 1.0, 1.0)), Pose.identity(), True, True)], HOME)
    first = eng.cast(O, D)
    entry = _slab(HOME, O[0], D[0])
    assert first.distance[0] == pytest.approx(entry, abs=1e-5)
    eng.set_body_pose(body, AWAY)
    assert eng.cast(O, D).distance[0] == pytest.approx(entry + 1.0, abs=1e-5)
    eng.set_body_pose(body, Pose(HOME.rotation.copy(), HOME.translation.copy()))
    again = eng.cast(O, D)
    assert np.isfinite(first.distance).sum() > 32
    assert again.distance.tobytes() == first.distance.tobytes()
    assert again.normal.tobytes() == first.normal.tobytes()
    assert again.shape.tobytes() == first.shape.tobytes()
