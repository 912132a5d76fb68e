"""InertialUnit and Compass: the device's orientation, as Webots reports it.

InertialUnit (``WbInertialUnit`` + the controller's ``inertial_unit.c``):

* the quaternion (x, y, z, w) of the device's rotation in world axes, of the sign Webots'
  ``WbMatrix3::toQuaternion`` gives it (:func:`webots_sign`: w > 0 for a turn up to 120°, else the
  component of the matrix's largest diagonal term > 0);
* ``noise`` > 0: the rotation is turned, in the device frame, by three Gaussian angles of
  standard deviation ``noise·π`` about its x, y and z axes;
* an axis switched off (``xAxis``/``yAxis``/``zAxis`` false) zeroes one component of the
  rotation's axis (Webots' mapping: xAxis → x, yAxis → z, zAxis → y, kept from its NUE days),
  the angle is kept;
* ``resolution`` rounds each quaternion component (``trunc(q/res + 0.5)·res``);
* roll / pitch / yaw from the quaternion: ENU ``roll = atan2(2(wx + yz), 1 - 2(x² + y²))``,
  ``pitch = asin(2(wy - zx))`` (clamped), ``yaw = atan2(2(wz + xy), 1 - 2(y² + z²))``; NUE (extrinsic
  Y(yaw)·Z(pitch)·X(roll)) ``yaw = atan2(2(yw - xz), 1 - 2(y² + z²))``, ``roll = atan2(2(xw - yz),
  1 - 2(x² + z²))``, ``pitch = asin(2(xy + zw))``.

Compass (``WbCompass``): the world's north (ENU: +y, NUE: +x) in the device frame, ``Rᵀ·north``
normalised, each enabled axis through the lookup table (with its noise), then ``resolution``; a
disabled axis reads NaN.

Pure: quaternions, vectors and a random stream in; values out.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.server.devices.lookup import LookupTable, quantize_sensor
from sensorium.server.devices.motion_sensors import axes_through_table

__all__ = ["compass_values", "inertial_quaternion", "north_vector", "quaternion_multiply", "roll_pitch_yaw",
           "webots_sign"]


def quaternion_multiply(a, b) -> np.ndarray:
    """Hamilton product ``a ⊗ b`` of (x, y, z, w) quaternions (the rotation ``a`` then, in its frame, ``b``)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz])


def _axis_quaternion(axis: int, angle: float) -> np.ndarray:
    q = np.zeros(4)
    q[axis] = math.sin(angle / 2.0)
    q[3] = math.cos(angle / 2.0)
    return q


def inertial_quaternion(q, *, noise: float = 0.0, rng: np.random.Generator | None = None,
                        x_axis: bool = True, y_axis: bool = True, z_axis: bool = True,
                        resolution: float = -1.0) -> np.ndarray:
    """``wb_inertial_unit_get_quaternion`` from the device's world rotation ``q`` (x, y, z, w)."""
    out = np.array(q, dtype=np.float64)
    if noise != 0.0:
        assert rng is not None
        a, b, c = noise * math.pi * rng.standard_normal(3)
        turn = quaternion_multiply(quaternion_multiply(_axis_quaternion(0, a), _axis_quaternion(1, b)),
                                   _axis_quaternion(2, c))
        out = quaternion_multiply(out, turn)
    if not (x_axis and y_axis and z_axis):
        half = math.atan2(math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2), out[3])
        axis = out[:3].copy()
        if not x_axis:
            axis[0] = 0.0
        if not y_axis:
            axis[2] = 0.0
        if not z_axis:
            axis[1] = 0.0
        norm = math.sqrt(float(axis @ axis))
        out = np.array([0.0, 0.0, 0.0, 1.0]) if norm == 0.0 else np.array([*(axis / norm * math.sin(half)),
                                                                           math.cos(half)])
    out = webots_sign(out)
    if resolution != -1.0:
        out = np.asarray(quantize_sensor(out, resolution), dtype=np.float64)
    return out


def webots_sign(q: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) (x, y, z, w), each as ``q`` or ``-q``: the one Webots'
    ``WbMatrix3::toQuaternion`` returns for its rotation matrix (whose diagonal is ``2w² − 1 + 2x²``,
    ``… + 2y²``, ``… + 2z²``, its trace ``4w² − 1``): w > 0 where the trace is >= 0, else the
    component of the largest diagonal term > 0 (x, then y, then z, ties as its strict tests break
    them). Webots discretizes these components (``resolution``), so the sign changes the values."""
    q = np.asarray(q, dtype=np.float64)
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    ww = 2.0 * w * w
    m0, m4, m8 = -1.0 + 2.0 * x * x + ww, -1.0 + 2.0 * y * y + ww, -1.0 + 2.0 * z * z + ww
    key = np.where(m0 + m4 + m8 >= 0.0, w, np.where((m0 > m4) & (m0 > m8), x, np.where(m4 > m8, y, z)))
    return np.where((key < 0.0)[..., None], -q, q)


def roll_pitch_yaw(q, axes: str = "ENU") -> np.ndarray:
    """``wb_inertial_unit_get_roll_pitch_yaw`` (rad) from a quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in q)
    if axes == "NUE":
        yaw = math.atan2(2 * y * w - 2 * x * z, 1 - 2 * y * y - 2 * z * z)
        roll = math.atan2(2 * x * w - 2 * y * z, 1 - 2 * x * x - 2 * z * z)
        pitch = math.asin(max(-1.0, min(1.0, 2 * x * y + 2 * z * w)))
        return np.array([roll, pitch, yaw])
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return np.array([roll, pitch, yaw])


def north_vector(axes: str) -> np.ndarray:
    """The world's north: the N axis of its coordinate system (ENU: +y, NUE: +x)."""
    v = np.zeros(3)
    v[axes.index("N")] = 1.0
    return v


def compass_values(rotation: np.ndarray, axes: str, table: LookupTable, rng: np.random.Generator | None,
                   *, x_axis: bool = True, y_axis: bool = True, z_axis: bool = True,
                   resolution: float = -1.0) -> np.ndarray:
    """``wb_compass_get_values``: north in the device frame, through the lookup table per axis."""
    local = np.asarray(rotation, dtype=np.float64).T @ north_vector(axes)
    local /= math.sqrt(float(local @ local))
    return axes_through_table(local, table, rng, (x_axis, y_axis, z_axis), resolution)
