"""Kinematic wheeled drives (two wheels, skid steer, car-like Ackermann steering, four mecanum
wheels, three or more omni wheels, wheels that each steer): Webots-style wheel motors and exact pose integration.

No physics: wheels never slip and nothing collides. Over a basic step the wheel speeds are
constant, so the robot follows an exact circular arc (or a straight segment); integrating the arc
in closed form, in float64, keeps a robot driven in a circle on its circle for millions of steps.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.schemas.world import wheel_max_speed
from sensorium.server.sim.ground import (
    Ground,
    ground_angular_velocity,
    ground_rotation,
    placing_ceiling,
    ride_height,
    robot_up,
    slope_scales,
    slope_twist,
    support_ceiling,
)
from sensorium.server.world.geometry import Pose

_TWO_PI = 2.0 * math.pi



def velocity_accepted(name: str, value: float, target_position: float, velocity: float) -> bool:
    """Whether the in-process ``setVelocity(value)`` of motor ``name`` applies: NaN (and a bool)
    raises; a negative velocity while in position control (a finite target) is ignored with
    Webots' error line on stderr, as libController and the clients do. Infinite speeds apply (the
    caller clamps them to ``maxVelocity``). Shared by the simulation's wheels and a batched copy's
    motor view (gym/views.py), so both take the same commands alike."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        raise ValueError(f"motor {name!r}: velocity must be a number (inf is clamped to maxVelocity), got {value!r}")
    if value < 0.0 and not math.isinf(target_position):
        print(f"Error: setVelocity() called with negative 'velocity' argument in position control mode "
              f"({target_position:g}): motor {name!r} keeps {velocity:g}.", file=sys.stderr)
        return False
    return True

@dataclass(slots=True)
class WheelMotor:
    """A RotationalMotor as a controller sees it (``setPosition``/``setVelocity``).

    ``position = inf`` is velocity control (the wheel turns at ``velocity``); a finite target makes
    the wheel turn toward it at ``|velocity|`` and stop there, as Webots' position control does with
    the velocity as its speed limit.
    """

    name: str
    max_velocity: float
    target_position: float = 0.0        # Webots' default: position control at 0 ...
    velocity: float = math.nan          # ... at maxVelocity (set in __post_init__)
    position: float = 0.0               # wheel angle (rad), integrated
    initial_position: float = 0.0       # its angle as loaded (a state's "__init__"), as a JointMotor's

    def __post_init__(self) -> None:
        if math.isnan(self.velocity):
            self.velocity = self.max_velocity

    def hold(self) -> None:
        """Stop where the wheel is (position control at its current angle)."""
        self.target_position = self.position

    def set_position(self, value: float) -> None:
        if not isinstance(value, (int, float)) or math.isnan(value):
            raise ValueError(f"motor {self.name!r}: position must be a number or inf, got {value!r}")
        self.target_position = float(value)

    def place(self, position: float) -> str | None:
        """A Supervisor's ``setJointPosition``: the wheel (or steering) at ``position`` at once, its
        motor holding it there (WbJoint::setPosition; a steering target within its limits): the
        robot does not move for it. No warning line (None)."""
        self.position = float(position)
        self.set_position(position)
        return None

    def restore(self, position: float) -> None:
        """A loaded state (``loadState``): at ``position``, holding it at ``maxVelocity``."""
        self.velocity = self.max_velocity
        self.place(position)

    def set_velocity(self, value: float) -> None:
        """Webots' ``setVelocity`` in the in-process API (:func:`velocity_accepted`), clamped to
        ``maxVelocity`` (WbMotor warns; the clients print that warning, this API clamps silently)."""
        if velocity_accepted(self.name, value, self.target_position, self.velocity):
            self.command_velocity(value)

    def command_velocity(self, value: float) -> None:
        """A velocity a controller's step (or a motor service) sends: clamped to ``maxVelocity``. The
        clients already left out a negative one in position control when it was set; one sent with
        the target that the same step changes applies as its magnitude (the speed towards the target)."""
        self.velocity = float(min(max(value, -self.max_velocity), self.max_velocity))

    def advance(self, dt_s: float) -> float:
        """Turn the wheel for one step; returns the wheel's angular speed during it (rad/s)."""
        if math.isinf(self.target_position):
            omega = self.velocity
        else:
            remaining = self.target_position - self.position
            speed = min(abs(self.velocity), abs(remaining) / dt_s) if dt_s > 0 else 0.0
            omega = math.copysign(speed, remaining) if remaining else 0.0
        self.position += omega * dt_s
        return omega


def arc_step(x: float, y: float, yaw: float, v: float, w: float, dt: float) -> tuple[float, float, float]:
    """Exact planar pose after moving ``dt`` seconds at linear speed ``v`` and turn rate ``w``."""
    dyaw = w * dt
    if abs(dyaw) < 1e-9:
        # straight (second-order term kept so that tiny turn rates stay continuous)
        mid = yaw + 0.5 * dyaw
        return x + v * dt * math.cos(mid), y + v * dt * math.sin(mid), _wrap(yaw + dyaw)
    r = v / w
    x += r * (math.sin(yaw + dyaw) - math.sin(yaw))
    y -= r * (math.cos(yaw + dyaw) - math.cos(yaw))
    return x, y, _wrap(yaw + dyaw)


