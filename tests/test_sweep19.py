"""Sweep 19: Webots' device samples for joints not run before (motor2, motor3, coupled_motors), each on a
stand-in world of ours (tests/data/sweep19/: the sample's poses, sizes, joints and motors, our own text,
PROTO shapes stood in for by plain ones) driven in process by the calls its controller makes and checked
against closed forms: each motor by Webots' kinematic rule, each end point by its joint's turns."""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep19"


def rot(axis, angle: float) -> np.ndarray:
    """Rodrigues: the rotation by ``angle`` about ``axis``."""
    x, y, z = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


class KinematicMotor:
    """Webots' kinematic motor control in position control (WbMotor::runKinematicControl), the closed
    form a motor without physics follows: its speed (a magnitude) grows by a·dt a step up to maxVelocity,
    a being maxTorque (the motor's acceleration is -1), and its position moves by speed·dt towards the
    target, never past it; within 1e-6 of the target it rests and its speed drops to 0."""

    def __init__(self, max_velocity: float, acceleration: float, position: float = 0.0):
        self.v_max, self.a = max_velocity, acceleration
        self.x, self.speed, self.target = position, 0.0, position

    def step(self, dt: float) -> None:
        to = self.target - self.x
        if abs(to) < 1e-6:
            self.speed = 0.0
            return
        if abs(self.v_max - self.speed) > 1e-6:
            self.speed = min(self.speed + self.a * dt, self.v_max)
        self.x = min(self.x + self.speed * dt, self.target) if to > 0 else max(self.x - self.speed * dt, self.target)


def supervised(path: Path, tmp_path: Path) -> Live:
    """The stand-in with ``supervisor TRUE`` on its robot (to read its end points' poses as Webots'
    Supervisor does), attached."""
    text = re.sub(r"(DEF \w+ Robot \{)", r'\1 supervisor TRUE name "robot"', path.read_text(), count=1)
    copy = tmp_path / path.name
    copy.write_text(text)
    shutil.copytree(path.parent / "protos", tmp_path / "protos", dirs_exist_ok=True)   # its stand-in PROTOs
    lv = Live(Simulation(load_world(copy), "exact"))
    lv.ok(A, "attach", {"robot": "robot"})
    return lv


def node_pose(lv: Live, name: str) -> tuple[np.ndarray, np.ndarray]:
    node = lv.ok(A, "/robot/robot/get_from_def", {"name": name})["node"]
    got = lv.ok(A, "/robot/robot/get_node_pose", {"node": node})
    return np.array(got["position"]), np.array(got["orientation"]).reshape(3, 3)


# ------------------------------------------------------------------------------------------ motor3
# motor3: a BallJoint whose anchor is 0.11 m up, in a column turned -pi/2 about z: its axes (WbBallJoint:
# jointParameters2's, jointParameters3's cross the first, jointParameters3's; Webots' defaults x, y, z)
# are, in the world, Rz(-pi/2)·x = -y for "motor 3" (the joint's device), x for "motor 1" (device2) and z
# for "motor 2" (device3). The bar's centre is 0.067 m above the anchor.
M3_TURN = -1.570805
M3_ANCHOR = np.array([0.0, 0.0, 0.11])
M3_BAR = np.array([0.0, 0.0, 0.177])


def motor3_targets(counter: int) -> dict[str, float]:
    """What motor3.c asks at its step ``counter`` (after wb_robot_step)."""
    fixed = {50: ("motor 1", 1.0), 100: ("motor 1", -1.0), 200: ("motor 1", 0.0), 300: ("motor 2", 1.0),
             400: ("motor 2", -1.0), 500: ("motor 2", 0.0), 600: ("motor 3", 1.0), 700: ("motor 3", -1.0),
             800: ("motor 3", 0.0)}
    if counter in fixed:
        name, q = fixed[counter]
        return {name: q}
    if counter > 900:
        return {"motor 1": math.cos(0.01 * counter), "motor 2": math.sin(0.012 * counter),
                "motor 3": math.cos(0.013 * counter)}
    return {}


