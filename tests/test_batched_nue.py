"""The batched simulation and vector env in NUE worlds (y up, Webots before R2022a): each copy is the
single Simulation with its seed, bit for bit (poses, every device value, noise); contact in NUE
stops a robot at a wall as in ENU; the vector env is the single env across autoresets."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, default_world_path, load_world
from sensorium.server.world.poses import axis_angle, axis_angle_matrix
from tests._motors import assert_same_readings, command_motors, random_motor_commands
from tests.test_batched_sim import _assert_same, _wheels_both

# ENU -> NUE (x north, y up, z east): the rows of NUE's axes in ENU
TO_NUE = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])

EPUCK = ["ls0", "ls1", *[f"ps{i}" for i in range(8)]]
SCOUT = ["lidar", "sonar_front", "sonar_left"]
MOTION = ["gps", "compass", "imu", "gyro", "acc", "alt"]


def _turn_pose(pose: dict) -> None:
    """A top-level pose of the ENU arena turned into NUE axes (the same place in the world)."""
    r = axis_angle_matrix(pose["rotation"][:3], pose["rotation"][3]) if "rotation" in pose else np.eye(3)
    pose["translation"] = (TO_NUE @ np.array(pose.get("translation", [0.0, 0.0, 0.0]), dtype=float)).tolist()
    pose["rotation"] = axis_angle(TO_NUE @ r)


def _to_nue(world: wm.World) -> dict:
    """An ENU world's data written in NUE axes: every top-level solid, robot and light turned."""
    data = world.model_dump(mode="json", exclude_none=True)
    data["world_info"]["coordinate_system"] = "NUE"
    for item in data.get("solids", []) + data.get("robots", []):
        _turn_pose(item.setdefault("pose", {}))
    for light in data.get("lights", []):
        for key in ("location", "direction"):
            if key in light:
                light[key] = (TO_NUE @ np.array(light[key], dtype=float)).tolist()
    return data


def nue_arena(seed: int, wgs84: bool = False) -> LoadedWorld:
    """The default arena written in NUE axes: every solid, robot and light turned, so a robot's own
    frame is still x forward, z up (its devices unchanged); the scout carries noisy motion sensors."""
    lw = load_world(default_world_path())
    data = _to_nue(lw.world)
    data["world_info"].update(random_seed=seed)
    if wgs84:
        data["world_info"].update(gps_coordinate_system="WGS84", gps_reference=[46.5, 6.6, 372.0])
    scout = next(r for r in data["robots"] if r["name"] == "scout")
    scout["devices"] += [
        {"device": "GPS", "name": "gps", "pose": {"translation": [0.05, 0.02, 0.07]}, "accuracy": 0.01,
         "noise_correlation": 0.5},
        {"device": "Compass", "name": "compass", "resolution": 0.001},
        {"device": "InertialUnit", "name": "imu", "noise": 0.01},
        {"device": "Gyro", "name": "gyro"},
        {"device": "Accelerometer", "name": "acc", "pose": {"translation": [0.1, 0.0, 0.0]}},
        {"device": "Altimeter", "name": "alt", "accuracy": 0.02}]
    return LoadedWorld(world=wm.World.model_validate(data), source="nue_arena", base_dir=lw.base_dir)


