"""Webots world files (``.wbt``, R2022a+ syntax) → a tree of ``Node`` objects.

The syntax is VRML97's as Webots writes it: a ``#VRML_SIM R2023b utf8`` header line, ``#`` comments,
commas as white space, ``EXTERNPROTO "url"`` declarations, and nodes ``[DEF name] Type { field value
... }`` or ``USE name``. Field values are parsed without knowing field types: a run of numbers, a
string, ``TRUE``/``FALSE``, ``NULL``, a node, or a ``[ ... ]`` list of any of these. ``hidden``
lines (Webots' saved joint and velocity state) are read and dropped.

Work is bounded: the file size, the nesting depth and the number of nodes are limited, and every
error names the file, line and column (``WbtSyntaxError``).
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

MAX_FILE_BYTES = 64 * 1024 * 1024
MAX_DEPTH = 100
MAX_NODES = 1_000_000

_HEADER = re.compile(r"#VRML_SIM\s+R(\d{4})([a-z])\b")
_TOKEN = re.compile(r"""
    (?P<ws>[\s,]+)
  | (?P<comment>\#[^\n]*)
  | (?P<num>[+-]?(?:0[xX][0-9a-fA-F]+|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)(?![A-Za-z_]))
  | (?P<str>"(?:[^"\\]|\\.)*")
  | (?P<punct>[{}\[\]])
  | (?P<name>[^\s,"#'.\[\]{}\\+\-0-9][^\s,"#'\[\]{}\\]*)
  | (?P<bad>.)
""", re.VERBOSE | re.DOTALL)


class WbtSyntaxError(Exception):
    """A .wbt file that cannot be read; the message is ``FILE:LINE:COL: what``."""

    def __init__(self, source: str, line: int, col: int, message: str):
        self.source, self.line, self.col, self.message = source, line, col, message
        super().__init__(f"{source}:{line}:{col}: {message}" if line else f"{source}: {message}")


class _Lines:
    """Offset → (line, column), both 1-based, by bisection over the newline offsets."""

    def __init__(self, text: str):
        self.starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def at(self, pos: int) -> tuple[int, int]:
        i = bisect.bisect_right(self.starts, pos) - 1
        return i + 1, pos - self.starts[i] + 1


class Token:
    """One token: kind ("num", "str", "name", "{", "}", "[", "]", "eof"), text, offset; its line
    and column are computed when asked (errors and node positions only)."""

    __slots__ = ("kind", "text", "pos", "lines")

    def __init__(self, kind: str, text: str, pos: int, lines: _Lines):
        self.kind, self.text, self.pos, self.lines = kind, text, pos, lines

    @property
    def line(self) -> int:
        return self.lines.at(self.pos)[0]

    @property
    def col(self) -> int:
        return self.lines.at(self.pos)[1]


@dataclass(eq=False)
class Node:
    """One node as written: type name, fields in file order, position, DEF name."""

    type: str
    fields: dict[str, Any]
    line: int
    col: int
    def_name: str | None = None
    field_pos: dict[str, tuple[int, int]] = field(default_factory=dict)


@dataclass
class WbtFile:
    version: str                 # e.g. "R2023b"
    nodes: list[Node]            # top-level nodes in file order
    externprotos: list[str]      # declared EXTERNPROTO urls


def tokenize(text: str, source: str) -> list[Token]:
    lines = _Lines(text)
    tokens: list[Token] = []
    append = tokens.append
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "ws" or kind == "comment":
            continue
        value = m.group()
        if kind == "punct":
            append(Token(value, value, m.start(), lines))
        elif kind == "bad":
            line, col = lines.at(m.start())
            what = "unterminated string" if value == '"' else f"unexpected character {value!r}"
            raise WbtSyntaxError(source, line, col, what)
        else:
            append(Token(kind, value, m.start(), lines))  # type: ignore[arg-type]
    append(Token("eof", "", len(text), lines))
    return tokens


def _unquote(text: str) -> str:
    return re.sub(r"\\(.)", r"\1", text[1:-1])


class _Parser:
    def __init__(self, tokens: list[Token], source: str):
        self.t = tokens
        self.n = len(tokens)
        self.i = 0
        self.source = source
        self.defs: dict[str, Node] = {}
        self.count = 0

    def error(self, tok: Token, message: str) -> WbtSyntaxError:
        return WbtSyntaxError(self.source, tok.line, tok.col, message)

    def peek(self, k: int = 0) -> Token:
        j = self.i + k
        return self.t[j] if j < self.n else self.t[-1]

    def take(self) -> Token:
        tok = self.t[self.i]
        if tok.kind != "eof":
            self.i += 1
        return tok

    def expect(self, kind: str, what: str) -> Token:
        tok = self.take()
        if tok.kind != kind:
            raise self.error(tok, f"expected {what}, found {_describe(tok)}")
        return tok

    def file(self, version: str) -> WbtFile:
        nodes: list[Node] = []
        protos: list[str] = []
        while self.peek().kind != "eof":
            tok = self.peek()
            if tok.kind == "name" and tok.text == "IMPORTABLE" and self.peek(1).text == "EXTERNPROTO":
                self.take()
                tok = self.peek()
            if tok.kind == "name" and tok.text == "EXTERNPROTO":
                self.take()
                protos.append(_unquote(self.expect("str", "a quoted url after EXTERNPROTO").text))
            elif tok.kind == "name" and tok.text == "PROTO":
                raise self.error(tok, "PROTO definitions inside a world file are not supported")
            else:
                nodes.append(self.node(0))
        return WbtFile(version, nodes, protos)

    def node(self, depth: int) -> Node:
        if depth > MAX_DEPTH:
            raise self.error(self.peek(), f"nodes nested deeper than {MAX_DEPTH} levels")
        tok = self.expect("name", "a node")
        if tok.text == "USE":
            ref = self.expect("name", "a DEF name after USE")
            if ref.text not in self.defs:
                raise self.error(ref, f"USE {ref.text}: no DEF {ref.text} before this point")
            return self.defs[ref.text]
        def_name = None
        if tok.text == "DEF":
            def_name = self.expect("name", "a name after DEF").text
            tok = self.expect("name", f"a node type after DEF {def_name}")
        if tok.text in ("TRUE", "FALSE", "NULL", "DEF", "USE"):
            raise self.error(tok, f"expected a node type, found {tok.text}")
        self.count += 1
        if self.count > MAX_NODES:
            raise self.error(tok, f"more than {MAX_NODES} nodes")
        self.expect("{", f"'{{' after node type {tok.text}")
        node = Node(tok.text, {}, *tok.lines.at(tok.pos), def_name)
        while True:
            ftok = self.take()
            if ftok.kind == "}":
                break
            if ftok.kind != "name":
                raise self.error(ftok, f"expected a field name or '}}' in {tok.text} (line {tok.line}), found {_describe(ftok)}")
            if ftok.text == "hidden":  # saved simulation state: "hidden NAME VALUE"
                self.expect("name", "a field name after 'hidden'")
                self.value(depth + 1)
                continue
            node.field_pos[ftok.text] = ftok.lines.at(ftok.pos)
            node.fields[ftok.text] = self.value(depth + 1)
        if def_name is not None:
            self.defs[def_name] = node
        return node

    def value(self, depth: int) -> Any:
        tok = self.peek()
        if tok.kind == "[":
            self.take()
            items: list[Any] = []
            while self.peek().kind != "]":
                if self.peek().kind == "eof":
                    raise self.error(self.peek(), f"end of file inside the list opened at line {tok.line}, column {tok.col}")
                items.append(self.item(depth))
            self.take()
            return items
        if tok.kind == "num":
            nums = []
            while self.peek().kind == "num":
                nums.append(_number(self.take()))
            return nums[0] if len(nums) == 1 else tuple(nums)
        return self.item(depth)

    def item(self, depth: int) -> Any:
        tok = self.peek()
        if tok.kind == "num":
            return _number(self.take())
        if tok.kind == "str":
            return _unquote(self.take().text)
        if tok.kind == "name":
            if tok.text in ("TRUE", "FALSE"):
                self.take()
                return tok.text == "TRUE"
            if tok.text == "NULL":
                self.take()
                return None
            return self.node(depth)
        raise self.error(tok, f"expected a value, found {_describe(tok)}")


def _number(tok: Token) -> float:
    text = tok.text
    if text.lstrip("+-").lower().startswith("0x"):
        return float(int(text, 16))
    return float(text)


def _describe(tok: Token) -> str:
    if tok.kind == "eof":
        return "end of file"
    return f"{tok.text!r}"


def parse_wbt(text: str, source: str = "<memory>") -> WbtFile:
    first = text.split("\n", 1)[0]
    m = _HEADER.match(first)
    if m is None:
        raise WbtSyntaxError(source, 1, 1, "not a Webots world: the first line must be '#VRML_SIM R20xxy utf8'")
    year, letter = int(m.group(1)), m.group(2)
    if (year, letter) < (2022, "a"):
        raise WbtSyntaxError(source, 1, 1, f"Webots R{year}{letter} world: only R2022a and later are supported "
                             "(open and save it in Webots R2022a+ to convert it to the z-up, FLU conventions)")
    return _Parser(tokenize(text, source), source).file(f"R{year}{letter}")


def read_wbt(path: str | Path) -> WbtFile:
    path = Path(path)
    source = str(path)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise WbtSyntaxError(source, 0, 0, f"file of {size} bytes exceeds the {MAX_FILE_BYTES}-byte limit for worlds")
        data = path.read_bytes()
    except OSError as exc:
        raise WbtSyntaxError(source, 0, 0, f"cannot read world file: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise WbtSyntaxError(source, line, exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1,
                             "not valid UTF-8") from None
    return parse_wbt(text, source)
