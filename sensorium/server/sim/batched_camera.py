"""Cameras (RGB images) in the batched simulation: every copy's due cameras rendered bit for bit as
the single simulation's Camera (sim/cameras.py, on the pure model devices/shading.py) renders them.

A camera's pixel rays go the range finder's way (batched_depth.py): the single device's rays
(``imaging.pixel_directions`` with its samples, ``clip_limits``), turned into each copy's world by
the same column sums from the same stacked ``Pose.compose``, cast as runs from one origin per
copy in a cast of their own (each camera's rays, every copy's; never joined to other rays: a
joined cast can move a FAST answer by a float32 step), meeting only their own copy's robots; a
camera housed in shapes of its own meets its robot's body once, in the body frame
(``OwnBodyRays``), as the single device does.

The shading is the single camera's, on every copy's rows at once: each step is elementwise
(``origin + t·D`` with the row's own copy's origin, the back-face flip, ``shading.radiance`` per
row, ``shading.fog``, the background, ``tone_map``), so concatenated rows give each row's bits.
Where the single device makes a call on its own image's rows that is not elementwise (a texture
lookup per textured shape, a body-frame normal turned by a 3x3 product, the 2x2 samples' mean),
it is made here per copy, on the same rows. Shadows (lights with ``castShadows``) are the single
camera's rays from each surface point towards each shadow-casting light, cast per copy and light
as the single camera casts them: a ray leaving a surface is told from a self-hit by thresholds
that depend on the cast's origins, so another copy's points must not share its cast. In a world
with semi-transparent surfaces each copy's image is composited as the single camera composites it
(``Camera._render``'s layers, from the copies' first cast): the rays going on past a surface are
cast for that copy alone, from its camera with per-ray limits. Noise: each (copy, camera) draws its
own stream (``device_rng(seed, "robot/camera")``), one standard normal per byte of RGB in C order,
as ``shading.to_bytes`` draws it. Motion blur and a noise mask (``_finish_copies``): each copy keeps
its own last mixed radiance and draws its mask's offsets from its own camera stream after its
image's noise, as the single camera does; such a camera's images are resolved copy by copy.

A textured robot body's texels are looked up per copy at that copy's pose of the shape
(batched_textures.py). Lights carried by robots (batched_lights.py) light only their own copy: in such a world each copy's
rows are shaded, and its shadow rays aimed, with that copy's light arrays (the fixed lights, then
its robots' at its poses: the single camera's arrays).

Recognition and segmentation are batched_recognition.py's (enabled per copy through the simulation,
never on the template). Changing the exposure or the field of view (a Zoom's setFov) is refused (the world file's are used).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.devices import imaging, shading
from sensorium.server.devices import light as light_math
from sensorium.server.raycast.engine import Precision, RayHits, RayKind
from sensorium.server.sim.batched_depth import PixelDevices, _Draws
from sensorium.server.sim.cameras import Camera, _shade, camera_lights, composite, masked, noise_mask_planes
from sensorium.server.sim.own_shapes import OwnBodyRays, cast_skipping
from sensorium.server.sim.scene import (
    _base_color,
    emissive_arrays,
    emissive_intensities,
    emissive_of,
    emissive_rows,
    emissive_scale,
    receives_shadows,
    scene_robot_parts,
    surface_colors,
    surface_opacity,
)

__all__ = ["KINDS", "CLASSES", "CameraDevices", "BatchedCamera", "own_body_hits"]

USE = "use Simulation"
PER_COPY = "BatchedSimulation.recognition_enable / enable_segmentation, or a copy's view"


class BatchedCamera(Camera):
    """A camera template of the batched simulation (its constants): what it does not measure
    there is refused, never silently kept on the template."""

    def recognition_enable(self, period_ms: int) -> None:
        raise ValueError(f"{self.path}: a batched camera's recognition is enabled per copy ({PER_COPY})")

    def enable_segmentation(self, on: bool) -> None:
        raise ValueError(f"{self.path}: a batched camera's segmentation is enabled per copy ({PER_COPY})")

    def set_exposure(self, exposure: float) -> None:
        raise ValueError(f"{self.path}: batched cameras keep the world file's exposure ({USE})")

    def set_fov(self, fov: float) -> None:
        raise ValueError(f"{self.path}: batched cameras keep the world file's field of view ({USE})")


KINDS = ("Camera",)
CLASSES: dict[str, type] = {"Camera": BatchedCamera}


class _CopyEngine:
    """One copy's world as a ray engine's ``cast`` (what ``cast_skipping`` calls): the copies' cast
    with that copy's rays alone."""

    def __init__(self, sim: Any, copy: int):
        self.sim, self.copy = sim, copy

    def cast(self, origins, directions, t_near=0.0, t_far=np.inf, kind=RayKind.VISUAL, exclude_owner=-1,
             directions32=None) -> RayHits:
        sim = self.sim
        copy = np.full(len(directions), self.copy, dtype=np.int64)
        return sim.rays.cast(origins, directions, t_near, t_far, kind, copy, sim.rot, sim.pos, exclude_owner, -1,
                             False, directions32=directions32)


