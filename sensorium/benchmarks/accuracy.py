"""Accuracy vs time of every knob that trades one for the other, each against an exact reference
(closed-form float64 intersections, or a converged quadrature) on a scene built for it."""

from __future__ import annotations

import math
import time

import numpy as np

from .common import (
    ROOM_LIDAR_AT,
    Config,
    Plot,
    Section,
    Series,
    Shape,
    Table,
    exact_cast,
    fmt_len,
    fmt_time,
    identity_table,
    interleaved,
    lidar_device,
    lidar_dirs,
    make_sim,
    median,
    room_shapes,
    room_world,
    timed,
)


def run(cfg: Config) -> Section:
    sec = Section("accuracy", "Accuracy vs time, knob by knob", intro=(
        "Each knob is measured on a scene built for it, against an exact reference: closed-form "
        "float64 ray/shape intersections (boxes, spheres, cylinders, capsules, planes) or, for the "
        "distance-sensor cone, a converged quadrature of the ideal cone integral. Times are medians "
        "of repeated in-process runs (`Simulation.step()` or `RayEngine.cast`). Each knob gets a "
        "table and a Pareto plot (error vs time; down-left is better)."))
    for knob in (precision_knob, distance_rays_knob, lidar_resolution_knob, tessellation_knob,
                 occlusion_knob, noise_knob, point_cloud_knob):
        t0 = time.perf_counter()
        knob(cfg, sec)
        cfg.log(f"  accuracy/{knob.__name__}: {time.perf_counter() - t0:.1f} s")
    return sec


def _steps_timed(fns: dict, cfg: Config, min_s: float) -> dict:
    """Median seconds per call of several step functions, alternating call by call (so an on/off
    pair sees the same machine load)."""
    one = max(1e-4, max(timed(f, 1, warmup=1) for f in fns.values()))
    rounds = max(cfg.repeat, min(200, int(min_s / one)))
    return {k: median(v) for k, v in interleaved(fns, rounds, warmup=0).items()}


def _modes_timed(eng, modes, cast, cfg: Config, min_s: float) -> dict:
    """Median time of ``cast()`` in each precision mode, the modes alternating call by call, and
    the result of each mode's last call."""
    out = {}

    def runner(mode):
        def go():
            eng.precision = mode
            out[mode.value] = cast()
        return go

    fns = {m.value: runner(m) for m in modes}
    one = max(1e-4, max(timed(f, 1, warmup=1) for f in fns.values()))
    rounds = max(cfg.repeat, min(200, int(min_s / one)))
    times = interleaved(fns, rounds)
    return {k: (median(v), out[k]) for k, v in times.items()}


