"""Mecanum (youBot-like) robots in the batched simulation: every copy steps as the single
Simulation does, bit for bit (random wheel commands, position control included, contact on and off,
walls, another mecanum robot and a two-wheel robot in the world, set_pose, every device read; a
ramp it rides; a NUE world), the copies never see each other, a pure strafe ends where its closed
form says, a strafe against a wall stops at its face; as an agent, its four normalised wheel speeds
are the action of the single and the batched environments alike, bit for bit, and both pass
Gymnasium's checker."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedSimulation, DeviceRef
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests._motors import assert_same_readings

R, LX, LY = 0.05, 0.228, 0.158        # the youBot's wheel radius, half wheelbase, half track
STEP = 16
DT = STEP / 1000.0
# the drive's wheel order (front left, front right, rear left, rear right) with the youBot's names
FL, FR, RL, RR = "wheel2", "wheel1", "wheel4", "wheel3"
WHEELS = (FL, FR, RL, RR)
HALF_W = 0.15                          # the body's half width (box 0.5 x 0.3)


def youbot(name: str, x: float, y: float, **drive) -> dict:
    return {"name": name, "pose": {"translation": [x, y, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.5, 2 * HALF_W, 0.1]}},
            "mecanum_drive": {"wheel_radius": R, "lx": LX, "ly": LY, **drive},
            "devices": [{"device": "PositionSensor", "name": "fl sensor", "motor": FL},
                        {"device": "PositionSensor", "name": "rr sensor", "motor": RR, "noise": 0.01},
                        {"device": "GPS", "name": "gps", "accuracy": 0.002},
                        {"device": "Compass", "name": "compass"},
                        {"device": "InertialUnit", "name": "imu"},
                        {"device": "Gyro", "name": "gyro"},
                        {"device": "Accelerometer", "name": "acc"},
                        {"device": "TouchSensor", "name": "bumper", "type": "bumper"},
                        {"device": "DistanceSensor", "name": "front", "pose": {"translation": [0.26, 0.0, 0.0]},
                         "lookup_table": [[0, 0, 0], [1.0, 1000, 0.05]]}]}


def wall(name: str, x: float, y: float, sx: float, sy: float) -> dict:
    return {"name": name, "pose": {"translation": [x, y, 0.25]}, "geometry": {"type": "box", "size": [sx, sy, 0.5]}}


def world(contact: bool = True) -> object:
    """Two youBot-like robots (one driving along its own +y), a two-wheel robot and a block in a 2.2 m square."""
    two_wheel = {"name": "dd", "pose": {"translation": [-0.6, 0.6, 0.05]},
                 "body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.1}},
                 "differential_drive": {"wheel_radius": 0.03, "axle_length": 0.15, "max_wheel_speed": 20.0},
                 "devices": [{"device": "GPS", "name": "gps"}]}
    return parse_world({"world_info": {"basic_time_step": STEP, "contact": contact, "random_seed": 5},
                        "solids": [wall("north", 0, 1.2, 2.6, 0.2), wall("south", 0, -1.2, 2.6, 0.2),
                                   wall("east", 1.2, 0, 0.2, 2.2), wall("west", -1.2, 0, 0.2, 2.2),
                                   wall("block", 0.5, -0.6, 0.3, 0.3)],
                        "robots": [youbot("yb", 0.0, 0.0), youbot("yb2", 0.7, 0.6, forward=[0, 1]), two_wheel]})


def wheel_speeds(vx: float, vy: float, w: float) -> np.ndarray:
    """The four wheel speeds (front left, front right, rear left, rear right) of a body twist, the
    youBot's rollers (standard mecanum inverse kinematics)."""
    k = LX + LY
    return np.array([vx - vy - k * w, vx + vy + k * w, vx + vy - k * w, vx - vy + k * w]) / R


def random_commands(rng, w) -> dict:
    """Per drive motor: (a held position, a velocity, whether it holds the position). A mecanum
    robot's wheels 70 % of the time at one body twist, 0.45 m/s in a random direction (so that it
    reaches walls and the other robots; the fastest wheel's speed may be clamped), else each at its
    own random speed, full speed often."""
    out = {}
    for r in w.robots:
        vmax = 14.81 if r.mecanum_drive is not None else 20.0
        heading = rng.uniform(-math.pi, math.pi)
        twist = (wheel_speeds(0.45 * math.cos(heading), 0.45 * math.sin(heading), rng.uniform(-0.5, 0.5))
                 if rng.random() < 0.7 else None)
        for j, (_, m) in enumerate(r.drive_motors):
            vel = rng.choice([-vmax, vmax]) if rng.random() < 0.3 else rng.uniform(-vmax, vmax)
            if twist is not None and r.mecanum_drive is not None:
                vel = twist[j]
            out[(r.name, m)] = (rng.uniform(-5.0, 5.0), float(vel), twist is None and rng.random() < 0.2)
    return out


