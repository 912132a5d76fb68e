"""Sweep 20: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep20/: the
sample's poses, sizes, joints and devices, our own text, PROTO shapes stood in for by plain ones) driven
in process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_supervisor import A, Live
from test_sweep19 import KinematicMotor, motor2_targets, rot

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep20"


def supervised(path: Path, tmp_path: Path, robot: str, after: str | None = None) -> Live:
    """The stand-in with ``supervisor TRUE`` on the robot named ``robot`` (to read the end points' poses
    as Webots' Supervisor does), written after its line ``after`` (its name's line unless said), attached
    to it."""
    line = after or f'  name "{robot}"'
    text = path.read_text().replace(line + "\n", line + "\n  supervisor TRUE\n", 1)
    assert "supervisor TRUE" in text
    copy = tmp_path / path.name
    copy.write_text(text)
    if (path.parent / "protos").is_dir():
        shutil.copytree(path.parent / "protos", tmp_path / "protos", dirs_exist_ok=True)
    lv = Live(Simulation(load_world(copy), "exact"))
    lv.ok(A, "attach", {"robot": robot})
    return lv


def node_pose(lv: Live, robot: str, name: str, inside: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The pose of the node DEF ``name`` (in the PROTO instance DEF ``inside``: getFromProtoDef, as a
    PROTO's own DEF names are hidden from getFromDef in Webots), read as a Supervisor reads it."""
    node = lv.ok(A, f"/{robot}/robot/get_from_def", {"name": inside or name})["node"]
    if inside is not None:
        node = lv.ok(A, f"/{robot}/robot/get_from_proto_def", {"node": node, "name": name})["node"]
    assert node != 0, (name, inside)
    got = lv.ok(A, f"/{robot}/robot/get_node_pose", {"node": node})
    return np.array(got["position"]), np.array(got["orientation"]).reshape(3, 3)


# ------------------------------------------------------------------------- hinge_2_joint_with_backlash
# hinge_2_joint_with_backlash: two robots run motor2.c. The first, at x 0.1, is sweep 19's motor2 head; the
# second, at x -0.1 turned by -1.570795 about z, its column turned back by 1.5708 (a net 5e-6 rad), holds a
# Hinge2JointWithBacklash (backlash 0.2 on both axes): a free hinge about -x ("motor 1") holding the first
# gear, a Hinge2Joint about -x within ±0.1 and about -y ("motor 2"), then a hinge about -y within ±0.1
# carrying the head. Each joint's anchor is 0.07 m above its column's centre (z 0.13).
H2_ROBOTS = {"robot without backlash": ("WITHOUT_BACKLASH", np.array([0.1, 0.0, 0.0]), 0.0),
             "robot with backlash": ("WITH_BACKLASH", np.array([-0.1, 0.0, 0.0]), -1.570795 + 1.5708)}
H2_HEAD = rot((0.5773509358554485, 0.5773489358556708, -0.5773509358554485), 2.0944)


def test_the_backlash_head_loads_its_motors_on_the_same_axes_as_the_plain_one() -> None:
    """Our JavaScript stand-in of Hinge2JointWithBacklash expands, for backlashes of 0.2, to a free
    hinge carrying "motor 1" and a Hinge2Joint carrying "motor 2" on its second axis, its first axis
    and the last hinge passive: the robot's two motors are on the axes of the plain robot's, turned with
    its column (in the robot's frame Rz(1.5708)·(−x) and Rz(1.5708)·(−y)), "motor 2" riding on "motor
    1", both through the anchor 0.13 m up. Each motor is one load line (no drive is looked for)."""
    w = load_world(DATA / "hinge_2_joint_with_backlash.wbt")
    assert len(w.warnings) == 4 and all("moves kinematically" in x for x in w.warnings), w.warnings
    robots = {r.name: r for r in w.world.robots}
    assert set(robots) == set(H2_ROBOTS)
    column = {"robot without backlash": np.eye(3), "robot with backlash": rot((0, 0, 1), 1.5708)}
    for name, robot in robots.items():
        assert robot.differential_drive is None and robot.ackermann_drive is None
        d = {m.name: m for m in robot.devices}
        assert set(d) == {"motor 1", "motor 2"}, name
        assert d["motor 1"].axis == pytest.approx(column[name] @ (-1, 0, 0), abs=1e-15), name
        assert d["motor 2"].axis == pytest.approx(column[name] @ (0, -1, 0), abs=1e-15), name
        assert d["motor 2"].on_joint == "motor 1" and d["motor 1"].on_joint is None, name
        for m in d.values():
            assert m.anchor == pytest.approx((0.0, 0.0, 0.13), abs=1e-15), name
            assert (m.min_position, m.max_position) == (0.0, 0.0), name      # no limits: Webots' defaults


