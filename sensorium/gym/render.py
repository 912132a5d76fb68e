"""Top-down RGB picture of a simulation (``env.render()``): numpy only, no GUI, no OpenGL.

Every shape (of solids, their nested children and multi-shape bodies) is drawn as the convex hull of its tessellation projected on the world's
ground plane, filled with its ``base_color``, lowest top first (so a tall wall covers the floor); sized planes
(floors) are drawn first. Robots are drawn on top with a white heading line (along the drive's forward,
:func:`sensorium.server.sim.frames.heading`), lights as yellow
dots. The view looks down the world's up axis with east to the right and north up (the world's
ENU view, :mod:`sensorium.server.sim.frames`: in an ENU world +x right, +y up the image; in a NUE world +z
right, +x up); it covers the bounding box of everything drawn plus a margin.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.gym.task import whole
from sensorium.schemas import world as wm
from sensorium.server.sim.frames import ENU_AXES, drive_forward, enu_axes, heading, own_up
from sensorium.server.sim.scene import primitive_from_model, robot_parts, solid_parts
from sensorium.server.world.geometry import Plane, Pose, tessellate
from sensorium.server.world.poses import pose_from_model

BACKGROUND = (40, 40, 46)


def _cross(o, a, b) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise) of 2-D points, Andrew's monotone chain."""
    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 3:
        return pts

    def half(seq):
        out: list = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower = half(pts)
    upper = half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _color(shape: wm.Shape | wm.Solid) -> tuple[int, int, int]:
    c = shape.appearance.base_color if shape.appearance is not None else (1.0, 1.0, 1.0)
    if shape.appearance is not None and shape.appearance.transparency >= 1.0:
        c = (0.6, 0.8, 1.0)   # glass: a pale blue so it stays visible
    return tuple(int(round(255 * min(max(v, 0.0), 1.0))) for v in c)  # type: ignore[return-value]


MAX_RENDER_SIZE = 4096
"""The largest ``render_size`` (pixels a side: a 4096 x 4096 RGB image is 48 MiB)."""


def check_render_size(value) -> int:
    """``render_size`` as an int in [1, MAX_RENDER_SIZE]; a ValueError naming it otherwise."""
    if not whole(value) or not 1 <= value <= MAX_RENDER_SIZE:
        raise ValueError(f"render_size must be an integer number of pixels from 1 to {MAX_RENDER_SIZE}, got {value!r}")
    return int(value)


