"""Sweeps: many simulations (worlds x parameters x controllers x seeds), each with its own MCAP
recording and one summary row, gathered into one table (CSV, Parquet).

    from sensorium.sweep import run_sweep
    result = run_sweep({"worlds": ["default"], "seeds": {"count": 8}, "duration_ms": 2000,
                        "controllers": ["circle"]}, output="out", engine="ray")
    result.frame()            # pandas DataFrame, one row per run, in run order

``sensorium sweep SPEC`` is the same from the command line. Engines: ``ray`` (tasks on a local
Ray bound to loopback, or on a cluster by ``address``), ``local`` (a process pool), ``auto`` (Ray
when installed, else local). The runs and rows do not depend on the engine: the same spec gives
the same table (except ``wall_s``) and the same recordings (``digest``) on both.
"""

from __future__ import annotations

import csv
import os
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sensorium.sweep.engines import ENGINES, available, default_workers, local_pool, ray_tasks
from sensorium.sweep.run import run_one
from sensorium.sweep.spec import RunSpec, SpecError, SweepSpec, load_spec, parse_spec

__all__ = ["run_sweep", "SweepResult", "SweepSpec", "RunSpec", "SpecError", "load_spec", "parse_spec", "run_one",
           "write_table", "NONDETERMINISTIC"]

NONDETERMINISTIC = ("wall_s",)
"""Columns that depend on the machine and load, not on the run's inputs."""

_FIRST = ["run", "world", "seed", "controller"]
_AFTER = ["status", "error", "steps", "sim_time_ms", "messages", "digest", "recording", "wall_s"]


@dataclass
class SweepResult:
    rows: list[dict]
    columns: list[str]
    engine: str
    workers: int
    wall_s: float
    tables: list[Path] = field(default_factory=list)

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.rows if r.get("status") != "ok"]

    @property
    def sim_time_s(self) -> float:
        return sum(r.get("sim_time_ms") or 0 for r in self.rows) / 1000.0

    def frame(self):
        """The table as a pandas DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.rows, columns=self.columns)


def _columns(rows: list[dict]) -> list[str]:
    seen: dict[str, None] = {}
    for r in rows:
        for k in r:
            seen.setdefault(k, None)
    params = [k for k in seen if k.startswith("param:")]
    head = _FIRST + params + _AFTER
    return head + sorted(k for k in seen if k not in head)


def write_table(rows: list[dict], columns: list[str], path: str | Path) -> Path:
    """Write the rows as CSV (``.csv``) or Parquet (``.parquet``, needs pyarrow)."""
    path = Path(path)
    if path.suffix == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        data: dict[str, list] = {}
        for c in columns:
            col = [r.get(c) for r in rows]
            kinds = {type(v) for v in col if v is not None}
            if kinds <= {int, float} and float in kinds:
                col = [None if v is None else float(v) for v in col]
            elif len(kinds) > 1 or (kinds and not kinds <= {int, float, str, bool}):
                col = [None if v is None else str(v) for v in col]
            data[c] = col
        pq.write_table(pa.table(data), path)
        return path
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if v is None else repr(v) if isinstance(v, float) else v) for k, v in r.items()})
    return path


def _progress(total: int, enabled: bool):
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit="run", desc="sweep", dynamic_ncols=True)


def run_sweep(spec: SweepSpec | Mapping | str | Path, output: str | Path | None = None, *, engine: str = "auto",
              workers: int | None = None, address: str | None = None, progress: bool = True,
              formats: Iterable[str] = ("csv", "parquet"), overwrite: bool = False,
              ray_init: dict[str, Any] | None = None) -> SweepResult:
    """Run every run of ``spec``; with ``output``, write ``output/runs/NNNN.mcap`` and
    ``output/summary.<fmt>``. A failing run is a row with ``status = "error"``, never an exception."""
    if isinstance(spec, (str, Path)):
        spec = load_spec(spec)
    elif isinstance(spec, Mapping):
        spec = parse_spec(spec)
    if engine not in ENGINES:
        raise SpecError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    if engine == "auto":
        engine = "ray" if (address or available("ray")) else "local"
    if engine == "ray" and not available("ray"):
        raise SpecError("engine 'ray' needs Ray: pip install 'sensorium[ray]' (or use --engine local)")
    formats = [f.lower().lstrip(".") for f in formats]
    for f in formats:
        if f not in ("csv", "parquet"):
            raise SpecError(f"unknown table format {f!r} (csv, parquet)")
    if "parquet" in formats:
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise SpecError("Parquet output needs pyarrow: pip install 'sensorium[sweep]' (or --format csv)") from None
    out = None
    if output is not None:
        out = Path(output).resolve()      # workers may run elsewhere (Ray): absolute paths
        clash = [p for p in [out / f"summary.{f}" for f in formats] + [out / "runs"] if p.exists()]
        if clash and not overwrite:
            raise SpecError(f"{clash[0]} already exists (use --overwrite / overwrite=True to replace the sweep's outputs)")
        out.mkdir(parents=True, exist_ok=True)
        if overwrite and (out / "runs").is_dir():
            for old in (out / "runs").glob("*.mcap"):
                old.unlink()
    runs = spec.runs(out)
    workers = workers or default_workers()
    bar = _progress(len(runs), progress)
    t0 = time.perf_counter()
    rows: dict[int, dict] = {}
    if engine == "ray":
        from sensorium.sweep.engines import init_ray

        try:
            ray = init_ray(address, workers, **(ray_init or {}))
        except Exception as exc:         # unreachable cluster, bad options, Ray failing to start
            where = f"join the Ray cluster at {address!r}" if address else "start a local Ray"
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
            raise SpecError(f"cannot {where}: {type(exc).__name__}: {first}") from None
        if address:                     # a cluster: report its CPUs, not this machine's
            workers = int(ray.cluster_resources().get("CPU", workers))
        source = ray_tasks(runs, workers, address)
    else:
        source = local_pool(runs, workers)
    failed = 0
    try:
        for index, row in source:
            rows[index] = row
            failed += row.get("status") != "ok"
            if bar is not None:
                bar.update(1)
                if failed:
                    bar.set_postfix(failed=failed)
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    ordered = [rows[i] for i in sorted(rows)]
    if out is not None:
        for r in ordered:
            if r.get("recording"):
                r["recording"] = os.path.relpath(r["recording"], out)
    result = SweepResult(ordered, _columns(ordered), engine, workers, wall)
    if out is not None:
        result.tables = [write_table(ordered, result.columns, out / f"summary.{f}") for f in formats]
    return result
