"""LightSensor irradiance (spec §2.2) — pure math, world frame, float64.

The simulation builds one :class:`LightArrays` from every light that is ON (lights that are off
contribute nothing, not even ambient), with positions and directions already in world coordinates.
A SpotLight's axis depends on the consumer, as in Webots: light sensors get it turned by the nearest
enclosing Pose's own rotation only (``WbLightSensor::computeLightMeasurement``;
``Scene.sensor_lights``), cameras by every enclosing frame (WREN's ``SpotLight::update``;
``Scene.world_lights``). For a sensor at ``p`` with normal ``N``
(its local +x axis in world), per light:

* point/spot: ``L = (q - p)/d``, ``d = |q - p|``, ``att = 1/(a1 + a2 d + a3 d²)``;
  directional: ``L = -direction/|direction|``, ``d = 1000``, ``att = 1``;
* spot factor (spot only): ``alpha`` = angle between ``L`` and ``-axis``; 0 if ``alpha > cutOff``,
  1 if ``alpha <= beamWidth``, else ``(alpha - cutOff)/(beamWidth - cutOff)``. The tests are in this
  order, so a ``beamWidth`` above ``cutOff`` (Webots lowers it to ``cutOff`` at load) gives the same
  factor as the lowered value;
* direct ``Id = I * c * spot`` with ``c = N·L`` if ``c > 0`` else 0, and 0 when occluded;
* contribution ``att * (Ia + Id) * C`` (ambient attenuated, never occluded).

``E = F · Σ contributions / 3``. It is evaluated as ``Σ att (Ia + Id) (F·C)/3`` (same value up to
rounding) so that a zero term stays zero even when ``att`` is infinite (below).

Degenerate cases (decided here):

* Sensor exactly at a point/spot light (``d == 0``): ``L`` is undefined, so ``L = 0``, ``c = 0``
  and the direct term is 0; the ambient term uses ``att = 1/a1``. When ``a1 == 0`` that is
  ``+inf``: a term whose ``(Ia + Id)·(F·C)`` is 0 contributes exactly 0 (never NaN), otherwise
  ``E = +inf`` (the lookup table then clamps). Attenuation ``(0, 0, 0)`` or negative components are
  rejected when the arrays are built (the world loader rejects them first).
* A light in the sensor plane: ``c`` is computed as ``N·(q - p)/d``, so when ``N·(q - p)`` is exactly
  0 (e.g. axis-aligned poses) ``c`` is exactly 0 and the light gives no direct term.
* Spot angle: ``alpha = atan2(|L × R|, L·R)`` (accurate at every angle, unlike ``arccos``); the
  factor is continuous at both beam edges, so rounding in ``alpha`` only moves it by ulps.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, fields
from enum import IntEnum

import numpy as np

__all__ = [
    "LightKind",
    "Light",
    "LightArrays",
    "DIRECTIONAL_DISTANCE",
    "irradiance_many",
]

DIRECTIONAL_DISTANCE = 1000.0
"""Distance used for a DirectionalLight (occlusion segment length)."""


class LightKind(IntEnum):
    POINT = 0
    SPOT = 1
    DIRECTIONAL = 2


@dataclass(frozen=True, slots=True)
class Light:
    """One light that is ON, in world coordinates; defaults are the Webots node defaults.

    ``position`` is ignored for directional lights, ``direction`` for point lights,
    ``attenuation`` for directional lights, ``beam_width``/``cut_off_angle`` for non-spot lights.
    ``radius`` (point/spot) is read by cameras only (``shading.py``: no direct term farther than
    it, as Webots' renderer); light sensors ignore it, as Webots' LightSensor does.
    """

    kind: LightKind
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    attenuation: tuple[float, float, float] = (1.0, 0.0, 0.0)
    intensity: float = 1.0
    ambient_intensity: float = 0.0
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    beam_width: float = 1.570796
    cut_off_angle: float = 0.785398
    radius: float = 100.0


@dataclass(frozen=True)
class LightArrays:
    """All ON lights as read-only float64 arrays (n lights). Build with :meth:`from_lights`, or pass
    arrays directly (they are converted, validated and frozen). Spot/directional directions are
    normalised here; they must not be zero."""

    kind: np.ndarray               # (n,) int: 0 point, 1 spot, 2 directional
    position: np.ndarray           # (n, 3) world
    direction: np.ndarray          # (n, 3) world, unit (spot axis / directional direction)
    attenuation: np.ndarray        # (n, 3)
    intensity: np.ndarray          # (n,)
    ambient_intensity: np.ndarray  # (n,)
    color: np.ndarray              # (n, 3)
    beam_width: np.ndarray         # (n,)
    cut_off_angle: np.ndarray      # (n,)
    radius: np.ndarray | None = None   # (n,) point/spot, cameras only; None: +inf (no cut); directional: unused

    def __post_init__(self) -> None:
        kind = np.asarray(self.kind, dtype=np.int64).reshape(-1)
        n = len(kind)
        if np.any((kind < 0) | (kind > 2)):
            raise ValueError("light kind must be 0 (point), 1 (spot) or 2 (directional)")
        vec = {f: np.asarray(getattr(self, f), dtype=np.float64).reshape(n, 3)
               for f in ("position", "direction", "attenuation", "color")}
        sca = {f: np.asarray(getattr(self, f), dtype=np.float64).reshape(n)
               for f in ("intensity", "ambient_intensity", "beam_width", "cut_off_angle")}
        if not all(np.all(np.isfinite(a)) for a in (*vec.values(), *sca.values())):
            raise ValueError("light fields must be finite")
        radius = np.full(n, np.inf) if self.radius is None else np.asarray(self.radius, dtype=np.float64).reshape(n)
        if not np.all(radius >= 0.0):
            raise ValueError("light radius must be >= 0")
        sca["radius"] = radius
        local = kind != LightKind.DIRECTIONAL
        att = vec["attenuation"]
        if np.any(local & (np.any(att < 0.0, axis=1) | np.all(att == 0.0, axis=1))):
            raise ValueError("point/spot light attenuation must be non-negative and not (0, 0, 0)")
        norm = np.linalg.norm(vec["direction"], axis=1)
        oriented = kind != LightKind.POINT
        if np.any(oriented & (norm == 0.0)):
            raise ValueError("spot/directional light direction must not be zero")
        vec["direction"] = np.where(oriented[:, None],
                                    vec["direction"] / np.where(norm > 0.0, norm, 1.0)[:, None],
                                    vec["direction"])
        for name, value in (("kind", kind), *vec.items(), *sca.items()):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    def __len__(self) -> int:
        return len(self.kind)

    @property
    def count(self) -> int:
        """Number of lights."""
        return len(self.kind)

    @classmethod
    def from_lights(cls, lights: Iterable[Light]) -> LightArrays:
        lights = list(lights)

        def col(name: str, shape: tuple[int, ...]) -> np.ndarray:
            return np.array([getattr(l, name) for l in lights], dtype=np.float64).reshape(shape)

        n = len(lights)
        return cls(kind=np.array([int(l.kind) for l in lights], dtype=np.int64),
                   position=col("position", (n, 3)), direction=col("direction", (n, 3)),
                   attenuation=col("attenuation", (n, 3)), intensity=col("intensity", (n,)),
                   ambient_intensity=col("ambient_intensity", (n,)), color=col("color", (n, 3)),
                   beam_width=col("beam_width", (n,)), cut_off_angle=col("cut_off_angle", (n,)),
                   radius=col("radius", (n,)))

    @classmethod
    def empty(cls) -> LightArrays:
        return cls.from_lights(())

    def subset(self, index: Sequence[int]) -> LightArrays:
        """These lights' arrays at ``index`` (in that order), their values as they are (not
        normalised again: a unit direction keeps its bits)."""
        idx = np.asarray(index, dtype=np.int64)
        out = object.__new__(LightArrays)
        for f in fields(self):
            a = getattr(self, f.name)
            if a is not None:
                a = a[:, idx] if a.ndim == 3 else a[idx]       # (S, n, 3): per point (batched lights)
                a.setflags(write=False)
            object.__setattr__(out, f.name, a)
        return out


def _per_point(a: np.ndarray) -> np.ndarray:
    """A light field (n, 3) shared by every point as (1, n, 3); (S, n, 3), one row per point (the
    batched simulation's lights carried by robots, sim/batched_lights.py), as it is."""
    return a if a.ndim == 3 else a[None, :, :]


def _vectors(points: np.ndarray, lights: LightArrays):
    """For S points: unnormalised sensor→light vectors v (S,n,3), |v| (S,n), unit L (S,n,3; 0 where
    |v| = 0) and distances d (S,n; 1000 for directional lights)."""
    directional = lights.kind == LightKind.DIRECTIONAL
    some = bool(directional.any())         # no directional light: no choice to make per pair
    v = _per_point(lights.position) - points[:, None, :]
    if some:
        v = np.where(directional[None, :, None], -_per_point(lights.direction), v)
    length = np.linalg.norm(v, axis=2)
    safe = np.where(length > 0.0, length, 1.0)
    unit = v / safe[:, :, None]
    d = np.where(directional[None, :], DIRECTIONAL_DISTANCE, length) if some else length
    return v, length, unit, d


def _terms(P: np.ndarray, N: np.ndarray, lights: LightArrays) -> tuple[np.ndarray, np.ndarray]:
    """Attenuation ``att`` (S,n) and un-occluded direct term ``Id = I·c·spot`` (S,n)."""
    vectors = _vectors(P, lights)
    return _attenuation(lights, vectors[3]), _direct(N, lights, vectors)


def _attenuation(lights: LightArrays, d: np.ndarray) -> np.ndarray:
    """``1 / (a0 + a1·d + a2·d²)`` (S,n) of each light at distance ``d``; 1 for a directional one."""
    local = lights.kind != LightKind.DIRECTIONAL
    a = lights.attenuation
    with np.errstate(divide="ignore"):
        return np.where(local[None, :], 1.0 / (a[:, 0] + a[:, 1] * d + a[:, 2] * d * d), 1.0)


def _direct(N: np.ndarray, lights: LightArrays, vectors: tuple) -> np.ndarray:
    """The un-occluded direct term ``Id = I·c·spot`` (S,n) from ``_vectors(P, lights)``."""
    v, length, unit, _ = vectors
    # c = N·(q - p)/d: exactly 0 when the light is exactly in the sensor plane (and when d = 0).
    c = np.einsum("sk,snk->sn", N, v) / np.where(length > 0.0, length, 1.0)

    is_spot = lights.kind == LightKind.SPOT
    if not np.any(is_spot):       # a spot factor of 1 everywhere: I·c·1 is I·c
        return np.where(c > 0.0, lights.intensity[None, :] * c, 0.0)
    R = -_per_point(lights.direction)
    alpha = np.arctan2(np.linalg.norm(np.cross(unit, R), axis=2), np.einsum("snk,snk->sn", unit, R))
    bw, co = lights.beam_width[None, :], lights.cut_off_angle[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = (alpha - co) / (bw - co)
    factor = np.where(alpha > co, 0.0, np.where(alpha <= bw, 1.0, linear))
    spot = np.where(is_spot[None, :], factor, 1.0)
    return np.where(c > 0.0, lights.intensity[None, :] * c * spot, 0.0)


def irradiance_many(positions: np.ndarray, normals: np.ndarray, lights: LightArrays,
                    occluded: np.ndarray | None = None,
                    color_filters: np.ndarray = (1.0, 1.0, 1.0)) -> np.ndarray:
    """Irradiance ``E`` (S,) for S sensors: positions (S,3), unit normals (S,3) (world +x axes),
    ``occluded`` (S,n) bool or None, colour filters (S,3) or (3,)."""
    P = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    N = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    if len(lights) == 0:
        return np.zeros(len(P))
    att, direct = _terms(P, N, lights)
    return irradiance_from_terms(att, direct, lights, occluded, color_filters)


def light_terms(positions: np.ndarray, normals: np.ndarray, lights: LightArrays) -> tuple[np.ndarray, np.ndarray]:
    """Attenuation (S,n) and un-occluded direct term (S,n) of S sensors, to compute once and use
    both for choosing occlusion rays and for :func:`irradiance_from_terms`."""
    return _terms(np.asarray(positions, dtype=np.float64).reshape(-1, 3),
                  np.asarray(normals, dtype=np.float64).reshape(-1, 3), lights)


def direct_and_segments(positions: np.ndarray, normals: np.ndarray, lights: LightArrays
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The un-occluded direct term (S,n) of :func:`light_terms` and the occlusion segments (S,n,3),
    (S,n) of :func:`occlusion_segments_many`, the same values, from one pass of the point-to-light
    vectors (a camera choosing its shadow rays needs no attenuation)."""
    P = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    vectors = _vectors(P, lights)
    direct = _direct(np.asarray(normals, dtype=np.float64).reshape(-1, 3), lights, vectors)
    unit, d = _segments(vectors)
    return direct, unit, d


def irradiance_from_terms(att: np.ndarray, direct: np.ndarray, lights: LightArrays,
                          occluded: np.ndarray | None = None,
                          color_filters: np.ndarray = (1.0, 1.0, 1.0)) -> np.ndarray:
    """Irradiance ``E`` (S,) from :func:`light_terms` (see :func:`irradiance_many`)."""
    S, n = att.shape
    if n == 0:
        return np.zeros(S)
    if occluded is not None:
        direct = np.where(np.asarray(occluded, dtype=bool).reshape(S, n), 0.0, direct)
    F = np.broadcast_to(np.asarray(color_filters, dtype=np.float64), (S, 3))
    weight = (lights.ambient_intensity[None, :] + direct) * (F @ lights.color.T) / 3.0  # (S, n)
    with np.errstate(invalid="ignore"):
        terms = np.where(weight == 0.0, 0.0, att * weight)
    return terms.sum(axis=1)


def occlusion_segments_many(positions: np.ndarray, lights: LightArrays) -> tuple[np.ndarray, np.ndarray]:
    """Occlusion segments of S sensors, one per light from each sensor toward it: unit directions
    (S,n,3) and lengths (S,n) (the sensor–light distance, 1000 for directional lights); a hit with
    ``0 <= t <= length`` means occluded. A sensor exactly at a light gets direction (1, 0, 0) and
    length 0: its direct term is 0 whatever the ray reports."""
    return _segments(_vectors(np.asarray(positions, dtype=np.float64).reshape(-1, 3), lights))


def _segments(vectors: tuple) -> tuple[np.ndarray, np.ndarray]:
    _, _, unit, d = vectors
    far = d > 0.0
    if not far.all():          # a point at a light
        unit = np.where(far[:, :, None], unit, np.array([1.0, 0.0, 0.0]))
    return unit, d


def _sum_orders_are_numpy_s() -> bool:
    """Whether numpy sums the three products of ``_direct``'s einsum as ``(p0 + p2) + p1`` and the
    three squares of ``_vectors``' norm as ``(s0 + s1) + s2`` on this machine (and the spot
    factor's einsum and norm the same way). The einsum order is
    its SIMD build's (two float64 lanes: x86-64's baseline; an FMA build such as aarch64's fuses
    p2 into p0), so :func:`lit_segments` writes these sums as columns only where a probe of varied
    magnitudes shows they are the same bits, and otherwise uses ``_vectors``/``_direct`` themselves."""
    rng = np.random.default_rng(20261206)
    a, b = (rng.standard_normal((1024, 3)) * 10.0 ** rng.integers(-4, 5, (1024, 3)) for _ in range(2))
    p, s = a * b, b * b
    dot = np.einsum("sk,snk->sn", a, b[:, None, :])[:, 0]
    norm = np.linalg.norm(b[:, None, :], axis=2)[:, 0]
    r = b[:1]                                    # the spot factor's cosine: one axis for every point
    q = a * r
    cos = np.einsum("snk,snk->sn", a[:, None, :], r[None, :, :])[:, 0]
    return (np.array_equal(dot, (p[:, 0] + p[:, 2]) + p[:, 1])
            and np.array_equal(cos, (q[:, 0] + q[:, 2]) + q[:, 1])
            and np.array_equal(norm, np.sqrt((s[:, 0] + s[:, 1]) + s[:, 2])))


_COLUMN_SUMS = _sum_orders_are_numpy_s()


def lit_segments(points: np.ndarray, normals: np.ndarray, lights: LightArrays, j: int,
                 keep=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Light ``j`` alone: the S points (ascending indices) where its un-occluded direct term is
    above 0, with their occlusion segments towards it (unit rows (m, 3), C-contiguous, and lengths
    (m,)). The bits of ``direct_and_segments``' column ``j`` (the same float64 operations per value,
    in the same order), made from (S,) columns without its (S, n, 3) temporaries, a spot factor only
    where ``c > 0``, units only for the chosen points; ``direct_and_segments`` itself where numpy
    sums otherwise (``_COLUMN_SUMS``) or lights are per point. ``keep(i, lengths)`` may drop chosen
    points first (a bool per chosen point, or None: keep all)."""
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    N = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    kind = int(lights.kind[j])
    if not _COLUMN_SUMS or lights.position.ndim == 3:     # (S, n, 3): per point
        one = lights.subset([j])
        direct, unit, d = direct_and_segments(P, N, one)
        i = (direct[:, 0] > 0.0).nonzero()[0]
        lengths = d[:, 0].take(i)
        if keep is not None and (near := keep(i, lengths)) is not None:
            i, lengths = i[near], lengths[near]
        return i, np.take(unit[:, 0], i, axis=0), lengths
    intensity = float(lights.intensity[j])
    if intensity <= 0.0 or len(P) == 0:        # I·c (no spot factor) is never above 0
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros(0)
    directional = kind == LightKind.DIRECTIONAL
    if directional:
        x, y, z = -lights.direction[j]
        length = np.sqrt((x * x + y * y) + z * z)
    else:       # v = q - p as three columns (a (3,) minus (S, 3) rows is a slow loop of 3)
        q = lights.position[j]
        x, y, z = (np.subtract(q[k], P[:, k]) for k in range(3))
        length = x * x
        t = y * y
        length += t
        np.multiply(z, z, out=t)
        length += t
        np.sqrt(length, out=length)
    positive = length.min() > 0.0          # no point at the light (nor NaN): every |v| is its own divisor
    # c = N·v/|v| as _direct's einsum sums it, (p0 + p2) + p1; |v| = 0 divides by 1
    c = N[:, 0] * x
    t = N[:, 2] * z
    c += t
    np.multiply(N[:, 1], y, out=t)
    c += t
    divisor = length if positive else np.where(length > 0.0, length, 1.0)
    c /= divisor
    if kind == LightKind.SPOT:
        i = _spot_lit(c, divisor, (x, y, z), lights, j, intensity)
    else:   # direct = I·c where c > 0: above 0 exactly where c·I is (I > 0), where c is (I >= 1: no underflow)
        i = ((c > 0.0) if intensity >= 1.0 else (np.multiply(c, intensity, out=c) > 0.0)).nonzero()[0]
    lengths = np.full(len(i), DIRECTIONAL_DISTANCE) if directional else length.take(i)
    if keep is not None and (near := keep(i, lengths)) is not None:
        i, lengths = i[near], lengths[near]
    unit = np.empty((len(i), 3))
    if directional:
        unit[:] = np.array([x, y, z]) / (length if positive else 1.0)
        return i, unit, lengths
    far = None if positive else lengths > 0.0
    safe = lengths if far is None else np.where(far, lengths, 1.0)
    for k, col in enumerate((x, y, z)):
        np.divide(col.take(i), safe, out=unit[:, k])
    if far is not None:      # a point at the light (or within 1e-162 m of it): _segments' (1, 0, 0), length 0
        unit[~far] = (1.0, 0.0, 0.0)
    return i, unit, lengths


def _spot_lit(c: np.ndarray, divisor: np.ndarray, v: tuple, lights: LightArrays, j: int, intensity: float) -> np.ndarray:
    """The points (ascending) where spot light ``j``'s direct term ``I·c·spot`` is above 0, its
    spot factor made (as ``_direct`` makes it: unit = v/divisor, the angle to the axis by
    ``atan2(|unit × R|, unit·R)``, numpy's cross products) only where ``c > 0``."""
    i = (c > 0.0).nonzero()[0]
    d = divisor.take(i)
    u0, u1, u2 = (col.take(i) / d for col in v)
    r0, r1, r2 = -lights.direction[j]
    cp0 = u1 * r2
    cp0 -= u2 * r1
    cp1 = u2 * r0
    cp1 -= u0 * r2
    cp2 = u0 * r1
    cp2 -= u1 * r0
    sin = cp0 * cp0
    sin += cp1 * cp1
    sin += cp2 * cp2
    np.sqrt(sin, out=sin)
    cos = u0 * r0
    cos += u2 * r2
    cos += u1 * r1
    alpha = np.arctan2(sin, cos)
    bw, co = lights.beam_width[j], lights.cut_off_angle[j]
    with np.errstate(divide="ignore", invalid="ignore"):
        linear = (alpha - co) / (bw - co)
    factor = np.where(alpha > co, 0.0, np.where(alpha <= bw, 1.0, linear))
    return i[(intensity * c.take(i)) * factor > 0.0]
