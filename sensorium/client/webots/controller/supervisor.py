"""Webots' ``Supervisor``, ``Node`` and ``Field`` classes — what Sensorium serves: the root and its
``children`` (robots, top-level solids and lights, WorldInfo, Viewpoint, ...), nodes by DEF, id or
name, their identity (type and PROTO name, DEF, parent), a PROTO instance's interface fields
(``getProto``, ``getParent``, ``getBaseNodeField``), fields (``translation``/``rotation`` read
and set, ``name``, ``model``, ``customData``, lights' ``on``/``intensity``/``color``/... read and
set, WorldInfo's, Viewpoint's and Background's values read), world poses and velocities; reset the
simulation and change its mode. The robot's world entry needs ``supervisor: true``.
``simulationQuit(status)`` ends the simulation for every controller (-1) and the server exits with
``status``, as Webots quits. Every other method of
Webots' classes is there too: it does nothing, prints one error line the first time and answers
Webots' "no value" (as the C library's functions)."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from sensorium.client import nodes, wb

from .robot import Robot
from .unsimulated import signed


class Field:
    SF_BOOL = wb.WB_SF_BOOL
    SF_INT32 = wb.WB_SF_INT32
    SF_FLOAT = wb.WB_SF_FLOAT
    SF_VEC2F = wb.WB_SF_VEC2F
    SF_VEC3F = wb.WB_SF_VEC3F
    SF_ROTATION = wb.WB_SF_ROTATION
    SF_COLOR = wb.WB_SF_COLOR
    SF_STRING = wb.WB_SF_STRING
    SF_NODE = wb.WB_SF_NODE
    MF_BOOL = 0x11              # Webots' WbFieldType values of the MF types Sensorium has no field of
    MF_INT32 = 0x12
    MF_FLOAT = 0x13
    MF_VEC2F = 0x14
    MF_VEC3F = 0x15
    MF_ROTATION = 0x16
    MF_COLOR = wb.WB_MF_COLOR
    MF_STRING = 0x18
    MF_NODE = wb.WB_MF_NODE

    def __init__(self, ref: tuple[int, str, int] | tuple[int, str, int, int]):
        self._ref = ref

    def getName(self) -> str:
        return wb.wb_supervisor_field_get_name(self._ref)

    def getType(self) -> int:
        return wb.wb_supervisor_field_get_type(self._ref)

    def getTypeName(self) -> str:
        return wb.wb_supervisor_field_get_type_name(self._ref)

    def getCount(self) -> int:
        return wb.wb_supervisor_field_get_count(self._ref)

    def getSFBool(self) -> bool:
        return wb.wb_supervisor_field_get_sf_bool(self._ref)

    def getSFInt32(self) -> int:
        return wb.wb_supervisor_field_get_sf_int32(self._ref)

    def getSFFloat(self) -> float:
        return wb.wb_supervisor_field_get_sf_float(self._ref)

    def getSFString(self) -> str:
        return wb.wb_supervisor_field_get_sf_string(self._ref)

    def getSFVec3f(self) -> list[float] | None:
        return wb.wb_supervisor_field_get_sf_vec3f(self._ref)

    def getSFRotation(self) -> list[float] | None:
        return wb.wb_supervisor_field_get_sf_rotation(self._ref)

    def getSFColor(self) -> list[float] | None:
        return wb.wb_supervisor_field_get_sf_color(self._ref)

    def getSFNode(self) -> Node | None:
        return _node_of(wb.wb_supervisor_field_get_sf_node(self._ref))

    def getMFNode(self, index: int) -> Node | None:
        return _node_of(wb.wb_supervisor_field_get_mf_node(self._ref, index))

    def getMFColor(self, index: int) -> list[float] | None:
        return wb.wb_supervisor_field_get_mf_color(self._ref, index)

    # a PROTO's interface fields have any VRML type
    def getSFVec2f(self) -> list[float] | None:
        return wb.wb_supervisor_field_get_sf_vec2f(self._ref)

    def getMFBool(self, index: int) -> bool:
        return wb.wb_supervisor_field_get_mf_bool(self._ref, index)

    def getMFInt32(self, index: int) -> int:
        return wb.wb_supervisor_field_get_mf_int32(self._ref, index)

    def getMFFloat(self, index: int) -> float:
        return wb.wb_supervisor_field_get_mf_float(self._ref, index)

    def getMFVec2f(self, index: int) -> list[float] | None:
        return wb.wb_supervisor_field_get_mf_vec2f(self._ref, index)

    def getMFVec3f(self, index: int) -> list[float] | None:
        return wb.wb_supervisor_field_get_mf_vec3f(self._ref, index)

    def getMFRotation(self, index: int) -> list[float] | None:
        return wb.wb_supervisor_field_get_mf_rotation(self._ref, index)

    def getMFString(self, index: int) -> str:
        return wb.wb_supervisor_field_get_mf_string(self._ref, index)

    def enableSFTracking(self, samplingPeriod: int) -> None:  # noqa: N803 - Webots' parameter name
        """Accepted: the getters ask the server at each call here (Webots streams tracked values)."""
        wb.wb_supervisor_field_enable_sf_tracking(self._ref, samplingPeriod)

    def disableSFTracking(self) -> None:
        wb.wb_supervisor_field_disable_sf_tracking(self._ref)

    def setSFBool(self, value: bool) -> None:
        wb.wb_supervisor_field_set_sf_bool(self._ref, value)

    def setSFFloat(self, value: float) -> None:
        wb.wb_supervisor_field_set_sf_float(self._ref, value)

    def setSFVec3f(self, value: list[float]) -> None:
        wb.wb_supervisor_field_set_sf_vec3f(self._ref, value)

    def setSFRotation(self, value: list[float]) -> None:
        wb.wb_supervisor_field_set_sf_rotation(self._ref, value)

    def setSFColor(self, value: list[float]) -> None:
        wb.wb_supervisor_field_set_sf_color(self._ref, value)

    # an imported line or point set's lists (README "Supervisor": the draw-trail pattern)
    def setMFInt32(self, index: int, value: int) -> None:
        wb.wb_supervisor_field_set_mf_int32(self._ref, index, value)

    def setMFVec3f(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_set_mf_vec3f(self._ref, index, value)

    def setMFColor(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_set_mf_color(self._ref, index, value)

    def insertMFInt32(self, index: int, value: int) -> None:
        wb.wb_supervisor_field_insert_mf_int32(self._ref, index, value)

    def insertMFVec3f(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_insert_mf_vec3f(self._ref, index, value)

    def insertMFColor(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_insert_mf_color(self._ref, index, value)

    def setMFBool(self, index: int, value: bool) -> None:
        wb.wb_supervisor_field_set_mf_bool(self._ref, index, value)

    def insertMFBool(self, index: int, value: bool) -> None:
        wb.wb_supervisor_field_insert_mf_bool(self._ref, index, value)

    def setMFFloat(self, index: int, value: float) -> None:
        wb.wb_supervisor_field_set_mf_float(self._ref, index, value)

    def insertMFFloat(self, index: int, value: float) -> None:
        wb.wb_supervisor_field_insert_mf_float(self._ref, index, value)

    def setMFVec2f(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_set_mf_vec2f(self._ref, index, value)

    def insertMFVec2f(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_insert_mf_vec2f(self._ref, index, value)

    def setMFRotation(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_set_mf_rotation(self._ref, index, value)

    def insertMFRotation(self, index: int, value: list[float]) -> None:
        wb.wb_supervisor_field_insert_mf_rotation(self._ref, index, value)

    def setMFString(self, index: int, value: str) -> None:
        wb.wb_supervisor_field_set_mf_string(self._ref, index, value)

    def insertMFString(self, index: int, value: str) -> None:
        wb.wb_supervisor_field_insert_mf_string(self._ref, index, value)

    def importSFNodeFromString(self, nodeString: str) -> None:  # noqa: N803 - Webots' name
        wb.wb_supervisor_field_import_sf_node_from_string(self._ref, nodeString)

    def setSFInt32(self, value: int) -> None:
        wb.wb_supervisor_field_set_sf_int32(self._ref, value)

    def setSFVec2f(self, value: list[float]) -> None:
        wb.wb_supervisor_field_set_sf_vec2f(self._ref, value)

    def setSFString(self, value: str) -> None:
        wb.wb_supervisor_field_set_sf_string(self._ref, value)

    def removeMF(self, index: int) -> None:
        wb.wb_supervisor_field_remove_mf(self._ref, index)

    def importMFNodeFromString(self, position: int, nodeString: str) -> None:  # noqa: N803 - Webots' name
        wb.wb_supervisor_field_import_mf_node_from_string(self._ref, position, nodeString)

    def removeSF(self) -> None:
        wb.wb_supervisor_field_remove_sf(self._ref)

    def getActualField(self) -> Field | None:
        ref = wb.wb_supervisor_field_get_actual_field(self._ref)
        return None if ref is None else Field(ref)

    _GETTERS = {wb.WB_SF_BOOL: getSFBool, wb.WB_SF_INT32: getSFInt32, wb.WB_SF_FLOAT: getSFFloat,
                wb.WB_SF_STRING: getSFString, wb.WB_SF_VEC2F: getSFVec2f,
                wb.WB_SF_VEC3F: getSFVec3f, wb.WB_SF_ROTATION: getSFRotation, wb.WB_SF_COLOR: getSFColor,
                wb.WB_SF_NODE: getSFNode}

    _MF_GETTERS = {wb.WB_MF_NODE: getMFNode, wb.WB_MF_COLOR: getMFColor, wb.WB_MF_BOOL: getMFBool,
                   wb.WB_MF_INT32: getMFInt32, wb.WB_MF_FLOAT: getMFFloat, wb.WB_MF_VEC2F: getMFVec2f,
                   wb.WB_MF_VEC3F: getMFVec3f, wb.WB_MF_ROTATION: getMFRotation, wb.WB_MF_STRING: getMFString}

    name = property(getName)
    type = property(getType)
    type_name = property(getTypeName)
    count = property(getCount)

    _SETTERS = {wb.WB_SF_BOOL: "setSFBool", wb.WB_SF_FLOAT: "setSFFloat", wb.WB_SF_STRING: "setSFString",
                wb.WB_SF_INT32: "setSFInt32", wb.WB_SF_VEC2F: "setSFVec2f", wb.WB_SF_VEC3F: "setSFVec3f", wb.WB_SF_ROTATION: "setSFRotation", wb.WB_SF_COLOR: "setSFColor"}

    @property
    def value(self) -> Any:
        """Webots' ``Field.value``: an SF field's value; an MF field's items as a list."""
        mf = Field._MF_GETTERS.get(self._ref[2])
        if mf is not None:
            return [mf(self, i) for i in range(self.getCount())]
        return Field._GETTERS[self._ref[2]](self)

    @value.setter
    def value(self, value: Any) -> None:
        """Webots' ``field.value = ...``: the setter of the field's type (``translation.value = [x, y, z]``);
        an MF field is not set this way (one error line, as in Webots)."""
        setter = Field._SETTERS.get(self._ref[2])
        if setter is None:
            print(f"Error: Field.value: the {self.getTypeName()} field {self.getName()!r} cannot be set as a whole.",
                  file=sys.stderr)
            return
        getattr(self, setter)(value)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Field) and other._ref == self._ref

    def __hash__(self) -> int:
        return hash(self._ref)

    def __repr__(self) -> str:
        return f"Field({self._ref[1]!r} of node {self._ref[0]})"



