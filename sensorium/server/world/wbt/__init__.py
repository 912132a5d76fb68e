"""Webots worlds (``.wbt``): tokenizer and parser (``parser``), PROTO expansion
(:mod:`sensorium.server.world.proto`), node-to-world conversion (``convert``, ``fields``, ``drive``,
``protos``: built-in stand-ins for common PROTOs; ``inside``: what a device's rays meet differently
here, said at load; ``mass``: a Solid's mass and centre of mass from its Physics node). ``load_wbt`` is what ``load_world`` calls for a
``.wbt`` file; ``wbt_to_dict`` gives the equivalent world file (``sensorium convert``)."""

from __future__ import annotations

import gc
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.wbt.parser import WbtSyntaxError, read_wbt

__all__ = ["WbtSyntaxError", "WbtConversion", "wbt_convert", "wbt_to_dict", "read_wbt"]


@dataclass
class WbtConversion:
    """A converted world: the world-file dict, warnings, converted path → (line, column, node type)
    it came from, the PROTOs used (``ProtoUse``: name, file, licence line, instances), the asset
    files outside the world's folder it may read (meshes of PROTOs, ``webots://`` assets) and the
    warnings that are losses sensors would notice (``losses``: robots, sensor devices, shapes;
    :mod:`sensorium.server.world.report`)."""

    data: dict[str, Any]
    warnings: list[str]
    origin: dict[str, tuple[int, int, str]]
    protos: list[Any]
    asset_files: frozenset[Path] = frozenset()
    losses: tuple[Any, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)   # wall seconds per stage (sensorium bench)


def wbt_convert(path: str | Path, *, webots_home: str | Path | None = None, proto_path: Sequence[str | Path] = (),
                limits: ProtoLimits | None = None) -> WbtConversion:
    """Read, expand (PROTOs found through ``webots_home``/``$WEBOTS_HOME`` and ``proto_path``) and
    convert a .wbt world."""
    with gc_paused():
        return _convert(path, webots_home, proto_path, limits)


@contextmanager
def gc_paused() -> Iterator[None]:
    """Python's cycle collector off while a world is read and converted: a big inline mesh is
    hundreds of thousands of small lists and tuples, none in a cycle, and every collection would
    scan them all again (half the load time of a robot of 30 mesh parts). Cycles made meanwhile
    are collected once it is back on."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def _convert(path: str | Path, webots_home: str | Path | None, proto_path: Sequence[str | Path],
             limits: ProtoLimits | None) -> WbtConversion:
    from sensorium.server.world.proto import ProtoSearch, expand
    from sensorium.server.world.wbt.convert import Converter, strip_origins

    source = str(path)
    limits = limits or ProtoLimits()
    t0 = time.perf_counter()
    search = ProtoSearch.create(Path(path).resolve().parent, webots_home, tuple(proto_path))
    wbt = read_wbt(path, limits)
    t1 = time.perf_counter()
    expansion = expand(wbt, search, limits)
    t2 = time.perf_counter()
    conv = Converter(expansion.as_wbt(), source, expansion.search, max_grid_points=limits.values)
    raw = conv.run()
    origin: dict[str, tuple[int, int, str]] = {}
    data = strip_origins(raw, "", origin)
    t3 = time.perf_counter()
    files, template = expansion.timings.get("proto files", 0.0), expansion.timings.get("template", 0.0)
    timings = {"parse": t1 - t0, "proto files": files, "instantiate": t2 - t1 - files - template,
               "template": template, "convert": t3 - t2}
    return WbtConversion(data, [*expansion.warnings, *conv.warnings], origin, expansion.protos,
                         frozenset(conv.asset_files), tuple(conv.losses), timings)


def wbt_to_dict(path: str | Path, *, webots_home: str | Path | None = None, proto_path: Sequence[str | Path] = (),
                limits: ProtoLimits | None = None) -> tuple[dict[str, Any], list[str], dict[str, tuple[int, int, str]]]:
    """(world-file dict, warnings, converted path → (line, column, node type) it came from)."""
    c = wbt_convert(path, webots_home=webots_home, proto_path=proto_path, limits=limits)
    return c.data, c.warnings, c.origin
