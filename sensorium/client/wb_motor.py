"""Webots' actuator functions: ``wb_motor_*`` (commands buffered and sent with the next step)
and ``wb_led_*``."""

from __future__ import annotations

import math
import sys

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_connector import brake_of
from sensorium.client.wb_robot import (
    LED,
    LINEAR_MOTOR,
    POSITION_SENSOR,
    ROTATIONAL_MOTOR,
    WB_LINEAR,
    WB_ROTATIONAL,
    DeviceState,
    _float,
    answers,
    current,
    integer,
    real,
)

_NAN = math.nan

# ---------------------------------------------------------------------- motor

def _motor(tag: int, func: str) -> DeviceState:
    return current().device(tag, ROTATIONAL_MOTOR, func)


@answers(None)
def wb_motor_set_position(tag: int, position: float) -> None:
    """Target position (rad) sent with the next step; ``float('inf')`` selects velocity control."""
    current().set_motor_position(_motor(tag, "wb_motor_set_position"), position, "wb_motor_set_position")


@answers(None)
def wb_motor_set_velocity(tag: int, velocity: float) -> None:
    """Velocity (rad/s) sent with the next step: the wheel speed in velocity control, the speed
    limit in position control. Above ``maxVelocity`` it is clamped (with Webots' warning)."""
    current().set_motor_velocity(_motor(tag, "wb_motor_set_velocity"), velocity, "wb_motor_set_velocity")


@answers(_NAN)
def wb_motor_get_velocity(tag: int) -> float:
    return _motor(tag, "wb_motor_get_velocity").velocity


@answers(_NAN)
def wb_motor_get_max_velocity(tag: int) -> float:
    return _motor(tag, "wb_motor_get_max_velocity").max_velocity


@answers(_NAN)
def wb_motor_get_target_position(tag: int) -> float:
    return _motor(tag, "wb_motor_get_target_position").target_position


@answers(_NAN)
def wb_motor_get_min_position(tag: int) -> float:
    """0 with :func:`wb_motor_get_max_position` 0: no position limits (a wheel)."""
    return _float(_motor(tag, "wb_motor_get_min_position").desc.get("minPosition"), 0.0)


@answers(_NAN)
def wb_motor_get_max_position(tag: int) -> float:
    return _float(_motor(tag, "wb_motor_get_max_position").desc.get("maxPosition"), 0.0)


def wb_motor_get_type(tag: int) -> int:
    """``WB_ROTATIONAL`` or ``WB_LINEAR`` (a linear motor is listed, not simulated)."""
    dev = current().device(tag, None, "wb_motor_get_type")
    if dev.kind not in (ROTATIONAL_MOTOR, LINEAR_MOTOR):
        raise SensoriumError(ErrorCode.UNKNOWN_DEVICE, f"wb_motor_get_type(): device tag {tag} is {dev.name!r}, a {dev.kind}, not a motor")
    return WB_LINEAR if dev.kind == LINEAR_MOTOR else WB_ROTATIONAL


@answers(0)
def wb_motor_get_position_sensor(tag: int) -> int:
    """The tag of the PositionSensor on the wheel's joint, 0 if it has none."""
    r = current()
    name = _motor(tag, "wb_motor_get_position_sensor").name
    for dev in r.devices:
        if dev.kind == POSITION_SENSOR and dev.desc.get("motor") == name:
            return dev.tag
    return 0


@answers(0)
def wb_motor_get_brake(tag: int) -> int:
    """The tag of the Brake on the motor's joint, 0 if it has none."""
    return brake_of("motor", _motor(tag, "wb_motor_get_brake").name)


# -- what needs physics. A drive's wheel turns at its commanded speed at once: its setters are
#    accepted and ignored, its getters answer Webots' default or NaN. A joint's motor (its attach
#    entry has ``maxForce``) moves as Webots moves it without physics: its acceleration and
#    available torque/force bound the speed ramp (sent with the next step), PID gains, forces and
#    torques are ignored (as Webots' kinematic control ignores them) and feedback reads NaN (Webots
#    gives none without a Physics node). One warning line per motor for what is ignored.

