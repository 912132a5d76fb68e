"""Webots' Python controller API on Sensorium: ``from controller import Robot`` works unchanged
once ``sensorium controller`` (or ``PYTHONPATH=<sensorium.client>/webots``) puts this package on
the path. State lives in :mod:`sensorium.client.wb`, so importing this package under both names
(``controller`` and ``sensorium.client.webots.controller``) still drives one robot."""

from sensorium.client.connection import SensoriumError

from .accelerometer import Accelerometer
from .altimeter import Altimeter
from .ansi_codes import AnsiCodes
from .brake import Brake
from .camera import Camera, CameraRecognitionObject
from .compass import Compass
from .connector import Connector
from .device import Device, Sensor
from .display import Display
from .distance_sensor import DistanceSensor
from .emitter import Emitter
from .gps import GPS
from .gyro import Gyro
from .inertial_unit import InertialUnit
from .joystick import Joystick
from .keyboard import Keyboard
from .led import LED
from .lidar import Lidar, LidarPoint
from .light_sensor import LightSensor
from .motion import Motion
from .motor import LinearMotor, Motor, RotationalMotor
from .mouse import Mouse, MouseState
from .pen import Pen
from .position_sensor import PositionSensor
from .radar import Radar, RadarTarget
from .range_finder import RangeFinder
from .receiver import Receiver
from .robot import Robot
from .skin import Skin
from .speaker import Speaker
from .supervisor import ContactPoint, Field, Node, Supervisor
from .touch_sensor import TouchSensor
from .vacuum_gripper import VacuumGripper

__all__ = ["GPS", "LED", "Accelerometer", "Altimeter", "AnsiCodes", "Brake", "Camera", "CameraRecognitionObject",
           "Compass", "Connector", "ContactPoint", "Device", "Display", "DistanceSensor", "Emitter", "Field", "Gyro",
           "InertialUnit", "Joystick", "Keyboard", "Lidar", "LidarPoint", "LightSensor", "LinearMotor", "Motion",
           "Motor", "Mouse", "MouseState", "Node", "Pen", "PositionSensor", "Radar", "RadarTarget", "RangeFinder",
           "Receiver", "Robot", "RotationalMotor", "Sensor", "SensoriumError", "Skin", "Speaker", "Supervisor",
           "TouchSensor", "VacuumGripper"]
