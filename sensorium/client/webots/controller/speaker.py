"""Webots' ``Speaker`` class (listed, not simulated: a headless server plays no sound)."""

from __future__ import annotations

from sensorium.client import wb

from .unsimulated import UnsimulatedDevice


class Speaker(UnsimulatedDevice):
    _KIND = "Speaker"
    _NO_VALUES = {"stop": None, "isSoundPlaying": False, "setEngine": False, "setLanguage": False,
                  "getEngine": "", "getLanguage": "", "speak": None, "isSpeaking": False}

    @staticmethod
    def playSound(left: Speaker, right: Speaker, sound: str, volume: float, pitch: float, balance: float,
                  loop: bool) -> None:
        wb.wb_speaker_play_sound(left._tag, right._tag, sound, volume, pitch, balance, loop)
