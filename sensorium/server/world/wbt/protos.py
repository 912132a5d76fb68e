"""Built-in PROTOs: the most common Webots world-building PROTOs, expanded into base nodes.

Geometry and defaults follow the PROTOs' published fields (R2022a+, z up): RectangleArena, Floor,
SolidBox, WoodenBox, CircleArena, SolidPipe, and TexturedBackgroundLight (the directional light
matching each background, which light sensors do see). Textured default appearances (parquetry,
brushed aluminium, wood, SolidPipe's tagged wall) are not sampled: such surfaces read as white to
infra-red sensors, like a shape without appearance.

CircleArena and SolidPipe are made with their templates' arithmetic, operation for operation in
float64 (the numbers Webots' template text carries are the doubles themselves), so every vertex and
box is the one Webots makes: the pipe's rendered ring (an IndexedFaceSet: what visual rays see) and
PipeBoundingObject's boxes (what bounding rays and contact see), their z jitter drawn from
wbrandom's generator as a template run starts it. A value the template replaces is replaced the same
way, with the template's own message as a warning at the field's line.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from sensorium.server.world.wbt import resets
from sensorium.server.world.wbt.fields import Fields
from sensorium.server.world.wbt.parser import Node

# a pipe's subdivisions are its boxes, each a shape: more than the shapes a world may hold
# (convert.MAX_PARTS) could never load, so they are refused before a node is made
MAX_PIPE_SUBDIVISION = 200_000


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


def _js(v: float) -> str:
    """A number as a JavaScript template prints it (``1``, ``0.5``): in the templates' messages."""
    return str(int(v)) if float(v).is_integer() and abs(v) < 1e21 else repr(float(v))


def _replaced(f: Fields, name: str, message: str, who: str = "", then: str = "") -> None:
    """The template's own message about a value it replaces, a warning at the field's line (at the
    node when the field is not written); ``who``: the template that says it, when not the node's;
    ``then``: what it does then, when its message does not say."""
    written = f.node.fields.get(name)
    shown = f" {resets.shown(written)}" if isinstance(written, int | float) else ""
    if f.reset is None:
        raise f.error(name, message)
    who = who or f"Webots' {f.node.type}"
    f.reset(f.node, name, f"{f.node.type}.{name}{shown}: {message} (as {who} does{then})")


def _subdivision(f: Fields, default: int, at_least: int, message: str) -> int:
    n = f.integer("subdivision", default)
    if n > MAX_PIPE_SUBDIVISION:
        raise f.error("subdivision", f"{n:,} segments: more than {MAX_PIPE_SUBDIVISION:,} (each segment is a "
                                     "bounding box, a shape, and a world holds at most that many shapes here)")
    if n < at_least:
        _replaced(f, "subdivision", message)
        return 8
    return n


def _reset_positive(f: Fields, name: str, default: float) -> float:
    """A size the templates reset to its default when it is not > 0."""
    v = f.num(name, default)
    if v > 0:
        return v
    _replaced(f, name, f"'{name}' must be strictly positive. Value reset to {_js(default)}.")
    return default


class _WbRandom:
    """wbrandom.js's generator (a linear congruential one modulo 2^24, in doubles as JavaScript
    computes it), from the seed 0 every template run starts with."""

    def __init__(self) -> None:
        self.state = 0.0

    def real(self, lo: float, hi: float) -> float:
        self.state = math.fmod(1140671485.0 * self.state + 12820163.0, 16777216.0)
        return lo + self.state * (hi - lo) / (16777216.0 - 1.0)


def _turn_about_z(angle: float) -> tuple[float, float, float, float]:
    """wbrotation.combine(identity, (0 0 1 angle)) as Webots computes it: the angle brought into
    [-pi, pi], through the quaternion and back by acos (an angle under 1e-4 is no turn: 0 1 0 0)."""
    while angle < -math.pi:
        angle = angle + 2 * math.pi
    while angle > math.pi:
        angle = angle - 2 * math.pi
    half = angle * 0.5
    w, z = math.cos(half), math.sin(half)
    a = 2 * math.acos(w)
    if a < 0.0001:
        return (0.0, 1.0, 0.0, 0.0)
    return (0.0, 0.0, z / math.sqrt(z * z), a)


