"""Images (issue 23): what a camera's or range finder's picture costs, against raw embreex on the
same rays, in one interleaved run.

The bundled arena world with three devices on the e-puck (in front of its body, looking ahead):
an e-puck camera (52 × 39, fov 0.84: Webots' e-puck), a 640 × 480 camera and a 320 × 240 range
finder. Each is timed alone, enabled at the basic step, as ``sim.step()`` (the step then makes one
image; the other devices are off), beside the step with no device enabled and beside raw embreex
casting the very same rays (distances only, one scene of the world's visible triangles, planes as
two triangles: Embree's float32 floor). A camera's time is split into its casts (every
``engine.cast``: pixels, shadows, transparency) and the shading. Counters show that a disabled
device casts nothing.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import yaml

from sensorium.benchmarks.common import (
    Config,
    Section,
    Table,
    fmt_time,
    make_sim,
    median,
    merge_triangles,
    world_triangles,
)

__all__ = ["run"]

DEVICES = {
    "e-puck camera 52×39": {"device": "Camera", "name": "cam_epuck", "width": 52, "height": 39, "field_of_view": 0.84},
    "camera 640×480": {"device": "Camera", "name": "cam_vga", "width": 640, "height": 480, "field_of_view": 1.0},
    "range finder 320×240": {"device": "RangeFinder", "name": "depth", "width": 320, "height": 240,
                             "field_of_view": 1.0, "max_range": 5.0},
}
MOUNT = {"translation": [0.04, 0.0, 0.03]}       # on the e-puck's front, above its ring of sensors


def _world() -> tuple[dict, Path]:
    from sensorium.worlds import world_path

    path = world_path("arena")
    data = yaml.safe_load(path.read_text())
    data = copy.deepcopy(data)
    for r in data["robots"]:
        if r["name"] == "epuck":
            r["devices"] = [*r.get("devices", []), *({**d, "pose": MOUNT} for d in DEVICES.values())]
    return data, path.parent


class _Raw:
    """raw embreex (rtcIntersect1 loop) on the world's visible triangles."""

    def __init__(self, sim):
        from embreex import rtcore as rtc
        from embreex import rtcore_scene as rts
        from embreex.mesh_construction import TriangleMesh

        V, F = merge_triangles(world_triangles(sim))
        self.dev = rtc.EmbreeDevice()
        self.scene = rts.EmbreeScene(self.dev)
        TriangleMesh(self.scene, V.astype(np.float32), F.astype(np.int32))

    def caster(self, origin: np.ndarray, dirs: np.ndarray, far: float):
        o32 = np.ascontiguousarray(np.broadcast_to(origin, dirs.shape), dtype=np.float32)
        d32 = np.ascontiguousarray(dirs, dtype=np.float32)
        dist = np.full(len(dirs), far, dtype=np.float32)
        self.scene.run(o32[:1], d32[:1])
        return lambda: self.scene.run(o32, d32, dists=dist.copy(), query="DISTANCE")


def _interleaved_cpu(fns: dict, rounds: int) -> tuple[dict[str, list[float]], dict[str, list[float]]]:
    """Like ``common.interleaved`` (A B C A B C …, one warm-up each, gc off), with each call's
    wall-clock and CPU time (``time.process_time``)."""
    import gc
    import time

    for fn in fns.values():
        fn()
    wall: dict[str, list[float]] = {k: [] for k in fns}
    cpu: dict[str, list[float]] = {k: [] for k in fns}
    was = gc.isenabled()
    gc.disable()
    try:
        for _ in range(rounds):
            for k, fn in fns.items():
                t0, c0 = time.perf_counter(), time.process_time()
                fn()
                cpu[k].append(time.process_time() - c0)
                wall[k].append(time.perf_counter() - t0)
    finally:
        if was:
            gc.enable()
    return wall, cpu


