"""Joints moved by their motors without physics: Webots' kinematic motor control.

A RotationalMotor (HingeJoint) or LinearMotor (SliderJoint) that is not part of a robot's drive
moves its joint's position the way Webots moves it when the end point has no physics (WbMotor's
kinematic control, run once per basic step):

* nothing happens in position control once the joint is within 1e-6 of the target, nor in velocity
  control (target ±inf) at a position limit it is pushing against; the speed drops to 0 then;
* otherwise the speed moves towards the commanded velocity (its magnitude in position control) by
  at most ``a·dt`` (``a``: the motor's ``acceleration``, or its available torque/force when that is
  -1 or larger), then the position moves by ``speed·dt`` towards the target (up for +inf), never
  past a finite target.

Coupled motors (names ``group::part``, WbMotor's couplings): a position or velocity command given
to one reaches every motor of its group, each scaling it by its own ``multiplier``.

:class:`Links` moves what rides on the joints (``on_joint`` in the world file): a hinge at position
``q`` turns its end point by ``q - q0`` (``q0``: its initial position, where the file places the end
point) about its axis through its anchor, a slider moves it by ``q - q0`` along its axis (Webots'
HingeJoint/SliderJoint end point rule), nested joints composed outward.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.motion import velocity_accepted
from sensorium.server.world.geometry import Pose

_POSITION_THRESHOLD = 1e-6       # Webots' TARGET_POSITION_THRESHOLD
_VELOCITY_THRESHOLD = 1e-6       # Webots' TARGET_VELOCITY_THRESHOLD


@dataclass(slots=True)
class JointMotor:
    """A joint's motor as a controller commands it (``setPosition``, ``setVelocity``,
    ``setAcceleration``, ``setAvailableTorque``/``Force``) and the joint position it moves.

    The interface the drives' :class:`~sensorium.server.sim.motion.WheelMotor` has (``position``,
    ``target_position``, ``velocity``, ``max_velocity``, ``set_position``, ``command_velocity``,
    ``hold``), so the services, step commands and encoders treat both alike."""

    name: str
    kind: str                            # "RotationalMotor" or "LinearMotor"
    max_velocity: float
    min_position: float = 0.0
    max_position: float = 0.0            # min = max = 0: no limits (Webots)
    acceleration: float = -1.0           # -1: bounded by the available torque/force only
    max_force: float = 10.0              # maxTorque (rotational) or maxForce (linear)
    initial_position: float = 0.0
    position: float = math.nan           # the joint's position (rad or m)
    target_position: float = math.nan
    velocity: float = math.nan           # the commanded velocity (Webots' target velocity)
    speed: float = 0.0                   # the current velocity (Webots' mCurrentVelocity)
    available_force: float = math.nan
    rate: float = 0.0                    # how fast the position moved over the last basic step (signed)
    multiplier: float = 1.0              # scales the position and velocity commands it takes (Webots)
    # the other motors of its coupled group ("group::part" names); out of repr and ==, which would
    # go round the group for ever
    coupled: tuple[JointMotor, ...] = field(default=(), repr=False, compare=False)

    def __post_init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """As loaded: at the joint's initial position, holding it at maxVelocity (WbMotor::reset)."""
        self.position = self.initial_position
        self.target_position = self.initial_position
        self.velocity = self.max_velocity
        self.speed = 0.0
        self.rate = 0.0
        self.available_force = self.max_force

    @property
    def limited(self) -> bool:
        return self.min_position != self.max_position

    def hold(self) -> None:
        """Stop where the joint is (position control at its current position)."""
        self.target_position = self.position

    def set_position(self, value: float, warn: bool = True) -> None:
        """Webots' setTargetPosition, given to this motor and every motor coupled with it
        (WbMotor::handleMessage relays it): each one's target is ``value`` times its multiplier
        (±inf, velocity control, as given), clamped to its limits with Webots' warning on stderr
        (``warn``), which names the value asked for."""
        if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
            raise ValueError(f"motor {self.name!r}: position must be a number or inf, got {value!r}")
        for motor in (self, *self.coupled):
            motor._take_position(float(value), warn)

    def _take_position(self, value: float, warn: bool) -> str | None:
        """Its target from a position asked for; Webots' warning line when it clamped it (None if not)."""
        if math.isinf(value):
            self.target_position = value
            return None
        target = value * self.multiplier
        if self.limited:
            hi, lo = self.max_position, self.min_position
            line = None           # Webots judges the scaled target, and names the value asked for
            if target > hi:
                line = f'WARNING: {self.kind} "{self.name}": too big requested position: {value:g} > {hi:g}'
            elif target < lo:
                line = f'WARNING: {self.kind} "{self.name}": too low requested position: {value:g} < {lo:g}'
            if line is not None:
                if warn:
                    print(line, file=sys.stderr)
                target = min(max(target, lo), hi)
            self.target_position = target
            return line
        self.target_position = target
        return None

    def place(self, position: float) -> str | None:
        """A Supervisor's ``setJointPosition`` (WbJoint::setPosition): the joint is at ``position``
        at once, and this motor (not those coupled with it) targets it: ``position`` times its
        multiplier, clamped to its limits (WbMotor::setTargetPosition), its speed 0. Returns Webots'
        warning line when the target was clamped (the joint then moves back within the limits)."""
        self.position = float(position)
        self.speed = 0.0
        self.rate = 0.0
        return self._take_position(float(position), warn=False)

    def restore(self, position: float) -> None:
        """A loaded state (``loadState``: WbMotor::reset, then WbJoint::setPosition): the joint back at
        ``position``, the motor targeting it as :meth:`place` does, at ``maxVelocity`` with its full
        torque/force."""
        self.velocity = self.max_velocity
        self.available_force = self.max_force
        self.place(position)

    def command(self, position: float | None, velocity: float | None, acceleration: float | None,
                available_force: float | None) -> None:
        """A controller step's commands (checked by the request's schema; the client printed
        Webots' warnings): applied in libController's order, without printing. A position and a
        velocity reach the motors coupled with this one too; an acceleration and an available
        torque/force only this one (as WbMotor relays them)."""
        if position is not None:
            self.set_position(position, warn=False)
        if velocity is not None:
            self.command_velocity(velocity)
        if acceleration is not None:
            self.set_acceleration(acceleration)
        if available_force is not None:
            self.set_available_force(available_force)

    def set_velocity(self, value: float) -> None:
        """In-process ``setVelocity``: NaN raises; a negative velocity in position control is
        ignored with Webots' line (:func:`~sensorium.server.sim.motion.velocity_accepted`, the wheels'
        rule); otherwise as :meth:`command_velocity`."""
        if velocity_accepted(self.name, value, self.target_position, self.velocity):
            self.command_velocity(value)

    def command_velocity(self, value: float) -> None:
        """A velocity a controller sends, to this motor and every motor coupled with it: each one's
        is ``value`` times its multiplier, clamped to ``±maxVelocity`` (WbMotor::setVelocity)."""
        for motor in (self, *self.coupled):
            wanted = float(value) * motor.multiplier
            motor.velocity = float(min(max(wanted, -motor.max_velocity), motor.max_velocity))

    def set_acceleration(self, value: float) -> None:
        """``setAcceleration``: >= 0, or -1 (bounded by the available torque/force only)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not (value >= 0.0 or value == -1.0) \
                or math.isinf(value):
            raise ValueError(f"motor {self.name!r}: acceleration must be >= 0 and finite, or -1, got {value!r}")
        self.acceleration = float(value)

    def set_available_force(self, value: float) -> None:
        """``setAvailableTorque``/``Force``: >= 0, at most ``maxTorque``/``maxForce`` (clamped to it)."""
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0.0:
            raise ValueError(f"motor {self.name!r}: available torque/force must be >= 0, got {value!r}")
        self.available_force = float(min(value, self.max_force))

    def advance(self, dt_s: float) -> None:
        """One basic step of Webots' kinematic control (WbMotor::runKinematicControl)."""
        target = self.target_position
        position = self.position
        if math.isinf(target):
            lo, hi = self.min_position, self.max_position
            idle = lo != hi and ((position >= hi and self.velocity >= 0.0) or (position <= lo and self.velocity <= 0.0))
        else:
            idle = abs(target - position) < _POSITION_THRESHOLD
        if idle:
            self.speed = 0.0
            self.rate = 0.0
            return
        acc = self.acceleration
        if acc == -1.0 or acc > self.available_force:
            acc = self.available_force
        speed = self.speed
        # in position control, the velocity's magnitude (departure: Webots' kinematic control would
        # carry a negative one -- left from velocity control, or a coupled motor's negative
        # multiplier -- away from the target for ever; its physics, and its manual, take the magnitude)
        wanted = self.velocity if math.isinf(target) else abs(self.velocity)
        if abs(wanted - speed) > _VELOCITY_THRESHOLD:
            speed = min(speed + acc * dt_s, wanted) if wanted > speed else max(speed - acc * dt_s, wanted)
        self.speed = speed
        if target > position:
            self.position = min(position + speed * dt_s, target)
        else:
            self.position = max(position - speed * dt_s, target)
        self.rate = (self.position - position) / dt_s


