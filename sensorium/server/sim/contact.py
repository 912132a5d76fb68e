"""Kinematic contact: a driven robot's body cannot enter solids (as bounding rays see them) or
other robots' bodies. No physics engine: a blocked robot *slides* along what it touched.

Robots move in the world xy-plane, so contact is solved in 2D within each robot's height band:

* a robot's footprint follows its shape: one convex piece ``hull(points) ⊕ disc(r)`` in its
  frame, turned with its heading -- an upright box its rectangle, an upright cylinder, capsule or
  sphere its circle, a tilted box or mesh the outline of its projection, a tilted cylinder its end
  discs' circumscribed 16-gons; several shapes the hull of their outlines, a part inside a round
  part's disc dropped and a part rounder than the rest its circumscribed 16-gon
  (:func:`robot_footprint`). A robot that is one centred upright cylinder is the disc it always
  was, on the old path, bit for bit. The disc about the origin holding the piece at every heading
  (``Footprint.radius``) is the broad phase's. A concave body -- its hull's area more than CONCAVE
  (1 %) over its shapes' union -- is its convex pieces (``Footprint.pieces``: the shapes grouped at
  load while a group's hull adds under 1 %), each in its own band, any of them stopping it
  (:meth:`Contact._clip_pieces`; its turn pushed off by its pieces, :meth:`Contact._push_by_pieces`,
  else as its hull's push, :meth:`Contact._push_pieces`);
* an obstacle is a convex 2D set ``hull(points) ⊕ disc(radius)``: an upright box is its 4
  corners, an upright cylinder or capsule a point with its radius, a sphere a point with the
  radius of its widest section inside the band, anything else the convex hull of its projected
  vertices (conservative); a vertical infinite plane is a two-sided wall line. Shapes entirely
  above or below the robot's band and terrains (ElevationGrids, ground whatever their relief) are
  ignored, and so is a solid whose top is at most ``FLOOR`` (1 mm) above the bottom of the band:
  the floor the robot rests on or has sunk into (a Box or any solid used as the floor), not an
  obstacle. Webots' soft contacts let a settled robot sink into its floor -- worlds saved from
  Webots put an e-puck at z = -6.4e-05 m, tens of µm, and heavier robots a fraction of a mm --
  and a robot sunk so into a floor Box would otherwise start inside it and never drive toward
  its centre. A millimetre covers those settled poses several times over and stays below
  anything a robot's body should be stopped by; a solid rising more than that into the band is
  an obstacle. Robots' bodies meet one another without the tolerance (robots never stand on
  robots). A solid a robot's VacuumGripper holds (:meth:`Contact.hold`) is no obstacle to that
  robot, nor touched by its bumpers (Webots' fixed joint makes them one body); it stays one to the
  others. Its shapes are pieces of the carrier's outline, each with its own height band (the floor
  rule per piece), so the carrier stops where its load meets something; the carrier's own footprint,
  band and floor line stay its own (:meth:`Contact._clip_carrying`: its turn cut short, never pushed). A solid's ramp (a tilted Box whose top face leans less than 45°, :func:`ramp_top`)
  tops out, for this rule, at its top face's low edge: a robot that can drive on at that edge rides
  the ramp (ground.py) and is never stopped by its box; for one below the edge it is an obstacle;
* over one basic step a shaped robot first turns in place at its start, as far as the footprint
  sweeping through the turn overlaps nothing it did not already overlap, or deeper (each vertex's
  arc about the centre tested in closed form, :func:`turn_gap_holds`); where the turn would go into something,
  the whole turn is kept and the centre pushed off it the least distance, to touching
  (:meth:`Contact._push`, closed form; in a corner of two polygons, off both at once:
  :meth:`Contact._push_off_both`; where the turn ends clear of it but a corner's arc dips into it
  on the way, past the peak of its reach, off by as far as the arc went in, off two at once where
  it dips into both walls of a corner: :meth:`Contact._push_sweep`), unless that push meets something else: then the turn is
  cut short, found by halving to 2^-12 of the step's turn (either counts as a contact); then its centre moves along the chord from
  its start to its end pose (poses are only observed at the end of steps, and the end point is
  the exact arc end unless contact clips it) at the heading it kept. The chord is tested against
  every obstacle near it (an AABB broad phase) in closed form — segment vs. offset edges and
  vertex circles of the obstacle grown by the footprint: for a disc ``obstacle ⊕ disc(R)``, for a
  piece ``hull(Q − P) ⊕ disc(ρ + r)`` with P the turned piece's points (the Minkowski sum of
  convex sets, :func:`_grown`), for a wall line its reach toward the wall — so a fast robot at a
  grazing angle cannot tunnel, whatever the step length. Features the chord
  certainly cannot reach (plain float screens, margins far above the tests' rounding) are not
  tested: the answer of testing them all, bit for bit. Likewise the turn test is answered before its
  arcs where a screen proves it False (:func:`turn_gap_holds`), an obstacle grown by a turned
  footprint is made once per heading (:func:`_grown`), and moves near nothing end all at once
  (:meth:`Contact.resolve_all`): the same answers, bit for bit.

On contact the robot stops at the contact point and the rest of its displacement is projected on
the contact's tangent (slide), up to three times per step (corners). A robot pushed straight into
a wall therefore stops at the contact distance; one meeting it obliquely keeps the tangential
part of its motion, as a Webots robot rubbing along a wall does. A disc turns freely; a shaped
robot can always back out along its heading (a move that goes no deeper is free), turn the way
that frees its corner, and turn the other way pushed off the wall (off both walls of a corner)
but in a corridor too narrow for the push. Deterministic: robots are resolved in world order, each against the others'
current positions and headings. Float64 throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose

EPS = 1e-9            # m: "touching" tolerance
FLOOR = 1e-3          # m: a solid whose top is at most this above a robot band's bottom is its floor
BACK_OFF = 1e-12      # m: contact points are placed this far outside, never on or inside
MAX_SLIDES = 3
TURN_HALVINGS = 12    # a turn cut short by contact is found to 2^-12 of the step's turn
UPRIGHT = 1.0 - 1e-12
BOX_UPRIGHT_TOL = 1e-12   # |tilt| of a box's local axis from the world's up still upright (its top a flat floor)
# a tilted box whose top face leans less than this from the world's up is a ramp (ground.py). Below 45°
# at most one face can be its top (three orthogonal normals' up components squared sum to 1)
RAMP_MAX_TILT = math.pi / 4


def deepest_end(gap: float, p: np.ndarray) -> float:
    """The least signed distance a move or turn that starts ``gap`` from something (negative:
    overlapping) may end at: touching or within the tolerance, -EPS, whatever the steps (so a robot
    turning into a solid by steps of less than EPS each stops EPS in; a bound on each move's change
    let it creep in step by step); overlapping deeper (placed so from outside), no deeper than it
    starts, less a rounding slack of 4e-15 of the coordinates (~18 ulps: two distances found apart,
    at a slide's start and end, may round that much deeper; taken for going in, it stalled the robot)."""
    if gap >= -EPS:
        return -EPS
    return gap - 4e-15 * (1.0 + abs(float(p[0])) + abs(float(p[1])))


def ramp_top(r: np.ndarray, t: np.ndarray, half: tuple[float, float, float]) -> tuple[int, float, np.ndarray, float] | None:
    """A box (rotation ``r``, centre ``t`` in ENU, half sizes ``half``) that is a ramp: not upright
    (none of its axes within BOX_UPRIGHT_TOL of the world's up: ground.py's box tops) and its top
    face -- the one whose outward normal is most upward -- tilted less than RAMP_MAX_TILT. Returns
    (the local axis of that normal, its sign, the box's 8 corners ``corners @ r.T + t`` as
    :func:`obstacle` computes them, the top face's lowest corner height: its **low edge**), else
    None. Kinematic contact takes the low edge as the ramp's top (the floor rule) and ground.py
    takes it for the support rule, so a ramp is a robot's ground or its obstacle, never both."""
    if any(abs(r[0, k]) <= BOX_UPRIGHT_TOL and abs(r[1, k]) <= BOX_UPRIGHT_TOL
           and all(abs(r[2, j]) <= BOX_UPRIGHT_TOL for j in range(3) if j != k) for k in range(3)):
        return None
    k = max(range(3), key=lambda a: abs(float(r[2, a])))
    sign = 1.0 if r[2, k] > 0.0 else -1.0
    if not sign * float(r[2, k]) > math.cos(RAMP_MAX_TILT):
        return None
    hx, hy, hz = half
    local = np.array([[x, y, z] for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)])
    corners = local @ r.T + t
    top = local[:, k] == sign * half[k]
    return k, sign, corners, float(corners[top, 2].min())


@dataclass(slots=True)
class Obstacle:
    """``hull(points) ⊕ disc(radius)`` in world xy (points counter-clockwise), or a wall line
    ``normal · p + offset = 0`` when ``normal`` is set."""

    name: str
    owner: int                              # robot index, -1 for a solid
    points: np.ndarray                      # (n, 2), n >= 1
    radius: float
    z_range: tuple[float, float]
    normal: np.ndarray | None = None        # wall line
    offset: float = 0.0
    sphere: bool = False                    # a sphere: its section depends on the height band
    edge_normals: bool = False              # touching an edge, its normal is the edge's (_closest_on_list)
    lo: np.ndarray = field(default_factory=lambda: np.zeros(2))
    hi: np.ndarray = field(default_factory=lambda: np.zeros(2))
    # per grown radius: the vertices as floats and the edges offset by it (_hull_data; points never change)
    grown: dict = field(default_factory=dict, init=False, repr=False, compare=False)
    # lo, hi and the vertices as floats (_flat), made when first needed
    flat: tuple | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        pts = self.points
        if self.normal is None and 1 < len(pts) <= 16 and self._small_post_init():
            return
        if len(pts) > 1:
            # vertices that coincide (a footprint 1e-12 m thin turned and moved 1e5 m from the origin
            # rounds two corners to one point): one of them, never an edge of no length or direction
            same = (pts == np.roll(pts, -1, axis=0)).all(axis=1)
            if same.any():
                self.points = pts[:1] if same.all() else pts[~same]
        if self.normal is not None:
            self.lo = np.full(2, -math.inf)
            self.hi = np.full(2, math.inf)
        elif len(self.points) == 1:     # one point (a robot's disc, a pillar): it is its min and max
            self.lo = self.points[0] - self.radius
            self.hi = self.points[0] + self.radius
        else:
            self.lo = self.points.min(axis=0) - self.radius
            self.hi = self.points.max(axis=0) + self.radius

    def _small_post_init(self) -> bool:
        """__post_init__ of a hull of a few vertices in plain floats (a grown footprint is made every
        step it turns near something): done, True, where no two neighbours coincide, every coordinate
        is finite and no extreme is a zero (whose sign numpy's min and max may pick otherwise); else
        False, for numpy's way. The same lo and hi, bit for bit; the vertices then keep their array."""
        v = self.points.tolist()
        px, py = v[-1]
        for x, y in v:
            if x == px and y == py:
                return False
            px, py = x, y
        xs = [p[0] for p in v]
        ys = [p[1] for p in v]
        if not -math.inf < sum(xs) + sum(ys) < math.inf:        # a NaN or an infinity (or a sum that overflows)
            return False
        x0, y0, x1, y1 = min(xs), min(ys), max(xs), max(ys)
        if not (x0 and y0 and x1 and y1):
            return False
        r = self.radius
        self.lo = np.array([x0 - r, y0 - r])
        self.hi = np.array([x1 + r, y1 + r])
        self.flat = (x0 - r, y0 - r, x1 + r, y1 + r, v)
        return True


@dataclass(slots=True)
class Footprint:
    """A robot's footprint and height band relative to its origin (ENU axes, its heading taken
    out: :func:`enu_body`): ``hull(points) ⊕ disc(round)`` (points counter-clockwise), and
    ``radius`` a disc about the origin that contains it at every heading (the broad phase's).
    ``points`` None: the disc of ``radius`` about the origin itself."""

    radius: float
    z_low: float
    z_high: float
    points: np.ndarray | None = None
    round: float = 0.0
    # a concave body (:func:`robot_footprint`'s rule): its convex pieces, each a Footprint in the same
    # frame with its own band; the hull above stays the broad phase's. None: the hull is the footprint
    pieces: tuple[Footprint, ...] | None = None
    # which shapes (their indices among those with a footprint) make each piece, as decided when the
    # robot loaded: a joint moving its shapes keeps the grouping (:meth:`Contact.reshape`). () the hull
    groups: tuple[tuple[int, ...], ...] = ()

    @property
    def disc(self) -> bool:
        """Whether the footprint is a disc about the origin (of radius ``round``; ``radius`` with no
        points): it turns freely, and a centred upright cylinder's is its radius, as it always was."""
        p = self.points
        return p is None or (len(p) == 1 and p[0, 0] == 0.0 and p[0, 1] == 0.0)

    @property
    def disc_radius(self) -> float:
        """The radius of a :attr:`disc` footprint."""
        return self.radius if self.points is None else self.round


# ---------------------------------------------------------------------- shapes → 2D

