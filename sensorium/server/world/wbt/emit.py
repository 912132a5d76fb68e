"""The converted world as a file: mesh and texture urls made relative to where it is written, compact YAML."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
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


TEXTURE_KEYS = ("texture", "roughness_map", "occlusion_map", "emissive_map")     # an appearance's image files


def _rebase(data: Any, src_dir: Path, out_dir: Path) -> Any:
    if isinstance(data, dict):
        if data.get("type") == "mesh" and isinstance(data.get("url"), str):
            return {**data, "url": _relative(data["url"], src_dir, out_dir)}
        if data.get("device") == "Camera" and isinstance(data.get("noise_mask_url"), str):    # an image file too
            data = {**data, "noise_mask_url": _relative(data["noise_mask_url"], src_dir, out_dir)}
        return {k: _rebase_texture(v, src_dir, out_dir) if k in TEXTURE_KEYS else _rebase(v, src_dir, out_dir)
                for k, v in data.items()}
    if isinstance(data, list):
        return [_rebase(v, src_dir, out_dir) for v in data]
    if isinstance(data, np.ndarray):        # an IndexedFaceSet's points or faces: written as numbers
        return data.tolist()
    return data


def _relative(url: str, src_dir: Path, out_dir: Path) -> str:
    return Path(os.path.relpath((src_dir / url).resolve(), out_dir)).as_posix()


def _rebase_texture(texture: Any, src_dir: Path, out_dir: Path) -> Any:
    if isinstance(texture, dict) and isinstance(texture.get("url"), str) and "://" not in texture["url"]:
        return {**texture, "url": _relative(texture["url"], src_dir, out_dir)}
    return texture


def converted_world(src: str | Path, out_dir: Path) -> dict:
    """The world-file dict of a .wbt file, mesh and texture urls relative to ``out_dir``."""
    data, _, _ = wbt_to_dict(src)
    return _rebase(data, Path(src).resolve().parent, out_dir.resolve())