def command(sim, cmds: dict) -> None:
    for (name, m), (pos, vel, hold) in cmds.items():
        motor = sim.robot(name).motors[m]
        if hold:
            motor.set_position(motor.position + pos)
            motor.set_velocity(abs(vel))
        else:
            motor.set_position(math.inf)
            motor.set_velocity(vel)


def same_pose(sim, view, name: str) -> bool:
    a, b = sim.robot(name).pose, view.robot(name).pose
    return a.rotation.tobytes() == b.rotation.tobytes() and a.translation.tobytes() == b.translation.tobytes()


@pytest.mark.parametrize("contact", [True, False])
def test_every_copy_steps_as_the_single_simulation_bit_for_bit(contact):
    """Three copies, each against its own Simulation (world seeds 5, 6, 7), 400 steps of random
    commands changed every 40 steps (velocity and position control), a set_pose at step 200: every
    robot's pose and every device's reading the same bits every step; contact clipped moves."""
    batched, _, pressed = lockstep(world(contact), 400, (5, 6, 7), rng_seed=8, sample_ms=32,
                                   set_poses=(200, 1, {"yb": ([-0.5, -0.5, 0.1], [0, 0, 1, 0.7])}))
    if contact:
        assert pressed["yb"] + pressed["yb2"] > 20 and batched.counters["contacts"] > 0      # walls and robots were met
    else:
        assert batched.contact is None and pressed["yb"] + pressed["yb2"] == 0


def test_strafe_turn_and_diagonal_in_closed_form_each_copy_its_own():
    """Copy 0 strafes left, copy 1 turns on the spot, copy 2 moves diagonally (two wheels), copy 3
    drives a general twist, copy 4 stands: each ends where its closed form says after N steps, and
    equals its own single Simulation bit for bit."""
    w = parse_world({"world_info": {"basic_time_step": STEP},
                     "robots": [youbot("yb", 0.0, 0.0)]})
    n, N = 5, 250
    batched = BatchedSimulation(w, n)
    slot = batched.slot("yb")
    vx, vy, wz = 0.12, -0.07, 0.4
    speeds = np.array([wheel_speeds(0.0, 0.2, 0.0), wheel_speeds(0.0, 0.0, 0.9), [0.0, 6.0, 6.0, 0.0],
                       wheel_speeds(vx, vy, wz), [0.0] * 4])
    batched.mecanum.command(slot, speeds)
    batched.run(N)
    t = N * DT
    d = R * 6.0 / 2.0 * t
    s, c = math.sin(wz * t), math.cos(wz * t)
    expect = [(0.0, 0.2 * t, 0.0), (0.0, 0.0, math.remainder(0.9 * t, math.tau)), (d, d, 0.0),
              ((vx * s - vy * (1 - c)) / wz, (vx * (1 - c) + vy * s) / wz, math.remainder(wz * t, math.tau)),
              (0.0, 0.0, 0.0)]
    for k in range(n):
        rot, pos = batched.rot[k, slot], batched.pos[k, slot]
        got = (pos[0], pos[1], math.atan2(rot[1, 0], rot[0, 0]))
        assert got == pytest.approx(expect[k], abs=1e-9), k
        assert pos[2] == 0.1
        single = Simulation(w)
        for name, u in zip(WHEELS, speeds[k]):
            m = single.robot("yb").motor(name)
            m.set_position(math.inf)
            m.set_velocity(float(u))
        single.run(N)
        assert single.robot("yb").pose.translation.tobytes() == pos.tobytes(), k
        assert single.robot("yb").pose.rotation.tobytes() == rot.tobytes(), k
    assert (batched.rot[0, slot] == np.eye(3)).all()            # a pure strafe never turns


