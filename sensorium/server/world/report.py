"""What loading a world left out, said once: the losses sensors would notice and the other warnings.

A world file Sensorium cannot take whole still loads; what it left out is either a **loss** — a
robot, a sensor device, or a shape or solid that sensors see, so readings differ from Webots' — or
a plain **warning** (visual- or physics-only differences, notes about stand-ins, renames). Every
command that loads a world shows the same :class:`LoadReport`: ``validate`` lists each loss and
exits non-zero for them (``--allow-skipped`` accepts them), ``serve``/``probe``/``demo`` print it
once, grouped and counted; in process it is ``LoadedWorld.report`` (and one
:class:`WorldLossWarning` when something was lost).
"""

from __future__ import annotations

import re
import warnings
from collections import Counter
from dataclasses import dataclass

__all__ = ["Loss", "LoadReport", "WorldLossWarning", "warn_losses", "dropped_robot_note"]

KINDS = ("robot", "device", "solid", "shape", "node")
_KIND_WORDS = {"robot": ("robot", "robots"), "device": ("device", "devices"), "solid": ("solid", "solids"),
               "shape": ("shape", "shapes"), "node": ("unknown node", "unknown nodes")}
# "file:line:col (in PROTO X at file:line:col): message" or "file: message"
_WHERE = re.compile(r"^(?P<where>.+?:\d+:\d+(?: \(in PROTO [^)]*\))?): (?P<msg>.*)$", re.S)


class WorldLossWarning(UserWarning):
    """A world was loaded without something sensors would notice (a robot, a device, a shape)."""


@dataclass(frozen=True, slots=True)
class Loss:
    """One thing left out that sensors would notice: ``kind`` (robot, device, solid, shape, or an
    unknown node that could have been any of them), its ``name`` when known, ``where`` it is written
    (``file:line:col``, and the PROTO instance that brought it) and ``why``."""

    kind: str
    name: str                # a shape's: the solid or robot it belonged to
    where: str
    why: str
    robot: str = ""          # the robot a lost device belonged to

    @property
    def text(self) -> str:
        return f"{self.where}: {self.why}"

    def label(self) -> str:
        """``robot 'e-puck'``, ``device 'ps0' of robot 'r'``, ``shape of 'table'``, ``unknown node 'E-puck'``."""
        word = _KIND_WORDS.get(self.kind, (self.kind, self.kind))[0]
        if self.kind == "shape":          # a shape's name is the solid or robot it belonged to
            return f"shape of {self.name!r}" if self.name else word
        out = f"{word} {self.name!r}" if self.name else word
        return out + (f" of robot {self.robot!r}" if self.robot else "")


def _split(text: str) -> tuple[str, str]:
    m = _WHERE.match(text)
    if m:
        return m.group("where"), m.group("msg")
    where, sep, msg = text.partition(": ")
    return (where, msg) if sep else ("", text)


# a robot named in a message, as the loaders write it: robot 'name' (repr: double quotes when it holds one)
_ROBOT = re.compile(r"""\brobot ('(?:[^'\\]|\\.)*'|"(?:[^"\\]|\\.)*")""")
_NAMED = "\x00"  # where a robot's name was taken out of a message
_SHOWN = 3      # places and robot names a folded line shows before "and N more"


def _robot_names(msg: str) -> tuple[str, tuple[str, ...]]:
    """``msg`` with each robot it names taken out (``_NAMED``), and those names (as written, quoted)."""
    if _NAMED in msg:               # a name written with a NUL in it: folded only with its exact repeats
        return msg, ()
    return _ROBOT.sub(_NAMED, msg), tuple(m.group(1) for m in _ROBOT.finditer(msg))


def _listed(names: list[str], one: str, many: str) -> str:
    """``robot 'a'`` or ``robots 'a', 'b', 'c' and 7 more``."""
    if len(names) == 1:
        return f"{one} {names[0]}"
    if len(names) > _SHOWN:
        return f"{many} {', '.join(names[:_SHOWN])} and {len(names) - _SHOWN} more"
    return f"{many} {', '.join(names[:-1])} and {names[-1]}"


def _places(places: list[str]) -> str:
    """``first at A; then B, C and 7 more``: a place inside a PROTO instance is shortened to what
    differs from the first place: the instance's own place when the line in the PROTO file is the
    same (fifty instances of one PROTO), the line in the PROTO file when the instance is."""
    first = places[0]
    inner, sep0, outer = first.partition(" (in PROTO ")
    rest = []
    for place in places[1:_SHOWN]:
        head, sep, instance = place.partition(" (in PROTO ")
        if sep and sep0 and head == inner and instance.endswith(")"):
            place = "PROTO " + instance[:-1]
        elif sep and sep0 and instance == outer:
            place = head
        rest.append(place)
    text = f"first at {first}" if first else "first without a place"
    more = len(places) - _SHOWN
    if rest:
        text += "; then " + ", ".join(rest) + (f" and {more} more" if more > 0 else "")
    return text


