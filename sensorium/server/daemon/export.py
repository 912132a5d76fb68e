"""A Supervisor's ``exportString`` and ``worldSave`` (sans-IO): nodes and the whole world as ``.wbt`` text.

A top-level node is written from the node as the world file (or the node string it was imported from)
wrote it, with the fields the server keeps written as they are now: a robot's or solid's ``translation``
and ``rotation`` (where it drove or a Supervisor put it), ``name``, ``customData``, ``controller``,
``radarCrossSection``; a light's fields; a PROTO instance's fields that pass through IS to those (its
other fields as last set: a set builds the solid again from its written node, sim/regenerate.py). A field
whose value is Webots' default is left out, as Webots writes only the fields that differ from it.
A node inside a robot or solid (nested.py) is found where its owner's file writes it (``Nested.at``, the
import's line and column; a joint's ``jointParameters`` and a shape's appearance, material, texture and
geometry in their parent's field) and written so, with what the server changed since: an end point's pose
its joint moved, a joint's ``position``, a shape's fields a Supervisor set; exportString answers it alone,
and the top-level node and ``worldSave`` holding it write it so too. A node a PROTO's body made is found in
its top-level node written, its PROTOs expanded again (``Nested.made``: its place in that body) and written as
Webots writes it: as the body writes it, a PROTO instance in it as that instance. Text only: the client writes ``worldSave``'s file (the server
never writes a path a client names)."""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

import numpy as np

from sensorium.server.daemon import nested
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.regenerate import reparsed_world, written_value
from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.wbt.parser import Node as ParsedNode
from sensorium.server.world.wbt.parser import WbtFile, WbtSyntaxError
from sensorium.server.world.wbt.write import Writer

_POSE = {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 1.0, 0.0]}
_LIGHT = {"on": True, "intensity": 1.0, "color": [1.0, 1.0, 1.0], "ambientIntensity": 0.0, "castShadows": False}
_LOCAL = {"location": [0.0, 0.0, 0.0], "attenuation": [1.0, 0.0, 0.0], "radius": 100.0}
DEFAULTS: dict[str, dict[str, Any]] = {
    # a .wbt robot without a controller reads "<extern>" here (Webots' default is "<generic>"): one set to
    # "<extern>" keeps its field written, and one never written stays unwritten
    "Robot": {**_POSE, "name": "robot", "model": "", "radarCrossSection": 0.0, "customData": "",
              "controller": "<extern>", "supervisor": False, "synchronization": True,
              "battery": [], "cpuConsumption": 10.0},     # (WbRobot writes its energy now in its field each step)
    "Solid": {**_POSE, "name": "solid", "model": "", "radarCrossSection": 0.0},
    "PointLight": {**_LIGHT, **_LOCAL},
    "SpotLight": {**_LIGHT, **_LOCAL, "direction": [0.0, 0.0, -1.0], "beamWidth": 1.570796, "cutOffAngle": 0.785398},
    "DirectionalLight": {**_LIGHT, "direction": [0.0, 0.0, -1.0]},
}
"""Webots' defaults (its reference manual) of the fields written from the server's state: a field at its
default is not written."""

_FIRST = ("translation", "rotation")      # Webots declares them first: a pose field not written goes first


_IN_PARENT = frozenset({"jointParameters", "appearance", "material", "texture", "baseColorMap", "geometry"})
"""The SF fields whose nested node is found in its parent's written node (it has no place of its own)."""

_PLACES_KEPT = 256
"""The most written top-level nodes whose places are kept (each one's table made again when dropped)."""

_NESTED_POSE = {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 1.0, 0.0]}


class NotExported(ValueError):
    """A node with no ``.wbt`` text here: one line, what and why."""


def _world_file(sim: Any) -> WbtFile | None:
    """The world file parsed again (once; None for a YAML or JSON world)."""
    kept = getattr(sim, "_export_world", None)
    if kept is not None:
        return kept or None
    wbt = reparsed_world(sim, NotExported)
    sim._export_world = wbt if wbt is not None else ()
    return wbt


