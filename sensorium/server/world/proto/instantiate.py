"""Instantiate: every PROTO instance of a world replaced by the base nodes it stands for.

For an instance of PROTO P (declared by an EXTERNPROTO of the file the instance is written in, or
defined in that file): its field values are checked against P's interface (types, accepted values,
unknown fields are errors at file:line:col), the fields it does not give take P's defaults; P's
body is generated (a template, :mod:`.template`) or taken as written, parsed in a DEF/USE scope of
its own, and every ``field IS name`` in it, at any depth, is replaced by the value of P's field
``name``. The result is expanded in turn: PROTO instances inside P's body resolve through P's own
EXTERNPROTOs, nodes the instance passed in (slots such as ``extensionSlot``) through the file they
were written in. A PROTO that instantiates itself, directly or through others, is an error naming
the chain.

Nodes are never changed in place: a node whose subtree holds an instance is copied, the rest is
shared (as DEF/USE shares it), so a parsed body serves every instance. Work is bounded by
:class:`~sensorium.server.world.limits.ProtoLimits`: instances, nesting, the nodes and values of the
expanded tree (DEF/USE reuse counted), template time, memory and output.
"""

from __future__ import annotations

import json
import os
import platform
import re
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.proto import template as tpl
from sensorium.server.world.proto.errors import ProtoError
from sensorium.server.world.proto.interface import (
    BASE_NODES,
    FIELD_TYPES,
    FieldDecl,
    ProtoDef,
    accepted_list,
    check_value,
    read_proto_file,
    refused,
    show,
)
from sensorium.server.world.proto.resolve import ProtoSearch, logical_location, proto_index, resolve_url, webots_path
from sensorium.server.world.wbt import legacy as wbt_legacy  # (a module: legacy imports proto.interface)
from sensorium.server.world.wbt.convert import SKIPPED
from sensorium.server.world.wbt.parser import ExternProto, IsRef, Node, Parser, Tokens, WbtFile, WbtSyntaxError, short
from sensorium.server.world.wbt.protos import BUILTIN_PROTOS
from sensorium.server.world.wbt.resets import color as clamped_color
from sensorium.server.world.wbt.resets import shown

# PROTOs Sensorium stands in for when their file is not found: built-in expansions, and the
# visual-only nodes the converter skips anyway (backgrounds)
STAND_INS = frozenset(BUILTIN_PROTOS) | SKIPPED

# Webots' appearance PROTOs (SandyGround, Parquetry, ...: a PBRAppearance with textures, whose
# colorOverride, or a paint's baseColor, multiplies the texture) stand in, when their file is not
# found, as a plain PBRAppearance: this grey × that colour, and the roughness and metalness below (SolidBox's
# stand-in takes the same for its textured default)
APPEARANCE_GREY = 0.5
APPEARANCE_ROUGHNESS = 0.5
APPEARANCE_METALNESS = 0.0
_APPEARANCES = re.compile(r"projects/appearances/protos/[^/]+\.proto", re.IGNORECASE)

TREE_DEPTH = 150            # nodes nested inside one another in the expanded tree (the converter recurses)


@dataclass
class ProtoUse:
    """One PROTO the world used: its file, licence line and how many instances."""

    name: str
    path: str                          # the file it was read from ('' for a built-in stand-in)
    url: str                           # as declared (or the world file for a definition written in it)
    license: str | None
    license_url: str | None
    instances: int = 0
    builtin: bool = False              # Sensorium's built-in stand-in (the file was not found)


@dataclass
class Expansion:
    """A world with every PROTO instance expanded. ``nodes``: the world's top-level nodes, base
    nodes only (built-in stand-ins excepted); ``protos``: each PROTO used; ``warnings``: one
    "file:line:col: message" each; ``search``: where files were looked for (with the world's
    version tag), for resolving asset urls the same way."""

    nodes: list[Node]
    protos: list[ProtoUse]
    warnings: list[str]
    search: ProtoSearch
    wbt: WbtFile | None = None
    timings: dict[str, float] = field(default_factory=dict)   # wall seconds: "proto files", "template"

    def as_wbt(self) -> WbtFile:
        """The world file with its nodes replaced by the expansion."""
        assert self.wbt is not None
        return replace(self.wbt, nodes=self.nodes)


@dataclass
class _Scope:
    """What a file's node types resolve to: its EXTERNPROTOs and the PROTOs written in it."""

    source: str
    declared: dict[str, ExternProto]
    defined: dict[str, ProtoDef] = field(default_factory=dict)
    found: dict[str, ProtoDef | None] = field(default_factory=dict)


def expand(wbt: WbtFile, search: ProtoSearch, limits: ProtoLimits | None = None) -> Expansion:
    """Expand every PROTO instance of ``wbt`` (read by :func:`~sensorium.server.world.wbt.parser.read_wbt`).
    Raises ``ProtoError`` (one line) for a PROTO that cannot be found or instantiated."""
    if search.version is None:
        search = replace(search, version=wbt.version)
    from sensorium.server.world.proto import engine

    try:
        return _Expander(wbt, search, limits or ProtoLimits()).run()
    except ProtoError:
        raise
    except WbtSyntaxError as exc:      # in a PROTO file's text
        raise ProtoError(exc.source, exc.line, exc.col, exc.message) from None
    finally:
        engine.release()               # no worker process outlives the load


