"""Gyro, Accelerometer and Altimeter from the kinematic motion (no physics: no forces, no vibration).

The motion is the device's world pose after each basic step; a kinematic robot moves by exact arcs
(or is placed by a supervisor), so differences over one basic step ``dt`` are the readings:

* Gyro: the angular velocity in the device frame, the rotation vector of ``R₀ᵀ·R₁`` over ``dt``
  (exact for a constant turn: ``(0, 0, ω)`` about up);
* Accelerometer: the specific force in the device frame, ``Rᵀ·(a + g·up)`` with ``a`` the second
  difference of the device position over the last two basic steps ``(p₂ - 2p₁ + p₀)/dt²`` (0 at
  rest and on a straight line; a constant turn of radius ``r`` gives ``2r(1 - cos ωdt)/dt²``
  towards the centre, → ``v·ω``), ``g`` the world's gravity: at rest it reads ``+g`` on the up
  axis, as Webots' does;
* Altimeter: the height of the device along the up axis (plus ``gpsReference``'s altitude in a
  WGS84 world).

Before the motion is known (fewer poses than needed since the device was enabled) the Gyro and
Accelerometer assume rest. Each axis then goes through the lookup table (with its noise) and
``resolution``; a disabled axis reads NaN.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.server.devices.lookup import LookupTable, quantize_sensor

__all__ = ["angular_velocity", "axes_through_table", "specific_force", "up_vector"]


def up_vector(axes: str) -> np.ndarray:
    v = np.zeros(3)
    v[axes.index("U")] = 1.0
    return v


def angular_velocity(r0: np.ndarray, r1: np.ndarray, dt_s: float) -> np.ndarray:
    """rad/s in the frame of ``r1``: the rotation from ``r0`` to ``r1`` (world rotations) over ``dt_s``."""
    rel = np.asarray(r0).T @ np.asarray(r1)               # r1 = r0 · rel: the turn in the device frame
    cos = max(-1.0, min(1.0, (float(np.trace(rel)) - 1.0) / 2.0))
    angle = math.acos(cos)
    v = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    if angle < 1e-6:                                      # sin(angle) ~ angle: the skew part is the vector
        return v / 2.0 / dt_s
    return v * (angle / (2.0 * math.sin(angle))) / dt_s


def specific_force(rotation: np.ndarray, p0, p1, p2, dt_s: float, gravity: float, axes: str) -> np.ndarray:
    """m/s² in the device frame: what an accelerometer at ``p2`` (after ``p1``, ``p0``) reads."""
    a = (np.asarray(p2, dtype=np.float64) - 2.0 * np.asarray(p1) + np.asarray(p0)) / (dt_s * dt_s)
    return np.asarray(rotation).T @ (a + gravity * up_vector(axes))


def axes_through_table(values: np.ndarray, table: LookupTable, rng: np.random.Generator | None,
                       enabled: tuple[bool, bool, bool], resolution: float) -> np.ndarray:
    """Each enabled axis through the lookup table (one call: its noise drawn in axis order; an
    empty table is the identity), then ``resolution``; a disabled axis is NaN."""
    out = np.full(3, math.nan)
    on = [i for i in range(3) if enabled[i]]
    if not on:
        return out
    v = np.asarray(values, dtype=np.float64)[on]
    if len(table):
        v = np.asarray(table.lookup(v, rng), dtype=np.float64)
    if resolution != -1.0:
        v = np.asarray(quantize_sensor(v, resolution), dtype=np.float64)
    out[on] = v
    return out