def test_the_motor3_stand_in_loads_its_ball_joint_s_three_motors_on_webots_axes() -> None:
    """The BallJoint's three motors load on WbBallJoint's axes turned with the column (-pi/2 about z):
    "motor 3" about -y, "motor 1" about x riding on it, "motor 2" about z riding on "motor 1", all
    through the anchor (0, 0, 0.11); one load line says the joint moves kinematically, and no drive is
    looked for."""
    w = load_world(DATA / "motor3.wbt")
    assert len(w.warnings) == 1 and "BallJoint motor 'motor 3', 'motor 1', 'motor 2'" in w.warnings[0], w.warnings
    robot = w.world.robots[0]
    assert robot.differential_drive is None and robot.ackermann_drive is None
    d = {m.name: m for m in robot.devices}
    turn = rot((0, 0, 1), M3_TURN)
    for name, axis, on in (("motor 3", (1, 0, 0), None), ("motor 1", (0, 1, 0), "motor 3"),
                           ("motor 2", (0, 0, 1), "motor 1")):
        assert d[name].axis == pytest.approx(turn @ axis, abs=1e-15), name
        assert d[name].anchor == pytest.approx(M3_ANCHOR, abs=1e-15) and d[name].on_joint == on, name
    assert (d["motor 1"].min_position, d["motor 1"].max_position) == (-math.pi / 2, math.pi / 2)


def test_the_motor3_calls_turn_the_bar_about_the_ball_s_three_axes_by_the_kinematic_rule(tmp_path: Path) -> None:
    """motor3.c's calls in process, 1200 steps of 32 ms (the world's default basic step): each motor
    moves by Webots' kinematic rule (maxVelocity 1, maxTorque 10 as its acceleration), "motor 1" to 1,
    −1 and 0 from step 50, "motor 2" from step 300, "motor 3" from 600, then all three following the
    controller's cosines and sine from step 901 (1e-12). Each step the bar (DEF BAR, read as a Supervisor
    reads it) is at anchor + R(a3, q3)·R(a1, q1)·R(z, q2)·(bar₀ − anchor), a3 and a1 Rz(−1.570805)·x ≈
    −y and Rz(−1.570805)·y ≈ x, and turned by that rotation
    (1e-12): the first axis carries the second, which carries the third, as WbBallJoint turns its end
    point."""
    lv = supervised(DATA / "motor3.wbt", tmp_path)
    robot = lv.sim.robot("robot")
    motors = {n: robot.motor(n) for n in ("motor 1", "motor 2", "motor 3")}
    twin = {n: KinematicMotor(1.0, 10.0) for n in motors}
    column = rot((0, 0, 1), M3_TURN)             # -pi/2 to 1e-5: the axes as the column turns them
    axes = {"motor 3": column @ (1, 0, 0), "motor 1": column @ (0, 1, 0), "motor 2": (0.0, 0.0, 1.0)}
    at0, turned0 = node_pose(lv, "BAR")
    assert at0 == pytest.approx(M3_BAR, abs=1e-12)
    assert turned0 == pytest.approx(rot((0, 0, 1), 2 * M3_TURN), abs=1e-12)
    extremes = {n: [0.0, 0.0] for n in motors}
    for counter in range(1, 1201):
        lv.sim.step()
        assert lv.sim.time_ms == 32 * counter
        for n, m in twin.items():
            m.step(0.032)
            assert motors[n].position == pytest.approx(m.x, abs=1e-12), (counter, n)
            extremes[n] = [min(extremes[n][0], m.x), max(extremes[n][1], m.x)]
        turn = rot(axes["motor 3"], twin["motor 3"].x) @ rot(axes["motor 1"], twin["motor 1"].x) @ \
            rot(axes["motor 2"], twin["motor 2"].x)
        if counter % 10 == 0 or counter > 1150:
            at, turned = node_pose(lv, "BAR")
            assert at == pytest.approx(M3_ANCHOR + turn @ (M3_BAR - M3_ANCHOR), abs=1e-12), counter
            assert turned == pytest.approx(turn @ turned0, abs=1e-12), counter
        for n, q in motor3_targets(counter).items():
            motors[n].set_position(q)
            twin[n].target = q
    # each fixed target is reached (1 rad at 1 rad/s after its 0.1 s ramp: within 50 steps of 32 ms)
    assert all(e == [-1.0, 1.0] for e in extremes.values()), extremes


