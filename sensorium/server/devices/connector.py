"""Webots Connector presence (WbConnector's rule, written from Webots' reference manual and its
source as facts): whether a peer connector is in position for this one to dock.

A peer is *present* when it is compatible (both ``symmetric``, or one ``active`` and the other
``passive``, with equal ``model`` strings) and in position as judged with *this* connector's
tolerances: the origins at most ``distance_tolerance`` apart (squared distances compared, ``<=``),
the x axes (the docking axes, pointing out of the docking surface) at an angle above
``pi - axis_tolerance`` (opposed), and, unless ``number_of_rotations`` is 0, the angle between the z
axes strictly within ``rotation_tolerance`` of one of the allowed docking rotations 0, 2π/n, ... up
to the half turn. Angles between unit vectors are ``acos`` of their dot product, clamped to [0, π].
float64 throughout; no state, no I/O.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["COMPATIBLE", "axes_opposed", "compatible", "near_enough", "presence", "rotation_aligned",
           "unit_angle"]

COMPATIBLE = frozenset({("symmetric", "symmetric"), ("active", "passive"), ("passive", "active")})


def unit_angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle (rad, [0, π]) between two unit vectors: acos of the dot product, clamped."""
    c = float(np.dot(a, b))
    if c >= 1.0:
        return 0.0
    if c <= -1.0:
        return math.pi
    return math.acos(c)


def compatible(type_a: str, model_a: str, type_b: str, model_b: str) -> bool:
    """Face types that dock together (symmetric-symmetric, active-passive) and equal models."""
    return (type_a, type_b) in COMPATIBLE and model_a == model_b


def axes_opposed(x_a: np.ndarray, x_b: np.ndarray, axis_tolerance: float) -> bool:
    """The docking (x) axes point at each other: their angle is above ``pi - axis_tolerance``."""
    return unit_angle(x_a, x_b) > math.pi - axis_tolerance


def rotation_aligned(z_a: np.ndarray, z_b: np.ndarray, number_of_rotations: int, rotation_tolerance: float) -> bool:
    """The z axes' angle alpha lies strictly within ``rotation_tolerance`` of k·2π/n for some k in
    0..n//2 (n = ``number_of_rotations``; 0: any rotation is aligned)."""
    n = int(number_of_rotations)
    if n == 0:
        return True
    alpha = unit_angle(z_a, z_b)
    step = 2.0 * math.pi / n
    beta = 0.0
    for _ in range(n // 2 + 1):
        if beta - rotation_tolerance < alpha < beta + rotation_tolerance:
            return True
        beta += step
    return False


def near_enough(origin_a: np.ndarray, origin_b: np.ndarray, distance_tolerance: float) -> bool:
    """The origins at most ``distance_tolerance`` apart (squared, as Webots compares them)."""
    d = np.asarray(origin_a, dtype=np.float64) - np.asarray(origin_b, dtype=np.float64)
    return float(np.dot(d, d)) <= distance_tolerance * distance_tolerance


def presence(me: tuple[str, str, float, float, int, float], my_rotation: np.ndarray, my_origin: np.ndarray,
             peers: Sequence[tuple[str, str, np.ndarray, np.ndarray]]) -> int:
    """Webots' presence value of a connector: -1 for a passive one, else 1 when one of ``peers``
    is present (see the module docstring), else 0.

    ``me``: (type, model, distance_tolerance, axis_tolerance, number_of_rotations, rotation_tolerance);
    ``my_rotation``: its world rotation (columns: its x, y, z axes); each peer: (type, model, world
    rotation, world origin)."""
    kind, model, distance_tolerance, axis_tolerance, rotations, rotation_tolerance = me
    if kind == "passive":
        return -1
    x, z = my_rotation[:, 0], my_rotation[:, 2]
    for p_kind, p_model, p_rotation, p_origin in peers:
        if (compatible(kind, model, p_kind, p_model) and axes_opposed(x, p_rotation[:, 0], axis_tolerance)
                and rotation_aligned(z, p_rotation[:, 2], rotations, rotation_tolerance)
                and near_enough(my_origin, p_origin, distance_tolerance)):
            return 1
    return 0
