"""The converted world as a file: mesh urls made relative to where it is written, compact YAML."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import yaml

from sensorium.server.world.wbt import wbt_to_dict


class _Dumper(yaml.SafeDumper):
    """Lists of numbers on one line (poses, sizes, colours); everything else in block style."""


def _list(dumper: yaml.SafeDumper, data: list) -> yaml.Node:
    flow = all(isinstance(v, int | float) and not isinstance(v, bool) for v in data) or (
        all(isinstance(v, list) for v in data) and all(isinstance(x, int | float) for v in data for x in v))
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow and bool(data))


_Dumper.add_representer(list, _list)


def dump_yaml(data: Any) -> str:
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, width=120)


def _rebase(data: Any, src_dir: Path, out_dir: Path) -> Any:
    if isinstance(data, dict):
        if data.get("type") == "mesh" and isinstance(data.get("url"), str):
            target = (src_dir / data["url"]).resolve()
            return {**data, "url": Path(os.path.relpath(target, out_dir)).as_posix()}
        return {k: _rebase(v, src_dir, out_dir) for k, v in data.items()}
    if isinstance(data, list):
        return [_rebase(v, src_dir, out_dir) for v in data]
    return data


def converted_world(src: str | Path, out_dir: Path) -> dict:
    """The world-file dict of a .wbt file, mesh urls relative to ``out_dir``."""
    data, _, _ = wbt_to_dict(src)
    return _rebase(data, Path(src).resolve().parent, out_dir.resolve())
