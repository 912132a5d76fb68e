"""Sweep 15: Webots robots not swept before, each a stand-in of ours (tests/data/sweep15/: the PROTO's
device names, joint axes and anchors and wheel radii, our own text) driven in process by the calls
its Webots sample controller makes, checked against closed forms."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import REPO, child_env, sensorium

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep15"
TESTS_C = Path(__file__).parent / "c"

# BlueBotics' Shrimp III: six wheels of radius 0.058 m, the front and back ones on steering hinges
# (front at x 0.271, back at -0.252), two per side on passive bogies at x ±0.089, y ±0.182.
SHRIMP_R = 0.058
SHRIMP_SIGNS = (-1, 1, -1, 1, -1, -1)       # wheel motor 00..05: the sign of a forward roll (their axes)


def shrimp_command(velocity: int, direction: int) -> tuple[list[float], float, float]:
    """The Shrimp protocol's speed-and-direction command (0x04) as its Webots controller turns it
    into motor commands: a 5000 rpm motor behind an 86:1 gear at full scale 127, the back wheel
    steered by ``direction`` degrees, the others set for a turn about one point 0.242 m ahead of the
    back wheel's axis (the controller's geometry). Returns the six wheel speeds (rad/s, signed as
    set), the front and back steering positions."""
    back = math.radians(direction)
    v_back = velocity * 5000 * 2 * math.pi / (60 * 86 * 127)
    r_back = 0.242 / math.cos(math.pi / 2 - abs(back))
    rate = v_back / r_back
    r_centre = math.sqrt(r_back ** 2 - 0.242 ** 2) if abs(r_back) != 0.242 else 0.0
    r_front = math.hypot(r_centre, 0.271)
    front = (math.pi / 2 - math.asin(r_centre / r_front)) * (-1 if direction < 0 else 1)
    near, far = math.hypot(r_centre - 0.182, 0.089), math.hypot(r_centre + 0.182, 0.089)
    left, right = (far, near) if direction > 0 else (near, far)
    speeds = [rate * r_front, rate * left, rate * right, 0.0, 0.0, v_back]
    if r_centre < 0.182:                     # the turning point between the body and the near side
        speeds[1 if direction < 0 else 2] *= -1
    speeds[3], speeds[4] = speeds[1], speeds[2]
    return [s * k for s, k in zip(speeds, SHRIMP_SIGNS)], -front, back


def set_shrimp(robot, velocity: int, direction: int) -> None:
    speeds, front, back = shrimp_command(velocity, direction)
    for i, s in enumerate(speeds):
        m = robot.motor(f"wheel motor 0{i}")
        m.set_position(math.inf)
        m.set_velocity(s)
    robot.motor("front wheel rotation").set_position(front)
    robot.motor("back wheel rotation").set_position(back)


def test_the_shrimp_keeps_its_six_wheels_steered_front_and_back() -> None:
    """The Shrimp's two steering hinges stand one behind the other on its x axis, no car's front axle:
    it gets the steered-wheel drive (each steered wheel under its hinge, the four bogie wheels where
    they roll). Before, two steering joints were taken for a car's and the robot lost its drive ('no
    Ackermann drive (... not on one front axle ...); the robot will not move')."""
    w = load_world(DATA / "shrimp.wbt")
    assert not [x for x in w.warnings if "will not move" in x], w.warnings
    (robot,) = w.world.robots
    assert [d.name for d in robot.devices] == [
        "back wheel rotation", "wheel motor 05", "wheel sensor 05", "wheel motor 04", "wheel sensor 04",
        "wheel motor 02", "wheel sensor 02", "wheel motor 03", "wheel sensor 03", "wheel motor 01",
        "wheel sensor 01", "front wheel rotation", "wheel motor 00", "wheel sensor 00"]
    drive = robot.steered_drive
    assert drive is not None
    by_motor = {x.motor: x for x in drive.wheels}
    assert by_motor["wheel motor 05"].steer == "back wheel rotation"
    assert by_motor["wheel motor 00"].steer == "front wheel rotation"
    assert by_motor["wheel motor 05"].position == pytest.approx((-0.252, 0.0), abs=1e-12)
    # the front fork's two frames (turned by -0.4712 and back about y) put its hinge at x 0.271
    assert by_motor["wheel motor 00"].position == pytest.approx((0.271, 0.0), abs=1e-4)
    for i, (x, y) in {1: (0.089, 0.182), 2: (0.089, -0.182), 3: (-0.089, 0.182), 4: (-0.089, -0.182)}.items():
        assert by_motor[f"wheel motor 0{i}"].steer is None
        assert by_motor[f"wheel motor 0{i}"].position == pytest.approx((x, y), abs=1e-4)
    assert {x.radius for x in drive.wheels} == {SHRIMP_R}


