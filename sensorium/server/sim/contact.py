"""Kinematic contact: a driven robot's body cannot enter solids (as bounding rays see them) or
other robots' bodies. No physics engine: a blocked robot *slides* along what it touched.

Robots move in the world xy-plane, so contact is solved in 2D within each robot's height band:

* a robot's footprint is the vertical disc of radius ``R`` around its origin that contains its
  body (exact for an upright cylinder, capsule or sphere; the circumscribed circle of a box);
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
  robots);
* over one basic step the robot's centre moves along the chord from its start to its end pose
  (poses are only observed at the end of steps, and the end point is the exact arc end unless
  contact clips it). The chord is tested against every obstacle near it (an AABB broad phase)
  in closed form — segment vs. offset edges and vertex circles of ``obstacle ⊕ disc(R)`` — so a
  fast robot at a grazing angle cannot tunnel, whatever the step length. Features the chord
  certainly cannot reach (plain float screens, margins far above the tests' rounding) are not
  tested: the answer of testing them all, bit for bit.

On contact the robot stops at the contact point and the rest of its displacement is projected on
the contact's tangent (slide), up to three times per step (corners). A robot pushed straight into
a wall therefore stops at the contact distance; one meeting it obliquely keeps the tangential
part of its motion, as a Webots robot rubbing along a wall does. Its heading change is always
applied (a disc turns freely), so a blocked robot can always turn away. Deterministic: robots are
resolved in world order, each against the others' current positions. Float64 throughout.
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
UPRIGHT = 1.0 - 1e-12


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
    lo: np.ndarray = field(default_factory=lambda: np.zeros(2))
    hi: np.ndarray = field(default_factory=lambda: np.zeros(2))
    # per grown radius: the vertices as floats and the edges offset by it (_hull_data; points never change)
    grown: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.normal is not None:
            self.lo = np.full(2, -math.inf)
            self.hi = np.full(2, math.inf)
        elif len(self.points) == 1:     # one point (a robot's disc, a pillar): it is its min and max
            self.lo = self.points[0] - self.radius
            self.hi = self.points[0] + self.radius
        else:
            self.lo = self.points.min(axis=0) - self.radius
            self.hi = self.points.max(axis=0) + self.radius


@dataclass(slots=True)
class Footprint:
    """A robot's disc: radius and height band relative to its origin."""

    radius: float
    z_low: float
    z_high: float


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


def robot_footprint(parts: list[tuple[geo.Primitive, Pose]]) -> Footprint | None:
    """The disc (about the robot's origin) containing every body shape, each at its offset in the
    robot frame: conservative for off-centre shapes, exact for one centred upright shape."""
    feet = []
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
    if not feet:
        return None
    return Footprint(max(f.radius for f in feet), min(f.z_low for f in feet), max(f.z_high for f in feet))


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


def obstacle(name: str, owner: int, prim: geo.Primitive, pose: Pose) -> Obstacle | None:
    """A solid's (or robot body's) 2D obstacle at ``pose``; None for a non-vertical plane."""
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


def _closest_on_list(px: float, py: float, v: list) -> tuple[float, np.ndarray]:
    """:func:`_closest_on_hull` of the point (px, py) and the hull's vertices as a list of [x, y]."""
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
            # (overlapping, as a move from outside may leave it: deeper than it already is)
            return (0.0, nrm) if rate < -EPS or gap + rate < min(gap, 0.0) - EPS else (math.inf, None)
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
        dist, normal = _closest_on_list(px, py, v)
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
            return (0.0, normal) if end_dist - rad < min(dist - rad, 0.0) - EPS else (math.inf, None)
    best: float = math.inf
    best_n: np.ndarray | None = None
    a = float(d @ d)
    # Each vertex circle and offset edge whose answer is certainly inf or beyond the move (s > 1:
    # never the answer) is skipped on a float test with margins far above its rounding (see
    # _circle_beyond, _edge_beyond); the others get the exact test, in the same order: the same
    # answer, bit for bit, for a few float operations instead of a dozen numpy calls per feature.
    if a != 0.0:                                     # (a == 0: every circle test answers inf)
        for i, (cx, cy) in enumerate(v):
            if _circle_beyond(px - cx, py - cy, dx, dy, a, rad):
                continue
            s = _ray_circle(p, d, pts[i], rad, a)
            if s < best:
                best, best_n = s, (p + s * d - pts[i]) / rad
    for A, B, out, ax, ay, ox, oy in edges:          # a segment (n = 2) gets both sides: a→b and b→a
        if _edge_beyond(ax - px, ay - py, dx, dy, ox, oy):
            continue
        s = _ray_segment(p, d, A, B, out)
        if s < best:
            best, best_n = s, out.copy()
    if best > 1.0:
        return math.inf, None
    return best, best_n


