"""Ray-query engine: Embree (float32 BVH traversal) + float64 refinement.

The only module importing embreex.

Architecture
------------
* Static tier: the shapes of all static bodies (never moved) that a ray kind sees, in ONE Embree
  scene.  Its vertices are stored relative to the bounding-box centre (the *anchor*, subtracted
  in float64 before the float32 conversion; skipped when the geometry already surrounds the
  origin) so worlds far from the origin keep float32 precision.
* Mover tiers: each mover (``movable=True`` body, or a static body once moved) has its own scene
  in its BODY frame, built once.  Rays are moved into the body frame in float64; a vectorised
  bounding-sphere test picks the rays worth casting (skipping excluded owners), so moving a body
  never rebuilds anything.
* Planes are analytic (float64), never triangles.
* Curved primitives are tessellated CIRCUMSCRIBED (true surface inside the shell) and inflated
  by 4 float32 ulps, so every true hit lies inside the shell.  Rays whose start point is inside
  a curved shell are intersected analytically with that shape up front (a pre-pass screened by
  the bounding box of all start points): their true hit may come before any shell crossing the
  cast would reach (t_far or a nearer hit elsewhere ends the cast first).
* Scenes are built lazily on the first cast after a change, one per tier and ray kind; every
  commit counts in ``counters["bvh_builds"]``, every ``scene.run`` in ``counters["embree_calls"]``.
* FAST uses plain scenes, EXACT robust ones (``EmbreeScene(robust=True)``), each built when the
  mode first needs it.  Measured in a 600-triangle room with 131k lidar rays, all hitting: robust
  traversal costs ~40% more.  On rays aimed exactly at the vertices and edge midpoints of closed
  meshes, the plain scenes leak ~4% of rays; robust ones plus the repair below leak none.

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

from dataclasses import dataclass, field
from enum import Enum, IntEnum
from typing import Sequence

import numpy as np
from embreex import rtcore as _rtc
from embreex import rtcore_scene as _rts
from embreex.mesh_construction import TriangleMesh as _TriangleMesh

from sensorium.server.geometry import (
    Capsule, Cylinder, Mesh, Plane, Pose, Primitive, Sphere, tessellate,
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
    """x - v for (n,3) x and (3,) v, column by column (numpy broadcasts a length-3 inner axis
    slowly)."""
    out = np.empty(x.shape)
    for k in range(3):
        np.subtract(x[:, k], v[k], out=out[:, k])
    return out


def _ulp32(x: float) -> float:
    return float(np.spacing(_F32(max(abs(x), 1e-30))))


def _moller_trumbore(o, d, v0, e1, e2, tol=_BARY_TOL):
    """Float64 ray/triangle test: (inside within barycentric tol, t)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        p = _cross(d, e2)
        inv = 1.0 / _dot(e1, p)
        s = o - v0
        u = _dot(s, p) * inv
        q = _cross(s, e1)
        v = _dot(d, q) * inv
        t = _dot(e2, q) * inv
        ok = np.isfinite(t) & (u >= -tol) & (v >= -tol) & (u + v <= 1.0 + tol)
    return ok, t


def _roots(a, b, c, disc):
    """Both roots of a t^2 + 2 b t + c = 0 given disc = b^2 - a c (computed stably by the
    caller); +inf where there is no real root."""
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.sqrt(np.maximum(disc, 0.0))
        q = -(b + np.copysign(s, b))
        t1 = q / a
        t2 = np.where(q != 0.0, c / q, t1)
        bad = (disc < 0.0) | ~np.isfinite(t1)
    return np.where(bad, _INF, t1), np.where(bad, _INF, t2)


def _sphere_roots(p, d, r):
    a = _dot(d, d)
    b = _dot(p, d)
    c = _dot(p, p) - r * r
    x = _cross(p, d)
    return _roots(a, b, c, a * r * r - _dot(x, x))  # |p x d|^2 form: no cancellation far away


def _side_roots(p, d, r):
    """Roots against the infinite cylinder x^2 + y^2 = r^2."""
    a = d[:, 0] ** 2 + d[:, 1] ** 2
    b = p[:, 0] * d[:, 0] + p[:, 1] * d[:, 1]
    c = p[:, 0] ** 2 + p[:, 1] ** 2 - r * r
    x = p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0]
    return _roots(a, b, c, a * r * r - x * x)


