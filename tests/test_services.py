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
from sensorium.server.daemon.services import Core

A, B = b"peer-A", b"peer-B"


class Harness:
    def __init__(self, world=None, **kw):
        self.sim = FakeSim(world or small_world())
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


def test_reattached_controller_gets_no_reading_of_the_previous_one(h):
    """A new controller's first value is its own first sample (NaN before, as in Webots), not the
    last reading a previous controller of the robot left in the device."""
    s = ok(h.call(A, "attach", {"robot": "bot"}))["session"]
    ok(h.call(A, "/bot/ls/enable", {"value": 64}))
    rid = h.send(A, "/bot/robot/step", {"duration": 64})
    h.run()
    assert set(ok(h.reply(rid))["values"]) == {"ls"}                          # sampled at 64
    ok(h.call(A, "detach", {"session": s}))
    ok(h.call(B, "attach", {"robot": "bot"}))
    ok(h.call(B, "/bot/ls/enable", {"value": 64}))
    rid = h.send(B, "/bot/robot/step", {})                                   # 96: not sampled yet
    h.run()
    assert ok(h.reply(rid))["values"] == {}
    rid = h.send(B, "/bot/robot/step", {})                                   # 128: its first sample
    h.run()
    assert ok(h.reply(rid))["values"]["ls"]["value"] == pytest.approx(100.128)


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


# ====================================================================== motors and poses

DRIVE = {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0}
LEFT, RIGHT = "left wheel motor", "right wheel motor"


@pytest.fixture
def hm():
    """``bot`` with a differential drive (two wheel motors)."""
    return Harness(small_world(differential_drive=DRIVE))


def test_motors_are_devices_after_the_sensors(hm):
    info = S.InfoResult.model_validate(ok(hm.call(A, "get_info")))
    assert [(d.name, d.type) for d in info.robots[0].devices][-3:] == [
        ("lidar2", "Lidar"), (LEFT, "RotationalMotor"), (RIGHT, "RotationalMotor")]
    assert "/bot/pose" in [t.name for t in info.topics] and "/free/pose" in [t.name for t in info.topics]
    res = S.AttachResult.model_validate(ok(hm.call(A, "attach", {"robot": "bot"})))
    assert [d.name for d in res.devices] == ["ls", "ds", "lidar", "lidar2", LEFT, RIGHT]
    assert res.devices[4].model_dump() == {"name": LEFT, "type": "RotationalMotor", "maxVelocity": 10.0,
                                           "minPosition": 0.0, "maxPosition": 0.0, "targetPosition": 0.0,
                                           "velocity": 10.0, "model": "", "index": 4, "simulated": True}
    assert ok(hm.call(B, "/bot/robot/get_device_list")) == {"list": ["ls", "ds", "lidar", "lidar2", LEFT, RIGHT]}
    assert ok(hm.call(B, "/bot/robot/get_number_of_devices")) == {"value": 6}
    assert ok(hm.call(B, "/free/robot/get_number_of_devices")) == {"value": 1}      # no drive, no motors


def test_motor_commands_travel_with_the_step_and_apply_at_once(hm):
    ok(hm.call(A, "attach", {"robot": "bot"}))
    left, right = (hm.sim.robots["bot"].motors[n] for n in (LEFT, RIGHT))
    rid = hm.send(A, "/bot/robot/step", {"duration": 64, "motors": {
        LEFT: {"position": math.inf, "velocity": 4.0}, RIGHT: {"position": math.inf, "velocity": 4}}})
    assert hm.out == []                                                  # deferred, but already applied:
    assert (left.target_position, left.velocity, right.velocity) == (math.inf, 4.0, 4.0)
    assert hm.sim.time_ms == 0
    hm.run()
    assert ok(hm.reply(rid))["time_ms"] == 64
    pose = ok(hm.call(B, "/bot/robot/get_pose"))
    assert pose["translation"] == pytest.approx([0.05 * 4.0 * 0.064, 0.0, 0.0], abs=1e-15)   # 2 basic steps straight
    assert pose["quaternion"] == [0.0, 0.0, 0.0, 1.0]
    # one key only; the other keeps its value; a clamped velocity; -inf is velocity control too
    rid = hm.send(A, "/bot/robot/step", {"motors": {LEFT: {"velocity": 99.0}, RIGHT: {"position": -math.inf}}})
    assert (left.velocity, left.target_position, right.velocity, right.target_position) == (10.0, math.inf, 4.0, -math.inf)
    hm.run()
    ok(hm.reply(rid))
    assert ok(hm.call(B, f"/bot/{LEFT}/get_velocity")) == {"value": 10.0}
    assert ok(hm.call(B, f"/bot/{RIGHT}/get_target_position")) == {"value": -math.inf}
    # position control: the wheel turns toward the target at |velocity| and stops there
    start_left, start_right = left.position, right.position
    rid = hm.send(A, "/bot/robot/step", {"motors": {LEFT: {"position": start_left + 0.5, "velocity": 10.0},
                                                    RIGHT: {"position": start_right, "velocity": 1.0}}})
    hm.run()
    ok(hm.reply(rid))
    assert left.position == pytest.approx(start_left + 10.0 * 0.032) and right.position == start_right
    for _ in range(2):
        rid = hm.send(A, "/bot/robot/step", {})
        hm.run()
        ok(hm.reply(rid))
    assert left.position == pytest.approx(start_left + 0.5)


