"""What an environment asks of the agent: the task description and example rewards/terminations.

A :class:`Task` names the agent robot, the devices it observes (and their sampling periods), how
often it acts, and three callables, each called as ``fn(sim, robot, obs)``:

* ``reward``     -> float, after every action;
* ``terminated`` -> bool, after every action (the episode ended for a reason inside the world);
* ``start``      -> None, once per reset with ``(sim, robot, rng)`` (e.g. a random start pose).

A callable that keeps state between steps (the previous distance to a goal, say) may have a
``reset(sim, robot)`` method: the environment calls it after every reset, before the first action.

Examples (all small, all deterministic given the world):

* :class:`ReachLight`   - progress toward a light plus a bonus on arrival; terminates on arrival;
* :class:`AvoidObstacles` - forward, straight and far from obstacles (Floreano & Mondada's fitness);
  terminates on contact (:func:`clearance` below ``contact_distance``);
* :func:`clearance`     - the free horizontal distance around a robot's centre, by ray casting.

The batched vector environment (:mod:`sensorium.gym.vector`) asks a reward or termination for its
*vectorised form*: an object with ``vectorized(sim, slot)`` (``ReachLight`` and ``AvoidObstacles``
have one) returns a :class:`VectorGoal` computing every copy's values in a few array operations,
bit for bit what the callables give one copy at a time. A callable without one is called once per
copy with views of that copy (slower, same values).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.batched_lights import copy_world_lights
from sensorium.server.sim.frames import (
    ENU_AXES,
    drive_forward,
    enu_axes,
    forward_turn,
    horizontal_directions,
    to_enu,
    upright_quaternion,
)
from sensorium.server.sim.ground import placing_ceiling

__all__ = ["Task", "ReachLight", "AvoidObstacles", "clearance", "never", "random_start", "VectorGoal"]

StepFn = Callable[[Any, Any, dict], Any]


def whole(value: Any) -> bool:
    """An integer (Python's or numpy's), not a bool: what counts, sizes, periods and seeds must be
    (a float would be cut to an integer silently)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def never(sim, robot, obs) -> bool:
    """A termination that never happens (episodes end by truncation only)."""
    return False


def zero(sim, robot, obs) -> float:
    return 0.0


@dataclass
class Task:
    """The agent's task in a world.

    ``robot``: the agent (default: the first robot with a differential drive or an ackermann drive).
    ``observations``: device name -> sampling period in ms, or a list of names (sampled every
    control period); default: every device of the robot, sampled every control period.
    ``control_period_ms``: simulated time per action, a multiple of the world's basic step
    (default: one basic step). ``max_steps``: actions per episode before truncation (None: never).
    """

    robot: str | None = None
    observations: Mapping[str, int] | Sequence[str] | None = None
    control_period_ms: int | None = None
    max_steps: int | None = 500
    reward: StepFn = zero
    terminated: StepFn = never
    start: Callable[[Any, Any, np.random.Generator], None] | None = None


# ------------------------------------------------------------------------------------------ helpers

def clearance(sim, robot, rays: int = 32, max_distance: float = 1.0) -> float:
    """Smallest distance (m) from the robot's centre to anything seen by bounding rays, over
    ``rays`` horizontal directions (on the world's ground plane: normal to y in a NUE world) at the
    centre's height, ignoring the robot's own body; at most ``max_distance``. Obstacles entirely
    below or above the centre are not seen."""
    pose = robot.pose
    dirs = horizontal_directions(enu_axes(sim.world), rays)
    origins = np.broadcast_to(pose.translation, dirs.shape)
    hits = sim.scene.engine.cast(origins, dirs, 0.0, max_distance, kind=RayKind.BOUNDING, exclude_owner=robot.index)
    d = hits.distance[np.isfinite(hits.distance)]
    return float(d.min()) if d.size else float(max_distance)


