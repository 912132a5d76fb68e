"""Webots' motion files (``wbu_motion_*``): a ``.motion`` file's poses played on a robot's motors.

As in libController, playback is client side: every ``wb_robot_step`` (its ``step_begin``), each
playing motion first sets its motors' target positions for its current time (linear interpolation
between the two poses around it; ``*`` leaves a motor alone), then moves its time on by the step's
duration. The positions travel with that step's request, so the joints move during it (README
"Joints"). The C library (``client/c/src/motion.c``) follows the same rules and bounds, and prints
the same lines.

A file: a header ``#WEBOTS_MOTION,V1.0,<motor>,<motor>…`` then one line per pose
``[[mm:]ss:]mmm,<pose name>,<value or *>,…`` with strictly increasing times; an empty line ends the
poses. Fields are separated by commas; empty fields are skipped (Webots' tokenizer). A damaged file
prints one line naming the file and the line and gives no motion (Webots' NULL, Python ``None``).
"""

from __future__ import annotations

import math
import os
import re
import sys
from array import array
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, BinaryIO

from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_motor import wb_motor_set_position
from sensorium.client.wb_robot import LINEAR_MOTOR, ROTATIONAL_MOTOR, RobotClient, c_string, current, integer

__all__ = ["MotionFile", "MotionFileError", "MotionPlayer", "parse_motion", "wbu_motion_delete",
           "wbu_motion_get_duration", "wbu_motion_get_time", "wbu_motion_is_over", "wbu_motion_new",
           "wbu_motion_play", "wbu_motion_set_loop", "wbu_motion_set_reverse", "wbu_motion_set_time",
           "wbu_motion_stop"]

# What a file may ask for (the C library's bounds are the same).
MAX_LINE = 4094            # characters (bytes) a line may hold, its end of line not counted (Webots reads 4095)
MAX_VALUES = 1_000_000     # poses x motors
MAX_TIME_MS = 1_000_000_000  # a pose's time, so that a motion's clock never overflows a C int
INT_MIN, INT_MAX = -(2 ** 31), 2 ** 31 - 1

HEADER, VERSION = "#WEBOTS_MOTION", "V1.0"
_TIME = re.compile(r"[0-9]+(?::[0-9]+){0,2}")
_NUMBER = re.compile(r"[ \t]*[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?[ \t]*")
_FIELDS = re.compile(r"[,\r]")
_NEW = "wbu_motion_new"


class MotionFileError(ValueError):
    """A motion file Sensorium does not play; the message is the one line printed."""


@dataclass(frozen=True, slots=True)
class MotionFile:
    """A parsed file: the motors of its columns, the time (ms) of each pose, and the values row by
    row (``len(times) * len(motors)`` of them; NaN where the file says ``*``)."""
    motors: tuple[str, ...]
    times: tuple[int, ...]
    values: array


def _tokens(line: bytes) -> list[str]:
    return [t for t in _FIELDS.split(line.decode("utf-8", "replace")) if t]


def _time(token: str) -> int | None:
    """``[[mm:]ss:]mmm`` in ms; None if it is not that."""
    if not _TIME.fullmatch(token):
        return None
    parts = [int(p) for p in token.split(":")]
    parts = [0] * (3 - len(parts)) + parts
    return parts[0] * 60000 + parts[1] * 1000 + parts[2]


def _lines(stream: BinaryIO, fail: Callable[[int, str], MotionFileError]) -> Iterator[tuple[int, bytes]]:
    """(line number, line without its end of line), read at most ``MAX_LINE`` + 2 bytes at a time."""
    number = 0
    while True:
        raw = stream.readline(MAX_LINE + 2)
        if not raw:
            return
        number += 1
        line = raw[:-1] if raw.endswith(b"\n") else raw
        if len(line) > MAX_LINE:
            raise fail(number, f"longer than {MAX_LINE} characters")
        if b"\0" in line:
            raise fail(number, "holds a NUL character")
        yield number, line


