"""``sensorium convert WORLD.wbt OUT.yaml``: a Webots world as an editable Sensorium world file."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from sensorium.server.world.loader import WorldError, bundled_or_path, load_world
from sensorium.server.world.wbt.emit import converted_world, dump_yaml


def convert(args: argparse.Namespace) -> int:
    src = bundled_or_path(args.world)          # a bundled name (epuck.wbt) works from any directory
    out = None if args.out == "-" else Path(args.out)
    if src.suffix.lower() != ".wbt":
        print(f"{src}: expected a Webots world (.wbt)", file=sys.stderr)
        return 2
    if out is not None:
        if out.suffix.lower() not in (".yaml", ".yml", ".json"):
            print(f"{out}: the output must end in .yaml, .yml or .json", file=sys.stderr)
            return 2
        if out.exists() and not args.force:
            print(f"{out}: exists; not overwriting it (use --force)", file=sys.stderr)
            return 1
    if not src.is_file():
        from sensorium import worlds

        print(f"{args.world}: no such file (nor a bundled world: {', '.join(worlds.names())})", file=sys.stderr)
        return 1
    try:
        loaded = load_world(src)   # every check a load makes, with problems at .wbt lines
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    data = converted_world(src, out.resolve().parent if out is not None else Path.cwd())
    if loaded.report:
        print(loaded.report.text(), file=sys.stderr)
    if out is not None and out.suffix.lower() == ".json":
        text = json.dumps(data, indent=2) + "\n"
    else:
        text = f"# Converted from {src.name} by `sensorium convert` (mesh and texture urls relative to this file).\n" + dump_yaml(data)
    if out is None:
        sys.stdout.write(text)
        return 0
    tmp = out.with_name(out.name + ".tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, out)
    except OSError as exc:
        tmp.unlink(missing_ok=True)    # (a directory named OUT, a full disk: no half-written file left behind)
        print(f"{out}: cannot write: {exc.strerror or exc}", file=sys.stderr)
        return 1
    print(f"{out}: written ({len(data.get('solids', []))} solids, {len(data.get('lights', []))} lights, "
          f"{len(data.get('robots', []))} robots)")
    outside = sorted({u for u in _mesh_urls(data) if Path(u).is_absolute() or u.startswith("..")})
    if outside:
        print(f"note: {len(outside)} mesh or texture url(s) leave {out.parent or '.'} (e.g. {outside[0]}): load the "
              "world with --allow-outside-meshes, or move the files next to it", file=sys.stderr)
    return 0


def _mesh_urls(data: object):
    """Every mesh and texture url of a world-file dict."""
    from sensorium.server.world.wbt.emit import TEXTURE_KEYS

    if isinstance(data, dict):
        if data.get("type") == "mesh" and isinstance(data.get("url"), str):
            yield data["url"]
        for k, v in data.items():
            if k in TEXTURE_KEYS and isinstance(v, dict) and isinstance(v.get("url"), str):
                yield v["url"]
            yield from _mesh_urls(v)
    elif isinstance(data, list):
        for v in data:
            yield from _mesh_urls(v)