def body_radius(robot, base_dir=None, world=None) -> float:
    """Horizontal radius of the disc about the robot's origin that contains its body shapes at every
    heading, the kinematic contact's broad-phase disc (its footprint, the body's turned outline,
    lies inside; 0 without a body): in a NUE ``world`` about the world's up (y), its
    body turned as its world-file rotation stands it (contact.enu_body)."""
    from pathlib import Path

    from sensorium.server.sim.contact import enu_body, robot_footprint
    from sensorium.server.sim.scene import primitive_from_model, robot_parts
    from sensorium.server.world.poses import pose_from_model

    base = Path(base_dir) if base_dir is not None else Path.cwd()
    parts = [(primitive_from_model(shape.geometry, base), local) for _, local, shape in robot_parts(robot.model)]
    turn = to_enu(world) if world is not None else None
    if turn is not None:
        parts = enu_body(parts, pose_from_model(robot.model.pose), turn)
    foot = robot_footprint(parts)
    return float(foot.radius) if foot is not None else 0.0


class random_start:
    """``Task.start``: put the robot at a uniformly random (x, y, yaw) in the given ranges, at its
    world-file height (in a world with terrains: its world-file clearance above the ground there,
    so it rides the terrain from where it lands: its ground here is the highest under it not above
    its origin + 1 mm (a box top it stands on, not a table above it), there the highest ground at
    (x, y), a table's top included: keep the ranges off tables). Draws from the environment's seeded generator,
    so a seed fixes the start.

    The ranges are the world's ENU view (:mod:`sensorium.server.sim.frames`): ``x`` east, ``y`` north, ``yaw``
    counter-clockwise about up from east, the heading of the robot's drive's ``forward`` (its own x
    axis by default). In an ENU world the robot's rotation becomes a turn about z, ``yaw`` for an
    x-forward drive; in a NUE world (x north, y up, z east) ``x`` ranges over the world's z, ``y``
    over its x, the height is kept along y, and the robot stands upright (the one of its own y and
    z axes that was closer to up along the world's y) with its forward at ``yaw``."""

    def __init__(self, x: tuple[float, float], y: tuple[float, float], yaw: tuple[float, float] = (-math.pi, math.pi)):
        self.x, self.y, self.yaw = x, y, yaw

    def __call__(self, sim, robot, rng: np.random.Generator) -> None:
        axes = enu_axes(sim.world)
        e, n, u = axes
        now = robot.pose
        z = float(now.translation[u])
        x = rng.uniform(*self.x)
        y = rng.uniform(*self.y)
        # the yaw is the drive's forward's: its own x goes forward_turn short of it (0 for an x-forward drive)
        yaw = rng.uniform(*self.yaw)
        turn = forward_turn(axes, now.rotation, drive_forward(robot.model))
        if turn:
            yaw -= turn
        ground = getattr(sim, "ground", None)         # (in ENU axes in any world)
        if ground is not None:      # its ground here (box tops up to its origin + 1 mm), the highest there
            here = ground.at(float(now.translation[e]), float(now.translation[n]), placing_ceiling(z, 0.0))
            there = ground.at(x, y)
            if here is not None and there is not None:
                z = there[0] + (z - here[0])
        if axes == ENU_AXES:
            robot.set_pose([x, y, z], rotation=[0.0, 0.0, 1.0, yaw])
            return
        place = [0.0, 0.0, 0.0]
        place[e], place[n], place[u] = x, y, z
        robot.set_pose(place, quaternion=upright_quaternion(axes, now.rotation, yaw))


# ------------------------------------------------------------------------------------------ examples

