"""Tiers: one Embree scene of a set of shapes and the float64 data that refines its hits.

The engine's Embree scenes are made here: through the packet path (:mod:`.packets`) when it is
available, else through embreex (the only other embreex importer is :mod:`.packets`, to find the
library embreex loaded).
"""

from __future__ import annotations

import math
import threading

import numpy as np
from embreex import rtcore as _rtc
from embreex import rtcore_scene as _rts
from embreex.mesh_construction import TriangleMesh as _TriangleMesh

from sensorium.server.raycast import packets
from sensorium.server.raycast.exact import _CAPSULE, _CONE, _CYLINDER, _F32, _SPHERE, _dot, _mat, _minus, _ulp32
from sensorium.server.raycast.guards import (
    MAX_CANDIDATES_BASE,
    MAX_CANDIDATES_PER_FLAT_TRIANGLE,
    MAX_EDGES_PER_FLAT_TRIANGLE,
    MAX_GUARDED_EDGES,
    MAX_PRISM_TRIANGLES_PER_TRIANGLE,
    MAX_WIDTH_PER_EDGE_LENGTH,
    PRISM_TRIANGLES,
    candidates,
    prisms,
    risky_edges,
)
from sensorium.server.world.geometry import Capsule, Cone, Cylinder, Mesh, Pose, Primitive, Sphere, tessellate
from sensorium.server.world.meshes import welded as _welded  # (a mesh file's Mesh is welded already: then unchanged)


def new_device():
    """A fresh Embree device (one per engine): the packet path's when it is available."""
    if packets.library() is not None:
        return packets.Device()
    return _rtc.EmbreeDevice()


def _cone_shell(cone: Cone, a: float) -> np.ndarray:
    """The shell of a cone with a margin of at least ``a`` everywhere: the tessellation of the cone
    whose side and base planes lie ``a`` outside the true ones (apex ``a / sin α`` higher, α the
    half angle; base ``a`` lower), in the cone's frame. Scaling the shell as for a cylinder would
    leave less than ``a`` near the apex of a slender cone."""
    r, h = cone.bottom_radius, cone.height
    slant = math.hypot(r, h)
    up, down = a * slant / r, a                      # a / sin α, a
    grown = Cone(r + a * slant / h + a * r / h, h + up + down, cone.subdivision)   # r + a / cos α + a tan α
    v, _ = tessellate(grown)
    return v + np.array([0.0, 0.0, (up - down) / 2.0])


