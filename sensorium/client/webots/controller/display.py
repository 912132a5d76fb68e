"""Webots' ``Display`` class (listed, not simulated: a headless server draws nothing)."""

from __future__ import annotations

from .unsimulated import UnsimulatedDevice


class Display(UnsimulatedDevice):
    RGB = 3
    RGBA = 4
    ARGB = 5
    BGRA = 6
    ABGR = 7
    _KIND = "Display"
    _NO_VALUES = {"getWidth": 0, "getHeight": 0, "setColor": None, "setAlpha": None, "setOpacity": None,
                  "setFont": None, "attachCamera": None, "detachCamera": None, "drawPixel": None, "drawLine": None,
                  "drawRectangle": None, "drawOval": None, "drawPolygon": None, "drawText": None,
                  "fillRectangle": None, "fillOval": None, "fillPolygon": None, "imageNew": None,
                  "imageLoad": None, "imageCopy": None, "imagePaste": None, "imageSave": None, "imageDelete": None}
    _PROPERTIES = {"width": "getWidth", "height": "getHeight"}
