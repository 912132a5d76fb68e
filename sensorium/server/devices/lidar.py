"""Lidar mathematics (spec §4, with this project's departures) — beams, ranges, point cloud, sweep.

Frames are FLU: x forward, y left, z up. W = horizontalResolution, L = numberOfLayers,
Φ = fieldOfView, φ_v = verticalFieldOfView, τ = tiltAngle.

Beams
    Layer i has the exact elevation ``e_i = φ_v/2 - i·φ_v/(L-1)`` (0 when L = 1). Column azimuths:
    fixed ``θ_j = Φ/2 - (j+½)·Φ/W`` (left → right; Φ = 2π gives no duplicated column), rotating
    ``θ_j = π - j·2π/W`` (column 0 behind, W/2 ahead, clockwise seen from +z), in (-π, π].

    Tilt is a pitch of the sensing head (positive τ raises z), applied where Webots applies it,
    to the internal camera:

    * fixed lidar: the whole fan is pitched about the lidar's y axis,
      ``d = pitch(τ)·(cos e cos θ, cos e sin θ, sin e)``;
    * rotating lidar: the camera is pitched inside the head, which yaws to each column's azimuth,
      ``d = (cos(e+τ) cos θ, cos(e+τ) sin θ, sin(e+τ))`` (a tilted beam sweeps a cone);
    * planar projection, fixed: beams go through the pixel centres of a perspective image,
      ``d ∝ pitch(τ)·(1, (1 - 2(j+½)/W)·tan(Φ/2), tan e_i)``. Layer rows: layer i is the image row
      at ordinate ``tan e_i``, i.e. the row on which the central beam has exactly elevation ``e_i``
      (each layer is a plane through the camera's y axis). Planar + rotating: the sampled column is
      at the image centre, so the beams are those of the rotating cylindrical case.

    Directions are in the lidar (base) frame also for a rotating lidar: the head's yaw is the
    column azimuth, so the simulation must not rotate the rays by the head pose.

Ranges (``ranges_from_hits``)
    The value is the Euclidean range (cylindrical) or the depth along the camera's optical axis
    (planar: ``pitch(τ)·x`` for a fixed lidar, the head's pitched forward axis for a rotating one).
    ``near``: the simulation casts with ``t_near = near``, so surfaces closer than ``near`` along the
    beam are clipped and do not occlude (Webots clips on each cube face's planar depth instead).
    Steps: (1) no hit, ``v < minRange`` or ``v >= maxRange`` → ``+inf``; (2) if ``noise > 0``, add
    ``N(0, (noise·maxRange)²)`` to each finite value (one draw per finite value, C order); (3) if
    ``resolution > 0``, ``floor(v/res + ½)·res``; (4) re-check the bounds: anything outside
    ``[minRange, maxRange)`` becomes ``+inf`` (noise or rounding can push a value out, never in),
    and after the cast to float32 a value that rounded up to ``float32(maxRange)`` becomes ``+inf``
    too. So every finite output ``v`` has ``minRange <= v`` (as float64 before the cast; a value
    exactly at minRange is kept) and ``v < float32(maxRange)``.
    Objects below minRange still occlude (the ray engine stops at them).

Point cloud (``point_cloud``)
    Cylindrical: each point is ``r·d`` with the beam direction above, i.e. exactly where the beam hit.
    This is Webots' formula ``(r cos θ cos φ, r sin θ cos φ, r sin φ)``, ``φ = e_i + τ``, whenever
    τ = 0 or the lidar rotates; for a tilted fixed lidar Webots puts off-axis points at
    ``(θ_j, e_i + τ)`` although its camera looked along the pitched beam — we use the pitched beam.
    Planar: Webots' formula verbatim, equal-angle ``θ_j``/``φ = e_i + τ`` with the planar depth as r.
    ``r = inf`` gives ±inf/NaN components, as in Webots. Times: fixed lidar
    ``t_j = T_now - j·P/W`` (absolute column j, P the refresh period); rotating lidar: see
    :func:`rotating_sweep` (the time at which the head passed the column).

Rotating sweep (``rotating_sweep``)
    Each basic step the head yaw ψ turns by ``Δ = -2π·f·dt`` (clockwise). In column units the head
    sits at ``h(ψ) = ((π - ψ)·W/2π) mod W`` and advances by ``|Δ|·W/2π``; the step samples the
    columns ``j ≡ x (mod W)`` for the integers x in ``[h_before, h_after)`` (at most the last W of
    them when ``|Δ| >= 2π``). The returned head angle is wrapped to [-π, π) and the next step's
    ``h_before`` is computed from that very value, so consecutive steps partition the columns
    exactly: over a revolution every column is sampled once. A column's time is when the head
    passed it, interpolated linearly over the step: ``t_end - dt·(h_after - x)/(h_after - h_before)``
    (in ``[t_end - dt, t_end)``). The ranges themselves come from the end-of-step scene.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .lookup import RESOLUTION_OFF, quantize_lidar
from .noise import gaussian

__all__ = [
    "LidarParams",
    "POINT_DTYPE",
    "layer_elevations",
    "column_azimuths",
    "ray_directions",
    "value_factors",
    "ranges_from_hits",
    "point_cloud",
    "point_xyz",
    "point_records",
    "RotatingSweep",
    "rotating_sweep",
    "wrap_angle",
]

_TWO_PI = 2.0 * math.pi

_XYZ_BLOCK = 16384   # points per block of point_xyz (its float64 buffer: 384 KB)

POINT_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("layer_id", "<i4"), ("time", "<f4")])
"""One WbLidarPoint (20 bytes)."""


@dataclass(frozen=True, slots=True)
class LidarParams:
    """Lidar fields (Webots node defaults). Validated; sanitising is the world loader's job."""

    horizontal_resolution: int = 512
    number_of_layers: int = 4
    field_of_view: float = 1.5708
    vertical_field_of_view: float = 0.2
    tilt_angle: float = 0.0
    near: float = 0.01
    min_range: float = 0.01
    max_range: float = 1.0
    type: str = "fixed"
    projection: str = "cylindrical"
    noise: float = 0.0
    resolution: float = -1.0
    default_frequency: float = 10.0
    min_frequency: float = 1.0
    max_frequency: float = 25.0

    def __post_init__(self) -> None:
        problems = []
        if self.type not in ("fixed", "rotating"):
            problems.append(f"type must be 'fixed' or 'rotating', got {self.type!r}")
        if self.projection not in ("cylindrical", "planar"):
            problems.append(f"projection must be 'cylindrical' or 'planar', got {self.projection!r}")
        if int(self.horizontal_resolution) < 1 or int(self.number_of_layers) < 1:
            problems.append("horizontalResolution and numberOfLayers must be >= 1")
        if not self.field_of_view > 0.0:
            problems.append("fieldOfView must be > 0")
        if self.projection == "planar" and self.field_of_view > math.pi:
            problems.append("fieldOfView must be <= pi for a planar projection")
        if not 0.0 < self.vertical_field_of_view <= math.pi:
            problems.append("verticalFieldOfView must be in (0, pi]")
        if not (0.0 <= self.near and 0.0 <= self.min_range < self.max_range):
            problems.append("need 0 <= near, 0 <= minRange < maxRange")
        if not self.noise >= 0.0:
            problems.append("noise must be >= 0")
        if self.resolution != RESOLUTION_OFF and not self.resolution > 0.0:
            problems.append("resolution must be -1 (off) or > 0")
        if problems:
            raise ValueError("invalid lidar parameters: " + "; ".join(problems))

    @property
    def rotating(self) -> bool:
        return self.type == "rotating"

    @property
    def planar(self) -> bool:
        return self.projection == "planar"

    @property
    def noise_sigma(self) -> float:
        """Standard deviation of the range noise: ``noise · maxRange`` (reference manual)."""
        return self.noise * self.max_range

    @property
    def number_of_points(self) -> int:
        return int(self.horizontal_resolution) * int(self.number_of_layers)


