"""Webots' ``VacuumGripper`` class: the pump and the presence of a held solid (one with physics it
touched while on, carried kinematically until the pump is off: README "VacuumGripper and Speaker")."""

from __future__ import annotations

from sensorium.client import wb

from .device import Device


class VacuumGripper(Device):
    def __init__(self, name: str | int, sampling_period: int | None = None):
        super().__init__(name)
        if sampling_period is not None:
            self.enablePresence(sampling_period)

    def enablePresence(self, sampling_period: int) -> None:
        wb.wb_vacuum_gripper_enable_presence(self._tag, sampling_period)

    def disablePresence(self) -> None:
        wb.wb_vacuum_gripper_disable_presence(self._tag)

    def getPresenceSamplingPeriod(self) -> int:
        return wb.wb_vacuum_gripper_get_presence_sampling_period(self._tag)

    def getPresence(self) -> bool:
        return wb.wb_vacuum_gripper_get_presence(self._tag)

    def turnOn(self) -> None:
        wb.wb_vacuum_gripper_turn_on(self._tag)

    def turnOff(self) -> None:
        wb.wb_vacuum_gripper_turn_off(self._tag)

    def isOn(self) -> bool:
        return wb.wb_vacuum_gripper_is_on(self._tag)

    presence = property(getPresence)
    presence_sampling_period = property(getPresenceSamplingPeriod)
    on = property(isOn)
