"""Webots' functions of the devices Sensorium lists but does not simulate (Brake, Connector,
Skin): each checks its tag names a device of its type,
prints the device's one warning line and answers Webots' "no value" (NaN, ``None`` for NULL, 0,
False). Camera, RangeFinder, Pen, Display, Radar, Speaker and VacuumGripper have their own modules.

The functions are made from :data:`NO_VALUE` (C name -> (device type, answer)); a device of the
type that the server does simulate (none today) would get real functions instead."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from sensorium.client.wb_robot import answers, current

WB_BRAKE_ROTATIONAL = 0
WB_BRAKE_LINEAR = 1

_NAN = math.nan

NO_VALUE: dict[str, tuple[str, Any]] = {
    # Brake
    "wb_brake_set_damping_constant": ("Brake", None),
    "wb_brake_get_type": ("Brake", 0),
    "wb_brake_get_motor": ("Brake", 0),
    "wb_brake_get_position_sensor": ("Brake", 0),
    # Connector
    "wb_connector_enable_presence": ("Connector", None),
    "wb_connector_disable_presence": ("Connector", None),
    "wb_connector_get_presence_sampling_period": ("Connector", 0),
    "wb_connector_get_presence": ("Connector", -1),
    "wb_connector_lock": ("Connector", None),
    "wb_connector_unlock": ("Connector", None),
    "wb_connector_is_locked": ("Connector", False),
    # Skin
    "wb_skin_set_bone_orientation": ("Skin", None),
    "wb_skin_set_bone_position": ("Skin", None),
    "wb_skin_get_bone_count": ("Skin", 0),
    "wb_skin_get_bone_name": ("Skin", ""),
    "wb_skin_get_bone_orientation": ("Skin", None),
    "wb_skin_get_bone_position": ("Skin", None),
}


def no_value_function(name: str, kind: str, answer: Any) -> Callable[..., Any]:
    """``name(tag, *args)``: the device must be a ``kind``; answers ``answer`` with one warning."""
    @answers(answer)
    def fn(tag: int, *args: Any) -> Any:
        current().device(tag, kind, name)        # a listed-only device raises NoValue (answers)
        return answer                            # (a simulated one would need its real function)

    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = f"Webots' {name}(): {kind} is not simulated, answers {answer!r}."
    return fn


globals().update({name: no_value_function(name, kind, answer) for name, (kind, answer) in NO_VALUE.items()})

