"""The Supervisor subset (sans-IO): node handles, ``translation``/``rotation`` fields, poses.

Nodes are the world's robots and solids, found by name (their DEF names in a converted ``.wbt``).
A node's id is stable for the life of the server: robots 1..R in world order, then solids. Field
values are Webots' ``SFVec3f`` (x, y, z) and ``SFRotation`` (axis x, y, z, angle), in the parent
frame (the world here: nodes are not nested). Setting one field keeps the other (Webots).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

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
    for n in _nodes(sim):
        if n.name == name:
            return n
    return None


def node_by_id(sim: Any, node: int) -> Node:
    nodes = _nodes(sim)
    if not 1 <= node <= len(nodes):
        raise KeyError(f"no node with id {node} (ids 1..{len(nodes)})")
    return nodes[node - 1]


def node_ref(sim: Any, node: Node | None) -> dict:
    if node is None:
        return {"node": 0, "type": "", "name": ""}
    return {"node": node.id, "type": node.type, "name": node.name}


def _pose(sim: Any, node: Node) -> Any:
    return sim.robots[node.name].pose if node.type == "Robot" else sim.scene.solid_poses[node.name]


def matrix_axis_angle(r: np.ndarray) -> list[float]:
    """Rotation matrix → Webots axis-angle (unit axis, angle in [0, pi]); identity → 0 0 1 0."""
    m = np.asarray(r, dtype=np.float64)
    c = max(-1.0, min(1.0, (m[0, 0] + m[1, 1] + m[2, 2] - 1.0) / 2.0))
    angle = math.acos(c)
    if angle < 1e-12:
        return [0.0, 0.0, 1.0, 0.0]
    if math.pi - angle < 1e-6:
        # near a half turn: the axis from the diagonal (sin(angle) ~ 0 makes the skew part useless)
        xx, yy, zz = (max((m[i, i] + 1.0) / 2.0, 0.0) for i in range(3))
        axis = np.sqrt([xx, yy, zz])
        k = int(np.argmax(axis))
        for j in range(3):
            if j != k:
                axis[j] = math.copysign(axis[j], m[k, j] + m[j, k])
    else:
        axis = np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
    axis = axis / np.linalg.norm(axis)
    return [float(axis[0]), float(axis[1]), float(axis[2]), float(angle)]


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
