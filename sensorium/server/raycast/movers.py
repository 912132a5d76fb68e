"""Moving bodies and the broad phase: which (ray, mover) pairs can meet.

A mover is cast against a body-frame tier shared by all movers with the same shapes; per cast,
the broad phase finds the (ray, mover) pairs whose segment passes within the mover's bounding
sphere (dense test for few movers or rays, else a uniform grid keyed by segment midpoints).
Rays rigidly mounted on movers (sensors on robots) pair bodies before rays (``_mounted_pairs``);
a :class:`Mount` keeps that pairing between casts as two lists with margins: the neighbouring
bodies (the reach of a body's rays from its centre is fixed by the mounting), and per neighbour
the rays that can reach it (decided in the body frame, where a mounted ray never moves), so per
cast only those rays are tested.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.exact import _DENSE_PAIRS, _INF, _TINY, _dot, _full, _mat, _minus, _take, _to_frame
from sensorium.server.world.arrays import unique_ints
from sensorium.server.world.geometry import Pose

_FEW = 8   # one-origin batches against up to this many movers: one matrix-vector test per mover
_TABLE = 1 << 18   # entries of a one-origin (rays, movers in view) table per block (2 MB of float64)


def _segment_near_sphere(rel_x, rel_y, rel_z, dx, dy, dz, t_lo, t_hi, r2):
    """Does the segment o + t d, t in [t_lo, t_hi] (unit d), pass within the sphere of squared
    radius r2 centred at o + rel?  Arguments broadcast.  The squared distance from the centre to
    the closest segment point is |rel|^2 - tc (2 b - tc) with b = rel.d and tc = b clamped to the
    segment; the slack covers its rounding (the test only has to be conservative)."""
    b = rel_x * dx + rel_y * dy + rel_z * dz
    e2 = rel_x * rel_x + rel_y * rel_y + rel_z * rel_z
    tc = np.minimum(np.maximum(b, t_lo), t_hi)
    return e2 - tc * (b + b - tc) <= r2 + 1e-12 * e2


def _sphere_pairs(C, r2, owner, O, D, t_near, lim, excl, among=None, cone: bool = True):
    """(ray, mover) index pairs whose segment [t_near, lim] passes within the mover's bounding
    sphere (centre C, squared radius r2) and whose owner is not excluded (``owner`` None: no
    check).  Small tables: one (rays, movers, 3) computation, pairs ordered by ray.  Large batches
    (a lidar): one mover at a time on contiguous columns, pairs ordered by mover (so the pairs of
    any one mover are always in ray order); ``among`` (ascending mover indices: a superset of those
    any ray can pass near, or those whose pairs the caller keeps) then skips the others' tests (the
    same pairs of those movers, the same arithmetic).
    ``cone`` False: rows of one origin given as a broadcast array take the test (and give the
    pairs) they would as a gathered copy of those rows, without the broadcast origin's cone test."""
    n, M = len(O), len(C)
    one = cone and O.strides[0] == 0 and n > 1   # one origin for all rays (a lidar): the per-mover path below
    if n * M <= _TINY and not one:  # a few rays and movers: plain floats (same test)
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
    if n * M <= _DENSE_PAIRS and not (one and M <= _FEW):
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
    shared = one or O.strides[0] == 0 or not np.count_nonzero(O != O[0])   # one origin: rel = C - o is per mover
    if not shared:
        ox, oy, oz, dx, dy, dz = (np.ascontiguousarray(a[:, k]) for a in (O, D) for k in range(3))
    prs, pms = [], []
    for j in (range(M) if among is None else among.tolist()):
        if owner is not None and not isinstance(excl, np.ndarray) and owner[j] == excl:
            continue
        r = None
        if shared:
            rel = C[j] - O[0]
            e2 = float(rel @ rel)
            if one and e2 > 2.0 * r2[j]:
                # one origin well outside the sphere: its rays that pass within it are those
                # within the sphere's cone, b >= sqrt(e2 - r2) (unit directions), whatever their
                # limits (a superset: a pair whose segment stops short traces to no hit); the
                # slack covers the rounding of b (so the C pass, summing b its own way, selects
                # the same rays that can hit)
                thr = math.sqrt(e2 - r2[j]) * (1.0 - 1e-9) - 1e-12 * math.sqrt(e2)
                r = packets.cone_rows(D, rel, thr)
                if r is None:
                    sel = D @ rel >= thr
            else:
                b = D @ rel                          # matrix-vector: fast at any size
                tc = np.minimum(np.maximum(b, t_near), lim)
                sel = e2 - tc * (b + b - tc) <= r2[j] + 1e-12 * e2
        else:
            sel = _segment_near_sphere(C[j, 0] - ox, C[j, 1] - oy, C[j, 2] - oz, dx, dy, dz, t_near, lim, r2[j])
        if r is not None:
            if owner is not None and isinstance(excl, np.ndarray):
                r = r[excl[r] != owner[j]]
        else:
            if owner is not None and isinstance(excl, np.ndarray):
                sel &= excl != owner[j]
            r = sel.nonzero()[0]
        prs.append(r)
        pms.append(np.full(len(r), j, dtype=np.int64))
    if not prs:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(prs), np.concatenate(pms)


