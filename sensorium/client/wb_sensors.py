"""Webots' sensor functions: ``wb_light_sensor_*``, ``wb_distance_sensor_*``, ``wb_lidar_*``,
``wb_position_sensor_*`` (readings cached per step, see :mod:`sensorium.client.wb`)."""

from __future__ import annotations

from typing import Any

from sensorium.client import arrays
from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_connector import brake_of
from sensorium.client.wb_robot import (
    DISTANCE_SENSOR,
    LIDAR,
    LIGHT_SENSOR,
    LINEAR_MOTOR,
    POSITION_SENSOR,
    WB_LINEAR,
    WB_ROTATIONAL,
    DeviceState,
    RobotClient,
    current,
    integer,
    sensor_enable,
    sensor_period,
    sensor_reading,
)

# ---------------------------------------------------------------------- light sensor

def _scalar_value(tag: int, kind: str, func: str, enabler: str) -> float:
    return sensor_reading(tag, kind, func, enabler).value


def wb_light_sensor_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, LIGHT_SENSOR, sampling_period, "wb_light_sensor_enable")


def wb_light_sensor_disable(tag: int) -> None:
    sensor_enable(tag, LIGHT_SENSOR, 0, "wb_light_sensor_disable")


def wb_light_sensor_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, LIGHT_SENSOR, "wb_light_sensor_get_sampling_period")


def wb_light_sensor_get_value(tag: int) -> float:
    return _scalar_value(tag, LIGHT_SENSOR, "wb_light_sensor_get_value", "wb_light_sensor_enable")


def wb_light_sensor_get_lookup_table_size(tag: int) -> int:
    return len(wb_light_sensor_get_lookup_table(tag)) // 3


def wb_light_sensor_get_lookup_table(tag: int) -> list[float]:
    """The N x 3 table flattened: input, output, noise, input, output, noise…"""
    r = current()
    return list(r.constant(r.device(tag, LIGHT_SENSOR, "wb_light_sensor_get_lookup_table"), "lookup_table"))


# ---------------------------------------------------------------------- distance sensor

def wb_distance_sensor_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, DISTANCE_SENSOR, sampling_period, "wb_distance_sensor_enable")


def wb_distance_sensor_disable(tag: int) -> None:
    sensor_enable(tag, DISTANCE_SENSOR, 0, "wb_distance_sensor_disable")


def wb_distance_sensor_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, DISTANCE_SENSOR, "wb_distance_sensor_get_sampling_period")


def wb_distance_sensor_get_value(tag: int) -> float:
    return _scalar_value(tag, DISTANCE_SENSOR, "wb_distance_sensor_get_value", "wb_distance_sensor_enable")


def _distance_constant(tag: int, key: str, func: str) -> Any:
    r = current()
    return r.constant(r.device(tag, DISTANCE_SENSOR, func), key)


def wb_distance_sensor_get_min_value(tag: int) -> float:
    return _distance_constant(tag, "min_value", "wb_distance_sensor_get_min_value")


def wb_distance_sensor_get_max_value(tag: int) -> float:
    return _distance_constant(tag, "max_value", "wb_distance_sensor_get_max_value")


def wb_distance_sensor_get_aperture(tag: int) -> float:
    return _distance_constant(tag, "aperture", "wb_distance_sensor_get_aperture")


def wb_distance_sensor_get_type(tag: int) -> int:
    """One of WB_DISTANCE_SENSOR_GENERIC, _INFRA_RED, _SONAR, _LASER."""
    return _distance_constant(tag, "distance_type", "wb_distance_sensor_get_type")


def wb_distance_sensor_get_lookup_table_size(tag: int) -> int:
    return len(wb_distance_sensor_get_lookup_table(tag)) // 3


def wb_distance_sensor_get_lookup_table(tag: int) -> list[float]:
    return list(_distance_constant(tag, "lookup_table", "wb_distance_sensor_get_lookup_table"))


# ---------------------------------------------------------------------- lidar

def _lidar(tag: int, func: str) -> DeviceState:
    return current().device(tag, LIDAR, func)


def _lidar_constant(tag: int, key: str, func: str) -> Any:
    return current().constant(_lidar(tag, func), key)


