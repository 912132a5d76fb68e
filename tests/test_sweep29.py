"""Sweep 29: Webots' `projects/vehicles` city sample not run before, on a stand-in world of ours
(tests/data/sweep29/: the BmwX5's Car geometry, joints and device names and the sample's sensors where it
puts them, our own text; roads, buildings and traffic stood in for by plain shapes) driven by the calls its
controller makes and checked against closed forms."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_sweep19 import KinematicMotor

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

REPO = Path(__file__).resolve().parent.parent
DATA = Path(__file__).parent / "data" / "sweep29"
CITY = DATA / "city.wbt"

# ------------------------------------------------------------------------------------------------- city
# city (projects/vehicles, R2023b): the BmwX5 (a traction Car: wheelbase 2.995 m, tracks 1.628 m, wheels of
# radius 0.374 m, the rear axle's centre its origin) at (−45, 45.88, 0.4) turned 3.14159 rad about z, facing −x;
# its SICK LMS 291 in the front slot (3.85, 0, 0.45) + (0.06, 0, 0): 180 rays over π to 80 m, one layer; its
# camera in the top slot (1, 0, 1.45) + (0.72, 0, −0.05): 128 × 64, fov 1; GPS, gyro and a 200 × 150 display at
# its origin. autonomous_vehicle.c: 10 ms steps, the sensors read every 50 ms; a pixel is the road's yellow when
# its BGR is within 30 (summed) of (95, 187, 203); the line's angle (mean column / width − 0.5) · fov; a SICK
# obstacle is a ray below 20 m among the middle 40, its angle (mean index / 180 − 0.5) · fov.
HEADING = 3.14159
START = (-45.0, 45.88)
TYRE = 0.374
CAMERA = (1.72, 0.0, 1.40)            # in the car's frame
SICK = (3.91, 0.0, 0.45)
LINE_Z, LINE_Y, LINE_HALF = 0.002, (45.1, 44.9), 0.05      # the two yellow strips' centres and half width
BOX_LO, BOX_HI = np.array([-62.0, 45.5, 0.0]), np.array([-60.0, 47.5, 1.5])   # the obstacle
YELLOW = np.array([95, 187, 203])


def car_frame(translation) -> tuple[np.ndarray, np.ndarray]:
    c, s = math.cos(HEADING), math.sin(HEADING)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.asarray(translation, dtype=float)


def box_hit(origin: np.ndarray, d: np.ndarray) -> float:
    """The ray's parameter where it enters the obstacle box, inf if it misses (slabs)."""
    lo, hi = -math.inf, math.inf
    for k in range(3):
        if d[k] == 0.0:
            if not BOX_LO[k] <= origin[k] <= BOX_HI[k]:
                return math.inf
            continue
        a, b = (BOX_LO[k] - origin[k]) / d[k], (BOX_HI[k] - origin[k]) / d[k]
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    return lo if lo <= hi and hi > 0.0 else math.inf


def yellow_mask(translation) -> np.ndarray:
    """The pixels whose centre's ray meets a yellow strip before anything else: the camera's pinhole at the
    car's (1.72, 0, 1.40), looking along the car's x, f = 64 / tan 0.5."""
    r, t = car_frame(translation)
    eye = t + r @ np.array(CAMERA)
    f = 64.0 / math.tan(0.5)
    mask = np.zeros((64, 128), dtype=bool)
    for v in range(64):
        for u in range(128):
            d = r @ np.array([f, 64.0 - (u + 0.5), 32.0 - (v + 0.5)])
            if d[2] >= 0.0:
                continue
            s = (LINE_Z - eye[2]) / d[2]
            p = eye + s * d
            mask[v, u] = any(abs(p[1] - y) <= LINE_HALF for y in LINE_Y) and box_hit(eye, d) > s
    return mask


def line_angle(mask: np.ndarray) -> float:
    """autonomous_vehicle.c's process_camera_image over a mask of yellow pixels (99999.99: none)."""
    vs, us = np.nonzero(mask)
    return (int(us.sum()) / len(us) / 128 - 0.5) * 1.0 if len(us) else 99999.99


