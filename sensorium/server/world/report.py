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
        the warnings; messages repeated at several places (the same PROTO instantiated fifty times)
        are one line with their count and first place, unless ``every``."""
        out: list[str] = []
        if every:
            out += [f"lost {loss.label()}: {loss.text}" for loss in self.losses]
            out += [f"warning: {w}" for w in self.notes]
            return out
        groups: dict[tuple[str, str], list[tuple[str, str]]] = {}     # (head, message) -> (where, label)
        for loss in self.losses:
            where, msg = _split(loss.text)
            word = _KIND_WORDS[loss.kind][0] if loss.kind in _KIND_WORDS else loss.kind
            groups.setdefault(("lost " + word, msg), []).append((where, "lost " + loss.label()))
        for w in self.notes:
            where, msg = _split(w)
            groups.setdefault(("warning", msg), []).append((where, "warning"))
        for (head, msg), places in groups.items():
            where, label = places[0]
            if len(places) == 1:
                out.append(f"{label}: {where}: {msg}" if where else f"{label}: {msg}")
            else:
                out.append(f"{head} (x{len(places)}, first at {where}): {msg}")
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