class _Expander:
    def __init__(self, wbt: WbtFile, search: ProtoSearch, limits: ProtoLimits):
        self.wbt = wbt
        self.search = search
        self.limits = limits
        self.world = wbt.source
        self.scopes: dict[str, _Scope] = {}
        world_scope = _Scope(self.world, _declared(wbt.declarations), {p.name: p for p in wbt.protos})
        self.scopes[self.world] = world_scope
        self.files: dict[str, ProtoDef] = {}               # resolved path → PROTO read
        self.uses: dict[str, ProtoUse] = {}
        self.warnings: list[str] = list(wbt.warnings)
        self.legacy_protos = {id(n) for n in wbt.legacy_protos}   # rule C (wbt.legacy)
        # the PROTO instances an old PROTO's converted body holds (wbt.legacy): id → (node, whether an instance's
        # field value holds it)
        self.legacy_inner: dict[int, tuple[Node, bool]] = {}
        self.noted: set[str] = set()
        self.stand_ins: dict[str, tuple[str, int, int]] = {}
        self.appearances: dict[str, set[str]] = {}          # file → the appearance PROTOs standing in there
        self.memo: dict[int, tuple[Node, Node]] = {}       # id(node) → (node, its expansion)
        self.outer: dict[int, tuple[str, ...]] = {}        # nodes an instance passed in → the chain they were written in
        self.bodies: dict[tuple[str, int, str], Node] = {}  # (PROTO file, body offset, generated text) → parsed root
        self.is_holders: dict[int, tuple[Node, bool]] = {}  # id(body node) → (node, whether an IS is under it)
        self.rendered: dict[tuple[str, int, str], tpl.Rendered] = {}
        self.budget = tpl.Budget(limits.template_total_seconds)
        self.instances = 0
        self.timings = {"proto files": 0.0, "template": 0.0}   # wall seconds (``sensorium bench --only loading``)
        self.coordinate_system = _coordinate_system(wbt.nodes)
        self.by_name = _before_externproto(wbt.version)     # R2022a: types found by PROTO file name
        for p in wbt.protos:
            self.warnings += p.warnings

    # ------------------------------------------------------------------ top level
    def run(self) -> Expansion:
        nodes = [self.node(n, (), 0) for n in self.wbt.nodes]
        self.check_size(nodes)
        self.unused_declarations()
        self.stand_in_note()
        return Expansion(nodes, list(self.uses.values()), self.warnings, self.search, self.wbt, self.timings)

    def check_size(self, nodes: list[Node]) -> None:
        """Nodes and values of the expanded tree, each DEF/USE or shared copy counted (what the
        converter walks), stopped at the bound; and the instances of each PROTO, counted alike."""
        Uses = dict[str, int] | None
        weight: dict[int, tuple[int, int, Uses]] = {}
        lim = self.limits
        total_n = total_v = 0
        total_uses: dict[str, int] = {}
        stand_ins = set(self.stand_ins)

        def add(into: Uses, more: Uses, times: int = 1) -> Uses:
            if not more:
                return into
            out = dict(into) if into else {}
            for k, c in more.items():
                out[k] = out.get(k, 0) + c * times
            return out

        def of(node: Node) -> tuple[int, int, Uses]:
            key = id(node)
            if key in weight:
                return weight[key]
            n, v = 1, 0
            uses: Uses = None
            own = node.__dict__.get("uses")
            if node.type in stand_ins:      # a built-in stand-in (RectangleArena, ...) the converter expands
                own = (*(own or ()), f"\0{node.type}")
            if own:
                uses = {}
                for k in own:
                    uses[k] = uses.get(k, 0) + 1
            for value in node.fields.values():
                dn, dv, du = of_value(value)
                n, v, uses = n + dn, v + dv, add(uses, du)
            weight[key] = (n, v, uses)
            return n, v, uses

        def of_value(value: Any) -> tuple[int, int, Uses]:
            if isinstance(value, Node):
                return of(value)
            if isinstance(value, list):
                if set(map(type, value)) <= _VALUE_TYPES:      # numbers, strings, booleans (a mesh's points)
                    return 0, len(value), None
                n = v = 0
                uses: Uses = None
                for x in value:
                    dn, dv, du = of_value(x)
                    n, v, uses = n + dn, v + dv, add(uses, du)
                return n, v, uses
            if isinstance(value, tuple):
                return 0, len(value), None
            return 0, 0 if value is None else 1, None

        for top in nodes:
            n, v, uses = of(top)
            total_n, total_v = total_n + n, total_v + v
            if total_n > lim.nodes or total_v > lim.values:
                what = f"{lim.nodes:,} nodes" if total_n > lim.nodes else f"{lim.values:,} values"
                raise ProtoError(top.source or self.world, top.line, top.col,
                                 f"the world holds more than {what} once PROTO instances are expanded and DEF/USE "
                                 "copies counted (raise the limits with --allow-large)")
            for k, c in (uses or {}).items():
                total_uses[k] = total_uses.get(k, 0) + c
        for k, c in total_uses.items():
            if k in self.uses:
                self.uses[k].instances = c

    def unused_declarations(self) -> None:
        scope = self.scopes[self.world]
        for name, decl in scope.declared.items():
            if name in scope.found or decl.importable or name in self.stand_ins:
                continue
            try:
                resolve_url(decl.url, self.world, self.search)
            except ProtoError as exc:
                self.warnings.append(f"{self.world}:{decl.line}:{decl.col}: EXTERNPROTO {short(name)} (not used by "
                                     f"the world): {exc.message}")

    # ------------------------------------------------------------------ resolution
    def scope_of(self, node: Node) -> _Scope | None:
        return self.scopes.get(node.source or self.world)

    def lookup(self, node: Node) -> ProtoDef | None:
        """The PROTO ``node``'s type names in the file it was written in (None: a base node, an
        undeclared type, or a built-in stand-in)."""
        scope = self.scope_of(node)
        if scope is None:
            return None
        name = node.type
        if name in scope.found:
            return scope.found[name]
        found: ProtoDef | None = None
        if name in scope.defined:
            found = scope.defined[name]
            self.use(found, "", found.source)
        elif name in scope.declared:
            found = self.load(scope, scope.declared[name])
        elif name not in BASE_NODES and (self.by_name or os.path.isfile(scope.source)) \
                and (path := self.undeclared(name)) is not None:
            # since R2022b a file must declare it: Webots says so, and loads it (a Supervisor's node string,
            # no file, imports only what the world declares, as in Webots)
            if not self.by_name:
                self.warnings.append(f"{scope.source}:{node.line}:{node.col}: missing declaration for {short(name)}: "
                                     f"add 'EXTERNPROTO \"{self.declaration(path, scope.source)}\"' to the file (found "
                                     "by its file name, as Webots finds it and says so)")
            found = self.load(scope, ExternProto(str(path), node.line, node.col))
        scope.found[name] = found
        return found

    def undeclared(self, name: str) -> Path | None:
        """A PROTO a file uses without declaring it, looked up by file name as Webots looks it up (a world
        before R2022b had no EXTERNPROTO; a later one missing a declaration gets Webots' error line and
        the PROTO): NAME.proto in the world's project's ``protos`` folder, then under the --proto-path
        folders, then in the installation's ``projects`` tree."""
        file = f"{name}.proto"
        project = Path(self.world).resolve().parent.parent / "protos"
        home = self.search.home
        for root in [project, *self.search.proto_path, *([home / "projects"] if home is not None else [])]:
            try:
                hit = proto_index(root).get(file) if root.is_dir() else None
            except OSError:
                hit = None
            if hit is not None:
                return hit
        return None

    def declaration(self, path: Path, source: str) -> str:
        """The url an EXTERNPROTO declaring ``path`` from file ``source`` gives: ``webots://`` within the
        installation, else relative to the file's folder."""
        home = self.search.home
        if home is not None and path.resolve().is_relative_to(home.resolve()):
            return "webots://" + path.resolve().relative_to(home.resolve()).as_posix()
        return Path(os.path.relpath(path.resolve(), Path(source).resolve().parent)).as_posix()

    def load(self, scope: _Scope, decl: ExternProto) -> ProtoDef | None:
        try:
            path = resolve_url(decl.url, scope.source, self.search)
        except ProtoError as exc:
            if decl.name in STAND_INS or _is_appearance(decl.url, scope.source, self.search):
                self.note_builtin(scope, decl, exc.message)
                return None
            raise ProtoError(scope.source, decl.line, decl.col, f"EXTERNPROTO {short(decl.name)}: {exc.message}") from None
        key = str(path)
        if key not in self.files:
            if len(self.files) >= self.limits.proto_files:
                raise ProtoError(scope.source, decl.line, decl.col, f"more than {self.limits.proto_files:,} PROTO files "
                                 "(raise the limits with --allow-large)")
            t0 = time.perf_counter()
            proto = read_proto_file(path, key, self.limits)
            self.timings["proto files"] += time.perf_counter() - t0
            if proto.name != decl.name:
                raise ProtoError(key, proto.line, proto.col, f"PROTO {short(proto.name)}: the name does not match the "
                                 f"file name {short(decl.name)}.proto (Webots requires them to match)")
            self.files[key] = proto
            self.scopes[key] = _Scope(key, _declared(proto.externprotos))
            self.warnings += proto.warnings
            self.version_note(path, decl)
        proto = self.files[key]
        self.use(proto, decl.url, key)
        return proto

    def use(self, proto: ProtoDef, url: str, path: str) -> None:
        key = f"{proto.source}\0{proto.name}"
        if key not in self.uses:
            self.uses[key] = ProtoUse(proto.name, path, url or path, proto.license, proto.license_url)

    def note_builtin(self, scope: _Scope, decl: ExternProto, why: str) -> None:
        appearance = decl.name not in STAND_INS
        if appearance:
            self.appearances.setdefault(scope.source, set()).add(decl.name)
        if decl.name not in self.stand_ins:
            self.stand_ins[decl.name] = (scope.source, decl.line, decl.col)
            what = ("Sensorium's built-in stand-in (no Webots file used)" if decl.name in BUILTIN_PROTOS
                    else "Sensorium's built-in stand-in: a plain PBRAppearance (no Webots file used)" if appearance
                    else f"not read (skipped: {_skipped_why(decl.name)})")
            self.uses[f"\0{decl.name}"] = ProtoUse(decl.name, "", decl.url, what, None, builtin=True)

    def stand_in_note(self) -> None:
        """One line for every PROTO file not found that Sensorium stands in for."""
        if not self.stand_ins:
            return
        source, line, col = min(self.stand_ins.values(), key=lambda at: (at[0] != self.world, at))
        built = sorted(n for n in self.stand_ins if n in BUILTIN_PROTOS)
        skipped = sorted(n for n in self.stand_ins if n in SKIPPED and n not in BUILTIN_PROTOS)
        looks = sorted(n for n in self.stand_ins if n not in STAND_INS)
        parts = ([f"Sensorium's built-in stand-ins used for {', '.join(built)}"] if built else []) + \
                ([f"plain PBRAppearances stand in for the appearances {', '.join(looks)} ({APPEARANCE_GREY:g} grey × "
                  "its colorOverride or baseColor, other fields ignored: cameras and infra-red distance sensors see that colour, not "
                  "the texture; lidars, range finders and other distance sensors are unaffected)"] if looks else []) + \
                [f"{name} skipped ({_skipped_why(name)})" for name in skipped]
        home = self.search.home
        hint = ("give --webots-home or WEBOTS_HOME to use Webots' own" if home is None else
                f"not in the Webots installation {home} nor the --proto-path folders: a complete installation "
                "(or --proto-path) gives Webots' own")
        self.warnings.append(f"{source}:{line}:{col}: PROTO files not found: {'; '.join(parts)} ({hint})")

    def version_note(self, path: Path, decl: ExternProto) -> None:
        home = self.search.home
        if home is None or "installation" in self.noted:
            return
        try:
            inside = path.resolve().is_relative_to(home.resolve())
        except OSError:
            inside = False
        installed = self.search.installed_version()
        wanted = self.search.version
        if inside and installed and wanted and installed != wanted:
            self.noted.add("installation")
            self.warnings.append(f"{self.world}: PROTOs of Webots {wanted} are read from the Webots {installed} "
                                 f"installation at {home} (its PROTOs may differ from {wanted}'s)")

    # ------------------------------------------------------------------ the walk
    def node(self, node: Node, chain: tuple[str, ...], depth: int) -> Node:
        key = id(node)
        hit = self.memo.get(key)
        if hit is not None:
            return hit[1]
        if depth > TREE_DEPTH:
            raise ProtoError(node.source or self.world, node.line, node.col,
                             f"nodes nested deeper than {TREE_DEPTH} levels once PROTOs are expanded")
        chain = self.outer.get(key, chain)
        proto = self.lookup(node)
        legacy = key in self.legacy_protos
        inner = self.legacy_inner.get(key)
        if inner is not None:
            legacy = self.legacy_nested(node, proto, inner[1])
        if legacy and proto is None and node.type in BUILTIN_PROTOS:
            # a stand-in for a PROTO Webots ships: its translation and rotation are its base Solid's
            node = _copy(node, fields=dict(node.fields))
            wbt_legacy.turn_proto_instance(node, pose=node.type != "TexturedBackgroundLight")
        if proto is not None:
            result = self.instance(node, proto, chain, depth)
            if legacy and self.ships(proto):
                result = _copy(result, fields=dict(result.fields))
                wbt_legacy.turn_proto_instance(result)
        elif self.appearances and node.type in self.appearances.get(node.source or self.world, ()):
            result = self.plain_appearance(node)
        else:
            result = self.fields(node, chain, depth)
        self.memo[key] = (node, result)
        return result

    def ships(self, proto: ProtoDef) -> bool:
        """Whether Webots ships ``proto``: its file under the installation (rule C of an R2020b-R2021b world)."""
        home = self.search.home
        return home is not None and Path(proto.source).resolve().is_relative_to(home.resolve())

    def legacy_nested(self, node: Node, proto: ProtoDef | None, foreign: bool) -> bool:
        """A PROTO instance inside an old PROTO's converted body: whether rule C turns it (Webots ships it);
        one Webots would convert twice (its own old body, at its creation and again within the outer
        one's), or that an instance's field value holds (Webots walks the value and its copy), is refused."""
        where = node.source or self.world
        if proto is None:
            ships = node.type in BUILTIN_PROTOS and node.type != "TexturedBackgroundLight"
        else:
            ships = self.ships(proto)      # (a pose is turned: its expansion's base node, turn_proto_instance)
            if not ships and converted(proto):
                raise ProtoError(where, node.line, node.col, f"{short(node.type)}: a PROTO written for Webots "
                                 f"{proto.version} inside another's body written before R2022a: Webots converts its "
                                 "body at its own instance and again within the outer one's; not converted here "
                                 "(port the PROTOs to R2022a's z-up axes)")
        if ships and foreign:
            raise ProtoError(where, node.line, node.col, f"{short(node.type)}: a PROTO Webots ships, given to a field "
                             "of an instance of a PROTO written before R2022a: Webots turns the value and its copy in "
                             "the body, in an order not settled here; not converted")
        return ships

    def legacy_body(self, root: Node, proto: ProtoDef, values: dict[str, Any]) -> Node:
        """Webots' conversion of an old PROTO's body at this instance (``wbt.legacy.turn_proto_body``) on a
        copy of ``root`` (the body with the instance's values), the nodes those values hold left shared."""
        if root.type not in BASE_NODES:
            raise ProtoError(proto.source, root.line, root.col, f"PROTO {proto.name} (written for Webots "
                             f"{proto.version}, whose body Webots converts at each instance): its body is an instance "
                             f"of {short(root.type)} (a derived PROTO), which Webots walks into as one node; not "
                             "converted here (port the PROTO to R2022a's z-up axes)")
        foreign: set[int] = set()
        stack = [v for v in values.values() if isinstance(v, (Node, list))]
        while stack:
            v = stack.pop()
            if isinstance(v, list):
                stack += [x for x in v if isinstance(x, (Node, list))]
            elif id(v) not in foreign:
                foreign.add(id(v))
                stack += [x for x in v.fields.values() if isinstance(x, (Node, list))]
        made: dict[int, Node] = {}

        def copy(n: Node) -> Node:
            if id(n) in foreign or n.type not in BASE_NODES:
                return n
            if id(n) in made:
                return made[id(n)]
            new = made[id(n)] = _copy(n, fields=dict(n.fields))
            for name, v in n.fields.items():
                if isinstance(v, Node):
                    new.fields[name] = copy(v)
                elif isinstance(v, list) and not set(map(type, v)) <= _VALUE_TYPES and any(isinstance(x, Node) for x in v):
                    new.fields[name] = [copy(x) if isinstance(x, Node) else x for x in v]
            return new

        root = copy(root)
        _, warnings, inner = wbt_legacy.turn_proto_body(root, proto.name, proto.version, proto.source,
                                                        frozenset(foreign))
        for n in inner:
            self.legacy_inner[id(n)] = (n, id(n) in foreign)
        self.warnings += [w for w in warnings if w not in self.warnings]
        return root

    def plain_appearance(self, node: Node) -> Node:
        """The PBRAppearance an appearance PROTO whose file is not found stands in as: grey × its
        ``colorOverride`` (a paint's ``baseColor``: MattePaint, GlossyCarPaint, ...), clamped to [0, 1] as
        Webots clamps a baseColor; its other fields (a textureTransform, IBLStrength, ...) are not used,
        whatever they are."""
        where = node.source or self.world
        color: tuple[float, ...] = (1.0, 1.0, 1.0)
        name = "colorOverride" if "colorOverride" in node.fields else "baseColor"
        if name in node.fields:
            raw = node.fields[name]
            line, col = node.field_pos.get(name, (node.line, node.col))
            if isinstance(raw, IsRef):
                raise ProtoError(where, raw.line, raw.col, f"IS {raw.name}: outside a PROTO body")
            try:
                color = tuple(check_value("SFColor", raw))
            except ValueError as exc:
                raise ProtoError(where, line, col, f"{node.type}.{name}: {exc}") from None
            fixed, why = clamped_color(color)
            if why:
                self.warnings.append(f"{where}:{line}:{col}: {node.type}.{name}: {shown(color)} {why}; using "
                                     f"{shown(fixed)} (as Webots does)")
            color = fixed
        self.instances += 1
        base = tuple(APPEARANCE_GREY * c for c in color)
        plain = Node("PBRAppearance", {"baseColor": base, "roughness": APPEARANCE_ROUGHNESS,
                                       "metalness": APPEARANCE_METALNESS}, node.line, node.col, def_name=node.def_name,
                     source=where, proto=node.type, instance_at=(where, node.line, node.col))
        return _copy(plain, uses=(f"\0{node.type}",), body_of=node.__dict__.get("body_of"))

    def fields(self, node: Node, chain: tuple[str, ...], depth: int) -> Node:
        changed: dict[str, Any] | None = None
        for name, value in node.fields.items():
            new = self.value(value, chain, depth)
            if new is not value:
                if changed is None:
                    changed = dict(node.fields)
                changed[name] = new
        if changed is None:
            return node
        return _copy(node, fields=changed)

    def value(self, value: Any, chain: tuple[str, ...], depth: int) -> Any:
        if isinstance(value, Node):
            return self.node(value, chain, depth + 1)
        if isinstance(value, list) and not set(map(type, value)) <= _VALUE_TYPES and any(isinstance(x, Node) for x in value):
            out = [self.node(x, chain, depth + 1) if isinstance(x, Node) else x for x in value]
            return value if all(a is b for a, b in zip(out, value)) else out
        if isinstance(value, IsRef):
            raise ProtoError(self.world, value.line, value.col, f"IS {value.name}: outside a PROTO body")
        return value

    # ------------------------------------------------------------------ one instance
    def instance(self, node: Node, proto: ProtoDef, chain: tuple[str, ...], depth: int) -> Node:
        where = node.source or self.world
        if proto.name in chain:
            loop = " → ".join([*chain[chain.index(proto.name):], proto.name])
            raise ProtoError(where, node.line, node.col, f"PROTO {proto.name} instantiates itself: {loop}")
        if len(chain) >= self.limits.depth:
            raise ProtoError(where, node.line, node.col, f"PROTO instances nested deeper than {self.limits.depth} "
                             f"levels: {' → '.join(chain[:6])} … {proto.name} (raise the limits with --allow-large)")
        self.instances += 1
        if self.instances > self.limits.instances:
            raise ProtoError(where, node.line, node.col, f"more than {self.limits.instances:,} PROTO instances "
                             "(raise the limits with --allow-large)")
        if proto.is_lua:
            raise ProtoError(proto.source, proto.line, proto.col, f"PROTO {proto.name}: Lua templates (Webots before "
                             "R2022b) are not supported: open and save the PROTO in Webots R2022b or later, or port its "
                             "template to JavaScript")
        values, given = self.values(node, proto, chain)
        body = self.body(node, proto, values)
        inner = (*chain, proto.name)
        root = self.substitute(body, proto, values, given, chain)
        if converted(proto):
            root = self.legacy_body(root, proto, values)
        out = self.node(root, inner, depth)
        # the PROTOs this node stands for (a derived PROTO's base too), counted where it sits in the
        # expanded tree (check_size): an expansion shared by several places is several instances
        uses = (f"{proto.source}\0{proto.name}", *out.__dict__.get("uses", ()))
        # its interface as the Supervisor reads it (interface_levels): this PROTO's values, then the
        # PROTO its body is an instance of (a derived PROTO's parent), each field's base-node field when
        # the value passes there through IS unchanged
        parent = out.__dict__.get("interface") if out.proto is not None else None
        parent_base: dict[str, str] | None = parent[2] if parent is not None else None
        base: dict[str, str | None] = {}
        for fname, value in body.fields.items():
            if isinstance(value, IsRef) and value.name not in base:
                base[value.name] = fname if parent_base is None else parent_base.get(fname)
        interface = (proto, values, {k: v for k, v in base.items() if v is not None}, parent)
        # body_of: the body the instance is written in (its root stands where the instance is written)
        return _copy(out, def_name=node.def_name, proto=proto.name, instance_at=(where, node.line, node.col), uses=uses,
                     interface=interface, body_of=node.__dict__.get("body_of"))

    def values(self, node: Node, proto: ProtoDef, chain: tuple[str, ...]) -> tuple[dict[str, Any], set[str]]:
        """The instance's value of every field of ``proto``, checked."""
        where = node.source or self.world
        values: dict[str, Any] = {}
        for name, raw in node.fields.items():
            line, col = node.field_pos.get(name, (node.line, node.col))
            decl = proto.fields.get(name)
            if decl is None:
                raise ProtoError(where, line, col, f"{proto.name}.{short(name)}: not a field of PROTO {proto.name} "
                                 f"(its fields: {proto.field_list()})")
            if isinstance(raw, IsRef):
                raise ProtoError(where, raw.line, raw.col, f"IS {raw.name}: outside a PROTO body")
            try:
                value = check_value(decl.type, raw)
            except ValueError as exc:
                raise ProtoError(where, line, col, f"{proto.name}.{name}: {exc}") from None
            bad = refused(decl, value, self.type_names)
            if bad is not None:
                raise ProtoError(where, line, col, f"{proto.name}.{name}: {show(bad)} is not an accepted value "
                                 f"(one of: {accepted_list(decl)})")
            values[name] = value
        given = set(values)
        for name, decl in proto.fields.items():
            values.setdefault(name, decl.default)
        return values, given

    def type_names(self, node: Node) -> set[str]:
        """A node's type and, for a PROTO instance, the base node type it expands to."""
        names = {node.type}
        proto = self.lookup(node)
        if proto is None and node.type in self.appearances.get(node.source or self.world, ()):
            names.add("PBRAppearance")       # a plain PBRAppearance stands in for it
        while proto is not None and len(names) < 16:
            base = _body_type(proto)
            if base is None or base in names:
                break
            names.add(base)
            probe = Node(base, {}, node.line, node.col, source=proto.source)
            proto = self.lookup(probe)
        return names

    # ------------------------------------------------------------------ the body
    def body(self, node: Node, proto: ProtoDef, values: dict[str, Any]) -> Node:
        """The PROTO's body as nodes (with IsRefs): generated by its template when it has one."""
        if not proto.is_template:
            key = (proto.source, proto.body_offset, "")    # a world file may define several PROTOs
            if key not in self.bodies:
                tokens = Tokens(proto.text, proto.source, proto.lines, proto.body_offset, proto.body_end)
                self.bodies[key] = self.parse_body(tokens, proto)
            return self.bodies[key]
        names = tpl.referenced_fields(proto.body, list(proto.fields))
        if "indirectFieldAccess" in proto.tags:
            names = list(proto.fields)
        fields_js = "{" + ", ".join(
            f"{n}: {{value: {self.js(proto.fields[n], values[n])}, defaultValue: {self.js(proto.fields[n], proto.fields[n].default)}}}"
            for n in names) + "}"
        deterministic = "nonDeterministic" not in proto.tags
        key = (proto.source, proto.body_offset, fields_js + "\0" + self.coordinate_system)
        rendered = self.rendered.get(key) if deterministic else None
        if rendered is None:
            context = self.context(proto)
            t0 = time.perf_counter()
            rendered = tpl.render(proto.body, source=proto.source, proto=proto.name, file_lines=proto.lines,
                                  body_offset=proto.body_offset, fields_js=fields_js, context_js=context,
                                  limits=self.limits, budget=self.budget)
            self.timings["template"] += time.perf_counter() - t0
            if deterministic:
                self.rendered[key] = rendered
            for level, message in rendered.messages:
                if level in ("error", "warn") and len(self.warnings) < 1000:
                    self.warnings.append(f"{proto.source}:{proto.line}:{proto.col}: PROTO {proto.name} (instance at "
                                         f"{node.source or self.world}:{node.line}): template says: {message}")
        bkey = (proto.source, proto.body_offset, rendered.text)
        if bkey not in self.bodies:
            try:
                self.bodies[bkey] = self.parse_body(Tokens(rendered.text, proto.source, rendered.lines), proto)
            except WbtSyntaxError as exc:
                raise ProtoError(exc.source, exc.line, exc.col, f"{exc.message} (in the text PROTO {proto.name}'s "
                                 "template generated)") from None
        return self.bodies[bkey]

    def parse_body(self, tokens: Tokens, proto: ProtoDef) -> Node:
        parser = Parser(tokens, proto.source, limits=self.limits, proto_body=True)
        first = parser.peek()
        if first.kind == "eof":
            raise ProtoError(proto.source, proto.line, proto.col, f"PROTO {proto.name}: the body holds no node")
        root = parser.node(0)
        extra = parser.peek()
        if extra.kind != "eof":
            raise parser.error(extra, f"PROTO {proto.name}: the body holds more than one node (found {extra.text!r} "
                                      "after its first node)")
        _mark_body(root, proto_key(proto))
        return root

    def context(self, proto: ProtoDef) -> str:
        world = os.path.abspath(self.world)
        home = self.search.home
        system = platform.system()
        version = self.search.version or ""
        ctx = {"world": world, "proto": logical_location(proto.source) if not proto.inline else world,
               "project_path": str(Path(world).parent.parent) + os.sep,
               "webots_home": str(home) if home is not None else "", "temporary_files_path": "",
               "os": {"Windows": "windows", "Darwin": "mac"}.get(system, "linux"), "id": str(self.instances),
               "coordinate_system": self.coordinate_system,
               "webots_version": {"major": version, "revision": "0"}}
        return json.dumps(ctx)

    def js(self, decl: FieldDecl, value: Any) -> str:
        budget = [2000]                       # nodes written out per field (a huge slot stays a small object)
        return tpl.js_value(decl.type, value, lambda n: self.node_js(n, budget, 0))

    def node_js(self, node: Node | None, budget: list[int], depth: int) -> str:
        if node is None:
            return "undefined"
        budget[0] -= 1
        if budget[0] < 0 or depth > 12:
            return json.dumps({"node_name": node.type, "fields": {}})
        proto = self.lookup(node)
        parts = []
        if proto is not None:
            for name, decl in proto.fields.items():
                try:
                    value = check_value(decl.type, node.fields[name]) if name in node.fields else decl.default
                except ValueError:
                    value = decl.default
                if isinstance(value, IsRef):
                    value = decl.default
                write = lambda n, b=budget, d=depth: self.node_js(n, b, d + 1)
                parts.append(f"{name}: {{value: {tpl.js_value(decl.type, value, write)}, "
                             f"defaultValue: {tpl.js_value(decl.type, decl.default, write)}}}")
        else:
            for name, value in node.fields.items():
                js = self.guess_js(name, value, budget, depth)
                parts.append(f"{name}: {{value: {js}, defaultValue: {js}}}")
        return "{node_name: " + json.dumps(node.type) + ", fields: {" + ", ".join(parts) + "}}"

    def guess_js(self, name: str, value: Any, budget: list[int], depth: int) -> str:
        """A base node's field in JavaScript without its declared type: numbers by their count
        (three numbers named like a colour are {r, g, b})."""
        write = lambda n: self.node_js(n, budget, depth + 1)
        if isinstance(value, Node) or value is None:
            return write(value)
        if isinstance(value, bool):
            return "true" if value else "false"
        if isinstance(value, float | int):
            return tpl.js_number(value)
        if isinstance(value, str):
            return json.dumps(value)
        if isinstance(value, tuple):
            kind = {2: "SFVec2f", 3: "SFColor" if "color" in name.lower() else "SFVec3f", 4: "SFRotation"}.get(len(value))
            if kind is None:
                return "[" + ", ".join(tpl.js_number(x) for x in value) + "]"
            return tpl.js_value(kind, value, write)
        if isinstance(value, list):
            return "[" + ", ".join(self.guess_js(name, x, budget, depth) for x in value) + "]"
        return "undefined"

    # ------------------------------------------------------------------ IS
    def substitute(self, body: Node, proto: ProtoDef, values: dict[str, Any], given: set[str],
                   chain: tuple[str, ...]) -> Node:
        """``body`` with every ``IS name`` replaced by the value of the PROTO's field ``name``;
        nodes the instance passed in keep the chain they were written in."""
        done: dict[int, Node] = {}

        def put(value: Any, name: str) -> Any:
            if name in given:
                for n in (value if isinstance(value, list) else [value]):
                    if isinstance(n, Node):
                        self.outer.setdefault(id(n), chain)
                        self.memo_keep(n)
            return value

        def walk(node: Node) -> Node:
            key = id(node)
            if key in done:
                return done[key]
            if not self.holds_is(node):
                done[key] = node
                return node
            changed: dict[str, Any] | None = None
            for fname, value in node.fields.items():
                new = value
                if isinstance(value, IsRef):
                    if value.name not in proto.fields:
                        raise ProtoError(proto.source, value.line, value.col, f"IS {short(value.name)}: PROTO "
                                         f"{proto.name} has no field {short(value.name)} (its fields: {proto.field_list()})")
                    new = put(values[value.name], value.name)
                    if isinstance(new, list):
                        new = list(new)
                elif isinstance(value, Node):
                    new = walk(value)
                elif isinstance(value, list) and any(isinstance(x, Node) for x in value):
                    out = [walk(x) if isinstance(x, Node) else x for x in value]
                    new = value if all(a is b for a, b in zip(out, value)) else out
                if new is not value:
                    if changed is None:
                        changed = dict(node.fields)
                    changed[fname] = new
            result = node if changed is None else _copy(node, fields=changed)
            done[key] = result
            return result

        return walk(body)

    def holds_is(self, node: Node) -> bool:
        """Whether an IS is written anywhere under ``node`` (body nodes, asked once each)."""
        key = id(node)
        known = self.is_holders.get(key)
        if known is not None:
            return known[1]
        found = False
        for value in node.fields.values():
            if isinstance(value, IsRef):
                found = True
            elif isinstance(value, Node):
                found = self.holds_is(value) or found
            elif isinstance(value, list) and not set(map(type, value)) <= _VALUE_TYPES:    # (a mesh's points: no node)
                for x in value:
                    if isinstance(x, Node) and self.holds_is(x):
                        found = True
        self.is_holders[key] = (node, found)
        return found

    def memo_keep(self, node: Node) -> None:
        """Nodes marked by id must stay alive while the expansion runs (ids are reused)."""
        self._kept = getattr(self, "_kept", [])
        self._kept.append(node)


