"""Webots' static balance (the Supervisor's ``getStaticBalance``) without physics.

Webots takes the contact points its physics found under a top-level solid (and the solids inside it)
in the last step, their convex hull seen along gravity (its support polygon), and answers whether the
solid's centre of mass, seen the same way, is over that polygon, its edges included. Here nothing
collides, so the contact points are where the solid's bounding shapes touch the ground under them now:
the points of each shape that can touch a ground below it (:func:`lowest_points`: a box's corners, a
sphere's or capsule's lowest point, a cylinder's lowest rim points and its end rims, a wheel's bottom
among them; any other shape's support points, ground.support_points) that lie within CONTACT_TOL of the
ground under them, that ground being the one a let-go solid lands on (``Simulation.landing_ground``:
floors, terrains, ramps' top faces, box and cylinder tops not above the point, the other solids where
they are); and where a shape's points at a box or cylinder top's height span a face, a line or a point,
the part of it over that top (:func:`clip`), so a face over a table's edge is held up to the edge. A
solid touching nothing (in the air) has no contact point and is not balanced.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.contact import FLOOR, enu_pose
from sensorium.server.sim.ground import Ground, hull_2d, over_support, support_points, volume_centre
from sensorium.server.sim.motion import _TO_ENU
from sensorium.server.world.geometry import Pose

__all__ = ["CONTACT_TOL", "EDGE_TOL", "FACING_DOWN", "balanced", "clip", "contact_points", "dynamic_entries", "dynamic_solids",
           "lowest_points", "robot_balance", "robot_contacts", "shapes_centre", "solid_balance", "solid_contacts", "touching"]

CONTACT_TOL = FLOOR
"""m: a bounding shape's point at most this far above or below the ground under it touches it (kinematic
contact's floor tolerance)."""
EDGE_TOL = 1e-9
"""m: a centre of mass this close to the support polygon's edge is over it (Webots counts the edges in)."""

FACING_DOWN = 1e-9
"""A box face's outward normal's vertical part below minus this faces down (a face turned level by a
rotation's rounding, some 1e-16, does not)."""

_UP = np.array([0.0, 0.0, 1.0])


def lowest_points(g: object, prim: object, at: Pose) -> np.ndarray:
    """The points (ENU) of a bounding shape at ENU pose ``at`` that may touch a ground under it: a
    sphere's lowest point; a capsule's lowest point of each end; a cylinder's lowest rim point of each
    end (on its side it touches along the line between them), a cone's lowest base rim point and its
    apex, and, when the bottom rim lies within CONTACT_TOL of level, the end turned down alone with its
    rim (standing on an end it touches all round; its rim's points near the bottom are never taken for a side's line); a
    box's corners on a face turned down (FACING_DOWN); any other shape's support points (ground.support_points)."""
    r, c = at.rotation, at.translation
    if isinstance(g, wm.Sphere):
        return (c - float(g.radius) * _UP)[None]
    if isinstance(g, wm.Box):
        # the corners on a face turned down: a top corner is the box's own height above the bottom one under
        # it, which a box 1 mm high or less would put within CONTACT_TOL of the ground too
        corners = support_points(g, prim)
        down = (np.sign(corners) * r[2]).min(axis=1) < -FACING_DOWN
        return corners[down] @ r.T + c
    if not isinstance(g, (wm.Capsule, wm.Cylinder, wm.Cone)):
        return support_points(g, prim) @ r.T + c
    axis = r[:, 2]
    half = float(g.height) / 2.0
    ends = np.array([c + half * axis, c - half * axis])
    if isinstance(g, wm.Capsule):
        return ends - float(g.radius) * _UP
    radius = float(g.bottom_radius if isinstance(g, wm.Cone) else g.radius)
    side = _UP - float(_UP @ axis) * axis         # the up without its part along the axis
    n = float(np.linalg.norm(side))               # sin of the axis's tilt from the vertical
    lowest = ends if n == 0.0 else ends - (radius / n) * side
    if isinstance(g, wm.Cone):                    # its apex, the top end's centre
        lowest = np.array([ends[0], lowest[1]])
    if 2.0 * radius * n > CONTACT_TOL:
        return lowest
    # level: the end turned down alone (a disc 1 mm thick or less has its top end within CONTACT_TOL too), its
    # centre (any rim point is a lowest one: a tilt of 1e-16 would pick one of them) and its rim
    rim = support_points(g, prim)
    return np.vstack([ends[[axis[2] < 0.0, axis[2] > 0.0]], rim[np.sign(rim[:, 2]) * axis[2] < 0.0] @ r.T + c])


