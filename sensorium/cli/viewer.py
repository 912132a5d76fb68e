"""``sensorium layout``: write a Foxglove layout for a recording or a world file (thin shell over
:mod:`sensorium.server.viewer.layout`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["layout_cmd"]


def layout_cmd(args: argparse.Namespace) -> int:
    from sensorium.server.world.loader import WorldError, bundled_or_path, default_world_path

    source = bundled_or_path(args.source) if args.source else default_world_path()
    if not source.is_file():
        from sensorium import worlds

        print(f"sensorium layout: {source}: no such file (nor a bundled world: {', '.join(worlds.names())})",
              file=sys.stderr)
        return 1
    out = Path(args.out) if args.out else None
    if out is not None and out.exists() and not args.force:
        print(f"sensorium layout: {out} exists already; not overwriting (--force to replace it)", file=sys.stderr)
        return 1
    try:
        from sensorium.server.viewer.layout import layout_for

        text = layout_for(source)
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    except ImportError as exc:
        print(f"sensorium layout: needs foxglove-sdk ({exc.name} is missing): pip install 'sensorium[foxglove]'",
              file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - an unreadable recording: one line, no traceback
        print(f"sensorium layout: {source}: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    if out is None:
        print(text)
    else:
        try:
            out.write_text(text + "\n")
        except OSError as exc:      # a missing folder, a directory, no permission: one line, no traceback
            print(f"sensorium layout: cannot write {out}: {exc.strerror or exc}", file=sys.stderr)
            return 1
        print(f"sensorium: wrote {out} (Foxglove: Layouts, Import from file)", file=sys.stderr)
    return 0
