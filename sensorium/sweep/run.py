"""One run of a sweep, in whatever process executes it: world variant -> simulation -> recording
-> one summary row. Never raises: a failure is a row with ``status = "error"`` and the reason.

The row holds only values fixed by the run's inputs (so a sweep gives the same table on any
engine), except ``wall_s``. Columns: ``run, world, seed, controller, param:<path>..., status,
error, steps, sim_time_ms, messages, digest, recording`` then per robot ``<robot>.x, .y, .yaw,
.path_m`` (final planar pose -- east, north and the heading about up from east, the drive's forward,
in a NUE world too: sim/frames.py -- and the distance driven on the ground plane) and per light/distance sensor that measured
``<robot>/<device>.mean, .min, .max, .n``. ``digest`` is the SHA-256 of every recorded message
(topic, log time, sequence, bytes) in order: equal digests mean equal recordings.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from pathlib import Path
from typing import Any

import yaml

from sensorium.sweep.spec import RunSpec, SpecError, set_path

__all__ = ["run_one", "build_world", "fixed_columns"]

fixed_columns = ["run", "world", "seed", "controller"]


_LOADED: dict[tuple, Any] = {}


def _load(path: Path):
    """``load_world`` once per file version and worker process: a sweep runs the same few worlds
    many times, and parsing + validating a file costs more than building its simulation."""
    from sensorium.server.world.loader import WorldError, load_world

    try:
        st = path.stat()
    except OSError:
        return load_world(path)       # raises the loader's own error
    key = (str(path.resolve()), st.st_mtime_ns, st.st_size)
    hit = _LOADED.get(key)
    if hit is None:
        try:
            hit = load_world(path)
        except WorldError as exc:
            hit = exc
        if len(_LOADED) >= 64:
            _LOADED.clear()
        _LOADED[key] = hit
    if isinstance(hit, Exception):
        raise hit
    return hit


def build_world(world: str, seed: int, parameters) -> tuple[Any, bytes, str]:
    """(LoadedWorld, world text to attach, world name) for one run: the file with the parameters
    set and ``world_info.random_seed = seed``."""
    from sensorium.server.world.loader import default_world_path, parse_world

    path = default_world_path() if world == "default" else Path(world)
    base = _load(path)
    if not parameters:
        w = base.world.model_copy(update={"world_info": base.world.world_info.model_copy(update={"random_seed": seed})})
        return type(base)(world=w, source=base.source, base_dir=base.base_dir, text=base.text), base.text, path.name
    data = json.loads(json.dumps(base.world.model_dump(mode="json", exclude_none=True)))  # no shared YAML aliases
    for key, value in parameters:
        try:
            set_path(data, key, value)
        except SpecError as exc:
            raise SpecError(f"{path}: {exc}") from None
    data.setdefault("world_info", {})["random_seed"] = seed
    text = yaml.safe_dump(data, sort_keys=False).encode()
    return parse_world(data, source=str(path), base_dir=base.base_dir, text=text), text, path.name


class _Digest:
    """Recorder tee: hashes every message the recorder stores (same order, same bytes)."""

    def __init__(self, inner):
        self.inner = inner
        self.h = hashlib.sha256()
        self.count = 0

    def wants(self, topic: str) -> bool:
        return self.inner.wants(topic)

    def demands(self, topic: str) -> bool:
        return self.inner.demands(topic)

    def record(self, topic, ros_type, envelope, body, stamp_ns, seq) -> None:
        self.h.update(f"{topic}\0{ros_type}\0{stamp_ns}\0{seq}\0{len(body)}\0".encode())
        self.h.update(body)
        self.count += 1
        self.inner.record(topic, ros_type, envelope, body, stamp_ns, seq)


def _error_text(exc: BaseException) -> str:
    """One line: the exception type and its message (a world's problems joined by ' | ')."""
    text = " | ".join(line.strip() for line in str(exc).splitlines() if line.strip())
    return f"{type(exc).__name__}: {text}"[:2000]


def run_one(run: RunSpec) -> dict:
    """Execute one run; return its summary row (see the module docstring)."""
    row: dict[str, Any] = {"run": run.index, "world": run.world, "seed": run.seed, "controller": run.controller_name}
    for key, value in run.parameters:
        row[f"param:{key}"] = json.dumps(value) if isinstance(value, (list, dict)) else value
    row.update(status="ok", error="", steps=0, sim_time_ms=0, messages=0, digest="",
               recording=run.recording or "", wall_s=0.0)
    t0 = time.perf_counter()
    try:
        _simulate(run, row)
    except Exception as exc:   # a run's failure is data, not a dead sweep
        row["status"] = "error"
        row["error"] = _error_text(exc)
    row["wall_s"] = round(time.perf_counter() - t0, 6)
    return row


def _simulate(run: RunSpec, row: dict) -> None:
    from sensorium.server.daemon.topics import Topics
    from sensorium.server.recording.writer import McapRecorder
    from sensorium.server.sim.frames import drive_forward, enu_axes, planar_pose
    from sensorium.server.sim.sensors import Lidar
    from sensorium.server.sim.simulation import Simulation
    from sensorium.sweep.controllers import resolve

    loaded, text, name = build_world(run.world, run.seed, run.parameters)
    factory = resolve(run.controller)
    sim = Simulation(loaded)
    topics = Topics(sim)
    recorder = digest = None
    if run.recording:
        Path(run.recording).parent.mkdir(parents=True, exist_ok=True)
        meta = {"seed": str(run.seed), "basic_time_step_ms": str(sim.basic_time_step), "run": str(run.index),
                "controller": run.controller_name, "world": name,
                "parameters": json.dumps(dict(run.parameters), sort_keys=True)}
        recorder = McapRecorder(run.recording, text, name, meta, list(run.topics) if run.topics else None,
                                flush_interval=None, background_flush=False, session={"mode": "sweep"})
        digest = _Digest(recorder)
        topics.set_recorder(digest)
    try:
        step = factory(sim)
        steps = math.ceil(run.duration_ms / sim.basic_time_step)
        stats: dict[str, list[float]] = {}
        east, north, _ = axes = enu_axes(sim.world)
        last = {r.name: r.pose.translation[[east, north]] for r in sim.robots.values()}
        travelled = dict.fromkeys(sim.robots, 0.0)
        for _ in range(steps):
            if step is not None:
                step(sim)
            report = sim.step()
            for dev in report.measured:
                if not isinstance(dev, Lidar):
                    v = float(dev.value)
                    if math.isfinite(v):
                        s = stats.setdefault(dev.path, [0.0, math.inf, -math.inf, 0])
                        s[0] += v
                        s[1] = min(s[1], v)
                        s[2] = max(s[2], v)
                        s[3] += 1
            for r in sim.robots.values():
                xy = r.pose.translation[[east, north]]
                travelled[r.name] += math.hypot(*(xy - last[r.name]))
                last[r.name] = xy
            topics.publish(sim.time_ms)
        row["steps"] = steps
        row["sim_time_ms"] = sim.time_ms
    finally:
        if recorder is not None:
            recorder.close()
    if digest is not None:
        row["messages"] = digest.count
        row["digest"] = digest.h.hexdigest()
    for r in sim.robots.values():
        x, y, yaw = planar_pose(axes, r.pose.translation, r.pose.rotation, drive_forward(r.model))
        row[f"{r.name}.x"], row[f"{r.name}.y"], row[f"{r.name}.yaw"] = x, y, yaw
        row[f"{r.name}.path_m"] = travelled[r.name]
    for path in sorted(stats):
        total, lo, hi, n = stats[path]
        row[f"{path}.mean"] = total / n
        row[f"{path}.min"] = lo
        row[f"{path}.max"] = hi
        row[f"{path}.n"] = n
