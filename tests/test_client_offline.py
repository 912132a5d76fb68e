"""The client library against an in-process fake server (tests/fake_router.py): URLs, request
correlation, pipelining, timeouts, heartbeats, reading caches, the Webots classes, topic decoding,
the CLI, and that the client imports with pyzmq + msgpack alone."""

from __future__ import annotations

import math
import os
import runpy
import struct
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import msgpack
import pytest
import zmq
from _serve import Proc, sensorium
from fake_router import BASIC, COLUMNS, LAYERS, FakeServer, distance_value, light_value, range_image

from sensorium.client import arrays, wb
from sensorium.client.connection import (
    Connection,
    ControllerURL,
    ErrorCode,
    SensoriumError,
    ServiceTimeout,
    controller_url_from_env,
    parse_controller_url,
)
from sensorium.client.topics import Subscriber, decode_frames, subscription_prefix

REPO = Path(__file__).resolve().parents[1]
WEBOTS_DIR = REPO / "sensorium" / "client" / "webots"


@pytest.fixture
def server():
    s = FakeServer()
    s.start()
    yield s
    s.stop()


@pytest.fixture
def minimal_server():
    s = FakeServer(full_descriptions=False)
    s.start()
    yield s
    s.stop()


@pytest.fixture
def robot(server):
    r = wb.RobotClient(server.endpoint, robot="r1", timeout=20.0)
    yield r
    r.close()


@pytest.fixture
def global_robot(server, monkeypatch):
    """The process-wide robot of the flat API and the classes, reset afterwards."""
    monkeypatch.setenv("SENSORIUM_CONTROLLER_URL", f"{server.endpoint}/r1")
    yield server
    wb.wb_robot_cleanup()
    robot_module = sys.modules.get("sensorium.client.webots.controller.robot")
    if robot_module is not None:
        robot_module.Robot.created = None


def _until(cond, timeout=30.0):
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, "condition not reached"
        time.sleep(0.005)


# ====================================================================== URLs

@pytest.mark.parametrize("url, endpoint, robot", [
    (None, "tcp://127.0.0.1:5560", None),
    ("", "tcp://127.0.0.1:5560", None),
    ("epuck", "tcp://127.0.0.1:5560", "epuck"),
    ("my%20bot", "tcp://127.0.0.1:5560", "my bot"),
    ("tcp://10.0.0.5:6000/epuck", "tcp://10.0.0.5:6000", "epuck"),
    ("tcp://10.0.0.5:6000/epuck/", "tcp://10.0.0.5:6000", "epuck"),
    ("tcp://10.0.0.5:6000", "tcp://10.0.0.5:6000", None),
    ("tcp://10.0.0.5:6000/", "tcp://10.0.0.5:6000", None),
    ("tcp://localhost/scout", "tcp://localhost:5560", "scout"),
    ("tcp://[::1]:7000/r%2F1", "tcp://[::1]:7000", "r/1"),
    ("TCP://host:1/a", "tcp://host:1", "a"),
    ("ipc:///tmp/sensorium-rpc/epuck", "ipc:///tmp/sensorium-rpc", "epuck"),
    ("ipc:///tmp/sensorium-rpc/", "ipc:///tmp/sensorium-rpc", None),
    ("ipc://rpc", "ipc://rpc", None),
    ("ipc://1234/epuck", "ipc://1234", "epuck"),
])
def test_parse_controller_url(url, endpoint, robot):
    parsed = parse_controller_url(url)
    assert (parsed.endpoint, parsed.robot) == (endpoint, robot)


@pytest.mark.parametrize("url", ["tcp://", "tcp://:5560/a", "tcp://h:notaport/a", "tcp://h:70000",
                                 "tcp://h:1/a/b", "http://h/a", "ipc://", "tcp://[::1:5/a"])
def test_bad_controller_urls_raise_clear_errors(url):
    with pytest.raises(SensoriumError) as err:
        parse_controller_url(url)
    assert err.value.code == ErrorCode.BAD_URL and repr(url) in str(err.value)


def test_ipc_url_naming_an_existing_socket_has_no_robot(tmp_path):
    path = tmp_path / "rpc"
    sock = zmq.Context.instance().socket(zmq.ROUTER)
    sock.bind(f"ipc://{path}")
    try:
        assert parse_controller_url(f"ipc://{path}") == ControllerURL(f"ipc://{path}", None)
        assert parse_controller_url(f"ipc://{path}/bot") == ControllerURL(f"ipc://{path}", "bot")
    finally:
        sock.close(0)


def test_controller_url_round_trips_and_env_precedence():
    url = ControllerURL("tcp://h:1", "my bot/x")
    assert str(url) == "tcp://h:1/my%20bot%2Fx"
    assert parse_controller_url(str(url)) == url
    env = {"WEBOTS_CONTROLLER_URL": "tcp://w:1/webots", "SENSORIUM_CONTROLLER_URL": "tcp://s:2/ours"}
    assert controller_url_from_env(env) == ControllerURL("tcp://s:2", "ours")
    del env["SENSORIUM_CONTROLLER_URL"]
    assert controller_url_from_env(env) == ControllerURL("tcp://w:1", "webots")
    assert controller_url_from_env({}) == ControllerURL("tcp://127.0.0.1:5560", None)
    # WEBOTS_ROBOT_NAME names the robot of a URL that names none (Webots sets it for the controllers it
    # starts; extern controllers before R2022b chose their robot with it), as it is: no percent-decoding
    assert controller_url_from_env({"WEBOTS_ROBOT_NAME": "beta %41"}) == ControllerURL("tcp://127.0.0.1:5560", "beta %41")
    assert controller_url_from_env({"WEBOTS_ROBOT_NAME": "b", "WEBOTS_CONTROLLER_URL": "tcp://w:1"}) == \
        ControllerURL("tcp://w:1", "b")
    assert controller_url_from_env({"WEBOTS_ROBOT_NAME": "b", "WEBOTS_CONTROLLER_URL": "tcp://w:1/a"}) == \
        ControllerURL("tcp://w:1", "a")                     # the URL's robot wins
    assert controller_url_from_env({"WEBOTS_ROBOT_NAME": ""}) == ControllerURL("tcp://127.0.0.1:5560", None)


# ====================================================================== connection

