"""Webots' ``Car`` class: present for ``from vehicle import Car``; constructing it ends the
controller with one line (see the package docstring)."""

from __future__ import annotations

from .driver import Driver


class Car(Driver):
    TRACTION = 0
    PROPULSION = 1
    FOUR_BY_FOUR = 2
    COMBUSTION_ENGINE = 0
    ELECTRIC_ENGINE = 1
    PARALLEL_HYBRID_ENGINE = 2
    POWER_SPLIT_HYBRID_ENGINE = 3
    WHEEL_FRONT_RIGHT = 0
    WHEEL_FRONT_LEFT = 1
    WHEEL_REAR_RIGHT = 2
    WHEEL_REAR_LEFT = 3
    WHEEL_NB = 4
