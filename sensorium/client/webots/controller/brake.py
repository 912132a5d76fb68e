"""Webots' ``Brake`` class: its joint's type and the motor and position sensor on its joint; its
damping constant is accepted and has no effect (no physics)."""

from __future__ import annotations

from sensorium.client import wb

from .device import Device


class Brake(Device):
    ROTATIONAL = wb.WB_ROTATIONAL
    LINEAR = wb.WB_LINEAR

    def setDampingConstant(self, c: float) -> None:
        wb.wb_brake_set_damping_constant(self._tag, c)

    def getType(self) -> int:
        return wb.wb_brake_get_type(self._tag)

    def getMotor(self):
        """The motor on the brake's joint, ``None`` when it has none."""
        from .robot import Robot

        return Robot.device_by_tag(wb.wb_brake_get_motor(self._tag))

    def getPositionSensor(self):
        """The PositionSensor on the brake's joint, ``None`` when it has none."""
        from .robot import Robot

        return Robot.device_by_tag(wb.wb_brake_get_position_sensor(self._tag))

    type = property(getType)
    dampingConstant = property(fset=setDampingConstant)  # noqa: N815 - Webots' name
    motor = property(getMotor)
    position_sensor = property(getPositionSensor)
