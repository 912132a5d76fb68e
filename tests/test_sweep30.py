"""Sweep 30: Webots' `projects/vehicles` highway_overtake sample not run before, on a stand-in world of ours
(tests/data/sweep30/: the LincolnMKZ's Car geometry, joints, slots and the sample's sensors where it puts them,
our own text; SUMO's traffic stood in for by two boxes our Supervisor moves at constant speeds) driven by the
calls its controllers make and checked against closed forms."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep30"
HIGHWAY = DATA / "highway_overtake.wbt"

# highway_overtake (projects/vehicles, R2025a): the LincolnMKZ (a 4x4 Car: wheelbase 2.94 m, tracks 1.64 m,
# tyres 0.358 m, the rear axle's centre its origin) at (-40, 6.71, 0.4) turned 3.14159 rad about -z (facing -x,
# its left -y); its slots as the stand-in puts them: front (3.944, 0, 0.142), rear (-1.06, 0, 0.33) turned π,
# top (1.11, 0, 1.16), centre the origin. Each distance sensor: two rays at ±aperture/2 beside its x axis
# (Webots' layout for two rays), the identity table up to its range. The traffic: boxes 4.9 × 1.8 × 1.5 on the
# road, their centres 0.75 m up.
YAW = -3.14159
TYRE = 0.358
START = (-40.0, 6.71)
FRONT, CENTRE = np.array([3.944, 0.0, 0.142]), np.zeros(3)
HALF = np.array([2.45, 0.9, 0.75])
SENSORS = {   # name: (slot, translation in the slot, yaw in the slot, aperture, range)
    "front": (FRONT, (-0.14, 0.0, 0.3), 0.0, 0.1, 20.0),
    "front right 0": (FRONT, (-0.292861, 0.645126, 0.3), 0.130899, 0.1, 20.0),
    "front left 0": (FRONT, (-0.284201, -0.650126, 0.3), -0.130901, 0.1, 20.0),
    "right": (CENTRE, (1.32, -0.9, 0.3), -1.5708, 0.9, 4.0),
    "left": (CENTRE, (1.32, 0.9, 0.3), 1.5708, 0.9, 4.0),
}


def rot(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def box_hit(origin: np.ndarray, d: np.ndarray, centre: np.ndarray) -> float:
    """The ray's parameter where it enters the box of half sizes HALF about ``centre`` (slabs), inf if it misses."""
    lo, hi = -math.inf, math.inf
    for k in range(3):
        a_, b_ = centre[k] - HALF[k], centre[k] + HALF[k]
        if d[k] == 0.0:
            if not a_ <= origin[k] <= b_:
                return math.inf
            continue
        a, b = (a_ - origin[k]) / d[k], (b_ - origin[k]) / d[k]
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    return lo if lo <= hi and lo > 0.0 else math.inf


def sensor_closed_form(name: str, car: np.ndarray, cars: list[np.ndarray]) -> float:
    """The sensor's value: the mean of its two rays' distances to the nearest box, each at most its range."""
    slot, at, yaw, aperture, reach = SENSORS[name]
    r = rot(YAW)
    eye = car + r @ (slot + np.array(at))
    out = []
    for side in (1.0, -1.0):
        d = r @ rot(yaw) @ np.array([math.cos(aperture / 2), side * math.sin(aperture / 2), 0.0])
        out.append(min([reach] + [box_hit(eye, d, c) for c in cars]))
    return sum(out) / 2.0


def beside_protos(path: Path) -> Path:
    """``path``, with the stand-in's PROTOs copied beside it."""
    if not (path.parent / "protos").exists():
        shutil.copytree(DATA / "protos", path.parent / "protos")
    return path


def scene(text: str, slow: tuple[float, float], far: tuple[float, float], path: Path) -> Path:
    """The stand-in with the two traffic cars' centres moved to (x, y)."""
    beside_protos(path)
    text = text.replace("translation -70 6.875 0.75", f"translation {slow[0]} {slow[1]} 0.75")
    text = text.replace("translation -240 3.2 0.75", f"translation {far[0]} {far[1]} 0.75")
    path.write_text(text)
    return path