# ---------------------------------------------------------------------------- precision mode
def precision_knob(cfg: Config, sec: Section) -> None:
    """FAST (Embree float32 hit) vs EXACT (float64 refinement) on flat faces, near and far from
    the origin. Two scene families: a compact cluster far away (the engine anchors each Embree
    scene at its own centre, so FAST stays precise), and a world that spans the origin to the
    cluster (a landmark at the origin: float32 resolution then follows the world's size)."""
    from sensorium.server.raycast.engine import Precision, RayKind

    n = cfg.pick(65536, 8192)
    offsets = cfg.pick([0.0, 1e2, 1e4, 1e6], [0.0, 1e4, 1e6])
    rng = np.random.default_rng(7)
    rows, series = [], {}
    data = []
    for spans in (False, True):
        for x0 in offsets:
            if spans and x0 == 0.0:
                continue
            c = np.array([x0, 0.5 * x0, 0.0])
            target = Shape("box", tuple(c + [6.0, 0.0, 0.0]), size=(2.0, 3.0, 1.5), yaw=0.35, name="target")
            shapes = [target]
            if spans:
                shapes.append(Shape("box", (0.0, 0.0, 0.0), size=(1.0, 1.0, 1.0), name="landmark"))
            sim = make_sim({"solids": [s.solid() for s in shapes]}, "exact")
            eng = sim.scene.engine
            # rays from the sensor point toward random points of the target's faces seen from it
            pts = rng.uniform(-0.48, 0.48, size=(n, 3)) * np.array([2.0, 3.0, 1.5])
            pts = pts @ target.R.T + np.asarray(target.pos)
            O = np.broadcast_to(c + rng.uniform(-0.2, 0.2, size=3), (n, 3)).copy()
            D = pts - O
            D /= np.linalg.norm(D, axis=1)[:, None]
            ref, _ = exact_cast(shapes, O, D)
            timing = _modes_timed(eng, (Precision.FAST, Precision.EXACT),
                                  lambda: eng.cast(O, D, 0.0, np.inf, kind=RayKind.VISUAL), cfg, cfg.pick(0.6, 0.1))
            for mode in (Precision.FAST, Precision.EXACT):
                t, hits = timing[mode.value]
                err = np.abs(hits.distance - ref)
                off = int(np.sum(err > 1e-6))
                label = ("world spans 0…x0" if spans else "compact cluster at x0")
                rows.append([label, f"{x0:g} m", mode.value, fmt_len(float(np.median(err))), fmt_len(float(np.max(err))),
                             f"{off} ({100 * off / n:.2f} %)", fmt_time(t), f"{t / n * 1e9:.0f}"])
                series.setdefault(f"{mode.value}, {label}", Series(f"{mode.value}, {label}", [], [], []))
                s = series[f"{mode.value}, {label}"]
                s.x.append(t / n * 1e9)
                s.y.append(max(float(np.max(err)), 1e-16))
                s.labels.append(f"{x0:g}")
                data.append({"spans_origin": spans, "offset_m": x0, "mode": mode.value, "rays": n, "time_s": t,
                             "err_median_m": float(np.median(err)), "err_max_m": float(np.max(err)), "rays_off_1um": off})
    sec.tables.append(Table("precision", "Precision mode: FAST (float32 Embree hit) vs EXACT (float64 refinement)",
                            ["scene", "offset x0", "mode", "median |error|", "max |error|", "rays off by > 1 µm",
                             f"time / {n} rays", "ns / ray"],
                            rows, notes=[
                                "Flat faces only (a rotated box), so the error is float precision alone; curved "
                                "shapes add the tessellation error of the next tables in FAST mode.",
                                "Reference: float64 slab intersection in the box's frame.",
                            ]))
    sec.plots.append(Plot("precision", "Precision mode (labels: offset x0 in m)", "time per ray (ns)",
                          "max |range error| (m)", list(series.values()), logx=False, kind="pareto"))
    sec.data["precision"] = data
    worst_fast = max(d["err_max_m"] for d in data if d["mode"] == "fast" and d["spans_origin"])
    fast_t = median([d["time_s"] for d in data if d["mode"] == "fast"])
    ratio = median([d["time_s"] for d in data if d["mode"] == "exact"]) / fast_t
    text = (f"Precision: EXACT costs {ratio:.2f}× FAST per ray here (median over the scenes); it removes FAST's float32 "
            f"errors, up to {fmt_len(worst_fast)} when the world spans the origin to {max(offsets):g} m. A compact scene "
            "far from the origin is already precise in FAST (each Embree scene is anchored at its centre).")
    bad = [d for d in data if d["mode"] == "exact" and d["rays_off_1um"] > 0]
    if bad:
        text += (" EXACT is not exact everywhere: " + "; ".join(
            f"{d['rays_off_1um']} of {d['rays']:,} rays off by up to {fmt_len(d['err_max_m'])} when the world spans "
            f"0…{d['offset_m']:g} m" for d in bad)
            + " (rays near the box's edges: the float64 refinement keeps the plane of the triangle float32 Embree "
            "picked, and at that scale float32 can pick the adjacent face).")
    sec.findings.append(text)
    compact_fast = max(d["err_max_m"] for d in data if d["mode"] == "fast" and not d["spans_origin"])
    saving = (f"saves {100 * (1 - 1 / ratio):.0f} % of the ray time" if ratio >= 1.05
              else "saves no measurable ray time here")
    sec.findings.append(
        f"What this means for you: EXACT (the default) gives the float64 answer in every scene measured here; `--precision fast` "
        f"{saving} and is safe for a compact scene (within {fmt_len(compact_fast)} wherever "
        f"it sits on flat faces, curved shapes as tessellated), not for one world spanning the origin to "
        f"{max(offsets):g} m (off by up to {fmt_len(worst_fast)}). The knobs below (rays per distance sensor, lidar resolution, tessellation, occlusion, noise) each "
        "list the error you buy with time; pick from their Pareto plots.")


# ---------------------------------------------------------------------------- distance-sensor rays
def _cone_reference(aperture: float, g: float, dist_fn, n_theta: int = 256, n_alpha: int = 1024) -> float:
    """Ideal reading: the Gaussian-weighted solid-angle average over the cone,
    ∫∫ w(θ) r(θ, α) sinθ dθ dα / ∫∫ w(θ) sinθ dθ dα, w = exp(-(θ/(aperture·g))²)."""
    x, wq = np.polynomial.legendre.leggauss(n_theta)
    half = aperture / 2.0
    theta = (x + 1.0) * half / 2.0
    wt = wq * half / 2.0 * np.exp(-(theta / (aperture * g)) ** 2) * np.sin(theta)
    alpha = (np.arange(n_alpha) + 0.5) * 2 * math.pi / n_alpha
    r = dist_fn(theta[:, None], alpha[None, :])        # (n_theta, n_alpha)
    return float((wt[:, None] * r).sum() / (wt.sum() * n_alpha))


