"""Encoding helpers: bounded msgpack, request parsing, typed arrays, topic frames, stamps."""

from __future__ import annotations

import subprocess
import sys

import msgpack
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sensorium.schemas import wire
from sensorium.schemas.wire import ErrorCode, RequestError, WireError


def test_imports_with_msgpack_alone():
    code = ("import sys; sys.modules['numpy'] = None; sys.modules['pydantic'] = None; sys.modules['zmq'] = None\n"
            "from sensorium.schemas import wire\n"
            "assert wire.unpack(wire.pack({'a': b'x'})) == {'a': b'x'}\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_pack_roundtrip_and_types():
    obj = {"s": "é", "b": b"\x00\xff", "f": 1.5, "nan": float("nan"), "i": -3, "l": [1, None, True]}
    out = wire.unpack(wire.pack(obj))
    assert out["s"] == "é" and out["b"] == b"\x00\xff" and out["l"] == [1, None, True]
    assert out["nan"] != out["nan"]
    assert isinstance(wire.pack({"m": memoryview(b"ab")}), bytes)


@pytest.mark.parametrize("data", [
    b"\xc1",                                   # never-used byte
    b"\x92\x01",                               # truncated array
    b"\x01\x02",                               # extra data
    b"\x81\x01\x02",                           # int map key
    b"\xa3\xff\xfe\xfd",                       # invalid UTF-8 str
    b"\xd6\xff\x00\x00\x00\x01",               # extension type (timestamp)
    b"\x91" * 5000 + b"\x00",                  # nesting too deep
    b"\xdd\xff\xff\xff\xff",                   # array claiming 4 G items
    b"\xc6\x7f\xff\xff\xff",                   # bin claiming 2 GB
    b"",
])
def test_unpack_rejects(data):
    with pytest.raises(WireError):
        wire.unpack(data)


def test_unpack_size_limit():
    big = wire.pack({"x": b"\0" * 100})
    with pytest.raises(WireError):
        wire.unpack(big, max_size=50)
    assert wire.unpack(big, max_size=None)["x"] == b"\0" * 100


@pytest.mark.parametrize("obj, code, rid", [
    ([1, 2], ErrorCode.BAD_REQUEST, None),
    ("get_info", ErrorCode.BAD_REQUEST, None),
    ({"service": "get_info", "args": {}}, ErrorCode.BAD_REQUEST, None),
    ({"id": -1, "service": "get_info", "args": {}}, ErrorCode.BAD_REQUEST, None),
    ({"id": True, "service": "get_info", "args": {}}, ErrorCode.BAD_REQUEST, None),
    ({"id": "7", "service": "get_info", "args": {}}, ErrorCode.BAD_REQUEST, None),
    ({"id": 7, "args": {}}, ErrorCode.BAD_REQUEST, 7),
    ({"id": 7, "service": 3, "args": {}}, ErrorCode.BAD_REQUEST, 7),
    ({"id": 7, "service": "", "args": {}}, ErrorCode.BAD_REQUEST, 7),
    ({"id": 7, "service": "get_info"}, ErrorCode.BAD_REQUEST, 7),
    ({"id": 7, "service": "get_info", "args": []}, ErrorCode.BAD_REQUEST, 7),
])
def test_parse_request_errors(obj, code, rid):
    with pytest.raises(RequestError) as e:
        wire.parse_request(wire.pack(obj))
    assert e.value.code == code and e.value.id == rid


def test_parse_request_ok_and_too_large():
    r = wire.parse_request(wire.pack({"id": 2**64 - 1, "service": "ping", "args": {"session": "x"}, "extra": 1}))
    assert r == wire.Request(2**64 - 1, "ping", {"session": "x"})
    big = wire.pack({"id": 1, "service": "x", "args": {"pad": b"\0" * (wire.SOFT_LIMIT + 1)}})
    with pytest.raises(RequestError) as e:
        wire.parse_request(big)
    assert e.value.code == ErrorCode.TOO_LARGE


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=64))
def test_parse_request_fuzz(data):
    try:
        wire.parse_request(data)
    except RequestError as e:
        assert e.code in (ErrorCode.BAD_REQUEST, ErrorCode.TOO_LARGE)


