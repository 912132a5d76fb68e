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

Two ways to cast blind to them, the same loop: a ray whose nearest hit is one of its device's own
shapes is cast again from just past it, until it meets another shape or nothing.

* :func:`cast_local_skipping`, rigidly mounted rays (infra-red, lidar): the robot's own body is
  cast once per sensor, in the body frame, and kept.
* :func:`cast_skipping`, an image's rays in the world (cameras, range finders: their casts carry
  shape ids anyway): every capture, only the rays that met an own shape are cast again (a camera
  inside a closed box: each ray twice).

Only devices that have own shapes pay for this.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from sensorium.server.raycast.engine import RayHits, RayKind

MAX_PASSES = 64     # crossings of a device's own shapes one ray may pass (two per closed shape)


def _skipping(cast: Callable[[bool, np.ndarray, np.ndarray, np.ndarray], RayHits], n: int, t_near, t_far,
              mine: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> RayHits:
    """The loop: ``cast(first, rows, near, far)`` casts those rays (``first``: every ray, with the
    caller's own limits), ``mine(rows, shapes)`` says which hits are own shapes; those rays go
    again from just past their hit."""
    near = np.broadcast_to(np.asarray(t_near, dtype=np.float64), (n,)).copy()
    far = np.broadcast_to(np.asarray(t_far, dtype=np.float64), (n,))
    t = np.full(n, np.inf)
    shape = np.full(n, -1, dtype=np.int64)
    normal = np.zeros((n, 3))
    rows = np.arange(n)
    for p in range(MAX_PASSES):
        if not len(rows):
            break
        h = cast(p == 0, rows, near[rows], far[rows])
        own = mine(rows, h.shape)
        done = ~own
        t[rows[done]], shape[rows[done]], normal[rows[done]] = h.distance[done], h.shape[done], h.normal[done]
        rows = rows[own]
        near[rows] = np.nextafter(h.distance[own], np.inf)     # again, from just past the own shape
    return RayHits(t, normal, shape)


def cast_local_skipping(engine, body: int, origins: np.ndarray, directions: np.ndarray, t_near, t_far,
                        kind: RayKind, skip_transparent: bool, own: Sequence[frozenset[int]]) -> RayHits:
    """``engine.cast_local`` on ``body``, each ray ``i`` blind to the shapes ``own[i]`` (global shape
    indices): the nearest hit on any other shape of the body, or no hit."""

    def cast(first: bool, rows: np.ndarray, near: np.ndarray, far: np.ndarray) -> RayHits:
        return engine.cast_local(body, origins[rows], directions[rows], near, far, kind=kind,
                                 skip_transparent=skip_transparent)

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
