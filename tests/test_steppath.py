"""The step path (issue 25): the optional C gate recognises exactly the plain step request and
nothing else, a recognised step is answered as ``Core.handle`` answers the same bytes, and a whole
scripted session through the server gives byte-identical replies with the C gate and with the
pure-Python one. The C tests are skipped (with the reason) where the extension is not built."""

from __future__ import annotations

import itertools
import random
import threading

import msgpack
import pytest
import zmq
from _inproc import WORLD

from sensorium.schemas.services import MAX_PERIOD_MS
from sensorium.server.daemon.services import Core
from sensorium.server.daemon.steppath import PyGate, gate_for, native_gate_class
from sensorium.server.daemon.transport import MAX_FRAMES, Transport
from sensorium.server.sim.simulation import Simulation

GATE, WHY = native_gate_class()
needs_c = pytest.mark.skipif(GATE is None, reason=WHY or "C step path not built")
IDENT = b"S-controller-0001"
SERVICE = b"/bot/robot/step"


def pk(obj) -> bytes:
    return msgpack.packb(obj, use_bin_type=True)


def raw_map(*pairs: bytes) -> bytes:
    """A msgpack fixmap written by hand (to choose encodings msgpack-python would not)."""
    return bytes([0x80 | len(pairs) // 2]) + b"".join(pairs)


def s(text: str) -> bytes:
    return pk(text)


STEP = s("/bot/robot/step")
ARGS_EMPTY = b"\x80"
# bodies the C gate must recognise: (body, rid, duration)
RECOGNISED = [
    (pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": 16}}), 7, 16),
    (pk({"id": 7, "service": "/bot/robot/step", "args": {}}), 7, None),
    (pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": None}}), 7, None),
    (pk({"args": {"duration": 48}, "service": "/bot/robot/step", "id": 2**40}), 2**40, 48),      # any key order
    (pk({"id": 0, "service": "/bot/robot/step", "args": {"duration": MAX_PERIOD_MS}}), 0, MAX_PERIOD_MS),
    (pk({"id": 2**64 - 1, "service": "/bot/robot/step", "args": {}}), 2**64 - 1, None),
    (raw_map(s("id"), b"\xd2\x00\x00\x00\x05", s("service"), STEP, s("args"), b"\x81" + s("duration") + b"\xd0\x10"),
     5, 16),                                                                                      # signed encodings >= 0
    (raw_map(s("id"), b"\x05", s("service"), b"\xd9\x0f/bot/robot/step", s("args"), ARGS_EMPTY), 5, None),   # str8
]
# bodies it must hand to Python unrecognised (Python answers them, errors included)
OTHERS = [
    pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": 0}}),                # Webots' step(0)
    pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": -16}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": MAX_PERIOD_MS + 1}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": 16.0}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": True}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {"duration": 16, "motors": {}}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {"motors": {"m": {"velocity": 1.0}}}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {"durations": 16}}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {}, "extra": 1}),
    pk({"id": 7, "service": "/bot/robot/step"}),
    pk({"id": -7, "service": "/bot/robot/step", "args": {}}),
    pk({"id": 7.0, "service": "/bot/robot/step", "args": {}}),
    pk({"id": None, "service": "/bot/robot/step", "args": {}}),
    pk({"id": 7, "service": "/bot2/robot/step", "args": {}}),                              # another robot's step
    pk({"id": 7, "service": "/bot/robot/time_step", "args": {"value": 0}}),
    pk({"id": 7, "service": "/bot/robot/stepx", "args": {}}),
    pk({b"id": 7, "service": "/bot/robot/step", "args": {}}),                              # a bin key
    pk({"id": 7, "service": b"/bot/robot/step", "args": {}}),                              # a bin service
    pk({"id": 7, "service": "/bot/robot/step", "args": []}),
    pk({"id": 7, "service": "/bot/robot/step", "args": {}}) + b"\xc0",                     # trailing bytes
    pk({"id": 7, "service": "/bot/robot/step", "args": {}})[:-1],                          # cut short
    raw_map(s("id"), b"\x07", s("id"), b"\x08", s("args"), ARGS_EMPTY),                   # a key twice
    b"\xde\x00\x03" + pk({"id": 7, "service": "/bot/robot/step", "args": {}})[1:],         # map16 header
    b"",
    b"\xc1",
    pk([7, "/bot/robot/step", {}]),
]