@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("wgs84", [False, True])
def test_every_copy_of_a_nue_world_is_the_single_simulation_with_its_seed(precision, wgs84):
    """Both robots drive (full speed into walls, then at random); light and distance sensors, the
    lidar, GPS, compass, inertial unit, gyro, accelerometer and altimeter are enabled; after every
    basic step each copy's poses, clock and values are its Simulation's, bit for bit."""
    seeds = [21, 22, 23]
    bs = BatchedSimulation(nue_arena(0, wgs84), len(seeds), precision=precision)
    bs.reset(np.arange(3), seeds)
    sims = [Simulation(nue_arena(s, wgs84), precision=precision) for s in seeds]
    periods = {"ls0": 64, "lidar": 64, "ps3": 96, "gps": 64, "imu": 96}
    for robot, names in (("epuck", EPUCK), ("scout", SCOUT + MOTION)):
        for n in names:
            bs.enable(bs.device(robot, n), periods.get(n, 32))
            for s in sims:
                s.robot(robot).device(n).enable(periods.get(n, 32))
    # the scout put 0.25 m short of the north wall, facing it (supervisor-style, in NUE axes)
    facing_north = axis_angle(TO_NUE @ axis_angle_matrix([0.0, 0.0, 1.0], math.pi / 2))
    for c, s in enumerate(sims):
        bs.set_pose(c, bs.slot("scout"), [1.75, 0.06, 0.3 * c], rotation=facing_north)
        s.robot("scout").set_pose([1.75, 0.06, 0.3 * c], rotation=facing_north)
    rng = np.random.default_rng(0)
    pressed = 0
    for step in range(60):
        if step % 4 == 0:
            for robot in ("epuck", "scout"):
                vmax = float(bs.max_wheel[bs.slot(robot), 0])
                _wheels_both(bs, sims, robot, np.full((3, 2), vmax) if step < 32 else rng.uniform(-vmax, vmax, (3, 2)))
        bs.step()
        for s in sims:
            s.step()
            pressed += s.robot("scout").pressing
        _assert_same(bs, sims, step, (("epuck", EPUCK), ("scout", SCOUT + MOTION)))
        assert (bs.pressing[:, bs.slot("scout")] == [s.robot("scout").pressing for s in sims]).all()
    # the robots moved on NUE's ground plane (x north, z east): their heights (y) never changed
    assert (bs.pos[:, :, 1] == np.array([r.pose.translation[1] for r in sims[0].world.robots])).all()
    assert pressed > 10                                   # the scout pushed against the wall
    ps = bs.value(bs.device("epuck", "ps0"))
    assert len(set(ps.tolist())) == 3                    # each copy's own noise


def _wall_world() -> wm.World:
    """A NUE world: a robot (a sphere of radius 0.04 on the ground, its own frame y up) facing a
    wall whose near face is 0.55 m ahead along north (+x)."""
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "coordinate_system": "NUE"},
        "solids": [{"name": "wall", "pose": {"translation": [0.6, 0.1, 0.0]}, "geometry": {"type": "box", "size": [0.1, 0.2, 2.0]}}],
        "robots": [{"name": "bot", "pose": {"translation": [0.0, 0.04, 0.0]},
                    "body": {"geometry": {"type": "sphere", "radius": 0.04}},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10.0}}]})


def test_a_robot_drives_straight_along_nue_x_at_r_omega_and_stops_at_a_wall():
    """Closed forms: wheels at omega move a NUE robot along its heading (+x, north) by r*omega*t,
    its height (y) and east (z) unchanged; pushed on, contact stops it where its footprint (the
    sphere's section, radius 0.04, however its frame is turned) meets the wall's face at x = 0.55,
    in the single simulation and every batched copy alike."""
    r, omega, dt = 0.02, 5.0, 0.016
    world = _wall_world()
    bs = BatchedSimulation(world, 2)
    sim = Simulation(world)
    bs.set_wheels(0, np.full(2, omega), np.full(2, omega))
    for m in sim.robot("bot").motors.values():
        m.set_position(math.inf)
        m.set_velocity(omega)
    for _ in range(100):                                  # 1.6 s: 0.16 m
        bs.step()
        sim.step()
    x, y, z = sim.robot("bot").pose.translation
    assert x == pytest.approx(r * omega * 100 * dt, abs=1e-12) and y == 0.04 and abs(z) < 1e-15
    assert (bs.pos == sim.robot("bot").pose.translation).all()
    assert (bs.rot == sim.robot("bot").pose.rotation).all() and (bs.rot == np.eye(3)).all()
    for _ in range(400):                                  # 6.4 s more: far past the wall without contact
        bs.step()
        sim.step()
    stop = 0.55 - 0.04
    assert sim.robot("bot").pose.translation[0] == pytest.approx(stop, abs=1e-9)
    assert (bs.pos[:, 0, 0] == sim.robot("bot").pose.translation[0]).all() and bs.pressing.all()


