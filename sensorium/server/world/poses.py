"""World-file poses (axis-angle or quaternion) → float64 rotation matrices and back."""

from __future__ import annotations

import math

import numpy as np

from sensorium.server.world.geometry import Pose

# rad: a robot's own axis this near the world's up still counts as its up (sim/ground.py settles a robot
# whose z is; the .wbt drive judgement takes that axis for the robot's up). Webots' saved worlds keep the
# small tilts physics left (pr2.wbt's robot at 4.7e-6 rad); settling along the robot's up then errs by
# under 1 mm per metre between its origin and a wheel
ROBOT_UPRIGHT_TOL = 1e-3


def axis_angle_matrix(axis: tuple[float, float, float] | np.ndarray, angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=np.float64)
    big = float(np.max(np.abs(a)))
    if big == 0.0:
        return np.eye(3)
    a = a / big                        # first to [-1, 1]: a norm of 1e300-sized values would overflow
    x, y, z = a / float(np.linalg.norm(a))
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array([
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ])


def quaternion_matrix(q: tuple[float, float, float, float] | np.ndarray) -> np.ndarray:
    """Quaternion in ROS order (x, y, z, w), normalised here (scaled to [-1, 1] first, so that
    1e300-sized or 1e-300-sized components neither overflow nor vanish)."""
    q = np.asarray(q, dtype=np.float64)
    q = q / float(np.max(np.abs(q)))
    x, y, z, w = q / float(np.linalg.norm(q))
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def _shepperd(r: np.ndarray) -> tuple[float, float, float, float]:
    """Rotation matrix → its quaternion (w, x, y, z), not normalised, by Shepperd's method: the
    largest of w, x, y, z first, accurate at half turns."""
    m = np.asarray(r, dtype=np.float64)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0.0:
        s = math.sqrt(tr + 1.0) * 2.0
        return 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    if m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2.0
        return (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    if m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2.0
        return (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2.0
    return (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s


def matrix_quaternion(r: np.ndarray) -> tuple[float, float, float, float]:
    """Rotation matrix → unit quaternion (x, y, z, w) with w >= 0."""
    w, x, y, z = _shepperd(r)
    q = np.array([x, y, z, w])
    q /= np.linalg.norm(q)
    if q[3] < 0:
        q = -q
    return tuple(float(v) for v in q)  # type: ignore[return-value]


def axis_angle(r: np.ndarray) -> list[float]:
    """Rotation matrix → Webots axis-angle (unit axis, angle in [0, π]); identity → 0 0 1 0. Through
    the quaternion of :func:`_shepperd`, accurate at half turns (a recognised object's orientation)."""
    w, x, y, z = _shepperd(r)
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-300:
        return [0.0, 0.0, 1.0, 0.0]
    return [x / n, y / n, z / n, 2.0 * math.atan2(n, w)]


def pose_from_model(p) -> Pose:
    """``schemas.world.Pose`` → float64 ``Pose``."""
    if p.quaternion is not None:
        r = quaternion_matrix(p.quaternion)
    elif p.rotation is not None:
        r = axis_angle_matrix(p.rotation[:3], p.rotation[3])
    else:
        r = np.eye(3)
    return Pose(rotation=r, translation=np.asarray(p.translation, dtype=np.float64))


def pose_from_values(translation, rotation=None, quaternion=None) -> Pose:
    """Pose from plain sequences (services, tests): axis-angle ``rotation`` or ``quaternion`` (x, y, z, w)."""
    t = np.asarray(translation, dtype=np.float64).reshape(3)
    if not np.isfinite(t).all():
        raise ValueError("translation must be finite")
    if quaternion is not None:
        q = np.asarray(quaternion, dtype=np.float64).reshape(4)
        if not np.isfinite(q).all() or not np.abs(q).max() > 0:
            raise ValueError("quaternion must be finite and non-zero")
        r = quaternion_matrix(q)
    elif rotation is not None:
        a = np.asarray(rotation, dtype=np.float64).reshape(4)
        if not np.isfinite(a).all():
            raise ValueError("rotation must be finite")
        r = axis_angle_matrix(a[:3], float(a[3]))
    else:
        r = np.eye(3)
    return Pose(rotation=r, translation=t)


def moved_pose(current: Pose, translation=None, rotation=None, quaternion=None) -> Pose:
    """``current`` with what is given replaced (a supervisor's move): no ``translation`` keeps its
    translation, neither ``rotation`` nor ``quaternion`` keeps its rotation."""
    if translation is None:
        translation = current.translation
    if rotation is None and quaternion is None:
        return Pose(rotation=current.rotation.copy(), translation=pose_from_values(translation).translation)
    return pose_from_values(translation, rotation, quaternion)