def test_call_correlates_and_raises_server_errors(server):
    with Connection(server.endpoint, timeout=20.0) as conn:
        info = conn.call("get_info")
        assert info["basic_time_step"] == BASIC and [r["name"] for r in info["robots"]] == ["r1", "r2"]
        with pytest.raises(SensoriumError) as err:
            conn.call("no_such_service")
        assert err.value.code == ErrorCode.UNKNOWN_SERVICE and err.value.name == "UNKNOWN_SERVICE"
        with pytest.raises(SensoriumError) as err:
            conn.call("attach", {"robot": "nobody"})
        assert err.value.code == ErrorCode.UNKNOWN_ROBOT and "nobody" in str(err.value)
        # replies matched by id even when read in another order
        a, b = conn.send("get_info"), conn.send("/r1/ls/get_lookup_table")
        assert conn.wait(b)["value"][4] == 1000.0
        assert conn.wait(a)["world"] == "fake"
        assert conn.outstanding == 0


def test_timeout_names_service_and_endpoint():
    port_sock = zmq.Context.instance().socket(zmq.ROUTER)
    port_sock.bind("tcp://127.0.0.1:*")
    endpoint = port_sock.getsockopt_string(zmq.LAST_ENDPOINT)
    port_sock.close(0)                      # nobody listens there now
    with Connection(endpoint, timeout=0.2) as conn:
        t0 = time.monotonic()
        with pytest.raises(ServiceTimeout) as err:
            conn.call("get_info")
        assert 0.15 < time.monotonic() - t0 < 2.0
        assert isinstance(err.value, TimeoutError) and err.value.code == ErrorCode.TIMEOUT
        assert "'get_info'" in str(err.value) and endpoint in str(err.value) and "sensorium serve" in str(err.value)


def test_late_reply_to_abandoned_request_is_dropped(server):
    with Connection(server.endpoint, timeout=20.0) as conn:
        server.silent = True
        with pytest.raises(ServiceTimeout):
            conn.call("get_info", timeout=0.1)
        server.silent = False
        assert conn.call("get_info")["world"] == "fake"


def test_handshake_monitor_pipe_never_fills(server):
    """libzmq sends monitor events from its I/O thread and blocks when the pipe is full, which would
    stall every socket of the shared context; the reader's RCVHWM 0 makes the pipe unbounded, and
    the monitor still ends after the first handshake."""
    with Connection(server.endpoint, timeout=20.0) as conn:
        assert conn._monitor is not None and conn._monitor.getsockopt(zmq.RCVHWM) == 0
        assert conn.call("get_info")["world"] == "fake"
        _until(lambda: conn.handshake_problem() is None and conn._monitor is None)


def test_undecodable_request_error_is_raised(server):
    with Connection(server.endpoint, timeout=20.0) as conn:
        # a server's id-less error reply (PROTOCOL §3.1) surfaces as its error
        rid = conn.send("get_info")
        conn._outstanding[rid] = "get_info"
        fake = msgpack.packb({"id": None, "ok": False, "error": {"code": 1, "message": "not msgpack"}})
        # the DEALER's monitor stopped first, as Connection.close does: closed under a live monitor
        # whose reader then goes, a late handshake event blocks libzmq's I/O thread in its send and
        # every later tcp socket of the shared context hangs (seen as the next tests' attach timeouts)
        conn._stop_monitor()
        conn._socket.close(0)
        pair = zmq.Context.instance().socket(zmq.PAIR)
        pair.bind("inproc://fake-reply")
        conn._socket = zmq.Context.instance().socket(zmq.PAIR)
        conn._socket.connect("inproc://fake-reply")
        conn._poller = zmq.Poller()
        conn._poller.register(conn._socket, zmq.POLLIN)
        pair.send(fake)
        with pytest.raises(SensoriumError) as err:
            conn.wait(rid)
        assert err.value.code == ErrorCode.BAD_REQUEST
        pair.close(0)


# ====================================================================== robot session, caching

def test_attach_description_gives_constants_without_round_trips(robot, server):
    before = len(server.services())
    r1 = robot
    assert (r1.name, r1.basic_time_step, r1.time_ms) == ("r1", BASIC, 0)
    lid = r1.by_name["lid"]
    assert r1.constant(lid, "horizontal_resolution") == COLUMNS
    assert r1.constant(lid, "number_of_layers") == LAYERS
    assert r1.constant(lid, "max_frequency") == 25.0
    assert r1.constant(r1.by_name["ds"], "distance_type") == wb.WB_DISTANCE_SENSOR_SONAR
    assert r1.constant(r1.by_name["ls"], "lookup_table") == [0.0, 0.0, 0.0, 10.0, 1000.0, 0.01]
    assert len(server.services()) == before


def test_missing_constants_fall_back_to_services_once(minimal_server):
    with wb.RobotClient(minimal_server.endpoint, robot="r1", timeout=20.0) as r1:
        lid, ds = r1.by_name["lid"], r1.by_name["ds"]
        for _ in range(2):
            assert r1.constant(lid, "fov") == 1.5
            assert r1.constant(lid, "min_frequency") == 1.0
            assert r1.constant(ds, "aperture") == 0.2
            assert r1.constant(ds, "distance_type") == 2
        services = minimal_server.services()
        assert services.count("/r1/lid/get_info") == 1
        assert services.count("/r1/lid/get_frequency_info") == 1
        assert services.count("/r1/ds/get_aperture") == 1


def test_values_cached_nan_first_kept_after_disable(robot, server, capsys):
    r1 = robot
    ls, ds = r1.by_name["ls"], r1.by_name["ds"]
    assert math.isnan(ls.value) and math.isnan(ds.value)
    r1.enable(ls, 64, "test")
    r1.enable(ds, 32, "test")
    assert r1.step() == 0 and r1.time_ms == 32
    assert math.isnan(ls.value)                      # first value one period after enable
    assert ds.value == distance_value(32)
    assert r1.step(64) == 0 and r1.time_ms == 96
    assert ls.value == light_value(64) and ds.value == distance_value(96)
    n = len(server.services())
    for _ in range(100):
        assert ds.value == distance_value(96)        # reads are local
    assert len(server.services()) == n
    r1.enable(ds, 0, "test")
    assert server.services()[-1] == "/r1/ds/enable"
    r1.step()
    assert ds.value == distance_value(96)            # last value kept after disable


def test_step_rules(robot, server):
    with pytest.raises(SensoriumError) as err:
        robot.step(33)
    assert err.value.code == ErrorCode.INVALID_ARGUMENT
    with pytest.raises(SensoriumError):
        robot.step(1.5)
    assert robot.step(64.0) == 0 and robot.time_ms == 64
    robot.step_begin()
    with pytest.raises(SensoriumError) as err:
        robot.step_begin()
    assert err.value.code == ErrorCode.WRONG_STATE
    assert robot.step_end() == 0
    with pytest.raises(SensoriumError):
        robot.step_end()


