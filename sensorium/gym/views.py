"""One copy of a batched simulation seen as a single simulation: what task callables and the
renderer read of ``sim`` and ``robot``.

A :class:`~sensorium.gym.task.Task`'s ``start(sim, robot, rng)`` (and a reward or termination
without a vectorised form) is written against :class:`~sensorium.server.sim.simulation.Simulation`
and its ``RobotState``. The vector environment hands them these views of one copy instead:

* ``CopySim``: ``time_ms``, ``basic_time_step``, ``world``, ``loaded``, ``ground``, ``robots`` / ``robot(name)``,
  ``run(steps)`` / ``step()`` (this copy alone),
  ``scene`` (``world_lights()``, ``solid_poses``, ``solids_version``, and ``engine.cast(...)`` casting in this copy only:
  ``exclude_owner`` is a robot index, as in the single simulation);
* ``CopyRobot``: ``name``, ``index``, ``model``, ``pose``, ``set_pose(...)``, ``motors`` /
  ``motor(name)``, ``drive.left`` / ``drive.right`` and ``drive.lefts`` / ``drive.rights`` (every
  wheel of a side: ``set_position``, ``set_velocity``, ``velocity``, ``position``,
  ``max_velocity``), ``drive.left_sign`` / ``drive.right_sign`` (-1.0 for a side mounted mirrored:
  ``reversed_motors``), ``device(name).enable(period)`` / ``.value`` (a GPS's ``.values``, ``.speed``,
  ``.speed_vector``, a compass's, a gyro's or an accelerometer's ``.values``, an inertial unit's
  ``.roll_pitch_yaw``, ``.quaternion``; a bumper's or an altimeter's ``.value``; a camera's ``.image``,
  ``.recognition_enable(period)``, ``.enable_segmentation(on)``, ``.recognition_objects`` (or
  ``.objects``) and ``.segmentation_image``: this copy's, batched_recognition.py).
  The batched simulation drives a skid-steer robot's wheels of one side together: its wheels of a
  side share one state, so commanding one of them commands its side. A car-like robot has
  ``motors`` (its steering and driven wheels) and no ``drive``; so have a mecanum robot (its four
  wheels, batched_mecanum.MecanumDrives), an omni-wheel robot (its wheels, batched_omni.OmniDrives) and a
  steered-wheel robot (its rolling wheels, batched_steered.SteeredDrives).
  A robot's joint motors are in its ``motors`` too (batched_joints.BatchedJoints).

Anything else a callable reaches for raises AttributeError naming the view.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sensorium.server.raycast.engine import RayHits, RayKind
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.batched_holonomic import HolonomicDrives
from sensorium.server.sim.batched_kinematic import READINGS
from sensorium.server.sim.batched_lights import copy_world_lights
from sensorium.server.sim.motion import velocity_accepted

__all__ = ["CopySim", "CopyRobot"]


class _Motor:
    """A motor in one copy, over the batched state arrays that hold it (``target``, ``velocity``,
    ``angle`` at ``index``): a wheel of a drive, a car's steering or driven-wheel motor
    (batched_car.CarDrives; a steering motor's target clamped to +-``limit``), or a mecanum or omni
    wheel (batched_holonomic.HolonomicDrives)."""

    def __init__(self, name: str, max_velocity: float, arrays: tuple[np.ndarray, np.ndarray, np.ndarray],
                 index: tuple[int, int, int], limit: float = math.inf):
        self.name = name
        self.max_velocity = max_velocity
        self._target, self._velocity, self._angle = arrays
        self._i = index
        self._limit = limit

    @classmethod
    def wheel(cls, sim: BatchedSimulation, copy: int, slot: int, name: str) -> _Motor:
        w = sim.wheel_side[slot][name]
        return cls(name, float(sim.max_wheel[slot, w]), (sim.target, sim.velocity, sim.wheel_angle), (copy, slot, w))

    @classmethod
    def car(cls, sim: BatchedSimulation, copy: int, slot: int, name: str) -> _Motor:
        cars = sim.cars
        assert cars is not None
        k, j = cars.column(slot, name)
        return cls(name, float(cars.max_velocity[k, j]), (cars.target, cars.velocity, cars.angle), (copy, k, j),
                   float(cars.limit[k]) if j < 2 else math.inf)

    @classmethod
    def holonomic(cls, drives: HolonomicDrives, copy: int, slot: int, name: str) -> _Motor:
        k, j = drives.column(slot, name)
        return cls(name, float(drives.max_velocity[k, j]), (drives.target, drives.velocity, drives.angle), (copy, k, j))

    @property
    def velocity(self) -> float:
        return float(self._velocity[self._i])

    @property
    def position(self) -> float:
        return float(self._angle[self._i])

    @property
    def target_position(self) -> float:
        return float(self._target[self._i])

    def set_position(self, value: float) -> None:
        if not isinstance(value, (int, float)) or math.isnan(value):
            raise ValueError(f"motor {self.name!r}: position must be a number or inf, got {value!r}")
        self._target[self._i] = float(min(max(value, -self._limit), self._limit))

    def set_velocity(self, value: float) -> None:
        """``WheelMotor.set_velocity``'s rules (motion.velocity_accepted), so a task callable's commands
        do in a copy what they do in a Simulation; clamped to ``max_velocity``."""
        if velocity_accepted(self.name, value, self.target_position, self.velocity):
            self._velocity[self._i] = float(min(max(value, -self.max_velocity), self.max_velocity))

class _JointMotor:
    """A joint motor in one copy (batched_joints.BatchedJoints): ``position``, ``target_position``,
    ``velocity``, ``max_velocity``, ``set_position``, ``set_velocity`` (the single JointMotor's rules:
    coupled motors, multiplier, limits, a negative velocity in position control ignored)."""

    def __init__(self, sim: BatchedSimulation, copy: int, slot: int, name: str):
        self._joints, self._c, self._slot, self.name = sim.joints, copy, slot, name
        self._j = sim.joints.of(slot, name)
        self.max_velocity = float(sim.joints.max_velocity[self._j])

    @property
    def position(self) -> float:
        return float(self._joints.position[self._c, self._j])

    @property
    def target_position(self) -> float:
        return float(self._joints.target[self._c, self._j])

    @property
    def velocity(self) -> float:
        return float(self._joints.velocity[self._c, self._j])

    def set_position(self, value: float) -> None:
        self._joints.command(self._slot, self.name, position=value, copies=[self._c])

    def set_velocity(self, value: float) -> None:
        if velocity_accepted(self.name, value, self.target_position, self.velocity):
            self._joints.command(self._slot, self.name, velocity=value, copies=[self._c])


class _Drive:
    def __init__(self, sim: BatchedSimulation, copy: int, slot: int):
        left, right = sim.world.robots[slot].differential_drive.motor_names
        self.lefts = [_Motor.wheel(sim, copy, slot, name) for name in left]
        self.rights = [_Motor.wheel(sim, copy, slot, name) for name in right]
        self.left, self.right = self.lefts[0], self.rights[0]
        self.left_sign, self.right_sign = (float(v) for v in sim.wheel_sign[slot])   # (motion.DifferentialDrive's)

    @property
    def motors(self) -> dict[str, _Motor]:
        return {m.name: m for m in (*self.lefts, *self.rights)}


class _Device:
    def __init__(self, sim: BatchedSimulation, copy: int, slot: int, name: str):
        self._s, self._c = sim, copy
        self.ref = sim.device(sim.robot_names[slot], name)
        self.name = name
        self.kind = self.ref.kind

    def enable(self, period_ms: int) -> None:
        self._s.enable(self.ref, period_ms, copies=[self._c])

    @property
    def value(self) -> float:
        return float(self._s.value(self.ref)[self._c])

    @property
    def range_image(self) -> np.ndarray:
        return self._s.range_image(self.ref)[self._c]

    @property
    def image(self) -> np.ndarray:
        """A camera's latest BGRA image in this copy."""
        return self._s.image(self.ref)[self._c]

    def recognition_enable(self, period_ms: int) -> None:
        """A camera's recognition in this copy (batched_recognition.py)."""
        self._s.recognition_enable(self.ref, period_ms, copies=[self._c])

    def enable_segmentation(self, on: bool) -> None:
        self._s.enable_segmentation(self.ref, on, copies=[self._c])

    @property
    def recognition_objects(self) -> list:
        """A camera's latest recognised objects in this copy (``Camera.objects``)."""
        return self._s.recognition_objects(self.ref, self._c)

    @property
    def objects(self) -> list:
        return self.recognition_objects

    @property
    def segmentation_image(self) -> np.ndarray:
        """A camera's latest BGRA segmentation image in this copy."""
        return self._s.segmentation_image(self.ref)[self._c]

    def __getattr__(self, name: str) -> Any:
        ref = self.__dict__.get("ref")
        if ref is not None and name in READINGS.get(ref.kind, ()):   # a GPS's values, speed, ...: this copy's
            return self._s.reading(ref, name)[self._c].copy()
        # the device's constants (config, params, table, ...) from its template in the batched simulation
        return getattr(self._s.template(self.ref), name)


class CopyRobot:
    """Robot ``slot`` of copy ``copy`` (see the module docstring)."""

    def __init__(self, sim: BatchedSimulation, copy: int, slot: int):
        self._s, self._c = sim, copy
        self.index = slot
        self.name = sim.robot_names[slot]
        self.model = sim.world.robots[slot]
        self.motors: dict[str, _Motor | _JointMotor]
        if sim.has_drive[slot]:
            self.drive: _Drive | None = _Drive(sim, copy, slot)
            self.motors = dict(self.drive.motors)
        elif sim.cars is not None and slot in sim.cars.car_of:     # a car: its motors (no drive view)
            self.drive = None
            self.motors = {name: _Motor.car(sim, copy, slot, name) for name in sim.cars.columns[sim.cars.car_of[slot]]}
        else:           # a mecanum or omni-wheel robot: its wheels; any other robot: no motors
            self.drive = None
            self.motors = {}
            for drives in (sim.mecanum, sim.omni, sim.steered):
                if drives is not None and slot in drives.of:
                    self.motors = {name: _Motor.holonomic(drives, copy, slot, name)
                                   for name in drives.columns[drives.of[slot]]}
        # its joint motors (every motor but the drive's): batched_joints.py
        self.motors.update({name: _JointMotor(sim, copy, slot, name) for name in sim.joints.slot_joints.get(slot, {})})

    @property
    def pose(self):
        return self._s.pose(self._c, self.index)

    def set_pose(self, translation=None, rotation=None, quaternion=None) -> None:
        self._s.set_pose(self._c, self.index, translation, rotation, quaternion)

    def motor(self, name: str) -> _Motor | _JointMotor:
        try:
            return self.motors[name]
        except KeyError:
            raise KeyError(f"robot {self.name!r} has no motor {name!r}") from None

    def device(self, name: str) -> _Device:
        return _Device(self._s, self._c, self.index, name)

    def __getattr__(self, name: str) -> Any:
        raise AttributeError(f"CopyRobot (a robot of one copy of a batched simulation) has no {name!r}")


class _Engine:
    def __init__(self, sim: BatchedSimulation, copy: int):
        self._s, self._c = sim, copy

    @property
    def precision(self):
        return self._s.precision

    def cast(self, origins, directions, t_near=0.0, t_far=np.inf, kind=RayKind.BOUNDING, exclude_owner=-1,
             skip_transparent=False, **_ignored) -> RayHits:
        O = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
        return self._s.cast(np.full(len(O), self._c, dtype=np.int64), O, directions, t_near, t_far, kind,
                            exclude_owner, skip_transparent)


class _Scene:
    def __init__(self, sim: BatchedSimulation, copy: int):
        self._s = sim
        self._copy = copy
        self.engine = _Engine(sim, copy)
        self.solid_poses = sim.scene.solid_poses

    def world_lights(self) -> list:
        """The copy's lights: the fixed ones, then its robots' at its poses."""
        return copy_world_lights(self._s, self._copy)

    @property
    def solids_version(self) -> int:
        return self._s.scene.solids_version


class CopySim:
    """Copy ``copy`` of a batched simulation (see the module docstring)."""

    def __init__(self, sim: BatchedSimulation, copy: int):
        self._s, self.copy = sim, copy
        self.world = sim.world
        self.loaded = sim.loaded
        self.basic_time_step = sim.basic_time_step
        self.scene = _Scene(sim, copy)
        self.ground = sim.ground           # the terrains robots ride (shared by every copy; None without)
        self.robots = {name: CopyRobot(sim, copy, i) for i, name in enumerate(sim.robot_names)}

    @property
    def time_ms(self) -> int:
        return int(self._s.time_ms[self.copy])

    @property
    def precision(self):
        return self._s.precision

    def robot(self, name: str) -> CopyRobot:
        try:
            return self.robots[name]
        except KeyError:
            raise KeyError(f"no robot {name!r} (robots: {', '.join(self.robots)})") from None

    def run(self, steps: int) -> None:
        """Advance this copy alone by ``steps`` basic steps."""
        active = np.zeros(self._s.copies, dtype=bool)
        active[self.copy] = True
        self._s.run(steps, active if self._s.copies > 1 else None)

    def step(self) -> None:
        self.run(1)

    def __getattr__(self, name: str) -> Any:
        raise AttributeError(f"CopySim (one copy of a batched simulation) has no {name!r}")
