"""Webots' ``PositionSensor`` class (the encoder of a drive's wheel or steering joint)."""

from __future__ import annotations

from sensorium.client import wb

from .device import Sensor


class PositionSensor(Sensor):
    ROTATIONAL = wb.WB_ROTATIONAL
    ANGULAR = ROTATIONAL                # Webots' name before R2021
    LINEAR = wb.WB_LINEAR

    _enable = staticmethod(wb.wb_position_sensor_enable)
    _get_sampling_period = staticmethod(wb.wb_position_sensor_get_sampling_period)

    def getValue(self) -> float:
        """The wheel's angle (rad); NaN before the first measurement."""
        return wb.wb_position_sensor_get_value(self._tag)

    def getType(self) -> int:
        return wb.wb_position_sensor_get_type(self._tag)

    def getMotor(self):
        """The wheel motor on the same joint."""
        from .robot import Robot

        tag = wb.wb_position_sensor_get_motor(self._tag)
        return Robot.device_by_tag(tag)

    def getBrake(self):
        """The Brake on the same joint, ``None`` when it has none."""
        from .robot import Robot

        return Robot.device_by_tag(wb.wb_position_sensor_get_brake(self._tag))

    value = property(getValue)
    type = property(getType)
    motor = property(getMotor)
    brake = property(getBrake)