def converted(proto: ProtoDef) -> bool:
    """Whether Webots converts the body of ``proto``'s instances: its file's header is R2021b or older
    (``fileVersion() > WbVersion(2021, 1, 1)`` is read as written; no header: read as current, here)."""
    m = re.fullmatch(r"R(\d{4})([a-z])", proto.version)
    return m is not None and (int(m.group(1)), m.group(2)) <= (2021, "b") and not proto.inline


def proto_key(proto: ProtoDef) -> str:
    """A PROTO definition's name among the bodies (its file and name: a world file may define several)."""
    return f"{proto.source}\0{proto.name}"


def _mark_body(root: Node, key: str) -> None:
    """Mark every node written in a PROTO's body (``body_of``: :func:`proto_key`), so the Supervisor tells
    the nodes of an instance's own body from those a nested instance's body holds (getFromProtoDef's
    scope: :func:`body_of`, :func:`chain_keys`). A parsed body is shared by the instances using it."""
    stack, seen = [root], set()
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        node.__dict__["body_of"] = key
        for value in node.fields.values():
            if isinstance(value, Node):
                stack.append(value)
            elif isinstance(value, list) and not set(map(type, value)) <= _VALUE_TYPES:
                stack += [x for x in value if isinstance(x, Node)]


def body_of(node: Node) -> str | None:
    """The PROTO body ``node`` is written in (:func:`proto_key`), None for a node the world file writes."""
    key: str | None = node.__dict__.get("body_of")
    return key


