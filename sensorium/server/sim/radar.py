"""The simulation's Radar (Webots' node; the model is ``server/devices/radar.py``): at each
measurement it places the scene's radar targets (robots, the solids they carry and top-level solids
with a radar cross section, ``Scene.radar_targets``) in its frame — each one's box, from its bounding
shapes (else all its shapes; a robot's shapes on its joints where the joints have put them) clipped
to the radar's frustum, as Webots' ``WbObjectDetection`` (the geometry a camera's recognition uses,
``devices/recognition.py``), or its origin when it has no shape —, computes their radial speeds
from their positions at its previous measurement, and, with ``occlusion``, casts one ray to each
detected target's origin (Webots' ONE_RAY): a target is hidden when the ray meets any shape but the
target's own more than half its box's x extent before its origin."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.devices import radar as rmath
from sensorium.server.devices import recognition as geo
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.recognition import shape_kind
from sensorium.server.sim.scene import TargetKey
from sensorium.server.sim.sensors import Device

__all__ = ["Radar"]


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

    def _target_parts(self, key: TargetKey) -> tuple[tuple, frozenset[int]]:
        """A target's shapes as (the shape when it rides on a joint's link, else -1; pose in its owner's
        frame, kind, params, points): its bounding shapes, else all of them (Webots: its bounding
        objects, else its bounding sphere); infinite planes left out. And all its shapes (those an
        occlusion ray passes)."""
        scene = self._robot.scene
        if self._parts_version != scene.shapes_version:          # a Supervisor imported shapes
            self._parts, self._parts_version = {}, scene.shapes_version
        parts = self._parts.get(key)
        if parts is None:
            shapes = scene.target_shapes(key)
            bounding = [i for i in shapes if scene.part(i)[2].seen_by in ("both", "bounding")]
            placed = ((i if scene.on_link(i) else -1, scene.part(i)[1],
                       *shape_kind(scene.part(i)[2].geometry, scene.base_dir)) for i in (bounding or shapes))
            parts = self._parts[key] = (tuple(p for p in placed if p[2] != "unbounded"), frozenset(shapes))
        return parts

    def _box(self, key: TargetKey, at: np.ndarray, radar: Any, inverse: np.ndarray) -> tuple[np.ndarray, float] | None:
        """The centre and x extent of a target's box in view (radar frame), None when nothing of it is in
        view; its origin ``at`` (size 0) for a target without shapes, if it is in view."""
        scene = self._robot.scene
        parts = self._target_parts(key)[0]
        if not parts:
            local = inverse @ (at - radar.translation)
            return (local, 0.0) if rmath.in_frustum(local, self._frustum) else None
        owner = scene.owner_pose(key[0] if isinstance(key, tuple) else key)     # its shapes' frame
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for link, local_pose, kind, params, points in parts:
            pose = (owner if link < 0 else scene.carrier(link)).compose(local_pose)   # on a joint: where it put it
            _, seen = geo.clipped_bounds(kind, params, inverse @ pose.rotation,
                                         inverse @ (pose.translation - radar.translation), points, self._frustum)
            if seen is not None:
                lo, hi = np.minimum(lo, seen[0]), np.maximum(hi, seen[1])
        if not np.isfinite(lo).all():
            return None
        return (lo + hi) / 2.0, float(hi[0] - lo[0])

    def measure(self, now_ms: int) -> None:
        scene = self._robot.scene
        pose = self.world_pose(self._robot.pose)
        origin = np.asarray(pose.translation, dtype=np.float64)
        inverse = np.asarray(pose.rotation, dtype=np.float64).T
        elapsed = now_ms - self.schedule.last_update_ms
        keys, candidates, now = [], [], {}
        for key, rcs in scene.radar_targets.items():
            at = np.asarray(scene.target_pose(key).translation, dtype=np.float64)
            now[key] = at
            offset = at - origin
            d = float(np.linalg.norm(offset))
            if d == 0.0:                      # the radar's own place (the radar itself): no direction
                continue
            box = self._box(key, at, pose, inverse)
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
        own = self._target_parts(key)[1]
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
