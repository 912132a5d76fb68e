"""The simulation's VacuumGripper (Webots' WbVacuumGripper, kinematically: no ODE, no forces).

What Webots does: the pump is on or off (``isOn``, ``turnOn``/``turnOff``); while it is on and holds
nothing, a solid its bounding object collides with (the deepest contact, with at least
``contactPoints`` points) is attached by a fixed joint after the physics step, and the presence sensor
reads whether a solid is attached (``mSolid != NULL``), refreshed at its sampling period. Turning the
pump off (or a reset) detaches it; a pull beyond ``tensileStrength``/``shearStrength`` breaks the joint.
A gripper without a bounding object collides with nothing.

Here, at the end of every basic step (:meth:`VacuumGripper.carry`, before the sensors measure): a
gripper holding a solid puts it at the pose it had relative to the gripper when attached (float64
poses composed: the gripper's frame, the robot's pose with its link's displacement, then the held
offset), through :meth:`Simulation.place_solid`, the path of a Supervisor's move; a gripper whose pump
is on and holds nothing attaches, of the top-level solids with ``physics`` that its own bounding shapes
(the robot's shapes whose ``of_device`` names it) touch -- overlap, or a gap of at most
:data:`GRIP_DISTANCE` -- the one it touches deepest (:func:`prism_depth`: Webots takes the deepest
contact), the first in world order on a tie. The presence reads 1 exactly while a solid is held. Each shape is taken as
contact.py takes obstacles (a 2D convex section ⊕ a disc, over a height range), so the distance
between two shapes is the exact distance between those two vertical prisms, in float64:
√(d_xy² + d_z²) with d_xy the gap between the sections (0 when they overlap) and d_z the gap between
the height ranges. Exact for upright boxes and cylinders; other shapes are bounded as kinematic contact
bounds them. Robots are never attached, and no force breaks the hold (no physics).

A held solid is part of its carrier, as Webots' fixed joint makes the two one body: kinematic contact
never stops the carrier at it nor do its bumpers touch it (``Contact.hold``/``let_go``), while it stops
the other robots where it is. A solid let go (``turnOff``) is an obstacle to its carrier again at
once and falls from where it is, from the simulated time it is let go (sim/falling.py: straight down
under the world's gravity, to the pose ground.land_solid gives -- tipped onto the face under it
(ground.resting_pose), its lowest point on the highest support under its origin, the settling ground
without it: ``Simulation.landing_ground`` -- which it takes at the step its lowest point reaches that
support), with no bounce or rolling. While held, a load the kinematic
carrier holds below the top of that support is raised onto it (:meth:`VacuumGripper._on_support`),
where Webots' contact would push back on the load and, through the joint, on the arm.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.sim.contact import UPRIGHT, Obstacle, _closest_on_list, _hull, enu_pose, obstacle
from sensorium.server.sim.ground import falling_shapes, lift_pose, shapes_span
from sensorium.server.sim.scene import primitive_from_model, solid_parts
from sensorium.server.sim.sensors import Device
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import pose_from_model

__all__ = ["GRIP_DISTANCE", "VacuumGripper", "caught_at_load", "may_touch", "prism_depth", "prism_gap"]

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


def prism_depth(a: Obstacle, b: Obstacle) -> float:
    """How deep two prisms (a gripper's shape ``a``, a solid's ``b``) overlap: the least distance one
    must move to part them, along z or in the plane (> 0), or minus the gap between them (<= 0).
    Webots attaches the solid of the deepest contact; float64."""
    gap = prism_gap(a, b)
    if gap > 0.0:
        return -gap
    dz = min(a.z_range[1] - b.z_range[0], b.z_range[1] - a.z_range[0])
    if math.isinf(b.radius):                             # an unbounded sheet: parted along z only
        return dz
    if b.normal is not None:                             # a wall line: a's section pushed off it
        s = a.points @ b.normal + b.offset
        return min(dz, min(float(s.max()), -float(s.min())) + a.radius)
    diff = (a.points[:, None, :] - b.points[None, :, :]).reshape(-1, 2)
    signed, _ = _closest_on_list(0.0, 0.0, _hull(diff).tolist())      # origin to A ⊖ B: < 0 inside
    return min(dz, a.radius + b.radius - signed)


_SCREEN = GRIP_DISTANCE * (1.0 + 1e-9) + 1e-12
"""m: a pair whose boxes are farther apart than this along one axis is no touch (margin over rounding)."""


def may_touch(a: Obstacle, b: Obstacle) -> bool:
    """False when the two prisms are surely farther apart than GRIP_DISTANCE: their heights, or their
    sections' bounding boxes grown by their radii, are apart by more (a lower bound of the prism
    distance), so :func:`prism_gap`'s hull is built only for pairs near each other."""
    if max(b.z_range[0] - a.z_range[1], a.z_range[0] - b.z_range[1]) > _SCREEN:
        return False
    if math.isinf(a.radius) or math.isinf(b.radius) or a.normal is not None or b.normal is not None:   # sheets, walls
        return True
    lo_a, hi_a = a.points.min(axis=0) - a.radius, a.points.max(axis=0) + a.radius
    lo_b, hi_b = b.points.min(axis=0) - b.radius, b.points.max(axis=0) + b.radius
    return bool(max(float((lo_b - hi_a).max()), float((lo_a - hi_b).max())) <= _SCREEN)


