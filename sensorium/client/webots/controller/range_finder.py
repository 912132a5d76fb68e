"""Webots' ``RangeFinder`` class: the generic shape of a listed device (every method answers Webots'
"no value" with one warning). Issue 23 replaces this file with the simulated range finder."""

from __future__ import annotations

import math

from .unsimulated import UnsimulatedDevice


class RangeFinder(UnsimulatedDevice):
    _KIND = "RangeFinder"
    _NO_VALUES = {"enable": None, "disable": None, "getSamplingPeriod": 0, "getRangeImage": None,
                  "getRangeImageArray": None, "getWidth": 0, "getHeight": 0, "getFov": math.nan,
                  "getMinRange": math.nan, "getMaxRange": math.nan, "saveImage": -1}
    _PROPERTIES = {"width": "getWidth", "height": "getHeight", "fov": "getFov", "sampling_period": "getSamplingPeriod"}
