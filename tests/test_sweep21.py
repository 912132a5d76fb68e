"""Sweep 21: Webots' demos not run before (projects/samples/demos: gantry, soccer), each on a stand-in world
of ours (tests/data/sweep21/: the demo's poses, sizes, joints, motors and devices, our own text, textures and
meshes left out) driven in process by the calls its controllers make and checked against closed forms; the
slow tests run our Python controllers making the same calls under ``sensorium run``."""

from __future__ import annotations

import ctypes
import math
import re
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_supervisor import A, Live
from test_sweep19 import KinematicMotor, rot
from test_sweep20 import k3_move_on

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep21"


def yaw_of(robot) -> float:
    r = robot.pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


def node_pose(lv: Live, robot: str, name: str) -> np.ndarray:
    node = lv.ok(A, f"/{robot}/robot/get_from_def", {"name": name})["node"]
    return np.array(lv.ok(A, f"/{robot}/robot/get_node_pose", {"node": node})["position"])


# ------------------------------------------------------------------------------------------- gantry
# gantry (demos): a gantry robot on four wheels of radius 0.08 m (hinges about -y) plays the Towers of Hanoi
# with three boxes, one command every 2300 ms (basic step 4 ms). Its six "position" motors go to a platform's
# targets: the wheels to 0, 5 or 10 rad (the gantry at x = -0.08·q: a positive turn about -y rolls it along
# -x), "bridge_motor" (a slider along -y, maxVelocity 1, maxForce 100) to 0.8, 0 or -0.8, "turret_motor"
# (about z, maxVelocity 3.14, maxTorque 100) to -3.1416, 0 or 3.1416; "lift_motor" (along -z, maxVelocity 1,
# maxForce 400) lowers to 0.72 and raises to 0; "grip_motor1"/"grip_motor2" (maxForce 200) close to 0.09
# and open to 0.
GANTRY_STEP_MS = 2300
GANTRY_TARGETS = ([0.0, 0.0, 0.0, 0.0, 0.8, -3.1416], [5.0, 5.0, 5.0, 5.0, 0.0, 0.0], [10.0, 10.0, 10.0, 10.0, -0.8, 3.1416])
GANTRY_MOTORS = ["wheel1_motor", "wheel2_motor", "wheel3_motor", "wheel4_motor", "bridge_motor", "turret_motor",
                 "lift_motor", "grip_motor1", "grip_motor2"]


def hanoi_commands() -> list[tuple[str, int]]:
    """gantry.c's list: moveTower(3, 1, 2, 3), each move of a box eight commands."""
    out: list[tuple[str, int]] = []

    def disc(src: int, dst: int) -> None:
        out.extend([("goto", src), ("lower", 0), ("close", 0), ("raise", 0), ("goto", dst), ("lower", 0),
                    ("open", 0), ("raise", 0)])

    def tower(n: int, src: int, aux: int, dst: int) -> None:
        if n:
            tower(n - 1, src, dst, aux)
            disc(src, dst)
            tower(n - 1, aux, src, dst)

    tower(3, 1, 2, 3)
    return out


def gantry_targets(command: tuple[str, int]) -> dict[int, float]:
    """The motors (by index) a command sets and their targets."""
    kind, platform = command
    if kind == "goto":
        return dict(enumerate(GANTRY_TARGETS[platform - 1]))
    return {"lower": {6: 0.72}, "raise": {6: 0.0}, "close": {7: 0.09, 8: 0.09}, "open": {7: 0.0, 8: 0.0}}[kind]


