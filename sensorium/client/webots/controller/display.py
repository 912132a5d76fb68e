"""Webots' ``Display`` class (listed, not simulated: a headless server draws nothing, but the
Display's size is the world's and image references are usable; see ``wb_unsimulated``)."""

from __future__ import annotations

from typing import Any

from sensorium.client import wb

from .unsimulated import UnsimulatedDevice


class Display(UnsimulatedDevice):
    RGB = 3
    RGBA = 4
    ARGB = 5
    BGRA = 6
    ABGR = 7
    _KIND = "Display"
    _NO_VALUES = {"setColor": None, "setAlpha": None, "setOpacity": None,
                  "setFont": None, "attachCamera": None, "detachCamera": None, "drawPixel": None, "drawLine": None,
                  "drawRectangle": None, "drawOval": None, "drawPolygon": None, "drawText": None,
                  "fillRectangle": None, "fillOval": None, "fillPolygon": None,
                  "imageLoad": None, "imagePaste": None, "imageDelete": None}
    _PROPERTIES = {"width": "getWidth", "height": "getHeight"}

    def getWidth(self) -> int:
        return wb.wb_display_get_width(self._tag)

    def getHeight(self) -> int:
        return wb.wb_display_get_height(self._tag)

    def imageNew(self, data: Any, format: int, width: int, height: int) -> int | None:
        return wb.wb_display_image_new(self._tag, int(width), int(height), data, format)

    def imageCopy(self, x: int, y: int, width: int, height: int) -> int | None:
        return wb.wb_display_image_copy(self._tag, int(x), int(y), int(width), int(height))

    def imageSave(self, image: Any, filename: str) -> None:
        wb.wb_display_image_save(self._tag, image, filename)
