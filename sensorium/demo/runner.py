"""Run the demo: check the world, start the server and the two controllers, show progress.

The server starts paused and is switched to fast mode once both controllers are attached, so
every run of the same world gives the same recording (no controller starts late).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "client" / "examples"
MOTORS = ("left wheel motor", "right wheel motor")


@dataclass(frozen=True)
class DemoController:
    robot: str
    script: str
    role: str
    devices: dict[str, str]           # device name -> type the controller uses


CONTROLLERS = (
    DemoController("epuck", "light_follower.py", "light follower",
                   {"ls0": "LightSensor", "ls1": "LightSensor", **{f"ps{i}": "DistanceSensor" for i in range(8)}}),
    DemoController("scout", "wanderer.py", "wanderer",
                   {"lidar": "Lidar", **{f"sonar_{s}": "DistanceSensor" for s in ("front", "left", "right", "back")}}),
)


class DemoError(Exception):
    """The demo cannot run or failed: one line for the user."""


@dataclass
class DemoResult:
    world: str
    world_path: Path
    simulated_s: float
    wall_s: float
    recording: Path
    picture: Path | None
    messages: dict[str, int] = field(default_factory=dict)
    distance_m: dict[str, float] = field(default_factory=dict)
    cells_visited: dict[str, int] = field(default_factory=dict)       # distinct 0.5 m grid cells
    smoothness: dict[str, float] = field(default_factory=dict)        # 1 s-resampled length / driven length
    longest_stuck_s: dict[str, float] = field(default_factory=dict)   # longest stretch without progress (summary.py)
    light_start: float = math.nan          # e-puck ls0 + ls1 at the first and last reading
    light_end: float = math.nan
    lamp_distance_start: float = math.nan  # e-puck distance to the point light (m)
    lamp_distance_end: float = math.nan
    lamp_distance_min: float = math.nan
    lamp_reached_s: float = math.nan       # first time within LAMP_NEAR_M of the lamp
    lamp_distance_max_after_reached: float = math.nan
    exit_codes: dict[str, int | None] = field(default_factory=dict)

    @property
    def real_time_factor(self) -> float:
        return self.simulated_s / self.wall_s if self.wall_s > 0 else math.inf

    def as_dict(self) -> dict:
        def clean(v: float) -> float | None:
            return None if isinstance(v, float) and math.isnan(v) else v

        return {
            "world": self.world, "simulated_s": self.simulated_s, "wall_s": round(self.wall_s, 3),
            "real_time_factor": round(self.real_time_factor, 2), "recording": str(self.recording),
            "picture": str(self.picture) if self.picture else None, "messages": self.messages,
            "distance_m": self.distance_m, "cells_visited": self.cells_visited, "smoothness": self.smoothness,
            "longest_stuck_s": self.longest_stuck_s,
            "light_start": clean(self.light_start), "light_end": clean(self.light_end),
            "lamp_distance_start": clean(self.lamp_distance_start), "lamp_distance_end": clean(self.lamp_distance_end),
            "lamp_distance_min": clean(self.lamp_distance_min), "lamp_reached_s": clean(self.lamp_reached_s),
            "lamp_distance_max_after_reached": clean(self.lamp_distance_max_after_reached),
            "exit_codes": self.exit_codes,
        }


def examples_dir() -> Path:
    if EXAMPLES.is_dir():
        return EXAMPLES
    from importlib.resources import files

    return Path(str(files("sensorium.client.examples")))


def check_demo_world(world) -> list[str]:
    """What the example controllers need and the world lacks (empty: the demo can run)."""
    robots = {r.name: r for r in world.robots}
    problems = []
    for c in CONTROLLERS:
        r = robots.get(c.robot)
        if r is None:
            problems.append(f"no robot {c.robot!r}")
            continue
        have = {d.name: d.device for d in r.devices}
        missing = [f"{name} ({kind})" for name, kind in c.devices.items() if have.get(name) != kind]
        if missing:
            problems.append(f"robot {c.robot!r} lacks {', '.join(missing)}")
        drive = r.differential_drive
        if drive is None or (drive.left_motor, drive.right_motor) != MOTORS:
            problems.append(f"robot {c.robot!r} needs a differential_drive with motors {MOTORS[0]!r} and {MOTORS[1]!r}")
        if getattr(r, "controller", "<extern>") != "<extern>":
            problems.append(f"robot {c.robot!r} has controller {r.controller!r}, the demo needs \"<extern>\"")
    return problems


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "sensorium", *args]


def _last_line(path: Path) -> str:
    try:
        lines = [ln for ln in path.read_text(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return ""
    return lines[-1].strip() if lines else ""


class _Progress:
    """Simulated time and real-time factor on stderr, only on a terminal (tqdm, throttled)."""

    def __init__(self, total_s: float, enabled: bool | None = None):
        if enabled is None:
            enabled = sys.stderr.isatty()
        self.bar = None
        if enabled:
            try:
                from tqdm import tqdm
            except ImportError:
                return
            self.bar = tqdm(total=total_s, unit="s", file=sys.stderr, mininterval=0.5, leave=False,
                            bar_format="{desc} {percentage:3.0f}%|{bar}| {n:.1f}/{total:g} s simulated "
                                       "[{elapsed}<{remaining}{postfix}]", desc="demo")

    def update(self, time_s: float, rtf: float) -> None:
        if self.bar is not None:
            self.bar.set_postfix_str(f"real-time factor {rtf:.1f}", refresh=False)
            self.bar.update(max(0.0, time_s - self.bar.n))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


DEMO_MARK = ".sensorium-demo"      # in a folder the demo wrote: its files there are the demo's own


def demo_outputs(out_dir: Path) -> list[Path]:
    """The files a demo run writes in ``out_dir``."""
    return [out_dir / name for name in ("demo.mcap", "server.log", *(f"{c.robot}.log" for c in CONTROLLERS),
                                        "arena.png")]


def run_demo(world: str | None, duration_s: float, out_dir: Path, precision: str = "exact",
             timeout_s: float = 600.0, log: Callable[[str], None] = print, progress: bool | None = None,
             draw: bool = True, overwrite: bool = False) -> DemoResult:
    """Run the demo; raises :class:`DemoError` (one line) if it cannot run or a process fails to start.
    A previous demo's files in ``out_dir`` (marked by :data:`DEMO_MARK`) are replaced; files of the
    same names that no demo wrote only with ``overwrite``."""
    from sensorium.client.connection import Connection, SensoriumError
    from sensorium.server.world.loader import WorldError, default_world_path, load_world

    world_path = Path(world) if world else default_world_path()
    try:
        loaded = load_world(world_path)
    except WorldError as exc:
        raise DemoError(str(exc).splitlines()[0] if str(exc) else f"invalid world {world_path}") from None
    if loaded.report:           # what the load left out, once (the server's copy goes to server.log)
        log(loaded.report.text())
    problems = check_demo_world(loaded.world)
    if problems:
        raise DemoError(f"{world_path}: cannot run the demo's controllers on this world: {'; '.join(problems)}")
    if not (duration_s > 0 and math.isfinite(duration_s)):
        raise DemoError(f"--duration must be a positive number of seconds, got {duration_s:g}")
    taken = [p.name for p in demo_outputs(out_dir) if p.exists() or p.is_symlink()]
    if taken and not overwrite and not (out_dir / DEMO_MARK).is_file():
        raise DemoError(f"{out_dir} already holds {', '.join(taken)}, not written by a demo: not overwriting "
                        "(--force to replace them, or --out another folder)")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / DEMO_MARK).write_text("written by `sensorium demo`: the next demo run with this --out replaces "
                                         f"{', '.join(p.name for p in demo_outputs(out_dir))}\n")
    except OSError as exc:
        raise DemoError(f"cannot create the output directory {out_dir}: {exc.strerror or exc}") from None
    recording = out_dir / "demo.mcap"
    if recording.exists():
        recording.unlink()             # the demo's own output from a previous run
    step = loaded.world.world_info.basic_time_step
    until_ms = int(round(duration_s * 1000))
    until_ms = max(step, until_ms - until_ms % step)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    server_log = out_dir / "server.log"
    server = subprocess.Popen(
        _cli("serve", str(world_path), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0",
             "--mode", "pause", "--precision", precision, "--until", str(until_ms), "--record", str(recording)),
        stdout=subprocess.PIPE, stderr=open(server_log, "w"), text=True, env=env)
    procs: dict[str, subprocess.Popen] = {}
    bar = _Progress(0.0, False)
    start = time.monotonic()
    try:
        assert server.stdout is not None
        line = server.stdout.readline()
        if "rpc=" not in line:
            server.wait(timeout=30)
            raise DemoError(f"the server did not start: {_last_line(server_log) or line.strip() or 'no output'} "
                            f"(see {server_log})")
        rpc = line.split("rpc=")[1].split()[0]
        log(f"demo: server up ({rpc}); {until_ms / 1000:g} s of simulated time in fast mode; "
            f"logs in {out_dir}/")
        bar = _Progress(until_ms / 1000, progress)
        for c in CONTROLLERS:
            procs[c.robot] = subprocess.Popen(
                _cli("controller", str(examples_dir() / c.script), "--robot", c.robot, "--url", f"{rpc}/{c.robot}"),
                stdout=open(out_dir / f"{c.robot}.log", "w"), stderr=subprocess.STDOUT, env=env)
        deadline = start + timeout_s
        with Connection(rpc, timeout=5.0) as conn:
            _start_when_attached(conn, server, procs, deadline, out_dir)
            while server.poll() is None:
                if time.monotonic() > deadline:
                    raise DemoError(f"the demo did not finish within {timeout_s:g} s (see {out_dir}/*.log)")
                if all(p.poll() is not None for p in procs.values()):
                    try:                       # the normal end: -1 to every controller, then the server quits
                        server.wait(timeout=15)
                    except subprocess.TimeoutExpired:
                        raise DemoError(f"every controller exited before the end (see {out_dir}/*.log)") from None
                    break
                try:
                    info = conn.call("get_info", timeout=2.0)
                    bar.update(info["time_ms"] / 1000, info.get("real_time_factor", 0.0))
                except (SensoriumError, KeyError, TypeError):
                    pass                                          # the server is finishing
                time.sleep(0.25)
        bar.update(until_ms / 1000, 0.0)
        for p in procs.values():
            p.wait(timeout=max(1.0, deadline - time.monotonic()))
    except subprocess.TimeoutExpired:
        raise DemoError(f"the demo did not finish within {timeout_s:g} s (see {out_dir}/*.log)") from None
    finally:
        bar.close()
        for p in [*procs.values(), server]:
            if p.poll() is None:
                p.kill()
                p.wait()
        if server.stdout:
            server.stdout.close()
    wall = time.monotonic() - start
    from sensorium.demo.summary import summarise

    result = DemoResult(world=loaded.world.world_info.name, world_path=world_path, simulated_s=until_ms / 1000,
                        wall_s=wall, recording=recording, picture=None,
                        exit_codes={"server": server.returncode, **{r: p.returncode for r, p in procs.items()}})
    paths = summarise(result, loaded.world)
    if draw:
        from sensorium.demo.picture import draw_picture

        result.picture = draw_picture(result, loaded, paths, out_dir / "arena.png", log=log)
    return result


def _start_when_attached(conn, server: subprocess.Popen, procs: dict[str, subprocess.Popen], deadline: float,
                         out_dir: Path) -> None:
    """Leave pause (fast mode) once every demo robot has its controller attached."""
    from sensorium.client.connection import SensoriumError

    wanted = {c.robot for c in CONTROLLERS}
    while True:
        if server.poll() is not None:
            raise DemoError(f"the server stopped: {_last_line(out_dir / 'server.log')} (see {out_dir}/server.log)")
        for robot, p in procs.items():
            if p.poll() is not None:
                raise DemoError(f"the {robot} controller exited before attaching: "
                                f"{_last_line(out_dir / f'{robot}.log')} (see {out_dir}/{robot}.log)")
        if time.monotonic() > deadline:
            raise DemoError(f"the controllers did not attach in time (see {out_dir}/*.log)")
        try:
            info = conn.call("get_info", timeout=2.0)
            if {r["name"] for r in info["robots"] if r["attached"]} >= wanted:
                conn.call("set_mode", {"mode": "fast"}, timeout=5.0)
                return
        except SensoriumError:
            pass
        time.sleep(0.05)