class GantryTwin:
    """The closed form of the gantry's motors: its wheels are drive wheels, which turn towards their target
    at their maxVelocity (10 rad/s) from the first step (a wheel's acceleration is ignored here); the other
    motors follow Webots' kinematic rule, their acceleration their maxTorque or maxForce."""

    def __init__(self) -> None:
        self.wheel, self.wheel_target = 0.0, 0.0
        self.joints = {4: KinematicMotor(1.0, 100.0), 5: KinematicMotor(3.14, 100.0), 6: KinematicMotor(1.0, 400.0),
                       7: KinematicMotor(10.0, 200.0), 8: KinematicMotor(10.0, 200.0)}

    def set(self, targets: dict[int, float]) -> None:
        for i, q in targets.items():
            if i < 4:
                self.wheel_target = q
            else:
                self.joints[i].target = q

    def step(self, dt: float) -> None:
        to = self.wheel_target - self.wheel
        self.wheel += math.copysign(min(10.0, abs(to) / dt), to) * dt if to else 0.0
        for m in self.joints.values():
            m.step(dt)

    def grips(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The gantry's origin and its two jaws' centres: the bridge at (0, -b, 0) turned a quarter about z,
        the turret 0.11 m up on it turned by the turret's angle and a quarter more, the lift 0.36 - l up on it
        turned a quarter about -y, the jaws at (-0.6, 0, ∓0.19) in the lift's frame, each moved by its
        slider towards the other."""
        q = {i: m.x for i, m in self.joints.items()}
        origin = np.array([-0.08 * self.wheel, 0.0, 0.98])
        bridge_turn = rot((0, 0, 1), 1.5708)
        bridge = origin + np.array([0.0, -q[4], 0.0])
        turret_turn = bridge_turn @ rot((0, 0, 1), q[5]) @ rot((0, 0, 1), 1.5708)
        turret = bridge + bridge_turn @ np.array([0.0, 0.0, 0.11])
        lift_turn = turret_turn @ rot((0, -1, 0), 1.5708)
        lift = turret + turret_turn @ np.array([0.0, 0.0, 0.36 - q[6]])
        return (origin, lift + lift_turn @ np.array([-0.6, 0.0, -0.19 + q[7]]),
                lift + lift_turn @ np.array([-0.6, 0.0, 0.19 - q[8]]))


def test_the_gantry_loads_as_a_skid_steer_on_its_rails_with_its_nine_motors() -> None:
    """The stand-in loads with gantry.c's nine motors; its four wheels (radius 0.08 m, touching the floor
    0.98 m below its origin) are a skid-steer drive rolling along -x; each of the five other motors moves its
    joint kinematically (one line each); the three boxes stand on platform 1."""
    w = load_world(DATA / "gantry.wbt")
    robot = w.world.robots[0]
    assert [(d.name, type(d).__name__) for d in robot.devices] == [
        (n, "LinearMotor" if n in ("bridge_motor", "lift_motor", "grip_motor1", "grip_motor2") else "RotationalMotor")
        for n in GANTRY_MOTORS]
    drive = robot.differential_drive
    assert drive is not None and drive.wheel_radius == 0.08 and drive.forward == (-1.0, 0.0)
    assert drive.wheel_bottom == pytest.approx(-0.98, abs=1e-12)
    assert {drive.left_motor, drive.right_motor, *drive.skid_steer.left, *drive.skid_steer.right} == set(GANTRY_MOTORS[:4])
    assert len(w.warnings) == 5, w.warnings
    for name in GANTRY_MOTORS[4:]:
        assert sum(f"motor '{name}'" in line and "moves kinematically" in line for line in w.warnings) == 1, name


def test_the_gantry_calls_move_it_and_its_jaws_by_the_closed_form(tmp_path: Path) -> None:
    """gantry.c's first nine commands (the smallest box from platform 1 to platform 3 and back to
    position 2; 20.7 s of 4 ms steps), read as a Supervisor reads them (every 25th step): each step the gantry is at
    x = -0.08·q of its wheels (10 rad/s from the first step), and its jaws where the bridge, turret, lift
    and grip motors' kinematic rule puts them (1e-12); it reaches platform 3 (x -0.8, the bridge at y 0.8)
    1 s after the command. The jaws close on nothing: the boxes, which Webots' lift lowers onto and whose
    top one its jaws grip by friction, stay stacked on platform 1 (the lift goes down through them)."""
    text = re.sub(r"(DEF GANTRY Robot \{)", r"\1 supervisor TRUE", (DATA / "gantry.wbt").read_text())
    world = tmp_path / "gantry.wbt"
    world.write_text(text)
    lv = Live(Simulation(load_world(world), "exact"))
    lv.ok(A, "attach", {"robot": "gantry"})
    robot = lv.sim.robot("gantry")
    motors = [robot.motor(n) for n in GANTRY_MOTORS]
    boxes = {n: node_pose(lv, "gantry", n) for n in ("BOX_A", "BOX_B", "BOX_C")}
    assert [b[2] for b in boxes.values()] == pytest.approx([0.54, 0.34, 0.14], abs=1e-12)   # on the 0.04 m platform
    twin = GantryTwin()
    issued = None
    for command in hanoi_commands()[:9]:
        for k in range(GANTRY_STEP_MS // 4):
            lv.sim.step()
            twin.step(0.004)
            origin, jaw1, jaw2 = twin.grips()
            assert [float(v) for v in robot.pose.translation] == pytest.approx(origin, abs=1e-12), (command, k)
            if k % 25 == 0:
                assert node_pose(lv, "gantry", "GANTRY") == pytest.approx(origin, abs=1e-12), (command, k)
                assert node_pose(lv, "gantry", "GRIP1") == pytest.approx(jaw1, abs=1e-12), (command, k)
                assert node_pose(lv, "gantry", "GRIP2") == pytest.approx(jaw2, abs=1e-12), (command, k)
            if issued == ("goto", 3) and k in (248, 249):     # 10 rad at 10 rad/s: there 1 s after the command
                assert (origin[0] == pytest.approx(-0.8, abs=1e-12)) == (k == 249)
        for i, q in gantry_targets(command).items():
            motors[i].set_position(q)
        twin.set(gantry_targets(command))
        issued = command
    assert lv.sim.time_ms == 9 * GANTRY_STEP_MS
    for name, at in boxes.items():
        assert node_pose(lv, "gantry", name).tolist() == at.tolist(), name


GANTRY_CONTROLLER = '''\
# Sensorium's test controller making gantry.c's calls (Webots' demo): moveTower(3, 1, 2, 3), one command
# every 2300 ms.
from controller import Robot

Z, X, ALPHA = (0.0, 5.0, 10.0), (0.8, 0.0, -0.8), (-3.1416, 0.0, 3.1416)
robot = Robot()
motors = [robot.getDevice(n) for n in ("wheel1_motor", "wheel2_motor", "wheel3_motor", "wheel4_motor",
                                       "bridge_motor", "turret_motor", "lift_motor", "grip_motor1", "grip_motor2")]
commands = []


def goto(p):
    def go():
        for i, q in enumerate([Z[p - 1]] * 4 + [X[p - 1], ALPHA[p - 1]]):
            motors[i].setPosition(q)
    return go


def lift(q):
    return lambda: motors[6].setPosition(q)


def grip(q):
    return lambda: (motors[7].setPosition(q), motors[8].setPosition(q))


def tower(n, src, aux, dst):
    if n:
        tower(n - 1, src, dst, aux)
        commands.extend([goto(src), lift(0.72), grip(0.09), lift(0.0), goto(dst), lift(0.72), grip(0.0), lift(0.0)])
        tower(n - 1, aux, src, dst)


tower(3, 1, 2, 3)
print(f"{len(commands)} commands", flush=True)
state = 0
while robot.step(2300) != -1:
    if state < len(commands):
        commands[state]()
    state += 1
'''

GANTRY_WATCHER = '''\
from controller import Supervisor

sup = Supervisor()
nodes = {n: sup.getFromDef(n) for n in ("GANTRY", "GRIP1", "GRIP2", "BOX_A", "BOX_B", "BOX_C")}
while sup.step(4) != -1:
    t = round(sup.getTime() * 1000)
    if t in (13800, 20700, 64400, 128800):
        for name, node in nodes.items():
            p = node.getPosition()
            print(f"{name} {t} {p[0]:.9f} {p[1]:.9f} {p[2]:.9f}", flush=True)
'''


@pytest.mark.slow
def test_the_gantry_plays_its_towers_under_sensorium_run(tmp_path: Path) -> None:
    """Our Python controller making gantry.c's 56 commands under ``sensorium run`` for 128.8 s with a
    watcher Supervisor: the gantry and its jaws are where the closed form puts them at 13.8, 20.7, 64.4 and
    128.8 s (1e-9; at the end over platform 3, the lift raised), the boxes still on platform 1."""
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "gantry.wbt"
    world.write_text((DATA / "gantry.wbt").read_text() +
                     'Robot { name "watcher" supervisor TRUE controller "watcher" }\n')
    for name, source in (("gantry", GANTRY_CONTROLLER), ("watcher", GANTRY_WATCHER)):
        (tmp_path / "controllers" / name).mkdir(parents=True)
        (tmp_path / "controllers" / name / f"{name}.py").write_text(source)
    done = subprocess.run(sensorium("run", str(world), "--until", "128800", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    assert "[gantry] 56 commands" in done.stdout.splitlines(), done.stdout[-2000:]
    got = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] "):
            name, t, *values = line.split("] ", 1)[1].split()
            got[name, int(t)] = [float(v) for v in values]
    twin = GantryTwin()
    commands = hanoi_commands()
    assert len(commands) == 56
    for state in range(56):
        for _ in range(GANTRY_STEP_MS // 4):
            twin.step(0.004)
        t = GANTRY_STEP_MS * (state + 1)
        if t in (13800, 20700, 64400, 128800):
            for name, at in zip(("GANTRY", "GRIP1", "GRIP2"), twin.grips()):
                assert got[name, t] == pytest.approx(at.tolist(), abs=1e-9), (name, t)
            for name, z in (("BOX_A", 0.54), ("BOX_B", 0.34), ("BOX_C", 0.14)):
                assert got[name, t] == pytest.approx([0.0, -0.8, z], abs=1e-9), (name, t)
        twin.set(gantry_targets(commands[state]))
    assert twin.grips()[0].tolist() == pytest.approx([-0.8, 0.0, 0.98], abs=1e-12)


# ------------------------------------------------------------------------------------------- soccer
# soccer (demos): six players (0.075 m cubes on wheels of radius 0.02 m, 0.09 m apart, turning about +y: a
# positive speed drives along the robot's +x) and a supervisor referee whose Emitter sends, each 64 ms, the
# players' x, y and angle about z (B1, B2, B3, Y1, Y2, Y3) and the ball's x, y: 20 doubles. A player's
# name ("b1" ... "y3") says its team and number. Players 1 and 2 count the packets: both wheels at 10 rad/s
# while the counter is under max (50 at first), then -10 and 10 (a turn in place), a new max 30 +
# rand()/(RAND_MAX/70) at 100 (glibc's rand, srand(team + player)); the goalkeepers (3) drive both wheels
# at ±10 towards the ball's y while within ±0.16. Y3's "left wheel motor" is on its right (y -0.045).
PLAYERS = ("b1", "b2", "b3", "y1", "y2", "y3")
BALL_RADIUS, HALF_SIDE = 0.021, 0.0375
RAND_MAX = 2147483647
# The field's walls as the demo's bounding boxes (centre x, y, half sizes along x and y, turn about z).
WALLS = [(0, 0.655, 0.75, 0.005, 0), (0, -0.655, 0.75, 0.005, 0)] + \
    [(sx * 0.755, sy * 0.43, 0.005, 0.2175, 0) for sx in (-1, 1) for sy in (-1, 1)] + \
    [(0.725, -0.62, 0.005, 0.045, -0.7853), (-0.725, -0.62, 0.005, 0.045, 0.7853),
     (0.725, 0.62, 0.005, 0.045, 0.7853), (-0.725, 0.62, 0.005, 0.045, -0.7853)] + \
    [(sx * 0.855, 0, 0.005, 0.21, 0) for sx in (-1, 1)] + [(sx * 0.8, sy * 0.205, 0.05, 0.005, 0) for sx in (-1, 1)
                                                           for sy in (-1, 1)]


def glibc_rand(libc, seed: int):
    """One controller's rand() (glibc, after srand(seed)): each Webots controller is a process of its own."""
    drawn = 0

    def draw() -> int:
        nonlocal drawn
        libc.srand(seed)
        for _ in range(drawn):
            libc.rand()
        drawn += 1
        return int(libc.rand())
    return draw