class Links:
    """A robot's links: for each of its joints, the displacement (robot frame) of what rides on it
    from where the world file places it, composed through the joints it rides on. Axes and anchors
    are in the robot frame with every joint at its initial position (schemas/world.py ``Motor``)."""

    def __init__(self, model: wm.Robot, joints: dict[str, JointMotor]):
        specs = {d.name: d for d in model.devices if isinstance(d, wm.Motor) and d.name in joints}
        self._joints = joints
        self.order: list[str] = []           # parents before children
        placed: set[str] = set()

        def visit(name: str) -> None:
            if name in placed:
                return
            parent = specs[name].on_joint
            if parent is not None:
                visit(parent)
            placed.add(name)
            self.order.append(name)

        for name in specs:
            visit(name)
        self._frames = {}
        for name in self.order:
            d = specs[name]
            axis = np.asarray(d.joint_axis, dtype=np.float64)
            axis = axis / np.max(np.abs(axis))
            axis = axis / float(np.linalg.norm(axis))          # a unit axis (scaled first: no overflow)
            self._frames[name] = (isinstance(d, wm.RotationalMotor), axis, np.asarray(d.anchor, dtype=np.float64),
                                  d.on_joint)
        self.poses: dict[str, Pose] = {name: Pose.identity() for name in self.order}
        self._at: dict[str, float] = {name: self._joints[name].initial_position for name in self.order}

    def update(self) -> list[str]:
        """Recompute the links after the joints moved: the names of those whose pose changed."""
        changed: list[str] = []
        moved: set[str] = set()
        for name in self.order:
            hinge, axis, anchor, parent = self._frames[name]
            q = self._joints[name].position
            if q == self._at[name] and parent not in moved:
                continue
            self._at[name] = q
            delta = q - self._joints[name].initial_position
            if hinge:
                own = Pose.from_axis_angle(axis, delta)
                own = Pose._owned(own.rotation.copy(), anchor - own.rotation @ anchor)
            else:
                own = Pose(np.eye(3), axis * delta)
            self.poses[name] = own if parent is None else self.poses[parent].compose(own)
            moved.add(name)
            changed.append(name)
        return changed
