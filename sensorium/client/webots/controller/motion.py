"""Webots' ``Motion`` class: a ``.motion`` file played on the robot's motors, one pose interpolation
per ``robot.step`` (:mod:`sensorium.client.wb_motion`). A file that cannot be read or is damaged
prints one line and gives a motion whose ``isValid()`` is False; dropping the object deletes the
motion (it stops playing), as in Webots."""

from __future__ import annotations

import os

from sensorium.client import wb_motion


class Motion:
    def __init__(self, filename: str | os.PathLike[str]):
        self._ref = wb_motion.wbu_motion_new(filename)

    def __del__(self) -> None:
        ref, self._ref = getattr(self, "_ref", None), None
        if ref is not None:
            wb_motion.wbu_motion_delete(ref)

    def isValid(self) -> bool:
        return self._ref is not None

    def play(self) -> None:
        wb_motion.wbu_motion_play(self._ref)

    def stop(self) -> None:
        wb_motion.wbu_motion_stop(self._ref)

    def setLoop(self, loop: bool) -> None:
        wb_motion.wbu_motion_set_loop(self._ref, loop)

    def setReverse(self, reverse: bool) -> None:
        wb_motion.wbu_motion_set_reverse(self._ref, reverse)

    def isOver(self) -> bool:
        return wb_motion.wbu_motion_is_over(self._ref)

    def getDuration(self) -> int:
        return wb_motion.wbu_motion_get_duration(self._ref)

    def getTime(self) -> int:
        return wb_motion.wbu_motion_get_time(self._ref)

    def setTime(self, time: int) -> None:
        wb_motion.wbu_motion_set_time(self._ref, time)

    duration = property(getDuration)
    time = property(getTime, setTime)
