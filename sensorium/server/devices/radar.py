"""Radar (Webots' Radar node): which targets a radar sees and what it reads of each.

A target is a solid or robot with a radar cross section σ > 0. As Webots' ``WbObjectDetection``
places it, a target has a box in the radar frame (x forward, y left, z up): the union of the boxes
of its bounding shapes' parts inside the radar's frustum (:func:`frustum`, clipped as a camera's
recognition clips, ``devices/recognition.py``), without any, that of its bounding sphere (its
shapes' spheres joined by :func:`enclose_sphere`, a mesh's by :func:`ritter_sphere`) cut across the
view, or, without shapes, its origin (a point, size 0).
For each candidate in view, in order (Webots' ``WbRadar``, its noise drawn in this order too):

1. the distance to the box's centre is at most ``max_range`` + half the box's x extent;
2. distance r = |centre| + N(0, range_noise); below ``min_range`` − half the x extent the target is
   dropped; r is clamped to [``min_range``, ``max_range``];
3. received power P = Pt·G²·λ²·σ / ((4π)³·r⁴) (W), with Pt = 10^(transmitted_power/10) mW,
   G = 10^(antenna_gain/10), λ = 0.299792458 / frequency (GHz) m; P below
   10^(min_detectable_signal/10) mW drops it;
4. radial speed: the velocity of the target's origin relative to the radar (both from their positions
   at the previous measurement, over the time since) along the radar-to-origin direction, positive
   when it moves away, + N(0, speed_noise); outside [min_radial_speed, max_radial_speed] (unless both
   are 0) or below ``min_absolute_radial_speed`` in magnitude (if > 0) drops it;
5. azimuth: the angle from the x axis to the target's origin in the radar's x-y plane, positive
   towards -y (to the right: Webots' sign), clamped to ±h/2, + N(0, angular_noise).

Then targets closer than ``cell_distance`` in distance (and, with ``cell_speed`` > 0, closer than
it in speed) merge into one whose distance, speed and azimuth are averages weighted by power and
whose power is their sum (Webots' ``mergeTargets``), and the power is given in dBm.
No clock, no I/O, no state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .recognition import Frustum

__all__ = ["Candidate", "RadarTarget", "azimuth", "candidate_targets", "detect", "enclose_point", "enclose_sphere",
           "finish", "frustum", "in_frustum", "merge", "radial_speed", "received_power_factor", "ritter_sphere", "to_dbm",
           "to_watts"]

LIGHT_SPEED_M_PER_NS = 0.299792458     # λ (m) = this / frequency (GHz)


@dataclass(frozen=True, slots=True)
class RadarTarget:
    """One target as Webots' ``WbRadarTarget`` gives it (power in dBm once :func:`detect` returns)."""

    distance: float
    received_power: float
    speed: float
    azimuth: float

    def as_list(self) -> list[float]:
        return [self.distance, self.received_power, self.speed, self.azimuth]


def to_watts(dbm: float) -> float:
    return 0.001 * 10.0 ** (dbm / 10.0)


def to_dbm(watts: float) -> float:
    return 10.0 * math.log10(watts / 0.001)


def received_power_factor(transmitted_power_dbm: float, antenna_gain_dbi: float, frequency_ghz: float) -> float:
    """Pt·G²·λ²/(4π)³ (W·m²): the radar equation's part that depends on the radar alone; the received
    power of a target of cross section σ at distance r is this × σ / r⁴."""
    gain = 10.0 ** (antenna_gain_dbi / 10.0)
    wavelength = LIGHT_SPEED_M_PER_NS / frequency_ghz if frequency_ghz != 0.0 else math.inf   # 0 GHz: as Webots
    return to_watts(transmitted_power_dbm) * gain * gain * wavelength * wavelength / (4.0 * math.pi) ** 3


