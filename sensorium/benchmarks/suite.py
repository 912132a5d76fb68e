"""Run benchmark sections and write the report (``sensorium bench`` is the argparse shell over this)."""

from __future__ import annotations

import datetime as _dt
import importlib
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from sensorium.benchmarks import SECTIONS

__all__ = ["SuiteResult", "run_suite"]


@dataclass
class SuiteResult:
    doc: dict                                        # what benchmarks.json holds
    written: list = field(default_factory=list)      # files written
    failed: list[str] = field(default_factory=list)  # sections that raised


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def run_suite(out: Path, only: Sequence[str] | None, *, quick: bool, plots: bool, command: str,
              log: Callable[[str], None]) -> SuiteResult:
    """Run ``only`` (default: every section) and write ``benchmarks.md``/``.json`` and plots to
    ``out``. With ``only``, the other sections of an existing ``benchmarks.json`` are kept. A
    section that raises is logged and listed in ``failed``; the others still run."""
    from sensorium.benchmarks import report
    from sensorium.benchmarks.common import Config, machine

    names = list(dict.fromkeys(only or SECTIONS))
    cfg = Config(quick=quick, log=log)
    doc = report.load(out) if only else {}
    here = machine()
    doc["schema"] = report.SCHEMA
    if not only or "generated" not in doc:     # the header keeps the full run's date and machine
        doc.update({"generated": _now(), "machine": here, "quick": quick})
    if not only:
        doc["command"] = command
    else:
        doc.setdefault("command", "sensorium bench --out " + str(out))
    sections = doc.setdefault("sections", {})
    for s in sections.values():
        s.pop("_fresh", None)
    failed = []
    t_all = time.perf_counter()
    for name in names:
        log(f"sensorium bench: {name} …")
        t0 = time.perf_counter()
        try:
            sec = importlib.import_module(f"sensorium.benchmarks.{name}").run(cfg)
        except Exception as exc:  # noqa: BLE001 - one broken section must not lose the others
            failed.append(name)
            log(f"sensorium bench: {name} failed: {type(exc).__name__}: {exc}\n{traceback.format_exc()}")
            continue
        sec.elapsed_s = time.perf_counter() - t0
        js = sec.to_json()
        js.update({"measured_at": _now(), "machine": here, "quick": quick, "command": command, "_fresh": True})
        sections[name] = js
        log(f"sensorium bench: {name} done in {sec.elapsed_s:.0f} s")
    if not only:
        doc["elapsed_s"] = time.perf_counter() - t_all
    written = report.write(out, doc, plots=plots, log=log)
    for s in sections.values():
        s.pop("_fresh", None)
    # rewrite the JSON without the run-local flag
    report.write(out, doc, plots=False, log=log)
    return SuiteResult(doc, list(written), failed)
