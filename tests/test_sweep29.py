"""Sweep 29: Webots' `projects/vehicles` city sample not run before, on a stand-in world of ours
(tests/data/sweep29/: the BmwX5's Car geometry, joints and device names and the sample's sensors where it
puts them, our own text; roads, buildings and traffic stood in for by plain shapes) driven by the calls its
controller makes and checked against closed forms."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _serve import child_env, sensorium
from test_sweep19 import KinematicMotor

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

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
