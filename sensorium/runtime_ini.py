"""A controller folder's ``runtime.ini``, as Webots reads it when it starts the controller: environment
variables for the controller's process, and the Python command to run it with. No I/O besides
:func:`read`: :func:`parse` turns the text into entries, :func:`environment` applies them to an
environment (``$(NAME)`` replaced by that variable's value at that point, earlier entries included).

The format (Webots' user guide, "Environment variables"): ``[section]`` lines, ``KEY = VALUE`` lines,
``;`` starting a comment (a ``;`` before the ``=`` makes the file invalid: Webots then reads none of
it); a value in double quotes keeps its semicolons. Lines end at ``\n`` (a ``\r`` before it is
trimmed with the spaces), a line's text ends at its first NUL byte and a UTF-8 byte-order mark at
its start is skipped, as Webots' Qt reads the file line by line; bytes that are not UTF-8 read as U+FFFD. Sections applied here: ``environment variables
with paths`` (and its deprecated name ``... with relative paths``), ``environment variables``, and
the ones for this platform (``... for linux``, ``... for linux 64``; ``... for macos`` /
``... for mac os x``); ``python`` gives ``COMMAND`` and ``OPTIONS`` (split at its spaces, as Webots
splits it). ``java`` and ``matlab`` are
for controllers Sensorium does not run.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

__all__ = ["FILE", "MAX_BYTES", "MAX_SET", "RuntimeIni", "RuntimeIniError", "environment", "parse", "read"]

FILE = "runtime.ini"
MAX_BYTES = 1 << 20          # a runtime.ini larger than this is refused (one line), not read
# the characters a runtime.ini's values may set together once their $(NAME) references are replaced: twice
# Linux's default limit for a program's arguments and environment together (no controller could start with more),
# so a file of references to references (A = $(A)$(A), again and again) cannot fill the memory
MAX_SET = 1 << 22
NOTES_MAX = 8                # unknown [python] keys named, at most (then one line counts the others)
PATH_SECTIONS = ("environment variables with paths", "environment variables with relative paths")
_REFERENCE = re.compile(r"\$\(([^)]*)\)")
# what Qt's trimmed() takes off a line, a key and a value: Python's whitespace less \x1c-\x1f (Qt keeps those)
_SPACE = "".join(c for c in map(chr, range(0x3001)) if c.isspace() and c not in "\x1c\x1d\x1e\x1f")


class RuntimeIniError(Exception):
    """A runtime.ini that is not read: one line naming the file and the line."""


@dataclass(frozen=True)
class RuntimeIni:
    """What a ``runtime.ini`` says: its ``(section, key, value)`` entries in file order (sections
    lower-cased), and the unknown keys of its ``python`` section (Webots warns about them)."""

    entries: tuple[tuple[str, str, str], ...] = ()
    where: str = FILE                       # the file, for the lines said about it
    lines: tuple[int, ...] = ()             # each entry's line number in it

    def python(self, key: str, env: Mapping[str, str] | None = None, platform: str = sys.platform) -> str | None:
        """The ``python`` section's ``COMMAND`` or ``OPTIONS`` (the last one given), else None. With
        ``env``, its ``$(NAME)`` references replaced as Webots replaces every entry's: against ``env``
        with the file's entries before it applied for ``platform`` (RuntimeIniError when too long)."""
        found = None
        for i, (section, k, _) in enumerate(self.entries):
            if section == "python" and k == key:
                found = i
        if found is None:
            return None
        value = self.entries[found][2]
        if env is None or "$(" not in value:
            return value
        before = environment(RuntimeIni(self.entries[:found], self.where, self.lines[:found]), env, platform)
        resolved = _resolve(value, before, False, MAX_SET)
        if resolved is None:
            line = f"line {self.lines[found]}: " if found < len(self.lines) else ""
            raise RuntimeIniError(f"{self.where}: {line}[python] {key} with its $(...) references replaced is longer "
                                  f"than the {MAX_SET} characters set at most")
        return resolved

    def python_options(self, env: Mapping[str, str] | None = None) -> list[str]:
        """The ``python`` section's ``OPTIONS`` (``$(NAME)`` replaced against ``env`` as :meth:`python`
        replaces it) as the arguments Webots makes of it (WbController splits the value at each space,
        with no quoting: a tab stays inside its argument, and quotes inside the value stay in theirs),
        less the empty ones two spaces in a row would make (Webots passes each as an empty argument,
        which Python then takes for the script to run)."""
        return [part for part in (self.python("OPTIONS", env) or "").split(" ") if part]

    def notes(self) -> list[str]:
        """Lines Webots would say about this file (unknown ``python`` keys, the deprecated section):
        at most :data:`NOTES_MAX` unknown keys by name, then one line counting the others."""
        unknown = list(dict.fromkeys(key for section, key, _ in self.entries
                                     if section == "python" and key not in ("COMMAND", "OPTIONS")))
        out = [f"unknown key {key if key.isprintable() and len(key) <= 80 else repr(key[:80])} in its [python] "
               "section (COMMAND and OPTIONS are read)"
               for key in unknown[:NOTES_MAX]]
        if len(unknown) > NOTES_MAX:
            out.append(f"{len(unknown) - NOTES_MAX} more unknown keys in its [python] section")
        if any(section == "environment variables with relative paths" for section, _, _ in self.entries):
            out.append("[environment variables with relative paths] is deprecated: use [environment variables "
                       "with paths]")
        return out