def player_rule(name: str, state: dict, packet: tuple[float, ...]) -> tuple[float, float]:
    """soccer_player.c's speeds for one packet (left, right)."""
    if name[1] in "12":
        state["counter"] += 1
        speeds = (10.0, 10.0) if state["counter"] < state["max"] else (-10.0, 10.0)
        if state["counter"] == 100:
            state["counter"] = 0
            state["max"] = 30 + state["rand"]() // (RAND_MAX // 70)
        return speeds
    me = 3 * (int(name[1]) - 1 + (3 if name[0] == "y" else 0))
    y = packet[me + 1]
    d = y - packet[19]
    if d > 0.01 and y > -0.16:
        return 10.0, 10.0
    if d < -0.01 and y < 0.16:
        return -10.0, -10.0
    return 0.0, 0.0


def rectangle(x: float, y: float, hx: float, hy: float, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([(x + c * u - s * v, y + s * u + c * v) for u, v in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))])


def depth(a: np.ndarray, b: np.ndarray) -> float:
    """How deep two convex polygons overlap (the least overlap of their projections on their edges'
    normals: > 0 inside each other, <= 0 apart or touching)."""
    least = math.inf
    for poly in (a, b):
        for i in range(len(poly)):
            e = poly[(i + 1) % len(poly)] - poly[i]
            n = np.array([-e[1], e[0]]) / math.hypot(*e)
            pa, pb = a @ n, b @ n
            least = min(least, min(pa.max(), pb.max()) - max(pa.min(), pb.min()))
    return least


