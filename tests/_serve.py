"""Sensorium commands as subprocesses of a test: the one place that starts, watches and stops them.

* ``Proc(argv)``: any process; a thread collects its stdout lines (``line``, ``wait_line``,
  ``stdout``), another its stderr (``stderr``, for failure messages), so neither pipe ever fills
  and blocks it. ``stop`` sends SIGINT (or the signal given), then SIGTERM, then SIGKILL, each after
  a generous limit, and waits for the process and both pipes to close.
* ``Served(argv, ready)``: a process that prints a ready line (``sensorium serve``: ``sensorium:
  serving world 'NAME' rpc=… pub=… [foxglove=…]``; ``sensorium replay``: ``sensorium: replaying
  PATH pub=… rpc=…``); ``wait_ready`` polls its stdout for that line (60 s by default; an early exit
  fails at once, with the process's stderr) and parses the ``key=value`` fields: ``rpc``, ``pub``,
  ``fields["foxglove"]``; ``conn`` (a client ``Connection``, made on first use), ``url(robot)``,
  ``wait_attached(robots)``. A context manager: stops the process on exit.
* ``serve(WORLD, *extra)``: ``sensorium serve`` on 127.0.0.1 free ports (``--rpc``/``--pub``
  ``tcp://127.0.0.1:0``), ready. ``serve(..., wait=False)`` starts it only (to start several side
  by side, then ``wait_ready`` each).
* ``run_example(WORLD, EXAMPLE, ROBOT, STEPS)``: a bundled example controller run to its end against
  ``sensorium serve WORLD``; the robot's final pose and the finished controller process.

The child imports this tree (the repository is put first on its PYTHONPATH) and runs unbuffered.
``env`` adds variables to the test's environment; a value of ``None`` removes one. Whatever a
failed test left running is killed when the test run ends.
"""

from __future__ import annotations

import atexit
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

REPO = Path(__file__).resolve().parents[1]
READY_S = 60.0      # a server's start: imports, world loading and ray scenes on a busy 2-core machine
STOP_S = 60.0       # each stage of a stop: the signal asked for, then SIGTERM, then SIGKILL
ANY_PORT = "tcp://127.0.0.1:0"


def sensorium(*args: str) -> list[str]:
    """The argv of ``sensorium ARGS…`` run by this interpreter."""
    return [sys.executable, "-m", "sensorium", *args]


