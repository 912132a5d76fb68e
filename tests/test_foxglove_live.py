"""`sensorium serve --foxglove`: a Foxglove client we did not write (@foxglove/ws-protocol under Node)
lists the channels, subscribes, decodes with independent decoders (@foxglove/rosmsg2-serialization,
protobufjs), and every value is compared with what the server publishes on ZeroMQ; subscribing and
unsubscribing moves the server's demand."""

from __future__ import annotations

import base64
import itertools
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import msgpack
import numpy as np
import pytest
import zmq
from _node import NodeProcess, require_node
from _serve import Served, sensorium, serve, wait_until

pytest.importorskip("foxglove")

WORLD = Path(__file__).parent / "worlds" / "server.yaml"
ROOT = Path(__file__).resolve().parents[1]


class Rpc:
    ids = itertools.count(1)

    def __init__(self, ctx: zmq.Context, endpoint: str):
        self.sock = ctx.socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.connect(endpoint)
        self.session: str | None = None

    def ok(self, service: str, args: dict | None = None, timeout: float = 30.0):
        rid = next(self.ids)
        self.sock.send(msgpack.packb({"id": rid, "service": service, "args": args or {}}))
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.sock.poll(100):
                r = msgpack.unpackb(self.sock.recv_multipart()[-1], raw=False)
                if r["id"] == rid:
                    assert r["ok"] is True, r
                    return r["result"]
        raise TimeoutError(service)



SENSORS = ["/bot/ls/value", "/bot/ds/value", "/bot/lidar/laser_scan", "/bot/lidar/point_cloud", "/bot/lidar/range_image"]


@pytest.fixture()
def live():
    require_node()
    srv = serve(WORLD, "--precision", "fast", "--heartbeat-ms", "2000", "--foxglove", "127.0.0.1:0")
    ctx = zmq.Context()
    node = None
    try:
        assert srv.fields["foxglove"].startswith("ws://127.0.0.1:")
        node = NodeProcess("live_client.js", srv.fields["foxglove"])
        yield srv, ctx, node
    finally:
        if node is not None:
            node.close()
        code = srv.stop(signal.SIGTERM)
        ctx.destroy(0)
        err = srv.stderr()
        assert code == 0, err
        assert "sensorium: Foxglove viewer: " in err and "not converted" not in err, err