def gap_to_ball(x: float, y: float, yaw: float, ball: tuple[float, float]) -> float:
    """The distance from the ball's centre to a player's square footprint at (x, y, yaw), less its radius."""
    dx, dy = ball[0] - x, ball[1] - y
    lx, ly = math.cos(yaw) * dx + math.sin(yaw) * dy, -math.sin(yaw) * dx + math.cos(yaw) * dy
    return math.hypot(lx - max(-HALF_SIDE, min(HALF_SIDE, lx)), ly - max(-HALF_SIDE, min(HALF_SIDE, ly))) - BALL_RADIUS


def meets(pose: tuple[float, float, float], ball: tuple[float, float], others: dict[str, tuple[float, float, float]]) -> str | None:
    """What a player's square at ``pose`` would enter: the ball, a wall or another player (at its pose)."""
    if gap_to_ball(*pose, ball) < -1e-12:
        return "ball"
    me = rectangle(pose[0], pose[1], HALF_SIDE, HALF_SIDE, pose[2])
    if any(depth(me, rectangle(*w)) > 1e-12 for w in WALLS):
        return "wall"
    for name, (x, y, yaw) in others.items():
        if depth(me, rectangle(x, y, HALF_SIDE, HALF_SIDE, yaw)) > 1e-12:
            return name
    return None