def sick_closed_form(translation) -> np.ndarray:
    """Each of the 180 rays (left to right, azimuth π/2 − (i + 0.5)·π/180 from the car's x, horizontal from
    the SICK) to the box's face at x −60, inf where it passes beside the box."""
    r, t = car_frame(translation)
    eye = t + r @ np.array(SICK)
    out = np.full(180, math.inf)
    for i in range(180):
        a = 3.14159 / 2 - (i + 0.5) * 3.14159 / 180
        d = r @ np.array([math.cos(a), math.sin(a), 0.0])
        out[i] = box_hit(eye, d)
    return out


def sick_obstacle(ranges) -> tuple[float, float]:
    """autonomous_vehicle.c's process_sick_data: (angle, mean distance) of the middle 40 rays below 20 m."""
    hits = [(x, float(ranges[x])) for x in range(70, 110) if ranges[x] < 20.0]
    if not hits:
        return 99999.99, 0.0
    return ((sum(x for x, _ in hits) / len(hits) / 180 - 0.5) * 3.14159, sum(d for _, d in hits) / len(hits))


def test_the_bmw_loads_as_a_traction_car_its_fittings_moving_as_joints() -> None:
    """The BmwX5 loads with the 37 devices Webots' car and driver libraries and the controller look for, in
    one line: its seven interior motors (two wipers, the central mirror's two, the steering wheel, the speed and
    rpm needles) are joints, no wheels; the car is a traction Ackermann drive of Webots' Car geometry (its rear
    wheels' encoders free wheels), and it lands on its wheels at z 0.374 (the tyre's radius) from the world's
    0.4, its heading kept."""
    w = load_world(CITY)
    (said,) = w.warnings
    assert said.endswith("robot 'vehicle': its 7 motorised joints are no wheels (1 steering none; 6 a car's fittings): "
                         "they move kinematically (Webots' rule without physics; their PositionSensors read them), and "
                         "the shapes and devices past each joint with it ('rear_yaw_mirror_frame_motor', "
                         "'right_wiper_motor', 'left_wiper_motor', 'rear_pitch_mirror_frame_motor' and 3 more)")
    (robot,) = w.world.robots
    names = {d.name for d in robot.devices}
    assert len(names) == 37 and {"Sick LMS 291", "camera", "gps", "gyro", "display", "engine_speaker",
                                 "steering_wheel_motor", "speed_needle_motor", "right_wiper_motor",
                                 "wiper_sensor", "right_rear_sensor", "left_front_brake"} <= names
    car = robot.ackermann_drive
    assert (car.type, car.wheelbase, car.track_front, car.track_rear) == ("traction", 2.995, 1.628, 1.628)
    assert (car.front_wheel_radius, car.rear_wheel_radius, car.positive_steers) == (TYRE, TYRE, "right")
    assert (car.right_steer, car.left_front_wheel) == ("right_steer", "left_front_wheel")
    free = {d.name: d.free_wheel for d in robot.devices if getattr(d, "free_wheel", None)}
    assert free == {"right_rear_sensor": "right_rear", "left_rear_sensor": "left_rear"}
    sim = Simulation(w, "exact")
    pose = sim.robot("vehicle").pose
    assert list(pose.translation) == pytest.approx([*START, TYRE], abs=1e-12)
    r, _ = car_frame(pose.translation)
    assert np.asarray(pose.rotation) == pytest.approx(r, abs=1e-12)


def test_the_camera_sees_the_yellow_line_where_its_pinhole_puts_it() -> None:
    """The controller's yellow pixels (BGR within 30 of its reference) are exactly those whose centre's ray
    meets a strip of the double line, 0.88 m to the car's left, before the obstacle box (57 less the 3 the box
    hides), and its line angle is the closed form's mask's, −0.0897 rad (left), with the car still at load."""
    sim = Simulation(load_world(CITY), "exact")
    camera = sim.device("vehicle/camera")
    camera.enable(50)
    assert (camera.config.width, camera.config.height, camera.fov) == (128, 64, 1.0)
    for _ in range(5):
        sim.step()
    image = np.asarray(camera.image).astype(int)
    seen = np.abs(image[..., :3] - YELLOW).sum(axis=-1) < 30
    expected = yellow_mask(sim.robot("vehicle").pose.translation)
    assert int(expected.sum()) == 54
    assert np.array_equal(seen, expected)
    assert line_angle(seen) == pytest.approx(line_angle(expected), abs=0.0)
    assert line_angle(seen) == pytest.approx(-0.0897, abs=1e-4)


