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

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from sensorium.schemas import world as wm
from sensorium.server.sim.imports import ImportedNode, ImportRefused, rebuild_node, string_file, world_protos
from sensorium.server.world.geometry import Pose
from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.poses import pose_from_model
from sensorium.server.world.wbt.frames import Frame
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


def _edited(node: ParsedNode, at: tuple[int, int], edit: Callable[[ParsedNode], ParsedNode]) -> ParsedNode | None:
    """``node`` with the node written at ``at`` (line, column, in the same file) replaced by ``edit`` of it, or
    None when no node inside it is written there."""
    if (node.line, node.col) == at:
        return edit(node)
    for name, value in node.fields.items():
        items = value if isinstance(value, list) else [value]
        for i, item in enumerate(items):
            if isinstance(item, ParsedNode):
                found = _edited(item, at, edit)
                if found is not None:
                    value = found if not isinstance(value, list) else [*value[:i], found, *value[i + 1:]]
                    return replace(node, fields={**node.fields, name: value})
    return None


def _replaced(node: ParsedNode, at: tuple[int, int], fields: dict[str, Any]) -> ParsedNode | None:
    """``node`` with the node written at ``at`` given ``fields`` (None: the field taken out, as unwritten), or
    None when no node inside it is written there."""
    def given(n: ParsedNode) -> ParsedNode:
        new = {k: v for k, v in n.fields.items() if k not in fields}
        new.update({k: v for k, v in fields.items() if v is not None})
        order = [*(k for k in new if k not in n.fields), *n.fields]     # (pose fields first, as Webots writes)
        return replace(n, fields={k: new[k] for k in order if k in new})
    return _edited(node, at, given)


def _pruned(node: ParsedNode, drop: Callable[[ParsedNode], bool]) -> ParsedNode:
    """``node`` without the nodes inside it that ``drop`` names (with what they hold)."""
    fields = {}
    for name, value in node.fields.items():
        if isinstance(value, list):
            value = [_pruned(v, drop) if isinstance(v, ParsedNode) else v for v in value
                     if not (isinstance(v, ParsedNode) and drop(v))]
        elif isinstance(value, ParsedNode):
            if drop(value):
                continue
            value = _pruned(value, drop)
        fields[name] = value
    return replace(node, fields=fields)


def _without(node: ParsedNode, gone: set[tuple[int, int]]) -> ParsedNode:
    """``node`` without the nodes written at ``gone`` (line, column) inside it (a Supervisor removed them)."""
    return _pruned(node, lambda v: (v.line, v.col) in gone)


def written_fields(sim: Any, key: str, at: tuple[int, int], names: tuple[str, ...]) -> dict[str, Any] | None:
    """The values ``names`` have in the node written at ``at`` inside top-level solid ``key`` as it is
    written now (None each: unwritten); None when that node is not at hand (:func:`rebuild_posed`)."""
    node = written_node(sim, key, at)
    return None if node is None else {name: node.fields.get(name) for name in names}


def rebuild_posed(sim: Any, key: str, node_id: int, at: tuple[int, int], fields: dict[str, Any],
                  gone: set[tuple[int, int]] | None = None) -> ImportedNode:
    """Top-level solid ``key`` (Supervisor node ``node_id``) built again with the Pose or Transform written at
    ``at`` inside it given ``fields`` (a parsed value each; None: unwritten): what that Pose holds is where
    the world file written with those values puts it, through the path a PROTO field set takes
    (:func:`regenerate`). ``ImportRefused`` (one line, nothing changed) when the solid's written node is not
    at hand here (a solid a Supervisor imported) or does not build. ``gone``: the nodes written there a
    Supervisor removed since, left out (a reset keeps them removed)."""
    new, file = _written_edited(sim, key, at, lambda written: _replaced(written, at, fields))
    return _rebuilt(sim, key, node_id, _without(new, gone) if gone else new, file)


def _written_edited(sim: Any, key: str, at: tuple[int, int],
                    edit: Callable[[ParsedNode], ParsedNode | None]) -> tuple[ParsedNode, WbtFile]:
    """Top-level solid ``key``'s written node changed by ``edit`` (None: nothing written at ``at``), and its
    file; ``ImportRefused`` when the solid's written node is not at hand or nothing is written at ``at``."""
    found = _instance(sim, key)
    if found is None:
        raise ImportRefused(f"solid {key!r} was not loaded from a .wbt world file's node kept here")
    new = edit(found[0])
    if new is None:
        raise ImportRefused(f"no node of solid {key!r} is written at line {at[0]}, column {at[1]}")
    return new, found[1]