@pytest.mark.parametrize("motors, code, words", [
    ({"ghost motor": {"velocity": 1.0}}, ErrorCode.UNKNOWN_DEVICE, "ghost motor"),
    ({"ds": {"velocity": 1.0}}, ErrorCode.UNKNOWN_DEVICE, "not a motor"),
    ({LEFT: {"velocity": 1.0}, "nope": {"velocity": 1.0}}, ErrorCode.UNKNOWN_DEVICE, "nope"),   # nothing applied
    ({LEFT: {"position": math.nan}}, ErrorCode.INVALID_ARGUMENT, "NaN"),
    ({LEFT: {"velocity": math.nan}}, ErrorCode.INVALID_ARGUMENT, "velocity"),
    ({LEFT: {"velocity": math.inf}}, ErrorCode.INVALID_ARGUMENT, "finite"),
    ({LEFT: {"velocity": -math.inf}}, ErrorCode.INVALID_ARGUMENT, "finite"),
    ({LEFT: {"velocity": "fast"}}, ErrorCode.INVALID_ARGUMENT, "velocity"),
    ({LEFT: {"velocity": True}}, ErrorCode.INVALID_ARGUMENT, "velocity"),
    ({LEFT: {"torque": 1.0}}, ErrorCode.INVALID_ARGUMENT, "torque"),
    ({LEFT: 1.0}, ErrorCode.INVALID_ARGUMENT, LEFT),
    ([1.0], ErrorCode.INVALID_ARGUMENT, "motors"),
])
def test_motor_command_validation(hm, motors, code, words):
    ok(hm.call(A, "attach", {"robot": "bot"}))
    left = hm.sim.robots["bot"].motors[LEFT]
    assert words in err(hm.call(A, "/bot/robot/step", {"motors": motors}), code)
    assert (left.target_position, left.velocity) == (0.0, left.max_velocity)   # a refused request applies nothing
    assert hm.core.lockstep.session_for("bot").pending is None


def test_refused_step_applies_no_motor_command(hm):
    ok(hm.call(A, "attach", {"robot": "bot"}))
    left = hm.sim.robots["bot"].motors[LEFT]
    err(hm.call(A, "/bot/robot/step", {"duration": -1, "motors": {LEFT: {"velocity": 1.0}}}), ErrorCode.INVALID_ARGUMENT)
    hm.send(A, "/bot/robot/step", {"motors": {LEFT: {"velocity": 1.0}}})
    err(hm.call(A, "/bot/robot/step", {"motors": {LEFT: {"velocity": 2.0}}}), ErrorCode.WRONG_STATE)
    assert left.velocity == 1.0
    err(hm.call(B, "/bot/robot/step", {"motors": {LEFT: {"velocity": 3.0}}}), ErrorCode.NOT_ATTACHED)
    assert left.velocity == 1.0


def test_motor_services(hm):
    m = f"/bot/{LEFT}/"
    err(hm.call(A, m + "set_velocity", {"value": 1.0}), ErrorCode.NOT_ATTACHED)       # setters: the controller only
    err(hm.call(A, m + "set_position", {"value": 1.0}), ErrorCode.NOT_ATTACHED)
    assert ok(hm.call(B, m + "get_max_velocity")) == {"value": 10.0}                   # getters: anyone
    ok(hm.call(A, "attach", {"robot": "bot"}))
    assert ok(hm.call(A, m + "set_position", {"value": math.inf})) == {"success": True}
    assert ok(hm.call(A, m + "set_velocity", {"value": -12})) == {"success": True}
    assert ok(hm.call(B, m + "get_target_position")) == {"value": math.inf}
    assert ok(hm.call(B, m + "get_velocity")) == {"value": -10.0}                      # clamped
    assert "NaN" in err(hm.call(A, m + "set_position", {"value": math.nan}), ErrorCode.INVALID_ARGUMENT)
    err(hm.call(A, m + "set_velocity", {"value": math.inf}), ErrorCode.INVALID_ARGUMENT)
    err(hm.call(A, m + "set_velocity", {}), ErrorCode.INVALID_ARGUMENT)
    assert "RotationalMotor bot/left wheel motor has no service 'enable'" in err(
        hm.call(A, m + "enable", {"value": 32}), ErrorCode.UNKNOWN_DEVICE)
    err(hm.call(A, "/bot/ls/set_velocity", {"value": 1.0}), ErrorCode.UNKNOWN_DEVICE)
    err(hm.call(A, "/free/left wheel motor/get_velocity"), ErrorCode.UNKNOWN_DEVICE)
    rid = hm.send(A, "/bot/robot/step", {})
    hm.run()
    ok(hm.reply(rid))
    assert ok(hm.call(B, "/bot/robot/get_pose"))["translation"][0] != 0.0             # turning backwards on the spot
    # released, the robot stops: its wheels hold where they are; a new controller sees that
    angle = hm.sim.robots["bot"].motors[LEFT].position
    assert angle < 0.0
    ok(hm.call(A, "detach", {"session": "s0"}))
    desc = ok(hm.call(B, "attach", {"robot": "bot"}))["devices"][4]
    assert (desc["targetPosition"], desc["velocity"]) == (angle, -10.0)


