"""Webots' ``Driver`` class over a car-like robot's ordinary motors (its world entry's
``ackermann_drive``): ``setSteeringAngle`` turns the two steering motors to Webots' Ackermann
angles, ``setCruisingSpeed`` sets the driven wheels' velocities by Webots' geometric differentials,
``getCurrentSpeed`` reads them back. The brake intensity, indicators, hazard flashers, dipped beams
and antifog lights are the controller's commands, kept and answered as Webots' library keeps them
(and the car's LEDs of Webots' names switched for them); the interior's motors Webots' library turns
(the steering wheel, the speedometer's needle, the wipers) are turned as it turns them. Sensorium's
car is kinematic (no engine, gearbox or torque control): those functions answer Webots' "no value"
after one line the first time."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from typing import Any

from sensorium.client import wb
from sensorium.client.webots.controller.supervisor import Supervisor
from sensorium.client.webots.controller.unsimulated import signed

_UNMODELLED = ("Sensorium's car is kinematic (a bicycle model of its steering and wheel motors): no engine, "
               "gearbox or torque control")

LIGHTS = ("front_lights", "antifog_lights", "right_indicators", "left_indicators", "rear_lights", "backwards_lights",
          "brake_lights", "interior_right_indicators", "interior_left_indicators")
"""The LEDs Webots' car library switches when the car has them (Webots' VehicleLights names)."""
INDICATOR_PERIOD = 0.34
"""s: Webots' car library's indicator period until setIndicatorPeriod."""
AUTO_DISABLING_THRESHOLD = 0.1
"""rad: how far the steering comes back from its furthest turn towards the indicator's side before
the indicator switches itself off (Webots' driver library)."""
STEERING_WHEEL_RATIO = 10.0
"""The steering wheel motor's position per radian of steering angle (Webots' driver library)."""
SPEEDOMETER_MAX = 220.0
"""km/h: the speed at the speedometer needle's maxPosition (Webots' speedometer texture's last mark)."""


def refuse(cls: str, robot: str) -> SystemExit:
    """The one-line exit of a vehicle constructor on a robot that is not a car (status 1)."""
    return SystemExit(f"Error: {cls}(): robot {robot!r} has no ackermann_drive: Sensorium's vehicle library drives a "
                      "car-like robot whose world entry has one (README \"World files\"; a .wbt car is mapped when its "
                      "steering and wheel joints are a car's).")


def ackermann_angles(steering_angle: float, wheelbase: float, track_front: float) -> tuple[float, float]:
    """(right, left) front wheel angles for the bicycle-model angle (positive: right), as Webots'
    Driver computes them: cot δ_right = cot δ - t/2L, cot δ_left = cot δ + t/2L (a cotangent of 0 is a
    right angle, as C's atan(1/0) answers)."""
    if steering_angle == 0.0:
        return 0.0, 0.0
    tan, half = math.tan(steering_angle), track_front / (2.0 * wheelbase)
    cot = 1.0 / tan if tan != 0.0 else math.copysign(math.inf, tan)
    return _atan_inv(cot - half), _atan_inv(cot + half)


def _atan_inv(x: float) -> float:
    """atan(1 / x) as C computes it (1 / ±0 = ±inf)."""
    return math.atan(1.0 / x) if x != 0.0 else math.copysign(math.pi / 2, x)


def _shown(x: float) -> str:
    """A number in a warning line, as the C library prints it (NaN of either sign as NaN)."""
    return "NaN" if math.isnan(x) else f"{x:g}"


def _ratio(r_right: float, r_left: float) -> float:
    """A differential's share of the right wheel from its wheels' turn radii; 0.5 (straight on) where an
    angle too small for a float makes them infinite, or one past a right angle makes them cancel (C's
    division by 0 is not finite either)."""
    ratio = _div(r_right, r_left + r_right) if math.isfinite(r_right) and math.isfinite(r_left) else math.nan
    return ratio if math.isfinite(ratio) else 0.5


def _div(a: float, b: float) -> float:
    """a / b as C computes it (b == 0: an infinity, or NaN for 0 / 0)."""
    if b != 0.0:
        return a / b
    return math.nan if a == 0.0 else math.copysign(math.inf, a) * math.copysign(1.0, b)


def blink_on(time: float, period: float) -> bool:
    """Webots' indicators: on while int(t / period) is even; a quotient past a float's integers is even."""
    q = time / period
    return math.fmod(math.floor(q), 2.0) == 0.0 if math.isfinite(q) else True


def unmodelled(func: str, answer: Any, params: str = "") -> Callable[..., Any]:
    """A method standing for the C function ``func`` that does nothing and answers ``answer``,
    after one line the first time it is called in this process; it takes Webots' ``params``."""
    said: list[bool] = []

    def method(self: object, *args: Any, **kwargs: Any) -> Any:
        if not said:
            said.append(True)
            print(f"Warning: {func}(): not simulated ({_UNMODELLED}); it answers {answer!r}.", file=sys.stderr)
        return answer

    method.__doc__ = f"Not simulated (no engine model): one line the first time, then {answer!r}."
    return signed(method, params)


class Driver(Supervisor):
    INDICATOR_OFF = 0
    INDICATOR_RIGHT = 1
    INDICATOR_LEFT = 2
    SPEED = 0
    TORQUE = 1
    DOWN = 0
    SLOW = 1
    NORMAL = 2
    FAST = 3

    def __init__(self) -> None:
        super().__init__()
        geo = wb.current().ackermann_drive
        if geo is None:
            raise refuse(type(self).__name__, self.getName())
        self._geo = geo
        self._sign = 1.0 if geo["positive_steers"] == "right" else -1.0
        self._steer = [self._motor(geo["right_steer"]), self._motor(geo["left_steer"])]
        step = int(self.getBasicTimeStep())
        self._steer_sensors = [m.getPositionSensor() for m in self._steer]
        # the driven wheels (Webots' order: front right, front left, rear right, rear left), each with its radius
        axles = {"traction": ("front",), "propulsion": ("rear",), "4x4": ("front", "rear")}[geo["type"]]
        self._wheels: dict[str, tuple[Any, float]] = {}
        for axle in axles:
            for side in ("right", "left"):
                self._wheels[f"{side}_{axle}"] = (self._motor(geo[f"{side}_{axle}_wheel"]), geo[f"{axle}_wheel_radius"])
        wheel_sensors = [self.devices.get(f"{side}_{axle}_sensor") for axle in ("front", "rear")
                         for side in ("right", "left")]
        # the encoders of the wheels without a motor (Webots' order): their speeds from each step's change
        self._free_sensors: dict[int, Any] = {i: sensor for i, (sensor, key) in enumerate(zip(wheel_sensors, (
            "right_front", "left_front", "right_rear", "left_rear")))
            if key not in self._wheels and sensor is not None and type(sensor).__name__ == "PositionSensor"}
        self._free_last: dict[int, float] = {}
        self._free_speed = dict.fromkeys(self._free_sensors, 0.0)
        for sensor in (*self._steer_sensors, *wheel_sensors):   # as Webots' car library: its encoders on
            if sensor is not None and type(sensor).__name__ == "PositionSensor":
                sensor.enable(step)
        for motor, _ in self._wheels.values():      # velocity control at rest (Webots' wbu_car_init)
            motor.setPosition(math.inf)
            motor.setVelocity(0.0)
        self._angle = 0.0
        self._angles = (0.0, 0.0)
        self._cruising = 0.0
        self._mode: int | None = None
        # the controller's own commands Webots' library keeps (lights, indicators, brake) and the LEDs it
        # switches for them when the car has them (looked up quietly, as Webots does)
        self._lights: dict[str, Any] = {name: dev for name in LIGHTS
                                        if (dev := self.devices.get(name)) is not None and type(dev).__name__ == "LED"}
        self._lit: dict[str, int] = {}
        self._brake = 0.0
        self._indicator = self.INDICATOR_OFF
        self._indicator_angle = 0.0
        self._hazard = False
        self._dipped = False
        self._antifog = False
        self._backwards = False
        self._indicator_period = INDICATOR_PERIOD
        self._limited_slip = True
        self._auto_disabling = True
        engine = geo.get("engine_type", "combustion")
        self._engine = ("combustion", "electric", "parallel hybrid", "power-split hybrid").index(engine)
        # the interior's motors Webots' library turns when the car has them (looked up quietly, as Webots does)
        self._steering_wheel = self._quiet("steering_wheel_motor", "RotationalMotor")
        self._speed_needle = self._quiet("speed_needle_motor", "RotationalMotor")
        self._wipers = [self._quiet(n, "RotationalMotor") for n in ("right_wiper_motor", "left_wiper_motor")]
        self._wiper_sensor = self._quiet("wiper_sensor", "PositionSensor")
        self._wiper_mode = self.DOWN
        if self._wiper_sensor is not None:
            self._wiper_sensor.enable(step)

    def _quiet(self, name: str, kind: str) -> Any:
        """The car's device ``name`` of class ``kind``, None when it has none (no line: Webots' library
        looks its optional devices up quietly)."""
        dev = self.devices.get(name)
        return dev if dev is not None and type(dev).__name__ == kind else None

    def _light(self, name: str, on: bool) -> None:
        """Switch the car's LED ``name`` (and the interior indicator with an indicator), if it has it."""
        names = (name, f"interior_{name}") if name.endswith("_indicators") else (name,)
        for n in names:
            led = self._lights.get(n)
            if led is not None and self._lit.get(n) != int(on):
                led.set(int(on))
                self._lit[n] = int(on)

    def _motor(self, name: str) -> Any:
        motor = self.devices.get(name)
        if motor is None:       # the server lists every drive motor: only a mismatched server gets here
            raise SystemExit(f"Error: {type(self).__name__}(): robot {self.getName()!r} has no motor {name!r}.")
        return motor

    # -- steering
    def setSteeringAngle(self, steeringAngle: float) -> None:
        """Turn the front wheels to Webots' Ackermann angles for ``steeringAngle`` (rad, positive:
        right); the steering motors clamp to their limits. In speed control the wheel speeds follow."""
        if not isinstance(steeringAngle, (int, float)) or not math.isfinite(steeringAngle):
            shown = _shown(steeringAngle) if isinstance(steeringAngle, (int, float)) else repr(steeringAngle)
            print("Warning: wbu_driver_set_steering_angle() called with an invalid 'steering_angle' argument "
                  f"({shown})", file=sys.stderr)
            return
        if self._steering_wheel is not None:       # Webots' library turns the steering wheel with it
            self._steering_wheel.setPosition(STEERING_WHEEL_RATIO * float(steeringAngle))
        self._angle = float(steeringAngle)
        self._angles = ackermann_angles(self._angle, self._geo["wheelbase"], self._geo["track_front"])
        for motor, angle in zip(self._steer, self._angles):
            motor.setPosition(self._sign * angle)
        if self._mode == self.SPEED:
            self.setCruisingSpeed(self._cruising)
        if self._auto_disabling and self._indicator != self.INDICATOR_OFF:
            # Webots' driver: an indicator follows the steering to its furthest turn its way, and goes off
            # once the steering has come back from there by the threshold
            toward = 1.0 if self._indicator == self.INDICATOR_RIGHT else -1.0
            if toward * (self._angle - self._indicator_angle) > 0.0:
                self._indicator_angle = self._angle
            elif toward * (self._angle - self._indicator_angle) <= -AUTO_DISABLING_THRESHOLD:
                self._indicator = self.INDICATOR_OFF

    def getSteeringAngle(self) -> float:
        """The mean of the two front wheels' angles (Webots: of the steering encoders; here the
        motors' targets where a steering motor has no encoder)."""
        angles = []
        for motor, sensor in zip(self._steer, self._steer_sensors):
            value = sensor.getValue() if sensor is not None else math.nan
            angles.append(value if value == value else motor.getTargetPosition())
        return self._sign * (angles[0] + angles[1]) / 2.0

    # -- speed
    def _ratio_front(self) -> float:
        right, left = self._angles
        if self._angle == 0.0:
            return 0.5
        return _ratio(_div(self._geo["wheelbase"], math.sin(right)), _div(self._geo["wheelbase"], math.sin(left)))

    def _ratio_rear(self) -> float:
        if self._angle == 0.0:
            return 0.5
        r = _div(self._geo["wheelbase"], math.tan(self._angle))
        return _ratio(r - self._geo["track_rear"] / 2, r + self._geo["track_rear"] / 2)

    def _ratio_central(self) -> float:
        if self._angle == 0.0:
            return 0.5
        wheelbase = self._geo["wheelbase"]
        front, rear = _div(wheelbase, math.sin(self._angle)), _div(wheelbase, math.tan(self._angle))
        share = _div(front, front + rear) if math.isfinite(front) and math.isfinite(rear) else math.nan
        share = share if math.isfinite(share) else 0.5
        return self._geo["rear_wheel_radius"] / self._geo["front_wheel_radius"] * share

    def setCruisingSpeed(self, cruisingSpeed: float) -> None:
        """Speed control (km/h): each driven wheel's velocity by Webots' geometric differentials
        (each axle's pair shares 2·speed in proportion to its wheels' turn radii; a 4x4's central
        differential splits front and rear)."""
        speed = float(cruisingSpeed)
        if not math.isfinite(speed):
            print("Warning: wbu_driver_set_cruising_speed() called with an invalid 'speed' argument "
                  f"({_shown(speed)}): ignored.", file=sys.stderr)
            return
        central = self._ratio_central() if self._geo["type"] == "4x4" else 0.5
        for axle, ratio, share in (("front", self._ratio_front(), 2 * central), ("rear", self._ratio_rear(),
                                                                                  2 * (1 - central))):
            if f"right_{axle}" not in self._wheels:
                continue
            for side, part in (("right", ratio), ("left", 1 - ratio)):
                motor, radius = self._wheels[f"{side}_{axle}"]
                kmh = 2 * speed * part * (share if self._geo["type"] == "4x4" else 1.0)
                motor.setVelocity(kmh / 3.6 / radius)
        self._cruising = speed
        self._mode = self.SPEED

    def getTargetCruisingSpeed(self) -> float:
        return self._cruising

    def getCurrentSpeed(self) -> float:
        """km/h from the driven wheels' speeds (Webots: their encoders' last step; a kinematic
        wheel in velocity control turns exactly at its commanded velocity)."""
        def axle(name: str) -> float:
            (right, radius), (left, _) = self._wheels[f"right_{name}"], self._wheels[f"left_{name}"]
            return 0.5 * (right.getVelocity() + left.getVelocity()) * radius
        if self._geo["type"] == "4x4":
            return 3.6 * 0.5 * (axle("front") + axle("rear"))
        return 3.6 * axle("front" if self._geo["type"] == "traction" else "rear")

    def getControlMode(self) -> int | None:
        """``SPEED`` once a cruising speed is set, ``None`` before (Webots' undefined mode)."""
        return self._mode

    def step(self, time_step: int | None = None) -> int:
        """One basic time step (Webots' ``wbu_driver_step``); -1 when the simulation ends. Before it,
        as Webots' library: the indicators' LEDs blink (on for the first half of each period, by the
        simulated time), the wipers sweep in any mode but ``DOWN`` (up to their motors' maxPosition from
        their minPosition and back; in ``SLOW`` only during the first second of every four), the
        backwards lights are on while a negative cruising speed is set and the speedometer's needle
        shows the current speed (its maxPosition at 220 km/h)."""
        on = blink_on(self.getTime(), self._indicator_period)
        self._light("right_indicators", on and (self._hazard or self._indicator == self.INDICATOR_RIGHT))
        self._light("left_indicators", on and (self._hazard or self._indicator == self.INDICATOR_LEFT))
        right, left = self._wipers
        if right is not None and left is not None and self._wiper_sensor is not None and self._wiper_mode != self.DOWN:
            at = self._wiper_sensor.getValue()
            if at == right.getMinPosition():     # Webots' library: at rest down, the wipers go up
                right.setPosition(right.getMaxPosition())
                left.setPosition(left.getMaxPosition())
            if at == right.getMaxPosition() or (self._wiper_mode == self.SLOW and int(self.getTime()) % 4 != 0):
                right.setPosition(right.getMinPosition())
                left.setPosition(left.getMinPosition())
        self._backwards = self._mode == self.SPEED and self._cruising < 0.0
        self._light("backwards_lights", self._backwards)
        if self._speed_needle is not None:
            top = self._speed_needle.getMaxPosition()
            speed = abs(self.getCurrentSpeed())
            self._speed_needle.setPosition(speed * top / SPEEDOMETER_MAX if speed <= SPEEDOMETER_MAX else top)
        # a free wheel's speed, as Webots' driver works out every wheel's: its encoder's change since the
        # last step over the basic time step (0 until the encoder has read twice)
        ms = self.getBasicTimeStep()
        for i, sensor in self._free_sensors.items():
            now = sensor.getValue()
            last = self._free_last.get(i, math.nan)
            self._free_speed[i] = 1000.0 * (now - last) / ms if now == now and last == last else 0.0
            self._free_last[i] = now
        return super().step(time_step)

    # -- the controller's own commands: brake, indicators, lights (kept and answered, as Webots' library)
    def setBrakeIntensity(self, brakeIntensity: float) -> None:
        """Kept and answered (clamped to [0, 1] with Webots' line; NaN: one line, ignored) and the brake
        lights on while it is above 0; it does not slow the car here (the wheels follow their speed
        control)."""
        value = float(brakeIntensity)
        if math.isnan(value):
            print("Warning: wbu_driver_set_brake_intensity() called with an invalid 'intensity' argument (NaN): "
                  "ignored.", file=sys.stderr)
            return
        if value < 0.0:       # Webots' lines
            print("Warning: 'intensity' should be bigger or equal to 0, used 0 instead.", file=sys.stderr)
            value = 0.0
        elif value > 1.0:
            print("Warning: 'intensity' should be smaller or equal to 1, used 1 instead.", file=sys.stderr)
            value = 1.0
        self._brake = value
        self._light("brake_lights", value > 0.0)

    def getBrakeIntensity(self) -> float:
        return self._brake

    def setIndicator(self, indicator: int) -> None:
        """``INDICATOR_OFF``, ``INDICATOR_RIGHT`` or ``INDICATOR_LEFT``; the indicator's LEDs blink with
        the steps (if the car has them), and it switches itself off as Webots' (``enableIndicatorAutoDisabling``)."""
        self._indicator = int(indicator)
        self._indicator_angle = self._angle

    def getIndicator(self) -> int:
        return self._indicator

    def setHazardFlashers(self, hazardFlasher: bool) -> None:
        self._hazard = bool(hazardFlasher)

    def getHazardFlashers(self) -> bool:
        return self._hazard

    def setDippedBeams(self, state: bool) -> None:
        """Kept, and the front and rear lights' LEDs switched (if the car has them)."""
        self._dipped = bool(state)
        self._light("front_lights", self._dipped)
        self._light("rear_lights", self._dipped)

    def getDippedBeams(self) -> bool:
        return self._dipped

    def setAntifogLights(self, state: bool) -> None:
        self._antifog = bool(state)
        self._light("antifog_lights", self._antifog)

    def getAntifogLights(self) -> bool:
        return self._antifog

    def setWiperMode(self, mode: int) -> None:
        """``DOWN``, ``SLOW``, ``NORMAL`` or ``FAST``: kept, and the car's wipers (Webots' motor names,
        with their ``wiper_sensor``) sweep at each ``step`` as Webots' library sweeps them; ``NORMAL``
        and ``FAST`` alike, as there (the motors' speed is the world's)."""
        self._wiper_mode = int(mode)

    def getWiperMode(self) -> int:
        return self._wiper_mode

    @staticmethod
    def isInitialisationPossible() -> bool:
        """Whether this controller's robot is a car the vehicle library drives (its world entry has an
        ``ackermann_drive``); attaches to the robot as ``Robot()`` does."""
        wb.wb_robot_init()
        return wb.current().ackermann_drive is not None

    # -- no engine, gearbox or torque control here
    setThrottle = unmodelled("wbu_driver_set_throttle", None, "throttle")
    getThrottle = unmodelled("wbu_driver_get_throttle", 0.0)
    setGear = unmodelled("wbu_driver_set_gear", None, "gear")
    getGear = unmodelled("wbu_driver_get_gear", 0)
    getGearNumber = unmodelled("wbu_driver_get_gear_number", 0)
    getRpm = unmodelled("wbu_driver_get_rpm", 0.0)

    # Webots' properties
    steering_angle = property(getSteeringAngle, setSteeringAngle)
    target_cruising_speed = property(getTargetCruisingSpeed, setCruisingSpeed)
    current_speed = property(getCurrentSpeed)
    control_mode = property(getControlMode)
    throttle = property(getThrottle, setThrottle)
    brake_intensity = property(getBrakeIntensity, setBrakeIntensity)
    gear = property(getGear, setGear)
    gear_number = property(getGearNumber)
    rpm = property(getRpm)
    indicator = property(getIndicator, setIndicator)
    hazard_flashers = property(getHazardFlashers, setHazardFlashers)
    dipped_beams = property(getDippedBeams, setDippedBeams)
    antifog_lights = property(getAntifogLights, setAntifogLights)
    wiper_mode = property(getWiperMode, setWiperMode)
