"""Devices that see images: Webots' RangeFinder (and Camera, its recognition) on the ray engine.

An image is a batch of rays, one per pixel (four with anti-aliasing), rigidly mounted on the
device: their directions in the device frame are made once (on the first capture), rotated into
the world only when the device turns, and cast in one engine call (plus, for a camera, the calls
its shading needs). Nothing is computed while a device is disabled; the simulation calls
``capture`` when ``due``. The pure models are ``server/devices/imaging.py`` (rays, ranges),
``shading.py`` (colours) and ``recognition.py`` (objects).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from sensorium.server.devices import imaging
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.sensors import Device
from sensorium.server.world.geometry import Pose

__all__ = ["RangeFinder", "MountedRays"]


class MountedRays:
    """A device's pixel rays: local directions (made once), world directions kept until the
    device's rotation changes (a parked or translating robot rotates nothing), and their float32
    copy for Embree."""

    def __init__(self, local: np.ndarray):
        self.local = np.ascontiguousarray(local.reshape(-1, 3))
        self._cols = tuple(np.ascontiguousarray(self.local[:, k]) for k in range(3))
        self._key: bytes | None = None
        self.world = np.empty((0, 3))
        self.world32 = np.empty((0, 3), dtype=np.float32)

    def __len__(self) -> int:
        return len(self.local)

    def at(self, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = rotation.tobytes()
        if key != self._key:
            x, y, z = self._cols
            out = np.empty((len(x), 3))
            for k in range(3):     # by columns: no BLAS call (threads stall on a busy machine)
                out[:, k] = x * rotation[k, 0] + y * rotation[k, 1] + z * rotation[k, 2]
            out.flags.writeable = False
            w32 = out.astype(np.float32)
            w32.flags.writeable = False
            self._key, self.world, self.world32 = key, out, w32
        return self.world, self.world32


def camera_info(geometry: imaging.ImageGeometry) -> dict:
    """The fields of a ``sensor_msgs/CameraInfo`` after its header (a planar image's exact pinhole)."""
    fx, fy, cx, cy = imaging.pinhole_intrinsics(geometry)
    k = np.array([fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0], dtype="<f8")
    p = np.array([fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0], dtype="<f8")
    return {"height": int(geometry.height), "width": int(geometry.width), "distortion_model": "plumb_bob",
            "d": bytes(40), "k": k.tobytes(), "r": np.eye(3, dtype="<f8").tobytes(), "p": p.tobytes(),
            "binning_x": 0, "binning_y": 0,
            "roi": {"x_offset": 0, "y_offset": 0, "height": 0, "width": 0, "do_rectify": False}}


class RangeFinder(Device):
    """Webots' RangeFinder: a float32 range image (H, W), zeros before the first one (Webots)."""

    captures: ClassVar[bool] = True
    """The simulation calls ``capture(now_ms, counters)`` when ``due(now_ms)``."""

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.geometry = imaging.ImageGeometry(c.width, c.height, c.field_of_view, c.projection)
        self.range_image = np.zeros((c.height, c.width), dtype=np.float32)
        self._rays: MountedRays | None = None
        self._factors: np.ndarray | None = None
        self._limits: tuple[Any, Any] = (0.0, 0.0)
        self._robot: Any = None
        self._scene: Any = None

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._scene = robot.scene

    # -- controller API
    def describe(self) -> dict:
        c = self.config
        return {"width": int(c.width), "height": int(c.height), "fov": float(c.field_of_view),
                "near": float(c.near), "minRange": float(c.min_range), "maxRange": float(c.max_range),
                "projection": c.projection}

    def readings(self) -> dict:
        return {"range_image": self.range_image}

    def camera_info(self) -> dict:
        return camera_info(self.geometry)

    # -- measurement
    def due(self, now_ms: int) -> bool:
        return self.schedule.due(now_ms)

    def _prepare(self) -> MountedRays:
        if self._rays is None:
            dirs = imaging.pixel_directions(self.geometry)[0]
            self._factors = imaging.depth_factors(self.geometry, dirs)
            # rays need not reach beyond max_range (in depth for a planar image): nothing there counts
            self._limits = imaging.clip_limits(self.geometry, self._factors, self.config.near, self.config.max_range)
            self._rays = MountedRays(dirs)
        return self._rays

    def capture(self, now_ms: int, counters: Any) -> None:
        rays = self._prepare()
        pose: Pose = self.world_pose(self._robot.pose)
        dirs, dirs32 = rays.at(pose.rotation)
        origins = np.broadcast_to(pose.translation, dirs.shape)
        t_near, t_far = self._limits
        hits = self._scene.engine.cast(origins, dirs, t_near, t_far, kind=RayKind.VISUAL, exclude_owner=-1,
                                       distance_only=True, directions32=dirs32)
        counters["rays_range_finder"] += len(rays)
        counters["cast_calls"] += 1
        c = self.config
        self.range_image = imaging.range_values(
            hits.distance.reshape(c.height, c.width), self._factors, c.min_range, c.max_range, c.noise,
            c.resolution, self.rng if c.noise > 0 else None)
        self.schedule.last_update_ms = now_ms
        self._mark(now_ms)