# ---------------------------------------------------------------------- the gate alone

def pair(step_path: str):
    """A ROUTER with its gate and a DEALER named IDENT, on inproc."""
    ctx = zmq.Context.instance()
    router = ctx.socket(zmq.ROUTER)
    router.setsockopt(zmq.LINGER, 0)
    endpoint = f"inproc://steppath-{next(_names)}"
    router.bind(endpoint)
    dealer = ctx.socket(zmq.DEALER)
    dealer.setsockopt(zmq.LINGER, 0)
    dealer.setsockopt(zmq.ROUTING_ID, IDENT)
    dealer.connect(endpoint)
    gate = gate_for(router, max_frames=MAX_FRAMES, max_request=1 << 20, max_duration=MAX_PERIOD_MS,
                    discard_budget=1000, step_path=step_path)
    gate.set_peers([(IDENT, SERVICE, 0), (b"S-someone-else", b"/bot2/robot/step", 1)])
    return router, dealer, gate


_names = itertools.count()


@needs_c
def test_the_c_gate_recognises_the_plain_step_request_and_nothing_else():
    router, dealer, gate = pair("c")
    try:
        for body, rid, duration in RECOGNISED:
            dealer.send(body)
            assert gate.receive(1000, [0], 64) == [(0, IDENT, rid, duration)], body
        for body in OTHERS:
            dealer.send(body)
            assert gate.receive(1000, [0], 64) == [[IDENT, body]], body
        dealer.send_multipart([b"", RECOGNISED[0][0]])                 # a REQ-style envelope: Python's
        assert gate.receive(1000, [0], 64) == [[IDENT, b"", RECOGNISED[0][0]]]
        gate.set_peers([(b"S-someone-else", SERVICE, 0)])              # the robot is attached to another socket
        dealer.send(RECOGNISED[0][0])
        assert gate.receive(1000, [0], 64) == [[IDENT, RECOGNISED[0][0]]]
        assert gate.receive(0, [0], 64) is None
    finally:
        dealer.close()
        router.close()


def _plain_step(body: bytes) -> tuple | None:
    """(rid, duration) where msgpack decodes ``body`` to a plain step request of /bot, else None
    (an oracle written from the protocol, not from the C parser)."""
    try:
        m = msgpack.unpackb(body, raw=False, strict_map_key=False)
    except Exception:  # noqa: BLE001 - anything undecodable is not a step
        return None
    if type(m) is not dict or set(m) != {"id", "service", "args"}:
        return None
    rid, args = m["id"], m["args"]
    if type(rid) is not int or not 0 <= rid < 2**64 or m["service"] != "/bot/robot/step" or type(args) is not dict:
        return None
    duration = args.get("duration") if set(args) <= {"duration"} else 0
    if duration is None:
        return rid, None
    return (rid, duration) if type(duration) is int and 1 <= duration <= MAX_PERIOD_MS else None


@needs_c
def test_the_c_gate_never_misreads_damaged_bytes():
    """6,000 damaged bodies (cut short, bytes overwritten, inserted or appended) from the bodies
    above: the C gate recognises a body only where msgpack decodes it to a plain step with the same
    id and duration, and hands every other body to Python whole (run under AddressSanitizer too:
    no read outside a message)."""
    rng = random.Random(25)
    seeds = [body for body, _, _ in RECOGNISED] + [b for b in OTHERS if b]
    router, dealer, gate = pair("c")
    recognised = 0
    try:
        for _ in range(6000):
            b = bytearray(rng.choice(seeds))
            how = rng.randrange(4)
            if how == 0:
                del b[rng.randrange(len(b)):]
            elif how == 1:
                for _ in range(rng.randrange(1, 4)):
                    b[rng.randrange(len(b))] = rng.randrange(256)
            elif how == 2:
                b[rng.randrange(len(b) + 1):0] = bytes([rng.randrange(256)])
            else:
                b += bytes(rng.randrange(256) for _ in range(rng.randrange(1, 5)))
            body = bytes(b)
            dealer.send(body)
            (item,) = gate.receive(1000, [0], 64)
            if isinstance(item, tuple):
                recognised += 1
                want = _plain_step(body)
                assert want is not None and item == (0, IDENT, *want), (body, item, want)
            else:
                assert item == [IDENT, body], body
    finally:
        dealer.close()
        router.close()
    assert recognised >= 10       # damage that keeps a valid step (an id's or a duration's digit) is read


