"""Frames of a .wbt tree (Pose/Transform nesting), and geometry under a Transform's ``scale``.

A frame maps its children's coordinates to the world: ``x_parent = R (s (M x)) + t``, with R a
rotation, s a uniform scale and M the non-uniform part ("stretch", None when the scale is uniform)
expressed in the frame's own axes. Rigid and uniformly scaled frames compose exactly as before M
existed, so worlds without a non-uniform scale convert bit for bit as they did.

Geometry under a non-uniform scale (Webots R2022a+ allows any non-zero ``scale`` on a Transform,
whose children are only Transform, Pose, Group and Shape):

* a **visual** shape is what Webots renders (what its lidars and cameras see): the exact affine
  image. When the scale axes are the shape's own axes ("aligned"): a Box stays an exact box, a
  Cylinder or Capsule scaled alike across its axis stays an exact cylinder/capsule, a Mesh keeps a
  per-axis scale, an IndexedFaceSet and a Plane are scaled exactly. Otherwise (an ellipsoid, an
  elliptic cylinder, or a shape turned between two non-uniform scales, "sheared") it becomes
  triangles: exact for a Box and an IndexedFaceSet (a parallelepiped is 12 triangles), a
  tessellation with its vertices on the true surface for a Sphere, Cylinder or Capsule
  (``CURVED_LEVELS``; the largest gap between the triangles and the true surface is given in
  README "Coming from Webots"). A Mesh file turned between two non-uniform scales is left out
  (a loss, said).
* a **bounding** shape is what Webots gives ODE (generic/sonar/laser rays, light occlusion):
  Webots scales ODE geoms by the *absolute scale* (the product of the Transforms' scale vectors,
  whatever rotations lie between them) in the geometry's own axes: a Box's size times it, a
  Sphere's radius times its largest component, a Cylinder's or Capsule's radius times the larger
  of x and y and its height times z (``WbBox::scaledSize``, ``WbSphere::scaledRadius``,
  ``WbCylinder::scaledRadius``…). A Transform directly in a boundingObject holding a Sphere or a
  Capsule is made uniform, one holding a Cylinder gets x = y, with Webots' warnings
  (``WbAbstractTransform::checkScale``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.server.world import geometry as geo
from sensorium.server.world.poses import axis_angle_matrix, matrix_quaternion

# tessellation of curved visual shapes under a non-uniform scale (vertices on the true surface)
CURVED_LEVELS = {"sphere": 4, "cylinder": 64, "capsule": 64, "cone": 64}    # icosphere level, sides around the axis
_ALIGNED_TOL = 1e-12      # off-diagonal terms of the stretch below this (relative) count as aligned axes


@dataclass(frozen=True)
class Frame:
    """``x_parent = R (s (M x)) + t``; ``aa`` = the exact axis-angle of R when known (None once two
    rotations were composed); ``stretch`` = M (None: uniform scale); ``webots_scale`` = Webots'
    absolute scale (the product of the scale vectors, for bounding objects)."""

    rotation: np.ndarray
    translation: np.ndarray
    scale: float = 1.0
    aa: tuple[float, float, float, float] | None = (0.0, 0.0, 1.0, 0.0)
    stretch: np.ndarray | None = None
    webots_scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    own_rotation: np.ndarray | None = None   # the last Pose/Transform/Solid's own rotation (``then``); None
                                             # at an owner's identity frame (what a LightSensor turns a spot by)

    @staticmethod
    def identity() -> Frame:
        return Frame(np.eye(3), np.zeros(3))

    @property
    def rigid(self) -> bool:
        return self.scale == 1.0 and self.stretch is None

    def then(self, translation, rotation, scale: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> Frame:
        """The frame of a child Pose/Transform (its translation, axis-angle rotation and scale)."""
        turned = rotation[3] != 0.0
        r2 = axis_angle_matrix(rotation[:3], rotation[3]) if turned else np.eye(3)
        local = np.asarray(translation, dtype=np.float64)
        if self.stretch is not None:
            local = self.stretch @ local
        t = self.rotation @ (self.scale * local) + self.translation
        aa: tuple[float, ...] | None
        if self.aa is not None and self.aa[3] == 0.0:
            aa = tuple(rotation)
        elif not turned:
            aa = self.aa
        else:
            aa = None
        sx, sy, sz = (float(v) for v in scale)
        webots = (self.webots_scale[0] * sx, self.webots_scale[1] * sy, self.webots_scale[2] * sz)
        s, stretch = self.scale, self.stretch
        if stretch is None and sx == sy == sz:
            s *= sx
        else:
            inherited = stretch if stretch is None or not turned else r2.T @ stretch @ r2
            stretch = (np.eye(3) if inherited is None else inherited) * np.array([sx, sy, sz])
            off = stretch - np.diag(np.diag(stretch))
            if not off.any() and stretch[0, 0] == stretch[1, 1] == stretch[2, 2]:
                s, stretch = s * float(stretch[0, 0]), None
        return Frame(self.rotation @ r2, t, s, aa, stretch, webots, r2)  # type: ignore[arg-type]

    def compose(self, inner: Frame) -> Frame:
        """``inner`` (a rigid frame given relative to this one) in this frame's parent."""
        aa: tuple[float, float, float, float] | None
        if self.aa is not None and self.aa[3] == 0.0:
            aa = inner.aa
        elif inner.aa is not None and inner.aa[3] == 0.0:
            aa = self.aa
        else:
            aa = None
        local = inner.translation if self.stretch is None else self.stretch @ inner.translation
        t = self.rotation @ (self.scale * local) + self.translation
        return Frame(self.rotation @ inner.rotation, t, self.scale * inner.scale, aa, own_rotation=inner.own_rotation)

    def apply(self, p) -> list[float]:
        local = np.asarray(p, dtype=np.float64)
        if self.stretch is not None:
            local = self.stretch @ local
        return [float(v) for v in self.rotation @ (self.scale * local) + self.translation]

    def pose(self) -> dict:
        out: dict[str, Any] = {"translation": [float(v) for v in self.translation]}
        if self.aa is None:
            out["quaternion"] = list(matrix_quaternion(self.rotation))
        elif self.aa[3] != 0.0:
            out["rotation"] = list(self.aa)
        return out

    def key(self) -> bytes:
        out = self.rotation.tobytes() + self.translation.tobytes() + np.float64(self.scale).tobytes()
        return out if self.stretch is None else out + self.stretch.tobytes()

    def linear(self) -> np.ndarray:
        """s·M: the scale part of the map, in this frame's axes."""
        return self.scale * (np.eye(3) if self.stretch is None else self.stretch)

    def aligned(self) -> tuple[float, float, float] | None:
        """The per-axis scale when the stretch is along this frame's own axes, else None (sheared)."""
        lin = self.linear()
        off = lin - np.diag(np.diag(lin))
        if np.abs(off).max() > _ALIGNED_TOL * np.abs(lin).max():
            return None
        return float(lin[0, 0]), float(lin[1, 1]), float(lin[2, 2])


