"""Parse: a PROTO's header and interface (Webots reference manual, "PROTO Definition").

A PROTO file is ``#VRML_SIM R20xxy utf8``, ``#`` header comments (``license:``, ``license url:``,
``tags:``, ``template language:`` ...), ``[IMPORTABLE] EXTERNPROTO "url"`` declarations, then
``PROTO Name [ declarations ] { body }``. A declaration is ``KIND TYPE[{accepted values}] name
default`` with KIND one of ``field``, ``vrmlField``, ``hiddenField``, ``deprecatedField``,
``unconnectedField`` (and ``hidden``, Webots' saved state) and TYPE one of the VRML97 field types
(SF/MF Bool, Int32, Float, Vec2f, Vec3f, Rotation, Color, String, Node). The body is kept as text:
it is a template when it holds ``%< ... >%`` statements (JavaScript), and is parsed into nodes
only when an instance needs it (:mod:`.instantiate`).

Values keep the shapes the .wbt parser gives (a number, a tuple of numbers, a string, a bool, a
node or None; MF values as flat lists), checked against the declared type by :func:`check_value`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.proto.errors import ProtoError
from sensorium.server.world.wbt.parser import (
    ExternProto,
    Lines,
    Node,
    Parser,
    Token,
    Tokens,
    header_comments,
    header_version,
    read_text,
    short,
    unquote,
)

# type → (element kind, numbers per element); element kinds: bool, int, float, vec, string, node
FIELD_TYPES: dict[str, tuple[str, int]] = {
    "SFBool": ("bool", 1), "SFInt32": ("int", 1), "SFFloat": ("float", 1), "SFVec2f": ("vec", 2),
    "SFVec3f": ("vec", 3), "SFRotation": ("vec", 4), "SFColor": ("vec", 3), "SFString": ("string", 1),
    "SFNode": ("node", 1),
}
FIELD_TYPES.update({"MF" + t[2:]: v for t, v in list(FIELD_TYPES.items())})
DECLARATION_KINDS = ("field", "vrmlField", "hiddenField", "deprecatedField", "unconnectedField", "hidden")
_HIDDEN_TYPES = (("rotation", "SFRotation"), ("translation", "SFVec3f"), ("position", "SFFloat"),
                 ("linearVelocity", "SFVec3f"), ("angularVelocity", "SFVec3f"))
_INT32 = 2 ** 31


@dataclass
class FieldDecl:
    """One interface field: its declared type, default (checked), accepted values (or None)."""

    name: str
    type: str
    kind: str
    default: Any
    line: int
    col: int
    accepted: list[Any] | None = None

    @property
    def multiple(self) -> bool:
        return self.type.startswith("MF")


@dataclass
class ProtoDef:
    """A PROTO as read: interface, declarations, header facts and the body's text."""

    name: str
    source: str                       # the file it was read from (Node.source of its nodes)
    text: str                         # the whole file's text (positions of the body's nodes)
    lines: Lines
    fields: dict[str, FieldDecl]
    externprotos: list[ExternProto]
    body: str                         # the body's text between its braces, '#' comments blanked
    body_offset: int                  # where the body starts in ``text``
    body_end: int
    line: int                         # where "PROTO" is written
    col: int
    header: list[str] = field(default_factory=list)
    version: str = ""
    inline: bool = False              # written inside a world file
    warnings: list[str] = field(default_factory=list)

    def header_value(self, key: str) -> str | None:
        for line in self.header:
            if line.lower().startswith(key + ":"):
                return line[len(key) + 1:].strip()
        return None

    @property
    def license(self) -> str | None:
        return self.header_value("license")

    @property
    def license_url(self) -> str | None:
        return self.header_value("license url")

    @property
    def tags(self) -> list[str]:
        return [t.strip() for t in (self.header_value("tags") or "").split(",") if t.strip()]

    @property
    def template_language(self) -> str | None:
        lang = self.header_value("template language")
        return lang.lower() if lang else None

    @property
    def is_template(self) -> bool:
        return "%<" in self.body

    @property
    def is_lua(self) -> bool:
        """A Lua template (Webots before R2022b): ``%{ ... }%`` statements or the header says so."""
        if self.template_language == "lua":
            return True
        return self.template_language is None and not self.is_template and "%{" in self.body and "}%" in self.body

    def field_list(self, limit: int = 30) -> str:
        names = list(self.fields)
        return ", ".join(names[:limit]) + (f", … ({len(names)} fields)" if len(names) > limit else "") if names else "none"