def _points(parts: list[tuple[Pose, Any]], pose: Pose, base_dir: Any, to_enu: np.ndarray | None) -> list[np.ndarray]:
    """:func:`lowest_points` of each bounding shape of ``parts`` ((pose in the owner's frame, shape)),
    the owner at ``pose``; Planes and ElevationGrids are ground, not something that rests."""
    from sensorium.server.sim.scene import primitive_from_model

    return [lowest_points(shape.geometry, primitive_from_model(shape.geometry, base_dir),
                          enu_pose(pose.compose(local), to_enu))
            for local, shape in parts if _touches(shape)]


def _inside(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """How far ``p`` (x, y) is on the inner (left) side of the edge from ``a`` to ``b`` (m)."""
    e = b - a
    return float(e[0] * (p[1] - a[1]) - e[1] * (p[0] - a[0])) / float(np.hypot(e[0], e[1]))


def clip(face: np.ndarray, outline: np.ndarray) -> np.ndarray:
    """The part of ``face`` (x, y: a convex polygon counter-clockwise, a segment or a point, as
    ground's hull gives them) inside the convex counter-clockwise ``outline`` (within EDGE_TOL), its
    corners: Sutherland-Hodgman, each edge of the outline cutting it in turn (a segment as a polygon of
    two corners that does not close)."""
    pts = [np.asarray(p, dtype=np.float64) for p in face]
    closed = len(pts) >= 3
    for k in range(len(outline)):
        a, b = outline[k], outline[(k + 1) % len(outline)]
        kept: list[np.ndarray] = []
        ends = len(pts) if closed else len(pts) - 1
        if len(pts) == 1:
            kept = pts if _inside(pts[0], a, b) >= -EDGE_TOL else []
        for i in range(max(ends, 0)):
            p, q = pts[i], pts[(i + 1) % len(pts)]
            dp, dq = _inside(p, a, b), _inside(q, a, b)
            if dp >= -EDGE_TOL and (not kept or not np.array_equal(kept[-1], p)):
                kept.append(p)
            if (dp < -EDGE_TOL) != (dq < -EDGE_TOL):            # the edge crosses the line: its crossing
                kept.append(p + (dp / (dp - dq)) * (q - p))
            if not closed and dq >= -EDGE_TOL:
                kept.append(q)
        pts = kept
        if not pts:
            break
    return np.array(pts, dtype=np.float64).reshape(-1, 2)


def contact_points(shapes: list[np.ndarray], ground: Ground | None) -> np.ndarray:
    """The contact points (ENU) of shapes whose :func:`lowest_points` are ``shapes`` (one array each):
    those points within CONTACT_TOL of the ground under each (``Ground.under``, taking no box top or
    ramp above the point + CONTACT_TOL), and where a shape's points at a box or cylinder top's height
    (within CONTACT_TOL) span a face, a line or a point, the part of it over that top (:func:`clip`):
    a face over a top's edge is held up to that edge."""
    return touching(shapes, ground)[0]


def touching(shapes: list[np.ndarray], ground: Ground | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`contact_points` and, for each point, the index in ``shapes`` of the shape touching there; a
    shape's points at the same place seen from above counted once."""
    if ground is None or not shapes:
        return np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
    points = np.vstack(shapes)
    of = np.repeat(np.arange(len(shapes)), [len(p) for p in shapes])
    found, z, _, _ = ground.under(points[:, 0], points[:, 1], points[:, 2] + CONTACT_TOL)
    on = found & (np.abs(points[:, 2] - z) <= CONTACT_TOL)
    contacts = [points[on]]
    owners = [of[on]]
    tops = ground.tops()
    if tops:
        heights = np.array([h for h, _ in tops])
        lows = np.array([o.min(axis=0) for _, o in tops])
        highs = np.array([o.max(axis=0) for _, o in tops])
        for index, shape in enumerate(shapes):
            # the tops at its points' heights whose outline's box meets its own, seen from above
            lo, hi = shape.min(axis=0), shape.max(axis=0)
            near_tops = ((heights >= lo[2] - CONTACT_TOL) & (heights <= hi[2] + CONTACT_TOL)
                         & (lows <= hi[:2]).all(axis=1) & (highs >= lo[:2]).all(axis=1))
            for k in near_tops.nonzero()[0]:
                height, outline = tops[k]
                near = shape[np.abs(shape[:, 2] - height) <= CONTACT_TOL]
                if len(near):
                    held = clip(hull_2d(near[:, :2]), outline)
                    contacts.append(np.column_stack([held, np.full(len(held), height)]))
                    owners.append(np.full(len(held), index))
    points, of = np.vstack(contacts), np.concatenate(owners)
    if len(contacts) > 1:
        # a point over a top is found twice: on the ground under it and as a corner of its face held by the
        # top (clip keeps the hull's own coordinates): once per shape, the first kept, in order
        _, first = np.unique(np.column_stack([of.astype(np.float64), points[:, :2]]), axis=0, return_index=True)
        first.sort()
        points, of = points[first], of[first]
    return points, of


def balanced(contacts: np.ndarray, centre: np.ndarray) -> bool:
    """Whether the centre of mass (ENU) is over (within EDGE_TOL of) the support polygon of ``contacts``
    (ENU) seen from above: their convex hull, or the segment or point they make; False without any."""
    return bool(len(contacts)) and over_support(contacts[:, :2], np.asarray(centre, dtype=np.float64)[:2], EDGE_TOL)


def shapes_centre(parts: list[tuple[Pose, Any]], pose: Pose, base_dir: Any, to_enu: np.ndarray | None) -> np.ndarray:
    """The centre (ENU) of the bounding shapes' volumes of a solid with physics but no mass given (a YAML
    world's ``physics: true``), uniform density, as its landing weighs it (ground.volume_centre)."""
    from sensorium.server.sim.scene import primitive_from_model

    weighed = []
    for local, shape in parts:
        if shape.seen_by in ("both", "bounding") and not isinstance(shape.geometry, (wm.Plane, wm.ElevationGrid)):
            at = enu_pose(pose.compose(local), to_enu)
            volume, centre = volume_centre(shape.geometry, primitive_from_model(shape.geometry, base_dir))
            weighed.append((volume, at.rotation @ centre + at.translation))
    total = sum(v for v, _ in weighed)
    if total > 0.0:
        return sum(v * c for v, c in weighed) / total
    return enu_pose(pose, to_enu).translation


def _enu(point: Any, to_enu: np.ndarray | None) -> np.ndarray:
    p = np.asarray(point, dtype=np.float64)
    return p if to_enu is None else to_enu @ p


def solid_balance(sim: Any, name: str, centre: Any) -> bool:
    """A top-level solid with physics: whether ``centre`` (its centre of mass, world axes; None for a
    solid given no mass: its shapes' volumes', :func:`shapes_centre`) is over its contact points on the
    ground a let-go solid lands on, itself left out (:func:`balanced`)."""
    from sensorium.server.sim.scene import solid_parts

    model = next(s for s in sim.world.solids if s.name == name)
    parts = [(local, shape) for _, local, shape in solid_parts(model, Pose.identity())]
    pose = sim.scene.solid_poses[name]
    to_enu = _TO_ENU[sim.world.world_info.coordinate_system]
    base = sim.loaded.base_dir
    contacts = contact_points(_points(parts, pose, base, to_enu), sim.landing_ground(name))
    return balanced(contacts, shapes_centre(parts, pose, base, to_enu) if centre is None else _enu(centre, to_enu))


def _world(points: np.ndarray, to_enu: np.ndarray | None) -> np.ndarray:
    """ENU points back in the world's axes (``to_enu`` is a permutation: its transpose undoes it)."""
    return points if to_enu is None else points @ to_enu


def solid_contacts(sim: Any, name: str, descendants: bool) -> tuple[np.ndarray, list[tuple[int, ...]]]:
    """Webots' ``getContactPoints`` of top-level solid ``name``: where its bounding shapes (and, with
    ``descendants``, those of the solids inside it) touch the ground a let-go solid lands on now
    (:func:`touching`), in world axes, and for each point the path of the solid whose shape touches there
    (scene.owned_solid_parts: () the top one)."""
    from sensorium.server.sim.scene import owned_solid_parts

    model = next(s for s in sim.world.solids if s.name == name)
    owned = [(path, local, shape) for path, _, local, shape in owned_solid_parts(model, Pose.identity())
             if descendants or not path]
    parts = [(local, shape) for _, local, shape in owned]
    owners = [path for path, _, shape in owned if _touches(shape)]
    to_enu = _TO_ENU[sim.world.world_info.coordinate_system]
    points, of = touching(_points(parts, sim.scene.solid_poses[name], sim.loaded.base_dir, to_enu),
                          sim.landing_ground(name))
    return _world(points, to_enu), [owners[k] for k in of]


def dynamic_solids(model: wm.Solid) -> set[tuple[int, ...]]:
    """The paths (scene.owned_solid_parts) of the solids inside ``model`` that Webots' physics moves although
    ``model`` has no Physics: each nested one with a Physics node (the import keeps a nested solid's Physics as
    its mass; one without a volume to weigh has no shape that touches either) and every solid inside it (merged
    into its body)."""
    moving: set[tuple[int, ...]] = set()
    stack: list[tuple[wm.Solid, tuple[int, ...], bool]] = [(child, (k,), False) for k, child in enumerate(model.children)]
    while stack:
        solid, path, inside_moving = stack.pop()
        if inside_moving or solid.physics or solid.mass is not None or solid.pending_mass is not None:
            moving.add(path)
        stack.extend((child, (*path, k), path in moving) for k, child in enumerate(solid.children))
    return moving


def dynamic_entries(nodes: list[wm.NestedNode]) -> set[int]:
    """The indices in a robot's ``nodes`` of those Webots' physics moves although the robot has no Physics:
    each with a Physics node (its mass) and every node inside one (a Solid there is merged into its body)."""
    moving: set[int] = set()
    for k, n in enumerate(nodes):          # (a parent is an earlier entry)
        if n.mass is not None or n.pending_mass is not None or n.parent in moving:
            moving.add(k)
    return moving


def robot_contacts(sim: Any, state: Any, descendants: bool) -> tuple[np.ndarray, list[int]]:
    """Webots' ``getContactPoints`` of a robot: where its bounding shapes touch the ground now, its
    joints holding them where they are (:func:`robot_balance`'s points), in world axes, and for each
    point the index in the robot's ``nodes`` of the Solid whose shape touches (``Part.in_solid``; -1:
    the robot's own). Without ``descendants``, the robot's own shapes only."""
    from sensorium.server.sim.scene import robot_parts

    links = state.links
    owned = [(getattr(shape, "in_solid", -1), local if links is None or (j := getattr(shape, "on_joint", None))
              not in links.poses else links.poses[j].compose(local), shape) for _, local, shape in robot_parts(state.model)]
    owned = [o for o in owned if descendants or o[0] < 0]
    ground = sim.landing_ground("\0" + state.model.name, carrier=state.index)
    points, of = touching(_points([(local, shape) for _, local, shape in owned], state.pose, sim.loaded.base_dir,
                                  state.to_enu), ground)
    owners = [solid for solid, _, shape in owned if _touches(shape)]
    return _world(points, state.to_enu), [owners[k] for k in of]


def _touches(shape: Any) -> bool:
    """Whether :func:`_points` takes ``shape`` (a bounding shape that is no ground)."""
    return shape.seen_by in ("both", "bounding") and not isinstance(shape.geometry, (wm.Plane, wm.ElevationGrid))


def robot_balance(sim: Any, state: Any, centre: Any) -> bool:
    """A robot with physics: whether ``centre`` (its centre of mass, world axes) is over its contact
    points: its bounding shapes where its joints hold them now (its wheels among them) on the ground a
    let-go solid lands on, its own shapes left out (:func:`balanced`)."""
    from sensorium.server.sim.scene import robot_parts

    links = state.links
    parts = [(local if links is None or (j := getattr(shape, "on_joint", None)) not in links.poses
              else links.poses[j].compose(local), shape) for _, local, shape in robot_parts(state.model)]
    ground = sim.landing_ground("\0" + state.model.name, carrier=state.index)
    contacts = contact_points(_points(parts, state.pose, sim.loaded.base_dir, state.to_enu), ground)
    return balanced(contacts, _enu(centre, state.to_enu))
