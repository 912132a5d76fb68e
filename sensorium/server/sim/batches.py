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
from sensorium.server.devices.lookup import RESOLUTION_OFF, add_noise, quantize_sensor
from sensorium.server.raycast.engine import Mount, RayHits, RayKind
from sensorium.server.sim.own_shapes import cast_local_skipping
from sensorium.server.sim.sensors import DistanceSensor, LightSensor, RayRequest
from sensorium.server.world.arrays import unique_ints
from sensorium.server.world.geometry import Pose

_INFRA_RED = dmath.SENSOR_TYPES["infra-red"]
_LASER = dmath.SENSOR_TYPES["laser"]


def world_frames(devices: list, robot_poses: list[Pose]) -> tuple[np.ndarray, np.ndarray]:
    """World rotations (S,3,3) and positions (S,3) of devices: robot pose ∘ device pose."""
    rr = np.array([robot_poses[d.robot_index].rotation for d in devices])
    rt = np.array([robot_poses[d.robot_index].translation for d in devices])
    lr = np.array([d.local_pose.rotation for d in devices])
    lt = np.array([d.local_pose.translation for d in devices])
    return compose_rotations(rr, lr), np.einsum("sij,sj->si", rr, lt) + rt


def compose_rotations(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a @ b for stacks of 3x3 matrices, bit for bit what ``np.einsum("sij,sjk->sik", a, b)`` gives
    (it sums the three products in order starting from +0.0; the final + 0.0 does the same to a
    -0.0) in about half its time: einsum is slow on length-3 axes."""
    out = a[:, :, 0:1] * b[:, 0:1, :]
    out += a[:, :, 1:2] * b[:, 1:2, :]
    out += a[:, :, 2:3] * b[:, 2:3, :]
    out += 0.0
    return out


def joined(requests: list, sizes: list[int], field: str, dtype) -> np.ndarray:
    """Every request's ``field`` (one value per ray, or one value for all ``sizes[i]`` rays of
    request ``i``) in one array, in request order: an input of one cast for all of them."""
    return np.concatenate([np.broadcast_to(np.asarray(getattr(r, field), dtype=dtype), (n,))
                           for r, n in zip(requests, sizes)])


def split_hits(hits: RayHits, sizes: list[int]) -> list[RayHits]:
    """The hits of one cast over requests of ``sizes`` rays each (in order), as one RayHits each."""
    out, start = [], 0
    for n in sizes:
        sl = slice(start, start + n)
        out.append(RayHits(hits.distance[sl], None if hits.normal is None else hits.normal[sl],
                           None if hits.shape is None else hits.shape[sl]))
        start += n
    return out


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


def _frames_t(rr_t: np.ndarray, lr_t: np.ndarray, lp_t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Component-major robot ∘ sensor frames: rotations [i, k, s] = sum_j rr[i, j, s] lr[j, k, s] and
    rotated local positions [i, s] = sum_j rr[i, j, s] lp[j, s], summed in the orders numpy's einsum
    uses for ``"sij,sjk->sik"`` ((j0 + j1) + j2, as compose_rotations) and ``"sij,sj->si"`` ((j0 + j2)
    + j1: its two-lane inner loop), each from +0.0, so the bits are einsum's
    (tests/test_distance_math.py pins these orders; numpy may pick others for einsum elsewhere)."""
    rot = rr_t[:, 0, None, :] * lr_t[0]
    rot += rr_t[:, 1, None, :] * lr_t[1]
    rot += rr_t[:, 2, None, :] * lr_t[2]
    rot += 0.0
    pos = rr_t[:, 0] * lp_t[0]
    pos += rr_t[:, 2] * lp_t[2]
    pos += rr_t[:, 1] * lp_t[1]
    pos += 0.0
    return rot, pos