def test_the_lincoln_loads_as_a_4x4_car_with_the_samples_sensors_and_the_radar_robot_riding_it() -> None:
    """The LincolnMKZ stand-in loads as a 4x4 Ackermann car of its Car geometry with every device
    highway_overtake looks up (twelve distance sensors, the GPS, the camera) and the four lidars, and lands on
    its tyres at z 0.358; the sample's radar, in a supervisor Robot nested in the front slot (the
    radar_target_tracker's), is a robot of its own riding the car 0.11 m ahead of the slot, at z 0.5 (it was
    dropped, one line, before this sweep)."""
    w = load_world(HIGHWAY)
    assert w.warnings == [] and w.report.losses == ()
    assert [r.name for r in w.world.robots] == ["traffic", "vehicle", "robot"]
    car, rider = w.world.robots[1], w.world.robots[2]
    drive = car.ackermann_drive
    assert (drive.type, drive.wheelbase, drive.track_front, drive.track_rear) == ("4x4", 2.94, 1.64, 1.64)
    assert (drive.front_wheel_radius, drive.rear_wheel_radius, drive.positive_steers) == (TYRE, TYRE, "right")
    names = {d.name for d in car.devices}
    wanted = {"distance sensor " + n for n in ("front", "front right 0", "front right 1", "front right 2",
                                               "front left 0", "front left 1", "front left 2", "rear", "rear left",
                                               "rear right", "right", "left")}
    assert wanted | {"gps", "camera", "ibeo 1", "ibeo 2"} <= names and "radar" not in names
    assert [d.name for d in rider.devices] == ["radar"] and rider.supervisor
    assert (rider.controller, rider.carried_by.robot) == ("radar_target_tracker", "vehicle")
    assert rider.carried_by.frame.translation == pytest.approx((3.944 + 0.11, 0.0, 0.142), abs=1e-12)
    sim = Simulation(w, "exact")
    pose = sim.robot("vehicle").pose
    assert list(pose.translation) == pytest.approx([*START, TYRE], abs=1e-12)
    assert np.asarray(pose.rotation) == pytest.approx(rot(YAW), abs=1e-12)
    radar = sim.robot("robot").pose
    assert list(radar.translation) == pytest.approx(list(pose.translation + pose.rotation @ (FRONT + [0.11, 0, 0])),
                                                    abs=1e-12)
    assert radar.translation[2] == pytest.approx(0.5, abs=1e-12)


@pytest.mark.parametrize("slow, far", [((-55.0, 6.875), (-45.0, 3.9)),      # ahead; a car beside on the left
                                       ((-52.0, 8.5), (-48.0, 5.2)),       # ahead, off to the right; front left
                                       ((-46.5, 3.0), (-60.0, 10.0))])     # beside, left; ahead, right lane
def test_the_distance_sensors_read_the_cars_around_by_their_closed_forms(tmp_path: Path, slow, far) -> None:
    """With the two traffic cars placed around the still Lincoln, each distance sensor reads the mean of its two
    rays' distances to the nearest box face (each ray at most the sensor's range): the front one (0.3 m above
    the front slot), the first of each front side's three and the side ones (aperture 0.9), 1e-9 (float64
    rays)."""
    world = scene(HIGHWAY.read_text(), slow, far, tmp_path / "highway.wbt")
    sim = Simulation(load_world(world), "exact")
    devices = {n: sim.device("vehicle/distance sensor " + n) for n in SENSORS}
    for d in devices.values():
        d.enable(10)
    sim.step()
    car = np.asarray(sim.robot("vehicle").pose.translation, dtype=float)
    boxes = [np.array([*slow, 0.75]), np.array([*far, 0.75])]
    seen = 0
    for name, d in devices.items():
        want = sensor_closed_form(name, car, boxes)
        assert float(d.value) == pytest.approx(want, abs=1e-9), name
        seen += want < SENSORS[name][4]
    assert seen >= 1