def test_both_heads_follow_the_motor2_calls_by_the_kinematic_rule(tmp_path: Path) -> None:
    """motor2.c's calls, made by both robots' controllers, in process for 800 steps of 32 ms: each robot's
    motors follow Webots' kinematic rule (maxVelocity 1, maxTorque 10 as the acceleration) (1e-12), and
    each block (DEF BLOCK_..., read by a Supervisor) is at anchor + R(a1, q1)·R(a2, q2)·(block₀ − anchor)
    and turned by it (1e-12), a1 and a2 the robot's −x and −y turned by its column's net yaw (0, and
    −1.570795 + 1.5708 = 5e-6 rad). The backlash joint's passive stops (±0.1) never move here: its head
    turns with its motors exactly as the plain one, where Webots' physics lets it lag behind them by up
    to 0.1 rad about each axis after each reversal."""
    lv = supervised(DATA / "hinge_2_joint_with_backlash.wbt", tmp_path, "robot without backlash")
    heads = {}
    for name, (tag, origin, yaw) in H2_ROBOTS.items():
        robot = lv.sim.robot(name)
        turn = rot((0, 0, 1), yaw)
        anchor = origin + np.array([0.0, 0.0, 0.13])
        block0 = anchor + turn @ H2_HEAD @ np.array([-0.026, 0.0, 0.0])
        at0, turned0 = node_pose(lv, "robot without backlash", f"BLOCK_{tag}")
        assert at0 == pytest.approx(block0, abs=1e-12), name
        assert turned0 == pytest.approx(turn @ H2_HEAD @ rot((0, 0, 1), 3.14159), abs=1e-12), name
        heads[name] = (tag, anchor, block0, turned0, turn @ (-1, 0, 0), turn @ (0, -1, 0),
                       {n: robot.motor(n) for n in ("motor 1", "motor 2")},
                       {n: KinematicMotor(1.0, 10.0) for n in ("motor 1", "motor 2")})
    for counter in range(1, 801):
        lv.sim.step()
        for name, (tag, anchor, block0, turned0, a1, a2, motors, twin) in heads.items():
            for n, m in twin.items():
                m.step(0.032)
                assert motors[n].position == pytest.approx(m.x, abs=1e-12), (name, counter, n)
            if counter % 10 == 0 or counter > 780:
                turn = rot(a1, twin["motor 1"].x) @ rot(a2, twin["motor 2"].x)
                at, turned = node_pose(lv, "robot without backlash", f"BLOCK_{tag}")
                assert at == pytest.approx(anchor + turn @ (block0 - anchor), abs=1e-12), (name, counter)
                assert turned == pytest.approx(turn @ turned0, abs=1e-12), (name, counter)
            if counter == 500:
                assert (twin["motor 1"].x, twin["motor 2"].x) == (0.0, -1.0)
            for n, q in motor2_targets(counter).items():
                motors[n].set_position(q)
                twin[n].target = q



MOTOR2_CONTROLLER = '''\
# Sensorium's test controller making motor2.c's calls (Webots' sample): "motor 1" to 1, -1, 0 from step
# 50, "motor 2" to 1, -1 from step 300, then both following cosines and sines from step 501.
import math
from controller import Robot

robot = Robot()
motors = {n: robot.getDevice(n) for n in ("motor 1", "motor 2")}
print(f"{robot.getName()} runs", flush=True)
fixed = {50: ("motor 1", 1.0), 100: ("motor 1", -1.0), 200: ("motor 1", 0.0), 300: ("motor 2", 1.0),
         400: ("motor 2", -1.0)}
counter = 0
while robot.step(32) != -1:
    counter += 1
    if counter in fixed:
        motors[fixed[counter][0]].setPosition(fixed[counter][1])
    elif counter > 500:
        motors["motor 1"].setPosition(0.5 * math.cos(0.01 * counter))
        motors["motor 2"].setPosition(0.5 * math.sin(0.003 * counter))
'''

H2_WATCHER = '''\
from controller import Supervisor

sup = Supervisor()
blocks = {tag: sup.getFromDef(f"BLOCK_{tag}") for tag in ("WITHOUT_BACKLASH", "WITH_BACKLASH")}
while sup.step(32) != -1:
    t = round(sup.getTime() * 1000)
    if t in (6400, 16000, 25600):
        for tag, node in blocks.items():
            p = node.getPosition()
            print(f"{tag} {t} {p[0]:.9f} {p[1]:.9f} {p[2]:.9f}", flush=True)
'''


