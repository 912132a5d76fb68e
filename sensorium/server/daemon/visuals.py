"""The Supervisor's imported visual nodes (sans-IO): a ``Shape``, or a ``Group`` of shapes, that a
Supervisor imported at the root (Webots' ``supervisor_draw_trail`` pattern: a Shape holding an
``IndexedLineSet`` whose points it moves every few steps).

sim/imports.py imports such a node as a solid without boundingObject holding it (what a world file
makes of a top-level Shape: its area geometry is seen by every sensor from the next step); the
string's nodes themselves (``ImportedNode.visual``, the parsed tree) are served here: the root
under its own type (``Shape``, ``Group``) with the backing solid's id, each node inside it
(``Appearance``, ``Material``, geometry, ``Coordinate``, ``Color``, ...) with an id from
:data:`FIRST_ID` on, in import order, depth first (never reused). Their fields read what the string
wrote, Webots' defaults otherwise. The MF fields of a line or point set (its ``coordIndex`` and
``colorIndex``, its ``Coordinate``'s ``point``, its ``Color``'s ``color``) are set, inserted into
and removed from (Webots' index rules; at most :data:`MAX_ITEMS` items), with no effect on any
sensor: no sensor here sees lines or points. Everything else is read-only (one line).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from sensorium.server.daemon.mf_items import item_position
from sensorium.server.world.limits import MAX_COORDINATE_M
from sensorium.server.world.wbt.fields import GEOMETRY_FIELDS, MATERIAL_FIELDS, PBR_FIELDS, TEXTURE_FIELDS

FIRST_ID = 1 << 25
"""The first id of a node inside an imported visual node (above the nested nodes' range, nested.py)."""

MAX_ITEMS = 100_000
"""The most items an MF field of an imported line or point set holds (a set or insert past it is refused)."""

ROOTS = frozenset({"Shape", "Group"})
"""The visual nodes imported at the root as themselves (a Pose or Transform of shapes is a Solid: imports.py)."""

INSIDE = frozenset({"Shape", "Group", "Pose", "Transform"})
"""What a visual root may hold (through its children)."""

LINES = frozenset({"IndexedLineSet", "PointSet"})
AREAS = frozenset({"Box", "Sphere", "Cylinder", "Capsule", "Cone", "Plane", "IndexedFaceSet", "ElevationGrid", "Mesh"})
"""Geometries sensors see: their Shape is one of the import's solid's shapes (its colours set as a world file's)."""
"""Geometries no sensor sees here: their MF fields are set freely."""

_POSE = {"translation": ("SFVec3f", (0.0, 0.0, 0.0)), "rotation": ("SFRotation", (0.0, 0.0, 1.0, 0.0))}
TABLES: dict[str, dict[str, tuple[str, Any]]] = {
    "Shape": {"appearance": ("SFNode", None), "geometry": ("SFNode", None), "castShadows": ("SFBool", True),
              "isPickable": ("SFBool", True)},
    "Group": {"children": ("MFNode", ())},
    "Pose": {**_POSE, "children": ("MFNode", ())},
    "Transform": {**_POSE, "scale": ("SFVec3f", (1.0, 1.0, 1.0)), "children": ("MFNode", ())},
    "Appearance": {"material": ("SFNode", None), "texture": ("SFNode", None), "textureTransform": ("SFNode", None),
                   "name": ("SFString", "appearance")},
    "PBRAppearance": {**PBR_FIELDS, "baseColorMap": ("SFNode", None), "name": ("SFString", "PBRAppearance")},
    "Material": dict(MATERIAL_FIELDS),
    "ImageTexture": dict(TEXTURE_FIELDS),
    **{k: dict(v) for k, v in GEOMETRY_FIELDS.items()},
    "IndexedLineSet": {"coord": ("SFNode", None), "coordIndex": ("MFInt32", ()), "color": ("SFNode", None),
                       "colorIndex": ("MFInt32", ()), "colorPerVertex": ("SFBool", True)},
    "PointSet": {"coord": ("SFNode", None), "color": ("SFNode", None)},
    "IndexedFaceSet": {"coord": ("SFNode", None), "coordIndex": ("MFInt32", ()), "solid": ("SFBool", True),
                       "ccw": ("SFBool", True), "creaseAngle": ("SFFloat", 0.0)},
    "ElevationGrid": {"xDimension": ("SFInt32", 0), "yDimension": ("SFInt32", 0), "xSpacing": ("SFFloat", 1.0),
                      "ySpacing": ("SFFloat", 1.0), "height": ("MFFloat", ()), "thickness": ("SFFloat", 0.0)},
    "Mesh": {"url": ("MFString", ()), "ccw": ("SFBool", True), "name": ("SFString", ""),
             "materialIndex": ("SFInt32", -1)},
    "Coordinate": {"point": ("MFVec3f", ())},
    "Color": {"color": ("MFColor", ())},
}
"""Each served node type's fields (Webots' names, types and defaults); a field not listed is not served."""

_WIDTH = {"MFVec3f": 3, "MFColor": 3, "MFVec2f": 2, "MFRotation": 4, "SFVec3f": 3, "SFColor": 3, "SFVec2f": 2,
          "SFRotation": 4}
SF_SLOTS = {"IndexedLineSet": {"coord": "Coordinate", "color": "Color"}, "PointSet": {"coord": "Coordinate",
                                                                                        "color": "Color"}}
"""The SFNode fields a node string is imported into (when empty), with the node type each takes."""
SETTABLE = {"IndexedLineSet": ("coordIndex", "colorIndex"), "Coordinate": ("point",), "Color": ("color",)}
"""The MF fields set here, on nodes of a line or point set only."""


@dataclass
class VNode:
    id: int
    type: str
    def_name: str
    parent: int                   # the parent's id (the root's: 0, the scene's root)
    field: str                    # the parent's field holding it
    key: str                      # the backing solid's name (the import's)
    values: dict[str, Any] = field(default_factory=dict)    # field -> value (SFNode: id; MFNode: ids)
    inert: bool = False           # inside a line or point set: no sensor sees it
    shape: int = -1               # its area Shape's place among the import's (the solid's shapes), -1: none
    role: str = ""                # in that Shape: "Shape", "appearance", "material", "texture", "geometry"


@dataclass
class Store:
    """Every imported visual node, by id (roots keep their top-level id)."""

    nodes: dict[int, VNode] = field(default_factory=dict)
    _areas: int = 0
    roots: dict[str, int] = field(default_factory=dict)     # backing solid name -> the root's id
    next_id: int = FIRST_ID

    def add(self, key: str, root_id: int, written: Any) -> None:
        """The parsed tree of an import (``written``: a parser Node) under ``root_id``."""
        if key in self.roots:
            return
        self.roots[key] = root_id
        self._areas = 0
        self._node(written, root_id, 0, "children", key, False, -1)

    def _node(self, w: Any, node_id: int, parent: int, held: str, key: str, inert: bool, shape: int) -> None:
        inert = inert or w.type in LINES
        role = ""
        if w.type == "Shape":
            geometry = w.fields.get("geometry")
            shape, role = -1, "Shape"
            if hasattr(geometry, "type") and geometry.type in AREAS:    # the solid's next shape (the converter's order)
                shape, self._areas = self._areas, self._areas + 1
        elif shape >= 0:
            role = {"appearance": "appearance", "material": "material", "texture": "texture",
                    "baseColorMap": "texture", "geometry": "geometry"}.get(held, "")
        me = VNode(node_id, w.type, w.def_name or "", parent, held, key, inert=inert, shape=shape, role=role)
        self.nodes[node_id] = me
        for name, (kind, default) in TABLES.get(w.type, {}).items():
            value = w.fields.get(name)
            if kind == "SFNode":
                if value is not None and hasattr(value, "type") and value.type in TABLES:
                    child = self.next_id
                    self.next_id += 1
                    self._node(value, child, node_id, name, key, inert, shape)
                    me.values[name] = child
                else:
                    me.values[name] = 0
            elif kind == "MFNode":
                ids = []
                for c in value if isinstance(value, list) else []:
                    if hasattr(c, "type") and c.type in TABLES:
                        child = self.next_id
                        self.next_id += 1
                        self._node(c, child, node_id, name, key, inert, -1)
                        ids.append(child)
                me.values[name] = ids
            else:
                me.values[name] = _read(kind, value, default)

    def attach(self, parent: VNode, name: str, written: Any) -> int:
        """Webots' ``importSFNodeFromString`` into an empty slot of an imported line or point set (its
        ``coord`` takes a ``Coordinate``, its ``color`` a ``Color``): the node joins with the next id, as
        written; ValueError (one line, nothing changed) for any other field, a full slot or another node type."""
        kind = fields(parent).get(name)
        where = f"field {name!r} ({kind}) of {what(parent)}"
        want = SF_SLOTS.get(parent.type, {}).get(name) if parent.inert else None
        if want is None:
            raise ValueError(f"{where} is read-only here: a node string is imported into the empty coord or color of "
                             "an imported line or point set only; nothing changed")
        if parent.values.get(name, 0):
            raise ValueError(f"{where} is not empty (Webots imports into an empty SFNode field only: remove its "
                             "node first, or import the whole shape again); nothing changed")
        if getattr(written, "type", None) != want:
            raise ValueError(f"{where} takes a {want} node here, got {getattr(written, 'type', written)!r}; nothing "
                             "changed")
        child = first = self.next_id
        self.next_id += 1
        self._node(written, child, parent.id, name, parent.key, True, -1)
        me = self.nodes[child]
        try:             # its lists as the item setters check them: at most MAX_ITEMS, each item in range
            for field_name in SETTABLE.get(me.type, ()):
                items = me.values[field_name]
                if len(items) > MAX_ITEMS:
                    raise ValueError(f"field {field_name!r} of {what(me)}: {len(items):,} items, more than the "
                                     f"{MAX_ITEMS:,} an imported line or point set's field holds here; nothing changed")
                for item in items:
                    _item(me, field_name, fields(me)[field_name], item)
        except ValueError:
            for i in range(first, self.next_id):
                self.nodes.pop(i, None)
            self.next_id = first
            raise
        parent.values[name] = child
        return child

    def detach(self, parent: VNode, name: str) -> None:
        """Webots' ``removeSF`` on the ``coord`` or ``color`` of an imported line or point set: its node and
        those inside it leave (their ids read as removed, never given again), the slot is empty; ValueError
        (one line, nothing changed) for any other field."""
        if not (parent.inert and name in SF_SLOTS.get(parent.type, {})):
            raise ValueError(f"field {name!r} of {what(parent)} is read-only here: removeSF takes the node out of the "
                             "coord or color of an imported line or point set only; nothing changed")
        child = parent.values.get(name, 0)
        if not child:
            return
        for n in [self.nodes[child], *self.inside(child)]:
            del self.nodes[n.id]
        parent.values[name] = 0

    def inside(self, root_id: int) -> list[VNode]:
        """The nodes inside a root, depth first (its own fields' order)."""
        out: list[VNode] = []

        def walk(n: VNode) -> None:
            for name, (kind, _) in TABLES.get(n.type, {}).items():
                ids = [n.values.get(name, 0)] if kind == "SFNode" else n.values.get(name, []) if kind == "MFNode" else []
                for i in ids:
                    if i:
                        out.append(self.nodes[i])
                        walk(self.nodes[i])

        walk(self.nodes[root_id])
        return out


def _read(kind: str, value: Any, default: Any) -> Any:
    """A written value in the form a getter answers (Webots' default when not written or not of its type)."""
    if value is None:
        value = default
    try:
        if kind == "SFBool":
            return bool(value) if isinstance(value, bool) else bool(default)
        if kind == "SFInt32":
            return int(value[0] if isinstance(value, list) else value)
        if kind == "SFFloat":
            return float(value[0] if isinstance(value, list) else value)
        if kind == "SFString":
            return str(value[0] if isinstance(value, list) and value else value)
        if kind in _WIDTH and kind.startswith("SF"):
            return [float(v) for v in value][:_WIDTH[kind]]
        if kind == "MFInt32":
            return [int(v) for v in value]
        if kind in ("MFFloat",):
            return [float(v) for v in value]
        if kind == "MFString":
            return [str(v) for v in (value if isinstance(value, list | tuple) else [value])]
        if kind in _WIDTH:
            flat, w = [float(v) for v in value], _WIDTH[kind]
            return [flat[i:i + w] for i in range(0, len(flat) - len(flat) % w, w)]
    except (TypeError, ValueError):
        pass
    return _read(kind, default, default) if value is not default else default


def what(n: VNode) -> str:
    return f"{n.type} {n.def_name!r} (node {n.id})" if n.def_name else f"{n.type} (node {n.id})"


def fields(n: VNode) -> dict[str, str]:
    """The node's field names -> types."""
    return {name: kind for name, (kind, _) in TABLES.get(n.type, {}).items()}


def settable(n: VNode, name: str) -> bool:
    return n.inert and name in SETTABLE.get(n.type, ())


def read_only_line(n: VNode, name: str, kind: str) -> str:
    return (f"field {name!r} ({kind}) of {what(n)} is read-only here: of an imported visual node a Supervisor sets "
            "the MF fields of a line or point set (an IndexedLineSet's coordIndex and colorIndex, its Coordinate's "
            "point, its Color's color) only; nothing changed")


def _item(n: VNode, name: str, kind: str, value: Any) -> Any:
    """A value checked for one item of ``kind`` (ValueError: one line)."""
    where = f"field {name!r} ({kind}) of {what(n)}"
    if kind == "MFInt32":
        if isinstance(value, bool) or not isinstance(value, int | float) or not float(value).is_integer() or \
                not -1 <= value < 1 << 31:
            raise ValueError(f"{where}: an index is a whole number from -1 (the end of a line) to 2^31 - 1, got "
                             f"{value!r}; nothing changed")
        return int(value)
    width = _WIDTH[kind]
    if not isinstance(value, list) or len(value) != width or any(
            isinstance(v, bool) or not isinstance(v, int | float) for v in value):
        raise ValueError(f"{where}: takes {width} numbers, got {value!r}; nothing changed")
    out = [float(v) for v in value]
    if kind == "MFColor" and not all(0.0 <= v <= 1.0 for v in out):
        raise ValueError(f"{where}: each component must be in [0, 1], got {value!r}; nothing changed")
    if not all(math.isfinite(v) and abs(v) <= MAX_COORDINATE_M for v in out):
        raise ValueError(f"{where}: each coordinate must be finite and within ±{MAX_COORDINATE_M:g} m, got "
                         f"{value!r}; nothing changed")
    return out


def change(n: VNode, name: str, op: str, index: int, value: Any) -> None:
    """Webots' ``setMF*`` (op ``set``), ``insertMF*`` (``insert``) and ``removeMF`` (``remove``) on a
    settable field (:func:`settable`): index negative from the end, as Webots; ValueError (one line,
    nothing changed) for an index out of bounds, a value of the wrong type, a field past :data:`MAX_ITEMS`."""
    kind = fields(n)[name]
    items: list = n.values[name]
    count = len(items)
    where = f"field {name!r} ({kind}) of {what(n)}"
    at = item_position(where, op, index, count)
    if op == "insert":
        if count >= MAX_ITEMS:
            raise ValueError(f"{where}: it holds {count:,} items, the most an imported line or point set's field "
                             f"holds here ({MAX_ITEMS:,}); nothing changed")
        items.insert(at, _item(n, name, kind, value))
    elif op == "remove":
        del items[at]
    else:
        items[at] = _item(n, name, kind, value)


__all__ = ["FIRST_ID", "MAX_ITEMS", "ROOTS", "INSIDE", "LINES", "TABLES", "VNode", "Store", "fields", "settable",
           "change", "what", "read_only_line", "SF_SLOTS"]
