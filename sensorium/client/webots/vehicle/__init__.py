"""Webots' Python ``vehicle`` package (``from vehicle import Driver, Car``) on Sensorium.

A car-like robot (its world entry's ``ackermann_drive``, or a .wbt car mapped to one) is driven
through its ordinary motors: ``Driver.setSteeringAngle`` sets the two steering motors to Webots'
Ackermann angles, ``setCruisingSpeed`` the driven wheels' velocities by Webots' geometric
differentials. The brake intensity, indicators, lights and the car's flags are kept and answered as
Webots' library keeps them (the car's LEDs of Webots' names switched for them). There is no engine,
gearbox or torque control model: those functions print one line the first time and answer
Webots' "no value"; the steering wheel, speedometer needle and wipers turn as Webots' library turns them. On a robot without an ``ackermann_drive`` the constructor prints one line and
exits with status 1."""

from .car import Car
from .driver import Driver

__all__ = ["Car", "Driver"]
