"""Limits: what a world at the world-file limits costs to build, and how fast oversize or damaged
input is answered (issue 28). ``sensorium bench --only limits``.

Each world runs in a fresh ``sensorium probe WORLD --steps 1 --enable all:32`` (EXACT, every device
enabled, one step: the ray engine's scene built and every ray cast once); its peak resident memory
comes from the operating system (``wait4``). A mesh file over 1 MiB is read by a worker process of
its own (limited to ``WorldLimits.mesh_load_bytes``), not counted in the row. The refusal and
recording rows time one call in this process (best of 3)."""

from __future__ import annotations

import json
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from .common import Config, Section, Table, Target, fmt_time

_DS = {"device": "DistanceSensor", "number_of_rays": 1024, "aperture": 0.5}


def _spheres(n: int) -> list[dict]:
    return [{"name": f"s{i}", "pose": {"translation": [i % 7 * 3, i // 7 * 3, 0]},
             "geometry": {"type": "sphere", "radius": 1, "subdivision": 6}} for i in range(n)]


def _worlds(d: Path, quick: bool) -> dict[str, tuple[str, dict]]:
    """name -> (what it asks for, world)."""
    from PIL import Image

    rng = np.random.default_rng(0)
    side = 1024 if quick else 4096
    for i in range(2):
        Image.fromarray(rng.integers(0, 256, (side, side, 3), dtype=np.uint8)).save(d / f"tex{i}.png", compress_level=1)
    textured = [{"name": f"f{i}", "pose": {"translation": [i * 3, -5, 0]}, "geometry": {"type": "box", "size": [2, 2, 0.1]},
                 "appearance": {"texture": f"tex{i}.png"}} for i in range(2)]
    one_ds = [{"name": "r", "devices": [{"device": "DistanceSensor", "name": "d"}]}]
    k = 4 if quick else 1
    n_sph = 47 // k
    ds_robots = [{"name": f"r{j}", "pose": {"translation": [j * 0.5, -3, 0.5]},
                  "devices": [dict(_DS, name=f"d{i}") for i in range(256)]} for j in range(16 // k)]
    lid = [{"device": "Lidar", "name": f"l{i}", "horizontal_resolution": 65536, "number_of_layers": 16, "max_range": 100}
           for i in range(4 // k)]
    dome = [{"name": "dome", "geometry": {"type": "sphere", "radius": 20, "subdivision": 6}}]
    lights = [{"type": "PointLight", "location": [i % 8 * 0.5, i // 8 * 0.5, 1.0]} for i in range(64)]
    sensors = [{"name": f"r{j}", "devices": [{"device": "LightSensor", "name": f"l{i}", "occlusion": True}
                                              for i in range(256)]} for j in range(64 // k)]
    tri = 1_000_000 // k
    rec = np.zeros(tri, dtype=[("n", "<f4", 3), ("v", "<f4", 9), ("a", "<u2")])
    base = rng.uniform(-5, 5, (tri, 3)).astype("<f4")
    rec["v"] = np.concatenate([base, base + [0.01, 0, 0], base + [0, 0.01, 0]], axis=1)
    (d / "mesh.stl").write_bytes(b"\0" * 80 + struct.pack("<I", tri) + rec.tobytes())
    return {
        "base": ("one distance sensor", {"robots": one_ds}),
        "triangles": (f"{n_sph} spheres (81,920 triangles each)", {"solids": _spheres(n_sph), "robots": one_ds}),
        "triangles+textures": (f"{n_sph - 1} spheres and two {side}² textures on boxes (EXACT edge guards)",
                               {"solids": _spheres(n_sph - 1) + textured, "robots": one_ds}),
        "rays": (f"{len(ds_robots)} robots × 256 distance sensors × 1024 rays, in a dome",
                 {"solids": dome, "robots": ds_robots}),
        "beams": (f"{len(lid)} lidars × 65,536 × 16 beams, in a dome", {"solids": dome, "robots": [{"name": "r", "devices": lid}]}),
        "occlusion": (f"{len(sensors) * 256:,} occluding light sensors × 64 lights", {"lights": lights, "robots": sensors}),
        "textures": (f"two {side}² textures", {"solids": textured, "robots": one_ds}),
        "mesh": (f"a binary STL of {tri:,} triangles (read by the worker)",
                 {"solids": [{"name": "m", "geometry": {"type": "mesh", "url": "mesh.stl"}}], "robots": one_ds}),
        "all together": (f"{n_sph} spheres, two {side}² textures, {len(ds_robots) * 256 * 1024:,} rays per step",
                         {"solids": _spheres(n_sph) + textured, "robots": ds_robots}),
    }


_PROBE = r"""
import sys
from sensorium.cli import main
code = main(sys.argv[1:])
for line in open("/proc/self/status"):          # this process's own peak (a forked child's RSS before
    if line.startswith("VmHWM:"):               # exec would count in its rusage)
        print("VmHWM", int(line.split()[1]) * 1024, file=sys.stderr)
sys.exit(code)
"""


def _probe(path: Path, large: bool) -> tuple[int, float, str]:
    """(peak resident bytes, seconds, the last other line of stderr) of ``sensorium probe``."""
    argv = [sys.executable, "-c", _PROBE, "probe", str(path), "--steps", "1", "--enable", "all:32"]
    if large:
        argv.append("--allow-large")
    t0 = time.perf_counter()
    out = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=1800, check=False)
    secs = time.perf_counter() - t0
    lines = out.stderr.strip().splitlines()
    peak = next((int(line.split()[1]) for line in reversed(lines) if line.startswith("VmHWM ")), 0)
    other = [line for line in lines if not line.startswith("VmHWM ")]
    return peak, secs, (other or [""])[-1]


def _best(fn, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def _record_boundary(data: bytes, near: int) -> int:
    """The end of the last record that ends at or before ``near`` (the zeros of a power loss start
    there: after the last write that reached the disk)."""
    pos = 8
    while True:
        (length,) = struct.unpack_from("<Q", data, pos + 1)
        if pos + 9 + length > near:
            return pos
        pos += 9 + length


def _refusals(d: Path) -> list[list[str]]:
    from sensorium.server.recording.reader import summarize
    from sensorium.server.recording.recover import recover
    from sensorium.server.recording.writer import McapRecorder
    from sensorium.server.world.loader import WorldError, load_world

    rows = []
    robot = json.dumps({"name": "r", "devices": [
        {"device": "DistanceSensor", "name": f"ps{k}", "type": "infra-red",
         "lookup_table": [[0.0, 4095, 0.002], [0.01, 1465.73, 0.0073], [0.07, 67.19, 0.0778]],
         "pose": {"translation": [0.03, 0.001 * k, 0.01], "rotation": [0, 0, 1, 0.1 * k]}} for k in range(18)]})
    crowd = d / "crowd.yaml"
    named = robot.replace('"name": "r"', '"name": "r#"', 1)
    crowd.write_text("robots:\n" + "".join("  - " + named.replace("#", str(i), 1) + "\n" for i in range(1000)))

    def refuse() -> None:
        try:
            load_world(crowd)
        except WorldError:
            return
        raise AssertionError("the crowd validated")

    rows.append([f"a {crowd.stat().st_size / 1e6:.1f} MB YAML world of 1,000 robots (limit 256)", "load_world",
                 fmt_time(_best(refuse))])
    rec = d / "run.mcap"
    with McapRecorder(rec, b"", "w.yaml", {"seed": "1"}, None, 1 << 16, flush_interval=None) as r:
        body = bytes(2000)
        for k in range(20_000):
            r.record(f"/r/d{k % 8}/value", "sensor_msgs/msg/Range", b"", body, (k // 8 + 1) * 32_000_000, k // 8)
    data = rec.read_bytes()
    cut = d / "cut.mcap"
    cut.write_bytes(data[:_record_boundary(data, len(data) * 6 // 10)])
    zeros = d / "zeros.mcap"
    with open(zeros, "wb") as f:
        f.write(cut.read_bytes())
        f.truncate(cut.stat().st_size + (64 << 20))
    n = summarize(zeros)["messages"]
    rows.append([f"a recording cut after a record ({cut.stat().st_size / 1e6:.1f} MB, {n:,} messages) + 64 MiB of "
                 "zeros (a power loss)",
                 "summarize (info)", fmt_time(_best(lambda: summarize(zeros)))])
    out = d / "fixed.mcap"
    rows.append(["the same", "recover", fmt_time(_best(lambda: recover(zeros, out, overwrite=True)))])
    return rows


def run(cfg: Config) -> Section:
    from sensorium.server.world.limits import BYTES_PER_RAY, BYTES_PER_TRIANGLE, GiB, WorldLimits
    from sensorium.server.world.loader import WorldError, load_world

    sec = Section("limits", "Limits: building worlds at the world-file limits; refusing oversize and damaged input",
                  intro=__doc__.split("\n\n", 1)[1].replace("\n", " ") if __doc__ else "")
    t_start = time.perf_counter()
    rows, data = [], {}
    with tempfile.TemporaryDirectory(prefix="sensorium-limits-") as tmp:
        d = Path(tmp)
        for name, (what, world) in _worlds(d, cfg.quick).items():
            path = d / f"{name.replace(' ', '_').replace('+', '_')}.yaml"
            path.write_text(json.dumps(world))
            try:
                loaded = load_world(path, limits=WorldLimits.large())
                verdict = "validates"
                try:
                    load_world(path)
                except WorldError as exc:
                    verdict = "refused: " + str(exc).split(": ", 2)[-1][:90]
                est_tri, est_rays = _counts(loaded)
            except WorldError as exc:
                rows.append([name, what, "-", "-", str(exc)[:90]])
                continue
            peak, secs, last = _probe(path, large=True)
            estimate = BYTES_PER_TRIANGLE * est_tri + BYTES_PER_RAY * est_rays
            data[name] = {"peak_bytes": peak, "seconds": secs, "triangles": est_tri, "rays": est_rays,
                          "estimate_bytes": estimate, "verdict": verdict, "stderr": last}
            rows.append([name, what, f"{est_tri:,} / {est_rays:,}", f"{estimate / GiB:.2f} GiB",
                         f"{peak / GiB:.2f} GiB", fmt_time(secs), verdict])
            cfg.log(f"  limits: {name}: peak {peak / GiB:.2f} GiB in {secs:.1f} s ({verdict})")
        sec.tables.append(Table("limits_build", "Building a world at the limits (one step, every device enabled)",
                                ["world", "asks for", "triangles / rays per step", "estimate (limits.py)",
                                 "peak memory", "time", "with the default limits"], rows,
                                ["Peak: the probe process's maximum resident set (Python, numpy and Embree included; "
                                 "a trivial world's row is the floor). The estimate is what check_work compares "
                                 "with build_bytes (2 GiB): triangles × "
                                 f"{BYTES_PER_TRIANGLE} B + rays per step × {BYTES_PER_RAY} B; textures have "
                                 "their own limits and are not in it.",
                                 "Reproduce: `sensorium bench --only limits` (sensorium/benchmarks/limits.py)."]))
        refusals = _refusals(d)
    sec.tables.append(Table("limits_refusals", "Oversize and damaged input: time to answer", ["input", "call", "time"],
                            refusals, ["Best of 3 in one process."]))
    sec.data["build"] = data
    accepted = [v for v in data.values() if v["verdict"] == "validates"]
    worst = max((v["peak_bytes"] for v in accepted), default=0)
    sec.targets.append(Target("What validates builds within 2.5 GiB (the estimate's 2 GiB, textures, the floor)",
                              "≤ 2.5 GiB", f"{worst / GiB:.2f} GiB", worst <= 2.5 * GiB,
                              "The largest peak among the worlds the default limits accept."))
    sec.findings.append(f"Limits: the largest build among worlds the default limits accept peaked at "
                        f"{worst / GiB:.2f} GiB; oversize YAML is refused in {refusals[0][2]}.")
    cfg.log(f"  limits: {time.perf_counter() - t_start:.0f} s")
    return sec


def _counts(loaded) -> tuple[int, int]:
    """(triangles, rays per step) as check_work counts them."""
    from sensorium.schemas.devices import KINDS
    from sensorium.server.world.limits import _walk, triangle_count
    from sensorium.server.world.meshes import load_mesh

    triangles = lights = 0
    for path, v in _walk(loaded.world):
        kind = getattr(v, "type", None)
        if kind in ("box", "sphere", "cylinder", "capsule", "plane", "mesh", "triangles") and path.endswith("geometry"):
            triangles += triangle_count(v, lambda g: len(load_mesh(loaded.base_dir / g.url, g.scale, material=g.material_index,
                                                                      name=g.name).faces))
        elif isinstance(kind, str) and kind.endswith("Light") and not path.endswith("geometry"):
            lights += 1
    rays = 0
    for robot in loaded.world.robots:
        for dev in robot.devices:
            k = KINDS.get(getattr(dev, "device", ""))
            rays += k.rays(dev, lights) if k is not None and k.rays is not None else 0
    return triangles, rays