def test_a_pure_strafe_is_exact_in_closed_form_every_step():
    """All four wheels at ±ω in the strafe pattern: y = r·ω·t after every step, x and yaw exactly 0."""
    w = parse_world({"world_info": {"basic_time_step": STEP}, "robots": [youbot("yb", 0.0, 0.0)]})
    batched = BatchedSimulation(w, 2)
    batched.mecanum.command(0, [[-4.0, 4.0, 4.0, -4.0], [4.0, -4.0, -4.0, 4.0]])    # left, right
    for n in range(1, 101):
        batched.step()
        assert batched.pos[:, 0, 0].tolist() == [0.0, 0.0]
        assert batched.pos[:, 0, 1] == pytest.approx([R * 4.0 * n * DT, -R * 4.0 * n * DT], abs=1e-12)
        assert (batched.rot[:, 0] == np.eye(3)).all()


def plan_copies(w, plan: list[dict], drive: str, motors, bumper_of: str, steps: int) -> tuple[BatchedSimulation, DeviceRef]:
    """A copy of ``w`` per entry of ``plan`` ({robot: its wheels' speeds in ``motors``' order}), each
    commanded through the batched simulation's ``drive`` ("mecanum" or "omni"), run ``steps`` with the
    bumper of robot ``bumper_of`` enabled; beside each, a Simulation commanded alike whose poses (the
    plan's robots) and bumper reading are the copy's bit for bit. Returns the batched simulation and
    its bumper device."""
    batched = BatchedSimulation(w, len(plan))
    for name in plan[0]:
        getattr(batched, drive).command(batched.slot(name), [p[name] for p in plan])
    bumper = batched.device(bumper_of, "bumper")
    batched.enable(bumper, 16)
    batched.run(steps)
    for c, p in enumerate(plan):
        single = Simulation(w)
        single.device(f"{bumper_of}/bumper").enable(16)
        for name, speeds in p.items():
            for m, u in zip(motors, speeds):
                single.robot(name).motor(m).set_position(math.inf)
                single.robot(name).motor(m).set_velocity(u)
        single.run(steps)
        for name in p:
            pose = single.robot(name).pose
            slot = batched.slot(name)
            assert pose.translation.tobytes() == batched.pos[c, slot].tobytes(), (c, name)
            assert pose.rotation.tobytes() == batched.rot[c, slot].tobytes(), (c, name)
        assert single.device(f"{bumper_of}/bumper").value == batched.value(bumper)[c]
    return batched, bumper


LEFT, RIGHT, STAND = [-10.0, 10.0, 10.0, -10.0], [10.0, -10.0, -10.0, 10.0], [0.0] * 4


