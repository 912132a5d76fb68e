"""The batched simulation's joint motors: every copy's joints moved by Webots' kinematic motor control
(joints.py's :meth:`~sensorium.server.sim.joints.JointMotor.advance`, element by element the same
float64 operations over a ``(copies, joints)`` state), and what rides on them placed per copy.

A joint motor is a RotationalMotor or LinearMotor that is no drive's wheel (joints.py). Its state per
copy (position, target, commanded velocity, current speed, acceleration, available torque/force)
lives in arrays here; :meth:`BatchedJoints.command` is a controller's ``setPosition`` /
``setVelocity`` / ``setAcceleration`` / ``setAvailableTorque`` for many copies at once, relayed to the
motors coupled with it (``group::part`` names) as :class:`~sensorium.server.sim.joints.JointMotor`
relays it. Python's ``min``/``max`` (the second argument when it is strictly smaller / larger) are
written as ``np.where`` of the same comparison, so even a zero's sign is the single motor's.

Each copy's links (:class:`~sensorium.server.sim.joints.Links`' displacements) are arrays too,
``(copies, joints)`` poses made again, for all the copies whose joints moved at once, with Links'
arithmetic (Pose.from_axis_angle on libm's cosine and sine, Pose.compose's stacked products); each
device riding a moved link gets that copy's local pose, ``displacement ∘ mount`` (the single device's
``move_with``), in :attr:`BatchedJoints.local_rot` / ``local_pos``. (Measured: 256 copies, five joints
on two robots, per-copy Links objects took 28 ms a step; the arrays take ~1 ms.) The batched
simulation casts the rays of the distance sensors and lidars (a rotating one's sectors too: batched_lidar.py)
riding joints from those poses, and
places the light sensors, cameras and range finders riding them there (and measures the GPS,
compasses, inertial units, gyros, accelerometers and altimeters riding them there: batched_kinematic.py);
the links' shapes are bodies of their own in the copies' cast and their lights are placed per copy,
both from ``link_rot`` / ``link_pos`` (batched.py's ``_with_links``, batched_lights.py); it refuses
what else rides a joint (batched.py's ``_check_supported``): a bumper's own shapes, planes, textured
shapes and other devices.
"""

from __future__ import annotations

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.sim.batched_kinematic import libm_cos_sin
from sensorium.server.sim.joints import Links
from sensorium.server.sim.simulation import couple, joint_motor
from sensorium.server.world.geometry import Pose

__all__ = ["BatchedJoints", "PLACED_KINDS", "RIDING_KINDS", "compose_stacked", "joint_motors"]

_POSITION_THRESHOLD = 1e-6       # joints.py's (Webots' TARGET_POSITION_THRESHOLD)
_VELOCITY_THRESHOLD = 1e-6

PLACED_KINDS = ("DistanceSensor", "LightSensor", "Lidar", "RangeFinder", "Camera", "GPS", "Compass", "InertialUnit",
                "Gyro", "Accelerometer", "Altimeter")
"""The devices riding a joint that the batched simulation places per copy (their local poses here)."""

RIDING_KINDS = (*PLACED_KINDS, "PositionSensor", "TouchSensor", "RotationalMotor", "LinearMotor")
"""What may ride a joint (``on_joint``) in the batched simulation: the sensors whose rays (and a
light sensor's normal) start from each copy's link, encoders (which read a motor, wherever they sit),
bumpers without shapes of their own (which read their robot's contact, wherever they sit: a bumper's
own shapes on a joint are refused) and the nested joints' motors."""