class ReachLight:
    """Drive to a light: reward ``progress_weight`` x (metres gained toward the light) minus
    ``step_cost`` per action, plus ``bonus`` on arrival (horizontal distance < ``radius``), which
    also terminates the episode. Use it for both ``Task.reward`` and ``Task.terminated``."""

    def __init__(self, light: str | None = None, radius: float = 0.2, progress_weight: float = 10.0,
                 bonus: float = 10.0, step_cost: float = 0.01):
        self.light = light
        self.radius = radius
        self.progress_weight = progress_weight
        self.bonus = bonus
        self.step_cost = step_cost
        self._target: np.ndarray | None = None
        self._previous = math.inf

    def target(self, sim) -> np.ndarray:
        # also lights carried by solids and robots, placed
        return self.target_among(sim.scene.world_lights(), enu_axes(sim.world))

    def target_among(self, lights: list, axes: tuple[int, int, int] = ENU_AXES) -> np.ndarray:
        """The (east, north) of the light this goal drives to among light models placed in the
        world (``axes``: the world's east, north and up, :func:`~sensorium.server.sim.frames.enu_axes`)."""
        for lt in lights:
            if lt.type == "DirectionalLight":
                continue
            if self.light is None or lt.name == self.light:
                return np.array([lt.location[axes[0]], lt.location[axes[1]]], dtype=np.float64)
        raise ValueError(f"ReachLight: the world has no point or spot light named {self.light!r}"
                         if self.light else "ReachLight: the world has no point or spot light")

    def distance(self, sim, robot) -> float:
        """The robot's horizontal distance to the light (on the ground plane, east and north)."""
        if self._target is None:
            self._target = self.target(sim)
        e, n, _ = enu_axes(sim.world)
        t = robot.pose.translation
        return float(np.hypot(t[e] - self._target[0], t[n] - self._target[1]))

    def reset(self, sim, robot) -> None:
        self._target = self.target(sim)
        self._previous = self.distance(sim, robot)

    def reward(self, sim, robot, obs) -> float:
        d = self.distance(sim, robot)
        r = self.progress_weight * (self._previous - d) - self.step_cost
        self._previous = d
        if d < self.radius:
            r += self.bonus
        return float(r)

    __call__ = reward

    def terminated(self, sim, robot, obs) -> bool:
        return self.distance(sim, robot) < self.radius

    def vectorized(self, sim, slot: int) -> VectorGoal:
        return _ReachLightCopies(self, sim, slot)


class VectorGoal:
    """A reward/termination for every copy of a batched simulation (see the module docstring):
    ``reset(copies)`` after those copies' reset (as ``reset(sim, robot)``), then per action
    ``reward(copies)`` and ``terminated(copies)`` (both read the state after the action; reward
    first, as the single environment calls them), each an array over ``copies``."""

    def reset(self, copies: np.ndarray) -> None:
        """After a reset of these copies (and their warm-up), before their first action."""

    def reward(self, copies: np.ndarray) -> np.ndarray:
        return np.zeros(len(copies))

    def terminated(self, copies: np.ndarray) -> np.ndarray:
        return np.zeros(len(copies), dtype=bool)


class _ReachLightCopies(VectorGoal):
    def __init__(self, goal: ReachLight, sim, slot: int):
        self.goal, self.sim, self.slot = goal, sim, slot
        # in a world whose robots carry lights the light may be one of them: each copy's own place, taken
        # at its reset as the single env takes it (None: one target, the world's fixed light, for all)
        self.targets: np.ndarray | None = np.zeros((sim.copies, 2)) if any(r.lights for r in sim.world.robots) else None
        self.target = goal.target(sim) if self.targets is None else np.zeros(2)
        self.previous = np.full(sim.copies, math.inf)
        self.axes = enu_axes(sim.world)

    def distance(self, copies: np.ndarray) -> np.ndarray:
        p = self.sim.pos[copies, self.slot]
        e, n, _ = self.axes
        if self.targets is not None:
            t = self.targets[copies]
            return np.hypot(p[:, e] - t[:, 0], p[:, n] - t[:, 1])
        return np.hypot(p[:, e] - self.target[0], p[:, n] - self.target[1])

    def reset(self, copies: np.ndarray) -> None:
        if self.targets is not None:
            for c in copies.tolist():
                self.targets[c] = self.goal.target_among(copy_world_lights(self.sim, c), self.axes)
        self.previous[copies] = self.distance(copies)

    def reward(self, copies: np.ndarray) -> np.ndarray:
        g = self.goal
        d = self.distance(copies)
        r = g.progress_weight * (self.previous[copies] - d) - g.step_cost
        self.previous[copies] = d
        return np.where(d < g.radius, r + g.bonus, r)

    def terminated(self, copies: np.ndarray) -> np.ndarray:
        return self.distance(copies) < self.goal.radius