# ------------------------------------------------------------------------------------ reading


# what a PROTO body written before R2022a (y up) places along its axes: poses, directions, geometry and the
# devices Webots' conversion turns (wbt.legacy's A2)
_POSED = re.compile(r"\b(translation|rotation|location|direction|Box|Cylinder|Capsule|Cone|Plane|ElevationGrid|"
                    r"Coordinate|Mesh|CadShape|Camera|Lidar|Radar|Pen|Emitter|Receiver|Connector|TouchSensor|"
                    r"Track)\b")


def read_proto_file(path: Path, source: str, limits: ProtoLimits) -> ProtoDef:
    """A PROTO file: header comments, EXTERNPROTO declarations, interface, body text."""
    text = read_text(path, "PROTO", limits.proto_file_bytes)
    version = header_version(text)
    parser = Parser(Tokens(text, source, chunk=1), source, limits=limits)
    decls: list[ExternProto] = []
    while True:
        tok = parser.peek()
        importable = tok.kind == "name" and tok.text == "IMPORTABLE" and parser.peek(1).text == "EXTERNPROTO"
        if importable:
            parser.take()
            tok = parser.peek()
        if tok.kind == "name" and tok.text == "EXTERNPROTO":
            parser.take()
            url = unquote(parser.expect("str", "a quoted url after EXTERNPROTO").text)
            decls.append(ExternProto(url, tok.line, tok.col, importable))
            continue
        break
    if not (tok.kind == "name" and tok.text == "PROTO"):
        raise parser.error(tok, f"expected PROTO or EXTERNPROTO, found {_describe(tok)}")
    proto = read_proto_definition(parser, text, inline=False)
    proto.externprotos = decls
    if version is None:
        # Webots requires the header of worlds only: a PROTO without one is read, with a warning, as a file of
        # its own version (z up); every line of its leading comment block is a header comment
        proto.header = header_comments("\n" + text)
        proto.warnings.append(f"{source}:1:1: PROTO {proto.name}: no '#VRML_SIM R20xxy utf8' header on the "
                              "first line; read as a current (R2022a and later, z-up) PROTO, as Webots reads it")
        return proto
    year, letter = version
    proto.header = header_comments(text)
    proto.version = f"R{year}{letter}"
    if (year, letter) < (2022, "a") and _POSED.search(proto.body):    # a PROTO of devices alone has no poses to turn
        # Webots converts the body of a file up to R2021b at each instance (proto.instantiate: legacy_body)
        # and reads an R2021c one (its development name of R2022a) as written
        done = ("its body is converted at each instance as Webots R2022a and later convert it (Webots warns that "
                "parts may end up upside down)" if (year, letter) <= (2021, "b") else
                "read as written, as Webots reads it (it converts files up to R2021b): its poses may come out wrong")
        proto.warnings.append(f"{source}:1:1: PROTO {proto.name} was written for Webots R{year}{letter}, before "
                              f"R2022a's z-up, FLU conventions: {done}")
    return proto


