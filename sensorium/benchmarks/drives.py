"""What each kind of drive costs the batched simulation: copy-steps per CPU second, and the drive alone.

``python -m sensorium.benchmarks.drives [--copies 64] [--steps 800] [--rounds 5] [--only mecanum,omni3]``

One robot in a walled 2.2 m square, with a GPS and four distance sensors, ``copies`` copies stepped
together (FAST, one thread, kinematic contact on), random wheel speeds every 4 basic steps. The kinds
(two-wheel and two-wheel with its wheels' centre off its origin, both in the C drive pass, mecanum,
three- and four-wheel omni, and a mecanum robot with a two-wheel robot beside it: a mixed world, whose
two-wheel robot's wheels and moves are C passes within the numpy drive) run interleaved in one
process, round after round; each figure is the median of the rounds. "drive" is the CPU time of the drive step alone per basic step (the same commands, no devices).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.world.loader import parse_world

STEP_MS = 16
COMMAND_EVERY = 4       # basic steps between two random commands
SPEED = 10.0            # rad/s: commands are uniform in [-SPEED, SPEED]


def _omni_wheels(count: int, distance: float, radius: float, first: float) -> list[dict]:
    """``count`` omni wheels evenly round the centre, each rolling along its axis × up."""
    angles = [first + i * 2.0 * math.pi / count for i in range(count)]
    return [{"motor": f"wheel{i + 1}", "position": [distance * math.cos(a), distance * math.sin(a)],
             "axis": [math.cos(a), math.sin(a)], "radius": radius} for i, a in enumerate(angles)]


KINDS: dict[str, dict] = {
    "two-wheel": {"differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": SPEED}},
    "two-wheel off-centre": {"differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2,
                                                    "max_wheel_speed": SPEED, "axle_center": [0.025, 0.0]}},
    "mecanum": {"mecanum_drive": {"wheel_radius": 0.05, "lx": 0.1, "ly": 0.1, "max_wheel_speed": SPEED}},
    "omni3": {"omni_drive": {"max_wheel_speed": SPEED, "wheels": _omni_wheels(3, 0.1, 0.05, math.pi)}},
    "omni4": {"omni_drive": {"max_wheel_speed": SPEED, "wheels": _omni_wheels(4, 0.12, 0.05, math.pi / 4)}},
}
# a second robot beside the first (no devices): a mixed world, its two-wheel robot still in C passes
KINDS["mecanum + two-wheel"] = KINDS["mecanum"]
PARTNER = {"mecanum + two-wheel": KINDS["two-wheel"]}
SENSORS = ["gps", "ds0", "ds1", "ds2", "ds3"]


def _wall(name: str, x: float, y: float, sx: float, sy: float) -> dict:
    return {"name": name, "pose": {"translation": [x, y, 0.25]}, "geometry": {"type": "box", "size": [sx, sy, 0.5]}}


def _devices() -> list[dict]:
    out: list[dict] = [{"device": "GPS", "name": "gps"}]
    for i, a in enumerate((0.0, math.pi / 2, math.pi, -math.pi / 2)):
        out.append({"device": "DistanceSensor", "name": f"ds{i}",
                    "pose": {"translation": [0.2 * math.cos(a), 0.2 * math.sin(a), 0.0], "rotation": [0, 0, 1, a]},
                    "lookup_table": [[0, 0, 0], [1.0, 1000, 0]]})
    return out


def build(kind: str, copies: int) -> BatchedSimulation:
    world = parse_world({"world_info": {"basic_time_step": STEP_MS, "contact": True},
                         "solids": [_wall("n", 0, 1.2, 2.6, 0.2), _wall("s", 0, -1.2, 2.6, 0.2),
                                    _wall("e", 1.2, 0, 0.2, 2.2), _wall("w", -1.2, 0, 0.2, 2.2)],
                         "robots": [{"name": "r", "pose": {"translation": [0, 0, 0.05]},
                                     "body": {"geometry": {"type": "box", "size": [0.3, 0.3, 0.1]}},
                                     **KINDS[kind], "devices": _devices()},
                                    *([{"name": "partner", "pose": {"translation": [0.6, 0.6, 0.05]},
                                        "body": {"geometry": {"type": "box", "size": [0.3, 0.3, 0.1]}},
                                        **PARTNER[kind]}] if kind in PARTNER else [])]})
    return BatchedSimulation(world, copies, precision="fast", threads=1)


def _command(sim: BatchedSimulation, kind: str, rng: np.random.Generator) -> None:
    c = sim.copies
    if kind.startswith("two-wheel"):
        sim.set_wheels(0, rng.uniform(-SPEED, SPEED, c), rng.uniform(-SPEED, SPEED, c))
    elif kind.startswith("mecanum"):
        sim.mecanum.command(0, rng.uniform(-SPEED, SPEED, (c, 4)))
        if kind in PARTNER:
            sim.set_wheels(1, rng.uniform(-SPEED, SPEED, c), rng.uniform(-SPEED, SPEED, c))
    else:
        wheels = len(KINDS[kind]["omni_drive"]["wheels"])
        sim.omni.command(0, rng.uniform(-SPEED, SPEED, (c, wheels)))


def _round(sim: BatchedSimulation, kind: str, seed: int, steps: int, step) -> float:
    """CPU seconds of ``steps`` calls of ``step`` after a reset, commands drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    sim.reset(np.arange(sim.copies), list(range(sim.copies)))
    for name in SENSORS:
        sim.enable(sim.device("r", name), STEP_MS)
    t0 = time.process_time()
    for s in range(steps):
        if s % COMMAND_EVERY == 0:
            _command(sim, kind, rng)
        step()
    return time.process_time() - t0