class Node:
    """A node of the scene tree Sensorium has: the root (id 0), a robot, a top-level solid or light, a
    node inside a robot or solid (a Solid, device, Pose, Group, joint).
    ``type_name`` and ``name`` are what it was when found (its ``repr``); the getters ask again."""

    def __init__(self, ref: int, type_name: str = "", name: str = ""):
        self._ref = ref
        self._type_name = type_name
        self._name = name

    # the identity readers ask the server, as Webots' Node class asks libController: a removed
    # node answers Webots' line and its "no value" ('', WB_NODE_NO_NODE, None, -1), not what it was
    def getId(self) -> int:
        return wb.wb_supervisor_node_get_id(self._ref)

    def getDef(self) -> str:
        return wb.wb_supervisor_node_get_def(self._ref)

    def getTypeName(self) -> str:
        return wb.wb_supervisor_node_get_type_name(self._ref)

    def getBaseTypeName(self) -> str:
        return wb.wb_supervisor_node_get_base_type_name(self._ref)

    def isProto(self) -> bool:
        return wb.wb_supervisor_node_is_proto(self._ref)

    def getType(self) -> int:
        return wb.wb_supervisor_node_get_type(self._ref)

    def getParentNode(self) -> Node | None:
        return _node_of(wb.wb_supervisor_node_get_parent_node(self._ref))

    def getField(self, fieldName: str) -> Field | None:  # noqa: N803 - Webots' parameter name
        """The field of that name: a PROTO instance's PROTO field (its interface), else the node's own."""
        ref = wb.wb_supervisor_node_get_field(self._ref, fieldName)
        return None if ref is None else Field(ref)

    def getBaseNodeField(self, fieldName: str) -> Field | None:  # noqa: N803
        """The base node's field (a PROTO instance's Robot, Solid, ...): read-only on a PROTO instance."""
        ref = wb.wb_supervisor_node_get_base_node_field(self._ref, fieldName)
        return None if ref is None else Field(ref)

    def getProto(self) -> Proto | None:
        """The node's PROTO (None for a base node)."""
        ref = wb.wb_supervisor_node_get_proto(self._ref)
        return None if ref is None else Proto(ref)

    def getNumberOfFields(self) -> int:
        """A PROTO instance's interface fields; a base node's fields served here (Webots' order)."""
        return wb.wb_supervisor_node_get_number_of_fields(self._ref)

    def getFieldByIndex(self, index: int) -> Field | None:
        ref = wb.wb_supervisor_node_get_field_by_index(self._ref, index)
        return None if ref is None else Field(ref)

    def getFromProtoDef(self, DEF: str) -> Node | None:  # noqa: N803 - Webots' name
        """The node of this PROTO instance's body with that DEF (Webots' scope), None if there is none."""
        return _node_of(wb.wb_supervisor_node_get_from_proto_def(self._ref, DEF))

    def getNumberOfBaseNodeFields(self) -> int:
        """The base node's fields served here (a PROTO instance's Robot, Solid, ...), in Webots' order."""
        return wb.wb_supervisor_node_get_number_of_base_node_fields(self._ref)

    def getBaseNodeFieldByIndex(self, index: int) -> Field | None:
        ref = wb.wb_supervisor_node_get_base_node_field_by_index(self._ref, index)
        return None if ref is None else Field(ref)

    def getPosition(self) -> list[float]:
        return wb.wb_supervisor_node_get_position(self._ref)

    def getOrientation(self) -> list[float]:
        return wb.wb_supervisor_node_get_orientation(self._ref)

    def getPose(self, fromNode: Node | None = None) -> list[float]:  # noqa: N803 - Webots' parameter name
        """Webots' 4×4 row-major transform of this node in ``fromNode``'s frame (the world's by default)."""
        return wb.wb_supervisor_node_get_pose(self._ref, None if fromNode is None else fromNode._ref)

    def enablePoseTracking(self, samplingPeriod: int, fromNode: Node | None = None) -> None:  # noqa: N803
        """Accepted: :meth:`getPose` asks the server at each call here (Webots streams tracked poses)."""
        wb.wb_supervisor_node_enable_pose_tracking(self._ref, samplingPeriod,
                                                   None if fromNode is None else fromNode._ref)

    def disablePoseTracking(self, fromNode: Node | None = None) -> None:  # noqa: N803
        wb.wb_supervisor_node_disable_pose_tracking(self._ref, None if fromNode is None else fromNode._ref)

    def getVelocity(self) -> list[float]:
        return wb.wb_supervisor_node_get_velocity(self._ref)

    def getCenterOfMass(self) -> list[float]:
        return wb.wb_supervisor_node_get_center_of_mass(self._ref)

    def getStaticBalance(self) -> bool:
        return wb.wb_supervisor_node_get_static_balance(self._ref)

    def setVelocity(self, velocity: list[float]) -> None:
        wb.wb_supervisor_node_set_velocity(self._ref, velocity)

    def resetPhysics(self) -> None:
        wb.wb_supervisor_node_reset_physics(self._ref)

    def exportString(self) -> str:
        return wb.wb_supervisor_node_export_string(self._ref)

    def remove(self) -> None:
        wb.wb_supervisor_node_remove(self._ref)

    def restartController(self) -> None:
        wb.wb_supervisor_node_restart_controller(self._ref)

    def moveViewpoint(self) -> None:
        wb.wb_supervisor_node_move_viewpoint(self._ref)

    def setVisibility(self, fromNode: Node | None, visible: bool) -> None:  # noqa: N803 - Webots' parameter name
        wb.wb_supervisor_node_set_visibility(self._ref, None if fromNode is None else fromNode._ref, visible)

    def setJointPosition(self, position: float, index: int = 1) -> None:
        """Webots' ``setJointPosition``: the joint (this node) at ``position`` on its axis ``index`` at
        once, its motor targeting it (README "Supervisor": resets)."""
        wb.wb_supervisor_node_set_joint_position(self._ref, position, index)

    def saveState(self, stateName: str) -> None:  # noqa: N803
        """Keep this node's state (pose, joints' positions) under ``stateName``."""
        wb.wb_supervisor_node_save_state(self._ref, stateName)

    def loadState(self, stateName: str) -> None:  # noqa: N803
        """Put back the state saved under ``stateName`` (``"__init__"``: as the world loaded)."""
        wb.wb_supervisor_node_load_state(self._ref, stateName)

    # -- contact points: where its bounding shapes touch the ground now (README "Supervisor")
    def getContactPoints(self, includeDescendants: bool = False) -> list[ContactPoint]:  # noqa: N803
        return [ContactPoint(point, node) for point, node in wb.wb_supervisor_node_get_contact_points(self._ref, includeDescendants)]

    def enableContactPointsTracking(self, samplingPeriod: int, includeDescendants: bool = False) -> None:  # noqa: N803
        wb.wb_supervisor_node_enable_contact_points_tracking(self._ref, samplingPeriod, includeDescendants)

    def disableContactPointsTracking(self, includeDescendants: bool = False) -> None:  # noqa: N803
        wb.wb_supervisor_node_disable_contact_points_tracking(self._ref)

    def getNumberOfContactPoints(self, includeDescendants: bool = False) -> int:  # noqa: N803
        return wb.wb_supervisor_node_get_number_of_contact_points(self._ref, includeDescendants)

    def getContactPoint(self, index: int) -> list[float]:
        return wb.wb_supervisor_node_get_contact_point(self._ref, index)

    def getContactPointNode(self, index: int) -> Node | None:
        return _node_of(wb.wb_supervisor_node_get_contact_point_node(self._ref, index))

    id = property(getId)
    DEF = property(getDef)
    def_name = DEF
    type = property(getType)
    type_name = property(getTypeName)
    base_type_name = property(getBaseTypeName)
    # Webots' number_of_fields and number_of_base_node_fields: see the end of this file

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Node) and other._ref == self._ref

    def __hash__(self) -> int:
        return hash(self._ref)

    def __repr__(self) -> str:
        return f"Node({self._type_name} {self._name!r}, id={self._ref})"


