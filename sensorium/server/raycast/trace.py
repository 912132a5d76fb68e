"""Tracing one tier: the FAST path (one Embree call, vectorised judging) and the general loop
(judge each hit, refine in EXACT, continue rejected rays).  A mixin of :class:`RayEngine`: the
methods use its ``counters`` and the pre-pass/refinement methods of :mod:`.refine`."""

from __future__ import annotations

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.blocks import MIN_RAYS, in_block
from sensorium.server.raycast.exact import (
    _BARY_TOL,
    _F32,
    _INF,
    _LEAK_OFFSET_ULPS,
    _MAX_LOOPS,
    _SMALL,
    _dot,
    _full,
    _minus,
    _one_row,
    _perpendicular,
    _rows,
    _start32,
    _take,
)
from sensorium.server.raycast.refine import Refiner
from sensorium.server.raycast.tiers import _Tier


def _vec(x, dtype=np.float64) -> tuple:
    """(array kept alive, address, stride in elements) of a per-ray parameter that may be a scalar
    (stride 0: one value for every ray)."""
    if isinstance(x, np.ndarray):
        a = np.ascontiguousarray(x, dtype=dtype)
        return a, a.ctypes.data, 1
    a = np.array([x], dtype=dtype)
    return a, a.ctypes.data, 0