def _rotate_t(rot_t: np.ndarray, d_t: np.ndarray) -> np.ndarray:
    """(S, N, 3) world directions from component-major rotations [i, j, s] and local directions
    [j, n, s]: einsum("sij,snj->sni", rot, dirs) bit for bit ((j0 + j2) + j1 from +0.0, as _frames_t)."""
    out = rot_t[:, 0, None, :] * d_t[0]
    out += rot_t[:, 2, None, :] * d_t[2]
    out += rot_t[:, 1, None, :] * d_t[1]
    out += 0.0
    return np.ascontiguousarray(out.transpose(2, 1, 0))


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
        # each sensor's segments toward every light (S × n), then the pairs': per pair it would be
        # (S × n) × n (4.3 GB for 16,384 occluding sensors and 64 lights)
        unit, length = light_math.occlusion_segments_many(self.positions, self.lights)
        exclude = np.array([d.exclude_self() for d in self.devices], dtype=np.int64)[s]
        return [RayRequest(self.positions[s], unit[s, light], 0.0, length[s, light],
                           RayKind.BOUNDING, exclude, tag="light")]

    def finish(self, hits: list[RayHits], now_ms: int) -> None:
        occluded = np.zeros((len(self.devices), self.lights.count), dtype=bool)
        if self._pairs is not None:
            s, light = self._pairs
            occluded[s, light] = np.isfinite(hits[0].distance)
        e = light_math.irradiance_from_terms(self.att, self.direct, self.lights, occluded, self.filters)
        _output(self.devices, e, now_ms)


class DistancePlan:
    """The constants of a set of distance sensors, stacked once (the same sensors are due step after
    step, so the simulation keeps this while they are): per-group local ray directions, exclusion,
    ranges, weights and types; lookup-table groups; resolutions; each ray's mount body; and each
    ray's hit on its own robot's body, decided once in the body frame (a sensor is rigidly mounted:
    where its rays meet their own body never changes)."""

    def __init__(self, devices: list[DistanceSensor], robot_bodies: list[int | None] | None = None):
        self.all = devices
        self.empty = [d for d in devices if not d.config.lookup_table]     # value 0, no ray matters (§3.1)
        self.devices = devs = [d for d in devices if d.config.lookup_table]
        self.groups: list[_Group] = []
        if not devs:
            return
        self.robot = np.array([d.robot_index for d in devs], dtype=np.int64)
        self.local_rot = np.array([d.local_pose.rotation for d in devs])
        self.local_pos = np.array([d.local_pose.translation for d in devs])
        # where each sensor sits on the body it is mounted on, and its link's rotation (None: no
        # sensor rides a joint, every one is mounted on its robot's body where local_pose puts it)
        self.mount_rot, self.mount_pos, self.link_rot = self.local_rot, self.local_pos, None
        if any(d.link is not None for d in devs):
            self.mount_rot = np.array([d.mount_pose.rotation for d in devs])
            self.mount_pos = np.array([d.mount_pose.translation for d in devs])
            self.link_rot = np.array([np.eye(3) if d.link is None else d.link.rotation for d in devs])
        # the same, component-major ([j, k, sensor], [j, sensor]): long inner axes for the per-step products
        self.local_rot_t = np.ascontiguousarray(self.local_rot.transpose(1, 2, 0))
        self.local_pos_t = np.ascontiguousarray(self.local_pos.T)
        by_shape: dict = defaultdict(list)
        for i, d in enumerate(devs):
            infra_red = d.type_code == _INFRA_RED
            by_shape[(len(d.weights), RayKind.VISUAL if infra_red else RayKind.BOUNDING, d.type_code == _LASER)].append(i)
        for (n, kind, skip), idx in by_shape.items():
            self.groups.append(_Group(np.array(idx, dtype=np.int64), [devs[i] for i in idx], n, kind, skip, robot_bodies))
            self.groups[-1].every = len(idx) == len(devs)
        by_table: dict = defaultdict(list)
        for i, d in enumerate(devs):
            by_table[d.table].append(i)
        self.tables = [(table, np.array(idx, dtype=np.int64)) for table, idx in by_table.items()]
        self.resolution = np.array([float(d.config.resolution) for d in devs])
        self.rounded = self.resolution != RESOLUTION_OFF

    def output(self, measured: np.ndarray, now_ms: int) -> None:
        """Lookup (by table), per-sensor noise from each sensor's own stream, resolution; store."""
        values = np.empty(len(self.devices))
        for table, idx in self.tables:
            y, n = table.interpolate(measured[idx])
            noisy = (n != 0.0).nonzero()[0]
            for k in noisy.tolist():   # noise drawn only when non-zero, from the device's own stream
                y[k] = add_noise(y[k:k + 1], n[k:k + 1], self.devices[int(idx[k])].rng)[0]
            values[idx] = y
        if np.count_nonzero(self.rounded):   # quantize_sensor, element by element the same arithmetic
            res = self.resolution
            q = np.trunc(values / res + 0.5) * res + 0.0
            values = np.where(self.rounded, q, values)
        for d, v in zip(self.devices, values.tolist()):
            d.value = v
            d.measurements += 1
            d.measured_at_ms = now_ms


