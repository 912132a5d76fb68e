"""The line-following world's floor (``line_following.yaml``): a dark line loop on white.

The loop is the closed curve r(θ) = 0.55 + 0.12·cos 3θ (metres, polar about the floor's centre):
three bulges and three dents, so a robot following it turns both ways (radius of curvature at
least 0.26 m). The floor image is the line drawn 2 cm wide on a 2 m × 2 m plane, 1024 × 1024
texels (2 mm each, a power of two as Webots prefers): white (255, 255, 255) where the texel
centre is farther than 1 cm from the curve, dark (30, 30, 30) elsewhere. A Plane maps its image
with u = x/2 + 0.5, v = 0.5 − y/2 (Webots), so texel (row, column) has its centre at
x = (column + 0.5)·2/1024 − 1, y = 1 − (row + 0.5)·2/1024.

    python -m sensorium.worlds.line_loop                     # rewrite textures/line_loop.png
    python -m sensorium.worlds.line_loop picture OUT.png     # one lap, drawn over the floor

The committed image is this module's output (tests/test_line_following.py checks it texel for
texel), so the world needs nothing generated at install time.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from sensorium.worlds import floor_runs

HERE = Path(__file__).resolve().parent
IMAGE = HERE / "textures" / "line_loop.png"
WORLD = HERE / "line_following.yaml"
FLOOR = 2.0             # m, the floor plane's side
PIXELS = 1024           # texels per side
WIDTH = 0.02            # m, the line's width
DARK, WHITE = 30, 255   # texel values (all three channels)
R0, AMPLITUDE, LOBES = 0.55, 0.12, 3


def centreline(n: int = 6000) -> np.ndarray:
    """``(n, 2)`` points along the loop, counter-clockwise from θ = 0 (closed: the last joins the first)."""
    theta = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    r = R0 + AMPLITUDE * np.cos(LOBES * theta)
    return np.stack([r * np.cos(theta), r * np.sin(theta)], axis=1)


def distance_to_line(points: np.ndarray, line: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(distance to the loop, index of the nearest centreline segment) for ``(k, 2)`` points."""
    a = centreline() if line is None else line
    b = np.roll(a, -1, axis=0)
    ab = b - a
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    best = np.full(len(p), np.inf)
    seg = np.zeros(len(p), dtype=np.int64)
    for start in range(0, len(p), 4096):        # bounded temporaries: (4096 x segments) at a time
        q = p[start:start + 4096, None, :]
        t = np.clip(((q - a) * ab).sum(-1) / (ab * ab).sum(-1), 0.0, 1.0)
        d = np.linalg.norm(q - (a + t[..., None] * ab), axis=-1)
        best[start:start + 4096] = d.min(axis=1)
        seg[start:start + 4096] = d.argmin(axis=1)
    return best, seg


def render() -> np.ndarray:
    """The floor image, ``(PIXELS, PIXELS, 3)`` uint8, top row first."""
    c = (np.arange(PIXELS) + 0.5) * FLOOR / PIXELS
    x, y = np.meshgrid(c - FLOOR / 2, FLOOR / 2 - c)       # texel centres (row = -y)
    pts = np.stack([x.ravel(), y.ravel()], axis=1)
    rho = np.hypot(pts[:, 0], pts[:, 1])
    theta = np.mod(np.arctan2(pts[:, 1], pts[:, 0]), 2 * math.pi)
    r_line = R0 + AMPLITUDE * np.cos(LOBES * theta)
    # a texel within WIDTH/2 of the loop (at ρ >= 0.41) sees its nearest point at most asin(0.01/0.41)
    # = 0.0244 rad (31 segments) from its own angle, where the loop's radius differs from its own by at
    # most 0.01 + 0.36 x 0.0244 = 0.0188 m (|dr/dθ| <= AMPLITUDE x LOBES): only those texels, and only
    # those segments, are looked at
    near = (np.abs(rho - r_line) < 0.02).nonzero()[0]
    n, window = 8000, 40
    a = centreline(n)
    ab = np.roll(a, -1, axis=0) - a
    dark = np.zeros(len(pts), dtype=bool)
    offsets = np.arange(-window, window + 1)
    for start in range(0, len(near), 4096):
        rows = near[start:start + 4096]
        i0 = np.round(theta[rows] / (2 * math.pi) * n).astype(np.int64)
        idx = (i0[:, None] + offsets) % n
        q = pts[rows][:, None, :]
        t = np.clip(((q - a[idx]) * ab[idx]).sum(-1) / (ab[idx] ** 2).sum(-1), 0.0, 1.0)
        d = np.linalg.norm(q - (a[idx] + t[..., None] * ab[idx]), axis=-1).min(axis=1)
        dark[rows] = d <= WIDTH / 2
    img = np.where(dark, DARK, WHITE).astype(np.uint8).reshape(PIXELS, PIXELS)
    return np.repeat(img[..., None], 3, axis=2)


def lap(steps: int | None = None, precision: str = "exact") -> dict:
    """The example controller's law (client/examples/line_follower.py) driving the world's robot in
    process until it completes one lap (or for ``steps`` steps): its positions, the largest
    distance of its centre from the line, whether it lapped, and the steps taken."""
    from sensorium.client.examples.line_follower import LineFollower

    sim, robot, sensors, (left, right) = floor_runs.epuck(WORLD, precision)
    law = LineFollower()
    line = centreline()
    seg_len = np.linalg.norm(np.roll(line, -1, axis=0) - line, axis=1)
    total = float(seg_len.sum())
    arc = np.concatenate([[0.0], np.cumsum(seg_len)[:-1]])
    path = [robot.pose.translation[:2].copy()]
    start = distance_to_line(path[0][None], line)[1][0]
    progress, last, worst, n = 0.0, arc[start], 0.0, 0
    limit = steps if steps is not None else 20_000
    while n < limit:
        sim.step()
        n += 1
        speeds = law.step([s.value for s in sensors])
        left.set_velocity(speeds[0])
        right.set_velocity(speeds[1])
        p = robot.pose.translation[:2].copy()
        path.append(p)
        d, seg = distance_to_line(p[None], line)
        worst = max(worst, float(d[0]))
        s_now = arc[seg[0]]
        delta = (s_now - last + total / 2) % total - total / 2      # unwrapped progress along the loop
        progress += delta
        last = s_now
        if steps is None and progress >= total:
            break
    return {"path": np.array(path), "worst": worst, "lapped": progress >= total, "steps": n,
            "progress": progress, "length": total, "time_ms": sim.time_ms}


def picture(out: Path) -> dict:
    """One lap drawn over the floor image (matplotlib), saved to ``out``; returns :func:`lap`'s result."""
    from PIL import Image

    run = lap()
    path = run["path"]
    floor_runs.save_picture(
        out, np.asarray(Image.open(IMAGE)), FLOOR / 2, path, label="robot centre", lw=1.2, start=path[0], lim=0.85,
        title=f"one lap in {run['time_ms'] / 1000:.1f} s, at most {run['worst'] * 100:.1f} cm off the line")
    return run


def _picture_line(out: Path) -> str:
    run = picture(out)
    return f"lapped={run['lapped']} in {run['time_ms']} ms, worst {run['worst'] * 100:.2f} cm off the line"


def main(argv: list[str]) -> int:
    return floor_runs.main(argv, "line_loop", IMAGE, render, _picture_line)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
