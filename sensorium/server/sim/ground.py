"""The ground driven robots ride on: terrains (ElevationGrids), ramps (tilted boxes) and the floor
planes, box floors and cylinder tops around them.

No physics: a driven robot keeps the clearance it was placed with above the ground under its
origin. After each step's planar move its height is ``ground(x, y) + clearance`` and, over a
sloped triangle, its attitude is the ground's (:func:`ground_rotation`): its up axis is the
triangle's normal and its heading the drive's yaw. Over nothing it keeps its height, upright.

What counts as ground (seen by bounding rays, as kinematic contact reads the world):

* an ElevationGrid whose local z is the world's up (a grid turned about the vertical, or not at
  all): its surface is each cell's two triangles split from point ``(i, j)`` to ``(i + 1, j + 1)``,
  the triangles rays see, evaluated in float64 from the grid's own vertex coordinates; it covers
  its closed extent ``[0, (x_dimension − 1)·x_spacing] × [0, (y_dimension − 1)·y_spacing]`` and
  nothing beyond;
* a Plane facing up (its local z the world's up): a floor at its height, everywhere (bounding rays
  and Webots' physics take every plane as infinite, whatever its size); a Plane that leans less than
  contact.RAMP_MAX_TILT (45°) from facing up -- a floor written with a small turn, as Webots' worlds
  converted from R2021c write `RectangleArena { rotation 0 1 0 4.692820414042842e-06 }` -- a sloped floor,
  everywhere, ridden as a terrain triangle is (its height under the origin through the plane's point,
  its slope for the attitude);
* the top of a Box whose faces are horizontal and vertical (one of its local axes the world's up,
  within UPRIGHT_TOL; turned about the vertical or not): a floor at its top over its closed
  footprint rectangle -- a slab used as the floor, a raised platform, a step -- but only *for a
  robot whose support ceiling it does not exceed* (below);
* the top of an upright Cylinder (its local z the world's up or down, within UPRIGHT_TOL): a floor
  at its centre's height plus half its height (contact.obstacle's top of it) over its closed disc,
  under the same support rule as a box top (what is said of box tops below holds for it);
* the top face of a **ramp**: a Box that is not upright whose top face (the one whose outward normal
  is most upward) leans less than contact.RAMP_MAX_TILT (45°) from the world's up
  (:func:`contact.ramp_top`): a plane over that closed rectangle, ridden as a terrain triangle is
  (its height under the origin, its slope for the attitude). A ramp is judged by its top face's
  **low edge** (its lowest corner): it is ground for a robot whose support ceiling (below) that edge
  does not exceed -- everywhere over its face, however high it rises there -- and kinematic contact
  takes the same edge as the ramp's top (contact.obstacle), so it never stops such a robot; for a
  robot below the edge it is an obstacle (its whole outline) and never ground. A ramp flush with the
  floor is driven onto at its low edge and climbed; one driven at from the side is climbed onto
  there, as a terrain's cliff is.

The support rule (box and cylinder tops only). A box top is ground for a robot only if it is not above the
robot's **support ceiling**, ``max(band bottom, the ground it rides) + contact.FLOOR``: its
body's height band bottom (the bottom of the disc kinematic contact gives it, ``z + z_low``;
its origin for a robot with no body) or the height of the ground it rides now (``z − clearance``),
whichever is higher, plus the 1 mm floor tolerance; placed or moved by a supervisor it has only
its band bottom. This is kinematic contact's own floor line, taken with the same operations
(``band_lo + FLOOR``, contact.py): a solid whose top is above it is an obstacle contact stops the
robot at, one whose top is not is its floor, so for a robot whose body does not reach below the
ground it rides a box is either ground or an obstacle, never both -- a robot is never lifted onto
what contact stops it at (a table top above it, a kerb 1 cm up), and the box it rides always
stays eligible (it never drops through a box floor onto a plane or terrain below). A box lower
than its body (under the band, which contact lets pass beneath) is climbed onto at once, as
wheels would; no step reaching more than 1 mm into the band is: the kinematic model has no
wheels to climb a kerb with. (A robot whose body reaches below the ground it rides has its
ceiling at that ground + FLOOR: a box top between its band bottom + FLOOR and that ceiling would
be both, but contact (when on) keeps its disc, and so its origin, off it.) Terrains and planes are ground
whatever their height (contact never stops a robot at them), as before.

Other solids are not ridden. In a world without terrains, ramps or leaning planes there is no Ground at all: robots
keep their heights over Box floors and Planes alike.

Where several cover a point the highest is the ground (the first in world order on a tie). On a
line shared by two triangles (a cell's diagonal or edge, a grid point) both triangles give the
same height, bit for bit (the barycentric weights below make the shared terms identical); the
slope there is the triangle on the +x / +y side (the lower triangle ``s ≥ t`` on the diagonal,
the last cell on the grid's far edges). Every function here is element-wise float64 arithmetic
that gives the same bits on a scalar and on any array (the box tops, taken all at once, per point
too), so the batched simulation's copies ride exactly as the single simulation's robot does.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.contact import (
    BOX_UPRIGHT_TOL,
    FLOOR,
    RAMP_MAX_TILT,
    enu_body,
    enu_pose,
    obstacle,
    ramp_top,
    robot_footprint,
)
from sensorium.server.sim.hull import FlatPoints, convex_hull, enclosed, extreme_points, hull_tolerance
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import (
    ROBOT_UPRIGHT_TOL,
    axis_angle,
    axis_angle_matrix,
    matrix_quaternion,
    pose_from_model,
)

__all__ = ["Ground", "GroundPieces", "GroundWarning", "band_low", "falling_shapes", "falling_span", "ground_rotation", "hull_2d", "land_pose", "land_solid", "lift_pose", "over_support", "placing_ceiling", "resting_pose",
           "ride_height", "robot_up", "settle_pose", "settle_world", "settles", "settling_ground", "shapes_span", "slope_scales", "support_ceiling",
           "support_points", "volume_centre"]

UPRIGHT_TOL = BOX_UPRIGHT_TOL     # |tilt| of a grid's or plane's local z from the world's up still taken as upright
SETTLE_TOL = 1e-6       # m: wheels off the ground by at most this stay as placed (a world on it keeps its bits)
SETTLE_NOTE = 1e-3      # m: a robot settled by more than this gets a load note
SETTLE_NOTES = 8        # load notes said one robot a line; more robots settled are counted in one more line


class GroundWarning(UserWarning):
    """Something a driven robot will not ride on (a tilted terrain) or a robot with no ground
    under it in a world that has terrains: one line saying what and why."""


@dataclass(slots=True)
class _Grid:
    """An ElevationGrid in the solid's frame: its vertex coordinates and heights."""

    xs: np.ndarray          # (nx,) i·x_spacing, as the mesh's vertices
    ys: np.ndarray          # (ny,)
    heights: np.ndarray     # (ny, nx)


@dataclass(slots=True)
class _Surface:
    """One piece of ground placed in the world (ENU axes): a grid, a box's top (``half``: its half
    sizes), an upright cylinder's top (``disc``: its radius and half height), or a floor plane
    (none of them)."""

    solid: str
    local: Pose                       # in the solid's frame
    grid: _Grid | None
    half: tuple[float, float, float] | None = None
    disc: tuple[float, float] | None = None
    # a box: its top (tz) and its footprint, |u| <= hu and |v| <= hv with u = r00·ex + r10·ey and
    # v = r01·ex + r11·ey (its two horizontal local axes)
    hu: float = 0.0
    hv: float = 0.0
    # its world placement (set by Ground.place): origin and the turn about the vertical
    tx: float = 0.0
    ty: float = 0.0
    tz: float = 0.0
    r00: float = 1.0
    r01: float = 0.0
    r10: float = 0.0
    r11: float = 1.0
    upright: bool = True
    # a box that is a ramp (contact.ramp_top; set by Ground.place): its top face's centre (cx, cy, cz),
    # slope (gx, gy), in-face axes and half sizes (ai, hi), (aj, hj), and low edge
    ramp: tuple | None = None
    # a plane leaning less than RAMP_MAX_TILT (set by Ground.place): its slope (gx, gy) through (tx, ty, tz)
    tilt: tuple[float, float] | None = None
    # an upright box's or cylinder's top seen from above (Ground.tops), made once per placing
    outline: np.ndarray | None = None


def _is_upright(r: np.ndarray) -> bool:
    return (abs(r[0, 2]) <= UPRIGHT_TOL and abs(r[1, 2]) <= UPRIGHT_TOL and abs(r[2, 0]) <= UPRIGHT_TOL
            and abs(r[2, 1]) <= UPRIGHT_TOL and r[2, 2] > 0.0)


def _surfaces(s: wm.Solid) -> list[_Surface]:
    """The ground a top-level solid holds: its shapes seen by bounding rays that are terrains, planes, boxes
    or cylinders."""
    from sensorium.server.sim.scene import solid_parts

    return _parts_surfaces(s.name, solid_parts(s, Pose.identity()))


def _parts_surfaces(owner: str, parts) -> list[_Surface]:
    """The ground among ``parts`` ((name, pose in the owner's frame, shape)) of the solid or robot ``owner``."""
    surfaces: list[_Surface] = []
    for _, local, shape in parts:
        if shape.seen_by not in ("both", "bounding"):
            continue
        g = shape.geometry
        if isinstance(g, wm.ElevationGrid):
            xs = np.arange(g.x_dimension, dtype=np.float64) * float(g.x_spacing)
            ys = np.arange(g.y_dimension, dtype=np.float64) * float(g.y_spacing)
            h = np.asarray(g.height, dtype=np.float64).reshape(g.y_dimension, g.x_dimension)
            surfaces.append(_Surface(owner, local, _Grid(xs, ys, h)))
        elif isinstance(g, wm.Plane):
            surfaces.append(_Surface(owner, local, None))
        elif isinstance(g, wm.Box):
            sx, sy, sz = (float(v) / 2.0 for v in g.size)
            surfaces.append(_Surface(owner, local, None, (sx, sy, sz)))
        elif isinstance(g, wm.Cylinder):
            surfaces.append(_Surface(owner, local, None, disc=(float(g.radius), float(g.height) / 2.0)))
    return surfaces


