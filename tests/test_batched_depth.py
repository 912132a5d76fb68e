"""RangeFinders in the batched simulation (sensorium/server/sim/batched_depth.py): every copy's depth
images bit-identical to the single Simulation with its seed (noise included), closed-form depths,
copies blind to each other's robots, the noise streams' draws, the vector environment observing
them, and a camera measured next to them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.devices.noise import device_rng
from sensorium.server.sim import batched_depth
from sensorium.server.sim.batched import BatchedSimulation, NoiseStreams
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests._copies import check_sub_env, copies_and_singles, reseed_copy, seeded, steer_randomly, vector_beside_singles
from tests.test_gym_vector import _random_steps, _reset_both

WORLD = Path(__file__).parent / "worlds" / "depth.yaml"
PERIODS = {"rover": {"depth": 32, "wide": 16, "housed": 48}, "scout": {"eye": 16}}
BOTH = ["fast", "exact"]


def _world(seed: int) -> LoadedWorld:
    return seeded(WORLD, seed)


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_captures_its_range_finders_as_the_single_simulation(precision: str):
    """Two robots driving among a wall, a post and a crate with random per-copy wheel commands;
    range finders planar (noise, resolution, min_range, near), cylindrical (noise, tilted), spherical
    (resolution) and one housed in a box of its own, at different periods; a reset of one copy with
    a new seed on the way: after every basic step every image of every copy equals that of a
    Simulation built with that copy's seed, bit for bit (zeros before the first capture, +inf for
    no hit)."""
    seeds = [5, 6, 7]
    bs, sims = copies_and_singles(_world, seeds, precision, PERIODS)
    rng = np.random.default_rng(1)
    seen = {"inf": 0, "finite": 0, "zeros": 0, "near": 0}
    for step in range(90):
        if step % 10 == 0:
            steer_randomly(bs, sims, rng, PERIODS)
        if step == 50:                          # copy 1 as a new world with another seed
            reseed_copy(bs, sims, _world, 1, 42, precision, PERIODS)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in PERIODS.items():
                for n in names:
                    want = s.robot(robot).device(n).range_image
                    got = bs.range_image(bs.device(robot, n))[c]
                    assert got.dtype == np.float32 and got.shape == want.shape
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n)
                    seen["inf"] += int(np.isinf(got).any())
                    seen["finite"] += int(np.isfinite(got).any())
                    seen["zeros"] += int(not got.any())
            seen["near"] += int((bs.range_image(bs.device("rover", "wide"))[c] < 0.05).any())   # its own robot
    assert seen["inf"] > 100 and seen["finite"] > 100 and seen["zeros"] > 0 and seen["near"] > 0
    # the noise is each copy's own: the same device's images differ between copies
    depth = bs.range_image(bs.device("rover", "depth"))
    assert len({img.tobytes() for img in depth}) == len(seeds)


def _blurred(seed: int) -> LoadedWorld:
    """depth.yaml with motion blur on every range finder (the rover's planar one also noisy and
    quantised, its cylindrical and housed ones, the scout's spherical one), at different lengths."""
    lw = _world(seed)
    blur = {"depth": 60.0, "wide": 200.0, "housed": 40.0, "eye": 100.0}
    robots = [r.model_copy(update={"devices": [d.model_copy(update={"motion_blur": blur[d.name]}) for d in r.devices]})
              for r in lw.world.robots]
    return LoadedWorld(world=lw.world.model_copy(update={"robots": robots}), source=lw.source, base_dir=lw.base_dir)


@pytest.mark.parametrize("precision", BOTH)
def test_every_copy_blurs_its_range_images_as_the_single_simulation(precision: str):
    """The driving copies with motion blur on every range finder: each copy keeps its own blurred
    values (+inf before its first image and again after its reset) and mixes them at the weight of
    its own sampling period (copy 2's planar one changes period on the way), before its own noise:
    after every basic step every image of every copy equals its Simulation's, bit for bit."""
    seeds = [5, 6, 7]
    bs, sims = copies_and_singles(_blurred, seeds, precision, PERIODS)
    rng = np.random.default_rng(2)
    moved = 0
    for step in range(70):
        if step % 10 == 0:
            steer_randomly(bs, sims, rng, PERIODS)
        if step == 25:                          # one copy's planar range finder at another period
            bs.enable(bs.device("rover", "depth"), 48, copies=[2])
            sims[2].robot("rover").device("depth").enable(48)
        if step == 40:                          # copy 1 as a new world with another seed
            reseed_copy(bs, sims, _blurred, 1, 42, precision, PERIODS)
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            for robot, names in PERIODS.items():
                for n in names:
                    want = s.robot(robot).device(n).range_image
                    got = bs.range_image(bs.device(robot, n))[c]
                    assert want.tobytes() == got.tobytes(), (step, c, robot, n)
            moved += int(np.isfinite(s.robot("rover").device("wide")._blurred).any())
    assert moved > 100          # (the single devices blur: a batched copy that did not would differ)


def _facing(d: list[float], projection: str, noise: float = 0.0) -> wm.World:
    """A robot without a body whose range finder (11 x 5 pixels, at the robot's origin, 0.1 m up)
    faces a wide wall whose face is the plane x = 2."""
    dev = {"device": "RangeFinder", "name": "rf", "pose": {"translation": [0.0, 0.0, 0.1]}, "width": 11, "height": 5,
           "field_of_view": 1.0, "projection": projection, "min_range": 0.01, "max_range": 5.0, "noise": noise}
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8, "contact": False},
        "solids": [{"name": "wall", "pose": {"translation": [2.5, 0.0, 0.0]},
                    "geometry": {"type": "box", "size": [1.0, 40.0, 40.0]}}],
        "robots": [{"name": "bot", "pose": {"translation": [2.0 - d[0], 0.0, 0.0]},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0},
                    "devices": [dev]}]})


