"""Sweep 17: Webots' sample controllers not run before, each on a stand-in world of ours
(tests/data/sweep17/: the sample's poses and sizes and its PROTO's device names, places and tables, our
own text) driven by the calls its sample controller makes, checked against closed forms."""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import pytest
from _serve import child_env, sensorium

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep17"

# pioneer3dx_collision_avoidance: the Pioneer 3-DX (wheels of radius 0.0975 m at y ±0.165) and its 16
# sonars (x, y, heading in degrees; all at z 0.114 above the origin, itself 0.0975 m up) in the 12 x 12 m
# arena with six 0.6 m boxes; its controller's rule (MAX_SPEED 5.24, 0.7 of it to turn, weights, 100).
P3DX = "Pioneer 3-DX"
P3DX_R, P3DX_AXLE, P3DX_STEP = 0.0975, 0.33, 8
SONARS = [(0.061, 0.1402, 90), (0.1103, 0.1223, 50), (0.1455, 0.0801, 30), (0.1642, 0.0285, 10),
          (0.1642, -0.0264, -10), (0.1455, -0.078, -30), (0.1103, -0.1201, -50), (0.061, -0.1381, -90),
          (-0.1549, -0.1373, -90), (-0.2041, -0.1194, -130), (-0.2392, -0.0774, -150), (-0.2578, -0.0259, -170),
          (-0.2578, 0.0289, 170), (-0.2392, 0.0804, 150), (-0.2041, 0.1224, 130), (-0.1549, 0.1403, 90)]
WEIGHTS = [(150, 0), (200, 0), (300, 0), (600, 0), (0, 600), (0, 300), (0, 200), (0, 150)] + [(0, 0)] * 8
BOXES = [(-0.201269, 4.94642), (0.225428, -5.08162), (4.01933, -3.31136), (3.98789, 3.08066),
         (-4.22157, -3.54663), (-4.21065, 2.89465)]


def p3dx_world(tmp_path: Path):
    """The stand-in loaded, its sonars' 1 % noise taken out: (simulation, robot)."""
    text = (DATA / "pioneer3dx_collision_avoidance.wbt").read_text()
    text = text.replace("lookupTable [ 0 1024 0.01, 5 0 0.01 ]", "lookupTable [ 0 1024 0, 5 0 0 ]")
    path = tmp_path / "pioneer3dx_collision_avoidance.wbt"
    path.write_text(text)
    sim = Simulation(load_world(path), "exact")
    return sim, sim.robot(P3DX)


def sonar_closed_form(x: float, y: float, heading: float) -> float:
    """A sonar's reading from (x, y) along ``heading``: the nearest of the arena's inner wall faces
    (x, y = ±6) and the boxes' faces (0.6 m cubes, taller than the sonars' 0.2115 m) its ray meets,
    1024·(1 - d/5) if the ray meets it within 5 m at no more than π/8 from the face's normal (a sonar
    hears no echo past that), else 0 (the table's far end)."""
    dx, dy = math.cos(heading), math.sin(heading)
    rects = [(-6.0, -6.0, 6.0, 6.0, True)] + [(bx - 0.3, by - 0.3, bx + 0.3, by + 0.3, False) for bx, by in BOXES]
    best, best_cos = math.inf, 0.0
    for x0, y0, x1, y1, inside in rects:
        faces = []
        if abs(dx) > 1e-15:
            for fx, nx in ((x0, -1.0), (x1, 1.0)):
                t = (fx - x) / dx
                if t > 0 and y0 <= y + t * dy <= y1 and (dx * nx > 0) == inside:
                    faces.append((t, abs(dx)))
        if abs(dy) > 1e-15:
            for fy, ny in ((y0, -1.0), (y1, 1.0)):
                t = (fy - y) / dy
                if t > 0 and x0 <= x + t * dx <= x1 and (dy * ny > 0) == inside:
                    faces.append((t, abs(dy)))
        for t, c in faces:
            if t < best:
                best, best_cos = t, c
    if best >= 5.0 or best_cos < math.cos(math.pi / 8):
        return 0.0
    return 1024.0 * (1.0 - best / 5.0)