# ------------------------------------------------------------------------------------------ motor2
# motor2: a Hinge2Joint whose anchor is 0.13 m up, its first axis -x ("motor 1"), its second -y
# ("motor 2", riding on the first); the block (DEF BLOCK) 0.026 m behind the head's axis.
M2_ANCHOR = np.array([0.0, 0.0, 0.13])
M2_HEAD = rot((0.5773509358554485, 0.5773489358556708, -0.5773509358554485), 2.0944)


def motor2_targets(counter: int) -> dict[str, float]:
    """What motor2.c asks at its step ``counter`` (after wb_robot_step)."""
    fixed = {50: ("motor 1", 1.0), 100: ("motor 1", -1.0), 200: ("motor 1", 0.0), 300: ("motor 2", 1.0),
             400: ("motor 2", -1.0)}
    if counter in fixed:
        name, q = fixed[counter]
        return {name: q}
    if counter > 500:
        return {"motor 1": 0.5 * math.cos(0.01 * counter), "motor 2": 0.5 * math.sin(0.003 * counter)}
    return {}


def test_the_motor2_calls_turn_the_head_about_its_two_axes_by_the_kinematic_rule(tmp_path: Path) -> None:
    """motor2.c's calls in process, 800 steps of 32 ms: the Hinge2Joint's motors (maxVelocity 1,
    maxTorque 10) follow Webots' kinematic rule to each target (1e-12), "motor 2" held at −1 from step
    400 until the controller's sines take both from step 501; the block is at anchor + R(−x, q1)·R(−y,
    q2)·(block₀ − anchor), turned by R(−x, q1)·R(−y, q2) from where the file puts it (1e-12). The load
    says each motor once (the robot's only motorised joint: no drive looked for)."""
    w = load_world(DATA / "motor2.wbt")
    assert len(w.warnings) == 2 and all("is no wheel (the robot's only motorised joint)" in x for x in w.warnings)
    d = {m.name: m for m in w.world.robots[0].devices}
    assert (d["motor 1"].axis, d["motor 2"].axis) == ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0))
    assert d["motor 2"].on_joint == "motor 1" and d["motor 2"].anchor == pytest.approx(M2_ANCHOR)
    lv = supervised(DATA / "motor2.wbt", tmp_path)
    robot = lv.sim.robot("robot")
    motors = {n: robot.motor(n) for n in ("motor 1", "motor 2")}
    twin = {n: KinematicMotor(1.0, 10.0) for n in motors}
    block0 = M2_ANCHOR + M2_HEAD @ np.array([-0.026, 0.0, 0.0])
    at0, turned0 = node_pose(lv, "BLOCK")
    assert at0 == pytest.approx(block0, abs=1e-12)
    assert turned0 == pytest.approx(M2_HEAD @ rot((0, 0, 1), 3.14159), abs=1e-12)
    for counter in range(1, 801):
        lv.sim.step()
        for n, m in twin.items():
            m.step(0.032)
            assert motors[n].position == pytest.approx(m.x, abs=1e-12), (counter, n)
        turn = rot((-1, 0, 0), twin["motor 1"].x) @ rot((0, -1, 0), twin["motor 2"].x)
        if counter % 10 == 0 or counter > 780:
            at, turned = node_pose(lv, "BLOCK")
            assert at == pytest.approx(M2_ANCHOR + turn @ (block0 - M2_ANCHOR), abs=1e-12), counter
            assert turned == pytest.approx(turn @ turned0, abs=1e-12), counter
        if counter == 500:
            assert (twin["motor 1"].x, twin["motor 2"].x) == (0.0, -1.0)
        for n, q in motor2_targets(counter).items():
            motors[n].set_position(q)
            twin[n].target = q


# ---------------------------------------------------------------------------------- coupled_motors
# coupled_motors: the gripper at (0.2, 0.5, 0) climbs its rod on a SliderJoint (z); each actuated link
# turns about z through (0, ∓0.008) on the carriage (0.01 m up at slider 0) and holds its finger's pivot
# 0.0399 m away, at (0.02869, ∓0.02787) from its anchor, where the finger's origin is. 16 ms steps of the
# controller over the world's basic 8 ms; its cycle: 50 steps, close (0.42), 50, climb to 0.14 at 0.1 m/s,
# 100, open (0), 50, down to 0, 100.
GRIPPER = np.array([0.2, 0.5, 0.0])
FINGERS = {"LEFT_FINGER": (np.array([0.0, -0.008, 0.01]), np.array([0.02869, -0.02787, 0.0]), 1.5708),
           "RIGHT_FINGER": (np.array([0.0, 0.008, 0.01]), np.array([0.02869, 0.02787, 0.0]), 0.0)}