def _written(sim: Any, node: sv.Node) -> ParsedNode:
    """The node as written: the world file's top-level node it alone became, or the node string's."""
    why = "the world was not loaded from a .wbt file" if _world_file(sim) is None else \
        "it is not one top-level node of the world file (a node it became among others, or shapes outside any solid)"
    if node.nested:
        table = sv._table(sim)
        n = table.get(node.id)
        assert n is not None
        return _nested_written(sim, table, n)
    if node.visual and node.id >= sv.visuals.FIRST_ID:
        raise NotExported(f"{sv._what(node)} is inside an imported Shape or Group: exportString serves the root's "
                          "children here")
    if node.id == 0:
        raise NotExported("the root node is not exported: worldSave writes the whole world")
    key = node.key
    if node.visual:
        written = getattr(sim, "imported_visuals", {}).get(key)
    elif key in getattr(sim, "_regen_written", {}) and not node.scenery:
        written = sim._regen_written[key]
    elif not node.scenery and key in getattr(sim, "imported_written", {}):
        written = sim.imported_written[key]
    else:
        wbt = _world_file(sim)
        at = sim.top_level.written.get(_place(sim, node)) if wbt is not None else None
        written = wbt.nodes[at] if wbt is not None and at is not None and _became(sim)[at] == 1 else None
    if written is None:
        raise NotExported(f"{sv._what(node)} has no .wbt text here: {why}")
    return written


def _places(root: ParsedNode) -> dict[tuple[int, ...], ParsedNode]:
    """Every node written inside ``root`` (itself included) by its (line, column)."""
    out: dict[tuple[int, ...], ParsedNode] = {}
    todo: list[Any] = [root]
    while todo:
        v = todo.pop()
        if isinstance(v, ParsedNode):
            if (v.line, v.col) not in out:
                out[(v.line, v.col)] = v
                todo.extend(v.fields.values())
        elif isinstance(v, list):
            todo.extend(v)
    return out


def _owner_places(sim: Any, owner: int) -> dict[tuple[int, ...], ParsedNode]:
    """The nodes written inside the top-level node ``owner`` as written (the whole world file's when it is no one
    top-level node of it), by (line, column); kept per written node."""
    try:
        roots = [_written(sim, sv.node_by_id(sim, owner))]
    except NotExported:
        wbt = _world_file(sim)
        roots = list(wbt.nodes) if wbt is not None else []
    kept = getattr(sim, "_export_places", None)
    if kept is None or len(kept) > _PLACES_KEPT:       # (imports and rebuilds for days: bounded)
        kept = sim._export_places = {}
    out: dict[tuple[int, ...], ParsedNode] = {}
    for root in roots:
        if id(root) not in kept or kept[id(root)][0] is not root:
            kept[id(root)] = (root, _places(root))
        out.update(kept[id(root)][1])
    return out


def _maker(sim: Any, table: nested.Table, n: nested.Nested) -> str:
    """The PROTO instance written in the file whose body (or a PROTO's inside it) made nested node ``n``: the
    nearest written instance holding it."""
    above: nested.Nested | None = n
    while above is not None:
        if above.proto and above.at:
            return f"PROTO {above.proto}"
        if above.parent == above.owner:
            break
        above = table.get(above.parent)
    proto = sv.node_by_id(sim, n.owner).proto
    return f"PROTO {proto}" if proto else "a PROTO"


def _found(sim: Any, table: nested.Table, n: nested.Nested) -> ParsedNode | None:
    """A nested node as its owner's file writes it: at its place (``Nested.at``), or in its parent's field;
    None when no file writes it."""
    if n.at:
        return _owner_places(sim, n.owner).get(n.at)
    parent = table.get(n.parent) if n.field in _IN_PARENT else None
    above = None if parent is None else _found(sim, table, parent)
    value = None if above is None else above.fields.get(n.field)
    return value if isinstance(value, ParsedNode) else None


def _nested_written(sim: Any, table: nested.Table, n: nested.Nested) -> ParsedNode:
    """A nested node as its owner's file writes it (NotExported: one line)."""
    if _world_file(sim) is None and n.owner not in table.segments:
        raise NotExported(f"{sv._what(sv._nested_node(n))} has no .wbt text here: the world was not loaded from a "
                          ".wbt file")
    found = _found(sim, table, n)
    if found is not None:
        return found
    what = f"{sv._what(sv._nested_node(n))} is made by the body of {_maker(sim, table, n)}"
    try:
        made = _made(sim, table, n, {})
    except NotExported as exc:
        raise NotExported(f"{what}: {exc}") from None
    if made is not None:
        return made
    raise NotExported(f"{what}, and that body's node is not found where the world's PROTOs make it again here: it "
                      "has no .wbt text here")