def _hull_data(ob: Obstacle, rad: float) -> tuple[list, list]:
    """``ob``'s vertices as [x, y] floats and, with 2 vertices or more, its edges a→b offset
    outward by ``rad``: (a + rad·out, b + rad·out, out, and their floats a + rad·out, out), the
    same numpy operations :func:`time_of_impact` did per call; made once per (obstacle, rad) --
    a solid's obstacle lives as long as the solid stays put, and a robot's grown radius is fixed."""
    got = ob.grown.get(rad)
    if got is None:
        pts = ob.points
        n = len(pts)
        edges = []
        if n >= 2:
            for i in range(n):
                a, b = pts[i], pts[(i + 1) % n]
                e = b - a
                out = np.array([e[1], -e[0]]) / math.hypot(e[0], e[1])
                A, B = a + rad * out, b + rad * out
                edges.append((A, B, out, float(A[0]), float(A[1]), float(out[0]), float(out[1])))
        got = ob.grown[rad] = (pts.tolist(), edges)
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


# ---------------------------------------------------------------------- the resolver

class Contact:
    """The world's static obstacles plus the robots' discs; :meth:`resolve` clips one robot's move."""

    def __init__(self, solids: list[tuple[str, geo.Primitive, Pose, Pose, bool]],
                 robots: list[tuple[list[tuple[geo.Primitive, Pose]], Pose]], to_enu: np.ndarray | None = None):
        """``solids``: one entry per shape — (solid name, primitive, pose in the solid's frame, the
        solid's world pose, seen by bounding rays); a solid made of several shapes (or with nested
        children) gives several entries under one name, moved together. ``robots``: (body shapes
        with their poses in the robot frame, initial pose) in world order. ``to_enu``: world axes to
        ENU (None in an ENU world): contact is solved in ENU, where the drives keep their planar
        state, so every pose given (here, :meth:`update_solid`, :meth:`place`) is turned into it."""
        self._to_enu = to_enu
        self.prims: dict[str, list[tuple[geo.Primitive, Pose]]] = {}
        first_pose: dict[str, Pose] = {}
        for name, prim, local, pose, bounding in solids:
            if bounding:
                self.prims.setdefault(name, []).append((prim, local))
                first_pose.setdefault(name, pose)
        self.solids: dict[tuple[str, int], Obstacle] = {}
        for name, pose in first_pose.items():
            self.update_solid(name, pose)
        self.feet: list[Footprint | None] = [robot_footprint(enu_body(parts, pose, to_enu)) for parts, pose in robots]
        nan = math.nan                            # robots without a footprint never match the broad phase
        self._radius = np.array([f.radius if f else nan for f in self.feet], dtype=np.float64)
        self._z_low = np.array([f.z_low if f else nan for f in self.feet], dtype=np.float64)
        self._z_high = np.array([f.z_high if f else nan for f in self.feet], dtype=np.float64)
        starts = [enu_pose(p, to_enu).translation for _, p in robots]
        self.centres = np.array([[t[0], t[1]] for t in starts], dtype=np.float64).reshape(-1, 2)
        self.heights = np.array([t[2] for t in starts], dtype=np.float64)
        self.contacts = 0                         # robot-steps whose motion was clipped
        self.checks = 0                           # narrow-phase obstacle tests
        self._rebuild()

    def update_solid(self, name: str, pose: Pose) -> None:
        pose = enu_pose(pose, self._to_enu)
        for i, (prim, local) in enumerate(self.prims.get(name, ())):
            ob = obstacle(name, -1, prim, pose.compose(local))
            if ob is None:
                self.solids.pop((name, i), None)
            else:
                self.solids[(name, i)] = ob
        if hasattr(self, "feet"):
            self._rebuild()

    def add_solid(self, name: str, shapes: list[tuple[geo.Primitive, Pose, bool]], pose: Pose) -> None:
        """A solid a Supervisor imported: an obstacle from now on (its bounding shapes: (primitive,
        pose in the solid's frame, seen by bounding rays), as the constructor takes them)."""
        prims = [(prim, local) for prim, local, bounding in shapes if bounding]
        if prims:
            self.prims[name] = prims
            self.update_solid(name, pose)

    def remove_solid(self, name: str) -> None:
        """A solid removed by a Supervisor: no longer an obstacle."""
        for i in range(len(self.prims.pop(name, ()))):
            self.solids.pop((name, i), None)
        self._rebuild()

    def _rebuild(self) -> None:
        obs = list(self.solids.values())
        self._obs = obs
        self._lo = np.array([o.lo for o in obs]).reshape(-1, 2)
        self._hi = np.array([o.hi for o in obs]).reshape(-1, 2)
        self._zlo = np.array([o.z_range[0] for o in obs], dtype=np.float64)
        self._zhi = np.array([o.z_range[1] for o in obs], dtype=np.float64)

    def place(self, index: int, pose: Pose) -> None:
        """A robot was moved from outside (set_pose, reset): no contact check, as in Webots."""
        pose = enu_pose(pose, self._to_enu)
        self.centres[index] = pose.translation[:2]
        self.heights[index] = pose.translation[2]

    def resolve(self, index: int, start, end) -> tuple[np.ndarray, bool]:
        """Clip robot ``index``'s move from ``start`` to ``end`` (xy): ``(final xy, clipped)``."""
        return self.resolve_all([index], np.asarray([start], dtype=np.float64),
                                np.asarray([end], dtype=np.float64))[0]

    def resolve_all(self, indices: list[int], starts: np.ndarray, ends: np.ndarray) -> list[tuple[np.ndarray, bool]]:
        """Clip the moves of several robots (one basic step), in order: each sees the others where
        they are when its turn comes. One vectorised broad phase for all of them: a move (with its
        slides) never leaves the disc of radius |end - start| around its start."""
        k = len(indices)
        idx = np.asarray(indices, dtype=np.int64)
        reach = np.hypot(*(ends - starts).T) + EPS
        R = self._radius[idx]
        box_lo = starts - (reach + R)[:, None]
        box_hi = starts + (reach + R)[:, None]
        band_lo = self.heights[idx] + self._z_low[idx]
        band_hi = self.heights[idx] + self._z_high[idx]
        if len(self._obs):
            solid_hit = (np.all((self._lo[None] <= box_hi[:, None]) & (self._hi[None] >= box_lo[:, None]), axis=2)
                         & (self._zhi[None] > band_lo[:, None] + FLOOR) & (self._zlo[None] < band_hi[:, None] - EPS))
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
        near_solids: list[list[int]] = [[] for _ in range(k)]
        near_robots: list[list[int]] = [[] for _ in range(k)]
        if len(self._obs):
            for m, j in zip(*(x.tolist() for x in np.nonzero(solid_hit))):
                near_solids[m].append(j)
        if robot_hit is not None:
            for m, j in zip(*(x.tolist() for x in np.nonzero(robot_hit))):
                near_robots[m].append(j)
        out = []
        for m in range(k):
            i = int(idx[m])
            if self.feet[i] is None:
                self.centres[i] = ends[m]
                out.append((ends[m].copy(), False))
                continue
            cands: list[Obstacle] = [self._in_band(self._obs[j], float(band_lo[m]), float(band_hi[m]))
                                     for j in near_solids[m]]
            if near_robots[m]:
                for j in near_robots[m]:
                    cands.append(Obstacle(f"robot {j}", int(j), self.centres[j][None, :].copy(), float(self._radius[j]),
                                          (float(self.heights[j] + self._z_low[j]), float(self.heights[j] + self._z_high[j]))))
            p, clipped = self._clip(starts[m].copy(), ends[m] - starts[m], float(R[m]), cands)
            self.centres[i] = p
            out.append((p, clipped))
        return out

    @staticmethod
    def _in_band(ob: Obstacle, low: float, high: float) -> Obstacle:
        if ob.sphere:
            cz = (ob.z_range[0] + ob.z_range[1]) / 2.0
            return Obstacle(ob.name, -1, ob.points, sphere_radius_in_band(cz, ob.radius, low, high), ob.z_range)
        return ob

    def _clip(self, p: np.ndarray, d: np.ndarray, R: float, cands: list[Obstacle]) -> tuple[np.ndarray, bool]:
        """The narrow phase: stop at the first contact, slide on, at most MAX_SLIDES times."""
        if not cands:
            return p + d, False
        clipped = False
        for _ in range(MAX_SLIDES + 1):
            if not (d[0] or d[1]):
                break
            best, best_n = math.inf, None
            for ob in cands:
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
