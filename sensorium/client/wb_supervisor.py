"""Webots' Supervisor as ``wb_supervisor_*`` functions (PROTOCOL.md, Supervisor services).

Only a controller of a robot whose world entry has ``supervisor: true`` may call them; any other
prints Webots' error and gets the null answer (the server refuses too). Nodes are the world's root
(Webots' root Group, id 0), robots, top-level solids and top-level lights, and the nodes inside robots
and solids (Solids, devices, Poses, Groups, joints), found by DEF name (a dotted path ``A.B``; else a
top-level node's name), by id, by device or through ``children``; a node is its ``int`` id, ``None``
is Webots' NULL.
A field is a ``(node, name, type)`` tuple (``WB_SF_*``/``WB_MF_NODE``). Every call is one round trip,
answered at once; setters take effect before the next measurement.
"""

from __future__ import annotations

import itertools
import math
import reprlib
import sys
from collections.abc import Sized
from typing import Any

from sensorium.client import nodes
from sensorium.client.connection import ErrorCode, SensoriumError
from sensorium.client.wb_robot import RobotClient, c_string, current

WB_SUPERVISOR_SIMULATION_MODE_PAUSE = 0
WB_SUPERVISOR_SIMULATION_MODE_REAL_TIME = 1
WB_SUPERVISOR_SIMULATION_MODE_FAST = 2

WB_NO_FIELD = 0
WB_SF_BOOL = 1
WB_SF_INT32 = 2
WB_SF_FLOAT = 3
WB_SF_VEC2F = 4
WB_SF_VEC3F = 5
WB_SF_ROTATION = 6
WB_SF_COLOR = 7
WB_SF_STRING = 8
WB_SF_NODE = 9
WB_MF = 0x10
WB_MF_BOOL = 0x11
WB_MF_INT32 = 0x12
WB_MF_FLOAT = 0x13
WB_MF_VEC2F = 0x14
WB_MF_VEC3F = 0x15
WB_MF_ROTATION = 0x16
WB_MF_COLOR = 0x17
WB_MF_STRING = 0x18
WB_MF_NODE = 0x19

FIELD_TYPES = {"SFBool": WB_SF_BOOL, "SFInt32": WB_SF_INT32, "SFFloat": WB_SF_FLOAT, "SFVec2f": WB_SF_VEC2F,
               "SFVec3f": WB_SF_VEC3F, "SFRotation": WB_SF_ROTATION, "SFColor": WB_SF_COLOR,
               "SFString": WB_SF_STRING, "SFNode": WB_SF_NODE, "MFBool": WB_MF_BOOL, "MFInt32": WB_MF_INT32,
               "MFFloat": WB_MF_FLOAT, "MFVec2f": WB_MF_VEC2F, "MFVec3f": WB_MF_VEC3F, "MFRotation": WB_MF_ROTATION,
               "MFColor": WB_MF_COLOR, "MFString": WB_MF_STRING, "MFNode": WB_MF_NODE}
_TYPE_NAMES = {v: k for k, v in FIELD_TYPES.items()}
# Webots' node type constants by type name (any other type, a device's, a Pose's, a HingeJoint's:
# nodes.node_type, which spells the constant from the name; Hinge2Joint's and PBRAppearance's do not spell it)
NODE_TYPES = {"Group": "WB_NODE_GROUP", "Robot": "WB_NODE_ROBOT", "Solid": "WB_NODE_SOLID",
              "PointLight": "WB_NODE_POINT_LIGHT", "SpotLight": "WB_NODE_SPOT_LIGHT",
              "DirectionalLight": "WB_NODE_DIRECTIONAL_LIGHT", "Hinge2Joint": "WB_NODE_HINGE_2_JOINT",
              "PBRAppearance": "WB_NODE_PBR_APPEARANCE"}

Field = tuple[int, str, int] | tuple[int, str, int, int]
"""(node, name, type) — and, for a PROTO's field, the PROTO level: 0 the base node's (getBaseNodeField), k the
k-th PROTO of the node's chain (1 its own: getProto().getField; a PROTO node's getField is level 1 too)."""
Proto = tuple[int, int]
"""Webots' WbProtoRef here: (node, level), level 1 the node's own PROTO, 2 the one it is built on, ..."""
_NAN3 = [math.nan] * 3


def _supervisor(func: str) -> RobotClient | None:
    r = current()
    if not r.supervisor:
        print(f"Error: ignoring illegal call to {func}() in a 'Robot' controller.\n"
              f"Error: this function can only be used in a 'Supervisor' controller "
              f"(set 'supervisor: true' on robot {r.name!r} in the world file).", file=sys.stderr)
        return None
    return r


def _call(r: RobotClient, item: str, args: dict | None = None) -> dict:
    return r.conn.call(f"/{r.name}/robot/{item}", args)


def _answer(r: RobotClient, item: str, args: dict | None, func: str) -> dict | None:
    """The server's answer, or None after its line when it refuses the request (a removed node, a
    light's value out of its range, a zero rotation axis): Webots prints and answers its "no value"
    there, it does not stop the controller."""
    try:
        return _call(r, item, args)
    except SensoriumError as err:
        if err.code != ErrorCode.INVALID_ARGUMENT:
            raise
        print(f"Error: {func}(): {err.message}.", file=sys.stderr)
        return None


def _node_id(reply: dict) -> int | None:
    """A NodeResult's node id, None for Webots' NULL (type '')."""
    return int(reply["node"]) if reply.get("type") else None


def _checked_node(node: Any, func: str) -> RobotClient | None:
    """The robot client when the caller is a supervisor and ``node`` a node id; Webots' line otherwise."""
    r = _supervisor(func)
    if r is None:
        return None
    if node is None or isinstance(node, bool) or not isinstance(node, int) or not 0 <= node < 1 << 31:   # (ids: int32)
        print(f"Error: {func}() called with a NULL or invalid 'node' argument.", file=sys.stderr)
        return None
    return r


# ---------------------------------------------------------------------- nodes

def node_info(node: Any, func: str) -> dict | None:
    """The server's description of a node (get_from_id): type, name, DEF, parent; None if there is none."""
    r = _checked_node(node, func)
    if r is None:
        return None
    info = _call(r, "get_from_id", {"id": int(node)})
    return info if info.get("type") else None


def _live_node_info(node: Any, func: str) -> dict | None:
    """:func:`node_info` for the functions that read a node's identity: a node the server no longer
    has (removed by ``remove()``, here or by another supervisor) gets Webots' line and None, as
    libController answers for a node reference it dropped from its list."""
    r = _checked_node(node, func)
    if r is None:
        return None
    info = _call(r, "get_from_id", {"id": int(node)})
    if not info.get("type"):
        print(f"Error: {func}() called with a NULL or invalid 'node' argument.", file=sys.stderr)
        return None
    return info


def wb_supervisor_node_get_root() -> int | None:
    """The root node (Webots' root Group, id 0): its ``children`` are the top-level nodes."""
    r = _supervisor("wb_supervisor_node_get_root")
    return None if r is None else _node_id(_call(r, "get_root"))


def wb_supervisor_node_get_from_def(name: str) -> int | None:
    """The node (robot, solid or light) of that DEF name (else name), None if there is none."""
    name = c_string(name)
    r = _supervisor("wb_supervisor_node_get_from_def")
    if r is None:
        return None
    if not isinstance(name, str) or not name:
        print("Error: wb_supervisor_node_get_from_def() called with a NULL or empty 'def' argument.", file=sys.stderr)
        return None
    return _node_id(_call(r, "get_from_def", {"name": name}))


def wb_supervisor_node_get_from_device(tag: int) -> int | None:
    """The node of this robot's device ``tag`` (Webots' getFromDevice): its world pose, parent and
    fields as any node inside the robot; None (with Webots' line) for a tag that is no device."""
    func = "wb_supervisor_node_get_from_device"
    r = _supervisor(func)
    if r is None:
        return None
    dev = next((d for d in r.devices if d.tag == tag), None) if isinstance(tag, int) else None
    if dev is None:
        print(f"Error: {func}() called with an invalid 'tag' argument.", file=sys.stderr)
        return None
    return _node_id(_call(r, "get_from_device", {"device": dev.name}))


def wb_supervisor_node_get_self() -> int | None:
    r = _supervisor("wb_supervisor_node_get_self")
    return None if r is None else _node_id(_call(r, "get_self"))


def wb_supervisor_node_get_from_id(id: int) -> int | None:  # noqa: A002 - Webots' parameter name
    r = _supervisor("wb_supervisor_node_get_from_id")
    if r is None:
        return None
    if isinstance(id, bool) or not isinstance(id, int) or id < 0:
        print("Error: wb_supervisor_node_get_from_id() called with a negative 'id' argument.", file=sys.stderr)
        return None
    if id >= 1 << 31:
        return None
    return _node_id(_call(r, "get_from_id", {"id": id}))


def wb_supervisor_node_get_id(node: int | None) -> int:
    return -1 if _live_node_info(node, "wb_supervisor_node_get_id") is None else int(node)  # type: ignore[arg-type]