def chain_keys(node: Node) -> frozenset[str]:
    """The bodies an expanded PROTO instance is made of: its PROTO's, and for a derived PROTO the bodies
    of the PROTOs it is built on (one node in Webots: their DEFs are the instance's own)."""
    keys: list[str] = []
    level = node.__dict__.get("interface")
    while level is not None and len(keys) < 16:
        keys.append(proto_key(level[0]))
        level = level[3]
    return frozenset(keys)


def _is_appearance(url: str, source: str, search: ProtoSearch) -> bool:
    """Whether an EXTERNPROTO url names one of Webots' appearance PROTOs (its
    ``projects/appearances/protos/`` folder holds appearances only, all PBRAppearances)."""
    trees = [p for p in (search.home, *search.proto_path) if p is not None]
    rel = webots_path(url, source, trees)
    return rel is not None and _APPEARANCES.fullmatch(rel) is not None


def _skipped_why(name: str) -> str:
    """Why a PROTO Sensorium skips costs a user nothing, or what it costs."""
    if name == "TexturedBackground":     # its sky box is seen by Webots' cameras
        return "cameras see the flat sky colour, not its sky box"
    return "no effect on these sensors"


_VALUE_TYPES = {float, int, str, bool}     # list items that are neither nodes nor None (types gathered at C speed)


