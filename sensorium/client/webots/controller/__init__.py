"""Webots' Python controller API on Sensorium: ``from controller import Robot`` works unchanged
once ``sensorium controller`` (or ``PYTHONPATH=<sensorium.client>/webots``) puts this package on
the path. State lives in :mod:`sensorium.client.wb`, so importing this package under both names
(``controller`` and ``sensorium.client.webots.controller``) still drives one robot."""

from sensorium.client.connection import SensoriumError

from .camera import Camera, CameraRecognitionObject
from .device import Device, Sensor
from .distance_sensor import DistanceSensor
from .keyboard import Keyboard
from .led import LED
from .lidar import Lidar, LidarPoint
from .light_sensor import LightSensor
from .motor import Motor, RotationalMotor
from .pen import Pen
from .position_sensor import PositionSensor
from .range_finder import RangeFinder
from .robot import Robot
from .supervisor import Field, Node, Supervisor

__all__ = ["LED", "Camera", "CameraRecognitionObject", "Device", "DistanceSensor", "Field", "Keyboard", "Lidar",
           "LidarPoint", "LightSensor", "Motor", "Node", "Pen", "PositionSensor", "RangeFinder", "Robot", "RotationalMotor",
           "Sensor", "SensoriumError", "Supervisor"]
