"""Replay a recording on the socket layout of a live server (PROTOCOL.md §1, §4, "Replay").

An ``XPUB`` publishes the recorded messages as ``[topic\\0, envelope, body]`` — the body is the
recorded bytes, the envelope ``{type, seq, stamp_ns}`` is rebuilt from the record — so subscriber
code cannot tell a replay from a live server. A ``ROUTER`` answers ``get_info`` like the server
(``mode`` is ``"replay"`` or ``"lockstep"``) plus the replay services below.

Two modes:

* **free-running** (default): messages go out with their recorded spacing divided by ``rate``
  (``rate = 0``: as fast as possible), optionally looping, optionally with a ``/clock`` topic at
  ``clock_hz``. Services ``/replay/pause``, ``/replay/resume``, ``/replay/set_rate {value}``,
  ``/replay/get_state``, ``/replay/quit``.
* **lockstep**: nothing moves until a client calls ``/replay/step {duration}`` (ms); the replay then
  publishes every message with ``log time <= time + duration`` and answers ``{status, time_ms,
  emitted, done}``. Also ``/replay/seek {time_ms}``, ``/replay/get_state``, ``/replay/quit``.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable, Iterator
from typing import IO, Any

import zmq

from sensorium.schemas.services import MAX_PERIOD_MS
from sensorium.schemas.wire import (
    HARD_LIMIT,
    ErrorCode,
    RequestError,
    error_reply,
    ok_reply,
    pack,
    parse_request,
    stamp,
)
from sensorium.server.daemon.transport import MAX_FRAMES, SUB_LIMIT, TOO_MANY_FRAMES, check_endpoints
from sensorium.server.recording.envelope import pack_envelope, topic_matcher, unmatched_topics
from sensorium.server.recording.reader import RecordedMessage, Recording
from sensorium.server.recording.scan import Damage

CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
DEFAULT_PUB = "tcp://127.0.0.1:5561"
DEFAULT_RPC = "tcp://127.0.0.1:5560"
# the latest replay time a step or seek may reach: its nanoseconds fit a ROS stamp's int64 (and
# every reply's msgpack integers); beyond it the replay's state could no longer be sent at all
MAX_TIME_MS = ((1 << 63) - 1) // 1_000_000


def _fmt_s(ns: int | float) -> str:
    return f"{ns / 1e9:.3f}"


class Replayer:
    """One replay session. ``bind()`` then ``run()`` (blocking; ``stop()`` from another thread or a
    signal ends it). Times ``start_s``/``end_s`` are seconds of simulation time (the recording's log
    time), both inclusive."""

    def __init__(self, path: str, *, pub: str = DEFAULT_PUB, rpc: str | None = DEFAULT_RPC,
                 rate: float = 1.0, loop: bool = False, topics: list[str] | None = None,
                 start_s: float | None = None, end_s: float | None = None,
                 clock_hz: float | None = None, lockstep: bool = False, progress: bool | None = None,
                 wait_subscriber: bool = False, delay_s: float = 0.0, sndhwm: int = 1000,
                 nodrop: bool = False, out: IO[str] | None = None, context: zmq.Context | None = None,
                 on_damage: Callable[[Damage], None] | None = None):
        if rate < 0 or not math.isfinite(rate):
            raise ValueError("rate must be >= 0 (0: as fast as possible)")
        check_endpoints(("--pub", pub), ("--rpc", rpc))
        self.path = str(path)
        self.recording = Recording(path, on_damage=on_damage)     # a damaged chunk is skipped and said
        foreign = self.recording.foreign()
        if foreign:                 # a ROS 2 bag: it would replay 0 messages without a word
            self.recording.close()
            raise ValueError(foreign)
        self.pub_url, self.rpc_url = pub, rpc
        self.rate = float(rate)
        self.loop = loop
        self.topics = topics
        self.start_ns = None if start_s is None else int(round(start_s * 1e9))
        self.end_ns = None if end_s is None else int(round(end_s * 1e9))
        if self.start_ns is not None and self.end_ns is not None and self.end_ns < self.start_ns:
            raise ValueError("--end is before --start")
        self.clock_hz = clock_hz
        self.lockstep = lockstep
        self.wait_subscriber = wait_subscriber
        self.delay_s = delay_s
        self.out = out if out is not None else sys.stderr
        self._progress_opt = progress
        self._ctx = context or zmq.Context.instance()
        self._sndhwm = sndhwm
        self._nodrop = nodrop
        self._stop = False
        self._paused = False
        self.emitted = 0
        self.interrupted = False               # run() ended by Ctrl-C / SIGTERM (not by its end or /replay/quit)
        self.loops = 0
        self.subscriptions: set[bytes] = set()
        self.viewer: Any = None                # a recorder-like sink also fed every published message
        self._clock_seq = 0
        self._last_clock_ns: int | None = None
        self.pub: zmq.Socket | None = None
        self.rpc: zmq.Socket | None = None
        self.pub_endpoint = ""
        self.rpc_endpoint = ""
        meta = self.recording.metadata().get("sensorium", {})
        self.meta = meta
        try:
            self.basic_time_step = int(float(meta.get("basic_time_step_ms", meta.get("basic_time_step", 32))))
        except ValueError:
            self.basic_time_step = 32
        match = topic_matcher(topics)
        skip_clock = clock_hz is not None
        self._match = lambda t: match(t) and not (skip_clock and t == CLOCK_TOPIC)
        infos = self.recording.topics()
        problem = unmatched_topics(topics, [t.topic for t in infos], self.path)
        if problem:
            self.recording.close()
            raise ValueError(problem)
        self.topic_types = {t.topic: t.ros_type for t in infos if self._match(t.topic)}
        times = [(t.first_ns, t.last_ns) for t in infos
                 if self._match(t.topic) and t.first_ns is not None and t.last_ns is not None]
        self.first_ns = min((a for a, _ in times), default=0)
        self.last_ns = max((b for _, b in times), default=0)
        if self.start_ns is not None:
            self.first_ns = max(self.first_ns, self.start_ns)
        if self.end_ns is not None:
            self.last_ns = min(self.last_ns, self.end_ns)
        # playback time state
        self.time_ns = self.start_ns if self.start_ns is not None else (0 if lockstep else self.first_ns)
        self._base_ns = self.time_ns
        self._wall0 = time.monotonic()
        self._paused_at_ns: int | None = None
        self._iter: Iterator[RecordedMessage] = iter(())
        self._next: RecordedMessage | None = None
        self.done = False
        self._progress_last = 0.0
        self._progress_shown = False

    # ------------------------------------------------------------------ sockets
    def bind(self) -> tuple[str, str]:
        self.pub = self._ctx.socket(zmq.XPUB)
        self.pub.setsockopt(zmq.LINGER, 2000)
        self.pub.setsockopt(zmq.SNDHWM, self._sndhwm)
        if self._nodrop:
            self.pub.setsockopt(zmq.XPUB_NODROP, 1)
        self.pub.setsockopt(zmq.MAXMSGSIZE, SUB_LIMIT)          # the live server's bounds (transport.py)
        self.pub.bind(self.pub_url)
        self.pub_endpoint = self.pub.getsockopt_string(zmq.LAST_ENDPOINT)
        if self.rpc_url:
            self.rpc = self._ctx.socket(zmq.ROUTER)
            self.rpc.setsockopt(zmq.LINGER, 500)
            self.rpc.setsockopt(zmq.MAXMSGSIZE, HARD_LIMIT)    # a larger message drops its peer, unread
            self.rpc.bind(self.rpc_url)
            self.rpc_endpoint = self.rpc.getsockopt_string(zmq.LAST_ENDPOINT)
        self._poller = zmq.Poller()
        self._poller.register(self.pub, zmq.POLLIN)
        if self.rpc is not None:
            self._poller.register(self.rpc, zmq.POLLIN)
        return self.pub_endpoint, self.rpc_endpoint

    def announce(self) -> str:
        return f"sensorium: replaying {self.path} pub={self.pub_endpoint} rpc={self.rpc_endpoint or '-'}"

    def close(self) -> None:
        for s in (self.pub, self.rpc):
            if s is not None and not s.closed:
                s.close()
        self.recording.close()

    def stop(self) -> None:
        self._stop = True

    # ------------------------------------------------------------------ messages
    def _open(self, start_ns: int | None) -> None:
        self._iter = self.recording.messages(self._match, start_ns, self.end_ns)
        self._next = next(self._iter, None)

    def _send(self, frames: list[bytes]) -> None:
        assert self.pub is not None, "bind() first"
        while True:
            try:
                self.pub.send_multipart(frames, flags=zmq.NOBLOCK if self._nodrop else 0, copy=False)
                return
            except zmq.Again:  # nodrop and a subscriber's queue is full: wait for it
                self._service(0.001)
                if self._stop:
                    return

    def _publish(self, msg: RecordedMessage) -> None:
        env = msg.envelope()
        self._send([msg.topic.encode() + b"\0", env, msg.data])
        if self.viewer is not None:        # the Foxglove bridge (--foxglove): never blocks
            self.viewer(msg.topic, msg.ros_type, env, msg.data, msg.stamp_ns, msg.seq)
        self.emitted += 1

    def _publish_clock(self, t_ns: int) -> None:
        t_ns = max(0, int(t_ns))
        body = pack({"clock": stamp(t_ns)})
        self._send([CLOCK_TOPIC.encode() + b"\0", pack_envelope(CLOCK_TYPE, self._clock_seq, t_ns), body])
        self._clock_seq += 1
        self._last_clock_ns = t_ns

    def _emit_until(self, t_ns: int) -> int:
        """Publish every pending message with log time <= t_ns (a /clock before each new stamp)."""
        n = 0
        while self._next is not None and self._next.stamp_ns <= t_ns and not self._stop:
            msg = self._next
            if self.clock_hz is not None and (self._last_clock_ns is None or msg.stamp_ns > self._last_clock_ns):
                self._publish_clock(msg.stamp_ns)
            self._publish(msg)
            n += 1
            self._next = next(self._iter, None)
        return n

    # ------------------------------------------------------------------ RPC
    def _service(self, timeout_s: float) -> None:
        """Wait up to ``timeout_s`` (at most a second: callers wait in a loop) for requests or
        subscriptions and handle them."""
        timeout_ms = max(0, int(math.ceil(min(timeout_s, 1.0) * 1000)))
        events = dict(self._poller.poll(timeout_ms))
        assert self.pub is not None, "bind() first"
        if self.pub in events:
            while True:
                try:
                    msg = self.pub.recv(zmq.NOBLOCK)
                except zmq.Again:
                    break
                if msg[:1] == b"\x01":
                    self.subscriptions.add(msg[1:])
                elif msg[:1] == b"\x00":
                    self.subscriptions.discard(msg[1:])
        if self.rpc is not None and self.rpc in events:
            while True:
                try:
                    frames = self.rpc.recv_multipart(zmq.NOBLOCK)
                except zmq.Again:
                    break
                if len(frames) < 2:
                    continue
                if len(frames) > MAX_FRAMES:
                    self.rpc.send_multipart([frames[0], TOO_MANY_FRAMES])
                    continue
                reply = self._handle(frames[-1])
                self.rpc.send_multipart(frames[:-1] + [reply])

    def _handle(self, body: bytes) -> bytes:
        rid = None
        try:
            req = parse_request(body)
            rid = req.id
            result = self._dispatch(req.service, req.args)
            return ok_reply(rid, result)
        except RequestError as exc:
            return error_reply(exc.id if exc.id is not None else rid, exc.code, exc.message)
        except Exception as exc:  # a bug: answer and keep serving
            return error_reply(rid, ErrorCode.INTERNAL, f"{type(exc).__name__}: {exc}")

    def state(self) -> dict:
        return {"time_ms": self.time_ns // 1_000_000, "time_ns": self.time_ns, "paused": self._paused,
                "rate": self.rate, "emitted": self.emitted, "done": self.done, "loops": self.loops,
                "mode": "lockstep" if self.lockstep else "replay",
                "subscriptions": sorted(s.decode("utf-8", "replace") for s in self.subscriptions)}

    def service_names(self) -> list[str]:
        """The services of this mode, as ``get_info`` lists them."""
        return ["get_info", "get_services", "ping", "/replay/get_state", "/replay/quit",
                *(["/replay/step", "/replay/seek"] if self.lockstep
                  else ["/replay/pause", "/replay/resume", "/replay/set_rate"])]

    def info(self) -> dict:
        world = self.meta.get("world") or self.meta.get("world_file") or ""
        services = self.service_names()
        topics = [{"name": k, "type": v} for k, v in sorted(self.topic_types.items())]
        if self.clock_hz is not None:
            topics.append({"name": CLOCK_TOPIC, "type": CLOCK_TYPE})
        return {"protocol": 1, "version": self._version(), "world": world,
                "basic_time_step": self.basic_time_step, "time_ms": self.time_ns // 1_000_000,
                "mode": "lockstep" if self.lockstep else "replay", "pub_endpoint": self.pub_endpoint,
                "robots": [], "topics": topics, "services": services,
                "recording": {"path": self.path, "start_ns": self.first_ns, "end_ns": self.last_ns,
                              "truncated": self.recording.truncated, "metadata": self.meta}}

    @staticmethod
    def _version() -> str:
        from sensorium import __version__

        return __version__

    # arguments of each service, as ``get_services`` lists them (``sensorium services`` prints them)
    SERVICE_ARGS = {"/replay/set_rate": {"value": "float"}, "/replay/step": {"duration?": "int"},
                    "/replay/seek": {"time_ms": "int"}}

    def services(self) -> dict:
        return {"services": [{"name": n, "scope": "server", "robot": None, "device": None, "device_type": None,
                              "attached": False, "args": self.SERVICE_ARGS.get(n, {})}
                             for n in self.info()["services"]]}

    def _dispatch(self, service: str, args: dict) -> dict:
        if service != "ping" and service in self.service_names():     # ping may carry a session (§3.3)
            known = {name.rstrip("?") for name in self.SERVICE_ARGS.get(service, {})}
            unknown = sorted(str(k) for k in args if k not in known)
            if unknown:                # as the server does (PROTOCOL.md §3.1): a typo never passes silently
                raise RequestError(ErrorCode.INVALID_ARGUMENT, f"{service}: unknown argument {unknown[0]!r}"
                                   + (f" (it takes {', '.join(sorted(known))})" if known else " (it takes none)"))
        if service == "get_info":
            return self.info()
        if service == "get_services":
            return self.services()
        if service == "ping":
            return {"time_ms": self.time_ns // 1_000_000}
        if service == "/replay/get_state":
            return self.state()
        if service == "/replay/quit":
            self._stop = True
            return {}
        if self.lockstep:
            if service == "/replay/step":
                return self._step(args)
            if service == "/replay/seek":
                return self._seek(args)
        else:
            if service == "/replay/pause":
                self._pause(True)
                return self.state()
            if service == "/replay/resume":
                self._pause(False)
                return self.state()
            if service == "/replay/set_rate":
                value = args.get("value")
                if not isinstance(value, (int, float)) or isinstance(value, bool) or value < 0 or not math.isfinite(value):
                    raise RequestError(ErrorCode.INVALID_ARGUMENT, "value: a rate >= 0 is required")
                self._set_rate(float(value))
                return self.state()
        if service in ("/replay/step", "/replay/seek", "/replay/pause", "/replay/resume", "/replay/set_rate"):
            raise RequestError(ErrorCode.WRONG_STATE,
                               f"{service} is not available in {'lockstep' if self.lockstep else 'free-running'} mode")
        raise RequestError(ErrorCode.UNKNOWN_SERVICE, f"no service {service!r} in a replay")

    # lockstep
    def _step(self, args: dict) -> dict:
        duration = args.get("duration", self.basic_time_step)
        if not isinstance(duration, int) or isinstance(duration, bool) or not 0 < duration <= MAX_PERIOD_MS:
            raise RequestError(ErrorCode.INVALID_ARGUMENT,
                               f"duration: a positive integer number of ms up to {MAX_PERIOD_MS} is required")
        if self.time_ns + duration * 1_000_000 > MAX_TIME_MS * 1_000_000:
            raise RequestError(ErrorCode.INVALID_ARGUMENT, f"duration: the replay time would pass {MAX_TIME_MS} ms")
        self.time_ns += duration * 1_000_000
        n = self._emit_until(self.time_ns)
        if self.clock_hz is not None and (self._last_clock_ns is None or self.time_ns > self._last_clock_ns):
            self._publish_clock(self.time_ns)
        self.done = self._next is None
        self._show_progress()
        return {"status": 0, "time_ms": self.time_ns // 1_000_000, "emitted": n, "done": self.done}

    def _seek(self, args: dict) -> dict:
        t = args.get("time_ms")
        if not isinstance(t, int) or isinstance(t, bool) or not 0 <= t <= MAX_TIME_MS:
            raise RequestError(ErrorCode.INVALID_ARGUMENT, f"time_ms: an integer from 0 to {MAX_TIME_MS} is required")
        self.time_ns = t * 1_000_000
        lo = self.time_ns + 1  # messages at exactly time_ms count as already emitted
        if self.start_ns is not None:
            lo = max(lo, self.start_ns)
        self._open(lo)
        self._last_clock_ns = None
        self.done = self._next is None
        return self.state()

    # free-running timeline: playback time p(now) = base + (now - wall0) * rate
    def _playhead(self, now: float) -> int:
        if self._paused and self._paused_at_ns is not None:
            return self._paused_at_ns
        if self.rate <= 0:
            return self.time_ns
        # saturated: a huge rate (set_rate {value: 1e308}) makes this infinite, never an error
        return int(min(self._base_ns + (now - self._wall0) * self.rate * 1e9, MAX_TIME_MS * 1_000_000))

    def _wall_of(self, t_ns: int) -> float:
        return self._wall0 + (t_ns - self._base_ns) / (self.rate * 1e9)

    def _pause(self, paused: bool) -> None:
        now = time.monotonic()
        if paused and not self._paused:
            self._paused_at_ns = self._playhead(now)
            if self.rate > 0 and self._next is not None:
                self.time_ns = max(self.time_ns, min(self._paused_at_ns, self._next.stamp_ns))
                self._paused_at_ns = self.time_ns
            self._paused = True
        elif not paused and self._paused:
            self._paused = False
            if self._paused_at_ns is not None:
                self._base_ns, self._wall0 = self._paused_at_ns, now
            self._paused_at_ns = None

    def _set_rate(self, rate: float) -> None:
        now = time.monotonic()
        p = self._playhead(now)
        self.rate = rate
        self._base_ns, self._wall0 = p, now
        if self._paused:
            self._paused_at_ns = p

    # ------------------------------------------------------------------ progress
    def _progress_enabled(self) -> bool:
        if self._progress_opt is not None:
            return self._progress_opt
        isatty = getattr(self.out, "isatty", lambda: False)()
        span_s = (self.last_ns - self.first_ns) / 1e9
        wall_s = span_s / self.rate if self.rate > 0 else 0
        return bool(isatty) and (wall_s >= 5.0 or span_s >= 60.0)

    def _show_progress(self, final: bool = False) -> None:
        if not self._progress_enabled():
            return
        now = time.monotonic()
        tty = getattr(self.out, "isatty", lambda: False)()
        if not final and now - self._progress_last < (0.2 if tty else 1.0):
            return
        self._progress_last = now
        span = max(1, self.last_ns - self.first_ns)
        pos = min(max(self.time_ns - self.first_ns, 0), span)
        pct = 100.0 * pos / span
        rate = "max" if self.rate <= 0 else f"{self.rate:g}x"
        line = (f"replay {_fmt_s(self.time_ns)} / {_fmt_s(self.last_ns)} s ({pct:5.1f}%)  "
                f"{self.emitted} msgs  rate {rate}" + ("  [paused]" if self._paused else "")
                + (f"  loop {self.loops}" if self.loops else ""))
        if tty:
            self.out.write("\r" + line + "\033[K" + ("\n" if final else ""))
        else:
            self.out.write(line + "\n")
        self._progress_shown = True
        self.out.flush()

    # ------------------------------------------------------------------ main loops
    def run(self) -> int:
        if self.pub is None:
            self.bind()
        try:
            if self.lockstep:
                self._open(self.start_ns)
                self.done = self._next is None
                while not self._stop:
                    self._service(0.2)
            else:
                self._run_free()
        except KeyboardInterrupt:
            self.interrupted = True
        finally:
            if self._progress_shown or self._progress_enabled():
                self._show_progress(final=True)
        return 0

    def _wait_start(self) -> None:
        if self.wait_subscriber:
            while not self.subscriptions and not self._stop:
                self._service(0.1)
        if self.delay_s > 0:
            end = time.monotonic() + self.delay_s
            while not self._stop and (left := end - time.monotonic()) > 0:
                self._service(left)

    def _run_free(self) -> None:
        self._wait_start()
        count = 0
        while not self._stop:
            self._open(self.start_ns)
            if self._next is None:
                break
            self._base_ns = self.start_ns if self.start_ns is not None else self._next.stamp_ns
            self.time_ns = self._base_ns
            self._wall0 = time.monotonic()
            self._last_clock_ns = None
            if self._paused:
                self._paused_at_ns = self._base_ns
            next_clock = time.monotonic()
            clock_period = 1.0 / self.clock_hz if self.clock_hz else None
            self._service(0)
            while self._next is not None and not self._stop:
                if self.rate > 0 or self._paused:
                    now = time.monotonic()
                    if clock_period is not None and self.rate > 0 and now >= next_clock:
                        # never ahead of the next unpublished message: /clock must not go backwards
                        self._publish_clock(max(min(self._playhead(now), self._next.stamp_ns), self._base_ns))
                        next_clock = now + clock_period
                    if self._paused:
                        self._service(0.05 if clock_period is None else min(0.05, clock_period))
                        self._show_progress()
                        continue
                    due = self._wall_of(self._next.stamp_ns)
                    if now < due:
                        wake = due if clock_period is None else min(due, next_clock)
                        self._service(wake - now)
                        self.time_ns = min(self._playhead(time.monotonic()), self._next.stamp_ns)
                        self._show_progress()
                        continue
                    msg = self._next
                    self._publish(msg)
                    self.time_ns = msg.stamp_ns
                    self._next = next(self._iter, None)
                else:  # as fast as possible; /clock before each new stamp
                    self.time_ns = self._next.stamp_ns
                    count += self._emit_until(self._next.stamp_ns)
                    if count >= 64:
                        count = 0
                        self._service(0)
                        self._show_progress()
                    continue
                count += 1
                if count >= 256:
                    count = 0
                    self._service(0)
                self._show_progress()
            if self._stop:
                break
            if self.clock_hz is not None and (self._last_clock_ns is None or self.time_ns > self._last_clock_ns):
                self._publish_clock(self.time_ns)
            if not self.loop:
                break
            self.loops += 1
            if self.delay_s > 0:
                end = time.monotonic() + self.delay_s
                while not self._stop and (left := end - time.monotonic()) > 0:
                    self._service(left)
        self.done = True


def replay(path: str, **kwargs: Any) -> int:
    """Bind, announce on stdout, run until the end (or forever in lockstep mode)."""
    r = Replayer(path, **kwargs)
    try:
        r.bind()
        print(r.announce(), flush=True)
        return r.run()
    finally:
        r.close()
