"""Topic names, demand (XPUB prefixes, recorder), device control, message shapes, seq numbers."""

from __future__ import annotations

import math

import msgpack
import numpy as np
import pytest
from server_fakes import FakeSim, small_world

from sensorium.schemas import messages as M
from sensorium.schemas import world as wm
from sensorium.schemas.wire import from_bin
from sensorium.server.daemon.topics import Topics, laser_scan_angles

SUB, UNSUB = b"\x01", b"\x00"


def make(**kw):
    sim = FakeSim(small_world(**kw))
    return sim, Topics(sim)


def step(sim, topics, n=1):
    out = []
    for _ in range(n):
        sim.step()
        out += topics.publish(sim.time_ms)
    return out


def decoded(frames):
    return [(f[0][:-1].decode(), msgpack.unpackb(f[1]), msgpack.unpackb(f[2])) for f in frames]


def test_topic_names_and_types():
    _, t = make()
    assert [(x.name, x.type) for x in t.topics] == [
        ("/clock", M.CLOCK),
        ("/bot/ls/value", M.ILLUMINANCE),
        ("/bot/ds/value", M.RANGE),
        ("/bot/lidar/range_image", M.IMAGE),
        ("/bot/lidar/laser_scan", M.LASER_SCAN),          # one layer: LaserScan
        ("/bot/lidar/point_cloud", M.POINT_CLOUD),
        ("/bot/lidar2/range_image", M.IMAGE),             # two layers: no LaserScan
        ("/bot/lidar2/point_cloud", M.POINT_CLOUD),
        ("/bot/pose", M.POSE_STAMPED),                    # every robot: its pose after each basic step
        ("/bot/robot_window", M.STRING),                  # ... and what its controller sends its robot window
        ("/bot/robot_window/to_controller", M.STRING),    # ... and what is sent to its controller from there
        ("/free/ls/value", M.ILLUMINANCE),
        ("/free/pose", M.POSE_STAMPED),
        ("/free/robot_window", M.STRING),
        ("/free/robot_window/to_controller", M.STRING),
    ]


@pytest.mark.parametrize("prefixes, demanded", [
    ([], set()),
    ([b""], {"/clock", "/bot/ls/value", "/bot/ds/value", "/bot/lidar/range_image", "/bot/lidar/laser_scan",
             "/bot/lidar/point_cloud", "/bot/lidar2/range_image", "/bot/lidar2/point_cloud", "/bot/pose",
             "/bot/robot_window", "/bot/robot_window/to_controller", "/free/ls/value", "/free/pose",
             "/free/robot_window", "/free/robot_window/to_controller"}),
    ([b"/bot/robot_window\0"], {"/bot/robot_window"}),              # exact: not the other direction
    ([b"/bot/robot_window"], {"/bot/robot_window", "/bot/robot_window/to_controller"}),
    ([b"/bot/pose\0"], {"/bot/pose"}),
    ([b"/bot/pose/"], set()),
    ([b"/bot/lidar/"], {"/bot/lidar/range_image", "/bot/lidar/laser_scan", "/bot/lidar/point_cloud"}),
    ([b"/bot/lidar"], {"/bot/lidar/range_image", "/bot/lidar/laser_scan", "/bot/lidar/point_cloud",
                       "/bot/lidar2/range_image", "/bot/lidar2/point_cloud"}),
    ([b"/bot/lidar/range_image\0"], {"/bot/lidar/range_image"}),
    ([b"/bot/ls/value\0", b"/clock\0"], {"/bot/ls/value", "/clock"}),
    ([b"/bot/ls/value\0x"], set()),
    ([b"/nobody/"], set()),
])
def test_prefix_rule(prefixes, demanded):
    _, t = make()
    for p in prefixes:
        t.subscription(SUB + p)
    assert t.demanded == demanded