def _number(value: float, what: str, func: str) -> float:
    number = real(value)
    if number is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): '{what}' must be a number, got {value!r}")
    return number


def _joint(dev: DeviceState) -> bool:
    return "maxForce" in dev.desc


def _physics(tag: int, func: str) -> DeviceState:
    dev = _motor(tag, func)
    if not dev._consts.get("physics_warned"):
        dev._consts["physics_warned"] = True
        if _joint(dev):
            print(f"Warning: {func}(): {dev.kind} '{dev.name}' moves its joint kinematically (no physics): PID gains, "
                  "forces and torques are ignored, force and torque feedback read NaN.", file=sys.stderr)
        else:
            print(f"Warning: {func}(): {dev.kind} '{dev.name}' is a kinematic wheel: accelerations, forces, torques "
                  "and PID gains are ignored, force and torque feedback read NaN.", file=sys.stderr)
    return dev


@answers(None)
def wb_motor_set_acceleration(tag: int, acceleration: float) -> None:
    """A joint's motor: the bound of its speed ramp (>= 0, or -1: its available torque/force)."""
    dev = _motor(tag, "wb_motor_set_acceleration")
    if not _joint(dev):
        _physics(tag, "wb_motor_set_acceleration")._consts["acceleration"] = float(acceleration)
        return
    value = _number(acceleration, "acceleration", "wb_motor_set_acceleration")
    if value != value or (value < 0.0 and value != -1.0) or math.isinf(value):
        print("Error: wb_motor_set_acceleration() called with negative 'acceleration' argument.", file=sys.stderr)
        return
    dev._consts["acceleration"] = value
    current().set_motor_quantity(dev, "acceleration", value)


@answers(_NAN)
def wb_motor_get_acceleration(tag: int) -> float:
    """-1 (unlimited, Webots' default) unless set, or a joint motor's ``acceleration`` field."""
    dev = _motor(tag, "wb_motor_get_acceleration")
    return float(dev._consts.get("acceleration", _float(dev.desc.get("acceleration"), -1.0)))


def _set_available(tag: int, value: float, func: str) -> None:
    dev = _motor(tag, func)
    if not _joint(dev):
        _physics(tag, func)
        return
    number = _number(value, "torque" if "torque" in func else "force", func)
    if number != number or number < 0.0 or math.isinf(number):
        what = "torque" if "torque" in func else "force"
        print(f"Error: {func}() called with negative '{what}' argument.", file=sys.stderr)
        return
    dev._consts["available"] = number          # (Webots clamps it to the maximum, with a warning)
    current().set_motor_quantity(dev, "available_force", number)


def _get_available(tag: int, func: str) -> float:
    dev = _motor(tag, func)
    if not _joint(dev):
        _physics(tag, func)
        return _NAN
    return float(dev._consts.get("available", _float(dev.desc.get("maxForce"), _NAN)))


def _get_max(tag: int, func: str) -> float:
    dev = _motor(tag, func)
    if not _joint(dev):
        _physics(tag, func)
        return _NAN
    return _float(dev.desc.get("maxForce"), _NAN)


@answers(None)
def wb_motor_set_available_force(tag: int, force: float) -> None:
    _set_available(tag, force, "wb_motor_set_available_force")


@answers(None)
def wb_motor_set_available_torque(tag: int, torque: float) -> None:
    _set_available(tag, torque, "wb_motor_set_available_torque")


@answers(_NAN)
def wb_motor_get_available_force(tag: int) -> float:
    return _get_available(tag, "wb_motor_get_available_force")


@answers(_NAN)
def wb_motor_get_available_torque(tag: int) -> float:
    return _get_available(tag, "wb_motor_get_available_torque")


@answers(_NAN)
def wb_motor_get_max_force(tag: int) -> float:
    return _get_max(tag, "wb_motor_get_max_force")


@answers(_NAN)
def wb_motor_get_max_torque(tag: int) -> float:
    return _get_max(tag, "wb_motor_get_max_torque")


