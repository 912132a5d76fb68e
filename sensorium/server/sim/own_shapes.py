"""A device never sees its own shapes.

Real PROTOs wrap a device's origin in shapes of its own Solid: each e-puck infra-red sensor sits
in its own small box, its camera in another, a SICK lidar's origin inside its housing. Webots'
visual sensing never sees them: its infra-red ray casting reports no hit for a ray starting inside
a Box or a Sphere (``WbBox::computeLocalCollisionPoint``, ``WbRay::intersects`` with culling) and
culls triangles seen from behind; its lidars, cameras and range finders render with back faces
culled and clip at ``near``. Sensorium's visual rays see surfaces from both sides, so the shapes of
a device's own Solid (and of its children), ``of_device`` in the world file, are left out of that
device's visual rays -- infra-red rays, lidar beams, camera and range-finder pixel rays (a
camera's recognition rays too); the rest of its robot stays visible to it, as in Webots. (ODE-style
rays -- generic, sonar, laser, light occlusion -- skip the whole robot unless ``self_collision``, as
Webots does, and are not changed; a camera's shadow rays are the scene's lighting: its housing
still casts shadows, as in Webots.)

The loop: a ray whose nearest hit is one of its device's own shapes is cast again from just past
it, until it meets another shape or nothing. Rays rigidly mounted on the robot (infra-red, lidar
beams, an image's pixel rays) are cast in the world without their robot's body (``mount``), and
that body is met once, in its own frame, with :func:`cast_local_skipping` (the same answer at every
pose: kept); :class:`OwnBodyRays` does both for an image device. :func:`cast_skipping` runs the
loop in the world, for the rays a camera casts on past a semi-transparent surface. Only devices
that have own shapes pay for this.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from sensorium.server.raycast.engine import Mount, RayHits, RayKind
from sensorium.server.raycast.exact import _mat
from sensorium.server.world.geometry import Pose

MAX_PASSES = 64     # crossings of a device's own shapes one ray may pass (two per closed shape)


def _skipping(cast: Callable[[bool, np.ndarray, np.ndarray, np.ndarray], RayHits], n: int, t_near, t_far,
              mine: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> RayHits:
    """The loop: ``cast(first, rows, near, far)`` casts those rays (``first``: every ray, with the
    caller's own limits), ``mine(rows, shapes)`` says which hits are own shapes; those rays go
    again from just past their hit. When no ray's first hit is an own shape (most casts), that
    cast is the answer, with no per-ray tables made."""
    rows = np.arange(n)
    first = cast(True, rows, t_near, t_far)
    own = mine(rows, first.shape)
    if not own.any():
        return RayHits(first.distance, first.normal, first.shape)
    near = np.broadcast_to(np.asarray(t_near, dtype=np.float64), (n,)).copy()
    far = np.broadcast_to(np.asarray(t_far, dtype=np.float64), (n,))
    t = np.full(n, np.inf)
    shape = np.full(n, -1, dtype=np.int64)
    normal = np.zeros((n, 3))
    for p in range(MAX_PASSES):
        if not len(rows):
            break
        if p:
            h = cast(False, rows, near[rows], far[rows])
            own = mine(rows, h.shape)
        else:
            h = first
        done = ~own
        t[rows[done]], shape[rows[done]], normal[rows[done]] = h.distance[done], h.shape[done], h.normal[done]
        rows = rows[own]
        near[rows] = np.nextafter(h.distance[own], np.inf)     # again, from just past the own shape
    return RayHits(t, normal, shape)


def cast_local_skipping(engine, body: int, origins: np.ndarray, directions: np.ndarray, t_near, t_far,
                        kind: RayKind, skip_transparent: bool,
                        own: Sequence[frozenset[int]] | frozenset[int]) -> RayHits:
    """``engine.cast_local`` on ``body``, each ray ``i`` blind to the shapes ``own[i]`` (global shape
    indices; one set for every ray: ``own``): the nearest hit on any other shape of the body, or no hit."""

    def cast(first: bool, rows: np.ndarray, near, far) -> RayHits:
        if first:       # every ray, with the caller's limits: no gathered copies
            return engine.cast_local(body, origins, directions, near, far, kind=kind, skip_transparent=skip_transparent)
        return engine.cast_local(body, origins[rows], directions[rows], near, far, kind=kind,
                                 skip_transparent=skip_transparent)

    if isinstance(own, frozenset):
        ids = np.fromiter(own, dtype=np.int64, count=len(own))

        def mine(rows: np.ndarray, shapes: np.ndarray) -> np.ndarray:
            return np.isin(shapes, ids)
    else:
        def mine(rows: np.ndarray, shapes: np.ndarray) -> np.ndarray:
            return np.array([s >= 0 and int(s) in own[r] for r, s in zip(rows.tolist(), shapes.tolist())], dtype=bool)

    return _skipping(cast, len(origins), t_near, t_far, mine)


def cast_skipping(engine, origins: np.ndarray, directions: np.ndarray, t_near, t_far, own: frozenset[int],
                  kind: RayKind = RayKind.VISUAL, directions32: np.ndarray | None = None) -> RayHits:
    """``engine.cast`` of one device's rays in the world (nothing excluded), blind to the shapes
    ``own`` (global shape indices): each ray's nearest hit on any other shape, or no hit. The first
    pass is the plain cast (``directions32`` as :meth:`RayEngine.cast` takes it)."""
    own_ids = np.fromiter(own, dtype=np.int64, count=len(own))
    one = origins.ndim == 2 and len(origins) > 0 and origins.strides[0] == 0      # a broadcast origin

    def cast(first: bool, rows: np.ndarray, near: np.ndarray, far: np.ndarray) -> RayHits:
        if first:
            return engine.cast(origins, directions, t_near, t_far, kind=kind, exclude_owner=-1,
                               directions32=directions32)
        O = np.broadcast_to(origins[0], (len(rows), 3)) if one else origins[rows]
        return engine.cast(O, directions[rows], near, far, kind=kind, exclude_owner=-1)

    def mine(rows: np.ndarray, shapes: np.ndarray) -> np.ndarray:
        return np.isin(shapes, own_ids)

    return _skipping(cast, len(origins), t_near, t_far, mine)


def cast_past(engine, origins: np.ndarray, directions: np.ndarray, t_near, t_far, first: RayHits,
              skip: frozenset[int], kind: RayKind = RayKind.VISUAL) -> RayHits:
    """``first`` (a plain world cast of these rays, shapes kept) with each ray whose hit is one of ``skip``
    cast on from just past it, blind to ``skip``: the shapes a Supervisor hid from a device (setVisibility)
    and its own. Only the rays that met such a shape are cast again."""
    ids = np.fromiter(skip, dtype=np.int64, count=len(skip))
    rows = np.flatnonzero(np.isin(first.shape, ids))
    if not len(rows):
        return first
    n = len(first.distance)
    far = np.broadcast_to(np.asarray(t_far, dtype=np.float64), (n,))[rows]
    near = np.nextafter(first.distance[rows], np.inf)
    h = cast_skipping(engine, np.ascontiguousarray(origins[rows]), np.ascontiguousarray(directions[rows]), near, far,
                      skip, kind)
    distance, normal, shape = first.distance.copy(), np.array(first.normal, copy=True), first.shape.copy()
    distance[rows], normal[rows], shape[rows] = h.distance, h.normal, h.shape
    return RayHits(distance, normal, shape)


class OwnBodyRays:
    """An image device's pixel rays (directions in its frame) when it has shapes of its own: cast
    mounted on its robot's body, which the world cast then skips, and nearer hits on that body
    (blind to the device's own shapes) taken from one cast in the body frame, kept per precision --
    the lidar's way. Distances come out as a plain cast's; a hit on the robot's body is the body-frame
    answer (the same surface; the last bit may differ from a world cast's)."""

    def __init__(self, body: int, local: Pose, directions: np.ndarray, t_near, t_far, own: frozenset[int]):
        self.body = body
        self.mount = Mount(np.full(len(directions), body, dtype=np.int64))
        self.limits = (t_near, t_far)
        self._local = (np.ascontiguousarray(np.broadcast_to(local.translation, directions.shape)),
                       _mat(directions, local.rotation.T))    # (row blocks)
        self._own = own
        self._hits: tuple[object, RayHits] | None = None

    def body_hits(self, engine) -> RayHits:
        if self._hits is None or self._hits[0] != (engine.precision, engine.seen_version):
            O, D = self._local
            self._hits = ((engine.precision, engine.seen_version), cast_local_skipping(engine, self.body, O, D, *self.limits,
                                                                RayKind.VISUAL, False, self._own))
        return self._hits[1]

    def cast(self, engine, origins: np.ndarray, directions: np.ndarray, robot_rotation: np.ndarray,
             directions32: np.ndarray | None = None, distance_only: bool = False) -> RayHits:
        """The rays from the device's world pose (``directions``: these rays turned into the world)."""
        h = engine.cast(origins, directions, *self.limits, kind=RayKind.VISUAL, exclude_owner=-1, mount=self.mount,
                        distance_only=distance_only, directions32=directions32)
        b = self.body_hits(engine)
        win = (b.distance < h.distance).nonzero()[0]
        if not len(win):
            return h
        dist = h.distance.copy()
        dist[win] = b.distance[win]
        if distance_only:
            return RayHits(dist, None, None)
        assert h.shape is not None and h.normal is not None and b.shape is not None
        shape, normal = h.shape.copy(), h.normal.copy()
        shape[win] = b.shape[win]
        normal[win] = b.normal[win] @ robot_rotation.T          # body frame -> world
        return RayHits(dist, normal, shape)
