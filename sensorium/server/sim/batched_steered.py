"""Steered-wheel robots (``steered_drive``: a rover's steered corners, a PR2's casters) in the batched
simulation: their wheel motors per copy (batched_holonomic.HolonomicDrives) and
:class:`~sensorium.server.sim.motion.SteeredDrive`'s body twist, element by element the same float64
operations, on every copy and every steered robot at once.

A wheel's heading is its fixed ``heading`` plus ``steer_sign`` times its steering joint's position in
that copy (the joints move first: batched_joints.py). Its ground velocity is r·ω·(cos h, sin h)
(libm's cosine and sine, as ``math.cos``/``math.sin``), and the twist sums each wheel's two columns of
the template drive's pseudo-inverse times it, wheel by wheel from 0, as ``SteeredDrive.twist``.
Robots with fewer wheels than the world's widest have zero columns after their own (the sums keep
their bits: batched_holonomic's note). Free wheels (no motor: a tricycle's), whose twist is the
single drive's constrained fit, are refused by batched.py.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.sim.batched_holonomic import HolonomicDrives
from sensorium.server.sim.batched_joints import BatchedJoints
from sensorium.server.sim.batched_kinematic import libm_cos_sin
from sensorium.server.sim.motion import SteeredDrive, WheelMotor

__all__ = ["SteeredDrives"]


class SteeredDrives(HolonomicDrives):
    """The steered-wheel robots of a world, ``copies`` times (see the module docstring). ``drives``:
    each robot slot's template drive; ``joints``: the world's joint motors, whose steering joints
    give the headings."""

    field = "steered_drive"

    def __init__(self, drives: list, copies: int, joints: BatchedJoints):
        super().__init__(drives, copies, SteeredDrive)
        self.joints = joints
        mine = [drives[s] for s in self.slots.tolist()]
        M, W = len(mine), self.width
        self.radius = np.zeros((M, W))
        self.heading = np.zeros((M, W))
        self.sign = np.zeros((M, W))
        self.steer = np.full((M, W), -1, dtype=np.int64)    # the steering joint's column, -1: fixed
        self.solve_x = np.zeros((M, 3, W))     # per robot: each wheel's column for u_x, then zero ones
        self.solve_y = np.zeros((M, 3, W))     # ... for u_y
        for k, (slot, d) in enumerate(zip(self.slots.tolist(), mine)):
            for i, ((_, r, h, sign, steer), (a, b)) in enumerate(zip(d.wheels, d.columns)):
                self.radius[k, i], self.heading[k, i], self.sign[k, i] = r, h, sign
                if steer is not None:
                    self.steer[k, i] = joints.of(slot, steer)
                self.solve_x[k, :, i], self.solve_y[k, :, i] = a, b

    def wheel_motors(self, drive) -> list[WheelMotor]:
        return [m for m, *_ in drive.wheels]

    def twist(self, rows: np.ndarray, u: np.ndarray, copies: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        assert copies is not None
        steer = self.steer[rows]
        steered = steer >= 0
        h = self.heading[rows].copy()
        rr, cc = steered.nonzero()      # SteeredDrive.headings: h + sign * the joint's position
        h[rr, cc] = h[rr, cc] + self.sign[rows][rr, cc] * self.joints.position[copies[rr], steer[rr, cc]]
        cos, sin = libm_cos_sin(h)
        rim = u * self.radius[rows]
        ux, uy = rim * cos, rim * sin
        a, b = self.solve_x[rows], self.solve_y[rows]
        vx = vy = w = np.zeros(len(rows))
        for j in range(self.width):     # wheel by wheel from 0, as SteeredDrive.twist sums them
            vx = vx + a[:, 0, j] * ux[:, j] + b[:, 0, j] * uy[:, j]
            vy = vy + a[:, 1, j] * ux[:, j] + b[:, 1, j] * uy[:, j]
            w = w + a[:, 2, j] * ux[:, j] + b[:, 2, j] * uy[:, j]
        return vx, vy, w