def _circle(radius: float, n: int, shift: float) -> list[tuple[float, float]]:
    """wbgeometry.circle: n + 1 points (the first repeated last) from the angle ``shift``."""
    quantum = 2 * math.pi / n
    return [(radius * math.cos(i * quantum + shift) + 0.0, radius * math.sin(i * quantum + shift) + 0.0)
            for i in range(n + 1)]


def _pipe(at: Node, *, radius: float, height: float, thickness: float, n: int, accuracy: float,
          appearance: Node | None, bounded: bool, too_thin: Callable[[], None], **solid) -> Node:
    """SolidPipe's Solid (``solid``: its translation, rotation, name and physics) from checked values:
    the rendered ring and, when ``bounded``, PipeBoundingObject's n boxes. ``too_thin`` is told when
    the thickness is under the ring's sagitta (both templates then take the gap's absolute value)."""
    beta = 2.0 * math.pi / n
    alpha = beta * 0.5
    inner = radius - thickness
    gap = radius * math.cos(alpha) - inner      # SolidPipe's su, PipeBoundingObject's sv: the same number
    if gap < 0:
        too_thin()
        gap = abs(gap)
    # the ring: top outer, top inner, bottom outer, bottom inner circles; quads top, bottom, inner, outer
    outer_ring = _circle(radius, n, -math.pi * 0.5)
    inner_ring = _circle(radius - gap, n, -math.pi * 0.5)
    points: list[float] = []
    for ring, z in ((outer_ring, height * 0.5), (inner_ring, height * 0.5), (outer_ring, -height * 0.5),
                    (inner_ring, -height * 0.5)):
        for x, y in ring:
            points += (x, y, z)
    m = n + 1
    top_out, top_in, bottom_out, bottom_in = 0, m, 2 * m, 3 * m
    quads = ([(top_out + i, top_out + i + 1, top_in + i + 1, top_in + i) for i in range(n)]
             + [(bottom_out + i, bottom_in + i, bottom_in + i + 1, bottom_out + i + 1) for i in range(n)]
             + [(top_in + i, top_in + i + 1, bottom_in + i + 1, bottom_in + i) for i in range(n)]
             + [(top_out + i, bottom_out + i, bottom_out + i + 1, top_out + i + 1) for i in range(n)])
    index = [float(v) for quad in quads for v in (*quad, -1)]
    ring = _node("IndexedFaceSet", at, coord=_node("Coordinate", at, point=points), coordIndex=index, creaseAngle=1.5)
    extra: dict = {}
    if bounded:     # PipeBoundingObject, as SolidPipe instantiates it (at its own origin, unturned)
        side = radius * math.sin(alpha) * 2.0
        box_radius = inner + gap * 0.5
        size = (side, gap, height)
        draw = _WbRandom()
        boxes = []
        for i in range(n):
            gamma = beta * i + beta * 0.5 + (n % 2) * math.pi / n
            z = draw.real(-1.0, 1.0) * accuracy    # its jitter off the top and bottom faces' coplanarity
            boxes.append(_node("Pose", at, translation=(box_radius * math.cos(gamma), box_radius * math.sin(gamma), z),
                               rotation=_turn_about_z(gamma + 0.5 * math.pi), children=[_node("Box", at, size=size)]))
        extra["boundingObject"] = _node("Group", at, children=boxes)
    return _node("Solid", at, children=[_node("Shape", at, appearance=appearance, geometry=ring)], model="pipe",
                 **solid, **extra)


def solid_pipe(node: Node, f: Fields, system: str) -> Node:
    n = _subdivision(f, 24, 8, "'subdivision' must be greater or equal to 8. Using 8 instead.")
    height = _reset_positive(f, "height", 2.0)
    written_radius = f.num("radius", 1.0)
    radius = _reset_positive(f, "radius", 1.0)
    thickness = f.num("thickness", 0.1)
    if thickness <= 0:
        thickness = radius * 0.5
        _replaced(f, "thickness", f"'thickness' must be greater than 0. Value reset to {_js(thickness)}.")
    elif thickness >= written_radius:     # the template compares with the radius as written
        thickness = radius * 0.5
        _replaced(f, "thickness", f"'thickness' must be smaller than 'radius'. Value reset to {_js(thickness)}.")
    default = _node("PBRAppearance", node, roughness=0.5, metalness=0.0)   # its textured default, untextured
    physics = {"physics": f.node_("physics")} if f.node_("physics") is not None else {}
    return _pipe(node, radius=radius, height=height, thickness=thickness, n=n, accuracy=f.num("accuracy", 0.0001),
                 appearance=_appearance(f, "appearance", default), bounded=f.flag("enableBoundingObject", True),
                 too_thin=lambda: _replaced(f, "thickness", _TOO_THIN, then=_ABS),
                 translation=f.vec("translation", (0.0, 0.0, 1.0)), rotation=f.vec("rotation", (0.0, 0.0, 1.0, 0.0)),
                 name=f.string("name", "pipe"), **physics)