def read_proto_definition(parser: Parser, text: str, inline: bool) -> ProtoDef:
    """``PROTO Name [ ... ] { ... }`` at the parser's position. A PROTO file's body runs to the
    file's last '}' (as Webots reads it: template branches need not balance braces); a definition
    written in a world file ends at its matching '}'."""
    start = parser.expect("name", "PROTO")
    name_tok = parser.expect("name", "a PROTO name after PROTO")
    name = name_tok.text
    if name in BASE_NODES:
        raise parser.error(name_tok, f"PROTO {name}: a PROTO cannot have the name of a Webots base node")
    saved = parser.defs, parser.def_weight          # default values are a DEF/USE scope of their own
    parser.defs, parser.def_weight = {}, {}
    try:
        parser.expect("[", f"'[' after PROTO {short(name)}")
        fields: dict[str, FieldDecl] = {}
        warnings: list[str] = []
        while parser.peek().kind != "]":
            if parser.peek().kind == "eof":
                raise parser.error(parser.peek(), f"end of file inside the interface of PROTO {short(name)}")
            decl = _declaration(parser, name, warnings)
            if decl.name in fields:
                warnings.append(f"{parser.source}:{decl.line}:{decl.col}: PROTO {name}: field {decl.name} declared "
                                "twice; the second declaration is ignored")
                continue
            fields[decl.name] = decl
        parser.take()
    finally:
        parser.defs, parser.def_weight = saved
    open_tok = parser.expect("{", f"'{{' opening the body of PROTO {short(name)}")
    body_offset = open_tok.pos + 1
    if inline:
        depth = 1
        while True:
            tok = parser.take()
            if tok.kind == "eof":
                raise parser.error(open_tok, f"end of file inside the body of PROTO {short(name)}")
            depth += (tok.kind == "{") - (tok.kind == "}")
            if depth == 0:
                break
        body_end = tok.pos
        body = blank_comments(text[body_offset:body_end])
    else:
        rest = blank_comments(text[body_offset:])
        cut = rest.rfind("}")
        if cut < 0:
            raise parser.error(open_tok, f"the body of PROTO {short(name)} has no closing '}}'")
        body, body_end = rest[:cut], body_offset + cut
    lines = parser.toks.lines
    return ProtoDef(name, parser.source, text, lines, fields, [], body, body_offset, body_end, start.line, start.col,
                    inline=inline, warnings=warnings)


def _declaration(parser: Parser, proto: str, warnings: list[str]) -> FieldDecl:
    kind_tok = parser.take()
    if kind_tok.kind != "name" or kind_tok.text not in DECLARATION_KINDS:
        raise parser.error(kind_tok, f"PROTO {short(proto)}: expected a field declaration ({', '.join(DECLARATION_KINDS[:-1])}), "
                                     f"found {_describe(kind_tok)}")
    if kind_tok.text == "hidden":
        ahead = parser.peek()
        ftype = next((t for prefix, t in _HIDDEN_TYPES if ahead.text.startswith(prefix)), "")
        if not ftype:
            raise parser.error(ahead, f"PROTO {short(proto)}: unknown hidden field {_describe(ahead)}")
    else:
        type_tok = parser.take()
        ftype = type_tok.text
        if type_tok.kind != "name" or ftype not in FIELD_TYPES:
            raise parser.error(type_tok, f"PROTO {short(proto)}: unknown field type {_describe(type_tok)} "
                                         f"(one of {', '.join(FIELD_TYPES)})")
    accepted: list[Any] | None = None
    if parser.peek().kind == "{":
        accepted = _accepted_values(parser, proto, ftype)
    name_tok = parser.expect("name", "a field name")
    if name_tok.text in DECLARATION_KINDS or name_tok.text in ("IS", "DEF", "USE"):
        raise parser.error(name_tok, f"PROTO {short(proto)}: expected a field name, found {name_tok.text}")
    at = parser.peek()
    raw = parser.value(0)
    try:
        default = check_value(ftype, raw)
    except ValueError as exc:
        raise parser.error(at, f"PROTO {short(proto)}.{short(name_tok.text)}: default value: {exc}") from None
    decl = FieldDecl(name_tok.text, ftype, kind_tok.text, default, name_tok.line, name_tok.col, accepted)
    if accepted is not None:
        bad = refused(decl, default, lambda n: {n.type})
        if bad is not None:
            warnings.append(f"{parser.source}:{at.line}:{at.col}: PROTO {proto}.{decl.name}: the default value is not "
                            "one of the accepted values (accepted anyway)")
            accepted.extend(_elements(decl.type, default))
    return decl