@pytest.mark.slow
def test_both_robots_run_motor2_under_sensorium_run_and_their_blocks_meet_the_closed_form(tmp_path: Path) -> None:
    """Our Python controller making motor2.c's calls, named by both robots, under ``sensorium run`` for
    26 s with a watcher Supervisor: each robot runs its own copy, and each block is where the kinematic
    rule and the two turns put it at 6.4, 16 and 25.6 s (1e-9)."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "hinge_2_joint_with_backlash.wbt"
    world.write_text((DATA / "hinge_2_joint_with_backlash.wbt").read_text() +
                     'Robot { name "watcher" supervisor TRUE controller "watcher" }\n')
    for name, source in (("motor2", MOTOR2_CONTROLLER), ("watcher", H2_WATCHER)):
        (tmp_path / "controllers" / name).mkdir(parents=True)
        (tmp_path / "controllers" / name / f"{name}.py").write_text(source)
    done = subprocess.run(sensorium("run", str(world), "--until", "26000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    for name in H2_ROBOTS:
        assert f"[{name}] {name} runs" in lines, done.stdout[-2000:]
    got = {}
    for line in lines:
        if line.startswith("[watcher] "):
            tag, t, *values = line.split("] ", 1)[1].split()
            got[tag, int(t)] = [float(v) for v in values]
    twin = {n: KinematicMotor(1.0, 10.0) for n in ("motor 1", "motor 2")}
    for counter in range(1, 801):
        for m in twin.values():
            m.step(0.032)
        if 32 * counter in (6400, 16000, 25600):
            for tag, origin, yaw in H2_ROBOTS.values():
                turn = rot((0, 0, 1), yaw)
                anchor = origin + np.array([0.0, 0.0, 0.13])
                block0 = anchor + turn @ H2_HEAD @ np.array([-0.026, 0.0, 0.0])
                q = rot(turn @ (-1, 0, 0), twin["motor 1"].x) @ rot(turn @ (0, -1, 0), twin["motor 2"].x)
                assert got[tag, 32 * counter] == pytest.approx(anchor + q @ (block0 - anchor), abs=1e-9), (tag, counter)
        for n, target in motor2_targets(counter).items():
            twin[n].target = target

# ----------------------------------------------------------------------------------- khepera3_gripper
# khepera3_gripper (k-team/khepera3): the Khepera III (wheels of 0.0212 m at y ±0.0458, turning about +y)
# turned 2.87979 rad at the origin, 16 ms steps; its gripper in the turret slot: "horizontal_motor" turns
# the driven arm about -y through (0.05, -0.028, 0.087) in the robot's frame (maxTorque 5: its
# acceleration here), "finger_motor::left" and its coupled "finger_motor::right" (maxTorque 10) turn the
# fingers' tip hinges. The controller's script: step(s) runs ⌈s / 0.016⌉ steps.
K3 = "Khepera III"
K3_R, K3_AXLE = 0.0212, 0.0916
K3_YAW0 = 2.87979
K3_ARM_ANCHOR = np.array([0.05, -0.028, 0.087])
K3_ARM0 = rot((0.57735, -0.57735, -0.57735), 2.094395)


def k3_script() -> list[tuple[dict[str, float], int]]:
    """khepera3_gripper.c's calls before its Braitenberg loop: (the settings made, then the steps run)."""
    def steps(seconds: float) -> int:
        return math.ceil(seconds * 1000 / 16)

    def wheels(left: float, right: float) -> dict[str, float]:
        return {"left": left, "right": right}

    return [(wheels(0, 0), steps(1.0)),                                   # stop(1.0)
            ({**wheels(12.8, 12.8), "arm": -3.0}, steps(1.0)),           # moveForwards, moveArms(-3)
            (wheels(0, 0), steps(1.0)),                                   # stop(1.0)
            ({"fingers": 0.42}, steps(1.0)),
            ({"arm": 0.0, **wheels(-12.8, -12.8)}, steps(1.0)),
            (wheels(0, 0), steps(1.0)),
            (wheels(-2.4, 2.4), steps(0.5)),                              # turn(-2.4): left about its axle
            (wheels(12.8, 12.8), steps(0.6)),
            (wheels(0, 0), steps(0.25)),
            ({"arm": -1.6}, steps(1.5)),
            ({"fingers": 0.0}, steps(1.0)),
            ({"arm": 0.0, "fingers": 0.0}, steps(1.0)),
            (wheels(-12.8, -12.8), steps(1.0)),
            (wheels(-10.7, 10.7), steps(1.0))]


