"""Rotating lidars in the batched simulation (sensorium/server/sim/batched_lidar.py): every copy's range
images bit-identical to the single Simulation with its seed (noise included) step by step, through
resets, a disable and a re-enable; each swept column against the closed-form distance to the walls
of a square room; the vector environment observing one, as the single env."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, from_model
from tests._copies import check_sub_env, copies_and_singles, reseed_copy, seeded, steer_randomly, vector_beside_singles
from tests.test_gym_vector import _random_steps, _reset_both

WORLD = Path(__file__).parent / "worlds" / "rotating_lidar.yaml"
# sampling periods: a multiple of the 16 ms step and ones that are not (the head turns every step anyway)
PERIODS = {"rover": {"spin": 16, "flat": 20, "housed": 48, "low": 16}, "scout": {"ring": 40, "front": 32}}
BOTH = ["fast", "exact"]


def _world(seed: int) -> LoadedWorld:
    return seeded(WORLD, seed)


def _enable_one(bs: BatchedSimulation, sims: list, copy: int, robot: str, name: str, period: int) -> None:
    bs.enable(bs.device(robot, name), period, copies=[copy])
    sims[copy].robot(robot).device(name).enable(period)


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_sweeps_its_rotating_lidars_as_the_single_simulation(precision: str):
    """Two robots driving among walls, a post and a crate with random per-copy wheel commands; rotating
    lidars with 4 tilted noisy layers (10.08 columns per step), a planar projection with resolution
    (7.04), one housed in a box of its own (2.56) and one seeing its robot's mast (9.52), beside a fixed
    lidar; copy 1 reset with a new seed mid-run, copy 2's noisy lidar disabled and enabled again (with
    another period), a copy stepped alone: after every basic step every image of every copy equals
    that of a Simulation built with that copy's seed, bit for bit (zeros where the head has not swept
    yet, +inf for no hit)."""
    seeds = [5, 6, 7]
    bs, sims = copies_and_singles(_world, seeds, precision, PERIODS)
    rng = np.random.default_rng(1)
    seen = {"inf": 0, "finite": 0, "unswept": 0, "mast": 0}
    held = None
    for step in range(130):
        if step % 10 == 0:
            steer_randomly(bs, sims, rng, PERIODS)
        if step == 50:                          # copy 1 as a new world with another seed
            reseed_copy(bs, sims, _world, 1, 42, precision, PERIODS)
        if step == 70:                          # copy 2's head stops where it is, its image kept
            _enable_one(bs, sims, 2, "rover", "spin", 0)
            held = bs.range_image(bs.device("rover", "spin"))[2].copy()
        if step == 85:                          # and turns on from there
            assert bs.range_image(bs.device("rover", "spin"))[2].tobytes() == held.tobytes()
            _enable_one(bs, sims, 2, "rover", "spin", 24)
        alone = step in (100, 101, 102)         # copy 0 steps alone: the others' heads wait
        bs.step(np.array([True, False, False]) if alone else None)
        for c, s in enumerate(sims):
            if alone and c:
                continue
            s.step()
            for robot, names in PERIODS.items():
                for n in names:
                    want = s.robot(robot).device(n).range_image
                    got = bs.range_image(bs.device(robot, n))[c]
                    assert got.dtype == np.float32 and got.shape == want.shape
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n)
                    seen["inf"] += int(np.isinf(got).any())
                    seen["finite"] += int(np.isfinite(got).any())
                    seen["unswept"] += int((got == 0.0).any())
            seen["mast"] += int((bs.range_image(bs.device("scout", "ring"))[c] < 0.1).any())   # its own robot
    assert seen["inf"] > 100 and seen["finite"] > 100 and seen["unswept"] > 20 and seen["mast"] > 0
    # the noise is each copy's own: the same lidar's images differ between copies
    spin = bs.range_image(bs.device("rover", "spin"))
    assert len({img.tobytes() for img in spin}) == len(seeds)


def _square_room(half: float, heading: float, layers: int) -> wm.World:
    """A robot at the centre of a square room (walls ``half`` m from it, 2 m tall, 0.1 m thick)
    heading ``heading`` rad, carrying a rotating lidar 1 m up: 36 columns, ``layers`` layers over
    0.3 rad, 7 Hz (4.032 columns per 16 ms step)."""
    walls = [{"name": f"wall{k}", "pose": {"translation": [x, y, 1.0]},
              "geometry": {"type": "box", "size": [sx, sy, 2.0]}}
             for k, (x, y, sx, sy) in enumerate([(half + 0.05, 0, 0.1, 2 * half + 0.2), (-half - 0.05, 0, 0.1, 2 * half + 0.2),
                                                 (0, half + 0.05, 2 * half + 0.2, 0.1), (0, -half - 0.05, 2 * half + 0.2, 0.1)])]
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 1},
        "solids": walls,
        "robots": [{"name": "bot", "pose": {"translation": [0, 0, 0], "rotation": [0, 0, 1, heading]},
                    "devices": [{"device": "Lidar", "name": "head", "pose": {"translation": [0, 0, 1.0]},
                                 "type": "rotating", "horizontal_resolution": 36, "field_of_view": 2 * math.pi,
                                 "number_of_layers": layers, "vertical_field_of_view": 0.3, "near": 0.01,
                                 "min_range": 0.01, "max_range": 10.0, "default_frequency": 7.0,
                                 "min_frequency": 1.0, "max_frequency": 20.0}]}]})


@pytest.mark.parametrize("precision", BOTH)
def test_each_swept_column_reads_the_closed_form_distance_to_the_walls(precision: str):
    """In a square room (walls 1.5 m from the robot at its centre) each column j's beam of layer i
    leaves at azimuth ``yaw + π - j·2π/W`` and elevation e_i, so it meets the nearer wall at
    ``1.5 / max(|cos a|, |sin a|) / cos e_i``. The head starts at column W/2 and advances
    ``7 Hz · 16 ms · 36 = 4.032`` columns per step: after step k the swept columns are W/2 ...
    ceil(W/2 + 4.032 k) - 1 (mod W), each reading that distance (float32), the others still 0; two
    copies with different headings, equal to the single simulation's images at every step."""
    half, W, L = 1.5, 36, 3
    headings = [0.0, 0.4]
    bs = BatchedSimulation(_square_room(half, 0.0, L), len(headings), precision=precision)
    for c, yaw in enumerate(headings):
        bs.set_pose(c, 0, rotation=[0, 0, 1, yaw])
    ref = bs.device("bot", "head")
    bs.enable(ref, 16)
    sims = [Simulation(from_model(_square_room(half, yaw, L)), precision=precision) for yaw in headings]
    for s in sims:
        s.robot("bot").device("head").enable(16)
    elev = 0.15 - np.arange(L) * 0.15
    advance = 7.0 * 0.016 * W
    for k in range(1, 12):                      # 44 columns: past a full turn
        bs.step()
        ends = math.ceil(W / 2 + advance * k)
        swept = np.arange(W // 2, ends) % W
        for c, yaw in enumerate(headings):
            sims[c].step()
            img = bs.range_image(ref)[c]
            assert img.tobytes() == sims[c].robot("bot").device("head").range_image.tobytes(), (k, c)
            a = yaw + math.pi - swept * (2 * math.pi / W)
            want = half / np.maximum(np.abs(np.cos(a)), np.abs(np.sin(a)))[None, :] / np.cos(elev)[:, None]
            assert np.allclose(img[:, swept], want, rtol=0, atol=2e-5), (k, c)
            rest = np.setdiff1d(np.arange(W), swept)
            assert (img[:, rest] == 0.0).all(), (k, c)


gym = pytest.importorskip("gymnasium")

from sensorium.gym import Task  # noqa: E402

OBSERVED = {"spin": 32, "flat": 32}


def _task() -> Task:
    return Task(robot="rover", observations=OBSERVED, control_period_ms=32, max_steps=20)


@pytest.mark.parametrize("precision", BOTH)
def test_the_vector_env_observes_rotating_lidars_as_the_single_env(precision: str):
    """A task observing a noisy rotating lidar and a planar one: float32 (layers, width) boxes in
    [0, max_range]; every sub-env equals the single env (rebuilt Simulation, and the one-copy batched
    engine, which "auto" picks) with its seed, observations, rewards and poses bit for bit, across
    autoresets that happen at different times (each sub-env's head its own); a sub-env passes
    Gymnasium's checker."""
    n = 3
    venv, singles = vector_beside_singles(WORLD, _task(), n, precision)
    space = venv.single_observation_space
    assert space["spin"].shape == (4, 90) and space["flat"].shape == (3, 40)
    assert space["spin"].dtype == np.float32 and space["spin"].high.max() == np.float32(2.5)
    obs = _reset_both(venv, singles, 4)
    assert (obs["spin"] == 0.0).any() and (obs["spin"] > 0.0).any()     # a part swept, the rest not yet
    def reset_sub_env_0(t: int) -> None:
        if t == 7:                                   # sub-env 0's episode ends early: resets out of phase
            vobs, _ = venv.reset(options={"reset_mask": np.array([True, False, False])})
            o, _ = singles[0].reset()
            assert all(o[k].tobytes() == vobs[k][0].tobytes() for k in OBSERVED)

    assert _random_steps(venv, singles, OBSERVED, 50, before=reset_sub_env_0) >= n     # autoresets happened
    check_sub_env(venv)
    venv.close()
