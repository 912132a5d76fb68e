"""The sans-IO server core: routing, argument validation, typed errors, step replies, sessions.

Two "sockets" are just peer identities here; frames go in and out as lists of bytes."""

from __future__ import annotations

import itertools
import math

import msgpack
import pytest
from server_fakes import FakeSim, small_world

from sensorium.schemas import services as S
from sensorium.schemas.wire import SOFT_LIMIT, ErrorCode, from_bin
from sensorium.server.services import Core

A, B = b"peer-A", b"peer-B"


class Harness:
    def __init__(self, **kw):
        self.sim = FakeSim(small_world())
        self.logs = []
        counter = itertools.count()
        self.core = Core(self.sim, new_token=lambda: f"s{next(counter)}", log=self.logs.append, **kw)
        self.ids = itertools.count(1)
        self.now = 0.0
        self.out: list[tuple[bytes, dict]] = []      # replies not yet read

    def send(self, peer, service, args=None, raw=None, rid=None):
        rid = next(self.ids) if rid is None else rid
        body = raw if raw is not None else msgpack.packb({"id": rid, "service": service, "args": {} if args is None else args})
        for frames in self.core.handle([peer, body], self.now):
            assert frames[0] == peer or frames[0] in (A, B)
            self.out.append((frames[0], msgpack.unpackb(frames[-1])))
        return rid

    def call(self, peer, service, args=None):
        rid = self.send(peer, service, args)
        return self.reply(rid)

    def reply(self, rid):
        for i, (_, r) in enumerate(self.out):
            if r["id"] == rid:
                del self.out[i]
                return r
        raise AssertionError(f"no reply to {rid}")

    def run(self):
        pubs = []
        while (t := self.core.next_advance(self.now)) is not None and t <= self.now:
            replies, p = self.core.step_once(self.now)
            pubs += p
            for frames in replies:
                self.out.append((frames[0], msgpack.unpackb(frames[-1])))
        return pubs


def ok(r):
    assert r["ok"] is True, r
    return r["result"]


def err(r, code):
    assert r["ok"] is False and r["error"]["code"] == code, r
    assert isinstance(r["error"]["message"], str) and r["error"]["message"]
    return r["error"]["message"]


@pytest.fixture
def h():
    return Harness()


def test_get_info_shape(h):
    info = S.InfoResult.model_validate(ok(h.call(A, "get_info")))
    assert info.protocol == 1 and info.world == "small" and info.basic_time_step == 32 and info.mode == "fast"
    assert [r.name for r in info.robots] == ["bot", "free"]
    assert [(d.name, d.type) for d in info.robots[0].devices] == [
        ("ls", "LightSensor"), ("ds", "DistanceSensor"), ("lidar", "Lidar"), ("lidar2", "Lidar")]
    assert info.topics[0].name == "/clock"


def test_attach_describes_devices(h):
    res = S.AttachResult.model_validate(ok(h.call(A, "attach", {"robot": "bot"})))
    assert res.session == "s0" and res.heartbeat_ms == 1000 and res.synchronization is True
    ds = res.devices[1]
    assert (ds.min_value, ds.max_value, ds.aperture, ds.sensor_type, ds.lookup_table) == (
        0.0, 2000.0, 0.3, 2, [0.0, 0.0, 0.0, 2.0, 2000.0, 0.0])
    lidar = res.devices[2]
    assert (lidar.horizontalResolution, lidar.numberOfLayers, lidar.fov, lidar.maxRange, lidar.frequency,
            lidar.point_cloud_enabled) == (4, 1, 1.0, 5.0, 10.0, False)
    assert ok(h.call(A, "get_info"))["robots"][0]["attached"] is True


@pytest.mark.parametrize("raw, code", [
    (b"\xc1\xc1", ErrorCode.BAD_REQUEST),
    (msgpack.packb([1, 2, 3]), ErrorCode.BAD_REQUEST),
    (msgpack.packb({"id": "x", "service": "get_info", "args": {}}), ErrorCode.BAD_REQUEST),
    (msgpack.packb({"id": 1, "service": "get_info", "args": 5}), ErrorCode.BAD_REQUEST),
    (b"\x00" * (SOFT_LIMIT + 1), ErrorCode.TOO_LARGE),
])
def test_undecodable_requests(h, raw, code):
    h.send(A, None, raw=raw)
    (peer, r), = h.out
    assert peer == A and r["id"] in (None, 1)
    err(r, code)