def _node(ref: dict | None) -> Node | None:
    if not ref or not ref.get("type"):
        return None
    return Node(int(ref["node"]), str(ref["type"]), str(ref.get("name", "")))


def _node_of(node: int | None) -> Node | None:
    """The Node object of a node id (its type, name, DEF and parent from the server)."""
    if node is None:
        return None
    return _node(wb.node_info(node, "wb_supervisor_node_get_from_id"))


# Webots' node types as Node class constants (Node.ROBOT, Node.GPS, ...)
for _name, _value in nodes.WEBOTS_NODE_TYPES.items():
    setattr(Node, _name[len("WB_NODE_"):], _value)


@dataclass
class ContactPoint:
    """Webots' contact point (``Node.getContactPoints``): ``point`` in world coordinates (m) and the id of
    the Solid touching there, ``node_id``."""

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

    def getRoot(self) -> Node | None:
        return _node_of(wb.wb_supervisor_node_get_root())

    def getFromDef(self, d: str) -> Node | None:
        d = wb.c_string(d)
        return _node(self._lookup("get_from_def", {"name": d}, "wb_supervisor_node_get_from_def", d))

    def getSelf(self) -> Node | None:
        return _node(self._lookup("get_self", None, "wb_supervisor_node_get_self", "self"))

    def getFromId(self, id: int) -> Node | None:  # noqa: A002 - Webots' parameter name
        return _node_of(wb.wb_supervisor_node_get_from_id(id))

    def getFromDevice(self, tag: Any) -> Node | None:
        """The node of one of this robot's devices (a Device object, as Webots takes, or its tag)."""
        tag = tag.getTag() if hasattr(tag, "getTag") else tag
        return _node_of(wb.wb_supervisor_node_get_from_device(tag))

    @staticmethod
    def _lookup(item: str, args: dict | None, func: str, name: str) -> dict | None:
        """The node reference (with its type, name, DEF and parent, which the flat API's int id lacks)."""
        r = wb.current()
        if not r.supervisor:
            getattr(wb, func)(*([name] if args else []))      # prints Webots' error, answers NULL
            return None
        if not isinstance(name, str) or not name:
            return None
        return r.conn.call(f"/{r.name}/robot/{item}", args)

    def setLabel(self, id: int, label: str, x: float, y: float, size: float, color: int,
                 transparency: float = 0.0, font: str = "Arial") -> None:
        wb.wb_supervisor_set_label(id, label, x, y, size, color, transparency, font)

    def exportImage(self, filename: str, quality: int) -> None:
        wb.wb_supervisor_export_image(filename, quality)

    def movieStartRecording(self, filename: str, width: int, height: int, codec: int, quality: int,
                            acceleration: int, caption: bool) -> None:
        wb.wb_supervisor_movie_start_recording(filename, width, height, codec, quality, acceleration, caption)

    def movieStopRecording(self) -> None:
        wb.wb_supervisor_movie_stop_recording()

    def movieIsReady(self) -> bool:
        return wb.wb_supervisor_movie_is_ready()

    def movieFailed(self) -> bool:
        return wb.wb_supervisor_movie_failed()

    def simulationReset(self) -> None:
        wb.wb_supervisor_simulation_reset()

    def simulationResetPhysics(self) -> None:
        wb.wb_supervisor_simulation_reset_physics()

    def simulationSetMode(self, mode: int) -> None:
        wb.wb_supervisor_simulation_set_mode(mode)

    def simulationGetMode(self) -> int:
        return wb.wb_supervisor_simulation_get_mode()

    def worldSave(self, filename: str | None = None) -> bool:
        return wb.wb_supervisor_world_save(filename)

    def worldReload(self) -> None:
        wb.wb_supervisor_world_reload()

    def worldLoad(self, filename: str) -> None:
        wb.wb_supervisor_world_load(filename)

    simulation_mode = property(simulationGetMode, simulationSetMode)

    def simulationQuit(self, status: int) -> None:
        wb.wb_supervisor_simulation_quit(status)


