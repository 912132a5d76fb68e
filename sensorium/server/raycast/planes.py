"""Analytic planes: all planes one ray kind sees, intersected in one (rays x planes) float64 pass."""

from __future__ import annotations

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.exact import _INF
from sensorium.server.raycast.kinds import ShapeEntry
from sensorium.server.raycast.movers import _Body


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
        self._rows: tuple | None = None
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
        # one axis-aligned plane (a floor): its normal's only non-zero component, else -1; when sized,
        # also the world axes of its x and y (each a unit axis), else None
        zero = self.nz == 0.0
        self.axis = int(np.argmin(zero[0])) if len(self.nz) == 1 and np.count_nonzero(zero[0]) == 2 else -1
        self.size_axes = None
        if self.axis >= 0 and self.sized:
            a, b = np.abs(self.ax[0]), np.abs(self.ay[0])
            if np.count_nonzero(a == 1.0) == 1 and np.count_nonzero(a) == 1 and np.count_nonzero(b == 1.0) == 1 \
                    and np.count_nonzero(b) == 1:
                self.size_axes = (int(np.argmax(a)), int(np.argmax(b)))
        self._poses = poses
        self._rows = None

    def native_rows(self) -> tuple:
        """The addresses of the first plane's point, normal, x and y axes and half sizes as contiguous
        float64 rows (packets.plane1 reads them; the rows kept with them), made once per refresh that
        changed them."""
        if self._rows is None:
            rows = [np.ascontiguousarray(a[0], dtype=np.float64) for a in (self.pt, self.nz, self.ax, self.ay, self.half)]
            self._rows = (rows, *(a.ctypes.data for a in rows))
        return self._rows[1:]



def plane_terms(O, D, pt, nz, ax, ay, half, den, ok, lo, hi, sized: bool) -> np.ndarray:
    """The distances ``t`` of rays ``O + t D`` ((n, 3) rows; O may be one row) to planes through
    ``pt`` with normals ``nz`` (each a sequence of 3 coordinate arrays that broadcast with the (n, 1)
    columns of O and D: (P,) for planes every ray meets, (n, K) for planes per ray), ``den`` = D . nz,
    and ``ok`` (updated in place) -- the rays' candidates, then those hitting within [lo, hi] and,
    when ``sized``, within the half sizes ``half`` (2 arrays) along ``ax``, ``ay``. The one float64
    arithmetic every plane pass runs, element by element in a fixed order (the single world's
    cast_planes and the copies' robot planes, CopyRays: the same bits)."""
    # rel = P - O column by column, then rel . nz: exact far from the origin (no cancellation)
    r0 = pt[0] - O[:, 0:1]
    r1 = pt[1] - O[:, 1:2]
    r2 = pt[2] - O[:, 2:3]
    t = (r0 * nz[0] + r1 * nz[1] + r2 * nz[2]) / den
    ok &= (t >= lo) & (t <= hi)
    if sized and np.count_nonzero(ok):  # hit point in the plane frame within the size
        x0, x1, x2 = t * D[:, 0:1] - r0, t * D[:, 1:2] - r1, t * D[:, 2:3] - r2
        ok &= (np.abs(x0 * ax[0] + x1 * ax[1] + x2 * ax[2]) <= half[0]) & \
              (np.abs(x0 * ay[0] + x1 * ay[1] + x2 * ay[2]) <= half[1])
    return t


