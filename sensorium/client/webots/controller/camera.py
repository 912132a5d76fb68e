"""Webots' ``Camera`` and ``CameraRecognitionObject`` classes: the generic shape of a listed device
(every method answers Webots' "no value" with one warning). Issue 23 replaces this file with the
simulated camera."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .unsimulated import UnsimulatedDevice


@dataclass
class CameraRecognitionObject:
    id: int = 0
    position: list[float] = field(default_factory=lambda: [math.nan] * 3)
    orientation: list[float] = field(default_factory=lambda: [math.nan] * 4)
    size: list[float] = field(default_factory=lambda: [math.nan] * 2)
    position_on_image: list[int] = field(default_factory=lambda: [0, 0])
    size_on_image: list[int] = field(default_factory=lambda: [0, 0])
    number_of_colors: int = 0
    colors: list[float] = field(default_factory=list)
    model: str = ""


class Camera(UnsimulatedDevice):
    _KIND = "Camera"
    _NO_VALUES = {"enable": None, "disable": None, "getSamplingPeriod": 0, "getImage": None, "getImageArray": None,
                  "getWidth": 0, "getHeight": 0, "getFov": math.nan, "getMinFov": math.nan, "getMaxFov": math.nan,
                  "setFov": None, "getExposure": math.nan, "setExposure": None, "getFocalLength": math.nan,
                  "getFocalDistance": math.nan, "getMinFocalDistance": math.nan, "getMaxFocalDistance": math.nan,
                  "setFocalDistance": None, "getNear": math.nan, "saveImage": -1, "hasRecognition": False,
                  "recognitionEnable": None, "recognitionDisable": None, "getRecognitionSamplingPeriod": 0,
                  "getRecognitionNumberOfObjects": 0, "getRecognitionObjects": [], "hasRecognitionSegmentation": False,
                  "enableRecognitionSegmentation": None, "disableRecognitionSegmentation": None,
                  "isRecognitionSegmentationEnabled": False, "getRecognitionSegmentationImage": None,
                  "saveRecognitionSegmentationImage": -1}
    _PROPERTIES = {"width": "getWidth", "height": "getHeight", "fov": "getFov", "sampling_period": "getSamplingPeriod"}
