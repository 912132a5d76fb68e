"""Webots world files (``.wbt``, R2022a+ syntax) → a tree of ``Node`` objects.

The syntax is VRML97's as Webots writes it: a ``#VRML_SIM R2023b utf8`` header line, ``#`` comments,
commas as white space, ``[IMPORTABLE] EXTERNPROTO "url"`` declarations, ``PROTO`` definitions (read
by :mod:`sensorium.server.world.proto.interface`), and nodes ``[DEF name] Type { field value ... }``
or ``USE name``. Field values are parsed without knowing field types: a run of numbers, a string,
``TRUE``/``FALSE``, ``NULL``, a node, or a ``[ ... ]`` list of any of these; inside a PROTO body a
value may also be ``IS name`` (an ``IsRef``). ``hidden`` lines (Webots' saved joint and velocity
state) are read and dropped.

Work is bounded while parsing: the file size, the nesting depth, and the nodes and values the tree
holds once every ``USE`` is counted as the copy it stands for (``ProtoLimits``), so a small file
that USEs a big subtree many times is refused as soon as the count passes the bound. Every error
names the file, line and column (``WbtSyntaxError``) and quotes at most a short prefix of the input.
"""

from __future__ import annotations

import bisect
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sensorium.server.world.limits import ProtoLimits, quote

MAX_FILE_BYTES = 64 * 1024 * 1024
MAX_DEPTH = 100
MAX_NODES = 1_000_000      # nodes as written (the expanded count is ProtoLimits.nodes)
MAX_NAME_CHARS = 1024     # node types, field and DEF names
MAX_MESSAGE_CHARS = 2000   # an error line longer than this is cut (it never echoes a huge input)

_HEADER = re.compile(r"#VRML_SIM\s+R(\d{4})([a-z])\b")
_TOKEN = re.compile(r"""
    (?P<ws>[\s,]+)
  | (?P<comment>\#[^\n]*)
  | (?P<num>[+-]?(?:0[xX][0-9a-fA-F]+|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)(?![A-Za-z_]))
  | (?P<str>"[^"\\]*(?:\\.[^"\\]*)*")
  | (?P<tmpl>%<.*?>%)
  | (?P<punct>[{}\[\]])
  | (?P<name>[^\s,"#'.\[\]{}\\+\-0-9][^\s,"#'\[\]{}\\]*)
  | (?P<bad>.)
""", re.VERBOSE | re.DOTALL)


_NUM = r"[+-]?(?:0[xX][0-9a-fA-F]+|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)(?![A-Za-z_])"
# a run of numbers read in one go (big meshes: one token instead of one per number); the run stops
# at anything else (a comment, a word, a bracket), which is then tokenized as before
# (read a thousand numbers at a time: one match over a whole run keeps a backtracking frame per number)
_RUN = re.compile(_NUM + r"(?:[\s,]+" + _NUM + r"){0,1023}")
_RUN_MORE = re.compile(r"(?:[\s,]+" + _NUM + r"){1,1024}")
_NUM_AT = re.compile(_NUM)
_SPAN = re.compile(r"[0-9eE+\-.,\s]+")
RUN_MIN = 16        # shorter runs stay single "num" tokens

_SIGNED_NONFINITE = re.compile(r"[+-](?:nan|inf(?:inity)?)(?![^\s,\[\]{}])", re.IGNORECASE)


class WbtSyntaxError(Exception):
    """A .wbt file that cannot be read; the message is ``FILE:LINE:COL: what`` (one line, short)."""

    def __init__(self, source: str, line: int, col: int, message: str):
        if len(message) > MAX_MESSAGE_CHARS or "\n" in message:
            flat = message.replace("\n", " ")
            message = flat[:MAX_MESSAGE_CHARS] + (f"… ({len(flat)} characters)" if len(flat) > MAX_MESSAGE_CHARS else "")
        self.source, self.line, self.col, self.message = source, line, col, message
        super().__init__(f"{source}:{line}:{col}: {message}" if line else f"{source}: {message}")


class Lines:
    """Offset → (line, column), both 1-based, by bisection over the newline offsets."""

    def __init__(self, text: str):
        self.starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def at(self, pos: int) -> tuple[int, int]:
        i = bisect.bisect_right(self.starts, pos) - 1
        return i + 1, pos - self.starts[i] + 1


_Lines = Lines


