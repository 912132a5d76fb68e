"""Webots' functions of the sensors measured from the kinematic motion: ``wb_gps_*``,
``wb_inertial_unit_*``, ``wb_compass_*``, ``wb_accelerometer_*``, ``wb_gyro_*``,
``wb_altimeter_*``, ``wb_touch_sensor_*``. Readings arrive with the step reply and are read
locally (NaN before the first value, the last one kept after a disable); vectors are new lists."""

from __future__ import annotations

import math
import sys
from typing import Any

from sensorium.client.wb_robot import DeviceState, current, sensor_enable, sensor_period, sensor_reading

WB_GPS_LOCAL_COORDINATE = 0
WB_GPS_WGS84_COORDINATE = 1

WB_TOUCH_SENSOR_BUMPER = 0
WB_TOUCH_SENSOR_FORCE = 1
WB_TOUCH_SENSOR_FORCE3D = 2

GPS = "GPS"
INERTIAL_UNIT = "InertialUnit"
COMPASS = "Compass"
ACCELEROMETER = "Accelerometer"
GYRO = "Gyro"
ALTIMETER = "Altimeter"
TOUCH_SENSOR = "TouchSensor"


def _dev(tag: int, kind: str, func: str) -> DeviceState:
    return current().device(tag, kind, func)


def _table(tag: int, kind: str, func: str) -> list[float]:
    r = current()
    return list(r.constant(r.device(tag, kind, func), "lookup_table"))


# ---------------------------------------------------------------------- GPS

def wb_gps_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, GPS, sampling_period, "wb_gps_enable")


def wb_gps_disable(tag: int) -> None:
    sensor_enable(tag, GPS, 0, "wb_gps_disable")


def wb_gps_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, GPS, "wb_gps_get_sampling_period")


def wb_gps_get_values(tag: int) -> list[float]:
    """x, y, z (local, m) or latitude, longitude (degrees), altitude (m) with WGS84."""
    return list(sensor_reading(tag, GPS, "wb_gps_get_values", "wb_gps_enable").values)


def wb_gps_get_speed(tag: int) -> float:
    return sensor_reading(tag, GPS, "wb_gps_get_speed", "wb_gps_enable").speed


def wb_gps_get_speed_vector(tag: int) -> list[float]:
    return list(sensor_reading(tag, GPS, "wb_gps_get_speed_vector", "wb_gps_enable").speed_vector)


def wb_gps_get_coordinate_system(tag: int) -> int:
    """``WB_GPS_LOCAL_COORDINATE`` or ``WB_GPS_WGS84_COORDINATE`` (the world's ``gps_coordinate_system``)."""
    return int(_dev(tag, GPS, "wb_gps_get_coordinate_system").desc.get("coordinate_system", 0))


def wb_gps_convert_to_degrees_minutes_seconds(decimal_degrees: float) -> str:
    """libController's text: whole degrees, minutes and seconds, each C's ``(int)`` of its double
    (truncated toward zero, so each carries the angle's sign; NaN, a GPS value before its first
    sample, and infinities give INT_MIN, as x86-64 converts them)."""
    d = float(decimal_degrees)
    degrees = _c_int(d)
    minutes = _c_int((d - degrees) * 60)
    seconds = _c_int(((d - degrees) * 60 - minutes) * 60)
    return f"{degrees}\u00b0 {minutes}\u2032 {seconds}\u2033"


def _c_int(v: float) -> int:
    """C's ``(int)`` of a double on x86-64: truncated toward zero; INT_MIN for NaN, infinities and
    values out of int's range (undefined in C, the processor's "integer indefinite")."""
    return int(v) if -2147483649.0 < v < 2147483648.0 else -(1 << 31)


# ---------------------------------------------------------------------- InertialUnit

def wb_inertial_unit_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, INERTIAL_UNIT, sampling_period, "wb_inertial_unit_enable")


def wb_inertial_unit_disable(tag: int) -> None:
    sensor_enable(tag, INERTIAL_UNIT, 0, "wb_inertial_unit_disable")


def wb_inertial_unit_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, INERTIAL_UNIT, "wb_inertial_unit_get_sampling_period")


def wb_inertial_unit_get_roll_pitch_yaw(tag: int) -> list[float]:
    """Roll, pitch, yaw (rad) in the world's convention (ENU or NUE)."""
    return list(sensor_reading(tag, INERTIAL_UNIT, "wb_inertial_unit_get_roll_pitch_yaw", "wb_inertial_unit_enable").roll_pitch_yaw)


def wb_inertial_unit_get_quaternion(tag: int) -> list[float]:
    """x, y, z, w."""
    return list(sensor_reading(tag, INERTIAL_UNIT, "wb_inertial_unit_get_quaternion", "wb_inertial_unit_enable").quaternion)


def wb_inertial_unit_get_noise(tag: int) -> float:
    return float(_dev(tag, INERTIAL_UNIT, "wb_inertial_unit_get_noise").desc.get("noise", 0.0))


# ---------------------------------------------------------------------- Compass, Accelerometer, Gyro

def wb_compass_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, COMPASS, sampling_period, "wb_compass_enable")


def wb_compass_disable(tag: int) -> None:
    sensor_enable(tag, COMPASS, 0, "wb_compass_disable")


def wb_compass_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, COMPASS, "wb_compass_get_sampling_period")