def wb_supervisor_node_get_type_name(node: int | None) -> str:
    """Webots' type name: a PROTO instance's PROTO name ("MiniPuck"), else the node's type ("Solid")."""
    info = _live_node_info(node, "wb_supervisor_node_get_type_name")
    return "" if info is None else str(info.get("proto") or info["type"])


def wb_supervisor_node_get_base_type_name(node: int | None) -> str:
    """The base node type (Robot, Solid, PointLight, Background, ...), a PROTO instance's too."""
    info = _live_node_info(node, "wb_supervisor_node_get_base_type_name")
    return "" if info is None else str(info["type"])


def wb_supervisor_node_is_proto(node: int | None) -> bool:
    """Whether the node is a PROTO instance (the world file writes it with a PROTO's name)."""
    info = _live_node_info(node, "wb_supervisor_node_is_proto")
    return info is not None and bool(info.get("proto"))


def wb_supervisor_node_get_type(node: int | None) -> int:
    info = _live_node_info(node, "wb_supervisor_node_get_type")
    if info is None:
        return nodes.WEBOTS_NODE_TYPES["WB_NODE_NO_NODE"]
    name = NODE_TYPES.get(info["type"])     # else a top-level node not simulated: WorldInfo, Viewpoint, ...
    return nodes.WEBOTS_NODE_TYPES[name] if name is not None else nodes.node_type(str(info["type"]))


def wb_supervisor_node_get_def(node: int | None) -> str:
    info = _live_node_info(node, "wb_supervisor_node_get_def")
    return "" if info is None else str(info["def_name"])


def wb_supervisor_node_get_parent_node(node: int | None) -> int | None:
    """The root for a top-level node, the node holding a nested one (a robot, a solid, a Pose, a
    joint for its end point and devices); None for the root."""
    info = _live_node_info(node, "wb_supervisor_node_get_parent_node")
    if info is None or int(info["parent"]) < 0:
        return None
    return int(info["parent"])


def _node_pose(node: int | None, func: str) -> dict | None:
    r = _checked_node(node, func)
    return None if r is None else _answer(r, "get_node_pose", {"node": int(node)}, func)  # type: ignore[arg-type]


def wb_supervisor_node_get_position(node: int | None) -> list[float]:
    """World position (m) of the node's origin; NaN for a node that has none (the root, a light)."""
    p = _node_pose(node, "wb_supervisor_node_get_position")
    return list(_NAN3) if p is None else [float(v) for v in p["position"]]


def wb_supervisor_node_get_orientation(node: int | None) -> list[float]:
    """World rotation matrix of the node, 9 numbers row-major (Webots)."""
    p = _node_pose(node, "wb_supervisor_node_get_orientation")
    return [math.nan] * 9 if p is None else [float(v) for v in p["orientation"]]


def _pose_matrix(p: dict) -> list[float] | None:
    """A get_node_pose answer as Webots' 4×4 row-major transform; None for a node with no pose."""
    t, r = [float(v) for v in p["position"]], [float(v) for v in p["orientation"]]
    if any(math.isnan(v) for v in t + r):
        return None
    return [*r[0:3], t[0], *r[3:6], t[1], *r[6:9], t[2], 0.0, 0.0, 0.0, 1.0]


def wb_supervisor_node_get_pose(node: int | None, from_node: int | None = None) -> list[float]:
    """Webots' 4×4 transform of ``node`` (16 numbers, row-major: rotation and translation, then
    0 0 0 1) in the frame of ``from_node``: the world's for None and, as Webots' server answers a
    "from" node that is no Pose, for the root or a light. NaN for a node with no pose (the root, a
    light), as its position; Webots' line and NaN for a NULL, invalid or removed node."""
    func = "wb_supervisor_node_get_pose"
    nan16 = [math.nan] * 16
    if _supervisor(func) is None:
        return nan16
    if from_node is not None and (isinstance(from_node, bool) or not isinstance(from_node, int) or from_node < 0):
        print(f"Error: {func}() called with a NULL or invalid 'from_node' argument.", file=sys.stderr)
        return nan16
    base = None
    if from_node is not None:
        got = _node_pose(from_node, func)
        if got is None:
            return nan16
        base = _pose_matrix(got)
    to = _node_pose(node, func)
    m = None if to is None else _pose_matrix(to)
    if m is None:
        return nan16
    if base is None:
        return m
    # inverse(base) · m: the rotation Rbᵀ·R, the translation Rbᵀ·(t − tb)
    rb = [base[0:3], base[4:7], base[8:11]]
    tb = [base[3], base[7], base[11]]
    rm = [m[0:3], m[4:7], m[8:11]]
    d = [m[3] - tb[0], m[7] - tb[1], m[11] - tb[2]]
    out: list[float] = []
    for i in range(3):
        out += [sum(rb[k][i] * rm[k][j] for k in range(3)) for j in range(3)]
        out.append(sum(rb[k][i] * d[k] for k in range(3)))
    return out + [0.0, 0.0, 0.0, 1.0]


def wb_supervisor_node_enable_pose_tracking(node: int | None, sampling_period: int,
                                            from_node: int | None = None) -> None:
    """Webots streams a tracked pose every sampling period; :func:`wb_supervisor_node_get_pose` asks
    the server at each call here, so tracking changes nothing: accepted after Webots' checks."""
    func = "wb_supervisor_node_enable_pose_tracking"
    if sampling_period < 0:
        print(f"Error: {func}() called with negative sampling period.", file=sys.stderr)
        return
    _checked_node(node, func)


def wb_supervisor_node_disable_pose_tracking(node: int | None, from_node: int | None = None) -> None:
    _checked_node(node, "wb_supervisor_node_disable_pose_tracking")


def wb_supervisor_node_get_velocity(node: int | None) -> list[float]:
    """Linear (m/s) then angular (rad/s) velocity in world axes: a driven robot's from its last step,
    zeros for anything else (nothing else moves by itself here)."""
    func = "wb_supervisor_node_get_velocity"
    r = _checked_node(node, func)
    got = None if r is None else _answer(r, "get_node_velocity", {"node": int(node)}, func)  # type: ignore[arg-type]
    return [math.nan] * 6 if got is None else [float(v) for v in got["value"]]


def wb_supervisor_node_get_center_of_mass(node: int | None) -> list[float]:
    """The centre of mass in world coordinates of a robot, solid or device with the Solids inside it that
    have a Physics node (masses from the world file, poses now); 0 0 0 for one without Physics, NaN for a
    node that is no Solid (Webots)."""
    func = "wb_supervisor_node_get_center_of_mass"
    r = _checked_node(node, func)
    got = None if r is None else _answer(r, "get_node_center_of_mass", {"node": int(node)}, func)  # type: ignore[arg-type]
    return [math.nan] * 3 if got is None else [float(v) for v in got["value"]]


def wb_supervisor_node_get_static_balance(node: int | None) -> bool:
    """Whether a top-level solid's or robot's centre of mass, seen from above, is over the support polygon
    of where its bounding shapes touch the ground now (README "Supervisor"); false without physics or
    touching nothing, and after the server's line for a node that is no top-level Solid (Webots)."""
    func = "wb_supervisor_node_get_static_balance"
    r = _checked_node(node, func)
    got = None if r is None else _answer(r, "get_node_static_balance", {"node": int(node)}, func)  # type: ignore[arg-type]
    return False if got is None else bool(got["value"])


_contact_descendants: dict[int, bool] = {}       # node -> include_descendants of its last number query
_contact_steps: dict[tuple[int, bool], tuple[int, dict]] = {}   # (node, descendants) -> (time ms, answer)
_deprecation_warned: set[str] = set()


def _contacts(r: RobotClient, node: int, descendants: bool, func: str) -> dict | None:
    """The server's contact points of ``node``, asked at its first query in a step: as Webots' library,
    the step's later queries answer that one's."""
    key = (node, descendants)
    kept = _contact_steps.get(key)
    if kept is not None and kept[0] == r.time_ms:
        return kept[1]
    got = _answer(r, "get_node_contact_points", {"node": node, "include_descendants": descendants}, func)
    if got is not None:
        _contact_steps[key] = (r.time_ms, got)
    return got


def wb_supervisor_node_get_contact_points(node: int | None, include_descendants: bool = False) -> list[tuple[list[float], int]]:
    """Where a top-level solid's or robot's bounding shapes (with ``include_descendants``, those of the
    solids inside it too) touch the ground now (README "Supervisor"): each point in world coordinates
    with the id of the Solid touching there; none without physics or touching nothing, and after the
    server's line for a node that is no top-level Solid."""
    func = "wb_supervisor_node_get_contact_points"
    r = _checked_node(node, func)
    got = None if r is None else _contacts(r, int(node), bool(include_descendants), func)  # type: ignore[arg-type]
    if got is None:
        return []
    flat = [float(v) for v in got["points"]]
    return [(flat[3 * k:3 * k + 3], int(n)) for k, n in enumerate(got["nodes"])]