def parse_motion(stream: BinaryIO, filename: str) -> MotionFile:
    """Parse a motion file read from ``stream``; raise :class:`MotionFileError` (one line) if it is
    damaged or asks for more than the bounds."""
    def fail(line: int, what: str) -> MotionFileError:
        return MotionFileError(f"Error: {_NEW}(): file '{filename}', line {line}: {what}.")

    lines = _lines(stream, fail)
    first = next(lines, None)
    if first is None:
        raise MotionFileError(f"Error: {_NEW}(): file '{filename}' is empty.")
    header = _tokens(first[1])
    if not header or header[0] != HEADER:
        raise fail(1, f"expected the header '{HEADER},{VERSION},<motor names>' but found "
                      f"'{header[0] if header else ''}'")
    if len(header) < 2 or header[1] != VERSION:
        raise fail(1, f"unsupported version '{header[1] if len(header) > 1 else ''}' (Sensorium reads {VERSION})")
    motors = tuple(header[2:])
    if not motors:
        raise fail(1, "no motor names after the version")
    times: list[int] = []
    values = array("d")
    for number, line in lines:
        tokens = _tokens(line)
        if not tokens:                               # an empty line ends the poses (Webots)
            for later, rest in lines:
                if _tokens(rest):
                    print(f"Warning: {_NEW}(): file '{filename}', line {later}: ignored with every line after the "
                          f"empty line {number} (an empty line ends the poses, as in Webots).", file=sys.stderr)
                    break
            break
        t = _time(tokens[0])
        if t is None:
            raise fail(number, f"expected a time ([[mm:]ss:]mmm) but found '{tokens[0]}'")
        if t > MAX_TIME_MS:
            raise fail(number, f"time '{tokens[0]}' is beyond {MAX_TIME_MS} ms")
        if times and t <= times[-1]:
            raise fail(number, f"time '{tokens[0]}' is not after the previous pose's ({times[-1]} ms)")
        if len(tokens) < 2:
            raise fail(number, "pose name expected")
        if len(tokens) < 2 + len(motors):
            raise fail(number, f"{len(tokens) - 2} values for {len(motors)} motors")
        if len(tokens) > 2 + len(motors):
            raise fail(number, f"unexpected extra data '{tokens[2 + len(motors)]}' after {len(motors)} values")
        if (len(times) + 1) * len(motors) > MAX_VALUES:
            raise fail(number, f"more than {MAX_VALUES} values (poses x motors)")
        for token in tokens[2:]:
            if token == "*":
                values.append(math.nan)
                continue
            v = float(token) if _NUMBER.fullmatch(token) else math.nan
            if not math.isfinite(v):
                raise fail(number, f"expected a number or '*' but found '{token}'")
            values.append(v)
        times.append(t)
    if not times:
        raise MotionFileError(f"Error: {_NEW}(): file '{filename}' has no pose.")
    return MotionFile(motors, tuple(times), values)


class MotionPlayer:
    """One loaded motion's playback state (Webots' rules, no I/O): :meth:`positions` then
    :meth:`advance` each step while it plays."""

    __slots__ = ("file", "filename", "tags", "elapsed", "playing", "reverse", "loop", "deleted", "__weakref__")

    def __init__(self, file: MotionFile, filename: str, tags: list[int]):
        self.file = file
        self.filename = filename
        self.tags = tags               # each column's motor tag, 0 if the robot has no such motor
        self.elapsed = 0               # ms
        self.playing = self.reverse = self.loop = self.deleted = False

    @property
    def duration(self) -> int:
        return self.file.times[-1]

    def position(self, column: int) -> float:
        """The column's motor position at the current time; NaN where the poses around it leave
        the motor alone."""
        f, e = self.file, self.elapsed
        n, times, values = len(f.motors), f.times, f.values
        if e <= times[0]:
            return values[column]
        last = len(times) - 1
        if e >= times[last]:
            return values[last * n + column]
        a = 0
        while not times[a] <= e <= times[a + 1]:
            a += 1
        pa, pb = values[a * n + column], values[(a + 1) * n + column]
        # the same operations in the same order as the C library's: the same bits
        return pa + (e - times[a]) * (pb - pa) / (times[a + 1] - times[a])

    def positions(self) -> list[tuple[int, float]]:
        """(motor tag, position) for each column this step sets."""
        out = []
        for column, tag in enumerate(self.tags):
            if tag:
                p = self.position(column)
                if not math.isnan(p):
                    out.append((tag, p))
        return out

    def advance(self, millis: int) -> None:
        d = self.duration
        if self.reverse:
            if self.elapsed <= 0:
                if self.loop:
                    self.elapsed = d
                else:
                    self.elapsed, self.playing = 0, False
            else:
                self.elapsed -= millis
        elif self.elapsed >= d:
            if self.loop:
                self.elapsed = 0
            else:
                self.elapsed, self.playing = d, False
        else:
            self.elapsed += millis

    def is_over(self) -> bool:
        if self.loop:
            return False
        return self.elapsed <= 0 if self.reverse else self.elapsed >= self.duration


# ---------------------------------------------------------------------- the playing motions
# Newest first, as libController's list: when two motions set one motor, the older one sets it
# last and wins.
_motions: list[MotionPlayer] = []
_robot: RobotClient | None = None


def _step_all(millis: int) -> None:
    if millis <= 0:
        return
    for m in list(_motions):
        if m.playing:
            for tag, position in m.positions():
                wb_motor_set_position(tag, position)
            m.advance(millis)