def test_the_sick_reads_the_obstacle_box_by_its_closed_form() -> None:
    """The SICK LMS 291, 0.824 m up, 11.09 m from the box's face: rays 88 to 97 (of 180, left to right) read the
    face at 11.09 / cos(azimuth) (1e-6, the lidar's float32), the others inf; the controller's obstacle is at
    (92.5 / 180 − 0.5) · π = 0.04363 rad (right) and 11.12 m."""
    sim = Simulation(load_world(CITY), "exact")
    sick = sim.device("vehicle/Sick LMS 291")
    sick.enable(50)
    assert (sick.config.horizontal_resolution, sick.config.max_range) == (180, 80.0)
    for _ in range(5):
        sim.step()
    got = np.asarray(sick.range_image, dtype=float).reshape(-1)
    want = sick_closed_form(sim.robot("vehicle").pose.translation)
    assert list(np.nonzero(np.isfinite(want))[0]) == list(range(88, 98))
    assert np.array_equal(np.isinf(got), np.isinf(want))
    assert got[np.isfinite(want)] == pytest.approx(want[np.isfinite(want)], abs=1e-5)
    angle, dist = sick_obstacle(got)
    assert angle == pytest.approx((92.5 / 180 - 0.5) * 3.14159, abs=1e-12)
    assert dist == pytest.approx(float(np.mean(want[88:98])), abs=1e-5)


# ------------------------------------------------------------------------------------------- city_night
# city_night (projects/vehicles, R2023b): the same BmwX5 and place with `frontSpotLights TRUE`: two SpotLights
# (intensity 20, attenuation 0 0 1, cutOffAngle 0.8, radius 20, directions (1, ∓0.2, −1) from (3.95, ±0.65,
# 0.45)) in a Group, the first child of its "front_lights" LED, which the driver library's dipped beams switch;
# the camera turned 0.15 rad down, no SICK, a near-black sky (0.00784), no other light (the street lights left
# out). autonomous_vehicle.c switches the dipped beams on before its first step.
NIGHT = DATA / "city_night.wbt"
SPOTS = (((3.95, 0.65, 0.45), (1.0, -0.2, -1.0)), ((3.95, -0.65, 0.45), (1.0, 0.2, -1.0)))
BODY = (((2.6775, 0.0, 0.29), (2.0, 1.73, 0.76)), ((0.5875, 0.0, 0.63), (2.14, 1.73, 1.44)),
        ((-0.1725, 0.0, 0.53), (1.41, 1.73, 0.78)))


def night_lit(pose, camera_pose) -> dict[tuple[int, int], bool]:
    """For each pixel whose centre's ray meets the floor (within its 1000 m) before the car's body: whether the
    road there is within 0.8 rad of a headlight's axis and 20 m of it (lit) or not (dark)."""
    r, t = np.asarray(pose.rotation), np.asarray(pose.translation)
    rc, eye = np.asarray(camera_pose.rotation), np.asarray(camera_pose.translation)
    lights = [(t + r @ np.array(p), r @ (np.array(d) / np.linalg.norm(d))) for p, d in SPOTS]

    def body_hit(d: np.ndarray) -> float:
        best = math.inf
        for centre, size in BODY:
            o, e, h = r.T @ (eye - t) - np.array(centre), r.T @ d, np.array(size) / 2.0
            lo, hi = -math.inf, math.inf
            for k in range(3):
                a, b = (-h[k] - o[k]) / e[k], (h[k] - o[k]) / e[k]
                lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
            if lo <= hi and hi > 0.0:
                best = min(best, lo)
        return best

    f = 64.0 / math.tan(0.5)
    out = {}
    for v in range(64):
        for u in range(128):
            d = rc @ np.array([f, 64.0 - (u + 0.5), 32.0 - (v + 0.5)])
            if d[2] >= 0.0:
                continue
            s = (0.001 - eye[2]) / d[2]
            p = eye + s * d
            if max(abs(p[0]), abs(p[1])) > 1000.0 or body_hit(d) < s:
                continue
            out[(v, u)] = any(np.linalg.norm(p - q) <= 20.0 and
                              math.acos(float(np.dot((p - q) / np.linalg.norm(p - q), a))) <= 0.8 for q, a in lights)
    return out