def collision_avoidance_rule(values: list[float], state: str) -> tuple[float, float, str]:
    """pioneer3dx_collision_avoidance's step: each sonar's distance 5·(1 - v/1024) under 1 m weighs
    (1 - d) on each wheel; over 100 on the left (right) wheel's sum it turns right (left) in place at
    0.7·5.24 rad/s and keeps turning while either sum is over 100, else drives on at 5.24 rad/s."""
    total = [0.0, 0.0]
    for v, w in zip(values, WEIGHTS):
        d = 5.0 * (1.0 - v / 1024.0)
        m = 0.0 if v == 0.0 or d >= 1.0 else 1.0 - d
        total[0] += w[0] * m
        total[1] += w[1] * m
    if state == "forward":
        if total[0] > 100:
            return 0.7 * 5.24, -0.7 * 5.24, "left"
        if total[1] > 100:
            return -0.7 * 5.24, 0.7 * 5.24, "right"
        return 5.24, 5.24, "forward"
    if total[0] > 100 or total[1] > 100:
        return (0.7 * 5.24, -0.7 * 5.24, state) if state == "left" else (-0.7 * 5.24, 0.7 * 5.24, state)
    return 5.24, 5.24, "forward"


def yaw_of(robot) -> float:
    r = robot.pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


def test_the_pioneer_3dx_stand_in_loads_with_its_drive_sonars_and_leds() -> None:
    """The stand-in loads with no line; its wheels (radius 0.0975 m, 0.33 m apart, both hinges on the
    axle through the origin) are a two-wheel drive, and every device the controller asks for is there."""
    w = load_world(DATA / "pioneer3dx_collision_avoidance.wbt")
    assert w.warnings == []
    robot = w.world.robots[0]
    drive = robot.differential_drive
    assert drive is not None
    assert (drive.wheel_radius, drive.axle_length, tuple(drive.axle_center)) == (P3DX_R, P3DX_AXLE, (0.0, 0.0))
    names = {d.name for d in robot.devices}
    assert {f"so{i}" for i in range(16)} | {"left wheel", "right wheel", "red led 1", "red led 2", "red led 3"} <= names


def test_the_pioneer_3dx_sonars_read_the_closed_form_and_its_rule_drives_it_so(tmp_path: Path) -> None:
    """pioneer3dx_collision_avoidance's calls in process, its 8 ms step, the sonars' noise taken out, for
    24 s: every step the 16 sonars read the closed form's echo from the walls and boxes (1e-6 of 1024:
    the rays are cast in float32), and the controller's rule on them drives the robot: straight on at
    5.24 × 0.0975 = 0.5109 m/s, turning in place about its axle's centre at 0.7 × 5.24 × 2 × 0.0975 /
    0.33 = 2.1675 rad/s, the pose the closed form's step by step (1e-9). It drives 5.4687 m (10.704 s from
    its first step's command) towards the north wall and first turns right, its front sonars so2 and
    so3 hearing the wall within 1 m, at 10.712 s; one 8 ms step of turning brings the sums under 100
    again, so it turns in short bursts; by 24 s it has turned at the north and east walls."""
    sim, robot = p3dx_world(tmp_path)
    sonars = [sim.device(f"{P3DX}/so{i}") for i in range(16)]
    for s in sonars:
        s.enable(P3DX_STEP)
    left, right = robot.motor("left wheel"), robot.motor("right wheel")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    x, y = (float(v) for v in robot.pose.translation[:2])
    yaw = yaw_of(robot)
    state, wl, wr, dt = "forward", 0.0, 0.0, P3DX_STEP / 1000
    turns = []
    for k in range(1, 3001):
        sim.step()
        v_, w_ = P3DX_R * (wl + wr) / 2, P3DX_R * (wr - wl) / P3DX_AXLE
        if w_ == 0.0:
            x, y = x + v_ * dt * math.cos(yaw), y + v_ * dt * math.sin(yaw)
        else:                                          # a turn in place: v is 0
            yaw = math.remainder(yaw + w_ * dt, 2 * math.pi)
        assert [float(v) for v in robot.pose.translation[:2]] == pytest.approx([x, y], abs=1e-9), k
        assert math.remainder(yaw_of(robot) - yaw, 2 * math.pi) == pytest.approx(0.0, abs=1e-9), k
        values = [float(s.value) for s in sonars]
        want = [sonar_closed_form(x + math.cos(yaw) * sx - math.sin(yaw) * sy,
                                  y + math.sin(yaw) * sx + math.cos(yaw) * sy, yaw + math.radians(deg))
                for sx, sy, deg in SONARS]
        assert values == pytest.approx(want, abs=1e-6 * 1024), k
        wl, wr, new_state = collision_avoidance_rule(values, state)
        if new_state != state and new_state != "forward":
            turns.append((k * P3DX_STEP, new_state, round(x, 4), round(y, 4)))
        state = new_state
        left.set_velocity(wl)
        right.set_velocity(wr)
    assert turns[0] == (10712, "left", 1.5704, 4.9672)
    assert math.hypot(1.5704 + 0.613659, 4.9672 + 0.0464224) == pytest.approx(5.24 * P3DX_R * 10.704, abs=1e-4)
    assert any(t > 18000 and px > 4.5 for t, _, px, _ in turns)      # the east wall


