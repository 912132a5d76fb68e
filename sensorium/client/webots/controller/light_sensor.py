"""Webots' ``LightSensor`` class."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class LightSensor(Sensor):
    _enable = staticmethod(wb.wb_light_sensor_enable)
    _get_sampling_period = staticmethod(wb.wb_light_sensor_get_sampling_period)

    def getValue(self) -> float:
        return wb.wb_light_sensor_get_value(self._tag)

    def getLookupTable(self) -> list[float]:
        return wb.wb_light_sensor_get_lookup_table(self._tag)

    @property
    def value(self) -> float:
        return wb.wb_light_sensor_get_value(self._tag)

    @property
    def lookup_table(self) -> list[float]:
        return self.getLookupTable()