def _deprecated(func: str) -> None:
    if func not in _deprecation_warned:          # Webots' line, once per function
        _deprecation_warned.add(func)
        print(f"Warning: {func}() is deprecated, use wb_supervisor_node_get_contact_points() instead.", file=sys.stderr)


def wb_supervisor_node_get_number_of_contact_points(node: int | None, include_descendants: bool = False) -> int:
    """Webots' deprecated count of :func:`wb_supervisor_node_get_contact_points`; -1 for a node that is
    no top-level Solid. ``get_contact_point`` and ``get_contact_point_node`` then take the same
    ``include_descendants``."""
    func = "wb_supervisor_node_get_number_of_contact_points"
    _deprecated(func)
    r = _checked_node(node, func)
    if r is None:
        return -1
    _contact_descendants[int(node)] = bool(include_descendants)  # type: ignore[arg-type]
    got = _contacts(r, int(node), bool(include_descendants), func)  # type: ignore[arg-type]
    return -1 if got is None else len(got["nodes"])


def _contact_point(node: int | None, index: int, func: str) -> tuple[list[float], int] | None:
    _deprecated(func)
    r = _checked_node(node, func)
    if r is None:
        return None
    got = _contacts(r, int(node), _contact_descendants.get(int(node), False), func)  # type: ignore[arg-type]
    if got is None or isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(got["nodes"]):
        return None
    return [float(v) for v in got["points"][3 * index:3 * index + 3]], int(got["nodes"][index])


def wb_supervisor_node_get_contact_point(node: int | None, index: int) -> list[float]:
    """Webots' deprecated contact point ``index`` (NaNs past the last)."""
    got = _contact_point(node, index, "wb_supervisor_node_get_contact_point")
    return [math.nan] * 3 if got is None else got[0]


def wb_supervisor_node_get_contact_point_node(node: int | None, index: int) -> int | None:
    """Webots' deprecated Solid of contact point ``index`` (None past the last)."""
    got = _contact_point(node, index, "wb_supervisor_node_get_contact_point_node")
    return None if got is None else wb_supervisor_node_get_from_id(got[1])


def wb_supervisor_node_enable_contact_points_tracking(node: int | None, sampling_period: int,
                                                      include_descendants: bool = False) -> None:
    """Accepted; every query computes the points of that moment (README "Supervisor")."""
    _checked_node(node, "wb_supervisor_node_enable_contact_points_tracking")


def wb_supervisor_node_disable_contact_points_tracking(node: int | None) -> None:
    _checked_node(node, "wb_supervisor_node_disable_contact_points_tracking")


def wb_supervisor_node_export_string(node: int | None) -> str:
    """Webots' ``exportString``: a node as ``.wbt`` text (``DEF NAME Type { ... }``), as its world file or node
    string wrote it with the fields the server keeps as they are now (where it stands, its name, custom data, a
    light's fields, a joint's position; README "Supervisor"), ready for ``importMFNodeFromString``. A node a
    PROTO's body made, or of a YAML world, has no such text here: the server's one line and ""."""
    func = "wb_supervisor_node_export_string"
    r = _checked_node(node, func)
    got = None if r is None else _answer(r, "node_export_string", {"node": int(node)}, func)  # type: ignore[arg-type]
    return "" if got is None else str(got["value"])


def wb_supervisor_node_remove(node: int | None) -> None:
    """Take a top-level solid or light out of the world for good: from the next step no sensor sees
    it and robots drive through where it stood; its id answers NULL from then on and is never reused;
    ``simulationReset`` does not bring it back (Webots). The root and robots cannot be removed here
    (one error line, nothing removed: a departure from Webots, which removes robots too)."""
    func = "wb_supervisor_node_remove"
    r = _checked_node(node, func)
    if r is None:
        return
    try:
        _call(r, "remove_node", {"node": int(node)})  # type: ignore[arg-type]
    except SensoriumError as err:      # the root, a robot, a node already removed: the server's line
        if err.code != ErrorCode.INVALID_ARGUMENT:
            raise
        print(f"Error: {func}(): {err.message}.", file=sys.stderr)


def wb_supervisor_node_set_joint_position(node: int | None, position: float, index: int = 1) -> None:
    """Webots' ``setJointPosition``: a joint node's axis ``index`` (1; a Hinge2Joint's 1 or 2, a
    BallJoint's 1 to 3) at ``position`` (rad, or m) at once, with what rides on it; its motor then
    targets that position (its multiplier and limits applied). A joint without a motor on that axis
    does not move here (one line)."""
    func = "wb_supervisor_node_set_joint_position"
    r = _checked_node(node, func)
    if r is None:
        return
    if isinstance(index, bool) or not isinstance(index, int) or index < 1:
        print(f"Error: {func}() called with an invalid 'index'. Only values greater than or equal to 1 are "
              "supported.", file=sys.stderr)
        return
    if isinstance(position, bool) or not isinstance(position, (int, float)) or not math.isfinite(position):
        print(f"Error: {func}() called with a 'position' that is not a finite number: {position!r}.", file=sys.stderr)
        return
    _answer(r, "set_joint_position", {"node": int(node), "position": float(position),  # type: ignore[arg-type]
                                      "index": min(index, 1 << 30)}, func)


MAX_STATE_NAME = 1024
"""The longest state name the server keeps (a longer one is refused with one line)."""


def _node_state(node: Any, state_name: Any, item: str, func: str) -> None:
    state_name = c_string(state_name)
    r = _checked_node(node, func)
    if r is None:
        return
    if not isinstance(state_name, str):
        print(f"Error: {func}() called with a NULL or invalid 'state_name' argument.", file=sys.stderr)
        return
    if len(state_name) > MAX_STATE_NAME:
        print(f"Error: {func}() called with a 'state_name' of {len(state_name)} characters: at most "
              f"{MAX_STATE_NAME} here.", file=sys.stderr)
        return
    _answer(r, item, {"node": int(node), "state": state_name}, func)


def wb_supervisor_node_save_state(node: int | None, state_name: str) -> None:
    """Keep the node's state under ``state_name``: a robot's pose and its joints' positions, a
    top-level solid's pose, a nested node's joints (README "Supervisor"); at most 64 names per node."""
    _node_state(node, state_name, "save_node_state", "wb_supervisor_node_save_state")


def wb_supervisor_node_load_state(node: int | None, state_name: str) -> None:
    """Put the node's state saved under ``state_name`` back (``"__init__"``: as the world loaded):
    the pose bit for bit, each joint at its position with its motor holding it, LEDs off; the clock
    keeps running. An unknown name is refused with one line, nothing changed."""
    _node_state(node, state_name, "load_node_state", "wb_supervisor_node_load_state")


_set_velocity_warned: list[bool] = []
# Webots' Solid and the nodes derived from it (its node chart): Robot, Charger, Track and the devices that are
# Solids; not Pose, Group, Shape, joints, motors, position sensors, brakes, Propeller, Skin, ...
SOLID_TYPES = frozenset({
    "Solid", "Robot", "Charger", "Track", "Accelerometer", "Altimeter", "Camera", "Compass", "Connector", "Display",
    "DistanceSensor", "Emitter", "GPS", "Gyro", "InertialUnit", "LED", "Lidar", "LightSensor", "Pen", "Radar",
    "RangeFinder", "Receiver", "Speaker", "TouchSensor", "VacuumGripper", "Microphone", "Radio"})


def wb_supervisor_node_set_velocity(node: int | None, velocity: Any) -> None:
    """Webots' ``setVelocity`` (linear then angular, world axes). Zero is served: it is ``resetPhysics``
    here (the one velocity of its own a node can have is a top-level solid's fall, which then starts
    again from rest; a robot keeps its motors' commands), the usual call after a supervisor moves a
    solid. Any other velocity has nothing to act on without a physics engine (a robot moves only by its
    wheels, a solid only falls straight down): one warning, ignored. Webots' check first: 6 finite
    numbers; then a node that is no Solid (its type from get_from_id) is Webots' warning, nothing asked."""
    func = "wb_supervisor_node_set_velocity"
    r = _checked_node(node, func)
    if r is None:
        return
    try:
        if isinstance(velocity, str):      # (its characters are no numbers: ctypes refuses them too)
            raise TypeError
        wire = [float(v) for v in itertools.islice(velocity, 7)]     # (an endless iterator: 7 at most)
    except (TypeError, ValueError, OverflowError):
        print(f"Error: {func}(): expected 6 numbers, got {reprlib.repr(velocity)}.", file=sys.stderr)
        return
    if len(wire) != 6:
        count = len(velocity) if isinstance(velocity, Sized) else "more than 6" if len(wire) > 6 else len(wire)
        print(f"Error: {func}(): expected 6 numbers, got {count}.", file=sys.stderr)
        return
    if not all(math.isfinite(v) for v in wire):
        print(f"Error: {func}() called with a NaN or infinite value.", file=sys.stderr)
        return
    # a node that is no Solid (the root, whose resetPhysics would stop all, a Pose, a joint, ...): Webots
    # warns and sets nothing, whatever the velocity; no request (a node the server no longer has: its answer)
    info = None if node == 0 else _call(r, "get_from_id", {"id": int(node)})  # type: ignore[arg-type]
    if node == 0 or info is not None and info.get("type") and info["type"] not in SOLID_TYPES:
        print(f"Warning: {func}() can exclusively be used with a Solid.", file=sys.stderr)
        return
    if not any(wire):
        _answer(r, "reset_physics", {"node": int(node)}, func)  # type: ignore[arg-type]
        return
    if _set_velocity_warned:
        return
    _set_velocity_warned.append(True)
    print(f"Warning: {func}(): a velocity other than zero is ignored: Sensorium has no physics engine (robots move "
          "by their wheels' commands, solids only fall straight down from rest).", file=sys.stderr)


