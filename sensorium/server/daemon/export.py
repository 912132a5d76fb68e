"""A Supervisor's ``exportString`` and ``worldSave`` (sans-IO): nodes and the whole world as ``.wbt`` text.

A top-level node is written from the node as the world file (or the node string it was imported from)
wrote it, with the fields the server keeps written as they are now: a robot's or solid's ``translation``
and ``rotation`` (where it drove or a Supervisor put it), ``name``, ``customData``, ``controller``,
``radarCrossSection``; a light's fields; a PROTO instance's fields that pass through IS to those (its
other fields as last set: a set builds the solid again from its written node, sim/regenerate.py). A field
whose value is Webots' default is left out, as Webots writes only the fields that differ from it.
What is inside a robot or solid is written as the file wrote it (a joint's position, a shape's colour
set since are not: README "Supervisor"). Text only: the client writes ``worldSave``'s file (the server
never writes a path a client names)."""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.regenerate import reparsed_world, written_value
from sensorium.server.world.wbt.parser import Node as ParsedNode
from sensorium.server.world.wbt.parser import WbtFile
from sensorium.server.world.wbt.write import Writer

_POSE = {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 1.0, 0.0]}
_LIGHT = {"on": True, "intensity": 1.0, "color": [1.0, 1.0, 1.0], "ambientIntensity": 0.0, "castShadows": False}
_LOCAL = {"location": [0.0, 0.0, 0.0], "attenuation": [1.0, 0.0, 0.0], "radius": 100.0}
DEFAULTS: dict[str, dict[str, Any]] = {
    # a .wbt robot without a controller reads "<extern>" here (Webots' default is "<generic>"): one set to
    # "<extern>" keeps its field written, and one never written stays unwritten
    "Robot": {**_POSE, "name": "robot", "model": "", "radarCrossSection": 0.0, "customData": "",
              "controller": "<extern>", "supervisor": False, "synchronization": True},
    "Solid": {**_POSE, "name": "solid", "model": "", "radarCrossSection": 0.0},
    "PointLight": {**_LIGHT, **_LOCAL},
    "SpotLight": {**_LIGHT, **_LOCAL, "direction": [0.0, 0.0, -1.0], "beamWidth": 1.570796, "cutOffAngle": 0.785398},
    "DirectionalLight": {**_LIGHT, "direction": [0.0, 0.0, -1.0]},
}
"""Webots' defaults (its reference manual) of the fields written from the server's state: a field at its
default is not written."""

_FIRST = ("translation", "rotation")      # Webots declares them first: a pose field not written goes first


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
        raise NotExported(f"{sv._what(node)} is inside a robot or solid: exportString serves the root's children "
                          "here (export the top-level node holding it)")
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
    if "rotation" in fields and "translation" in fields and list(fields).index("rotation") < list(fields).index(
            "translation"):
        fields = {"translation": fields.pop("translation"), **fields}
    return (writer or Writer()).node(written, 0, fields)


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
    writer = Writer()
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
                lines.append(f"{node.type} {{\n}}")
            continue                # the solid holding the file's shapes outside any solid: written as those shapes
        lines.append(node_string(sim, node, writer))
    return "\n".join(lines) + "\n"
