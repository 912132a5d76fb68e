"""Subscribe to Sensorium topics from any process (no robot needed).

    with Subscriber("tcp://127.0.0.1:5561", "/epuck/ps0/value", "/scout/") as sub:
        for msg in sub:                       # or sub.recv(timeout=1.0)
            print(msg.topic, msg.seq, msg.body["range"])

A message is three frames ``[topic + "\\0", envelope, body]`` (PROTOCOL.md §4). Typed arrays in the
body (``ranges``, ``data``, ``points``, channel ``values``) are decoded per their message type: numpy
arrays when numpy is installed, ``array('f')`` otherwise (``decode_arrays=False`` keeps the bytes).
A gap in a topic's ``seq`` is reported on the message (``gap``) and counted in ``dropped``.

The socket itself is :class:`~sensorium.client.connection.SubSocket` (the client's zmq stays in
``connection``).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from sensorium.client import arrays
from sensorium.client.connection import DEFAULT_PUB_ENDPOINT, ErrorCode, SensoriumError, SubSocket, unpack


@dataclass(frozen=True, slots=True)
class Message:
    topic: str
    type: str
    seq: int
    stamp_ns: int
    body: dict = field(repr=False)
    gap: int = 0                 # messages of this topic missed just before this one

    @property
    def stamp(self) -> float:
        """Simulated time of the measurement, seconds."""
        return self.stamp_ns / 1e9


def _f32_field(body: dict, key: str, shape: tuple[int, ...] | None = None) -> None:
    buf = body.get(key)
    if isinstance(buf, (bytes, bytearray, memoryview)):
        if shape is not None and arrays.numpy_module() is None:
            shape = None
        body[key] = arrays.float32s(bytes(buf), shape)


def decode_body(msg_type: str, body: dict) -> dict:
    """Decode a body's typed arrays in place (and return it), per PROTOCOL.md §4's dtypes."""
    if msg_type == "sensor_msgs/msg/LaserScan":
        _f32_field(body, "ranges")
        _f32_field(body, "intensities")
    elif msg_type == "sensor_msgs/msg/Image":
        if body.get("encoding") == "32FC1":
            h, w = int(body.get("height", 0)), int(body.get("width", 0))
            _f32_field(body, "data", (h, w) if h * w * 4 == len(body.get("data", b"")) else None)
    elif msg_type == "sensor_msgs/msg/PointCloud":
        pts = body.get("points")
        if isinstance(pts, (bytes, bytearray, memoryview)):
            _f32_field(body, "points", (len(pts) // 12, 3))
        for channel in body.get("channels") or ():
            if isinstance(channel, dict):
                _f32_field(channel, "values")
    return body


def decode_frames(frames: list[bytes], decode_arrays: bool = True) -> tuple[str, str, int, int, dict]:
    """``(topic, type, seq, stamp_ns, body)`` from one message's frames; raise on malformed ones."""
    if len(frames) != 3:
        raise SensoriumError(ErrorCode.BAD_REPLY, f"topic message has {len(frames)} frames, expected 3")
    raw_topic = bytes(frames[0])
    topic = (raw_topic[:-1] if raw_topic.endswith(b"\0") else raw_topic).decode("utf-8")
    try:
        envelope, body = unpack(frames[1]), unpack(frames[2])
    except Exception as exc:  # noqa: BLE001
        raise SensoriumError(ErrorCode.BAD_REPLY, f"undecodable message on {topic!r}: {exc}") from None
    if not isinstance(envelope, dict) or not isinstance(body, dict):
        raise SensoriumError(ErrorCode.BAD_REPLY, f"message on {topic!r}: envelope and body must be maps")
    msg_type = str(envelope.get("type", ""))
    if decode_arrays:
        decode_body(msg_type, body)
    return topic, msg_type, int(envelope.get("seq", 0)), int(envelope.get("stamp_ns", 0)), body


def subscription_prefix(name: str) -> bytes:
    """What to subscribe to: a name ending in ``/`` (or empty) is a prefix, anything else one exact
    topic (the trailing NUL keeps ``/a/ps1/value`` from matching ``/a/ps10/value``)."""
    if name == "" or name.endswith("/") or name.endswith("\0"):
        return name.encode("utf-8")
    return name.encode("utf-8") + b"\0"


class Subscriber:
    """A SUB socket on the server's topic endpoint (default ``tcp://127.0.0.1:5561``)."""

    def __init__(self, url: str = DEFAULT_PUB_ENDPOINT, *topics: str, decode_arrays: bool = True,
                 context: Any = None, rcvhwm: int = 1000):
        self.url = url
        self.decode_arrays = decode_arrays
        self._socket = SubSocket(url, context=context, rcvhwm=rcvhwm)
        self.last_seq: dict[str, int] = {}
        self.dropped: dict[str, int] = {}
        self.received = 0
        self.closed = False
        for t in topics:
            self.subscribe(t)

    def subscribe(self, topic: str) -> None:
        """Receive ``topic`` (exact) or every topic under a prefix ending in ``/`` (``""``: all)."""
        self._socket.subscribe(subscription_prefix(topic))

    def unsubscribe(self, topic: str) -> None:
        self._socket.unsubscribe(subscription_prefix(topic))

    def recv(self, timeout: float | None = None) -> Message | None:
        """The next message, or ``None`` if none arrives within ``timeout`` seconds."""
        if not self._socket.poll(None if timeout is None else max(0, int(timeout * 1000))):
            return None
        frames = self._socket.recv_frames()
        topic, msg_type, seq, stamp_ns, body = decode_frames(frames, self.decode_arrays)
        gap = 0
        last = self.last_seq.get(topic)
        if last is not None and seq > last + 1:
            gap = seq - last - 1
            self.dropped[topic] = self.dropped.get(topic, 0) + gap
        self.last_seq[topic] = seq          # a smaller seq (server restarted) starts over
        self.received += 1
        return Message(topic, msg_type, seq, stamp_ns, body, gap)

    def __iter__(self) -> Iterator[Message]:
        while not self.closed:
            msg = self.recv()
            if msg is not None:
                yield msg

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            self._socket.close()

    def __enter__(self) -> Subscriber:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