def _rows_of(O: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """O[rows], one origin (a broadcast array) kept one."""
    return _one_row(O[:1], len(rows)) if O.strides[0] == 0 and len(O) else O[rows]


def _rows_ptr(x: np.ndarray) -> tuple:
    """(array kept alive, address, row stride in elements) of (m,3) float64 rows, possibly one
    broadcast row (stride 0)."""
    if x.strides[0] == 0 and x.strides[1] == 8 and x.dtype == np.float64:
        return x, x.ctypes.data, 0
    a = np.ascontiguousarray(x, dtype=np.float64)
    return a, a.ctypes.data, 3


def shell_spheres(tier: _Tier) -> tuple[np.ndarray, np.ndarray]:
    """(centres (k, 3), screening radii (k,)) of the tier's curved shells, contiguous float64, made
    once (the shells never change): what :func:`_near_shells` screens start points against."""
    kept = tier.__dict__.get("_shell_spheres")
    if kept is None:
        kept = tier._shell_spheres = (np.ascontiguousarray(tier.c_pos, dtype=np.float64),
                                      np.ascontiguousarray(np.sqrt(tier.c_bound2), dtype=np.float64))
    return kept


def _near_shells(tier: _Tier, rows: np.ndarray, lo: float) -> bool:
    """Whether a start point ``o + lo d`` (unit ``d``) of a ray from one of the origins ``rows``
    (tier frame) may lie in a curved shell's bounding sphere: the pre-pass's screen of one origin
    (``refine._contained_prepass``: centre distance <= (bound + lo) (1 + 1e-9)) for each row. False:
    every start point lies outside every shell, so the pre-pass, which looks only at start points
    inside a shell, finds nothing (a lidar scanning from 64 copies' robots, a sensor's rays)."""
    c, bound = shell_spheres(tier)
    dx = rows[:, 0:1] - c[:, 0]
    dy = rows[:, 1:2] - c[:, 1]
    dz = rows[:, 2:3] - c[:, 2]
    # (a NaN or infinite origin: never near, as its start points are in no shell for the pre-pass)
    return bool(np.count_nonzero(np.sqrt(dx * dx + dy * dy + dz * dz) <= (bound + lo) * (1.0 + 1e-9)))


class TierTracer(Refiner):
    """Per-tier tracing methods of :class:`~sensorium.server.raycast.engine.RayEngine`."""

    counters: dict[str, int]
    native: bool   # judge (and in EXACT refine) hits in packets.c where the packet path is on
    threads: int   # a FAST pass of >= MIN_RAYS rays is split over this many threads inside packets.c

    def _run(self, tier: _Tier, o32, d32, far, robust: bool, coherent: bool = False):
        """One Embree call; ``coherent``: rays from one origin (a FAST lidar scan), traced as coherent
        packets where the packet path is on (~3x faster; a ray within float32 rounding of an edge
        may get the neighbouring triangle: see :mod:`.packets`). EXACT never asks for it: its
        incoherent packets give embreex's answers bit for bit."""
        scene, built = tier.scene(robust)
        self._count("bvh_builds", built)
        self._count("embree_calls", 1)
        if coherent and isinstance(scene, packets.Scene):
            return scene.run(o32, d32, far, output=1, coherent=True)
        return scene.run(o32, d32, far, output=1)

    def _trace(self, tier: _Tier, O, D, t_near, lim, excl, eps64: float, exact: bool, big: float | None = None,
               distance_only: bool = False, d32=None, coherent: bool = False, box=None, rows=None, run: int = 0,
               seg_end=None):
        """Nearest accepted hit in one tier.  O, D in the tier's parent frame; returns (t, shape,
        normal oriented toward the origin) with normal in the parent frame's orientation, or None
        when no ray hits.  ``big``: max |coordinate| of O when already known (saves two reductions
        for an unanchored tier).  ``distance_only``: FAST may return None for shape and normal
        (the same t; a lidar needs nothing else), and so may EXACT.  ``d32``: ``D`` rounded to
        float32 when the caller has it.  ``coherent``: FAST traces the rays as coherent packets even
        with several origins (rays in runs from one origin each: the copies' lidars of a batched
        world; a ray's answer is then the one it gets in a one-origin cast).  ``box``: FAST's
        curved-shell pre-pass takes the (min, max) per column of O from it when given (the values
        it would find; an unanchored tier); ``rows``: O's distinct rows (every ray's origin is one
        of them), whose distance to the curved shells can rule the pre-pass out. ``run`` > 0 with
        ``coherent``: the runs' length (each run's packets are its own one-origin cast's); ``seg_end``
        ((m,) int64, with ``coherent``): runs of any length, each ray's run ending before
        ``seg_end[i]`` (the C pass only: packets never span two runs)."""
        if exact:
            res = self._trace_loop(tier, O, D, t_near, lim, excl, eps64, exact=True, distance_only=distance_only,
                                   d32_all=d32)
            if not np.count_nonzero(res[0] < _INF):
                return None
            return (res[0], None, None) if distance_only else res
        return self._trace_fast(tier, O, D, t_near, lim, excl, eps64, big, distance_only, d32, coherent, box, rows,
                                run, seg_end)

    def _trace_fast(self, tier: _Tier, O, D, t_near, lim, excl, eps64: float, big: float | None = None,
                    distance_only: bool = False, d32=None, coherent: bool = False, box=None, rows=None,
                    run: int = 0, seg_end=None):
        """FAST: one Embree call and vectorised gathers; the rare rays needing judgement (possible
        self-hits, shells left from inside, excluded owners) are redone by the general loop.
        Mostly-missing batches (short sensor rays) work on the hit rows only, mostly-hitting ones
        (a lidar in a room) on whole arrays without gathers."""
        m = len(O)
        one = m > 1 and O.strides[0] == 0   # one origin for every ray (a broadcast array: a lidar)
        if tier.anchored:   # (the same subtraction for one origin as for each row)
            Ot = _one_row(_minus(O[:1], tier.anchor), m) if one else _minus(O, tier.anchor)
        else:
            Ot = O
        pre = None
        lim_in = lim   # the redo below gets the caller's limit: it runs its own pre-pass, whose
        # float64 path (scalar or vectorised) may differ from this one's in the last bit
        if tier.has_curved:  # origins inside a curved shell: analytic first (see the pre-pass)
            lo = np.maximum(t_near, eps64) if isinstance(t_near, np.ndarray) else max(t_near, eps64)
            if rows is not None and 4 * len(rows) <= m and not tier.anchored and not isinstance(lo, np.ndarray) \
                    and not _near_shells(tier, rows, lo):
                pass   # no start point can lie in a shell: the pre-pass would find nothing (screened by
                # the rows where they are a few per ray: a lidar's 360, a sonar's 5, not an e-puck's 3)
            else:
                pre = self._contained_prepass(tier, Ot, D, lo, lim, excl, None if tier.anchored else box)
            if pre is not None:  # the cast only needs to look before the analytic hits
                lim = np.array(lim, dtype=np.float64) if isinstance(lim, np.ndarray) else np.full(m, lim)
                lim[pre[0]] = np.minimum(lim[pre[0]], pre[1])
        # one origin: its float32 row o1, as a read-only broadcast o32 once needed (the C pass takes
        # o1 and the start itself: see _fast_native); many origins: the C pass rounds Ot's rows to
        # float32 itself (and shifts them by a scalar start) unless o32 is needed here first
        native = self.native and m > 0 and tier.native(False) is not None
        o1 = Ot[:1].astype(_F32) if one else None
        o32 = None if one or (native and big is not None) else Ot.astype(_F32)
        shared = one
        d32 = D.astype(_F32) if d32 is None else d32   # never written
        start = t_near
        dead = None
        if big is None:
            ob = o1 if one else o32
            big = max(map(abs, ob.ravel().tolist())) if len(ob) <= _SMALL else max(-float(ob.min()), float(ob.max()))
        if big * 1.7321 > tier.radius:
            if o32 is None:
                o32 = _one_row(o1, m) if one else Ot.astype(_F32)
            far_rows = (_dot(o32, o32) > _F32(tier.radius * tier.radius)).nonzero()[0]
            if len(far_rows):  # origin outside the tier's sphere: start at its entry (precision)
                if shared:
                    o32, shared = o32.copy(), False
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
        shifted = False   # o32 = float32(start) d32 + o1 (or + float32(Ot)), made in the C pass
        if not isinstance(start, np.ndarray):
            if start > 0.0 and shared:   # o + s d in float32 (the same sum, operands swapped)
                if native and o32 is None:
                    shifted = True
                else:
                    o32 = _F32(start) * d32
                    o32 += o1
                shared = False
            elif start > 0.0:
                if o32 is None:
                    shifted = True
                else:
                    o32 += _F32(start) * d32
        elif dead is None:
            if shared:
                o32, shared = (_one_row(o1, m) if o32 is None else o32).copy(), False
            elif o32 is None:
                o32 = Ot.astype(_F32)
            o32 += start[:, None] * d32
        slack = 1.0 + 2.0 ** -20  # float32 slack so a hit exactly at t_far counts
        if (dead is None or not len(dead)) and (isinstance(lim, np.ndarray) or isinstance(start, np.ndarray)):
            # per-ray limits straight into float32 (the float64 product, rounded once); x - 0.0 == x
            base = lim if not isinstance(start, np.ndarray) and start == 0.0 else lim - start
            far = np.multiply(base, slack, out=np.empty(m, dtype=_F32), casting="same_kind")
        else:
            far = (lim - start) * slack
            if dead is not None and len(dead):
                far = np.array(_full(far, m))
                far[dead] = -1.0
            if isinstance(far, np.ndarray):
                far = far.astype(_F32)
            elif far == _INF:
                far = None
            else:
                far = float(far)
        if native:   # traversal and judging in one C call (the same values)
            n_hit, t, shape, normal, redo = self._fast_native(tier, Ot, D, o32, o1, shifted, d32, far, one or coherent,
                                                              start, lim, excl, distance_only, 0 if one else run,
                                                              None if one else seg_end)
            if n_hit == 0 and pre is None:
                return None
        else:
            if o32 is None:
                o32 = _one_row(o1, m)
            res = self._run(tier, o32, d32, far, robust=False, coherent=one or coherent)
            prim = res["primID"]
            hit = prim >= 0
            n_hit = np.count_nonzero(hit)
            if n_hit == 0 and pre is None:
                return None   # no hit at all (the common case for short sensor rays)
        if native:
            pass
        elif 2 * n_hit >= m:  # mostly hits: whole arrays, misses masked (primID -1 picks the
            # sentinel rows: shape -1, zero normal)
            (t, normal), redo = self._judge_fast(tier, Ot, D, d32, res, prim, slice(None), start, lim, excl,
                                                 distance_only)
            shape = None if distance_only else tier.tri_shape.take(prim)
            if n_hit < m:
                t[~hit] = _INF
        else:
            h = hit.nonzero()[0]
            t = np.full(m, _INF)
            shape = None if distance_only else np.full(m, -1, dtype=np.int64)
            normal = None if distance_only else np.zeros((m, 3))
            redo = None
            if len(h):
                (th, nrm), special = self._judge_fast(tier, Ot, D, d32, res, prim[h], h, start, lim, excl,
                                                      distance_only)
                t[h] = th
                if not distance_only:
                    shape[h], normal[h] = tier.tri_shape.take(prim[h]), nrm
                if special is not None:
                    redo = np.zeros(m, dtype=bool)
                    redo[h[special]] = True
        if redo is not None and pre is not None:  # rays the pre-pass settles need no redo
            redo[pre[0][pre[1] <= t[pre[0]]]] = False
        if redo is not None and np.count_nonzero(redo):
            rows = redo.nonzero()[0]
            t2, s2, n2 = self._trace_loop(tier, _rows_of(O, rows), D[rows], _take(t_near, rows), _take(lim_in, rows),
                                          _take(excl, rows), eps64, exact=False)
            t[rows] = t2
            if not distance_only:
                shape[rows], normal[rows] = s2, n2
        if pre is not None:  # analytic hits of the pre-pass, unless a nearer hit was found
            rows, tp, sp, np_ = pre
            if len(rows) <= _SMALL:  # a few: plain Python (ten numpy calls otherwise)
                for k, (i, ti) in enumerate(zip(rows.tolist(), tp.tolist())):
                    if ti <= t[i]:
                        t[i] = ti
                        if not distance_only:
                            shape[i], normal[i] = sp[k], np_[k]
            else:
                take = (tp <= t[rows]).nonzero()[0]
                r = rows[take]
                t[r] = tp[take]
                if not distance_only:
                    shape[r], normal[r] = sp[take], np_[take]
        return t, shape, normal

    def _fast_native(self, tier: _Tier, Ot, D, o32, o1, shifted: bool, d32, far, coherent: bool, start, lim, excl,
                     distance_only: bool, run: int = 0, seg_end=None):
        """FAST's Embree call and judging (``_judge_fast``, ``_special``) in one call of packets.c:
        (hits, t, shape, normal, redo mask or None), the values of the numpy path. ``o32`` None: one
        origin ``o1``, shifted by ``start`` along each ray when ``shifted``; ``o32`` and ``o1`` None:
        ``Ot``'s rows rounded to float32 (``Ot.astype(float32)``), shifted likewise. A small cast writes into
        the thread's scratch buffers and passes no array it did not pass before (a lidar's beams):
        its fixed cost is the call."""
        scene, built = tier.scene(False)
        if built:
            self._count("bvh_builds", built)
        self._count("embree_calls", 1)
        m = len(d32)
        sc = packets.scratch()
        small = m <= packets.SCRATCH
        addr = packets.address if small else (lambda a: a.ctypes.data)
        if not (d32.flags.c_contiguous and d32.dtype == _F32):
            d32 = np.ascontiguousarray(d32, dtype=_F32)
        p_o1 = sc.p_o1
        if o32 is None and o1 is None:   # Ot's rows, rounded in the C pass
            o_ptr, o_stride, p_o1 = None, 0, None
        elif o32 is None:
            sc.o1[:] = o1[0]
            o_ptr, o_stride = None, 0
        elif o32.strides[0] == 0:
            sc.o1[:] = o32[0]
            o_ptr, o_stride = None, 0
        else:
            o32 = np.ascontiguousarray(o32, dtype=_F32)
            o_ptr, o_stride = o32.ctypes.data, 3
        if isinstance(far, np.ndarray):
            far = np.ascontiguousarray(far, dtype=_F32)
            far_ptr, far_value = far.ctypes.data, 0.0
        else:
            far_ptr, far_value = None, 0.0 if far is None else far
        if Ot.strides[0] == 0:
            sc.origin[:] = Ot[0]
            ot_ptr, ot_stride = None, 0
        else:
            ot = _rows_ptr(Ot)
            ot_ptr, ot_stride = ot[1], ot[2]
        dd = D if D.flags.c_contiguous else np.ascontiguousarray(D)
        st_arr = np.ascontiguousarray(start, dtype=np.float64) if isinstance(start, np.ndarray) else None
        lim_arr = np.ascontiguousarray(lim, dtype=np.float64) if isinstance(lim, np.ndarray) else None
        has_excl = tier.owned and not (not isinstance(excl, np.ndarray) and excl < 0)
        ex_arr = np.ascontiguousarray(excl, dtype=np.int64) if has_excl and isinstance(excl, np.ndarray) else None
        if small:
            p_t, p_s, p_n, p_sp = sc.p_t, sc.p_s, sc.p_n, sc.p_sp
        else:
            t, special = np.empty(m), np.empty(m, dtype=np.uint8)
            shape = None if distance_only else np.empty(m, dtype=np.int64)
            normal = None if distance_only else np.empty((m, 3))
            p_t, p_sp = t.ctypes.data, special.ctypes.data
            p_s, p_n = (None, None) if distance_only else (shape.ctypes.data, normal.ctypes.data)
        n_hit = packets.library().sp_fast_pass(
            scene.handle, tier.native(False), m, 1 if coherent else 0, o_ptr, o_stride, p_o1, 1 if shifted else 0,
            _F32(start) if shifted else 0.0, addr(d32), far_ptr, far_value, 1 if far is None else 0, ot_ptr,
            ot_stride, sc.p_origin, addr(dd), None if st_arr is None else st_arr.ctypes.data,
            0.0 if st_arr is not None else start, None if lim_arr is None else lim_arr.ctypes.data,
            0.0 if lim_arr is not None else lim, 1 if isinstance(lim, np.ndarray) or lim != _INF else 0,
            None if ex_arr is None else ex_arr.ctypes.data, 0 if ex_arr is not None or not has_excl else excl,
            1 if has_excl else 0, 1 if distance_only else 0, p_t, p_s, p_n, p_sp,
            self.threads if m >= MIN_RAYS and not in_block() else 1, max(0, int(run)),
            None if seg_end is None else seg_end.ctypes.data)
        if small:
            t = sc.t[:m].copy()
            shape = None if distance_only else sc.s[:m].copy()
            normal = None if distance_only else sc.n[:m].copy()
            special = sc.sp[:m]
        redo = special.view(bool)
        return n_hit, t, shape, normal, (redo.copy() if np.count_nonzero(redo) else None)

    def _exact_native(self, tier: _Tier, st: int, Ot, D, d32, seg, lo, lim, excl, alive, thr: float, best_t, best_s,
                      best_n, distance_only: bool) -> None:
        """EXACT's ``_trace_loop`` in packets.c for a tier with edge guards or no risky edge: robust
        scene, incoherent packets, the guards' second look, the float64 refinement of flat hits
        (vertex rings and nearby triangles near edges) and curved hits, rays continued past rejected
        hits; updates ``best_*`` (and ``seg``, ``lim``) as the numpy loop does."""
        scene, built = tier.scene(True)
        self._count("bvh_builds", built)
        self._count("embree_calls", 1)
        m = len(D)
        ot = _rows_ptr(Ot)
        dd = np.ascontiguousarray(D, dtype=np.float64)
        d32 = None if d32 is None or len(d32) != m else np.ascontiguousarray(d32, dtype=_F32)
        ex = None if excl is None else _vec(excl, np.int64)
        counts = np.zeros(3, dtype=np.uintp)
        packets.library().sp_exact_pass(
            scene.handle, st, m, ot[1], ot[2], dd.ctypes.data, None if d32 is None else d32.ctypes.data,
            seg.ctypes.data, lo.ctypes.data, 1, lim.ctypes.data, None if ex is None else ex[1],
            0 if ex is None else ex[2], alive.ctypes.data, thr, best_t.ctypes.data, best_s.ctypes.data,
            None if distance_only else best_n.ctypes.data, counts.ctypes.data)
        for key, k in (("continued_rays", 0), ("unresolved_rays", 1), ("edge_guard_hits", 2)):
            if counts[k]:
                self._count(key, int(counts[k]))

    def _judge_fast(self, tier: _Tier, Ot, D, d32, res, ph, rows, start, lim, excl, distance_only=False):
        """FAST hit data of the Embree results at ``rows`` (a slice of all rays, or an index array
        of hit rays; ``ph`` = their primIDs): ((t, normal toward the origin), special mask or None),
        special = rays the general loop must redo.  ``distance_only``: normal None, and the side
        hit is only worked out when curved shells need it (the same t and special)."""
        every = isinstance(rows, slice)
        tf = res["tfar"][rows]
        t = np.add(tf, start if not isinstance(start, np.ndarray) else start[rows], dtype=np.float64)
        if isinstance(lim, np.ndarray):
            np.minimum(t, lim[rows], out=t)
        elif lim != _INF:
            np.minimum(t, lim, out=t)
        if distance_only:   # the side hit matters only on curved shells: judge those rows alone
            leaving = None
            if tier.has_curved:
                cv = tier.tri_curved.take(ph).nonzero()[0]
                back = self._back(tier, D, d32, res, ph[cv], rows if every else rows[cv], cv if every else None)
                leaving = cv[back]
            return (t, None), self._special(tier, Ot, tf, ph, rows, every, None, excl, leaving)
        dh = d32[rows]
        ng = res["Ng"][rows]                 # Embree's Ng has our winding: sign = side hit
        if len(ng) > _SMALL:                 # one pass over the rows
            dots = np.einsum("ij,ij->i", ng, dh)
        else:
            dots = ng[:, 0] * dh[:, 0] + ng[:, 1] * dh[:, 1] + ng[:, 2] * dh[:, 2]
        back = dots > 0.0
        nrm = tier.normal.take(ph, axis=0)   # misses (-1): the zero sentinel row
        # toward the origin (exact negation); misses keep the sign bits they always had (-0.0
        # unless "back"), so the arrays stay bit-identical to the former [normal; -normal] table
        nrm[(back ^ (ph < 0)) if every else back] *= -1.0
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
        return (t, nrm), self._special(tier, Ot, tf, ph, rows, every, back, excl)

    @staticmethod
    def _back(tier: _Tier, D, d32, res, ph, rows, sub):
        """Side hit (True: the back) of the hits of ``ph`` at ray ``rows`` (``sub``: their indices
        when ``rows`` is a slice of all rays), as :meth:`_judge_fast` decides it."""
        idx = rows if sub is None else sub
        dh = d32.take(idx, axis=0)       # (np.take: several times faster than fancy indexing here)
        ng = res["Ng"].take(idx, axis=0)
        if len(ng) > _SMALL:
            dots = np.einsum("ij,ij->i", ng, dh)
        else:
            dots = ng[:, 0] * dh[:, 0] + ng[:, 1] * dh[:, 1] + ng[:, 2] * dh[:, 2]
        back = dots > 0.0
        grazing = (np.abs(dots) < 1e-5 * tier.ng_max).nonzero()[0]
        if len(grazing):  # float32 sign unreliable: orient in float64
            back[grazing] = _dot(tier.normal[ph[grazing]], D[idx[grazing]]) > 0.0
        return back

    @staticmethod
    def _special(tier: _Tier, Ot, tf, ph, rows, every: bool, back, excl, leaving=None):
        """Mask of the rays FAST must redo in the general loop, or None: possible self-hits, shells
        left from inside (``back``: side hit, needed when the tier has curved shells; or ``leaving``:
        the positions of the curved hits on a back face), excluded owners."""
        special = tf < tier.eps              # possible self-hit (origin on the surface)
        found = bool(np.count_nonzero(special))
        if found:
            if every:
                special &= ph >= 0
            sp = special.nonzero()[0]
            if len(sp):
                tri = ph[sp]
                gap = np.abs(_dot(Ot[sp if every else rows[sp]] - tier.first_vertex(tri), tier.normal[tri]))
                special[sp] = gap <= 2.0 * tier.eps
        if leaving is not None:              # leaving a curved shell: the true surface decides
            if len(leaving):
                special[leaving] = found = True
        elif tier.has_curved:
            special |= back & tier.tri_curved.take(ph)
            found = True
        if tier.owned and not (not isinstance(excl, np.ndarray) and excl < 0):
            special |= tier.tri_owner.take(ph) == (excl[rows] if isinstance(excl, np.ndarray) else excl)
            found = True
        return special if found and np.count_nonzero(special) else None

    def _trace_loop(self, tier: _Tier, O, D, t_near, lim, excl, eps64: float, exact: bool,
                    distance_only: bool = False, d32_all=None):
        """General path: cast, judge each hit, continue rejected rays past their hit (bounded).
        Judging: excluded owners are skipped; EXACT refines flat hits in float64 and curved hits
        on the true surface; FAST keeps Embree's answer except self-hits and shells left from
        inside.  Returns (t, shape, normal oriented toward the origin); ``distance_only``: the shape
        and normal of flat hits are left unset (the same t); ``d32_all``: ``D`` as float32, if the
        caller has it).  EXACT runs in packets.c where the packet path is on (``_exact_native``)."""
        m = len(O)
        eps = tier.eps
        if tier.anchored:   # one origin (a broadcast array) stays one
            Ot = _one_row(O[:1] - tier.anchor, m) if O.strides[0] == 0 and m else _minus(O, tier.anchor)
        else:
            Ot = O
        # Embree's start along the ray: eps before t_near, not before eps (FAST: it redoes its
        # self-hits from there) or 1e-6 m (EXACT: the floor of eps; a room's tier has eps of a few
        # um). EXACT judges a self-hit in float64 (t < lo) and continues past it, so in a coarse
        # tier (eps ~ 3 cm in a static tier spanning 1e5 m) a surface nearer than eps is seen
        first = min(eps, 1e-6) if exact else eps
        if isinstance(t_near, np.ndarray):       # accepted hits: lo <= t <= lim
            lo = np.maximum(t_near, eps64)
            seg = np.maximum(t_near - eps, first)
        else:
            lo = np.full(m, max(t_near, eps64))
            seg = np.full(m, max(t_near - eps, first))
        lim = np.array(lim, dtype=np.float64) if isinstance(lim, np.ndarray) else np.full(m, float(lim))
        excl_arr = None
        if tier.owned:
            excl_arr = excl if isinstance(excl, np.ndarray) else np.full(m, excl, dtype=np.int64)
        best_t = np.full(m, _INF)
        best_s = np.full(m, -1, dtype=np.int64)
        best_n = np.zeros((m, 3))
        r2 = tier.radius ** 2
        Ou = Ot[:1] if m and Ot.strides[0] == 0 else Ot
        if m and max(-float(Ou.min()), float(Ou.max())) * 1.7321 > tier.radius:
            # some origins outside the tier's sphere: clip to it
            b = _dot(Ot, D)
            q2 = _dot(Ot, Ot) - b * b
            half = np.sqrt(np.maximum(r2 - q2, 0.0))
            np.maximum(seg, -b - half, out=seg)
            alive = (q2 <= r2) & (-b + half >= lo) & (seg <= lim + eps)
            s_one = None
        else:
            alive = seg <= lim + eps
            s_one = None if isinstance(t_near, np.ndarray) else float(seg[0]) if m else None   # every start alike
        if tier.has_curved:   # (a uniform start as a scalar: the pre-pass's one-origin screen)
            pre = self._contained_prepass(tier, Ot, D, lo if isinstance(t_near, np.ndarray) else float(lo[0]) if m else lo,
                                          lim, excl)
            if pre is not None:
                rows, tp, sp, np_ = pre
                best_t[rows], best_s[rows], best_n[rows] = tp, sp, np_
                np.minimum(lim, best_t, out=lim)

        one_origin = Ot.strides[0] == 0 and m > 0   # a broadcast array: one origin for all rays
        if exact:   # bound of |d| (the float32 reach below scales with it): sqrt(3) max |component|
            d_max = 1.7321 * max(float(D.max()), -float(D.min())) if m else 0.0
            if self.native and m and tier.guarded:
                st = tier.native(True)
                if st is not None:   # the passes in C
                    self._exact_native(tier, st, Ot, D, d32_all, seg, lo, lim, excl_arr, alive, 4.0 * eps * d_max,
                                       best_t, best_s, best_n, distance_only)
                    return best_t, best_s, best_n
        act = alive.nonzero()[0]
        delta = None   # per-ray continuation step, allocated on the first continuation
        for _ in range(_MAX_LOOPS):
            if len(act) == 0:
                break
            view = slice(None) if len(act) == m else act   # all rays active: views, not copies
            oa = np.broadcast_to(Ot[:1], (len(act), 3)) if one_origin else Ot[view]   # one origin stays one
            da, sa = D[view], seg[view]
            o32 = _start32(oa, da, sa if s_one is None else s_one)   # oa + sa da in float64, rounded once
            s_one = None   # continued rays start apart
            d32 = d32_all if d32_all is not None and len(act) == m else da.astype(_F32)
            far = ((lim[view] - sa) + (eps if exact else 0.0)) * (1.0 + 2.0 ** -20)
            far32 = np.where(far >= 0.0, far, -1.0).astype(_F32)
            copy = exact and not tier.guarded
            res = self._run(tier, o32, d32, far32.copy() if copy else far32, robust=exact)
            prim, tf = res["primID"].astype(np.int64), res["tfar"]
            repaired = fixed = None
            if exact and not copy:
                if tier.guard is not None:   # rays that met an edge guard first: the second look
                    g = (res["geomID"] == 1).nonzero()[0]
                    if len(g):
                        self._guard_rays(tier, res, g, act, Ot, D, o32, d32, sa, far, lo, lim, excl_arr,
                                         best_t, best_s, best_n)
                        prim = res["primID"].astype(np.int64)
            elif exact:
                # leak repair: a copy offset by a few ulps perpendicular to the ray
                o2 = (oa + sa[:, None] * da + _perpendicular(da) * (_LEAK_OFFSET_ULPS * tier.res)).astype(_F32)
                prim2 = self._run(tier, o2, d32, far32, robust=True)["primID"]
                sus = ((prim2 >= 0) & (prim2 != prim)).nonzero()[0]
                if len(sus):
                    # (never before lo: the surface a ray starts on is no repair, only a continued ray)
                    ok, t2, tri2 = self._refine_triangles(tier, oa[sus], da[sus], prim2[sus].astype(np.int64),
                                                          np.maximum(sa[sus] - eps, lo[view][sus]),
                                                          lim[view][sus] + eps)
                    t_sus = np.where(prim[sus] >= 0, sa[sus] + tf[sus], _INF)
                    fix = ok & ((prim[sus] < 0) | (t2 < t_sus - eps))
                    if np.count_nonzero(fix):
                        fixed = (sus[fix], t2[fix])
                        prim[fixed[0]] = tri2[fix]
                        repaired = np.zeros(len(prim), dtype=bool)   # Embree's barycentrics no longer apply
                        repaired[fixed[0]] = True
                        self._count("leak_repairs", len(fixed[0]))
            h = (prim >= 0).nonzero()[0]
            if len(h) == 0:  # nothing hit: every active ray is done
                break
            t_e = sa + tf   # Embree distance along the whole ray (read at hit rows only)
            if fixed is not None:
                t_e[fixed[0]] = fixed[1]
            cont = np.zeros(len(act), dtype=bool)   # rays to continue past their hit
            if len(h):
                ph = prim[h]
                rows_h = h if len(act) == m else act[h]   # all active: act is 0..m-1
                rej = np.zeros(len(h), dtype=bool)
                if excl_arr is not None:
                    rej |= tier.tri_owner[ph] == excl_arr[rows_h]
                slot = tier.tri_slot[ph]
                curved = slot >= 0
                # --- flat triangles (boxes, meshes)
                fl = (~curved & ~rej).nonzero()[0]
                if exact and len(act) == m and excl_arr is None and repaired is None and 2 * len(fl) > m:
                    cont |= self._flat_dense(tier, res, prim, Ot, D, one_origin, lo, lim, t_e, d_max,
                                             best_t, best_s, best_n, distance_only)
                elif len(fl):
                    rows = rows_h[fl]
                    tri = ph[fl]
                    nrm = tier.normal.take(tri, axis=0)
                    Dr = _rows(D, rows)
                    dn = _dot(Dr, nrm)
                    if exact:
                        V0 = tier.v0.take(tri, axis=0)
                        if one_origin:   # a lidar: v0 - o for its one origin (the same values)
                            tx = _dot(_minus(V0, Ot[0]), nrm) / dn
                        else:
                            tx = _dot(V0 - _rows(Ot, rows), nrm) / dn
                        ok = np.isfinite(tx) & (tx >= lo[rows]) & (tx <= lim[rows])
                        # Embree barycentrics comfortably inside the triangle: float32 cannot have
                        # picked the wrong one and its float64 plane gives the exact distance; near
                        # an edge (or repaired), test in float64
                        hf = h[fl]
                        u, v = res["u"][hf], res["v"][hf]
                        margin = np.minimum(np.minimum(u, v), 1.0 - u - v)
                        near_edge = ~(margin > 1e-4)
                        if repaired is not None:
                            near_edge |= repaired[hf]
                        # float64 barycentrics of the plane hit (in a coarse float32 frame Embree
                        # can report comfortable barycentrics on the adjacent face's triangle),
                        # unless Embree's hit lies farther inside than the float32 rounding of the
                        # ray and the triangle can move it (a few ulps, < 4 eps, across the plane:
                        # / sin of the incidence): then they are inside for sure
                        check = ~(margin * tier.h_min.take(tri) * np.abs(dn) > 4.0 * eps * d_max)
                        check &= ~near_edge
                        ci = check.nonzero()[0]
                        if len(ci):
                            P = Ot[rows[ci]] + tx[ci, None] * Dr[ci] - V0[ci]
                            bu = _dot(P, tier.g1.take(tri[ci], axis=0))
                            bv = _dot(P, tier.g2.take(tri[ci], axis=0))
                            near_edge[ci] = ~((bu >= -_BARY_TOL) & (bv >= -_BARY_TOL) & (bu + bv <= 1.0 + _BARY_TOL))
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
                        gap = np.abs(_dot(_rows(Ot, rows) - tier.first_vertex(tri), nrm))
                        ok = ~((t_e[h[fl]] < seg[rows] + eps) & (gap <= 2.0 * eps))  # self-hit
                    acc = ok & (tx < best_t[rows])
                    if len(rows) == m and acc.all():
                        best_t[:] = tx
                        if not distance_only:
                            nrm *= np.where(dn > 0.0, -1.0, 1.0)[:, None]   # toward the origin
                            best_s[:], best_n[:] = tier.tri_shape[tri], nrm
                    else:
                        k = acc.nonzero()[0]
                        r = rows[k]
                        best_t[r] = tx[k]
                        if not distance_only:
                            nk = nrm.take(k, axis=0)
                            nk *= np.where(dn[k] > 0.0, -1.0, 1.0)[:, None]   # toward the origin
                            best_s[r], best_n[r] = tier.tri_shape[tri[k]], nk
                    rej[fl[~ok]] = True
                # --- curved shells (sphere, cylinder, capsule)
                cv = (curved & ~rej).nonzero()[0]
                if len(cv):
                    rows = rows_h[cv]
                    nrm = tier.normal[ph[cv]]
                    leaving = None if exact else _dot(nrm, D[rows]) > 0.0
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
                        # (in C where the helper is: the same bits, without ~40 numpy calls a ray)
                        got = (packets.analytic(tier, sl, Ot[rr], D[rr], lo[rr], lim[rr], not distance_only)
                               if self.native else None)
                        ta, na = got if got is not None else self._analytic(tier, sl, Ot[rr], D[rr], lo[rr], lim[rr],
                                                                            not distance_only)
                        found = np.isfinite(ta)
                        better = found & (ta < best_t[rr])
                        r = rr[better]
                        best_t[r] = ta[better]
                        if na is not None:
                            na = na[better]
                            na[_dot(na, D[r]) > 0.0] *= -1.0
                            best_s[r], best_n[r] = tier.c_shape[sl[better]], na
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
            if delta is None:   # (EXACT: a first step of eps past a hit stuck at its start, a self-hit from 0)
                delta = np.full(m, 0.25 * eps if exact else eps)
            delta[rows] = np.where(stuck, delta[rows] * 4.0, eps)
            seg[rows] = np.maximum(te, seg[rows]) + delta[rows]
            act = rows[seg[rows] <= lim[rows] + eps]
            self._count("continued_rays", int(len(rows)))
        else:
            self._count("unresolved_rays", int(len(act)))
        return best_t, best_s, best_n
