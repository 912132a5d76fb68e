"""The world as Foxglove sees it: a ``foxglove.SceneUpdate`` and ``foxglove.FrameTransforms``
(used by recordings and by the live viewer, sensorium.server.viewer).

Frames (the same names the topics' ``header.frame_id`` use):

* ``world`` — the world frame (z up);
* ``<robot>`` — a robot's body frame, placed by its pose (``/<robot>/pose``);
* ``<robot>/<device>`` — a device's frame (FLU), fixed on its robot by the device's ``pose`` (a
  device riding a joint: moved with it, from ``/<robot>/joint_states``).

The scene has one entity per static solid (frame ``world``), one per robot body (frame
``<robot>``, ``frame_locked`` so it moves with the robot's transform) and one per light (a small
sphere at a point/spot light's location, an arrow for a directional light or a spot light's
direction, in the light's colour). Boxes, spheres and cylinders are Foxglove primitives; capsules and
mesh files are triangle lists; a finite plane is a flat cube, an infinite plane is drawn as a
``INFINITE_PLANE_SIZE`` square (Foxglove has no infinite primitive). Colours are the appearance's
``base_color`` with alpha ``1 - transparency``; a shape without appearance is drawn light grey
(Webots draws it white). A textured shape keeps that rule: an ``Appearance`` with an image is white
(the loader's base colour: the image replaces the diffuse colour), a ``PBRAppearance`` its
``baseColor``. ``drawn`` gives the models of the shapes whose appearance a Supervisor changed
(``Scene.drawn_models``): those are drawn as they look now, by the same rule.

Everything here is pure: world model in, ``foxglove.messages`` objects out (encode with
``.encode()``; the schema is ``SceneUpdate.get_schema()`` / ``FrameTransforms.get_schema()``).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from collections.abc import Set as AbstractSet
from pathlib import Path
from typing import Any

import numpy as np
from foxglove.messages import (
    ArrowPrimitive,
    Color,
    CubePrimitive,
    CylinderPrimitive,
    FrameTransform,
    FrameTransforms,
    KeyValuePair,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneEntityDeletion,
    SceneEntityDeletionType,
    SceneUpdate,
    SpherePrimitive,
    Timestamp,
    TriangleListPrimitive,
    Vector3,
)

from sensorium.schemas import world as wm
from sensorium.server.recording.frames import (
    INFINITE_PLANE_SIZE,
    WORLD_FRAME,
    bodies,
    lights,
    mounts,
    quat_from_x,
    shape_rgba,
)
from sensorium.server.world import geometry as geo
from sensorium.server.world.poses import matrix_quaternion

__all__ = ["WORLD_FRAME", "INFINITE_PLANE_SIZE", "MAX_SCENE_TRIANGLES", "scene_update", "mounts",
           "frame_transforms", "mount_transforms", "timestamp"]

MAX_SCENE_TRIANGLES = 200_000    # meshes beyond this budget (whole scene) are drawn as their bounding boxes
_LIGHT_MARK = 0.05               # radius of the sphere drawn at a light's location (m)


def timestamp(ns: int) -> Timestamp:
    ns = max(int(ns), 0)
    return Timestamp(ns // 1_000_000_000, ns % 1_000_000_000)


def _color(shape: Any, ghost: bool = False) -> Color:
    r, g, b, a = shape_rgba(shape, ghost)
    return Color(r=r, g=g, b=b, a=a)


def _pose(translation: Iterable[float], quaternion: Iterable[float]) -> Pose:
    t = [float(v) for v in translation]
    q = [float(v) for v in quaternion]
    return Pose(position=Vector3(x=t[0], y=t[1], z=t[2]), orientation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))


_IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def _triangles(vertices: np.ndarray, faces: np.ndarray, pose: Pose, color: Color) -> TriangleListPrimitive:
    v = np.asarray(vertices, dtype=np.float64)
    pts = [Point3(x=x, y=y, z=z) for x, y, z in v.tolist()]
    return TriangleListPrimitive(pose=pose, points=pts, color=color,
                                 indices=[int(i) for i in np.asarray(faces, dtype=np.int64).reshape(-1).tolist()])


def shape_primitives(shape: wm.Shape, pose: Pose, base_dir: Path, budget: list[int],
                     ghost: bool = False) -> dict[str, list[Any]]:
    """The Foxglove primitives drawing one shape at ``pose`` (in its entity's frame), keyed by the
    ``SceneEntity`` field they go in. ``budget`` (one-element list) is the triangles left."""
    from sensorium.server.sim.scene import primitive_from_model

    g, color = shape.geometry, _color(shape, ghost)
    if isinstance(g, wm.Box):
        return {"cubes": [CubePrimitive(pose=pose, size=Vector3(x=g.size[0], y=g.size[1], z=g.size[2]), color=color)]}
    if isinstance(g, wm.Sphere):
        d = 2.0 * g.radius
        return {"spheres": [SpherePrimitive(pose=pose, size=Vector3(x=d, y=d, z=d), color=color)]}
    if isinstance(g, wm.Cylinder):      # both Webots (R2022+ here) and Foxglove: axis along local z
        d = 2.0 * g.radius
        return {"cylinders": [CylinderPrimitive(pose=pose, size=Vector3(x=d, y=d, z=g.height),
                                                bottom_scale=1.0, top_scale=1.0, color=color)]}
    if isinstance(g, wm.Plane):
        sx, sy = g.size if g.size is not None else (INFINITE_PLANE_SIZE, INFINITE_PLANE_SIZE)
        return {"cubes": [CubePrimitive(pose=pose, size=Vector3(x=sx, y=sy, z=0.0), color=color)]}
    prim = primitive_from_model(g, base_dir)          # capsule, mesh
    vertices, faces = fit_budget(*geo.tessellate(prim), budget)
    return {"triangles": [_triangles(vertices, faces, pose, color)]}


def fit_budget(vertices: np.ndarray, faces: np.ndarray, budget: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """The triangles to draw: the mesh itself while ``budget[0]`` (triangles left for the scene)
    allows, else its bounding box (12 triangles, in the shape's own frame; budget unchanged)."""
    if len(faces) <= budget[0]:
        budget[0] -= len(faces)
        return vertices, faces
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    sx, sy, sz = (float(max(s, 1e-6)) for s in hi - lo)
    box_v, box_f = geo.tessellate(geo.Box(size=(sx, sy, sz)))
    return box_v + (lo + hi) / 2.0, box_f


def _entity(frame_id: str, entity_id: str, stamp_ns: int, parts: dict[str, Any], kind: str,
            frame_locked: bool = False) -> SceneEntity:
    return SceneEntity(timestamp=timestamp(stamp_ns), frame_id=frame_id, id=entity_id, frame_locked=frame_locked,
                       metadata=[KeyValuePair(key="kind", value=kind)], **parts)


def _light_entity(entity_id: str, frame_id: str, frame_locked: bool, light: Any, stamp_ns: int) -> SceneEntity:
    r, g, b = (float(c) for c in light.color)
    alpha = 1.0 if light.on else 0.3
    color = Color(r=r, g=g, b=b, a=alpha)
    parts: dict[str, list[Any]] = {}
    loc = getattr(light, "location", None)
    if loc is not None:
        d = 2.0 * _LIGHT_MARK
        parts["spheres"] = [SpherePrimitive(pose=_pose(loc, _IDENTITY[1]), size=Vector3(x=d, y=d, z=d), color=color)]
    direction = getattr(light, "direction", None)
    if direction is not None:
        dvec = np.asarray(direction, dtype=np.float64)
        dvec = dvec / np.linalg.norm(dvec)
        q = quat_from_x(dvec)
        start = loc if loc is not None else (0.0, 0.0, 1.0)      # a directional light has no place: drawn above the origin
        parts["arrows"] = [ArrowPrimitive(pose=_pose(start, q), shaft_length=0.25, shaft_diameter=0.01,
                                          head_length=0.06, head_diameter=0.03, color=color)]
    return _entity(frame_id, entity_id, stamp_ns, parts, f"light:{light.type}", frame_locked=frame_locked)


MAX_DELETIONS = 64
"""Past this many removed nodes, a scene update deletes everything drawn before it (then draws the world)."""


def scene_update(world: wm.World, base_dir: str | Path, stamp_ns: int = 0,
                 solid_poses: dict[str, Any] | None = None, removed_lights: AbstractSet[int] = frozenset(),
                 drawn: Mapping[int, Any] | None = None) -> SceneUpdate:
    """The whole world as one ``SceneUpdate``. ``solid_poses`` (name → geometry ``Pose``) overrides
    the file's pose of a solid that was moved since loading (its children and lights move with it);
    a solid it leaves out was removed (a Supervisor's ``node.remove()``): not drawn, and deleted, as
    the world's top-level lights of ``removed_lights`` (indices in ``world.lights``). ``drawn``
    (``id()`` of a shape model ``world`` holds → the model to draw in its place) gives the shapes
    whose appearance a Supervisor changed (``Scene.drawn_models``)."""
    base = Path(base_dir)
    budget = [MAX_SCENE_TRIANGLES]
    entities: list[SceneEntity] = []
    for body in bodies(world, solid_poses):
        merged: dict[str, list[Any]] = {}
        for shape, pose, ghost in body.parts:
            if drawn:
                shape = drawn.get(id(shape), shape)
            fx_pose = _pose(pose.translation, matrix_quaternion(pose.rotation))
            for key, prims in shape_primitives(shape, fx_pose, base, budget, ghost).items():
                merged.setdefault(key, []).extend(prims)
        entities.append(_entity(body.frame_id, body.entity_id, stamp_ns, merged, body.kind,
                                frame_locked=body.frame_locked))
    # what a Supervisor removed (a solid in the world, not in solid_poses; a top-level light): deleted
    # from a viewer that drew it (whatever its timestamp: a removed node never comes back)
    gone = [] if solid_poses is None else [f"solid/{s.name}" for s in world.solids if s.name not in solid_poses]
    for k, (entity_id, frame_id, locked, light) in enumerate(lights(world, solid_poses)):
        if k < len(world.lights) and k in removed_lights:       # the world's top-level lights come first
            gone.append(entity_id)
            continue
        entities.append(_light_entity(entity_id, frame_id, locked, light, stamp_ns))
    if len(gone) > MAX_DELETIONS:
        # a Supervisor that removed many nodes (importing and removing for days): one deletion of everything
        # drawn before, then the whole world again (a viewer applies the deletions first), not one per node
        # the world has ever lost, which would grow every scene update without bound
        deletions = [SceneEntityDeletion(timestamp=Timestamp(2**32 - 1, 0), type=SceneEntityDeletionType.All, id="")]
    else:
        deletions = [SceneEntityDeletion(timestamp=Timestamp(2**32 - 1, 0), type=SceneEntityDeletionType.MatchingId,
                                         id=entity_id) for entity_id in gone]
    return SceneUpdate(deletions=deletions, entities=entities)


def frame_transforms(robot: str, stamp_ns: int, translation: Iterable[float], quaternion: Iterable[float],
                     robot_mounts: list[tuple[str, Any, Any]]) -> FrameTransforms:
    """``world → robot`` at its pose plus ``robot → robot/device`` for each device mount."""
    ts = timestamp(stamp_ns)
    t = [float(v) for v in translation]
    q = [float(v) for v in quaternion]
    items = [FrameTransform(timestamp=ts, parent_frame_id=WORLD_FRAME, child_frame_id=robot,
                            translation=Vector3(x=t[0], y=t[1], z=t[2]),
                            rotation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))]
    return FrameTransforms(transforms=items + _mount_items(robot, ts, robot_mounts))


def mount_transforms(robot: str, stamp_ns: int, robot_mounts: list[tuple[str, Any, Any]]) -> FrameTransforms:
    """``robot → robot/device`` for each mount only (the devices a joint moved)."""
    return FrameTransforms(transforms=_mount_items(robot, timestamp(stamp_ns), robot_mounts))


def _mount_items(robot: str, ts: Timestamp, robot_mounts: list[tuple[str, Any, Any]]) -> list[FrameTransform]:
    return [FrameTransform(timestamp=ts, parent_frame_id=robot, child_frame_id=frame,
                           translation=Vector3(x=mt[0], y=mt[1], z=mt[2]),
                           rotation=Quaternion(x=mq[0], y=mq[1], z=mq[2], w=mq[3]))
            for frame, mt, mq in robot_mounts]