def test_the_headlights_light_their_cones_only_while_the_dipped_beams_are_on() -> None:
    """city_night's BmwX5: with its front_lights LED off (as loaded, before the controller's dipped beams) every
    floor pixel is black; on, a floor pixel shows exactly where its point is within a headlight's cone (0.8 rad)
    and reach (20 m): 3880 of them, the hood hiding the rest below; off again, black. The yellow line in the
    beams renders dimmer than the controller's reference (none within 30), so autonomous_vehicle.c sees no line
    here and brakes (0.4), as the stand-in has none of the sample's street lights."""
    w = load_world(NIGHT)
    joints, background = w.warnings
    assert "its 7 motorised joints are no wheels" in joints
    assert background.endswith("skipped nodes that do not matter to these sensors: Background (all but its skyColor)")
    sim = Simulation(w, "exact")
    camera, led = sim.device("vehicle/camera"), sim.device("vehicle/front_lights")
    camera.enable(10)
    pose = sim.robot("vehicle").pose
    lit = night_lit(pose, camera.world_pose(pose))
    assert sum(lit.values()) == 3880
    for on in (0, 1, 0):
        led.set(on, sim.time_ms)
        sim.step()
        image = np.asarray(camera.image).astype(int)
        shown = {k: bool(image[k][:3].max() > 0) for k in lit}
        assert shown == ({k: False for k in lit} if on == 0 else lit), on
        assert not (np.abs(image[..., :3] - YELLOW).sum(axis=-1) < 30).any()


