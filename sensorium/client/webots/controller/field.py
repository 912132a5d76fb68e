"""Webots' ``controller.field`` module (``from controller.field import Field``): the class lives in
``supervisor.py`` here."""

from .supervisor import Field

__all__ = ["Field"]
