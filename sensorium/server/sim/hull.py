"""The convex hull of points in 3-D (float64, numpy): what a falling solid can rest on (ground.py).

Quickhull: a first tetrahedron from extreme points, then, again and again, a point outside a face
(the farthest one of its face); the faces it sees go and its horizon is joined to it. Which side of
a face a point is on is decided exactly (:func:`beyond`: float64's orient3d where Shewchuk's error
bound says its sign is sure, integers elsewhere), so a point on a face's plane is never outside it:
duplicate points and points on a face or edge (a box sampled on its faces, a mesh's coplanar
vertices) make no faces of their own, and every input point is inside or on the hull, exactly. The
faces are triangles (a flat face of many points is several coplanar ones); their normals are
float64, from integers for slivers. Points within :func:`hull_tolerance` (1e-10 of the points'
largest coordinate or extent) of one plane, one line or one point have no volume worth a hull:
:class:`FlatPoints` says which.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sensorium.server.world.arrays import unique_ints

__all__ = ["FlatPoints", "Hull", "MAX_POINTS", "beyond", "convex_hull", "enclosed", "extreme_points",
           "hull_tolerance"]

_RELATIVE_TOL = 1e-10

MAX_POINTS = 2048
"""Points beyond which a hull is built from :func:`extreme_points` instead: the hull's time grows with
the square of its corners (measured: 1,000 points on a sphere 0.28 s of CPU, 4,000 2.7 s), and a world
file's round mesh may have a hundred thousand."""

_DIRECTIONS = 1024
_CHUNK = 4096


def extreme_points(points: np.ndarray, limit: int = MAX_POINTS) -> np.ndarray:
    """``points`` themselves when there are at most ``limit``, else those farthest along each of 1,024
    directions spread evenly over the sphere (a Fibonacci lattice) and the six axes' (each one a
    corner of the true hull; their hull lies inside it, its corners exact input points, at most 1,030
    of them). Read in blocks of rows, so memory stays bounded whatever the count."""
    points = np.asarray(points, dtype=np.float64)
    if len(points) <= limit:
        return points
    k = np.arange(_DIRECTIONS) + 0.5
    z = 1.0 - 2.0 * k / _DIRECTIONS
    ring = np.sqrt(1.0 - z * z)
    turn = np.pi * (3.0 - np.sqrt(5.0)) * k
    dirs = np.vstack([np.column_stack([ring * np.cos(turn), ring * np.sin(turn), z]), np.eye(3), -np.eye(3)])
    best = np.full(len(dirs), -np.inf)
    index = np.zeros(len(dirs), dtype=np.int64)
    for start in range(0, len(points), _CHUNK):
        proj = points[start:start + _CHUNK] @ dirs.T
        rows = np.argmax(proj, axis=0)
        top = proj[rows, np.arange(len(dirs))]
        better = top > best
        best[better], index[better] = top[better], rows[better] + start
    return points[unique_ints(index)]


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
        six, centroid = enclosed(self.points, self.faces, self.points[self.vertices[0]])
        return six / 6.0, centroid


def enclosed(points: np.ndarray, faces: np.ndarray, apex: np.ndarray | None = None) -> tuple[float, np.ndarray]:
    """Six times the signed volume that triangles ``faces`` (indices into ``points``, wound outward
    counter-clockwise) enclose, and the centre of that volume: tetrahedra from ``apex`` (the origin when
    None) to each triangle. The centre is NaN when the volume is 0."""
    a, b, c = (points[faces[:, k]] if apex is None else points[faces[:, k]] - apex for k in range(3))
    six = np.einsum("ij,ij->i", a, np.cross(b, c))          # 6 × each tetrahedron's volume
    total = float(six.sum())
    with np.errstate(divide="ignore", invalid="ignore"):
        centre = (six[:, None] * (a + b + c)).sum(axis=0) / (4.0 * total)
    return total, centre if apex is None else apex + centre


def hull_tolerance(points: np.ndarray) -> float:
    """How far beyond a face's plane a point must be to be outside it: 1e-10 of the larger of the
    points' largest |coordinate| and their extent (float64's rounding of a plane's offset there is
    under 1e-15 of it)."""
    p = np.asarray(points, dtype=np.float64)
    scale = max(float(np.abs(p).max()), float((p.max(axis=0) - p.min(axis=0)).max()))
    return _RELATIVE_TOL * scale if scale > 0.0 else 0.0


# Shewchuk's static bound on float64's error in orient3d's determinant, times its permanent: outside
# it the float sign is the exact one; inside, the determinant is taken again in integers
_ORIENT_BOUND = (7.0 + 56.0 * 2.0 ** -53) * 2.0 ** -53


