"""A device never sees its own shapes.

Real PROTOs wrap a device's origin in shapes of its own Solid: each e-puck infra-red sensor sits
in its own small box, a SICK lidar's origin inside its housing. Webots' visual sensing never sees
them: its infra-red ray casting reports no hit for a ray starting inside a Box or a Sphere
(``WbBox::computeLocalCollisionPoint``, ``WbRay::intersects`` with culling) and culls triangles
seen from behind; its lidars render with back faces culled and clip at ``near``. Sensorium's visual
rays see surfaces from both sides, so the shapes of a device's own Solid (and of its children),
``of_device`` in the world file, are left out of that device's visual rays; the rest of its robot
stays visible to it, as in Webots. (ODE-style rays — generic, sonar, laser, light occlusion — skip
the whole robot unless ``self_collision``, as Webots does, and are not changed.)

The robot's own body is cast once per sensor, in the body frame (the rays are rigidly mounted): a
ray whose nearest own-body hit is one of its device's own shapes is cast again from just past it,
until it meets another shape or nothing. Only devices that have own shapes pay for this, once.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sensorium.server.raycast.engine import RayHits, RayKind

MAX_PASSES = 64     # crossings of a device's own shapes one ray may pass (two per closed shape)


def cast_local_skipping(engine, body: int, origins: np.ndarray, directions: np.ndarray, t_near, t_far,
                        kind: RayKind, skip_transparent: bool, own: Sequence[frozenset[int]]) -> RayHits:
    """``engine.cast_local`` on ``body``, each ray ``i`` blind to the shapes ``own[i]`` (global shape
    indices): the nearest hit on any other shape of the body, or no hit."""
    n = len(origins)
    near = np.broadcast_to(np.asarray(t_near, dtype=np.float64), (n,)).copy()
    far = np.broadcast_to(np.asarray(t_far, dtype=np.float64), (n,))
    t = np.full(n, np.inf)
    shape = np.full(n, -1, dtype=np.int64)
    normal = np.zeros((n, 3))
    rows = np.arange(n)
    for _ in range(MAX_PASSES):
        if not len(rows):
            break
        h = engine.cast_local(body, origins[rows], directions[rows], near[rows], far[rows], kind=kind,
                              skip_transparent=skip_transparent)
        mine = np.array([s >= 0 and int(s) in own[r] for r, s in zip(rows.tolist(), h.shape.tolist())], dtype=bool)
        done = ~mine
        t[rows[done]], shape[rows[done]], normal[rows[done]] = h.distance[done], h.shape[done], h.normal[done]
        rows = rows[mine]
        near[rows] = np.nextafter(h.distance[mine], np.inf)     # again, from just past the own shape
    return RayHits(t, normal, shape)