def test_pipelined_step_begin_end(robot, server):
    r1, ds = robot, robot.by_name["ds"]
    r1.enable(ds, 32, "test")
    server.hold = True
    assert r1.step_begin(64) == 0
    r1.enable(r1.by_name["ls"], 32, "test")          # an RPC while the step is pending
    assert math.isnan(ds.value)                      # values change only at step_end
    time.sleep(0.05)
    assert r1.conn.outstanding == 1
    server.release()
    assert r1.step_end() == 0 and r1.time_ms == 64
    assert ds.value == distance_value(64)


def test_second_controller_for_a_robot_is_refused(robot, server):
    with pytest.raises(SensoriumError) as err:
        wb.RobotClient(server.endpoint, robot="r1", timeout=20.0)
    assert err.value.code == ErrorCode.ROBOT_TAKEN
    robot.close()
    again = wb.RobotClient(server.endpoint, robot="r1", timeout=20.0)   # released by detach
    again.close()


def test_url_without_robot_needs_a_single_robot_world(server):
    with pytest.raises(SensoriumError) as err:
        wb.RobotClient(server.endpoint, timeout=20.0)
    assert "r1, r2" in str(err.value) and "/ROBOT" in str(err.value)


def test_shutdown_status_minus_one_sticks(robot, server):
    assert robot.step() == 0
    server.quitting = True
    assert robot.step() == -1
    n = len(server.services())
    assert robot.step() == -1 and robot.step_begin() == -1 and robot.step_end() == -1
    robot.enable(robot.by_name["ls"], 32, "test")    # no RPC after the end: local only
    assert len(server.services()) == n


def test_heartbeat_pings_from_its_own_socket(robot, server):
    _until(lambda: len(server.pings) >= 3)          # heartbeat 100 ms
    assert robot.conn.heartbeat.problem() is None


def test_a_blocked_step_waits_for_a_silent_server_and_ends_when_it_is_gone(server, capsys):
    """A server that answers nothing (a long step) but whose ZeroMQ connection lives is busy: the
    step waits past lost_after_s. Once its socket closes (the server gone), the step ends with -1
    at the heartbeat's next look, not after the 20 s timeout."""
    r1 = wb.RobotClient(server.endpoint, robot="r1", timeout=20.0, lost_after_s=0.4)
    hb = r1.conn.heartbeat
    try:
        server.hold = True
        r1.step_begin()
        server.silent = True
        status: list[int] = []
        waiter = threading.Thread(target=lambda: status.append(r1.step_end()), daemon=True)
        waiter.start()
        _until(lambda: status or time.monotonic() - hb.last_reply > 2.0)      # five times lost_after_s
        assert status == [], "the step gave up on a busy server"
        t0 = time.monotonic()
        server.stop()                                  # its socket closes: gone
        waiter.join(30)
        assert status == [-1]
        assert time.monotonic() - t0 < 10.0            # lost_after_s and the grace, not the 20 s timeout
        assert "no answer" in capsys.readouterr().err
        assert r1.step() == -1
    finally:
        r1.close()


def test_dropped_session_ends_the_step(server, capsys):
    r1 = wb.RobotClient(server.endpoint, robot="r1", timeout=20.0)
    try:
        server.hold = True
        r1.step_begin()
        _until(lambda: "r1" in server.pending)
        server.attached.clear()           # the server forgets the session: pings now fail
        assert r1.step_end() == -1
        assert "released the robot" in capsys.readouterr().err
    finally:
        r1.close()


# ====================================================================== flat API

def test_flat_api(global_robot, capsys):
    server = global_robot
    wb.wb_robot_init()
    wb.wb_robot_init()                                 # idempotent
    assert wb.wb_robot_get_name() == "r1" and wb.wb_robot_get_basic_time_step() == 32.0
    assert wb.wb_robot_get_number_of_devices() == 3
    ls, ds, lid = (wb.wb_robot_get_device(n) for n in ("ls", "ds", "lid"))
    assert (ls, ds, lid) == (1, 2, 3) and capsys.readouterr().err == ""
    assert wb.wb_robot_get_device("nope") == 0                         # Webots warns: a misspelt name shows
    assert capsys.readouterr().err == 'Warning: wb_robot_get_device(): robot "r1" has no device "nope".\n'
    assert wb.wb_robot_get_device("") == 0 and "NULL or empty name" in capsys.readouterr().err
    assert wb.wb_robot_get_device_by_index(2) == lid and capsys.readouterr().err == ""
    assert wb.wb_robot_get_device_by_index(3) == wb.wb_robot_get_device_by_index(-1) == 0
    assert capsys.readouterr().err.count("wb_robot_get_device_by_index(): index") == 2
    assert wb.wb_device_get_name(ds) == "ds"
    with pytest.raises(SensoriumError) as err:
        wb.wb_lidar_get_fov(ls)
    assert "LightSensor" in str(err.value)
    with pytest.raises(SensoriumError):
        wb.wb_light_sensor_get_value(99)
    with pytest.raises(SensoriumError):
        wb.wb_light_sensor_enable(ls, -1)

    assert math.isnan(wb.wb_light_sensor_get_value(ls))
    assert "wb_light_sensor_get_value() called for a disabled device" in capsys.readouterr().err
    wb.wb_light_sensor_get_value(ls)
    assert capsys.readouterr().err == ""               # once per disable
    wb.wb_light_sensor_enable(ls, 32)
    wb.wb_distance_sensor_enable(ds, 64)
    assert wb.wb_light_sensor_get_sampling_period(ls) == 32
    assert wb.wb_robot_step(64) == 0 and wb.wb_robot_get_time() == 0.064
    assert wb.wb_light_sensor_get_value(ls) == light_value(64)
    assert wb.wb_distance_sensor_get_value(ds) == distance_value(64)
    assert wb.wb_light_sensor_get_lookup_table_size(ls) == 2
    assert wb.wb_distance_sensor_get_lookup_table(ds)[:2] == [0.0, 1000.0]
    assert (wb.wb_distance_sensor_get_min_value(ds), wb.wb_distance_sensor_get_max_value(ds)) == (0.0, 1000.0)
    assert wb.wb_distance_sensor_get_aperture(ds) == 0.2
    assert wb.wb_distance_sensor_get_type(ds) == wb.WB_DISTANCE_SENSOR_SONAR
    wb.wb_light_sensor_disable(ls)
    assert wb.wb_light_sensor_get_sampling_period(ls) == 0
    assert wb.wb_light_sensor_get_value(ls) == light_value(64)
    assert wb.wb_robot_step_begin(32) == 0 and wb.wb_robot_step_end() == 0
    wb.wb_robot_cleanup()
    assert "detach" in server.services()
    with pytest.raises(SensoriumError):
        wb.wb_robot_get_time()


