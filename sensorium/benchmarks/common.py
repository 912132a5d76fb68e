"""Shared pieces of the benchmark sections: configuration, timing, growth fits, result containers,
scene descriptions that give both a Sensorium world and an exact float64 reference."""

from __future__ import annotations

import gc
import math
import os
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np


# ----------------------------------------------------------------------------- configuration
@dataclass
class Config:
    quick: bool = False
    log: Callable[[str], None] = print

    def pick(self, full, quick):
        """``quick`` value in --quick runs, ``full`` otherwise."""
        return quick if self.quick else full

    @property
    def repeat(self) -> int:
        return 3 if self.quick else 7


# ----------------------------------------------------------------------------- results
@dataclass
class Table:
    id: str
    title: str
    columns: list[str]
    rows: list[list[Any]]
    notes: list[str] = field(default_factory=list)


@dataclass
class Series:
    label: str
    x: list[float]
    y: list[float]
    labels: list[str] = field(default_factory=list)   # per-point annotations (Pareto plots)


@dataclass
class Plot:
    id: str
    title: str
    xlabel: str
    ylabel: str
    series: list[Series]
    logx: bool = True
    logy: bool = True
    kind: str = "line"                                 # "line" (scaling) or "pareto"


@dataclass
class Target:
    name: str
    target: str
    measured: str
    ok: bool | None                                    # None: could not be measured
    why: str = ""


@dataclass
class Section:
    name: str
    title: str
    intro: str = ""
    tables: list[Table] = field(default_factory=list)
    plots: list[Plot] = field(default_factory=list)
    targets: list[Target] = field(default_factory=list)
    findings: list[str] = field(default_factory=list)
    data: dict = field(default_factory=dict)
    elapsed_s: float = 0.0

    def to_json(self) -> dict:
        return _jsonable(asdict(self))


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        v = float(x)
        return v if math.isfinite(v) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    return x


# ----------------------------------------------------------------------------- timing
def samples(fn: Callable[[], Any], repeat: int, warmup: int = 1, min_total_s: float = 0.0,
            max_repeat: int = 1000) -> list[float]:
    """Wall-clock seconds of ``repeat`` calls (after ``warmup``); keeps calling, up to
    ``max_repeat``, until ``min_total_s`` has been spent (cheap calls get many samples)."""
    for _ in range(warmup):
        fn()
    gc_was = gc.isenabled()
    gc.disable()
    try:
        out: list[float] = []
        total = 0.0
        while len(out) < repeat or (total < min_total_s and len(out) < max_repeat):
            t0 = time.perf_counter()
            fn()
            dt = time.perf_counter() - t0
            out.append(dt)
            total += dt
        return out
    finally:
        if gc_was:
            gc.enable()


