"""Camera recognition (Webots' Recognition node) — pure geometry, camera frame FLU, float64.

An object is a top-level solid or a robot with ``recognition_colors``. From its shapes (their
bounding shapes if it has any, else all of them — Webots: the boundingObjects, else the object's
bounding sphere):

* ``bounds`` — its axis-aligned box in the camera frame, exact: a box's 8 corners, a mesh's or a
  finite plane's vertices, a sphere's ``c ± r``, a cylinder's ``|a_k|·h/2 + r·√(1 − a_k²)`` and a
  capsule's ``|a_k|·h/2 + r`` per camera axis k (``a`` its axis in the camera frame); an infinite
  plane has none (never recognised);
* ``position`` its centre, ``size`` its extents along the camera's y and z (Webots: "the Y and Z
  sizes ... relatively to the camera"), ``orientation`` the axis-angle of ``R_cam^T·R_object`` (``world.poses.axis_angle``);
* on the image (``box_on_image``, Webots' ``WbCamera::setRecognizedObjectProperties``): its 8
  corners (and, for a non-planar camera, its centre) projected by ``project_on_image``, whose image
  coordinates are the inverse of the camera's pixel rays (``imaging.py``), clamped to the image and
  mapped as Webots does, ``int((W − 1)·u)``; ``position_on_image`` = C's ``round`` (halves up) of the middle,
  ``size_on_image = ceil`` of the extent; an object under one pixel in either direction is not
  recognised. A planar camera maps a point behind it to the image corner on its side (Webots).

A planar camera first clips each shape to its view (``frustum``, ``clip_points``, ``clip_round``:
Webots' ``WbObjectDetection``), so an object across the image border is reported by its part in
view. The view is four planes through the camera — right, bottom, left, top, in Webots' order —
at Webots' half angles (rounded to float32 as there: ``tan`` of ``float32(Φ/2)`` and of half the
float32 vertical angle ``2·atan(tan(Φ/2)·H/W)``):

* a box, a mesh or a finite plane by its points: a point in front of the camera (``x > 0``) outside
  a plane is moved onto it by orthogonal projection, plane after plane in that order (so its depth
  changes too); points behind the camera are kept as they are; the shape is seen if one point is
  in front, and one is inside all four planes or the points cross the view from side to side (some
  outside the right plane, some outside the left, some inside the bottom and some inside the top
  one) or likewise from bottom to top; its box is that of the moved and kept points;
* a sphere, cylinder or capsule by its centre ``c`` and box: with ``d`` the signed distance from
  ``c`` to a plane (positive inside) and ``e`` half the box's extent across it (y for right/left,
  z for bottom/top), ``d < −e`` hides the shape; else ``e − d`` (when positive) is cut from that
  side of the box (for a field of view up to π/2, as in Webots; wider, the box stays whole). This
  is Webots' approximation: ``d`` is measured square to the slanted plane, not along y or z.

The object's box is the union of its seen shapes' boxes; an object with no seen shape is not recognised.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .imaging import ImageGeometry

__all__ = ["image_coordinates", "project_on_image", "box_on_image", "shape_bounds", "Frustum", "frustum",
           "clip_points", "clip_round", "clipped_bounds"]


def image_coordinates(p: np.ndarray, g: ImageGeometry) -> np.ndarray:
    """``(u − ½, v − ½)`` (N, 2) of camera-frame points (N, 3): where the pixel ray through them
    meets the image (unclamped)."""
    p = np.asarray(p, dtype=np.float64).reshape(-1, 3)
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    fov = float(g.field_of_view)
    W, H = int(g.width), int(g.height)
    with np.errstate(divide="ignore", invalid="ignore"):
        if g.projection == "planar":
            t = math.tan(fov / 2.0)
            ax = np.abs(x)
            u = -0.5 * (y / ax) / t
            v = -0.5 * (z / ax) / (t * H / W)
            behind = x < 0.0
            u = np.where(behind, np.where(y > 0.0, -0.5, 0.5), u)
            v = np.where(behind, np.where(z > 0.0, -0.5, 0.5), v)
        elif g.projection == "cylindrical":
            r = np.sqrt(x * x + y * y + z * z)
            u = -np.arctan2(y, x) / fov
            v = -np.arcsin(np.clip(z / r, -1.0, 1.0)) / (fov * H / W)
        else:   # spherical: the fisheye angle from +x, along the ray's direction in the image
            r = np.sqrt(x * x + y * y + z * z)
            psi = np.arccos(np.clip(x / r, -1.0, 1.0))
            rho = np.hypot(y, z)
            k = np.where(rho > 0.0, psi / fov / np.where(rho > 0.0, rho, 1.0), 0.0)
            u, v = -k * y, -k * z
    return np.stack([u, v], axis=1)


def project_on_image(p: np.ndarray, g: ImageGeometry) -> np.ndarray:
    """Pixel coordinates (N, 2) int64 of camera-frame points, Webots' way: the image coordinates
    clamped to the image, then ``int((W − 1)·u)``, ``int((H − 1)·v)``."""
    uv = np.clip(image_coordinates(p, g) + 0.5, 0.0, 1.0)
    uv = np.where(np.isnan(uv), 0.0, uv)
    return np.stack([((int(g.width) - 1) * uv[:, 0]).astype(np.int64),
                     ((int(g.height) - 1) * uv[:, 1]).astype(np.int64)], axis=1)


_CORNERS = np.array([[sx, sy, sz] for sx in (1, -1) for sy in (1, -1) for sz in (1, -1)], dtype=np.float64) * 0.5


def box_on_image(centre: np.ndarray, size: np.ndarray, g: ImageGeometry) -> tuple[tuple[int, int], tuple[int, int]] | None:
    """``(position_on_image, size_on_image)`` of a camera-frame box (its 8 corners, and its centre
    for a non-planar camera), or None when it covers less than one pixel either way."""
    pts = np.asarray(centre, dtype=np.float64) + _CORNERS * np.asarray(size, dtype=np.float64)
    if not g.planar:
        pts = np.vstack([pts, np.asarray(centre, dtype=np.float64)])
    uv = project_on_image(pts, g)
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    w, h = int(math.ceil(hi[0] - lo[0])), int(math.ceil(hi[1] - lo[1]))
    if w < 1 or h < 1:
        return None
    # C's round(): halves away from zero (Python's round() takes them to the even integer: one pixel
    # off for every other object whose extent is odd), exact on these halves of non-negative integers
    return (int(math.floor((hi[0] + lo[0]) / 2.0 + 0.5)), int(math.floor((hi[1] + lo[1]) / 2.0 + 0.5))), (w, h)


def _shape_points(kind: str, params: tuple, R: np.ndarray, c: np.ndarray, points: np.ndarray | None) -> np.ndarray | None:
    """The camera-frame points whose box is a box's, a mesh's or a finite plane's."""
    if kind == "box":
        return (_CORNERS * np.asarray(params[0], dtype=np.float64)) @ R.T + c
    if kind == "points" and points is not None and len(points):
        return np.asarray(points, dtype=np.float64) @ R.T + c
    return None


