"""A controller folder's ``runtime.ini``, as Webots reads it when it starts the controller: environment
variables for the controller's process, and the Python command to run it with. No I/O besides
:func:`read`: :func:`parse` turns the text into entries, :func:`environment` applies them to an
environment (``$(NAME)`` replaced by that variable's value at that point, earlier entries included).

The format (Webots' user guide, "Environment variables"): ``[section]`` lines, ``KEY = VALUE`` lines,
``;`` starting a comment (a ``;`` before the ``=`` makes the file invalid: Webots then reads none of
it); a value in double quotes keeps its semicolons. Sections applied here: ``environment variables
with paths`` (and its deprecated name ``... with relative paths``), ``environment variables``, and
the ones for this platform (``... for linux``, ``... for linux 64``; ``... for macos`` /
``... for mac os x``); ``python`` gives ``COMMAND`` and ``OPTIONS``. ``java`` and ``matlab`` are
for controllers Sensorium does not run.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

__all__ = ["FILE", "MAX_BYTES", "RuntimeIni", "RuntimeIniError", "environment", "parse", "read"]

FILE = "runtime.ini"
MAX_BYTES = 1 << 20          # a runtime.ini larger than this is refused (one line), not read
PATH_SECTIONS = ("environment variables with paths", "environment variables with relative paths")
_REFERENCE = re.compile(r"\$\(([^)]*)\)")


class RuntimeIniError(Exception):
    """A runtime.ini that is not read: one line naming the file and the line."""


@dataclass(frozen=True)
class RuntimeIni:
    """What a ``runtime.ini`` says: its ``(section, key, value)`` entries in file order (sections
    lower-cased), and the unknown keys of its ``python`` section (Webots warns about them)."""

    entries: tuple[tuple[str, str, str], ...] = ()

    def python(self, key: str) -> str | None:
        """The ``python`` section's ``COMMAND`` or ``OPTIONS`` (the last one given), else None."""
        found = None
        for section, k, value in self.entries:
            if section == "python" and k == key:
                found = value
        return found

    def notes(self) -> list[str]:
        """Lines Webots would say about this file (unknown ``python`` keys, the deprecated section)."""
        out = []
        for section, key, _ in self.entries:
            if section == "python" and key not in ("COMMAND", "OPTIONS"):
                out.append(f"unknown key {key} in its [python] section (COMMAND and OPTIONS are read)")
            if section == "environment variables with relative paths":
                out.append("[environment variables with relative paths] is deprecated: use [environment variables "
                           "with paths]")
        return list(dict.fromkeys(out))


def parse(text: str, where: str = FILE) -> RuntimeIni:
    """The entries of a runtime.ini's ``text``; RuntimeIniError for a ``;`` before a ``=``."""
    section = ""
    entries = []
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith(";"):
            continue
        if line.startswith("["):
            section = line.split(";", 1)[0].replace("[", "").replace("]", "").strip().lower()
            continue
        if "=" not in line:
            continue
        key, _, value = line.partition("=")
        if ";" in key:
            raise RuntimeIniError(f"{where}: line {number}: a ';' before the '=' ({line!r}): Webots reads none "
                                  "of this file then")
        value = value.strip()
        if value.startswith('"'):
            close = value.rfind('"')
            if close > 0:                # "a;b" keeps its ';', a comment after the closing quote goes
                value = value[1:close]
        else:
            value = value.split(";", 1)[0]
        entries.append((section, key.strip(), value.strip()))
    return RuntimeIni(tuple(entries))


def read(folder: Path) -> RuntimeIni | None:
    """``folder/runtime.ini`` parsed, or None when there is none; RuntimeIniError when it cannot be
    read or is not valid."""
    path = folder / FILE
    if not path.is_file():
        return None
    try:
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise RuntimeIniError(f"{path}: {size} bytes, more than the {MAX_BYTES} read: not read")
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise RuntimeIniError(f"{path}: cannot be read: {exc.strerror or exc}") from None
    return parse(text, str(path))


def _sections(platform: str) -> tuple[str, ...]:
    if platform.startswith("linux"):
        return ("environment variables for linux",
                "environment variables for linux 64" if sys.maxsize > 2**32 else "environment variables for linux 32")
    if platform == "darwin":
        return ("environment variables for mac os x", "environment variables for macos")
    if platform.startswith("win"):
        return ("environment variables for windows",)
    return ()


def _resolve(value: str, env: Mapping[str, str], path_like: bool) -> str:
    """``$(NAME)`` replaced by NAME's value (empty when unset); in a path section the empty entries
    that leaves (``a::b``, a leading or trailing ``:``) are dropped, as Webots does."""
    out = _REFERENCE.sub(lambda m: env.get(m.group(1), ""), value)
    if path_like and "$(" in value:
        out = ":".join(part for part in out.split(":") if part)
    return out


def environment(ini: RuntimeIni, env: Mapping[str, str], platform: str = sys.platform) -> dict[str, str]:
    """``env`` with ``ini``'s variables set for ``platform``, in file order."""
    out = dict(env)
    applied = ("environment variables", *PATH_SECTIONS, *_sections(platform))
    for section, key, value in ini.entries:
        if section in applied and key:
            out[key] = _resolve(value, out, section in PATH_SECTIONS)
    return out
