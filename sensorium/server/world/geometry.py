"""Shape-local geometric primitives, rigid poses and tessellation (all float64).

Every primitive is described in its own local frame (centred at the origin; the axis of
cylinders and capsules and the normal of planes is local +z).  ``tessellate`` turns a primitive
into a triangle mesh for the ray engine.  Curved primitives are tessellated as CIRCUMSCRIBED
polyhedra: every face plane lies at or outside the true surface, so the true surface is inside
the polyhedron and a ray that truly hits the shape always crosses the polyhedron first.  The
engine's EXACT mode then re-intersects the true analytic surface.

This module never imports embreex.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = [
    "Box", "Sphere", "Cylinder", "Capsule", "Cone", "Plane", "Mesh", "Primitive", "Pose",
    "tessellate", "triangle_count", "valid_faces", "capsule_segments", "Terrain", "elevation_grid",
]


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be a finite positive number, got {value!r}")
    return value


@dataclass(frozen=True, slots=True)
class Box:
    """Axis-aligned box centred at the origin; ``size`` = full edge lengths (x, y, z)."""

    size: tuple[float, float, float]

    def __post_init__(self) -> None:
        if len(self.size) != 3:
            raise ValueError(f"Box.size needs 3 values, got {self.size!r}")
        object.__setattr__(self, "size", tuple(_positive("Box.size", s) for s in self.size))


@dataclass(frozen=True, slots=True)
class Sphere:
    """Sphere centred at the origin.  ``subdivision`` = icosphere level used for tessellation."""

    radius: float
    subdivision: int = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", _positive("Sphere.radius", self.radius))
        if not 0 <= int(self.subdivision) <= 8:
            raise ValueError(f"Sphere.subdivision must be in [0, 8], got {self.subdivision!r}")
        object.__setattr__(self, "subdivision", int(self.subdivision))


@dataclass(frozen=True, slots=True)
class Cylinder:
    """Closed cylinder, axis local z, centred.  ``subdivision`` = number of sides."""

    radius: float
    height: float
    subdivision: int = 36

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", _positive("Cylinder.radius", self.radius))
        object.__setattr__(self, "height", _positive("Cylinder.height", self.height))
        if int(self.subdivision) < 3:
            raise ValueError(f"Cylinder.subdivision must be >= 3, got {self.subdivision!r}")
        object.__setattr__(self, "subdivision", int(self.subdivision))


@dataclass(frozen=True, slots=True)
class Capsule:
    """Capsule, axis local z, centred: a cylinder of length ``height`` capped by hemispheres whose
    centres are at z = ±height/2.  ``subdivision`` controls tessellation (see ``capsule_segments``)."""

    radius: float
    height: float
    subdivision: int = 12

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius", _positive("Capsule.radius", self.radius))
        h = float(self.height)
        if not (math.isfinite(h) and h >= 0.0):
            raise ValueError(f"Capsule.height must be finite and >= 0, got {self.height!r}")
        object.__setattr__(self, "height", h)
        if int(self.subdivision) < 2:
            raise ValueError(f"Capsule.subdivision must be >= 2, got {self.subdivision!r}")
        object.__setattr__(self, "subdivision", int(self.subdivision))


@dataclass(frozen=True, slots=True)
class Cone:
    """Cone, axis local z, centred as Webots' Cone: apex at z = +height/2, base disc of
    ``bottom_radius`` at z = −height/2.  ``subdivision`` = number of sides of the tessellation."""

    bottom_radius: float
    height: float
    subdivision: int = 36

    def __post_init__(self) -> None:
        object.__setattr__(self, "bottom_radius", _positive("Cone.bottom_radius", self.bottom_radius))
        object.__setattr__(self, "height", _positive("Cone.height", self.height))
        if int(self.subdivision) < 3:
            raise ValueError(f"Cone.subdivision must be >= 3, got {self.subdivision!r}")
        object.__setattr__(self, "subdivision", int(self.subdivision))


@dataclass(frozen=True, slots=True)
class Plane:
    """Plane z = 0 with normal local +z, centred; ``size`` = (x, y) extent or None (infinite).
    Planes are intersected analytically by the engine and are never tessellated."""

    size: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.size is not None:
            if len(self.size) != 2:
                raise ValueError(f"Plane.size needs 2 values, got {self.size!r}")
            object.__setattr__(self, "size", tuple(_positive("Plane.size", s) for s in self.size))


def reach(p: Box | Sphere | Cylinder | Capsule, direction: Sequence[float] | np.ndarray) -> float:
    """How far ``p`` reaches from its centre along the unit ``direction`` (in ``p``'s own frame), exactly:
    a box's half sizes times the direction's parts; a cylinder's or capsule's axis (local z) part a, each
    end reaching h/2·|a| plus its rim's r·√(1 − a²) (a capsule's cap: r), ``direction`` of unit length. The lowest point of a shape
    whose frame has rotation R is its centre's height less reach(p, R[up, :])."""
    d = [float(v) for v in direction]
    if isinstance(p, Box):
        return sum(abs(d[k]) * float(p.size[k]) / 2.0 for k in range(3))
    if isinstance(p, Sphere):
        return float(p.radius)
    # the rim's part from the direction's other two (not √(1 − a²), which cancels near the axis)
    rim = min(1.0, math.hypot(d[0], d[1])) if isinstance(p, Cylinder) else 1.0
    return float(p.height) / 2.0 * abs(d[2]) + float(p.radius) * rim


