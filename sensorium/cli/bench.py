"""``sensorium bench [--quick] [--out DIR] [--only SECTION]…``: run the sections, write the report."""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib
import sys
import time
import traceback
from pathlib import Path

from sensorium.benchmarks import SECTIONS


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quick", action="store_true", help="smoke run (~30 s): fewer sizes and repeats")
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
    from sensorium.benchmarks import report
    from sensorium.benchmarks.common import Config, machine

    out = Path(args.out)
    only = list(dict.fromkeys(args.only or SECTIONS))
    cfg = Config(quick=args.quick, log=lambda line: print(line, file=sys.stderr, flush=True))
    now = lambda: _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")  # noqa: E731
    doc = report.load(out) if args.only else {}
    doc.update({"schema": report.SCHEMA, "generated": now(), "machine": machine(), "quick": args.quick})
    if not args.only:
        doc["command"] = _command(args)
    else:
        doc.setdefault("command", "sensorium bench --out " + str(args.out))
    sections = doc.setdefault("sections", {})
    for s in sections.values():
        s.pop("_fresh", None)
    failed = []
    t_all = time.perf_counter()
    for name in only:
        cfg.log(f"sensorium bench: {name} …")
        t0 = time.perf_counter()
        try:
            sec = importlib.import_module(f"sensorium.benchmarks.{name}").run(cfg)
        except Exception as exc:  # noqa: BLE001 - one broken section must not lose the others
            failed.append(name)
            cfg.log(f"sensorium bench: {name} failed: {type(exc).__name__}: {exc}\n{traceback.format_exc()}")
            continue
        sec.elapsed_s = time.perf_counter() - t0
        js = sec.to_json()
        js.update({"measured_at": now(), "quick": args.quick, "command": _command(args), "_fresh": True})
        sections[name] = js
        cfg.log(f"sensorium bench: {name} done in {sec.elapsed_s:.0f} s")
    if not args.only:
        doc["elapsed_s"] = time.perf_counter() - t_all
    written = report.write(out, doc, plots=not args.no_plots, log=cfg.log)
    for s in sections.values():
        s.pop("_fresh", None)
    # rewrite the JSON without the run-local flag
    report.write(out, doc, plots=False, log=cfg.log)
    for w in written:
        print(w)
    for name in SECTIONS:
        for t in sections.get(name, {}).get("targets", []):
            verdict = "PASS" if t["ok"] is True else ("MISS" if t["ok"] is False else "n/a")
            print(f"{verdict:4}  {t['name']}: {t['measured']} (goal {t['target']})")
    if failed:
        print(f"sensorium bench: failed sections: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks")
    add_arguments(parser)
    sys.exit(main(parser.parse_args()))
