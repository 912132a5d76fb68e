"""Webots' texture coordinates of a surface point, per geometry, in the shape's local frame (float64).

These are the ``(u, v)`` Webots' infra-red picking computes (``pickUVCoordinate`` of each geometry
node; sources named per function), **not** its rendering meshes' coordinates where the two differ
(a Box's rendering is the same per face; an IndexedFaceSet's default mapping is the same). ``v``
counts from the image's *top* row (Webots uploads images top row first and flips file and
``TextureCoordinate`` ``t``): the texel is row ``floor(v·h)`` of the image as stored.

Every function takes points on the surface (``(n, 3)``), as the ray engine reports them. FAST
hits lie on the circumscribed shells of curved shapes, slightly off the true surface: points
farther than a tolerance from it are first moved onto it along the surface normal direction of
the primitive (exact points are used as they are, bit for bit).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["box_uv", "plane_uv", "sphere_uv", "cylinder_uv", "capsule_uv", "cone_uv", "elevation_grid_uv", "triangle_uv",
           "default_triangle_uv", "BOX_FACE_ORDER"]

TOLERANCE = 1e-9             # WbBox::findIntersectedFace's face test (metres)
BOX_FACE_ORDER = ("front", "back", "bottom", "top", "left", "right")   # Webots' test order


def _on_surface(points: np.ndarray, centre_dist: np.ndarray, radius: float) -> np.ndarray:
    """Scale factor moving points at ``centre_dist`` to ``radius`` where they are off it by more
    than the tolerance (1 elsewhere, so exact points keep their bits)."""
    off = np.abs(centre_dist - radius) > TOLERANCE * max(1.0, radius)
    scale = np.ones(len(points))
    np.divide(radius, centre_dist, out=scale, where=off & (centre_dist > 0))
    return scale


# where each box face sits in Webots' "non-recursive" atlas (texture set 1, the pen's paint
# texture): u scaled by 1/4 and v by 1/2, then offset (WbBox::computeTextureCoordinate)
_ATLAS_OFFSETS = np.array([(0.75, 0.5), (0.25, 0.5), (0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)])


def box_uv(points: np.ndarray, size, atlas: bool = False) -> np.ndarray:
    """WbBox::computeTextureCoordinate (texture set 0: the whole image on each face; ``atlas``:
    set 1, the faces side by side in one image, as the pen paints them).

    The face is the first of front (+x), back (−x), bottom (−z), top (+z), left (+y), right (−y)
    within 1e-9 m of the point, as in WbBox::findIntersectedFace (so an edge or corner belongs to
    the first face of that order); a point on none (a FAST hit) takes the nearest face."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    s = np.asarray(size, dtype=np.float64)
    return _face_uv(_box_face(p, s / 2.0), p + s / 2.0, s, atlas)