def test_strafes_against_a_wall_and_a_robot_stop_there_and_copies_never_meet():
    """A wall 1 m to the left of "yb", a robot "other" 1 m to its right. Copy 0: yb strafes right
    into the standing other and stops against it; copy 1: both strafe right at the same speed, so
    yb crosses where copy 0's other stands without meeting anything (copies never see each other);
    copy 2: yb strafes left and stops with its left side on the wall's face. Each copy equals its
    own single Simulation bit for bit; the bumper of the stopped ones reads 1."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": True},
                     "solids": [wall("wall", 0.0, 1.0, 4.0, 0.2)],
                     "robots": [youbot("yb", 0.0, 0.0), youbot("other", 0.0, -1.0)]})
    plan = [{"yb": RIGHT, "other": STAND}, {"yb": RIGHT, "other": RIGHT}, {"yb": LEFT, "other": STAND}]
    batched, bumper = plan_copies(w, plan, "mecanum", WHEELS, "yb", 100)       # 1.6 s at 0.5 m/s
    yb, other = batched.slot("yb"), batched.slot("other")
    assert batched.pos[0, yb, 1] == pytest.approx(-1.0 + 2 * HALF_W, abs=1e-6)      # side against side
    assert batched.pos[0, other, 1] == -1.0
    assert batched.pos[1, yb, 1] == pytest.approx(-0.8, abs=1e-9)
    assert batched.pos[1, other, 1] == pytest.approx(-1.8, abs=1e-9)
    assert batched.pos[2, yb, 1] == pytest.approx(0.9 - HALF_W, abs=1e-9)           # its left side on the face
    assert batched.pos[:, yb, 0].tolist() == [0.0] * 3 and (batched.rot[:, yb] == np.eye(3)).all()
    assert batched.value(bumper).tolist() == [1.0, 0.0, 1.0]


def test_set_wheels_on_a_mecanum_robot_says_how_to_command_it():
    batched = BatchedSimulation(parse_world({"robots": [youbot("yb", 0.0, 0.0)]}), 2)
    with pytest.raises(ValueError, match=r"^yb: a mecanum robot has no left and right wheels: command it with "
                                         r"mecanum.command\(slot, speeds\) \(copies, 4\)$"):
        batched.set_wheels(0, [1.0, 1.0], [1.0, 1.0])
    with pytest.raises(ValueError, match=r"^mecanum wheel speeds must be \(copies, 4\)"):
        batched.mecanum.command(0, [[1.0, 2.0]] * 2)


# ---------------------------------------------------------------- a mecanum agent (Gymnasium)

def agent_task(max_steps: int = 30, observations=("gps", "compass", "bumper", "front", "imu")):
    from sensorium.gym import Task
    from sensorium.gym.task import random_start

    return Task(robot="yb", control_period_ms=32, max_steps=max_steps, observations=list(observations),
                start=random_start((-0.8, 0.8), (-0.8, 0.8)))


@pytest.mark.parametrize("actions", ["normalized", "wheel"])
def test_sub_env_i_is_the_single_env_with_seed_i_across_autoresets(actions):
    """Random four-wheel actions (all four at one extreme a third of the time), episodes of 30
    actions, random starts, walls, a block and two other robots: every observation, reward, flag,
    clock and pose of sub-env i equals the single env (the rebuilt Simulation) reset with seed + i,
    bit for bit; the bumper was pressed."""
    gymnasium = pytest.importorskip("gymnasium")
    del gymnasium
    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv
    from tests.test_gym_vector import _reset_both, _step_both

    w = world(True)
    n, seed = 3, 21
    venv = SensoriumVectorEnv(w, agent_task(), n, actions=actions)
    singles = [SensoriumEnv(w, agent_task(), actions=actions, engine="simulation") for _ in range(n)]
    space = singles[0].action_space
    assert space.shape == (4,) and venv.action_space.shape == (n, 4)
    _reset_both(venv, singles, seed)
    rng = np.random.default_rng(3)
    done = np.zeros(n, dtype=bool)
    resets, pressed = 0, 0
    for t in range(90):
        a = rng.uniform(space.low, space.high, (n, 4)).astype(np.float32)
        if t % 3 == 0:          # a strafe, a turn or a drive at full speed
            a = np.tile(np.array([[-1, 1, 1, -1], [-1, 1, -1, 1], [1, 1, 1, 1]][t % 9 // 3], dtype=np.float32)
                        * space.high, (n, 1))
        got, vobs = _step_both(venv, singles, a, done, t)
        resets += got
        pressed += int((vobs["bumper"][:, 0] == 1.0).sum())
    assert resets >= 3 and pressed > 0


def test_a_normalised_strafe_action_moves_the_agent_left_in_closed_form_in_both_engines():
    """Action (-1, +1, +1, -1): every wheel at max_wheel_speed in the youBot's strafe pattern, so the
    robot slides left at r·ω_max without turning: after k actions of 32 ms its pose is (0, r·ω·t, 0)
    in the single env and in a batched sub-env alike, the same bits."""
    from sensorium.gym import SensoriumEnv, Task
    from sensorium.gym.vector import SensoriumVectorEnv

    w = parse_world({"world_info": {"basic_time_step": STEP}, "robots": [youbot("yb", 0.0, 0.0)]})
    task = Task(robot="yb", control_period_ms=32, max_steps=None, observations=["gps"])
    env = SensoriumEnv(w, task)
    venv = SensoriumVectorEnv(w, task, 2)
    env.reset(seed=0)
    venv.reset(seed=0)
    strafe = np.array([-1.0, 1.0, 1.0, -1.0], dtype=np.float32)
    warm = env.agent.warmup_steps
    for k in range(1, 41):
        info = env.step(strafe)[4]
        vinfo = venv.step(np.stack([strafe, -strafe]))[4]
        t = (k * 32) / 1000.0
        assert info["pose"] == pytest.approx([0.0, R * 14.81 * t, 0.0], abs=1e-12), (k, warm)
        assert info["pose"].tobytes() == vinfo["pose"][0].tobytes()
        assert vinfo["pose"][1] == pytest.approx([0.0, -R * 14.81 * t, 0.0], abs=1e-12)


def test_the_checker_passes_on_both_engines_and_a_sub_env():
    from gymnasium.utils.env_checker import check_env

    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv

    w = world(True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(SensoriumEnv(w, agent_task()), skip_render_check=True)
        check_env(SensoriumEnv(w, agent_task(), engine="batched"), skip_render_check=True)
        check_env(SensoriumVectorEnv(w, agent_task(), 3).sub_env(1), skip_render_check=True)


@pytest.mark.parametrize("bad", [[np.nan, 0.0, 0.0, 0.0], [0.1, 0.2], [0.1, 0.2, 0.3, 0.4, 0.5]])
def test_bad_actions_are_refused_in_one_line(bad):
    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv

    w = world(True)
    env = SensoriumEnv(w, agent_task())
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^yb: action must be 4 finite values \(in \[-1, 1\]: beyond it, clipped\) \(front left, front "
                                         r"right, rear left, rear right\), got .*$") as e:
        env.step(np.array(bad, dtype=np.float32))
    assert "\n" not in str(e.value)
    venv = SensoriumVectorEnv(w, agent_task(), 2)
    venv.reset(seed=0)
    if len(bad) == 4:
        with pytest.raises(ValueError, match="^sub-env 1: action must be 4 finite values"):
            venv.step(np.array([[0.0] * 4, bad], dtype=np.float32))
    else:
        with pytest.raises(ValueError, match=r"^actions must have shape \(2, 4\)"):
            venv.step(np.zeros((2, len(bad)), dtype=np.float32))


def parallel_engines_agree(w, robots: tuple[str, ...]):
    """Every robot of ``w`` (``robots``, in order) an agent of a PettingZoo env on each engine, random
    actions from the same seeds: every GPS observation, reward and flag the same bits until all are
    truncated after 20 actions. Returns the simulation engine's env (for its action spaces)."""
    from sensorium.gym import Task
    from sensorium.gym.multi import SensoriumParallelEnv

    assert SensoriumParallelEnv(w).possible_agents == list(robots)

    def make(engine):
        return SensoriumParallelEnv(w, {r: Task(robot=r, control_period_ms=32, max_steps=20, observations=["gps"])
                                        for r in robots}, engine=engine)
    a, b = make("simulation"), make("batched")
    oa, _ = a.reset(seed=7)
    ob, _ = b.reset(seed=7)
    rng = np.random.default_rng(0)
    for _ in range(25):
        assert all(np.asarray(oa[k]["gps"]).tobytes() == np.asarray(ob[k]["gps"]).tobytes() for k in oa)
        if not a.agents:
            break
        acts = {k: rng.uniform(-1, 1, a.action_space(k).shape).astype(np.float32) for k in a.agents}
        oa, ra, ta, ua, _ = a.step(acts)
        ob, rb, tb, ub, _ = b.step(acts)
        assert (ra, ta, ua) == (rb, tb, ub)
    assert not a.agents                                  # all truncated after 20 actions, robots stopped
    return a


