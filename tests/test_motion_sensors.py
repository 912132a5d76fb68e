"""Gyro, Accelerometer and Altimeter from the kinematic motion, against closed-form answers: at rest,
a straight line, a constant turn, a supervisor pose on a slope."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.server.daemon.services import Core
from sensorium.server.devices import motion_sensors as ms
from sensorium.server.sim.simulation import Simulation

R_WHEEL, AXLE, DT = 0.02, 0.1, 0.016
G = 9.81


def make(accel=None, gyro=None, alt=None, world_info=None, pose=None):
    data = {"world_info": {"basic_time_step": 16, "contact": False, **(world_info or {})},
            "robots": [{"name": "r", "pose": pose or {"translation": [0.0, 0.0, 0.0]},
                        "differential_drive": {"wheel_radius": R_WHEEL, "axle_length": AXLE, "max_wheel_speed": 100},
                        "devices": [{"device": "Accelerometer", "name": "acc", **(accel or {})},
                                    {"device": "Gyro", "name": "gyro", **(gyro or {})},
                                    {"device": "Altimeter", "name": "alt", **(alt or {})}]}]}
    sim = Simulation(wm.World.model_validate(data))
    for d in ("acc", "gyro", "alt"):
        sim.device(f"r/{d}").enable(16)
    return sim


def drive(sim, left, right):
    r = sim.robot("r")
    for name, w in (("left wheel motor", left), ("right wheel motor", right)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)


def test_at_rest():
    sim = make(pose={"translation": [0.0, 0.0, 0.3]})
    acc, gyro, alt = (sim.device(f"r/{d}") for d in ("acc", "gyro", "alt"))
    assert np.isnan(acc.values).all() and np.isnan(gyro.values).all() and math.isnan(alt.value)
    sim.step()
    np.testing.assert_array_equal(acc.values, [0.0, 0.0, G])            # gravity, as Webots' at rest
    np.testing.assert_array_equal(gyro.values, [0.0, 0.0, 0.0])
    assert alt.value == 0.3


def test_straight_line():
    sim = make()
    drive(sim, 5.0, 5.0)
    sim.run(10)
    np.testing.assert_allclose(sim.device("r/acc").values, [0.0, 0.0, G], atol=1e-9)
    np.testing.assert_allclose(sim.device("r/gyro").values, [0.0, 0.0, 0.0], atol=1e-12)


def test_constant_turn():
    sim = make()
    drive(sim, 2.0, 6.0)
    v, w = R_WHEEL * 8.0 / 2, R_WHEEL * 4.0 / AXLE          # 0.08 m/s, 0.8 rad/s: radius 0.1 m
    sim.run(20)
    np.testing.assert_allclose(sim.device("r/gyro").values, [0.0, 0.0, w], atol=1e-9)
    # the second difference of three points of the circle, seen from the frame of the last one
    rad = v / w
    mag = 2.0 * rad * (1.0 - math.cos(w * DT)) / DT ** 2
    expected = [mag * math.sin(w * DT), mag * math.cos(w * DT), G]
    np.testing.assert_allclose(sim.device("r/acc").values, expected, atol=1e-7)
    assert mag == pytest.approx(v * w, rel=1e-4)                        # the centripetal acceleration


def test_supervisor_pose_on_a_slope():
    sim = make()
    theta = 0.3
    sim.robot("r").set_pose([0.0, 0.0, 2.0], [0.0, 1.0, 0.0, theta])
    sim.run(3)                                           # at rest on the slope from the 2nd step on
    np.testing.assert_allclose(sim.device("r/acc").values, [-G * math.sin(theta), 0.0, G * math.cos(theta)],
                               atol=1e-12)
    np.testing.assert_allclose(sim.device("r/gyro").values, [0.0, 0.0, 0.0], atol=1e-12)
    assert sim.device("r/alt").value == 2.0


def test_a_supervisor_move_or_a_reset_is_a_jump_not_motion():
    """Webots' gyro and accelerometer read the bodies' velocities, which a Supervisor move keeps and
    a simulation reset zeroes: moving or resetting a turning robot is no turn of 30 rad/s nor an
    acceleration of 1,000 m/s² (it was read so: the jump over one step, then back)."""
    sim = make()
    drive(sim, 2.0, 6.0)
    v, w = R_WHEEL * 8.0 / 2, R_WHEEL * 4.0 / AXLE          # 0.08 m/s, 0.8 rad/s: radius 0.1 m
    mag = 2.0 * (v / w) * (1.0 - math.cos(w * DT)) / DT ** 2
    turning = [mag * math.sin(w * DT), mag * math.cos(w * DT), G]
    sim.run(20)
    acc, gyro = sim.device("r/acc"), sim.device("r/gyro")
    np.testing.assert_allclose(acc.values, turning, atol=1e-7)
    for move in (lambda: sim.robot("r").set_pose([1.0, -2.0, 0.0], [0.0, 0.0, 1.0, 2.5]), sim.reset):
        move()
        drive(sim, 2.0, 6.0)                                # (a reset puts the wheels back to rest)
        sim.step()                                          # rest assumed for the acceleration, as at enable
        np.testing.assert_allclose(gyro.values, [0.0, 0.0, w], atol=1e-9)
        np.testing.assert_allclose(acc.values, [0.0, 0.0, G], atol=1e-12)
        sim.run(2)                                          # then the turn's own values again
        np.testing.assert_allclose(gyro.values, [0.0, 0.0, w], atol=1e-9)
        np.testing.assert_allclose(acc.values, turning, atol=1e-7)


@pytest.mark.parametrize("axes, up", [("ENU", 2), ("NUE", 1)])
def test_altimeter_adds_the_reference_altitude_in_local_coordinates_too(axes, up):
    """Webots' WbAltimeter adds the gps_reference's up component in local coordinates (its third
    value in WGS84), as the GPS adds the reference: a robot 0.3 m up under a local reference
    (100, 7, -20) reads 0.3 + the reference's up value (it read 0.3, while its GPS read 0.3 + it)."""
    ref = [100.0, 7.0, -20.0]
    pose = [0.0, 0.0, 0.3] if axes == "ENU" else [0.0, 0.3, 0.0]
    sim = make(world_info={"coordinate_system": axes, "gps_reference": ref}, pose={"translation": pose})
    sim.step()
    assert sim.device("r/alt").value == 0.3 + ref[up]
    sim = make(world_info={"coordinate_system": axes, "gps_reference": [46.5, 6.6, 372.0],
                           "gps_coordinate_system": "WGS84"}, pose={"translation": pose})
    sim.step()
    assert sim.device("r/alt").value == 0.3 + 372.0


