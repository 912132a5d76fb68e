"""What the generators of the bundled floor worlds (:mod:`.line_loop`, :mod:`.pen_drawing`) share:
their e-puck set up as its example controller sets it up, the picture of a run over the floor, and
the command line that rewrites the floor's texture or draws that picture.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np


def epuck(world: Path, precision: str) -> tuple[Any, Any, list, tuple[Any, Any]]:
    """The world in process with its robot ``epuck`` as the example controllers make it: the three
    ground sensors ``gs0..gs2`` enabled every basic step, both wheel motors under velocity control
    and standing still. Returns the simulation, the robot, the sensors and the (left, right) motors."""
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(world, precision=precision)
    robot = sim.robot("epuck")
    sensors = [sim.device(f"epuck/gs{i}") for i in range(3)]
    for s in sensors:
        s.enable(sim.basic_time_step)
    wheels = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for motor in wheels:
        motor.set_position(math.inf)
        motor.set_velocity(0.0)
    return sim, robot, sensors, wheels


def save_picture(out: Path, floor: np.ndarray, half: float, path: np.ndarray, *, label: str, lw: float,
                 start: Any, lim: float, title: str) -> None:
    """``floor`` (an image of the ``2·half`` m square floor) with the robot's ``path`` (``(n, 2)``)
    over it and its ``start`` marked, the view ``±lim`` m, saved to ``out`` (matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 5), dpi=120)
    ax.imshow(floor, extent=(-half, half, -half, half), interpolation="nearest")
    ax.plot(path[:, 0], path[:, 1], color="tab:red", lw=lw, label=label)
    ax.plot(*start, "o", color="tab:green", label="start")
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def main(argv: list[str], module: str, image: Path, render: Callable[[], np.ndarray],
         picture: Callable[[Path], str]) -> int:
    """``python -m sensorium.worlds.<module>`` rewrites ``image`` from ``render()``; with
    ``picture OUT.png`` it runs ``picture(OUT.png)`` and prints the line it returns."""
    from PIL import Image

    if argv[:1] == ["picture"] and len(argv) == 2:
        print(f"{argv[1]}: {picture(Path(argv[1]))}")
        return 0
    if argv:
        print(f"usage: python -m sensorium.worlds.{module} [picture OUT.png]", file=sys.stderr)
        return 2
    image.parent.mkdir(exist_ok=True)
    Image.fromarray(render()).save(image, optimize=True)
    print(f"wrote {image}")
    return 0
