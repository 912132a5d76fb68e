"""Lights carried by robots in the batched simulation (sensorium/server/sim/batched_lights.py): each
copy's light sensors and cameras lit by that copy's robots' lights at that copy's poses, bit for bit
the single Simulation with the copy's seed; the inverse-square closed form; copies never lit by each
other's lights; the vector environment observing them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, load_world
from tests._copies import copies_and_singles, reseed_copy, steer_randomly
from tests.test_batched_sim import _wheels_both

WORLD = Path(__file__).parent / "worlds" / "robot_lights.yaml"
PERIODS = {"seeker": {"front": 16, "left": 32, "tinted": 48, "eye": 32}}
SENSORS = ("front", "left", "tinted")


def _world(seed: int) -> LoadedWorld:
    lw = load_world(WORLD)
    info = lw.world.world_info.model_copy(update={"random_seed": seed})
    return LoadedWorld(world=lw.world.model_copy(update={"world_info": info}), source=lw.source, base_dir=lw.base_dir)


def _assert_copies_are_their_simulations(bs: BatchedSimulation, sims: list[Simulation], step: int) -> None:
    for c, s in enumerate(sims):
        for robot in ("leader", "seeker"):
            assert s.robot(robot).pose.translation.tobytes() == bs.pos[c, bs.slot(robot)].tobytes(), (step, c)
        seeker = s.robot("seeker")
        for n in SENSORS:
            want, got = seeker.device(n).value, float(bs.value(bs.device("seeker", n))[c])
            assert want == got or (math.isnan(want) and math.isnan(got)), (step, c, n, want, got)
        want_img = seeker.device("eye").image
        assert want_img.tobytes() == bs.image(bs.device("seeker", "eye"))[c].tobytes(), (step, c)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_every_copy_is_lit_by_its_own_leader_as_the_single_simulation(precision: str):
    """A leader carrying a point light (casting shadows), an aimed spot light, a directional light and
    a light that is off, and a seeker with three light sensors (occlusion, a colour filter, noise) and
    a camera (noise, anti-aliasing), both driving with random per-copy wheel commands, under a fixed
    point light and a shadow-casting sun; copy 1 reset with a new seed on the way: after every basic
    step every copy's poses, light-sensor values and camera images equal those of a Simulation built
    with that copy's seed, bit for bit. The leader's lights reach the sensors (values change with the
    copy and over time) and the wall hides them sometimes (the occluded sensor drops)."""
    seeds = [5, 6, 7, 8]
    bs, sims = copies_and_singles(_world, seeds, precision, PERIODS)
    assert bs.carried is not None and bs.carried.count == 3          # the "spare" light is off
    rng = np.random.default_rng(11)
    front = bs.device("seeker", "front")
    seen: list[np.ndarray] = []
    for step in range(60):
        if step % 12 == 0:
            steer_randomly(bs, sims, rng, ("leader", "seeker"), 0.4)
        if step == 30:                          # copy 1 as a new world with another seed
            reseed_copy(bs, sims, _world, 1, 42, precision, PERIODS)
        bs.step()
        for s in sims:
            s.step()
        _assert_copies_are_their_simulations(bs, sims, step)
        seen.append(bs.value(front).copy())
    values = np.array(seen)
    assert len({v.tobytes() for v in values.T}) == len(seeds)        # every copy lit its own way
    assert np.ptp(values, axis=0).min() > 1.0                        # the leaders' lights move over time


def _pair(r: float, copies_apart: bool = False) -> wm.World:
    """A bodiless robot "probe" at the origin with a light sensor along +x (table 0..10 -> 0..1000,
    noiseless), and a bodiless robot "lamp" carrying a point light (intensity 0.8, attenuation 0 0 1:
    no ambient, Webots' rule) 0.1 m above its origin, placed r m ahead of the probe at the sensor's height."""
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 8},
        "robots": [
            {"name": "probe", "devices": [{"device": "LightSensor", "name": "ls", "pose": {"translation": [0, 0, 0.1]},
                                           "lookup_table": [[0, 0, 0], [10, 1000, 0]]}]},
            {"name": "lamp", "pose": {"translation": [r, 0.0, 0.0], "rotation": [0, 0, 1, 0.7]},
             "lights": [{"type": "PointLight", "location": [0, 0, 0.1], "intensity": 0.8, "attenuation": [0, 0, 1]}]},
        ]})


def test_a_sensor_facing_a_carried_point_light_reads_the_inverse_square_law():
    """Copies whose lamp robot stands at r = 0.5, 1, 2, 4 m straight ahead of the probe's sensor read
    I cos 0 / r^2 = 0.8 / r^2 through the table (x 100), each its own r: the light moves with the
    copy's robot only."""
    radii = [0.5, 1.0, 2.0, 4.0]
    bs = BatchedSimulation(_pair(1.0), len(radii))
    lamp = bs.slot("lamp")
    for c, r in enumerate(radii):
        bs.set_pose(c, lamp, translation=[r, 0.0, 0.0])
    ref = bs.device("probe", "ls")
    bs.enable(ref, 8)
    bs.step()
    want = np.array([100.0 * 0.8 / (r * r) for r in radii])
    np.testing.assert_allclose(bs.value(ref), want, rtol=1e-12)
    # and each is the single simulation's value with the lamp there
    for c, r in enumerate(radii):
        s = Simulation(LoadedWorld(world=_pair(r), source="pair", base_dir=Path(".")))
        s.robot("probe").device("ls").enable(8)
        s.step()
        assert s.robot("probe").device("ls").value == float(bs.value(ref)[c])


def test_copies_never_see_each_others_lights():
    """Copy 0's lamp 0.5 m ahead of its probe, copy 1's 5 m behind it: copy 1's probe reads exactly 0
    (its own lamp is behind the sensor, no ambient), never copy 0's light; copy 0 reads 0.8 / 0.5^2
    through the table, not a sum with copy 1's lamp."""
    bs = BatchedSimulation(_pair(0.5), 2)
    bs.set_pose(1, bs.slot("lamp"), translation=[-5.0, 0.0, 0.0])
    ref = bs.device("probe", "ls")
    bs.enable(ref, 8)
    bs.step()
    v = bs.value(ref)
    assert v[0] == pytest.approx(100.0 * 0.8 / 0.25, rel=1e-12)
    assert v[1] == 0.0


def test_a_leader_carrying_lights_is_observed_by_the_vector_env_as_by_the_single_env():
    """A task on the seeker observing its light sensors and camera (the leader placed at a random
    pose per episode by the task's start): the vector env's sub-env i equals the single env with seed
    seed + i, observation by observation, across autoresets, and Gymnasium's checker passes."""
    gym = pytest.importorskip("gymnasium")
    from gymnasium.utils.env_checker import check_env

    from sensorium.gym import SensoriumEnv, Task
    from sensorium.gym.vector import SensoriumVectorEnv
    from tests.test_gym_vector import _reset_both, _step_both

    def place_leader(sim, robot, rng) -> None:
        leader = sim.robot("leader")
        leader.set_pose([rng.uniform(0.2, 0.8), rng.uniform(-0.5, 0.5), 0.0],
                        rotation=[0.0, 0.0, 1.0, rng.uniform(-math.pi, math.pi)])

    def beacon_reward(sim, robot, obs) -> float:       # the copy's own beacon, as its scene places it
        beacon = next(lt for lt in sim.scene.world_lights() if lt.name == "beacon")
        return -float(np.hypot(*(robot.pose.translation[:2] - np.asarray(beacon.location[:2]))))

    task = Task(robot="seeker", observations={"front": 32, "left": 32, "tinted": 32, "eye": 32},
                control_period_ms=32, max_steps=6, reward=beacon_reward, start=place_leader)
    world = _world(4)
    n = 3
    venv = SensoriumVectorEnv(world, task, n)
    singles = [SensoriumEnv(world, task, engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, 20)
    rng = np.random.default_rng(3)
    done = np.zeros(n, dtype=bool)
    resets = 0
    for t in range(14):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        k, obs = _step_both(venv, singles, a, done, t)
        resets += k
    assert resets >= n                                  # every sub-env went through an autoreset
    assert len({bytes(o) for o in obs["front"]}) == n
    check_env(SensoriumEnv(world, task, engine="batched"), skip_render_check=True)
    check_env(venv.sub_env(1), skip_render_check=True)
    assert gym is not None


def test_reach_light_toward_a_robots_beacon_takes_each_copys_beacon():
    """ReachLight("beacon") (its vectorised reward and termination) in the vector env, the beacon
    carried by the leader placed at random per episode: each sub-env's rewards and flags are the
    single env's with its seed (the target taken per copy at its reset, as the single env takes it
    at its reset), the arrival radius wide enough for some episodes to end on arrival."""
    pytest.importorskip("gymnasium")
    from sensorium.gym import ReachLight, SensoriumEnv, Task
    from sensorium.gym.vector import SensoriumVectorEnv
    from tests.test_gym_vector import _reset_both, _step_both

    def place_leader(sim, robot, rng) -> None:
        sim.robot("leader").set_pose([rng.uniform(-0.2, 0.6), rng.uniform(-0.5, 0.5), 0.0],
                                     rotation=[0.0, 0.0, 1.0, rng.uniform(-math.pi, math.pi)])

    def task() -> Task:
        goal = ReachLight("beacon", radius=0.45)
        return Task(robot="seeker", observations={"front": 32}, control_period_ms=32, max_steps=8, reward=goal,
                    terminated=goal.terminated, start=place_leader)

    n = 4
    venv = SensoriumVectorEnv(_world(4), task(), n)
    singles = [SensoriumEnv(_world(4), task(), engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, 7)
    terminated: list[np.ndarray] = []
    step = venv.step

    def recorded(a):
        out = step(a)
        terminated.append(out[2].copy())
        return out

    venv.step = recorded                               # type: ignore[method-assign]
    rng = np.random.default_rng(5)
    done = np.zeros(n, dtype=bool)
    for t in range(24):
        _step_both(venv, singles, rng.uniform(-1, 1, (n, 2)).astype(np.float32), done, t)
    goal = venv._goals[0]
    assert goal.targets is not None and len({goal.targets[c].tobytes() for c in range(n)}) == n   # each its own
    assert np.array(terminated).any()                  # some arrived at their leader's beacon


# ---------------------------------------------------------------- textured robot bodies

TEXTURED = Path(__file__).parent / "worlds" / "textured_robots.yaml"
TEXTURED_PERIODS = {"viewer": {"ir0": 16, "ir1": 32, "ir2": 16, "eye": 32}}


@pytest.fixture(scope="module")
def textured_dir(tmp_path_factory) -> Path:
    """The world's images, seeded random texels (written here, not committed): paint.png 8 x 6 RGB,
    rough.png 4 x 4 RGB (the roughness and occlusion maps), checker.png 8 x 8 (the floor)."""
    from PIL import Image
    d = tmp_path_factory.mktemp("textured_robots")
    rng = np.random.default_rng(13)
    for name, (h, w) in (("paint.png", (6, 8)), ("rough.png", (4, 4)), ("checker.png", (8, 8))):
        Image.fromarray(rng.integers(0, 256, (h, w, 3), dtype=np.uint8), "RGB").save(d / name)
    (d / TEXTURED.name).write_text(TEXTURED.read_text())
    return d


def _textured(seed: int, base: Path) -> LoadedWorld:
    lw = load_world(base / TEXTURED.name)
    info = lw.world.world_info.model_copy(update={"random_seed": seed})
    return LoadedWorld(world=lw.world.model_copy(update={"world_info": info}), source=lw.source, base_dir=base)


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_textured_robot_bodies_read_as_in_the_single_simulation(precision: str, textured_dir: Path):
    """A robot whose box body has a texture (repeated, transformed), a roughness map and an occlusion
    map, with a textured cylinder on top, driving slowly in front of a viewer with three infra-red
    sensors and a camera, over a textured floor, per-copy wheel commands, copy 2 reset on the way:
    every infra-red value and camera image of every copy, every step, equals the single
    simulation's with that copy's seed, bit for bit; the body's and the dome's texels were looked
    up, and the copies' images differ (each its own pose of the painted robot)."""
    seeds = [3, 4, 9]
    def textured(seed: int) -> LoadedWorld:
        return _textured(seed, textured_dir)

    bs, sims = copies_and_singles(textured, seeds, precision, TEXTURED_PERIODS)
    assert bs.robot_textures is not None
    rng = np.random.default_rng(2)
    textures = bs.robot_textures
    looked_up: list[int] = []                    # the robot shapes whose texels a copy read
    world_to_shape = textures.world_to_shape

    def counted(copy: int):
        inverse = world_to_shape(copy)

        def shape_pose(shape: int):
            if shape >= textures.n_static:
                looked_up.append(shape)
            return inverse(shape)
        return shape_pose

    textures.world_to_shape = counted            # type: ignore[method-assign]
    for step in range(40):
        if step % 10 == 0:
            for robot in ("painted", "viewer"):
                lr = rng.uniform(-2.0, 2.0, (len(seeds), 2))
                _wheels_both(bs, sims, robot, lr if robot == "painted" else 0.2 * lr)
        if step == 20:
            reseed_copy(bs, sims, textured, 2, 77, precision, TEXTURED_PERIODS)
        bs.step()
        for s in sims:
            s.step()
        for c, s in enumerate(sims):
            viewer = s.robot("viewer")
            for n in ("ir0", "ir1", "ir2"):
                want, got = viewer.device(n).value, float(bs.value(bs.device("viewer", n))[c])
                assert want == got or (math.isnan(want) and math.isnan(got)), (step, c, n, want, got)
            want_img = viewer.device("eye").image
            assert want_img.tobytes() == bs.image(bs.device("viewer", "eye"))[c].tobytes(), (step, c)
    n = textures.n_static
    assert {n, n + 1} <= set(looked_up)        # the box body and the dome were read, each many times
    assert min(looked_up.count(n), looked_up.count(n + 1)) > 10
    assert len({img.tobytes() for img in bs.image(bs.device("viewer", "eye"))}) == len(seeds)


def test_a_textured_robot_body_is_read_at_each_copys_pose(textured_dir: Path):
    """The painted robot turned differently in two copies, a noiseless infra-red sensor's single ray
    straight at its body: each copy's value is that of a Simulation with the robot placed so, and the
    two differ (a different texel under the ray), so the texture is read at each copy's own pose."""
    lw = _textured(1, textured_dir)
    viewer = lw.world.robots[1]
    ray = {"device": "DistanceSensor", "name": "probe", "type": "infra-red", "pose": {"translation": [0.05, 0.0, 0.05]},
           "lookup_table": [[0.0, 1000.0, 0.0], [0.6, 0.0, 0.0]]}
    viewer = viewer.model_copy(update={"devices": [wm.DistanceSensor.model_validate(ray)]})
    world = lw.world.model_copy(update={"robots": [lw.world.robots[0], viewer]})
    one = LoadedWorld(world=world, source=lw.source, base_dir=textured_dir)
    yaws = [0.1, 0.9]
    bs = BatchedSimulation(one, len(yaws))
    painted, ref = bs.slot("painted"), bs.device("viewer", "probe")
    for c, yaw in enumerate(yaws):
        bs.set_pose(c, painted, translation=[0.25, 0.0, 0.0], rotation=[0, 0, 1, yaw])
    bs.enable(ref, 16)
    bs.step()
    got = bs.value(ref)
    for c, yaw in enumerate(yaws):
        s = Simulation(one)
        s.robot("painted").set_pose(translation=[0.25, 0.0, 0.0], rotation=[0, 0, 1, yaw])
        s.robot("viewer").device("probe").enable(16)
        s.step()
        assert s.robot("viewer").device("probe").value == float(got[c])
    assert got[0] != got[1]