def run(cfg: Config) -> Section:
    data, base = _world()
    rounds = cfg.pick(7, 3)
    rows, split_rows, counter_rows = [], [], []
    findings = []
    out: dict = {}
    for precision in ("fast", "exact"):
        sim = make_sim(data, precision, base_dir=base)
        robot = sim.robot("epuck")
        step = sim.basic_time_step
        sim.run(2)
        quiet = dict(sim.counters)
        counter_rows.append([precision, "none enabled (2 steps)", str(quiet.get("rays_camera", 0)),
                             str(quiet.get("rays_range_finder", 0)), str(quiet.get("engine_rays", 0))])
        raw = _Raw(sim)
        fns: dict = {"step, no device enabled": sim.step}
        raws: dict = {}
        casts: dict = {}
        for label, d in DEVICES.items():
            dev = robot.device(d["name"])
            dev.enable(step)
            sim.step()                                   # rays made and rotated once
            before = sim.counters
            sim.step()
            after = sim.counters
            kind = "rays_camera" if d["device"] == "Camera" else "rays_range_finder"
            counter_rows.append([precision, f"{label} enabled (1 step)", str(after["rays_camera"] - before["rays_camera"]),
                                 str(after["rays_range_finder"] - before["rays_range_finder"]),
                                 str(after["engine_rays"] - before["engine_rays"])])
            assert after[kind] - before[kind] >= d["width"] * d["height"]
            rays = dev._rays
            pose = dev.world_pose(robot.pose)
            far = float(d.get("max_range", 1e30))
            raws[label] = raw.caster(pose.translation, rays.world, far)
            dev.enable(0)

            def one(dev=dev):
                dev.schedule.last_update_ms = sim.time_ms - step     # due at this step
                dev.schedule.period_ms = step
                sim.step()
                dev.schedule.period_ms = 0

            fns[label] = one
            casts[label] = dev
        fns.update({f"raw embreex, {k} rays": v for k, v in raws.items()})
        times, cpu = _interleaved_cpu(fns, rounds)
        base_t, base_c = median(times["step, no device enabled"]), median(cpu["step, no device enabled"])
        for label, d in DEVICES.items():
            t, c = median(times[label]), median(cpu[label])
            tr, cr = median(times[f"raw embreex, {label} rays"]), median(cpu[f"raw embreex, {label} rays"])
            n = d["width"] * d["height"]
            rows.append([precision, label, f"{n:,}", fmt_time(t - base_t), fmt_time(c - base_c), fmt_time(tr),
                         fmt_time(cr), f"{(c - base_c) / max(cr, 1e-9):.1f}×", f"{n / max(c - base_c, 1e-12) / 1e6:.2f} M"])
            out.setdefault(precision, {})[label] = {"step_s": t, "image_s": t - base_t, "image_cpu_s": c - base_c,
                                                    "raw_embreex_s": tr, "raw_embreex_cpu_s": cr, "pixels": n}
        # a camera's image split into its casts and the shading (engine.cast wrapped)
        for label, d in DEVICES.items():
            if d["device"] != "Camera":
                continue
            dev = casts[label]
            eng = sim.scene.engine
            inner = eng.cast
            spent = [0.0]

            def timed_cast(*a, _inner=inner, **k):
                import time as _t
                t0 = _t.process_time()
                try:
                    return _inner(*a, **k)
                finally:
                    spent[0] += _t.process_time() - t0

            eng.cast = timed_cast
            totals = []
            cast_totals = []
            for _ in range(rounds):
                spent[0] = 0.0
                import time as _t
                t0 = _t.process_time()
                dev._capture_image(dev.world_pose(robot.pose), sim._counters)
                totals.append(_t.process_time() - t0)
                cast_totals.append(spent[0])
            del eng.cast
            tt, tc = median(totals), median(cast_totals)
            split_rows.append([precision, label, fmt_time(tt), fmt_time(tc), fmt_time(tt - tc), f"{tc / tt:.0%}"])
    table = Table("images_time", "Time per image, and raw embreex on the same rays (one interleaved run)",
                  ["precision", "device", "rays", "image (wall)", "image (CPU)", "raw embreex (wall)",
                   "raw embreex (CPU)", "image ÷ raw embreex (CPU)", "pixels per CPU second"], rows,
                  ["the arena world; each device alone on the e-puck, enabled at the basic step; an image = a step "
                   "that makes it − a step with nothing enabled; medians of "
                   f"{rounds} interleaved rounds, wall-clock and this process's CPU time (time.process_time: on a "
                   "shared machine the wall clock also counts other jobs); raw embreex: distances only, float32, one call",
                   "a camera's image is one visual cast of its pixel rays plus shadow rays for lights with "
                   "cast_shadows, then the lighting of every pixel (numpy); a range finder's is one distance-only cast"])
    split = Table("images_split", "A camera image: its casts and its shading",
                  ["precision", "device", "image", "engine.cast", "shading, tone mapping, bytes", "cast share"], split_rows,
                  ["CPU time (time.process_time) of one capture of the image and of the engine.cast calls in it (medians)"])
    counters = Table("images_counters", "Only enabled devices cost anything (sim.counters)",
                     ["precision", "what", "rays_camera", "rays_range_finder", "engine_rays"], counter_rows,
                     ["no device of the arena is enabled but the one named: every ray counted is the image's"])
    fog_table = _fog_cost(data, base, rounds, out)
    epuck = out["exact"]["e-puck camera 52×39"]
    findings.append(f"an e-puck camera image (52×39) costs {fmt_time(epuck['image_cpu_s'])} of CPU in EXACT "
                    f"({fmt_time(out['fast']['e-puck camera 52×39']['image_cpu_s'])} FAST); a 640×480 image "
                    f"{fmt_time(out['exact']['camera 640×480']['image_cpu_s'])} EXACT, "
                    f"{fmt_time(out['fast']['camera 640×480']['image_cpu_s'])} FAST; a 320×240 range image "
                    f"{fmt_time(out['exact']['range finder 320×240']['image_cpu_s'])} EXACT")
    if not math.isfinite(epuck["image_s"]):
        findings.append("the e-puck camera could not be timed")
    return Section("images", "Images: cameras and range finders on the ray engine",
                   intro=__doc__.split("\n\n", 1)[1].strip(), tables=[table, split, counters, fog_table], findings=findings, data=out)