def mid_heading_step(x: float, y: float, yaw: float, v: float, w: float, dt: float) -> tuple[float, float, float]:
    """Webots' kinematic step of a robot without Physics (``step_rule: mid_heading``): a straight segment of
    length ``v·dt`` along the heading at mid-step, then the heading turned by ``w·dt`` (:func:`arc_step`'s
    straight branch, whatever the turn: the same float64 operations)."""
    dyaw = w * dt
    mid = yaw + 0.5 * dyaw
    return x + v * dt * math.cos(mid), y + v * dt * math.sin(mid), _wrap(yaw + dyaw)


def plain_sum(values: Iterable[float]) -> float:
    """The values added left to right from 0.0, one rounding each: ``sum()`` up to Python 3.11
    (3.12's compensates), and what the batched simulation adds column by column (batched_steered.py)."""
    total = 0.0
    for v in values:
        total = total + v
    return total


def _wrap(a: float) -> float:
    return (a + math.pi) % _TWO_PI - math.pi


def _rz(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# world axes → ENU axes (x east, y north, z up) for each supported WorldInfo.coordinate_system
_TO_ENU = {
    "ENU": None,
    "NUE": np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),  # x north, y up, z east
}


@dataclass(slots=True)
class SteeringMotor(WheelMotor):
    """A steering hinge's RotationalMotor: position control within ``±max_position`` (Webots clamps
    a target beyond the motor's min/maxPosition to it)."""

    max_position: float = math.inf

    def set_position(self, value: float) -> None:
        WheelMotor.set_position(self, value)     # (no zero-argument super() in a slots dataclass)
        self.target_position = min(max(self.target_position, -self.max_position), self.max_position)