@pytest.mark.parametrize("step_path", [pytest.param("c", marks=needs_c), "python"])
def test_a_batch_ends_where_the_world_might_step(step_path):
    """C: recognised steps of controllers the world waits for are read on until the last one
    (the barrier); any other message, or every message when nobody is waited for, ends it.
    Python: one message per batch. Either way the core sees the same messages between steps."""
    router, dealer, gate = pair(step_path)
    try:
        step = RECOGNISED[1][0]
        get_time = pk({"id": 9, "service": "/bot/robot/get_time", "args": {}})
        for body in (step, get_time, step):
            dealer.send(body)
        first = gate.receive(1000, [0, 1], 64)                        # waiting for 0 and 1: 0's step, then get_time
        if step_path == "c":
            assert first == [(0, IDENT, 7, None), [IDENT, get_time]]
            assert gate.receive(1000, [], 64) == [(0, IDENT, 7, None)]  # nobody waited for: one by one
        else:
            assert first == [[IDENT, step]]
            assert gate.receive(1000, [0, 1], 64) == [[IDENT, get_time]]
            assert gate.receive(1000, [0, 1], 64) == [[IDENT, step]]
        dealer.send_multipart([b"x"] * (MAX_FRAMES + 5))                  # too many frames: the identity
        assert gate.receive(1000, [0], 64) == [IDENT] and gate.discarding
        with pytest.raises(RuntimeError, match="discard"):
            gate.receive(0, [0], 64)
        assert gate.discard() and not gate.discarding
        dealer.send(step)
        assert gate.receive(1000, [0], 64) is not None
        gate.close()                         # the transport closes the gate before its socket
        if step_path == "c":                 # (no call may reach a freed libzmq socket)
            with pytest.raises(RuntimeError, match="closed"):
                gate.receive(0, [0], 64)
    finally:
        dealer.close()
        router.close()


# integers at msgpack's encoding boundaries (fixint, 8, 16, 32, 64 bits; both signs for the status)
RIDS = [0, 1, 127, 128, 255, 256, 65535, 65536, 2**32 - 1, 2**32, 2**63, 2**64 - 1]
STATUSES = [0, 5, -1, -32, -33, -128, -129, -32768, -32769, -2**31, -2**31 - 1, -2**63, 2**63 - 1, 2**64 - 1]