# ---------------------------------------------------------------------------------------- beams
def layer_elevations(params: LidarParams, include_tilt: bool = True) -> np.ndarray:
    """Layer elevations (L,), top to bottom: ``φ_v/2 - i·φ_v/(L-1)`` (0 for one layer), plus the
    tilt when ``include_tilt`` — the beam elevation at the head's forward azimuth (every column of
    a rotating lidar, the central column of a fixed one)."""
    L = int(params.number_of_layers)
    if L == 1:
        e = np.zeros(1)
    else:
        v = float(params.vertical_field_of_view)
        e = v / 2.0 - np.arange(L) * (v / (L - 1))
    return e + float(params.tilt_angle) if include_tilt else e


def column_azimuths(params: LidarParams, columns=None) -> np.ndarray:
    """Column azimuths (W,) or for the given absolute ``columns``: fixed ``Φ/2 - (j+½)Φ/W``,
    rotating ``π - j·2π/W``. (For a fixed planar lidar these are the equal-angle azimuths the point
    cloud uses; its beams go through ``atan((1 - 2(j+½)/W)·tan(Φ/2))``.)"""
    W = int(params.horizontal_resolution)
    j = _columns(params, columns).astype(np.float64)
    if params.rotating:
        return math.pi - j * (_TWO_PI / W)
    fov = float(params.field_of_view)
    return fov / 2.0 - (j + 0.5) * (fov / W)