def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise, no collinear points) of 2D points; 1 or 2 points if degenerate."""
    pts = sorted({(float(x), float(y)) for x, y in points})
    if len(pts) <= 2:
        return np.array(pts, dtype=np.float64)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1], dtype=np.float64)


def footprint(prim: geo.Primitive) -> Footprint | None:
    """The disc containing a robot body (in the robot's frame, robot assumed upright)."""
    if isinstance(prim, geo.Box):
        sx, sy, sz = prim.size
        return Footprint(math.hypot(sx, sy) / 2.0, -sz / 2.0, sz / 2.0)
    if isinstance(prim, geo.Cylinder):
        return Footprint(prim.radius, -prim.height / 2.0, prim.height / 2.0)
    if isinstance(prim, geo.Capsule):
        h = prim.height / 2.0 + prim.radius
        return Footprint(prim.radius, -h, h)
    if isinstance(prim, geo.Sphere):
        return Footprint(prim.radius, -prim.radius, prim.radius)
    if isinstance(prim, geo.Mesh):
        v = prim.vertices
        if len(v) == 0:
            return None
        return Footprint(float(np.max(np.hypot(v[:, 0], v[:, 1]))), float(v[:, 2].min()), float(v[:, 2].max()))
    return None                                  # a plane body: no footprint


def _z_extent(prim: geo.Primitive, rotation: np.ndarray) -> tuple[float, float]:
    """The lowest and highest points of a centred shape turned by ``rotation``, along z (exact)."""
    up = rotation[2]                              # the world z axis in the shape's frame
    if isinstance(prim, geo.Box):
        e = 0.5 * float(np.abs(up) @ np.asarray(prim.size, dtype=np.float64))
    elif isinstance(prim, geo.Cylinder):
        az = min(1.0, abs(float(up[2])))
        e = prim.height / 2.0 * az + prim.radius * math.sqrt(1.0 - az * az)
    elif isinstance(prim, geo.Capsule):
        e = prim.height / 2.0 * abs(float(up[2])) + prim.radius
    elif isinstance(prim, geo.Sphere):
        e = prim.radius
    elif isinstance(prim, geo.Mesh):
        z = prim.vertices @ up
        return float(z.min()), float(z.max())
    else:
        return -math.inf, math.inf
    return -e, e


def robot_footprint(parts: list[tuple[geo.Primitive, Pose]],
                    grouping: tuple[tuple[int, ...], ...] | None = None) -> Footprint | None:
    """A robot's footprint from its body shapes, each at its pose in the robot frame: the convex
    piece holding their outlines (:func:`_section`, :func:`_body_section`), the height band, and
    the disc about the origin holding the piece at any heading (the old footprint's radius, which
    it always was, or wider where a tilted round part's circumscribed polygon reaches past it).
    ``grouping``: the shapes' pieces as an earlier footprint of the same shapes grouped them
    (:attr:`Footprint.groups`); None: decided here (:func:`_concave_groups`)."""
    feet = []
    bands: list[Footprint] = []             # per shape with a footprint: its band (and its section below)
    sections: list[tuple[np.ndarray, float] | None] = []
    for prim, local in parts:
        f = footprint(prim)
        if f is None:
            continue
        x, y, z = (float(v) for v in local.translation)
        if not np.allclose(local.rotation, np.eye(3)):
            # a tilted shape: its disc bounded by its circumscribed sphere, its height band exact (a
            # wheel, a cylinder turned to lie on its side, reaches down exactly its radius: the
            # sphere's band would sink it into the floor Box it rolls on)
            r = math.hypot(f.radius, max(abs(f.z_low), abs(f.z_high)))
            lo, hi = _z_extent(prim, np.asarray(local.rotation, dtype=np.float64))
            f = Footprint(r, max(lo, -r), min(hi, r))
        feet.append(Footprint(math.hypot(x, y) + f.radius, z + f.z_low, z + f.z_high))
        bands.append(feet[-1])
        sections.append(_section(prim, local))
    if not feet:
        return None
    radius = max(f.radius for f in feet)
    points, rnd = _body_section([sec for sec in sections if sec is not None])
    # the disc about the origin (the broad phase's) must hold the shape at every heading: the old
    # radius does, but for a tilted round part's circumscribed polygon, which may reach past it
    reach = float(np.max(np.hypot(points[:, 0], points[:, 1]))) + rnd
    groups = _concave_groups(sections) if grouping is None else grouping
    return Footprint(max(radius, reach), min(f.z_low for f in feet), max(f.z_high for f in feet), points, rnd,
                     _pieces(groups, sections, bands), groups)


CONCAVE = 0.01        # a body whose hull's area exceeds its shapes' union's by more than this: its pieces


def _outline(sec: tuple[np.ndarray, float]) -> np.ndarray:
    """A section ``hull(points) ⊕ disc(r)`` as a convex polygon for the area rule (a round part its
    points ⊕ the circumscribed ROUND_SIDES-gon, as merged round parts are taken)."""
    pts, r = sec
    return _hull(pts if r == 0.0 else (pts[:, None, :] + _polygon(r)[None]).reshape(-1, 2))


def _area(poly: np.ndarray) -> float:
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _union_area(polys: list[np.ndarray]) -> float:
    """The area of the union of convex counter-clockwise polygons (Green's theorem over the parts of
    each edge no other polygon covers; an edge lying on an earlier polygon's edge of the same
    direction counts once, opposite edges cancel). Plain floats: a moving joint's body makes it again."""
    vs = [p.tolist() for p in polys]
    boxes = [(min(x for x, _ in v), min(y for _, y in v), max(x for x, _ in v), max(y for _, y in v)) if v else None
             for v in vs]
    total = 0.0
    for i, poly in enumerate(vs):
        if len(poly) < 3:
            continue
        others = [j for j, v in enumerate(vs) if j != i and len(v) >= 3]
        for k in range(len(poly)):
            ax, ay = poly[k]
            bx, by = poly[(k + 1) % len(poly)]
            dx, dy = bx - ax, by - ay
            dn = math.hypot(dx, dy)
            covered = []
            for j in others:
                x0, y0, x1, y1 = boxes[j]            # type: ignore[misc]
                if max(ax, bx) < x0 or min(ax, bx) > x1 or max(ay, by) < y0 or min(ay, by) > y1:
                    continue
                lo, hi = 0.0, 1.0
                other = vs[j]
                for m in range(len(other)):
                    vx, vy = other[m]
                    wx, wy = other[(m + 1) % len(other)]
                    ex, ey = wx - vx, wy - vy
                    en = math.hypot(ex, ey)
                    f0 = ex * (ay - vy) - ey * (ax - vx)      # > 0: a left of (inside) edge e
                    df = ex * dy - ey * dx
                    if abs(df) <= 1e-12 * en * dn:
                        tol = 1e-12 * en * (dn + math.hypot(ax - vx, ay - vy))
                        if f0 > tol or (abs(f0) <= tol and j < i and ex * dx + ey * dy > 0.0):
                            continue
                        lo, hi = 1.0, 0.0
                        break
                    t = -f0 / df
                    if df > 0.0:
                        lo = max(lo, t)
                    else:
                        hi = min(hi, t)
                    if lo >= hi:
                        break
                if lo < hi:
                    covered.append((lo, hi))
            t0 = 0.0
            for lo, hi in sorted(covered) + [(1.0, 1.0)]:
                if lo > t0:
                    px, py, qx, qy = ax + t0 * dx, ay + t0 * dy, ax + lo * dx, ay + lo * dy
                    total += 0.5 * (px * qy - qx * py)
                t0 = max(t0, hi)
    return total


def _concave_groups(sections: list[tuple[np.ndarray, float] | None]) -> tuple[tuple[int, ...], ...]:
    """A body's shapes grouped into convex pieces where the hull of their outlines closes a notch:
    () (the hull is the footprint, as it always was) when the hull's area is within CONCAVE (1 %) of
    the union's; else the groups -- the two whose hull adds least over their union merged, while that
    is under CONCAVE."""
    groups = [[k] for k, sec in enumerate(sections) if sec is not None]
    if len(groups) < 2:
        return ()
    outline = {k: _outline(sections[k]) for k, in groups}       # type: ignore[arg-type]
    everything = [outline[k] for k, in groups]
    if _area(_hull(np.concatenate(everything))) <= (1.0 + CONCAVE) * _union_area(everything):
        return ()
    excesses: dict[tuple[int, ...], float] = {}       # by the pair's shapes, kept from round to round
    while len(groups) > 1:
        best = None
        for gi in range(len(groups)):
            for gj in range(gi + 1, len(groups)):
                key = tuple(groups[gi] + groups[gj])
                excess = excesses.get(key)
                if excess is None:
                    polys = [outline[k] for k in key]
                    hull, union = _area(_hull(np.concatenate(polys))), _union_area(polys)
                    # (outlines of no area, a 1e-30 wheel's: nothing to merge them into unless their hull has none)
                    excess = excesses[key] = hull / union - 1.0 if union > 0.0 else (0.0 if hull <= 0.0 else math.inf)
                if excess <= CONCAVE and (best is None or excess < best[0]):
                    best = (excess, gi, gj)
        if best is None:
            break
        _, gi, gj = best
        groups[gi] = groups[gi] + groups.pop(gj)
    return tuple(tuple(g) for g in groups) if len(groups) > 1 else ()


def _pieces(groups: tuple[tuple[int, ...], ...], sections: list[tuple[np.ndarray, float] | None],
            bands: list[Footprint]) -> tuple[Footprint, ...] | None:
    """Each group of shapes one convex piece (:func:`_body_section`) with its own height band; None
    for no groups (the hull)."""
    if not groups:
        return None
    out = []
    for g in groups:
        pts, rnd = _body_section([sections[k] for k in g])     # type: ignore[misc]
        out.append(Footprint(float(np.max(np.hypot(pts[:, 0], pts[:, 1]))) + rnd,
                             min(bands[k].z_low for k in g), max(bands[k].z_high for k in g), pts, rnd))
    return tuple(out)


ROUND_SIDES = 16      # a round part merged with others: its circumscribed 16-gon (1.9 % wider)


def _polygon(rho: float) -> np.ndarray:
    """The regular ROUND_SIDES-gon circumscribed about the disc of radius ``rho`` at the origin,
    its edges touching the disc straight ahead, behind and on each side (so a robot's round front
    stops exactly ``rho`` ahead of its centre head-on)."""
    k = (np.arange(ROUND_SIDES) + 0.5) * (2.0 * math.pi / ROUND_SIDES)
    return (rho / math.cos(math.pi / ROUND_SIDES)) * np.stack([np.cos(k), np.sin(k)], axis=1)


def _section(prim: geo.Primitive, local: Pose) -> tuple[np.ndarray, float] | None:
    """A body shape's footprint in the robot's xy plane, ``(points, r)``: ``hull(points) ⊕ disc(r)``
    contains the shape's vertical projection (exact for a box, sphere, capsule, mesh and an
    upright cylinder; a tilted cylinder's end discs as circumscribed polygons)."""
    t = np.asarray(local.translation, dtype=np.float64)
    # a shape not turned in the robot's frame up to rounding (a NUE robot's frame turned upright,
    # enu_body) is taken as not turned, as robot_footprint takes its band: its ENU twin's bits
    r = np.eye(3) if np.allclose(local.rotation, np.eye(3)) else np.asarray(local.rotation, dtype=np.float64)
    if isinstance(prim, geo.Sphere):
        return t[None, :2].copy(), float(prim.radius)
    if isinstance(prim, geo.Capsule):
        ends = np.array([[0.0, 0.0, -prim.height / 2.0], [0.0, 0.0, prim.height / 2.0]]) @ r.T + t
        return _hull(ends[:, :2]), float(prim.radius)
    if isinstance(prim, geo.Cylinder):
        if abs(r[2, 2]) >= UPRIGHT:
            return t[None, :2].copy(), float(prim.radius)
        ring = _polygon(prim.radius)
        local_pts = np.concatenate([np.column_stack([ring, np.full(len(ring), z)])
                                    for z in (-prim.height / 2.0, prim.height / 2.0)])
        return _hull((local_pts @ r.T + t)[:, :2]), 0.0
    if isinstance(prim, geo.Box):
        sx, sy, sz = (v / 2.0 for v in prim.size)
        corners = np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)])
        return _hull((corners @ r.T + t)[:, :2]), 0.0
    if isinstance(prim, geo.Mesh):
        if len(prim.vertices) == 0:
            return None
        return _hull((np.asarray(prim.vertices, dtype=np.float64) @ r.T + t)[:, :2]), 0.0
    return None


def _body_section(parts: list[tuple[np.ndarray, float]]) -> tuple[np.ndarray, float]:
    """One convex piece ``hull(points) ⊕ disc(round)`` containing every part's: a part inside a
    round part (a wheel inside a round body's disc) is dropped; ``round`` is the smallest part's
    radius left, and a part rounder than that is its points ⊕ the circumscribed polygon of the
    difference. Exact for one part, for boxes and meshes (round 0), for round parts of one radius."""
    def inside(j: int, i: int) -> bool:
        (pj, rj), (pi, ri) = parts[j], parts[i]
        return (len(pi) == 1 and i != j and bool(np.all(np.hypot(pj[:, 0] - pi[0, 0], pj[:, 1] - pi[0, 1]) + rj <= ri))
                and not (j < i and len(pj) == 1 and rj == ri and pj[0, 0] == pi[0, 0] and pj[0, 1] == pi[0, 1]))
    kept = [parts[j] for j in range(len(parts)) if not any(inside(j, i) for i in range(len(parts)))]
    rnd = min(r for _, r in kept)
    pts = [p if r == rnd else (p[:, None, :] + _polygon(r - rnd)[None]).reshape(-1, 2) for p, r in kept]
    return _hull(np.concatenate(pts)), rnd


def enu_pose(pose: Pose, to_enu: np.ndarray | None) -> Pose:
    """``pose`` in ENU axes (itself in an ENU world, ``to_enu`` None): in a NUE world contact
    works in the drives' ENU frame."""
    if to_enu is None:
        return pose
    return Pose(to_enu @ pose.rotation, to_enu @ pose.translation)


def enu_body(parts: list[tuple[geo.Primitive, Pose]], pose: Pose,
             to_enu: np.ndarray | None) -> list[tuple[geo.Primitive, Pose]]:
    """A robot's body shapes for its footprint: as given in an ENU world; in a NUE world turned by
    the robot's rotation without its turn about up (PlanarState.base), so a robot whose own frame
    is y-up (base ``to_enu``) or z-up (base identity) gets the same footprint about ENU's up."""
    if to_enu is None:
        return parts
    r = to_enu @ pose.rotation
    yaw = math.atan2(r[1, 0], r[0, 0])
    c, s = math.cos(yaw), math.sin(yaw)
    base = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) @ r      # Rz(-yaw) @ r
    return [(prim, Pose(base, np.zeros(3)).compose(local)) for prim, local in parts]


def obstacle(name: str, owner: int, prim: geo.Primitive, pose: Pose, ramps: bool = False) -> Obstacle | None:
    """A solid's (or robot body's) 2D obstacle at ``pose``; None for a non-vertical plane. ``ramps``:
    a Box that is a ramp (:func:`ramp_top`) tops out at its low edge (kinematic contact's solids)."""
    if isinstance(prim, geo.Terrain):
        return None                              # ground (an ElevationGrid), like a floor plane
    r, t = pose.rotation, pose.translation
    upright = abs(r[2, 2]) >= UPRIGHT
    if isinstance(prim, geo.Plane):
        n = r[:, 2]
        if abs(n[2]) > 1e-9:
            return None                          # floors, ceilings and slopes never block a planar robot
        n2 = np.array([n[0], n[1]]) / math.hypot(n[0], n[1])
        return Obstacle(name, owner, np.zeros((1, 2)), 0.0, (-math.inf, math.inf), n2, -float(n2 @ t[:2]))
    if isinstance(prim, geo.Sphere):
        return Obstacle(name, owner, t[None, :2].copy(), prim.radius, (t[2] - prim.radius, t[2] + prim.radius),
                        sphere=True)
    if isinstance(prim, (geo.Cylinder, geo.Capsule)) and upright:
        h = prim.height / 2.0 + (prim.radius if isinstance(prim, geo.Capsule) else 0.0)
        return Obstacle(name, owner, t[None, :2].copy(), prim.radius, (t[2] - h, t[2] + h))
    if isinstance(prim, geo.Capsule):
        ends = np.array([[0.0, 0.0, -prim.height / 2.0], [0.0, 0.0, prim.height / 2.0]]) @ r.T + t
        return Obstacle(name, owner, _hull(ends[:, :2]), prim.radius,
                        (float(ends[:, 2].min()) - prim.radius, float(ends[:, 2].max()) + prim.radius))
    if isinstance(prim, geo.Box):
        sx, sy, sz = (s / 2.0 for s in prim.size)
        ramp = ramp_top(r, t, (sx, sy, sz)) if ramps else None
        if ramp is not None:
            # a solid's ramp: its band reaches up to its top face's low edge only, so a robot whose band
            # bottom is within FLOOR of that edge (it can drive on at it) rides it, never stopped by it
            corners = ramp[2]
            return Obstacle(name, owner, _hull(corners[:, :2]), 0.0, (float(corners[:, 2].min()), ramp[3]))
        local = np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)])
    else:
        local, _ = geo.tessellate(prim)          # circumscribed: conservative
    world = local @ r.T + t
    if len(world) == 0:
        return None
    return Obstacle(name, owner, _hull(world[:, :2]), 0.0, (float(world[:, 2].min()), float(world[:, 2].max())))


def sphere_radius_in_band(center_z: float, radius: float, low: float, high: float) -> float:
    """The widest horizontal section of a sphere within the height band [low, high]."""
    dz = 0.0 if low <= center_z <= high else min(abs(center_z - low), abs(center_z - high))
    return math.sqrt(max(radius * radius - dz * dz, 0.0))