def _grid_pairs(C, radius, r2, owner, O, D, t_near, lim, excl, origin=None):
    """Same contract as ``_sphere_pairs``, for many movers and many rays.  A segment no longer than
    ``L_cap`` looks up ONE cell of a uniform grid, the cell of its midpoint; each mover is
    registered in every cell overlapped by the box of its bounding sphere grown by L_cap / 2.  A
    segment passing within r of a mover has its midpoint within r + L / 2 of the centre, so the
    lookup finds every candidate; the exact sphere test then runs on the candidate pairs only.
    Longer segments (a lidar among short infra-red rays) take the dense test.

    Rays from one origin (a camera's pixels; O a broadcast array, or ``origin`` given) pair with
    the movers in their view only (``_origin_cull``): the same pairs, in the same order."""
    n, M = len(O), len(C)
    if origin is None and O.strides[0] == 0 and n:
        origin = O[0]
    if origin is not None and not _never_back(t_near):
        origin = None
    L = lim - t_near
    valid = L >= 0.0                         # a negative segment sees nothing
    fin = valid & (L < _INF)
    Lf = L[fin]
    if len(Lf) == 0:
        return _sphere_pairs(C, r2, owner, O, D, t_near, lim, excl, among=_among(C, radius, r2, origin, D, t_near, lim))
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
        return _sphere_pairs(C, r2, owner, O, D, t_near, lim, excl, among=_among(C, radius, r2, origin, D, t_near, lim))
    short_m = fin & (L <= L_cap)
    every = bool(short_m.all())
    short = None if every else short_m.nonzero()[0]
    Os, Ds, Ls = (O, D, L) if every else (O.take(short, axis=0), D.take(short, axis=0), L[short])
    # one origin (a camera's pixels): movers culled by the cone of the directions and their reach,
    # then a table of rays x movers in view (the pairs the grid lookup would keep, in its order);
    # the grid registers every mover and pairs a ray with all movers of a cell as long as a segment
    cull = (_origin_cull(C, radius, r2, origin, Ds, float((lim if every else lim[short]).max()))
            if origin is not None and len(Ds) else None)
    if cull is not None:
        pr, pm = _origin_candidates(r2, Ds, cull)
        if not every:
            pr = short[pr]
    else:
        pr, pm = _cell_candidates(C, reach, g0, span, cell, Os, Ds, Ls, t_near if short is None else _take(t_near, short),
                                  n, short)
    # exact sphere test on the candidates
    rel = C.take(pm, axis=0) - O.take(pr, axis=0)
    Dp = D.take(pr, axis=0)
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
            Dl = D.take(longs, axis=0)
            cull = _origin_cull(C, radius, r2, origin, Dl, float(lim[longs].max())) if origin is not None else None
            lp, lm = _sphere_pairs(C, r2, owner, O.take(longs, axis=0), Dl, _take(t_near, longs), lim[longs],
                                   _take(excl, longs), among=None if cull is None else cull[0])
            pr = np.concatenate([pr, longs[lp]])
            pm = np.concatenate([pm, lm])
            order = np.argsort(pr, kind="stable")   # back in ray order (callers rely on it per mover)
            pr, pm = pr[order], pm[order]
    return pr, pm


def _never_back(t_near) -> bool:
    """No segment starts behind its origin (t_near >= 0 for every ray): a segment passing near a
    sphere whose centre lies well away from the origin then points towards it."""
    return bool(t_near >= 0.0) if not isinstance(t_near, np.ndarray) else bool(len(t_near) == 0 or t_near.min() >= 0.0)


def _among(C, radius, r2, origin, D, t_near, lim):
    """The movers rays from one ``origin`` (None: not known) can pass near whatever their
    segments' lengths (``_origin_cull`` by direction only: ``_sphere_pairs``' one-origin test lists
    the rays of a mover's cone however far it is), for ``_sphere_pairs``' per-mover test; None when
    not known or when some segment ends behind the origin (its test point would lie behind it)."""
    if origin is None or not len(D) or not bool(lim.min() >= 0.0) or not _never_back(t_near):
        return None
    cull = _origin_cull(C, radius, r2, origin, D, _INF)
    return None if cull is None else cull[0]


