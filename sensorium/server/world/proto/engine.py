"""The sandboxed JavaScript engine templates run in: QuickJS (the ``quickjs`` package) in a worker
process (:mod:`.engine_worker`), with a memory limit, a CPU-time limit, a stack limit and no file,
network, ``std`` or ``os`` access (QuickJS's bare context has none of them).

Why a process: QuickJS 2021-03-27 (what the package bundles) can crash on some out-of-memory
paths, and a template is untrusted input. In the worker a crash ends only the worker: the caller
gets one line saying so, and the next template starts a new worker. The parent also stops a
worker that does not answer within a wall-clock bound. One worker, started on a world's first
template (~50 ms) and ended when that world's expansion is done.
"""

from __future__ import annotations

import atexit
import json
import os
import select
import struct
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

_WORKER = Path(__file__).with_name("engine_worker.py")


@dataclass
class Result:
    ok: bool
    out: str = ""
    messages: str = "[]"
    error: str = ""
    kind: str = ""             # the exception's class name, or "crash" / "timeout"
    cpu: float = 0.0


class Engine:
    def __init__(self) -> None:
        self.proc: subprocess.Popen[bytes] | None = None
        self.lock = threading.Lock()

    def _start(self) -> subprocess.Popen[bytes]:
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
        return subprocess.Popen([sys.executable, "-I", str(_WORKER)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, env=env, close_fds=True)

    def run(self, code: str, *, memory: int, seconds: float, stack: int = 1 << 20) -> Result:
        with self.lock:
            if self.proc is None or self.proc.poll() is not None:
                self.proc = self._start()
            proc = self.proc
            assert proc.stdin is not None and proc.stdout is not None
            data = json.dumps({"code": code, "memory": memory, "seconds": seconds, "stack": stack}).encode("utf-8")
            t0 = time.monotonic()
            try:
                proc.stdin.write(struct.pack(">I", len(data)) + data)
                proc.stdin.flush()
                head = self._read(proc, 4, t0 + seconds * 4 + 5.0)
                body = self._read(proc, struct.unpack(">I", head)[0], t0 + seconds * 4 + 10.0)
            except _Timeout:
                self.stop()
                return Result(False, kind="timeout", cpu=seconds)
            except (OSError, EOFError, struct.error):
                self.stop()
                return Result(False, kind="crash", cpu=time.monotonic() - t0)
            reply = json.loads(body)
            return Result(bool(reply["ok"]), reply.get("out", ""), reply.get("messages", "[]"), reply.get("error", ""),
                          reply.get("kind", ""), float(reply.get("cpu", 0.0)))

    @staticmethod
    def _read(proc: subprocess.Popen[bytes], n: int, deadline: float) -> bytes:
        assert proc.stdout is not None
        fd = proc.stdout.fileno()
        chunks: list[bytes] = []
        left = n
        while left:
            wait = deadline - time.monotonic()
            if wait <= 0:
                raise _Timeout
            ready, _, _ = select.select([fd], [], [], wait)
            if not ready:
                raise _Timeout
            chunk = os.read(fd, min(left, 1 << 20))
            if not chunk:
                raise EOFError
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)

    def stop(self) -> None:
        proc, self.proc = self.proc, None
        if proc is None:
            return
        try:
            proc.kill()
        except OSError:
            pass
        proc.wait()
        for stream in (proc.stdin, proc.stdout):
            if stream is not None:
                stream.close()


class _Timeout(Exception):
    pass


_ENGINE = Engine()
atexit.register(_ENGINE.stop)


def run(code: str, *, memory: int, seconds: float, stack: int = 1 << 20) -> Result:
    """Run one template program in the shared worker."""
    return _ENGINE.run(code, memory=memory, seconds=seconds, stack=stack)


def release() -> None:
    """End the worker (the next run starts another): called when a world's expansion is done."""
    with _ENGINE.lock:
        _ENGINE.stop()
