"""The transport bench's 'server work' role: a raw REP that answers each message only after it kept
its thread busy for the stated time (what the row measures depends on that)."""

from __future__ import annotations

import shutil
import subprocess
import threading
import time
from pathlib import Path

import pytest
import zmq

from sensorium.benchmarks.transport_roles import _role_rep_work

C_DIR = Path(__file__).resolve().parents[1] / "sensorium" / "benchmarks" / "c"


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


@pytest.mark.slow
def test_c_router_echo_sends_every_frame_back_to_its_sender(tmp_path) -> None:
    """The bench's C pattern row: rep_echo.c with `router` echoes each DEALER's message, every frame in
    order, to that DEALER only (and without it stays a REP echo)."""
    cc = shutil.which("cc")
    if cc is None or not Path("/usr/include/zmq.h").exists():
        pytest.skip("no C compiler or libzmq headers")
    exe = tmp_path / "rep_echo"
    subprocess.run([cc, "-std=c11", "-O2", "-Wall", "-Werror", str(C_DIR / "rep_echo.c"), "-o", str(exe), "-lzmq"],
                   check=True, timeout=120)
    ctx = zmq.Context()
    procs, socks = [], []
    try:
        for mode, kind in (("router", zmq.DEALER), ("rep", zmq.REQ)):
            p = subprocess.Popen([str(exe), "tcp://127.0.0.1:*", mode], stdout=subprocess.PIPE, text=True)
            procs.append(p)
            endpoint = p.stdout.readline().split()[1]             # "ready ENDPOINT" once bound
            pair = [ctx.socket(kind) for _ in range(2 if mode == "router" else 1)]
            socks += pair
            for s in pair:
                s.setsockopt(zmq.RCVTIMEO, 30_000)
                s.connect(endpoint)
            for i in range(3):
                if mode == "router":
                    for k, s in enumerate(pair):
                        s.send_multipart([b"client %d" % k, b"frame %d" % i])
                    for k, s in enumerate(pair):
                        assert s.recv_multipart() == [b"client %d" % k, b"frame %d" % i]
                else:
                    pair[0].send(b"step %d" % i)
                    assert pair[0].recv() == b"step %d" % i
    finally:
        for s in socks:
            s.close(0)
        ctx.term()
        for p in procs:
            p.kill()
            p.wait(10)
