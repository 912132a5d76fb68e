"""What a step costs after a Supervisor's Pose set inside a solid when the world holds many other static
shapes: the set moves only shapes (sim/regenerate.py ``move_posed``), but the world-frame static tier holding
them is built again at the next cast (its Embree scenes and, under EXACT, its edge guards), so the step's cost
grows with the static geometry. The world: pose_marker_sets.py's probe and marker solid, plus N small boxes
(12 triangles each) in a 50-column grid beside it. Prints the median step after one set, and a step alone.
Compare two trees by running this in each, alternating (ratios in one interleaved run).

    python docs/bench/static_tier_rebuild.py [boxes ...]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pose_marker_sets  # noqa: E402

from sensorium.server.daemon import supervisor as sv  # noqa: E402
from sensorium.server.sim.simulation import Simulation  # noqa: E402
from sensorium.server.world.loader import load_world  # noqa: E402


def world(boxes: int) -> str:
    grid = "\n".join(f'Solid {{ translation {3 + (i % 50) * 0.3} {(i // 50) * 0.3} 0 name "w{i}" children [ '
                     "Shape { geometry Box { size 0.1 0.1 0.1 } } ] }" for i in range(boxes))
    return pose_marker_sets.world() + grid


def main(counts: list[int], rounds: int = 9) -> None:
    for boxes in counts:
        path = Path(tempfile.mkdtemp()) / "boxes.wbt"
        path.write_text(world(boxes))
        sim = Simulation(load_world(path))
        sim.robot("probe").device("lidar").enable(8)
        sim.step()
        marker = sv.find_node(sim, "M0")
        after, alone = [], []
        for r in range(rounds):
            sv.set_field(sim, marker, "translation", [0.0, 0.05 * (r % 7 + 1), 0.0])
            t0 = time.perf_counter()
            sim.step()
            t1 = time.perf_counter()
            sim.step()
            alone.append(time.perf_counter() - t1)
            after.append(t1 - t0)
        print(f"{boxes} boxes ({12 * boxes} triangles): step after a set {statistics.median(after) * 1e3:.1f} ms, "
              f"a step alone {statistics.median(alone) * 1e3:.2f} ms")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [100, 500, 1500])
