"""`sensorium serve` in a real subprocess, driven by raw pyzmq + msgpack clients written from
PROTOCOL.md alone (no sensorium client code)."""

from __future__ import annotations

import itertools
import math
import signal
import time
from pathlib import Path

import msgpack
import numpy as np
import pytest
import zmq
from _serve import Served, serve, wait_until

from sensorium.schemas import messages as M

WORLD = Path(__file__).parent / "worlds" / "server.yaml"
HEARTBEAT_MS = 1000   # a session is dropped after 3 silent heartbeats: 3 s, generous on a busy machine
BASIC = 16


# ---------------------------------------------------------------------- a server process

def server_process(*extra: str, heartbeat_ms: int = HEARTBEAT_MS, wait: bool = True) -> Served:
    return serve(WORLD, "--heartbeat-ms", str(heartbeat_ms), "--precision", "fast", *extra, pub="tcp://127.0.0.1:*",
                 wait=wait, stop_signal=signal.SIGTERM)


def ready(s: Served) -> Served:
    s.wait_ready()
    assert "'server-test'" in s.ready_line
    return s


class Raw:
    """A DEALER (or REQ) client: requests are msgpack maps, replies matched by id."""

    ids = itertools.count(1)

    def __init__(self, ctx: zmq.Context, endpoint: str, kind: int = zmq.DEALER):
        self.sock = ctx.socket(kind)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.connect(endpoint)
        self.stash: dict = {}
        self.session: str | None = None
        self.last_ping = 0.0

    def send_raw(self, body: bytes) -> None:
        self.sock.send(body)

    def send(self, service: str, args: dict | None = None) -> int:
        rid = next(self.ids)
        self.send_raw(msgpack.packb({"id": rid, "service": service, "args": {} if args is None else args}))
        return rid

    def recv(self, timeout: float = 30.0) -> dict:
        if not self.sock.poll(int(timeout * 1000)):
            raise TimeoutError("no reply")
        return msgpack.unpackb(self.sock.recv_multipart()[-1], raw=False)

    def wait(self, rid, timeout: float = 30.0, keepalive: bool = True) -> dict:
        """The reply to ``rid``; pings the session meanwhile (PROTOCOL §3.3 liveness)."""
        deadline = time.monotonic() + timeout
        while rid not in self.stash:
            now = time.monotonic()
            if now > deadline:
                raise TimeoutError(f"no reply to {rid}")
            if keepalive and self.session and now - self.last_ping > HEARTBEAT_MS / 2000:
                self.last_ping = now
                self.send("ping", {"session": self.session})
            if self.sock.poll(10):
                r = msgpack.unpackb(self.sock.recv_multipart()[-1], raw=False)
                self.stash[r["id"]] = r
        return self.stash.pop(rid)

    def call(self, service: str, args: dict | None = None, timeout: float = 30.0) -> dict:
        return self.wait(self.send(service, args), timeout)

    def ok(self, service: str, args: dict | None = None) -> dict:
        r = self.call(service, args)
        assert r["ok"] is True, r
        return r["result"]

    def attach(self, robot: str) -> dict:
        res = self.ok("attach", {"robot": robot})
        self.session = res["session"]
        return res


def error_code(reply: dict) -> int:
    assert reply["ok"] is False, reply
    assert isinstance(reply["error"]["message"], str)
    return reply["error"]["code"]



@pytest.fixture(scope="module")
def ctx():
    c = zmq.Context()
    yield c
    c.destroy(linger=0)


@pytest.fixture(scope="module")
def server():
    s = ready(server_process())
    yield s
    rc = s.stop(signal.SIGTERM)
    assert rc == 0, s.stderr()


@pytest.fixture
def client(ctx, server):
    clients = []

    def make(kind=zmq.DEALER):
        c = Raw(ctx, server.rpc, kind)
        clients.append(c)
        return c

    yield make
    for c in clients:                       # release robots for the next test
        if c.session:
            try:
                c.call("detach", {"session": c.session}, timeout=2)
            except TimeoutError:
                pass
        c.sock.close(0)


# ---------------------------------------------------------------------- services

