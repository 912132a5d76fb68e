"""Rays of many copies of one world: the static geometry held once, each copy's moving bodies its own.

N independent copies of a world (a batched training environment) share everything that never
moves, so that is built once: ``static`` is a :class:`~.engine.RayEngine` holding the world's
solids (its static tier and planes). What moves -- the robots -- differs per copy, but every copy
has the same *slots* (robot 0, robot 1, ...), each with the same shapes, so ``movers`` holds one
template body per slot; a copy's robot is that template at the copy's pose (a robot's links, the
shapes riding its joints, are slots of their own owned by it, posed per copy by ``expand``). Copies overlap in
space (they all use the world's own coordinates, so a copy's rays see the static geometry exactly
as the single world's rays do) and never see each other: a ray carries its copy, and it is paired
only with the bodies of its own copy.

One :meth:`CopyRays.cast` covers every copy's rays of one ray kind:

* the robots' planes first (the template bodies' ``plane`` parts, analytic, never in a tier): each ray
  against its own copy's, each plane at that copy's pose as the single world composes it, with that
  world's float64 plane arithmetic (:func:`.planes.plane_terms`), its excluded slot's planes (its links' too) left out
  (a mount does not hide them: the single world casts planes with every ray); the static pass then
  goes only up to a ray's robot-plane hit, as that world's tiers go only up to its planes' hits, and
  a robot's plane wins a tie with a static tier's hit, never with a static plane (ordered first);
* the static pass is one :meth:`RayEngine.cast` of all the rays on ``static`` (which has no movers);
* the mover pass pairs each ray with the bodies of its copy (a dense (rays x slots) bounding-sphere
  test: the copy gives the candidates, no grid), drops its excluded owner and its mount, moves each
  pair into the body's frame with the same float64 products the single world's engine uses for
  one mover (``(O - T) @ R`` in the engine's summation order, ``exact._to_frame``, for all pairs at once, so the bits are the engine's), and traces all
  pairs of one template tier in ONE call -- a hundred robots' pairs cost one Embree call, not a
  hundred. Coherent runs (every copy's lidar meeting a robot or a link) too: each copy's pairs with
  one body are packed as the single world packs its lidar's pairs with that body (a coherent
  packet's lane can change with its other lanes), by the C pass itself (``seg_end``: packets never
  span two runs), in one call for the runs that start inside the tier's sphere and one for those
  that start outside it (their rays then start at the sphere, per row, as the single world's do).

A FAST cast whose data allows it takes a lean path (:meth:`CopyRays._lean_cast`): the planes (one
axis-aligned plane, a floor), the static tier and the broad phase in ONE C call (``sp_copy_cast``)
instead of RayEngine.cast's Python stages around the same C passes (the origins' box, pointers,
per-ray limits, the merge): the same answers, bit for bit (tests/test_copy_lean.py). The stages it
does not do are ruled out from the cast's data, never from who casts: an origin row within reach of
a curved shell (the pre-pass), origins outside the static tier's sphere, several or tilted planes,
an anchored tier, per-ray t_near; any of them, EXACT, or no packet helper: the general path.

Per ray, the answer is the single world's: the same static tier, the same body-frame rays, the
same tiers. What depends on the batch is only what the engine itself takes from a whole cast: the
float64 self-hit threshold ``1e-9 m + 1e-14 max|O|`` (max over the cast's origins, so a hit closer
than ~1 nm to a ray's origin could be judged differently) -- the same dependence a single world
has between casts of different sizes.
"""

from __future__ import annotations

import ctypes
import threading
from collections.abc import Sequence

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.blocks import MIN_RAYS, in_block
from sensorium.server.raycast.engine import RayEngine
from sensorium.server.raycast.exact import _CHUNK, _INF, _PRUNE, _SMALL, _dot, _minus, _param, _take
from sensorium.server.raycast.kinds import Precision, RayHits, RayKind
from sensorium.server.raycast.planes import plane_terms
from sensorium.server.raycast.trace import shell_spheres
from sensorium.server.world.geometry import Plane, Pose

__all__ = ["CopyRays"]


def _no_hits(n: int, distance_only: bool) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """``n`` rays' answers before any hit: distances inf, shapes -1, normals 0 (the last two None
    when only distances are asked)."""
    if distance_only:
        return np.full(n, _INF), None, None
    return np.full(n, _INF), np.full(n, -1, dtype=np.int64), np.zeros((n, 3))


