"""Device instances: what a controller enables and reads, and how each turns rays into values.

Rays are *planned* at the end-of-step pose, the simulation casts every device's rays of a step in
as few batched calls as possible, and the hits are *reduced* to values: per lidar here, and for
all light and distance sensors of a step together in ``batches.py``. Devices never read the clock:
the simulation passes times in and decides who is due (``Schedule``).
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from sensorium.schemas import world as wm
from sensorium.schemas.devices import kind
from sensorium.server.devices import distance as dmath
from sensorium.server.devices import gps as gps_math
from sensorium.server.devices import lidar as lmath
from sensorium.server.devices import motion_sensors as motion_math
from sensorium.server.devices import orientation as orient
from sensorium.server.devices.lookup import RESOLUTION_OFF, LookupTable, quantize_sensor
from sensorium.server.devices.noise import device_rng
from sensorium.server.raycast import blocks, packets
from sensorium.server.raycast.engine import Mount, RayHits, RayKind
from sensorium.server.sim.own_shapes import cast_local_skipping, cast_past
from sensorium.server.sim.scene import primitive_from_model
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import matrix_quaternion, pose_from_model


@dataclass(slots=True)
class RayRequest:
    """Rays of one device for one measurement, in world coordinates (float64)."""

    origins: np.ndarray
    directions: np.ndarray
    t_near: np.ndarray | float
    t_far: np.ndarray | float
    kind: RayKind
    exclude_owner: int | np.ndarray   # per request or per ray
    skip_transparent: bool = False
    tag: str = ""              # counter bucket: "light", "distance", "lidar"
    mount: np.ndarray | Mount | None = None   # per ray: body the ray is rigidly mounted on, -1 none (see RayEngine.cast)
    distance_only: bool = False       # the device reads only distances (see RayEngine.cast)
    directions32: np.ndarray | None = None   # the directions rounded to float32, when kept (see RayEngine.cast)

    def __len__(self) -> int:
        return len(self.origins)


@dataclass(slots=True)
class Schedule:
    """Webots' sensor timing (devices.md §1.1): measure when (t - last_update) >= period."""

    period_ms: int = 0          # requested sampling period; 0 = disabled
    last_update_ms: int = 0

    def enable(self, period_ms: int, now_ms: int) -> None:
        self.period_ms = period_ms
        self.last_update_ms = now_ms

    def due(self, now_ms: int) -> bool:
        return self.period_ms > 0 and now_ms - self.last_update_ms >= self.period_ms


def _check_period(period_ms: object) -> int:
    if isinstance(period_ms, bool) or not isinstance(period_ms, (int, np.integer)):
        raise ValueError(f"sampling period must be an integer number of milliseconds, got {period_ms!r}")
    if period_ms < 0:
        raise ValueError(f"sampling period must be >= 0 ms, got {period_ms}")
    return int(period_ms)


@dataclass(eq=False)
class Device:
    """Common state: name, owner robot, local pose, schedule, random stream (created on first use)."""

    config: Any          # the kind's world-file model (schemas/world.py)
    robot_index: int
    robot_name: str
    self_collision: bool
    world_seed: int
    clock: Callable[[], int]        # the simulation's current time (ms); enable() starts counting from it
    schedule: Schedule = field(default_factory=Schedule)
    measurements: int = 0           # how many values were produced (publishers watch it)
    measured_at_ms: int = -1        # simulated time of the latest value
    _rng: np.random.Generator | None = None
    own_shapes: frozenset[int] = frozenset()   # its own Solid's shapes: its visual rays do not see them (own_shapes.py)
    # shapes a Supervisor hid from it (setVisibility), by the node hidden: its visual rays pass through them
    hidden: dict[int, frozenset[int]] = field(default_factory=dict)

    tracks_motion: ClassVar[bool] = False
    """The step calls ``track()`` after every basic step while the device is enabled."""
    kinematic: ClassVar[bool] = False
    """A device measured without rays from the kinematic world: the step calls ``measure(now_ms)``
    when it is due (after ``bind`` handed it what it reads)."""

    def __post_init__(self) -> None:
        self.local_pose: Pose = pose_from_model(self.config.pose)
        # on a joint (``on_joint``): its pose in its link's body frame (the robot frame with every joint
        # at its initial position), the link's displacement now, and the link's engine body (None
        # without shapes); local_pose is then displacement ∘ mount_pose, updated as the joint moves
        self.mount_pose: Pose = self.local_pose
        self.link: Pose | None = None
        self.link_body: int | None = None

    @property
    def on_joint(self) -> str | None:
        return getattr(self.config, "on_joint", None)

    def move_with(self, displacement: Pose) -> None:
        """Its joint's link moved: it is ``displacement`` (robot frame) from where the file placed it."""
        self.link = displacement
        self.local_pose = displacement.compose(self.mount_pose)

    def carrier_rotation(self, robot_pose: Pose) -> np.ndarray:
        """The world rotation of the body it is rigidly mounted on (its robot's, or its link's)."""
        return robot_pose.rotation if self.link is None else robot_pose.rotation @ self.link.rotation

    @property
    def name(self) -> str:
        return self.config.name

    @property
    def path(self) -> str:
        return f"{self.robot_name}/{self.config.name}"

    @property
    def kind(self) -> str:
        return self.config.device

    @property
    def rng(self) -> np.random.Generator:
        # lazily: a device whose noise is zero never creates (nor advances) a stream
        if self._rng is None:
            self._rng = device_rng(self.world_seed, self.path)
        return self._rng

    def enable(self, period_ms: int) -> None:
        """Webots' ``enable``: 0 disables; the first value comes one sampling period later and
        values then refresh every ceil(period / basic step) basic steps (devices.md §1.1)."""
        self.schedule.enable(_check_period(period_ms), self.clock())

    def disable(self) -> None:
        self.schedule.enable(0, self.clock())

    @property
    def sampling_period(self) -> int:
        return self.schedule.period_ms

    @property
    def enabled(self) -> bool:
        return self.schedule.period_ms > 0

    def world_pose(self, robot_pose: Pose) -> Pose:
        return robot_pose.compose(self.local_pose)

    def exclude_self(self) -> int:
        return -1 if self.self_collision else self.robot_index

    def _mark(self, now_ms: int) -> None:
        self.measurements += 1
        self.measured_at_ms = now_ms

    def step_reading(self) -> dict:
        """What a step reply carries for the device (PROTOCOL §3.6)."""
        return {"value": float(self.value)}  # type: ignore[attr-defined]

    @property
    def hidden_shapes(self) -> frozenset[int]:
        """The shapes of every node hidden from it (empty for a device no Supervisor hid anything from)."""
        return frozenset().union(*self.hidden.values()) if self.hidden else frozenset()

    def bind(self, robot: Any) -> None:
        """Called once with the device's ``RobotState`` (motors, drive, pose) when the robot is made."""

    def describe(self) -> dict:
        """The kind's own fields of its ``attach`` description (schemas/services.py ``*Description``)."""
        return {}

    def flat_lookup_table(self) -> list[float]:
        """Webots' ``get_lookup_table``: the rows flattened (x0, y0, n0, x1, ...)."""
        table = getattr(self, "table", None)
        flat = getattr(table, "flattened", None)
        if flat is None:
            flat = [v for row in self.config.lookup_table for v in row]
        return [float(v) for v in flat]