def test_the_vector_env_in_a_nue_world_is_the_single_env_across_autoresets():
    """gym.make_vec's batched env on a NUE world: sub-env i and the single env (a rebuilt
    Simulation) with seed 5 + i agree on observations (lidar, sonar, GPS, compass, inertial unit),
    rewards, flags and pose info across autoresets; both pass Gymnasium's checker."""
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    from sensorium.gym import SensoriumEnv, Task
    from sensorium.gym.vector import SensoriumVectorEnv
    from tests.test_gym_vector import _reset_both, _step_both

    world = nue_arena(0)
    task = Task(robot="scout", observations=["lidar", "sonar_front", "gps", "compass", "imu"], max_steps=12,
                control_period_ms=64)
    n = 3
    venv = SensoriumVectorEnv(world, task, n, precision="fast")
    singles = [SensoriumEnv(world, task, precision="fast", engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, 5)
    rng = np.random.default_rng(2)
    done = np.zeros(n, dtype=bool)
    resets = 0
    for t in range(40):
        resets += _step_both(venv, singles, rng.uniform(-1, 1, (n, 2)).astype(np.float32), done, t)[0]
    assert resets >= 3
    venv.close()
    assert SensoriumEnv(world, task, engine="auto").engine == "batched"
    # the registered ids on this world: make_vec gives the batched env, and the checker says nothing
    with warnings.catch_warnings():
        warnings.simplefilter("error")                    # any checker warning fails the test
        venv = gym.make_vec("sensorium/LidarAvoid-v0", num_envs=2, vectorization_mode="vector_entry_point",
                            world=world, max_steps=8)
        assert isinstance(venv.unwrapped, SensoriumVectorEnv)
        venv.reset(seed=0)
        venv.step(np.ones((2, 2), dtype=np.float32))
        check_env(venv.unwrapped.sub_env(1))
        check_env(gym.make("sensorium/LidarAvoid-v0", world=world, engine="batched").unwrapped)
        check_env(gym.make("sensorium/LidarAvoid-v0", world=world, engine="simulation").unwrapped)


def test_cars_and_a_terrain_in_a_nue_world_are_the_single_simulation_step_by_step():
    """tests/worlds/cars.yaml turned into NUE (three cars, a two-wheel robot, a ramp they ride):
    every robot commanded through its motors (position and velocity control), a supervisor move,
    every device enabled: the batched copy's poses and readings are the Simulation's, bit for bit."""
    from pathlib import Path

    from sensorium.gym.views import CopySim

    cars = load_world(Path(__file__).parent / "worlds" / "cars.yaml")
    loaded = LoadedWorld(world=wm.World.model_validate(_to_nue(cars.world)), source="cars_nue", base_dir=cars.base_dir)
    sim = Simulation(loaded)
    view = CopySim(BatchedSimulation(loaded, 2), 1)
    rng = np.random.default_rng(4)
    for s in (sim, view):
        for r in s.robots.values():
            for d in r.model.devices:
                r.device(d.name).enable(32)
    rode = 0
    for t in range(120):
        if t % 15 == 0:
            cmds = random_motor_commands(rng, loaded.world)
        if t == 60:
            for s in (sim, view):
                s.robot("van").set_pose(translation=(TO_NUE @ [0.0, -1.0, 0.1]).tolist())
        for s in (sim, view):
            command_motors(s, cmds)
            s.step()
        for name in sim.robots:
            pose = sim.robot(name).pose
            assert pose.rotation.tobytes() == view.robot(name).pose.rotation.tobytes(), (t, name)
            assert pose.translation.tobytes() == view.robot(name).pose.translation.tobytes(), (t, name)
            rode += abs(pose.rotation[1, 1]) < 1.0 - 1e-9       # tilted off NUE's up (y): on the ramp
            assert_same_readings(sim, view, name, t)
    assert rode > 0
