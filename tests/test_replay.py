"""Replay: the frames of a live server on an XPUB, rate/filters/clock/loop, lockstep, and
``sensorium record --connect`` against a replay (0 gaps when keeping up, exact loss count when not)."""

from __future__ import annotations

import signal
import subprocess
import threading
import time
from contextlib import contextmanager

import msgpack
import pytest
import zmq
from _recdata import STEP_NS, TOPICS, make_recording, published
from _serve import Proc, Served, sensorium

from sensorium.schemas.wire import HARD_LIMIT
from sensorium.server.recording.envelope import pack_envelope
from sensorium.server.recording.live import LiveRecorder, subscription_prefixes
from sensorium.server.recording.reader import Recording
from sensorium.server.recording.replay import Replayer
from sensorium.server.recording.writer import McapRecorder

ANY = "tcp://127.0.0.1:*"


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    path = tmp_path_factory.mktemp("replay") / "rec.mcap"
    items = make_recording(path, steps=32)  # 32 ms .. 1024 ms of simulation time
    return path, items


@pytest.fixture
def ctx():
    c = zmq.Context()
    yield c
    c.destroy(linger=0)


@contextmanager
def running(path, ctx, **kw):
    kw.setdefault("pub", ANY)
    kw.setdefault("rpc", ANY)
    r = Replayer(str(path), context=ctx, **kw)
    r.bind()
    th = threading.Thread(target=r.run, daemon=True)
    try:
        yield r, th
    finally:
        r.stop()
        if th.is_alive():
            th.join(10)
        r.close()


def subscriber(ctx, endpoint, *prefixes):
    s = ctx.socket(zmq.SUB)
    s.setsockopt(zmq.LINGER, 0)
    for p in prefixes or (b"",):
        s.setsockopt(zmq.SUBSCRIBE, p)
    s.connect(endpoint)
    return s


def drain(sock, idle=0.5, limit=100000, extra=0.1):
    """Receive until ``limit`` messages (then check ``extra`` seconds that no more come) or until
    nothing comes for ``idle`` seconds."""
    out = []
    while len(out) < limit and sock.poll(int(idle * 1000)):
        out.append((time.monotonic(), sock.recv_multipart()))
    if len(out) >= limit and limit < 100000 and extra and sock.poll(int(extra * 1000)):
        out.append((time.monotonic(), sock.recv_multipart()))
    return out


def call(ctx, endpoint, service, args=None, rid=1):
    s = ctx.socket(zmq.DEALER)
    s.setsockopt(zmq.LINGER, 0)
    s.connect(endpoint)
    try:
        s.send(msgpack.packb({"id": rid, "service": service, "args": args or {}}))
        assert s.poll(5000), f"no reply to {service}"
        return msgpack.unpackb(s.recv())
    finally:
        s.close()


def frames_of(items):
    return [[i[0].encode() + b"\0", i[2], i[3]] for i in items]


def test_frames_identical_to_the_live_server(rec_path, ctx):
    path, items = rec_path
    with running(path, ctx, rate=0, wait_subscriber=True) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        got = [f for _t, f in drain(sub, limit=len(items))]
    assert got == frames_of(items)
    assert r.emitted == len(items)


def test_rate_scaling(rec_path, ctx):
    path, items = rec_path
    span = (items[-1][4] - items[0][4]) / 1e9  # 0.992 s
    for rate in (8.0, 3.0):
        with running(path, ctx, rate=rate, wait_subscriber=True, topics=["/epuck/ls0"]) as (r, th):
            sub = subscriber(ctx, r.pub_endpoint)
            th.start()
            got = drain(sub, idle=1.0, limit=32)
        assert len(got) == 32
        elapsed = got[-1][0] - got[0][0]
        assert span / rate * 0.6 < elapsed < span / rate * 2 + 0.2, (rate, elapsed)
        # spacing is kept: the middle message comes about half way
        mid = got[16][0] - got[0][0]
        assert abs(mid - elapsed * 16 / 31) < 0.15


def test_start_end_topics_filters(rec_path, ctx):
    path, items = rec_path
    with running(path, ctx, rate=0, wait_subscriber=True, topics=["/epuck", "/scout/lidar/point_*"],
                 start_s=0.32, end_s=0.64) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        want = [i for i in items if (i[0].startswith("/epuck/") or i[0] == "/scout/lidar/point_cloud")
                and 320_000_000 <= i[4] <= 640_000_000]
        got = [f for _t, f in drain(sub, limit=len(want))]
    assert got == frames_of(want) and want