# ---------------------------------------------------------------------- 2D queries

def _closest_on_hull(p: np.ndarray, pts: np.ndarray) -> tuple[float, np.ndarray]:
    """Signed distance from ``p`` to the convex hull ``pts`` (negative inside) and the outward
    unit normal at the closest feature. Scalar float64 arithmetic: hulls have a few vertices."""
    return _closest_on_list(float(p[0]), float(p[1]), pts.tolist())


def _closest_on_list(px: float, py: float, v: list, edge_normals: bool = False) -> tuple[float, np.ndarray]:
    """:func:`_closest_on_hull` of the point (px, py) and the hull's vertices as a list of [x, y].
    ``edge_normals``: when the closest point is inside an edge, its normal is the edge's own, not
    the direction from it (whose rounding, a robot 1e-12 m from the edge, turns it by 1e-4 rad)."""
    n = len(v)
    if n == 1:
        dx, dy = px - v[0][0], py - v[0][1]
        L = math.hypot(dx, dy)
        return L, (np.array([dx / L, dy / L]) if L > 0 else np.array([1.0, 0.0]))
    best, best_n = math.inf, (1.0, 0.0)
    inside = n >= 3
    deepest, deep_n = -math.inf, (1.0, 0.0)
    for i in range(n if n >= 3 else 1):            # edges a -> b, counter-clockwise
        ax, ay = v[i]
        bx, by = v[(i + 1) % n]
        ex, ey = bx - ax, by - ay
        el = math.hypot(ex, ey)
        ox, oy = ey / el, -ex / el                  # outward normal
        rx, ry = px - ax, py - ay
        t = min(max((rx * ex + ry * ey) / (el * el), 0.0), 1.0)
        dx, dy = rx - t * ex, ry - t * ey
        L = math.hypot(dx, dy)
        if L < best:
            if edge_normals and 0.0 < t < 1.0:
                best, best_n = L, ((ox, oy) if dx * ox + dy * oy >= 0.0 else (-ox, -oy))
            else:
                best, best_n = L, ((dx / L, dy / L) if L > 0 else (ox, oy))
        if n >= 3:
            side = rx * ox + ry * oy
            if side > 0.0:
                inside = False
            if side > deepest:
                deepest, deep_n = side, (ox, oy)
    if inside:
        return deepest, np.array(deep_n)
    return best, np.array(best_n)


def _ray_circle(p: np.ndarray, d: np.ndarray, c: np.ndarray, rho: float, a: float | None = None) -> float:
    """First s >= 0 where p + s·d enters the circle (c, rho); inf if never (``a``: d @ d when known)."""
    f = p - c
    if a is None:
        a = float(d @ d)
    b = float(f @ d)
    cc = float(f @ f) - rho * rho
    if a == 0.0 or b >= 0.0:
        return math.inf                              # not approaching
    disc = b * b - a * cc
    if disc < 0.0:
        return math.inf
    return max((-b - math.sqrt(disc)) / a, 0.0)


def _ray_segment(p: np.ndarray, d: np.ndarray, a: np.ndarray, b: np.ndarray, n: np.ndarray) -> float:
    """First s >= 0 where p + s·d crosses the segment (a, b) against its outward normal n."""
    dn = float(d @ n)
    if dn >= 0.0:
        return math.inf
    s = float((a - p) @ n) / dn
    if s < 0.0:
        return math.inf
    q = p + s * d - a
    e = b - a
    u = float(q @ e) / float(e @ e)
    return s if -1e-12 <= u <= 1.0 + 1e-12 else math.inf


def time_of_impact(p: np.ndarray, d: np.ndarray, ob: Obstacle, rho: float) -> tuple[float, np.ndarray | None]:
    """Where the moving point ``p + s·d`` (s in [0, 1]) first touches ``ob ⊕ disc(rho)``:
    ``(s, outward normal)``; ``(inf, None)`` if it does not (or starts touching and moves away)."""
    if ob.normal is not None:                        # two-sided wall line
        dist = float(ob.normal @ p) + ob.offset
        side = 1.0 if dist >= 0.0 else -1.0
        nrm = side * ob.normal
        gap = abs(dist) - rho
        rate = float(nrm @ d)
        if gap <= EPS:       # touching: an impact when the move goes in by more than the tolerance
            # or ends past it (overlapping, as a move from outside may leave it: deeper than it is)
            return (0.0, nrm) if rate < -EPS or gap + rate < deepest_end(gap, p) else (math.inf, None)
        if rate >= 0.0 or gap + rate > 0.0:
            return math.inf, None
        return gap / -rate, nrm
    pts = ob.points
    rad = ob.radius + rho
    v, edges = _hull_data(ob, rad)
    px, py = float(p[0]), float(p[1])
    dx, dy = float(d[0]), float(d[1])
    clear = _clear_of(px, py, dx, dy, rad, edges)
    if clear == _SWEPT_CLEAR:
        return math.inf, None
    if not clear:                                    # (clear: not touching, the distance not needed)
        dist, normal = _closest_on_list(px, py, v, ob.edge_normals)
        if dist - rad <= EPS:                        # touching (or overlapping) now
            # an impact when the move goes in by more than the tolerance; a slide's leftover (the
            # rounding of its projection, ~1e-19 m inward) is none: taken for one, it stalled the robot.
            # Overlapping (a robot placed so from outside: world file, Supervisor move, reset), the
            # move is free unless it ends deeper than it starts, so the robot can back out or slide
            # out (the signed distance to a convex set is convex: a move that does not start inward
            # never goes deeper on the way)
            if float(normal @ d) < -EPS:
                return 0.0, normal
            end_dist, _ = _closest_on_hull(p + d, pts)
            return (0.0, normal) if end_dist - rad < deepest_end(dist - rad, p) else (math.inf, None)
    best: float = math.inf
    best_n: np.ndarray | None = None
    a = float(d @ d)
    # Each vertex circle and offset edge whose answer is certainly inf or beyond the move (s > 1:
    # never the answer) is skipped on a float test with margins far above its rounding (see
    # _circle_beyond, _edge_beyond); the others get the exact test, in the same order: the same
    # answer, bit for bit, for a few float operations instead of a dozen numpy calls per feature.
    # (a == 0: every circle test answers inf; rad == 0: a vertex is no circle, its edges hold it)
    if a != 0.0 and rad > 0.0:
        for i, (cx, cy) in enumerate(v):
            if _circle_beyond(px - cx, py - cy, dx, dy, a, rad):
                continue
            s = _ray_circle(p, d, pts[i], rad, a)
            if s < best:
                best, best_n = s, (p + s * d - pts[i]) / rad
    n_e = len(edges)
    for k, (A, B, out, ax, ay, ox, oy) in enumerate(edges):   # a segment (n = 2) gets both sides: a→b and b→a
        if _edge_beyond(ax - px, ay - py, dx, dy, ox, oy):
            continue
        s = _ray_segment(p, d, A, B, out)
        if s < best and not (rad == 0.0 and n_e >= 3 and _skims_past(p, d, s, edges[k - 1], edges[(k + 1) % n_e])):
            best, best_n = s, out.copy()
    if best > 1.0:
        return math.inf, None
    return best, best_n


def _skims_past(p: np.ndarray, d: np.ndarray, s: float, before: tuple, after: tuple) -> bool:
    """Whether a move meeting an edge at ``s`` meets it at an end only, running on along the line
    of the edge there (``before`` or ``after``, the polygon's neighbouring edges) without going
    in: from the meeting point to the move's end it stays within EPS outside that neighbour's
    line, so it never enters the convex polygon. A robot sliding flush along a wall of boards laid
    end to end (Webots' maze blocks) meets the next board's end face at its corner, in line with
    the face it slides on: no impact, or it stalled at every joint."""
    h = p + s * d
    e = p + d
    for nb in (before, after):
        a, o = nb[0], nb[2]
        if float((h - a) @ o) >= -EPS and float((e - a) @ o) >= -EPS:
            return True
    return False


def _hull_data(ob: Obstacle, rad: float) -> tuple[list, list]:
    """``ob``'s vertices as [x, y] floats and, with 2 vertices or more, its edges a→b offset
    outward by ``rad``: (a + rad·out, b + rad·out, out, and their floats a + rad·out, out), the
    same numpy operations :func:`time_of_impact` did per call; made once per (obstacle, rad) --
    a solid's obstacle lives as long as the solid stays put, and a robot's grown radius is fixed."""
    got = ob.grown.get(rad)
    if got is None:
        pts = ob.points
        v = pts.tolist()
        n = len(v)
        edges = []
        if n >= 2:
            rad_f = float(rad)
            for i in range(n):
                (a0, a1), (b0, b1) = v[i], v[(i + 1) % n]
                e0, e1 = b0 - a0, b1 - a1
                el = math.hypot(e0, e1)
                if el == 0.0:               # (no such edge once the points are made; numpy's inf and NaN)
                    a, b = pts[i], pts[(i + 1) % n]
                    e = b - a
                    out = np.array([e[1], -e[0]]) / math.hypot(e[0], e[1])
                    A, B = a + rad * out, b + rad * out
                    edges.append((A, B, out, float(A[0]), float(A[1]), float(out[0]), float(out[1])))
                    continue
                # numpy's elementwise operations in plain floats: the same roundings, bit for bit
                o0, o1 = e1 / el, -e0 / el
                A0, A1 = a0 + rad_f * o0, a1 + rad_f * o1
                edges.append((np.array([A0, A1]), np.array([b0 + rad_f * o0, b1 + rad_f * o1]), np.array([o0, o1]),
                              A0, A1, o0, o1))
        got = ob.grown[rad] = (v, edges)
    return got


_SWEPT_CLEAR = 2


def _clear_of(px: float, py: float, dx: float, dy: float, rad: float, edges: list) -> int:
    """How certainly the move from (px, py) by (dx, dy) keeps clear of the hull grown by ``rad``,
    whose offset edges (:func:`_hull_data`, counter-clockwise) are ``edges``. 1: the start
    is more than EPS outside an offset edge's line, plus 1e-9 of the coordinates (far above their
    rounding) -- the distance to a convex hull is at least the distance to any of its edges' lines
    (a segment's two sides: its line), so _closest_on_list would find it not touching.
    _SWEPT_CLEAR: the start and the end are both outside one offset edge's line by 1e-6 (1 + rad
    + the coordinates' differences): the grown hull (its vertex circles, its offset edges) lies inside
    that line's half-plane, so the whole move stays farther than that from every feature, and the
    exact tests, whose rounding is ~3e-8 of those lengths at worst (a graze), answer inf or s > 1:
    no impact. 0: neither (no edges, a point: 0)."""
    clear = 0
    for _, _, _, ax, ay, ox, oy in edges:
        wx, wy = px - ax, py - ay
        side = wx * ox + wy * oy
        if side > EPS + 1e-9 * (1.0 + abs(ax) + abs(ay) + abs(wx) + abs(wy)):
            clear = 1
            m = 1e-6 * (1.0 + rad + abs(wx) + abs(wy) + abs(dx) + abs(dy))
            if side > m and side + (dx * ox + dy * oy) > m:
                return _SWEPT_CLEAR
    return clear


def _circle_beyond(fx: float, fy: float, dx: float, dy: float, a: float, rad: float) -> bool:
    """Whether :func:`_ray_circle` (f = p - c = (fx, fy), these exact: elementwise differences;
    ``a`` its d @ d) certainly answers inf or s > 1. Its dot products may round differently (BLAS,
    fused) from these plain ones: all within a few ulps of |f||d|, far inside the margins. Not
    approaching (b >= 0): inf. Else the move's segment [p, p + d] keeps its distance to c
    above the circle's radius by 1e-5 (1 + |f|²) m² squared: the line misses (computed disc < 0,
    whose rounding is ~1e-15 |f|² a) or enters beyond the move's end by more than the rounding
    of the computed entry (at most ~3e-8 |f| m when grazing). NaN answers False."""
    b = fx * dx + fy * dy
    if b > 1e-12 * (abs(fx * dx) + abs(fy * dy)):
        return True
    t = -b / a
    t = 0.0 if not t > 0.0 else (1.0 if t > 1.0 else t)
    qx, qy = fx + t * dx, fy + t * dy
    return qx * qx + qy * qy > rad * rad + 1e-5 * (1.0 + fx * fx + fy * fy)


def _edge_beyond(wx: float, wy: float, dx: float, dy: float, ox: float, oy: float) -> bool:
    """Whether :func:`_ray_segment` (w = a - p = (wx, wy), exact: elementwise; out = (ox, oy))
    certainly answers inf or s > 1: moving away from the edge's line (dn = d·out > 0: inf), or
    crossing it behind the start (num = w·out > 0 with dn < 0: s < 0, inf) or beyond the end (num
    < dn < 0 with a margin: the computed s = num/dn > 1). Margins 1e-12 of each dot product's
    terms, far above their rounding in any order (BLAS, fused); NaN answers False."""
    dn = dx * ox + dy * oy
    tol_dn = 1e-12 * (abs(dx * ox) + abs(dy * oy))
    if dn > tol_dn:
        return True
    num = wx * ox + wy * oy
    tol_num = 1e-12 * (abs(wx * ox) + abs(wy * oy))
    if num > tol_num and num > 1e-290 * abs(dn):     # (s < 0, not rounded to -0.0)
        return True
    return num < dn - (tol_num + tol_dn + 1e-12 * abs(dn))


# ---------------------------------------------------------------------- shaped footprints

def heading(pose: Pose) -> float:
    """The turn about up of an (ENU) pose, as :func:`enu_body` takes it out of the body."""
    r = pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


def drive_footprint(parts: list[tuple[geo.Primitive, Pose]], pose: Pose, to_enu: np.ndarray | None,
                    yaw: float | None = None,
                    grouping: tuple[tuple[int, ...], ...] | None = None) -> Footprint | None:
    """A robot's footprint (:func:`robot_footprint` of :func:`enu_body`) about the heading its drive
    keeps, ``yaw`` at ``pose`` (None: :func:`heading` of the pose, whose turn enu_body takes out):
    a drive whose forward axis is not the robot's x axis has its heading off that one."""
    foot = robot_footprint(enu_body(parts, pose, to_enu), grouping)
    if foot is None or yaw is None or foot.points is None:
        return foot
    off = heading(enu_pose(pose, to_enu)) - yaw
    if off == 0.0:
        return foot
    pieces = None if foot.pieces is None else tuple(
        Footprint(pc.radius, pc.z_low, pc.z_high, _turned(pc.points, off), pc.round) for pc in foot.pieces
        if pc.points is not None)
    return Footprint(foot.radius, foot.z_low, foot.z_high, _turned(foot.points, off), foot.round, pieces, foot.groups)


def shaped_obstacle(j: int, foot: Footprint, centre: np.ndarray, yaw: float, band: tuple[float, float]) -> Obstacle:
    """Robot ``j``'s shaped footprint at ``centre``, heading ``yaw``, as an obstacle."""
    assert foot.points is not None
    return Obstacle(f"robot {j}", int(j), _turned(foot.points, yaw) + centre[None, :], foot.round, band)


def robot_obstacles(j: int, foot: Footprint, centre: np.ndarray, yaw: float,
                    band: tuple[float, float]) -> list[Obstacle]:
    """Robot ``j``'s footprint at ``centre``, heading ``yaw``, as the obstacles others meet: its disc,
    its shape (:func:`shaped_obstacle`), or one per piece of a concave body, each over the robot's band."""
    if foot.disc:
        return [Obstacle(f"robot {j}", int(j), centre[None, :].copy(), foot.disc_radius, band)]
    if foot.pieces is None:
        return [shaped_obstacle(j, foot, centre, yaw, band)]
    return [shaped_obstacle(j, pc, centre, yaw, band) for pc in foot.pieces]


