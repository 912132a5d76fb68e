"""A Supervisor that changes the world for days: what each change leaves behind.

``python -m sensorium.benchmarks.churn [--cycles N] [--only import,regen,colour] [--no-trace]``

Three loops an RL Supervisor runs between episodes, each ``N`` cycles in one process (the Supervisor's
own calls of daemon/supervisor.py on an in-process ``Simulation``, no sockets), on a generated world: a
supervisor robot with a camera (recognition on), a range finder, a lidar and two distance sensors looking
at a PROTO obstacle (a PROTO of this module's own, no template) and a painted box:

* ``import``: import a small solid (a box, its recognition colour) in front of the sensors, read its Shape's
  geometry through its ``children`` (the nodes inside it served), step, remove it;
* ``regen``:  set the obstacle's ``size`` (its solid built again, sim/regenerate.py), step;
* ``colour``: set the painted box's ``baseColor``, step.

For each loop: resident memory and Python's traced memory (tracemalloc) per cycle between cycle 100 and
the last; the CPU time of a step (every device due) at cycle 100 and at the last, beside a world loaded
fresh with the same content; the CPU time of a Supervisor look-up (``getFromDef`` of the robot) at both;
the scene's shape count and the engine's bodies at the end. The readings after the last cycle are compared
with those of the fresh world (they must be equal, bit for bit).
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path
from typing import Any

import numpy as np

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

PROTO = """#VRML_SIM R2023b utf8
# Sensorium's churn benchmark: a box obstacle whose size a Supervisor sets (no template)
PROTO Crate [
  field SFVec3f    translation 0 0 0
  field SFRotation rotation    0 0 1 0
  field SFString   name        "crate"
  field SFVec3f    size        0.2 0.2 0.2
]
{
  Solid {
    translation IS translation
    rotation IS rotation
    name IS name
    recognitionColors [ 1 0 0 ]
    children [ Shape { geometry Box { size IS size } } ]
    boundingObject Box { size IS size }
  }
}
"""

WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Crate.proto"
WorldInfo {{
  basicTimeStep 16
}}
Viewpoint {{
}}
DirectionalLight {{
  direction 1 0.2 -1
}}
DEF CRATE Crate {{
  translation 1.5 0.6 0
  size {size}
}}
DEF PAINTED Solid {{
  translation 2 -0.6 0
  name "painted"
  children [ Shape {{ appearance DEF PAINT PBRAppearance {{ baseColor {colour} metalness 0 }}
                     geometry Box {{ size 0.3 0.3 0.3 }} }} ]
  boundingObject Box {{ size 0.3 0.3 0.3 }}
}}
{extra}
DEF EYE Robot {{
  name "eye"
  supervisor TRUE
  controller "<extern>"
  children [
    Camera {{ translation 0.1 0 0 name "cam" width 16 height 12 fieldOfView 1.2 recognition Recognition {{ }} }}
    RangeFinder {{ translation 0.1 0 0 name "depth" width 16 height 12 fieldOfView 1.2 maxRange 5 }}
    Lidar {{ translation 0.1 0 0 name "lidar" horizontalResolution 64 fieldOfView 1.5 numberOfLayers 1 maxRange 5 }}
    DistanceSensor {{ translation 0.1 0 0 name "ds" lookupTable [ 0 0 0 4 4000 0 ] }}
    DistanceSensor {{ translation 0.1 0 0 name "ir" type "infra-red" lookupTable [ 0 0 0 4 4000 0 ] }}
  ]
}}
"""

BALL = ('DEF BALL Solid {{ translation {x} 0 0 name "ball" recognitionColors [ 0 1 0 ] '
        'children [ Shape {{ geometry Box {{ size 0.2 0.4 0.3 }} }} ] boundingObject Box {{ size 0.2 0.4 0.3 }} }}')
DEVICES = ("cam", "depth", "lidar", "ds", "ir")


def world_file(folder: Path, size: str = "0.2 0.2 0.2", colour: str = "0.5 0.5 0.5", extra: str = "") -> Path:
    """The benchmark's world written in ``folder`` with those values (and ``extra`` top-level nodes)."""
    (folder / "Crate.proto").write_text(PROTO)
    path = folder / f"churn{len(list(folder.glob('churn*.wbt')))}.wbt"
    path.write_text(WORLD.format(size=size, colour=colour, extra=extra))
    return path


def simulation(path: Path) -> Simulation:
    sim = Simulation(load_world(path))
    for name in DEVICES:
        sim.device(f"eye/{name}").enable(16)
    sim.device("eye/cam").recognition_enable(16)
    return sim


def readings(sim: Simulation) -> dict[str, Any]:
    """Every device's reading after one step."""
    sim.step()
    dev = sim.device
    return {"cam": dev("eye/cam").image.copy(), "depth": np.array(dev("eye/depth").range_image),
            "lidar": np.array(dev("eye/lidar").range_image), "ds": float(dev("eye/ds").value),
            "ir": float(dev("eye/ir").value), "objects": [(o.position, o.size, o.colors) for o in dev("eye/cam").objects]}


def same(a: dict, b: dict) -> bool:
    return all(np.array_equal(a[k], b[k]) for k in DEVICES) and repr(a["objects"]) == repr(b["objects"])


def _rss() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def _step_cpu(sim: Simulation, steps: int = 40) -> float:
    """The median CPU time of a step (every device due each step)."""
    times = []
    for _ in range(steps):
        t = time.process_time()
        sim.step()
        times.append(time.process_time() - t)
    return float(np.median(times))


