"""Solids falling under the world's gravity after a VacuumGripper lets them go, a Supervisor imports
them or moves them into the air, or a belt carries them past its edge (Webots' physics drops them;
settling at load and a PROTO rebuild stay instant: ground.py).

A solid let go (or imported) at simulated time ``t0`` (integer ms) from pose ``P0`` falls straight down the world's up
(ENU z; a NUE world's y), its x, y and rotation kept, no air drag and no spin: at each step's end ``t``
its origin is ``g·(t − t0)²/2`` below ``P0``'s (``g``: ``WorldInfo.gravity``; float64), until its lowest
point (``ground.falling_span`` at ``P0``) reaches the top it rests on, the lowest point of the pose
``ground.land_solid`` gives for ``P0`` (the support under its origin when let go, tipping included):
from that step on it is at exactly that pose, as it was put at once before. What is under it is judged
once, when it is let go. Its velocity while it falls is ``−g·(t − t0)`` along the up, no rotation
(:meth:`Falls.velocity`, a Supervisor's ``getVelocity``). A fall ends early, the solid staying where it
is, when something else puts it somewhere (a gripper holding it, a state loaded, a reset: its pose in
the scene is then not the one the fall put) or when it is removed or rebuilt; a Supervisor's move
starts it over, from rest, from the pose it puts (``Simulation.set_solid_pose`` calls :meth:`Falls.let_go`); a
Supervisor's ``resetPhysics`` zeroes its velocity: it falls again from rest from where it is, onto the support
and into the pose judged when it was let go (:meth:`Falls.stop`). While
it falls, it is support where it will rest (:meth:`Falls.resting`, read by ``Simulation.landing_ground``).
Only falling solids cost work per step: none, nothing.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.server.sim.ground import falling_span, land_solid
from sensorium.server.world.geometry import Pose

__all__ = ["Fall", "Falls"]


@dataclass
class Fall:
    """One falling solid: ``start`` its pose let go at ``start_ms``, ``drop`` (m, > 0) how far its
    origin goes down until it touches, ``landed`` its resting pose, ``placed`` the pose the fall last put."""

    model: Any
    start: Pose
    start_ms: int
    start_height: float       # its origin's ENU height at ``start``
    drop: float
    landed: Pose
    placed: Pose


class Falls:
    """The simulation's falling solids (none in most worlds: :meth:`advance` is then one test)."""

    def __init__(self, sim: Any, to_enu: np.ndarray | None, gravity: float) -> None:
        self._sim = sim
        self._to_enu = to_enu
        self.gravity = float(gravity)
        self._up = np.array([0.0, 0.0, 1.0]) if to_enu is None else np.array(to_enu[2], dtype=np.float64)
        self.falling: dict[str, Fall] = {}

    def __bool__(self) -> bool:
        return bool(self.falling)

    def let_go(self, name: str, model: Any, start_ms: int) -> Pose:
        """Solid ``name`` (``model``) let go (or imported) at ``start_ms`` where it is now: it falls from
        there (and is put at its pose for the simulation's time now), or, already on or below its
        support, is put on it at once; over no support, or with no gravity, it stays. Returns the pose
        it comes to rest at."""
        sim = self._sim
        pose = sim.scene.solid_poses[name]
        self.falling.pop(name, None)
        landed = land_solid(model, pose, sim.loaded.base_dir, sim.landing_ground(name), self._to_enu)
        if landed is pose:
            return pose
        base = sim.loaded.base_dir
        before, after = falling_span(model, base, self._to_enu, pose), falling_span(model, base, self._to_enu, landed)
        assert before is not None and after is not None      # land_solid moved it: it falls
        drop = before[0] - after[0]              # its lowest point now, less the top it comes to rest on
        if drop <= 0.0:                          # sunk into its support (or tipped up onto it): raised at once
            sim.place_solid(name, landed)
            return landed
        if self.gravity <= 0.0:                  # no gravity: it floats where it was let go, as in Webots
            return pose
        t = pose.translation if self._to_enu is None else self._to_enu @ pose.translation
        self.falling[name] = Fall(model, pose, int(start_ms), float(t[2]), drop, landed, pose)
        self._move(name, self.falling[name], sim.time_ms)
        return landed

    def stop(self, name: str, now_ms: int) -> None:
        """Webots' ``resetPhysics`` on solid ``name``: a falling one's velocity zeroed at ``now_ms``, so it
        falls again from rest from where it is now (its height then less ``g·(t − now)²/2``), onto the
        same support, coming to the same resting pose; one not falling is left as it is."""
        fall = self.falling.get(name)
        if fall is None:
            return
        if not self._still(name, fall):          # put elsewhere since: that fall is over
            del self.falling[name]
            return
        here = fall.placed                       # where the fall has it now (put there at the last step's end)
        t = here.translation if self._to_enu is None else self._to_enu @ here.translation
        height = float(t[2])
        drop = fall.drop - (fall.start_height - height)      # what is left of the way down (> 0: not landed)
        fall.start, fall.start_ms, fall.start_height, fall.drop = here, int(now_ms), height, drop

    def resting(self, name: str, pose: Pose) -> Pose:
        """Where solid ``name``, now at ``pose``, comes to rest: its fall's end if it falls, else ``pose``."""
        fall = self.falling.get(name)
        return pose if fall is None else fall.landed

    def advance(self, now_ms: int) -> None:
        """Every falling solid put where its fall has it at ``now_ms`` (a step's end)."""
        if not self.falling:
            return
        for name, fall in list(self.falling.items()):
            if not self._still(name, fall):
                del self.falling[name]
                continue
            self._move(name, fall, now_ms)

    def _still(self, name: str, fall: Fall) -> bool:
        """Whether the fall goes on: the solid is there, the same model, where the fall put it, held by no gripper."""
        sim = self._sim
        if sim.scene.solid_poses.get(name) is not fall.placed:
            return False
        if not any(s is fall.model for s in sim.world.solids):
            return False
        return not any(g.held == name for g in sim._grippers)

    def _move(self, name: str, fall: Fall, now_ms: int) -> None:
        t = (now_ms - fall.start_ms) * 0.001
        down = 0.5 * self.gravity * t * t
        if down >= fall.drop:
            pose = fall.landed
            del self.falling[name]
        else:
            pose = _lowered(fall.start, fall.start_height - down, self._to_enu)
            fall.placed = pose
        self._sim.place_solid(name, pose)

    def velocity(self, name: str, now_ms: int) -> list[float] | None:
        """A falling solid's velocity at ``now_ms`` (world axes, linear m/s then angular rad/s): −g·t
        along the up, no rotation; None when it is not falling."""
        fall = self.falling.get(name)
        if fall is None:
            return None
        v = -self.gravity * (now_ms - fall.start_ms) * 0.001 * self._up + 0.0     # (+ 0.0: no -0.0 at rest)
        return [float(v[0]), float(v[1]), float(v[2]), 0.0, 0.0, 0.0]

    def clear(self) -> None:
        self.falling.clear()


def _lowered(pose: Pose, height: float, to_enu: np.ndarray | None) -> Pose:
    """``pose`` with its origin's ENU height set (x, y and rotation kept)."""
    translation = np.array(pose.translation, dtype=np.float64)
    if to_enu is None:
        translation[2] = height
    else:
        up = int(np.argmax(np.abs(to_enu[2])))
        translation[up] = float(np.sign(to_enu[2][up])) * height
    return Pose(pose.rotation, translation)