class CopyRays:
    """Casts for ``copies`` copies of a world (see the module docstring).

    ``static``: an engine with the world's solids and no movable body. ``movers``: an engine with
    one movable template body per robot slot that has a body (``slot_body[r]`` its body index, None
    for a robot without one; the body's owner is the slot). ``shape_offset``: the number of shapes
    of ``static``; a hit on a robot is reported as ``shape_offset`` + its shape index in ``movers``
    (with solids added before robots, as a world's scene does, these are the single world's shape
    indices).

    ``owner``: each slot's robot (default: itself). A robot's links (the shapes riding its joints)
    are slots of their own after the robots' (their owner the robot, as the single world's link
    bodies are owned by their robot): a ray's ``exclude_slot`` drops its robot's links too, its
    ``mount_slot`` only the robot's own body. ``expand``: with links, ``(rot, pos)`` of the robots
    ``(C, robots, ...)`` -> every slot's ``(C, slots, ...)`` (the links' world poses per copy)."""

    def __init__(self, static: RayEngine, movers: RayEngine, slot_body: Sequence[int | None], shape_offset: int,
                 owner: Sequence[int] | None = None, expand=None):
        self.static = static
        self.movers = movers
        self.slot_body = list(slot_body)
        self.shape_offset = int(shape_offset)
        self.slots = len(self.slot_body)
        self.owner = np.arange(self.slots, dtype=np.int64) if owner is None else np.asarray(owner, dtype=np.int64)
        # the slots that are links (owned by another slot): their pairs with an excluded owner are dropped
        self._links = bool((self.owner != np.arange(self.slots)).any())
        self.expand = expand
        # the order the engine takes bodies in (ties between bodies: the earlier body's hit)
        self._body_rank = np.array([-1 if b is None else b for b in self.slot_body], dtype=np.int64)
        self._spheres: dict[str, tuple] = {}     # per variant: (tier per slot, anchor (R,3), r2 (R,), has body (R,))
        self.counters = {"casts": 0, "rays": 0, "mover_pairs": 0, "mover_traces": 0, "lean_casts": 0}
        self.lean = True     # FAST casts through sp_copy_cast where their data allows (False: the general path)
        self._local = threading.local()   # per thread: the lean path's job struct and scratch buffers
        self._static_kept: dict[str, tuple] = {}   # per variant: the lean job's static fields (_static_fields)
        self._planes: dict[str, tuple | None] = {}   # per variant: the robots' planes (_robot_planes)
        self._plane_kept: dict[int, tuple] = {}      # the copies' robot planes in the world (_plane_poses)

    @property
    def precision(self) -> Precision:
        return self.static.precision

    @precision.setter
    def precision(self, value: Precision | str) -> None:
        self.static.precision = value
        self.movers.precision = value

    def _slot_tiers(self, variant: str) -> tuple:
        got = self._spheres.get(variant)
        if got is None:
            eng = self.movers
            tiers: list = []
            anchor = np.zeros((self.slots, 3))
            r2 = np.full(self.slots, -1.0)           # no body (or nothing this ray kind sees): never paired
            for r, body in enumerate(self.slot_body):
                tier = None if body is None else eng._mover_tier(eng._bodies[body], variant)
                tiers.append(tier)
                if tier is not None:
                    anchor[r] = tier.anchor
                    r2[r] = tier.radius * tier.radius
            present = r2 >= 0.0
            # (the lean path's view of them: contiguous arrays and their addresses, made once)
            native = (anchor, r2, present.astype(np.uint8), bool(present.any()))
            got = self._spheres[variant] = (tiers, anchor, r2, present,
                                            (*native[:3], [a.ctypes.data for a in native[:3]], native[3]))
        return got

    def may_reach(self, slot: int, kind: RayKind, origins, directions, t_near, t_far,
                  skip_transparent: bool = False, margin: float = 1e-6) -> np.ndarray:
        """Which rays, given in slot ``slot``'s body frame, may meet its body: the box of the
        body's tier (its shells included) grown by ``margin`` -- conservative for the same rays
        moved into the frame from any pose (their rounding is ~1e-15 m). A rigidly mounted ray
        that fails it never meets that body, at any pose: pass the slot as its ``mount_slot``."""
        tiers = self._slot_tiers(self.movers._variant(kind, skip_transparent))[0]
        O = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
        D = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        tier = tiers[slot]
        if tier is None:
            return np.zeros(len(D), dtype=bool)
        lo = tier.V.min(axis=0) + tier.anchor - margin
        hi = tier.V.max(axis=0) + tier.anchor + margin
        with np.errstate(divide="ignore", invalid="ignore"):
            Dn = np.where(D == 0.0, 1e-300, D)
            ta, tb = (lo - O) / Dn, (hi - O) / Dn
        near = np.minimum(ta, tb).max(axis=1)
        far = np.maximum(ta, tb).min(axis=1)
        t0 = np.maximum(near, np.broadcast_to(np.asarray(t_near, dtype=np.float64), (len(D),)) - margin)
        t1 = np.minimum(far, np.broadcast_to(np.asarray(t_far, dtype=np.float64), (len(D),)) + margin)
        return t0 <= t1

    def cast(self, origins, directions, t_near, t_far, kind: RayKind, copy: np.ndarray, rot: np.ndarray,
             pos: np.ndarray, exclude_slot=-1, mount_slot=-1, skip_transparent: bool = False,
             distance_only: bool = False, directions32=None, coherent: bool = False, origin_rows=None,
             run: int = 0) -> RayHits:
        """Nearest hits of rays of several copies. ``copy``: (n,) the copy of each ray; ``rot``
        (C, R, 3, 3) and ``pos`` (C, R, 3): every copy's robot poses now; ``exclude_slot``: the
        robot (slot) whose body a ray ignores (scalar or (n,); -1 none), as ``exclude_owner``;
        ``mount_slot``: a robot whose body the ray is never paired with (-1 none): the robot a
        sensor is rigidly mounted on, whose hits the caller decides once in the body frame (as
        with ``RayEngine.cast(mount=...)``), or whose body it cannot reach (:meth:`may_reach`).
        ``coherent``: the rays come in runs from one origin each (every copy's lidar): traced as
        the single world traces one lidar's beams (coherent packets, FAST), so each beam gets the
        single world's answer. ``run`` > 0: the rays come in runs of ``run`` consecutive rays sharing
        one origin and one copy (a copy's lidar scan, its clearance rays): the broad phase works each
        run's origin out once (the same pairs). Other arguments as :meth:`RayEngine.cast`
        (``origin_rows``: the distinct origins, e.g. every copy's lidar position)."""
        O = np.asarray(origins, dtype=np.float64)
        D = np.asarray(directions, dtype=np.float64)
        n = len(O)
        t_near = _param(t_near, n, np.float64, float)     # uniform -> scalar, as the engine normalises it
        self.counters["casts"] += 1
        self.counters["rays"] += n
        if self.expand is not None and rot.shape[1] != self.slots:    # the robots' poses -> their links' too
            rot, pos = self.expand(rot, pos)
        # the robots' planes first, each ray against its own copy's (the single world casts its planes
        # before its tiers, every tier then up to the nearest plane hit): the static pass up to them
        planes = self._robot_plane_pass(O, D, n, t_near, t_far, kind, skip_transparent, copy, rot, pos, exclude_slot,
                                        distance_only) if n and self.slots else None
        if planes is not None:
            t_far = np.minimum(t_far, planes[0])
        lean = (self._lean_cast(O, D, n, t_near, t_far, kind, copy, rot, pos, exclude_slot, mount_slot,
                                skip_transparent, distance_only, directions32, coherent, origin_rows, run)
                if self.lean and self.static.native and self.static._precision is Precision.FAST else None)
        if lean is not None:
            hits, pr, pm, far = lean
            if planes is not None:
                hits = self._with_planes(hits, planes)
            if pr is not None and self._links:
                pr, pm = self._drop_owned(pr, pm, exclude_slot)
            if pr is None or not len(pr):
                return hits
            tiers = self._slot_tiers(self.movers._variant(kind, skip_transparent))[0]
            return self._mover_pass(hits, O, D, t_near, far, pr, pm, tiers, rot, pos, distance_only, coherent, run)
        hits = self.static.cast(O, D, t_near, t_far, kind=kind, skip_transparent=skip_transparent,
                                distance_only=distance_only, directions32=directions32, coherent=coherent,
                                origin_rows=origin_rows, run=run)
        if planes is not None:
            hits = self._with_planes(hits, planes)
        if n == 0 or not self.slots:
            return hits
        variant = self.movers._variant(kind, skip_transparent)
        tiers, anchor, r2, present, _ = self._slot_tiers(variant)
        if not present.any():
            return hits
        dist = hits.distance
        far = np.asarray(t_far, dtype=np.float64)
        far = float(far) if far.ndim == 0 else np.ascontiguousarray(np.broadcast_to(far, (n,)))
        copy = np.asarray(copy, dtype=np.int64).reshape(n)
        # broad phase: each ray against the bounding spheres of its own copy's bodies
        centre = pos + np.einsum("crij,rj->cri", rot, anchor)          # (C, R, 3): a conservative test only
        excl = exclude_slot if isinstance(exclude_slot, (int, np.integer)) else np.asarray(exclude_slot).reshape(n)
        mnt = mount_slot if isinstance(mount_slot, (int, np.integer)) else np.asarray(mount_slot).reshape(n)
        got = (packets.copy_pairs(O, D, copy, centre, r2, present, t_near, far, excl, mnt, dist, run)
               if self.static.native else None)
        if got is None:
            lo = np.broadcast_to(np.asarray(t_near, dtype=np.float64), (n,))
            got = _pairs(O, D, copy, centre, r2, present, lo, np.minimum(far, dist), excl, mnt)
        pr, pm = got
        if self._links:
            pr, pm = self._drop_owned(pr, pm, excl)
        if not len(pr):
            return hits
        return self._mover_pass(hits, O, D, t_near, far, pr, pm, tiers, rot, pos, distance_only, coherent, run)

    def _drop_owned(self, pr: np.ndarray, pm: np.ndarray, exclude_slot) -> tuple[np.ndarray, np.ndarray]:
        """The broad phase's pairs without those of a link whose owner is the ray's excluded slot
        (the broad phase compares slots; a link's owner is another slot). Each pair is judged on its
        own, so dropping one afterwards is the same as never pairing it."""
        owner = self.owner.take(pm % self.slots)
        link = owner != pm % self.slots
        if isinstance(exclude_slot, (int, np.integer)):
            drop = link & (owner == int(exclude_slot))
        else:
            drop = link & (owner == np.asarray(exclude_slot, dtype=np.int64).reshape(-1).take(pr))
        if not drop.any():
            return pr, pm
        keep = ~drop
        return pr[keep], pm[keep]

    def _robot_planes(self, variant: str) -> tuple | None:
        """The robots' planes ``variant`` sees, as the template bodies carry them: (the movers'
        :class:`_Planes`, each plane's slot), None when no robot has one."""
        got = self._planes.get(variant, False)
        if got is False:
            pl = self.movers._plane_set(variant)
            got = None
            if pl is not None:
                slot_of = {b: r for r, b in enumerate(self.slot_body) if b is not None}
                got = (pl, np.array([slot_of[b.index] for b in pl.bodies], dtype=np.int64))
            self._planes[variant] = got
        return got

    def _plane_poses(self, pl, slots: np.ndarray, rot: np.ndarray, pos: np.ndarray) -> tuple:
        """Every copy's robot planes in the world: (point, normal, x axis, y axis), each (C, K, 3),
        each plane's pose the single world's ``body pose.compose(local pose)`` (the same call: the
        same bits), made again only for the copies whose robots carrying one moved."""
        r_now = np.ascontiguousarray(rot[:, slots]).reshape(len(rot), -1)
        p_now = np.ascontiguousarray(pos[:, slots]).reshape(len(pos), -1)
        kept = self._plane_kept.get(id(pl))
        C, K = len(rot), len(slots)
        if kept is None or kept[0].shape != r_now.shape:
            out = tuple(np.empty((C, K, 3)) for _ in range(4))
            todo = range(C)
        else:
            r_was, p_was, out = kept   # (bits compared: a signed zero is a change)
            todo = np.flatnonzero((r_now.view(np.int64) != r_was.view(np.int64)).any(axis=1)
                                  | (p_now.view(np.int64) != p_was.view(np.int64)).any(axis=1)).tolist()
        for c in todo:
            for k, (r, local) in enumerate(zip(slots.tolist(), pl.local)):
                w = Pose(rot[c, r], pos[c, r]).compose(local)
                out[0][c, k], out[1][c, k], out[2][c, k], out[3][c, k] = (
                    w.translation, w.rotation[:, 2], w.rotation[:, 0], w.rotation[:, 1])
        self._plane_kept[id(pl)] = (r_now, p_now, out)
        return out

    def _robot_plane_pass(self, O: np.ndarray, D: np.ndarray, n: int, t_near, t_far, kind: RayKind,
                          skip_transparent: bool, copy, rot: np.ndarray, pos: np.ndarray, exclude_slot,
                          distance_only: bool) -> tuple | None:
        """The nearest hit of each ray on its own copy's robots' planes (never another copy's), with
        the single world's plane arithmetic (:func:`.planes.plane_terms`, each (ray, plane) on its
        own: the bits of that world's cast_planes): (dist (n,), shape (n,), normal (n, 3)) with inf,
        -1 and zeros where it meets none (shape and normal None with ``distance_only``), None when
        no ray meets one. A ray's excluded slot hides that robot's planes (its owner, as
        ``exclude_owner`` does); a mount does not (the single world casts planes with every ray).
        Dense: every ray against its copy's K planes, in blocks of rays (bounded temporaries)."""
        got = self._robot_planes(self.movers._variant(kind, skip_transparent))
        if got is None:
            return None
        pl, slots = got
        world = self._plane_poses(pl, slots, rot, pos)
        owners = self.owner[slots]          # (a link's planes: its robot's, which an excluded slot hides)
        copy = np.asarray(copy, dtype=np.int64).reshape(n)
        big = max(float(O.max()), -float(O.min()))
        eps64 = 1e-9 + 1e-14 * big          # the engine's float64 self-hit threshold for this cast
        near = np.broadcast_to(np.maximum(t_near, eps64), (n,)) if isinstance(t_near, np.ndarray) else \
            max(t_near, eps64)
        far = np.asarray(t_far, dtype=np.float64)
        far = float(far) if far.ndim == 0 else np.broadcast_to(far, (n,))
        excl = None if isinstance(exclude_slot, (int, np.integer)) and exclude_slot < 0 else (
            int(exclude_slot) if isinstance(exclude_slot, (int, np.integer)) else
            np.broadcast_to(np.asarray(exclude_slot, dtype=np.int64).reshape(-1), (n,)))
        dist, shape, normal = _no_hits(n, distance_only)
        hit = False
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # as the engine's casts
            for a in range(0, n, _CHUNK):
                sl = slice(a, min(n, a + _CHUNK))
                got = _plane_block(pl, slots, owners, world, O[sl], D[sl], copy[sl],
                                   near[sl, None] if isinstance(near, np.ndarray) else near,
                                   far[sl, None] if isinstance(far, np.ndarray) else far,
                                   excl[sl, None] if isinstance(excl, np.ndarray) else excl, distance_only)
                if got is None:
                    continue
                hit = True
                dist[sl] = got[0]
                if not distance_only:
                    shape[sl], normal[sl] = got[1], got[2]
        if not hit:
            return None
        if shape is not None:
            shape[shape >= 0] += self.shape_offset
        return dist, shape, normal

    def _with_planes(self, hits: RayHits, planes: tuple) -> RayHits:
        """The static pass's hits with the robots' plane hits: a robot's plane is nearer, or as near
        as a static tier's hit (the single world keeps its planes' hits on ties with a tier), but
        never wins a tie with a static plane (those come first among that world's planes)."""
        t, s, nrm = planes
        dist = hits.distance
        win = t < dist
        if s is not None:
            assert hits.shape is not None and hits.normal is not None
            entries = self.static._entries
            tie = (t == dist).nonzero()[0]
            if len(tie):
                st = hits.shape[tie]
                win[tie] = [k < 0 or not isinstance(entries[k].primitive, Plane) for k in st.tolist()]
        rows = win.nonzero()[0]
        if not len(rows):
            return hits
        dist = dist.copy()
        dist[rows] = t[rows]
        if s is None:
            return RayHits(dist, hits.normal, hits.shape)
        assert hits.shape is not None and hits.normal is not None
        shape, normal = hits.shape.copy(), hits.normal.copy()
        shape[rows], normal[rows] = s[rows], nrm[rows]
        return RayHits(dist, normal, shape)

    def _mover_pass(self, hits: RayHits, O: np.ndarray, D: np.ndarray, t_near, far, pr: np.ndarray, pm: np.ndarray,
                    tiers: list, rot: np.ndarray, pos: np.ndarray, distance_only: bool, coherent: bool,
                    run: int = 0) -> RayHits:
        """The mover pass of :meth:`cast` over the broad phase's (ray, copy * R + slot) pairs: each
        pair into its body's frame, one trace per template tier, the nearest body hit per ray where
        it is nearer than the static one (``hits``). Coherent runs (``run`` > 0): each body's pairs
        of one copy are packed on their own (:meth:`_trace_bodies`)."""
        R = self.slots
        dist = hits.distance
        lim = np.minimum(far, dist)
        self.counters["mover_pairs"] += len(pr)
        # pairs grouped by body, each body's rays in ray order (as the engine's one-mover path sees them)
        order = np.lexsort((pr, pm))
        pr, pm = pr[order], pm[order]
        rotf = rot.reshape(-1, 3, 3)
        posf = pos.reshape(-1, 3)
        # every pair into its body's frame at once, each row summed (x0 R0 + x1 R1) + x2 R2 as the
        # engine's _to_frame sums it for one body (elementwise products and sums: the same bits)
        Rg = rotf.take(pm, axis=0)
        x = O.take(pr, axis=0) - posf.take(pm, axis=0)
        Ob = (x[:, 0:1] * Rg[:, 0] + x[:, 1:2] * Rg[:, 1]) + x[:, 2:3] * Rg[:, 2]
        x = D.take(pr, axis=0)
        Db = (x[:, 0:1] * Rg[:, 0] + x[:, 1:2] * Rg[:, 1]) + x[:, 2:3] * Rg[:, 2]
        slot = pm % R
        t_all, s_all, n_all = _no_hits(len(pr), distance_only)
        exact = self.movers.precision is Precision.EXACT
        big = max(float(O.max()), -float(O.min()))     # max |coordinate| (no |O| temporary: 0.5 MB for a lidar)
        eps64 = 1e-9 + 1e-14 * big          # the engine's float64 self-hit threshold for this cast
        done: set[int] = set()
        for r in range(R):
            tier = tiers[r]
            if tier is None or id(tier) in done:
                continue
            done.add(id(tier))
            sel = np.flatnonzero(np.isin(slot, [q for q in range(R) if tiers[q] is tier]))
            if not len(sel):
                continue
            ob, db, rr = Ob[sel], Db[sel], pr[sel]
            tn, lm = _take(t_near, rr) if isinstance(t_near, np.ndarray) else t_near, lim[rr]
            if coherent and run > 0 and not exact:   # (EXACT's answers never depend on packets)
                res = self._trace_bodies(tier, ob, db, tn, lm, pm[sel], eps64, exact, distance_only)
            else:
                res = self._trace_pairs(tier, ob, db, tn, lm, eps64, exact, distance_only, coherent)
            if res is None:
                continue
            keep, res = res
            if keep is not None:
                sel = sel[keep]
            t_all[sel] = res[0]
            if not distance_only:
                body = np.array([self.movers._bodies[self.slot_body[q]].first if self.slot_body[q] is not None else 0
                                 for q in range(R)], dtype=np.int64)
                s_all[sel] = np.where(res[1] >= 0, res[1] + body[slot[sel]], -1)
                n_all[sel] = res[2]
        win = (t_all < dist[pr]).nonzero()[0]
        if not len(win):
            return hits
        # the nearest body per ray; equal distances: the earlier body (the engine takes bodies in order)
        keep = np.lexsort((self._body_rank.take(slot[win]), t_all[win], pr[win]))
        w = win[keep]
        first = np.ones(len(w), dtype=bool)
        first[1:] = pr[w][1:] != pr[w][:-1]
        w = np.sort(w[first])                  # by body, then ray (the pairs' order)
        rows = pr[w]
        dist = dist.copy()
        dist[rows] = t_all[w]
        if distance_only:
            return RayHits(dist, hits.normal, hits.shape)
        shape = hits.shape.copy()
        normal = hits.normal.copy()
        shape[rows] = self.shape_offset + s_all[w]
        # body frame -> world, each row summed (x0 R[:,0] + x2 R[:,2]) + x1 R[:,1] as the engine's
        # _from_frame sums it for one body
        Rw = rotf.take(pm[w], axis=0)
        x = n_all[w]
        normal[rows] = (x[:, 0:1] * Rw[:, :, 0] + x[:, 2:3] * Rw[:, :, 2]) + x[:, 1:2] * Rw[:, :, 1]
        return RayHits(dist, normal, shape)

    def _trace_pairs(self, tier, ob, db, tn, lm, eps64: float, exact: bool, distance_only: bool, coherent: bool):
        """One trace of a tier's pairs (in its body frames): (kept rows or None, the trace's
        answers), None when nothing is hit; many pairs: those missing the tier's tight bound
        dropped first (conservative)."""
        keep = None
        if len(ob) >= _PRUNE:
            keep = tier.may_hit(ob, db, tn, lm).nonzero()[0]
            if len(keep) == len(ob):
                keep = None
            elif not len(keep):
                return None
            else:
                ob, db, lm = ob[keep], db[keep], lm[keep]
                tn = tn[keep] if isinstance(tn, np.ndarray) else tn
        self.counters["mover_traces"] += 1
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # as the engine's casts
            res = self.movers._trace(tier, ob, db, tn, lm, -1, eps64, exact, None, distance_only, coherent=coherent)
        return None if res is None else (keep, res)

    def _trace_bodies(self, tier, ob, db, tn, lm, pm: np.ndarray, eps64: float, exact: bool, distance_only: bool):
        """:meth:`_trace_pairs` of coherent runs (a lidar's beams in every copy): each body's pairs
        of one copy (``pm``: copy * R + slot, in blocks, rays in order) packed on their own, as the
        single world traces one lidar's pairs with one body (a coherent packet's traversal can
        change a lane's answer with the packet's other rays: packets never mix two copies' beams).
        With the packet helper all copies' runs go in one call per group (:meth:`_trace_runs`), else
        one trace per run."""
        cuts = (np.flatnonzero(pm[1:] != pm[:-1]) + 1).tolist()
        if self.movers.native and tier.native(False) is not None:
            return self._trace_runs(tier, ob, db, tn, lm, np.array([0, *cuts], dtype=np.int64),
                                    np.array([*cuts, len(ob)], dtype=np.int64), eps64, distance_only)
        t, s, nrm = _no_hits(len(ob), distance_only)
        hit = False
        for a, b in zip([0, *cuts], [*cuts, len(ob)]):
            got = self._trace_pairs(tier, ob[a:b], db[a:b], tn[a:b] if isinstance(tn, np.ndarray) else tn, lm[a:b],
                                    eps64, exact, distance_only, True)
            if got is None:
                continue
            hit = True
            keep, res = got
            rows = np.arange(a, b) if keep is None else a + keep
            t[rows] = res[0]
            if not distance_only:
                s[rows], nrm[rows] = res[1], res[2]
        return (None, (t, s, nrm)) if hit else None

    def _trace_runs(self, tier, ob, db, tn, lm, a: np.ndarray, b: np.ndarray, eps64: float, distance_only: bool):
        """The runs ``[a[k], b[k])`` of :meth:`_trace_bodies` (FAST, each run's rows one origin in the
        body frame), each answered as its own trace answers it, in one C pass per group: each run of
        :data:`_PRUNE` pairs or more first pruned by the tier's bound (a per-row test, as its own
        trace prunes it), then the runs whose origin lies outside the tier's sphere (their own
        traces start each ray at the sphere, per row) apart from those inside (their traces keep one
        start): a group's pass packs each run on its own (``seg_end``) and starts every ray as its
        run's trace does, so every row gets that trace's bits."""
        m = len(ob)
        size = b - a
        keep = np.ones(m, dtype=bool)
        big = (size >= _PRUNE).nonzero()[0]
        if len(big):
            rows = np.concatenate([np.arange(a[k], b[k]) for k in big.tolist()])
            keep[rows] = tier.may_hit(ob[rows], db[rows], _take(tn, rows) if isinstance(tn, np.ndarray) else tn,
                                      lm[rows])
        run = np.repeat(np.arange(len(a)), size)
        # each row's origin outside the tier's sphere, as _trace_fast tests each row; a run is in
        # one group when all its rows are (a run of two origins, partly outside: a trace of its own)
        o32 = (_minus(ob, tier.anchor) if tier.anchored else ob).astype(np.float32)
        far = _dot(o32, o32) > np.float32(tier.radius * tier.radius)
        n_far = np.bincount(run, weights=far, minlength=len(a))
        t, s, nrm = _no_hits(m, distance_only)
        hit = False
        for k in ((n_far > 0) & (n_far < size)).nonzero()[0].tolist():
            got = self._trace_pairs(tier, ob[a[k]:b[k]], db[a[k]:b[k]], tn[a[k]:b[k]] if isinstance(tn, np.ndarray)
                                    else tn, lm[a[k]:b[k]], eps64, False, distance_only, True)
            if got is not None:
                hit = True
                rows = np.arange(a[k], b[k]) if got[0] is None else a[k] + got[0]
                t[rows] = got[1][0]
                if not distance_only:
                    s[rows], nrm[rows] = got[1][1], got[1][2]
        for group in (n_far == 0, n_far == size):
            sel = (keep & group[run]).nonzero()[0]
            if not len(sel):
                continue
            r = run[sel]
            ends = np.ones(len(sel), dtype=bool)      # a row ends its run's kept rows
            ends[:-1] = r[1:] != r[:-1]
            last = ends.nonzero()[0] + 1
            seg_end = np.repeat(last, np.diff(np.concatenate([[0], last]))).astype(np.int64)
            self.counters["mover_traces"] += 1
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # as the engine's casts
                res = self.movers._trace(tier, ob[sel], db[sel], _take(tn, sel) if isinstance(tn, np.ndarray) else tn,
                                         lm[sel], -1, eps64, False, None, distance_only, coherent=True,
                                         seg_end=seg_end)
            if res is None:
                continue
            hit = True
            t[sel] = res[0]
            if not distance_only:
                s[sel], nrm[sel] = res[1], res[2]
        return (None, (t, s, nrm)) if hit else None

    def _lean_cast(self, O: np.ndarray, D: np.ndarray, n: int, t_near, t_far, kind: RayKind, copy, rot, pos,
                   exclude_slot, mount_slot, skip_transparent: bool, distance_only: bool, directions32, coherent: bool,
                   origin_rows, run: int) -> tuple | None:
        """A FAST cast's static pass and broad phase in one C call (``sp_copy_cast``): (hits, pairs'
        rays or None, pairs' bodies, far) with the general path's values, or None where its data
        needs a stage the call does not do (several or tilted planes, an anchored tier, a curved
        shell near an origin, origins outside the tier's sphere, per-ray t_near, ...): the general
        path then answers. The engine's Python around its C passes -- parameter checks, the origins'
        box, the planes' and the tier's pointers, each ray's limits, the merge -- is what it saves."""
        lib = packets.library()
        st = self.static
        if lib is None or not 2 <= n <= _CHUNK or isinstance(t_near, np.ndarray) or st._movers \
                or O.shape != (n, 3) or D.shape != (n, 3) or not O.flags.c_contiguous:
            return None
        if directions32 is not None and (directions32.dtype != np.float32 or directions32.shape != (n, 3)):
            return None    # (the general path says what is wrong)
        variant = self.movers._variant(kind, skip_transparent)
        fields = self._static_fields(st, variant)
        if fields is None:
            return None
        plane, scene, curved, static, spheres = fields
        J, keep = self._job(n)
        tf = _param(t_far, n, np.float64, float)
        rows = None
        if origin_rows is not None and n > _SMALL:    # the engine's box of the origins from their rows
            rows = np.ascontiguousarray(origin_rows, dtype=np.float64)
            if rows.ndim != 2 or rows.shape[1] != 3 or not len(rows):
                return None
        if plane is None:
            J.plane = 0
        else:
            J.plane, J.axis, J.c, J.visual, J.sized, J.sid, J.pt, J.nz, J.ax, J.ay, J.half = plane
        if scene is None:
            J.scene = None
        else:
            J.scene, J.T, J.radius = scene
            J.n_shells, J.shell_c, J.shell_bound = curved if curved is not None else (0, None, None)
        if not D.flags.c_contiguous:
            D = np.ascontiguousarray(D)
        arrays = [O, D]
        if directions32 is not None:
            arrays.append(np.ascontiguousarray(directions32))
        far_arr = isinstance(tf, np.ndarray)
        if far_arr:
            tf = np.ascontiguousarray(tf)     # (a strided view: read as rows of 8 bytes in C)
            arrays.append(tf)
        if rows is not None:
            arrays.append(rows)
        t = np.empty(n)
        arrays.append(t)
        if not distance_only:
            s, nrm = np.empty(n, dtype=np.int64), np.empty((n, 3))
            arrays += [s, nrm]
        sphere_ptrs, present = spheres
        pairs = present and self.slots > 0
        if pairs:
            R = self.slots
            C = len(rot)
            rot = np.ascontiguousarray(rot, dtype=np.float64)
            pos = np.ascontiguousarray(pos, dtype=np.float64)
            if rot.shape != (C, R, 3, 3) or pos.shape != (C, R, 3):
                return None
            copy = np.ascontiguousarray(copy, dtype=np.int64).reshape(n)
            arrays += [copy, rot, pos]
            excl = exclude_slot if isinstance(exclude_slot, (int, np.integer)) else \
                np.ascontiguousarray(exclude_slot, dtype=np.int64).reshape(n)
            mnt = mount_slot if isinstance(mount_slot, (int, np.integer)) else \
                np.ascontiguousarray(mount_slot, dtype=np.int64).reshape(n)
            for a in (excl, mnt):
                if isinstance(a, np.ndarray):
                    arrays.append(a)
            out_ray, out_body, p_ray, p_body = packets.pair_buffers(n * R)
            if len(keep["centre"]) < C * R * 3:
                keep["centre"] = np.empty(C * R * 3)
                keep["p_centre"] = keep["centre"].ctypes.data
        p = iter(packets.addresses(arrays))
        J.n, J.O, J.D = n, next(p), next(p)
        J.d32 = next(p) if directions32 is not None else None
        J.near, J.distance_only, J.coherent, J.run = t_near, int(distance_only), int(coherent), max(0, int(run))
        J.far, J.far_value = (next(p), 0.0) if far_arr else (None, tf)
        J.threads = st.threads if n >= MIN_RAYS and not in_block() else 1
        J.n_rows, J.rows = (len(rows), next(p)) if rows is not None else (0, None)
        J.t = next(p)
        J.s, J.nrm = (None, None) if distance_only else (next(p), next(p))
        J.R = 0
        if pairs:
            J.C, J.R = C, R
            J.copy, J.rot, J.pos = next(p), next(p), next(p)
            J.excl, J.excl_value = (next(p), 0) if isinstance(excl, np.ndarray) else (None, int(excl))
            J.mnt, J.mnt_value = (next(p), 0) if isinstance(mnt, np.ndarray) else (None, int(mnt))
            J.anchor, J.r2, J.present = sphere_ptrs
            J.centre, J.out_ray, J.out_body = keep["p_centre"], p_ray, p_body
        job = keep["address"]
        got = lib.sp_copy_cast(job)
        if got < 0:
            return None
        st.counters["rays_cast"] += n
        self.counters["lean_casts"] += 1
        if static is not None:
            st._count("embree_calls", 1)
        if got == 1:   # rays FAST judges in the general loop (trace.py's redo), then the merge and pairs
            redo = keep["special"][:n].view(bool).nonzero()[0]
            tt, ss, nn = (t, None if distance_only else s, None if distance_only else nrm) if J.into_out else (
                keep["st_t"][:n], keep["st_s"][:n], keep["st_n"][:n])
            lim = tf if J.plane_hits == 0 else keep["lim"][:n]
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # as the engine's casts
                t2, s2, n2 = st._trace_loop(static, O[redo], D[redo], t_near, _take(lim, redo), -1, J.eps64, exact=False)
            tt[redo] = t2
            if not distance_only:
                ss[redo], nn[redo] = s2, n2
            lib.sp_copy_finish(job)
        hits = RayHits(t, None, None) if distance_only else RayHits(t, nrm, s)
        k = J.n_pairs
        if not k:
            return hits, None, None, tf
        return hits, out_ray[:k].copy(), out_body[:k].copy(), tf

    def _static_fields(self, st: RayEngine, variant: str) -> tuple | None:
        """The lean job's fields of ``variant``'s planes and static tier -- (plane's or None, the
        tier's (scene, tier, radius) or None, its shells' (count, centres, bounds) or None when it
        has no curved shell, the tier, the slots' spheres' addresses and whether any has a body) -- or None where the lean path cannot take them (several or tilted
        planes, an anchored tier, no native tier). Worked out on the first cast and again after
        the static engine changed (its epoch, or a rebuilt plane set or tier): cast after cast the
        same pointers, their look-ups saved."""
        planes = st._plane_set(variant)     # (built on the first cast after a change, as the engine does)
        static = st._static_tier(variant)
        kept = self._static_kept.get(variant)
        if kept is not None and kept[0] == st._epoch and kept[1] is planes and kept[2] is static:
            return kept[3]
        fields: tuple | None = None
        plane = scene = curved = None
        ok = True
        if planes is not None:
            planes.refresh(st._epoch)
            ok = planes.axis >= 0
            if ok:
                plane = (1, planes.axis, float(planes.nz[0, planes.axis]), int(planes.visual), int(planes.sized),
                         int(planes.sid[0]), *planes.native_rows())
        if ok and static is not None:
            tier = static.native(False)
            ok = not static.anchored and tier is not None
            if ok:
                if static.has_curved:
                    curved = static.__dict__.get("_shell_ptrs")
                    if curved is None:   # (the shells never change: their addresses taken once)
                        c, bound = shell_spheres(static)
                        curved = static._shell_ptrs = (len(c), c.ctypes.data, bound.ctypes.data)
                sc, built = static.scene(False)
                if built:
                    st._count("bvh_builds", built)
                scene = (sc.handle, tier, static.radius)
        if ok:
            fields = (plane, scene, curved, static, self._slot_tiers(variant)[4][3:])
        self._static_kept[variant] = (st._epoch, planes, static, fields)
        return fields

    def _job(self, n: int) -> tuple:
        """This thread's :class:`packets.CopyJob` and its scratch buffers (grown to the largest cast
        seen: no new pages cast after cast), their addresses set in the job once."""
        local = self._local
        keep = getattr(local, "keep", None)
        if keep is None or keep["cap"] < n:
            cap = max(n, 1024)
            J = keep["job"] if keep is not None else packets.CopyJob()
            keep = {"job": J, "address": ctypes.addressof(J), "cap": cap, "lim": np.empty(cap),
                    "far32": np.empty(cap, dtype=np.float32), "st_t": np.empty(cap),
                    "st_s": np.empty(cap, dtype=np.int64), "st_n": np.empty((cap, 3)),
                    "special": np.empty(cap, dtype=np.uint8), "d32": np.empty((cap, 3), dtype=np.float32),
                    "centre": np.empty(0), "p_centre": None}
            J.lim, J.far32, J.st_t, J.st_s, J.st_n, J.special, J.d32_buf = (
                keep[name].ctypes.data for name in ("lim", "far32", "st_t", "st_s", "st_n", "special", "d32"))
            local.keep = keep
        return keep["job"], keep