@pytest.mark.parametrize("precision", BOTH)
def test_a_range_finder_facing_a_wall_reads_the_closed_form_depths(precision: str):
    """Copy c stands d_c from a wall, facing it. Planar: every pixel reads the depth d_c (the distance
    to the device's image plane). Cylindrical: the distance along the ray, d_c / cos(a_j) along the
    middle row (elevation 0), a_j = (1/2 - (j + 1/2)/W) fov the column's azimuth."""
    d = [0.5, 1.0, 1.7, 3.2]
    tol = 2e-7 if precision == "exact" else 2e-6
    for projection in ("planar", "cylindrical"):
        bs = BatchedSimulation(LoadedWorld(world=_facing(d, projection), source="<test>", base_dir=Path.cwd()),
                               len(d), precision=precision)
        for c, dc in enumerate(d):
            bs.set_pose(c, 0, translation=[2.0 - dc, 0.0, 0.0])
        ref = bs.device("bot", "rf")
        bs.enable(ref, 8)
        assert not bs.range_image(ref).any()                      # zeros before the first image (Webots)
        bs.step()
        img = bs.range_image(ref).astype(np.float64)
        for c, dc in enumerate(d):
            if projection == "planar":
                np.testing.assert_allclose(img[c], dc, rtol=tol)
            else:
                a = (0.5 - (np.arange(11) + 0.5) / 11) * 1.0
                np.testing.assert_allclose(img[c, 2], dc / np.cos(a), rtol=tol)
                assert (img[c, 0] > img[c, 2]).all()               # rows above look up: farther


def scout_ahead_in_copy_0(lw: LoadedWorld, names: tuple[str, ...], corner: tuple[float, float],
                          reading: str) -> BatchedSimulation:
    """Two copies of ``lw`` (world seed 0) with the scout parked 0.5 m in front of the rover in copy 0
    and at ``corner`` in copy 1, the rover's devices ``names`` enabled, stepped 3 times beside two
    Simulations with their scout placed alike: each copy's images (``reading``: "range_image" or
    "image") equal its Simulation's, byte for byte, every step. Returns the batched simulation."""
    bs = BatchedSimulation(lw, 2, precision="exact")
    bs.reset([0, 1], [0, 0])
    rover = bs.pose(0, bs.slot("rover"))
    fwd = rover.rotation[:, 0]
    ahead = rover.translation + 0.5 * fwd
    places = [([float(ahead[0]), float(ahead[1]), 0.0], [0, 0, 1, math.atan2(fwd[1], fwd[0])]),
              ([corner[0], corner[1], 0.0], [0, 0, 1, 0.0])]
    singles = []
    for c, (t, r) in enumerate(places):
        bs.set_pose(c, bs.slot("scout"), translation=t, rotation=r)
        single = Simulation(lw, precision="exact")
        single.robot("scout").set_pose(t, r)
        for n in names:
            single.robot("rover").device(n).enable(16)
        singles.append(single)
    for n in names:
        bs.enable(bs.device("rover", n), 16)
    for _ in range(3):
        bs.step()
        for c, single in enumerate(singles):
            single.step()
            for n in names:
                got = getattr(bs, reading)(bs.device("rover", n))[c]
                assert got.tobytes() == getattr(single.robot("rover").device(n), reading).tobytes(), (c, n)
    return bs