def wb_compass_get_values(tag: int) -> list[float]:
    """The north direction in the device frame (through the lookup table)."""
    return list(sensor_reading(tag, COMPASS, "wb_compass_get_values", "wb_compass_enable").values)


def wb_compass_get_lookup_table_size(tag: int) -> int:
    return len(_table(tag, COMPASS, "wb_compass_get_lookup_table_size")) // 3


def wb_compass_get_lookup_table(tag: int) -> list[float]:
    return _table(tag, COMPASS, "wb_compass_get_lookup_table")


def wb_accelerometer_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, ACCELEROMETER, sampling_period, "wb_accelerometer_enable")


def wb_accelerometer_disable(tag: int) -> None:
    sensor_enable(tag, ACCELEROMETER, 0, "wb_accelerometer_disable")


def wb_accelerometer_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, ACCELEROMETER, "wb_accelerometer_get_sampling_period")


def wb_accelerometer_get_values(tag: int) -> list[float]:
    """The specific force (m/s²) in the device frame: (0, 0, g) at rest in ENU."""
    return list(sensor_reading(tag, ACCELEROMETER, "wb_accelerometer_get_values", "wb_accelerometer_enable").values)


def wb_accelerometer_get_lookup_table_size(tag: int) -> int:
    return len(_table(tag, ACCELEROMETER, "wb_accelerometer_get_lookup_table_size")) // 3


def wb_accelerometer_get_lookup_table(tag: int) -> list[float]:
    return _table(tag, ACCELEROMETER, "wb_accelerometer_get_lookup_table")


def wb_gyro_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, GYRO, sampling_period, "wb_gyro_enable")


def wb_gyro_disable(tag: int) -> None:
    sensor_enable(tag, GYRO, 0, "wb_gyro_disable")


def wb_gyro_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, GYRO, "wb_gyro_get_sampling_period")


def wb_gyro_get_values(tag: int) -> list[float]:
    """The angular velocity (rad/s) in the device frame."""
    return list(sensor_reading(tag, GYRO, "wb_gyro_get_values", "wb_gyro_enable").values)


def wb_gyro_get_lookup_table_size(tag: int) -> int:
    return len(_table(tag, GYRO, "wb_gyro_get_lookup_table_size")) // 3


def wb_gyro_get_lookup_table(tag: int) -> list[float]:
    return _table(tag, GYRO, "wb_gyro_get_lookup_table")


# ---------------------------------------------------------------------- Altimeter

def wb_altimeter_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, ALTIMETER, sampling_period, "wb_altimeter_enable")


def wb_altimeter_disable(tag: int) -> None:
    sensor_enable(tag, ALTIMETER, 0, "wb_altimeter_disable")


def wb_altimeter_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, ALTIMETER, "wb_altimeter_get_sampling_period")


def wb_altimeter_get_value(tag: int) -> float:
    """The device's height (m) along the world's up axis."""
    return sensor_reading(tag, ALTIMETER, "wb_altimeter_get_value", "wb_altimeter_enable").value


# ---------------------------------------------------------------------- TouchSensor

def wb_touch_sensor_enable(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, TOUCH_SENSOR, sampling_period, "wb_touch_sensor_enable")


def wb_touch_sensor_disable(tag: int) -> None:
    sensor_enable(tag, TOUCH_SENSOR, 0, "wb_touch_sensor_disable")


def wb_touch_sensor_get_sampling_period(tag: int) -> int:
    return sensor_period(tag, TOUCH_SENSOR, "wb_touch_sensor_get_sampling_period")


def wb_touch_sensor_get_type(tag: int) -> int:
    return int(_dev(tag, TOUCH_SENSOR, "wb_touch_sensor_get_type").desc.get("sensor_type", 0))


def wb_touch_sensor_get_value(tag: int) -> float:
    """A bumper's 0/1 (a force sensor's NaN: no physics); Webots' error and NaN for a force-3d one."""
    func = "wb_touch_sensor_get_value"
    if wb_touch_sensor_get_type(tag) == WB_TOUCH_SENSOR_FORCE3D:
        print(f'Error: {func}() must be used with a TouchSensor of type "bumper" or "force"\n'
              "Error: you should use wb_touch_sensor_get_values() instead.", file=sys.stderr)
        return math.nan
    return sensor_reading(tag, TOUCH_SENSOR, func, "wb_touch_sensor_enable").value


def wb_touch_sensor_get_values(tag: int) -> Any:
    """A force-3d sensor's three values (NaN: no physics); Webots' error and ``None`` for other types."""
    func = "wb_touch_sensor_get_values"
    if wb_touch_sensor_get_type(tag) != WB_TOUCH_SENSOR_FORCE3D:
        print(f'Error: {func}() must be used with a TouchSensor of type "force-3d"\n'
              "Error: you should use wb_touch_sensor_get_value() instead.", file=sys.stderr)
        return None
    return list(sensor_reading(tag, TOUCH_SENSOR, func, "wb_touch_sensor_enable").values)


def wb_touch_sensor_get_lookup_table_size(tag: int) -> int:
    return len(_table(tag, TOUCH_SENSOR, "wb_touch_sensor_get_lookup_table_size")) // 3


def wb_touch_sensor_get_lookup_table(tag: int) -> list[float]:
    return _table(tag, TOUCH_SENSOR, "wb_touch_sensor_get_lookup_table")
