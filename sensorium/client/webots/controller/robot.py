"""Webots' ``Robot`` class: one per controller process."""

from __future__ import annotations

import sys

from sensorium.client import wb

from .camera import Camera
from .device import Device
from .distance_sensor import DistanceSensor
from .keyboard import Keyboard
from .led import LED
from .lidar import Lidar
from .light_sensor import LightSensor
from .motor import RotationalMotor
from .pen import Pen
from .position_sensor import PositionSensor
from .range_finder import RangeFinder

_CLASSES: dict[str, type[Device]] = {
    wb.LIGHT_SENSOR: LightSensor,
    wb.DISTANCE_SENSOR: DistanceSensor,
    wb.LIDAR: Lidar,
    wb.ROTATIONAL_MOTOR: RotationalMotor,
    wb.POSITION_SENSOR: PositionSensor,
    wb.LED: LED,
    "Pen": Pen,
    wb.RANGE_FINDER: RangeFinder,
    wb.CAMERA: Camera,
}


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
        self.keyboard = Keyboard()
        self.devices: dict[str, Device] = {}
        for i in range(wb.wb_robot_get_number_of_devices()):
            tag = wb.wb_robot_get_device_by_index(i)
            kind = wb.wb_device_get_type_name(tag)
            cls = _CLASSES.get(kind)
            if cls is None:
                # a device this client has no class for yet (listed, not simulated): present with its
                # name and model, so getDevice/getDeviceByIndex find it as in Webots
                cls = Device
            self.devices[wb.wb_device_get_name(tag)] = cls(tag)

    # -- stepping
    def step(self, duration: int | None = None) -> int:
        """Run ``duration`` ms of simulated time (default: the basic time step); -1 when the
        simulation ends."""
        return wb.wb_robot_step(duration)

    def stepBegin(self, duration: int | None = None) -> int:
        return wb.wb_robot_step_begin(duration)

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

    def getLightSensor(self, name: str) -> Device | None:
        return self._deprecated("getLightSensor", name)

    def getDistanceSensor(self, name: str) -> Device | None:
        return self._deprecated("getDistanceSensor", name)

    def getLidar(self, name: str) -> Device | None:
        return self._deprecated("getLidar", name)

    def getMotor(self, name: str) -> Device | None:
        return self._deprecated("getMotor", name)

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
        """No user input ever arrives headless: steps ``timeout`` ms and answers EVENT_NO_EVENT
        (EVENT_QUIT when the simulation ends)."""
        return self.EVENT_QUIT if self.step(max(int(timeout), 0)) == -1 else self.EVENT_NO_EVENT

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
