"""Webots' ``controller.node`` module (``from controller.node import Node``): the class lives in
``supervisor.py`` here."""

from .supervisor import ContactPoint, Node

__all__ = ["ContactPoint", "Node"]
