"""Hardening of the one mesh worker that reads a world's mesh files in turn (sensorium/server/world/
meshes.py, mesh_worker.py): hostile files (random bytes of every format) followed by good files, a file
deleted or replaced while it is being loaded, two threads loading at once, and a fork (multiprocessing's
fork start method) after a load. Each hostile file is one line or a mesh; the good files after it read
the triangles a worker of their own reads; no worker is stuck, shared between threads or processes, or
left running. Process starts are counted through ``meshes._start_worker``, never timed."""

from __future__ import annotations

import multiprocessing
import os
import threading
from pathlib import Path

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_mesh_worker import starts  # noqa: F401  (the fixture)

from sensorium.benchmarks.cad import part_mesh, write_dae, write_obj, write_stl
from sensorium.server.world import meshes

pytestmark = pytest.mark.skipif("libasan" in os.environ.get("LD_PRELOAD", ""),
                                reason="the mesh worker's memory limit is below the sanitizers' shadow memory")

MEMORY = 512 << 20


def _good(folder: Path, counted: list[int]) -> dict[str, tuple[bytes, bytes]]:
    """Three good files and their triangles, each read by a worker of its own (``counted`` then 0)."""
    write_stl(folder / "g0.stl", *part_mesh(0, 1_500))
    write_obj(folder / "g1.obj", *part_mesh(1, 1_500))
    write_dae(folder / "g2.dae", *part_mesh(2, 1_500))
    out = {}
    for name in ("g0.stl", "g1.obj", "g2.dae"):
        meshes.close_workers()
        meshes._CACHE.clear()
        m = meshes.load_mesh(folder / name, memory=MEMORY)
        out[name] = (m.vertices.tobytes(), m.faces.tobytes())
    meshes.close_workers()
    meshes._CACHE.clear()
    counted[0] = 0
    return out


def _read(folder: Path, name: str) -> tuple[bytes, bytes]:
    m = meshes.load_mesh(folder / name, memory=MEMORY)
    return m.vertices.tobytes(), m.faces.tobytes()


STL_HEAD = b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
hostile = st.one_of(
    st.binary(max_size=600),
    st.builds(lambda b: STL_HEAD + b, st.binary(max_size=200)),
    st.builds(lambda n: b"\x00" * 80 + n.to_bytes(4, "little") + b"\x00" * 50, st.integers(0, (1 << 32) - 1)),
    st.builds(lambda t: t.encode("utf-8", "replace"), st.text(st.sampled_from("vf 0123456789.-e/#\n"), max_size=300)),
    st.sampled_from([b"<?xml version='1.0'?><COLLADA>", b"ply\nformat ascii 1.0\nelement vertex 99999999\nend_header\n",
                     b"glTF\x02\x00\x00\x00\xff\xff\xff\x7f", b"OFF\n99999999 99999999 0\n"]))


@pytest.mark.parametrize("examples", example_counts(60))
def test_hostile_files_then_good_files(tmp_path: Path, starts, examples: int) -> None:  # noqa: F811
    good = _good(tmp_path, starts)
    suffixes = ["stl", "obj", "dae", "ply", "glb", "off"]

    @settings(SETTINGS, max_examples=examples)
    @given(hostile, st.sampled_from(suffixes), st.sampled_from(sorted(good)))
    def run(data, suffix, name):
        bad = tmp_path / f"bad.{suffix}"
        bad.write_bytes(data)
        meshes._CACHE.clear()
        try:
            meshes.load_mesh(bad, display=bad.name, memory=MEMORY)
        except meshes.MeshFileError as exc:
            assert "\n" not in str(exc) and len(str(exc)) < 1000, exc
        assert _read(tmp_path, name) == good[name]
        assert len(meshes._IDLE) <= 1

    run()
    assert starts[0] < 60, starts      # a file it could not read is not its worker's end