@pytest.mark.parametrize("step_path", [pytest.param("c", marks=needs_c), "python"])
def test_send_steps_packs_the_plain_step_reply_as_msgpack_does(step_path):
    """A world step's replies in one call: (envelope, rid, status, time_ms) becomes exactly
    ok_reply(rid, {"status", "time_ms", "values": {}}) behind its envelope (a REQ's delimiter too),
    frames lists go out as they are, in order; a bad batch raises and sends nothing."""
    from sensorium.schemas.wire import ok_reply
    from sensorium.server.daemon.services import STEP_REPLY_PIECES

    router, dealer, gate = pair(step_path)
    try:
        cases = [(rid, status, t) for rid, status, t in zip(RIDS * 2, STATUSES * 2, reversed(RIDS * 2))]
        for rid, status, t in cases:
            gate.send_steps([([IDENT], rid, status, t), [IDENT, b"as is"], ([IDENT, b""], rid, status, t)],
                            STEP_REPLY_PIECES)
            want = ok_reply(rid, {"status": status, "time_ms": t, "values": {}})
            for expected in ([want], [b"as is"], [b"", want]):
                assert dealer.poll(5000)
                assert dealer.recv_multipart() == expected, (rid, status, t)
        for bad in ([([IDENT], 1, 0, 0), ([IDENT], 2**64, 0, 0)], [([IDENT], 1, -2**63 - 1, 0)],
                    [([IDENT], 1, 0, 0), "x"], [([IDENT], 1, 0.0, 0)], [([IDENT], 1, True, 0)], [(IDENT, 1, 0, 0)]):
            with pytest.raises((TypeError, OverflowError)):
                gate.send_steps(bad, STEP_REPLY_PIECES)
        gate.send_steps([[IDENT, b"after"]], STEP_REPLY_PIECES)
        assert dealer.poll(5000) and dealer.recv_multipart() == [b"after"]     # nothing of the bad batches came
    finally:
        gate.close()
        dealer.close()
        router.close()


@pytest.mark.parametrize("step_path", [pytest.param("c", marks=needs_c), "python"])
def test_exchange_sends_the_replies_then_receives(step_path):
    """exchange = send_steps then receive in one call (the transport's hot path); no replies: only
    the receive."""
    from sensorium.schemas.wire import ok_reply
    from sensorium.server.daemon.services import STEP_REPLY_PIECES

    router, dealer, gate = pair(step_path)
    try:
        assert gate.exchange([], STEP_REPLY_PIECES, 0, [0], 64) is None
        body = RECOGNISED[1][0]
        dealer.send(body)
        first = gate.exchange([], STEP_REPLY_PIECES, 5000, [0], 64)
        assert first in ([(0, IDENT, 7, None)], [[IDENT, body]])           # recognised (C) or frames (Python)
        got = gate.exchange([([IDENT], 7, 0, 16)], STEP_REPLY_PIECES, 0, [0], 64)
        assert got is None                                                # nothing more came meanwhile
        assert dealer.poll(5000) and dealer.recv() == ok_reply(7, {"status": 0, "time_ms": 16, "values": {}})
    finally:
        gate.close()
        dealer.close()
        router.close()


def test_python_is_chosen_when_asked_and_bad_choices_are_named(monkeypatch):
    router = zmq.Context.instance().socket(zmq.ROUTER)
    try:
        kw = dict(max_frames=MAX_FRAMES, max_request=1 << 20, max_duration=MAX_PERIOD_MS, discard_budget=10)
        assert isinstance(gate_for(router, step_path="python", **kw), PyGate)
        monkeypatch.setenv("SENSORIUM_STEP_PATH", "python")
        assert isinstance(gate_for(router, **kw), PyGate)
        with pytest.raises(ValueError, match="one of auto, c, python"):
            gate_for(router, step_path="fast", **kw)
    finally:
        router.close(0)


# ---------------------------------------------------------------------- the core: handle_step == handle

def core() -> Core:
    counter = itertools.count()
    return Core(Simulation.from_file(WORLD, precision="fast"), heartbeat_ms=1000, log=lambda line: None,
                new_token=lambda: f"t{next(counter)}")


def attach(c: Core, peer: bytes, robot: str) -> None:
    c.handle([peer, pk({"id": 1, "service": "attach", "args": {"robot": robot}})], 0.0)


def step_all(c: Core) -> list[list[bytes]]:
    out = []
    while (t := c.next_advance(0.0)) is not None and t <= 0.0:
        out += c.step_once(0.0)[0]
    return out