def _hooked() -> RobotClient:
    """The robot, with the playing motions stepped before each of its steps."""
    global _robot
    r = current()
    if r is not _robot:
        for m in _motions:               # motions of an earlier session drive nothing now
            m.deleted = True
        _motions.clear()
        _robot = r
        r.step_hooks.append(_step_all)
    return r


def wbu_motion_new(filename: Any) -> MotionPlayer | None:
    """Load a motion file; None (one line printed) if it cannot be read or is damaged."""
    filename = c_string(filename)
    if isinstance(filename, os.PathLike):
        filename = os.fspath(filename)
    if not isinstance(filename, str) or not filename:
        print(f"Error: {_NEW}() called with NULL or empty 'filename' argument.", file=sys.stderr)
        return None
    r = _hooked()
    try:
        with open(filename, "rb") as fh:
            file = parse_motion(fh, filename)
    except OSError:
        print(f"Error: {_NEW}(): could not open '{filename}' file.", file=sys.stderr)
        return None
    except MotionFileError as exc:
        print(exc, file=sys.stderr)
        return None
    tags = []
    for name in file.motors:
        dev = r.by_name.get(name)
        if dev is None:
            print(f"Warning: {_NEW}(): ignoring motor '{name}' of file '{filename}': robot '{r.name}' has no such "
                  f"device.", file=sys.stderr)
            tags.append(0)
        elif dev.kind not in (ROTATIONAL_MOTOR, LINEAR_MOTOR):
            print(f"Warning: {_NEW}(): ignoring '{name}' of file '{filename}': it is a {dev.kind}, not a motor.",
                  file=sys.stderr)
            tags.append(0)
        else:
            tags.append(dev.tag)
    player = MotionPlayer(file, filename, tags)
    _motions.insert(0, player)
    return player


def _valid(motion: Any, func: str, what: str = "argument") -> MotionPlayer | None:
    """``motion`` if it is a live motion; else None, after Webots' line for NULL (or ours for a
    deleted one)."""
    if isinstance(motion, MotionPlayer):
        if not motion.deleted:
            return motion
        print(f"Error: {func}(): not a motion (deleted?).", file=sys.stderr)
        return None
    if motion is None:
        print(f"Error: {func}() called with NULL {what}.", file=sys.stderr)
        return None
    raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): not a motion: {motion!r}")


def wbu_motion_delete(motion: MotionPlayer | None) -> None:
    if motion is None:
        return
    if not isinstance(motion, MotionPlayer) or motion.deleted or motion not in _motions:
        print("Error: wbu_motion_delete(): attempt to delete an invalid 'motion'.", file=sys.stderr)
        return
    motion.deleted = True
    _motions.remove(motion)


def wbu_motion_play(motion: MotionPlayer | None) -> None:
    """Play from the current time; from the other end if it is at the end it plays towards."""
    m = _valid(motion, "wbu_motion_play", "'motion' argument")
    if m is None:
        return
    m.playing = True
    if m.reverse and m.elapsed <= 0:
        m.elapsed = m.duration
    elif not m.reverse and m.elapsed >= m.duration:
        m.elapsed = 0


def wbu_motion_stop(motion: MotionPlayer | None) -> None:
    m = _valid(motion, "wbu_motion_stop")
    if m is not None:
        m.playing = False


def wbu_motion_set_loop(motion: MotionPlayer | None, loop: bool) -> None:
    m = _valid(motion, "wbu_motion_set_loop")
    if m is not None:
        m.loop = bool(loop)


def wbu_motion_set_reverse(motion: MotionPlayer | None, reverse: bool) -> None:
    m = _valid(motion, "wbu_motion_set_reverse")
    if m is not None:
        m.reverse = bool(reverse)


def wbu_motion_is_over(motion: MotionPlayer | None) -> bool:
    m = _valid(motion, "wbu_motion_is_over")
    return False if m is None else m.is_over()


def wbu_motion_get_duration(motion: MotionPlayer | None) -> int:
    m = _valid(motion, "wbu_motion_get_duration")
    return -1 if m is None else m.duration


def wbu_motion_get_time(motion: MotionPlayer | None) -> int:
    m = _valid(motion, "wbu_motion_get_time")
    return -1 if m is None else max(INT_MIN, min(INT_MAX, m.elapsed))


def wbu_motion_set_time(motion: MotionPlayer | None, time: int) -> None:
    m = _valid(motion, "wbu_motion_set_time")
    if m is None:
        return
    t = integer(time)
    if t is None:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wbu_motion_set_time(): 'time' must be an integer (ms), "
                                                         f"got {time!r}")
    m.elapsed = max(0, min(m.duration, t))
