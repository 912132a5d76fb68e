"""Reads one mesh file in a process of its own, with a memory limit, for :mod:`.meshes`.

Mesh readers cost far more memory than the mesh they return: trimesh's OBJ reader took 3.4 GB
for a 16 MB file of 2 million ``f 1 2 3`` lines, its STL path ~1 KB per triangle (merging vertices
to judge watertightness included). A world file names its meshes, so a hostile one could make
``validate`` exhaust the machine. Here the reading runs under ``RLIMIT_AS``: past the limit the
reader fails (``MemoryError``) or the process dies, and the parent reports one line.

Run as ``python -I mesh_worker.py PATH SX SY SZ MEMORY_BYTES [FORMAT [MATERIAL NAME CAP]]`` (FORMAT:
``stl``, ``obj``, ``dae``, ...; by default the file's suffix; MATERIAL and NAME select a COLLADA file's
triangles (an OBJ file's: MATERIAL), as ``meshes.load_mesh``; CAP: the most triangles its scene may
place, "" for cad.py's own). It imports numpy and trimesh, and for those files ``cad.py`` by its path
(numpy, pycollada, trimesh), never the sensorium package. Reply on stdout: a 4-byte big-endian length
and a JSON header — ``{"ok": true, "vertices": NV, "faces": NF, "closed": bool}`` followed by NV×3
float64 and NF×3 int64 (native order), or ``{"ok": false, "kind": "memory" | "no triangles" | "cad" |
"error", "error": "..."}``. MATERIAL -2 asks for a COLLADA or OBJ file's materials only: ``{"ok": true,
"materials": [[name, diffuse, transparency, texture], ...], "used": [index, ...]}``, no arrays. MATERIAL
-3 asks for every used material's triangles from one reading (a CadShape of many materials reads a
large file once, not once a material): ``{"ok": true, "groups": [[MATERIAL, NV, NF, closed], ...]}``
followed by each group's NV×3 float64 and NF×3 int64, in that order.
"""

import json
import resource
import struct
import sys


def _reply(header, *arrays):
    out = sys.stdout.buffer
    data = json.dumps(header).encode("utf-8")
    out.write(struct.pack(">I", len(data)) + data)
    for a in arrays:
        out.write(memoryview(a).cast("B"))
    out.flush()


MATERIALS_ONLY = -2      # MATERIAL: reply with the file's materials and the ones its triangles use, no arrays
ALL_MATERIALS = -3       # MATERIAL: reply with each used material's triangles, read once


def _closed(np, trimesh, vertices, faces, scale):
    """Whether the triangles close a volume, coincident vertices merged (judged on the topology, as
    meshes.py does)."""
    if not (np.isfinite(vertices).all() and faces.min() >= 0 and faces.max() < len(vertices)):
        return False
    scaled = vertices * np.asarray(scale, dtype=np.float64)
    return bool(trimesh.Trimesh(vertices=scaled, faces=faces, process=True, validate=False).is_watertight)


def _cad_module():
    """``cad.py`` beside this file, loaded by its path (this process does not import sensorium)."""
    import importlib.util
    import os

    spec = importlib.util.spec_from_file_location("_sensorium_cad", os.path.join(os.path.dirname(__file__), "cad.py"))
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module          # (its dataclasses look their module up)
    spec.loader.exec_module(module)
    return module


def main():
    path, sx, sy, sz, memory = sys.argv[1], *map(float, sys.argv[2:5]), int(sys.argv[5])
    kind = sys.argv[6] if len(sys.argv) > 6 and sys.argv[6] else None
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    resource.setrlimit(resource.RLIMIT_CPU, (300, 300))       # a reader that never ends is stopped too
    try:
        import numpy as np
        import trimesh

        material = int(sys.argv[7]) if len(sys.argv) > 7 else -1
        if material == MATERIALS_ONLY:
            cad = _cad_module()
            try:
                read = cad.read_cad(path, kind)
            except cad.CadError as exc:
                _reply({"ok": False, "kind": "cad", "error": str(exc)[:2000]})
                return
            _reply({"ok": True, "materials": [[m.name, list(m.diffuse), m.transparency, m.texture]
                                              for m in read.materials], "used": read.used()})
            return
        if material == ALL_MATERIALS:
            cad = _cad_module()
            cap = int(sys.argv[9]) if len(sys.argv) > 9 and sys.argv[9] else None
            try:
                read = cad.read_cad(path, kind, cap)
                groups = []
                for m in read.used():
                    v, f, _ = read.select(m)
                    groups.append((m, np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64)))
            except cad.CadError as exc:
                _reply({"ok": False, "kind": "cad", "error": str(exc)[:2000]})
                return
            del read
            heads = [[m, len(v), len(f), _closed(np, trimesh, v, f, (sx, sy, sz))] for m, v, f in groups]
            _reply({"ok": True, "groups": heads}, *[a for _, v, f in groups for a in (v, f)])
            return
        if kind == "dae" or (kind == "obj" and material >= 0):
            cad = _cad_module()
            name = sys.argv[8] if len(sys.argv) > 8 else ""
            cap = int(sys.argv[9]) if len(sys.argv) > 9 and sys.argv[9] else None
            try:
                v, f, _ = cad.read_cad(path, kind, cap).select(material, name)
            except cad.CadError as exc:
                _reply({"ok": False, "kind": "cad", "error": str(exc)[:2000]})
                return
            vertices, faces = np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64)
        else:
            loaded = trimesh.load(path, file_type=kind, force="mesh", process=False)
            vertices = np.ascontiguousarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=np.float64)
            faces = np.ascontiguousarray(getattr(loaded, "faces", np.empty((0, 3))), dtype=np.int64)
            del loaded
        if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0 or vertices.ndim != 2 or vertices.shape[1] != 3:
            _reply({"ok": False, "kind": "no triangles", "error": "no triangles"})
            return
        closed = _closed(np, trimesh, vertices, faces, (sx, sy, sz))
    except MemoryError:
        _reply({"ok": False, "kind": "memory", "error": "out of memory"})
        return
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for bad files
        _reply({"ok": False, "kind": "error", "error": f"{type(exc).__name__}: {exc}"[:2000]})
        return
    _reply({"ok": True, "vertices": len(vertices), "faces": len(faces), "closed": closed}, vertices, faces)


if __name__ == "__main__":
    main()
