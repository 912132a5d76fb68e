"""Memory: resident bytes per static triangle, and the transient memory and time per ray of large
scans (is there a cost cliff at 10^6 rays?).  Each measurement runs in a fresh interpreter, so the
numbers are deltas of that process alone (``VmRSS`` from /proc for the scene, which includes
Embree's BVH; ``tracemalloc``'s peak for a scan, which sees every numpy buffer)."""

from __future__ import annotations

import json
import subprocess
import sys
import time

from .common import Config, Section, Table, Target, fmt_time

TRI_TARGET_B = 300
SCAN_TARGET_MB = 60.0

# One child per measurement: a terrain of N triangles (the scaling section's heightfield) loaded as
# one static mesh; RSS before/after the first cast (the build); then tracemalloc's peak over one
# cast of R rays from one origin (a lidar) with distances only, and the time per ray.
_CHILD = r"""
import json, sys, time, tracemalloc
import numpy as np
from sensorium.benchmarks.scaling import _terrain
from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.world.geometry import Mesh, Pose

import ctypes
try:
    _trim = ctypes.CDLL("libc.so.6").malloc_trim   # hand freed heap pages back: RSS = live memory
except (OSError, AttributeError):
    _trim = lambda pad: 0

def rss():
    _trim(0)
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0

n_tri, rays, prec = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
mesh = _terrain(n_tri)
V, F = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
prim = Mesh(V, F, False)
before = rss()
eng = RayEngine(Precision(prec))
eng.threads = 1                      # the table says 1 thread (two would hold two blocks' temporaries)
eng.add_body([ShapeEntry(prim, Pose.identity(), True, True)], Pose.identity())
del mesh
o = np.array([[0.0, 0.0, 1.5]])
eng.cast(o, np.array([[0.3, 0.1, -1.0]]) / np.linalg.norm([0.3, 0.1, -1.0]), kind=RayKind.VISUAL)   # builds
scene = rss() - before
rng = np.random.default_rng(0)
az = rng.uniform(-np.pi, np.pi, rays)
el = rng.uniform(-0.9, -0.05, rays)
D = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], 1)
O = np.broadcast_to(o[0], D.shape)
eng.cast(O, D, 0.0, 30.0, kind=RayKind.VISUAL, distance_only=True)   # one-off data made on first use
after_scan = rss() - before
tracemalloc.start()
t0 = time.perf_counter()
h = eng.cast(O, D, 0.0, 30.0, kind=RayKind.VISUAL, distance_only=True)
t = time.perf_counter() - t0
_, peak = tracemalloc.get_traced_memory()
tracemalloc.stop()
out_b = h.distance.nbytes
# per-ray time of this scan and of its first tenth, interleaved (load from other jobs hits both)
small = len(D) // 10
ts, ts_small = [t], []
for _ in range(4):
    t0 = time.perf_counter()
    eng.cast(O[:small], D[:small], 0.0, 30.0, kind=RayKind.VISUAL, distance_only=True)
    ts_small.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    eng.cast(O, D, 0.0, 30.0, kind=RayKind.VISUAL, distance_only=True)
    ts.append(time.perf_counter() - t0)
ratios = [(b / len(D)) / (a / small) for a, b in zip(ts_small, ts[1:])]   # each round's own pair
print(json.dumps({"triangles": int(len(F)), "scene_bytes": scene, "scene_after_scan_bytes": after_scan,
                  "scan_peak_bytes": peak, "output_bytes": out_b, "scan_s": min(ts),
                  "tenth_rays": small, "tenth_s": min(ts_small), "cliff": float(np.median(ratios)),
                  "hits": int(np.isfinite(h.distance).sum())}))
"""


