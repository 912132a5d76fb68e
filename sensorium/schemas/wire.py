"""Bytes on the wire (PROTOCOL.md §2–§4): msgpack with limits, typed arrays, frames, stamps.

Imports with ``msgpack`` alone; numpy is imported lazily by the helpers that build or read
arrays. Decoding never uses pickle and never trusts sizes: every unpack is bounded, map keys must
be strings (or bytes), extension types are refused, and every failure is a :class:`WireError`.

    body = pack({"id": 1, "service": "get_info", "args": {}})
    req = parse_request(body)                       # -> Request(id=1, service="get_info", args={})
    frames = topic_frames("/epuck/ps0/value", "sensor_msgs/msg/Range", 0, 32_000_000, body_bytes)
    topic, env, body = decode_topic(frames)
"""

from __future__ import annotations

import math
import threading
from enum import IntEnum
from typing import Any, NamedTuple

import msgpack

__all__ = [
    "PROTOCOL_VERSION", "SOFT_LIMIT", "HARD_LIMIT", "MAX_REPLY", "ErrorCode", "WireError", "RequestError",
    "pack", "unpack", "Request", "parse_request", "ok_reply", "error_reply",
    "to_bin", "from_bin", "F32", "I32", "topic_frame", "topic_frames", "decode_topic",
    "stamp", "stamp_ns", "ms_to_ns", "covers",
]

PROTOCOL_VERSION = 1

SOFT_LIMIT = 1 << 20
"""Requests larger than this (bytes, all frames) are answered with ``TOO_LARGE`` (PROTOCOL §3.1)."""

HARD_LIMIT = 2 << 20
"""ZMQ_MAXMSGSIZE on the server's ROUTER, per frame: libzmq drops the connection of a peer sending
a larger frame (the number of frames is bounded by the transport, PROTOCOL §3.1)."""

MAX_REPLY = 64 << 20
"""The largest reply the server sends (PROTOCOL §3.1): a longer one is answered with ``TOO_LARGE``
instead. Clients may refuse longer messages (the C client sets ``ZMQ_MAXMSGSIZE`` to it)."""


class ErrorCode(IntEnum):
    """Error codes of PROTOCOL.md §3.2 (re-exported by :mod:`sensorium.schemas.services`)."""

    BAD_REQUEST = 1
    UNKNOWN_SERVICE = 2
    UNKNOWN_ROBOT = 3
    UNKNOWN_DEVICE = 4
    INVALID_ARGUMENT = 5
    NOT_ATTACHED = 6
    ROBOT_TAKEN = 7
    TOO_LARGE = 8
    SHUTTING_DOWN = 9
    WRONG_STATE = 10
    NOT_SUPERVISOR = 11
    INTERNAL = 99


class WireError(ValueError):
    """Bytes that are not a valid message of this protocol."""


class RequestError(Exception):
    """A request that must be answered with an error reply: ``code``, ``message`` and the request
    ``id`` when it could be read (``None`` otherwise)."""

    def __init__(self, code: ErrorCode, message: str, id: int | None = None):
        super().__init__(f"{code.name}: {message}")
        self.code = ErrorCode(code)
        self.message = message
        self.id = id


# ---------------------------------------------------------------------- msgpack

_PACKERS = threading.local()    # one reused msgpack.Packer per thread (packb makes a new one per call)
PACKER_KEEP = 64 * 1024         # a packer that made a larger document is dropped, not its buffer kept


def pack(obj: Any) -> bytes:
    """One msgpack document; ``str`` as str, ``bytes``/``memoryview`` as bin, floats as float64."""
    packer = getattr(_PACKERS, "packer", None)
    if packer is None:
        packer = _PACKERS.packer = msgpack.Packer(use_bin_type=True)
    data = packer.pack(obj)            # resets its buffer, also when packing fails
    if len(data) > PACKER_KEEP:
        _PACKERS.packer = None
    return data