class _Group:
    """Sensors of one plan with the same ray count, ray kind and transparency rule."""

    def __init__(self, idx: np.ndarray, devs: list[DistanceSensor], n: int, kind: RayKind, skip: bool,
                 robot_bodies: list[int | None] | None):
        self.idx, self.n, self.kind, self.skip = idx, n, kind, skip
        self.local_dirs = np.stack([d.directions_local for d in devs])           # (S, N, 3)
        self.local_dirs_t = np.ascontiguousarray(self.local_dirs.transpose(2, 1, 0))   # [j, ray, sensor]
        self.every = False                   # all the plan's sensors, in order (set by DistancePlan)
        # infra-red sees the robot's own visual shapes (Webots); ODE-style rays skip them
        exclude = np.array([-1 if kind == RayKind.VISUAL else d.exclude_self() for d in devs], dtype=np.int64)
        self.exclude = np.repeat(exclude, n)
        self.lut_max_range = np.array([d.lut_max_range for d in devs])
        self.t_far = np.repeat(self.lut_max_range, n)
        self.types = np.array([d.type_code for d in devs])
        self.weights = np.stack([d.weights for d in devs])
        self.sensitivity = np.array([d.config.red_color_sensitivity for d in devs])
        self.mount: np.ndarray | None = None
        self.mounted: Mount | None = None     # the same, kept by the engine between casts
        self.own_visible: np.ndarray | None = None
        if robot_bodies is not None:
            # each sensor's rays are mounted on the body it rides: its robot's, or its joint's link's
            carriers = [robot_bodies[d.robot_index] if d.link is None else d.link_body for d in devs]
            body = np.array([-1 if b is None else b for b in carriers], dtype=np.int64)
            if np.count_nonzero(body >= 0):
                self.mount = np.repeat(body, n)
                self.mounted = Mount(self.mount)
                robot = np.repeat(np.array([d.robot_index for d in devs], dtype=np.int64), n)
                self.own_visible = (self.mount >= 0) & (self.exclude != robot)
        self.own: tuple | None = None        # (precision, RayHits in body frames), made on first use
        # infra-red rays do not see their device's own shapes (own_shapes.py): per ray, those shapes
        owned = kind == RayKind.VISUAL and any(d.own_shapes for d in devs)
        self.blind: list[frozenset[int]] | None = [d.own_shapes for d in devs for _ in range(n)] if owned else None
        # the request's limit and exclusion: one scalar when uniform (what the engine would make of them)
        self.far_arg = float(self.t_far[0]) if not np.count_nonzero(self.t_far != self.t_far[0]) else self.t_far
        self.exclude_arg = int(self.exclude[0]) if not np.count_nonzero(self.exclude != self.exclude[0]) else self.exclude

    def own_hits(self, engine, local_rot: np.ndarray, local_pos: np.ndarray) -> RayHits | None:
        """Each ray's hit on its own robot's body (body frame), cast once per engine precision."""
        if self.own_visible is None or not np.count_nonzero(self.own_visible):
            return None
        if self.own is None or self.own[0] != (engine.precision, engine.seen_version):
            S, n = len(self.idx), self.n
            O = np.repeat(local_pos[self.idx], n, axis=0)
            D = np.einsum("sij,snj->sni", local_rot[self.idx], self.local_dirs).reshape(-1, 3)
            t = np.full(S * n, np.inf)
            shape = np.full(S * n, -1, dtype=np.int64)
            normal = np.zeros((S * n, 3))
            for body in unique_ints(self.mount[self.own_visible]).tolist():
                rows = (self.own_visible & (self.mount == body)).nonzero()[0]
                if self.blind is not None:
                    h = cast_local_skipping(engine, body, O[rows], D[rows], 0.0, self.t_far[rows], self.kind,
                                            self.skip, [self.blind[r] for r in rows.tolist()])
                else:
                    h = engine.cast_local(body, O[rows], D[rows], 0.0, self.t_far[rows], kind=self.kind,
                                          skip_transparent=self.skip)
                t[rows], shape[rows], normal[rows] = h.distance, h.shape, h.normal
            self.own = ((engine.precision, engine.seen_version), RayHits(t, normal, shape))
        return self.own[1]


