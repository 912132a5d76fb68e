"""YAML world text → plain data in one pass over libyaml's events, bounded while it is read.

PyYAML's own loader composes a node graph and resolves every scalar in Python: a 4 MB world took
~8 s with the C parser and ~17 s without, after a separate pass had checked its limits. Here the
C parser's events are turned into dicts, lists and scalars directly, and the limits are checked as
they come, so a hostile file stops at the first value over a bound:

* nesting depth and the number of values once aliases are expanded (``&a [*b, *b, ...]`` bombs);
* the number of robots, devices per robot, lights and solids (nested children included): the
  257th robot stops the read at its line, before the rest of the file is built.

The result is what ``yaml.load`` with YAML 1.2 booleans gave (``true``/``false`` only; Webots'
field name ``on`` stays a string): YAML 1.1 numbers, null, merge keys (``<<``; explicit keys win,
then the first merged mapping), timestamps, ``!!str``/``!!int``/``!!float``/``!!bool``/``!!null``/
``!!binary``/``!!timestamp`` tags. Departures (refused with a line and column): an alias inside
the node it names (a recursive structure), a key repeated in one mapping (YAML requires keys to be
unique; PyYAML kept the last value in silence), and the ``!!set``/``!!omap``/``!!pairs`` collection tags.
Errors are PyYAML's (``yaml.MarkedYAMLError``, with a mark) or :class:`~.limits.LimitError`.
"""

from __future__ import annotations

import re
from typing import Any

import yaml
from yaml.composer import ComposerError
from yaml.constructor import ConstructorError, SafeConstructor
from yaml.events import (
    AliasEvent,
    DocumentStartEvent,
    MappingEndEvent,
    MappingStartEvent,
    ScalarEvent,
    SequenceEndEvent,
    SequenceStartEvent,
    StreamEndEvent,
)
from yaml.nodes import ScalarNode

from sensorium.server.world.limits import RAISE, LimitError, WorldLimits

__all__ = ["YAML12_RESOLVERS", "load_yaml"]

try:
    from yaml.cyaml import CParser as _CParser  # libyaml
    _Parser: Any = _CParser
except ImportError:                                   # pragma: no cover - PyYAML built without libyaml
    _Parser = yaml.SafeLoader

