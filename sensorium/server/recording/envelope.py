"""The recording format's constants, the topic envelope, and ``--topics`` matching.

Shared by the writer (:mod:`.writer`), the reader (:mod:`.reader`), replay and the live recorder.
The on-disk layout is described in :mod:`.writer`.
"""

from __future__ import annotations

import difflib
import fnmatch
from collections.abc import Callable, Iterable
from pathlib import Path

import msgpack

PROFILE = "x-sensorium"
MESSAGE_ENCODING = "msgpack"
MAGIC = b"\x89MCAP0\r\n"
SEQ_MODULUS = 1 << 32
DEFAULT_CHUNK_SIZE = 1 << 20


def library_version() -> str:
    """The installed sensorium version (written into every recording)."""
    try:
        from sensorium import __version__

        return __version__
    except Exception:  # pragma: no cover - the package is always importable when installed
        return "unknown"


def pack_envelope(ros_type: str, seq: int, stamp_ns: int) -> bytes:
    """The topic envelope of PROTOCOL.md §4: msgpack ``{"type", "seq", "stamp_ns"}`` in that order."""
    return msgpack.packb({"type": ros_type, "seq": seq, "stamp_ns": stamp_ns})


# --------------------------------------------------------------------------------------------
# topic filters


def topic_matcher(patterns: Iterable[str] | None) -> Callable[[str], bool]:
    """A predicate for ``--topics`` lists. ``None``/empty matches every topic. A pattern matches a
    topic when it is the topic itself, a path prefix of it (``/epuck`` and ``/epuck/`` match
    ``/epuck/ps0/value`` but ``/epuck/ps1`` does not match ``/epuck/ps10/value``), or, when it
    contains ``*``, ``?`` or ``[``, a shell-style glob over the whole topic (``/epuck/ps*``)."""
    pats = [p for p in (patterns or []) if p]
    if not pats:
        return lambda topic: True
    exact: set[str] = set()
    prefixes: list[str] = []
    globs: list[str] = []
    for p in pats:
        if any(c in p for c in "*?["):
            globs.append(p)
        else:
            exact.add(p.rstrip("/") or "/")
            prefixes.append(p if p.endswith("/") else p + "/")
    cache: dict[str, bool] = {}

    def match(topic: str) -> bool:
        hit = cache.get(topic)
        if hit is None:
            hit = (topic in exact or any(topic.startswith(p) for p in prefixes)
                   or any(fnmatch.fnmatchcase(topic, g) for g in globs))
            if len(cache) < 65536:
                cache[topic] = hit
        return hit

    return match


def unmatched_topics(patterns: Iterable[str] | None, topics: Iterable[str], where: str) -> str | None:
    """One line naming the first ``--topics`` pattern that matches none of ``topics`` (those of
    ``where``: a recording, a world, a server), with the closest names; None when every pattern matches some topic: a typo in ``--topics`` would
    otherwise give an empty recording, replay or export without a word."""
    names = sorted(set(topics))
    for pattern in patterns or []:
        if not pattern:
            continue
        match = topic_matcher([pattern])
        if any(match(t) for t in names):
            continue
        near = difflib.get_close_matches(pattern, names, n=3, cutoff=0.5)
        hint = (f"closest: {', '.join(near)}" if near else
                f"topics: {', '.join(names[:6])}{' ...' if len(names) > 6 else ''}" if names else "there are none")
        return f"--topics {pattern}: no topic of {where} matches it ({hint})"
    return None




def media_type(name: str) -> str:
    """The attachment media type of a world or mesh file, by suffix."""
    suffix = Path(name).suffix.lower()
    return {".yaml": "application/yaml", ".yml": "application/yaml", ".json": "application/json",
            ".wbt": "text/plain"}.get(suffix, "application/octet-stream")