@pytest.mark.parametrize("service, args, code, words", [
    ("nope", {}, ErrorCode.UNKNOWN_SERVICE, "nope"),
    ("/ghost/robot/step", {}, ErrorCode.UNKNOWN_ROBOT, "ghost"),
    ("/bot/robot/fly", {}, ErrorCode.UNKNOWN_SERVICE, "fly"),
    ("/bot/zz/enable", {"value": 32}, ErrorCode.UNKNOWN_DEVICE, "zz"),
    ("/bot/ls/get_aperture", {}, ErrorCode.UNKNOWN_DEVICE, "get_aperture"),   # a light sensor has no aperture
    ("/bot/ds/get_info", {}, ErrorCode.UNKNOWN_DEVICE, "get_info"),
    ("/bot/ls/enable", {}, ErrorCode.INVALID_ARGUMENT, "value"),
    ("/bot/ls/enable", {"value": -1}, ErrorCode.INVALID_ARGUMENT, "value"),
    ("/bot/ls/enable", {"value": "32"}, ErrorCode.INVALID_ARGUMENT, "value"),
    ("/bot/ls/enable", {"value": 32.0}, ErrorCode.INVALID_ARGUMENT, "value"),
    ("/bot/ls/enable", {"value": True}, ErrorCode.INVALID_ARGUMENT, "value"),
    ("/bot/ls/enable", {"value": 32, "extra": 1}, ErrorCode.INVALID_ARGUMENT, "extra"),
    ("/bot/robot/step", {"duration": 33}, ErrorCode.INVALID_ARGUMENT, "multiple"),
    ("/bot/robot/step", {"duration": 0}, ErrorCode.INVALID_ARGUMENT, "duration"),
    ("/bot/robot/step", {"duration": -32}, ErrorCode.INVALID_ARGUMENT, "duration"),
    ("/bot/lidar/set_frequency", {"value": 99.0}, ErrorCode.INVALID_ARGUMENT, "frequency"),
    ("/bot/lidar/set_frequency", {"value": float("nan")}, ErrorCode.INVALID_ARGUMENT, "value"),
    ("/bot/lidar/get_layer_range_image", {"layer": 1}, ErrorCode.INVALID_ARGUMENT, "layer"),
    ("/bot/lidar/get_layer_point_cloud", {"layer": 0}, ErrorCode.WRONG_STATE, "point cloud"),
    ("/bot/robot/set_pose", {"translation": [0, 0]}, ErrorCode.INVALID_ARGUMENT, "translation"),
    ("/bot/robot/set_pose", {"translation": [0, 0, 0], "rotation": [0, 0, 0, 1]}, ErrorCode.INVALID_ARGUMENT, "axis"),
    ("set_mode", {"mode": "slow"}, ErrorCode.INVALID_ARGUMENT, "mode"),
    ("ping", {"session": "nobody"}, ErrorCode.NOT_ATTACHED, "session"),
    ("detach", {"session": "nobody"}, ErrorCode.NOT_ATTACHED, "session"),
    ("attach", {"robot": "ghost"}, ErrorCode.UNKNOWN_ROBOT, "ghost"),
    ("attach", {}, ErrorCode.INVALID_ARGUMENT, "robot"),
])
def test_error_codes(h, service, args, code, words):
    ok(h.call(A, "attach", {"robot": "bot"}))
    assert words in err(h.call(A, service, args), code)


def test_attached_only_services(h):
    for service, args in [("/bot/robot/step", {}), ("/bot/ls/enable", {"value": 32}),
                          ("/bot/lidar/enable_point_cloud", {"value": True}), ("/bot/robot/time_step", {"value": 32})]:
        err(h.call(A, service, args), ErrorCode.NOT_ATTACHED)
    ok(h.call(A, "attach", {"robot": "bot"}))
    err(h.call(B, "/bot/robot/step", {}), ErrorCode.NOT_ATTACHED)           # another socket
    assert ok(h.call(B, "/bot/ls/get_sampling_period")) == {"value": 0}     # getters: anyone
    err(h.call(B, "attach", {"robot": "bot"}), ErrorCode.ROBOT_TAKEN)