def test_set_pose_resets_the_drive(hm):
    ok(hm.call(A, "attach", {"robot": "bot"}))
    motors = {LEFT: {"position": math.inf, "velocity": 2.0}, RIGHT: {"position": math.inf, "velocity": 2.0}}
    rid = hm.send(A, "/bot/robot/step", {"motors": motors})
    hm.run()
    ok(hm.reply(rid))
    assert ok(hm.call(B, "/bot/robot/set_pose", {"translation": [1.0, 2.0, 0.5], "quaternion": [0, 0, 0, 1]}))["success"]
    rid = hm.send(A, "/bot/robot/step", {})
    hm.run()
    ok(hm.reply(rid))
    pose = ok(hm.call(B, "/bot/robot/get_pose"))
    assert pose["translation"] == pytest.approx([1.0 + 0.05 * 2.0 * 0.032, 2.0, 0.5], abs=1e-15)   # on from the new pose


def test_pose_topic_is_lazy_in_counters(hm):
    ok(hm.call(A, "attach", {"robot": "bot"}))
    rid = hm.send(A, "/bot/robot/step", {"duration": 64})
    assert hm.run() == []
    ok(hm.reply(rid))
    assert ok(hm.call(A, "get_counters"))["counters"]["poses_built"] == 0
    hm.core.subscription(b"\x01/bot/pose\0")
    assert ok(hm.call(A, "get_counters"))["demanded"] == ["/bot/pose"]
    rid = hm.send(A, "/bot/robot/step", {"duration": 96, "motors": {LEFT: {"position": math.inf, "velocity": 1.0}}})
    pubs = hm.run()
    ok(hm.reply(rid))
    assert ok(hm.call(A, "get_counters"))["counters"]["poses_built"] == 3
    assert [f[0] for f in pubs] == [b"/bot/pose\0"] * 3
    last = msgpack.unpackb(pubs[-1][2])
    pose = ok(hm.call(B, "/bot/robot/get_pose"))
    p, q = last["pose"]["position"], last["pose"]["orientation"]
    assert [p["x"], p["y"], p["z"]] == pose["translation"] and [q["x"], q["y"], q["z"], q["w"]] == pose["quaternion"]
    assert last["header"] == {"stamp": {"sec": 0, "nanosec": 160_000_000}, "frame_id": "world"}
    hm.core.subscription(b"\x00/bot/pose\0")
    rid = hm.send(A, "/bot/robot/step", {})
    assert hm.run() == []
    assert ok(hm.call(A, "get_counters"))["counters"]["poses_built"] == 3


def test_motor_routes_counted():
    core = Harness(small_world(differential_drive=DRIVE)).core
    names = S.service_names({"bot": {**{d: k for d, k in [("ls", "LightSensor"), ("ds", "DistanceSensor"),
                                                          ("lidar", "Lidar"), ("lidar2", "Lidar")]},
                                     LEFT: "RotationalMotor", RIGHT: "RotationalMotor"},
                             "free": {"ls": "LightSensor"}})
    assert set(core.routes) == set(names)
    assert {n for n in names if n.startswith(f"/bot/{LEFT}/")} == {
        f"/bot/{LEFT}/{i}" for i in ("set_position", "set_velocity", "get_velocity", "get_max_velocity", "get_target_position")}


def test_a_union_arguments_refusal_is_one_short_line():
    # SetFieldArgs.value takes one of several types: pydantic reports every member's mismatch, each echoing
    # the value; the line names the argument once, with what was really wrong, the value shortened
    from pydantic import ValidationError

    from sensorium.server.daemon.services import _arg_errors

    def line(value):
        with pytest.raises(ValidationError) as e:
            S.SetFieldArgs.model_validate({"node": 1, "field": "translation", "value": value})
        return _arg_errors(e.value, S.SetFieldArgs)

    assert line(math.nan) == "argument 'value': Input should be a finite number (got nan)"
    assert line([1.0, math.inf]) == "argument 'value.1': Input should be a finite number (got inf)"
    assert line([1.0, "a"]) == "argument 'value.1': Input should be a valid number (got 'a')"
    assert line([1.0]).startswith("argument 'value': List should have at least 2 items")
    assert line({"a": 1}) == "argument 'value': Input should be one of bool, int, float, list[float], str (got {'a': 1})"
    long = line("x" * 5000)
    assert long.startswith("argument 'value': String should have at most 4096 characters (got 'xxx")
    assert long.endswith("...)") and len(long) < 200 and long.count("argument") == 1