def test_flat_lidar(global_robot, capsys):
    np = pytest.importorskip("numpy")
    wb.wb_robot_init()
    lid = wb.wb_robot_get_device("lid")
    img = wb.wb_lidar_get_range_image(lid)             # disabled, never measured: zeros + message
    assert img.shape == (LAYERS * COLUMNS,) and not img.any()
    assert "wb_lidar_enable" in capsys.readouterr().err
    assert wb.wb_lidar_get_layer_range_image(lid, 0) is None
    assert wb.wb_lidar_get_point_cloud(lid) is None and wb.wb_lidar_get_number_of_points(lid) == 0
    wb.wb_lidar_enable(lid, 32)
    wb.wb_lidar_enable_point_cloud(lid)
    assert wb.wb_lidar_is_point_cloud_enabled(lid)
    wb.wb_robot_step(32)
    img = wb.wb_lidar_get_range_image(lid)
    assert img.dtype == np.float32 and img.tobytes() == range_image(32)
    assert not img.flags.writeable
    assert wb.wb_lidar_get_layer_range_image(lid, 1).tolist() == img[COLUMNS:].tolist()
    with pytest.raises(SensoriumError):
        wb.wb_lidar_get_layer_range_image(lid, LAYERS)
    cloud = wb.wb_lidar_get_point_cloud(lid)
    assert len(cloud) == wb.wb_lidar_get_number_of_points(lid) == LAYERS * COLUMNS
    assert cloud["layer_id"].tolist() == [0] * COLUMNS + [1] * COLUMNS and cloud["time"][0] == np.float32(0.032)
    assert wb.wb_lidar_get_layer_point_cloud(lid, 1)["x"].tolist() == [4.0, 5.0, 6.0, 7.0]
    assert (wb.wb_lidar_get_horizontal_resolution(lid), wb.wb_lidar_get_number_of_layers(lid)) == (COLUMNS, LAYERS)
    assert (wb.wb_lidar_get_fov(lid), wb.wb_lidar_get_vertical_fov(lid)) == (1.5, 0.2)
    assert (wb.wb_lidar_get_min_range(lid), wb.wb_lidar_get_max_range(lid)) == (0.05, 6.0)
    wb.wb_lidar_set_frequency(lid, 12.5)
    assert wb.wb_lidar_get_frequency(lid) == 12.5 and global_robot.robots["r1"]["lid"].frequency == 12.5
    with pytest.raises(SensoriumError):
        wb.wb_lidar_set_frequency(lid, 30.0)
    # numpy scalars (an index or a rate from an array) are numbers here, as Webots' ctypes takes them
    assert wb.wb_lidar_get_layer_range_image(lid, np.int64(1)).tolist() == img[COLUMNS:].tolist()
    wb.wb_lidar_set_frequency(lid, np.float32(10.0))
    assert wb.wb_lidar_get_frequency(lid) == 10.0 and type(global_robot.robots["r1"]["lid"].frequency) is float
    with pytest.raises(SensoriumError):
        wb.wb_lidar_get_layer_range_image(lid, 1.0)                   # a layer is an integer
    wb.wb_keyboard_enable(np.int32(32))
    assert wb.wb_keyboard_get_sampling_period() == 32
    wb.wb_lidar_disable_point_cloud(lid)
    assert wb.wb_lidar_get_point_cloud(lid) is None


# ====================================================================== Webots classes

def _controller_module():
    import sensorium.client.webots.controller as controller

    return controller


def test_controller_classes(global_robot, capsys):
    controller = _controller_module()
    robot = controller.Robot()
    capsys.readouterr()
    again = controller.Robot()           # Webots prints an error; here the second one shares the first's state
    assert "only one Robot instance" in capsys.readouterr().err
    assert again.getName() == "r1" and again.getDevice("ls") is robot.getDevice("ls")
    assert robot.getName() == "r1" and robot.getBasicTimeStep() == 32.0 and robot.getNumberOfDevices() == 3
    ls = robot.getDevice("ls")
    ds = robot.getDistanceSensor("ds")
    assert "DEPRECATION" in capsys.readouterr().err
    lidar = robot.getDeviceByIndex(2)
    assert isinstance(ls, controller.LightSensor) and isinstance(ds, controller.DistanceSensor)
    assert isinstance(lidar, controller.Lidar) and lidar.getName() == "lid"
    assert robot.getDevice("nope") is None and "not found" in capsys.readouterr().err
    assert controller.DistanceSensor.SONAR == ds.getType() == 2 and ds.INFRA_RED == 1
    ls.enable(32)
    ds.sampling_period = 64
    lidar.enable(32)
    lidar.enablePointCloud()
    assert (ls.getSamplingPeriod(), ds.sampling_period) == (32, 64)
    assert math.isnan(ls.getValue()) and math.isnan(ds.value)
    assert robot.step() == 0 and robot.getTime() == 0.032
    assert ls.value == light_value(32)
    assert robot.step(64) == 0 and robot.time == 0.096
    assert ds.getValue() == distance_value(64)
    assert ls.getLookupTable() == [0.0, 0.0, 0.0, 10.0, 1000.0, 0.01]
    assert (ds.getMinValue(), ds.getMaxValue(), ds.getAperture()) == (0.0, 1000.0, 0.2)

    expected = list(struct.unpack(f"<{LAYERS * COLUMNS}f", range_image(96)))
    assert lidar.getRangeImage() == expected
    assert lidar.getRangeImage(data_type="buffer") == range_image(96)
    assert lidar.getRangeImageArray() == [expected[:COLUMNS], expected[COLUMNS:]]
    assert lidar.getLayerRangeImage(1) == expected[COLUMNS:]
    points = lidar.getPointCloud()
    assert len(points) == lidar.getNumberOfPoints() == 8
    assert isinstance(points[5], controller.LidarPoint) and points[5].layer_id == 1 == points[5].layer and points[5].x == 5.0
    assert len(lidar.getPointCloud(data_type="buffer")) == 8 * 20
    assert [p.x for p in lidar.getLayerPointCloud(1)] == [4.0, 5.0, 6.0, 7.0]
    assert (lidar.getHorizontalResolution(), lidar.getNumberOfLayers(), lidar.getFov()) == (COLUMNS, LAYERS, 1.5)
    assert (lidar.getMinFrequency(), lidar.getMaxFrequency(), lidar.getFrequency()) == (1.0, 25.0, 10.0)
    lidar.setFrequency(20)
    assert lidar.frequency == 20.0
    with pytest.raises(ValueError):
        lidar.getRangeImage(data_type="numpy")
    ls.disable()
    assert ls.getSamplingPeriod() == 0 and ls.getValue() == light_value(96)
    assert robot.stepBegin(32) == 0 and robot.stepEnd() == 0