FOG = {"color": [0.8, 0.8, 0.8], "visibility_range": 3.0}


def _fog_cost(data: dict, base: Path, rounds: int, out: dict) -> Table:
    """The 640×480 camera's image in the same world without and with a Fog (each fog type),
    interleaved, FAST: what the fog's blend adds (a world without fog computes nothing for it)."""
    label = "camera 640×480"
    name = DEVICES[label]["name"]
    captures: dict = {}
    for fog_type in (None, "LINEAR", "EXPONENTIAL", "EXPONENTIAL2"):
        world = data if fog_type is None else {**data, "fog": {**FOG, "fog_type": fog_type}}
        sim = make_sim(world, "fast", base_dir=base)
        robot = sim.robot("epuck")
        dev = robot.device(name)
        sim.step()
        captures["no fog" if fog_type is None else fog_type] = (
            lambda dev=dev, robot=robot, sim=sim: dev._capture_image(dev.world_pose(robot.pose), sim._counters))
    _, cpu = _interleaved_cpu(captures, rounds)
    plain = median(cpu["no fog"])
    rows = [[k, fmt_time(median(v)), f"{median(v) / max(plain, 1e-12):.2f}×"] for k, v in cpu.items()]
    out["fog"] = {k: median(v) for k, v in cpu.items()}
    return Table("images_fog", "What a Fog costs a camera image (640×480, FAST)",
                 ["world", "image (CPU)", "÷ no fog"], rows,
                 [f"the same arena with a top-level fog ({FOG['visibility_range']} m visibility range) of each type; "
                  f"one capture of the image, medians of {rounds} interleaved rounds (time.process_time)"])
