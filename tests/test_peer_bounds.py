"""One client cannot stall the world or make the server hold memory for it (issue: hardening).

Each test first does what an adversarial or broken client did (a message of a million frames,
deeply nested arguments, a huge request echoed back, long junk subscriptions), then checks that a
well-behaved controller keeps stepping and that what the server holds stays bounded.
"""

from __future__ import annotations

import threading
import time

import msgpack
import pytest
import zmq
from _inproc import WORLD, inproc_server
from _serve import wait_until

from sensorium.client.connection import Connection
from sensorium.schemas.wire import MAX_ERROR_MESSAGE, ErrorCode
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.transport import MAX_FRAMES, Transport
from sensorium.server.sim.simulation import Simulation


@pytest.fixture
def server():
    with inproc_server(heartbeat_ms=1000) as running:
        yield running


class Dealer:
    def __init__(self, endpoint: str):
        self.sock = zmq.Context.instance().socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.connect(endpoint)
        self.ids = iter(range(1, 1 << 30))

    def call(self, service: str, args: dict | None = None) -> dict:
        rid = next(self.ids)
        self.sock.send(msgpack.packb({"id": rid, "service": service, "args": args or {}}))
        while True:
            assert self.sock.poll(30_000), f"no reply to {service}"
            reply = msgpack.unpackb(self.sock.recv())
            if reply["id"] == rid:
                return reply

    def close(self) -> None:
        self.sock.close()


def test_a_message_of_many_frames_is_refused_without_stalling_the_world(server) -> None:
    core, transport = server
    good, bad = Connection(transport.rpc_endpoint, timeout=60), Dealer(transport.rpc_endpoint)
    try:
        good.start_heartbeat(good.call("attach", {"robot": "bot2"})["session"], 500)   # a live controller
        bad.sock.send_multipart([b""] * 200_000 + [msgpack.packb({"id": 1, "service": "get_info", "args": {}})])
        assert bad.sock.poll(60_000)
        reply = msgpack.unpackb(bad.sock.recv())
        assert reply["error"]["code"] == ErrorCode.TOO_LARGE and str(MAX_FRAMES) in reply["error"]["message"]
        # the world steps while the rest of that message is dropped a bounded amount per turn
        t = [good.call("/bot2/robot/step")["time_ms"] for _ in range(5)]
        assert t == [16, 32, 48, 64, 80]
        assert bad.call("get_info")["ok"]                 # the sender is served again afterwards
    finally:
        good.close()
        bad.close()


def test_deep_or_huge_arguments_are_refused_before_validation(server) -> None:
    core, transport = server
    client = Dealer(transport.rpc_endpoint)
    try:
        deep: object = 1
        for _ in range(1000):
            deep = [deep]
        r = client.call("get_info", {"x": deep})
        assert r["error"]["code"] == ErrorCode.TOO_LARGE and "nested deeper" in r["error"]["message"]
        r = client.call("get_info", {"x": [0] * 200_000})
        assert r["error"]["code"] in (ErrorCode.TOO_LARGE,)
        assert core.errors == 0                            # no INTERNAL, no traceback logged
    finally:
        client.close()


def test_error_replies_do_not_echo_large_input(server) -> None:
    core, transport = server
    client = Dealer(transport.rpc_endpoint)
    try:
        name = "/x" * 200_000                               # 400 kB service name
        rid = 9
        client.sock.send(msgpack.packb({"id": rid, "service": name, "args": {}}))
        assert client.sock.poll(30_000)
        raw = client.sock.recv()
        reply = msgpack.unpackb(raw)
        assert reply["error"]["code"] in (ErrorCode.UNKNOWN_SERVICE, ErrorCode.UNKNOWN_ROBOT)
        assert len(reply["error"]["message"]) <= MAX_ERROR_MESSAGE and len(raw) < 1024
    finally:
        client.close()


