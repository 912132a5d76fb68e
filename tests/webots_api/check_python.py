"""Compares Sensorium's Python controller packages (``controller``, ``vehicle``) with Webots' API as
listed in python.txt, and prints one line per gap (nothing when they agree). Run as a script, with
sensorium/client/webots on the path (as ``sensorium controller`` runs a controller):
``python tests/webots_api/check_python.py``."""

from __future__ import annotations

import ast
import importlib
import inspect
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
WEBOTS_DIR = HERE.parents[1] / "sensorium" / "client" / "webots"
_MISSING = object()


def _params(text: str) -> list[tuple[str, object]]:
    """``a, b=1`` -> [("a", _MISSING), ("b", 1)] (the listed defaults are Python literals)."""
    args = ast.parse(f"def f({text}): pass").body[0].args      # type: ignore[attr-defined]
    names = [a.arg for a in args.args]
    defaults = [ast.literal_eval(d) for d in args.defaults]
    return [(n, defaults[i - (len(names) - len(defaults))] if i >= len(names) - len(defaults) else _MISSING)
            for i, n in enumerate(names)]


def _check_signature(where: str, func: object, wanted: list[tuple[str, object]], static: bool) -> list[str]:
    try:
        sig = inspect.signature(func)            # type: ignore[arg-type]
    except (TypeError, ValueError):
        return [f"{where}: no signature to check"]
    params = list(sig.parameters.values())
    if not static:
        params = params[1:]                      # self
    if any(p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) for p in params):
        return [f"{where}{sig}: takes *args/**kwargs, Webots' is ({', '.join(n for n, _ in wanted)})"]
    problems = []
    for i, (name, default) in enumerate(wanted):
        if i >= len(params):
            problems.append(f"{where}: parameter {name!r} missing")
            continue
        p = params[i]
        if p.name != name:
            problems.append(f"{where}: parameter {i + 1} is {p.name!r}, Webots' is {name!r}")
        if p.kind not in (p.POSITIONAL_OR_KEYWORD,):
            problems.append(f"{where}: parameter {name!r} is {p.kind.description}, Webots' is positional or keyword")
        if default is not _MISSING and (p.default is p.empty or p.default != default):
            shown = "none" if p.default is p.empty else repr(p.default)
            problems.append(f"{where}: parameter {name!r} defaults to {shown}, Webots' to {default!r}")
    for p in params[len(wanted):]:
        if p.default is p.empty and p.kind not in (p.KEYWORD_ONLY,):
            problems.append(f"{where}: extra parameter {p.name!r} without a default")
        elif p.kind == p.KEYWORD_ONLY and p.default is p.empty:
            problems.append(f"{where}: extra keyword {p.name!r} without a default")
    return problems


def _lookup(cls: type, name: str) -> object:
    for klass in cls.__mro__:
        if name in vars(klass):
            return vars(klass)[name]
    return _MISSING


def _has_attr(cls: type, name: str) -> bool:
    if _lookup(cls, name) is not _MISSING:
        return True
    for klass in cls.__mro__:
        if name in getattr(klass, "__dataclass_fields__", {}) or name in getattr(klass, "__slots__", ()):
            return True
        if name in getattr(klass, "__annotations__", {}):
            return True
        try:
            if re.search(rf"\bself\.{name}\s*[:=]", inspect.getsource(klass)):
                return True
        except (OSError, TypeError):
            pass
    return False


def check(listing: Path = HERE / "python.txt") -> list[str]:
    problems: list[str] = []
    cls: type | None = None
    where = ""
    for raw in listing.read_text(encoding="utf-8").splitlines():
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        kind, _, rest = line.partition(" ")
        if kind == "module":
            mod_name, _, names = rest.partition(":")
            mod = importlib.import_module(mod_name)
            problems += [f"{mod_name}: no {n}" for n in names.split() if not hasattr(mod, n)]
        elif kind == "submodule":
            try:
                importlib.import_module(rest)
            except ImportError as e:
                problems.append(f"{rest}: cannot be imported ({e})")
        elif kind == "class":
            path, _, base = rest.partition("(")
            mod_name, _, cls_name = path.rpartition(".")
            where = f"{mod_name.split('.')[0]}.{cls_name}"
            cls = None
            try:
                cls = getattr(importlib.import_module(mod_name), cls_name)
            except (ImportError, AttributeError) as e:
                problems.append(f"{where}: missing ({e})")
                continue
            base = base.rstrip(")")
            if base and base not in [k.__name__ for k in cls.__mro__]:
                problems.append(f"{where}: does not derive from {base}")
        elif cls is None:
            continue
        elif kind in ("def", "static"):
            name, _, args = rest.partition("(")
            member = _lookup(cls, name)
            at = f"{where}.{name}"
            if member is _MISSING:
                problems.append(f"{at}: missing")
            elif isinstance(member, property):
                problems.append(f"{at}: a property, Webots' is a method")
            elif kind == "static" and not isinstance(member, staticmethod):
                problems.append(f"{at}: not a static method")
            elif kind == "def" and isinstance(member, (staticmethod, classmethod)):
                problems.append(f"{at}: a {type(member).__name__}, Webots' is a method")
            else:
                func = member.__func__ if isinstance(member, staticmethod) else member
                problems += _check_signature(at, func, _params(args.rstrip(")")), kind == "static")
        elif kind == "prop":
            name, _, mode = rest.partition(" ")
            member = _lookup(cls, name)
            at = f"{where}.{name}"
            if member is _MISSING:
                problems.append(f"{at}: missing (a property in Webots)")
            elif not isinstance(member, property):
                if mode or type(member).__name__ != "member_descriptor":    # a slot reads as Webots' getter does
                    problems.append(f"{at}: not a property ({type(member).__name__}), Webots' is")
            else:
                if mode in ("", "rw") and member.fget is None:
                    problems.append(f"{at}: cannot be read")
                if mode in ("rw", "w") and member.fset is None:
                    problems.append(f"{at}: cannot be set")
        elif kind == "const":
            name, _, value = rest.partition(" = ")
            member = _lookup(cls, name)
            at = f"{where}.{name}"
            if member is _MISSING:
                problems.append(f"{at}: missing")
            elif callable(member) or isinstance(member, property):
                problems.append(f"{at}: not a constant")
            elif value and member != ast.literal_eval(value):
                problems.append(f"{at} = {member!r}, Webots' is {value}")
        elif kind == "attr":
            if not _has_attr(cls, rest):
                problems.append(f"{where}.{rest}: missing (an attribute in Webots)")
        else:
            problems.append(f"python.txt: cannot read {line!r}")
    return problems


if __name__ == "__main__":
    sys.path.insert(0, str(WEBOTS_DIR))
    found = check()
    for line in found:
        print(line)
    sys.exit(1 if found else 0)