_TOO_THIN = "Either 'thickness' or 'subdivision' are too small for the box subdivision algorithm."
_ABS = ": the ring and boxes are made with the gap's absolute value"


def circle_arena(node: Node, f: Fields, system: str) -> Node:
    n = _subdivision(f, 48, 9, "'subdivision' must be greater than 8. Using 8 instead.")
    radius = _reset_positive(f, "radius", 1.0)
    thickness = _reset_positive(f, "wallThickness", 0.01)
    height = _reset_positive(f, "wallHeight", 0.1)
    wall = _pipe(node, radius=radius + thickness, height=height, thickness=thickness, n=n, accuracy=0.0001,
                 appearance=_appearance(f, "wallAppearance"), bounded=True,
                 too_thin=lambda: _replaced(f, "wallThickness", _TOO_THIN, "the SolidPipe of Webots' CircleArena", _ABS),
                 translation=(0.0, 0.0, height / 2), rotation=(0.0, 0.0, 1.0, 0.0), name="pipe")
    # the floor: a fan over the circle through the wall's middle (its first triangle, 0 0 1, has no area)
    rim = _circle(radius + thickness * 0.5, n, 0.0)
    disc = _node("IndexedFaceSet", node, coord=_node("Coordinate", node, point=[v for x, y in rim for v in (x, y, 0.0)]),
                 coordIndex=[float(v) for j in range(n) for v in (0, j, j + 1, -1)])
    return _node("Solid", node, translation=f.vec("translation", (0.0, 0.0, 0.0)),
                 rotation=f.vec("rotation", (0.0, 0.0, 1.0, 0.0)), name=f.string("name", "circle arena"),
                 children=[wall, _node("Shape", node, appearance=_appearance(f, "floorAppearance"), geometry=disc)],
                 boundingObject=_node("Plane", node, size=(2 * radius, 2 * radius)), model="circle arena")


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
    "CircleArena": circle_arena, "SolidPipe": solid_pipe, "TexturedBackgroundLight": textured_background_light,
}

_SOLID = ("translation", "rotation", "name", "contactMaterial")
BUILTIN_FIELDS: dict[str, frozenset[str]] = {
    # each stand-in's PROTO interface as Webots' releases publish it (hidden deprecated fields included):
    # an instance field outside it is a typo Webots would skip with an error
    "RectangleArena": frozenset((*_SOLID, "floorSize", "floorTileSize", "floorAppearance", "wallThickness",
                                 "wallHeight", "wallAppearance", "floorTextureUrl", "wallTextureUrl", "wallColor",
                                 "wallTileSize")),
    "Floor": frozenset((*_SOLID, "size", "tileSize", "appearance", "texture")),
    "SolidBox": frozenset((*_SOLID, "size", "appearance", "physics", "enableBoundingObject", "castShadows",
                           "recognitionColors")),
    "WoodenBox": frozenset(("translation", "rotation", "name", "size", "mass", "immersionProperties", "locked")),
    "CircleArena": frozenset((*_SOLID, "radius", "floorAppearance", "floorTileSize", "wallThickness", "wallHeight",
                              "wallAppearance", "subdivision", "floorTextureUrl", "wallTextureUrl", "wallTileSize")),
    "SolidPipe": frozenset((*_SOLID, "height", "radius", "thickness", "subdivision", "accuracy", "appearance",
                            "physics", "enableBoundingObject")),
    "TexturedBackgroundLight": frozenset(("texture", "luminosity", "castShadows")),
}
