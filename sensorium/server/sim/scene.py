"""Validated world → scene: ray-engine bodies, per-shape metadata, lights, robot poses.

Every solid is one static body (until it is moved); every robot is one movable body (its optional
body geometry). The global shape index returned by the ray engine indexes ``Scene.shapes``, which
carries what the devices need: owner robot, and the red channel and roughness infra-red sensors
read.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.raycast.engine import Precision, RayEngine, ShapeEntry
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.meshes import load_mesh
from sensorium.server.world.poses import pose_from_model


@dataclass(frozen=True, slots=True)
class ShapeInfo:
    name: str            # solid name, or "<robot>/body"
    owner: int           # robot index, -1 for world solids
    red: float           # infra-red reflectance: base_color.r * (1 - transparency); 1 without appearance
    roughness: float
    transparency: float


def primitive_from_model(g: wm.Box | wm.Sphere | wm.Cylinder | wm.Capsule | wm.Plane | wm.Mesh, base_dir: Path) -> geo.Primitive:
    if isinstance(g, wm.Box):
        return geo.Box(size=tuple(g.size))
    if isinstance(g, wm.Sphere):
        return geo.Sphere(radius=g.radius, subdivision=g.subdivision)
    if isinstance(g, wm.Cylinder):
        return geo.Cylinder(radius=g.radius, height=g.height, subdivision=g.subdivision)
    if isinstance(g, wm.Capsule):
        return geo.Capsule(radius=g.radius, height=g.height, subdivision=g.subdivision)
    if isinstance(g, wm.Plane):
        return geo.Plane(size=None if g.size is None else tuple(g.size))
    if isinstance(g, wm.Mesh):
        return load_mesh(base_dir / g.url, g.scale)
    raise TypeError(f"unknown geometry {g!r}")


def _shape_info(name: str, owner: int, shape: wm.Shape) -> ShapeInfo:
    a = shape.appearance
    if a is None:
        return ShapeInfo(name, owner, red=1.0, roughness=0.0, transparency=0.0)
    return ShapeInfo(name, owner, red=a.base_color[0] * (1.0 - a.transparency), roughness=a.roughness,
                     transparency=a.transparency)


def _entry(shape: wm.Shape, base_dir: Path) -> ShapeEntry:
    transparent = shape.appearance is not None and shape.appearance.transparency >= 1.0
    return ShapeEntry(
        primitive=primitive_from_model(shape.geometry, base_dir),
        local_pose=Pose.identity(),
        bounding=shape.seen_by in ("both", "bounding"),
        visual=shape.seen_by in ("both", "visual"),
        transparent=transparent,
    )


class Scene:
    """Geometry and poses of a world; the only owner of the ray engine."""

    def __init__(self, world: wm.World, base_dir: Path, precision: Precision | str = Precision.EXACT):
        self.engine = RayEngine(Precision(precision))
        self.shapes: list[ShapeInfo] = []
        self.solid_names = [s.name for s in world.solids]
        self._solid_body: dict[str, int] = {}
        self.solid_poses: dict[str, Pose] = {}
        for s in world.solids:
            pose = pose_from_model(s.pose)
            self._solid_body[s.name] = self.engine.add_body([_entry(s, base_dir)], pose, owner=-1, movable=False)
            self.shapes.append(_shape_info(s.name, -1, s))
            self.solid_poses[s.name] = pose
        self.robot_names = [r.name for r in world.robots]
        self.robot_poses: list[Pose] = []
        self._robot_body: dict[int, int] = {}
        for i, r in enumerate(world.robots):
            pose = pose_from_model(r.pose)
            self.robot_poses.append(pose)
            if r.body is not None:
                self._robot_body[i] = self.engine.add_body([_entry(r.body, base_dir)], pose, owner=i, movable=True)
                self.shapes.append(_shape_info(f"{r.name}/body", i, r.body))
        self.triangle_count = sum(
            geo.triangle_count(primitive_from_model(s.geometry, base_dir))
            for s in [*world.solids, *[r.body for r in world.robots if r.body is not None]]
            if not isinstance(s.geometry, wm.Plane)
        )
        # infra-red reads these per hit shape; -1 (no hit) indexes the trailing "no hit" entry
        self.red = np.array([s.red for s in self.shapes] + [1.0])
        self.roughness = np.array([s.roughness for s in self.shapes] + [0.0])

    def set_robot_pose(self, index: int, pose: Pose) -> None:
        self.robot_poses[index] = pose
        body = self._robot_body.get(index)
        if body is not None:
            self.engine.set_body_pose(body, pose)

    def set_solid_pose(self, name: str, pose: Pose) -> None:
        if name not in self._solid_body:
            raise KeyError(name)
        self.solid_poses[name] = pose
        self.engine.set_body_pose(self._solid_body[name], pose)
