"""Car-like robots (``ackermann_drive``) in the batched simulation: their motors per copy and the
bicycle model's step of :class:`~sensorium.server.sim.motion.AckermannDrive`, element by element
the same float64 operations.

Per copy and car the six motors (two steering, up to four driven wheels) keep a target, a velocity
and an angle, as :class:`~sensorium.server.sim.motion.WheelMotor`. A step advances them (position
control for the steering, velocity or position control for the wheels), works out each moving
car's speed ``v`` and turn rate ``v·κ`` (``AckermannDrive.step``) and hands them to the batched
simulation's shared arc, contact and placing (``BatchedSimulation._drive_numpy``), which treat a
car as any other driven robot (a car whose origin is off its rear axle, ``rear_axle``, moves its
axle's centre on the arc and its origin after it, as ``motion.offset_arc_step``). The tangents and
the wheels' distance factors go through ``math.tan`` and ``math.hypot`` per element: the single
simulation's calls (numpy's float64 routines may round differently on this machine), and the same
on every path (nothing here needs the C helper).
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.batched_kinematic import libm_each
from sensorium.server.sim.motion import FREE_WHEELS, wheel_places

__all__ = ["CarDrives", "MOTORS"]

MOTORS = 6
"""Motor columns per car: right steer, left steer, then the driven wheels in the drive's order."""


