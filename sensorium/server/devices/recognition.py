"""Camera recognition (Webots' Recognition node) — pure geometry, camera frame FLU, float64.

An object is a top-level solid or a robot with ``recognition_colors``. From its shapes (their
bounding shapes if it has any, else all of them — Webots: the boundingObject, else the shapes):

* ``bounds`` — its axis-aligned box in the camera frame, exact: a box's 8 corners, a mesh's or a
  finite plane's vertices, a sphere's ``c ± r``, a cylinder's ``|a_k|·h/2 + r·√(1 − a_k²)`` and a
  capsule's ``|a_k|·h/2 + r`` per camera axis k (``a`` its axis in the camera frame); an infinite
  plane has none (never recognised);
* ``position`` its centre, ``size`` its extents along the camera's y and z (Webots: "the Y and Z
  sizes ... relatively to the camera"), ``orientation`` the axis-angle of ``R_cam^T·R_object`` (``world.poses.axis_angle``);
* on the image (``box_on_image``, Webots' ``WbCamera::setRecognizedObjectProperties``): its 8
  corners (and, for a non-planar camera, its centre) projected by ``project_on_image``, whose image
  coordinates are the inverse of the camera's pixel rays (``imaging.py``), clamped to the image and
  mapped as Webots does, ``int((W − 1)·u)``; ``position_on_image = round`` of the middle,
  ``size_on_image = ceil`` of the extent; an object under one pixel in either direction is not
  recognised. A planar camera maps a point behind it to the image corner on its side (Webots).
"""

from __future__ import annotations

import math

import numpy as np

from .imaging import ImageGeometry

__all__ = ["image_coordinates", "project_on_image", "box_on_image", "shape_bounds"]


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
    return (int(round((hi[0] + lo[0]) / 2.0)), int(round((hi[1] + lo[1]) / 2.0))), (w, h)


def shape_bounds(kind: str, params: tuple, rotation: np.ndarray, centre: np.ndarray,
                 points: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """``(lo, hi)`` of one shape in the camera frame: ``rotation`` and ``centre`` place the shape's
    frame in the camera's. ``kind``: "box" (size), "sphere" (radius), "cylinder"/"capsule" (radius,
    height; axis local z), "points" (``points`` in the shape frame), "unbounded" (None)."""
    R = np.asarray(rotation, dtype=np.float64)
    c = np.asarray(centre, dtype=np.float64)
    if kind == "box":
        pts = (_CORNERS * np.asarray(params[0], dtype=np.float64)) @ R.T + c
        return pts.min(axis=0), pts.max(axis=0)
    if kind == "sphere":
        r = float(params[0])
        return c - r, c + r
    if kind in ("cylinder", "capsule"):
        r, h = float(params[0]), float(params[1])
        a = np.abs(R[:, 2])                                   # the axis's components in the camera frame
        half = a * h / 2.0 + (r * np.sqrt(np.maximum(0.0, 1.0 - a * a)) if kind == "cylinder" else r)
        return c - half, c + half
    if kind == "points" and points is not None and len(points):
        pts = np.asarray(points, dtype=np.float64) @ R.T + c
        return pts.min(axis=0), pts.max(axis=0)
    return None