def parse(text: str, where: str = FILE) -> RuntimeIni:
    """The entries of a runtime.ini's ``text``; RuntimeIniError for a ``;`` before a ``=``."""
    section = ""
    entries = []
    numbers = []
    for number, raw in enumerate(text.split("\n"), 1):
        line = raw.split("\0", 1)[0]
        line = (line[1:] if line.startswith("\ufeff") else line).strip(_SPACE)
        if not line or line.startswith(";"):
            continue
        if line.startswith("["):
            section = line.split(";", 1)[0].replace("[", "").replace("]", "").strip(_SPACE).lower()
            continue
        if "=" not in line:
            continue
        key, _, value = line.partition("=")
        if ";" in key:
            shown = line if len(line) <= 80 else line[:80] + "…"
            raise RuntimeIniError(f"{where}: line {number}: a ';' before the '=' ({shown!r}): Webots reads none "
                                  "of this file then")
        entries.append((section, key.strip(_SPACE), _value(value.strip(_SPACE))))
        numbers.append(number)
    return RuntimeIni(tuple(entries), where, tuple(numbers))


def _value(value: str) -> str:
    """A value as Webots reads it: unquoted, it ends at a ``;``; in double quotes it keeps its ``;``
    (a ``;`` after the closing quote starts a comment); a quote never closed is kept as written."""
    if not value.startswith('"'):
        return value.split(";", 1)[0].strip(_SPACE)
    close = value.rfind('"')
    if close == 0:
        return value
    comment = value.rfind(";")
    if comment > close:          # "a;b" ; note: the text before the comment, less its closing quote
        return value[1:comment].strip(_SPACE)[:-1].strip(_SPACE)
    return value[1:close].strip(_SPACE)


def read(folder: Path) -> RuntimeIni | None:
    """``folder/runtime.ini`` parsed, or None when there is none; RuntimeIniError when it cannot be
    read or is not valid."""
    path = folder / FILE
    if not path.is_file():
        return None
    try:
        with open(path, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            data = f.read(MAX_BYTES + 1)          # no more, whatever its size said or has become
    except OSError as exc:
        raise RuntimeIniError(f"{path}: cannot be read: {exc.strerror or exc}") from None
    if len(data) > MAX_BYTES:
        raise RuntimeIniError(f"{path}: {max(size, len(data))} bytes, more than the {MAX_BYTES} read: not read")
    return parse(data.decode("utf-8", errors="replace"), str(path))


def _sections(platform: str) -> tuple[str, ...]:
    if platform.startswith("linux"):
        return ("environment variables for linux",
                "environment variables for linux 64" if sys.maxsize > 2**32 else "environment variables for linux 32")
    if platform == "darwin":
        return ("environment variables for mac os x", "environment variables for macos")
    if platform.startswith("win"):
        return ("environment variables for windows",)
    return ()


def _resolve(value: str, env: Mapping[str, str], path_like: bool, budget: int) -> str | None:
    """``$(NAME)`` replaced by NAME's value (empty when unset; text a variable brings in is not
    replaced again); in a path section the empty entries that leaves (``a::b``, a leading or
    trailing ``:``) are dropped, as Webots does. None when the result would be longer than
    ``budget`` characters (nothing that long is built)."""
    parts, size, at = [], 0, 0
    for m in _REFERENCE.finditer(value):
        for piece in (value[at:m.start()], env.get(m.group(1), "")):
            size += len(piece)
            if size > budget:
                return None
            parts.append(piece)
        at = m.end()
    size += len(value) - at
    if size > budget:
        return None
    out = "".join(parts) + value[at:]
    if path_like and "$(" in value:
        out = ":".join(part for part in out.split(":") if part)
    return out


def environment(ini: RuntimeIni, env: Mapping[str, str], platform: str = sys.platform) -> dict[str, str]:
    """``env`` with ``ini``'s variables set for ``platform``, in file order. RuntimeIniError (naming
    the file and the line) when the values it sets would together be longer than :data:`MAX_SET`
    characters."""
    out = dict(env)
    applied = ("environment variables", *PATH_SECTIONS, *_sections(platform))
    sizes: dict[str, int] = {}        # the values the file has set, as they are now, and their total
    total = 0
    for i, (section, key, value) in enumerate(ini.entries):
        if section in applied and key:
            budget = MAX_SET - (total - sizes.get(key, 0))
            resolved = _resolve(value, out, section in PATH_SECTIONS, budget)
            if resolved is None:
                line = f"line {ini.lines[i]}: " if i < len(ini.lines) else ""
                raise RuntimeIniError(f"{ini.where}: {line}{key}'s value with its $(...) references replaced makes "
                                      f"the file's values longer than the {MAX_SET} characters set at most")
            total += len(resolved) - sizes.get(key, 0)
            sizes[key] = len(resolved)
            out[key] = resolved
    return out
