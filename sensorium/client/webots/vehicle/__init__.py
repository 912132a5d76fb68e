"""Webots' Python ``vehicle`` package (``from vehicle import Driver, Car``) on Sensorium.

Sensorium does not simulate Webots' vehicle library: its robots move kinematically by two-wheel or
skid-steer drives only, so a car-like robot with steered wheels is not driven. The classes import
(with Webots' constants) so a controller file loads; constructing one prints one line saying why and
exits with status 1, before any connection to a server (no wait, no traceback) — as the C library's
``wbu_driver_init()`` / ``wbu_car_init()`` do."""

from .car import Car
from .driver import Driver

__all__ = ["Car", "Driver"]
