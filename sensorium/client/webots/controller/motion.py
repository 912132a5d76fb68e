"""Webots' ``Motion`` class (a ``.motion`` file played on a robot's motors). Sensorium's robots have
no joints to animate: a motion loads nothing and never plays (one warning), its getters answer
Webots' "no value"."""

from __future__ import annotations

import sys


class Motion:
    _warned = False

    def __init__(self, filename: str):
        self.filename = filename
        if not Motion._warned:
            Motion._warned = True
            print(f"Warning: Motion({filename!r}): Sensorium does not play motion files (no joints to animate).",
                  file=sys.stderr)

    def isValid(self) -> bool:
        return False

    def play(self) -> None:
        pass

    def stop(self) -> None:
        pass

    def setLoop(self, loop: bool) -> None:
        pass

    def setReverse(self, reverse: bool) -> None:
        pass

    def isOver(self) -> bool:
        return True

    def getDuration(self) -> int:
        return -1

    def getTime(self) -> int:
        return -1

    def setTime(self, time: int) -> None:
        pass

    duration = property(getDuration)
    time = property(getTime, setTime)
