"""Template: a procedural PROTO's body run as JavaScript (Webots reference manual, "Procedural PROTO
Nodes"), in QuickJS with no file, network, ``std`` or ``os`` access and bounded CPU time, memory,
stack and output.

The body's text is cut at ``%< statements >%`` and ``%<= expression >%``: plain text is emitted as
is, an expression's value as JavaScript's string of it, statements run where they stand; ``import
... from 'wbx.js'`` lines are hoisted, as Webots does. Templates see Webots' shapes:
``fields.<name>.value`` / ``.defaultValue`` (SFVec3f ``{x, y, z}``, SFRotation ``{x, y, z, a}``,
SFColor ``{r, g, b}``, SFVec2f ``{x, y}``, SFNode ``{node_name, fields}`` or ``undefined``, MF as
arrays) and ``context`` (world, proto, project_path, webots_home, temporary_files_path, os, id,
coordinate_system, webots_version ``{major, revision}``).

Programs run in :mod:`.engine` (QuickJS in a worker process). The modules are our own implementations (``modules/*.js``) of the documented ``wbgeometry``,
``wbrandom``, ``wbrotation``, ``wbvector2``, ``wbvector3`` and ``wbutility``; ``wbfile`` answers every
call with an error. Runs are reproducible: ``wbrandom``'s seed starts at 0 (Webots' default),
``Math.random`` is a fixed-seed generator and ``Date.now()`` is 0.

Every emitted piece records where it came from, so the generated text's nodes and errors point at
the PROTO file's own lines (:class:`MappedLines`).
"""

from __future__ import annotations

import bisect
import json
import re
from dataclasses import dataclass
from importlib.resources import files
from typing import Any

from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.proto.errors import ProtoError
from sensorium.server.world.wbt.parser import Lines, short

MODULES = ("wbgeometry", "wbrandom", "wbrotation", "wbvector2", "wbvector3", "wbutility")
_IMPORT = re.compile(r"""import\s+(?P<what>\*\s*as\s+[A-Za-z_$][\w$]*|\{[^}]*\}|[A-Za-z_$][\w$]*)\s*from\s*(?P<q>['"])(?P<mod>[^'"]*)(?P=q)\s*;?""")
_EXPORT = re.compile(r"^export\s+(?:function\*?|const|let|var|class)\s+([A-Za-z_$][\w$]*)", re.MULTILINE)
_STACK_LINE = re.compile(r"<input>:(\d+)")
_OUTPUT_LIMIT = "__sensorium_output_limit__"

_PRELUDE = r"""
"use strict";
globalThis.__messages = [];
globalThis.console = (function () {
  const say = (level) => function (...args) {
    if (__messages.length < 50) __messages.push([level, args.map((a) => String(a)).join(' ').slice(0, 400)]);
  };
  return {log: say('log'), info: say('info'), debug: say('debug'), warn: say('warn'), error: say('error')};
})();
globalThis.wbfile = (function () {
  const refuse = (name) => function () { throw new Error('wbfile.' + name + ': templates have no file access here'); };
  return {fileExists: refuse('fileExists'), readTextFile: refuse('readTextFile'), writeTextFile: refuse('writeTextFile')};
})();
Date.now = function () { return 0; };
Math.random = (function () {
  let s = 0x2545F491;                         // xorshift32, fixed seed: runs are reproducible
  return function () { s ^= s << 13; s ^= s >>> 17; s ^= s << 5; return (s >>> 0) / 4294967296; };
})();
globalThis.__mods = {wbfile: globalThis.wbfile};
"""


class MappedLines(Lines):
    """Positions in generated text → (line, column) in the PROTO file: text pieces map character
    for character, an expression's value to where ``%<=`` is written."""

    def __init__(self, file_lines: Lines, body_offset: int, pieces: list[tuple[int, int, int]]):
        self.file_lines = file_lines
        self.body_offset = body_offset
        self.out = [p[0] for p in pieces]
        self.pieces = pieces

    def at(self, pos: int) -> tuple[int, int]:
        i = bisect.bisect_right(self.out, pos) - 1
        if i < 0:
            return self.file_lines.at(self.body_offset)
        out_start, src, kind = self.pieces[i]
        return self.file_lines.at(self.body_offset + (src + pos - out_start if kind == 0 else src))


@dataclass
class Rendered:
    text: str
    lines: MappedLines
    messages: list[tuple[str, str]]


def _module_source(name: str) -> str:
    return (files("sensorium.server.world.proto") / "modules" / f"{name}.js").read_text(encoding="utf-8")


def _imports_of(code: str) -> list[tuple[str, str, re.Match[str]]]:
    """(binding text, module name, match) of each import statement in ``code``."""
    out = []
    for m in _IMPORT.finditer(code):
        mod = m.group("mod").rsplit("/", 1)[-1]
        mod = mod[:-3] if mod.endswith(".js") else mod
        out.append((m.group("what"), mod, m))
    return out


