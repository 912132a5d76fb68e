"""Webots' actuator functions: ``wb_motor_*`` (commands buffered and sent with the next step)
and ``wb_led_*``."""

from __future__ import annotations

import sys

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import (
    LED,
    POSITION_SENSOR,
    ROTATIONAL_MOTOR,
    WB_ROTATIONAL,
    DeviceState,
    _float,
    current,
)

# ---------------------------------------------------------------------- motor

def _motor(tag: int, func: str) -> DeviceState:
    return current().device(tag, ROTATIONAL_MOTOR, func)


def wb_motor_set_position(tag: int, position: float) -> None:
    """Target position (rad) sent with the next step; ``float('inf')`` selects velocity control."""
    current().set_motor_position(_motor(tag, "wb_motor_set_position"), position, "wb_motor_set_position")


def wb_motor_set_velocity(tag: int, velocity: float) -> None:
    """Velocity (rad/s) sent with the next step: the wheel speed in velocity control, the speed
    limit in position control. Above ``maxVelocity`` it is clamped (with Webots' warning)."""
    current().set_motor_velocity(_motor(tag, "wb_motor_set_velocity"), velocity, "wb_motor_set_velocity")


def wb_motor_get_velocity(tag: int) -> float:
    return _motor(tag, "wb_motor_get_velocity").velocity


def wb_motor_get_max_velocity(tag: int) -> float:
    return _motor(tag, "wb_motor_get_max_velocity").max_velocity


def wb_motor_get_target_position(tag: int) -> float:
    return _motor(tag, "wb_motor_get_target_position").target_position


def wb_motor_get_min_position(tag: int) -> float:
    """0 with :func:`wb_motor_get_max_position` 0: no position limits (a wheel)."""
    return _float(_motor(tag, "wb_motor_get_min_position").desc.get("minPosition"), 0.0)


def wb_motor_get_max_position(tag: int) -> float:
    return _float(_motor(tag, "wb_motor_get_max_position").desc.get("maxPosition"), 0.0)


def wb_motor_get_type(tag: int) -> int:
    _motor(tag, "wb_motor_get_type")
    return WB_ROTATIONAL


def wb_motor_get_position_sensor(tag: int) -> int:
    """The tag of the PositionSensor on the wheel's joint, 0 if it has none."""
    r = current()
    name = _motor(tag, "wb_motor_get_position_sensor").name
    for dev in r.devices:
        if dev.kind == POSITION_SENSOR and dev.desc.get("motor") == name:
            return dev.tag
    return 0


def wb_motor_get_brake(tag: int) -> int:
    _motor(tag, "wb_motor_get_brake")
    return 0


# ---------------------------------------------------------------------- LED

def _led(tag: int, func: str) -> DeviceState:
    return current().device(tag, LED, func)


def wb_led_set(tag: int, value: int) -> None:
    """0 switches the LED off; 1..n lights colour n of its ``color`` list; a gradual LED takes
    0xRRGGBB. Sent at once (the ``/<robot>/<led>/value`` topic publishes it); a value out of range
    is printed and ignored (Webots)."""
    r = current()
    dev = _led(tag, "wb_led_set")
    if isinstance(value, bool) or not isinstance(value, int):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wb_led_set(): value must be an integer, got {value!r}")
    colors = len(dev.desc.get("color", [])) // 3
    hi = 0xFFFFFF if dev.desc.get("gradual") else colors
    if not 0 <= value <= hi:
        print(f"Error: wb_led_set(): value {value} out of range [0, {hi}] for LED {dev.name!r}.", file=sys.stderr)
        return
    if not r.terminated:
        r.rpc(dev, "set", {"value": value})
    dev.value = value


def wb_led_get(tag: int) -> int:
    dev = _led(tag, "wb_led_get")
    v = dev.value
    return int(dev.desc.get("value", 0)) if v != v else int(v)     # NaN: never set by this controller
