"""Webots' Radar functions (``wb_radar_*``) on Sensorium; :mod:`sensorium.client.wb` re-exports them.

The targets arrive with the step reply at the radar's sampling period and are read locally (none
before the first value, the last ones kept after a disable); the range and field-of-view values are
the radar's world fields, from its ``attach`` description (Webots sends them once, at start)."""

from __future__ import annotations

import math

from sensorium.client.wb_robot import DeviceState, answers, current, sensor_enable, sensor_period, sensor_reading

RADAR = "Radar"

__all__ = ["RADAR", "wb_radar_disable", "wb_radar_enable", "wb_radar_get_horizontal_fov", "wb_radar_get_max_range",
           "wb_radar_get_min_range", "wb_radar_get_number_of_targets", "wb_radar_get_sampling_period",
           "wb_radar_get_targets", "wb_radar_get_vertical_fov"]


def _field(tag: int, key: str, func: str) -> float:
    dev: DeviceState = current().device(tag, RADAR, func)
    return float(dev.desc.get(key, math.nan))


@answers(None)
def wb_radar_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, RADAR, sampling_period, "wb_radar_enable")


@answers(None)
def wb_radar_disable(tag: int) -> None:
    sensor_enable(tag, RADAR, 0, "wb_radar_disable")


@answers(0)
def wb_radar_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, RADAR, "wb_radar_get_sampling_period")


@answers(0)
def wb_radar_get_number_of_targets(tag: int) -> int:
    """How many targets the latest measurement saw (0 before the first)."""
    targets = sensor_reading(tag, RADAR, "wb_radar_get_number_of_targets", "wb_radar_enable").targets
    return len(targets) // 4 if targets else 0


@answers([])
def wb_radar_get_targets(tag: int) -> list[tuple[float, float, float, float]]:
    """The latest targets, each (distance m, received power dBm, radial speed m/s, azimuth rad:
    Webots' sign, positive to the right); a new list."""
    flat = sensor_reading(tag, RADAR, "wb_radar_get_targets", "wb_radar_enable").targets or []
    return [(flat[i], flat[i + 1], flat[i + 2], flat[i + 3]) for i in range(0, len(flat) - 3, 4)]


@answers(math.nan)
def wb_radar_get_min_range(tag: int) -> float:
    return _field(tag, "min_range", "wb_radar_get_min_range")


@answers(math.nan)
def wb_radar_get_max_range(tag: int) -> float:
    return _field(tag, "max_range", "wb_radar_get_max_range")


@answers(math.nan)
def wb_radar_get_horizontal_fov(tag: int) -> float:
    return _field(tag, "horizontal_fov", "wb_radar_get_horizontal_fov")


@answers(math.nan)
def wb_radar_get_vertical_fov(tag: int) -> float:
    return _field(tag, "vertical_fov", "wb_radar_get_vertical_fov")
