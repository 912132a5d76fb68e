"""``record --connect`` across a server restart (issue 16): before, two runs were merged into one
file with duplicate timestamps and "Truncated: no"; now the recorder detects the clock going back
and continues in ``NAME-2.mcap``, each file one run, linked by metadata that ``info`` shows."""

from __future__ import annotations

import subprocess
import sys
import threading
import time

from test_record_live import drive, server_factory  # noqa: F401 - the fixture

from sensorium.server.recording.live import LiveRecorder
from sensorium.server.recording.reader import Recording

PY = sys.executable


def _wait(cond, within_s: float, what: str) -> None:
    deadline = time.monotonic() + within_s
    while not cond():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def test_a_server_restart_starts_a_new_file(server_factory, tmp_path):  # noqa: F811
    first = server_factory(name="r")
    out = tmp_path / "run.mcap"
    (tmp_path / "run-2.mcap").write_bytes(b"someone else's file")      # never overwritten
    logs: list[str] = []
    rec = LiveRecorder(out, connect=first.rpc_url, log=logs.append)
    rec.open()
    t = threading.Thread(target=rec.run, daemon=True)
    t.start()
    try:
        first.wait_subscribed(30)
        drive(first, 20)
        _wait(lambda: rec.gaps.received.get("/clock", 0) >= 20, 30, "the first run's messages")
        first.stop()
        second = server_factory(name="r")                               # same endpoints, a new run
        second.wait_subscribed(30)
        drive(second, 10)
        _wait(lambda: len(rec.files) == 2 and rec.gaps.received.get("/clock", 0) >= 30, 30, "the second run")
    finally:
        rec.stop()
        t.join(30)
        summary = rec.close()
    assert summary["restarts"] == 1 and summary["files"] == [str(out), str(tmp_path / "run-3.mcap")]
    assert (tmp_path / "run-2.mcap").read_bytes() == b"someone else's file"
    assert sum("the server restarted" in line for line in logs) == 1
    clocks = []
    for path in (out, tmp_path / "run-3.mcap"):
        with Recording(path) as r:
            assert not r.truncated
            stamps = [m.stamp_ns for m in r.messages(["/clock"])]
            meta = r.metadata()
        assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)    # one run, one clock
        clocks.append(stamps)
        if path == out:
            assert meta["server_restart"]["next_file"] == "run-3.mcap"
        else:
            assert meta["session"]["previous_file"] == "run.mcap"
    assert len(clocks[0]) == 20 and len(clocks[1]) == 10 and clocks[1][0] < clocks[0][-1]
    info = subprocess.run([PY, "-m", "sensorium", "info", str(out)], capture_output=True, text=True, timeout=60)
    assert "Continues in:" in info.stdout and "run-3.mcap" in info.stdout and "restart" in info.stdout
    info = subprocess.run([PY, "-m", "sensorium", "info", str(tmp_path / "run-3.mcap")], capture_output=True,
                          text=True, timeout=60)
    assert "Continues from:" in info.stdout and "run.mcap" in info.stdout
    assert "record --url" in info.stdout and "--connect" not in info.stdout   # not the deprecated spelling