def test_the_soccer_stand_in_loads_its_six_players_and_the_referee() -> None:
    """Seven robots load without a line: each player a two-wheel drive (radius 0.02 m, 0.09 m apart) with
    a Receiver, Y3's drive taking its "right wheel motor" as its left wheel (where it is); the referee a
    Supervisor with an Emitter of range 10 at 115200 baud."""
    w = load_world(DATA / "soccer.wbt")
    assert w.warnings == []
    robots = {r.name: r for r in w.world.robots}
    assert sorted(robots) == sorted([*PLAYERS, "robot"])
    for name in PLAYERS:
        drive = robots[name].differential_drive
        assert drive is not None and (drive.wheel_radius, drive.axle_length) == (0.02, 0.09), name
        assert (drive.left_motor, drive.right_motor) == (("right wheel motor", "left wheel motor") if name == "y3" else
                                                         ("left wheel motor", "right wheel motor")), name
        assert "receiver" in {d.name for d in robots[name].devices}
    assert [d.name for d in robots["robot"].devices] == ["emitter"]


def soccer_in_process(steps: int) -> tuple[dict, dict[int, dict[str, tuple[float, float, float]]], dict]:
    """The referee's and the players' calls in process for ``steps`` steps of 64 ms, checked as they go
    (see the test below): the contacts met (player: (step, what)), each step's closed-form poses of the
    players not yet stopped, and the last poses."""
    lv = Live(Simulation(load_world(DATA / "soccer.wbt"), "exact"))
    sim = lv.sim
    lv.ok(A, "attach", {"robot": "robot"})
    field = lambda node, f: lv.ok(A, "/robot/robot/get_field", {"node": node, "field": f})["value"]  # noqa: E731
    nodes = [lv.ok(A, "/robot/robot/get_from_def", {"name": n.upper()})["node"] for n in PLAYERS]
    ball_node = lv.ok(A, "/robot/robot/get_from_def", {"name": "BALL"})["node"]
    rotations = [field(n, "rotation") for n in nodes]
    angles = [r[3] if r[2] > 0 else -r[3] for r in rotations]
    assert angles == pytest.approx([3.14159, 2.72043, -1.5319153071795863, -0.4665753071795864, 0.464067, -1.5613],
                                   abs=1e-12)
    emitter = sim.device("robot/emitter")
    libc = ctypes.CDLL("libc.so.6")
    players = {}
    for name in PLAYERS:
        sim.device(f"{name}/receiver").enable(64)
        robot = sim.robot(name)
        wheels = (robot.motor("left wheel motor"), robot.motor("right wheel motor"))
        for m in wheels:
            m.set_position(math.inf)
            m.set_velocity(0.0)
        players[name] = {"robot": robot, "wheels": wheels, "counter": 0, "max": 50,
                         "rand": glibc_rand(libc, ord(name[0]) + ord(name[1])),
                         "pose": (float(robot.pose.translation[0]), float(robot.pose.translation[1]), yaw_of(robot)),
                         "speeds": (0.0, 0.0), "met": None}
    ball = tuple(field(ball_node, "translation")[:2])
    met = {}
    previous = None
    arcs = {}
    for step in range(1, steps + 1):
        sim.run(2)
        assert sim.time_ms == 64 * step
        now = {}
        for name, p in players.items():
            t = p["robot"].pose.translation
            now[name] = (float(t[0]), float(t[1]), yaw_of(p["robot"]))
        for name, p in players.items():
            if p["met"]:
                continue
            left, right = p["speeds"]
            if name == "y3":
                left, right = right, left           # the drive's left wheel is its "right wheel motor"
            arc = k3_move_on(*p["pose"], left, right, 0.064, 0.02, 0.09)
            hit = meets(arc, ball, {n: pose for n, pose in now.items() if n != name})
            if hit:
                p["met"] = met[name] = (step, hit)
                assert meets(now[name], ball, {n: pose for n, pose in now.items() if n != name}) is None, name
                if hit == "ball":                   # stopped with its face on it
                    assert gap_to_ball(*now[name], ball) == pytest.approx(0.0, abs=1e-9), name
                continue
            assert now[name][:2] == pytest.approx(arc[:2], abs=1e-9), (name, step)
            assert math.remainder(now[name][2] - arc[2], 2 * math.pi) == pytest.approx(0.0, abs=1e-9), (name, step)
            p["pose"] = arc
            arcs.setdefault(step, {})[name] = arc
        packet = []
        for i, node in enumerate(nodes):
            t = field(node, "translation")
            assert t[:2] == list(now[PLAYERS[i]][:2]), PLAYERS[i]
            packet += [t[0], t[1], angles[i]]
        ball_now = field(ball_node, "translation")
        assert tuple(ball_now[:2]) == ball
        packet += ball_now[:2]
        assert emitter.send(struct.pack("<20d", *packet))
        clock = 600 - 0.064 * step
        lv.ok(A, "/robot/robot/set_label", {"id": 2, "text": f"{int(clock / 60):02d}:{int(clock) % 60:02d}",
                                             "x": 0.45, "y": 0.01, "size": 0.1, "color": 0, "transparency": 0.0,
                                             "font": "Arial"})
        for name, p in players.items():
            speeds = (0.0, 0.0)
            got = sim.device(f"{name}/receiver").take()
            assert len(got) == (0 if step == 1 else 1), (name, step)
            for received in got:
                data = struct.unpack("<20d", received.data)
                assert list(data) == previous
                speeds = player_rule(name, p, data)
            for m, v in zip(p["wheels"], speeds):
                m.set_velocity(v)
            p["speeds"] = speeds
        previous = packet
    return met, arcs, {name: p["pose"] for name, p in players.items()}


