"""Webots' ``controller.node`` module (``from controller.node import Node``): the class lives in
``supervisor.py`` here."""

from .supervisor import Node

__all__ = ["Node"]
