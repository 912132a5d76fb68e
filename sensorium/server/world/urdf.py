"""A robot's URDF as Webots' ``wb_robot_get_urdf(prefix)`` exports it, from the robot's nodes
(``schemas.world.NestedNode``: Solids, Poses, joints and devices in the robot's frame as the world
loads; a joint's axis and anchor on its node) and its motors (limits).

What Webots writes, and so what is written here: a link ``base_link`` for the robot; a link per
Solid (devices that are Solids too), named by its ``name`` (else its DEF name, else its node type in
lower case; a name already given gets ``_N``, N counting such clashes); a joint per HingeJoint
(``revolute`` when its motor has limits, else ``continuous``) and SliderJoint (``prismatic``), with a
motor, a position sensor only or no device at all, named after its motor (else its position sensor,
else as a link is), whose child link's frame sits on the hinge's anchor with the end point's
orientation, its axis (a unit vector) in that frame, ``<limit>`` from the motor if it has one (effort:
maxTorque or maxForce, velocity: maxVelocity, lower/upper when the motor has limits); a ``fixed`` joint
``PARENT_CHILD_joint`` for every other Solid. Origins are relative to the parent link's frame,
``rpy`` Z-Y-X as URDF reads it. Links and joints come in the order Webots writes them (a last-in,
first-out queue of the link roots and joints met under each link), so that a chain built by
following the first joint of each link (ikpy) meets the same links.

Departures (README "getUrdf"): the poses are the world file's (every joint at its initial
position), not the current ones; numbers are printed in full (``repr``), not rounded to 6 decimals;
links carry no visual or collision geometry; Hinge2Joints and BallJoints are fixed joints here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

import numpy as np

from sensorium.schemas import world as wm
from sensorium.server.world.poses import pose_from_model

_JOINTS = ("HingeJoint", "SliderJoint")
_ANY_JOINT = ("HingeJoint", "SliderJoint", "Hinge2Joint", "BallJoint")
_MOTORS = ("RotationalMotor", "LinearMotor")


@dataclass(frozen=True)
class _Frame:
    """A link's frame in the robot frame (float64)."""

    rotation: np.ndarray
    origin: np.ndarray


def _num(v: float) -> str:
    v = float(v)
    return repr(0.0 if v == 0.0 else v)    # no "-0.0"


def _vec(v: Sequence[float] | np.ndarray) -> str:
    return " ".join(_num(x) for x in v)


def _rpy(r: np.ndarray) -> tuple[float, float, float]:
    """URDF's roll, pitch, yaw of r = Rz(yaw) Ry(pitch) Rx(roll)."""
    pitch = math.atan2(-r[2, 0], math.hypot(r[0, 0], r[1, 0]))
    if math.hypot(r[0, 0], r[1, 0]) < 1e-12:       # gimbal lock: yaw 0, roll takes the rest
        return math.atan2(-r[1, 2], r[1, 1]), pitch, 0.0
    return math.atan2(r[2, 1], r[2, 2]), pitch, math.atan2(r[1, 0], r[0, 0])


