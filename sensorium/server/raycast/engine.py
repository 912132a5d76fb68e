"""Ray-query engine: Embree (float32 BVH traversal) + float64 refinement.

The public cast API (:class:`RayEngine`).  The package is split by job: :mod:`.kinds` (value
types), :mod:`.exact` (float64 kernels), :mod:`.tiers` (Embree scenes), :mod:`.packets` (Embree's
packet traversal through a small C helper, when a compiler is there; else embreex), :mod:`.blocks`
(large casts in ray blocks on both cores), :mod:`.movers` (moving bodies, broad phase, Mount),
:mod:`.planes` (analytic planes), :mod:`.trace` (tracing one tier) and :mod:`.refine` (float64
refinement, curved-shell pre-pass).

Speed (measured in ``sensorium bench``, peers section)
------------------------------------------------------
* Traversal: packets of 16 rays through the Embree library embreex loaded; a FAST scan from one
  origin as coherent packets (~3.4x embreex's one ray per call on one thread), everything else as
  incoherent ones (embreex's answers bit for bit; see :mod:`.packets` for the bounded difference
  of coherent packets).  Without a C compiler: embreex, the same answers.
* Judging in C: with the packet path, the same C helper also judges each tier's hits where the
  numpy code of :mod:`.trace` and :mod:`.refine` would: FAST's side, self-hit and limit tests
  (``sp_fast_pass``), and EXACT's whole loop for a tier with edge guards or no risky edge
  (``sp_exact_pass``: the guards' second look, the float64 plane and barycentric check of flat hits
  with vertex rings and nearby triangles near edges, the true surface of curved hits, rays continued
  past rejected hits).  The same formulas in the same order, compiled without fused multiply-adds:
  the same bits (tests/test_native_judging.py compares them with ``RayEngine.native = False``, the
  numpy path on the same traversal).  A small cast's fixed cost is then mostly the Python around
  the calls (a 360-ray FAST scan: ~0.6 M instructions, Embree ~0.25 M of them; callgrind).
* Threads: a cast of >= ``blocks.MIN_RAYS`` rays runs its planes and static tier in blocks on
  ``RayEngine.threads`` threads (default: the cores this process may use; ``SENSORIUM_THREADS``),
  and so do a lidar's Mount pairs (listed on the calling thread while the workers start on their
  blocks). A FAST cast of up to ``_CHUNK`` rays through the packet path is one C pass instead,
  which traces parts of the batch on POSIX threads itself (packets.c, ``sp_fast_pass``): Python
  blocks would each repeat the cast's Python stages (measured: LidarAvoid x64's 23,040 beams were
  slower on 2 threads than on 1 that way). No ray's answer depends on its block or on the other rays of
  its batch (world-to-frame rotations are summed in one fixed order, never by BLAS; a curved
  shape's frame as einsum sums it, a sum of zeros being +0.0, whether one shape or several are
  refined together), so the bits are the same on any number of threads.  No BLAS call runs beside
  the blocks either (OpenBLAS's own threads fight them: ~10x slower on a busy 2-core machine).

Architecture
------------
* Static tier: the shapes of all static bodies (added static, at the pose they were added at)
  that a ray kind sees, in ONE Embree scene.  Its vertices are stored relative to the bounding-box centre (the *anchor*, subtracted
  in float64 before the float32 conversion; skipped when the geometry already surrounds the
  origin) so worlds far from the origin keep float32 precision.
* Mover tiers: a mover (``movable=True`` body, or a static body while away from the pose it was
  added at; put back there, it is in the static tier again: a reset reads as the loaded world, bit
  for bit under FAST too, whose float32 answers differ by an ulp between the frames) is cast against a
  scene of its shapes in its BODY frame, built once and shared by every mover with the same shapes
  (same primitives and local poses: a hundred identical robots cost one build).  Moving a body
  never rebuilds anything.  Per cast, a broad phase finds the (ray, mover) pairs whose segment
  passes within the mover's bounding sphere (excluded owners dropped): one dense vectorised test
  for few movers or small batches, else a uniform grid keyed by the segment midpoints.  The pairs
  of each shared scene are moved into their body frames in float64; when there are many, those
  whose segment misses a tight bound of the scene (the shell's own cylinder for a round body, else
  its box) are dropped; the rest go to ONE Embree call per shared scene.  Rays rigidly mounted on
  movers (``cast(mount=...)``: sensors on robots) never meet their own mount here, and bodies are
  paired before rays; with a :class:`Mount` passed again and again, the pairing is kept between
  casts as lists with margins (see :mod:`.movers`).  A FAST lidar's own-body hits (distances only,
  scalar limits) are traced once in the body frame and kept with its Mount (``_apply_own_hits``):
  the per-cast answers, the rounding of the body-frame rays at the first cast aside.
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
  meshes, the plain scenes leak ~4% of rays; robust ones plus the repair below leak none.  The
  EXACT scene of a tier with few risky edges also holds their guards (:mod:`.guards`) as a second
  geometry, beside a copy without them (built together, one build).
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
  whose refinement misses are continued past the hit (bounded loop).  Embree's barycentrics are
  trusted to pick the triangle only where they lie farther inside it than float32 rounding can
  move the hit (``h_min`` margin); elsewhere the plane hit's float64 barycentrics decide.
* EXACT repair rule (one cast; :mod:`.guards` proves it): after one watertight float32 cast a
  float64 hit can be missed only where the float64 ray passes within float32 reach (< eps) of a
  *risky* edge -- a boundary edge, or one between faces at an angle (box edges); curved shells
  are inflated beyond that reach instead.  Thin prisms around the risky edges sit in the EXACT
  scene: a ray that meets one is tested in float64 against that edge's triangles and their vertex
  rings (and those of edges whose prisms come close), the same past every further prism up to its
  hit, and then gets the hit of the scene without prisms (``counters["edge_guard_hits"]`` counts
  the float64 hits they found).  A tier with many risky edges (a curved or terrain mesh alone:
  more than 1.2 per flat triangle and prisms adding more than 4 triangles per triangle of the
  tier, or 20,000 edges; candidate lists past their budget, see :mod:`.guards`) keeps the former
  repair instead: each Embree cast paired
  with a copy offset 4 float32 ulps perpendicular to the ray, whose nearer hits are taken when the
  float64 ray hits that triangle or a neighbour (``counters["leak_repairs"]``).

Epsilons (per tier; res = float32 spacing at the tier's radius in the anchored frame)
* ``eps`` = max(1e-6 m, 8 res): self-hit distance and continuation step.  EXACT casts start at
  max(t_near - eps, 1e-6 m): a hit its float64 refinement puts before the limit below (the
  surface a ray starts on) is continued from ``eps`` past it, and a surface nearer than ``eps``
  is seen (a static tier spanning 1e5 m has eps ~ 3 cm).  FAST casts start at t_near; a hit closer than
  ``eps`` whose plane passes within 2 eps of the origin is a self-hit and is redone from ``eps``.
  So a sensor flush with a surface never reports that surface at t ~ 0.  A room-sized world gives
  eps = 1e-6 m.
* Refined (EXACT) and analytic hits must also satisfy t >= t_near and t >= 1e-9 m + 1e-14 max|O|.

Known limits (measure-zero in practice)
* Two surfaces closer together along a ray than float32 resolution (~res) may come out in either order.
* A surface within ``eps`` beyond a rejected or continued hit can be skipped.
* EXACT guards: a float64 hit on a flat triangle seen at grazing incidence alpha can be missed
  when another surface lies less than ~eps / sin(alpha) behind it (the float32 ray crosses the
  guard past that surface), or across more than one coplanar sliver triangle from its risky edge.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import threading
from collections.abc import Sequence

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.blocks import MIN_RAYS, available, split
from sensorium.server.raycast.blocks import run as run_blocks
from sensorium.server.raycast.exact import (
    _CHUNK,
    _DENSE_PAIRS,
    _FEW_MOVERS,
    _INF,
    _PRUNE,
    _SMALL,
    _TINY,
    _best_per_row,
    _from_frame,
    _full,
    _minus,
    _one_row,
    _param,
    _strictly_increasing,
    _take,
    _to_frame,
)
from sensorium.server.raycast.kinds import Precision, RayHits, RayKind, ShapeEntry
from sensorium.server.raycast.movers import (
    Mount,
    Riding,
    _Body,
    _grid_pairs,
    _mounted_pairs,
    _Movers,
    _near_pairs,
    _sphere_pairs,
    mount_candidates,
    mount_state,
    one_origin_pairs,
    with_own_pairs,
)
from sensorium.server.raycast.planes import _Planes, cast_planes
from sensorium.server.raycast.tiers import _Tier, new_device
from sensorium.server.raycast.trace import TierTracer
from sensorium.server.world.geometry import Plane, Pose

__all__ = ["RayKind", "Precision", "ShapeEntry", "RayHits", "RayEngine", "Mount", "Riding"]


# variants: which shapes a scene holds
_V_VISUAL, _V_BOUNDING, _V_OPAQUE, _V_SHADOW = "visual", "bounding", "bounding-opaque", "shadow"
# a variant whose scenes are another's when no shape tells them apart (built once, shared)
_NARROWS = {_V_OPAQUE: _V_BOUNDING, _V_SHADOW: _V_VISUAL}
_NOWHERE = Pose.identity()   # a removed body's pose (its own let go)


def _sees(e: ShapeEntry, variant: str) -> bool:
    if variant == _V_VISUAL:
        return e.visual and not e.transparent
    if variant == _V_BOUNDING:
        return e.bounding
    if variant == _V_SHADOW:
        return e.visual and not e.transparent and e.casts_shadow
    return e.bounding and not e.transparent


def _items_key(items) -> tuple:
    """What a tier is built of (``_Tier``'s items: shape number, primitive, pose), as a dict key."""
    return tuple((i, prim, pose.rotation.tobytes(), pose.translation.tobytes()) for i, prim, pose in items)


# static tiers kept by their items (_drop_static's keep_built): two static sets' worth of the variants'
_STATIC_KEPT = 8
_BOUND_ROWS = 32768   # rows of a large cast_local's bound test at a time (its temporaries stay in the cache)


class RayEngine(TierTracer):
    """Nearest-hit ray queries against bodies of shapes (see module docstring)."""

    def __init__(self, precision: Precision = Precision.EXACT) -> None:
        self._precision = Precision(precision)
        self._device = new_device()
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
        self._static_items: dict[tuple, _Tier | None] = {}   # the static tiers by their shapes (_items_key)
        self._shared: dict[tuple, _Tier | None] = {}   # body-frame tiers by their shapes (_items_key)
        self._epoch = 0                                 # bumped by every set_body_pose, add and removal
        # bumped whenever which rays see a shape changes (set_shape_seen): hits a caller kept are stale then
        self.seen_version = 0
        self.threads = available()   # threads a large cast may use (see .blocks; 1: the calling thread only)
        self.native = True   # judge and refine hits in packets.c where the packet path is on (the same answers)
        self._counting = threading.Lock()
        self.counters: dict[str, int] = {
            "bvh_builds": 0, "embree_calls": 0, "rays_cast": 0, "leak_repairs": 0,
            "continued_rays": 0, "unresolved_rays": 0, "edge_guard_hits": 0, "neighbour_lists": 0, "ray_lists": 0,
            "unbounded_mounts": 0, "local_pruned": 0, "riding_rays": 0,
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
        self._bodies.append(_Body(list(range(first, len(self._entries))), pose, int(owner), bool(movable), body,
                                  baked=None if movable else pose))
        self._rot = np.concatenate([self._rot, pose.rotation[None]])
        self._pos = np.concatenate([self._pos, pose.translation[None]])
        self._epoch += 1               # a body added while casting (a Supervisor's import): caches rebuild
        self._planes.clear()
        if movable:
            self._movers.append(self._bodies[-1])
            self._mover_tables.clear()
        else:
            self._drop_static()
        return body

    def set_body_pose(self, body: int, pose: Pose) -> None:
        b = self._bodies[body]
        if b.removed:
            raise ValueError(f"body {body} was removed")
        b.pose = pose
        self._epoch += 1
        self._rot[body] = pose.rotation
        self._pos[body] = pose.translation
        if b.baked is None:   # added movable: a mover for good
            return
        # A body added static is cast in the world-frame static tier while it is at the pose it was
        # added at, bit for bit, and as a mover (rays taken into its frame) while it is elsewhere: a
        # body put back (a reset, loadState) reads as at load, also under FAST precision, whose
        # float32 answers differ by an ulp between the two frames.
        home = pose is b.baked or (pose.translation.tobytes() == b.baked.translation.tobytes()
                                   and pose.rotation.tobytes() == b.baked.rotation.tobytes())
        if home == b.mover:
            b.mover = not home
            if home:
                self._movers.remove(b)
            else:   # in body order: the movers' table a function of which bodies are away, not of history
                bisect.insort(self._movers, b, key=lambda m: m.index)
            self._drop_static(keep_built=True)
            self._mover_tables.clear()

    def remove_body(self, body: int) -> None:
        """Take a body out of every ray query for good (a Supervisor's ``node.remove()``): a mover
        leaves the movers' tables, a static body the static tier (rebuilt on the next cast, as a
        static body's first move does). Every other body's and shape's number is unchanged; the last
        bodies, once all removed, leave the tables and the next ones added take their numbers again
        (a Supervisor importing and removing solids for days: bounded tables), while a removed body
        followed by one still there keeps its number and an empty entry. Casts in a world that never
        removes do no more work."""
        b = self._bodies[body]
        if b.removed:
            return
        b.removed = True
        if b.mover:
            self._movers.remove(b)
        self._forget_tiers(b)
        b.pose = _NOWHERE
        while self._bodies and self._bodies[-1].removed:   # the last bodies removed: their slots are free again
            last = self._bodies.pop()
            del self._entries[last.first if last.shapes else len(self._entries):]
            del self._shape_body[len(self._entries):]
        if len(self._owner_of) != len(self._entries):
            self._owner_of = self._owner_of[:len(self._entries)].copy()
            self._rot, self._pos = self._rot[:len(self._bodies)].copy(), self._pos[:len(self._bodies)].copy()

    def set_shape_seen(self, shape: int, transparent: bool, casts_shadow: bool) -> None:
        """Which rays see a shape, changed (a Supervisor's ``transparency`` crossing 0 or 1: see
        :class:`ShapeEntry`): its body's scenes are made again at the next cast, as after a removal --
        the static tier for a static body, else the body's own tiers and the movers' table -- from
        the same items a world loaded with these flags builds them of (the same answers, bit for bit).
        Every body and shape keeps its number; a body-frame tier no body uses any more is let go (a
        Supervisor hiding and showing a shape for days keeps bounded tables). Nothing happens when
        the flags are the same."""
        e = self._entries[shape]
        if e.transparent == bool(transparent) and e.casts_shadow == bool(casts_shadow):
            return
        self._entries[shape] = dataclasses.replace(e, transparent=bool(transparent), casts_shadow=bool(casts_shadow))
        self._forget_tiers(self._bodies[self._shape_body[shape]])
        self.seen_version += 1

    def set_shape_poses(self, poses: dict[int, Pose]) -> None:
        """Shapes moved within their bodies (a Supervisor set a Pose inside a solid): each one's pose in its
        body's frame now (``ShapeEntry.local_pose``); the scenes holding them are made again at the next
        cast, as after :meth:`set_shape_seen`, from the same items a world loaded with these poses builds
        them of. Every body and shape keeps its number."""
        bodies = set()
        for shape, local in poses.items():
            self._entries[shape] = dataclasses.replace(self._entries[shape], local_pose=local)
            bodies.add(self._shape_body[shape])
        for body in sorted(bodies):
            self._forget_tiers(self._bodies[body])

    def _forget_tiers(self, b: _Body) -> None:
        """The scenes holding body ``b``'s shapes forgotten (made again on use): the planes, the static
        tier of a static body, a mover's own tiers and the movers' tables; body-frame tiers no mover
        uses any more leave the shared table."""
        self._epoch += 1
        self._planes.clear()
        if b.mover:
            self._mover_tables.clear()
        else:
            self._drop_static()
        old, b.tiers = b.tiers, {}
        # its body-frame tiers, when no body left uses them (a Supervisor randomising a moved solid's
        # size between episodes would otherwise keep one Embree scene per size for good)
        used = {id(t) for m in self._bodies for t in m.tiers.values()}
        gone = {id(t) for t in old.values() if t is not None and id(t) not in used}
        if gone:
            self._shared = {k: t for k, t in self._shared.items() if id(t) not in gone}

    @property
    def held_tiers(self) -> int:
        """The Embree tiers held now (the static tiers and the body-frame tiers, each counted once)."""
        return len({id(t) for t in (*self._static_items.values(), *self._shared.values()) if t is not None})

    @property
    def shape_count(self) -> int:
        """The shapes numbered now: every body's but those of the last bodies removed (whose numbers the
        next bodies added take again)."""
        return len(self._entries)

    def body_shapes(self, body: int) -> list[int]:
        """The shape numbers of ``body``."""
        return list(self._bodies[body].shapes)

    def shape_owner(self, shape: int) -> int:
        return int(self._owner_of[shape])

    def shape_body(self, shape: int) -> int:
        return self._shape_body[shape]

    # ---- lazy builds ------------------------------------------------------------------------

    def _variant(self, kind: RayKind, skip_transparent: bool) -> str:
        if kind != RayKind.BOUNDING and kind != RayKind.VISUAL:
            RayKind(kind)  # raises ValueError for anything else (the enum call costs ~1 us: only here)
            return _V_SHADOW
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

    def _narrows(self, variant: str, bodies) -> bool:
        """Whether ``variant`` sees fewer of these bodies' triangle shapes than the variant it narrows
        (else it shares that variant's scenes): a bounding shape that is transparent, a visual one that
        casts no shadow."""
        wider = _NARROWS[variant]
        return any(_sees(e, wider) and not _sees(e, variant) and not isinstance(e.primitive, Plane)
                   for b in bodies for e in map(self._entries.__getitem__, b.shapes))

    def _static_tier(self, variant: str) -> _Tier | None:
        """The world-frame tier of the static bodies' shapes seen by ``variant``: one tier for
        every variant that sees the same shapes (bounding and visual rays, where each shape is seen
        by both: a tier is made of its items alone, so the two would hold the same arrays and BVH)."""
        if variant not in self._static:
            statics = [b for b in self._bodies if not b.mover and not b.removed]
            if variant in _NARROWS and not self._narrows(variant, statics):
                self._static[variant] = self._static_tier(_NARROWS[variant])
            else:
                items = [i for b in statics for i in self._items(b, variant, True)]
                key = _items_key(items)
                tier = self._static_items.pop(key) if key in self._static_items else self._build(items, self._owner_of)
                self._static_items[key] = tier      # the most recently used last
                while len(self._static_items) > _STATIC_KEPT:
                    del self._static_items[next(iter(self._static_items))]
                self._static[variant] = tier
        return self._static[variant]

    def _drop_static(self, keep_built: bool = False) -> None:
        """Forget the static tiers (a body added, removed, seen otherwise, or leaving or joining the
        static bodies): rebuilt on use. ``keep_built`` (the same shapes, a body away or back): the tiers
        already built stay at hand by their items, the last few of them, so a solid moved away and put
        back again and again builds nothing after its first round trip."""
        self._static.clear()
        if not keep_built:
            self._static_items.clear()

    def _mover_tier(self, body: _Body, variant: str) -> _Tier | None:
        """The body-frame tier of a mover, shared by all bodies with the same shapes (primitive and
        local pose) seen by the variant, and by the variants that see the same shapes.  Shared tiers carry no owner: exclusion is decided per
        (ray, mover) pair in the broad phase."""
        if variant not in body.tiers:
            if variant in _NARROWS and not self._narrows(variant, [body]):
                body.tiers[variant] = self._mover_tier(body, _NARROWS[variant])
            else:
                items = self._items(body, variant, False)
                key = _items_key(items)        # (a variant seeing the same shapes shares the tier)
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
            items = [(sid, b) for b in self._bodies if not b.removed for sid in b.shapes
                     if isinstance(self._entries[sid].primitive, Plane) and _sees(self._entries[sid], variant)]
            self._planes[variant] = (_Planes(items, self._entries, self._owner_of, variant in (_V_VISUAL, _V_SHADOW))
                                     if items else None)
        return self._planes[variant]

    # ---- casting ----------------------------------------------------------------------------

    def cast(self, origins, directions, t_near=0.0, t_far=np.inf, kind=RayKind.BOUNDING,
             exclude_owner=-1, skip_transparent=False, mount=None, distance_only=False,
             directions32=None, coherent: bool = False, origin_rows=None, run: int = 0,
             riding: Riding | None = None) -> RayHits:
        """Nearest hits of rays ``origins + t directions``, t in [t_near, t_far] (scalars or per ray).

        ``mount``: optional (n,) body index each ray is rigidly mounted on (-1: none).  Such a ray
        is never tested against its mount body (a moving body): the caller decides those hits
        once, in the body frame, with :meth:`cast_local`, and keeps the nearer of the two.  It
        also lets the broad phase skip, in one test per body, the rays of bodies whose rays cannot
        reach any other moving body (the rays of 100 robots' sensors, instead of one grid lookup
        per ray).  A :class:`Mount` (the same rays cast again, step after step) keeps that pairing
        between casts: a neighbour list of the bodies and, per neighbour, the rays that can reach
        it, each redone only when something moved by more than a margin; the answers are the same
        as with the plain array.

        ``distance_only``: the caller reads only ``distance`` (a lidar); the normals and shape ids
        are then skipped (returned as None) with the work that only serves them, with the same
        distances.  Origins may be a broadcast array (one origin for all rays), never written.

        ``directions32``: optional ``directions.astype(float32)`` the caller keeps (a lidar whose
        beams did not turn since the last scan); it is handed to Embree instead of rounding again.

        ``coherent``: the rays come in runs from one origin each (the lidars of a batched world's
        copies, one after another): FAST traces them as coherent packets, as it does a one-origin
        cast. ``run`` > 0: the runs' length; each run is then packed as its own one-origin cast packs
        it (a packet never spans two runs), so each ray gets the answer of its own lidar's one-origin
        cast -- a coherent packet's traversal can change a lane's answer with the packet's other rays
        (seen in FAST's float32 far from the origin), so this holds only with ``run``.

        ``origin_rows``: optional (k, 3) float64 array of the rays' distinct origins -- every ray's
        origin is one of its rows and every row is some ray's origin (the scan origins of a batched
        lidar cast) -- from which the cast takes the largest coordinate and the box of the origins
        (the same values) instead of passes over all n rows; where they are a few per ray, FAST
        also screens the curved shells' pre-pass by them (unit directions, as that pre-pass's
        one-origin screen assumes: every start point lies within t_near of its row).

        ``riding``: the rays (from one origin, ``mount`` None) ride that :class:`Riding`'s body, which
        they see: while their origin lies inside the body's bounding sphere, only the rays it keeps
        are paired with that body (the others cannot meet it), with the same answers."""
        O = np.asarray(origins, dtype=np.float64)
        D = np.asarray(directions, dtype=np.float64)
        if O.ndim == 1:
            O, D = O.reshape(1, 3), D.reshape(1, 3)
        if O.shape != D.shape or O.ndim != 2 or O.shape[1] != 3:
            raise ValueError(f"origins/directions must both be (n,3), got {O.shape} and {D.shape}")
        if directions32 is not None and (getattr(directions32, "dtype", None) != np.float32
                                         or directions32.shape != D.shape):
            raise ValueError(f"directions32 must be the directions as a float32 {D.shape} array")
        n = len(O)
        t_near = _param(t_near, n, np.float64, float)
        t_far = _param(t_far, n, np.float64, float)
        excl = _param(exclude_owner, n, np.int64, int)
        if isinstance(mount, Mount):   # the same rays cast again: what rigid mounting fixes is kept
            if len(mount) != n:
                raise ValueError(f"mount must hold one body per ray: {len(mount)} for {n} rays")
            if n and (mount.hi >= len(self._bodies) or mount.lo < -1):
                raise ValueError(f"mount must hold body indices in [-1, {len(self._bodies) - 1}]")
        elif mount is not None:
            mount = np.asarray(mount, dtype=np.int64).reshape(n)
            if n and (int(mount.max()) >= len(self._bodies) or int(mount.min()) < -1):
                raise ValueError(f"mount must hold body indices in [-1, {len(self._bodies) - 1}]")
        if riding is not None and (mount is not None or len(riding) != n or (n > 1 and O.strides[0] != 0)):
            raise ValueError("riding takes one-origin rays (a broadcast origin) without a mount, one per ray")
        self.counters["rays_cast"] += n
        variant = self._variant(kind, skip_transparent)
        # builds happen on the first cast after a change, even with no rays
        planes = self._plane_set(variant)
        static = self._static_tier(variant)
        movers = self._mover_table(variant) if self._movers else None
        if n == 0:
            return RayHits(np.zeros(0), np.zeros((0, 3)), np.zeros(0, dtype=np.int64))
        ride = None if riding is None or movers is None else self._riding(movers, riding, variant)
        # largest |coordinate| of the origins (a Python max beats two numpy reductions on a few rays)
        box = rows = None
        if O.strides[0] == 0:   # one origin for all rays (a broadcast array)
            big = max(map(abs, O[0].tolist()))
        elif origin_rows is not None and n > _SMALL:   # the same rows' values: the same max, min and box
            rows = np.asarray(origin_rows, dtype=np.float64)
            box = packets.box3(rows) if self.native else None   # (one C pass: numpy reduces 3 columns slowly)
            if box is None:
                box = (rows.min(axis=0), rows.max(axis=0))   # (rows also screen the curved shells: _trace_fast)
            big = max(float(box[1].max()), -float(box[0].min()))
        else:
            big = max(map(abs, O.ravel().tolist())) if n <= _SMALL else max(float(O.max()), -float(O.min()))
        # one errstate for the whole cast: inf/NaN are handled explicitly (entering the context
        # costs as much as a few numpy calls, so the helpers do not open their own)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            threads = self.threads
            # one part: split's answer, or a FAST cast through the packet path, whose C pass splits
            # its rays over the threads itself (no block's Python around it)
            if n <= _CHUNK and (threads <= 1 or n < MIN_RAYS or (self._precision is Precision.FAST and self.native
                                                                   and packets.library() is not None)):
                return self._cast(O, D, t_near, t_far, excl, planes, static, movers, big, mount, distance_only,
                                  directions32, coherent, box, rows, run, ride)
            parts = split(n, threads, _CHUNK)
            if coherent and run > 0:   # blocks start where runs start (each run packed as its own cast)
                size = -(-parts[0].stop // run) * run
                parts = [slice(a, min(n, a + size)) for a in range(0, n, size)]
            if len(parts) == 1:
                return self._cast(O, D, t_near, t_far, excl, planes, static, movers, big, mount, distance_only,
                                  directions32, coherent, box, rows, run, ride)
            # large batches in blocks: the temporaries (~150 bytes per ray) stay a few MB whatever the
            # batch, and the blocks of the planes and the static tier run side by side on the
            # threads; then the movers, on the whole batch (a Mount keeps its lists for it) or in
            # blocks; every ray's answer is the same (big is the batch's)
            exact = self._precision is Precision.EXACT
            if planes is not None:
                planes.refresh(self._epoch)
            if static is not None:
                static.prepare(exact)
            dist = np.empty(n)
            normal = None if distance_only else np.empty((n, 3))
            shape = None if distance_only else np.empty(n, dtype=np.int64)
            eps64 = 1e-9 + 1e-14 * big
            listed: dict = {}   # "pairs", "own" once listed (see list_pairs)
            ready = threading.Event()
            mounted = movers is not None and isinstance(mount, Mount)

            def list_pairs() -> None:
                """A Mount's pairs, listed for the whole batch up to t_far (a superset of those up to each
                ray's nearest static hit), then traced in the blocks beside the static tier with each
                ray's own limit: the same hits as tracing them after all blocks. Listed on the calling
                thread while the workers trace their first blocks' static tier."""
                try:
                    *pairs, own = self._mover_pairs(movers, O, D, t_near, t_far,
                                                    t_far if isinstance(t_far, np.ndarray) else np.full(n, t_far),
                                                    excl, mount, own_apart=distance_only and not exact)
                    if movers.R is None:
                        movers.R = self._rot[movers.index]
                    for tier in movers.tiers:
                        tier.prepare(exact)
                    listed.update(pairs=pairs, own=own)
                finally:
                    ready.set()

            def block(sl: slice) -> None:
                m = sl.stop - sl.start
                with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # per thread
                    tn, tf = _param(_take(t_near, sl), m, np.float64, float), _param(_take(t_far, sl), m, np.float64, float)
                    h = self._cast_static(O[sl], D[sl], tn, tf, _param(_take(excl, sl), m, np.int64, int), planes,
                                          static, big, distance_only, None if directions32 is None else directions32[sl],
                                          coherent, run=run)
                    dist[sl] = h[0]
                    if not distance_only:
                        shape[sl], normal[sl] = h[1], h[2]
                    if mounted:
                        ready.wait()
                    pairs = listed.get("pairs")
                    if pairs is not None and len(pairs[0]):
                        pr, pm, tight = pairs
                        sel = ((pr >= sl.start) & (pr < sl.stop)).nonzero()[0]
                        if len(sel):
                            d = dist[sl]
                            self._trace_pairs(movers, O[sl], D[sl], tn, np.minimum(tf, d), eps64, exact, d,
                                              None if distance_only else shape[sl],
                                              None if distance_only else normal[sl], pr[sel] - sl.start, pm[sel],
                                              tight, split=False)

            run_blocks(block, parts, threads, list_pairs if mounted else None)
            if listed.get("own") is not None:   # the own-mount hits, traced once
                self._apply_own_hits(listed["own"], movers, O, D, t_near, t_far, eps64, dist)
            if movers is not None and not mounted:   # no Mount: the movers after the blocks, in chunks
                hits = (dist, shape, normal)
                for sl in split(n, 1, _CHUNK):
                    self._cast_movers(movers, O[sl], D[sl], _take(t_near, sl), _take(t_far, sl), _take(excl, sl),
                                      eps64, exact, *(None if x is None else x[sl] for x in hits),
                                      mount=None if mount is None else np.asarray(mount)[sl],
                                      riding=None if ride is None else (*ride, sl.start))
            return RayHits(dist, normal, shape)

    def cast_local(self, body: int, origins, directions, t_near=0.0, t_far=np.inf, kind=RayKind.BOUNDING,
                   skip_transparent=False) -> RayHits:
        """Hits of rays given in ``body``'s own frame on that (moving) body's shapes only (planes
        excepted: they take part in every :meth:`cast`); normals in the body frame.  Rigidly
        mounted rays (a sensor on its robot) give the same answer at every pose, so this is called
        once and combined with casts that pass ``mount`` (see :meth:`cast`).  The same tier and
        trace as :meth:`cast` uses for this body; the float64 self-hit epsilon comes from the local
        origins instead of the batch's world coordinates (it is 1e-9 m + 1e-14 max|O|)."""
        b = self._bodies[body]
        if not b.mover:
            raise ValueError(f"body {body} is static: only moving bodies are cast in their own frame")
        O = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
        D = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        n = len(O)
        tier = self._mover_tier(b, self._variant(kind, skip_transparent))
        t = np.full(n, _INF)
        shape = np.full(n, -1, dtype=np.int64)
        normal = np.zeros((n, 3))
        if tier is None or n == 0:
            return RayHits(t, normal, shape)
        t_near = _param(t_near, n, np.float64, float)
        t_far = _param(t_far, n, np.float64, float)
        big = max(float(O.max()), -float(O.min()))
        far = np.array(_full(t_far, n), dtype=np.float64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            # a large batch (an image's pixel rays on their robot, cast once): only the rays whose
            # segment may meet the tier's bound, grown well past the test's rounding, are traced
            # (the others meet none of its shapes; no ray's answer depends on the rays beside it)
            sel = None
            if n >= MIN_RAYS:
                grow = 1e-9 + 1e-12 * big
                may = np.empty(n, dtype=bool)

                def test(sl: slice) -> None:     # row blocks (each row's own test) in the cache
                    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # per thread
                        may[sl] = tier.may_hit(O[sl], D[sl], _take(t_near, sl), far[sl], grow=grow)

                run_blocks(test, [slice(a, min(n, a + _BOUND_ROWS)) for a in range(0, n, _BOUND_ROWS)], self.threads)
                if not may.all():
                    sel = may.nonzero()[0]
                    self.counters["local_pruned"] += n - len(sel)
            if sel is None:
                res = self._trace(tier, O, D, t_near, far, -1, 1e-9 + 1e-14 * big, self._precision is Precision.EXACT)
            elif len(sel) == 0:
                res = None
            else:
                res = self._trace(tier, O.take(sel, axis=0), D.take(sel, axis=0), _take(t_near, sel), far[sel], -1,
                                  1e-9 + 1e-14 * big, self._precision is Precision.EXACT)
        if res is not None:
            ts, s, nrm = res
            if sel is None:
                t, normal = ts, nrm
                shape = np.where(s >= 0, s + b.first, -1)
            else:
                t[sel] = ts
                shape[sel] = np.where(s >= 0, s + b.first, -1)
                normal[sel] = nrm
        return RayHits(t, normal, shape)

    def _cast(self, O, D, t_near, t_far, excl, planes, static, movers, big: float, mount=None,
              distance_only: bool = False, d32=None, coherent: bool = False, box=None, rows=None,
              run: int = 0, ride: tuple | None = None) -> RayHits:
        exact = self._precision is Precision.EXACT
        hits = self._cast_static(O, D, t_near, t_far, excl, planes, static, big, distance_only, d32, coherent, box,
                                 rows, run)
        if movers is not None:
            self._cast_movers(movers, O, D, t_near, t_far, excl, 1e-9 + 1e-14 * big, exact, *hits, mount=mount,
                              own_apart=distance_only and not exact,
                              riding=None if ride is None else (*ride, 0))
        return RayHits(hits[0], hits[2], hits[1])

    def _cast_static(self, O, D, t_near, t_far, excl, planes, static, big: float, distance_only: bool = False,
                     d32=None, coherent: bool = False, box=None, rows=None, run: int = 0) -> tuple:
        """(dist, shape, normal) of the planes and the static tier (shape, normal None when
        ``distance_only``): the part of a cast that blocks of rays run side by side. ``box``: the
        (min, max) per column of the origins when the caller has it, ``rows`` the distinct origins
        themselves (see ``origin_rows``)."""
        n = len(O)
        exact = self._precision is Precision.EXACT
        eps64 = 1e-9 + 1e-14 * big  # float64 self-hit epsilon: 1e-9 m + ~50 ulps of the largest coordinate
        hits = (cast_planes(planes, self._epoch, O, D, t_near, t_far, excl, eps64, distance_only, self.native)
                if planes is not None else None)
        if static is not None:
            lim = t_far if hits is None else np.minimum(t_far, hits[0])
            res = self._trace(static, O, D, t_near, lim, excl, eps64, exact, None if static.anchored else big,
                              distance_only, d32, coherent, None if static.anchored else box,
                              None if static.anchored else rows, run)
            if res is not None and hits is None:
                hits = res
            elif res is not None and distance_only:   # the nearer of plane and mesh (ties: the plane)
                np.minimum(hits[0], res[0], out=hits[0])
            elif res is not None:
                t, s, nrm = res
                better = (t < hits[0]).nonzero()[0]
                hits[0][better], hits[1][better], hits[2][better] = t[better], s[better], nrm[better]
        if hits is None:
            hits = ((np.full(n, _INF), None, None) if distance_only else
                    (np.full(n, _INF), np.full(n, -1, dtype=np.int64), np.zeros((n, 3))))
        return hits

    def _trace_split(self, tier: _Tier, O, D, t_near, lim, eps64: float, exact: bool, distance_only: bool):
        """``_trace`` of a mover tier's (ray, mover) pairs, in blocks on the threads when they are
        many (a lidar's beams that can reach its own robot): the same answers."""
        m = len(O)
        parts = split(m, self.threads, _CHUNK)
        if len(parts) == 1:
            return self._trace(tier, O, D, t_near, lim, -1, eps64, exact, None, distance_only)
        tier.prepare(exact)

        def block(sl: slice):
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # per thread
                return self._trace(tier, O[sl], D[sl], _take(t_near, sl), lim[sl], -1, eps64, exact, None,
                                   distance_only)

        outs = run_blocks(block, parts, self.threads)
        if all(o is None for o in outs):
            return None
        t = np.full(m, _INF)
        s = None if distance_only else np.full(m, -1, dtype=np.int64)
        nrm = None if distance_only else np.zeros((m, 3))
        for sl, o in zip(parts, outs):
            if o is not None:
                t[sl] = o[0]
                if not distance_only:
                    s[sl], nrm[sl] = o[1], o[2]
        return t, s, nrm

    def _mover_poses(self, mt: _Movers) -> None:
        if mt.epoch != self._epoch:  # poses changed since the last cast (rotations gathered when needed)
            mt.T = self._pos[mt.index]
            mt.R = self._rot[mt.index] if mt.anchored else None
            mt.C = mt.T + np.einsum("mij,mj->mi", mt.R, mt.anchor) if mt.anchored else mt.T
            mt.epoch = self._epoch

    def _riding(self, mt: _Movers, riding: Riding, variant: str) -> tuple | None:
        """(mover row, rays that may meet it, how far from the origin they start) of a :class:`Riding`'s body, or None when the general
        pairing applies: the body is no mover of this variant, or there are more movers than
        :meth:`_trace_pairs` traces one by one (its order over a shared tier would change)."""
        if len(mt.index) > _FEW_MOVERS or not 0 <= riding.body < len(self._bodies):
            return None
        if len(mt.row_of) != len(self._bodies) + 1:   # body index -> mover row (-1: none)
            mt.row_of = np.full(len(self._bodies) + 1, -1, dtype=np.int64)
            mt.row_of[mt.index] = np.arange(len(mt.index))
        row = int(mt.row_of[riding.body])
        if row < 0:
            return None
        return row, riding.rows(mt.tiers[mt.group[row]]), riding.reach

    def _riding_pairs(self, mt: _Movers, O, D, t_near, lim, excl, riding: tuple) -> np.ndarray | None:
        """The rays of this one-origin cast (ascending) the broad phase pairs with the body a
        :class:`Riding` rides, among those that may meet its bound (the others' pairs would all be
        dropped by the bound test), tested as every ray is; None when the general pairing must
        decide (fewer than :data:`_PRUNE` pairs, when the bound test may not run; an excluded
        owner; a body far from the world's origin). An origin inside the body's bounding sphere (by
        far more than its test's rounding, with the rays' start points) pairs every ray with it:
        those rays' pairs then, without a test."""
        row, rows, reach, start = riding
        n = len(O)
        if n < _PRUNE or (mt.owned and not (not isinstance(excl, np.ndarray) and excl < 0)):
            return None
        self._mover_poses(mt)
        T = mt.T[row]
        if max(abs(float(T[0])), abs(float(T[1])), abs(float(T[2]))) > 1e5:
            return None
        lo, hi = np.searchsorted(rows, [start, start + n])
        sub = rows[lo:hi] - start
        rel = mt.C[row] - O[0]
        far = math.sqrt(float(rel @ rel)) + reach
        if far * far <= float(mt.r2[row]) * (1.0 - 1e-6):
            return sub
        if len(sub) < _PRUNE:
            return None
        pr, pm = _sphere_pairs(mt.C, mt.r2, None, _one_row(O[:1], len(sub)), D.take(sub, axis=0), _take(t_near, sub),
                               lim[sub], excl, among=np.array([row]))
        got = sub[pr[pm == row]]
        return got if len(got) >= _PRUNE else None

    def _cast_movers(self, mt: _Movers, O, D, t_near, t_far, excl, eps64, exact, dist, shape, normal,
                     mount=None, own_apart: bool = False, riding: tuple | None = None) -> None:
        """Broad phase over all movers, then one trace per shared tier over its (ray, mover) pairs
        moved into their body frames; improves dist/shape/normal in place. ``own_apart``: see
        :meth:`_mover_pairs`; ``riding``: :meth:`_riding`'s answer and the row of this chunk's
        first ray."""
        lim = np.minimum(t_far, dist)
        mine = None if riding is None else self._riding_pairs(mt, O, D, t_near, lim, excl, riding)
        rode = -1 if mine is None else riding[0]
        pr, pm, tight, own = self._mover_pairs(mt, O, D, t_near, t_far, lim, excl, mount, own_apart, skip=rode)
        if mine is not None:
            # the pairs with the ridden body: only those of rays that may meet its bound, which the
            # bound test then keeps or drops as it does every pair (the general pairs are >= _PRUNE)
            other = (pm != rode).nonzero()[0]
            pr = np.concatenate([pr[other], mine])
            pm = np.concatenate([pm[other], np.full(len(mine), rode, dtype=np.int64)])
            self.counters["riding_rays"] += len(mine)
        if len(pr):
            self._trace_pairs(mt, O, D, t_near, lim, eps64, exact, dist, shape, normal, pr, pm, tight, rode=rode)
        if own is not None:
            self._apply_own_hits(own, mt, O, D, t_near, t_far, eps64, dist)

    def _apply_own_hits(self, st, mt: _Movers, O, D, t_near, t_far, eps64: float, dist) -> None:
        """A FAST lidar's own-mount hits (the Mount's own pairs: its beams that can reach its robot's
        body) into ``dist``: traced once, in the body frame, up to t_far, and kept in the Mount's state
        while its limits are the same. A rigidly mounted beam's body-frame ray is the same at every
        pose up to the rounding of the world round trip (the float32 ray Embree gets changes only when
        a body-frame coordinate lies within float64 rounding of a float32 rounding boundary), so the
        nearest of its own-body hit and the other hits is the per-cast answer: a hit the per-cast
        trace finds before its limit (the nearest other hit, else t_far) is the one traced up to t_far,
        and one found beyond it never wins (tests/test_mounted_rays.py)."""
        got = st.own_hits
        key = (t_near, t_far)
        if got is None or got[0] != key:
            rr = st.own_pr
            row = int(st.own_pm[0])
            if mt.R is None:
                mt.R = self._rot[mt.index]
            Rb, Tb = mt.R[row], mt.T[row]
            # the rays into the body frame as the per-cast trace moves them (_trace_pairs: one mover)
            Db = packets.to_frame_rows(D, rr, Rb)
            if Db is None:
                Db = _to_frame(D.take(rr, axis=0), Rb)
            Ob = _one_row(_to_frame(_minus(O[:1], Tb), Rb), len(rr))
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                res = self._trace(mt.tiers[mt.group[row]], Ob, Db, t_near, np.full(len(rr), t_far), -1, eps64,
                                  False, None, True)
            t = np.full(len(rr), _INF) if res is None else res[0]
            hit = (t < _INF).nonzero()[0]
            st.own_hits = got = (key, rr[hit], t[hit])
        rows, t = got[1], got[2]
        if len(rows):
            cur = dist[rows]
            np.minimum(cur, t, out=cur)
            dist[rows] = cur

    def _mover_pairs(self, mt: _Movers, O, D, t_near, t_far, lim, excl, mount=None, own_apart: bool = False,
                     skip: int = -1) -> tuple:
        """(rays, mover rows, tight row, own) of the (ray, mover) pairs whose segment up to ``lim`` can
        meet the mover (every test is conservative: a larger ``lim`` gives more pairs, never fewer);
        ``tight``: a mover row whose pairs are only a Mount's own pairs (tested against its bound
        when listed), else -1. ``own_apart`` (a FAST cast of distances only): a lidar's own-mount
        pairs are left out when its Mount keeps their hits (scalar limits, as when its state was
        made); ``own`` is then that state, for :meth:`_apply_own_hits`, else None. ``skip`` (no mount):
        a mover row whose test may be skipped, its pairs the caller's (they may still be listed)."""
        self._mover_poses(mt)
        C = mt.C
        n = len(O)
        owner = mt.owner if mt.owned and not (not isinstance(excl, np.ndarray) and excl < 0) else None
        mounted = mrow = own = None
        tight = -1   # a mover row whose pairs are only a Mount's own pairs (already tested against its bound)
        row = -1     # the mover row every ray rides (a kept Mount on one body), else -1
        if mount is not None:
            if len(mt.row_of) != len(self._bodies) + 1:   # body index -> mover row (-1: none)
                mt.row_of = np.full(len(self._bodies) + 1, -1, dtype=np.int64)
                mt.row_of[mt.index] = np.arange(len(mt.index))
            kept = isinstance(mount, Mount)
            row = int(mt.row_of[mount.lo]) if kept and mount.lo == mount.hi >= 0 else -1
            if (row >= 0 and mount.own is None and not (len(C) > _FEW_MOVERS and n * len(C) > _DENSE_PAIRS)
                    and not np.count_nonzero(lim < _INF)):
                # every ray rides one mover and no segment is bounded (a camera without a far plane):
                # mount_state and _mounted_pairs would build their per-ray tables only to find every
                # ray unbounded and hand them all to the general broad phase, which this is, on the
                # same values without their gathered copies (_sphere_pairs' test for rows of one
                # origin, as it runs on such a copy), less the pairs with the mount itself, whose
                # test is skipped where it runs mover by mover (a camera inside its robot's
                # bounding sphere would pair every pixel with it, only to drop them all)
                self.counters["unbounded_mounts"] += 1
                others = np.delete(np.arange(len(C)), row)
                pr, pm = _sphere_pairs(C, mt.r2, owner, O, D, t_near, lim, excl, among=others, cone=False)
                keep = (pm != row).nonzero()[0]
                order = np.argsort(pr[keep], kind="stable")
                return pr[keep][order], pm[keep][order], -1, None
            st = mount_state(mount, mt, C, O, t_near, t_far, D, self._rot) if kept else None
            if st is None and kept and mount.own is not None:
                pass   # unbounded rays that see their own mount: the general broad phase for all
            elif st is None:
                mrow = mt.row_of[np.asarray(mount)]
                mounted = _mounted_pairs(mt, C, owner, O, D, t_near, lim, excl, mrow)
            elif len(st.mi) and O.strides[0] == 0 and len(st.used) == 1 and not len(st.rest):   # a lidar
                mrow = st.mrow
                tight = int(st.used[0])
                if (own_apart and st.limits is not None and st.limits == (t_near, t_far) and len(st.own_pr)
                        and not np.count_nonzero(st.own_pm != st.own_pm[0])):
                    own = st
                mounted = (*one_origin_pairs(st, mt, C, O, D, t_near, lim, excl, owner, self._epoch, self.counters,
                                             own=own is None), st.rest)
            elif len(st.mi):   # candidates kept between casts; the segment test as _mounted_pairs does it
                mrow = st.mrow
                cr, cm = with_own_pairs(st, *mount_candidates(st, mt, C, self._rot, O, D, self._epoch, self.counters))
                mounted = (*_near_pairs(C, O, D, t_near, lim, excl, owner, mt.r2, cr, cm), st.rest)
        if mounted is not None and len(mounted[2]) == 0:   # every ray mounted
            pr, pm = mounted[0], mounted[1]
        else:
            sub = None if mounted is None else mounted[2]
            if sub is None:
                Os, Ds, tn, ls, ex = O, D, t_near, lim, excl
            else:   # the unmounted rays only
                Os, Ds, ls = O.take(sub, axis=0), D.take(sub, axis=0), lim[sub]
                tn, ex = _take(t_near, sub), _take(excl, sub)
            if len(C) > _FEW_MOVERS and len(Os) * len(C) > _DENSE_PAIRS:
                pr, pm = _grid_pairs(C, mt.radius, mt.r2, owner, Os, Ds, tn, ls, ex,
                                     origin=O[0] if O.strides[0] == 0 and len(O) else None)
            else:   # rays that all ride one mover: its test skipped mover by mover (its pairs are dropped below)
                cut = row if sub is not None and row >= 0 else skip if sub is None else -1
                pr, pm = _sphere_pairs(C, mt.r2, owner, Os, Ds, tn, ls, ex,
                                       among=np.delete(np.arange(len(C)), cut) if cut >= 0 else None)
            if sub is not None:   # merge with the mounted rays' pairs, in ray order
                pr = sub[pr]
                if len(pr):       # an unbounded mounted ray never meets its own body here either
                    keep = (pm != mrow[pr]).nonzero()[0]
                    pr, pm = pr[keep], pm[keep]
                pr = np.concatenate([pr, mounted[0]])
                pm = np.concatenate([pm, mounted[1]])
                order = np.argsort(pr, kind="stable")
                pr, pm = pr[order], pm[order]
        return pr, pm, tight, own

    def _trace_pairs(self, mt: _Movers, O, D, t_near, lim, eps64, exact, dist, shape, normal, pr, pm, tight: int,
                     split: bool = True, rode: int = -1) -> None:
        """One trace per mover (few) or shared tier over the pairs (``pr``, ``pm``, as
        :meth:`_mover_pairs` gives them), the rays moved into their body frames; improves
        dist/shape/normal in place. ``split``: large traces in blocks on the engine's threads.
        ``rode``: a mover row whose pairs stand for every ray's (a :class:`Riding`): tested against
        its bound whatever their number, as every ray's would be."""
        n = len(O)
        T, C = mt.T, mt.C
        if mt.R is None:
            mt.R = self._rot[mt.index]
        R = mt.R
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
        one_origin = O.strides[0] == 0   # one origin for all rays (a lidar): it stays one, in every frame
        for tier, rr, mm, one in todo:
            # rays into the body frames (float64): one matrix when all pairs share a mover
            Db = None
            if one and len(rr) == n:   # one mover, every ray (its pairs are then 0..n-1 in order)
                Or, Dr = O, D
            elif one and one_origin and len(rr) > _SMALL:   # a lidar's beams: gathered and turned in one pass
                Or, Dr = _one_row(O[:1], len(rr)), None
                Db = packets.to_frame_rows(D, rr, R[mm[0]])
            else:
                Or = _one_row(O[:1], len(rr)) if one_origin else O.take(rr, axis=0)
                Dr = D.take(rr, axis=0)
            if one:
                Rb, Tb = R[mm[0]], T[mm[0]]
                Ob = (_one_row(_to_frame(_minus(O[:1], Tb), Rb), len(rr)) if one_origin
                      else _to_frame(_minus(Or, Tb), Rb))
                if Db is None:
                    Db = _to_frame(D.take(rr, axis=0) if Dr is None else Dr, Rb)
            else:
                Rg = R.take(mm, axis=0)
                Ob = np.einsum("nij,ni->nj", Rg, Or - T.take(mm, axis=0))
                Db = np.einsum("nij,ni->nj", Rg, Dr)
            lim_r = lim[rr]
            # many pairs (many movers): drop those missing the tier's tight bound (a Mount's own
            # pairs passed that test when they were listed)
            if (len(rr) >= _PRUNE or (one and int(mm[0]) == rode)) and not (one and int(mm[0]) == tight):
                keep = tier.may_hit(Ob, Db, _take(t_near, rr), lim_r).nonzero()[0]
                if len(keep) < len(rr):
                    if len(keep) == 0:
                        continue
                    Ob = _one_row(Ob[:1], len(keep)) if Ob.strides[0] == 0 else Ob[keep]
                    rr, mm, Db, lim_r = rr[keep], mm[keep], Db[keep], lim_r[keep]
            res = (self._trace_split(tier, Ob, Db, _take(t_near, rr), lim_r, eps64, exact, shape is None) if split
                   else self._trace(tier, Ob, Db, _take(t_near, rr), lim_r, -1, eps64, exact, None, shape is None))
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
            mw = mm[win]
            dist[rows] = t[win]
            if shape is not None:
                shape[rows] = mt.first[mw] + s[win]
                nb = nb[win]
                normal[rows] = _from_frame(nb, Rb) if one else np.einsum("nij,nj->ni", R[mw], nb)