def _edge_reference(aperture: float, g: float, h: float, e: float, rmax: float, n: int = 400) -> float:
    """Wall x = h covering y <= e: per θ the α-fraction that hits is closed form
    (sin α <= e / (h tan θ)), then Gauss–Legendre in θ, split at the kink tan θ* = e / h."""
    half = aperture / 2.0
    kink = math.atan2(abs(e), h)
    parts = [(0.0, min(kink, half))] + ([(kink, half)] if kink < half else [])
    num = den = 0.0
    for a, b in parts:
        x, wq = np.polynomial.legendre.leggauss(n)
        th = (x + 1.0) * (b - a) / 2.0 + a
        w = wq * (b - a) / 2.0 * np.exp(-(th / (aperture * g)) ** 2) * np.sin(th)
        with np.errstate(divide="ignore"):
            k = e / (h * np.tan(th))
        frac = np.where(k >= 1.0, 1.0, np.where(k <= -1.0, 0.0, (math.pi + 2.0 * np.arcsin(np.clip(k, -1, 1))) / (2 * math.pi)))
        r = frac * (h / np.cos(th)) + (1.0 - frac) * rmax
        num += float((w * r).sum())
        den += float(w.sum())
    return num / den


def distance_rays_knob(cfg: Config, sec: Section) -> None:
    aperture, g, h, beta, rmax = 0.8, 1.0, 0.5, 0.6, 1.0
    counts = cfg.pick([1, 2, 3, 4, 5, 6, 8, 10, 16, 32, 64, 128, 256, 1024], [1, 3, 8, 64])
    n_vec = np.array([math.cos(beta), math.sin(beta), 0.0])
    tilted = Shape("box", tuple((h + 0.05) * n_vec), size=(0.1, 6.0, 6.0), yaw=beta, name="wall")
    e = 0.05
    edge = Shape("box", (h + 0.05, e - 1.5, 0.0), size=(0.1, 3.0, 3.0), name="wall")

    def tilted_r(theta, alpha):
        nd = math.cos(beta) * np.cos(theta) + math.sin(beta) * np.sin(theta) * np.sin(alpha)
        return h / nd

    refs = {"tilted wall (β = 0.6 rad)": (tilted, _cone_reference(aperture, g, tilted_r)),
            "wall edge across the cone": (edge, _edge_reference(aperture, g, h, e, rmax))}
    rows, series, data = [], [], []
    for label, (wall, ref) in refs.items():
        s = Series(label, [], [], [])
        sims, values = {}, {}
        for n in counts:
            dev = {"device": "DistanceSensor", "name": "ds", "type": "generic", "number_of_rays": n,
                   "aperture": aperture, "gaussian_width": g, "lookup_table": identity_table(rmax)}
            sim = make_sim({"world_info": {"basic_time_step": 8}, "solids": [wall.solid()],
                            "robots": [{"name": "r", "devices": [dev]}]}, "exact")
            ds = sim.device("r/ds")
            ds.enable(8)
            sim.step()
            sims[n], values[n] = sim, ds.value
        times = _steps_timed({n: sim.step for n, sim in sims.items()}, cfg, cfg.pick(1.0, 0.1))
        for n in counts:
            value, t = values[n], times[n]
            err = abs(value - ref)
            rows.append([label, n, f"{value:.6f}", f"{ref:.6f}", fmt_len(err), fmt_time(t)])
            s.x.append(t * 1e6)
            s.y.append(max(err, 1e-12))
            s.labels.append(str(n))
            data.append({"scene": label, "rays": n, "value": value, "reference": ref, "abs_err_m": err, "step_s": t})
        series.append(s)
    sec.tables.append(Table("distance_rays", "Distance sensor: number of rays vs the ideal cone integral",
                            ["scene", "rays", "reading (m)", "ideal (m)", "|error|", "step time"], rows, notes=[
                                f"Generic sensor, aperture {aperture} rad, gaussianWidth {g}, identity lookup table up to "
                                f"{rmax} m (reading = averaged distance), wall at {h} m; EXACT mode.",
                                "Ideal: ∫∫ w(θ)·r(θ,α) sinθ dθ dα / ∫∫ w(θ) sinθ dθ dα over the cone, w = exp(-(θ/(aperture·g))²); "
                                "Gauss–Legendre in θ (400 nodes per smooth piece), closed form or 1024 points in α (converged to < 1e-8 m).",
                                "Step time = one `Simulation.step()` measuring this one sensor (ray planning, cast, reduction); "
                                "the ray counts of a scene are timed in alternation. The discrete layout converges slowly "
                                "and not monotonically (Webots' fixed patterns up to 10 rays, then rings of 3c+1 rays "
                                "with its azimuth quirk).",
                            ]))
    sec.plots.append(Plot("distance_rays", "Distance sensor rays (labels: numberOfRays)", "step time (µs)",
                          "|reading − ideal cone integral| (m)", series, kind="pareto"))
    sec.data["distance_rays"] = data
    best = {}
    for d in data:
        best.setdefault(d["scene"], []).append(d)
    parts = []
    for k, v in best.items():
        one = next(x for x in v if x["rays"] == 1) if any(x["rays"] == 1 for x in v) else v[0]
        big = v[-1]
        parts.append(f"{k}: {fmt_len(one['abs_err_m'])} with 1 ray → {fmt_len(big['abs_err_m'])} with {big['rays']} rays "
                     f"for {big['step_s'] / one['step_s']:.1f}× the step time")
    sec.findings.append("Distance-sensor rays: " + "; ".join(parts) + ".")


