"""``sensorium validate``, ``info`` and ``probe``: world files at a terminal (printing only; the
library parts are :mod:`sensorium.server.world.loader`, :mod:`sensorium.server.sim.summary` and
:class:`sensorium.server.sim.simulation.Simulation`)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from sensorium.server.sim.summary import world_summary
from sensorium.server.world.loader import WorldError, bundled_or_path, default_world_path, load_world


def world_options(args: argparse.Namespace) -> dict[str, Any]:
    """``--allow-large``/``--allow-outside-meshes`` → keyword arguments of ``load_world``."""
    from sensorium.server.world.limits import WorldLimits

    return {"limits": WorldLimits.large() if getattr(args, "allow_large", False) else WorldLimits(),
            "allow_outside_meshes": getattr(args, "allow_outside_meshes", False)}


def print_report(loaded, *, every: bool = False) -> None:
    """What a load left out, once, on standard error: a header with the counts, then each loss and
    warning (``every``) or the same grouped with their counts (:mod:`sensorium.server.world.report`)."""
    report = loaded.report
    if report:
        print(report.text(every=every), file=sys.stderr, flush=True)


def validate(args: argparse.Namespace) -> int:
    """Exit 1 when a world cannot load, or loads without a robot, a sensor device or a shape sensors
    see (each named with its line and why); ``--allow-skipped`` accepts those. Visual- or
    physics-only differences are warnings (exit 0)."""
    status = 0
    for path in args.world:
        try:
            loaded = load_world(path, **world_options(args))
        except WorldError as exc:
            print(str(exc), file=sys.stderr)
            print(f"{path}: INVALID ({len(exc.problems)} problem{'s' if len(exc.problems) != 1 else ''})", file=sys.stderr)
            status = 1
            continue
        print_report(loaded, every=getattr(args, "every", False))
        losses = loaded.report.losses
        if losses and not getattr(args, "allow_skipped", False):
            print(f"{path}: INVALID ({loaded.report.counts()}; --allow-skipped accepts what was left out)",
                  file=sys.stderr)
            status = 1
            continue
        print(f"{path}: OK")
    return status


def info(args: argparse.Namespace) -> int:
    path = str(bundled_or_path(args.path)) if args.path else str(default_world_path())
    if Path(path).is_dir():
        from sensorium.cli.recording import print_bag_info  # a rosbag2 directory (sensorium export)

        return print_bag_info(path, as_json=args.json)
    if str(path).endswith(".mcap"):
        from sensorium.cli.recording import print_info  # recordings

        return print_info(path, as_json=args.json)
    try:
        s = world_summary(path)
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    if path.lower().endswith(".wbt"):       # each PROTO used, with its licence line
        from dataclasses import asdict

        from sensorium.server.world.proto import protos_used

        s["protos"] = [asdict(u) for u in protos_used(path)]
    if args.json:
        print(json.dumps(s, indent=2))
        return 0
    print(f"world     {s['world']}  ({s['file']})")
    print(f"time step {s['basic_time_step_ms']} ms   seed {s['random_seed']}")
    print(f"solids    {len(s['solids'])}: " + ", ".join(f"{x['name']} ({x['geometry']})" for x in s["solids"]))
    print(f"triangles {s['triangles']} (infinite planes are analytic and not counted)")
    print(f"lights    {len(s['lights'])}: " + ", ".join(f"{x['name'] or '-'} ({x['type']}{'' if x['on'] else ', off'})" for x in s["lights"]))
    print(f"robots    {len(s['robots'])}")
    for r in s["robots"]:
        given = "".join(f" {a!r}" for a in r["controller_args"])    # which controller `run` starts, and with what
        controller = f"controller {r['controller']!r}{f' (controllerArgs{given})' if given else ''}"
        if path.lower().endswith(".wbt") and not r["controller_given"]:
            controller += " (no controller field: `run` gives it Webots' default '<generic>')"
        print(f"  {r['name']}{'' if r['synchronization'] else ' (asynchronous)'}: {len(r['devices'])} devices, "
              f"{controller}")
        print(f"    {'(drive)':<14} {r['drive']}")
        for d in r["devices"]:
            print(f"    {d['name']:<14} {d['summary']}")
    for u in s.get("protos", []):
        print(f"proto     {u['name']} x{u['instances']}: {u['license'] or 'no license line'} ({u['path'] or u['url']})")
    for line in s["report"]:
        print(line)
    return 0


def _parse_enable(spec: str) -> tuple[str, int]:
    target, _, period = spec.rpartition(":")
    if not target or not period.isdigit() or int(period) <= 0:
        raise SystemExit(f"--enable expects ROBOT/DEVICE:PERIOD with PERIOD a positive integer (ms), got {spec!r}")
    return target, int(period)


def _summary(value) -> object:
    import numpy as np

    if isinstance(value, float):
        return None if math.isnan(value) else value
    if isinstance(value, (bool, int, str)) or value is None:      # a presence, a lock state, a joint type
        return value
    arr = np.asarray(value)
    if arr.dtype.names:
        xyz = np.stack([arr["x"], arr["y"], arr["z"]], axis=-1)
        finite = np.isfinite(xyz).all(axis=-1)
        return {"points": int(arr.size), "finite": int(finite.sum())}
    finite = arr[np.isfinite(arr)]
    return {"shape": list(arr.shape), "finite": int(finite.size),
            "min": float(finite.min()) if finite.size else None,
            "max": float(finite.max()) if finite.size else None,
            "mean": float(finite.mean()) if finite.size else None}


def probe(args: argparse.Namespace) -> int:
    from sensorium.server.sim.sensors import Lidar
    from sensorium.server.sim.simulation import Simulation

    path = args.world or str(default_world_path())
    try:
        loaded = load_world(path, **world_options(args))
        sim = Simulation(loaded, precision=args.precision)
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    print_report(loaded)
    enabled: list[Any] = []        # sensors.LightSensor | DistanceSensor | Lidar: each has readings()
    try:
        for spec in args.enable:
            target, period = _parse_enable(spec)
            devices = ([d for d in sim.all_devices() if d.kind != "LED"]      # all sensors: an LED measures nothing
                       if target == "all" else [sim.device(target)])
            for dev in devices:
                dev.enable(period)
                enabled.append(dev)
        for target in args.point_cloud:
            lidar = sim.device(target)
            if not isinstance(lidar, Lidar):
                print(f"probe: --point-cloud {target}: not a lidar ({lidar.kind})", file=sys.stderr)
                return 2
            lidar.enable_point_cloud()
    except KeyError as exc:
        print(f"probe: {exc.args[0]}", file=sys.stderr)
        return 2
    if not enabled:
        print("probe: nothing enabled; use --enable ROBOT/DEVICE:PERIOD (or all:PERIOD)", file=sys.stderr)
    from sensorium.cli.progress import bar

    # a progress bar while the lines go to a file or a pipe (on a terminal they show the progress)
    progress = bar(args.steps, "probe", "step", enabled=sys.stderr.isatty() and not sys.stdout.isatty())
    for step in range(1, args.steps + 1):
        sim.step()
        progress.update(1)
        for dev in enabled:
            readings = dev.readings()
            if args.json:
                row = {"step": step, "time_ms": sim.time_ms, "robot": dev.robot_name, "device": dev.name}
                row.update({k: _summary(v) for k, v in readings.items()})
                print(json.dumps(row), flush=True)
            else:
                text = ", ".join(f"{k}={_summary(v)}" for k, v in readings.items())
                print(f"step {step:>4} t={sim.time_ms:>6} ms  {dev.path:<22} {text}", flush=True)
    progress.close()
    return 0
