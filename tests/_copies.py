"""Batched copies of a world beside one Simulation per copy (and a vector env beside single envs):
the seeded setup, the random wheel commands, the mid-run reseed of one copy and the pose-for-pose
loop that the sensor comparisons (tests/test_batched_depth.py, test_batched_rotating_lidar.py,
test_batched_camera.py, test_camera_light_radius.py, test_batched_led_lights.py,
test_batched_robot_lights.py, test_lens.py) and the ground-riding ones (tests/test_ground_box.py,
test_ground_ramp.py, test_ground_cylinder.py) share."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.raycast import packets
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests.test_batched_nue import _to_nue
from tests.test_batched_sim import _enable_both, _wheels_both


def seeded(path: Path, seed: int) -> LoadedWorld:
    """The world file at ``path`` with its random_seed ``seed``."""
    lw = load_world(path)
    w = lw.world.model_copy(update={"world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def copies_and_singles(make: Callable[[int], LoadedWorld], seeds: Sequence[int], precision: str,
                       periods: dict) -> tuple[BatchedSimulation, list[Simulation]]:
    """A BatchedSimulation of ``make(0)`` with a copy per seed, reset with those seeds, a Simulation of
    ``make(seed)`` per copy, and the devices of ``periods`` ({robot: {device: ms}}) enabled in both."""
    bs = BatchedSimulation(make(0), len(seeds), precision=precision)
    bs.reset(np.arange(len(seeds)), list(seeds))
    sims = [Simulation(make(s), precision=precision) for s in seeds]
    for c in range(len(seeds)):
        _enable_both(bs, sims, periods, c)
    return bs, sims


def steer_randomly(bs: BatchedSimulation, sims: list[Simulation], rng: np.random.Generator, robots,
                   share: float = 0.3) -> None:
    """Each of ``robots``' two wheels at a random speed within ``share`` of its maximum, per copy, in
    the copies and their Simulations alike."""
    for robot in robots:
        vmax = share * float(bs.max_wheel[bs.slot(robot), 0])
        _wheels_both(bs, sims, robot, rng.uniform(-vmax, vmax, (len(sims), 2)))


def reseed_copy(bs: BatchedSimulation, sims: list[Simulation], make: Callable[[int], LoadedWorld], copy: int,
                seed: int, precision: str, periods: dict) -> None:
    """Copy ``copy`` reset as a new world with ``seed``, its Simulation rebuilt from ``make(seed)``, and
    the devices of ``periods`` enabled again in both."""
    bs.reset([copy], [seed])
    sims[copy] = Simulation(make(seed), precision=precision)
    _enable_both(bs, sims, periods, copy)


def vector_beside_singles(world, task, n: int, precision: str) -> tuple:
    """A vector env of ``n`` sub-envs of ``task`` and, for sub-envs 0 to 2, the single env on the
    engines "simulation", "auto" (which picks the one-copy batched engine) and "simulation"."""
    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv

    venv = SensoriumVectorEnv(world, task, n, precision=precision)
    singles = [SensoriumEnv(world, task, precision=precision, engine=e) for e in ("simulation", "auto", "simulation")]
    assert [e.engine for e in singles] == ["simulation", "batched", "simulation"]
    return venv, singles


def check_sub_env(venv) -> None:
    """Gymnasium's checker passes on sub-env 1 of ``venv``, no warning allowed."""
    from gymnasium.utils.env_checker import check_env

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(venv.sub_env(1), skip_render_check=True)


def drive_and_compare(bs: BatchedSimulation, sims: list[Simulation], robots, rng: np.random.Generator, steps: int,
                      every: int, full_every: int | None = None, move=None, up: int = 2) -> set[float]:
    """``steps`` steps of ``bs`` and of each copy's Simulation. Every ``every`` steps each of ``robots``
    (two-wheel) gets random wheel speeds in [-12, 12] rad/s per copy, or all 10 rad/s at the multiples
    of ``full_every``; ``move``, (step, robot, place), puts that robot there by set_pose in copy 1 and
    its Simulation before that step. After each step every robot's pose is its Simulation's bit for
    bit. Returns the heights (coordinate ``up``) the robots were at."""
    heights: set[float] = set()
    for step in range(steps):
        if step % every == 0:
            for robot in robots:
                full = full_every is not None and step % full_every == 0
                _wheels_both(bs, sims, robot, np.full((len(sims), 2), 10.0) if full
                             else rng.uniform(-12.0, 12.0, (len(sims), 2)))
        if move is not None and step == move[0]:
            bs.set_pose(1, bs.slot(move[1]), move[2])
            sims[1].robot(move[1]).set_pose(move[2])
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot in robots:
                slot = bs.slot(robot)
                pose = s.robot(robot).pose
                assert pose.rotation.tobytes() == bs.rot[c, slot].tobytes(), (step, c, robot)
                assert pose.translation.tobytes() == bs.pos[c, slot].tobytes(), (step, c, robot)
                heights.add(float(pose.translation[up]))
    return heights


def ground_copies(world: Callable[[int], wm.World], nue: bool, c_drive: bool) -> tuple[BatchedSimulation,
                                                                                       list[Simulation], int]:
    """Three copies of ``world(seed)`` reset with seeds 3, 4, 5 (the world written in NUE axes, y up,
    with ``nue``), stepped by the C drive pass or (``c_drive`` False) the numpy one, a Simulation per
    copy, and the index of the up axis. Skips the test when the C pass is asked for and not built."""
    if c_drive and packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")

    def make(seed: int) -> wm.World:
        return wm.World.model_validate(_to_nue(world(seed))) if nue else world(seed)

    seeds = [3, 4, 5]
    bs = BatchedSimulation(make(0), len(seeds))
    if not c_drive:
        bs._drive_step = None
    bs.reset(np.arange(3), seeds)
    return bs, [Simulation(make(s)) for s in seeds], 1 if nue else 2