_UNIT = (1.0, 1.0, 1.0)


def _vec(node: ParsedNode, name: str, default: tuple[float, ...]) -> tuple[float, ...] | None:
    """A field's numbers as the converter reads them (wbt/fields.py ``vec``); None for anything else."""
    v = node.fields.get(name, default)
    if isinstance(v, float | int) and not isinstance(v, bool):
        v = (float(v),)
    if not isinstance(v, tuple) or len(v) != len(default) or not all(isinstance(x, float | int) for x in v):
        return None
    return tuple(float(x) for x in v)


def _frame(node: ParsedNode, frame: Frame) -> Frame | None:
    """The frame of a Pose or unscaled Transform under ``frame``, as the converter makes it (``child_frame``);
    None for a scaled Transform or a rotation the converter refuses."""
    translation, rotation = _vec(node, "translation", (0.0, 0.0, 0.0)), _vec(node, "rotation", (0.0, 0.0, 1.0, 0.0))
    if translation is None or rotation is None or (rotation[3] != 0.0 and math.hypot(*rotation[:3]) == 0.0):
        return None
    if node.type == "Transform" and _vec(node, "scale", _UNIT) != _UNIT:
        return None
    return frame.then(translation, rotation, _UNIT)


def written_children(node: ParsedNode) -> list[Any]:
    """The nodes written in ``node``'s ``children`` (a lone node written without brackets: a list of one)."""
    value = node.fields.get("children", [])
    return value if isinstance(value, list) else [value]


def _unshared(sim: Any, key: str, top: ParsedNode) -> bool:
    """Whether each node inside ``top`` (top-level solid ``key``'s written node) is written once there (a USE
    would place one written node twice); kept for the node checked, and for the one a set makes of it (a
    Pose's new values share no node)."""
    if getattr(sim, "_regen_unshared", {}).get(key) is top:
        return True
    seen: set[int] = set()
    stack: list[ParsedNode] = [top]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            return False
        seen.add(id(node))
        for value in node.fields.values():
            stack += [v for v in (value if isinstance(value, list) else [value]) if isinstance(v, ParsedNode)]
    sim._regen_unshared = {**getattr(sim, "_regen_unshared", {}), key: top}
    return True


def _path(top: ParsedNode, at: tuple[int, int]) -> list[ParsedNode] | None:
    """The nodes from ``top`` down to the one written at ``at`` through Poses', Transforms' and Groups'
    ``children`` (None: not so)."""
    stack: list[list[ParsedNode]] = [[top]]
    while stack:
        path = stack.pop()
        if (path[-1].line, path[-1].col) == at:
            return path
        stack += [[*path, c] for c in written_children(path[-1])
                  if isinstance(c, ParsedNode) and c.type in ("Pose", "Transform", "Group")]
    return None


def _placed(top: ParsedNode, at: tuple[int, int]) -> tuple[dict, dict] | None:
    """Where the shapes and Poses under the Pose written at ``at`` inside plain Solid ``top`` sit in its frame,
    as the converter places them: ((line, column) of each Shape -> its Frame, of each Pose or Transform -> its
    frame); None unless only Poses, unscaled Transforms and Groups lead from ``top`` to it through ``children``
    and only those and Shapes are under it."""
    path = _path(top, at)
    if path is None or path[-1].type not in ("Pose", "Transform"):
        return None
    frame = Frame.identity()
    for node in path[1:]:                       # down to it, a frame at a time
        if node.type != "Group":
            step = _frame(node, frame)
            if step is None:
                return None
            frame = step
    node = path[-1]
    shapes: dict[tuple[int, int], Frame] = {}
    poses: dict[tuple[int, int], Frame] = {(node.line, node.col): frame}
    walk = [(node, frame)]
    while walk:
        parent, inner = walk.pop()
        for child in written_children(parent):
            if not isinstance(child, ParsedNode):
                return None
            if child.type == "Shape":
                shapes[(child.line, child.col)] = inner
            elif child.type == "Group":
                walk.append((child, inner))
            elif child.type in ("Pose", "Transform"):
                step = _frame(child, inner)
                if step is None:
                    return None
                poses[(child.line, child.col)] = step
                walk.append((child, step))
            else:                               # a light, a solid, a PROTO instance...: the rebuild places it
                return None
    return shapes, poses


