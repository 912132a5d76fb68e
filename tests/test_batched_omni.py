"""Omni-wheel robots (``omni_drive``) and two-wheel robots whose wheels' centre is off their origin
(``differential_drive.axle_center``, a Boe-Bot) in the batched simulation: every copy steps as its
own single Simulation, bit for bit (random wheel commands, position control included, contact on
and off, walls, a three-wheeler, a four-wheeler, a mecanum robot, an off-centre two-wheel and an
off-centre skid-steer robot in one world, set_pose, every device read; a ramp; a NUE world); closed
forms: an omni robot with every wheel at one speed turns in place at r·ω/L, an off-centre robot
turning in place circles about its wheels' centre; a strafe into a wall or a robot stops at its
face, copies never meeting; as an agent, an omni robot's wheel speeds are the action of the single
and the batched environments alike, bit for bit, and both pass Gymnasium's checker."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests.test_batched_mecanum import lockstep, parallel_engines_agree, plan_copies, wall, workers_agree, youbot

STEP = 16
DT = STEP / 1000.0
R3, L3 = 0.05, 0.1            # the three-wheeler's wheel radius and its wheels' distance from its centre
R4, L4 = 0.04, 0.12           # the four-wheeler's (wheels at the corners of a square, axes pointing out)
BODY3, BODY4 = 0.12, 0.16     # their bodies' radii (cylinders)
RB, AXLE, CX = 0.033, 0.1, 0.025      # the Boe-Bot-like robot: wheel radius, axle length, centre ahead


def omni_wheels(count: int, dist: float, radius: float, first: float) -> list[dict]:
    """``count`` wheels ``dist`` from the centre, the first at angle ``first``, axes pointing out."""
    out = []
    for i in range(count):
        t = first + i * 2.0 * math.pi / count
        out.append({"motor": f"wheel{i + 1}", "position": [dist * math.cos(t), dist * math.sin(t)],
                    "axis": [math.cos(t), math.sin(t)], "radius": radius})
    return out


def sensors(first_wheel: str, second_wheel: str) -> list[dict]:
    return [{"device": "PositionSensor", "name": "enc", "motor": first_wheel},
            {"device": "PositionSensor", "name": "noisy enc", "motor": second_wheel, "noise": 0.01},
            {"device": "GPS", "name": "gps", "accuracy": 0.002},
            {"device": "Compass", "name": "compass"},
            {"device": "InertialUnit", "name": "imu"},
            {"device": "Gyro", "name": "gyro"},
            {"device": "Accelerometer", "name": "acc"},
            {"device": "TouchSensor", "name": "bumper", "type": "bumper"},
            {"device": "DistanceSensor", "name": "front", "pose": {"translation": [0.2, 0.0, 0.0]},
             "lookup_table": [[0, 0, 0], [1.0, 1000, 0.05]]}]


def omni(name: str, x: float, y: float, count: int = 3, yaw: float = 0.0) -> dict:
    dist, radius, body = (L3, R3, BODY3) if count == 3 else (L4, R4, BODY4)
    return {"name": name, "pose": {"translation": [x, y, 0.05], "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "cylinder", "radius": body, "height": 0.05}},
            "omni_drive": {"max_wheel_speed": 12.0,
                           "wheels": omni_wheels(count, dist, radius, math.pi if count == 3 else math.pi / 4)},
            "devices": sensors("wheel1", "wheel2")}


def boebot(name: str, x: float, y: float, skid: bool = False) -> dict:
    drive = {"wheel_radius": RB, "axle_length": AXLE, "max_wheel_speed": 12.0, "axle_center": [CX, 0.0]}
    if skid:
        drive["skid_steer"] = {"left": ["rear left"], "right": ["rear right"]}
    return {"name": name, "pose": {"translation": [x, y, 0.04]},
            "body": {"geometry": {"type": "box", "size": [0.12, 0.1, 0.05]}},
            "differential_drive": drive, "devices": sensors("left wheel motor", "right wheel motor")}


def world(contact: bool = True):
    """A three-wheeler, a four-wheeler, a mecanum robot, an off-centre two-wheel and an off-centre
    skid-steer robot among four walls and a block (a 2.2 m square)."""
    return parse_world({"world_info": {"basic_time_step": STEP, "contact": contact, "random_seed": 5},
                        "solids": [wall("north", 0, 1.2, 2.6, 0.2), wall("south", 0, -1.2, 2.6, 0.2),
                                   wall("east", 1.2, 0, 0.2, 2.2), wall("west", -1.2, 0, 0.2, 2.2),
                                   wall("block", 0.5, -0.6, 0.3, 0.3)],
                        "robots": [omni("tri", 0.0, 0.0), omni("quad", 0.6, 0.6, 4, 0.4), youbot("yb", -0.6, -0.5),
                                   boebot("boe", -0.95, 0.9), boebot("skid", 0.6, -0.1, skid=True)]})


def rim_speeds(drive, vx: float, vy: float, w: float) -> list[float]:
    """Each omni wheel's speed for a body twist: d · (v + ω × p) / r, d = axis × up."""
    out = []
    for wh in drive.wheels:
        n = math.hypot(*wh.axis)
        dx, dy = wh.axis[1] / n, -wh.axis[0] / n
        px, py = wh.position
        out.append((dx * (vx - w * py) + dy * (vy + w * px)) / wh.radius)
    return out


