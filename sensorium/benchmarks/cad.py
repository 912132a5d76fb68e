"""CAD robots: the memory and load time of a robot built of many meshes, and of a swarm.

A CAD export gives a robot of tens of parts, each a mesh file or an inline `IndexedFaceSet` of
tens of thousands of triangles. The worlds here are generated (`cad_robot_world`, `swarm_world`: our
own shapes, no Webots file): one robot of 30 distinct closed meshes (a bumpy torus each, 20,000-50,000
triangles), a lidar and four laser distance sensors, written three ways -- binary STL files, inline
`triangles` in a JSON world file, a `.wbt` of `IndexedFaceSet` nodes -- and swarms of small robots of
one model, three meshes each (three shared STL files, or the same three inline meshes in every robot).
Each world is measured in a fresh interpreter, stage by stage: the resident memory (`VmRSS`, after
glibc's `malloc_trim`) and the process's peak so far (`VmHWM`) after loading the world, building the
scene (`Simulation`), the first step (the BVHs built, the first cast) and a second step.

``python -m sensorium.benchmarks.cad`` prints the table (``--quick``: a quarter of the triangles;
``--compare TREE``: the same worlds measured with another source tree too, say the base checkout,
interleaved); ``sensorium bench --only cad`` puts it in the report.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from .common import Config, Section, Table

PARTS = 30
STAGES = ("load", "scene", "first step", "step")


# ----------------------------------------------------------------------------- the worlds
def part_mesh(k: int, triangles: int) -> tuple[np.ndarray, np.ndarray]:
    """Part ``k``: a closed bumpy torus of about ``triangles`` triangles (float64 vertices, int64
    faces, outward), ~0.1 m across, distinct for each ``k``."""
    nv = max(3, int(round(np.sqrt(triangles / 2.0 / 3.0))))     # around the tube
    nu = max(3, triangles // (2 * nv))                            # around the ring
    u = np.arange(nu) * (2.0 * np.pi / nu)
    v = np.arange(nv) * (2.0 * np.pi / nv)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    big, small = 0.05 + 0.001 * (k % 7), 0.015 * (1.0 + 0.1 * np.sin((k + 3) * uu) * np.cos(2 * vv))
    ring = big + small * np.cos(vv)
    verts = np.stack([ring * np.cos(uu), ring * np.sin(uu), small * np.sin(vv)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * nv + j).ravel()
    b = (((i + 1) % nu) * nv + j).ravel()
    c = (((i + 1) % nu) * nv + (j + 1) % nv).ravel()
    d = (i * nv + (j + 1) % nv).ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return verts, faces


def write_stl(path: Path, verts: np.ndarray, faces: np.ndarray) -> None:
    """A binary STL of the triangles (each corner written out, as STL does; zero normals)."""
    rec = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["v"] = verts[faces]
    with open(path, "wb") as f:
        f.write(b"sensorium cad benchmark".ljust(80, b" "))
        f.write(np.uint32(len(faces)).tobytes())
        f.write(rec.tobytes())


def _triangle_counts(parts: int, scale: float) -> list[int]:
    return [int((20_000 + 10_000 * (k % 4)) * scale) for k in range(parts)]     # 20k, 30k, 40k, 50k, ...


_DEVICES = [
    {"device": "Lidar", "name": "lidar", "pose": {"translation": [0.0, 0.0, 0.25]}, "horizontal_resolution": 512,
     "field_of_view": 6.283185307179586, "number_of_layers": 4, "vertical_field_of_view": 0.4,
     "min_range": 0.05, "max_range": 8.0},
    *({"device": "DistanceSensor", "name": f"ds{i}", "type": "laser",
       "pose": {"translation": [0.2 * np.cos(a), 0.2 * np.sin(a), 0.05], "rotation": [0, 0, 1, float(a)]},
       "lookup_table": [[0.0, 0.0, 0.0], [2.0, 2000.0, 0.0]]} for i, a in enumerate(np.arange(4) * np.pi / 2)),
]


def _part_pose(k: int) -> dict:
    return {"translation": [0.12 * (k % 5 - 2), 0.12 * ((k // 5) % 3 - 1), 0.04 + 0.05 * (k // 15)]}


def _room() -> list[dict]:
    walls = [("n", [0, 3, 0.5], [6.2, 0.1, 1]), ("s", [0, -3, 0.5], [6.2, 0.1, 1]),
             ("e", [3, 0, 0.5], [0.1, 6, 1]), ("w", [-3, 0, 0.5], [0.1, 6, 1])]
    return [{"name": "floor", "geometry": {"type": "plane", "size": [6.0, 6.0]}},
            *({"name": f"wall_{n}", "pose": {"translation": t}, "geometry": {"type": "box", "size": s}}
              for n, t, s in walls)]


def cad_robot_world(folder: Path, form: str = "stl", parts: int = PARTS, scale: float = 1.0) -> Path:
    """A world of one robot of ``parts`` distinct mesh parts (20k-50k triangles each, times
    ``scale``) with a lidar and four distance sensors, in a room, written under ``folder``.
    ``form``: "stl" (binary STL files), "triangles" (YAML, inline), "wbt" (inline IndexedFaceSets)."""
    folder.mkdir(parents=True, exist_ok=True)
    counts = _triangle_counts(parts, scale)
    if form == "wbt":
        return _wbt_world(folder, counts)
    shapes = []
    for k, n in enumerate(counts):
        v, f = part_mesh(k, n)
        if form == "stl":
            (folder / "parts").mkdir(exist_ok=True)
            write_stl(folder / "parts" / f"part{k:02d}.stl", v, f)
            geometry: dict = {"type": "mesh", "url": f"parts/part{k:02d}.stl"}
        elif form == "triangles":
            geometry = {"type": "triangles", "vertices": np.round(v, 6).tolist(), "faces": f.tolist()}
        else:
            raise ValueError(f"unknown form {form!r}")
        shapes.append({"name": f"part{k}", "pose": _part_pose(k), "geometry": geometry})
    world = {"world_info": {"name": f"cad_{form}", "basic_time_step": 32}, "solids": _room(),
             "robots": [{"name": "cad", "controller": "<none>", "pose": {"translation": [0.0, 0.0, 0.0]},
                         "shapes": shapes, "devices": _DEVICES}]}
    path = folder / f"cad_{form}.json"          # JSON: written and read fast, the same model as YAML
    path.write_text(json.dumps(world))
    return path


def _wbt_world(folder: Path, counts: list[int]) -> Path:
    parts = []
    for k, n in enumerate(counts):
        v, f = part_mesh(k, n)
        point = " ".join(f"{x:.6f}" for x in v.ravel())
        index = " ".join(f"{a} {b} {c} -1" for a, b, c in f.tolist())
        t = _part_pose(k)["translation"]
        parts.append(f"Solid {{ translation {t[0]} {t[1]} {t[2]} name \"part{k}\" children [ Shape {{ geometry "
                     f"IndexedFaceSet {{ coord Coordinate {{ point [ {point} ] }} coordIndex [ {index} ] }} }} ] }}")
    lidar = ("Lidar { translation 0 0 0.25 name \"lidar\" horizontalResolution 512 fieldOfView 6.283185 "
             "numberOfLayers 4 verticalFieldOfView 0.4 minRange 0.05 maxRange 8 }")
    sensors = " ".join(f"DistanceSensor {{ translation {0.2 * np.cos(a):.6f} {0.2 * np.sin(a):.6f} 0.05 "
                       f"rotation 0 0 1 {a:.6f} name \"ds{i}\" type \"laser\" lookupTable [ 0 0 0 2 2000 0 ] }}"
                       for i, a in enumerate(np.arange(4) * np.pi / 2))
    walls = " ".join(f"Solid {{ translation {t} children [ Shape {{ geometry Box {{ size {s} }} }} ] "
                     f"name \"wall_{n}\" boundingObject Box {{ size {s} }} }}"
                     for n, t, s in (("n", "0 3 0.5", "6.2 0.1 1"), ("s", "0 -3 0.5", "6.2 0.1 1"),
                                     ("e", "3 0 0.5", "0.1 6 1"), ("w", "-3 0 0.5", "0.1 6 1")))
    path = folder / "cad_wbt.wbt"
    path.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 32 }\n"
                    "Solid { name \"floor\" children [ Shape { geometry Plane { size 6 6 } } ] "
                    "boundingObject Plane { size 6 6 } }\n" + walls + "\n"
                    f"Robot {{ name \"cad\" controller \"<none>\" children [ {' '.join(parts)} {lidar} {sensors} ] }}\n")
    return path


def swarm_world(folder: Path, robots: int, form: str = "stl", triangles: int = 2_000) -> Path:
    """A world of ``robots`` small robots in a grid, one robot model: three parts of ``triangles``
    triangles each, read from the same three STL files (``form`` "stl") or written inline in each
    robot (``form`` "triangles", as a PROTO's IndexedFaceSets are converted), with two distance sensors."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "parts").mkdir(exist_ok=True)
    geometries: list[dict] = []
    for k in range(3):
        v, f = part_mesh(100 + k, triangles)
        if form == "stl":
            write_stl(folder / "parts" / f"small{k}.stl", v * 0.5, f)
            geometries.append({"type": "mesh", "url": f"parts/small{k}.stl"})
        elif form == "triangles":
            geometries.append({"type": "triangles", "vertices": np.round(v * 0.5, 6).tolist(), "faces": f.tolist()})
        else:
            raise ValueError(f"unknown form {form!r}")
    side = int(np.ceil(np.sqrt(robots)))
    bots = []
    for r in range(robots):
        bots.append({"name": f"bot{r}", "controller": "<none>",
                     "pose": {"translation": [0.5 * (r % side) - 2.5, 0.5 * (r // side) - 2.5, 0.0]},
                     "shapes": [{"name": f"p{k}", "pose": {"translation": [0.0, 0.0, 0.02 + 0.03 * k]},
                                 "geometry": g} for k, g in enumerate(geometries)],
                     "devices": [{"device": "DistanceSensor", "name": f"ds{i}", "type": "laser",
                                  "pose": {"translation": [0.06 * (1 - 2 * i), 0.0, 0.03],
                                           "rotation": [0, 0, 1, np.pi * i]},
                                  "lookup_table": [[0.0, 0.0, 0.0], [2.0, 2000.0, 0.0]]} for i in range(2)]})
    world = {"world_info": {"name": "swarm", "basic_time_step": 32}, "solids": _room(), "robots": bots}
    path = folder / f"swarm_{form}_{robots}.json"
    path.write_text(json.dumps(world))
    return path


# ----------------------------------------------------------------------------- one measurement
# One child per measurement, run with a source tree of its own on PYTHONPATH (``--compare`` runs
# another tree's child with the same code): load the world, build its simulation (FAST), enable every
# device and step twice; per stage the wall time, the resident memory after it (VmRSS after glibc's
# malloc_trim, so freed temporaries do not count) and the process's peak so far (VmHWM).
_CHILD = r"""
import ctypes, json, sys, time
try:
    _trim = ctypes.CDLL("libc.so.6").malloc_trim
except (OSError, AttributeError):
    _trim = lambda pad: 0

def status(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1]) * 1024
    return 0

def rss():
    _trim(0)
    return status("VmRSS:")

import numpy as np
import trimesh
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import load_world

# warm up what loads lazily (trimesh's watertightness judge), so that no stage times an import
trimesh.Trimesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
                [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], process=True, validate=False).is_watertight
out = {"rss": {}, "peak": {}, "ms": {}, "base": rss()}

def stage(name, t0):
    out["ms"][name] = (time.perf_counter() - t0) * 1e3
    out["rss"][name] = rss()
    out["peak"][name] = status("VmHWM:")     # (this process's own: ru_maxrss starts from its parent's at exec)

t0 = time.perf_counter()
loaded = load_world(sys.argv[1], limits=WorldLimits.large())
stage("load", t0)
t0 = time.perf_counter()
sim = Simulation(loaded, "fast")
del loaded
stage("scene", t0)
for robot in sim.world.robots:
    for d in robot.devices:
        sim.device(robot.name + "/" + d.name).enable(32)
t0 = time.perf_counter()
sim.step()
stage("first step", t0)
t0 = time.perf_counter()
sim.step()
stage("step", t0)
eng = sim.scene.engine
tiers = {id(t): t for t in (*eng._static.values(), *eng._shared.values()) if t is not None}
out["triangles"] = sum(len(t.F) for t in tiers.values())      # (each tier's, a shared tier once)
out["robots"] = len(sim.world.robots)
print(json.dumps(out))
"""


def _child(path: Path, tree: str | None = None) -> dict:
    """One measurement of the world ``path`` in a fresh interpreter, with ``tree`` (a source tree)
    first on its path (default: this one's). (``-P``: the working directory is not put before it, so
    a run started inside one tree measures the other tree's code, not its own twice.)"""
    env = dict(os.environ)
    env["PYTHONPATH"] = tree if tree is not None else str(Path(__file__).resolve().parents[2])
    out = subprocess.run([sys.executable, "-P", "-c", _CHILD, str(path)], capture_output=True, text=True, timeout=1800,
                         check=False, env=env)
    if out.returncode != 0:
        raise RuntimeError(f"cad child failed on {path.name}: {out.stderr.strip().splitlines()[-3:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


# ----------------------------------------------------------------------------- the section
def worlds(tmp: Path, quick: bool) -> dict[str, Path]:
    """The measured worlds, written under ``tmp``, by row name."""
    scale = 0.25 if quick else 1.0
    n = SWARM_QUICK if quick else SWARM
    return {f"STL files ({PARTS} parts)": cad_robot_world(tmp / "stl", "stl", scale=scale),
            f"inline triangles, JSON ({PARTS} parts)": cad_robot_world(tmp / "tri", "triangles", scale=scale),
            f"inline IndexedFaceSet, .wbt ({PARTS} parts)": cad_robot_world(tmp / "wbt", "wbt", scale=scale),
            **{f"swarm of {k}, {form}": swarm_world(tmp / "swarm", k, form)
               for form in ("stl", "triangles") for k in (1, n)}}


SWARM, SWARM_QUICK = 50, 20


def measure_all(paths: dict[str, Path], trees: dict[str, str | None], rounds: int, log) -> dict[str, dict[str, list]]:
    """{tree: {world: [samples]}}: every world with every tree, ``rounds`` times, interleaved
    (A B A B ...: the machine's load hits both alike)."""
    runs: dict[str, dict[str, list]] = {t: {w: [] for w in paths} for t in trees}
    for _ in range(rounds):
        for w, path in paths.items():
            for t, tree in trees.items():
                runs[t][w].append(_child(path, tree))
                log(f"  cad: {t}: {w}: peak {runs[t][w][-1]['peak']['step'] / 1e6:.0f} MB")
    return runs


def per_robot_ms(samples: dict[str, list], form: str) -> float:
    """Load and scene ms per added robot of a swarm: (swarm of n - swarm of 1) / (n - 1), median over rounds."""
    big = [k for k in samples if k.startswith("swarm of ") and k.endswith(form) and not k.startswith("swarm of 1,")][0]
    n = samples[big][0]["robots"]
    one = samples[f"swarm of 1, {form}"]
    per = [(a["ms"]["load"] + a["ms"]["scene"] - b["ms"]["load"] - b["ms"]["scene"]) / (n - 1)
           for a, b in zip(samples[big], one, strict=True)]
    return float(np.median(per))


def rows_of(samples: dict[str, list]) -> list[list[str]]:
    rows = []
    for name, got in samples.items():
        best = min(got, key=lambda s: s["peak"]["step"])
        ms = {k: float(np.median([s["ms"][k] for s in got])) for k in STAGES}
        rows.append([name, f"{best['triangles']:,}", *(f"{best['rss'][k] / 1e6:.0f}" for k in STAGES),
                     f"{best['peak']['step'] / 1e6:.0f}",
                     f"{ms['load']:.0f}", f"{ms['scene']:.0f}", f"{ms['first step']:.0f}"])
    return rows


COLUMNS = ["world", "triangles in tiers", *(f"RSS MB after {k}" for k in STAGES), "peak MB",
           "load ms", "scene ms", "first step ms"]


def run(cfg: Config) -> Section:
    sec = Section("cad", "CAD robots: memory and load time of a robot of many meshes, and of a swarm",
                  intro=" ".join(__doc__.split("\n\n")[1].split()))
    rounds = cfg.pick(3, 1)
    with tempfile.TemporaryDirectory() as tmp:
        runs = measure_all(worlds(Path(tmp), cfg.quick), {"this": None}, rounds, cfg.log)["this"]
    per = {form: per_robot_ms(runs, form) for form in ("stl", "triangles")}
    sec.data.update(samples=runs, swarm_ms_per_robot=per)
    sec.tables.append(Table("cad", f"A CAD robot and a swarm: resident memory after each stage, peak, load time "
                            f"({rounds} interleaved rounds, fresh interpreters)", COLUMNS, rows_of(runs), notes=[
                                "RSS after malloc_trim, the interpreter's own "
                                f"{runs[next(iter(runs))][0]['base'] / 1e6:.0f} MB included; peak: the process's "
                                "VmHWM (the mesh workers reading files over 1 MiB are processes of their own)",
                                f"swarm: {per['stl']:.1f} ms (three shared STL files) and {per['triangles']:.1f} ms "
                                "(three inline meshes) per added robot, loading and the scene",
                                "Reproduce: `python -m sensorium.benchmarks.cad` (sensorium/benchmarks/cad.py)"]))
    stl = runs[f"STL files ({PARTS} parts)"][0]
    sec.findings.append(f"A robot of {PARTS} mesh parts ({stl['triangles']:,} triangles in the ray engine) peaks at "
                        f"{stl['peak']['step'] / 1e6:.0f} MB and holds {stl['rss']['step'] / 1e6:.0f} MB once stepping; "
                        f"a swarm robot costs {per['stl']:.1f} ms (shared mesh files) or {per['triangles']:.1f} ms "
                        "(inline meshes) to load.")
    load_split_section(sec, cfg)
    return sec


def _print(title: str, rows: list[list[str]]) -> None:
    print(title)
    widths = [max(len(str(c)), *(len(str(r[i])) for r in rows)) for i, c in enumerate(COLUMNS)]
    for row in [COLUMNS, *rows]:
        print("  ".join(str(c).rjust(w) for c, w in zip(row, widths)))


def main(argv: list[str]) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m sensorium.benchmarks.cad", description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="a quarter of the triangles, a swarm of 20")
    parser.add_argument("--rounds", type=int, default=1, help="interleaved rounds (default 1)")
    parser.add_argument("--compare", metavar="TREE", help="also measure another source tree (say the base "
                        "checkout), interleaved with this one")
    parser.add_argument("--load-split", action="store_true", help="only load a robot of 24 mesh files and split "
                        "its load time: mesh worker starts, their reading, the rest")
    args = parser.parse_args(argv)
    here = str(Path(__file__).resolve().parents[2])
    trees: dict[str, str | None] = {"this": here}
    if args.compare:
        trees = {args.compare: str(Path(args.compare).resolve()), "this": here}
    if args.load_split:
        load_split_main(trees, args.rounds)
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        runs = measure_all(worlds(Path(tmp), args.quick), trees, args.rounds, lambda s: print(s, file=sys.stderr))
    for name, samples in runs.items():
        _print(f"{name} ({here if name == 'this' else name}): best of {args.rounds}", rows_of(samples))
        print(f"swarm, ms per added robot: {per_robot_ms(samples, 'stl'):.1f} (shared STL files), "
              f"{per_robot_ms(samples, 'triangles'):.1f} (inline meshes)\n")
    return 0



# ----------------------------------------------------------------------------- mesh files: where the load goes
# A URDF robot converted for Webots: ~20 STL links of ~1.5 MB each, and a few OBJ and COLLADA parts,
# every file over meshes.IN_PROCESS_BYTES (read by the bounded mesh worker). ``--load-split`` loads
# it in a fresh interpreter per tree and splits the load: the worker processes' starts (each timed
# alone: an interpreter importing numpy and trimesh, as the worker does first), their reading (the
# time spent waiting on workers, less those starts) and the rest (the loader: validation, welding).
URDF_STL, URDF_OBJ, URDF_DAE = 20, 2, 2


def write_obj(path: Path, verts: np.ndarray, faces: np.ndarray) -> None:
    """A Wavefront OBJ of the triangles (1-based indices)."""
    with open(path, "w") as f:
        f.write("".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in verts.tolist()))
        f.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces.tolist()))


def write_dae(path: Path, verts: np.ndarray, faces: np.ndarray) -> None:
    """A COLLADA file of one geometry and one material, Z up, in metres."""
    points = " ".join(f"{x:.6f}" for x in verts.ravel())
    index = " ".join(str(i) for i in faces.ravel())
    path.write_text(
        '<?xml version="1.0" encoding="utf-8"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" '
        'version="1.4.1"><asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>'
        '<library_effects><effect id="e"><profile_COMMON><technique sid="t"><lambert><diffuse><color>0.6 0.6 0.7 1'
        '</color></diffuse></lambert></technique></profile_COMMON></effect></library_effects>'
        '<library_materials><material id="m" name="m"><instance_effect url="#e"/></material></library_materials>'
        f'<library_geometries><geometry id="g" name="g"><mesh><source id="p"><float_array id="pa" count="{verts.size}">'
        f'{points}</float_array><technique_common><accessor source="#pa" count="{len(verts)}" stride="3">'
        '<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>'
        '</technique_common></source><vertices id="v"><input semantic="POSITION" source="#p"/></vertices>'
        f'<triangles count="{len(faces)}" material="s"><input semantic="VERTEX" source="#v" offset="0"/><p>{index}</p>'
        '</triangles></mesh></geometry></library_geometries><library_visual_scenes><visual_scene id="vs"><node id="n">'
        '<instance_geometry url="#g"><bind_material><technique_common><instance_material symbol="s" target="#m"/>'
        '</technique_common></bind_material></instance_geometry></node></visual_scene></library_visual_scenes>'
        '<scene><instance_visual_scene url="#vs"/></scene></COLLADA>\n')


def urdf_robot_world(folder: Path) -> Path:
    """A robot of URDF_STL binary STL links of 30,000 triangles (1.5 MB each), URDF_OBJ OBJ parts and
    URDF_DAE COLLADA parts of 40,000 triangles (~2 MB each), as mesh files, written under ``folder``."""
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    shapes = []
    for k in range(URDF_STL + URDF_OBJ + URDF_DAE):
        form = "stl" if k < URDF_STL else "obj" if k < URDF_STL + URDF_OBJ else "dae"
        v, f = part_mesh(200 + k, 30_000 if form == "stl" else 40_000)
        name = f"meshes/link{k:02d}.{form}"
        {"stl": write_stl, "obj": write_obj, "dae": write_dae}[form](folder / name, v, f)
        shapes.append({"name": f"link{k}", "pose": _part_pose(k), "geometry": {"type": "mesh", "url": name}})
    world = {"world_info": {"name": "urdf_meshes", "basic_time_step": 32}, "solids": _room(),
             "robots": [{"name": "arm", "controller": "<none>", "shapes": shapes}]}
    path = folder / "urdf_meshes.json"
    path.write_text(json.dumps(world))
    return path


_LOAD_CHILD = r"""
import json, os, statistics, subprocess, sys, time
import numpy as np
import trimesh
from sensorium.server.world import meshes
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import load_world

trimesh.Trimesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
                [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], process=True, validate=False).is_watertight
waited = {"ms": 0.0, "runs": 0}
for name in ("_run_worker", "_worker_header"):          # every wait on a mesh worker goes through these
    def timed(*a, _f=getattr(meshes, name), **k):
        t = time.perf_counter()
        try:
            return _f(*a, **k)
        finally:
            waited["ms"] += (time.perf_counter() - t) * 1e3
            waited["runs"] += 1
    setattr(meshes, name, timed)
t0 = time.perf_counter()
load_world(sys.argv[1], limits=WorldLimits.large())
total = (time.perf_counter() - t0) * 1e3
starts = getattr(meshes, "worker_starts", lambda: waited["runs"])()
env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
one = []
for _ in range(3):
    t = time.perf_counter()
    subprocess.run([sys.executable, "-I", "-c", "import numpy, trimesh"], env=env, check=True)
    one.append((time.perf_counter() - t) * 1e3)
start = statistics.median(one)
print(json.dumps({"total": total, "starts": starts, "start_ms": start, "workers_ms": waited["ms"],
                  "files": waited["runs"]}))
"""


def load_split(path: Path, tree: str | None = None) -> dict:
    """The load of ``path`` in a fresh interpreter (``tree`` first on its path), split: ms in worker
    starts, in their reading, in the rest."""
    env = dict(os.environ)
    env["PYTHONPATH"] = tree if tree is not None else str(Path(__file__).resolve().parents[2])
    out = subprocess.run([sys.executable, "-P", "-c", _LOAD_CHILD, str(path)], capture_output=True, text=True,
                         timeout=1800, check=False, env=env)        # (-P: as _child)
    if out.returncode != 0:
        raise RuntimeError(f"load child failed on {path.name}: {out.stderr.strip().splitlines()[-3:]}")
    got = json.loads(out.stdout.strip().splitlines()[-1])
    started = got["starts"] * got["start_ms"]
    return {"total ms": got["total"], "worker starts": got["starts"], "start ms": started,
            "reading ms": got["workers_ms"] - started, "rest ms": got["total"] - got["workers_ms"],
            "files": got["files"]}


def load_split_section(sec: Section, cfg: Config) -> None:
    """The mesh-file robot's load, split (``--load-split``), as a table and a finding of ``sec``."""
    with tempfile.TemporaryDirectory() as tmp:
        path = urdf_robot_world(Path(tmp))
        got = [load_split(path) for _ in range(cfg.pick(2, 1))]
    med = {k: float(np.median([g[k] for g in got])) for k in got[0]}
    sec.data.update(load_split=got)
    sec.tables.append(Table("cad_load_split", f"A robot of {URDF_STL + URDF_OBJ + URDF_DAE} mesh files over 1 MiB "
                            f"({URDF_STL} STL links of 1.5 MB, {URDF_OBJ} OBJ and {URDF_DAE} COLLADA parts of ~2 MB): "
                            "its load, split", ["load ms", "worker starts", "starts ms", "reading ms", "rest ms"],
                            [[f"{med['total ms']:.0f}", f"{med['worker starts']:.0f}", f"{med['start ms']:.0f}",
                              f"{med['reading ms']:.0f}", f"{med['rest ms']:.0f}"]], notes=[
                                "starts ms: the starts counted times one start timed alone (an interpreter importing "
                                "numpy and trimesh); reading ms: the time waiting on mesh workers less the starts",
                                "Reproduce: `python -m sensorium.benchmarks.cad --load-split`"]))
    sec.findings.append(f"A robot of {URDF_STL + URDF_OBJ + URDF_DAE} mesh files over 1 MiB loads in "
                        f"{med['total ms'] / 1e3:.1f} s with {med['worker starts']:.0f} mesh worker start(s).")


def load_split_main(trees: dict[str, str | None], rounds: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = urdf_robot_world(Path(tmp))
        runs: dict[str, list[dict]] = {t: [] for t in trees}
        for _ in range(rounds):
            for t, tree in trees.items():
                runs[t].append(load_split(path, tree))
                print(f"  load split: {t}: {runs[t][-1]['total ms']:.0f} ms", file=sys.stderr)
    print(f"a robot of {URDF_STL} STL links (1.5 MB each), {URDF_OBJ} OBJ and {URDF_DAE} COLLADA parts (~2 MB), "
          f"loaded; median of {rounds}:")
    for t, got in runs.items():
        med = {k: float(np.median([g[k] for g in got])) for k in got[0]}
        print(f"  {t}: load {med['total ms']:.0f} ms = worker starts {med['start ms']:.0f} ms "
              f"({med['worker starts']:.0f} starts) + reading {med['reading ms']:.0f} ms + rest {med['rest ms']:.0f} ms")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