class Token:
    """One token: kind ("num", "str", "name", "tmpl", "{", "}", "[", "]", "eof", or "nums": a run of
    numbers), text, offset; its line and column are computed when asked (errors and node positions
    only). A "nums" token's text and offset are its first number's (an error quoting it reads as one
    about that number); ``values`` are its numbers (floats, every one finite; once the parser has
    put them in a list value, a ``range`` of as many) and ``end`` where the run ends."""

    __slots__ = ("kind", "text", "pos", "lines", "values", "end")

    def __init__(self, kind: str, text: str, pos: int, lines: Lines):
        self.kind, self.text, self.pos, self.lines = kind, text, pos, lines

    @property
    def line(self) -> int:
        return self.lines.at(self.pos)[0]

    @property
    def col(self) -> int:
        return self.lines.at(self.pos)[1]


@dataclass(eq=False)
class Node:
    """One node as written: type name, fields in file order, position, DEF name.

    ``source`` is the file whose text the node was read from (a world or a PROTO file; a node a
    PROTO instance received through a field keeps the file it was written in). On the root node of
    an expanded PROTO instance, ``proto`` is the PROTO's name and ``instance_at`` the (file, line,
    column) of the instance as written."""

    type: str
    fields: dict[str, Any]
    line: int
    col: int
    def_name: str | None = None
    field_pos: dict[str, tuple[int, int]] = field(default_factory=dict)
    source: str = ""
    proto: str | None = None
    instance_at: tuple[str, int, int] | None = None


@dataclass(frozen=True)
class IsRef:
    """``field IS name`` inside a PROTO body: the value of the PROTO's field ``name``."""

    name: str
    line: int
    col: int


@dataclass(frozen=True)
class ExternProto:
    """One ``[IMPORTABLE] EXTERNPROTO "url"`` declaration and where it is written."""

    url: str
    line: int
    col: int
    importable: bool = False

    @property
    def name(self) -> str:
        """The PROTO it declares: the url's file name without ``.proto`` (as Webots matches them)."""
        base = self.url.replace("\\", "/").rstrip("/").rsplit("/", 1)[-1]
        return base[:-6] if base.lower().endswith(".proto") else base


@dataclass
class WbtFile:
    version: str                 # e.g. "R2023b"
    nodes: list[Node]            # top-level nodes in file order
    externprotos: list[str]      # declared EXTERNPROTO urls
    source: str = ""
    declarations: list[ExternProto] = field(default_factory=list)
    protos: list[Any] = field(default_factory=list)   # PROTO definitions written in the file (proto.interface.ProtoDef)
    header: list[str] = field(default_factory=list)   # the '#' comment lines after the first line
    warnings: list[str] = field(default_factory=list)  # what reading it said (an R2020b-R2021b world's conversion)
    legacy_protos: list[Node] = field(default_factory=list)  # an R2020b-R2021b world's PROTO instances (rule C)


