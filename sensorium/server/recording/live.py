"""``sensorium record --connect``: record a running server's topics as an ordinary subscriber.

This module talks ZeroMQ as a *client* of a server (one DEALER request to ``get_info``, one SUB
socket), like any other subscriber; it is the recording side's only zmq client code (replay.py
binds the server-shaped sockets of a replay).

Such a subscriber can fall behind (PUB drops at the high-water mark), so it checks every topic's
envelope ``seq`` and reports each gap and the exact number of messages lost between the ones it
received. For a recording that cannot lose anything, use ``sensorium serve --record``, which writes
from inside the server's step loop (:func:`sensorium.server.recording.writer.recorder_for_server`).
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlsplit

import msgpack
import zmq

from sensorium.server.daemon.transport import curve_client_from_env
from sensorium.server.recording.envelope import DEFAULT_CHUNK_SIZE, topic_matcher, unmatched_topics
from sensorium.server.recording.writer import McapRecorder

__all__ = ["LiveRecorder", "GapTracker", "subscription_prefixes", "rpc_call"]


def subscription_prefixes(patterns: list[str] | None) -> list[bytes]:
    """SUB prefixes covering a ``--topics`` list (the exact filter is applied on receipt)."""
    if not patterns:
        return [b""]
    out = []
    for p in patterns:
        cut = min([i for i, c in enumerate(p) if c in "*?["] or [len(p)])
        lit = p[:cut]
        if cut == len(p) and not p.endswith("/"):
            out.append(p.encode() + b"\0")  # the exact topic
            out.append(p.rstrip("/").encode() + b"/")  # and anything below it
        else:
            out.append(lit.encode())
    return sorted(set(out))


@dataclass
class GapTracker:
    """Per-topic ``seq`` bookkeeping: a jump of k > 1 is a gap of k - 1 lost messages."""

    last: dict[str, int] = field(default_factory=dict)
    received: dict[str, int] = field(default_factory=dict)
    lost: dict[str, int] = field(default_factory=dict)
    gaps: int = 0
    resets: int = 0

    def see(self, topic: str, seq: int) -> int:
        """Record ``seq``; returns how many messages were lost just before it."""
        self.received[topic] = self.received.get(topic, 0) + 1
        last = self.last.get(topic)
        self.last[topic] = seq
        if last is None:
            return 0
        if seq > last + 1:
            n = seq - last - 1
            self.gaps += 1
            self.lost[topic] = self.lost.get(topic, 0) + n
            return n
        if seq <= last:  # publisher restarted (or a replay looped)
            self.resets += 1
        return 0

    @property
    def total_lost(self) -> int:
        return sum(self.lost.values())

    @property
    def total_received(self) -> int:
        return sum(self.received.values())


def rpc_call(ctx: zmq.Context, url: str, service: str, args: dict | None = None, timeout: float = 5.0) -> dict:
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    try:
        curve_client_from_env(sock)
        sock.connect(url)
        sock.send(msgpack.packb({"id": 1, "service": service, "args": args or {}}))
        if not sock.poll(int(timeout * 1000)):
            raise TimeoutError(f"no answer from {url} within {timeout:g} s (is a server running there?)")
        reply = msgpack.unpackb(sock.recv(), raw=False)
    finally:
        sock.close()
    if not reply.get("ok"):
        err = reply.get("error") or {}
        raise RuntimeError(f"{service} failed: {err.get('message', err)}")
    return reply.get("result") or {}


def rpc_endpoint(url: str) -> str:
    """A controller URL (``tcp://host:port/robot``) → its RPC endpoint (``tcp://host:port``)."""
    parts = urlsplit(url)
    if parts.scheme == "tcp":
        return f"tcp://{parts.netloc}"
    return url


def reachable_pub(pub: str, rpc: str) -> str:
    """A pub endpoint bound to a wildcard address is reached on the RPC endpoint's host."""
    p, r = urlsplit(pub), urlsplit(rpc)
    if p.scheme == "tcp" and r.scheme == "tcp" and p.hostname in ("0.0.0.0", "*", "::", None):
        return f"tcp://{r.hostname}:{p.port}"
    return pub


class LiveRecorder:
    """Subscribe to a server's topics and record them. ``on_message(topic, seq)`` is called after
    each message is stored (tests use it to play a slow reader).

    A server restart (a topic's ``seq`` or stamp goes back: a new server on the same endpoint)
    starts a new file, ``NAME-2.mcap`` (then ``-3``...; never an existing file), so that each file
    holds one run with one clock. The closed file gets a ``server_restart`` metadata record naming
    the next file; the new one a ``session.previous_file``; ``sensorium info`` shows both."""

    def __init__(self, path: str | Path, *, connect: str | None = "tcp://127.0.0.1:5560",
                 pub: str | None = None, topics: list[str] | None = None, world: str | None = None,
                 chunk_size: int = DEFAULT_CHUNK_SIZE, rcvhwm: int = 1000,
                 on_message: Callable[[str, int], None] | None = None,
                 log: Callable[[str], None] | None = None, context: zmq.Context | None = None):
        self.path = Path(path)
        self.connect = connect
        self.pub = pub
        self.topics = topics
        self.world = world
        self.chunk_size = chunk_size
        self.rcvhwm = rcvhwm
        self.on_message = on_message
        self.log = log or (lambda text: print(text, file=sys.stderr, flush=True))
        self.ctx = context or zmq.Context.instance()
        self.gaps = GapTracker()
        self.info: dict = {}
        self._stop = False
        self.sub: zmq.Socket | None = None
        self.recorder: McapRecorder | None = None
        self.pub_endpoint = ""
        self._gap_lines = 0
        self.files: list[Path] = [self.path]      # one per server run
        self._last_stamp: dict[str, int] = {}
        self._rec_args: tuple = ()

    def stop(self) -> None:
        """End :meth:`run` at its next safe point: once the message being stored is counted too, or
        within 100 ms while it waits for one (a signal handler may call it)."""
        self._stop = True

    def open(self) -> None:
        rpc = rpc_endpoint(self.connect) if self.connect else None
        if rpc and not self.pub:
            self.info = rpc_call(self.ctx, rpc, "get_info")
            self.pub_endpoint = reachable_pub(self.info["pub_endpoint"], rpc)
        else:
            if rpc:
                try:
                    self.info = rpc_call(self.ctx, rpc, "get_info", timeout=2.0)
                except Exception:
                    self.info = {}
            if not self.pub:
                raise ValueError("nothing to record from: give a server (connect) or a topic endpoint (pub)")
            self.pub_endpoint = self.pub
        listed = self.info.get("topics")
        if self.topics and isinstance(listed, list):     # a server's topics are known: a typo records nothing
            problem = unmatched_topics(self.topics, [str(t.get("name")) for t in listed if isinstance(t, dict)],
                                       f"the server at {rpc}")
            if problem:
                raise ValueError(problem)
        world_text, world_name = b"", ""
        world_model, base_dir = None, Path(".")
        if self.world:
            world_text, world_name = Path(self.world).read_bytes(), Path(self.world).name
            try:                        # for the Foxglove /scene; a world that does not load just has none
                from sensorium.server.world.loader import WorldError, load_world
                world_model, base_dir = load_world(self.world).world, Path(self.world).resolve().parent
            except (WorldError, OSError, ValueError):
                pass
        self._rec_args = (world_text, world_name or "world.yaml", world_model, base_dir)
        self.sub = self.ctx.socket(zmq.SUB)
        self.sub.setsockopt(zmq.RCVHWM, self.rcvhwm)
        self.sub.setsockopt(zmq.LINGER, 0)
        for prefix in subscription_prefixes(self.topics):
            self.sub.setsockopt(zmq.SUBSCRIBE, prefix)
        curve_client_from_env(self.sub)
        self.sub.connect(self.pub_endpoint)
        self.recorder = self._new_recorder(self.path)

    def _metadata(self) -> dict[str, str]:
        meta = {}
        rec_meta = self.info.get("recording", {}).get("metadata", {}) if isinstance(self.info.get("recording"), dict) else {}
        meta.update({k: str(v) for k, v in rec_meta.items() if k in ("seed", "world", "basic_time_step_ms")})
        if self.info.get("world"):
            meta["world"] = str(self.info["world"])
        if self.info.get("basic_time_step") is not None:
            meta["basic_time_step_ms"] = str(self.info["basic_time_step"])
        for key in ("seed", "random_seed"):
            if self.info.get(key) is not None:
                meta["seed"] = str(self.info[key])
        if self.info.get("version"):
            meta["server_version"] = str(self.info["version"])
        return meta

    def _new_recorder(self, path: Path, previous: str | None = None) -> McapRecorder:
        world_text, world_name, world_model, base_dir = self._rec_args
        session = {"mode": "subscriber", "pub_endpoint": self.pub_endpoint, "connect": self.connect or ""}
        if previous:
            session["previous_file"] = previous
        return McapRecorder(path, world_text, world_name, self._metadata(), self.topics, self.chunk_size,
                            world=world_model, base_dir=base_dir, session=session)

    def _next_path(self) -> Path:
        n = len(self.files) + 1
        while True:
            p = self.path.with_name(f"{self.path.stem}-{n}{self.path.suffix}")
            if not p.exists():
                return p
            n += 1

    def _restarted(self, topic: str, seq: int, stamp_ns: int) -> bool:
        last_stamp, last_seq = self._last_stamp.get(topic), self.gaps.last.get(topic)
        return (last_stamp is not None and stamp_ns < last_stamp) or (last_seq is not None and seq < last_seq)

    def _rotate(self, topic: str, stamp_ns: int) -> None:
        """A new server run: finish this file, continue in the next one."""
        assert self.recorder is not None
        last = self._last_stamp.get(topic, 0)
        nxt = self._next_path()
        self.recorder.add_metadata("server_restart", {
            "next_file": nxt.name, "topic": topic, "last_stamp_ns": str(last), "stamp_ns": str(stamp_ns)})
        self.recorder.close()
        self.gaps.last.clear()
        self._last_stamp.clear()
        if self.connect:
            try:
                self.info = rpc_call(self.ctx, rpc_endpoint(self.connect), "get_info", timeout=2.0)
            except Exception:  # noqa: BLE001 - the new run's metadata is a nicety; keep recording
                pass
        self.recorder = self._new_recorder(nxt, previous=self.files[-1].name)
        self.files.append(nxt)
        self.log(f"sensorium: the server restarted ({topic} went back from {last / 1e9:.3f} s to "
                 f"{stamp_ns / 1e9:.3f} s): continuing in {nxt}")

    def run(self, duration: float | None = None, max_messages: int | None = None) -> None:
        assert self.sub is not None and self.recorder is not None
        match = topic_matcher(self.topics)
        deadline = None if duration is None else time.monotonic() + duration
        n = 0
        while not self._stop:
            if deadline is not None and time.monotonic() >= deadline:
                break
            if not self.sub.poll(100):
                self.recorder.maybe_flush()
                continue
            while True:
                try:
                    frames = self.sub.recv_multipart(zmq.NOBLOCK)
                except zmq.Again:
                    break
                if len(frames) != 3 or not frames[0].endswith(b"\0"):
                    continue
                topic = frames[0][:-1].decode("utf-8", "replace")
                if not match(topic):
                    continue
                try:
                    env = msgpack.unpackb(frames[1], raw=False)
                    ros_type, seq, stamp_ns = str(env["type"]), int(env["seq"]), int(env["stamp_ns"])
                except Exception:
                    continue
                if self._restarted(topic, seq, stamp_ns):
                    self._rotate(topic, stamp_ns)
                self._last_stamp[topic] = stamp_ns
                self.recorder.record(topic, ros_type, frames[1], frames[2], stamp_ns, seq)
                if self.recorder.failed:                 # disk full: said once by the recorder; stop
                    return
                lost = self.gaps.see(topic, seq)
                if lost:
                    self._gap_lines += 1
                    if self._gap_lines <= 20:
                        self.log(f"sensorium: gap on {topic}: seq {seq - lost - 1} -> {seq} ({lost} lost)")
                    elif self._gap_lines == 21:
                        self.log("sensorium: more gaps; see the summary at the end")
                if self.on_message is not None:
                    self.on_message(topic, seq)
                n += 1
                if max_messages is not None and n >= max_messages:
                    return
                if self._stop:
                    return

    def close(self) -> dict:
        """Finish the file; returns the summary (also stored as metadata ``record``)."""
        summary = self.summary()
        if self.recorder is not None:
            self.recorder.add_metadata("record", {"received": str(summary["received"]), "gaps": str(summary["gaps"]),
                                                  "lost": str(summary["lost"]),
                                                  "lost_by_topic": json.dumps(summary["lost_by_topic"])})
            self.recorder.close()
        if self.sub is not None:
            self.sub.close()
        return summary

    def summary(self) -> dict:
        g = self.gaps
        return {"file": str(self.path), "received": g.total_received, "topics": len(g.received),
                "gaps": g.gaps, "lost": g.total_lost, "lost_by_topic": dict(sorted(g.lost.items())),
                "resets": g.resets, "files": [str(p) for p in self.files], "restarts": len(self.files) - 1}
