"""A camera's Recognition (Webots' node): which recognisable objects it sees and where, and its
segmentation image. The geometry is ``server/devices/recognition.py``; this module gathers the
objects' shapes from the scene once, places them at each recognition, and casts the rays the
occlusion test needs (Webots' ``occlusion`` field):

* 0 — no test: every object in range and on the image is recognised;
* 1 — one ray from the camera to the object's origin (its Solid's or robot's translation, as
  Webots aims it, in view or not): recognised if it reaches the origin or first meets one of the
  object's own shapes (Webots' ray meets bounding objects; ours visible shapes);
* 2 — the image's pixel rays: recognised if at least one pixel sees it (exact at the image's
  resolution; Webots tests the object's outline).

An object's box (a robot's shapes on its joints where the joints have put them, as Webots bounds
the Solids past a joint where they are) is, for a planar camera, that of its part in view (Webots clips each shape to the
view first; a non-planar camera's boxes are whole). An object is in range when that box reaches in
front of the camera and starts before ``max_range`` (in depth). ``max_objects`` (> 0) keeps the biggest
on the image (``size_on_image`` area), listed biggest first as Webots does (ties in id order); otherwise
objects come in id order. The segmentation image: each pixel whose ray's first visible surface belongs to a
recognisable object within ``max_range`` (depth for a planar camera) has the object's first
recognition colour, the rest black; alpha 255.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import imaging
from sensorium.server.devices import recognition as rmath
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.scene import primitive_from_model
from sensorium.server.world.arrays import unique_ints
from sensorium.server.world.geometry import Pose, tessellate
from sensorium.server.world.poses import axis_angle

__all__ = ["RecognisedObject", "Recognizer", "shape_kind"]


@dataclass(frozen=True, slots=True)
class RecognisedObject:
    """One object a camera recognised (Webots' ``WbCameraRecognitionObject``)."""

    id: int
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    size: tuple[float, float]
    position_on_image: tuple[int, int]
    size_on_image: tuple[int, int]
    colors: tuple[tuple[float, float, float], ...]
    model: str

    def as_dict(self) -> dict:
        return {"id": self.id, "position": list(self.position), "orientation": list(self.orientation),
                "size": list(self.size), "position_on_image": list(self.position_on_image),
                "size_on_image": list(self.size_on_image), "colors": [v for c in self.colors for v in c],
                "model": self.model}


@dataclass(frozen=True, slots=True)
class _Object:
    key: str | int
    id: int
    colors: tuple[tuple[float, float, float], ...]
    model: str
    shapes: tuple[int, ...]                                # every shape (occlusion, segmentation)
    # the shapes its size is read from: (the shape when it rides on a joint's link, else -1; its pose in its
    # owner's frame, kind, params, points)
    parts: tuple[tuple[int, Pose, str, tuple, np.ndarray | None], ...]


def shape_kind(g: Any, base_dir: Any) -> tuple[str, tuple, np.ndarray | None]:
    """A geometry as ``devices/recognition.py`` bounds it: (kind, params, points in its frame)."""
    if isinstance(g, wm.Box):
        return "box", (tuple(g.size),), None
    if isinstance(g, wm.Sphere):
        return "sphere", (g.radius,), None
    if isinstance(g, wm.Cylinder):
        return "cylinder", (g.radius, g.height), None
    if isinstance(g, wm.Capsule):
        return "capsule", (g.radius, g.height), None
    if isinstance(g, wm.Plane):
        if g.size is None:
            return "unbounded", (), None
        sx, sy = g.size[0] / 2.0, g.size[1] / 2.0
        return "points", (), np.array([[sx, sy, 0.0], [sx, -sy, 0.0], [-sx, sy, 0.0], [-sx, -sy, 0.0]])
    if isinstance(g, wm.Triangles):
        return "points", (), np.asarray(g.vertices, dtype=np.float64).reshape(-1, 3)
    if isinstance(g, wm.Cone):   # its tessellation's corners: the circumscribed pyramid (a little larger)
        return "points", (), np.asarray(tessellate(primitive_from_model(g, base_dir))[0], dtype=np.float64)
    return "points", (), np.asarray(primitive_from_model(g, base_dir).vertices, dtype=np.float64)


def link_of(scene: Any, shape: int) -> int:
    """The shape itself when it rides on a joint's link (``Scene.carrier`` places it then), else -1:
    the first entry of the parts an object's or radar target's box is read from."""
    return shape if scene.on_link(shape) else -1


def shape_part(scene: Any, shape: int) -> tuple:
    """A shape as an object's box is read from it: (:func:`link_of`, its pose in its owner's frame,
    kind, params, points)."""
    return (link_of(scene, shape), scene.part(shape)[1], *shape_kind(scene.part(shape)[2].geometry, scene.base_dir))


def part_pose(scene: Any, owner: Pose, link: int, local: Pose) -> Pose:
    """A part's pose now: ``local`` in its owner's frame (``owner``, its pose now), on a joint's
    link where the joint has put it."""
    return (owner if link < 0 else scene.carrier(link)).compose(local)


def occlusion_ray(cam: Pose, centre: np.ndarray) -> tuple[np.ndarray, float] | None:
    """The occlusion ray (world direction, length) from the camera at ``cam`` to a camera-frame
    point, None when the point is the camera's own place (seen)."""
    d = cam.rotation @ centre
    dist = float(np.linalg.norm(d))
    if dist == 0.0:
        return None
    return d / dist, dist


class Recognizer:
    """The recognisable objects of a scene as one camera (on robot ``own``) sees them."""

    def __init__(self, scene: Any, own: int, config: wm.Recognition, geometry: imaging.ImageGeometry):
        self.scene = scene
        self.own = own
        self.config = config
        self.geometry = geometry
        self.frustum = rmath.frustum(geometry)          # None: a non-planar camera's boxes are not clipped
        self.key_of = np.full(len(scene.shapes) + 1, -1, dtype=np.int64)   # shape -> object index (-1: none)
        objects: list[_Object] = []
        by_owner: dict[Any, list[int]] = {}            # one pass over the shapes
        for i in range(len(scene.shapes)):
            key = scene.part(i)[0]
            if key in scene.recognisable:
                by_owner.setdefault(key, []).append(i)
        for key, (node_id, colors, model) in sorted(scene.recognisable.items(), key=lambda kv: kv[1][0]):
            if key == own:                      # Webots skips the camera's own robot and what it carries
                continue
            shapes = by_owner.get(key, [])
            bounding = [i for i in shapes if scene.part(i)[2].seen_by in ("both", "bounding")]
            parts = tuple(shape_part(scene, i) for i in (bounding or shapes))
            self.key_of[shapes] = len(objects)
            objects.append(_Object(key, node_id, tuple(colors), model, tuple(shapes), parts))  # type: ignore[arg-type]
        self.objects = objects
        self.first_color = np.array([o.colors[0] for o in objects] + [(0.0, 0.0, 0.0)]).reshape(-1, 3)

    def _box(self, obj: _Object, cam: Pose) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The object's box (lo, hi) in the camera frame — for a planar camera the union of its
        shapes' parts in view (Webots' clipping, ``devices/recognition.py``), else of its whole
        shapes — and its origin there (the occlusion ray's target: Webots aims at the Solid's
        position, which may lie far from its box's centre); None if a shape is unbounded or nothing
        of it is in view."""
        owner = self.scene.owner_pose(obj.key)
        inv = cam.rotation.T
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        for link, local, kind, params, points in obj.parts:
            if kind == "unbounded":
                return None
            pose = part_pose(self.scene, owner, link, local)
            rotation, centre = inv @ pose.rotation, inv @ (pose.translation - cam.translation)
            whole, b = rmath.clipped_bounds(kind, params, rotation, centre, points, self.frustum)
            if whole is not None and b is not None:
                lo, hi = np.minimum(lo, b[0]), np.maximum(hi, b[1])
        return (lo, hi, inv @ (owner.translation - cam.translation)) if np.isfinite(lo).all() else None

    def recognise(self, cam: Pose, pixel_objects: np.ndarray | None, counters: Any) -> list[RecognisedObject]:
        """The objects seen from the camera pose ``cam``; ``pixel_objects`` (H·W,) the object index
        each pixel sees (-1 none), needed for occlusion 2."""
        seen = self.candidates(cam, pixel_objects)
        if self.config.occlusion == 1:
            seen = [s for s in seen if self._origin_visible(s[0], cam, s[2], counters)]
        return self.trim([s[1] for s in seen])

    def candidates(self, cam: Pose, pixel_objects: np.ndarray | None) -> list[tuple[int, RecognisedObject, np.ndarray]]:
        """(object index, object, its occlusion ray's target in the camera frame) of every object in
        range, on the image and (occlusion 2) seen by a pixel: those occlusion 1 then tests."""
        c = self.config
        out: list[tuple[int, RecognisedObject, np.ndarray]] = []
        seen_by_pixels = set(unique_ints(pixel_objects).tolist()) if pixel_objects is not None else set()
        for k, obj in enumerate(self.objects):
            if obj.key not in self.scene.recognisable:     # removed by a Supervisor
                continue
            box = self._box(obj, cam)
            if box is None:
                continue
            lo, hi, target = box
            if not (hi[0] > 0.0 and lo[0] < c.max_range):
                continue
            centre, size = (lo + hi) / 2.0, hi - lo
            on_image = rmath.box_on_image(centre, size, self.geometry)
            if on_image is None:
                continue
            if c.occlusion == 2 and k not in seen_by_pixels:
                continue
            orientation = axis_angle(cam.rotation.T @ self.scene.owner_pose(obj.key).rotation)
            out.append((k, RecognisedObject(obj.id, tuple(float(v) for v in centre), tuple(float(v) for v in orientation),  # type: ignore[arg-type]
                                            (float(size[1]), float(size[2])), on_image[0], on_image[1], obj.colors,
                                            obj.model), target))
        return out

    def trim(self, out: list[RecognisedObject]) -> list[RecognisedObject]:
        """``max_objects`` (> 0) keeps the biggest on the image, biggest first."""
        c = self.config
        if c.max_objects > 0 and len(out) > c.max_objects:     # Webots: -1 and 0 keep every object
            keep = sorted(range(len(out)), key=lambda i: -out[i].size_on_image[0] * out[i].size_on_image[1])
            out = [out[i] for i in keep[:c.max_objects]]      # biggest first, as Webots lists them then
        return out

    def _origin_visible(self, k: int, cam: Pose, origin: np.ndarray, counters: Any) -> bool:
        ray = occlusion_ray(cam, origin)
        if ray is None:
            return True
        hits = self.scene.engine.cast(cam.translation.reshape(1, 3), ray[0].reshape(1, 3), 0.0, ray[1],
                                      kind=RayKind.VISUAL, exclude_owner=self.own)
        counters["rays_camera"] += 1
        counters["cast_calls"] += 1
        return self.reached(k, float(hits.distance[0]), int(hits.shape[0]))

    def reached(self, k: int, distance: float, shape: int) -> bool:
        """Object ``k``'s occlusion ray (its hit: distance, shape) reached it: nothing in the way, or
        the object itself first."""
        return not math.isfinite(distance) or int(self.key_of[shape]) == k

    def segmentation(self, pixel_objects: np.ndarray, height: int, width: int) -> np.ndarray:
        """BGRA (H, W, 4): each pixel the first recognition colour of the object it sees, else black."""
        rgb = np.floor(self.first_color[pixel_objects] * 255.0 + 0.5).astype(np.uint8).reshape(height, width, 3)
        out = np.empty((height, width, 4), dtype=np.uint8)
        out[:, :, 0], out[:, :, 1], out[:, :, 2], out[:, :, 3] = rgb[:, :, 2], rgb[:, :, 1], rgb[:, :, 0], 255
        return out