def _origin_cull(C, radius, r2, o, D, lim_max: float):
    """For rays from one origin ``o`` (a camera's pixels) whose segments start at t_near >= 0 and end
    at or before ``lim_max``: (the movers any of them can pass near, ascending; which of those have
    the origin in or near their sphere), or None when the directions span a hemisphere or more.
    A superset, with generous slack (1e-3 rad, 1e-6 relative): a segment passing within r of a
    centre at distance d > r lies within angle asin(r/d) of the direction to it, hence within
    th + asin(r/d) of the axis of the directions' cone (half-angle th), and reaches d - r."""
    a = D.sum(axis=0)
    na = math.sqrt(float(a @ a))
    if not na > 0.0:
        return None
    a /= na
    cmin = float((D @ a).min())
    if not cmin > 0.0:      # wider than a hemisphere: no cull to speak of
        return None
    th = math.acos(min(1.0, cmin))
    rel = C - o
    e2 = _dot(rel, rel)
    d = np.sqrt(e2)
    near = e2 <= 2.0 * r2                    # the origin in or near the sphere: every ray a candidate
    with np.errstate(divide="ignore", invalid="ignore"):
        ca = np.clip((rel @ a) / d, -1.0, 1.0)
        half = np.arcsin(np.minimum(1.0, radius / d))
    keep = near | ((np.arccos(ca) <= th + half + 1e-3) & (d - radius <= lim_max * (1.0 + 1e-6) + 1e-9 * (d + 1.0)))
    K = keep.nonzero()[0]
    return K, near[K], rel[K], e2[K]


