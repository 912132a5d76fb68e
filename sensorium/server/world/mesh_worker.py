"""Reads mesh files one after another in a process of its own, each within a memory limit, for
:mod:`.meshes`.

Mesh readers cost far more memory than the mesh they return: trimesh's OBJ reader took 3.4 GB
for a 16 MB file of 2 million ``f 1 2 3`` lines, its STL path ~1 KB per triangle (merging vertices
to judge watertightness included). A world file names its meshes, so a hostile one could make
``validate`` exhaust the machine. Here each file is read under ``RLIMIT_AS``: past the limit the
reader fails (``MemoryError``) or the process dies, and the parent reports one line. Starting this
process (an interpreter importing numpy and trimesh) costs ~0.4 s, more than reading a 1.5 MB STL
file, so one process reads the files of a world in turn: the address-space soft limit is set before
each file to what the process holds then plus what that file may take (MEMORY, less what the
process held when it was ready: a fresh process's limit is MEMORY, as a process of its own per file
had), the CPU-time soft limit to 300 s more than it has used, both restored after the file. After a
file that hit the memory limit the process ends (its state is not trusted); the parent starts
another for the next file. It ends too when its standard input closes, or after IDLE seconds
without a request.

Run as ``python -I mesh_worker.py [IDLE]``. It imports numpy and trimesh, and for COLLADA and OBJ
material reads ``cad.py`` by its path (numpy, pycollada, trimesh), never the sensorium package.
Requests on stdin, one JSON object a line: ``{"path": PATH, "scale": [SX, SY, SZ], "memory":
MEMORY_BYTES, "format": FORMAT, "material": MATERIAL, "name": NAME, "cap": CAP}`` (FORMAT: ``stl``,
``obj``, ``dae``, ...; MATERIAL and NAME select a COLLADA file's triangles (an OBJ file's: MATERIAL),
as ``meshes.load_mesh``, -1 and "": all; CAP: the most triangles its scene may place, null for
cad.py's own). For each request it writes one byte 0x01 (taken: a parent that sees end of file
before it knows this process had ended before it read the request), then the reply: a 4-byte
big-endian length and a JSON header — ``{"ok": true, "vertices": NV, "faces": NF, "closed": bool}``
followed by NV×3 float64 and NF×3 int64 (native order), or ``{"ok": false, "kind": "memory" | "no
triangles" | "cad" | "error", "error": "..."}``. MATERIAL -2 asks for a COLLADA or OBJ file's
materials only: ``{"ok": true, "materials": [[name, diffuse, transparency, texture], ...], "used":
[index, ...]}``, no arrays. MATERIAL -3 asks for every used material's triangles from one reading (a
CadShape of many materials reads a large file once, not once a material): ``{"ok": true, "groups":
[[MATERIAL, NV, NF, closed], ...]}`` followed by each group's NV×3 float64 and NF×3 int64, in that order.
"""

import json
import os
import resource
import struct
import sys

TAKEN = b"\x01"
CPU_SECONDS = 300        # a reader that never ends is stopped too
RETIRE_BYTES = 256 << 20  # a process left holding this much more than when it was ready ends after the file


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


_CAD = []


def _cad_module():
    """``cad.py`` beside this file, loaded by its path once (this process does not import sensorium)."""
    if not _CAD:
        import importlib.util

        spec = importlib.util.spec_from_file_location("_sensorium_cad", os.path.join(os.path.dirname(__file__), "cad.py"))
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module          # (its dataclasses look their module up)
        spec.loader.exec_module(module)
        _CAD.append(module)
    return _CAD[0]