class Tokens:
    """The token list, read lazily from the text, ``chunk`` tokens at a time (1 for a PROTO file's
    header: its body, template code, is never tokenized as VRML)."""

    def __init__(self, text: str, source: str, lines: Lines | None = None, start: int = 0, end: int | None = None,
                 chunk: int = 64):
        self.text, self.source, self.chunk = text, source, chunk
        self.lines = lines or Lines(text)
        self.items: list[Token] = []
        self._it: Iterator[re.Match[str]] | None = _TOKEN.finditer(text, start, len(text) if end is None else end)
        self.end = len(text) if end is None else end
        self._plain = 0         # numbers before this offset are single tokens (a run found too short or not plain)
        self._owed = 0          # tokens to read after a run that passed the end of its chunk

    def get(self, j: int) -> Token:
        items = self.items
        while j >= len(items) and self._it is not None:
            owed, self._owed = self._owed, 0
            self._more(owed or max(self.chunk, j + 1 - len(items)))
        return items[j] if j < len(items) else items[-1]

    def _more(self, n: int) -> None:
        items, lines = self.items, self.lines
        while self._it is not None:
            it = self._it
            for m in it:
                kind = m.lastgroup
                if kind == "ws" or kind == "comment":
                    continue
                value = m.group()
                if kind == "punct":
                    items.append(Token(value, value, m.start(), lines))
                elif kind == "num" and m.start() >= self._plain and (run := self._run(m.start())) is not None:
                    items.append(run)
                    self._it = _TOKEN.finditer(self.text, run.end, self.end)     # on after the run
                    # counted as its numbers; past the chunk, the reading after it is owed: read when the
                    # parser has taken the run, up to where a number-by-number reading would have read
                    # on (a multiple of chunk), so a later syntax error is met at the same point
                    n -= len(run.values)
                    if n < 0:
                        self._owed = n % self.chunk
                    if n <= 0:
                        return
                    break
                elif kind == "bad":
                    line, col = lines.at(m.start())
                    what = "unterminated string" if value == '"' else f"unexpected character {value!r}"
                    signed = _SIGNED_NONFINITE.match(self.text, m.start(), self.end) if value in "+-" else None
                    if signed:
                        what = f"number {quote(signed.group(), 40)} is not finite (a world's numbers must be finite)"
                    raise WbtSyntaxError(self.source, line, col, what)
                else:
                    items.append(Token(kind, value, m.start(), lines))  # type: ignore[arg-type]
                n -= 1
                if n <= 0:
                    return
            else:
                self._it = None
        items.append(Token("eof", "", self.end, lines))

    def _run(self, pos: int) -> Token | None:
        """The run of numbers starting at ``pos`` as one "nums" token, when it holds at least
        ``RUN_MIN`` numbers, all decimal and finite (else None, and its numbers are read one by one,
        so a hex or out-of-range number gets its own error as before)."""
        fast = self._span(pos)
        if fast is not None:
            end, parts, values = fast
        else:
            m = _RUN.match(self.text, pos, self.end)
            assert m is not None
            end = m.end()
            while (more := _RUN_MORE.match(self.text, end, self.end)) is not None:
                end = more.end()
            text = self.text[pos:end]
            parts = text.replace(",", " ").split()
            if len(parts) < RUN_MIN or "x" in text or "X" in text:
                self._plain = end
                return None
            values = floats(parts)
        if len(parts) < RUN_MIN or not all(map(math.isfinite, values)):     # short, or beyond ±1.8e308
            self._plain = end
            return None
        tok = Token("nums", parts[0], pos, self.lines)
        tok.values, tok.end = values, end
        return tok

    def _span(self, pos: int) -> tuple[int, list[str], list[float]] | None:
        """The run at ``pos`` found the quick way, (end, its numbers' texts, values): the longest stretch of
        digits, signs, dots, exponents and separators, cut after its last number, when every piece
        is a decimal number (``float`` reads exactly the ``_NUM`` grammar on these characters) and
        what follows cannot continue one (a letter, a digit of another script, ``_``). None: not
        sure, the run is matched number by number."""
        m = _SPAN.match(self.text, pos, self.end)
        if m is None or (m.end() < self.end and self.text[m.end()].isdecimal()):    # a digit of another script (\d reads it)
            return None
        body = m.group().rstrip()
        while body.endswith(","):
            body = body[:-1].rstrip()
        end = pos + len(body)
        if end < self.end:
            after = self.text[end]
            if after.isalnum() or after == "_":
                return None
        parts = body.replace(",", " ").split()
        try:
            return end, parts, floats(parts)
        except ValueError:
            return None

    def explode(self, j: int) -> None:
        """Item ``j``, a "nums" token, replaced by one "num" token per number (contexts that read one
        number at a time)."""
        run = self.items[j]
        self.items[j:j + 1] = [Token("num", m.group(), m.start(), self.lines)
                               for m in _NUM_AT.finditer(self.text, run.pos, run.end)]


def floats(parts: list[str]) -> list[float]:
    """``float`` of each text, one float object for each distinct text: a mesh's coordIndex repeats
    each vertex index about six times, and a float is 24 bytes (the values are those of
    ``map(float, parts)``; ValueError as it raises)."""
    if len(parts) < RUN_MIN:
        return list(map(float, parts))
    memo = {p: float(p) for p in set(parts)}
    return list(map(memo.__getitem__, parts))


def tokenize(text: str, source: str, lines: Lines | None = None) -> list[Token]:
    toks = Tokens(text, source, lines)
    toks.get(len(text) + 1)
    return toks.items


def unquote(text: str) -> str:
    return re.sub(r"\\(.)", r"\1", text[1:-1])


_unquote = unquote


