"""Webots' ``Pen`` class: ``write(True/False)`` and ``setInkColor(0xRRGGBB, density)``; the server
inks what the pen points at every basic step while it writes (infra-red sensors see the ink)."""

from __future__ import annotations

from sensorium.client import wb_pen

from .device import Device


class Pen(Device):
    def write(self, write: bool) -> None:
        wb_pen.wb_pen_write(self._tag, write)

    def setInkColor(self, color: int, density: float) -> None:  # noqa: N802 - Webots' name
        wb_pen.wb_pen_set_ink_color(self._tag, color, density)
