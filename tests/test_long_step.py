"""A long world step never loses a controller; a server that is gone still ends it.

While the server computes one step it reads no request, so a controller's heartbeat pings go
unanswered. Both clients (Python, and C built with sanitizers) used to take five unanswered
heartbeats for a server gone: the step returned -1 and the world ran on without that robot (Webots'
parallel_robot_step how-to, a 1920x1080 anti-aliased camera: 13-26 s for its first frame). Now a
client also watches its heartbeat connection at ZeroMQ's level (ZMTP heartbeats, which the
server's ZeroMQ I/O thread answers while Python computes): alive means busy, keep waiting. A server
SIGKILLed (the connection closes) or SIGSTOPped (its I/O threads stop too, the ZMTP heartbeats
time out) mid-step is still gone within about five heartbeats.

The server is tests/_slow_server.py: its world step blocks while a file exists (the test removes
it once the controller has waited through twice its five heartbeats).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from _serve import Served, wait_until
from test_c_client import ENV, finish, sanitized_controller

from sensorium.client.connection import PING_BACKLOG, Connection, ConnectionLost
from sensorium.server.daemon.transport import generate_curve_keys

TESTS = Path(__file__).parent
SLOW_SERVER = TESTS / "_slow_server.py"
WORLD = TESTS / "worlds" / "server.yaml"          # bot2: synchronous, no devices, 16 ms steps
HB_MS = 200
LOST_S = 2.0                                      # the clients' rule: 5 heartbeats, at least 2 s
GONE_WITHIN_S = 15.0                              # generous: a loaded machine; "never" is what fails


@contextmanager
def slow_server(tmp_path: Path, rpc: str = "tcp://127.0.0.1:0", keys: Path | None = None) -> Iterator[tuple[Served, Path]]:
    hold = tmp_path / "hold"
    argv = [sys.executable, str(SLOW_SERVER), str(WORLD), str(HB_MS), rpc, str(hold), *([str(keys)] if keys else [])]
    server = Served(argv, "ready ")
    try:
        server.wait_ready()
        yield server, hold
    finally:
        if server.returncode is None:
            os.kill(server.pid, signal.SIGCONT)        # a frozen one must run to stop
        hold.unlink(missing_ok=True)
        server.stop()


class Step(threading.Thread):
    """One step request waited for in a thread (the test watches meanwhile)."""

    def __init__(self, conn: Connection):
        super().__init__(daemon=True)
        self.conn = conn
        self.result: dict | None = None
        self.error: BaseException | None = None
        self.ended = 0.0
        self.start()

    def run(self) -> None:
        try:
            self.result = self.conn.call("/bot2/robot/step", {"duration": 16}, timeout=None)
        except BaseException as exc:  # noqa: BLE001 - the test reads it
            self.error = exc
        self.ended = time.monotonic()


def _attached(url: str) -> Connection:
    conn = Connection(url, timeout=60)
    conn.start_heartbeat(conn.call("attach", {"robot": "bot2"})["session"], HB_MS)
    assert conn.heartbeat is not None and conn.heartbeat.lost_after == LOST_S
    assert conn.call("/bot2/robot/step", {"duration": 16}, timeout=60)["time_ms"] == 16
    return conn


def _long_step(conn: Connection, hold: Path, silent_s: float = 2 * LOST_S) -> Step:
    """A step the server computes until the controller has heard nothing for ``silent_s`` (twice its
    five heartbeats); the controller still waiting for it at the end."""
    hb = conn.heartbeat
    assert hb is not None
    hold.touch()
    step = Step(conn)
    wait_until(Path(f"{hold}.holding").exists, what="the server's long step")
    wait_until(lambda: step.ended or time.monotonic() - hb.last_reply > silent_s, timeout=120,
               what="the controller's wait without an answer")
    assert step.error is None and step.result is None, f"the controller gave up on a busy server: {step.error}"
    return step


def _close_after(conn: Connection, step: Step | None, hold: Path) -> None:
    """Close the connection once no step thread waits on it: a ZeroMQ socket is one thread's, and
    closing it under a thread blocked in it aborts the process (a failed assertion must stay one)."""
    hold.unlink(missing_ok=True)              # the server ends the step it holds
    if step is not None:
        step.join(120)
    if step is None or not step.is_alive():
        conn.close()


@pytest.mark.parametrize("kind", ["tcp", "ipc", "curve"])
def test_a_python_controller_waits_out_a_step_longer_than_five_heartbeats(tmp_path, monkeypatch, kind) -> None:
    for var in ("SENSORIUM_CURVE_SERVERKEY", "SENSORIUM_CURVE_PUBLICKEY", "SENSORIUM_CURVE_SECRETKEY"):
        monkeypatch.delenv(var, raising=False)
    keys = None
    if kind == "curve":
        keys = tmp_path / "keys"
        public = generate_curve_keys(keys).decode()
    rpc = f"ipc://{tmp_path}/rpc" if kind == "ipc" else "tcp://127.0.0.1:0"
    with slow_server(tmp_path, rpc, keys) as (server, hold):
        conn = _attached(server.rpc + (f"?serverkey={public}" if keys else ""))
        hb = conn.heartbeat
        assert hb is not None
        step = None
        try:
            pings, replies, retries = hb.pings, hb.replies, conn.retries
            began = time.monotonic()
            step = _long_step(conn, hold, 6.0)                  # 30 heartbeats
            # what waits in the server's queue meanwhile stays short: pings stop at PING_BACKLOG
            # unanswered (a ping the server answered before it took the step counts none), the step's
            # copies (against a lost reply) come 1, 2, 4, 8 … s apart, so n of them take 2^n - 1 s at
            # least (a loaded machine may watch for longer than 6 s)
            waited = time.monotonic() - began
            assert hb.pings - pings - (hb.replies - replies) <= PING_BACKLOG, (hb.pings - pings, hb.replies - replies)
            assert 2 ** (conn.retries - retries) - 1 <= waited, (conn.retries - retries, waited)
            hold.unlink()
            step.join(60)
            assert step.error is None and step.result is not None and step.result["time_ms"] == 32
            assert [conn.call("/bot2/robot/step", {"duration": 16})["time_ms"] for _ in range(2)] == [48, 64]
        finally:
            _close_after(conn, step, hold)


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGSTOP], ids=["SIGKILL", "SIGSTOP"])
def test_a_python_controller_still_finds_a_killed_or_frozen_server_gone_mid_step(tmp_path, sig) -> None:
    with slow_server(tmp_path) as (server, hold):
        conn = _attached(server.rpc)
        step = None
        try:
            step = _long_step(conn, hold)
            sent = time.monotonic()
            os.kill(server.pid, sig)
            step.join(60)
            assert isinstance(step.error, ConnectionLost), step.error
            assert "server gone" in str(step.error), step.error
            assert step.ended - sent < GONE_WITHIN_S
        finally:
            _close_after(conn, step, hold)


@pytest.fixture(scope="module")
def script(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, TESTS / "c" / "script.c")


def _c_controller(script: str, server: Served, steps: int, serverkey: str | None = None) -> subprocess.Popen:
    env = {**ENV, "SENSORIUM_CONTROLLER_URL": server.url("bot2")}
    if serverkey is not None:
        env["SENSORIUM_CURVE_SERVERKEY"] = serverkey
    return subprocess.Popen([script, "step", "16", str(steps)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env)


def _waits_through_a_long_step(p: subprocess.Popen, hold: Path) -> None:
    """The C controller's first step is computed for twice its five heartbeats; it is still waiting."""
    wait_until(Path(f"{hold}.holding").exists, what="the server's long step")
    began = time.monotonic()
    wait_until(lambda: p.poll() is not None or time.monotonic() - began > 2 * LOST_S, timeout=120,
               what="twice five heartbeats")
    assert p.poll() is None, f"the C controller gave up on a busy server: {p.communicate()[1]}"


