"""A Supervisor's set of a PROTO field of a top-level solid: the instance built again with the new value,
as Webots regenerates a PROTO node (WbTemplateManager).

The instance as written (the ``.wbt`` world's top-level node, parsed once at the first set; an imported
instance's node string as read) gets the new value in that field (the caller moves the new solid where a
Supervisor had put the old one), then goes through
the import's path (sim/imports.py ``rebuild_node``: PROTO expansion and template within the world's PROTO
limits, conversion, validation) and takes the old solid's place (``Simulation.replace_solid``: the removal
and import paths) under the same name. What fails changes nothing (``ImportRefused``, one line). The
written node kept is then the one with the value, so successive sets add up."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from sensorium.server.sim.imports import ImportedNode, ImportRefused, rebuild_node, string_file, world_protos
from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.wbt.parser import Node as ParsedNode
from sensorium.server.world.wbt.parser import WbtFile, WbtSyntaxError, parse_wbt

_VECTORS = frozenset({"SFVec2f", "SFVec3f", "SFColor", "SFRotation"})


def written_value(kind: str, value: Any) -> Any:
    """A Supervisor's value (checked by the caller) as the ``.wbt`` parser gives that field's value: numbers
    as floats, a vector as a tuple, an MF vector field's items flattened into one list."""
    if kind in ("SFBool", "SFString"):
        return value
    if kind in ("SFInt32", "SFFloat"):
        return float(value)
    if kind in _VECTORS:
        return tuple(float(v) for v in value)
    if kind in ("MFBool", "MFString"):
        return list(value)
    if kind in ("MFInt32", "MFFloat"):
        return [float(v) for v in value]
    return [float(v) for item in value for v in item]          # MFVec2f, MFVec3f, MFColor, MFRotation


def reparsed_world(sim: Any, refused: type[ValueError]) -> WbtFile | None:
    """The world file parsed again from the bytes it loaded from (within the world's PROTO limits); None
    for a world not loaded from a ``.wbt`` file; ``refused`` (one line) if it does not parse."""
    loaded = sim.loaded
    if not loaded.source.lower().endswith(".wbt") or not loaded.text:
        return None
    text = loaded.text.removeprefix(b"\xef\xbb\xbf").decode("utf-8", errors="replace")
    try:
        return parse_wbt(text, loaded.source, ProtoLimits.matching(sim.limits))
    except WbtSyntaxError as exc:
        raise refused(f"{loaded.source}: the world file does not parse again: {exc.message}") from None


def _world_instances(sim: Any) -> tuple[WbtFile, dict[str, ParsedNode]]:
    """The world file's declarations and PROTOs, and its top-level PROTO instances that became one top-level
    solid each (by the solid's name): the file parsed again once, at the first set, the rest dropped."""
    kept = getattr(sim, "_regen_world", None)
    if kept is not None:
        return kept
    wbt = reparsed_world(sim, ImportRefused)
    if wbt is None:
        kept = (WbtFile("", [], [], sim.loaded.source), {})
    else:
        instances: dict[str, ParsedNode] = {}
        solids = 0
        faces = sim.top_level.interfaces
        for written, top in zip(wbt.nodes, sim.loaded.world.top_nodes):
            if top.solids == 1 and not top.robots and not top.lights and (("solids", solids) in faces
                                                                          or written.type == "Solid"):
                instances[sim.scene.solid_names[solids]] = written      # (a plain Solid: its Poses' sets)
            solids += top.solids
        kept = (replace(wbt, nodes=[]), instances)
    sim._regen_world = kept
    return kept


def _instance(sim: Any, key: str) -> tuple[ParsedNode, WbtFile] | None:
    """The instance top-level solid ``key`` was built from, as written, and the file it was written in."""
    done = getattr(sim, "_regen_written", {})
    if key in sim.imported_written:
        if sim._import_protos is None:
            sim._import_protos = world_protos(sim.loaded, ProtoLimits.matching(sim.limits))
        return done.get(key, sim.imported_written[key]), string_file(sim.loaded, sim._import_protos)
    wbt, instances = _world_instances(sim)
    written = done.get(key, instances.get(key))
    return None if written is None else (written, wbt)


