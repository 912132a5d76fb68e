"""What a robot of many meshes holds once its scene is built (``sensorium/benchmarks/cad.py`` measures
it): each mesh's triangles once in the ray engine whatever kinds of rays see them, and no cache
holding a second copy of an inline mesh's numbers. Counted (objects, tracemalloc's allocations),
never timed."""

from __future__ import annotations

import gc
import os
import tracemalloc
from pathlib import Path

import numpy as np

from sensorium.benchmarks.cad import cad_robot_world, part_mesh, swarm_world
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.limits import WorldLimits
from sensorium.server.world.loader import load_world
from sensorium.server.world.meshes import triangles_mesh


def _tiers(sim: Simulation) -> list:
    eng = sim.scene.engine
    return list({id(t): t for t in (*eng._static.values(), *eng._shared.values()) if t is not None}.values())


def _stepped(path: Path) -> Simulation:
    sim = Simulation(load_world(path, limits=WorldLimits.large()), "fast")
    for robot in sim.world.robots:
        for d in robot.devices:
            sim.device(f"{robot.name}/{d.name}").enable(32)
    sim.step()
    return sim


def test_a_cad_robots_meshes_are_held_once_for_bounding_and_visual_rays(tmp_path: Path) -> None:
    """Three inline meshes seen by both kinds of rays (the default), a lidar (visual rays) and laser
    distance sensors (bounding rays): two tiers in all, the room's and the robot's, the robot's
    holding each of its triangles once (before: a bounding and a visual copy of each, BVH included)."""
    sim = _stepped(cad_robot_world(tmp_path, "triangles", parts=3, scale=0.05))
    expected = sum(len(part_mesh(k, n)[1]) for k, n in enumerate([1000, 1500, 2000]))
    tiers = _tiers(sim)
    assert len(tiers) == 2
    assert sorted(len(t.F) for t in tiers) == [12 * 4, expected]      # four walls of 12 triangles; the parts
    assert np.isfinite(sim.device("cad/lidar").range_image).any()


def test_a_swarms_inline_meshes_are_one_mesh_and_one_tier(tmp_path: Path) -> None:
    """Twelve robots carrying the same three inline meshes (a PROTO's IndexedFaceSets, converted):
    one Mesh per part, and one body-frame tier for all of them."""
    sim = _stepped(swarm_world(tmp_path, 12, "triangles", triangles=300))
    robot_tiers = [t for t in _tiers(sim) if t is not sim.scene.engine._static_tier("visual")]
    assert len(robot_tiers) == 1 and len(robot_tiers[0].F) == 3 * len(part_mesh(100, 300)[1])
    meshes = {id(e.primitive) for e in sim.scene.engine._entries if type(e.primitive).__name__ == "Mesh"}
    assert len(meshes) == 3


def test_inline_triangles_are_cached_without_a_second_copy_of_their_numbers() -> None:
    """triangles_mesh keeps the Mesh (float64 vertices, int64 faces: 24 bytes a row) and a digest;
    before, its cache key was the numbers again as tuples of Python floats and ints (~64 bytes a
    row more, kept as long as the cached Mesh). The same numbers in other lists: the same Mesh."""
    v, f = part_mesh(7, 6000)
    vertices, faces = [tuple(r) for r in v.tolist()], [tuple(r) for r in f.tolist()]
    arrays = 24 * (len(v) + len(f))
    triangles_mesh(*part_mesh(8, 200))      # (trimesh's watertightness judge imports what it needs on first use)
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        mesh = triangles_mesh(vertices, faces)
        gc.collect()
        kept = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert arrays <= kept < arrays + 64_000, (kept, arrays)
    assert np.array_equal(mesh.vertices, v) and np.array_equal(mesh.faces, f) and mesh.closed
    again = triangles_mesh([list(r) for r in vertices], [list(r) for r in faces])
    assert again is mesh
    moved = triangles_mesh([(x + 1.0, y, z) for x, y, z in vertices], faces)
    assert moved is not mesh and np.array_equal(moved.vertices[:, 0], v[:, 0] + 1.0)


