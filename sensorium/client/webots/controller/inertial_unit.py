"""Webots' ``InertialUnit`` class: roll/pitch/yaw and quaternion in the world's convention."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class InertialUnit(Sensor):
    _enable = staticmethod(wb.wb_inertial_unit_enable)
    _get_sampling_period = staticmethod(wb.wb_inertial_unit_get_sampling_period)

    def getRollPitchYaw(self) -> list[float]:
        return wb.wb_inertial_unit_get_roll_pitch_yaw(self._tag)

    def getQuaternion(self) -> list[float]:
        return wb.wb_inertial_unit_get_quaternion(self._tag)

    def getNoise(self) -> float:
        return wb.wb_inertial_unit_get_noise(self._tag)

    roll_pitch_yaw = property(getRollPitchYaw)
    quaternion = property(getQuaternion)
    noise = property(getNoise)