def lidar_closed_form(car: np.ndarray, boxes: list[np.ndarray]) -> np.ndarray:
    """ibeo 1 (the stand-in's Lidar: 440 rays over 1.91986 rad, one layer) at (-0.225167, 0.71, 0) in the front
    slot turned 0.785398 rad: ray i (left to right) at azimuth fov/2 − (i + 0.5)·fov/440 from its x axis, each
    to the nearest box's faces within its 200 m (inf past them)."""
    r = rot(YAW)
    eye = car + r @ (FRONT + np.array([-0.225167, 0.71, 0.0]))
    fov = 1.91986
    out = np.full(440, math.inf)
    for i in range(440):
        a = 0.785398 + fov / 2 - (i + 0.5) * fov / 440
        d = r @ np.array([math.cos(a), math.sin(a), 0.0])
        out[i] = min(box_hit(eye, d, box) for box in boxes)
        out[i] = out[i] if out[i] <= 200.0 else math.inf
    return out


def test_the_front_lidar_reads_the_car_ahead_by_its_closed_form(tmp_path: Path) -> None:
    """The front-left-slot lidar ("ibeo 1", turned 45° to the car's left) sees the slow car 12.5 m ahead in the
    lane on 29 of its right-hand rays (from 13.83 m), two rays just left of it the far car 193.8 m off in the
    left lane, at their ray lengths (1e-4: float32 ranges), inf where the rays pass them."""
    world = scene(HIGHWAY.read_text(), (-60.0, 6.875), (-240.0, 3.2), tmp_path / "highway.wbt")
    sim = Simulation(load_world(world), "exact")
    lidar = sim.device("vehicle/ibeo 1")
    lidar.enable(10)
    sim.step()
    car = np.asarray(sim.robot("vehicle").pose.translation, dtype=float)
    want = lidar_closed_form(car, [np.array([-60.0, 6.875, 0.75]), np.array([-240.0, 3.2, 0.75])])
    got = np.asarray(lidar.range_image, dtype=float).reshape(-1)
    hit = np.isfinite(want)
    assert list(np.nonzero(hit)[0]) == [396, 397, *range(400, 429)]
    assert want[396] > 190.0 and 13.8 < want[400] < 14.0
    assert np.array_equal(np.isinf(got), ~hit)
    assert got[hit] == pytest.approx(want[hit], abs=1e-4)


def test_the_radar_riding_the_car_reads_the_slow_car_by_its_closed_form() -> None:
    """The radar robot riding the Lincoln at 80 km/h (its four wheels at 80/3.6/0.358 rad/s), the slow car 30 m
    ahead moving at 10 m/s along -x: one target (the far car beyond the 60 m range, the Lincoln, behind the
    radar, out of its view) at the box's centre's distance from the radar, its radial speed −12.222 m/s times
    the cosine to the line of sight (NaN at the first measurement, no earlier position), its azimuth atan of
    the 0.165 m lateral offset over the distance, positive: to the right (the stand-in leaves the sample's
    noise fields out)."""
    sim = Simulation(load_world(HIGHWAY), "exact")
    radar = sim.device("robot/radar")
    radar.enable(10)
    robot = sim.robot("vehicle")
    for name in ("right_front_wheel", "left_front_wheel", "right_rear_wheel", "left_rear_wheel"):
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(80 / 3.6 / TYRE)
    before = None
    for k in range(1, 11):
        slow = np.array([-70.0 - 10.0 * 0.01 * k, 6.875, 0.75])
        sim.set_solid_pose("vehicle(1)", slow.tolist())
        sim.step()
        pose = robot.pose
        eye = np.asarray(pose.translation) + np.asarray(pose.rotation) @ (FRONT + np.array([0.11, 0.0, 0.0]))
        assert list(sim.robot("robot").pose.translation) == pytest.approx(list(eye), abs=1e-12)
        rel = np.asarray(pose.rotation).T @ (slow - eye)
        (target,) = radar.targets
        assert target.distance == pytest.approx(float(np.linalg.norm(rel)), abs=1e-9)
        assert target.azimuth == pytest.approx(-math.atan2(rel[1], rel[0]), abs=1e-12)
        assert target.azimuth == pytest.approx(math.atan(0.165 / np.linalg.norm(rel)), abs=1e-5)
        if before is None:
            assert math.isnan(target.speed)
        else:
            closing = (slow - before[0]) / 0.01 - (eye - before[1]) / 0.01
            assert target.speed == pytest.approx(float(closing @ (slow - eye) / np.linalg.norm(slow - eye)), abs=1e-9)
            assert target.speed == pytest.approx(-(80 / 3.6 - 10.0), abs=1e-3)
        before = (slow, eye)


