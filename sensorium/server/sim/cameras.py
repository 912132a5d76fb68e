"""Devices that see images: Webots' RangeFinder (and Camera, its recognition) on the ray engine.

An image is a batch of rays, one per pixel (four with anti-aliasing), rigidly mounted on the
device: their directions in the device frame are made once (on the first capture), rotated into
the world only when the device turns, and cast in one engine call (plus, for a camera, the calls
its shading needs). Nothing is computed while a device is disabled; the simulation calls
``capture`` when ``due``. The pure models are ``server/devices/imaging.py`` (rays, ranges),
``shading.py`` (colours) and ``recognition.py`` (objects). A device never sees the shapes of its
own Solid (``of_device``, a camera's small housing): its pixel rays pass through them
(``own_shapes.py``, the lidar's rule).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import imaging, shading
from sensorium.server.devices import light as light_math
from sensorium.server.raycast import blocks
from sensorium.server.raycast.engine import Precision, RayHits, RayKind, Riding
from sensorium.server.sim.own_shapes import OwnBodyRays, cast_skipping
from sensorium.server.sim.scene import emissive_rows, emissive_scale, light_from_model
from sensorium.server.sim.sensors import Device, Schedule
from sensorium.server.sim.sensors import _check_period as _period
from sensorium.server.world.geometry import Pose

__all__ = ["Camera", "RangeFinder", "MountedRays", "ShadowBuffers", "camera_lights", "camera_info", "composite",
           "lens_of", "noise_mask_planes"]


class MountedRays:
    """A device's pixel rays: local directions (made once), world directions kept until the
    device's rotation changes (a parked or translating robot rotates nothing), and their float32
    copy for Embree. ``own``: how they are cast when the device has shapes of its own; ``riding``:
    else, the robot's body they ride, which they see (which of them can meet it decided once)."""

    def __init__(self, local: np.ndarray, own: OwnBodyRays | None = None, riding: Riding | None = None):
        self.local = np.ascontiguousarray(local.reshape(-1, 3))
        self.own = own
        self.riding = riding
        self._cols = tuple(np.ascontiguousarray(self.local[:, k]) for k in range(3))
        self._key: bytes | None = None
        self.world = np.empty((0, 3))
        self.world32 = np.empty((0, 3), dtype=np.float32)

    def __len__(self) -> int:
        return len(self.local)

    def at(self, rotation: np.ndarray, threads: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """The world directions (and their float32 copy) at ``rotation``: turned in row blocks on up
        to ``threads`` threads, each row's value the same on any number of them."""
        key = rotation.tobytes()
        if key != self._key:
            x, y, z = self._cols
            n = len(x)
            out = np.empty((n, 3))
            w32 = np.empty((n, 3), dtype=np.float32)

            def turn(sl: slice) -> None:
                for k in range(3):     # by columns: no BLAS call (threads stall on a busy machine)
                    out[sl, k] = x[sl] * rotation[k, 0] + y[sl] * rotation[k, 1] + z[sl] * rotation[k, 2]
                w32[sl] = out[sl]      # rounded to float32 as astype rounds

            rows = shading.BLOCK if n >= blocks.MIN_RAYS else max(n, 1)
            blocks.run(turn, [slice(a, min(n, a + rows)) for a in range(0, n, rows)], threads)
            out.flags.writeable = False
            w32.flags.writeable = False
            self._key, self.world, self.world32 = key, out, w32
        return self.world, self.world32


def _mounted(device: Any, dirs: np.ndarray, limits: tuple[Any, Any]) -> MountedRays:
    """A device's pixel rays (directions in its frame) and, when it has shapes of its own, their
    cast mounted on its robot's body, blind to those shapes (``own_shapes.py``, the lidar's way);
    else, on a robot with a body, which of them can meet that body, decided once in its frame."""
    body = device._scene.device_body(device.robot_index, device.on_joint)
    if body is None:
        return MountedRays(dirs)
    mount = device.mount_pose
    if device.own_shapes:
        return MountedRays(dirs, own=OwnBodyRays(body, mount, dirs.reshape(-1, 3), *limits, device.own_shapes))
    local = dirs.reshape(-1, 3) @ mount.rotation.T
    return MountedRays(dirs, riding=Riding(body, mount.translation, local, *limits))


def _cast_pixels(device: Any, rays: MountedRays, pose: Pose, limits: tuple[Any, Any],
                 distance_only: bool = False) -> RayHits:
    """The nearest surface along each of a device's pixel rays from its world pose ``pose``: nothing
    excluded (its robot is in view), but blind to the device's own shapes."""
    engine = device._scene.engine
    dirs, dirs32 = rays.at(pose.rotation, engine.threads)
    origins = np.broadcast_to(pose.translation, dirs.shape)
    if device.hidden:     # a Supervisor hid nodes from it (setVisibility): a plain cast, on past them
        return cast_skipping(engine, origins, dirs, *limits, device.own_shapes | device.hidden_shapes,
                             directions32=dirs32)
    if rays.own is not None:
        return rays.own.cast(engine, origins, dirs, device.carrier_rotation(device._robot.pose), dirs32,
                             distance_only)
    return engine.cast(origins, dirs, *limits, kind=RayKind.VISUAL, exclude_owner=-1, distance_only=distance_only,
                       directions32=dirs32, riding=rays.riding)


def _shade(P: np.ndarray, N: np.ndarray, albedo: np.ndarray, lights: light_math.LightArrays, lit: np.ndarray | None,
           threads: int) -> np.ndarray:
    """``shading.radiance`` of an image's points, its row blocks on up to ``threads`` threads (numpy
    releases the GIL in each pass; every row's value is the one a single call gives)."""
    S = len(P)
    if threads <= 1 or S < 2 * shading.BLOCK:
        return shading.radiance(P, N, albedo, lights, lit)
    out = np.empty((S, 3))

    def part(sl: slice) -> None:
        out[sl] = shading.radiance(P[sl], N[sl], albedo[sl], lights, None if lit is None else lit[sl])

    blocks.run(part, [slice(a, min(S, a + shading.BLOCK)) for a in range(0, S, shading.BLOCK)], threads)
    return out


def lens_of(config: Any) -> imaging.Lens | None:
    """A Camera's or RangeFinder's lens as the image model takes it (None without a Lens node): a
    planar image's own, or each cube face's of a spherical or cylindrical one (imaging's docstring)."""
    lens = config.lens
    if lens is None:
        return None
    return imaging.Lens(tuple(lens.center), tuple(lens.radial_coefficients), tuple(lens.tangential_coefficients))


def noise_mask_planes(scene: Any, url: str) -> np.ndarray | None:
    """A camera's noise mask (None without one): the image the world's check read
    (world/textures.py; the ``scene``'s images), as a shape's texture (read and checked here when a
    world was given unchecked), as R, G, B, A planes (4, h, w) in [0, 1]
    (``shading.apply_noise_mask``). The single and the batched camera share it."""
    if not url:
        return None
    if url in scene.images:
        rgb, alpha, _ = scene.images[url][1]
    else:
        from sensorium.server.world.limits import WorldLimits
        from sensorium.server.world.textures import read_checked_image

        rgb, alpha, _ = read_checked_image(url, scene.base_dir, WorldLimits(), allow_outside=True)[2]
    mask = np.empty((4, *rgb.shape[:2]))
    mask[:3] = np.moveaxis(rgb, 2, 0)
    mask[3] = 255.0 if alpha is None else alpha
    mask /= 255.0
    return mask


def camera_info(geometry: imaging.ImageGeometry) -> dict:
    """The fields of a ``sensor_msgs/CameraInfo`` after its header (a planar image's exact pinhole).
    ``d`` stays zeros with a lens: Webots' distortion is not OpenCV's plumb_bob (image units per
    axis, an approximate inverse; README "Lens distortion")."""
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
        self.lens = lens_of(c)
        self.range_image = np.zeros((c.height, c.width), dtype=np.float32)
        self._rays: MountedRays | None = None
        self._factors: np.ndarray | None = None
        self._limits: tuple[Any, Any] = (0.0, 0.0)
        self._robot: Any = None
        self._scene: Any = None
        # motion blur: the last image's blurred values (+inf before the first: that one is itself)
        self._blurred: np.ndarray | None = None

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
            dirs = imaging.pixel_directions(self.geometry, lens=self.lens)[0]
            self._factors = imaging.depth_factors(self.geometry, dirs, self.lens)
            # rays need not reach beyond max_range (in depth for a planar image): nothing there counts
            self._limits = imaging.clip_limits(self.geometry, self._factors, self.config.near, self.config.max_range)
            self._rays = _mounted(self, dirs, self._limits)
        return self._rays

    def capture(self, now_ms: int, counters: Any) -> None:
        rays = self._prepare()
        hits = _cast_pixels(self, rays, self.world_pose(self._robot.pose), self._limits, distance_only=True)
        counters["rays_range_finder"] += len(rays)
        counters["cast_calls"] += 1
        c = self.config
        blur = None
        if c.motion_blur > 0:
            if self._blurred is None:
                self._blurred = np.full((c.height, c.width), np.inf)
            blur = (self._blurred, shading.motion_blur_weight(self.schedule.period_ms, c.motion_blur))
        self.range_image = imaging.range_values(
            hits.distance.reshape(c.height, c.width), self._factors, c.min_range, c.max_range, c.noise,
            c.resolution, self.rng if c.noise > 0 else None, blur)
        self.schedule.last_update_ms = now_ms
        self._mark(now_ms)


# ---------------------------------------------------------------------------------- Camera

MAX_LAYERS = 8
"""Semi-transparent surfaces (or see-through texels) composited along one ray: a ray goes on past at
most this many; the surface it meets after them is taken as opaque (its colour, even where its
texel is clear), so a pixel never costs more than ``MAX_LAYERS + 1`` casts."""

F32_PAST = 2.0 ** -15
"""FAST: how far past a semi-transparent surface a ray goes on, per metre of |origin| + t, at normal
incidence (divided by |cos| of the incidence, at most by 16). Its float32 start point (origin + t D
rounded) and Embree's float32 distance to a large triangle (error growing with the vertices' distance
from the ray's origin) can put the start on the surface's near side: the surface is met again, taken
for its far face, and the real far face for a new entering one (a half-transparent box wall read 23 to
40 levels too bright at oblique pixels). 2^-18 was the least that kept a 400 m wall exact up to grazing
incidence (tests/test_camera.py); this is 8 times it. A far face nearer than that is passed with its
front face, as back-face culling hides it anyway"""


def composite(origin: np.ndarray, dirs: np.ndarray, first: RayHits, limits: tuple[Any, Any], cast_on,
              transparency: np.ndarray, background: np.ndarray, fog, surface, alpha=None,
              float32: bool = False) -> np.ndarray:
    """The radiance (N, 3) along every ray of a camera at ``origin``: the surfaces it crosses
    composited front to back (semi-transparent ones let ``transparency`` of what is behind through;
    a closed shape's faces are crossed twice and only its entering face is seen, as with back-face
    culling), each surface mixed with the ``fog`` (``shading.fog``'s arguments, or None) by its
    distance, the ``background`` (not fogged) where nothing is hit. ``first``: the rays' first hits
    within ``limits``; ``cast_on(D, t_near, t_far)``: the hits of rays from ``origin`` going on past
    a semi-transparent surface; ``surface(shape, P, N, D, t)``: the radiance (n, 3) of the surfaces
    seen, before fog. ``alpha``: None in a world without alpha textures, else ``(shapes, opacity)``:
    ``shapes[s]`` whether shape s's image has transparent texels, ``opacity(shape, D, t)`` the
    texel alpha (n,) at hits on such shapes; a hit there lets ``1 − (1 − transparency)·alpha``
    through (Webots' final alpha), and a fully clear texel is not shaded. ``float32``: the casts are
    FAST's float32 traversal, so a ray goes on past a surface by :data:`F32_PAST` of its reach (EXACT's
    float64 hits: by 1e-7 m and 1e-12 of t). The single camera and the batched one (per copy) share it."""
    n = len(dirs)
    t_near, t_far = limits
    tn = tf = inside = None           # per-ray limits and the transparent shapes each ray is in: made
    out = np.zeros((n, 3))            # when a ray first goes through a semi-transparent surface
    weight = None                     # what each ray's next surface adds: 1 until a surface lets some through
    rows = np.arange(0)               # the rays going on past the last layer's surfaces
    for layer in range(MAX_LAYERS + 1):
        if layer == 0:
            D, hits = dirs, first
        else:                       # on past semi-transparent surfaces
            assert tn is not None and tf is not None
            D = dirs[rows]
            hits = cast_on(D, tn[rows], tf[rows])
        t, shape, normal = hits.distance, hits.shape, hits.normal
        assert shape is not None and normal is not None
        hit = np.isfinite(t)
        if layer == 0:             # every weight 1, every sum 0: the sky is 0 + 1·background, filled by mask
            sky = np.zeros(3)
            sky += shading.scaled_rows(np.ones(1), background)[0]
            shading.set_rows(out, ~hit, sky)
        else:
            miss = (~hit).nonzero()[0]
            if len(miss):
                assert weight is not None
                rm = rows[miss]
                shading.add_to_rows(out, rm, shading.scaled_rows(weight[rm], background))
        k = hit.nonzero()[0]
        if len(k) == 0:
            break
        r, s = (k, shape if len(k) == n else shape[k]) if layer == 0 else (rows[k], shape[k])
        tau = transparency[s]
        clear = tau > 0.0
        textured = None                # the hits on shapes with transparent texels (an alpha world only)
        if alpha is not None:
            textured = alpha[0][s]
            if textured.any():
                clear = clear | textured     # may let light through: entering and leaving as above
            else:
                textured = None
        leaving = np.zeros(len(k), dtype=bool)
        any_clear = bool(clear.any())
        if any_clear and inside is None:
            inside = np.full((n, MAX_LAYERS), -1, dtype=np.int64)
            tn = np.broadcast_to(np.asarray(t_near, dtype=np.float64), (n,)).copy()
            tf = np.broadcast_to(np.asarray(t_far, dtype=np.float64), (n,))
        if any_clear:              # a transparent shape the ray is already in: its far face
            assert inside is not None
            leaving = clear & (inside[r] == s[:, None]).any(axis=1)
        seen = (~leaving).nonzero()[0]
        if textured is not None:   # each entering hit's own transparency: 1 - (1 - tau) alpha
            ta = (textured & ~leaving).nonzero()[0]
            if len(ta):
                ka = k[ta]
                tau[ta] = 1.0 - (1.0 - tau[ta]) * alpha[1](s[ta], D.take(ka, axis=0), t.take(ka))
            clear = leaving | (tau > 0.0)      # an opaque texel stops the ray
            if layer < MAX_LAYERS:             # a clear texel adds nothing: not shaded
                seen = seen[tau[seen] < 1.0]
        if len(seen):
            every = len(seen) == len(k)
            kk, rr, ss = (k, r, s) if every else (k[seen], r[seen], s[seen])
            whole = len(kk) == len(D)
            Dk = D if whole else shading.take_rows(D, kk)
            tk = t if whole else t.take(kk)
            P = np.multiply(Dk, tk[:, None])     # origin + t D: each value's product, then its sum
            P += origin
            N = normal if whole else shading.take_rows(normal, kk)
            dot = N[:, 0] * Dk[:, 0]            # N·D, summed as (x + y) + z
            dot += N[:, 1] * Dk[:, 1]
            dot += N[:, 2] * Dk[:, 2]
            back = dot > 0.0
            if back.any():         # facing the camera
                bk = back.nonzero()[0]
                N = N.copy() if whole else N
                N[bk] = np.negative(shading.take_rows(N, bk))
            L = surface(ss, P, N, Dk, tk)
            if fog is not None:           # Webots mixes each surface (not the sky) with the fog colour
                L = shading.fog(L, tk, *fog)
            if layer == 0 and not any_clear and not tau.any():
                # nothing seen through (the common opaque image): each share is 1 (1 - 0), each sum
                # 0 + L; no ray goes on, so no weight is needed again
                np.add(L, 0.0, out=L)           # 0 + L (as the sum: -0.0 becomes 0.0)
                if whole:
                    return L
                shading.set_rows(out, hit, L)
                break
            if weight is None:
                weight = np.ones(n)
            last = layer == MAX_LAYERS
            a = np.where(last, 0.0, tau[seen])
            share = weight[rr] * (1.0 - a)
            for ch in range(3):    # (weight (1 - a)) L, column by column
                L[:, ch] *= share
            shading.add_to_rows(out, rr, L)
            weight[rr] *= a
        # the rays that go on: through a transparent surface (entering or leaving it)
        go = clear & (layer < MAX_LAYERS)
        if not go.any():
            break
        if weight is None:       # no surface seen yet (clear texels only): every weight still 1
            weight = np.ones(n)
        assert inside is not None and tn is not None
        g = go.nonzero()[0]
        rg, sg = r[g], s[g]
        ent = ~leaving[g]
        if ent.any():            # entering: remember the shape (in its first free slot)
            free = np.argmax(inside[rg[ent]] < 0, axis=1)
            inside[rg[ent], free] = sg[ent]
        if (~ent).any():         # leaving: forget it
            lv = rg[~ent]
            inside[lv] = np.where(inside[lv] == sg[~ent][:, None], -1, inside[lv])
        kg = k[g]
        tg = t[kg]
        past = tg * (1.0 + 1e-12) + 1e-7                 # just past this surface
        if float32:                                      # (beyond float32's rounding of the start point)
            nd = np.abs(np.einsum("ij,ij->i", normal[kg], D[kg]))
            reach = float(np.max(np.abs(origin))) + tg
            past = np.maximum(past, tg + F32_PAST * reach / np.maximum(nd, 1.0 / 16.0))
        tn[rg] = past
        rows = rg
    return out


def camera_lights(models: list) -> tuple[light_math.LightArrays, np.ndarray]:
    """The lights that are on (world frame) and which of them cast shadows (Webots' castShadows)."""
    on = [m for m in models if m.on]
    return (light_math.LightArrays.from_lights([light_from_model(m) for m in on]),
            np.array([bool(m.cast_shadows) for m in on], dtype=bool))


class Camera(Device):
    """Webots' Camera: a BGRA image (H, W, 4) uint8, black (alpha 255) before the first one (Webots).
    The shading model is ``server/devices/shading.py``."""

    captures: ClassVar[bool] = True

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.geometry = imaging.ImageGeometry(c.width, c.height, c.field_of_view, c.projection)
        self.lens = lens_of(c)     # the image's; recognition and segmentation are Webots' undistorted ones
        self.fov = float(c.field_of_view)    # a controller's setFov() changes it (a camera with a Zoom)
        self.image = np.zeros((c.height, c.width, 4), dtype=np.uint8)
        self.image[:, :, 3] = 255
        self.exposure = float(c.exposure)
        self._samples = imaging.SAMPLES_2X2 if c.anti_aliasing else imaging.SAMPLES_CENTRE
        self._rays: MountedRays | None = None
        self._limits: tuple[Any, Any] = (0.0, 0.0)
        self._robot: Any = None
        self._scene: Any = None
        self._background = np.zeros(3)
        self._lights: tuple[int, light_math.LightArrays, np.ndarray] | None = None
        self._shadow_out: ShadowBuffers | None = ShadowBuffers()   # None while a render holds it
        self._bytes: tuple[int, bytes] = (-1, b"")
        # recognition (Webots' Recognition node): its own period, objects, segmentation image
        self.recognition_schedule = Schedule()
        self.segmentation_enabled = False
        self.objects: list[Any] = []
        self.segmentation_image = np.zeros((c.height, c.width, 4), dtype=np.uint8)
        self.segmentation_image[:, :, 3] = 255
        self._recognizer: Any = None
        self._recognizer_shapes = -1      # the scene's shapes_version it was built for
        self._centre_rays: MountedRays | None = None
        self._image_at = self._segmentation_at = -1      # the measurement that made the latest of each
        self._seg_bytes: tuple[int, bytes] = (-1, b"")
        self._blurred: np.ndarray | None = None     # motion blur: the last image's mixed radiance (M, 3)
        self._mask: np.ndarray | None = None        # the noise mask's texels (RGBA, h, w) in [0, 1]

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._scene = robot.scene
        self._background = self._scene.background
        self._mask = noise_mask_planes(self._scene, self.config.noise_mask_url)

    # -- controller API
    def describe(self) -> dict:
        c = self.config
        rc = c.recognition
        zoom = c.zoom
        low, high = (self.fov, self.fov) if zoom is None else (zoom.min_field_of_view, zoom.max_field_of_view)
        focus = c.focus if c.focus is not None else wm.Focus()
        return {"focal_length": focus.focal_length, "focal_distance": focus.focal_distance,
                "min_focal_distance": focus.min_focal_distance, "max_focal_distance": focus.max_focal_distance,
                "width": int(c.width), "height": int(c.height), "fov": self.fov, "near": float(c.near),
                "min_fov": float(low), "max_fov": float(high),
                "far": float(c.far), "exposure": float(self.exposure), "projection": c.projection,
                "anti_aliasing": bool(c.anti_aliasing), "noise": float(c.noise),
                "has_recognition": rc is not None, "has_segmentation": bool(rc is not None and rc.segmentation),
                "recognition_sampling_period": int(self.recognition_schedule.period_ms),
                "segmentation_enabled": bool(self.segmentation_enabled)}

    # -- recognition (controller API)
    def recognition_enable(self, period_ms: int) -> None:
        """Webots' ``wb_camera_recognition_enable`` (0 disables it, and the segmentation with it)."""
        if self.config.recognition is None:
            raise ValueError("this camera has no Recognition node")
        self.recognition_schedule.enable(_period(period_ms), self.clock())
        if period_ms == 0:
            self.segmentation_enabled = False

    def controller_released(self) -> None:
        """The robot's controller left: its recognition requests end with it."""
        self.recognition_schedule.enable(0, self.clock())
        self.segmentation_enabled = False

    def enable_segmentation(self, on: bool) -> None:
        rc = self.config.recognition
        if on and (rc is None or not rc.segmentation):
            raise ValueError("this camera's Recognition node has no segmentation (segmentation: true)")
        if on and self.recognition_schedule.period_ms <= 0:
            raise ValueError("the segmentation needs the recognition enabled first (recognition_enable)")
        self.segmentation_enabled = bool(on)

    def set_exposure(self, exposure: float) -> None:
        if not (isinstance(exposure, (int, float)) and math.isfinite(exposure) and exposure >= 0.0):
            raise ValueError(f"exposure must be a finite number >= 0, got {exposure!r}")
        self.exposure = float(exposure)

    def set_fov(self, fov: float) -> None:
        """Webots' ``wb_camera_set_fov`` on a camera with a Zoom: the images (and the recognition, the
        segmentation, ``camera_info``) taken from now on see ``fov``; refused outside the Zoom's range."""
        zoom = self.config.zoom
        if zoom is None:
            raise ValueError("this camera has no Zoom node: its field of view cannot change")
        if isinstance(fov, bool) or not isinstance(fov, (int, float)) or not math.isfinite(fov):
            raise ValueError(f"fov must be a finite number, got {fov!r}")
        if not zoom.min_field_of_view <= fov <= zoom.max_field_of_view:
            raise ValueError(f"fov {fov:g} is out of the Zoom's range [{zoom.min_field_of_view:g}, "
                             f"{zoom.max_field_of_view:g}]")
        planar = self.config.projection == "planar"
        if fov <= 0.0 or (fov >= math.pi if planar else fov > 2.0 * math.pi):
            raise ValueError(f"fov {fov:g} cannot be rendered by a {self.config.projection} camera (it must be in "
                             f"{'(0, pi)' if planar else '(0, 2*pi]'})")
        self._use_fov(float(fov))

    def reset_fov(self) -> None:
        """The world file's field of view again (a simulation reset)."""
        self._use_fov(float(self.config.field_of_view))

    def _use_fov(self, fov: float) -> None:
        if fov == self.fov:
            return
        c = self.config
        self.fov = fov
        self.geometry = imaging.ImageGeometry(c.width, c.height, fov, c.projection)
        self._rays = self._centre_rays = None      # rays, limits and the recognizer are made again for it
        self._recognizer = None

    @property
    def recognition_objects(self) -> list[Any]:
        """The latest recognised objects (``objects``), by the name a batched copy's view gives them."""
        return self.objects

    def readings(self) -> dict:
        return {"image": self.image}

    def image_bytes(self) -> bytes:
        """The BGRA bytes of the latest image, made once per image (topics and step replies share them)."""
        if self._bytes[0] != self._image_at:
            self._bytes = (self._image_at, self.image.tobytes())
        return self._bytes[1]

    def segmentation_bytes(self) -> bytes:
        if self._seg_bytes[0] != self._segmentation_at:
            self._seg_bytes = (self._segmentation_at, self.segmentation_image.tobytes())
        return self._seg_bytes[1]

    def step_reading(self) -> dict:
        out: dict[str, Any] = {}
        if self.config.zoom is not None:      # a reset may have changed it back
            out["fov"] = self.fov
        if self.schedule.period_ms > 0:
            out["image"] = self.image_bytes()
        if self.recognition_schedule.period_ms > 0:
            out["recognition"] = [o.as_dict() for o in self.objects]
            if self.segmentation_enabled:
                out["segmentation_image"] = self.segmentation_bytes()
        return out

    def image_data(self, reading: str) -> tuple[int, int, str, bytes] | None:
        """(height, width, encoding, bytes) of an image a topic publishes (``sensor_msgs/Image``), or
        None when the latest measurement did not make it (a recognition-only one, say)."""
        c = self.config
        if reading == "segmentation_image":
            if self._segmentation_at != self.measurements:
                return None
            return int(c.height), int(c.width), "bgra8", self.segmentation_bytes()
        if self._image_at != self.measurements:
            return None
        return int(c.height), int(c.width), "bgra8", self.image_bytes()

    def camera_info(self) -> dict:
        return camera_info(self.geometry)

    # -- measurement
    def due(self, now_ms: int) -> bool:
        return self.schedule.due(now_ms) or self.recognition_schedule.due(now_ms)

    def _prepare(self) -> MountedRays:
        if self._rays is None:
            c = self.config
            dirs = imaging.pixel_directions(self.geometry, self._samples, self.lens)
            factors = imaging.depth_factors(self.geometry, dirs)
            self._limits = imaging.clip_limits(self.geometry, factors, c.near, c.far if c.far > 0 else math.inf)
            self._rays = _mounted(self, dirs, self._limits)
        return self._rays

    def _light_arrays(self) -> tuple[light_math.LightArrays, np.ndarray]:
        scene = self._scene
        if self._lights is None or self._lights[0] != scene.lights_version:
            arrays, shadows = camera_lights(scene.world_lights())
            self._lights = (scene.lights_version, arrays, shadows)
        return self._lights[1], self._lights[2]

    def capture(self, now_ms: int, counters: Any) -> None:
        pose: Pose = self.world_pose(self._robot.pose)
        if self.schedule.due(now_ms):
            self._capture_image(pose, counters)
            self.schedule.last_update_ms = now_ms
            self._image_at = self.measurements + 1
        if self.recognition_schedule.due(now_ms):
            self._recognise(pose, counters)
            self.recognition_schedule.last_update_ms = now_ms
        self._mark(now_ms)

    def _recognise(self, pose: Pose, counters: Any) -> None:
        from sensorium.server.sim.recognition import Recognizer

        rc = self.config.recognition
        assert rc is not None
        shapes = getattr(self._scene, "shapes_version", 0)      # changed by a Supervisor's import
        if self._recognizer is None or self._recognizer_shapes != shapes:
            self._recognizer = Recognizer(self._scene, self.robot_index, rc, self.geometry)
            self._recognizer_shapes = shapes
        rec = self._recognizer
        pixels = None
        if rc.occlusion == 2 or self.segmentation_enabled:
            pixels = self._pixel_objects(pose, rec, counters)
        self.objects = rec.recognise(pose, pixels, counters)
        if self.segmentation_enabled and pixels is not None:
            c = self.config
            self.segmentation_image = rec.segmentation(pixels, c.height, c.width)
            self._segmentation_at = self.measurements + 1

    def _pixel_objects(self, pose: Pose, rec: Any, counters: Any) -> np.ndarray:
        """The recognisable object (index, -1 none) each pixel centre's ray sees within max_range."""
        c = self.config
        if self._centre_rays is None:
            dirs = imaging.pixel_directions(self.geometry)[0]
            self._centre_factors = imaging.depth_factors(self.geometry, dirs)
            rng = float(c.recognition.max_range) if c.recognition is not None else math.inf
            self._centre_limits = imaging.clip_limits(self.geometry, self._centre_factors, c.near, rng)
            self._centre_rays = _mounted(self, dirs, self._centre_limits)
        hits = _cast_pixels(self, self._centre_rays, pose, self._centre_limits)
        counters["rays_camera"] += len(self._centre_rays)
        counters["cast_calls"] += 1
        return np.where(np.isfinite(hits.distance), rec.key_of[hits.shape], -1)

    def _capture_image(self, pose: Pose, counters: Any) -> None:
        rays = self._prepare()
        L = self._render(pose, rays, counters)
        c = self.config
        # supersampling: the mean radiance of the pixel's rays; then the motion blur, the resolve, the
        # noise, BGRA, the noise mask (Webots' order of passes)
        blur = None
        if c.motion_blur > 0:
            if self._blurred is None:      # the first image: itself (motion_blur.frag's firstRender)
                self._blurred = np.zeros((c.height * c.width, 3))
                blur = (self._blurred, 0.0)
            else:
                blur = (self._blurred, shading.motion_blur_weight(self.schedule.period_ms, c.motion_blur))
        bgra = shading.resolve_bgra(L, self.exposure, c.noise, self.rng if c.noise > 0 else None, len(self._samples),
                                    blur)
        if self._mask is not None:
            masked(bgra, c, self._mask, self.rng)
        self.image = bgra.reshape(c.height, c.width, 4)

    def _render(self, pose: Pose, rays: MountedRays, counters: Any) -> np.ndarray:
        """The radiance (N, 3) along every ray (:func:`composite`); the device's own shapes are
        never met."""
        scene = self._scene
        engine = scene.engine
        origin = pose.translation
        dirs = rays.at(pose.rotation)[0]
        lights, shadows = self._light_arrays()
        first = _cast_pixels(self, rays, pose, self._limits)
        counters["rays_camera"] += len(dirs)
        counters["cast_calls"] += 1

        def cast_on(D: np.ndarray, tn: np.ndarray, tf: np.ndarray) -> RayHits:
            counters["rays_camera"] += len(D)
            counters["cast_calls"] += 1
            O = np.broadcast_to(origin, D.shape)
            if self.own_shapes or self.hidden:
                return cast_skipping(engine, O, D, tn, tf, self.own_shapes | self.hidden_shapes)
            return engine.cast(O, D, tn, tf, kind=RayKind.VISUAL, exclude_owner=-1)

        def surface(s: np.ndarray, P: np.ndarray, N: np.ndarray, D: np.ndarray, t: np.ndarray) -> np.ndarray:
            glow = emissive_rows(scene.emissive, s)
            texel = scene.emissive_texel
            albedo = scene.surface_colors(s, np.broadcast_to(origin, (len(s), 3)), D, t,
                                          None if glow is None or texel is None else (glow, texel))
            if glow is not None and scene.emissive_intensity is not None:
                emissive_scale(glow, scene.emissive_intensity, ~scene.receives_shadows(s), s, bool(shadows.any()))
            lit = None
            if shadows.any():    # shadows fall on opaque surfaces only (Webots' translucent ones take none)
                on = scene.receives_shadows(s).nonzero()[0]
                if len(on) == len(s):     # every surface seen (an opaque world): no gathered copies
                    lit = self._shadows(P, N, lights, shadows, counters)
                else:
                    lit = np.ones((len(s), len(shadows)), dtype=bool)
                    lit[on] = self._shadows(P[on], N[on], lights, shadows, counters)
            L = _shade(P, N, albedo, lights, lit, engine.threads)
            if glow is not None:       # Webots' shaders add the emissive colour to the lit one
                L += glow
            return L

        alpha = None
        shapes = scene.alpha_shapes              # None unless an image has transparent texels
        if shapes is not None:
            def opacity(s: np.ndarray, D: np.ndarray, t: np.ndarray) -> np.ndarray:
                return scene.surface_opacity(s, np.broadcast_to(origin, (len(s), 3)), D, t)

            alpha = (shapes, opacity)
        return composite(origin, dirs, first, self._limits, cast_on, scene.transparency, self._background, scene.fog,
                         surface, alpha, float32=engine.precision is Precision.FAST)

    def _shadows(self, P: np.ndarray, N: np.ndarray, lights: light_math.LightArrays, shadows: np.ndarray,
                 counters: Any) -> np.ndarray:
        """(S, n) False where a shadow-casting light is hidden from the point by a visible shape
        (its segment to the light, 1000 m towards a directional one), not one a Supervisor hid from
        this camera (``hidden_shapes``); only lit, facing pairs cast.
        Which pairs cast and their segments come from :func:`shadow_rays` (row blocks on the
        engine's threads); each light's rays are then one cast, as one batch."""
        lit = np.ones((len(P), len(lights)), dtype=bool)
        engine = self._scene.engine
        # this camera's kept outputs, taken for this call (another thread rendering it meanwhile
        # finds none and makes its own): sized for all its rays, they are made once
        out, self._shadow_out = self._shadow_out, None
        if out is None:
            out = ShadowBuffers()
        try:
            rays = shadow_rays(P, N, lights, shadows, engine.threads, out, max(len(P), len(self._rays or ())))
            for k, (j, (i, unit, length)) in enumerate(rays.items()):
                if len(i) == 0:
                    continue
                if self.hidden:    # a node hidden from this camera casts no shadow in its image (Webots
                    # sets it invisible for the camera's render, and WREN's shadow volumes are its visible nodes')
                    hits = cast_skipping(engine, out.origins(k, P, i), unit, 0.0, length, self.hidden_shapes,
                                         kind=RayKind.SHADOW)
                else:
                    hits = engine.cast(out.origins(k, P, i), unit, 0.0, length, kind=RayKind.SHADOW, exclude_owner=-1,
                                       distance_only=True)
                counters["rays_camera"] += len(i)
                counters["cast_calls"] += 1
                lit[i, j] = ~(hits.distance <= length)
        finally:
            self._shadow_out = out
        return lit


def masked(bgra: np.ndarray, config: Any, mask: np.ndarray, rng: np.random.Generator) -> None:
    """A camera's noise mask over its image's BGRA pixels (M, 4), in place, shifted by two uniform
    draws of its stream (``rng``) per image, after the image's colour noise draws (Webots' order).
    The single and the batched camera (per copy) share it."""
    offset = rng.random(2)
    th, tw = mask.shape[1:]
    shading.apply_noise_mask(bgra, config.width, config.height, mask, (float(offset[0]), float(offset[1])),
                             shading.noise_mask_factor(config.width, config.height, tw, th))


class ShadowBuffers:
    """A camera's shadow rays kept between images: per shadow-casting light (in the order of
    :func:`shadow_rays`' lights), the chosen points' rows, unit segments, lengths and the segments'
    origins, each for up to ``rows`` points (the camera's rays), made again only when more rows or
    lights are asked for. An image of a 640 x 480 anti-aliased camera would otherwise map and fault
    in some 60 MB afresh per shadow-casting light. One call uses them at a time: what it returns
    are views into them, valid until the next call."""

    def __init__(self) -> None:
        self.rows = 0
        self._sets: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []

    def sized(self, rows: int, lights: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
        """The (index, unit, length, origin) buffers of ``lights`` lights, each for ``rows`` points."""
        if rows > self.rows:
            self.rows, self._sets = rows, []
        while len(self._sets) < lights:
            n = self.rows
            self._sets.append((np.empty(n, dtype=np.int64), np.empty((n, 3)), np.empty(n), np.empty((n, 3))))
        return self._sets[:lights]

    def origins(self, k: int, P: np.ndarray, i: np.ndarray) -> np.ndarray:
        """``P[i]`` (light ``k``'s chosen points) in that light's origin buffer when ``i`` fits it."""
        if k >= len(self._sets) or len(i) > self.rows:
            return shading.take_rows(P, i)
        return np.take(P, i, axis=0, out=self._sets[k][3][: len(i)], mode="clip")   # (valid rows: clip is a no-op)


def shadow_rays(P: np.ndarray, N: np.ndarray, lights: light_math.LightArrays, shadows: np.ndarray,
                threads: int, out: ShadowBuffers | None = None,
                rows: int = 0) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per shadow-casting light ``j``: the points (ascending indices into ``P``) whose direct term
    from it is above 0 (``light.light_terms``) and which lie within its radius
    (``shading.within_radius``), with their unit segments towards it and the segments' lengths
    (``light.occlusion_segments_many``), the bits ``light.direct_and_segments`` gives, made one light
    at a time from (S,) columns (``light.lit_segments``). Every value is elementwise, so it is worked
    out on row blocks of ``shading.BLOCK`` points (each block's columns stay in the CPU's cache) on
    up to ``threads`` threads: the same points and the same bits as one pass over all of them.
    ``out``: the blocks' parts are joined in its buffers (sized for ``rows`` points, at least
    ``len(P)``) instead of new arrays; the answers are then views into them."""
    js = shadows.nonzero()[0].tolist()
    S = len(P)
    parts = [slice(a, min(S, a + shading.BLOCK)) for a in range(0, S, shading.BLOCK)]
    # the shadow-casting lights only (each light's values are its own: the others change none of them)
    casting = lights if len(js) == len(lights) else lights.subset(js)

    n = len(casting)
    reach = [math.inf if int(casting.kind[j]) == light_math.LightKind.DIRECTIONAL else float(casting.radius[j])
             for j in range(n)]

    def part(sl: slice) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
        Pb, Nb = P[sl], N[sl]
        out = []
        for j in range(n):
            def near(i: np.ndarray, length: np.ndarray, j: int = j) -> np.ndarray | None:
                # beyond the light's radius: unlit anyway. within_radius measures each distance its own way
                # (radiance's), a few ulps from these: points far inside the radius need none of them
                if len(i) == 0 or length.max() < reach[j] * (1.0 - 1e-9):
                    return None
                return shading.within_radius(shading.take_rows(Pb, i), casting, j)

            i, unit, length = light_math.lit_segments(Pb, Nb, casting, j, None if reach[j] == math.inf else near)
            out.append((i + sl.start, unit, length))
        return out

    done = blocks.run(part, parts, threads) if js and S else []
    rays = {}
    kept = out.sized(max(rows, S), len(js)) if out is not None and len(done) > 1 else None
    for k, j in enumerate(js):
        got = [d[k] for d in done]
        if len(got) == 1:
            rays[j] = got[0]
        elif kept is not None:
            m = sum(len(g[0]) for g in got)
            idx, unit, length, _ = kept[k]
            rays[j] = (np.concatenate([g[0] for g in got], out=idx[:m]), np.concatenate([g[1] for g in got], out=unit[:m]),
                       np.concatenate([g[2] for g in got], out=length[:m]))
        elif got:
            rays[j] = (np.concatenate([g[0] for g in got]), np.concatenate([g[1] for g in got]),
                       np.concatenate([g[2] for g in got]))
        else:
            rays[j] = (np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros(0))
    return rays
