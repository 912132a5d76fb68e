"""The convex hull of points in 3-D (float64, numpy): what a falling solid can rest on (ground.py).

Quickhull: a first tetrahedron from extreme points, then, again and again, the point farthest
outside a face; the faces it sees go and its horizon is joined to it. A point counts as outside a
face only when it is more than ``tolerance`` beyond its plane (:func:`hull_tolerance`: 1e-10 of the
points' largest coordinate or extent), so duplicate points and points on a face or edge (a box
sampled on its faces, a mesh's coplanar vertices) never make faces of their own; the hull's faces
are triangles (a flat face of many points is several coplanar triangles). Input all on a plane, on
a line or at one point has no volume and raises :class:`FlatPoints` naming which.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FlatPoints", "Hull", "convex_hull", "hull_tolerance"]

_RELATIVE_TOL = 1e-10


class FlatPoints(ValueError):
    """The points span no volume: ``kind`` is "point", "line" or "plane"; ``where`` says it in words
    ("on one plane")."""

    def __init__(self, kind: str):
        self.kind = kind
        self.where = "at one point" if kind == "point" else f"on one {kind}"
        super().__init__(f"the points lie {self.where}: no 3-D hull")


@dataclass(frozen=True, slots=True)
class Hull:
    """A convex hull: ``faces`` (m, 3) indices into ``points``, counter-clockwise seen from outside,
    their unit outward ``normals`` and ``offsets`` (normal · point on the face), ``vertices`` the
    indices of the points that are corners of a face, and the ``tolerance`` it was built with."""

    points: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray
    vertices: np.ndarray
    tolerance: float

    def volume_centroid(self) -> tuple[float, np.ndarray]:
        """The hull's volume and the centre of that volume (tetrahedra from one hull vertex)."""
        p = self.points
        apex = p[self.vertices[0]]
        a, b, c = (p[self.faces[:, k]] - apex for k in range(3))
        six = np.einsum("ij,ij->i", a, np.cross(b, c))          # 6 × each tetrahedron's volume
        volume = float(six.sum()) / 6.0
        centroid = apex + (six[:, None] * (a + b + c)).sum(axis=0) / (4.0 * float(six.sum()))
        return volume, centroid


def hull_tolerance(points: np.ndarray) -> float:
    """How far beyond a face's plane a point must be to be outside it: 1e-10 of the larger of the
    points' largest |coordinate| and their extent (float64's rounding of a plane's offset there is
    under 1e-15 of it)."""
    p = np.asarray(points, dtype=np.float64)
    scale = max(float(np.abs(p).max()), float((p.max(axis=0) - p.min(axis=0)).max()))
    return _RELATIVE_TOL * scale if scale > 0.0 else 0.0


def _plane(p: np.ndarray, a: int, b: int, c: int) -> tuple[np.ndarray, float]:
    n = np.cross(p[b] - p[a], p[c] - p[a])
    n = n / float(np.linalg.norm(n))
    return n, float(n @ p[a])


def convex_hull(points: np.ndarray) -> Hull:
    """The convex hull of (n, 3) finite points (see the module docstring); :class:`FlatPoints` when
    they span no volume, ValueError for no points or a non-finite one."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(p) == 0 or not np.isfinite(p).all():
        raise ValueError("convex_hull needs at least one point, all finite")
    tol = hull_tolerance(p)
    # the first tetrahedron: the lowest x, the farthest from it, from their line, from their plane
    i0 = int(np.argmin(p[:, 0]))
    d = np.linalg.norm(p - p[i0], axis=1)
    i1 = int(np.argmax(d))
    if d[i1] <= tol:
        raise FlatPoints("point")
    u = (p[i1] - p[i0]) / d[i1]
    rel = p - p[i0]
    d = np.linalg.norm(rel - np.outer(rel @ u, u), axis=1)
    i2 = int(np.argmax(d))
    if d[i2] <= tol:
        raise FlatPoints("line")
    n = np.cross(p[i1] - p[i0], p[i2] - p[i0])
    n /= float(np.linalg.norm(n))
    d = rel @ n
    i3 = int(np.argmax(np.abs(d)))
    if abs(float(d[i3])) <= tol:
        raise FlatPoints("plane")
    if d[i3] > 0.0:                         # i3 above (i0, i1, i2): that face looks the other way
        i1, i2 = i2, i1
    faces = [(i0, i1, i2), (i0, i3, i1), (i1, i3, i2), (i2, i3, i0)]
    cap = 4 + 2 * len(p)
    tri = np.zeros((cap, 3), dtype=np.int64)
    normals = np.zeros((cap, 3))
    offsets = np.zeros(cap)
    alive = np.zeros(cap, dtype=bool)
    for k, f in enumerate(faces):
        tri[k] = f
        normals[k], offsets[k] = _plane(p, *f)
        alive[k] = True
    count = 4
    # each point's face it is farthest outside (-1: inside or on the hull so far) and how far
    dist = p @ normals[:4].T - offsets[:4]
    owner = np.where(dist.max(axis=1) > tol, dist.argmax(axis=1), -1)
    far = np.where(owner >= 0, dist.max(axis=1), 0.0)
    owner[[i0, i1, i2, i3]] = -1
    far[[i0, i1, i2, i3]] = 0.0
    while True:
        k = int(np.argmax(far))
        if far[k] <= 0.0:
            break
        seen = np.flatnonzero((normals[:count] @ p[k] - offsets[:count] > tol) & alive[:count])
        edges = {(int(tri[f, j]), int(tri[f, (j + 1) % 3])) for f in seen for j in range(3)}
        horizon = [e for e in edges if (e[1], e[0]) not in edges]
        alive[seen] = False
        new = np.arange(count, count + len(horizon))
        if count + len(horizon) > len(tri):           # (a tolerance-bent hull may need more room)
            grow = len(tri) + len(horizon)
            tri, normals, offsets, alive = (np.concatenate([a, np.zeros((grow,) + a.shape[1:], a.dtype)])
                                            for a in (tri, normals, offsets, alive))
        ends = np.array(horizon, dtype=np.int64).reshape(-1, 2)
        tri[new, :2], tri[new, 2] = ends, k
        u, v = p[ends[:, 1]] - p[ends[:, 0]], p[k] - p[ends[:, 0]]
        n = np.column_stack([u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1], u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2],
                             u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]])        # (np.cross costs more than this)
        n /= np.linalg.norm(n, axis=1)[:, None]
        normals[new], offsets[new] = n, np.einsum("ij,ij->i", n, p[ends[:, 0]])
        alive[new] = True
        count += len(horizon)
        # the points outside the faces that went: outside a new face, or inside the hull now
        gone = np.zeros(len(tri) + 1, dtype=bool)      # (the last entry: owner -1, no face)
        gone[seen] = True
        moved = np.flatnonzero(gone[owner])
        owner[k], far[k] = -1, 0.0
        moved = moved[moved != k]
        if len(moved):
            dist = p[moved] @ normals[new].T - offsets[new]
            best = dist.max(axis=1)
            owner[moved] = np.where(best > tol, new[dist.argmax(axis=1)], -1)
            far[moved] = np.where(best > tol, best, 0.0)
    live = np.flatnonzero(alive[:count])
    faces_out = tri[live]
    return Hull(p, faces_out, normals[live], offsets[live], np.unique(faces_out), tol)