def test_the_coupled_motors_stand_in_says_its_open_loops_and_couples_its_fingers() -> None:
    """The gripper loads with its three motors: the unnamed LinearMotor is "linear motor" (Webots'
    default name), the fingers' "motor::left finger" and "motor::right finger" (multiplier −1) ride on it;
    each passive link's pivot ends in a SolidReference naming the finger, the loop of a parallelogram,
    which no physics closes here: one load line each names it. No drive is looked for."""
    w = load_world(DATA / "coupled_motors.wbt")
    loops = [x for x in w.warnings if "ending in SolidReference" in x]
    assert [x.split(": ", 1)[1] for x in loops] == [
        f"HingeJoint ending in SolidReference {n!r}: the loop it closes is not closed here (no physics); "
        f"{n!r} moves with the joints it is written in only" for n in ("left_gripper", "right_gripper")]
    assert len(w.warnings) == 5, w.warnings       # and one line for each of the three motors' joints
    robot = w.world.robots[0]
    assert robot.differential_drive is None and robot.ackermann_drive is None
    d = {m.name: m for m in robot.devices}
    assert set(d) == {"linear motor", "motor::left finger", "motor::right finger"}
    assert (d["motor::left finger"].on_joint, d["motor::right finger"].on_joint) == ("linear motor",) * 2
    assert (d["motor::left finger"].multiplier, d["motor::right finger"].multiplier) == (1.0, -1.0)


def test_the_coupled_motors_calls_close_lift_open_and_lower_the_gripper_by_the_kinematic_rule(tmp_path: Path) -> None:
    """coupled_motors.c's calls in process for two cycles (700 steps of 16 ms): only "motor::left finger"
    is commanded, and its coupled right finger takes −1 times each target (Webots' coupling). Each
    motor follows Webots' kinematic rule (the fingers at maxVelocity 10 with maxTorque 10 as their
    acceleration: 0.42 in 36 basic steps, 0.288 s; the slider at the 0.1 m/s set, maxForce 15: 0.14 m in
    1.4 s) (1e-12). Each finger's origin is at its link's pivot, carriage anchor + slider + Rz(±q)·pivot,
    as in Webots (1e-12), but turned by ±q with its link, where Webots' closed parallelogram keeps it
    parallel to the carriage; the red block, which Webots' fingers grip and lift, stays on the table
    (the fingers pass through it)."""
    lv = supervised(DATA / "coupled_motors.wbt", tmp_path)
    robot = lv.sim.robot("robot")
    slider, left, right = (robot.motor(n) for n in ("linear motor", "motor::left finger", "motor::right finger"))
    twins = {"slider": KinematicMotor(10.0, 15.0), "left": KinematicMotor(10.0, 10.0),
             "right": KinematicMotor(10.0, 10.0)}
    block0, _ = node_pose(lv, "OBJECT")
    assert block0 == pytest.approx([0.255, 0.49, 0.01], abs=1e-12)
    plan = {50: ("finger", 0.42), 100: ("slider", 0.14), 200: ("finger", 0.0), 250: ("slider", 0.0)}
    closed_at, top_at = None, None
    for step in range(1, 701):
        for _ in range(2):                         # 16 ms: two basic steps of 8 ms
            lv.sim.step()
            for m in twins.values():
                m.step(0.008)
            if closed_at is None and twins["left"].x == 0.42:
                closed_at = lv.sim.time_ms
            if top_at is None and abs(twins["slider"].x - 0.14) < 1e-6:     # 175 steps of 0.0008 m
                top_at = lv.sim.time_ms
        got = (slider.position, left.position, right.position)
        want = (twins["slider"].x, twins["left"].x, twins["right"].x)
        assert got == pytest.approx(want, abs=1e-12), step
        if step % 5 == 0:
            lift = np.array([0.0, 0.0, twins["slider"].x])
            for name, q in (("LEFT_FINGER", twins["left"].x), ("RIGHT_FINGER", twins["right"].x)):
                anchor, pivot, yaw0 = FINGERS[name]
                at, turned = node_pose(lv, name)
                assert at == pytest.approx(GRIPPER + anchor + lift + rot((0, 0, 1), q) @ pivot, abs=1e-12), step
                assert turned == pytest.approx(rot((0, 0, 1), yaw0 + q), abs=1e-12), step
            assert node_pose(lv, "OBJECT")[0] == pytest.approx(block0, abs=1e-12), step
        kind, target = plan.get(step % 350, (None, 0.0))
        if kind == "finger":
            left.set_position(target)              # the controller's one call reaches both fingers
            twins["left"].target, twins["right"].target = target, -target
        elif kind == "slider":
            slider.set_position(target)
            slider.set_velocity(0.1)
            twins["slider"].target, twins["slider"].v_max = target, 0.1
    assert (closed_at, top_at) == (800 + 288, 1600 + 1400)


