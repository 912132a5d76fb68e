"""Webots' ``GPS`` class: position, speed and speed vector with the step (NaN before the first value)."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class GPS(Sensor):
    LOCAL = wb.WB_GPS_LOCAL_COORDINATE
    WGS84 = wb.WB_GPS_WGS84_COORDINATE

    _enable = staticmethod(wb.wb_gps_enable)
    _get_sampling_period = staticmethod(wb.wb_gps_get_sampling_period)

    def getValues(self) -> list[float]:
        return wb.wb_gps_get_values(self._tag)

    def getSpeed(self) -> float:
        return wb.wb_gps_get_speed(self._tag)

    def getSpeedVector(self) -> list[float]:
        return wb.wb_gps_get_speed_vector(self._tag)

    def getCoordinateSystem(self) -> int:
        return wb.wb_gps_get_coordinate_system(self._tag)

    @staticmethod
    def convertToDegreesMinutesSeconds(decimalDegrees: float) -> str:  # noqa: N803 - Webots' name
        return wb.wb_gps_convert_to_degrees_minutes_seconds(decimalDegrees)

    value = property(getValues)
    speed = property(getSpeed)
    speed_vector = property(getSpeedVector)
    coordinate_system = property(getCoordinateSystem)