def test_the_shrimp_drives_straight_at_r_omega() -> None:
    """The controller's first command (speed 95 of 127, straight): every wheel at
    95·5000·2π/(60·86·127) = 4.5543 rad/s, the Shrimp along its x at 0.058·4.5543 = 0.26415 m/s.
    (The left bogies are turned by 3.1415, not π, as in the PROTO: their wheels 9.3e-5 rad off.)"""
    w = load_world(DATA / "shrimp.wbt")
    sim = Simulation(w, "fast")
    robot = sim.robot("Shrimp")
    set_shrimp(robot, 95, 0)
    speeds, front, back = shrimp_command(95, 0)
    assert (front, back) == (0.0, 0.0)
    assert speeds == pytest.approx([-4.5543, 4.5543, -4.5543, 4.5543, -4.5543, -4.5543], abs=1e-4)
    start = robot.pose.translation.copy()
    sim.run(125)                                            # 2 s
    moved = robot.pose.translation - start
    assert moved[0] == pytest.approx(SHRIMP_R * 4.55432 * 2.0, rel=1e-4)
    assert abs(moved[1]) < 1e-4


def fit_twist(wheels, speeds: dict[str, float], steer: dict[str, float]) -> tuple[float, float, float]:
    """The body's (vx, vy, ωz) whose velocity at each wheel is nearest (least squares) to where the
    wheel rolls it: r·ω along its heading (steered ones turned by their hinge)."""
    rows, rhs = [], []
    for x in wheels:
        heading = (x.heading or 0.0) + x.steer_sign * steer.get(x.steer or "", 0.0)
        u = x.radius * speeds[x.motor]
        px, py = x.position
        rows += [[1.0, 0.0, -py], [0.0, 1.0, px]]
        rhs += [u * math.cos(heading), u * math.sin(heading)]
    sol = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
    return float(sol[0]), float(sol[1]), float(sol[2])


def test_the_shrimp_turns_by_its_six_wheels_fit() -> None:
    """The controller's second command (full speed 127, back wheel steered 75° right): back at
    -1.309 rad, front at +1.336, the left wheels backwards (the turning point 0.065 m to the left,
    inside the wheels). The Shrimp turns left at the least-squares fit of its six wheels (closed form
    below), within 1 % of the 6.088·0.058/0.2505 = 1.409 rad/s its controller means (the back wheel
    stands 0.252 m behind, its formula says 0.242)."""
    w = load_world(DATA / "shrimp.wbt")
    sim = Simulation(w, "fast")
    robot = sim.robot("Shrimp")
    speeds, front, back = shrimp_command(127, -75)
    assert (front, back) == pytest.approx((1.3359, -1.3090), abs=1e-4)
    robot.motor("front wheel rotation").set_position(front)
    robot.motor("back wheel rotation").set_position(back)
    sim.run(100)                                            # the hinges turn; the wheels hold
    assert robot.motor("front wheel rotation").position == pytest.approx(front, abs=1e-12)
    set_shrimp(robot, 127, -75)
    sim.run(1)
    drive = w.world.robots[0].steered_drive
    by_name = {f"wheel motor 0{i}": s for i, s in enumerate(speeds)}
    _, _, wz = fit_twist(drive.wheels, by_name, {"front wheel rotation": front, "back wheel rotation": back})
    assert robot.drive.velocity()[5] == pytest.approx(wz, abs=1e-12)
    assert wz == pytest.approx(1.3268, abs=1e-4)             # 6 % under the controller's 1.409: its
    assert wz == pytest.approx(6.0883 * SHRIMP_R / 0.25054, rel=0.06)   # 0.242 and unsteered bogies
    sim.run(62)                                              # 1.008 s in all at that rate
    yaw = math.atan2(robot.pose.rotation[1, 0], robot.pose.rotation[0, 0])
    assert yaw == pytest.approx(wz * 63 * 0.016, abs=1e-9)


# NEX Robotics' Fire Bird 6: two wheels of radius 0.046 m, 0.3 m apart, their hinges anchored on the
# body's centre line at x 0.07 (the end points at y ±0.15), eight sonars ps0..ps7 reading metres.
FB6 = "Fire Bird 6"
FB6_R, FB6_STEP = 0.046, 64


def fb6_world():
    w = load_world(DATA / "fire_bird_6.wbt")
    sim = Simulation(w, "fast")
    return w, sim, sim.robot(FB6)


def test_the_fire_bird_6_keeps_its_two_wheel_drive_about_its_axle() -> None:
    """Both wheel hinges are anchored at (0.07, 0, -0.08), on the centre line: the wheels' places are
    their end points', 0.3 m apart, the axle's centre 0.07 m ahead of the origin. Every device the
    obstacle-avoidance controller asks for is there."""
    w, _, _ = fb6_world()
    assert not [x for x in w.warnings if "will not move" in x], w.warnings
    drive = w.world.robots[0].differential_drive
    assert drive is not None
    assert (drive.wheel_radius, drive.axle_length, tuple(drive.axle_center)) == (FB6_R, 0.3, (0.07, 0.0))
    names = {d.name for d in w.world.robots[0].devices}
    assert {f"ps{i}" for i in range(8)} | {"left wheel motor", "right wheel motor"} <= names


