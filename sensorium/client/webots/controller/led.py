"""Webots' ``LED`` class: ``set(0)`` off, ``set(i)`` colour ``i`` of its list (a gradual LED
takes 0xRRGGBB). Sent to the server at once; sensors do not see its light."""

from __future__ import annotations

from sensorium.client import wb

from .device import Device


class LED(Device):
    def set(self, v: int) -> None:
        wb.wb_led_set(self._tag, v)

    def get(self) -> int:
        return wb.wb_led_get(self._tag)

    value = property(get, set)