def _pose_model(frame: Frame) -> wm.Pose:
    return wm.Pose.model_validate(frame.pose())


def move_posed(sim: Any, key: str, at: tuple[int, int], fields: dict[str, Any]) -> tuple[wm.Solid, list[int]] | None:
    """:func:`rebuild_posed` without building the solid again, where the set only moves shapes within it: the
    shapes under the Pose (or Transform) written at ``at`` get the poses in the solid's frame the converter
    gives them with ``fields``, their numbers, entries and looks kept, and the solid's model and written node
    become those the rebuild would leave; returns the new model and the indices of its ``poses`` moved.
    None (nothing changed: the caller rebuilds) unless top-level solid ``key`` is a plain Solid written in the
    file, without physics (the rebuild lands it), and only visual shapes sit under that Pose. Left to the
    rebuild: a light (the scene's light arrays), a solid (contact, radar targets, its nodes), a scaled
    Transform (its geometry follows the scale), a bounding shape (kinematic contact and the terrains judge
    those), a USE (one written node placed twice), a PROTO instance (placed through its body)."""
    found = _instance(sim, key)
    if found is None or found[0].type != "Solid" or found[0].proto is not None:
        return None
    written = found[0]
    new = _replaced(written, at, fields) if _unshared(sim, key, written) else None
    placed = None if new is None else _placed(new, at)
    if placed is None:
        return None
    shapes, poses = placed
    k = next(i for i in range(len(sim.world.solids) - 1, -1, -1) if sim.world.solids[i].name == key)
    solid = sim.world.solids[k]
    if solid.physics:
        return None
    mine = sim.scene.solid_shapes(key)
    first = 0 if solid.geometry is None else 1
    parts = list(solid.shapes)
    moved: dict[int, tuple[Pose, wm.Part]] = {}
    for j, part in enumerate(parts):
        where = part.node.written_at if part.node is not None else None
        frame = shapes.get((where[0], where[1])) if where else None
        if frame is None:
            continue
        if part.seen_by != "visual" or part.node.piece or first + j >= len(mine) \
                or sim.scene.loaded_model(mine[first + j]) is not part:
            return None
        parts[j] = part.model_copy(update={"pose": _pose_model(frame)})
        moved[mine[first + j]] = (Pose.identity().compose(pose_from_model(parts[j].pose)), parts[j])
    if len(moved) != len(shapes):               # (a Shape that is no part here, or not found by its place)
        return None
    entries = list(solid.poses)
    changed = []
    for j, entry in enumerate(entries):
        frame = poses.get((entry.written_at[0], entry.written_at[1])) if entry.written_at else None
        if frame is not None and entry.type != "Group":
            entries[j] = entry.model_copy(update={"pose": _pose_model(frame)})
            changed.append(j)
    if len(changed) != len(poses):              # (a Pose the solid does not serve: placed otherwise)
        return None
    model = solid.model_copy(update={"shapes": parts, "poses": entries})
    sim.world.solids[k] = model
    sim.scene.move_shapes(moved)
    sim._regen_written = {**getattr(sim, "_regen_written", {}), key: new}
    sim._regen_unshared[key] = new
    return model, changed


IMPORT_LINES = 1 << 32
"""Where the lines of the nodes a Supervisor imports inside a top-level solid are numbered from: the string's
``k``-th such import's line ``n`` is ``k * IMPORT_LINES + n``, past any world file's, so that each node inside
the solid keeps a place (line, column) no other node has (what a Pose's set, a removal and export find it by)."""


def imported_line(line: int) -> bool:
    """A line :func:`parse_nested_import` numbered (a node a Supervisor imported inside a solid)."""
    return line >= IMPORT_LINES


def _shifted(node: ParsedNode, by: int) -> ParsedNode:
    fields = {name: [_shifted(v, by) if isinstance(v, ParsedNode) else v for v in value] if isinstance(value, list)
              else _shifted(value, by) if isinstance(value, ParsedNode) else value
              for name, value in node.fields.items()}
    return replace(node, fields=fields, line=node.line + by,
                   field_pos={k: (line + by, col) for k, (line, col) in node.field_pos.items()})