def _columns(params: LidarParams, columns) -> np.ndarray:
    W = int(params.horizontal_resolution)
    if columns is None:
        return np.arange(W)
    j = np.asarray(columns, dtype=np.int64).reshape(-1)
    if np.any((j < 0) | (j >= W)):
        raise ValueError("column index out of range")
    return j


def _pitch(d: np.ndarray, tau: float) -> np.ndarray:
    """Rotate (..., 3) directions about y so that a positive angle raises +x toward +z."""
    if tau == 0.0:
        return d
    c, s = math.cos(tau), math.sin(tau)
    out = d.copy()
    out[..., 0] = c * d[..., 0] - s * d[..., 2]
    out[..., 2] = s * d[..., 0] + c * d[..., 2]
    return out


def _spherical(elev: np.ndarray, azim: np.ndarray) -> np.ndarray:
    """(L, C, 3) unit vectors at elevations (L,) and azimuths (C,)."""
    ce, se = np.cos(elev)[:, None], np.sin(elev)[:, None]
    ct, st = np.cos(azim)[None, :], np.sin(azim)[None, :]
    return np.stack(np.broadcast_arrays(ce * ct, ce * st, se), axis=-1)


def ray_directions(params: LidarParams, columns=None) -> np.ndarray:
    """Unit beam directions (L, C, 3) in the lidar frame, layers top → bottom, columns as given
    (default all, left → right). See the module docstring for tilt and the planar rows."""
    j = _columns(params, columns)
    tau = float(params.tilt_angle)
    elev = layer_elevations(params, include_tilt=False)
    if params.rotating:
        return _spherical(elev + tau, column_azimuths(params, j))
    if params.planar:
        W = int(params.horizontal_resolution)
        a = (1.0 - 2.0 * (j + 0.5) / W) * math.tan(float(params.field_of_view) / 2.0)
        b = np.tan(elev)
        d = np.stack(np.broadcast_arrays(np.ones((len(b), len(a))), a[None, :], b[:, None]), axis=-1)
        d = d / np.linalg.norm(d, axis=-1, keepdims=True)
        return _pitch(d, tau)
    return _pitch(_spherical(elev, column_azimuths(params, j)), tau)


def value_factors(params: LidarParams, directions: np.ndarray) -> np.ndarray:
    """Factor (L, C) turning a beam's hit distance into the stored value: 1 (cylindrical) or the
    cosine between the beam and the camera's optical axis (planar depth). For a fixed planar lidar
    the axis is ``pitch(τ)·x``; for a rotating one it is the head's pitched forward axis, which gives
    ``cos e_i`` in every column. A ray must reach ``max_range / factor`` to see every valid depth."""
    d = np.asarray(directions, dtype=np.float64)
    if not params.planar:
        return np.ones(d.shape[:2])
    if params.rotating:
        return np.broadcast_to(np.cos(layer_elevations(params, include_tilt=False))[:, None], d.shape[:2]).copy()
    tau = float(params.tilt_angle)
    return d @ np.array([math.cos(tau), 0.0, math.sin(tau)])


