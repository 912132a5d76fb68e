"""Direct ROS 2 CDR serialisation of Sensorium's own message bodies (msgpack dicts as published).

The generic path (rosbags type store: body → nested dicts → dataclasses → ``serialize_cdr``) costs
~0.3 ms per message, too much inside the step loop of a Foxglove-ready recording. For the eight
types Sensorium publishes most this module writes the same XCDR1 little-endian bytes directly (header
``00 01 00 00``, every primitive aligned to its size counted from the end of that header, strings
as uint32 length including the NUL). ``tests/test_cdr.py`` checks it byte for byte against
rosbags' ``serialize_cdr`` on real messages of every type; :class:`~.export.CdrEncoder` falls back to
the generic path for any other type or any body this module cannot take.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

__all__ = ["FAST_TYPES", "encode"]

_HEAD = b"\x00\x01\x00\x00"
_I32_U32 = struct.Struct("<iI")
_U32 = struct.Struct("<I")
_F32 = struct.Struct("<f")
_F64 = struct.Struct("<d")


class _Writer:
    __slots__ = ("buf",)

    def __init__(self) -> None:
        self.buf = bytearray(_HEAD)

    def align(self, n: int) -> None:
        pad = -(len(self.buf) - 4) % n
        if pad:
            self.buf += b"\0" * pad

    def u8(self, v: int) -> None:
        self.buf.append(int(v) & 0xFF)

    def u32(self, v: int) -> None:
        self.align(4)
        self.buf += _U32.pack(int(v))

    def f32(self, *vs: float) -> None:
        self.align(4)
        for v in vs:
            self.buf += _F32.pack(float(v))

    def f64(self, *vs: float) -> None:
        self.align(8)
        for v in vs:
            self.buf += _F64.pack(float(v))

    def string(self, s: Any) -> None:
        b = s if isinstance(s, (bytes, bytearray)) else str(s if s is not None else "").encode()
        self.u32(len(b) + 1)
        self.buf += b
        self.buf.append(0)

    def blob(self, raw: bytes, item: int) -> None:
        """A sequence of ``item``-byte primitives given as little-endian bytes."""
        if len(raw) % item:
            raise ValueError(f"{len(raw)} bytes is not a whole number of {item}-byte items")
        self.u32(len(raw) // item)
        if raw:
            self.align(item)
            self.buf += raw

    def time(self, t: Any) -> None:
        t = t or {}
        self.align(4)
        self.buf += _I32_U32.pack(int(t.get("sec", 0)), int(t.get("nanosec", 0)))

    def header(self, h: Any) -> None:
        h = h or {}
        self.time(h.get("stamp"))
        self.string(h.get("frame_id", ""))


def _bytes(v: Any) -> bytes:
    if v is None:
        return b""
    if isinstance(v, (bytes, bytearray, memoryview)):
        return bytes(v)
    raise TypeError("expected bytes")


def _illuminance(w: _Writer, b: dict, distro: str) -> None:
    w.header(b.get("header"))
    w.f64(b.get("illuminance", 0.0), b.get("variance", 0.0))


def _range(w: _Writer, b: dict, distro: str) -> None:
    w.header(b.get("header"))
    w.u8(b.get("radiation_type", 0))
    w.f32(b.get("field_of_view", 0.0), b.get("min_range", 0.0), b.get("max_range", 0.0), b.get("range", 0.0))
    if distro != "humble":                      # sensor_msgs/Range gained `variance` after Humble
        w.f32(b.get("variance", 0.0))


def _laser_scan(w: _Writer, b: dict, distro: str) -> None:
    w.header(b.get("header"))
    w.f32(*(b.get(k, 0.0) for k in ("angle_min", "angle_max", "angle_increment", "time_increment", "scan_time",
                                     "range_min", "range_max")))
    w.blob(_bytes(b.get("ranges")), 4)
    w.blob(_bytes(b.get("intensities")), 4)


def _image(w: _Writer, b: dict, distro: str) -> None:
    w.header(b.get("header"))
    w.u32(b.get("height", 0))
    w.u32(b.get("width", 0))
    w.string(b.get("encoding", ""))
    w.u8(b.get("is_bigendian", 0))
    w.u32(b.get("step", 0))
    w.blob(_bytes(b.get("data")), 1)


def _pose_stamped(w: _Writer, b: dict, distro: str) -> None:
    w.header(b.get("header"))
    p = b["pose"]
    pos, q = p["position"], p["orientation"]
    w.f64(pos["x"], pos["y"], pos["z"], q["x"], q["y"], q["z"], q["w"])


def _clock(w: _Writer, b: dict, distro: str) -> None:
    w.time(b.get("clock"))


def _point_cloud2(w: _Writer, m: dict, distro: str) -> None:
    """From the dict of :func:`~.export.pointcloud2_from_body` (``data`` a uint8 numpy array)."""
    w.header(m.get("header"))
    w.u32(m["height"])
    w.u32(m["width"])
    fields = m["fields"]
    w.u32(len(fields))
    for f in fields:
        w.string(f["name"])
        w.u32(f["offset"])
        w.u8(f["datatype"])
        w.u32(f["count"])
    w.u8(bool(m["is_bigendian"]))
    w.u32(m["point_step"])
    w.u32(m["row_step"])
    w.blob(m["data"].tobytes(), 1)
    w.u8(bool(m["is_dense"]))


def _battery_state(w: _Writer, b: dict, distro: str) -> None:
    w.header(b.get("header"))
    w.f32(*(b.get(k, 0.0) for k in ("voltage", "temperature", "current", "charge", "capacity", "design_capacity",
                                     "percentage")))
    w.u8(b.get("power_supply_status", 0))
    w.u8(b.get("power_supply_health", 0))
    w.u8(b.get("power_supply_technology", 0))
    w.u8(bool(b.get("present", False)))
    w.blob(_bytes(b.get("cell_voltage")), 4)
    w.blob(_bytes(b.get("cell_temperature")), 4)
    w.string(b.get("location", ""))
    w.string(b.get("serial_number", ""))


FAST_TYPES: dict[str, Callable[[_Writer, dict, str], None]] = {
    "sensor_msgs/msg/Illuminance": _illuminance,
    "sensor_msgs/msg/Range": _range,
    "sensor_msgs/msg/LaserScan": _laser_scan,
    "sensor_msgs/msg/Image": _image,
    "geometry_msgs/msg/PoseStamped": _pose_stamped,
    "rosgraph_msgs/msg/Clock": _clock,
    "sensor_msgs/msg/PointCloud2": _point_cloud2,
    "sensor_msgs/msg/BatteryState": _battery_state,
}


def encode(typename: str, msg: dict, distro: str) -> bytes:
    """CDR bytes of ``msg`` (a Sensorium body; for PointCloud2 the converted dict) as ``typename``.
    Raises ``KeyError`` for a type without a direct encoder, ``TypeError``/``ValueError``/
    ``OverflowError``/``struct.error`` for a body it cannot take (callers fall back)."""
    fn = FAST_TYPES[typename]
    w = _Writer()
    fn(w, msg, distro)
    return bytes(w.buf)