_NO_WHEEL_PAIR = ("AvoidObstacles' reward reads a left and a right wheel speed: robot {!r} has no differential_drive "
                  "(a car-like, mecanum or omni-wheel robot: write a reward for it; AvoidObstacles().terminated works)")


class AvoidObstacles:
    """Explore without touching anything: per action, ``v (1 - sqrt(|dv|)) (1 - p)`` with ``v`` the
    mean wheel speed and ``dv`` the wheel speed difference (each wheel over its own maximum) and ``p`` the
    proximity ``1 - clearance / near`` (0 when nothing is within ``near`` m of the body), minus
    ``contact_penalty`` on contact. Contact (terminates): clearance below the body radius plus
    ``contact_distance``."""

    def __init__(self, near: float = 0.15, contact_distance: float = 0.005, contact_penalty: float = 10.0):
        self.near = near
        self.contact_distance = contact_distance
        self.contact_penalty = contact_penalty
        self._radius_key: tuple | None = None
        self._radius = 0.0

    def reset(self, sim, robot) -> None:
        self._radius_key = None

    def _gap(self, sim, robot) -> float:
        key = (id(sim), robot.index)
        if self._radius_key != key:
            self._radius_key, self._radius = key, body_radius(robot, sim.loaded.base_dir, sim.world)
        r = self._radius
        return clearance(sim, robot, max_distance=r + max(self.near, self.contact_distance) + 1e-6) - r

    def reward(self, sim, robot, obs) -> float:
        drive = robot.drive
        if robot.model.differential_drive is None:
            raise ValueError(_NO_WHEEL_PAIR.format(robot.name))
        # each over its own maximum, as actions scale; a side mounted mirrored (reversed_motors) rolls forward
        # at its negated velocity
        wl = drive.left_sign * drive.left.velocity / drive.left.max_velocity
        wr = drive.right_sign * drive.right.velocity / drive.right.max_velocity
        v = 0.5 * (wl + wr)
        dv = abs(wl - wr) / 2.0
        gap = self._gap(sim, robot)
        p = min(max(1.0 - gap / self.near, 0.0), 1.0)
        r = v * (1.0 - math.sqrt(dv)) * (1.0 - p)
        if gap < self.contact_distance:
            r -= self.contact_penalty
        return float(r)

    __call__ = reward

    def terminated(self, sim, robot, obs) -> bool:
        return self._gap(sim, robot) < self.contact_distance

    def vectorized(self, sim, slot: int) -> VectorGoal:
        return _AvoidObstaclesCopies(self, sim, slot)


