"""Car-like robots (``ackermann_drive``) as RL agents: the (steering, speed) action's closed forms
(a steady steering angle drives the bicycle model's circle, zero steering drives straight at r·ω,
+1 turns left whatever the motors' sense), the single env's episodes equal the batched vector env's
sub-envs bit for bit (three kinds of car, random actions, autoresets, walls and other robots), the
batched simulation equals the single one step by step, Gymnasium's checker, bad actions refused."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from sensorium.client.webots.vehicle.driver import ackermann_angles as client_angles  # noqa: E402
from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.gym.multi import SensoriumParallelEnv  # noqa: E402
from sensorium.gym.task import random_start  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402
from sensorium.server.sim.batched import BatchedSimulation  # noqa: E402
from sensorium.server.sim.motion import ackermann_angles  # noqa: E402
from sensorium.server.sim.simulation import Simulation  # noqa: E402
from sensorium.server.world.loader import load_world, parse_world  # noqa: E402
from tests._motors import assert_same_readings, command_motors, random_motor_commands  # noqa: E402
from tests.test_gym_vector import _reset_both, _step_both  # noqa: E402

WORLD = Path(__file__).parent / "worlds" / "cars.yaml"
L, TF, TR, RF, RR = 0.5, 0.36, 0.38, 0.08, 0.09      # the open-field car's geometry (m)
LIMIT, STEP = 0.5, 16                                # max_steering_angle (rad), basic step (ms)


def open_field(positive_steers: str = "right", kind: str = "propulsion") -> object:
    """A car alone on an empty plane (no walls, no noise), at the origin facing +x."""
    return parse_world({"world_info": {"basic_time_step": STEP},
                        "robots": [{"name": "car", "pose": {"translation": [0.0, 0.0, 0.1]},
                                    "body": {"geometry": {"type": "box", "size": [0.7, 0.4, 0.2]}},
                                    "ackermann_drive": {"wheelbase": L, "track_front": TF, "track_rear": TR,
                                                        "front_wheel_radius": RF, "rear_wheel_radius": RR,
                                                        "type": kind, "max_wheel_speed": 60.0,
                                                        "max_steering_angle": LIMIT, "max_steering_speed": 4.0,
                                                        "positive_steers": positive_steers},
                                    "devices": [{"device": "GPS", "name": "gps"}]}]})


def make_env(world, engine: str, actions: str = "wheel", **task) -> SensoriumEnv:
    return SensoriumEnv(world, Task(robot="car", max_steps=None, **task), actions=actions, engine=engine)


def settle_then_drive(env: SensoriumEnv, steer: float, omega: float, steps: int) -> np.ndarray:
    """Steer with the car standing until the wheels hold their angles, then drive ``steps`` steps
    at wheel speed ``omega``; the pose (x, y, yaw) the drive started from and ended at."""
    env.reset(seed=0)
    for _ in range(20):                 # 0.5 rad at 4 rad/s: within 8 steps
        env.step(np.array([steer, 0.0], dtype=np.float32))
    start = env.step(np.array([steer, 0.0], dtype=np.float32))[4]["pose"]
    assert (start == np.array([0.0, 0.0, 0.0])).all()            # steering alone does not move the car
    for _ in range(steps):
        info = env.step(np.array([steer, omega], dtype=np.float32))[4]
    return info["pose"]


def f32(x: float) -> float:
    return float(np.float32(x))


def arc(radius: float, travelled: float) -> list[float]:
    """Where a left circle of ``radius`` about (0, radius) ends after ``travelled`` metres from the
    origin facing +x: (x, y, yaw)."""
    theta = travelled / radius
    return [radius * math.sin(theta), radius * (1.0 - math.cos(theta)), theta]


def test_the_env_steers_through_the_vehicle_librarys_ackermann_angles():
    for delta in (0.05, 0.3, -0.45, 1e-9):
        assert ackermann_angles(delta, L, TF) == client_angles(delta, L, TF)     # bit for bit
    assert ackermann_angles(0.0, L, TF) == (0.0, 0.0)


@pytest.mark.parametrize("engine", ["simulation", "batched"])
@pytest.mark.parametrize("positive_steers", ["right", "left"])
def test_a_steady_steering_angle_drives_the_bicycle_models_circle(engine, positive_steers):
    """δ = 0.3 rad (left): the front wheels at the Ackermann angles (inner below the limit), so the
    rear axle's centre circles at R = L / tan δ about (0, R) at r·ω: a quarter turn in N steps ends
    at (R, R) facing +y, whichever way the motors count."""
    delta, n = 0.3, 100
    radius = L / math.tan(delta)
    omega = (math.pi / 2) * radius / (RR * n * STEP / 1000.0)
    end = settle_then_drive(make_env(open_field(positive_steers), engine), delta, omega, n)
    # (the action is float32: the angle and speed driven are float32(0.3) and float32(ω))
    assert end == pytest.approx(arc(L / math.tan(f32(delta)), RR * f32(omega) * n * STEP / 1000.0), abs=1e-9)
    assert end == pytest.approx([radius, radius, math.pi / 2], abs=2e-6)


@pytest.mark.parametrize("engine", ["simulation", "batched"])
def test_full_lock_clamps_the_inner_wheel_and_circles_at_the_compromise_radius(engine):
    """A normalised +1 asks for δ = max_steering_angle: the inner (left) wheel's Ackermann angle
    exceeds the limit and stops there, the outer keeps its own (cot = cot δ + t/2L), and the turn
    radius is L·(cot δ_inner + cot δ_outer)/2 = L·cot δ + t/4 (README)."""
    n = 80
    radius = L / math.tan(LIMIT) + TF / 4
    omega = (math.pi / 2) * radius / (RR * n * STEP / 1000.0)
    env = make_env(open_field(), engine, actions="normalized")
    end = settle_then_drive(env, 1.0, omega / 60.0, n)
    right, left = (env.sim.robot("car").motors[m].position for m in ("right_steer", "left_steer"))
    assert left == -LIMIT and right == -math.atan(1.0 / (1.0 / math.tan(LIMIT) + TF / (2 * L)))
    assert end == pytest.approx(arc(radius, RR * f32(omega / 60.0) * 60.0 * n * STEP / 1000.0), abs=1e-9)
    assert end == pytest.approx([radius, radius, math.pi / 2], abs=2e-6)


@pytest.mark.parametrize("engine", ["simulation", "batched"])
@pytest.mark.parametrize("kind", ["propulsion", "traction", "4x4"])
def test_zero_steering_drives_straight_at_r_omega(engine, kind):
    n, omega = 50, 20.0                 # (exact in float32)
    end = settle_then_drive(make_env(open_field(kind=kind), engine), 0.0, omega, n)
    r = RR if kind == "propulsion" else RF if kind == "traction" else None
    if r is None:       # 4x4: every wheel at ω, the centre at the mean of their rolling speeds
        r = (RF + RR) / 2
    assert end == pytest.approx([r * omega * n * STEP / 1000.0, 0.0, 0.0], abs=1e-9)


def test_the_action_space_is_steering_and_speed():
    env = make_env(WORLD, "simulation")
    assert env.action_space == gym.spaces.Box(np.array([-0.5, -30.0], dtype=np.float32),
                                              np.array([0.5, 30.0], dtype=np.float32), dtype=np.float32)
    assert SensoriumEnv(WORLD, Task(robot="van")).action_space == gym.spaces.Box(-1.0, 1.0, (2,), np.float32)
    # the first driven robot of the world is the default agent: here a car
    assert SensoriumEnv(WORLD).agent.robot == "car"


def test_a_raw_steering_angle_beyond_the_limit_is_the_limit():
    a, b = make_env(open_field(), "simulation"), make_env(open_field(), "simulation")
    for env, steer in ((a, 0.5), (b, 7.0)):
        env.reset(seed=0)
        for _ in range(30):
            info = env.step(np.array([steer, 25.0], dtype=np.float32))[4]
        env.final = info["pose"]
    assert a.final.tobytes() == b.final.tobytes() and a.final[2] > 0.5


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return set(a) == set(b) and all(np.asarray(a[k]).tobytes() == np.asarray(b[k]).tobytes() for k in a)
    return np.asarray(a).tobytes() == np.asarray(b).tobytes()


def task(robot: str, max_steps: int = 25, observations=None) -> Task:
    return Task(robot=robot, control_period_ms=32, max_steps=max_steps, observations=observations,
                start=random_start((-1.8, 1.8), (-1.8, 1.8)))


@pytest.mark.parametrize("actions", ["normalized", "wheel"])
@pytest.mark.parametrize("robot", ["car", "van", "cart", "bot"])
def test_sub_env_i_is_the_single_env_with_seed_i_across_autoresets(robot, actions):
    """Random actions, full speed half of the time (walls, the ball, the other robots, the ramp),
    episodes of 25 actions: every observation, reward, flag, clock and pose of sub-env i equals
    the single env reset with seed + i, on the rebuilt Simulation, bit for bit (the two-wheel
    "bot" too, among standing cars)."""
    n, seed = 3, 11
    venv = SensoriumVectorEnv(WORLD, task(robot), n, actions=actions)
    singles = [SensoriumEnv(WORLD, task(robot), actions=actions, engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, seed)
    space = singles[0].action_space
    rng = np.random.default_rng(2)
    done = np.zeros(n, dtype=bool)
    resets, pressed = 0, 0
    for t in range(60):
        a = rng.uniform(space.low, space.high, (n, 2)).astype(np.float32)
        if t % 20 < 10:
            a[:, 1] = space.high[1]                         # full speed ahead
        got, vobs = _step_both(venv, singles, a, done, t)
        resets += got
        pressed += int((vobs["bumper"][:, 0] == 1.0).sum())
    assert resets >= 3 and pressed > 0                      # episodes restarted; cars pushed against things


def test_a_car_driving_into_a_wall_stops_there_in_both_engines():
    """Straight at the east wall (inner face x = 2.4) from x = 0.3, clear of the other robots: the body's front face stops at the wall,
    the bumper reads 1, the same bits on the rebuilt Simulation and the batched engine."""
    def put(sim, robot, rng):
        robot.set_pose(translation=[0.3, -0.45, 0.1], rotation=[0, 0, 1, 0])

    got = []
    for engine in ("simulation", "batched"):
        env = SensoriumEnv(WORLD, Task(robot="car", control_period_ms=32, max_steps=None, start=put), engine=engine)
        env.reset(seed=3)
        trace = [env.step(np.array([0.0, 1.0], dtype=np.float32)) for _ in range(40)]
        got.append(trace)
        x = trace[-1][4]["pose"][0]
        half = 0.35                                         # the box body's half length: its front face on the wall
        assert x == pytest.approx(2.4 - half, abs=1e-9) and trace[-1][0]["bumper"][0] == 1.0
        assert trace[-1][4]["pose"][1] == -0.45
    for (o1, *_, i1), (o2, *_, i2) in zip(*got):
        assert _same(o1, o2) and _same(i1["pose"], i2["pose"])


def test_the_batched_simulation_drives_cars_as_the_simulation_step_by_step():
    """Every robot of the world (three cars, a two-wheel robot) commanded through its motors with
    position and velocity control, set_pose, every device enabled: poses and readings equal."""
    loaded = load_world(WORLD)
    sim = Simulation(loaded)
    batched = BatchedSimulation(loaded, 2)
    from sensorium.gym.views import CopySim
    view = CopySim(batched, 1)
    rng = np.random.default_rng(4)
    for s in (sim, view):
        for r in s.robots.values():
            for d in r.model.devices:
                r.device(d.name).enable(32)
    for t in range(120):
        if t % 15 == 0:
            cmds = random_motor_commands(rng, loaded.world)
        if t == 60:
            for s in (sim, view):
                s.robot("van").set_pose(translation=[0.0, -1.0, 0.1])
        for s in (sim, view):
            command_motors(s, cmds)
            s.step()
        for name in sim.robots:
            assert sim.robot(name).pose.rotation.tobytes() == view.robot(name).pose.rotation.tobytes(), (t, name)
            assert sim.robot(name).pose.translation.tobytes() == view.robot(name).pose.translation.tobytes()
            assert_same_readings(sim, view, name, t)


def test_the_checker_passes_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # (wheel encoders are unbounded boxes, which the checker warns about: not observed here)
        check_env(SensoriumEnv(WORLD, task("car", observations=["front", "bumper", "gps", "imu", "gyro"])),
                  skip_render_check=True)
        check_env(SensoriumEnv(WORLD, task("van", observations=["front", "compass"]), engine="batched"),
                  skip_render_check=True)
        check_env(SensoriumVectorEnv(WORLD, task("cart", observations=["bumper"]), 3).sub_env(1), skip_render_check=True)


def test_pettingzoo_cars_are_agents_and_both_engines_agree():
    from pettingzoo.test import parallel_api_test

    def make(engine):
        return SensoriumParallelEnv(WORLD, {r: Task(robot=r, control_period_ms=32, max_steps=30)
                                            for r in ("car", "van", "cart", "bot")}, engine=engine)
    parallel_api_test(make("auto"), num_cycles=20)
    a, b = make("simulation"), make("batched")
    assert SensoriumParallelEnv(WORLD).possible_agents == ["car", "van", "cart", "bot"]
    oa, _ = a.reset(seed=7)
    ob, _ = b.reset(seed=7)
    rng = np.random.default_rng(0)
    for _ in range(30):
        assert all(_same(oa[k], ob[k]) for k in oa)
        if not a.agents:
            break
        acts = {k: rng.uniform(-1, 1, 2).astype(np.float32) for k in a.agents}
        oa, ra, ta, ua, _ = a.step(acts)
        ob, rb, tb, ub, _ = b.step(acts)
        assert (ra, ta, ua) == (rb, tb, ub)


@pytest.mark.parametrize("bad", [[np.nan, 0.0], [0.0, np.inf], [0.1, 0.2, 0.3], [[0.1, 0.2]] * 2])
def test_bad_actions_are_refused_in_one_line(bad):
    env = SensoriumEnv(WORLD, task("car"))
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^car: action must be 2 finite values \(in \[-1, 1\]: beyond it, clipped\) \(steering, speed\), "
                                         r"got .*$") as e:
        env.step(np.array(bad, dtype=np.float32))
    assert "\n" not in str(e.value)
    venv = SensoriumVectorEnv(WORLD, task("car"), 2)
    venv.reset(seed=0)
    if np.asarray(bad).shape == (2,):
        with pytest.raises(ValueError, match="^sub-env 1: action must be 2 finite values"):
            venv.step(np.array([[0.0, 0.0], bad], dtype=np.float32))
    else:
        with pytest.raises(ValueError, match=r"actions must have shape \(2, 2\)"):
            venv.step(np.zeros((2, 3), dtype=np.float32))


def test_a_world_without_a_drive_has_no_agent():
    w = parse_world({"robots": [{"name": "pole"}]})
    with pytest.raises(ValueError, match="no robot with a differential_drive, an ackermann_drive, a mecanum_drive or an omni_drive to act as the agent"):
        SensoriumEnv(w)


def test_avoid_obstacles_reward_refuses_a_car_in_one_line():
    from sensorium.gym import AvoidObstacles

    goal = AvoidObstacles()
    for env in (SensoriumEnv(WORLD, Task(robot="car", reward=goal)),
                SensoriumVectorEnv(WORLD, Task(robot="car", reward=goal), 2)):
        env.reset(seed=0)
        with pytest.raises(ValueError, match=r"^AvoidObstacles' reward reads a left and a right wheel speed: "
                                             r"robot 'car' has no differential_drive"):
            env.step(np.zeros((2, 2) if isinstance(env, SensoriumVectorEnv) else 2, dtype=np.float32))
    # its termination (clearance alone) works for a car
    env = SensoriumEnv(WORLD, Task(robot="car", terminated=goal.terminated))
    env.reset(seed=0)
    assert env.step(np.zeros(2, dtype=np.float32))[2] is False


def test_set_wheels_on_a_car_says_how_to_command_it():
    sim = BatchedSimulation(load_world(WORLD), 2)
    with pytest.raises(ValueError, match=r"^car: a car-like robot has no left and right wheels: command it with "
                                         r"cars.command"):
        sim.set_wheels(sim.slot("car"), [1.0, 1.0], [1.0, 1.0])


def test_the_registered_car_task_is_checked_and_batched_bit_for_bit():
    """sensorium/CarReachLight-v0 (the bundled car_park world): the checker without warnings on the
    single env and a sub-env, and sub-env i equals gym.make's env with seed 3 + i, autoresets included."""
    import sensorium.gym  # noqa: F401  (registers the ids)

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(gym.make("sensorium/CarReachLight-v0").unwrapped)
        venv = gym.make_vec("sensorium/CarReachLight-v0", num_envs=2, vectorization_mode="vector_entry_point",
                            render_mode="rgb_array", max_steps=15)
        check_env(venv.unwrapped.sub_env(1), skip_render_check=False)
    singles = [gym.make("sensorium/CarReachLight-v0", max_steps=15).unwrapped for _ in range(2)]
    obs, _ = venv.reset(seed=3)
    for i, env in enumerate(singles):
        assert _same({k: v[i] for k, v in obs.items()}, env.reset(seed=3 + i)[0])
    rng = np.random.default_rng(0)
    done = np.zeros(2, dtype=bool)
    moved = 0.0
    for t in range(40):
        a = rng.uniform(-1, 1, (2, 2)).astype(np.float32)
        a[:, 1] = np.abs(a[:, 1])                        # forward
        vobs, vr, vte, vtr, vinfo = venv.step(a)
        for i, env in enumerate(singles):
            if done[i]:
                o, r, te, tr = env.reset()[0], 0.0, False, False
            else:
                o, r, te, tr, inf = env.step(a[i])
                moved += abs(r)
            assert _same({k: v[i] for k, v in vobs.items()}, o) and (r, te, tr) == (vr[i], vte[i], vtr[i]), (t, i)
            done[i] = te or tr
    assert moved > 0.0                                    # the progress reward moved