class LightSensor(Device):
    def __post_init__(self) -> None:
        super().__post_init__()
        self.table = LookupTable(self.config.lookup_table)
        self.value = math.nan

    def readings(self) -> dict:
        return {"value": self.value}

    def describe(self) -> dict:
        return {"lookup_table": self.flat_lookup_table()}


class DistanceSensor(Device):
    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.table = LookupTable(c.lookup_table)
        self.type_code = dmath.SENSOR_TYPES[c.type]
        self.directions_local = dmath.ray_directions(c.number_of_rays, c.aperture)
        self.weights = dmath.ray_weights(c.number_of_rays, c.aperture, c.gaussian_width)
        self.lut_max_range = float(c.lookup_table[-1][0]) if c.lookup_table else math.inf
        self.value = math.nan

    def readings(self) -> dict:
        return {"value": self.value}

    def describe(self) -> dict:
        return {"lookup_table": self.flat_lookup_table(), "min_value": float(self.table.min_value),
                "max_value": float(self.table.max_value), "aperture": float(self.config.aperture),
                "sensor_type": int(self.type_code)}


class Lidar(Device):
    """A Webots Lidar. Per-device constants are made once: the beams in the lidar frame (as three
    contiguous columns; ``_all_dirs`` is an (L, W, 3) view of them), the point-cloud directions, the
    far limits. A fixed lidar also keeps its beams in world coordinates for the rotation they were
    planned at: a lidar that does not turn between scans (it may move) plans no rays. The point
    cloud of a fixed lidar is kept as coordinates; its WbLidarPoint records are made when read."""

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.params = lmath.LidarParams(
            horizontal_resolution=c.horizontal_resolution, number_of_layers=c.number_of_layers,
            field_of_view=c.field_of_view, vertical_field_of_view=c.vertical_field_of_view,
            tilt_angle=c.tilt_angle, near=c.near, min_range=c.min_range, max_range=c.max_range,
            type=c.type, projection=c.projection, noise=c.noise, resolution=c.resolution,
            default_frequency=c.default_frequency, min_frequency=c.min_frequency, max_frequency=c.max_frequency,
        )
        self.rotating = c.type == "rotating"
        self.frequency = float(c.default_frequency)
        self.head_angle = 0.0
        self.point_cloud_enabled = False
        L, W = c.number_of_layers, c.horizontal_resolution
        # before the first measurement the image and cloud are all zeros (Webots)
        self.range_image = np.zeros((L, W), dtype=np.float32)
        self._records: np.ndarray | None = np.zeros(L * W, dtype=lmath.POINT_DTYPE)
        self._xyz: np.ndarray | None = None           # (L·W, 3) float32 of the latest fixed scan
        self._cloud_time = (0.0, 0.0)                 # (time_s, period_s) of that scan
        self._layers_f4: np.ndarray | None = None     # layer of every point as float32 (messages)
        # the beams (L, W, 3) in the lidar frame, stored as three contiguous columns (planning and
        # the point cloud read columns); _all_dirs is a view in (L, W, 3) order
        cols = np.ascontiguousarray(np.moveaxis(lmath.ray_directions(self.params), -1, 0))   # (3, L, W)
        self._all_dirs = np.moveaxis(cols, 0, -1)
        self._dir_columns = tuple(cols[k].reshape(-1) for k in range(3))
        self._cloud_columns: tuple[np.ndarray, ...] | None = None   # point-cloud directions, made on first use
        # planar lidars store depth: a ray must reach max_range in depth, not in length
        factor = lmath.value_factors(self.params, self._all_dirs)
        # a planar lidar's depth factors (ranges_from_hits' product, made once), None for a cylindrical one
        self._factor = np.ascontiguousarray(factor, dtype=np.float64).reshape(-1) if self.params.planar else None
        with np.errstate(divide="ignore"):
            t_far = np.where(factor > 0, self.params.max_range / np.where(factor > 0, factor, 1.0), 0.0)
        # one value for every beam (cylindrical): the engine then needs no per-ray limits
        self._t_far: np.ndarray | float = float(t_far.flat[0]) if not np.count_nonzero(t_far != t_far.flat[0]) else t_far
        self._sweep: lmath.RotatingSweep | None = None
        # (rotation bytes, world beams float64, the same as float32) of a fixed lidar's latest plan
        self._planned: tuple[bytes, np.ndarray, np.ndarray] | None = None
        # a lidar with shapes of its own (a housing): its beams are mounted on the robot's body and
        # meet that body once, in its frame, blind to the lidar's own shapes (own_shapes.py)
        self._own_body: tuple[Any, int, Mount] | None = None     # (scene, body, mount of every beam)
        self._own_hits: tuple[Any, np.ndarray] | None = None       # (precision, (L, W) distances)
        # a fixed lidar on a robot with a body (and no shapes of its own): its beams are rigidly
        # mounted on that body, which they also see (Mount(own=True): which beams can reach it is
        # decided once)
        self._mount: tuple[int, Mount] | None = None
        self._scene: Any = None
        # this step's beams while a Supervisor hides shapes from it: (origins, directions, far), cast again past them
        self._past: tuple[np.ndarray, np.ndarray, Any] | None = None

    def bind(self, robot: Any) -> None:
        self._scene = robot.scene       # (its engine, for beams past the shapes a Supervisor hid from it)
        if self.own_shapes:
            scene = robot.scene
            body = scene.device_body(self.robot_index, self.on_joint)
            if body is not None:
                n = self.config.number_of_layers * self.config.horizontal_resolution
                self._own_body = (scene, body, Mount(np.full(n, body, dtype=np.int64)))

    def _own_distances(self) -> np.ndarray:
        """Each beam's distance to its robot's body other than the lidar's own shapes (L, W)."""
        assert self._own_body is not None
        scene, body, _ = self._own_body
        engine = scene.engine
        if self._own_hits is None or self._own_hits[0] != (engine.precision, engine.seen_version):
            L, W = self.config.number_of_layers, self.config.horizontal_resolution
            D = self._all_dirs.reshape(-1, 3) @ self.mount_pose.rotation.T
            O = np.broadcast_to(self.mount_pose.translation, D.shape)
            far = self._t_far.reshape(-1) if isinstance(self._t_far, np.ndarray) else self._t_far
            h = cast_local_skipping(engine, body, np.ascontiguousarray(O), D, self.params.near, far, RayKind.VISUAL,
                                    False, [self.own_shapes] * (L * W))
            self._own_hits = ((engine.precision, engine.seen_version), h.distance.reshape(L, W))
        return self._own_hits[1]

    # -- controller API
    def info(self) -> dict:
        """Webots' lidar constants (``get_info``)."""
        cfg = self.config
        return {"horizontalResolution": int(cfg.horizontal_resolution), "numberOfLayers": int(cfg.number_of_layers),
                "fov": float(cfg.field_of_view), "verticalFov": float(cfg.vertical_field_of_view),
                "minRange": float(cfg.min_range), "maxRange": float(cfg.max_range)}

    def frequency_info(self) -> dict:
        cfg = self.config
        return {"frequency": float(self.frequency), "minFrequency": float(cfg.min_frequency),
                "maxFrequency": float(cfg.max_frequency)}

    def describe(self) -> dict:
        return {**self.info(), **self.frequency_info(), "point_cloud_enabled": self.point_cloud_enabled}

    def set_frequency(self, f: float) -> None:
        c = self.config
        if not (isinstance(f, (int, float)) and math.isfinite(f) and c.min_frequency <= f <= c.max_frequency):
            raise ValueError(f"frequency {f!r} outside [{c.min_frequency}, {c.max_frequency}] Hz")
        self.frequency = float(f)

    def enable_point_cloud(self) -> None:
        self.point_cloud_enabled = True

    def disable_point_cloud(self) -> None:
        self.point_cloud_enabled = False

    @property
    def point_cloud(self) -> np.ndarray:
        """WbLidarPoint records (L·W,) of the latest measurement (zeros before the first)."""
        if self._records is None:   # a fixed scan's coordinates: records on first read
            L, W = self.config.number_of_layers, self.config.horizontal_resolution
            time_s, period_s = self._cloud_time
            t = time_s - np.arange(W) * (period_s / W)
            self._records = lmath.point_records(self._xyz, L, W, t)
        return self._records

    def cloud_points(self) -> np.ndarray:
        """Point coordinates (L·W, 3) float32 of the latest measurement: a fixed lidar's scan gives a
        fresh array that is never written afterwards (messages may keep it); otherwise (a rotating
        head, or before the first scan) a view of the records, which later steps overwrite."""
        if self._records is None:
            return self._xyz
        return self._records.view(np.float32).reshape(-1, 5)[:, 0:3]

    def cloud_layers(self) -> np.ndarray:
        """The layer of every point as float32: for a fixed scan a constant of the device (made on
        first use); else the records' (zeros where a rotating head has not swept yet)."""
        if self._records is not None:
            return self._records["layer_id"].astype(np.float32)
        if self._layers_f4 is None:
            L, W = self.config.number_of_layers, self.config.horizontal_resolution
            self._layers_f4 = np.repeat(np.arange(L, dtype=np.float32), W)
            self._layers_f4.flags.writeable = False
        return self._layers_f4

    def layer_range_image(self, layer: int) -> np.ndarray:
        if not 0 <= layer < self.config.number_of_layers:
            raise ValueError(f"layer {layer} outside [0, {self.config.number_of_layers - 1}]")
        return self.range_image[layer].copy()

    def layer_point_cloud(self, layer: int) -> np.ndarray:
        if not 0 <= layer < self.config.number_of_layers:
            raise ValueError(f"layer {layer} outside [0, {self.config.number_of_layers - 1}]")
        W = self.config.horizontal_resolution
        return self.point_cloud[layer * W:(layer + 1) * W].copy()

    # -- measurement
    def due(self, now_ms: int) -> bool:
        # a rotating head turns (and sweeps its sector) every basic step while enabled
        return self.enabled if self.rotating else self.schedule.due(now_ms)

    def plan(self, robot_pose: Pose, now_ms: int, dt_ms: int, body: int | None = None) -> list[RayRequest]:
        """The rays of this step's measurement; ``body``: the engine body of the robot carrying the
        lidar (None: it has none), which a fixed lidar's rays are mounted on."""
        pose = self.world_pose(robot_pose)
        self._past = None
        if self.hidden:
            return self._plan_past_hidden(pose, now_ms, dt_ms)
        if self.rotating:
            swept = self._swept(pose, now_ms, dt_ms)
            if swept is None:
                return []
            dirs, t_far = swept
            if self._own_body is not None:
                return [RayRequest(np.broadcast_to(pose.translation, dirs.shape), dirs, self.params.near, t_far,
                                   RayKind.VISUAL, -1, tag="lidar", distance_only=True,
                                   mount=np.full(len(dirs), self._own_body[1], dtype=np.int64))]
        else:
            t_far = self._t_far if not isinstance(self._t_far, np.ndarray) else self._t_far.reshape(-1)
            key = pose.rotation.tobytes()
            if self._planned is None or self._planned[0] != key:   # the lidar turned: rotate the beams
                d32 = np.empty((len(self._dir_columns[0]), 3), dtype=np.float32)
                dirs = _rotate_columns(pose.rotation, self._dir_columns, out32=d32)
                dirs.flags.writeable = d32.flags.writeable = False   # handed to every cast until it turns
                self._planned = (key, dirs, d32)
            _, dirs, d32 = self._planned
            origins = np.broadcast_to(pose.translation, dirs.shape)
            mount = None
            if self._own_body is not None:        # blind to its own shapes: the body met apart (finish)
                mount = self._own_body[2]
            elif body is not None:
                if self._mount is None or self._mount[0] != body:
                    self._mount = (body, Mount(np.full(len(dirs), body, dtype=np.int64), own=True))
                mount = self._mount[1]
            return [RayRequest(origins, dirs, self.params.near, t_far, RayKind.VISUAL, -1, tag="lidar",
                               mount=mount, distance_only=True, directions32=d32)]
        origins = np.broadcast_to(pose.translation, dirs.shape)
        return [RayRequest(origins, dirs, self.params.near, t_far, RayKind.VISUAL, -1, tag="lidar",
                           distance_only=True)]

    def _swept(self, pose: Pose, now_ms: int, dt_ms: int) -> tuple[np.ndarray, Any] | None:
        """A rotating head's beams this step: only the sector it sweeps (devices.md §4.9), their world
        directions and far limits; None when it sweeps no column."""
        self._sweep = lmath.rotating_sweep(self.params, self.head_angle, self.frequency, dt_ms, now_ms / 1000.0)
        cols = self._sweep.columns
        if cols.size == 0:
            return None
        t_far = self._t_far if not isinstance(self._t_far, np.ndarray) else self._t_far[:, cols].reshape(-1)
        return _rotate(pose.rotation, self._all_dirs[:, cols, :].reshape(-1, 3)), t_far

    def _plan_past_hidden(self, pose: Pose, now_ms: int, dt_ms: int) -> list[RayRequest]:
        """The beams as one plain world cast (its robot's body in it, nothing mounted), their shapes kept:
        ``finish`` casts again, from just past it, each beam whose hit is a hidden or own shape."""
        if self.rotating:
            swept = self._swept(pose, now_ms, dt_ms)
            if swept is None:
                return []
            dirs, t_far = swept
        else:
            dirs = _rotate(pose.rotation, self._all_dirs.reshape(-1, 3))
            t_far = self._t_far if not isinstance(self._t_far, np.ndarray) else self._t_far.reshape(-1)
        origins = np.broadcast_to(pose.translation, dirs.shape)
        self._past = (origins, dirs, t_far)
        return [RayRequest(origins, dirs, self.params.near, t_far, RayKind.VISUAL, -1, tag="lidar")]

    def finish(self, hits: list[RayHits], now_ms: int, counters: dict[str, int], threads: int = 1) -> None:
        """Range image and point cloud from this step's hits; ``threads``: the point coordinates of a
        large scan are made in blocks on that many threads (the same values)."""
        L = self.config.number_of_layers
        if self._past is not None:      # a Supervisor hid shapes from it: past them (and its own shapes)
            origins, dirs, t_far = self._past
            hits = [cast_past(self._scene.engine, origins, dirs, self.params.near, t_far, hits[0],
                              self.own_shapes | self.hidden_shapes)]
        own_body = None if self._past is not None else self._own_body
        if self.rotating:
            sweep = self._sweep
            self.head_angle = sweep.head_angle_after
            cols = sweep.columns
            if cols.size == 0:
                return
            dist = hits[0].distance.reshape(L, cols.size)
            if own_body is not None:
                dist = np.minimum(dist, self._own_distances()[:, cols])
            ranges = lmath.ranges_from_hits(self.params, dist, self._all_dirs[:, cols, :], self._noise_rng())
            self.range_image[:, cols] = ranges
            if self.point_cloud_enabled:
                # point times follow the sweep: when the head passed each column
                W = self.config.horizontal_resolution
                xyz = lmath.point_xyz(ranges, tuple(c.reshape(L, W)[:, cols] for c in self._point_columns()))
                pts = lmath.point_records(xyz, L, cols.size, sweep.times)
                index = (np.arange(L)[:, None] * W + cols[None, :]).reshape(-1)
                self.point_cloud[index] = pts
                counters["points_built"] += pts.size
        else:
            W = self.config.horizontal_resolution
            dist = hits[0].distance.reshape(L, W)
            if own_body is not None:
                dist = np.minimum(dist, self._own_distances())
            xyz = np.empty((L * W, 3), dtype=np.float32) if self.point_cloud_enabled else None
            ranges = np.empty((L, W), dtype=np.float32)
            # nothing moves a value (no noise, no resolution): range image and points in one C pass
            # where the packet helper is built (the same bits as the two numpy steps below)
            if self.params.noise > 0.0 or self.params.resolution != RESOLUTION_OFF or not packets.lidar_scan(
                    np.ascontiguousarray(dist, dtype=np.float64).reshape(-1), self.params.min_range,
                    self.params.max_range, ranges.reshape(-1), self._point_columns(), xyz, self._factor, threads):
                ranges = lmath.ranges_from_hits(self.params, dist, self._all_dirs, self._noise_rng())
                if xyz is not None:
                    xyz = _point_xyz(ranges, self._point_columns(), threads)
            self.range_image = ranges
            if xyz is not None:
                self._xyz = xyz
                self._xyz.flags.writeable = False   # messages may hold it
                self._cloud_time = (now_ms / 1000.0, self.schedule.period_ms / 1000.0)
                self._records = None
                counters["points_built"] += len(self._xyz)
        self._mark(now_ms)

    def _point_columns(self) -> tuple[np.ndarray, ...]:
        """Point-cloud directions (lmath.point_cloud_directions) as three columns, made once: the
        beams themselves unless the projection is planar."""
        if self._cloud_columns is None:
            if self.params.planar:
                d = lmath.point_cloud_directions(self.params)
                self._cloud_columns = tuple(np.ascontiguousarray(d[:, :, k]).reshape(-1) for k in range(3))
            else:
                self._cloud_columns = self._dir_columns
        return self._cloud_columns

    def _noise_rng(self) -> np.random.Generator | None:
        return self.rng if self.params.noise > 0 else None

    def readings(self) -> dict:
        out: dict = {"range_image": self.range_image}
        if self.point_cloud_enabled:
            out["point_cloud"] = self.point_cloud
        return out


