"""Webots' ``controller.radar_target`` module (``from controller.radar_target import RadarTarget``): the class lives in
``radar.py`` here."""

from .radar import RadarTarget

__all__ = ["RadarTarget"]