def test_channels_subscriptions_demand_and_values(live):
    srv, ctx, node = live
    rpc = Rpc(ctx, srv.fields["rpc"])
    adv = node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
    chans = {c["topic"]: c for c in adv["channels"]}
    # every topic of the server is a channel Foxglove decodes, plus /tf and /scene
    topics = {t["name"]: t["type"] for t in rpc.ok("get_info")["topics"]}
    assert set(chans) == set(topics) | {"/tf", "/scene"}
    for name, typ in topics.items():
        want = "sensor_msgs/msg/PointCloud2" if typ == "sensor_msgs/msg/PointCloud" else typ
        assert (chans[name]["encoding"], chans[name]["schemaEncoding"], chans[name]["schemaName"]) == ("cdr", "ros2msg", want)
    assert (chans["/tf"]["schemaName"], chans["/tf"]["encoding"]) == ("foxglove.FrameTransforms", "protobuf")
    assert (chans["/scene"]["schemaName"], chans["/scene"]["encoding"]) == ("foxglove.SceneUpdate", "protobuf")
    assert not [e for e in node.drain() if e["event"] == "error"]

    assert rpc.ok("get_counters")["demanded"] == []
    for t in [*SENSORS, "/tf", "/scene"]:
        node.send(cmd="subscribe", topic=t)
    poses = {"/bot/pose", "/free/pose", "/bot2/pose", "/rover/pose"}
    wait_until(lambda: set(rpc.ok("get_counters")["demanded"]) == set(SENSORS) | poses, what="viewer demand")

    # the server's own values: a ZeroMQ subscriber to the same topics
    sub = ctx.socket(zmq.SUB)
    sub.setsockopt(zmq.LINGER, 0)
    sub.connect(srv.fields["pub"])
    for t in [*SENSORS, "/bot/pose"]:
        sub.setsockopt(zmq.SUBSCRIBE, t.encode() + b"\0")
    wait_until(lambda: len(rpc.ok("get_counters")["subscriptions"]) == 6, what="zmq subscriptions")
    rpc.session = rpc.ok("attach", {"robot": "bot"})["session"]
    ours: dict[tuple[str, int], dict] = {}
    raw: dict[tuple[str, int], bytes] = {}
    for _ in range(6):
        rpc.ok("/bot/robot/step")
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and len(ours) < 6 * 6:
        if sub.poll(100):
            topic, env, body = sub.recv_multipart()
            key = (topic[:-1].decode(), msgpack.unpackb(env)["stamp_ns"])
            ours[key] = msgpack.unpackb(body, raw=False)
            raw[key] = body
    sub.close(0)
    assert len(ours) == 36

    def got(topic: str, ns: int) -> dict:
        return event(topic, ns)["msg"]

    def event(topic: str, ns: int) -> dict:
        return node.find(lambda e: e["event"] == "message" and e["topic"] == topic and e["log_time"] == ns,
                         what=f"{topic} at {ns}")

    last = 6 * 16 * 1_000_000
    # Illuminance: float64 end to end
    b = ours[("/bot/ls/value", last)]
    m = got("/bot/ls/value", last)
    assert m["illuminance"] == b["illuminance"] and m["header"]["frame_id"] == "bot/ls"
    assert m["header"]["stamp"]["sec"] * 10**9 + m["header"]["stamp"]["nanosec"] == last
    # Range: float32 fields
    b, m = ours[("/bot/ds/value", last)], got("/bot/ds/value", last)
    for k in ("range", "min_range", "max_range", "field_of_view"):
        assert m[k] == float(np.float32(b[k])), k
    assert m["radiation_type"] == b["radiation_type"] == 0
    # LaserScan
    b, m = ours[("/bot/lidar/laser_scan", last)], got("/bot/lidar/laser_scan", last)
    assert m["ranges"] == np.frombuffer(b["ranges"], "<f4").astype(float).tolist()
    for k in ("angle_min", "angle_max", "angle_increment", "range_min", "range_max", "scan_time"):
        assert m[k] == float(np.float32(b[k])), k
    assert len(m["ranges"]) == 16 and math.isfinite(m["ranges"][8])
    # PointCloud → PointCloud2: x, y, z, layer as FLOAT32 fields
    b, m = ours[("/bot/lidar/point_cloud", last)], got("/bot/lidar/point_cloud", last)
    assert [f["name"] for f in m["fields"]] == ["x", "y", "z", "layer"]
    assert all(f["datatype"] == 7 for f in m["fields"]) and m["point_step"] == 16 and m["width"] == 16
    rec = np.frombuffer(bytes(m["data"]), "<f4").reshape(-1, 4)
    assert np.array_equal(rec[:, :3], np.frombuffer(b["points"], "<f4").reshape(-1, 3), equal_nan=True)
    assert np.array_equal(rec[:, 3], np.frombuffer(b["channels"][0]["values"], "<f4"))
    # Image 32FC1
    b, m = ours[("/bot/lidar/range_image", last)], got("/bot/lidar/range_image", last)
    assert (m["encoding"], m["width"], m["height"], m["step"]) == ("32FC1", 16, 1, 64)
    assert bytes(m["data"]) == b["data"]
    # /tf: world → bot at the published pose, bot → bot/<device> mounts from the world file
    tf = got("/tf", last)["transforms"]
    pose = ours[("/bot/pose", last)]["pose"]
    frames = {(t["parent_frame_id"], t["child_frame_id"]): t for t in tf}
    w = frames[("world", "bot")]
    assert [w["translation"][k] for k in "xyz"] == [pose["position"][k] for k in "xyz"]
    assert [w["rotation"][k] for k in "xyzw"] == [pose["orientation"][k] for k in "xyzw"]
    assert [frames[("bot", "bot/ds")]["translation"][k] for k in "xyz"] == [0.05, 0.0, 0.1]
    assert set(frames) == {("world", "bot"), ("bot", "bot/ls"), ("bot", "bot/ds"), ("bot", "bot/lidar"),
                           ("bot", "bot/lidar2")}
    # /scene: the floor (4 x 4 plane), the wall box and the lamp, at their places
    scene = node.find(lambda e: e["event"] == "message" and e["topic"] == "/scene", what="scene")["msg"]
    ents = {e["id"]: e for e in scene["entities"]}
    assert set(ents) == {"solid/floor", "solid/wall", "light/lamp"}
    wall = ents["solid/wall"]["cubes"][0]
    assert ents["solid/wall"]["frame_id"] == "world"
    assert [wall["size"][k] for k in "xyz"] == [0.1, 2.0, 0.5]
    assert [wall["pose"]["position"][k] for k in "xyz"] == [1.0, 0.0, 0.25]
    assert [ents["solid/floor"]["cubes"][0]["size"][k] for k in "xyz"] == [4.0, 4.0, 0.0]
    lamp = ents["light/lamp"]["spheres"][0]
    assert [lamp["pose"]["position"][k] for k in "xyz"] == [0.5, 0.5, 0.5]
    # the live bytes are the ROS 2 export's bytes (rosbags' serialize_cdr, the rosbag2 exporter's encoder)
    from sensorium.server.recording.export import CdrEncoder

    enc = CdrEncoder("jazzy", pointcloud2=True)
    for topic in SENSORS:
        assert base64.b64decode(event(topic, last)["raw"]) == enc.encode_generic(topics[topic], raw[(topic, last)]), topic
    # simulated time is the server time
    node.find(lambda e: e["event"] == "time" and e["ns"] == last, what="server time")
    assert not [e for e in node.drain() + node.seen if e["event"] == "error"]

    # unsubscribing stops the work: no demand, no measurement while the controller steps on
    for t in [*SENSORS, "/tf", "/scene"]:
        node.send(cmd="unsubscribe", topic=t)
    wait_until(lambda: rpc.ok("get_counters")["demanded"] == [], what="demand gone")
    before = rpc.ok("get_counters")["measurements"]
    for _ in range(3):
        rpc.ok("/bot/robot/step")
    after = rpc.ok("get_counters")["measurements"]
    assert after == before
    # and subscribing again brings it back for that topic only
    node.send(cmd="subscribe", topic="/bot/ls/value")
    wait_until(lambda: rpc.ok("get_counters")["demanded"] == ["/bot/ls/value"], what="demand back")
    rpc.ok("/bot/robot/step")
    again = rpc.ok("get_counters")["measurements"]
    assert again["bot/ls"] == after["bot/ls"] + 1 and again["bot/ds"] == after["bot/ds"]


