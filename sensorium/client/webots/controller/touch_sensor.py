"""Webots' ``TouchSensor`` class: a bumper reads 1 while its robot pushes against something (kinematic
contact); force sensors read NaN (no physics)."""

from __future__ import annotations

from typing import Any

from sensorium.client import wb

from .device import Sensor


class TouchSensor(Sensor):
    BUMPER = wb.WB_TOUCH_SENSOR_BUMPER
    FORCE = wb.WB_TOUCH_SENSOR_FORCE
    FORCE3D = wb.WB_TOUCH_SENSOR_FORCE3D

    _enable = staticmethod(wb.wb_touch_sensor_enable)
    _get_sampling_period = staticmethod(wb.wb_touch_sensor_get_sampling_period)

    def getValue(self) -> float:
        return wb.wb_touch_sensor_get_value(self._tag)

    def getValues(self) -> Any:
        return wb.wb_touch_sensor_get_values(self._tag)

    def getLookupTable(self) -> list[float]:
        return wb.wb_touch_sensor_get_lookup_table(self._tag)

    def getType(self) -> int:
        return wb.wb_touch_sensor_get_type(self._tag)

    value = property(getValue)
    values = property(getValues)
    lookup_table = property(getLookupTable)
    type = property(getType)