def bounding_constraint(kind: str, scale: tuple[float, float, float]) -> tuple[tuple[float, float, float], str]:
    """Webots' scale constraint on a Transform in a boundingObject whose geometry is ``kind``: the
    scale it keeps and Webots' warning (empty when unchanged)."""
    x, y, z = scale
    if kind in ("Sphere", "Capsule"):
        if x != y:
            s = y if x == z else x
            return (s, s, s), "'scale' was made uniform because of physics constraints inside a 'boundingObject'."
        if y != z:
            return (z, z, z), "'scale' was made uniform because of physics constraints inside a 'boundingObject'."
    elif kind == "Cylinder" and x != y:
        # Webots keeps x unless x is still its initial 1 (mPreviousXscaleValue), then takes y
        out = (y, y, z) if x == 1.0 else (x, x, z)
        return out, "'scale' were changed so that x = y because of physics constraints inside a 'boundingObject'."
    return scale, ""


def bounding_geometry(kind: str, g: dict, scale: tuple[float, float, float]) -> dict:
    """A bounding geometry dict (sizes unscaled) scaled as Webots scales its ODE geom."""
    ax, ay, az = (abs(v) for v in scale)
    if kind == "box":
        return {**g, "size": [v * a for v, a in zip(g["size"], (ax, ay, az))]}
    if kind == "sphere":
        return {**g, "radius": g["radius"] * abs(max(scale))}
    if kind in ("cylinder", "capsule"):
        return {**g, "radius": g["radius"] * abs(max(scale[0], scale[1])), "height": g["height"] * az}
    if kind == "plane":
        return {**g, "size": [g["size"][0] * ax, g["size"][1] * ay]}
    if kind == "mesh":
        return {**g, "scale": [float(v) for v in scale]}
    if kind == "elevation_grid":        # WbElevationGrid: |scale| on the spacings, the z scale on the heights
        return {**g, "x_spacing": g["x_spacing"] * ax, "y_spacing": g["y_spacing"] * ay,
                "height": [h * scale[2] for h in g["height"]]}
    return _triangles_by(g, np.diag(np.asarray(scale, dtype=np.float64)))


