"""Webots' ``DistanceSensor`` class."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class DistanceSensor(Sensor):
    GENERIC = wb.WB_DISTANCE_SENSOR_GENERIC
    INFRA_RED = wb.WB_DISTANCE_SENSOR_INFRA_RED
    SONAR = wb.WB_DISTANCE_SENSOR_SONAR
    LASER = wb.WB_DISTANCE_SENSOR_LASER

    _enable = staticmethod(wb.wb_distance_sensor_enable)
    _get_sampling_period = staticmethod(wb.wb_distance_sensor_get_sampling_period)

    def getValue(self) -> float:
        return wb.wb_distance_sensor_get_value(self._tag)

    def getMinValue(self) -> float:
        return wb.wb_distance_sensor_get_min_value(self._tag)

    def getMaxValue(self) -> float:
        return wb.wb_distance_sensor_get_max_value(self._tag)

    def getAperture(self) -> float:
        return wb.wb_distance_sensor_get_aperture(self._tag)

    def getType(self) -> int:
        return wb.wb_distance_sensor_get_type(self._tag)

    def getLookupTable(self) -> list[float]:
        return wb.wb_distance_sensor_get_lookup_table(self._tag)

    @property
    def value(self) -> float:
        return self.getValue()

    @property
    def min_value(self) -> float:
        return self.getMinValue()

    @property
    def max_value(self) -> float:
        return self.getMaxValue()

    @property
    def aperture(self) -> float:
        return self.getAperture()

    @property
    def type(self) -> int:
        return self.getType()

    @property
    def lookup_table(self) -> list[float]:
        return self.getLookupTable()
