"""Webots' functions of the devices Sensorium lists but does not simulate (Skin;
Microphone and Radio: wb_radio.py): each checks its tag names a device of its type,
prints the device's one warning line and answers Webots' "no value" (NaN, ``None`` for NULL, 0,
False). Camera, RangeFinder, Pen, Display, Radar, Speaker, VacuumGripper, Connector and Brake have their own
modules.

The functions are made from :data:`NO_VALUE` (C name -> (device type, answer)); a device of the
type that the server does simulate (none today) would get real functions instead."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from sensorium.client.wb_robot import answers, current

_NAN = math.nan

NO_VALUE: dict[str, tuple[str, Any]] = {
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

