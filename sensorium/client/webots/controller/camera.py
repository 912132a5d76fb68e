"""Webots' ``Camera`` class (and ``CameraRecognitionObject``)."""

from __future__ import annotations

from typing import Any

from sensorium.client import wb

from .device import Sensor


class CameraRecognitionObject:
    """One object a camera recognised (Webots' class; fields as ``WbCameraRecognitionObject``)."""

    __slots__ = ("id", "position", "orientation", "size", "position_on_image", "size_on_image",
                 "number_of_colors", "colors", "model")

    def __init__(self, data: dict):
        self.id = int(data.get("id", 0))
        self.position = [float(v) for v in data.get("position", ())]
        self.orientation = [float(v) for v in data.get("orientation", ())]
        self.size = [float(v) for v in data.get("size", ())]
        self.position_on_image = [int(v) for v in data.get("position_on_image", ())]
        self.size_on_image = [int(v) for v in data.get("size_on_image", ())]
        self.colors = [float(v) for v in data.get("colors", ())]
        self.number_of_colors = len(self.colors) // 3
        self.model = str(data.get("model", ""))

    def getId(self) -> int:
        return self.id

    def getPosition(self) -> list[float]:
        return self.position

    def getOrientation(self) -> list[float]:
        return self.orientation

    def getSize(self) -> list[float]:
        return self.size

    def getPositionOnImage(self) -> list[int]:
        return self.position_on_image

    def getSizeOnImage(self) -> list[int]:
        return self.size_on_image

    def getNumberOfColors(self) -> int:
        return self.number_of_colors

    def getColors(self) -> list[float]:
        return self.colors

    def getModel(self) -> str:
        return self.model

    def __repr__(self) -> str:
        return (f"CameraRecognitionObject(id={self.id}, model={self.model!r}, position={self.position}, "
                f"position_on_image={self.position_on_image}, size_on_image={self.size_on_image})")


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

    def setFov(self, f: float) -> None:
        wb.wb_camera_set_fov(self._tag, f)

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

    def setFocalDistance(self, d: float) -> None:
        wb.wb_camera_set_focal_distance(self._tag, d)

    def getNear(self) -> float:
        return wb.wb_camera_get_near(self._tag)

    # -- recognition
    def hasRecognition(self) -> bool:
        return wb.wb_camera_has_recognition(self._tag)

    def recognitionEnable(self, sampling_period: int) -> None:
        wb.wb_camera_recognition_enable(self._tag, sampling_period)

    def recognitionDisable(self) -> None:
        wb.wb_camera_recognition_disable(self._tag)

    def getRecognitionSamplingPeriod(self) -> int:
        return wb.wb_camera_recognition_get_sampling_period(self._tag)

    def getRecognitionNumberOfObjects(self) -> int:
        return wb.wb_camera_recognition_get_number_of_objects(self._tag)

    def getRecognitionObjects(self) -> list[CameraRecognitionObject]:
        objs = wb.recognition_objects(self._tag, "getRecognitionObjects")
        return [] if objs is None else [CameraRecognitionObject(o) for o in objs]

    def hasRecognitionSegmentation(self) -> bool:
        return wb.wb_camera_recognition_has_segmentation(self._tag)

    def enableRecognitionSegmentation(self) -> None:
        wb.wb_camera_recognition_enable_segmentation(self._tag)

    def disableRecognitionSegmentation(self) -> None:
        wb.wb_camera_recognition_disable_segmentation(self._tag)

    def isRecognitionSegmentationEnabled(self) -> bool:
        return wb.wb_camera_recognition_is_segmentation_enabled(self._tag)

    def getRecognitionSegmentationImage(self) -> bytes | None:
        return wb.segmentation_bytes(self._tag, "getRecognitionSegmentationImage")

    def getRecognitionSegmentationImageArray(self) -> list[list[list[int]]] | None:
        img = self.getRecognitionSegmentationImage()
        if img is None:
            return None
        w, h = self.getWidth(), self.getHeight()
        return [[[img[4 * (y * w + x) + 2], img[4 * (y * w + x) + 1], img[4 * (y * w + x)]] for y in range(h)]
                for x in range(w)]

    def saveRecognitionSegmentationImage(self, filename: str, quality: int) -> int:
        return wb.wb_camera_recognition_save_segmentation_image(self._tag, filename, quality)

    # Webots' properties
    image = property(getImage)
    segmentation_image = property(getRecognitionSegmentationImage)
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