class Parser:
    """Nodes and values from a token stream. ``proto_body``: ``IS name`` is a value (a PROTO body).
    ``nodes``/``values`` count what the tree holds once every USE stands for its copy."""

    def __init__(self, tokens: Tokens, source: str, *, limits: ProtoLimits | None = None, proto_body: bool = False):
        self.toks = tokens
        self.i = 0
        self.source = source
        self.limits = limits or ProtoLimits()
        self.proto_body = proto_body
        self.defs: dict[str, Node] = {}
        self.def_weight: dict[str, tuple[int, int]] = {}
        self.count = 0          # nodes as written
        self.nodes = 0          # nodes, USE counted as its copy
        self.values = 0         # scalar values, USE counted as its copy

    def error(self, tok: Token, message: str) -> WbtSyntaxError:
        return WbtSyntaxError(self.source, tok.line, tok.col, message)

    def peek(self, k: int = 0) -> Token:
        return self.toks.get(self.i + k)

    def take(self) -> Token:
        tok = self.toks.get(self.i)
        if tok.kind != "eof":
            self.i += 1
        return tok

    def expect(self, kind: str, what: str) -> Token:
        tok = self.take()
        if tok.kind != kind:
            raise self.error(tok, f"expected {what}, found {_describe(tok)}")
        if kind == "name" and len(tok.text) > MAX_NAME_CHARS:
            raise self.error(tok, f"a name of {len(tok.text):,} characters (at most {MAX_NAME_CHARS}): "
                                  f"{short(tok.text, 40)}")
        return tok

    def _grew(self, tok: Token) -> None:
        lim = self.limits
        if self.nodes > lim.nodes:
            raise self.error(tok, f"more than {lim.nodes:,} nodes once DEF/USE copies are counted "
                                  "(raise the limits with --allow-large)")
        if self.values > lim.values:
            raise self.error(tok, f"more than {lim.values:,} values once DEF/USE copies are counted "
                                  "(raise the limits with --allow-large)")

    def file(self, version: str, text: str) -> WbtFile:
        nodes: list[Node] = []
        protos: list[str] = []
        decls: list[ExternProto] = []
        defined: list[Any] = []
        while self.peek().kind != "eof":
            tok = self.peek()
            importable = False
            if tok.kind == "name" and tok.text == "IMPORTABLE" and self.peek(1).text == "EXTERNPROTO":
                self.take()
                importable = True
                tok = self.peek()
            if tok.kind == "name" and tok.text == "EXTERNPROTO":
                self.take()
                url = unquote(self.expect("str", "a quoted url after EXTERNPROTO").text)
                protos.append(url)
                decls.append(ExternProto(url, tok.line, tok.col, importable))
            elif tok.kind == "name" and tok.text == "PROTO":
                from sensorium.server.world.proto.interface import read_proto_definition

                defined.append(read_proto_definition(self, text, inline=True))
            else:
                nodes.append(self.node(0))
        return WbtFile(version, nodes, protos, self.source, decls, defined)

    def node(self, depth: int) -> Node:
        if depth > MAX_DEPTH:
            raise self.error(self.peek(), f"nodes nested deeper than {MAX_DEPTH} levels")
        tok = self.expect("name", "a node")
        if tok.text == "USE":
            ref = self.expect("name", "a DEF name after USE")
            if ref.text not in self.defs:
                raise self.error(ref, f"USE {short(ref.text, 40)}: no DEF {short(ref.text, 40)} before this point")
            n, v = self.def_weight[ref.text]
            self.nodes += n
            self.values += v
            self._grew(ref)
            return self.defs[ref.text]
        def_name = None
        if tok.text == "DEF":
            def_name = self.expect("name", "a name after DEF").text
            tok = self.expect("name", f"a node type after DEF {short(def_name, 40)}")
        if tok.text in ("TRUE", "FALSE", "NULL", "DEF", "USE", "IS"):
            raise self.error(tok, f"expected a node type, found {tok.text}")
        self.count += 1
        if self.count > MAX_NODES:
            raise self.error(tok, f"more than {MAX_NODES} nodes")
        nodes0, values0 = self.nodes, self.values
        self.nodes += 1
        self._grew(tok)
        self.expect("{", f"'{{' after node type {short(tok.text, 40)}")
        node = Node(tok.text, {}, *tok.lines.at(tok.pos), def_name, source=self.source)
        while True:
            ftok = self.take()
            if ftok.kind == "}":
                break
            if ftok.kind != "name":
                raise self.error(ftok, f"expected a field name or '}}' in {short(tok.text, 40)} (line {tok.line}), "
                                       f"found {_describe(ftok)}")
            if len(ftok.text) > MAX_NAME_CHARS:
                raise self.error(ftok, f"a field name of {len(ftok.text):,} characters (at most {MAX_NAME_CHARS}): "
                                       f"{short(ftok.text, 40)}")
            if ftok.text == "hidden":  # saved simulation state: "hidden NAME VALUE"
                self.expect("name", "a field name after 'hidden'")
                self.value(depth + 1)
                continue
            nxt = self.peek()
            if nxt.kind == "name" and nxt.text == "IS":
                self.take()
                ref = self.expect("name", "a PROTO field name after IS")
                if not self.proto_body:
                    raise self.error(nxt, "IS is only allowed inside a PROTO body")
                node.field_pos[ftok.text] = ftok.lines.at(ftok.pos)
                node.fields[ftok.text] = IsRef(ref.text, *ref.lines.at(ref.pos))
                continue
            value = self.value(depth + 1)
            if isinstance(node.fields.get(ftok.text), IsRef):
                continue     # given again after its IS: Webots keeps the field bound to the parameter
            node.field_pos[ftok.text] = ftok.lines.at(ftok.pos)
            node.fields[ftok.text] = value
        if def_name is not None:
            self.defs[def_name] = node
            self.def_weight[def_name] = (self.nodes - nodes0, self.values - values0)
        return node

    def value(self, depth: int) -> Any:
        tok = self.peek()
        if tok.kind == "[":
            self.take()
            items: list[Any] = []
            while self.peek().kind != "]":
                if self.peek().kind == "eof":
                    raise self.error(self.peek(), f"end of file inside the list opened at line {tok.line}, column {tok.col}")
                if self.peek().kind == "nums":
                    run = self.run(self.take())
                    if items:
                        items += run
                    else:
                        items = run         # (the token's list, handed over: no second list of the numbers)
                else:
                    items.append(self.item(depth))
            self.take()
            return items
        if tok.kind == "num" or tok.kind == "nums":
            nums: list[float] = []
            while True:
                kind = self.peek().kind
                if kind == "num":
                    nums.append(self.number(self.take()))
                elif kind == "nums":
                    nums += self.take().values
                else:
                    break
            self.nonfinite()
            self.values += len(nums)
            self._grew(tok)
            return nums[0] if len(nums) == 1 else tuple(nums)
        return self.item(depth)

    def run(self, tok: Token) -> list[float]:
        """A "nums" token's numbers, each counted as a value (the error names the number that passes
        the bound, as one read alone would)."""
        values = tok.values
        tok.values = range(len(values))     # (its count kept for the bound's error; the list goes to the node)
        self.values += len(values)
        if self.values > self.limits.values:
            self.values -= len(values)
            toks = self.toks
            # a number-by-number reading would have read the chunk holding the number that passes
            # the bound before counting it: when that chunk runs past the run, read on (a syntax
            # error there is met first, as it would have been)
            j = self.i - 1
            first = j + sum(len(t.values) - 1 for t in toks.items[:j] if t.kind == "nums")
            k = self.limits.values - self.values
            if (first + k) // toks.chunk == (first + len(values) - 1) // toks.chunk:
                toks.get(self.i)
            for m in _NUM_AT.finditer(self.toks.text, tok.pos, tok.end):
                self.values += 1
                self._grew(Token("num", m.group(), m.start(), tok.lines))
        return values

    def item(self, depth: int) -> Any:
        tok = self.peek()
        if tok.kind == "nums":          # one number at a time here (accepted values, ...)
            self.toks.explode(self.i)
            tok = self.peek()
        if tok.kind == "num":
            self.values += 1
            self._grew(tok)
            return self.number(self.take())
        if tok.kind == "str":
            self.values += 1
            self._grew(tok)
            return unquote(self.take().text)
        self.nonfinite()
        if tok.kind == "name":
            if tok.text in ("TRUE", "FALSE"):
                self.take()
                self.values += 1
                return tok.text == "TRUE"
            if tok.text == "NULL":
                self.take()
                return None
            return self.node(depth)
        if tok.kind == "tmpl":
            raise self.error(tok, "template statement (%< ... >%) outside a PROTO body")
        raise self.error(tok, f"expected a value, found {_describe(tok)}")

    def nonfinite(self) -> None:
        """Refuse ``nan``, ``inf`` or ``infinity`` (any case, signed) where a value may be next: they
        would otherwise be read as a field name or a node type, and the error would name something else
        (a node type, followed by '{', is left alone: a PROTO may be called Inf)."""
        tok = self.peek()
        if tok.kind == "name" and tok.text.lower() in ("nan", "inf", "infinity") and self.peek(1).kind != "{":
            raise self.error(tok, f"number {quote(tok.text, 40)} is not finite (a world's numbers must be finite)")

    def number(self, tok: Token) -> float:
        text = tok.text
        try:
            if text.lstrip("+-").lower().startswith("0x"):
                v = float(int(text, 16))
            else:
                v = float(text)
        except OverflowError:
            v = math.inf
        if not math.isfinite(v):
            raise self.error(tok, f"number {quote(text, 40)} is out of range (beyond ±1.8e308)")
        return v