def test_disconnect_releases_demand(live):
    srv, ctx, node = live
    rpc = Rpc(ctx, srv.fields["rpc"])
    node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
    node.send(cmd="subscribe", topic="/bot/lidar/point_cloud")
    wait_until(lambda: rpc.ok("get_counters")["demanded"] == ["/bot/lidar/point_cloud"], what="demand")
    node.proc.kill()                          # a viewer that vanishes without unsubscribing
    node.proc.wait()
    wait_until(lambda: rpc.ok("get_counters")["demanded"] == [], what="demand released")


def test_bad_foxglove_address_is_one_line(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, "-m", "sensorium", "serve", str(WORLD), "--rpc", "tcp://127.0.0.1:0", "--pub",
                        "tcp://127.0.0.1:0", "--foxglove", "localhost:http"], capture_output=True, text=True, env=env,
                       timeout=60)
    assert r.returncode == 1
    assert r.stderr.strip().splitlines() == ["sensorium serve: --foxglove 'localhost:http': port 'http' is not a number"]


def test_replay_serves_foxglove(tmp_path):
    require_node()
    from _recdata import make_recording

    from sensorium.server.recording.reader import Recording

    path = tmp_path / "rec.mcap"
    make_recording(path, steps=20)
    with Recording(path) as rec:
        values = {msgpack.unpackb(m.data, raw=False)["illuminance"] for m in rec.messages(["/epuck/ls0/value"])}
    replay = Served(sensorium("replay", str(path), "--loop", "--rate", "1", "--pub", "tcp://127.0.0.1:0", "--rpc",
                              "tcp://127.0.0.1:0", "--foxglove", "127.0.0.1:0", "--no-progress"),
                    "sensorium: Foxglove viewer at ")
    node = None
    try:
        url = replay.wait_ready().ready_line.split("Foxglove viewer at ", 1)[1].strip()
        assert url and url.startswith("ws://127.0.0.1:")
        node = NodeProcess("live_client.js", url)
        node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
        node.send(cmd="subscribe", topic="/epuck/ls0/value")
        m = node.wait_for(lambda e: e["event"] == "message" and e["topic"] == "/epuck/ls0/value", what="replayed")
        assert m["msg"]["illuminance"] in values and m["msg"]["header"]["frame_id"] == "epuck/ls0"
    finally:
        if node is not None:
            node.close()
        replay.stop(signal.SIGTERM)