def cast_planes(pl: _Planes, epoch: int, O, D, t_near, t_far, excl, eps64, distance_only: bool = False,
                native: bool = False):
    """(dist, shape, normal) of the nearest plane hits, or None if no ray hits a plane (shape and
    normal None with ``distance_only``).  Rays sharing one origin (a broadcast array: a lidar)
    compute the origin's offsets once.  ``native``: one axis-aligned plane (a floor) in one C pass
    where the helper is (packets.plane1: this function's values, bit for bit)."""
    pl.refresh(epoch)
    n, P = len(O), len(pl.sid)
    check_owner = pl.owned and not (not isinstance(excl, np.ndarray) and excl < 0)
    if distance_only and pl.axis >= 0 and pl.visual and n > 1 and O.strides[0] == 0 and \
            (not pl.sized or (pl.size_axes is not None and not isinstance(t_far, np.ndarray) and t_far < _INF)) and \
            not check_owner:
        return _floor_distances(pl, O, D, t_near, t_far, eps64)
    if native and pl.axis >= 0 and n > 1:
        lo = np.maximum(t_near, eps64) if isinstance(t_near, np.ndarray) else max(t_near, eps64)
        got = packets.plane1(pl, O, D, lo, t_far, excl, check_owner, distance_only)
        if got is not False:
            return got
    if pl.axis >= 0:   # one axis-aligned plane (a floor): D . n is one column times the normal's
        # non-zero component, the product's value whatever BLAS does (it adds exact zeros to that
        # one rounded product; see _floor_distances), without a BLAS call (OpenBLAS threads fight
        # the engine's block threads: ~10x slower on a busy 2-core machine)
        c = float(pl.nz[0, pl.axis])
        den = (D[:, pl.axis] if c == 1.0 else D[:, pl.axis] * c).reshape(n, 1)
    else:   # (n, P), each element summed in one fixed order, as plane_terms sums it (never BLAS: its
        # fused multiply-adds would make a ray's answer depend on the cast's shape)
        nz = pl.nz
        den = (D[:, 0:1] * nz[:, 0] + D[:, 1:2] * nz[:, 1]) + D[:, 2:3] * nz[:, 2]
    ok = den < 0.0 if pl.visual else den != 0.0
    if not np.count_nonzero(ok):  # e.g. horizontal rays over a floor
        return None
    lo = np.maximum(t_near, eps64)[:, None] if isinstance(t_near, np.ndarray) else max(t_near, eps64)
    hi = t_far[:, None] if isinstance(t_far, np.ndarray) else t_far
    Oo = O[:1] if O.strides[0] == 0 else O   # one origin: (1, P) offsets, the same values
    nz = pl.nz
    t = plane_terms(Oo, D, pl.pt.T, nz.T, pl.ax.T, pl.ay.T, pl.half.T, den, ok, lo, hi, pl.sized)
    if check_owner:
        ok &= pl.owner != (excl[:, None] if isinstance(excl, np.ndarray) else excl)
    if not np.count_nonzero(ok):
        return None
    np.copyto(t, _INF, where=~ok)
    if distance_only:   # the nearest plane's distance (argmin's pick, without the argmin)
        return (t.reshape(n) if P == 1 else t.min(axis=1)), None, None
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


def _floor_distances(pl: _Planes, O, D, t_near, t_far, eps64):
    """:func:`cast_planes` (distances only) for one axis-aligned visual plane (unbounded, or sized
    along world axes with a finite t_far) and rays sharing one origin (a lidar over a floor): the
    same numbers with a third of the work. The
    denominator ``D . n`` is one column times the normal's non-zero component (the matrix product
    adds exact zeros to that one rounded product, so it is the same value up to the sign of a zero,
    which only decides rays that miss either way). The numerator is one number: from above the
    front side, ``t > 0`` exactly when the ray goes down, so the range test alone picks the hits;
    from behind or on the plane no ray hits it."""
    Oo = O[:1]
    (px, py, pz), (ox, oy, oz), (nx, ny, nz_) = pl.pt[0].tolist(), Oo[0].tolist(), pl.nz[0].tolist()
    num = (px - ox) * nx + (py - oy) * ny + (pz - oz) * nz_   # the general pass's sum, in plain floats
    nz = pl.nz
    if not num < 0.0:
        return None
    k = pl.axis
    c = float(nz[0, k])
    lo = np.maximum(t_near, eps64) if isinstance(t_near, np.ndarray) else max(t_near, eps64)
    t = num / (D[:, k] if c == 1.0 else D[:, k] * c)
    bad = t < lo
    if np.count_nonzero(bad) == len(t):   # no ray reaches it (e.g. the upper layers)
        return None
    if isinstance(t_far, np.ndarray) or t_far < _INF:
        bad |= t > t_far
    if pl.sized:   # the hit within the size along the plane's x and y (unit world axes i, j): the
        # general test's x.ax sums exact zeros to the one product (finite: t <= t_far < inf)
        for j, h in zip(pl.size_axes, pl.half[0].tolist()):
            x = t * D[:, j]
            x -= float(pl.pt[0, j] - Oo[0, j])
            bad |= ~(np.abs(x) <= h)
    np.copyto(t, _INF, where=bad)
    return t, None, None

