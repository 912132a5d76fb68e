"""Built-in PROTOs: the few most common Webots world-building PROTOs, expanded into base nodes.

Geometry follows the PROTOs' published fields (R2022a+, z up). Their default textured appearances
(parquetry, brushed aluminium) are not sampled: surfaces without an explicit base-node appearance
read as white to infra-red sensors, like a shape without appearance.
"""

from __future__ import annotations

from collections.abc import Callable

from sensorium.server.world.wbt.fields import Fields
from sensorium.server.world.wbt.parser import Node


def _node(type_: str, at: Node, **fields) -> Node:
    return Node(type_, dict(fields), at.line, at.col)


def _solid_with(at: Node, f: Fields, name: str, items: list[tuple[tuple[float, float, float], Node, Node | None]]) -> Node:
    """A Solid whose shapes (pose translation, geometry, appearance) are seen by both ray kinds."""
    visual, bounding = [], []
    for t, geometry, appearance in items:
        shape = _node("Shape", at, geometry=geometry, appearance=appearance)
        visual.append(_node("Pose", at, translation=t, children=[shape]))
        bounding.append(_node("Pose", at, translation=t, children=[geometry]))
    fields = {"translation": f.vec("translation", (0.0, 0.0, 0.0)), "rotation": f.vec("rotation", (0.0, 0.0, 1.0, 0.0)),
              "name": f.str("name", name), "children": visual, "boundingObject": _node("Group", at, children=bounding)}
    return _node("Solid", at, **fields)


def _appearance(f: Fields, name: str) -> Node | None:
    node = f.node_(name)
    return node if node is not None and node.type in ("Appearance", "PBRAppearance") else None


def rectangle_arena(node: Node, source: str) -> Node:
    f = Fields(node, source)
    fx, fy = f.vec("floorSize", (1.0, 1.0))
    t = f.num("wallThickness", 0.01)
    h = f.num("wallHeight", 0.1)
    if min(fx, fy, t, h) <= 0:
        raise f.error(None, "floorSize, wallThickness and wallHeight must be positive")
    wall = _appearance(f, "wallAppearance")
    side = _node("Box", node, size=(t, fy, h))
    end = _node("Box", node, size=(fx + 2 * t, t, h))
    return _solid_with(node, f, "rectangle arena", [
        ((0.0, 0.0, 0.0), _node("Plane", node, size=(fx, fy)), _appearance(f, "floorAppearance")),
        ((fx / 2 + t / 2, 0.0, h / 2), side, wall),
        ((-(fx / 2 + t / 2), 0.0, h / 2), side, wall),
        ((0.0, fy / 2 + t / 2, h / 2), end, wall),
        ((0.0, -(fy / 2 + t / 2), h / 2), end, wall),
    ])


def floor(node: Node, source: str) -> Node:
    f = Fields(node, source)
    size = f.vec("size", (10.0, 10.0))
    return _solid_with(node, f, "floor", [((0.0, 0.0, 0.0), _node("Plane", node, size=size), _appearance(f, "appearance"))])


BUILTIN_PROTOS: dict[str, Callable[[Node, str], Node]] = {"RectangleArena": rectangle_arena, "Floor": floor}