def k3_move(x: float, y: float, yaw: float, wl: float, wr: float, dt: float) -> tuple[float, float, float]:
    return k3_move_on(x, y, yaw, wl, wr, dt, K3_R, K3_AXLE)


def k3_move_on(x: float, y: float, yaw: float, wl: float, wr: float, dt: float, radius: float,
               axle: float) -> tuple[float, float, float]:
    """One step of a two-wheel drive (the axle's centre at the origin): the arc of v = r(ωl + ωr)/2,
    ω = r(ωr − ωl)/axle."""
    v, w = radius * (wl + wr) / 2, radius * (wr - wl) / axle
    if w == 0.0:
        return x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw), yaw
    return (x + v / w * (math.sin(yaw + w * dt) - math.sin(yaw)), y - v / w * (math.cos(yaw + w * dt) - math.cos(yaw)),
            math.remainder(yaw + w * dt, 2 * math.pi))


def test_the_khepera3_gripper_stand_in_loads_its_sensors_drive_and_gripper_motors() -> None:
    """The Khepera III loads with the devices its controllers ask for (ds0..ds10, us0..us4, both wheel
    motors and sensors, the rs232 emitter and receiver, the gripper's three motors), a two-wheel drive
    (radius 0.0212 m, axle 0.0916 m) settled from z 0 to −0.0033 (its wheels' bottom 3.3 mm above its
    origin); each finger motor sits on the tip hinge that closes its finger's loop (a SolidReference to
    the tip): one line says the loop is not closed (and one for each of the head's two), and the motor's
    own line says it moves nothing (it said the shapes past its joint moved with it, and none are); the
    fingers' motors ride on the arm's."""
    w = load_world(DATA / "khepera3_gripper.wbt")
    loops = [x.split(": ", 1)[1].split(":")[0] for x in w.warnings if "ending in SolidReference" in x]
    assert sorted(loops) == ["HingeJoint ending in SolidReference 'gripper_head'"] * 2 + [
        "HingeJoint ending in SolidReference 'left_finger_tip'", "HingeJoint ending in SolidReference 'right_finger_tip'"]
    for side in ("left", "right"):         # a motor on a loop-closing joint: moved by the rule, moving nothing
        (line,) = [x for x in w.warnings if f"motor 'finger_motor::{side}'" in x]
        assert line.endswith(f"its joint moves kinematically (Webots' rule without physics; its PositionSensor reads "
                             f"it), but moves nothing: its end point is SolidReference '{side}_finger_tip', whose "
                             f"loop is not closed here"), line
    (line,) = [x for x in w.warnings if "motor 'horizontal_motor'" in x]
    assert line.endswith("and the shapes and devices past the joint with it"), line
    assert len(w.warnings) == 7, w.warnings
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert names == {*(f"ds{k}" for k in range(11)), *(f"us{k}" for k in range(5)), "left wheel motor", "right wheel motor",
                     "left wheel sensor", "right wheel sensor", "rs232_out", "rs232_in", "horizontal_motor",
                     "finger_motor::left", "finger_motor::right"}
    drive = robot.differential_drive
    assert (drive.wheel_radius, drive.axle_length, drive.wheel_bottom) == pytest.approx((K3_R, K3_AXLE, 0.0033), abs=1e-15)
    d = {m.name: m for m in robot.devices}
    assert d["horizontal_motor"].axis == (0.0, -1.0, 0.0)
    assert d["horizontal_motor"].anchor == pytest.approx(K3_ARM_ANCHOR, abs=1e-15)
    assert d["finger_motor::left"].on_joint == d["finger_motor::right"].on_joint == "horizontal_motor"
    sim = Simulation(w, "exact")
    assert sim.robot(K3).pose.translation == pytest.approx([0.0, 0.0, -0.0033], abs=1e-15)