def test_subscriptions_that_match_no_topic_are_not_held(server) -> None:
    core, transport = server
    sub = zmq.Context.instance().socket(zmq.SUB)
    sub.setsockopt(zmq.LINGER, 0)
    sub.connect(transport.pub_endpoint)
    try:
        for i in range(300):
            sub.setsockopt(zmq.SUBSCRIBE, b"/junk/%d/" % i + b"x" * 900)   # under the 1 KiB cap, no topic
        sub.setsockopt(zmq.SUBSCRIBE, b"/bot/ls/")
        deadline = time.monotonic() + 30
        while core.topics.prefixes != {b"/bot/ls/": 1} and time.monotonic() < deadline:
            time.sleep(0.02)                                # poll: the server applies them in its loop
        assert core.topics.prefixes == {b"/bot/ls/": 1}
        assert "/bot/ls/value" in core.topics.demanded
        sub.close()                                         # the peer goes: its subscription too
        deadline = time.monotonic() + 30
        while core.topics.prefixes and time.monotonic() < deadline:
            time.sleep(0.02)
        assert core.topics.prefixes == {} and core.topics.demanded == set()
    finally:
        if not sub.closed:
            sub.close()


def test_a_repeated_error_is_logged_at_powers_of_ten() -> None:
    lines: list[str] = []
    core = Core(Simulation.from_file(WORLD, precision="fast"), log=lines.append)
    for _ in range(1000):
        core.log_error("internal error: boom\ntraceback lines")
    core.log_error("internal error: another")
    assert lines == ["internal error: boom\ntraceback lines", "internal error: boom (seen 10 times)",
                     "internal error: boom (seen 100 times)", "internal error: boom (seen 1000 times)",
                     "internal error: another"]


def test_errors_sharing_a_long_start_are_each_logged() -> None:
    """Two lines whose first 300 characters agree (a rebuilt PROTO's path, then what failed) both print."""
    lines: list[str] = []
    core = Core(Simulation.from_file(WORLD, precision="fast"), log=lines.append)
    start = "/a/long/path/" + "p" * 300 + ".proto: "
    for what in ("texture 'a.png' not found", "texture 'b.png' not found", "texture 'a.png' not found"):
        core.log_error(start + what)
    assert lines == [start + "texture 'a.png' not found", start + "texture 'b.png' not found"]


def test_a_step_with_thousands_of_motor_commands_is_refused_cheaply(server) -> None:
    core, transport = server
    client = Dealer(transport.rpc_endpoint)
    try:
        assert client.call("attach", {"robot": "rover"})["ok"]
        motors = {f"m{i}": {"velocity": 1.0} for i in range(20_000)}
        r = client.call("/rover/robot/step", {"motors": motors})
        assert r["error"]["code"] == ErrorCode.INVALID_ARGUMENT and "at most 256" in r["error"]["message"]
        assert core.sim.time_ms == 0                       # refused before any step
    finally:
        client.close()


def _stepping_controller(endpoint: str, robot: str = "bot2") -> tuple[Connection, str]:
    """A live controller: attached, pinging every 100 ms (its own judgement of the server made
    patient: what is under test is the server's judgement of it)."""
    good = Connection(endpoint, timeout=60)
    session = good.call("attach", {"robot": robot})["session"]
    good.start_heartbeat(session, 100, lost_after_s=120)
    return good, session


