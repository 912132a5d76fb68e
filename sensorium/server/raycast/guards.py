"""Edge guards of the EXACT cast: which flat-triangle edges one float32 cast can get wrong, and
the thin prisms around them that make the cast report every ray passing close to one.

Why (the repair rule of EXACT, see the engine docstring).  Embree's robust traversal is watertight
for the float32 ray it is given, and that ray stays within ``delta`` (a few float32 ulps of the
tier, ``eps`` here) of the float64 ray over the tier.  Suppose the float64 ray hits a flat triangle
T at p and the float32 ray misses T.  Moving the ray continuously from the float64 to the float32
one, its crossing with T's plane moves from p (inside T) to a point outside T, so it leaves T
through an edge e: the float64 ray passes within ``delta`` of a point of e.  If e is shared by
exactly two triangles of the tier that are coplanar and consistently wound (a face diagonal of a
box, the interior of a flat region), the float32 ray hits the other triangle at the same distance
(watertightness) and the float64 test of the hit triangle's vertex ring repairs it.  Every other
edge -- a boundary edge, an edge between two faces at an angle (a box edge: a silhouette for some
rays), a non-manifold or inconsistently wound edge -- is *risky*.  Curved shapes need no guard:
their shells are inflated by more than ``delta``, so a float64 hit on the true surface always lies
well inside the shell the float32 ray crosses.

So a ray can be wrong after one cast only if its float64 line passes within ``delta`` of a risky
edge.  A closed square prism of half-width ``w = 4 eps`` around each risky edge (extended by ``w``
past its ends) contains every point within ``2 eps`` of the edge with room to spare, so the float32
ray of any such ray crosses the prism (or starts inside it and leaves through it).  The prisms are
a second geometry of the EXACT Embree scene: a ray that meets one first is re-examined in float64
against the triangles of that edge, then continued.  No second cast for the other rays.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.world.arrays import unique_ints

# a tier uses guards while they stay few: at most this many risky edges, and either at most this
# many per flat triangle (a world of boxes has 1) or prisms (12 triangles each) adding at most this
# many triangles per triangle of the tier (a room of boxes, a rock mesh and curved shells, like the
# arena: 1.4 edges per flat triangle, 2.7 prism triangles per triangle; measured there: guards
# 1.4x faster than the copy on a 360-ray EXACT scan). A curved mesh or a terrain alone (~1.5 edges
# per flat triangle, ~18 prism triangles per triangle) keeps the offset copy
MAX_GUARDED_EDGES = 20000
MAX_EDGES_PER_FLAT_TRIANGLE = 1.2
MAX_PRISM_TRIANGLES_PER_TRIANGLE = 4.0
# ... and while the prisms stay thin beside the edges: in a float32 frame far coarser than the
# geometry (a room in a tier spanning 1e6 m: 2 m prisms) most rays would meet one
MAX_WIDTH_PER_EDGE_LENGTH = 0.05
# ... and while the float64 look of each guard stays short. A guard's candidate triangles are the
# vertex rings around its edge and around every risky edge whose prism comes close: a few dozen in
# a world of boxes, but k copies of the same box at one pose (coincident edges) give every edge k
# neighbours, and the lists grow as k^2 (333 copies of a world's solids: 3.4 GB). Beyond this many
# entries per flat triangle (plus a fixed allowance), counted before any list is made, the tier
# keeps the offset copy (a second cast, linear in the scene) instead
MAX_CANDIDATES_PER_FLAT_TRIANGLE = 256
MAX_CANDIDATES_BASE = 1 << 20
_COPLANAR = 1.0 - 1e-12   # cosine between two unit normals treated as the same plane

# the 6 faces of a prism whose corners are numbered (end, side1, side2) -> 4 * end + 2 * s1 + s2
_PRISM_FACES = np.array([
    [0, 1, 3], [0, 3, 2], [4, 7, 5], [4, 6, 7],      # end caps
    [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],      # side 2 = 0 / 1
    [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],      # side 1 = 0 / 1
], dtype=np.int32)
PRISM_TRIANGLES = len(_PRISM_FACES)


def risky_edges(F: np.ndarray, flat: np.ndarray, normal: np.ndarray, too_many=None):
    """Risky edges of the flat triangles ``F[flat]`` (``normal``: unit normals per triangle, zero
    for degenerate ones).  Returns (edges (k, 2) vertex indices, ptr, idx): the triangles of edge
    i are ``idx[ptr[i]:ptr[i + 1]]``; or None if ``too_many(k)`` (counted before they are listed:
    a triangle soup's every edge is risky)."""
    tri = flat.nonzero()[0]
    if len(tri) == 0:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64)
    # the 3 edges of every flat triangle (edge 3i + c: corner c to the next), as keys lo * M + hi
    # sorted (stably); the rest is read through that order where needed (~90 B per triangle at the
    # peak, not ~300: a mesh of millions of triangles builds this)
    f = F[tri]
    a = f.ravel()
    b = f[:, [1, 2, 0]].ravel()
    del f
    M = int(F.max()) + 1
    fwd = a < b
    key = np.minimum(a, b).astype(np.int64)
    key *= M
    key += np.maximum(a, b)
    del a, b
    order = np.argsort(key, kind="stable")
    key = key[order]
    start = np.r_[True, key[1:] != key[:-1]].nonzero()[0]
    count = np.diff(np.r_[start, len(key)])
    safe = count == 2
    two = start[safe]
    o1, o2 = order[two], order[two + 1]
    n1, n2 = normal[tri[o1 // 3]], normal[tri[o2 // 3]]
    safe[safe] = (fwd[o1] != fwd[o2]) & (np.einsum("ij,ij->i", n1, n2) >= _COPLANAR)
    risky = (~safe).nonzero()[0]
    if too_many is not None and too_many(len(risky)):
        return None
    k = key[start[risky]]
    edges = np.c_[k // M, k % M]
    counts = count[risky]
    ptr = np.r_[0, np.cumsum(counts)]
    idx = tri[order[np.repeat(start[risky] - ptr[:-1], counts) + np.arange(int(ptr[-1]))] // 3]
    return edges, ptr, idx


def prisms(V: np.ndarray, edges: np.ndarray, w: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed square prisms of half-width ``w`` around the segments ``V[edges]``, extended by ``w``
    beyond both ends: (vertices (8k, 3) float64, faces (12k, 3) int32)."""
    p, q = V[edges[:, 0]], V[edges[:, 1]]
    u = q - p
    length = np.linalg.norm(u, axis=1)
    u = np.where(length[:, None] > 0.0, u / np.where(length > 0.0, length, 1.0)[:, None], [1.0, 0.0, 0.0])
    helper = np.where((np.abs(u[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    s1 = np.cross(u, helper)
    s1 /= np.linalg.norm(s1, axis=1)[:, None]
    s2 = np.cross(u, s1)
    ends = (p - w * u, q + w * u)
    corners = np.empty((len(edges), 8, 3))
    for e in range(2):
        for i in range(2):
            for j in range(2):
                corners[:, 4 * e + 2 * i + j] = ends[e] + (2 * i - 1) * w * s1 + (2 * j - 1) * w * s2
    faces = (_PRISM_FACES[None] + 8 * np.arange(len(edges), dtype=np.int32)[:, None, None]).reshape(-1, 3)
    return corners.reshape(-1, 3), faces


def _expand(ptr: np.ndarray, idx: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For CSR (ptr, idx): (position in ``rows``, entry) of every entry of every row listed."""
    cnt = ptr[rows + 1] - ptr[rows]
    pos = np.repeat(np.arange(len(rows)), cnt)
    return pos, idx[np.repeat(ptr[rows] - (np.cumsum(cnt) - cnt), cnt) + np.arange(int(cnt.sum()))]


def _overlapping(lo: np.ndarray, hi: np.ndarray, limit: int) -> tuple[np.ndarray, np.ndarray] | None:
    """All (i, j) with boxes i and j overlapping (i == j included), by a sweep along x; None when
    the sweep would test more than ``limit`` pairs."""
    n = len(lo)
    order = np.argsort(lo[:, 0], kind="stable")
    slo, shi = lo[order], hi[order]
    end = np.searchsorted(slo[:, 0], shi[:, 0], side="right")
    cnt = np.maximum(end - np.arange(n), 1)
    if int(cnt.sum()) > limit:
        return None
    i = np.repeat(np.arange(n), cnt)
    j = i + np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    # along x every such pair overlaps (slo[j, 0] <= shi[i, 0] by the sweep, shi[j, 0] >= slo[j, 0] >=
    # slo[i, 0] by the order): y and z are tested, a column at a time (no (pairs, 3) temporaries)
    ok = np.ones(len(i), dtype=bool)
    for axis in (1, 2):
        lo_a, hi_a = np.ascontiguousarray(slo[:, axis]), np.ascontiguousarray(shi[:, axis])
        ok &= lo_a[j] <= hi_a[i]
        ok &= hi_a[j] >= lo_a[i]
    i, j = order[i[ok]], order[j[ok]]
    return np.r_[i, j], np.r_[j, i]


def candidates(V, edges, ptr, idx, ring, flat, w: float, budget: int) -> tuple[np.ndarray, np.ndarray] | None:
    """CSR (ptr, idx) of the flat triangles to test in float64 when a ray meets the guard of risky
    edge i: the vertex rings of the edge's triangles (the float64 hit can lie across a coplanar
    neighbour: the other triangle of a box face), for edge i and for every risky edge whose prism
    comes within w/2 of i's (coincident or crossing prisms, e.g. the common edge of two touching
    boxes: stepping past one prism's face must not step past the other's unexamined).  None when
    the lists would hold more than ``budget`` entries (counted before they are made: see
    MAX_CANDIDATES_PER_FLAT_TRIANGLE). ``ring``: the tier's :class:`.tiers.VertexRings`."""
    e_of, tri = np.repeat(np.arange(len(edges)), np.diff(ptr)), idx
    if int(ring.sizes(tri).sum()) > budget:
        return None
    pos, cand = ring.rows(tri)
    own = unique_ints(e_of[pos] * (len(flat) + 1) + cand)   # (edge, triangle) keys, sorted
    own_e, own_t = own // (len(flat) + 1), own % (len(flat) + 1)
    own_ptr = np.r_[0, np.cumsum(np.bincount(own_e, minlength=len(edges)))]
    p, q = V[edges[:, 0]], V[edges[:, 1]]
    grow = 1.5 * w
    pairs = _overlapping(np.minimum(p, q) - grow, np.maximum(p, q) + grow, budget)
    if pairs is None:
        return None
    i, j = pairs
    if int((own_ptr[j + 1] - own_ptr[j]).sum()) > budget:
        return None
    pos, cand = _expand(own_ptr, own_t, j)
    key = unique_ints(i[pos] * (len(flat) + 1) + cand)
    e_of, cand = key // (len(flat) + 1), key % (len(flat) + 1)
    keep = flat[cand]
    e_of, cand = e_of[keep], cand[keep]
    return np.r_[0, np.cumsum(np.bincount(e_of, minlength=len(edges)))], cand