def _binding(what: str, mod: str) -> str:
    ref = f'__mods["{mod}"]'
    what = what.strip()
    if what.startswith("*"):
        return f"const {what.split()[-1]} = {ref};"
    if what.startswith("{"):
        parts = []
        for item in what[1:-1].split(","):
            item = item.strip()
            if not item:
                continue
            bits = item.split()
            parts.append(f"{bits[0]}: {bits[2]}" if len(bits) == 3 and bits[1] == "as" else bits[0])
        return f"const {{{', '.join(parts)}}} = {ref};"
    return f"const {what} = {ref}.default;"


_MODULE_JS: dict[str, str] = {}


def _module_js(name: str) -> str:
    """Our module ``name`` as a script that fills ``__mods[name]`` (dependencies first)."""
    if name in _MODULE_JS:
        return _MODULE_JS[name]
    src = _module_source(name)
    deps = []
    bindings = []
    for what, mod, m in _imports_of(src):
        deps.append(mod)
        bindings.append(_binding(what, mod))
        src = src.replace(m.group(0), " " * len(m.group(0)))
    exported = _EXPORT.findall(src)
    body = re.sub(r"^export\s+", "", src, flags=re.MULTILINE)
    script = "".join(_module_js(d) for d in deps if d in MODULES)
    script += (f'if (!__mods["{name}"]) __mods["{name}"] = (function () {{ "use strict"; {" ".join(bindings)}\n{body}\n'
               f'return {{{", ".join(exported)}}}; }})();\n')
    _MODULE_JS[name] = script
    return script


def referenced_fields(body: str, names: list[str]) -> list[str]:
    """The fields a template reads (``fields.NAME``); every field with ``fields[`` or the
    ``indirectFieldAccess`` tag (as Webots decides which fields regenerate a template)."""
    code = "".join(m.group(0) for m in re.finditer(r"%<.*?>%", body, re.DOTALL))
    if re.search(r"(^|\W)fields\s*\[", code) or re.search(r"(^|[^\w.])fields\s*[);,]", code):
        return list(names)
    return [n for n in names if re.search(rf"(^|\W)fields\.{re.escape(n)}($|\W)", code)]


class Budget:
    """CPU time left for the templates of one world."""

    def __init__(self, seconds: float):
        self.left = seconds


def render(body: str, *, source: str, proto: str, file_lines: Lines, body_offset: int, fields_js: str, context_js: str,
           limits: ProtoLimits, budget: Budget) -> Rendered:
    """Run one template; the generated text and where each of its characters came from."""
    from sensorium.server.world.proto import engine

    modules = "".join(_module_js(mod) for mod in _needed_modules(body))
    template, line_map = _program(body, fields_js, context_js, limits.template_output_chars, source, file_lines,
                                  body_offset, proto)
    before = _PRELUDE + modules + "\n"
    shift = before.count("\n")
    line_map = [(line + shift, off) for line, off in line_map]
    if budget.left <= 0:
        raise _over_budget(source, proto, file_lines, body_offset, limits)
    seconds = min(limits.template_seconds, budget.left)
    result = engine.run(before + template, memory=limits.template_memory, seconds=seconds)
    budget.left -= result.cpu
    if not result.ok:
        if result.kind in ("crash", "timeout"):
            what = (f"the template's JavaScript engine crashed (most likely it ran out of its "
                    f"{limits.template_memory >> 20} MiB of memory)" if result.kind == "crash"
                    else f"the template did not finish within {seconds * 4 + 5:g} s")
            raise ProtoError(source, *file_lines.at(body_offset), f"PROTO {proto}: {what}")
        if "interrupted" in result.error.split("\n", 1)[0] and seconds < limits.template_seconds:
            raise _over_budget(source, proto, file_lines, body_offset, limits)
        raise _template_error(result.error, result.kind, source, proto, file_lines, body_offset, line_map, limits,
                              seconds)
    out = result.out
    messages = [(str(level), str(msg)) for level, msg in json.loads(result.messages)]
    data = json.loads(out)
    parts, srcs = data["parts"], data["map"]
    triples = []
    n = 0
    for i, part in enumerate(parts):
        triples.append((n, srcs[2 * i], srcs[2 * i + 1]))
        n += len(part)
    return Rendered("".join(parts), MappedLines(file_lines, body_offset, triples), messages)


def _needed_modules(body: str) -> list[str]:
    code = "".join(m.group(0) for m in re.finditer(r"%<.*?>%", body, re.DOTALL))
    return [mod for _, mod, _ in _imports_of(code) if mod in MODULES]