def test_pettingzoo_mecanum_robots_are_agents_and_both_engines_agree():
    a = parallel_engines_agree(world(True), ("yb", "yb2", "dd"))
    assert a.action_space("yb").shape == (4,) and a.action_space("dd").shape == (2,)


def workers_agree(w, task, n: int, width: int) -> None:
    """SensoriumWorkersEnv (two processes) and the one-process vector env of ``n`` sub-envs of ``task``:
    the same action space, (n, ``width``) random actions, every reset and step the same (autoresets
    included); a wrong action shape refused in one line."""
    from sensorium.gym.vector import SensoriumVectorEnv
    from sensorium.gym.workers import SensoriumWorkersEnv
    from tests.test_gym_workers import _same

    ref, envs = SensoriumVectorEnv(w, task, n), SensoriumWorkersEnv(w, task, n, workers=2)
    try:
        assert envs.action_space == ref.action_space and envs.single_action_space.shape == (width,)
        _same(envs.reset(seed=2), ref.reset(seed=2), "reset")
        rng = np.random.default_rng(1)
        for t in range(12):
            a = rng.uniform(-1, 1, (n, width)).astype(np.float32)
            _same(envs.step(a), ref.step(a), f"step {t}")
        with pytest.raises(ValueError, match=rf"^actions must have shape \({n}, {width}\)"):
            envs.step(np.zeros((n, 2), dtype=np.float32))
    finally:
        ref.close()
        envs.close()


@pytest.mark.slow           # starts worker processes
def test_the_workers_env_carries_four_wheel_actions_bit_for_bit():
    """SensoriumWorkersEnv (two processes) shares (n, 4) actions: sub-env i equals the one-process
    vector env's, autoresets included."""
    workers_agree(world(True), agent_task(max_steps=5), 3, 4)


