"""Steered-wheel robots (``steered_drive``: a rover's steered corners, a PR2's casters) in the batched
simulation: their wheel motors per copy (batched_holonomic.HolonomicDrives) and
:class:`~sensorium.server.sim.motion.SteeredDrive`'s body twist, element by element the same float64
operations, on every copy and every steered robot at once.

A wheel's heading is its fixed ``heading`` plus ``steer_sign`` times its steering joint's position in
that copy (the joints move first: batched_joints.py). Its ground velocity is r·ω·(cos h, sin h)
(libm's cosine and sine, as ``math.cos``/``math.sin``), and the twist sums each wheel's two columns of
the template drive's pseudo-inverse times it, wheel by wheel from 0, as ``SteeredDrive.twist``.
Robots with fewer wheels than the world's widest have zero columns after their own (the sums keep
their bits: batched_holonomic's note).

A robot with free wheels (no motor: a tricycle's steered front wheel, Tinkerbots' vision_car's passive
wheels) takes ``SteeredDrive.constrained_twist`` instead, robot by robot over its moving copies: the
no-sideways-slip rows of its wheels, the cross product of the two farthest from parallel (the first of
the largest, as the single drive's strict ``>`` keeps it), the driven rims' speeds along it, each sum
added left to right from 0.0 (``motion.plain_sum``); a copy whose rows leave no one line takes the
single drive's least-squares fallback, copy by copy. Its free wheels have columns that never turn
(no motor, maximum velocity 0); their rolled angles (``free_turned``, per copy, as
``SteeredDrive.free_turned``) grow by the twist's velocity of each one's ground point along its
heading, and a PositionSensor with ``free_wheel`` reads them (:meth:`SteeredDrives.read_encoders`).
"""

from __future__ import annotations

import numpy as np

