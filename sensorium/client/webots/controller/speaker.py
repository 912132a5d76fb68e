"""Webots' ``Speaker`` class: sounds and speech whose state follows the simulated time (a headless
server produces no audio; README "The Speaker")."""

from __future__ import annotations

from sensorium.client import wb

from .device import Device


class Speaker(Device):
    @staticmethod
    def playSound(left: Speaker | None, right: Speaker | None, sound: str, volume: float, pitch: float,
                  balance: float, loop: bool) -> None:
        wb.wb_speaker_play_sound(left._tag if left is not None else 0, right._tag if right is not None else 0,
                                 sound, volume, pitch, balance, loop)

    def stop(self, sound: str | None = None) -> None:
        wb.wb_speaker_stop(self._tag, sound)

    def isSoundPlaying(self, sound: str | None = None) -> bool:
        return wb.wb_speaker_is_sound_playing(self._tag, sound)

    def setEngine(self, engine: str) -> bool:
        return wb.wb_speaker_set_engine(self._tag, engine)

    def setLanguage(self, language: str) -> bool:
        """wb_speaker_set_language (Webots' Python class calls wb_speaker_set_engine here, so it answers
        False for every language: a slip not copied, README "VacuumGripper and Speaker")."""
        return wb.wb_speaker_set_language(self._tag, language)

    def getEngine(self) -> str:
        return wb.wb_speaker_get_engine(self._tag)

    def getLanguage(self) -> str:
        return wb.wb_speaker_get_language(self._tag)

    def speak(self, text: str, volume: float) -> None:
        wb.wb_speaker_speak(self._tag, text, volume)

    def isSpeaking(self) -> bool:
        return wb.wb_speaker_is_speaking(self._tag)