def frustum(horizontal_fov: float, vertical_fov: float) -> Frustum:
    """The radar's view as Webots' ``computeFrustumPlanes`` makes it (half angles in float32): the
    clipping planes of ``devices/recognition.py``; round shapes are cut to it up to h = π/2."""
    th = math.tan(float(np.float32(horizontal_fov / 2.0)))
    tv = math.tan(float(np.float32(vertical_fov / 2.0)))
    n = np.array([[th, 1.0, 0.0], [tv, 0.0, 1.0], [th, -1.0, 0.0], [tv, 0.0, -1.0]], dtype=np.float64)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return Frustum(n, horizontal_fov <= math.pi / 2.0)


def in_frustum(p: np.ndarray, f: Frustum) -> bool:
    """Whether a point ``p`` in the radar frame is inside the frustum ``f`` (a target without shapes)."""
    q = np.asarray(p, dtype=np.float64)
    return bool(q[0] > 0.0 and (f.normals @ q >= 0.0).all())


def azimuth(p: np.ndarray) -> float:
    """Webots' azimuth of a point in the radar frame: positive to the right (towards -y)."""
    return -math.atan2(float(p[1]), float(p[0]))


def radial_speed(direction: np.ndarray, target_now: np.ndarray, target_before: np.ndarray | None,
                 radar_now: np.ndarray, radar_before: np.ndarray | None, elapsed_ms: int) -> float:
    """The target's velocity relative to the radar along ``direction`` (a unit vector from radar to
    target, world frame), from the positions at the previous measurement ``elapsed_ms`` ago; NaN
    without a previous position (the first measurement) or elapsed time."""
    if target_before is None or radar_before is None or elapsed_ms <= 0:
        return math.nan
    scale = 1000.0 / elapsed_ms
    relative = (target_now - target_before) * scale - (radar_now - radar_before) * scale
    return float(direction @ relative)


def ritter_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Webots' bounding sphere of a point set (its meshes' and elevation grids'): Ritter's
    approximation — from the first point, twice the farthest point from the last one found, the sphere
    on the last two as diameter, then each point enclosed in turn (:func:`enclose_point`)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        return np.zeros(3), 0.0
    far, near = pts[0], pts[0]
    farthest = 0.0
    for _ in range(2):
        near = far
        d2 = ((pts - near) ** 2).sum(axis=1)
        k = int(np.argmax(d2))
        farthest = float(d2[k])
        far = pts[k] if farthest > 0.0 else far
    centre, radius = (far + near) * 0.5, math.sqrt(farthest) * 0.5
    for p in pts:
        centre, radius = enclose_point(centre, radius, p)
    return centre, radius


def _empty(centre: np.ndarray, radius: float) -> bool:
    return radius == 0.0 and not centre.any()          # Webots' WbBoundingSphere::isEmpty


def enclose_point(centre: np.ndarray, radius: float, p: np.ndarray) -> tuple[np.ndarray, float]:
    """Webots' ``WbBoundingSphere::enclose(point)``: the sphere grown on the far side to take ``p``."""
    if _empty(centre, radius):
        return np.array(p, dtype=np.float64), 0.0
    delta = centre - p
    length = float(np.linalg.norm(delta))
    if length <= radius:
        return centre, radius
    grown = (length + radius) / 2.0
    return p + delta / length * grown, grown


def enclose_sphere(centre: np.ndarray, radius: float, other: np.ndarray, other_radius: float) -> tuple[np.ndarray, float]:
    """Webots' ``WbBoundingSphere::enclose(sphere)``: the smallest sphere on the line of both centres
    holding this one and ``other`` (an empty one, radius 0 at the origin, takes ``other`` as it is)."""
    if _empty(other, other_radius):
        return centre, radius
    if _empty(centre, radius):
        return np.array(other, dtype=np.float64), other_radius
    if np.array_equal(centre, other):
        return centre, max(radius, other_radius)
    offset = other - centre
    distance = float(np.linalg.norm(offset))
    total = radius + distance + other_radius
    if total <= 2.0 * radius:
        return centre, radius
    if total <= 2.0 * other_radius:
        return np.array(other, dtype=np.float64), other_radius
    grown = total / 2.0
    return centre + offset / distance * (grown - radius), grown


