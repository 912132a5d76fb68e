"""Sweep 22: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep22/: the
sample's poses, sizes and devices, our own text, PROTO meshes stood in for by plain shapes) driven in
process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_sweep19 import rot
from test_sweep20 import k3_move_on, ray_to_boxes

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep22"

# ------------------------------------------------------------------------------------------------ e-puck2
# e-puck2 (gctronic/e-puck): the E-puck, version "2", turned 1.57 rad at the centre of a 2 m RectangleArena
# with five 0.1 m boxes, running the `e-puck` controller: it picks a 64 ms step from the model
# "GCtronic e-puck2" (256 ms for the first e-puck), and each step sets the wheels by Braitenberg
# weights on 1 − ps_j/512 of its eight infra-red sensors, printing its odometry from the wheels'
# sensors (resolution 0.00628 rad) and its accelerometer. Each sensor is a Solid turned by the E-puck's
# ring rotation, its DistanceSensor turned 0.16 rad more about z; the table's last row is 67.19 at 0.07 m.
EP = "e-puck2"
EP_R, EP_AXLE, EP_RES = 0.02, 0.052, 0.00628
EP_KINEMATIC_AXLE = 2.0 * math.hypot(0.026, 0.02)    # Webots' rule without Physics: the wheels' 3-D distances
EP_RING = [(0.03, -0.01, (-0.977797, 0.14818, 0.148178), -1.593259),
           (0.022, -0.025, (0.858029, -0.363171, -0.363172), 1.723331),
           (0.0, -0.031, (-0.577352, 0.577348, 0.577352), -2.094405),
           (-0.03, -0.015, (0.176824, -0.695961, -0.695968), 2.79157),
           (-0.03, 0.015, (0.17854, 0.695742, 0.695749), 2.788236),
           (0.0, 0.031, (0.577354, 0.577344, 0.577352), 2.094396),
           (0.022, 0.025, (0.858533, 0.362572, 0.362579), 1.722748),
           (0.03, 0.01, (-0.978028, -0.147411, -0.147416), -1.593022)]
EP_TABLE = ([0, 0.005, 0.01, 0.015, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07],
            [4095, 2133.33, 1465.73, 601.46, 383.84, 234.93, 158.03, 120, 104.09, 67.19])
EP_WEIGHTS = [(0.942, -0.22), (0.63, -0.1), (0.5, -0.06), (-0.06, -0.06), (-0.06, -0.06), (-0.06, 0.5),
              (-0.19, 0.63), (-0.13, 0.942)]


def ep_move_on(x: float, y: float, yaw: float, wl: float, wr: float, dt: float) -> tuple[float, float, float]:
    """One step of the e-puck's drive: the arc of its wheel speeds, straight when they differ by rounding
    only (the Braitenberg weights' two sums, equal in open space, differ by 4e-16: their arc's radius
    would be 1e14 m, its closed form all cancellation)."""
    if abs(wr - wl) * EP_R / EP_AXLE * dt < 1e-13:
        wl = wr = (wl + wr) / 2
    return k3_move_on(x, y, yaw, wl, wr, dt, EP_R, EP_AXLE)


def ep_mid_heading(x: float, y: float, yaw: float, wl: float, wr: float, t: float) -> tuple[float, float, float]:
    """One basic step of ``t`` s of Webots' kinematic rule (the e-puck without Physics): d = (ωr − ωl)·t·r /
    (2·axle), a straight segment of v = (ωl + ωr)·r·t/2 along yaw + d, the heading then yaw + 2d."""
    d = (wr - wl) * t * EP_R / (2.0 * EP_KINEMATIC_AXLE)
    v = 0.5 * (wl + wr) * EP_R * t
    return x + v * math.cos(yaw + d), y + v * math.sin(yaw + d), yaw + 2.0 * d


def ep_obstacles() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The boxes the infra-red rays can meet: the arena's four walls (0.01 m thick, 0.1 m high, outside
    the 2 m floor) and the five 0.1 m boxes where the world file puts them."""
    walls = [((1.005, 0.0), (0.005, 1.0)), ((-1.005, 0.0), (0.005, 1.0)),
             ((0.0, 1.005), (1.01, 0.005)), ((0.0, -1.005), (1.01, 0.005))]
    out = [(np.array([x, y, 0.05]), np.eye(3), np.array([hx, hy, 0.05])) for (x, y), (hx, hy) in walls]
    for x, y, a in ((-0.683174, 0.2, 0.5), (0.35, 0.75, 4.96782), (-0.35471, -0.5, 5.36782), (0.36, 0.3, 5.36782),
                    (-0.66, 0.65, 5.36782)):
        out.append((np.array([x, y, 0.05]), rot((0, 0, 1), a), np.array([0.05, 0.05, 0.05])))
    return out