def _check_layer(r: RobotClient, dev: DeviceState, layer: int, func: str) -> int:
    layers = r.constant(dev, "number_of_layers")
    index = integer(layer)
    if index is None or not 0 <= index < layers:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): layer {layer!r} outside [0, {layers - 1}]")
    return index


def wb_lidar_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, LIDAR, sampling_period, "wb_lidar_enable")


def wb_lidar_disable(tag: int) -> None:
    sensor_enable(tag, LIDAR, 0, "wb_lidar_disable")


def wb_lidar_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, LIDAR, "wb_lidar_get_sampling_period")


def wb_lidar_enable_point_cloud(tag: int) -> None:
    current().enable_point_cloud(_lidar(tag, "wb_lidar_enable_point_cloud"), True, "wb_lidar_enable_point_cloud")


def wb_lidar_disable_point_cloud(tag: int) -> None:
    current().enable_point_cloud(_lidar(tag, "wb_lidar_disable_point_cloud"), False, "wb_lidar_disable_point_cloud")


def wb_lidar_is_point_cloud_enabled(tag: int) -> bool:
    return _lidar(tag, "wb_lidar_is_point_cloud_enabled").point_cloud_enabled


def lidar_range_bytes(tag: int, layer: int | None = None, func: str = "wb_lidar_get_range_image") -> bytes | None:
    """The raw ``<f4`` range image (or one layer of it) with Webots' checks: a disabled lidar
    prints an error and still returns the whole cached image, but no layer (``None``)."""
    r = current()
    dev = _lidar(tag, func)
    if layer is not None:
        _check_layer(r, dev, layer, func)
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, "wb_lidar_enable")
        if layer is not None:
            return None
    buf = r.range_bytes(dev)
    if layer is None:
        return buf
    row = 4 * r.constant(dev, "horizontal_resolution")
    return buf[row * layer:row * (layer + 1)]


def lidar_cloud_bytes(tag: int, layer: int | None = None, func: str = "wb_lidar_get_point_cloud") -> bytes | None:
    """The raw point-cloud records (or one layer's); ``None`` with Webots' message unless the
    lidar and its point cloud are enabled."""
    r = current()
    dev = _lidar(tag, func)
    if layer is not None:
        _check_layer(r, dev, layer, func)
    if not _cloud_usable(r, dev, func):
        return None
    buf = r.cloud_bytes(dev)
    if layer is None:
        return buf
    row = arrays.POINT_SIZE * r.constant(dev, "horizontal_resolution")
    return buf[row * layer:row * (layer + 1)]


def _cloud_usable(r: RobotClient, dev: DeviceState, func: str) -> bool:
    if not dev.point_cloud_enabled:
        r.warn_disabled(dev, func, "wb_lidar_enable_point_cloud", "a lidar with point cloud disabled")
        return False
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, "wb_lidar_enable")
        return False
    return True


def wb_lidar_get_range_image(tag: int) -> Any:
    """The latest range image, ``layers x horizontal_resolution`` float32 values flattened (left to
    right, first layer to last): a read-only numpy array, or ``array('f')`` without numpy.
    Zeros before the first measurement."""
    buf = lidar_range_bytes(tag)
    assert buf is not None                      # without a layer: always the whole image
    if arrays.numpy_module() is None:
        return arrays.float32s(buf or b"")
    r = current()
    return r.range_image(r.devices[tag - 1])


def wb_lidar_get_layer_range_image(tag: int, layer: int) -> Any:
    """One layer of the range image; ``None`` (with Webots' message) while the lidar is disabled."""
    buf = lidar_range_bytes(tag, layer, "wb_lidar_get_layer_range_image")
    return None if buf is None else arrays.float32s(buf)


def wb_lidar_get_point_cloud(tag: int) -> Any:
    """The latest point cloud (records x, y, z, layer_id, time): a read-only numpy structured array,
    or a list of tuples without numpy; ``None`` unless the lidar and its point cloud are enabled."""
    buf = lidar_cloud_bytes(tag)
    if buf is None:
        return None
    if arrays.numpy_module() is None:
        return arrays.points(buf)
    r = current()
    return r.point_cloud(r.devices[tag - 1])