def test_the_khepera3_gripper_script_drives_and_moves_the_gripper_by_the_closed_forms(tmp_path: Path) -> None:
    """khepera3_gripper.c's script in process (810 steps of 16 ms, 12.96 s): the robot stays 1.008 s,
    drives 12.8 × 0.0212 = 0.27136 m/s for 63 steps, backs the same, turns left in place at 2 × 2.4 ×
    0.0212 / 0.0916 = 1.1109 rad/s for 32 steps, drives 38 steps, backs 63 and turns at 4.9528 rad/s for
    63, its pose the arc of the wheel speeds each step (1e-9); nothing holds it (the boxes and the
    cylinder are out of its way). The arm motor follows Webots' kinematic rule at the 2 rad/s set
    (acceleration 5) to −3, 0, −1.6 and 0, the fingers' coupled pair at 2 rad/s (acceleration 10) to 0.42
    and back, each step (1e-12); the gripper head (read by a Supervisor) turns rigidly with the arm about
    its anchor (1e-9). Webots' parallelogram keeps the head level and its fingers close on the cylinder
    and lift it; here the head tilts with the arm, the fingers' motors move nothing (their hinges end in
    SolidReferences) and the cylinder stays where it stands."""
    lv = supervised(DATA / "khepera3_gripper.wbt", tmp_path, K3, after='  controller "khepera3_gripper"')
    sim = lv.sim
    robot = sim.robot(K3)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    arm, finger, coupled = (robot.motor(n) for n in ("horizontal_motor", "finger_motor::left", "finger_motor::right"))
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    arm_twin, finger_twin = KinematicMotor(10.0, 5.0), KinematicMotor(10.0, 10.0)
    x, y, yaw = 0.0, 0.0, K3_YAW0
    load0, _ = node_pose(lv, K3, "CYLINDER_LOAD")
    wl = wr = 0.0
    counter = 0
    for settings, steps in k3_script():
        if "left" in settings:
            wl, wr = settings["left"], settings["right"]
            left.set_velocity(wl)
            right.set_velocity(wr)
        if "arm" in settings:
            arm.set_velocity(2.0)
            arm.set_position(settings["arm"])
            arm_twin.v_max, arm_twin.target = 2.0, settings["arm"]
        if "fingers" in settings:
            finger.set_velocity(2.0)
            finger.set_position(settings["fingers"])
            finger_twin.v_max, finger_twin.target = 2.0, settings["fingers"]
        for _ in range(steps):
            sim.step()
            counter += 1
            x, y, yaw = k3_move(x, y, yaw, wl, wr, 0.016)
            arm_twin.step(0.016)
            finger_twin.step(0.016)
            r = robot.pose.rotation
            assert [*robot.pose.translation[:2], math.atan2(r[1][0], r[0][0])] == pytest.approx([x, y, yaw], abs=1e-9), counter
            assert arm.position == pytest.approx(arm_twin.x, abs=1e-12), counter
            assert finger.position == pytest.approx(finger_twin.x, abs=1e-12), counter
            assert coupled.position == pytest.approx(finger_twin.x, abs=1e-12), counter
            if counter % 8 == 0:
                body = rot((0, 0, 1), yaw)
                turn = rot((0, -1, 0), arm_twin.x)
                head_at = np.array([x, y, -0.0033]) + body @ (K3_ARM_ANCHOR + turn @ (np.array([0, 0, 0.074]) - K3_ARM_ANCHOR))
                at, turned = node_pose(lv, K3, "GRIPPER_HEAD", inside="BASE")
                assert at == pytest.approx(head_at, abs=1e-9), counter
                assert turned == pytest.approx(body @ turn @ K3_ARM0, abs=1e-9), counter
    assert counter == 810
    assert node_pose(lv, K3, "CYLINDER_LOAD")[0] == pytest.approx(load0, abs=1e-12)


K3_CONTROLLER = '''\
# Sensorium's test controller making khepera3_gripper.c's calls (Webots' sample): its script, then its
# Braitenberg loop over ds0..ds8.
import math
from controller import Robot

robot = Robot()
step_ms = int(robot.getBasicTimeStep())
sensors = [robot.getDevice(f"ds{k}") for k in range(9)]
for s in sensors:
    s.enable(step_ms)
arm, fingers = robot.getDevice("horizontal_motor"), robot.getDevice("finger_motor::left")
left, right = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
for m in (left, right):
    m.setPosition(math.inf)
    m.setVelocity(0.0)
print(f"The {robot.getName()} robot is initialized, it uses {len(sensors)} distance sensors", flush=True)
MATRIX = [(-2.67, -2.67), (-10.86, 21.37), (-16.03, 26.71), (-37.4, 37.4), (37.4, -32.06), (26.71, -21.37),
          (21.37, -10.86), (-2.67, -2.67), (-5.34, -5.34)]


def wait(seconds):
    elapsed = 0
    while elapsed < seconds * 1000:
        robot.step(step_ms)
        elapsed += step_ms


def wheels(l, r):
    left.setVelocity(l)
    right.setVelocity(r)


def move(motor, q):
    motor.setVelocity(2.0)
    motor.setPosition(q)


wheels(0, 0); wait(1.0)
wheels(12.8, 12.8); move(arm, -3.0); wait(1.0)
wheels(0, 0); wait(1.0)
move(fingers, 0.42); wait(1.0)
move(arm, 0.0); wheels(-12.8, -12.8); wait(1.0)
wheels(0, 0); wait(1.0)
wheels(-2.4, 2.4); wait(0.5)
wheels(12.8, 12.8); wait(0.6)
wheels(0, 0); wait(0.25)
move(arm, -1.6); wait(1.5)
move(fingers, 0.0); wait(1.0)
move(arm, 0.0); move(fingers, 0.0); wait(1.0)
wheels(-12.8, -12.8); wait(1.0)
wheels(-10.7, 10.7); wait(1.0)
while robot.step(step_ms) != -1:
    values = [s.getValue() for s in sensors]
    speed = [max(-19.1, min(19.1, sum(MATRIX[j][i] * (1.0 - values[j] / 2000.0) for j in range(9)))) for i in (0, 1)]
    wheels(*speed)
'''