def spin_reach(feet: list[Footprint | None]) -> np.ndarray:
    """Per robot, what the broad phase grows a move by per radian of its turn (up to 2 rad): a
    shaped footprint's radius (a turn by t moves no point of it farther than radius·min(|t|, 2),
    so no push off what it turns into is longer, :meth:`Contact._push`), 0 for a disc or no footprint."""
    return np.array([f.radius if f is not None and not f.disc else 0.0 for f in feet], dtype=np.float64)


def _wrap(a: float) -> float:
    """``a`` in [-π, π), as the drives keep their heading (motion._wrap)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def _turned(points: np.ndarray, yaw: float) -> np.ndarray:
    """``points`` (robot frame, heading out) turned by ``yaw`` about up."""
    c, s = math.cos(yaw), math.sin(yaw)
    return points @ np.array([[c, s], [-s, c]])


def _grown(ob: Obstacle, shape: np.ndarray, rnd: float, p: np.ndarray) -> tuple[Obstacle, float]:
    """``ob`` grown by the footprint ``hull(shape) ⊕ disc(rnd)`` (relative to the robot's centre,
    already turned): the set of centres where the footprint meets ``ob``, as (obstacle, radius) for
    :func:`time_of_impact`. A convex ``hull(Q) ⊕ disc(ρ)`` grown so is ``hull(Q − shape) ⊕ disc(ρ +
    rnd)``; a wall line, on the side of ``p``, is grown by the footprint's reach toward it."""
    if ob.normal is not None:
        side = 1.0 if float(ob.normal @ p) + ob.offset >= 0.0 else -1.0
        return ob, float(np.max(shape @ (-side * ob.normal))) + rnd
    q = ob.points
    # the same obstacle grown by the same turned footprint is made once (a robot's turn, its push and
    # its move grow its candidates by the footprint at the same headings, and the next step's turn
    # starts at this one's end): keyed by the very vertex array (points never change), the radius'
    # bits, what the grown one copies and the turned footprint's bits
    key = (id(q), ob.radius.hex() if isinstance(ob.radius, float) else repr(ob.radius), ob.name, ob.owner,
           id(ob.z_range), shape.shape, shape.tobytes())
    hit = _GROWN.get(key)
    if hit is not None and hit[0] is q and hit[1] is ob.z_range:
        return hit[2], rnd
    if len(q) == 1:                     # a point (a pillar, a round robot): the footprint turned over
        pts = q[0] - shape
    elif len(q) >= 3 and len(shape) >= 3:
        pts = np.array(_minkowski(q.tolist(), (-shape).tolist()), dtype=np.float64)
    else:
        pts = _hull((q[:, None, :] - shape[None, :, :]).reshape(-1, 2))
    g = Obstacle(ob.name, ob.owner, pts, ob.radius, ob.z_range, edge_normals=True)
    if len(_GROWN) >= _GROWN_MAX:
        _GROWN.clear()
    _GROWN[key] = (q, ob.z_range, g)
    return g, rnd


_GROWN: dict = {}          # _grown's obstacles made lately (the arrays they came from held, so no id is reused)
_GROWN_MAX = 512        # (a mesh grown by a footprint is hundreds of edges: a few MB at most)


def _minkowski(a: list, b: list) -> list:
    """The Minkowski sum of two convex polygons (counter-clockwise vertex lists, 3 or more each):
    their edges merged by direction, O(n + m). A vertex turning by less than 1e-12 rad (rounding
    of parallel edges) is dropped: at most 1e-12 of the edges' lengths inside the exact sum. So is
    one within 1e-15 of its coordinates of the previous one (a few ulps: an edge of no length or
    direction), at most that far inside: dropping a vertex moves the hull in by up to the short
    edge's length, whatever the long ones' (1e-12 of the coordinates, 2e-7 m 1e5 m from the
    origin, let a footprint's 2e-7 m rounded end into a solid by 2e-8 m)."""
    def lowest(v: list) -> list:
        k = min(range(len(v)), key=lambda i: (v[i][1], v[i][0]))
        return v[k:] + v[:k]
    a, b = lowest(a), lowest(b)
    n, m = len(a), len(b)
    a, b = a + a[:2], b + b[:2]
    out: list = []
    i = j = 0
    while i < n or j < m:
        out.append((a[i][0] + b[j][0], a[i][1] + b[j][1]))
        c = ((a[i + 1][0] - a[i][0]) * (b[j + 1][1] - b[j][1])
             - (a[i + 1][1] - a[i][1]) * (b[j + 1][0] - b[j][0]))
        if j >= m or (i < n and c > 0.0):
            i += 1
        elif i >= n or c < 0.0:
            j += 1
        else:
            i += 1
            j += 1
    dropped = True
    while dropped and len(out) > 3:           # cyclic passes until none is dropped
        dropped = False
        k = 0
        while k < len(out) and len(out) > 3:
            (ox, oy), (px, py), (qx, qy) = out[k - 1], out[k], out[(k + 1) % len(out)]
            ux, uy, vx, vy = px - ox, py - oy, qx - px, qy - py
            lu, lv = math.hypot(ux, uy), math.hypot(vx, vy)
            if lu <= 1e-15 * (1.0 + abs(px) + abs(py)) or ux * vy - uy * vx <= 1e-12 * lu * lv:
                del out[k]
                dropped = True
            else:
                k += 1
    return out


def _gap_normal(p: np.ndarray, ob: Obstacle, rho: float) -> tuple[float, np.ndarray]:
    """:func:`_gap` and the outward unit normal of the nearest feature (inside: the shallowest
    edge's, the way out of a convex set that is shortest)."""
    if ob.normal is not None:
        dist = float(ob.normal @ p) + ob.offset
        return abs(dist) - rho, (1.0 if dist >= 0.0 else -1.0) * ob.normal
    d, n = _closest_on_list(float(p[0]), float(p[1]), ob.points.tolist(), ob.edge_normals)
    return d - (ob.radius + rho), n


_STILL = np.zeros(2)


def _in_reach(cands: list[Obstacle], p: np.ndarray, d: np.ndarray, radius: float,
              memo: dict | None = None) -> list[Obstacle]:
    """The candidates a footprint within ``radius`` of its centre can meet moving from ``p`` by ``d``
    (sliding included: the path is no longer than ``|d|``): their boxes, then the shapes, within that
    reach of ``p``, with a margin far above rounding. The others cannot stop the move, so their grown shapes are not
    built (a turning robot's broad phase reaches further, for the push). ``memo``: as :func:`_gap`'s."""
    reach = radius + math.hypot(float(d[0]), float(d[1]))
    x, y = float(p[0]), float(p[1])
    m = reach + 1e-6 * (1.0 + abs(x) + abs(y) + reach)
    margin = m - reach
    out = []
    for ob in cands:
        lx, ly, hx, hy, _ = ob.flat or _flat(ob)
        if not (lx > x + m or hx < x - m or ly > y + m or hy < y - m) and _gap(p, ob, reach, memo) <= margin:
            out.append(ob)
    return out


def _in_reaches(cands: list[Obstacle], p: np.ndarray, turn_radius: float | None, d: np.ndarray, radius: float,
                memo: dict) -> tuple[list[Obstacle], list[Obstacle]]:
    """``(_in_reach(cands, p, 0, turn_radius), _in_reach(cands, p, d, radius))``, the first ``[]`` for
    ``turn_radius`` None, sharing ``memo``: each candidate's distance from ``p`` is found once."""
    near = [] if turn_radius is None else _in_reach(cands, p, _STILL, turn_radius, memo)
    return near, _in_reach(cands, p, d, radius, memo)


def _flat(ob: Obstacle) -> tuple:
    """``ob``'s lo and hi as floats and its vertices as a list of [x, y] (made once: points never change)."""
    (lx, ly), (hx, hy) = ob.lo.tolist(), ob.hi.tolist()
    ob.flat = (lx, ly, hx, hy, ob.points.tolist())
    return ob.flat


def _gap(p: np.ndarray, ob: Obstacle, rho: float, memo: dict | None = None) -> float:
    """The signed distance from ``p`` to ``ob ⊕ disc(rho)`` (negative inside). ``memo``: the distances
    from this very ``p`` found so far, by obstacle (its id; the obstacles outlive the memo)."""
    if memo is not None:
        dist = memo.get(id(ob))
        if dist is None:
            dist = memo[id(ob)] = _base_gap(p, ob)
    else:
        dist = _base_gap(p, ob)
    return dist - rho if ob.normal is not None else dist - (ob.radius + rho)


def _base_gap(p: np.ndarray, ob: Obstacle) -> float:
    """The distance from ``p`` to ``ob``'s line or hull (negative inside), before its radius and any."""
    if ob.normal is not None:
        return abs(float(ob.normal @ p) + ob.offset)
    return _closest_dist(float(p[0]), float(p[1]), (ob.flat or _flat(ob))[4])


def _closest_dist(px: float, py: float, v: list) -> float:
    """The distance of :func:`_closest_on_list` alone, the same operations without the normal."""
    n = len(v)
    if n == 1:
        return math.hypot(px - v[0][0], py - v[0][1])
    best = math.inf
    inside = n >= 3
    deepest = -math.inf
    for i in range(n if n >= 3 else 1):
        ax, ay = v[i]
        bx, by = v[(i + 1) % n]
        ex, ey = bx - ax, by - ay
        el = math.hypot(ex, ey)
        rx, ry = px - ax, py - ay
        t = min(max((rx * ex + ry * ey) / (el * el), 0.0), 1.0)
        L = math.hypot(rx - t * ex, ry - t * ey)
        if L < best:
            best = L
        if n >= 3:
            side = rx * (ey / el) + ry * (-ex / el)
            if side > 0.0:
                inside = False
            if side > deepest:
                deepest = side
    return deepest if inside else best


# ---------------------------------------------------------------------- turns in place (exact arcs)

