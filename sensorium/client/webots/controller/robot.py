"""Webots' ``Robot`` class: one per controller process."""

from __future__ import annotations

import sys
from typing import Any

from sensorium.client import wb

from .accelerometer import Accelerometer
from .altimeter import Altimeter
from .brake import Brake
from .camera import Camera
from .compass import Compass
from .connector import Connector
from .device import Device
from .display import Display
from .distance_sensor import DistanceSensor
from .emitter import Emitter
from .gps import GPS
from .gyro import Gyro
from .inertial_unit import InertialUnit
from .joystick import Joystick
from .keyboard import Keyboard
from .led import LED
from .lidar import Lidar
from .light_sensor import LightSensor
from .motor import LinearMotor, RotationalMotor
from .mouse import Mouse
from .pen import Pen
from .position_sensor import PositionSensor
from .radar import Radar
from .range_finder import RangeFinder
from .receiver import Receiver
from .skin import Skin
from .speaker import Speaker
from .touch_sensor import TouchSensor
from .vacuum_gripper import VacuumGripper

# Webots' device classes by node type name (every device type a robot may have)
_CLASSES: dict[str, type[Device]] = {cls.__name__: cls for cls in (
    Accelerometer, Altimeter, Brake, Camera, Compass, Connector, Display, DistanceSensor, Emitter, GPS, Gyro,
    InertialUnit, LED, Lidar, LightSensor, LinearMotor, Pen, PositionSensor, Radar, RangeFinder, Receiver,
    RotationalMotor, Skin, Speaker, TouchSensor, VacuumGripper)}