def _lookup_cpu(sim: Simulation, calls: int = 20) -> float:
    times = []
    for _ in range(calls):
        t = time.process_time()
        sv.find_node(sim, "EYE")
        times.append(time.process_time() - t)
    return float(np.median(times))


class Loop:
    """One of the three loops on its own world (``cycle`` does one change and one step)."""

    def __init__(self, kind: str, folder: Path):
        self.kind = kind
        self.folder = folder
        self.sim = simulation(world_file(folder))
        self.k = 0
        self.ball: int | None = None

    def cycle(self) -> None:
        sim, k = self.sim, self.k
        self.k += 1
        if self.kind == "import":
            (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, BALL.format(x=1.0 + 0.001 * (k % 500)))
            shape = sv.get_field(sim, sv.node_by_id(sim, node), "children")["value"]     # its inner nodes served
            if shape:
                sv.get_field(sim, sv.node_by_id(sim, sv.get_field(sim, sv.node_by_id(sim, shape[0]), "geometry")["value"]),
                             "size")
            sim.step()
            sv.remove_node(sim, sv.node_by_id(sim, node))
        elif self.kind == "regen":
            sv.set_field(sim, sv.find_node(sim, "CRATE"), "size", self.size(k))
            sim.step()
        else:
            sv.set_field(sim, sv.find_node(sim, "PAINT"), "baseColor", self.colour(k))
            sim.step()

    @staticmethod
    def size(k: int) -> list[float]:
        return [0.1 + 0.001 * (k % 300), 0.2 + 0.0005 * (k % 200), 0.3]

    @staticmethod
    def colour(k: int) -> list[float]:
        return [(k % 97) / 97.0, (k % 89) / 89.0, 0.25]

    def fresh(self) -> Simulation:
        """A world loaded with the content this one has now (the last cycle's values)."""
        k = self.k - 1
        if self.kind == "regen":
            return simulation(world_file(self.folder, size=" ".join(map(repr, self.size(k)))))
        if self.kind == "colour":
            return simulation(world_file(self.folder, colour=" ".join(map(repr, self.colour(k)))))
        return simulation(world_file(self.folder))


def run(kind: str, cycles: int, trace: bool, out=sys.stdout) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        loop = Loop(kind, Path(tmp))
        mark = min(100, cycles)
        for _ in range(mark):
            loop.cycle()
        gc.collect()
        if trace:
            tracemalloc.start()
        rss0, traced0 = _rss(), tracemalloc.get_traced_memory()[0] if trace else 0
        step0, look0 = _step_cpu(loop.sim), _lookup_cpu(loop.sim)
        wall = time.perf_counter()
        for _ in range(cycles - mark):
            loop.cycle()
        wall = time.perf_counter() - wall
        gc.collect()
        rss1, traced1 = _rss(), tracemalloc.get_traced_memory()[0] if trace else 0
        if trace:
            tracemalloc.stop()
        step1, look1 = _step_cpu(loop.sim), _lookup_cpu(loop.sim)
        fresh = loop.fresh()
        step_fresh = _step_cpu(fresh)
        equal = same(readings(loop.sim), readings(fresh))
        n = max(cycles - mark, 1)
        row = {"loop": kind, "cycles": cycles, "rss_per_cycle": (rss1 - rss0) / n,
               "traced_per_cycle": (traced1 - traced0) / n if trace else float("nan"),
               "cycle_ms": wall / n * 1e3, "step_ms_100": step0 * 1e3, "step_ms_last": step1 * 1e3,
               "step_ms_fresh": step_fresh * 1e3, "lookup_ms_100": look0 * 1e3, "lookup_ms_last": look1 * 1e3,
               "shapes": len(loop.sim.scene.shapes), "bodies": len(loop.sim.scene.engine._bodies),
               "fresh_shapes": len(fresh.scene.shapes), "equal": equal}
        print(" | ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()),
              file=out, flush=True)
        return row


def table(rows: list[dict[str, Any]]) -> str:
    head = ("| loop | cycles | RSS / cycle | traced / cycle | cycle | step at 100 | step at last | step, fresh world "
            "| getFromDef at 100 | at last | shapes (fresh) | readings = fresh |\n|---|---|---|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        lines.append(f"| {r['loop']} | {r['cycles']:,} | {r['rss_per_cycle']:.0f} B | {r['traced_per_cycle']:.0f} B "
                     f"| {r['cycle_ms']:.2f} ms | {r['step_ms_100']:.3f} ms | {r['step_ms_last']:.3f} ms "
                     f"| {r['step_ms_fresh']:.3f} ms | {r['lookup_ms_100']:.3f} ms | {r['lookup_ms_last']:.3f} ms "
                     f"| {r['shapes']} ({r['fresh_shapes']}) | {'yes' if r['equal'] else 'NO'} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.churn", description=__doc__.split("\n")[0])
    parser.add_argument("--cycles", type=int, default=10_000, help="cycles per loop (default 10,000)")
    parser.add_argument("--only", default="import,regen,colour", help="loops, comma-separated")
    parser.add_argument("--no-trace", action="store_true", help="without tracemalloc (it slows the loops)")
    args = parser.parse_args(argv)
    kinds = [k for k in args.only.split(",") if k]
    bad = [k for k in kinds if k not in ("import", "regen", "colour")]
    if bad or args.cycles < 1:
        print(f"churn: {'unknown loop ' + repr(bad[0]) if bad else '--cycles must be at least 1'} "
              "(loops: import, regen, colour)", file=sys.stderr)
        return 2
    rows = [run(kind, args.cycles, not args.no_trace) for kind in kinds]
    print(table(rows))
    return 0 if all(r["equal"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