def test_attach_enable_step_read(client):
    c = client()
    info = c.ok("get_info")
    assert info["protocol"] == 1 and info["world"] == "server-test" and info["basic_time_step"] == BASIC
    assert info["pub_endpoint"].startswith("tcp://127.0.0.1:")
    res = c.attach("bot")
    assert [d["name"] for d in res["devices"]] == ["ls", "ds", "lidar", "lidar2"]
    assert res["heartbeat_ms"] == HEARTBEAT_MS and res["synchronization"] is True
    for dev, period in [("ls", BASIC), ("ds", 2 * BASIC), ("lidar", BASIC), ("lidar2", BASIC)]:
        assert c.ok(f"/bot/{dev}/enable", {"value": period}) == {"success": True}
    assert c.ok("/bot/lidar2/enable_point_cloud", {"value": True}) == {"success": True}
    assert c.ok("/bot/ds/get_sampling_period") == {"value": 2 * BASIC}
    t0 = res["time_ms"]
    seen = {}
    for i in range(1, 5):
        r = c.ok("/bot/robot/step", {"duration": BASIC})
        assert r["status"] == 0 and r["time_ms"] == t0 + i * BASIC
        seen.update(r["values"])
    assert set(seen) == {"ls", "ds", "lidar", "lidar2"}
    assert 0.0 < seen["ds"]["value"] <= 2000.0                       # the wall is 0.95 m ahead
    assert len(seen["lidar"]["range_image"]) == 16 * 4
    assert len(seen["lidar2"]["range_image"]) == 2 * 8 * 4 and len(seen["lidar2"]["point_cloud"]) == 16 * 20
    assert "point_cloud" not in seen["lidar"]
    r = c.ok("/bot/robot/step", {"duration": 3 * BASIC})             # several basic steps per control step
    assert r["time_ms"] == t0 + 7 * BASIC
    assert c.ok("/bot/robot/time_step", {"value": BASIC}) == {"success": True}
    assert c.ok("/bot/robot/get_time")["value"] == pytest.approx((t0 + 8 * BASIC) / 1000)


def test_bad_requests_get_typed_errors_while_a_client_steps(client, ctx, server):
    good = client()
    good.attach("bot2")
    bad = client()
    cases = [
        (b"\xc1 not msgpack", 1),
        (msgpack.packb([1, 2, 3]), 1),
        (msgpack.packb("get_info"), 1),
        (msgpack.packb({"id": 1, "service": "get_info"}), 1),
        (msgpack.packb({"id": "one", "service": "get_info", "args": {}}), 1),
        (msgpack.packb({"id": 5, "service": "no_such_service", "args": {}}), 2),
        (msgpack.packb({"id": 6, "service": "/ghost/robot/step", "args": {}}), 3),
        (msgpack.packb({"id": 7, "service": "/bot/ghost/enable", "args": {"value": 16}}), 4),
        (msgpack.packb({"id": 8, "service": "/bot/ls/get_aperture", "args": {}}), 4),
        (msgpack.packb({"id": 9, "service": "/bot/ls/enable", "args": {"value": "16"}}), 5),
        (msgpack.packb({"id": 10, "service": "/bot/ls/enable", "args": {"value": -16}}), 5),
        (msgpack.packb({"id": 11, "service": "/bot/ls/enable", "args": {"value": 16}}), 6),   # not attached
        (msgpack.packb({"id": 12, "service": "/bot2/robot/step", "args": {}}), 6),             # someone else's robot
        (msgpack.packb({"id": 13, "service": "attach", "args": {"robot": "bot2"}}), 7),
        (msgpack.packb({"id": 14, "service": "get_info", "args": {"pad": b"\0" * (1 << 20)}}), 8),
    ]
    t = good.ok("/bot2/robot/step")["time_ms"]
    for body, code in cases:
        bad.send_raw(body)
        r = bad.recv()
        assert error_code(r) == code, (body[:40], r)
        r = good.ok("/bot2/robot/step")                              # the well-behaved client keeps stepping
        assert r["time_ms"] == t + BASIC
        t = r["time_ms"]
    # a request id is echoed when it could be read; null otherwise
    bad.send_raw(msgpack.packb({"id": 77, "service": "nope", "args": {}}))
    assert bad.recv()["id"] == 77
    bad.send_raw(b"\xc1")
    assert bad.recv()["id"] is None
    # a second step while one is pending
    good.ok("set_mode", {"mode": "pause"})
    rid = good.send("/bot2/robot/step")
    assert error_code(good.call("/bot2/robot/step")) == 10
    good.ok("set_mode", {"mode": "fast"})
    assert good.wait(rid)["result"]["status"] == 0
    # a REQ client gets its envelope back
    req = client(zmq.REQ)
    assert req.ok("get_info")["world"] == "server-test"
    # above the hard cap (2 MiB per frame) libzmq drops that connection; the server goes on
    huge = ctx.socket(zmq.DEALER)
    huge.setsockopt(zmq.LINGER, 0)
    huge.connect(server.rpc)
    huge.send(b"\0" * (17 << 20))
    time.sleep(0.2)
    huge.close(0)
    assert good.ok("/bot2/robot/step")["status"] == 0