COUPLED_CONTROLLER = '''\
# Sensorium's test controller making coupled_motors.c's calls (Webots' sample), printing what it asked and
# what the coupled right finger took.
from controller import Robot

robot = Robot()
linear_motor = robot.getDevice("linear motor")
motor = robot.getDevice("motor::left finger")
right = robot.getDevice("motor::right finger")


def wait(n):
    for _ in range(n):
        if robot.step(16) == -1:
            raise SystemExit(0)


while True:
    wait(50)
    motor.setPosition(0.42)
    print(f"close {round(robot.getTime() * 1000)} right target {right.getTargetPosition():g}", flush=True)
    wait(50)
    linear_motor.setPosition(0.14)
    linear_motor.setVelocity(0.1)
    wait(100)
    motor.setPosition(0)
    print(f"open {round(robot.getTime() * 1000)} right target {right.getTargetPosition():g}", flush=True)
    wait(50)
    linear_motor.setPosition(0)
    wait(100)
'''

FINGER_WATCHER = '''\
import math
import os
from controller import Supervisor

sup = Supervisor()
fingers = [sup.getFromDef(n) for n in ("LEFT_FINGER", "RIGHT_FINGER")]
while sup.step(8) != -1:
    t = round(sup.getTime() * 1000)
    if t in (1088, 3000, 3200, 3488, 5600):
        for name, node in zip("LR", fingers):
            p, r = node.getPosition(), node.getOrientation()
            print(f"{name} {t} {p[0]:.9f} {p[1]:.9f} {p[2]:.9f} {math.atan2(r[3], r[0]):.9f}", flush=True)
'''


@pytest.mark.slow
def test_the_coupled_motors_calls_under_sensorium_run_move_both_fingers_and_the_carriage(tmp_path: Path) -> None:
    """Our Python controller making coupled_motors.c's calls under ``sensorium run`` for 6 s, a watcher
    Supervisor printing the fingers' poses: the one command to "motor::left finger" gives the right
    finger −0.42 (its getTargetPosition), and each finger is where the closed form puts it (1e-9): closed
    at 1.088 s, carried 0.14 m up at 3.0 s, open again 0.288 s after 3.2 s, down by 5.6 s."""
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "coupled_motors.wbt"
    world.write_text((DATA / "coupled_motors.wbt").read_text() +
                     'Robot { name "watcher" supervisor TRUE controller "watcher" }\n')
    for name, source in (("coupled_motors", COUPLED_CONTROLLER), ("watcher", FINGER_WATCHER)):
        (tmp_path / "controllers" / name).mkdir(parents=True)
        (tmp_path / "controllers" / name / f"{name}.py").write_text(source)
    done = subprocess.run(sensorium("run", str(world), "--until", "6000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    said = [x.split("] ", 1)[1] for x in done.stdout.splitlines() if x.startswith("[robot] ")]
    assert said[:2] == ["close 800 right target -0.42", "open 3200 right target -0"], done.stdout[-2000:]
    poses = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] "):
            name, t, *values = line.split("] ", 1)[1].split()
            poses[name, int(t)] = [float(v) for v in values]
    for t, q, lift in ((1088, 0.42, 0.0), (3000, 0.42, 0.14), (3488, 0.0, 0.14), (5600, 0.0, 0.0)):
        for name, key, sign in (("L", "LEFT_FINGER", 1), ("R", "RIGHT_FINGER", -1)):
            anchor, pivot, yaw0 = FINGERS[key]
            at = GRIPPER + anchor + [0.0, 0.0, lift] + rot((0, 0, 1), sign * q) @ pivot
            assert poses[name, t] == pytest.approx([*at, yaw0 + sign * q], abs=1e-9), (name, t)