def wb_supervisor_node_reset_physics(node: int | None) -> None:
    """Webots' ``resetPhysics``: the velocities of the node and the Solids under it zeroed. A top-level solid
    falling (README "Falling") falls again from rest from where it is, onto the same support; a robot keeps
    its motors' commands (its motion here), so nothing else changes. The root's: every falling solid's."""
    func = "wb_supervisor_node_reset_physics"
    r = _checked_node(node, func)
    if r is not None:
        _answer(r, "reset_physics", {"node": int(node)}, func)  # type: ignore[arg-type]


def wb_supervisor_node_move_viewpoint(node: int | None) -> None:
    """Webots' ``moveViewpoint``: the Viewpoint backed off along its view direction until the node's bounding
    sphere fills the view, its orientation kept; at once (Webots animates it over about a second), seen by
    its ``position`` field and the next exportImage or movie frame (README "Supervisor")."""
    func = "wb_supervisor_node_move_viewpoint"
    r = _checked_node(node, func)
    if r is not None:
        _answer(r, "move_viewpoint", {"node": int(node)}, func)  # type: ignore[arg-type]


def wb_supervisor_simulation_reset_physics() -> None:
    """Webots' ``simulationResetPhysics``: the root's ``resetPhysics``, every falling solid falls again from rest."""
    func = "wb_supervisor_simulation_reset_physics"
    r = _supervisor(func)
    if r is not None:
        _answer(r, "reset_physics", {"node": 0}, func)


# ---------------------------------------------------------------------- fields

def _field_args(field: Field) -> dict:
    """A field's request arguments (a PROTO level only when the field names one)."""
    args: dict[str, Any] = {"node": field[0], "field": field[1]}
    if len(field) > 3:
        args["level"] = field[3]       # type: ignore[misc]
    return args


def _get_field(node: Any, field_name: Any, level: int, func: str) -> Field | None:
    field_name = c_string(field_name)
    r = _checked_node(node, func)
    if r is None:
        return None
    if not isinstance(field_name, str) or not field_name or len(field_name) > 256:
        print(f"Error: {func}() called with a NULL, empty or invalid 'field_name' argument.", file=sys.stderr)
        return None
    args: dict[str, Any] = {"node": int(node), "field": field_name}
    if level >= 0:
        args["level"] = level
    got = _answer(r, "get_field", args, func)
    if got is None:
        return None
    if not got["type"]:
        if not got.get("absent", False):     # absent: Webots' node has none either (NULL, no message)
            print(f"Error: {func}(): node {node} has no field {field_name!r} in Sensorium (README \"Supervisor\" "
                  f"lists the fields of each node kind).", file=sys.stderr)
        return None
    if level >= 0:
        return (int(node), field_name, FIELD_TYPES[got["type"]], level)
    return (int(node), field_name, FIELD_TYPES[got["type"]])


def wb_supervisor_node_get_field(node: int | None, field_name: str) -> Field | None:
    """The node's field of that name (a PROTO instance's: its PROTO's interface field, as Webots), None
    (with one line) when the node has no such field here."""
    return _get_field(node, field_name, -1, "wb_supervisor_node_get_field")


def wb_supervisor_node_get_base_node_field(node: int | None, field_name: str) -> Field | None:
    """The field of the node's base node (a PROTO instance's Robot, Solid, ...): read-only on a PROTO
    instance, as in Webots."""
    return _get_field(node, field_name, 0, "wb_supervisor_node_get_base_node_field")


def _proto_info(r: RobotClient, node: int, level: int, func: str) -> dict | None:
    got = _answer(r, "get_proto", {"node": node, "level": level}, func)
    return got if got is not None and got.get("type_name") else None


def wb_supervisor_node_get_proto(node: int | None) -> Proto | None:
    """The node's PROTO (Webots' WbProtoRef): None for a base node (or a PROTO Sensorium builds in)."""
    func = "wb_supervisor_node_get_proto"
    r = _checked_node(node, func)
    if r is None:
        return None
    return None if _proto_info(r, int(node), 1, func) is None else (int(node), 1)  # type: ignore[arg-type]


def _proto_checked(proto: Any, func: str) -> tuple[RobotClient, dict] | None:
    r = _supervisor(func)
    if r is None:
        return None
    info = None
    if isinstance(proto, tuple) and len(proto) == 2 and all(type(x) is int for x in proto) and 0 <= proto[0] < 1 << 63 \
            and 1 <= proto[1] <= 16:              # (a ref the library could have given: else asked for nothing)
        info = _proto_info(r, proto[0], proto[1], func)
    if info is None:
        print(f"Error: {func}() called with a NULL or invalid 'proto' argument.", file=sys.stderr)
        return None
    return r, info


def wb_supervisor_proto_get_type_name(proto: Proto | None) -> str:
    got = _proto_checked(proto, "wb_supervisor_proto_get_type_name")
    return "" if got is None else str(got[1]["type_name"])


def wb_supervisor_proto_is_derived(proto: Proto | None) -> bool:
    got = _proto_checked(proto, "wb_supervisor_proto_is_derived")
    return got is not None and bool(got[1].get("derived"))


def wb_supervisor_proto_get_parent(proto: Proto | None) -> Proto | None:
    """The PROTO this one is built on (its body is an instance of it), None when it is built on a base node."""
    func = "wb_supervisor_proto_get_parent"
    got = _proto_checked(proto, func)
    if got is None or not got[1].get("derived"):
        return None
    assert proto is not None             # asked now, as the C library does: past the chain kept, one line and None
    return None if _proto_info(got[0], proto[0], proto[1] + 1, func) is None else (proto[0], proto[1] + 1)


def wb_supervisor_proto_get_number_of_fields(proto: Proto | None) -> int:
    got = _proto_checked(proto, "wb_supervisor_proto_get_number_of_fields")
    return -1 if got is None else len(got[1].get("fields", []))


def wb_supervisor_proto_get_field(proto: Proto | None, field_name: str) -> Field | None:
    """The PROTO's interface field of that name (on a parent PROTO: read-only, as in Webots)."""
    func = "wb_supervisor_proto_get_field"
    if _proto_checked(proto, func) is None:
        return None
    assert proto is not None
    return _get_field(proto[0], field_name, proto[1], func)


def _field_by_index(names: list, index: Any, func: str, whose: str = "the PROTO") -> str | None:
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(names):
        print(f"Error: {func}() called with an invalid 'index' argument: {index!r} ({whose} has {len(names)} "
              "fields).", file=sys.stderr)
        return None
    return str(names[index])


def wb_supervisor_proto_get_field_by_index(proto: Proto | None, index: int) -> Field | None:
    func = "wb_supervisor_proto_get_field_by_index"
    got = _proto_checked(proto, func)
    if got is None:
        return None
    assert proto is not None
    name = _field_by_index(got[1].get("fields", []), index, func)
    return None if name is None else _get_field(proto[0], name, proto[1], func)


def _node_fields(node: Any, func: str, base: bool) -> tuple[list, int, str] | None:
    """The field names ``getNumberOfFields`` (``base`` False: a PROTO instance's interface, else its base
    node's) or ``getNumberOfBaseNodeFields`` (``base`` True) count, with the level a field is asked at and
    whose fields they are (for a line); None after one line (a NULL or removed node)."""
    r = _checked_node(node, func)
    if r is None:
        return None
    info = None if base else _proto_info(r, int(node), 1, func)
    if info is not None:
        return list(info.get("fields", [])), -1, "the PROTO"
    got = _answer(r, "get_proto", {"node": int(node), "level": 0}, func)    # the base node's served fields
    return None if got is None else (list(got.get("fields", [])), 0 if base else -1, "the node")


