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
        """Enabled at ``sampling_period`` (the basic time step by default, as Webots); 0 leaves it off."""
        if sampling_period is None:
            sampling_period = int(wb.wb_robot_get_basic_time_step())
        if sampling_period:
            self.enable(sampling_period)

    def enable(self, p: int) -> None:
        wb.wb_keyboard_enable(p)

    def disable(self) -> None:
        wb.wb_keyboard_disable()

    def getSamplingPeriod(self) -> int:
        return wb.wb_keyboard_get_sampling_period()

    def getKey(self) -> int:
        return wb.wb_keyboard_get_key()

    def getKeyCode(self) -> int:
        return wb.wb_keyboard_get_key()

    def get_key(self) -> str:
        """Webots' text of the next key: modifiers first (``"shift-"``, ``"control-"``, and Webots'
        ``"atl-"`` for Alt), then the key's name or its character; ``""`` when no key is pressed."""
        k = wb.wb_keyboard_get_key()
        if k < 0:
            return ""
        text = "".join(prefix for bit, prefix in ((Keyboard.SHIFT, "shift-"), (Keyboard.CONTROL, "control-"),
                                                  (Keyboard.ALT, "atl-")) if k & bit)
        k &= Keyboard.KEY
        return text + _KEY_NAMES.get(k, chr(k))

    sampling_period = property(getSamplingPeriod, lambda self, p: self.enable(0 if p is None else p))


_KEY_NAMES = {Keyboard.END: "end", Keyboard.HOME: "home", Keyboard.LEFT: "left", Keyboard.RIGHT: "right",
              Keyboard.UP: "up", Keyboard.DOWN: "down", Keyboard.PAGEUP: "page up", Keyboard.PAGEDOWN: "page down",
              Keyboard.NUMPAD_END: "numpad end", Keyboard.NUMPAD_HOME: "numpad home",
              Keyboard.NUMPAD_LEFT: "numpad left", Keyboard.NUMPAD_RIGHT: "numpad right",
              Keyboard.NUMPAD_UP: "numpad up", Keyboard.NUMPAD_DOWN: "numpad down"}
