"""Webots' ``controller.lidar_point`` module (``from controller.lidar_point import LidarPoint``): the class lives in
``lidar.py`` here."""

from .lidar import LidarPoint

__all__ = ["LidarPoint"]