def process_cpu_s(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` so far (Linux ``/proc/<pid>/stat``; 0 where it
    cannot be read)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return 0.0


def median(xs) -> float:
    return float(np.median(np.asarray(xs, dtype=np.float64))) if len(xs) else float("nan")


def pct(xs, q: float) -> float:
    return float(np.percentile(np.asarray(xs, dtype=np.float64), q)) if len(xs) else float("nan")


def timed(fn: Callable[[], Any], repeat: int, warmup: int = 1, min_total_s: float = 0.0) -> float:
    """Median seconds per call."""
    return median(samples(fn, repeat, warmup, min_total_s))


def interleaved(fns: dict[str, Callable[[], Any]], rounds: int, per_round: int = 1,
                warmup: int = 1, clock: Callable[[], float] = time.perf_counter) -> dict[str, list[float]]:
    """Time several competitors in alternation (A B C A B C …) so that load from other processes
    on this shared machine hits all of them alike; returns per-call seconds for each. ``clock``:
    ``time.thread_time`` measures the calling thread's CPU time instead of the wall clock (for
    one-thread calls on a busy machine: a call preempted by another process is not charged for
    the wait, which otherwise falls more often on the longer calls)."""
    for fn in fns.values():
        for _ in range(warmup):
            fn()
    out: dict[str, list[float]] = {k: [] for k in fns}
    gc_was = gc.isenabled()
    gc.disable()
    try:
        for _ in range(rounds):
            for k, fn in fns.items():
                for _ in range(per_round):
                    t0 = clock()
                    fn()
                    out[k].append(clock() - t0)
    finally:
        if gc_was:
            gc.enable()
    return out


class Stopwatch:
    """Accumulates the time spent inside a wrapped callable (e.g. ``engine.cast``)."""

    def __init__(self, fn: Callable):
        self.fn = fn
        self.total = 0.0
        self.cpu = 0.0          # this process's CPU time inside the calls (time.process_time)
        self.calls = 0

    def __call__(self, *a, **k):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            return self.fn(*a, **k)
        finally:
            self.total += time.perf_counter() - t0
            self.cpu += time.process_time() - c0
            self.calls += 1

    def reset(self) -> None:
        self.total = 0.0
        self.cpu = 0.0
        self.calls = 0


# ----------------------------------------------------------------------------- growth
def growth(xs, ys, floor_frac: float = 0.0) -> dict:
    """Log-log slope of time vs size over the points (a least-squares fit), and a word for it.
    ``floor_frac``: drop the smallest sizes whose time is within this fraction of the first time
    (fixed per-step overhead hides the growth there)."""
    x = np.asarray(xs, dtype=np.float64)
    y = np.asarray(ys, dtype=np.float64)
    ok = (x > 0) & (y > 0) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if len(x) < 2:
        return {"slope": None, "label": "n/a", "fit_points": int(len(x))}
    # fit the upper half of the range too: where the work, not the fixed overhead, dominates
    slope_all = float(np.polyfit(np.log(x), np.log(y), 1)[0])
    k = max(2, len(x) // 2 + (len(x) % 2))
    slope_hi = float(np.polyfit(np.log(x[-k:]), np.log(y[-k:]), 1)[0])
    return {"slope": slope_all, "slope_upper": slope_hi, "label": growth_word(slope_hi),
            "fixed_cost_s": float(y[0]), "marginal_s_per_unit": float((y[-1] - y[0]) / (x[-1] - x[0]))}


def growth_word(slope: float) -> str:
    if slope < 0.12:
        return "flat (≈ constant)"
    if slope < 0.45:
        return "sublinear (≈ logarithmic)"
    if slope < 0.85:
        return "sublinear"
    if slope < 1.15:
        return "linear"
    return "superlinear"


def fmt_growth(g: dict) -> str:
    if g.get("slope") is None:
        return "n/a"
    return f"{g['label']} — log-log slope {g['slope_upper']:.2f} over the upper half ({g['slope']:.2f} overall)"


# ----------------------------------------------------------------------------- formatting
def fmt_time(s: float) -> str:
    if s is None or not math.isfinite(s):
        return "–"
    if s >= 1.0:
        return f"{s:.2f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.2f} ms"
    if s >= 1e-6:
        return f"{s * 1e6:.1f} µs"
    return f"{s * 1e9:.0f} ns"


def fmt_len(m: float) -> str:
    """A length error in metres, readable from 1e-15 to 1."""
    if m is None or not math.isfinite(m):
        return "–"
    if m == 0.0:
        return "0"
    return f"{m:.2e} m"


def fmt_rate(r: float) -> str:
    if r is None or not math.isfinite(r):
        return "–"
    if r >= 1e6:
        return f"{r / 1e6:.2f} M/s"
    if r >= 1e3:
        return f"{r / 1e3:.1f} k/s"
    return f"{r:.0f} /s"


def machine() -> dict:
    import platform

    info = {"python": platform.python_version(), "platform": platform.platform(), "cpus": os.cpu_count(),
            "numpy": np.__version__}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    info["cpu"] = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        info["load_average"] = [round(v, 2) for v in os.getloadavg()]
    except OSError:
        pass
    from importlib import metadata

    for dist in ("embreex", "pyzmq", "msgpack", "open3d", "mujoco", "pybullet", "trimesh", "matplotlib"):
        try:
            info[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            info[dist] = None
    try:
        import zmq

        info["zmq"] = f"{zmq.zmq_version()} (pyzmq {zmq.__version__})"
    except ImportError:
        info["zmq"] = None
    return info


# ----------------------------------------------------------------------------- simulations
def make_sim(world: dict, precision: str = "exact", base_dir=None, threads: int | None = None):
    """A simulation of ``world`` (limits raised: benchmark worlds are deliberately large);
    ``threads``: the threads its ray engine may use (default: the engine's, both cores here)."""
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.limits import WorldLimits
    from sensorium.server.world.loader import parse_world

    sim = Simulation(parse_world(world, base_dir=base_dir, limits=WorldLimits.large()), precision=precision)
    if threads is not None:
        sim.scene.engine.threads = threads
    return sim


def identity_table(max_range: float, noise: float = 0.0) -> list[list[float]]:
    """A lookup table whose output is the input distance (optionally with relative noise)."""
    return [[0.0, 0.0, noise], [float(max_range), float(max_range), noise]]


def wrap_cast(sim) -> Stopwatch:
    """Time every ``engine.cast`` of ``sim`` (the ray work of a step)."""
    eng = sim.scene.engine
    sw = Stopwatch(eng.cast)
    eng.cast = sw  # instance attribute shadows the method
    return sw


# ----------------------------------------------------------------------------- exact reference
def rot_z(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass
class Shape:
    """One solid of a benchmark scene: enough to write it in a world file and to intersect it
    exactly in float64. ``kind`` box (size) | sphere (radius) | cylinder (radius, height) |
    capsule (radius, height) | plane (size or None). Rotation: yaw about z, or ``axis_x`` (a
    quarter turn about x, to lay cylinders/capsules down)."""

    kind: str
    pos: tuple[float, float, float]
    size: tuple | None = None
    radius: float = 0.0
    height: float = 0.0
    yaw: float = 0.0
    subdivision: int | None = None
    name: str = ""
    red: float = 0.8

    @property
    def R(self) -> np.ndarray:
        return rot_z(self.yaw)

    def solid(self) -> dict:
        g: dict = {"type": self.kind}
        if self.kind == "box":
            g["size"] = list(self.size)
        elif self.kind == "plane":
            g["size"] = None if self.size is None else list(self.size)
        else:
            g["radius"] = self.radius
            if self.kind in ("cylinder", "capsule"):
                g["height"] = self.height
        if self.subdivision is not None:
            g["subdivision"] = self.subdivision
        pose: dict = {"translation": list(self.pos)}
        if self.yaw:
            pose["rotation"] = [0.0, 0.0, 1.0, self.yaw]
        return {"name": self.name, "pose": pose, "geometry": g,
                "appearance": {"base_color": [self.red, 0.5, 0.5], "roughness": 0.5}}


def exact_cast(shapes: list[Shape], O: np.ndarray, D: np.ndarray, t_near: float = 0.0,
               t_far: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
    """Nearest hit (t, shape index) of rays against the true shapes, float64 closed forms.
    Rays are in world coordinates; each shape works in its own frame (origin subtracted in float64
    first, so far-from-origin scenes stay exact). Planes are one-sided (front = +z), as the
    visual rays of lidars and infra-red sensors see them."""
    O = np.asarray(O, dtype=np.float64)
    D = np.asarray(D, dtype=np.float64)
    n = len(O)
    best = np.full(n, np.inf)
    who = np.full(n, -1, dtype=np.int64)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for i, s in enumerate(shapes):
            R = s.R
            o = (O - np.asarray(s.pos)) @ R          # R^T (o - c), row-vector form
            d = D @ R
            t = _local_hit(s, o, d, t_near)
            t = np.where((t >= t_near) & (t <= t_far), t, np.inf)
            better = t < best
            best[better] = t[better]
            who[better] = i
    return best, who


def _first_root(a, b, c, t_near):
    """Smallest root >= t_near of a t^2 + 2 b t + c = 0 (stable form)."""
    disc = b * b - a * c
    s = np.sqrt(np.maximum(disc, 0.0))
    q = -(b + np.copysign(s, b))
    r1 = q / a
    r2 = c / q
    lo = np.minimum(r1, r2)
    hi = np.maximum(r1, r2)
    t = np.where(lo >= t_near, lo, np.where(hi >= t_near, hi, np.inf))
    return np.where(disc >= 0.0, t, np.inf)


def _local_hit(s: Shape, o: np.ndarray, d: np.ndarray, t_near: float) -> np.ndarray:
    if s.kind == "box":
        h = np.asarray(s.size, dtype=np.float64) / 2.0
        t1 = (-h - o) / d
        t2 = (h - o) / d
        tmin = np.nanmax(np.minimum(t1, t2), axis=1)
        tmax = np.nanmin(np.maximum(t1, t2), axis=1)
        hit = tmin <= tmax
        return np.where(hit, np.where(tmin >= t_near, tmin, np.where(tmax >= t_near, tmax, np.inf)), np.inf)
    if s.kind == "sphere":
        a = (d * d).sum(1)
        b = (o * d).sum(1)
        c = (o * o).sum(1) - s.radius ** 2
        return _first_root(a, b, c, t_near)
    if s.kind == "plane":
        t = -o[:, 2] / d[:, 2]
        ok = d[:, 2] < 0.0
        if s.size is not None:
            p = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
            ok &= (np.abs(p[:, 0]) <= s.size[0] / 2) & (np.abs(p[:, 1]) <= s.size[1] / 2)
        return np.where(ok, t, np.inf)
    r, h = s.radius, s.height / 2.0
    a = d[:, 0] ** 2 + d[:, 1] ** 2
    b = o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]
    c = o[:, 0] ** 2 + o[:, 1] ** 2 - r * r
    disc = b * b - a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    cands = []
    for sign in (-1.0, 1.0):
        t = np.where(disc >= 0.0, (-b + sign * sq) / a, np.inf)
        z = o[:, 2] + t * d[:, 2]
        cands.append(np.where(np.abs(z) <= h, t, np.inf))
    if s.kind == "cylinder":
        for zc in (-h, h):
            t = (zc - o[:, 2]) / d[:, 2]
            x = o[:, 0] + t * d[:, 0]
            y = o[:, 1] + t * d[:, 1]
            cands.append(np.where(x * x + y * y <= r * r, t, np.inf))
    else:  # capsule: hemispheres beyond the straight part
        for zc in (-h, h):
            oc = o.copy()
            oc[:, 2] -= zc
            aa = (d * d).sum(1)
            bb = (oc * d).sum(1)
            cc = (oc * oc).sum(1) - r * r
            dd = bb * bb - aa * cc
            sq2 = np.sqrt(np.maximum(dd, 0.0))
            for sign in (-1.0, 1.0):
                t = np.where(dd >= 0.0, (-bb + sign * sq2) / aa, np.inf)
                z = o[:, 2] + t * d[:, 2]
                cands.append(np.where(np.sign(zc) * z >= abs(zc), t, np.inf))
    ts = np.stack(cands, 1)
    ts = np.where(ts >= t_near, ts, np.inf)
    return ts.min(1)


# ----------------------------------------------------------------------------- lidar helpers
def lidar_dirs(W: int, L: int, fov: float = 2 * math.pi, vfov: float = 0.5) -> np.ndarray:
    """Beam directions (L·W, 3) of a fixed cylindrical lidar, the same layout Sensorium uses."""
    from sensorium.server.devices import lidar as lmath

    p = lmath.LidarParams(horizontal_resolution=W, number_of_layers=L, field_of_view=fov,
                          vertical_field_of_view=vfov, max_range=100.0)
    return lmath.ray_directions(p).reshape(-1, 3)


def lidar_device(name: str, W: int, L: int, *, fov: float = 2 * math.pi, vfov: float = 0.5,
                 max_range: float = 50.0, near: float = 0.01, noise: float = 0.0,
                 z: float = 0.0) -> dict:
    return {"device": "Lidar", "name": name, "pose": {"translation": [0.0, 0.0, z]},
            "horizontal_resolution": W, "number_of_layers": L, "field_of_view": fov,
            "vertical_field_of_view": vfov, "near": near, "min_range": near, "max_range": max_range,
            "noise": noise, "type": "fixed"}


# ----------------------------------------------------------------------------- the benchmark room
def room_shapes(with_floor: bool = True) -> list[Shape]:
    """A closed 8 m × 6 m room (walls 3 m high) with pillars, a crate, a ball and a bollard: every
    lidar beam from inside hits something, and every shape has a closed-form intersection."""
    s = [
        Shape("box", (0.0, 3.1, 1.5), size=(8.4, 0.2, 3.0), name="wall_n"),
        Shape("box", (0.0, -3.1, 1.5), size=(8.4, 0.2, 3.0), name="wall_s"),
        Shape("box", (4.1, 0.0, 1.5), size=(0.2, 6.0, 3.0), name="wall_e"),
        Shape("box", (-4.1, 0.0, 1.5), size=(0.2, 6.0, 3.0), name="wall_w"),
        Shape("box", (1.8, 1.2, 0.4), size=(0.8, 0.6, 0.8), yaw=0.4, name="crate"),
        Shape("cylinder", (-1.5, 1.0, 1.5), radius=0.2, height=3.0, name="pillar_a"),
        Shape("cylinder", (1.0, -1.6, 1.5), radius=0.3, height=3.0, name="pillar_b"),
        Shape("sphere", (-2.2, -1.2, 0.5), radius=0.5, name="ball"),
        Shape("capsule", (2.8, -0.6, 0.9), radius=0.15, height=1.2, name="bollard"),
    ]
    if with_floor:
        s.insert(0, Shape("plane", (0.0, 0.0, 0.0), size=None, name="floor"))
    return s


ROOM_LIDAR_AT = (0.3, -0.2, 1.0)


def room_world(devices: list[dict], *, robot_at=ROOM_LIDAR_AT, shapes: list[Shape] | None = None,
               step: int = 32, seed: int = 1, extra_robots: list[dict] | None = None) -> dict:
    shapes = room_shapes() if shapes is None else shapes
    return {
        "world_info": {"name": "bench-room", "basic_time_step": step, "random_seed": seed},
        "solids": [sh.solid() for sh in shapes],
        "robots": [{"name": "r", "pose": {"translation": list(robot_at)}, "devices": devices},
                   *(extra_robots or [])],
    }


def world_triangles(sim, plane_half: float = 100.0) -> list[tuple[str, np.ndarray, np.ndarray, bool]]:
    """The triangles Sensorium's engine builds for a simulation's visible shapes, in world
    coordinates, one entry per solid or robot body: (name, vertices float64 (n,3), faces int (m,3),
    is_plane). Planes (analytic in Sensorium) become two triangles, ``plane_half`` m each way when
    infinite, so that triangle-only engines see the same surfaces."""
    from sensorium.schemas import world as wm
    from sensorium.server.sim.scene import primitive_from_model
    from sensorium.server.world.geometry import tessellate
    from sensorium.server.world.poses import pose_from_model

    out = []
    items = [(s.name, s, pose_from_model(s.pose)) for s in sim.world.solids]
    items += [(f"{r.name}/body", r.body, sim.scene.robot_poses[i]) for i, r in enumerate(sim.world.robots)
              if r.body is not None]
    for name, shape, pose in items:
        if shape.seen_by == "bounding":
            continue
        g = shape.geometry
        if isinstance(g, wm.Plane):
            hx, hy = (plane_half, plane_half) if g.size is None else (g.size[0] / 2, g.size[1] / 2)
            v = np.array([[-hx, -hy, 0.0], [hx, -hy, 0.0], [hx, hy, 0.0], [-hx, hy, 0.0]])
            f = np.array([[0, 1, 2], [0, 2, 3]])
            out.append((name, pose.apply(v), f, True))
            continue
        v, f = tessellate(primitive_from_model(g, sim.loaded.base_dir))
        out.append((name, pose.apply(v), np.asarray(f), False))
    return out


def world_shapes(sim) -> list[tuple[str, Any, Any]]:
    """The visible shapes of a simulation as (name, geometry model, world pose), one per solid or
    robot body, for engines with their own primitives (MuJoCo's planes, boxes, spheres, cylinders,
    capsules; a mesh stays a mesh)."""
    items = [(s.name, s, None) for s in sim.world.solids]
    items += [(f"{r.name}/body", r.body, sim.scene.robot_poses[i]) for i, r in enumerate(sim.world.robots)
              if r.body is not None]
    from sensorium.server.world.poses import pose_from_model

    return [(name, shape.geometry, pose if pose is not None else pose_from_model(shape.pose))
            for name, shape, pose in items if shape.seen_by != "bounding"]


def merge_triangles(parts) -> tuple[np.ndarray, np.ndarray]:
    vs, fs, k = [], [], 0
    for _, v, f, _ in parts:
        vs.append(v)
        fs.append(f + k)
        k += len(v)
    return np.vstack(vs), np.vstack(fs)


def profile_top(fn: Callable[[], Any], calls: int = 5, top: int = 8) -> list[dict]:
    """cProfile ``calls`` runs of ``fn``; the ``top`` functions by self time (share of the total).
    The profiler slows Python code more than native code, so shares are indicative."""
    import cProfile
    import pstats

    prof = cProfile.Profile()
    prof.enable()
    for _ in range(calls):
        fn()
    prof.disable()
    st = pstats.Stats(prof)
    total = st.total_tt or 1e-12
    rows = []
    for (path, line, func), (_cc, nc, tt, ct, _) in st.stats.items():
        name = func if path == "~" else f"{_short(path)}:{line}({func})"
        rows.append({"function": name, "self_share": tt / total, "cum_share": ct / total,
                     "calls_per_run": nc / calls, "self_s_per_run": tt / calls})
    rows.sort(key=lambda r: -r["self_share"])
    return rows[:top]


def _short(path: str) -> str:
    for marker in ("/server/", "/client/", "/schemas/", "/benchmarks/", "site-packages/"):
        if marker in path:
            return marker.strip("/").replace("site-packages", "") + "/" + path.split(marker, 1)[1] if marker != "site-packages/" else path.split(marker, 1)[1]
    return path.rsplit("/", 1)[-1]


def profile_table(tid: str, title: str, rows: list[dict], note: str) -> Table:
    return Table(tid, title, ["function", "self time", "share of run (self)", "share (cumulative)", "calls per run"],
                 [[r["function"], fmt_time(r["self_s_per_run"]), f"{100 * r['self_share']:.0f} %",
                   f"{100 * r['cum_share']:.0f} %", f"{r['calls_per_run']:,.0f}"] for r in rows],
                 [note, "cProfile: Python-level costs are inflated relative to native code; read the ranking, not "
                        "the absolute times."])
