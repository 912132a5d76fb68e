"""Cost of Emitter/Receiver traffic (``sensorium bench --only radio``, or ``python -m
sensorium.benchmarks.radio``): R robots in a ring, each with an emitter and a receiver, every robot
sending one 16-byte packet per basic step that every other robot hears (R·(R−1) deliveries per
step), radio (range and direction only) and infra-red (cones off, a line-of-sight ray per packet),
against the same world with no packet sent. Interleaved rounds: load on this shared machine hits
every variant alike; the extra time per delivered packet is the difference over R·(R−1)."""

from __future__ import annotations

import argparse
import math

from sensorium.benchmarks.common import Config, Section, Table, interleaved, median
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world


def world(robots: int, medium: str) -> dict:
    bots = []
    for i in range(robots):
        a = 2 * math.pi * i / robots
        bots.append({"name": f"r{i}", "pose": {"translation": [3 * math.cos(a), 3 * math.sin(a), 0.05]},
                     "body": {"geometry": {"type": "cylinder", "radius": 0.05, "height": 0.08}},
                     "devices": [{"device": "Emitter", "name": "tx", "type": medium},
                                 {"device": "Receiver", "name": "rx", "type": medium}]})
    return {"world_info": {"basic_time_step": 16}, "solids": [{"name": "floor", "geometry": {"type": "plane"}}],
            "robots": bots}


def stepper(robots: int, medium: str, send: bool):
    sim = Simulation(parse_world(world(robots, medium)))
    emitters = [r.devices["tx"] for r in sim.robots.values()]
    receivers = [r.devices["rx"] for r in sim.robots.values()]
    for rx in receivers:
        rx.enable(16)
    packet = bytes(16)

    def step() -> None:
        if send:
            for tx in emitters:
                tx.send(packet)
        sim.step()
        for rx in receivers:
            rx.take()
    return sim, step


def measure(robots: int, rounds: int) -> dict[str, float]:
    """Median ms per step of each variant (interleaved)."""
    sims, fns = {}, {}
    for name, medium, send in (("quiet", "radio", False), ("radio", "radio", True), ("infra-red", "infra-red", True)):
        sims[name], fns[name] = stepper(robots, medium, send)
    times = interleaved(fns, rounds, per_round=5, warmup=3)
    delivered = sims["radio"].counters["radio_packets"]
    assert delivered and sims["infra-red"].counters["radio_packets"] == delivered       # nothing blocked
    return {k: median(v) * 1e3 for k, v in times.items()}


def run(cfg: Config) -> Section:
    rounds = cfg.pick(40, 8)
    rows = []
    for robots in cfg.pick((5, 10, 20), (5, 10)):
        ms = measure(robots, rounds)
        pairs = robots * (robots - 1)
        rows.append([robots, pairs, f"{ms['quiet']:.3f}", f"{ms['radio']:.3f}", f"{ms['infra-red']:.3f}",
                     f"{(ms['radio'] - ms['quiet']) / pairs * 1e3:.1f}",
                     f"{(ms['infra-red'] - ms['quiet']) / pairs * 1e3:.1f}"])
        cfg.log(f"  radio: {robots} robots {ms}")
    table = Table("radio", "Emitter/Receiver: ms per basic step, µs per delivered packet",
                  ["robots", "packets/step", "no packet (ms)", "radio (ms)", "infra-red (ms)",
                   "radio µs/packet", "infra-red µs/packet"], rows,
                  notes=["each robot sends 16 bytes per step that every other robot hears; the infra-red "
                         "column adds one line-of-sight ray per packet (no obstacle in the ring)"])
    return Section("radio", "Emitter and Receiver", intro=__doc__.split("\n\n")[0].replace("``", "`"), tables=[table],
                   data={"rows": rows})


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.radio", description=__doc__)
    p.add_argument("--quick", action="store_true")
    args = p.parse_args(argv)
    sec = run(Config(quick=args.quick))
    t = sec.tables[0]
    print(" | ".join(t.columns))
    for row in t.rows:
        print(" | ".join(str(v) for v in row))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
