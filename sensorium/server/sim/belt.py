"""Conveyor belts (schemas ``ConveyorBelt``; Webots' ``ConveyorBelt``, one ``Track`` whose LinearMotor
moves the belt): each basic step, a top-level solid with physics lying on a moving belt's top face -- its
lowest point within contact.FLOOR of the face, its origin over the face -- moves along the belt by the
motor's travel that step, as Webots' physics carries it on the Track's moving contact surface. Once its
origin is past the face's edge it falls (sim/falling.py) onto what is under it. A carried solid whose
move would put it into another solid or a robot's part (above the belt's face) goes as far as their faces
meet, and the solids behind it on that belt as far as they meet it (a row stops together). A Track with
several Boxes has a face for each, all moving along its +x; a solid moves once a step. Only a belt whose
motor moved costs anything; a world without belts builds no ``Belts``."""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.contact import EPS, FLOOR
from sensorium.server.sim.ground import GroundWarning, falling_shapes, shapes_span
from sensorium.server.sim.scene import primitive_from_model, robot_parts, solid_parts
from sensorium.server.world.poses import Pose

if TYPE_CHECKING:
    from sensorium.server.sim.joints import JointMotor
    from sensorium.server.sim.simulation import RobotState, Simulation

# a face whose axes rise more than this (a sine: 0.06 degrees) carries nothing; within it (world files
# write rotations to a few digits) the face is taken level and carries along its axis's horizontal part
_LEVEL = 1e-3


