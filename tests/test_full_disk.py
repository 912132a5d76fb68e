"""A full disk while ``serve --record`` runs (issue 16): the recording stops with one clear error,
live topics keep being published, SIGTERM exits cleanly, the file is recoverable.

Reproduced for real with ``RLIMIT_FSIZE`` on the server process (writes past the limit fail with
EFBIG, exactly like ENOSPC for the recorder; SIGXFSZ ignored so the write returns the error)."""

from __future__ import annotations

import resource
import signal
import sys
import time

import zmq
from _serve import serve

from sensorium.client.connection import Connection, SubSocket
from sensorium.server.recording.reader import Recording
from sensorium.server.recording.recover import recover

PY = sys.executable
LIMIT = 256 * 1024


def _limit_file_size() -> None:
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


def _wait(cond, within_s: float, what: str) -> None:
    deadline = time.monotonic() + within_s
    while not cond():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def test_full_disk_stops_the_recording_not_the_server(tmp_path):
    out = tmp_path / "run.mcap"
    server = serve(None, "--record", str(out), preexec_fn=_limit_file_size)
    errors = server.err                                            # stderr lines, collected while it runs
    ctx = zmq.Context()
    try:
        sub = SubSocket(server.pub, context=ctx)
        sub.subscribe(b"/clock")
        with Connection(server.rpc, timeout=30, context=ctx) as c:
            info = c.call("get_info")
            robot, dt = info["robots"][0]["name"], info["basic_time_step"]
            c.call("attach", {"robot": robot})
            stopped = lambda: any("recording to" in e and "stopped" in e for e in errors)  # noqa: E731
            deadline = time.monotonic() + 120
            while not stopped():                                   # fill the "disk"
                assert time.monotonic() < deadline, server.stderr()
                for _ in range(20):
                    c.call(f"/{robot}/robot/step", {"duration": dt})
            # after the failure: the world steps and live topics are still published
            while sub.poll(0):
                sub.recv_frames()
            t0 = c.call(f"/{robot}/robot/step", {"duration": dt})["time_ms"]
            got: list[list[bytes]] = []
            deadline = time.monotonic() + 30
            while len(got) < 5:
                assert time.monotonic() < deadline, "no live topics after the recording stopped"
                c.call(f"/{robot}/robot/step", {"duration": dt})
                if sub.poll(50):
                    got.append(sub.recv_frames())
            assert all(f[0] == b"/clock\0" for f in got)
            assert c.call("get_info")["time_ms"] > t0
        sub.close()
        server.p.send_signal(signal.SIGTERM)
        assert server.wait() == 0
    finally:
        ctx.destroy(linger=0)
        server.stop()
    text = server.stderr()
    assert "Traceback" not in text and "internal error" not in text, text
    failures = [e for e in errors if "recording to" in e and "stopped" in e]
    assert len(failures) == 1, text                                # one clear error, not one per message
    assert "live topics are still published" in failures[0] and "sensorium recover" in failures[0]
    assert "stopped early" in text
    assert out.stat().st_size <= LIMIT
    with Recording(out) as rec:
        assert rec.truncated
        n = sum(1 for _ in rec.messages())
    assert n > 0
    fixed = tmp_path / "fixed.mcap"
    assert recover(out, fixed).messages >= n