def test_clock_replaces_the_recorded_clock(rec_path, ctx):
    path, items = rec_path
    with running(path, ctx, rate=0, wait_subscriber=True, clock_hz=40.0, topics=["/epuck/ps0", "/clock"]) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        got = [f for _t, f in drain(sub, limit=64)]
    clocks = [f for f in got if f[0] == b"/clock\0"]
    others = [f for f in got if f[0] != b"/clock\0"]
    assert others == frames_of([i for i in items if i[0] == "/epuck/ps0/value"])
    # one /clock before each new stamp, our own sequence, recorded /clock not replayed
    assert len(clocks) == 32
    for k, (_t, env, body) in enumerate(clocks):
        e, b = msgpack.unpackb(env), msgpack.unpackb(body)
        assert e == {"type": "rosgraph_msgs/msg/Clock", "seq": k, "stamp_ns": (k + 1) * STEP_NS}
        assert b == {"clock": {"sec": 0 if k < 31 else 1, "nanosec": ((k + 1) * STEP_NS) % 1_000_000_000}}
    assert got.index(clocks[0]) < got.index(others[0])


def test_clock_at_a_wall_clock_rate(rec_path, ctx):
    path, items = rec_path
    with running(path, ctx, rate=1.0, wait_subscriber=True, clock_hz=50.0, topics=["/epuck/ls0"], end_s=0.3) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint, b"/clock\0")
        th.start()
        got = [f for _t, f in drain(sub, idle=0.3)]
    stamps = [msgpack.unpackb(f[1])["stamp_ns"] for f in got]
    assert all(f[0] == b"/clock\0" for f in got)
    assert 8 <= len(got) <= 20  # about 0.27 s at 50 Hz
    assert stamps == sorted(stamps) and STEP_NS <= stamps[0] < STEP_NS + 30_000_000 and stamps[-1] == 288_000_000
    assert [msgpack.unpackb(f[1])["seq"] for f in got] == list(range(len(got)))


def test_loop_and_quit(rec_path, ctx):
    path, items = rec_path
    n = sum(1 for i in items if i[0] == "/epuck/ls0/value")
    with running(path, ctx, rate=0, loop=True, wait_subscriber=True, topics=["/epuck/ls0"]) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        got = drain(sub, idle=0.5, limit=3 * n, extra=0)
        assert call(ctx, r.rpc_endpoint, "/replay/quit")["ok"]
        th.join(5)
        assert not th.is_alive()
    seqs = [msgpack.unpackb(f[1])["seq"] for _t, f in got]
    assert seqs == list(range(n)) * 3


def test_free_running_services(rec_path, ctx):
    path, items = rec_path
    with running(path, ctx, rate=1.0, wait_subscriber=True, topics=["/epuck/ls0"]) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        info = call(ctx, r.rpc_endpoint, "get_info")["result"]
        assert info["mode"] == "replay" and info["pub_endpoint"] == r.pub_endpoint
        assert info["basic_time_step"] == 32 and info["topics"] == [{"name": "/epuck/ls0/value",
                                                                     "type": "sensor_msgs/msg/Illuminance"}]
        paused = call(ctx, r.rpc_endpoint, "/replay/pause")["result"]
        assert paused["paused"] is True
        before = drain(sub, idle=0.1)
        assert not sub.poll(300)  # nothing while paused
        state = call(ctx, r.rpc_endpoint, "/replay/set_rate", {"value": 0})["result"]
        assert state["rate"] == 0 and state["time_ms"] == paused["time_ms"]
        err = call(ctx, r.rpc_endpoint, "/replay/step", {"duration": 32})
        assert err["ok"] is False and err["error"]["code"] == 10  # WRONG_STATE
        bad = call(ctx, r.rpc_endpoint, "/replay/set_rate", {"value": -1})
        assert bad["error"]["code"] == 5
        assert call(ctx, r.rpc_endpoint, "nope")["error"]["code"] == 2
        call(ctx, r.rpc_endpoint, "/replay/resume")  # the rest as fast as possible, then the replay ends
        rest = drain(sub, idle=0.5, limit=32 - len(before))
        th.join(5)
        assert not th.is_alive() and r.done
    seqs = [msgpack.unpackb(f[1])["seq"] for _t, f in before + rest]
    assert seqs == list(range(32))