def _shape_changed(sim: Any, shape: int) -> bool:
    """Whether a shape's nodes hold a field the server changed: one a Supervisor set, or the
    ``emissiveColor`` a Charger makes glow."""
    return shape in sim.scene.appearance_values or sim.scene.glow_of(shape) is not None


def _made_string(sim: Any, table: nested.Table, n: nested.Nested) -> str:
    """A PROTO body's node ``n`` as text (:func:`_made`), with what the server changed in it and the nodes
    inside it (an end point's pose its joint moved, a joint's ``position``, a shape's fields a Supervisor set)."""
    memo: dict[int, ParsedNode | None] = {}
    found = _made_node(sim, table, n, memo)
    assert found is not None            # (_written found it)
    done: dict[int, ParsedNode] = {}
    out = _as_webots_writes(found, done)
    changed: dict[int, dict[str, Any]] = {}
    for m in table.by_owner.get(n.owner, ()):
        if not (m.motor or m.joint or m.shape is not None and _shape_changed(sim, m.shape.index)):
            continue             # nothing the server changes
        now = _nested_now(sim, table, m)
        at = _made_node(sim, table, m, memo) if now else None
        mine = None if at is None else done.get(id(at))
        if mine is not None:
            changed[id(mine)] = _overlay(mine, now)
    return Writer(lambda w: changed.get(id(w))).node(out, 0, changed.get(id(out)))


def _expanded(sim: Any, owner: int) -> tuple[ParsedNode, str]:
    """Top-level node ``owner`` as written, its PROTO instances expanded again (the load's expansion: templates
    run within the world's PROTO limits), and the file it is written in (its ``source``); kept per written node."""
    from sensorium.server.sim.imports import string_file, world_protos
    from sensorium.server.world.proto import ProtoError, ProtoSearch, expand

    node = sv.node_by_id(sim, owner)
    written = _written(sim, node)
    kept = getattr(sim, "_export_expanded", None)
    if kept is None or len(kept) > _PLACES_KEPT:
        kept = sim._export_expanded = {}
    if id(written) in kept and kept[id(written)][0] is written:
        return kept[id(written)][1]
    if not node.scenery and node.key in getattr(sim, "imported_written", {}):
        if sim._import_protos is None:
            sim._import_protos = world_protos(sim.loaded, ProtoLimits.matching(sim.limits))
        file = string_file(sim.loaded, sim._import_protos)
    else:
        wbt = _world_file(sim)
        assert wbt is not None          # (_written found the node in it)
        file = wbt
    one = WbtFile(file.version, [written], [], file.source, list(file.declarations), list(file.protos))
    try:
        (root,) = expand(one, ProtoSearch.create(sim.loaded.base_dir), ProtoLimits.matching(sim.limits)).nodes
    except (ProtoError, WbtSyntaxError) as exc:
        raise NotExported(f"{sv._what(node)}: its PROTOs do not expand again: {exc.message}") from None
    kept[id(written)] = (written, (root, file.source))
    return root, file.source


def _made(sim: Any, table: nested.Table, n: nested.Nested, memo: dict[int, ParsedNode | None]) -> ParsedNode | None:
    """Nested node ``n`` as the PROTO body that made it writes it, as Webots writes such a node (its fields as
    the body gives them, its IS fields at the instance's values; a PROTO instance in it as that instance, its
    fields at other than their defaults); None when not found (:func:`_made_node`)."""
    found = _made_node(sim, table, n, memo)
    return None if found is None else _as_webots_writes(found, {})


def _made_node(sim: Any, table: nested.Table, n: nested.Nested, memo: dict[int, ParsedNode | None]) -> ParsedNode | None:
    """``n``'s node in its owner expanded again (:func:`_expanded`): found in its parent's, at its place in the
    world file (``Nested.at``) or in the body that made it (``Nested.made``); None when not found."""
    if n.id not in memo:
        if n.parent == n.owner:
            above: ParsedNode | None = _expanded(sim, n.owner)[0]
        else:
            parent = table.get(n.parent)
            above = None if parent is None else _made_node(sim, table, parent, memo)
        memo[n.id] = None if above is None else _in_expanded(above, n, _expanded(sim, n.owner)[1])
    return memo[n.id]


_SEARCHED = 100_000
"""The most nodes searched below a parent for a nested node's place (a body shares nodes: DEF/USE)."""