# ---------------------------------------------------------------------------- lidar resolution
def _nearest_beam_ranges(img: np.ndarray, W: int, L: int, az: np.ndarray, el: np.ndarray,
                         fov: float, vfov: float) -> np.ndarray:
    j = np.rint((fov / 2.0 - az) / (fov / W) - 0.5).astype(np.int64) % W
    if L == 1:
        i = np.zeros(len(el), dtype=np.int64)
    else:
        i = np.clip(np.rint((vfov / 2.0 - el) / (vfov / (L - 1))).astype(np.int64), 0, L - 1)
    return img[i, j]


def lidar_resolution_knob(cfg: Config, sec: Section) -> None:
    fov, vfov = 2 * math.pi, 0.5
    configs = cfg.pick([(64, 16), (128, 16), (256, 16), (512, 16), (1024, 16), (2048, 16), (4096, 16),
                        (1024, 1), (1024, 4), (1024, 8), (1024, 32), (1024, 64)],
                       [(128, 16), (512, 16), (1024, 4), (1024, 16)])
    shapes = room_shapes()
    rng = np.random.default_rng(3)
    m = cfg.pick(200_000, 20_000)
    az = rng.uniform(-math.pi, math.pi, m)
    el = rng.uniform(-vfov / 2, vfov / 2, m)
    Dref = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], 1)
    O = np.broadcast_to(np.asarray(ROOM_LIDAR_AT), (m, 3))
    truth, _ = exact_cast(shapes, O, Dref, 0.01)
    rows, data = [], []
    ser = {"columns (16 layers)": Series("horizontal resolution (16 layers)", [], [], []),
           "layers (1024 columns)": Series("layers (1024 columns)", [], [], [])}
    for W, L in configs:
        sim = make_sim(room_world([lidar_device("lidar", W, L, fov=fov, vfov=vfov)]), "exact")
        dev = sim.device("r/lidar")
        dev.enable(32)
        sim.step()
        t = timed(sim.step, cfg.pick(5, 3), min_total_s=cfg.pick(0.2, 0.0))
        img = dev.range_image.astype(np.float64)
        beams = lidar_dirs(W, L, fov, vfov)
        bt, _ = exact_cast(shapes, np.broadcast_to(np.asarray(ROOM_LIDAR_AT), beams.shape), beams, 0.01)
        beam_err = float(np.max(np.abs(img.reshape(-1) - bt)))
        pred = _nearest_beam_ranges(img, W, L, az, el, fov, vfov)
        err = np.abs(pred - truth)
        mean, p90 = float(err.mean()), float(np.percentile(err, 90))
        rows.append([W, L, W * L, fmt_len(beam_err), f"{mean * 100:.2f} cm", f"{p90 * 100:.2f} cm", fmt_time(t)])
        data.append({"columns": W, "layers": L, "rays": W * L, "beam_err_max_m": beam_err, "map_err_mean_m": mean,
                     "map_err_p90_m": p90, "step_s": t})
        if L == 16 and W in [c[0] for c in configs if c[1] == 16]:
            s = ser["columns (16 layers)"]
            s.x.append(t * 1e3), s.y.append(mean), s.labels.append(f"{W}×{L}")
        if W == 1024:
            s = ser["layers (1024 columns)"]
            s.x.append(t * 1e3), s.y.append(mean), s.labels.append(f"{W}×{L}")
    sec.tables.append(Table("lidar_resolution", "Lidar: horizontal resolution and layers vs map error and time",
                            ["columns", "layers", "rays", "max beam error", "map error (mean)", "map error (p90)", "step time"],
                            rows, notes=[
                                f"Fixed 360° lidar, vertical FOV {vfov} rad, in the 8 m × 6 m benchmark room (walls, "
                                "pillars, crate, ball, bollard); EXACT mode.",
                                f"Map error: for {m:,} random directions in the lidar's field of view, the range the scan "
                                "predicts (its nearest beam) vs the exact range in that direction — what a map built "
                                "from the scan gets wrong between beams. Max beam error: each beam vs its exact range.",
                            ]))
    sec.plots.append(Plot("lidar_resolution", "Lidar resolution (labels: columns×layers)", "step time (ms)",
                          "mean map error (m)", list(ser.values()), kind="pareto"))
    sec.data["lidar_resolution"] = data
    lo, hi = data[0], max((d for d in data if d["layers"] == 16), key=lambda d: d["columns"])
    sec.findings.append(
        f"Lidar resolution: {lo['columns']}×{lo['layers']} → {hi['columns']}×{hi['layers']} cuts the mean map error "
        f"from {lo['map_err_mean_m'] * 100:.1f} cm to {hi['map_err_mean_m'] * 100:.1f} cm for "
        f"{hi['step_s'] / lo['step_s']:.1f}× the step time; every beam itself is exact to "
        f"{fmt_len(max(d['beam_err_max_m'] for d in data))} (float32 range image).")