K3_WATCHER = '''\
import math
from controller import Supervisor

sup = Supervisor()
khepera = sup.getFromDef("KHEPERA")
ends = {int(t) for t in "ENDS".split()}
while sup.step(16) != -1:
    t = round(sup.getTime() * 1000)
    if t in ends:
        p, r = khepera.getPosition(), khepera.getOrientation()
        print(f"{t} {p[0]:.9f} {p[1]:.9f} {math.atan2(r[3], r[0]):.9f}", flush=True)
'''


@pytest.mark.slow
def test_the_khepera3_gripper_calls_under_sensorium_run_drive_the_script_s_closed_form(tmp_path: Path) -> None:
    """Our Python controller making khepera3_gripper.c's calls under ``sensorium run`` for 16 s, a watcher
    Supervisor printing the Khepera's pose at the end of each scripted phase: it prints Webots' sample's
    first line, and the robot is where the closed form of the script's wheel speeds puts it (1e-9) until
    its Braitenberg loop takes over at 12.96 s."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    ends, t, x, y, yaw, want = [], 0, 0.0, 0.0, K3_YAW0, {}
    wl = wr = 0.0
    for settings, steps in k3_script():
        wl, wr = (settings["left"], settings["right"]) if "left" in settings else (wl, wr)
        for _ in range(steps):
            x, y, yaw = k3_move(x, y, yaw, wl, wr, 0.016)
        t += 16 * steps
        ends.append(t)
        want[t] = (x, y, yaw)
    world = tmp_path / "worlds" / "khepera3_gripper.wbt"
    world.write_text((DATA / "khepera3_gripper.wbt").read_text() +
                     'Robot { name "watcher" supervisor TRUE controller "watcher" }\n')
    for name, source in (("khepera3_gripper", K3_CONTROLLER),
                         ("watcher", K3_WATCHER.replace("ENDS", " ".join(map(str, ends))))):
        (tmp_path / "controllers" / name).mkdir(parents=True)
        (tmp_path / "controllers" / name / f"{name}.py").write_text(source)
    done = subprocess.run(sensorium("run", str(world), "--until", "16000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert f"[{K3}] The {K3} robot is initialized, it uses 9 distance sensors" in done.stdout.splitlines(), done.stdout
    got = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] "):
            t, *values = line.split("] ", 1)[1].split()
            got[int(t)] = [float(v) for v in values]
    assert sorted(got) == ends, done.stdout[-2000:]
    for t in ends:
        assert got[t] == pytest.approx(want[t], abs=1e-9), t


# ------------------------------------------------------------------------------------------- khepera4
# khepera4 (k-team/khepera4): the Khepera IV (wheels of 0.021 m at y ±0.0527, turning about +y) turned
# 0.261803 rad at the centre of the default CircleArena (radius 1 m), six boxes about it, 16 ms steps. Each
# step its controller sets the wheels from three infra-red sensors: 0.2 (47.6 − 0.03 front) ± 0.03 (front
# left − front right). An infra-red ray reads the PROTO's table at the distance to a box's face (white:
# the distance itself), 120 past its 0.2 m.
K4 = "Khepera IV"
K4_R, K4_AXLE = 0.021, 0.1054
K4_TURN = ((1.78221999971205e-05, -2.346349999620905e-06, 0.9999999998384319), 0.261803)
K4_IR = {"front left infrared sensor": ((0.0495, 0.0495, 0.014), (0.862854, 0.357409, 0.357409), 1.717773),
         "front infrared sensor": ((0.07, 0.0, 0.014), (-1.0, 0.0, 0.0), -1.570796),
         "front right infrared sensor": ((0.0495, -0.0495, 0.014), (0.862857, -0.357406, -0.357406), 1.717771)}
K4_TABLE = ([0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.1, 0.15, 0.2],
            [1023, 1010, 1000, 990, 800, 500, 400, 350, 280, 250, 220, 180, 120])


def k4_boxes() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The stand-in's boxes as the world file writes them: (centre, rotation, half sizes)."""
    text = (DATA / "khepera4.wbt").read_text()
    boxes = []
    for t, r, s in re.findall(r"translation ([^\n]+)\n  rotation ([^\n]+)\n  children \[ DEF BOX\d_SHAPE Shape "
                              r"\{ geometry Box \{ size ([^}]+) \}", text):
        axis_angle = [float(v) for v in r.split()]
        boxes.append((np.array([float(v) for v in t.split()]), rot(axis_angle[:3], axis_angle[3]),
                      np.array([float(v) for v in s.split()]) / 2))
    assert len(boxes) == 6
    return boxes


