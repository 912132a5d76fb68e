"""The simulation's Radar (Webots' node; the model is ``server/devices/radar.py``): at each
measurement it places the scene's radar targets (robots and top-level solids with a radar cross
section, ``Scene.radar_targets``) in its frame, computes their radial speeds from their positions
at its previous measurement, and, with ``occlusion``, casts one ray to each detected target's
origin: a target whose ray first meets another body's shape is hidden (Webots casts that ray
against bounding objects)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.devices import radar as rmath
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.sensors import Device

__all__ = ["Radar"]


class Radar(Device):
    """Webots Radar: ``targets`` (a list of :class:`~sensorium.server.devices.radar.RadarTarget`),
    empty before the first value."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.targets: list[rmath.RadarTarget] = []
        self._robot: Any = None
        self._previous: dict[str | int, np.ndarray] = {}     # each target's position at the previous measurement
        self._radar_before: np.ndarray | None = None
        self._noisy = any(getattr(self.config, f) > 0.0 for f in ("range_noise", "speed_noise", "angular_noise"))

    def bind(self, robot: Any) -> None:
        self._robot = robot

    def measure(self, now_ms: int) -> None:
        scene = self._robot.scene
        pose = self.world_pose(self._robot.pose)
        origin = np.asarray(pose.translation, dtype=np.float64)
        inverse = np.asarray(pose.rotation, dtype=np.float64).T
        elapsed = now_ms - self.schedule.last_update_ms
        keys, candidates, now = [], [], {}
        for key, rcs in scene.radar_targets.items():
            at = np.asarray(scene.owner_pose(key).translation, dtype=np.float64)
            now[key] = at
            offset = at - origin
            d = float(np.linalg.norm(offset))
            if d == 0.0:                      # the radar's own place: no direction, never in its frustum
                continue
            speed = rmath.radial_speed(offset / d, at, self._previous.get(key), origin, self._radar_before, elapsed)
            keys.append(key)
            candidates.append(rmath.Candidate(inverse @ offset, rcs, speed))
        found = rmath.candidate_targets(candidates, self.config, self.rng if self._noisy else None)
        if self.config.occlusion:
            found = [(k, t) for k, t in found if self._visible(keys[k], candidates[k].local, pose)]
        self.targets = rmath.finish([t for _, t in found], self.config)
        self._previous = now
        self._radar_before = origin
        self._mark(now_ms)

    def _visible(self, key: str | int, local: np.ndarray, pose: Any) -> bool:
        """One ray from the radar to the target's origin: seen if it reaches it or first meets one
        of the target's own shapes (the radar's own robot is not in the way, as for cameras)."""
        scene = self._robot.scene
        length = float(np.linalg.norm(local))
        direction = (pose.rotation @ local) / length
        hits = scene.engine.cast(np.asarray(pose.translation, dtype=np.float64).reshape(1, 3), direction.reshape(1, 3),
                                 0.0, length, kind=RayKind.BOUNDING, exclude_owner=self._robot.index)
        if not math.isfinite(float(hits.distance[0])):
            return True
        return scene.part(int(hits.shape[0]))[0] == key

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