INTERFACE_ITEMS = 4096
"""Items of one interface field the Supervisor gets (an MF field's elements, a string's characters):
a longer value is not kept (its field answers one line), so a PROTO fed a mesh's points costs nothing."""


def interface_levels(node: Node) -> list[dict[str, Any]]:
    """A PROTO instance's interface as the Supervisor serves it (Webots' ``getProto()`` chain): one
    ``{"name", "fields"}`` per PROTO, the instance's own first, then the PROTO its body instantiates (a
    derived PROTO's parent), …; each field ``{"name", "type", "value"}`` in declaration order, the value
    the instance gives or the PROTO's default (SFVec3f → 3 numbers, MFFloat → a list, MFVec3f → lists of
    3), ``"base"``: the base node's field the value passes to through IS unchanged. A node-typed field,
    or a value over :data:`INTERFACE_ITEMS` items, is kept without its value (``"value"`` absent).
    [] for a base node or a built-in stand-in."""
    out: list[dict[str, Any]] = []
    level = node.__dict__.get("interface")
    while level is not None and len(out) < 16:
        proto, values, base, level = level[0], level[1], level[2], level[3]
        fields: list[dict[str, Any]] = []
        for name, decl in proto.fields.items():
            if decl.kind == "hidden" or len(name) > 256:   # Webots' saved state (translation_1, ...), not a parameter
                continue
            if len(fields) == INTERFACE_FIELDS:
                break
            entry: dict[str, Any] = {"name": name, "type": decl.type}
            value = _plain(decl.type, values.get(name, decl.default))
            if value is not _NOT_KEPT:
                entry["value"] = value
            if name in base:
                entry["base"] = base[name]
            fields.append(entry)
        out.append({"name": proto.name, "fields": fields, "derived": level is not None})
    return out


