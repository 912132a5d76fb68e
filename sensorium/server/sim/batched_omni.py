"""Omni-wheel robots (``omni_drive``: Webots' ``omni_wheels`` how-to, a Robotino) in the batched
simulation: their wheel motors per copy (batched_holonomic.HolonomicDrives) and
:class:`~sensorium.server.sim.motion.OmniDrive`'s body twist, element by element the same float64
operations, on every copy and every omni-wheel robot at once.

The twist is the single drive's: each wheel's rim speed r_i·ω_i times its column of the
pseudo-inverse (taken from the template drive, so the very numbers), summed in wheel order from 0.
Robots with fewer wheels than the world's widest have zero columns after their own (the sums keep
their bits: batched_holonomic's note). The move is batched_holonomic.twist_steps.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.sim.batched_holonomic import HolonomicDrives
from sensorium.server.sim.motion import OmniDrive, WheelMotor

__all__ = ["OmniDrives"]


class OmniDrives(HolonomicDrives):
    """The omni-wheel robots of a world, ``copies`` times (see the module docstring). ``drives``: each
    robot slot's template drive (None, or a drive of another kind, for the other robots)."""

    field = "omni_drive"

    def __init__(self, drives: list, copies: int):
        super().__init__(drives, copies, OmniDrive)
        mine = [drives[s] for s in self.slots.tolist()]
        M, W = len(mine), self.width
        self.radius = np.zeros((M, W))
        self.solve = np.zeros((M, 3, W))        # per robot: its drive's columns, then zero ones
        for k, d in enumerate(mine):
            n = len(d.wheels)
            self.radius[k, :n] = [r for _, r in d.wheels]
            self.solve[k, :, :n] = np.array(d.columns, dtype=np.float64).T

    def wheel_motors(self, drive) -> list[WheelMotor]:
        return [m for m, _ in drive.wheels]

    def twist(self, rows: np.ndarray, u: np.ndarray, copies: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        rim = u * self.radius[rows]
        a = self.solve[rows]
        # OmniDrive.twist: from 0, wheel by wheel, each column times its rim's speed
        vx, vy, w = 0.0 + a[:, 0, 0] * rim[:, 0], 0.0 + a[:, 1, 0] * rim[:, 0], 0.0 + a[:, 2, 0] * rim[:, 0]
        for j in range(1, self.width):
            vx = vx + a[:, 0, j] * rim[:, j]
            vy = vy + a[:, 1, j] * rim[:, j]
            w = w + a[:, 2, j] * rim[:, j]
        return vx, vy, w