def _origin_candidates(r2, D, cull):
    """Candidate (ray, mover) pairs of rays from one origin among the culled movers (``_origin_cull``):
    one (rays, movers) table of D . rel against each mover's cone threshold (``_sphere_pairs``' test
    for a lidar, whose slack covers the rounding of D . rel); a superset of the pairs passing the
    segment/sphere test, ordered by ray, then mover (the grid lookup's order)."""
    K, near, rel, e2 = cull
    if len(K) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    thr = np.where(near, -_INF, np.sqrt(np.maximum(e2 - r2[K], 0.0)) * (1.0 - 1e-9) - 1e-12 * np.sqrt(e2))
    relT = np.ascontiguousarray(rel.T)
    rows = max(1, _TABLE // len(K))          # the table in row blocks: a few MB whatever the image and swarm
    if rows >= len(D):
        ri, ki = (_mat(D, relT) >= thr).nonzero()   # row-major: by ray, then mover
        return ri, K[ki]
    ris, kis = [], []
    for a in range(0, len(D), rows):
        r, k = (_mat(D[a:a + rows], relT) >= thr).nonzero()
        ris.append(r + a)
        kis.append(k)
    return np.concatenate(ris), K[np.concatenate(kis)]


def _cell_candidates(C, reach, g0, span: float, cell: float, Os, Ds, Ls, tn, n: int, short):
    """The grid lookup of ``_grid_pairs``: every mover registered in the cells its grown sphere
    overlaps, each short segment looking up the cell of its midpoint; candidate pairs by ray, then
    mover."""
    M = len(C)
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
    mid = Os + (tn + 0.5 * Ls)[:, None] * Ds
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
    pr = np.repeat(np.arange(len(key)) if short is None else short, c2)
    pm = smov[np.repeat(start - (np.cumsum(c2) - c2), c2) + np.arange(len(pr))]
    return pr, pm



@dataclass(slots=True)
class _Body:
    shapes: list[int]          # global shape ids: first .. first + len - 1
    pose: Pose
    owner: int
    mover: bool
    index: int
    tiers: dict = field(default_factory=dict)  # variant -> shared body-frame _Tier (movers only)
    removed: bool = False      # taken out of every query (RayEngine.remove_body)
    baked: Pose | None = None  # a body added static: the pose its shapes are baked in the static tier at

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
    row_of: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # body -> row, -1: none


def _mounted_pairs(mt: _Movers, C: np.ndarray, owner, O, D, t_near, lim: np.ndarray, excl, mrow: np.ndarray):
    """Broad phase of rays rigidly mounted on movers (``mrow``: each ray's mount row, -1 for none):
    (ray, mover) pairs of the mounted rays, never with their own mount, and the indices of the
    other rays (unmounted, or unbounded: for the general broad phase); None when no ray is mounted.  Every point of a
    mounted ray's segment lies within |o - c| + max(lim, -t_near) of its mount's centre c (unit
    directions); a body's reach is the largest over its rays.  Bodies are paired with the movers
    their reach can touch (a sweep over sorted centres), each ray inherits its body's neighbours,
    and the segment/sphere test runs on those candidates: no per-ray grid, and the rays of a body
    with no neighbour cost nothing."""
    mounted = mrow >= 0
    mi = mounted.nonzero()[0]
    if len(mi) == 0:
        return None
    rows = mrow[mi]
    rel = O.take(mi, axis=0) - C.take(rows, axis=0)
    reach = np.sqrt(_dot(rel, rel)) + np.maximum(lim[mi], -_take(t_near, mi))
    bounded = reach < _INF
    if not bounded.all():                   # unbounded rays: the general broad phase
        mounted[mi[~bounded]] = False
        mi, rows, reach = mi[bounded], rows[bounded], reach[bounded]
    M = len(C)
    R = np.full(M, -1.0)                    # -1: no mounted ray on this mover
    np.maximum.at(R, rows, reach)
    used = (R >= 0.0).nonzero()[0]
    pb, pm = _near_centres(C.take(used, axis=0), R[used], C, mt.radius)
    nb = (pm != used[pb]).nonzero()[0]      # CSR of each mover's neighbours (pb is sorted)
    src, dst = used[pb[nb]], pm[nb]
    if (len(used) == 1 and O.strides[0] == 0 and len(dst) > _FEW and _never_back(t_near)
            and bool(lim[mi].min() >= 0.0)):
        # one origin on one body (a camera with shapes of its own): of the body's neighbours (in
        # their order), those in view of its rays, and per ray those whose cone holds it
        cull = _origin_cull(C.take(dst, axis=0), mt.radius[dst], mt.r2[dst], O[0], D.take(mi, axis=0),
                            float(lim[mi].max()))
        if cull is not None:
            ri, pm = _origin_candidates(mt.r2[dst], D.take(mi, axis=0), cull)
            pr, pm = _near_pairs(C, O, D, t_near, lim, excl, owner, mt.r2, mi[ri], dst[pm])
            return pr, pm, (~mounted).nonzero()[0]
    cnt = np.bincount(src, minlength=M)
    ptr = np.cumsum(cnt) - cnt
    c = cnt[rows]
    pr = np.repeat(mi, c)
    pm = dst[np.repeat(ptr[rows] - (np.cumsum(c) - c), c) + np.arange(len(pr))]
    pr, pm = _near_pairs(C, O, D, t_near, lim, excl, owner, mt.r2, pr, pm)
    rest = (~mounted).nonzero()[0]
    return pr, pm, rest


def _near_pairs(C, O, D, t_near, lim, excl, owner, r2, pr, pm):
    """Those of the candidate (ray, mover) pairs ``pr``, ``pm`` whose segment passes within the
    mover's bounding sphere (centres C, squared radii r2) and whose owner is not excluded (``owner``
    None: no check)."""
    if len(pr) == 0:
        return pr, pm
    Cp = C.take(pm, axis=0)
    Op = O.take(pr, axis=0)
    Dp = D.take(pr, axis=0)
    sel = _segment_near_sphere(Cp[:, 0] - Op[:, 0], Cp[:, 1] - Op[:, 1], Cp[:, 2] - Op[:, 2],
                               Dp[:, 0], Dp[:, 1], Dp[:, 2], _take(t_near, pr), lim[pr], r2[pm])
    if owner is not None:
        sel &= owner[pm] != _take(excl, pr)
    keep = sel.nonzero()[0]
    return pr[keep], pm[keep]


def _near_centres(Cu: np.ndarray, Ru: np.ndarray, C: np.ndarray, radius: np.ndarray):
    """(i, j) pairs with |Cu[i] - C[j]| <= Ru[i] + radius[j] (with a relative slack of 1e-9): a
    sweep along the axis of largest spread (sorted centres, two binary searches), then the exact
    test on the candidates; linear in the number of bodies when they are spread out.  Pairs
    ordered by i."""
    k = int(np.argmax(C.max(0) - C.min(0)))
    order = np.argsort(C[:, k], kind="stable")
    xs = C[order, k]
    w = (Ru + float(radius.max())) * (1.0 + 1e-9) + 1e-12 * float(np.abs(xs).max())   # rounding slack
    lo = np.searchsorted(xs, Cu[:, k] - w, "left")
    hi = np.searchsorted(xs, Cu[:, k] + w, "right")
    cnt = hi - lo
    pb = np.repeat(np.arange(len(Cu)), cnt)
    pm = order[np.repeat(lo - (np.cumsum(cnt) - cnt), cnt) + np.arange(len(pb))]
    d = C.take(pm, axis=0) - Cu.take(pb, axis=0)
    gap = Ru[pb] + radius[pm]
    ok = (_dot(d, d) <= gap * gap * (1.0 + 1e-9) + 1e-18).nonzero()[0]
    return pb[ok], pm[ok]


class Mount:
    """Rays rigidly mounted on bodies, cast again and again (a robot's distance sensors, step after
    step): ``bodies[i]`` is the body ray i rides (-1: none).  Array-like (``np.asarray(mount)`` is
    ``bodies``, so it concatenates like a plain mount array).  Passing the same Mount to every cast
    of the same rays lets the engine keep what rigid mounting leaves unchanged: which mover each ray
    rides, how far each body's rays reach from its centre (the same at every pose), which movers
    are near enough to matter (a neighbour list kept until some mover has moved by more than a
    margin) and which of a body's rays can reach each neighbour (kept until the neighbour has moved
    by more than a margin in the body's frame).  Per cast only the segment test of the listed
    (ray, mover) candidates remains; rays of bodies with no neighbour cost nothing.  The caller
    promises that the rays are those of the first cast (same mounts, local origins and unit
    directions), moved with their bodies.

    ``own``: rays (True for all, or a per-ray mask) that also see their own mount body (a lidar sees
    its robot; a distance sensor's own-body hits are decided by the caller instead, see
    :meth:`RayEngine.cast`): which of them can reach it is decided once, in the body frame, and
    only those are tested against it per cast, with the same arithmetic as rays that are not
    mounted (the same bits)."""

    __slots__ = ("bodies", "lo", "hi", "own", "_state")

    def __init__(self, bodies, own=False) -> None:
        self.bodies = np.array(bodies, dtype=np.int64).reshape(-1)
        self.bodies.setflags(write=False)
        self.lo, self.hi = (int(self.bodies.min()), int(self.bodies.max())) if len(self.bodies) else (-1, -1)
        mask = np.broadcast_to(np.asarray(own, dtype=bool), self.bodies.shape)
        self.own: np.ndarray | None = np.array(mask) if mask.any() else None
        self._state: _MountState | None = None

    def __len__(self) -> int:
        return len(self.bodies)

    def __array__(self, dtype=None, copy=None):
        return self.bodies if dtype is None else self.bodies.astype(dtype)


class Riding:
    """Rays from one origin rigidly mounted on one moving body but cast unmounted, so they meet that
    body as any ray does (a camera without shapes of its own on its robot): ``origin`` and
    ``directions`` in the body frame, the limits the casts use. Which rays can meet the body is
    decided once, in the body frame, by its tier's bound grown by ``GROW`` (far beyond the rounding
    of the rays' world round trip); each cast pairs only those with the body (its broad phase and
    bound test run on them alone, or its bound test only from inside the body's bounding sphere,
    where every ray is paired: the rays it then traces are those every ray's tests keep, traced as
    before, the same bits; RayEngine.cast)."""

    __slots__ = ("body", "origin", "directions", "t_near", "t_far", "reach", "_rows")

    GROW = 1e-6

    def __init__(self, body: int, origin: np.ndarray, directions: np.ndarray, t_near, t_far) -> None:
        self.body = int(body)
        self.origin = np.asarray(origin, dtype=np.float64).reshape(3)
        self.directions = np.ascontiguousarray(directions, dtype=np.float64).reshape(-1, 3)
        self.t_near, self.t_far = t_near, t_far
        # how far from the origin the rays start (t_near times the longest direction)
        longest = float(np.sqrt((self.directions * self.directions).sum(axis=1).max())) if len(self.directions) else 0.0
        self.reach = (float(np.max(t_near)) if np.size(t_near) else 0.0) * max(longest, 1.0)
        self._rows: tuple[object, np.ndarray] | None = None

    def __len__(self) -> int:
        return len(self.directions)

    def rows(self, tier) -> np.ndarray:
        """The rays (ascending) that may meet ``tier`` (the body's, in its frame), kept per tier."""
        if self._rows is None or self._rows[0] is not tier:
            n = len(self.directions)
            O = np.ndarray((n, 3), np.float64, self.origin, 0, (0, 8))
            lo = np.broadcast_to(np.asarray(self.t_near, dtype=np.float64), (n,))
            hi = np.broadcast_to(np.asarray(self.t_far, dtype=np.float64), (n,))
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                may = tier.may_hit(O, self.directions, lo, hi, grow=self.GROW)
            self._rows = (tier, may.nonzero()[0])
        return self._rows[1]


_SKIN = 0.25          # neighbour-list margin, as a fraction of the median reach of the bodies' rays


@dataclass(slots=True)
class _MountState:
    """What a :class:`Mount` keeps for one mover table (see there)."""
    mt: _Movers
    limits: tuple | None  # (t_near, t_far) when both were scalars
    span: np.ndarray      # per mounted ray: how far its segment reaches from its origin (then)
    mrow: np.ndarray      # per ray: its mover row, -1 none
    mi: np.ndarray        # the mounted rays
    rows: np.ndarray      # their mover rows
    rest: np.ndarray      # the other rays
    used: np.ndarray      # mover rows carrying mounted rays
    reach: np.ndarray     # per used row: no point of its rays' segments is farther from its centre
    skin: float
    shift: float          # neighbour list valid while no centre moved more than this per axis
    reach_row: np.ndarray = field(default_factory=lambda: np.zeros(0))   # reach by mover row (0: none)
    C_ref: np.ndarray | None = None   # centres when the body list was made
    epoch: int = -1       # engine pose epoch of the last check
    src: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # body list: (b, j) rows
    dst: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    skin_r: float = 0.0   # margin of the ray list (length), checked per axis against skin_r / sqrt(3)
    shift_r: float = 0.0
    c_ref: np.ndarray | None = None   # j's centre in b's frame, per listed pair, when the ray list was made
    o_loc: np.ndarray | None = None   # mounted rays in their bodies' frames (origin about the centre)
    d_loc: np.ndarray | None = None
    by_body: np.ndarray | None = None  # mounted rays (indices into mi) by body row, and CSR of it
    body_cnt: np.ndarray | None = None
    body_ptr: np.ndarray | None = None
    pr: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # candidates: rays
    pm: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # and movers
    own_pr: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # rays that can reach
    own_pm: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))   # their own mount
    merged: tuple = ()    # (pr, pm, candidates with the own pairs) of the last merge
    own_ahead: bool | None = None   # own pairs tested for t >= 0 only (kept while t_near >= 0)
    own_hits: tuple | None = None   # FAST distances of the own pairs, traced once (RayEngine._own_hits)