# ----------------------------------------------------------------------------- hinge_joint_with_backlash
# hinge_joint_with_backlash: the rotor's hinge along x through (0.19, 0, 0) in our plain stand-in of the
# HingeJointWithBacklash PROTO (tests/data/sweep19/protos/); the output's marker 0.005 m past the anchor,
# 0.0075 m off the axis. The controller turns the rotor at ±0.2 rad/s, reversing once its sensor reads
# past ±1.0471; its 16 ms steps are the world's 32 ms basic steps here (rounded up, as Webots does).
BACKLASH_ANCHOR = np.array([0.19, 0.0, 0.0])


class VelocityMotor:
    """Webots' kinematic rule in velocity control (target +inf): the signed speed moves towards the
    commanded velocity by at most a·dt a step (a: maxTorque 10 here), the position by speed·dt."""

    def __init__(self, acceleration: float):
        self.a, self.x, self.speed, self.velocity = acceleration, 0.0, 0.0, 0.0

    def step(self, dt: float) -> None:
        if abs(self.velocity - self.speed) > 1e-6:
            self.speed = (min(self.speed + self.a * dt, self.velocity) if self.velocity > self.speed
                          else max(self.speed - self.a * dt, self.velocity))
        self.x += self.speed * dt


def test_the_backlash_sample_s_rotor_swings_between_its_bounds_and_the_output_turns_with_it(tmp_path: Path) -> None:
    """hinge_joint_with_backlash.c's calls in process for 60 s (1875 steps of 32 ms): the rotor reaches
    0.2 rad/s in one step (maxTorque 10 as its acceleration: 0.32 rad/s a step), its sensor reads the
    rule's angle at every step (1e-12) and the controller reverses it the step after it reads past
    ±1.0471: first at 5.248 s (164 steps of 0.0064 rad: 1.0496), then every 10.528 s at −1.0534 and
    1.0496 in turn (329 steps: the speed turns over in two, 0.2, −0.12, −0.2, then 328 of 0.0064 rad). The output (DEF OUTPUT) turns with the rotor about x
    through the anchor (1e-12, as a Supervisor reads it): our stand-in PROTO's inner hinge stays at 0,
    where Webots' physics lets the output lag up to the 0.4 rad backlash behind the rotor after each
    reversal, pushed by the gear's stops."""
    w = load_world(DATA / "hinge_joint_with_backlash.wbt")
    assert len(w.warnings) == 1 and "HingeJoint motor 'rotor motor' is no wheel" in w.warnings[0], w.warnings
    lv = supervised(DATA / "hinge_joint_with_backlash.wbt", tmp_path)
    robot = lv.sim.robot("robot")
    motor, sensor = robot.motor("rotor motor"), lv.sim.device("robot/rotor sensor")
    sensor.enable(32)
    motor.set_position(math.inf)
    motor.set_velocity(0.2)
    twin = VelocityMotor(10.0)
    twin.velocity = 0.2
    at0, turned0 = node_pose(lv, "OUTPUT")
    assert at0 == pytest.approx([0.0, 0.0, 0.0], abs=1e-12) and turned0 == pytest.approx(np.eye(3), abs=1e-12)
    reversals = []
    for k in range(1, 1876):
        lv.sim.step()
        twin.step(0.032)
        position = float(sensor.value)
        assert position == pytest.approx(twin.x, abs=1e-12), k
        if k % 25 == 0:
            at, turned = node_pose(lv, "OUTPUT")
            turn = rot((1, 0, 0), twin.x)
            assert turned == pytest.approx(turn, abs=1e-12), k
            assert at == pytest.approx(BACKLASH_ANCHOR - turn @ BACKLASH_ANCHOR, abs=1e-12), k
        if position > 1.0471 and twin.velocity > 0 or position < -1.0471 and twin.velocity < 0:
            reversals.append((lv.sim.time_ms, round(position, 4)))
        if position > 1.0471:
            motor.set_velocity(-0.2)
            twin.velocity = -0.2
        elif position < -1.0471:
            motor.set_velocity(0.2)
            twin.velocity = 0.2
    assert reversals == [(5248 + 10528 * i, (1.0496, -1.0534)[i % 2]) for i in range(6)]


