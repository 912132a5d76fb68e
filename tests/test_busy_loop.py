"""The lockstep's hot path (issue 14): the transport's busy mode (blocking in the ROUTER's recv while
requests flow) still serves subscriptions, wake-ups and stop; the core's cache of validated
arguments skips no check; the reused msgpack packers give msgpack's bytes; the client's leaner
wait still matches out-of-order replies."""

from __future__ import annotations

import threading

import msgpack
import pytest
import zmq
from _inproc import WORLD, inproc_server
from _serve import wait_until

from sensorium.client.connection import Connection
from sensorium.schemas import services as S
from sensorium.schemas import wire
from sensorium.server.daemon import services as services_mod
from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation

BASIC = 16      # tests/worlds/server.yaml



class Stepper(threading.Thread):
    """A controller stepping robot bot2 as fast as it can (keeps the server's loop busy)."""

    def __init__(self, endpoint: str):
        super().__init__(daemon=True)
        self.conn = Connection(endpoint, timeout=30)
        self.conn.call("attach", {"robot": "bot2"})
        self.steps = 0
        self.last: dict = {}
        self.halt = threading.Event()
        self.error: BaseException | None = None

    def run(self) -> None:
        try:
            while not self.halt.is_set():
                self.last = self.conn.call("/bot2/robot/step", {"duration": BASIC})
                self.steps += 1
                if self.last["status"] == -1:
                    return
        except BaseException as exc:  # noqa: BLE001 - reported by the test
            self.error = exc
        finally:
            self.conn.close()


def test_subscription_and_wake_are_served_while_a_controller_steps_nonstop():
    with inproc_server(heartbeat_ms=2000) as (_core, transport):
        stepper = Stepper(transport.rpc_endpoint)
        stepper.start()
        ctx = zmq.Context.instance()
        sub = ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.LINGER, 0)
        try:
            wait_until(lambda: stepper.steps > 50, what="stepping")
            sub.connect(transport.pub_endpoint)
            sub.setsockopt(zmq.SUBSCRIBE, b"/clock\0")
            # the subscription reaches the XPUB while the loop blocks in the ROUTER's recv: it is
            # applied within a look-around, and /clock arrives with the steps that follow
            assert sub.poll(30_000), "no /clock message while a controller was stepping"
            topic, env, body = wire.decode_topic(sub.recv_multipart())
            assert topic == "/clock" and wire.stamp_ns(body["clock"]) % (BASIC * 10**6) == 0
            # a wake from another thread runs the hooks (they run every pass; a wake makes one soon)
            ran = threading.Event()
            transport.hooks.append(ran.set)
            transport.wake()
            assert ran.wait(30), "hook never ran"
            assert stepper.error is None and stepper.is_alive()
        finally:
            sub.close(0)
            stepper.halt.set()
            stepper.join(30)


def test_stop_while_busy_answers_the_pending_step_with_minus_one():
    with inproc_server(heartbeat_ms=2000) as (core, transport):
        stepper = Stepper(transport.rpc_endpoint)
        stepper.start()
        wait_until(lambda: stepper.steps > 50, what="stepping")
        transport.stop()
        stepper.join(30)
        assert not stepper.is_alive() and stepper.error is None
        assert stepper.last["status"] == -1
        assert core.lockstep.shutting_down


def test_wake_runs_the_hooks_of_an_idle_loop():
    with inproc_server(heartbeat_ms=2000) as (_core, transport):
        ran = threading.Event()
        with Connection(transport.rpc_endpoint, timeout=30) as conn:
            conn.call("get_info")                       # the loop is up; nothing else in flight
        transport.hooks.append(ran.set)
        ran.clear()
        transport.wake()
        assert ran.wait(30), "hook never ran after wake()"


def test_client_matches_replies_that_arrive_out_of_order():
    with inproc_server(heartbeat_ms=2000) as (_core, transport):
        with Connection(transport.rpc_endpoint, timeout=30) as conn:
            session = conn.call("attach", {"robot": "bot2"})["session"]
            r_step = conn.send("/bot2/robot/step", {"duration": BASIC})
            r_info = conn.send("get_info")
            r_ping = conn.send("ping", {"session": session})
            # the step's reply comes after the others: waiting for it keeps theirs
            assert conn.wait(r_step)["status"] == 0
            assert conn.wait(r_ping)["time_ms"] >= BASIC
            assert conn.wait(r_info)["world"] == "server-test"
            assert conn.outstanding == 0


