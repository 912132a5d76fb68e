"""Webots' functions of the devices Sensorium lists but does not simulate (Brake, Connector,
Display, Skin, Speaker, VacuumGripper): each checks its tag names a device of its type,
prints the device's one warning line and answers Webots' "no value" (NaN, ``None`` for NULL, 0,
False). Camera, RangeFinder and Pen have their own modules.

A Display draws nothing but answers its world size (``wb_display_get_width``/``get_height``, no
warning), and ``wb_display_image_new``/``image_copy`` give a usable image reference (a number that
``image_paste``/``image_save``/``image_delete`` take); ``wb_display_image_save`` says once per
Display that it writes no file.

The functions are made from :data:`NO_VALUE` (C name -> (device type, answer)); a device of the
type that the server does simulate (none today) would get real functions instead."""

from __future__ import annotations

import itertools
import math
import sys
from collections.abc import Callable
from typing import Any

from sensorium.client.wb_robot import answers, current

WB_BRAKE_ROTATIONAL = 0
WB_BRAKE_LINEAR = 1
WB_IMAGE_RGB = 3
WB_IMAGE_RGBA = 4
WB_IMAGE_ARGB = 5
WB_IMAGE_BGRA = 6
WB_IMAGE_ABGR = 7

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
    # Display
    "wb_display_set_color": ("Display", None),
    "wb_display_set_alpha": ("Display", None),
    "wb_display_set_opacity": ("Display", None),
    "wb_display_set_font": ("Display", None),
    "wb_display_attach_camera": ("Display", None),
    "wb_display_detach_camera": ("Display", None),
    "wb_display_draw_pixel": ("Display", None),
    "wb_display_draw_line": ("Display", None),
    "wb_display_draw_rectangle": ("Display", None),
    "wb_display_draw_oval": ("Display", None),
    "wb_display_draw_polygon": ("Display", None),
    "wb_display_draw_text": ("Display", None),
    "wb_display_fill_rectangle": ("Display", None),
    "wb_display_fill_oval": ("Display", None),
    "wb_display_fill_polygon": ("Display", None),
    "wb_display_image_load": ("Display", None),
    "wb_display_image_paste": ("Display", None),
    "wb_display_image_delete": ("Display", None),
    # Skin
    "wb_skin_set_bone_orientation": ("Skin", None),
    "wb_skin_set_bone_position": ("Skin", None),
    "wb_skin_get_bone_count": ("Skin", 0),
    "wb_skin_get_bone_name": ("Skin", ""),
    "wb_skin_get_bone_orientation": ("Skin", None),
    "wb_skin_get_bone_position": ("Skin", None),
    # Speaker
    "wb_speaker_stop": ("Speaker", None),
    "wb_speaker_is_sound_playing": ("Speaker", False),
    "wb_speaker_set_engine": ("Speaker", False),
    "wb_speaker_set_language": ("Speaker", False),
    "wb_speaker_get_engine": ("Speaker", ""),
    "wb_speaker_get_language": ("Speaker", ""),
    "wb_speaker_speak": ("Speaker", None),
    "wb_speaker_is_speaking": ("Speaker", False),
    # VacuumGripper
    "wb_vacuum_gripper_enable_presence": ("VacuumGripper", None),
    "wb_vacuum_gripper_disable_presence": ("VacuumGripper", None),
    "wb_vacuum_gripper_get_presence_sampling_period": ("VacuumGripper", 0),
    "wb_vacuum_gripper_get_presence": ("VacuumGripper", False),
    "wb_vacuum_gripper_turn_on": ("VacuumGripper", None),
    "wb_vacuum_gripper_turn_off": ("VacuumGripper", None),
    "wb_vacuum_gripper_is_on": ("VacuumGripper", False),
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


@answers(None)
def wb_speaker_play_sound(left: int, right: int, sound: str, volume: float, pitch: float, balance: float,
                          loop: bool) -> None:
    """No sound is played (a headless server)."""
    current().device(left, "Speaker", "wb_speaker_play_sound")
    if right and right != left:
        current().device(right, "Speaker", "wb_speaker_play_sound")


def _display(tag: int, func: str) -> Any:
    """The Display of ``tag`` (its description), without the "not simulated" line."""
    return current().device(tag, "Display", func, listed=True)


@answers(0)
def wb_display_get_width(tag: int) -> int:
    """The world's width (pixels) of the Display: it draws nothing, but its size is known."""
    return int(_display(tag, "wb_display_get_width").desc.get("width", 0))


@answers(0)
def wb_display_get_height(tag: int) -> int:
    """The world's height (pixels) of the Display."""
    return int(_display(tag, "wb_display_get_height").desc.get("height", 0))


_image_refs = itertools.count(1)


def _image_ref(tag: int, func: str) -> int | None:
    dev = _display(tag, func)
    current().warn_unsimulated(dev, func)
    return next(_image_refs)


@answers(None)
def wb_display_image_new(tag: int, width: int, height: int, data: Any = None, format: int = WB_IMAGE_RGB) -> int | None:
    """A usable image reference (nothing is stored: no image is drawn here)."""
    return _image_ref(tag, "wb_display_image_new")


@answers(None)
def wb_display_image_copy(tag: int, x: int, y: int, width: int, height: int) -> int | None:
    """A usable image reference (of no pixels: the Display draws nothing here)."""
    return _image_ref(tag, "wb_display_image_copy")


_save_warned: set[tuple[int, int]] = set()


@answers(None)
def wb_display_image_save(tag: int, ref: Any, filename: str) -> None:
    """No file is written (nothing is drawn); said once per Display, naming the file."""
    c = current()
    dev = _display(tag, "wb_display_image_save")
    c.warn_unsimulated(dev, "wb_display_image_save")
    if (id(c), dev.tag) not in _save_warned:
        _save_warned.add((id(c), dev.tag))
        print(f"Warning: wb_display_image_save(): Display '{dev.name}' draws no image here: "
              f"{str(filename)!r} is not written.", file=sys.stderr)