def test_the_referee_and_players_calls_drive_them_by_the_closed_form() -> None:
    """The referee's and the six players' calls in process for 19.2 s (300 steps of 64 ms, basic step 32).
    Each step the referee reads the players' and the ball's translations (the rotations read once, at the
    start), sends them and sets its clock label, and each player reads that packet one step later, bit for
    bit. Each player moves on the arc of its wheel speeds (1e-9) until that arc would take its square into
    the ball, a wall or another player: B1 (at 0.2 m/s along -x from 128 ms) then stops with its face on
    the ball (x = -0.182283 + 0.021 + 0.0375), 1e-9, in the step its arc would enter it (576 ms), Y1 on the
    ball at 832 ms, Y2 on Y1 at 7.552 s, B2 on a wall at 14.656 s; the ball, which Webots' players
    push, stays. The goalkeepers follow the ball's y all along: B3 backs along +y until its packet's y is
    past 0.16 (0.1739), Y3 (its wheels named the other way round, no matter at equal speeds) to 0.1787."""
    met, _, last = soccer_in_process(300)
    assert met == {"b1": (9, "ball"), "y1": (13, "ball"), "y2": (118, "y1"), "b2": (229, "wall")}
    for name, y in (("b3", 0.1739), ("y3", 0.1787)):
        assert last[name][1] == pytest.approx(y, abs=5e-5), name