def _own(values: object, dtype: type) -> np.ndarray:
    """``values`` as an (n, 3) array of ``dtype`` no one can write: a read-only array of that dtype
    as it is (a world model's mesh arrays, ``Rows``: no second copy), anything else copied."""
    a = np.asarray(values, dtype=dtype)
    if a.flags.writeable and isinstance(values, np.ndarray):     # (from a list: already a fresh array)
        a = a.copy()
    return a.reshape(-1, 3)


@dataclass(frozen=True, eq=False)
class Mesh:
    """Indexed triangle mesh in its local frame.  ``closed`` = watertight (as trimesh.is_watertight)."""

    vertices: np.ndarray
    faces: np.ndarray
    closed: bool

    def __post_init__(self) -> None:
        v = _own(self.vertices, np.float64)
        f = _own(self.faces, np.int64)
        if not np.all(np.isfinite(v)):
            raise ValueError("Mesh.vertices must be finite")
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            raise ValueError("Mesh.faces index outside the vertex array")
        v.flags.writeable = False
        f.flags.writeable = False
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f)
        object.__setattr__(self, "closed", bool(self.closed))


@dataclass(frozen=True, eq=False)
class Terrain(Mesh):
    """The triangles of a height field (an ElevationGrid): a mesh to the ray engine, ground to the
    kinematic contact (robots move in a plane; a terrain never stops them, as a floor plane)."""