class TopDown:
    """Renders ``sim`` at ``size`` x ``size`` pixels. The solids are drawn into a static layer, drawn
    again only when the scene's ``solids_version`` changes (a solid moved, imported or removed); robots and
    lights (which may ride on them) at every call. The view (centre and scale) is fixed when the
    renderer is made, so frames of one episode line up; a solid moved outside it is cut off."""

    def __init__(self, sim, size: int = 256, margin: float = 0.1):
        self.sim = sim
        self.size = check_render_size(size)
        axes = enu_axes(sim.world)
        e, n, self._up = axes
        self._ground = [e, n]          # the world axes drawn to the right and up the image
        # each robot: its body shapes' vertices in the robot frame, with their colours, and its own
        # horizontal axes (x and y; in a NUE world x and the one of y, z its world-file pose has level)
        self._robot_parts: list[list[tuple[np.ndarray, tuple[int, int, int]]]] = []
        self._robot_level: list[list[int]] = []
        self._robot_forward = [drive_forward(r) for r in sim.world.robots]    # the heading line's direction
        for r in sim.world.robots:
            level = [0, 1]
            if axes != ENU_AXES:
                level = [0, 3 - own_up(axes, pose_from_model(r.pose).rotation)[0]]
            self._robot_level.append(level)
            parts = []
            for _, local, shape in robot_parts(r):
                prim = primitive_from_model(shape.geometry, sim.loaded.base_dir)
                if not isinstance(prim, Plane):
                    parts.append((local.apply(tessellate(prim)[0]), _color(shape)))
            self._robot_parts.append(parts)
        floors, static = self._solid_polygons()
        pts = [h for _, h, _ in static] + [f for f, _ in floors]
        pts += [np.asarray(rb.pose.translation[self._ground])[None, :] for rb in sim.robots.values()]
        pts += [np.asarray(lt.location)[self._ground][None, :] for lt in sim.scene.world_lights()
                if lt.type != "DirectionalLight"]
        allp = np.concatenate(pts) if pts else np.zeros((1, 2))
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-3)) * (1.0 + 2.0 * margin)
        self.center = 0.5 * (lo + hi)
        self.scale = self.size / span           # pixels per metre
        self._static = self._draw_static(floors, static)
        self._static_version = sim.scene.solids_version

    def _solid_polygons(self) -> tuple[list[tuple[np.ndarray, tuple[int, int, int]]],
                                       list[tuple[float, np.ndarray, tuple[int, int, int]]]]:
        """The solids' shapes at their poses now (a removed solid has none): sized planes as
        (corners on the ground plane, colour), every other shape as (top along up, hull on the
        ground plane, colour), lowest top first."""
        base = self.sim.loaded.base_dir
        poses = self.sim.scene.solid_poses
        static: list[tuple[float, np.ndarray, tuple[int, int, int]]] = []   # (top, hull, colour)
        floors: list[tuple[np.ndarray, tuple[int, int, int]]] = []
        for solid in self.sim.world.solids:
            frame = poses.get(solid.name)
            if frame is None:               # removed by a Supervisor
                continue
            for _, local, shape in solid_parts(solid, Pose.identity()):
                prim = primitive_from_model(shape.geometry, base)
                pose = frame.compose(local)
                if isinstance(prim, Plane):
                    if prim.size is None:
                        continue
                    sx, sy = prim.size[0] / 2.0, prim.size[1] / 2.0
                    corners = pose.apply(np.array([[-sx, -sy, 0], [sx, -sy, 0], [sx, sy, 0], [-sx, sy, 0]], float))
                    floors.append((corners[:, self._ground], _color(shape)))
                    continue
                w = pose.apply(tessellate(prim)[0])
                static.append((float(w[:, self._up].max()), _hull(w[:, self._ground]), _color(shape)))
        static.sort(key=lambda item: item[0])
        return floors, static

    def _draw_static(self, floors, static) -> np.ndarray:
        img = np.empty((self.size, self.size, 3), dtype=np.uint8)
        img[:] = BACKGROUND
        for poly, col in floors:
            self._fill(img, _hull(poly), col)
        for _, poly, col in static:
            self._fill(img, poly, col)
        return img

    # -------------------------------------------------------------------------------- drawing
    def _px(self, xy: np.ndarray) -> np.ndarray:
        """Ground-plane points (east, north) (n, 2) -> pixel coordinates (column, row) as floats."""
        rel = (np.asarray(xy, dtype=np.float64) - self.center) * self.scale
        return np.stack([rel[..., 0] + self.size / 2.0, self.size / 2.0 - rel[..., 1]], axis=-1)

    def _fill(self, img: np.ndarray, hull_xy: np.ndarray, color) -> None:
        if len(hull_xy) < 3:
            return
        p = self._px(hull_xy)
        c0, r0 = np.floor(p.min(axis=0)).astype(int)
        c1, r1 = np.ceil(p.max(axis=0)).astype(int)
        c0, r0 = max(c0, 0), max(r0, 0)
        c1, r1 = min(c1, self.size - 1), min(r1, self.size - 1)
        if c0 > c1 or r0 > r1:
            return
        cols, rows = np.meshgrid(np.arange(c0, c1 + 1) + 0.5, np.arange(r0, r1 + 1) + 0.5)
        inside = np.ones(cols.shape, dtype=bool)
        # pixel rows grow downward, which mirrors the polygon: it is clockwise in pixel space
        for a, b in zip(p, np.roll(p, -1, axis=0)):
            inside &= (b[0] - a[0]) * (rows - a[1]) - (b[1] - a[1]) * (cols - a[0]) <= 1e-9
        img[r0:r1 + 1, c0:c1 + 1][inside] = color

    def _disc(self, img: np.ndarray, xy: np.ndarray, radius_px: float, color) -> None:
        c, r = self._px(xy[None, :])[0]
        rr, cc = np.ogrid[:self.size, :self.size]
        img[(rr + 0.5 - r) ** 2 + (cc + 0.5 - c) ** 2 <= radius_px ** 2] = color

    def _line(self, img: np.ndarray, a: np.ndarray, b: np.ndarray, color) -> None:
        pa, pb = self._px(np.stack([a, b]))
        n = int(max(abs(pb - pa).max(), 1)) + 1
        t = np.linspace(0.0, 1.0, n)[:, None]
        pts = np.floor(pa + t * (pb - pa)).astype(int)
        ok = (pts >= 0).all(axis=1) & (pts < self.size).all(axis=1)
        img[pts[ok, 1], pts[ok, 0]] = color

    def render(self) -> np.ndarray:
        version = self.sim.scene.solids_version
        if version != self._static_version:       # a solid moved, was imported or removed since the last drawing
            self._static = self._draw_static(*self._solid_polygons())
            self._static_version = version
        img = self._static.copy()
        for lt in self.sim.scene.world_lights():
            if lt.type != "DirectionalLight" and lt.on:
                self._disc(img, np.asarray(lt.location)[self._ground], 4, (255, 230, 40))
        for rb, parts, level, forward in zip(self.sim.robots.values(), self._robot_parts, self._robot_level,
                                             self._robot_forward):
            pose = rb.pose
            reach = 4.0 / self.scale
            if parts:
                for v, col in parts:
                    self._fill(img, _hull(pose.apply(v)[:, self._ground]), col)
                reach = max(max(float(np.abs(v[:, level]).max()) for v, _ in parts), 2.0 / self.scale)
            else:
                self._disc(img, pose.translation[self._ground], 3, (200, 200, 200))
            at = pose.translation[self._ground]
            fwd = heading(pose.rotation, forward)[self._ground]
            norm = math.hypot(*fwd) or 1.0
            self._line(img, at, at + fwd / norm * reach * 1.4, (255, 255, 255))
        return img


class TopDownRendering:
    """``render()`` (``render_mode="rgb_array"``: a top-down RGB image) and ``close()`` for the
    single- and multi-robot environments, which both hold ``sim``, ``render_mode``,
    ``render_size`` and ``_renderer``."""

    sim: Any
    render_mode: str | None
    render_size: int
    _renderer: TopDown | None

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        if self.sim is None:
            raise RuntimeError("call reset() before render()")
        if self._renderer is None:
            self._renderer = TopDown(self.sim, self.render_size)
        return self._renderer.render()

    def close(self) -> None:
        self.sim = None
        self._renderer = None