def compose_stacked(rot: np.ndarray, pos: np.ndarray, rot2: np.ndarray, pos2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Frames (``rot`` (..., 3, 3), ``pos`` (..., 3)) composed with others, stacked: Pose.compose's
    products (``rot @ rot2``, ``rot @ pos2 + pos``), so each frame's bits are the single simulation's."""
    return np.matmul(rot, rot2), np.matmul(rot, pos2[..., None])[..., 0] + pos


def joint_motors(robot: wm.Robot) -> list[wm.RotationalMotor | wm.LinearMotor]:
    """A robot's motors that move joints (every motor but its drive's), in device-list order."""
    drive = {m for _, m in robot.drive_motors}
    return [d for d in robot.devices if isinstance(d, wm.Motor) and d.name not in drive]


class BatchedJoints:
    """Every joint motor of a world's robots, ``copies`` times (see the module docstring)."""

    def __init__(self, world: wm.World, copies: int):
        C = copies
        self.copies = C
        self.column: dict[tuple[int, str], int] = {}        # (slot, motor name) -> joint column
        templates = []
        self.slot_joints: dict[int, dict[str, int]] = {}     # slot -> {motor name: column}
        for slot, r in enumerate(world.robots):
            motors = {d.name: joint_motor(d) for d in joint_motors(r)}
            if not motors:
                continue
            couple(motors)
            mine = self.slot_joints[slot] = {}
            for name, m in motors.items():
                mine[name] = self.column[(slot, name)] = len(templates)
                templates.append((slot, m))
        self.templates = [m for _, m in templates]
        J = len(templates)
        self.J = J
        self.slot = np.array([s for s, _ in templates], dtype=np.int64)
        self.kind = [m.kind for m in self.templates]
        self.names = [m.name for m in self.templates]
        t = self.templates
        self.max_velocity = np.array([m.max_velocity for m in t], dtype=np.float64)
        self.min_position = np.array([m.min_position for m in t], dtype=np.float64)
        self.max_position = np.array([m.max_position for m in t], dtype=np.float64)
        self.limited = self.min_position != self.max_position
        self.max_force = np.array([m.max_force for m in t], dtype=np.float64)
        self.initial = np.array([m.initial_position for m in t], dtype=np.float64)
        self.multiplier = np.array([m.multiplier for m in t], dtype=np.float64)
        self.file_acceleration = np.array([m.acceleration for m in t], dtype=np.float64)
        # each motor and the motors coupled with it (those a position or velocity command reaches)
        self.group: list[np.ndarray] = []
        for slot, m in templates:
            self.group.append(np.array([self.column[(slot, x.name)] for x in (m, *m.coupled)], dtype=np.int64))
        shape = (C, J)
        self.position = np.zeros(shape)
        self.target = np.zeros(shape)
        self.velocity = np.zeros(shape)
        self.speed = np.zeros(shape)
        self.rate = np.zeros(shape)
        self.acceleration = np.zeros(shape)
        self.available_force = np.zeros(shape)
        # -- links: each joint's displacement per copy, parents before children (Links' order and frames)
        self.links: list[tuple[int, int, bool, np.ndarray, np.ndarray, np.ndarray]] = []
        for slot, r in enumerate(world.robots):
            if slot not in self.slot_joints or not any(getattr(x, "on_joint", None) is not None
                                                       for x in (*r.shapes, *r.devices, *r.lights)):
                continue
            template = Links(r, {name: self.templates[j] for name, j in self.slot_joints[slot].items()})
            for name in template.order:
                hinge, axis, anchor, parent = template._frames[name]
                # Pose.from_axis_angle's unit axis (its norm and division, on Links' unit axis)
                unit = axis / float(np.linalg.norm(axis))
                self.links.append((self.column[(slot, name)], -1 if parent is None else self.column[(slot, parent)],
                                   hinge, axis, anchor, unit))
        self.link_rot = np.broadcast_to(np.eye(3), (C, J, 3, 3)).copy()
        self.link_pos = np.zeros((C, J, 3))
        self._at = np.broadcast_to(self.initial, (C, J)).copy()     # the positions the links were made at
        # a link displaced since the copy's reset (Links.poses holds it then, and the scene composes its
        # robot's pose with it; before, it is where the robot is: recognition's carrier)
        self.placed = np.zeros((C, J), dtype=bool)
        # devices riding joints: (kind, column) -> (slot, joint, mount pose), their local poses per copy
        self.riders: dict[tuple[str, int], tuple[int, str, Pose]] = {}
        self._rider_of: dict[int, dict[tuple[str, int], Pose]] = {}    # joint column -> its riders' mounts
        self._loaded: dict[tuple[str, int], Pose] = {}                # a rider's local pose as built
        self.local_rot: dict[tuple[str, int], np.ndarray] = {}
        self.local_pos: dict[tuple[str, int], np.ndarray] = {}
        self.moved = False          # whether a rider's local pose changed in the last step or reset

    def add_rider(self, kind: str, column: int, slot: int, joint: str, mount: Pose, local: Pose) -> None:
        """A device (its kind's ``column``) riding ``joint`` of robot ``slot``, where the file places it
        with every joint at its initial position (``mount``); ``local``: its local pose as built
        (the single device's ``move_with`` of its link's identity displacement)."""
        key = (kind, column)
        self.riders[key] = (slot, joint, mount)
        self._rider_of.setdefault(self.of(slot, joint), {})[key] = mount
        self._loaded[key] = local
        self.local_rot[key] = np.broadcast_to(local.rotation, (self.copies, 3, 3)).copy()
        self.local_pos[key] = np.broadcast_to(local.translation, (self.copies, 3)).copy()

    def of(self, slot: int, name: str) -> int:
        col = self.column.get((int(slot), name))
        if col is None:
            raise KeyError(f"robot slot {slot} has no joint motor {name!r}")
        return col

    # ------------------------------------------------------------------ control
    def reset(self, idx: np.ndarray) -> None:
        """These copies' joints as built: at their initial positions, held there at maxVelocity with
        their full torque/force and the file's acceleration (JointMotor's state when made)."""
        if not self.J:
            return
        self.position[idx] = self.initial
        self.target[idx] = self.initial
        self.velocity[idx] = self.max_velocity
        self.speed[idx] = 0.0
        self.rate[idx] = 0.0
        self.acceleration[idx] = self.file_acceleration
        self.available_force[idx] = self.max_force
        # the links as built (identity displacements), as a fresh Simulation's Links
        self.link_rot[idx] = np.eye(3)
        self.link_pos[idx] = 0.0
        self._at[idx] = self.initial
        self.placed[idx] = False
        for key, local in self._loaded.items():
            self.local_rot[key][idx] = local.rotation
            self.local_pos[key][idx] = local.translation
        self.moved = True

    def command(self, slot: int, name: str, position=None, velocity=None, acceleration=None,
                available_force=None, copies=None) -> None:
        """A controller's commands to motor ``name`` of robot ``slot`` in the named copies (default:
        all), each a number or one per copy, applied in libController's order as
        :meth:`JointMotor.command <sensorium.server.sim.joints.JointMotor.command>` applies them: a
        position (±inf: velocity control) and a velocity reach the coupled motors too, each scaled
        by its multiplier, a position clamped to each one's limits, a velocity to ±maxVelocity; an
        acceleration (>= 0, or -1) and an available torque/force (>= 0, at most the maximum) only
        this motor. Bad values raise ValueError naming the motor."""
        j = self.of(slot, name)
        idx = np.arange(self.copies) if copies is None else np.asarray(copies, dtype=np.int64).reshape(-1)
        n = len(idx)

        def values(v, what: str) -> np.ndarray:
            try:
                a = np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
            except (TypeError, ValueError):
                raise ValueError(f"motor {name!r}: {what} must be a number or one per copy ({n}), got "
                                 f"{np.shape(v)}") from None
            if np.isnan(a).any():
                raise ValueError(f"motor {name!r}: {what} must be a number, got NaN")
            return a

        if position is not None:
            p = values(position, "position")
            for k in self.group[j].tolist():
                scaled = np.where(np.isinf(p), p, p * self.multiplier[k])
                if self.limited[k]:
                    lo, hi = self.min_position[k], self.max_position[k]
                    low = np.where(lo > scaled, lo, scaled)                # min(max(target, lo), hi)
                    scaled = np.where(np.isinf(p), p, np.where(hi < low, hi, low))
                self.target[idx, k] = scaled
        if velocity is not None:
            v = values(velocity, "velocity")
            for k in self.group[j].tolist():
                vmax = self.max_velocity[k]
                wanted = v * self.multiplier[k]
                low = np.where(-vmax > wanted, -vmax, wanted)              # min(max(wanted, -vmax), vmax)
                self.velocity[idx, k] = np.where(vmax < low, vmax, low)
        if acceleration is not None:
            a = values(acceleration, "acceleration")
            if not ((a >= 0.0) | (a == -1.0)).all() or np.isinf(a).any():
                raise ValueError(f"motor {name!r}: acceleration must be >= 0 and finite, or -1")
            self.acceleration[idx, j] = a
        if available_force is not None:
            f = values(available_force, "available torque/force")
            if not (f >= 0.0).all():
                raise ValueError(f"motor {name!r}: available torque/force must be >= 0")
            self.available_force[idx, j] = np.where(self.max_force[j] < f, self.max_force[j], f)   # min(f, max)

    # ------------------------------------------------------------------ stepping
    def step(self, live: np.ndarray, dt_s: float) -> None:
        """One basic step of the live copies' joints (JointMotor.advance), then their links."""
        if not self.J:
            return
        every = len(live) == self.copies
        at = slice(None) if every else live
        pos, tgt, vel = self.position[at], self.target[at], self.velocity[at]
        speed, acc, force = self.speed[at], self.acceleration[at], self.available_force[at]
        inf = np.isinf(tgt)
        with np.errstate(invalid="ignore"):
            pushing = self.limited & (((pos >= self.max_position) & (vel >= 0.0))
                                      | ((pos <= self.min_position) & (vel <= 0.0)))
            idle = np.where(inf, pushing, np.abs(tgt - pos) < _POSITION_THRESHOLD)
        a = np.where((acc == -1.0) | (acc > force), force, acc)
        wanted = np.where(inf, vel, np.abs(vel))
        up = speed + a * dt_s
        down = speed - a * dt_s
        changed = np.where(wanted > speed, np.where(wanted < up, wanted, up),      # min(up, wanted)
                           np.where(wanted > down, wanted, down))                  # max(down, wanted)
        speed = np.where(np.abs(wanted - speed) > _VELOCITY_THRESHOLD, changed, speed)
        ahead = pos + speed * dt_s
        back = pos - speed * dt_s
        moved = np.where(tgt > pos, np.where(tgt < ahead, tgt, ahead),           # min(ahead, target)
                         np.where(tgt > back, tgt, back))                        # max(back, target)
        new = np.where(idle, pos, moved)
        changed_copies = (new != pos).any(axis=1)     # (before pos, a view when every copy steps, is written)
        self.speed[at] = np.where(idle, 0.0, speed)
        self.rate[at] = np.where(idle, 0.0, (new - pos) / dt_s)
        self.position[at] = new
        self._place_links(live[changed_copies])

    def _place_links(self, copies: np.ndarray) -> None:
        """Links.update for these copies at once: each joint whose position changed since its link
        was made, or whose parent's link moved, gets its displacement again -- a hinge's
        Pose.from_axis_angle (libm's cosine and sine) about its anchor, a slider's translation,
        composed onto its parent's (Pose.compose: the same 3x3 products, stacked) -- and the
        devices riding a moved link their local poses (``displacement ∘ mount``)."""
        self.moved = False
        if not len(copies) or not self.links:
            return
        moved: dict[int, np.ndarray] = {}
        for j, parent, hinge, axis, anchor, unit in self.links:
            q = self.position[copies, j]
            rows = q != self._at[copies, j]
            if parent >= 0:
                rows |= moved[parent]
            moved[j] = rows
            if not rows.any():
                continue
            c = copies[rows]
            self._at[c, j] = q[rows]
            delta = q[rows] - self.initial[j]
            if hinge:
                x, y, z = unit.tolist()
                cos, sin = libm_cos_sin(delta)
                k = 1.0 - cos
                rot = np.empty((len(c), 3, 3))
                rot[:, 0, 0], rot[:, 0, 1], rot[:, 0, 2] = cos + x * x * k, x * y * k - z * sin, x * z * k + y * sin
                rot[:, 1, 0], rot[:, 1, 1], rot[:, 1, 2] = y * x * k + z * sin, cos + y * y * k, y * z * k - x * sin
                rot[:, 2, 0], rot[:, 2, 1], rot[:, 2, 2] = z * x * k - y * sin, z * y * k + x * sin, cos + z * z * k
                pos = anchor - np.matmul(rot, anchor)
            else:
                rot = np.broadcast_to(np.eye(3), (len(c), 3, 3))
                pos = axis * delta[:, None]
            if parent >= 0:              # the parent's displacement ∘ its own (Pose.compose)
                rot, pos = compose_stacked(self.link_rot[c, parent], self.link_pos[c, parent], rot, pos)
            self.link_rot[c, j] = rot
            self.link_pos[c, j] = pos
            self.placed[c, j] = True
            for key, mount in self._rider_of.get(j, {}).items():
                self.local_rot[key][c] = np.matmul(self.link_rot[c, j], mount.rotation)
                self.local_pos[key][c] = np.matmul(self.link_rot[c, j], mount.translation) + self.link_pos[c, j]
                self.moved = True

    # ------------------------------------------------------------------ encoders
    def read_encoders(self, positions: list, copies: np.ndarray, cols: np.ndarray, values: np.ndarray) -> None:
        """The due position sensors (``cols`` of ``positions``) of a joint motor read its position."""
        if not self.J:
            return
        enc = getattr(self, "_encoders", None)
        if enc is None:
            enc = self._encoders = np.array([self.column.get((int(d.robot_index), d.config.motor), -1)
                                             if d.config.motor is not None else -1 for d in positions], dtype=np.int64)
        j = enc[cols]
        mine = (j >= 0).nonzero()[0]
        if len(mine):
            values[mine] = self.position[copies[mine], j[mine]]