class _Export:
    def __init__(self, robot: wm.Robot, entries: Sequence[wm.NestedNode], prefix: str):
        self.robot, self.entries, self.prefix = robot, list(entries), prefix
        self.children: dict[int, list[int]] = {}
        for i, e in enumerate(self.entries):
            self.children.setdefault(e.parent, []).append(i)
        self.devices = {d.name: d for d in robot.devices}
        self.names: dict[int, str] = {}
        self.clashes = 0
        self.frames: dict[int, _Frame] = {-1: _Frame(np.eye(3), np.zeros(3))}
        self.out: list[str] = []

    # ---------------------------------------------------------------- names
    def link_root(self, i: int) -> bool:
        """Webots' link roots: nodes with a name field (Solids, Solid devices) and joints' end points."""
        e = self.entries[i]
        if e.field == "endPoint":
            return True
        return e.field == "children" and e.pose is not None and (e.type == "Solid" or e.device is not None
                                                                 or e.name is not None)

    def name(self, i: int) -> str:
        if i == -1:
            return self.prefix + "base_link"
        if i not in self.names:
            e = self.entries[i]
            full = self.prefix + (e.name or e.def_name or e.type.lower())
            if full in self.names.values():
                full += f"_{self.clashes}"
                self.clashes += 1
            self.names[i] = full
        return self.names[i]

    def joint_name(self, i: int) -> str:
        devs = [self.entries[k] for k in self.children.get(i, []) if self.entries[k].field.startswith("device")]
        for kinds in (_MOTORS, ("PositionSensor",)):
            for d in devs:
                if d.type in kinds and d.device:
                    return self.prefix + d.device
        return self.name(i)

    def upper_root(self, i: int) -> int:
        p = self.entries[i].parent
        while p != -1 and not self.link_root(p):
            p = self.entries[p].parent
        return p

    def motor(self, i: int) -> wm.Motor | None:
        for k in self.children.get(i, []):
            e = self.entries[k]
            if e.field.startswith("device") and e.type in _MOTORS and e.device:
                d = self.devices.get(e.device)
                if isinstance(d, wm.Motor):
                    return d
        return None

    # ---------------------------------------------------------------- frames
    def pose(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        p = pose_from_model(self.entries[i].pose or wm.Pose())
        return p.rotation, p.translation

    def origin(self, parent: int, rotation: np.ndarray, at: np.ndarray) -> str:
        f = self.frames[parent]
        xyz = f.rotation.T @ (at - f.origin)
        return f'<origin xyz="{_vec(xyz)}" rpy="{_vec(_rpy(f.rotation.T @ rotation))}"/>'

    # ---------------------------------------------------------------- writing
    def queue_under(self, i: int, queue: list[int]) -> None:
        """The link roots and joints met under node i (not past them), appended in file order."""
        for k in self.children.get(i, []):
            e = self.entries[k]
            if e.field != "children":
                continue
            if e.type in _ANY_JOINT or self.link_root(k):
                queue.append(k)
            else:
                self.queue_under(k, queue)

    def write(self) -> str:
        queue: list[int] = []
        self.out.append(f"  <link name={quoteattr(self.name(-1))}>\n  </link>\n")
        self.queue_under(-1, queue)
        while queue:
            i = queue.pop()
            e = self.entries[i]
            if e.type in _JOINTS:
                end = next((k for k in self.children.get(i, []) if self.entries[k].field == "endPoint"), None)
                if end is not None:
                    self.joint(i, end)
                    queue.append(end)
            elif e.type in _ANY_JOINT:        # Hinge2/Ball: their end point fixed
                queue.extend(k for k in self.children.get(i, []) if self.entries[k].field == "endPoint")
            else:
                self.link(i, queue)
        return ('<?xml version="1.0"?>\n'
                f"<robot name={quoteattr(self.robot.name)}>\n" + "".join(self.out) + "</robot>\n")

    def link(self, i: int, queue: list[int]) -> None:
        e = self.entries[i]
        name = self.name(i)
        self.out.append(f"  <link name={quoteattr(name)}>\n  </link>\n")
        self.queue_under(i, queue)
        parent_joint = self.entries[e.parent] if e.parent >= 0 else None
        if e.field == "endPoint" and parent_joint is not None and parent_joint.type in _JOINTS:
            return                                # its joint was written, its frame set
        up = self.upper_root(i)
        rotation, at = self.pose(i)
        self.frames[i] = _Frame(rotation, at)
        upper = self.name(up)
        self.out.append(f"  <joint name={quoteattr(f'{upper}_{name}_joint')} type=\"fixed\">\n"
                        f"    <parent link={quoteattr(upper)}/>\n    <child link={quoteattr(name)}/>\n"
                        f"    {self.origin(up, rotation, at)}\n  </joint>\n")

    def joint(self, i: int, end: int) -> None:
        up = self.upper_root(i)
        rotation, at = self.pose(end)
        m = self.motor(i)
        node = self.entries[i]
        hinge = node.type == "HingeJoint"
        # the joint's own axis and anchor (a .wbt joint's, whatever its devices), else its motor's
        anchor = node.anchor if node.anchor is not None else m.anchor if m is not None else None
        if hinge and anchor is not None:
            at = np.asarray(anchor, dtype=np.float64)       # the child frame on the hinge's axis
        axis = np.asarray(node.axis if node.axis is not None else m.joint_axis if m is not None
                          else (1.0, 0.0, 0.0) if hinge else (0.0, 0.0, 1.0), dtype=np.float64)
        length = float(np.linalg.norm(axis))
        axis = rotation.T @ (axis / length if length > 0.0 else np.array([0.0, 0.0, 1.0]))  # Webots' reset of 0
        self.frames[end] = _Frame(rotation, at)
        limited = m is not None and (m.min_position != 0.0 or m.max_position != 0.0)
        kind = "prismatic" if not hinge else "revolute" if limited else "continuous"
        lines = [f"  <joint name={quoteattr(self.joint_name(i))} type=\"{kind}\">",
                 f"    <parent link={quoteattr(self.name(up))}/>",
                 f"    <child link={quoteattr(self.name(end))}/>",
                 f'    <axis xyz="{_vec(axis)}"/>']
        if m is not None:
            effort = m.max_torque if isinstance(m, wm.RotationalMotor) else getattr(m, "max_force", 0.0)
            bounds = f'lower="{_num(m.min_position)}" upper="{_num(m.max_position)}" ' if limited else ""
            lines.append(f'    <limit effort="{_num(effort)}" {bounds}velocity="{_num(m.max_velocity)}"/>')
        lines.append(f"    {self.origin(up, rotation, at)}")
        self.out.append("\n".join(lines) + "\n  </joint>\n")


def robot_urdf(robot: wm.Robot, entries: Sequence[wm.NestedNode], prefix: str = "") -> str:
    """The robot's URDF (see the module), ``prefix`` before every link and joint name as Webots puts it."""
    return _Export(robot, entries, prefix).write()