def ray_to_boxes(origin: np.ndarray, u: np.ndarray, boxes: list) -> float:
    """The distance along the unit ray to the nearest box face it meets (slabs in each box's frame); inf
    when it meets none."""
    best = math.inf
    for centre, turn, half in boxes:
        p, d = turn.T @ (origin - centre), turn.T @ u
        near, far = -math.inf, math.inf
        for k in range(3):
            if abs(d[k]) < 1e-15:
                if abs(p[k]) > half[k]:
                    break
                continue
            a, b = (-half[k] - p[k]) / d[k], (half[k] - p[k]) / d[k]
            near, far = max(near, min(a, b)), min(far, max(a, b))
        else:
            if near <= far and near >= 0.0:
                best = min(best, near)
    return best


def k4_reading(distance: float) -> float:
    return float(np.interp(distance, *K4_TABLE)) if distance < 0.2 else 120.0


def noiseless(path: Path, tmp_path: Path) -> Path:
    """A copy of a stand-in (and its PROTOs) with every lookup table's noise column 0 (the rows of a table
    between ``[`` and ``]``, or between a template's branch markers)."""
    def quiet(rows: str) -> str:
        return ", ".join(f"{a} {b} 0" for a, b, _ in (r.split() for r in rows.replace("\n", ",").split(",") if r.strip()))

    shutil.copytree(path.parent / "protos", tmp_path / "protos", dirs_exist_ok=True)
    for proto in (tmp_path / "protos").glob("Khepera4*.proto"):
        text = re.sub(r"(lookupTable \[)([^\]%]*)(\])", lambda m: m.group(1) + quiet(m.group(2)) + m.group(3),
                      proto.read_text())
        text = re.sub(r"(>%\n)(\s*0 [^%]*?)(\n\s*%<)", lambda m: m.group(1) + quiet(m.group(2)) + m.group(3), text)
        proto.write_text(text)
    copy = tmp_path / path.name
    copy.write_text(path.read_text())
    return copy


def test_the_khepera4_stand_in_loads_every_device_its_controller_asks_for() -> None:
    """The Khepera IV loads with its 30 devices (the controller's five sonars, twelve infra-red sensors,
    three LEDs, camera and wheel motors among them), a two-wheel drive (radius 0.021 m, axle 0.1054 m)
    whose wheels touch the floor where the world puts it (no settling); its camera, inside the body's
    cylinder, is said once (the cylinder is both the visual shape and the bounding object: it was said
    twice)."""
    w = load_world(DATA / "khepera4.wbt")
    (line,) = w.warnings
    assert "Camera 'camera' of robot 'Khepera IV' is inside the robot's cylinder" in line, w.warnings
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert len(names) == 30 and {"camera", "rear led", "left ultrasonic sensor",
                                 "ground right infrared sensor", *K4_IR} <= names
    drive = robot.differential_drive
    assert (drive.wheel_radius, drive.axle_length, drive.wheel_bottom) == pytest.approx((K4_R, K4_AXLE, 0.0), abs=1e-15)