def test_step_values_and_wrong_state(h):
    ok(h.call(A, "attach", {"robot": "bot"}))
    ok(h.call(A, "/bot/ls/enable", {"value": 64}))
    ok(h.call(A, "/bot/lidar2/enable", {"value": 32}))
    ok(h.call(A, "/bot/lidar2/enable_point_cloud", {"value": True}))
    assert ok(h.call(A, "/bot/ls/get_sampling_period")) == {"value": 64}
    assert ok(h.call(A, "/bot/lidar2/is_point_cloud_enabled")) == {"status": 1}
    rid = h.send(A, "/bot/robot/step", {"duration": 64})
    assert h.out == []                                                       # deferred
    err(h.call(A, "/bot/robot/step", {}), ErrorCode.WRONG_STATE)
    h.run()
    res = S.StepResult.model_validate(ok(h.reply(rid)))
    assert res.status == 0 and res.time_ms == 64
    assert res.values["ls"].value == pytest.approx(100.064)
    img = from_bin(res.values["lidar2"].range_image, "<f4", (2, 3))
    assert img[1, 2] == pytest.approx(1.084)
    assert len(res.values["lidar2"].point_cloud) == 6 * 20
    rid = h.send(A, "/bot/robot/step", {})                                   # 96: ls not measured again
    h.run()
    assert set(ok(h.reply(rid))["values"]) == {"lidar2"}
    image = ok(h.call(B, "/bot/lidar2/get_layer_range_image", {"layer": 1}))["image"]
    assert (image["height"], image["width"], len(image["data"])) == (1, 3, 12)
    assert image["header"] == {"stamp": {"sec": 0, "nanosec": 96_000_000}, "frame_id": "bot/lidar2"}
    cloud = ok(h.call(B, "/bot/lidar2/get_layer_point_cloud", {"layer": 1}))["pointCloud"]
    assert len(cloud["points"]) == 3 * 12
    assert ok(h.call(B, "/bot/robot/get_time")) == {"value": 0.096}


def test_time_step_and_getters(h):
    ok(h.call(A, "attach", {"robot": "bot"}))
    rid = h.send(A, "/bot/robot/time_step", {"value": 0})                   # 0: one basic step
    h.run()
    assert ok(h.reply(rid)) == {"success": True}
    assert ok(h.call(A, "/bot/robot/get_basic_time_step")) == {"value": 32.0}
    assert ok(h.call(A, "/bot/robot/get_device_list")) == {"list": ["ls", "ds", "lidar", "lidar2"]}
    assert ok(h.call(A, "/bot/robot/get_number_of_devices")) == {"value": 4}
    assert ok(h.call(A, "/bot/ds/get_type")) == {"value": 2}
    assert ok(h.call(A, "/bot/ds/get_min_value")) == {"value": 0.0}
    assert ok(h.call(A, "/bot/lidar/get_frequency_info")) == {"frequency": 10.0, "minFrequency": 1.0, "maxFrequency": 25.0}
    assert ok(h.call(A, "/bot/lidar/set_frequency", {"value": 20})) == {"success": True}
    assert ok(h.call(A, "/bot/lidar/get_frequency_info"))["frequency"] == 20.0
    assert ok(h.call(B, "/bot/robot/set_pose", {"translation": [1, 2, 3], "quaternion": [0, 0, 0, 1]}))["success"]
    assert ok(h.call(B, "/bot/robot/get_pose")) == {"translation": [1.0, 2.0, 3.0], "quaternion": [0.0, 0.0, 0.0, 1.0]}


def test_detach_and_reattach(h):
    s = ok(h.call(A, "attach", {"robot": "bot"}))["session"]
    ok(h.call(A, "/bot/ls/enable", {"value": 32}))
    rid = h.send(A, "/bot/robot/step", {"duration": 64})
    assert ok(h.call(A, "detach", {"session": s})) == {}
    assert ok(h.reply(rid))["status"] == -1                                   # pending step released
    assert h.sim.robots["bot"].devices["ls"].sampling_period == 0             # controller's enables forgotten
    assert ok(h.call(B, "attach", {"robot": "bot"}))["session"] == "s1"


