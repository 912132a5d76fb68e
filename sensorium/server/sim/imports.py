"""A Supervisor's ``importMFNodeFromString``: a node string read as the top-level nodes of a world
file are (the ``.wbt`` parser with its bounds, PROTO expansion, the converter, the world model's
validation and sanitising), each node one solid or light.

Pure: a string in, world models out (or one ``ImportRefused`` line naming what is wrong and where:
``node string:LINE:COL`` for the string, ``FILE:LINE:COL`` inside a PROTO file). Nothing of the
running simulation changes here; :meth:`Simulation.import_nodes` adds what this returns.

As Webots, a PROTO instance must be of a PROTO the world file declares (``EXTERNPROTO`` or
``IMPORTABLE EXTERNPROTO``; Sensorium's built-in stand-ins need none), a solid whose name is taken
is renamed ``name(1)``, ``name(2)``, ... (Webots' name clash rule), and every node of the string is
imported in order. A ``Shape`` (or a ``Group`` of shapes) is imported as a solid without
boundingObject holding it, as a world file holds its top-level shapes (``ImportedNode.visual`` keeps
the parsed node: the Supervisor serves it, daemon/visuals.py). Departures: a robot (a ``Robot`` or a
PROTO that is one, or a solid holding one) is refused, as are nodes that are neither a solid, a light
nor shapes (``WorldInfo``, a scaled ``Transform``, ...); a ``Pose`` (or a ``Transform`` of scale 1) is
imported as a ``Solid`` of its shapes, with one warning; a ``USE`` names a ``DEF`` of the string
only.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Collection
from dataclasses import dataclass, replace
from typing import Any

from sensorium.schemas import world as wm
from sensorium.server.world.limits import ProtoLimits, WorldLimits
from sensorium.server.world.loader import LoadedWorld, WorldError, _wbt_problem, _wbt_warning, parse_world
from sensorium.server.world.wbt.convert import Converter, Owner, strip_origins
from sensorium.server.world.wbt.frames import Frame
from sensorium.server.world.wbt.parser import (
    ExternProto,
    Parser,
    Tokens,
    WbtFile,
    WbtSyntaxError,
    parse_header,
)
from sensorium.server.world.wbt.parser import (
    Node as ParsedNode,
)

LABEL = "node string"           # how errors name the string (file:line:col style)
_NAME = "<importMFNodeFromString>"   # its pseudo file, in the world's folder: relative urls resolve there
DEFAULT_VERSION = "R2023b"      # the Webots version webots:// urls of a YAML world's imports refer to


class ImportRefused(ValueError):
    """A node string that is not imported: one line, what is wrong and where."""


@dataclass(frozen=True)
class ImportedNode:
    type: str           # "Solid" or the light's type (PointLight, SpotLight, DirectionalLight)
    model: Any          # wm.Solid or the light model, validated and sanitised
    proto: str = ""     # the PROTO the string's node is an instance of (Supervisor getTypeName), "" for a base node
    interface: tuple = ()   # that PROTO instance's interface (wm.ProtoLevel each: Supervisor getField, getProto)
    visual: Any = None      # a Shape or Group of shapes imported at the root: its parsed node (the solid holds it)
    written: Any = None     # the node as written (parsed): a PROTO instance is built again from it when a
                            # Supervisor sets one of its fields (sim/regenerate.py)


@dataclass
class _WorldProtos:
    """What a world file declares for its imports: EXTERNPROTO declarations and its version tag."""

    version: str
    declarations: list[ExternProto]


def world_protos(loaded: LoadedWorld, limits: ProtoLimits) -> _WorldProtos:
    """The EXTERNPROTO declarations at the head of a ``.wbt`` world (read once by the caller;
    a YAML world declares none)."""
    if not loaded.source.lower().endswith(".wbt") or not loaded.text:
        return _WorldProtos(DEFAULT_VERSION, [])
    text = loaded.text.decode("utf-8", errors="replace")
    year, letter = parse_header(text, loaded.source)
    parser = Parser(Tokens(text, loaded.source), loaded.source, limits=limits)
    decls: list[ExternProto] = []
    while True:             # declarations come before the first node (Webots writes them there)
        tok = parser.peek()
        importable = tok.kind == "name" and tok.text == "IMPORTABLE" and parser.peek(1).text == "EXTERNPROTO"
        if importable:
            parser.take()
            tok = parser.peek()
        if not (tok.kind == "name" and tok.text == "EXTERNPROTO"):
            break
        parser.take()
        url = parser.expect("str", "a quoted url after EXTERNPROTO").text[1:-1]
        # importable for the expansion: an import uses some of them, the others are not checked again
        decls.append(ExternProto(url, tok.line, tok.col, True))
    return _WorldProtos(f"R{year}{letter}", decls)


class _Converter(Converter):
    """The converter with Webots' name clash rule against every solid name the world has had."""

    def __init__(self, *args: Any, taken: Collection[str], suffixes: dict[str, int] | None = None, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self.taken = taken                  # (read only: a set the caller keeps)
        self.added: set[str] = set()
        # name -> a k such that name(1) ... name(k - 1) are all taken (names are never freed: a Supervisor
        # importing "ball" for days finds the next free "ball(k)" at once)
        self.suffixes = {} if suffixes is None else suffixes

    def unique_name(self, name: str) -> str:
        k = self.suffixes.get(name, 0)
        unique = name if k == 0 else f"{name}({k})"
        free_from = None                    # the first one taken by this string only (free if it is not imported)
        while unique in self.taken or unique in self.added:
            if free_from is None and unique not in self.taken:
                free_from = k
            k += 1
            unique = f"{name}({k})"
        if k > 0:
            self.suffixes[name] = k if free_from is None else free_from
        self.added.add(unique)
        return unique


def _shown(message: str, source: str, label: str = LABEL) -> str:
    return message.replace(source, label)


def _syntax(exc: WbtSyntaxError, source: str) -> ImportRefused:
    where = LABEL if exc.source == source else exc.source
    at = f"{where}:{exc.line}:{exc.col}" if exc.line else where
    return ImportRefused(f"{at}: {_shown(exc.message, source)}")


def _check_string(text: Any, limits: WorldLimits) -> None:
    """A node string a Supervisor sends: a string within the world file's size limit (ImportRefused)."""
    if not isinstance(text, str):
        raise ImportRefused(f"the node string must be a string, got {type(text).__name__}")
    size = len(text.encode("utf-8", errors="surrogatepass"))
    if size > limits.file_bytes:
        raise ImportRefused(f"a node string of {size:,} bytes, more than the world file limit of "
                            f"{limits.file_bytes:,} (raise the limits with --allow-large)")


def parse_sf_node_string(text: Any, limits: WorldLimits) -> Any:
    """A Supervisor's ``importSFNodeFromString`` string read as one node with the world file's parser and
    bounds (no PROTO, no conversion: the caller serves the node as written); ImportRefused (one line) for
    anything else."""
    _check_string(text, limits)
    source = "<importSFNodeFromString>"
    try:
        wbt = Parser(Tokens(text, source), source, limits=ProtoLimits.matching(limits)).file(DEFAULT_VERSION, text)
    except WbtSyntaxError as exc:
        raise _syntax(exc, source) from None
    if wbt.declarations or wbt.protos or len(wbt.nodes) != 1:
        raise ImportRefused(f"{LABEL}: an SFNode field takes exactly one node, declaring no PROTO "
                            f"(got {len(wbt.nodes)} nodes)")
    return wbt.nodes[0]


def read_node_string(text: Any, loaded: LoadedWorld, world: wm.World, *, taken: Collection[str], limits: WorldLimits,
                     allow_outside_meshes: bool = False, protos: _WorldProtos | None = None,
                     warnings: list[str] | None = None, suffixes: dict[str, int] | None = None) -> list[ImportedNode]:
    """The nodes of ``text`` as world models, in order (``ImportRefused`` for anything that is not
    imported). ``taken``: every solid name the world has had (removed ones included: names are
    never reused); ``limits``: the world's (the string alone stays within them; what it adds to
    the world is checked by the caller). ``warnings``: given, it gets one line per value corrected
    as Webots corrects it (a ``Sphere { radius 0 }`` gets radius 1, as in a world file), placed in
    the string."""
    _check_string(text, limits)
    proto_limits = ProtoLimits.matching(limits)
    source = str(loaded.base_dir / _NAME)
    try:
        protos = protos or world_protos(loaded, proto_limits)
        wbt = Parser(Tokens(text, source), source, limits=proto_limits).file(protos.version, text)
        if wbt.declarations or wbt.protos:
            at = wbt.declarations[0] if wbt.declarations else wbt.protos[0]
            raise ImportRefused(f"{LABEL}:{at.line}:{at.col}: a node string declares no PROTO: declare it in the "
                                "world file (IMPORTABLE EXTERNPROTO), as Webots requires")
        if not wbt.nodes:
            raise ImportRefused(f"{LABEL}: no node in it (e.g. 'Solid {{ ... }}')")
        wbt = WbtFile(protos.version, wbt.nodes, [], source, list(protos.declarations))
        return _convert(wbt, source, loaded, world, taken, limits, proto_limits, allow_outside_meshes,
                        [] if warnings is None else warnings, suffixes=suffixes)
    except WbtSyntaxError as exc:           # ProtoError too: in the string or a PROTO file
        raise _syntax(exc, source) from None


def string_file(loaded: LoadedWorld, protos: _WorldProtos) -> WbtFile:
    """What a node string is read as part of (no node): the world's version and declarations, the string's
    pseudo file in the world's folder (``rebuild_node`` of an imported instance)."""
    return WbtFile(protos.version, [], [], str(loaded.base_dir / _NAME), list(protos.declarations))


def rebuild_node(written: ParsedNode, wbt: WbtFile, loaded: LoadedWorld, world: wm.World, *, taken: set[str],
                 limits: WorldLimits, allow_outside_meshes: bool = False,
                 warnings: list[str] | None = None) -> ImportedNode:
    """A top-level PROTO instance built again from ``written`` (its node as written, a field's value
    changed: a Supervisor's set, daemon/supervisor.py): the same PROTO expansion (its template run within
    the world's PROTO limits), conversion and validation as a load or an import, the PROTOs of ``wbt``
    (the file it was written in: its declarations and the PROTOs it defines). Errors are
    ``ImportRefused`` lines placed in that file (``wbt.source``, a world's path or the import's string)."""
    label = LABEL if wbt.source.endswith(_NAME) else wbt.source
    proto_limits = ProtoLimits.matching(limits)
    try:
        one = WbtFile(wbt.version, [written], [], wbt.source, list(wbt.declarations), list(wbt.protos))
        (node,) = _convert(one, wbt.source, loaded, world, taken, limits, proto_limits, allow_outside_meshes,
                           [] if warnings is None else warnings, label)
        return node
    except WbtSyntaxError as exc:           # ProtoError too: in the instance or a PROTO file
        where = label if exc.source == wbt.source else exc.source
        at = f"{where}:{exc.line}:{exc.col}" if exc.line else where
        raise ImportRefused(f"{at}: {_shown(exc.message, wbt.source, label)}") from None


def _convert(wbt: WbtFile, source: str, loaded: LoadedWorld, world: wm.World, taken: Collection[str],
             limits: WorldLimits, proto_limits: ProtoLimits, allow_outside_meshes: bool, warnings: list[str],
             label: str = LABEL, suffixes: dict[str, int] | None = None) -> list[ImportedNode]:
    from sensorium.server.world.proto import ProtoSearch, expand

    expansion = expand(wbt, ProtoSearch.create(loaded.base_dir), proto_limits)
    conv = _Converter(expansion.as_wbt(), source, expansion.search, max_grid_points=proto_limits.values, taken=taken,
                      suffixes=suffixes)
    conv.world["world_info"] = {"coordinate_system": world.world_info.coordinate_system}
    top = Owner("world", {})
    kinds: list[str] = []
    protos: list[str] = []
    faces: list[tuple] = []
    visuals: list[Any] = []
    for written, node in zip(wbt.nodes, expansion.nodes):
        solids, lights = len(conv.world["solids"]), len(conv.world["lights"])
        what = written.type if written.type == node.type else f"{written.type} (a {node.type})"
        at = f"{label}:{written.line}:{written.col}"
        if node.type in ("Pose", "Transform") and node.proto is None and _unscaled(node):
            # a grouping node of shapes (Webots' supervisor sample imports a Pose holding a Sphere, then
            # moves it by its translation): a Solid of the same frame and children, movable the same way
            node = replace(node, type="Solid")
            warnings.append(f"{at}: {written.type} imported as a Solid of its shapes (getTypeName() answers "
                            "'Solid'): Sensorium imports solids and lights")
        visual = None
        if node.type in ("Shape", "Group") and node.proto is None and _only_shapes(node):
            # a visual node at the root (Webots' draw-trail sample): a solid without boundingObject holds it,
            # as a world file's top-level shapes are held (its area shapes seen by every sensor; lines by none)
            visual = node
            node = ParsedNode("Solid", {"children": [node], "name": "shapes"}, node.line, node.col, source=node.source)
        visuals.append(visual)
        conv.visit(node, Frame.identity(), top, top=True)
        if conv.world["robots"]:
            held = "" if node.type == "Robot" else f" (it holds robot {conv.world['robots'][0]['name']!r})"
            raise ImportRefused(f"{at}: {what}: a robot cannot be imported here{held}: a departure from Webots, "
                                "which imports robots too (write it in the world file)")
        if conv.losses:
            hint = " (a PROTO must be declared in the world file: IMPORTABLE EXTERNPROTO)" \
                if "not a built-in node or PROTO" in conv.losses[0].text else ""
            raise ImportRefused(_shown(conv.losses[0].text, source, label).replace("; skipped (with everything inside it)", "")
                                + hint)
        made = [("Solid", s) for s in conv.world["solids"][solids:]] + \
               [(lt["type"], lt) for lt in conv.world["lights"][lights:]]
        if len(made) != 1 or top.parts or conv.world["world_info"].keys() - {"coordinate_system"}:
            raise ImportRefused(f"{at}: {what}: not importable here: a node string holds solids (Solid, or a PROTO "
                                "that is one), lights (PointLight, SpotLight, DirectionalLight) and shapes (Shape, "
                                "or a Group, Pose or Transform of shapes) only")
        kinds.append(made[0][0])
        entry = conv.top_node(node, {})          # the PROTO's name as a world file's top-level node keeps it
        protos.append(entry.get("proto", "") if entry["type"] == made[0][0] else "")
        faces.append(tuple(wm.ProtoLevel.model_validate(x) for x in entry.get("interface", []))
                     if entry["type"] == made[0][0] else ())
    origin: dict[str, tuple[int, int, str]] = {}
    data = strip_origins({"solids": conv.world["solids"], "lights": conv.world["lights"]}, "", origin)
    data["world_info"] = {"coordinate_system": world.world_info.coordinate_system}
    try:
        parsed = parse_world(data, source=label, base_dir=loaded.base_dir, limits=limits,
                             allow_outside_meshes=allow_outside_meshes, asset_files=conv.asset_files)
        fragment = parsed.world
    except WorldError as exc:
        first = _wbt_problem(exc.problems[0], origin)
        more = f" (and {len(exc.problems) - 1} more)" if len(exc.problems) > 1 else ""
        if first.path.startswith("line "):      # placed at the string's node it came from
            where = first.path.replace("line ", f"{label}:", 1).replace(", column ", ":", 1)
        else:
            where = f"{label}: {first.path}" if first.path else label
        raise ImportRefused(f"{where}: {_shown(first.message, source, label)}{more}") from None
    if conv.textured:        # said once, as a world's are: a texture not loaded draws the shape untextured
        conv.warnings.append(conv.textures_not_loaded())
    warnings += [_shown(w, source, label) for w in conv.warnings]
    warnings += [_wbt_warning(w, origin, label) for w in parsed.warnings]
    queue: Counter[str] = Counter()
    out = []
    for kind, proto, face, visual, written in zip(kinds, protos, faces, visuals, wbt.nodes):
        group = "Solid" if kind == "Solid" else "light"
        models = fragment.solids if group == "Solid" else fragment.lights
        out.append(ImportedNode(kind, models[queue[group]], proto, face, visual, written))
        queue[group] += 1
    return out


def _only_shapes(node: Any) -> bool:
    """A Shape, or a Group holding only shapes (through Groups, Poses and Transforms)."""
    stack = [node]
    while stack:
        n = stack.pop()
        if not isinstance(n, ParsedNode) or n.type not in ("Shape", "Group", "Pose", "Transform") or n.proto is not None:
            return False
        if n.type != "Shape":
            children = n.fields.get("children", [])
            stack += children if isinstance(children, list) else [children]
    return True


def _unscaled(node: Any) -> bool:
    """A Transform without a scale other than 1 1 1 (a Pose has none): a Solid can stand for it."""
    scale = node.fields.get("scale")
    return scale is None or tuple(float(v) for v in scale) == (1.0, 1.0, 1.0)


def solid_count(solid: wm.Solid) -> tuple[int, int]:
    """A solid's solids (itself and its nested children) and lights."""
    n, lights = 1, len(solid.lights)
    for child in solid.children:
        dn, dl = solid_count(child)
        n, lights = n + dn, lights + dl
    return n, lights


def check_additions(world: wm.World, alive: set[str], lights_now: int, triangles_now: int, triangles_added: int,
                    nodes: list[ImportedNode], limits: WorldLimits, solids_now: int | None = None) -> None:
    """The world with ``nodes`` added stays within its limits (solids with their nested children,
    lights, triangles), else ``ImportRefused`` saying by how much. ``solids_now``: the world's solids
    (nested children included) when the caller keeps the count (else counted in ``world``'s ``alive`` ones)."""

    def over(what: str, now: int, added: int, cap: int) -> None:
        if now + added > cap:
            raise ImportRefused(f"importing it would bring the world to {now + added:,} {what} ({now:,} now, "
                                f"{added:,} added), more than the limit of {cap:,} (raise the limits with --allow-large)")

    if solids_now is None:
        solids_now = sum(solid_count(s)[0] for s in world.solids if s.name in alive)
    added = [solid_count(n.model) if n.type == "Solid" else (0, 1) for n in nodes]
    over("solids (nested children included)", solids_now, sum(a[0] for a in added), limits.solids)
    over("lights", lights_now, sum(a[1] for a in added), limits.lights)
    over("triangles", triangles_now, triangles_added, limits.triangles)


__all__ = ["parse_sf_node_string", "ImportRefused", "ImportedNode", "read_node_string", "rebuild_node", "check_additions",
           "solid_count", "string_file", "world_protos"]