def _address_space():
    """This process's address space in bytes (what RLIMIT_AS bounds)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


def _read(np, trimesh, request):
    """Reply to one request; False when the process must end (it hit the memory limit)."""
    path, (sx, sy, sz) = str(request["path"]), (float(s) for s in request["scale"])
    kind = request.get("format") or None
    material, name = int(request.get("material", -1)), str(request.get("name", ""))
    cap = None if request.get("cap") is None else int(request["cap"])
    try:
        if material == MATERIALS_ONLY:
            cad = _cad_module()
            try:
                read = cad.read_cad(path, kind)
            except cad.CadError as exc:
                _reply({"ok": False, "kind": "cad", "error": str(exc)[:2000]})
                return True
            _reply({"ok": True, "materials": [[m.name, list(m.diffuse), m.transparency, m.texture]
                                              for m in read.materials], "used": read.used()})
            return True
        if material == ALL_MATERIALS:
            cad = _cad_module()
            try:
                read = cad.read_cad(path, kind, cap)
                groups = []
                for m in read.used():
                    v, f, _ = read.select(m)
                    groups.append((m, np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64)))
            except cad.CadError as exc:
                _reply({"ok": False, "kind": "cad", "error": str(exc)[:2000]})
                return True
            del read
            heads = [[m, len(v), len(f), _closed(np, trimesh, v, f, (sx, sy, sz))] for m, v, f in groups]
            _reply({"ok": True, "groups": heads}, *[a for _, v, f in groups for a in (v, f)])
            return True
        if kind == "dae" or (kind == "obj" and material >= 0):
            cad = _cad_module()
            try:
                v, f, _ = cad.read_cad(path, kind, cap).select(material, name)
            except cad.CadError as exc:
                _reply({"ok": False, "kind": "cad", "error": str(exc)[:2000]})
                return True
            vertices, faces = np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64)
        else:
            loaded = trimesh.load(path, file_type=kind, force="mesh", process=False)
            vertices = np.ascontiguousarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=np.float64)
            faces = np.ascontiguousarray(getattr(loaded, "faces", np.empty((0, 3))), dtype=np.int64)
            del loaded
        if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0 or vertices.ndim != 2 or vertices.shape[1] != 3:
            _reply({"ok": False, "kind": "no triangles", "error": "no triangles"})
            return True
        closed = _closed(np, trimesh, vertices, faces, (sx, sy, sz))
    except MemoryError:
        _reply({"ok": False, "kind": "memory", "error": "out of memory"})
        return False
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for bad files
        _reply({"ok": False, "kind": "error", "error": f"{type(exc).__name__}: {exc}"[:2000]})
        return True
    _reply({"ok": True, "vertices": len(vertices), "faces": len(faces), "closed": closed}, vertices, faces)
    return True


def _bounded(np, trimesh, request, ready):
    """``_read`` with the address space bounded to what the process holds now plus the file's budget
    (MEMORY less ``ready``, what it held when it was ready) and the CPU time to CPU_SECONDS more;
    both limits restored after."""
    budget = int(request["memory"]) - ready
    if budget <= 0:                  # (the interpreter and its imports alone are over the limit)
        _reply({"ok": False, "kind": "memory", "error": "out of memory"})
        return True
    space = resource.getrlimit(resource.RLIMIT_AS)
    cpu = resource.getrlimit(resource.RLIMIT_CPU)
    used = resource.getrusage(resource.RUSAGE_SELF)
    limit = _address_space() + budget
    seconds = int(used.ru_utime + used.ru_stime) + 1 + CPU_SECONDS
    resource.setrlimit(resource.RLIMIT_AS, (limit if space[1] == resource.RLIM_INFINITY else min(limit, space[1]),
                                            space[1]))
    resource.setrlimit(resource.RLIMIT_CPU, (seconds if cpu[1] == resource.RLIM_INFINITY else min(seconds, cpu[1]),
                                             cpu[1]))
    try:
        return _read(np, trimesh, request)
    finally:
        resource.setrlimit(resource.RLIMIT_AS, space)
        resource.setrlimit(resource.RLIMIT_CPU, cpu)


def _tidy():
    """Free what the last file left: cad.py's cache of read files, cycles, glibc's free pages."""
    import gc

    if _CAD:
        _CAD[0]._read.cache_clear()
    gc.collect()
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


def main():
    import select

    idle = float(sys.argv[1]) if len(sys.argv) > 1 else 5.0
    os.environ.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")   # little address space
    import numpy as np
    import trimesh

    ready = _address_space()
    stdin = sys.stdin.buffer
    while True:
        if not select.select([stdin], [], [], idle)[0]:
            return                   # idle: the parent starts another when it needs one
        line = stdin.readline()
        if not line:
            return                   # the parent closed its end
        sys.stdout.buffer.write(TAKEN)
        sys.stdout.buffer.flush()
        try:
            request = json.loads(line)
            if not isinstance(request, dict):
                raise TypeError("not an object")
        except (ValueError, TypeError) as exc:
            _reply({"ok": False, "kind": "error", "error": f"bad request: {exc}"[:2000]})
            return
        if not _bounded(np, trimesh, request, ready):
            return
        _tidy()
        if _address_space() - ready > RETIRE_BYTES:
            return


if __name__ == "__main__":
    main()
