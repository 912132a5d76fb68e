"""Webots' ``Motor`` and ``RotationalMotor`` classes (a differential drive's wheel motors).

Commands cost no round trip: they are kept by the client and sent with the next ``Robot.step``
(see :mod:`sensorium.client.wb`), so ``setVelocity`` takes effect at the start of that step.
"""

from __future__ import annotations

from sensorium.client import wb

from .device import Device


class Motor(Device):
    ROTATIONAL = wb.WB_ROTATIONAL
    LINEAR = wb.WB_LINEAR

    def setPosition(self, position: float) -> None:
        """Target position (rad); ``float('inf')`` switches to velocity control."""
        wb.wb_motor_set_position(self._tag, position)

    def setVelocity(self, velocity: float) -> None:
        """rad/s; clamped to ``getMaxVelocity()`` with Webots' warning."""
        wb.wb_motor_set_velocity(self._tag, velocity)

    def getTargetPosition(self) -> float:
        return wb.wb_motor_get_target_position(self._tag)

    def getVelocity(self) -> float:
        return wb.wb_motor_get_velocity(self._tag)

    def getMaxVelocity(self) -> float:
        return wb.wb_motor_get_max_velocity(self._tag)

    def getMinPosition(self) -> float:
        return wb.wb_motor_get_min_position(self._tag)

    def getMaxPosition(self) -> float:
        return wb.wb_motor_get_max_position(self._tag)

    def getType(self) -> int:
        return wb.wb_motor_get_type(self._tag)

    def getPositionSensor(self):
        """The PositionSensor on the wheel's joint, ``None`` when it has none."""
        from .robot import Robot

        return Robot.device_by_tag(wb.wb_motor_get_position_sensor(self._tag))

    def getBrake(self) -> None:
        return None

    # -- Webots' property spellings
    target_position = property(getTargetPosition, setPosition)
    target_velocity = property(getVelocity, setVelocity)
    max_velocity = property(getMaxVelocity)
    min_position = property(getMinPosition)
    max_position = property(getMaxPosition)
    type = property(getType)
    position_sensor = property(getPositionSensor)
    brake = property(getBrake)


class RotationalMotor(Motor):
    """What ``Robot.getDevice`` returns for a wheel motor."""
