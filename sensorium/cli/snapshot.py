"""``sensorium snapshot WORLD OUT.png``: a world pictured from its Viewpoint on the CPU (the
library part is :mod:`sensorium.server.sim.viewshot`)."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from sensorium.cli.world import print_report, world_options
from sensorium.server.world.loader import WorldError, load_world


def snapshot(args: argparse.Namespace) -> int:
    from sensorium.server.sim import viewshot
    from sensorium.server.sim.simulation import Simulation

    out = Path(args.out)
    try:
        fmt = viewshot.image_format(args.out)
        width, height = viewshot.parse_size(args.size)
        if not 1 <= args.quality <= 100:
            raise ValueError(f"--quality must be in 1..100, got {args.quality}")
        if not 0 <= args.steps <= viewshot.MAX_STEPS:
            raise ValueError(f"--steps must be in 0..{viewshot.MAX_STEPS}, got {args.steps}")
    except ValueError as exc:
        print(f"snapshot: {exc}", file=sys.stderr)
        return 1
    try:
        if out.is_dir():
            raise IsADirectoryError(0, "is a directory; give the picture's file name")
        if out.exists() and not args.force:
            raise FileExistsError(0, "exists; not overwriting it (use --force)")
    except OSError as exc:       # also a name too long for the file system, a folder we may not see
        print(f"snapshot: {out}: {exc.strerror or exc}", file=sys.stderr)
        return 1
    try:
        loaded = load_world(args.world, **world_options(args))
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    print_report(loaded)
    try:
        sim = Simulation(loaded)
        if not viewshot.placed_viewpoint(sim):
            print(f"snapshot: {args.world}: no Viewpoint placed: Webots' default one, at (-10, 0, 0) looking along +x at "
                  "ground level, which may show little; list one in the world (README 'World files')", file=sys.stderr)
        rgb = viewshot.snapshot(sim, width, height, args.steps)
        data = viewshot.encode(rgb, fmt, args.quality)
    except ValueError as exc:
        print(f"snapshot: {args.world}: {exc}", file=sys.stderr)
        return 1
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    try:
        tmp.write_bytes(data)
        if out.exists() and not args.force:       # made meanwhile: still never overwritten unasked
            raise FileExistsError(0, "exists; not overwriting it (use --force)")
        os.replace(tmp, out)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        print(f"snapshot: {out}: cannot write: {exc.strerror or exc}", file=sys.stderr)
        return 1
    print(f"{out}: {width}x{height} {fmt} from the Viewpoint after {args.steps} step(s)")
    return 0
