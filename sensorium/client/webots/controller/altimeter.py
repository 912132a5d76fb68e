"""Webots' ``Altimeter`` class: the device's height along the world's up axis."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class Altimeter(Sensor):
    _enable = staticmethod(wb.wb_altimeter_enable)
    _get_sampling_period = staticmethod(wb.wb_altimeter_get_sampling_period)

    def getValue(self) -> float:
        return wb.wb_altimeter_get_value(self._tag)

    value = property(getValue)
