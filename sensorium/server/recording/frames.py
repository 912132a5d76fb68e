"""Frame names and transforms shared by the Foxglove scene and the ROS 2 export (no foxglove-sdk
needed): ``world``; ``<robot>`` placed by the robot's pose; ``<robot>/<device>`` fixed on its robot
by the device's ``pose``, or, for a device riding a joint (``on_joint``), moved with the joint from
the recorded ``/<robot>/joint_states`` (:class:`JointFrames`, robot_state_publisher's job), as is
``<robot>/<joint>/link``, the frame the shapes riding a joint are drawn in."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import matrix_quaternion, pose_from_model

__all__ = ["WORLD_FRAME", "INFINITE_PLANE_SIZE", "Mount", "mounts", "link_frame", "JointFrames", "quat_from_x", "Body", "bodies", "lights",
           "shape_rgba", "GHOST_ALPHA", "Appearances"]

WORLD_FRAME = "world"
INFINITE_PLANE_SIZE = 50.0      # metres: an infinite plane is drawn as a square of this side

NO_APPEARANCE = (0.85, 0.85, 0.85)  # a shape without appearance (Webots draws it white: grey shows on a light floor)
GHOST_ALPHA = 0.25               # bounding-only shapes (invisible in Webots) are drawn this translucent

Mount = tuple[str, tuple[float, float, float], tuple[float, float, float, float]]


class Appearances(Protocol):
    """Where the scene's drawers read what a Supervisor changed in shapes' appearances (the
    simulation's ``Scene``): ``appearance_version`` changes with every change and reset, so a
    drawer compares one number per step; ``drawn_models()`` gives the changed shapes' models now
    (``id()`` of the world's model -> the model to draw)."""

    appearance_version: int

    def drawn_models(self) -> dict[int, Any]: ...


def shape_rgba(shape: Any, ghost: bool = False) -> tuple[float, float, float, float]:
    """A shape's drawing colour: ``base_color`` with alpha 1 - transparency (light grey without an
    appearance); a bounding-only (``ghost``) shape at alpha ``GHOST_ALPHA``, so that even a fully
    transparent one (a glass pane sonars see) shows."""
    a = shape.appearance
    r, g, b = NO_APPEARANCE if a is None else (float(c) for c in a.base_color)
    alpha = 1.0 if a is None else float(1.0 - a.transparency)
    if ghost:
        alpha = GHOST_ALPHA
    return r, g, b, alpha


def mounts(world: wm.World) -> dict[str, list[Mount]]:
    """robot → [(frame, translation, quaternion xyzw)] of the robot's devices, then of the links
    its shapes or lights ride on (:func:`link_frame`, at the joints' initial positions)."""
    out: dict[str, list[Mount]] = {}
    for r in world.robots:
        items: list[Mount] = []
        for d in r.devices:
            p = pose_from_model(d.pose)
            t = (float(p.translation[0]), float(p.translation[1]), float(p.translation[2]))
            items.append((f"{r.name}/{d.name}", t, matrix_quaternion(p.rotation)))
        items.extend((link_frame(r.name, j), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)) for j in _link_joints(r))
        out[r.name] = items
    return out


def link_frame(robot: str, joint: str) -> str:
    """The frame of the shapes riding a joint: the robot frame moved by the joint (identity with
    every joint at its initial position, where the world file places the shapes)."""
    return f"{robot}/{joint}/link"


def _shape_joints(r: wm.Robot) -> list[str]:
    """The joints shapes of ``r`` ride on, in order of first appearance."""
    return list(dict.fromkeys(j for part in r.shapes if (j := getattr(part, "on_joint", None)) is not None))


def _link_joints(r: wm.Robot) -> list[str]:
    """The joints that have a link frame: those shapes or lights of ``r`` (not directional) ride on."""
    lit = (lt.on_joint for lt in r.lights if lt.on_joint is not None and lt.type != "DirectionalLight")
    return list(dict.fromkeys([*_shape_joints(r), *lit]))


def _mount(frame: str, p: Pose) -> Mount:
    t = (float(p.translation[0]), float(p.translation[1]), float(p.translation[2]))
    return frame, t, matrix_quaternion(p.rotation)


class JointFrames:
    """The frames of devices riding joints, and of the links shapes ride (:func:`link_frame`),
    placed from joint positions as the simulation places them (sim/joints.py ``Links``:
    ``displacement ∘ pose``). ``robots``: those with such frames."""

    def __init__(self, world: wm.World):
        from sensorium.server.sim.joints import JointMotor, Links

        self._robots: dict[str, tuple[Links, dict[str, JointMotor], list[tuple[str, str, Pose]]]] = {}
        for r in world.robots:
            riders = [(f"{r.name}/{d.name}", joint, pose_from_model(d.pose)) for d in r.devices
                      if (joint := getattr(d, "on_joint", None)) is not None]
            riders += [(link_frame(r.name, j), j, Pose.identity()) for j in _link_joints(r)]
            if not riders:
                continue
            joints = {d.name: JointMotor(d.name, d.device, d.max_velocity, initial_position=d.position)
                      for d in r.devices if isinstance(d, wm.Motor)}
            self._robots[r.name] = (Links(r, joints), joints, riders)
        self.robots = frozenset(self._robots)

    def frames(self, robot: str) -> frozenset[str]:
        """The robot's frames that ride joints."""
        return frozenset(f for f, _j, _p in self._robots[robot][2]) if robot in self._robots else frozenset()

    def update(self, robot: str, names: list[str], positions: list[float]) -> list[Mount]:
        """Joint positions (a JointState's ``name`` and ``position``; unknown names ignored): the
        robot's riding frames (robot frame) with the joints there."""
        links, joints, riders = self._robots[robot]
        for name, q in zip(names, positions):
            if name in joints:
                joints[name].position = float(q)
        links.update()
        return [_mount(frame, links.poses[joint].compose(pose)) for frame, joint, pose in riders]


def quat_from_x(d: np.ndarray) -> tuple[float, float, float, float]:
    """The rotation (x, y, z, w) taking +x onto the unit vector ``d`` (arrows point along +x)."""
    x = np.array([1.0, 0.0, 0.0])
    axis = np.cross(x, d)
    s, c = float(np.linalg.norm(axis)), float(np.dot(x, d))
    if s < 1e-12:
        return (0.0, 0.0, 0.0, 1.0) if c > 0 else (0.0, 0.0, 1.0, 0.0)
    axis /= s
    half = np.arctan2(s, c) / 2.0
    sh = float(np.sin(half))
    return (float(axis[0]) * sh, float(axis[1]) * sh, float(axis[2]) * sh, float(np.cos(half)))


@dataclass(frozen=True)
class Body:
    """One drawn object: a top-level solid (all its shapes and children, world poses), a robot's
    body (its shapes, poses in the robot frame; ``frame_locked`` so it moves with the robot) or the
    shapes riding one of its joints (poses in the link's frame, which is the robot frame moved by
    the joint)."""

    entity_id: str
    frame_id: str
    kind: str                                   # solid | robot | link
    frame_locked: bool
    parts: list[tuple[Any, Pose, bool]]         # (Shape-like model, pose in frame_id, ghost: bounding-only)


def bodies(world: wm.World, solid_poses: dict[str, Pose] | None = None) -> Iterator[Body]:
    """Every solid and robot body to draw, with every shape: ``ghost`` marks a bounding-only shape
    (Webots' invisible boundingObject, seen only by generic/sonar/laser rays), drawn translucent.
    ``solid_poses`` overrides where a solid is now; a solid it leaves out was removed (Supervisor)."""
    from sensorium.server.sim.scene import robot_parts, solid_parts

    for s in world.solids:
        if solid_poses is not None and s.name not in solid_poses:
            continue
        top = solid_poses[s.name] if solid_poses is not None else pose_from_model(s.pose)
        parts = [(shape, pose, shape.seen_by == "bounding") for _n, pose, shape in solid_parts(s, top)]
        if parts:
            yield Body(f"solid/{s.name}", WORLD_FRAME, "solid", False, parts)
    for r in world.robots:
        parts = [(shape, pose, shape.seen_by == "bounding") for _n, pose, shape in robot_parts(r)
                 if getattr(shape, "on_joint", None) is None]
        if parts:
            yield Body(f"robot/{r.name}", r.name, "robot", True, parts)
        for joint in _shape_joints(r):        # a link: drawn in its frame, which its joint moves
            parts = [(shape, pose, shape.seen_by == "bounding") for _n, pose, shape in robot_parts(r)
                     if getattr(shape, "on_joint", None) == joint]
            yield Body(f"robot/{r.name}/{joint}", link_frame(r.name, joint), "link", True, parts)


def lights(world: wm.World, solid_poses: dict[str, Pose] | None = None) -> Iterator[tuple[str, str, bool, Any]]:
    """Every light to draw: (entity id, frame, frame_locked, light model with location/direction in
    that frame). World and solid lights are in ``world``; a robot's lights ride in its frame (a
    DirectionalLight's direction stays in world axes wherever it is attached, as in Webots), one on a
    joint in its link's frame (:func:`link_frame`)."""
    from sensorium.server.sim.scene import place_light, solid_lights

    seen: set[str] = set()

    def unique(name: str) -> str:
        base, n = f"light/{name}", 1
        out = base
        while out in seen:
            n += 1
            out = f"{base}#{n}"
        seen.add(out)
        return out

    for i, lt in enumerate(world.lights):
        yield unique(lt.name or f"light{i}"), WORLD_FRAME, False, lt
    for s in world.solids:
        if solid_poses is not None and s.name not in solid_poses:     # removed, with its lights
            continue
        top = solid_poses[s.name] if solid_poses is not None else pose_from_model(s.pose)
        for j, (lt, local) in enumerate(solid_lights(s, Pose.identity())):
            yield unique(lt.name or f"{s.name}/light{j}"), WORLD_FRAME, False, place_light(lt, top.compose(local))
    for r in world.robots:
        for j, lt in enumerate(r.lights):
            frame = WORLD_FRAME if lt.type == "DirectionalLight" else \
                r.name if lt.on_joint is None else link_frame(r.name, lt.on_joint)   # on a joint: its link's frame
            yield unique(lt.name or f"{r.name}/light{j}"), frame, frame != WORLD_FRAME, lt