def _in_expanded(above: ParsedNode, n: nested.Nested, top: str) -> ParsedNode | None:
    """The node of ``above``'s expanded tree that ``n`` is: its SF field's node (a shape's appearance, ...), or
    the shallowest node at ``n``'s place (written in the file ``top``: ``n.at``; made by a body: ``n.made``)."""
    if n.field in _IN_PARENT:
        v = above.fields.get(n.field)
        return v if isinstance(v, ParsedNode) else None
    if not (n.at or n.made):
        return None

    def here(v: ParsedNode) -> bool:
        if v.instance_at is not None:
            return (v.instance_at[0] == top, tuple(v.instance_at[1:])) in ((True, n.at), (False, n.made))
        return ((v.source or top) == top, (v.line, v.col)) in ((True, n.at), (False, n.made))

    level: list[Any] = list(above.fields.values())
    seen: set[int] = set()
    while level and len(seen) < _SEARCHED:
        below: list[Any] = []
        for v in level:
            if isinstance(v, list):
                below.extend(v)
            elif isinstance(v, ParsedNode) and id(v) not in seen:
                seen.add(id(v))
                if here(v):
                    return v
                below.extend(v.fields.values())
        level = below
    return None


def _as_webots_writes(node: ParsedNode, done: dict[int, ParsedNode]) -> ParsedNode:
    """An expanded node as Webots writes it: a base node with its fields (the nodes in them so too), a PROTO
    instance as the instance (its fields whose values are not its PROTO's defaults; those values as given,
    unexpanded); a node met again is the same node (the writer's USE)."""
    if id(node) in done:
        return done[id(node)]
    face = node.__dict__.get("interface") if node.proto is not None else None
    if face is not None:
        proto, values = face[0], face[1]
        fields = {name: values[name] for name, decl in proto.fields.items()
                  if name in values and not _same_value(values[name], decl.default)}
        out = ParsedNode(proto.name, fields, node.line, node.col, node.def_name, source=node.source)
    else:
        out = ParsedNode(node.type, {}, node.line, node.col, node.def_name, source=node.source)
        done[id(node)] = out
        out.fields.update({name: _webots_value(v, done) for name, v in node.fields.items()})
    done[id(node)] = out
    return out


def _webots_value(v: Any, done: dict[int, ParsedNode]) -> Any:
    if isinstance(v, ParsedNode):
        return _as_webots_writes(v, done)
    if isinstance(v, list):
        return [_webots_value(x, done) for x in v]
    return v


def _same_value(a: Any, b: Any) -> bool:
    """Whether a PROTO field's value is its default (numbers compared as floats, lists item by item)."""
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same_value(x, y) for x, y in zip(a, b))
    if isinstance(a, ParsedNode) or isinstance(b, ParsedNode):
        return a is b
    if isinstance(a, int | float) and isinstance(b, int | float) and not isinstance(a, bool) and not isinstance(b, bool):
        return float(a) == float(b)
    return bool(a == b)


def _nested_now(sim: Any, table: nested.Table, n: nested.Nested) -> list[tuple[str, str, Any, Any]]:
    """(field, type, value now, Webots' default or None) of the fields of nested node ``n`` the server changed:
    an end point's pose its joint moved, a JointParameters' ``position``, a shape's fields a Supervisor set, a
    light's fields."""
    out: list[tuple[str, str, Any, Any]] = []
    if n.shape is not None:
        changed = [key.split(".", 1)[1] for key in sim.scene.appearance_values.get(n.shape.index, {})
                   if key.split(".", 1)[0] == n.shape.role]
        if sim.scene.glow_of(n.shape.index) is not None and n.shape.role in ("appearance", "material") \
                and "emissiveColor" not in changed:
            changed.append("emissiveColor")          # a Charger's glow (WbCharger writes the field each step)
        if changed:
            node = sv._nested_node(n)
            base = sv._base_fields(sim, node)
            out += [(name, base[name][0], base[name][1](sim, node), None) for name in changed if name in base]
        return out
    if n.light >= 0:       # a light's fields as they are now (a Supervisor's sets, a Charger's colour)
        node = sv._nested_node(n)
        defaults = DEFAULTS[n.type]
        out += [(name, kind, get(sim, node), defaults[name]) for name, (kind, get, _) in sv._base_fields(sim, node).items()
                if name in defaults]
    if n.motor:
        out.append(("position", "SFFloat", nested.joint_position(sim, n), 0.0))
    if n.own is not None and _moved(n.own, nested.own_pose(sim, table, n)):
        node = sv._nested_node(n)
        base = sv._base_fields(sim, node)
        out += [(name, base[name][0], base[name][1](sim, node), default) for name, default in _NESTED_POSE.items()]
    if n.interface:        # an instance's fields passing straight through IS to those
        face = n.interface[0].fields
        out = [(f.name, f.type, value, f.value) for name, kind, value, _ in out for f in face
               if f.base == name and f.type == kind]
    return out