def _child(n_tri: int, rays: int, prec: str) -> dict:
    out = subprocess.run([sys.executable, "-c", _CHILD, str(n_tri), str(rays), prec], capture_output=True,
                         text=True, timeout=900, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"memory child failed: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def run(cfg: Config) -> Section:
    sec = Section("memory", "Memory: per triangle and per scan", intro=(
        "Each row runs in a fresh interpreter: a heightfield mesh of N triangles as one static solid, its "
        "Embree scene built by a first cast; 'scene' is the growth of the process's resident memory (VmRSS, "
        "after glibc's malloc_trim so freed build temporaries do not count) over the build, Embree's BVH "
        "included, divided by the triangles. Then one cast of R rays from one "
        "origin (a lidar's layout) asking for distances only: 'scan peak' is tracemalloc's peak during that "
        "cast (every numpy buffer, the returned distances included); the time per ray is the best of 5 "
        "casts, beside the same for the first tenth of the rays, cast in alternation with the whole scan in "
        "the same process; a per-ray cost cliff shows as the ratio of the two in each round (the median over "
        "rounds is in the target: adjacent casts share the machine's load). Large casts run in 65,536-ray chunks, so the temporaries stay the same size whatever R."))
    t_start = time.perf_counter()
    n_big = cfg.pick(1_000_000, 100_000)
    rows, data = [], []
    for prec in ("fast", "exact"):
        for rays in cfg.pick((100_000, 1_000_000), (100_000, 300_000)):
            d = _child(n_big, rays, prec)
            d.update(precision=prec, rays=rays)
            data.append(d)
            rows.append([prec.upper(), f"{d['triangles']:,}", f"{d['scene_bytes'] / d['triangles']:.0f} B",
                         f"{d['scene_after_scan_bytes'] / d['triangles']:.0f} B",
                         f"{rays:,}", f"{d['scan_peak_bytes'] / 1e6:.1f} MB", f"{d['output_bytes'] / 1e6:.1f} MB",
                         fmt_time(d["scan_s"]), f"{d['scan_s'] / rays * 1e9:.0f} ns",
                         f"{d['tenth_s'] / d['tenth_rays'] * 1e9:.0f} ns"])
            cfg.log(f"  memory: {prec} {rays:,} rays: {rows[-1]}")
    sec.tables.append(Table("memory", "Memory per static triangle and per scan (1 thread)", [
        "mode", "triangles", "scene per triangle", "after a scan", "rays", "scan peak (tracemalloc)", "of which the distances",
        "scan time", "per ray", "per ray, first tenth of the rays"], rows, [
        "EXACT builds Embree's robust scene and, on its first refinement, the float64 per-triangle data "
        "(edges, dual basis, boxes); FAST keeps only what it reads (normals, shape ids, float32 copies).",
        "Reproduce: `sensorium bench --only memory` (each row is one `python -c` child; see "
        "sensorium/benchmarks/memory.py)."]))
    sec.data["memory"] = data
    fast = [d for d in data if d["precision"] == "fast"]
    per_tri = fast[0]["scene_bytes"] / fast[0]["triangles"]
    big = max(fast, key=lambda d: d["rays"])
    peak_mb = big["scan_peak_bytes"] / 1e6
    ns_small, ns_big = big["tenth_s"] / big["tenth_rays"] * 1e9, big["scan_s"] / big["rays"] * 1e9
    cliff = big["cliff"]     # median over rounds of (per-ray time, whole scan) / (per-ray time, its tenth)
    ok = per_tri <= TRI_TARGET_B and peak_mb <= SCAN_TARGET_MB and cliff < 1.25
    exact_tri = [d for d in data if d["precision"] == "exact"][0]
    sec.targets.append(Target(
        "Static scene memory per triangle; transient memory of a 10⁶-ray scan; no per-ray cliff", "≤ 300 B; ≤ 60 MB; none",
        f"{per_tri:.0f} B (FAST); {peak_mb:.1f} MB; per-ray ratio {cliff:.2f}×", ok,
        f"{fast[0]['triangles']:,}-triangle static mesh: {per_tri:.0f} B per triangle in FAST (Embree's BVH included), "
        f"{exact_tri['scene_after_scan_bytes'] / exact_tri['triangles']:.0f} B in EXACT once scanned (robust BVH, "
        f"float64 refinement data and vertex rings). "
        f"A {big['rays']:,}-ray distance-only scan peaks at {peak_mb:.1f} MB of numpy buffers, "
        f"{big['output_bytes'] / 1e6:.1f} MB of them the returned distances; per ray {ns_small:.0f} ns at "
        f"{big['tenth_rays']:,} rays and {ns_big:.0f} ns at {big['rays']:,} (best of 5 each); the per-ray ratio of "
        f"the two casts in each round, whole scan over tenth, has a median of {cliff:.2f}× (1 = no cliff)."))
    sec.findings.append(
        f"Memory: {per_tri:.0f} B per static triangle (FAST, BVH included), a {big['rays']:,}-ray scan peaks at "
        f"{peak_mb:.1f} MB; what this means for you: a 1M-triangle world fits in "
        f"{per_tri * 1e6 / 1e6:.0f} MB (FAST) and a 10⁶-ray scan needs no more than its own outputs plus a few chunks.")
    cfg.log(f"  memory: {time.perf_counter() - t_start:.0f} s")
    return sec
