"""Ray-query engine: Embree (float32 BVH traversal) + float64 refinement.

The only module importing embreex.

Architecture
------------
* Static tier: the shapes of all static bodies (never moved) that a ray kind sees, in ONE Embree
  scene.  Its vertices are stored relative to the bounding-box centre (the *anchor*, subtracted
  in float64 before the float32 conversion; skipped when the geometry already surrounds the
  origin) so worlds far from the origin keep float32 precision.
* Mover tiers: a mover (``movable=True`` body, or a static body once moved) is cast against a
  scene of its shapes in its BODY frame, built once and shared by every mover with the same shapes
  (same primitives and local poses: a hundred identical robots cost one build).  Moving a body
  never rebuilds anything.  Per cast, a broad phase finds the (ray, mover) pairs whose segment
  passes within the mover's bounding sphere (excluded owners dropped): one dense vectorised test
  for few movers or small batches, else a uniform grid keyed by the segment midpoints.  The pairs
  of each shared scene are moved into their body frames in float64; when there are many, those
  whose segment misses a tight bound of the scene (the shell's own cylinder for a round body, else
  its box) are dropped; the rest go to ONE Embree call per shared scene.
* Planes are analytic (float64), never triangles, all planes of a ray kind in one (rays x planes)
  computation.
* Curved primitives are tessellated CIRCUMSCRIBED (true surface inside the shell) and inflated
  by 4 float32 ulps, so every true hit lies inside the shell.  Rays whose start point is inside
  a curved shell are intersected analytically with that shape up front (a pre-pass screened by a
  sphere test of the start points, or for large batches by their bounding box): their true hit
  may come before any shell crossing the cast would reach (t_far or a nearer hit elsewhere ends
  the cast first).
* Scenes are built lazily on the first cast after a change, one per tier and ray kind; every
  commit counts in ``counters["bvh_builds"]``, every ``scene.run`` in ``counters["embree_calls"]``.
* FAST uses plain scenes, EXACT robust ones (``EmbreeScene(robust=True)``), each built when the
  mode first needs it.  Measured in a 600-triangle room with 131k lidar rays, all hitting: robust
  traversal costs ~40% more.  On rays aimed exactly at the vertices and edge midpoints of closed
  meshes, the plain scenes leak ~4% of rays; robust ones plus the repair below leak none.
* Small batches (a distance sensor's few rays) are dominated by the fixed cost of each numpy
  call (~1-3 us), so the per-cast path avoids work that does not apply: per-ray parameters that
  are uniform collapse to scalars, a tier that no ray hits returns at once, judging runs on the
  rays that hit, the pose-derived data of the movers is cached until a pose changes, one errstate
  context covers the cast, and the few-element steps (broad phase, pre-pass screening, analytic
  intersection of a few pairs) run in plain Python floats with the same formulas.
* (n,3) @ (3,3) products go through ``_mat`` in row blocks: OpenBLAS multi-threads larger ones,
  ~100x slower on a busy 2-core machine.

Precision
---------
* FAST: one Embree call per tier; distance = float32 tfar + float64 offsets, normal = the float64
  normal of the hit triangle, oriented with the sign of Embree's float32 Ng·d (checked in
  float64 for grazing hits).  Curved shapes are seen as their shells, except for rays starting
  inside a shell or leaving one, where the true surface decides (a sensor flush with a round
  body must not see the shell around it).
* EXACT: every hit is re-intersected in float64: boxes/meshes on the plane of the hit triangle,
  with a float64 Moller-Trumbore test on the triangle and its vertex neighbours when Embree's
  barycentrics are within 1e-4 of an edge; spheres/cylinders/capsules on the true surface.  Rays
  whose refinement misses are continued past the hit (bounded loop).  Each Embree cast is paired
  with a copy offset 4 float32 ulps perpendicular to the ray.  When the copy hits a nearer
  triangle, and the float64 ray hits that triangle or one of its neighbours (barycentric
  tolerance 1e-9), the nearer hit is taken.  This repairs leaks through shared edges and
  vertices (``counters["leak_repairs"]``).

Epsilons (per tier; res = float32 spacing at the tier's radius in the anchored frame)
* ``eps`` = max(1e-6 m, 8 res): self-hit distance and continuation step.  EXACT casts start
  ``eps`` along the ray.  FAST casts start at t_near; a hit closer than ``eps`` whose plane passes
  within 2 eps of the origin is a self-hit and is redone from ``eps``.  So a sensor flush with a
  surface never reports that surface at t ~ 0.  A room-sized world gives eps = 1e-6 m.
* Refined (EXACT) and analytic hits must also satisfy t >= t_near and t >= 1e-9 m + 1e-14 max|O|.

Known limits (measure-zero in practice)
* Two surfaces closer together along a ray than float32 resolution (~res) may come out in either order.
* A surface within ``eps`` beyond a rejected or continued hit can be skipped.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum, IntEnum

import numpy as np
from embreex import rtcore as _rtc
from embreex import rtcore_scene as _rts
from embreex.mesh_construction import TriangleMesh as _TriangleMesh

from sensorium.server.world.geometry import (
    Capsule,
    Cylinder,
    Mesh,
    Plane,
    Pose,
    Primitive,
    Sphere,
    tessellate,
)

__all__ = ["RayKind", "Precision", "ShapeEntry", "RayHits", "RayEngine"]

_F32 = np.float32
_INF = np.inf
_MAX_LOOPS = 32          # continuation iterations per tier and cast
_BARY_TOL = 1e-9         # barycentric tolerance of float64 triangle tests (relative)
_LEAK_OFFSET_ULPS = 4.0  # perpendicular offset of the repair copy, in float32 ulps of the tier
_SPHERE, _CYLINDER, _CAPSULE = 1, 2, 3
# two generic (non axis-aligned) directions used to build a perpendicular for the repair copy
_AUX1 = np.array([0.5773, 0.2113, 0.7887]) / np.linalg.norm([0.5773, 0.2113, 0.7887])
_AUX2 = np.array([-0.3, 0.9, 0.1]) / np.linalg.norm([-0.3, 0.9, 0.1])
# Size thresholds.  A numpy call costs ~1-3 us whatever its size up to a few thousand elements,
# so small batches (a distance sensor's 3 rays) take plain-float shortcuts and large ones stay
# vectorised; every shortcut computes the same answer (tests/test_raycast_paths.py).
_SMALL = 64              # per-ray arrays up to this size: Python list tricks (uniformity, max |x|)
_TINY = 12               # (ray, mover) / (ray, curved shape) tables up to this size: Python floats
_SCALAR = 8              # (ray, curved shape) pairs intersected analytically in Python floats
_FEW_MOVERS = 4          # up to this many movers, or ...
_DENSE_PAIRS = 16384     # ... (rays x movers) up to this size: one dense broad-phase test, else a grid
_PRUNE = 64              # from this many (ray, mover) pairs of one tier, a bound test prunes them
_MATMUL_ROWS = 32768     # row block of (n,3) @ (3,3) products (see _mat)


class RayKind(IntEnum):
    BOUNDING = 0  # boundingObject rays: generic/sonar/laser distance sensors, light occlusion
    VISUAL = 1    # visual rays: infra-red distance sensors, lidar


class Precision(str, Enum):
    FAST = "fast"
    EXACT = "exact"


@dataclass(frozen=True, slots=True)
class ShapeEntry:
    primitive: Primitive
    local_pose: Pose          # shape pose in its body's frame
    bounding: bool            # seen by BOUNDING rays
    visual: bool              # seen by VISUAL rays
    transparent: bool = False  # invisible to VISUAL rays and to casts with skip_transparent


@dataclass(slots=True)
class RayHits:
    distance: np.ndarray  # (n,) float64, +inf where no hit
    normal: np.ndarray    # (n,3) float64 unit, dot(normal, dir) <= 0; zeros where no hit
    shape: np.ndarray     # (n,) int64 global shape index, -1 where no hit


# --------------------------------------------------------------------------------------------
# float64 helpers


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise dot product of (n,3) arrays (column sums beat einsum here)."""
    p = a * b
    return p[:, 0] + p[:, 1] + p[:, 2]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _take(x, idx):
    """Index a per-ray parameter that may be a scalar."""
    return x[idx] if isinstance(x, np.ndarray) else x