# our Python controllers: the traffic's Supervisor, and highway_overtake.py's calls in its order (only the
# prints are the test's)
TRAFFIC = '''"""Sensorium's stand-in for SUMO's traffic (sweep 30): moves each named car (DEF, then m/s) along -x at its
constant speed from where the world puts it."""
import sys

from controller import Supervisor

robot = Supervisor()
step = int(robot.getBasicTimeStep())
args = sys.argv[1:]
cars = []
for k in range(0, len(args), 2):
    field = robot.getFromDef(args[k]).getField("translation")
    cars.append((field, list(field.getSFVec3f()), float(args[k + 1])))
while robot.step(step) != -1:
    t = robot.getTime()
    for field, start, speed in cars:
        field.setSFVec3f([start[0] - speed * t, start[1], start[2]])
'''

RADAR_TARGET_TRACKER = '''"""Sensorium's stand-in for radar_target_tracker.c (sweep 30): our own Python making its calls in its order
(the radar enabled at 10 ms, 25 marker Transforms imported into its own children, each found as the last child
with its translation and its material's diffuseColor, hidden from the named lidars and camera; each step each
marker moved to its target, in the robot's frame, and coloured by its power, or parked 10 m up). The markers'
box size set is left out (a Box's size is read-only here, one line). Each step it prints the targets it read,
then its own position and its first marker's."""
import math

from controller import Supervisor

MAX_TARGETS = 25
TARGET = ("Transform {\\n  translation 0 0 10.0\\n  children [\\n    Shape {\\n      appearance Appearance {\\n"
          "        material Material {\\n          diffuseColor 0.8 0 0.0117647\\n          transparency 0.7\\n"
          "        }\\n      }\\n      geometry Box {\\n        size 5.0 2.5 2.0\\n      }\\n    }\\n  ]\\n}\\n")
robot = Supervisor()
radar = robot.getDevice("radar")
radar.enable(10)
children = robot.getSelf().getField("children")
translations, colors, markers = [], [], []
for i in range(MAX_TARGETS):
    children.importMFNodeFromString(-1, TARGET)
    node = children.getMFNode(-1)
    markers.append(node)
    translations.append(node.getField("translation"))
    shape = node.getField("children").getMFNode(0)
    material = shape.getField("appearance").getSFNode().getField("material").getSFNode()
    colors.append(material.getField("diffuseColor"))
    for name in ("FRONT_RIGHT_LIDAR", "FRONT_LEFT_LIDAR", "REAR_RIGHT_LIDAR", "REAR_LEFT_LIDAR", "TOP_CAMERA"):
        viewer = robot.getFromDef(name)
        if viewer is not None:
            node.setVisibility(viewer, False)
print("children", children.getCount(), flush=True)
while robot.step(10) != -1:
    targets = radar.getTargets()
    n = radar.getNumberOfTargets()
    for i in range(MAX_TARGETS):
        if 0 < i < n and targets[i].distance > 2.0:
            d = targets[i].distance
            translations[i].setSFVec3f([d, -d * math.sin(targets[i].azimuth), -0.5])
            factor = max(min((targets[i].received_power + 60.0) / 50.0, 1.0), 0.0) ** 0.33
            colors[i].setSFColor([factor, 0.0, 1.0 - factor])
        else:
            translations[i].setSFVec3f([0.0, 0.0, 10.0])
    print(round(robot.getTime() * 1000), n,
          " ".join(f"{t.distance!r} {t.speed!r} {t.azimuth!r}" for t in targets), flush=True)
    print("at", *(repr(v) for v in robot.getSelf().getPosition()), *(repr(v) for v in markers[0].getPosition()),
          flush=True)
'''