def test_the_fire_bird_6_obstacle_avoidance_stops_its_run_at_the_wall_by_its_sonar() -> None:
    """fire_bird_6_obstacle_avoidance's rule, step by step at its 64 ms: both wheels at 1 rad/s
    (0.046 m/s, 2.944 mm a step) until ps2 (at x 0.15, reading metres) reads under 0.25, then left 0,
    right -1. The wall's face is at x 1.45, so ps2 reads 1.30 - 0.002944·(k - 1) at step k (the speed
    set one step after the reading): under 0.25 first at k = 358 (22.912 s), the robot 1.051008 m on."""
    _, sim, robot = fb6_world()
    ps = [sim.device(f"{FB6}/ps{i}") for i in range(8)]
    for p in ps:
        p.enable(FB6_STEP)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    for k in range(1, 400):
        for _ in range(FB6_STEP // 16):
            sim.step()
        v = [float(p.value) for p in ps]
        assert v[2] == pytest.approx(1.30 - FB6_R * FB6_STEP / 1000 * max(k - 1, 0), abs=1e-6)   # rays cast in float32
        if v[2] < 0.25:
            break
        assert min(v[0], v[1], v[3], v[4]) >= 0.25           # nothing beside it: straight on
        left.set_velocity(1.0)
        right.set_velocity(1.0)
    assert k == 358
    assert robot.pose.translation[:2] == pytest.approx([357 * FB6_R * 0.064, 0.0], abs=1e-9)


def test_the_fire_bird_6_turns_about_its_axle_centre() -> None:
    """The controller's 'turn right' (left 3, right -1 rad/s): ω = 0.046·(-1 - 3)/0.3 = -0.61333 rad/s
    about the axle's centre, which moves on at 0.046·(3 - 1)/2 = 0.046 m/s along the heading."""
    _, sim, robot = fb6_world()
    for name, s in (("left wheel motor", 3.0), ("right wheel motor", -1.0)):
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(s)
    sim.run(64)                                              # 1.024 s
    rot = robot.pose.rotation
    yaw = math.atan2(rot[1, 0], rot[0, 0])
    wz, v, t = FB6_R * -4 / 0.3, FB6_R, 1.024
    assert yaw == pytest.approx(wz * t, abs=1e-9)
    centre = robot.pose.translation[:2] + rot[:2, :2] @ np.array([0.07, 0.0])
    # the axle's centre on its arc from (0.07, 0): radius v/|ω|, turning right
    expect = [0.07 + v / wz * math.sin(wz * t), v / wz * (1 - math.cos(wz * t))]
    assert centre == pytest.approx(expect, abs=1e-9)


# The Surveyor SRV-1: ten wheels of radius 0.014 m (wheel_motor00..04 on its left, 05..09 on its
# right, 0.0788 m apart), all about -y: a negative speed rolls it forward (+x), as its controller's
# protocol drives it.
SRV = "SurveyorSrv1"
SRV_R, SRV_TRACK = 0.014, 0.0788


def srv_world():
    w = load_world(DATA / "srv-1.wbt")
    sim = Simulation(w, "fast")
    return w, sim, sim.robot(SRV)


def srv_set(robot, left: float, right: float) -> None:
    for i in range(10):
        m = robot.motor(f"wheel_motor0{i}")
        m.set_position(math.inf)
        m.set_velocity(left if i < 5 else right)


def test_the_surveyor_keeps_its_ten_wheels_as_a_skid_steer_driven_backwards_by_positive_speeds() -> None:
    """Its ten wheels turn about -y: a skid-steer drive whose forward is -x (positive speeds roll it
    back), every wheel kept. Every device surveyor_init asks for is there (camera, ten motors and
    sensors, ds0..ds3)."""
    w, _, _ = srv_world()
    assert not [x for x in w.warnings if "will not move" in x], w.warnings
    drive = w.world.robots[0].differential_drive
    assert drive is not None and drive.skid_steer is not None
    assert (drive.wheel_radius, drive.axle_length, tuple(drive.forward)) == (SRV_R, SRV_TRACK, (-1.0, 0.0))
    assert {drive.left_motor, drive.right_motor, *drive.skid_steer.left, *drive.skid_steer.right} == {
        f"wheel_motor0{i}" for i in range(10)}
    names = {d.name for d in w.world.robots[0].devices}
    assert {"camera", "ds0", "ds1", "ds2", "ds3"} | {f"wheel_sensor0{i}" for i in range(10)} <= names


@pytest.mark.parametrize(("command", "left_power"), [("8 forward", 0.5), ("7 drift left", 0.4), ("9 drift right", 0.6)])
def test_the_surveyor_protocol_commands_drive_it_by_the_closed_form(command: str, left_power: float) -> None:
    """Its protocol's forward and drift commands at the initial 0.3 m/s: each left wheel at
    -(p/0.5)·0.3/0.014 rad/s, each right one at -((1 - p)/0.5)·0.3/0.014, so the sides roll at
    0.6·p and 0.6·(1 - p) m/s: 0.3 m/s ahead, turning at (0.6 - 1.2·p)/0.0788 rad/s (drift left
    1.5228, right -1.5228) about its centre."""
    _, sim, robot = srv_world()
    v_left, v_right = 0.6 * left_power, 0.6 * (1 - left_power)
    srv_set(robot, -v_left / SRV_R, -v_right / SRV_R)
    sim.run(64)                                               # 1.024 s
    t, v, wz = 1.024, 0.3, (v_right - v_left) / SRV_TRACK
    rot = robot.pose.rotation
    assert math.atan2(rot[1, 0], rot[0, 0]) == pytest.approx(wz * t, abs=1e-9)
    expect = [v * t, 0.0] if wz == 0 else [v / wz * math.sin(wz * t), v / wz * (1 - math.cos(wz * t))]
    assert robot.pose.translation[:2] == pytest.approx(expect, abs=1e-9)


def test_the_surveyor_spins_20_degrees_in_200_ms_at_the_kinematic_rate() -> None:
    """The protocol's '0' (turn 20° left): left wheels +0.3/0.014, right -0.3/0.014 for 200 ms (its
    clock counts 16 ms steps: 13 of them). Here the skid-steer turns at 0.6/0.0788 = 7.614 rad/s, 1.58
    rad in those 208 ms, in place; Webots' tracks slip in the turn (the protocol's 20° is the real
    robot's figure) -- a departure the README says."""
    _, sim, robot = srv_world()
    srv_set(robot, 0.3 / SRV_R, -0.3 / SRV_R)
    sim.run(13)
    rot = robot.pose.rotation
    assert math.atan2(rot[1, 0], rot[0, 0]) == pytest.approx(0.6 / SRV_TRACK * 0.208, abs=1e-9)
    assert robot.pose.translation[:2] == pytest.approx([0.0, 0.0], abs=1e-12)


FB6_CONTROLLER = '''
from controller import Robot

robot = Robot()
print("Fire Bird 6 controller for obstacle avoidance")
ps = [robot.getDevice(f"ps{i}") for i in range(8)]
for p in ps:
    p.enable(64)
left, right = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
for m in (left, right):
    m.setPosition(float("inf"))
    m.setVelocity(0.0)
while robot.step(64) != -1:
    v = [p.getValue() for p in ps]
    front = v[2] < 0.25
    ls, rs = (0.0, -1.0) if front else (3.0, -1.0) if v[0] < 0.25 or v[1] < 0.25 else (
        -1.0, 3.0) if v[3] < 0.25 or v[4] < 0.25 else (1.0, 1.0)
    if front:
        print(f"front {robot.getTime():.3f} {v[2]:.5f}", flush=True)
        break
    left.setVelocity(ls)
    right.setVelocity(rs)
'''


@pytest.mark.slow
def test_the_fire_bird_6_controller_runs_under_sensorium_run(tmp_path: Path) -> None:
    """A Python controller of ours making fire_bird_6_obstacle_avoidance's calls (its devices, its
    64 ms step, its rule), started by ``sensorium run`` from the project's controllers/ folder: its
    sonar ps2 sees the wall under 0.25 m first at 22.912 s (the closed form above), reading 0.24899."""
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "fire_bird_6.wbt").write_text((DATA / "fire_bird_6.wbt").read_text())
    folder = tmp_path / "controllers" / "fire_bird_6_obstacle_avoidance"
    folder.mkdir(parents=True)
    (folder / "fire_bird_6_obstacle_avoidance.py").write_text(FB6_CONTROLLER)
    done = subprocess.run(sensorium("run", str(tmp_path / "worlds" / "fire_bird_6.wbt"), "--until", "23500",
                                    "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "Fire Bird 6 controller for obstacle avoidance" in done.stdout, done.stderr
    assert "front 22.912 0.24899" in done.stdout, (done.stdout, done.stderr)


def test_the_scara_t6_example_reaches_its_targets_and_carries_the_shaft_there() -> None:
    """scara's calls (Epson's SCARA T6, our stand-in): base_arm_motor to 0.5, arm_motor to 0.14,
    shaft_linear_motor to -0.1, the LED toggled each second. Each joint moves kinematically and
    holds its target; the shaft, 0.2615 m past the arm's hinge at (0.37, 0.005), which is 0.31 m
    past the base hinge at (0.06, 0), stands where the two turns put it (closed form below), 0.1 m
    lower. The robot has no wheel: one line per joint says it moves kinematically, no drive is missed."""
    w = load_world(DATA / "scara_t6.wbt")
    assert not [x for x in w.warnings if "will not move" in x], w.warnings
    sim = Simulation(w, "fast")
    robot = sim.robot("ScaraT6")
    sensors = {n: sim.device(f"ScaraT6/{n}") for n in ("base_arm_position", "arm_position")}
    for s in sensors.values():
        s.enable(16)
    led = sim.device("ScaraT6/epson_led")
    led.set(1, sim.time_ms)
    robot.motor("arm_motor").set_position(0.14)
    robot.motor("base_arm_motor").set_position(0.5)
    robot.motor("shaft_linear_motor").set_position(-0.1)
    sim.run(63)                                               # 1.008 s
    assert float(sensors["base_arm_position"].value) == pytest.approx(0.5, abs=1e-12)
    assert float(sensors["arm_position"].value) == pytest.approx(0.14, abs=1e-12)

    def turn(a: float, p: np.ndarray) -> np.ndarray:
        c, s = math.cos(a), math.sin(a)
        return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])

    p1, p2, p3 = np.array([0.06, 0.0]), np.array([0.37, 0.005]), np.array([0.6245, 0.0])
    p2_now = p1 + turn(0.5, p2 - p1)
    p3_now = p2_now + turn(0.64, p3 - p2)
    shaft = robot.link_pose("shaft_linear_motor")
    assert shaft is not None
    at = shaft.rotation @ np.array([0.6245, 0.0, 0.256]) + shaft.translation
    assert at == pytest.approx([*p3_now, 0.156], abs=1e-9)


