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

from sensorium.worlds import floor_runs

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

    sim, robot, sensors, (left, right) = floor_runs.epuck(WORLD, precision)
    pen = sim.device("epuck/pen")
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
    result = run()
    layer = result["sim"].scene.textures.ink[0]
    shade = 1.0 - layer.density[..., None] * (1.0 - layer.rgb)       # the ink over white paper
    floor_runs.save_picture(
        out, np.clip(shade, 0, 1), 1, result["path"], label="robot centre, following the ink", lw=1.0,
        start=result["strokes"][0], lim=0.7,
        title=f"{len(result['strokes'])} strokes drawn, then a lap {result['worst'] * 1000:.1f} mm at most off them")
    return result


def _picture_line(out: Path) -> str:
    result = picture(out)
    return (f"{len(result['strokes'])} strokes, lapped={result['lapped']} in {result['follow_steps']} steps, "
            f"worst {result['worst'] * 1000:.2f} mm off the drawn circle")


def main(argv: list[str]) -> int:
    return floor_runs.main(argv, "pen_drawing", IMAGE, render, _picture_line)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