def test_a_goal_scores_and_the_referee_puts_the_ball_and_players_back_three_seconds_later() -> None:
    """The referee's goal rule in process: the ball, put by hand (another Supervisor call) into the blue
    goal at (0.8, 0, 0.05), falls there (the field's Plane is infinite to physics, as in Webots) and, its x
    past 0.745, scores for blue: label 0 reads "1" in blue; 47 steps later (3 s counted down by 0.064 s) the
    referee sets the ball's and the six players' translations and rotations back to what it read at the
    start, and B1, driven at 10 rad/s all along, is back there and one step further on its heading."""
    lv = Live(Simulation(load_world(DATA / "soccer.wbt"), "exact"))
    sim = lv.sim
    lv.ok(A, "attach", {"robot": "robot"})
    call = lambda service, args: lv.ok(A, f"/robot/robot/{service}", args)  # noqa: E731
    nodes = [call("get_from_def", {"name": n.upper()})["node"] for n in PLAYERS]
    ball = call("get_from_def", {"name": "BALL"})["node"]
    field = lambda node, f: call("get_field", {"node": node, "field": f})["value"]  # noqa: E731
    start = {n: (field(n, "translation"), field(n, "rotation")) for n in nodes}
    ball0 = field(ball, "translation")
    b1 = sim.robot("b1")
    for m in (b1.motor("left wheel motor"), b1.motor("right wheel motor")):
        m.set_position(math.inf)
        m.set_velocity(10.0)
    score = [0, 0]

    def scores() -> None:
        for i, (text, x, colour) in enumerate(((str(score[0]), 0.92, 0x0000FF), (str(score[1]), 0.05, 0xFFFF00))):
            call("set_label", {"id": i, "text": text, "x": x, "y": 0.01, "size": 0.1, "color": colour,
                               "transparency": 0.0, "font": "Arial"})

    scores()
    timer, scored_at, reset_at = 0.0, None, None
    for step in range(1, 61):
        sim.run(2)
        if step == 5:
            call("set_field", {"node": ball, "field": "translation", "value": [0.8, 0.0, 0.05]})
        at = field(ball, "translation")
        if timer == 0:
            if at[0] > 0.745:
                score[0] += 1
                scores()
                timer, scored_at = 3.0, step
            elif at[0] < -0.745:
                score[1] += 1
                scores()
                timer = 3.0
        else:
            timer -= 0.064
            if timer <= 0:
                timer, reset_at = 0.0, step
                call("set_field", {"node": ball, "field": "translation", "value": ball0})
                for n, (t, r) in start.items():
                    call("set_field", {"node": n, "field": "translation", "value": t})
                    call("set_field", {"node": n, "field": "rotation", "value": r})
                for n, (t, r) in start.items():
                    assert (field(n, "translation"), field(n, "rotation")) == (t, r)
            if reset_at and step == reset_at + 1:
                assert field(ball, "translation") == ball0
                for n, (t, r) in list(start.items())[1:]:
                    assert field(n, "translation") == pytest.approx(t, abs=1e-12) and \
                        field(n, "rotation") == pytest.approx(r, abs=1e-12)
                moved = field(nodes[0], "translation")
                assert moved == pytest.approx([start[nodes[0]][0][0] - 0.2 * 0.064, start[nodes[0]][0][1],
                                               start[nodes[0]][0][2]], abs=1e-9)
        if step == 6:
            assert at[:2] == [0.8, 0.0] and at[2] < 0.05          # falling in the goal
    assert (scored_at, reset_at) == (5, 5 + 47)
    assert field(ball, "translation") == ball0
    labels = dict(sim._labels.items())
    assert (labels[0].text, labels[0].color, labels[1].text, labels[1].color) == ("1", 0x0000FF, "0", 0xFFFF00)


