"""Webots' ``Lidar`` and ``LidarPoint`` classes."""

from __future__ import annotations

import struct

from sensorium.client import arrays, wb

from .device import Sensor


class LidarPoint:
    """One point of a lidar point cloud (lidar frame, metres; ``time`` in seconds)."""

    __slots__ = ("x", "y", "z", "layer_id", "time")

    def __init__(self, x: float, y: float, z: float, layer_id: int, time: float):
        self.x = x
        self.y = y
        self.z = z
        self.layer_id = layer_id
        self.time = time

    @classmethod
    def from_bytes(cls, data: bytes, index: int = 0) -> LidarPoint:
        return cls(*struct.unpack_from(arrays.POINT_FORMAT, data, index * arrays.POINT_SIZE))

    @property
    def layer(self) -> int:
        """Webots' Python spelling of ``layer_id``."""
        return self.layer_id

    def __repr__(self) -> str:
        return f"LidarPoint(x={self.x}, y={self.y}, z={self.z}, layer_id={self.layer_id}, time={self.time})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, LidarPoint):
            return NotImplemented
        return all(getattr(self, k) == getattr(other, k) for k in self.__slots__)


def _points(buf: bytes | None, data_type: str) -> list[LidarPoint] | bytes:
    if data_type == "buffer":
        return b"" if buf is None else buf
    if data_type != "list":
        raise ValueError(f"data_type must be 'list' or 'buffer', got {data_type!r}")
    return [] if buf is None else [LidarPoint(*t) for t in arrays.point_tuples(buf)]


def _floats(buf: bytes | None, data_type: str) -> list[float] | bytes | None:
    if data_type == "buffer":
        return buf
    if data_type != "list":
        raise ValueError(f"data_type must be 'list' or 'buffer', got {data_type!r}")
    return None if buf is None else arrays.float32_list(buf)


class Lidar(Sensor):
    _enable = staticmethod(wb.wb_lidar_enable)
    _get_sampling_period = staticmethod(wb.wb_lidar_get_sampling_period)

    # -- images
    def getRangeImage(self, data_type: str = "list") -> list[float] | bytes | None:
        """Ranges left to right, first layer to last: a list of floats, or with
        ``data_type='buffer'`` the raw little-endian float32 bytes."""
        return _floats(wb.lidar_range_bytes(self._tag, None, "getRangeImage"), data_type)

    def getRangeImageArray(self) -> list[list[float]]:
        """The range image as ``[layer][column]`` lists."""
        flat = self.getRangeImage()
        if not isinstance(flat, list):
            return []
        w = self.getHorizontalResolution()
        return [flat[i:i + w] for i in range(0, len(flat), w)] if w else []

    def getLayerRangeImage(self, layer: int, data_type: str = "list") -> list[float] | bytes | None:
        return _floats(wb.lidar_range_bytes(self._tag, layer, "getLayerRangeImage"), data_type)

    # -- point cloud
    def enablePointCloud(self) -> None:
        wb.wb_lidar_enable_point_cloud(self._tag)

    def disablePointCloud(self) -> None:
        wb.wb_lidar_disable_point_cloud(self._tag)

    def isPointCloudEnabled(self) -> bool:
        return wb.wb_lidar_is_point_cloud_enabled(self._tag)

    def getPointCloud(self, data_type: str = "list") -> list[LidarPoint] | bytes:
        """A list of :class:`LidarPoint`, or with ``data_type='buffer'`` the raw 20-byte records."""
        return _points(wb.lidar_cloud_bytes(self._tag, None, "getPointCloud"), data_type)

    def getLayerPointCloud(self, layer: int, data_type: str = "list") -> list[LidarPoint] | bytes:
        return _points(wb.lidar_cloud_bytes(self._tag, layer, "getLayerPointCloud"), data_type)

    def getNumberOfPoints(self) -> int:
        return wb.wb_lidar_get_number_of_points(self._tag)

    # -- constants and frequency
    def getHorizontalResolution(self) -> int:
        return wb.wb_lidar_get_horizontal_resolution(self._tag)

    def getNumberOfLayers(self) -> int:
        return wb.wb_lidar_get_number_of_layers(self._tag)

    def getFov(self) -> float:
        return wb.wb_lidar_get_fov(self._tag)

    def getVerticalFov(self) -> float:
        return wb.wb_lidar_get_vertical_fov(self._tag)

    def getMinRange(self) -> float:
        return wb.wb_lidar_get_min_range(self._tag)

    def getMaxRange(self) -> float:
        return wb.wb_lidar_get_max_range(self._tag)

    def getFrequency(self) -> float:
        return wb.wb_lidar_get_frequency(self._tag)

    def setFrequency(self, frequency: float) -> None:
        wb.wb_lidar_set_frequency(self._tag, frequency)

    def getMinFrequency(self) -> float:
        return wb.wb_lidar_get_min_frequency(self._tag)

    def getMaxFrequency(self) -> float:
        return wb.wb_lidar_get_max_frequency(self._tag)

    # -- Webots' property spellings
    range_image = property(getRangeImage)
    point_cloud = property(getPointCloud)
    number_of_points = property(getNumberOfPoints)
    horizontal_resolution = property(getHorizontalResolution)
    number_of_layers = property(getNumberOfLayers)
    fov = property(getFov)
    vertical_fov = property(getVerticalFov)
    min_range = property(getMinRange)
    max_range = property(getMaxRange)
    frequency = property(getFrequency, setFrequency)
    min_frequency = property(getMinFrequency)
    max_frequency = property(getMaxFrequency)