class _AvoidObstaclesCopies(VectorGoal):
    """AvoidObstacles for every copy: one clearance cast of every copy's rays per action (the gap
    is computed once and read by both reward and termination; the single environment casts it
    twice with the same answer)."""

    RAYS = 32

    def __init__(self, goal: AvoidObstacles, sim, slot: int):
        self.goal, self.sim, self.slot = goal, sim, slot
        self.radius = body_radius(SimpleNamespace(model=sim.world.robots[slot]), sim.loaded.base_dir, sim.world)
        self.dirs = horizontal_directions(enu_axes(sim.world), self.RAYS)   # clearance()'s directions
        # each wheel's own maximum, signed: a side mounted mirrored (reversed_motors) rolls forward at its negated
        # velocity, and velocity / -max is -(velocity / max) exactly, the single env's sign * velocity / max
        self.vmax = (float(sim.wheel_sign[slot, 0] * sim.max_wheel[slot, 0]),
                     float(sim.wheel_sign[slot, 1] * sim.max_wheel[slot, 1]))
        self.wheels = sim.world.robots[slot].differential_drive is not None    # (a car has no wheel pair)
        self._gap: tuple | None = None     # (step key, copies, gaps, terminations or None)
        self._passes = packets.avoid_outcome(sim.velocity)   # (None without the C helper)
        self._rays: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None   # (copies, each ray's copy, directions)

    def gaps(self, copies: np.ndarray) -> np.ndarray:
        return self._outcome(copies, False)[0]

    def _outcome(self, copies: np.ndarray, reward: bool) -> tuple:
        """(gaps, reward or None, terminated or None) of these copies now; the gaps (and the
        terminations) kept for the step. ``reward``: also the reward, from the same C call as the
        gaps when they are cast now."""
        key = int(self.sim.counters["copy_steps"])
        kept = self._gap
        if kept is not None and kept[0] == key and np.array_equal(kept[1], copies):
            return kept[2], None, kept[3]
        g, r = self.goal, self.radius
        far = r + max(g.near, g.contact_distance) + 1e-6
        n = len(copies)
        rows = self.sim.pos[copies, self.slot]
        origins = np.empty((n, self.RAYS, 3))
        origins[:] = rows[:, None, :]                                    # (np.repeat's rows)
        origins = origins.reshape(-1, 3)
        if self._rays is None or not np.array_equal(self._rays[0], copies):   # (the same copies step after step)
            self._rays = (copies.copy(), np.repeat(copies, self.RAYS), np.tile(self.dirs, (n, 1)))
        # each copy's rays from one origin, as clearance() casts them (coherent packets: each ray the
        # single world's answer); only the distances are read
        hits = self.sim.cast(self._rays[1], origins, self._rays[2], 0.0, far, kind=RayKind.BOUNDING,
                             exclude_slot=self.slot, distance_only=True, coherent=True,
                             run=self.RAYS, origin_rows=rows)
        d = hits.distance.reshape(n, self.RAYS)
        got = None
        if reward and self._passes is not None:   # gaps, reward and terminations in one C call
            got = self._passes(d, far, r, np.asarray(copies), self.slot, self.vmax, g.near, g.contact_distance,
                               g.contact_penalty)
        if got is None:
            gap = packets.clearance_gaps(d, far, r)   # (these steps in one C pass)
            if gap is None:
                clear = np.where(np.isfinite(d), d, np.inf).min(axis=1)
                clear = np.where(np.isfinite(clear), clear, far)
                gap = clear - r
            got = (gap, None, None)
        self._gap = (key, copies.copy(), got[0], got[2])
        return got

    def reward(self, copies: np.ndarray) -> np.ndarray:
        if not self.wheels:
            raise ValueError(_NO_WHEEL_PAIR.format(self.sim.robot_names[self.slot]))
        g = self.goal
        gap, reward, _ = self._outcome(copies, True)
        if reward is not None:
            return reward
        got = packets.avoid_reward(copies, self.slot, self.sim.velocity, self.vmax, gap, g.near, g.contact_distance,
                                   g.contact_penalty)     # (the steps below in one C pass)
        if got is not None:
            return got
        vel = self.sim.velocity[copies, self.slot]
        wl, wr = vel[:, 0] / self.vmax[0], vel[:, 1] / self.vmax[1]
        v = 0.5 * (wl + wr)
        dv = np.abs(wl - wr) / 2.0
        p = np.minimum(np.maximum(1.0 - gap / g.near, 0.0), 1.0)
        r = v * (1.0 - np.sqrt(dv)) * (1.0 - p)
        return np.where(gap < g.contact_distance, r - g.contact_penalty, r)

    def terminated(self, copies: np.ndarray) -> np.ndarray:
        gap, _, term = self._outcome(copies, False)
        return term.copy() if term is not None else gap < self.goal.contact_distance
