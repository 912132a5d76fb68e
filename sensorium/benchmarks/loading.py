"""Loading: how long a world takes from file to a simulation, per stage.

A PROTO-heavy Webots world (``tests/worlds/proto/fifty_minipucks.wbt``: 50 e-puck-like PROTO robots
built by JavaScript templates and sub-PROTOs, 500 instances, 1 550 devices), the same world as the
Sensorium YAML file ``sensorium convert`` writes, a one-robot PROTO world and a robot of three parts
of a 20 000-point inline mesh (``big_mesh_world``), loaded in turn (A B C D A B C D …, so the
machine's load hits them alike). Stages, wall clock (``LoadedWorld.timings``):
parse (the .wbt text), proto files (reading and parsing PROTO files), instantiate (PROTO expansion
without its templates), template (QuickJS runs, the worker's start included), convert (nodes → the
world-file dict), validate (the pydantic model, cross-field checks, meshes, sanitising) and scene
(``Simulation(...)``: primitives, the ray engine's bodies, devices; BVHs are built at the first
cast, not here).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from .common import Config, Section, Table, median

STAGES = ("parse", "proto files", "instantiate", "template", "convert", "validate", "scene")
_TESTS = Path(__file__).resolve().parents[2] / "tests" / "worlds" / "proto"


def _load(path: Path) -> dict[str, float]:
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    t0 = time.perf_counter()
    loaded = load_world(path)
    t1 = time.perf_counter()
    Simulation(loaded, "exact")
    t2 = time.perf_counter()
    out = dict(loaded.timings)
    if "validate" not in out:           # a YAML world: reading, parsing and validating are one stage
        out["validate"] = t1 - t0
    out["scene"] = t2 - t1
    out["total"] = t2 - t0
    return out


def big_mesh_world(folder: Path, points: int = 20_000, parts: int = 3) -> Path:
    """A robot of ``parts`` instances of one PROTO holding an inline IndexedFaceSet of ``points``
    points and as many triangles (~1 MB of numbers, as a TIAGo's or a UR arm's PROTOs carry), written
    under ``folder``; the world file."""
    import numpy as np

    rng = np.random.default_rng(1)
    xyz = " ".join(f"{v:.6f}" for v in rng.uniform(-1.0, 1.0, 3 * points))
    index = " ".join(f"{a} {b} {c} -1" for a, b, c in rng.integers(0, points, (points, 3)).tolist())
    (folder / "protos").mkdir(parents=True, exist_ok=True)
    (folder / "worlds").mkdir(parents=True, exist_ok=True)
    (folder / "protos" / "BigPart.proto").write_text(
        "#VRML_SIM R2023b utf8\nPROTO BigPart [ field SFVec3f translation 0 0 0 ] {\n"
        "Solid { translation IS translation children [ Shape { geometry IndexedFaceSet {\n"
        f"coord Coordinate {{ point [ {xyz} ] }}\ncoordIndex [ {index} ]\n}} }} ] }}\n}}\n")
    kids = " ".join(f"BigPart {{ translation {k} 0 0 }}" for k in range(parts))
    world = folder / "worlds" / "big_mesh.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "../protos/BigPart.proto"\nWorldInfo { }\n'
                     f'Robot {{ name "r" children [ {kids} ] }}\n')
    return world


def run(cfg: Config) -> Section:
    from sensorium.server.world.wbt import wbt_to_dict
    from sensorium.server.world.wbt.emit import dump_yaml

    sec = Section("loading", "Loading worlds: PROTO expansion, conversion, validation, scene", intro=(
        "A PROTO-heavy Webots world (`tests/worlds/proto/fifty_minipucks.wbt`: 50 e-puck-like PROTO robots built "
        "by JavaScript templates and sub-PROTOs, 500 instances, 1 550 devices), the same world as the YAML file "
        "`sensorium convert` writes, a one-robot PROTO world and a robot of three instances of a PROTO holding "
        "a 20 000-point inline IndexedFaceSet (1 MB of numbers, as big robots' PROTOs carry), loaded in turn "
        "(A B C D A B C D …). Stages, wall "
        "clock (`LoadedWorld.timings`): parse (the .wbt text), proto files (reading and parsing PROTO files), "
        "instantiate (PROTO expansion without templates), template (QuickJS runs, the worker's start included), "
        "convert (nodes to the world-file dict), validate (model, cross-field checks, meshes, sanitising) and scene "
        "(`Simulation(...)`; BVHs are built at the first cast, not here)."))
    heavy = _TESTS / "fifty_minipucks.wbt"
    if not heavy.is_file():
        sec.findings.append(f"{heavy} not found (the benchmark worlds are in the source tree's tests/): not measured")
        return sec
    rounds = cfg.pick(9, 3)
    with tempfile.TemporaryDirectory() as tmp:
        yaml_twin = Path(tmp) / "fifty_minipucks.yaml"
        data, _, _ = wbt_to_dict(heavy)
        yaml_twin.write_text(dump_yaml(data))
        worlds = {"fifty_minipucks.wbt (50 PROTO robots)": heavy,
                  "fifty_minipucks.yaml (the same, converted)": yaml_twin,
                  "minipuck.wbt (1 PROTO robot)": _TESTS / "minipuck.wbt",
                  "big_mesh.wbt (3 parts of a 20k-point inline mesh)": big_mesh_world(Path(tmp) / "mesh")}
        if cfg.quick:          # the YAML twin alone takes seconds (PyYAML parsing 0.6 MB)
            del worlds["fifty_minipucks.yaml (the same, converted)"]
        for path in worlds.values():            # warm-up: imports, caches, the first worker start
            _load(path)
        runs: dict[str, list[dict[str, float]]] = {name: [] for name in worlds}
        for _ in range(rounds):
            for name, path in worlds.items():
                runs[name].append(_load(path))
    rows = []
    for name, samples in runs.items():
        stage = {k: median([s.get(k, 0.0) for s in samples]) * 1e3 for k in (*STAGES, "total")}
        rows.append([name, *(f"{stage[k]:.1f}" if any(k in s for s in samples) else "-" for k in STAGES),
                     f"{stage['total']:.0f}"])
        sec.data[name] = stage
    sec.tables.append(Table("loading", f"Loading a world, ms per stage (median of {rounds} interleaved loads)",
                            ["world", *STAGES, "total"], rows, notes=[
                                "validate: for the YAML twin, reading + parsing + validating the file",
                                "scene: building the simulation (BVHs are built at the first cast)"]))
    heavy_ms = sec.data[next(iter(worlds))]
    proto_ms = sum(heavy_ms[k] for k in ("proto files", "instantiate", "template"))
    twin = sec.data.get("fifty_minipucks.yaml (the same, converted)")
    sec.findings.append(f"Loading the 50-robot PROTO world takes {heavy_ms['total']:.0f} ms, of which "
                        f"{proto_ms:.0f} ms is PROTO expansion ({heavy_ms['template']:.0f} ms in templates), "
                        f"{heavy_ms['convert']:.0f} ms conversion and {heavy_ms['validate']:.0f} ms validation"
                        + (f"; the same world as converted YAML loads in {twin['total']:.0f} ms (YAML parsing)"
                           if twin else "") + ".")
    mesh = sec.data.get("big_mesh.wbt (3 parts of a 20k-point inline mesh)")
    if mesh:
        sec.findings.append(f"A robot of three parts of a 20 000-point inline mesh (a 1 MB PROTO) loads in "
                            f"{mesh['total']:.0f} ms, the scene included.")
    return sec