def test_a_file_deleted_or_replaced_while_it_loads(tmp_path: Path, starts, monkeypatch) -> None:  # noqa: F811
    good = _good(tmp_path, starts)
    write_stl(tmp_path / "other.stl", *part_mesh(5, 1_700))
    meshes.close_workers()
    meshes._CACHE.clear()
    other = _read(tmp_path, "other.stl")
    meshes._CACHE.clear()
    read = meshes._read_in_worker
    change: list[str] = []

    def changed_first(path, *args, **kwargs):
        """The file is checked and stat'ed; then, before the worker reads it, it goes or changes."""
        if change:
            what = change.pop()
            if what == "delete":
                os.unlink(path)
            elif what == "replace":
                os.replace(tmp_path / "other.stl", path)
            else:
                Path(path).write_bytes(b"solid x\nfacet nope\n")
        return read(path, *args, **kwargs)

    monkeypatch.setattr(meshes, "_read_in_worker", changed_first)
    write_stl(tmp_path / "v.stl", *part_mesh(0, 1_500))
    change.append("delete")
    with pytest.raises(meshes.MeshFileError) as err:
        meshes.load_mesh(tmp_path / "v.stl", display="v.stl", memory=MEMORY)
    assert "\n" not in str(err.value) and "v.stl" in str(err.value), err.value
    assert _read(tmp_path, "g1.obj") == good["g1.obj"]
    write_stl(tmp_path / "v.stl", *part_mesh(0, 1_500))
    change.append("garbage")
    with pytest.raises(meshes.MeshFileError, match="^mesh v.stl has no triangles$"):
        meshes.load_mesh(tmp_path / "v.stl", display="v.stl", memory=MEMORY)
    write_stl(tmp_path / "v.stl", *part_mesh(0, 1_500))
    change.append("replace")                   # a whole other file: its triangles, not a mix
    assert _read(tmp_path, "v.stl") == other
    write_stl(tmp_path / "v.stl", *part_mesh(0, 1_500))   # written again: read again, not the cache's
    assert _read(tmp_path, "v.stl") == good["g0.stl"]
    assert starts[0] == 1


def test_two_threads_loading_at_once_each_read_right(tmp_path: Path, starts) -> None:  # noqa: F811
    good = _good(tmp_path, starts)
    names = sorted(good) * 4
    results: dict[int, list] = {}
    errors: list[BaseException] = []
    go = threading.Barrier(2)

    def load(k: int) -> None:
        try:
            go.wait()
            results[k] = [(n, _read(tmp_path, n)) for n in (names if k == 0 else names[::-1])]
        except BaseException as exc:      # (reported below)
            errors.append(exc)

    for _ in range(3):
        meshes._CACHE.clear()
        threads = [threading.Thread(target=load, args=(k,)) for k in (0, 1)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(timeout=120)
        assert not errors and not any(t.is_alive() for t in threads), errors
        for k in (0, 1):
            assert all(got == good[n] for n, got in results[k])
    assert starts[0] <= 2 and len(meshes._IDLE) <= 2      # one worker per thread at most, then kept


def _child(folder: str, queue) -> None:
    m = meshes.load_mesh(Path(folder) / "g1.obj", memory=MEMORY)
    queue.put((m.vertices.tobytes(), m.faces.tobytes(), meshes.worker_starts()))


def test_a_fork_after_a_load_reads_with_its_own_worker_and_holds_none_of_the_parents(
        tmp_path: Path, starts) -> None:  # noqa: F811
    good = _good(tmp_path, starts)
    assert _read(tmp_path, "g0.stl") == good["g0.stl"]
    (parent_worker,) = meshes._IDLE
    parent_starts = meshes.worker_starts()
    ctx = multiprocessing.get_context("fork")
    queue, gate = ctx.Queue(), ctx.Event()
    holder = ctx.Process(target=gate.wait, args=(120,))       # a forked process that lives on (a pool's)
    holder.start()
    try:
        meshes._CACHE.clear()
        child = ctx.Process(target=_child, args=(str(tmp_path), queue))
        child.start()
        vertices, faces, child_starts = queue.get(timeout=120)
        child.join(timeout=120)
        assert child.exitcode == 0
        assert (vertices, faces) == good["g1.obj"]
        assert child_starts == parent_starts + 1         # its own worker, not its parent's
        assert _read(tmp_path, "g2.dae") == good["g2.dae"]      # the parent's worker reads on
        assert meshes._IDLE == [parent_worker]
        # the parent ends its worker while the forked process lives: the worker sees its input close and
        # ends by itself (a fork held the pipe open: the worker waited out 30 s, then was killed)
        meshes.close_workers()
        assert parent_worker.proc.returncode == 0, parent_worker.proc.returncode
    finally:
        gate.set()
        holder.join(timeout=120)
