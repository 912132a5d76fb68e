"""Typed arrays off the wire (PROTOCOL.md §2): little-endian raw bytes → numpy when it is
installed, else ``array.array`` / tuples. numpy is imported on first use, never at import time.

Set ``SENSORIUM_NO_NUMPY=1`` to force the pure-Python forms.
"""

from __future__ import annotations

import array
import os
import struct
import sys
from typing import Any

POINT_SIZE = 20                          # x, y, z: <f4, layer_id: <i4, time: <f4
POINT_FORMAT = "<fffif"
POINT_FIELDS = ("x", "y", "z", "layer_id", "time")

_numpy: Any = None
_numpy_checked = False


def numpy_module() -> Any:
    """numpy, or ``None`` when it is not installed (or disabled by ``SENSORIUM_NO_NUMPY``)."""
    global _numpy, _numpy_checked
    if not _numpy_checked:
        _numpy_checked = True
        if os.environ.get("SENSORIUM_NO_NUMPY", "") not in ("", "0"):
            _numpy = None
        else:
            try:
                import numpy as found
            except ImportError:
                found = None  # type: ignore[assignment]
            _numpy = found
    return _numpy


def point_dtype(np: Any) -> Any:
    return np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("layer_id", "<i4"), ("time", "<f4")])


def float32s(buf: bytes, shape: tuple[int, ...] | None = None) -> Any:
    """A ``<f4`` buffer as a read-only numpy array (reshaped to ``shape``), else ``array('f')``."""
    np = numpy_module()
    if np is not None:
        a = np.frombuffer(buf, dtype="<f4")
        if shape is not None:
            a = a.reshape(shape)
        a.flags.writeable = False
        return a
    a = array.array("f")
    a.frombytes(bytes(buf))
    if sys.byteorder == "big":
        a.byteswap()
    return a


def float32_list(buf: bytes) -> list[float]:
    """A ``<f4`` buffer as a list of Python floats (exactly the float32 values)."""
    return [v for (v,) in struct.iter_unpack("<f", buf)]


def points(buf: bytes) -> Any:
    """Point-cloud records: a read-only numpy structured array, else a list of 5-tuples."""
    np = numpy_module()
    if np is not None:
        a = np.frombuffer(buf, dtype=point_dtype(np))
        a.flags.writeable = False
        return a
    return list(struct.iter_unpack(POINT_FORMAT, buf))


def point_tuples(buf: bytes) -> list[tuple[float, float, float, int, float]]:
    return list(struct.iter_unpack(POINT_FORMAT, buf))
