"""GPS against closed-form answers on scripted motions: at rest, a straight line, a constant turn, a
supervisor pose on a slope; WGS84 via the UTM series; Webots' timing, noise and resolution."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import messages as msgs
from sensorium.schemas import world as wm
from sensorium.schemas.wire import pack, unpack
from sensorium.server.daemon.services import Core
from sensorium.server.devices import gps as gps_math
from sensorium.server.sim.simulation import Simulation

R_WHEEL, AXLE = 0.02, 0.1


def make(gps=None, world_info=None, pose=None, devices_extra=()):
    data = {"world_info": {"basic_time_step": 16, "contact": False, **(world_info or {})},
            "robots": [{"name": "r", "pose": pose or {"translation": [1.0, 2.0, 0.0]},
                        "differential_drive": {"wheel_radius": R_WHEEL, "axle_length": AXLE, "max_wheel_speed": 100},
                        "devices": [{"device": "GPS", "name": "gps", **(gps or {})}, *devices_extra]}]}
    return Simulation(wm.World.model_validate(data))


def drive(sim, left, right):
    r = sim.robot("r")
    for name, w in (("left wheel motor", left), ("right wheel motor", right)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)


def test_at_rest_timing_and_mount_offset():
    sim = make({"pose": {"translation": [0.1, 0.0, 0.05]}},
               pose={"translation": [1.0, 2.0, 0.0], "rotation": [0, 0, 1, math.pi / 2]})
    g = sim.device("r/gps")
    assert np.isnan(g.values).all() and math.isnan(g.speed)
    g.enable(32)
    sim.step()
    assert np.isnan(g.values).all()                                  # NaN until one period elapsed
    sim.step()
    np.testing.assert_allclose(g.values, [1.0, 2.1, 0.05], atol=1e-15)   # the mount, turned with the robot
    assert np.isnan(g.speed_vector).all() and math.isnan(g.speed)    # no previous position yet (Webots)
    sim.run(2)
    np.testing.assert_array_equal(g.speed_vector, [0.0, 0.0, 0.0])
    assert g.speed == 0.0 and g.measurements == 2


def test_straight_line():
    sim = make()
    drive(sim, 5.0, 5.0)                                              # v = 0.1 m/s along +x
    g = sim.device("r/gps")
    g.enable(16)
    for k in range(1, 21):
        sim.step()
        t = k * 0.016
        assert g.values[0] == pytest.approx(1.0 + 0.1 * t, abs=1e-12) and g.values[1] == pytest.approx(2.0, abs=1e-15)
    np.testing.assert_allclose(g.speed_vector, [0.1, 0.0, 0.0], atol=1e-12)
    assert g.speed == pytest.approx(0.1, abs=1e-12)


def test_a_simulation_reset_leaves_no_previous_position():
    """Webots' WbGps::reset forgets the previous position: the first value after a simulation
    reset has a NaN speed, as the first value after enable (it read the jump back to the start
    over one period: 2 m/s for a robot at 0.1 m/s), then the speed of the motion again."""
    sim = make()
    drive(sim, 5.0, 5.0)                                              # v = 0.1 m/s along +x
    g = sim.device("r/gps")
    g.enable(32)
    sim.run(40)                                                       # 0.64 m along +x
    assert g.speed == pytest.approx(0.1, abs=1e-12)
    sim.reset()                                                       # back at (1, 2), wheels at rest
    drive(sim, 5.0, 5.0)
    sim.run(2)
    assert g.values[0] == pytest.approx(1.0 + 0.1 * 0.032, abs=1e-12)
    assert math.isnan(g.speed) and np.isnan(g.speed_vector).all()
    sim.run(2)
    assert g.speed == pytest.approx(0.1, abs=1e-12)
    np.testing.assert_allclose(g.speed_vector, [0.1, 0.0, 0.0], atol=1e-12)


def test_constant_turn_reads_the_chord():
    sim = make({"pose": {"translation": [0.05, 0.0, 0.0]}})
    drive(sim, 2.0, 6.0)                  # v = R(ωl+ωr)/2 = 0.08 m/s, ω = R(ωr-ωl)/L = 0.8 rad/s
    v, w = R_WHEEL * 8.0 / 2, R_WHEEL * 4.0 / AXLE
    g = sim.device("r/gps")
    g.enable(64)
    sim.run(40)                                       # t = 0.64 s, 10 measurements
    t = 0.64
    yaw = w * t
    rad = v / w
    cx, cy = 1.0, 2.0 + rad                           # the centre of the turn (robot starts at yaw 0)
    robot = np.array([cx + rad * math.sin(yaw), cy - rad * math.cos(yaw)])
    mount = robot + 0.05 * np.array([math.cos(yaw), math.sin(yaw)])
    np.testing.assert_allclose(g.values[:2], mount, atol=1e-12)
    # the speed vector of a device without physics: the chord of the last period over its duration
    dt = 0.064
    prev_yaw = w * (t - dt)
    prev = np.array([cx + rad * math.sin(prev_yaw), cy - rad * math.cos(prev_yaw)]) \
        + 0.05 * np.array([math.cos(prev_yaw), math.sin(prev_yaw)])
    np.testing.assert_allclose(g.speed_vector[:2], (mount - prev) / dt, atol=1e-12)
    radius = math.hypot(rad, 0.05)                     # the mount turns on its own circle
    assert g.speed == pytest.approx(2 * radius * math.sin(w * dt / 2) / dt, abs=1e-12)


def test_supervisor_pose_on_a_slope():
    sim = make({"pose": {"translation": [0.0, 0.0, 0.2]}})
    g = sim.device("r/gps")
    g.enable(16)
    slope = math.radians(30)
    sim.robot("r").set_pose([3.0, -1.0, 0.5], [0.0, 1.0, 0.0, slope])      # pitched about y
    sim.step()
    # R_y(θ)·(0, 0, 0.2) = (0.2 sin θ, 0, 0.2 cos θ)
    np.testing.assert_allclose(g.values, [3.0 + 0.2 * math.sin(slope), -1.0, 0.5 + 0.2 * math.cos(slope)], atol=1e-15)


def test_local_reference_is_added():
    sim = make(world_info={"gps_reference": [10.0, -20.0, 300.0]})
    g = sim.device("r/gps")
    g.enable(16)
    sim.step()
    np.testing.assert_allclose(g.values, [11.0, -18.0, 300.0], atol=1e-12)
    assert g.coordinate_system == 0


def _meridian_radius(lat_deg):
    f = 1 / 298.2572236
    e2 = f * (2 - f)
    s = math.sin(math.radians(lat_deg))
    return 6378137.0 * (1 - e2) / (1 - e2 * s * s) ** 1.5


@pytest.mark.parametrize("axes", ["ENU", "NUE"])
def test_wgs84(axes):
    lat0, lon0, alt0 = 46.5, 9.0, 400.0           # lon 9 = zone 32's central meridian: the scale factor is k0
    sim = make(world_info={"gps_coordinate_system": "WGS84", "gps_reference": [lat0, lon0, alt0],
                           "coordinate_system": axes},
               pose={"translation": [0.0, 0.0, 0.0]})
    g = sim.device("r/gps")
    g.enable(16)
    sim.step()
    assert g.coordinate_system == 1
    assert g.values[0] == pytest.approx(lat0, abs=1e-8) and g.values[1] == pytest.approx(lon0, abs=1e-8)
    assert g.values[2] == pytest.approx(alt0, abs=1e-9)
    north = {"ENU": [0.0, 1000.0, 5.0], "NUE": [1000.0, 5.0, 0.0]}[axes]   # 1 km north, 5 m up
    sim.robot("r").set_pose(north)
    sim.step()
    dlat = math.degrees(1000.0 / (0.9996 * _meridian_radius(lat0 + 0.0045)))
    assert g.values[0] - lat0 == pytest.approx(dlat, rel=1e-6)
    assert g.values[1] == pytest.approx(lon0, abs=1e-8) and g.values[2] == pytest.approx(alt0 + 5.0, abs=1e-9)


def test_utm_round_trip_and_hemispheres():
    for lat, lon in [(46.5, 6.6), (-33.9, 18.4), (0.0, -179.0), (70.0, 25.0)]:
        u = gps_math.Utm(lat, lon)
        n, e = u.north_east(lat, lon)
        back = u.latitude_longitude(n, e)
        assert back == pytest.approx((lat, lon), abs=1e-8)
    assert gps_math.Utm(-1.0, 0.0).false_northing == 10_000_000.0
    assert gps_math.Utm(0.0, 3.0).north_east(0.0, 3.0) == pytest.approx((0.0, 500000.0), abs=1e-9)


def test_noise_resolution_and_streams():
    sim = make({"accuracy": 0.5, "speed_noise": 0.1}, pose={"translation": [0.0, 0.0, 0.0]})
    g = sim.device("r/gps")
    g.enable(16)
    samples = []
    for _ in range(2000):
        sim.step()
        samples.append(g.values.copy())
    a = np.array(samples)
    assert np.abs(a.mean(axis=0)).max() < 0.05 and np.allclose(a.std(axis=0), 0.5, rtol=0.08)
    assert abs(np.corrcoef(a[:-1, 0], a[1:, 0])[0, 1]) < 0.1          # no correlation asked
    sim2 = make({"accuracy": 0.5, "speed_noise": 0.1}, pose={"translation": [0.0, 0.0, 0.0]})
    sim2.device("r/gps").enable(16)
    sim2.run(2000)
    np.testing.assert_array_equal(sim2.device("r/gps").values, g.values)   # one stream per device, seeded
    # resolution rounds each coordinate (Webots' trunc(v/res + 0.5)·res: toward zero below 0)
    sim3 = make({"resolution": 0.25}, pose={"translation": [1.13, -0.3, -0.4]})
    sim3.device("r/gps").enable(16)
    sim3.step()
    np.testing.assert_allclose(sim3.device("r/gps").values, [1.25, 0.0, -0.25], atol=1e-15)


def test_correlated_noise_is_a_gauss_markov_process():
    sim = make({"accuracy": 1.0, "noise_correlation": 0.5}, pose={"translation": [0.0, 0.0, 0.0]})
    g = sim.device("r/gps")
    g.enable(1000)                                   # one value per second: ratio = 0.5
    xs = []
    for _ in range(1500):
        sim.run(63)                                  # 63 · 16 ms = 1008 ms ≥ 1 s: one value each time
        xs.append(g.values[0])
    x = np.array(xs)
    assert np.corrcoef(x[:-1], x[1:])[0, 1] == pytest.approx(0.5 ** 1.008, abs=0.07)
    assert x.std() == pytest.approx(1.0, rel=0.1)


def call(core, service, args=None, _id=[0]):  # noqa: B006 - a request counter
    _id[0] += 1
    [reply] = core.handle([b"peer", pack({"id": _id[0], "service": service, "args": args or {}})], 0.0)
    return unpack(reply[-1])


def test_services_topics_and_step_values():
    sim = make(world_info={"gps_coordinate_system": "WGS84", "gps_reference": [46.5, 9.0, 400.0]},
               gps={"accuracy": 0.0})
    core = Core(sim)
    assert {"/r/gps/get_values", "/r/gps/get_speed", "/r/gps/get_speed_vector", "/r/gps/get_coordinate_system",
            "/r/gps/enable"} <= set(core.routes)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/gps/values"] == msgs.NAV_SAT_FIX and types["/r/gps/speed_vector"] == msgs.VECTOR3_STAMPED
    att = call(core, "attach", {"robot": "r"})["result"]
    [desc] = [d for d in att["devices"] if d["name"] == "gps"]
    assert desc["coordinate_system"] == 1 and desc["type"] == "GPS" and desc["simulated"] is True
    assert call(core, "/r/gps/get_coordinate_system")["result"]["value"] == 1
    assert call(core, "/r/gps/enable", {"value": 16})["ok"]
    sim.step()
    values = call(core, "/r/gps/get_values")["result"]["value"]
    assert values[0] == pytest.approx(46.5 + 2.0 / 111_000, abs=1e-6)        # 2 m north of the reference
    ctl = core.topics.controls["r/gps"]
    fix = msgs.validate(msgs.NAV_SAT_FIX, core.topics.build(ctl, "values", sim.time_ms))
    assert fix.latitude == values[0] and fix.position_covariance_type == 0
    step = core.topics.reading(ctl)
    assert step["values"] == values and math.isnan(step["speed"])


def test_local_gps_publishes_a_point():
    sim = make()
    core = Core(sim)
    types = {t.name: t.type for t in core.topics.topics}
    assert types["/r/gps/values"] == msgs.POINT_STAMPED and types["/r/gps/speed"] == msgs.FLOAT64


def test_gps_messages_export_to_ros2():
    from sensorium.server.recording.export import to_ros, to_rosbags, typestore_for
    sim = make(world_info={"gps_coordinate_system": "WGS84", "gps_reference": [46.5, 9.0, 400.0]},
               gps={"accuracy": 0.3})
    core = Core(sim)
    ctl = core.topics.controls["r/gps"]
    sim.device("r/gps").enable(16)
    sim.run(2)
    store = typestore_for("jazzy")
    fix = to_rosbags(store, msgs.NAV_SAT_FIX, to_ros(store, msgs.NAV_SAT_FIX, core.topics.build(ctl, "values", sim.time_ms)))
    assert fix.latitude == sim.device("r/gps").values[0] and fix.position_covariance_type == 2
    np.testing.assert_allclose(fix.position_covariance, np.diag([0.09] * 3).ravel())
    vec = to_rosbags(store, msgs.VECTOR3_STAMPED, to_ros(store, msgs.VECTOR3_STAMPED, core.topics.build(ctl, "speed_vector", sim.time_ms)))
    assert vec.vector.x == sim.device("r/gps").speed_vector[0]
    speed = to_rosbags(store, msgs.FLOAT64, to_ros(store, msgs.FLOAT64, core.topics.build(ctl, "speed", sim.time_ms)))
    assert speed.data == sim.device("r/gps").speed
