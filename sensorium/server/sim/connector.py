"""The simulation's Connector and Brake (Webots' nodes; the presence rule is ``server/devices/connector.py``).

A Connector's presence is measured at its sampling period from the world poses of every other
connector of the world's robots (``peers``, handed over by the simulation once the robots are made).
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

__all__ = ["Brake", "Connector", "ConnectorWarning"]


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
        self.peers: list[Connector] = []          # every connector of the world (itself included)
        self._robot: Any = None
        self._me = (c.type, c.model, float(c.distance_tolerance), float(c.axis_tolerance),
                    int(c.number_of_rotations), float(c.rotation_tolerance))
        self._warned_link = False

    def bind(self, robot: Any) -> None:
        self._robot = robot

    def placed(self) -> tuple[np.ndarray, np.ndarray]:
        """Its world rotation and origin now."""
        pose = self.world_pose(self._robot.pose)
        return np.asarray(pose.rotation, dtype=np.float64), np.asarray(pose.translation, dtype=np.float64)

    def presence_now(self) -> int:
        """Webots' presence at the current poses (-1 passive, 1 a peer present, 0 none)."""
        if self.config.type == "passive":
            return -1
        rotation, origin = self.placed()
        others = []
        for p in self.peers:
            if p is not self:
                r, o = p.placed()
                others.append((p.config.type, p.config.model, r, o))
        return cmath.presence(self._me, rotation, origin, others)

    def measure(self, now_ms: int) -> None:
        self.value = self.presence_now()
        self._mark(now_ms)

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


class Brake(Device):
    """Webots Brake: its joint's type (``type_code``: 0 rotational, 1 linear, ``get_type``) and the
    motor and position sensor sharing the joint. It has no reading: nothing to publish."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.type_code = 1 if self.config.joint_type == "linear" else 0

    def describe(self) -> dict:
        c = self.config
        return {"joint_type": self.type_code, "motor": c.motor, "position_sensor": c.position_sensor}
