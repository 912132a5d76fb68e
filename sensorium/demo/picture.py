"""The demo's top-down picture (matplotlib, no display needed): the world's solids and lights, each
robot's path with start and end markers, and the scout's last lidar scan, in metres."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from sensorium.demo.runner import CONTROLLERS, DemoResult

ROBOT_COLOURS = ("tab:green", "tab:orange", "tab:purple", "tab:brown")
SCAN_ROBOT = "scout"


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise (Andrew's monotone chain)."""
    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 3:
        return pts

    def half(seq: np.ndarray) -> list[np.ndarray]:
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2 and np.cross(out[-1] - out[-2], p - out[-2]) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _footprint(geometry, pose, base_dir: Path) -> np.ndarray | None:
    """The outline, seen from above, of a shape placed at ``pose`` (None for planes)."""
    from sensorium.server.sim.scene import primitive_from_model
    from sensorium.server.world import geometry as geo

    prim = primitive_from_model(geometry, base_dir)
    if isinstance(prim, geo.Plane):
        return None
    vertices = prim.vertices if isinstance(prim, geo.Mesh) else geo.tessellate(prim)[0]
    return _hull(pose.apply(vertices)[:, :2])


def _draw_shape(ax, Polygon, name: str, shape, pose, base_dir: Path) -> None:
    """One shape of a solid, seen from above: its outline filled with its colour, its name."""
    outline = _footprint(shape.geometry, pose, base_dir)
    a = shape.appearance
    colour = tuple(a.base_color) if a else (0.7, 0.7, 0.7)
    if outline is None:                              # a plane (the floor): its extent if finite
        size = getattr(shape.geometry, "size", None)
        if size:
            c = pose.translation
            corners = [(c[0] + sx * size[0] / 2, c[1] + sy * size[1] / 2) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            ax.add_patch(Polygon(corners, closed=True, facecolor="0.96", edgecolor="none", zorder=0))
        return
    transparent = a is not None and a.transparency >= 1.0
    if min(colour) > 0.75:                           # white walls would vanish on the light floor
        colour = (0.55, 0.55, 0.55)
    ax.add_patch(Polygon(outline, closed=True, zorder=1, linewidth=1.0,
                         facecolor="none" if transparent else colour, alpha=1.0 if transparent else 0.55,
                         edgecolor="0.25", linestyle="--" if transparent else "-"))
    if not name.startswith("wall"):
        ax.annotate(name + (" (glass)" if transparent else ""), outline.mean(axis=0), xytext=(0, -14),
                    textcoords="offset points", ha="center", fontsize=7, color="0.3", zorder=6)


def _yaw(q: dict) -> float:
    return math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))


def _last_scan(recording: Path, robot: str) -> tuple[np.ndarray, float] | None:
    """The robot's last LaserScan as world xy points, placed with the pose recorded at its stamp."""
    from sensorium.server.recording.reader import iter_messages

    scan, poses = None, {}
    for m in iter_messages(recording, topics=[f"/{robot}/lidar/laser_scan", f"/{robot}/pose"]):
        if m.topic.endswith("/pose"):
            poses[m.stamp_ns] = m.decode()["pose"]
        else:
            scan = m
    if scan is None or scan.stamp_ns not in poses:
        return None
    body = scan.decode()
    ranges = np.frombuffer(body["ranges"], dtype="<f4").astype(np.float64)
    angles = body["angle_min"] + body["angle_increment"] * np.arange(len(ranges))
    p = poses[scan.stamp_ns]
    yaw = _yaw(p["orientation"])
    ok = np.isfinite(ranges)
    xy = np.stack([p["position"]["x"] + ranges[ok] * np.cos(angles[ok] + yaw),
                   p["position"]["y"] + ranges[ok] * np.sin(angles[ok] + yaw)], axis=1)
    return xy, scan.stamp_ns / 1e9


def draw_picture(result: DemoResult, loaded, paths: dict, out: Path,
                 log: Callable[[str], None] = print) -> Path | None:
    """Write the picture to ``out``; returns its path, or None (with one line logged) without matplotlib."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.patches import Polygon
    except ImportError:
        log("demo: matplotlib is not installed: no picture (pip install matplotlib)")
        return None
    from sensorium.server.sim.scene import place_light, solid_lights, solid_parts
    from sensorium.server.world.poses import pose_from_model

    world = loaded.world
    fig, ax = plt.subplots(figsize=(8.5, 8), dpi=110)
    for s in world.solids:
        for name, pose, shape in solid_parts(s, pose_from_model(s.pose)):
            _draw_shape(ax, Polygon, name, shape, pose, loaded.base_dir)
    lights = [lt for lt in world.lights]
    for s in world.solids:
        lights += [place_light(lt, frame) for lt, frame in solid_lights(s, pose_from_model(s.pose))]
    for lt in lights:
        if lt.type == "DirectionalLight" or not lt.on:
            continue
        x, y = lt.location[0], lt.location[1]
        ax.plot([x], [y], marker="*", markersize=20, color="gold", markeredgecolor="darkgoldenrod", zorder=5,
                linestyle="none")
        ax.annotate(f"{lt.name or 'light'} ({lt.type})", (x, y), xytext=(8, 8), textcoords="offset points",
                    fontsize=8, color="darkgoldenrod", zorder=6)
    roles = {c.robot: c.role for c in CONTROLLERS}
    for i, robot in enumerate(r.name for r in world.robots):
        if robot not in paths:
            continue
        _, xy = paths[robot]
        colour = ROBOT_COLOURS[i % len(ROBOT_COLOURS)]
        label = f"{robot} ({roles.get(robot, 'robot')}): {result.distance_m.get(robot, 0):.1f} m driven"
        ax.plot(xy[:, 0], xy[:, 1], color=colour, linewidth=1.6, zorder=3, label=label)
        ax.plot(*xy[0], marker="o", markersize=9, color=colour, markeredgecolor="black", zorder=4, linestyle="none")
        ax.plot(*xy[-1], marker="s", markersize=9, color=colour, markeredgecolor="black", zorder=4, linestyle="none")
    # shared legend entries for the markers
    ax.plot([], [], marker="o", color="0.6", markeredgecolor="black", linestyle="none", label="start")
    ax.plot([], [], marker="s", color="0.6", markeredgecolor="black", linestyle="none", label="end")
    scan = _last_scan(result.recording, SCAN_ROBOT) if SCAN_ROBOT in paths else None
    if scan is not None:
        xy, t = scan
        ax.scatter(xy[:, 0], xy[:, 1], s=4, color="crimson", zorder=4,
                   label=f"{SCAN_ROBOT}'s last lidar scan (t = {t:.1f} s)")
    sun = [lt for lt in lights if lt.type == "DirectionalLight" and lt.on]
    if sun:
        ax.plot([], [], linestyle="none", label=", ".join(f"{lt.name or 'light'}: directional light" for lt in sun))
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True, color="0.85", linewidth=0.5, zorder=0)
    ax.set_title(f"Sensorium demo: world '{result.world}', {result.simulated_s:g} s simulated\n"
                 "paths of the two controllers, seen from above", fontsize=11)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2, fontsize=8, frameon=False)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)
    return out
