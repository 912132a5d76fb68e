"""Webots' image devices: ``wb_range_finder_*`` (and ``wb_camera_*``), readings cached per step.

The images arrive with the step reply (PROTOCOL.md §3.6) as raw bytes; constants (size, field of
view, ranges) come from the ``attach`` description. As in Webots' library, reading the image of a
disabled device prints Webots' error and still returns the last image (zeros before the first).
"""

from __future__ import annotations

import math
from typing import Any

from sensorium.client import arrays, images
from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import DeviceState, current

RANGE_FINDER = "RangeFinder"

__all__ = ["RANGE_FINDER", "wb_range_finder_enable", "wb_range_finder_disable", "wb_range_finder_get_sampling_period",
           "wb_range_finder_get_range_image", "wb_range_finder_image_get_depth", "wb_range_finder_get_width",
           "wb_range_finder_get_height", "wb_range_finder_get_fov", "wb_range_finder_get_min_range",
           "wb_range_finder_get_max_range", "wb_range_finder_save_image", "range_finder_bytes"]


def _desc(dev: DeviceState, key: str, func: str) -> Any:
    try:
        return dev.desc[key]
    except KeyError:
        raise SensoriumError(ErrorCode.BAD_REPLY, f"{func}(): the server described {dev.name!r} without {key!r}") from None


# ---------------------------------------------------------------------- range finder

def _rf(tag: int, func: str) -> DeviceState:
    return current().device(tag, RANGE_FINDER, func)


def wb_range_finder_enable(tag: int, sampling_period: int) -> None:
    r = current()
    r.enable(_rf(tag, "wb_range_finder_enable"), sampling_period, "wb_range_finder_enable")


def wb_range_finder_disable(tag: int) -> None:
    r = current()
    r.enable(_rf(tag, "wb_range_finder_disable"), 0, "wb_range_finder_disable")


def wb_range_finder_get_sampling_period(tag: int) -> int:
    return _rf(tag, "wb_range_finder_get_sampling_period").sampling_period


def wb_range_finder_get_width(tag: int) -> int:
    return int(_desc(_rf(tag, "wb_range_finder_get_width"), "width", "wb_range_finder_get_width"))


def wb_range_finder_get_height(tag: int) -> int:
    return int(_desc(_rf(tag, "wb_range_finder_get_height"), "height", "wb_range_finder_get_height"))


def wb_range_finder_get_fov(tag: int) -> float:
    return float(_desc(_rf(tag, "wb_range_finder_get_fov"), "fov", "wb_range_finder_get_fov"))


def wb_range_finder_get_min_range(tag: int) -> float:
    return float(_desc(_rf(tag, "wb_range_finder_get_min_range"), "minRange", "wb_range_finder_get_min_range"))


def wb_range_finder_get_max_range(tag: int) -> float:
    return float(_desc(_rf(tag, "wb_range_finder_get_max_range"), "maxRange", "wb_range_finder_get_max_range"))


def range_finder_bytes(tag: int, func: str = "wb_range_finder_get_range_image") -> bytes:
    """The raw little-endian float32 image (``height`` rows of ``width``), zeros before the first
    image; a disabled device prints Webots' error once and still returns it (Webots)."""
    r = current()
    dev = _rf(tag, func)
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, "wb_range_finder_enable")
    if dev.range_bytes is None:
        return bytes(4 * int(dev.desc.get("width", 0)) * int(dev.desc.get("height", 0)))
    return dev.range_bytes


def wb_range_finder_get_range_image(tag: int) -> Any:
    """The latest range image, ``height × width`` float32 values row by row (top row first, left to
    right): a read-only numpy array, or ``array('f')`` without numpy; ``+inf`` where nothing valid
    is seen (Webots)."""
    buf = range_finder_bytes(tag)
    dev = current().devices[tag - 1]
    if dev._range is None:           # decoded once per new image (the step reply resets it)
        dev._range = arrays.float32s(buf)
    return dev._range


def wb_range_finder_image_get_depth(image: Any, width: int, x: int, y: int) -> float:
    """Webots' macro: ``image[y·width + x]``."""
    return float(image[y * width + x])


def depth_gray(buf: bytes, near: float, max_range: float) -> bytes:
    """Webots' range-finder PNG/JPEG: grey ``(unsigned char)(255·clamp((v − near)/maxRange, 0, 1))``
    (``near`` = the device's minRange, as Webots' library has it), as RGB bytes."""
    out = bytearray()
    for v in arrays.float32_list(buf):
        g = (v - near) / max_range
        g = 1.0 if not g <= 1.0 else (0.0 if g < 0.0 else g)     # NaN and inf: 1 (as the C comparisons)
        out += bytes((int(g * 255.0),)) * 3
    return bytes(out)


def wb_range_finder_save_image(tag: int, filename: str, quality: int) -> int:
    """PNG (or JPEG with Pillow) of the latest range image in Webots' grey scale; 0 or -1."""
    func = "wb_range_finder_save_image"
    dev = _rf(tag, func)
    buf = range_finder_bytes(tag, func)
    w, h = int(dev.desc.get("width", 0)), int(dev.desc.get("height", 0))
    max_range = float(dev.desc.get("maxRange", math.inf))
    return images.save_rgb(func, filename, quality, depth_gray(buf, float(dev.desc.get("minRange", 0.0)), max_range), w, h)