# ====================================================================== motors

LEFT, RIGHT = "left wheel motor", "right wheel motor"


def _step_args(server) -> list[dict]:
    with server.lock:
        return [args for service, args in server.log if service.endswith("/robot/step")]


def _requests(server) -> list[str]:
    """Services called, heartbeat pings left out."""
    return [s for s in server.services() if s != "ping"]


def test_motor_commands_are_buffered_and_sent_with_the_step(server, capsys):
    with wb.RobotClient(server.endpoint, robot="r2", timeout=20.0) as r2:
        left, right = r2.by_name[LEFT], r2.by_name[RIGHT]
        assert (left.kind, left.max_velocity, left.target_position, left.velocity) == ("RotationalMotor", 6.28, 0.0, 0.0)
        n = len(_requests(server))
        r2.set_motor_position(left, math.inf, "test")
        r2.set_motor_velocity(left, 2.0, "test")
        r2.set_motor_velocity(left, 3, "test")                 # the last command wins
        r2.set_motor_position(right, float("-inf"), "test")
        assert len(_requests(server)) == n                     # no round trip
        assert r2.step() == 0
        assert _step_args(server)[-1] == {"duration": BASIC, "motors": {LEFT: {"position": math.inf, "velocity": 3.0},
                                                                        RIGHT: {"position": -math.inf}}}
        assert len(_requests(server)) == n + 1
        assert r2.step() == 0
        assert _step_args(server)[-1] == {"duration": BASIC}     # nothing new: no motors key
        # clamped locally, with Webots' warning
        r2.set_motor_velocity(right, -10.0, "test")
        assert right.velocity == -6.28
        assert capsys.readouterr().err == ('WARNING: RotationalMotor "right wheel motor": The requested velocity -10 '
                                           "exceeds 'maxVelocity' = 6.28.\n")
        r2.set_motor_velocity(left, math.inf, "test")            # Webots clamps inf too
        assert left.velocity == 6.28
        # commands set while a step is pending go with the next one
        server.hold = True
        r2.step_begin()
        r2.set_motor_velocity(left, 1.0, "test")
        _until(lambda: len(_step_args(server)) == 3)
        assert _step_args(server)[-1]["motors"] == {RIGHT: {"velocity": -6.28}, LEFT: {"velocity": 6.28}}
        server.release()
        assert r2.step_end() == 0
        r2.step()
        assert _step_args(server)[-1]["motors"] == {LEFT: {"velocity": 1.0}}
        # non-numbers raise (Python's ctypes would too); nothing is buffered
        for bad in ("fast", True, None):
            with pytest.raises(SensoriumError) as err:
                r2.set_motor_velocity(left, bad, "wb_motor_set_velocity")
            assert err.value.code == ErrorCode.INVALID_ARGUMENT and "wb_motor_set_velocity()" in str(err.value)
        capsys.readouterr()
        before = left.target_position
        r2.set_motor_position(left, math.nan, "wb_motor_set_position")          # Webots prints and ignores
        assert "invalid 'position' argument (NaN)" in capsys.readouterr().err
        assert left.target_position == before and r2.motor_commands == {}
        r2.set_motor_position(left, 1.5, "test")
        # Webots prints and ignores a NaN velocity and a negative one in position control
        r2.set_motor_velocity(left, math.nan, "wb_motor_set_velocity")
        r2.set_motor_velocity(left, -1.0, "wb_motor_set_velocity")
        err_text = capsys.readouterr().err
        assert "invalid 'velocity' argument (NaN)" in err_text
        assert "negative 'velocity' argument in position control mode (1.5)." in err_text     # the target
        assert r2.motor_commands == {LEFT: {"position": 1.5}} and left.velocity == 1.0


def test_motor_description_defaults_follow_libcontroller(minimal_server):
    with wb.RobotClient(minimal_server.endpoint, robot="r2", timeout=20.0) as r2:
        left = r2.by_name[LEFT]                                  # description with name and type only
        assert (left.max_velocity, left.velocity, left.target_position) == (10.0, 10.0, 0.0)


def test_flat_motor_api(server, monkeypatch, capsys):
    monkeypatch.setenv("SENSORIUM_CONTROLLER_URL", f"{server.endpoint}/r2")
    try:
        wb.wb_robot_init()
        assert wb.wb_robot_get_number_of_devices() == 3
        left, right = wb.wb_robot_get_device(LEFT), wb.wb_robot_get_device(RIGHT)
        assert (left, right) == (2, 3) and wb.wb_device_get_type_name(left) == "RotationalMotor"
        assert wb.wb_motor_get_max_velocity(left) == 6.28 and wb.wb_motor_get_velocity(left) == 0.0
        wb.wb_motor_set_position(left, math.inf)
        wb.wb_motor_set_velocity(left, 7.0)
        assert "exceeds 'maxVelocity' = 6.28" in capsys.readouterr().err
        assert (wb.wb_motor_get_target_position(left), wb.wb_motor_get_velocity(left)) == (math.inf, 6.28)
        assert (wb.wb_motor_get_min_position(left), wb.wb_motor_get_max_position(left)) == (0.0, 0.0)
        assert wb.wb_motor_get_type(left) == wb.WB_ROTATIONAL and wb.wb_motor_get_position_sensor(left) == 0
        with pytest.raises(SensoriumError) as err:
            wb.wb_motor_set_velocity(wb.wb_robot_get_device("ds"), 1.0)
        assert "DistanceSensor, not a RotationalMotor" in str(err.value)
        with pytest.raises(SensoriumError):
            wb.wb_distance_sensor_enable(left, 32)
        assert wb.wb_robot_step(64) == 0
        assert _step_args(server)[-1] == {"duration": 64, "motors": {LEFT: {"position": math.inf, "velocity": 6.28}}}
    finally:
        wb.wb_robot_cleanup()