def test_the_khepera4_avoids_the_boxes_by_its_closed_form_readings_and_arcs(tmp_path: Path) -> None:
    """khepera4.c's calls in process, its sensors' noise taken out, while the robot is more than 0.7 m
    from the arena's centre (its rays, 0.2 m from 0.07 m out, cannot reach the wall): each 16 ms step the
    three front infra-red sensors read the closed form (the table at the ray's distance to the nearest box
    face; 120 past 0.2 m) and the pose is the arc of the wheel speeds the controller set from them (1e-9).
    In open space it drives at 0.2 × (47.6 − 3.6) × 0.021 = 0.1848 m/s; the first box enters its front
    sensor's ray at 1.328 s (the robot at (0.2342, 0.0628)), and it slows and turns left, its front right
    sensor seeing the box too, until it leaves the 0.7 m disc at 4.672 s, at (0.3775, 0.5912) heading
    1.5649. (Webots' wheels reach their speeds at their 130.45 rad/s² acceleration, which the kinematic
    drive ignores: 0.07 s at the start, a step or two at each change.)"""
    sim = Simulation(load_world(noiseless(DATA / "khepera4.wbt", tmp_path)), "exact")
    robot = sim.robot(K4)
    irs = {n: sim.device(f"{K4}/{n}") for n in K4_IR}
    for d in irs.values():
        d.enable(16)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    boxes = k4_boxes()
    turn0 = rot(*K4_TURN)
    yaw0 = math.atan2(turn0[1, 0], turn0[0, 0])
    x, y, yaw, wl, wr = 0.0, 0.0, yaw0, 0.0, 0.0
    seen, steps, first = set(), 0, None
    while math.hypot(x, y) < 0.7 and steps < 2500:
        sim.step()
        steps += 1
        x, y, yaw = k3_move_on(x, y, yaw, wl, wr, 0.016, K4_R, K4_AXLE)
        body = rot((0, 0, 1), yaw - yaw0) @ turn0
        assert np.asarray(robot.pose.rotation) == pytest.approx(body, abs=1e-9), steps
        assert list(robot.pose.translation[:2]) == pytest.approx([x, y], abs=1e-9), steps
        values = {}
        for name, (at, axis, angle) in K4_IR.items():
            origin = np.array([x, y, 0.0]) + body @ np.array(at)
            distance = ray_to_boxes(origin, body @ rot(axis, angle) @ np.array([1.0, 0.0, 0.0]), boxes)
            values[name] = k4_reading(distance)
            if distance < 0.2:
                seen.add(name)
                first = first or (steps, name, x, y)
            assert float(irs[name].value) == pytest.approx(values[name], abs=1e-9), (steps, name)
        offset = 0.2 * (47.6 - 0.03 * values["front infrared sensor"])
        delta = 0.03 * values["front left infrared sensor"] - 0.03 * values["front right infrared sensor"]
        wl, wr = offset + delta, offset - delta
        left.set_velocity(wl)
        right.set_velocity(wr)
    assert first is not None and first[:2] == (83, "front infrared sensor"), first
    assert seen == {"front infrared sensor", "front right infrared sensor"} and steps == 292, (seen, steps)
    assert [x, y, yaw] == pytest.approx([0.3775, 0.5912, 1.5649], abs=1e-4)


def test_a_wheel_whose_cylinder_lies_across_its_hinge_is_said(tmp_path: Path) -> None:
    """A stand-in of this sweep first had its wheels' cylinders lying across their hinges (a Cylinder's
    axis is its z since R2022a), and the robot drove on them, where Webots' would not roll: the drive
    still takes such a wheel (its radius as the rolling one), and one load line now names it; the
    other, turned onto the hinge's axis, is a wheel without a word."""
    world = tmp_path / "discs.wbt"
    wheel = ('HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.02 }} '
             'device [ RotationalMotor {{ name "{side} wheel motor" }} ] endPoint Solid {{ translation 0 {y} 0.02 '
             'children [ Pose {{ {turn}children [ Shape {{ geometry Cylinder {{ height 0.003 radius 0.02 }} }} ] }} ] '
             'name "{side} wheel" }} }}\n')
    world.write_text('#VRML_SIM R2023b utf8\nWorldInfo { }\nRobot {\n  children [\n' +
                     wheel.format(y=0.05, side="left", turn="rotation 1 0 0 1.5708 ") +
                     wheel.format(y=-0.05, side="right", turn="") + '  ]\n  controller "<none>"\n}\n')
    w = load_world(world)
    assert w.warnings == [f"{world}:6:1: HingeJoint motor 'right wheel motor': its wheel's cylinder lies across the "
                          "hinge's axis, not along it; taken as a wheel of radius 0.02 all the same, where Webots' "
                          "would not roll on it"], w.warnings
    drive = w.world.robots[0].differential_drive
    assert (drive.wheel_radius, drive.axle_length) == (0.02, 0.1)
