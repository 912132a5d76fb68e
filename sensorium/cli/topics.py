"""``sensorium topics``, ``echo`` and ``hz``: look at a running server's topics (pyzmq + msgpack only).

``echo`` and ``hz`` first ask the server (its RPC endpoint ``--url``, ``get_info``) which topics
exist: a name that is not one of them fails at once with the closest names; a server that does not
answer makes them give up after ``--timeout`` (default 5 s, as every client command) with a message
instead of waiting forever. One flag, one meaning across commands: ``--url`` is the server's RPC
endpoint (topics, services, call, controller, echo, hz, record), ``--pub`` a topic endpoint. The
old spellings still work with a deprecation line: ``--rpc`` of echo/hz, and ``--url`` of echo/hz
given a topic endpoint (no server answers there: it is taken as ``--pub``).
"""

from __future__ import annotations

import argparse
import difflib
import math
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from sensorium.cli.format import dumps, to_yaml
from sensorium.client.connection import (
    DEFAULT_PUB_ENDPOINT,
    DEFAULT_RPC_ENDPOINT,
    Connection,
    SensoriumError,
    parse_controller_url,
)

DEFAULT_WAIT_S = 5.0           # no server answered: give up after this long without a message (as topics/call)
NOTE_AFTER_S = 3.0             # the server answered but nothing came: say why after this long


def add_endpoint_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--url", help=f"the server's RPC endpoint, asked for its topics (default {DEFAULT_RPC_ENDPOINT})")
    p.add_argument("--pub", metavar="URL",
                   help=f"topic endpoint to subscribe to (default: the server's, else {DEFAULT_PUB_ENDPOINT})")
    p.add_argument("--rpc", help=argparse.SUPPRESS)            # deprecated spelling of --url
    from sensorium.cli import positive_seconds

    p.add_argument("--timeout", type=positive_seconds, metavar="S",
                   help=f"exit 1 if no message arrives for S seconds (default: {DEFAULT_WAIT_S:g} s when no server "
                        "answers, else wait)")


@dataclass
class ServerView:
    """What ``get_info`` told us (``info`` None: no server answered on ``rpc``)."""

    rpc: str
    info: dict | None = None
    problem: str = ""
    names: list[str] = field(default_factory=list)

    @property
    def pub(self) -> str | None:
        return self.info.get("pub_endpoint") if self.info else None


def ask_server(rpc: str | None, timeout: float = 2.0) -> ServerView:
    view = ServerView(rpc or DEFAULT_RPC_ENDPOINT)
    try:
        view.rpc = parse_controller_url(view.rpc).endpoint          # a controller URL works too
        with Connection(view.rpc, timeout=timeout) as conn:
            view.info = conn.call("get_info")
    except SensoriumError as exc:
        view.problem = str(exc)
        return view
    view.names = [str(t.get("name")) for t in view.info.get("topics", [])]
    return view


def closest(name: str, names: list[str], n: int = 3) -> list[str]:
    """The existing topic names nearest to ``name`` (same device or same kind first)."""
    picks = difflib.get_close_matches(name, names, n=n, cutoff=0.5)
    if not picks:
        tail = name.rstrip("/").rsplit("/", 1)[-1]
        picks = [t for t in names if t.endswith("/" + tail)][:n]
    return picks


def unknown_topic(name: str, view: ServerView) -> str | None:
    """A one-line complaint if ``name`` (exact, or a prefix ending in '/') matches no topic."""
    if view.info is None or name == "":
        return None
    if name.endswith("/"):
        if any(t.startswith(name) for t in view.names):
            return None
    elif name in view.names:
        return None
    near = closest(name, view.names)
    hint = f"; closest: {', '.join(near)}" if near else f"; topics: {', '.join(view.names[:6])}{' ...' if len(view.names) > 6 else ''}"
    return f"no topic {name!r} on world {view.info.get('world')!r} at {view.rpc}{hint} (sensorium topics lists them)"


def why_silent(view: ServerView) -> str:
    """Why a server that answered publishes nothing (mode, controllers)."""
    info = view.info or {}
    if info.get("mode") == "pause":
        return "the server is paused (sensorium call set_mode '{mode: fast}')"
    robots = info.get("robots", [])
    if not any(r.get("attached") for r in robots):
        waiting = [r["name"] for r in robots if r.get("controller", "<extern>") != "<none>" and r.get("synchronization")]
        if waiting:
            return (f"the world waits for a controller to attach to {' or '.join(repr(r) for r in waiting)} "
                    "(see PROTOCOL.md 3.7)")
    return f"the world is at {info.get('time_ms', 0) / 1000:g} s; is the topic's device producing values?"