def test_motor_class(server, monkeypatch, capsys):
    controller = _controller_module()
    monkeypatch.setenv("SENSORIUM_CONTROLLER_URL", f"{server.endpoint}/r2")
    try:
        robot = controller.Robot()
        left = robot.getDevice(LEFT)
        right = robot.getMotor(RIGHT)
        assert "DEPRECATION: Robot.getMotor is deprecated" in capsys.readouterr().err
        assert isinstance(left, controller.RotationalMotor) and isinstance(right, controller.Motor)
        assert robot.devices[LEFT] is left and robot.getDeviceByIndex(2) is right and left.getName() == LEFT
        assert left.getPositionSensor() is None and left.position_sensor is None and left.getBrake() is None
        assert left.getType() == controller.Motor.ROTATIONAL == left.type
        assert (left.getMaxVelocity(), left.max_velocity, left.getMinPosition(), left.max_position) == (6.28, 6.28, 0.0, 0.0)
        for m in (left, right):
            m.setPosition(float("inf"))
        left.setVelocity(1.25)
        right.target_velocity = -2.5                             # Webots' property spelling
        assert (left.getVelocity(), right.target_velocity, left.getTargetPosition(), right.target_position) == (
            1.25, -2.5, math.inf, math.inf)
        assert robot.step() == 0
        assert _step_args(server)[-1]["motors"] == {LEFT: {"position": math.inf, "velocity": 1.25},
                                                    RIGHT: {"position": math.inf, "velocity": -2.5}}
    finally:
        wb.wb_robot_cleanup()
        controller.Robot.created = None


def test_gps_degrees_minutes_seconds_text_as_the_c_library_also_for_nan():
    """libController's text, "%d° %d′ %d″" of C's (int) of the degrees, minutes and seconds (each
    truncated toward zero); a GPS value before its first sample is NaN and must not raise: C's (int)
    of it on x86-64 is INT_MIN, and so for infinities."""
    convert = wb.wb_gps_convert_to_degrees_minutes_seconds
    assert convert(46.5202) == "46\u00b0 31\u2032 12\u2033"             # 31.212′: 12.72″ truncated
    assert convert(-1.5) == "-1\u00b0 -30\u2032 0\u2033"
    assert convert(-73.94) == "-73\u00b0 -56\u2032 -23\u2033"     # −73.94 + 73 is −0.9399999999999977: 23.99…″
    indefinite = "-2147483648"
    assert convert(math.nan) == f"{indefinite}\u00b0 {indefinite}\u2032 {indefinite}\u2033"
    assert convert(math.inf) == f"{indefinite}\u00b0 {indefinite}\u2032 {indefinite}\u2033"


def test_numpy_scalars_are_numbers_as_in_webots(server, monkeypatch):
    """An RL policy's actions are numpy float32s and configs hold numpy ints: Webots' ctypes wrappers
    take them (c_double / c_int convert them), so setVelocity(action[0]), enable(np.int64(32)) and
    step(np.int64(32)) work; they are sent as plain numbers."""
    np = pytest.importorskip("numpy")
    monkeypatch.setenv("SENSORIUM_CONTROLLER_URL", f"{server.endpoint}/r2")
    try:
        wb.wb_robot_init()
        left, ds = wb.wb_robot_get_device(LEFT), wb.wb_robot_get_device("ds")
        action = np.array([1.5, -0.25], dtype=np.float32)
        wb.wb_motor_set_position(left, np.float64(np.inf))
        wb.wb_motor_set_velocity(left, action[0])
        wb.wb_distance_sensor_enable(ds, np.int64(32))
        assert wb.wb_distance_sensor_get_sampling_period(ds) == 32
        assert wb.wb_robot_step(np.int32(32)) == 0
        sent = _step_args(server)[-1]
        assert sent == {"duration": 32, "motors": {LEFT: {"position": math.inf, "velocity": 1.5}}}
        assert type(sent["duration"]) is int and type(sent["motors"][LEFT]["velocity"]) is float
        wb.wb_motor_set_position(left, action[1])
        assert wb.wb_motor_get_target_position(left) == -0.25
        for bad in (np.bool_(True), "1.5", None):
            with pytest.raises(SensoriumError):
                wb.wb_motor_set_velocity(left, bad)
        with pytest.raises(SensoriumError):
            wb.wb_robot_step(np.float32(32.5))
    finally:
        wb.wb_robot_cleanup()


# ====================================================================== topics

def _frames(topic: str, msg_type: str, seq: int, body: dict) -> list[bytes]:
    return [topic.encode() + b"\0", msgpack.packb({"type": msg_type, "seq": seq, "stamp_ns": 32_000_000}),
            msgpack.packb(body, use_bin_type=True)]


HEADER = {"stamp": {"sec": 0, "nanosec": 32_000_000}, "frame_id": "r1/lid"}


def test_decode_messages_arrays_per_type():
    np = pytest.importorskip("numpy")
    ranges = struct.pack("<3f", 1.0, float("inf"), 2.5)
    topic, kind, seq, stamp, body = decode_frames(_frames("/r1/lid/laser_scan", "sensor_msgs/msg/LaserScan", 4, {
        "header": HEADER, "angle_min": 0.5, "ranges": ranges, "intensities": b""}))
    assert (topic, kind, seq, stamp) == ("/r1/lid/laser_scan", "sensor_msgs/msg/LaserScan", 4, 32_000_000)
    assert body["ranges"].dtype == np.float32 and body["ranges"].tolist() == [1.0, math.inf, 2.5]
    assert body["intensities"].size == 0
    _, _, _, _, body = decode_frames(_frames("/r1/lid/range_image", "sensor_msgs/msg/Image", 0, {
        "header": HEADER, "height": 2, "width": 4, "encoding": "32FC1", "is_bigendian": 0, "step": 16,
        "data": range_image(32)}))
    assert body["data"].shape == (2, 4) and body["data"].tobytes() == range_image(32)
    pts = struct.pack("<6f", 1, 2, 3, 4, 5, 6)
    _, _, _, _, body = decode_frames(_frames("/r1/lid/point_cloud", "sensor_msgs/msg/PointCloud", 0, {
        "header": HEADER, "points": pts, "channels": [{"name": "layer", "values": struct.pack("<2f", 0, 1)}]}))
    assert body["points"].shape == (2, 3) and body["points"][1].tolist() == [4, 5, 6]
    assert body["channels"][0]["values"].tolist() == [0.0, 1.0]
    _, _, _, _, body = decode_frames(_frames("/r1/ds/value", "sensor_msgs/msg/Range", 0, {
        "header": HEADER, "radiation_type": 1, "range": 0.25}))
    assert body["range"] == 0.25
    with pytest.raises(SensoriumError):
        decode_frames([b"/x\0", b"\xc1", b"\x80"])
    with pytest.raises(SensoriumError):
        decode_frames([b"/x\0", b"\x80"])


def test_decode_without_numpy(monkeypatch):
    monkeypatch.setattr(arrays, "_numpy", None)
    monkeypatch.setattr(arrays, "_numpy_checked", True)
    _, _, _, _, body = decode_frames(_frames("/r1/lid/range_image", "sensor_msgs/msg/Image", 0, {
        "height": 2, "width": 4, "encoding": "32FC1", "data": range_image(32)}))
    assert body["data"].typecode == "f" and list(body["data"]) == list(struct.unpack("<8f", range_image(32)))
    assert arrays.points(struct.pack("<fffif", 1, 2, 3, 4, 5)) == [(1.0, 2.0, 3.0, 4, 5.0)]


