"""Float64 refinement around Embree hits: triangle re-tests (hit triangle and its vertex ring,
or triangles near the hit point), true-surface hits of curved shapes, and the pre-pass for rays
starting inside a curved shell.  A mixin of :class:`RayEngine` (via :class:`.trace.TierTracer`)."""

from __future__ import annotations

import math
import threading

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.exact import (
    _BARY_TOL,
    _CAPSULE,
    _CONE,
    _CYLINDER,
    _DENSE_PAIRS,
    _F32,
    _INF,
    _MAX_LOOPS,
    _MIXED,
    _SCALAR,
    _SPHERE,
    _TINY,
    _analytic_local,
    _analytic_mixed,
    _analytic_one,
    _best_per_row,
    _dot,
    _from_frame,
    _full,
    _minus,
    _moller_trumbore,
    _strictly_increasing,
    _take,
    _to_frame,
)
from sensorium.server.raycast.guards import PRISM_TRIANGLES
from sensorium.server.raycast.tiers import _Tier


class Refiner:
    """Refinement methods of :class:`~sensorium.server.raycast.engine.RayEngine`."""

    counters: dict[str, int]
    _counting: threading.Lock

    def _count(self, key: str, n: int) -> None:
        """counters[key] += n (blocks of a cast may run on several threads)."""
        with self._counting:
            self.counters[key] += n

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
            ray, cand = tier.ring.rows(tri[bad])
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

    def _guard_rays(self, tier: _Tier, res, g, act, Ot, D, o32, d32, sa, far, lo, lim, excl, best_t, best_s, best_n):
        """The second look of EXACT (see :mod:`.guards`) for the rays ``g`` (rows of this pass's Embree
        results ``res``; ray ``act[g]``, segment from ``sa`` (float32 start ``o32``), float64 ``far``) whose first hit was a
        guard: (1) their hit in the scene without guards (it replaces theirs in ``res``, so that the
        pass goes on as if the guards were not there); (2) a float64 test of the guarded edge's
        triangles, and the same for every further guard met up to a little past that hit (steps of
        w/2 past each surface or guard: they cannot jump over a prism that a ray within w/2 of its
        edge crosses, and prisms closer together than that share their candidates)."""
        rows = act[g]
        fg = far[g]
        s = res["tfar"][g].astype(np.float64)   # the first guard, from the segment start
        d32g = d32[g]
        self._count("embree_calls", 1)
        r0 = tier.bare_scene().run(o32[g], d32g, np.where(fg >= 0.0, fg, -1.0).astype(_F32), output=1)
        w = 4.0 * tier.eps
        stop = np.minimum(fg, np.where(r0["primID"] >= 0, r0["tfar"].astype(np.float64) + 4.0 * w, _INF))
        self._guard_hits(tier, Ot, D, rows, res["primID"][g], lo, lim, excl, best_t, best_s, best_n)
        for k in ("primID", "tfar", "u", "v", "Ng", "geomID"):
            res[k][g] = r0[k]
        scene = tier.scene(True)[0]
        sub = np.arange(len(g))
        for _ in range(_MAX_LOOPS):
            s = s + 0.5 * w
            f = stop[sub] - s
            keep = (f >= 0.0).nonzero()[0]
            sub, s, f = sub[keep], s[keep], f[keep]
            if not len(sub):
                return
            r = rows[sub]
            o = (Ot[r] + (sa[g[sub]] + s)[:, None] * D[r]).astype(_F32)
            self._count("embree_calls", 1)
            r1 = scene.run(o, d32g[sub], f.astype(_F32), output=1)
            met = (r1["primID"] >= 0).nonzero()[0]
            sub, s = sub[met], s[met] + r1["tfar"][met]
            more = (r1["geomID"][met] == 1).nonzero()[0]
            if len(more):
                self._guard_hits(tier, Ot, D, rows[sub[more]], r1["primID"][met[more]], lo, lim, excl,
                                 best_t, best_s, best_n)
        self._count("unresolved_rays", len(sub))

    def _guard_hits(self, tier: _Tier, Ot, D, rows, gprim, lo, hi, excl, best_t, best_s, best_n):
        """The second look of EXACT (see :mod:`.guards`): rays ``rows`` met the guards (prism triangles
        ``gprim``) of risky edges; test them in float64 on the flat triangles of those edges, and
        where one is hit with lo <= t <= hi nearer than ``best_t``, take it (``best_*``, ``hi`` are
        updated in place; arrays indexed by ray)."""
        _, ptr, idx = tier.guard[:3]
        edge = gprim.astype(np.int64) // PRISM_TRIANGLES
        starts = ptr[edge]
        counts = ptr[edge + 1] - starts
        ray = rows[np.repeat(np.arange(len(rows)), counts)]
        cand = idx[np.repeat(starts - (np.cumsum(counts) - counts), counts) + np.arange(int(counts.sum()))]
        if excl is not None:
            keep = tier.tri_owner[cand] != excl[ray]
            ray, cand = ray[keep], cand[keep]
        ok, t = _moller_trumbore(Ot[ray], D[ray], tier.v0[cand], tier.e1[cand], tier.e2[cand])
        ok &= (t >= lo[ray]) & (t <= hi[ray]) & (t < best_t[ray])
        ray, t, cand = ray[ok], t[ok], cand[ok]
        if not len(ray):
            return
        if len(ray) > 1 and not _strictly_increasing(ray):
            keep = _best_per_row(ray, t)
            ray, t, cand = ray[keep], t[keep], cand[keep]
        nrm = tier.normal[cand]
        nrm[_dot(nrm, D[ray]) > 0.0] *= -1.0
        best_t[ray], best_s[ray], best_n[ray] = t, tier.tri_shape[cand], nrm
        hi[ray] = t
        self._count("edge_guard_hits", len(ray))

    def _flat_dense(self, tier: _Tier, res, prim, Ot, D, one_origin: bool, lo, lim, t_e, d_max: float,
                    best_t, best_s, best_n, distance_only: bool):
        """EXACT's judging of flat hits (see :meth:`.trace.TierTracer._trace_loop`) in a pass where every ray is active
        and most hit a flat triangle (a lidar in a room): on whole arrays, misses and curved hits
        masked, instead of gathering the hit rows; the same values.  Updates ``best_*``; returns
        the mask of rays to continue (refinement missed)."""
        eps = tier.eps
        flat = tier.tri_flat.take(prim)            # primID -1 picks the sentinel row: False
        nx, ny, nz = (c.take(prim) for c in tier.normal_cols)   # ... and a zero normal
        dn = D[:, 0] * nx + D[:, 1] * ny              # = _dot(D, normal[prim]), column by column
        dn += D[:, 2] * nz
        fi = tier.flat_index
        if one_origin and len(fi) < len(prim):   # n.(v0 - o) per flat triangle, then per ray (same values)
            c = np.zeros(len(tier.normal))
            c[fi] = _dot(_minus(tier.v0[fi], Ot[0]), tier.normal[fi])
            tx = c.take(prim) / dn
        else:
            V0 = tier.v0.take(prim, axis=0, mode="clip")
            tx = _dot(_minus(V0, Ot[0]) if one_origin else V0 - Ot, tier.normal.take(prim, axis=0)) / dn
        ok = np.isfinite(tx) & (tx >= lo) & (tx <= lim) & flat
        u, v = res["u"], res["v"]
        margin = np.minimum(np.minimum(u, v), 1.0 - u - v)
        near_edge = ~(margin > 1e-4) & flat
        check = ~(margin * tier.h_min.take(prim, mode="clip") * np.abs(dn) > 4.0 * eps * d_max)
        check &= flat & ~near_edge
        ci = check.nonzero()[0]
        if len(ci):
            P = Ot[ci] + tx[ci, None] * D[ci] - tier.v0.take(prim[ci], axis=0)
            bu = _dot(P, tier.g1.take(prim[ci], axis=0))
            bv = _dot(P, tier.g2.take(prim[ci], axis=0))
            near_edge[ci] = ~((bu >= -_BARY_TOL) & (bv >= -_BARY_TOL) & (bu + bv <= 1.0 + _BARY_TOL))
        r = near_edge.nonzero()[0]
        tri = prim
        if len(r):
            tri = prim.copy()
            ok_e, t_x, tri_e = self._refine_triangles(tier, Ot[r], D[r], tri[r], lo[r], lim[r])
            miss = (~ok_e).nonzero()[0]
            if len(miss):   # not the hit triangle nor a vertex neighbour: nearby triangles
                rm = r[miss]
                ok_n, t_n, tri_n = self._nearby_triangles(tier, Ot[rm], D[rm], t_e[rm], lo[rm], lim[rm], None)
                ok_e[miss], t_x[miss], tri_e[miss] = ok_n, t_n, tri_n
            ok[r], tx[r], tri[r] = ok_e, t_x, tri_e
            dn[r] = _dot(D[r], tier.normal[tri_e])
        k = (ok & (tx < best_t)).nonzero()[0]
        best_t[k] = tx[k]
        if not distance_only:
            nk = tier.normal.take(tri[k], axis=0)
            nk *= np.where(dn[k] > 0.0, -1.0, 1.0)[:, None]   # toward the origin
            best_s[k], best_n[k] = tier.tri_shape[tri[k]], nk
        return flat & ~ok

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

    def _analytic(self, tier: _Tier, slots, Ot, D, lo, hi, normals=True):
        """True-surface hit of curved shapes (tier-frame rays): (t, tier-frame unit normal); the
        normal None without ``normals`` (the same t). The frames in and out are einsum's sums, whose
        sum of zeros is +0.0: the one-shape path adds +0.0 to its sums for the same bits (the sign of
        a zero in the shape frame can decide which rounding of a root is taken), so a ray's answer
        does not depend on the other rays refined with it (and packets.c computes the same)."""
        n = len(slots)
        lo, hi = _full(lo, n), _full(hi, n)
        if n and not np.count_nonzero(slots != slots[0]):   # one shape: one matrix
            s0 = int(slots[0])
            R = tier.c_rot[s0]
            p = _to_frame(_minus(Ot, tier.c_pos[s0]), R)   # R^T (o - c)
            p += 0.0
            d = _to_frame(D, R)
            d += 0.0
            t, n_loc = _analytic_local(int(tier.c_code[s0]), p, d, tier.c_r[s0], tier.c_h[s0], lo, hi, normals)
            if n_loc is None:
                return t, None
            nw = _from_frame(n_loc, R)
            nw += 0.0
            return t, nw
        R = tier.c_rot[slots]
        p = np.einsum("nij,ni->nj", R, Ot - tier.c_pos[slots])  # R^T (o - c)
        d = np.einsum("nij,ni->nj", R, D)
        codes = tier.c_code[slots]
        if n <= _MIXED and np.count_nonzero(codes != codes[0]) and not np.count_nonzero(codes == _CONE):
            # a few rays, several kinds (not cones: their own pass below): one pass
            t, n_loc = _analytic_mixed(codes, p, d, tier.c_r[slots], tier.c_h[slots], lo, hi, normals)
            return t, (np.einsum("nij,nj->ni", R, n_loc) if normals else None)
        t = np.full(n, _INF)
        n_loc = np.zeros((n, 3)) if normals else None
        for code in (_SPHERE, _CYLINDER, _CAPSULE, _CONE):
            g = (codes == code).nonzero()[0]
            if len(g):
                s = slots[g]
                t[g], ng = _analytic_local(code, p[g], d[g], tier.c_r[s], tier.c_h[s], lo[g], hi[g], normals)
                if normals:
                    n_loc[g] = ng
        return t, (np.einsum("nij,nj->ni", R, n_loc) if normals else None)

    def _screen_starts(self, tier: _Tier, S, near):
        """The numpy screening of :meth:`_contained_prepass` (``packets.inside_shells`` does it in one
        C pass): (rows, slots, tight) of the start points ``S`` that may lie inside a shell, None if
        none. ``near``: the shells to test one by one, each by its own extent (tight); None with
        several shells: a dense (rays, shapes) bounding-sphere test (the extents are tested after)."""
        cp = tier.c_pos
        if near is not None or len(cp) == 1:
            rs, ss = [], []
            for k in (near if near is not None else [0]):
                r = self._inside_shell(tier, k, S).nonzero()[0]
                rs.append(r)
                ss.append(np.full(len(r), k, dtype=np.int64))
            rows = np.concatenate(rs) if rs else np.zeros(0, dtype=np.int64)
            if len(rows) == 0:
                return None
            return rows, np.concatenate(ss), True
        dx, dy, dz = S[:, 0:1] - cp[:, 0], S[:, 1:2] - cp[:, 1], S[:, 2:3] - cp[:, 2]
        cand = dx * dx + dy * dy + dz * dz <= tier.c_bound2
        if not np.count_nonzero(cand):
            return None
        rows, slots = cand.nonzero()
        return rows, slots, False

    def _contained_prepass(self, tier: _Tier, Ot, D, lo, lim, excl, box=None):
        """Rays starting inside a curved shell may reach the true surface before any crossing of
        that shell that the cast will see (the exit can lie beyond t_far or a nearer hit found
        elsewhere), so those (ray, shape) pairs are intersected analytically up front.  Screening
        of the start points: a few rays in plain floats; many rays against the bounding box of
        their origins first (a lidar's rays share one origin); then each shell's own extent (or a
        dense bounding-sphere test against several shells).  So this costs a few numpy calls unless
        some start point really is inside a shell.  Returns None, or (rows, t, global shape,
        normal toward the origin) of the hits found.  ``box``: the (min, max) per column of ``Ot``
        when the caller has it (the screening's box, without a pass over the rows)."""
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
        if Ot.strides[0] == 0 and not isinstance(lo, np.ndarray):   # one origin (a lidar), plain floats:
            # its start points lie within lo of it (unit directions)
            ox, oy, oz = Ot[0].tolist()
            near = [k for k, (cx, cy, cz, b2) in enumerate(tier.c_sphere)
                    if math.sqrt((ox - cx) ** 2 + (oy - cy) ** 2 + (oz - cz) ** 2) <= (math.sqrt(b2) + lo) * (1.0 + 1e-9)]
            if not near:
                return None
        elif m * len(cp) > _DENSE_PAIRS:  # many rays: screen their bounding box first (a lidar: a point)
            # per column: numpy reduces a short inner axis ~10x slower than a contiguous column
            reach = float(lo.max()) if isinstance(lo, np.ndarray) else lo
            Ou = Ot[:1] if Ot.strides[0] == 0 else Ot   # one origin for all rays (a broadcast array)
            if box is None:
                box = packets.box3(Ou) if self.native and len(Ou) > 1 else None
            if box is None:
                box = np.array([Ou[:, k].min() for k in range(3)]), np.array([Ou[:, k].max() for k in range(3)])
            box_lo, box_hi = box[0] - reach, box[1] + reach
            gap = cp - np.minimum(np.maximum(cp, box_lo), box_hi)
            near = (_dot(gap, gap) <= tier.c_bound2).nonzero()[0].tolist()
            if not near:
                return None
        else:
            near = None
        # the screening below in one C pass where the helper is (the same tests and pairs in the same
        # order; the start points only made once some are inside): shape by shape, each shell's own
        # extent straight away, or (dense) the bounding spheres and then the extents, by row
        dense = near is None and len(cp) > 1
        got = (packets.inside_shells(tier, Ot, D, lo, range(len(cp)) if dense else near if near is not None else [0],
                                     bound_first=dense) if self.native else None)
        if got is not None:
            rows, slots = got
            if len(rows) == 0:
                return None
            if dense:
                order = np.lexsort((slots, rows))
                rows, slots = rows[order], slots[order]
            tight = True
        S = Ot + lo_col * D
        if got is None:
            screened = self._screen_starts(tier, S, near)
            if screened is None:
                return None
            rows, slots, tight = screened
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
        p = _to_frame(p, tier.c_rot[k])
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
            # into the shape frame and back as einsum sums (see _analytic): + 0.0 makes a sum of zeros +0.0
            t, (nx, ny, nz) = _analytic_one(
                code, ((ox * r0 + oy * r3 + oz * r6) + 0.0, (ox * r1 + oy * r4 + oz * r7) + 0.0,
                       (ox * r2 + oy * r5 + oz * r8) + 0.0),
                ((dx * r0 + dy * r3 + dz * r6) + 0.0, (dx * r1 + dy * r4 + dz * r7) + 0.0,
                 (dx * r2 + dy * r5 + dz * r8) + 0.0),
                r, h, lo if lo_l is None else float(lo_l[i]), lim if lim_l is None else float(lim_l[i]))
            if t < _INF and (i not in found or t < found[i][0]):
                # R n, summed (0 + 2) + 1 as einsum("nij,nj->ni") does for the vectorised pre-pass
                n = ((r0 * nx + r2 * nz + r1 * ny) + 0.0, (r3 * nx + r5 * nz + r4 * ny) + 0.0,
                     (r6 * nx + r8 * nz + r7 * ny) + 0.0)
                if n[0] * dx + n[1] * dy + n[2] * dz > 0.0:   # toward the origin
                    n = (-n[0], -n[1], -n[2])
                found[i] = (t, sid, n)
        if not found:
            return None
        keys = sorted(found)
        return (np.array(keys, dtype=np.int64), np.array([found[i][0] for i in keys]),
                np.array([found[i][1] for i in keys], dtype=np.int64), np.array([found[i][2] for i in keys]))