def regenerate(sim: Any, key: str, node_id: int, values: dict[str, tuple[str, Any]],
               warnings: list[str] | None = None) -> ImportedNode:
    """Top-level solid ``key`` (Supervisor node ``node_id``, a PROTO instance) built again with ``values``
    (field name -> (its VRML type, the Supervisor's value)) in its instance; returns what it became.
    ``ImportRefused`` (one line, nothing changed) when it is not built from an instance kept here or the
    new instance does not load."""
    found = _instance(sim, key)
    if found is None:
        raise ImportRefused(f"the PROTO instance solid {key!r} was built from is not at hand here")
    written, file = found
    fields = dict(written.fields)
    for name, (kind, value) in values.items():
        fields[name] = written_value(kind, value)
    new = replace(written, fields=fields)
    taken = set(sim.scene.solid_names) - {key}
    node = rebuild_node(new, file, sim.loaded, sim.world, taken=taken, limits=sim.limits,
                        allow_outside_meshes=sim.allow_outside_meshes, warnings=warnings)
    if node.type != "Solid":
        raise ImportRefused(f"it would become a {node.type}, no longer a solid")
    if node.model.name != key:
        raise ImportRefused(f"it would be named {node.model.name!r}: a top-level solid keeps its name here (its key)")
    sim.replace_solid(key, node, node_id)
    sim._regen_written = {**getattr(sim, "_regen_written", {}), key: new}
    if key in sim.imported_interfaces:
        sim.imported_interfaces[key] = node.interface
    else:
        sim.top_level.interfaces[("solids", sim.scene.solid_names.index(key))] = node.interface
    return node


def _replaced(node: ParsedNode, at: tuple[int, int], fields: dict[str, Any]) -> ParsedNode | None:
    """``node`` with the node written at ``at`` (line, column, in the same file) given ``fields`` (None:
    the field taken out, as unwritten), or None when no node inside it is written there."""
    if (node.line, node.col) == at:
        new = {k: v for k, v in node.fields.items() if k not in fields}
        new.update({k: v for k, v in fields.items() if v is not None})
        order = [*(k for k in new if k not in node.fields), *node.fields]     # (pose fields first, as Webots writes)
        return replace(node, fields={k: new[k] for k in order if k in new})
    for name, value in node.fields.items():
        items = value if isinstance(value, list) else [value]
        for i, item in enumerate(items):
            if isinstance(item, ParsedNode):
                found = _replaced(item, at, fields)
                if found is not None:
                    value = found if not isinstance(value, list) else [*value[:i], found, *value[i + 1:]]
                    return replace(node, fields={**node.fields, name: value})
    return None


def _without(node: ParsedNode, gone: set[tuple[int, int]]) -> ParsedNode:
    """``node`` without the nodes written at ``gone`` (line, column) inside it (a Supervisor removed them)."""
    fields = {}
    for name, value in node.fields.items():
        if isinstance(value, list):
            value = [_without(v, gone) if isinstance(v, ParsedNode) else v for v in value
                     if not (isinstance(v, ParsedNode) and (v.line, v.col) in gone)]
        elif isinstance(value, ParsedNode):
            value = None if (value.line, value.col) in gone else _without(value, gone)
            if value is None:
                continue
        fields[name] = value
    return replace(node, fields=fields)


def written_fields(sim: Any, key: str, at: tuple[int, int], names: tuple[str, ...]) -> dict[str, Any] | None:
    """The values ``names`` have in the node written at ``at`` inside top-level solid ``key`` as it is
    written now (None each: unwritten); None when that node is not at hand (:func:`rebuild_posed`)."""
    found = _instance(sim, key)
    if found is None:
        return None
    stack = [found[0]]
    while stack:
        node = stack.pop()
        if (node.line, node.col) == at:
            return {name: node.fields.get(name) for name in names}
        for value in node.fields.values():
            stack += [v for v in (value if isinstance(value, list) else [value]) if isinstance(v, ParsedNode)]
    return None


def rebuild_posed(sim: Any, key: str, node_id: int, at: tuple[int, int], fields: dict[str, Any],
                  gone: set[tuple[int, int]] | None = None) -> ImportedNode:
    """Top-level solid ``key`` (Supervisor node ``node_id``) built again with the Pose or Transform written at
    ``at`` inside it given ``fields`` (a parsed value each; None: unwritten): what that Pose holds is where
    the world file written with those values puts it, through the path a PROTO field set takes
    (:func:`regenerate`). ``ImportRefused`` (one line, nothing changed) when the solid's written node is not
    at hand here (a solid a Supervisor imported) or does not build. ``gone``: the nodes written there a
    Supervisor removed since, left out (a reset keeps them removed)."""
    found = _instance(sim, key)
    if found is None:
        raise ImportRefused(f"solid {key!r} was not loaded from a .wbt world file's node kept here")
    written, file = found
    new = _replaced(written, at, fields)
    if new is None:
        raise ImportRefused(f"no node of solid {key!r} is written at line {at[0]}, column {at[1]}")
    if gone:
        new = _without(new, gone)
    taken = set(sim.scene.solid_names) - {key}
    node = rebuild_node(new, file, sim.loaded, sim.world, taken=taken, limits=sim.limits,
                        allow_outside_meshes=sim.allow_outside_meshes)
    if node.type != "Solid" or node.model.name != key:
        raise ImportRefused(f"solid {key!r} does not build again as it was")
    sim.replace_solid(key, node, node_id)
    sim._regen_written = {**getattr(sim, "_regen_written", {}), key: new}
    return node
