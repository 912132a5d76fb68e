"""Cost of kinematic contact: ``python -m sensorium.benchmarks.contact [--steps N] [--body box]``.

24 driven e-puck-sized robots among 100 random boxes, cylinders and spheres (fixed seed), no
sensors enabled, so the step is the drive plus contact; prints ms per basic step with contact off
and on, and the contact counters. ``--body box``: the robots' bodies are 7 x 5 cm boxes (shaped
footprints: turns checked, obstacles grown by the turned rectangle) instead of e-puck cylinders."""

from __future__ import annotations

import argparse
import math
import random
import time

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

BODIES = {"cylinder": {"type": "cylinder", "radius": 0.035, "height": 0.05},
          "box": {"type": "box", "size": [0.07, 0.05, 0.05]}}


def world(contact: bool, robots: int = 24, solids: int = 100, seed: int = 1, body: str = "cylinder") -> dict:
    rng = random.Random(seed)
    shapes = [{"type": "box", "size": [0.2, 0.2, 0.3]}, {"type": "cylinder", "radius": 0.1, "height": 0.3},
              {"type": "sphere", "radius": 0.1}]
    out = [{"name": "floor", "geometry": {"type": "plane", "size": None}}]
    for i in range(solids):
        out.append({"name": f"s{i}", "geometry": shapes[i % 3],
                    "pose": {"translation": [rng.uniform(-5, 5), rng.uniform(-5, 5), 0.15],
                             "rotation": [0, 0, 1, rng.uniform(0, 3)]}})
    bots = [{"name": f"r{i}", "pose": {"translation": [rng.uniform(-5, 5), rng.uniform(-5, 5), 0.025],
                                       "rotation": [0, 0, 1, rng.uniform(0, 6)]},
             "body": {"geometry": BODIES[body]},
             "differential_drive": {}} for i in range(robots)]
    return {"world_info": {"basic_time_step": 32, "contact": contact}, "solids": out, "robots": bots}


def measure(contact: bool, steps: int, body: str = "cylinder") -> tuple[float, dict]:
    sim = Simulation(parse_world(world(contact, body=body)))
    for r in sim.robots.values():
        for k, m in enumerate(r.motors.values()):
            m.set_position(math.inf)
            m.set_velocity(6.0 if k == 0 else 5.0)          # gentle curves: many robots meet obstacles
    sim.run(20)
    t = time.perf_counter()
    sim.run(steps)
    return (time.perf_counter() - t) / steps * 1e3, sim.counters


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.contact", description=__doc__)
    p.add_argument("--steps", type=int, default=500)
    p.add_argument("--body", choices=sorted(BODIES), default="cylinder")
    args = p.parse_args(argv)
    for contact in (False, True):
        ms, c = measure(contact, args.steps, args.body)
        print(f"contact {'on ' if contact else 'off'}: {ms:.3f} ms/step  contacts={c['contacts']} "
              f"narrow-phase checks={c['contact_checks']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
