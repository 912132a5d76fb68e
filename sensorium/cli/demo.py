"""``sensorium demo``: the server, two Webots-style controllers and a recording, end to end.

Starts ``sensorium serve`` on the default world with ``--record``, launches the two example
controllers (``client/examples/braitenberg.py`` on the e-puck, ``wanderer.py`` on the scout) as
separate processes through ``sensorium controller``, lets them run for a bounded simulated time in
fast mode, then summarises the recording and draws a top-down picture of the arena.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parents[1] / "client" / "examples"


def _examples_dir() -> Path:
    if EXAMPLES.is_dir():
        return EXAMPLES
    from importlib.resources import files

    return Path(str(files("sensorium.client.examples")))


CONTROLLERS = (("epuck", "braitenberg.py"), ("scout", "wanderer.py"))


@dataclass
class DemoResult:
    world: str
    simulated_s: float
    wall_s: float
    recording: Path
    picture: Path
    messages: dict[str, int] = field(default_factory=dict)
    distance_m: dict[str, float] = field(default_factory=dict)
    light_start: float = math.nan          # e-puck ls0 + ls1 at the first and last reading
    light_end: float = math.nan
    lamp_distance_start: float = math.nan  # e-puck distance to the point light
    lamp_distance_end: float = math.nan
    exit_codes: dict[str, int] = field(default_factory=dict)

    @property
    def real_time_factor(self) -> float:
        return self.simulated_s / self.wall_s if self.wall_s > 0 else math.inf

    def as_dict(self) -> dict:
        return {
            "world": self.world, "simulated_s": self.simulated_s, "wall_s": round(self.wall_s, 3),
            "real_time_factor": round(self.real_time_factor, 2), "recording": str(self.recording),
            "picture": str(self.picture), "messages": self.messages, "distance_m": self.distance_m,
            "light_start": self.light_start, "light_end": self.light_end,
            "lamp_distance_start": self.lamp_distance_start, "lamp_distance_end": self.lamp_distance_end,
            "exit_codes": self.exit_codes,
        }


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "sensorium", *args]


def run_demo(world: str | None, duration_s: float, out_dir: Path, precision: str = "exact",
             timeout_s: float = 600.0, log=print) -> DemoResult:
    from sensorium.server.world.loader import default_world_path, load_world

    world_path = Path(world) if world else default_world_path()
    loaded = load_world(world_path)
    out_dir.mkdir(parents=True, exist_ok=True)
    recording = out_dir / "demo.mcap"
    picture = out_dir / "arena.png"
    if recording.exists():
        recording.unlink()
    until_ms = int(round(duration_s * 1000))
    step = loaded.world.world_info.basic_time_step
    until_ms = max(step, until_ms - until_ms % step)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    server = subprocess.Popen(
        _cli("serve", str(world_path), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0",
             "--mode", "fast", "--precision", precision, "--until", str(until_ms), "--record", str(recording)),
        stdout=subprocess.PIPE, stderr=open(out_dir / "server.log", "w"), text=True, env=env)
    procs: dict[str, subprocess.Popen] = {}
    start = time.monotonic()
    try:
        assert server.stdout is not None
        line = server.stdout.readline()
        if "rpc=" not in line:
            raise RuntimeError(f"the server did not start (see {out_dir / 'server.log'}): {line.strip()}")
        rpc = line.split("rpc=")[1].split()[0]
        log(f"demo: server up ({rpc}); running {until_ms / 1000:g} s of simulated time in fast mode")
        for robot, script in CONTROLLERS:
            procs[robot] = subprocess.Popen(
                _cli("controller", str(_examples_dir() / script), "--robot", robot, "--url", f"{rpc}/{robot}"),
                stdout=open(out_dir / f"{robot}.log", "w"), stderr=subprocess.STDOUT, env=env)
        deadline = start + timeout_s
        server.wait(timeout=max(1.0, deadline - time.monotonic()))
        for p in procs.values():
            p.wait(timeout=max(1.0, deadline - time.monotonic()))
    finally:
        for p in [*procs.values(), server]:
            if p.poll() is None:
                p.kill()
                p.wait()
        if server.stdout:
            server.stdout.close()
    wall = time.monotonic() - start
    result = DemoResult(world=loaded.world.world_info.name, simulated_s=until_ms / 1000, wall_s=wall,
                        recording=recording, picture=picture,
                        exit_codes={"server": server.returncode, **{r: p.returncode for r, p in procs.items()}})
    _summarise(result, loaded.world)
    _draw(result, loaded.world, picture)
    return result


def _summarise(result: DemoResult, world) -> None:
    from sensorium.server.recording.reader import iter_messages

    paths: dict[str, list[tuple[float, float]]] = {}
    light: list[float] = []
    ls = {}
    for m in iter_messages(result.recording):
        result.messages[m.topic] = result.messages.get(m.topic, 0) + 1
        if m.topic.endswith("/pose"):
            p = m.decode()["pose"]["position"]
            paths.setdefault(m.topic.split("/")[1], []).append((p["x"], p["y"]))
        elif m.topic in ("/epuck/ls0/value", "/epuck/ls1/value"):
            ls[m.topic] = m.decode()["illuminance"]
            if len(ls) == 2:
                light.append(sum(ls.values()))
    result._paths = {k: np.asarray(v) for k, v in paths.items()}  # type: ignore[attr-defined]
    for robot, xy in result._paths.items():  # type: ignore[attr-defined]
        result.distance_m[robot] = float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1))) if len(xy) > 1 else 0.0
    if light:
        result.light_start, result.light_end = light[0], light[-1]
    lamp = next((lt for lt in world.lights if lt.type == "PointLight" and lt.on), None)
    xy = result._paths.get("epuck")  # type: ignore[attr-defined]
    if lamp is not None and xy is not None and len(xy):
        q = np.asarray(lamp.location[:2])
        result.lamp_distance_start = float(np.linalg.norm(xy[0] - q))
        result.lamp_distance_end = float(np.linalg.norm(xy[-1] - q))


def _draw(result: DemoResult, world, path: Path) -> None:
    from sensorium.cli.png import Canvas
    from sensorium.server.recording.reader import iter_messages
    from sensorium.server.world.poses import pose_from_model

    canvas = Canvas(-2.2, 2.2, -2.2, 2.2, pixels_per_metre=160)
    for s in world.solids:
        g = s.geometry
        if g is None:
            continue
        pose = pose_from_model(s.pose)
        cx, cy = pose.translation[:2]
        yaw = math.atan2(pose.rotation[1, 0], pose.rotation[0, 0])
        grey = tuple(int(160 * c) + 40 for c in (s.appearance.base_color if s.appearance else (0.6, 0.6, 0.6)))
        if g.type == "box":
            canvas.rectangle(cx, cy, g.size[0], g.size[1], yaw, grey)
        elif g.type in ("sphere", "cylinder"):
            canvas.disc(cx, cy, g.radius, grey)
        elif g.type == "capsule":
            axis = pose.rotation[:2, 2] * g.height / 2
            canvas.polyline(np.array([[cx, cy] - axis, [cx, cy] + axis]), grey, width=max(1, int(2 * g.radius * 160)))
        elif g.type == "mesh":
            canvas.disc(cx, cy, 0.15, grey)
    for lt in world.lights:
        if lt.type in ("PointLight", "SpotLight"):
            canvas.disc(lt.location[0], lt.location[1], 0.06, (240, 200, 0))
    colours = {"epuck": (0, 140, 0), "scout": (220, 100, 0)}
    paths = getattr(result, "_paths", {})
    for robot, xy in paths.items():
        canvas.polyline(xy, colours.get(robot, (0, 0, 0)), width=3)
        if len(xy):
            canvas.points(xy[-1:], colours.get(robot, (0, 0, 0)), radius=6)
    # the last lidar scan of the scout, placed with the pose recorded at that time
    scan, pose_at = None, {}
    for m in iter_messages(result.recording, topics=["/scout/lidar/laser_scan", "/scout/pose"]):
        if m.topic == "/scout/pose":
            pose_at[m.stamp_ns] = m.decode()["pose"]
        else:
            scan = m
    if scan is not None and scan.stamp_ns in pose_at:
        body = scan.decode()
        ranges = np.frombuffer(body["ranges"], dtype="<f4").astype(np.float64)
        ang = body["angle_min"] + body["angle_increment"] * np.arange(len(ranges))
        p = pose_at[scan.stamp_ns]
        q = p["orientation"]
        yaw = math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))
        ok = np.isfinite(ranges)
        pts = np.stack([p["position"]["x"] + ranges[ok] * np.cos(ang[ok] + yaw),
                        p["position"]["y"] + ranges[ok] * np.sin(ang[ok] + yaw)], axis=1)
        canvas.points(pts, (200, 0, 0), radius=1)
    canvas.save(path)


def main(args: argparse.Namespace) -> int:
    out = Path(args.out)
    try:
        result = run_demo(args.world, args.duration, out, precision=args.precision,
                          log=lambda text: print(text, file=sys.stderr, flush=True))
    except (RuntimeError, subprocess.TimeoutExpired) as exc:
        print(f"demo: failed: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print(f"demo: {result.simulated_s:g} s simulated in {result.wall_s:.1f} s wall "
              f"(real-time factor {result.real_time_factor:.1f})")
        for robot, d in result.distance_m.items():
            print(f"  {robot:<6} drove {d:.2f} m")
        print(f"  e-puck light (ls0+ls1): {result.light_start:.1f} at start -> {result.light_end:.1f} at end; "
              f"distance to the lamp {result.lamp_distance_start:.2f} m -> {result.lamp_distance_end:.2f} m")
        print(f"  recorded {sum(result.messages.values())} messages to {result.recording}:")
        for topic, n in sorted(result.messages.items()):
            print(f"    {topic:<28} {n}")
        print(f"  picture: {result.picture}   logs: {out}/*.log   replay: sensorium replay {result.recording}")
    bad = {k: v for k, v in result.exit_codes.items() if v != 0}
    if bad:
        print(f"demo: processes failed: {bad} (see {out}/*.log)", file=sys.stderr)
        return 1
    return 0