@answers(None)
def wb_motor_set_control_pid(tag: int, p: float, i: float, d: float) -> None:
    _physics(tag, "wb_motor_set_control_pid")


@answers(_NAN)
def wb_motor_get_multiplier(tag: int) -> float:
    """What the motor scales its position and velocity commands by (its ``multiplier``; 1 for a
    drive's wheel)."""
    return _float(_motor(tag, "wb_motor_get_multiplier").desc.get("multiplier"), 1.0)


@answers(None)
def wb_motor_set_force(tag: int, force: float) -> None:
    _physics(tag, "wb_motor_set_force")


@answers(None)
def wb_motor_set_torque(tag: int, torque: float) -> None:
    _physics(tag, "wb_motor_set_torque")


def _feedback_period(tag: int, key: str, period: int, func: str) -> None:
    dev = _physics(tag, func)
    if isinstance(period, bool) or not isinstance(period, int) or period < 0:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): sampling period must be an integer >= 0 (ms), got {period!r}")
    dev._consts[key] = period


@answers(None)
def wb_motor_enable_force_feedback(tag: int, sampling_period: int) -> None:
    _feedback_period(tag, "force_feedback", sampling_period, "wb_motor_enable_force_feedback")


@answers(None)
def wb_motor_disable_force_feedback(tag: int) -> None:
    _feedback_period(tag, "force_feedback", 0, "wb_motor_disable_force_feedback")


@answers(0)
def wb_motor_get_force_feedback_sampling_period(tag: int) -> int:
    return int(_motor(tag, "wb_motor_get_force_feedback_sampling_period")._consts.get("force_feedback", 0))


@answers(_NAN)
def wb_motor_get_force_feedback(tag: int) -> float:
    _physics(tag, "wb_motor_get_force_feedback")
    return _NAN


@answers(None)
def wb_motor_enable_torque_feedback(tag: int, sampling_period: int) -> None:
    _feedback_period(tag, "torque_feedback", sampling_period, "wb_motor_enable_torque_feedback")


@answers(None)
def wb_motor_disable_torque_feedback(tag: int) -> None:
    _feedback_period(tag, "torque_feedback", 0, "wb_motor_disable_torque_feedback")


@answers(0)
def wb_motor_get_torque_feedback_sampling_period(tag: int) -> int:
    return int(_motor(tag, "wb_motor_get_torque_feedback_sampling_period")._consts.get("torque_feedback", 0))


@answers(_NAN)
def wb_motor_get_torque_feedback(tag: int) -> float:
    _physics(tag, "wb_motor_get_torque_feedback")
    return _NAN


# ---------------------------------------------------------------------- LED

def _led(tag: int, func: str) -> DeviceState:
    return current().device(tag, LED, func)


def wb_led_set(tag: int, value: int) -> None:
    """0 switches the LED off; 1..n lights colour n of its ``color`` list; a gradual LED takes
    0xRRGGBB (no colour listed) or an intensity 0..255 of its one colour. Sent at once (the ``/<robot>/<led>/value`` topic publishes it); a value out of range
    is printed and ignored (Webots)."""
    r = current()
    dev = _led(tag, "wb_led_set")
    # Webots' Python LED passes the value to C through ctypes, which takes a bool as the int 0 or 1:
    # its own scara sample blinks the Epson's LED with set(True) / set(False)
    whole = int(value) if isinstance(value, bool) else integer(value)
    if whole is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wb_led_set(): value must be an integer, got {value!r}")
    value = whole
    colors = len(dev.desc.get("color", [])) // 3
    hi = (0xFFFFFF if colors == 0 else 255) if dev.desc.get("gradual") else colors
    if not 0 <= value <= hi:
        print(f"Error: wb_led_set(): value {value} out of range [0, {hi}] for LED {dev.name!r}.", file=sys.stderr)
        return
    r.device_set(dev, "set", value, "wb_led_set")
    dev.value = value


def wb_led_get(tag: int) -> int:
    dev = _led(tag, "wb_led_get")
    v = dev.value
    return int(dev.desc.get("value", 0)) if v != v else int(v)     # NaN: never set by this controller