def test_extreme_rates_keep_the_replay_running(rec_path, ctx):
    """/replay/set_rate {value: 1e-300} killed the replay (OverflowError in its poll) and 1e308 too
    (an infinite playhead): one request of any client ended it for everyone."""
    path, _ = rec_path
    with running(path, ctx, rate=1.0, wait_subscriber=True, topics=["/epuck/ls0"]) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        assert call(ctx, r.rpc_endpoint, "/replay/set_rate", {"value": 1e-300})["ok"]
        first = drain(sub, idle=0.5)
        assert th.is_alive() and call(ctx, r.rpc_endpoint, "/replay/get_state")["result"]["rate"] == 1e-300
        assert call(ctx, r.rpc_endpoint, "/replay/set_rate", {"value": 1e308})["ok"]
        rest = drain(sub, idle=0.5, limit=32 - len(first))
        th.join(10)
        assert not th.is_alive() and r.done            # it ran to its end
    assert [msgpack.unpackb(f[1])["seq"] for _t, f in first + rest] == list(range(32))


def test_lockstep(rec_path, ctx):
    path, items = rec_path
    with running(path, ctx, lockstep=True) as (r, th):
        sub = subscriber(ctx, r.pub_endpoint)
        th.start()
        deadline = time.monotonic() + 5
        while not call(ctx, r.rpc_endpoint, "/replay/get_state")["result"]["subscriptions"]:
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert not sub.poll(200)  # nothing moves until a step
        info = call(ctx, r.rpc_endpoint, "get_info")["result"]
        assert info["mode"] == "lockstep" and "/replay/step" in info["services"]
        t = 0
        received = []
        for duration in (32, 64, 96, 320, 1000):
            reply = call(ctx, r.rpc_endpoint, "/replay/step", {"duration": duration})
            assert reply["ok"], reply
            t += duration
            res = reply["result"]
            want = [i for i in items if t - duration < i[4] / 1e6 <= t]
            assert res["time_ms"] == t and res["emitted"] == len(want) and res["status"] == 0
            got = [sub.recv_multipart() for _ in want] if want else []
            assert got == frames_of(want)
            received += got
            assert not sub.poll(50)  # nothing beyond the step's end
        assert res["done"] is True and received == frames_of(items)
        # seek back and step again; default duration is the recording's basic time step
        assert call(ctx, r.rpc_endpoint, "/replay/seek", {"time_ms": 320})["ok"]
        res = call(ctx, r.rpc_endpoint, "/replay/step")["result"]
        want = [i for i in items if i[4] == 352_000_000]
        assert res["time_ms"] == 352 and [sub.recv_multipart() for _ in want] == frames_of(want)
        assert call(ctx, r.rpc_endpoint, "/replay/step", {"duration": 0})["error"]["code"] == 5


def test_unknown_argument_names_are_refused_as_the_server_does(rec_path, ctx):
    """/replay/step {durations: 320} (a typo) stepped the default 32 ms and answered ok."""
    path, _ = rec_path
    with running(path, ctx, lockstep=True) as (r, th):
        th.start()
        bad = call(ctx, r.rpc_endpoint, "/replay/step", {"durations": 320})
        assert bad["error"] == {"code": 5, "message": "/replay/step: unknown argument 'durations' (it takes duration)"}
        bad = call(ctx, r.rpc_endpoint, "/replay/get_state", {"verbose": True})
        assert bad["error"] == {"code": 5, "message": "/replay/get_state: unknown argument 'verbose' (it takes none)"}
        assert call(ctx, r.rpc_endpoint, "/replay/get_state")["result"]["time_ms"] == 0       # nothing moved
        assert call(ctx, r.rpc_endpoint, "/replay/step", {"duration": 64})["result"]["time_ms"] == 64
        assert call(ctx, r.rpc_endpoint, "ping", {"session": "abc"})["ok"]      # what clients send to a server
    with running(path, ctx, rate=0, wait_subscriber=True) as (r, th):
        th.start()
        bad = call(ctx, r.rpc_endpoint, "/replay/set_rate", {"rate": 2})
        assert bad["error"] == {"code": 5, "message": "/replay/set_rate: unknown argument 'rate' (it takes value)"}