def unpack(data: bytes | bytearray | memoryview, max_size: int | None = SOFT_LIMIT) -> Any:
    """Decode one msgpack document of at most ``max_size`` bytes (``None``: any size), or raise
    :class:`WireError`.

    Strings must be UTF-8, map keys str or bytes, no extension types, nesting bounded by msgpack's
    own stack limit; no element may claim more than the document's size."""
    n = len(data)
    if max_size is not None and n > max_size:
        raise WireError(f"message of {n} bytes exceeds the limit of {max_size} bytes")
    try:
        return msgpack.unpackb(
            data, raw=False, strict_map_key=True, use_list=True,
            max_str_len=n, max_bin_len=n, max_array_len=n, max_map_len=n,
            max_ext_len=0,
        )
    except UnicodeDecodeError as exc:             # a C caller's Latin-1 file name, say: a well-formed document
        raise WireError(f"a string in the message is not UTF-8 text (at "
                        f"{bytes(exc.object[max(0, exc.start - 30):exc.end])!r})") from None
    except (ValueError, OverflowError) as exc:   # every msgpack failure (ExtraData, StackError, ...)
        raise WireError(f"not a msgpack document: {type(exc).__name__}: {exc}".rstrip(": ")) from None


# ---------------------------------------------------------------------- RPC envelopes

class Request(NamedTuple):
    id: int
    service: str
    args: dict


