"""Kinematic wheeled drive (two wheels, or skid steer): Webots-style wheel motors and exact pose
integration.

No physics: wheels never slip and nothing collides. Over a basic step the wheel speeds are
constant, so the robot follows an exact circular arc (or a straight segment); integrating the arc
in closed form, in float64, keeps a robot driven in a circle on its circle for millions of steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sensorium.server.world.geometry import Pose

_TWO_PI = 2.0 * math.pi


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

    def set_velocity(self, value: float) -> None:
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ValueError(f"motor {self.name!r}: velocity must be a finite number, got {value!r}")
        # Webots clamps to maxVelocity (with a warning)
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


class DifferentialDrive:
    """The drive of one robot: its wheel motors and the robot's planar state (x, y, yaw).

    Two wheels, or several per side (skid steer, ``config.skid_steer``): each side rolls at the
    mean of its wheels' speeds, without slip, so a skid-steer robot turns as a two-wheel robot whose
    track is the distance between its wheel lines (a real one skids and turns slower).

    The robot's rotation is kept as ``Rz(yaw) @ base`` where ``base`` is the part of its initial
    rotation that is not a turn about the up axis, so a tilted robot keeps its tilt while driving.
    The state is kept in ENU axes; in a NUE world poses are converted on the way in and out, so the
    robot drives on the ground plane (normal +y) there.
    """

    def __init__(self, config, pose: Pose, up: str = "ENU"):
        self._to_enu = _TO_ENU[up]
        self.wheel_radius = float(config.wheel_radius)
        self.axle_length = float(config.axle_length)
        speed = float(config.max_wheel_speed)
        skid = getattr(config, "skid_steer", None)
        self.left = WheelMotor(config.left_motor, speed)
        self.right = WheelMotor(config.right_motor, speed)
        self.lefts = [self.left, *(WheelMotor(name, speed) for name in (skid.left if skid else ()))]
        self.rights = [self.right, *(WheelMotor(name, speed) for name in (skid.right if skid else ()))]
        self.reset(pose)

    def reset(self, pose: Pose) -> None:
        """Take over a pose set from outside (initial pose, supervisor set_pose)."""
        if self._to_enu is not None:
            pose = Pose(self._to_enu @ pose.rotation, self._to_enu @ pose.translation)
        forward = pose.rotation[:, 0]
        self.yaw = math.atan2(forward[1], forward[0])
        self.base = _rz(-self.yaw) @ pose.rotation
        self.x, self.y, self.z = (float(v) for v in pose.translation)

    @property
    def motors(self) -> dict[str, WheelMotor]:
        return {m.name: m for m in (*self.lefts, *self.rights)}

    @property
    def moving(self) -> bool:
        return any(m.velocity != 0.0 for m in (*self.lefts, *self.rights))

    def step(self, dt_ms: int) -> Pose | None:
        """Advance one basic step; the new pose, or None when the wheels did not turn."""
        dt = dt_ms / 1000.0
        if len(self.lefts) == 1 and len(self.rights) == 1:
            wl, wr = self.left.advance(dt), self.right.advance(dt)
        else:       # skid steer: each side at the mean of its wheels
            wl = sum(m.advance(dt) for m in self.lefts) / len(self.lefts)
            wr = sum(m.advance(dt) for m in self.rights) / len(self.rights)
        if wl == 0.0 and wr == 0.0:
            return None
        v = self.wheel_radius * (wl + wr) / 2.0
        w = self.wheel_radius * (wr - wl) / self.axle_length
        self.x, self.y, self.yaw = arc_step(self.x, self.y, self.yaw, v, w, dt)
        return self.pose()

    def pose(self) -> Pose:
        r, t = _rz(self.yaw) @ self.base, np.array([self.x, self.y, self.z])
        if self._to_enu is not None:
            r, t = self._to_enu.T @ r, self._to_enu.T @ t
        return Pose(rotation=r, translation=t)
