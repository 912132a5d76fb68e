"""The transport bench's 'server work' role: a raw REP that answers each message only after it kept
its thread busy for the stated time (what the row measures depends on that)."""

from __future__ import annotations

import threading
import time

import zmq

from sensorium.benchmarks.transport_roles import _role_rep_work


def test_rep_work_echoes_each_message_after_its_work(tmp_path, capsys) -> None:
    endpoint = f"ipc://{tmp_path}/work"
    work_us, n = 3000, 20
    server = threading.Thread(target=_role_rep_work, args=(endpoint, str(work_us)), daemon=True)
    server.start()
    deadline = time.monotonic() + 30
    while f"ready {endpoint}" not in capsys.readouterr().out:     # bound (and said so) before we connect
        assert time.monotonic() < deadline, "rep-work did not start"
        time.sleep(0.01)
    ctx = zmq.Context()
    req = ctx.socket(zmq.REQ)
    req.setsockopt(zmq.RCVTIMEO, 30_000)
    req.connect(endpoint)
    try:
        t0 = time.perf_counter()
        for i in range(n):
            msg = b"step %d" % i
            req.send(msg)
            assert req.recv() == msg                             # an echo, in order
        elapsed = time.perf_counter() - t0
        assert elapsed >= n * work_us * 1e-6                     # each answer waited for its work
        req.send(b"quit")
        assert req.recv() == b"bye"
        server.join(10)
        assert not server.is_alive()
    finally:
        req.close(0)
        ctx.term()


def test_router_raw_echoes_each_clients_bytes_to_that_client(tmp_path, capsys) -> None:
    """The 'socket pattern' floor: a ROUTER that sends every message back unchanged, to its sender."""
    from sensorium.benchmarks.transport_roles import _role_router_raw

    endpoint = f"ipc://{tmp_path}/router-raw"
    server = threading.Thread(target=_role_router_raw, args=(endpoint,), daemon=True)
    server.start()
    deadline = time.monotonic() + 30
    while f"ready {endpoint}" not in capsys.readouterr().out:
        assert time.monotonic() < deadline, "router-raw did not start"
        time.sleep(0.01)
    ctx = zmq.Context()
    dealers = [ctx.socket(zmq.DEALER) for _ in range(2)]
    try:
        for d in dealers:
            d.setsockopt(zmq.RCVTIMEO, 30_000)
            d.connect(endpoint)
        for i in range(5):
            for k, d in enumerate(dealers):
                d.send(b"client %d message %d" % (k, i))
            for k, d in enumerate(dealers):
                assert d.recv() == b"client %d message %d" % (k, i)     # its own bytes, unchanged
        dealers[0].send(b"quit")
        assert dealers[0].recv() == b"quit"
        server.join(10)
        assert not server.is_alive()
    finally:
        for d in dealers:
            d.close(0)
        ctx.term()