_Parser = Parser


def short(text: str, limit: int = 40) -> str:
    """``text`` cut to a short prefix (names echoed in errors)."""
    return text if len(text) <= limit else text[:limit] + f"… ({len(text)} characters)"


def _describe(tok: Token) -> str:
    if tok.kind == "eof":
        return "end of file"
    return quote(tok.text, 60)


def header_version(text: str) -> tuple[int, str] | None:
    """The version of ``#VRML_SIM R20xxy utf8`` on the first line, (year, letter); None without one."""
    m = _HEADER.match(text.split("\n", 1)[0])
    return (int(m.group(1)), m.group(2)) if m else None


def parse_header(text: str, source: str, what: str = "world") -> tuple[int, str]:
    """The version of ``#VRML_SIM R20xxy utf8`` on the first line: (year, letter)."""
    version = header_version(text)
    if version is None:
        raise WbtSyntaxError(source, 1, 1, f"not a Webots {what}: the first line must be '#VRML_SIM R20xxy utf8'")
    return version


def header_comments(text: str) -> list[str]:
    """The ``#`` comment lines right after the first line (a file's licence, tags, template language)."""
    out = []
    for line in text.split("\n", 200)[1:200]:
        s = line.strip()
        if not s.startswith("#"):
            if s:
                break
            continue
        out.append(s[1:].strip())
    return out


