"""Sweep 26: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep26/: the
sample's poses, sizes, joints and devices, our own text, PROTO meshes stood in for by plain shapes) driven in
process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import math
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_sweep19 import KinematicMotor, rot
from test_sweep20 import ray_to_boxes
from test_sweep24 import K1_DS, K2_AXLE, khepera_arena, run_braitenberg_khepera

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep26"

# ------------------------------------------------------------------------------------------ khepera_gripper
# khepera_gripper (k-team/khepera1): a Khepera I with Physics at (-0.0746, -0.0246) on the 2 m RectangleArena,
# which the world turns 4.692820414042842e-06 rad about y (Webots' R2021c conversion), so its floor plane
# leans; a red stick (box bounds 0.013 x 0.013 x 0.06) stands 0.055 m ahead. The gripper turret: an arm on
# a hinge about y through A = (-0.01, 0, 0.022), written at its position -1.4 (raised; the end point's rotation
# R0 is the raised one), two fingers on sliders along the arm's +x and -x (LinearMotors of maxVelocity
# 0.1 m/s, maxForce 100 N), the right finger's infra-red "ds" (table 0 -> 0, 0.05 m -> 1000) looking at the
# left finger across the gap. khepera_gripper.c: 50 ms steps of a 281-step cycle: open the gripper (0.029 m),
# arm down (0), close it (0.005), arm up (-1.4), turn (-2, 2 rad/s) 2 s, forward (10, 10) 1 s, turn 2 s, stop.
K1_R, K1_AXLE = 0.0075, 0.052
START = np.array([-0.0746, -0.0246, 0.0])
FLOOR_TURN = 4.692820414042842e-06                     # the arena's turn about y
ANCHOR = np.array([-0.01, 0.0, 0.022])
ARM_R0 = rot((0.705814842414855, -0.7058148424148553, -0.06042198650976584), 3.020895)   # at position -1.4
ARM_Q0 = -1.4
HALF_PI_WRITTEN = 1.5708                               # the fingers' and the sensor's turns as written
STICK_AT, STICK_RADIUS, STICK_HALF_HEIGHT = np.array([-0.0198, -0.0261, 0.03]), 0.008, 0.03   # its visible cylinder
STICK_TURN = rot((1, 0, 0), 3.14159)
# khepera_gripper_camera: the same turret on "khepera camera" put 4.6 mm up at (0.0245671, 0) (Webots' physics drops
# it onto its wheels; here it settles at load), the arena not turned, the stick straight ahead at (0.08, 0), upright
GRIPPER = {"world": "khepera_gripper.wbt", "robot": "khepera", "start": START, "floor": FLOOR_TURN,
           "stick": STICK_AT, "stick turn": STICK_TURN}
GRIPPER_CAMERA = {"world": "khepera_gripper_camera.wbt", "robot": "khepera camera",
                  "start": np.array([0.0245671, 0.0, 0.0]), "floor": 0.0, "stick": np.array([0.08, 0.0, 0.03]),
                  "stick turn": np.eye(3)}
FINGER_HALF = np.array([0.014, 0.0035, 0.0025])
# Webots' infra-red factor 0.2 + 0.8 · red · (1 − 0.5 · roughness): the grey fingers (0.8, roughness 1), the red stick
FINGER_FACTOR = 0.2 + 0.8 * 0.8 * 0.5
STICK_FACTOR = 0.2 + 0.8 * 1.0 * (1.0 - 0.5 * 0.783569247)


def gripper_frames(body: np.ndarray, origin: np.ndarray, q_arm: float, q_right: float,
                   q_left: float) -> tuple[np.ndarray, np.ndarray, tuple]:
    """The ds's ray (origin, unit direction) and the left finger's box in the world, for the robot at
    (``body``, ``origin``) and the joints at their positions: the arm turned q − q0 about y through the
    anchor from where the file writes it, each finger slid along its axis (the arm's ±x) and placed 0.048 m
    down the arm's −z, turned 1.5708 (right) or −1.5708 (left) about y; the ds 0.015 m along the right
    finger's x, turned 1.5708 about y again (its ray along its x)."""
    arm = body @ rot((0, 1, 0), q_arm - ARM_Q0) @ ARM_R0
    arm_at = origin + body @ ANCHOR
    right = arm @ rot((0, 1, 0), HALF_PI_WRITTEN)
    right_at = arm_at + arm @ np.array([q_right, 0.0, -0.048])
    ds = right @ rot((0, 1, 0), HALF_PI_WRITTEN)
    ds_at = right_at + right @ np.array([0.015, 0.0, 0.0])
    left = arm @ rot((0, 1, 0), -HALF_PI_WRITTEN)
    left_at = arm_at + arm @ np.array([-q_left, 0.0, -0.048])
    box = (left_at + left @ np.array([-0.015, 0.0, 0.003]), left, FINGER_HALF)
    return ds_at, ds @ np.array([1.0, 0.0, 0.0]), box


def ray_to_stick(o: np.ndarray, u: np.ndarray, at: np.ndarray = STICK_AT, turn: np.ndarray = STICK_TURN) -> float:
    """The distance along the unit ray to the stick's visible cylinder (its side or its ends, in its Pose's
    frame: turned 3.14159 about x, so its axis leans 2.65e-6 rad); inf if it misses."""
    p, d = turn.T @ (o - at), turn.T @ u
    hits = []
    a, b, c = d[0] ** 2 + d[1] ** 2, p[0] * d[0] + p[1] * d[1], p[0] ** 2 + p[1] ** 2 - STICK_RADIUS ** 2
    if a > 0.0 and b * b - a * c >= 0.0:
        # from inside (a finger closed through the stick, which Webots' physics would have stopped it at) the far
        # wall: Sensorium's rays see both sides of a shape that is not the device's own (README's table)
        for t in ((-b - math.sqrt(b * b - a * c)) / a, (-b + math.sqrt(b * b - a * c)) / a):
            if t >= 0.0 and abs(p[2] + t * d[2]) <= STICK_HALF_HEIGHT:
                hits.append(t)
                break
    for end in (-STICK_HALF_HEIGHT, STICK_HALF_HEIGHT):
        if d[2] != 0.0 and (t := (end - p[2]) / d[2]) >= 0.0 and math.hypot(*(p[:2] + t * d[:2])) <= STICK_RADIUS:
            hits.append(t)
    return min(hits, default=math.inf)


def gripper_reading(ds_at: np.ndarray, u: np.ndarray, finger: tuple, layout: dict = GRIPPER) -> float:
    """The table at the nearer of the left finger (grey) and the stick (red) over its reflection factor:
    infra-red rays see the shapes (the stick's cylinder of radius 0.008 m), not its 0.013 m bounding box."""
    finger_at, stick_at = ray_to_boxes(ds_at, u, [finger]), ray_to_stick(ds_at, u, layout["stick"], layout["stick turn"])
    seen = finger_at / FINGER_FACTOR if finger_at <= stick_at else stick_at / STICK_FACTOR     # the nearer one
    return 1000.0 * min(seen, 0.05) / 0.05


def floor_pose(x: float, y: float, yaw: float, layout: dict = GRIPPER) -> tuple[np.ndarray, np.ndarray]:
    """A robot riding the leaning floor from START: its attitude the floor's (turned FLOOR_TURN about y), its
    heading ``yaw``, its height the floor's rise from START (it keeps the clearance it was placed with)."""
    slope = -math.tan(layout["floor"])          # dz/dx of the plane whose normal is R_y(θ)·z
    return rot((0, 1, 0), layout["floor"]) @ rot((0, 0, 1), yaw), np.array([x, y, slope * (x - layout["start"][0])])


def test_the_gripper_khepera_loads_its_turret_raised_and_rides_the_leaning_arena_floor() -> None:
    """The robot loads with the 29 devices (the turret's "motor", "left grip", "right grip" and "ds" among them)
    and a differential drive on the wheels (radius 0.0075 m, axle 0.052 m: the arc rule of a robot with
    Physics); the three joints each get their one line (kinematic motion), and nothing else: the arm starts at
    −1.4, where the file writes it. What changed: the arena's floor Plane, turned 4.7e-6 rad, was no ground
    (a plane had to face up within 1e-12), so the robot "started over no ground" in a GroundWarning; a plane
    leaning less than 45° is now a sloped floor, as Webots' physics has it, and the robot stands on it, turned
    with it (1e-12)."""
    w = load_world(DATA / "khepera_gripper.wbt")
    assert len(w.warnings) == 3 and all("moves kinematically" in line for line in w.warnings)
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert len(names) == 29 and {"motor", "left grip", "right grip", "ds", "left wheel motor", "right wheel motor",
                                 "camera"} <= names
    drive = robot.differential_drive
    assert (drive.wheel_radius, drive.axle_length, drive.step_rule) == (K1_R, K1_AXLE, "arc")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim = Simulation(w, "exact")
    r = sim.robot("khepera")
    assert r.motor("motor").position == ARM_Q0
    turn, at = floor_pose(*START[:2], 0.0)
    assert np.asarray(r.pose.rotation) == pytest.approx(turn, abs=1e-12)
    assert list(r.pose.translation) == pytest.approx(list(at), abs=1e-15)


def run_gripper(control_steps: int, layout: dict = GRIPPER) -> tuple[list[tuple[int, float, float, float, float]], list[float]]:
    """khepera_gripper.c's calls in process for ``control_steps`` steps of 50 ms, each step checked against
    the closed forms: the three joints by Webots' kinematic motor control (KinematicMotor: the arm's speed
    grows by maxTorque 10 rad/s² up to 10 rad/s, the fingers' reach 0.1 m/s in one 10 ms step), the ds reading
    its table at the ray's distance to the left finger (over 0.52) or the stick (over 0.68657), the robot's
    pose the arc rule on the wheel speeds over the leaning floor (1e-9). Returns each step's (k, arm, left and
    right grips, ds) and the final x, y, yaw."""
    sim = Simulation(load_world(DATA / layout["world"]), "exact")
    r = sim.robot(layout["robot"])
    assert sim.basic_time_step == 10
    ds = r.device("ds")
    ds.enable(50)
    wheels = r.motor("left wheel motor"), r.motor("right wheel motor")
    for m in wheels:
        m.set_position(math.inf)
        m.set_velocity(0.0)
    model = {"motor": KinematicMotor(10.0, 10.0, ARM_Q0), "left grip": KinematicMotor(0.1, 100.0),
             "right grip": KinematicMotor(0.1, 100.0)}
    x, y, yaw, wl, wr = float(layout["start"][0]), float(layout["start"][1]), 0.0, 0.0, 0.0
    out = []
    i = 0
    for k in range(control_steps):
        for _ in range(5):
            sim.step()
            for mm in model.values():
                mm.step(0.01)
            v, w = 0.5 * (wl + wr) * K1_R, (wr - wl) * K1_R / K1_AXLE
            x, y, yaw = x + v * 0.01 * math.cos(yaw), y + v * 0.01 * math.sin(yaw), yaw + w * 0.01
        q = {name: mm.x for name, mm in model.items()}
        for name, value in q.items():
            assert r.motor(name).position == pytest.approx(value, abs=1e-12), (k, name)
        body, origin = floor_pose(x, y, yaw, layout)
        assert np.asarray(r.pose.rotation) == pytest.approx(body, abs=1e-9), k
        assert list(r.pose.translation) == pytest.approx(list(origin), abs=1e-9), k
        ds_at, u, finger = gripper_frames(body, origin, q["motor"], q["right grip"], q["left grip"])
        expected = gripper_reading(ds_at, u, finger, layout)
        assert float(ds.value) == pytest.approx(expected, abs=1e-6), (k, q)
        out.append((k, q["motor"], q["left grip"], q["right grip"], float(ds.value)))
        commands = {0: {"left grip": 0.029, "right grip": 0.029}, 20: {"motor": 0.0},
                    40: {"left grip": 0.005, "right grip": 0.005}, 80: {"motor": -1.4}, 200: {"motor": 0.0},
                    240: {"left grip": 0.029, "right grip": 0.029}, 260: {"motor": -1.4}}.get(i, {})
        for name, target in commands.items():
            r.motor(name).set_position(target)
            model[name].target = target
        speeds = {100: (-2.0, 2.0), 140: (10.0, 10.0), 160: (-2.0, 2.0), 200: (0.0, 0.0)}.get(i)
        if speeds is not None:
            wl, wr = speeds
            for m, s in zip(wheels, speeds, strict=True):
                m.set_velocity(s)
        i = 0 if i == 280 else i + 1
    return out, [x, y, yaw]


def test_khepera_grippers_calls_open_lower_and_close_the_gripper_by_the_closed_forms() -> None:
    """khepera_gripper: the first 60 steps (3 s). The fingers open at 0.1 m/s, 5 mm a step, to 0.029 m; the ds
    reads the left finger across the gap 0.0005 + q_r + q_l (19.23 at rest, 403.84 at 5 mm each) and 1000 (the
    table's last value) past 0.026 m of it. The arm comes down from 1.05 s, its speed growing 0.1 rad/s every
    10 ms (0.53 s to its target), turned 1.4 rad about the anchor from where the file writes it; the ds then
    sees the stick between the open fingers. The gripper closes from 2.05 s: the fingers pass through the
    stick's bounds, which Webots' physics stops them at and grips (10 N·s friction): here joints are kinematic
    and hold nothing (README: Joints)."""
    out, _ = run_gripper(60)
    assert [round(v, 3) for *_, v in out[:4]] == [19.227, 403.842, 788.457, 1000.0]
    assert out[10][2:4] == (0.029, 0.029) and out[20][1] == ARM_Q0
    down = next(k for k, q, *_ in out if q == 0.0)
    assert down == 31      # 53 basic steps of 10 ms after the command at the end of step 20
    assert next(o[0] for o in out[5:] if o[4] < 1000.0) == 29       # the stick, first seen as the arm comes down
    assert out[35][4] == pytest.approx(574.0122, abs=1e-4)         # the stick 0.019705 m away, between the fingers


def test_khepera_grippers_calls_for_a_whole_cycle_turn_drive_and_turn_the_robot() -> None:
    """The whole 281-step cycle (14.05 s): after the arm is up again the robot turns in place at
    2·2·0.0075/0.052 = 0.5769 rad/s for 2 s, drives 0.075 m at 0.075 m/s, turns 2 s more and stops at
    (−0.0442, 0.0440), heading 2.3077, tilted with the floor; the arm goes down and up again, the fingers open."""
    out, end = run_gripper(281)
    assert out[-1][1:4] == (ARM_Q0, 0.029, 0.029)
    turn = 2.0 * 2.0 * K1_R / K1_AXLE * 2.0
    assert end == pytest.approx([START[0] + 0.075 * math.cos(turn), START[1] + 0.075 * math.sin(turn), 2.0 * turn],
                                abs=1e-12)




GRIPPER_CONTROLLER = '''\
import math
from controller import Robot

OPEN_GRIP, CLOSED_GRIP = 0.029, 0.005
robot = Robot()
motor, left_grip, right_grip = (robot.getDevice(n) for n in ("motor", "left grip", "right grip"))
ds = robot.getDevice("ds")
left_motor, right_motor = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
for m in (left_motor, right_motor):
    m.setPosition(math.inf)
    m.setVelocity(0.0)
ds.enable(50)
i = k = 0
while robot.step(50) != -1:
    print(f"{k} {ds.getValue():.6f}", flush=True)
    if i == 0:
        left_grip.setPosition(OPEN_GRIP)
        right_grip.setPosition(OPEN_GRIP)
    elif i == 20:
        motor.setPosition(0.0)
    elif i == 40:
        left_grip.setPosition(CLOSED_GRIP)
        right_grip.setPosition(CLOSED_GRIP)
    i, k = (0 if i == 280 else i + 1), k + 1
'''


@pytest.mark.slow
def test_khepera_grippers_calls_under_sensorium_run(tmp_path: Path) -> None:
    """Our Python controller making khepera_gripper.c's calls (its first 60 steps) under ``sensorium run``: no
    GroundWarning, and each step's ds reading is the in-process closed form's (1e-6)."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "khepera_gripper.wbt"
    world.write_text((DATA / "khepera_gripper.wbt").read_text())
    (tmp_path / "controllers" / "khepera_gripper").mkdir(parents=True)
    (tmp_path / "controllers" / "khepera_gripper" / "khepera_gripper.py").write_text(GRIPPER_CONTROLLER)
    done = subprocess.run(sensorium("run", str(world), "--until", "3000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "ground" not in (done.stdout + done.stderr).lower()
    rows = [line.split("] ", 1)[1].split() for line in done.stdout.splitlines() if line.startswith("[khepera] ")]
    expected, _ = run_gripper(60)
    assert [int(k) for k, _ in rows] == list(range(60))
    assert [float(v) for _, v in rows] == pytest.approx([v for *_, v in expected], abs=1e-6)

def test_khepera_grippers_calls_on_the_gripper_camera_world_settle_the_robot_and_meet_the_closed_forms() -> None:
    """khepera_gripper_camera: the robot put 4.6 mm up settles on its wheels at load (one line), its camera 64 × 64
    of field of view 0.785398 (Webots' defaults); the whole cycle meets run_gripper's closed forms on the flat
    floor, the ds seeing the stick centred between the open fingers at 622.772 (0.021378 m over the red's 0.68657)
    and the robot ending at (0.0549, 0.0686), heading 2.3077."""
    w = load_world(DATA / "khepera_gripper_camera.wbt")
    assert len(w.warnings) == 3
    sim = Simulation(w, "exact")
    assert sim.loaded.warnings[3:] == [
        f"{DATA / 'khepera_gripper_camera.wbt'}: robot 'khepera camera' settled on the ground at load, as Webots' "
        "physics drops it: its origin's z from 0.0046 to 0.0000 m (its lowest wheel now touches the ground under it)"]
    (camera,) = [d for d in w.world.robots[0].devices if d.name == "camera"]
    assert (camera.width, camera.height, camera.field_of_view) == (64, 64, 0.785398)
    out, end = run_gripper(281, GRIPPER_CAMERA)
    assert out[35][4] == pytest.approx(622.7716, abs=1e-4)
    turn = 2.0 * 2.0 * K1_R / K1_AXLE * 2.0
    assert end == pytest.approx([0.0245671 + 0.075 * math.cos(turn), 0.075 * math.sin(turn), 2.0 * turn], abs=1e-12)

@pytest.mark.parametrize("angle", [4.692820414042842e-06, 0.3, -0.7])
def test_a_plane_leaning_less_than_45_degrees_is_a_sloped_floor_everywhere(tmp_path: Path, angle: float) -> None:
    """The fix khepera_gripper called for, in closed form: a Plane at (0.5, −0.2, 0.1) turned ``angle`` about
    (1, 1, 0)/√2 is ground at every point (x, y): its height 0.1 − (n_x·(x − 0.5) + n_y·(y + 0.2))/n_z and its
    slope (−n_x/n_z, −n_y/n_z), n its turned z (1e-15); turned 0.8 rad (over 45°) it is no ground, as a ramp
    that steep is none."""
    from sensorium.server.sim.ground import Ground

    def ground(turn: float) -> Ground | None:
        (tmp_path / "plane.wbt").write_text(
            "#VRML_SIM R2023b utf8\nWorldInfo {}\n"
            f"Solid {{ translation 0.5 -0.2 0.1 rotation 1 1 0 {turn!r} boundingObject Plane {{ size 1 1 }} }}\n")
        return Simulation(load_world(tmp_path / "plane.wbt"), "exact").ground

    n = rot((1, 1, 0), angle) @ np.array([0.0, 0.0, 1.0])
    g = ground(angle)
    assert g is not None
    for x, y in [(0.5, -0.2), (3.0, 4.0), (-250.0, 17.5)]:
        z, gx, gy = g.at(x, y)
        assert (gx, gy) == pytest.approx((-n[0] / n[2], -n[1] / n[2]), abs=1e-15)
        assert z == pytest.approx(0.1 - (n[0] * (x - 0.5) + n[1] * (y + 0.2)) / n[2], abs=1e-12)
    assert ground(0.8) is None


@pytest.mark.parametrize("helper", [True, False])
def test_the_batched_simulation_rides_the_leaning_arena_floor_as_simulation_does_bit_for_bit(tmp_path: Path,
                                                                                             helper: bool) -> None:
    """The Khepera (Physics, its turret left out) on khepera_gripper's leaning arena floor in the batched
    simulation: each copy's pose is the single Simulation's bit for bit at every step (C drive pass and numpy),
    tilted with the floor (its rotation's third column the floor's normal, (sin θ, 0, cos θ))."""
    from sensorium.gym.views import CopySim
    from sensorium.server.raycast import packets
    from sensorium.server.sim.batched import BatchedSimulation

    if helper and packets.library() is None:
        pytest.skip(f"no C helper: {packets.status()}")
    shutil.copytree(DATA / "protos", tmp_path / "protos")
    text = (DATA / "khepera_gripper.wbt").read_text()
    world = tmp_path / "khepera_floor.wbt"
    world.write_text(text[:text.index("  extensionSlot [")] + "}\n")
    lw = load_world(world)
    batched = BatchedSimulation(lw, 2)
    if not helper:
        batched._drive_step = None
    batched.reset(np.arange(2), [1, 2])
    singles = [Simulation(lw, "exact") for _ in range(2)]
    slot = batched.slot("khepera")
    speeds = [(4.0, 6.0), (-3.0, 5.0)]
    for c, single in enumerate(singles):
        for sim in (single, CopySim(batched, c)):
            for m, v in zip(("left wheel motor", "right wheel motor"), speeds[c], strict=True):
                motor = sim.robot("khepera").motors[m]
                motor.set_position(math.inf)
                motor.set_velocity(v)
    for t in range(60):
        batched.step()
        for c, single in enumerate(singles):
            single.step()
            p = single.robot("khepera").pose
            assert batched.pos[c, slot].tobytes() == p.translation.tobytes(), (t, c)
            assert batched.rot[c, slot].tobytes() == p.rotation.tobytes(), (t, c)
            assert batched.rot[c, slot, :, 2] == pytest.approx([math.sin(FLOOR_TURN), 0.0, math.cos(FLOOR_TURN)],
                                                               abs=1e-15)
    assert float(np.hypot(*(batched.pos[1, slot, :2] - batched.pos[0, slot, :2]))) > 0.01   # the copies differ


# ------------------------------------------------------------------------------------------------ khepera
# khepera (k-team/khepera1): the Khepera I with Physics, named "khepera", at the centre of the 2 m RectangleArena
# with five 0.1 m boxes (Webots' WoodenBoxes; white boxes here), running Webots' generic `braitenberg`
# controller: the name starts with "khepera", so the Khepera weights on ds0…ds7 (table 0 -> 1023, 0.05 m -> 0),
# each wheel Σ_j w_j (1 − ds_j/512) bounded to ±1 rad/s. With Physics, its drive is the arc on the 0.052 m
# between its wheels (not the kinematic rule of khepera_kinematic's robots, sweep 24).
K1_BOXES = [((-0.2, -0.683174), (0.940554832051147, 0.240163077829669, 0.240163077829669), 1.632043330248321),
            ((-0.75, 0.35), (-0.675244449310683, 0.521557731068725, 0.521557731068725), 4.329427817464676),
            ((0.5, -0.35471), (-0.820542997539208, 0.404171491566001, 0.404171491566001), 4.515877143482041),
            ((-0.3, 0.36), (-0.820542997539208, 0.404171491566001, 0.404171491566001), 4.515877143482041),
            ((-0.65, -0.66), (-0.820542997539208, 0.404171491566001, 0.404171491566001), 4.515877143482041)]
K1_RES = 0.0314


def khepera_obstacles() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """khepera's arena and its five boxes."""
    return khepera_arena(K1_BOXES)


def noiseless_khepera(tmp_path: Path) -> Path:
    """A copy of the khepera stand-in whose infra-red tables have no noise (0.01 at 0.05 m)."""
    (tmp_path / "protos").mkdir()
    proto = (DATA / "protos" / "Khepera1.proto").read_text()
    (tmp_path / "protos" / "Khepera1.proto").write_text(
        proto.replace("lookupTable [ 0 1023 0, 0.05 0 0.01 ]", "lookupTable [ 0 1023 0, 0.05 0 0 ]"))
    (tmp_path / "khepera.wbt").write_text((DATA / "khepera.wbt").read_text())
    return tmp_path / "khepera.wbt"


def run_khepera(world: Path, duration_ms: int) -> tuple[list[tuple[int, int]], list[tuple[int, float]], list[float]]:
    """braitenberg.c's calls for the Khepera I with Physics (the exact arc on the 0.052 m between its wheels),
    checked step by step against the closed forms (test_sweep24's :func:`run_braitenberg_khepera`)."""
    return run_braitenberg_khepera(world, "khepera", duration_ms, K1_DS, khepera_obstacles(), K1_R, K1_AXLE, K1_RES,
                                   "arc")


def test_the_khepera_with_physics_loads_the_devices_braitenberg_asks_for_and_the_arc_drive() -> None:
    """The Khepera I with Physics loads without a line with its 24 devices and a differential drive of radius
    0.0075 m on the 0.052 m between its wheels (the arc rule of a robot with Physics), its wheels on the floor."""
    w = load_world(DATA / "khepera.wbt")
    assert w.warnings == []
    (robot,) = w.world.robots
    assert len({d.name for d in robot.devices}) == 24
    drive = robot.differential_drive
    assert robot.mass is not None and drive.step_rule == "arc"
    assert (drive.wheel_radius, drive.axle_length, drive.wheel_bottom) == (K1_R, K1_AXLE, 0.0)


def test_braitenbergs_calls_drive_the_khepera_straight_at_its_bounded_speed(tmp_path: Path) -> None:
    """khepera: in open space the Braitenberg sums are 3 on both wheels, bounded to 1 rad/s: 0.0075 m/s along +x;
    for 24 s (750 steps) every reading (0), wheel sensor and pose meet run_khepera's closed forms."""
    seen, pushes, end = run_khepera(noiseless_khepera(tmp_path), 24000)
    assert seen == [] and pushes == []
    assert end == pytest.approx([0.0075 * 23.968, 0.0, 0.0], abs=1e-12)


@pytest.mark.slow
def test_braitenbergs_calls_drive_the_khepera_to_the_wall_and_round(tmp_path: Path) -> None:
    """The same closed forms for 200 s (6250 steps): ds2 and ds3 meet the wall at x 1 at 123.104 s (the robot at
    1 − 0.027 − 0.05 m and a step), then ds1 and ds4, ds0, and the rear ds7 as it turns; it turns right along the
    wall, never touching it, to (0.7014, −0.4097), heading −2.1339 (the arc where khepera_kinematic's rule
    gave its robots a 4 % wider axle)."""
    seen, pushes, end = run_khepera(noiseless_khepera(tmp_path), 200000)
    assert seen == [(123104, 2), (123104, 3), (125856, 1), (125856, 4), (129216, 0), (134976, 7)] and pushes == []
    assert end == pytest.approx([0.7014, -0.4097, -2.1339], abs=1e-4)


# ------------------------------------------------------------------------------------------------ khepera_k213
# khepera_k213 (k-team/khepera1): the Khepera I with `kinematic TRUE` (no Physics: Webots' kinematic rule, axle
# 2·√(0.026² + 0.0075²)) at (−0.101226, −0.218527) heading 1.58668 rad, a K213 linear camera (64 × 1 pixels, field
# of view 0.6283) 0.04 m up in its extensionSlot, in a 0.98 m RectangleArena turned a quarter turn with walls
# 0.02 m high, five red 0.23 × 0.04 × 0.1 m boxes. khepera_k213.c: 64 ms steps; one step of 64 s first (the robot
# still), then each step ds1…ds4 (their values truncated to integers) against 150: both front ones over it, back
# at −2; none, forward at 4; else ds3 or ds4 over it, left (−2, 2); then ds1 or ds2 over it, right (2, −2); the
# image read and printed as 64 characters, one per gray level band.
K213_START = (-0.101226, -0.218527, 1.586680526794897)
ARENA_TURN = rot((0, 0, 1), 1.570796326794897)
RED_FACTOR = 0.2 + 0.8 * 1.0 * 0.5                   # baseColor red 1, roughness 1
K213_BOXES = [((-0.2, -0.4), (0.577656775505086, 0.577196954995895, 0.577196954995895), 2.093935403939799),
              ((0.37, 0.44), (1, 0, 0), 1.5707963267948966),
              ((-0.39, -0.2), (0.990082465225964, -0.099339599486002, -0.099339599486002), 1.580763202889407),
              ((0.45, -0.48), (0.888584723211755, 0.324358744043296, 0.324358744043296), 1.688647850036833),
              ((-0.45, 0.48), (0.888584723211755, 0.324358744043296, 0.324358744043296), 1.688647850036833)]


def k213_obstacles() -> tuple[list, list]:
    """The arena's four white walls (0.01 m thick, 0.02 m high, outside the 0.98 m floor, turned with it), and the
    five red boxes."""
    walls = [((0.495, 0.0), (0.005, 0.49)), ((-0.495, 0.0), (0.005, 0.49)),
             ((0.0, 0.495), (0.5, 0.005)), ((0.0, -0.495), (0.5, 0.005))]
    white = [(ARENA_TURN @ np.array([x, y, 0.01]), ARENA_TURN, np.array([hx, hy, 0.01])) for (x, y), (hx, hy) in walls]
    red = [(np.array([x, y, 0.02]), rot(axis, a), np.array([0.115, 0.02, 0.05])) for (x, y), axis, a in K213_BOXES]
    return white, red


def run_k213(duration_ms: int) -> tuple[list[tuple[int, tuple[int, int]]], list[float], np.ndarray]:
    """khepera_k213.c's calls in process for ``duration_ms`` after its 64 s wait, each step checked against the
    closed forms: ds1…ds4 read the table at their ray's distance to the nearest white wall, or red box over 0.6
    (noise zeroed), the pose Webots' kinematic rule on the speeds set (1e-9), the camera's image 64 × 1. Returns
    the speeds' changes (time, speeds), the final x, y, yaw and the last image's gray levels."""
    import re
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "protos").mkdir()
        proto = (DATA / "protos" / "Khepera1.proto").read_text()
        (Path(tmp) / "protos" / "Khepera1.proto").write_text(re.sub(r"0\.05 0 0\.01 \]", "0.05 0 0 ]", proto))
        (Path(tmp) / "khepera_k213.wbt").write_text((DATA / "khepera_k213.wbt").read_text())
        sim = Simulation(load_world(Path(tmp) / "khepera_k213.wbt"), "exact")
    robot = sim.robot("khepera")
    step = sim.basic_time_step
    assert step == 32
    ds = [sim.device(f"khepera/ds{i}") for i in range(8)]
    for s in ds:
        s.enable(64)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    camera = sim.device("khepera/k213")
    camera.enable(64)
    for _ in range(2000):                      # wb_robot_step(1000 * 64): 64 s still
        sim.step()
    x, y, yaw = K213_START
    assert list(robot.pose.translation) == pytest.approx([x, y, 0.0], abs=1e-12)
    white, red = k213_obstacles()
    rays = [(np.array(at), rot(axis, a) @ np.array([1.0, 0.0, 0.0])) for at, axis, a in K1_DS]
    wl = wr = 0
    changes: list[tuple[int, tuple[int, int]]] = []
    gray = np.zeros(64)
    for k in range(1, duration_ms // 64 + 1):
        for _ in range(2):
            sim.step()
            d = (wr - wl) * 0.032 * K1_R / (2.0 * K2_AXLE)
            v = 0.5 * (wl + wr) * K1_R * 0.032
            x, y, yaw = x + v * math.cos(yaw + d), y + v * math.sin(yaw + d), yaw + 2.0 * d
        body = rot((0, 0, 1), yaw)
        assert list(robot.pose.translation) == pytest.approx([x, y, 0.0], abs=1e-9), k
        assert np.asarray(robot.pose.rotation) == pytest.approx(body, abs=1e-9), k
        values = []
        for i, (p, u) in enumerate(rays):
            o, w = np.array([x, y, 0.0]) + body @ p, body @ u
            seen = min(ray_to_boxes(o, w, white), ray_to_boxes(o, w, red) / RED_FACTOR)
            values.append(1023.0 * (1.0 - seen / 0.05) if seen < 0.05 else 0.0)
            assert float(ds[i].value) == pytest.approx(values[-1], abs=1e-6), (k, i, seen)
        v1, v2, v3, v4 = (int(float(ds[i].value)) for i in (1, 2, 3, 4))      # unsigned short: truncated
        speeds = wl, wr
        if v2 > 150 and v3 > 150:
            speeds = -2, -2
        elif v1 < 150 and v2 < 150 and v3 < 150 and v4 < 150:
            speeds = 4, 4
        elif v3 > 150 or v4 > 150:
            speeds = -2, 2
        if v1 > 150 or v2 > 150:
            speeds = 2, -2
        image = np.asarray(camera.image)
        assert image.shape == (1, 64, 4)
        gray = image[0, :, :3].astype(int).sum(axis=1) // 3           # wb_camera_image_get_gray: (r + g + b) / 3
        if speeds != (wl, wr):
            changes.append((64000 + k * 64, speeds))
        wl, wr = speeds
        left.set_velocity(wl)
        right.set_velocity(wr)
    return changes, [x, y, math.remainder(yaw, 2 * math.pi)], gray


def test_the_k213_khepera_loads_its_linear_camera_and_stays_still_through_the_wait_then_drives_straight() -> None:
    """The robot loads without a line with 25 devices, the K213 a 64 × 1 camera of field of view 0.6283, and
    Webots' kinematic rule; through the 64 s step it stays where it is placed (1e-12), then, its front sensors
    reading 0, drives at 4 rad/s: 0.03 m/s along its heading 1.58668, every reading and pose the closed form's for
    4 s (1e-9), each image 64 × 1."""
    w = load_world(DATA / "khepera_k213.wbt")
    assert w.warnings == []
    (robot,) = w.world.robots
    assert len({d.name for d in robot.devices}) == 25
    (k213,) = [d for d in robot.devices if d.name == "k213"]
    assert (k213.width, k213.height, k213.field_of_view) == (64, 1, 0.6283)
    assert robot.differential_drive.step_rule == "mid_heading"
    changes, end, _ = run_k213(4000)
    assert changes == [(64064, (4, 4))]
    x0, y0, yaw0 = K213_START
    assert end == pytest.approx([x0 + 0.03 * 3.904 * math.cos(yaw0), y0 + 0.03 * 3.904 * math.sin(yaw0), yaw0], abs=1e-12)


def test_khepera_k213s_calls_drive_the_khepera_to_the_wall_and_along_it() -> None:
    """khepera_k213 for 30 s after the wait: forward until ds1, looking out to the front left, passes 150 on the
    wall at y 0.49 at 85.376 s (the robot 0.63936 m on, at y 0.42075), then the controller's right turns and
    forward steps alternating along the wall, to (0.0554, 0.4400), heading −0.0098, every reading and pose the
    closed form's (1e-9)."""
    changes, end, _ = run_k213(30000)
    assert changes[:3] == [(64064, (4, 4)), (85376, (2, -2)), (85888, (4, 4))] and len(changes) == 31
    assert all(s in ((4, 4), (2, -2)) for _, s in changes)
    assert end == pytest.approx([0.0554, 0.4400, -0.0098], abs=1e-4)
