"""Webots' ``Motor`` and ``RotationalMotor`` classes (a drive's wheel and steering motors).

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

    def getBrake(self):
        """The Brake on the same joint, ``None`` when it has none."""
        from .robot import Robot

        return Robot.device_by_tag(wb.wb_motor_get_brake(self._tag))

    # -- what needs physics (kinematic wheels: ignored, NaN; see sensorium.client.wb_motor)
    def setAcceleration(self, acceleration: float) -> None:
        wb.wb_motor_set_acceleration(self._tag, acceleration)

    def getAcceleration(self) -> float:
        return wb.wb_motor_get_acceleration(self._tag)

    def setAvailableForce(self, force: float) -> None:
        wb.wb_motor_set_available_force(self._tag, force)

    def getAvailableForce(self) -> float:
        return wb.wb_motor_get_available_force(self._tag)

    def getMaxForce(self) -> float:
        return wb.wb_motor_get_max_force(self._tag)

    def setAvailableTorque(self, torque: float) -> None:
        wb.wb_motor_set_available_torque(self._tag, torque)

    def getAvailableTorque(self) -> float:
        return wb.wb_motor_get_available_torque(self._tag)

    def getMaxTorque(self) -> float:
        return wb.wb_motor_get_max_torque(self._tag)

    def setControlPID(self, p: float, i: float, d: float) -> None:
        wb.wb_motor_set_control_pid(self._tag, p, i, d)

    def getMultiplier(self) -> float:
        return wb.wb_motor_get_multiplier(self._tag)

    def setForce(self, force: float) -> None:
        wb.wb_motor_set_force(self._tag, force)

    def setTorque(self, torque: float) -> None:
        wb.wb_motor_set_torque(self._tag, torque)

    def enableForceFeedback(self, sampling_period: int) -> None:
        wb.wb_motor_enable_force_feedback(self._tag, sampling_period)

    def disableForceFeedback(self) -> None:
        wb.wb_motor_disable_force_feedback(self._tag)

    def getForceFeedbackSamplingPeriod(self) -> int:
        return wb.wb_motor_get_force_feedback_sampling_period(self._tag)

    def getForceFeedback(self) -> float:
        return wb.wb_motor_get_force_feedback(self._tag)

    def enableTorqueFeedback(self, sampling_period: int) -> None:
        wb.wb_motor_enable_torque_feedback(self._tag, sampling_period)

    def disableTorqueFeedback(self) -> None:
        wb.wb_motor_disable_torque_feedback(self._tag)

    def getTorqueFeedbackSamplingPeriod(self) -> int:
        return wb.wb_motor_get_torque_feedback_sampling_period(self._tag)

    def getTorqueFeedback(self) -> float:
        return wb.wb_motor_get_torque_feedback(self._tag)

    # -- Webots' property spellings
    target_position = property(getTargetPosition, setPosition)
    target_velocity = property(getVelocity, setVelocity)
    max_velocity = property(getMaxVelocity)
    min_position = property(getMinPosition)
    max_position = property(getMaxPosition)
    type = property(getType)
    position_sensor = property(getPositionSensor)
    brake = property(getBrake)
    target_acceleration = property(getAcceleration, setAcceleration)
    available_force = property(getAvailableForce, setAvailableForce)
    available_torque = property(getAvailableTorque, setAvailableTorque)
    max_force = property(getMaxForce)
    max_torque = property(getMaxTorque)
    multiplier = property(getMultiplier)
    force_feedback = property(getForceFeedback)
    torque_feedback = property(getTorqueFeedback)
    force_feedback_sampling_period = property(getForceFeedbackSamplingPeriod, enableForceFeedback)
    torque_feedback_sampling_period = property(getTorqueFeedbackSamplingPeriod, enableTorqueFeedback)
    force = property(fset=setForce)
    torque = property(fset=setTorque)


class RotationalMotor(Motor):
    """What ``Robot.getDevice`` returns for a rotational motor (a differential drive's wheel is
    simulated; any other is listed and answers Webots' "no value")."""


class LinearMotor(Motor):
    """What ``Robot.getDevice`` returns for a linear motor: a slider's, its joint moved kinematically,
    or a Track's (a tracked robot's drive wheel, in m and m/s)."""
