"""The Supervisor subset (sans-IO): node handles, ``translation``/``rotation`` fields, poses.

Nodes are the world's robots and top-level solids, found by DEF name (``def_name``, set from a
``.wbt`` world's ``DEF``) or else by name.
A node's id is stable for the life of the server: robots 1..R in world order, then solids. Field
values are Webots' ``SFVec3f`` (x, y, z) and ``SFRotation`` (axis x, y, z, angle), in the parent
frame (the world here: nodes are not nested). Setting one field keeps the other (Webots).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from sensorium.server.daemon.roles import check_pose
from sensorium.server.world.poses import matrix_quaternion

MODES = ("pause", "realtime", "fast")     # Webots WB_SUPERVISOR_SIMULATION_MODE_PAUSE = 0, REAL_TIME, FAST


@dataclass(frozen=True, slots=True)
class Node:
    id: int
    type: str          # "Robot" | "Solid"
    name: str


def _nodes(sim: Any) -> list[Node]:
    robots = [Node(i + 1, "Robot", name) for i, name in enumerate(sim.robots)]
    solids = [Node(len(robots) + i + 1, "Solid", name) for i, name in enumerate(sim.scene.solid_poses)]
    return robots + solids


def find_node(sim: Any, name: str) -> Node | None:
    """The robot or top-level solid whose DEF name (``def_name``) is ``name``, else whose name is."""
    nodes = _nodes(sim)
    world = getattr(sim, "world", None)
    if world is not None:
        defs = [getattr(m, "def_name", None) for m in (*world.robots, *world.solids)]
        for n, d in zip(nodes, defs):
            if d == name:
                return n
    for n in nodes:
        if n.name == name:
            return n
    return None


def node_by_id(sim: Any, node: int) -> Node:
    nodes = _nodes(sim)
    if not 1 <= node <= len(nodes):
        raise ValueError(f"no node with id {node} (ids 1..{len(nodes)})")
    return nodes[node - 1]


def node_ref(sim: Any, node: Node | None) -> dict:
    if node is None:
        return {"node": 0, "type": "", "name": ""}
    return {"node": node.id, "type": node.type, "name": node.name}


def _pose(sim: Any, node: Node) -> Any:
    return sim.robots[node.name].pose if node.type == "Robot" else sim.scene.solid_poses[node.name]


def matrix_axis_angle(r: np.ndarray) -> list[float]:
    """Rotation matrix → Webots axis-angle (unit axis, angle in [0, pi]); identity → 0 0 1 0.
    Through the unit quaternion, which stays accurate near half turns."""
    x, y, z, w = matrix_quaternion(r)             # w >= 0
    n = math.sqrt(x * x + y * y + z * z)
    if n < 1e-300:
        return [0.0, 0.0, 1.0, 0.0]
    return [x / n, y / n, z / n, 2.0 * math.atan2(n, w)]


def get_field(sim: Any, node: Node, field: str) -> list[float]:
    pose = _pose(sim, node)
    if field == "translation":
        return [float(v) for v in pose.translation]
    return matrix_axis_angle(pose.rotation)


def set_field(sim: Any, node: Node, field: str, value: list[float]) -> None:
    want = 3 if field == "translation" else 4
    if len(value) != want:
        raise ValueError(f"field {field!r} takes {want} numbers, got {len(value)}")
    if not all(math.isfinite(v) for v in value):
        raise ValueError(f"field {field!r}: values must be finite")
    if field == "translation":
        check_pose(translation=value)
    if field == "rotation" and math.hypot(*value[:3]) == 0.0:
        raise ValueError("rotation axis must not be zero")
    kwargs = {"translation": value} if field == "translation" else {"translation": None, "rotation": value}
    if node.type == "Robot":
        sim.robots[node.name].set_pose(**kwargs)
    else:
        sim.set_solid_pose(node.name, **kwargs)


def node_pose(sim: Any, node: Node) -> dict:
    pose = _pose(sim, node)
    return {"position": [float(v) for v in pose.translation],
            "orientation": [float(v) for v in np.asarray(pose.rotation).reshape(9)]}


# ---------------------------------------------------------------------- the services
# handler(sim, lockstep, calling robot, validated args) -> result; ValueError = INVALID_ARGUMENT

def _set_field(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    set_field(sim, node_by_id(sim, a.node), a.field, a.value)
    return {"success": True}


def _reset(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    sim.reset()
    return {"success": True}


def _set_mode(sim: Any, ls: Any, robot: str, a: Any) -> dict:
    ls.set_mode(MODES[a.mode])
    return {"success": True}


HANDLERS = {
    "get_from_def": lambda sim, ls, robot, a: node_ref(sim, find_node(sim, a.name)),
    "get_self": lambda sim, ls, robot, a: node_ref(sim, find_node(sim, robot)),
    "get_field": lambda sim, ls, robot, a: {"value": get_field(sim, node_by_id(sim, a.node), a.field)},
    "set_field": _set_field,
    "get_node_pose": lambda sim, ls, robot, a: node_pose(sim, node_by_id(sim, a.node)),
    "simulation_reset": _reset,
    "simulation_set_mode": _set_mode,
    "simulation_get_mode": lambda sim, ls, robot, a: {"value": MODES.index(ls.mode)},
}