def _accepted_values(parser: Parser, proto: str, ftype: str) -> list[Any]:
    """``{v1, v2, ...}`` after a field type: single values of the field's element type."""
    open_tok = parser.take()
    items: list[Any] = []
    while parser.peek().kind != "}":
        if parser.peek().kind == "eof":
            raise parser.error(open_tok, "end of file inside a list of accepted values")
        items.append(parser.item(0))
    parser.take()
    kind, width = FIELD_TYPES[ftype]
    single = "SF" + ftype[2:]
    if kind in ("vec", "int", "float"):
        if not all(_is_num(x) for x in items) or len(items) % width:
            raise parser.error(open_tok, f"PROTO {short(proto)}: accepted values of a {ftype} must be groups of {width} "
                                         "number(s)")
        grouped = [tuple(items[i:i + width]) if width > 1 else items[i] for i in range(0, len(items), width)]
        items = grouped
    out = []
    for x in items:
        try:
            out.append(check_value(single, x))
        except ValueError as exc:
            raise parser.error(open_tok, f"PROTO {short(proto)}: accepted value: {exc}") from None
    return out


# ------------------------------------------------------------------------------------ values


def _is_num(x: Any) -> bool:
    return isinstance(x, float | int) and not isinstance(x, bool)


def show(v: Any) -> str:
    """A value as a message shows it: short."""
    if isinstance(v, Node):
        return f"a {short(v.type)} node"
    if isinstance(v, tuple):
        return f"{len(v)} numbers"
    if isinstance(v, list):
        return f"a list of {len(v)}"
    if isinstance(v, str):
        return repr(short(v, 60))
    if v is None:
        return "NULL"
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    return repr(v)


def check_value(ftype: str, v: Any) -> Any:
    """``v`` (as parsed) checked against a VRML type; the normalised value (MF: a flat list).
    Raises ``ValueError`` with what is wrong."""
    kind, width = FIELD_TYPES[ftype]
    if ftype.startswith("SF"):
        return _single(ftype, kind, width, v)
    items = v if isinstance(v, list) else [v]
    if kind in ("vec", "int", "float"):
        flat: list[float] = []
        for x in items:
            if isinstance(x, tuple):
                flat += x
            elif _is_num(x):
                flat.append(float(x))
            else:
                raise ValueError(f"{ftype} expects numbers, got {show(x)}")
        if len(flat) % width:
            raise ValueError(f"{ftype} expects groups of {width} numbers, got {len(flat)} numbers")
        if kind == "int":
            for x in flat:
                _int(x)
        return flat
    single = "SF" + ftype[2:]
    if kind == "node" and v is None:
        # a bare NULL for a whole MFNode value: no nodes, as Webots reads it (its Hinge2JointWithBacklash
        # declares `field MFNode startPoint NULL`); NULL inside brackets stays an error
        return []
    what = {"node": "nodes", "string": "strings", "bool": "TRUE or FALSE values"}[kind]
    out = []
    for x in items:
        if kind == "node" and x is None:
            raise ValueError(f"{ftype} expects nodes, got NULL")
        try:
            out.append(_single(single, kind, width, x))
        except ValueError:
            raise ValueError(f"{ftype} expects {what}, got {show(x)}") from None
    return out


def _int(x: float) -> float:
    if x != math.floor(x) or not -_INT32 <= x < _INT32:
        raise ValueError(f"SFInt32 expects a 32-bit integer, got {short(repr(x), 40)}")
    return x


