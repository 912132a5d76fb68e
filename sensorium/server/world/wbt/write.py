"""Parsed ``.wbt`` nodes written back as ``.wbt`` text, in Webots' layout (WbWriter's): two spaces of indent
per level, one field a line (``name value``), ``DEF NAME Type {`` ... ``}``, a list ``[`` with one item a
line and ``]`` on a line of its own (``[]`` when empty), strings quoted with ``\\`` and ``"`` escaped,
``TRUE``/``FALSE``/``NULL``, a node written a second time as ``USE NAME``.

Numbers are written as the shortest text that reads back to the same float64 (Webots rounds to its own
precision): an export read again gives the same values, bit for bit. The parser keeps no field types: a
list of numbers is written one item a line for the fields :data:`WIDTHS` knows (a Coordinate's ``point``,
a ``lookupTable``, ...), else all on one line, comma-separated (Webots' layout of an MFInt32 or MFFloat)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sensorium.server.world.wbt.parser import Node

INDENT = "  "

WIDTHS = {"lookupTable": 3, "Coordinate.point": 3, "TextureCoordinate.point": 2, "Normal.vector": 3, "Color.color": 3,
          "Background.skyColor": 3, "Background.groundColor": 3, "Background.groundAngle": 1, "Background.skyAngle": 1}
"""The numbers per item of the MF vector fields written one item a line (``Type.field``, or ``field`` in any node)."""


def number(v: float) -> str:
    """``v`` as the shortest text that reads back to the same float64; whole numbers without ``.0``."""
    if isinstance(v, bool):
        raise TypeError("a bool is no number here")
    f = float(v)
    if f.is_integer() and abs(f) < 1e16:
        return str(int(f)) if f != 0 else "0"
    return repr(f)


def string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


class Writer:
    """Nodes to text; a DEF node met again in the same writer is written ``USE NAME`` (Webots' rule).
    ``fields_of(node)``: the values to write in place of a node's own fields (None: its own), for every node
    written without ``fields`` given (the nodes inside one too). ``left_out``: ids of nodes not written in a
    list of nodes (a Shape a Supervisor removed)."""

    def __init__(self, fields_of: Callable[[Node], dict[str, Any] | None] | None = None,
                 left_out: frozenset[int] = frozenset()) -> None:
        self.fields_of = fields_of
        self.left_out = left_out
        self.written: set[int] = set()        # ids of the DEF nodes written so far
        self.written_nodes: set[int] = set()  # ids of the top-level nodes written so far (depth 0)

    def node(self, n: Node, depth: int = 0, fields: dict[str, Any] | None = None) -> str:
        """``n`` at ``depth`` levels of indent (its first line not indented: the caller places it);
        ``fields``: the values to write in place of ``n.fields`` (its own order kept)."""
        if n.def_name and id(n) in self.written:
            return f"USE {n.def_name}"
        if n.def_name:
            self.written.add(id(n))
        if depth == 0:
            self.written_nodes.add(id(n))
        if fields is None and self.fields_of is not None:
            fields = self.fields_of(n)
        head = f"DEF {n.def_name} {n.type}" if n.def_name else n.type
        lines = [head + " {"]
        pad = INDENT * (depth + 1)
        for name, value in (n.fields if fields is None else fields).items():
            if isinstance(value, list) and value and all(id(x) in self.left_out for x in value):
                continue                          # emptied: Webots' default, not written
            width = WIDTHS.get(f"{n.type}.{name}", WIDTHS.get(name))
            if width and isinstance(value, list) and value and all(_is_number(x) for x in value):
                value = [tuple(value[k:k + width]) for k in range(0, len(value), width)]
            lines.append(f"{pad}{name} {self.value(value, depth + 1)}")
        lines.append(INDENT * depth + "}")
        return "\n".join(lines)

    def value(self, v: Any, depth: int) -> str:
        if v is None:
            return "NULL"
        if isinstance(v, bool):
            return "TRUE" if v else "FALSE"
        if isinstance(v, str):
            return string(v)
        if isinstance(v, Node):
            return self.node(v, depth)
        if isinstance(v, tuple):                  # an SF vector, rotation or colour: its numbers on one line
            return " ".join(number(x) for x in v)
        if isinstance(v, list):
            v = [x for x in v if id(x) not in self.left_out]
            if not v:
                return "[]"
            pad = INDENT * (depth + 1)
            if all(_is_number(x) for x in v):
                return "[\n" + pad + ", ".join(number(x) for x in v) + "\n" + INDENT * depth + "]"
            items = [pad + (" ".join(number(x) for x in item) if isinstance(item, tuple) else self.value(item, depth + 1))
                     for item in v]
            return "[\n" + "\n".join(items) + "\n" + INDENT * depth + "]"
        if isinstance(v, int | float):
            return number(v)
        raise TypeError(f"a value of type {type(v).__name__} has no .wbt form")


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)