@pytest.mark.parametrize("body, rid, duration", RECOGNISED)
def test_handle_step_answers_as_handle_does(body, rid, duration):
    """Both cores get the same script; one reads the step's bytes, the other is handed them parsed.
    Every reply (the deferred step reply too, and a repeated id, a step while one is pending, a
    caller that is not attached, a step while quitting) is the same bytes."""
    a, b = core(), core()
    for c in (a, b):
        attach(c, IDENT, "bot")
        attach(c, b"S-other", "bot2")
    stranger = b"S-stranger"

    def both(peer: bytes, body_: bytes, parsed: tuple | None = None) -> None:
        got_a = a.handle([peer, body_], 0.0)
        got_b = b.handle_step(*parsed, 0.0) if parsed else b.handle([peer, body_], 0.0)
        assert got_a == got_b, (body_, got_a, got_b)

    parsed = (0, IDENT, rid, duration)
    both(IDENT, body, parsed)                                   # queued: nothing yet
    both(IDENT, body, parsed)                                   # the same id again: re-routed, still nothing
    again = pk({"id": rid + 1 if rid < 2**64 - 1 else 1, "service": "/bot/robot/step", "args": {}})
    both(IDENT, again, (0, IDENT, rid + 1 if rid < 2**64 - 1 else 1, None))   # a second step: WRONG_STATE
    both(stranger, body, (0, stranger, rid, duration))          # not the attached socket: NOT_ATTACHED
    both(b"S-other", pk({"id": 3, "service": "/bot2/robot/step", "args": {}}), (2, b"S-other", 3, None))
    assert step_all(a) == step_all(b) != []                      # the deferred replies
    both(IDENT, body, parsed)                                    # answered already: the same reply again
    a.shutdown()
    b.shutdown()
    both(IDENT, pk({"id": 99, "service": "/bot/robot/step", "args": {}}), (0, IDENT, 99, None))   # quitting: -1
    assert a.lockstep.time_ms == b.lockstep.time_ms


def test_a_step_reply_without_values_is_msgpacks_bytes():
    """Core assembles the common step reply (no new value) from pieces: the same bytes as packing it."""
    from sensorium.schemas.wire import ok_reply

    c = core()
    attach(c, IDENT, "bot2")
    for i, rid in enumerate((0, 1, 127, 128, 255, 256, 65535, 65536, 2**32, 2**64 - 1)):
        for duration in ((None, 16 * 4200)[i % 2],):     # time_ms past 127, 255, 65535 too
            c.handle_step(2, IDENT, rid, duration, 0.0)
            (reply,) = step_all(c)
            t = c.lockstep.time_ms
            assert reply == [IDENT, ok_reply(rid, {"status": 0, "time_ms": t, "values": {}})], (rid, t)
    c.shutdown()
    assert c.handle_step(2, IDENT, 5, None, 0.0) == [[IDENT, ok_reply(5, {"status": -1, "time_ms": c.lockstep.time_ms,
                                                                          "values": {}})]]


def test_a_batch_of_steps_is_answered_as_one_step_after_the_other():
    """handle_steps (the C path's batch up to the barrier) == handle_step for each, in order: the
    common ones queued, a stranger, a repeated id and a second step answered as handle answers."""
    a, b = core(), core()
    for c in (a, b):
        attach(c, IDENT, "bot")
        attach(c, b"S-other", "bot2")
    batch = [(0, IDENT, 7, 16), (0, b"S-stranger", 8, None), (0, IDENT, 7, 16), (0, IDENT, 9, None),
             (2, b"S-other", 3, 32)]
    one_by_one = [r for item in batch for r in a.handle_step(*item, 0.0)]
    assert b.handle_steps(batch, 0.0) == one_by_one and len(one_by_one) == 2
    assert step_all(a) == step_all(b) != []
    assert a.lockstep.time_ms == b.lockstep.time_ms == 16