def _plane_block(pl, slots: np.ndarray, owners: np.ndarray, world: tuple, O: np.ndarray, D: np.ndarray, copy: np.ndarray,
                 lo, hi, excl,
                 distance_only: bool) -> tuple | None:
    """A block of :meth:`CopyRays._robot_plane_pass`: its rays against their copies' planes ``world``
    ((C, K, 3) points, normals, x and y axes), limits ``lo``, ``hi`` and excluded slots ``excl``
    (scalars or (m, 1); None: none). (dist, movers' shape index or -1, normal) of the nearest, None
    when no ray of the block meets one."""
    m = len(O)
    PT, NZ, AX, AY = world
    nz = NZ.take(copy, axis=0)                     # (m, K, 3): each ray its copy's planes
    nz0, nz1, nz2 = nz[:, :, 0], nz[:, :, 1], nz[:, :, 2]
    den = (D[:, 0:1] * nz0 + D[:, 1:2] * nz1) + D[:, 2:3] * nz2      # cast_planes' sum, element by element
    ok = den < 0.0 if pl.visual else den != 0.0
    if excl is not None:
        ok &= owners != excl
    if not np.count_nonzero(ok):
        return None
    pt = PT.take(copy, axis=0)
    axes = [None, None]
    if pl.sized:
        axes = [(a[:, :, 0], a[:, :, 1], a[:, :, 2]) for a in (AX.take(copy, axis=0), AY.take(copy, axis=0))]
    t = plane_terms(O, D, (pt[:, :, 0], pt[:, :, 1], pt[:, :, 2]), (nz0, nz1, nz2), axes[0], axes[1],
                    (pl.half[:, 0], pl.half[:, 1]), den, ok, lo, hi, pl.sized)
    if not np.count_nonzero(ok):
        return None
    np.copyto(t, _INF, where=~ok)
    col = np.argmin(t, axis=1)        # the nearest plane; ties keep the first (the single world's order)
    ar = np.arange(m)
    dist = t[ar, col]
    if distance_only:
        return dist, None, None
    hit = (dist < _INF).nonzero()[0]
    shape = np.full(m, -1, dtype=np.int64)
    normal = np.zeros((m, 3))
    c = col[hit]
    shape[hit] = pl.sid[c]
    normal[hit] = nz[hit, c] * (1.0 - 2.0 * (den[hit, c] > 0.0))[:, None]   # toward the origin
    return dist, shape, normal


