"""Webots' ``Driver`` class: present for ``from vehicle import Driver``; constructing it ends the
controller with one line (see the package docstring)."""

from __future__ import annotations

from sensorium.client.webots.controller.supervisor import Supervisor


def refuse(cls: str) -> SystemExit:
    """The one-line exit a vehicle constructor raises (status 1; the same words as the C library)."""
    return SystemExit(f"Error: {cls}(): Sensorium does not simulate Webots' vehicle library (Car, Driver): its robots "
                      "move kinematically by two-wheel or skid-steer drives only, so a car-like robot with steered "
                      "wheels is not driven.")


class Driver(Supervisor):
    INDICATOR_OFF = 0
    INDICATOR_RIGHT = 1
    INDICATOR_LEFT = 2
    SPEED = 0
    TORQUE = 1
    DOWN = 0
    SLOW = 1
    NORMAL = 2
    FAST = 3

    def __init__(self) -> None:  # raises before Supervisor.__init__ would look for a server
        raise refuse(type(self).__name__)
