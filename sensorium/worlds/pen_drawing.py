"""The pen-drawing world (``pen_drawing.yaml``): its white paper texture, and the example run.

The robot drives one lap of a circle of radius 0.5 m writing with its Pen (black ink, density 1,
a 1.5 cm lead), then follows the ink with its ground sensors (``example:pen_drawer``). The paper
is a plain white 512 x 512 PNG: on the 2 m floor it gives the paint texture texels of 3.9 mm, and
the lead ``int(0.015 x 512 / 1.414) = 5`` texels, a disc 2 cm across.

    python -m sensorium.worlds.pen_drawing                    # rewrite textures/paper.png
    python -m sensorium.worlds.pen_drawing picture OUT.png    # the ink and the robot's path after a run
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
IMAGE = HERE / "textures" / "paper.png"
WORLD = HERE / "pen_drawing.yaml"
PIXELS = 512


def render() -> np.ndarray:
    """The paper: ``(PIXELS, PIXELS, 3)`` uint8, all white."""
    return np.full((PIXELS, PIXELS, 3), 255, dtype=np.uint8)


def run(follow_steps: int | None = None, precision: str = "exact") -> dict:
    """The example controller's law driving the world's robot in process: the drawing lap, then
    following the ink until one more lap is done (or for ``follow_steps`` steps). Returns the
    strokes' points, the robot's path while following, the largest distance of its centre from the
    drawn circle, whether it lapped, the steps and the simulation."""
    from sensorium.client.examples.pen_drawer import RADIUS, PenDrawer
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(WORLD, precision=precision)
    robot = sim.robot("epuck")
    pen = sim.device("epuck/pen")
    sensors = [sim.device(f"epuck/gs{i}") for i in range(3)]
    for s in sensors:
        s.enable(sim.basic_time_step)
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for motor in (left, right):
        motor.set_position(math.inf)
    law = PenDrawer(sim.basic_time_step)
    values = [math.nan] * 3
    strokes, path, readings = [], [], []
    angle, last = 0.0, None
    limit = follow_steps if follow_steps is not None else 20_000
    while law.steps < law.draw_steps + limit:
        speeds = law.step(values)
        pen.set_write(speeds[2])
        left.set_velocity(speeds[0])
        right.set_velocity(speeds[1])
        made = pen.measurements
        sim.step()
        values = [s.value for s in sensors]
        if pen.measurements != made:
            strokes.append(pen.stroke[:2].copy())
        if law.steps <= law.draw_steps:
            continue
        p = robot.pose.translation[:2].copy()
        path.append(p)
        readings.append(values)
        a = math.atan2(p[1], p[0])
        if last is not None:
            angle += (a - last + math.pi) % (2 * math.pi) - math.pi
        last = a
        if follow_steps is None and angle >= 2 * math.pi:
            break
    ink = np.array(strokes)
    drawn = float(np.mean(np.hypot(ink[:, 0], ink[:, 1])))
    route = np.array(path)
    off = np.abs(np.hypot(route[:, 0], route[:, 1]) - drawn)
    return {"strokes": ink, "drawn_radius": drawn, "radius": RADIUS, "path": route, "worst": float(off.max()),
            "lapped": angle >= 2 * math.pi, "angle": angle, "draw_steps": law.draw_steps,
            "follow_steps": law.steps - law.draw_steps, "readings": np.array(readings), "sim": sim}


def picture(out: Path) -> dict:
    """The paint texture after a run (the ink as the floor shows it) with the robot's path while it
    followed the ink; returns :func:`run`'s result."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    result = run()
    sim = result["sim"]
    layer = sim.scene.textures.ink[0]
    shade = 1.0 - layer.density[..., None] * (1.0 - layer.rgb)       # the ink over white paper
    fig, ax = plt.subplots(figsize=(5, 5), dpi=120)
    ax.imshow(np.clip(shade, 0, 1), extent=(-1, 1, -1, 1), interpolation="nearest")
    path = result["path"]
    ax.plot(path[:, 0], path[:, 1], color="tab:red", lw=1.0, label="robot centre, following the ink")
    ax.plot(*result["strokes"][0], "o", color="tab:green", label="start")
    ax.set_xlim(-0.7, 0.7)
    ax.set_ylim(-0.7, 0.7)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"{len(result['strokes'])} strokes drawn, then a lap {result['worst'] * 1000:.1f} mm at most off them")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)
    return result


def main(argv: list[str]) -> int:
    from PIL import Image

    if argv[:1] == ["picture"] and len(argv) == 2:
        result = picture(Path(argv[1]))
        print(f"{argv[1]}: {len(result['strokes'])} strokes, lapped={result['lapped']} in "
              f"{result['follow_steps']} steps, worst {result['worst'] * 1000:.2f} mm off the drawn circle")
        return 0
    if argv:
        print("usage: python -m sensorium.worlds.pen_drawing [picture OUT.png]", file=sys.stderr)
        return 2
    IMAGE.parent.mkdir(exist_ok=True)
    Image.fromarray(render()).save(IMAGE, optimize=True)
    print(f"wrote {IMAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