def test_copies_never_see_each_others_robots():
    """The scout parked 0.5 m in front of the rover in copy 0, and off to a corner in
    copy 1 (both copies with world seed 0): each copy's images are those of a Simulation with its
    scout where that copy has it, bit for bit, and copy 0's show the scout (near pixels) where copy
    1's, with the same noise, do not -- copy 1's rover does not see copy 0's scout."""
    bs = scout_ahead_in_copy_0(_world(0), ("depth", "wide", "housed"), (-1.5, 1.5), "range_image")
    # the noiseless housed device: the pixels on copy 0's scout (its near face 0.33 m ahead) read
    # nearer than copy 1's (the floor there), every other pixel the same
    img = bs.range_image(bs.device("rover", "housed"))
    differ = img[0] != img[1]
    assert differ.sum() >= 4 and (img[0][differ] < 0.35).all() and (img[1][differ] > img[0][differ] + 0.1).all()


def test_noise_draws_continue_each_stream_in_order_whatever_the_block_sizes():
    """An image draws one normal per valid pixel: batched_depth.draw takes what the bank buffered,
    then the rest straight from the stream, leaving the bank to go on from there -- the same numbers,
    in the same order, as one generator drawing them all, with single draws (NoiseStreams.next) and
    block refills in between, and after a reseed the stream from its start again."""
    bank = NoiseStreams(2, ["r/a", "r/b"], block=64)
    bank.reseed([0, 1], [11, 12])
    ref = {(c, d): device_rng(11 + c, p) for c in (0, 1) for d, p in enumerate(["r/a", "r/b"])}
    got: dict = {k: [] for k in ref}
    for size in (1, 3, 200, 0, 61, 64, 1, 500, 2):
        for (c, d) in ref:
            if size == 1:
                got[(c, d)].append(bank.next(np.array([c]), np.array([d])))
            else:
                got[(c, d)].append(batched_depth.draw(bank, c, d, size))
    for k, rng in ref.items():
        seq = np.concatenate(got[k])
        assert seq.tobytes() == rng.standard_normal(len(seq)).tobytes(), k
    bank.reseed([1], [12])
    assert batched_depth.draw(bank, 1, 0, 100).tobytes() == device_rng(12, "r/a").standard_normal(100).tobytes()


gym = pytest.importorskip("gymnasium")

from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402

OBSERVED = {"depth": 32, "wide": 32}


def _task() -> Task:
    return Task(robot="rover", observations=OBSERVED, control_period_ms=32, max_steps=20)


@pytest.mark.parametrize("precision", BOTH)
def test_the_vector_env_observes_range_finders_as_the_single_env(precision: str):
    """A task observing a noisy planar and a noisy cylindrical range finder: float32 (height, width)
    boxes in [0, max_range]; every sub-env equals the single env (rebuilt Simulation, and the one-copy
    batched engine, which "auto" now picks) with its seed, observations, rewards and poses bit for
    bit, across autoresets; "no hit" reads max_range; a sub-env passes Gymnasium's checker."""
    n = 3
    venv, singles = vector_beside_singles(WORLD, _task(), n, precision)
    space = venv.single_observation_space
    assert space["depth"].shape == (12, 16) and space["wide"].shape == (6, 24)
    assert space["depth"].dtype == np.float32 and space["depth"].high.max() == np.float32(2.5)
    obs = _reset_both(venv, singles, 4)
    assert (obs["depth"] == np.float32(2.5)).any() and (obs["depth"] < 2.5).any()   # no hit: max_range
    assert _random_steps(venv, singles, OBSERVED, 45) >= n       # autoresets happened
    check_sub_env(venv)
    venv.close()


def test_a_camera_is_measured_next_to_the_range_finders():
    """Cameras are measured by the batched simulation now (tests/test_batched_camera.py): a task
    observing a range finder and a camera runs batched, "auto" included."""
    lw = load_world(WORLD)
    data = lw.world.model_dump(mode="json", exclude_none=True)
    data["robots"][0]["devices"].append({"device": "Camera", "name": "cam", "width": 8, "height": 6})
    world = LoadedWorld(world=wm.World.model_validate(data), source=lw.source, base_dir=lw.base_dir)
    bs = BatchedSimulation(world, 2)
    assert bs.device("rover", "cam").kind == "Camera" and bs.device("rover", "depth").kind == "RangeFinder"
    venv = SensoriumVectorEnv(world, Task(robot="rover", observations=["depth", "cam"]), 2)
    assert venv.single_observation_space["cam"].shape == (6, 8, 3)
    assert SensoriumEnv(world, Task(robot="rover", observations=["depth", "cam"]), engine="auto").engine == "batched"