@settings(max_examples=100, deadline=None)
@given(st.recursive(st.none() | st.booleans() | st.integers(-2**63, 2**64 - 1) | st.text(max_size=8) | st.binary(max_size=8),
                    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=4), inner, max_size=4),
                    max_leaves=20))
def test_unpack_roundtrip_any(obj):
    assert wire.unpack(wire.pack(obj)) == obj


def test_replies():
    assert msgpack.unpackb(wire.ok_reply(3, {"a": 1})) == {"id": 3, "ok": True, "result": {"a": 1}}
    assert msgpack.unpackb(wire.error_reply(None, ErrorCode.TOO_LARGE, "big")) == {
        "id": None, "ok": False, "error": {"code": 8, "message": "big"}}


def test_arrays_are_little_endian():
    a = np.array([[1.0, -2.5], [np.inf, np.nan]], dtype=">f4")   # big-endian input
    b = wire.to_bin(a)
    assert b[:4] == np.float32(1.0).tobytes() if sys.byteorder == "little" else True
    assert b[:4] == b"\x00\x00\x80\x3f"
    back = wire.from_bin(b, wire.F32, (2, 2))
    assert back.shape == (2, 2) and back[0, 1] == -2.5 and np.isinf(back[1, 0]) and np.isnan(back[1, 1])
    assert wire.from_bin(wire.to_bin([1, -2], wire.I32), wire.I32).tolist() == [1, -2]
    with pytest.raises(WireError):
        wire.from_bin(b"\0" * 5, wire.F32)
    with pytest.raises(WireError):
        wire.from_bin(b"\0" * 8, wire.F32, (3,))


def test_topic_frames_roundtrip():
    body = wire.pack({"clock": wire.stamp(1_500_000_000)})
    frames = wire.topic_frames("/clock", "rosgraph_msgs/msg/Clock", 4, 1_500_000_000, body)
    assert frames[0] == b"/clock\0" and frames[2] is body
    name, env, b = wire.decode_topic(frames)
    assert name == "/clock" and env == {"type": "rosgraph_msgs/msg/Clock", "seq": 4, "stamp_ns": 1_500_000_000}
    assert b == {"clock": {"sec": 1, "nanosec": 500_000_000}}
    for bad in ([b"/clock", frames[1], body], frames[:2], [b"/c\0", b"\xc1", body], [b"/c\0", wire.pack([1]), body]):
        with pytest.raises(WireError):
            wire.decode_topic(bad)


@pytest.mark.parametrize("prefix, topic, covered", [
    (b"", "/epuck/ps1/value", True),
    (b"/epuck/", "/epuck/ps1/value", True),
    (b"/epuck/ps1/value\0", "/epuck/ps1/value", True),
    (b"/epuck/ps1/value\0", "/epuck/ps10/value", False),
    (b"/epuck/ps1", "/epuck/ps10/value", True),            # a prefix without NUL is a prefix
    (b"/scout/", "/epuck/ps1/value", False),
    (b"/epuck/ps1/value\0x", "/epuck/ps1/value", False),
])
def test_covers(prefix, topic, covered):
    assert wire.covers(prefix, wire.topic_frame(topic)) is covered


@pytest.mark.parametrize("ns, sec, nanosec", [(0, 0, 0), (32_000_000, 0, 32_000_000), (1_000_000_000, 1, 0),
                                              (123_456_789_012, 123, 456_789_012)])
def test_stamps(ns, sec, nanosec):
    assert wire.stamp(ns) == {"sec": sec, "nanosec": nanosec}
    assert wire.stamp_ns(wire.stamp(ns)) == ns
    assert wire.ms_to_ns(32) == 32_000_000