class Proto:
    """Webots' PROTO of a node (``Node.getProto``): its name, its interface fields (the instance's values,
    or the PROTO's defaults), the PROTO it is built on (``getParent``)."""

    def __init__(self, ref: tuple[int, int] = (0, 0)):
        self._ref = ref

    def getTypeName(self) -> str:
        return wb.wb_supervisor_proto_get_type_name(self._ref)

    def isDerived(self) -> bool:
        return wb.wb_supervisor_proto_is_derived(self._ref)

    def getParent(self) -> Proto | None:
        ref = wb.wb_supervisor_proto_get_parent(self._ref)
        return None if ref is None else Proto(ref)

    def getField(self, name: str) -> Field | None:
        ref = wb.wb_supervisor_proto_get_field(self._ref, name)
        return None if ref is None else Field(ref)

    def getFieldByIndex(self, index: int) -> Field | None:
        ref = wb.wb_supervisor_proto_get_field_by_index(self._ref, index)
        return None if ref is None else Field(ref)

    def getNumberOfFields(self) -> int:
        return wb.wb_supervisor_proto_get_number_of_fields(self._ref)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Proto) and other._ref == self._ref

    def __hash__(self) -> int:
        return hash(self._ref)

    def __repr__(self) -> str:
        return f"Proto(level {self._ref[1]} of node {self._ref[0]})"