def caught_at_load(world: Any, base_dir: Any, to_enu: np.ndarray | None) -> set[str]:
    """The top-level solids with physics that a VacuumGripper on at load holds from its first step: each
    such gripper's choice (:meth:`VacuumGripper.touched`'s rule, deepest first, the world order on a tie)
    among the solids its bounding shapes touch as the world file places them (the robot at its world-file
    pose). Webots' gripper catches such a solid at the end of its first step, after a fall of about a
    millimetre; here it does not settle at load (ground.settle_world) and is held from the first step."""
    if not any(d.device == "VacuumGripper" and d.is_on for r in world.robots for d in r.devices):
        return set()
    solids = []
    for s in world.solids:
        if not s.physics:
            continue
        pose = pose_from_model(s.pose)
        solids.append((s.name, [ob for _, local, shape in solid_parts(s, Pose.identity())
                                if shape.seen_by in ("both", "bounding") and (ob := _shape_obstacle(
                                    primitive_from_model(shape.geometry, base_dir),
                                    enu_pose(pose.compose(local), to_enu))) is not None]))
    caught: set[str] = set()
    for r in world.robots:
        pose = pose_from_model(r.pose)
        for d in r.devices:
            if d.device != "VacuumGripper" or not d.is_on:
                continue
            mine = [ob for p in r.shapes if p.of_device == d.name and p.seen_by in ("both", "bounding")
                    and (ob := _shape_obstacle(primitive_from_model(p.geometry, base_dir),
                                               enu_pose(pose.compose(pose_from_model(p.pose)), to_enu))) is not None]
            chosen, deepest = None, -math.inf
            for name, obs in solids:
                for ob in obs:
                    for m in mine:
                        if may_touch(m, ob) and prism_gap(m, ob) <= GRIP_DISTANCE:
                            depth = prism_depth(m, ob)
                            if depth > deepest:
                                chosen, deepest = name, depth
            if chosen is not None:
                caught.add(chosen)
    return caught


