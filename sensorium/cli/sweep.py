"""``sensorium sweep SPEC``: a thin shell over :func:`sensorium.sweep.run_sweep`."""

from __future__ import annotations

import argparse
import json
import sys


def main(args: argparse.Namespace) -> int:
    from sensorium.sweep import SpecError, load_spec, run_sweep

    try:
        spec = load_spec(args.spec)
        if args.no_record:
            spec.record = False
        if args.workers is not None and args.workers < 1:
            raise SpecError(f"--workers must be >= 1, got {args.workers}")
        formats = args.format
        if not formats:
            try:
                import pyarrow  # noqa: F401
                formats = ["csv", "parquet"]
            except ImportError:
                formats = ["csv"]
        progress = sys.stderr.isatty() if args.progress is None else args.progress
        result = run_sweep(spec, args.out, engine=args.engine, workers=args.workers, address=args.address,
                           progress=progress, formats=formats, overwrite=args.overwrite)
    except SpecError as exc:
        print(f"sensorium sweep: {exc}", file=sys.stderr)
        return 2
    failed = result.failed
    summary = {"runs": len(result.rows), "failed": len(failed), "engine": result.engine, "workers": result.workers,
               "wall_s": round(result.wall_s, 3), "simulated_s": result.sim_time_s,
               "simulated_s_per_wall_s": round(result.sim_time_s / result.wall_s, 3) if result.wall_s > 0 else None,
               "tables": [str(p) for p in result.tables]}
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"{summary['runs']} runs ({summary['failed']} failed) on {result.engine} with {result.workers} workers "
              f"in {summary['wall_s']} s: {summary['simulated_s']:.1f} simulated s "
              f"({summary['simulated_s_per_wall_s']} simulated s per wall s)")
        for p in result.tables:
            print(f"table: {p}")
        for r in failed[:10]:
            print(f"run {r['run']} failed: {r['error']}", file=sys.stderr)
        if len(failed) > 10:
            print(f"... and {len(failed) - 10} more failed runs (see the table's error column)", file=sys.stderr)
    return 1 if failed else 0
