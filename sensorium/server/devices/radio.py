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

import numpy as np

__all__ = ["BROADCAST", "channels_match", "within_range", "within_cone", "reception"]

BROADCAST = -1


def channels_match(packet_channel: int, receiver_channel: int) -> bool:
    return packet_channel == receiver_channel or BROADCAST in (packet_channel, receiver_channel)


def within_range(emitter_pos: np.ndarray, receiver_pos: np.ndarray, range_m: float) -> bool:
    """Webots compares squared lengths: ``|r - e|² <= range²``; -1 is unlimited."""
    if range_m == -1.0:
        return True
    d = np.asarray(receiver_pos, dtype=np.float64) - np.asarray(emitter_pos, dtype=np.float64)
    return float(d @ d) <= range_m * range_m


def within_cone(apex: np.ndarray, axis: np.ndarray, target: np.ndarray, aperture: float) -> bool:
    """Whether ``target`` is within ``aperture / 2`` of the ray from ``apex`` along ``axis``
    (no cone when ``aperture <= 0``; a target at the apex has no angle and passes, as in Webots)."""
    if not aperture > 0.0:
        return True
    v = np.asarray(target, dtype=np.float64) - np.asarray(apex, dtype=np.float64)
    a = np.asarray(axis, dtype=np.float64)
    denom = math.sqrt(float(v @ v) * float(a @ a))
    if denom == 0.0:
        return True
    angle = math.acos(max(-1.0, min(1.0, float(v @ a) / denom)))
    return not angle > aperture / 2.0


def reception(receiver_rotation: np.ndarray, receiver_pos: np.ndarray, emitter_pos: np.ndarray, *,
              direction_noise: float = 0.0, signal_strength_noise: float = 0.0,
              rng: np.random.Generator | None = None) -> tuple[np.ndarray, float]:
    """(emitter direction in the receiver frame, signal strength) of one packet. ``rng`` is drawn
    from only for the noises that are non-zero (direction's three samples first)."""
    local = np.asarray(receiver_rotation, dtype=np.float64).T @ (
        np.asarray(emitter_pos, dtype=np.float64) - np.asarray(receiver_pos, dtype=np.float64))
    dist = math.sqrt(float(local @ local))
    with np.errstate(divide="ignore", invalid="ignore"):
        if direction_noise == 0.0 or rng is None:
            direction = local / dist
        else:
            noisy = local + dist * direction_noise * rng.standard_normal(3)
            direction = noisy / math.sqrt(float(noisy @ noisy))
    strength = 1.0 / (dist * dist) if dist > 0.0 else math.inf
    if signal_strength_noise != 0.0 and rng is not None:
        strength = max(0.0, strength * (1.0 + signal_strength_noise * float(rng.standard_normal())))
    return direction, strength
