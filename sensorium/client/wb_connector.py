"""Webots' Connector and Brake functions (``wb_connector_*``, ``wb_brake_*``) on Sensorium;
:mod:`sensorium.client.wb` re-exports them.

A connector's presence arrives with the step reply at its sampling period (-1 before the first
value, the last one kept after a disable, Webots' message when read while disabled); ``lock`` and
``unlock`` ask the server, which holds the lock state (``is_locked`` answers the server's last word).
Nothing is physically joined: there is no physics (README "Connector and Brake"). A brake answers
its joint's type and the tags of the motor and position sensor on its joint (0 when none) from its
``attach`` description; ``wb_brake_set_damping_constant`` is accepted and has no effect, with one
warning per brake."""

from __future__ import annotations

import math
import sys

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import DeviceState, answers, current, real, sensor_enable, sensor_period, sensor_reading

CONNECTOR = "Connector"
BRAKE = "Brake"
WB_BRAKE_ROTATIONAL = 0
WB_BRAKE_LINEAR = 1

__all__ = ["BRAKE", "CONNECTOR", "WB_BRAKE_LINEAR", "WB_BRAKE_ROTATIONAL", "wb_brake_get_motor", "wb_brake_get_position_sensor", "wb_brake_get_type",
           "wb_brake_set_damping_constant", "wb_connector_disable_presence", "wb_connector_enable_presence",
           "wb_connector_get_presence", "wb_connector_get_presence_sampling_period", "wb_connector_is_locked",
           "wb_connector_lock", "wb_connector_unlock"]


# ---------------------------------------------------------------- Connector

@answers(None)
def wb_connector_enable_presence(tag: int, sampling_period: int) -> None:
    sensor_enable(tag, CONNECTOR, sampling_period, "wb_connector_enable_presence")


@answers(None)
def wb_connector_disable_presence(tag: int) -> None:
    sensor_enable(tag, CONNECTOR, 0, "wb_connector_disable_presence")


@answers(0)
def wb_connector_get_presence_sampling_period(tag: int) -> int:
    return sensor_period(tag, CONNECTOR, "wb_connector_get_presence_sampling_period")


@answers(-1)
def wb_connector_get_presence(tag: int) -> int:
    """1: a compatible peer connector in position, 0: none, -1: a passive connector, or no value yet."""
    v = sensor_reading(tag, CONNECTOR, "wb_connector_get_presence", "wb_connector_enable_presence").value
    return -1 if v is None or math.isnan(v) else int(v)


def _locking(tag: int, item: str, func: str) -> None:
    r = current()
    dev = r.device(tag, CONNECTOR, func)
    if dev.desc.get("connector_type") == "passive":          # Webots' message; the state stays unlocked
        print(f"Warning: {func}(): connector '{dev.name}': passive connectors cannot lock.", file=sys.stderr)
        return
    if r.terminated:                                         # no server any more: the local state only
        dev.desc["is_locked"] = item == "lock"
        return
    dev.desc["is_locked"] = bool(r.rpc(dev, item).get("status", 0))


@answers(None)
def wb_connector_lock(tag: int) -> None:
    """The lock state on (a peer present is not joined: no physics)."""
    _locking(tag, "lock", "wb_connector_lock")


@answers(None)
def wb_connector_unlock(tag: int) -> None:
    _locking(tag, "unlock", "wb_connector_unlock")


@answers(False)
def wb_connector_is_locked(tag: int) -> bool:
    return bool(current().device(tag, CONNECTOR, "wb_connector_is_locked").desc.get("is_locked", False))


# ---------------------------------------------------------------- Brake

def _brake(tag: int, func: str) -> DeviceState:
    return current().device(tag, BRAKE, func)


@answers(None)
def wb_brake_set_damping_constant(tag: int, damping_constant: float) -> None:
    """Accepted, no effect: braking needs physics (one warning per brake). NaN is refused in Webots' line."""
    func = "wb_brake_set_damping_constant"
    dev = _brake(tag, func)
    value = real(damping_constant)
    if value is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT,
                             f"{func}(): called with an invalid 'damping_constant' argument ({damping_constant!r})")
    if math.isnan(value):                                    # Webots' line, and nothing else
        print(f"Error: {func}() called with an invalid 'damping_constant' argument (NaN).", file=sys.stderr)
        return
    if not dev._consts.get("physics_warned"):
        dev._consts["physics_warned"] = True
        print(f"Warning: {func}(): brake '{dev.name}': Sensorium has no physics, the damping constant has no "
              "effect (its joint moves as its motor drives it).", file=sys.stderr)


@answers(0)
def wb_brake_get_type(tag: int) -> int:
    """``WB_ROTATIONAL`` (0) or ``WB_LINEAR`` (1): its joint's."""
    return int(_brake(tag, "wb_brake_get_type").desc.get("joint_type", 0) or 0)


@answers(0)
def wb_brake_get_motor(tag: int) -> int:
    """The tag of the motor on the brake's joint, 0 when it has none."""
    name = _brake(tag, "wb_brake_get_motor").desc.get("motor")
    return current().tag_of(str(name)) if name else 0


@answers(0)
def wb_brake_get_position_sensor(tag: int) -> int:
    """The tag of the position sensor on the brake's joint, 0 when it has none."""
    name = _brake(tag, "wb_brake_get_position_sensor").desc.get("position_sensor")
    return current().tag_of(str(name)) if name else 0


def brake_of(key: str, name: str) -> int:
    """The tag of the brake whose ``key`` ("motor" or "position_sensor") is ``name``, 0 when none."""
    for dev in current().devices:
        if dev.kind == BRAKE and dev.simulated and dev.desc.get(key) == name:
            return dev.tag
    return 0
