"""Mecanum robots (``mecanum_drive``, a KUKA youBot's base) in the batched simulation: their four
wheel motors per copy and :class:`~sensorium.server.sim.motion.MecanumDrive`'s body twist and exact
twist step, element by element the same float64 operations, on every copy and every mecanum robot
at once.

Per copy and robot the four wheel motors (front left, front right, rear left, rear right: the
drive's order, its ``rollers``') keep a target, a velocity and an angle, as
:class:`~sensorium.server.sim.motion.WheelMotor`. A step advances them, works out each moving
robot's twist (vx, vy, ωz) -- the sums in the single drive's order, from its own constants (roller
signs, each wheel's c = s·x − y and 4c², taken from the template drive) -- and moves it by
:func:`~sensorium.server.sim.motion.twist_step` (:func:`twist_steps`); the batched simulation's
contact, ground and placing (``BatchedSimulation._drive_numpy``) then treat the move as any other
robot's. The sines and cosines are libm's (``math.sin`` / ``math.cos``: batched_kinematic's
``libm_cos_sin``, one C pass where the packets helper is built), the wrap numpy's remainder, as the
arcs of the other drives.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.server.sim.batched_kinematic import libm_cos_sin
from sensorium.server.sim.motion import MecanumDrive

__all__ = ["MecanumDrives", "WHEELS", "twist_steps"]

WHEELS = 4
"""Motor columns per mecanum robot: front left, front right, rear left, rear right (``rollers``' order)."""
_TWO_PI = 2.0 * math.pi


class MecanumDrives:
    """The mecanum robots of a world, ``copies`` times (see the module docstring). ``drives``: each
    robot slot's template drive (None, or a drive of another kind, for the other robots)."""

    def __init__(self, drives: list, copies: int):
        mine = [(i, d) for i, d in enumerate(drives) if isinstance(d, MecanumDrive)]
        self.slots = np.array([i for i, _ in mine], dtype=np.int64)
        self.slot_index = np.full(len(drives), -1, dtype=np.int64)     # per robot slot: its mecanum row, or -1
        self.slot_index[self.slots] = np.arange(len(mine))
        self.of = {int(s): k for k, s in enumerate(self.slots.tolist())}
        M = len(mine)
        self.columns: list[dict[str, int]] = [{m.name: j for j, (m, _, _) in enumerate(d.wheels)} for _, d in mine]
        # the single drive's own constants, so the sums below use its very numbers
        self.radius = np.array([d.wheel_radius for _, d in mine], dtype=np.float64)
        self.max_velocity = np.array([[m.max_velocity for m, _, _ in d.wheels] for _, d in mine],
                                     dtype=np.float64).reshape(M, WHEELS)
        self.sign = np.array([[s for _, s, _ in d.wheels] for _, d in mine], dtype=np.float64).reshape(M, WHEELS)
        self.c = np.array([[c for _, _, c in d.wheels] for _, d in mine], dtype=np.float64).reshape(M, WHEELS)
        self.c2 = np.array([d.c2 for _, d in mine], dtype=np.float64)
        self.target = np.zeros((copies, M, WHEELS))        # inf: velocity control
        self.velocity = np.zeros((copies, M, WHEELS))
        self.angle = np.zeros((copies, M, WHEELS))
        self._encoders: np.ndarray | None = None           # per position sensor: (robot, column) or (-1, -1)

    # ------------------------------------------------------------------ control
    def reset(self, idx: np.ndarray) -> None:
        """Every wheel motor of these copies as built: position control at 0 at its maxVelocity (Webots' default)."""
        self.target[idx] = 0.0
        self.velocity[idx] = self.max_velocity
        self.angle[idx] = 0.0

    def column(self, slot: int, name: str) -> tuple[int, int]:
        """(robot row, column) of a mecanum robot's wheel motor."""
        k = self.of[slot]
        return k, self.columns[k][name]

    def command(self, slot: int, speeds, copies=None) -> None:
        """Velocity control of a mecanum robot's four wheels (``setPosition(inf)``, ``setVelocity``) in
        the named copies (default: all): ``speeds`` (copies, 4) rad/s in the drive's wheel order (front
        left, front right, rear left, rear right), clamped to the maximum as Webots does."""
        k = self.of.get(int(slot))
        if k is None:
            raise ValueError(f"robot slot {slot} has no mecanum_drive")
        idx = slice(None) if copies is None else np.asarray(copies, dtype=np.int64)
        u = np.asarray(speeds, dtype=np.float64)
        if u.shape[-1:] != (WHEELS,):
            raise ValueError(f"mecanum wheel speeds must be (copies, 4) (front left, front right, rear left, rear "
                             f"right), got shape {u.shape}")
        if not np.isfinite(u).all():
            raise ValueError("mecanum wheel speeds must be finite")
        vmax = self.max_velocity[k]
        self.target[idx, k] = math.inf
        self.velocity[idx, k] = np.minimum(np.maximum(u, -vmax), vmax)

    # ------------------------------------------------------------------ stepping
    def step(self, live: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
        """Advance the live copies' wheels one step; the moving robots' (copies, slots, vx, vy, ωz):
        MecanumDrive.step up to its twist step (a robot moves when any wheel turned)."""
        every = len(live) == len(self.angle)        # every copy (live is then 0 ... C-1): no gathers
        tgt = self.target if every else self.target[live]
        vel = self.velocity if every else self.velocity[live]
        ang = self.angle if every else self.angle[live]
        remaining = tgt - ang                                   # WheelMotor.advance, element by element
        with np.errstate(invalid="ignore"):
            speed = np.minimum(np.abs(vel), np.abs(remaining) / dt) if dt > 0 else np.zeros_like(vel)
            held = np.where(remaining != 0.0, np.copysign(speed, remaining), 0.0)
        u = np.where(np.isinf(tgt), vel, held)                  # (live, M, 4)
        if every:
            ang += u * dt
        else:
            self.angle[live] = ang + u * dt
        ci, ri = (u != 0.0).any(axis=2).nonzero()
        u = u[ci, ri]                                           # (n, 4): the moving robots' wheel speeds
        r, s, c = self.radius[ri], self.sign[ri], self.c[ri]
        # MecanumDrive.twist: Python's sum (0 + a + b ...) in wheel order, then r * sum / 4 (or / 4c²)
        tot, ts, tc = 0.0 + u[:, 0], 0.0 + s[:, 0] * u[:, 0], 0.0 + c[:, 0] * u[:, 0]
        for j in range(1, WHEELS):
            tot = tot + u[:, j]
            ts = ts + s[:, j] * u[:, j]
            tc = tc + c[:, j] * u[:, j]
        return live[ci], self.slots[ri], r * tot / 4.0, r * ts / 4.0, r * tc / self.c2[ri]

    # ------------------------------------------------------------------ encoders
    def read_encoders(self, positions: list, copies: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
        """The due position sensors (``cols`` of ``positions``, the batched simulation's list) of a
        mecanum wheel read its angle, written into ``values`` (before noise and resolution)."""
        if self._encoders is None:
            enc = np.full((len(positions), 2), -1, dtype=np.int64)
            for i, d in enumerate(positions):
                k = self.of.get(int(d.robot_index))
                if k is not None and d.config.motor in self.columns[k]:
                    enc[i] = (k, self.columns[k][d.config.motor])
            self._encoders = enc
        row = self._encoders[cols]
        mine = (row[:, 0] >= 0).nonzero()[0]
        if len(mine):
            values[mine] = self.angle[copies[mine], row[mine, 0], row[mine, 1]]


def twist_steps(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, vx: np.ndarray, vy: np.ndarray, w: np.ndarray,
                dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """motion.twist_step for many robots, element by element the same float64 operations (a = dt,
    b = 0 where ω is 0; sin(ω·dt)/ω and 2 sin²(ω·dt/2)/ω elsewhere)."""
    k = len(w)
    turning = w != 0.0
    n_turning = int(np.count_nonzero(turning))
    # one libm pass for every sine and cosine: sin(0.5·ω·dt) and sin(ω·dt) of the turning robots,
    # cos and sin of every heading
    t = slice(None) if n_turning == k else turning.nonzero()[0]
    wt = w[t]
    cos, sin = libm_cos_sin(np.concatenate([0.5 * wt * dt, wt * dt, yaw]))
    c, s = cos[2 * n_turning:], sin[2 * n_turning:]
    if n_turning == k:
        a = sin[k:2 * k] / w
        b = 2.0 * sin[:k] * sin[:k] / w
    else:
        a = np.full(k, dt)
        b = np.zeros(k)
        if n_turning:
            half = sin[:n_turning]
            a[t] = sin[n_turning:2 * n_turning] / wt
            b[t] = 2.0 * half * half / wt
    dx, dy = a * vx - b * vy, b * vx + a * vy
    return (x + c * dx - s * dy, y + s * dx + c * dy,
            np.remainder(yaw + w * dt + math.pi, _TWO_PI) - math.pi)
