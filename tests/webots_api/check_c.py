"""Builds the two programs that compare Sensorium's C and C++ libraries with Webots' API:

* ``c_program(include)``: every Sensorium C header, then c_functions.h (Webots' prototypes: one that
  differs from ours is a compile error), then a table of the address of every function (one the
  library lacks is a link error);
* ``cpp_program(include, listing)``: every Sensorium C++ header, then one compile-time check per line
  of cpp_methods.txt: the call (on a const object for a const method; with and without its defaulted
  parameters) compiles and its result converts to Webots' return type; each check carries its
  method's name, so a compiler error names what is missing.

The tests (tests/test_webots_api_names.py) compile them and report the names from the errors."""

from __future__ import annotations

import re
from pathlib import Path

HERE = Path(__file__).resolve().parent

# class-scope type names of Webots' C++ classes (Motor::Type, Robot::Mode, ...)
_NESTED = r"\b(Type|Mode|UserInputEvent|SimulationMode|IndicatorState|ControlMode|WiperMode|EngineType|WheelIndex" \
          r"|CoordinateSystem)\b"


def c_functions(listing: Path = HERE / "c_functions.h") -> list[str]:
    """The function names c_functions.h declares, in order (its prototypes come before its constants)."""
    text = listing.read_text(encoding="utf-8").split("/* constants a controller uses")[0]
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return re.findall(r"^[^\s#][^;]*?\b(wbu?_\w+)\s*\(", text, re.M)


def c_program(include: Path) -> str:
    headers = sorted(p.relative_to(include).as_posix() for p in (include / "webots").rglob("*.h"))
    lines = ["#include <stddef.h>"] + [f"#include <{h}>" for h in headers] + ['#include "c_functions.h"', "",
                                                    "typedef void (*any_function)(void);",
                                                    "const any_function table[] = {"]
    lines += [f"  (any_function){name}," for name in c_functions()]
    lines += ["};", "", "int main(void) { return table[0] == 0; }", ""]
    return "\n".join(lines)


def _params(text: str) -> list[tuple[str, bool]]:
    """``const std::string &name, int x = 1`` -> [("const std::string &", False), ("int", True)]."""
    if not text.strip():
        return []
    parts, depth, cur = [], 0, ""
    for ch in text:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            depth += (ch in "(<") - (ch in ")>")
            cur += ch
    parts.append(cur)
    out = []
    for part in parts:
        decl = part.split("=", 1)[0].strip()
        m = re.match(r"^(.*?)(\w+)$", decl)
        out.append((m.group(1).strip() if m and m.group(1).strip() else decl, "=" in part))
    return out


def cpp_checks(listing: Path = HERE / "cpp_methods.txt") -> list[str]:
    checks: list[str] = []
    cls = ""
    n = 0
    for raw in listing.read_text(encoding="utf-8").splitlines():
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("type "):
            n += 1
            checks.append(f"typedef {line[len('type '):]} type_{n};  // the type webots::{line[len('type '):]}")
            continue
        if line.startswith("class "):
            m = re.match(r"class (\w+)(?: : (\w+))?$", line)
            assert m, line
            cls, base = m.group(1), m.group(2)
            if base:
                checks.append(f'static_assert(std::is_base_of<{base}, {cls}>::value, "x");  // {cls} derives from {base}')
            continue

        def qual(t: str, cls: str = cls) -> str:
            return re.sub(_NESTED, rf"{cls}::\1", t)

        if line.startswith("enum "):
            name, value = line[len("enum "):].split(" = ")
            checks.append(f'static_assert({cls}::{name} == {value}, "x");  // {cls}::{name} == {value}')
            continue
        if line.startswith("ctor "):
            params = _params(line[len("ctor ("):-1])
            label = f"{cls}({', '.join(t for t, _ in params)})"
            types = "".join(", " + qual(t) for t, _ in params)
            checks.append(f'static_assert(std::is_constructible<{cls}{types}>::value, "x");  // {label}')
            continue
        m = re.match(r"^(static )?(.*?)\b(\w+)\((.*)\)( const)?$", line)
        assert m, line
        static, ret, name, args_text, const = m.groups()
        params, ret = _params(args_text), ret.strip()
        required = len(params)
        while required and params[required - 1][1]:
            required -= 1
        for k in sorted({required, len(params)}):
            args = ", ".join(f"std::declval<{qual(t)}>()" for t, _ in params[:k])
            obj = f"{cls}::" if static else f"std::declval<{'const ' if const else ''}{cls} &>()."
            expr = f"{obj}{name}({args})"
            label = f"{cls}::{name}({', '.join(t for t, _ in params[:k])}){const or ''} -> {ret}"
            n += 1
            if ret == "void":
                checks.append(f"typedef decltype({expr}) call_{n};  // {label}")
            else:
                checks.append(f'static_assert(std::is_convertible<decltype({expr}), {qual(ret)}>::value, "x");  '
                              f"// {label}")
    return checks


def cpp_program(include: Path, listing: Path = HERE / "cpp_methods.txt") -> str:
    headers = sorted(p.relative_to(include).as_posix() for p in (include / "webots").rglob("*.hpp"))
    lines = [f"#include <{h}>" for h in headers] + ["#include <string>", "#include <type_traits>", "#include <utility>",
                                                    "", "namespace webots {"]
    lines += cpp_checks(listing) + ["}  // namespace webots", "", "int main() { return 0; }", ""]
    return "\n".join(lines)


def failing_lines(program: str, compiler_output: str, name: str) -> list[str]:
    """The labels (``// ...``) of the program's lines a compiler error points at."""
    rows = program.splitlines()
    hit = sorted({int(n) for n in re.findall(rf"{re.escape(name)}:(\d+):\d+: error", compiler_output)})
    return [rows[i - 1].split("// ", 1)[-1] if "// " in rows[i - 1] else rows[i - 1] for i in hit]