class PlanarState:
    """A driven robot's planar state (x, y, yaw) in ENU axes and its pose.

    The robot's rotation is kept as ``Rz(yaw) @ base`` where ``base`` is the part of its initial
    rotation that is not a turn about the up axis, so a tilted robot keeps its tilt while driving.
    In a NUE world poses are converted on the way in and out, so the robot drives on the ground
    plane (normal +y) there.

    With a ``ground`` (a world with terrains, sim/ground.py) the robot rides it: :meth:`settle`,
    after each planar move, sets its height to the ground under its origin plus the clearance it
    was placed with, and over a sloped triangle its rotation becomes ``ground_rotation(slope, yaw)
    @ base`` (the ground's roll and pitch, the drive's yaw). A robot placed over nothing keeps its
    height wherever it goes, as without a ground. On a slope the wheels' speed is along the ground and
    their turn about its normal (:meth:`over_ground`), as Webots' wheels roll. ``band_low``: the bottom of its body's height
    band below its origin (ground.band_low), which with its height makes its support ceiling: box
    tops above it are not its ground (ground.py's support rule).

    ``forward``: the direction in the robot's own frame it drives along, (x, y) or (x, y, z) (a robot
    built y-up, whose forward lies in its x–z plane); None is its x axis (the heading is then read
    straight off the rotation's first column, as it always was). The heading ``yaw`` is that
    direction's in the world, about the world's up, and ``base`` what is left of the rotation, so the
    pose ``Rz(yaw) @ base`` is the robot's own rotation whichever of its axes is forward and whichever
    is up: an upright robot, z-up or y-up, turns about the world's up and rolls in the ground plane."""

    free_turned: dict[Any, float] | None = None
    """The rolled angles of its free wheels (a car's by key, a steered drive's by index); None: it has none."""

    def __init__(self, pose: Pose, up: str = "ENU", ground: Ground | None = None, band_low: float = 0.0,
                 forward: tuple[float, ...] | None = None):
        self._to_enu = _TO_ENU[up]
        self.ground = ground
        self.band_low = band_low
        self._forward: np.ndarray | None = None
        if forward is not None and tuple(forward) not in ((1.0, 0.0), (1.0, 0.0, 0.0)):
            f = [float(v) for v in forward] + [0.0] * (3 - len(forward))
            norm = math.hypot(*f)
            self._forward = np.array([f[0] / norm, f[1] / norm, f[2] / norm])
        self.reset(pose)

    def reset(self, pose: Pose) -> None:
        """Take over a pose set from outside (initial pose, supervisor set_pose)."""
        if self._to_enu is not None:
            pose = Pose(self._to_enu @ pose.rotation, self._to_enu @ pose.translation)
        forward = pose.rotation[:, 0] if self._forward is None else pose.rotation @ self._forward
        self.yaw = math.atan2(forward[1], forward[0])
        self.base = _rz(-self.yaw) @ pose.rotation
        self.x, self.y, self.z = (float(v) for v in pose.translation)
        # the last step's speed along the heading and turn rate (rad/s); ``linear`` (ENU x, y, m/s)
        # when kinematic contact replaced the move (its actual displacement) or the origin does not
        # move along the heading (a car's origin off its rear axle), else None
        self.speed = 0.0
        self.turn = 0.0
        self.linear: tuple[float, float] | None = None
        # riding the ground: its height where the robot was placed (None: nothing under it, or no
        # ground in the world), the robot's height then, the slope under it (None: level)
        self.rest: float | None = None
        self.z0 = self.z
        self.slope: tuple[float, float] | None = None
        if self.ground is not None:
            under = self.ground.at(self.x, self.y, float(placing_ceiling(self.z, self.band_low)))
            if under is not None:
                self.rest = under[0]
                self.slope = under[1:] if (under[1] or under[2]) else None
            if self.slope is not None and robot_up(pose.rotation, self._to_enu) is None:
                # placed tilted as the slope under it is (Webots' worlds put a robot on a ramp so): it stands
                # on the slope, its own rotation the placed one without the ground's attitude, never tilted twice
                gx, gy = self.slope
                on = ground_rotation(gx, gy, math.cos(self.yaw), math.sin(self.yaw), np.eye(3)).T @ pose.rotation
                if robot_up(on, self._to_enu) is not None:
                    self.base = on

    def settle(self) -> None:
        """Ride the ground after a planar move (nothing to do without one)."""
        if self.ground is None or self.rest is None:
            return
        under = self.ground.at(self.x, self.y, float(support_ceiling(self.z, self.band_low, self.z0, self.rest)))
        if under is None:
            self.slope = None         # nothing under it: it keeps its height, upright
            return
        h, gx, gy = under
        self.z = float(ride_height(self.z, self.z0, self.rest, True, h))
        self.slope = (gx, gy) if (gx or gy) else None

    def placed(self, pose: Pose) -> Pose:
        """The pose a robot put at ``pose`` (just :meth:`reset` there) takes: ``pose`` itself, or
        over a slope the ground's attitude (its height is kept)."""
        return pose if self.slope is None else self.pose()

    def own_pose(self) -> Pose:
        """The pose without the ground's attitude (``Rz(yaw) @ base``): what a supervisor move of
        the translation alone keeps as the rotation, so a robot on a slope is not tilted twice."""
        if self.slope is None:
            return self.pose()
        slope, self.slope = self.slope, None
        try:
            return self.pose()
        finally:
            self.slope = slope

    def over_ground(self, v: float, w: float) -> tuple[float, float]:
        """The wheels' speed along the ground ``v`` and turn rate about its normal ``w`` as the planar
        state integrates them, seen from above: on the slope under the origin at the step's start,
        ``v / √(1 + k²)`` (cos θ of the slope along the heading) and ``w·(1 + k²)/√(1 + gx² + gy²)``
        (:func:`ground.slope_scales`); level or off the ground, ``(v, w)`` untouched."""
        if self.slope is None:
            return v, w
        gx, gy = self.slope
        root, turn = slope_scales(gx, gy, math.cos(self.yaw), math.sin(self.yaw))
        return float(v / root), float(w * turn)

    def twist_over_ground(self, vx: float, vy: float, w: float) -> tuple[float, float, float]:
        """A holonomic drive's body twist (``vx`` ahead, ``vy`` to the left, both along the ground, ``w``
        about its normal) as the planar state integrates it, seen from above: on the slope under the
        origin at the step's start, :func:`ground.slope_twist`; level or off the ground, untouched."""
        if self.slope is None:
            return vx, vy, w
        gx, gy = self.slope
        hx, hy, hw = slope_twist(gx, gy, math.cos(self.yaw), math.sin(self.yaw), vx, vy, w)
        return float(hx), float(hy), float(hw)

    def moved(self, v: float, w: float) -> None:
        """Record the step's motion (v along the heading the step ends with, turn rate w): what
        :meth:`velocity` reports until the next step (worked out only when asked)."""
        self.speed, self.turn, self.linear = v, w, None

    def velocity(self) -> list[float]:
        """Webots' ``getVelocity``: linear (m/s) then angular (rad/s) velocity in world axes, as at
        the end of the last step (zeros when the robot did not move)."""
        linear = self.linear
        if linear is None:
            linear = (self.speed * math.cos(self.yaw), self.speed * math.sin(self.yaw))
        if self.slope is None:
            lin, ang = np.array([*linear, 0.0]), np.array([0.0, 0.0, self.turn])
        else:                         # along the plane under it, turning about its normal
            gx, gy = self.slope
            lin = np.array([*linear, gx * linear[0] + gy * linear[1]])
            ang = np.array(ground_angular_velocity(gx, gy, math.cos(self.yaw), math.sin(self.yaw), self.turn))
        if self._to_enu is not None:
            lin, ang = self._to_enu.T @ lin, self._to_enu.T @ ang
        return [float(v) for v in (*lin, *ang)]

    def pose(self) -> Pose:
        if self.slope is None:
            r = _rz(self.yaw) @ self.base
        else:
            r = ground_rotation(self.slope[0], self.slope[1], math.cos(self.yaw), math.sin(self.yaw), self.base)
        t = np.array([self.x, self.y, self.z])
        if self._to_enu is not None:
            r, t = self._to_enu.T @ r, self._to_enu.T @ t
        return Pose(rotation=r, translation=t)