def test_the_e_puck2_stand_in_loads_its_model_and_the_devices_the_e_puck_controller_asks_for() -> None:
    """The version-2 template gives the model "GCtronic e-puck2" (which the controller reads to pick its
    64 ms step) and wheels of maxVelocity 7.536 rad/s (6.28 for version 1, model "GCtronic e-puck"):
    the robot loads without a line with its 36 devices, a two-wheel drive of radius 0.02 m and axle
    0.052 m whose wheels touch the floor where the world puts it."""
    w = load_world(DATA / "e-puck2.wbt")
    assert w.warnings == []
    (robot,) = w.world.robots
    assert robot.model == "GCtronic e-puck2"
    names = {d.name for d in robot.devices}
    assert len(names) == 36 and {"camera", "accelerometer", "gyro", "left wheel sensor", "right wheel sensor",
                                 *(f"ps{i}" for i in range(8)), *(f"ls{i}" for i in range(8)),
                                 *(f"led{i}" for i in range(10))} <= names
    drive = robot.differential_drive
    assert (drive.wheel_radius, drive.axle_length, drive.wheel_bottom, drive.max_wheel_speed) == pytest.approx(
        (EP_R, EP_AXLE, 0.0, 7.536), abs=1e-15)
    camera = next(d for d in robot.devices if d.name == "camera")
    assert (camera.width, camera.height) == (160, 120)