def test_subscription_prefixes_are_exact_unless_slash():
    assert subscription_prefix("/r1/ps1/value") == b"/r1/ps1/value\0"
    assert subscription_prefix("/r1/") == b"/r1/"
    assert subscription_prefix("") == b""


def test_subscriber_receives_filters_and_counts_gaps():
    pub = zmq.Context.instance().socket(zmq.XPUB)
    pub.bind("tcp://127.0.0.1:*")
    url = pub.getsockopt_string(zmq.LAST_ENDPOINT)
    with Subscriber(url, "/r1/ps1/value", "/r2/") as sub:
        subs = {pub.recv(), pub.recv()}           # wait until both subscriptions reached the publisher
        assert subs == {b"\x01/r1/ps1/value\0", b"\x01/r2/"}
        for topic, seq in [("/r1/ps10/value", 0), ("/r1/ps1/value", 0), ("/r1/ps1/value", 1),
                           ("/r2/ds/value", 7), ("/r1/ps1/value", 4), ("/r2/ds/value", 8)]:
            pub.send_multipart(_frames(topic, "sensor_msgs/msg/Range", seq, {"range": float(seq)}))
        got = [sub.recv(timeout=20.0) for _ in range(5)]
        assert [(m.topic, m.seq, m.gap) for m in got] == [
            ("/r1/ps1/value", 0, 0), ("/r1/ps1/value", 1, 0), ("/r2/ds/value", 7, 0),
            ("/r1/ps1/value", 4, 2), ("/r2/ds/value", 8, 0)]
        assert got[3].body["range"] == 4.0 and got[0].stamp == 0.032
        assert sub.dropped == {"/r1/ps1/value": 2}
        assert sub.recv(timeout=0.05) is None
    pub.close(0)


# ====================================================================== import lightness and CLI

BLOCKER = """
import sys
HEAVY = ("numpy", "pydantic", "embreex", "trimesh", "yaml", "mcap")
class Blocker:
    strict = True          # also refuse sensorium.server / sensorium.schemas
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in HEAVY or (self.strict and name.startswith(("sensorium.server", "sensorium.schemas"))):
            raise ImportError("blocked: " + name)
        return None
blocker = Blocker()
sys.meta_path.insert(0, blocker)
"""


def _run(code: str, env: dict | None = None, timeout: float = 30) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


def test_client_imports_with_pyzmq_and_msgpack_only():
    code = BLOCKER + textwrap.dedent(f"""
        import sensorium.client, sensorium.client.connection, sensorium.client.wb, sensorium.client.topics
        import sensorium.cli.client, sensorium.cli.topics, sensorium.cli.services, sensorium.client.webots.controller
        sys.path.insert(0, {str(WEBOTS_DIR)!r})
        from controller import Robot, LightSensor, DistanceSensor, Lidar, LidarPoint, Motor, RotationalMotor
        bad = [m for m in sys.modules if m.split(".")[0] in HEAVY
               or m.startswith(("sensorium.server", "sensorium.schemas"))]
        assert not bad, bad
        # the `sensorium` command line (all subcommands' options) builds without the heavy packages
        blocker.strict = False
        import sensorium.cli
        sensorium.cli.build_parser().parse_args(["controller", "x.py", "--robot", "r"])
        assert not [m for m in sys.modules if m.split(".")[0] in HEAVY]
        print("ok")
    """)
    proc = _run(code)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "ok"


def test_controller_without_numpy_end_to_end(server):
    """A Webots controller in a process where numpy cannot be imported: lists and array('f')."""
    code = BLOCKER + textwrap.dedent(f"""
        sys.path.insert(0, {str(WEBOTS_DIR)!r})
        from controller import Robot
        from sensorium.client import wb
        robot = Robot()
        lidar = robot.getDevice("lid")
        lidar.enable(32)
        lidar.enablePointCloud()
        robot.getDevice("ds").enable(32)
        assert robot.step() == 0
        print(robot.getDevice("ds").getValue())
        print(lidar.getRangeImage()[:3])
        print(type(wb.wb_lidar_get_range_image(lidar.getTag())).__name__)
        print(wb.wb_lidar_get_point_cloud(lidar.getTag())[5])
        assert "numpy" not in sys.modules
    """)
    proc = _run(code, {"SENSORIUM_CONTROLLER_URL": f"{server.endpoint}/r1"})
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert float(lines[0]) == distance_value(32)
    assert eval(lines[1]) == list(struct.unpack("<3f", range_image(32)[:12]))
    assert lines[2] == "array"
    assert eval(lines[3])[:4] == (5.0, -5.0, 0.5, 1)


def _sensorium(*args: str, env: dict | None = None, timeout: float = 30) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True,
                          timeout=timeout, env={**os.environ, **(env or {})}, cwd=str(REPO))


def test_cli_controller_launcher(server, tmp_path):
    helper = tmp_path / "helper.py"
    helper.write_text("SCALE = 2\n")
    script = tmp_path / "ctrl.py"
    script.write_text(textwrap.dedent("""
        import sys
        from controller import Robot
        import helper                           # the script's folder is on sys.path, as in Webots
        robot = Robot()
        ds = robot.getDevice("ds")
        ds.enable(int(robot.getBasicTimeStep()))
        n = 0
        while robot.step() != -1 and n < 3:
            print(robot.getName(), robot.getTime(), ds.getValue() * helper.SCALE)
            n += 1
        sys.exit(int(sys.argv[1]))
    """))
    proc = _sensorium("controller", str(script), "--robot", "r2", "--url", server.endpoint, "7")
    assert proc.returncode == 7, proc.stderr
    assert proc.stdout.splitlines() == [f"r2 {t / 1000} {distance_value(t) * 2}" for t in (32, 64, 96)]
    assert "detach" in server.services()

    crash = tmp_path / "crash.py"
    crash.write_text("from controller import Robot\nrobot = Robot()\nraise RuntimeError('boom')\n")
    proc = _sensorium("controller", str(crash), "--url", f"{server.endpoint}/r1")
    assert proc.returncode == 1 and "RuntimeError: boom" in proc.stderr and "runpy" not in proc.stderr

    proc = _sensorium("controller", str(crash), "--url", f"{server.endpoint}/nobody")
    assert proc.returncode == 1 and "UNKNOWN_ROBOT" in proc.stderr
    assert _sensorium("controller", str(tmp_path / "missing.py")).returncode == 2