class DifferentialDrive(PlanarState):
    """The drive of one robot: its wheel motors and the robot's planar state (x, y, yaw).

    Two wheels, or several per side (skid steer, ``config.skid_steer``): each side rolls at the
    mean of its wheels' speeds (negated for a side in ``config.reversed_motors``), without slip, so a skid-steer robot turns as a two-wheel robot whose
    track is the distance between its wheel lines (a real one skids and turns slower).

    The robot's rotation is kept as ``Rz(yaw) @ base`` where ``base`` is the part of its initial
    rotation that is not a turn about the up axis, so a tilted robot keeps its tilt while driving.
    The state is kept in ENU axes; in a NUE world poses are converted on the way in and out, so the
    robot drives on the ground plane (normal +y) there.

    The wheels' centre (``config.axle_center``, (cx, cy) along forward and its left) is where the
    robot turns: it moves at v along the heading while the robot turns at w, so the origin, at
    -(cx, cy) from it, moves with the body twist (v + w·cy, -w·cx), taken exactly over a step by
    :func:`twist_step`; a centre under the origin is the arc of the origin itself (:func:`arc_step`).
    ``config.step_rule`` ``mid_heading`` (Webots' rule without Physics) moves the origin by
    :func:`mid_heading_step` instead.
    """

    def __init__(self, config, pose: Pose, up: str = "ENU", ground: Ground | None = None, band_low: float = 0.0):
        self.wheel_radius = float(config.wheel_radius)
        self.axle_length = float(config.axle_length)
        cx, cy = getattr(config, "axle_center", (0.0, 0.0))
        self.center: tuple[float, float] | None = (float(cx), float(cy)) if (cx or cy) else None
        self.mid_heading = getattr(config, "step_rule", "arc") == "mid_heading"
        skid = getattr(config, "skid_steer", None)
        self.left = WheelMotor(config.left_motor, wheel_max_speed(config, config.left_motor))
        self.right = WheelMotor(config.right_motor, wheel_max_speed(config, config.right_motor))
        self.lefts = [self.left, *(WheelMotor(n, wheel_max_speed(config, n)) for n in (skid.left if skid else ()))]
        self.rights = [self.right, *(WheelMotor(n, wheel_max_speed(config, n)) for n in (skid.right if skid else ()))]
        # -1.0 for a side whose wheels are mounted mirrored (reversed_motors): a positive speed rolls them backward
        self.left_sign, self.right_sign = config.side_signs if hasattr(config, "side_signs") else (1.0, 1.0)
        super().__init__(pose, up, ground, band_low, getattr(config, "forward", None))

    @property
    def motors(self) -> dict[str, WheelMotor]:
        return {m.name: m for m in (*self.lefts, *self.rights)}

    def step(self, dt_ms: int) -> Pose | None:
        """Advance one basic step; the new pose, or None when the wheels did not turn."""
        dt = dt_ms / 1000.0
        if len(self.lefts) == 1 and len(self.rights) == 1:
            wl, wr = self.left.advance(dt), self.right.advance(dt)
        else:       # skid steer: each side at the mean of its wheels
            wl = sum(m.advance(dt) for m in self.lefts) / len(self.lefts)
            wr = sum(m.advance(dt) for m in self.rights) / len(self.rights)
        wl, wr = self.left_sign * wl, self.right_sign * wr      # (exact: a sign, the same bits as the batched pass)
        if wl == 0.0 and wr == 0.0:
            self.moved(0.0, 0.0)
            return None
        v = self.wheel_radius * (wl + wr) / 2.0
        w = self.wheel_radius * (wr - wl) / self.axle_length
        v, w = self.over_ground(v, w)
        if self.center is None:
            step = mid_heading_step if self.mid_heading else arc_step
            self.x, self.y, self.yaw = step(self.x, self.y, self.yaw, v, w, dt)
            self.moved(v, w)
            return self.pose()
        cx, cy = self.center           # the origin's body twist, the wheels' centre moving at v
        vx, vy = v + w * cy, -w * cx
        self.x, self.y, self.yaw = twist_step(self.x, self.y, self.yaw, vx, vy, w, dt)
        self.moved(vx, w)
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        self.linear = (vx * c - vy * s, vx * s + vy * c)     # the origin's velocity at the step's end
        return self.pose()


def twist_step(x: float, y: float, yaw: float, vx: float, vy: float, w: float,
               dt: float) -> tuple[float, float, float]:
    """Exact planar pose after moving ``dt`` seconds at the constant body twist (``vx`` ahead, ``vy``
    to the left, turn rate ``w``): the displacement in the step's starting frame is (a·vx − b·vy,
    b·vx + a·vy) with a = sin(w·dt)/w and b = (1 − cos(w·dt))/w = 2 sin²(w·dt/2)/w (a = dt, b = 0
    when w is 0), turned by the starting heading."""
    if w == 0.0:
        a, b = dt, 0.0
    else:
        half = math.sin(0.5 * w * dt)
        a, b = math.sin(w * dt) / w, 2.0 * half * half / w
    dx, dy = a * vx - b * vy, b * vx + a * vy
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * dx - s * dy, y + s * dx + c * dy, _wrap(yaw + w * dt)


class HolonomicDrive(PlanarState):
    """A drive whose wheels' speeds give a body twist (vx, vy, ω) of their own (:meth:`twist`)."""

    def twist(self, speeds: list[float]) -> tuple[float, float, float]:
        raise NotImplementedError

    def roll(self, speeds: list[float], dt: float) -> Pose | None:
        """Move by the twist of the wheels' ``speeds`` over ``dt`` s, exactly (:func:`twist_step`); the
        new pose, or None when no wheel turned."""
        if all(u == 0.0 for u in speeds):
            self.moved(0.0, 0.0)
            return None
        vx, vy, w = self.twist_over_ground(*self.twist(speeds))
        self.x, self.y, self.yaw = twist_step(self.x, self.y, self.yaw, vx, vy, w, dt)
        self.moved(vx, w)
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        self.linear = (vx * c - vy * s, vx * s + vy * c)     # the origin's velocity at the step's end
        return self.pose()