def _pairs(O, D, copy, centre, r2, present, lo, lim, excl, mnt) -> tuple[np.ndarray, np.ndarray]:
    """The broad phase of :meth:`CopyRays.cast` in numpy (``packets.copy_pairs`` does it in one C
    pass): (ray, copy * R + slot) pairs, slot by slot, each slot's rays ascending."""
    n = len(O)
    R = len(r2)
    pr_list, pm_list = [], []
    valid = lim >= lo
    for r in range(R):
        if not present[r]:
            continue
        cand = valid
        for skip in (excl, mnt):      # rays that ignore this body (excluded owner, mount)
            if isinstance(skip, np.ndarray):
                cand = cand & (skip != r)
            elif skip == r:
                cand = None
                break
        if cand is None:
            continue
        rows = cand.nonzero()[0]
        if not len(rows):
            continue
        every = len(rows) == n          # no ray skips this body: the arrays as they are
        rc = copy if every else copy[rows]
        rel = np.ascontiguousarray(centre[:, r]).take(rc, axis=0)
        rel -= O if every else O.take(rows, axis=0)
        Dr = D if every else D.take(rows, axis=0)
        b = np.einsum("ij,ij->i", rel, Dr)
        e2 = np.einsum("ij,ij->i", rel, rel)
        tc = np.minimum(np.maximum(b, lo if every else lo[rows]), lim if every else lim[rows])
        near = (e2 - tc * (b + b - tc) <= r2[r] + 1e-9 * (1.0 + e2)).nonzero()[0]
        if len(near):
            pr_list.append(rows[near])
            pm_list.append(rc[near] * R + r)
    if not pr_list:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(pr_list), np.concatenate(pm_list)