def test_subscription_events_and_device_state():
    sim, t = make()
    ls = sim.robots["bot"].devices["ls"]
    assert t.subscription(SUB + b"/bot/ls/value\0") is True
    assert ls.sampling_period == 32                  # a subscriber alone enables at the basic step
    assert t.subscription(SUB + b"/bot/ls/value\0") is False   # a second subscriber: no change
    assert t.subscription(b"\x02junk") is False and t.subscription(b"") is False
    assert t.subscription(UNSUB + b"/bot/ls/value\0") is False  # one of the two left: still demanded
    assert ls.sampling_period == 32
    assert t.subscription(UNSUB + b"/bot/ls/value\0") is True
    assert ls.sampling_period == 0 and t.demanded == set()
    assert t.subscription(UNSUB + b"/bot/ls/value\0") is False  # nobody subscribed: ignored


def test_subscriptions_that_match_no_topic_are_not_kept():
    sim, t = make()
    assert t.subscription(SUB + b"/nothing/here") is False
    assert t.subscription(SUB + b"/bot/ls/value\0" + b"x" * 100) is False
    assert t.subscription(SUB + b"/" * 70_000) is False
    assert t.prefixes == {}
    assert t.subscription(SUB + b"/bo") is True                  # a prefix of topics: kept
    assert t.prefixes == {b"/bo": 1}


def test_nothing_computed_without_demand():
    sim, t = make()
    assert step(sim, t, 5) == []
    assert sum(sim.counters.values()) == 0
    assert all(d.measurements == 0 for r in sim.robots.values() for d in r.devices.values())


def test_controller_enable_is_not_disturbed():
    sim, t = make()
    ds = sim.robots["bot"].devices["ds"]
    t.controller_enable("bot/ds", 96)
    sim.step()                                       # 32
    t.subscription(SUB + b"/bot/ds/")
    assert ds.sampling_period == 96 and ds.enable_calls == [96]
    frames = step(sim, t, 3)                         # 64, 96, 128: measured once (at 96)
    assert [e["stamp_ns"] for _, e, _ in decoded(frames)] == [96_000_000]
    t.controller_enable("bot/ds", 0)                 # the controller disables: topic keeps it at basic step
    assert ds.sampling_period == 32 and t.control("bot/ds").controller_period == 0
    assert len(step(sim, t, 2)) == 2
    t.subscription(UNSUB + b"/bot/ds/")
    assert ds.sampling_period == 0


def test_controller_enable_after_subscriber():
    sim, t = make()
    ls = sim.robots["bot"].devices["ls"]
    t.subscription(SUB + b"/bot/ls/value\0")
    sim.step()
    t.controller_enable("bot/ls", 64)                # controller's own period and phase
    assert ls.sampling_period == 64 and ls.last == 32
    t.subscription(UNSUB + b"/bot/ls/value\0")
    assert ls.sampling_period == 64                  # the controller's enable survives
    t.release_robot("bot")                           # controller gone, no subscriber: off
    assert ls.sampling_period == 0


def test_point_cloud_only_when_demanded_or_enabled():
    sim, t = make()
    lidar = sim.robots["bot"].devices["lidar"]
    t.subscription(SUB + b"/bot/lidar/laser_scan\0")
    step(sim, t, 2)
    assert sim.counters["rays_lidar"] == 8 and sim.counters["points_built"] == 0
    assert not lidar.point_cloud_enabled
    t.subscription(SUB + b"/bot/lidar/point_cloud\0")
    assert lidar.point_cloud_enabled
    step(sim, t)
    assert sim.counters["points_built"] == 4
    t.subscription(UNSUB + b"/bot/lidar/point_cloud\0")
    assert not lidar.point_cloud_enabled
    t.controller_point_cloud("bot/lidar", True)
    assert lidar.point_cloud_enabled
    t.controller_point_cloud("bot/lidar", False)
    assert not lidar.point_cloud_enabled