def _count(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


@dataclass(frozen=True)
class LoadReport:
    """The losses and warnings of one world load. ``warnings`` holds every message, losses
    included (in the order they were found); ``losses`` the structured losses."""

    source: str
    losses: tuple[Loss, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def notes(self) -> list[str]:
        """The warnings that are not losses."""
        lost = {loss.text for loss in self.losses}
        return [w for w in self.warnings if w not in lost]

    def __bool__(self) -> bool:
        return bool(self.losses or self.warnings)

    def counts(self) -> str:
        """``2 losses sensors notice (1 robot, 1 shape) and 3 warnings``."""
        parts = []
        if self.losses:
            by = Counter(loss.kind for loss in self.losses)
            kinds = ", ".join(_count(by[k], *_KIND_WORDS[k]) for k in KINDS if by[k])
            parts.append(f"{_count(len(self.losses), 'loss', 'losses')} sensors notice ({kinds})")
        notes = self.notes
        if notes:
            parts.append(_count(len(notes), "warning", "warnings"))
        return " and ".join(parts) or "nothing left out"

    def lines(self, *, every: bool = False) -> list[str]:
        """The report as lines (without the header): each loss as ``lost <what>: where: why``, then
        the warnings. Unless ``every``, messages repeated at several places are one line with their
        count and first places (the same PROTO instantiated fifty times), and so are messages the same
        but for the robot they name (ten robots of one kind: ``robots 'e1', 'e2', 'e3' and 7 more``)."""
        out: list[str] = []
        if every:
            out += [f"lost {loss.label()}: {loss.text}" for loss in self.losses]
            out += [f"warning: {w}" for w in self.notes]
            return out
        # (head, message with its robot names taken out) -> [(where, label, message, names)]
        groups: dict[tuple[str, str], list[tuple[str, str, str, tuple[str, ...]]]] = {}
        for loss in self.losses:
            where, msg = _split(loss.text)
            word = _KIND_WORDS[loss.kind][0] if loss.kind in _KIND_WORDS else loss.kind
            shape, names = _robot_names(msg)
            groups.setdefault(("lost " + word, shape), []).append((where, "lost " + loss.label(), msg, names))
        for w in self.notes:
            where, msg = _split(w)
            shape, names = _robot_names(msg)
            groups.setdefault(("warning", shape), []).append((where, "warning", msg, names))
        for (head, shape), places in groups.items():
            where, label, msg, _ = places[0]
            if len(places) == 1:
                out.append(f"{label}: {where}: {msg}" if where else f"{label}: {msg}")
                continue
            slots = [_listed(list(dict.fromkeys(p[3][i] for p in places)), "robot", "robots")
                     for i in range(len(places[0][3]))]
            pieces = shape.split(_NAMED)
            msg = pieces[0] + "".join(slot + piece for slot, piece in zip(slots, pieces[1:], strict=True))
            out.append(f"{head} (x{len(places)}, {_places([p[0] for p in places])}): {msg}")
        return out

    def text(self, *, every: bool = False) -> str:
        """A header line with the counts, then :meth:`lines` indented."""
        return "\n".join([f"{self.source}: {self.counts()}", *(f"  {line}" for line in self.lines(every=every))])

    def dropped_robots(self) -> list[Loss]:
        """The losses that were, or could have been, robots (unknown nodes)."""
        return [loss for loss in self.losses if loss.kind in ("robot", "node")]


def dropped_robot_note(report: LoadReport | None, robot: str) -> str:
    """Why ``robot`` is not in the world, when the load dropped it (or dropped unknown nodes that
    may have been it): one clause for an attach error, or "" when nothing was dropped."""
    if report is None:
        return ""
    candidates = report.dropped_robots()
    if not candidates:
        return ""
    named = [loss for loss in candidates if loss.name == robot]
    if named:
        return f"; it was dropped when the world loaded: {named[0].text}"
    shown = "; ".join(f"{loss.label()} at {loss.text}" for loss in candidates[:3])
    more = f" (and {len(candidates) - 3} more)" if len(candidates) > 3 else ""
    return f"; the world lost {_count(len(candidates), 'node', 'nodes')} that may have been it when it loaded: {shown}{more}"


def warn_losses(report: LoadReport, stacklevel: int = 3) -> None:
    """In process: one :class:`WorldLossWarning` naming what sensors would miss (nothing when the
    world loaded whole; plain warnings stay on ``LoadedWorld.warnings``)."""
    if report.losses:
        warnings.warn(report.text(), WorldLossWarning, stacklevel=stacklevel)
