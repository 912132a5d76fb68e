"""Webots' ``Pen`` class: the generic shape of a listed device (every method answers Webots' "no
value" with one warning). Issue 21 replaces this file with the simulated pen."""

from __future__ import annotations

from .unsimulated import UnsimulatedDevice


class Pen(UnsimulatedDevice):
    _KIND = "Pen"
    _NO_VALUES = {"write": None, "setInkColor": None}