def test_silent_controller_released(h):
    core = h.core
    ok(h.call(A, "attach", {"robot": "bot"}))
    ok(h.call(A, "/bot/ls/enable", {"value": 32}))
    ok(h.call(B, "attach", {"robot": "free"}))
    h.now = 2.0
    h.send(B, "/free/robot/step", {})
    h.now = 3.5                                                              # A silent for 3.5 s > 3 s
    core.expire(h.now)
    assert core.lockstep.session_for("bot") is None
    assert h.sim.robots["bot"].devices["ls"].sampling_period == 0
    assert any("silent" in line for line in h.logs)
    h.run()
    assert h.sim.time_ms == 32


def test_shutdown_answers_minus_one(h):
    ok(h.call(A, "attach", {"robot": "bot"}))
    ok(h.call(B, "attach", {"robot": "free"}))
    rid = h.send(A, "/bot/robot/step", {"duration": 64})
    for frames in h.core.shutdown():
        h.out.append((frames[0], msgpack.unpackb(frames[-1])))
    assert ok(h.reply(rid)) == {"status": -1, "time_ms": 0, "values": {}}
    assert ok(h.call(B, "/free/robot/step", {}))["status"] == -1
    assert ok(h.call(B, "/free/robot/time_step", {"value": 32})) == {"success": False}
    err(h.call(B, "attach", {"robot": "bot"}), ErrorCode.SHUTTING_DOWN)


def test_step_failure_pauses_and_answers_internal(h):
    ok(h.call(A, "attach", {"robot": "bot"}))
    rid = h.send(A, "/bot/robot/step", {})
    h.sim.fail = True
    h.run()
    err(h.reply(rid), ErrorCode.INTERNAL)
    assert h.core.lockstep.mode == "pause" and any("failed to step" in line for line in h.logs)
    assert ok(h.call(A, "get_info"))["mode"] == "pause"


def test_handler_bug_is_internal(h):
    route = h.core.routes["get_info"]
    h.core.routes["get_info"] = type(route)(route.spec, lambda c: 1 / 0, None, None)
    err(h.call(A, "get_info"), ErrorCode.INTERNAL)
    assert h.core.errors == 1
    assert ok(h.call(A, "set_mode", {"mode": "realtime"})) == {"mode": "realtime"}


def test_counters_and_subscriptions(h):
    h.core.subscription(b"\x01/bot/lidar/laser_scan\0")
    ok(h.call(A, "attach", {"robot": "bot"}))
    rid = h.send(A, "/bot/robot/step", {"duration": 64})
    pubs = h.run()
    ok(h.reply(rid))
    c = S.CountersResult.model_validate(ok(h.call(A, "get_counters")))
    assert c.demanded == ["/bot/lidar/laser_scan"] and c.subscriptions == [b"/bot/lidar/laser_scan\0"]
    assert c.measurements["bot/lidar"] == 2 and c.measurements["bot/lidar2"] == 0
    assert c.counters["rays_lidar"] == 8 and c.counters.get("points_built", 0) == 0
    assert [f[0] for f in pubs] == [b"/bot/lidar/laser_scan\0"] * 2


def test_every_spec_has_a_handler():
    core = Harness().core
    for name, route in core.routes.items():
        assert callable(route.handler), name
    device_kinds = ["LightSensor", "DistanceSensor", "Lidar", "Lidar", "LightSensor"]   # small_world, both robots
    expected = sum(1 for s in S.SERVICES if s.scope == "server") + 2 * sum(1 for s in S.SERVICES if s.scope == "robot")
    expected += sum(1 for s in S.SERVICES for k in device_kinds if s.scope == "device" and k in s.devices)
    assert len(core.routes) == expected


def test_nan_value_before_first_measurement_is_not_sent(h):
    ok(h.call(A, "attach", {"robot": "bot"}))
    ok(h.call(A, "/bot/ls/enable", {"value": 64}))
    rid = h.send(A, "/bot/robot/step", {})
    h.run()
    assert ok(h.reply(rid))["values"] == {}
    assert math.isnan(ok(h.call(A, "get_info"))["real_time_factor"]) is False
