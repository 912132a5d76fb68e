"""The simulation's Radar (Webots' node; the model is ``server/devices/radar.py``): at each
measurement it places the scene's radar targets (robots, the solids they carry and top-level solids
with a radar cross section, ``Scene.radar_targets``) in its frame — each one's box, from its bounding
shapes (a robot's shapes on its joints where the joints have put them) clipped to the radar's
frustum, else from its bounding sphere, as Webots' ``WbObjectDetection`` (the geometry a camera's
recognition uses, ``devices/recognition.py``), or its origin when it has no shape —, computes their
radial speeds from their positions at its previous measurement, and, with ``occlusion``, casts one
ray to each detected target's origin (Webots' ONE_RAY): a target is hidden when the ray meets any
shape but the target's own more than half its box's x extent before its origin."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import radar as rmath
from sensorium.server.devices import recognition as geo
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.recognition import link_of, part_pose, shape_kind, shape_part
from sensorium.server.sim.scene import TargetKey
from sensorium.server.sim.sensors import Device

__all__ = ["Radar"]


def geometry_sphere(g: Any, base_dir: Any) -> tuple[np.ndarray, float] | None:
    """Webots' bounding sphere of a geometry (centre in its frame, radius; its ``recomputeBoundingSphere``):
    a box's or plane's half diagonal, a cylinder's corner circle, a capsule's tips, a cone's sphere
    through its apex and base rim (its base disc when it is not taller than wide), Ritter's sphere
    of a mesh's or elevation grid's points; None for an infinite plane."""
    if isinstance(g, wm.Box):
        return np.zeros(3), float(np.linalg.norm(g.size)) / 2.0
    if isinstance(g, wm.Sphere):
        return np.zeros(3), float(g.radius)
    if isinstance(g, wm.Cylinder):
        return np.zeros(3), math.hypot(g.radius, g.height / 2.0)
    if isinstance(g, wm.Capsule):
        return np.zeros(3), g.height / 2.0 + g.radius
    if isinstance(g, wm.Cone):
        half, r = g.height / 2.0, g.bottom_radius
        if g.height <= r:
            return np.array([0.0, 0.0, -half]), float(r)
        radius = half + r * r / (2.0 * g.height)
        return np.array([0.0, 0.0, half - radius]), radius
    if isinstance(g, wm.Plane):
        return None if g.size is None else (np.zeros(3), math.hypot(*g.size) / 2.0)
    _, _, points = shape_kind(g, base_dir)
    return rmath.ritter_sphere(points) if points is not None else None


class Radar(Device):
    """Webots Radar: ``targets`` (a list of :class:`~sensorium.server.devices.radar.RadarTarget`),
    empty before the first value."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.targets: list[rmath.RadarTarget] = []
        self._robot: Any = None
        self._previous: dict[TargetKey, np.ndarray] = {}     # each target's position at the previous measurement
        self._radar_before: np.ndarray | None = None
        self._noisy = any(getattr(c, f) > 0.0 for f in ("range_noise", "speed_noise", "angular_noise"))
        self._frustum = rmath.frustum(c.horizontal_field_of_view, c.vertical_field_of_view)
        self._parts: dict[TargetKey, tuple] = {}
        self._parts_version = -1

    def bind(self, robot: Any) -> None:
        self._robot = robot

    def _target_parts(self, key: TargetKey) -> tuple[tuple, tuple, frozenset[int]]:
        """A target's shapes, each with the shape when it rides on a joint's link (else -1) and its pose
        in its owner's frame: its bounding shapes as (link, pose, kind, params, points) — their boxes
        make its box —, or, without any, its visual shapes as (link, pose, sphere centre in the shape's
        frame, radius) — Webots bounds it with its bounding sphere then; infinite planes left out. And
        all its shapes (those an occlusion ray passes)."""
        scene = self._robot.scene
        if self._parts_version != scene.shapes_version:          # a Supervisor imported shapes
            self._parts, self._parts_version = {}, scene.shapes_version
        parts = self._parts.get(key)
        if parts is None:
            shapes = scene.target_shapes(key)
            bounding = [i for i in shapes if scene.part(i)[2].seen_by in ("both", "bounding")]
            boxes = tuple(p for p in (shape_part(scene, i) for i in bounding) if p[2] != "unbounded")
            spheres = () if bounding else tuple(
                (link_of(scene, i), scene.part(i)[1], *sphere)
                for i in shapes if (sphere := geometry_sphere(scene.part(i)[2].geometry, scene.base_dir)) is not None)
            parts = self._parts[key] = (boxes, spheres, frozenset(shapes))
        return parts

    def _box(self, key: TargetKey, at: Any, radar: Any, inverse: np.ndarray) -> tuple[np.ndarray, float] | None:
        """The centre and x extent of a target's box in view (radar frame), None when nothing of it is in
        view: from its bounding shapes, else from its bounding sphere; a target without any shape is its
        origin (size 0), a point, if it is in view. ``at``: the target's pose now."""
        scene = self._robot.scene
        boxes, spheres, _ = self._target_parts(key)
        owner = scene.owner_pose(key[0] if isinstance(key, tuple) else key)     # its shapes' frame
        if spheres:
            return self._sphere_box(spheres, owner, at, radar, inverse)
        if not boxes:
            local = inverse @ (np.asarray(at.translation, dtype=np.float64) - radar.translation)
            return (local, 0.0) if rmath.in_frustum(local, self._frustum) else None
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for link, local_pose, kind, params, points in boxes:
            pose = part_pose(scene, owner, link, local_pose)
            _, seen = geo.clipped_bounds(kind, params, inverse @ pose.rotation,
                                         inverse @ (pose.translation - radar.translation), points, self._frustum)
            if seen is not None:
                lo, hi = np.minimum(lo, seen[0]), np.maximum(hi, seen[1])
        if not np.isfinite(lo).all():
            return None
        return (lo + hi) / 2.0, float(hi[0] - lo[0])

    def _sphere_box(self, spheres: tuple, owner: Any, at: Any, radar: Any,
                    inverse: np.ndarray) -> tuple[np.ndarray, float] | None:
        """Webots' box of a target without bounding objects: its bounding sphere (its shapes' spheres
        enclosed one after the other in its own frame, WbBoundingSphere) cut to the frustum across
        the view only, as a bounding sphere object (its x extent stays the diameter)."""
        scene = self._robot.scene
        to_target = at.inverse()
        centre, radius = np.zeros(3), 0.0
        for link, local_pose, c, r in spheres:
            pose = part_pose(scene, owner, link, local_pose)
            centre, radius = rmath.enclose_sphere(centre, radius, to_target.apply(pose.apply(c)), r)
        local = inverse @ (at.apply(centre) - radar.translation)
        seen = geo.clip_round(local - radius, local + radius, self._frustum)
        if seen is None:
            return None
        return (seen[0] + seen[1]) / 2.0, 2.0 * radius

    def measure(self, now_ms: int) -> None:
        scene = self._robot.scene
        pose = self.world_pose(self._robot.pose)
        origin = np.asarray(pose.translation, dtype=np.float64)
        inverse = np.asarray(pose.rotation, dtype=np.float64).T
        elapsed = now_ms - self.schedule.last_update_ms
        keys, candidates, now = [], [], {}
        for key, rcs in scene.radar_targets.items():
            target = scene.target_pose(key)
            at = np.asarray(target.translation, dtype=np.float64)
            now[key] = at
            offset = at - origin
            d = float(np.linalg.norm(offset))
            if d == 0.0:                      # the radar's own place (the radar itself): no direction
                continue
            box = self._box(key, target, pose, inverse)
            if box is None:
                continue
            speed = rmath.radial_speed(offset / d, at, self._previous.get(key), origin, self._radar_before, elapsed)
            keys.append(key)
            candidates.append(rmath.Candidate(box[0], inverse @ offset, box[1], rcs, speed))
        found = rmath.candidate_targets(candidates, self.config, self.rng if self._noisy else None)
        if self.config.occlusion:
            found = [(k, t) for k, t in found if self._visible(keys[k], candidates[k], pose)]
        self.targets = rmath.finish([t for _, t in found], self.config)
        self._previous = now
        self._radar_before = origin
        self._mark(now_ms)

    def _visible(self, key: TargetKey, cand: rmath.Candidate, pose: Any) -> bool:
        """One ray from the radar to the target's origin against bounding shapes (Webots' ONE_RAY): the
        target is hidden when any other body's shape meets it more than half the target's box (along x)
        before the origin (Webots' hasCollided over every contact of the ray but the target's own). The
        target's own shapes are passed through, whatever is behind them still counts; the radar's own
        robot is never in the way (Webots collides no ray with its own robot)."""
        scene = self._robot.scene
        own = self._target_parts(key)[2]
        length = float(np.linalg.norm(cand.origin))
        start = np.asarray(pose.translation, dtype=np.float64).reshape(1, 3)
        direction = ((pose.rotation @ cand.origin) / length).reshape(1, 3)
        near = 0.0
        for _ in range(256):                  # each pass steps past one of the target's own shapes
            hits = scene.engine.cast(start, direction, near, length, kind=RayKind.BOUNDING,
                                     exclude_owner=self._robot.index)
            distance = float(hits.distance[0])
            if not math.isfinite(distance):
                return True
            if int(hits.shape[0]) not in own:
                return length - distance <= 0.5 * cand.size
            near = distance + 1e-9 * max(1.0, distance)
        return True

    def restart(self) -> None:
        """A simulation reset: no previous positions, so the next value's speeds are NaN (Webots'
        WbRadar::reset forgets them too)."""
        self._previous = {}
        self._radar_before = None

    def readings(self) -> dict:
        """(n, 4) float64: distance, received power, speed, azimuth of each target (``sensorium probe``)."""
        return {"targets": np.array([t.as_list() for t in self.targets], dtype=np.float64).reshape(-1, 4)}

    def step_reading(self) -> dict:
        return {"targets": [v for t in self.targets for v in t.as_list()]}

    def describe(self) -> dict:
        c = self.config
        return {"min_range": float(c.min_range), "max_range": float(c.max_range),
                "horizontal_fov": float(c.horizontal_field_of_view), "vertical_fov": float(c.vertical_field_of_view)}
