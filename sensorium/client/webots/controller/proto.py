"""Webots' ``controller.proto`` module (``from controller.proto import Proto``): the class lives in
``supervisor.py`` here."""

from .supervisor import Proto

__all__ = ["Proto"]