# ---------------------------------------------------------------------------- tessellation
def _primitive(s: Shape):
    from sensorium.server.world import geometry as geo

    if s.kind == "sphere":
        return geo.Sphere(s.radius, s.subdivision)
    if s.kind == "cylinder":
        return geo.Cylinder(s.radius, s.height, s.subdivision)
    return geo.Capsule(s.radius, s.height, s.subdivision)


def tessellation_knob(cfg: Config, sec: Section) -> None:
    from sensorium.server.raycast.engine import Precision, RayKind
    from sensorium.server.world.geometry import triangle_count

    n = cfg.pick(20000, 5000)
    rng = np.random.default_rng(11)
    cases = {
        "sphere r 0.5": (lambda k: Shape("sphere", (2.0, 0.0, 0.0), radius=0.5, subdivision=k, name="s"),
                         cfg.pick([0, 1, 2, 3, 4, 5, 6], [0, 3, 4])),
        "cylinder r 0.3": (lambda k: Shape("cylinder", (2.0, 0.0, 0.0), radius=0.3, height=1.0, subdivision=k, name="s"),
                           cfg.pick([6, 12, 24, 36, 72, 144, 288, 1024], [6, 36])),
        "capsule r 0.2": (lambda k: Shape("capsule", (2.0, 0.0, 0.0), radius=0.2, height=0.6, subdivision=k, name="s"),
                          cfg.pick([2, 4, 8, 12, 24, 48, 96], [2, 12])),
    }
    defaults = {"sphere r 0.5": 3, "cylinder r 0.3": 36, "capsule r 0.2": 12}
    rows, series, data = [], [], []
    for label, (make, levels) in cases.items():
        # rays from the origin over the shape's angular extent (+5 %, so silhouettes are crossed)
        probe = make(defaults[label])
        half_w = math.atan2(probe.radius, 2.0) * 1.05
        half_h = math.atan2(max(probe.radius, probe.height / 2 + (probe.radius if probe.kind == "capsule" else 0)), 2.0) * 1.05
        if probe.kind == "sphere":
            half_h = half_w
        a = rng.uniform(-half_w, half_w, n)
        b = rng.uniform(-half_h, half_h, n)
        D = np.stack([np.cos(b) * np.cos(a), np.cos(b) * np.sin(a), np.sin(b)], 1)
        O = np.zeros((n, 3))
        s_fast = Series(f"{label}, FAST", [], [], [])
        s_exact = Series(f"{label}, EXACT", [], [], [])
        for k in levels:
            shape = make(k)
            ref, _ = exact_cast([shape], O, D)
            sim = make_sim({"solids": [shape.solid()]}, "fast")
            eng = sim.scene.engine
            tris = triangle_count(_primitive(shape))
            t0 = time.perf_counter()
            eng.cast(O[:1], D[:1], kind=RayKind.VISUAL)           # builds the BVH
            build = time.perf_counter() - t0
            modes = (Precision.FAST, Precision.EXACT) if k in (levels[0], defaults[label], levels[-1]) else (Precision.FAST,)
            timing = _modes_timed(eng, modes, lambda: eng.cast(O, D, kind=RayKind.VISUAL), cfg, cfg.pick(0.4, 0.06))
            for mode, ser in ((Precision.FAST, s_fast), (Precision.EXACT, s_exact)):
                if mode.value not in timing:
                    continue
                t, hits = timing[mode.value]
                dist = hits.distance
                both = np.isfinite(dist) & np.isfinite(ref)
                err = np.abs(dist[both] - ref[both])
                wrong = int(np.sum(np.isfinite(dist) != np.isfinite(ref)))
                mean = float(err.mean()) if len(err) else float("nan")
                mx = float(err.max()) if len(err) else float("nan")
                rows.append([label, k, tris, mode.value, fmt_len(mean), fmt_len(mx), f"{100 * wrong / n:.2f} %",
                             fmt_time(t), fmt_time(build)])
                ser.x.append(t / n * 1e9)
                ser.y.append(max(mx, 1e-16))
                ser.labels.append(str(k))
                data.append({"shape": label, "subdivision": k, "triangles": tris, "mode": mode.value, "err_mean_m": mean,
                             "err_max_m": mx, "hit_miss_disagree": wrong / n, "time_s": t, "rays": n, "build_s": build})
        series += [s_fast, s_exact]
    sec.tables.append(Table("tessellation", "Tessellation of curved primitives vs range error",
                            ["shape", "subdivision", "triangles", "mode", "mean |error| (both hit)", "max |error|",
                             "hit/miss disagreements", f"time / {n} rays", "BVH build"], rows, notes=[
                                "Curved primitives are tessellated as circumscribed shells. FAST reports the shell; "
                                "EXACT re-intersects the true surface (so its error does not depend on the subdivision).",
                                "Rays from 2 m away cover the shape's angular extent + 5 %, so silhouette rays are "
                                "included: 'disagreements' are rays the shell catches but the true shape does not "
                                "(or the reverse). Reference: closed-form float64 intersection.",
                                "Defaults: sphere subdivision 3 (icosphere level), cylinder 36 sides, capsule 12.",
                            ]))
    sec.plots.append(Plot("tessellation", "Tessellation (labels: subdivision)", "time per ray (ns)",
                          "max |range error| (m)", series, logx=False, kind="pareto"))
    sec.data["tessellation"] = data
    parts = []
    for label in cases:
        dflt = next(d for d in data if d["shape"] == label and d["mode"] == "fast" and d["subdivision"] == defaults[label])
        ex = next(d for d in data if d["shape"] == label and d["mode"] == "exact" and d["subdivision"] == defaults[label])
        parts.append(f"{label} at its default subdivision: FAST max error {fmt_len(dflt['err_max_m'])} "
                     f"({100 * dflt['hit_miss_disagree']:.1f} % silhouette disagreements), EXACT {fmt_len(ex['err_max_m'])} "
                     f"for {ex['time_s'] / dflt['time_s']:.1f}× the time")
    sec.findings.append("Tessellation: " + "; ".join(parts) + ".")