def _box_face(p: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Index (Webots' order, see box_uv) of the face of a box of half sizes ``h`` a point is on."""
    gap = np.stack([np.abs(p[:, 0] - h[0]), np.abs(p[:, 0] + h[0]), np.abs(p[:, 2] + h[2]),
                    np.abs(p[:, 2] - h[2]), np.abs(p[:, 1] - h[1]), np.abs(p[:, 1] + h[1])], axis=1)
    near = gap < TOLERANCE
    return np.where(near.any(axis=1), np.argmax(near, axis=1), np.argmin(gap, axis=1))


def _face_uv(face: np.ndarray, vertex: np.ndarray, s: np.ndarray, atlas: bool) -> np.ndarray:
    """(u, v) on box ``face`` of points ``vertex`` given relative to the min corner, size ``s``."""
    a, b, c = vertex[:, 0] / s[0], vertex[:, 1] / s[1], vertex[:, 2] / s[2]
    u = np.select([face == 0, face == 1, face == 2, face == 3, face == 4], [b, 1 - b, a, a, 1 - a], a)
    v = np.select([face == 2, face == 3], [b, 1 - b], 1 - c)
    if atlas:
        off = _ATLAS_OFFSETS[face]
        u, v = 0.25 * u + off[:, 0], 0.5 * v + off[:, 1]
    return np.stack([u, v], axis=1)


def plane_uv(points: np.ndarray, size) -> np.ndarray:
    """WbPlane::pickUVCoordinate: ``u = x/sx + 0.5``, ``v = −y/sy + 0.5`` (the image spans the plane
    once). An infinite plane (``size`` None) reads its image's centre."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if size is None:
        return np.full((len(p), 2), 0.5)
    if len(p) <= 8:       # a few points: the same arithmetic in Python floats (cheaper than numpy calls)
        sx, sy = size
        return np.array([(x / sx + 0.5, -y / sy + 0.5) for x, y, _ in p.tolist()]).reshape(-1, 2)
    return np.stack([p[:, 0] / size[0] + 0.5, -p[:, 1] / size[1] + 0.5], axis=1)


def _cone_points(p: np.ndarray, radius: float, half: float) -> tuple[np.ndarray, np.ndarray]:
    """(points on the true surface, is-base) of a cone (apex at z = +half): a point on the base
    plane within the disc (within the tolerance) is a base point; any other (a FAST hit on the
    shell) belongs to the nearer of the side and the base, and is moved onto it (exact points keep
    their bits)."""
    tol_r, tol_h = TOLERANCE * max(1.0, radius), TOLERANCE * max(1.0, half)
    rho = np.hypot(p[:, 0], p[:, 1])
    d_base = np.abs(p[:, 2] + half)
    on_base = (d_base <= tol_h) & (rho <= radius + tol_r)
    slant = math.hypot(radius, 2.0 * half)
    d_side = (rho * 2.0 * half - (half - p[:, 2]) * radius) / slant      # signed distance to the side's cone
    base = on_base | ((np.abs(d_side) > tol_r) & (d_base < np.abs(d_side)))
    q = p.copy()
    q[base & ~on_base, 2] = -half
    move = ~base & (np.abs(d_side) > tol_r)
    if move.any():          # along the side's normal (2 half, ·, radius)/slant in the (rho, z) plane
        nr, nz = 2.0 * half / slant, radius / slant
        r_new = rho[move] - d_side[move] * nr
        z_new = p[move, 2] - d_side[move] * nz
        scale = np.divide(r_new, rho[move], out=np.zeros(int(move.sum())), where=rho[move] > 0)
        q[move, 0] *= scale
        q[move, 1] *= scale
        q[move, 2] = z_new
    return q, base


def cone_uv(points: np.ndarray, radius: float, height: float, atlas: bool = False) -> np.ndarray:
    """WbCone::pickUVCoordinate (``atlas``: texture set 1, the pen's: the side's u halved, the
    base's moved right by 1/2). Base (``z = −h/2``): ``u = (x + r)/(2r)``, ``v = 1 − (r − y)/(2r)``.
    Side: ``θ = atan(x/−y)`` wrapped to [0, 2π) and moved by π per quadrant as Webots does (so
    ``θ = atan2(x, −y) + π`` off the axes, and Webots' own values on them), ``u = θ/(2π)``,
    ``v = 1 − (z + h/2)/h``; the apex reads u = 0."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    q, base = _cone_points(p, radius, height / 2.0)
    x, y, z = q[:, 0], q[:, 1], q[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        theta = np.arctan(x / -y)
    theta = np.nan_to_num(theta, nan=0.0)          # the apex (0/0)
    theta = theta - np.floor(theta / (2.0 * math.pi)) * 2.0 * math.pi
    my = -y
    theta = np.where((theta < math.pi) & (x > 0) & (my != 0), theta + math.pi,
                     np.where((theta > math.pi) & (x < 0) & (my != 0), theta - math.pi, theta))
    u_side = theta / (2.0 * math.pi)
    v_side = 1.0 - (z + height / 2.0) / height
    u_base = (x + radius) / (2.0 * radius)
    v_base = 1.0 - (-y + radius) / (2.0 * radius)
    if atlas:
        u_side, u_base = u_side * 0.5, u_base * 0.5 + 0.5
    return np.stack([np.where(base, u_base, u_side), np.where(base, v_base, v_side)], axis=1)


def elevation_grid_uv(points: np.ndarray, size: tuple[float, float]) -> np.ndarray:
    """WbElevationGrid::pickUVCoordinate: ``u = x/W``, ``v = 1 − y/D`` over the grid's extent ``W × D``
    (the image spans the grid once, its top row along the last row of points; WREN's rendering
    mesh maps it alike). Both texture sets (the pen's too) are this one."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return np.stack([p[:, 0] / size[0], 1.0 - p[:, 1] / size[1]], axis=1)


def sphere_uv(points: np.ndarray, radius: float) -> np.ndarray:
    """WbSphere::pickUVCoordinate: ``u = 0.5 + atan2(x, −y)/(2π)``, ``v = 0.5 − asin(z/r)/π`` (the
    seam on the +y side, the top pole v = 0)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    p = p * _on_surface(p, np.linalg.norm(p, axis=1), radius)[:, None]
    u = 0.5 + np.arctan2(p[:, 0], -p[:, 1]) * 0.5 * (1.0 / math.pi)
    v = 0.5 - np.arcsin(np.clip(p[:, 2] / radius, -1.0, 1.0)) * (1.0 / math.pi)
    return np.stack([u, v], axis=1)


def _cylinder_points(p: np.ndarray, radius: float, half: float) -> tuple[np.ndarray, np.ndarray]:
    """(points on the true surface, is-side) of a closed cylinder. A point on the side (within the
    tolerance, rim included: Webots keeps the side hit unless a cap is strictly nearer) is a side
    point; one on a cap plane within the disc is a cap point; any other (a FAST hit on the shell)
    belongs to the nearer of the two, and is moved onto it."""
    rho = np.hypot(p[:, 0], p[:, 1])
    tol_r, tol_h = TOLERANCE * max(1.0, radius), TOLERANCE * max(1.0, half)
    d_side, d_cap = np.abs(rho - radius), np.abs(np.abs(p[:, 2]) - half)
    on_side = (d_side <= tol_r) & (np.abs(p[:, 2]) <= half + tol_h)
    on_cap = (d_cap <= tol_h) & (rho <= radius + tol_r)
    side = on_side | (~on_cap & (d_side <= d_cap))
    q = p.copy()
    scale = _on_surface(p, rho, radius)
    q[side, :2] *= scale[side, None]
    moved = ~side & (d_cap > tol_h)
    q[moved, 2] = np.where(p[moved, 2] > 0, half, -half)
    return q, side


def _capsule_points(p: np.ndarray, radius: float, half: float) -> tuple[np.ndarray, np.ndarray]:
    """(points on the true surface, is-body) of a capsule: the body where ``|z| <= h/2`` (Webots'
    own test on the point), else the hemisphere of that side; off-surface points moved onto it."""
    side = np.abs(p[:, 2]) <= half
    q = p.copy()
    scale = _on_surface(p, np.hypot(p[:, 0], p[:, 1]), radius)
    q[side, :2] *= scale[side, None]
    hemi = ~side
    if hemi.any():
        rows = hemi.nonzero()[0]
        centre = np.where(p[rows, 2] > 0, half, -half)
        rel = p[rows].copy()
        rel[:, 2] -= centre
        scale = _on_surface(rel, np.linalg.norm(rel, axis=1), radius)
        moved = scale != 1.0                  # exact points keep their bits
        rel = rel[moved] * scale[moved, None]
        rel[:, 2] += centre[moved]
        q[rows[moved]] = rel
    return q, side


def cylinder_uv(points: np.ndarray, radius: float, height: float, atlas: bool = False) -> np.ndarray:
    """WbCylinder::pickUVCoordinate (texture set 0; ``atlas``: set 1, the pen's: every part scaled
    by 1/2, the top cap moved right by 1/2, the bottom cap down by 1/2).

    Side: ``θ = asin(−x/r)``, ``π − θ`` where ``y < 0``, wrapped to [0, 2π); ``u = θ/(2π)``,
    ``v = 1 − (z + h/2)/h``. Caps: ``u = (x + r)/(2r)``, ``v = (r − y)/(2r)``, flipped (``1 − v``)
    on the bottom cap."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    q, side = _cylinder_points(p, radius, height / 2.0)
    theta = np.arcsin(np.clip(-q[:, 0] / radius, -1.0, 1.0))
    theta = np.where(-q[:, 1] > 0, math.pi - theta, theta)
    theta = theta - np.floor(theta / (2 * math.pi)) * 2 * math.pi
    u_side = theta / (2 * math.pi)
    v_side = 1 - (q[:, 2] + height / 2) / height
    u_cap = (q[:, 0] + radius) / (2 * radius)
    v_cap = (-q[:, 1] + radius) / (2 * radius)
    v_cap = np.where(q[:, 2] < 0, 1 - v_cap, v_cap)
    u, v = np.where(side, u_side, u_cap), np.where(side, v_side, v_cap)
    if atlas:
        top = ~side & (q[:, 2] > 0)
        bottom = ~side & ~top
        u, v = 0.5 * u + np.where(top, 0.5, 0.0), 0.5 * v + np.where(bottom, 0.5, 0.0)
    return np.stack([u, v], axis=1)


def capsule_uv(points: np.ndarray, radius: float, height: float, subdivision: int) -> np.ndarray:
    """WbCapsule::pickUVCoordinate: ``u = (atan2(x, −y) + π)/(2π)``; the body spans v in [1/3, 2/3]
    (``v = (2 − (z + h/2)/h)/3``), each hemisphere a third, piecewise linear in ``z`` over Webots'
    ``⌊subdivision/4⌋`` latitude bands (``sin`` spaced).

    Webots' quirk kept: exactly at a pole no band matches and v stays 0, so the bottom pole reads
    v = 0 and the top pole v = 1 (everywhere else the top hemisphere is near v = 0, the bottom near 1)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    h2 = height / 2.0
    q, side = _capsule_points(p, radius, h2)
    u = (np.arctan2(q[:, 0], -q[:, 1]) + math.pi) * 0.5 / math.pi
    v = np.zeros(len(q))
    v[side] = (2.0 - (q[side, 2] + h2) / height) / 3.0
    hemi = (~side).nonzero()[0]
    if len(hemi):
        sub4 = int(0.25 * subdivision)
        zi = np.abs(q[hemi, 2]) - h2
        vh = np.zeros(len(hemi))
        done = np.zeros(len(hemi), dtype=bool)
        p3 = 3 * sub4
        prev = 0.0
        for i in range(1, sub4 + 1):          # the first band whose top is above the point
            d = radius * math.sin(math.pi / 2 / sub4 * i)
            hit = ~done & (zi < d)
            vh[hit] = (i - 1 + 2 * sub4) / p3 + (zi[hit] - prev) / (p3 * (d - prev))
            done |= hit
            prev = d
        v[hemi] = np.where(q[hemi, 2] > 0, 1.0 - vh, vh)
    return np.stack([u, v], axis=1)


def triangle_uv(corners: np.ndarray, b1: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """WbTriangleMeshGeometry::pickUVCoordinate: the corners' coordinates ``(k, 3, 2)``
    interpolated with the hit's barycentrics (``b1`` weighs corner 1, ``b2`` corner 2)."""
    b0 = 1.0 - b1 - b2
    return b0[:, None] * corners[:, 0] + b1[:, None] * corners[:, 1] + b2[:, None] * corners[:, 2]


def default_triangle_uv(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Corner coordinates ``(F, 3, 2)`` of an IndexedFaceSet without ``texCoord``
    (WbTriangleMesh::setDefaultTextureCoordinates): over the bounding box of all points, ``u``
    along the longest dimension, ``v = 1 −`` the second longest, both divided by the longest
    extent (first dimension wins ties, in x, y, z order)."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    lo, hi = v.min(axis=0), v.max(axis=0)
    size = hi - lo
    longest = second = -1
    for i in range(3):
        if longest < 0 or size[i] > size[longest]:
            second, longest = longest, i
        elif second < 0 or size[i] > size[second]:
            second = i
    corner = v[np.asarray(faces, dtype=np.int64).reshape(-1, 3)]      # (F, 3, 3)
    extent = size[longest] if size[longest] > 0 else 1.0
    u = (corner[..., longest] - lo[longest]) / extent
    w = 1.0 - (corner[..., second] - lo[second]) / extent
    return np.stack([u, w], axis=-1)


def default_triangle_atlas_uv(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Corner coordinates ``(F, 3, 2)`` of texture set 1 (the pen's) of an IndexedFaceSet without
    ``texCoord`` (WbTriangleMesh::setDefaultTextureCoordinates): each triangle is mapped on the
    box atlas of the points' bounding box, on the face its normal from its centroid leaves by."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    lo, hi = v.min(axis=0), v.max(axis=0)
    size = hi - lo
    safe = np.where(size > 0, size, 1.0)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    corner = v[f]
    n = np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    centroid = corner.mean(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):      # where the normal leaves the box
        t = np.where(n > 0, (hi - centroid) / n, np.where(n < 0, (lo - centroid) / n, np.inf)).min(axis=1)
    face = _box_face(centroid + t[:, None] * n - (lo + hi) / 2, size / 2)
    return np.stack([_face_uv(face, corner[:, k] - lo, safe, atlas=True) for k in range(3)], axis=1)
