"""Webots' ``Radar`` and ``RadarTarget`` classes: the targets a radar sees (distance, received
power, radial speed, azimuth), read with the step."""

from __future__ import annotations

from dataclasses import dataclass

from sensorium.client import wb

from .device import Sensor


@dataclass
class RadarTarget:
    """One target: ``distance`` (m), ``received_power`` (dBm), ``speed`` (m/s, positive moving
    away), ``azimuth`` (rad, positive to the right, Webots' sign)."""

    distance: float
    received_power: float
    speed: float
    azimuth: float

    @property
    def receiver_power(self) -> float:
        """Webots' Python name of ``received_power``."""
        return self.received_power


class Radar(Sensor):
    _enable = staticmethod(wb.wb_radar_enable)
    _get_sampling_period = staticmethod(wb.wb_radar_get_sampling_period)

    def getNumberOfTargets(self) -> int:
        return wb.wb_radar_get_number_of_targets(self._tag)

    def getTargets(self) -> list[RadarTarget]:
        return [RadarTarget(*t) for t in wb.wb_radar_get_targets(self._tag)]

    def getMinRange(self) -> float:
        return wb.wb_radar_get_min_range(self._tag)

    def getMaxRange(self) -> float:
        return wb.wb_radar_get_max_range(self._tag)

    def getHorizontalFov(self) -> float:
        return wb.wb_radar_get_horizontal_fov(self._tag)

    def getVerticalFov(self) -> float:
        return wb.wb_radar_get_vertical_fov(self._tag)

    number_of_targets = property(getNumberOfTargets)
    targets = property(getTargets)
    min_range = property(getMinRange)
    max_range = property(getMaxRange)
    horizontal_fov = property(getHorizontalFov)
    vertical_fov = property(getVerticalFov)