class MecanumDrive(HolonomicDrive):
    """Four mecanum wheels at (±lx, ±ly) (x forward, y left), rollers at 45°, no slip.

    A wheel at (x_i, y_i) with roller sign s_i turning at ω_i rolls the robot with r·ω_i = vx +
    s_i·vy + c_i·ωz, c_i = s_i·x_i − y_i. With diagonal wheels alike and the front two opposite (the
    schema's rule) the three columns (1, s_i, c_i) are orthogonal and every |c_i| is one c, so the
    least-squares body twist of the four speeds is vx = r·Σω_i/4, vy = r·Σs_i·ω_i/4, ωz =
    r·Σc_i·ω_i/(4c²): exact when the speeds agree with one twist, their best fit when they do not
    (a real robot's wheels would slip). Over a basic step the twist is constant and
    :func:`twist_step` moves the robot exactly."""

    def __init__(self, config, pose: Pose, up: str = "ENU", ground: Ground | None = None, band_low: float = 0.0):
        self.wheel_radius = float(config.wheel_radius)
        lx, ly = float(config.lx), float(config.ly)
        places = ((lx, ly), (lx, -ly), (-lx, ly), (-lx, -ly))      # front left, front right, rear left, rear right
        # each wheel: its motor, its roller sign, its c = s·x − y
        self.wheels = [(WheelMotor(name, wheel_max_speed(config, name)), float(s), float(s) * px - py)
                       for (_, name), s, (px, py) in zip(config.motor_fields, config.rollers, places)]
        self.c2 = 4.0 * self.wheels[0][2] ** 2
        super().__init__(pose, up, ground, band_low, getattr(config, "forward", None))

    @property
    def motors(self) -> dict[str, WheelMotor]:
        return {m.name: m for m, _, _ in self.wheels}

    def twist(self, speeds: list[float]) -> tuple[float, float, float]:
        """(vx, vy, ωz) in the drive's frame for the four wheels' speeds (rad/s, the wheels' order)."""
        r = self.wheel_radius
        tot = ts = tc = 0.0           # summed left to right (sum() compensates from Python 3.12 on), as
        for u, (_, s, c) in zip(speeds, self.wheels):       # the batched simulation sums (batched_mecanum.py)
            tot, ts, tc = tot + u, ts + s * u, tc + c * u
        return r * tot / 4.0, r * ts / 4.0, r * tc / self.c2

    def step(self, dt_ms: int) -> Pose | None:
        """Advance one basic step; the new pose, or None when the wheels did not turn."""
        dt = dt_ms / 1000.0
        speeds = [m.advance(dt) for m, _, _ in self.wheels]
        return self.roll(speeds, dt)


class OmniDrive(HolonomicDrive):
    """Three or more omni wheels (``omni_drive``): wheel i at p_i (x forward, y left) turning about
    a_i in the ground plane, rollers letting it slip freely along a_i, rolling without slip along
    d_i = a_i × up (where a positive speed rolls a wheel's centre: ω·r·(a × up)). A twist (vx, vy, ωz)
    rolls it at r_i·ω_i = d_i · (v + ωz × p_i), one row (d_ix, d_iy, d_i · (up × p_i)) of a matrix A;
    the body twist over a step is the least-squares solution of A·t = (r_i·ω_i), A's pseudo-inverse
    applied to the wheels' rims' speeds: exact when they agree with one twist (three wheels always do
    when A is invertible), their best fit when they do not (a real robot's wheels would slip). Over a
    basic step the twist is constant and :func:`twist_step` moves the robot exactly."""

    def __init__(self, config, pose: Pose, up: str = "ENU", ground: Ground | None = None, band_low: float = 0.0):
        rows = []
        self.wheels: list[tuple[WheelMotor, float]] = []
        for w in config.wheels:
            n = math.hypot(float(w.axis[0]), float(w.axis[1]))
            dx, dy = float(w.axis[1]) / n, -float(w.axis[0]) / n
            px, py = float(w.position[0]), float(w.position[1])
            rows.append((dx, dy, dx * -py + dy * px))
            self.wheels.append((WheelMotor(w.motor, wheel_max_speed(config, w.motor)), float(w.radius)))
        self.solve = np.linalg.pinv(np.array(rows, dtype=np.float64))
        """3 × N: the wheels' rim speeds (r_i·ω_i) to the body twist (vx, vy, ωz)."""
        self.columns = [(float(a), float(b), float(c)) for a, b, c in self.solve.T.tolist()]
        """Each wheel's column of :attr:`solve`, the numbers :meth:`twist` sums."""
        super().__init__(pose, up, ground, band_low, getattr(config, "forward", None))

    @property
    def motors(self) -> dict[str, WheelMotor]:
        return {m.name: m for m, _ in self.wheels}

    def twist(self, speeds: list[float]) -> tuple[float, float, float]:
        """(vx, vy, ωz) in the robot's frame for the wheels' speeds (rad/s, the wheels' order): the
        pseudo-inverse's columns times the rims' speeds, summed left to right in plain float64 (as the
        batched simulation sums them, batched_omni.py; a BLAS product may fuse and reorder)."""
        vx = vy = w = 0.0
        for u, (_, r), (a, b, c) in zip(speeds, self.wheels, self.columns):
            rim = u * r
            vx, vy, w = vx + a * rim, vy + b * rim, w + c * rim
        return vx, vy, w

    def step(self, dt_ms: int) -> Pose | None:
        """Advance one basic step; the new pose, or None when the wheels did not turn."""
        dt = dt_ms / 1000.0
        speeds = [m.advance(dt) for m, _ in self.wheels]
        return self.roll(speeds, dt)