def test_nue_world_gravity_and_height():
    sim = make(world_info={"coordinate_system": "NUE", "gravity": 3.7},
               pose={"translation": [0.0, 0.5, 0.0], "rotation": [1, 0, 0, -math.pi / 2]})
    sim.step()
    # the robot is turned so that its z is the world's y (up): gravity on its z
    np.testing.assert_allclose(sim.device("r/acc").values, [0.0, 0.0, 3.7], atol=1e-12)
    assert sim.device("r/alt").value == pytest.approx(0.5, abs=1e-15)


def test_tables_axes_resolution_noise():
    sim = make(accel={"lookup_table": [[-100, -1000, 0], [100, 1000, 0]], "x_axis": False, "resolution": 3},
               alt={"accuracy": 0.1})
    sim.run(2)
    a = sim.device("r/acc").values
    assert math.isnan(a[0]) and a[1] == 0.0 and a[2] == 99.0          # 98.1 → trunc(32.7 + 0.5)·3
    xs = []
    for _ in range(2000):
        sim.step()
        xs.append(sim.device("r/alt").value)
    assert np.std(xs) == pytest.approx(0.1, rel=0.08) and abs(np.mean(xs)) < 0.01


def test_angular_velocity_small_and_large_angles():
    for angle in (1e-9, 1e-3, 1.0, 3.0):
        c, s = math.cos(angle), math.sin(angle)
        r1 = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
        np.testing.assert_allclose(ms.angular_velocity(np.eye(3), r1, 0.5), [2 * angle, 0, 0], rtol=1e-9)


def test_services_and_topics():
    sim = make()
    core = Core(sim)
    assert {"/r/acc/get_values", "/r/acc/get_lookup_table", "/r/gyro/get_values", "/r/alt/get_value"} <= set(core.routes)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/acc/values"] == msgs.VECTOR3_STAMPED and types["/r/alt/value"] == msgs.FLOAT64
    sim.step()
    body = msgs.validate(msgs.VECTOR3_STAMPED, core.topics.build(core.topics.controls["r/acc"], "values", sim.time_ms))
    assert body.vector.z == G
    assert core.topics.reading(core.topics.controls["r/alt"]) == {"value": 0.0}