HIGHWAY_OVERTAKE = '''"""Sensorium's stand-in for highway_overtake.py (sweep 30): our own Python making its calls in its order (the
twelve distance sensors and the GPS enabled at 10 ms, the camera fetched; each step the speed from the front
sensor, the overtaking decision from the side ones, the lane PID on the GPS's y); each step prints what it
read and sent."""
from vehicle import Driver

NAMES = ["front", "front right 0", "front right 1", "front right 2", "front left 0", "front left 1",
         "front left 2", "rear", "rear left", "rear right", "right", "left"]
LANES = [10.6, 6.875, 3.2]
MAX_SPEED = 80
lane, side, safe = 1, None, False
integral, previous = 0.0, None
speeds = []


def pid(position, target):
    global integral, previous
    diff = position - target
    if previous is None:
        previous = diff
    if (diff > 0 > previous) or (diff < 0 < previous):
        integral = 0.0
    integral += diff
    out = 0.05 * diff + 0.000015 * integral + 25 * (diff - previous)
    previous = diff
    return out


def filtered(speed):
    speeds.append(speed)
    if len(speeds) > 100:
        speeds.pop(0)
    return sum(speeds) / len(speeds)


driver = Driver()
sensors = {}
for name in NAMES:
    sensors[name] = driver.getDevice("distance sensor " + name)
    sensors[name].enable(10)
gps = driver.getDevice("gps")
gps.enable(10)
camera = driver.getDevice("camera")


def free(name):
    return sensors[name].getValue() > 0.8 * sensors[name].getMaxValue()


while driver.step() != -1:
    front, front_range = sensors["front"].getValue(), sensors["front"].getMaxValue()
    speed = MAX_SPEED * front / front_range
    if sensors["front right 0"].getValue() < 8.0 or sensors["front left 0"].getValue() < 8.0:
        speed = min(0.5 * MAX_SPEED, speed)
    if side is not None:
        if side == "right" and not free("left"):
            side, lane = None, lane - 1
        elif side == "left" and not free("right"):
            side, lane = None, lane + 1
        else:
            ratio = min([1.0] + [sensors[f"front {side} {i}"].getValue() / sensors[f"front {side} {i}"].getMaxValue()
                                 for i in range(3)])
            speed = min(speed, ratio * speed)
    speed = filtered(speed)
    driver.setCruisingSpeed(speed)
    diff = driver.getCurrentSpeed() - speed
    driver.setBrakeIntensity(min(diff / speed, 1) if diff > 0 else 0)
    if front < 0.8 * front_range and side is None:
        if any(free(f"front left {i}") for i in range(3)) and (not safe or free("rear left")) and free("left") \\
                and lane < 2:
            lane, side = lane + 1, "right"
        elif any(free(f"front right {i}") for i in range(3)) and (not safe or free("rear right")) \\
                and free("right") and lane > 0:
            lane, side = lane - 1, "left"
    position = gps.getValues()[1]
    angle = max(min(pid(position, LANES[lane]), 0.5), -0.5)
    driver.setSteeringAngle(-angle)
    if abs(position - LANES[lane]) < 1.5:
        side = None
    values = " ".join(repr(sensors[n].getValue()) for n in NAMES)
    print(f"{round(driver.getTime() * 1000)} {lane} {side} {speed!r} {driver.getCurrentSpeed()!r} {-angle!r} "
          f"{gps.getValues()[0]!r} {position!r} {driver.getSteeringAngle()!r} {values}", flush=True)
'''