class SteeredDrive(HolonomicDrive):
    """Wheels that each roll along their own heading (``steered_drive``: a PR2's casters, a rover's
    steered corners), no slip. Wheel i at p_i = (x_i, y_i) with heading h_i turning at ω_i moves its
    ground point at u_i = r_i·ω_i·(cos h_i, sin h_i); a body twist t = (vx, vy, ωz) moves it at
    v + ωz × p_i, the two rows (1, 0, -y_i) and (0, 1, x_i) of a matrix A that the headings do not
    change. The twist over a step is the least-squares fit A⁺·u, A's pseudo-inverse (the normal
    equations' closed form) computed once: exact when the wheels agree with one twist, their best
    fit when they do not. A steered wheel's heading is its fixed ``heading`` plus ``steer_sign`` times
    its steering joint's position that step (the joint moves first, by Webots' kinematic motor
    control, sim/joints.py; :meth:`bind` hands the drive the robot's joints)."""

    def __init__(self, config, pose: Pose, up: str = "ENU", ground: Ground | None = None, band_low: float = 0.0):
        rows = []
        # each wheel: its motor (None: a free wheel), radius, fixed heading, steer sign, steering motor's
        # name (None: fixed)
        self.wheels: list[tuple[WheelMotor | None, float, float, float, str | None]] = []
        self.places: list[tuple[float, float]] = []
        for w in config.wheels:
            px, py = float(w.position[0]), float(w.position[1])
            rows += [(1.0, 0.0, -py), (0.0, 1.0, px)]
            motor = WheelMotor(w.motor, wheel_max_speed(config, w.motor)) if w.motor is not None else None
            self.wheels.append((motor, float(w.radius), float(w.heading), float(w.steer_sign), w.steer))
            self.places.append((px, py))
        self.has_free = any(m is None for m, *_ in self.wheels)
        """Free wheels make the fit depend on the headings: :meth:`constrained_twist` each step."""
        self.free_turned: dict[int, float] = {i: 0.0 for i, (m, *_) in enumerate(self.wheels) if m is None}
        """Each free wheel's rolled angle (rad, along its heading positive) since the start, by wheel index."""
        solve = np.linalg.pinv(np.array(rows, dtype=np.float64))
        """3 × 2N: the wheels' ground velocities (u_ix, u_iy, ...) to the body twist (vx, vy, ωz)."""
        self.columns = [(tuple(float(v) for v in solve[:, 2 * i]), tuple(float(v) for v in solve[:, 2 * i + 1]))
                        for i in range(len(self.wheels))]
        """Each wheel's two columns of the pseudo-inverse (for u_ix, for u_iy), the numbers :meth:`twist` sums."""
        self.steering: list[object | None] = [None] * len(self.wheels)
        super().__init__(pose, up, ground, band_low, getattr(config, "forward", None))

    def bind(self, joints: dict) -> None:
        """The robot's joint motors: each steered wheel reads its steering motor's position."""
        self.steering = [joints[name] if name is not None else None for *_, name in self.wheels]

    @property
    def motors(self) -> dict[str, WheelMotor]:
        return {m.name: m for m, *_ in self.wheels if m is not None}

    def headings(self) -> list[float]:
        """Each wheel's heading now (rad, from forward towards the left)."""
        return [h + sign * float(joint.position) if joint is not None else h     # type: ignore[attr-defined]
                for (_, _, h, sign, _), joint in zip(self.wheels, self.steering)]

    def twist(self, speeds: list[float]) -> tuple[float, float, float]:
        """(vx, vy, ωz) in the robot's frame for the wheels' speeds (rad/s, the wheels' order) at their
        headings now: the pseudo-inverse's columns times the wheels' ground velocities, summed wheel by
        wheel in plain float64. With free wheels: :meth:`constrained_twist`."""
        if self.has_free:
            return self.constrained_twist(speeds)
        vx = vy = w = 0.0
        for u, (_, r, _, _, _), h, (a, b) in zip(speeds, self.wheels, self.headings(), self.columns):
            ux, uy = u * r * math.cos(h), u * r * math.sin(h)
            vx, vy, w = vx + a[0] * ux + b[0] * uy, vy + a[1] * ux + b[1] * uy, w + a[2] * ux + b[2] * uy
        return vx, vy, w

    def step(self, dt_ms: int) -> Pose | None:
        """Advance one basic step; the new pose, or None when the wheels did not turn."""
        dt = dt_ms / 1000.0
        speeds = [m.advance(dt) if m is not None else 0.0 for m, *_ in self.wheels]
        if self.has_free and any(u != 0.0 for u in speeds):
            self.roll_free(speeds, dt)
        return self.roll(speeds, dt)

    def roll_free(self, speeds: list[float], dt: float) -> None:
        """Turn the free wheels by the step's twist: each ground point's velocity v + ωz × p along the
        wheel's heading, times dt over its radius."""
        vx, vy, w = self.twist(speeds)
        headings = self.headings()
        for i in self.free_turned:
            px, py = self.places[i]
            h = headings[i]
            along = (vx - w * py) * math.cos(h) + (vy + w * px) * math.sin(h)
            self.free_turned[i] += along * dt / self.wheels[i][1]

    def constrained_twist(self, speeds: list[float]) -> tuple[float, float, float]:
        """The twist of a drive with free wheels, from its headings now. No wheel slides across its
        heading h_i: n_i · (v + ωz × p_i) = 0 with n_i = (-sin h_i, cos h_i), the row (-sin h_i, cos h_i,
        x_i cos h_i + y_i sin h_i). When those rows leave one line of twists d (rank 2: a tricycle's
        rear axle and steered wheel; d the cross product of the two rows farthest from parallel, in
        plain float64), the body moves at s·d with s = Σ r_i·ω_i / Σ a_i over the driven wheels, a_i =
        d's velocity of wheel i's ground point along its heading: the driven rims' speeds sum to the
        ground's (the rear axle's centre of a tricycle moves at the mean rim speed, AckermannDrive's
        rule), so the bicycle model comes out: v = r·ω, ωz = v·tan δ / L; when the a_i cancel (the front
        wheel across, the rear wheels turning the robot about their axle's centre) s is their least-squares
        Σ a_i·r_i·ω_i / Σ a_i². Rows of any other rank (the
        wheels' lines not meeting in one turn centre, or all parallel) fall back to the least-squares
        fit of every driven wheel's ground velocity and every wheel's no-slip-across row."""
        rows, along, rims = [], [], []
        for u, (motor, r, _, _, _), h, (px, py) in zip(speeds, self.wheels, self.headings(), self.places):
            c, s = math.cos(h), math.sin(h)
            rows.append((-s, c, px * c + py * s))
            if motor is not None:
                along.append((c, s, py * -c + px * s))          # (cos h, sin h) · (v + ωz × p)
                rims.append(u * r)
        best, d = 0.0, (0.0, 0.0, 0.0)
        for i, a in enumerate(rows):
            for b in rows[i + 1:]:
                cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
                size = math.sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2])
                if size > best:
                    best, d = size, cross
        scale = plain_sum(abs(v) for row in rows for v in row)
        if best > 1e-12 * scale * scale and all(
                abs(row[0] * d[0] + row[1] * d[1] + row[2] * d[2]) <= 1e-9 * best * scale for row in rows):
            speeds_of_d = [a[0] * d[0] + a[1] * d[1] + a[2] * d[2] for a in along]
            total, size = plain_sum(speeds_of_d), plain_sum(abs(a) for a in speeds_of_d)
            if size > 0.0:
                if abs(total) > 1e-9 * size:
                    k = plain_sum(rims) / total
                else:                   # the driven wheels' a_i cancel (a turn about the axle's centre)
                    k = plain_sum(a * u for a, u in zip(speeds_of_d, rims)) / plain_sum(a * a for a in speeds_of_d)
                return k * d[0], k * d[1], k * d[2]
        fit = np.array(rows + along, dtype=np.float64)
        target = np.array([0.0] * len(rows) + rims, dtype=np.float64)
        vx, vy, w = np.linalg.lstsq(fit, target, rcond=None)[0].tolist()
        return float(vx), float(vy), float(w)