def shape_bounds(kind: str, params: tuple, rotation: np.ndarray, centre: np.ndarray,
                 points: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """``(lo, hi)`` of one shape in the camera frame: ``rotation`` and ``centre`` place the shape's
    frame in the camera's. ``kind``: "box" (size), "sphere" (radius), "cylinder"/"capsule" (radius,
    height; axis local z), "points" (``points`` in the shape frame), "unbounded" (None)."""
    R = np.asarray(rotation, dtype=np.float64)
    c = np.asarray(centre, dtype=np.float64)
    if kind == "sphere":
        r = float(params[0])
        return c - r, c + r
    if kind in ("cylinder", "capsule"):
        r, h = float(params[0]), float(params[1])
        a = np.abs(R[:, 2])                                   # the axis's components in the camera frame
        half = a * h / 2.0 + (r * np.sqrt(np.maximum(0.0, 1.0 - a * a)) if kind == "cylinder" else r)
        return c - half, c + half
    pts = _shape_points(kind, params, R, c, points)
    return None if pts is None else (pts.min(axis=0), pts.max(axis=0))


RIGHT, BOTTOM, LEFT, TOP = range(4)


@dataclass(frozen=True, slots=True)
class Frustum:
    """A planar camera's view as Webots' recognition clips to it: the unit normals (4, 3) of its side
    planes through the camera, pointing inwards, in the order right, bottom, left, top (camera frame
    FLU); ``shrink_round``: spheres, cylinders and capsules are cut to the view (field of view ≤ π/2)."""

    normals: np.ndarray
    shrink_round: bool


def frustum(g: ImageGeometry) -> Frustum | None:
    """The view a planar camera clips recognised shapes to; None for a non-planar camera (not clipped)."""
    if not g.planar:
        return None
    fov = float(g.field_of_view)
    # Webots keeps both half angles in float32 (WbObjectDetection::computeFrustumPlanes and
    # WbWrenCamera::computeFieldOfViewY); the planes follow them to the last bit
    half_x = float(np.float32(fov / 2.0))
    half_y = float(np.float32(np.float32(2.0 * math.atan(math.tan(fov * 0.5) / (int(g.width) / int(g.height))))) / 2.0)
    th, tv = math.tan(half_x), math.tan(half_y)
    n = np.array([[th, 1.0, 0.0], [tv, 0.0, 1.0], [th, -1.0, 0.0], [tv, 0.0, -1.0]], dtype=np.float64)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return Frustum(n, fov <= math.pi / 2.0)


def clip_points(points: np.ndarray, f: Frustum) -> tuple[np.ndarray, np.ndarray] | None:
    """``(lo, hi)`` of a shape's camera-frame points (N, 3) clipped to the view (see the module
    docstring), None when the shape is not in view."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    front = p[p[:, 0] > 0.0]                     # (a boolean index copies)
    if not len(front):
        return None
    outside = np.zeros((len(front), 4), dtype=bool)
    for j in range(4):                            # plane after plane: a moved point meets the next one moved
        n = f.normals[j]
        d = front @ n
        out = d < 0.0
        front[out] -= d[out, None] * n
        outside[:, j] = out
    if outside.any(axis=1).all():                 # no point inside: the shape must cross the view
        out_j, in_j = outside.any(axis=0), (~outside).any(axis=0)
        across = out_j[RIGHT] and out_j[LEFT] and in_j[BOTTOM] and in_j[TOP]
        up = out_j[BOTTOM] and out_j[TOP] and in_j[RIGHT] and in_j[LEFT]
        if not (across or up):
            return None
    kept = np.vstack([front, p[p[:, 0] <= 0.0]])
    return kept.min(axis=0), kept.max(axis=0)


def clip_round(lo: np.ndarray, hi: np.ndarray, f: Frustum) -> tuple[np.ndarray, np.ndarray] | None:
    """``(lo, hi)`` of a sphere's, cylinder's or capsule's camera-frame box cut to the view (see the
    module docstring), None when the shape is not in view (or nothing of its box is left)."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    c, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    d = f.normals @ c
    e = half[[1, 2, 1, 2]]
    if (d < -e).any():
        return None
    if not f.shrink_round:
        return lo, hi
    cut = np.where(d < e, e - d, 0.0)
    c = c + 0.5 * np.array([0.0, cut[RIGHT] - cut[LEFT], cut[BOTTOM] - cut[TOP]])
    half = half - 0.5 * np.array([0.0, cut[RIGHT] + cut[LEFT], cut[BOTTOM] + cut[TOP]])
    if half[1] <= 0.0 or half[2] <= 0.0:          # Webots would report a negative size (camera inside the shape)
        return None
    return c - half, c + half


def clipped_bounds(kind: str, params: tuple, rotation: np.ndarray, centre: np.ndarray, points: np.ndarray | None,
                   f: Frustum | None) -> tuple[tuple[np.ndarray, np.ndarray] | None, tuple[np.ndarray, np.ndarray] | None]:
    """``(whole, seen)``: the shape's ``shape_bounds`` and those of its part in view (``f``; the whole
    box when ``f`` is None), from one placing of its points; ``seen`` None when the shape is out of
    view, both None when it is unbounded."""
    R, c = np.asarray(rotation, dtype=np.float64), np.asarray(centre, dtype=np.float64)
    pts = _shape_points(kind, params, R, c, points)
    if pts is not None:
        whole = pts.min(axis=0), pts.max(axis=0)
        return whole, (whole if f is None else clip_points(pts, f))
    whole = shape_bounds(kind, params, R, c)               # a sphere, cylinder or capsule (or unbounded)
    return whole, (whole if whole is None or f is None else clip_round(whole[0], whole[1], f))
