"""What one Supervisor set of a Pose's translation inside a top-level solid costs (the solid is built again
with the Pose's new frame: sim/regenerate.py ``rebuild_posed``), against the solid's triangle count: a solid
holding a Pose of an IndexedFaceSet grid of N triangles next to a Box, the median over a run of sets (each
followed by one step, a lidar reading it), and for scale the cost of one step alone and of a set of the
solid's own translation (a mover: no rebuild). Sizes interleaved round by round in one process.

    python docs/bench/solid_pose_set_cost.py [rounds]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world


def grid(triangles: int) -> str:
    n = max(1, round((triangles / 2) ** 0.5))
    pts = " ".join(f"{i / n - 0.5} {j / n - 0.5} 0" for i in range(n + 1) for j in range(n + 1))
    faces = " ".join(f"{i * (n + 1) + j} {i * (n + 1) + j + 1} {(i + 1) * (n + 1) + j + 1} -1 "
                     f"{i * (n + 1) + j} {(i + 1) * (n + 1) + j + 1} {(i + 1) * (n + 1) + j} -1"
                     for i in range(n) for j in range(n))
    return f"IndexedFaceSet {{ coord Coordinate {{ point [ {pts} ] }} coordIndex [ {faces} ] }}"


def world(triangles: int) -> str:
    return f"""#VRML_SIM R2023b utf8
WorldInfo {{ basicTimeStep 8 }}
Robot {{ name "probe" supervisor TRUE controller "<extern>" children [
  Lidar {{ name "lidar" horizontalResolution 64 fieldOfView 1 numberOfLayers 1 maxRange 10 }} ] }}
DEF TABLE Solid {{ translation 2 0 0 name "table" children [
  Shape {{ geometry Box {{ size 0.2 0.2 0.2 }} }}
  DEF TOP Pose {{ translation 0 0 0.5 rotation 0 1 0 1.5707963267948966 children [ Shape {{ geometry {grid(triangles)} }} ] }}
] }}
"""


def main(rounds: int) -> None:
    sizes = (1_000, 10_000, 40_000)
    tmp = Path(tempfile.mkdtemp())
    sims = {}
    for size in sizes:
        path = tmp / f"w{size}.wbt"
        path.write_text(world(size))
        sim = Simulation(load_world(path))
        sim.robot("probe").device("lidar").enable(8)
        sims[size] = (sim, sv.find_node(sim, "TOP"), sv.find_node(sim, "TABLE"), sim.scene.solid_triangles("table"))
    times = {size: {"pose set + step": [], "solid set + step": [], "step": []} for size in sizes}
    for r in range(rounds):
        for size in sizes:
            sim, node, table, _ = sims[size]
            t0 = time.perf_counter()
            sv.set_field(sim, node, "translation", [0.0, 0.01 * (r % 7), 0.5])
            sim.step()
            t1 = time.perf_counter()
            sv.set_field(sim, table, "translation", [2.0, 0.01 * (r % 5), 0.0])
            sim.step()
            t2 = time.perf_counter()
            sim.step()
            t3 = time.perf_counter()
            times[size]["pose set + step"].append(t1 - t0)
            times[size]["solid set + step"].append(t2 - t1)
            times[size]["step"].append(t3 - t2)
    for size in sizes:
        row = {k: f"{statistics.median(v) * 1e3:.2f} ms" for k, v in times[size].items()}
        print(f"{sims[size][3]:>6} triangles: {row}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20)
