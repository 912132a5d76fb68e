"""Webots' ``Gyro`` class: the angular velocity (rad/s) in the device frame, through its lookup table."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class Gyro(Sensor):
    _enable = staticmethod(wb.wb_gyro_enable)
    _get_sampling_period = staticmethod(wb.wb_gyro_get_sampling_period)

    def getValues(self) -> list[float]:
        return wb.wb_gyro_get_values(self._tag)

    def getLookupTable(self) -> list[float]:
        return wb.wb_gyro_get_lookup_table(self._tag)

    value = property(getValues)
    lookup_table = property(getLookupTable)