def random_commands(rng, w) -> dict:
    """Per drive motor: (a held position, a velocity, whether it holds the position). An omni robot's
    wheels 70 % of the time at one body twist (0.45 m/s in a random direction, so that it reaches
    walls and the other robots), else each at its own random speed, full speed often; a two-wheel
    robot's sides each at a random speed (a skid-steer robot's wheels of a side alike)."""
    out = {}
    for r in w.robots:
        vmax = 12.0
        twist = None
        if r.omni_drive is not None and rng.random() < 0.7:
            heading = rng.uniform(-math.pi, math.pi)
            twist = rim_speeds(r.omni_drive, 0.45 * math.cos(heading), 0.45 * math.sin(heading),
                               rng.uniform(-1.0, 1.0))
        for j, (_, m) in enumerate(r.drive_motors):
            vel = rng.choice([-vmax, vmax]) if rng.random() < 0.3 else rng.uniform(-vmax, vmax)
            if twist is not None:
                vel = twist[j]
            out[(r.name, m)] = (rng.uniform(-5.0, 5.0), float(vel), twist is None and rng.random() < 0.2)
        if r.differential_drive is not None:      # (the batched simulation drives a side's wheels together)
            for side in r.differential_drive.motor_names:
                for m in side[1:]:
                    out[(r.name, m)] = out[(r.name, side[0])]
    return out


NAMES = ("tri", "quad", "yb", "boe", "skid")


