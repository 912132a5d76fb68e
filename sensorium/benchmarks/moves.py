"""What a Supervisor's moves and balance questions cost among many solids: an RL reset putting solids back.

``python -m sensorium.benchmarks.moves [--solids 10,50] [--rounds 5] [--compare TREE]``

A generated world: a floor plane, a table (a 1 m box, 0.8 m tall), a drum (an upright cylinder), a two-wheel
robot with physics and ``N`` boxes with physics in a grid beside them. In process (the Supervisor's own calls, no sockets), the median CPU time of:

* ``move``: ``Simulation.set_solid_pose`` putting one box 1.7 m up over the table, then back on the floor (it
  falls: what it lands on is judged at once, on the ground the other solids make, ``Simulation.landing_ground``);
* ``balance``: ``getStaticBalance`` of a box on the floor (sim/balance.py: its contacts on that same ground);
* ``landing ground``: ``Simulation.landing_ground`` alone;
* ``robot move``: a box put back where it was (no fall), then a two-wheel robot with physics put 0.5 m over the
  table (it settles at once on the ground as the world is then, ``Simulation.settled``): the robot's move timed.

Each measurement runs in a fresh interpreter with one source tree on its path; ``--compare TREE`` measures
another tree (say a checkout of the base) too, the two trees' children interleaved round by round, and
prints each tree's medians over the rounds and this tree's ratio to the other's.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

_CHILD = r"""
import json, sys, time
import numpy as np
from sensorium.server.sim import balance
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

sim = Simulation(load_world(sys.argv[1]))
reps = int(sys.argv[2])

def cpu(call):
    times = []
    for k in range(reps):
        t = time.process_time()
        call(k)
        times.append(time.process_time() - t)
    return float(np.median(times)) * 1e3

out = {}
out["move"] = cpu(lambda k: sim.set_solid_pose("b0", [0.1 * (k % 3), 0.0, 1.7] if k % 2 == 0 else [1.5, 0.0, 0.05]))
out["balance"] = cpu(lambda k: balance.solid_balance(sim, "b1", None))
out["landing ground"] = cpu(lambda k: sim.landing_ground("b1"))
robot = sim.robot("bot")

def timed_robot_move():
    times = []
    for k in range(reps):
        sim.set_solid_pose("b1", [1.8, 0.0, 0.05 + 1e-6 * (k % 2)])     # a solid moved: the settling ground is stale
        t = time.process_time()
        robot.set_pose([0.1 * (k % 3), 0.2, 1.3])
        times.append(time.process_time() - t)
    return float(np.median(times)) * 1e3

out["robot move"] = timed_robot_move()
print(json.dumps(out))
"""


def world_text(solids: int) -> str:
    """The benchmark's world with ``solids`` boxes with physics (10 a row, 0.3 m apart)."""
    text = ("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
            'Solid { name "floor" boundingObject Plane { size 40 40 } }\n'
            'Solid { translation 0 0 0.4 name "table" boundingObject Box { size 1 1 0.8 } }\n'
            'Solid { translation 0 -2 0.25 name "drum" boundingObject Cylinder { radius 0.3 height 0.5 } }\n')
    wheels = "".join(
        f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.03 }} '
        f'device [ RotationalMotor {{ name "{side} wheel motor" maxVelocity 10 }} ] '
        f'endPoint Solid {{ translation 0 {y} 0.03 rotation 1 0 0 1.5707963267948966 name "{side} wheel" '
        'boundingObject Cylinder { radius 0.025 height 0.01 } physics Physics { } } }\n'
        for side, y in (("left", 0.05), ("right", -0.05)))
    text += f'Robot {{ translation 0 -4 0 name "bot" controller "<extern>" children [\n{wheels}] physics Physics {{ }} }}\n'
    for i in range(solids):
        text += (f'Solid {{ translation {1.5 + (i % 10) * 0.3} {(i // 10) * 0.3} 0.05 name "b{i}" '
                 'boundingObject Box { size 0.1 0.1 0.1 } physics Physics { } }\n')
    return text


def child(world: Path, tree: str, reps: int) -> dict[str, float]:
    """One measurement in a fresh interpreter with ``tree`` first on its path (``-P``: not the working directory)."""
    env = dict(os.environ, PYTHONPATH=tree)
    out = subprocess.run([sys.executable, "-P", "-c", _CHILD, str(world), str(reps)], capture_output=True, text=True,
                         timeout=1800, check=False, env=env)
    if out.returncode != 0:
        raise RuntimeError(f"moves child failed with {tree}: {out.stderr.strip().splitlines()[-3:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.moves", description=__doc__.split("\n")[0])
    parser.add_argument("--solids", default="10,50", help="box counts, comma-separated (default 10,50)")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds (default 5)")
    parser.add_argument("--reps", type=int, default=200, help="calls per measurement (default 200)")
    parser.add_argument("--compare", metavar="TREE", help="also measure another source tree, interleaved with this one")
    args = parser.parse_args(argv)
    try:
        counts = [int(n) for n in args.solids.split(",") if n]
    except ValueError:
        counts = []
    if not counts or min(counts) < 2 or args.rounds < 1 or args.reps < 1:
        print("moves: --solids must list counts of at least 2; --rounds and --reps at least 1", file=sys.stderr)
        return 2
    here = str(Path(__file__).resolve().parents[2])
    trees = {"this": here} if not args.compare else {args.compare: str(Path(args.compare).resolve()), "this": here}
    with tempfile.TemporaryDirectory() as tmp:
        samples: dict[tuple[str, int], list[dict[str, float]]] = {}
        for n in counts:
            world = Path(tmp) / f"moves{n}.wbt"
            world.write_text(world_text(n))
            for _ in range(args.rounds):
                for name, tree in trees.items():
                    samples.setdefault((name, n), []).append(child(world, tree, args.reps))
    print("| tree | solids | " + " | ".join(f"{k} (ms CPU)" for k in ("move", "balance", "landing ground", "robot move"))
          + (" | ratio this/other |" if args.compare else " |"))
    for n in counts:
        for name in trees:
            rows = samples[(name, n)]
            med = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
            ratio = ""
            if args.compare and name == "this":
                other = samples[(args.compare, n)]
                ratio = " | " + ", ".join(f"{k} {med[k] / statistics.median(r[k] for r in other):.2f}" for k in med)
            print(f"| {name} | {n} | " + " | ".join(f"{med[k]:.3f}" for k in med) + ratio + (" |" if ratio or not args.compare else " | |"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