# ---------------------------------------------------------------------------- light occlusion
def occlusion_knob(cfg: Config, sec: Section) -> None:
    from sensorium.server.devices import light as light_math
    from sensorium.server.sim.simulation import lights_from_models

    grid = cfg.pick(10, 6)
    lights = [{"type": "PointLight", "name": f"l{i}", "location": [x, y, 2.0], "intensity": 1.0,
               "attenuation": [1.0, 0.0, 0.0]} for i, (x, y) in enumerate([(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.2, 1.3)])]
    occluder = Shape("box", (0.3, 0.2, 1.0), size=(0.8, 0.8, 0.05), name="occluder")
    table = identity_table(100.0)
    xs = np.linspace(-1.0, 1.0, grid)
    positions = [(float(x), float(y), 0.05) for x in xs for y in xs]
    rows, series, data = [], [], []
    results, sims = {}, {}
    for occl in (False, True):
        devs = [{"device": "LightSensor", "name": f"ls{i}", "pose": {"translation": list(p), "rotation": [0, 1, 0, -math.pi / 2]},
                 "lookup_table": table, "occlusion": occl} for i, p in enumerate(positions)]
        world = {"world_info": {"basic_time_step": 8}, "solids": [occluder.solid()], "lights": lights,
                 "robots": [{"name": "r", "devices": devs}]}
        sim = make_sim(world, "exact")
        for d in sim.all_devices():
            d.enable(8)
        sim.step()
        results[occl] = np.array([sim.device(f"r/ls{i}").value for i in range(len(positions))])
        sims[occl] = sim
        la = lights_from_models(sim.world.lights)
    times = _steps_timed({k: v.step for k, v in sims.items()}, cfg, cfg.pick(1.0, 0.15))
    results = {k: (v, times[k]) for k, v in results.items()}
    # exact: the spec's irradiance with exact float64 visibility (segment vs the occluder)
    exact = []
    for p in positions:
        P = np.asarray(p, dtype=np.float64).reshape(1, 3)
        u, length = light_math.occlusion_segments_many(P, la)
        t_hit, _ = exact_cast([occluder], np.repeat(P, la.count, axis=0), u[0], 0.0, np.inf)
        occluded = (t_hit <= length[0]).reshape(1, -1)
        exact.append(float(light_math.irradiance_many(P, np.array([[0.0, 0.0, 1.0]]), la, occluded)[0]))
    exact = np.asarray(exact)
    shadowed = int(np.sum(np.abs(results[False][0] - exact) > 1e-12))
    for occl in (False, True):
        values, t = results[occl]
        err = np.abs(values - exact)
        rel = err / np.maximum(np.abs(exact), 1e-12)
        wrong = int(np.sum(err > 1e-9 * np.maximum(1.0, np.abs(exact))))
        rows.append(["on" if occl else "off", len(positions), f"{float(err.mean()):.4g}", f"{float(err.max()):.4g}",
                     f"{100 * float(rel.max()):.1f} %", wrong, fmt_time(t), fmt_time(t / len(positions))])
        series.append(Series(f"occlusion {'on' if occl else 'off'}", [t * 1e3], [max(float(err.max()), 1e-16)],
                             ["on" if occl else "off"]))
        data.append({"occlusion": occl, "sensors": len(positions), "lights": len(lights), "err_mean": float(err.mean()),
                     "err_max": float(err.max()), "rel_err_max": float(rel.max()), "wrong": wrong, "step_s": t})
    sec.tables.append(Table("occlusion", "Light sensors: occlusion on vs off",
                            ["occlusion", "sensors", "mean |error|", "max |error|", "max relative error",
                             "sensors wrong", "step time", "per sensor"], rows, notes=[
                                f"{len(positions)} upward-facing light sensors on a {grid}×{grid} grid, 4 point lights "
                                f"2 m up, one 0.8 m × 0.8 m plate casting shadows on {shadowed} of them. Identity lookup "
                                "table (value = irradiance, W/m²).",
                                "Reference: the LightSensor formula with exact float64 visibility (segment vs plate).",
                            ]))
    sec.plots.append(Plot("occlusion", "Light occlusion", "step time (ms)", "max |error| (W/m²)", series,
                          logx=False, kind="pareto"))
    sec.data["occlusion"] = data
    off, on = data
    sec.findings.append(
        f"Light occlusion: on removes a max error of {off['err_max']:.3g} W/m² ({100 * off['rel_err_max']:.0f} %, "
        f"{off['wrong']} of {off['sensors']} sensors wrong) for {on['step_s'] / off['step_s']:.2f}× the step time; "
        f"with it on, {on['wrong']} sensors differ from the exact value.")