def test_a_million_frame_message_neither_stalls_the_world_for_long_nor_drops_an_innocent_controller() -> None:
    """issue 28: one message of 10^6 empty frames stopped the world ~6 s (its frames dropped 4096 per
    loop turn at ~5 µs each), then the server dropped the innocent controller's session ("silent
    for 3 s") and its step answered NOT_ATTACHED. Now the frames go at ~0.05 µs (C step path) or
    ~0.7 µs (Python) each, and a stretch in which the server read no request is not counted as
    anyone's silence. Here the liveness is 0.3 s (heartbeat 100 ms) so that the old stall (300,000
    frames: ~1.5 s) reproduced the drop."""
    with inproc_server(heartbeat_ms=100) as (core, transport):
        good, session = _stepping_controller(transport.rpc_endpoint)
        bad = Dealer(transport.rpc_endpoint)
        try:
            t = [good.call("/bot2/robot/step")["time_ms"] for _ in range(3)]
            bad.sock.send_multipart([b""] * 300_000 + [msgpack.packb({"id": 1, "service": "get_info", "args": {}})])
            assert bad.sock.poll(60_000)
            reply = msgpack.unpackb(bad.sock.recv())
            assert reply["error"]["code"] == ErrorCode.TOO_LARGE and str(MAX_FRAMES) in reply["error"]["message"]
            t += [good.call("/bot2/robot/step")["time_ms"] for _ in range(3)]
            assert t == [16, 32, 48, 64, 80, 96]                   # the same session, no step lost
            assert core.lockstep.session_for("bot2").token == session
            assert bad.call("get_info")["ok"]
            assert transport.gate.counts["frames_dropped"] >= 300_000 - MAX_FRAMES
        finally:
            good.close()
            bad.close()


def test_the_servers_own_stall_is_not_a_controllers_silence() -> None:
    """issue 28: never blame a peer for the server's stall. The server's clock jumps 1 s inside one
    loop pass (a hook, standing in for a long world step or request: the loop read nothing for
    that second) while a controller with a 0.3 s liveness pings on: it keeps its session. Before,
    the session expired on the next pass."""
    offset = [0.0]
    core = Core(Simulation.from_file(WORLD, precision="fast"), heartbeat_ms=100)
    transport = Transport(core, "tcp://127.0.0.1:0", "tcp://127.0.0.1:0", clock=lambda: time.monotonic() + offset[0])
    thread = threading.Thread(target=transport.run, daemon=True)
    thread.start()
    good, session = _stepping_controller(transport.rpc_endpoint)

    def stall() -> None:
        if not offset[0]:
            offset[0] = 1.0

    try:
        assert good.call("/bot2/robot/step")["time_ms"] == 16
        transport.hooks.append(stall)
        transport.wake()
        wait_until(lambda: offset[0], what="the stall")
        assert [good.call("/bot2/robot/step")["time_ms"] for _ in range(3)] == [32, 48, 64]
        assert core.lockstep.session_for("bot2").token == session
    finally:
        good.close()
        transport.stop()
        thread.join(30)


def test_a_reply_over_64_mib_is_answered_too_large_naming_its_largest_values(monkeypatch) -> None:
    """issue 28: a step reply above a client's limit (the C client's 64 MiB) never arrived and the
    step never returned. The server sends no reply longer than wire.MAX_REPLY; the limit is made
    small here so that the lidars of the test world exceed it."""
    import sensorium.server.daemon.services as services

    monkeypatch.setattr(services, "MAX_REPLY", 200)
    core = Core(Simulation.from_file(WORLD, precision="fast"), log=lambda line: None)
    A = b"S-A"

    def call(service: str, args: dict, rid: int) -> list[dict]:
        return [msgpack.unpackb(f[-1]) for f in core.handle([A, msgpack.packb({"id": rid, "service": service,
                                                                                 "args": args})], 0.0)]

    call("attach", {"robot": "bot"}, 1)
    for rid, dev in enumerate(("lidar", "lidar2", "ls"), start=2):
        call(f"/bot/{dev}/enable", {"value": 16}, rid)
    assert call("/bot/robot/step", {}, 9) == []
    replies, _ = core.step_once(0.0)
    reply = msgpack.unpackb(replies[0][-1])
    assert reply["id"] == 9 and reply["error"]["code"] == ErrorCode.TOO_LARGE
    assert "exceeds the limit of 200 bytes" in reply["error"]["message"]
    assert "largest values: lidar, lidar2, ls" in reply["error"]["message"]
    assert call("/bot/robot/step", {}, 9) == [reply]             # a retry gets the same answer
    assert call("get_info", {}, 10)[0]["error"]["code"] == ErrorCode.TOO_LARGE     # any reply
