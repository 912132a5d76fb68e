"""RangeFinders (depth images) in the batched simulation: every copy's due range finders cast in the
step's one cast per ray kind, bit for bit the images the single simulation's RangeFinder
(sim/cameras.py, on the pure model devices/imaging.py) captures.

A range finder is, for the ray engine, a fixed lidar with one ray per pixel, so it goes the batched
lidar's way (``BatchedSimulation._plan_lidars``):

* the pixel rays are the single device's (``imaging.pixel_directions``, ``depth_factors``,
  ``clip_limits`` -- the same calls, once per device), turned into each copy's world by the same
  column sums (``packets.lidar_beams``, or the numpy sums the single ``MountedRays.at`` does) from
  the same stacked ``Pose.compose``;
* they go out as runs from one origin per copy, traced as coherent packets as the single device's
  one-origin cast is, and meet only their own copy's robots. Each device's rays (every copy's) are
  a cast of their own, not joined to the step's other rays of their kind: a joined cast has one
  form of ``t_near`` for all its rays (per ray when they differ), and FAST starts a ray's float32
  traversal at ``t_near`` by a per-ray or a scalar sum that differ in the last bit. A device sees its own robot, except
  where a pixel can never reach it (decided once: ``CopyRays.may_reach``, then each of the robot's
  shapes' boxes, :func:`may_meet_parts`), and a device with shapes
  of its own (``of_device``) meets its robot's body once, in the body frame, blind to those shapes
  (``OwnBodyRays.body_hits`` on the movers' engine, as the single device does on its scene's);
* ``imaging.range_values`` makes every copy's image in one call: its per-pixel steps (a product,
  comparisons, an addition of the noise, the resolution's ``floor(v/res + 1/2)·res``) are exactly
  rounded elementwise, whatever the batch;
* noise: each (copy, device) draws from its own stream (``device_rng(seed, "robot/device")``), one
  standard normal per valid pixel, in the image's order, as the single device does; a copy's block
  is taken from the bank's buffer and then straight from the stream (:func:`draw`), the same
  numbers in the same order whatever the block sizes;
* motion blur: each copy keeps its own last blurred values (``+inf`` before its first image and
  after a reset) and mixes at the weight of its own sampling period, in the same ``range_values``
  call (the mix is elementwise too).

What range finders and cameras (batched_camera.py) share -- the pixel rays of every capturing copy,
their rows and the mount -- is :class:`PixelDevices`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.devices import imaging, shading
from sensorium.server.raycast import packets
from sensorium.server.raycast.engine import RayHits, RayKind
from sensorium.server.sim.cameras import RangeFinder
from sensorium.server.sim.own_shapes import OwnBodyRays
from sensorium.server.sim.scene import primitive_from_model, robot_parts
from sensorium.server.world.geometry import tessellate

__all__ = ["KINDS", "CLASSES", "DepthDevices", "PixelDevices", "draw", "may_meet_parts"]

KINDS = ("RangeFinder",)
CLASSES: dict[str, type] = {"RangeFinder": RangeFinder}


def draw(bank: Any, copy: int, column: int, count: int) -> np.ndarray:
    """``count`` standard normals of one (copy, device) stream of a ``NoiseStreams`` bank, in order:
    what is left of its buffered block, then the rest in one draw from the stream itself (an
    image's thousands of numbers without a refill per block). The buffer is left empty, so the
    next draw, of any size, continues the stream where this one stopped."""
    parts = []
    need = int(count)
    while need > 0:
        a = int(bank.cursor[copy, column])
        if a < bank.block:                       # the buffered numbers come first
            m = min(bank.block - a, need)
            parts.append(bank.buffer[copy, column, a:a + m].copy())
            bank.cursor[copy, column] = a + m
            need -= m
            continue
        rng = bank.rngs[copy][column]
        if rng is None:                          # the stream's first draw since a reseed: created with a block
            bank._refill(copy, column)
            continue
        parts.append(rng.standard_normal(need))
        need = 0
    return np.concatenate(parts) if parts else np.zeros(0)


def _tiled(limit: np.ndarray | float, copies: int) -> np.ndarray | float:
    """A per-pixel limit repeated for each copy's image (one value for every ray stays one)."""
    return np.tile(limit, copies) if isinstance(limit, np.ndarray) else limit


class _Draws:
    """The noise of several copies' images of one device as ``range_values`` draws it in one call:
    copy after copy, each its own stream's next ``counts[k]`` numbers."""

    def __init__(self, bank: Any, copies: list[int], column: int, counts: list[int]):
        self.bank, self.copies, self.column, self.counts = bank, copies, column, counts

    def standard_normal(self, count: int) -> np.ndarray:
        if int(count) != sum(self.counts):
            raise AssertionError(f"range finder noise: {count} draws asked, {sum(self.counts)} valid pixels counted")
        return np.concatenate([draw(self.bank, c, self.column, n) for c, n in zip(self.copies, self.counts)])


class _Device:
    """One range finder's constants, made once (the single RangeFinder._prepare's calls)."""

    def __init__(self, template: RangeFinder):
        self.template = template
        c = template.config
        self.height, self.width = int(c.height), int(c.width)
        self.n = self.height * self.width
        dirs = imaging.pixel_directions(template.geometry, lens=template.lens)[0]
        self.dirs = np.ascontiguousarray(dirs.reshape(-1, 3))
        self.columns = tuple(np.ascontiguousarray(self.dirs[:, k]) for k in range(3))
        self.factors = imaging.depth_factors(template.geometry, dirs, template.lens)
        self.limits = imaging.clip_limits(template.geometry, self.factors, c.near, c.max_range)
        self.own: OwnBodyRays | None = None
        self.own_joint = -1                              # a housed device's link's joint column (-1: its robot's body)
        self.skip: np.ndarray | int | None = None       # per pixel: the mount slot where it never meets its robot
        self.plan: tuple | None = None                   # (copies, each ray's copy, mount, t_near, t_far) kept


def may_meet_parts(robot: wm.Robot, base_dir: Any, origins: np.ndarray, directions: np.ndarray, t_near, t_far,
                    margin: float = 1e-6) -> np.ndarray:
    """Which rays, given in the robot's body frame, may meet one of its shapes: the box of each
    shape's tessellation (curved ones circumscribed: it holds the analytic surface) grown by
    ``margin``, as ``CopyRays.may_reach`` tests the whole body's box (conservative for the same rays
    moved into the frame from any pose). A camera sits inside its robot's box, rarely inside one
    of its shapes' boxes: most of its pixel rays can then skip their robot in every copy's cast
    (a pixel ray that may meet none of them has the same answer without its robot)."""
    O = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    D = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    lo_t = np.broadcast_to(np.asarray(t_near, dtype=np.float64), (len(D),)) - margin
    hi_t = np.broadcast_to(np.asarray(t_far, dtype=np.float64), (len(D),)) + margin
    out = np.zeros(len(D), dtype=bool)
    with np.errstate(divide="ignore", invalid="ignore"):
        Dn = np.where(D == 0.0, 1e-300, D)
        for _, local, shape in robot_parts(robot):
            try:
                v = tessellate(primitive_from_model(shape.geometry, base_dir))[0]
            except ValueError:             # a plane: unbounded
                return np.ones(len(D), dtype=bool)
            w = local.apply(v)
            ta, tb = (w.min(axis=0) - margin - O) / Dn, (w.max(axis=0) + margin - O) / Dn
            t0 = np.maximum(np.minimum(ta, tb).max(axis=1), lo_t)
            t1 = np.minimum(np.maximum(ta, tb).min(axis=1), hi_t)
            out |= t0 <= t1
    return out


class PixelDevices:
    """What the batched range finders and cameras share: each device's pixel rays turned into every
    capturing copy's world (the single device's ``Pose.compose`` and column sums, stacked), the rays'
    copies, mount and limits kept while the same copies capture, and the mount decided once. A
    device's constants (``devices[col]``) have ``template``, ``n`` (rays per image), ``dirs``,
    ``columns``, ``limits`` and the kept ``own``, ``skip``, ``plan``."""

    kind = "RangeFinder"     # the devices' kind: a device riding a joint is (kind, column) in sim.joints

    def __init__(self, sim: Any, devices: list):
        self.sim = sim
        self.devices = devices
        self._buffers: dict[int, tuple] = {}

    def _beams(self, col: int, copies: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(each copy's device origin, the rays' origins, directions, float32 directions)."""
        from sensorium.server.sim.batched import _lidar_beams  # (batched.py imports this module)

        sim = self.sim
        dev = self.devices[col]
        slot = dev.template.robot_index
        rr = sim.rot[copies, slot]
        rider = (self.kind, col)
        if rider in sim.joints.riders:        # on a joint: each copy's local pose (batched_joints.py)
            rot = np.matmul(rr, sim.joints.local_rot[rider][copies])
            org = np.matmul(rr, sim.joints.local_pos[rider][copies][:, :, None])[:, :, 0] + sim.pos[copies, slot]
        else:
            local = dev.template.local_pose
            rot = np.matmul(rr, local.rotation)                              # Pose.compose, stacked
            org = np.matmul(rr, local.translation[None, :, None])[:, :, 0] + sim.pos[copies, slot]
        got = packets.lidar_beams(rot, org, dev.columns, self._beam_buffers(col, len(copies) * dev.n))
        origins, d, d32 = got if got is not None else _lidar_beams(rot, org, dev.columns)
        return org, origins, d, d32

    def _beam_buffers(self, col: int, rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        got = self._buffers.get(col)
        if got is None or len(got[0]) != rows:
            got = self._buffers[col] = (np.empty((rows, 3)), np.empty((rows, 3)), np.empty((rows, 3), dtype=np.float32))
        return got

    def _rows(self, col: int, copies: np.ndarray) -> tuple:
        """Per ray of the images of ``copies``: its copy, its mount slot (scalar when all alike) and
        its limits; kept while the same copies capture."""
        dev = self.devices[col]
        if dev.plan is not None and np.array_equal(dev.plan[0], copies):
            return dev.plan[1:]
        k = len(copies)
        mount = self._mount(col)
        if isinstance(mount, np.ndarray):
            mount = np.tile(mount, k)
        t_near, t_far = dev.limits
        dev.plan = (copies.copy(), np.repeat(copies, dev.n), mount, _tiled(t_near, k), _tiled(t_far, k))
        return dev.plan[1:]

    def _mount(self, col: int) -> np.ndarray | int:
        """The slot a device's pixel rays are never paired with in the world cast: its robot's, for
        a device with shapes of its own (that body is met apart, in the body frame: ``own``), else per
        pixel its robot's where the ray can never meet that body, -1 where it may (it sees its robot).
        A device riding a joint turns in the body frame: every ray may meet its robot (on a link
        without shapes the single device is mounted on no body; on one with shapes its rays ride
        that link, meeting it through the world's frame as any ray does: ``Riding``), and one with
        shapes of its own on a link with shapes meets that link apart, as ``own``."""
        dev = self.devices[col]
        rider = self.sim.joints.riders.get((self.kind, col))
        if dev.skip is None and rider is not None:
            tpl = dev.template
            link = self.sim.link_bodies.get((rider[0], rider[1]))
            if tpl.own_shapes and link is not None:   # (its mount: its pose in the link's frame)
                dev.own = OwnBodyRays(link, tpl.mount_pose, dev.dirs, *dev.limits, tpl.own_shapes)
                dev.own_joint = self.sim.joints.of(rider[0], rider[1])
                dev.skip = self.sim.slot_of_body(link)
            else:
                dev.skip = -1
        if dev.skip is None:
            tpl = dev.template
            slot = tpl.robot_index
            body = self.sim.rays.slot_body[slot]
            if tpl.own_shapes and body is not None:
                dev.own = OwnBodyRays(body, tpl.local_pose, dev.dirs, *dev.limits, tpl.own_shapes)
                dev.skip = slot
            else:
                local = tpl.local_pose
                d = dev.dirs @ local.rotation.T
                o = np.broadcast_to(local.translation, d.shape)
                reach = self.sim.rays.may_reach(slot, RayKind.VISUAL, o, d, *dev.limits)
                if reach.any():     # a device inside its robot's box: which rays may meet one of its shapes
                    reach &= may_meet_parts(self.sim.world.robots[slot], self.sim.loaded.base_dir, o, d, *dev.limits)
                skip = np.where(reach, -1, slot).astype(np.int64)
                dev.skip = int(skip[0]) if (skip == skip[0]).all() else skip
        return dev.skip


class DepthDevices(PixelDevices):
    """The batched simulation's range finders: constants per device, images per copy."""

    def __init__(self, sim: Any, devices: list[RangeFinder]):
        super().__init__(sim, [_Device(d) for d in devices])
        self.images = [np.zeros((sim.copies, d.height, d.width), dtype=np.float32) for d in self.devices]
        # motion blur: each copy's last blurred values (+inf before its first image), as the single device's
        self.blurred = [np.full((sim.copies, d.height, d.width), np.inf) if d.template.config.motion_blur > 0 else None
                        for d in self.devices]

    def reset(self, idx: np.ndarray) -> None:
        """Zeros before the first image (Webots), as a freshly built device."""
        for img in self.images:
            img[idx] = 0.0
        for b in self.blurred:
            if b is not None:
                b[idx] = np.inf

    # -- planning: every copy's pixel rays of each due device
    def plan(self, copies: np.ndarray, cols: np.ndarray) -> tuple[dict, list]:
        """(state, no joined requests): each device's rays of every copy, cast by :meth:`finish`
        in a cast of their own (see the module docstring)."""
        from sensorium.server.sim.batched import _Rays  # (batched.py imports this module)

        state: dict = {"items": []}
        for col in sorted(set(cols.tolist())):
            dev = self.devices[col]
            c = copies[cols == col]
            org, origins, d, d32 = self._beams(col, c)
            ray_copy, mount, t_near, t_far = self._rows(col, c)
            state["items"].append((col, c, _Rays(origins, d, t_near, t_far, RayKind.VISUAL, ray_copy, -1, mount,
                                                 distance_only=True, d32=d32, coherent=True, origin_rows=org,
                                                 run=dev.n)))
        return state, []

    def _own_distances(self, col: int) -> np.ndarray | None:
        """Each pixel's distance to its robot's body other than the device's own shapes (a device
        with own shapes), in the body frame, kept per precision (OwnBodyRays.body_hits)."""
        own = self.devices[col].own
        return None if own is None else own.body_hits(self.sim.rays.movers).distance

    # -- finishing: the images from the hits
    def finish(self, state: dict, hits: list[RayHits]) -> None:
        """Cast each device's rays and make its images (``hits``: none, see :meth:`plan`)."""
        sim = self.sim
        for col, c, r in state["items"]:
            h = sim.rays.cast(r.origins, r.directions, r.t_near, r.t_far, r.kind, r.copy, sim.rot, sim.pos, r.exclude,
                              r.mount, False, True, r.d32, True, origin_rows=r.origin_rows, run=r.run)
            dev = self.devices[col]
            cfg = dev.template.config
            k = len(c)
            dist = h.distance.reshape(k, dev.n)
            own = self._own_distances(col)
            if own is not None:           # the nearer of the world cast and the body (OwnBodyRays.cast)
                dist = np.where(own[None, :] < dist, own[None, :], dist)
            dist = dist.reshape(k, dev.height, dev.width)
            factors = None if dev.factors is None else np.broadcast_to(dev.factors, dist.shape)
            rng = None
            if cfg.noise > 0:
                rng = _Draws(sim.noise, c.tolist(), sim._noise_col[("RangeFinder", col)],
                             self._valid_counts(dist, factors, cfg.min_range, cfg.max_range))
            blur = None
            blurred = self.blurred[col]
            if blurred is not None:      # each copy's weight from its own sampling period (RangeFinder.capture)
                w = [shading.motion_blur_weight(int(p), cfg.motion_blur) for p in sim.period["RangeFinder"][c, col]]
                blur = (blurred[c], np.array(w).reshape(k, 1, 1))
            self.images[col][c] = imaging.range_values(dist, factors, cfg.min_range, cfg.max_range, cfg.noise,
                                                       cfg.resolution, rng, blur)    # type: ignore[arg-type]
            if blur is not None and blurred is not None:
                blurred[c] = blur[0]
            sim.last["RangeFinder"][c, col] = sim.time_ms[c]
            sim.counters["measurements"] += k

    @staticmethod
    def _valid_counts(dist: np.ndarray, factors: np.ndarray | None, lo: float, hi: float) -> list[int]:
        """Per copy, the pixels that draw noise: range_values' valid test (a finite value in
        [min_range, max_range)), on the same values."""
        with np.errstate(invalid="ignore"):
            v = dist if factors is None else dist * factors
            valid = np.isfinite(v) & (v >= float(lo)) & (v < float(hi))
        return np.count_nonzero(valid.reshape(len(dist), -1), axis=1).tolist()
