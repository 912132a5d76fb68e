"""Webots' ``Keyboard`` class. A headless server has no keyboard: ``getKey()`` is always -1."""

from __future__ import annotations

from sensorium.client import wb


class Keyboard:
    END = wb.WB_KEYBOARD_END
    HOME = wb.WB_KEYBOARD_HOME
    LEFT = wb.WB_KEYBOARD_LEFT
    UP = wb.WB_KEYBOARD_UP
    RIGHT = wb.WB_KEYBOARD_RIGHT
    DOWN = wb.WB_KEYBOARD_DOWN
    PAGEUP = wb.WB_KEYBOARD_PAGEUP
    PAGEDOWN = wb.WB_KEYBOARD_PAGEDOWN
    NUMPAD_HOME = wb.WB_KEYBOARD_NUMPAD_HOME
    NUMPAD_LEFT = wb.WB_KEYBOARD_NUMPAD_LEFT
    NUMPAD_UP = wb.WB_KEYBOARD_NUMPAD_UP
    NUMPAD_RIGHT = wb.WB_KEYBOARD_NUMPAD_RIGHT
    NUMPAD_DOWN = wb.WB_KEYBOARD_NUMPAD_DOWN
    NUMPAD_END = wb.WB_KEYBOARD_NUMPAD_END
    KEY = wb.WB_KEYBOARD_KEY
    SHIFT = wb.WB_KEYBOARD_SHIFT
    CONTROL = wb.WB_KEYBOARD_CONTROL
    ALT = wb.WB_KEYBOARD_ALT

    def __init__(self, sampling_period: int | None = None):
        if sampling_period is not None:
            self.enable(sampling_period)

    def enable(self, samplingPeriod: int) -> None:  # noqa: N803 - Webots' parameter name
        wb.wb_keyboard_enable(samplingPeriod)

    def disable(self) -> None:
        wb.wb_keyboard_disable()

    def getSamplingPeriod(self) -> int:
        return wb.wb_keyboard_get_sampling_period()

    def getKey(self) -> int:
        return wb.wb_keyboard_get_key()

    sampling_period = property(getSamplingPeriod)
