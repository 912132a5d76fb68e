"""Webots' resets of field values it will not use, as rules: a .wbt world loads as in Webots.

Webots does not refuse a world for a bad number: each node's ``sanitizeFields`` (or ``update...``)
resets the field with a warning (``WbFieldChecker``), and every SFColor or MFColor is clamped to
[0, 1] as it is read. Each rule here says whether a value is one Webots uses and, if not, which
value it uses instead and a few words on what was wrong. ``Fields`` (fields.py) applies them and
says each correction once; the native YAML/JSON format keeps refusing the same values.

A rule returns ``(value used, "")`` for a good value, else ``(value used, what was wrong)``.
Which node uses which rule (and reset value) is where the node is read (fields.py, convert.py).
"""

from __future__ import annotations

from collections.abc import Sequence


def positive(value: float, reset: float) -> tuple[float, str]:
    """``> 0``, else ``reset`` (WbFieldChecker's reset-if-non-positive)."""
    return (value, "") if value > 0 else (reset, "is not > 0")


def non_negative(value: float, reset: float) -> tuple[float, str]:
    """``>= 0``, else ``reset`` (reset-if-negative)."""
    return (value, "") if value >= 0 else (reset, "is negative")


def within(value: float, lo: float, hi: float, reset: float) -> tuple[float, str]:
    """Within ``[lo, hi]``, else ``reset`` (reset-if-not-in-range-with-included-bounds)."""
    return (value, "") if lo <= value <= hi else (reset, f"is outside [{lo:g}, {hi:g}]")


def positive_vector(value: Sequence[float], reset: tuple[float, ...]) -> tuple[tuple[float, ...], str]:
    """Every component ``> 0``, else the whole vector is ``reset`` (reset-vector-if-non-positive)."""
    if all(v > 0 for v in value):
        return tuple(value), ""
    return reset, "has a component that is not > 0"


def color(value: Sequence[float]) -> tuple[tuple[float, ...], str]:
    """Each component clamped to [0, 1] (an SFColor or MFColor item as Webots reads it)."""
    clamped = tuple(min(max(v, 0.0), 1.0) for v in value)
    return (clamped, "") if clamped == tuple(value) else (clamped, "is outside [0, 1]")


def shown(value: str | float | Sequence[float]) -> str:
    """A value as the .wbt file writes it: ``0``, ``1 -1 1``, ``"planar"``."""
    if isinstance(value, str):
        return '"' + value + '"'
    if isinstance(value, int | float):
        return f"{value:g}"
    return " ".join(f"{v:g}" for v in value)