def wb_supervisor_node_get_from_proto_def(node: int | None, def_name: str) -> int | None:
    """Webots' DEF lookup inside a PROTO instance's body: the node of the instance's own body (and of what
    its nested PROTO instances hold in their fields, not their own bodies) with that DEF, usable as any
    node; None when there is none. Webots' lines for a NULL or empty ``def``, a NULL node, a node that is
    no PROTO instance; Sensorium's line when the DEF names a node it serves no Supervisor node for."""
    def_name = c_string(def_name)
    func = "wb_supervisor_node_get_from_proto_def"
    r = _supervisor(func)
    if r is None:
        return None
    if not isinstance(def_name, str) or not def_name:
        print(f"Error: {func}() called with NULL or empty 'def' argument.", file=sys.stderr)
        return None
    info = _live_node_info(node, func)
    if info is None:
        return None
    if not info.get("proto"):
        print(f"Error: {func}(): 'node' is not a PROTO node.", file=sys.stderr)
        return None
    got = _answer(r, "get_from_proto_def", {"node": int(node), "name": def_name}, func)  # type: ignore[arg-type]
    if got is None:
        return None
    if got.get("note"):
        print(f"Error: {func}(): {got['note']}.", file=sys.stderr)
    return _node_id(got)


def wb_supervisor_node_get_number_of_fields(node: int | None) -> int:
    """A PROTO instance's interface fields, as Webots counts them; a base node's fields served here
    (Webots counts all its node type's fields; README "Supervisor" says which are left out)."""
    got = _node_fields(node, "wb_supervisor_node_get_number_of_fields", False)
    return -1 if got is None else len(got[0])


def wb_supervisor_node_get_field_by_index(node: int | None, index: int) -> Field | None:
    """A PROTO instance's interface field ``index`` (declaration order); a base node's served field ``index``
    (Webots' declaration order)."""
    func = "wb_supervisor_node_get_field_by_index"
    got = _node_fields(node, func, False)
    name = None if got is None else _field_by_index(got[0], index, func, got[2])
    return None if name is None or got is None else _get_field(node, name, got[1], func)


def wb_supervisor_node_get_number_of_base_node_fields(node: int | None) -> int:
    """The base node's fields served here (a PROTO instance's Robot, Solid, ...; a base node's own)."""
    got = _node_fields(node, "wb_supervisor_node_get_number_of_base_node_fields", True)
    return -1 if got is None else len(got[0])


def wb_supervisor_node_get_base_node_field_by_index(node: int | None, index: int) -> Field | None:
    """The base node's served field ``index``, in Webots' declaration order (on a PROTO instance read-only,
    as ``getBaseNodeField``)."""
    func = "wb_supervisor_node_get_base_node_field_by_index"
    got = _node_fields(node, func, True)
    name = None if got is None else _field_by_index(got[0], index, func, got[2])
    return None if name is None or got is None else _get_field(node, name, got[1], func)


def wb_supervisor_field_get_type(field: Field | None) -> int:
    return WB_NO_FIELD if field is None else field[2]


def wb_supervisor_field_get_type_name(field: Field | None) -> str:
    return "" if field is None else _TYPE_NAMES[field[2]]


def wb_supervisor_field_get_name(field: Field | None) -> str:
    return "" if field is None else field[1]


def wb_supervisor_field_get_actual_field(field: Field | None) -> Field | None:
    """Webots' ``getActualField``: the node's own field (``getField``, what the scene tree shows) that
    ``field`` takes its value from through IS -- a PROTO instance's base-node field or a field of a PROTO it
    is built on gives the interface field passing straight to it; a node's own field is its own; None when
    no interface field reaches it (README "Supervisor")."""
    func = "wb_supervisor_field_get_actual_field"
    r = _field_robot(field, None, func)
    if r is None:
        return None
    assert field is not None
    if len(field) == 3:                  # the node's own field already (getField)
        return field
    got = _answer(r, "get_actual_field", _field_args(field), func)
    if got is None or not got["value"]:
        return None
    return (field[0], str(got["value"]), field[2])


def _field_robot(field: Field | None, want: int | None, func: str):
    """The supervisor robot for a call on ``field`` of type ``want`` (None: any), or None after
    Webots' line for a NULL field or a wrong type."""
    r = _supervisor(func)
    if r is None:
        return None
    if field is None:
        print(f"Error: {func}() called with NULL 'field' argument.", file=sys.stderr)
        return None
    if want is not None and field[2] != want:
        print(f"Error: {func}() called with wrong field type: {_TYPE_NAMES[field[2]]}.", file=sys.stderr)
        return None
    return r


def _field_value(field: Field | None, want: int | None, func: str) -> Any:
    """The field's value from the server; None after Webots' line for a NULL field or a wrong type."""
    r = _field_robot(field, want, func)
    if r is None:
        return None
    assert field is not None
    got = _answer(r, "get_field", _field_args(field), func)
    return None if got is None else _noted(got, func)


def _noted(got: dict, func: str) -> Any:
    """A get_field reply's value; None after the server's line for a value it does not serve (a PROTO's
    node-typed field, a value over its bound)."""
    if got.get("note"):
        print(f"Error: {func}(): {got['note']}.", file=sys.stderr)
        return None
    return got["value"]


def wb_supervisor_field_get_count(field: Field | None) -> int:
    """Webots: the number of items of an MF field, -1 for a single (SF) field."""
    func = "wb_supervisor_field_get_count"
    r = _supervisor(func)
    if r is None:
        return -1
    if field is None:
        print(f"Error: {func}() called with NULL 'field' argument.", file=sys.stderr)
        return -1
    if not field[2] & WB_MF:
        return -1
    got = _answer(r, "get_field", _field_args(field), func)
    value = None if got is None else _noted(got, func)
    return -1 if value is None else len(value)


def wb_supervisor_field_get_sf_bool(field: Field | None) -> bool:
    v = _field_value(field, WB_SF_BOOL, "wb_supervisor_field_get_sf_bool")
    return False if v is None else bool(v)


def wb_supervisor_field_get_sf_int32(field: Field | None) -> int:
    v = _field_value(field, WB_SF_INT32, "wb_supervisor_field_get_sf_int32")
    return 0 if v is None else int(v)


def wb_supervisor_field_get_sf_float(field: Field | None) -> float:
    v = _field_value(field, WB_SF_FLOAT, "wb_supervisor_field_get_sf_float")
    return math.nan if v is None else float(v)


def wb_supervisor_field_get_sf_string(field: Field | None) -> str:
    v = _field_value(field, WB_SF_STRING, "wb_supervisor_field_get_sf_string")
    return "" if v is None else str(v)


def _floats(v: Any, n: int) -> list[float] | None:
    return None if v is None else [float(x) for x in v][:n]


def wb_supervisor_field_get_sf_vec2f(field: Field | None) -> list[float] | None:
    return _floats(_field_value(field, WB_SF_VEC2F, "wb_supervisor_field_get_sf_vec2f"), 2)


def wb_supervisor_field_get_sf_vec3f(field: Field | None) -> list[float] | None:
    return _floats(_field_value(field, WB_SF_VEC3F, "wb_supervisor_field_get_sf_vec3f"), 3)


def wb_supervisor_field_get_sf_rotation(field: Field | None) -> list[float] | None:
    return _floats(_field_value(field, WB_SF_ROTATION, "wb_supervisor_field_get_sf_rotation"), 4)


def wb_supervisor_field_get_sf_color(field: Field | None) -> list[float] | None:
    return _floats(_field_value(field, WB_SF_COLOR, "wb_supervisor_field_get_sf_color"), 3)


def _mf_item(field: Field | None, want: int, index: int, func: str) -> Any:
    """Item ``index`` of an MF field (negative counts from the end, as Webots); None after Webots' line."""
    items = _field_value(field, want, func)
    if items is None:
        return None
    count = len(items)
    if isinstance(index, bool) or not isinstance(index, int) or not -count <= index < count:
        if count == 0:
            print(f"Error: {func}() called on an empty list.", file=sys.stderr)
        else:
            print(f"Error: {func}() called with an out-of-bound index: {index} (should be between {-count} and "
                  f"{count - 1}).", file=sys.stderr)
        return None
    return items[index]


def wb_supervisor_field_get_sf_node(field: Field | None) -> int | None:
    """The node of an SFNode field (a joint's ``jointParameters``); None for NULL."""
    node = _field_value(field, WB_SF_NODE, "wb_supervisor_field_get_sf_node")
    return None if node is None or isinstance(node, bool) or not isinstance(node, int) or node <= 0 else node


def wb_supervisor_field_get_mf_node(field: Field | None, index: int) -> int | None:
    """Item ``index`` of an MFNode field (negative counts from the end, as Webots)."""
    node = _mf_item(field, WB_MF_NODE, index, "wb_supervisor_field_get_mf_node")
    return None if node is None else int(node)


def wb_supervisor_field_get_mf_color(field: Field | None, index: int) -> list[float] | None:
    """Colour ``index`` of an MFColor field (a Background's ``skyColor``; negative counts from the end)."""
    return _floats(_mf_item(field, WB_MF_COLOR, index, "wb_supervisor_field_get_mf_color"), 3)


# the other MF types: a PROTO's interface fields (negative indices count from the end, as Webots)
def wb_supervisor_field_get_mf_bool(field: Field | None, index: int) -> bool:
    return bool(_mf_item(field, WB_MF_BOOL, index, "wb_supervisor_field_get_mf_bool") or False)


