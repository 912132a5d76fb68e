"""Webots' ``Skin`` class (listed, not simulated: no skeleton is animated here)."""

from __future__ import annotations

from .unsimulated import UnsimulatedDevice


class Skin(UnsimulatedDevice):
    _KIND = "Skin"
    _NO_VALUES = {"getBoneCount": 0, "getBoneName": "", "getBoneOrientation": None, "getBonePosition": None,
                  "setBoneOrientation": None, "setBonePosition": None}
    _PROPERTIES = {"bone_count": "getBoneCount"}
    _PARAMS = {"getBoneName": "index", "getBoneOrientation": "index, absolute", "getBonePosition": "index, absolute",
               "setBoneOrientation": "index, orientation, absolute", "setBonePosition": "index, position, absolute"}
