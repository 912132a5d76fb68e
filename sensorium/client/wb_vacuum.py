"""Webots' VacuumGripper functions (``wb_vacuum_gripper_*``) on Sensorium; :mod:`sensorium.client.wb`
re-exports them.

The presence (whether the gripper holds a solid: one with physics its bounding shapes touched while
the pump was on, carried until the pump is off, README "VacuumGripper and Speaker") arrives with the step reply at its sampling period, False before the
first value, with Webots' message when read while disabled. ``turn_on``/``turn_off`` go to the
server at once (one round trip each; libController sends them with the next step request: the next
step's presence reads them either way); ``is_on`` answers this controller's copy at once, as
libController's does, starting from the world's ``isOn``."""

from __future__ import annotations

import math

from sensorium.client.wb_robot import answers, current, sensor_enable, sensor_period, sensor_reading

VACUUM_GRIPPER = "VacuumGripper"

__all__ = ["VACUUM_GRIPPER", "wb_vacuum_gripper_disable_presence", "wb_vacuum_gripper_enable_presence",
           "wb_vacuum_gripper_get_presence", "wb_vacuum_gripper_get_presence_sampling_period",
           "wb_vacuum_gripper_is_on", "wb_vacuum_gripper_turn_off", "wb_vacuum_gripper_turn_on"]


@answers(None)
def wb_vacuum_gripper_enable_presence(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, VACUUM_GRIPPER, sampling_period, "wb_vacuum_gripper_enable_presence")


@answers(None)
def wb_vacuum_gripper_disable_presence(tag: int) -> None:
    sensor_enable(tag, VACUUM_GRIPPER, 0, "wb_vacuum_gripper_disable_presence")


@answers(0)
def wb_vacuum_gripper_get_presence_sampling_period(tag: int) -> int:
    return sensor_period(tag, VACUUM_GRIPPER, "wb_vacuum_gripper_get_presence_sampling_period")


@answers(False)
def wb_vacuum_gripper_get_presence(tag: int) -> bool:
    """Whether it held a solid at its latest value (False before the first one)."""
    dev = sensor_reading(tag, VACUUM_GRIPPER, "wb_vacuum_gripper_get_presence", "wb_vacuum_gripper_enable_presence")
    return not math.isnan(dev.value) and dev.value != 0.0


def _turn(tag: int, on: bool, func: str) -> None:
    r = current()
    dev = r.device(tag, VACUUM_GRIPPER, func)
    r.device_set(dev, "set_on", on, func)
    dev.desc["is_on"] = on


@answers(None)
def wb_vacuum_gripper_turn_on(tag: int) -> None:
    _turn(tag, True, "wb_vacuum_gripper_turn_on")


@answers(None)
def wb_vacuum_gripper_turn_off(tag: int) -> None:
    _turn(tag, False, "wb_vacuum_gripper_turn_off")


@answers(False)
def wb_vacuum_gripper_is_on(tag: int) -> bool:
    return bool(current().device(tag, VACUUM_GRIPPER, "wb_vacuum_gripper_is_on").desc.get("is_on", False))
