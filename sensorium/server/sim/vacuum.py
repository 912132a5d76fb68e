"""The simulation's VacuumGripper (Webots' WbVacuumGripper, without ODE).

What Webots does: the pump is on or off (``isOn``, ``turnOn``/``turnOff``); while it is on and holds
nothing, the first solid its bounding object collides with is attached by a fixed joint, and the
presence sensor reads whether a solid is attached (``mSolid != NULL``), refreshed at its sampling
period. Turning the pump off detaches it. A gripper without a bounding object collides with nothing.

Here there is no physics, so nothing is attached or lifted: the presence reads 1 exactly when the
pump is on and the gripper's own bounding shapes (the robot's shapes whose ``of_device`` names it)
touch the bounding shapes of another solid or robot at the end of the step -- overlap, or a gap of
at most :data:`GRIP_DISTANCE`. Each shape is taken as contact.py takes obstacles (a 2D convex
section ⊕ a disc, over a height range), so the distance between two shapes is the exact distance
between those two vertical prisms, in float64: √(d_xy² + d_z²) with d_xy the gap between the
sections (0 when they overlap) and d_z the gap between the height ranges. Exact for upright boxes
and cylinders; other shapes are bounded as kinematic contact bounds them. A horizontal plane is a
flat sheet (finite or not), a vertical one a wall line; terrains and tilted planes touch nothing.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.sim.contact import UPRIGHT, Obstacle, _closest_on_list, _hull, enu_pose, obstacle
from sensorium.server.sim.scene import primitive_from_model, robot_bounding_parts, solid_parts
from sensorium.server.sim.sensors import Device
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import pose_from_model

__all__ = ["GRIP_DISTANCE", "VacuumGripper", "prism_gap"]

GRIP_DISTANCE = 1e-3
"""m: a gripper whose bounding shapes come this near a solid's (or overlap it) touches it."""


def _shape_obstacle(prim: Any, pose: Pose) -> Obstacle | None:
    """A shape at its world (ENU) pose as a prism: contact.py's obstacle, a horizontal plane as a
    flat sheet (its corners, or unbounded in xy), None for what touches nothing (terrains, tilted planes)."""
    if isinstance(prim, geo.Plane):
        r, t = pose.rotation, pose.translation
        if abs(r[2, 2]) >= UPRIGHT:                      # horizontal: a sheet at its height
            z = float(t[2])
            if prim.size is None:
                return Obstacle("plane", -1, np.zeros((1, 2)), math.inf, (z, z))
            hx, hy = prim.size[0] / 2.0, prim.size[1] / 2.0
            corners = np.array([[x, y, 0.0] for x in (-hx, hx) for y in (-hy, hy)]) @ r.T + t
            return Obstacle("plane", -1, _hull(corners[:, :2]), 0.0, (z, z))
    return obstacle("shape", -1, prim, pose)


def prism_gap(a: Obstacle, b: Obstacle) -> float:
    """The distance between two shapes taken as prisms (0 when they overlap), float64."""
    if math.isinf(b.radius):                             # an unbounded horizontal sheet
        return max(0.0, b.z_range[0] - a.z_range[1], a.z_range[0] - b.z_range[1])
    if b.normal is not None:                             # a vertical wall line, two-sided, unbounded in z
        s = a.points @ b.normal + b.offset
        if float(s.min()) <= 0.0 <= float(s.max()):
            return 0.0
        return max(0.0, float(np.abs(s).min()) - a.radius)
    diff = (a.points[:, None, :] - b.points[None, :, :]).reshape(-1, 2)
    signed, _ = _closest_on_list(0.0, 0.0, _hull(diff).tolist())      # origin to A ⊖ B: < 0 inside
    d_xy = max(0.0, signed - a.radius - b.radius)
    d_z = max(0.0, b.z_range[0] - a.z_range[1], a.z_range[0] - b.z_range[1])
    return math.hypot(d_xy, d_z)