@pytest.mark.slow
def test_highway_overtakes_calls_change_lane_past_the_slow_car(tmp_path: Path) -> None:
    """Our Python controller making highway_overtake.py's calls under ``sensorium run`` for 3 s, the slow car
    placed 11.76 m ahead of the front sensor (its centre at x −58) and moving at 10 m/s, the far car at 20 m/s
    in the left lane 200 m on. At 10 ms the front sensor reads its closed form (the car still, the traffic not
    yet moved), the controller cruises at 80 · 11.76 / 20 km/h, decides to overtake on the left (lane 2, the
    slow car on its right: the front-left sensors and the left one free) and steers −(0.05 + 1.5e-5)·(y − 3.2)
    on the GPS's y; the lane stays 2 and the overtaking ends (|y − 3.2| < 1.5) once, at the first step the GPS
    is below y 4.7, the car then 80 km/h with nothing ahead. Each step getCurrentSpeed is the cruising speed
    just set (1e-9; the kinematic car reaches it at once). The PID's derivative (25 per step) on the GPS 5.03 m
    ahead of the rear axle swings the steering sent between left and right every step: the bicycle model turns
    the car at once, where Webots' tyres and inertia smooth it (docs/webots-samples.md, sweep 30)."""
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "highway_overtake.wbt"
    world.write_text(HIGHWAY.read_text().replace("translation -70 6.875 0.75", "translation -58 6.875 0.75"))
    for name, text in (("highway_overtake", HIGHWAY_OVERTAKE), ("traffic", TRAFFIC),
                       ("radar_target_tracker", RADAR_TARGET_TRACKER)):
        folder = tmp_path / "controllers" / name
        folder.mkdir(parents=True)
        (folder / f"{name}.py").write_text(text)
    done = subprocess.run(sensorium("run", str(world), "--until", "3000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "exited with status" not in done.stderr and "not simulated" not in done.stderr, done.stderr
    rows = [line.split("] ", 1)[1].split() for line in done.stdout.splitlines() if line.startswith("[vehicle] ")]
    lines = [line.split("] ", 1)[1].split() for line in done.stdout.splitlines() if line.startswith("[robot] ")]
    radar = [r for r in lines if r[0] != "at"]
    assert radar[0] == ["children", "26"] and [int(r[0]) for r in radar[1:]] == list(range(10, 3001, 10))
    # its markers ride it: the first (one target: every marker parked) 10 m above the radar robot, as it drives
    rides = [[float(v) for v in r[1:]] for r in lines if r[0] == "at"]
    assert len(rides) == 300 and math.dist(rides[-1][:2], rides[0][:2]) > 50.0
    for r in rides:
        assert r[3:] == pytest.approx([r[0], r[1], r[2] + 10.0], abs=1e-9)
    assert [int(r[0]) for r in rows] == list(range(10, 3001, 10))
    first = rows[0]
    front = float(first[9])
    boxes = [np.array([-58.0, 6.875, 0.75]), np.array([-240.0, 3.2, 0.75])]
    assert front == pytest.approx(sensor_closed_form("front", np.array([*START, TYRE]), boxes), abs=1e-9)
    assert front == pytest.approx(11.7607, abs=1e-4)
    assert (first[1], first[2]) == ("2", "right")
    assert float(first[3]) == 80.0 * front / 20.0
    y = float(first[7])
    assert y == pytest.approx(START[1] + 5.03 * math.sin(YAW), abs=1e-12)
    assert float(first[5]) == pytest.approx(-(0.05 * (y - 3.2) + 0.000015 * (y - 3.2)), abs=1e-12)
    for r in rows:
        assert float(r[4]) == pytest.approx(float(r[3]), abs=1e-9), r[0]
        assert r[1] == "2", r[0]
    over = next(k for k, r in enumerate(rows) if abs(float(r[7]) - 3.2) < 1.5)
    assert all(r[2] == "right" for r in rows[:over]) and all(r[2] == "None" for r in rows[over:])
    assert 1.0 < over * 0.01 < 2.0
    assert all(float(r[9]) == 20.0 for r in rows[over:]) and float(rows[-1][3]) == 80.0
    sent = [float(r[5]) for r in rows[:100]]
    assert all(a * b < 0.0 for a, b in zip(sent, sent[1:]))
    # the radar riding the car: the slow car its one target while ahead (its centre 13.96 m off at load), closing
    # at the car's speed less 10 m/s
    # (1 m/s: the traffic's and the car's moves a step apart); lost from view as the car draws level
    for k in range(2, 20):
        n, distance, speed, azimuth = int(radar[k][1]), *(float(v) for v in radar[k][2:5])
        assert n == 1 and 12.5 < distance < 14.5 and abs(azimuth) < 0.45
        assert speed == pytest.approx(-(float(rows[k - 2][4]) / 3.6 - 10.0), abs=1.0)
    assert any(int(r[1]) == 0 for r in radar[over // 2:])