# Webots' controller is Webots' file, never this repository's: the run below uses our own Python
# controller making its calls (under `sensorium run`, Webots' C one, built against our libController,
# printed the same poses: docs/webots-samples.md, sweep 17), and a watcher of ours printing the robot's pose.
P3DX_CONTROLLER = '''\
import math

from controller import Robot

WEIGHTS = [(150, 0), (200, 0), (300, 0), (600, 0), (0, 600), (0, 300), (0, 200), (0, 150)] + [(0, 0)] * 8
robot = Robot()
step = int(robot.getBasicTimeStep())
left, right = robot.getDevice("left wheel"), robot.getDevice("right wheel")
leds = [robot.getDevice(f"red led {i}") for i in (1, 2, 3)]
sonars = [robot.getDevice(f"so{i}") for i in range(16)]
for s in sonars:
    s.enable(step)
for m in (left, right):
    m.setPosition(math.inf)
    m.setVelocity(0.0)
state, led, delay = "forward", 0, 0
while robot.step(step) != -1:
    total = [0.0, 0.0]
    for s, w in zip(sonars, WEIGHTS):
        v = s.getValue()
        d = 5.0 * (1.0 - v / 1024)
        m = 0.0 if v == 0.0 or d >= 1.0 else 1.0 - d
        total = [total[0] + w[0] * m, total[1] + w[1] * m]
    near = total[0] > 100 or total[1] > 100
    if state == "forward" and near:
        state = "left" if total[0] > 100 else "right"
        print(f"turn {state} at {round(robot.getTime() * 1000)}", flush=True)
    elif state != "forward" and not near:
        state = "forward"
    speed = {"forward": (5.24, 5.24), "left": (3.668, -3.668), "right": (-3.668, 3.668)}[state]
    delay += 1
    if delay == 70:
        leds[led].set(0)
        led = (led + 1) % 3
        leds[led].set(1)
        delay = 0
    left.setVelocity(speed[0])
    right.setVelocity(speed[1])
'''

WATCHER = '''\
import math

from controller import Supervisor

sup = Supervisor()
node = sup.getFromDef("PIONEER_3DX")
while sup.step(8) != -1:
    p, r = node.getPosition(), node.getOrientation()
    print(f"pose {round(sup.getTime() * 1000)} {p[0]:.9f} {p[1]:.9f} {math.atan2(r[3], r[0]):.9f}", flush=True)
'''