def ackermann_angles(steering_angle: float, wheelbase: float, track_front: float) -> tuple[float, float]:
    """(right, left) front wheel angles for the bicycle model's angle ``steering_angle`` (positive:
    right), as Webots' Driver sets them: cot δ_right = cot δ - t/2L, cot δ_left = cot δ + t/2L (the
    client's vehicle library computes the same, sensorium/client/webots/vehicle/driver.py)."""
    if steering_angle == 0.0:
        return 0.0, 0.0
    cot, half = 1.0 / math.tan(steering_angle), track_front / (2.0 * wheelbase)
    return math.atan(1.0 / (cot - half)), math.atan(1.0 / (cot + half))


def wheel_places(config) -> dict[str, tuple[float, float, float]]:
    """A car's wheels by drive field: (x, y) from the rear axle's centre (x forward, y left; the
    robot's origin may be elsewhere: ``rear_axle_offset``) and radius."""
    L, tf, tr = float(config.wheelbase), float(config.track_front), float(config.track_rear)
    rf, rr = float(config.front_wheel_radius), float(config.rear_wheel_radius)
    return {"right_front_wheel": (L, -tf / 2, rf), "left_front_wheel": (L, tf / 2, rf),
            "right_rear_wheel": (0.0, -tr / 2, rr), "left_rear_wheel": (0.0, tr / 2, rr)}