@pytest.mark.parametrize("kind", ["tcp", "ipc", "curve"])
def test_a_c_controller_waits_out_a_step_longer_than_five_heartbeats(tmp_path, script, kind) -> None:
    keys = tmp_path / "keys" if kind == "curve" else None
    public = generate_curve_keys(keys).decode() if keys else None
    rpc = f"ipc://{tmp_path}/rpc" if kind == "ipc" else "tcp://127.0.0.1:0"
    with slow_server(tmp_path, rpc, keys) as (server, hold):
        hold.touch()
        p = _c_controller(script, server, 3, public)
        _waits_through_a_long_step(p, hold)
        hold.unlink()
        code, lines, err = finish(p, 60)
    assert code == 0, err
    assert [line.split()[:2] for line in lines if not line.startswith("#")] == [["16", "0"], ["32", "0"], ["48", "0"]]


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGSTOP], ids=["SIGKILL", "SIGSTOP"])
def test_a_c_controller_still_finds_a_killed_or_frozen_server_gone_mid_step(tmp_path, script, sig) -> None:
    with slow_server(tmp_path) as (server, hold):
        hold.touch()
        p = _c_controller(script, server, 1000)
        _waits_through_a_long_step(p, hold)
        sent = time.monotonic()
        os.kill(server.pid, sig)
        code, lines, err = finish(p, 60)
        ended = time.monotonic()
    assert code == 0, err
    assert [line.split()[1] for line in lines if not line.startswith("#")] == ["-1"], lines
    assert "CONNECTION_LOST" in err and "server gone" in err, err
    assert ended - sent < GONE_WITHIN_S