class VacuumGripper(Device):
    """One gripper: ``is_on`` (the pump), ``value`` (its presence: 1.0 holding, 0.0 not, read at its
    sampling period as other sensors) and ``touching`` (what the latest measurement touched)."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.is_on = bool(self.config.is_on)
        self.value = 0.0                    # libController's presence before a value: false
        self.touching: str | None = None
        self._sim: Any = None
        self._robot: Any = None
        self._own: list[tuple[Any, Pose, str | None]] = []          # (primitive, pose in robot frame, on_joint)
        # solid name -> (its model, [(primitive, pose in solid frame)]); the models by name, taken again when
        # the scene's solids change (a Supervisor's import, removal or rebuild under the same name)
        self._solids: dict[str, tuple[Any, list[tuple[Any, Pose]]]] = {}
        self._models: dict[str, Any] = {}
        self._models_version = -1
        self._robots: dict[int, list[tuple[Any, Pose]]] = {}

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._sim = robot.simulation
        base = self._sim.loaded.base_dir
        self._own = [(primitive_from_model(p.geometry, base), pose_from_model(p.pose), p.on_joint)
                     for p in robot.model.shapes
                     if p.of_device == self.name and p.seen_by in ("both", "bounding")]

    # -- controller API
    def set_on(self, on: bool) -> None:
        """``wb_vacuum_gripper_turn_on`` (True) / ``turn_off``: from now on (the next presence reads it)."""
        self.is_on = bool(on)

    def reset(self) -> None:
        """Webots' WbVacuumGripper::reset: the pump as the world file has it, nothing held (its
        controller learns the pump's state with its next presence value, as Webots' C_CONFIGURE)."""
        self.is_on = bool(self.config.is_on)

    # -- measuring
    def _solid_shapes(self, name: str) -> list[tuple[Any, Pose]]:
        scene = self._sim.scene
        if self._models_version != scene.solids_version:
            self._models = {s.name: s for s in self._sim.world.solids if s.name in scene.solid_poses}
            self._models_version = scene.solids_version
            self._solids = {k: v for k, v in self._solids.items() if self._models.get(k) is v[0]}
        model = self._models[name]
        cached = self._solids.get(name)
        if cached is None or cached[0] is not model:
            base = self._sim.loaded.base_dir
            cached = self._solids[name] = (model, [(primitive_from_model(shape.geometry, base), local)
                                                   for _, local, shape in solid_parts(model, Pose.identity())
                                                   if shape.seen_by in ("both", "bounding")])
        return cached[1]

    def _robot_shapes(self, index: int) -> list[tuple[Any, Pose]]:
        shapes = self._robots.get(index)
        if shapes is None:
            shapes = self._robots[index] = robot_bounding_parts(self._sim.world.robots[index], self._sim.loaded.base_dir)
        return shapes

    def touched(self) -> str | None:
        """The first solid (world order) or robot the gripper's bounding shapes touch now, None if none."""
        if not self._own:
            return None
        sim, to_enu = self._sim, self._robot.to_enu
        pose = self._robot.pose
        links = self._robot.links
        mine = []
        for prim, local, joint in self._own:
            frame = pose if joint is None or links is None else pose.compose(links.poses[joint])
            ob = _shape_obstacle(prim, enu_pose(frame.compose(local), to_enu))
            if ob is not None:
                mine.append(ob)
        if not mine:
            return None
        scene = sim.scene
        for name, solid_pose in scene.solid_poses.items():
            for prim, local in self._solid_shapes(name):
                ob = _shape_obstacle(prim, enu_pose(solid_pose.compose(local), to_enu))
                if ob is not None and any(prism_gap(m, ob) <= GRIP_DISTANCE for m in mine):
                    return name
        for other in sim.robots.values():
            if other.index == self.robot_index:
                continue
            for prim, local in self._robot_shapes(other.index):
                ob = _shape_obstacle(prim, enu_pose(other.pose.compose(local), to_enu))
                if ob is not None and any(prism_gap(m, ob) <= GRIP_DISTANCE for m in mine):
                    return other.name
        return None

    def measure(self, now_ms: int) -> None:
        self.touching = self.touched() if self.is_on else None
        self.value = 1.0 if self.touching is not None else 0.0
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"value": self.value}

    def step_reading(self) -> dict:
        return {"value": float(self.value), "is_on": self.is_on}

    def describe(self) -> dict:
        c = self.config
        return {"is_on": self.is_on, "tensile_strength": float(c.tensile_strength),
                "shear_strength": float(c.shear_strength), "contact_points": int(c.contact_points)}
