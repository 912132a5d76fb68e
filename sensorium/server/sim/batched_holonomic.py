"""What the batched simulation's holonomic drives share (mecanum robots: batched_mecanum.py; omni-wheel
robots: batched_omni.py): each robot's wheel motors per copy, their commands and encoders, and
:func:`~sensorium.server.sim.motion.twist_step` for many robots at once (:func:`twist_steps`).

Per copy and robot the wheel motors (in the drive's own order) keep a target, a velocity and an
angle, as :class:`~sensorium.server.sim.motion.WheelMotor`. A step advances them and hands the
moving robots' wheel speeds to the subclass's :meth:`HolonomicDrives.twist`, which sums the body
twist (vx, vy, ωz) in the single drive's order from its own constants; the batched simulation moves
those robots by :func:`twist_steps` (two-wheel robots whose wheels' centre is off their origin too),
then its contact, ground and placing (``BatchedSimulation._drive_numpy``) treat the moves as any
other robot's. The sines and cosines are libm's (``math.sin`` / ``math.cos``: batched_kinematic's
``libm_cos_sin``, one C pass where the packets helper is built), the wrap numpy's remainder, as the
arcs of the other drives.

Robots with fewer wheels than the widest one have their columns padded: a padded wheel never turns
(maximum velocity 0) and adds 0 · 0 to the sums, which leaves them the same bits. A steered drive's free
wheel (no motor) has its column too, never turned alike; :meth:`HolonomicDrives.command` takes the motors'
speeds only and puts each in its wheel's column.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.server.sim.batched_kinematic import libm_cos_sin
from sensorium.server.sim.motion import HolonomicDrive, WheelMotor

__all__ = ["HolonomicDrives", "twist_steps"]

_TWO_PI = 2.0 * math.pi


class HolonomicDrives:
    """The robots of a world whose template drive is a ``drive_type`` (a HolonomicDrive), ``copies``
    times. ``drives``: each robot slot's template drive (None, or a drive of another kind, for the
    other robots)."""

    field = ""
    """The world file's drive field (``mecanum_drive``, ``omni_drive``), for messages."""

    def __init__(self, drives: list, copies: int, drive_type: type[HolonomicDrive]):
        mine = [(i, d) for i, d in enumerate(drives) if isinstance(d, drive_type)]
        self.slots = np.array([i for i, _ in mine], dtype=np.int64)
        self.of = {int(s): k for k, s in enumerate(self.slots.tolist())}
        # each robot's wheels in its drive's order, a free wheel's (no motor: a steered drive's) None
        motors: list[list[WheelMotor | None]] = [self.wheel_motors(d) for _, d in mine]
        self.columns: list[dict[str, int]] = [{m.name: j for j, m in enumerate(ms) if m is not None} for ms in motors]
        self.count = np.array([len(c) for c in self.columns], dtype=np.int64)
        """Each robot's wheel motors (its free wheels have columns, never turned, and no motor)."""
        M, W = len(mine), max(len(ms) for ms in motors)
        self.width = W
        self.max_velocity = np.zeros((M, W))      # 0 for a free wheel and a padded one: they never turn
        for k, ms in enumerate(motors):
            self.max_velocity[k, :len(ms)] = [m.max_velocity if m is not None else 0.0 for m in ms]
        self.target = np.zeros((copies, M, W))        # inf: velocity control
        self.velocity = np.zeros((copies, M, W))
        self.angle = np.zeros((copies, M, W))
        self._encoders: np.ndarray | None = None           # per position sensor: (robot, column) or (-1, -1)

    def wheel_motors(self, drive) -> list[WheelMotor | None]:
        """A template drive's wheels' motors in its order (None: a free wheel)."""
        raise NotImplementedError

    def order(self, k: int) -> str:
        """Robot row k's wheels in the order :meth:`command` takes their speeds, for messages."""
        return ", ".join(self.columns[k])

    def twist(self, rows: np.ndarray, u: np.ndarray, copies: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The body twists (vx, vy, ωz) of robot ``rows`` turning their wheels at ``u`` (n, width)
        rad/s (``copies``: each row's copy, for a twist that depends on the copy's joints): the single
        drive's ``twist``, element by element the same float64 operations."""
        raise NotImplementedError

    # ------------------------------------------------------------------ control
    def reset(self, idx: np.ndarray) -> None:
        """Every wheel motor of these copies as built: position control at 0 at its maxVelocity (Webots' default)."""
        self.target[idx] = 0.0
        self.velocity[idx] = self.max_velocity
        self.angle[idx] = 0.0

    def column(self, slot: int, name: str) -> tuple[int, int]:
        """(robot row, column) of a robot's wheel motor."""
        k = self.of[slot]
        return k, self.columns[k][name]

    def command(self, slot: int, speeds, copies=None) -> None:
        """Velocity control of a robot's wheels (``setPosition(inf)``, ``setVelocity``) in the named
        copies (default: all): ``speeds`` (copies, wheels) rad/s in the drive's wheel order, clamped
        to the maximum as Webots does."""
        k = self.of.get(int(slot))
        if k is None:
            raise ValueError(f"robot slot {slot} has no {self.field}")
        n = int(self.count[k])
        idx = slice(None) if copies is None else np.asarray(copies, dtype=np.int64)
        u = np.asarray(speeds, dtype=np.float64)
        if u.shape[-1:] != (n,):
            raise ValueError(f"{self.field[:-6]} wheel speeds must be (copies, {n}) ({self.order(k)}), "
                             f"got shape {u.shape}")
        if not np.isfinite(u).all():
            raise ValueError(f"{self.field[:-6]} wheel speeds must be finite")
        cols = list(self.columns[k].values())
        if cols == list(range(n)):
            vmax = self.max_velocity[k, :n]
            self.target[idx, k, :n] = math.inf
            self.velocity[idx, k, :n] = np.minimum(np.maximum(u, -vmax), vmax)
            return
        for i, j in enumerate(cols):       # the motors among free wheels: speed i to wheel column j
            vmax = self.max_velocity[k, j]
            self.target[idx, k, j] = math.inf
            self.velocity[idx, k, j] = np.minimum(np.maximum(u[..., i], -vmax), vmax)

    # ------------------------------------------------------------------ stepping
    def step(self, live: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
        """Advance the live copies' wheels one step; the moving robots' (copies, slots, vx, vy, ωz):
        HolonomicDrive.roll up to its twist step (a robot moves when any wheel turned)."""
        every = len(live) == len(self.angle)        # every copy (live is then 0 ... C-1): no gathers
        tgt = self.target if every else self.target[live]
        vel = self.velocity if every else self.velocity[live]
        ang = self.angle if every else self.angle[live]
        remaining = tgt - ang                                   # WheelMotor.advance, element by element
        with np.errstate(invalid="ignore"):
            speed = np.minimum(np.abs(vel), np.abs(remaining) / dt) if dt > 0 else np.zeros_like(vel)
            held = np.where(remaining != 0.0, np.copysign(speed, remaining), 0.0)
        u = np.where(np.isinf(tgt), vel, held)                  # (live, M, W)
        if every:
            ang += u * dt
        else:
            self.angle[live] = ang + u * dt
        ci, ri = (u != 0.0).any(axis=2).nonzero()
        return (live[ci], self.slots[ri], *self.twist(ri, u[ci, ri], live[ci]))

    # ------------------------------------------------------------------ encoders
    def read_encoders(self, positions: list, copies: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
        """The due position sensors (``cols`` of ``positions``, the batched simulation's list) of one
        of these wheels read its angle, written into ``values`` (before noise and resolution)."""
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