def test_second_attach_is_taken(client):
    a, b = client(), client()
    a.attach("bot")
    assert error_code(b.call("attach", {"robot": "bot"})) == 7
    assert b.ok("get_info")["robots"][0]["attached"] is True


def test_silent_client_is_released_and_world_goes_on(client):
    silent, stepper = client(), client()
    silent.attach("bot")                      # synchronous, never steps, never pings
    stepper.attach("bot2")
    start = time.monotonic()
    rid = stepper.send("/bot2/robot/step")
    r = stepper.wait(rid, timeout=60)         # blocked until the silent one is dropped (3 heartbeats)
    waited = time.monotonic() - start
    assert r["ok"] and r["result"]["status"] == 0
    assert 2 * HEARTBEAT_MS / 1000 < waited < 30.0
    assert stepper.ok("get_info")["robots"][0]["attached"] is False
    assert error_code(silent.call("ping", {"session": silent.session})) == 6
    silent.session = None
    newcomer = client()
    newcomer.attach("bot")                    # the robot is free again


def test_realtime_mode_paces_and_reports_rtf(client):
    c = client()
    c.attach("bot2")
    c.ok("set_mode", {"mode": "realtime"})
    try:
        start = time.monotonic()
        steps = 0
        while steps < 10 or time.monotonic() - start < 1.5:   # past the 1 s RTF window: earlier tests' idle
            c.ok("/bot2/robot/step")                          # gaps no longer count
            steps += 1
        elapsed = time.monotonic() - start
        rtf = c.ok("get_info")["real_time_factor"]
    finally:
        c.ok("set_mode", {"mode": "fast"})
    assert elapsed >= (steps - 1) * BASIC / 1000
    assert 0.5 < rtf < 1.5