def mount_state(mount: Mount, mt: _Movers, C: np.ndarray, O: np.ndarray, t_near, t_far, D: np.ndarray | None = None,
                rot: np.ndarray | None = None) -> _MountState | None:
    """The Mount's state for this mover table (made on first use, with the rays' current world
    origins; ``D`` and the engine's body rotations ``rot`` are needed when some rays see their own
    mount), or None when a mounted ray is unbounded (the caller then takes the per-cast path).
    The state is kept while every mounted ray's segment is no longer than when it was made (its
    reaches still bound every segment; other limits, e.g. light rays cast in the same batch, do not
    matter)."""
    st = mount._state
    if st is not None and st.mt is mt:
        if (st.limits is not None and not isinstance(t_near, np.ndarray) and not isinstance(t_far, np.ndarray)
                and st.limits == (t_near, t_far)):   # scalars, as when made
            return st
        if np.all(np.maximum(_take(t_far, st.mi), -_take(t_near, st.mi)) <= st.span) and \
                (not st.own_ahead or np.all(_take(t_near, st.mi) >= 0.0)):
            return st
    mrow = mt.row_of[mount.bodies]
    mounted = mrow >= 0
    mi = mounted.nonzero()[0]
    rows = mrow[mi]
    span = np.maximum(_full(t_far, len(mi)) if not isinstance(t_far, np.ndarray) else t_far[mi],
                      -_take(t_near, mi))
    if not np.all(span < _INF):
        return None
    rel = O.take(mi, axis=0) - C.take(rows, axis=0)
    reach = np.full(len(C), -1.0)
    np.maximum.at(reach, rows, np.sqrt(_dot(rel, rel)) + span)
    used = (reach >= 0.0).nonzero()[0]
    reach = reach[used]
    # |o - c| is the same at every pose up to rounding (a few ulps of the coordinates): the slack
    # covers it (and the rebuild adds 1e-12 of the coordinates then)
    reach = reach * (1.0 + 1e-9) + 1e-12 * (float(np.abs(O).max()) + float(np.abs(C).max()) if len(mi) else 0.0)
    skin = _SKIN * float(np.median(reach)) if len(used) else 0.0
    scalar = not isinstance(t_near, np.ndarray) and not isinstance(t_far, np.ndarray)
    st = _MountState(mt, (t_near, t_far) if scalar else None, span, mrow, mi, rows, (~mounted).nonzero()[0], used,
                     reach, skin, 0.5 * skin / 1.7320508075688772 * (1.0 - 1e-6))
    st.reach_row = np.zeros(len(C))
    st.reach_row[used] = reach
    st.skin_r = 2.0 * skin
    st.shift_r = st.skin_r / 1.7320508075688772 * (1.0 - 1e-6)
    if mount.own is not None and D is not None and rot is not None:
        # segments that start at or beyond their origin (t_near >= 0: a lidar) are tested ahead of
        # it only, and the list is kept only while they do
        st.own_ahead = bool(np.all(_take(t_near, mi) >= 0.0)) if len(mi) else False
        _own_pairs(st, mount.own, mt, O, D, rot, span, st.own_ahead)
    mount._state = st
    return st