def wb_lidar_get_layer_point_cloud(tag: int, layer: int) -> Any:
    buf = lidar_cloud_bytes(tag, layer, "wb_lidar_get_layer_point_cloud")
    return None if buf is None else arrays.points(buf)


def wb_lidar_get_number_of_points(tag: int) -> int:
    """layers x horizontal resolution; 0 (with Webots' message) unless the lidar and its point
    cloud are enabled."""
    r = current()
    func = "wb_lidar_get_number_of_points"
    dev = _lidar(tag, func)
    if not _cloud_usable(r, dev, func):
        return 0
    return r.constant(dev, "horizontal_resolution") * r.constant(dev, "number_of_layers")


def wb_lidar_get_horizontal_resolution(tag: int) -> int:
    return _lidar_constant(tag, "horizontal_resolution", "wb_lidar_get_horizontal_resolution")


def wb_lidar_get_number_of_layers(tag: int) -> int:
    return _lidar_constant(tag, "number_of_layers", "wb_lidar_get_number_of_layers")


def wb_lidar_get_fov(tag: int) -> float:
    return _lidar_constant(tag, "fov", "wb_lidar_get_fov")


def wb_lidar_get_vertical_fov(tag: int) -> float:
    return _lidar_constant(tag, "vertical_fov", "wb_lidar_get_vertical_fov")


def wb_lidar_get_min_range(tag: int) -> float:
    return _lidar_constant(tag, "min_range", "wb_lidar_get_min_range")


def wb_lidar_get_max_range(tag: int) -> float:
    return _lidar_constant(tag, "max_range", "wb_lidar_get_max_range")


def wb_lidar_get_frequency(tag: int) -> float:
    return _lidar_constant(tag, "frequency", "wb_lidar_get_frequency")


def wb_lidar_set_frequency(tag: int, frequency: float) -> None:
    current().set_frequency(_lidar(tag, "wb_lidar_set_frequency"), frequency, "wb_lidar_set_frequency")


def wb_lidar_get_min_frequency(tag: int) -> float:
    return _lidar_constant(tag, "min_frequency", "wb_lidar_get_min_frequency")


def wb_lidar_get_max_frequency(tag: int) -> float:
    return _lidar_constant(tag, "max_frequency", "wb_lidar_get_max_frequency")


# ---------------------------------------------------------------------- position sensor (wheel encoder)

def _position_sensor(tag: int, func: str) -> DeviceState:
    return current().device(tag, POSITION_SENSOR, func)


def wb_position_sensor_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, POSITION_SENSOR, sampling_period, "wb_position_sensor_enable")


def wb_position_sensor_disable(tag: int) -> None:
    sensor_enable(tag, POSITION_SENSOR, 0, "wb_position_sensor_disable")


def wb_position_sensor_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, POSITION_SENSOR, "wb_position_sensor_get_sampling_period")


def wb_position_sensor_get_value(tag: int) -> float:
    """The wheel's angle (rad) at the latest measurement; NaN before the first one."""
    return _scalar_value(tag, POSITION_SENSOR, "wb_position_sensor_get_value", "wb_position_sensor_enable")


def wb_position_sensor_get_type(tag: int) -> int:
    """Its joint's type, which is its motor's (a slider's or a Track's LinearMotor: ``WB_LINEAR``)."""
    motor = current().by_name.get(str(_position_sensor(tag, "wb_position_sensor_get_type").desc.get("motor", "")))
    return WB_LINEAR if motor is not None and motor.kind == LINEAR_MOTOR else WB_ROTATIONAL


def wb_position_sensor_get_motor(tag: int) -> int:
    """The tag of the wheel motor on the same joint."""
    r = current()
    return r.tag_of(str(_position_sensor(tag, "wb_position_sensor_get_motor").desc.get("motor", "")))


def wb_position_sensor_get_brake(tag: int) -> int:
    """The tag of the Brake on the sensor's joint, 0 if it has none."""
    return brake_of("position_sensor", _position_sensor(tag, "wb_position_sensor_get_brake").name)