# ---------------------------------------------------------------------- motor3 under sensorium run
# Webots' controller is Webots' file, never this repository's: the test copies it from $WEBOTS_HOME (an
# installation or a source tree) into its temporary project, or, without it, our own C controller making
# the same calls (tests/c/ball_joint_targets.c), builds it against our libController and runs the world.
TESTS_C = Path(__file__).parent / "c"
REPO = Path(__file__).resolve().parent.parent
BAR_WATCHER = '''from controller import Supervisor

sup = Supervisor()
bar = sup.getFromDef("BAR")
while sup.step(32) != -1:
    t = round(sup.getTime() * 1000)
    if t % 3200 == 0:
        print(f"bar {t} " + " ".join(f"{v:.12f}" for v in bar.getPosition() + bar.getOrientation()), flush=True)
'''


@pytest.mark.slow
def test_the_motor3_controller_under_sensorium_run_turns_the_bar_as_the_closed_form(tmp_path: Path) -> None:
    """motor3 (Webots' C, unchanged, with WEBOTS_HOME; else tests/c/ball_joint_targets.c) built against our
    libController, under ``sensorium run`` for 38.4 s with a watcher Supervisor: every 3.2 s the bar is where
    the in-process closed form puts it (the kinematic rule on each motor, R(a3, q3)·R(a1, q1)·R(z, q2) about
    the anchor; 1e-9)."""
    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path / "cbuild"
    make = ["make", "-s", "-C", str(REPO / "sensorium" / "client" / "c")]
    done = subprocess.run([*make, f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    libs = subprocess.run([*make, "libs"], capture_output=True, text=True, timeout=60).stdout.split()
    folder = tmp_path / "controllers" / "motor3"
    home = os.environ.get("WEBOTS_HOME")
    webots = Path(home or "/nonexistent") / "projects" / "samples" / "devices" / "controllers" / "motor3" / "motor3.c"
    folder.mkdir(parents=True)
    shutil.copy(webots if webots.is_file() else TESTS_C / "ball_joint_targets.c", folder / "motor3.c")
    done = subprocess.run(["cc", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", str(folder / "motor3.c"),
                           "-o", str(folder / "motor3"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    (tmp_path / "controllers" / "watcher").mkdir()
    (tmp_path / "controllers" / "watcher" / "watcher.py").write_text(BAR_WATCHER)
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "motor3.wbt"
    world.write_text((DATA / "motor3.wbt").read_text() + 'Robot { name "watcher" supervisor TRUE controller "watcher" }\n')
    done = subprocess.run(sensorium("run", str(world), "--until", "38400", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    printed = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] bar "):
            t, *values = line.split()[2:]
            printed[int(t)] = np.array([float(v) for v in values])
    assert sorted(printed) == [3200 * i for i in range(1, 13)], done.stdout[-2000:]
    column = rot((0, 0, 1), M3_TURN)
    axes = {"motor 3": column @ (1, 0, 0), "motor 1": column @ (0, 1, 0), "motor 2": (0.0, 0.0, 1.0)}
    twin = {n: KinematicMotor(1.0, 10.0) for n in axes}
    turned0 = rot((0, 0, 1), 2 * M3_TURN)
    for counter in range(1, 1201):
        for m in twin.values():
            m.step(0.032)
        if 32 * counter in printed:
            turn = rot(axes["motor 3"], twin["motor 3"].x) @ rot(axes["motor 1"], twin["motor 1"].x) @ \
                rot(axes["motor 2"], twin["motor 2"].x)
            got = printed[32 * counter]
            assert got[:3] == pytest.approx(M3_ANCHOR + turn @ (M3_BAR - M3_ANCHOR), abs=1e-9), counter
            assert got[3:].reshape(3, 3) == pytest.approx(turn @ turned0, abs=1e-9), counter
        for n, q in motor3_targets(counter).items():
            twin[n].target = q