def run(kinds: list[str], copies: int, steps: int, rounds: int) -> dict[str, dict[str, float]]:
    """Per kind: median copy-steps per CPU second, ms per basic step, ms of the drive alone per basic step."""
    sims = {k: build(k, copies) for k in kinds}
    whole: dict[str, list[float]] = {k: [] for k in kinds}
    drive: dict[str, list[float]] = {k: [] for k in kinds}
    for r in range(rounds):
        for k, sim in sims.items():
            whole[k].append(_round(sim, k, r, steps, sim.step))
            assert np.isfinite(sim.values["DistanceSensor"]).all()
            drive[k].append(_round(sim, k, r, steps, lambda sim=sim: sim._drive(sim._every_copy, STEP_MS)))
    out = {}
    for k in kinds:
        t = statistics.median(whole[k])
        out[k] = {"copy_steps_per_cpu_s": copies * steps / t, "step_ms": t / steps * 1000.0,
                  "drive_ms": statistics.median(drive[k]) / steps * 1000.0,
                  "contacts": float(sims[k].counters["contacts"])}
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.drives", description=__doc__.split("\n")[0])
    parser.add_argument("--copies", type=int, default=64)
    parser.add_argument("--steps", type=int, default=800)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--only", default=",".join(KINDS), help="kinds, comma-separated: " + ", ".join(KINDS))
    args = parser.parse_args(argv)
    kinds = [k.strip() for k in args.only.split(",") if k.strip()]
    unknown = [k for k in kinds if k not in KINDS]
    if unknown or args.copies < 1 or args.steps < 1 or args.rounds < 1:
        parser.error(f"unknown kind {unknown[0]!r} (kinds: {', '.join(KINDS)})" if unknown
                     else "--copies, --steps and --rounds must be at least 1")
    print(f"{args.copies} copies, {args.steps} basic steps a round, medians of {args.rounds} interleaved rounds, "
          "FAST, one thread, contact on")
    for k, r in run(kinds, args.copies, args.steps, args.rounds).items():
        print(f"{k:22s} {r['copy_steps_per_cpu_s']:>10,.0f} copy-steps/CPU s   step {r['step_ms']:.3f} ms   "
              f"drive {r['drive_ms']:.3f} ms   contacts {r['contacts']:.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