def test_motors_over_the_wire_match_the_in_process_simulation(client):
    from sensorium.server.daemon.topics import pose_quaternion
    from sensorium.server.sim.simulation import Simulation

    c = client()
    res = c.attach("rover")
    assert res["devices"] == [
        {"name": n, "type": "RotationalMotor", "maxVelocity": 8.0, "minPosition": 0.0, "maxPosition": 0.0,
         "targetPosition": 0.0, "velocity": 8.0, "model": "", "index": i, "simulated": True}
        for i, n in enumerate(("left wheel motor", "right wheel motor"))]
    t0 = res["time_ms"]
    assert error_code(c.call("/rover/robot/step", {"motors": {"left wheel motor": {"position": math.nan}}})) == 5
    assert error_code(c.call("/rover/robot/step", {"motors": {"left wheel motor": {"velocity": math.inf}}})) == 5
    assert error_code(c.call("/rover/robot/step", {"motors": {"wheel": {"velocity": 1.0}}})) == 4
    plan = [({"left wheel motor": {"position": math.inf, "velocity": 5.0},
              "right wheel motor": {"position": math.inf, "velocity": 5}}, 6),
            ({"left wheel motor": {"velocity": 2.5}, "right wheel motor": {"velocity": 9.0}}, 5)]   # 9 -> 8 (clamped)
    for motors, steps in plan:
        assert c.ok("/rover/robot/step", {"motors": motors})["status"] == 0
        for _ in range(steps - 1):
            c.ok("/rover/robot/step")
    assert c.ok("/rover/left wheel motor/get_target_position") == {"value": math.inf}     # inf survives msgpack
    assert c.ok("/rover/right wheel motor/get_velocity") == {"value": 8.0}
    got = c.ok("/rover/robot/get_pose")
    # the same commands at the same times, in process
    sim = Simulation.from_file(WORLD, precision="fast")
    sim.run(t0 // BASIC)
    rover = sim.robot("rover")
    for motors, steps in plan:
        for name, cmd in motors.items():
            if "position" in cmd:
                rover.motor(name).set_position(cmd["position"])
            rover.motor(name).set_velocity(cmd["velocity"])
        sim.run(steps)
    assert got["translation"] == [float(v) for v in rover.pose.translation]
    assert got["quaternion"] == pose_quaternion(rover.pose) and got["quaternion"][2] != 0.0     # it turned
    assert got["translation"] != [0.5, -1.0, 0.0]
    c.ok("/rover/left wheel motor/set_velocity", {"value": 0.0})       # leave it parked for the other tests
    c.ok("/rover/right wheel motor/set_velocity", {"value": 0.0})


# ---------------------------------------------------------------------- topics and demand

def counters(c: Raw) -> dict:
    return c.ok("get_counters")


def test_subscriber_gets_every_topic_type(client, ctx, server):
    c = client()
    sub = ctx.socket(zmq.SUB)
    sub.setsockopt(zmq.LINGER, 0)
    sub.connect(server.pub)
    sub.setsockopt(zmq.SUBSCRIBE, b"")
    try:
        wait_until(lambda: b"" in counters(c)["subscriptions"], what="subscription")
        c.attach("bot2")
        for _ in range(3):
            c.ok("/bot2/robot/step")
        got: dict[str, list] = {}
        deadline = time.monotonic() + 5
        while len(got) < 13 and time.monotonic() < deadline:
            if sub.poll(100):
                frames = sub.recv_multipart()
                assert len(frames) == 3 and frames[0].endswith(b"\0")
                got.setdefault(frames[0][:-1].decode(), []).append(
                    (msgpack.unpackb(frames[1], raw=False), msgpack.unpackb(frames[2], raw=False)))
    finally:
        sub.close(0)
    assert set(got) == {"/clock", "/bot/ls/value", "/bot/ds/value", "/bot/lidar/range_image", "/bot/lidar/laser_scan",
                        "/bot/lidar/point_cloud", "/bot/lidar2/range_image", "/bot/lidar2/point_cloud", "/free/ls/value",
                        "/bot/pose", "/free/pose", "/bot2/pose", "/rover/pose"}
    for topic, msgs in got.items():
        seqs = [env["seq"] for env, _ in msgs]
        assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))
        for env, body in msgs:
            model = M.MESSAGE_TYPES[env["type"]]
            model.model_validate(body)
            assert list(body) == M.field_order(model)
            if topic != "/clock":
                st = body["header"]["stamp"]
                assert st["sec"] * 10**9 + st["nanosec"] == env["stamp_ns"] and env["stamp_ns"] % (BASIC * 10**6) == 0
                if topic.endswith("/pose"):
                    assert body["header"]["frame_id"] == "world" and env["type"] == M.POSE_STAMPED
                else:
                    assert body["header"]["frame_id"] == topic.split("/")[1] + "/" + topic.split("/")[2]
    assert got["/bot/ls/value"][0][0]["type"] == M.ILLUMINANCE
    rng = got["/bot/ds/value"][-1][1]
    assert (rng["radiation_type"], rng["min_range"], rng["max_range"]) == (0, 0.0, 2000.0)
    img = got["/bot/lidar2/range_image"][-1][1]
    assert (img["height"], img["width"], img["step"], img["encoding"], len(img["data"])) == (2, 8, 32, "32FC1", 64)
    scan = got["/bot/lidar/laser_scan"][-1][1]
    assert scan["angle_increment"] == pytest.approx(-3.14159 / 16)
    assert scan["angle_min"] == pytest.approx(3.14159 / 2 - 3.14159 / 32)
    assert scan["angle_max"] == pytest.approx(-scan["angle_min"])
    ranges = np.frombuffer(scan["ranges"], "<f4")
    assert len(ranges) == 16 and scan["intensities"] == b""
    ahead = ranges[7:9]                                          # the two columns around straight ahead
    assert np.all(np.abs(ahead - 0.95) < 0.05), ranges
    pc = got["/bot/lidar2/point_cloud"][-1][1]
    assert len(pc["points"]) == 16 * 12 and pc["channels"][0]["name"] == "layer"
    assert np.frombuffer(pc["channels"][0]["values"], "<f4").tolist() == [0.0] * 8 + [1.0] * 8
    clock = got["/clock"][-1][1]["clock"]              # the whole time, not its sub-second part (1 s % 16 ms != 0)
    assert (clock["sec"] * 10**9 + clock["nanosec"]) % (BASIC * 10**6) == 0
    assert not math.isnan(got["/bot/ls/value"][-1][1]["illuminance"])
    pose = got["/bot2/pose"][-1][1]["pose"]
    assert pose == {"position": {"x": -1.0, "y": 1.0, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}


def test_unsubscribed_topics_are_not_computed(client, ctx, server):
    c = client()
    wait_until(lambda: counters(c)["subscriptions"] == [], what="no subscriptions")
    c.attach("bot2")

    def delta(steps: int) -> dict:
        before = counters(c)
        for _ in range(steps):
            c.ok("/bot2/robot/step")
        after = counters(c)
        return {k: after["counters"].get(k, 0) - before["counters"].get(k, 0)
                for k in ("rays_lidar", "rays_distance", "rays_light", "points_built", "measurements")}

    assert delta(5) == {"rays_lidar": 0, "rays_distance": 0, "rays_light": 0, "points_built": 0, "measurements": 0}
    sub = ctx.socket(zmq.SUB)
    sub.setsockopt(zmq.LINGER, 0)
    sub.connect(server.pub)
    try:
        sub.setsockopt(zmq.SUBSCRIBE, b"/bot/lidar/laser_scan\0")
        wait_until(lambda: counters(c)["demanded"] == ["/bot/lidar/laser_scan"], what="demand")
        d = delta(5)
        assert d["rays_lidar"] == 5 * 16 and d["points_built"] == 0 and d["rays_distance"] == 0
        sub.setsockopt(zmq.SUBSCRIBE, b"/bot/lidar2/point_cloud\0")
        wait_until(lambda: len(counters(c)["demanded"]) == 2, what="demand")
        d = delta(4)
        assert d["rays_lidar"] == 4 * (16 + 16) and d["points_built"] == 4 * 16
    finally:
        sub.close(0)
    wait_until(lambda: counters(c)["demanded"] == [], what="unsubscription")
    assert delta(3)["rays_lidar"] == 0


# ---------------------------------------------------------------------- determinism and shutdown

def run_script(ctx, srv: Served) -> list[list[bytes]]:
    c = Raw(ctx, srv.rpc)
    sub = ctx.socket(zmq.SUB)
    sub.setsockopt(zmq.LINGER, 0)
    sub.connect(srv.pub)
    sub.setsockopt(zmq.SUBSCRIBE, b"")
    wait_until(lambda: c.ok("get_counters")["subscriptions"] == [b""], what="subscription")
    c.attach("bot")
    c.ok("/bot/ds/enable", {"value": 32})
    c.ok("/bot/lidar2/enable_point_cloud", {"value": True})
    c.ok("/bot/robot/set_pose", {"translation": [0.1, 0.0, 0.0], "rotation": [0, 0, 1, 0.2]})
    replies, frames = [], []
    for _ in range(6):
        r = c.call("/bot/robot/step", {"duration": 32})
        replies.append(msgpack.packb(r["result"]))
        while sub.poll(20):
            frames.append(sub.recv_multipart())
    sub.close(0)
    c.sock.close(0)
    return replies, frames


def test_deterministic_and_sigterm(ctx):
    a, b = server_process(wait=False), server_process(wait=False)
    try:
        ready(a)
        ready(b)
        ra, fa = run_script(ctx, a)
        rb, fb = run_script(ctx, b)
        assert ra == rb
        assert len(fa) > 50 and fa == fb                       # same world + same requests => same bytes

        # SIGTERM: a pending step is answered with status -1, then the server exits cleanly
        c = Raw(ctx, a.rpc)
        c.attach("bot2")
        c.ok("set_mode", {"mode": "pause"})
        rid = c.send("/bot2/robot/step")
        time.sleep(0.05)
        a.p.send_signal(signal.SIGTERM)
        r = c.wait(rid, keepalive=False)
        assert r["ok"] and r["result"]["status"] == -1
        assert a.wait() == 0
        assert "stopped" in a.stderr()
        c.sock.close(0)
    finally:
        assert a.stop(signal.SIGTERM) == 0
        assert b.stop(signal.SIGTERM) == 0


def test_a_port_out_of_range_is_refused_not_wrapped():
    """libzmq binds tcp://127.0.0.1:99999 as port 34463 (and :-1 as 65535): serve answered on a
    port nobody asked for. Now one line naming the option, exit 2, before the world loads."""
    import subprocess

    from _serve import child_env, sensorium

    from sensorium.server.daemon.serve import ServeOptions

    for rpc, said in (("tcp://127.0.0.1:99999", "got '99999'"), ("tcp://127.0.0.1:-1", "got '-1'"),
                      ("tcp://127.0.0.1", "no port")):
        with pytest.raises(ValueError, match=f"^--rpc {rpc}: .*{said}"):
            ServeOptions(rpc=rpc).check()
    for ok in ("tcp://127.0.0.1:0", "tcp://127.0.0.1:*", "tcp://[::1]:65535"):
        ServeOptions(rpc=ok, pub="tcp://127.0.0.1:0").check()
    r = subprocess.run(sensorium("serve", str(WORLD), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:65536"),
                       capture_output=True, text=True, timeout=120, env=child_env())
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.strip().splitlines() == ["sensorium serve: --pub tcp://127.0.0.1:65536: the port must be 0 to "
                                             "65535 (0 or * for a free one), got '65536'"]


def test_an_ipc_path_in_use_or_not_a_socket_is_refused(tmp_path):
    """libzmq unlinks whatever is at an ipc:// path before binding: serve --rpc ipc://FILE deleted
    the user's FILE, and a second server on another's path cut the first off from its clients (its
    socket file replaced, then removed when the second quit). rpc = pub took the path twice."""
    import socket

    from sensorium.server.daemon.serve import ServeOptions

    precious = tmp_path / "notes.txt"
    precious.write_text("keep me")
    with pytest.raises(ValueError, match=f"^--rpc ipc://{precious}: {precious} exists and is not a socket: not "
                                         "replacing it$"):
        ServeOptions(rpc=f"ipc://{precious}", pub="tcp://127.0.0.1:0").check()
    assert precious.read_text() == "keep me"
    live = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)        # another server's socket, listening
    live.bind(str(tmp_path / "live"))
    live.listen(1)
    stale = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)       # a socket file whose server died
    stale.bind(str(tmp_path / "stale"))
    stale.close()
    try:
        with pytest.raises(ValueError, match=f"^--pub ipc://{tmp_path}/live: another process listens there"):
            ServeOptions(rpc="tcp://127.0.0.1:0", pub=f"ipc://{tmp_path}/live").check()
        ServeOptions(rpc=f"ipc://{tmp_path}/stale", pub=f"ipc://{tmp_path}/new").check()   # replaced, as before
    finally:
        live.close()
    with pytest.raises(ValueError, match="^--rpc and --pub are the same endpoint ipc://"):
        ServeOptions(rpc=f"ipc://{tmp_path}/same", pub=f"ipc://{tmp_path}/same").check()
    with pytest.raises(ValueError, match=r"^--until must be a simulated time >= 0 ms, got -5$"):   # it stopped at once
        ServeOptions(rpc="tcp://127.0.0.1:0", pub="tcp://127.0.0.1:0", until=-5).check()
