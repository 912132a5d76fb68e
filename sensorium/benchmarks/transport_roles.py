"""The processes of the transport section (``python -m sensorium.benchmarks.transport_roles ROLE
ARGS…``): raw pyzmq floors, minimal servers, and clients that time round trips on request."""

from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

# a server role quits after this long without a message (its parent gone); the bench starts several
# `sensorium serve` processes after it, seconds each on a busy machine
IDLE_MS = 120_000


# ============================================================================ subprocess roles
def _bind(s, endpoint: str) -> str:
    """Bind ``tcp://host`` to an ephemeral port, or an ``ipc://path`` as given; the bound endpoint."""
    if endpoint.startswith("ipc://"):
        s.bind(endpoint)
        return endpoint
    return f"{endpoint}:{s.bind_to_random_port(endpoint)}"


def _role_rep_echo(endpoint: str, cpu: str = "") -> None:
    """Raw pyzmq REP: echo every message (the floor of any request/reply round trip). ``cpu``: its
    thread and ZeroMQ's I/O threads on that CPU, as ``sensorium serve --cpu`` runs (the pinned floor)."""
    _serve_rep(endpoint, 0.0, int(cpu) if cpu else None)


def _role_rep_work(endpoint: str, work_us: str) -> None:
    """``rep-echo`` that keeps its thread busy for ``work_us`` µs of wall time per message before
    answering (a spin on ``perf_counter``): what a server's per-message work costs a round trip on
    this machine, beyond the work itself (the section's 'server work' row)."""
    _serve_rep(endpoint, float(work_us) * 1e-6)


def _serve_rep(endpoint: str, work: float, cpu: int | None = None) -> None:
    import zmq

    ctx = zmq.Context()
    if cpu is not None:
        ctx.set(zmq.THREAD_AFFINITY_CPU_ADD, cpu)
        os.sched_setaffinity(0, {cpu})
    s = ctx.socket(zmq.REP)
    print(f"ready {_bind(s, endpoint)}", flush=True)
    clock = time.perf_counter
    poller = zmq.Poller()
    poller.register(s, zmq.POLLIN)
    while True:
        if not poller.poll(IDLE_MS):
            break                                    # idle that long: the parent is gone
        msg = s.recv()
        if msg == b"quit":
            s.send(b"bye")
            break
        if work:
            until = clock() + work
            while clock() < until:
                pass
        s.send(msg)
    s.close(0)
    ctx.term()


def _role_router_echo(endpoint: str) -> None:
    """A minimal Python msgpack server on a ROUTER: answer every request with a step-like ok reply.
    With the client library on the other end, it is the floor of a Python request/reply round trip."""
    import msgpack

    def answer(body: bytes) -> tuple[bytes | None, bool]:
        req = msgpack.unpackb(body, raw=False)
        if req.get("service") == "quit":
            return None, True
        return msgpack.packb({"id": req["id"], "ok": True, "result": {"status": 0, "time_ms": 0, "values": {}}},
                             use_bin_type=True), False

    _serve_router(endpoint, answer)


def _role_router_raw(endpoint: str) -> None:
    """Raw pyzmq ROUTER echo: every message sent back as received (no msgpack): the request/reply
    floor of the socket pattern a multi-client server needs, beside REQ ↔ REP's."""
    _serve_router(endpoint, lambda body: (body, body == b"quit"))


def _serve_router(endpoint: str, answer) -> None:
    """A ROUTER answering each request's last frame with ``answer(body)`` = (reply or None, stop)."""
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.ROUTER)
    print(f"ready {_bind(s, endpoint)}", flush=True)
    poller = zmq.Poller()
    poller.register(s, zmq.POLLIN)
    while poller.poll(IDLE_MS):
        frames = s.recv_multipart()
        reply, stop = answer(frames[-1])
        if reply is not None:
            s.send_multipart(frames[:-1] + [reply])
        if stop:
            break
    s.close(0)
    ctx.term()