def visual_geometry(kind: str, g: dict, frame: Frame) -> tuple[dict | None, str]:
    """A visual geometry dict (sizes unscaled) under ``frame``'s non-uniform scale: the exact affine
    image, as a primitive when it is one, else as triangles. (None, why) for what cannot be."""
    aligned = frame.aligned()
    if aligned is not None:
        ax, ay, az = (abs(v) for v in aligned)
        if kind == "box":
            return {**g, "size": [v * a for v, a in zip(g["size"], (ax, ay, az))]}, ""
        if kind == "plane":
            return {**g, "size": [g["size"][0] * ax, g["size"][1] * ay]}, ""
        if kind == "mesh":
            return {**g, "scale": [float(v) for v in aligned]}, ""
        if kind == "sphere" and ax == ay == az:
            return {**g, "radius": g["radius"] * ax}, ""
        if kind == "cylinder" and ax == ay:
            return {**g, "radius": g["radius"] * ax, "height": g["height"] * az}, ""
        if kind == "cone" and ax == ay and aligned[2] > 0:     # not turned upside down
            return {**g, "bottom_radius": g["bottom_radius"] * ax, "height": g["height"] * az}, ""
        if kind == "capsule" and ax == ay == az:
            return {**g, "radius": g["radius"] * ax, "height": g["height"] * az}, ""
        if kind == "elevation_grid" and min(aligned[0], aligned[1]) > 0:   # not mirrored in x or y
            return {**g, "x_spacing": g["x_spacing"] * ax, "y_spacing": g["y_spacing"] * ay,
                    "height": [h * aligned[2] for h in g["height"]]}, ""
    elif kind == "mesh":
        return None, (f"mesh {g['url']!r} under a scale that is not along its own axes (a rotation between "
                      "two non-uniform scales): not supported here; this shape is left out")
    lin = frame.linear()
    if kind in ("sphere", "cylinder", "capsule", "cone"):
        return _triangles_by(curved_triangles(kind, g), lin), ""
    if kind == "box":
        v, f = geo.tessellate(geo.Box(tuple(g["size"])))
        return _triangles_by({"type": "triangles", "vertices": v.tolist(), "faces": f.tolist()}, lin), ""
    if kind == "elevation_grid":        # mirrored or sheared: its triangles, mapped exactly
        v, f = geo.elevation_grid(g["height"], g["x_dimension"], g["x_spacing"], g["y_dimension"], g["y_spacing"])
        return _triangles_by({"type": "triangles", "vertices": v.tolist(), "faces": f.tolist()}, lin), ""
    if kind == "plane":
        sx, sy = (v / 2.0 for v in g["size"])
        quad = {"type": "triangles", "vertices": [[-sx, -sy, 0.0], [sx, -sy, 0.0], [sx, sy, 0.0], [-sx, sy, 0.0]],
                "faces": [[0, 1, 2], [0, 2, 3]]}
        return _triangles_by(quad, lin), ""
    return _triangles_by(g, lin), ""