def test_messages_shapes_order_and_seq():
    sim, t = make()
    t.subscription(SUB + b"")
    t.controller_enable("free/ls", 64)
    msgs = decoded(step(sim, t, 2))
    names = [n for n, _, _ in msgs]
    assert names[0] == "/clock" and names.count("/clock") == 2
    assert names[1:3] == ["/bot/pose", "/free/pose"] and names.count("/bot/pose") == 2
    assert names.count("/bot/ls/value") == 2 and names.count("/free/ls/value") == 1
    seqs: dict[str, list[int]] = {}
    for name, env, body in msgs:
        model = M.MESSAGE_TYPES[env["type"]]
        model.model_validate(body)                             # shape
        assert list(body) == M.field_order(model)              # ROS field order
        assert list(env) == ["type", "seq", "stamp_ns"]
        seqs.setdefault(name, []).append(env["seq"])
        if name.endswith("/pose"):
            assert body["header"]["frame_id"] == "world"
        elif name != "/clock":
            robot, dev = name.split("/")[1:3]
            assert body["header"]["frame_id"] == f"{robot}/{dev}"
            st = body["header"]["stamp"]
            assert st["sec"] * 10**9 + st["nanosec"] == env["stamp_ns"]
    assert all(v == list(range(len(v))) for v in seqs.values())

    by = {n: b for n, _, b in msgs}                            # the latest of each (t = 64 ms)
    assert by["/clock"] == {"clock": {"sec": 0, "nanosec": 64_000_000}}
    assert by["/bot/ls/value"]["illuminance"] == pytest.approx(100.064)
    r = by["/bot/ds/value"]
    assert (r["radiation_type"], r["field_of_view"], r["min_range"], r["max_range"], r["range"]) == (0, 0.3, 0.0, 2000.0, 32.0)
    img = by["/bot/lidar2/range_image"]
    assert (img["height"], img["width"], img["encoding"], img["is_bigendian"], img["step"]) == (2, 3, "32FC1", 0, 12)
    np.testing.assert_allclose(from_bin(img["data"], "<f4", (2, 3)), [[0.064, 0.074, 0.084], [1.064, 1.074, 1.084]], rtol=1e-6)
    pc = by["/bot/lidar2/point_cloud"]
    pts = from_bin(pc["points"], "<f4", (6, 3))
    np.testing.assert_allclose(pts[:, 0], from_bin(img["data"]).ravel())
    assert pc["channels"][0]["name"] == "layer"
    assert from_bin(pc["channels"][0]["values"]).tolist() == [0, 0, 0, 1, 1, 1]
    scan = by["/bot/lidar/laser_scan"]
    assert (scan["angle_min"], scan["angle_max"], scan["angle_increment"]) == pytest.approx((0.375, -0.375, -0.25))
    assert (scan["range_min"], scan["range_max"], scan["scan_time"], scan["time_increment"]) == pytest.approx((0.01, 5.0, 0.032, 0.0))
    assert len(scan["ranges"]) == 16 and scan["intensities"] == b""