class _Tier:
    """Triangles of a set of shapes in one Embree scene.  Tier frame = parent frame (world for the
    static tier, body frame for a mover) translated by ``-anchor``."""

    def __init__(self, device, items: list[tuple[int, Primitive, Pose]], owner_of: np.ndarray):
        verts, faces, tri_shape, curved = [], [], [], []
        nv = 0
        seen = set()
        for sid, prim, pose in items:
            # the same shape of the same owner again at the same pose adds nothing a ray could hit
            # first (k pasted copies of a world's solids: the tier, its guards and its refinement
            # would grow k-fold or worse); the first copy is the one hit
            key = (prim, pose.rotation.tobytes(), pose.translation.tobytes(), int(owner_of[sid]))
            if key in seen:
                continue
            seen.add(key)
            v, f = tessellate(prim)
            if len(f) == 0:
                continue
            if isinstance(prim, Mesh):
                # keep only referenced vertices (they set the tier bounds), each position once: an STL
                # file repeats a vertex in every triangle that has it, and the triangles that meet
                # there must share it (vertex rings, edges shared by two faces; the same surface)
                v, f = _welded(v, f)
            verts.append(pose.apply(v))
            faces.append(f + nv)
            tri_shape.append(np.full(len(f), sid, dtype=np.int64))
            if isinstance(prim, (Sphere, Cylinder, Capsule, Cone)):
                curved.append((sid, prim, pose, len(verts) - 1, v))
            nv += len(v)
        self.empty = nv == 0
        if self.empty:
            return
        box_lo, box_hi = _boxes(verts)
        lo, hi = box_lo.min(0), box_hi.max(0)
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
            if isinstance(prim, Cone):
                code, r, h = _CONE, prim.bottom_radius, prim.height / 2.0
                shell = _cone_shell(prim, a)
            elif isinstance(prim, Sphere):
                code, r, h, axial = _SPHERE, prim.radius, 0.0, prim.radius
            elif isinstance(prim, Cylinder):
                code, r, h = _CYLINDER, prim.radius, prim.height / 2.0
                axial = h
            else:
                code, r, h = _CAPSULE, prim.radius, prim.height / 2.0
                axial = h + r
            if code != _CONE:
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
        self.has_curved = bool(curved)
        self.has_cone = _CONE in c_code   # packets.c knows spheres, cylinders and capsules: numpy judges
        del curved   # the shapes' local vertices
        V = np.vstack(verts)
        # from here on only the shapes' boxes are needed (see _isolation): not a second copy of V
        starts = np.cumsum([0] + [len(v) for v in verts[:-1]])
        boxes = (np.minimum.reduceat(V, starts, axis=0), np.maximum.reduceat(V, starts, axis=0))
        del verts
        V -= self.anchor
        F = packets.padded(np.vstack(faces), np.int32)   # one index array: Embree's (shared with its scenes), and ours
        del faces
        self.V, self.F = V, F
        self.radius = float(np.max([np.linalg.norm(V[a:a + _BLOCK], axis=1).max() for a in range(0, len(V), _BLOCK)])) \
            + 4.0 * self.res
        self.tri_shape = np.append(np.concatenate(tri_shape), -1)  # sentinel row for primID = -1
        # unit normals (zero sentinel row), a block of triangles at a time: the temporaries stay a
        # few MB whatever the tier (every value is computed row by row: the same bits)
        self.normal = np.zeros((len(F) + 1, 3))
        ng = [0.0]
        for a, b, _, e1, e2 in _edges(V, F):
            nrm = np.cross(e1, e2)
            norm = np.linalg.norm(nrm, axis=1)
            ng.append(norm.max())
            with np.errstate(invalid="ignore", divide="ignore"):
                nrm /= norm[:, None]
            self.normal[a:b] = np.nan_to_num(nrm)
        self.ng_max = float(np.max(ng[1:])) if len(F) else 0.0
        # float64 refinement data is made on first use, each array when it is needed: FAST needs
        # none of it; EXACT in packets.c only the dual basis (see _exact_data) and the vertex rings
        self._exact: dict[str, np.ndarray] = {}
        self._making = threading.Lock()
        owners = owner_of[self.tri_shape[:-1]]
        self.owned = bool((owners >= 0).any())
        # -2 marks "no owner" so it never equals an exclude_owner value (>= -1)
        self.tri_owner = np.append(np.where(owners >= 0, owners, -2), -2).astype(np.int32)   # robot indices
        # curved shapes, indexed by "slot"
        self.c_shape = np.array(c_shape, dtype=np.int64)
        slot_of_shape = np.full(int(self.tri_shape.max()) + 2, -1, dtype=np.int64)
        slot_of_shape[self.c_shape] = np.arange(len(c_shape))
        self.tri_slot = slot_of_shape[self.tri_shape].astype(np.int32)  # sentinel row maps to -1 as well
        self.tri_curved = self.tri_slot >= 0
        self.tri_flat = ~self.tri_curved      # a flat triangle (sentinel row: False)
        self.tri_flat[-1] = False
        self.flat_index = self.tri_flat.nonzero()[0]
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
        self.c_isolated = self._isolation(*boxes, tri_shape, c_shape)
        # tight bound of the whole tier for pruning candidate rays (see ``may_hit``): the shell's own
        # cylinder for a tier of one cylinder or capsule (a round robot body), else the box of V
        slack = 16.0 * self.res
        if len(items) == 1 and len(c_shape) == 1 and c_code[0] != _SPHERE:
            self.bound = ("cylinder", self.c_rot[0], self.c_pos[0], self.c_rad[0] + slack, self.c_ax[0] + slack)
        else:
            self.bound = ("box", V.min(0) - slack, V.max(0) + slack)
        self._ring: VertexRings | None = None
        self._guard: tuple | None = None
        # Embree keeps pointers into these buffers: hold references for the scenes' lifetime
        self._v32 = packets.padded(V, _F32)   # shared with the packet path's scenes (see packets.Scene)
        self._f32 = F
        self._device = device
        self._scenes: dict[bool | str, object] = {}
        self._native: dict[bool, tuple] = {}   # per mode: the tier described to packets.c's judging passes

    def _exact_data(self, *keys: str) -> dict[str, np.ndarray]:
        """Per-triangle float64 data of EXACT's refinement, each group computed once on first use
        (under a lock: blocks of a cast run on threads) and named in ``keys`` by its first array:
        "v0" -- v0, e1, e2; "g1" -- the dual basis g1, g2 of (e1, e2) in each triangle's plane
        (barycentrics u = (P - v0).g1, v = (P - v0).g2, zero sentinel row) and the smallest height
        h_min; "t_lo" -- the per-triangle boxes t_lo, t_hi; "normal_cols" -- the normals' columns.
        packets.c reads only the "g1" group (it takes v0, e1, e2 and the boxes from V and F, the
        same values): a tier judged there holds ~56 B of it per triangle instead of ~250 B."""
        got = self._exact
        if all(k in got for k in keys):
            return got
        with self._making:
            V, F = self.V, self.F
            if "v0" in keys and "v0" not in got:
                v0 = V[F[:, 0]]
                got.update(v0=v0, e1=V[F[:, 1]] - v0, e2=V[F[:, 2]] - v0)
            if "g1" in keys and "g1" not in got:
                n = len(F)
                g1, g2, h_min = np.zeros((n + 1, 3)), np.zeros((n + 1, 3)), np.empty(n)
                for a, b, _, e1, e2 in _edges(V, F):   # row by row, a block at a time: the same bits
                    g11, g12, g22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
                    with np.errstate(invalid="ignore", divide="ignore"):
                        inv = 1.0 / (g11 * g22 - g12 * g12)
                    inv = np.where(np.isfinite(inv), inv, 0.0)[:, None]
                    g1[a:b] = (g22[:, None] * e1 - g12[:, None] * e2) * inv
                    g2[a:b] = (g11[:, None] * e2 - g12[:, None] * e1) * inv
                    # smallest height: every point at barycentric margin m is >= m * h_min from the edges
                    longest = np.sqrt(np.maximum(np.maximum(g11, g22), _dot(e2 - e1, e2 - e1)))
                    with np.errstate(invalid="ignore", divide="ignore"):
                        h = np.linalg.norm(np.cross(e1, e2), axis=1) / longest
                    h_min[a:b] = np.where(np.isfinite(h), h, 0.0)
                got.update(g1=g1, g2=g2, h_min=h_min)
            if "t_lo" in keys and "t_lo" not in got:
                n = len(F)
                t_lo, t_hi = np.empty((n, 3)), np.empty((n, 3))
                for a in range(0, n, _BLOCK):
                    tv = V[F[a:a + _BLOCK]]
                    t_lo[a:a + _BLOCK], t_hi[a:a + _BLOCK] = tv.min(1), tv.max(1)
                got.update(t_lo=t_lo, t_hi=t_hi)
            if "normal_cols" in keys and "normal_cols" not in got:
                got["normal_cols"] = tuple(np.ascontiguousarray(self.normal[:, k]) for k in range(3))
        return got

    v0 = property(lambda self: self._exact_data("v0")["v0"])
    e1 = property(lambda self: self._exact_data("v0")["e1"])
    e2 = property(lambda self: self._exact_data("v0")["e2"])
    g1 = property(lambda self: self._exact_data("g1")["g1"])
    g2 = property(lambda self: self._exact_data("g1")["g2"])
    t_lo = property(lambda self: self._exact_data("t_lo")["t_lo"])
    t_hi = property(lambda self: self._exact_data("t_lo")["t_hi"])
    h_min = property(lambda self: self._exact_data("g1")["h_min"])
    normal_cols = property(lambda self: self._exact_data("normal_cols")["normal_cols"])

    def first_vertex(self, tri: np.ndarray) -> np.ndarray:
        """v0 of the given triangles, without the full refinement data (FAST's self-hit test)."""
        return self.V[self.F[tri, 0]]

    def may_hit(self, O, D, lo, hi, grow: float = 0.0) -> np.ndarray:
        """Mask of the rays (parent frame) whose segment [lo, hi] may meet ``bound`` (conservative:
        every triangle of the tier, and every start point inside a shell, lies inside the bound),
        the bound grown by ``grow``."""
        Ot = _minus(O, self.anchor) if self.anchored else O
        hi = np.minimum(hi, 1e300)          # t * d stays finite (and 0 for d = 0)
        if self.bound[0] == "cylinder":
            # two cheap necessary conditions, tested separately: the segment comes within the
            # radius of the axis, and it overlaps the slab |z| <= half-height
            _, R, c, rad, ax = self.bound
            rad, ax = rad + grow, ax + grow
            p = _mat(_minus(Ot, c), R)
            d = _mat(D, R)
            px, py, pz, dx, dy, dz = p[:, 0], p[:, 1], p[:, 2], d[:, 0], d[:, 1], d[:, 2]
            # closest approach to the axis (a ray along the axis: any t, 1e-300 avoids 0/0)
            tc = np.minimum(np.maximum(-(px * dx + py * dy) / (dx * dx + dy * dy + 1e-300), lo), hi)
            qx, qy = px + tc * dx, py + tc * dy
            z0, z1 = pz + lo * dz, pz + hi * dz
            return (qx * qx + qy * qy <= rad * rad) & (np.maximum(z0, z1) >= -ax) & (np.minimum(z0, z1) <= ax)
        _, blo, bhi = self.bound
        if grow:
            blo, bhi = blo - grow, bhi + grow
        Dn = np.where(D == 0.0, 1e-300, D)   # parallel to a slab: +-huge (or 0 on its plane), no NaN
        t_a = (blo - Ot) / Dn
        t_b = (bhi - Ot) / Dn
        near, far = np.minimum(t_a, t_b), np.maximum(t_a, t_b)   # per axis; then across axes by column
        enter = np.maximum(np.maximum(np.maximum(near[:, 0], near[:, 1]), near[:, 2]), lo)
        leave = np.minimum(np.minimum(np.minimum(far[:, 0], far[:, 1]), far[:, 2]), hi)
        return enter <= leave

    def prepare(self, exact: bool) -> None:
        """Make now what casts make on first use (the scene of the mode and, for EXACT, the float64
        data, guards and vertex rings), so that blocks of rays on several threads only read."""
        self.scene(exact)
        if exact:
            if self.guard is not None:
                self.bare_scene()
            if self.native(exact) is None or not self.guarded:   # the numpy loop judges EXACT's hits
                self._exact_data("v0", "g1", "t_lo", "normal_cols")
                _ = self.ring
        else:
            self.native(exact)

    def native(self, exact: bool) -> int | None:
        """Address of this tier's ``struct sp_tier`` for the judging passes of packets.c (made once
        per mode), or None where its scenes are embreex's. EXACT's needs the refinement data."""
        got = self._native.get(exact)
        if got is None:
            if not isinstance(self._device, packets.Device) or self.has_cone:
                return None
            got = self._native[exact] = packets.tier_arrays(self, exact)
        return got[1]

    def scene(self, robust: bool):
        """(Embree scene, built now?).  FAST uses a plain scene, EXACT a robust one (watertight
        traversal, ~40% slower in a room where every ray hits); each is built on first use."""
        sc = self._scenes.get(robust)
        if sc is not None:
            return sc, False
        guard = self.guard if robust else None   # geometry 1 of the EXACT scene: the edge guards
        if isinstance(self._device, packets.Device):
            sc = packets.Scene(self._device, robust, self._v32, self._f32,
                               *((guard[3], guard[4]) if guard is not None else ()))
            if guard is not None:   # and the same without guards (for the rays that meet one)
                self._scenes["bare"] = packets.Scene(self._device, True, self._v32, self._f32)
            self._scenes[robust] = sc
            return sc, True
        sc = _rts.EmbreeScene(self._device, robust=robust)
        _TriangleMesh(sc, self._v32, self._f32)
        if guard is not None:
            _TriangleMesh(sc, guard[3], guard[4])
        sc.run(np.zeros((0, 3), _F32), np.zeros((0, 3), _F32))  # commit now: this is the build
        self._scenes[robust] = sc
        if guard is not None:
            bare = _rts.EmbreeScene(self._device, robust=True)
            _TriangleMesh(bare, self._v32, self._f32)
            bare.run(np.zeros((0, 3), _F32), np.zeros((0, 3), _F32))
            self._scenes["bare"] = bare
        return sc, True

    @property
    def guard(self) -> tuple | None:
        """Edge guards of the EXACT scene, or None (no risky edge; or too many, or too wide for
        the geometry (see :mod:`.guards`): then EXACT repairs leaks with an offset copy of each cast
        instead).  (edges, ptr, idx, prism vertices float32,
        prism faces): the triangles to test for a ray near risky edge i are ``idx[ptr[i]:ptr[i + 1]]``
        (see :func:`.guards.candidates`); prism triangle k guards edge ``k // PRISM_TRIANGLES``.
        Built on first use."""
        if self._guard is None:
            flat = ~self.tri_curved[:-1]
            n_flat = int(np.count_nonzero(flat))

            def too_many(k: int) -> bool:   # too many to guard, or too dense
                return k > MAX_GUARDED_EDGES or (k > MAX_EDGES_PER_FLAT_TRIANGLE * n_flat
                                                 and PRISM_TRIANGLES * k > MAX_PRISM_TRIANGLES_PER_TRIANGLE * len(self.F))

            found_edges = risky_edges(self.F, flat, self.normal[:-1], too_many)
            if found_edges is None:
                self._guard = (None, False)
                return None
            edges, ptr, idx = found_edges
            w = 4.0 * self.eps
            if len(edges) == 0 \
                    or w > MAX_WIDTH_PER_EDGE_LENGTH * float(np.median(np.linalg.norm(
                        self.V[edges[:, 0]] - self.V[edges[:, 1]], axis=1))):
                self._guard = (None, len(edges) == 0)
            else:
                found = candidates(self.V, edges, ptr, idx, self.ring, flat, w,
                                   MAX_CANDIDATES_PER_FLAT_TRIANGLE * n_flat + MAX_CANDIDATES_BASE)
                if found is None:   # coincident copies of the same edges: the offset copy instead
                    self._guard = (None, False)
                else:
                    pv, pf = prisms(self.V, edges, w)
                    self._guard = (edges, *found, np.ascontiguousarray(pv, dtype=_F32), pf)
        return None if self._guard[0] is None else self._guard

    def bare_scene(self):
        """The EXACT scene without its edge guards (built with it)."""
        if "bare" not in self._scenes:
            self.scene(True)
        return self._scenes["bare"]

    @property
    def guarded(self) -> bool:
        """True if the EXACT scene carries edge guards (False: EXACT uses the offset copy)."""
        return self.guard is not None or self._guard[1]

    def _isolation(self, lo, hi, tri_shape, c_shape) -> np.ndarray:
        """Per curved slot: True if no other shape of the tier overlaps its shell's bounding box
        (``lo``, ``hi``: each shape's box, in the tier's order). Then nothing can lie between a
        crossing of that shell and the true surface inside it."""
        if not c_shape:
            return np.zeros(0, dtype=bool)
        ids = np.array([int(t[0]) for t in tri_shape])
        out = np.empty(len(c_shape), dtype=bool)
        for i, sid in enumerate(c_shape):
            k = int(np.flatnonzero(ids == sid)[0])
            overlap = np.all((lo <= hi[k]) & (hi >= lo[k]), axis=1)
            overlap[k] = False
            out[i] = not overlap.any()
        return out

    @property
    def ring(self) -> VertexRings:
        """The vertex rings: for each triangle, the triangles sharing one of its vertices (itself
        included), read from the triangles of each vertex.  Built on first use (EXACT only)."""
        if self._ring is None:
            with self._making:
                if self._ring is None:
                    self._ring = VertexRings(self.F, len(self.V))
        return self._ring


