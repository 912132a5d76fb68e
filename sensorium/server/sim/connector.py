"""The simulation's Connector and Brake (Webots' nodes; the presence rule is ``server/devices/connector.py``).

A Connector's presence is measured at its sampling period from the world poses of every other
connector of the world: the robots' and those of the solids (``Solid.connectors``, a passive object
to dock with: :class:`SolidConnector`, which reads nothing), handed over by the simulation as ``peers``.
Its lock state (``is_locked``) is the server's: ``lock``/``unlock`` set it (a passive connector
cannot lock, as in Webots), a simulation reset restores the world file's. Nothing is ever joined:
without physics Webots itself makes no link ("none of their parent nodes have Physics nodes"), so
locking with a peer present, or an ``auto_lock`` connector meeting one while locked, gives that one
warning (once per connector) and the robots stay free; presence never stays 1 from a link.

A Brake only answers which joint it is on: its joint's type and the devices sharing the joint; its
damping constant is accepted by the clients and has no effect (no physics).
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from sensorium.server.devices import connector as cmath
from sensorium.server.sim.sensors import Device
from sensorium.server.world.geometry import Pose
from sensorium.server.world.poses import pose_from_model

__all__ = ["Brake", "Connector", "ConnectorWarning", "SolidConnector", "solid_connectors"]


class ConnectorWarning(UserWarning):
    """A connector locked with a peer present: nothing is joined here (no physics)."""


class Connector(Device):
    """Webots Connector: ``value`` is the latest presence (-1 before the first measurement and for
    a passive connector, else 1 or 0); ``is_locked`` its lock state."""

    kinematic = True

    def __post_init__(self) -> None:
        super().__post_init__()
        c = self.config
        self.value = -1
        self.is_locked = bool(c.is_locked)
        self.peers: list[Connector | SolidConnector] = []     # every connector of the world (itself included)
        self._robot: Any = None
        self._me = (c.type, c.model, float(c.distance_tolerance), float(c.axis_tolerance),
                    int(c.number_of_rotations), float(c.rotation_tolerance))
        self._warned_link = False

    def bind(self, robot: Any) -> None:
        self._robot = robot

    def placed(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Its world rotation and origin now."""
        pose = self.world_pose(self._robot.pose)
        return np.asarray(pose.rotation, dtype=np.float64), np.asarray(pose.translation, dtype=np.float64)

    def presence_now(self) -> int:
        """Webots' presence at the current poses (-1 passive, 1 a peer present, 0 none)."""
        if self.config.type == "passive":
            return -1
        me = self.placed()
        assert me is not None
        others = []
        for p in self.peers:
            if p is not self:
                at = p.placed()
                if at is not None:
                    others.append((p.config.type, p.config.model, at[0], at[1]))
        return cmath.presence(self._me, me[0], me[1], others)

    def measure(self, now_ms: int) -> None:
        self.value = self.presence_now()
        self._mark(now_ms)

    def readings(self) -> dict:
        return {"presence": int(self.value), "is_locked": self.is_locked}

    def step_reading(self) -> dict:
        return {"value": int(self.value)}

    def lock(self) -> bool:
        """Webots' ``lock``: the lock state on (a passive connector cannot lock: unchanged). With a
        peer present Webots would attach; here it warns that nothing is joined. The lock state."""
        if self.config.type == "passive":
            return False
        self.is_locked = True
        self.attach_attempt()
        return True

    def unlock(self) -> bool:
        """Webots' ``unlock``: the lock state off (a passive connector: unchanged). The lock state."""
        if self.config.type != "passive":
            self.is_locked = False
        return self.is_locked

    def attach_attempt(self) -> None:
        """Where Webots attaches to a present peer (``lock``; each step while ``auto_lock`` and
        locked): no physics here, so its one warning, once per connector."""
        if self._warned_link or self.presence_now() != 1:
            return
        self._warned_link = True
        warnings.warn(f"connector {self.path!r}: locked with a peer present, but nothing is joined: Sensorium has no "
                      "physics (as Webots without Physics nodes: the robots stay free)", ConnectorWarning, stacklevel=2)

    def reset(self) -> None:
        """A simulation reset: the lock state of the world file (WbConnector::reset)."""
        self.is_locked = bool(self.config.is_locked)

    def describe(self) -> dict:
        c = self.config
        return {"connector_type": c.type, "is_locked": self.is_locked, "auto_lock": bool(c.auto_lock),
                "distance_tolerance": float(c.distance_tolerance), "axis_tolerance": float(c.axis_tolerance),
                "rotation_tolerance": float(c.rotation_tolerance), "number_of_rotations": int(c.number_of_rotations)}


class SolidConnector:
    """A Connector on a solid (``Solid.connectors``): a peer the robots' connectors see, at its solid's
    pose now (a Supervisor may move the solid; a removed solid's connectors are gone). It reads nothing."""

    def __init__(self, config: Any, scene: Any, solid: str, local: Pose):
        self.config = config
        self._scene = scene
        self._solid = solid          # the top-level solid it rides on
        self._local = local          # its pose in that solid's frame (nested solids composed)

    def placed(self) -> tuple[np.ndarray, np.ndarray] | None:
        at = self._scene.solid_poses.get(self._solid)
        if at is None:
            return None
        pose = at.compose(self._local)
        return np.asarray(pose.rotation, dtype=np.float64), np.asarray(pose.translation, dtype=np.float64)


def solid_connectors(solids: list[Any], scene: Any) -> list[SolidConnector]:
    """The connectors of the world's solids and of their children, each with its pose in its
    top-level solid's frame."""
    out: list[SolidConnector] = []

    def walk(top: str, solid: Any, frame: Pose) -> None:
        for con in solid.connectors:
            out.append(SolidConnector(con, scene, top, frame.compose(pose_from_model(con.pose))))
        for child in solid.children:
            walk(top, child, frame.compose(pose_from_model(child.pose)))

    for s in solids:
        walk(s.name, s, Pose.identity())
    return out


class Brake(Device):
    """Webots Brake: its joint's type (``type_code``: 0 rotational, 1 linear, ``get_type``) and the
    motor and position sensor sharing the joint. It has no reading: nothing to publish."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.type_code = 1 if self.config.joint_type == "linear" else 0

    def readings(self) -> dict:
        """Nothing is measured: its joint's type (``get_type``), what a probe shows."""
        return {"type": self.type_code}

    def describe(self) -> dict:
        c = self.config
        return {"joint_type": self.type_code, "motor": c.motor, "position_sensor": c.position_sensor}