def test_the_default_client_and_the_sdk_name_are_both_accepted(live):
    """@foxglove/ws-protocol at its defaults offers foxglove.websocket.v1 (the SDK's server alone
    answers it with HTTP 400); the front names it back, and foxglove.sdk.v1 still works."""
    srv, _ctx, node = live
    opened = node.wait_for(lambda e: e["event"] == "open", what="open")
    assert opened["protocol"] == "foxglove.websocket.v1"
    node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
    other = NodeProcess("live_client.js", srv.fields["foxglove"], "sdk")
    try:
        assert other.wait_for(lambda e: e["event"] == "open", what="open (sdk)")["protocol"] == "foxglove.sdk.v1"
        other.wait_for(lambda e: e["event"] == "advertise", what="advertise (sdk)")
    finally:
        other.close()


def test_a_viewer_alone_is_told_why_nothing_moves(live):
    srv, ctx, node = live
    status = node.wait_for(lambda e: e["event"] == "status", what="waiting status")
    assert status["level"] == 1 and status["id"] == "sensorium-waiting"
    for robot in ("'bot'", "'bot2'", "'rover'"):
        assert robot in status["message"], status
    assert "'free'" not in status["message"]                       # asynchronous: never waited for
    assert "sensorium controller" in status["message"] and "--watch" in status["message"]
    rpc = Rpc(ctx, srv.fields["rpc"])
    rpc.session = rpc.ok("attach", {"robot": "bot"})["session"]
    rpc.ok("/bot/robot/step")
    gone = node.wait_for(lambda e: e["event"] == "removeStatus", what="status removed once the world steps")
    assert gone["ids"] == ["sensorium-waiting"]


def test_watch_shows_the_warehouse_lidar_without_a_controller():
    """`serve warehouse --watch`: its <extern> forklift runs as <none>, the world steps by itself
    and a viewer gets the lidar's scans (no controller, no edit of the world)."""
    require_node()
    srv = serve("warehouse", "--precision", "fast", "--watch", "--foxglove", "127.0.0.1:0")
    node = None
    try:
        node = NodeProcess("live_client.js", srv.fields["foxglove"])
        adv = node.wait_for(lambda e: e["event"] == "advertise", what="advertise")
        scans = [c["topic"] for c in adv["channels"] if c["schemaName"] == "sensor_msgs/msg/PointCloud2"]
        assert scans, adv
        node.send(cmd="subscribe", topic=scans[0], brief=True)
        m = node.wait_for(lambda e: e["event"] == "message" and e["topic"] == scans[0], what="a point cloud")
        assert m["msg"]["width"] > 0
        assert not [e for e in node.seen if e["event"] == "status"]
    finally:
        if node is not None:
            node.close()
        srv.stop(signal.SIGTERM)
        assert "waiting for a controller" not in srv.stderr()