def test_step_replies_without_values_are_left_for_the_gate_to_pack():
    """step_once_compact leaves the common reply as (envelope, rid, status, time_ms) and gives a
    reply with new values as frames; step_once is the same with the former packed; a repeated id
    after either gets the same bytes again."""
    c = core()
    attach(c, IDENT, "bot")
    attach(c, b"S-other", "bot2")
    c.handle([IDENT, pk({"id": 2, "service": "/bot/ls/enable", "args": {"value": 32}})], 0.0)
    c.handle_steps([(0, IDENT, 3, 32), (2, b"S-other", 4, 16)], 0.0)
    replies, _ = c.step_once_compact(0.0)
    assert replies == [([b"S-other"], 4, 0, 16)]                         # bot waits for 32 ms; bot2's is plain
    c.handle_step(2, b"S-other", 5, 16, 0.0)
    replies, _ = c.step_once_compact(0.0)
    (values, plain) = replies
    assert type(values) is list and values[0] == IDENT and msgpack.unpackb(values[1])["result"]["values"]
    assert plain == ([b"S-other"], 5, 0, 32)
    assert c.handle_step(2, b"S-other", 5, 16, 0.0) == [c.plain_step_frames(plain)]   # a repeated id
    assert c.handle_step(0, IDENT, 3, 32, 0.0) == [values]


# ---------------------------------------------------------------------- the whole server, both gates

def scripted_session(step_path: str) -> list[bytes]:
    """One client (a DEALER, and a REQ for one request) drives a server through a script that
    touches every branch of the step path; the reply bytes in the order they came."""
    counter = itertools.count()
    c = Core(Simulation.from_file(WORLD, precision="fast"), heartbeat_ms=5000, log=lambda line: None,
             new_token=lambda: f"t{next(counter)}")
    transport = Transport(c, "tcp://127.0.0.1:0", "tcp://127.0.0.1:0", step_path=step_path)
    thread = threading.Thread(target=transport.run, daemon=True)
    thread.start()
    ctx = zmq.Context.instance()
    d = ctx.socket(zmq.DEALER)
    d.setsockopt(zmq.LINGER, 0)
    d.setsockopt(zmq.ROUTING_ID, IDENT)
    d.connect(transport.rpc_endpoint)
    holder = ctx.socket(zmq.DEALER)          # attaches bot2 and never steps: the world waits, steps stay pending
    holder.setsockopt(zmq.LINGER, 0)
    holder.connect(transport.rpc_endpoint)
    got: list[bytes] = []

    def recv(sock: zmq.Socket = d, n: int = 1) -> None:
        for _ in range(n):
            assert sock.poll(30_000), f"no reply ({step_path})"
            got.append(sock.recv())

    def call(service: str, args: dict, rid: int, n: int = 1, sock: zmq.Socket = d) -> None:
        sock.send(pk({"id": rid, "service": service, "args": args}))
        recv(sock, n)

    try:
        call("attach", {"robot": "bot"}, 1)
        call("/bot/ls/enable", {"value": 32}, 2)
        for rid in range(3, 13):                                        # plain steps, 16 and 32 ms
            call("/bot/robot/step", {"duration": 16 * (1 + rid % 2)}, rid)
        call("/bot/robot/step", {}, 13)
        call("/bot/robot/step", {"duration": None}, 14)
        call("/bot/robot/step", {"duration": 20}, 15)                   # rounded up
        call("/bot/robot/step", {"duration": 0}, 16)                    # step(0)
        call("/bot/robot/step", {"duration": 16}, 15)                   # a repeated id: the same reply again
        call("attach", {"robot": "bot2"}, 1, sock=holder)
        d.send(pk({"id": 17, "service": "/bot/robot/step", "args": {"duration": 160}}))
        call("/bot/robot/step", {}, 18)                                 # one is pending: WRONG_STATE
        call("/bot/robot/step", {"duration": 160}, 17, n=0)             # the pending one again: re-routed
        call("/bot/robot/get_time", {}, 19)
        call("/bot2/robot/step", {}, 20)                                # bot2 is the holder's
        call("detach", {"session": "t1"}, 2, sock=holder)
        recv()                                                          # 17, now that the world goes on
        call("/bot/robot/step", {"duration": 16.5}, 21)
        call("/bot/robot/step", {"duration": 16, "motors": {"nope": {"velocity": 1.0}}}, 22)
        call("/bot/robot/time_step", {"value": 0}, 23)
        d.send_multipart([b"x"] * (MAX_FRAMES + 3))                     # too many frames
        recv()
        req = ctx.socket(zmq.REQ)                                       # a REQ client's envelope
        req.setsockopt(zmq.LINGER, 0)
        req.connect(transport.rpc_endpoint)
        req.send(pk({"id": 24, "service": "get_info", "args": {}}))
        assert req.poll(30_000)
        got.append(pk(sorted(msgpack.unpackb(req.recv())["result"].keys())))
        req.close()
        call("attach", {"robot": "bot2"}, 3, sock=holder)
        d.send(pk({"id": 25, "service": "/bot/robot/step", "args": {"duration": 64}}))
        call("detach", {"session": "t0"}, 26, n=2)                      # the pending step answers -1 first
        call("attach", {"robot": "bot"}, 27)
        call("detach", {"session": "t2"}, 4, sock=holder)
        call("/bot/robot/step", {}, 28)
        assert c.errors == 0
    finally:
        d.close()
        holder.close()
        transport.stop()
        thread.join(30)
    return got