def _scaled(x: float) -> int:
    """``x`` × 2^1074 as an exact integer (every finite float64 is one)."""
    num, den = float(x).as_integer_ratio()
    return num * ((1 << 1074) // den)


def _exact_orient(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> int:
    """The sign of orient3d(a, b, c, d) in exact integer arithmetic."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz), (dx, dy, dz) = ([_scaled(v) for v in q] for q in (a, b, c, d))
    adx, ady, adz, bdx, bdy, bdz, cdx, cdy, cdz = ax - dx, ay - dy, az - dz, bx - dx, by - dy, bz - dz, cx - dx, cy - dy, cz - dz
    det = adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy)
    return (det > 0) - (det < 0)


def beyond(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Whether each point of ``d`` (k, 3) is strictly on the side of each triangle (a, b, c) ((m, 3)
    each) its counter-clockwise winding faces, exactly: (k, m) booleans. Float64's orient3d with
    Shewchuk's error bound, integers where the float sign is not sure (a point on or next to the plane)."""
    ad, bd, cd = (q[None, :, :] - d[:, None, :] for q in (a, b, c))
    adx, ady, adz = ad[..., 0], ad[..., 1], ad[..., 2]
    bdx, bdy, bdz = bd[..., 0], bd[..., 1], bd[..., 2]
    cdx, cdy, cdz = cd[..., 0], cd[..., 1], cd[..., 2]
    det = adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) + cdx * (ady * bdz - adz * bdy)
    bound = _ORIENT_BOUND * ((np.abs(bdy * cdz) + np.abs(bdz * cdy)) * np.abs(adx)
                             + (np.abs(cdy * adz) + np.abs(cdz * ady)) * np.abs(bdx)
                             + (np.abs(ady * bdz) + np.abs(adz * bdy)) * np.abs(cdx))
    out = det < -bound                   # orient3d < 0: d above the counter-clockwise face
    for i, j in np.argwhere(np.abs(det) <= bound):
        out[i, j] = _exact_orient(a[j], b[j], c[j], d[i]) < 0
    return out


def _exact_normal(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """(b − a) × (c − a) in integers, its direction as floats (a sliver's normal, which float64's cross
    product of nearly parallel edges gets wrong or zero)."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = ([_scaled(v) for v in q] for q in (a, b, c))
    ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
    n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
    shift = max(0, max(abs(x).bit_length() for x in n) - 60)
    return np.array([float(x >> shift if x >= 0 else -((-x) >> shift)) for x in n])


def _planes(p: np.ndarray, tri: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit outward normals and offsets of faces (float64: for distances, not for deciding sides)."""
    a = p[tri[:, 0]]
    u, v = p[tri[:, 1]] - a, p[tri[:, 2]] - a
    n = np.column_stack([u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1], u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2],
                         u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]])        # (np.cross costs more than this)
    size = np.linalg.norm(n, axis=1)
    # float64 is sure of the direction to 1e-10 when the cross product is not under 1e-6 of |u||v|
    for f in np.flatnonzero(~(size > 1e-6 * np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))):
        n[f] = _exact_normal(p[tri[f, 0]], p[tri[f, 1]], p[tri[f, 2]])
        size[f] = np.linalg.norm(n[f])
    n /= size[:, None]
    return n, np.einsum("ij,ij->i", n, a)


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
    n = _planes(p, np.array([[i0, i1, i2]]))[0][0]
    d = rel @ n
    d[[i0, i1, i2]] = 0.0
    i3 = int(np.argmax(np.abs(d)))
    if abs(float(d[i3])) <= tol:
        raise FlatPoints("plane")
    if d[i3] > 0.0:                         # i3 above (i0, i1, i2): that face looks the other way
        i1, i2 = i2, i1
    cap = 4 + 2 * len(p)
    tri = np.zeros((cap, 3), dtype=np.int64)
    normals = np.zeros((cap, 3))
    offsets = np.zeros(cap)
    alive = np.zeros(cap, dtype=bool)
    tri[:4] = [(i0, i1, i2), (i0, i3, i1), (i1, i3, i2), (i2, i3, i0)]
    normals[:4], offsets[:4] = _planes(p, tri[:4])
    alive[:4] = True
    count = 4

    def assign(points: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each point's face among ``faces`` it is outside of (exactly) and farthest from (-1: none),
        and that distance (at least the smallest float: an exact sign decides, not the distance)."""
        out = beyond(p[tri[faces, 0]], p[tri[faces, 1]], p[tri[faces, 2]], p[points])
        dist = np.where(out, p[points] @ normals[faces].T - offsets[faces], -np.inf)
        best = dist.argmax(axis=1)
        has = out.any(axis=1)
        return (np.where(has, faces[best], -1),
                np.where(has, np.maximum(dist[np.arange(len(points)), best], np.finfo(np.float64).tiny), 0.0))

    # each point's face it is outside of (-1: inside or on the hull so far) and how far
    owner, far = assign(np.arange(len(p)), np.arange(4))
    owner[[i0, i1, i2, i3]] = -1
    far[[i0, i1, i2, i3]] = 0.0
    while True:
        k = int(np.argmax(far))
        if far[k] <= 0.0:
            break
        live = np.flatnonzero(alive[:count])
        seen = live[beyond(p[tri[live, 0]], p[tri[live, 1]], p[tri[live, 2]], p[k:k + 1])[0]]
        edges = {(int(tri[f, j]), int(tri[f, (j + 1) % 3])) for f in seen for j in range(3)}
        horizon = [e for e in edges if (e[1], e[0]) not in edges]
        alive[seen] = False
        new = np.arange(count, count + len(horizon))
        if count + len(horizon) > len(tri):
            grow = len(tri) + len(horizon)
            tri, normals, offsets, alive = (np.concatenate([a, np.zeros((grow,) + a.shape[1:], a.dtype)])
                                            for a in (tri, normals, offsets, alive))
        tri[new, :2], tri[new, 2] = np.array(horizon, dtype=np.int64).reshape(-1, 2), k
        normals[new], offsets[new] = _planes(p, tri[new])
        alive[new] = True
        count += len(horizon)
        # the points outside the faces that went: outside a new face, or inside the hull now
        gone = np.zeros(len(tri) + 1, dtype=bool)      # (the last entry: owner -1, no face)
        gone[seen] = True
        moved = np.flatnonzero(gone[owner])
        owner[k], far[k] = -1, 0.0
        moved = moved[moved != k]
        if len(moved):
            owner[moved], far[moved] = assign(moved, new)
    live = np.flatnonzero(alive[:count])
    faces_out = tri[live]
    return Hull(p, faces_out, normals[live], offsets[live], unique_ints(faces_out), tol)
