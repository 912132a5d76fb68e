"""Read the demo's recording back: what each robot did, in numbers the test and the user can check.

* ``distance_m``: path length of the recorded poses (every basic step);
* ``cells_visited``: distinct 0.5 m x 0.5 m floor cells the robot's centre entered (exploration);
* ``smoothness``: the length of the path sampled once per simulated second divided by the driven
  length: 1 for a robot that drives where it goes, near 0 for one that jitters on the spot;
* ``longest_stuck_s``: the longest stretch in which every 10 s window (:data:`STUCK_WINDOW_S`) kept
  the robot within :data:`STUCK_RADIUS_M` of where the window began (turning on the spot or
  bumping back and forth in a corner counts as stuck); 0 when every 10 s window made progress;
* the follower's distance to the lamp: at start, at the end, its minimum, when it first came
  within :data:`LAMP_NEAR_M`, and the farthest it went after that.
"""

from __future__ import annotations

import math

import numpy as np

from sensorium.demo.runner import DemoResult

CELL_M = 0.5
LAMP_NEAR_M = 0.6               # the follower's light sensors saturate ~0.45 m from the arena's lamp
FOLLOWER = "epuck"
STUCK_WINDOW_S = 10.0
STUCK_RADIUS_M = 0.3


def path_length(xy: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1))) if len(xy) > 1 else 0.0


def cells_visited(xy: np.ndarray, cell_m: float = CELL_M) -> int:
    return len({(int(c[0]), int(c[1])) for c in np.floor(xy / cell_m)}) if len(xy) else 0


def smoothness(t_ns: np.ndarray, xy: np.ndarray, every_ns: int = 1_000_000_000) -> float:
    driven = path_length(xy)
    if driven <= 1e-9:
        return 1.0
    picks = np.searchsorted(t_ns, np.arange(t_ns[0], t_ns[-1] + 1, every_ns))
    picks = np.unique(np.append(picks[picks < len(t_ns)], len(t_ns) - 1))
    return min(1.0, path_length(xy[picks]) / driven)


def stuck_spans(t_ns: np.ndarray, xy: np.ndarray, window_s: float = STUCK_WINDOW_S,
                radius_m: float = STUCK_RADIUS_M) -> list[tuple[float, float]]:
    """The (start s, end s) spans, merged, of every ``window_s`` window in which the robot never got
    farther than ``radius_m`` from its position at the window's start."""
    if len(t_ns) < 2:
        return []
    window = int(window_s * 1e9)
    ends = np.searchsorted(t_ns, t_ns + window, side="right")          # first sample after each window
    spans: list[tuple[float, float]] = []
    for i in range(len(t_ns)):
        j = int(ends[i])
        if j >= len(t_ns) + 1 or t_ns[-1] < t_ns[i] + window:
            break                                                       # the last windows are not whole
        if float(np.max(np.linalg.norm(xy[i:j] - xy[i], axis=1))) <= radius_m:
            start, end = t_ns[i] / 1e9, t_ns[j - 1] / 1e9
            if spans and start <= spans[-1][1]:
                spans[-1] = (spans[-1][0], end)
            else:
                spans.append((start, end))
    return spans


def longest_stuck_s(t_ns: np.ndarray, xy: np.ndarray) -> float:
    return max((b - a for a, b in stuck_spans(t_ns, xy)), default=0.0)


def summarise(result: DemoResult, world) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Fill ``result`` from its recording; returns each robot's (stamps ns, xy path)."""
    from sensorium.server.recording.reader import iter_messages

    stamps: dict[str, list[int]] = {}
    points: dict[str, list[tuple[float, float]]] = {}
    light: list[float] = []
    ls: dict[str, float] = {}
    eyes = (f"/{FOLLOWER}/ls0/value", f"/{FOLLOWER}/ls1/value")
    for m in iter_messages(result.recording):
        result.messages[m.topic] = result.messages.get(m.topic, 0) + 1
        if m.topic.endswith("/pose"):
            robot = m.topic.split("/")[1]
            p = m.decode()["pose"]["position"]
            stamps.setdefault(robot, []).append(m.stamp_ns)
            points.setdefault(robot, []).append((p["x"], p["y"]))
        elif m.topic in eyes:
            ls[m.topic] = m.decode()["illuminance"]
            if len(ls) == 2:
                light.append(sum(ls.values()))
    paths = {r: (np.asarray(stamps[r], dtype=np.int64), np.asarray(points[r], dtype=np.float64)) for r in points}
    for robot, (t, xy) in paths.items():
        result.distance_m[robot] = round(path_length(xy), 3)
        result.cells_visited[robot] = cells_visited(xy)
        result.smoothness[robot] = round(smoothness(t, xy), 3)
        result.longest_stuck_s[robot] = round(longest_stuck_s(t, xy), 3)
    if light:
        result.light_start, result.light_end = light[0], light[-1]
    lamp = next((lt for lt in world.lights if lt.type == "PointLight" and lt.on), None)
    if lamp is not None and FOLLOWER in paths and len(paths[FOLLOWER][1]):
        t, xy = paths[FOLLOWER]
        d = np.linalg.norm(xy - np.asarray(lamp.location[:2]), axis=1)
        result.lamp_distance_start = round(float(d[0]), 3)
        result.lamp_distance_end = round(float(d[-1]), 3)
        result.lamp_distance_min = round(float(d.min()), 3)
        near = np.flatnonzero(d <= LAMP_NEAR_M)
        if len(near):
            result.lamp_reached_s = round(float(t[near[0]]) / 1e9, 3)
            result.lamp_distance_max_after_reached = round(float(d[near[0]:].max()), 3)
    return paths


def describe(result: DemoResult) -> list[str]:
    """The summary lines ``sensorium demo`` prints."""
    out = [f"demo: {result.simulated_s:g} s simulated in {result.wall_s:.1f} s wall "
           f"(real-time factor {result.real_time_factor:.1f})"]
    for robot, d in result.distance_m.items():
        out.append(f"  {robot:<6} drove {d:.2f} m through {result.cells_visited.get(robot, 0)} of the floor's "
                   f"{CELL_M:g} m cells (smoothness {result.smoothness.get(robot, math.nan):.2f}"
                   + (f"; no progress for {stuck:.1f} s" if (stuck := result.longest_stuck_s.get(robot, 0.0)) > 0
                      else "") + ")")
    if not math.isnan(result.lamp_distance_start):
        reached = (f"within {LAMP_NEAR_M:g} m of it at t={result.lamp_reached_s:.1f} s and stayed within "
                   f"{result.lamp_distance_max_after_reached:.2f} m"
                   if not math.isnan(result.lamp_reached_s) else f"never within {LAMP_NEAR_M:g} m of it")
        out.append(f"  {FOLLOWER} light (ls0+ls1) {result.light_start:.0f} -> {result.light_end:.0f}; distance to "
                   f"the lamp {result.lamp_distance_start:.2f} m -> {result.lamp_distance_end:.2f} m, {reached}")
    out.append(f"  recorded {sum(result.messages.values())} messages on {len(result.messages)} topics to "
               f"{result.recording}")
    return out