def _program(body: str, fields_js: str, context_js: str, max_chars: int, source: str, file_lines: Lines,
             body_offset: int, proto: str) -> tuple[str, list[tuple[int, int]]]:
    """The template as a JavaScript function; (program line → source offset) for error lines."""
    head: list[str] = []
    lines: list[str] = []
    line_map: list[tuple[int, int]] = []
    pos = 0
    while True:
        start = body.find("%<", pos)
        if start < 0:
            if pos < len(body):
                line_map.append((len(lines) + 1, pos))
                lines.append(f"__emit({json.dumps(body[pos:])}, {pos}, 0);")
            break
        end = body.find(">%", start + 2)
        if end < 0:
            line, col = file_lines.at(body_offset + start)
            raise ProtoError(source, line, col, f"PROTO {proto}: template statement opened here is not closed by '>%'")
        if start > pos:
            line_map.append((len(lines) + 1, pos))
            lines.append(f"__emit({json.dumps(body[pos:start])}, {pos}, 0);")
        if body.startswith("%<=", start):
            code, code_at = body[start + 3:end], start + 3
            line_map.append((len(lines) + 1, code_at))
            lines.extend(f"__emit('' + ({code}\n), {start}, 1);".split("\n"))
        else:
            code, code_at = body[start + 2:end], start + 2
            for what, mod, m in _imports_of(code):
                if mod not in MODULES and mod != "wbfile":     # (wbfile: imported as Webots' templates do)
                    line, col = file_lines.at(body_offset + code_at + m.start())
                    raise ProtoError(source, line, col, f"PROTO {proto}: import of module {short(mod)!r}: not "
                                     f"available here (modules: {', '.join(m + '.js' for m in MODULES)})")
                head.append(_binding(what, mod))
                code = code[:m.start()] + re.sub(r"[^\n]", " ", m.group(0)) + code[m.end():]
            line_map.append((len(lines) + 1, code_at))
            lines.extend(code.split("\n"))
        pos = end + 2
    prologue = [
        "(function () {",
        '"use strict";',
        *head,
        f"const fields = {fields_js};",
        f"const context = {context_js};",
        "const __out = []; const __map = []; let __n = 0;",
        "function __emit(s, src, kind) {",
        f"  if (__n + s.length > {max_chars}) throw new Error('{_OUTPUT_LIMIT}');",
        "  __map.push(src, kind); __out.push(s); __n += s.length;",
        "}",
    ]
    epilogue = ["return JSON.stringify({parts: __out, map: __map});", "})()"]
    shift = len(prologue)
    program = "\n".join(prologue + lines + epilogue)
    return program, [(line + shift, off) for line, off in line_map]


def _over_budget(source: str, proto: str, file_lines: Lines, body_offset: int, limits: ProtoLimits) -> ProtoError:
    return ProtoError(source, *file_lines.at(body_offset), f"PROTO {proto}: the templates of this world used more than "
                      f"{limits.template_total_seconds:g} s of CPU time (raise the limits with --allow-large)")


def _template_error(text: str, kind: str, source: str, proto: str, file_lines: Lines, body_offset: int,
                    line_map: list[tuple[int, int]], limits: ProtoLimits, seconds: float) -> ProtoError:
    first = text.split("\n", 1)[0].strip()
    where = file_lines.at(body_offset)
    frames = [int(x) for x in _STACK_LINE.findall(text)]
    inside = [ln for ln in frames if line_map and ln >= line_map[0][0]]
    if inside:
        prog_line = inside[0]
        i = bisect.bisect_right([ln for ln, _ in line_map], prog_line) - 1
        if i >= 0:
            start_line, off = line_map[i]
            line, col = file_lines.at(body_offset + off)
            where = (line + prog_line - start_line, col if prog_line == start_line else 1)
    if _OUTPUT_LIMIT in text:
        what = f"the template generates more than {limits.template_output_chars:,} characters"
    elif "interrupted" in first:
        what = f"the template ran longer than {seconds:g} s of CPU time"
    elif "out of memory" in first:
        what = f"the template needs more than {limits.template_memory >> 20} MiB of memory"
    elif "stack overflow" in first or kind == "StackOverflow":
        what = "the template's recursion is too deep (stack overflow)"
    else:
        return ProtoError(source, *where, f"PROTO {proto}: template error: {short(first, 300)}")
    return ProtoError(source, *where, f"PROTO {proto}: {what} (raise the limits with --allow-large)")


# ------------------------------------------------------------------------------------ values as JavaScript


def js_number(x: float) -> str:
    return repr(float(x)) if x != int(x) or abs(x) >= 1e16 else str(int(x))


_VEC_KEYS = {"SFVec2f": "xy", "SFVec3f": "xyz", "SFRotation": "xyza", "SFColor": "rgb"}


def js_value(ftype: str, value: Any, node_js) -> str:
    """A field value (as checked by :func:`interface.check_value`) in Webots' JavaScript shape;
    ``node_js(node)`` writes an SFNode."""
    if ftype.startswith("MF"):
        single = "SF" + ftype[2:]
        if single in _VEC_KEYS:
            w = len(_VEC_KEYS[single])
            items = [tuple(value[i:i + w]) for i in range(0, len(value), w)]
        else:
            items = list(value)
        return "[" + ", ".join(js_value(single, v, node_js) for v in items) + "]"
    if ftype in _VEC_KEYS:
        return "{" + ", ".join(f"{k}: {js_number(v)}" for k, v in zip(_VEC_KEYS[ftype], value)) + "}"
    if ftype == "SFBool":
        return "true" if value else "false"
    if ftype in ("SFInt32", "SFFloat"):
        return js_number(value)
    if ftype == "SFString":
        return json.dumps(value)
    return node_js(value)