# --------------------------------------------------------------------------------------- ranges
def ranges_from_hits(params: LidarParams, distances: np.ndarray, directions: np.ndarray,
                     rng: np.random.Generator | None) -> np.ndarray:
    """Range image (L, C) float32 from the ray engine's hit distances (L, C) (``+inf`` = no hit)
    along ``directions`` (L, C, 3) from :func:`ray_directions` (any column subset). Validity,
    noise (σ = noise·maxRange; ``rng=None`` skips it), resolution and the final bounds check as in
    the module docstring."""
    d = np.asarray(distances, dtype=np.float64)
    if params.planar:
        with np.errstate(invalid="ignore"):
            v = d * value_factors(params, directions)
    else:
        v = d
    lo, hi = float(params.min_range), float(params.max_range)
    if not (params.noise > 0.0 and rng is not None) and params.resolution == RESOLUTION_OFF:
        # nothing moves a value: round to float32 first, then blank the invalid ones. The same
        # result as the general path below: ``v >= lo`` fails for NaN, and float32 rounding is
        # monotone, so ``float32(v) >= float32(hi)`` holds for every v >= hi (and for inf)
        with np.errstate(invalid="ignore", over="ignore"):   # beyond float32: inf, then blanked
            out = v.astype(np.float32)
            bad = np.greater_equal(v, lo)
            np.logical_not(bad, out=bad)
            bad |= out >= np.float32(hi)
        np.copyto(out, np.float32(np.inf), where=bad)
        return out
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(v) & (v >= lo) & (v < hi)
    v = np.where(valid, v, np.inf)
    if params.noise > 0.0 and rng is not None:
        count = int(np.count_nonzero(valid))
        if count:
            v[valid] += params.noise_sigma * gaussian(rng, count)
    v = quantize_lidar(v, params.resolution)
    with np.errstate(invalid="ignore"):
        out = np.where((v >= lo) & (v < hi), v, np.inf).astype(np.float32)
    out[out >= np.float32(hi)] = np.inf     # a value just below maxRange may round up to it
    return out


# ---------------------------------------------------------------------------------- point cloud
def point_cloud_directions(params: LidarParams, columns=None) -> np.ndarray:
    """Unit directions (L, C, 3) the point cloud places each range along: the beams themselves,
    except for a planar lidar, whose points lie on equal-angle rays (module docstring)."""
    j = _columns(params, columns)
    if params.planar:
        return _spherical(layer_elevations(params), column_azimuths(params, j))
    return ray_directions(params, j)


def point_cloud(params: LidarParams, range_image: np.ndarray, time_s: float, period_s: float,
                columns=None, times=None, directions: np.ndarray | None = None) -> np.ndarray:
    """Points (L·C,) of dtype :data:`POINT_DTYPE`, layer-major (index ``i·C + c``).

    ``range_image`` is (L, C) for the given ``columns`` (default all W). Times: ``times`` (C,) if
    given (rotating lidar: from :func:`rotating_sweep`), else ``time_s - j·period_s/W`` with j the
    absolute column index. ``directions``: :func:`point_cloud_directions` of these columns when
    the caller keeps them (they never change), else computed here."""
    j = _columns(params, columns)
    L, C = int(params.number_of_layers), len(j)
    dirs = point_cloud_directions(params, j) if directions is None else directions
    if times is None:
        t = float(time_s) - j * (float(period_s) / int(params.horizontal_resolution))
    else:
        t = np.asarray(times, dtype=np.float64).reshape(C)
    cols = tuple(dirs[:, :, k] for k in range(3))
    return point_records(point_xyz(range_image, cols), L, C, t)


