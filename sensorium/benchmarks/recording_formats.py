"""Recording formats compared: ``python -m sensorium.benchmarks.recording_formats [STEPS]``.

Steps the demo's arena world in-process with every topic demanded and records it twice, as format 1
(msgpack channels only) and as format 2 (Foxglove-ready: lossless wire channels + CDR views + /tf +
/scene), timing only the recorder calls (the step loop's extra cost) and reporting the file sizes.
Not part of ``sensorium bench``; the numbers are quoted in README "See it in Foxglove".
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from sensorium.server.daemon.topics import Topics
from sensorium.server.recording.writer import McapRecorder
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import default_world_path


def measure(steps: int, foxglove: bool, out: Path) -> dict:
    sim = Simulation.from_file(default_world_path(), precision="exact")
    topics = Topics(sim)
    rec = McapRecorder(out, b"", "world.yaml", {}, None, foxglove=foxglove, world=sim.world,
                       base_dir=sim.loaded.base_dir)
    spent = [0.0]

    def timed(*args):
        t0 = time.perf_counter()
        rec.record(*args)
        spent[0] += time.perf_counter() - t0

    topics.set_recorder(timed)
    t_loop = time.perf_counter()
    for _ in range(steps):
        sim.step()
        topics.publish(sim.time_ms)
    loop_s = time.perf_counter() - t_loop
    t0 = time.perf_counter()
    rec.close()
    close_s = time.perf_counter() - t0
    return {"format": "2 (foxglove)" if foxglove else "1 (msgpack)", "messages": rec.message_count,
            "bytes": out.stat().st_size, "record_s": spent[0], "close_s": close_s,
            "loop_s": loop_s}


def main(argv: list[str] | None = None) -> int:
    steps = int((argv or sys.argv[1:] or ["625"])[0])
    with tempfile.TemporaryDirectory() as d:
        rows = [measure(steps, fg, Path(d) / f"f{int(fg)}.mcap") for fg in (False, True)]
    print(f"{steps} steps of the arena world ({steps * 32 / 1000:g} s simulated), every topic recorded")
    print(f"{'format':14} {'messages':>9} {'file size':>12} {'recorder time':>14} {'per step':>10} {'share of loop':>14}")
    for r in rows:
        print(f"{r['format']:14} {r['messages']:9d} {r['bytes'] / 1e6:10.2f} MB {r['record_s']:12.2f} s "
              f"{r['record_s'] / steps * 1e3:7.2f} ms {100 * r['record_s'] / r['loop_s']:12.0f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