PLAYER_CONTROLLER = '''\
# Sensorium's test controller making soccer_player.c's calls (Webots' demo), glibc's srand and rand
# through ctypes as the C controller calls them.
import ctypes
import math
import struct
from controller import Robot

libc = ctypes.CDLL("libc.so.6")
robot = Robot()
name = robot.getName()
team, player = name[0], name[1]
receiver = robot.getDevice("receiver")
left, right = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
for m in (left, right):
    m.setPosition(math.inf)
    m.setVelocity(0.0)
libc.srand(ord(team) + ord(player))
receiver.enable(64)
counter, top = 0, 50
while robot.step(64) != -1:
    speeds = (0, 0)
    while receiver.getQueueLength() > 0:
        packet = struct.unpack("<20d", receiver.getBytes())
        if player in "12":
            counter += 1
            speeds = (10, 10) if counter < top else (-10, 10)
            if counter == 100:
                counter = 0
                top = 30 + libc.rand() // (2147483647 // 70)
        else:
            me = 3 * (int(player) - 1 + (3 if team == "y" else 0))
            y = packet[me + 1]
            d = y - packet[19]
            if d > 0.01 and y > -0.16:
                speeds = (10, 10)
            elif d < -0.01 and y < 0.16:
                speeds = (-10, -10)
        receiver.nextPacket()
    left.setVelocity(speeds[0])
    right.setVelocity(speeds[1])
'''

REFEREE_CONTROLLER = '''\
# Sensorium's test controller making soccer_referee_supervisor.c's calls (Webots' demo), printing the
# players' packet positions at three times.
import struct
from controller import Supervisor

sup = Supervisor()
emitter = sup.getDevice("emitter")
names = ("B1", "B2", "B3", "Y1", "Y2", "Y3")
translations = [sup.getFromDef(n).getField("translation") for n in names]
rotations = [sup.getFromDef(n).getField("rotation").getSFRotation() for n in names]
ball = sup.getFromDef("BALL").getField("translation")
sup.setLabel(0, "0", 0.92, 0.01, 0.1, 0x0000FF, 0.0, "Arial")
sup.setLabel(1, "0", 0.05, 0.01, 0.1, 0xFFFF00, 0.0, "Arial")
clock = 600.0
while sup.step(64) != -1:
    packet = []
    for t, r in zip(translations, rotations):
        x, y, _ = t.getSFVec3f()
        packet += [x, y, r[3] if r[2] > 0 else -r[3]]
    packet += ball.getSFVec3f()[:2]
    emitter.send(struct.pack("<20d", *packet))
    clock -= 0.064
    sup.setLabel(2, "%02d:%02d" % (int(clock / 60), int(clock) % 60), 0.45, 0.01, 0.1, 0x000000, 0.0, "Arial")
    t = round(sup.getTime() * 1000)
    if t in (3200, 6400, 12800):
        print(t, " ".join(f"{v:.9f}" for v in packet), flush=True)
'''


@pytest.mark.slow
def test_the_soccer_demo_runs_under_sensorium_run_as_in_process(tmp_path: Path) -> None:
    """Our Python controllers making soccer_player.c's and soccer_referee_supervisor.c's calls under
    ``sensorium run`` for 13 s: the referee's packets at 3.2, 6.4 and 12.8 s carry the positions the
    closed form gives each player not yet stopped (1e-9): the goalkeepers, B2, and Y2 before it meets Y1."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "soccer.wbt"
    shutil.copy(DATA / "soccer.wbt", world)
    for name, source in (("soccer_player", PLAYER_CONTROLLER), ("soccer_referee_supervisor", REFEREE_CONTROLLER)):
        (tmp_path / "controllers" / name).mkdir(parents=True)
        (tmp_path / "controllers" / name / f"{name}.py").write_text(source)
    done = subprocess.run(sensorium("run", str(world), "--until", "13000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    got = {}
    for line in done.stdout.splitlines():
        if line.startswith("[robot] "):
            t, *values = line.split("] ", 1)[1].split()
            got[int(t)] = [float(v) for v in values]
    assert sorted(got) == [3200, 6400, 12800], done.stdout[-2000:]
    _, arcs, _ = soccer_in_process(200)
    checked = 0
    for t, packet in got.items():
        for i, name in enumerate(PLAYERS):
            if name in arcs[t // 64]:
                assert packet[3 * i:3 * i + 2] == pytest.approx(list(arcs[t // 64][name][:2]), abs=1e-9), (name, t)
                checked += 1
    assert checked == 3 * 3 + 2       # b2, b3, y3 each time; y2 until it meets y1