def test_the_replays_request_socket_is_bounded_as_the_servers(rec_path, ctx):
    """The replay's ROUTER read messages of any size and frame count into memory (the live server's
    has ZMQ_MAXMSGSIZE and a frame cap)."""
    path, _ = rec_path
    with running(path, ctx, lockstep=True) as (r, th):
        th.start()
        many = ctx.socket(zmq.DEALER)
        many.setsockopt(zmq.LINGER, 0)
        many.connect(r.rpc_endpoint)
        many.send_multipart([b""] * 20 + [msgpack.packb({"id": 1, "service": "ping", "args": {}})])
        assert many.poll(5000)
        reply = msgpack.unpackb(many.recv_multipart()[-1])
        assert reply["error"]["code"] == 8 and "at most 16 frames" in reply["error"]["message"]
        big = ctx.socket(zmq.DEALER)
        big.setsockopt(zmq.LINGER, 0)
        big.connect(r.rpc_endpoint)
        big.send(b"\x00" * (HARD_LIMIT + 1))          # over the hard cap: libzmq drops the peer, unread
        assert not big.poll(500)
        many.close()
        big.close()
        assert call(ctx, r.rpc_endpoint, "/replay/get_state")["result"]["time_ms"] == 0      # still serving


def test_lockstep_refuses_times_it_could_not_answer(rec_path, ctx):
    """A step or seek to a time past 2^64 ns was taken, and from then on every request (get_info,
    get_state) was answered INTERNAL 'OverflowError': one bad request wedged the replay."""
    path, _ = rec_path
    with running(path, ctx, lockstep=True) as (r, th):
        th.start()
        for service, args in (("/replay/step", {"duration": 2**64 - 1}), ("/replay/step", {"duration": 2**31}),
                              ("/replay/seek", {"time_ms": 2**64 - 1}), ("/replay/seek", {"time_ms": 2**53})):
            reply = call(ctx, r.rpc_endpoint, service, args)
            assert not reply["ok"] and reply["error"]["code"] == 5, (service, args, reply)
        state = call(ctx, r.rpc_endpoint, "/replay/get_state")
        assert state["ok"] and state["result"]["time_ms"] == 0
        near_end = (2**63 - 1) // 1_000_000 - 10
        assert call(ctx, r.rpc_endpoint, "/replay/seek", {"time_ms": near_end})["ok"]
        assert call(ctx, r.rpc_endpoint, "/replay/step", {"duration": 20})["error"]["code"] == 5
        assert call(ctx, r.rpc_endpoint, "/replay/step", {"duration": 10})["result"]["time_ms"] == near_end + 10
        assert call(ctx, r.rpc_endpoint, "get_info")["ok"]


def test_cli_replay_announces_and_finishes(rec_path, ctx):
    path, items = rec_path
    with Served(sensorium("replay", str(path), "--pub", ANY, "--rpc", ANY, "--rate", "0", "--wait", "--topics",
                          "/epuck/ps1", "--progress"), "sensorium: replaying").wait_ready() as proc:
        assert proc.out[0] == proc.ready_line                       # its first line
        assert proc.ready_line.startswith(f"sensorium: replaying {path} pub=tcp://127.0.0.1:"), proc.ready_line
        assert call(ctx, proc.rpc, "get_info")["result"]["pub_endpoint"] == proc.pub
        sub = subscriber(ctx, proc.pub)
        got = [f for _t, f in drain(sub, limit=16)]
        assert proc.wait() == 0
    assert got == frames_of([i for i in items if i[0] == "/epuck/ps1/value"])
    err = proc.stderr()
    assert "replay" in err and "100.0%" in err and "replay finished: 16 messages" in err


# ---------------------------------------------------------------- record --connect


def test_subscription_prefixes():
    assert subscription_prefixes(None) == [b""]
    assert subscription_prefixes(["/epuck/ps1"]) == [b"/epuck/ps1\0", b"/epuck/ps1/"]
    assert subscription_prefixes(["/epuck/"]) == [b"/epuck/"]
    assert subscription_prefixes(["/epuck/ps*"]) == [b"/epuck/ps"]


