"""Emitter/Receiver geometry (Webots' WbReceiver, restated): who can hear a packet and what the
receiver reads about it. Pure functions of positions, axes and parameters; a random stream is
passed in. Which packets travel and when is the simulation's (``server/sim/radio.py``).

* Channels match when equal or when either side is -1 (broadcast / listen to all).
* Range: a receiver hears an emitter within ``range`` metres of it (-1: any distance), measured
  between the devices' origins.
* Infra-red cones: the receiver must lie within ``aperture / 2`` of the emitter's x axis, and the
  emitter within ``aperture / 2`` of the receiver's x axis (an aperture <= 0 or -1 is no cone, as
  Webots checks ``aperture > 0``); radio and serial ignore apertures.
* Signal strength ``s = 1 / r²`` (r: distance between the origins), times ``1 + σ·N(0, 1)`` with
  ``σ = signal_strength_noise``, clipped at 0.
* Emitter direction: the emitter's origin in the receiver frame, normalised; with
  ``direction_noise`` each component first gets ``r·σ·N(0, 1)`` (Webots draws x, y, z, then the
  strength's sample).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["BROADCAST", "channels_match", "within_range", "within_cone", "reception"]

BROADCAST = -1


def channels_match(packet_channel: int, receiver_channel: int) -> bool:
    return packet_channel == receiver_channel or BROADCAST in (packet_channel, receiver_channel)


Vec = Sequence[float] | np.ndarray


def within_range(emitter_pos: Vec, receiver_pos: Vec, range_m: float) -> bool:
    """Webots compares squared lengths: ``|r - e|² <= range²``; -1 is unlimited."""
    if range_m == -1.0:
        return True
    dx, dy, dz = (float(receiver_pos[k]) - float(emitter_pos[k]) for k in range(3))
    return dx * dx + dy * dy + dz * dz <= range_m * range_m


def within_cone(apex: Vec, axis: Vec, target: Vec, aperture: float) -> bool:
    """Whether ``target`` is within ``aperture / 2`` of the ray from ``apex`` along ``axis``
    (no cone when ``aperture <= 0``; a target at the apex has no angle and passes, as in Webots)."""
    if not aperture > 0.0:
        return True
    v = [float(target[k]) - float(apex[k]) for k in range(3)]
    a = [float(axis[k]) for k in range(3)]
    denom = math.sqrt((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]))
    if denom == 0.0:
        return True
    cos = (v[0] * a[0] + v[1] * a[1] + v[2] * a[2]) / denom
    return not math.acos(max(-1.0, min(1.0, cos))) > aperture / 2.0


def reception(receiver_rotation: Sequence[Sequence[float]] | np.ndarray, receiver_pos: Vec, emitter_pos: Vec, *,
              direction_noise: float = 0.0, signal_strength_noise: float = 0.0,
              rng: np.random.Generator | None = None) -> tuple[tuple[float, float, float], float]:
    """(emitter direction in the receiver frame, signal strength) of one packet. ``rng`` is drawn
    from only for the noises that are non-zero (direction's three samples first). Plain float64
    arithmetic: the receiver-frame position is ``Rᵀ (e − r)``, each component summed x, y, z."""
    d = [float(emitter_pos[k]) - float(receiver_pos[k]) for k in range(3)]
    R = receiver_rotation
    local = [float(R[0][j]) * d[0] + float(R[1][j]) * d[1] + float(R[2][j]) * d[2] for j in range(3)]
    dist = math.sqrt(local[0] * local[0] + local[1] * local[1] + local[2] * local[2])
    if direction_noise != 0.0 and rng is not None:
        n = rng.standard_normal(3)
        local = [local[k] + dist * direction_noise * float(n[k]) for k in range(3)]
        norm = math.sqrt(local[0] * local[0] + local[1] * local[1] + local[2] * local[2])
    else:
        norm = dist
    direction = (_div(local[0], norm), _div(local[1], norm), _div(local[2], norm))
    strength = 1.0 / (dist * dist) if dist > 0.0 else math.inf
    if signal_strength_noise != 0.0 and rng is not None:
        strength = max(0.0, strength * (1.0 + signal_strength_noise * float(rng.standard_normal())))
    return direction, strength


def _div(a: float, b: float) -> float:
    """IEEE division (a zero distance gives NaN, as Webots' 0/0)."""
    if b == 0.0:
        return math.nan if a == 0.0 or math.isnan(a) else math.copysign(math.inf, a)
    return a / b