class Robot:
    """Attaches to the robot named by ``SENSORIUM_CONTROLLER_URL`` (or ``WEBOTS_CONTROLLER_URL``).

    As in Webots, a second ``Robot()`` (or ``Supervisor()``) in the same process prints an error;
    here it then shares the first one's state, so it keeps working."""

    created: Robot | None = None

    EVENT_QUIT = wb.WB_EVENT_QUIT
    EVENT_NO_EVENT = wb.WB_EVENT_NO_EVENT
    EVENT_MOUSE_CLICK = wb.WB_EVENT_MOUSE_CLICK
    EVENT_MOUSE_MOVE = wb.WB_EVENT_MOUSE_MOVE
    EVENT_KEYBOARD = wb.WB_EVENT_KEYBOARD
    EVENT_JOYSTICK_BUTTON = wb.WB_EVENT_JOYSTICK_BUTTON
    EVENT_JOYSTICK_AXIS = wb.WB_EVENT_JOYSTICK_AXIS
    EVENT_JOYSTICK_POV = wb.WB_EVENT_JOYSTICK_POV
    MODE_SIMULATION = wb.WB_MODE_SIMULATION
    MODE_CROSS_COMPILATION = wb.WB_MODE_CROSS_COMPILATION
    MODE_REMOTE_CONTROL = wb.WB_MODE_REMOTE_CONTROL

    def __init__(self) -> None:
        if Robot.created is not None:
            print("Error: only one Robot instance can be created per controller process.", file=sys.stderr)
            self.__dict__ = Robot.created.__dict__
            return
        wb.wb_robot_init()
        Robot.created = self
        self.keyboard = Keyboard(0)         # 0: not enabled (Webots' Keyboard() enables at the basic time step)
        self.mouse = Mouse(0)
        self.joystick = Joystick(0)
        self.devices: dict[str, Device] = {}
        for i in range(wb.wb_robot_get_number_of_devices()):
            tag = wb.wb_robot_get_device_by_index(i)
            # a type this client has no class for (a newer server's) is still present as a Device
            cls = _CLASSES.get(wb.wb_device_get_type_name(tag), Device)
            self.devices[wb.wb_device_get_name(tag)] = cls(tag)

    # -- stepping
    def step(self, time_step: int | None = None) -> int:
        """Run ``time_step`` ms of simulated time (default: the basic time step); -1 when the
        simulation ends."""
        return wb.wb_robot_step(time_step)

    def stepBegin(self, time_step: int | None = None) -> int:
        return wb.wb_robot_step_begin(time_step)

    def stepEnd(self) -> int:
        return wb.wb_robot_step_end()

    # -- devices
    def getDevice(self, name: str) -> Device | None:
        dev = self.devices.get(name)
        if dev is None:
            print(f'Device "{name}" was not found on robot "{self.getName()}"', file=sys.stderr)
        return dev

    def getDeviceByIndex(self, index: int) -> Device | None:
        tag = wb.wb_robot_get_device_by_index(index)
        return self.devices.get(wb.wb_device_get_name(tag)) if tag else None

    def getNumberOfDevices(self) -> int:
        return wb.wb_robot_get_number_of_devices()

    def _deprecated(self, method: str, name: str) -> Device | None:
        print(f"DEPRECATION: Robot.{method} is deprecated, please use Robot.getDevice instead.", file=sys.stderr)
        return self.getDevice(name)


    def getPen(self, name: str) -> Device | None:
        return self._deprecated("getPen", name)

    @classmethod
    def device_by_tag(cls, tag: int) -> Device | None:
        robot = cls.created
        if robot is None or not tag:
            return None
        return robot.devices.get(wb.wb_device_get_name(tag))

    def getKeyboard(self) -> Keyboard:
        return self.keyboard

    def getMouse(self) -> Mouse:
        return self.mouse

    def getJoystick(self) -> Joystick:
        return self.joystick

    # -- what a headless server does not have
    def batterySensorEnable(self, sampling_period: int) -> None:
        wb.wb_robot_battery_sensor_enable(sampling_period)

    def batterySensorDisable(self) -> None:
        wb.wb_robot_battery_sensor_disable()

    def batterySensorGetSamplingPeriod(self) -> int:
        return wb.wb_robot_battery_sensor_get_sampling_period()

    def batterySensorGetValue(self) -> float:
        """The battery's energy (J) at the latest sample (README "Battery and Charger")."""
        return wb.wb_robot_battery_sensor_get_value()

    def getProjectPath(self) -> str:
        return wb.wb_robot_get_project_path()

    def getWorldPath(self) -> str:
        return wb.wb_robot_get_world_path()

    def getUrdf(self, prefix: str = "") -> str:
        return wb.wb_robot_get_urdf(prefix)

    def wwiSendText(self, text: str) -> None:
        wb.wb_robot_wwi_send_text(text)

    def wwiReceiveText(self) -> str | None:
        return wb.wb_robot_wwi_receive_text()

    def setMode(self, mode: int, arg: str = "") -> None:
        if mode != self.MODE_SIMULATION:
            print(f"Error: Robot.setMode(): Sensorium robots are simulated only (mode {mode} refused)", file=sys.stderr)

    # -- robot information
    def getCustomData(self) -> str:
        return wb.wb_robot_get_custom_data()

    def setCustomData(self, data: str) -> None:
        wb.wb_robot_set_custom_data(data)

    def getModel(self) -> str:
        return wb.wb_robot_get_model()

    def getSupervisor(self) -> bool:
        return wb.wb_robot_get_supervisor()

    def getMode(self) -> int:
        return wb.wb_robot_get_mode()

    def getType(self) -> str:
        return wb.wb_robot_get_type()

    def waitForUserInputEvent(self, event_type: int, timeout: int) -> int:
        """No user input ever arrives headless: runs whole basic steps covering ``timeout`` ms and
        answers EVENT_NO_EVENT (EVENT_QUIT when the simulation ends)."""
        return wb.wb_robot_wait_for_user_input_event(event_type, timeout)

    def getTime(self) -> float:
        return wb.wb_robot_get_time()

    def getBasicTimeStep(self) -> float:
        return wb.wb_robot_get_basic_time_step()

    def getName(self) -> str:
        return wb.wb_robot_get_name()

    def getSynchronization(self) -> bool:
        return wb.wb_robot_get_synchronization()

    time = property(getTime)
    basic_time_step = property(getBasicTimeStep)
    name = property(getName)
    number_of_devices = property(getNumberOfDevices)
    synchronization = property(getSynchronization)
    custom_data = property(getCustomData, setCustomData)
    model = property(getModel)
    supervisor = property(getSupervisor)
    mode = property(getMode)
    project_path = property(getProjectPath)
    world_path = property(getWorldPath)

    @property
    def battery_sensor_sampling_period(self) -> int:
        return self.batterySensorGetSamplingPeriod()

    @battery_sensor_sampling_period.setter
    def battery_sensor_sampling_period(self, sampling_period: int | None) -> None:
        """Webots: ``None`` enables the battery sensor at the basic time step."""
        self.batterySensorEnable(int(self.getBasicTimeStep()) if sampling_period is None else sampling_period)


def _deprecated_getter(method: str) -> Any:
    def get(self: Robot, name: str) -> Device | None:
        return self._deprecated(method, name)
    get.__name__ = get.__qualname__ = method
    return get


# Webots' deprecated getters, one per device class: getGPS(name) is getDevice(name) with a warning
for _cls in ("Accelerometer", "Altimeter", "Brake", "Camera", "Compass", "Connector", "Display", "DistanceSensor",
             "Emitter", "GPS", "Gyro", "InertialUnit", "LED", "Lidar", "LightSensor", "Motor", "Pen", "PositionSensor",
             "Radar", "RangeFinder", "Receiver", "Skin", "Speaker", "TouchSensor"):
    setattr(Robot, f"get{_cls}", _deprecated_getter(f"get{_cls}"))