def test_the_p_rob3_moves_by_its_joints_accelerations_and_opens_its_coupled_gripper() -> None:
    """p-rob3's first calls (F&P's P-Rob3 with its P-Grip, our stand-in): motor 5 to -1.95, then its
    half-second wait (32 steps of 16 ms): the joint accelerates at its 3.49066 rad/s² (its
    ``acceleration``), each step's speed a·dt, so it stands at -3.49066·0.016²·32·33/2 = -0.47183,
    far from its target (2.79253 rad/s is never reached). Then motors 2 and 3 to 1.55 and 1.12 and
    'gripper::right' to 0.5, which moves 'gripper::left' too (Webots couples 'NAME::x' motors), all
    there within the controller's 2 s wait. Its close_gripper() is a torque, ignored here (the
    client says so once): the fingers stay open, so the arm carries no can."""
    w = load_world(DATA / "p-rob3.wbt")
    assert not [x for x in w.warnings if "will not move" in x], w.warnings
    names = {d.name for d in w.world.robots[0].devices}
    assert {f"motor {i}" for i in range(1, 7)} | {"gripper::right", "gripper::left"} <= names
    sim = Simulation(w, "fast")
    robot = sim.robot("P-Rob3")
    robot.motor("motor 5").set_position(-1.95)
    sim.run(32)
    assert robot.motor("motor 5").position == pytest.approx(-3.49066 * 0.016 ** 2 * 32 * 33 / 2, abs=1e-12)
    robot.motor("motor 2").set_position(1.55)
    robot.motor("motor 3").set_position(1.12)
    robot.motor("gripper::right").set_position(0.5)
    sim.run(125)
    for name, target in (("motor 2", 1.55), ("motor 3", 1.12), ("motor 5", -1.95), ("gripper::right", 0.5),
                         ("gripper::left", 0.5)):
        assert robot.motor(name).position == pytest.approx(target, abs=1e-12), name