# ---------------------------------------------------------------------------- noise
def noise_knob(cfg: Config, sec: Section) -> None:
    W, L = cfg.pick((1024, 16), (512, 8))
    shapes = room_shapes()
    beams = lidar_dirs(W, L)
    truth, _ = exact_cast(shapes, np.broadcast_to(np.asarray(ROOM_LIDAR_AT), beams.shape), beams, 0.01)
    max_range = 20.0
    rows, data = [], []
    lidar_levels, ds_levels = (0.0, 0.0005, 0.005), (0.0, 0.01, 0.05)
    sims, rmse = {}, {}
    for noise in lidar_levels:
        sim = make_sim(room_world([lidar_device("lidar", W, L, max_range=max_range, noise=noise)]), "exact")
        dev = sim.device("r/lidar")
        dev.enable(32)
        sim.step()
        img = dev.range_image.astype(np.float64).reshape(-1)
        ok = np.isfinite(img) & np.isfinite(truth)
        rmse[("lidar", noise)] = float(np.sqrt(np.mean((img[ok] - truth[ok]) ** 2)))
        sims[("lidar", noise)] = sim
    # distance sensors: relative noise in the lookup table's third column
    wall = Shape("box", (0.55, 0.0, 0.0), size=(0.1, 4.0, 4.0), name="wall")
    for noise in ds_levels:
        devs = [{"device": "DistanceSensor", "name": f"ds{i}", "type": "generic", "number_of_rays": 1,
                 "pose": {"translation": [0.0, 0.0, 0.01 * i]}, "lookup_table": identity_table(1.0, noise)} for i in range(8)]
        sim = make_sim({"world_info": {"basic_time_step": 8}, "solids": [wall.solid()], "robots": [{"name": "r", "devices": devs}]}, "exact")
        for d in sim.all_devices():
            d.enable(8)
        vals = []
        for _ in range(cfg.pick(100, 20)):
            sim.step()
            vals += [d.value for d in sim.all_devices()]
        rmse[("distance", noise)] = float(np.sqrt(np.mean((np.asarray(vals) - 0.5) ** 2)))
        sims[("distance", noise)] = sim
    times = {}
    for kind in ("lidar", "distance"):
        times.update(_steps_timed({k: v.step for k, v in sims.items() if k[0] == kind}, cfg, cfg.pick(1.5, 0.2)))
    s_lidar = Series(f"lidar {W}×{L}", [], [], [])
    s_ds = Series("8 distance sensors", [], [], [])
    for (kind, noise), t in times.items():
        err = rmse[(kind, noise)]
        if kind == "lidar":
            rows.append([f"lidar {W}×{L}", f"noise {noise:g}", f"{noise * max_range:g} m", fmt_len(err), fmt_time(t)])
            ser, sigma = s_lidar, noise * max_range
        else:
            rows.append(["8 distance sensors", f"table noise {noise:g}", f"{noise * 0.5:g} m at 0.5 m", fmt_len(err), fmt_time(t)])
            ser, sigma = s_ds, noise * 0.5
        ser.x.append(t * 1e3), ser.y.append(max(err, 1e-12)), ser.labels.append(f"{noise:g}")
        data.append({"device": kind, "noise": noise, "sigma_m": sigma, "rmse_m": err, "step_s": t})
    sec.tables.append(Table("noise", "Noise on vs off", ["device", "setting", "σ", "RMS error vs exact", "step time"], rows, notes=[
        f"Lidar in the benchmark room (max range {max_range} m, σ = noise · maxRange); distance sensors 0.5 m from a "
        "wall with an identity table whose noise column is relative (σ = noise · value). EXACT mode; the settings "
        "of each device are timed in alternation.",
        "Noise is a fidelity knob, not an error to remove: the RMS error should equal σ, and the time column is "
        "what the random draws cost.",
    ]))
    sec.plots.append(Plot("noise", "Noise (labels: noise setting)", "step time (ms)", "RMS error vs exact (m)",
                          [s_lidar, s_ds], logx=False, kind="pareto"))
    sec.data["noise"] = data
    lid = [d for d in data if d["device"] == "lidar"]
    dsd = [d for d in data if d["device"] == "distance"]
    pairs = ", ".join(f"σ {d['sigma_m']:g} m → {d['rmse_m']:.2g} m" for d in lid)
    sec.findings.append(
        f"Noise: the lidar's RMS error follows σ ({pairs}); drawing it costs {lid[-1]['step_s'] / lid[0]['step_s']:.2f}× "
        f"the noiseless step time (distance sensors: {dsd[-1]['step_s'] / dsd[0]['step_s']:.2f}×).")


