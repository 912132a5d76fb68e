"""``sensorium bench [--quick] [--out DIR] [--only SECTION]…``: the argparse shell over
:func:`sensorium.benchmarks.suite.run_suite` (run the sections, write the report)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from sensorium.benchmarks import SECTIONS


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quick", action="store_true", help="smoke run: fewer sizes and repeats (about 5 min on 2 cores)")
    p.add_argument("--out", default="docs", metavar="DIR",
                   help="where benchmarks.md, benchmarks.json and bench/*.png go (default: docs)")
    p.add_argument("--only", action="append", choices=SECTIONS, metavar="SECTION",
                   help=f"run only this section (repeatable; one of {', '.join(SECTIONS)}); the other sections "
                   "of an existing benchmarks.json in DIR are kept")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")


def _command(args: argparse.Namespace) -> str:
    parts = ["sensorium bench"]
    if args.quick:
        parts.append("--quick")
    parts.append(f"--out {args.out}")
    for s in args.only or []:
        parts.append(f"--only {s}")
    return " ".join(parts)


def main(args: argparse.Namespace) -> int:
    from sensorium.benchmarks.suite import run_suite
    from sensorium.cli.progress import bar

    progress = bar(len(args.only or SECTIONS), "bench", "section")   # a bar over the sections, on a terminal

    def log(line: str) -> None:
        write = getattr(progress, "write", None)          # tqdm keeps its bar below the lines
        if write is not None:
            write(line, file=sys.stderr)
        else:
            print(line, file=sys.stderr, flush=True)
        if line.endswith("…"):
            progress.set_postfix_str(line.split(": ", 1)[-1].rstrip(" …"))
        elif " done in " in line or line.rstrip().endswith("failed") or " failed: " in line:
            progress.update(1)

    try:
        result = run_suite(Path(args.out), args.only, quick=args.quick, plots=not args.no_plots,
                           command=_command(args), log=log)
    finally:
        progress.close()
    for w in result.written:
        print(w)
    sections = result.doc.get("sections", {})
    for name in SECTIONS:
        for t in sections.get(name, {}).get("targets", []):
            verdict = "PASS" if t["ok"] is True else ("MISS" if t["ok"] is False else "n/a")
            print(f"{verdict:4}  {t['name']}: {t['measured']} (goal {t['target']})")
    if result.failed:
        print(f"sensorium bench: failed sections: {', '.join(result.failed)}", file=sys.stderr)
        return 1
    return 0

if __name__ == "__main__":
    parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks")
    add_arguments(parser)
    sys.exit(main(parser.parse_args()))