from sensorium.server.raycast import packets
from sensorium.server.sim.batched_holonomic import HolonomicDrives
from sensorium.server.sim.batched_joints import BatchedJoints
from sensorium.server.sim.batched_kinematic import libm_cos_sin
from sensorium.server.sim.motion import SteeredDrive, WheelMotor
from sensorium.server.world.arrays import unique_ints

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
        # per robot with free wheels: its wheels' places and which have a motor (SteeredDrive.constrained_twist)
        self.constrained: dict[int, tuple[list[tuple[float, float]], list[bool]]] = {}
        for k, (slot, d) in enumerate(zip(self.slots.tolist(), mine)):
            for i, ((_, r, h, sign, steer), (a, b)) in enumerate(zip(d.wheels, d.columns)):
                self.radius[k, i], self.heading[k, i], self.sign[k, i] = r, h, sign
                if steer is not None:
                    self.steer[k, i] = joints.of(slot, steer)
                self.solve_x[k, :, i], self.solve_y[k, :, i] = a, b
            if d.has_free:
                self.constrained[k] = (list(d.places), [m is not None for m, *_ in d.wheels])
        self.has_free = np.array([k in self.constrained for k in range(M)], dtype=bool)
        # ... and as the C pass takes them: places (W, 2), driven (W,) uint8
        self.constrained_arrays = {k: (np.array(places, dtype=np.float64), np.array(driven, dtype=np.uint8))
                                   for k, (places, driven) in self.constrained.items()}
        self.free_turned = np.zeros((copies, M, W))
        """Each free wheel's rolled angle (rad, along its heading positive) per copy, at its wheel's column."""
        self._dt = 0.0                      # the step's (s), for the free wheels' roll
        self._free_encoders: np.ndarray | None = None     # per position sensor: (robot, wheel) or (-1, -1)

    def wheel_motors(self, drive) -> list[WheelMotor | None]:
        return [m for m, *_ in drive.wheels]

    def reset(self, idx: np.ndarray) -> None:
        super().reset(idx)
        self.free_turned[idx] = 0.0

    def step(self, live: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
        self._dt = dt
        return super().step(live, dt)

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
        free = self.has_free[rows]
        if free.any():                  # robots with free wheels: their constrained twist, then their roll
            for k in unique_ints(rows[free]).tolist():
                sel = (rows == k).nonzero()[0]
                places, driven = self.constrained[k]
                tx, ty, tw = constrained_twists(places, driven, self.radius[k, :len(places)], u[sel],
                                                cos[sel], sin[sel], self.constrained_arrays[k])
                vx[sel], vy[sel], w[sel] = tx, ty, tw
                self._roll_free(copies[sel], k, places, driven, tx, ty, tw, cos[sel], sin[sel])
        return vx, vy, w

    def _roll_free(self, copies: np.ndarray, k: int, places: list[tuple[float, float]], driven: list[bool],
                   vx: np.ndarray, vy: np.ndarray, w: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> None:
        """SteeredDrive.roll_free of robot k's moving copies: each free wheel's ground point's velocity
        along its heading, times dt over its radius, the same operations."""
        for i, ((px, py), has_motor) in enumerate(zip(places, driven)):
            if has_motor:
                continue
            along = (vx - w * py) * cos[:, i] + (vy + w * px) * sin[:, i]
            self.free_turned[copies, k, i] = self.free_turned[copies, k, i] + along * self._dt / self.radius[k, i]

    def read_encoders(self, positions: list, copies: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
        """The wheel motors' encoders (HolonomicDrives.read_encoders), then a free wheel's (``free_wheel``:
        its world-file angle plus its sign times the rolled angle, as the single PositionSensor)."""
        super().read_encoders(positions, copies, cols, values)
        if self._free_encoders is None:
            enc = np.full((len(positions), 2), -1, dtype=np.int64)
            for i, d in enumerate(positions):
                k = self.of.get(int(d.robot_index))
                wheel = getattr(d.config, "free_wheel", None)
                if k is not None and isinstance(wheel, int):
                    enc[i] = (k, wheel)
            self._free_encoders = enc
        free = self._free_encoders[cols]
        for i in (free[:, 0] >= 0).nonzero()[0].tolist():
            cfg = positions[int(cols[i])].config
            values[i] = float(cfg.position) + cfg.free_wheel_sign * float(self.free_turned[copies[i], free[i, 0],
                                                                                            free[i, 1]])


def constrained_twists(places: list[tuple[float, float]], driven: list[bool], radius: np.ndarray, u: np.ndarray,
                       cos: np.ndarray, sin: np.ndarray, arrays: tuple[np.ndarray, np.ndarray] | None = None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SteeredDrive.constrained_twist of one robot in n copies: its wheels' ``places``, which are
    ``driven`` (have a motor), their radii, the copies' wheel speeds ``u`` (n, ≥ wheels) and headings'
    ``cos``, ``sin`` (n, ≥ wheels); the twists (vx, vy, ωz), element by element the same float64
    operations (each sum from 0.0, left to right), the least-squares fallback copy by copy. One C pass
    (packets.constrained_twists) where the helper is built, given ``arrays`` (places and driven as it
    takes them); these numpy operations otherwise, the same bits."""
    got = packets.constrained_twists(arrays[0], arrays[1], radius, u, cos, sin) if arrays is not None else None
    if got is not None:
        twist, fallback = got
        vx, vy, w = twist[:, 0].copy(), twist[:, 1].copy(), twist[:, 2].copy()
        if not fallback.any():
            return vx, vy, w
        return _least_squares(*_rows(places, driven, radius, u, cos, sin), ~fallback, vx, vy, w)
    n = len(u)
    rows, along, rims = _rows(places, driven, radius, u, cos, sin)
    best = np.zeros(n)
    d = [np.zeros(n), np.zeros(n), np.zeros(n)]
    for i, a in enumerate(rows):        # the first of the largest cross products, as the strict > keeps it
        for b in rows[i + 1:]:
            cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
            size = np.sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2])
            larger = size > best
            best = np.where(larger, size, best)
            d = [np.where(larger, x, y) for x, y in zip(cross, d)]
    scale = np.zeros(n)
    for row in rows:
        for v in row:
            scale = scale + np.abs(v)
    line = best > 1e-12 * scale * scale
    for row in rows:
        line &= np.abs(row[0] * d[0] + row[1] * d[1] + row[2] * d[2]) <= 1e-9 * best * scale
    speeds_of_d = [a[0] * d[0] + a[1] * d[1] + a[2] * d[2] for a in along]
    total, size, rim, cross_sum, square = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    for a, r in zip(speeds_of_d, rims):
        total, size, rim = total + a, size + np.abs(a), rim + r
        cross_sum, square = cross_sum + a * r, square + a * a
    line &= size > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(np.abs(total) > 1e-9 * size, rim / total, cross_sum / square)
    return _least_squares(rows, along, rims, line, k * d[0], k * d[1], k * d[2])


def _rows(places: list[tuple[float, float]], driven: list[bool], radius: np.ndarray, u: np.ndarray, cos: np.ndarray,
          sin: np.ndarray) -> tuple[list, list, list]:
    """constrained_twist's rows: each wheel's no-slip-across row (−sin h, cos h, x cos h + y sin h), each
    driven wheel's ground speed along its heading (cos h, sin h, −y cos h + x sin h) and rim speed r·ω."""
    rows, along, rims = [], [], []
    for i, ((px, py), has_motor) in enumerate(zip(places, driven)):
        c, s = cos[:, i], sin[:, i]
        rows.append((-s, c, px * c + py * s))
        if has_motor:
            along.append((c, s, py * -c + px * s))
            rims.append(u[:, i] * radius[i])
    return rows, along, rims


def _least_squares(rows: list, along: list, rims: list, line: np.ndarray, vx: np.ndarray, vy: np.ndarray,
                   w: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The twists of the copies whose rows leave no one line (``line`` False) written into (vx, vy, w):
    SteeredDrive.constrained_twist's least-squares fit of every driven wheel's ground speed and every
    wheel's no-slip-across row, copy by copy through the same np.linalg.lstsq call."""
    for j in (~line).nonzero()[0].tolist():     # rows of another rank: the least-squares fit of every row
        fit = np.array([[float(v[j]) for v in row] for row in rows] + [[float(v[j]) for v in a] for a in along],
                       dtype=np.float64)
        target = np.array([0.0] * len(rows) + [float(r[j]) for r in rims], dtype=np.float64)
        vx[j], vy[j], w[j] = np.linalg.lstsq(fit, target, rcond=None)[0].tolist()
    return vx, vy, w