def lockstep(w, steps: int, seeds=(5, 6), commands=random_commands, rng_seed: int | None = None,
             sample_ms: int = 16, set_poses=None) -> tuple[BatchedSimulation, int, dict[str, int]]:
    """Copies of ``w`` (one per seed, the world's random_seed that seed) and a Simulation per copy, with
    ``commands(rng, world)`` per copy changed every 40 steps (rng seeded ``rng_seed``, by default the
    robots' count): every robot's pose and readings the same bits every step. Every device is
    sampled every ``sample_ms`` but the GPSs, every 16 ms; ``set_poses``, (step, copy, {robot:
    (translation, rotation)}), moves those robots by set_pose in that copy and its Simulation before
    that step. Returns the batched simulation, the copy-steps in which a robot was tilted (on a
    slope), and per robot the copy-steps in which it was pressed against something."""
    from sensorium.gym.views import CopySim

    n = len(seeds)
    batched = BatchedSimulation(w, n)
    batched.reset(np.arange(n), list(seeds))
    singles = [Simulation(w.world.model_copy(update={"world_info": w.world.world_info.model_copy(
        update={"random_seed": s})})) for s in seeds]
    views = [CopySim(batched, c) for c in range(n)]
    for s in (*singles, *views):
        for r in s.robots.values():
            for d in r.model.devices:
                r.device(d.name).enable(sample_ms if d.device != "GPS" else 16)
    rng = np.random.default_rng(len(w.world.robots) if rng_seed is None else rng_seed)
    tilted = 0
    pressed = {r.name: 0 for r in w.world.robots}
    for t in range(steps):
        if t % 40 == 0:
            cmds = [commands(rng, w.world) for _ in range(n)]
        if set_poses is not None and t == set_poses[0]:
            for s in (singles[set_poses[1]], views[set_poses[1]]):
                for name, (translation, rotation) in set_poses[2].items():
                    s.robot(name).set_pose(translation=translation, rotation=rotation)
        for c in range(n):
            command(singles[c], cmds[c])
            command(views[c], cmds[c])
            singles[c].step()
        batched.step()
        for c in range(n):
            for name in singles[c].robots:
                assert same_pose(singles[c], views[c], name), (t, c, name)
                assert_same_readings(singles[c], views[c], name, (t, c))
                pressed[name] += bool(singles[c].robot(name).pressing)
        tilted += int(batched.tilted.sum())
    return batched, tilted, pressed


def test_a_mecanum_robot_rides_a_ramp_as_in_the_single_simulation():
    """An elevation grid under the robot's start (a ramp rising 0.3 m over 1.5 m along x): the copies
    ride up and down it, tilted, the same bits as their Simulations."""
    ramp = {"name": "ramp", "pose": {"translation": [-1.0, -1.0, 0.0]},
            "geometry": {"type": "elevation_grid", "x_dimension": 4, "x_spacing": 0.5, "y_dimension": 4,
                         "y_spacing": 0.5, "height": [0.0, 0.1, 0.2, 0.3] * 4}}
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": True},
                     "solids": [ramp, wall("east", 1.2, 0, 0.2, 2.6)],
                     "robots": [youbot("yb", -0.4, -0.4)]})
    batched, tilted, _ = lockstep(w, 240)
    assert batched.ground is not None and tilted > 50          # it rode the ramp's slope


def test_a_nue_world_batches_mecanum_robots_bit_for_bit():
    """A NUE world (y up): the robot drives, strafes and turns on its ground plane between four walls,
    as in its Simulation, the same bits (poses turned into the world's axes), pressed against them."""
    body = {"geometry": {"type": "box", "size": [0.5, 0.1, 2 * HALF_W]}}
    robot = {"name": "yb", "pose": {"translation": [0.0, 0.1, 0.0]}, "body": body,
             "mecanum_drive": {"wheel_radius": R, "lx": LX, "ly": LY},
             "devices": [{"device": "GPS", "name": "gps"}, {"device": "InertialUnit", "name": "imu"},
                         {"device": "PositionSensor", "name": "fl sensor", "motor": FL}]}
    w = parse_world({"world_info": {"basic_time_step": STEP, "coordinate_system": "NUE", "contact": True},
                     "solids": [{"name": n, "pose": {"translation": [x, 0.25, z]},
                                 "geometry": {"type": "box", "size": [sx, 0.5, sz]}}
                                for n, x, z, sx, sz in (("w", 0.0, -0.7, 2.0, 0.2), ("e", 0.0, 0.7, 2.0, 0.2),
                                                        ("n", 0.9, 0.0, 0.2, 1.6), ("s", -0.9, 0.0, 0.2, 1.6))],
                     "robots": [robot]})
    batched, _, pressed = lockstep(w, 240)
    assert batched.to_enu is not None and sum(pressed.values()) > 0