# ---------------------------------------------------------------------- validated-argument cache

def _core() -> Core:
    core = Core(Simulation.from_file(WORLD, precision="fast"), log=lambda line: None)
    reply = core.handle([b"A", wire.pack({"id": 1, "service": "attach", "args": {"robot": "bot2"}})], 0.0)
    assert msgpack.unpackb(reply[0][-1])["ok"] is True
    return core


def _step(core: Core, rid: int, args: dict) -> dict | None:
    """Send one step request; its reply (an error at once, or the step's after step_once)."""
    out = core.handle([b"A", wire.pack({"id": rid, "service": "/bot2/robot/step", "args": args})], 0.0)
    if out:
        return msgpack.unpackb(out[0][-1])
    replies, _ = core.step_once(0.0)
    return msgpack.unpackb(replies[0][-1]) if replies else None


@pytest.mark.parametrize("bad", [True, 16.0, -16, "16", S.MAX_PERIOD_MS + 1])
def test_cached_arguments_skip_no_check(bad):
    core = _core()
    assert _step(core, 2, {"duration": BASIC})["result"]["status"] == 0      # cached now
    assert _step(core, 3, {"duration": 1})["result"]["status"] == 0          # 1 == True: cached too
    reply = _step(core, 4, {"duration": bad})
    assert reply["ok"] is False and reply["error"]["code"] == wire.ErrorCode.INVALID_ARGUMENT
    assert "duration" in reply["error"]["message"]
    reply = _step(core, 5, {"duration": BASIC, "speed": 1})                   # unknown key: not cached away
    assert reply["ok"] is False and "unknown argument 'speed'" in reply["error"]["message"]


def test_cached_arguments_are_the_validated_model_and_bounded():
    core = _core()
    first = core._validated(S.StepArgs, "/bot2/robot/step", {"duration": 32})
    assert first == S.StepArgs.model_validate({"duration": 32})
    assert core._validated(S.StepArgs, "/bot2/robot/step", {"duration": 32}) is first
    for d in range(3 * services_mod.ARG_CACHE_SIZE):
        core._validated(S.StepArgs, "/bot2/robot/step", {"duration": d})
        assert len(core._arg_cache) <= services_mod.ARG_CACHE_SIZE
    # nested values are validated every time (never cached)
    core._arg_cache.clear()
    core._validated(S.StepArgs, "/bot2/robot/step", {"duration": 32, "motors": {}})
    assert core._arg_cache == {}


# ---------------------------------------------------------------------- reused msgpack packers

DOCS = [{"id": 1, "ok": True, "result": {"status": 0, "time_ms": 32, "values": {}}}, [1.5, -0.0, float("inf")],
        {"b": b"\x00\xff", "s": "é", "n": None, "big": 2**63}, "x" * 300, {"nested": [{"a": [1, 2, {"c": 3}]}]}]


def test_pack_gives_msgpacks_bytes_and_recovers_from_a_failure():
    for doc in DOCS:
        assert wire.pack(doc) == msgpack.packb(doc, use_bin_type=True)
    with pytest.raises(TypeError):
        wire.pack({"a": object()})
    assert wire.pack(DOCS[0]) == msgpack.packb(DOCS[0], use_bin_type=True)    # nothing left over


def test_a_packer_that_made_a_large_document_is_not_kept():
    big = {"data": b"\x01" * (wire.PACKER_KEEP + 1)}
    assert wire.pack(big) == msgpack.packb(big, use_bin_type=True)
    assert wire._PACKERS.packer is None
    assert wire.pack(DOCS[0]) == msgpack.packb(DOCS[0], use_bin_type=True)


def test_pack_from_many_threads():
    errors: list[str] = []

    def worker(k: int) -> None:
        for i in range(2000):
            doc = {"id": k * 100_000 + i, "payload": [k] * (i % 7), "name": f"t{k}-{i}"}
            if wire.pack(doc) != msgpack.packb(doc, use_bin_type=True):
                errors.append(f"thread {k} doc {i}")

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert errors == []