class CarDrives:
    """The car-like robots of a world, ``copies`` times (see the module docstring)."""

    def __init__(self, world: wm.World, copies: int):
        cars = [(i, r) for i, r in enumerate(world.robots) if r.ackermann_drive is not None]
        self.slots = np.array([i for i, _ in cars], dtype=np.int64)
        self.names = [r.name for _, r in cars]
        K = len(cars)
        self.car_of = {int(s): k for k, s in enumerate(self.slots.tolist())}
        # per car: its motors' names -> column, the limits, the bicycle model's constants
        self.columns: list[dict[str, int]] = []
        self.n_wheels = np.zeros(K, dtype=np.int64)
        self.max_velocity = np.zeros((K, MOTORS))
        self.limit = np.zeros(K)
        self.sign = np.zeros(K)
        self.wheelbase = np.zeros(K)
        self.wheel_x = np.zeros((K, MOTORS - 2))
        self.wheel_y = np.zeros((K, MOTORS - 2))
        self.wheel_r = np.zeros((K, MOTORS - 2))
        # per car: its free wheels (no motor: AckermannDrive.free), key -> index, and each one's (x, y,
        # radius, steering column or -1)
        self.free: list[dict[str, int]] = []
        self.free_place: list[list[tuple[float, float, float, int]]] = []
        # per robot slot: its rear axle's offset from its origin along forward (0 for every other robot)
        self.rear_axle = np.zeros(len(world.robots))
        for k, (i, r) in enumerate(cars):
            a = r.ackermann_drive
            assert a is not None
            place = wheel_places(a)
            self.columns.append({name: j for j, (_, name) in enumerate(a.motor_fields)})
            self.n_wheels[k] = len(a.driven)
            self.max_velocity[k, :2] = float(a.max_steering_speed)
            self.max_velocity[k, 2:2 + len(a.driven)] = [wm.wheel_max_speed(a, name) for _, name in a.driven]
            self.limit[k] = float(a.max_steering_angle)
            self.sign[k] = 1.0 if a.positive_steers == "right" else -1.0
            self.wheelbase[k] = float(a.wheelbase)
            self.rear_axle[i] = float(a.rear_axle_offset)
            for j, (field, _) in enumerate(a.driven):
                self.wheel_x[k, j], self.wheel_y[k, j], self.wheel_r[k, j] = place[field]
            driven = {field for field, _ in a.driven}
            free = [(field, steer) for field, steer in FREE_WHEELS if field not in driven]
            self.free.append({field[:-6]: j for j, (field, _) in enumerate(free)})
            self.free_place.append([(*place[field], steer) for field, steer in free])
        self.offset = bool(self.rear_axle.any())
        """Whether a car's origin is off its rear axle (its moves then go through the offset arc)."""
        self.target = np.zeros((copies, K, MOTORS))       # inf: velocity control
        self.velocity = np.zeros((copies, K, MOTORS))
        self.angle = np.zeros((copies, K, MOTORS))
        self.free_turned = np.zeros((copies, K, 2))        # each free wheel's rolled angle (AckermannDrive.free_turned)
        self._encoders: np.ndarray | None = None          # per position sensor: (car, column) or (-1, -1)
        self._free_encoders: np.ndarray | None = None     # per position sensor: (car, free wheel) or (-1, -1)

    # ------------------------------------------------------------------ control
    def reset(self, idx: np.ndarray) -> None:
        """Every motor of these copies as built: position control at 0 at its maxVelocity (Webots' default)."""
        self.target[idx] = 0.0
        self.velocity[idx] = self.max_velocity
        self.angle[idx] = 0.0
        self.free_turned[idx] = 0.0

    def column(self, slot: int, name: str) -> tuple[int, int]:
        """(car, column) of a car's motor."""
        k = self.car_of[slot]
        return k, self.columns[k][name]

    def set_position(self, copies, k: int, j: int, value) -> None:
        """``setPosition`` of motor ``j`` of car ``k`` in the named copies (a steering motor's target
        clamped to ±max_steering_angle, as SteeringMotor)."""
        value = np.asarray(value, dtype=np.float64)
        if j < 2:
            lim = self.limit[k]
            value = np.minimum(np.maximum(value, -lim), lim)
        self.target[copies, k, j] = value

    def set_velocity(self, copies, k: int, j: int, value) -> None:
        """``setVelocity`` of motor ``j`` of car ``k`` in the named copies (clamped to its maxVelocity)."""
        vmax = self.max_velocity[k, j]
        self.velocity[copies, k, j] = np.minimum(np.maximum(np.asarray(value, dtype=np.float64), -vmax), vmax)

    def command(self, slot: int, right, left, wheel, copies=None) -> None:
        """A car's steering motors to the positions ``right``, ``left`` (rad) and every driven wheel in
        velocity control at ``wheel`` (rad/s), in the named copies (default: all); (copies,) each."""
        idx = slice(None) if copies is None else np.asarray(copies, dtype=np.int64)
        k = self.car_of[slot]
        self.set_position(idx, k, 0, right)
        self.set_position(idx, k, 1, left)
        self.roll(slot, wheel, copies)

    def roll(self, slot: int, wheel, copies=None) -> None:
        """Every driven wheel of a car in velocity control at ``wheel`` (rad/s) in the named copies
        (default: all), its steering left as it is."""
        idx = slice(None) if copies is None else np.asarray(copies, dtype=np.int64)
        k = self.car_of[slot]
        for j in range(2, 2 + int(self.n_wheels[k])):
            self.target[idx, k, j] = math.inf
            self.set_velocity(idx, k, j, wheel)

    # ------------------------------------------------------------------ stepping
    def step(self, live: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Advance the live copies' car motors one step; the moving cars' (copies, slots, v, w):
        AckermannDrive.step up to its arc."""
        out: list[tuple[np.ndarray, ...]] = []
        for k in range(len(self.slots)):
            n = 2 + int(self.n_wheels[k])
            omega = self._advance(live, k, n, dt)
            rolled = omega[:, 2:] * self.wheel_r[k, :n - 2]              # motor.advance(dt) * r
            moving = (rolled != 0.0).any(axis=1).nonzero()[0]
            if not len(moving):
                continue
            rolled = rolled[moving]
            copies = live[moving]
            kl = -self._curvature(copies, k)
            # sum(u) / sum(hypot(1 - κ y, κ x)), summed as Python's sum (0 + a + b ...)
            u_sum = 0.0 + rolled[:, 0]
            h_sum = 0.0 + libm_each(math.hypot, 1.0 - kl * self.wheel_y[k, 0], kl * self.wheel_x[k, 0])
            for j in range(1, n - 2):
                u_sum = u_sum + rolled[:, j]
                h_sum = h_sum + libm_each(math.hypot, 1.0 - kl * self.wheel_y[k, j], kl * self.wheel_x[k, j])
            v = u_sum / h_sum
            self._roll_free(copies, k, v, kl, dt)
            out.append((copies, np.full(len(copies), self.slots[k], dtype=np.int64), v, v * kl))
        if not out:
            empty = np.zeros(0)
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), empty, empty
        return tuple(np.concatenate(parts) for parts in zip(*out))  # type: ignore[return-value]

    def _advance(self, live: np.ndarray, k: int, n: int, dt: float) -> np.ndarray:
        """WheelMotor.advance of car k's n motors in the live copies; their angular speeds (live, n)."""
        tgt = self.target[live, k, :n]
        vel = self.velocity[live, k, :n]
        ang = self.angle[live, k, :n]
        remaining = tgt - ang
        with np.errstate(invalid="ignore"):
            speed = np.minimum(np.abs(vel), np.abs(remaining) / dt) if dt > 0 else np.zeros_like(vel)
            held = np.where(remaining != 0.0, np.copysign(speed, remaining), 0.0)
        omega = np.where(np.isinf(tgt), vel, held)
        self.angle[live, k, :n] = ang + omega * dt
        return omega

    def _roll_free(self, copies: np.ndarray, k: int, v: np.ndarray, kl: np.ndarray, dt: float) -> None:
        """AckermannDrive.roll_free of car k in these copies (its moving ones), the same operations."""
        for j, (x, y, r, steer) in enumerate(self.free_place[k]):
            delta = self.sign[k] * self.angle[copies, k, steer] if steer >= 0 else np.zeros(len(copies))
            along = (1.0 - kl * y) * libm_each(math.cos, delta) - kl * x * libm_each(math.sin, delta)
            self.free_turned[copies, k, j] = self.free_turned[copies, k, j] + v * dt * along / r

    def _curvature(self, copies: np.ndarray, k: int) -> np.ndarray:
        """AckermannDrive.curvature of car k in these copies (1/R, positive turning right)."""
        sign = self.sign[k]
        tr = libm_each(math.tan, sign * self.angle[copies, k, 0])
        tl = libm_each(math.tan, sign * self.angle[copies, k, 1])
        s = tr + tl
        with np.errstate(divide="ignore", invalid="ignore"):
            curv = 2.0 * tr * tl / (self.wheelbase[k] * s)
        return np.where(s == 0.0, 0.0, curv)

    # ------------------------------------------------------------------ encoders
    def read_encoders(self, positions: list, copies: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
        """The due position sensors (``cols`` of ``positions``, the batched simulation's list) of a
        car's motor read its angle, written into ``values`` (before noise and resolution)."""
        if self._encoders is None:
            enc = np.full((len(positions), 2), -1, dtype=np.int64)
            for i, d in enumerate(positions):
                k = self.car_of.get(int(d.robot_index))
                if k is not None and d.config.motor in self.columns[k]:
                    enc[i] = (k, self.columns[k][d.config.motor])
            self._encoders = enc
        car = self._encoders[cols]
        mine = (car[:, 0] >= 0).nonzero()[0]
        if len(mine):
            values[mine] = self.angle[copies[mine], car[mine, 0], car[mine, 1]]
        if self._free_encoders is None:      # a free wheel's encoder: its world-file angle plus the rolled one
            enc = np.full((len(positions), 2), -1, dtype=np.int64)
            for i, d in enumerate(positions):
                k = self.car_of.get(int(d.robot_index))
                wheel = getattr(d.config, "free_wheel", None)
                if k is not None and wheel is not None:
                    enc[i] = (k, self.free[k][wheel])
            self._free_encoders = enc
        free = self._free_encoders[cols]
        mine = (free[:, 0] >= 0).nonzero()[0]
        for i in mine.tolist():
            cfg = positions[int(cols[i])].config
            values[i] = float(cfg.position) + cfg.free_wheel_sign * float(self.free_turned[copies[i], free[i, 0],
                                                                                            free[i, 1]])