def no_message(cmd: str, what: str, url: str, waited: float, view: ServerView) -> str:
    if view.info is None and not view.rpc:
        return (f"sensorium {cmd}: nothing on {what} from {url} for {waited:g} s (give --url to ask the server "
                "why, or check that a server or replay publishes there)")
    if view.info is None:
        return (f"sensorium {cmd}: nothing on {what} from {url} for {waited:g} s, and no server answers at "
                f"{view.rpc}: is `sensorium serve` running? (--url and --pub point elsewhere)")
    return f"sensorium {cmd}: nothing on {what} from {url} for {waited:g} s: {why_silent(view)}"


def _subscribe(cmd: str, url: str, topics: list[str], **kwargs: Any) -> Any:
    """A :class:`Subscriber` on ``url``, or None after one line saying why it cannot connect there
    (an unsupported scheme, no port: ZeroMQ refuses the endpoint)."""
    import zmq

    from sensorium.client.topics import Subscriber

    try:
        return Subscriber(url, *topics, **kwargs)
    except (zmq.ZMQError, ValueError) as exc:
        print(f"sensorium {cmd}: cannot subscribe to {url}: {exc}", file=sys.stderr)
        return None


def _setup(cmd: str, names: list[str], args: argparse.Namespace) -> tuple[ServerView, str] | int:
    """Ask the server, check the names; returns (view, topic endpoint) or an exit code."""
    rpc = args.url
    if args.rpc:
        print(f"sensorium {cmd}: --rpc is deprecated: use --url (the server's RPC endpoint, as for topics, "
              "services and call)", file=sys.stderr)
        rpc = rpc or args.rpc
    pub = args.pub
    if rpc:
        try:
            parse_controller_url(rpc)
        except SensoriumError as exc:       # not an endpoint at all: never taken for a topic endpoint
            print(f"sensorium {cmd}: {exc}", file=sys.stderr)
            return 2
    view = ask_server(rpc) if (rpc or not pub) else ServerView("")
    if view.info is None and args.url and not pub and not args.rpc:
        # the old meaning of echo/hz --url: a topic endpoint (nothing answers RPCs there)
        print(f"sensorium {cmd}: no server answers at --url {args.url}; taking it as the topic endpoint, which "
              f"--url named for echo and hz before (deprecated: use --pub {args.url})", file=sys.stderr)
        pub, view = args.url, ServerView("")
    for name in names:
        complaint = unknown_topic(name, view)
        if complaint:
            print(f"sensorium {cmd}: {complaint}", file=sys.stderr)
            return 1
    return view, pub or view.pub or DEFAULT_PUB_ENDPOINT


# ---------------------------------------------------------------------- topics

def topics(args: argparse.Namespace) -> int:
    view = ask_server(args.url, timeout=args.timeout)
    if view.info is None:
        print(f"sensorium topics: no server answered at {view.rpc}: {view.problem}", file=sys.stderr)
        return 1
    rows = [(str(t.get("name")), str(t.get("type"))) for t in view.info.get("topics", [])]
    if args.json:
        print(dumps({"world": view.info.get("world"), "pub_endpoint": view.pub,
                     "topics": [{"name": n, "type": t} for n, t in rows]}))
        return 0
    print(f"# world {view.info.get('world')!r}, topics on {view.pub or DEFAULT_PUB_ENDPOINT}", file=sys.stderr)
    width = max((len(n) for n, _ in rows), default=0)
    for name, kind in rows:
        print(f"{name:<{width}}  {kind}")
    return 0


# ---------------------------------------------------------------------- echo

def format_message(msg: Any, full: bool = False) -> str:
    """A message as a YAML document: a comment line naming it, the body, then '---'."""
    head = f"# {msg.topic} [{msg.type}] seq={msg.seq} t={msg.stamp_ns / 1e9:.3f} s"
    return "\n".join([head, *to_yaml(dict(msg.body), full), "---"])