def wb_supervisor_field_get_mf_int32(field: Field | None, index: int) -> int:
    return int(_mf_item(field, WB_MF_INT32, index, "wb_supervisor_field_get_mf_int32") or 0)


def wb_supervisor_field_get_mf_float(field: Field | None, index: int) -> float:
    v = _mf_item(field, WB_MF_FLOAT, index, "wb_supervisor_field_get_mf_float")
    return math.nan if v is None else float(v)


def wb_supervisor_field_get_mf_vec2f(field: Field | None, index: int) -> list[float] | None:
    return _floats(_mf_item(field, WB_MF_VEC2F, index, "wb_supervisor_field_get_mf_vec2f"), 2)


def wb_supervisor_field_get_mf_vec3f(field: Field | None, index: int) -> list[float] | None:
    return _floats(_mf_item(field, WB_MF_VEC3F, index, "wb_supervisor_field_get_mf_vec3f"), 3)


def wb_supervisor_field_get_mf_rotation(field: Field | None, index: int) -> list[float] | None:
    return _floats(_mf_item(field, WB_MF_ROTATION, index, "wb_supervisor_field_get_mf_rotation"), 4)


def wb_supervisor_field_get_mf_string(field: Field | None, index: int) -> str:
    v = _mf_item(field, WB_MF_STRING, index, "wb_supervisor_field_get_mf_string")
    return "" if v is None else str(v)


def wb_supervisor_field_enable_sf_tracking(field: Field | None, sampling_period: int) -> None:
    """Webots sends a tracked field's value every sampling period so that its getters need no round
    trip; here every getter asks the server and answers the value of now, which is what tracking
    shows at each step: accepted after Webots' checks, nothing else to do."""
    func = "wb_supervisor_field_enable_sf_tracking"
    if _field_robot(field, None, func) is not None and sampling_period < 0:
        print(f"Error: {func}() called with negative sampling period.", file=sys.stderr)


def wb_supervisor_field_disable_sf_tracking(field: Field | None) -> None:
    _field_robot(field, None, "wb_supervisor_field_disable_sf_tracking")


def _field_set(field: Field | None, want: int, value: Any, func: str) -> None:
    r = _field_robot(field, want, func)
    if r is None:
        return
    assert field is not None
    # a value of the wrong shape is printed and ignored, as Webots' Python Field does (no exception)
    if want == WB_SF_BOOL:
        wire: Any = bool(value)
    elif want in (WB_SF_INT32, WB_SF_STRING):     # read-only here: the server's line
        wire = _mf_value(WB_MF_INT32 if want == WB_SF_INT32 else WB_MF_STRING, value, func)
        if wire is None:
            return
    elif want == WB_SF_FLOAT:
        try:
            wire = float(value)
        except (TypeError, ValueError):
            print(f"Error: {func}(): expected a number, got {value!r}.", file=sys.stderr)
            return
    else:
        n = 4 if want == WB_SF_ROTATION else 2 if want == WB_SF_VEC2F else 3
        try:
            wire = [float(v) for v in value]
        except (TypeError, ValueError):
            print(f"Error: {func}(): expected {n} numbers, got {value!r}.", file=sys.stderr)
            return
        if len(wire) != n:
            print(f"Error: {func}(): expected {n} numbers, got {len(wire)}.", file=sys.stderr)
            return
    if isinstance(wire, float) and not math.isfinite(wire) or isinstance(wire, list) and \
            not all(math.isfinite(v) for v in wire):
        print(f"Error: {func}() called with a NaN or infinite value.", file=sys.stderr)
        return
    _answer(r, "set_field", {**_field_args(field), "value": wire}, func)


def wb_supervisor_field_set_sf_bool(field: Field | None, value: bool) -> None:
    _field_set(field, WB_SF_BOOL, value, "wb_supervisor_field_set_sf_bool")


def wb_supervisor_field_set_sf_float(field: Field | None, value: float) -> None:
    _field_set(field, WB_SF_FLOAT, value, "wb_supervisor_field_set_sf_float")


def wb_supervisor_field_set_sf_vec3f(field: Field | None, values: Any) -> None:
    _field_set(field, WB_SF_VEC3F, values, "wb_supervisor_field_set_sf_vec3f")


def wb_supervisor_field_set_sf_rotation(field: Field | None, values: Any) -> None:
    _field_set(field, WB_SF_ROTATION, values, "wb_supervisor_field_set_sf_rotation")


def wb_supervisor_field_set_sf_color(field: Field | None, values: Any) -> None:
    _field_set(field, WB_SF_COLOR, values, "wb_supervisor_field_set_sf_color")


def wb_supervisor_field_set_sf_int32(field: Field | None, value: int) -> None:
    _field_set(field, WB_SF_INT32, value, "wb_supervisor_field_set_sf_int32")


def wb_supervisor_field_set_sf_vec2f(field: Field | None, values: Any) -> None:
    _field_set(field, WB_SF_VEC2F, values, "wb_supervisor_field_set_sf_vec2f")


def wb_supervisor_field_set_sf_string(field: Field | None, value: str) -> None:
    value = c_string(value)
    _field_set(field, WB_SF_STRING, value, "wb_supervisor_field_set_sf_string")


MAX_MF_STRING = 4096
"""The longest MFString item a set or insert sends (the server's bound)."""


def _mf_change(field: Field | None, want: int | None, op: str, index: Any, value: Any, func: str) -> None:
    """An MF field's item set, inserted or removed (``want`` None: any MF type, removeMF); the server
    checks the index (negative from the end, as Webots) and the value, and says what is wrong in one
    line. Served on an imported line or point set's fields and on a shape's ImageTexture's ``url``
    (README "Supervisor")."""
    r = _field_robot(field, want, func)
    if r is None:
        return
    assert field is not None
    if want is None and not field[2] & WB_MF:
        print(f"Error: {func}() called with wrong field type: {_TYPE_NAMES[field[2]]}.", file=sys.stderr)
        return
    if isinstance(index, bool) or not isinstance(index, int) or not -(1 << 31) <= index < 1 << 31:
        print(f"Error: {func}() called with an invalid 'index' argument: {index!r}.", file=sys.stderr)
        return
    args: dict[str, Any] = {**_field_args(field), "index": index, "op": op}
    if op != "remove":
        wire = _mf_value(want, value, func)
        if wire is None:
            return
        args["value"] = wire
    _answer(r, "set_field", args, func)


def _mf_value(want: int | None, value: Any, func: str) -> Any:
    """An item's value as sent, after the client's checks (Webots': a NULL string, NaN, a zero rotation
    axis); None after one line."""
    if want == WB_MF_BOOL:
        return bool(value)
    if want == WB_MF_INT32:
        if isinstance(value, bool) or not isinstance(value, int) or not -(1 << 31) <= value < 1 << 31:
            print(f"Error: {func}(): expected a 32-bit whole number, got {value!r}.", file=sys.stderr)
            return None
        return value
    if want == WB_MF_STRING:
        if not isinstance(value, str):
            print(f"Error: {func}() called with a NULL or non-string 'value' argument: {value!r}.", file=sys.stderr)
            return None
        if len(value) > MAX_MF_STRING:
            print(f"Error: {func}(): a string of {len(value)} characters is longer than the {MAX_MF_STRING} "
                  "a field item takes here.", file=sys.stderr)
            return None
        return value
    if want == WB_MF_FLOAT:
        try:
            number = float(value)
        except (TypeError, ValueError):
            print(f"Error: {func}(): expected a number, got {value!r}.", file=sys.stderr)
            return None
        if not math.isfinite(number):
            print(f"Error: {func}() called with a NaN or infinite value.", file=sys.stderr)
            return None
        return number
    n = 4 if want == WB_MF_ROTATION else 2 if want == WB_MF_VEC2F else 3
    try:
        wire = [float(v) for v in value]
    except (TypeError, ValueError):
        print(f"Error: {func}(): expected {n} numbers, got {value!r}.", file=sys.stderr)
        return None
    if len(wire) != n:
        print(f"Error: {func}(): expected {n} numbers, got {len(wire)}.", file=sys.stderr)
        return None
    if not all(math.isfinite(v) for v in wire):
        print(f"Error: {func}() called with a NaN or infinite value.", file=sys.stderr)
        return None
    if want == WB_MF_ROTATION and wire[0] == wire[1] == wire[2] == 0.0:
        print(f"Error: {func}() called with invalid values for the [x y z] axis (a zero vector).", file=sys.stderr)
        return None
    return wire


def wb_supervisor_field_set_mf_int32(field: Field | None, index: int, value: int) -> None:
    _mf_change(field, WB_MF_INT32, "set", index, value, "wb_supervisor_field_set_mf_int32")


def wb_supervisor_field_set_mf_vec3f(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_VEC3F, "set", index, values, "wb_supervisor_field_set_mf_vec3f")


