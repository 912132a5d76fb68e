"""Built-in PROTOs: the most common Webots world-building PROTOs, expanded into base nodes.

Geometry and defaults follow the PROTOs' published fields (R2022a+, z up): RectangleArena, Floor,
SolidBox, WoodenBox, and TexturedBackgroundLight (the directional light matching each background,
which light sensors do see). Textured default appearances (parquetry, brushed aluminium, wood) are
not sampled: such surfaces read as white to infra-red sensors, like a shape without appearance.
"""

from __future__ import annotations

from collections.abc import Callable

from sensorium.server.world.wbt.fields import Fields
from sensorium.server.world.wbt.parser import Node


def _node(type_: str, at: Node, **fields) -> Node:
    return Node(type_, dict(fields), at.line, at.col, source=at.source)


def _solid(at: Node, f: Fields, name: str, items: list, translation=(0.0, 0.0, 0.0), **extra) -> Node:
    """A Solid from (pose translation, geometry, appearance, bounding) items; ``bounding`` True = the
    same geometry is the bounding object (seen by both kinds of ray); ``extra``: more Solid fields."""
    visual, bounding = [], []
    for t, geometry, appearance, bound in items:
        shape = _node("Shape", at, geometry=geometry, appearance=appearance)
        visual.append(_node("Pose", at, translation=t, children=[shape]))
        if bound:
            bounding.append(_node("Pose", at, translation=t, children=[geometry]))
    return _node("Solid", at, translation=f.vec("translation", translation),
                 rotation=f.vec("rotation", (0.0, 0.0, 1.0, 0.0)), name=f.string("name", name),
                 children=visual, boundingObject=_node("Group", at, children=bounding), **extra)


def _appearance(f: Fields, name: str, default: Node | None = None) -> Node | None:
    node = f.node_(name) if f.has(name) else default
    return node if node is not None and node.type in ("Appearance", "PBRAppearance") else None


def _positive(f: Fields, name: str, default: tuple[float, ...]) -> tuple[float, ...]:
    v = f.vec(name, default)
    return v if min(v) > 0 else default   # the PROTOs reset non-positive sizes to their defaults


def rectangle_arena(node: Node, f: Fields, system: str) -> Node:
    fx, fy = _positive(f, "floorSize", (1.0, 1.0))
    t = _positive(f, "wallThickness", (0.01,))[0]
    h = _positive(f, "wallHeight", (0.1,))[0]
    wall = _appearance(f, "wallAppearance")
    side = _node("Box", node, size=(t, fy, h))
    end = _node("Box", node, size=(fx + 2 * t, t, h))
    return _solid(node, f, "rectangle arena", [
        ((0.0, 0.0, 0.0), _node("Plane", node, size=(fx, fy)), _appearance(f, "floorAppearance"), True),
        ((fx * 0.5 + t * 0.5, 0.0, h * 0.5), side, wall, True),
        ((-(fx * 0.5 + t * 0.5), 0.0, h * 0.5), side, wall, True),
        ((0.0, fy * 0.5 + t * 0.5, h * 0.5), end, wall, True),
        ((0.0, -(fy * 0.5 + t * 0.5), h * 0.5), end, wall, True),
    ])


def floor(node: Node, f: Fields, system: str) -> Node:
    size = _positive(f, "size", (10.0, 10.0))
    return _solid(node, f, "floor", [((0.0, 0.0, 0.0), _node("Plane", node, size=size), _appearance(f, "appearance"), True)])


def solid_box(node: Node, f: Fields, system: str) -> Node:
    size = _positive(f, "size", (2.0, 2.0, 2.0))
    default = _node("PBRAppearance", node, roughness=0.5, metalness=0.0)   # its textured default, untextured
    colors = {"recognitionColors": node.fields["recognitionColors"]} if f.has("recognitionColors") else {}
    return _solid(node, f, "box", [((0.0, 0.0, 0.0), _node("Box", node, size=size), _appearance(f, "appearance", default),
                                    f.flag("enableBoundingObject", True))], translation=(0.0, 0.0, 1.0),
                  model="box", **colors)    # the PROTO's Solid: model "box", recognitionColors IS recognitionColors