def test_cli_topics(server):
    proc = _sensorium("topics", "--url", server.endpoint)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["/r1/ls/value", "sensor_msgs/msg/Illuminance", "/clock", "rosgraph_msgs/msg/Clock"]


def test_cli_echo():
    pub = zmq.Context.instance().socket(zmq.XPUB)
    pub.bind("tcp://127.0.0.1:*")
    url = pub.getsockopt_string(zmq.LAST_ENDPOINT)
    with Proc(sensorium("echo", "/r1/lid/laser_scan", "--url", url, "--count", "2", "--timeout", "60")) as proc:
        try:
            assert pub.poll(60000) and pub.recv() == b"\x01/r1/lid/laser_scan\0"
            for seq in (0, 3):
                pub.send_multipart(_frames("/r1/lid/laser_scan", "sensor_msgs/msg/LaserScan", seq, {
                    "header": HEADER, "range_min": 0.05, "ranges": struct.pack("<3f", 1.0, float("inf"), 2.5)}))
            code = proc.wait(90)
        finally:
            pub.close(0)
    out, err = proc.stdout(), proc.stderr()
    assert code == 0, err
    docs = out.split("---\n")
    assert len(docs) == 3 and docs[2] == ""                   # two YAML documents, each ended by ---
    assert docs[0].startswith("# /r1/lid/laser_scan [sensor_msgs/msg/LaserScan] seq=0 t=0.032 s\n")
    assert "range_min: 0.05\n" in docs[0] and "ranges: [1.0, .inf, 2.5]\n" in docs[0]   # short arrays in full
    assert "2 message(s) of /r1/lid/laser_scan lost" in err


def test_heartbeat_thread_stops_on_cleanup(server):
    r1 = wb.RobotClient(server.endpoint, robot="r1", timeout=20.0)
    hb = r1.conn.heartbeat
    r1.close()
    assert not hb.is_alive()
    assert not any(t.name == "sensorium-heartbeat" and t.is_alive() for t in threading.enumerate())


def test_webots_signatures_and_by_name_construction_offline(global_robot, capsys):
    """Webots' keywords and defaults work (``step(time_step=...)``, ``enable(p=...)``), a sensor built
    by name is enabled at the basic time step as in Webots (one from ``getDevice`` is not), and so is
    a hand-built ``Keyboard()``; the robot's own keyboard stays off."""
    controller = _controller_module()
    robot = controller.Robot()
    by_name = controller.DistanceSensor("ds")
    assert by_name.getSamplingPeriod() == 32 and by_name.sampling_period == 32
    assert controller.LightSensor("ls", 64).getSamplingPeriod() == 64
    assert robot.getDevice("lid").getSamplingPeriod() == 0
    assert robot.step(time_step=32) == 0 and robot.getTime() == 0.032
    assert by_name.getValue() == distance_value(32)
    robot.getDevice("ls").enable(p=96)
    assert robot.getDevice("ls").sampling_period == 96
    assert robot.keyboard.getSamplingPeriod() == 0
    assert controller.Keyboard().getSamplingPeriod() == 32
    assert controller.Keyboard().get_key() == "" and robot.keyboard.getKeyCode() == -1
    capsys.readouterr()
    robot.battery_sensor_sampling_period = None         # Webots: None enables at the basic time step
    assert robot.batterySensorGetSamplingPeriod() == robot.battery_sensor_sampling_period == 32
    with pytest.raises(TypeError):
        robot.step(duration=32)                         # not Webots' name


def test_keyboard_mode_and_supervisor_refusal_offline(global_robot, capsys):
    controller = _controller_module()
    robot = controller.Robot()
    assert robot.getMode() == robot.MODE_SIMULATION == 0 and robot.getSupervisor() is False
    assert (robot.EVENT_KEYBOARD, robot.EVENT_NO_EVENT, robot.EVENT_QUIT) == (4, 0, -1)
    kb = robot.getKeyboard()
    capsys.readouterr()
    assert kb.getKey() == -1 and "wb_keyboard_enable" in capsys.readouterr().err    # disabled: Webots' message
    kb.enable(32)
    assert kb.getSamplingPeriod() == 32 and kb.getKey() == -1 and capsys.readouterr().err == ""
    assert controller.Keyboard.UP == 315 and controller.Keyboard.CONTROL == 0x20000
    # a plain robot's controller gets Webots' refusal and NULL answers, without a round trip
    sup = controller.Supervisor()                       # a second instance: shares the first one's state
    capsys.readouterr()
    assert sup.getFromDef("anything") is None and sup.getSelf() is None
    assert wb.wb_supervisor_node_get_field(1, "translation") is None
    assert "can only be used in a 'Supervisor' controller" in capsys.readouterr().err


def test_a_controller_that_does_not_compile_shows_its_error_not_the_launchers_frames(tmp_path, capsys):
    """A syntax error ran no frame of the script, so the launcher's frames (sensorium/cli/client.py,
    runpy) were printed above it; now only the script's file, line and caret, as `python script.py`."""
    from sensorium.cli.client import _print_script_traceback

    script = tmp_path / "ctrl.py"
    script.write_text("from controller import Robot\ndef (:\n")
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SyntaxError as exc:
        _print_script_traceback(exc, str(script))
    err = capsys.readouterr().err
    assert f'File "{script}", line 2' in err and "SyntaxError: invalid syntax" in err
    assert "Traceback" not in err and "runpy" not in err and "test_client_offline" not in err


def test_launcher_options_after_the_scripts_own_arguments_are_the_scripts_with_a_note(capsys):
    """`sensorium controller SCRIPT -v --url U` gave --url U to the script and attached to the default
    URL, timing out there 10 s later without saying why; the script still gets them, and one line says so."""
    import argparse

    from sensorium.cli.client import _take_launcher_options

    args = argparse.Namespace(args=["--robot", "scout", "-v", "--url", "tcp://127.0.0.1:5580"], robot=None, url=None)
    assert _take_launcher_options(args) is None
    assert (args.robot, args.url, args.args) == ("scout", None, ["-v", "--url", "tcp://127.0.0.1:5580"])
    assert capsys.readouterr().err == ("sensorium controller: note: --url after the script's argument '-v' is passed "
                                       "to the script, not taken by sensorium (give --robot/--url before the script's "
                                       "arguments; `--` before them keeps them the script's without this note)\n")
    for given in (["--url=tcp://h:1", "-v"], ["--", "-v", "--url", "x"], ["-v", "--speed", "2"]):
        args = argparse.Namespace(args=given, robot=None, url=None)
        assert _take_launcher_options(args) is None
        assert capsys.readouterr().err == ""
    assert args.args == ["-v", "--speed", "2"]