def wb_supervisor_field_set_mf_color(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_COLOR, "set", index, values, "wb_supervisor_field_set_mf_color")


def wb_supervisor_field_insert_mf_int32(field: Field | None, index: int, value: int) -> None:
    _mf_change(field, WB_MF_INT32, "insert", index, value, "wb_supervisor_field_insert_mf_int32")


def wb_supervisor_field_insert_mf_vec3f(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_VEC3F, "insert", index, values, "wb_supervisor_field_insert_mf_vec3f")


def wb_supervisor_field_insert_mf_color(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_COLOR, "insert", index, values, "wb_supervisor_field_insert_mf_color")


def wb_supervisor_field_set_mf_bool(field: Field | None, index: int, value: bool) -> None:
    _mf_change(field, WB_MF_BOOL, "set", index, value, "wb_supervisor_field_set_mf_bool")


def wb_supervisor_field_insert_mf_bool(field: Field | None, index: int, value: bool) -> None:
    _mf_change(field, WB_MF_BOOL, "insert", index, value, "wb_supervisor_field_insert_mf_bool")


def wb_supervisor_field_set_mf_float(field: Field | None, index: int, value: float) -> None:
    _mf_change(field, WB_MF_FLOAT, "set", index, value, "wb_supervisor_field_set_mf_float")


def wb_supervisor_field_insert_mf_float(field: Field | None, index: int, value: float) -> None:
    _mf_change(field, WB_MF_FLOAT, "insert", index, value, "wb_supervisor_field_insert_mf_float")


def wb_supervisor_field_set_mf_vec2f(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_VEC2F, "set", index, values, "wb_supervisor_field_set_mf_vec2f")


def wb_supervisor_field_insert_mf_vec2f(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_VEC2F, "insert", index, values, "wb_supervisor_field_insert_mf_vec2f")


def wb_supervisor_field_set_mf_rotation(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_ROTATION, "set", index, values, "wb_supervisor_field_set_mf_rotation")


def wb_supervisor_field_insert_mf_rotation(field: Field | None, index: int, values: Any) -> None:
    _mf_change(field, WB_MF_ROTATION, "insert", index, values, "wb_supervisor_field_insert_mf_rotation")


def wb_supervisor_field_set_mf_string(field: Field | None, index: int, value: str) -> None:
    value = c_string(value)
    _mf_change(field, WB_MF_STRING, "set", index, value, "wb_supervisor_field_set_mf_string")


def wb_supervisor_field_insert_mf_string(field: Field | None, index: int, value: str) -> None:
    value = c_string(value)
    _mf_change(field, WB_MF_STRING, "insert", index, value, "wb_supervisor_field_insert_mf_string")


def wb_supervisor_field_remove_mf(field: Field | None, index: int) -> None:
    _mf_change(field, None, "remove", index, None, "wb_supervisor_field_remove_mf")


def wb_supervisor_field_import_mf_node_from_string(field: Field | None, position: int, node_string: str) -> None:
    """Webots' ``importMFNodeFromString`` into the root's ``children``: the string's solids (or PROTO
    instances that are solids, of PROTOs the world file declares) and lights join the world from the
    next step, inserted at ``position`` (0 first, -1 last, as Webots). The new nodes have new ids
    (never a removed node's) and are found by DEF; ``node.remove()`` removes them and
    ``simulationReset`` does too (Webots). A robot, a node that is neither a solid nor a light, or a
    string that does not read (the server's line names where: ``node string:LINE:COL``) is refused
    with one error line and nothing changes."""
    node_string = c_string(node_string)
    func = "wb_supervisor_field_import_mf_node_from_string"
    r = _field_robot(field, WB_MF_NODE, func)
    if r is None:
        return
    assert field is not None
    if not isinstance(node_string, str) or not node_string:
        print(f"Error: {func}() called with a NULL or empty 'node_string' argument.", file=sys.stderr)
        return
    if isinstance(position, bool) or not isinstance(position, int) or not -(1 << 31) <= position < 1 << 31:
        print(f"Error: {func}() called with an invalid 'position' argument: {position!r}.", file=sys.stderr)
        return
    try:
        _call(r, "import_node_from_string", {"node": field[0], "field": field[1], "position": position,
                                             "node_string": node_string})
    except SensoriumError as err:      # a robot, a bad string, limits: the server's line
        if err.code != ErrorCode.INVALID_ARGUMENT:
            raise
        print(f"Error: {func}(): {err.message}.", file=sys.stderr)


def wb_supervisor_field_import_sf_node_from_string(field: Field | None, node_string: str) -> None:
    """Webots' ``importSFNodeFromString``: served into the empty ``coord`` (a ``Coordinate``) or ``color`` (a
    ``Color``) of an imported line or point set; any other SFNode field, a full one or a string that does not
    read is refused with the server's one line, nothing changed."""
    node_string = c_string(node_string)
    func = "wb_supervisor_field_import_sf_node_from_string"
    r = _field_robot(field, WB_SF_NODE, func)
    if r is None:
        return
    assert field is not None
    if not isinstance(node_string, str) or not node_string:
        print(f"Error: {func}() called with a NULL or empty 'node_string' argument.", file=sys.stderr)
        return
    try:
        _call(r, "import_node_from_string", {"node": field[0], "field": field[1], "position": 0,
                                             "node_string": node_string})
    except SensoriumError as err:      # not a slot served here, a full one, a bad string: the server's line
        if err.code != ErrorCode.INVALID_ARGUMENT:
            raise
        print(f"Error: {func}(): {err.message}.", file=sys.stderr)


def wb_supervisor_field_remove_sf(field: Field | None) -> None:
    """Webots' ``removeSF``: served on the ``coord`` and ``color`` of an imported line or point set (the node
    ``importSFNodeFromString`` put there leaves; the field is then empty and takes a node again); an empty
    field stays empty; any other SFNode field is read-only here (the server's one line, nothing changed)."""
    func = "wb_supervisor_field_remove_sf"
    r = _field_robot(field, WB_SF_NODE, func)
    if r is None:
        return
    assert field is not None
    _answer(r, "field_remove_sf", _field_args(field), func)


# ---------------------------------------------------------------------- the simulation

def wb_supervisor_simulation_reset() -> None:
    """Robots and solids back to their initial poses, motors to their initial commands (joints to
    their initial positions),
    top-level lights' fields as loaded, LEDs off, custom data as in the world file; the clock keeps
    running (see README)."""
    r = _supervisor("wb_supervisor_simulation_reset")
    if r is not None:
        _call(r, "simulation_reset")
        for dev in r.devices:                      # the server reset the motors' commands
            if dev.kind in ("RotationalMotor", "LinearMotor"):     # a joint's: back to its initial position
                dev.target_position = float(dev.desc.get("initialPosition", 0.0))
                dev.velocity = dev.max_velocity
                dev._consts.pop("available", None)
            if dev.kind == "LED":
                dev.value = 0
        r.motor_commands.clear()
        # the robot's customData is reset too; Webots resets at its next step and sends the value with that
        # step's answer, so getCustomData() keeps the old value until step() returns (the server sends it)


def wb_supervisor_simulation_set_mode(mode: int) -> None:
    r = _supervisor("wb_supervisor_simulation_set_mode")
    if r is None:
        return
    if mode not in (0, 1, 2) or isinstance(mode, bool):
        print(f"Error: wb_supervisor_simulation_set_mode() called with an invalid mode {mode!r}.", file=sys.stderr)
        return
    _call(r, "simulation_set_mode", {"mode": int(mode)})


def wb_supervisor_simulation_get_mode() -> int:
    r = _supervisor("wb_supervisor_simulation_get_mode")
    return WB_SUPERVISOR_SIMULATION_MODE_FAST if r is None else int(_call(r, "simulation_get_mode")["value"])


def wb_supervisor_simulation_quit(status: int) -> None:
    """Webots' quit: the server stops, every controller's steps answer -1 (this one's next step at
    once) and ``sensorium run``/``serve`` exit with ``status``."""
    r = _supervisor("wb_supervisor_simulation_quit")
    if r is None:
        return
    _call(r, "simulation_quit", {"status": max(-2**31, min(2**31 - 1, int(status)))})
    r.end_steps()


def _launcher_call(r: RobotClient, item: str, args: dict | None, func: str) -> None:
    """A request only ``sensorium run`` serves (it starts the controllers): the server's line when it
    refuses (an <extern> controller under ``sensorium serve``, a node that is no robot)."""
    try:
        _call(r, item, args)
    except SensoriumError as err:
        if err.code not in (ErrorCode.INVALID_ARGUMENT, ErrorCode.WRONG_STATE):
            raise
        print(f"Error: {func}(): {err.message}.", file=sys.stderr)


_SEEING = frozenset({"Camera", "Lidar", "RangeFinder", "Viewpoint"})