def _rows_of(hits: RayHits, a: int, b: int) -> RayHits:
    assert hits.shape is not None and hits.normal is not None
    return RayHits(hits.distance[a:b], hits.normal[a:b], hits.shape[a:b])


class _Device:
    """One camera's constants, made once (the single Camera._prepare's calls)."""

    def __init__(self, template: BatchedCamera):
        self.template = template
        c = template.config
        self.height, self.width = int(c.height), int(c.width)
        self.samples = len(template._samples)
        dirs = imaging.pixel_directions(template.geometry, template._samples, template.lens)
        self.dirs = np.ascontiguousarray(dirs.reshape(-1, 3))
        self.n = len(self.dirs)                      # rays per image: samples x pixels
        self.columns = tuple(np.ascontiguousarray(self.dirs[:, k]) for k in range(3))
        factors = imaging.depth_factors(template.geometry, dirs)
        self.limits = imaging.clip_limits(template.geometry, factors, c.near, c.far if c.far > 0 else math.inf)
        self.exposure = float(c.exposure)
        self.own: OwnBodyRays | None = None
        self.skip: np.ndarray | int | None = None
        self.plan: tuple | None = None
        self.mask: np.ndarray | None = None          # the noise mask's planes (cameras.noise_mask_planes)
        self.blurred: np.ndarray | None = None       # motion blur: each copy's last mixed radiance (C, M, 3)
        self.started = np.zeros(0, dtype=bool)       # ... and whether it has made its first image


def own_body_hits(pixels: PixelDevices, col: int, copies: np.ndarray, h: RayHits) -> RayHits:
    """A housed device's hits (``pixels.devices[col]``, the copies' cast): the nearer of the world cast
    and its robot's body or link (OwnBodyRays.cast, per copy: the body-frame normal turned by that
    copy's robot rotation, on a link by its displacement's too, on the same rows)."""
    dev = pixels.devices[col]
    if dev.own is None:
        return h
    sim = pixels.sim
    b = dev.own.body_hits(sim.rays.movers)
    assert b.shape is not None and b.normal is not None and h.shape is not None and h.normal is not None
    dist, shape, normal = h.distance.copy(), h.shape.copy(), h.normal.copy()
    offset = sim.rays.shape_offset
    slot = dev.template.robot_index
    for k, cc in enumerate(copies.tolist()):
        a = k * dev.n
        win = (b.distance < dist[a:a + dev.n]).nonzero()[0]
        if not len(win):
            continue
        dist[a + win] = b.distance[win]
        shape[a + win] = offset + b.shape[win]
        carrier = sim.rot[cc, slot]          # (on a link: robot ∘ that copy's link, Device.carrier_rotation)
        if dev.own_joint >= 0:
            carrier = carrier @ sim.joints.link_rot[cc, dev.own_joint]
        normal[a + win] = b.normal[win] @ carrier.T          # body frame -> world
    return RayHits(dist, normal, shape)


