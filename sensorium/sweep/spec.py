"""Sweep specifications: the cross product of worlds x parameters x controllers x seeds.

A spec is a YAML or JSON mapping (``sensorium sweep SPEC``) or the same dict in Python::

    worlds: [arena.yaml, ../other.yaml]    # relative to the spec file; "default" = the embedded arena
    seeds: [1, 2, 3]                       # or {start: 0, count: 100}
    duration_ms: 2000                      # simulated time per run (rounded up to whole basic steps)
    parameters:                            # any world-file field by path; every combination is run
      robots[0].devices[0].lookup_table[1][2]: [0.0, 0.05]
      robots[epuck].pose.translation: [[-1.2, -0.3, 0.01], [0.0, 0.0, 0.01]]
    controllers: [idle, circle, controllers/mine.py:make]   # see sensorium.sweep.controllers
    record: true                           # or false, or {topics: [/epuck/, /clock]}

A path is dot-separated keys and ``[i]`` list indices; ``[name]`` selects the list item whose
``name`` is ``name``. Setting a field replaces it in the world file's data before validation, so a
bad value is reported exactly like the same mistake in the file (as that run's error).
"""

from __future__ import annotations

import itertools
import json
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

__all__ = ["SpecError", "SweepSpec", "RunSpec", "load_spec", "parse_spec", "set_path", "parse_path"]


class SpecError(ValueError):
    """A sweep spec that cannot be run (the message names the file and field)."""


@dataclass(frozen=True)
class RunSpec:
    """One simulation of a sweep: everything a worker needs (picklable)."""

    index: int
    world: str                                   # path, or "default"
    seed: int
    parameters: tuple[tuple[str, Any], ...]
    controller: str | Callable                   # name / reference, or a callable (Python API)
    duration_ms: int
    recording: str | None                        # output .mcap path, None = no recording
    topics: tuple[str, ...] | None = None

    @property
    def controller_name(self) -> str:
        c = self.controller
        return c if isinstance(c, str) else getattr(c, "__qualname__", repr(c))


@dataclass
class SweepSpec:
    worlds: list[str]
    seeds: list[int]
    duration_ms: int
    parameters: dict[str, list[Any]] = field(default_factory=dict)
    controllers: list[str | Callable] = field(default_factory=lambda: ["idle"])
    record: bool = True
    topics: list[str] | None = None
    source: str = "<spec>"

    def runs(self, output: str | Path | None) -> list[RunSpec]:
        """Every run, in a fixed order (world, parameters, controller, seed); recordings go to
        ``output/runs/NNNN.mcap`` (no recording without ``output`` or with ``record: false``)."""
        keys = list(self.parameters)
        combos = list(itertools.product(*(self.parameters[k] for k in keys))) if keys else [()]
        out: list[RunSpec] = []
        for world in self.worlds:
            for combo in combos:
                for ctrl in self.controllers:
                    for seed in self.seeds:
                        i = len(out)
                        rec = str(Path(output) / "runs" / f"{i:04d}.mcap") if (output is not None and self.record) else None
                        out.append(RunSpec(i, world, seed, tuple(zip(keys, combo)), ctrl, self.duration_ms, rec,
                                           tuple(self.topics) if self.topics else None))
        return out


MAX_RUNS = 100_000
"""The most runs a sweep may hold (its cross product): a stray digit in a seed count or a value list
is refused in one line, not listed into memory and started."""

_KEYS = {"worlds", "seeds", "duration_ms", "parameters", "controllers", "record"}


def load_spec(path: str | Path) -> SweepSpec:
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise SpecError(f"{p}: cannot read sweep spec: {exc.strerror or exc}") from None
    try:
        data = json.loads(text) if p.suffix.lower() == ".json" else yaml.safe_load(text)
    except (yaml.YAMLError, json.JSONDecodeError) as exc:
        raise SpecError(f"{p}: not valid YAML/JSON: {str(exc).splitlines()[0]}") from None
    return parse_spec(data, source=str(p), base_dir=p.resolve().parent)


def _resolve(world: str, base_dir: Path | None) -> str:
    if world == "default" or base_dir is None or Path(world).is_absolute():
        return world
    return str((base_dir / world).resolve())


def _resolve_controller(c: Any, base_dir: Path | None) -> Any:
    if not isinstance(c, str) or base_dir is None:
        return c
    file, sep, fn = c.partition(".py")
    if not sep:
        return c
    p = Path(file + ".py")
    return str((base_dir / p).resolve() if not p.is_absolute() else p) + fn