def test_topics_that_match_nothing_are_refused(rec_path, ctx, tmp_path):
    """A typo in --topics gave an empty replay or recording and exit 0 without a word."""
    path, _ = rec_path
    with pytest.raises(ValueError, match=r"--topics /epcuk: no topic of .*rec\.mcap matches it \(closest: "):
        Replayer(str(path), topics=["/epuck/ps*", "/epcuk"], context=ctx)
    with running(path, ctx, lockstep=True) as (r, th):
        th.start()
        out = tmp_path / "typo.mcap"
        live = LiveRecorder(out, connect=r.rpc_endpoint, topics=["/scout", "/scuot/lidar"], context=ctx)
        with pytest.raises(ValueError, match=r"--topics /scuot/lidar: no topic of the server at tcp://"):
            live.open()
        assert not out.exists()                      # nothing written
        live = LiveRecorder(out, connect=r.rpc_endpoint, topics=["/scout", "/epuck/ps1"], context=ctx)
        live.open()                                  # prefixes and exact names that match are fine
        live.close()
    proc = subprocess.run(sensorium("replay", str(path), "--rpc", ANY, "--pub", ANY, "--topics", "/nosuch"),
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.startswith("sensorium replay: --topics /nosuch: no topic of ") and "Traceback" not in proc.stderr


def test_a_ros2_bag_is_refused_not_replayed_empty(rec_path, ctx, tmp_path):
    """Replaying a ROS 2 bag (sensorium export's output) published nothing and said 'replay
    finished: 0 messages'."""
    pytest.importorskip("mcap_ros2")
    from sensorium.server.recording.export import export_ros2

    path, _ = rec_path
    bag = tmp_path / "ros2.mcap"
    export_ros2(path, bag)
    with pytest.raises(ValueError, match=r"ros2\.mcap is not a Sensorium recording \(MCAP profile 'ros2'"):
        Replayer(str(bag), context=ctx)


def test_a_port_out_of_range_is_refused_not_wrapped(rec_path, ctx):
    """replay --rpc tcp://127.0.0.1:99999 bound port 34463 (libzmq wraps it)."""
    path, _ = rec_path
    with pytest.raises(ValueError, match=r"^--rpc tcp://127.0.0.1:99999: the port must be 0 to 65535"):
        Replayer(str(path), rpc="tcp://127.0.0.1:99999", context=ctx)
    with pytest.raises(ValueError, match=r"^--pub tcp://127.0.0.1:-1: the port must be 0 to 65535"):
        Replayer(str(path), pub="tcp://127.0.0.1:-1", rpc=None, context=ctx)


def test_an_ipc_path_that_is_a_file_or_both_sockets_is_refused(rec_path, ctx, tmp_path):
    """replay --pub ipc://FILE deleted FILE (libzmq unlinks the path before binding)."""
    path, _ = rec_path
    precious = tmp_path / "notes.txt"
    precious.write_text("keep me")
    with pytest.raises(ValueError, match="exists and is not a socket: not replacing it"):
        Replayer(str(path), pub=f"ipc://{precious}", rpc=None, context=ctx)
    assert precious.read_text() == "keep me"
    with pytest.raises(ValueError, match="^--rpc and --pub are the same endpoint"):
        Replayer(str(path), pub=f"ipc://{tmp_path}/s", rpc=f"ipc://{tmp_path}/s", context=ctx)


def test_record_connect_keeps_up_zero_gaps(rec_path, ctx, tmp_path):
    path, items = rec_path
    out = tmp_path / "sub.mcap"
    with running(path, ctx, rate=4.0, wait_subscriber=True) as (r, th):
        th.start()  # serves get_info, waits for the first subscription
        live = LiveRecorder(out, connect=r.rpc_endpoint, context=ctx)
        live.open()
        assert live.pub_endpoint == r.pub_endpoint
        live.run(duration=10, max_messages=len(items))
        summary = live.close()
    assert summary["received"] == len(items) and summary["gaps"] == 0 and summary["lost"] == 0
    with Recording(out) as rec:
        got = [(m.topic, m.ros_type, m.seq, m.stamp_ns, m.data) for m in rec.messages()]
        meta = rec.metadata()
    assert got == [(i[0], i[1], i[5], i[4], i[3]) for i in items]  # the same bytes as the server's
    assert meta["record"]["gaps"] == "0" and meta["session"]["mode"] == "subscriber"
    assert meta["sensorium"]["basic_time_step_ms"] == "32"


def _burst_recording(path, n=300, size=64 * 1024):
    """n big messages 1 ms apart, then one more 400 ms later (so the last one is never dropped)."""
    body = msgpack.packb({"data": b"\x01" * size})
    with McapRecorder(path, chunk_size=1 << 20) as rec:
        for k in range(n + 1):
            t = (k + 1) * 1_000_000 + (400_000_000 if k == n else 0)
            rec.record("/big/blob/data", "std_msgs/msg/ByteMultiArray",
                       pack_envelope("std_msgs/msg/ByteMultiArray", k, t), body, t, k)
    return n + 1


def test_record_connect_counts_exactly_what_it_lost(ctx, tmp_path):
    src = tmp_path / "burst.mcap"
    total = _burst_recording(src)
    out = tmp_path / "lossy.mcap"
    with running(src, ctx, rate=1.0, wait_subscriber=True, sndhwm=2) as (r, th):
        th.start()
        live = LiveRecorder(out, connect=r.rpc_endpoint, rcvhwm=2, context=ctx,
                            on_message=lambda topic, seq: time.sleep(0.004) if seq < total - 1 else None,
                            log=lambda text: None)
        live.open()
        last = {}

        def watch(topic, seq, _slow=live.on_message):
            last["seq"] = seq
            _slow(topic, seq)
            if seq == total - 1:
                live.stop()

        live.on_message = watch
        live.run(duration=15)
        summary = live.close()
    assert last["seq"] == total - 1  # first and last arrive; everything between is accounted for
    with Recording(out) as rec:
        seqs = [m.seq for m in rec.messages()]
    assert seqs[0] == 0 and seqs[-1] == total - 1
    assert summary["received"] == len(seqs)
    assert summary["lost"] == total - len(seqs) > 0
    assert summary["gaps"] == sum(1 for a, b in zip(seqs, seqs[1:]) if b > a + 1)
    assert summary["lost_by_topic"] == {"/big/blob/data": total - len(seqs)}


def test_cli_record_sigint_finishes_and_reports(rec_path, ctx, tmp_path):
    path, items = rec_path
    out = tmp_path / "cli.mcap"
    with running(path, ctx, rate=0, wait_subscriber=True) as (r, th):
        th.start()
        with Proc(sensorium("record", str(out), "--url", r.rpc_endpoint, "--topics", "/epuck",
                            "/scout/lidar/laser_scan")) as proc:
            line = proc.line()
            assert line.startswith(f"sensorium: recording {out} from pub={r.pub_endpoint}"), (line, proc.stderr())
            th.join(10)
            want = [i for i in items if i[0].startswith("/epuck/") or i[0] == "/scout/lidar/laser_scan"]
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline:  # the file is flushed at least once a second
                time.sleep(0.2)
                try:
                    with Recording(out) as rec:
                        if sum(1 for _ in rec.messages()) == len(want):
                            break
                except Exception:
                    pass
            code = proc.stop(signal.SIGINT)
    stdout, stderr = proc.stdout(), proc.stderr()
    assert code == 0, stderr
    assert f"recorded {len(want)} messages on 4 topics" in stdout and "0 gaps, 0 messages lost" in stdout
    with Recording(out) as rec:
        assert not rec.truncated
        assert [m.data for m in rec.messages()] == [i[3] for i in want]


def test_published_helper_is_deterministic():
    assert list(published(5)) == list(published(5))
    assert set(TOPICS) >= {t for t, *_ in published(4)}


def test_cli_replay_stops_on_sigint_when_started_with_it_ignored(rec_path):
    # a shell script's background job (`sensorium replay ... &`) starts with SIGINT ignored; `kill -INT`
    # must still end the replay cleanly, as it ends `serve`
    path, _items = rec_path
    with Served(sensorium("replay", str(path), "--pub", ANY, "--rpc", ANY, "--loop"), "sensorium: replaying",
                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN)).wait_ready() as proc:
        proc.p.send_signal(signal.SIGINT)
        try:
            code = proc.p.wait(60)
        except subprocess.TimeoutExpired:
            code = None
    assert code is not None, "replay ignored SIGINT"
    assert "Traceback" not in proc.stderr(), proc.stderr()


def test_cli_replay_on_a_port_in_use_says_which_and_what_to_do(rec_path, ctx):
    """`sensorium replay` beside a running server said "cannot bind: Address already in use
    (addr='tcp://...')"; it now says it as serve and run do: the endpoint, and the ports to change."""
    path, _ = rec_path
    busy = ctx.socket(zmq.PUB)
    try:
        port = busy.bind_to_random_port("tcp://127.0.0.1")
        proc = subprocess.run(sensorium("replay", str(path), "--rpc", ANY, "--pub", f"tcp://127.0.0.1:{port}"),
                              capture_output=True, text=True, timeout=60)
    finally:
        busy.close(linger=0)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr == (f"sensorium replay: cannot bind tcp://127.0.0.1:{port}: Address already in use (another "
                           "server? choose other --rpc/--pub ports, or port 0 for free ones)\n")