def test_pose_topic_every_basic_step_only_when_demanded():
    world = small_world(differential_drive={"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0})
    sim = FakeSim(world)
    t = Topics(sim)
    bot = sim.robots["bot"]
    for m in bot.motors.values():
        m.set_position(math.inf)
        m.set_velocity(2.0)                                    # 0.1 m/s straight ahead
    assert step(sim, t, 3) == [] and t.work["poses_built"] == 0  # nobody asked: never read or packed
    t.subscription(SUB + b"/bot/pose\0")
    msgs = decoded(step(sim, t, 2))
    assert [(n, e["type"], e["seq"], e["stamp_ns"]) for n, e, _ in msgs] == [
        ("/bot/pose", M.POSE_STAMPED, 0, 128_000_000), ("/bot/pose", M.POSE_STAMPED, 1, 160_000_000)]
    assert t.work["poses_built"] == 2
    body = msgs[-1][2]
    M.PoseStamped.model_validate(body)
    assert list(body) == ["header", "pose"] and list(body["pose"]) == ["position", "orientation"]
    assert body["header"] == {"stamp": {"sec": 0, "nanosec": 160_000_000}, "frame_id": "world"}
    pos, q = body["pose"]["position"], body["pose"]["orientation"]
    assert list(pos) == ["x", "y", "z"] and list(q) == ["x", "y", "z", "w"]
    assert pos == {"x": bot.pose.translation[0], "y": 0.0, "z": 0.0} and pos["x"] == pytest.approx(0.1 * 0.160)
    assert q == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
    t.subscription(UNSUB + b"/bot/pose\0")
    assert step(sim, t, 2) == [] and t.work["poses_built"] == 2
    rec = []
    t.set_recorder(lambda *a: rec.append(a[0]), topics=["/free/pose"])   # the recorder demands it too
    step(sim, t, 2)
    assert rec == ["/free/pose"] * 2 and t.work["poses_built"] == 4


def cfg(**kw):
    return wm.Lidar.model_validate({"device": "Lidar", "name": "l", **kw})


@pytest.mark.parametrize("kw, expected", [
    (dict(horizontal_resolution=4, number_of_layers=1, field_of_view=1.0), (0.375, -0.375, -0.25)),
    (dict(horizontal_resolution=360, number_of_layers=1, field_of_view=2 * math.pi),
     (math.pi - math.pi / 360, -math.pi + math.pi / 360, -2 * math.pi / 360)),
    (dict(horizontal_resolution=4, number_of_layers=1, type="rotating"), (math.pi, math.pi - 1.5 * math.pi, -math.pi / 2)),
    (dict(horizontal_resolution=4, number_of_layers=2), None),
    (dict(horizontal_resolution=4, number_of_layers=1, projection="planar"), None),
])
def test_laser_scan_angles(kw, expected):
    got = laser_scan_angles(cfg(**kw))
    assert got == (None if expected is None else pytest.approx(expected))


def test_laser_scan_angles_match_ray_azimuths():
    """angle_min + j * angle_increment is exactly the azimuth of column j (devices/lidar.py)."""
    lmath = pytest.importorskip("sensorium.server.devices.lidar")
    for kw in (dict(horizontal_resolution=7, number_of_layers=1, field_of_view=2.0),
               dict(horizontal_resolution=8, number_of_layers=1, type="rotating")):
        c = cfg(**kw)
        params = lmath.LidarParams(horizontal_resolution=c.horizontal_resolution, number_of_layers=1,
                                   field_of_view=c.field_of_view, type=c.type)
        a0, _, inc = laser_scan_angles(c)
        az = lmath.column_azimuths(params)
        np.testing.assert_allclose(np.unwrap(a0 + inc * np.arange(c.horizontal_resolution)), np.unwrap(az), atol=1e-12)


def test_recorder_gets_published_bytes():
    sim, t = make()
    rec = []
    t.set_recorder(lambda *a: rec.append(a), topics=["/bot/ls/value"])
    assert t.demanded == {"/bot/ls/value"}                     # recording demands
    assert sim.robots["bot"].devices["ls"].sampling_period == 32
    assert step(sim, t, 2) == []                               # nobody subscribed: nothing to send
    assert [(r[0], r[1], r[4], r[5]) for r in rec] == [("/bot/ls/value", M.ILLUMINANCE, 32_000_000, 0),
                                                       ("/bot/ls/value", M.ILLUMINANCE, 64_000_000, 1)]
    t.subscription(SUB + b"/bot/ls/")
    frames = step(sim, t)
    assert frames[0][1] is rec[-1][2] and frames[0][2] is rec[-1][3]   # the very same bytes
    t.set_recorder(None)
    t.subscription(UNSUB + b"/bot/ls/")
    assert sim.robots["bot"].devices["ls"].sampling_period == 0


def test_recorder_object_with_wants_and_demands():
    class Rec:
        def __init__(self):
            self.got = []

        def wants(self, topic):                       # records everything published ...
            return True

        def demands(self, topic):                     # ... but only asks for the clock itself
            return topic == "/clock"

        def record(self, *a):
            self.got.append(a[0])

    sim, t = make()
    r = Rec()
    t.set_recorder(r)
    assert t.demanded == {"/clock"}
    t.subscription(SUB + b"/bot/ds/")
    step(sim, t, 2)
    assert r.got == ["/clock", "/bot/ds/value", "/clock", "/bot/ds/value"]


def test_deterministic_bytes():
    def run():
        sim, t = make()
        t.subscription(SUB + b"")
        t.controller_enable("bot/ds", 64)
        t.controller_point_cloud("bot/lidar2", True)
        return step(sim, t, 6)

    assert run() == run()
