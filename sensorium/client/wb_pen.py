"""Webots' Pen functions (``wb_pen_*``) on Sensorium; :mod:`sensorium.client.wb` re-exports them.

The server simulates the pen (README "Textures and line following"): at every basic step while it
writes, it inks what its -z axis points at, and infra-red sensors read that ink. Both functions
are sent to the server at once (one round trip each; Webots' libController sends them with the
next step request): the next basic step paints with them either way, since a step never starts
while its controller's call is being answered.

As in Webots, ``color`` is 0xRRGGBB (bits above 24 are ignored) and ``density`` is clamped to
[0, 1]. Departure, on an error path: a NaN density is printed and ignored (Webots would paint
with it)."""

from __future__ import annotations

import math
import sys

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import DeviceState, current, integer, real

PEN = "Pen"

__all__ = ["PEN", "wb_pen_write", "wb_pen_set_ink_color"]


def _pen(tag: int, func: str) -> DeviceState | None:
    """The pen of ``tag``; None (after one warning per device) when the server only lists it."""
    dev = current().device(tag, PEN, func)
    if dev.desc.get("simulated", True) is False:
        if not dev._warned:
            dev._warned = True
            print(f"Warning: {func}(): this server does not simulate Pen {dev.name!r}: nothing is drawn.",
                  file=sys.stderr)
        return None
    return dev


def wb_pen_write(tag: int, write: bool) -> None:
    """Switch writing on (True) or off, from the next basic step."""
    dev = _pen(tag, "wb_pen_write")
    r = current()
    if dev is None or r.terminated:
        return
    r.rpc(dev, "write", {"value": bool(write)})
    dev.desc["write"] = bool(write)


def wb_pen_set_ink_color(tag: int, color: int, density: float) -> None:
    """The ink from the next basic step: ``color`` 0xRRGGBB, ``density`` 0 (transparent) to 1 (opaque)."""
    func = "wb_pen_set_ink_color"
    rgb = integer(color)
    if rgb is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): color must be an integer 0xRRGGBB, got {color!r}")
    amount = real(density)
    if amount is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): density must be a number, got {density!r}")
    color, density = rgb, amount
    dev = _pen(tag, func)
    r = current()
    if dev is None or r.terminated:
        return
    if math.isnan(density):
        print(f"Error: {func}() called with an invalid 'density' argument (NaN).", file=sys.stderr)
        return
    density = min(max(float(density), 0.0), 1.0)
    r.rpc(dev, "set_ink_color", {"color": color & 0xFFFFFF, "density": density})