def _in_range(c: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The candidate angles ``c`` (any turn) moved into [lo, hi] where they fall in it (mod 2π),
    the others replaced by ``lo`` (a candidate already counted)."""
    k = np.mod(c - lo, math.tau)
    return np.where(k <= hi - lo, lo + k, lo)


def _rotated(x: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points ``x`` (..., 2) turned counter-clockwise by the angles ``u`` (broadcast), as :func:`_turned`."""
    c, s = np.cos(u), np.sin(u)
    return x[..., 0] * c - x[..., 1] * s, x[..., 0] * s + x[..., 1] * c


def _arc_to_segments(x: np.ndarray, lo: float, hi: float, a: np.ndarray, b: np.ndarray) -> float:
    """The least distance from the points ``x`` (k, 2), each turning about the origin through every
    angle of [lo, hi] (an arc), to the segments a→b (e, 2 each; a point where a = b): exact, the
    distance of each arc to each segment taken at its candidate angles -- the arc's ends, where it
    points at a segment's end (the nearest a segment's end gets), where it points along the
    segment line's normal either way (the nearest it gets to the line) and where the circle crosses
    that line. Between those the distance is monotone."""
    if len(x) == 0 or len(a) == 0:
        return math.inf
    X = x[:, None, :]
    A, B = a[None, :, :], b[None, :, :]
    rx = np.hypot(X[..., 0], X[..., 1])                     # (k, 1)
    px = np.arctan2(X[..., 1], X[..., 0])
    e = B - A
    el = np.hypot(e[..., 0], e[..., 1])
    safe = np.where(el > 0.0, el, 1.0)
    nx, ny = e[..., 1] / safe, -e[..., 0] / safe            # (1, e)
    off = nx * A[..., 0] + ny * A[..., 1]                   # the line n·y = off
    pn = np.arctan2(ny, nx)
    ratio = np.clip(off / np.where(rx > 0.0, rx, 1.0), -1.0, 1.0)
    cross = np.arccos(ratio)
    shape = np.broadcast_shapes(rx.shape, pn.shape)
    ends = np.broadcast_to(np.array([lo, hi]), (*shape, 2))
    cands = np.stack(np.broadcast_arrays(
        np.arctan2(A[..., 1], A[..., 0]) - px, np.arctan2(B[..., 1], B[..., 0]) - px,
        pn - px, pn - px + math.pi, pn - px + cross, pn - px - cross), axis=-1)
    u = np.concatenate([ends, _in_range(cands, lo, hi)], axis=-1)      # (k, e, 8)
    qx, qy = _rotated(x[:, None, None, :], u)
    ax, ay = A[..., 0][..., None], A[..., 1][..., None]
    ex, ey = e[..., 0][..., None], e[..., 1][..., None]
    ee = (el * el)[..., None]
    t = np.clip(((qx - ax) * ex + (qy - ay) * ey) / np.where(ee > 0.0, ee, 1.0), 0.0, 1.0)
    return float(np.min(np.hypot(qx - ax - t * ex, qy - ay - t * ey)))


def _least_along(x: np.ndarray, lo: float, hi: float, n: np.ndarray) -> np.ndarray:
    """Per axis n (e, 2), the least of n·R(u)x over the points ``x`` (k, 2) and u in [lo, hi]:
    each a sinusoid in u, least at the ends or where R(u)x points against n. Exact."""
    X = x[:, None, :]
    px = np.arctan2(X[..., 1], X[..., 0])
    pn = np.arctan2(n[None, :, 1], n[None, :, 0])
    crit = _in_range(pn - px + math.pi, lo, hi)
    u = np.concatenate([np.broadcast_to(np.array([lo, hi]), (*crit.shape, 2)), crit[..., None]], axis=-1)  # (k, e, 3)
    qx, qy = _rotated(x[:, None, None, :], u)
    return np.min(n[None, :, None, 0] * qx + n[None, :, None, 1] * qy, axis=(0, 2))


def _edges(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A convex hull's edges a→b (counter-clockwise; a segment both ways, a point none) and their
    outward unit normals."""
    if len(pts) < 2:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2))
    a, b = pts, np.concatenate([pts[1:], pts[:1]])
    e = b - a
    el = np.hypot(e[:, 0], e[:, 1])
    keep = el > 0.0
    a, e, el = a[keep], e[keep], el[keep]
    return a, a + e, np.stack([e[:, 1] / el, -e[:, 0] / el], axis=1)


def turn_gap_holds(shape: np.ndarray, rnd: float, turn: float, ob: Obstacle, p: np.ndarray,
                   target: float, start: float | None = None) -> bool:
    """Whether the footprint ``hull(shape) ⊕ disc(rnd)`` (turned to the turn's start, relative to
    its centre ``p``) turning in place by ``turn`` stays at a signed distance of at least ``target``
    from ``ob`` at every heading of the turn. Closed form, without sampling the turn: each vertex
    of the footprint turns on an arc about ``p``, and each of the obstacle's, seen from the robot,
    on an arc too (the other way).

    * A wall line: the footprint's reach toward it, the largest of its vertices' sinusoids.
    * The polygons must keep a signed distance s (``target`` less the rounds). First one
      separating axis for the whole turn, an edge normal of either polygon (turning with its
      polygon), along which their separation, the least of sinusoids, stays at least s
      (:func:`_least_along`): the signed distance is at least that at every heading (the largest
      such separation, where they overlap). Touching or overlapping (s <= EPS), this is the answer
      (conservative only where the deepest axis changes within the turn).
    * Else, s above EPS (apart): the least distance between the two polygons over the turn is
      the least of every footprint vertex's arc to the obstacle's edges and every obstacle
      vertex's arc to the footprint's edges (:func:`_arc_to_segments`): exact; they start at
      least that far apart and, to come nearer, would pass through that distance. Touching
      polygons that start apart and whose arcs stay more than EPS apart (far above the arcs'
      rounding) never overlap either.

    Screens answer False before the arcs where the arcs' answer is certainly False, by margins far
    above the rounding, so the answer is the arcs' bit for bit: apart (s above EPS), a vertex and
    an edge nearer than s at the turn's end (:func:`_end_nearer`; the arcs' candidate angles include
    it); touching, ``start`` (the footprint's signed distance from ``ob`` at the turn's start, when
    the caller knows it) puts the polygons within EPS / 2 of touching (:func:`_start_touching`: a
    vertex and an edge that near at the start), or a vertex of one is inside the other at the
    turn's end or halfway (:func:`_inside_in_turn`: it crossed an edge on the way, unless they were
    not apart at the start)."""
    lo, hi = (0.0, turn) if turn >= 0.0 else (turn, 0.0)
    if ob.normal is not None:
        side = 1.0 if float(ob.normal @ p) + ob.offset >= 0.0 else -1.0
        w = -side * ob.normal
        reach = -float(np.min(_least_along(shape, lo, hi, -w[None, :]))) + rnd
        return abs(float(ob.normal @ p) + ob.offset) - reach >= target
    q = ob.points - p[None, :]
    s = target + rnd + ob.radius
    fa, fb, fn = _edges(shape)
    qa, qb, qn = _edges(q)
    if len(fa) == 0:
        fa = fb = shape[:1]
    if len(qa) == 0:
        qa = qb = q[:1]

    def apart() -> float:
        return min(_arc_to_segments(shape, lo, hi, qa, qb), _arc_to_segments(q, -hi, -lo, fa, fb))

    # a point with a point or a segment never overlaps it as polygons (at any heading): their
    # distance is their vertices' to their edges'
    degenerate = len(shape) + len(q) <= 3
    if degenerate and s <= 0.0:
        return True
    # one separating axis for the whole turn (a lower bound of the signed distance at every heading:
    # cheaper than the arcs, and where they touch or overlap the only answer)
    if len(qn):             # the obstacle's edge normals (fixed): sep = min n·R(u)f - max n·q
        sep = _least_along(shape, lo, hi, qn) - np.max(qn @ q.T, axis=1)
        if float(np.max(sep)) >= s:
            return True
    if len(fn):             # the footprint's (turning with it): sep = min m·R(-u)q - max m·f
        sep = _least_along(q, -hi, -lo, fn) - np.max(fn @ shape.T, axis=1)
        if float(np.max(sep)) >= s:
            return True
    if s > EPS or degenerate:
        return not _end_nearer(shape, q, turn, s) and apart() >= s
    # apart at the start and kept farther apart than the rounding (EPS) all through the turn
    if start is not None and _start_touching(start + rnd + ob.radius, ob, p, shape):
        return False
    if _inside_in_turn(shape, q, turn):
        return False
    return _start_apart(shape, q) and apart() >= max(s, EPS)


def _start_touching(gap: float, ob: Obstacle, p: np.ndarray, shape: np.ndarray) -> bool:
    """Whether the polygons ``hull(shape)`` about ``p`` and ``ob``'s hull, whose distance (negative:
    less the depth of their overlap) the caller found to be ``gap`` (:func:`_gap` of ``ob`` grown by
    the footprint, :func:`_grown`), are certainly within EPS / 2 of touching. Then a vertex of one is
    within EPS / 2 of an edge of the other at the start (apart: their nearest points include a
    vertex; overlapping by less than that: moving one by the depth makes them touch, and no
    vertex-to-edge distance changes by more than the move), so :func:`_arc_to_segments`, which
    includes the turn's start, answers below EPS. The margin covers the rounding of both ways of
    finding the distance (~1e-15 of the coordinates) and the vertices :func:`_minkowski` drops (at
    most 1e-12 of the grown outline's edges inside it)."""
    if not abs(gap) <= 0.5 * EPS:
        return False
    lx, ly, hx, hy, _ = ob.flat or _flat(ob)
    reach = float(np.max(np.abs(shape)))
    extent = (hx - lx) + (hy - ly) + 4.0 * reach
    size = 1.0 + max(abs(lx), abs(ly), abs(hx), abs(hy)) + abs(float(p[0])) + abs(float(p[1])) + reach
    return abs(gap) + 4e-12 * extent + 1e-13 * size <= 0.5 * EPS


def _end_nearer(shape: np.ndarray, q: np.ndarray, turn: float, limit: float) -> bool:
    """Whether some vertex of ``hull(shape)`` turned by ``turn`` (about the origin) and an edge of
    ``hull(q)``, or the other way, are nearer than ``limit`` by far more than rounding (1e-12 of
    the coordinates): :func:`_arc_to_segments` of either, whose candidate angles include the turn's
    end, then answers below ``limit`` too. Plain floats, the same vertex-to-segment distances."""
    c, s = math.cos(turn), math.sin(turn)
    f = [(x * c - y * s, x * s + y * c) for x, y in shape.tolist()]
    g = [(x, y) for x, y in q.tolist()]
    size = 1.0 + max(max(abs(x), abs(y)) for x, y in f + g)
    return min(_vertex_edge(f, g), _vertex_edge(g, f)) + 1e-12 * size < limit


def _inside_in_turn(shape: np.ndarray, q: np.ndarray, turn: float) -> bool:
    """Whether, at the turn's end or halfway, a vertex of ``hull(shape)`` turned so is inside
    ``hull(q)``, or one of ``hull(q)``'s inside it, deeper than 1e-12 of the coordinates (far above
    rounding; hulls of 3 vertices or more, counter-clockwise); or a footprint vertex is inside
    ``hull(q)`` where its arc reaches deepest past one of its edges (a corner whose arc dips into a
    wall and out again). Then :func:`turn_gap_holds` answers False for two polygons
    touching or overlapping by less than EPS: apart at the start, the vertex crossed an edge on the
    way, where the arcs' least (:func:`_arc_to_segments`, exact to rounding) is 0; not apart,
    :func:`_start_apart` finds no separating axis, or one within rounding of none, where a vertex
    is that near an edge at the start (the overlap's depth, found along an edge normal)."""
    if len(shape) < 3 and len(q) < 3:
        return False
    g = [(x, y) for x, y in q.tolist()]
    pts = shape.tolist()
    for u in (turn, 0.5 * turn):
        c, s = math.cos(u), math.sin(u)
        f = [(x * c - y * s, x * s + y * c) for x, y in pts]
        tol = 1e-12 * (1.0 + max(max(abs(x), abs(y)) for x, y in f + g))
        if (len(g) >= 3 and _any_inside(f, g, tol)) or (len(f) >= 3 and _any_inside(g, f, tol)):
            return True
    if len(g) < 3:
        return False
    # and where each footprint vertex reaches deepest past each of the obstacle's edges on its arc
    # (its turn pointing it against the edge's normal), when that heading is within the turn
    lo, hi = (0.0, turn) if turn >= 0.0 else (turn, 0.0)
    lines = _edge_lines(g)
    if len(lines) < 3:
        return False
    for x, y in pts:
        at = math.atan2(y, x)
        for ax, ay, ox, oy in lines:
            k = (math.atan2(-oy, -ox) - at - lo) % math.tau
            if not k <= hi - lo:
                continue
            c, s = math.cos(lo + k), math.sin(lo + k)
            px, py = x * c - y * s, x * s + y * c
            if (px - ax) * ox + (py - ay) * oy < -tol and all(
                    (px - bx) * nx + (py - by) * ny < -tol for bx, by, nx, ny in lines):
                return True
    return False


def _edge_lines(w: list) -> list:
    """The lines of the counter-clockwise polygon ``w``'s edges: (a point, its outward unit normal)
    for each edge of non-zero length."""
    lines = []
    for (ax, ay), (bx, by) in zip([w[-1]] + w[:-1], w):
        ex, ey = bx - ax, by - ay
        el = math.hypot(ex, ey)
        if el > 0.0:
            lines.append((ax, ay, ey / el, -ex / el))
    return lines


def _any_inside(v: list, w: list, tol: float) -> bool:
    """Whether a point of ``v`` is inside the counter-clockwise polygon ``w`` deeper than ``tol``
    from each of its edges' lines."""
    lines = _edge_lines(w)
    if len(lines) < 3:
        return False
    for px, py in v:
        if all((px - ax) * ox + (py - ay) * oy < -tol for ax, ay, ox, oy in lines):
            return True
    return False


def _vertex_edge(v: list, w: list) -> float:
    """The least distance from the points ``v`` to the edges of the convex polygon ``w`` (a point,
    a segment or a closed outline)."""
    n = len(w)
    edges = [(w[0], w[0])] if n == 1 else [(w[0], w[1])] if n == 2 else [(w[i - 1], w[i]) for i in range(n)]
    best = math.inf
    for (ax, ay), (bx, by) in edges:
        ex, ey = bx - ax, by - ay
        ee = ex * ex + ey * ey
        for px, py in v:
            rx, ry = px - ax, py - ay
            t = min(max((rx * ex + ry * ey) / ee, 0.0), 1.0) if ee > 0.0 else 0.0
            d = math.hypot(rx - t * ex, ry - t * ey)
            if d < best:
                best = d
    return best


def _start_apart(shape: np.ndarray, q: np.ndarray) -> bool:
    """Whether the polygons ``hull(shape)`` and ``hull(q)`` (the same frame) are apart: a separating
    edge normal of either (exact but for a point with a point or a segment and two parallel
    segments, whose distance answers)."""
    for pa, pb in ((shape, q), (q, shape)):
        _, _, n = _edges(pa)
        if len(n) and float(np.max(np.min(n @ pb.T, axis=1) - np.max(n @ pa.T, axis=1))) > 0.0:
            return True
    parallel = (len(shape) == 2 and len(q) == 2
                and float((shape[1, 0] - shape[0, 0]) * (q[1, 1] - q[0, 1]) - (shape[1, 1] - shape[0, 1]) * (q[1, 0] - q[0, 0])) == 0.0)
    if len(shape) + len(q) <= 3 or parallel:
        fa, fb, _ = _edges(shape)
        if len(fa) == 0:
            fa = fb = shape[:1]
        qa, qb, _ = _edges(q)
        if len(qa) == 0:
            qa = qb = q[:1]
        return _arc_to_segments(shape, 0.0, 0.0, qa, qb) > 0.0 and _arc_to_segments(q, 0.0, 0.0, fa, fb) > 0.0
    return False


# ---------------------------------------------------------------------- bumpers

TOUCH = 1e-6          # m: a bumper's own shapes this near what contact sees (or overlapping it) touch it


def device_pieces(parts: list[tuple[geo.Primitive, Pose]], pose: Pose, to_enu: np.ndarray | None,
                  yaw: float | None) -> list[Footprint]:
    """A device's own bounding shapes (a bumper's), each as contact takes a robot's body: its piece
    and height band in the footprint's frame (:func:`drive_footprint` of that one shape, at the
    robot's world-file ``pose`` and drive heading ``yaw``), so it moves and turns with the footprint."""
    out = []
    for part in parts:
        piece = drive_footprint([part], pose, to_enu, yaw)
        if piece is not None and piece.points is not None:
            out.append(piece)
    return out


def pieces_touch(pieces: list[Footprint], centre: np.ndarray, yaw: float, height: float,
                 solids: list[Obstacle], robots: list[Obstacle]) -> bool:
    """Whether any of a robot's ``pieces`` (:func:`device_pieces`), with the robot at ``centre``,
    heading ``yaw`` and height ``height``, touches a solid's obstacle or another robot's footprint
    (``robots``): their bands overlapping as contact's broad phase takes them (a solid rising more
    than FLOOR into the band, a robot more than EPS), and the 2D gap between the piece and the
    obstacle (contact's Minkowski sum, :func:`_grown`) at most :data:`TOUCH`."""
    for piece in pieces:
        assert piece.points is not None
        lo, hi = height + piece.z_low, height + piece.z_high
        shape = _turned(piece.points, yaw)
        grow = piece.round + TOUCH
        (x0, y0), (x1, y1) = (shape.min(axis=0) + centre).tolist(), (shape.max(axis=0) + centre).tolist()
        x0, y0, x1, y1 = x0 - grow, y0 - grow, x1 + grow, y1 + grow
        for ob, floor in [(o, FLOOR) for o in solids] + [(o, EPS) for o in robots]:
            if not (ob.z_range[1] > lo + floor and ob.z_range[0] < hi - EPS):
                continue
            (lx, ly), (hx, hy) = ob.lo.tolist(), ob.hi.tolist()
            if lx > x1 or ly > y1 or hx < x0 or hy < y0:
                continue
            if ob.sphere:
                ob = Contact._in_band(ob, lo, hi)
            if _gap(centre, *_grown(ob, shape, piece.round, centre)) <= TOUCH:
                return True
    return False


# ---------------------------------------------------------------------- the resolver

class Contact:
    """The world's static obstacles plus the robots' footprints; :meth:`resolve` clips one robot's move."""

    def __init__(self, solids: list[tuple[str, geo.Primitive, Pose, Pose, bool]],
                 robots: list[tuple[list[tuple[geo.Primitive, Pose]], Pose]], to_enu: np.ndarray | None = None,
                 yaws: list[float | None] | None = None):
        """``solids``: one entry per shape — (solid name, primitive, pose in the solid's frame, the
        solid's world pose, seen by bounding rays); a solid made of several shapes (or with nested
        children) gives several entries under one name, moved together. ``robots``: (body shapes
        with their poses in the robot frame, initial pose) in world order. ``to_enu``: world axes to
        ENU (None in an ENU world): contact is solved in ENU, where the drives keep their planar
        state, so every pose given (here, :meth:`update_solid`, :meth:`place`) is turned into it.
        ``yaws``: each robot's heading as its drive keeps it at its initial pose (None, or a robot
        without a drive: :func:`heading` of its pose), the heading :meth:`resolve_all` is given."""
        self._to_enu = to_enu
        self.prims: dict[str, list[tuple[geo.Primitive, Pose]]] = {}
        first_pose: dict[str, Pose] = {}
        for name, prim, local, pose, bounding in solids:
            if bounding:
                self.prims.setdefault(name, []).append((prim, local))
                first_pose.setdefault(name, pose)
        self.solids: dict[tuple[str, int], Obstacle] = {}
        # the solids whose ramps top out at their low edge: the world file's, which are ground (ground.py)
        self._ramps = set(first_pose)
        for name, pose in first_pose.items():
            self.update_solid(name, pose)
        if yaws is None:
            yaws = [None] * len(robots)
        self.feet: list[Footprint | None] = [drive_footprint(parts, pose, to_enu, yaw)
                                             for (parts, pose), yaw in zip(robots, yaws)]
        nan = math.nan                            # robots without a footprint never match the broad phase
        self._radius = np.array([f.radius if f else nan for f in self.feet], dtype=np.float64)
        self._spin = spin_reach(self.feet)
        self._z_low = np.array([f.z_low if f else nan for f in self.feet], dtype=np.float64)
        self._z_high = np.array([f.z_high if f else nan for f in self.feet], dtype=np.float64)
        starts = [enu_pose(p, to_enu).translation for _, p in robots]
        self.centres = np.array([[t[0], t[1]] for t in starts], dtype=np.float64).reshape(-1, 2)
        self.heights = np.array([t[2] for t in starts], dtype=np.float64)
        # each robot's heading (its drive's: the footprint is turned to match, drive_footprint)
        self.yaw = np.array([heading(enu_pose(p, to_enu)) if y is None else y for (_, p), y in zip(robots, yaws)],
                            dtype=np.float64)
        self.initial = [(p, y) for (_, p), y in zip(robots, yaws)]     # what the footprints were made from
        self.contacts = 0                         # robot-steps whose motion was clipped
        self.checks = 0                           # narrow-phase obstacle tests
        # robot index -> the solids its VacuumGrippers hold (sim/vacuum.py): Webots' fixed joint makes
        # each one body with its carrier, so it never stops its carrier (other robots still meet it)
        self.carried: dict[int, list[str]] = {}
        # robot index -> {held solid -> its shapes' pieces (device_pieces: each its outline and its own
        # height band in the footprint's frame)}: the load is part of its carrier's outline, so the
        # carrier stops where its load meets something (:meth:`_clip_carrying`)
        self.loads: dict[int, dict[str, list[Footprint]]] = {}
        # robot index -> the robots fixed to it (a robot riding another, its carrier, the carrier's other riders):
        # one body in Webots, so they never stop or touch each other
        self.attached: dict[int, frozenset[int]] = {}
        self._rebuild()

    def update_solid(self, name: str, pose: Pose) -> None:
        pose = enu_pose(pose, self._to_enu)
        moved: list[tuple[str, int]] = []        # obstacles that were there and are still: changed in place
        same = True
        for i, (prim, local) in enumerate(self.prims.get(name, ())):
            ob = obstacle(name, -1, prim, pose.compose(local), ramps=name in self._ramps)
            if ob is None:
                same = self.solids.pop((name, i), None) is None and same
            else:
                same = same and (name, i) in self.solids
                self.solids[(name, i)] = ob
                moved.append((name, i))
        if not hasattr(self, "feet"):
            return
        if not same:
            self._rebuild()
            return
        # a solid moved with the same obstacles (a carried one, every step): its rows of the arrays
        # _rebuild makes, in place (a dict keeps a key's place when its value changes: the same arrays)
        for key in moved:
            j, ob = self._slot[key], self.solids[key]
            self._obs[j] = ob
            self._lo[j], self._hi[j] = ob.lo, ob.hi
            self._zlo[j], self._zhi[j] = ob.z_range

    def add_solid(self, name: str, shapes: list[tuple[geo.Primitive, Pose, bool]], pose: Pose,
                  ramps: bool = False) -> None:
        """A solid a Supervisor imported: an obstacle from now on (its bounding shapes: (primitive,
        pose in the solid's frame, seen by bounding rays), as the constructor takes them). ``ramps``:
        its ramps are ground (a solid built again in a world with a Ground), so they top out at their
        low edge; an imported solid is no ground, its ramps whole obstacles."""
        if ramps:
            self._ramps.add(name)
        else:
            self._ramps.discard(name)
        prims = [(prim, local) for prim, local, bounding in shapes if bounding]
        if prims:
            self.prims[name] = prims
            self.update_solid(name, pose)

    def remove_solid(self, name: str) -> None:
        """A solid removed by a Supervisor: no longer an obstacle."""
        self._ramps.discard(name)
        for i in range(len(self.prims.pop(name, ()))):
            self.solids.pop((name, i), None)
        self._rebuild()

    def hold(self, index: int, name: str, parts: list[tuple[geo.Primitive, Pose]] | None = None) -> None:
        """Robot ``index`` now carries solid ``name`` (a VacuumGripper took it): it no longer stops it,
        and its bounding shapes ``parts`` (robot frame, as :meth:`reshape` takes the robot's own) are
        part of the carrier's outline, each shape a piece with its own height band. Called again for
        a solid held, its pieces are made again (the gripper's joint moved it in the robot's frame)."""
        held = self.carried.setdefault(index, [])
        if name not in held:
            held.append(name)
        pieces = self.pieces(index, parts) if parts else []
        if pieces:
            self.loads.setdefault(index, {})[name] = pieces
        else:
            self._unload(index, name)

    def let_go(self, index: int, name: str) -> None:
        """Robot ``index`` no longer carries solid ``name``: an obstacle to it again, and its outline
        the robot's own again (the same footprint object: it moves as if it never held anything)."""
        held = self.carried.get(index)
        if held is not None and name in held:
            held.remove(name)
            if not held:
                del self.carried[index]
        self._unload(index, name)

    def _unload(self, index: int, name: str) -> None:
        loads = self.loads.get(index)
        if loads is not None and loads.pop(name, None) is not None and not loads:
            del self.loads[index]

    def _rebuild(self) -> None:
        obs = list(self.solids.values())
        self._obs = obs
        self._slot = {key: j for j, key in enumerate(self.solids)}
        self._lo = np.array([o.lo for o in obs]).reshape(-1, 2)
        self._hi = np.array([o.hi for o in obs]).reshape(-1, 2)
        self._zlo = np.array([o.z_range[0] for o in obs], dtype=np.float64)
        self._zhi = np.array([o.z_range[1] for o in obs], dtype=np.float64)

    def reshape(self, index: int, parts: list[tuple[geo.Primitive, Pose]]) -> None:
        """Robot ``index``'s bounding shapes moved on its joints: its footprint is made again from
        ``parts`` (as the constructor's ``robots`` give them, robot frame), at its world-file pose and
        heading as the first was (:func:`drive_footprint`), its shapes grouped into pieces as they were
        at load (:attr:`Footprint.groups`: no areas measured again each step a joint moves), and its
        broad-phase disc, spin reach and height band with it. Called only for a robot one of whose joints carrying bounding shapes
        moved (sim/simulation.py ``RobotState.move_links``)."""
        pose, yaw = self.initial[index]
        old = self.feet[index]
        foot = self.feet[index] = drive_footprint(parts, pose, self._to_enu, yaw, None if old is None else old.groups)
        nan = math.nan
        self._radius[index] = foot.radius if foot else nan
        self._spin[index] = spin_reach([foot])[0]
        self._z_low[index] = foot.z_low if foot else nan
        self._z_high[index] = foot.z_high if foot else nan

    def attach(self, groups: list[list[int]]) -> None:
        """Each group's robots fixed to one another (a carrier and the robots riding it): never each other's
        obstacle."""
        for group in groups:
            for i in group:
                self.attached[i] = frozenset(self.attached.get(i, frozenset()) | (set(group) - {i}))

    def fix_rider(self, index: int, rider: int, parts: list[tuple[geo.Primitive, Pose]]) -> None:
        """Robot ``rider`` rides robot ``index``, fixed in its frame: its bounding shapes ``parts`` (the
        carrier's frame, as :meth:`hold` takes a load's) are part of the carrier's outline, so the carrier
        stops where its rider meets something, as one body in Webots; the two never meet (:meth:`attach`)."""
        pieces = self.pieces(index, parts) if parts else []
        if pieces:
            self.loads.setdefault(index, {})[f"\0robot {rider}"] = pieces    # (no solid's name)

    def place(self, index: int, pose: Pose, yaw: float | None = None) -> None:
        """A robot was moved from outside (set_pose, reset): no contact check, as in Webots.
        ``yaw``: its drive's heading there (None: :func:`heading` of the pose)."""
        pose = enu_pose(pose, self._to_enu)
        self.centres[index] = pose.translation[:2]
        self.heights[index] = pose.translation[2]
        self.yaw[index] = heading(pose) if yaw is None else yaw

    def resolve(self, index: int, start, end, yaws=None) -> tuple[np.ndarray, bool, float]:
        """Clip robot ``index``'s move from ``start`` to ``end`` (xy), its heading going from
        ``yaws[0]`` to ``yaws[1]`` (None: kept): ``(final xy, clipped, final heading)``."""
        return self.resolve_all([index], np.asarray([start], dtype=np.float64), np.asarray([end], dtype=np.float64),
                                None if yaws is None else np.asarray([yaws], dtype=np.float64))[0]

    def resolve_all(self, indices: list[int], starts: np.ndarray, ends: np.ndarray,
                    yaws: np.ndarray | None = None) -> list[tuple[np.ndarray, bool, float]]:
        """Clip the moves of several robots (one basic step), in order: each sees the others where
        they are when its turn comes. ``yaws``: (k, 2), each one's heading at the start and the
        end of the step (None: headings kept). Returns (final xy, clipped, turned) per move: ``turned`` False when its turn
        was refused (its heading stays), which counts as clipped. One vectorised broad phase for
        all of them: a move (with its slides and its turn) never leaves the disc of radius
        |end - start| + its footprint's radius around its start, grown for a shaped robot by
        its radius times min(|yaw1 - yaw0|, 2), the farthest its turn can push it
        (:meth:`_push`, :func:`spin_reach`)."""
        k = len(indices)
        idx = np.asarray(indices, dtype=np.int64)
        reach = np.hypot(*(ends - starts).T) + EPS
        if yaws is not None:             # a shaped robot's turn may push it off what it turns into
            reach = reach + self._spin[idx] * np.minimum(np.abs(yaws[:, 1] - yaws[:, 0]), 2.0)
        R = self._radius[idx]
        band_lo = self.heights[idx] + self._z_low[idx]
        band_hi = self.heights[idx] + self._z_high[idx]
        loaded: dict[int, list[Footprint]] = {}
        if self.loads:                   # a carrier reaches as far as its loads, over their bands too
            R, band_lo, band_hi = R.copy(), band_lo.copy(), band_hi.copy()
            for m, i in enumerate(indices):
                held = self.loads.get(int(i))
                if held and self.feet[int(i)] is not None:
                    pieces = loaded[m] = [piece for pcs in held.values() for piece in pcs]
                    h = float(self.heights[int(i)])
                    R[m] = max(float(R[m]), *(pc.radius for pc in pieces))
                    band_lo[m] = min(float(band_lo[m]), *(h + pc.z_low for pc in pieces))
                    band_hi[m] = max(float(band_hi[m]), *(h + pc.z_high for pc in pieces))
        box_lo = starts - (reach + R)[:, None]
        box_hi = starts + (reach + R)[:, None]
        if len(self._obs):
            lo, hi = self._lo, self._hi
            solid_hit = ((lo[None, :, 0] <= box_hi[:, None, 0]) & (lo[None, :, 1] <= box_hi[:, None, 1])
                         & (hi[None, :, 0] >= box_lo[:, None, 0]) & (hi[None, :, 1] >= box_lo[:, None, 1])
                         & (self._zhi[None] > band_lo[:, None] + FLOOR) & (self._zlo[None] < band_hi[:, None] - EPS))
            if self.carried:             # what a robot carries is part of it: never its obstacle
                for m, i in enumerate(indices):
                    held = self.carried.get(int(i))
                    if held:
                        for j in np.flatnonzero(solid_hit[m]).tolist():
                            if self._obs[j].name in held:
                                solid_hit[m, j] = False
        robot_hit = None
        if len(self.feet) > 1:
            # where every robot may be during this step: its disc, grown by its own move if it moves
            grow = np.zeros(len(self.feet))
            grow[idx] = reach
            r_all = self._radius + grow
            c = self.centres
            a_lo, a_hi = self.heights + self._z_low, self.heights + self._z_high
            robot_hit = ((c[None, :, 0] + r_all[None] >= box_lo[:, None, 0]) & (c[None, :, 0] - r_all[None] <= box_hi[:, None, 0])
                         & (c[None, :, 1] + r_all[None] >= box_lo[:, None, 1]) & (c[None, :, 1] - r_all[None] <= box_hi[:, None, 1])
                         & (a_hi[None] > band_lo[:, None] + EPS) & (a_lo[None] < band_hi[:, None] - EPS))
            robot_hit[np.arange(k), idx] = False
            if self.attached:
                for m, i in enumerate(idx.tolist()):
                    for j in self.attached.get(i, ()):
                        robot_hit[m, j] = False
        near_solids: list[list[int]] = [[] for _ in range(k)]
        near_robots: list[list[int]] = [[] for _ in range(k)]
        if len(self._obs):
            for m, j in zip(*(x.tolist() for x in np.nonzero(solid_hit))):
                near_solids[m].append(j)
        if robot_hit is not None:
            for m, j in zip(*(x.tolist() for x in np.nonzero(robot_hit))):
                near_robots[m].append(j)
        # the moves near nothing that no other move has near it end where _clip and _clip_shaped put
        # them without candidates, start + (end - start), whatever the order: all at once (robots
        # each moved once; a robot without a footprint ends at its end, in the loop below). For a
        # few moves the loop is cheaper than the arrays
        out: list = [None] * k
        rest: list[int] | range = range(k)
        lone = None
        if k >= 4 and len(set(indices)) == k:
            lone = ~np.isnan(self._radius[idx])
            if len(self._obs):
                lone &= ~solid_hit.any(axis=1)
            if robot_hit is not None:
                lone &= ~robot_hit.any(axis=1) & ~robot_hit.any(axis=0)[idx]
        if lone is not None and lone.any():
            moved = starts + (ends - starts)
            li = idx[lone]
            self.centres[li] = moved[lone]
            if yaws is not None:
                self.yaw[li] = yaws[lone, 1]
            headings = self.yaw[idx].tolist()
            for m in lone.nonzero()[0].tolist():
                out[m] = (moved[m], False, headings[m])
            rest = (~lone).nonzero()[0].tolist()
        for m in rest:
            i = int(idx[m])
            yaw0, yaw1 = (float(self.yaw[i]),) * 2 if yaws is None else (float(yaws[m, 0]), float(yaws[m, 1]))
            foot = self.feet[i]
            if foot is None:
                self.centres[i] = ends[m]
                self.yaw[i] = yaw1
                out[m] = (ends[m].copy(), False, yaw1)
                continue
            if m in loaded or foot.pieces is not None:
                p, clipped, kept = self._clip_carrying(i, foot, loaded.get(m, []), starts[m].copy(), ends[m] - starts[m],
                                                       yaw0, yaw1, near_solids[m], near_robots[m])
                self.centres[i] = p
                self.yaw[i] = kept
                out[m] = (p, clipped, kept)
                continue
            cands: list[Obstacle] = [self._in_band(self._obs[j], float(band_lo[m]), float(band_hi[m]))
                                     for j in near_solids[m]]
            if near_robots[m]:
                for j in near_robots[m]:
                    cands += self._robot_obstacles(j)
            if foot.disc:                    # a disc turns freely
                p, clipped = self._clip(starts[m].copy(), ends[m] - starts[m], foot.disc_radius, cands)
                kept = yaw1
            else:
                p, clipped, kept = self._clip_shaped(foot, starts[m].copy(), ends[m] - starts[m], yaw0, yaw1, cands)
            self.centres[i] = p
            self.yaw[i] = kept
            out[m] = (p, clipped, kept)
        return out

    def pieces(self, index: int, parts: list[tuple[geo.Primitive, Pose]]) -> list[Footprint]:
        """Robot ``index``'s device shapes ``parts`` (robot frame) as :func:`device_pieces`, made as its
        footprint was."""
        pose, yaw = self.initial[index]
        return device_pieces(parts, pose, self._to_enu, yaw)

    def touching(self, index: int, pieces: list[Footprint]) -> bool:
        """Whether robot ``index``'s ``pieces`` touch a solid or another robot where they all are now
        (:func:`pieces_touch`)."""
        fixed = self.attached.get(index, ())
        robots = [ob for j, f in enumerate(self.feet) if f is not None and j != index and j not in fixed
                  for ob in self._robot_obstacles(j)]
        held = self.carried.get(index)      # what it carries is part of it: never touched
        solids = [ob for ob in self._obs if ob.name not in held] if held else self._obs
        return pieces_touch(pieces, self.centres[index], float(self.yaw[index]), float(self.heights[index]),
                            solids, robots)

    def touching_own(self, index: int, pieces: list[Footprint], own: list[Footprint]) -> bool:
        """Whether robot ``index``'s ``pieces`` touch its own shapes' pieces ``own`` (both as
        :meth:`pieces` makes them, where its joints hold them now), as :meth:`touching` takes another
        robot's footprint: a robot with selfCollision, whose bumpers its own parts press."""
        centre, yaw, height = self.centres[index], float(self.yaw[index]), float(self.heights[index])
        obstacles = [shaped_obstacle(index, pc, centre, yaw, (height + pc.z_low, height + pc.z_high)) for pc in own]
        return pieces_touch(pieces, centre, yaw, height, [], obstacles)

    def _robot_obstacles(self, j: int) -> list[Obstacle]:
        """Robot ``j``'s footprint where it is now, as obstacles (:func:`robot_obstacles`)."""
        foot = self.feet[j]
        assert foot is not None
        band = (float(self.heights[j] + self._z_low[j]), float(self.heights[j] + self._z_high[j]))
        return robot_obstacles(j, foot, self.centres[j], float(self.yaw[j]), band)

    @staticmethod
    def _in_band(ob: Obstacle, low: float, high: float) -> Obstacle:
        if ob.sphere:
            # a sphere's section in a band: made once per band (a robot on a flat floor keeps its band),
            # kept among the sphere's own caches (tuple keys, never a grown radius)
            key = ("band", low, high)
            got = ob.grown.get(key)
            if got is None:
                cz = (ob.z_range[0] + ob.z_range[1]) / 2.0
                got = Obstacle(ob.name, -1, ob.points, sphere_radius_in_band(cz, ob.radius, low, high), ob.z_range)
                if len(ob.grown) >= 64:
                    ob.grown.clear()
                ob.grown[key] = got
            return got
        return ob

    def _clip(self, p: np.ndarray, d: np.ndarray, R: float, cands: list[Obstacle]) -> tuple[np.ndarray, bool]:
        """The narrow phase of a disc of radius ``R``: stop at the first contact, slide on, at most
        MAX_SLIDES times."""
        if not cands:
            return p + d, False
        return self._sweep(p, d, [(ob, R) for ob in cands])

    def _clip_carrying(self, i: int, foot: Footprint, loads: list[Footprint], p: np.ndarray, d: np.ndarray,
                       yaw: float, yaw1: float, solids: list[int], robots: list[int]) -> tuple[np.ndarray, bool, float]:
        """The narrow phase of robot ``i`` carrying loads: its own footprint and each load's pieces,
        every piece against what is in its own height band (the floor rule per piece: a solid rising
        more than FLOOR above the piece's bottom, a robot more than EPS), all turning and moving as one
        body. The turn first, in place, as far as every piece sweeping through it overlaps nothing
        it did not already (:meth:`_turn_clear`; cut short by halving as :meth:`_clip_shaped` cuts
        it, never pushed), then the move at the heading kept, stopped by the first contact of any
        piece and slid on (:meth:`_sweep` over every piece's grown candidates). ``solids``,
        ``robots``: the broad phase's candidates over all the pieces' reach and bands."""
        own = foot if not foot.disc else Footprint(foot.radius, foot.z_low, foot.z_high, np.zeros((1, 2)),
                                                   foot.disc_radius)
        robot_obs = [ob for j in robots for ob in self._robot_obstacles(j)]
        return self._clip_pieces([*(own.pieces or (own,)), *loads], float(self.heights[i]), p, d, yaw, yaw1,
                                 solids, robot_obs, None if loads else own)

    def _clip_pieces(self, set_: list[Footprint], h: float, p: np.ndarray, d: np.ndarray, yaw: float, yaw1: float,
                     solids: list[int], robot_obs: list[Obstacle],
                     hull: Footprint | None = None) -> tuple[np.ndarray, bool, float]:
        """The narrow phase of a robot whose outline is the convex pieces ``set_`` (a concave body's,
        :attr:`Footprint.pieces`, and what it carries), at height ``h``: :meth:`_clip_carrying`'s rule,
        every piece against the solids ``solids`` (indices) and the robots' obstacles ``robot_obs`` in
        its own height band. ``hull``: a concave body's own footprint (its pieces' hull, nothing
        carried): a turn the pieces cannot make in place pushes the robot off (:meth:`_push_pieces`:
        by its pieces, else as its hull) before it is cut short."""
        pieces: list[tuple[Footprint, list[Obstacle]]] = []
        for piece in set_:
            lo, hi = h + piece.z_low, h + piece.z_high
            cands = [self._in_band(self._obs[j], lo, hi) for j in solids
                     if self._zhi[j] > lo + FLOOR and self._zlo[j] < hi - EPS]
            cands += [ob for ob in robot_obs if ob.z_range[1] > lo + EPS and ob.z_range[0] < hi - EPS]
            if cands:
                pieces.append((piece, cands))
        if not pieces:
            return p + d, False, yaw1
        kept = yaw1
        turn = math.remainder(yaw1 - yaw, math.tau)
        if turn != 0.0:
            tests = []
            for piece, cands in pieces:
                assert piece.points is not None
                near = _in_reach(cands, p, _STILL, piece.radius)
                if near:
                    here = _turned(piece.points, yaw)
                    tests.append((piece, near, [_gap(p, *_grown(ob, here, piece.round, p)) for ob in near]))

            def clear(part: float) -> bool:
                return all(self._turn_clear(pc, p, yaw, turn * part, near, now) for pc, near, now in tests)

            if tests and not clear(1.0) and hull is not None:
                pushed = self._push_pieces(hull, pieces, solids, robot_obs, h, p, yaw, yaw1, turn)
                if pushed is not None:
                    grown = []
                    for piece, cands in pieces:
                        assert piece.points is not None
                        shape = _turned(piece.points, yaw1)
                        grown += [_grown(ob, shape, piece.round, pushed) for ob in _in_reach(cands, pushed, d, piece.radius)]
                    end, clipped = self._sweep(pushed, d, grown)
                    if not clipped:
                        self.contacts += 1
                    return end, True, yaw1
            if tests and not clear(1.0):
                lo_, hi_ = 0.0, 1.0
                least = 0.5 ** TURN_HALVINGS
                if clear(least):
                    lo_ = least
                    for _ in range(TURN_HALVINGS):
                        mid = 0.5 * (lo_ + hi_)
                        if clear(mid):
                            lo_ = mid
                        else:
                            hi_ = mid
                kept = _wrap(yaw + turn * lo_) if lo_ > 0.0 else yaw
        grown: list[tuple[Obstacle, float]] = []
        for piece, cands in pieces:
            assert piece.points is not None
            reached = _in_reach(cands, p, d, piece.radius)
            if reached:
                shape = _turned(piece.points, kept)
                grown += [_grown(ob, shape, piece.round, p) for ob in reached]
        end, clipped = self._sweep(p, d, grown)
        if kept != yaw1 and not clipped:
            self.contacts += 1
        return end, clipped or kept != yaw1, kept

    def _push_pieces(self, hull: Footprint, pieces: list[tuple[Footprint, list[Obstacle]]], solids: list[int],
                     robot_obs: list[Obstacle], h: float, p: np.ndarray, yaw: float, yaw1: float,
                     turn: float) -> np.ndarray | None:
        """Where a concave body whose pieces' turn in place would go into something is pushed, or None:
        the pieces' own push (:meth:`_push_by_pieces`, the least one that clears them); where that does
        not hold through the turn (a corner passing the peak of its reach within the step), :meth:`_push`
        of its hull (the pieces lie in it, so the hull turned and pushed clear of a candidate leaves
        every piece clear of it) among the candidates in the whole body's band, taken only where every
        piece at the pushed centre, turned to ``yaw1``, is no deeper in any of its candidates than it
        was at ``p`` before the turn (an obstacle in a notch, which the hull overlaps already, may not
        be swept through by a piece)."""
        q = self._push_by_pieces(pieces, hull.radius * min(abs(turn), 2.0), p, yaw, yaw1, turn)
        if q is not None:
            return q
        assert hull.points is not None
        lo, hi = h + hull.z_low, h + hull.z_high
        cands = [self._in_band(self._obs[j], lo, hi) for j in solids] + robot_obs
        near = _in_reach(cands, p, _STILL, hull.radius * (1.0 + min(abs(turn), 2.0)))
        if not near:
            return None
        here = _turned(hull.points, yaw)
        q = self._push(hull, p, yaw, yaw1, turn, near, [_gap(p, *_grown(ob, here, hull.round, p)) for ob in near])
        if q is None:
            return None
        for piece, pcands in pieces:
            assert piece.points is not None
            before, after = _turned(piece.points, yaw), _turned(piece.points, yaw1)
            for ob in pcands:
                self.checks += 1
                if _gap(q, *_grown(ob, after, piece.round, q)) < deepest_end(_gap(p, *_grown(ob, before, piece.round, p)), p):
                    return None
        return q

    def _push_by_pieces(self, pieces: list[tuple[Footprint, list[Obstacle]]], limit: float, p: np.ndarray,
                        yaw: float, yaw1: float, turn: float) -> np.ndarray | None:
        """The least push of a concave body's centre off what its pieces, turned in place from ``yaw``
        to ``yaw1`` at ``p``, go into, or None: each candidate a piece enters, grown by that piece turned
        (:func:`_grown`, convex: the way out along its nearest feature's outward normal is exact), gives
        a push out of it, and each two such give the move meeting both pushes along their normals (a
        piece in a corner, or two pieces in two things); the shortest of these is taken that leaves
        every piece at the pushed centre, turned, no deeper in any candidate than it was at ``p`` (an
        obstacle in a notch stays in it), whose path meets no candidate it did not push off, that is
        not back toward the side the robot came from, no longer than ``limit`` (what the broad phase
        grew the move by), and from where every piece's whole turn is clear (:meth:`_turn_clear`).
        So a post in a U-shaped robot's notch that a finger turns into pushes the robot off it by the
        finger's depth in it, as Webots' bodies collide piece by piece, not out of the notch."""
        grow = 1.0 + min(abs(turn), 2.0)
        tests = []          # (piece, candidate, grown by the piece at yaw, at yaw1, distance at yaw)
        for piece, cands in pieces:
            assert piece.points is not None
            near = _in_reach(cands, p, _STILL, piece.radius * grow)
            if near:
                here, after = _turned(piece.points, yaw), _turned(piece.points, yaw1)
                for ob in near:
                    g0 = _grown(ob, here, piece.round, p)
                    tests.append((piece, ob, g0, _grown(ob, after, piece.round, p), _gap(p, *g0)))
        tries = []
        for k, (_, _, g0, g1, before) in enumerate(tests):
            self.checks += 1
            gap, normal = _gap_normal(p, *g1)
            target = min(before, 0.0)
            if gap < deepest_end(before, p) and float(normal @ _gap_normal(p, *g0)[1]) > 0.0:
                tries.append((target - gap, k, normal))
        if not tries:
            return None
        moves = [(t + BACK_OFF, ((t + BACK_OFF) * n, (k,))) for t, k, n in sorted(tries, key=lambda a: (a[0], a[1]))]
        for a, (ta, ka, na) in enumerate(tries):
            for tb, kb, nb in tries[a + 1:]:
                det = float(na[0] * nb[1] - na[1] * nb[0])
                if abs(det) < 1e-9:
                    continue
                ua, ub = ta + BACK_OFF, tb + BACK_OFF
                s = np.array([ua * nb[1] - ub * na[1], ub * na[0] - ua * nb[0]]) / det
                moves.append((float(np.hypot(*s)), (s, (ka, kb))))
        for size, (step, into) in sorted(moves, key=lambda m: (m[0], m[1][1])):
            if size > limit:
                break
            q = p + step
            ok = True
            for k, (_, _, _, g1, before) in enumerate(tests):
                self.checks += 1
                if _gap(q, *g1) < deepest_end(before, p) or (k not in into and time_of_impact(p, step, *g1)[1] is not None):
                    ok = False
                    break
            if ok and self._pieces_turn_clear(tests, q, yaw, turn):
                return q
        return None

    def _pieces_turn_clear(self, tests: list, q: np.ndarray, yaw: float, turn: float) -> bool:
        """Whether every piece of :meth:`_push_by_pieces`' ``tests``, at ``q`` heading ``yaw``, is no
        deeper in its candidates than at the start and turns by ``turn`` clear of them (:meth:`_turn_clear`)."""
        by_piece: dict[int, tuple[Footprint, list[Obstacle], list[float]]] = {}
        for piece, ob, _, _, before in tests:
            assert piece.points is not None
            now = _gap(q, *_grown(ob, _turned(piece.points, yaw), piece.round, q))
            if now < deepest_end(before, q):
                return False
            entry = by_piece.setdefault(id(piece), (piece, [], []))
            entry[1].append(ob)
            entry[2].append(now)
        return all(self._turn_clear(piece, q, yaw, turn, obs, now) for piece, obs, now in by_piece.values())

    def _clip_shaped(self, foot: Footprint, p: np.ndarray, d: np.ndarray, yaw: float, yaw1: float,
                     cands: list[Obstacle]) -> tuple[np.ndarray, bool, float]:
        """The narrow phase of a shaped footprint turning from heading ``yaw`` to ``yaw1`` (the
        short way): the turn first, in place at the start, as far as the footprint sweeping
        through it overlaps nothing it did not already (or deeper: :meth:`_turn_clear`), then the
        move at the heading it ends with, as :meth:`_clip` with each obstacle grown by the turned
        footprint (:func:`_grown`); a turn that would go into something pushes the robot off it
        instead where it can (:meth:`_push`). ``(end, clipped, heading)``: a turn cut short or
        pushed is clipped."""
        assert foot.points is not None
        if not cands:
            return p + d, False, yaw1
        kept = yaw1
        turn = math.remainder(yaw1 - yaw, math.tau)
        # what the turn, or a push of it (at most foot.radius * min(|turn|, 2)), can meet: the others
        # are left out of the turn's tests, which they cannot change
        memo: dict = {}         # each candidate's distance from p, found once for the reach tests below
        near, reached = _in_reaches(cands, p, foot.radius * (1.0 + min(abs(turn), 2.0)) if turn != 0.0 else None,
                                    d, foot.radius, memo)
        if not near and not reached:        # nothing within reach (most robots near something): the move
            return (p + d if d[0] or d[1] else p), False, yaw1        # as _sweep makes it among none
        if near and self._turn_may_meet(foot, p, turn, near, memo):
            here = _turned(foot.points, yaw)
            now = [_gap(p, *_grown(ob, here, foot.round, p)) for ob in near]
            if not self._turn_clear(foot, p, yaw, turn, near, now):
                pushed = self._push(foot, p, yaw, yaw1, turn, near, now)
                if pushed is not None:
                    # the whole turn, the centre pushed off what the footprint turned into, then the
                    # move from there (the push is a contact: clipped, the drive's x, y written back)
                    shape = _turned(foot.points, yaw1)
                    end, clipped = self._sweep(pushed, d, [_grown(ob, shape, foot.round, pushed)
                                                           for ob in _in_reach(cands, pushed, d, foot.radius)])
                    if not clipped:
                        self.contacts += 1
                    return end, True, yaw1
                # the largest part of the turn that is clear (none is), halving; a robot already
                # touching where it turns (pressed on) is told by its first step, 2^-12 of the turn
                lo, hi = 0.0, 1.0
                least = 0.5 ** TURN_HALVINGS
                if self._turn_clear(foot, p, yaw, turn * least, near, now):
                    lo = least
                    for _ in range(TURN_HALVINGS):
                        mid = 0.5 * (lo + hi)
                        if self._turn_clear(foot, p, yaw, turn * mid, near, now):
                            lo = mid
                        else:
                            hi = mid
                kept = _wrap(yaw + turn * lo) if lo > 0.0 else yaw
        if reached:
            shape = _turned(foot.points, kept)
            end, clipped = self._sweep(p, d, [_grown(ob, shape, foot.round, p) for ob in reached])
        else:
            end, clipped = self._sweep(p, d, [])
        if kept != yaw1 and not clipped:
            self.contacts += 1
        return end, clipped or kept != yaw1, kept

    def _push(self, foot: Footprint, p: np.ndarray, yaw: float, yaw1: float, turn: float,
              cands: list[Obstacle], now: list[float], swept: bool = True) -> np.ndarray | None:
        """Where rigid contact pushes the robot's centre when the whole turn from ``yaw`` to ``yaw1``
        at ``p`` would put its footprint into a candidate (``now``: each one's signed distance at
        ``yaw``), or None: the least move, out of the candidate it would go deepest into, along
        the outward normal of the nearest feature of that candidate grown by the turned footprint
        (:func:`_grown`, convex: the distance out is exact), to where the turned footprint touches
        it (no deeper than at ``yaw`` if it overlapped already). Refused (None: the turn is cut
        short as before) when the turn sweeps into any other candidate (:meth:`_turn_clear`), the
        push goes back toward the side the robot came from, is longer than any footprint point
        moved in the turn (``foot.radius`` times min(|turn|, 2): what the broad phase grew the move
        by), or its path or end meets another candidate (deeper than it already was). Each
        candidate the turn goes into is tried in turn, the deepest first: a wall of several
        blocks pushes the robot off all of them at once; in a corner of two walls, where a push
        off either leaves it in the other, :meth:`_push_off_both` pushes it out of both."""
        assert foot.points is not None
        shape = _turned(foot.points, yaw1)
        grown = [_grown(ob, shape, foot.round, p) for ob in cands]
        pushes = []
        for i, (g, before) in enumerate(zip(grown, now)):
            self.checks += 1
            gap, normal = _gap_normal(p, *g)
            target = min(before, 0.0)
            if gap < deepest_end(before, p):
                pushes.append((target - gap, i, normal))
        if not pushes:
            # the turned footprint overlaps nothing where the turn ends, but a corner's arc dips into
            # something on the way (past the peak of its reach toward a wall): pushed off by that depth
            return self._push_sweep(foot, p, yaw, turn, cands, now)
        into = {i for _, i, _ in pushes}
        rest = [j for j in range(len(cands)) if j not in into]
        if rest and not self._turn_clear(foot, p, yaw, turn, [cands[j] for j in rest], [now[j] for j in rest]):
            # the turn also sweeps into one it does not end in (a corner of two walls, the turn past
            # the peak of its reach toward one of them): pushed off that one's sweep first
            # (:meth:`_push_sweep`), then off the others from there, its sweep still clear
            if not swept:
                return None
            others, before = [cands[j] for j in rest], [now[j] for j in rest]
            base = self._push_sweep(foot, p, yaw, turn, others, before)
            if base is None:
                return None
            here = _turned(foot.points, yaw)
            for j in into:
                self.checks += 1
                if time_of_impact(p, base - p, *_grown(cands[j], here, foot.round, p))[1] is not None:
                    return None
            q = self._push(foot, base, yaw, yaw1, turn, cands,
                           [_gap(base, *_grown(ob, here, foot.round, base)) for ob in cands], False)
            if q is None or float(np.hypot(*(q - p))) > foot.radius * min(abs(turn), 2.0):
                return None
            after = [_gap(q, *_grown(ob, here, foot.round, q)) for ob in others]
            if any(a < deepest_end(b, p) for a, b in zip(after, before)) or not self._turn_clear(foot, q, yaw, turn, others, after):
                return None
            return q
        limit = foot.radius * min(abs(turn), 2.0)
        here = _turned(foot.points, yaw)
        for dist, i, normal in sorted(pushes, key=lambda t: (-t[0], t[1])):
            if dist > limit:
                continue
            _, back = _gap_normal(p, *_grown(cands[i], here, foot.round, p))
            if float(normal @ back) <= 0.0:
                continue
            step = (dist + BACK_OFF) * normal
            q = p + step
            ok = True
            for j, (g, before) in enumerate(zip(grown, now)):
                self.checks += 1
                if _gap(q, *g) < deepest_end(before, p) or (j != i and time_of_impact(p, step, *g)[1] is not None):
                    ok = False
                    break
            if ok:
                return q
        if len(pushes) == 2:         # a corner of two: the least move out of both, if that fits
            return self._push_off_both(p, pushes[0][1], pushes[1][1], grown, now, cands, here, foot.round, limit)
        return None

    def _push_sweep(self, foot: Footprint, p: np.ndarray, yaw: float, turn: float, cands: list[Obstacle],
                    now: list[float]) -> np.ndarray | None:
        """The push when the turn from ``yaw`` by ``turn`` at ``p`` ends overlapping nothing but sweeps
        into a candidate on the way (a box robot's corner passing the peak of its reach toward a wall
        it rests on), or None: the least move along one of that candidate's axes (its edge normals,
        fixed; a wall line's normal) that keeps the footprint at least touching it at every heading of
        the turn -- the turn's least separation along the axis (:func:`_least_along`, exact), so the
        centre ends as far off as the footprint reached into it; where no one axis's push clears the
        turn and it dips into two candidates (a square's corners passing their peaks toward both walls
        of a corner in one step), the least move meeting one axis of each. Checked as :meth:`_push` checks a push:
        not back toward the side the robot came from, no longer than any footprint point moved in the
        turn, neither its path nor its end meets another candidate (deeper than it already was), and
        the whole turn from there is clear of every candidate (:meth:`_turn_clear`)."""
        assert foot.points is not None
        if min(now) < -EPS:
            return None
        here = _turned(foot.points, yaw)
        rnd = foot.round
        lo, hi = (0.0, turn) if turn >= 0.0 else (turn, 0.0)
        limit = foot.radius * min(abs(turn), 2.0)
        grown = [_grown(ob, here, rnd, p) for ob in cands]
        tries = []
        for i, ob in enumerate(cands):
            if self._turn_clear(foot, p, yaw, turn, [ob], [now[i]]):
                continue
            self.checks += 1
            _, back = _gap_normal(p, *grown[i])
            if ob.normal is not None:
                side = 1.0 if float(ob.normal @ p) + ob.offset >= 0.0 else -1.0
                axes = (side * ob.normal)[None, :]
                reach = -float(np.min(_least_along(here, lo, hi, -axes))) + rnd
                need = np.array([reach - abs(float(ob.normal @ p) + ob.offset)])
            else:
                q = ob.points - p[None, :]
                _, _, axes = _edges(q)
                if not len(axes):
                    continue
                need = rnd + ob.radius - (_least_along(here, lo, hi, axes) - np.max(axes @ q.T, axis=1))
            for k in range(len(axes)):
                t = float(need[k])
                if 0.0 < t <= limit and float(axes[k] @ back) > 0.0:
                    tries.append((t, i, k, axes[k]))
        # one axis's push first; then, for a turn that dips into two candidates at once (a square's
        # corners passing their peaks toward both walls of a corner in one step), the least move
        # meeting one axis of each (both needs met exactly: each separation is linear in the centre)
        moves = [((t + BACK_OFF) * n, (i,)) for t, i, _, n in sorted(tries, key=lambda a: (a[0], a[1], a[2]))]
        pairs = []
        for a, (ta, ia, _, na) in enumerate(tries):
            for tb, ib, _, nb in tries[a + 1:]:
                det = float(na[0] * nb[1] - na[1] * nb[0])
                if ia == ib or abs(det) < 1e-9:
                    continue
                ua, ub = ta + BACK_OFF, tb + BACK_OFF
                s = np.array([ua * nb[1] - ub * na[1], ub * na[0] - ua * nb[0]]) / det
                size = float(np.hypot(*s))
                if size <= limit:
                    pairs.append((size, s, (ia, ib)))
        moves += [(s, ij) for _, s, ij in sorted(pairs, key=lambda a: (a[0], a[2]))]
        for step, into in moves:
            q = p + step
            after = []
            for j, (g, before) in enumerate(zip(grown, now)):
                self.checks += 1
                gap = _gap(q, *_grown(cands[j], here, rnd, q))
                if gap < deepest_end(before, p) or (j not in into and time_of_impact(p, step, *g)[1] is not None):
                    break
                after.append(gap)
            else:
                if self._turn_clear(foot, q, yaw, turn, cands, after):
                    return q
        return None

    def _push_off_both(self, p: np.ndarray, i: int, j: int, grown: list[tuple[Obstacle, float]], now: list[float],
                       cands: list[Obstacle], here: np.ndarray, rnd: float, limit: float) -> np.ndarray | None:
        """The push out of two candidates at once (a corner of two walls), when no push off one of
        them alone fits: the least move of the centre ``p``, which the turned footprint puts inside
        both (``grown``: each candidate grown by it), to a point outside both -- the nearest point
        of the boundary of their union, which is on an edge of one outside the other (the edge's
        nearest point to ``p``, clamped to the edge) or where an edge of each cross: exact, in closed
        form, for two polygons (a box's, a mesh's; grown by a footprint without a round part), None
        otherwise or where either overlapped the footprint before the turn (deeper than EPS). Then
        checked as :meth:`_push` checks a push off one: no longer than ``limit``, not back toward
        either side the robot came from, and neither its path nor its end meets another candidate."""
        ga, ra = grown[i]
        gb, rb = grown[j]
        if (ra or rb or ga.radius or gb.radius or ga.normal is not None or gb.normal is not None
                or len(ga.points) < 3 or len(gb.points) < 3 or min(now[i], now[j]) < -EPS):
            return None
        px, py = float(p[0]), float(p[1])
        best = (math.inf, px, py)
        for poly, other in ((ga, gb), (gb, ga)):
            v = poly.points.tolist()
            for k in range(len(v)):
                (ax, ay), (bx, by) = v[k - 1], v[k]
                ex, ey = bx - ax, by - ay
                ee = ex * ex + ey * ey
                t = min(max(((px - ax) * ex + (py - ay) * ey) / ee, 0.0), 1.0) if ee > 0.0 else 0.0
                qx, qy = ax + t * ex, ay + t * ey
                d = math.hypot(qx - px, qy - py)
                if d < best[0] and _gap(np.array([qx, qy]), other, 0.0) >= -EPS:
                    best = (d, qx, qy)
        va, vb = ga.points.tolist(), gb.points.tolist()
        for k in range(len(va)):
            (ax, ay), (bx, by) = va[k - 1], va[k]
            ex, ey = bx - ax, by - ay
            for m in range(len(vb)):
                (cx, cy), (dx, dy) = vb[m - 1], vb[m]
                fx, fy = dx - cx, dy - cy
                den = ex * fy - ey * fx
                if den == 0.0:
                    continue
                wx, wy = cx - ax, cy - ay
                s, u = (wx * fy - wy * fx) / den, (wx * ey - wy * ex) / den
                if 0.0 <= s <= 1.0 and 0.0 <= u <= 1.0:
                    qx, qy = ax + s * ex, ay + s * ey
                    d = math.hypot(qx - px, qy - py)
                    if d < best[0]:
                        best = (d, qx, qy)
        dist, qx, qy = best
        if not 0.0 < dist <= limit:
            return None
        unit = np.array([(qx - px) / dist, (qy - py) / dist])
        for k in (i, j):
            self.checks += 1
            _, back = _gap_normal(p, *_grown(cands[k], here, rnd, p))
            if float(unit @ back) <= 0.0:
                return None
        step = (dist + BACK_OFF) * unit
        q = p + step
        for k, (g, before) in enumerate(zip(grown, now)):
            self.checks += 1
            if _gap(q, *g) < deepest_end(before, p) or (k != i and k != j and time_of_impact(p, step, *g)[1] is not None):
                return None
        return q

    @staticmethod
    def _turn_may_meet(foot: Footprint, p: np.ndarray, turn: float, cands: list[Obstacle],
                       memo: dict | None = None) -> bool:
        """False when no candidate comes within reach of the turn, which :meth:`_turn_clear` would
        then find clear: at every heading the footprint lies in the disc of ``foot.radius`` about
        ``p``; a candidate farther than that (by more than the distances' rounding) is met at none.
        Most robots near something are turning in its broad-phase reach, not this one."""
        reach = foot.radius
        margin = EPS + 1e-9 * (1.0 + abs(float(p[0])) + abs(float(p[1])) + reach)
        return any(_gap(p, ob, reach, memo) <= margin for ob in cands)

    def _turn_clear(self, foot: Footprint, p: np.ndarray, yaw: float, turn: float, cands: list[Obstacle],
                    now: list[float]) -> bool:
        """Whether the footprint at ``p`` turning from ``yaw`` by ``turn`` stays clear of every
        candidate: at no heading of the turn nearer to it than ``now`` (each one's signed distance
        at ``yaw``) if it overlaps, nor overlapping it (by more than EPS) if it does not
        (:func:`turn_gap_holds`: each vertex's arc, closed form). A turn whose points move less
        than every candidate's distance (each point moves at most the chord 2 r sin(|turn| / 2) of
        its reach r, and a signed distance changes by no more than the footprint moves) is clear
        of a candidate without its arcs."""
        assert foot.points is not None
        delta = 2.0 * (foot.radius - foot.round) * math.sin(min(abs(turn), math.pi) / 2.0)
        margin = 1e-9 * (1.0 + abs(float(p[0])) + abs(float(p[1])) + foot.radius)
        shape = None
        for ob, gap in zip(cands, now):
            if gap - delta - margin >= deepest_end(gap, p):
                continue
            if shape is None:
                shape = _turned(foot.points, yaw)
            self.checks += 1
            if not turn_gap_holds(shape, foot.round, turn, ob, p, deepest_end(gap, p), gap):
                return False
        return True

    def _sweep(self, p: np.ndarray, d: np.ndarray, cands: list[tuple[Obstacle, float]]) -> tuple[np.ndarray, bool]:
        """Move the point ``p`` by ``d`` among ``cands`` (each an obstacle and the radius it is
        grown by): stop at the first contact, slide on, at most MAX_SLIDES times."""
        clipped = False
        for _ in range(MAX_SLIDES + 1):
            if not (d[0] or d[1]):
                break
            best, best_n = math.inf, None
            for ob, R in cands:
                self.checks += 1
                s, n = time_of_impact(p, d, ob, R)
                if s < best:
                    best, best_n = s, n
            if best_n is None:
                p = p + d
                break
            clipped = True
            length = math.hypot(d[0], d[1])
            s = max(best - BACK_OFF / length, 0.0) if best > 0.0 else 0.0
            p = p + s * d
            rest = (1.0 - s) * d
            into = float(rest @ best_n)
            d = rest - into * best_n if into < 0.0 else rest
        if clipped:
            self.contacts += 1
        return p, clipped