def _place_surface(s: _Surface, pose: Pose, to_enu: np.ndarray | None) -> None:
    """Surface ``s`` of a solid or robot at ``pose`` placed in the world (ENU axes)."""
    s.outline = None
    pose = pose.compose(s.local)
    r, t = pose.rotation, pose.translation
    if to_enu is not None:
        r, t = to_enu @ r, to_enu @ t
    if s.half is not None:
        _place_box(s, r, t)
    elif s.disc is not None:
        _place_disc(s, r, t)
    else:
        s.upright = _is_upright(r)
        s.tx, s.ty, s.tz = (float(v) for v in t)
        s.r00, s.r01, s.r10, s.r11 = float(r[0, 0]), float(r[0, 1]), float(r[1, 0]), float(r[1, 1])
        # a plane (no grid) whose normal, its local z, leans less than a ramp may: a sloped floor
        s.tilt = None
        if s.grid is None and not s.upright and float(r[2, 2]) > math.cos(RAMP_MAX_TILT):
            s.tilt = (float(-r[0, 2] / r[2, 2]), float(-r[1, 2] / r[2, 2]))


def _place_box(s: _Surface, r: np.ndarray, t: np.ndarray) -> None:
    """A box's top and footprint: ground only if one of its local axes is the world's up (its
    faces horizontal and vertical). Its top is the highest of its corners' heights computed as
    contact.obstacle computes them (``corners @ r.T + t``), so both judge the same number."""
    assert s.half is not None
    up = [k for k in range(3) if abs(r[0, k]) <= UPRIGHT_TOL and abs(r[1, k]) <= UPRIGHT_TOL
          and all(abs(r[2, j]) <= UPRIGHT_TOL for j in range(3) if j != k)]
    s.upright = bool(up)
    s.ramp = None
    if not up:
        ramp = ramp_top(r, t, s.half)
        if ramp is not None:
            k, sign, _, low = ramp
            i, j = (a for a in range(3) if a != k)
            n = sign * r[:, k]
            c = t + (sign * s.half[k]) * r[:, k]
            s.ramp = (float(c[0]), float(c[1]), float(c[2]), float(-n[0] / n[2]), float(-n[1] / n[2]),
                      *(float(v) for v in r[:, i]), s.half[i], *(float(v) for v in r[:, j]), s.half[j], low)
        return
    i, j = (a for a in range(3) if a != up[0])
    hx, hy, hz = s.half
    corners = np.array([[x, y, z] for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)])
    s.tx, s.ty = float(t[0]), float(t[1])
    s.tz = float((corners @ r.T + t)[:, 2].max())
    s.r00, s.r10, s.r01, s.r11 = float(r[0, i]), float(r[1, i]), float(r[0, j]), float(r[1, j])
    s.hu, s.hv = s.half[i], s.half[j]


def _place_disc(s: _Surface, r: np.ndarray, t: np.ndarray) -> None:
    """A cylinder's top disc: ground only if its axis (local z) is the world's up or down. Its
    top is its centre's height plus half its height, as contact.obstacle takes an upright
    cylinder's, and its disc its radius about its axis, so both judge the same numbers."""
    assert s.disc is not None
    s.upright = (abs(r[0, 2]) <= UPRIGHT_TOL and abs(r[1, 2]) <= UPRIGHT_TOL
                 and abs(r[2, 0]) <= UPRIGHT_TOL and abs(r[2, 1]) <= UPRIGHT_TOL)
    if not s.upright:
        return
    s.tx, s.ty = float(t[0]), float(t[1])
    s.tz = float(t[2] + s.disc[1])


_DISC = np.arange(64) * (2.0 * math.pi / 64)