def elevation_grid(height, x_dimension: int, x_spacing: float, y_dimension: int, y_spacing: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of a height field, float64: point ``(i, j)`` (vertex ``j·x_dimension + i``)
    at ``(i·x_spacing, j·y_spacing, height[j·x_dimension + i])``; each cell two triangles split
    along its diagonal from ``(i, j)`` to ``(i + 1, j + 1)`` (WREN's createUnitElevationGrid, the mesh
    Webots renders: lidars, cameras; its ODE height field splits a cell the same way), wound
    counter-clockwise seen from +z."""
    nx, ny = int(x_dimension), int(y_dimension)
    h = np.asarray(height, dtype=np.float64).reshape(-1)
    if nx < 2 or ny < 2 or len(h) != nx * ny:
        raise ValueError(f"an elevation grid needs x, y dimensions >= 2 and x*y heights, got {nx} x {ny}, {len(h)}")
    v = np.empty((nx * ny, 3), dtype=np.float64)
    v[:, 0] = np.tile(np.arange(nx, dtype=np.float64) * float(x_spacing), ny)
    v[:, 1] = np.repeat(np.arange(ny, dtype=np.float64) * float(y_spacing), nx)
    v[:, 2] = h
    i, j = np.meshgrid(np.arange(nx - 1, dtype=np.int64), np.arange(ny - 1, dtype=np.int64))
    a = (j * nx + i).reshape(-1)            # (i, j): the cell's low corner
    b, c, d = a + 1, a + nx + 1, a + nx      # (i+1, j), (i+1, j+1), (i, j+1)
    f = np.empty((2 * len(a), 3), dtype=np.int64)
    f[0::2] = np.stack([a, b, c], axis=1)
    f[1::2] = np.stack([a, c, d], axis=1)
    return v, f


Primitive = Box | Sphere | Cylinder | Capsule | Cone | Plane | Mesh


# --------------------------------------------------------------------------------------------
# Pose


@dataclass(frozen=True, slots=True, eq=False)
class Pose:
    """Rigid transform x' = rotation @ x + translation (float64).  ``a.compose(b)`` applies b
    first, then a (so world_from_body.compose(body_from_shape) = world_from_shape)."""

    rotation: np.ndarray
    translation: np.ndarray

    def __post_init__(self) -> None:
        r = np.array(self.rotation, dtype=np.float64, copy=True).reshape(3, 3)
        t = np.array(self.translation, dtype=np.float64, copy=True).reshape(3)
        r.flags.writeable = False
        t.flags.writeable = False
        object.__setattr__(self, "rotation", r)
        object.__setattr__(self, "translation", t)

    @classmethod
    def _owned(cls, rotation: np.ndarray, translation: np.ndarray) -> Pose:
        """Pose from fresh float64 (3,3) and (3,) arrays that nobody else references: no copy, no
        checks (``compose`` runs per device and step; the validating constructor costs ~3x more)."""
        p = object.__new__(cls)
        rotation.flags.writeable = False
        translation.flags.writeable = False
        object.__setattr__(p, "rotation", rotation)
        object.__setattr__(p, "translation", translation)
        return p

    @staticmethod
    def identity() -> Pose:
        return Pose(np.eye(3), np.zeros(3))

    @staticmethod
    def from_axis_angle(axis, angle: float, translation=(0.0, 0.0, 0.0)) -> Pose:
        """Pose from a rotation axis (need not be unit) and angle in radians (Webots convention)."""
        a = np.asarray(axis, dtype=np.float64)
        with np.errstate(over="ignore", under="ignore"):
            n = float(np.linalg.norm(a))
        if n == 0.0 and not a.any():
            return Pose(np.eye(3), translation)
        if not 1e-150 < n < 1e150:
            # a tiny or huge axis: its squares underflow to subnormals (a norm off by far more than
            # an ulp, so the matrix is no rotation) or overflow; scaled to [-1, 1] first, as
            # poses.axis_angle_matrix does (ordinary axes keep their one division, and their bits)
            a = a / float(np.max(np.abs(a)))
            n = float(np.linalg.norm(a))
        x, y, z = a / n
        c, s = math.cos(angle), math.sin(angle)
        k = 1.0 - c
        r = np.array([
            [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
            [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
            [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
        ])
        return Pose(r, translation)

    def compose(self, other: Pose) -> Pose:
        return Pose._owned(self.rotation @ other.rotation, self.rotation @ other.translation + self.translation)

    def inverse(self) -> Pose:
        rt = self.rotation.T.copy()
        return Pose._owned(rt, -(rt @ self.translation))

    def apply(self, points) -> np.ndarray:
        return np.asarray(points, dtype=np.float64) @ self.rotation.T + self.translation

    def apply_dirs(self, dirs) -> np.ndarray:
        return np.asarray(dirs, dtype=np.float64) @ self.rotation.T

    def __repr__(self) -> str:
        return f"Pose(rotation={self.rotation.tolist()}, translation={self.translation.tolist()})"


# --------------------------------------------------------------------------------------------
# Tessellation


def valid_faces(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Faces with three distinct indices and non-zero area (relative to their longest edge)."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        return faces
    vertices = np.asarray(vertices, dtype=np.float64)
    keep = np.empty(len(faces), dtype=bool)
    for a in range(0, len(faces), _BLOCK):   # a block at a time: the temporaries stay a few MB
        f = faces[a:a + _BLOCK]
        distinct = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
        v = vertices[f]
        e1, e2, e3 = v[:, 1] - v[:, 0], v[:, 2] - v[:, 0], v[:, 2] - v[:, 1]
        area2 = np.linalg.norm(np.cross(e1, e2), axis=1)
        longest2 = np.max(np.stack([(e1 * e1).sum(1), (e2 * e2).sum(1), (e3 * e3).sum(1)]), axis=0)
        # twice the area vs longest edge squared: below ~1e-14 the normal is numerical noise
        keep[a:a + len(f)] = distinct & (area2 > 1e-14 * longest2)
    return faces[keep]


_BLOCK = 1 << 16   # faces per block of valid_faces


def _orient_outward(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Wind every face counter-clockwise seen from outside (convex shapes containing the origin)."""
    v = vertices[faces]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    inward = (n * v.mean(axis=1)).sum(1) < 0.0
    faces = faces.copy()
    faces[inward] = faces[inward][:, [0, 2, 1]]
    return faces


def _box(size: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    h = np.asarray(size, dtype=np.float64) / 2.0
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64) * h
    # corner index = 4*ix + 2*iy + iz; two triangles per face
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], dtype=np.int64)
    return corners, _orient_outward(corners, faces)