def _rows(x: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """x[idx] for a sorted subset idx of range(len(x)): the array itself when idx is everything
    (np.take is also markedly faster than fancy indexing for (n,3) arrays)."""
    return x if len(idx) == len(x) else np.take(x, idx, axis=0)


def _minus(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """x - v for (n,3) x and (3,) v, column by column for large n (numpy broadcasts a length-3
    inner axis slowly; for a few rows one call is cheaper)."""
    if len(x) <= _SMALL:
        return x - v
    out = np.empty(x.shape)
    for k in range(3):
        np.subtract(x[:, k], v[k], out=out[:, k])
    return out


def _mat(x: np.ndarray, M: np.ndarray) -> np.ndarray:
    """x @ M for (n, k) x and a small (k, j) M, in blocks of rows: OpenBLAS multi-threads larger
    products, which made a (131072, 3) @ (3, 3) product ~100x slower on a busy 2-core machine."""
    n = len(x)
    if n <= _MATMUL_ROWS:
        return x @ M
    out = np.empty((n,) + M.shape[1:])
    for a in range(0, n, _MATMUL_ROWS):
        np.matmul(x[a:a + _MATMUL_ROWS], M, out=out[a:a + _MATMUL_ROWS])
    return out


def _ulp32(x: float) -> float:
    return float(np.spacing(_F32(max(abs(x), 1e-30))))


def _moller_trumbore(o, d, v0, e1, e2, tol=_BARY_TOL):
    """Float64 ray/triangle test: (inside within barycentric tol, t)."""
    p = _cross(d, e2)
    inv = 1.0 / _dot(e1, p)
    s = o - v0
    u = _dot(s, p) * inv
    q = _cross(s, e1)
    v = _dot(d, q) * inv
    t = _dot(e2, q) * inv
    ok = np.isfinite(t) & (u >= -tol) & (v >= -tol) & (u + v <= 1.0 + tol)
    return ok, t


# The analytic intersectors below write candidate distances into the columns of one (m, k) table
# and pick the nearest in [lo, hi]: a handful of numpy calls per shape kind, whatever m is (a
# distance sensor casts 3 rays; per-call overhead dominates).  Floating-point warnings are
# silenced once per cast (see RayEngine.cast).


def _roots_into(ts, k, a, b, c, disc):
    """Both roots of a t^2 + 2 b t + c = 0 into ts[:, k] and ts[:, k+1], given disc = b^2 - a c
    (computed stably by the caller); +inf where there is no real root."""
    s = np.sqrt(np.maximum(disc, 0.0))
    q = -(b + np.copysign(s, b))
    t1, t2 = ts[:, k], ts[:, k + 1]
    np.divide(q, a, out=t1)
    np.divide(c, q, out=t2)
    np.copyto(t2, t1, where=q == 0.0)
    bad = (disc < 0.0) | ~np.isfinite(t1)
    np.copyto(ts[:, k:k + 2], _INF, where=bad[:, None])


def _sphere_roots_into(ts, k, p, d, r):
    a = _dot(d, d)
    b = _dot(p, d)
    c = _dot(p, p) - r * r
    x = _cross(p, d)
    _roots_into(ts, k, a, b, c, a * r * r - _dot(x, x))  # |p x d|^2 form: no cancellation far away


def _analytic_local(code, p, d, r, h, lo, hi):
    """Nearest true-surface hit with lo <= t <= hi, shape-local frame.  ``r`` radius, ``h`` half
    height (cylinder) or half length of the straight part (capsule), scalars or per-ray arrays;
    ``lo``, ``hi`` per-ray arrays.  Returns (t, unit normal), +inf / zeros where no hit."""
    m = len(p)
    col = (lambda x: x[:, None]) if isinstance(h, np.ndarray) else (lambda x: x)  # noqa: E731
    tol = 1e-12 * (r + h)
    pz, dz = p[:, 2:3], d[:, 2:3]
    if code == _SPHERE:
        ts = np.empty((m, 2))
        _sphere_roots_into(ts, 0, p, d, r)
    else:
        # columns 0, 1: the side (infinite cylinder x^2 + y^2 = r^2) within the straight part
        ts = np.empty((m, 4 if code == _CYLINDER else 6))
        px, py, dx, dy = p[:, 0], p[:, 1], d[:, 0], d[:, 1]
        a = dx * dx + dy * dy
        x = px * dy - py * dx
        _roots_into(ts, 0, a, px * dx + py * dy, px * px + py * py - r * r, a * r * r - x * x)
        side = ts[:, 0:2]
        np.copyto(side, _INF, where=~(np.abs(pz + side * dz) <= col(h + tol)))
        if code == _CYLINDER:  # columns 2, 3: caps z = +h, z = -h, within the disc
            caps = ts[:, 2:4]
            np.divide(col(h) * np.array([1.0, -1.0]) - pz, dz, out=caps)
            cx, cy = p[:, 0:1] + caps * d[:, 0:1], p[:, 1:2] + caps * d[:, 1:2]
            np.copyto(caps, _INF, where=~(np.isfinite(caps) & (cx * cx + cy * cy <= col(r * r + tol * r))))
        else:  # columns 2, 3 / 4, 5: hemispheres centred at z = +h / -h, beyond their centre
            for k, sign in ((2, 1.0), (4, -1.0)):
                pc = p.copy()
                pc[:, 2] -= sign * h
                _sphere_roots_into(ts, k, pc, d, r)
                cap = ts[:, k:k + 2]
                np.copyto(cap, _INF, where=~(sign * (pz + cap * dz) >= col(h - tol)))
    np.copyto(ts, _INF, where=~((ts >= lo[:, None]) & (ts <= hi[:, None])))
    if m <= 256:
        k = ts.argmin(axis=1)   # first of equal candidates, in column order
        t = ts[np.arange(m), k]
    else:                       # the same by columns (argmin over a short axis is slow for many rows)
        t = ts[:, 0].copy()
        k = np.zeros(m, dtype=np.int64)
        for j in range(1, ts.shape[1]):
            better = ts[:, j] < t
            k[better] = j
            np.minimum(t, ts[:, j], out=t)
    hit = t < _INF
    t0 = t.copy()
    np.copyto(t0, 0.0, where=~hit)
    n = p + t0[:, None] * d            # hit point
    if code == _CYLINDER:              # side: radial; caps: +-z
        n[:, 0:2] *= (k < 2)[:, None]
        n[:, 2] = (k == 2).astype(np.float64) - (k == 3)
    elif code == _CAPSULE:             # side: radial; hemispheres: from their centre
        n[:, 2] -= np.where(k < 2, n[:, 2], np.where(k < 4, h, -h))
    n /= np.sqrt(_dot(n, n))[:, None]
    np.copyto(n, 0.0, where=~hit[:, None])
    return t, n


def _roots_one(a: float, b: float, c: float, disc: float) -> tuple[float, float]:
    """Scalar twin of ``_roots_into`` (same operations, so the same bits)."""
    if not disc >= 0.0 or a == 0.0:
        return _INF, _INF
    q = -(b + math.copysign(math.sqrt(disc), b))
    t1 = q / a
    if not math.isfinite(t1):
        return _INF, _INF
    return t1, (c / q if q != 0.0 else t1)


def _analytic_one(code: int, p, d, r: float, h: float, lo: float, hi: float):
    """Scalar twin of ``_analytic_local`` for ONE ray in Python floats: (t, normal tuple).  Same
    candidates in the same order, same tolerances and operation order (bit-identical results),
    for the few (ray, shape) pairs of a small batch, where numpy's per-call cost would dominate."""
    px, py, pz = p
    dx, dy, dz = d
    tol = 1e-12 * (r + h)
    cands = []
    if code == _SPHERE:
        cx, cy, cz = py * dz - pz * dy, pz * dx - px * dz, px * dy - py * dx
        a = dx * dx + dy * dy + dz * dz
        cands += _roots_one(a, px * dx + py * dy + pz * dz, px * px + py * py + pz * pz - r * r,
                            a * r * r - (cx * cx + cy * cy + cz * cz))
    else:
        a = dx * dx + dy * dy
        x = px * dy - py * dx
        for t in _roots_one(a, px * dx + py * dy, px * px + py * py - r * r, a * r * r - x * x):
            cands.append(t if abs(pz + t * dz) <= h + tol else _INF)
        if code == _CYLINDER:
            for zc in (h * 1.0, h * -1.0):
                t = (zc - pz) / dz if dz != 0.0 else _INF
                if math.isfinite(t):
                    cx, cy = px + t * dx, py + t * dy
                    if not cx * cx + cy * cy <= r * r + tol * r:
                        t = _INF
                cands.append(_INF if not math.isfinite(t) else t)
        else:
            for sign in (1.0, -1.0):
                qz = pz - sign * h
                cx, cy, cz = py * dz - qz * dy, qz * dx - px * dz, px * dy - py * dx
                a3 = dx * dx + dy * dy + dz * dz
                for t in _roots_one(a3, px * dx + py * dy + qz * dz, px * px + py * py + qz * qz - r * r,
                                    a3 * r * r - (cx * cx + cy * cy + cz * cz)):
                    cands.append(t if sign * (pz + t * dz) >= h - tol else _INF)
    best, k = _INF, -1
    for j, t in enumerate(cands):   # first of equal candidates, like argmin
        if lo <= t <= hi and t < best:
            best, k = t, j
    if k < 0:
        return _INF, (0.0, 0.0, 0.0)
    nx, ny, nz = px + best * dx, py + best * dy, pz + best * dz
    if code == _CYLINDER:
        if k >= 2:
            nx, ny, nz = 0.0, 0.0, (1.0 if k == 2 else -1.0)
        else:
            nz = 0.0
    elif code == _CAPSULE:
        nz -= nz if k < 2 else (h if k < 4 else -h)
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    return best, (nx / norm, ny / norm, nz / norm)


def _skew(a: np.ndarray) -> np.ndarray:
    """S with d @ S = d x a for row vectors d."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


_SKEW1, _SKEW2 = _skew(_AUX1), _skew(_AUX2)


def _perpendicular(d: np.ndarray) -> np.ndarray:
    """Unit vectors perpendicular to the rows of d (d x AUX1, or d x AUX2 where d ~ AUX1)."""
    c = _mat(d, _SKEW1)
    c2 = _dot(c, c)
    weak = (c2 < 0.1).nonzero()[0]
    if len(weak):
        c[weak] = _mat(d[weak], _SKEW2)
        c2[weak] = _dot(c[weak], c[weak])
    c /= np.sqrt(c2)[:, None]
    return c


def _full(x, m: int, dtype=np.float64) -> np.ndarray:
    """A per-ray parameter as an (m,) array; arrays pass through (not copied)."""
    return x if isinstance(x, np.ndarray) else np.full(m, x, dtype=dtype)


def _param(x, n: int, dtype, scalar):
    """Normalise a per-cast parameter: a Python scalar, or an (n,) array when it varies per ray.
    A uniform array collapses to its scalar: scalars unlock the cheap paths (no per-ray gathers,
    owner checks skipped for exclude_owner = -1, no t_far clamping for t_far = inf)."""
    if isinstance(x, (float, int)):
        return scalar(x)
    a = np.asarray(x, dtype=dtype)
    if a.ndim == 0:
        return scalar(a)
    a = a.reshape(n)
    if n == 0:
        return a
    if n <= _SMALL:  # list comparisons beat two numpy reductions on a few values; NaN never counts
        vals = a.tolist()
        if vals.count(vals[0]) == n:
            return scalar(vals[0])
    elif not np.count_nonzero(a != a[0]):
        return scalar(a[0])
    return a


def _strictly_increasing(rows: np.ndarray) -> bool:
    return len(rows) < 2 or not np.count_nonzero(rows[1:] <= rows[:-1])


def _best_per_row(rows: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Indices into (rows, t) of the smallest t of each distinct row (ties: the earliest)."""
    order = np.lexsort((t, rows))  # stable
    r = rows[order]
    first = np.empty(len(r), dtype=bool)
    first[0] = True
    np.not_equal(r[1:], r[:-1], out=first[1:])
    return order[first]


def _segment_near_sphere(rel_x, rel_y, rel_z, dx, dy, dz, t_lo, t_hi, r2):
    """Does the segment o + t d, t in [t_lo, t_hi] (unit d), pass within the sphere of squared
    radius r2 centred at o + rel?  Arguments broadcast.  The squared distance from the centre to
    the closest segment point is |rel|^2 - tc (2 b - tc) with b = rel.d and tc = b clamped to the
    segment; the slack covers its rounding (the test only has to be conservative)."""
    b = rel_x * dx + rel_y * dy + rel_z * dz
    e2 = rel_x * rel_x + rel_y * rel_y + rel_z * rel_z
    tc = np.minimum(np.maximum(b, t_lo), t_hi)
    return e2 - tc * (b + b - tc) <= r2 + 1e-12 * e2


def _sphere_pairs(C, r2, owner, O, D, t_near, lim, excl):
    """(ray, mover) index pairs whose segment [t_near, lim] passes within the mover's bounding
    sphere (centre C, squared radius r2) and whose owner is not excluded (``owner`` None: no
    check).  Small tables: one (rays, movers, 3) computation, pairs ordered by ray.  Large batches
    (a lidar): one mover at a time on contiguous columns, pairs ordered by mover (so the pairs of
    any one mover are always in ray order)."""
    n, M = len(O), len(C)
    if n * M <= _TINY:  # a few rays and movers: plain floats (same test)
        Cl, Ol, Dl, r2l, hil = C.tolist(), O.tolist(), D.tolist(), r2.tolist(), lim.tolist()
        lol = t_near.tolist() if isinstance(t_near, np.ndarray) else [t_near] * n
        exl = excl.tolist() if isinstance(excl, np.ndarray) else [excl] * n
        own = owner.tolist() if owner is not None else None
        pr, pm = [], []
        for i, ((ox, oy, oz), (dx, dy, dz), lo, hi, ex) in enumerate(zip(Ol, Dl, lol, hil, exl)):
            for j, (cx, cy, cz) in enumerate(Cl):
                if own is not None and own[j] == ex:
                    continue
                rx, ry, rz = cx - ox, cy - oy, cz - oz
                b = rx * dx + ry * dy + rz * dz
                e2 = rx * rx + ry * ry + rz * rz
                tc = min(max(b, lo), hi)
                if e2 - tc * (b + b - tc) <= r2l[j] + 1e-12 * e2:
                    pr.append(i)
                    pm.append(j)
        return np.array(pr, dtype=np.int64), np.array(pm, dtype=np.int64)
    if n * M <= _DENSE_PAIRS:
        tn = t_near[:, None] if isinstance(t_near, np.ndarray) else t_near
        if n * M <= 256:   # one (rays, movers, 3) table: fewest calls
            rel = C[None, :, :] - O[:, None, :]
            b = (rel * D[:, None, :]).sum(axis=2)
            e2 = (rel * rel).sum(axis=2)
            tc = np.minimum(np.maximum(b, tn), lim[:, None])
            sel = e2 - tc * (b + b - tc) <= r2 + 1e-12 * e2
        else:              # (rays, movers) tables per coordinate: no slow reduction over a length-3 axis
            sel = _segment_near_sphere(C[:, 0] - O[:, 0:1], C[:, 1] - O[:, 1:2], C[:, 2] - O[:, 2:3],
                                       D[:, 0:1], D[:, 1:2], D[:, 2:3], tn, lim[:, None], r2)
        if owner is not None:
            sel &= owner != (excl[:, None] if isinstance(excl, np.ndarray) else excl)
        return sel.nonzero()
    shared = not np.count_nonzero(O != O[0])   # one origin (a lidar): rel = C - o is per mover
    if not shared:
        ox, oy, oz, dx, dy, dz = (np.ascontiguousarray(a[:, k]) for a in (O, D) for k in range(3))
    prs, pms = [], []
    for j in range(M):
        if owner is not None and not isinstance(excl, np.ndarray) and owner[j] == excl:
            continue
        if shared:
            rel = C[j] - O[0]
            b = D @ rel                              # matrix-vector: fast at any size
            e2 = float(rel @ rel)
            tc = np.minimum(np.maximum(b, t_near), lim)
            sel = e2 - tc * (b + b - tc) <= r2[j] + 1e-12 * e2
        else:
            sel = _segment_near_sphere(C[j, 0] - ox, C[j, 1] - oy, C[j, 2] - oz, dx, dy, dz, t_near, lim, r2[j])
        if owner is not None and isinstance(excl, np.ndarray):
            sel &= excl != owner[j]
        r = sel.nonzero()[0]
        prs.append(r)
        pms.append(np.full(len(r), j, dtype=np.int64))
    if not prs:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(prs), np.concatenate(pms)


def _grid_pairs(C, radius, r2, owner, O, D, t_near, lim, excl):
    """Same contract as ``_sphere_pairs``, for many movers and many rays.  A segment no longer than
    ``L_cap`` looks up ONE cell of a uniform grid, the cell of its midpoint; each mover is
    registered in every cell overlapped by the box of its bounding sphere grown by L_cap / 2.  A
    segment passing within r of a mover has its midpoint within r + L / 2 of the centre, so the
    lookup finds every candidate; the exact sphere test then runs on the candidate pairs only.
    Longer segments (a lidar among short infra-red rays) take the dense test."""
    n, M = len(O), len(C)
    L = lim - t_near
    valid = L >= 0.0                         # a negative segment sees nothing
    fin = valid & (L < _INF)
    Lf = L[fin]
    if len(Lf) == 0:
        return _sphere_pairs(C, r2, owner, O, D, t_near, lim, excl)
    # cell size from the MEDIAN segment length and mover radius (robust to a few long rays and
    # big movers: a big mover registers in more cells, a long segment takes the dense test)
    r_med = float(np.partition(radius, M // 2)[M // 2])
    k = len(Lf) // 2
    L_cap = max(2.0 * r_med, float(np.partition(Lf, k)[k]))
    reach = (radius + 0.5 * L_cap)[:, None]
    g0 = (C - reach).min(0)
    span = float(((C + reach).max(0) - g0).max())
    cell = 2.0 * r_med + L_cap               # a typical grown sphere overlaps <= 2 cells per axis
    if 2.0 * cell >= span:                   # a grid of ~one cell would not prune anything
        return _sphere_pairs(C, r2, owner, O, D, t_near, lim, excl)
    cell = max(cell, span / 2.0 ** 20)       # <= 2^20 + 3 cells per axis: int64 keys G^3 < 2^61
    inv = 1.0 / cell
    G = int(span * inv) + 3                  # cells per axis, with an empty border ring (0, G-1)
    W = np.array([G * G, G, 1], dtype=np.int64)   # key of cell (x, y, z) = (x G + y) G + z
    # movers -> cells 1 .. G-2 (the slack covers the rounding of the cell arithmetic)
    slack = 1e-9 * (float(np.abs(C).max()) + span)
    m0 = np.floor((C - reach - (g0 + slack)) * inv).astype(np.int64) + 1
    cnt = np.floor((C + reach - (g0 - slack)) * inv).astype(np.int64) + 2 - m0
    per = cnt[:, 0] * cnt[:, 1] * cnt[:, 2]
    mov = np.repeat(np.arange(M), per)
    j = np.arange(len(mov)) - np.repeat(np.cumsum(per) - per, per)   # cell number within the mover's box
    cy, cz = cnt[mov, 1], cnt[mov, 2]
    jx = j // (cy * cz)
    j -= jx * cy * cz
    jy = j // cz
    base = m0 @ W
    mkeys = base[mov] + jx * (G * G) + jy * G + (j - jy * cz)
    order = np.argsort(mkeys, kind="stable")
    smov = mov[order]
    first = np.zeros(G ** 3 + 1, dtype=np.int64) if G ** 3 <= 8 * (len(mkeys) + n) else None
    # short segments -> the cell of their midpoint (clipped into the empty border ring)
    short_m = fin & (L <= L_cap)
    every = bool(short_m.all())
    short = None if every else short_m.nonzero()[0]
    Os, Ds, Ls = (O, D, L) if every else (np.take(O, short, axis=0), np.take(D, short, axis=0), L[short])
    mid = Os + ((t_near if short is None else _take(t_near, short)) + 0.5 * Ls)[:, None] * Ds
    q = np.floor((mid - g0) * inv) + 1.0
    np.clip(q, 0.0, G - 1.0, out=q)
    key = q.astype(np.int64) @ W
    if first is not None:                    # small grid: direct table, no binary search
        np.cumsum(np.bincount(mkeys, minlength=G ** 3), out=first[1:])
        start, stop = first[key], first[key + 1]
    else:
        skeys = mkeys[order]
        start, stop = np.searchsorted(skeys, key, "left"), np.searchsorted(skeys, key, "right")
    c2 = stop - start
    pr = np.repeat(np.arange(len(key)) if every else short, c2)
    pm = smov[np.repeat(start - (np.cumsum(c2) - c2), c2) + np.arange(len(pr))]
    # exact sphere test on the candidates
    rel = np.take(C, pm, axis=0) - np.take(O, pr, axis=0)
    Dp = np.take(D, pr, axis=0)
    b = np.einsum("ij,ij->i", rel, Dp)
    e2 = np.einsum("ij,ij->i", rel, rel)
    tc = np.minimum(np.maximum(b, _take(t_near, pr)), lim[pr])
    sel = e2 - tc * (b + b - tc) <= r2[pm] + 1e-12 * e2
    if owner is not None:
        sel &= owner[pm] != _take(excl, pr)
    pr, pm = pr[sel], pm[sel]
    if not every:
        longs = (valid & ~short_m).nonzero()[0]
        if len(longs):
            lp, lm = _sphere_pairs(C, r2, owner, np.take(O, longs, axis=0), np.take(D, longs, axis=0),
                                   _take(t_near, longs), lim[longs], _take(excl, longs))
            pr = np.concatenate([pr, longs[lp]])
            pm = np.concatenate([pm, lm])
            order = np.argsort(pr, kind="stable")   # back in ray order (callers rely on it per mover)
            pr, pm = pr[order], pm[order]
    return pr, pm


# --------------------------------------------------------------------------------------------
# Tier: one Embree scene and the float64 data to refine its hits


class _Tier:
    """Triangles of a set of shapes in one Embree scene.  Tier frame = parent frame (world for the
    static tier, body frame for a mover) translated by ``-anchor``."""

    def __init__(self, device, items: list[tuple[int, Primitive, Pose]], owner_of: np.ndarray):
        verts, faces, tri_shape, curved = [], [], [], []
        nv = 0
        for sid, prim, pose in items:
            v, f = tessellate(prim)
            if len(f) == 0:
                continue
            if isinstance(prim, Mesh):  # keep only referenced vertices (they set the tier bounds)
                used, f = np.unique(f, return_inverse=True)
                v, f = v[used], f.reshape(-1, 3)
            verts.append(pose.apply(v))
            faces.append(f + nv)
            tri_shape.append(np.full(len(f), sid, dtype=np.int64))
            if isinstance(prim, (Sphere, Cylinder, Capsule)):
                curved.append((sid, prim, pose, len(verts) - 1, v))
            nv += len(v)
        self.empty = nv == 0
        if self.empty:
            return
        lo = np.min([v.min(0) for v in verts], axis=0)
        hi = np.max([v.max(0) for v in verts], axis=0)
        centre, half = (lo + hi) / 2.0, float(np.linalg.norm(hi - lo)) / 2.0
        # anchor at the bounding-box centre, unless the geometry is already around the origin
        # (then float32 coordinates lose at most one bit and casts skip a float64 subtraction)
        self.anchored = bool(np.linalg.norm(centre) > half)
        self.anchor = centre if self.anchored else np.zeros(3)
        self.res = _ulp32(half + float(np.linalg.norm(self.anchor - centre)))
        self.eps = max(1e-6, 8.0 * self.res)
        # Inflate curved shells by a = 4 float32 ulps so rounding cannot cut into the true
        # surface.  Scaling the shape frame by (1 + a/r) radially and (1 + a/half-length) along z
        # maps the true shape onto a superset of the true shape grown by a (checked for sphere,
        # cylinder and capsule), so the scaled shell still circumscribes with a margin >= a.
        a = 4.0 * self.res
        c_code, c_r, c_h, c_rot, c_pos, c_shape, c_bound, c_rad, c_ax = [], [], [], [], [], [], [], [], []
        for sid, prim, pose, k, v_local in curved:
            if isinstance(prim, Sphere):
                code, r, h, axial = _SPHERE, prim.radius, 0.0, prim.radius
            elif isinstance(prim, Cylinder):
                code, r, h = _CYLINDER, prim.radius, prim.height / 2.0
                axial = h
            else:
                code, r, h = _CAPSULE, prim.radius, prim.height / 2.0
                axial = h + r
            shell = v_local * np.array([1.0 + a / r, 1.0 + a / r, 1.0 + a / axial])
            verts[k] = pose.apply(shell)
            c_rad.append(float(np.hypot(shell[:, 0], shell[:, 1]).max()))
            c_ax.append(float(np.abs(shell[:, 2]).max()))
            c_code.append(code)
            c_r.append(r)
            c_h.append(h)
            c_rot.append(pose.rotation)
            c_pos.append(pose.translation - self.anchor)
            c_shape.append(sid)
            c_bound.append(float(np.linalg.norm(verts[k] - pose.translation, axis=1).max()))
        V = np.vstack(verts) - self.anchor
        F = np.vstack(faces)
        self.V, self.F = V, F
        self.radius = float(np.linalg.norm(V, axis=1).max()) + 4.0 * self.res
        self.tri_shape = np.append(np.concatenate(tri_shape), -1)  # sentinel row for primID = -1
        self.v0 = V[F[:, 0]]
        self.e1 = V[F[:, 1]] - self.v0
        self.e2 = V[F[:, 2]] - self.v0
        nrm = np.cross(self.e1, self.e2)
        with np.errstate(invalid="ignore", divide="ignore"):
            nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        self.normal = np.vstack([np.nan_to_num(nrm), np.zeros((1, 3))])
        # [normal; -normal]: row prim + (M+1)*back is the normal oriented toward the ray origin
        self.normal2 = np.vstack([self.normal, -self.normal])
        self.n_rows = len(self.normal)
        self.ng_max = float(np.linalg.norm(np.cross(self.e1, self.e2), axis=1).max())
        # dual basis of (e1, e2) in each triangle's plane: barycentrics u = (P - v0).g1, v = (P - v0).g2
        g11, g12, g22 = _dot(self.e1, self.e1), _dot(self.e1, self.e2), _dot(self.e2, self.e2)
        with np.errstate(invalid="ignore", divide="ignore"):
            inv = 1.0 / (g11 * g22 - g12 * g12)
        inv = np.where(np.isfinite(inv), inv, 0.0)[:, None]
        self.g1 = np.vstack([(g22[:, None] * self.e1 - g12[:, None] * self.e2) * inv, np.zeros((1, 3))])
        self.g2 = np.vstack([(g11[:, None] * self.e2 - g12[:, None] * self.e1) * inv, np.zeros((1, 3))])
        tv = V[F]
        self.t_lo, self.t_hi = tv.min(1), tv.max(1)   # per-triangle boxes (float64)
        owners = owner_of[self.tri_shape[:-1]]
        self.owned = bool((owners >= 0).any())
        # -2 marks "no owner" so it never equals an exclude_owner value (>= -1)
        self.tri_owner = np.append(np.where(owners >= 0, owners, -2), -2)
        # curved shapes, indexed by "slot"
        self.has_curved = bool(curved)
        self.c_shape = np.array(c_shape, dtype=np.int64)
        slot_of_shape = np.full(int(self.tri_shape.max()) + 2, -1, dtype=np.int64)
        slot_of_shape[self.c_shape] = np.arange(len(c_shape))
        self.tri_slot = slot_of_shape[self.tri_shape]  # sentinel row maps to -1 as well
        self.tri_curved = self.tri_slot >= 0
        self.c_code = np.array(c_code, dtype=np.int64)
        self.c_r = np.array(c_r, dtype=np.float64)
        self.c_h = np.array(c_h, dtype=np.float64)
        self.c_rot = np.array(c_rot, dtype=np.float64).reshape(-1, 3, 3)
        self.c_pos = np.array(c_pos, dtype=np.float64).reshape(-1, 3)
        self.c_bound = np.array(c_bound, dtype=np.float64)
        self.c_rad = np.array(c_rad, dtype=np.float64)   # shell extent in the shape frame:
        self.c_ax = np.array(c_ax, dtype=np.float64)     # max radial distance and max |z|
        c_owner = owner_of[self.c_shape]
        self.c_owned = bool((c_owner >= 0).any())
        self.c_owner = np.where(c_owner >= 0, c_owner, -2)   # -2: no owner, never excluded
        self.c_bound2 = self.c_bound ** 2
        self.c_rad2 = self.c_rad ** 2
        # the same as Python lists, for the scalar path of small batches
        self.c_sphere = [(*c, b2) for c, b2 in zip(self.c_pos.tolist(), self.c_bound2.tolist())]
        self.c_py = [(code, r, h, *c, *rot, rad2, ax, sid) for code, r, h, c, rot, rad2, ax, sid in zip(
            self.c_code.tolist(), self.c_r.tolist(), self.c_h.tolist(), self.c_pos.tolist(),
            self.c_rot.reshape(-1, 9).tolist(), self.c_rad2.tolist(), self.c_ax.tolist(), self.c_shape.tolist())]
        self.c_isolated = self._isolation(verts, tri_shape, c_shape)
        # tight bound of the whole tier for pruning candidate rays (see ``may_hit``): the shell's own
        # cylinder for a tier of one cylinder or capsule (a round robot body), else the box of V
        slack = 16.0 * self.res
        if len(items) == 1 and len(c_shape) == 1 and c_code[0] != _SPHERE:
            self.bound = ("cylinder", self.c_rot[0], self.c_pos[0], self.c_rad[0] + slack, self.c_ax[0] + slack)
        else:
            self.bound = ("box", V.min(0) - slack, V.max(0) + slack)
        self._ring: tuple[np.ndarray, np.ndarray] | None = None
        # Embree keeps pointers into these buffers: hold references for the scenes' lifetime
        self._v32 = np.ascontiguousarray(V, dtype=_F32)
        self._f32 = np.ascontiguousarray(F, dtype=np.int32)
        self._device = device
        self._scenes: dict[bool, object] = {}

    def may_hit(self, O, D, lo, hi) -> np.ndarray:
        """Mask of the rays (parent frame) whose segment [lo, hi] may meet ``bound`` (conservative:
        every triangle of the tier, and every start point inside a shell, lies inside the bound)."""
        Ot = _minus(O, self.anchor) if self.anchored else O
        hi = np.minimum(hi, 1e300)          # t * d stays finite (and 0 for d = 0)
        if self.bound[0] == "cylinder":
            # two cheap necessary conditions, tested separately: the segment comes within the
            # radius of the axis, and it overlaps the slab |z| <= half-height
            _, R, c, rad, ax = self.bound
            p = _mat(_minus(Ot, c), R)
            d = _mat(D, R)
            px, py, pz, dx, dy, dz = p[:, 0], p[:, 1], p[:, 2], d[:, 0], d[:, 1], d[:, 2]
            # closest approach to the axis (a ray along the axis: any t, 1e-300 avoids 0/0)
            tc = np.minimum(np.maximum(-(px * dx + py * dy) / (dx * dx + dy * dy + 1e-300), lo), hi)
            qx, qy = px + tc * dx, py + tc * dy
            z0, z1 = pz + lo * dz, pz + hi * dz
            return (qx * qx + qy * qy <= rad * rad) & (np.maximum(z0, z1) >= -ax) & (np.minimum(z0, z1) <= ax)
        _, blo, bhi = self.bound
        Dn = np.where(D == 0.0, 1e-300, D)   # parallel to a slab: +-huge (or 0 on its plane), no NaN
        t_a = (blo - Ot) / Dn
        t_b = (bhi - Ot) / Dn
        near, far = np.minimum(t_a, t_b), np.maximum(t_a, t_b)   # per axis; then across axes by column
        enter = np.maximum(np.maximum(np.maximum(near[:, 0], near[:, 1]), near[:, 2]), lo)
        leave = np.minimum(np.minimum(np.minimum(far[:, 0], far[:, 1]), far[:, 2]), hi)
        return enter <= leave

    def scene(self, robust: bool):
        """(Embree scene, built now?).  FAST uses a plain scene, EXACT a robust one (watertight
        traversal, ~40% slower in a room where every ray hits); each is built on first use."""
        sc = self._scenes.get(robust)
        if sc is not None:
            return sc, False
        sc = _rts.EmbreeScene(self._device, robust=robust)
        _TriangleMesh(sc, self._v32, self._f32)
        sc.run(np.zeros((0, 3), _F32), np.zeros((0, 3), _F32))  # commit now: this is the build
        self._scenes[robust] = sc
        return sc, True

    def _isolation(self, verts, tri_shape, c_shape) -> np.ndarray:
        """Per curved slot: True if no other shape of the tier overlaps its shell's bounding box.
        Then nothing can lie between a crossing of that shell and the true surface inside it."""
        if not c_shape:
            return np.zeros(0, dtype=bool)
        ids = np.array([int(t[0]) for t in tri_shape])
        lo = np.array([v.min(0) for v in verts])
        hi = np.array([v.max(0) for v in verts])
        out = np.empty(len(c_shape), dtype=bool)
        for i, sid in enumerate(c_shape):
            k = int(np.flatnonzero(ids == sid)[0])
            overlap = np.all((lo <= hi[k]) & (hi >= lo[k]), axis=1)
            overlap[k] = False
            out[i] = not overlap.any()
        return out

    @property
    def ring(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR (ptr, idx): for each triangle, the triangles sharing one of its vertices (itself
        included).  Built on first use (EXACT only)."""
        if self._ring is None:
            flat = self.F.ravel()
            tri_of = np.argsort(flat, kind="stable") // 3
            deg = np.bincount(flat, minlength=len(self.V))
            vptr = np.concatenate([[0], np.cumsum(deg)])
            lens = deg[flat]
            total = int(lens.sum())
            first = np.repeat(vptr[flat] - (np.cumsum(lens) - lens), lens)
            idx = tri_of[first + np.arange(total)]
            ptr = np.concatenate([[0], np.cumsum(lens.reshape(-1, 3).sum(1))])
            self._ring = (ptr, idx)
        return self._ring


# --------------------------------------------------------------------------------------------
# Engine bookkeeping


@dataclass(slots=True)
class _Body:
    shapes: list[int]          # global shape ids: first .. first + len - 1
    pose: Pose
    owner: int
    mover: bool
    index: int
    tiers: dict = field(default_factory=dict)  # variant -> shared body-frame _Tier (movers only)

    @property
    def first(self) -> int:
        return self.shapes[0] if self.shapes else 0


@dataclass(slots=True)
class _Movers:
    """The movers one ray variant sees (those with a non-empty tier), as arrays for the broad phase."""
    index: np.ndarray      # (M,) body index
    group: np.ndarray      # (M,) index into tiers
    tiers: list            # shared body-frame tiers
    anchor: np.ndarray     # (M,3) tier anchor in the body frame
    anchored: bool
    radius: np.ndarray     # (M,) bounding sphere of the tier around its anchor
    r2: np.ndarray
    owner: np.ndarray      # (M,) owner, -2 for none (never equal to an exclude_owner value)
    owned: bool            # some mover has an owner
    first: np.ndarray      # (M,) first global shape id of the body
    epoch: int = -1        # engine pose epoch of the cached world-frame data below
    R: np.ndarray | None = None   # (M,3,3) body rotations
    T: np.ndarray | None = None   # (M,3) body translations
    C: np.ndarray | None = None   # (M,3) bounding-sphere centres, world


class _Planes:
    """The analytic planes one ray variant sees.  World-frame data is recomputed only when a body
    carrying one of them has a new pose."""

    def __init__(self, items: list[tuple[int, _Body]], entries: list[ShapeEntry], owner_of: np.ndarray, visual: bool):
        self.bodies = [b for _, b in items]
        self.local = [entries[sid].local_pose for sid, _ in items]
        self.sid = np.array([sid for sid, _ in items], dtype=np.int64)
        owner = owner_of[self.sid]
        self.owned = bool((owner >= 0).any())
        self.owner = np.where(owner >= 0, owner, -2)   # -2: no owner, never equal to exclude_owner
        self.visual = visual  # VISUAL rays: one-sided (front = +z side), finite when sized
        sizes = [entries[sid].primitive.size for sid, _ in items]
        self.sized = visual and any(s is not None for s in sizes)
        half = [(s[0] / 2.0, s[1] / 2.0) if s is not None else (_INF, _INF) for s in sizes]
        self.half = np.array(half).reshape(-1, 2)
        self._poses: list | None = None
        self._epoch = -1

    def refresh(self, epoch: int) -> None:
        """``epoch`` counts the engine's pose changes: unchanged, nothing to check."""
        if epoch == self._epoch:
            return
        self._epoch = epoch
        poses = [b.pose for b in self.bodies]
        if self._poses is not None and all(p is q for p, q in zip(poses, self._poses)):
            return
        world = [p.compose(loc) for p, loc in zip(poses, self.local)]
        self.nz = np.array([w.rotation[:, 2] for w in world])
        self.ax = np.array([w.rotation[:, 0] for w in world])
        self.ay = np.array([w.rotation[:, 1] for w in world])
        self.pt = np.array([w.translation for w in world])
        self.nz_t = np.ascontiguousarray(self.nz.T)
        self._poses = poses


# variants: which shapes a scene holds
_V_VISUAL, _V_BOUNDING, _V_OPAQUE = "visual", "bounding", "bounding-opaque"


def _sees(e: ShapeEntry, variant: str) -> bool:
    if variant == _V_VISUAL:
        return e.visual and not e.transparent
    if variant == _V_BOUNDING:
        return e.bounding
    return e.bounding and not e.transparent


class RayEngine:
    """Nearest-hit ray queries against bodies of shapes (see module docstring)."""

    def __init__(self, precision: Precision = Precision.EXACT) -> None:
        self._precision = Precision(precision)
        self._device = _rtc.EmbreeDevice()
        self._entries: list[ShapeEntry] = []
        self._shape_body: list[int] = []
        self._owner_of = np.zeros(0, dtype=np.int64)
        self._bodies: list[_Body] = []
        self._movers: list[_Body] = []
        self._rot = np.zeros((0, 3, 3))   # body poses as arrays (gathered per cast for the movers)
        self._pos = np.zeros((0, 3))
        self._static: dict[str, _Tier | None] = {}
        self._planes: dict[str, _Planes | None] = {}
        self._mover_tables: dict[str, _Movers | None] = {}
        self._shared: dict[tuple, _Tier | None] = {}   # body-frame tiers by (variant, shapes)
        self._epoch = 0                                 # bumped by every set_body_pose
        self.counters: dict[str, int] = {
            "bvh_builds": 0, "embree_calls": 0, "rays_cast": 0, "leak_repairs": 0,
            "continued_rays": 0, "unresolved_rays": 0,
        }

    # ---- configuration ----------------------------------------------------------------------

    @property
    def precision(self) -> Precision:
        return self._precision

    @precision.setter
    def precision(self, value: Precision | str) -> None:
        self._precision = Precision(value)

    def add_body(self, shapes: Sequence[ShapeEntry], pose: Pose, owner: int = -1, movable: bool = False) -> int:
        first = len(self._entries)
        body = len(self._bodies)
        for e in shapes:
            if not isinstance(e, ShapeEntry):
                raise TypeError(f"expected ShapeEntry, got {type(e).__name__}")
            self._entries.append(e)
            self._shape_body.append(body)
        self._owner_of = np.append(self._owner_of, np.full(len(shapes), int(owner), dtype=np.int64))
        self._bodies.append(_Body(list(range(first, len(self._entries))), pose, int(owner), bool(movable), body))
        self._rot = np.concatenate([self._rot, pose.rotation[None]])
        self._pos = np.concatenate([self._pos, pose.translation[None]])
        self._planes.clear()
        if movable:
            self._movers.append(self._bodies[-1])
            self._mover_tables.clear()
        else:
            self._static.clear()
        return body

    def set_body_pose(self, body: int, pose: Pose) -> None:
        b = self._bodies[body]
        b.pose = pose
        self._epoch += 1
        self._rot[body] = pose.rotation
        self._pos[body] = pose.translation
        if not b.mover:  # first move of a static body: it leaves the static tier for good
            b.mover = True
            self._movers.append(b)
            self._static.clear()
            self._mover_tables.clear()

    def shape_owner(self, shape: int) -> int:
        return int(self._owner_of[shape])

    def shape_body(self, shape: int) -> int:
        return self._shape_body[shape]

    # ---- lazy builds ------------------------------------------------------------------------

    def _variant(self, kind: RayKind, skip_transparent: bool) -> str:
        if kind != RayKind.BOUNDING and kind != RayKind.VISUAL:
            RayKind(kind)  # raises ValueError for anything else (the enum call costs ~1 us: only here)
        if kind == RayKind.VISUAL:
            return _V_VISUAL
        return _V_OPAQUE if skip_transparent else _V_BOUNDING

    def _build(self, items, owner_of: np.ndarray) -> _Tier | None:
        tier = _Tier(self._device, items, owner_of)
        if tier.empty:
            return None
        # commit the current mode's scene now, so builds happen on the first cast after a change
        # whether or not rays reach the tier (the other mode's scene is built if ever needed)
        self.counters["bvh_builds"] += tier.scene(self._precision == Precision.EXACT)[1]
        return tier

    def _items(self, body: _Body, variant: str, world: bool):
        out = []
        for sid in body.shapes:
            e = self._entries[sid]
            if isinstance(e.primitive, Plane) or not _sees(e, variant):
                continue
            if world:
                out.append((sid, e.primitive, body.pose.compose(e.local_pose)))
            else:  # body frame, shapes numbered within the body
                out.append((sid - body.first, e.primitive, e.local_pose))
        return out

    def _has_transparent(self, bodies) -> bool:
        return any(self._entries[s].transparent and self._entries[s].bounding
                   and not isinstance(self._entries[s].primitive, Plane) for b in bodies for s in b.shapes)

    def _static_tier(self, variant: str) -> _Tier | None:
        if variant not in self._static:
            statics = [b for b in self._bodies if not b.mover]
            if variant == _V_OPAQUE and not self._has_transparent(statics):
                self._static[variant] = self._static_tier(_V_BOUNDING)
            else:
                self._static[variant] = self._build([i for b in statics for i in self._items(b, variant, True)],
                                                    self._owner_of)
        return self._static[variant]

    def _mover_tier(self, body: _Body, variant: str) -> _Tier | None:
        """The body-frame tier of a mover, shared by all bodies with the same shapes (primitive and
        local pose) seen by the variant.  Shared tiers carry no owner: exclusion is decided per
        (ray, mover) pair in the broad phase."""
        if variant not in body.tiers:
            if variant == _V_OPAQUE and not self._has_transparent([body]):
                body.tiers[variant] = self._mover_tier(body, _V_BOUNDING)
            else:
                items = self._items(body, variant, False)
                key = (variant, tuple((i, prim, pose.rotation.tobytes(), pose.translation.tobytes())
                                      for i, prim, pose in items))
                if key not in self._shared:
                    self._shared[key] = self._build(items, np.full(len(body.shapes), -1, dtype=np.int64))
                body.tiers[variant] = self._shared[key]
        return body.tiers[variant]

    def _mover_table(self, variant: str) -> _Movers | None:
        if variant not in self._mover_tables:
            rows = [(b, t) for b in self._movers if (t := self._mover_tier(b, variant)) is not None]
            mt = None
            if rows:
                tiers: list[_Tier] = []      # distinct shared tiers; group = index of a mover's tier
                group, seen = [], {}
                for _, t in rows:
                    if id(t) not in seen:
                        seen[id(t)] = len(tiers)
                        tiers.append(t)
                    group.append(seen[id(t)])
                anchor = np.array([t.anchor for _, t in rows])
                radius = np.array([t.radius for _, t in rows])
                owner = np.array([b.owner for b, _ in rows], dtype=np.int64)
                mt = _Movers(np.array([b.index for b, _ in rows], dtype=np.int64), np.array(group, dtype=np.int64),
                             tiers, anchor, bool(np.any(anchor != 0.0)), radius, radius * radius,
                             np.where(owner >= 0, owner, -2),   # -2: no owner, never excluded
                             bool((owner >= 0).any()), np.array([b.first for b, _ in rows], dtype=np.int64))
            self._mover_tables[variant] = mt
        return self._mover_tables[variant]

    def _plane_set(self, variant: str) -> _Planes | None:
        if variant not in self._planes:
            items = [(sid, b) for b in self._bodies for sid in b.shapes
                     if isinstance(self._entries[sid].primitive, Plane) and _sees(self._entries[sid], variant)]
            self._planes[variant] = (_Planes(items, self._entries, self._owner_of, variant == _V_VISUAL)
                                     if items else None)
        return self._planes[variant]

    # ---- casting ----------------------------------------------------------------------------

    def cast(self, origins, directions, t_near=0.0, t_far=np.inf, kind=RayKind.BOUNDING,
             exclude_owner=-1, skip_transparent=False) -> RayHits:
        O = np.asarray(origins, dtype=np.float64)
        D = np.asarray(directions, dtype=np.float64)
        if O.ndim == 1:
            O, D = O.reshape(1, 3), D.reshape(1, 3)
        if O.shape != D.shape or O.ndim != 2 or O.shape[1] != 3:
            raise ValueError(f"origins/directions must both be (n,3), got {O.shape} and {D.shape}")
        n = len(O)
        t_near = _param(t_near, n, np.float64, float)
        t_far = _param(t_far, n, np.float64, float)
        excl = _param(exclude_owner, n, np.int64, int)
        self.counters["rays_cast"] += n
        variant = self._variant(kind, skip_transparent)
        # builds happen on the first cast after a change, even with no rays
        planes = self._plane_set(variant)
        static = self._static_tier(variant)
        movers = self._mover_table(variant) if self._movers else None
        if n == 0:
            return RayHits(np.zeros(0), np.zeros((0, 3)), np.zeros(0, dtype=np.int64))
        # largest |coordinate| of the origins (a Python max beats two numpy reductions on a few rays)
        big = max(map(abs, O.ravel().tolist())) if n <= _SMALL else max(float(O.max()), -float(O.min()))
        # one errstate for the whole cast: inf/NaN are handled explicitly (entering the context
        # costs as much as a few numpy calls, so the helpers do not open their own)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return self._cast(O, D, t_near, t_far, excl, planes, static, movers, big)

    def _cast(self, O, D, t_near, t_far, excl, planes, static, movers, big: float) -> RayHits:
        n = len(O)
        exact = self._precision is Precision.EXACT
        eps64 = 1e-9 + 1e-14 * big  # float64 self-hit epsilon: 1e-9 m + ~50 ulps of the largest coordinate
        hits = self._cast_planes(planes, O, D, t_near, t_far, excl, eps64) if planes is not None else None
        if static is not None:
            lim = t_far if hits is None else np.minimum(t_far, hits[0])
            res = self._trace(static, O, D, t_near, lim, excl, eps64, exact, None if static.anchored else big)
            if res is not None and hits is None:
                hits = res
            elif res is not None:
                t, s, nrm = res
                better = (t < hits[0]).nonzero()[0]
                hits[0][better], hits[1][better], hits[2][better] = t[better], s[better], nrm[better]
        if hits is None:
            hits = (np.full(n, _INF), np.full(n, -1, dtype=np.int64), np.zeros((n, 3)))
        if movers is not None:
            self._cast_movers(movers, O, D, t_near, t_far, excl, eps64, exact, *hits)
        return RayHits(hits[0], hits[2], hits[1])

    def _cast_planes(self, pl: _Planes, O, D, t_near, t_far, excl, eps64):
        """(dist, shape, normal) of the nearest plane hits, or None if no ray hits a plane."""
        pl.refresh(self._epoch)
        n, P = len(O), len(pl.sid)
        den = _mat(D, pl.nz_t)                               # (n, P)
        ok = den < 0.0 if pl.visual else den != 0.0
        if not np.count_nonzero(ok):  # e.g. horizontal rays over a floor
            return None
        lo = np.maximum(t_near, eps64)[:, None] if isinstance(t_near, np.ndarray) else max(t_near, eps64)
        hi = t_far[:, None] if isinstance(t_far, np.ndarray) else t_far
        # rel = P - O column by column, then rel . nz: exact far from the origin (no cancellation)
        r0 = pl.pt[:, 0] - O[:, 0:1]
        r1 = pl.pt[:, 1] - O[:, 1:2]
        r2 = pl.pt[:, 2] - O[:, 2:3]
        nz = pl.nz
        t = (r0 * nz[:, 0] + r1 * nz[:, 1] + r2 * nz[:, 2]) / den
        ok &= (t >= lo) & (t <= hi)
        if pl.sized and np.count_nonzero(ok):  # hit point in the plane frame within the size
            x0, x1, x2 = t * D[:, 0:1] - r0, t * D[:, 1:2] - r1, t * D[:, 2:3] - r2
            ax, ay = pl.ax, pl.ay
            ok &= (np.abs(x0 * ax[:, 0] + x1 * ax[:, 1] + x2 * ax[:, 2]) <= pl.half[:, 0]) & \
                  (np.abs(x0 * ay[:, 0] + x1 * ay[:, 1] + x2 * ay[:, 2]) <= pl.half[:, 1])
        if pl.owned and not (not isinstance(excl, np.ndarray) and excl < 0):
            ok &= pl.owner != (excl[:, None] if isinstance(excl, np.ndarray) else excl)
        if not np.count_nonzero(ok):
            return None
        np.copyto(t, _INF, where=~ok)
        if P == 1:
            dist = t.reshape(n)
            col = np.zeros(n, dtype=np.int64)
            d_hit = den.reshape(n)
        else:  # nearest plane; ties keep the first (argmin)
            col = np.argmin(t, axis=1)
            ar = np.arange(n)
            dist = t[ar, col]
            d_hit = den[ar, col]
        hit = (dist < _INF).nonzero()[0]
        shape = np.full(n, -1, dtype=np.int64)
        normal = np.zeros((n, 3))
        c = col[hit]
        shape[hit] = pl.sid[c]
        normal[hit] = nz[c] * (1.0 - 2.0 * (d_hit[hit] > 0.0))[:, None]   # toward the origin
        return dist, shape, normal

    def _cast_movers(self, mt: _Movers, O, D, t_near, t_far, excl, eps64, exact, dist, shape, normal) -> None:
        """Broad phase over all movers, then one trace per shared tier over its (ray, mover) pairs
        moved into their body frames; improves dist/shape/normal in place."""
        n = len(O)
        lim = np.minimum(t_far, dist)
        if mt.epoch != self._epoch:  # poses changed since the last cast
            mt.R = self._rot[mt.index]
            mt.T = self._pos[mt.index]
            mt.C = mt.T + np.einsum("mij,mj->mi", mt.R, mt.anchor) if mt.anchored else mt.T
            mt.epoch = self._epoch
        R, T, C = mt.R, mt.T, mt.C
        owner = mt.owner if mt.owned and not (not isinstance(excl, np.ndarray) and excl < 0) else None
        grid = len(C) > _FEW_MOVERS and n * len(C) > _DENSE_PAIRS
        if grid:
            pr, pm = _grid_pairs(C, mt.radius, mt.r2, owner, O, D, t_near, lim, excl)
        else:
            pr, pm = _sphere_pairs(C, mt.r2, owner, O, D, t_near, lim, excl)
        if len(pr) == 0:
            return
        if len(pr) <= _TINY:  # few pairs: is it one mover? (plain Python beats two numpy calls)
            pml = pm.tolist()
            single = pml.count(pml[0]) == len(pml)
        else:
            single = not np.count_nonzero(pm != pm[0])
        # work items (tier, rays, movers, all one mover?): one per mover when there are few (one
        # matrix each; a lidar on a robot pairs every ray with it), else one per shared tier
        if single:
            todo = [(mt.tiers[mt.group[pm[0]]], pr, pm, True)]
        else:
            present = np.bincount(pm, minlength=len(C)).nonzero()[0].tolist()
            if len(present) <= _FEW_MOVERS:
                todo = [(mt.tiers[mt.group[j]], pr[sel], pm[sel], True)
                        for j in present for sel in [(pm == j).nonzero()[0]]]
            elif len(mt.tiers) == 1:
                todo = [(mt.tiers[0], pr, pm, False)]
            else:
                gp = mt.group[pm]
                todo = [(tier, pr[sel], pm[sel], False)
                        for g, tier in enumerate(mt.tiers) if len(sel := (gp == g).nonzero()[0])]
        for tier, rr, mm, one in todo:
            # rays into the body frames (float64): one matrix when all pairs share a mover
            if one and len(rr) == n:   # one mover, every ray (its pairs are then 0..n-1 in order)
                Or, Dr = O, D
            else:
                Or, Dr = np.take(O, rr, axis=0), np.take(D, rr, axis=0)
            if one:
                Rb, Tb = R[mm[0]], T[mm[0]]
                Ob, Db = _mat(_minus(Or, Tb), Rb), _mat(Dr, Rb)
            else:
                Rg = np.take(R, mm, axis=0)
                Ob = np.einsum("nij,ni->nj", Rg, Or - np.take(T, mm, axis=0))
                Db = np.einsum("nij,ni->nj", Rg, Dr)
            lim_r = lim[rr]
            if len(rr) >= _PRUNE:  # many pairs (many movers): drop those missing the tier's tight bound
                keep = tier.may_hit(Ob, Db, _take(t_near, rr), lim_r).nonzero()[0]
                if len(keep) < len(rr):
                    if len(keep) == 0:
                        continue
                    rr, mm, Ob, Db, lim_r = rr[keep], mm[keep], Ob[keep], Db[keep], lim_r[keep]
            res = self._trace(tier, Ob, Db, _take(t_near, rr), lim_r, -1, eps64, exact)
            if res is None:
                continue
            t, s, nb = res
            win = (t < dist[rr]).nonzero()[0]   # dist may already hold another group's hits
            if len(win) == 0:
                continue
            rows = rr[win]
            if not _strictly_increasing(rows):  # a ray near several movers of this tier: nearest wins
                keep = _best_per_row(rows, t[win])
                win, rows = win[keep], rows[keep]
            nb = nb[win]
            mw = mm[win]
            dist[rows] = t[win]
            shape[rows] = mt.first[mw] + s[win]
            normal[rows] = _mat(nb, Rb.T) if one else np.einsum("nij,nj->ni", R[mw], nb)

    # ---- one tier -----------------------------------------------------------------------------

    def _run(self, tier: _Tier, o32, d32, far, robust: bool):
        scene, built = tier.scene(robust)
        self.counters["bvh_builds"] += built
        self.counters["embree_calls"] += 1
        return scene.run(o32, d32, far, output=1)

    def _trace(self, tier: _Tier, O, D, t_near, lim, excl, eps64: float, exact: bool, big: float | None = None):
        """Nearest accepted hit in one tier.  O, D in the tier's parent frame; returns (t, shape,
        normal oriented toward the origin) with normal in the parent frame's orientation, or None
        when no ray hits.  ``big``: max |coordinate| of O when already known (saves two reductions
        for an unanchored tier)."""
        if exact:
            res = self._trace_loop(tier, O, D, t_near, lim, excl, eps64, exact=True)
            return res if np.count_nonzero(res[0] < _INF) else None
        return self._trace_fast(tier, O, D, t_near, lim, excl, eps64, big)

    def _trace_fast(self, tier: _Tier, O, D, t_near, lim, excl, eps64: float, big: float | None = None):
        """FAST: one Embree call and vectorised gathers; the rare rays needing judgement (possible
        self-hits, shells left from inside, excluded owners) are redone by the general loop.
        Mostly-missing batches (short sensor rays) work on the hit rows only, mostly-hitting ones
        (a lidar in a room) on whole arrays without gathers."""
        m = len(O)
        Ot = _minus(O, tier.anchor) if tier.anchored else O
        pre = None
        lim_in = lim   # the redo below gets the caller's limit: it runs its own pre-pass, whose
        # float64 path (scalar or vectorised) may differ from this one's in the last bit
        if tier.has_curved:  # origins inside a curved shell: analytic first (see the pre-pass)
            lo = np.maximum(t_near, eps64) if isinstance(t_near, np.ndarray) else max(t_near, eps64)
            pre = self._contained_prepass(tier, Ot, D, lo, lim, excl)
            if pre is not None:  # the cast only needs to look before the analytic hits
                lim = np.array(lim, dtype=np.float64) if isinstance(lim, np.ndarray) else np.full(m, lim)
                lim[pre[0]] = np.minimum(lim[pre[0]], pre[1])
        o32 = Ot.astype(_F32)
        d32 = D.astype(_F32)
        start = t_near
        dead = None
        if big is None:
            big = max(map(abs, o32.ravel().tolist())) if m <= _SMALL else max(-float(o32.min()), float(o32.max()))
        if big * 1.7321 > tier.radius:
            far_rows = (_dot(o32, o32) > _F32(tier.radius * tier.radius)).nonzero()[0]
            if len(far_rows):  # origin outside the tier's sphere: start at its entry (precision)
                start = np.array(_full(start, m), dtype=np.float64)
                Of = Ot[far_rows]
                Df = D[far_rows]
                b = _dot(Of, Df)
                q2 = _dot(Of, Of) - b * b
                enter = -b - np.sqrt(np.maximum(tier.radius ** 2 - q2, 0.0))
                start[far_rows] = np.maximum(start[far_rows], enter)
                dead = far_rows[q2 > tier.radius ** 2]
                o32 += start[:, None] * d32
                o32[far_rows] = Of + start[far_rows][:, None] * Df
        if not isinstance(start, np.ndarray):
            if start > 0.0:
                o32 += _F32(start) * d32
        elif dead is None:
            o32 += start[:, None] * d32
        far = (lim - start) * (1.0 + 2.0 ** -20)  # float32 slack so a hit exactly at t_far counts
        if dead is not None and len(dead):
            far = np.array(_full(far, m))
            far[dead] = -1.0
        if isinstance(far, np.ndarray):
            far = far.astype(_F32)
        elif far == _INF:
            far = None
        else:
            far = float(far)
        res = self._run(tier, o32, d32, far, robust=False)
        prim = res["primID"]
        hit = prim >= 0
        n_hit = np.count_nonzero(hit)
        if n_hit == 0 and pre is None:
            return None   # no hit at all (the common case for short sensor rays)
        if 2 * n_hit >= m:  # mostly hits: whole arrays, misses masked (primID -1 picks the
            # sentinel rows: shape -1, zero normal)
            (t, normal), redo = self._judge_fast(tier, Ot, D, d32, res, prim, slice(None), start, lim, excl)
            shape = np.take(tier.tri_shape, prim)
            if n_hit < m:
                t[~hit] = _INF
        else:
            h = hit.nonzero()[0]
            t = np.full(m, _INF)
            shape = np.full(m, -1, dtype=np.int64)
            normal = np.zeros((m, 3))
            redo = None
            if len(h):
                (th, nrm), special = self._judge_fast(tier, Ot, D, d32, res, prim[h], h, start, lim, excl)
                t[h], shape[h], normal[h] = th, np.take(tier.tri_shape, prim[h]), nrm
                if special is not None:
                    redo = np.zeros(m, dtype=bool)
                    redo[h[special]] = True
        if redo is not None and pre is not None:  # rays the pre-pass settles need no redo
            redo[pre[0][pre[1] <= t[pre[0]]]] = False
        if redo is not None and np.count_nonzero(redo):
            rows = redo.nonzero()[0]
            t2, s2, n2 = self._trace_loop(tier, O[rows], D[rows], _take(t_near, rows), _take(lim_in, rows),
                                          _take(excl, rows), eps64, exact=False)
            t[rows], shape[rows], normal[rows] = t2, s2, n2
        if pre is not None:  # analytic hits of the pre-pass, unless a nearer hit was found
            rows, tp, sp, np_ = pre
            if len(rows) <= _SMALL:  # a few: plain Python (ten numpy calls otherwise)
                for k, (i, ti) in enumerate(zip(rows.tolist(), tp.tolist())):
                    if ti <= t[i]:
                        t[i], shape[i], normal[i] = ti, sp[k], np_[k]
            else:
                take = (tp <= t[rows]).nonzero()[0]
                r = rows[take]
                t[r], shape[r], normal[r] = tp[take], sp[take], np_[take]
        return t, shape, normal

    def _judge_fast(self, tier: _Tier, Ot, D, d32, res, ph, rows, start, lim, excl):
        """FAST hit data of the Embree results at ``rows`` (a slice of all rays, or an index array
        of hit rays; ``ph`` = their primIDs): ((t, normal toward the origin), special mask or None),
        special = rays the general loop must redo."""
        every = isinstance(rows, slice)
        tf = res["tfar"][rows]
        t = tf.astype(np.float64)
        t += start if not isinstance(start, np.ndarray) else start[rows]
        if isinstance(lim, np.ndarray):
            np.minimum(t, lim[rows], out=t)
        elif lim != _INF:
            np.minimum(t, lim, out=t)
        dh = d32[rows]
        ng = res["Ng"][rows]                 # Embree's Ng has our winding: sign = side hit
        if len(ng) > _SMALL:                 # one pass over the rows
            dots = np.einsum("ij,ij->i", ng, dh)
        else:
            dots = ng[:, 0] * dh[:, 0] + ng[:, 1] * dh[:, 1] + ng[:, 2] * dh[:, 2]
        back = dots > 0.0
        nrm = np.take(tier.normal2, ph + back * tier.n_rows, axis=0)   # misses: zero sentinel rows
        grazing = np.abs(dots) < 1e-5 * tier.ng_max
        if every:
            grazing &= ph >= 0
        grazing = grazing.nonzero()[0]
        if len(grazing):  # float32 sign unreliable: orient in float64
            g_nrm = tier.normal[ph[grazing]]
            flip = _dot(g_nrm, D[grazing if every else rows[grazing]]) > 0.0
            g_nrm[flip] *= -1.0
            nrm[grazing] = g_nrm
            back[grazing] = flip
        special = tf < tier.eps              # possible self-hit (origin on the surface)
        if every:
            special &= ph >= 0
        if np.count_nonzero(special):
            sp = special.nonzero()[0]
            tri = ph[sp]
            gap = np.abs(_dot(Ot[sp if every else rows[sp]] - tier.v0[tri], tier.normal[tri]))
            special[sp] = gap <= 2.0 * tier.eps
        if tier.has_curved:                  # leaving a curved shell: the true surface decides
            special |= back & np.take(tier.tri_curved, ph)
        if tier.owned and not (not isinstance(excl, np.ndarray) and excl < 0):
            special |= np.take(tier.tri_owner, ph) == (excl[rows] if isinstance(excl, np.ndarray) else excl)
        return (t, nrm), (special if np.count_nonzero(special) else None)

    def _trace_loop(self, tier: _Tier, O, D, t_near, lim, excl, eps64: float, exact: bool):
        """General path: cast, judge each hit, continue rejected rays past their hit (bounded).
        Judging: excluded owners are skipped; EXACT refines flat hits in float64 and curved hits
        on the true surface; FAST keeps Embree's answer except self-hits and shells left from
        inside.  Returns (t, shape, normal oriented toward the origin)."""
        m = len(O)
        eps = tier.eps
        Ot = _minus(O, tier.anchor) if tier.anchored else O
        if isinstance(t_near, np.ndarray):       # accepted hits: lo <= t <= lim
            lo = np.maximum(t_near, eps64)
            seg = np.maximum(t_near - eps, eps)   # Embree start along the ray
        else:
            lo = np.full(m, max(t_near, eps64))
            seg = np.full(m, max(t_near - eps, eps))
        lim = np.array(lim, dtype=np.float64) if isinstance(lim, np.ndarray) else np.full(m, float(lim))
        excl_arr = None
        if tier.owned:
            excl_arr = excl if isinstance(excl, np.ndarray) else np.full(m, excl, dtype=np.int64)
        best_t = np.full(m, _INF)
        best_s = np.full(m, -1, dtype=np.int64)
        best_n = np.zeros((m, 3))
        r2 = tier.radius ** 2
        if m and max(-float(Ot.min()), float(Ot.max())) * 1.7321 > tier.radius:
            # some origins outside the tier's sphere: clip to it
            b = _dot(Ot, D)
            q2 = _dot(Ot, Ot) - b * b
            half = np.sqrt(np.maximum(r2 - q2, 0.0))
            np.maximum(seg, -b - half, out=seg)
            alive = (q2 <= r2) & (-b + half >= lo) & (seg <= lim + eps)
        else:
            alive = seg <= lim + eps
        if tier.has_curved:
            pre = self._contained_prepass(tier, Ot, D, lo, lim, excl)
            if pre is not None:
                rows, tp, sp, np_ = pre
                best_t[rows], best_s[rows], best_n[rows] = tp, sp, np_
                np.minimum(lim, best_t, out=lim)

        act = alive.nonzero()[0]
        delta = None   # per-ray continuation step, allocated on the first continuation
        for _ in range(_MAX_LOOPS):
            if len(act) == 0:
                break
            view = slice(None) if len(act) == m else act   # all rays active: views, not copies
            oa, da, sa = Ot[view], D[view], seg[view]
            o_seg = oa + sa[:, None] * da
            d32 = da.astype(_F32)
            far = ((lim[view] - sa) + (eps if exact else 0.0)) * (1.0 + 2.0 ** -20)
            far32 = np.where(far >= 0.0, far, -1.0).astype(_F32)
            res = self._run(tier, o_seg.astype(_F32), d32, far32.copy() if exact else far32, robust=exact)
            prim, tf = res["primID"].astype(np.int64), res["tfar"]
            repaired = fixed = None
            if exact:
                # leak repair: a copy offset by a few ulps perpendicular to the ray
                o2 = (o_seg + _perpendicular(da) * (_LEAK_OFFSET_ULPS * tier.res)).astype(_F32)
                prim2 = self._run(tier, o2, d32, far32, robust=True)["primID"]
                sus = ((prim2 >= 0) & (prim2 != prim)).nonzero()[0]
                if len(sus):
                    ok, t2, tri2 = self._refine_triangles(tier, oa[sus], da[sus], prim2[sus].astype(np.int64),
                                                          sa[sus] - eps, lim[view][sus] + eps)
                    t_sus = np.where(prim[sus] >= 0, sa[sus] + tf[sus], _INF)
                    fix = ok & ((prim[sus] < 0) | (t2 < t_sus - eps))
                    if np.count_nonzero(fix):
                        fixed = (sus[fix], t2[fix])
                        prim[fixed[0]] = tri2[fix]
                        repaired = np.zeros(len(prim), dtype=bool)   # Embree's barycentrics no longer apply
                        repaired[fixed[0]] = True
                        self.counters["leak_repairs"] += len(fixed[0])
            h = (prim >= 0).nonzero()[0]
            if len(h) == 0:  # nothing hit: every active ray is done
                break
            t_e = np.where(prim >= 0, sa + tf, _INF)   # Embree distance along the whole ray
            if fixed is not None:
                t_e[fixed[0]] = fixed[1]
            cont = np.zeros(len(act), dtype=bool)   # rays to continue past their hit
            if len(h):
                ph = prim[h]
                rows_h = act[h]
                rej = np.zeros(len(h), dtype=bool)
                if excl_arr is not None:
                    rej |= tier.tri_owner[ph] == excl_arr[rows_h]
                slot = tier.tri_slot[ph]
                curved = slot >= 0
                # --- flat triangles (boxes, meshes)
                fl = (~curved & ~rej).nonzero()[0]
                if len(fl):
                    rows = rows_h[fl]
                    tri = ph[fl]
                    nrm = np.take(tier.normal, tri, axis=0)
                    Dr = _rows(D, rows)
                    dn = _dot(Dr, nrm)
                    if exact:
                        tx = _dot(np.take(tier.v0, tri, axis=0) - _rows(Ot, rows), nrm) / dn
                        ok = np.isfinite(tx) & (tx >= lo[rows]) & (tx <= lim[rows])
                        # Embree barycentrics comfortably inside the triangle: float32 cannot have
                        # picked the wrong one and its float64 plane gives the exact distance; near
                        # an edge (or repaired), test in float64
                        hf = h[fl]
                        u, v = res["u"][hf], res["v"][hf]
                        near_edge = ~(np.minimum(np.minimum(u, v), 1.0 - u - v) > 1e-4)
                        if repaired is not None:
                            near_edge |= repaired[hf]
                        edge = near_edge.nonzero()[0]
                        # float64 barycentrics of the plane hit: in a coarse float32 frame Embree
                        # can report comfortable barycentrics on the adjacent face's triangle
                        P = _rows(Ot, rows) + tx[:, None] * Dr - np.take(tier.v0, tri, axis=0)
                        bu = _dot(P, np.take(tier.g1, tri, axis=0))
                        bv = _dot(P, np.take(tier.g2, tri, axis=0))
                        near_edge |= ~((bu >= -_BARY_TOL) & (bv >= -_BARY_TOL) & (bu + bv <= 1.0 + _BARY_TOL))
                        edge = near_edge.nonzero()[0]
                        if len(edge):
                            r = rows[edge]
                            ok_e, t_x, tri_e = self._refine_triangles(tier, Ot[r], D[r], tri[edge], lo[r], lim[r])
                            miss = (~ok_e).nonzero()[0]
                            if len(miss):   # not the hit triangle nor a vertex neighbour: nearby triangles
                                rm = r[miss]
                                ok_n, t_n, tri_n = self._nearby_triangles(
                                    tier, Ot[rm], D[rm], t_e[hf[edge[miss]]], lo[rm], lim[rm],
                                    None if excl_arr is None else excl_arr[rm])
                                ok_e[miss], t_x[miss], tri_e[miss] = ok_n, t_n, tri_n
                            ok[edge], tx[edge], tri[edge] = ok_e, t_x, tri_e
                            nrm[edge] = tier.normal[tri_e]
                            dn[edge] = _dot(D[r], nrm[edge])
                    else:
                        tx = np.minimum(t_e[h[fl]], lim[rows])
                        gap = np.abs(_dot(_rows(Ot, rows) - np.take(tier.v0, tri, axis=0), nrm))
                        ok = ~((t_e[h[fl]] < seg[rows] + eps) & (gap <= 2.0 * eps))  # self-hit
                    acc = ok & (tx < best_t[rows])
                    nrm *= np.where(dn > 0.0, -1.0, 1.0)[:, None]   # toward the origin
                    if len(rows) == m and acc.all():
                        best_t[:], best_s[:], best_n[:] = tx, tier.tri_shape[tri], nrm
                    else:
                        r = rows[acc]
                        best_t[r], best_s[r], best_n[r] = tx[acc], tier.tri_shape[tri[acc]], nrm[acc]
                    rej[fl[~ok]] = True
                # --- curved shells (sphere, cylinder, capsule)
                cv = (curved & ~rej).nonzero()[0]
                if len(cv):
                    rows = rows_h[cv]
                    nrm = tier.normal[ph[cv]]
                    leaving = _dot(nrm, D[rows]) > 0.0
                    todo = np.ones(len(cv), dtype=bool) if exact else leaving
                    if not exact:  # FAST trusts the shell it enters
                        keep = (~todo).nonzero()[0]
                        r = rows[keep]
                        tk = np.minimum(t_e[h[cv[keep]]], lim[r])
                        better = tk < best_t[r]
                        r, kb = r[better], keep[better]
                        best_t[r], best_s[r], best_n[r] = tk[better], tier.tri_shape[ph[cv[kb]]], nrm[kb]
                    tdo = todo.nonzero()[0]
                    if len(tdo):
                        rr = rows[tdo]
                        sl = slot[cv[tdo]]
                        ta, na = self._analytic(tier, sl, Ot[rr], D[rr], lo[rr], lim[rr])
                        found = np.isfinite(ta)
                        better = found & (ta < best_t[rr])
                        r = rr[better]
                        na = na[better]
                        na[_dot(na, D[r]) > 0.0] *= -1.0
                        best_t[r], best_s[r], best_n[r] = ta[better], tier.c_shape[sl[better]], na
                        lim[rr] = np.minimum(lim[rr], np.where(found, ta, _INF))
                        # continue if missed, or if something else could sit between the shell
                        # crossing and the true surface (shell overlaps another shape)
                        again = ~found | ((ta > t_e[h[cv[tdo]]] + eps) & ~tier.c_isolated[sl])
                        rej[cv[tdo[again]]] = True
                cont[h[rej]] = True
            if not np.count_nonzero(cont):
                act = act[:0]
                break
            ci = cont.nonzero()[0]
            rows = act[ci]
            te = t_e[ci]
            stuck = te < seg[rows] + eps                  # no progress: widen the step
            if delta is None:
                delta = np.full(m, eps)
            delta[rows] = np.where(stuck, delta[rows] * 4.0, eps)
            seg[rows] = np.maximum(te, seg[rows]) + delta[rows]
            act = rows[seg[rows] <= lim[rows] + eps]
            self.counters["continued_rays"] += int(len(rows))
        else:
            self.counters["unresolved_rays"] += int(len(act))
        return best_t, best_s, best_n

    def _refine_triangles(self, tier: _Tier, Ot, D, tri, lo, hi):
        """Float64 hit of the ORIGINAL rays on triangle ``tri`` or, failing that, on the triangles
        sharing one of its vertices (float32 may pick the wrong side of an edge).  Returns
        (ok, t, triangle)."""
        ok, t = _moller_trumbore(Ot, D, tier.v0[tri], tier.e1[tri], tier.e2[tri])
        ok &= (t >= lo) & (t <= hi)
        t = np.where(ok, t, _INF)
        tri = tri.copy()
        bad = (~ok).nonzero()[0]
        if len(bad):
            ptr, idx = tier.ring
            starts = ptr[tri[bad]]
            counts = ptr[tri[bad] + 1] - starts
            ray = np.repeat(np.arange(len(bad)), counts)
            cand = idx[np.repeat(starts - (np.cumsum(counts) - counts), counts) + np.arange(int(counts.sum()))]
            okc, tc = _moller_trumbore(Ot[bad][ray], D[bad][ray], tier.v0[cand], tier.e1[cand], tier.e2[cand])
            okc &= (tc >= lo[bad][ray]) & (tc <= hi[bad][ray])
            tc = np.where(okc, tc, _INF)
            best = np.full(len(bad), _INF)
            np.minimum.at(best, ray, tc)
            won = np.isfinite(tc) & (tc == best[ray])
            btri = np.full(len(bad), -1, dtype=np.int64)
            btri[ray[won]] = cand[won]
            got = np.isfinite(best)
            t[bad[got]] = best[got]
            tri[bad[got]] = btri[got]
            ok[bad[got]] = True
        return ok, t, tri

    def _nearby_triangles(self, tier: _Tier, Ot, D, t_e, lo, hi, excl):
        """Float64 hit of the ORIGINAL rays on the flat triangles whose box, grown by float32
        uncertainty, contains the Embree hit point (a coarse float32 frame can report a triangle
        of a neighbouring face or shape).  Only hits up to t_e + eps count: beyond, a surface not
        among the candidates could come first (the ray is continued instead).  (ok, t, triangle)."""
        n = len(Ot)
        grow = tier.eps + 8.0 * tier.res
        P = Ot + np.minimum(t_e, 1e300)[:, None] * D
        t = np.full(n, _INF)
        tri = np.full(n, -1, dtype=np.int64)
        flat = ~tier.tri_curved[:-1]
        step = max(1, 4_000_000 // max(1, len(tier.F)))
        for a in range(0, n, step):
            b = min(n, a + step)
            near = np.all((P[a:b, None, :] >= tier.t_lo[None] - grow) & (P[a:b, None, :] <= tier.t_hi[None] + grow), axis=2)
            near &= flat[None]
            ray, cand = near.nonzero()
            ray = ray + a
            if excl is not None:
                keep = tier.tri_owner[cand] != excl[ray]
                ray, cand = ray[keep], cand[keep]
            if not len(ray):
                continue
            okc, tc = _moller_trumbore(Ot[ray], D[ray], tier.v0[cand], tier.e1[cand], tier.e2[cand])
            okc &= (tc >= lo[ray]) & (tc <= np.minimum(hi[ray], t_e[ray] + tier.eps))
            tc = np.where(okc, tc, _INF)
            order = np.lexsort((tc, ray))   # per ray, nearest first
            ray, cand, tc = ray[order], cand[order], tc[order]
            first = np.r_[True, ray[1:] != ray[:-1]]
            ray, cand, tc = ray[first], cand[first], tc[first]
            t[ray], tri[ray] = tc, cand
        ok = np.isfinite(t)
        tri[~ok] = -1
        return ok, t, tri

    def _analytic(self, tier: _Tier, slots, Ot, D, lo, hi):
        """True-surface hit of curved shapes (tier-frame rays): (t, tier-frame unit normal)."""
        n = len(slots)
        lo, hi = _full(lo, n), _full(hi, n)
        if n and not np.count_nonzero(slots != slots[0]):   # one shape: one matrix
            s0 = int(slots[0])
            R = tier.c_rot[s0]
            p = _mat(_minus(Ot, tier.c_pos[s0]), R)   # R^T (o - c)
            d = _mat(D, R)
            t, n_loc = _analytic_local(int(tier.c_code[s0]), p, d, tier.c_r[s0], tier.c_h[s0], lo, hi)
            return t, _mat(n_loc, R.T)
        R = tier.c_rot[slots]
        p = np.einsum("nij,ni->nj", R, Ot - tier.c_pos[slots])  # R^T (o - c)
        d = np.einsum("nij,ni->nj", R, D)
        t = np.full(n, _INF)
        n_loc = np.zeros((n, 3))
        codes = tier.c_code[slots]
        for code in (_SPHERE, _CYLINDER, _CAPSULE):
            g = (codes == code).nonzero()[0]
            if len(g):
                s = slots[g]
                t[g], n_loc[g] = _analytic_local(code, p[g], d[g], tier.c_r[s], tier.c_h[s], lo[g], hi[g])
        return t, np.einsum("nij,nj->ni", R, n_loc)

    def _contained_prepass(self, tier: _Tier, Ot, D, lo, lim, excl):
        """Rays starting inside a curved shell may reach the true surface before any crossing of
        that shell that the cast will see (the exit can lie beyond t_far or a nearer hit found
        elsewhere), so those (ray, shape) pairs are intersected analytically up front.  Screening
        of the start points: a few rays in plain floats; many rays against the bounding box of
        their origins first (a lidar's rays share one origin); then each shell's own extent (or a
        dense bounding-sphere test against several shells).  So this costs a few numpy calls unless
        some start point really is inside a shell.  Returns None, or (rows, t, global shape,
        normal toward the origin) of the hits found."""
        m = len(Ot)
        if m == 0:
            return None
        cp = tier.c_pos
        lo_col = lo[:, None] if isinstance(lo, np.ndarray) else lo
        if m * len(cp) <= (_TINY if len(cp) == 1 else 3 * _TINY):  # a few: plain floats throughout
            # (several shapes: most pairs fail the first sphere test, which is cheap in Python)
            S = (Ot + lo_col * D).tolist()
            pairs = [(i, k) for i, (x, y, z) in enumerate(S) for k, (cx, cy, cz, b2) in enumerate(tier.c_sphere)
                     if (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz) <= b2]
            if not pairs:
                return None
            return self._prepass_scalar(tier, pairs, S, Ot.tolist(), D.tolist(), lo, lim, excl)
        if m * len(cp) > _DENSE_PAIRS:  # many rays: screen their bounding box first (a lidar: a point)
            # per column: numpy reduces a short inner axis ~10x slower than a contiguous column
            reach = float(lo.max()) if isinstance(lo, np.ndarray) else lo
            box_lo = np.array([Ot[:, k].min() for k in range(3)]) - reach
            box_hi = np.array([Ot[:, k].max() for k in range(3)]) + reach
            gap = cp - np.minimum(np.maximum(cp, box_lo), box_hi)
            near = (_dot(gap, gap) <= tier.c_bound2).nonzero()[0].tolist()
            if not near:
                return None
        else:
            near = None
        S = Ot + lo_col * D
        if near is not None or len(cp) == 1:  # shape by shape, each shell's own extent straight away
            rs, ss = [], []
            for k in (near if near is not None else [0]):
                r = self._inside_shell(tier, k, S).nonzero()[0]
                rs.append(r)
                ss.append(np.full(len(r), k, dtype=np.int64))
            rows = np.concatenate(rs) if rs else np.zeros(0, dtype=np.int64)
            if len(rows) == 0:
                return None
            slots = np.concatenate(ss)
            tight = True
        else:  # a dense (rays, shapes) bounding-sphere test, then the shells' own extents
            dx, dy, dz = S[:, 0:1] - cp[:, 0], S[:, 1:2] - cp[:, 1], S[:, 2:3] - cp[:, 2]
            cand = dx * dx + dy * dy + dz * dz <= tier.c_bound2
            if not np.count_nonzero(cand):
                return None
            rows, slots = cand.nonzero()
            tight = False
        if len(rows) <= _SCALAR:
            pairs = list(zip(rows.tolist(), slots.tolist()))
            few = sorted({i for i, _ in pairs})
            rows_of = lambda a: dict(zip(few, a[few].tolist()))  # noqa: E731
            return self._prepass_scalar(tier, pairs, rows_of(S), rows_of(Ot), rows_of(D), lo, lim, excl)
        # tighter for cylinders and capsules: the shell's own extent in the shape frame
        tall = tier.c_code[slots] != _SPHERE
        if not tight and np.count_nonzero(tall):
            p = np.einsum("nij,ni->nj", tier.c_rot[slots], S[rows] - cp[slots])
            inside = ~tall | ((p[:, 0] ** 2 + p[:, 1] ** 2 <= tier.c_rad2[slots])
                              & (np.abs(p[:, 2]) <= tier.c_ax[slots]))
            rows, slots = rows[inside], slots[inside]
        if tier.c_owned and not (not isinstance(excl, np.ndarray) and excl < 0):
            keep = tier.c_owner[slots] != _take(excl, rows)
            rows, slots = rows[keep], slots[keep]
        if len(rows) == 0:
            return None
        ta, na = self._analytic(tier, slots, Ot[rows], D[rows], _take(lo, rows), _take(lim, rows))
        got = (ta < _INF).nonzero()[0]
        if len(got) == 0:
            return None
        rows, slots, ta, na = rows[got], slots[got], ta[got], na[got]
        if not _strictly_increasing(rows):  # inside several shells: the nearest surface
            keep = _best_per_row(rows, ta)
            rows, slots, ta, na = rows[keep], slots[keep], ta[keep], na[keep]
        na[_dot(na, D[rows]) > 0.0] *= -1.0
        return rows, ta, tier.c_shape[slots], na

    @staticmethod
    def _inside_shell(tier: _Tier, k: int, S) -> np.ndarray:
        """Mask of the points S (tier frame) inside curved slot k's shell extent: its bounding
        sphere for a sphere, the cylinder (max radius, max |z|) of its vertices otherwise."""
        p = _minus(S, tier.c_pos[k])
        if tier.c_code[k] == _SPHERE:
            return _dot(p, p) <= tier.c_bound2[k]
        p = _mat(p, tier.c_rot[k])
        return (p[:, 0] * p[:, 0] + p[:, 1] * p[:, 1] <= tier.c_rad2[k]) & (np.abs(p[:, 2]) <= tier.c_ax[k])

    def _prepass_scalar(self, tier: _Tier, pairs, S, Ot, D, lo, lim, excl):
        """The pre-pass after screening, for a few candidate (ray, shape) ``pairs``, in Python
        floats (same tests and answers as the vectorised tail).  S, Ot, D: start points, origins,
        directions as Python rows indexable by ray."""
        check_owner = tier.c_owned and not (not isinstance(excl, np.ndarray) and excl < 0)
        lo_l = lo if isinstance(lo, np.ndarray) else None
        lim_l = lim if isinstance(lim, np.ndarray) else None
        found: dict[int, tuple] = {}
        for i, k in pairs:
            code, r, h, c0, c1, c2, r0, r1, r2, r3, r4, r5, r6, r7, r8, rad2, ax, sid = tier.c_py[k]
            if code != _SPHERE:  # start point inside the shell's own extent (shape frame)?
                si = S[i]
                sx, sy, sz = si[0] - c0, si[1] - c1, si[2] - c2
                lx, ly, lz = sx * r0 + sy * r3 + sz * r6, sx * r1 + sy * r4 + sz * r7, sx * r2 + sy * r5 + sz * r8
                if not (lx * lx + ly * ly <= rad2 and abs(lz) <= ax):
                    continue
            if check_owner and tier.c_owner[k] == _take(excl, i):
                continue
            oi = Ot[i]
            ox, oy, oz = oi[0] - c0, oi[1] - c1, oi[2] - c2
            dx, dy, dz = D[i]
            t, (nx, ny, nz) = _analytic_one(
                code, (ox * r0 + oy * r3 + oz * r6, ox * r1 + oy * r4 + oz * r7, ox * r2 + oy * r5 + oz * r8),
                (dx * r0 + dy * r3 + dz * r6, dx * r1 + dy * r4 + dz * r7, dx * r2 + dy * r5 + dz * r8),
                r, h, lo if lo_l is None else float(lo_l[i]), lim if lim_l is None else float(lim_l[i]))
            if t < _INF and (i not in found or t < found[i][0]):
                n = (r0 * nx + r1 * ny + r2 * nz, r3 * nx + r4 * ny + r5 * nz, r6 * nx + r7 * ny + r8 * nz)
                if n[0] * dx + n[1] * dy + n[2] * dz > 0.0:   # toward the origin
                    n = (-n[0], -n[1], -n[2])
                found[i] = (t, sid, n)
        if not found:
            return None
        keys = sorted(found)
        return (np.array(keys, dtype=np.int64), np.array([found[i][0] for i in keys]),
                np.array([found[i][1] for i in keys], dtype=np.int64), np.array([found[i][2] for i in keys]))