def curved_triangles(kind: str, g: dict) -> dict:
    """A sphere, cylinder, capsule or cone as triangles whose vertices lie on its true surface."""
    if kind == "cone":
        r = float(g["bottom_radius"])
        v, f = geo.tessellate(geo.Cone(r, float(g["height"]), CURVED_LEVELS["cone"]))
        return {"type": "triangles", "vertices": _onto_axis_radius(v, r, None).tolist(), "faces": np.asarray(f).tolist()}
    r = float(g["radius"])
    if kind == "sphere":
        v, f = geo.tessellate(geo.Sphere(1.0, CURVED_LEVELS["sphere"]))
        v = v / np.linalg.norm(v, axis=1)[:, None] * r
    elif kind == "cylinder":
        n = CURVED_LEVELS["cylinder"]
        v, f = geo.tessellate(geo.Cylinder(r, float(g["height"]), n))
        v = _onto_axis_radius(v, r, None)
    else:
        h = float(g["height"]) / 2.0
        n_lat = CURVED_LEVELS["capsule"] // 4
        cap = [(r * math.sin(b), h + r * math.cos(b)) for b in (math.pi / 2 * k / n_lat for k in range(1, n_lat + 1))]
        profile = [(0.0, h + r), *cap, *[(rho, -z) for rho, z in reversed(cap)], (0.0, -h - r)]
        v, f = geo._revolve(profile, CURVED_LEVELS["capsule"])
        v = _onto_axis_radius(v, 0.0, profile)
    return {"type": "triangles", "vertices": np.asarray(v).tolist(), "faces": np.asarray(f).tolist()}


def _onto_axis_radius(v: np.ndarray, r: float, profile: list[tuple[float, float]] | None) -> np.ndarray:
    """Ring vertices of a circumscribed surface of revolution (``geometry._revolve``) moved back onto
    the true surface: radius ``r``, or each ring's profile radius (found by its height)."""
    out = np.array(v, dtype=np.float64)
    rho = np.hypot(out[:, 0], out[:, 1])
    ring = rho > 0
    if profile is None:
        want = np.full(len(out), r)
    else:
        by_z = {z: p for p, z in profile}
        want = np.array([by_z.get(z, 0.0) for z in out[:, 2]])
    out[ring, :2] *= (want[ring] / rho[ring])[:, None]
    return out


def _triangles_by(g: dict, lin: np.ndarray) -> dict:
    """Triangles (or an IndexedFaceSet's) with every vertex mapped by ``lin``; a mirroring map keeps
    the faces wound as before seen from outside."""
    out = dict(g)
    mapped = np.asarray(g["vertices"], dtype=np.float64) @ lin.T
    compact = isinstance(g["vertices"], np.ndarray)      # (an IndexedFaceSet's arrays stay arrays)
    out["vertices"] = mapped if compact else mapped.tolist()
    if np.linalg.det(lin) < 0:
        f = g["faces"]
        out["faces"] = f[:, [0, 2, 1]] if isinstance(f, np.ndarray) else [[a, c, b] for a, b, c in f]
        if "tex_coord_faces" in g:
            t = g["tex_coord_faces"]
            out["tex_coord_faces"] = t[:, [0, 2, 1]] if isinstance(t, np.ndarray) else [[a, c, b] for a, b, c in t]
    return out


def surface_gap(kind: str, height: float = 1.0, samples: int = 6) -> float:
    """The largest distance, over points sampled on every triangle, between ``curved_triangles`` of
    a unit-radius shape and its true surface (README quotes it, relative to the radius)."""
    tri = curved_triangles(kind, {"radius": 1.0, "height": height})
    v = np.asarray(tri["vertices"])[np.asarray(tri["faces"])]
    ab = [(i / samples, j / samples) for i in range(samples + 1) for j in range(samples + 1 - i)]
    w = np.array([(1.0 - a - b, a, b) for a, b in ab])
    p = np.einsum("kc,fcd->fkd", w, v).reshape(-1, 3)
    if kind == "sphere":
        d = np.linalg.norm(p, axis=1) - 1.0
    elif kind == "cylinder":
        q = np.stack([np.hypot(p[:, 0], p[:, 1]) - 1.0, np.abs(p[:, 2]) - height / 2.0], axis=1)
        d = np.where((q > 0).any(axis=1), np.linalg.norm(np.maximum(q, 0.0), axis=1), q.max(axis=1))
    else:
        c = np.clip(p[:, 2], -height / 2.0, height / 2.0)
        d = np.hypot(np.hypot(p[:, 0], p[:, 1]), p[:, 2] - c) - 1.0
    return float(np.abs(d).max())
