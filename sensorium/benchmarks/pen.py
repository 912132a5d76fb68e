"""Cost of the Pen: ``python -m sensorium.benchmarks.pen [--rounds N] [--steps N]``.

A robot driving a circle on the pen_drawing world's paper (a 2 m textured floor: a 512² paint
texture) with one infra-red sensor enabled, and 0, 1 or 10 pens writing (1 with the world's ink
evaporating at 0.1/s); interleaved rounds of ``steps`` basic steps, the fastest round of each case
(a busy machine slows rounds down, never speeds them up). Prints µs per basic step."""

from __future__ import annotations

import argparse
import math
import time

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from sensorium.worlds import pen_drawing


def world(pens: int, evaporation: float = 0.0) -> Simulation:
    devs = [{"device": "Pen", "name": f"p{i}", "lead_size": 0.015, "write": True,
             "pose": {"translation": [0.5 * math.cos(i), 0.5 * math.sin(i), 0.005]}} for i in range(pens)]
    devs.append({"device": "DistanceSensor", "name": "g", "type": "infra-red", "lookup_table": [[0, 1000, 0], [0.05, 0, 0]],
                 "pose": {"translation": [0.0, 0.0, 0.01], "rotation": [0, 1, 0, math.pi / 2]}})
    data = {"world_info": {"ink_evaporation": evaporation},
            "solids": [{"name": "floor", "geometry": {"type": "plane", "size": [2.0, 2.0]},
                        "appearance": {"texture": "textures/paper.png"}}],
            "robots": [{"name": "r", "devices": devs,
                        "differential_drive": {"wheel_radius": 0.0205, "axle_length": 0.052}}]}
    sim = Simulation(parse_world(data, base_dir=pen_drawing.HERE))
    for m in sim.robot("r").motors.values():      # a circle: each stroke lands somewhere new
        m.set_position(math.inf)
        m.set_velocity(3.0 if m.name.startswith("left") else 4.0)
    sim.device("r/g").enable(32)
    sim.step()
    return sim


def per_step(sim: Simulation, steps: int) -> float:
    t = time.perf_counter()
    sim.run(steps)
    return (time.perf_counter() - t) / steps


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.pen", description=__doc__)
    p.add_argument("--rounds", type=int, default=15)
    p.add_argument("--steps", type=int, default=100)
    args = p.parse_args(argv)
    cases = {"no pen": world(0), "1 pen": world(1), "10 pens": world(10), "1 pen, evaporating": world(1, 0.1)}
    best = dict.fromkeys(cases, math.inf)
    for _ in range(args.rounds):
        for name, sim in cases.items():
            best[name] = min(best[name], per_step(sim, args.steps))
    for name, t in best.items():
        print(f"{name}: {t * 1e6:.0f} us/step")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