# our Python controller making autonomous_vehicle.c's calls in its order (only the prints are the test's)
AUTONOMOUS_VEHICLE = '''"""Sensorium's stand-in for autonomous_vehicle.c (sweep 29): our own Python making its calls in its order
(the Driver, the device scan by index, camera, SICK, GPS, display and keyboard, the yellow-line PID and the
SICK's obstacle steering every 50 ms); each sensor cycle prints what it read and sent."""
import math

from vehicle import Driver

TIME_STEP = 50
UNKNOWN = 99999.99
KP, KI, KD = 0.25, 0.006, 2.0
REF = (95, 187, 203)

driver = Driver()
names = [driver.getDeviceByIndex(j).getName() for j in range(driver.getNumberOfDevices())]
camera = driver.getDevice("camera")
camera.enable(TIME_STEP)
width, height, fov = camera.getWidth(), camera.getHeight(), camera.getFov()
sick = driver.getDevice("Sick LMS 291")
sick.enable(TIME_STEP)
sick_width, sick_fov = sick.getHorizontalResolution(), sick.getFov()
gps = driver.getDevice("gps")
gps.enable(TIME_STEP)
display = driver.getDevice("display")
speedometer = display.imageLoad("speedometer.png")
wheel, needle = driver.getDevice("steering_wheel_motor"), driver.getDevice("speed_needle_motor")
wiper = driver.getDevice("wiper_sensor")
print("devices", len(names), "Sick LMS 291" in names, "display" in names, width, height, fov, sick_width,
      f"{sick_fov:.5f}", flush=True)
driver.setCruisingSpeed(50.0)
driver.setHazardFlashers(True)
driver.setDippedBeams(True)
driver.setAntifogLights(True)
driver.setWiperMode(Driver.SLOW)
driver.getKeyboard().enable(TIME_STEP)

steering_angle = 0.0
sent = 0.0
old = [0.0, 0.0, 0.0]
first = True
pid_reset = False
pid_old, integral = 0.0, 0.0


def set_steering_angle(a):
    global steering_angle, sent
    a = min(max(a, steering_angle - 0.1), steering_angle + 0.1)
    steering_angle = a
    sent = min(max(a, -0.5), 0.5)
    driver.setSteeringAngle(sent)


def line_angle(image):
    sumx, count = 0, 0
    for k in range(width * height):
        b, g, r = image[4 * k], image[4 * k + 1], image[4 * k + 2]
        if abs(b - REF[0]) + abs(g - REF[1]) + abs(r - REF[2]) < 30:
            sumx += k % width
            count += 1
    return UNKNOWN if count == 0 else (sumx / count / width - 0.5) * fov


def filtered(value):
    global first, old
    if first or value == UNKNOWN:
        first = False
        old = [0.0, 0.0, 0.0]
    else:
        old = old[1:] + [0.0]
    if value == UNKNOWN:
        return UNKNOWN
    old[2] = value
    return sum(old) / 3


def obstacle(ranges):
    hits = [(x, ranges[x]) for x in range(sick_width // 2 - 20, sick_width // 2 + 20) if ranges[x] < 20.0]
    if not hits:
        return UNKNOWN, 0.0
    return (sum(x for x, _ in hits) / len(hits) / sick_width - 0.5) * sick_fov, sum(d for _, d in hits) / len(hits)


def cdiv(a, b):
    """a / b as C divides doubles (b == 0: an infinity or NaN)."""
    if b != 0.0:
        return a / b
    return math.nan if a == 0.0 else math.copysign(math.inf, a) * math.copysign(1.0, b)


def pid(a):
    global pid_reset, pid_old, integral
    if pid_reset:
        pid_old, integral, pid_reset = a, 0.0, False
    if math.copysign(1, a) != math.copysign(1, pid_old):
        integral = 0.0
    diff = a - pid_old
    if -30 < integral < 30:
        integral += a
    pid_old = a
    return KP * a + KI * integral + KD * diff


i = 0
while driver.step() != -1:
    driver.getKeyboard().getKey()
    wiper_at = wiper.getValue()
    if i % (TIME_STEP // int(driver.getBasicTimeStep())) == 0:
        image = camera.getImage()
        ranges = sick.getRangeImage()
        yellow = filtered(line_angle(image))
        ob_angle, ob_dist = obstacle(ranges)
        brake = 0.0
        if ob_angle != UNKNOWN:
            ob_steer = steering_angle
            if 0.0 < ob_angle < 0.4:
                ob_steer = steering_angle + cdiv(ob_angle - 0.25, ob_dist)
            elif ob_angle > -0.4:
                ob_steer = steering_angle + cdiv(ob_angle + 0.25, ob_dist)
            steer = steering_angle
            if yellow != UNKNOWN:
                line = pid(yellow)
                if ob_steer > 0 and line > 0:
                    steer = max(ob_steer, line)
                elif ob_steer < 0 and line < 0:
                    steer = min(ob_steer, line)
            else:
                pid_reset = True
            set_steering_angle(steer)
        elif yellow != UNKNOWN:
            set_steering_angle(pid(yellow))
        else:
            brake = 0.4
            pid_reset = True
        driver.setBrakeIntensity(brake)
        coords = gps.getValues()
        gps_speed = gps.getSpeed() * 3.6
        speed = driver.getCurrentSpeed()
        display.imagePaste(speedometer, 0, 0, False)
        alpha = speed / 260.0 * 3.72 - 0.27
        display.drawLine(100, 95, 100 + int(-50 * math.cos(alpha)), 95 + int(-50 * math.sin(alpha)))
        display.drawText(f"GPS coords: {coords[0]:.1f} {coords[1]:.1f}", 10, 130)
        display.drawText(f"GPS speed:  {gps_speed:.1f}", 10, 140)
        t = round(driver.getTime() * 1000)
        if t == 1010:
            display.imageSave(None, "display.png")
        print(f"{t} {yellow!r} {ob_angle!r} {ob_dist!r} {sent!r} {brake} {coords[0]!r} {coords[1]!r} {gps_speed!r} "
              f"{speed!r} {wheel.getTargetPosition()!r} {needle.getTargetPosition()!r} {wiper_at!r}", flush=True)
    else:
        print(f"w {round(driver.getTime() * 1000)} {wiper_at!r}", flush=True)
    i += 1
'''