_ROTATE_BLOCK = 16384   # rows per block of _rotate_columns (its float64 temporaries: ~640 KB)


def _point_xyz(ranges: np.ndarray, columns: tuple[np.ndarray, ...], threads: int) -> np.ndarray:
    """lmath.point_xyz, in blocks on ``threads`` threads for a large scan (each point's value is
    its own product: the same array)."""
    r = ranges.reshape(-1)
    parts = blocks.split(len(r), threads, 1 << 16)
    if len(parts) == 1:
        return lmath.point_xyz(r, columns)
    out = np.empty((len(r), 3), dtype=np.float32)

    def block(sl: slice) -> None:
        out[sl] = lmath.point_xyz(r[sl], tuple(c[sl] for c in columns))

    blocks.run(block, parts, threads)
    return out


def _rotate(rotation: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``vectors @ rotation.T`` by columns: a BLAS matmul here lets OpenBLAS threads stall for tens
    of milliseconds when the other core is busy (measured), for no gain on (N, 3) arrays."""
    out = vectors[:, 0:1] * rotation[:, 0]
    out += vectors[:, 1:2] * rotation[:, 1]
    out += vectors[:, 2:3] * rotation[:, 2]
    return out


def _rotate_columns(rotation: np.ndarray, columns: tuple[np.ndarray, np.ndarray, np.ndarray],
                    out32: np.ndarray | None = None) -> np.ndarray:
    """``_rotate`` for vectors given as three contiguous columns (x, y, z): the same products and
    sums in the same order (bit-identical), on contiguous arrays instead of (N, 3) broadcasts, in
    blocks of rows whose temporaries stay in cache. ``out32``: an (N, 3) float32 array that also
    receives the result rounded to float32 (what ``astype`` would give), from the same blocks."""
    x, y, z = columns
    n = len(x)
    out = np.empty((n, 3))
    block = max(1, min(n, _ROTATE_BLOCK))
    buf = np.empty((block, 3))
    tmp = np.empty(block)
    acc = np.empty(block)
    for a in range(0, n, block):
        b = min(n, a + block)
        m = b - a
        t, c, part = tmp[:m], acc[:m], buf[:m]
        for k in range(3):
            np.multiply(x[a:b], rotation[k, 0], out=c)
            np.multiply(y[a:b], rotation[k, 1], out=t)
            c += t
            np.multiply(z[a:b], rotation[k, 2], out=t)
            c += t
            part[:, k] = c
        out[a:b] = part
        if out32 is not None:
            out32[a:b] = part
    return out



class PositionSensor(Device):
    """A joint's encoder: the position (rad, or m on a slider) of the joint turned by ``config.motor``
    (a drive's wheel or a car's steering, or a joint moved kinematically, sim/joints.py).

    Webots' timing (the first value one sampling period after ``enable``, NaN before), then
    Gaussian ``noise`` and ``resolution`` as Webots applies them. The simulation binds :attr:`wheel`
    to the robot's motor (:class:`~sensorium.server.sim.motion.WheelMotor` or
    :class:`~sensorium.server.sim.joints.JointMotor`).
    """

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.value = math.nan
        self.wheel: object | None = None          # the WheelMotor whose ``position`` is read
        self.car: Any = None                      # a free wheel's car (AckermannDrive), whose free_turned is read

    def bind(self, robot: Any) -> None:
        self.wheel = robot.motors.get(self.config.motor) if self.config.motor is not None else None
        self.car = robot.drive if getattr(self.config, "free_wheel", None) is not None else None

    def measure(self, now_ms: int) -> None:
        if self.car is not None:      # a car's free wheel: its world-file angle plus what it has rolled
            v = float(self.config.position) + self.config.free_wheel_sign * self.car.free_turned[self.config.free_wheel]
        else:
            v = float(self.wheel.position) if self.wheel is not None else float(self.config.position)  # type: ignore[attr-defined]
        noise = float(self.config.noise)
        if noise > 0.0:
            v += float(self.rng.normal(0.0, noise))
        res = float(self.config.resolution)
        if res > 0.0:                 # Webots' discretize: (int)(v/res + 0.5)·res, as other sensors
            v = float(quantize_sensor(v, res))
        self.value = v
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"value": self.value}

    def describe(self) -> dict:
        c = self.config
        return {"motor": c.motor, "noise": float(c.noise), "resolution": float(c.resolution)}


def led_value_bound(gradual: bool, colours: int) -> int:
    """The largest value an LED takes (Webots' LED page): a colour index up to ``colours``; a
    gradual LED 0xFFFFFF (RGB: no colour listed) or 255 (monochrome: an intensity of its colour)."""
    return (0xFFFFFF if colours == 0 else 255) if gradual else colours


class LED(Device):
    """Webots LED: ``value`` 0 (off) or a colour index 1..n; a gradual LED holds 0xRRGGBB when its
    ``color`` list is empty, else an intensity 0..255 of its first colour (WbLed's monochrome LED). Its
    ``lights`` (if any) are on exactly while the value is not 0, in its colour (``light_color``), and
    light sensors and cameras see them then. Each ``set`` counts as a new measurement (its topic
    publishes it). Its robot's battery emptying turns it off (``dark``, WbLed::powerOn(false) setting
    Webots' own value to 0) while ``value``, what ``get`` reads, keeps the controller's last set, as
    libController's; it stays off when power returns, until the next ``set``."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.value = 0
        self.dark = False
        self._switch: Callable[[bool, tuple[float, float, float]], None] | None = None

    def bind(self, robot: Any) -> None:
        if self.config.lights:
            scene, index, name = robot.scene, self.robot_index, self.name
            self._switch = lambda on, color: scene.set_led_lights(index, name, on, color)

    def set(self, value: int, now_ms: int) -> None:
        c = self.config
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"LED value must be an integer, got {value!r}")
        hi = led_value_bound(c.gradual, len(c.color))
        if not 0 <= value <= hi:
            what = ("a 0xRRGGBB colour" if not c.color else "an intensity 0..255") if c.gradual else \
                f"0 (off) or a colour index 1..{len(c.color)}"
            raise ValueError(f"LED {self.name!r}: value {value} is not {what}")
        self.value = int(value)
        self.dark = False
        self._mark(now_ms)
        if self._switch is not None:
            self._switch(self.value != 0, self.light_color())

    def power_off(self) -> None:
        """Its robot's battery emptied: off, lights too (``get`` still reads ``value``)."""
        self.dark = True
        if self._switch is not None:
            self._switch(False, (0.0, 0.0, 0.0))

    def light_color(self) -> tuple[float, float, float]:
        """The colour its lights take: ``rgb`` as ``WbLed::setMaterialsAndLightsColor`` computes it, in
        single precision (its ``float r, g, b``: an RGB LED's byte / 255.0f; a monochrome one's
        intensity value / 255.0f times its colour; a colour of the list rounded to float)."""
        v, c = (0 if self.dark else self.value), self.config
        if v != 0 and c.gradual:
            if not c.color:
                return tuple(float(np.float32((v >> s) & 255) / np.float32(255.0))   # type: ignore[return-value]
                             for s in (16, 8, 0))
            i = np.float32(v) / np.float32(255.0)
            return tuple(float(np.float32(float(i) * x)) for x in c.color[0])  # type: ignore[return-value]
        return tuple(float(np.float32(x)) for x in self.rgb())  # type: ignore[return-value]

    def rgb(self) -> tuple[float, float, float]:
        """The colour shown (0, 0, 0 when off)."""
        v, c = (0 if self.dark else self.value), self.config
        if v == 0:
            return (0.0, 0.0, 0.0)
        if c.gradual and not c.color:
            return (((v >> 16) & 255) / 255.0, ((v >> 8) & 255) / 255.0, (v & 255) / 255.0)
        if c.gradual:
            return tuple(v / 255.0 * float(x) for x in c.color[0])  # type: ignore[return-value]
        return tuple(float(x) for x in c.color[v - 1])  # type: ignore[return-value]

    def readings(self) -> dict:
        return {"value": self.value}

    def describe(self) -> dict:
        c = self.config
        return {"value": int(self.value), "color": [float(v) for rgb in c.color for v in rgb], "gradual": bool(c.gradual)}


def device_class(type_name: str) -> type | None:
    """The simulation's class of a device kind (its ``implementation`` in schemas/devices.py),
    ``None`` for a kind that is listed, not simulated."""
    impl = kind(type_name).implementation
    if impl is None:
        return None
    cls = _CLASSES.get(impl)
    if cls is None:
        module, _, name = impl.partition(":")
        cls = _CLASSES[impl] = getattr(importlib.import_module(module), name)
    return cls


_CLASSES: dict[str, type] = {}
RAY_DEVICES = (LightSensor, DistanceSensor, Lidar)


class GPS(Device):
    """Webots GPS (``server/devices/gps.py``): position, speed, speed vector of the device, from
    the kinematic world; NaN before the first value, the speed also at the first one (Webots: no
    previous position)."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.values = np.full(3, math.nan)
        self.speed = math.nan
        self.speed_vector = np.full(3, math.nan)
        self._noise = np.zeros(3)                         # the Gauss-Markov state of the position noise
        self._previous: np.ndarray | None = None          # the translation at the previous measurement
        self._robot: Any = None
        self._world_info: Any = wm.WorldInfo()

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._world_info = robot.world_info

    @property
    def coordinate_system(self) -> int:
        return 1 if self._world_info.gps_coordinate_system == "WGS84" else 0

    def measure(self, now_ms: int) -> None:
        c, wi = self.config, self._world_info
        elapsed = now_ms - self.schedule.last_update_ms
        t = self.world_pose(self._robot.pose).translation
        rng = self.rng if (c.accuracy > 0.0 or c.speed_noise > 0.0) else None
        self.values = gps_math.position(
            t, coordinate_system=wi.gps_coordinate_system, reference=wi.gps_reference, axes=wi.coordinate_system,
            accuracy=c.accuracy, correlation=c.noise_correlation, elapsed_ms=elapsed, noise=self._noise, rng=rng,
            resolution=c.resolution)
        self.speed_vector = gps_math.speed_vector(t, self._previous, elapsed)
        self._previous = np.array(t, dtype=np.float64)
        self.speed = gps_math.speed(self.speed_vector, noise=c.speed_noise, rng=rng, resolution=c.speed_resolution)
        self._mark(now_ms)

    def restart(self) -> None:
        """A simulation reset: no previous position, so the next value's speed is NaN, as the first
        one's (Webots' WbGps::reset; its device without physics)."""
        self._previous = None

    def readings(self) -> dict:
        return {"values": self.values, "speed": self.speed, "speed_vector": self.speed_vector}

    def step_reading(self) -> dict:
        return {"values": [float(v) for v in self.values], "speed": float(self.speed),
                "speed_vector": [float(v) for v in self.speed_vector]}

    def describe(self) -> dict:
        c = self.config
        return {"coordinate_system": self.coordinate_system, "accuracy": float(c.accuracy),
                "noise_correlation": float(c.noise_correlation), "resolution": float(c.resolution),
                "speed_noise": float(c.speed_noise), "speed_resolution": float(c.speed_resolution)}


class InertialUnit(Device):
    """Webots InertialUnit (``server/devices/orientation.py``): the device's world orientation as a
    quaternion and as roll, pitch, yaw in the world's convention (ENU or NUE); NaN before the first value."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.quaternion = np.full(4, math.nan)
        self.roll_pitch_yaw = np.full(3, math.nan)
        self._robot: Any = None
        self._axes = "ENU"

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._axes = robot.world_info.coordinate_system

    def measure(self, now_ms: int) -> None:
        c = self.config
        q = matrix_quaternion(self.world_pose(self._robot.pose).rotation)
        self.quaternion = orient.inertial_quaternion(
            q, noise=c.noise, rng=self.rng if c.noise > 0.0 else None, x_axis=c.x_axis, y_axis=c.y_axis,
            z_axis=c.z_axis, resolution=c.resolution)
        self.roll_pitch_yaw = orient.roll_pitch_yaw(self.quaternion, self._axes)
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"quaternion": self.quaternion, "roll_pitch_yaw": self.roll_pitch_yaw}

    def step_reading(self) -> dict:
        return {"quaternion": [float(v) for v in self.quaternion],
                "roll_pitch_yaw": [float(v) for v in self.roll_pitch_yaw]}

    def describe(self) -> dict:
        return {"noise": float(self.config.noise), "coordinate_system": self._axes}