def _moved(loaded: Any, now: Any) -> bool:
    """Whether a nested node's pose now is not the pose it loaded at (a rotation is compared as a matrix: its
    axis and angle read back may be written otherwise)."""
    return now is not loaded and not (np.allclose(now.translation, loaded.translation, rtol=0.0, atol=1e-12)
                                      and np.allclose(now.rotation, loaded.rotation, rtol=0.0, atol=1e-12))


def _overlay(written: ParsedNode, now: list[tuple[str, str, Any, Any]]) -> dict[str, Any]:
    """``written``'s fields with the values ``now`` where they differ (a field at ``default`` not added)."""
    fields = dict(written.fields)
    for name, kind, value, default in now:
        v = written_value(kind, value)
        if name in fields:
            if not _same(fields[name], v):
                fields[name] = v
        elif default is None or not _same(written_value(kind, default), v):
            fields = {name: v, **fields} if name in _FIRST else {**fields, name: v}
    return _pose_first(fields)


def _pose_first(fields: dict[str, Any]) -> dict[str, Any]:
    """``fields`` with ``translation`` before ``rotation`` (Webots' order) when both are written."""
    names = list(fields)
    if "rotation" in fields and "translation" in fields and names.index("rotation") < names.index("translation"):
        return {"translation": fields.pop("translation"), **fields}
    return fields


def _nested_fields(sim: Any, owner: int | None) -> dict[int, dict[str, Any]]:
    """id() of each nested node's written node -> its fields as they are now, for the nested nodes inside
    top-level node ``owner`` (None: every one) the server changed (a top-level node's text and worldSave write
    them so)."""
    table = sv._table(sim)
    out: dict[int, dict[str, Any]] = {}
    inside = table.by_owner.get(owner, ()) if owner is not None else [n for v in table.by_owner.values() for n in v]
    for n in inside:
        if not (n.motor or n.joint or n.light >= 0 or n.shape is not None and _shape_changed(sim, n.shape.index)):
            continue             # nothing the server changes
        now = _nested_now(sim, table, n)
        written = _found(sim, table, n) if now else None
        if written is None:
            continue
        fields = _overlay(written, now)
        if fields != written.fields:
            out[id(written)] = fields
    return out


def _writer(sim: Any, owner: int | None = None) -> Writer:
    """A writer of top-level node ``owner`` (None: every one) writing the nested nodes inside as they are now (the
    Shapes a Supervisor removed left out)."""
    changed = _nested_fields(sim, owner)
    table = sv._table(sim)
    removed = (_found(sim, table, n) for n in table.removed_shapes.values() if owner is None or n.owner == owner)
    return Writer(lambda written: changed.get(id(written)), frozenset(id(w) for w in removed if w is not None))


def _became(sim: Any) -> Counter[int]:
    """How many robots, solids and lights each top-level node of the file became (counted once per layout)."""
    places = sim.top_level.written
    kept = getattr(sim, "_export_became", None)
    if kept is None or kept[0] is not places:
        kept = sim._export_became = (places, Counter(places.values()))
    return kept[1]


def _place(sim: Any, node: sv.Node) -> tuple[str, int]:
    """The node's (kind, index) in the world's top-level layout (world/top_nodes.py)."""
    if node.scenery:
        return ("scenery", int(node.key))
    if node.type == "Robot":
        return ("robots", node.id - 1)
    if node.type == "Solid":
        return ("solids", node.id - 1 - len(sim.robots))
    return ("lights", int(node.key))


def _now(sim: Any, node: sv.Node) -> list[tuple[str, str, Any, Any]]:
    """(field as written, type, value now, the value not written) of the fields written from the server's state:
    a base node's at Webots' default; a PROTO instance's fields that pass straight through IS to those at the
    instance's value as it loaded (its PROTO's default when the instance does not write it)."""
    if node.scenery and node.type == "Viewpoint" and getattr(sim, "viewpoint_loaded", None) is not None:
        # moved by moveViewpoint: Webots' position field holds where it went, and its text writes it
        return [("position", "SFVec3f", sv.SCENERY_FIELDS["Viewpoint"]["position"][1](sim, node), None)]
    defaults = DEFAULTS.get(node.type)
    if defaults is None or node.scenery or node.visual:
        return []
    base = sv._base_fields(sim, node)
    if node.interface:
        return [(f.name, f.type, base[f.base][1](sim, node), f.value) for f in node.interface[0].fields
                if f.base in defaults and f.base in base and base[f.base][0] == f.type]
    return [(name, kind, get(sim, node), defaults[name]) for name, (kind, get, _) in base.items() if name in defaults]


