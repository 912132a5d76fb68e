"""What a world that validates costs to build stays bounded (issue 28: "10 validated worlds need
> 3 GiB to build"). Found by building worlds at the limits and measuring (README "Security and
limits"); each cause has a test here that failed before its fix:

* occluding LightSensors: the occlusion segments were computed for every (sensor, light) pair
  toward every light — (S × n) × n — 4.3 GB for 16,384 sensors and 64 lights;
* mesh files: trimesh's readers take up to hundreds of times a file's size (3.4 GB for a 16 MB OBJ
  of 2 million faces); a file larger than 1 MiB is now read in a worker process under a memory limit;
* EXACT's refinement data in the packet path: every float64 array of the numpy path made up front,
  and vertex rings stored per triangle as int64 (~18 entries each) -- ~400 B per triangle; now the
  dual basis and each vertex's triangles, ~75 B (README "Security and limits": 2.67 GiB peak for a
  world the limits accepted, now 1.4 GiB).

Memory is compared as a ratio of allocations (tracemalloc, deterministic) or bounded by the
operating system, never timed."""

from __future__ import annotations

import resource
import struct
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import WorldError, load_world, parse_world
from sensorium.server.world.meshes import IN_PROCESS_BYTES, MeshFileError, load_mesh


def _light_world(sensors: int, lights: int) -> dict:
    return {"lights": [{"type": "PointLight", "location": [k % 8 * 0.5, k // 8 * 0.5, 1.0]} for k in range(lights)],
            "robots": [{"name": "r", "devices": [{"device": "LightSensor", "name": f"l{i}", "occlusion": True,
                                                  "pose": {"translation": [0.001 * i, 0, 0.01]}}
                                                 for i in range(sensors)]}]}


def _step_peak(data: dict) -> tuple[int, list[float]]:
    sim = Simulation(parse_world(data))
    for dev in sim.robot("r").devices.values():
        dev.enable(sim.basic_time_step)
    sim.step()                                  # warm: scene and batches built
    tracemalloc.start()
    sim.step()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak, [float(d.value) for d in sim.robot("r").devices.values()]


def test_occlusion_rays_cost_sensors_times_lights_not_lights_squared() -> None:
    few, _ = _step_peak(_light_world(256, 8))
    many, values = _step_peak(_light_world(256, 32))
    # 4x the lights: 4x the rays; it was 16x the memory (each pair's segments toward every light)
    assert many < 8 * few, (few, many)
    assert all(v > 0 for v in values)


def test_occlusion_rays_are_those_of_each_pair() -> None:
    """The same rays as before (each sensor toward each light it sees), so the same readings:
    occluded by a wall between the sensors and two of the lights."""
    data = _light_world(4, 3)
    data["lights"] = [{"type": "PointLight", "location": [x, 0.0, 0.5], "intensity": 1.0} for x in (-1.0, 1.0, 3.0)]
    data["solids"] = [{"name": "wall", "pose": {"translation": [1.5, 0, 0.25]},
                       "geometry": {"type": "box", "size": [0.1, 2, 1]}}]
    open_data = {**data, "solids": []}
    _, walled = _step_peak(data)
    _, bare = _step_peak(open_data)
    # the wall hides the light at x=3 only: every sensor loses exactly that light's direct term
    assert all(w < b for w, b in zip(walled, bare))
    nowall3 = {**open_data, "lights": data["lights"][:2]}
    _, two = _step_peak(nowall3)
    assert walled == pytest.approx(two, rel=0, abs=1e-9)


# ------------------------------------------------------------------------------------ mesh files


def _binary_stl(path: Path, triangles: int) -> Path:
    rec = np.zeros(triangles, dtype=[("n", "<f4", 3), ("v", "<f4", 9), ("a", "<u2")])
    base = np.arange(triangles, dtype="<f4")[:, None] * np.array([1.0, 0.5, 0.25], dtype="<f4")
    rec["v"] = np.concatenate([base, base + [0.01, 0, 0], base + [0, 0.01, 0]], axis=1)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", triangles) + rec.tobytes())
    return path


def test_a_large_mesh_is_read_in_a_worker_and_equals_the_in_process_read(tmp_path: Path) -> None:
    big = _binary_stl(tmp_path / "big.stl", 30_000)             # 1.5 MB: read by the worker
    assert big.stat().st_size > IN_PROCESS_BYTES
    mesh = load_mesh(big, (2.0, 1.0, 0.5))
    import trimesh

    ref = trimesh.load(big, force="mesh", process=False)
    assert np.array_equal(mesh.vertices, np.asarray(ref.vertices, dtype=np.float64) * [2.0, 1.0, 0.5])
    assert np.array_equal(mesh.faces, np.asarray(ref.faces)) and mesh.closed is False
    assert load_mesh(big, (2.0, 1.0, 0.5)) is mesh                 # read once


def test_a_mesh_bomb_is_refused_within_the_memory_limit(tmp_path: Path) -> None:
    """2 million ``f 1 2 3`` lines (16 MB): trimesh took 3.4 GB for them in process. Under a
    512 MiB limit the worker stops and the world gets one line."""
    obj = tmp_path / "faces.obj"
    with open(obj, "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
        f.write("f 1 2 3\n" * 2_000_000)
    world = tmp_path / "w.yaml"
    world.write_text("solids: [{name: m, geometry: {type: mesh, url: faces.obj}}]\n")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(WorldError) as err:
        load_world(world, limits=WorldLimits(mesh_load_bytes=512 << 20))
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 200_000       # KiB: not read here
    assert [(p.path, p.message) for p in err.value.problems] == [
        ("solids[0].geometry.url", "cannot read mesh faces.obj: reading it needs more than 0.5 GiB of memory "
                                   "(raise the limits with --allow-large)")]


def test_a_mesh_over_the_triangle_limit_is_refused_before_its_arrays_are_copied(tmp_path: Path) -> None:
    stl = _binary_stl(tmp_path / "many.stl", 30_000)
    with pytest.raises(MeshFileError, match="has 30,000 triangles, more than the world's limit of 20,000"):
        load_mesh(stl, (1.0, 1.0, 1.0), max_triangles=20_000, memory=1 << 30)


def test_exact_refinement_data_of_the_packet_path_costs_under_100_bytes_per_triangle(monkeypatch) -> None:
    from sensorium.server.raycast import packets, tiers
    from sensorium.server.world.geometry import Pose, Sphere

    if packets.library() is None:
        pytest.skip(f"packet path unavailable: {packets.status()}")
    items = [(k, Sphere(radius=1.0, subdivision=5), Pose(np.eye(3), np.array([3.0 * k, 0.0, 0.0]))) for k in range(3)]
    monkeypatch.setattr(tiers, "_BLOCK", 4096)   # 15 blocks
    tracemalloc.start()
    try:
        tier = tiers._Tier(packets.Device(), items, np.full(3, -1))
        tier.scene(True)
        before = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        tier.prepare(True)          # what EXACT's first cast makes: the judging passes' data in packets.c
        held, peak = (m - before for m in tracemalloc.get_traced_memory())
    finally:
        tracemalloc.stop()
    n = len(tier.F)                 # 61,440 triangles
    assert tier.native(True) is not None
    assert held < 100 * n           # g1, g2 (48 B), h_min (8 B), each vertex's triangles (~16 B)
    assert peak < held + 40 * n     # made a block at a time (the vertices' sort: 36 B per triangle)