def run_e_puck(world: str, name: str, yaw0: float, duration_ms: int,
               kinematic: bool = False) -> tuple[int, tuple[int, int] | None, list[float]]:
    """e-puck.c's calls in process on ``world`` for ``duration_ms`` (the sensors' noise zeroed in the
    stand-in), each step checked against the closed forms: the eight infra-red sensors read the table at
    the ray's distance to the nearest wall or box face (white: the distance itself; 67.19 past 0.07 m),
    the wheels' sensors their angles rounded to 0.00628 rad, the accelerometer 9.81 up while the robot
    drives straight, and the pose is the arc of the wheel speeds set from the readings (1e-9; ``kinematic``:
    Webots' rule without Physics, :func:`ep_mid_heading` each basic step). Returns
    the step the model chose, when and which sensor first met something, and the final x, y, yaw."""
    sim = Simulation(load_world(DATA / world), "exact")
    robot = sim.robot(name)
    step = 64 if robot.model.model == "GCtronic e-puck2" else 256
    sim.device(f"{name}/camera").enable(step if step == 64 else 1024)
    accelerometer = sim.device(f"{name}/accelerometer")
    accelerometer.enable(step)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(0.0)
    wheel_sensors = [sim.device(f"{name}/left wheel sensor"), sim.device(f"{name}/right wheel sensor")]
    for s in wheel_sensors:
        s.enable(step)
    ps = [sim.device(f"{name}/ps{i}") for i in range(8)]
    for s in ps:
        s.enable(step)
    obstacles = ep_obstacles()
    rays = [(np.array([x, y, 0.033]), rot(axis, angle) @ rot((0, 0, 1), 0.16) @ np.array([1.0, 0.0, 0.0]))
            for x, y, axis, angle in EP_RING]
    turn0 = rot((0, 0, 1), yaw0)
    x, y, yaw, wl, wr = 0.0, 0.0, yaw0, 0.0, 0.0
    angles = [0.0, 0.0]
    first_seen = None
    for k in range(1, duration_ms // step + 1):
        for _ in range(step // sim.basic_time_step):
            sim.step()
        if kinematic:
            for _ in range(step // sim.basic_time_step):
                x, y, yaw = ep_mid_heading(x, y, yaw, wl, wr, sim.basic_time_step / 1000)
        else:
            x, y, yaw = ep_move_on(x, y, yaw, wl, wr, step / 1000)
        angles = [angles[0] + wl * step / 1000, angles[1] + wr * step / 1000]
        body = rot((0, 0, 1), yaw - yaw0) @ turn0
        assert list(robot.pose.translation) == pytest.approx([x, y, 0.0], abs=1e-9), k
        assert np.asarray(robot.pose.rotation) == pytest.approx(body, abs=1e-9), k
        values = []
        for i, (at, u) in enumerate(rays):
            distance = ray_to_boxes(np.array([x, y, 0.0]) + body @ at, body @ u, obstacles)
            values.append(float(np.interp(distance, *EP_TABLE)) if distance < 0.07 else 67.19)
            assert float(ps[i].value) == pytest.approx(values[-1], rel=1e-9), (k, i)
            if distance < 0.07 and first_seen is None:
                first_seen = (k * step, i)
        for s, a in zip(wheel_sensors, angles, strict=True):
            assert float(s.value) == pytest.approx(round(a / EP_RES) * EP_RES, abs=1e-12), k
        if abs(wl - wr) < 1e-12:
            assert list(accelerometer.values) == pytest.approx([0.0, 0.0, 9.81], abs=1e-9), k
        wl, wr = (sum(c[side] * (1.0 - v / 512) for c, v in zip(EP_WEIGHTS, values, strict=True)) for side in (0, 1))
        left.set_velocity(wl)
        right.set_velocity(wr)
    return step, first_seen, [x, y, yaw]


def test_the_e_puck_calls_drive_the_e_puck2_by_its_closed_form_readings_and_arcs() -> None:
    """e-puck2: the controller picks 64 ms from the model; for 36.992 s (578 steps) every reading and
    pose meets run_e_puck's closed forms. In open space both wheels turn at 1.572 × (1 − 67.19/512) =
    1.36571 rad/s: 0.0273141 m/s along its heading, until ps0 and ps7 meet the wall at y 1 (ps0 first,
    at 33.216 s, the robot at y 0.9055 = 0.0273141 × 33.152 s), where it turns left, away from it, to
    (−0.0030, 0.9588) heading 2.9750 at 36.992 s."""
    step, first_seen, end = run_e_puck("e-puck2.wbt", EP, 1.57, 36992)
    assert step == 64 and first_seen == (33216, 0), (step, first_seen)
    assert end == pytest.approx([-0.0030, 0.9588, 2.9750], abs=1e-4)


def test_the_e_puck_calls_drive_the_kinematic_e_puck_by_the_same_closed_forms() -> None:
    """e-puck_kinematic: the version-1 E-puck without Physics: the controller picks 256 ms from the model
    "GCtronic e-puck"; the same closed forms hold every step for 40.96 s (160 steps), the pose's by Webots'
    kinematic rule for a robot without Physics (a 3-D axle of 0.0656 m, each 32 ms basic step a straight
    segment along the mid-step heading): ps0 meets the wall at 33.536 s, the robot then turning left to
    (−0.0683, 0.9316) heading −2.6259 (by the arc and the 0.052 m axle it was (−0.0792, 0.9214), −2.5771). The
    stand-in loads
    without mass (nothing to settle) and with the version-1 wheels' maxVelocity, 6.28 rad/s."""
    step, first_seen, end = run_e_puck("e-puck_kinematic.wbt", "e-puck", 1.571595307179586, 40960, kinematic=True)
    assert step == 256 and first_seen == (33536, 0), (step, first_seen)
    assert [*end[:2], math.remainder(end[2], 2 * math.pi)] == pytest.approx([-0.0683, 0.9316, -2.6259], abs=1e-4)
    (robot,) = load_world(DATA / "e-puck_kinematic.wbt").world.robots
    assert robot.mass is None and robot.model == "GCtronic e-puck" and robot.differential_drive.max_wheel_speed == 6.28
    assert robot.differential_drive.step_rule == "mid_heading"
    assert robot.differential_drive.axle_length == pytest.approx(EP_KINEMATIC_AXLE, abs=1e-15)
