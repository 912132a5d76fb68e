"""Webots' ``controller.sensor`` module (``from controller.sensor import Sensor``): the class lives in
``device.py`` here."""

from .device import Sensor

__all__ = ["Sensor"]