def _single(ftype: str, kind: str, width: int, v: Any) -> Any:
    if kind == "bool":
        if not isinstance(v, bool):
            raise ValueError(f"{ftype} expects TRUE or FALSE, got {show(v)}")
        return v
    if kind in ("int", "float"):
        if not _is_num(v):
            raise ValueError(f"{ftype} expects one number, got {show(v)}")
        return _int(float(v)) if kind == "int" else float(v)
    if kind == "vec":
        if not isinstance(v, tuple) or len(v) != width:
            raise ValueError(f"{ftype} expects {width} numbers, got {show(v)}")
        return v
    if kind == "string":
        if not isinstance(v, str):
            raise ValueError(f"{ftype} expects a string, got {show(v)}")
        return v
    if v is not None and not isinstance(v, Node):
        raise ValueError(f"{ftype} expects a node or NULL, got {show(v)}")
    return v


def _elements(ftype: str, value: Any) -> list[Any]:
    """A value's elements, each as its SF type's value."""
    kind, width = FIELD_TYPES[ftype]
    if ftype.startswith("SF"):
        return [value]
    if kind in ("vec", "int", "float"):
        if width == 1:
            return list(value)
        return [tuple(value[i:i + width]) for i in range(0, len(value), width)]
    return list(value)


def refused(decl: FieldDecl, value: Any, type_names) -> Any:
    """The first element of ``value`` not among the accepted values (None when every one is).
    ``type_names(node)`` gives the names a node answers to (its type, the PROTO's base type)."""
    if decl.accepted is None:
        return None
    for x in _elements(decl.type, value):
        if isinstance(x, Node) or (x is None and FIELD_TYPES[decl.type][0] == "node"):
            if x is None:
                continue
            names = type_names(x)
            if not any(isinstance(a, Node) and a.type in names for a in decl.accepted):
                return x
        elif x not in decl.accepted:
            return x
    return None


def accepted_list(decl: FieldDecl, limit: int = 12) -> str:
    shown = [a.type if isinstance(a, Node) else (_vrml(a)) for a in (decl.accepted or [])]
    return ", ".join(shown[:limit]) + (f", … ({len(shown)})" if len(shown) > limit else "")


def _vrml(v: Any) -> str:
    if isinstance(v, str):
        return '"' + short(v, 40) + '"'
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, tuple):
        return " ".join(f"{x:g}" for x in v)
    if isinstance(v, float):
        return f"{v:g}"
    return repr(v)


def _describe(tok: Token) -> str:
    return "end of file" if tok.kind == "eof" else repr(short(tok.text, 60))


_COMMENTS = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"|%<.*?>%|#[^\n]*', re.DOTALL)


def blank_comments(text: str) -> str:
    """``text`` with its VRML ``#`` comments (outside strings and template statements) replaced by
    spaces: offsets and lines stay, and a comment never hides or starts a template statement."""
    return _COMMENTS.sub(lambda m: " " * len(m.group()) if m.group().startswith("#") else m.group(), text)


# the node types of Webots (R2023b reference manual): a PROTO may not take one of these names
BASE_NODES = frozenset("""
Accelerometer Altimeter Appearance Background BallJoint BallJointParameters Billboard Box Brake CadShape Camera
Capsule Charger Color Compass Cone Connector ContactProperties Coordinate Cylinder Damping DirectionalLight
Display DistanceSensor ElevationGrid Emitter Fluid Focus Fog GPS Group Gyro Hinge2Joint Hinge2JointParameters
HingeJoint HingeJointParameters ImageTexture ImmersionProperties IndexedFaceSet IndexedLineSet InertialUnit
Joint JointParameters LED Lens LensFlare Lidar LightSensor LinearMotor Material Mesh Microphone Motor Muscle
Normal Pen Physics Plane PointLight PointSet Pose PositionSensor Propeller Radar Radio RangeFinder Receiver
Recognition Robot RotationalMotor Shape Skin SliderJoint Slot Solid SolidReference Speaker SpotLight Sphere
TextureCoordinate TextureTransform TouchSensor Track TrackWheel Transform VacuumGripper Viewpoint WorldInfo
Zoom PBRAppearance
""".split())


def position(source: str, line: int, col: int, message: str) -> ProtoError:
    return ProtoError(source, line, col, message)
