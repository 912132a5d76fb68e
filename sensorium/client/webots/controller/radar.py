"""Webots' ``Radar`` and ``RadarTarget`` classes (listed, not simulated: no target is ever seen)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .unsimulated import UnsimulatedDevice


@dataclass
class RadarTarget:
    distance: float
    received_power: float
    speed: float
    azimuth: float


class Radar(UnsimulatedDevice):
    _KIND = "Radar"
    _NO_VALUES = {"enable": None, "disable": None, "getSamplingPeriod": 0, "getNumberOfTargets": 0,
                  "getTargets": [], "getMinRange": math.nan, "getMaxRange": math.nan,
                  "getHorizontalFov": math.nan, "getVerticalFov": math.nan}
    _PROPERTIES = {"sampling_period": "getSamplingPeriod", "number_of_targets": "getNumberOfTargets",
                   "min_range": "getMinRange", "max_range": "getMaxRange", "horizontal_fov": "getHorizontalFov",
                   "vertical_fov": "getVerticalFov"}

    def __init__(self, name: str | int, sampling_period: int | None = None):
        super().__init__(name)
        if sampling_period is not None:
            self.enable(sampling_period)  # type: ignore[attr-defined]