class Compass(Device):
    """Webots Compass (``server/devices/orientation.py``): north in the device frame through the
    lookup table; NaN before the first value and on a disabled axis."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.table = LookupTable(self.config.lookup_table)
        self.values = np.full(3, math.nan)
        self._robot: Any = None
        self._axes = "ENU"

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._axes = robot.world_info.coordinate_system

    def measure(self, now_ms: int) -> None:
        c = self.config
        self.values = orient.compass_values(
            self.world_pose(self._robot.pose).rotation, self._axes, self.table,
            self.rng if self.table.has_noise else None, x_axis=c.x_axis, y_axis=c.y_axis, z_axis=c.z_axis,
            resolution=c.resolution)
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"values": self.values}

    def step_reading(self) -> dict:
        return {"values": [float(v) for v in self.values]}

    def describe(self) -> dict:
        return {"lookup_table": self.flat_lookup_table()}


class _MotionSensor(Device):
    """A device that reads the kinematic motion: the device's world poses after the last basic
    steps (since it was enabled), kept by ``track``."""

    kinematic = True
    tracks_motion = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.values = np.full(3, math.nan)
        self._poses: list[Pose] = []
        self._robot: Any = None
        self._axes = "ENU"
        self._gravity = 9.81
        self._dt_s = 0.032

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._axes = robot.world_info.coordinate_system
        self._gravity = float(robot.world_info.gravity)
        self._dt_s = robot.basic_time_step / 1000.0

    def enable(self, period_ms: int) -> None:
        super().enable(period_ms)
        self._poses = [self.world_pose(self._robot.pose)] if self._robot is not None else []

    def track(self) -> None:
        self._poses = [*self._poses[-2:], self.world_pose(self._robot.pose)]

    def placed(self) -> None:
        """The robot was put somewhere from outside (a Supervisor move, a simulation reset): a jump,
        not motion (Webots' gyro and accelerometer read the bodies' velocities, which a move keeps
        and a reset zeroes), so the poses start over from there, as at ``enable``."""
        self._poses = [self.world_pose(self._robot.pose)]

    def _through_table(self, raw: np.ndarray) -> np.ndarray:
        c = self.config
        table = self.table
        return motion_math.axes_through_table(raw, table, self.rng if table.has_noise else None,
                                              (c.x_axis, c.y_axis, c.z_axis), c.resolution)

    def readings(self) -> dict:
        return {"values": self.values}

    def step_reading(self) -> dict:
        return {"values": [float(v) for v in self.values]}

    def describe(self) -> dict:
        return {"lookup_table": self.flat_lookup_table()}


class Accelerometer(_MotionSensor):
    """Webots Accelerometer (``server/devices/motion_sensors.py``): gravity and the kinematic
    acceleration in the device frame; rest is assumed until three poses are known."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.table = LookupTable(self.config.lookup_table)

    def measure(self, now_ms: int) -> None:
        poses = self._poses or [self.world_pose(self._robot.pose)]
        last = poses[-1]
        p = [q.translation for q in poses]
        p0, p1 = (p[-3], p[-2]) if len(p) >= 3 else (last.translation, last.translation)
        raw = motion_math.specific_force(last.rotation, p0, p1, last.translation, self._dt_s, self._gravity, self._axes)
        self.values = self._through_table(raw)
        self._mark(now_ms)