# PyYAML's implicit resolvers (YAML 1.1 numbers, null, merge, timestamps) with YAML 1.2 booleans
YAML12_RESOLVERS: dict[str | None, list[tuple[str, re.Pattern[str]]]] = {
    k: [(tag, rx) for tag, rx in v if tag != "tag:yaml.org,2002:bool"]
    for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_BOOL = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
for _c in "tTfF":
    YAML12_RESOLVERS.setdefault(_c, []).append(("tag:yaml.org,2002:bool", _BOOL))

_T = "tag:yaml.org,2002:"
_STR, _INT, _FLOAT, _BOOLT, _NULL, _MERGE = (_T + t for t in ("str", "int", "float", "bool", "null", "merge"))
_SCALAR_TAGS = {_T + t for t in ("str", "int", "float", "bool", "null", "binary", "timestamp", "value")}
_DECIMAL = re.compile(r"[-+]?[1-9][0-9]*\Z")
_OPEN = object()                   # an anchor whose node is still being read


class _MergeKey:
    """The ``<<`` key of a mapping (kept apart until the mapping ends)."""


_MERGE_KEY = _MergeKey()


class _ValueKey:
    """A plain ``=`` (YAML 1.1's value key): a string as a mapping key, an error elsewhere (as PyYAML)."""


_VALUE_KEY = _ValueKey()


def _resolve(value: str) -> str:
    for tag, rx in YAML12_RESOLVERS.get(value[0] if value else "", ()):
        if rx.match(value):
            return tag
    return _STR


_CTOR = SafeConstructor()


def _scalar(event: ScalarEvent) -> Any:
    tag, value = event.tag, event.value
    if tag is None or tag == "!":
        if not event.implicit[0]:               # quoted, or a block scalar: a string
            return value
        tag = _resolve(value)
        if tag == _STR:
            return value
        if tag == _FLOAT and "_" not in value and ":" not in value and value[-1] not in "nNfF":
            return float(value)                 # the common case, without PyYAML's node machinery
        if tag == _INT and _DECIMAL.match(value):
            return int(value)
        if tag == _NULL:
            return None
        if tag == _BOOLT:
            return value[0] in "tT"
        if tag == _MERGE:
            return _MERGE_KEY
        if tag == _T + "value":
            return _VALUE_KEY
    elif tag not in _SCALAR_TAGS:
        raise ConstructorError(None, None, f"tag {tag!r} is not supported in world files", event.start_mark)
    if tag == _T + "value":
        return _VALUE_KEY
    return _CTOR.yaml_constructors[tag](_CTOR, ScalarNode(tag, value, event.start_mark, event.end_mark))


class _Frame:
    """An open mapping or sequence."""

    __slots__ = ("items", "is_map", "key", "has_key", "anchor", "start", "mark", "role", "count", "path",
                 "merges", "counted", "keys")

    def __init__(self, is_map: bool, anchor: str | None, start: int, mark: Any, role: str, path: str,
                 counted: bool):
        self.items: list[Any] = []              # a sequence's items, or a mapping's (key, value) pairs
        self.is_map = is_map
        self.key: Any = None                    # a mapping's key waiting for its value
        self.has_key = False
        self.counted = counted                  # a sequence of robots, devices, solids or lights
        self.anchor = anchor
        self.start = start                      # values counted before it opened (for anchored sizes)
        self.mark = mark
        self.role = role                        # what the world file's structure makes it (see _ROLES)
        self.count = 0                          # items so far (counted sequences)
        self.path = path
        self.merges: list[tuple[Any, Any]] = []
        self.keys: set[Any] | None = None       # a mapping's keys so far (a repeated key is refused)


# (parent role, key) → the role of the container under that key; items of a counted sequence get
# the item role. Roles follow the world schema: robots[i].devices, solids[i].children, *.lights.
_ROLES = {("root", "robots"): "robots", ("root", "solids"): "solids", ("root", "lights"): "lights",
          ("robot", "devices"): "devices", ("robot", "lights"): "lights",
          ("solid", "children"): "solids", ("solid", "lights"): "lights"}
_ITEM_ROLE = {"robots": "robot", "solids": "solid", "devices": "", "lights": ""}


def load_yaml(text: bytes | str, limits: WorldLimits | None = None) -> Any:
    """Parse and build ``text`` (one YAML document), checking ``limits`` as it goes."""
    limits = limits or WorldLimits()
    parser = _Parser(text)
    try:
        return _build(parser, limits)
    except yaml.MarkedYAMLError as exc:
        # libyaml looks ahead through "[[[[..." and stops at its own depth (1000) before we see it
        if "maximum nesting depth" in str(exc.problem) and exc.problem_mark is not None:
            raise LimitError(f"line {exc.problem_mark.line + 1}",
                             f"nested deeper than {limits.nesting_depth} levels {RAISE}") from None
        raise
    finally:
        parser.dispose()


def _build(parser: Any, limits: WorldLimits) -> Any:
    """The event loop (kept flat: it runs once per scalar of the file)."""
    get_event = parser.get_event
    stack: list[_Frame] = []
    anchors: dict[str, Any] = {}
    sizes: dict[str, int] = {}
    values = 0
    max_values = limits.values
    totals = {"robots": 0, "solids": 0, "lights": 0}
    caps = {"robots": limits.robots, "solids": limits.solids, "lights": limits.lights,
            "devices": limits.devices_per_robot}
    result: Any = None
    documents = 0
    frame: _Frame | None = None                 # the open container (stack[-1])
    while True:
        event = get_event()
        kind = type(event)
        if kind is ScalarEvent:
            if frame is not None and frame.counted:
                _count(frame, totals, caps, event)
            values += 1
            if values > max_values:
                raise _too_many_values(limits, event)
            node = _scalar(event) if event.tag is not None or event.implicit[0] else event.value
            if event.anchor is not None:
                _anchor(anchors, event)
                anchors[event.anchor] = node
                sizes[event.anchor] = 1
        elif kind is MappingEndEvent or kind is SequenceEndEvent:
            assert frame is not None
            done = stack.pop()
            node = _close(done) if done.is_map else done.items
            if done.anchor is not None:
                anchors[done.anchor] = node
                sizes[done.anchor] = values - done.start
            frame = stack[-1] if stack else None
        elif kind is MappingStartEvent or kind is SequenceStartEvent:
            if frame is not None and frame.counted:
                _count(frame, totals, caps, event)
            is_map = kind is MappingStartEvent
            tag = event.tag
            if tag not in (None, "!", _T + ("map" if is_map else "seq")):
                raise ConstructorError(None, None, f"tag {tag!r} is not supported in world files", event.start_mark)
            if len(stack) >= limits.nesting_depth:
                raise LimitError(f"line {event.start_mark.line + 1}",
                                 f"nested deeper than {limits.nesting_depth} levels {RAISE}")
            if event.anchor is not None:
                _anchor(anchors, event)
                anchors[event.anchor] = _OPEN
            role = _child_role(frame)
            frame = _Frame(is_map, event.anchor, values, event.start_mark, role, _child_path(frame),
                           not is_map and role in caps)
            stack.append(frame)
            values += 1
            if values > max_values:
                raise _too_many_values(limits, event)
            continue
        elif kind is AliasEvent:
            if frame is not None and frame.counted:
                _count(frame, totals, caps, event)
            if event.anchor not in anchors:
                raise ComposerError(None, None, f"found undefined alias {event.anchor!r}", event.start_mark)
            node = anchors[event.anchor]
            if node is _OPEN:
                raise ComposerError(None, None, f"alias *{event.anchor} refers to a node that contains it "
                                                "(recursive structures are not allowed)", event.start_mark)
            values += sizes.get(event.anchor, 1)
            if values > max_values:
                raise _too_many_values(limits, event)
        elif kind is StreamEndEvent:
            return result
        elif kind is DocumentStartEvent:
            documents += 1
            if documents > 1:
                raise ComposerError("expected a single document in the stream", None, "but found another document",
                                    event.start_mark)
            continue
        else:                                   # stream start, document end
            continue
        # a finished node: an item, a key or a value of the open container, or the document
        if frame is None:
            if node is _VALUE_KEY or node is _MERGE_KEY:
                raise _no_constructor(event)
            result = node
        elif not frame.is_map:
            if node is _VALUE_KEY or node is _MERGE_KEY:
                raise _no_constructor(event)
            frame.items.append(node)
        elif not frame.has_key:
            if isinstance(node, (list, dict)):
                raise ConstructorError("while constructing a mapping", frame.mark, "found unhashable key",
                                       event.start_mark)
            frame.key = "=" if node is _VALUE_KEY else node
            frame.has_key = True
            if node is not _MERGE_KEY:
                if frame.keys is None:
                    frame.keys = set()
                elif frame.key in frame.keys:
                    raise ConstructorError("while constructing a mapping", frame.mark,
                                           f"found duplicate key {_show_key(frame.key)}", event.start_mark)
                frame.keys.add(frame.key)
        else:
            if node is _VALUE_KEY or node is _MERGE_KEY:
                raise _no_constructor(event)
            if frame.key is _MERGE_KEY:
                frame.merges.append((node, event.start_mark))
            else:
                frame.items.append((frame.key, node))
            frame.key = None
            frame.has_key = False


def _show_key(key: Any) -> str:
    text = repr(key)
    return text if len(text) <= 60 else text[:60] + "…"


def _count(frame: _Frame, totals: dict[str, int], caps: dict[str, int], event: Any) -> None:
    """An item of robots, devices, solids or lights begins: count it against its limit."""
    frame.count += 1
    n = frame.count
    if frame.role in totals:
        totals[frame.role] += 1
        n = totals[frame.role]
    if n > caps[frame.role]:
        raise _too_many(frame, caps[frame.role], event)


def _too_many_values(limits: WorldLimits, event: Any) -> LimitError:
    return LimitError(f"line {event.start_mark.line + 1}",
                      f"more than {limits.values} values once aliases are expanded {RAISE}")


def _anchor(anchors: dict[str, Any], event: Any) -> None:
    if event.anchor in anchors:
        raise ComposerError(f"found duplicate anchor {event.anchor!r}", None, "second occurrence", event.start_mark)


def _child_role(parent: _Frame | None) -> str:
    if parent is None:
        return "root"
    if parent.is_map:
        if not parent.has_key or not isinstance(parent.key, str):
            return ""
        return _ROLES.get((parent.role, parent.key), "")
    return _ITEM_ROLE.get(parent.role, "")


def _child_path(parent: _Frame | None) -> str:
    if parent is None:
        return ""
    if parent.is_map:
        key = parent.key if isinstance(parent.key, str) else "?"
        return f"{parent.path}.{key}" if parent.path else key
    return f"{parent.path}[{len(parent.items)}]"


_NOUNS = {"robots": "robots", "solids": "solids (nested children included)", "lights": "lights",
          "devices": "devices in this robot"}


def _too_many(frame: _Frame, cap: int, event: Any) -> LimitError:
    return LimitError(frame.path, f"more than {cap:,} {_NOUNS[frame.role]}: the next starts at line "
                                  f"{event.start_mark.line + 1} {RAISE}")


def _no_constructor(event: Any) -> ConstructorError:
    return ConstructorError(None, None, "a plain '=' or '<<' is only a mapping key", event.start_mark)


def _close(frame: _Frame) -> dict:
    """A finished mapping: merged mappings first (the first one's keys win), then its own keys."""
    if not frame.merges:
        return dict(frame.items)
    out: dict = {}
    for value, mark in frame.merges:
        for m in (value if isinstance(value, list) else [value]):
            if not isinstance(m, dict):
                raise ConstructorError("while constructing a mapping", frame.mark,
                                       "expected a mapping or list of mappings for merging", mark)
            for k, v in m.items():
                out.setdefault(k, v)
    out.update(frame.items)
    return out