# ---------------------------------------------------------------------------- point cloud
def point_cloud_knob(cfg: Config, sec: Section) -> None:
    from sensorium.schemas.wire import pack
    from sensorium.server.daemon.topics import header, image_msg, lidar_cloud_msg
    from sensorium.server.devices import lidar as lmath

    W, L = cfg.pick((1024, 64), (512, 32))
    shapes = room_shapes()
    beams = lidar_dirs(W, L)
    O = np.broadcast_to(np.asarray(ROOM_LIDAR_AT), beams.shape)
    truth, _ = exact_cast(shapes, O, beams, 0.01)
    exact_pts = beams * truth[:, None]                     # lidar frame = world axes here
    rows, series, data = [], [], []
    steps, sizes, devs = {}, {}, {}
    for on in (False, True):
        sim = make_sim(room_world([lidar_device("lidar", W, L)]), "exact")
        dev = sim.device("r/lidar")
        dev.enable(32)
        if on:
            dev.enable_point_cloud()

        def step(sim=sim, dev=dev, on=on):
            sim.step()
            hdr = header("r/lidar", sim.time_ms)
            size = len(pack(image_msg(hdr, L, W, np.ascontiguousarray(dev.range_image, dtype="<f4").tobytes())))
            if on:
                size += len(pack(lidar_cloud_msg(hdr, dev)))      # what the server publishes
            return size

        sizes[on] = step()
        steps[on], devs[on] = step, dev
    times = _steps_timed({k: v for k, v in steps.items()}, cfg, cfg.pick(2.0, 0.2))
    # the added work itself, timed alone, as a step does it: the points from the range image, then
    # the message from the device's points
    dev = devs[True]
    hdr = header("r/lidar", 0)
    added = timed(lambda: (lmath.point_xyz(dev.range_image, dev._point_columns()), pack(lidar_cloud_msg(hdr, dev))),
                  cfg.repeat, min_total_s=cfg.pick(0.3, 0.05))
    for on in (False, True):
        t = times[on]
        if on:
            pc = dev.point_cloud
            p = np.stack([pc["x"], pc["y"], pc["z"]], 1).astype(np.float64)
            ok = np.isfinite(truth)
            err = float(np.max(np.linalg.norm(p[ok] - exact_pts[ok], axis=1)))
            err_s = fmt_len(err)
        else:
            err, err_s = None, "no points (a client computes them from the range image)"
        rows.append(["on" if on else "off", W * L, err_s, f"{sizes[on] / 1e6:.2f} MB", fmt_time(t),
                     fmt_time(added) if on else "–"])
        series.append(Series(f"point cloud {'on' if on else 'off'}", [t * 1e3], [err if err else 1.0], ["on" if on else "off"]))
        data.append({"point_cloud": on, "points": W * L, "err_max_m": err, "message_bytes": sizes[on], "step_s": t,
                     "added_work_s": added if on else 0.0})
    sec.tables.append(Table("point_cloud", "Lidar point cloud on vs off",
                            ["point cloud", "beams", "max point error vs exact hit point", "message bytes", "step + messages",
                             "cloud + its message alone"], rows, notes=[
                                f"Fixed 360° lidar {W}×{L} in the benchmark room, EXACT mode; time = `Simulation.step()` "
                                "plus building and packing its Image (and PointCloud) messages, on and off timed in "
                                "alternation. The last column times the added work alone (point records from the range "
                                "image + the PointCloud message), which the scan's own variance can hide.",
                            ]))
    sec.plots.append(Plot("point_cloud", "Point cloud ('off' plotted at 1 m: no points)", "step + messages (ms)",
                          "max point error (m)", series, logx=False, kind="pareto"))
    sec.data["point_cloud"] = data
    off, on = data
    sec.findings.append(
        f"Point cloud: building it and its message costs {fmt_time(added)} for {W * L:,} points "
        f"({100 * added / off['step_s']:.0f} % of the {fmt_time(off['step_s'])} scan; step + messages measured "
        f"{on['step_s'] / off['step_s']:.2f}× with it on), {on['message_bytes'] / 1e6:.1f} MB of messages instead of "
        f"{off['message_bytes'] / 1e6:.2f} MB; points are within {fmt_len(on['err_max_m'])} of the exact hit points (float32).")
