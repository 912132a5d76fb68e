"""Webots' ``Car`` class: the ``Driver`` plus the car's read-outs (type, engine type, geometry, each
front wheel's angle, the wheels' encoders and speeds) and what Webots' library keeps of the
controller's commands (indicator period, brake and backwards lights, the limited-slip and indicator
auto-disabling flags)."""

from __future__ import annotations

import math
import sys

from .driver import Driver, _shown

# Webots' wheel indices → (the car's wheel key, the encoder name Webots' car library looks up)
_WHEELS = (("right_front", "right_front_sensor"), ("left_front", "left_front_sensor"),
           ("right_rear", "right_rear_sensor"), ("left_rear", "left_rear_sensor"))


class Car(Driver):
    TRACTION = 0
    PROPULSION = 1
    FOUR_BY_FOUR = 2
    COMBUSTION_ENGINE = 0
    ELECTRIC_ENGINE = 1
    PARALLEL_HYBRID_ENGINE = 2
    POWER_SPLIT_HYBRID_ENGINE = 3
    WHEEL_FRONT_RIGHT = 0
    WHEEL_FRONT_LEFT = 1
    WHEEL_REAR_RIGHT = 2
    WHEEL_REAR_LEFT = 3
    WHEEL_NB = 4

    def getType(self) -> int:  # type: ignore[override]   # Webots' Car.getType is the car's type
        return {"traction": self.TRACTION, "propulsion": self.PROPULSION, "4x4": self.FOUR_BY_FOUR}[self._geo["type"]]

    def getWheelbase(self) -> float:
        return float(self._geo["wheelbase"])

    def getTrackFront(self) -> float:
        return float(self._geo["track_front"])

    def getTrackRear(self) -> float:
        return float(self._geo["track_rear"])

    def getFrontWheelRadius(self) -> float:
        return float(self._geo["front_wheel_radius"])

    def getRearWheelRadius(self) -> float:
        return float(self._geo["rear_wheel_radius"])

    def getRightSteeringAngle(self) -> float:
        """The right front wheel's commanded angle (positive: right), as Webots' car library."""
        return self._angles[0]

    def getLeftSteeringAngle(self) -> float:
        return self._angles[1]

    def setRightSteeringAngle(self, angle: float) -> None:
        """Turn the right front wheel alone (Webots' car library: no Ackermann geometry applied)."""
        self._angles = (float(angle), self._angles[1])
        self._steer[0].setPosition(self._sign * float(angle))

    def setLeftSteeringAngle(self, angle: float) -> None:
        self._angles = (self._angles[0], float(angle))
        self._steer[1].setPosition(self._sign * float(angle))

    def getWheelEncoder(self, wheel_index: int) -> float:
        """The wheel's encoder (rad) by Webots' encoder name, NaN where the car has none."""
        if not 0 <= wheel_index < self.WHEEL_NB:
            return math.nan
        sensor = self.devices.get(_WHEELS[wheel_index][1])
        return sensor.getValue() if sensor is not None and hasattr(sensor, "getValue") else math.nan

    def getWheelSpeed(self, wheel_index: int) -> float:
        """A driven wheel's speed (rad/s: its commanded velocity, which a kinematic wheel keeps); a free
        wheel's, as Webots' driver works it out at each step: its encoder's change over the last step
        (0 until it has read twice); NaN for a wheel with neither motor nor encoder."""
        if not 0 <= wheel_index < self.WHEEL_NB:
            return math.nan
        if wheel_index in self._free_speed:
            return self._free_speed[wheel_index]
        if _WHEELS[wheel_index][0] not in self._wheels:
            return math.nan
        return float(self._wheels[_WHEELS[wheel_index][0]][0].getVelocity())

    def getEngineType(self) -> int:
        """The car's engine type from its world entry (a Webots Car's engineType); no engine runs here."""
        return self._engine

    def setIndicatorPeriod(self, period: float) -> None:
        """The indicators' blinking period (s; Webots' default 0.34); not a positive number: one line, ignored."""
        value = float(period)
        if not (math.isfinite(value) and value > 0.0):
            print("Warning: wbu_car_set_indicator_period() called with an invalid 'period' argument "
                  f"({_shown(value)}): it must be a positive number of seconds; ignored.", file=sys.stderr)
            return
        self._indicator_period = value

    def getIndicatorPeriod(self) -> float:
        return self._indicator_period

    def getBackwardsLights(self) -> bool:
        """Whether the backwards lights are on: as Webots' driver decides it at each step, while a
        negative cruising speed is set (reverse)."""
        return self._backwards

    def getBrakeLights(self) -> bool:
        """Whether the brake lights are on: while the brake intensity is above 0."""
        return self._brake > 0.0

    def enableLimitedSlipDifferential(self, enable: bool) -> None:
        """Kept (Webots' library uses it in torque control only, which a kinematic car has not)."""
        self._limited_slip = bool(enable)

    def enableIndicatorAutoDisabling(self, enable: bool) -> None:
        """Whether an indicator switches itself off once the steering comes back (Webots: on by default)."""
        self._auto_disabling = bool(enable)

    wheelbase = property(getWheelbase)
    track_front = property(getTrackFront)
    track_rear = property(getTrackRear)
    front_wheel_radius = property(getFrontWheelRadius)
    rear_wheel_radius = property(getRearWheelRadius)
    right_steering_angle = property(getRightSteeringAngle, setRightSteeringAngle)
    left_steering_angle = property(getLeftSteeringAngle, setLeftSteeringAngle)
    type = property(getType)
    engine_type = property(getEngineType)
    indicator_period = property(getIndicatorPeriod, setIndicatorPeriod)
    backwards_lights = property(getBackwardsLights)
    brake_lights = property(getBrakeLights)