def point_xyz(range_image: np.ndarray, direction_columns) -> np.ndarray:
    """Point coordinates (N, 3) float32 of ``range_image`` (N values in any shape, float32 or
    float64) along unit directions given as three columns (x, y, z) of N values each: the float64
    products ``r·d`` rounded to float32 (``inf·0`` gives NaN, as in Webots). Works in blocks: the
    products of a block land in a small float64 (B, 3) buffer that is rounded into the output in
    one contiguous copy (a third faster than three strided rounding writes)."""
    r = np.asarray(range_image).reshape(-1)
    cols = [np.asarray(c).reshape(-1) for c in direction_columns]
    n = len(r)
    xyz = np.empty((n, 3), dtype=np.float32)
    block = max(1, min(n, _XYZ_BLOCK))
    buf = np.empty((block, 3))
    rb = np.empty(block)   # the block's ranges as float64 (exact), converted once for three products
    with np.errstate(invalid="ignore"):
        for a in range(0, n, block):
            b = min(n, a + block)
            part, rr = buf[:b - a], rb[:b - a]
            rr[:] = r[a:b]
            for k in range(3):
                np.multiply(cols[k][a:b], rr, out=part[:, k])
            xyz[a:b] = part
    return xyz


def point_records(xyz: np.ndarray, L: int, C: int, times: np.ndarray) -> np.ndarray:
    """WbLidarPoint records (L·C,) from layer-major coordinates (L·C, 3) float32 and the float64
    times (C,) of the columns (rounded to float32); ``layer_id`` = the layer of each point."""
    pts = np.empty((L, C), dtype=POINT_DTYPE)
    words = pts.view(np.float32).reshape(L, C, 5)    # the 5 fields of each 20-byte point
    words[:, :, 0:3] = xyz.reshape(L, C, 3)
    words[:, :, 4] = np.asarray(times, dtype=np.float64)[None, :]
    pts.view(np.int32).reshape(L, C, 5)[:, :, 3] = np.arange(L, dtype=np.int32)[:, None]
    return pts.reshape(L * C)


# -------------------------------------------------------------------------------- rotating head
def wrap_angle(a: float) -> float:
    """Angle wrapped to [-π, π) (π itself can come out of float rounding)."""
    return float((a + math.pi) % _TWO_PI - math.pi)


def _head_column(psi: float, W: int) -> float:
    h = ((math.pi - psi) * W / _TWO_PI) % W
    return 0.0 if h >= W else h


@dataclass(frozen=True, slots=True)
class RotatingSweep:
    columns: np.ndarray       # (C,) int64 absolute column indices, in sweep order
    times: np.ndarray         # (C,) float64 seconds, when the head passed each column
    head_angle_after: float   # wrapped with wrap_angle


def rotating_sweep(params: LidarParams, head_angle_before: float, frequency: float, dt_ms: int,
                   time_end_s: float = 0.0) -> RotatingSweep:
    """The columns a rotating head samples during one basic step of ``dt_ms`` ending at
    ``time_end_s``, their times, and the head angle after the step (module docstring)."""
    f = float(frequency)
    if f < 0.0:
        raise ValueError("frequency must be >= 0")
    W = int(params.horizontal_resolution)
    dt_s = int(dt_ms) / 1000.0
    delta = -_TWO_PI * f * dt_s
    if delta == 0.0:
        return RotatingSweep(np.zeros(0, dtype=np.int64), np.zeros(0), float(head_angle_before))
    after = wrap_angle(float(head_angle_before) + delta)
    h_b = _head_column(float(head_angle_before), W)
    advance = -delta * W / _TWO_PI
    h_a_wrapped = _head_column(after, W)
    h_a = h_a_wrapped + W * round((h_b + advance - h_a_wrapped) / W)
    first = math.ceil(max(h_b, h_a - W))
    x = np.arange(first, math.ceil(h_a), dtype=np.int64)
    times = float(time_end_s) - dt_s * (h_a - x) / (h_a - h_b)
    return RotatingSweep(x % W, times, after)