def _own_pairs(st: _MountState, own: np.ndarray, mt: _Movers, O: np.ndarray, D: np.ndarray, rot: np.ndarray,
               span: np.ndarray, ahead: bool) -> None:
    """The (ray, own mount) pairs of the mounted rays that see their own body and whose segment can
    reach its tier's tight bound: tested in the body frame, where a rigidly mounted ray never moves
    (its coordinates change only by rounding there, far below the bound's slack, which is grown
    further by the rounding of the world coordinates), for t in [0, span] (``ahead``), else
    [-span, span]."""
    sel = own[st.mi].nonzero()[0]
    if len(sel) == 0:
        return
    rays, rows = st.mi[sel], st.rows[sel]
    grow = 1e-9 + 1e-12 * (float(np.abs(O[:1] if O.strides[0] == 0 else O).max()) + float(np.abs(mt.T).max()))
    prs, pms = [], []
    for row in unique_ints(rows).tolist():
        k = (rows == row).nonzero()[0]
        r = rays[k]
        Rb, Tb = rot[mt.index[row]], mt.T[row]
        Ob = _to_frame(_minus(O.take(r, axis=0), Tb), Rb)
        Db = _to_frame(D.take(r, axis=0), Rb)
        sp = span[sel[k]]
        reach = mt.tiers[mt.group[row]].may_hit(Ob, Db, 0.0 if ahead else -sp, sp, grow).nonzero()[0]
        prs.append(r[reach])
        pms.append(np.full(len(reach), row, dtype=np.int64))
    pr, pm = np.concatenate(prs), np.concatenate(pms)
    order = np.argsort(pr, kind="stable")
    st.own_pr, st.own_pm = pr[order], pm[order]