class VacuumGripper(Device):
    """One gripper: ``is_on`` (the pump), ``held`` (the name of the solid it carries, or None) and
    ``value`` (its presence: 1.0 holding, 0.0 not, read at its sampling period as other sensors)."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        self.is_on = bool(self.config.is_on)
        self.value = 0.0                    # libController's presence before a value: false
        self.held: str | None = None
        self._dropping: tuple[str, Any, int] | None = None     # (name, model, time in ms) of a solid let go: it falls
        self._offset: Pose | None = None    # the held solid's pose in the gripper's frame
        self._held_model: Any = None        # its world-file model when attached (a rebuilt one is another)
        self._outline: tuple[str, Pose | None] | None = None     # (held, link pose) its outline was given at
        self._falling: tuple[Any] | None = None     # (ground.falling_shapes of the held solid,)
        self._ground: tuple[tuple, Any] | None = None     # (what it was built from, the held solid's support)
        self._sim: Any = None
        self._robot: Any = None
        self._own: list[tuple[Any, Pose, str | None]] = []          # (primitive, pose in robot frame, on_joint)
        # solid name -> (its model, [(primitive, pose in solid frame)]); the models by name, taken again when
        # the scene's solids change (a Supervisor's import, removal or rebuild under the same name)
        self._solids: dict[str, tuple[Any, list[tuple[Any, Pose]]]] = {}
        self._models: dict[str, Any] = {}
        self._models_version = -1
        self._mine: tuple[Pose, tuple, list[Obstacle]] | None = None    # its own prisms and the poses they are at
        self._placed: dict[str, tuple[Pose, list, list[Obstacle]]] = {}     # name -> (pose, shapes, prisms)

    def bind(self, robot: Any) -> None:
        self._robot = robot
        self._sim = robot.simulation
        base = self._sim.loaded.base_dir
        self._own = [(primitive_from_model(p.geometry, base), pose_from_model(p.pose), p.on_joint)
                     for p in robot.model.shapes
                     if p.of_device == self.name and p.seen_by in ("both", "bounding")]

    # -- controller API
    def set_on(self, on: bool) -> None:
        """``wb_vacuum_gripper_turn_on`` (True: it attaches at the end of the next step) / ``turn_off``
        (False: what it holds is let go at once, where it is, as WbVacuumGripper::turnOff detaches, and
        falls from the simulation's time now: :meth:`carry`)."""
        self.is_on = bool(on)
        if not self.is_on:
            if self.held is not None:
                self._dropping = (self.held, self._held_model, self._sim.time_ms)
            self.release()

    def release(self) -> None:
        """Nothing held from now on: the solid is an obstacle to the carrier again (contact.py)."""
        if self.held is not None and self._sim.contact is not None:
            self._sim.contact.let_go(self._robot.index, self.held)
        self.held, self._offset, self._held_model, self._outline = None, None, None, None
        self._falling, self._ground = None, None

    def reset(self) -> None:
        """Webots' WbVacuumGripper::reset: the pump as the world file has it, nothing held (its
        controller learns the pump's state with its next presence value, as Webots' C_CONFIGURE)."""
        self.is_on = bool(self.config.is_on)
        self.release()
        self._dropping = None

    # -- holding
    def frame(self) -> Pose:
        """The gripper's body frame in the world: the robot's pose, composed with its link's
        displacement when it rides a joint."""
        pose, links, joint = self._robot.pose, self._robot.links, self.on_joint
        return pose if joint is None or links is None else pose.compose(links.poses[joint])

    def carry(self) -> None:
        """Once per basic step, after everything moved: the held solid put where the gripper now
        holds it, or, pump on and nothing held, the top-level solid with physics it touches deepest
        attached where it is. A held solid a Supervisor removed or rebuilt (a PROTO field set) is let
        go first, as Webots' joint goes with the destroyed node."""
        sim = self._sim
        if self._dropping is not None:
            self._land(*self._dropping)
            self._dropping = None
        if self.held is not None and self._model(self.held) is not self._held_model:
            self.release()
        if self.held is not None:
            assert self._offset is not None
            self._hold_outline()
            current = sim.scene.solid_poses[self.held]
            pose = self._on_support(self.frame().compose(self._offset))
            if not (np.array_equal(pose.translation, current.translation)
                    and np.array_equal(pose.rotation, current.rotation)):
                known = self._models_version == sim.scene.solids_version
                sim.place_solid(self.held, pose)
                if known:       # a move changes no model: the models by name stay current (none taken again)
                    self._models_version = sim.scene.solids_version
        elif self.is_on:
            name = self.touched()
            if name is not None:
                self.held, self._held_model = name, self._model(name)
                self._offset = self.frame().inverse().compose(sim.scene.solid_poses[name])
                self._hold_outline()

    def _on_support(self, pose: Pose) -> Pose:
        """The held solid at ``pose``, raised onto the support it is held into (ground.lift_pose: the one
        it would land on, the carrier left out): the kinematic carrier is not stopped by the floor, so
        its load is put on it instead of into it. Its heights are ground.falling_span's, the ones it lands
        by; a solid that does not fall (a Plane or ElevationGrid among its bounding shapes) is put where
        it is held."""
        if self._falling is None:             # the held solid's shapes, once per hold
            self._falling = (falling_shapes(self._held_model, self._sim.loaded.base_dir),)
        shapes = self._falling[0]
        span = None if shapes is None else shapes_span(shapes, pose, self._robot.to_enu, footprint=False)
        return pose if span is None else lift_pose(pose, span[0], span[1], self._support(), self._robot.to_enu)

    def _support(self) -> Any:
        """Simulation.landing_ground for the held solid without its carrier, built again only when
        something in it moved (poses and joint displacements are immutable objects: compared by identity)."""
        sim, scene = self._sim, self._sim.scene
        poses = [p for n, p in scene.solid_poses.items() if n != self.held]
        for r in sim.robots.values():
            if not r.model.drive_motors and r.index != self._robot.index:
                poses.append(scene.robot_poses[r.index])
                poses.extend(() if r.links is None else r.links.poses.values())
        key = (*sim.world.solids, *poses)        # the models (a rebuilt solid is a new one) and where they are
        kept = self._ground
        if kept is None or len(kept[0]) != len(key) or not all(a is b for a, b in zip(kept[0], key)):
            kept = self._ground = (key, sim.landing_ground(self.held, self._robot.index))
        return kept[1]

    def _hold_outline(self) -> None:
        """The held solid's bounding shapes, where the gripper holds them in its robot's frame, part of
        the robot's outline for kinematic contact (:meth:`Contact.hold`): given when it is attached and
        again when the gripper's joint moved it (the link's displacement, an immutable pose, changed)."""
        contact = self._sim.contact
        if contact is None or self.held is None:
            return
        links, joint = self._robot.links, self.on_joint
        link = None if joint is None or links is None else links.poses[joint]
        if self._outline is not None and self._outline[0] == self.held and self._outline[1] is link:
            return
        assert self._offset is not None
        in_robot = self._offset if link is None else link.compose(self._offset)
        parts = [(prim, in_robot.compose(local)) for prim, local in self._solid_shapes(self.held) or []]
        contact.hold(self._robot.index, self.held, parts)
        self._outline = (self.held, link)

    def _land(self, name: str, model: Any, start_ms: int) -> None:
        """The solid let go at ``start_ms`` starts falling onto what is under it (sim/falling.py:
        ``Falls.let_go``, put where its fall has it at this step's end), unless it is gone, rebuilt, or
        held again (by another gripper)."""
        sim = self._sim
        if self._model(name) is not model or any(
                isinstance(d, VacuumGripper) and d.held == name for d in sim.all_devices()):
            return
        sim.falls.let_go(name, model, start_ms)

    # -- touching
    def _model(self, name: str) -> Any:
        """The world-file model of the top-level solid now named so, None when there is none."""
        scene = self._sim.scene
        if self._models_version != scene.solids_version:
            self._models = {s.name: s for s in self._sim.world.solids if s.name in scene.solid_poses}
            self._models_version = scene.solids_version
            self._solids = {k: v for k, v in self._solids.items() if self._models.get(k) is v[0]}
            self._placed = {k: v for k, v in self._placed.items() if k in self._solids}
        return self._models.get(name)

    def _solid_shapes(self, name: str) -> list[tuple[Any, Pose]] | None:
        """A top-level solid's bounding shapes in its frame, None when it has no physics (never attached)."""
        model = self._model(name)
        if not model.physics:
            return None
        cached = self._solids.get(name)
        if cached is None or cached[0] is not model:
            base = self._sim.loaded.base_dir
            cached = self._solids[name] = (model, [(primitive_from_model(shape.geometry, base), local)
                                                   for _, local, shape in solid_parts(model, Pose.identity())
                                                   if shape.seen_by in ("both", "bounding")])
        return cached[1]

    def touched(self) -> str | None:
        """The top-level solid with physics the gripper's bounding shapes touch deepest now (the first
        in world order on a tie), None if none."""
        if not self._own:
            return None
        to_enu = self._robot.to_enu
        pose = self._robot.pose
        links = self._robot.links
        frames = tuple(None if joint is None or links is None else links.poses[joint] for _, _, joint in self._own)
        if self._mine is not None and self._mine[0] is pose and all(a is b for a, b in zip(self._mine[1], frames)):
            mine = self._mine[2]          # nothing it rides moved (poses are immutable objects)
        else:
            mine = []
            for (prim, local, _), link in zip(self._own, frames):
                frame = pose if link is None else pose.compose(link)
                ob = _shape_obstacle(prim, enu_pose(frame.compose(local), to_enu))
                if ob is not None:
                    mine.append(ob)
            self._mine = (pose, frames, mine)
        if not mine:
            return None
        chosen, deepest = None, -math.inf
        for name, solid_pose in self._sim.scene.solid_poses.items():
            for ob in self._solid_obstacles(name, solid_pose):
                for m in mine:
                    if may_touch(m, ob) and prism_gap(m, ob) <= GRIP_DISTANCE:
                        depth = prism_depth(m, ob)
                        if depth > deepest:          # the first in world order on a tie
                            chosen, deepest = name, depth
        return chosen

    def _solid_obstacles(self, name: str, pose: Pose) -> list[Obstacle]:
        """A solid's bounding shapes as prisms at ``pose``, kept while its (immutable) pose and shapes
        are the same objects: a pump on and holding nothing looks every step, and solids rarely move."""
        shapes = self._solid_shapes(name)
        if shapes is None:
            return []
        kept = self._placed.get(name)
        if kept is None or kept[0] is not pose or kept[1] is not shapes:
            to_enu = self._robot.to_enu
            obs = [ob for prim, local in shapes
                   if (ob := _shape_obstacle(prim, enu_pose(pose.compose(local), to_enu))) is not None]
            kept = self._placed[name] = (pose, shapes, obs)
        return kept[2]

    # -- measuring
    def measure(self, now_ms: int) -> None:
        self.value = 1.0 if self.held is not None else 0.0
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"value": self.value}

    def step_reading(self) -> dict:
        return {"value": float(self.value), "is_on": self.is_on}

    def describe(self) -> dict:
        c = self.config
        return {"is_on": self.is_on, "tensile_strength": float(c.tensile_strength),
                "shear_strength": float(c.shear_strength), "contact_points": int(c.contact_points)}