@dataclass(frozen=True, slots=True)
class Candidate:
    """A target in view: the centre of its box and its origin in the radar frame, its box's extent
    along x (0 for a point), its cross section (m²) and its radial speed before noise (m/s, NaN when
    unknown)."""

    centre: np.ndarray
    origin: np.ndarray
    size: float
    rcs: float
    speed: float


def detect(candidates: list[Candidate], config, rng: np.random.Generator | None = None) -> list[RadarTarget]:
    """The targets a radar of ``config`` (the world model's fields) reads from ``candidates``
    (module docstring); ``rng`` draws the noise (None: no noise)."""
    return finish([t for _, t in candidate_targets(candidates, config, rng)], config)


def candidate_targets(candidates: list[Candidate], config,
                      rng: np.random.Generator | None = None) -> list[tuple[int, RadarTarget]]:
    """Steps 1-5 of the module docstring for candidates in view: (candidate index, target with its
    power in W) of each that passes them, before any occlusion test and merging."""
    c = config
    factor = received_power_factor(c.transmitted_power, c.antenna_gain, c.frequency)
    threshold = to_watts(c.min_detectable_signal)
    limits = c.min_radial_speed != 0.0 or c.max_radial_speed != 0.0
    half = c.horizontal_field_of_view / 2.0

    def noise(sigma: float) -> float:
        return sigma * float(rng.standard_normal()) if rng is not None and sigma > 0.0 else 0.0

    found: list[tuple[int, RadarTarget]] = []
    for k, cand in enumerate(candidates):
        d = float(np.linalg.norm(cand.centre))
        if d > c.max_range + cand.size / 2.0:
            continue
        d += noise(c.range_noise)
        if d < c.min_range - cand.size / 2.0:
            continue
        d = min(max(d, c.min_range), c.max_range)
        power = factor * cand.rcs / d ** 4
        if power < threshold:
            continue
        speed = cand.speed + noise(c.speed_noise)
        if limits and (speed < c.min_radial_speed or speed > c.max_radial_speed):
            continue
        if c.min_absolute_radial_speed > 0.0 and abs(speed) < c.min_absolute_radial_speed:
            continue
        a = min(max(azimuth(cand.origin), -half), half) + noise(c.angular_noise)
        found.append((k, RadarTarget(d, power, speed, a)))
    return found


def finish(targets: list[RadarTarget], config) -> list[RadarTarget]:
    """The targets a controller reads: merged by cells (``cell_distance`` > 0), powers in dBm."""
    if config.cell_distance > 0.0:
        targets = merge(targets, config.cell_distance, config.cell_speed)
    return [RadarTarget(t.distance, to_dbm(t.received_power), t.speed, t.azimuth) for t in targets]


def merge(targets: list[RadarTarget], cell_distance: float, cell_speed: float) -> list[RadarTarget]:
    """Webots' ``mergeTargets`` (powers in W): the first target, in order, with later ones within
    ``cell_distance`` (and ``cell_speed`` when > 0) becomes their power-weighted average (power: the
    sum), the others leave; then again from that target on, until nothing merges."""
    out = list(targets)
    start = 0
    while True:
        merged = False
        i = start
        while i < len(out) - 1:
            t = out[i]
            close = [j for j in range(i + 1, len(out))
                     if abs(t.distance - out[j].distance) < cell_distance
                     and (cell_speed <= 0.0 or abs(t.speed - out[j].speed) < cell_speed)]
            if close:
                group = [t, *(out[j] for j in close)]
                p = sum(g.received_power for g in group)
                out[i] = RadarTarget(sum(g.distance * g.received_power for g in group) / p, p,
                                     sum(g.speed * g.received_power for g in group) / p,
                                     sum(g.azimuth * g.received_power for g in group) / p)
                for j in reversed(close):
                    del out[j]
                merged = True
                break
            i += 1
        if not merged:
            return out
        start = i