def _unserved(method: str, func: str, value: Any, params: str) -> Callable[..., Any]:
    def call(self: object, *args: Any) -> Any:
        wb.supervisor_unserved(func)
        return list(value) if isinstance(value, list) else value

    call.__name__ = call.__qualname__ = method
    call.__doc__ = f"Not served by Sensorium: one error line, Webots' \"no value\" ({value!r})."
    return signed(call, params)


_NAN = math.nan
# Webots' methods beyond the subset: Python name -> (the C function it stands for, its "no value", Webots' parameters)
_UNSERVED: dict[type, dict[str, tuple[str, Any, str]]] = {
    Supervisor: {
        "getSelected": ("node_get_selected", None, ""),
        "animationStartRecording": ("animation_start_recording", False, "filename"),
        "animationStopRecording": ("animation_stop_recording", False, ""),
        "virtualRealityHeadsetIsUsed": ("virtual_reality_headset_is_used", False, ""),
        "virtualRealityHeadsetGetPosition": ("virtual_reality_headset_get_position", [_NAN] * 3, ""),
        "virtualRealityHeadsetGetOrientation": ("virtual_reality_headset_get_orientation", [_NAN] * 9, "")},
    Node: {
        "addForce": ("node_add_force", None, "force, relative"),
        "addForceWithOffset": ("node_add_force_with_offset", None, "force, offset, relative"),
        "addTorque": ("node_add_torque", None, "torque, relative")},
}
for _cls, _methods in _UNSERVED.items():
    for _method, (_func, _value, _params) in _methods.items():
        assert not hasattr(_cls, _method), _method        # never hides a served method
        setattr(_cls, _method, _unserved(_method, "wb_supervisor_" + _func, _value, _params))
Node.number_of_fields = property(lambda self: self.getNumberOfFields())                     # type: ignore[attr-defined]
Node.number_of_base_node_fields = property(lambda self: self.getNumberOfBaseNodeFields())   # type: ignore[attr-defined]
Proto.type_name = property(lambda self: self.getTypeName())                # type: ignore[attr-defined]
Proto.number_of_fields = property(lambda self: self.getNumberOfFields())   # type: ignore[attr-defined]
Proto.is_derived = property(lambda self: self.isDerived())                 # type: ignore[attr-defined]