def wiper_closed_form(steps: int) -> list[float]:
    """The wiper sensor after each 10 ms step under Webots' driver library in SLOW mode: before each step, at
    its minPosition 0 both wipers go up to 1.6, at 1.6 (or in a second t with int(t) % 4 != 0) down to 0; the
    motors (maxVelocity 10, maxTorque 10: 10 rad/s² as their acceleration) follow Webots' kinematic rule; the
    sensor reads nothing (NaN) before the first step."""
    motor, read, out = KinematicMotor(10.0, 10.0), math.nan, []
    for k in range(steps):
        t = k * 0.01
        if read == 0.0:
            motor.target = 1.6
        if read == 1.6 or int(t) % 4 != 0:
            motor.target = 0.0
        motor.step(0.01)
        read = motor.x
        out.append(read)
    return out


@pytest.mark.slow
def test_autonomous_vehicles_calls_follow_the_line_avoid_the_box_and_turn_the_interior(tmp_path: Path) -> None:
    """Our Python controller making autonomous_vehicle.c's calls under ``sensorium run`` for 2 s: it finds the
    37 devices by index, the SICK and the display; 50 km/h from the first step (wheel accelerations are not
    simulated). At 60 ms, the first images (taken at 50 ms, the car 0.6944 m on, straight): the line angle is a
    third of the closed-form mask's (the filter's zeros), the obstacle the closed form's, and the controller
    steers min(its PID, (angle − 0.25) / distance) (1e-5: the SICK's float32); it steers left past the box and
    loses it from the SICK's middle rays at 560 ms. Each cycle Webots' library turns the steering wheel to 10 ×
    the angle sent and the speed needle to 50 · 4.42 / 220; the wiper sensor follows the library's SLOW sweep
    step by step (1e-12). The display saved at 1.01 s shows our speedometer image with the needle's line from
    (100, 95) to (55, 74) in white."""
    from PIL import Image

    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "city.wbt"
    world.write_text(CITY.read_text())
    folder = tmp_path / "controllers" / "autonomous_vehicle"
    folder.mkdir(parents=True)
    (folder / "autonomous_vehicle.py").write_text(AUTONOMOUS_VEHICLE)
    Image.new("RGB", (200, 150), (40, 60, 80)).save(folder / "speedometer.png")     # ours, a plain dial
    done = subprocess.run(sensorium("run", str(world), "--until", "2000", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "exited with status" not in done.stderr and "not simulated" not in done.stderr, done.stderr
    lines = [line.split("] ", 1)[1] for line in done.stdout.splitlines() if line.startswith("[vehicle] ")]
    assert lines[0] == "devices 37 True True 128 64 1.0 180 3.14159"
    wipers = wiper_closed_form(200)
    cycles = []
    for line in lines[1:]:
        cols = line.split()
        if cols[0] == "w":
            t, at = int(cols[1]), float(cols[2])
        else:
            t, at = int(cols[0]), float(cols[12])
            cycles.append([float(c) for c in cols[:12]])
        assert at == pytest.approx(wipers[t // 10 - 1], abs=1e-12), t
    assert [int(c[0]) for c in cycles] == list(range(10, 2000, 50))
    for c in cycles:
        sent, speed, wheel, needle = c[4], c[9], c[10], c[11]
        assert wheel == pytest.approx(10.0 * sent, abs=1e-15) and speed == pytest.approx(50.0, abs=1e-9)
        assert needle == pytest.approx(50.0 * 4.42 / 220.0, abs=1e-12)
    first = cycles[1]
    assert (first[6], first[7]) == pytest.approx((START[0] - 50 / 3.6 * 0.05, START[1] + 50 / 3.6 * 0.05 *
                                                  math.sin(HEADING)), abs=1e-9)
    pose = (first[6], first[7], TYRE)
    assert first[1] == pytest.approx(line_angle(yellow_mask(pose)) / 3.0, abs=1e-12)
    angle, dist = sick_obstacle(sick_closed_form(pose))
    assert (first[2], first[3]) == pytest.approx((angle, dist), abs=1e-5)
    line = 0.25 * first[1] + 0.006 * first[1]          # the PID's first value after its reset
    assert first[4] == pytest.approx(min((angle - 0.25) / dist, line), abs=1e-5)
    seen = [int(c[0]) for c in cycles if c[2] != 99999.99]
    assert seen[0] == 10 and seen[-1] == 510 and all(c[2] == 99999.99 for c in cycles if c[0] > 510)
    assert all(c[7] < 45.5 for c in cycles if -62.0 - 3.91 < c[6] < -60.0 + 1.0)      # past the box, to its left
    shown = Image.open(folder / "display.png").convert("RGB")
    assert shown.size == (200, 150)
    for xy in ((100, 95), (55, 74), (77, 84)):
        assert shown.getpixel(xy) == (255, 255, 255), xy
    for xy in ((0, 0), (150, 20), (199, 149)):
        assert shown.getpixel(xy) == (40, 60, 80), xy


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


@pytest.mark.slow
def test_the_c_driver_library_turns_the_interior_as_webots_library_does(tmp_path: Path, clib) -> None:
    """A C controller built against our libController: without $WEBOTS_HOME, ours (tests/c/car_interior.c)
    making autonomous_vehicle.c's library calls for 1.5 s: the wiper mode kept (SLOW, 1, by both names), the
    steering wheel at 0 then 10 × −0.05 from the 20th step, the speed needle at 50 · 4.42 / 220 from the first,
    the wiper sensor the library's SLOW sweep (1e-12), as the Python library's. With it, Webots'
    autonomous_vehicle.c itself runs 1.5 s and says it set 50 km/h, no line of ours refusing a call."""
    build, libs = clib
    (tmp_path / "worlds").mkdir()
    shutil.copytree(DATA / "protos", tmp_path / "worlds" / "protos")
    world = tmp_path / "worlds" / "city.wbt"
    world.write_text(CITY.read_text())
    folder = tmp_path / "controllers" / "autonomous_vehicle"
    home = os.environ.get("WEBOTS_HOME")
    webots = home is not None and (Path(home) / "projects" / "vehicles" / "controllers" / "autonomous_vehicle").is_dir()
    if webots:
        shutil.copytree(Path(home) / "projects" / "vehicles" / "controllers" / "autonomous_vehicle", folder)  # type: ignore[arg-type]
    else:
        folder.mkdir(parents=True)
        shutil.copy(REPO / "tests" / "c" / "car_interior.c", folder / "autonomous_vehicle.c")
    done = subprocess.run(["cc", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", str(folder / "autonomous_vehicle.c"),
                           "-o", str(folder / "autonomous_vehicle"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    done = subprocess.run(sensorium("run", str(world), "--until", "1500", "--rpc", "tcp://127.0.0.1:0",
                                    "--pub", "tcp://127.0.0.1:0"),
                          env=child_env(), cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "exited with status" not in done.stderr, done.stderr
    lines = [line.split("] ", 1)[1] for line in done.stdout.splitlines() if line.startswith("[vehicle] ")]
    if webots:
        assert "setting speed to 50 km/h" in lines
        return
    assert "not simulated" not in done.stderr, done.stderr
    assert lines[0] == "mode 1 1"
    wipers = wiper_closed_form(150)
    rows = [line.split() for line in lines[1:]]
    assert [int(r[0]) for r in rows] == list(range(1, 151))
    for k, wheel, needle, at in rows:
        assert float(wheel) == (0.0 if int(k) < 20 else 10.0 * -0.05), k
        assert float(needle) == pytest.approx(50.0 * 4.42 / 220.0, abs=1e-12), k
        assert float(at) == pytest.approx(wipers[int(k) - 1], abs=1e-12), k