INTERFACE_FIELDS = 1024
"""Interface fields kept per PROTO (the world model's bound; a PROTO declares tens)."""

_NOT_KEPT = object()


def _plain(ftype: str, value: Any) -> Any:
    """An interface value as plain data (lists, numbers, strings), or _NOT_KEPT."""
    kind, width = FIELD_TYPES[ftype]
    if kind == "node" or isinstance(value, IsRef):
        return _NOT_KEPT
    if ftype.startswith("SF"):
        if kind == "vec":
            return [float(x) for x in value]
        if kind == "int":
            return int(value)
        if kind == "string" and len(value) > INTERFACE_ITEMS:
            return _NOT_KEPT
        return value
    if len(value) > INTERFACE_ITEMS * width:
        return _NOT_KEPT
    items = list(value)
    if kind == "vec":
        return [[float(x) for x in items[i:i + width]] for i in range(0, len(items), width)]
    if kind == "int":
        return [int(x) for x in items]
    if kind == "float":
        return [float(x) for x in items]
    if kind == "string" and sum(len(x) for x in items) > INTERFACE_ITEMS * 16:
        return _NOT_KEPT
    return items


def _copy(node: Node, **changes: Any) -> Node:
    """A shallow copy of ``node`` with some attributes changed (dataclasses.replace, without its cost)."""
    new = object.__new__(Node)
    new.__dict__.update(node.__dict__)
    new.__dict__.update(changes)
    return new