def _analytic_local(code, p, d, r, h, lo, hi):
    """Nearest true-surface hit with lo <= t <= hi, shape-local frame.  ``r`` radius, ``h`` half
    height (cylinder) or half length of the straight part (capsule).  Returns (t, normal)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return _analytic_local_impl(code, p, d, r, h, lo, hi)


def _analytic_local_impl(code, p, d, r, h, lo, hi):
    m = len(p)
    tol = 1e-12 * (r + h)
    z = lambda t: p[:, 2] + t * d[:, 2]  # noqa: E731
    if code == _SPHERE:
        cands = list(_sphere_roots(p, d, r))
        kinds = [0, 0]
    else:
        s1, s2 = _side_roots(p, d, r)
        cands = [np.where(np.abs(z(s1)) <= h + tol, s1, _INF), np.where(np.abs(z(s2)) <= h + tol, s2, _INF)]
        kinds = [1, 1]
        if code == _CYLINDER:
            with np.errstate(divide="ignore", invalid="ignore"):
                for sign in (1.0, -1.0):
                    tc = (sign * h - p[:, 2]) / d[:, 2]
                    x = p[:, 0] + tc * d[:, 0]
                    y = p[:, 1] + tc * d[:, 1]
                    ok = np.isfinite(tc) & (x * x + y * y <= r * r + tol * r)
                    cands.append(np.where(ok, tc, _INF))
                    kinds.append(2 if sign > 0 else 3)
        else:
            for sign in (1.0, -1.0):
                pc = p.copy()
                pc[:, 2] -= sign * h
                for t in _sphere_roots(pc, d, r):
                    cands.append(np.where(sign * z(t) >= h - tol, t, _INF))  # beyond the centre
                    kinds.append(4 if sign > 0 else 5)
    ts = np.stack(cands, axis=1)
    ts = np.where((ts >= lo[:, None]) & (ts <= hi[:, None]), ts, _INF)
    col = np.argmin(ts, axis=1)
    t = ts[np.arange(m), col]
    kind = np.asarray(kinds)[col]
    x = p + np.where(np.isfinite(t), t, 0.0)[:, None] * d
    n = np.zeros((m, 3))
    if code == _SPHERE:
        n[:] = x
    else:
        side = kind == 1
        n[side, :2] = x[side, :2]
        n[kind == 2, 2] = 1.0
        n[kind == 3, 2] = -1.0
        for k, sign in ((4, 1.0), (5, -1.0)):
            sel = kind == k
            n[sel] = x[sel]
            n[sel, 2] -= sign * h[sel] if isinstance(h, np.ndarray) else sign * h
    with np.errstate(invalid="ignore", divide="ignore"):
        n /= np.linalg.norm(n, axis=1)[:, None]
    n[~np.isfinite(t)] = 0.0
    return t, n


def _perpendicular(d: np.ndarray) -> np.ndarray:
    c = _cross(d, np.broadcast_to(_AUX1, d.shape))
    weak = _dot(c, c) < 0.1
    if weak.any():
        c[weak] = _cross(d[weak], np.broadcast_to(_AUX2, (int(weak.sum()), 3)))
    return c / np.linalg.norm(c, axis=1)[:, None]


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
        self.ng_max = float(np.linalg.norm(np.cross(self.e1, self.e2), axis=1).max())
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
        self.c_owner = owner_of[self.c_shape]
        self.c_isolated = self._isolation(verts, tri_shape, c_shape)
        self._ring: tuple[np.ndarray, np.ndarray] | None = None
        # Embree keeps pointers into these buffers: hold references for the scenes' lifetime
        self._v32 = np.ascontiguousarray(V, dtype=_F32)
        self._f32 = np.ascontiguousarray(F, dtype=np.int32)
        self._device = device
        self._scenes: dict[bool, object] = {}

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
    shapes: list[int]
    pose: Pose
    owner: int
    mover: bool
    tiers: dict = field(default_factory=dict)  # variant -> _Tier (movers only)


@dataclass(slots=True)
class _Cast:
    """Per-cast parameters shared by the tiers."""
    O: np.ndarray
    D: np.ndarray
    t_near: float | np.ndarray
    excl: int | np.ndarray
    exact: bool
    _eps64: float | None = None
    _cols: tuple | None = None

    @property
    def cols(self) -> tuple:
        """Contiguous columns (ox, oy, oz, dx, dy, dz), shared by the per-mover sphere tests."""
        if self._cols is None:
            self._cols = tuple(np.ascontiguousarray(a[:, k]) for a in (self.O, self.D) for k in range(3))
        return self._cols

    @property
    def eps64(self) -> float:
        # float64 self-hit epsilon: 1e-9 m plus ~50 ulps of the largest world coordinate
        if self._eps64 is None:
            big = max(float(self.O.max()), -float(self.O.min())) if len(self.O) else 0.0
            self._eps64 = 1e-9 + 1e-14 * big
        return self._eps64


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
        self._static: dict[str, _Tier | None] = {}
        self._planes: dict[str, list[tuple[int, int]]] = {}
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
        self._bodies.append(_Body(list(range(first, len(self._entries))), pose, int(owner), bool(movable)))
        self._planes.clear()
        if movable:
            self._movers.append(self._bodies[-1])
        else:
            self._static.clear()
        return body

    def set_body_pose(self, body: int, pose: Pose) -> None:
        b = self._bodies[body]
        b.pose = pose
        if not b.mover:  # first move of a static body: it leaves the static tier for good
            b.mover = True
            self._movers.append(b)
            self._static.clear()

    def shape_owner(self, shape: int) -> int:
        return int(self._owner_of[shape])

    def shape_body(self, shape: int) -> int:
        return self._shape_body[shape]

    # ---- lazy builds ------------------------------------------------------------------------

    def _variant(self, kind: RayKind, skip_transparent: bool) -> str:
        if RayKind(kind) == RayKind.VISUAL:
            return _V_VISUAL
        return _V_OPAQUE if skip_transparent else _V_BOUNDING

    def _build(self, items) -> _Tier | None:
        tier = _Tier(self._device, items, self._owner_of)
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
            out.append((sid, e.primitive, body.pose.compose(e.local_pose) if world else e.local_pose))
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
                self._static[variant] = self._build([i for b in statics for i in self._items(b, variant, True)])
        return self._static[variant]

    def _mover_tier(self, body: _Body, variant: str) -> _Tier | None:
        if variant not in body.tiers:
            if variant == _V_OPAQUE and not self._has_transparent([body]):
                body.tiers[variant] = self._mover_tier(body, _V_BOUNDING)
            else:
                body.tiers[variant] = self._build(self._items(body, variant, False))
        return body.tiers[variant]

    def _plane_list(self, variant: str) -> list[tuple[int, int]]:
        if variant not in self._planes:
            self._planes[variant] = [
                (sid, bi) for bi, b in enumerate(self._bodies) for sid in b.shapes
                if isinstance(self._entries[sid].primitive, Plane) and _sees(self._entries[sid], variant)]
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
        t_near = float(t_near) if np.ndim(t_near) == 0 else np.asarray(t_near, dtype=np.float64).reshape(n)
        t_far = float(t_far) if np.ndim(t_far) == 0 else np.asarray(t_far, dtype=np.float64).reshape(n)
        excl = int(exclude_owner) if np.ndim(exclude_owner) == 0 else np.asarray(exclude_owner, dtype=np.int64).reshape(n)
        self.counters["rays_cast"] += n
        variant = self._variant(kind, skip_transparent)
        ctx = _Cast(O, D, t_near, excl, self._precision == Precision.EXACT)

        dist = shape = normal = None
        planes = self._plane_list(variant)
        if planes and n:
            dist, shape, normal = self._cast_planes(ctx, planes, variant, t_far)

        static = self._static_tier(variant)
        if static is not None and n:
            lim = t_far if dist is None else np.minimum(t_far, dist)
            t, s, nrm = self._trace(static, ctx, O, D, t_near, lim, excl)
            if dist is None:
                dist, shape, normal = t, s, nrm
            else:
                better = t < dist
                dist[better], shape[better], normal[better] = t[better], s[better], nrm[better]

        if dist is None:
            dist = np.full(n, _INF)
            shape = np.full(n, -1, dtype=np.int64)
            normal = np.zeros((n, 3))
        for b in self._movers if n else ():
            tier = self._mover_tier(b, variant)
            if tier is not None:
                self._cast_mover(tier, b, ctx, t_far, dist, shape, normal)
        return RayHits(dist, normal, shape)

    def _cast_planes(self, ctx: _Cast, planes, variant: str, t_far):
        O, D = ctx.O, ctx.D
        n = len(O)
        dist = np.full(n, _INF)
        shape = np.full(n, -1, dtype=np.int64)
        normal = np.zeros((n, 3))
        lo = np.maximum(ctx.t_near, ctx.eps64)
        for sid, bi in planes:
            owner = int(self._owner_of[sid])
            if owner >= 0 and np.all(ctx.excl == owner):
                continue
            e = self._entries[sid]
            pose = self._bodies[bi].pose.compose(e.local_pose)
            nz = pose.rotation[:, 2]
            rel = pose.translation - O
            den = D @ nz
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (rel @ nz) / den
            ok = (t >= lo) & (t <= t_far) & (t < dist)
            if variant == _V_VISUAL:  # one-sided (front = +z side), finite when sized
                ok &= den < 0.0
                if e.primitive.size is not None:
                    x = O + np.where(ok, t, 0.0)[:, None] * D - pose.translation
                    sx, sy = e.primitive.size
                    ok &= (np.abs(x @ pose.rotation[:, 0]) <= sx / 2.0) & (np.abs(x @ pose.rotation[:, 1]) <= sy / 2.0)
            else:
                ok &= den != 0.0
            if owner >= 0:
                ok &= ctx.excl != owner
            dist[ok] = t[ok]
            shape[ok] = sid
            normal[ok] = np.where((den[ok] > 0.0)[:, None], -nz, nz)
        return dist, shape, normal

    def _cast_mover(self, tier: _Tier, body: _Body, ctx: _Cast, t_far, dist, shape, normal) -> None:
        O, D = ctx.O, ctx.D
        n = len(O)
        R, T = body.pose.rotation, body.pose.translation
        centre = R @ tier.anchor + T
        ox, oy, oz, dx, dy, dz = ctx.cols
        cx, cy, cz = centre[0] - ox, centre[1] - oy, centre[2] - oz
        b = cx * dx + cy * dy + cz * dz
        q2 = cx * cx + cy * cy + cz * cz - b * b
        r2 = tier.radius * tier.radius
        half = np.sqrt(np.maximum(r2 - q2, 0.0))
        lim = np.minimum(t_far, dist)
        sel = (q2 <= r2) & (b + half >= ctx.t_near) & (b - half <= lim)
        if body.owner >= 0:
            sel &= ctx.excl != body.owner
        idx = np.flatnonzero(sel)
        if len(idx) == 0:
            return
        every = len(idx) == n
        Os, Ds = (O, D) if every else (np.take(O, idx, axis=0), np.take(D, idx, axis=0))
        Ob = _minus(Os, T) @ R  # world -> body frame, float64
        Db = Ds @ R
        sub = ctx if every else _Cast(Os, Ds, _take(ctx.t_near, idx), _take(ctx.excl, idx), ctx.exact, ctx.eps64)
        t, s, nrm = self._trace(tier, sub, Ob, Db, sub.t_near, lim if every else lim[idx], sub.excl)
        if every:
            better = np.flatnonzero(t < dist)
            w = better
        else:
            better = np.flatnonzero(t < dist[idx])
            w = idx[better]
        dist[w] = t[better]
        shape[w] = s[better]
        normal[w] = nrm[better] @ R.T

    # ---- one tier -----------------------------------------------------------------------------

    def _run(self, tier: _Tier, o32, d32, far, robust: bool):
        scene, built = tier.scene(robust)
        self.counters["bvh_builds"] += built
        self.counters["embree_calls"] += 1
        return scene.run(o32, d32, far, output=1)

    def _trace(self, tier: _Tier, ctx: _Cast, O, D, t_near, lim, excl):
        """Nearest accepted hit in one tier.  O, D in the tier's parent frame; returns (t, shape,
        normal oriented toward the origin) with normal in the parent frame's orientation."""
        if ctx.exact:
            return self._trace_loop(tier, ctx, O, D, t_near, lim, excl, exact=True)
        return self._trace_fast(tier, ctx, O, D, t_near, lim, excl)

    def _trace_fast(self, tier: _Tier, ctx: _Cast, O, D, t_near, lim, excl):
        """FAST: one Embree call and vectorised gathers; the rare rays needing judgement (possible
        self-hits, shells left from inside, excluded owners) are redone by the general loop."""
        m = len(O)
        if tier.anchored:
            o32 = np.empty((m, 3), dtype=_F32)
            for k in range(3):
                np.subtract(O[:, k], tier.anchor[k], out=o32[:, k], casting="unsafe")
        else:
            o32 = O.astype(_F32)
        d32 = D.astype(_F32)
        pre = None
        if tier.has_curved:  # origins inside a curved shell: analytic first (see the pre-pass)
            pre = (np.full(m, _INF), np.full(m, -1, dtype=np.int64), np.zeros((m, 3)))
            Ot = _minus(O, tier.anchor) if tier.anchored else O
            if self._contained_prepass(tier, Ot, D, np.maximum(t_near, ctx.eps64), lim, excl, *pre):
                lim = np.minimum(lim, pre[0])
            else:
                pre = None
        start = t_near
        dead = None
        if len(o32) and max(-float(o32.min()), float(o32.max())) * 1.7321 > tier.radius:
            far_rows = np.flatnonzero(_dot(o32, o32) > _F32(tier.radius * tier.radius))
            if len(far_rows):  # origin outside the tier's sphere: start at its entry (precision)
                start = np.array(np.broadcast_to(start, (m,)), dtype=np.float64)
                Ot = O[far_rows] - tier.anchor
                Dr = D[far_rows]
                b = _dot(Ot, Dr)
                q2 = _dot(Ot, Ot) - b * b
                enter = -b - np.sqrt(np.maximum(tier.radius ** 2 - q2, 0.0))
                start[far_rows] = np.maximum(start[far_rows], enter)
                dead = far_rows[q2 > tier.radius ** 2]
                o32 += start[:, None] * d32
                o32[far_rows] = Ot + start[far_rows][:, None] * Dr
        if not isinstance(start, np.ndarray) and start > 0.0:
            o32 += _F32(start) * d32
        elif isinstance(start, np.ndarray) and dead is None:
            o32 += start[:, None] * d32
        far = (lim - start) * (1.0 + 2.0 ** -20)  # float32 slack so a hit exactly at t_far counts
        if dead is not None and len(dead):
            far = np.array(np.broadcast_to(far, (m,)))
            far[dead] = -1.0
        if isinstance(far, np.ndarray):
            far = far.astype(_F32)
        elif far == _INF:
            far = None
        else:
            far = float(far)
        res = self._run(tier, o32, d32, far, robust=False)
        prim, tf = res["primID"], res["tfar"]
        hit = prim >= 0
        t = tf.astype(np.float64)
        t += start
        if not (np.isscalar(lim) and lim == _INF):
            np.minimum(t, lim, out=t)
        t[~hit] = _INF
        ng = res["Ng"] * d32                     # Embree's Ng has our winding: sign = side hit
        dots = ng[:, 0] + ng[:, 1] + ng[:, 2]
        back = dots > 0.0
        normal = np.take(tier.normal2, prim + back * (len(tier.normal)), axis=0)
        shape = np.take(tier.tri_shape, prim)
        grazing = np.flatnonzero(hit & (np.abs(dots) < 1e-5 * tier.ng_max))
        if len(grazing):  # float32 sign unreliable: orient in float64
            nrm = tier.normal[prim[grazing]]
            flip = _dot(nrm, D[grazing]) > 0.0
            nrm[flip] *= -1.0
            normal[grazing] = nrm
            back[grazing] = flip
        special = hit & (tf < tier.eps)         # possible self-hit (origin on the surface)
        if special.any():
            rows = np.flatnonzero(special)
            tri = prim[rows]
            gap = np.abs(_dot(O[rows] - tier.anchor - tier.v0[tri], tier.normal[tri]))
            special[rows] = gap <= 2.0 * tier.eps
        if tier.has_curved:                     # leaving a curved shell: the true surface decides
            special |= back & np.take(tier.tri_curved, prim)
        if tier.owned and not (np.isscalar(excl) and excl < 0):
            special |= np.take(tier.tri_owner, prim) == excl
        if pre is not None:  # analytic hits of the pre-pass (normals oriented below)
            take = np.flatnonzero(pre[0] <= t)
            t[take], shape[take] = pre[0][take], pre[1][take]
            nrm = pre[2][take]
            flip = _dot(nrm, D[take]) > 0.0
            nrm[flip] *= -1.0
            normal[take] = nrm
            special[take] = False
        rows = np.flatnonzero(special)
        if len(rows):
            t2, s2, n2 = self._trace_loop(tier, ctx, O[rows], D[rows], _take(t_near, rows), _take(lim, rows),
                                          _take(excl, rows), exact=False)
            t[rows], shape[rows], normal[rows] = t2, s2, n2
        return t, shape, normal

    def _trace_loop(self, tier: _Tier, ctx: _Cast, O, D, t_near, lim, excl, exact: bool):
        """General path: cast, judge each hit, continue rejected rays past their hit (bounded).
        Judging: excluded owners are skipped; EXACT refines flat hits in float64 and curved hits
        on the true surface; FAST keeps Embree's answer except self-hits and shells left from
        inside.  Returns (t, shape, normal oriented toward the origin)."""
        m = len(O)
        Ot = _minus(O, tier.anchor) if tier.anchored else O
        lo = np.broadcast_to(np.maximum(t_near, ctx.eps64), (m,))   # accepted hits: lo <= t <= lim
        lim = np.array(np.broadcast_to(lim, (m,)), dtype=np.float64)
        excl_arr = np.broadcast_to(np.asarray(excl, dtype=np.int64), (m,))
        best_t = np.full(m, _INF)
        best_s = np.full(m, -1, dtype=np.int64)
        best_n = np.zeros((m, 3))
        eps = tier.eps
        seg = np.full(m, eps)
        seg = np.maximum(seg, np.asarray(t_near) - eps)               # Embree start along the ray
        r2 = tier.radius ** 2
        bound = max(max(abs(float(Ot[:, k].min())), abs(float(Ot[:, k].max()))) for k in range(3)) if m else 0.0
        if bound * 1.7321 > tier.radius:  # some origins outside the tier's sphere: clip to it
            b = _dot(Ot, D)
            q2 = _dot(Ot, Ot) - b * b
            half = np.sqrt(np.maximum(r2 - q2, 0.0))
            np.maximum(seg, -b - half, out=seg)
            alive = (q2 <= r2) & (-b + half >= lo) & (seg <= lim + eps)
        else:
            alive = seg <= lim + eps
        if self._contained_prepass(tier, Ot, D, lo, lim, excl_arr, best_t, best_s, best_n):
            np.minimum(lim, best_t, out=lim)
            got = np.flatnonzero(np.isfinite(best_t))
            flip = _dot(best_n[got], D[got]) > 0.0
            best_n[got[flip]] *= -1.0

        act = np.flatnonzero(alive)
        delta = np.full(m, eps)
        for _ in range(_MAX_LOOPS):
            if len(act) == 0:
                break
            view = slice(None) if len(act) == m else act   # all rays active: views, not copies
            oa, da, sa = Ot[view], D[view], seg[view]
            o_seg = oa + sa[:, None] * da
            d32 = da.astype(_F32)
            far = ((lim[view] - sa) + (eps if exact else 0.0)) * (1.0 + 2.0 ** -20)
            far32 = np.where(far >= 0.0, far, -1.0).astype(_F32)
            res = self._run(tier, o_seg.astype(_F32), d32, far32.copy(), robust=exact)
            prim, tf = res["primID"].astype(np.int64), res["tfar"]
            t_e = np.where(prim >= 0, sa + tf, _INF)
            # Embree barycentrics: comfortably inside the triangle -> float32 cannot have picked
            # the wrong triangle, so its float64 plane gives the exact distance
            u, v = res["u"], res["v"]
            interior = np.minimum(np.minimum(u, v), 1.0 - u - v) > 1e-4
            if exact:  # leak repair: a copy offset by a few ulps perpendicular to the ray
                o2 = (o_seg + _perpendicular(da) * (_LEAK_OFFSET_ULPS * tier.res)).astype(_F32)
                prim2 = self._run(tier, o2, d32, far32.copy(), robust=True)["primID"]
                sus = np.flatnonzero((prim2 >= 0) & (prim2 != prim))
                if len(sus):
                    ok, t2, tri2 = self._refine_triangles(tier, oa[sus], da[sus], prim2[sus].astype(np.int64),
                                                          sa[sus] - eps, lim[view][sus] + eps)
                    fix = ok & ((prim[sus] < 0) | (t2 < t_e[sus] - eps))
                    if fix.any():
                        r = sus[fix]
                        prim[r], t_e[r], interior[r] = tri2[fix], t2[fix], False
                        self.counters["leak_repairs"] += int(fix.sum())
            h = np.flatnonzero(prim >= 0)
            cont = np.zeros(len(act), dtype=bool)   # rays to continue past their hit
            if len(h):
                ph = prim[h]
                rows_h = act[h]
                rej = np.zeros(len(h), dtype=bool)
                if tier.owned:
                    rej |= tier.tri_owner[ph] == excl_arr[rows_h]
                slot = tier.tri_slot[ph]
                curved = slot >= 0
                # --- flat triangles (boxes, meshes)
                fl = np.flatnonzero(~curved & ~rej)
                if len(fl):
                    rows = rows_h[fl]
                    tri = ph[fl]
                    nrm = np.take(tier.normal, tri, axis=0)
                    Dr = _rows(D, rows)
                    dn = _dot(Dr, nrm)
                    if exact:
                        with np.errstate(divide="ignore", invalid="ignore"):
                            tx = _dot(np.take(tier.v0, tri, axis=0) - _rows(Ot, rows), nrm) / dn
                        ok = np.isfinite(tx) & (tx >= lo[rows]) & (tx <= lim[rows])
                        edge = np.flatnonzero(~interior[h[fl]])   # near an edge: test in float64
                        if len(edge):
                            r = rows[edge]
                            ok_e, t_x, tri_e = self._refine_triangles(tier, Ot[r], D[r], tri[edge], lo[r], lim[r])
                            ok[edge], tx[edge], tri[edge] = ok_e, t_x, tri_e
                            nrm[edge] = tier.normal[tri_e]
                            dn[edge] = _dot(D[r], nrm[edge])
                    else:
                        tx = np.minimum(t_e[h[fl]], lim[rows])
                        gap = np.abs(_dot(_rows(Ot, rows) - np.take(tier.v0, tri, axis=0), nrm))
                        ok = ~((t_e[h[fl]] < seg[rows] + eps) & (gap <= 2.0 * eps))  # self-hit
                    acc = ok & (tx < best_t[rows])
                    nrm *= np.where(dn > 0.0, -1.0, 1.0)[:, None]   # toward the origin
                    if acc.all() and len(rows) == m:
                        best_t[:], best_s[:], best_n[:] = tx, tier.tri_shape[tri], nrm
                    else:
                        r = rows[acc]
                        best_t[r], best_s[r], best_n[r] = tx[acc], tier.tri_shape[tri[acc]], nrm[acc]
                    rej[fl[~ok]] = True
                # --- curved shells (sphere, cylinder, capsule)
                cv = np.flatnonzero(curved & ~rej)
                if len(cv):
                    rows = rows_h[cv]
                    nrm = tier.normal[ph[cv]]
                    leaving = _dot(nrm, D[rows]) > 0.0
                    todo = np.ones(len(cv), dtype=bool) if exact else leaving
                    if not exact:  # FAST trusts the shell it enters
                        keep = np.flatnonzero(~todo)
                        r = rows[keep]
                        tk = np.minimum(t_e[h[cv[keep]]], lim[r])
                        better = tk < best_t[r]
                        r, kb = r[better], keep[better]
                        best_t[r], best_s[r], best_n[r] = tk[better], tier.tri_shape[ph[cv[kb]]], nrm[kb]
                    tdo = np.flatnonzero(todo)
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
            if not cont.any():
                act = act[:0]
                break
            ci = np.flatnonzero(cont)
            rows = act[ci]
            te = t_e[ci]
            stuck = te < seg[rows] + eps                  # no progress: widen the step
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
        bad = np.flatnonzero(~ok)
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

    def _analytic(self, tier: _Tier, slots, Ot, D, lo, hi):
        """True-surface hit of curved shapes (tier-frame rays): (t, tier-frame unit normal)."""
        R = tier.c_rot[slots]
        p = np.einsum("nij,ni->nj", R, Ot - tier.c_pos[slots])  # R^T (o - c)
        d = np.einsum("nij,ni->nj", R, D)
        t = np.full(len(slots), _INF)
        n_loc = np.zeros((len(slots), 3))
        codes = tier.c_code[slots]
        for code in (_SPHERE, _CYLINDER, _CAPSULE):
            g = np.flatnonzero(codes == code)
            if len(g):
                s = slots[g]
                t[g], n_loc[g] = _analytic_local(code, p[g], d[g], tier.c_r[s], tier.c_h[s], lo[g], hi[g])
        return t, np.einsum("nij,nj->ni", R, n_loc)

    def _contained_prepass(self, tier: _Tier, Ot, D, lo, lim, excl, best_t, best_s, best_n) -> bool:
        """Rays starting inside a curved shell may reach the true surface before any crossing of
        that shell that the cast will see (the exit can lie beyond t_far or a nearer hit found
        elsewhere), so those (ray, shape) pairs are intersected analytically up front.  Shells
        are first screened against the bounding box of all start points (a lidar's rays share
        one origin), so this costs nothing unless some origin really is inside a shell.
        True if any hit was found."""
        if not tier.has_curved or len(Ot) == 0:
            return False
        reach = float(np.max(lo))
        box_lo = np.array([Ot[:, k].min() for k in range(3)]) - reach
        box_hi = np.array([Ot[:, k].max() for k in range(3)]) + reach
        nearest = np.clip(tier.c_pos, box_lo, box_hi)
        near = np.flatnonzero(((tier.c_pos - nearest) ** 2).sum(1) <= tier.c_bound ** 2)
        if len(near) == 0:
            return False
        corners = np.array([[x, y, z] for x in (box_lo[0], box_hi[0]) for y in (box_lo[1], box_hi[1])
                            for z in (box_lo[2], box_hi[2])])
        start = None
        found = False
        for slot in near:
            if tier.c_code[slot] != _SPHERE:  # box of the start points in the shape frame
                loc = (corners - tier.c_pos[slot]) @ tier.c_rot[slot]
                llo, lhi = loc.min(0), loc.max(0)
                closest = np.clip(0.0, llo, lhi)
                if np.hypot(closest[0], closest[1]) > tier.c_rad[slot] or abs(closest[2]) > tier.c_ax[slot]:
                    continue
            if start is None:
                start = Ot + np.asarray(lo, dtype=np.float64).reshape(-1, 1) * D
            rel = _minus(start, tier.c_pos[slot])
            rows = np.flatnonzero(_dot(rel, rel) <= tier.c_bound[slot] ** 2)
            if len(rows) and tier.c_code[slot] != _SPHERE:  # tighter: the shell's local cylinder
                p = rel[rows] @ tier.c_rot[slot]
                inside = (p[:, 0] ** 2 + p[:, 1] ** 2 <= tier.c_rad[slot] ** 2) & (np.abs(p[:, 2]) <= tier.c_ax[slot])
                rows = rows[inside]
            owner = tier.c_owner[slot]
            if owner >= 0 and len(rows):
                rows = rows[np.broadcast_to(excl, (len(Ot),))[rows] != owner]
            if len(rows) == 0:
                continue
            lo_r = np.broadcast_to(lo, (len(Ot),))[rows]
            hi_r = np.broadcast_to(lim, (len(Ot),))[rows]
            ta, na = self._analytic(tier, np.full(len(rows), slot), Ot[rows], D[rows], lo_r, hi_r)
            better = ta < best_t[rows]
            r = rows[better]
            best_t[r], best_s[r], best_n[r] = ta[better], tier.c_shape[slot], na[better]
            found |= bool(better.any())
        return found