@pytest.mark.slow
def test_the_collision_avoidance_calls_under_sensorium_run_turn_at_the_closed_form_step(tmp_path: Path) -> None:
    """Our Python controller making pioneer3dx_collision_avoidance's calls (the 16 sonars, the rule, the
    LEDs every 70 steps), the sonars' noise taken out, under ``sensorium run`` for 12 s: it prints its
    first turn at 10.712 s, where the robot is 0.5109 × 10.704 m on from its start (1e-6), and the next
    step it has turned 0.7 × 5.24 × 2 × 0.0975 / 0.33 × 0.008 rad in place."""
    text = (DATA / "pioneer3dx_collision_avoidance.wbt").read_text()
    text = text.replace("lookupTable [ 0 1024 0.01, 5 0 0.01 ]", "lookupTable [ 0 1024 0, 5 0 0 ]")
    text += 'Robot { name "watcher" supervisor TRUE controller "watcher" }\n'
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "pioneer3dx_collision_avoidance.wbt"
    world.write_text(text)
    for name, source in (("pioneer3dx_collision_avoidance", P3DX_CONTROLLER), ("watcher", WATCHER)):
        (tmp_path / "controllers" / name).mkdir(parents=True)
        (tmp_path / "controllers" / name / f"{name}.py").write_text(source)
    done = subprocess.run(sensorium("run", str(world), "--until", "12000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    turns = [x.split("] ", 1)[1] for x in done.stdout.splitlines() if " turn " in x]
    assert turns[0] == "turn left at 10712", done.stdout[-2000:]
    poses = {}
    for line in done.stdout.splitlines():
        if line.startswith("[watcher] pose "):
            t, *values = line.split()[2:]
            poses[int(t)] = [float(v) for v in values]
    x0, y0, yaw0 = -0.613659, -0.0464224, math.remainder(-5.12323, 2 * math.pi)
    on = 5.24 * P3DX_R * 10.704
    assert poses[10712] == pytest.approx([x0 + on * math.cos(yaw0), y0 + on * math.sin(yaw0), yaw0], abs=1e-6)
    turned = 0.7 * 5.24 * 2 * P3DX_R / P3DX_AXLE * P3DX_STEP / 1000
    assert poses[10720] == pytest.approx([*poses[10712][:2], yaw0 - turned], abs=1e-6)


# pioneer2: Webots' default braitenberg controller on the Pioneer 2 (no Physics: kinematic in Webots
# too): wheels of radius 0.0825 m at y ±0.1603, 16 infra-red sensors (x, y, heading in degrees) at z
# 0.209; the ground's walls, blocks and wedges (its y-up boxes: translation x, z, turn about y, size x,
# z) and the central cylinder, green PBR (roughness 1).
P2_R, P2_STEP = 0.0825, 32
P2_AXLE = 2.0 * math.hypot(0.1603, 0.0825)    # no Physics: Webots' kinematic rule's axle, the wheels' 3-D distances
P2_SENSORS = [(0.164, 0.027, 10), (0.147, 0.077, 30), (0.116, 0.118, 50), (0.071, 0.136, 90), (-0.16, 0.136, 90),
              (-0.205, 0.118, 130), (-0.236, 0.077, 150), (-0.253, 0.027, 170), (-0.253, -0.027, -170),
              (-0.236, -0.077, -150), (-0.205, -0.118, -130), (-0.16, -0.136, -90), (0.071, -0.136, -90),
              (0.116, -0.118, -50), (0.147, -0.077, -30), (0.164, -0.027, -10)]
P2_MATRIX = [(-1, 15), (-3, 13), (-3, 8), (-2, 7), (-3, -4), (-4, -2), (-3, -2), (-1, -1), (-1, -1), (-2, -3), (-2, -4),
             (4, -3), (7, -5), (7, -3), (10, -2), (11, -1)]
P2_BOXES = [(2, 0, 0, 0.02, 4), (-2, 0, 0, 0.02, 4), (0, 2, 1.57, 0.02, 4), (0, -2, 1.57, 0.02, 4),
            (1.7, 0, 0, 0.4, 0.6), (-1.7, 0, 0, 0.4, 0.6), (0, 1.7, 1.57, 0.4, 0.6), (0, -1.7, 1.57, 0.4, 0.6),
            (1.77, 0.455, 0.885, 0.1, 0.6), (-1.77, -0.455, 0.885, 0.1, 0.6), (1.77, -0.455, -0.885, 0.1, 0.6),
            (-1.77, 0.455, -0.885, 0.1, 0.6), (-0.445, 1.77, -0.685, 0.1, 0.6), (0.445, 1.77, 0.685, 0.1, 0.6),
            (0.445, -1.77, -0.685, 0.1, 0.6), (-0.445, -1.77, 0.685, 0.1, 0.6)]
GREEN_RED, CYLINDER_RED = 0.103335, 0.16452


def ir_closed_form(x: float, y: float, heading: float) -> float:
    """An infra-red sensor's reading from (x, y) along ``heading``: the nearest face its ray meets, a
    ground box (local (x, z) to the world's (x, -z), its turn θ about y: axes (cos θ, sin θ) and
    (sin θ, -cos θ)) or the cylinder (radius 0.3 at the origin), at d; read at d / (0.2 + 0.8·red·0.5)
    (roughness 1) in the table 0.2 m -> 1024, 0.4 m -> 0, beyond it 0."""
    dx, dy = math.cos(heading), math.sin(heading)
    best, red = math.inf, 0.0
    for tx, tz, th, sx, sz in P2_BOXES:
        cx, cy = tx, -tz
        a, b = (math.cos(th), math.sin(th)), (math.sin(th), -math.cos(th))
        px, py = (x - cx) * a[0] + (y - cy) * a[1], (x - cx) * b[0] + (y - cy) * b[1]
        ux, uy = dx * a[0] + dy * a[1], dx * b[0] + dy * b[1]
        lo, hi = -math.inf, math.inf
        for p, u, half in ((px, ux, sx / 2), (py, uy, sz / 2)):
            if abs(u) < 1e-15:
                if abs(p) > half:
                    lo, hi = math.inf, -math.inf
                continue
            t0, t1 = sorted(((-half - p) / u, (half - p) / u))
            lo, hi = max(lo, t0), min(hi, t1)
        if lo <= hi and 0 < lo < best:
            best, red = lo, GREEN_RED
    b = x * dx + y * dy
    disc = b * b - (x * x + y * y - 0.09)
    if disc >= 0 and 0 < -b - math.sqrt(disc) < best:
        best, red = -b - math.sqrt(disc), CYLINDER_RED
    seen = best / (0.2 + 0.8 * red * 0.5)
    if seen >= 0.4:
        return 0.0
    return 1024.0 if seen <= 0.2 else 1024.0 * (0.4 - seen) / 0.2


def test_the_braitenberg_controller_drives_the_pioneer_2_on_its_closed_form_arcs(tmp_path: Path) -> None:
    """Webots' braitenberg controller's pioneer2 rule in process (32 ms steps, each wheel 0.1 · Σ
    weight · (1 - value/512), within ±10 rad/s), the sensors' 10 % noise taken out, for 60 s: every step
    the 16 infra-red sensors read the closed form's (the nearest green face at d reads the table at
    d / 0.2413, the cylinder's at d / 0.2658; 0.02 of 1024, rays in float32) and the pose is Webots'
    kinematic rule's for a robot without Physics (axle 2·√(0.1603² + 0.0825²) = 0.36057 m, a straight
    segment along the mid-step heading) from the wheel speeds set the step before (1e-9), no wall
    holding it. In open space every sensor reads 0: left 1.4, right 1.2 rad/s, 0.10725 m/s curving right
    at 0.04576 rad/s (radius 2.344 m) from (1, 0) heading +y, until ds13 (50° right) first sees the east
    wall at 17.792 s; it turns away in time and roams the 60 s without a wall holding it. (By the arc on
    the 0.3206 m between the wheels it curved at 0.05147 rad/s and met the wall at 18.016 s.)"""
    text = (DATA / "pioneer2.wbt").read_text()
    text = text.replace("lookupTable [ 0 1024 0, 0.2 1024 0.1, 0.4 0 0.1 ]", "lookupTable [ 0 1024 0, 0.2 1024 0, 0.4 0 0 ]")
    path = tmp_path / "pioneer2.wbt"
    path.write_text(text)
    w = load_world(path)
    assert w.warnings == []
    drive = w.world.robots[0].differential_drive
    assert drive is not None and (drive.wheel_radius, drive.step_rule) == (P2_R, "mid_heading")
    assert drive.axle_length == pytest.approx(P2_AXLE, abs=1e-15)
    sim = Simulation(w, "exact")
    robot = sim.robot("pioneer2")
    sensors = [sim.device(f"pioneer2/ds{i}") for i in range(16)]
    for s in sensors:
        s.enable(P2_STEP)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    wl = wr = 0.0
    dt = P2_STEP / 1000
    first_seen, held = None, []
    for k in range(1, 60000 // P2_STEP + 1):
        x, y = (float(c) for c in robot.pose.translation[:2])
        yaw = yaw_of(robot)
        sim.run(1)
        # Webots' kinematic rule: a straight segment along the mid-step heading yaw + d, the heading then yaw + 2d
        d = (wr - wl) * dt * P2_R / (2.0 * P2_AXLE)
        v = 0.5 * (wl + wr) * P2_R * dt
        x, y, yaw = x + v * math.cos(yaw + d), y + v * math.sin(yaw + d), yaw + 2.0 * d
        gx, gy = (float(c) for c in robot.pose.translation[:2])
        if math.hypot(gx - x, gy - y) > 1e-9 or abs(math.remainder(yaw_of(robot) - yaw, 2 * math.pi)) > 1e-9:
            held.append((k, round(gx - x, 6), round(gy - y, 6)))       # a wall held it
        x, y, yaw = gx, gy, yaw_of(robot)
        values = [float(s.value) for s in sensors]
        want = [ir_closed_form(x + math.cos(yaw) * sx - math.sin(yaw) * sy, y + math.sin(yaw) * sx + math.cos(yaw) * sy,
                               yaw + math.radians(deg)) for sx, sy, deg in P2_SENSORS]
        assert values == pytest.approx(want, abs=0.02), k
        if first_seen is None and any(values):
            first_seen = (k * P2_STEP, [i for i, v in enumerate(values) if v], round(x, 4), round(y, 4))
        speeds = [max(-10.0, min(10.0, sum(0.1 * m[i] * (1.0 - val / 512) for m, val in zip(P2_MATRIX, values))))
                  for i in (0, 1)]
        wl, wr = speeds
        if first_seen is None:
            assert (wl, wr) == pytest.approx((1.4, 1.2), abs=1e-12)     # open space: Σ weights / 10
        left.set_velocity(wl)
        right.set_velocity(wr)
    assert first_seen == (17792, [13], 1.731, 1.7025)
    assert held == []             # turning by Webots' rule it turns away in time: no wall holds it in 60 s


def test_the_motor_sample_s_turntable_follows_its_staircase_by_the_kinematic_rule() -> None:
    """motor (Webots' device sample): each 8 ms step the controller sets the turntable's target, 0 for
    51 steps, then π/4 more every 51 steps. Its hinge starts at 1.5708 and moves kinematically (one load
    line: forces are ignored, so the client's torque feedback reads NaN; the robot's battery is one more
    line: with physics and a consuming motor, it drains by cpuConsumption only here): its speed grows by maxTorque × dt = 20 × 0.008 rad/s a step up to
    maxVelocity 2 rad/s towards the target and it stops on it the step it would pass it. Every step's
    angle is that rule's (1e-12): down from 1.5708 towards 0 at 2 rad/s, it meets the next target π/4
    on its way at 0.448 s and stops there; it rests until π/2 is set, and from then on, a π/4 step in
    0.408 s being 0.39 s at full speed, it lags the staircase (5.4828 rad at 3.28 s, the target 2π)."""
    w = load_world(DATA / "motor.wbt")
    assert any("its battery drains by cpuConsumption only" in x for x in w.warnings), w.warnings
    assert w.world.robots[0].battery == [3600.0, 36000.0, 5.0]
    assert any("HingeJoint motor 'motor' is no wheel" in x for x in w.warnings), w.warnings
    sim = Simulation(w, "exact")
    motor = sim.robot(w.world.robots[0].name).motor("motor")
    x, v, dt = 1.5708, 0.0, 0.008
    assert motor.position == pytest.approx(x, abs=1e-12)
    target, counter, rested = 0.0, 0, []
    target_set: float | None = None
    for k in range(1, 411):
        sim.run(1)
        if target_set is not None:                     # the rule on the target set after the step before
            to = target_set - x
            if to == 0.0:
                v = 0.0
            else:
                v = math.copysign(min(abs(v) + 20 * dt, 2.0), to) if v * to >= 0 else math.copysign(20 * dt, to)
                if abs(v * dt) >= abs(to):
                    x, v = target_set, 0.0
                    rested.append(k)
                else:
                    x += v * dt
        assert motor.position == pytest.approx(x, abs=1e-12), k
        motor.set_position(target)
        target_set = target
        if counter == 50:
            target += math.pi / 4
            counter = 0
        else:
            counter += 1
    assert rested[0] == 56 and x == pytest.approx(5.482831, abs=1e-6)


def test_the_position_sensor_sample_s_pole_stands_and_its_pid_asks_nothing() -> None:
    """position_sensor (Webots' device sample, an inverted pendulum balanced by a PID on the pole's
    hinge): the hinge's sensor, unnamed in the world, is "position sensor" as in Webots; the pole's free
    hinge is moved by nothing without physics (one load line), so it reads 0 at every step, the PID's
    speed KP·0 + KI·0 + KD·0 is 0 and MyBot stays where it stands (1e-12 after 10 s), where Webots'
    physics tips the pole and the robot drives to catch it."""
    w = load_world(DATA / "position_sensor.wbt")
    assert any("PositionSensor on a joint without a motor" in x for x in w.warnings), w.warnings
    robot_node = w.world.robots[0]
    assert "position sensor" in {d.name for d in robot_node.devices}
    sim = Simulation(w, "exact")
    robot = sim.robot("MyBot")
    sensor = sim.device("MyBot/position sensor")
    sensor.enable(16)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    start = [float(c) for c in robot.pose.translation]
    previous, integral = 0.0, 0.0
    for _ in range(625):
        sim.run(1)
        position = float(sensor.value)
        assert position == 0.0
        integral += (position + previous) * 0.5
        speed = max(-100.0, min(100.0, 35 * position + 5 * integral + 28.9 * (position - previous)))
        left.set_velocity(-speed)
        right.set_velocity(-speed)
        previous = position
    assert [float(c) for c in robot.pose.translation] == pytest.approx(start, abs=1e-12)
