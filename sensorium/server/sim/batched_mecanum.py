"""Mecanum robots (``mecanum_drive``, a KUKA youBot's base) in the batched simulation: their four
wheel motors per copy (batched_holonomic.HolonomicDrives) and
:class:`~sensorium.server.sim.motion.MecanumDrive`'s body twist, element by element the same float64
operations, on every copy and every mecanum robot at once.

The wheels are the drive's order (front left, front right, rear left, rear right: its ``rollers``').
The twist's sums run in the single drive's order from its own constants (roller signs, each wheel's
c = s·x − y and 4c², taken from the template drive); the move is batched_holonomic.twist_steps.
"""

from __future__ import annotations

import numpy as np

from sensorium.server.sim.batched_holonomic import HolonomicDrives
from sensorium.server.sim.motion import MecanumDrive, WheelMotor

__all__ = ["MecanumDrives", "WHEELS"]

WHEELS = 4
"""Motor columns per mecanum robot: front left, front right, rear left, rear right (``rollers``' order)."""


class MecanumDrives(HolonomicDrives):
    """The mecanum robots of a world, ``copies`` times (see the module docstring). ``drives``: each
    robot slot's template drive (None, or a drive of another kind, for the other robots)."""

    field = "mecanum_drive"

    def __init__(self, drives: list, copies: int):
        super().__init__(drives, copies, MecanumDrive)
        mine = [drives[s] for s in self.slots.tolist()]
        M = len(mine)
        # the single drive's own constants, so the sums below use its very numbers
        self.radius = np.array([d.wheel_radius for d in mine], dtype=np.float64)
        self.sign = np.array([[s for _, s, _ in d.wheels] for d in mine], dtype=np.float64).reshape(M, WHEELS)
        self.c = np.array([[c for _, _, c in d.wheels] for d in mine], dtype=np.float64).reshape(M, WHEELS)
        self.c2 = np.array([d.c2 for d in mine], dtype=np.float64)

    def wheel_motors(self, drive) -> list[WheelMotor]:
        return [m for m, _, _ in drive.wheels]

    def order(self, k: int) -> str:
        return "front left, front right, rear left, rear right"

    def twist(self, rows: np.ndarray, u: np.ndarray, copies: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r, s, c = self.radius[rows], self.sign[rows], self.c[rows]
        # MecanumDrive.twist: Python's sum (0 + a + b ...) in wheel order, then r * sum / 4 (or / 4c²)
        tot, ts, tc = 0.0 + u[:, 0], 0.0 + s[:, 0] * u[:, 0], 0.0 + c[:, 0] * u[:, 0]
        for j in range(1, WHEELS):
            tot = tot + u[:, j]
            ts = ts + s[:, j] * u[:, j]
            tc = tc + c[:, j] * u[:, j]
        return r * tot / 4.0, r * ts / 4.0, r * tc / self.c2[rows]