def _is_uint(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and 0 <= v < 1 << 64


def parse_request(data: bytes | memoryview, max_size: int = SOFT_LIMIT) -> Request:
    """Bytes → :class:`Request`, or raise :class:`RequestError` (``BAD_REQUEST``/``TOO_LARGE``)."""
    if len(data) > max_size:
        raise RequestError(ErrorCode.TOO_LARGE, f"request of {len(data)} bytes exceeds the limit of {max_size} bytes")
    try:
        msg = unpack(data, max_size)
    except WireError as exc:
        raise RequestError(ErrorCode.BAD_REQUEST, str(exc)) from None
    if not isinstance(msg, dict):
        raise RequestError(ErrorCode.BAD_REQUEST, f"request must be a msgpack map, got {type(msg).__name__}")
    rid: Any = msg.get("id")
    if not _is_uint(rid):
        raise RequestError(ErrorCode.BAD_REQUEST, "request 'id' must be an unsigned integer"
                           if "id" in msg else "request has no 'id'")
    service = msg.get("service")
    if not isinstance(service, str) or not service:
        raise RequestError(ErrorCode.BAD_REQUEST, "request 'service' must be a non-empty string"
                           if "service" in msg else "request has no 'service'", rid)
    args = msg.get("args")
    if not isinstance(args, dict):
        raise RequestError(ErrorCode.BAD_REQUEST, "request 'args' must be a map"
                           if "args" in msg else "request has no 'args' (send {} for none)", rid)
    assert isinstance(rid, int)  # _is_uint checked it
    return Request(rid, service, args)


def ok_reply(rid: int | None, result: dict) -> bytes:
    return pack({"id": rid, "ok": True, "result": result})


MAX_ERROR_MESSAGE = 512      # characters: an error never echoes a large input back


def error_reply(rid: int | None, code: ErrorCode | int, message: str) -> bytes:
    if len(message) > MAX_ERROR_MESSAGE:
        message = message[:MAX_ERROR_MESSAGE - 1] + "…"
    return pack({"id": rid, "ok": False, "error": {"code": int(code), "message": message}})


MAX_ARGS_DEPTH = 16          # nesting of a request's args (maps and arrays)
MAX_ARGS_ITEMS = 100_000     # values in a request's args, all levels


def check_args_shape(args: Any) -> str | None:
    """Why a request's args are too deep or too large to validate, or ``None``. Iterative (no
    recursion), stops at the first excess: the cost is bounded by the limits, not the input."""
    stack = [(args, 1)]
    items = 0
    while stack:
        value, depth = stack.pop()
        if isinstance(value, dict):
            children: Any = value.values()
        elif isinstance(value, (list, tuple)):
            children = value
        else:
            continue
        if depth > MAX_ARGS_DEPTH:
            return f"args nested deeper than {MAX_ARGS_DEPTH} levels"
        items += len(value)
        if items > MAX_ARGS_ITEMS:
            return f"args hold more than {MAX_ARGS_ITEMS} values"
        stack.extend((v, depth + 1) for v in children if isinstance(v, (dict, list, tuple)))
    return None


# ---------------------------------------------------------------------- typed arrays

F32 = "<f4"
I32 = "<i4"


def to_bin(array: Any, dtype: str = F32) -> bytes:
    """A numpy array (or anything ``numpy.asarray`` takes) → little-endian raw bytes of ``dtype``."""
    import numpy as np

    return np.ascontiguousarray(array, dtype=np.dtype(dtype)).tobytes()


def from_bin(data: bytes | memoryview, dtype: str = F32, shape: tuple[int, ...] | None = None) -> Any:
    """Little-endian raw bytes → read-only numpy array of ``dtype`` (native byte order view when
    possible), reshaped to ``shape`` if given. Raises :class:`WireError` on a size mismatch."""
    import numpy as np

    dt = np.dtype(dtype)
    if len(data) % dt.itemsize:
        raise WireError(f"{len(data)} bytes is not a whole number of {dt} items")
    arr = np.frombuffer(data, dtype=dt)
    if shape is not None:
        if math.prod(shape) != arr.size:
            raise WireError(f"{arr.size} items do not fill shape {shape}")
        arr = arr.reshape(shape)
    return arr


# ---------------------------------------------------------------------- topics

def topic_frame(name: str) -> bytes:
    """The first frame of a topic message: the name and a NUL (exact subscriptions, §4)."""
    return name.encode("utf-8") + b"\0"


def covers(prefix: bytes, frame: bytes) -> bool:
    """Does a SUB subscription ``prefix`` receive messages whose first frame is ``frame``?"""
    return frame.startswith(prefix)


def topic_frames(name: str | bytes, type_name: str, seq: int, stamp_ns_: int, body: bytes) -> list[bytes]:
    """The three frames of one topic message: ``[topic\\0, envelope, body]``."""
    frame = name if isinstance(name, bytes) else topic_frame(name)
    return [frame, pack({"type": type_name, "seq": seq, "stamp_ns": stamp_ns_}), body]


def decode_topic(frames: list[bytes], max_size: int | None = None) -> tuple[str, dict, dict]:
    """``[topic\\0, envelope, body]`` → (topic name, envelope map, body map); :class:`WireError` if
    the frames are not a topic message."""
    if len(frames) != 3:
        raise WireError(f"a topic message has 3 frames, got {len(frames)}")
    first = bytes(frames[0])
    if not first.endswith(b"\0"):
        raise WireError("topic frame does not end with NUL")
    try:
        name = first[:-1].decode("utf-8")
    except UnicodeDecodeError as exc:
        raise WireError(f"topic name is not UTF-8: {exc}") from None
    env = unpack(frames[1], max_size)
    body = unpack(frames[2], max_size)
    if not isinstance(env, dict) or not isinstance(body, dict):
        raise WireError("topic envelope and body must be maps")
    return name, env, body


# ---------------------------------------------------------------------- time

def ms_to_ns(ms: int) -> int:
    return int(ms) * 1_000_000


def stamp(ns: int) -> dict:
    """Integer nanoseconds → ROS ``builtin_interfaces/Time`` map ``{sec, nanosec}``."""
    sec, nanosec = divmod(int(ns), 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def stamp_ns(t: dict) -> int:
    """ROS ``{sec, nanosec}`` map → integer nanoseconds."""
    return int(t["sec"]) * 1_000_000_000 + int(t["nanosec"])