def wooden_box(node: Node, f: Fields, system: str) -> Node:
    size = tuple(min(max(v, 0.01), 3.0) for v in f.vec("size", (0.6, 0.6, 0.6)))   # the PROTO clamps to [0.01, 3]
    return _solid(node, f, "wooden box", [((0.0, 0.0, 0.0), _node("Box", node, size=size), None, True)],
                  translation=(0.0, 0.0, 0.3), model="wooden box")   # the PROTO's Solid has model "wooden box"


# TexturedBackgroundLight: per background texture, (direction (NUE axes), colour, intensity, on)
_SKY = {
    "dusk": ((-1.2, -0.3, -0.6), (1.0, 0.95, 0.8), 0.5, True),
    "empty_office": ((-0.2, -0.5, -0.9), (1.0, 1.0, 1.0), 0.05, True),
    "dawn_cloudy_empty": ((0.022, -0.12, -1.0), (1.0, 0.75, 0.5), 0.8, True),
    "mars": ((0.0, -1.0, 0.0), (0.83, 0.83, 0.75), 1.0, True),
    "morning_cloudy_empty": ((1.0, -0.8, -0.1), (1.0, 0.75, 0.5), 0.9, True),
    "noon_building_overcast": ((0.0, -1.0, 0.0), (1.0, 1.0, 1.0), 1.0, False),
    "factory": ((0.0, -1.0, 0.0), (1.0, 1.0, 1.0), 1.0, False),
    "entrance_hall": ((0.0, -1.0, 0.0), (1.0, 1.0, 1.0), 1.0, False),
    "noon_cloudy_countryside": ((-0.3, -1.0, -0.1), (0.95, 0.95, 1.0), 3.0, True),
    "noon_cloudy_empty": ((0.2, -1.0, 0.2), (0.9, 0.9, 1.0), 1.0, True),
    "noon_cloudy_mountains": ((0.0, -1.0, -0.5), (0.9, 0.9, 1.0), 0.9, True),
    "noon_park_empty": ((-0.023, -1.0, -0.08), (0.996, 1.0, 0.92), 3.5, True),
    "noon_stormy_empty": ((0.1, -1.0, 0.2), (0.9, 0.9, 1.0), 0.8, True),
    "noon_sunny_empty": ((0.9, -0.59, 0.28), (1.0, 1.0, 1.0), 1.0, True),
    "noon_sunny_garden": ((-0.1, -0.3, 0.3), (0.9, 0.9, 1.0), 1.0, True),
    "music_hall": ((-0.78, -0.6, -0.17), (0.9, 0.9, 1.0), 0.5, True),
    "twilight_cloudy_empty": ((1.0, -0.2, -0.7), (1.0, 0.75, 0.5), 1.8, True),
    "stadium": ((-2.1, -0.5, 2.1), (0.95, 0.95, 1.0), 2.9, True),
    "stadium_dry": ((-2.1, -0.5, 2.1), (0.95, 0.95, 1.0), 2.9, True),
    "mountains": ((-0.6, -1.0, 0.55), (1.0, 1.0, 1.0), 2.7, True),
}


def textured_background_light(node: Node, f: Fields, system: str) -> Node:
    texture = f.string("texture", "mountains")
    if texture not in _SKY:
        raise f.error("texture", f"unknown background {texture!r} (one of {', '.join(sorted(_SKY))})")
    d, colour, intensity, on = _SKY[texture]
    if system == "ENU":
        d = (d[2], d[0], d[1])
    return _node("DirectionalLight", node, ambientIntensity=1.0, direction=d, color=colour,
                 intensity=max(f.num("luminosity", 1.0), 0.0) * intensity, on=on)


BUILTIN_PROTOS: dict[str, Callable[[Node, Fields, str], Node]] = {
    "RectangleArena": rectangle_arena, "Floor": floor, "SolidBox": solid_box, "WoodenBox": wooden_box,
    "TexturedBackgroundLight": textured_background_light,
}