@pytest.mark.parametrize("step_path", [pytest.param("c", marks=needs_c)])
def test_a_scripted_session_gets_byte_identical_replies_from_both_gates(step_path):
    python = scripted_session("python")
    assert len(python) == 34
    assert scripted_session(step_path) == python


@needs_c
def test_steps_of_several_controllers_come_in_one_batch_per_world_step():
    """Three controllers stepping in lockstep: every step request is recognised, and the loop
    serves them in batches (it enters Python about once per world step, not per request)."""
    from sensorium.client.connection import Connection

    c = Core(Simulation.from_file(WORLD, precision="fast"), heartbeat_ms=5000, log=lambda line: None)
    transport = Transport(c, "tcp://127.0.0.1:0", "tcp://127.0.0.1:0", step_path="c")
    batches: list[int] = []
    serve = transport._serve
    transport._serve = lambda batch, now: (batches.append(len(batch)), serve(batch, now))[1]  # type: ignore[method-assign]
    thread = threading.Thread(target=transport.run, daemon=True)
    thread.start()
    robots = ["bot", "bot2", "rover"]
    conns = [Connection(transport.rpc_endpoint, timeout=60) for _ in robots]
    times: dict[str, list[int]] = {r: [] for r in robots}
    try:
        for conn, robot in zip(conns, robots):
            conn.call("attach", {"robot": robot})
        before = dict(transport.gate.counts)
        first = len(batches)

        def run(conn: Connection, robot: str) -> None:
            for _ in range(200):
                times[robot].append(conn.call(f"/{robot}/robot/step", {})["time_ms"])

        threads = [threading.Thread(target=run, args=(conn, robot)) for conn, robot in zip(conns, robots)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(120)
        counts = {k: v - before[k] for k, v in transport.gate.counts.items()}
    finally:
        for conn in conns:
            conn.close()
        transport.stop()
        thread.join(30)
    assert all(times[r] == list(range(16, 16 * 201, 16)) for r in robots)       # lockstep: no step skipped
    assert counts["fast_steps"] == counts["messages"] == 600
    served = batches[first:]
    assert sum(served) == 600 and len(served) < 450 and max(served) == 3, (len(served), max(served))


def test_an_extension_built_from_older_sources_is_refused_with_the_rebuild_command(monkeypatch):
    import sys
    import types

    from sensorium.server.daemon import steppath

    stale = types.ModuleType("sensorium.server.daemon._steppath")

    class Gate:             # an older build: the receive/send gate without the batched replies
        def receive(self): ...
        def send(self): ...

    stale.Gate, stale.MSG_SIZE = Gate, 64
    monkeypatch.setitem(sys.modules, "sensorium.server.daemon._steppath", stale)
    monkeypatch.setattr(sys.modules["sensorium.server.daemon"], "_steppath", stale, raising=False)
    monkeypatch.setattr(steppath, "_native", None)
    cls, why = steppath.native_gate_class()
    assert cls is None
    assert "older sources" in why and "Gate.send_steps" in why and "Gate.exchange" in why and "pip install ." in why
    monkeypatch.setattr(steppath, "_native", None)      # the next caller looks again