def test_a_mesh_files_vertices_are_held_once_per_position(tmp_path: Path) -> None:
    """A binary STL file gives three vertices per triangle; its Mesh holds each position once (the
    tier's welding, done once when read: the tier's arrays are unchanged), in process and from the
    reading worker (a file over 1 MiB). A file with an unused vertex is kept as read."""
    from sensorium.benchmarks.cad import write_stl
    from sensorium.server.raycast import tiers
    from sensorium.server.world.geometry import Pose
    from sensorium.server.world.meshes import IN_PROCESS_BYTES, load_mesh, welded

    # the worker cannot start under the sanitizers' LD_PRELOAD (CI's sanitizer pass: their shadow memory
    # is over its address-space limit, as tests/test_build_memory.py says): the in-process read only
    sizes = ((3, 3000),) if "libasan" in os.environ.get("LD_PRELOAD", "") else ((3, 3000), (4, 25_000))
    for k, n in sizes:
        v, f = part_mesh(k, n)
        path = tmp_path / f"part{k}.stl"
        write_stl(path, v, f)
        assert (path.stat().st_size > IN_PROCESS_BYTES) == (n > 20_000)
        mesh = load_mesh(path)
        assert len(mesh.vertices) == len(v) and len(mesh.faces) == len(f) and mesh.closed
        corners = v.astype(np.float32).astype(np.float64)[f]               # (STL stores float32)
        assert np.array_equal(mesh.vertices[mesh.faces], corners)
        again = welded(mesh.vertices, mesh.faces)
        assert np.array_equal(again[0], mesh.vertices) and np.array_equal(again[1], mesh.faces)
        tier = tiers._Tier(tiers.new_device(), [(0, mesh, Pose.identity())], np.array([-1]))
        soup = welded(corners.reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3))   # what the tier welded before
        assert np.array_equal(tier.V, soup[0]) and np.array_equal(tier.F[:len(f)], soup[1])
    ply = tmp_path / "spare.ply"          # (a repeated position and an unused vertex: as read)
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n0 1 0\n1 0 0\n5 5 5\n3 0 1 2\n3 2 3 0\n")
    assert len(load_mesh(ply).vertices) == 5


def test_a_meshs_valid_faces_are_found_once_and_are_its_own_faces_when_all_are_valid() -> None:
    """tessellate(Mesh) is asked for by the scene (triangle counts, robot after robot of a swarm
    sharing the Mesh) and the ray engine: its valid faces are found once, and are the Mesh's own
    array (no copy) when none is degenerate."""
    from sensorium.server.world.geometry import Mesh, tessellate

    v, f = part_mesh(2, 500)
    whole = Mesh(v, f, True)
    assert tessellate(whole)[1] is whole.faces and tessellate(whole)[1] is whole.faces
    spoiled = Mesh(v, np.r_[f, [[0, 0, 1]]], False)               # one degenerate face more
    kept = tessellate(spoiled)[1]
    assert np.array_equal(kept, f) and tessellate(spoiled)[1] is kept and not kept.flags.writeable


def test_a_face_indexing_outside_the_vertices_is_named_first_bad_face_first() -> None:
    """The loader's index check is one numpy pass over a mesh's faces: the same one problem, at the
    first face out of range (a negative index or one past the vertices), its indices quoted."""
    import pytest

    from sensorium.server.world.loader import WorldError, parse_world

    v, f = part_mesh(1, 400)
    for bad_at, bad in ((150, [3, -1, 4]), (7, [2, len(v), 5]), (len(f) - 1, [len(v) + 9, 0, 1])):
        faces = f.tolist()
        faces[bad_at] = bad
        world = {"robots": [{"name": "r", "shapes": [{"geometry": {"type": "triangles", "vertices": v.tolist(),
                                                                   "faces": faces}}]}]}
        with pytest.raises(WorldError) as info:
            parse_world(world)
        assert [(p.path, p.message) for p in info.value.problems] == [
            (f"robots[0].shapes[0].geometry.faces[{bad_at}]", f"vertex index outside 0..{len(v) - 1}: {bad}")]
    big = f.tolist()
    big[3] = [2**70, 0, 1]        # (beyond 64 bits: checked face by face, the same line)
    with pytest.raises(WorldError) as info:
        parse_world({"robots": [{"name": "r", "shapes": [{"geometry": {"type": "triangles", "vertices": v.tolist(),
                                                                       "faces": big}}]}]})
    assert [(p.path, p.message) for p in info.value.problems] == [
        ("robots[0].shapes[0].geometry.faces[3]", f"vertex index outside 0..{len(v) - 1}: [{2**70}, 0, 1]")]
