"""Webots' ``RangeFinder`` class (a depth camera)."""

from __future__ import annotations

from typing import Any

from sensorium.client import arrays, wb

from .device import Sensor


class RangeFinder(Sensor):
    _enable = staticmethod(wb.wb_range_finder_enable)
    _get_sampling_period = staticmethod(wb.wb_range_finder_get_sampling_period)

    def getFov(self) -> float:
        return wb.wb_range_finder_get_fov(self._tag)

    def getWidth(self) -> int:
        return wb.wb_range_finder_get_width(self._tag)

    def getHeight(self) -> int:
        return wb.wb_range_finder_get_height(self._tag)

    def getMinRange(self) -> float:
        return wb.wb_range_finder_get_min_range(self._tag)

    def getMaxRange(self) -> float:
        return wb.wb_range_finder_get_max_range(self._tag)

    def getRangeImage(self, data_type: str = "list") -> list[float] | bytes:
        """The ranges row by row (top row first, left to right): a list of floats, or with
        ``data_type='buffer'`` the raw little-endian float32 bytes (``numpy.frombuffer`` them)."""
        buf = wb.range_finder_bytes(self._tag, "getRangeImage")
        if data_type == "buffer":
            return buf
        if data_type != "list":
            raise ValueError(f"data_type must be 'list' or 'buffer', got {data_type!r}")
        return arrays.float32_list(buf)

    def getRangeImageArray(self) -> list[list[float]]:
        """The range image as ``[row][column]`` lists (Webots' ``height`` lists of ``width``)."""
        flat = arrays.float32_list(wb.range_finder_bytes(self._tag, "getRangeImageArray"))
        w = self.getWidth()
        return [flat[i:i + w] for i in range(0, len(flat), w)]

    @staticmethod
    def rangeImageGetDepth(image: Any, width: int, x: int, y: int) -> float:
        return wb.wb_range_finder_image_get_depth(image, width, x, y)

    def saveImage(self, filename: str, quality: int) -> int:
        return wb.wb_range_finder_save_image(self._tag, filename, quality)

    @property
    def fov(self) -> float:
        return self.getFov()

    @property
    def width(self) -> int:
        return self.getWidth()

    @property
    def height(self) -> int:
        return self.getHeight()

    @property
    def min_range(self) -> float:
        return self.getMinRange()

    @property
    def max_range(self) -> float:
        return self.getMaxRange()

    @property
    def range_image(self) -> Any:
        return wb.wb_range_finder_get_range_image(self._tag)