def _same(written: Any, now: Any) -> bool:
    """Whether a written value and the value now are the same up to the rounding of reading it back."""
    if isinstance(written, float) and isinstance(now, float):
        return math.isclose(written, now, rel_tol=1e-12, abs_tol=1e-12)
    if isinstance(written, tuple) and isinstance(now, tuple) and len(written) == len(now):
        return all(math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12) for a, b in zip(written, now))
    return bool(written == now)


def node_string(sim: Any, node: sv.Node, writer: Writer | None = None) -> str:
    """Webots' ``exportString``: the node as ``.wbt`` text (NotExported: one line)."""
    written = _written(sim, node)
    if node.nested:
        table = sv._table(sim)
        n = table.get(node.id)
        assert n is not None
        if _found(sim, table, n) is None:     # a PROTO body's node (:func:`_made`)
            return _made_string(sim, table, n)
        return (writer or _writer(sim, n.owner)).node(written, 0, _overlay(written, _nested_now(sim, table, n)))
    writer = writer or _writer(sim, node.id)
    fields = dict(written.fields)
    for name, kind, value, default in _now(sim, node):
        now = written_value(kind, value)
        if name in fields:
            if _same(fields[name], now):
                continue         # unchanged: as written (a rotation read back through its matrix differs in the last bits)
            if node.interface or value != default or name == "controller":
                fields[name] = now
            else:
                del fields[name]
        elif value != default and (default is None or not _same(written_value(kind, default), now)):
            fields = {name: now, **fields} if name in _FIRST else {**fields, name: now}
    return writer.node(written, 0, _pose_first(fields))


def _added_scenery(sim: Any, node: sv.Node, writer: Writer) -> str:
    """A WorldInfo or Viewpoint Webots added where the file has none: the fields the server set on it since
    it loaded (a Viewpoint moveViewpoint moved: its position; its orientation stays Webots' default, left
    out as every default is), else an empty node."""
    getters = sv.SCENERY_FIELDS.get(node.type, {})
    fields = {name: written_value(getters[name][0], getters[name][1](sim, node))
              for name in getters if name in sv._scenery(sim)[int(node.key)].fields}
    return writer.node(ParsedNode(node.type, fields, 0, 0))


def world_string(sim: Any) -> str:
    """Webots' ``worldSave``'s text: the header of the world file's version, its EXTERNPROTO declarations, then
    the root's children as :func:`node_string` writes them (NotExported: one line, nothing written)."""
    wbt = _world_file(sim)
    if wbt is None:
        raise NotExported(f"{sim.loaded.source}: the world was not loaded from a .wbt file: it has no .wbt text here")
    if wbt.protos:
        raise NotExported(f"{sim.loaded.source} defines PROTO {wbt.protos[0].name} in the world file itself: such "
                          "a world is not written here")
    lines = [f"#VRML_SIM {wbt.version} utf8"]
    lines += [("IMPORTABLE " if d.importable else "") + f'EXTERNPROTO "{d.url}"' for d in wbt.declarations]
    lines.append("")
    writer = _writer(sim)
    places, became = sim.top_level.written, _became(sim)
    imported = {n.id for n in sv._imported_nodes(sim, len(sv._loaded_nodes(sim))).every}
    for node in sv.root_children(sim):
        at = None if node.id in imported else places.get(_place(sim, node))
        if at is not None and became[at] > 1:     # one top-level node of the file that became several: written once, as written
            if id(wbt.nodes[at]) not in writer.written_nodes:
                lines.append(writer.node(wbt.nodes[at]))
            continue
        if at is None and node.id not in imported:
            if node.scenery:        # a WorldInfo or Viewpoint Webots adds where the file has none
                lines.append(_added_scenery(sim, node, writer))
            continue                # the solid holding the file's shapes outside any solid: written as those shapes
        lines.append(node_string(sim, node, writer))
    return "\n".join(lines) + "\n"