def parse_nested_import(sim: Any, key: str, text: Any, serial: int) -> list[ParsedNode]:
    """The nodes of an ``importMFNodeFromString`` string meant for a node inside top-level solid ``key``, as written
    in that solid's file (its relative urls resolve there), numbered past its lines (:data:`IMPORT_LINES`, ``serial``
    the import's number, from 1). ``ImportRefused`` (one line placed in the string) for a string that does not parse,
    declares a PROTO or holds no node."""
    from sensorium.server.sim.imports import LABEL, _check_string
    from sensorium.server.world.wbt.parser import Parser, Tokens

    found = _instance(sim, key)
    if found is None:
        raise ImportRefused(f"solid {key!r} was not loaded from a .wbt world file's node kept here")
    _check_string(text, sim.limits)
    file = found[1]
    try:
        wbt = Parser(Tokens(text, file.source), file.source, limits=ProtoLimits.matching(sim.limits)).file(
            file.version or "R2023b", text)
    except WbtSyntaxError as exc:
        at = f"{LABEL}:{exc.line}:{exc.col}" if exc.line else LABEL
        raise ImportRefused(f"{at}: {exc.message.replace(file.source, LABEL)}") from None
    if wbt.declarations or wbt.protos:
        raise ImportRefused(f"{LABEL}: a node string declares no PROTO: declare it in the world file "
                            "(IMPORTABLE EXTERNPROTO), as Webots requires")
    if not wbt.nodes:
        raise ImportRefused(f"{LABEL}: no node in it (e.g. 'Pose {{ ... }}')")
    return [_shifted(n, serial * IMPORT_LINES) for n in wbt.nodes]


def _grown(node: ParsedNode, at: tuple[int, int], change: Any) -> ParsedNode | None:
    """``node`` with the ``children`` of the node written at ``at`` changed by ``change`` (its list -> the new
    list), or None when no node inside it is written there."""
    def grown(n: ParsedNode) -> ParsedNode:
        return replace(n, fields={**n.fields, "children": change(list(written_children(n)))})
    return _edited(node, at, grown)


def written_node(sim: Any, key: str, at: tuple[int, int] | None = None) -> ParsedNode | None:
    """The node written at ``at`` inside top-level solid ``key`` as it is written now (None: the solid's own
    node), or None when it is not at hand."""
    found = _instance(sim, key)
    if found is None:
        return None
    stack = [found[0]]
    while stack:
        node = stack.pop()
        if at is None or (node.line, node.col) == at:
            return node
        for value in node.fields.values():
            stack += [v for v in (value if isinstance(value, list) else [value]) if isinstance(v, ParsedNode)]
    return None


def rebuild_children(sim: Any, key: str, node_id: int, at: tuple[int, int], change: Any,
                     warnings: list[str] | None = None) -> ImportedNode:
    """Top-level solid ``key`` (Supervisor node ``node_id``) built again with the ``children`` of the node written at
    ``at`` inside it (its own node's place: its own children) changed by ``change`` (the written list -> the new
    one): a Supervisor's import into, or removal from, a node's children, through the path a Pose's set takes
    (:func:`rebuild_posed`). ``ImportRefused`` (one line, nothing changed) when it does not build."""
    new, file = _written_edited(sim, key, at, lambda written: _grown(written, at, change))
    return _rebuilt(sim, key, node_id, new, file, warnings)


def rebuild_unimported(sim: Any, key: str, node_id: int) -> ImportedNode:
    """Top-level solid ``key`` built again without the nodes a Supervisor imported inside it (what a
    ``simulationReset`` takes out), as it is written now otherwise."""
    found = _instance(sim, key)
    assert found is not None
    return _rebuilt(sim, key, node_id, _pruned(found[0], lambda v: imported_line(v.line)), found[1])


def _rebuilt(sim: Any, key: str, node_id: int, new: ParsedNode, file: WbtFile,
             warnings: list[str] | None = None) -> ImportedNode:
    taken = set(sim.scene.solid_names) - {key}
    node = rebuild_node(new, file, sim.loaded, sim.world, taken=taken, limits=sim.limits,
                        allow_outside_meshes=sim.allow_outside_meshes, warnings=warnings)
    if node.type != "Solid" or node.model.name != key:
        raise ImportRefused(f"solid {key!r} would not build again as a solid of that name")
    sim.replace_solid(key, node, node_id)
    sim._regen_written = {**getattr(sim, "_regen_written", {}), key: new}
    return node