def wb_supervisor_node_set_visibility(node: int | None, from_node: int | None, visible: bool) -> None:
    """Webots' setVisibility: ``node`` (and what is inside it) hidden from, or shown again to, one Camera,
    Lidar or RangeFinder (``from_node``, its node) or the Viewpoint (exportImage); the other devices keep
    seeing it (README "Supervisor")."""
    func = "wb_supervisor_node_set_visibility"
    if _live_node_info(node, func) is None:
        return
    r = current()
    if from_node is None or isinstance(from_node, bool) or not isinstance(from_node, int) or from_node < 0:
        print(f"Error: {func}() called with a NULL or invalid 'from' argument.", file=sys.stderr)
        return
    seer = _call(r, "get_from_id", {"id": from_node})
    if not seer.get("type"):
        print(f"Error: {func}() called with a NULL or invalid 'from' argument.", file=sys.stderr)
        return
    if seer["type"] not in _SEEING:
        print(f"Error: {func}() called with a 'from' argument which is not the viewpoint or a camera, lidar or "
              "range-finder device.", file=sys.stderr)
        return
    _answer(r, "set_visibility", {"node": int(node), "from_node": from_node, "visible": bool(visible)},  # type: ignore[arg-type]
            func)


def wb_supervisor_node_restart_controller(node: int | None) -> None:
    """Webots' restartController, under ``sensorium run``: the robot's controller ends (its steps
    return -1; killed after a grace period) and starts again from its file. Under ``sensorium serve``
    (<extern> controllers, started by you) one error line, nothing done."""
    func = "wb_supervisor_node_restart_controller"
    r = _checked_node(node, func)
    if r is not None:
        _launcher_call(r, "restart_controller", {"node": int(node)}, func)  # type: ignore[arg-type]


def wb_supervisor_world_reload() -> None:
    """Webots' worldReload, under ``sensorium run``: the simulation ends (every controller's steps,
    this one's too, return -1), the world file loads again (time 0) and every controller starts again.
    Under ``sensorium serve`` one error line, nothing done."""
    func = "wb_supervisor_world_reload"
    r = _supervisor(func)
    if r is not None:
        _launcher_call(r, "world_reload", None, func)


def wb_supervisor_world_load(filename: str) -> None:
    """Webots' worldLoad, under ``sensorium run``: the simulation ends (every controller's steps, this
    one's too, return -1), ``filename`` loads (relative to this controller's folder, as in Webots; within
    the folder of the world ``run`` started with) and its controllers start. A name that gives no world
    is one line of ``run``'s and the run ends (exit 1). Under ``sensorium serve`` one error line, nothing done."""
    filename = c_string(filename)
    import os

    func = "wb_supervisor_world_load"
    r = _supervisor(func)
    if r is None:
        return
    if not filename or not isinstance(filename, str | os.PathLike):
        print(f"Error: {func}() called with NULL or empty 'filename' argument.", file=sys.stderr)
        return
    _launcher_call(r, "world_load", {"filename": os.fspath(filename)}, func)


def wb_supervisor_world_save(filename: str | None = None) -> bool:
    """Webots' ``worldSave``: the world as it is now (README "Supervisor": what is written) saved as ``filename``
    (a ``.wbt`` file; relative to the controller's folder, as every file a controller writes), through a
    temporary file renamed onto it. Without a filename Webots overwrites the world file it loaded: here one
    line and False (a headless server never overwrites its world file; name the file)."""
    filename = c_string(filename)
    import contextlib
    import os

    from sensorium.client import images

    func = "wb_supervisor_world_save"
    r = _supervisor(func)
    if r is None:
        return False
    if filename is None or filename == "":
        print(f"Error: {func}(): the world file is not overwritten here: name the file to write (a departure from "
              "Webots, which overwrites the world file it loaded).", file=sys.stderr)
        return False
    if not isinstance(filename, str | os.PathLike):
        print(f"Error: {func}() called with an invalid 'filename' argument: {filename!r}.", file=sys.stderr)
        return False
    name = os.fspath(filename)
    if not name.lower().endswith(".wbt"):
        print(f"Error: the target file given to {func}() should have the '.wbt' extension.", file=sys.stderr)
        return False
    got = _answer(r, "world_save", None, func)
    if got is None:
        return False
    folder, base = os.path.split(name)
    tmp = os.path.join(folder, f".{base}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8", newline="\n") as out:
            out.write(str(got["value"]))
    except OSError as exc:
        print(f"Error: {func}(): cannot write {name!r}: {exc.strerror or exc}", file=sys.stderr)
        with contextlib.suppress(OSError):      # a part written: not left behind
            os.unlink(tmp)
        return False
    return images.install(func, tmp, name)


_unserved_warned: set[str] = set()


def supervisor_unserved(func: str, what: str = "") -> None:
    """A Supervisor function Sensorium does not serve (``what``: in which case): Webots' error in a Robot
    controller, else one line the first time it is called (the same words as the C library's)."""
    if _supervisor(func) is None or func in _unserved_warned:
        return
    _unserved_warned.add(func)
    if what:
        print(f"Error: {func}(): not served by Sensorium {what}: ignored, Webots' \"no value\" returned.",
              file=sys.stderr)
        return
    print(f"Error: {func}(): not served by Sensorium (its Supervisor walks the root's children, reads nodes' "
          "identity, poses, velocities and fields (translation, rotation, name, lights' fields, ...), sets poses "
          "and lights, resets and sets the run mode): ignored, Webots' \"no value\" returned.", file=sys.stderr)


# ---------------------------------------------------------------------- labels and pictures

MAX_LABEL_ID = 65534       # Webots: 0..65534 (65535 is its movie caption's)


def _unit_arg(func: str, name: str, value: Any) -> bool:
    """Webots' range checks of a label's numbers ([0, 1]); NaN is refused too (Webots' C lets it by)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 <= value <= 1.0:
        print(f"Error: {func}() called with {name} parameter outside of [0,1] range.", file=sys.stderr)
        return False
    return True


def wb_supervisor_set_label(id: int, text: str, x: float, y: float, size: float, color: int,
                            transparency: float = 0.0, font: str = "Arial") -> None:
    """Webots' label over the 3D view: here over every ``wb_supervisor_export_image`` picture (and
    kept by the server under ``id`` until it ends; README "Supervisor")."""
    text, font = c_string(text), c_string(font)
    func = "wb_supervisor_set_label"
    for name, value in (("x", x), ("y", y), ("size", size), ("transparency", transparency)):
        if not _unit_arg(func, name, value):
            return
    r = _supervisor(func)
    if r is None:
        return
    if text is None or not isinstance(text, str):
        print(f"Error: {func}() called with NULL 'text' argument.", file=sys.stderr)
        return
    if font is None or not isinstance(font, str):
        print(f"Error: {func}() called with NULL 'font' argument.", file=sys.stderr)
        return
    if isinstance(id, bool) or not isinstance(id, int) or not 0 <= id <= MAX_LABEL_ID:
        print(f"Error: {func}() called with an 'id' outside of [0,{MAX_LABEL_ID}] ({id!r}).", file=sys.stderr)
        return
    if isinstance(color, bool) or not isinstance(color, int) or not 0 <= color <= 0xFFFFFF:
        print(f"Error: {func}() called with a 'color' that is no 0xRRGGBB value ({color!r}).", file=sys.stderr)
        return
    _answer(r, "set_label", {"id": id, "text": text, "x": float(x), "y": float(y), "size": float(size),
                             "color": color, "transparency": float(transparency), "font": font}, func)


def wb_supervisor_export_image(filename: str, quality: int) -> None:
    """Webots' ``exportImage``: the world seen from its Viewpoint (640 × 480 here) with the labels
    over it, saved as ``filename`` (``.png``, or ``.jpg``/``.jpeg`` at ``quality`` 1..100, Pillow
    needed for JPEG). The server sends the pixels; this client writes the file, through a
    temporary file renamed onto ``filename`` (Webots' way: never a half-written picture)."""
    filename = c_string(filename)
    import os

    from sensorium.client import images
    func = "wb_supervisor_export_image"
    r = _supervisor(func)
    if r is None:
        return
    if not filename or not isinstance(filename, str | os.PathLike):
        print(f"Error: {func}() called with NULL or empty 'filename' argument.", file=sys.stderr)
        return
    if isinstance(quality, bool) or not isinstance(quality, int) or not 1 <= quality <= 100:
        print(f"Error: {func}(): 'quality' argument ({quality!r}) must be between 1 and 100.", file=sys.stderr)
        return
    name = os.fspath(filename)
    ext = os.path.splitext(name)[1].lower()
    if ext not in (".png", ".jpg", ".jpeg"):
        print(f"Error: {func}(): unsupported image format of {name!r} (use .png, .jpg or .jpeg).", file=sys.stderr)
        return
    reply = _answer(r, "export_image", None, func)
    if reply is None:
        return
    folder, base = os.path.split(name)
    tmp = os.path.join(folder, f".{base}.{os.getpid()}.tmp{ext}")
    if images.save_rgb(func, tmp, quality, bytes(reply["data"]), int(reply["width"]), int(reply["height"])) != 0:
        return
    images.install(func, tmp, name)