def _chunks(call, close) -> None:
    """Serve timing requests from stdin: 'run K' → K timed calls, printed as a JSON list of
    seconds; anything else → ``close()`` and stop. (Lets the parent interleave several clients.)"""
    for _ in range(200):
        call()
    print("ready", flush=True)
    for line in sys.stdin:
        parts = line.split()
        if not parts or parts[0] != "run":
            break
        out = np.empty(int(parts[1]))
        for i in range(len(out)):
            t0 = time.perf_counter()
            call()
            out[i] = time.perf_counter() - t0
        print(json.dumps(out.tolist()), flush=True)
    close()


def _role_conn_client(endpoint: str) -> None:
    """The client library's Connection calling a step-like service."""
    from sensorium.client.connection import Connection

    conn = Connection(endpoint, timeout=30)
    args = {"duration": 8}

    def close():
        conn.send("quit", {})
        conn.close()

    _chunks(lambda: conn.call("/c0/robot/step", args), close)


def _role_dealer_client(endpoint: str) -> None:
    """A bare DEALER: pack, send, blocking recv, unpack."""
    import msgpack
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.DEALER)
    s.connect(endpoint)
    body = msgpack.packb({"id": 7, "service": "/c0/robot/step", "args": {"duration": 8}}, use_bin_type=True)

    def call():
        s.send(body)
        msgpack.unpackb(s.recv(), raw=False)

    def close():
        s.send(msgpack.packb({"id": 0, "service": "quit", "args": {}}))
        s.close(0)
        ctx.term()

    _chunks(call, close)


# a step request's bytes, as the raw floors send them (never decoded: they echo)
STEP_BYTES = b"\x83\xa2id\x01\xa7service\xae/c0/robot/step\xa4args\x81\xa8duration\x08"


def _role_req(endpoint: str) -> None:
    """Raw pyzmq REQ ping-pong of a step request's bytes (the floor)."""
    _raw_ping_pong(endpoint, "REQ")


def _role_dealer_raw(endpoint: str) -> None:
    """The same ping-pong from a raw DEALER (no msgpack), against ``router-raw``."""
    _raw_ping_pong(endpoint, "DEALER")


def _raw_ping_pong(endpoint: str, socket_type: str) -> None:
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(getattr(zmq, socket_type))
    s.connect(endpoint)

    def call():
        s.send(STEP_BYTES)
        s.recv()

    def close():
        s.send(b"quit")
        s.recv()
        s.close(0)
        ctx.term()

    _chunks(call, close)


def _role_stepper(rpc: str, robot: str, duration: str) -> None:
    """A Sensorium controller (client library ``Connection``) stepping its robot in lockstep."""
    from sensorium.client.connection import Connection

    conn = Connection(rpc, timeout=30)
    reply = conn.call("attach", {"robot": robot})
    session = reply["session"]
    conn.start_heartbeat(session, reply["heartbeat_ms"])        # silent while the other clients run
    service, args = f"/{robot}/robot/step", {"duration": int(duration)}

    def close():
        conn.call("detach", {"session": session})
        conn.close()

    _chunks(lambda: conn.call(service, args), close)


def _bare_step_session(rpc: str, robot: str, duration: str):
    """A bare DEALER attached to ``robot``: (context, socket, session, step), ``step`` one lockstep
    round trip (pack, send, blocking recv, unpack) without the client library."""
    import msgpack
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.DEALER)
    s.setsockopt(zmq.LINGER, 0)
    s.connect(rpc)
    s.send(msgpack.packb({"id": 1, "service": "attach", "args": {"robot": robot}}))
    session = msgpack.unpackb(s.recv())["result"]["session"]
    packer = msgpack.Packer()
    service, args = f"/{robot}/robot/step", {"duration": int(duration)}
    ids = iter(range(2, 1 << 62))

    def step():
        s.send(packer.pack({"id": next(ids), "service": service, "args": args}))
        msgpack.unpackb(s.recv(), raw=False)

    return ctx, s, session, step


def _role_bare_stepper(rpc: str, robot: str, duration: str) -> None:
    """A bare DEALER stepping a robot in lockstep (pack, send, blocking recv, unpack): the client
    library's share of a Sensorium round trip is the difference to ``stepper``."""
    import msgpack

    ctx, s, session, call = _bare_step_session(rpc, robot, duration)

    def close():
        s.send(msgpack.packb({"id": 0, "service": "detach", "args": {"session": session}}))
        s.recv()
        s.close(0)
        ctx.term()

    _chunks(call, close)