class Gyro(_MotionSensor):
    """Webots Gyro (``server/devices/motion_sensors.py``): the angular velocity in the device frame
    over the last basic step; rest until two poses are known."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.table = LookupTable(self.config.lookup_table)

    def measure(self, now_ms: int) -> None:
        poses = self._poses or [self.world_pose(self._robot.pose)]
        r0 = poses[-2].rotation if len(poses) >= 2 else poses[-1].rotation
        raw = motion_math.angular_velocity(r0, poses[-1].rotation, self._dt_s)
        self.values = self._through_table(raw)
        self._mark(now_ms)


def altitude_offset(world_info: Any) -> float:
    """What an Altimeter adds to its height along up: the ``gps_reference``'s altitude -- its third
    value in a WGS84 world, its up component (ENU: z, NUE: y) in local coordinates, as Webots'
    WbAltimeter (and so as the GPS, which adds the reference in local coordinates too)."""
    ref = world_info.gps_reference
    if world_info.gps_coordinate_system == "WGS84":
        return float(ref[2])
    return float(ref[world_info.coordinate_system.index("U")])


class Altimeter(Device):
    """Webots Altimeter: the device's height along the up axis plus the reference altitude
    (:func:`altitude_offset`), Gaussian ``accuracy`` noise, ``resolution``; NaN before the first value."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.value = math.nan
        self._robot: Any = None
        self._up = 2
        self._offset = 0.0

    def bind(self, robot: Any) -> None:
        self._robot = robot
        wi = robot.world_info
        self._up = wi.coordinate_system.index("U")
        self._offset = altitude_offset(wi)

    def measure(self, now_ms: int) -> None:
        c = self.config
        v = float(self.world_pose(self._robot.pose).translation[self._up]) + self._offset
        if c.accuracy > 0.0:
            v += c.accuracy * float(self.rng.standard_normal())
        if c.resolution != -1.0:
            v = float(quantize_sensor(v, c.resolution))
        self.value = v
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"value": self.value}

    def describe(self) -> dict:
        return {"accuracy": float(self.config.accuracy), "resolution": float(self.config.resolution)}