def child_env(env: Mapping[str, str | None] | None = None) -> dict[str, str]:
    """The test's environment, plus ``env`` (``None`` removes a variable), importing this tree."""
    full = {**os.environ, "PYTHONUNBUFFERED": "1"}
    for key, value in (env or {}).items():
        if value is None:
            full.pop(key, None)
        else:
            full[key] = value
    full["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), full.get("PYTHONPATH", "")) if p)
    return full


_STARTED: set[subprocess.Popen[str]] = set()


@atexit.register
def _kill_leftovers() -> None:
    """The safety net: a process a failed test did not stop does not outlive the test run."""
    for p in list(_STARTED):
        if p.poll() is None:
            p.kill()
            p.wait()


class Proc:
    """A subprocess whose stdout lines and stderr are collected by two threads."""

    def __init__(self, argv: list[str], *, env: Mapping[str, str | None] | None = None,
                 cwd: Path | str | None = REPO, **popen: Any):
        self.args = argv
        self.p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  env=child_env(env), cwd=None if cwd is None else str(cwd), **popen)
        _STARTED.add(self.p)
        self.lines: queue.Queue[str | None] = queue.Queue()     # None: stdout closed
        self.out: list[str] = []        # stdout lines, without their newlines
        self.err: list[str] = []        # stderr lines, without their newlines
        self._text: tuple[list[str], list[str]] = ([], [])     # stdout, stderr exactly as written
        self._pumps = [threading.Thread(target=self._pump, args=(self.p.stdout, self.out, self._text[0], self.lines),
                                        daemon=True),
                       threading.Thread(target=self._pump, args=(self.p.stderr, self.err, self._text[1], None),
                                        daemon=True)]
        for t in self._pumps:
            t.start()

    @staticmethod
    def _pump(stream: IO[str], into: list[str], text: list[str], lines: queue.Queue[str | None] | None) -> None:
        try:
            for raw in stream:
                text.append(raw)
                line = raw.rstrip("\n")
                into.append(line)
                if lines is not None:
                    lines.put(line)
        except (OSError, ValueError):       # the pipe closed under us (stop() after a kill)
            pass
        finally:
            if lines is not None:
                lines.put(None)

    @property
    def pid(self) -> int:
        return self.p.pid

    @property
    def returncode(self) -> int | None:
        return self.p.poll()

    def _what(self) -> str:
        args = ["sensorium", *self.args[3:]] if self.args[1:3] == ["-m", "sensorium"] else self.args
        return " ".join(Path(a).name if os.path.isabs(a) else a for a in args[:5])

    def _failure(self, why: str) -> AssertionError:
        return AssertionError(f"{self._what()}: {why}; exit code {self.p.poll()}; stderr:\n{self.stderr()}")

    def line(self, timeout: float = READY_S) -> str:
        """The next line of stdout (without its newline), waiting up to ``timeout`` s."""
        try:
            got = self.lines.get(timeout=max(0.0, timeout))
        except queue.Empty:
            raise self._failure(f"no further line on stdout in {timeout:.1f} s") from None
        if got is None:
            self.lines.put(None)            # stays closed for the next reader
            try:
                self.p.wait(STOP_S)
            except subprocess.TimeoutExpired:
                pass
            raise self._failure("stdout closed")
        return got

    def wait_line(self, prefix: str, timeout: float = READY_S) -> str:
        """The next stdout line that starts with ``prefix`` (earlier lines are skipped, kept in ``out``)."""
        deadline = time.monotonic() + timeout
        while True:
            try:
                line = self.line(deadline - time.monotonic())
            except AssertionError as exc:
                raise AssertionError(f"waiting {timeout:g} s for a line starting {prefix!r}: {exc}") from None
            if line.startswith(prefix):
                return line

    def wait(self, timeout: float = STOP_S) -> int:
        """The exit code, once the process has exited by itself within ``timeout`` s."""
        try:
            code = self.p.wait(timeout)
        except subprocess.TimeoutExpired:
            raise self._failure(f"still running after {timeout:g} s") from None
        _STARTED.discard(self.p)
        self._join()
        return code

    def _join(self) -> None:
        for t in self._pumps:
            t.join(STOP_S)

    def stderr(self) -> str:
        """What the process wrote to stderr so far (all of it once it has exited)."""
        if self.p.poll() is not None:
            self._pumps[1].join(STOP_S)
        return "".join(self._text[1])

    def stdout(self) -> str:
        """What the process wrote to stdout so far (all of it once it has exited)."""
        if self.p.poll() is not None:
            self._pumps[0].join(STOP_S)
        return "".join(self._text[0])

    def stop(self, sig: int = signal.SIGINT, timeout: float = STOP_S) -> int:
        """Stop the process: ``sig``, then SIGTERM, then SIGKILL, each given ``timeout`` s; its exit code."""
        for s in dict.fromkeys((sig, signal.SIGTERM, signal.SIGKILL)):
            if self.p.poll() is not None:
                break
            try:
                self.p.send_signal(s)
            except ProcessLookupError:
                pass
            try:
                self.p.wait(timeout)
            except subprocess.TimeoutExpired:
                continue
        self.p.wait()
        _STARTED.discard(self.p)
        self._join()
        for f, pump in zip((self.p.stdout, self.p.stderr), self._pumps):
            if f is not None and not pump.is_alive():   # (a grandchild may hold a pipe open: leave it be)
                f.close()
        return self.p.returncode

    def kill(self) -> None:
        """SIGKILL (when still running) and reap."""
        Proc.stop(self, signal.SIGKILL)

    def __enter__(self) -> Proc:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