def _short_why(message: str) -> str:
    """The places tried, from a not-found message (the note stays one short line)."""
    looked = message.split("; looked in: ", 1)
    return "looked in: " + looked[1].split("; nothing is downloaded", 1)[0] if len(looked) == 2 else message


def _before_externproto(version: str) -> bool:
    """A world saved before R2022b, when Webots found PROTOs by name (it has no EXTERNPROTO)."""
    m = re.match(r"R(\d{4})([a-z])", version or "")
    return m is not None and (int(m.group(1)), m.group(2)) < (2022, "b")


def _declared(decls: list[ExternProto]) -> dict[str, ExternProto]:
    out: dict[str, ExternProto] = {}
    for d in decls:
        out.setdefault(d.name, d)
    return out


def _coordinate_system(nodes: list[Node]) -> str:
    for n in nodes:
        if n.type == "WorldInfo":
            v = n.fields.get("coordinateSystem", "ENU")
            return v if isinstance(v, str) else "ENU"
    return "ENU"


def _body_type(proto: ProtoDef) -> str | None:
    """The type of a PROTO body's root node as written (templates: the first word outside a statement)."""
    import re

    text = re.sub(r"%<.*?>%", " ", proto.body, flags=re.DOTALL)
    m = re.search(r"(?:DEF\s+\S+\s+)?([A-Za-z_][^\s{}\[\]\"#,]*)\s*\{", text)
    return m.group(1) if m else None


def protos_used(path: str | Path, webots_home: str | Path | None = None,
                proto_path: tuple[str | Path, ...] = ()) -> list[ProtoUse]:
    """The PROTOs a .wbt world uses (name, file, licence line, instances), for ``sensorium info``."""
    from sensorium.server.world.wbt.parser import read_wbt

    path = Path(path)
    return expand(read_wbt(path), ProtoSearch.create(path.resolve().parent, webots_home, proto_path)).protos


__all__ = ["expand", "protos_used", "interface_levels", "body_of", "chain_keys", "proto_key", "Expansion", "ProtoUse",
           "FIELD_TYPES", "WbtSyntaxError"]