def _role_pub(endpoint: str, size: str, count: str) -> None:
    """Raw pyzmq PUB: wait for a subscriber, then publish ``count`` messages of ``size`` bytes."""
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.XPUB)
    s.setsockopt(zmq.SNDHWM, 100)
    port = s.bind_to_random_port(endpoint)
    print(f"ready {endpoint}:{port}", flush=True)
    if not s.poll(20_000):
        return
    s.recv()                                         # the subscription
    body = os.urandom(int(size))
    for i in range(int(count)):
        s.send_multipart([b"/pc\0", i.to_bytes(8, "little"), body])
    s.send_multipart([b"/pc\0", b"end", b""])
    time.sleep(1.0)
    s.close(0)
    ctx.term()


def _bursts(step, steps: int) -> None:
    """After 'ready': each stdin line 'go [N]' runs N steps (default ``steps``) as fast as the
    lockstep allows and prints their send/reply times (time.monotonic, comparable across processes)
    as JSON; 'quit' or the end of stdin stops. (One 'go' is a whole run; several interleave runs
    of different systems in bursts, so the load of the moment hits each alike.)"""
    print("ready", flush=True)
    for line in sys.stdin:
        parts = line.split()
        if not parts or parts[0] != "go":
            break
        n = int(parts[1]) if len(parts) > 1 else steps
        t0 = np.empty(n)
        t1 = np.empty(n)
        for i in range(n):
            t0[i] = time.monotonic()
            step()
            t1[i] = time.monotonic()
        print(json.dumps({"t0": t0.tolist(), "t1": t1.tolist()}), flush=True)


def _role_controller(rpc: str, robot: str, steps: str, duration: str) -> None:
    """A controller (the client library's ``Connection``, with its heartbeat as every controller
    has): attach, then step in bursts (:func:`_bursts`)."""
    from sensorium.client.connection import Connection

    conn = Connection(rpc, timeout=60)
    reply = conn.call("attach", {"robot": robot})
    conn.start_heartbeat(reply["session"], reply["heartbeat_ms"])   # silent while other bursts run
    service = f"/{robot}/robot/step"
    args = {"duration": int(duration)}
    _bursts(lambda: conn.call(service, args), int(steps))
    conn.close()


def _role_bare_controller(rpc: str, robot: str, steps: str, duration: str) -> None:
    """``controller`` with a bare DEALER instead of the client library (no heartbeat, no retries):
    what the library costs when 8 controllers share 2 cores."""
    ctx, s, _session, step = _bare_step_session(rpc, robot, duration)
    _bursts(step, int(steps))
    s.close(0)
    ctx.term()


def _role_raw_controller(endpoint: str, steps: str) -> None:
    """The raw floor of ``controller``: a REQ socket doing step-sized ping-pongs with a do-nothing REP
    server, in the same bursts."""
    import zmq

    ctx = zmq.Context()
    s = ctx.socket(zmq.REQ)
    s.connect(endpoint)
    msg = STEP_BYTES
    for _ in range(50):
        s.send(msg)
        s.recv()

    def step():
        s.send(msg)
        s.recv()

    _bursts(step, int(steps))
    s.close(0)
    ctx.term()


def main(argv: list[str]) -> None:
    roles = {"rep-echo": _role_rep_echo, "rep-work": _role_rep_work, "req": _role_req, "router-echo": _role_router_echo,
             "router-raw": _role_router_raw, "dealer-raw": _role_dealer_raw,
             "conn-client": _role_conn_client, "dealer-client": _role_dealer_client, "stepper": _role_stepper,
             "bare-stepper": _role_bare_stepper, "bare-controller": _role_bare_controller,
             "pub": _role_pub, "controller": _role_controller, "raw-controller": _role_raw_controller}
    roles[argv[0]](*argv[1:])


if __name__ == "__main__":
    main(sys.argv[1:])