class Served(Proc):
    """A process announcing its endpoints on a ready line (``sensorium serve``, ``sensorium replay``)."""

    def __init__(self, argv: list[str], ready: str, *, stop_signal: int = signal.SIGINT, **kw: Any):
        super().__init__(argv, **kw)
        self.ready_prefix = ready
        self.ready_line: str | None = None
        self.fields: dict[str, str] = {}
        self.stop_signal = stop_signal
        self._conn: Any = None

    def wait_ready(self, timeout: float = READY_S) -> Served:
        """Wait for the ready line (once); its ``key=value`` fields become ``fields``/``rpc``/``pub``."""
        if self.ready_line is None:
            try:
                self.ready_line = self.wait_line(self.ready_prefix, timeout)
            except AssertionError:
                Proc.stop(self, signal.SIGKILL)
                raise
            self.fields = dict(f.split("=", 1) for f in self.ready_line.split() if "=" in f)
        return self

    @property
    def rpc(self) -> str:
        return self.fields["rpc"]

    @property
    def pub(self) -> str:
        return self.fields["pub"]

    def url(self, robot: str) -> str:
        """The controller URL of ``robot`` on this server."""
        return f"{self.rpc}/{robot}"

    @property
    def conn(self) -> Any:
        """A ``sensorium.client.connection.Connection`` to ``rpc`` (made on first use, closed by ``stop``)."""
        if self._conn is None:
            from sensorium.client.connection import Connection

            self._conn = Connection(self.wait_ready().rpc, timeout=30.0)
        return self._conn

    def attached(self) -> set[str]:
        """The robots a controller is attached to now."""
        return {r["name"] for r in self.conn.call("get_info")["robots"] if r["attached"]}

    def wait_attached(self, robots: set[str], timeout: float = READY_S) -> None:
        """Poll until every robot of ``robots`` has a controller attached."""
        deadline = time.monotonic() + timeout
        while not robots <= (now := self.attached()):
            assert time.monotonic() < deadline, f"attached {now}, waiting for {robots}"
            time.sleep(0.02)

    def stop(self, sig: int | None = None, timeout: float = STOP_S) -> int:
        """Close ``conn``, then stop as ``Proc.stop`` does, with ``sig`` (default ``stop_signal``) first."""
        if self._conn is not None:
            self._conn.close()
            self._conn = None
        return super().stop(self.stop_signal if sig is None else sig, timeout)

    def __enter__(self) -> Served:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def serve(world: Path | str | None = None, *extra: str, rpc: str = ANY_PORT, pub: str = ANY_PORT,
          wait: bool = True, stop_signal: int = signal.SIGINT, **kw: Any) -> Served:
    """``sensorium serve [WORLD] --rpc RPC --pub PUB EXTRA…``, ready unless ``wait=False``.

    ``stop_signal`` is what leaving the ``with`` block sends first (SIGTERM, SIGKILL follow).
    """
    argv = sensorium("serve", *([] if world is None else [str(world)]), "--rpc", rpc, "--pub", pub, *extra)
    served = Served(argv, "sensorium: serving world", stop_signal=stop_signal, **kw)
    return served.wait_ready() if wait else served


def run_controller(world: Path, argv, env: dict[str, str] | None = None, robot: str = "bot",
                   cwd: Path | str = REPO, timeout: float = 120.0,
                   server_log: list[str] | None = None) -> tuple[list[str], str]:
    """``argv(url)`` run (in ``cwd``) as ``robot``'s controller against a fresh ``sensorium serve WORLD
    --mode fast`` until it exits by itself (code 0 asserted): (its stdout lines, its stderr). ``server_log``
    (when given) receives the server's stderr once it has stopped (what Webots prints in its console)."""
    with serve(world, "--mode", "fast", env=env) as server:
        url = server.url(robot)
        proc = Proc(argv(url), env={**(env or {}), "SENSORIUM_CONTROLLER_URL": url}, cwd=cwd)
        try:
            code = proc.wait(timeout)
        finally:
            proc.stop()
        assert code == 0, proc.stderr()
    if server_log is not None:
        server_log.append(server.stderr())
    return proc.stdout().splitlines(), proc.stderr()


def run_example(world: str, example: str, robot: str, steps: int) -> tuple[dict, Proc]:
    """``sensorium controller example:EXAMPLE --url … STEPS`` against ``sensorium serve WORLD``: the
    world waits (pause) until the controller has attached, then runs fast until the controller exits
    by itself (code 0 asserted). Returns ``ROBOT``'s pose then and the finished controller process."""
    with serve(world, "--mode", "pause", "--heartbeat-ms", "500") as server:
        proc = Proc(sensorium("controller", f"example:{example}", "--url", server.url(robot), str(steps)))
        try:
            server.wait_attached({robot})
            server.conn.call("set_mode", {"mode": "fast"})
            assert proc.wait(300) == 0, proc.stderr()
        finally:
            proc.stop()
        return server.conn.call(f"/{robot}/robot/get_pose"), proc


def alive(pid: int) -> bool:
    """Whether process ``pid`` still exists (a zombie not yet reaped counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def wait_until(pred, timeout: float = 30.0, what: str = "condition", every: float = 0.01):
    """Poll ``pred`` until it returns something truthy (returned) or ``timeout`` seconds pass."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        v = pred()
        if v:
            return v
        time.sleep(every)
    raise AssertionError(f"timed out waiting for {what}")