class Belts:
    """The world's conveyor belts and what they carry (``carry`` once per basic step, after the joints
    moved their motors)."""

    def __init__(self, sim: Simulation, to_enu: np.ndarray | None):
        self._sim = sim
        self._to_enu = to_enu
        self._belts: list[tuple[RobotState, wm.ConveyorBelt, JointMotor]] = [
            (r, b, r.joints[b.motor]) for r in sim.robots.values() for b in r.model.belts]
        self._shapes: dict[str, tuple[wm.Solid, list | None]] = {}   # each solid's falling shapes (_falling)
        self._kept: dict[tuple[str, str], tuple[tuple, list]] = {}     # obstacles' spans while still (_spans)
        self._moved: dict[str, tuple[Pose, wm.Solid, tuple]] = {}       # carried solids' spans where moved (_span)
        for robot, belt, _ in self._belts:
            if self._face(robot, belt) is None:
                warnings.warn(f"{sim.loaded.source}: robot {robot.name!r}: the belt of {belt.motor!r} is not level "
                              "(its top face's normal is not the world's up): it carries nothing",
                              GroundWarning, stacklevel=3)

    def _enu(self, v: np.ndarray) -> np.ndarray:
        return v if self._to_enu is None else self._to_enu @ v

    def _face(self, robot: RobotState, belt: wm.ConveyorBelt) -> tuple[np.ndarray, ...] | None:
        """The belt's top face in ENU (its centre, unit along and across, both horizontal) and its unit
        horizontal direction of travel; None when it is not level."""
        pose = self._sim.scene.robot_poses[robot.index]
        r = np.asarray(pose.rotation, dtype=np.float64)
        along = self._enu(r @ np.asarray(belt.along, dtype=np.float64))
        across = self._enu(r @ np.asarray(belt.across, dtype=np.float64))
        way = along if belt.direction is None else self._enu(r @ np.asarray(belt.direction, dtype=np.float64))
        if max(abs(along[2]), abs(across[2]), abs(way[2])) > _LEVEL or np.cross(along, across)[2] <= 0.0:
            return None
        along, across, way = (np.array([v[0], v[1], 0.0]) / np.hypot(v[0], v[1]) for v in (along, across, way))
        centre = self._enu(np.asarray(pose.translation, dtype=np.float64) + r @ np.asarray(belt.top, dtype=np.float64))
        return centre, along, across, way

    def _falling(self, solid: wm.Solid) -> list | None:
        kept = self._shapes.get(solid.name)
        if kept is None or kept[0] is not solid:       # (a Supervisor may build a solid again under its name)
            kept = self._shapes[solid.name] = (solid, falling_shapes(solid, self._sim.loaded.base_dir))
        return kept[1]

    def carry(self, dt_s: float) -> None:
        sim = self._sim
        moved: set[str] = set()        # a solid over two faces of one Track moves once a step
        for robot, belt, motor in self._belts:
            travel = motor.rate * dt_s          # the belt's own travel this step (its motor's position moved so)
            if travel == 0.0:
                continue
            face = self._face(robot, belt)
            if face is None:
                continue
            centre, along, across, way = face
            held = {g.held for g in sim._grippers if g.held is not None}
            poses = sim.scene.solid_poses
            on: list[tuple[wm.Solid, Pose, tuple[float, float, np.ndarray]]] = []
            for solid in sim.world.solids:
                if solid.name not in poses or solid.name in held or not solid.physics or solid.name in moved:
                    continue
                pose = poses[solid.name]
                offset = self._enu(np.asarray(pose.translation, dtype=np.float64)) - centre
                if abs(offset @ along) > belt.length / 2.0 or abs(offset @ across) > belt.width / 2.0:
                    continue
                span = self._span(solid, pose)
                if span is None or abs(span[0] - centre[2]) > FLOOR:
                    continue
                on.append((solid, pose, span))
            if on:
                self._move(on, way * travel, face, belt)
                moved |= {s.name for s, _, _ in on}

    def _span(self, solid: wm.Solid, pose: Pose) -> tuple[float, float, np.ndarray] | None:
        """ground.shapes_span of a solid with physics at ``pose``: kept for the pose a belt moved it to
        (a level move shifts its xy box and keeps its heights)."""
        kept = self._moved.get(solid.name)
        if kept is not None and kept[0] is pose and kept[1] is solid:
            return kept[2]
        shapes = self._falling(solid)
        return None if shapes is None else shapes_span(shapes, pose, self._to_enu)

    def _move(self, on: list, step: np.ndarray, face: tuple[np.ndarray, ...], belt: wm.ConveyorBelt) -> None:
        """Move the solids ``on`` the face by ``step`` (ENU), each as far as it goes before its xy box meets
        a wall's (another solid's or a robot part's above the face) or one carried ahead of it where that
        one stops: the faces meet there."""
        sim = self._sim
        centre, along, across, _ = face
        xy = step[:2]
        carried = [s.name for s, _, _ in on]
        boxes = {s.name: box for s, _, (_, _, box) in on}
        spans = {s.name: (lo, hi) for s, _, (lo, hi, _) in on}
        walls = self._obstacles(set(carried), float(centre[2]))
        bottoms = np.array([w[0] for w in walls])
        tops = np.array([w[1] for w in walls])
        others = np.array([w[2] for w in walls]).reshape(-1, 4)
        every = np.array([boxes[name] for name in carried])
        lows = np.array([spans[name][0] for name in carried])
        highs = np.array([spans[name][1] for name in carried])
        tall = (tops[None, :] > lows[:, None] + FLOOR) & (bottoms[None, :] < highs[:, None])
        enter, meet = _meets(every, others, xy)
        # the part of the step each solid makes before its faces meet a wall's
        reach = dict(zip(carried, np.where(tall & (enter < 1.0), meet, 1.0).min(axis=1, initial=1.0).tolist()))
        if min(reach.values()) < 1.0:
            self._rows(carried, every, xy, reach)
        world_xy = np.array([xy[0], xy[1], 0.0])
        world_step = world_xy if self._to_enu is None else self._to_enu.T @ world_xy
        for solid, pose, _ in on:
            part = reach[solid.name]
            if part <= 0.0:
                continue
            moved = Pose(pose.rotation, np.asarray(pose.translation, dtype=np.float64) + world_step * part)
            offset = self._enu(np.asarray(moved.translation, dtype=np.float64)) - centre
            if abs(offset @ along) > belt.length / 2.0 or abs(offset @ across) > belt.width / 2.0:
                # past the face's edge: from there it falls onto what is under it over the next steps
                # (sim/falling.py), as a gripper's let-go solid does
                sim.place_solid(solid.name, moved)
                sim.falls.let_go(solid.name, solid, sim.time_ms)
                continue
            sim.place_solid(solid.name, moved)
            lo, hi = spans[solid.name]
            shifted = boxes[solid.name] + np.concatenate([xy, xy]) * part
            self._moved[solid.name] = (sim.scene.solid_poses[solid.name], solid, (lo, hi, shifted))

    @staticmethod
    def _rows(carried: list[str], every: np.ndarray, xy: np.ndarray, reach: dict[str, float]) -> None:
        """A row stops together: each solid stops where it meets the one ahead where that one stops (its
        reach plus their gap, measured from where they are as both move along the same step); settled as
        shortest paths are, in at most one round per solid."""
        enter, meet = _meets(every, every, xy)
        np.fill_diagonal(enter, np.inf)
        pairs = [(carried[i], carried[j], float(enter[i, j]), float(meet[i, j])) for i, j in zip(*np.nonzero(enter < 1.0))]
        for _ in carried:
            changed = False
            for i, j, enter_ij, meet_ij in pairs:
                if reach[i] - reach[j] > enter_ij and reach[j] + meet_ij < reach[i]:
                    reach[i], changed = reach[j] + meet_ij, True
            if not changed:
                break

    def _obstacles(self, carried: set[str], face: float) -> list[tuple[float, float, np.ndarray]]:
        """(lowest, highest ENU point, xy box) of every bounding shape above the belt's face that is not
        carried: the other top-level solids' and the robots' (their joints' links where they hold them).
        Each solid's and robot's spans are kept while its pose (and its links' poses) are the same objects."""
        sim = self._sim
        out = []
        for solid in sim.world.solids:
            pose = sim.scene.solid_poses.get(solid.name)
            if pose is not None and solid.name not in carried:
                out += self._spans(("solid", solid.name), (pose, solid), lambda s=solid: [
                    (local, shape) for _, local, shape in solid_parts(s, Pose.identity())], pose)
        for r in sim.robots.values():
            links = r.links
            pose = sim.scene.robot_poses[r.index]
            held = (pose, r.model) if links is None else (pose, r.model, *links.poses.values())
            out += self._spans(("robot", r.name), held, lambda r=r, links=links: [
                (local if links is None or (j := getattr(shape, "on_joint", None)) not in links.poses
                 else links.poses[j].compose(local), shape) for _, local, shape in robot_parts(r.model)], pose)
        return [span for span in out if span[1] > face + FLOOR]

    def _spans(self, key: tuple[str, str], held: tuple, parts, pose: Pose) -> list[tuple[float, float, np.ndarray]]:
        kept = self._kept.get(key)
        if kept is not None and len(kept[0]) == len(held) and all(a is b for a, b in zip(kept[0], held)):
            return kept[1]
        base = self._sim.loaded.base_dir
        spans = []
        for local, shape in parts():
            if shape.seen_by not in ("both", "bounding") or isinstance(shape.geometry, (wm.Plane, wm.ElevationGrid)):
                continue
            span = shapes_span([(local, primitive_from_model(shape.geometry, base), shape.geometry)], pose, self._to_enu)
            if span is not None and span[2] is not None:
                spans.append(span)
        self._kept[key] = (held, spans)
        return spans


