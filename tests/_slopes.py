"""Robots on the ramp of tests/test_ground_ramp.py: its world, and batched copies stepped beside one
Simulation each, pose for pose bit for bit (tests/test_ramp_speed.py's two-wheel robots,
tests/test_holonomic_slopes.py's mecanum and omni robots)."""

from __future__ import annotations

from collections.abc import Callable

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests.test_ground_ramp import FLOOR, _ramp

STEP = 16                                # basicTimeStep (ms)


def ramp_world(robots: list[dict], ramp: bool = True) -> dict:
    """The floor, the ramp (unless ``ramp`` is False) and ``robots``."""
    return {"world_info": {"basic_time_step": STEP}, "solids": [FLOOR, _ramp()] if ramp else [FLOOR], "robots": robots}


def copies_at_headings(robot: Callable[[float], dict], at: list[float],
                       yaws: list[float]) -> tuple[BatchedSimulation, int, list[Simulation]]:
    """A BatchedSimulation with one copy per heading of ``robot(yaw)`` (named "r", placed at ``at`` by
    set_pose), its slot, and for each copy the Simulation of the world with that robot."""
    worlds = [parse_world(ramp_world([robot(yaw)])) for yaw in yaws]
    bs = BatchedSimulation(worlds[0], len(yaws))
    slot = bs.slot("r")
    for c, yaw in enumerate(yaws):
        bs.set_pose(c, slot, at, [0, 0, 1, yaw])
    return bs, slot, [Simulation(w, precision="exact") for w in worlds]


def step_copies_as_singles(bs: BatchedSimulation, slot: int, sims: list[Simulation], steps: int) -> int:
    """``steps`` steps of ``bs`` and of each copy's Simulation: after each, every copy's robot "r" has its
    Simulation's translation and rotation bit for bit. Returns how many (step, copy) rode a slope."""
    tilted = 0
    for step in range(steps):
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            pose = s.robot("r").pose
            assert pose.translation.tobytes() == bs.pos[c, slot].tobytes(), (step, c)
            assert pose.rotation.tobytes() == bs.rot[c, slot].tobytes(), (step, c)
            tilted += s.robot("r").drive.slope is not None
    return tilted