# ---------------------------------------------------------------------- Webots' own controllers, unchanged

# Webots' sample controllers are Webots' files, never this repository's: each test below copies one from
# $WEBOTS_HOME (an installation or a source tree) into its temporary project, or, without it, our own
# controller making the same calls (tests/c/, tests/controllers/), builds a C one against our
# libController, and runs the world with `sensorium run`; a watcher of ours (a supervisor robot added to
# the world's copy) prints the poses the closed forms are checked against.
WATCHER = '''import math
import sys

from controller import Supervisor

sup = Supervisor()
every = int(sys.argv[1])
nodes = [(name, sup.getFromDef(name)) for name in sys.argv[2:]]
while sup.step(16) != -1:
    t = round(sup.getTime() * 1000)
    if t % every == 0:
        for name, node in nodes:
            p, r = node.getPosition(), node.getOrientation()
            print(f"pose {t} {name} {p[0]:.9f} {p[1]:.9f} {p[2]:.9f} {math.atan2(r[3], r[0]):.9f} "
                  f"{math.atan2(r[2], r[0]):.9f} {math.atan2(-r[5], r[4]):.9f}", flush=True)
'''


@pytest.fixture(scope="module")
def clib(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """Our libController built once for this file: (its build folder, the libraries to link)."""
    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path_factory.mktemp("cbuild")
    make = ["make", "-s", "-C", str(REPO / "sensorium" / "client" / "c")]
    done = subprocess.run([*make, f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return build, subprocess.run([*make, "libs"], capture_output=True, text=True, timeout=60).stdout.split()


def sample_controller(tmp_path: Path, rel: str, ours: Path) -> tuple[Path, bool]:
    """Webots' controller folder projects/robots/REL under $WEBOTS_HOME (an installation or a source
    tree) and True; without it, a folder of that name holding ``ours`` (our own controller making the
    same calls, renamed) and False."""
    home = os.environ.get("WEBOTS_HOME")
    folder = Path(home) / "projects" / "robots" / rel if home else None
    if folder is not None and folder.is_dir():
        return folder, True
    name = rel.rsplit("/", 1)[-1]
    folder = tmp_path / "ours" / name
    folder.mkdir(parents=True)
    shutil.copy(ours, folder / f"{name}{ours.suffix}")
    return folder, False


def webots_project(tmp_path: Path, world: str, controller: Path, watched: dict[str, str], every: int,
                   extra: str = "", clib: tuple[Path, list[str]] | None = None) -> Path:
    """worlds/WORLD.wbt: our stand-in with DEF names on the ``watched`` solids (DEF: the solid's name) and
    the watcher printing their poses every ``every`` ms; controllers/: the Webots controller's copy (its
    C files built into its executable against our libController) and the watcher."""
    text = (DATA / f"{world}.wbt").read_text()
    for def_name, solid in watched.items():
        if def_name not in ("SHRIMP", "SRV1"):                 # the robots' own DEFs are in the file
            at = text.rindex("Solid {", 0, text.index(f'name "{solid}"'))
            text = f"{text[:at]}DEF {def_name} {text[at:]}"
    args = " ".join(f'"{x}"' for x in (str(every), *watched))
    text += f'{extra}\nRobot {{ name "watcher" supervisor TRUE controller "watcher" controllerArgs [ {args} ] }}\n'
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / f"{world}.wbt").write_text(text)
    (tmp_path / "controllers" / "watcher").mkdir(parents=True)
    (tmp_path / "controllers" / "watcher" / "watcher.py").write_text(WATCHER)
    folder = tmp_path / "controllers" / controller.name
    shutil.copytree(controller, folder)
    sources = sorted(str(x) for x in folder.glob("*.c"))
    if sources:
        assert clib is not None
        build, libs = clib
        done = subprocess.run(["cc", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", *sources, "-o",
                               str(folder / controller.name), str(build / "libController.a"), *libs, "-lm"],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
    return tmp_path / "worlds" / f"{world}.wbt"


def run_poses(world: Path, until_ms: int) -> tuple[dict[tuple[int, str], list[float]], subprocess.CompletedProcess]:
    """``sensorium run`` until ``until_ms``: the watcher's poses by (ms, DEF) as [x, y, z, yaw, pitch,
    roll], and the finished run."""
    done = subprocess.run(sensorium("run", str(world), "--until", str(until_ms), "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=world.parent.parent, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "exited with status" not in done.stderr and "INVALID_ARGUMENT" not in done.stderr, done.stderr
    poses = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] pose "):
            _, _, t, name, *values = line.split()
            poses[int(t), name] = [float(v) for v in values]
    return poses, done


def turned(yaws: list[float]) -> float:
    """The angle turned along a sampled yaw sequence (each sample within π of the last)."""
    return sum(math.remainder(b - a, 2 * math.pi) for a, b in zip(yaws, yaws[1:]))


@pytest.mark.slow
def test_webots_shrimp_controller_runs_its_demo_by_the_closed_form(tmp_path: Path, clib) -> None:
    """shrimp (Webots' C, unchanged; without it tests/c/shrimp_demo.c making its calls): command 95 straight, read wheel 00's encoder (16 counts a turn, rounded
    up) each 64 ms until it passes 200, then 127 at -75° until it passes 270, then stop. Straight at
    0.058·4.5543 m/s until 17.28 s (the count reaches 200 at 17.216 s, the command goes one step
    later), then the turn: the hinges swing and the six wheels' fit turns it at 1.3268 rad/s (as the
    in-process test above) until the count passes 270 at 21.312 s; it stands still from 21.376 s."""
    controller, webots = sample_controller(tmp_path, "bluebotics/shrimp/controllers/shrimp", TESTS_C / "shrimp_demo.c")
    world = webots_project(tmp_path, "shrimp", controller, {"SHRIMP": "Shrimp"}, 64, clib=clib)
    poses, done = run_poses(world, 23000)
    assert ("Select the 3D window and use the keyboard:" if webots else "demo done at 21.376 s") in done.stdout
    straight, turn = abs(shrimp_command(95, 0)[0][0]), abs(shrimp_command(127, -75)[0][0])

    def first_read(angle_at, counts: int, t: int) -> int:
        """The first 64 ms read from ``t`` on at which ceil(angle / 2π · 16) reaches ``counts``."""
        while math.ceil(angle_at(t) / (2 * math.pi) * 16) < counts:
            t += 64
        return t

    t_turn = first_read(lambda t: straight * t / 1000, 200, 64) + 64
    at_turn = straight * t_turn / 1000
    t_stop = first_read(lambda t: at_turn + turn * (t - t_turn) / 1000, 270, t_turn + 64) + 64
    assert (t_turn, t_stop) == (17280, 21376)
    for t in range(64, t_turn + 1, 64):
        x, y, _, yaw, _, _ = poses[t, "SHRIMP"]
        assert x == pytest.approx(SHRIMP_R * straight * t / 1000, rel=1e-4), t   # the bogies' 3.1415
        assert abs(y) < 2e-4 and abs(yaw) < 1e-4, t
    assert poses[t_turn + 64, "SHRIMP"][3] > 0.04                                # turning left
    drive = load_world(DATA / "shrimp.wbt").world.robots[0].steered_drive
    assert drive is not None
    speeds, front, back = shrimp_command(127, -75)
    wz = fit_twist(drive.wheels, {f"wheel motor 0{i}": s for i, s in enumerate(speeds)},
                   {"front wheel rotation": front, "back wheel rotation": back})[2]
    steady = [poses[t, "SHRIMP"][3] for t in range(t_turn + 640, t_stop + 1, 64)]
    assert turned(steady) == pytest.approx(wz * (t_stop - t_turn - 640) / 1000, abs=1e-6)
    assert poses[t_stop - 64, "SHRIMP"] != poses[t_stop, "SHRIMP"]
    assert all(poses[t, "SHRIMP"] == poses[t_stop, "SHRIMP"] for t in range(t_stop, 22976, 64))


def p_rob3_waits(*seconds: float) -> list[int]:
    """The times (ms) p-rob3's passive_wait()s end at, one after the other: each steps 16 ms while
    start + seconds > the robot's time, in doubles as its C compares them (2.512 + 2.0 > 4.512: that
    wait is one step longer)."""
    ms, ends = 0, []
    for wait in seconds:
        start = ms / 1000
        ms += 16
        while start + wait > ms / 1000:
            ms += 16
        ends.append(ms)
    return ends


@pytest.mark.slow
def test_webots_p_rob3_controller_moves_its_joints_by_their_accelerations(tmp_path: Path, clib) -> None:
    """p-rob3 (Webots' C, unchanged; without it tests/c/p_rob3_moves.c), its links' turns read by the watcher: motor 5 at -0.47183 after the
    first 0.512 s wait; then motors 2 and 3 at 1.55 and 1.12 and motor 5 at -1.95 (the links pitched
    1.55, 2.67, 0.72), 'gripper::right' at 0.5 and its coupled 'gripper::left' with it; then motor 5 at
    -1.09. close_gripper()'s torque is ignored (one warning): half a second later the fingers are still
    open. Motors 2, 3, 5 then reach -0.92, 1.88, 1.5, and motor 1 starts its turn at its 2.61799
    rad/s²: -2.61799·0.016²·32·33/2 = -0.35387 rad 32 steps later."""
    links = {"L1": "motor 1 link", "L2": "motor 2 link", "L3": "motor 3 link", "L5": "motor 5 link",
             "RF": "right finger", "LF": "left finger"}
    controller, _ = sample_controller(tmp_path, "fp_robotics/p-rob3/controllers/p-rob3", TESTS_C / "p_rob3_moves.c")
    world = webots_project(tmp_path, "p-rob3", controller, links, 16, clib=clib)
    poses, done = run_poses(world, 8400)
    pitch = {(t, k): v[4] for (t, k), v in poses.items()}
    roll = {(t, k): v[5] for (t, k), v in poses.items()}
    grasp, align, close, up, lift, rotate = p_rob3_waits(0.5, 2.0, 2.0, 0.5, 0.3, 2.0)
    assert (grasp, align, close, up, lift, rotate) == (512, 2512, 4528, 5040, 5344, 7344)
    assert pitch[grasp, "L5"] == pytest.approx(-3.49066 * 0.016 ** 2 * 32 * 33 / 2, abs=1e-8)
    assert pitch[grasp, "L2"] == pitch[grasp, "L3"] == 0.0
    for t in (align, close):
        assert (pitch[t, "L2"], pitch[t, "L3"]) == pytest.approx((1.55, 2.67), abs=1e-8)
        assert (roll[t, "RF"], roll[t, "LF"]) == pytest.approx((-0.5, 0.5), abs=1e-8)
    assert pitch[align, "L5"] == pytest.approx(0.72, abs=1e-8)
    assert pitch[align + 16, "L5"] == pytest.approx(0.72 + 3.49066 * 0.016 ** 2, abs=1e-8)   # its next move
    assert pitch[close, "L5"] == pytest.approx(1.58, abs=1e-8)
    assert (roll[up, "RF"], roll[up, "LF"]) == pytest.approx((-0.5, 0.5), abs=1e-8)
    assert "wb_motor_set_torque(): RotationalMotor 'gripper::right' moves its joint kinematically" in done.stderr
    assert (pitch[rotate, "L2"], pitch[rotate, "L3"], pitch[rotate, "L5"]) == pytest.approx((-0.92, 0.96, 2.46),
                                                                                           abs=1e-8)
    assert poses[rotate, "L1"][3] == 0.0
    assert poses[rotate + 512, "L1"][3] == pytest.approx(-2.61799 * 0.016 ** 2 * 32 * 33 / 2, abs=1e-8)


@pytest.mark.slow
def test_webots_scara_controller_carries_the_shaft_where_its_two_turns_put_it(tmp_path: Path) -> None:
    """scara (Webots' Python, unchanged; without it tests/controllers/scara_moves.py; it blinks the LED with set(True) / set(False), which Webots' ctypes takes
    as 1 and 0): from its first step on it sets base 0.5, arm 0.14, shaft -0.1; the shaft's solid,
    0.2545 m past the arm's hinge at (0.37, 0.005), itself 0.31 m past the base hinge at (0.06, 0),
    stands where the two turns put it, 0.1 m lower, at 1.008 s and still at 2.096 s."""
    controller, _ = sample_controller(tmp_path, "epson/scara_t6/controllers/scara",
                                      Path(__file__).parent / "controllers" / "scara_moves.py")
    world = webots_project(tmp_path, "scara_t6", controller, {"SHAFT": "shaft_solid"}, 16)
    poses, _ = run_poses(world, 2100)
    assert poses[16, "SHAFT"][:4] == pytest.approx([0.6245, 0.0, 0.256, 0.0], abs=1e-9)

    def turn(a: float, p: np.ndarray) -> np.ndarray:
        c, s = math.cos(a), math.sin(a)
        return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])

    p1, p2, p3 = np.array([0.06, 0.0]), np.array([0.37, 0.005]), np.array([0.6245, 0.0])
    p2_now = p1 + turn(0.5, p2 - p1)
    shaft = p2_now + turn(0.64, p3 - p2)
    for t in (1008, 2096):
        assert poses[t, "SHAFT"][:4] == pytest.approx([*shaft, 0.156, 0.64], abs=1e-8), t


SRV_WALL = '''
Background { skyColor [ 0.4 0.7 1 ] }
DirectionalLight { direction -1 0 -1 }
Solid { translation 1.05 0 0.03 children [ Shape { geometry Box { size 0.1 3 0.06 } } ]
  boundingObject Box { size 0.1 3 0.06 } name "wall" }
'''


@pytest.mark.slow
def test_webots_surveyor_controller_wanders_by_its_camera_and_turns_at_the_wall(tmp_path: Path, clib) -> None:
    """surveyor (Webots' C, unchanged; without it tests/c/surveyor_wander.c, whose simpler rule
    spins right when the whole row is blocked, else goes straight on) starts in its wander mode: each step it compares the image with the
    colours it sampled at its first step. Its scan is hard-wired for 80 × 64 pixels; on the 160 × 128
    camera its bottom scan row is the right half of image row 31, whose pixel-centre rays rise at
    atan(32.5/f) - 0.1742 = 0.04290 rad (f = 80/tan(0.994838/2), the camera pitched down 0.1742). It
    goes straight at 0.3 m/s from 32 ms, until a wall of ours 0.06 m high with its face at x 1.0 (unlit,
    black against the blue sky the scan sampled) fills that row: then all seven column groups are blocked and it spins right ('.': left wheels
    -0.3/0.014 rad/s, right +0.3/0.014), -7.614 rad/s in place, the step after."""
    controller, webots = sample_controller(tmp_path, "surveyor/controllers/surveyor", TESTS_C / "surveyor_wander.c")
    world = webots_project(tmp_path, "srv-1", controller, {"SRV1": "SurveyorSrv1"}, 16, extra=SRV_WALL, clib=clib)
    poses, done = run_poses(world, 2000)
    assert not webots or "O (Wander on)\tP (Wander off)" in done.stdout
    rise = math.atan(32.5 * math.tan(0.994838 / 2) / 80) - 0.1742
    x = lambda t: 0.3 * max(t - 32, 0) / 1000                               # noqa: E731
    seen = next(t for t in range(16, 2000, 16) if x(t) + 0.058 > 1.0 - (0.06 - 0.037) / math.tan(rise))
    assert seen == 1392
    for t in range(16, seen + 1, 16):
        assert poses[t, "SRV1"][:2] + poses[t, "SRV1"][3:4] == pytest.approx([x(t), 0.0, 0.0], abs=1e-9), t
    spun = poses[seen + 16, "SRV1"]
    assert spun[:2] + spun[3:4] == pytest.approx([x(seen), 0.0, -0.6 / SRV_TRACK * 0.016], abs=1e-9)
    assert poses[1984, "SRV1"][3] < -0.3 and poses[1984, "SRV1"][0] < 0.6         # turning away from it