def _meets(boxes: np.ndarray, others: np.ndarray, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each of xy boxes ``boxes`` (m x 4: x0, y0, x1, y1) moved by f * ``xy`` and each of ``others``
    (n x 4), m x n: the least f >= 0 at which they come to overlap by more than contact.EPS both ways
    (touching is not overlapping; inf when they never do, or overlap now), and the f at which their
    faces meet (0 when they touch now)."""
    lo, hi, olo, ohi = boxes[:, None, :2], boxes[:, None, 2:], others[None, :, :2], others[None, :, 2:]

    def axis(k: int, by: float) -> tuple[np.ndarray, np.ndarray]:
        """The f interval over which the two overlap by more than ``by`` along axis k."""
        low, high, other_low, other_high, d = lo[..., k], hi[..., k], olo[..., k], ohi[..., k], float(xy[k])
        if d > 0.0:
            return (other_low - high + by) / d, (other_high - low - by) / d
        if d < 0.0:
            return (other_high - low - by) / d, (other_low - high + by) / d
        still = np.minimum(high, other_high) - np.maximum(low, other_low) > by     # the step does not move along k
        return np.where(still, -np.inf, np.inf), np.where(still, np.inf, -np.inf)

    (x0, x1), (y0, y1) = axis(0, EPS), axis(1, EPS)
    enter, leave = np.maximum(x0, y0), np.minimum(x1, y1)
    return (np.where((enter >= 0.0) & (enter < leave), enter, np.inf),
            np.maximum(np.maximum(axis(0, 0.0)[0], axis(1, 0.0)[0]), 0.0))
