"""Running the independent Node decoders of tests/js/ from pytest.

They need Node and ``npm ci`` in tests/js (CI does both, see .ci/run). Without them the tests are
skipped — unless ``SENSORIUM_REQUIRE_NODE=1`` (set by .ci/run), when they fail instead.
"""

from __future__ import annotations

import json
import os
import queue
import shutil
import subprocess
import threading
import time
from pathlib import Path

import pytest

JS = Path(__file__).parent / "js"


def require_node() -> str:
    node = shutil.which("node")
    missing = None
    if node is None:
        missing = "node is not installed"
    elif not (JS / "node_modules" / "@foxglove" / "ws-protocol").is_dir():
        missing = f"the npm packages are not installed: run `npm ci` in {JS}"
    if missing:
        if os.environ.get("SENSORIUM_REQUIRE_NODE") == "1":
            pytest.fail(missing)
        pytest.skip(missing)
    return node  # type: ignore[return-value]


def run_script(script: str, *args: str, timeout: float = 120.0) -> list[dict]:
    """Run ``node tests/js/<script> args…`` to completion; its stdout JSON lines."""
    node = require_node()
    proc = subprocess.run([node, str(JS / script), *args], capture_output=True, text=True, timeout=timeout, cwd=JS)
    if proc.returncode != 0:
        raise AssertionError(f"{script} failed ({proc.returncode}): {proc.stderr[-3000:]}")
    return [json.loads(line) for line in proc.stdout.splitlines() if line.strip()]


class NodeProcess:
    """A long-running node script talking JSON lines (stdin commands, stdout events)."""

    def __init__(self, script: str, *args: str):
        node = require_node()
        self.proc = subprocess.Popen([node, str(JS / script), *args], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, cwd=JS)
        self.events: queue.Queue[dict] = queue.Queue()
        self.seen: list[dict] = []
        self._thread = threading.Thread(target=self._read, daemon=True)
        self._thread.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            if line.strip():
                try:
                    self.events.put(json.loads(line))
                except json.JSONDecodeError:      # a line cut short when the script is stopped mid-write
                    if self.proc.poll() is None and line.endswith("\n"):
                        raise

    def send(self, **cmd) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(json.dumps(cmd) + "\n")
        self.proc.stdin.flush()

    def drain(self) -> list[dict]:
        """Every event received so far (also kept in ``seen``)."""
        out = []
        while True:
            try:
                out.append(self.events.get_nowait())
            except queue.Empty:
                break
        self.seen.extend(out)
        return out

    def wait_for(self, pred, timeout: float = 30.0, what: str = "event") -> dict:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                ev = self.events.get(timeout=0.1)
            except queue.Empty:
                if self.proc.poll() is not None:
                    break
                continue
            self.seen.append(ev)
            if pred(ev):
                return ev
        err = self.proc.stderr.read() if self.proc.poll() is not None and self.proc.stderr else ""
        raise AssertionError(f"node: no {what} within {timeout} s; exit={self.proc.poll()} {err[-2000:]}")

    def find(self, pred, timeout: float = 30.0, what: str = "event") -> dict:
        """Like :meth:`wait_for`, but an event seen already counts too."""
        for ev in self.seen:
            if pred(ev):
                return ev
        return self.wait_for(pred, timeout, what)

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self.send(cmd="close")
                self.proc.wait(10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()
        for f in (self.proc.stdin, self.proc.stdout, self.proc.stderr):
            if f is not None:
                try:
                    f.close()
                except OSError:
                    pass