class CameraDevices(PixelDevices):
    """The batched simulation's cameras: constants per device, BGRA images per copy."""

    kind = "Camera"

    def __init__(self, sim: Any, devices: list[BatchedCamera]):
        super().__init__(sim, [_Device(d) for d in devices])
        self.images = [np.zeros((sim.copies, d.height, d.width, 4), dtype=np.uint8) for d in self.devices]
        for d in self.devices:      # the effects carried from image to image: each copy's own (_finish_copies)
            cfg = d.template.config
            d.mask = noise_mask_planes(sim.scene, cfg.noise_mask_url)
            if cfg.motion_blur > 0:
                d.blurred = np.zeros((sim.copies, d.height * d.width, 3))
                d.started = np.zeros(sim.copies, dtype=bool)
        for img in self.images:
            img[..., 3] = 255
        scene = sim.scene
        # the lights that are on and which cast shadows: static, shared by all copies; with lights carried by
        # robots, each copy's own (_lights_of), fixed then carried as the single camera lists them
        self.lights, self.shadows = camera_lights(scene.world_lights()) if devices else (None, np.zeros(0, dtype=bool))
        self._fixed_shadows = self.shadows
        if devices and sim.carried is not None:
            self.shadows = sim.carried.cast_shadows     # every light a copy may have (LEDs' ones all on)
        # per hit shape (static shapes, then the robots' as CopyRays numbers them; -1 reads the last): the
        # base colour a camera sees (a textured shape's texels come on top: _albedo) and the
        # transparency
        models = [scene.part(i)[2] for i in range(sim.n_static_shapes)]
        models += [shape for r in sim.world.robots for _, _, shape in scene_robot_parts(r)]
        self.colors = np.array([_base_color(m) for m in models] + [(1.0, 1.0, 1.0)], dtype=np.float64).reshape(-1, 3)
        self.transparency = np.array([m.appearance.transparency if m.appearance is not None else 0.0
                                      for m in models] + [0.0])
        self.emissive, self.emissive_texel = emissive_arrays([emissive_of(m) for m in models], models)
        self.emissive_intensity = None if self.emissive is None else emissive_intensities(models)
        self.clear = bool((self.transparency > 0.0).any())     # semi-transparent surfaces: layers per copy

    def _shadow_volumes(self, copies: np.ndarray) -> np.ndarray:
        """Per copy whether a light that is on casts shadows (WREN then draws opaque shapes with its
        shadow-volume shaders, which leave emissiveIntensity out): an LED's lights count in the copies
        where it is on."""
        carried = self.sim.carried
        if carried is None:
            return np.full(len(copies), bool(self.shadows.any()))
        return np.array([bool(carried.shadows(int(c), self._fixed_shadows).any()) for c in copies], dtype=bool)

    def _lights_of(self, copy: int) -> light_math.LightArrays:
        """The lights copy ``copy`` (a copy of the simulation) shades with: its robots' at its poses."""
        sim = self.sim
        if sim.carried is None:
            assert self.lights is not None
            return self.lights
        return sim.carried.arrays(sim.rot, sim.pos, copy)

    def reset(self, idx: np.ndarray) -> None:
        """Black (alpha 255) before the first image (Webots), as a freshly built device."""
        for img in self.images:
            img[idx] = 0
            img[idx, :, :, 3] = 255
        for d in self.devices:
            if d.blurred is not None:      # the next image is the first again: itself
                d.blurred[idx] = 0.0
                d.started[idx] = False

    # -- planning: each due camera's rays of every copy, cast in finish
    def plan(self, copies: np.ndarray, cols: np.ndarray) -> tuple[dict, list]:
        items = []
        for col in sorted(set(cols.tolist())):
            c = copies[cols == col]
            items.append((col, c, *self._beams(col, c)))
        return {"items": items}, []

    # -- finishing: cast, shade, the images
    def finish(self, state: dict, hits: list[RayHits]) -> None:
        sim = self.sim
        for col, c, org, origins, d, d32 in state["items"]:
            dev = self.devices[col]
            ray_copy, mount, t_near, t_far = self._rows(col, c)
            h = sim.rays.cast(origins, d, t_near, t_far, RayKind.VISUAL, ray_copy, sim.rot, sim.pos, -1, mount, False,
                              False, d32, True, origin_rows=org, run=dev.n)
            sim.counters["measurements"] += len(c)
            self._image(col, c, org, d, self._with_own_body(col, c, h))
            sim.last["Camera"][c, col] = sim.time_ms[c]

    def _with_own_body(self, col: int, copies: np.ndarray, h: RayHits) -> RayHits:
        return own_body_hits(self, col, copies, h)

    def _albedo(self, shape: np.ndarray, org: np.ndarray, row_copy: np.ndarray, D: np.ndarray,
                t: np.ndarray, copies: np.ndarray, glow: np.ndarray | None = None) -> np.ndarray:
        """``Scene.surface_colors`` of hits of every copy: base colours by shape; a textured shape's
        texels per copy (a solid's, or a robot body's at that copy's pose: batched_textures.py), on the
        rows the single camera would pass (its image's hits). ``glow``: the hits' emissive rows, a
        Phong shape's multiplied in place by its texture's colour (``surface_colors``' ``glow``)."""
        col = np.take(self.colors, shape, axis=0)
        sim = self.sim
        scene = sim.scene
        sampler = scene.textures
        if sampler is None:
            return col
        texel = self.emissive_texel if glow is not None else None
        robots = sim.robot_textures
        textured = np.zeros(len(shape), dtype=bool)
        flags = sampler.textured if texel is None or not sampler.has_emissive_map else \
            sampler.textured | sampler.emissive_mapped         # (an emissive map is read on those rows too)
        if robots is not None:        # the sampler numbers every shape, robots' included
            textured = flags[shape]
        else:
            static = shape < sim.n_static_shapes
            textured[static] = flags[shape[static]]
        rows = textured.nonzero()[0]
        of = row_copy[rows]                  # nondecreasing: the hits come copy after copy
        cuts = np.flatnonzero(of[1:] != of[:-1]) + 1
        for rq in np.split(rows, cuts) if len(rows) else ():
            q = int(row_copy[rq[0]])
            o = np.broadcast_to(org[q], (len(rq), 3))
            g = None if texel is None else (glow[rq], texel)     # type: ignore[index]
            if robots is None:
                col[rq] = scene.surface_colors(shape[rq], o, D[rq], t[rq], g)
            else:
                col[rq] = surface_colors(self.colors, sampler, robots.world_to_shape(int(copies[q])), shape[rq], o,
                                         D[rq], t[rq], g)
            if g is not None:
                glow[rq] = g[0]          # type: ignore[index]
        return col

    def _shadows(self, P: np.ndarray, N: np.ndarray, row_copy: np.ndarray, copies: np.ndarray) -> np.ndarray:
        """Camera._shadows of each copy's hits, copy by copy (its rows, in order): (rows, lights) False
        where a shadow-casting light is hidden from the point by a visible shape of that copy (its
        segment to the light, 1000 m towards a directional one); only lit, facing pairs cast. Each
        copy's shadow rays of a light are a cast of their own, as the single camera's: rays leaving a
        surface are judged against self-hits with thresholds that depend on the cast's origins."""
        sim = self.sim
        lit = np.ones((len(P), len(self.shadows)), dtype=bool)
        cuts = np.flatnonzero(row_copy[1:] != row_copy[:-1]) + 1
        for rq in np.split(np.arange(len(P)), cuts) if len(P) else ():
            q = int(copies[row_copy[rq[0]]])
            lights = self._lights_of(q)
            Pq, Nq = P[rq], N[rq]
            # the copy's own lights (with LEDs' lights: those on in it) are the first columns
            casting = self.shadows if sim.carried is None else sim.carried.shadows(q, self._fixed_shadows)
            for j in casting.nonzero()[0].tolist():
                # the facing points and their segments of this light only (light_terms' and
                # occlusion_segments_many's values); beyond the light's radius: unlit anyway
                def near(i: np.ndarray, _: np.ndarray, Pq: np.ndarray = Pq, lights=lights, j: int = j) -> np.ndarray | None:
                    return shading.within_radius(Pq[i], lights, j)

                i, unit, length = light_math.lit_segments(Pq, Nq, lights, j, near)
                if len(i) == 0:
                    continue
                h = sim.rays.cast(Pq[i], unit, 0.0, length, RayKind.SHADOW, np.full(len(i), q, dtype=np.int64),
                                  sim.rot, sim.pos, -1, -1, False, distance_only=True)
                lit[rq[i], j] = ~(h.distance <= length)
        return lit

    def _image(self, col: int, copies: np.ndarray, org: np.ndarray, dirs: np.ndarray, hits: RayHits) -> None:
        """Camera._capture_image of each copy's rays (``hits``: the copies' cast, copy after copy)."""
        dev = self.devices[col]
        k = len(copies)
        alpha = self._alpha_shapes()
        if self.clear or alpha is not None:     # semi-transparent surfaces or texels: each copy's layers
            out = np.concatenate([self._layers(col, copies[q:q + 1], org[q], dirs[q * dev.n:(q + 1) * dev.n],
                                               _rows_of(hits, q * dev.n, (q + 1) * dev.n), alpha) for q in range(k)])
        else:
            out = self._opaque(col, copies, org, dirs, hits)
        self._finish_image(col, copies, out)

    def _opaque(self, col: int, copies: np.ndarray, org: np.ndarray, dirs: np.ndarray, hits: RayHits) -> np.ndarray:
        """The radiance of every copy's rays in a world without semi-transparent surfaces: the first
        layer of Camera._render, rows of all copies at once."""
        dev = self.devices[col]
        scene = self.sim.scene
        n = len(dirs)
        out = np.zeros((n, 3))
        weight = np.ones(n)
        t, shape, normal = hits.distance, hits.shape, hits.normal
        assert shape is not None and normal is not None
        hit = np.isfinite(t)
        miss = (~hit).nonzero()[0]
        if len(miss):
            shading.add_to_rows(out, miss, shading.scaled_rows(weight[miss], scene.background))
        kk = hit.nonzero()[0]
        if len(kk):
            row_copy = kk // dev.n                     # each hit's copy (its index in ``copies``)
            Dk = shading.take_rows(dirs, kk)
            tk = t.take(kk)
            P = np.empty((len(kk), 3))                 # origin + t D, column by column
            for ch in range(3):
                np.multiply(tk, Dk[:, ch], out=P[:, ch])
                P[:, ch] += org[row_copy, ch]
            N = shading.take_rows(normal, kk)
            back = (N[:, 0] * Dk[:, 0] + N[:, 1] * Dk[:, 1] + N[:, 2] * Dk[:, 2]) > 0.0
            if back.any():                             # facing the camera
                bk = back.nonzero()[0]
                N[bk] = np.negative(shading.take_rows(N, bk))
            s = shape.take(kk)
            glow = emissive_rows(self.emissive, s)
            albedo = self._albedo(s, org, row_copy, Dk, tk, copies, glow)
            if glow is not None and self.emissive_intensity is not None:
                emissive_scale(glow, self.emissive_intensity, ~receives_shadows(self.transparency,
                               self._translucent_shapes(), s), s, self._shadow_volumes(copies)[row_copy])
            lit = None
            if self.shadows.any():
                translucent = self._translucent_shapes()
                if translucent is None:
                    lit = self._shadows(P, N, row_copy, copies)
                else:              # shadows fall on opaque surfaces only, as in _layers
                    lit = np.ones((len(kk), len(self.shadows)), dtype=bool)
                    on = (~translucent[s]).nonzero()[0]
                    lit[on] = self._shadows(P[on], N[on], row_copy[on], copies)
            L = self._shade_copies(P, N, albedo, lit, row_copy, copies)
            if glow is not None:                   # as Camera's surface
                L += glow
            if scene.fog is not None:
                L = shading.fog(L, tk, *scene.fog)
            share = weight[kk] * (1.0 - np.zeros(len(kk)))   # (opaque: transparency 0, as the single's share)
            for ch in range(3):
                L[:, ch] *= share
            shading.add_to_rows(out, kk, L)
        return out

    def _shade_copies(self, P: np.ndarray, N: np.ndarray, albedo: np.ndarray, lit: np.ndarray | None,
                      row_copy: np.ndarray, copies: np.ndarray) -> np.ndarray:
        """``_shade`` of every copy's rows: all at once under shared lights; copy by copy (its rows, each
        shaded alone: every row's value is the one a single call gives) under its robots' lights."""
        threads = self.sim.scene.engine.threads
        if self.sim.carried is None:
            assert self.lights is not None
            return _shade(P, N, albedo, self.lights, lit, threads)
        out = np.empty((len(P), 3))
        cuts = np.flatnonzero(row_copy[1:] != row_copy[:-1]) + 1
        for rq in np.split(np.arange(len(P)), cuts) if len(P) else ():
            lights = self._lights_of(int(copies[row_copy[rq[0]]]))
            out[rq] = _shade(P[rq], N[rq], albedo[rq], lights, None if lit is None else lit[rq, :lights.count],
                             threads)
        return out

    def _alpha_shapes(self) -> np.ndarray | None:
        """Per hit shape (static shapes, then the robots'; −1 last): whether its image has
        transparent texels (``Scene.alpha_shapes`` over this scene's sampler); None without any."""
        sampler = self.sim.scene.textures
        if sampler is None or not sampler.has_alpha:
            return None
        return self._per_hit_shape(sampler.alpha)

    def _translucent_shapes(self) -> np.ndarray | None:
        """Per hit shape, as :meth:`_alpha_shapes`: whether its image's pixel format has alpha, even
        255 everywhere (``Scene.translucent_shapes``: no shadow falls on it); None without any."""
        sampler = self.sim.scene.textures
        if sampler is None or not sampler.has_translucent:
            return None
        return self._per_hit_shape(sampler.translucent)

    def _per_hit_shape(self, of_sampler: np.ndarray) -> np.ndarray:
        flags = np.zeros(len(self.colors), dtype=bool)
        m = min(len(of_sampler), len(flags)) - 1          # the sampler numbers the robots' shapes when textured
        flags[:m] = of_sampler[:m]
        return flags

    def _layers(self, col: int, copy: np.ndarray, origin: np.ndarray, dirs: np.ndarray, hits: RayHits,
                alpha_shapes: np.ndarray | None = None) -> np.ndarray:
        """Camera._render of one copy's rays (``hits``: its first layer, from the copies' cast): the
        single camera's :func:`composite`, its rays going on past semi-transparent surfaces (and
        see-through texels: ``alpha_shapes``, their alpha read at this copy's poses) cast for this
        copy alone (as the single camera casts them, from its origin with per-ray limits), blind to
        the camera's own shapes."""
        sim = self.sim
        scene = sim.scene
        dev = self.devices[col]
        engine = _CopyEngine(sim, int(copy[0]))
        own = frozenset(sim.rays.shape_offset + i for i in dev.template.own_shapes)
        translucent = self._translucent_shapes()

        def cast_on(D: np.ndarray, tn: np.ndarray, tf: np.ndarray) -> RayHits:
            O = np.broadcast_to(origin, D.shape)
            if own:
                return cast_skipping(engine, O, D, tn, tf, own)
            return engine.cast(O, D, tn, tf, kind=RayKind.VISUAL, exclude_owner=-1)

        def surface(s: np.ndarray, P: np.ndarray, N: np.ndarray, D: np.ndarray, t: np.ndarray) -> np.ndarray:
            zeros = np.zeros(len(s), dtype=np.int64)
            glow = emissive_rows(self.emissive, s)
            albedo = self._albedo(s, origin[None, :], zeros, D, t, copy, glow)
            if glow is not None and self.emissive_intensity is not None:
                emissive_scale(glow, self.emissive_intensity, ~receives_shadows(self.transparency, translucent, s), s,
                               bool(self._shadow_volumes(copy[:1])[0]))
            lit = None
            if self.shadows.any():    # on opaque surfaces only, as Camera's surface
                lit = np.ones((len(s), len(self.shadows)), dtype=bool)
                on = receives_shadows(self.transparency, translucent, s).nonzero()[0]   # (this camera's numbering)
                lit[on] = self._shadows(P[on], N[on], zeros[on], copy)
            lights = self._lights_of(int(copy[0]))
            L = _shade(P, N, albedo, lights, None if lit is None else lit[:, :lights.count], scene.engine.threads)
            if glow is not None:                   # as Camera's surface
                L += glow
            return L

        alpha = None
        if alpha_shapes is not None:
            robots = sim.robot_textures
            to_shape = scene._world_to_shape if robots is None else robots.world_to_shape(int(copy[0]))

            def opacity(s: np.ndarray, D: np.ndarray, t: np.ndarray) -> np.ndarray:
                return surface_opacity(scene.textures, to_shape, s, np.broadcast_to(origin, (len(s), 3)), D, t)

            alpha = (alpha_shapes, opacity)
        return composite(origin, dirs, hits, dev.limits, cast_on, self.transparency, scene.background, scene.fog,
                         surface, alpha, float32=scene.engine.precision is Precision.FAST)

    def _finish_image(self, col: int, copies: np.ndarray, out: np.ndarray) -> None:
        """Camera._capture_image from the radiance of every copy's rays: the samples' mean, the
        resolve, the noise, BGRA bytes."""
        sim = self.sim
        dev = self.devices[col]
        cfg = dev.template.config
        k = len(copies)
        S = dev.samples
        if S > 1:     # supersampling, per copy as the single camera averages its image's rays
            per = out.reshape(k, S * dev.height * dev.width, 3)
            out = np.concatenate([per[q].reshape(S, -1, 3).mean(axis=0) for q in range(k)])
        if dev.blurred is not None or dev.mask is not None:
            self._finish_copies(col, copies, out)
            return
        rng = None
        if cfg.noise > 0:
            rng = _Draws(sim.noise, copies.tolist(), sim._noise_col[("Camera", col)], [dev.height * dev.width * 3] * k)
        bgra = shading.resolve_bgra(out, dev.exposure, cfg.noise, rng)      # type: ignore[arg-type]
        self.images[col][copies] = bgra.reshape(k, dev.height, dev.width, 4)

    def _finish_copies(self, col: int, copies: np.ndarray, out: np.ndarray) -> None:
        """The resolve of a camera with motion blur or a noise mask, copy by copy as the single
        camera makes its image: its own last mixed radiance and the weight of its own sampling
        period, then its colour noise and its mask's two uniform offsets from its own stream, in
        that order (the stream taken whole: ``NoiseStreams.stream``, nothing drawn ahead)."""
        sim = self.sim
        dev = self.devices[col]
        cfg = dev.template.config
        M = dev.height * dev.width
        column = sim._noise_col.get(("Camera", col), -1)
        for q, cc in enumerate(copies.tolist()):
            stream = sim.noise.stream(cc, column) if dev.mask is not None else None
            rng = _Draws(sim.noise, [cc], column, [M * 3]) if cfg.noise > 0 else None
            blur = None
            if dev.blurred is not None:     # the first image: itself (Camera._capture_image)
                w = shading.motion_blur_weight(int(sim.period["Camera"][cc, col]), cfg.motion_blur) \
                    if dev.started[cc] else 0.0
                dev.started[cc] = True
                blur = (dev.blurred[cc], w)
            bgra = shading.resolve_bgra(out[q * M:(q + 1) * M], dev.exposure, cfg.noise, rng, 1,  # type: ignore[arg-type]
                                        blur)
            if dev.mask is not None:
                assert stream is not None
                masked(bgra, cfg, dev.mask, stream)
            self.images[col][cc] = bgra.reshape(dev.height, dev.width, 4)
