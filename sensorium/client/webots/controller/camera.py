"""Webots' ``Camera`` class (and ``CameraRecognitionObject``)."""

from __future__ import annotations

from typing import Any

from sensorium.client import wb

from .device import Sensor


class Camera(Sensor):
    _enable = staticmethod(wb.wb_camera_enable)
    _get_sampling_period = staticmethod(wb.wb_camera_get_sampling_period)

    # -- the image
    def getImage(self) -> bytes | None:
        """BGRA bytes (4 a pixel, row by row from the top left); ``None`` while disabled."""
        return wb.camera_bytes(self._tag, "getImage")

    def getImageArray(self) -> list[list[list[int]]] | None:
        """``image[x][y] = [red, green, blue]`` (Webots' documented layout: column first)."""
        img = self.getImage()
        if img is None:
            return None
        w, h = self.getWidth(), self.getHeight()
        return [[[img[4 * (y * w + x) + 2], img[4 * (y * w + x) + 1], img[4 * (y * w + x)]] for y in range(h)]
                for x in range(w)]

    @staticmethod
    def imageGetRed(image: Any, width: int, x: int, y: int) -> int:
        return wb.wb_camera_image_get_red(image, width, x, y)

    @staticmethod
    def imageGetGreen(image: Any, width: int, x: int, y: int) -> int:
        return wb.wb_camera_image_get_green(image, width, x, y)

    @staticmethod
    def imageGetBlue(image: Any, width: int, x: int, y: int) -> int:
        return wb.wb_camera_image_get_blue(image, width, x, y)

    @staticmethod
    def imageGetGray(image: Any, width: int, x: int, y: int) -> float:
        """``(red + green + blue) / 3`` (Webots' Python returns the true quotient)."""
        i = 4 * (y * width + x)
        return (image[i + 2] + image[i + 1] + image[i]) / 3

    imageGetGrey = imageGetGray

    def saveImage(self, filename: str, quality: int) -> int:
        return wb.wb_camera_save_image(self._tag, filename, quality)

    # -- constants and settings
    def getWidth(self) -> int:
        return wb.wb_camera_get_width(self._tag)

    def getHeight(self) -> int:
        return wb.wb_camera_get_height(self._tag)

    def getFov(self) -> float:
        return wb.wb_camera_get_fov(self._tag)

    def getMinFov(self) -> float:
        return wb.wb_camera_get_min_fov(self._tag)

    def getMaxFov(self) -> float:
        return wb.wb_camera_get_max_fov(self._tag)

    def setFov(self, fov: float) -> None:
        wb.wb_camera_set_fov(self._tag, fov)

    def getExposure(self) -> float:
        return wb.wb_camera_get_exposure(self._tag)

    def setExposure(self, exposure: float) -> None:
        wb.wb_camera_set_exposure(self._tag, exposure)

    def getFocalLength(self) -> float:
        return wb.wb_camera_get_focal_length(self._tag)

    def getFocalDistance(self) -> float:
        return wb.wb_camera_get_focal_distance(self._tag)

    def getMinFocalDistance(self) -> float:
        return wb.wb_camera_get_min_focal_distance(self._tag)

    def getMaxFocalDistance(self) -> float:
        return wb.wb_camera_get_max_focal_distance(self._tag)

    def setFocalDistance(self, focal_distance: float) -> None:
        wb.wb_camera_set_focal_distance(self._tag, focal_distance)

    def getNear(self) -> float:
        return wb.wb_camera_get_near(self._tag)

    # Webots' properties
    image = property(getImage)
    width = property(getWidth)
    height = property(getHeight)
    fov = property(getFov, setFov)
    min_fov = property(getMinFov)
    max_fov = property(getMaxFov)
    exposure = property(getExposure, setExposure)
    focal_length = property(getFocalLength)
    focal_distance = property(getFocalDistance, setFocalDistance)
    min_focal_distance = property(getMinFocalDistance)
    max_focal_distance = property(getMaxFocalDistance)
    near = property(getNear)