class AckermannDrive(PlanarState):
    """A car-like robot: two steered front wheels, driven wheels at the front, the rear or both, the
    rear axle's centre at the robot's origin or ``rear_axle_offset`` from it along forward (x
    forward, y left).

    Bicycle model without slip: the turn centre lies on the rear axle's line at R = L·(cot δ_r +
    cot δ_l)/2 from its centre (δ: the front wheels' angles, positive to the right), so curvature
    κ = 2 tan δ_r tan δ_l / (L (tan δ_r + tan δ_l)), exact for Ackermann angles and a compromise
    for others. A wheel at (x_i, y_i) then rolls at v·s_i with s_i = |(1 - κ_l y_i, κ_l x_i)|
    (κ_l the curvature to the left), so the rear axle's centre moves at v = Σ r_i ω_i / Σ s_i over
    the driven wheels. The steering angles used for a step are the motors' at its end (they hold
    their positions by position control, at most ``max_steering_speed`` fast).

    With a ``rear_axle_offset`` a the rear axle's centre, a ahead of the origin along the heading,
    follows the arc, and the origin, rigidly a behind it, then lies on its own circle about the turn
    centre (radius √(R² + a²)) with the same change of heading (:func:`offset_arc_step`); a = 0 is
    the arc of the origin itself, operation for operation."""

    def __init__(self, config, pose: Pose, up: str = "ENU", ground: Ground | None = None, band_low: float = 0.0):
        self.wheelbase = float(config.wheelbase)
        self.track_front, self.track_rear = float(config.track_front), float(config.track_rear)
        self.sign = 1.0 if config.positive_steers == "right" else -1.0
        limit, steer_speed = float(config.max_steering_angle), float(config.max_steering_speed)
        self.right_steer = SteeringMotor(config.right_steer, steer_speed, max_position=limit)
        self.left_steer = SteeringMotor(config.left_steer, steer_speed, max_position=limit)
        place = wheel_places(config)
        # each driven wheel: its motor, its (x, y) on the car, its radius
        self.wheels = [(WheelMotor(name, wheel_max_speed(config, name)), *place[field]) for field, name in config.driven]
        # the wheels without a motor (Webots' Car: a propulsion car's front ones, a traction car's rear
        # ones): each rolls with the car; key -> (x, y, radius, steering index: 0 right, 1 left, -1 none)
        driven = {field for field, _ in config.driven}
        self.free: dict[str, tuple[float, float, float, int]] = {
            field[:-6]: (*place[field], steer) for field, steer in FREE_WHEELS if field not in driven}
        self.free_turned = dict.fromkeys(self.free, 0.0)
        """Each free wheel's rolled angle (rad, forward positive) since the start."""
        self.rear_axle = float(getattr(config, "rear_axle_offset", 0.0))
        super().__init__(pose, up, ground, band_low, getattr(config, "forward", None))

    @property
    def motors(self) -> dict[str, WheelMotor]:
        return {m.name: m for m in (self.right_steer, self.left_steer, *(w[0] for w in self.wheels))}

    def steering(self) -> tuple[float, float]:
        """The front wheels' angles (right, left), positive to the right."""
        return self.sign * self.right_steer.position, self.sign * self.left_steer.position

    def curvature(self) -> float:
        """1/R of the rear axle's centre, positive turning right (0: straight)."""
        tr, tl = (math.tan(a) for a in self.steering())
        if tr + tl == 0.0:
            return 0.0
        return 2.0 * tr * tl / (self.wheelbase * (tr + tl))

    def step(self, dt_ms: int) -> Pose | None:
        """Advance one basic step; the new pose, or None when the car did not move."""
        dt = dt_ms / 1000.0
        self.right_steer.advance(dt)
        self.left_steer.advance(dt)
        rolled = [(motor.advance(dt) * r, x, y) for motor, x, y, r in self.wheels]
        if all(u == 0.0 for u, _, _ in rolled):
            self.moved(0.0, 0.0)
            return None
        kl = -self.curvature()          # to the left, as yaw grows
        v = sum(u for u, _, _ in rolled) / sum(math.hypot(1.0 - kl * y, kl * x) for _, x, y in rolled)
        if self.free:
            self.roll_free(v, kl, dt)
        a = self.rear_axle
        v, w = self.over_ground(v, v * kl)
        if a == 0.0:
            self.x, self.y, self.yaw = arc_step(self.x, self.y, self.yaw, v, w, dt)
            self.moved(v, w)
        else:
            self.x, self.y, self.yaw = offset_arc_step(self.x, self.y, self.yaw, v, w, dt, a)
            self.moved(v, w)
            # the origin's own velocity: the axle's v along the heading plus ω × (origin - axle)
            c, s = math.cos(self.yaw), math.sin(self.yaw)
            self.linear = (v * c + a * w * s, v * s - a * w * c)
        return self.pose()


    def roll_free(self, v: float, kl: float, dt: float) -> None:
        """Turn the free wheels by the step's move: each wheel's contact point moves at v·(1 - κ y, κ x)
        (κ the curvature to the left), its rolled angle grows by that velocity along the wheel's own
        heading (its steering angle δ, positive right: (cos δ, -sin δ)) times dt over its radius."""
        steering = self.steering()
        for key, (x, y, r, steer) in self.free.items():
            delta = steering[steer] if steer >= 0 else 0.0
            along = (1.0 - kl * y) * math.cos(delta) - kl * x * math.sin(delta)
            self.free_turned[key] += v * dt * along / r


FREE_WHEELS = (("right_front_wheel", 0), ("left_front_wheel", 1), ("right_rear_wheel", -1), ("left_rear_wheel", -1))
"""A car's wheels by drive field, with the steering motor that turns each (0 right, 1 left, -1 none)."""


def offset_arc_step(x: float, y: float, yaw: float, v: float, w: float, dt: float,
                    a: float) -> tuple[float, float, float]:
    """:func:`arc_step` of the point ``a`` ahead of (x, y) along the heading (a car's rear axle
    centre, its origin at (x, y)): the origin's pose after the move, the point ``a`` behind the
    arc's end (sensorium/server/sim/batched.py's cars repeat these operations)."""
    ax, ay, yaw1 = arc_step(x + a * math.cos(yaw), y + a * math.sin(yaw), yaw, v, w, dt)
    return ax - a * math.cos(yaw1), ay - a * math.sin(yaw1), yaw1