def parse_wbt(text: str, source: str = "<memory>", limits: ProtoLimits | None = None) -> WbtFile:
    year, letter = parse_header(text, source)
    # Webots converts a world up to R2021b revision 1 (WbNodeUtilities::fixBackwardCompatibility: version >
    # WbVersion(2021, 1, 1) is read as written, so R2021c, its development name of R2022a, is)
    legacy = (2020, "b") <= (year, letter) <= (2021, "b")
    if (year, letter) < (2020, "b"):
        # worlds before R2020b: a vector gravity, northDirection (WbWorldInfo's conversion, not done here)
        raise WbtSyntaxError(source, 1, 1, f"Webots R{year}{letter} world: only R2020b-R2021b (converted) and "
                             "R2021c and later are supported (open and save it in Webots R2022a or later, whose "
                             "backward-compatibility pass turns its nodes to z-up, FLU; or run Webots' "
                             "scripts/converter/convert_nue_to_enu_rub_to_flu.py on a copy: it rewrites the file "
                             "in place, NUE to ENU)")
    wbt = Parser(Tokens(text, source), source, limits=limits).file(f"R{year}{letter}", text)
    wbt.header = header_comments(text)
    if legacy:
        from sensorium.server.world.wbt.legacy import turn_legacy

        wbt.warnings, wbt.legacy_protos = turn_legacy(wbt.nodes, wbt.version, source)
    return wbt


def read_text(path: str | Path, what: str, max_bytes: int) -> str:
    """A file's UTF-8 text, its size bounded; errors as ``WbtSyntaxError``."""
    path = Path(path)
    source = str(path)
    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise WbtSyntaxError(source, 0, 0, f"file of {size} bytes exceeds the {max_bytes}-byte limit for {what}s")
        data = path.read_bytes()
    except OSError as exc:
        raise WbtSyntaxError(source, 0, 0, f"cannot read {what} file: {exc.strerror or exc}") from None
    if data.startswith(b"\xef\xbb\xbf"):    # a byte-order mark (some Windows editors write one): dropped
        data = data[3:]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise WbtSyntaxError(source, line, exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1,
                             "not valid UTF-8") from None


def read_wbt(path: str | Path, limits: ProtoLimits | None = None) -> WbtFile:
    return parse_wbt(read_text(path, "world", MAX_FILE_BYTES), str(path), limits)