def one_origin_pairs(st: _MountState, mt: _Movers, C: np.ndarray, O: np.ndarray, D: np.ndarray, t_near, lim,
                     excl, owner, epoch: int, counters: dict[str, int], own: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(ray, mover) candidates of a batch from one origin mounted on one body (a lidar): its
    own-mount pairs (decided once) and, per neighbouring mover of the body list (kept as for any
    Mount), the rays whose segment passes within that mover's bounding sphere, tested for all rays
    with one matrix-vector product per neighbour. No ray lists: a lidar's beams fan out in every
    direction, so a list would hold most of them and cost more to keep than this test. ``own``
    False: without the own-mount pairs (the caller has their hits already)."""
    if st.epoch != epoch:
        st.epoch = epoch
        if st.C_ref is None or len(C) != len(st.C_ref) or float(np.abs(C - st.C_ref).max()) > st.shift:
            _body_list(st, mt, C, counters)
    nb = st.dst
    if len(nb):
        Cn = C.take(nb, axis=0)
        # a camera's pixels (directions within a cone): the neighbours out of its view are skipped
        among = _among(Cn, mt.radius[nb], mt.r2[nb], O[0], D, t_near, lim) if len(nb) > _FEW else None
        pr, pm = _sphere_pairs(Cn, mt.r2[nb], None if owner is None else owner[nb], O, D, t_near, lim, excl,
                               among=among)
        pm = nb[pm]
    else:
        pr = pm = np.zeros(0, dtype=np.int64)
    if own and len(st.own_pr):   # pairs of one mover stay in ray order; groups of movers in any order
        pr, pm = np.concatenate([st.own_pr, pr]), np.concatenate([st.own_pm, pm])
    return pr, pm


def with_own_pairs(st: _MountState, pr: np.ndarray, pm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The candidates ``pr``, ``pm`` (ray order) with the own-mount pairs merged in, in ray order
    (then mover row); kept while the candidates are the same arrays."""
    if not len(st.own_pr):
        return pr, pm
    if st.merged and st.merged[0] is pr and st.merged[1] is pm:
        return st.merged[2], st.merged[3]
    r, m = np.concatenate([pr, st.own_pr]), np.concatenate([pm, st.own_pm])
    order = np.lexsort((m, r))
    st.merged = (pr, pm, r[order], m[order])
    return st.merged[2], st.merged[3]


def mount_candidates(st: _MountState, mt: _Movers, C: np.ndarray, rot: np.ndarray, O: np.ndarray, D: np.ndarray,
                     epoch: int, counters: dict[str, int]) -> tuple[np.ndarray, np.ndarray]:
    """(ray, mover) candidates of the mounted rays at the movers' current centres C (``rot``: the
    engine's body rotations; O, D: this cast's rays): every pair whose segment can come within the
    mover's bounding sphere, never the ray's own mount, in ray order (then mover row).

    Two lists, both kept between casts.  Bodies: the pairs (b, j) whose centres are within b's reach
    plus j's radius, grown by the skin; kept while no centre has moved by more than half the skin
    (|shift| per axis, so <= skin / 2 in length): an unlisted pair then still cannot meet.  Rays:
    per listed pair, the rays of b whose segment (in b's frame, where it never moves) passes within
    j's radius grown by ``skin_r`` of j's centre in b's frame; kept while no such centre has moved by
    more than ``skin_r`` in its b's frame (turning b moves it too).  Each new list counts in
    ``counters["neighbour_lists"]`` (bodies) or ``counters["ray_lists"]`` (rays)."""
    if st.epoch == epoch:
        return st.pr, st.pm
    st.epoch = epoch
    if st.C_ref is None or len(C) != len(st.C_ref) or float(np.abs(C - st.C_ref).max()) > st.shift:
        _body_list(st, mt, C, counters)
    if len(st.src) == 0:
        return st.pr, st.pm
    # neighbour centres in the frames of the bodies whose rays may reach them
    Rb = rot.take(mt.index[st.src], axis=0)
    rel = C.take(st.dst, axis=0) - C.take(st.src, axis=0)
    cb = np.einsum("pji,pj->pi", Rb, rel)
    if st.c_ref is None or float(np.abs(cb - st.c_ref).max()) > st.shift_r:
        _ray_list(st, mt, C, cb, rot, O, D, counters)
    return st.pr, st.pm


def _body_list(st: _MountState, mt: _Movers, C: np.ndarray, counters: dict[str, int]) -> None:
    """A new body list (see mount_candidates); the ray list is then redone too."""
    st.C_ref = C.copy()
    st.c_ref = None
    counters["neighbour_lists"] += 1
    st.src = st.dst = st.pr = st.pm = np.zeros(0, dtype=np.int64)
    if len(st.used) == 0:
        return
    # grown by the skin, and by a slack that keeps the list a superset of what the per-cast body
    # test (_mounted_pairs) would pair, whatever the rounding
    Ru = st.reach * (1.0 + 1e-8) + (st.skin + 1e-8 * float(mt.radius.max()) + 1e-9 + 1e-12 * float(np.abs(C).max()))
    pb, pm = _near_centres(C.take(st.used, axis=0), Ru, C, mt.radius)
    nb = (pm != st.used[pb]).nonzero()[0]
    src, dst = st.used[pb[nb]], pm[nb]
    order = np.lexsort((dst, src))
    st.src, st.dst = src[order], dst[order]


def _ray_list(st: _MountState, mt: _Movers, C: np.ndarray, cb: np.ndarray, rot: np.ndarray, O: np.ndarray,
              D: np.ndarray, counters: dict[str, int]) -> None:
    """A new ray list for the listed body pairs (``cb``: each neighbour's centre in its body's frame)."""
    counters["ray_lists"] += 1
    st.c_ref = cb
    if st.o_loc is None:   # the mounted rays in their bodies' frames, about the centres (rigid: fixed)
        Rr = rot.take(mt.index[st.rows], axis=0)
        st.o_loc = np.einsum("nji,nj->ni", Rr, O.take(st.mi, axis=0) - C.take(st.rows, axis=0))
        st.d_loc = np.einsum("nji,nj->ni", Rr, D.take(st.mi, axis=0))
        by_body = np.argsort(st.rows, kind="stable")
        cnt = np.bincount(st.rows, minlength=len(C))
        st.by_body, st.body_cnt, st.body_ptr = by_body, cnt, np.cumsum(cnt) - cnt
    c = st.body_cnt[st.src]
    pp = np.repeat(np.arange(len(st.src)), c)
    kk = st.by_body[np.repeat(st.body_ptr[st.src] - (np.cumsum(c) - c), c) + np.arange(len(pp))]
    # the segment test in the body frame, for t in [-span, span] (covers [t_near, lim] while the
    # state holds), radius grown by the skin and by slacks for rounding and for the per-cast test's
    # own slack (1e-12 of |o - c|^2)
    j = st.dst[pp]
    rad = mt.radius[j] + (st.skin_r + 1e-9 + 1e-12 * float(np.abs(C).max())) + 1e-6 * (st.reach_row[st.src[pp]] + mt.radius[j])
    o, d, sp = st.o_loc[kk], st.d_loc[kk], st.span[kk]
    near = _segment_near_sphere(cb[pp, 0] - o[:, 0], cb[pp, 1] - o[:, 1], cb[pp, 2] - o[:, 2],
                                d[:, 0], d[:, 1], d[:, 2], -sp, sp, rad * rad)
    keep = near.nonzero()[0]
    pr, pm = st.mi[kk[keep]], j[keep]
    order = np.lexsort((pm, pr))
    st.pr, st.pm = pr[order], pm[order]
