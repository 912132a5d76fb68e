"""Mesh files over meshes.IN_PROCESS_BYTES are read by a worker process under a memory limit
(sensorium/server/world/mesh_worker.py). Starting one costs ~0.4 s (an interpreter importing numpy
and trimesh), so one worker reads the files of a world one after another, each under its own limit:
the same triangles as a process of its own per file, bit for bit; a file that hits the limit is one
line and the next file is read by a new worker. Process starts are counted through the
``meshes._start_worker`` seam, never timed."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from sensorium.benchmarks.cad import part_mesh, write_dae, write_obj, write_stl
from sensorium.server.world import meshes
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import WorldError, load_world

# the worker's memory limit is below the sanitizers' shadow memory (CI's sanitizer pass, as
# tests/test_dae.py and tests/test_build_memory.py say): no worker reads there
pytestmark = pytest.mark.skipif("libasan" in os.environ.get("LD_PRELOAD", ""),
                                reason="the mesh worker's memory limit is below the sanitizers' shadow memory")


@pytest.fixture
def starts(monkeypatch) -> list[int]:
    """Every file read by a worker (IN_PROCESS_BYTES 0: small files, fast), workers never left to end
    idle while a test runs; the number of worker processes started, counted as they start."""
    meshes.close_workers()
    meshes._CACHE.clear()
    meshes._MATERIALS.clear()
    monkeypatch.setattr(meshes, "IN_PROCESS_BYTES", 0)
    monkeypatch.setattr(meshes, "WORKER_IDLE_S", 600.0)
    count = [0]
    start = meshes._start_worker

    def counted():
        count[0] += 1
        return start()

    monkeypatch.setattr(meshes, "_start_worker", counted)
    yield count
    meshes.close_workers()
    meshes._CACHE.clear()
    meshes._MATERIALS.clear()


def _parts(folder: Path) -> list[tuple[str, dict]]:
    """Five files of closed bumpy tori (STL, STL, OBJ, COLLADA) and how each is asked for
    (load_mesh's keywords): trimesh's readers, a COLLADA file whole and by material (cad.py)."""
    files = []
    for k, (form, write) in enumerate((("stl", write_stl), ("stl", write_stl), ("obj", write_obj), ("dae", write_dae))):
        v, f = part_mesh(k, 2_000 + 500 * k)
        write(folder / f"link{k}.{form}", v, f)
        files.append(f"link{k}.{form}")
    return [(files[0], {"scale": (1.0, 2.0, 0.5)}), (files[1], {}), (files[2], {"scale": (3.0, 3.0, 3.0)}),
            (files[3], {}), (files[3], {"material": 0})]


def _read(folder: Path, asks: list[tuple[str, dict]]) -> list[tuple[bytes, bytes, bool]]:
    out = []
    for name, kw in asks:
        m = meshes.load_mesh(folder / name, kw.get("scale", (1.0, 1.0, 1.0)), material=kw.get("material", -1))
        out.append((m.vertices.tobytes(), m.faces.tobytes(), m.closed))
    return out


def test_the_files_of_a_world_are_read_by_one_worker_with_the_triangles_of_a_worker_per_file(
        tmp_path: Path, starts: list[int]) -> None:
    asks = _parts(tmp_path)
    alone = []
    for ask in asks:                    # each file by a new worker, as each had a process of its own
        meshes.close_workers()
        meshes._CACHE.clear()
        alone += _read(tmp_path, [ask])
    assert starts[0] == len(asks)
    meshes.close_workers()
    meshes._CACHE.clear()
    starts[0] = 0
    together = _read(tmp_path, asks)
    materials = meshes.file_materials(tmp_path / "link3.dae", "dae")
    assert starts[0] == 1
    assert together == alone                                     # bit for bit
    assert all(closed for _, _, closed in together)              # (closed tori, as read)
    assert [m.diffuse for m in materials[0]] == [(0.6, 0.6, 0.7)] and materials[1] == [0]
    # a world's load: every file by the one worker still waiting, none read twice
    meshes._CACHE.clear()
    world = {"solids": [{"name": f"p{i}", "geometry": {"type": "mesh", "url": name, "scale": list(kw.get("scale", (1, 1, 1))),
                                                      **({"material_index": kw["material"]} if "material" in kw else {})}}
                        for i, (name, kw) in enumerate(asks)]}
    (tmp_path / "w.json").write_text(json.dumps(world))
    loaded = load_world(tmp_path / "w.json")
    assert starts[0] == 1 and len(loaded.world.solids) == len(asks)
    assert _read(tmp_path, asks) == alone


def test_a_file_over_the_memory_limit_is_one_line_and_the_next_file_loads(tmp_path: Path, starts: list[int]) -> None:
    """2 million ``f 1 2 3`` lines (16 MB, 3.4 GB in trimesh) between two STL files, under 512 MiB:
    the bomb is said in today's line; the worker that hit the limit ends and a new one reads on."""
    for k in (0, 1):
        write_stl(tmp_path / f"link{k}.stl", *part_mesh(k, 2_000))
    with open(tmp_path / "faces.obj", "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
        f.write("f 1 2 3\n" * 2_000_000)
    memory = 512 << 20
    first = meshes.load_mesh(tmp_path / "link0.stl", memory=memory)
    with pytest.raises(meshes.MeshFileError) as err:
        meshes.load_mesh(tmp_path / "faces.obj", display="faces.obj", memory=memory)
    assert str(err.value) == ("cannot read mesh faces.obj: reading it needs more than 0.5 GiB of memory "
                              "(raise the limits with --allow-large)")
    assert starts[0] == 1                                         # the bomb went to the worker that read link0
    second = meshes.load_mesh(tmp_path / "link1.stl", memory=memory)
    assert starts[0] == 2
    n = len(part_mesh(0, 2_000)[1])
    assert len(first.faces) == len(second.faces) == n and first.closed and second.closed
    # the same in a world: one problem, for the bomb only, and the file after it read
    meshes._CACHE.clear()
    world = {"solids": [{"name": n, "geometry": {"type": "mesh", "url": n}} for n in ("link0.stl", "faces.obj", "link1.stl")]}
    (tmp_path / "w.json").write_text(json.dumps(world))
    with pytest.raises(WorldError) as bad:
        load_world(tmp_path / "w.json", limits=WorldLimits(mesh_load_bytes=memory))
    assert [(p.path, p.message) for p in bad.value.problems] == [
        ("solids[1].geometry.url", "cannot read mesh faces.obj: reading it needs more than 0.5 GiB of memory "
                                   "(raise the limits with --allow-large)")]
    assert str((tmp_path / "link1.stl").resolve()) in {k[0] for k in meshes._CACHE}


def test_a_worker_that_ended_while_waiting_is_replaced_and_a_bad_file_leaves_it_reading(
        tmp_path: Path, starts: list[int]) -> None:
    for k in (0, 1, 2):
        write_stl(tmp_path / f"link{k}.stl", *part_mesh(k, 2_000))
    (tmp_path / "bad.stl").write_bytes(b"solid x\nfacet normal 0 0 nope\n" * 1000)
    write_dae(tmp_path / "whole.dae", *part_mesh(3, 2_000))
    (tmp_path / "bad.dae").write_text((tmp_path / "whole.dae").read_text()[:3000])
    meshes.load_mesh(tmp_path / "link0.stl")
    with pytest.raises(meshes.MeshFileError, match=r"^mesh bad\.stl has no triangles$"):
        meshes.load_mesh(tmp_path / "bad.stl", display="bad.stl")
    with pytest.raises(meshes.MeshFileError, match=r"^cannot read COLLADA mesh bad\.dae: XML Parsing Error"):
        meshes.load_mesh(tmp_path / "bad.dae", display="bad.dae")
    meshes.load_mesh(tmp_path / "link1.stl")
    assert starts[0] == 1                                         # a file it could not read is not its end
    (idle,) = meshes._IDLE
    idle.proc.kill()                                              # as if it had ended, idle
    idle.proc.wait()
    n = len(part_mesh(2, 2_000)[1])
    assert len(meshes.load_mesh(tmp_path / "link2.stl").faces) == n
    assert starts[0] == 2
    # more triangles than the world's limit: said before the arrays are read; that worker is ended
    meshes._CACHE.clear()
    n = len(part_mesh(0, 2_000)[1])
    with pytest.raises(meshes.MeshFileError, match=f"has {n:,} triangles, more than the world's limit of {n - 1:,}"):
        meshes.load_mesh(tmp_path / "link0.stl", max_triangles=n - 1)
    assert len(meshes.load_mesh(tmp_path / "link0.stl").faces) == n and starts[0] == 3


def test_a_wbt_worlds_cad_shapes_and_meshes_are_read_by_one_worker(tmp_path: Path, starts: list[int]) -> None:
    """A .wbt's CadShapes (their materials read while converting, then their triangles) and Mesh
    nodes: one worker reads them all, the same triangles as a worker per file."""
    write_dae(tmp_path / "a.dae", *part_mesh(0, 2_000))
    write_dae(tmp_path / "b.dae", *part_mesh(1, 2_500))
    write_stl(tmp_path / "c.stl", *part_mesh(2, 3_000))
    (tmp_path / "w.wbt").write_text(
        '#VRML_SIM R2023b utf8\nSolid { children [ CadShape { url [ "a.dae" ] } CadShape { url [ "b.dae" ] } '
        'Shape { geometry Mesh { url [ "c.stl" ] } } ] }\n')
    shapes = load_world(tmp_path / "w.wbt").world.solids[0].shapes
    assert starts[0] == 1
    assert [(s.geometry.url, s.appearance.base_color if s.appearance else None) for s in shapes][:2] == [
        ("a.dae", (0.6, 0.6, 0.7)), ("b.dae", (0.6, 0.6, 0.7))]
    together = _read(tmp_path, [("a.dae", {"material": 0}), ("b.dae", {"material": 0}), ("c.stl", {})])
    meshes._CACHE.clear()
    alone = []
    for ask in [("a.dae", {"material": 0}), ("b.dae", {"material": 0}), ("c.stl", {})]:
        meshes.close_workers()
        meshes._CACHE.clear()
        alone += _read(tmp_path, [ask])
    assert together == alone and starts[0] == 4


def test_a_worker_that_dies_reading_is_said_in_one_line_and_the_next_file_loads(
        tmp_path: Path, starts: list[int], monkeypatch) -> None:
    """A worker that takes a file and dies before its reply (as one killed at the CPU limit, or by the
    system at the memory limit): today's line with its exit status; a new worker reads the next file."""
    for k in (0, 1):
        write_stl(tmp_path / f"link{k}.stl", *part_mesh(k, 2_000))
    dies = "import sys\nsys.stdin.buffer.readline()\nsys.stdout.buffer.write(b'\\x01')\nsys.stdout.flush()\nsys.exit(3)\n"

    def first_dies() -> meshes._Worker:
        starts[0] += 1
        return meshes._Worker(600.0, dies if starts[0] == 1 else None)

    monkeypatch.setattr(meshes, "_start_worker", first_dies)
    with pytest.raises(meshes.MeshFileError) as err:
        meshes.load_mesh(tmp_path / "link0.stl", display="link0.stl")
    assert str(err.value) == ("cannot read mesh link0.stl: its reader stopped (exit status 3), most likely at the "
                              "limits for reading a mesh (2 GiB of memory, 300 s) (raise the limits with --allow-large)")
    assert len(meshes.load_mesh(tmp_path / "link1.stl").faces) == len(part_mesh(1, 2_000)[1]) and starts[0] == 2
