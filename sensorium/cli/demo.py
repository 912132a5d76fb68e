"""``sensorium demo``: a thin shell over :func:`sensorium.demo.run_demo` (see sensorium/demo/)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def main(args: argparse.Namespace) -> int:
    from sensorium.demo import DemoError, run_demo
    from sensorium.demo.summary import describe

    out = Path(args.out)
    try:
        result = run_demo(args.world, args.duration, out, precision=args.precision,
                          log=lambda text: print(text, file=sys.stderr, flush=True), progress=args.progress,
                          overwrite=getattr(args, "force", False))
    except DemoError as exc:
        print(f"sensorium demo: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print("\n".join(describe(result)))
        print(f"  picture: {result.picture or '(none)'}   logs: {out}/*.log   "
              f"replay: sensorium replay {result.recording}")
    bad = {k: v for k, v in result.exit_codes.items() if v != 0}
    if bad:
        print(f"sensorium demo: processes failed: {bad} (see {out}/*.log)", file=sys.stderr)
        return 1
    return 0
