"""Webots' ``Robot`` class: one per controller process."""

from __future__ import annotations

import sys

from sensorium.client import wb

from .device import Device
from .distance_sensor import DistanceSensor
from .lidar import Lidar
from .light_sensor import LightSensor
from .motor import RotationalMotor

_CLASSES: dict[str, type[Device]] = {
    wb.LIGHT_SENSOR: LightSensor,
    wb.DISTANCE_SENSOR: DistanceSensor,
    wb.LIDAR: Lidar,
    wb.ROTATIONAL_MOTOR: RotationalMotor,
}


class Robot:
    """Attaches to the robot named by ``SENSORIUM_CONTROLLER_URL`` (or ``WEBOTS_CONTROLLER_URL``)."""

    created: Robot | None = None

    def __init__(self) -> None:
        if Robot.created is not None:
            raise RuntimeError("only one Robot instance can be created per controller process")
        wb.wb_robot_init()
        Robot.created = self
        self.devices: dict[str, Device] = {}
        for i in range(wb.wb_robot_get_number_of_devices()):
            tag = wb.wb_robot_get_device_by_index(i)
            kind = wb.wb_device_get_type_name(tag)
            cls = _CLASSES.get(kind)
            if cls is None:
                print(f"Unsupported device type {kind!r} for device {wb.wb_device_get_name(tag)!r}", file=sys.stderr)
                continue
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

    # -- robot information
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