def _outline(s: _Surface) -> np.ndarray:
    """An upright box's or cylinder's top seen from above: x, y corners counter-clockwise (a cylinder's disc
    a 64-gon inscribed in it), kept on the surface until it is placed again (read only: shared)."""
    if s.outline is None:
        if s.disc is None:       # a box: its corners at ±hu along (r00, r10), ±hv along (r01, r11)
            corners = [(su * s.hu, sv * s.hv) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            outline = np.array([[s.tx + u * s.r00 + v * s.r01, s.ty + u * s.r10 + v * s.r11] for u, v in corners])
            if s.r00 * s.r11 - s.r10 * s.r01 < 0.0:          # a mirrored frame: keep them counter-clockwise
                outline = outline[::-1]
        else:
            radius = math.sqrt(s.disc[0] * s.disc[0])
            outline = np.column_stack([s.tx + radius * np.cos(_DISC), s.ty + radius * np.sin(_DISC)])
        outline.flags.writeable = False
        s.outline = outline
    return s.outline


class Ground:
    """The world's ground (see the module docstring); :meth:`under` samples it at points."""

    def __init__(self, surfaces: list[_Surface], poses: dict[str, Pose], to_enu: np.ndarray | None,
                 placed: bool = False):
        """``placed``: the surfaces are placed at ``poses`` already (:class:`GroundPieces`' ones, shared with
        other grounds: :meth:`update_solid` places copies of them)."""
        self._surfaces = surfaces
        self._boxes: tuple[np.ndarray, ...] | None = None      # _box_table's, made again when stale
        self._boxes_stale = True
        self._tops: tuple[tuple[np.ndarray, ...], list[tuple[float, np.ndarray]]] | None = None   # tops()'s
        self._to_enu = to_enu
        self._poses = dict(poses)
        if not placed:
            for s in surfaces:
                self._place(s)

    @classmethod
    def from_world(cls, world: wm.World, solid_poses: dict[str, Pose], to_enu: np.ndarray | None) -> Ground | None:
        """The ground of a world with at least one terrain, ramp or leaning plane seen by bounding rays (None
        otherwise: robots then keep their heights, as they always did). ``solid_poses``: the top-level solids'
        world poses; ``to_enu``: world axes to ENU (None in an ENU world)."""
        surfaces = [surface for s in world.solids for surface in _surfaces(s)]
        if all(s.disc is not None for s in surfaces):       # cylinder tops alone (or nothing) make no ground
            return None
        ground = cls(surfaces, solid_poses, to_enu)
        return ground if any(s.grid is not None or s.ramp is not None or s.tilt is not None for s in surfaces) else None

    def add_solid(self, solid: wm.Solid, pose: Pose) -> None:
        """A top-level solid built again (a Supervisor set a PROTO field of it): its terrains, floors and
        box tops are ground as the world file's are."""
        added = _surfaces(solid)
        self._poses[solid.name] = pose
        self._surfaces += added
        self._boxes_stale = True
        for s in added:
            self._place(s)

    def tilted_terrains(self) -> list[str]:
        """The solids holding a grid that is not upright (not ground: robots keep their height over it)."""
        return [s.solid for s in self._surfaces if s.grid is not None and not s.upright]

    def _place(self, s: _Surface) -> None:
        _place_surface(s, self._poses[s.solid], self._to_enu)
        self._boxes_stale = True

    def update_solid(self, name: str, pose: Pose) -> None:
        """A solid moved (supervisor): its pieces of ground move with it."""
        if name not in self._poses:
            return
        self._poses[name] = pose
        for k, s in enumerate(self._surfaces):
            if s.solid == name:
                self._surfaces[k] = s = replace(s)       # (the old one may be GroundPieces', shared)
                self._place(s)

    def remove_solid(self, name: str) -> None:
        """A solid removed (supervisor): no longer ground."""
        self._surfaces = [s for s in self._surfaces if s.solid != name]
        self._boxes_stale = True
        self._poses.pop(name, None)

    def under(self, x: np.ndarray, y: np.ndarray,
              ceiling: np.ndarray | float = math.inf) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The ground under points (ENU x, y arrays) for robots whose support ceilings are
        ``ceiling`` (:func:`support_ceiling`, :func:`placing_ceiling`: a box top above it is not
        ground there; the robots always give theirs, the default inf is the ground seen from above):
        ``(found, z, gx, gy)`` — whether any covers each point, its height there and its slope
        (dz/dx, dz/dy in ENU axes; 0 on floors)."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        ceiling = np.broadcast_to(np.asarray(ceiling, dtype=np.float64), x.shape)
        best = np.full(x.shape, -math.inf)
        gx = np.zeros(x.shape)
        gy = np.zeros(x.shape)
        found = np.zeros(x.shape, dtype=bool)
        first = np.full(x.shape, len(self._surfaces))     # the world-order index of each point's ground
        for i, s in enumerate(self._surfaces):
            if s.ramp is not None:               # a ramp's top face: a plane over a rectangle
                cx, cy, cz, sx, sy, aix, aiy, aiz, hi, ajx, ajy, ajz, hj, low = s.ramp
                ex, ey = x - cx, y - cy
                dz = sx * ex + sy * ey
                u = aix * ex + aiy * ey + aiz * dz       # the point on the plane in the face's axes
                v = ajx * ex + ajy * ey + ajz * dz
                z = cz + dz
                take = (np.abs(u) <= hi) & (np.abs(v) <= hj) & (low <= ceiling) & (z > best)
                best = np.where(take, z, best)
                gx = np.where(take, sx, gx)
                gy = np.where(take, sy, gy)
                first = np.where(take, i, first)
                found |= take
                continue
            if s.tilt is not None:               # a leaning plane: a sloped floor, everywhere
                gpx, gpy = s.tilt
                z = s.tz + (gpx * (x - s.tx) + gpy * (y - s.ty))
                take = z > best
                best = np.where(take, z, best)
                gx = np.where(take, gpx, gx)
                gy = np.where(take, gpy, gy)
                first = np.where(take, i, first)
                found |= take
                continue
            if not s.upright or s.half is not None or s.disc is not None:    # (box and cylinder tops: below)
                continue
            if s.grid is None:                   # an infinite floor
                z = np.full(x.shape, s.tz)
                take = z > best
                best = np.where(take, z, best)
                gx = np.where(take, 0.0, gx)
                gy = np.where(take, 0.0, gy)
                first = np.where(take, i, first)
                found |= take
                continue
            ex, ey = x - s.tx, y - s.ty
            u = s.r00 * ex + s.r10 * ey          # the point in the grid's frame (R^T (p - t))
            v = s.r01 * ex + s.r11 * ey
            g = s.grid
            cover = (u >= 0.0) & (u <= g.xs[-1]) & (v >= 0.0) & (v <= g.ys[-1])
            if not cover.any():
                continue
            k = cover.nonzero()
            h, gu, gv = grid_height(g, u[k], v[k])
            z = s.tz + h
            take = z > best[k]
            kk = tuple(a[take] for a in k)
            best[kk] = z[take]
            gx[kk] = s.r00 * gu[take] + s.r01 * gv[take]      # the slope turns with the grid
            gy[kk] = s.r10 * gu[take] + s.r11 * gv[take]
            first[kk] = i
            found[kk] = True
        boxes = self._box_table()
        if boxes is not None and x.size:
            # every box or cylinder top at every point (points x tops): over its footprint (a box's
            # rectangle; a cylinder's disc: the other's bounds are inf) and not above the point's
            # ceiling; each point's highest, the first in world order on a tie (argmax), then
            # against the other surfaces' winner as the one loop in world order would have it
            order, tx, ty, tz, a, b, c, d, hu, hv, rr = boxes
            ex, ey = x[..., None] - tx, y[..., None] - ty
            u = a * ex + b * ey                  # the point in the box's horizontal axes
            v = c * ex + d * ey
            ok = (np.abs(u) <= hu) & (np.abs(v) <= hv) & (ex * ex + ey * ey <= rr) & (tz <= ceiling[..., None])
            zb = np.where(ok, tz, -math.inf)
            j = np.argmax(zb, axis=-1)
            top = np.take_along_axis(zb, j[..., None], axis=-1)[..., 0]
            take = ok.any(axis=-1) & ((top > best) | ((top == best) & (order[j] < first)))
            best = np.where(take, top, best)
            gx = np.where(take, 0.0, gx)
            gy = np.where(take, 0.0, gy)
            found |= take
        return found, best, gx, gy

    def _box_table(self) -> tuple[np.ndarray, ...] | None:
        """The upright boxes' and cylinders' tops as arrays (world-order index, tx, ty, top, r00,
        r10, r01, r11, hu, hv, squared radius; a box's radius and a cylinder's half sizes inf),
        made once per change of the surfaces; None without one."""
        if self._boxes_stale:
            self._boxes_stale = False
            rows = [(i, s.tx, s.ty, s.tz, s.r00, s.r10, s.r01, s.r11, s.hu, s.hv, math.inf) if s.disc is None else
                    (i, s.tx, s.ty, s.tz, 1.0, 0.0, 0.0, 1.0, math.inf, math.inf, s.disc[0] * s.disc[0])
                    for i, s in enumerate(self._surfaces) if (s.half is not None or s.disc is not None) and s.upright]
            self._boxes = None if not rows else (np.array([r[0] for r in rows], dtype=np.int64),
                                                 *np.array([r[1:] for r in rows], dtype=np.float64).T)
        return self._boxes

    def tops(self) -> list[tuple[float, np.ndarray]]:
        """The upright box and cylinder tops as (height, their outline seen from above: x, y corners
        counter-clockwise; a cylinder's disc a 64-gon inscribed in it), for the Supervisor's static balance
        (sim/balance.py: where a flat face over a top's edge is held)."""
        boxes = self._box_table()
        if boxes is None:
            return []
        if self._tops is None or self._tops[0] is not boxes:    # made again with the box table
            self._tops = (boxes, [(s.tz, _outline(s)) for s in self._surfaces
                                  if (s.half is not None or s.disc is not None) and s.upright])
        return self._tops[1]

    def at(self, x: float, y: float, ceiling: float = math.inf) -> tuple[float, float, float] | None:
        """:meth:`under` at one point: ``(z, gx, gy)`` or None (the same arithmetic, so the same bits)."""
        found, z, gx, gy = self.under(np.array([x]), np.array([y]), np.array([ceiling]))
        if not found[0]:
            return None
        return float(z[0]), float(gx[0]), float(gy[0])


def cell_of(grid: _Grid, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cell holding each point of the grid's extent: ``xs[i] <= u < xs[i + 1]`` (the last cell
    also holds its far edge), likewise j."""
    i = np.clip(np.searchsorted(grid.xs, u, side="right") - 1, 0, len(grid.xs) - 2)
    j = np.clip(np.searchsorted(grid.ys, v, side="right") - 1, 0, len(grid.ys) - 2)
    return i, j


def triangle_height(grid: _Grid, i: np.ndarray, j: np.ndarray, lower: np.ndarray, u: np.ndarray,
                    v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Height and slope (along local x, y) at (u, v) of cell (i, j)'s lower triangle (points
    (i, j), (i+1, j), (i+1, j+1)) where ``lower``, else its upper one ((i, j), (i+1, j+1), (i, j+1)).

    Barycentric weights from the cell's own vertex coordinates: s, t in the cell; lower
    ``(1−s)·a + (s−t)·b + t·c``, upper ``(1−t)·a + s·c + (t−s)·d``. On the diagonal (s = t) both are
    ``(1−s)·a + s·c`` plus an exact 0; on a cell edge the neighbour's weights are the same terms, so
    a shared point gets one height whichever triangle is asked."""
    x0, x1 = grid.xs[i], grid.xs[i + 1]
    y0, y1 = grid.ys[j], grid.ys[j + 1]
    s = (u - x0) / (x1 - x0)
    t = (v - y0) / (y1 - y0)
    H = grid.heights
    a, b, c, d = H[j, i], H[j, i + 1], H[j + 1, i + 1], H[j + 1, i]
    h = np.where(lower, (1.0 - s) * a + (s - t) * b + t * c, (1.0 - t) * a + s * c + (t - s) * d)
    gu = np.where(lower, (b - a) / (x1 - x0), (c - d) / (x1 - x0))
    gv = np.where(lower, (c - b) / (y1 - y0), (d - a) / (y1 - y0))
    return h, gu, gv


def grid_height(grid: _Grid, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Height and local slope of the grid's surface at points of its extent (see :func:`cell_of`;
    the lower triangle on the diagonal)."""
    i, j = cell_of(grid, u, v)
    s = (u - grid.xs[i]) / (grid.xs[i + 1] - grid.xs[i])
    t = (v - grid.ys[j]) / (grid.ys[j + 1] - grid.ys[j])
    return triangle_height(grid, i, j, s >= t, u, v)


def band_low(parts: list, pose: Pose, to_enu: np.ndarray | None) -> float:
    """The bottom of a robot's height band relative to its origin, as kinematic contact takes it
    (``robot_footprint(enu_body(...)).z_low``: its bounding body shapes, ``parts`` as (primitive,
    pose in the robot frame), at its initial ``pose``); 0.0 (its origin) for a robot with no body."""
    foot = robot_footprint(enu_body(parts, pose, to_enu))
    return 0.0 if foot is None else foot.z_low


def placing_ceiling(z, low):
    """The support ceiling of a robot placed at height ``z`` (band bottom ``z + low``): it rides no
    ground yet, so its band bottom alone, plus FLOOR. Scalars or arrays, the same bits."""
    return (z + low) + FLOOR


def support_ceiling(z, low, z0, rest):
    """The support ceiling of a robot riding the ground (height ``z``, band bottom ``z + low``,
    placed at ``z0`` over ground at ``rest``): ``max(z + low, z − (z0 − rest)) + FLOOR``, its band
    bottom or the ground it rides, whichever is higher, plus FLOOR (module docstring). Scalars or
    arrays, the same bits."""
    return np.maximum(z + low, z - (z0 - rest)) + FLOOR


def ride_height(z_last, z0, rest, found, h):
    """A driven robot's height over the ground sampled under it: ``h + (z0 − rest)`` (its clearance
    kept), exactly ``z0`` over ground as high as where it was placed, its last height over nothing.
    Scalars or arrays, the same bits."""
    return np.where(found, np.where(h == rest, z0, h + (z0 - rest)), z_last)


def ground_rotation(gx, gy, c, s, base: np.ndarray) -> np.ndarray:
    """A robot's rotation on a ground of slope (gx, gy) with heading (cos, sin) = (c, s): ``A @ base``
    where A's columns are the forward axis ``f ∝ (c, s, gx·c + gy·s)`` (in the ground plane, seen
    from above along the heading), ``n × f`` and the ground's normal ``n ∝ (−gx, −gy, 1)``; so the
    roll and pitch are the ground's and the yaw the drive's. Element-wise (any leading shape, with
    ``base`` (..., 3, 3)), each entry summed in one fixed order: the same bits for one robot or many."""
    k = gx * c + gy * s
    fl = np.sqrt(c * c + s * s + k * k)
    fx, fy, fz = c / fl, s / fl, k / fl
    nl = np.sqrt(gx * gx + gy * gy + 1.0)
    nx, ny, nz = -gx / nl, -gy / nl, 1.0 / nl
    lx, ly, lz = ny * fz - nz * fy, nz * fx - nx * fz, nx * fy - ny * fx
    a = ((fx, lx, nx), (fy, ly, ny), (fz, lz, nz))
    rows = [np.stack([a[r][0] * base[..., 0, col] + a[r][1] * base[..., 1, col] + a[r][2] * base[..., 2, col]
                      for col in range(3)], axis=-1) for r in range(3)]
    return np.stack(rows, axis=-2)


def ground_angular_velocity(gx: float, gy: float, c: float, s: float, turn: float) -> tuple[float, float, float]:
    """The angular velocity (ENU) of a robot turning at ``turn`` rad/s on a plane of slope (gx, gy)
    with heading (c, s): it turns about the plane's normal, ``turn·(−gx, −gy, 1)/(1 + k²)`` with k
    the slope along its heading (its yaw turns at ``turn``; 0 slope: ``(0, 0, turn)``)."""
    k = gx * c + gy * s
    w = turn / (1.0 + k * k)
    return -gx * w, -gy * w, w


def slope_scales(gx, gy, c, s):
    """What a slope (gx, gy) does to wheels rolling with heading (cos, sin) = (c, s): ``(root, turn)``,
    the horizontal speed being the speed along the ground over ``root`` = √(1 + k²) = 1/cos θ (k =
    tan θ the slope along the heading), and the yaw rate about the world's up the turn rate about the
    ground's normal times ``turn`` = (1 + k²)/√(1 + gx² + gy²). (A forward axis f ∝ (c, s, k) turning
    at ω about the unit normal n ∝ (−gx, −gy, 1) has its heading turn at ω·n_z·|f|²/(f_x² + f_y²):
    the inverse of :func:`ground_angular_velocity`.) Element-wise: the same bits on scalars and arrays."""
    k = gx * c + gy * s
    q = 1.0 + k * k
    return np.sqrt(q), q / np.sqrt(1.0 + gx * gx + gy * gy)


def slope_twist(gx, gy, c, s, vx, vy, w):
    """A body twist in the slope's plane seen from above: a robot with heading (cos, sin) = (c, s) on
    the slope (gx, gy), moving at ``vx`` along its forward axis and ``vy`` along its left axis, both in
    the ground's plane, and turning at ``w`` about the ground's normal, moves its origin horizontally at
    (``vx_h`` ahead, ``vy_h`` to the left, in the heading's horizontal frame) and turns its heading about
    the world's up at ``w_h``.

    Derivation. In the heading's horizontal frame a (ahead), b (left), z (up) the plane is
    z = k·a + m·b, k = gx·c + gy·s and m = gy·c − gx·s the slopes along a and b, its normal
    n ∝ (−k, −m, 1). The forward axis in the plane is f ∝ (1, 0, k), |f| = √(1 + k²): seen from above
    (1, 0)/√(1 + k²). The left axis is n × f = (−m·k, 1 + k², m), of length √((1 + k²)·G²) with
    G² = 1 + k² + m² = 1 + gx² + gy² (the gradient's length in any horizontal frame): seen from above
    (−m·k, 1 + k²)/(√(1 + k²)·G). So vx_h = (vx − vy·m·k/G)/√(1 + k²), vy_h = vy·√(1 + k²)/G; the heading
    turns as :func:`slope_scales` has it, w_h = w·(1 + k²)/G. Heading up a slope of angle A (k = tan A,
    m = 0): vx·cos A ahead, vy to the left; sideways up it (k = 0, m = tan A): vx ahead, vy·cos A to the
    left; with vy = 0 it is :func:`slope_scales`' v/√(1 + k²), operation for operation. Element-wise:
    the same bits on scalars and arrays."""
    k = gx * c + gy * s
    m = gy * c - gx * s
    root, turn = slope_scales(gx, gy, c, s)
    g = np.sqrt(1.0 + gx * gx + gy * gy)
    return (vx - vy * (m * k / g)) / root, vy * (root / g), w * turn


def _wheels(robot: wm.Robot) -> tuple[float, float] | None:
    """(its lowest wheel's bottom from its origin, its smallest wheel radius) for a robot whose drive
    gives the wheel bottom (``wheel_bottom``), else None."""
    if robot.differential_drive is not None:
        drive, radius = robot.differential_drive, robot.differential_drive.wheel_radius
    elif robot.mecanum_drive is not None:
        drive, radius = robot.mecanum_drive, robot.mecanum_drive.wheel_radius
    elif robot.ackermann_drive is not None:
        a = robot.ackermann_drive
        drive, radius = a, min(a.front_wheel_radius, a.rear_wheel_radius)
    elif robot.omni_drive is not None:
        drive, radius = robot.omni_drive, min(w.radius for w in robot.omni_drive.wheels)
    elif robot.steered_drive is not None:
        drive, radius = robot.steered_drive, min(w.radius for w in robot.steered_drive.wheels)
    else:
        return None
    return None if drive.wheel_bottom is None else (float(drive.wheel_bottom), float(radius))


def robot_up(r: np.ndarray, to_enu: np.ndarray | None) -> int | None:
    """Which of a robot's own axes stands up (its rotation ``r`` in ENU axes): its z (2) when that is
    the world's up, in a NUE world its y (1) when that is (a robot built y-up, as Webots' robots were
    before R2022a); None when neither is (a tilted robot). Its ``wheel_bottom`` is along that axis."""
    for k in ((2,) if to_enu is None else (2, 1)):
        if abs(r[0, k]) <= ROBOT_UPRIGHT_TOL and abs(r[1, k]) <= ROBOT_UPRIGHT_TOL and r[2, k] > 0.0:
            return k
    return None


def settling_ground(solids: list[tuple[wm.Solid, Pose]], floors: list[tuple[wm.Robot, Pose]],
                    to_enu: np.ndarray | None, floor_parts: list[list] | None = None) -> Ground | None:
    """The ground wheeled robots settle on: the top-level ``solids``' (each at its pose) and the shapes
    of the robots without a drive (``floors``, each at its pose: a Webots world's floor may be a
    robot's, create.wbt's ground supervisor holds its Plane), box and cylinder tops included whatever
    the world has (terrains or not); None when there is none. A robot's surfaces are keyed apart from
    any solid's name. ``floor_parts``: each floor robot's parts as scene.robot_parts gives them, where its
    joints hold them now (None: as the world file places them)."""
    from sensorium.server.sim.scene import robot_parts

    surfaces = [surface for s, _ in solids for surface in _surfaces(s)]
    parts = floor_parts if floor_parts is not None else [list(robot_parts(r)) for r, _ in floors]
    surfaces += [surface for (r, _), p in zip(floors, parts) for surface in _parts_surfaces("\0" + r.name, p)]
    if not surfaces:
        return None
    poses = {s.name: pose for s, pose in solids}
    poses.update({"\0" + r.name: pose for r, pose in floors})
    return Ground(surfaces, poses, to_enu)


class GroundPieces:
    """The pieces of ground of each top-level solid and robot, placed where it is, kept from one
    ``Simulation.landing_ground`` to the next (a Supervisor moving, balancing or letting go solids among many
    others builds again only what changed): an owner's pieces are read again from its model when the model
    or its joints' displacements changed (a solid built again or imported under a name is a new model) and
    placed again when its pose did -- models, poses and displacements are immutable objects, compared by
    identity, so every path that changes one (a move, an import, a removal, a PROTO field set, a reset, a
    gripper, a fall) changes what is compared. The same placing arithmetic as :class:`Ground`'s, so a ground
    made of them is bit for bit the one :func:`settling_ground` builds; its surfaces are shared (read only)."""

    def __init__(self, to_enu: np.ndarray | None):
        self.to_enu = to_enu
        # owner -> (what its pieces are read from, its unplaced pieces, the pose they are placed at, placed)
        self._kept: dict[str, tuple[tuple, list[_Surface], Pose, list[_Surface]]] = {}

    def pieces(self, owner: str, source: tuple, parts: Callable[[], Iterable], pose: Pose) -> list[_Surface]:
        """Owner ``owner``'s pieces placed at ``pose``: ``source`` the objects its ``parts()`` (scene.solid_parts'
        or robot_parts' (name, local pose, shape)) are made from, its model and displacements."""
        kept = self._kept.get(owner)
        if kept is not None and len(kept[0]) == len(source) and all(a is b for a, b in zip(kept[0], source)):
            if kept[2] is pose:
                return kept[3]
            unplaced = kept[1]
        else:
            unplaced = _parts_surfaces(owner, parts())
        placed = [replace(u) for u in unplaced]
        for s in placed:
            _place_surface(s, pose, self.to_enu)
        self._kept[owner] = (source, unplaced, pose, placed)
        return placed

    def ground(self, solids: Sequence[tuple[wm.Solid, Pose]],
               floors: Sequence[tuple[wm.Robot, Pose, tuple, Callable[[], Iterable]]]) -> Ground | None:
        """:func:`settling_ground` of ``solids`` and ``floors`` ((model, pose, what its parts are made from: its
        model and joint displacements, its parts where its joints hold them)) from the kept pieces."""
        from sensorium.server.sim.scene import solid_parts

        surfaces: list[_Surface] = []
        poses: dict[str, Pose] = {}
        for s, pose in solids:
            surfaces += self.pieces(s.name, (s,), lambda s=s: solid_parts(s, Pose.identity()), pose)
            poses[s.name] = pose
        for r, pose, source, parts in floors:
            surfaces += self.pieces("\0" + r.name, source, parts, pose)
            poses["\0" + r.name] = pose
        if len(self._kept) > 2 * len(poses) + 16:     # owners gone (removed solids): forgotten
            self._kept = {k: v for k, v in self._kept.items() if k in poses}
        return Ground(surfaces, poses, self.to_enu, placed=True) if surfaces else None


def _settled(ground: Ground, bottoms: np.ndarray, axles: np.ndarray, xs: np.ndarray, ys: np.ndarray,
             zs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which upright robots (ENU origins xs, ys, zs; wheel bottoms and axle heights above them) settle,
    and their heights ``ground − bottom``: the ground under the origin not above ``(z + axle) +
    FLOOR``, found and more than SETTLE_TOL away. Element-wise: one robot or many, the same bits."""
    found, heights, _, _ = ground.under(xs, ys, (zs + axles) + FLOOR)
    heights = heights - bottoms
    return found & ~(np.abs(heights - zs) <= SETTLE_TOL), heights


def _upright_wheels(robot: wm.Robot, pose: Pose, to_enu: np.ndarray | None) -> tuple[float, float, np.ndarray] | None:
    """(wheel bottom, axle height above the origin, the origin in ENU) of a robot that settles at
    ``pose`` (its drive gives ``wheel_bottom`` and it stands upright: :func:`robot_up`), else None."""
    wheels = _wheels(robot)
    if wheels is None:
        return None
    bottom, radius = wheels
    r, t = pose.rotation, pose.translation
    if to_enu is not None:
        r, t = to_enu @ r, to_enu @ t
    if robot_up(r, to_enu) is None:
        return None
    return bottom, max(0.0, bottom + radius), t


CAR_LEAN_TOL = 0.35
"""rad: a car on wheels of two sizes (``axle_bottoms``) whose up is within this of the world's, turned about
its own y only (its left level within ROBOT_UPRIGHT_TOL), settles onto its lean; beyond, it keeps its pose."""


def car_lean(robot: wm.Robot) -> tuple[float, float, float] | None:
    """(θ, h, c) for a car whose axles' wheels differ (``axle_bottoms``, x forward): θ its lean about its y
    (Webots' rotation about +y: positive puts its nose down) at which both axles' wheels touch a flat ground,
    h the rear wheels' contact height above its origin leaning so, c their centre's; None for any other robot. With the
    axles' centres c = bottom + radius, a wheel's lowest point stays its centre less its radius however it
    leans (a circle turned in its plane), so L sin θ + (c_rear − c_front) cos θ = r_rear − r_front."""
    a = robot.ackermann_drive
    if a is None or a.axle_bottoms is None or a.wheel_bottom is None or tuple(a.forward) != (1.0, 0.0):
        return None
    rr, rf = float(a.rear_wheel_radius), float(a.front_wheel_radius)
    cr, cf = float(a.axle_bottoms[0]) + rr, float(a.axle_bottoms[1]) + rf
    size = math.hypot(float(a.wheelbase), cr - cf)
    if abs(rr - rf) >= size:
        return None
    theta = math.asin((rr - rf) / size) - math.atan2(cr - cf, float(a.wheelbase))
    x = float(a.rear_axle_offset)
    centre = -x * math.sin(theta) + cr * math.cos(theta)
    return theta, centre - rr, centre


def lean_pose(robot: wm.Robot, pose: Pose, ground: Ground | None,
              to_enu: np.ndarray | None) -> tuple[Pose | None, bool]:
    """(its pose, True) for a car on wheels of two sizes (:func:`car_lean`) in a z-up world, placed within
    CAR_LEAN_TOL of upright and turned about its own y only: leaning by θ about its y, its heading kept,
    its origin's height ``ground − h`` over the ground under it (``pose`` itself when within SETTLE_TOL and
    1e-9 rad of that, or over no ground); (None, False) for any other robot, settled by the upright rule."""
    lean = None if to_enu is not None else car_lean(robot)
    r, t = pose.rotation, pose.translation
    if lean is None or abs(r[2, 1]) > ROBOT_UPRIGHT_TOL or r[2, 2] < math.cos(CAR_LEAN_TOL):
        return None, False
    theta, contact, centre = lean
    if ground is None:
        return pose, True
    found, heights, _, _ = ground.under(np.array([float(t[0])]), np.array([float(t[1])]),
                                        np.array([float(t[2]) + max(0.0, centre)]) + FLOOR)
    if not found[0]:
        return pose, True
    yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    pitch = math.atan2(-float(r[2, 0]), float(r[2, 2]))
    height = float(heights[0]) - contact
    if abs(pitch - theta) <= 1e-9 and abs(height - float(t[2])) <= SETTLE_TOL:
        return pose, True
    rotation = axis_angle_matrix((0.0, 0.0, 1.0), yaw) @ axis_angle_matrix((0.0, 1.0, 0.0), theta)
    return Pose(rotation, np.array([float(t[0]), float(t[1]), height])), True


def _up_axis(to_enu: np.ndarray | None) -> tuple[int, float]:
    """The world axis that is up and its sign (ENU's z: the world's y in a NUE world)."""
    if to_enu is None:
        return 2, 1.0
    up = int(np.argmax(np.abs(to_enu[2])))
    return up, float(to_enu[2, up])


def settles(robot: wm.Robot) -> bool:
    """Whether a robot settles on the ground (its drive gives ``wheel_bottom``)."""
    return _wheels(robot) is not None


def settle_pose(robot: wm.Robot, pose: Pose, ground: Ground | None, to_enu: np.ndarray | None) -> Pose:
    """The pose of a wheeled robot a Supervisor put at ``pose``: settled on ``ground``
    (:func:`settling_ground` as the world is now) as :func:`settle_world` settles it at load, with
    the same arithmetic (so a robot put back at its world-file pose takes its settled initial pose,
    bit for bit); ``pose`` itself when it does not settle (no ``wheel_bottom``, not upright, over no
    ground, within SETTLE_TOL of it)."""
    leaned, leans = lean_pose(robot, pose, ground, to_enu)
    if leans:
        return pose if leaned is None else leaned
    got = None if ground is None else _upright_wheels(robot, pose, to_enu)
    if got is None:
        return pose
    assert ground is not None
    bottom, axle, t = got
    move, heights = _settled(ground, np.array([bottom]), np.array([axle]), np.array([float(t[0])]),
                             np.array([float(t[1])]), np.array([float(t[2])]))
    if not move[0]:
        return pose
    up, sign = _up_axis(to_enu)
    translation = np.array(pose.translation, dtype=np.float64)
    translation[up] = sign * float(heights[0])
    return Pose(pose.rotation, translation)


def _landing_heights(ground: Ground, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, lows: np.ndarray,
                     highs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where solids (ENU origins xs, ys, zs; their bounding shapes spanning the heights lows to highs)
    land on ``ground``: whether a support is under each origin not above the middle of its span +
    FLOOR, and the origin's height with its lowest point on that support's top. Element-wise: one
    solid or many, the same bits (land_pose and settle_world share it)."""
    found, z, _, _ = ground.under(xs, ys, (lows + highs) / 2.0 + FLOOR)
    return found, z + (zs - lows)


def _land_height(pose: Pose, low: float, high: float, ground: Ground | None,
                 to_enu: np.ndarray | None) -> float | None:
    """The ENU height a solid at ``pose`` spanning ``low`` to ``high`` lands at (land_pose's rule),
    None over no support."""
    if ground is None:
        return None
    t = pose.translation if to_enu is None else to_enu @ pose.translation
    found, heights = _landing_heights(ground, np.array([float(t[0])]), np.array([float(t[1])]),
                                      np.array([float(t[2])]), np.array([low]), np.array([high]))
    return float(heights[0]) if found[0] else None


def _at_height(pose: Pose, height: float, to_enu: np.ndarray | None) -> Pose:
    """``pose`` with its origin's ENU height set (its x, y and rotation kept)."""
    up, sign = _up_axis(to_enu)
    translation = np.array(pose.translation, dtype=np.float64)
    translation[up] = sign * height
    return Pose(pose.rotation, translation)


def land_pose(pose: Pose, low: float, high: float, ground: Ground | None, to_enu: np.ndarray | None) -> Pose:
    """The pose a solid at ``pose`` lands at, its rotation as it is (:func:`land_solid` tips it first):
    its bounding shapes span the heights ``low`` to ``high`` (ENU z) there; it goes straight down (or
    up) onto the highest ground under its origin (``ground``: :func:`settling_ground` without it) not
    above the middle of that span + FLOOR, its lowest point on that ground, its x, y and rotation
    kept -- settle_pose's rule with the span's middle for the axle (a top it sank into less than half
    its height is its support; a higher one it sank into more is not). ``pose`` itself over no such
    ground or within SETTLE_TOL of it."""
    height = _land_height(pose, low, high, ground, to_enu)
    t = pose.translation if to_enu is None else to_enu @ pose.translation
    if height is None or abs(height - float(t[2])) <= SETTLE_TOL:
        return pose
    return _at_height(pose, height, to_enu)


def lift_pose(pose: Pose, low: float, high: float, ground: Ground | None, to_enu: np.ndarray | None) -> Pose:
    """A carried solid at ``pose`` (spanning ``low`` to ``high``) held into its support -- the one
    :func:`land_pose` would put it on -- raised so its lowest point lies on that support's top; ``pose``
    itself when it is not below it by more than SETTLE_TOL (held above it, or over none)."""
    height = _land_height(pose, low, high, ground, to_enu)
    t = pose.translation if to_enu is None else to_enu @ pose.translation
    if height is None or height - float(t[2]) <= SETTLE_TOL:
        return pose
    return _at_height(pose, height, to_enu)


TIP_TOL = 1e-6
"""sin of the tilt of a solid's resting face from the ground under which it is taken as resting on it
(kept bit for bit: the small tilts Webots' saved worlds hold, under 1 µm per metre)."""

_SIDE_OR_END = math.sqrt(0.5)     # |cos| of a cylinder's axis from the vertical at 45°: nearer an end above it


def _world_up(to_enu: np.ndarray | None) -> np.ndarray:
    """The world's up as a vector in world axes (ENU's z; the world's y in a NUE world)."""
    return np.array([0.0, 0.0, 1.0]) if to_enu is None else np.array(to_enu[2], dtype=np.float64)


def _down_face(geometry: wm.Box | wm.Cylinder, r: np.ndarray, up: np.ndarray) -> np.ndarray:
    """The outward normal (world axes) of the face a box or cylinder with world rotation ``r`` comes
    to rest on: a box's face whose normal is nearest straight down; a cylinder's end when its axis
    (local z) is within 45° of the vertical, else its side along the line nearest down."""
    if isinstance(geometry, wm.Box):
        ups = r.T @ up                                  # each local axis's upward part
        k = int(np.argmax(np.abs(ups)))
        return -math.copysign(1.0, float(ups[k])) * r[:, k]
    axis = r[:, 2]
    a = float(axis @ up)
    if abs(a) >= _SIDE_OR_END:
        return -math.copysign(1.0, a) * axis
    side = a * axis - up                                # -up without its part along the axis
    return side / float(np.linalg.norm(side))


def resting_pose(solid: wm.Solid, pose: Pose, base_dir: Path, to_enu: np.ndarray | None) -> Pose:
    """The pose a solid with physics at ``pose`` has once it has tipped onto the face under it, as
    Webots' physics lets a box stood on a corner or edge fall onto a face. A solid whose bounding
    shapes are one Box or one Cylinder: that shape turned by the least rotation (about a horizontal axis
    through its centre, so its yaw about the world's up and its centre's x, y kept) that puts
    :func:`_down_face`'s normal straight down. One Sphere keeps its rotation. Any other falling solid
    (meshes, capsules, cones, several shapes: :func:`falling_shapes`) by :func:`_hull_tip`'s rule on
    the convex hull of its shapes' support points; one whose shapes lie on a plane or a line keeps its
    rotation (a GroundWarning says so). ``pose`` itself when the face is within TIP_TOL of lying flat
    and holds the solid up."""
    if not solid.physics:
        return pose
    from sensorium.server.sim.scene import solid_parts

    parts = [(local, shape.geometry) for _, local, shape in solid_parts(solid, Pose.identity())
             if shape.seen_by in ("both", "bounding")]
    if len(parts) == 1 and isinstance(parts[0][1], wm.Sphere):
        return pose
    if len(parts) != 1 or not isinstance(parts[0][1], (wm.Box, wm.Cylinder)):
        return _hull_resting_pose(solid, pose, base_dir, to_enu)
    local, geometry = parts[0]
    shape = pose.compose(local)
    up = _world_up(to_enu)
    normal = _down_face(geometry, shape.rotation, up)
    axis = np.cross(normal, -up)                        # horizontal: both are unit, -up is vertical
    sin = float(np.linalg.norm(axis))
    if sin <= TIP_TOL:
        return pose
    turn = axis_angle_matrix(axis / sin, math.atan2(sin, float(normal @ -up)))
    centre = shape.translation
    return Pose(turn @ pose.rotation, centre + turn @ (pose.translation - centre))


# Support points of curved shapes: rims and rings of _AROUND points, a hemisphere _RINGS rings of
# latitude (π/16 apart) and its pole, all on the true surface, so the hull lies inside the shape by at
# most r·(1 − cos(π/32)), 0.48 % of its radius r, and a resting face's normal is within π/32 of the
# true surface's there (a capsule or cylinder side's facets are parallel to its axis: it lies with its
# axis level, exactly)
_AROUND = 32
_RINGS = 8


def _ring(radius: float, z: float) -> np.ndarray:
    a = np.arange(_AROUND) * (2.0 * math.pi / _AROUND)
    return np.column_stack([radius * np.cos(a), radius * np.sin(a), np.full(_AROUND, z)])


def _dome(radius: float, z: float, sign: float) -> np.ndarray:
    """A hemisphere of ``radius`` centred at height ``z`` of the local axis, towards ``sign``."""
    lat = np.arange(_RINGS) * (math.pi / 2.0 / _RINGS)
    return np.vstack([*(_ring(radius * math.cos(t), z + sign * radius * math.sin(t)) for t in lat),
                      [[0.0, 0.0, z + sign * radius]]])


def support_points(g: object, prim: object) -> np.ndarray:
    """Points (local frame) whose convex hull is the shape's, curved ones sampled (above)."""
    if isinstance(g, wm.Box):
        hx, hy, hz = (float(v) / 2.0 for v in g.size)
        return np.array([[x, y, z] for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)])
    if isinstance(g, wm.Cylinder):
        return np.vstack([_ring(float(g.radius), -float(g.height) / 2.0), _ring(float(g.radius), float(g.height) / 2.0)])
    if isinstance(g, wm.Cone):
        return np.vstack([_ring(float(g.bottom_radius), -float(g.height) / 2.0), [[0.0, 0.0, float(g.height) / 2.0]]])
    if isinstance(g, wm.Sphere):
        return np.vstack([_dome(float(g.radius), 0.0, 1.0), _dome(float(g.radius), 0.0, -1.0)])
    if isinstance(g, wm.Capsule):
        return np.vstack([_dome(float(g.radius), float(g.height) / 2.0, 1.0),
                          _dome(float(g.radius), -float(g.height) / 2.0, -1.0)])
    assert isinstance(prim, geo.Mesh)
    return np.asarray(prim.vertices, dtype=np.float64)


def volume_centre(g: object, prim: object) -> tuple[float, np.ndarray]:
    """A shape's volume and the centre of that volume (local frame), for uniform density: a closed
    mesh's own (signed tetrahedra), an open one's convex hull's, a flat one none."""
    r = float(getattr(g, "radius", 0.0))
    if isinstance(g, wm.Box):
        return float(np.prod(np.asarray(g.size, dtype=np.float64))), np.zeros(3)
    if isinstance(g, wm.Sphere):
        return 4.0 / 3.0 * math.pi * r ** 3, np.zeros(3)
    if isinstance(g, wm.Cylinder):
        return math.pi * r * r * float(g.height), np.zeros(3)
    if isinstance(g, wm.Capsule):
        return math.pi * r * r * (float(g.height) + 4.0 / 3.0 * r), np.zeros(3)
    if isinstance(g, wm.Cone):      # its centroid a quarter of its height above its base
        return math.pi * float(g.bottom_radius) ** 2 * float(g.height) / 3.0, np.array([0.0, 0.0, -float(g.height) / 4.0])
    assert isinstance(prim, geo.Mesh)
    v = np.asarray(prim.vertices, dtype=np.float64)
    if prim.closed and len(prim.faces):
        six, centre = enclosed(v, prim.faces)
        if six != 0.0:
            return abs(six) / 6.0, centre
    try:
        return convex_hull(extreme_points(v)).volume_centroid()
    except FlatPoints:
        return 0.0, v.mean(axis=0)


def hull_2d(xy: np.ndarray) -> np.ndarray:
    """The 2-D convex hull of points, counter-clockwise, no collinear corners (Andrew's monotone chain)."""
    pts = sorted({(float(x), float(y)) for x, y in xy})
    if len(pts) <= 2:
        return np.array(pts, dtype=np.float64).reshape(-1, 2)

    def cross(o: tuple, a: tuple, b: tuple) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    chain: list[tuple[float, float]] = []
    for sweep in (pts, pts[::-1]):
        half: list[tuple[float, float]] = []
        for p in sweep:
            while len(half) >= 2 and cross(half[-2], half[-1], p) <= 0.0:
                half.pop()
            half.append(p)
        chain += half[:-1]
    return np.array(chain, dtype=np.float64).reshape(-1, 2)


def _tipping_edge(poly: np.ndarray, q: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The edge of the resting polygon ``poly`` (counter-clockwise) a centre over ``q`` tips the solid
    across, as (a point of it, its outward unit normal): the nearest edge ``q`` is beyond (more than
    ``tol``), the one it is farthest beyond on a tie (a corner nearest); None when ``q`` is over the
    polygon (or within ``tol`` of its edges)."""
    best = None
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        d = b - a
        length = float(np.hypot(d[0], d[1]))
        m = np.array([d[1], -d[0]]) / length
        beyond = float((q - a) @ m)
        if beyond <= tol:
            continue
        t = min(max(float((q - a) @ d) / (length * length), 0.0), 1.0)
        gap = float(np.hypot(*(q - a - t * d)))
        if best is None or (gap, -beyond) < best[0]:
            best = ((gap, -beyond), a, m)
    return None if best is None else (best[1], best[2])


def over_support(xy: np.ndarray, q: np.ndarray, tol: float) -> bool:
    """Whether the point ``q`` (x, y) is over (within ``tol`` of) what the points ``xy`` span seen from
    above: their convex polygon, or the segment or point they make (the Supervisor's static balance,
    sim/balance.py, and :func:`_balanced`)."""
    poly = hull_2d(xy)
    if len(poly) >= 3:
        return _tipping_edge(poly, q, tol) is None
    a, b = poly[0], poly[-1]
    d = b - a
    t = 0.0 if len(poly) == 1 else min(max(float((q - a) @ d) / float(d @ d), 0.0), 1.0)
    return float(np.hypot(*(q - a - t * d))) <= tol


def _balanced(corners: np.ndarray, centre: np.ndarray, tol: float) -> bool:
    """Whether the centre is over (within ``tol`` of) what the lowest corners span seen from above: a
    face, an edge or a point it stands on as it is (an upright capsule on its pole, Webots' balance)."""
    low = corners[corners[:, 2] <= float(corners[:, 2].min()) + tol][:, :2]
    return over_support(low, centre[:2], tol)


def _hull_tip(points: np.ndarray, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """How a solid whose support points (ENU) are ``points`` and centre of mass ``centre`` tips onto
    its hull: (turn, shift), the map x → turn·x + shift of ENU points, or None when it rests as it is.

    It stays when its centre is over the face, edge or point its lowest corners span (:func:`_balanced`).
    Else, as a box's rule (:func:`resting_pose`): the hull face whose outward normal is nearest straight
    down is laid flat by the least rotation about a horizontal axis through the centre (none within
    TIP_TOL). Then, while the centre seen from above is off that face's polygon (its corners within
    the hull's tolerance of the ground), the solid tips about the polygon's edge nearest it
    (:func:`_tipping_edge`), that edge staying on the ground, until the next hull corner touches: the
    next face. Each tip lowers the centre, so no face comes twice. :class:`FlatPoints` for points on a
    plane or a line."""
    if _balanced(points, centre, hull_tolerance(points)):
        return None      # (the lowest points span what the lowest corners do: no hull needed to stay)
    hull = convex_hull(points)
    corners = hull.points[hull.vertices]
    tol = hull.tolerance
    down = np.array([0.0, 0.0, -1.0])
    normal = hull.normals[int(np.argmax(hull.normals @ down))]
    turn, shift = np.eye(3), np.zeros(3)
    axis = np.cross(normal, down)
    sin = float(np.linalg.norm(axis))
    tipped = sin > TIP_TOL
    if tipped:
        turn = axis_angle_matrix(axis / sin, math.atan2(sin, float(normal @ down)))
        shift = centre - turn @ centre
    for _ in range(2 * len(corners) + 2):
        at = corners @ turn.T + shift
        ground = float(at[:, 2].min())
        poly = hull_2d(at[at[:, 2] <= ground + tol][:, :2])
        if len(poly) < 3:
            break
        edge = _tipping_edge(poly, (turn @ centre + shift)[:2], tol)
        if edge is None:
            break
        a, m = edge
        pivot = np.array([a[0], a[1], ground])
        out = np.array([m[0], m[1], 0.0])
        rel = at - pivot
        s, z = rel @ out, rel[:, 2]
        past = s > tol
        if not past.any():          # (the centre is inside the hull: some corner is beyond it)
            break
        theta = float(np.arctan2(z[past], s[past]).min())
        step = axis_angle_matrix(np.cross([0.0, 0.0, 1.0], out), theta)
        turn, shift = step @ turn, step @ (shift - pivot) + pivot
        tipped = True
    return (turn, shift) if tipped else None


def _hull_resting_pose(solid: wm.Solid, pose: Pose, base_dir: Path, to_enu: np.ndarray | None) -> Pose:
    """:func:`resting_pose` for a solid of several shapes, a mesh, a capsule or a cone: its shapes'
    support points and centre of mass (its Physics' masses where the world gives them, mesh files'
    volumes weighed by the loader, else uniform density over their volumes), placed at ``pose`` in ENU,
    tipped by :func:`_hull_tip`."""
    shapes = falling_shapes(solid, base_dir)
    if shapes is None:
        return pose
    # its Physics' masses (the .wbt import's and the loader's, Webots' rules, mesh files' volumes
    # included) over uniform density: the shapes' volumes are weighed only without them
    weighed = _mass_centre(solid)
    points, volumes, centres = [], [], []
    for local, prim, g in shapes:
        at = enu_pose(pose.compose(local), to_enu)
        points.append(support_points(g, prim) @ at.rotation.T + at.translation)
        if weighed is None:
            volume, centre = volume_centre(g, prim)
            volumes.append(volume)
            centres.append(at.rotation @ centre + at.translation)
    cloud = np.vstack(points)
    if weighed is not None:
        placed = enu_pose(pose, to_enu)
        centre = placed.rotation @ weighed + placed.translation
    else:
        total = sum(volumes)
        centre = (sum(v * c for v, c in zip(volumes, centres)) / total) if total > 0.0 else cloud.mean(axis=0)
    try:
        got = _hull_tip(extreme_points(cloud), centre)
    except FlatPoints as flat:
        warnings.warn(f"solid {solid.name!r}: its bounding shapes lie {flat.where}, "
                      "no face to tip onto: it keeps its rotation", GroundWarning, stacklevel=2)
        return pose
    if got is None:
        return pose
    turn, shift = got
    t = np.eye(3) if to_enu is None else np.asarray(to_enu, dtype=np.float64)
    return Pose(t.T @ turn @ t @ pose.rotation, t.T @ (turn @ (t @ pose.translation) + shift))


def _mass_centre(solid: wm.Solid) -> np.ndarray | None:
    """The centre of mass, in the solid's frame, of a solid with a Physics mass and of the solids inside
    it with one (as the Supervisor's getCenterOfMass weighs them); None without a mass of its own."""
    if solid.mass is None:
        return None
    weighted = [(solid.mass.kg, np.asarray(solid.mass.center, dtype=np.float64))]
    stack = [(child, pose_from_model(child.pose)) for child in solid.children]
    while stack:
        child, at = stack.pop()
        if child.mass is not None:
            weighted.append((child.mass.kg, at.rotation @ np.asarray(child.mass.center, dtype=np.float64)
                             + at.translation))
        stack += [(inner, at.compose(pose_from_model(inner.pose))) for inner in child.children]
    return sum(kg * c for kg, c in weighted) / sum(kg for kg, _ in weighted)


def land_solid(solid: wm.Solid, pose: Pose, base_dir: Path, ground: Ground | None,
               to_enu: np.ndarray | None) -> Pose:
    """Where a top-level solid let go at ``pose`` comes to rest: over a support (:func:`land_pose`'s
    rule), tipped onto the face under it (:func:`resting_pose`) and then put straight down (or up)
    on that support, its lowest point on its top. ``pose`` itself for a solid that does not fall
    (:func:`falling_span`), over no support (judged tipped), or already resting there (within TIP_TOL
    and SETTLE_TOL)."""
    got = _tipped_span(solid, pose, base_dir, to_enu)
    if got is None:
        return pose
    tipped, (low, high, _) = got
    if tipped is pose:
        return land_pose(pose, low, high, ground, to_enu)
    height = _land_height(tipped, low, high, ground, to_enu)
    return pose if height is None else _at_height(tipped, height, to_enu)


def _tipped_span(solid: wm.Solid, pose: Pose, base_dir: Path, to_enu: np.ndarray | None
                 ) -> tuple[Pose, tuple[float, float, np.ndarray]] | None:
    """A falling solid at ``pose`` tipped onto the face under it (:func:`resting_pose`; ``pose`` itself
    when it does not tip) and its :func:`falling_span` there; None for a solid that does not fall."""
    span = falling_span(solid, base_dir, to_enu, pose)
    if span is None:
        return None
    tipped = resting_pose(solid, pose, base_dir, to_enu)
    if tipped is pose:
        return pose, span
    turned = falling_span(solid, base_dir, to_enu, tipped)
    assert turned is not None            # the same shapes, turned: they still fall
    return tipped, turned


def falling_shapes(solid: wm.Solid, base_dir: Path) -> list[tuple[Pose, object, object]] | None:
    """The bounding shapes of a top-level solid that falls -- ``physics``, at least one bounding shape,
    none of them a Plane or ElevationGrid (those are ground, static in Webots' physics too) -- as (pose
    in the solid's frame, primitive, geometry model); None for any other solid."""
    from sensorium.server.sim.scene import primitive_from_model, solid_parts

    if not solid.physics:
        return None
    shapes = []
    for _, local, shape in solid_parts(solid, Pose.identity()):
        if shape.seen_by not in ("both", "bounding"):
            continue
        if isinstance(shape.geometry, (wm.Plane, wm.ElevationGrid)):
            return None
        shapes.append((local, primitive_from_model(shape.geometry, base_dir), shape.geometry))
    return shapes or None


def _exact_reach(prim: object, r: np.ndarray) -> float | None:
    """How far a Box, Sphere, Cylinder or Capsule with ENU rotation ``r`` reaches above and below its
    centre, exactly (:func:`geometry.reach`), where contact.obstacle bounds a tilted cylinder by its
    circumscribed facets; None for other shapes."""
    if isinstance(prim, (geo.Box, geo.Sphere, geo.Cylinder, geo.Capsule)):
        return geo.reach(prim, r[2, :])
    return None


def shapes_span(shapes: list[tuple[Pose, object, object]], pose: Pose, to_enu: np.ndarray | None,
                footprint: bool = True) -> tuple[float, float, np.ndarray | None] | None:
    """(lowest, highest point, xy box (x0, y0, x1, y1)) in ENU of :func:`falling_shapes` at ``pose``:
    a Box's, Sphere's, Cylinder's or Capsule's heights exact (:func:`_exact_reach`), any other shape's
    as kinematic contact takes it (contact.obstacle, which gives every xy box); None when none of them
    is an obstacle. ``footprint`` False: the heights alone (the xy box None)."""
    spans: list[tuple[float, float]] = []
    boxes = []
    for local, prim, _ in shapes:
        at = enu_pose(pose.compose(local), to_enu)
        reach = _exact_reach(prim, at.rotation)
        ob = obstacle("shape", -1, prim, at) if footprint or reach is None else None
        if reach is not None:
            z = float(at.translation[2])
            spans.append((z - reach, z + reach))
        elif ob is not None:
            spans.append(ob.z_range)
        else:
            continue
        if ob is not None:
            boxes.append([*(ob.points.min(axis=0) - ob.radius), *(ob.points.max(axis=0) + ob.radius)])
    if not spans:
        return None
    box = None
    if footprint:
        xy = np.array(boxes)
        box = np.array([xy[:, 0].min(), xy[:, 1].min(), xy[:, 2].max(), xy[:, 3].max()])
    return min(lo for lo, _ in spans), max(hi for _, hi in spans), box


def falling_span(solid: wm.Solid, base_dir: Path, to_enu: np.ndarray | None,
                 pose: Pose | None = None) -> tuple[float, float, np.ndarray] | None:
    """:func:`shapes_span` of a top-level solid's :func:`falling_shapes` at ``pose`` (default its
    world-file pose): the one span every falling solid is judged by (settling at load, landing, a
    carried load's support); None for a solid that does not fall."""
    shapes = falling_shapes(solid, base_dir)
    if shapes is None:
        return None
    return shapes_span(shapes, pose_from_model(solid.pose) if pose is None else pose, to_enu)


def _settle_solids(world: wm.World, to_enu: np.ndarray | None, base_dir: Path, source: str, caught: Collection[str]
                   ) -> tuple[wm.World, list[str]]:
    """The world with its top-level solids with physics landed at load (settle_world's first part) and
    their note lines.

    Lowest first (by their lowest point; world order on a tie), each lands as :func:`land_pose` lands a
    solid let go, on the ground of what is settled already: every solid that does not fall (no physics,
    no bounding shape, a Plane or ElevationGrid among them) and the robots without a drive as the world
    file places them, and the solids with physics landed before it where they landed (a box stacked on
    a box lands on it once that one has landed). A solid with physics not yet landed is no support. The
    solids in ``caught`` (held by a VacuumGripper from the first step: vacuum.caught_at_load) stay."""
    poses = {s.name: pose_from_model(s.pose) for s in world.solids}
    # each falling solid tipped onto the face under it first (resting_pose), then landed as it lies
    falling = []
    for i, s in enumerate(world.solids):
        if s.name not in caught and (got := _tipped_span(s, poses[s.name], base_dir, to_enu)) is not None:
            falling.append((i, s, got[1], got[0]))
    if not falling:
        return world, []
    moving = {i for i, *_ in falling}
    floors = [(r, pose_from_model(r.pose)) for r in world.robots if not r.drive_motors]
    still = settling_ground([(s, poses[s.name]) for i, s in enumerate(world.solids) if i not in moving], floors, to_enu)
    falling.sort(key=lambda f: f[2][0])          # lowest first (a stable sort: world order on a tie)
    ts = [pose.translation if to_enu is None else to_enu @ pose.translation for *_, pose in falling]
    xs, ys, zs = (np.array([float(t[k]) for t in ts]) for k in range(3))
    lows = np.array([f[2][0] for f in falling])
    highs = np.array([f[2][1] for f in falling])
    boxes = np.array([f[2][2] for f in falling]).reshape(-1, 4)
    # the ground that stays, under every falling solid in one call; the landed ones below, one by one
    found, heights = ((np.zeros(len(falling), dtype=bool), np.zeros(len(falling))) if still is None
                      else _landing_heights(still, xs, ys, zs, lows, highs))
    up, sign = _up_axis(to_enu)
    solids = list(world.solids)
    landed = Ground([], {}, to_enu)               # the falling solids already landed, each added where it landed
    moved: list[tuple[str, float, float, bool]] = []
    for k, (i, solid, _, tipped) in enumerate(falling):
        # asked only when one of them may be under it (its shapes' xy box holds the origin: x, y never change)
        if (k and ((boxes[:k, 0] <= xs[k]) & (xs[k] <= boxes[:k, 2]) & (boxes[:k, 1] <= ys[k])
                   & (ys[k] <= boxes[:k, 3])).any()):
            on, h = _landing_heights(landed, xs[k:k + 1], ys[k:k + 1], zs[k:k + 1], lows[k:k + 1], highs[k:k + 1])
            if on[0] and (not found[k] or h[0] > heights[k]):
                found[k], heights[k] = True, h[0]
        height = float(heights[k])
        turned = tipped is not poses[solid.name]
        if found[k] and (turned or not abs(height - float(zs[k])) <= SETTLE_TOL):
            translation = [float(v) for v in tipped.translation] if turned else list(solid.pose.translation)
            translation[up] = sign * height
            update: dict = {"translation": tuple(translation)}
            if turned:                  # its rotation as the world file wrote it (axis-angle or quaternion)
                update.update({"rotation": None, "quaternion": matrix_quaternion(tipped.rotation)}
                              if solid.pose.quaternion is not None else {"rotation": tuple(axis_angle(tipped.rotation))})
            solid = solids[i] = solid.model_copy(update={"pose": solid.pose.model_copy(update=update)})
            moved.append((solid.name, float(zs[k]), height, turned))
        landed.add_solid(solid, pose_from_model(solid.pose))
    notes = [f"{source}: solid {name!r} settled on the ground at load, as Webots' physics drops it: "
             f"{'tipped onto a face, ' if turned else ''}its origin's {'xyz'[up]} from {sign * z:.4f} to {sign * h:.4f} m"
             for name, z, h, turned in moved if turned or abs(h - z) > SETTLE_NOTE]
    if len(notes) > SETTLE_NOTES:
        notes = [*notes[:SETTLE_NOTES], f"{source}: {len(notes) - SETTLE_NOTES} more solids settled on the ground at load"]
    return (world.model_copy(update={"solids": solids}) if moved else world), notes


def settle_world(world: wm.World, to_enu: np.ndarray | None, source: str, base_dir: Path,
                 caught: Collection[str] = ()) -> tuple[wm.World, list[str]]:
    """The world with its top-level solids with physics and its wheeled robots settled on the ground,
    as Webots' physics drops them at load, and one note line per solid or robot moved by more than
    SETTLE_NOTE (at most SETTLE_NOTES of each, then a count). ``base_dir``: where the world's meshes are;
    ``caught``: the solids a VacuumGripper holds from the first step (they stay).

    The solids first (:func:`_settle_solids`: each on the highest support under its origin, by
    :func:`land_pose`'s rule), then the robots on the world so settled.

    A robot is settled when its drive gives ``wheel_bottom`` and it stands upright (its z axis the
    world's up, or in a NUE world its y: :func:`robot_up`): its height becomes ``ground −
    wheel_bottom``, so its lowest wheel's bottom touches the ground under its origin; x, y and its
    rotation are kept. The ground is :func:`settling_ground`'s, under the ceiling ``max(origin,
    wheel bottom + smallest wheel radius) + FLOOR``: a box top above its wheels' axle (and its
    origin) is something it sank into, not its floor. The shapes of robots without a drive are
    ground here too, as the world loads them (Webots' physics drops a robot on any bounding object).
    Over no ground, off by at most SETTLE_TOL, or not upright, a robot keeps its pose bit for bit."""
    world, solid_notes = _settle_solids(world, to_enu, base_dir, source, caught)
    leaning = [i for i, r in enumerate(world.robots)
               if to_enu is None and car_lean(r) is not None and lean_pose(r, pose_from_model(r.pose), None, None)[1]]
    settling = [(i, r, got) for i, r in enumerate(world.robots)
                if i not in leaning and (got := _upright_wheels(r, pose_from_model(r.pose), to_enu)) is not None]
    if not settling and not leaning:
        return world, solid_notes
    ground = settling_ground([(s, pose_from_model(s.pose)) for s in world.solids],
                             [(r, pose_from_model(r.pose)) for r in world.robots if not r.drive_motors], to_enu)
    if ground is None:
        return world, solid_notes
    robots = list(world.robots)
    lean_notes = []
    for i in leaning:       # cars on wheels of two sizes: onto both axles (ground.lean_pose)
        robot = robots[i]
        before = pose_from_model(robot.pose)
        after, _ = lean_pose(robot, before, ground, None)
        if after is None or after is before:
            continue
        axis, angle = axis_angle(after.rotation)[:3], axis_angle(after.rotation)[3]
        robots[i] = robot.model_copy(update={"pose": wm.Pose(translation=tuple(float(v) for v in after.translation),
                                                             rotation=(*axis, angle))})
        theta = car_lean(robot)[0]  # type: ignore[index]
        lean_notes.append(f"{source}: robot {robot.name!r} settled on the ground at load, as Webots' physics drops it: "
                          f"leaning {theta:.4f} rad about its y on its wheels of two sizes (both axles now touch the "
                          f"ground under it), its origin's z from {float(before.translation[2]):.4f} to "
                          f"{float(after.translation[2]):.4f} m")
    if not settling:
        return world.model_copy(update={"robots": robots}), [*solid_notes, *lean_notes]
    up, sign = _up_axis(to_enu)
    # every robot's ground in one call (element-wise: the bits settle_pose gives one robot)
    bottoms, axles, xs, ys, zs = (np.array(c) for c in zip(*[(b, a, float(t[0]), float(t[1]), float(t[2]))
                                                               for _, _, (b, a, t) in settling]))
    move, heights = _settled(ground, bottoms, axles, xs, ys, zs)
    moved: list[tuple[str, float, float]] = []
    for k, (i, robot, _) in enumerate(settling):
        if not move[k]:
            continue
        height = float(heights[k])
        translation = list(robot.pose.translation)
        translation[up] = sign * height
        robots[i] = robot.model_copy(update={"pose": robot.pose.model_copy(update={"translation": tuple(translation)})})
        moved.append((robot.name, float(zs[k]), height))
    axis = "xyz"[up]
    notes = [f"{source}: robot {name!r} settled on the ground at load, as Webots' physics drops it: its origin's "
             f"{axis} from {sign * z:.4f} to {sign * h:.4f} m (its lowest wheel now touches the ground under it)"
             for name, z, h in moved if abs(h - z) > SETTLE_NOTE]
    if len(notes) > SETTLE_NOTES:
        more = len(notes) - SETTLE_NOTES
        notes = [*notes[:SETTLE_NOTES], f"{source}: {more} more robots settled on the ground at load"]
    return (world.model_copy(update={"robots": robots}) if moved or lean_notes else world), \
        [*solid_notes, *lean_notes, *notes]