def _rss_kib(pid: int, key: str = "VmRSS") -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1])
    raise AssertionError(f"no {key} for {pid}")


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc")
def test_200_vanishing_viewers_leave_memory_bounded_and_the_log_quiet():
    """Issue 28: after 200 viewers (20 at a time) subscribed to everything (the warehouse's 16-layer
    lidar cloud is ~260 KB) and vanished without unsubscribing, the server kept 2.1–2.4 GB and
    logged ~48,000 "Broken pipe" lines. Now each viewer's queue is bounded in bytes, freed memory
    is returned, and the SDK's lines are one per viewer connection."""
    require_node()
    srv = serve("warehouse", "--precision", "fast", "--watch", "--foxglove", "127.0.0.1:0")
    try:
        before = _rss_kib(srv.pid)
        from _node import run_script

        for _ in range(2):
            result = run_script("viewer_churn.js", srv.fields["foxglove"], "200", "20", "--parallel", "20", timeout=300)
            assert result[-1]["viewers"] == 200 and result[-1]["messages"] > 200, result
        wait_until(lambda: _rss_kib(srv.pid) < before + 300 * 1024,
                           timeout=30, what=f"RSS back under {before // 1024 + 300} MB (now {_rss_kib(srv.pid) // 1024} MB)")
        peak = _rss_kib(srv.pid, "VmHWM")
        assert peak < before + 700 * 1024, f"peak {peak // 1024} MB (started at {before // 1024} MB)"
    finally:
        srv.stop(signal.SIGTERM)
    err = srv.stderr()
    sdk_lines = [line for line in err.splitlines() if line.startswith("sensorium: Foxglove: ")]
    assert len(sdk_lines) <= 400 + 10, f"{len(sdk_lines)} SDK lines for 400 viewers"
    broken = [line for line in err.splitlines() if "Broken pipe" in line]
    assert len(broken) <= 400, f"{len(broken)} 'Broken pipe' lines for 400 viewers"
    assert all(line.startswith("sensorium") for line in err.splitlines() if line.strip()), \
        [line for line in err.splitlines() if not line.startswith("sensorium")][:5]
    assert "400 connections" in err, err[-2000:]


def test_subscribe_churn_does_not_stall_stepping():
    """Issue 28: 10,000 subscribe/unsubscribe pairs (every channel, /scene included) stalled
    stepping for 1.46 s, and each /scene subscription queued one more full scene. Now each
    subscription event is O(1), wakes the loop at most once per pass, and a viewer's scene is
    queued once: the controller's steps go on, and the churning viewer still gets its data."""
    require_node()
    srv = serve(None, "--precision", "fast", "--foxglove", "127.0.0.1:0")
    ctx = zmq.Context()
    try:
        rpc = Rpc(ctx, srv.fields["rpc"])
        rpc.session = rpc.ok("attach", {"robot": "epuck"})["session"]
        durations: list[float] = []
        done = threading.Event()

        def stepper() -> None:
            while not done.is_set():
                t = time.perf_counter()
                rpc.ok("/epuck/robot/step")
                durations.append(time.perf_counter() - t)

        thread = threading.Thread(target=stepper, daemon=True)
        thread.start()
        wait_until(lambda: len(durations) > 50, what="the controller stepping")
        from _node import run_script

        rounds = -(-10_000 // 22)                                           # arena: 22 channels
        result = run_script("viewer_churn.js", srv.fields["foxglove"], "1", "1", "--churn", str(rounds),
                            "--wait", "60", timeout=180)[-1]
        n = len(durations)
        wait_until(lambda: len(durations) > n + 50, what="stepping after the churn")
        done.set()
        thread.join(30)
        # the churning viewer got its data (within 60 s of its last subscribe: generous for a busy machine)
        assert result["churned"] >= 10_000 and result["failed"] == 0, json.dumps(result)     # (its reasons in full)
        assert max(durations) < 0.5, f"a step took {max(durations) * 1000:.0f} ms during the churn"
    finally:
        ctx.destroy(0)
        srv.stop(signal.SIGTERM)