@pytest.mark.parametrize("steps", [200, pytest.param(400, marks=pytest.mark.slow)])
@pytest.mark.parametrize("contact", [True, False])
def test_every_copy_steps_as_the_single_simulation_bit_for_bit(contact, steps):
    """Three copies, each against its own Simulation (world seeds 5, 6, 7), 200 steps (400 in the
    slow stage) of random commands changed every 40 steps (velocity and position control), set_poses
    half-way: every robot's pose and every device's reading the same bits every step; contact
    clipped moves (every robot pressed already in the first 200 steps)."""
    moves = {"tri": ([-0.5, -0.1, 0.05], [0, 0, 1, 0.7]), "boe": ([0.2, 0.8, 0.04], [0, 0, 1, -2.0])}
    batched, _, pressed = lockstep(world(contact), steps, (5, 6, 7), random_commands, rng_seed=8, sample_ms=32,
                                   set_poses=(steps // 2, 1, moves))
    assert batched.omni is not None and batched.omni.width == 4 and batched.omni.count.tolist() == [3, 4]
    assert list(pressed) == list(NAMES)
    if contact:       # walls and robots were met, by every kind of robot
        assert all(p > 0 for p in pressed.values()), pressed
    else:
        assert batched.contact is None and sum(pressed.values()) == 0


def single_of(w, speeds: dict[str, float], robot: str, steps: int) -> Simulation:
    sim = Simulation(w)
    for name, u in speeds.items():
        m = sim.robot(robot).motor(name)
        m.set_position(math.inf)
        m.set_velocity(float(u))
    sim.run(steps)
    return sim


def test_every_wheel_at_one_speed_turns_an_omni_robot_in_place_at_r_omega_over_l():
    """Three-wheeler and four-wheeler, each copy its own ω: after N steps each stands where it
    started, its heading −r·ω·t/L (clockwise for ω > 0), every copy its single Simulation's bits;
    the encoders read ω·t."""
    w = parse_world({"world_info": {"basic_time_step": STEP},
                     "robots": [omni("tri", 0.0, 0.0), omni("quad", 1.0, 0.5, 4, 0.3)]})
    omegas = [3.0, -7.5, 12.0, 0.0]
    n, N = len(omegas), 150
    batched = BatchedSimulation(w, n)
    tri, quad = batched.slot("tri"), batched.slot("quad")
    batched.omni.command(tri, np.repeat(np.array(omegas)[:, None], 3, axis=1))
    batched.omni.command(quad, np.repeat(np.array(omegas)[:, None], 4, axis=1))
    enc = batched.device("quad", "enc")
    batched.enable(enc, STEP)
    batched.run(N)
    t = N * DT
    for k, om in enumerate(omegas):
        for slot, r, L, x, y, yaw0 in ((tri, R3, L3, 0.0, 0.0, 0.0), (quad, R4, L4, 1.0, 0.5, 0.3)):
            rot, pos = batched.rot[k, slot], batched.pos[k, slot]
            assert pos.tolist() == pytest.approx([x, y, 0.05], abs=1e-12), (k, slot)
            expect = math.remainder(yaw0 - r * om * t / L, math.tau)
            assert math.remainder(math.atan2(rot[1, 0], rot[0, 0]) - expect, math.tau) == pytest.approx(0.0, abs=1e-9)
            single = single_of(w, {f"wheel{i + 1}": om for i in range(3 if slot == tri else 4)},
                               batched.robot_names[slot], N)
            pose = single.robot(batched.robot_names[slot]).pose
            assert pose.translation.tobytes() == pos.tobytes() and pose.rotation.tobytes() == rot.tobytes(), (k, slot)
    assert batched.value(enc) == pytest.approx(np.array(omegas) * t, abs=1e-12)


def test_an_off_centre_robot_turning_in_place_circles_about_its_wheels_centre():
    """A Boe-Bot-like robot (wheels' centre 2.5 cm ahead of its origin), wheels at −ω and +ω (each
    copy its own ω, one copy driving straight, one standing): the wheels' centre stays where it
    started and the origin lies on its circle, 2.5 cm behind it along the heading ω_z·t, ω_z =
    2·r·ω/axle; straight driving moves both at r·ω; every copy its single Simulation's bits."""
    yaw0 = 0.6
    robot = boebot("boe", 0.3, -0.2)
    robot["pose"]["rotation"] = [0, 0, 1, yaw0]
    w = parse_world({"world_info": {"basic_time_step": STEP}, "robots": [robot]})
    plans = [(-4.0, 4.0), (9.0, -9.0), (12.0, -12.0), (5.0, 5.0), (0.0, 0.0)]
    n, N = len(plans), 170
    batched = BatchedSimulation(w, n)
    left, right = np.array(plans).T
    batched.set_wheels(0, left, right)
    batched.run(N)
    t = N * DT
    centre0 = np.array([0.3 + CX * math.cos(yaw0), -0.2 + CX * math.sin(yaw0)])
    for k, (wl, wr) in enumerate(plans):
        rot, pos = batched.rot[k, 0], batched.pos[k, 0]
        yaw = math.atan2(rot[1, 0], rot[0, 0])
        if wl == -wr:
            expect_yaw = yaw0 + RB * (wr - wl) / AXLE * t
            centre = centre0
        else:             # straight along the heading
            expect_yaw = yaw0
            centre = centre0 + RB * wl * t * np.array([math.cos(yaw0), math.sin(yaw0)])
        assert math.remainder(yaw - expect_yaw, math.tau) == pytest.approx(0.0, abs=1e-9), k
        origin = centre - CX * np.array([math.cos(expect_yaw), math.sin(expect_yaw)])
        assert pos[:2] == pytest.approx(origin, abs=1e-9), k
        assert pos[:2] + CX * rot[:2, 0] == pytest.approx(centre, abs=1e-9), k       # the centre, from the pose
        single = single_of(w, {"left wheel motor": wl, "right wheel motor": wr}, "boe", N)
        pose = single.robot("boe").pose
        assert pose.translation.tobytes() == pos.tobytes() and pose.rotation.tobytes() == rot.tobytes(), k
    # the origin really circles (it is not the centre): a quarter turn apart it moved sqrt(2)·2.5 cm
    assert np.hypot(*(batched.pos[0, 0, :2] - [0.3, -0.2])) > 0.01


def test_strafes_against_a_wall_and_a_robot_stop_there_and_copies_never_meet():
    """A wall 1 m to the left of "tri", another three-wheeler 1 m to its right. Copy 0: tri strafes
    right into the standing other and stops against it; copy 1: both strafe right alike, so tri
    crosses where copy 0's other stands without meeting anything; copy 2: tri strafes left and stops
    with its disc on the wall's face. Each copy equals its own single Simulation bit for bit; the
    bumper of the stopped ones reads 1."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": True},
                     "solids": [wall("wall", 0.0, 1.0, 4.0, 0.2)],
                     "robots": [omni("tri", 0.0, 0.0), omni("other", 0.0, -1.0)]})
    drive = w.world.robots[0].omni_drive
    right, left, stand = rim_speeds(drive, 0.0, -0.5, 0.0), rim_speeds(drive, 0.0, 0.5, 0.0), [0.0] * 3
    plan = [{"tri": right, "other": stand}, {"tri": right, "other": right}, {"tri": left, "other": stand}]
    batched, bumper = plan_copies(w, plan, "omni", ("wheel1", "wheel2", "wheel3"), "tri", 100)     # 1.6 s at 0.5 m/s
    tri, other = batched.slot("tri"), batched.slot("other")
    assert batched.pos[0, tri, 1] == pytest.approx(-1.0 + 2 * BODY3, abs=1e-6)      # disc against disc
    assert batched.pos[0, other, 1] == -1.0
    assert batched.pos[1, tri, 1] == pytest.approx(-0.8, abs=1e-9)
    assert batched.pos[1, other, 1] == pytest.approx(-1.8, abs=1e-9)
    assert batched.pos[2, tri, 1] == pytest.approx(0.9 - BODY3, abs=1e-9)           # its disc on the face
    assert batched.pos[:, tri, 0] == pytest.approx([0.0] * 3, abs=1e-12)
    assert batched.value(bumper).tolist() == [1.0, 0.0, 1.0]


def test_commands_are_checked_in_one_line():
    batched = BatchedSimulation(parse_world({"robots": [omni("tri", 0.0, 0.0), omni("quad", 1.0, 0.0, 4)]}), 2)
    with pytest.raises(ValueError, match=r"^quad: an omni-wheel robot has no left and right wheels: command it with "
                                         r"omni.command\(slot, speeds\) \(copies, 4\)$"):
        batched.set_wheels(1, [1.0, 1.0], [1.0, 1.0])
    with pytest.raises(ValueError, match=r"^omni wheel speeds must be \(copies, 3\) \(wheel1, wheel2, wheel3\), "
                                         r"got shape \(2, 4\)$"):
        batched.omni.command(0, [[1.0] * 4] * 2)
    with pytest.raises(ValueError, match=r"^omni wheel speeds must be finite$"):
        batched.omni.command(1, [[1.0, math.nan, 0.0, 0.0]] * 2)
    batched.omni.command(0, [[100.0, -100.0, 1.0]] * 2)          # clamped to max_wheel_speed, as Webots does
    assert batched.omni.velocity[:, 0, :3].tolist() == [[12.0, -12.0, 1.0]] * 2


def test_omni_and_off_centre_robots_ride_a_ramp_and_a_nue_world_as_in_the_single_simulation():
    """An elevation grid (a ramp rising 0.3 m over 1.5 m) under a three-wheeler and an off-centre
    robot: the copies ride it, tilted, the same bits as their Simulations; the same robots in a NUE
    world (y up) among walls, pressed against them, the same bits."""
    ramp = {"name": "ramp", "pose": {"translation": [-1.0, -1.0, 0.0]},
            "geometry": {"type": "elevation_grid", "x_dimension": 4, "x_spacing": 0.5, "y_dimension": 4,
                         "y_spacing": 0.5, "height": [0.0, 0.1, 0.2, 0.3] * 4}}
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": True},
                     "solids": [ramp, wall("east", 1.2, 0, 0.2, 2.6)],
                     "robots": [omni("tri", -0.4, -0.4), boebot("boe", -0.4, 0.2)]})
    batched, tilted, _ = lockstep(w, 200)
    assert batched.ground is not None and tilted > 50

    def nue(robot: dict, x: float, z: float, width: float, length: float) -> dict:
        """The robot standing in a y-up world: a box body, height along y."""
        return {**robot, "pose": {"translation": [x, 0.05, z]},
                "body": {"geometry": {"type": "box", "size": [length, 0.05, width]}}}

    w = parse_world({"world_info": {"basic_time_step": STEP, "coordinate_system": "NUE", "contact": True},
                     "solids": [{"name": n, "pose": {"translation": [x, 0.25, z]},
                                 "geometry": {"type": "box", "size": [sx, 0.5, sz]}}
                                for n, x, z, sx, sz in (("w", 0.0, -0.7, 2.0, 0.2), ("e", 0.0, 0.7, 2.0, 0.2),
                                                        ("n", 0.9, 0.0, 0.2, 1.6), ("s", -0.9, 0.0, 0.2, 1.6))],
                     "robots": [nue(omni("tri", 0, 0), 0.0, 0.0, 0.24, 0.24),
                                nue(boebot("boe", 0, 0), 0.5, 0.3, 0.1, 0.12)]})
    batched, _, pressed = lockstep(w, 240)
    assert batched.to_enu is not None and sum(pressed.values()) > 0


# ---------------------------------------------------------------- an omni-wheel agent (Gymnasium)

def agent_task(robot: str = "tri", max_steps: int = 30, observations=("gps", "compass", "bumper", "front", "enc")):
    from sensorium.gym import Task
    from sensorium.gym.task import random_start

    return Task(robot=robot, control_period_ms=32, max_steps=max_steps, observations=list(observations),
                start=random_start((-0.8, 0.8), (-0.8, 0.8)))


@pytest.mark.parametrize(("robot", "actions"), [("tri", "normalized"), ("quad", "wheel"), ("boe", "normalized")])
def test_sub_env_i_is_the_single_env_with_seed_i_across_autoresets(robot, actions):
    """Random wheel actions (all at one extreme a third of the time), episodes of 30 actions, random
    starts, walls, a block and the other robots: every observation, reward, flag, clock and pose of
    sub-env i equals the single env (the rebuilt Simulation) reset with seed + i, bit for bit; the
    bumper was pressed. The three-wheeler acts with (3,), the four-wheeler with (4,), the
    off-centre two-wheel robot with (left, right)."""
    pytest.importorskip("gymnasium")
    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv
    from tests.test_gym_vector import _reset_both, _step_both

    w = world(True)
    n, seed = 3, 21
    width = {"tri": 3, "quad": 4, "boe": 2}[robot]
    venv = SensoriumVectorEnv(w, agent_task(robot), n, actions=actions)
    singles = [SensoriumEnv(w, agent_task(robot), actions=actions, engine="simulation") for _ in range(n)]
    space = singles[0].action_space
    assert space.shape == (width,) and venv.action_space.shape == (n, width)
    _reset_both(venv, singles, seed)
    rng = np.random.default_rng(3)
    done = np.zeros(n, dtype=bool)
    resets, pressed = 0, 0
    for t in range(90):
        a = rng.uniform(space.low, space.high, (n, width)).astype(np.float32)
        if t % 3 == 0:          # every wheel at one extreme: a turn on the spot, or straight ahead
            a = np.tile(space.high * (1 if t % 2 else -1), (n, 1)).astype(np.float32)
        got, vobs = _step_both(venv, singles, a, done, t)
        resets += got
        pressed += int((vobs["bumper"][:, 0] == 1.0).sum())
    assert resets >= 3 and pressed > 0


def test_every_wheel_at_plus_one_turns_the_agent_in_place_in_closed_form_in_both_engines():
    """Action (1, 1, 1): every wheel at max_wheel_speed, so the three-wheeler turns in place clockwise
    at r·ω_max/L: after k actions of 32 ms its pose is (0, 0, −r·ω·t/L) in the single env and in a
    batched sub-env alike, the same bits; the other sub-env, (−1, −1, −1), turns the other way."""
    from sensorium.gym import SensoriumEnv, Task
    from sensorium.gym.vector import SensoriumVectorEnv

    w = parse_world({"world_info": {"basic_time_step": STEP}, "robots": [omni("tri", 0.0, 0.0)]})
    task = Task(robot="tri", control_period_ms=32, max_steps=None, observations=["gps"])
    env = SensoriumEnv(w, task)
    venv = SensoriumVectorEnv(w, task, 2)
    env.reset(seed=0)
    venv.reset(seed=0)
    spin = np.ones(3, dtype=np.float32)
    rate = R3 * 12.0 / L3
    for k in range(1, 41):
        info = env.step(spin)[4]
        vinfo = venv.step(np.stack([spin, -spin]))[4]
        t = (k * 32) / 1000.0
        assert info["pose"][:2] == pytest.approx([0.0, 0.0], abs=1e-12)
        assert math.remainder(info["pose"][2] + rate * t, math.tau) == pytest.approx(0.0, abs=1e-9), k
        assert info["pose"].tobytes() == vinfo["pose"][0].tobytes()
        assert math.remainder(vinfo["pose"][1][2] - rate * t, math.tau) == pytest.approx(0.0, abs=1e-9), k


def test_the_checker_passes_on_both_engines_and_a_sub_env():
    from gymnasium.utils.env_checker import check_env

    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv

    w = world(True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for robot in ("tri", "boe"):
            task = agent_task(robot, observations=("gps", "compass", "bumper", "front", "imu"))
            check_env(SensoriumEnv(w, task), skip_render_check=True)
            check_env(SensoriumEnv(w, task, engine="batched"), skip_render_check=True)
            check_env(SensoriumVectorEnv(w, task, 3).sub_env(1), skip_render_check=True)


def test_bad_actions_are_refused_in_one_line():
    from sensorium.gym import SensoriumEnv
    from sensorium.gym.vector import SensoriumVectorEnv

    w = world(True)
    env = SensoriumEnv(w, agent_task("quad"))
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^quad: action must be 4 finite values \(in \[-1, 1\]: beyond it, clipped\) \(wheel1, wheel2, "
                                         r"wheel3, wheel4\), got \[0\.1\d*, 0\.2\d*, 0\.3\d*\]$"):
        env.step(np.array([0.1, 0.2, 0.3], dtype=np.float32))
    venv = SensoriumVectorEnv(w, agent_task("quad"), 2)
    venv.reset(seed=0)
    with pytest.raises(ValueError, match="^sub-env 1: action must be 4 finite values"):
        venv.step(np.array([[0.0] * 4, [0.0, math.nan, 0.0, 0.0]], dtype=np.float32))


def test_pettingzoo_omni_and_off_centre_robots_are_agents_and_both_engines_agree():
    a = parallel_engines_agree(world(True), NAMES)
    assert [a.action_space(r).shape for r in NAMES] == [(3,), (4,), (4,), (2,), (2,)]


@pytest.mark.slow           # starts worker processes
def test_the_workers_env_carries_omni_wheel_actions_bit_for_bit():
    """SensoriumWorkersEnv (two processes) shares (n, 3) actions: sub-env i equals the one-process
    vector env's, autoresets included."""
    workers_agree(world(True), agent_task(max_steps=5), 3, 3)