def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    phi = (1.0 + math.sqrt(5.0)) / 2.0
    pts = []
    for a in (-1.0, 1.0):
        for b in (-phi, phi):
            pts += [(a, b, 0.0), (0.0, a, b), (b, 0.0, a)]
    v = np.array(pts, dtype=np.float64)
    # faces = vertex triples that are pairwise at the edge length (2)
    d = np.linalg.norm(v[:, None] - v[None], axis=2)
    adj = np.abs(d - 2.0) < 1e-9
    faces = [(i, j, k) for i in range(12) for j in range(i + 1, 12) for k in range(j + 1, 12)
             if adj[i, j] and adj[j, k] and adj[i, k]]
    v /= np.linalg.norm(v, axis=1)[:, None]
    return v, _orient_outward(v, np.array(faces, dtype=np.int64))


def _subdivide_unit(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split each triangle in four, projecting new edge midpoints onto the unit sphere."""
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    keys = edges[:, 0] * len(v) + edges[:, 1]
    uniq, inverse = np.unique(keys, return_inverse=True)
    a, b = uniq // len(v), uniq % len(v)
    mid = v[a] + v[b]
    mid /= np.linalg.norm(mid, axis=1)[:, None]
    m = inverse.reshape(3, -1) + len(v)  # midpoint index of edges (01, 12, 20) per face
    m01, m12, m20 = m
    f0, f1, f2 = f.T
    new = np.concatenate([
        np.stack([f0, m01, m20], 1), np.stack([f1, m12, m01], 1),
        np.stack([f2, m20, m12], 1), np.stack([m01, m12, m20], 1),
    ])
    return np.vstack([v, mid]), new


def _icosphere(radius: float, level: int) -> tuple[np.ndarray, np.ndarray]:
    v, f = _icosahedron()
    for _ in range(level):
        v, f = _subdivide_unit(v, f)
    # scale so the closest face plane is tangent to the sphere: circumscribed polyhedron
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    inradius = float(np.min((n * tri[:, 0]).sum(1)))
    return v * (radius / inradius), f


def _revolve(profile: list[tuple[float, float]], n_az: int) -> tuple[np.ndarray, np.ndarray]:
    """Surface of revolution about z from a convex (rho, z) profile running top pole -> bottom pole.

    Interior profile points become rings of ``n_az`` vertices at radius rho / cos(pi / n_az): the
    polygon then circumscribes the circle of radius rho, and if the profile polyline circumscribes
    the true profile curve the whole polyhedron circumscribes the true surface of revolution."""
    rings = profile[1:-1]
    scale = 1.0 / math.cos(math.pi / n_az)
    ang = 2.0 * math.pi * np.arange(n_az) / n_az
    cs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    verts = [np.array([[0.0, 0.0, profile[0][1]]])]
    for rho, z in rings:
        ring = np.empty((n_az, 3))
        ring[:, :2] = cs * (rho * scale)
        ring[:, 2] = z
        verts.append(ring)
    verts.append(np.array([[0.0, 0.0, profile[-1][1]]]))
    v = np.vstack(verts)
    k = np.arange(n_az)
    k1 = (k + 1) % n_az
    top, bottom = 0, len(v) - 1
    faces = [np.stack([np.full(n_az, top), 1 + k, 1 + k1], 1)]
    for i in range(len(rings) - 1):
        a, b = 1 + i * n_az + k, 1 + i * n_az + k1
        c, d = a + n_az, b + n_az
        faces += [np.stack([a, c, d], 1), np.stack([a, d, b], 1)]
    last = 1 + (len(rings) - 1) * n_az
    faces.append(np.stack([np.full(n_az, bottom), last + k1, last + k], 1))
    f = np.concatenate(faces).astype(np.int64)
    return v, _orient_outward(v, f)


def _cylinder(radius: float, height: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    h = height / 2.0
    return _revolve([(0.0, h), (radius, h), (radius, -h), (0.0, -h)], n)


def _cone(radius: float, height: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A pyramid on an n-gon: every section circumscribes the cone's (the ring at the base does)."""
    h = height / 2.0
    return _revolve([(0.0, h), (radius, -h), (0.0, -h)], n)


def capsule_segments(subdivision: int) -> tuple[int, int]:
    """(azimuthal segments, latitude segments per hemisphere) used for a Capsule tessellation."""
    return 2 * subdivision, max(2, subdivision // 2)


def _capsule(radius: float, height: float, subdivision: int) -> tuple[np.ndarray, np.ndarray]:
    n_az, n_lat = capsule_segments(subdivision)
    h = height / 2.0
    step = (math.pi / 2.0) / n_lat
    # vertices where consecutive tangent lines of the hemisphere arc meet: circumscribed polyline
    r_out = radius / math.cos(step / 2.0)
    polar = (np.arange(n_lat) + 0.5) * step
    top = [(r_out * math.sin(b), h + r_out * math.cos(b)) for b in polar]
    bottom = [(rho, -z) for rho, z in reversed(top)]
    return _revolve([(0.0, h + radius)] + top + bottom + [(0.0, -h - radius)], n_az)


@lru_cache(maxsize=256)
def _tessellate_cached(p: Box | Sphere | Cylinder | Capsule | Cone) -> tuple[np.ndarray, np.ndarray]:
    if isinstance(p, Box):
        v, f = _box(p.size)
    elif isinstance(p, Sphere):
        v, f = _icosphere(p.radius, p.subdivision)
    elif isinstance(p, Cylinder):
        v, f = _cylinder(p.radius, p.height, p.subdivision)
    elif isinstance(p, Cone):
        v, f = _cone(p.bottom_radius, p.height, p.subdivision)
    else:
        v, f = _capsule(p.radius, p.height, p.subdivision)
    v.flags.writeable = False
    f.flags.writeable = False
    return v, f


def tessellate(p: Primitive) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n,3) float64, faces (m,3) int64) in the primitive's local frame, faces wound
    counter-clockwise seen from outside.  Curved primitives are circumscribed.  For a Mesh the
    degenerate faces are dropped (see ``valid_faces``).  Plane -> ValueError (planes are analytic).
    The returned arrays are read-only and may be shared between calls."""
    if isinstance(p, Plane):
        raise ValueError("planes are intersected analytically and have no tessellation")
    if isinstance(p, Mesh):
        return p.vertices, _mesh_faces(p)
    if isinstance(p, (Box, Sphere, Cylinder, Capsule, Cone)):
        return _tessellate_cached(p)
    raise TypeError(f"not a primitive: {p!r}")


def _mesh_faces(p: Mesh) -> np.ndarray:
    """A Mesh's valid faces (``valid_faces``), found once per Mesh -- the scene counts them, the
    ray engine builds them, and a swarm's robots share one Mesh --: its own faces array when every
    face is valid (no copy), else a read-only array of those kept."""
    got = p.__dict__.get("_valid_faces")
    if got is None:
        got = valid_faces(p.vertices, p.faces)
        if len(got) == len(p.faces):
            got = p.faces
        got.flags.writeable = False
        object.__setattr__(p, "_valid_faces", got)
    return got


def triangle_count(p: Primitive) -> int:
    """Number of triangles the ray engine builds for ``p`` (0 for a Plane)."""
    if isinstance(p, Plane):
        return 0
    if isinstance(p, Box):
        return 12
    if isinstance(p, Sphere):
        return 20 * 4 ** p.subdivision
    if isinstance(p, Cylinder):
        return 4 * p.subdivision
    if isinstance(p, Cone):
        return 2 * p.subdivision
    if isinstance(p, Capsule):
        n_az, n_lat = capsule_segments(p.subdivision)
        return 4 * n_az * n_lat
    return len(tessellate(p)[1])