def parse_spec(data: Any, source: str = "<spec>", base_dir: Path | None = None) -> SweepSpec:
    """Validate a spec mapping; relative world and controller files are taken from ``base_dir``."""
    if not isinstance(data, Mapping):
        raise SpecError(f"{source}: a sweep spec must be a mapping, got {type(data).__name__}")
    unknown = set(data) - _KEYS
    if unknown:
        raise SpecError(f"{source}: unknown key(s) {', '.join(sorted(map(str, unknown)))} "
                        f"(known: {', '.join(sorted(_KEYS))})")
    worlds = data.get("worlds", ["default"])
    if isinstance(worlds, str):
        worlds = [worlds]
    if not isinstance(worlds, list) or not worlds or not all(isinstance(w, str) and w for w in worlds):
        raise SpecError(f"{source}: worlds: a non-empty list of world file paths (or 'default')")
    seeds = data.get("seeds", [0])
    if isinstance(seeds, Mapping):
        if set(seeds) - {"start", "count"} or not isinstance(seeds.get("count"), int) or seeds["count"] < 1:
            raise SpecError(f"{source}: seeds: a list of integers or {{start: S, count: N}} with N >= 1")
        start = seeds.get("start", 0)
        if not isinstance(start, int) or isinstance(start, bool):
            raise SpecError(f"{source}: seeds.start must be an integer")
        if seeds["count"] > MAX_RUNS:
            raise SpecError(f"{source}: seeds.count: at most {MAX_RUNS} runs in a sweep, got {seeds['count']}")
        seeds = list(range(start, start + seeds["count"]))
    if isinstance(seeds, int) and not isinstance(seeds, bool):
        seeds = [seeds]
    if (not isinstance(seeds, list) or not seeds
            or not all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < 2**63 for s in seeds)):
        raise SpecError(f"{source}: seeds: a non-empty list of integers in [0, 2^63)")
    duration = data.get("duration_ms", 1000)
    if not isinstance(duration, int) or isinstance(duration, bool) or not 0 < duration <= 86_400_000:
        raise SpecError(f"{source}: duration_ms: an integer number of milliseconds in (0, 86400000], got {duration!r}")
    params = data.get("parameters") or {}
    if not isinstance(params, Mapping):
        raise SpecError(f"{source}: parameters: a mapping of world-file field path -> list of values")
    for k, v in params.items():
        try:
            parse_path(str(k))
        except SpecError as exc:
            raise SpecError(f"{source}: parameters: {exc}") from None
        if not isinstance(v, list) or not v:
            raise SpecError(f"{source}: parameters.{k}: a non-empty list of values, got {v!r}")
    controllers = data.get("controllers", ["idle"])
    if isinstance(controllers, str) or callable(controllers):
        controllers = [controllers]
    if not isinstance(controllers, list) or not controllers or not all(isinstance(c, str) or callable(c) for c in controllers):
        raise SpecError(f"{source}: controllers: a non-empty list of names, 'module:function' or 'file.py[:function]'")
    record = data.get("record", True)
    topics = None
    if isinstance(record, Mapping):
        if set(record) - {"topics"}:
            raise SpecError(f"{source}: record: true, false or {{topics: [...]}}")
        topics = record.get("topics")
        if topics is not None and (not isinstance(topics, list) or not all(isinstance(t, str) for t in topics)):
            raise SpecError(f"{source}: record.topics: a list of topic names or prefixes")
        record = True
    if not isinstance(record, bool):
        raise SpecError(f"{source}: record: true, false or {{topics: [...]}}, got {record!r}")
    runs = len(worlds) * math.prod(len(v) for v in params.values()) * len(controllers) * len(seeds)
    if runs > MAX_RUNS:
        raise SpecError(f"{source}: {runs} runs (worlds x parameter values x controllers x seeds); a sweep holds "
                        f"at most {MAX_RUNS}")
    return SweepSpec(worlds=[_resolve(w, base_dir) for w in worlds], seeds=list(seeds), duration_ms=duration,
                     parameters={str(k): list(v) for k, v in params.items()},
                     controllers=[_resolve_controller(c, base_dir) for c in controllers],
                     record=record, topics=topics, source=source)


# ------------------------------------------------------------------------------ field paths

_TOKEN = re.compile(r"\s*(?:\.?([A-Za-z_][A-Za-z0-9_]*)|\[\s*(-?\d+)\s*\]|\[\s*([^\]]+?)\s*\])")


def parse_path(path: str) -> list[str | int | tuple[str]]:
    """``robots[0].devices[ps0].noise`` -> ['robots', 0, 'devices', ('ps0',), 'noise']: keys, list
    indices, and ``(name,)`` for "the item named name"."""
    out: list[str | int | tuple[str]] = []
    pos = 0
    while pos < len(path):
        m = _TOKEN.match(path, pos)
        if not m or m.end() == pos or (m.group(1) and out == [] and path[pos] == "."):
            raise SpecError(f"bad field path {path!r} at character {pos + 1}")
        if m.group(1):
            out.append(m.group(1))
        elif m.group(2) is not None:
            out.append(int(m.group(2)))
        else:
            out.append((m.group(3).strip("'\""),))
        pos = m.end()
    if not out or not isinstance(out[0], str):
        raise SpecError(f"bad field path {path!r}: it must start with a world-file key")
    return out


def set_path(data: dict, path: str, value: Any) -> None:
    """Set the field at ``path`` in world-file data (dicts and lists, modified in place). A missing
    last key is created (a field left at its default); anything else missing is an error."""
    steps = parse_path(path)
    node: Any = data
    for i, step in enumerate(steps):
        last = i == len(steps) - 1
        where = f"field {path!r}"
        if isinstance(step, str):
            if not isinstance(node, dict):
                raise SpecError(f"{where}: {step!r} applies to a mapping, found {type(node).__name__}")
            if last:
                node[step] = value
                return
            if step not in node:
                raise SpecError(f"{where}: no {step!r} in the world file")
            node = node[step]
        else:
            if not isinstance(node, list):
                raise SpecError(f"{where}: {step!r} applies to a list, found {type(node).__name__}")
            if isinstance(step, tuple):
                idx = [j for j, item in enumerate(node) if isinstance(item, dict) and item.get("name") == step[0]]
                if not idx:
                    raise SpecError(f"{where}: no item named {step[0]!r}")
                j = idx[0]
            else:
                if not -len(node) <= step < len(node):
                    raise SpecError(f"{where}: index {step} outside a list of {len(node)}")
                j = step
            if last:
                node[j] = value
                return
            node = node[j]