class DistanceBatch:
    """All distance sensors due this step; sensors with the same ray count share array shapes.
    ``plan``: the constants of these sensors when already stacked (see :class:`DistancePlan`);
    ``engine``: the ray engine, to decide the rays' hits on their own bodies once; ``scene``: the
    scene, whose textures infra-red rays read (nothing is sampled in a world without textures)."""

    def __init__(self, devices: list[DistanceSensor], robot_poses: list[Pose], scene_red: np.ndarray,
                 scene_roughness: np.ndarray, plan: DistancePlan | None = None, engine=None, scene=None):
        self.red, self.roughness = scene_red, scene_roughness
        # the scene, when it has textures: infra-red hits on textured shapes read their texels
        self.textured = scene.textures.textured if scene is not None and scene.textures is not None else None
        self.scene = scene
        self.plan_data = plan = plan if plan is not None else DistancePlan(devices)
        self.engine = engine if plan.groups and plan.groups[0].mount is not None else None
        self.empty, self.devices = plan.empty, plan.devices
        self.dirs: list[np.ndarray] = []
        if not self.devices:
            return
        # robot pose ∘ device pose, bit for bit what world_frames and einsum("sij,snj->sni", rot, dirs)
        # give, computed component-major (einsum is slow on length-3 axes): see _frames_t
        self.robot_rot = robot_rot = np.array([p.rotation for p in robot_poses])
        robot_pos = np.array([p.translation for p in robot_poses])
        rr_t = np.take(robot_rot.transpose(1, 2, 0), plan.robot, axis=2)      # [i, j, sensor]
        rot_t, pos_t = _frames_t(rr_t, plan.local_rot_t, plan.local_pos_t)
        self.positions = pos_t.T + robot_pos[plan.robot]
        for g in plan.groups:
            self.dirs.append(_rotate_t(rot_t if g.every else rot_t[:, :, g.idx], g.local_dirs_t))

    def plan(self) -> list[RayRequest]:
        requests = []
        for g, dirs in zip(self.plan_data.groups, self.dirs):
            requests.append(RayRequest(
                np.repeat(self.positions[g.idx], g.n, axis=0), dirs.reshape(-1, 3), 0.0, g.far_arg, g.kind,
                g.exclude_arg, skip_transparent=g.skip, tag="distance",
                mount=g.mounted if self.engine is not None else None))
        return requests

    def finish(self, hits: list[RayHits], now_ms: int) -> None:
        for d in self.empty:
            d.value = 0.0
            d._mark(now_ms)
        if not self.devices:
            return
        plan = self.plan_data
        measured = np.empty(len(self.devices))
        for g, dirs, h in zip(plan.groups, self.dirs, hits):
            S, n = dirs.shape[:2]
            dist, shape, normal = h.distance, h.shape, h.normal
            own = g.own_hits(self.engine, plan.mount_rot, plan.mount_pos) if self.engine is not None else None
            if own is not None:   # the nearer of the cast and the ray's own-body hit
                win = (own.distance < dist).nonzero()[0]
                if len(win):
                    dist, shape, normal = dist.copy(), shape.copy(), normal.copy()
                    dist[win], shape[win] = own.distance[win], own.shape[win]
                    rr = plan.robot[np.repeat(g.idx, n)[win]]
                    carrier = self.robot_rot[rr]
                    if plan.link_rot is not None:    # sensors on a joint: their link's rotation too
                        carrier = carrier @ plan.link_rot[np.repeat(g.idx, n)[win]]
                    normal[win] = np.einsum("sij,sj->si", carrier, own.normal[win])
            dist = dist.reshape(S, n)
            reflection = None
            if g.kind == RayKind.VISUAL:
                # colour lookups only for infra-red; shape -1 picks the trailing "no hit" entry
                sh = shape.reshape(S, n)
                if self.textured is not None and np.count_nonzero(self.textured[shape]):
                    red, rough, occl = self.scene.infra_red_terms(
                        shape, np.repeat(self.positions[g.idx], n, axis=0), dirs.reshape(-1, 3), dist.reshape(-1))
                    shade = dmath.reflection_factor(red, rough, occl).reshape(S, n)
                else:
                    shade = dmath.reflection_factor(self.red[sh], self.roughness[sh])
                reflection = np.where(sh >= 0, shade, 1.0)
            measured[g.idx] = dmath.combine_distance_batch(
                g.types, dist, dirs, normal.reshape(S, n, 3), g.weights, g.lut_max_range, reflection, g.sensitivity)
        plan.output(measured, now_ms)
