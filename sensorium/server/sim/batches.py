"""Light and distance sensors due in the same step, planned and reduced together.

A step may have hundreds of small sensors (8 infra-red sensors per e-puck); handling each with its
own numpy calls costs far more than its rays. Here every per-sensor quantity is stacked once, rays
of sensors with the same ray count are built in one array operation, the reduction formulas run
on (sensors × rays) arrays, and sensors sharing a lookup table are interpolated together. Only the
noise is drawn per sensor, from the sensor's own stream, so values do not depend on batching.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np

from sensorium.server.devices import distance as dmath
from sensorium.server.devices import light as light_math
from sensorium.server.devices.lookup import add_noise, quantize_sensor
from sensorium.server.raycast.engine import RayHits, RayKind
from sensorium.server.sim.sensors import DistanceSensor, LightSensor, RayRequest
from sensorium.server.world.geometry import Pose

_INFRA_RED = dmath.SENSOR_TYPES["infra-red"]
_LASER = dmath.SENSOR_TYPES["laser"]


def world_frames(devices: list, robot_poses: list[Pose]) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (S,3,3) and positions (S,3) of devices: robot pose ∘ device pose."""
    rr = np.stack([robot_poses[d.robot_index].rotation for d in devices])
    rt = np.stack([robot_poses[d.robot_index].translation for d in devices])
    lr = np.stack([d.local_pose.rotation for d in devices])
    lt = np.stack([d.local_pose.translation for d in devices])
    return np.einsum("sij,sjk->sik", rr, lr), np.einsum("sij,sj->si", rr, lt) + rt


def _output(devices: list, measured: np.ndarray, now_ms: int) -> None:
    """Lookup (grouped by table), per-sensor noise, resolution; store the values."""
    by_table: dict = defaultdict(list)
    for i, d in enumerate(devices):
        by_table[d.table].append(i)
    for table, idx in by_table.items():
        if len(table) == 0:          # devices.md §1.2: an empty table is the identity, without noise
            y, n = np.asarray(measured[idx], dtype=np.float64), np.zeros(len(idx))
        else:
            y, n = table.interpolate(measured[idx])
        for k, i in enumerate(idx):
            d = devices[i]
            v = y[k:k + 1]
            if n[k] != 0.0:   # noise drawn only when non-zero, from the device's own stream
                v = add_noise(v, n[k:k + 1], d.rng)
            d.value = float(quantize_sensor(float(v[0]), d.config.resolution))
            d._mark(now_ms)


class LightBatch:
    """All light sensors due this step."""

    def __init__(self, devices: list[LightSensor], robot_poses: list[Pose], lights: light_math.LightArrays):
        self.devices = devices
        self.lights = lights
        rot, self.positions = world_frames(devices, robot_poses)
        self.normals = rot[:, :, 0]                      # a light sensor looks along its +x axis
        self.filters = np.array([d.config.color_filter for d in devices], dtype=np.float64)
        self.att, self.direct = light_math.light_terms(self.positions, self.normals, lights)
        self._pairs: tuple[np.ndarray, np.ndarray] | None = None

    def plan(self) -> list[RayRequest]:
        occluding = np.array([d.config.occlusion for d in self.devices])
        if self.lights.count == 0 or not occluding.any():
            return []
        # occlusion rays only toward lights that light the sensor directly: ambient is never
        # occluded, so a light with no direct term cannot change the value
        mask = (self.direct > 0.0) & occluding[:, None]
        s, light = np.nonzero(mask)
        if s.size == 0:
            return []
        self._pairs = (s, light)
        unit, length = light_math.occlusion_segments_many(self.positions[s], self.lights)
        rows = np.arange(s.size)
        exclude = np.array([d.exclude_self() for d in self.devices], dtype=np.int64)[s]
        return [RayRequest(self.positions[s], unit[rows, light], 0.0, length[rows, light],
                           RayKind.BOUNDING, exclude, tag="light")]

    def finish(self, hits: list[RayHits], now_ms: int) -> None:
        occluded = np.zeros((len(self.devices), self.lights.count), dtype=bool)
        if self._pairs is not None:
            s, light = self._pairs
            occluded[s, light] = np.isfinite(hits[0].distance)
        e = light_math.irradiance_from_terms(self.att, self.direct, self.lights, occluded, self.filters)
        _output(self.devices, e, now_ms)


class DistanceBatch:
    """All distance sensors due this step; sensors with the same ray count share array shapes."""

    def __init__(self, devices: list[DistanceSensor], robot_poses: list[Pose], scene_red: np.ndarray,
                 scene_roughness: np.ndarray):
        self.red, self.roughness = scene_red, scene_roughness
        self.empty = [d for d in devices if not d.config.lookup_table]     # value 0, no ray matters (§3.1)
        self.devices = [d for d in devices if d.config.lookup_table]
        self.groups: list[tuple[list[int], np.ndarray, int, bool]] = []   # (indices, world dirs, kind, skip)
        if not self.devices:
            return
        rot, self.positions = world_frames(self.devices, robot_poses)
        by_shape: dict = defaultdict(list)
        for i, d in enumerate(self.devices):
            infra_red = d.type_code == _INFRA_RED
            by_shape[(len(d.weights), RayKind.VISUAL if infra_red else RayKind.BOUNDING, d.type_code == _LASER)].append(i)
        for (_n, kind, skip), idx in by_shape.items():
            local = np.stack([self.devices[i].directions_local for i in idx])           # (S, N, 3)
            dirs = np.einsum("sij,snj->sni", rot[idx], local)
            self.groups.append((idx, dirs, kind, skip))

    def plan(self) -> list[RayRequest]:
        requests = []
        for idx, dirs, kind, skip in self.groups:
            devs = [self.devices[i] for i in idx]
            n = dirs.shape[1]
            # infra-red sees the robot's own visual shapes (Webots); ODE-style rays skip them
            exclude = np.array([-1 if kind == RayKind.VISUAL else d.exclude_self() for d in devs], dtype=np.int64)
            requests.append(RayRequest(
                np.repeat(self.positions[idx], n, axis=0), dirs.reshape(-1, 3), 0.0,
                np.repeat(np.array([d.lut_max_range for d in devs]), n), kind, np.repeat(exclude, n),
                skip_transparent=skip, tag="distance"))
        return requests

    def finish(self, hits: list[RayHits], now_ms: int) -> None:
        for d in self.empty:
            d.value = 0.0
            d._mark(now_ms)
        if not self.devices:
            return
        measured = np.empty(len(self.devices))
        for (idx, dirs, kind, _skip), h in zip(self.groups, hits):
            devs = [self.devices[i] for i in idx]
            S, n = dirs.shape[:2]
            dist = h.distance.reshape(S, n)
            types = np.array([d.type_code for d in devs])
            reflection = None
            if kind == RayKind.VISUAL:
                # colour lookups only for infra-red; shape -1 picks the trailing "no hit" entry
                shape = h.shape.reshape(S, n)
                reflection = np.where(shape >= 0, dmath.reflection_factor(self.red[shape], self.roughness[shape]), 1.0)
            measured[idx] = dmath.combine_distance_batch(
                types, dist, dirs, h.normal.reshape(S, n, 3), np.stack([d.weights for d in devs]),
                np.array([d.lut_max_range for d in devs]), reflection,
                np.array([d.config.red_color_sensitivity for d in devs]))
        _output(self.devices, measured, now_ms)