class VertexRings:
    """The vertex rings of faces F, kept as the triangles of each vertex: CSR (``vptr`` int64 per
    vertex, ``tri_of`` int32, ascending) -- 3 entries per triangle. The ring of triangle i is, for
    each corner of i in order, that corner's list: reading it from here costs nothing more, while
    storing the rings would take ~18 entries per triangle of a closed mesh and grow with the square
    of a vertex's valence (a fan of n triangles around one vertex: n² entries)."""

    def __init__(self, F: np.ndarray, n_vertices: int) -> None:
        self.F = F
        flat = F.ravel()
        order = np.argsort(flat, kind="stable")
        order //= 3
        self.tri_of = order.astype(np.int32)
        del order
        self.deg = np.bincount(flat, minlength=n_vertices)
        self.vptr = np.concatenate([[0], np.cumsum(self.deg)])

    def sizes(self, tri: np.ndarray) -> np.ndarray:
        """The ring length of each triangle listed."""
        return self.deg[self.F[tri]].sum(1)

    def rows(self, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(position in ``tri``, ring member) of every member of the rings of the triangles listed,
        ring after ring, each in ring order."""
        v = self.F[tri].ravel()
        cnt = self.deg[v]
        pos = np.repeat(np.repeat(np.arange(len(tri)), 3), cnt)
        first = np.repeat(self.vptr[v] - (np.cumsum(cnt) - cnt), cnt)
        first += np.arange(len(first))
        return pos, self.tri_of[first]


_BLOCK = 1 << 16   # triangles per block of the per-triangle arrays' computations (a few MB of temporaries)


def _edges(V: np.ndarray, F: np.ndarray):
    """(a, b, v0, e1, e2) for the triangles F[a:b], a block at a time: v0 = V[F[:, 0]], e1 = V[F[:, 1]]
    - v0, e2 = V[F[:, 2]] - v0 (the values of the whole arrays, row by row)."""
    for a in range(0, len(F), _BLOCK):
        f = F[a:a + _BLOCK]
        v0 = V[f[:, 0]]
        yield a, a + len(f), v0, V[f[:, 1]] - v0, V[f[:, 2]] - v0


def _boxes(verts: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Each vertex array's box (k, 3) lo and hi: ``v.min(0)``, ``v.max(0)`` each (the same values), the
    arrays of small shapes stacked in blocks of up to ``_BLOCK`` rows and reduced at once (two numpy
    reductions per shape cost ~5 us each: 25 ms for a tier of 5,000 boxes)."""
    lo, hi = np.empty((len(verts), 3)), np.empty((len(verts), 3))
    i = 0
    while i < len(verts):
        j, rows = i + 1, len(verts[i])
        while j < len(verts) and rows + len(verts[j]) <= _BLOCK:
            rows += len(verts[j])
            j += 1
        block = verts[i] if j == i + 1 else np.vstack(verts[i:j])
        starts = np.cumsum([0] + [len(v) for v in verts[i:j - 1]])
        lo[i:j] = np.minimum.reduceat(block, starts, axis=0)
        hi[i:j] = np.maximum.reduceat(block, starts, axis=0)
        i = j
    return lo, hi
