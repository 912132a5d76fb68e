"""Webots' ``Supervisor``, ``Node`` and ``Field`` classes — the subset Sensorium serves: find
robots and solids by name, read and set their ``translation``/``rotation``, their world pose,
reset the simulation and change its mode. The robot's world entry needs ``supervisor: true``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from sensorium.client import nodes, wb

from .robot import Robot


class Field:
    SF_VEC3F = wb.WB_SF_VEC3F
    SF_ROTATION = wb.WB_SF_ROTATION

    def __init__(self, ref: tuple[int, str]):
        self._ref = ref

    def getName(self) -> str:
        return wb.wb_supervisor_field_get_name(self._ref)

    def getType(self) -> int:
        return wb.wb_supervisor_field_get_type(self._ref)

    def getTypeName(self) -> str:
        return "SFVec3f" if self._ref[1] == "translation" else "SFRotation"

    def getSFVec3f(self) -> list[float] | None:
        return wb.wb_supervisor_field_get_sf_vec3f(self._ref)

    def setSFVec3f(self, values: list[float]) -> None:
        wb.wb_supervisor_field_set_sf_vec3f(self._ref, values)

    def getSFRotation(self) -> list[float] | None:
        return wb.wb_supervisor_field_get_sf_rotation(self._ref)

    def setSFRotation(self, values: list[float]) -> None:
        wb.wb_supervisor_field_set_sf_rotation(self._ref, values)

    name = property(getName)
    type = property(getType)
    value = property(lambda self: self.getSFVec3f() if self._ref[1] == "translation" else self.getSFRotation())

    def __repr__(self) -> str:
        return f"Field({self._ref[1]!r} of node {self._ref[0]})"


class Node:
    def __init__(self, ref: int, type_name: str = "", name: str = ""):
        self._ref = ref
        self._type_name = type_name
        self._name = name

    def getId(self) -> int:
        return self._ref

    def getDef(self) -> str:
        return self._name

    def getTypeName(self) -> str:
        return self._type_name

    def getBaseTypeName(self) -> str:
        return self._type_name

    def getField(self, fieldName: str) -> Field | None:  # noqa: N803 - Webots' parameter name
        ref = wb.wb_supervisor_node_get_field(self._ref, fieldName)
        return None if ref is None else Field(ref)

    def getPosition(self) -> list[float] | None:
        return wb.wb_supervisor_node_get_position(self._ref)

    def getOrientation(self) -> list[float] | None:
        return wb.wb_supervisor_node_get_orientation(self._ref)

    # -- contact points: Sensorium has no physics contacts, so a node touches nothing (as in the C client)
    def getContactPoints(self, includeDescendants: bool = False) -> list[ContactPoint]:  # noqa: N803
        return []

    def enableContactPointsTracking(self, samplingPeriod: int, includeDescendants: bool = False) -> None:  # noqa: N803
        pass

    def disableContactPointsTracking(self, includeDescendants: bool = False) -> None:  # noqa: N803
        pass

    def getNumberOfContactPoints(self, includeDescendants: bool = False) -> int:  # noqa: N803
        return 0

    def getContactPoint(self, index: int) -> list[float]:
        return [math.nan] * 3

    def getContactPointNode(self, index: int) -> Node | None:
        return None

    id = property(getId)
    def_name = property(getDef)
    type_name = property(getTypeName)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Node) and other._ref == self._ref

    def __hash__(self) -> int:
        return hash(self._ref)

    def __repr__(self) -> str:
        return f"Node({self._type_name} {self._name!r}, id={self._ref})"


def _node(ref: dict | None) -> Node | None:
    if not ref or not ref.get("node"):
        return None
    return Node(int(ref["node"]), str(ref.get("type", "")), str(ref.get("name", "")))


# Webots' node types as Node class constants (Node.ROBOT, Node.GPS, ...)
for _name, _value in nodes.WEBOTS_NODE_TYPES.items():
    setattr(Node, _name[len("WB_NODE_"):], _value)


@dataclass
class ContactPoint:
    """Webots' contact point (``Node.getContactPoints``): Sensorium has no physics contacts, so no
    function returns one (``getContactPoints()`` is ``[]``); the class exists for ``from controller
    import ContactPoint``."""

    point: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    node_id: int = -1

    def getPoint(self) -> list[float]:
        return self.point

    def getNodeId(self) -> int:
        return self.node_id


class Supervisor(Robot):
    SIMULATION_MODE_PAUSE = wb.WB_SUPERVISOR_SIMULATION_MODE_PAUSE
    SIMULATION_MODE_REAL_TIME = wb.WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME
    SIMULATION_MODE_FAST = wb.WB_SUPERVISOR_SIMULATION_MODE_FAST

    def getFromDef(self, name: str) -> Node | None:
        return _node(self._lookup("get_from_def", {"name": name}, "wb_supervisor_node_get_from_def", name))

    def getSelf(self) -> Node | None:
        return _node(self._lookup("get_self", None, "wb_supervisor_node_get_self", "self"))

    @staticmethod
    def _lookup(item: str, args: dict | None, func: str, name: str) -> dict | None:
        """The node reference (with its type and name, which the flat API's int id lacks)."""
        r = wb.current()
        if not r.supervisor:
            getattr(wb, func)(*([name] if args else []))      # prints Webots' error, answers NULL
            return None
        if not isinstance(name, str) or not name:
            return None
        return r.conn.call(f"/{r.name}/robot/{item}", args)

    def simulationReset(self) -> None:
        wb.wb_supervisor_simulation_reset()

    def simulationSetMode(self, mode: int) -> None:
        wb.wb_supervisor_simulation_set_mode(mode)

    def simulationGetMode(self) -> int:
        return wb.wb_supervisor_simulation_get_mode()