def echo(args: argparse.Namespace) -> int:
    setup = _setup("echo", args.topics, args)
    if isinstance(setup, int):
        return setup
    view, url = setup
    limit = args.timeout if args.timeout is not None else (None if view.info else DEFAULT_WAIT_S)
    count = 0
    noted = False
    last = time.monotonic()
    sub = _subscribe("echo", url, args.topics)      # one socket: several topics come in the order published
    if sub is None:
        return 1
    with sub:
        while args.count is None or count < args.count:
            wait = 0.25 if limit is None else max(0.0, min(0.25, limit - (time.monotonic() - last)))
            msg = sub.recv(timeout=wait)
            if msg is None:
                idle = time.monotonic() - last
                if limit is not None and idle >= limit:
                    print(no_message("echo", " or ".join(map(repr, args.topics)), url, limit, view), file=sys.stderr)
                    return 1
                if not noted and count == 0 and view.info is not None and idle >= NOTE_AFTER_S:
                    view = ask_server(view.rpc) if view.info else view
                    print(f"# nothing yet: {why_silent(view)}", file=sys.stderr, flush=True)
                    noted = True
                continue
            last = time.monotonic()
            if msg.gap:
                print(f"# {msg.gap} message(s) of {msg.topic} lost before seq {msg.seq}", file=sys.stderr)
            if args.json:
                print(dumps({"topic": msg.topic, "type": msg.type, "seq": msg.seq, "stamp_ns": msg.stamp_ns,
                             "body": msg.body}), flush=True)
            else:
                print(format_message(msg, args.full), flush=True)
            count += 1
    return 0


# ---------------------------------------------------------------------- hz

@dataclass
class Rate:
    """Arrival statistics of one topic over the last ``window`` messages."""

    window: int
    wall: deque = field(default_factory=deque)
    stamps: deque = field(default_factory=deque)
    total: int = 0

    def add(self, wall_s: float, stamp_ns: int) -> None:
        self.wall.append(wall_s)
        self.stamps.append(stamp_ns)
        self.total += 1
        while len(self.wall) > self.window + 1:
            self.wall.popleft()
            self.stamps.popleft()

    def stats(self) -> dict | None:
        """Rates (Hz) from wall arrival times and from the messages' simulated stamps, and the
        wall-clock period's min/max/std (s), like ``ros2 topic hz``; None below two messages."""
        if len(self.wall) < 2:
            return None
        periods = [b - a for a, b in zip(self.wall, list(self.wall)[1:])]
        mean = sum(periods) / len(periods)
        std = math.sqrt(sum((p - mean) ** 2 for p in periods) / len(periods))
        sim_span = (self.stamps[-1] - self.stamps[0]) / 1e9
        return {"rate_hz": (len(periods) / (self.wall[-1] - self.wall[0])) if self.wall[-1] > self.wall[0] else math.inf,
                "sim_rate_hz": len(periods) / sim_span if sim_span > 0 else math.inf,
                "min_s": min(periods), "max_s": max(periods), "std_s": std, "window": len(periods),
                "messages": self.total}


def hz(args: argparse.Namespace) -> int:
    setup = _setup("hz", args.topics, args)
    if isinstance(setup, int):
        return setup
    view, url = setup
    limit = args.timeout if args.timeout is not None else (None if view.info else DEFAULT_WAIT_S)
    rates: dict[str, Rate] = {}
    start = last = next_report = time.monotonic()
    next_report += args.every
    noted = False
    sub = _subscribe("hz", url, list(args.topics), decode_arrays=False)
    if sub is None:
        return 1
    with sub:
        while args.duration is None or time.monotonic() - start < args.duration:
            msg = sub.recv(timeout=0.05)
            now = time.monotonic()
            if msg is not None:
                last = now
                rates.setdefault(msg.topic, Rate(args.window)).add(now, msg.stamp_ns)
            elif limit is not None and now - last >= limit:
                print(no_message("hz", ", ".join(repr(t) for t in args.topics), url, limit, view), file=sys.stderr)
                return 1
            elif not noted and not rates and view.info is not None and now - start >= NOTE_AFTER_S:
                print(f"# nothing yet: {why_silent(ask_server(view.rpc))}", file=sys.stderr, flush=True)
                noted = True
            if now >= next_report:
                next_report = now + args.every
                _report(rates, args.json)
    _report(rates, args.json)
    if not rates:               # --duration ended it before a message came: say why, as --timeout does
        print(no_message("hz", ", ".join(repr(t) for t in args.topics), url, args.duration,
                         ask_server(view.rpc) if view.info else view), file=sys.stderr)
        return 1
    return 0


def _report(rates: dict[str, Rate], as_json: bool) -> None:
    for topic in sorted(rates):
        s = rates[topic].stats()
        if s is None:
            continue
        if as_json:
            print(dumps({"topic": topic, **s}), flush=True)
        else:
            print(f"{topic}: average rate {s['rate_hz']:.3f} Hz ({s['sim_rate_hz']:.3f} Hz of simulated time)\n"
                  f"\tmin: {s['min_s']:.4f}s max: {s['max_s']:.4f}s std dev: {s['std_s']:.5f}s window: {s['window']}",
                  flush=True)
