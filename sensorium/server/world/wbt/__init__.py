"""Webots worlds (``.wbt``): tokenizer and parser (``parser``), node-to-world conversion
(``convert``, ``fields``, ``drive``, ``protos``). ``load_wbt`` is what ``load_world`` calls for a
``.wbt`` file; ``wbt_to_dict`` gives the equivalent world file (``sensorium convert``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sensorium.server.world.wbt.parser import WbtSyntaxError, read_wbt

__all__ = ["WbtSyntaxError", "wbt_to_dict", "read_wbt"]


def wbt_to_dict(path: str | Path) -> tuple[dict[str, Any], list[str], dict[str, tuple[int, int, str]]]:
    """(world-file dict, warnings, converted path → (line, column, node type) it came from)."""
    from sensorium.server.world.wbt.convert import Converter, strip_origins

    source = str(path)
    conv = Converter(read_wbt(path), source)
    raw = conv.run()
    origin: dict[str, tuple[int, int, str]] = {}
    return strip_origins(raw, "", origin), conv.warnings, origin
