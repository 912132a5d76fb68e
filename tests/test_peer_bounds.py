"""One client cannot stall the world or make the server hold memory for it (issue: hardening).

Each test first does what an adversarial or broken client did (a message of a million frames,
deeply nested arguments, a huge request echoed back, long junk subscriptions), then checks that a
well-behaved controller keeps stepping and that what the server holds stays bounded.
"""

from __future__ import annotations

import time

import msgpack
import pytest
import zmq
from _inproc import WORLD, inproc_server

from sensorium.client.connection import Connection
from sensorium.schemas.wire import MAX_ERROR_MESSAGE, ErrorCode
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.transport import MAX_FRAMES
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