def self_collision_shapes(model: wm.Robot, device: str, links: set[str | None]) -> list:
    """The bounding shapes of robot ``model`` (its selfCollision TRUE) that bumper ``device``, whose
    own shapes ride on ``links`` (joint names, None the body), may touch: Webots detects collisions
    between the robot's solids that are not consecutive, so those on its own links and on the links
    one joint away from them (a joint's end point and the solid it hangs from) are left out, and the
    bumper's own shapes."""
    parent = {d.name: d.on_joint for d in model.devices if isinstance(d, wm.Motor)}
    near = set(links) | {parent.get(j) for j in links if j is not None} | \
        {j for j, up in parent.items() if up in links}
    return [p for p in model.shapes if p.seen_by in ("both", "bounding") and p.of_device != device
            and p.on_joint not in near]


class TouchSensor(Device):
    """Webots TouchSensor. A bumper with bounding shapes of its own (the robot's shapes whose
    ``of_device`` names it) touches on a step when, at the end of it, one of them touches a solid or
    another robot as kinematic contact sees them (contact.pieces_touch: a gap of at most
    contact.TOUCH, bands overlapping) -- each shape where its joint holds it now, the pieces made
    again only when such a joint moved; a bumper without any touches on a step contact clipped its
    robot's move. A reading is 1 when it touched on any step since its previous reading, else 0
    (WbTouchSensor: each step's collisions set its flag, only a reading clears it): after each step
    the simulation asks the bumpers that are not due -- enabled ones between two readings, and
    disabled ones that were enabled before (``armed``) -- whether they touch (:meth:`sample`), each
    only until it touched. A bumper never enabled is never asked. ``force`` and ``force-3d`` read NaN
    (they need physics; Webots' force readings are each reading's step's value, never kept). On a
    robot whose ``selfCollision`` is TRUE a bumper also touches the robot's own shapes that are not
    consecutive to it (:func:`self_collision_shapes`: Webots' A4 Portal's end stops, pressed by its gate)."""

    kinematic = True
    TYPE_CODES: ClassVar[dict[str, int]] = {"bumper": 0, "force": 1, "force-3d": 2}

    def __post_init__(self) -> None:
        super().__post_init__()
        self.table = LookupTable(self.config.lookup_table)
        self.type_code = self.TYPE_CODES[self.config.type]
        self.value = math.nan
        self.values = np.full(3, math.nan)
        self._robot: Any = None
        self._own: list = []                   # its own bounding shapes (primitive, pose in the robot frame)
        self._on: list = []                    # the joint each of them rides on (None: the body)
        self._pieces: list | None = None       # as contact takes them (contact.device_pieces), made when first due
        self._held: list = []                  # the joints' displacements the pieces were made at
        self._riding = False                   # whether any of its shapes rides on a joint
        self.touched = False                   # a bumper touched on a step since its last reading
        self.armed = False                     # a bumper enabled at least once: asked between readings
        # selfCollision: its robot's own bounding shapes it may touch (primitive, pose, joint), their
        # pieces as contact takes them and the joints' displacements they were made at
        self._others: list = []
        self._other_pieces: list | None = None
        self._others_held: list = []

    def bind(self, robot: Any) -> None:
        self._robot = robot
        if self.type_code == 0:
            base = robot.simulation.loaded.base_dir
            own = [p for p in robot.model.shapes if p.of_device == self.name and p.seen_by in ("both", "bounding")]
            self._own = [(primitive_from_model(p.geometry, base), pose_from_model(p.pose)) for p in own]
            self._on = [p.on_joint for p in own]
            self._riding = any(j is not None for j in self._on)
            self._held = [None] * len(own)
            if own and robot.model.self_collision:
                others = self_collision_shapes(robot.model, self.name, set(self._on))
                self._others = [(primitive_from_model(p.geometry, base), pose_from_model(p.pose), p.on_joint)
                                for p in others]
                self._others_held = [None] * len(others)

    @property
    def self_touching(self) -> bool:
        """Whether this bumper may touch its own robot's shapes (selfCollision: :func:`self_collision_shapes`)."""
        return bool(self._others)

    def _held_now(self) -> list:
        """Where the joints its shapes ride on hold them now: each one's displacement (a joint's
        displacement is a new Pose whenever it moved, the same one while it stays)."""
        if not self._riding:
            return self._held
        robot = self._robot
        return [None if j is None else robot.link_pose(j) for j in self._on]

    def touching(self) -> bool:
        """Whether a bumper touches at the end of this step (see the class)."""
        robot = self._robot
        if not self._own:                      # no shapes of its own: its robot's contact
            return bool(robot.pressing)
        contact = robot.simulation.contact
        if contact is None:                    # contact off: nothing is touched
            return False
        held = self._held_now()
        if self._pieces is None or any(a is not b for a, b in zip(held, self._held)):
            # made again only when a joint it rides on moved since they were made
            own = [(prim, local if at is None else at.compose(local)) for (prim, local), at in zip(self._own, held)]
            self._pieces = contact.pieces(robot.index, own)
            self._held = held
        if contact.touching(robot.index, self._pieces):
            return True
        if not self._others:
            return False
        held = [None if j is None else robot.link_pose(j) for _, _, j in self._others]
        if self._other_pieces is None or any(a is not b for a, b in zip(held, self._others_held)):
            parts = [(prim, local if at is None else at.compose(local)) for (prim, local, _), at in zip(self._others, held)]
            self._other_pieces = contact.pieces(robot.index, parts)
            self._others_held = held
        return contact.touching_own(robot.index, self._pieces, self._other_pieces)

    def enable(self, period_ms: int) -> None:
        super().enable(period_ms)
        if self.type_code == 0 and self.schedule.period_ms > 0:
            self.armed = True

    def sample(self) -> None:
        """A step on which an armed bumper is not due: remember whether it touched (asked until it
        did; the next reading clears it)."""
        if not self.touched:
            self.touched = self.touching()

    def measure(self, now_ms: int) -> None:
        if self.type_code == 0:
            self.value = 1.0 if self.touched or self.touching() else 0.0
            self.touched = False
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"value": self.value, "values": self.values}

    def step_reading(self) -> dict:
        if self.type_code == 2:
            return {"values": [float(v) for v in self.values]}
        return {"value": float(self.value)}

    def describe(self) -> dict:
        return {"sensor_type": self.type_code, "lookup_table": self.flat_lookup_table()}
