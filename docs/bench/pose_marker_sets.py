"""What a Supervisor's sets of marker Poses inside a top-level solid cost when they only move shapes (placed anew:
sim/regenerate.py ``move_posed``) against building the solid again for each (``rebuild_pose_sets``, the path
every other Pose set takes): a solid holding 25 marker Poses (a small box each), each one's translation set once
per step (as Webots' radar_target_tracker moves its 25 markers), then a step with a 64-beam lidar reading them;
both simulations interleaved round by round in one process, their lidar images compared bit for bit. Also the
cost of one step alone.

    python docs/bench/pose_marker_sets.py [rounds]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

MARKERS = 25


def world() -> str:
    markers = "\n".join(f"  DEF M{i} Pose {{ translation {0.1 * i} 0 0 children [ Shape {{ geometry Box {{ size 0.05 "
                        f"0.05 0.05 }} }} ] }}" for i in range(MARKERS))
    return f"""#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 8 }}
Robot {{ name "probe" supervisor TRUE controller "<extern>" children [
  Lidar {{ name "lidar" horizontalResolution 64 fieldOfView 1.2 numberOfLayers 1 maxRange 10 }} ] }}
DEF MARKS Solid {{ translation 1 -1.2 0 name "marks" children [
{markers}
] }}
"""


def main(rounds: int) -> None:
    path = Path(tempfile.mkdtemp()) / "markers.wbt"
    path.write_text(world())
    sims = {}
    for name, rebuild in (("placed anew", False), ("built again", True)):
        sim = Simulation(load_world(path))
        sim.rebuild_pose_sets = rebuild
        sim.robot("probe").device("lidar").enable(8)
        sims[name] = (sim, [sv.find_node(sim, f"M{i}") for i in range(MARKERS)])
    times: dict[str, dict[str, list[float]]] = {name: {"25 sets + step": [], "step": []} for name in sims}
    for r in range(rounds):
        images = []
        for name in (list(sims) if r % 2 == 0 else list(sims)[::-1]):
            sim, nodes = sims[name]
            t0 = time.perf_counter()
            for i, node in enumerate(nodes):
                sv.set_field(sim, node, "translation", [0.1 * i, 0.05 * ((r + i) % 7), 0.0])
            sim.step()
            t1 = time.perf_counter()
            sim.step()
            t2 = time.perf_counter()
            times[name]["25 sets + step"].append(t1 - t0)
            times[name]["step"].append(t2 - t1)
            images.append(np.asarray(sim.robot("probe").device("lidar").range_image).tobytes())
        assert images[0] == images[1], "the two paths read differently"
    for name in sims:
        print(f"{name}: " + ", ".join(f"{k} {statistics.median(v) * 1e3:.2f} ms" for k, v in times[name].items()))
    fast, slow = (statistics.median(times[name]["25 sets + step"]) for name in sims)
    print(f"built again / placed anew: {slow / fast:.1f}x")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 40)
