"""What texture alpha costs a world without it: camera images of the same scenes rendered by two
source trees (a checkout before the change and this one), in interleaved rounds of subprocesses,
the fastest round of each. Neither scene has an alpha texture nor a semi-transparent material, so
both trees must take the same path and make the same bytes (checked: each round's image digest).

    python docs/bench/camera_alpha_cost.py BASELINE_TREE THIS_TREE [rounds]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

CHILD = r'''
import hashlib, json, math, sys, tempfile, time
from pathlib import Path
import numpy as np
from PIL import Image
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

scene, steps = sys.argv[1], int(sys.argv[2])
d = Path(tempfile.mkdtemp())
Image.fromarray(np.random.default_rng(7).integers(0, 256, (64, 64, 3), dtype=np.uint8), "RGB").save(d / "rgb.png")
floor = {"name": "floor", "geometry": {"type": "plane", "size": [6, 6]},
         "appearance": {"base_color": [1, 1, 1], "texture": {"url": "rgb.png"}}}
walls = [{"name": f"w{i}", "pose": {"translation": [2.5 * math.cos(i), 2.5 * math.sin(i), 0.25]},
          "geometry": {"type": "box", "size": [0.2, 1.5, 0.5]}, "appearance": {"base_color": [0.2 + 0.1 * i, 0.5, 0.3]}}
         for i in range(6)]
lights = [{"type": "PointLight", "location": [0, 0, 2], "intensity": 1.5, "cast_shadows": True},
          {"type": "DirectionalLight", "direction": [0.3, 0.2, -1], "intensity": 0.5, "ambient_intensity": 0.2}]
w, h = (320, 240) if scene == "big" else (52, 39)
cam = {"device": "Camera", "name": "cam", "pose": {"translation": [0, 0, 0.3], "rotation": [0, 1, 0, 0.3]},
       "width": w, "height": h, "field_of_view": 1.0}
world = {"world_info": {"basic_time_step": 16}, "solids": [floor, *walls], "lights": lights,
         "robots": [{"name": "r", "pose": {"translation": [-1, 0, 0]}, "devices": [cam]}]}
sim = Simulation(parse_world(world, base_dir=d), precision="fast")
dev = sim.device("r/cam")
dev.enable(16)
sim.run(3)
t0, c0 = time.perf_counter(), time.process_time()
sim.run(steps)
dt, dc = (time.perf_counter() - t0) / steps, (time.process_time() - c0) / steps
print(json.dumps({"s": dt, "cpu": dc, "digest": hashlib.sha256(dev.image.tobytes()).hexdigest()}))
'''


def run(tree: str, scene: str, steps: int) -> dict:
    env = {**os.environ, "PYTHONPATH": tree}
    out = subprocess.run([sys.executable, "-c", CHILD, scene, str(steps)], env=env, cwd=tempfile.gettempdir(),
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    base, new = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    for scene, steps in (("small", 200), ("big", 10)):
        best = {(tree, k): float("inf") for tree in (base, new) for k in ("s", "cpu")}
        digests: dict[str, set] = {base: set(), new: set()}
        for r in range(rounds):
            for tree in ((base, new) if r % 2 == 0 else (new, base)):       # interleaved, alternating first
                got = run(tree, scene, steps)
                for k in ("s", "cpu"):
                    best[tree, k] = min(best[tree, k], got[k])
                digests[tree].add(got["digest"])
        same = digests[base] == digests[new] and len(digests[new]) == 1
        for k, what in (("s", "wall"), ("cpu", "CPU")):
            print(f"{scene} ({what}): baseline {best[base, k] * 1e3:.3f} ms/step, this tree {best[new, k] * 1e3:.3f} "
                  f"ms/step, ratio {best[new, k] / best[base, k]:.3f}, same image bytes: {same}")


if __name__ == "__main__":
    main()
