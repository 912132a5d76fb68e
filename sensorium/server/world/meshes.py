"""Mesh files (STL, OBJ, PLY, GLB via trimesh; COLLADA, and an OBJ file's faces of one material, via
:mod:`.cad`) → float64 triangle arrays, each position once (welded, as the ray engine holds them).

Loaded meshes are cached by (resolved path, modification time, scale): validating a world and then
building its scene reads each file once. A file larger than ``IN_PROCESS_BYTES`` is read by a
worker process under a memory limit (:mod:`.mesh_worker`): mesh readers need up to hundreds of
times a file's size (3.4 GB for a 16 MB OBJ), and a world file names its meshes. One worker reads
files in turn, each under its own limit (its start costs more than reading a 1.5 MB file).
"""

from __future__ import annotations

import os
import threading
import weakref
from collections import OrderedDict
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

SUPPORTED = {".stl", ".obj", ".ply", ".glb", ".gltf", ".off", ".dae"}
IN_PROCESS_BYTES = 1 << 20            # smaller files are read in process (a 1 MiB OBJ costs ~0.2 GB at worst)
DEFAULT_LOAD_MEMORY = 2 << 30         # the worker's address space (WorldLimits.mesh_load_bytes)


class MeshFileError(Exception):
    """A mesh file that is missing, unreadable or not a triangle mesh."""


class MeshMemoryError(MeshFileError):
    """A file's materials did not fit in the reading worker's memory (its geometry may still load,
    under raised limits)."""


def resolve_mesh_url(url: str, base_dir: Path, *, allow_outside: bool = False, max_bytes: int | None = None,
                     allowed: frozenset[Path] = frozenset()) -> Path:
    """A world file's mesh ``url`` → the file it names, relative to the world's folder.

    Unless ``allow_outside``, the file (symbolic links followed) must be inside ``base_dir``: an
    absolute url or one that climbs out with ``..`` is refused, except the files in ``allowed`` (a
    .wbt world's PROTO meshes and ``webots://`` assets, read only). Errors quote the url as written,
    never a resolved path elsewhere on the machine."""
    if "\0" in url:
        raise MeshFileError("mesh url contains a NUL byte")
    if not url.strip():
        raise MeshFileError("mesh url is empty")
    base = Path(base_dir).resolve()
    try:
        path = (base / url).resolve()
    except (OSError, RuntimeError, ValueError) as exc:       # symlink loops, bad names
        raise MeshFileError(f"mesh url {url!r} cannot be resolved: {exc}") from None
    if not allow_outside and not path.is_relative_to(base) and path not in allowed:
        raise MeshFileError(f"mesh url {url!r} leaves the world's folder (absolute paths and '..' are refused; "
                            "use --allow-outside-meshes to allow them)")
    try:
        if not path.is_file():
            raise MeshFileError(f"mesh file {url!r} not found (urls are relative to the world file)")
        size = path.stat().st_size
    except OSError as exc:
        raise MeshFileError(f"mesh file {url!r} cannot be read: {exc.strerror or exc}") from None
    if max_bytes is not None and size > max_bytes:
        raise MeshFileError(f"mesh file {url!r} is larger than the limit of {max_bytes:,} bytes "
                            "(raise the limits with --allow-large)")
    return path


def load_mesh(path: str | Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *, display: str | None = None,
              memory: int | None = None, max_triangles: int | None = None, material: int = -1, name: str = ""):
    """Load and scale a mesh file (cached). ``display``: how errors name the file (default: its path);
    ``memory``: what reading a large file may take (default ``DEFAULT_LOAD_MEMORY``);
    ``max_triangles``: refuse a larger mesh before its arrays are copied out of the worker;
    ``material``/``name``: a COLLADA file's triangles of that material index / geometry name only
    (Webots' Mesh.materialIndex and Mesh.name; -1 and "": all); an OBJ file's of that material
    (:mod:`.cad`'s numbering: a CadShape's materials)."""
    path = Path(path).resolve()
    shown = display if display is not None else str(path)
    if not path.is_file():
        raise MeshFileError(f"mesh file not found: {shown}")
    kind = mesh_format(path)
    if kind is None and not path.suffix:
        raise MeshFileError(f"mesh file {shown} has no suffix and is not a mesh format read here "
                            f"(expected one of {sorted(SUPPORTED)})")
    if kind is None:
        raise MeshFileError(f"unsupported mesh format {path.suffix!r} (expected one of {sorted(SUPPORTED)})")
    try:
        stat = path.stat()
        select = _selection(kind, material, name)
        key = (str(path), stat.st_mtime_ns, tuple(float(s) for s in scale), *select)
        mesh = _CACHE.get(key)
        if mesh is None and stat.st_size > IN_PROCESS_BYTES and by_cad(kind, select) and select[0] >= 0 \
                and not select[1]:
            # a CadShape asks for each of its materials in turn: a large file is read once for all of them
            mesh = _load_materials(key, memory if memory is not None else DEFAULT_LOAD_MEMORY, max_triangles, kind)
        elif mesh is None:
            mesh = _load(*key[:3], memory if memory is not None else DEFAULT_LOAD_MEMORY, stat.st_size, max_triangles,
                         kind, select)
            _remember(key, mesh)
        else:
            _CACHE.move_to_end(key)
        return mesh
    except MeshFileError as exc:
        raise MeshFileError(str(exc).replace(str(path), shown)) from None


def _remember(key: tuple, mesh: Any) -> None:
    _CACHE[key] = mesh
    while len(_CACHE) > CACHED_MESHES:
        _CACHE.popitem(last=False)


def _load_materials(key: tuple, memory: int, max_triangles: int | None, kind: str):
    """The mesh of material ``key[3]`` of a large COLLADA or OBJ file, every other material its
    triangles use cached on the way (one worker run for a CadShape's materials)."""
    from sensorium.server.world.geometry import Mesh

    path, mtime, scale, material, _ = key
    groups = _read_materials_in_worker(path, scale, memory, max_triangles, kind)
    if material not in groups:
        raise MeshFileError(f"mesh {path} has no triangles {_selected((material, ''))}")
    wanted = None
    for m, (vertices, faces, closed) in groups.items():
        if len(faces) == 0:
            continue
        vertices *= np.asarray(scale, dtype=np.float64)
        mesh = Mesh(*_compact(vertices, faces), closed=closed)
        _remember((path, mtime, scale, m, ""), mesh)
        if m == material:
            wanted = mesh
    if wanted is None:
        raise MeshFileError(f"mesh {path} has no triangles {_selected((material, ''))}")
    return wanted


def _selection(kind: str, material: int, name: str) -> tuple[int, str]:
    """The (material, geometry name) a file of ``kind`` is read by: COLLADA both, OBJ a material
    (then through :mod:`.cad`), other formats neither."""
    if kind == "dae":
        return int(material), str(name)
    return (int(material), "") if kind == "obj" and material >= 0 else (-1, "")


def by_cad(kind: str, select: tuple[int, str]) -> bool:
    """Whether a file of ``kind`` read by ``select`` is read through :mod:`.cad` (else trimesh)."""
    return kind == "dae" or (kind == "obj" and select[0] >= 0)


def mesh_format(path: Path) -> str | None:
    """The format of a mesh file (``stl``, ``obj``, ...): its suffix's; for a file without one
    (Webots' asset cache names each file by the SHA-1 of its url), what its first bytes show. None:
    not a format read here."""
    suffix = path.suffix.lower()
    if suffix:
        return suffix[1:] if suffix in SUPPORTED else None
    try:
        with open(path, "rb") as f:
            head = f.read(512)
        size = path.stat().st_size
    except OSError:
        return None
    if head[:4] == b"glTF":
        return "glb"
    if head[:3] == b"ply":
        return "ply"
    if len(head) >= 84 and size == 84 + 50 * int.from_bytes(head[80:84], "little"):
        return "stl"                   # binary STL: an 80-byte header, a count, 50 bytes per triangle
    text = head.lstrip()
    if text.startswith(b"solid"):
        return "stl"
    if text.split(maxsplit=1)[:1] in ([b"OFF"], [b"COFF"], [b"NOFF"]):
        return "off"
    if text.startswith(b"{") and b'"asset"' in head:
        return "gltf"
    if b"<COLLADA" in head:
        return "dae"
    lines = text.splitlines() if size <= len(head) else text.splitlines()[:-1]    # (the last one may be cut)
    words = {line.split(maxsplit=1)[0] for line in lines if line.strip()}
    if words and words <= {b"#", b"v", b"vt", b"vn", b"vp", b"f", b"o", b"g", b"s", b"l", b"usemtl", b"mtllib"} \
            and b"v" in words:
        return "obj"
    return None


# meshes read, by (resolved path, modification time, scale, COLLADA material and geometry name), the
# CACHED_MESHES most recently used (whatever memory bound they were read under: validating and building read each file once)
_CACHE: OrderedDict[tuple[str, int, tuple[float, ...], int, str], Any] = OrderedDict()
CACHED_MESHES = 256       # (a robot arm of CAD files has ~10 links of ~10 materials each)


def _load(path: str, _mtime: int, scale: tuple[float, ...], memory: int, size: int, max_triangles: int | None,
          kind: str, select: tuple[int, str] = (-1, "")):
    from sensorium.server.world.geometry import Mesh

    if size > IN_PROCESS_BYTES:
        vertices, faces, closed = _read_in_worker(path, scale, memory, max_triangles, kind, select)
        vertices *= np.asarray(scale, dtype=np.float64)
        return Mesh(*_compact(vertices, faces), closed=closed)
    import trimesh

    if by_cad(kind, select):
        from sensorium.server.world.cad import CadError, read_cad

        try:
            vertices, faces, _ = read_cad(path, kind, max_triangles).select(*select)
        except CadError as exc:
            raise MeshFileError(f"cannot read {_FORMAT_NAMES[kind]} mesh {path}: {exc}") from None
        if len(faces) == 0:
            raise MeshFileError(f"mesh {path} has no triangles {_selected(select)}")
    else:
        try:
            loaded = trimesh.load(path, file_type=kind, force="mesh", process=False)
        except Exception as exc:  # trimesh raises many types for bad files
            raise MeshFileError(f"cannot read mesh {path}: {exc}") from None
        vertices = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=np.float64)
        faces = np.asarray(getattr(loaded, "faces", np.empty((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise MeshFileError(f"mesh {path} has no triangles")
    if max_triangles is not None and len(faces) > max_triangles:
        raise MeshFileError(f"mesh {path} has {len(faces):,} triangles, more than the world's limit of "
                            f"{max_triangles:,} (raise the limits with --allow-large)")
    if not np.isfinite(vertices).all():
        raise MeshFileError(f"mesh {path} has non-finite vertex coordinates")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshFileError(f"mesh {path} has face indices outside its vertex list")
    vertices = vertices * np.asarray(scale, dtype=np.float64)
    # merge coincident vertices so that watertightness can be judged on the topology
    merged = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
    closed = bool(merged.is_watertight)
    del merged
    return Mesh(*_compact(vertices, np.asarray(faces, dtype=np.int64)), closed=closed)


_FORMAT_NAMES = {"dae": "COLLADA", "obj": "OBJ"}


def _selected(select: tuple[int, str]) -> str:
    """How an empty COLLADA selection is said."""
    material, name = select
    said = [f"of material index {material}"] if material >= 0 else []
    said += [f"in geometry {name!r}"] if name else []
    return " ".join(said) if said else "in its scene"


def file_materials(path: str | Path, kind: str, memory: int | None = None) -> tuple[list[Any], list[int]]:
    """(materials, the indices its triangles use) of a COLLADA or OBJ file (:mod:`.cad`): a file over
    ``IN_PROCESS_BYTES`` read by the worker within ``memory`` bytes (default ``DEFAULT_LOAD_MEMORY``).
    MeshFileError: it cannot be read. Cached by path and modification time."""
    path = str(Path(path).resolve())
    try:
        stat = Path(path).stat()
        size = stat.st_size
    except OSError as exc:
        raise MeshFileError(f"cannot read mesh {path}: {exc.strerror or exc}") from None
    key = (path, stat.st_mtime_ns, kind)
    if key in _MATERIALS:       # (a .wbt world is converted twice by `sensorium convert`: read once)
        _MATERIALS.move_to_end(key)
        return list(_MATERIALS[key][0]), list(_MATERIALS[key][1])
    materials, used = _file_materials(path, size, kind, memory)
    _MATERIALS[key] = (tuple(materials), tuple(used))
    while len(_MATERIALS) > CACHED_MESHES:
        _MATERIALS.popitem(last=False)
    return materials, used


# the materials of the files read, by (resolved path, modification time, format)
_MATERIALS: OrderedDict[tuple[str, int, str], tuple[tuple[Any, ...], tuple[int, ...]]] = OrderedDict()


def _file_materials(path: str, size: int, kind: str, memory: int | None) -> tuple[list[Any], list[int]]:
    from sensorium.server.world.cad import CadError, CadMaterial, read_cad

    if size <= IN_PROCESS_BYTES:
        try:
            cad = read_cad(path, kind)
        except CadError as exc:
            raise MeshFileError(f"cannot read {_FORMAT_NAMES.get(kind, '')} mesh {path}: {exc}") from None
        return list(cad.materials), cad.used()
    header = _worker_header(path, memory if memory is not None else DEFAULT_LOAD_MEMORY, kind, [str(MATERIALS_ONLY)])
    if header is None or not header.get("ok"):
        why = "its reader stopped" if header is None else header.get("error", "?")
        if header is not None and header.get("kind") == "memory":
            raise MeshMemoryError(f"its materials take more than {memory if memory is not None else DEFAULT_LOAD_MEMORY:,} "
                                  "bytes to read")
        raise MeshFileError(f"cannot read {_FORMAT_NAMES.get(kind, '')} mesh {path}: {why}")
    try:
        materials = [CadMaterial(str(n), (float(d[0]), float(d[1]), float(d[2])), float(t),
                                 None if x is None else str(x)) for n, d, t, x in header["materials"]]
        used = [int(i) for i in header["used"] if 0 <= int(i) < len(materials)]
    except (KeyError, TypeError, ValueError, IndexError):
        raise MeshFileError(f"cannot read {_FORMAT_NAMES.get(kind, '')} mesh {path}: a bad reply") from None
    return materials, used


MATERIALS_ONLY = -2       # (mesh_worker.MATERIALS_ONLY)


def _worker_header(path: str, memory: int, kind: str, extra: list[str]) -> dict | None:
    """Ask a :mod:`.mesh_worker` about ``path`` for a reply without arrays (``extra``: [MATERIAL]):
    its JSON header (None: it stopped without one)."""
    def header_only(stream) -> tuple[dict | None, bool]:
        header = _read_header(stream)
        return header, header is not None and header.get("kind") != "memory"

    header, _ = _exchange({"path": path, "scale": [1.0, 1.0, 1.0], "memory": memory, "format": kind,
                           "material": int(extra[0]) if extra else -1, "name": "", "cap": None}, header_only)
    return header


def _read_header(stream) -> dict | None:
    """A worker reply's JSON header (None: no header, or not a JSON object)."""
    import json
    import struct

    try:
        head = stream.read(4)
        header = json.loads(stream.read(struct.unpack(">I", head)[0])) if len(head) == 4 else None
    except ValueError:       # (a reply that is not JSON)
        return None
    return header if isinstance(header, dict) else None


# ----------------------------------------------------------------------------- the mesh workers
# A worker process reads files one after another (mesh_worker.py: each under its own memory limit):
# starting one (an interpreter importing numpy and trimesh) costs ~0.4 s, more than reading a
# 1.5 MB STL file, and a robot converted from URDF has tens of such files. Idle workers wait here for
# the next file; one ends by itself after WORKER_IDLE_S seconds without a request, after a file that
# hit its memory limit, or when this process ends. A worker is used by one read at a time.
WORKER_IDLE_S = 5.0


class _Worker:
    """One mesh_worker.py process, with pipes to it."""

    def __init__(self, idle: float, script: str | None = None) -> None:
        """``script``: Python source run instead of mesh_worker.py (tests: a worker that dies)."""
        import subprocess
        import sys

        worker = Path(__file__).with_name("mesh_worker.py")
        env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
        env.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")   # little address space
        run = [str(worker)] if script is None else ["-c", script]
        self.proc = subprocess.Popen([sys.executable, "-I", *run, repr(float(idle))], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env, close_fds=True)
        self.owner = os.getpid()
        _LIVE.add(self)

    def end(self, wait: bool = True) -> int | None:
        """Close its pipes: it ends at the end of its input (or, writing, on the closed pipe); its exit
        status (``wait``: once it has ended, killed if it has not within 30 s)."""
        import subprocess

        for pipe in (self.proc.stdin, self.proc.stdout):
            try:
                if pipe is not None:
                    pipe.close()
            except OSError:
                pass
        if not wait:
            return self.proc.poll()
        try:
            return self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return self.proc.wait()


_IDLE: list[_Worker] = []
_STARTS = [0]


def _start_worker() -> _Worker:
    """A new worker process (a seam: tests count the starts)."""
    _STARTS[0] += 1
    return _Worker(WORKER_IDLE_S)


def worker_starts() -> int:
    """How many mesh worker processes this process has started."""
    return _STARTS[0]


def close_workers() -> None:
    """End the idle mesh workers (at exit; a worker also ends by itself when left idle): each ends at
    the end of its input, at once (waiting for the next request)."""
    with _WORKERS_LOCK:
        idle, _IDLE[:] = list(_IDLE), []
    for w in idle:
        if w.owner == os.getpid():          # (a forked child leaves its parent's workers alone)
            w.end()


def _take_worker() -> tuple[_Worker, bool]:
    """(an idle worker of this process, else a new one; whether it is new)."""
    with _WORKERS_LOCK:
        while _IDLE:
            w = _IDLE.pop()
            if w.owner == os.getpid() and w.proc.poll() is None:
                return w, False
            if w.owner == os.getpid():
                w.end()
    global _AT_EXIT
    if not _AT_EXIT:
        import atexit

        atexit.register(close_workers)
        _AT_EXIT = True
    return _start_worker(), True


def _exchange(request: dict, read_reply) -> tuple[Any, int | None]:
    """Send ``request`` to a worker and read its reply with ``read_reply(stream)`` → (result, whether
    the worker may read another file): (the result, the worker's exit status when it was not kept).
    A worker that had ended before it took the request (left idle, or retired after its last file)
    is passed over for the next; a new worker that does not take it is the reader stopping."""
    import json

    line = (json.dumps(request) + "\n").encode("utf-8")
    while True:
        w, new = _take_worker()
        assert w.proc.stdin is not None and w.proc.stdout is not None
        try:
            w.proc.stdin.write(line)
            w.proc.stdin.flush()
            taken = w.proc.stdout.read(1) == b"\x01"
        except OSError:         # (a broken pipe: it had ended)
            taken = False
        if not taken:
            code = w.end()
            if new:
                return None, code
            continue
        try:
            result, keep = read_reply(w.proc.stdout)
        except BaseException:
            w.end(wait=False)           # (its pipes closed: it ends)
            raise
        if keep:
            with _WORKERS_LOCK:
                _IDLE.append(w)
            return result, None
        return result, w.end()


_WORKERS_LOCK = threading.Lock()
_AT_EXIT = False
_LIVE: weakref.WeakSet[_Worker] = weakref.WeakSet()     # every worker this process started (not yet collected)


def _after_fork_in_child() -> None:
    """A forked process (``os.fork``, multiprocessing's fork start method) lets go of its parent's workers: their
    pipes' descriptors point at /dev/null in it (closed by its file objects in time, never flushed into a
    worker), so a parent's worker sees its input end when the parent closes it, not when every fork
    has ended; the lock starts afresh (another thread may have held it at the fork)."""
    global _WORKERS_LOCK
    _WORKERS_LOCK = threading.Lock()
    _IDLE.clear()
    try:
        devnull = os.open(os.devnull, os.O_RDWR)
    except OSError:
        return
    try:
        for w in list(_LIVE):
            for pipe in (w.proc.stdin, w.proc.stdout):
                try:
                    if pipe is not None and not pipe.closed:
                        os.dup2(devnull, pipe.fileno())
                except (OSError, ValueError):
                    pass
        _LIVE.clear()
    finally:
        os.close(devnull)


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


ALL_MATERIALS = -3        # (mesh_worker.ALL_MATERIALS)


def _read_in_worker(path: str, scale: tuple[float, ...], memory: int,
                    max_triangles: int | None = None, kind: str | None = None,
                    select: tuple[int, str] = (-1, "")) -> tuple[np.ndarray, np.ndarray, bool]:
    """(vertices, faces, closed) of a mesh file read by :mod:`.mesh_worker` within ``memory`` bytes."""
    header, arrays = _run_worker(path, scale, memory, max_triangles, kind, select)
    (vertices, faces), = arrays
    _check_arrays(path, vertices, faces)
    return vertices, faces, bool(header["closed"])


def _read_materials_in_worker(path: str, scale: tuple[float, ...], memory: int, max_triangles: int | None,
                              kind: str) -> dict[int, tuple[np.ndarray, np.ndarray, bool]]:
    """{material index: (vertices, faces, closed)} of every material a COLLADA or OBJ file's
    triangles use, from one reading by :mod:`.mesh_worker` (a CadShape asks for each material)."""
    header, arrays = _run_worker(path, scale, memory, max_triangles, kind, (ALL_MATERIALS, ""))
    out = {}
    for (m, _, _, closed), (vertices, faces) in zip(header["groups"], arrays, strict=True):
        _check_arrays(path, vertices, faces)
        out[int(m)] = (vertices, faces, bool(closed))
    return out


def _check_arrays(path: str, vertices: np.ndarray, faces: np.ndarray) -> None:
    if not np.isfinite(vertices).all():
        raise MeshFileError(f"mesh {path} has non-finite vertex coordinates")
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise MeshFileError(f"mesh {path} has face indices outside its vertex list")


def _run_worker(path: str, scale: tuple[float, ...], memory: int, max_triangles: int | None, kind: str | None,
                select: tuple[int, str]) -> tuple[dict, list[tuple[np.ndarray, np.ndarray]]]:
    """Have a :mod:`.mesh_worker` read a file's triangles: (its JSON header, the (vertices, faces)
    arrays it sent: one pair, or one per group when ``select`` asks for every material).
    MeshFileError: it failed."""
    arrays: list[tuple[np.ndarray, np.ndarray]] = []
    too_many: list[int] = []

    def triangles(stream) -> tuple[dict | None, bool]:
        header = _read_header(stream)
        if header is None or not header.get("ok"):
            return header, header is not None and header.get("kind") != "memory"
        try:
            sizes = [(int(g[1]), int(g[2])) for g in header["groups"]] if "groups" in header \
                else [(int(header["vertices"]), int(header["faces"]))]
        except (ValueError, KeyError, TypeError, IndexError):       # (a reply that is not what was asked)
            return None, False
        for _, nf in sizes:
            if max_triangles is not None and nf > max_triangles:
                too_many.append(nf)
                return header, False             # (its arrays are not read: the worker is ended)
        for nv, nf in sizes:
            pair = (np.empty((nv, 3), dtype=np.float64), np.empty((nf, 3), dtype=np.int64))
            for a in pair:
                view = memoryview(a).cast("B")
                got = 0
                while got < len(view):
                    n = stream.readinto(view[got:])
                    if not n:
                        return None, False
                    got += n
            arrays.append(pair)
        return header, True

    header, code = _exchange({"path": path, "scale": [float(s) for s in scale], "memory": int(memory),
                              "format": kind or Path(path).suffix.lower()[1:], "material": int(select[0]),
                              "name": select[1], "cap": max_triangles}, triangles)
    if too_many:
        raise MeshFileError(f"mesh {path} has {too_many[0]:,} triangles, more than the world's limit of "
                            f"{max_triangles:,} (raise the limits with --allow-large)")
    limit = f"{memory / (1 << 30):g} GiB"
    if header is None:
        raise MeshFileError(f"cannot read mesh {path}: its reader stopped (exit status {code}), most likely at the "
                            f"limits for reading a mesh ({limit} of memory, 300 s) (raise the limits with --allow-large)")
    if not header.get("ok"):
        if header.get("kind") == "memory":
            raise MeshFileError(f"cannot read mesh {path}: reading it needs more than {limit} of memory "
                                "(raise the limits with --allow-large)")
        if header.get("kind") == "no triangles":
            raise MeshFileError(f"mesh {path} has no triangles"
                                + (f" {_selected(select)}" if kind is not None and by_cad(kind, select) else ""))
        if header.get("kind") == "cad":
            raise MeshFileError(f"cannot read {_FORMAT_NAMES.get(kind or '', '')} mesh {path}: "
                                f"{header.get('error', '?')}")
        raise MeshFileError(f"cannot read mesh {path}: {header.get('error', '?')}")
    return header, arrays


def triangles_mesh(vertices, faces):
    """Inline triangles (a world's ``triangles`` geometry) → ``geometry.Mesh``; indices are checked
    by the loader. Cached on the exact values (their bytes as float64 and int64 arrays), like files:
    the robots of a swarm that carry the same inline mesh share one Mesh (and the ray engine one
    tier for them), and the scene, recognition and the viewer ask for it again. The cache keeps the
    Mesh and a digest of its bytes, never a second copy of the numbers."""
    import hashlib

    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)      # (one pass at C speed over the lists)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    digest = hashlib.blake2b(v.data, digest_size=16)
    digest.update(f.data)
    key = (v.shape, f.shape, digest.digest())
    mesh = _TRIANGLES.get(key)
    if mesh is not None and np.array_equal(mesh.vertices.view(np.int64), v.view(np.int64)) \
            and np.array_equal(mesh.faces, f):       # (the bytes, as the digest: -0.0 is not 0.0)
        _TRIANGLES.move_to_end(key)
        return mesh
    import trimesh

    from sensorium.server.world.geometry import Mesh

    merged = trimesh.Trimesh(vertices=v, faces=f, process=True, validate=False)
    mesh = Mesh(vertices=v, faces=f, closed=bool(merged.is_watertight))
    del merged
    _TRIANGLES[key] = mesh
    while len(_TRIANGLES) > CACHED_TRIANGLES:
        _TRIANGLES.popitem(last=False)
    return mesh


# inline meshes made, by (shapes, digest of the bytes), the CACHED_TRIANGLES most recently used
_TRIANGLES: OrderedDict[tuple, Any] = OrderedDict()
CACHED_TRIANGLES = 64


def welded(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The referenced vertices of a mesh, one per distinct position (in order of first use), and
    its faces on them: the ray engine's tiers hold a mesh this way (vertex rings, edges shared by
    two faces), and a mesh read from a file is kept this way (:func:`_compact`); on such a mesh it
    returns the same values. (Positions are grouped by their bytes, as np.unique of 24-byte rows would,
    through a stable sort of the three coordinates' int64 views: ~40 B per vertex at the peak
    instead of ~100; a binary STL file gives three vertices per triangle.)"""
    f = np.asarray(f).reshape(-1, 3)
    present = np.zeros(len(v), dtype=bool)
    present[f.ravel()] = True
    used = present.nonzero()[0]                  # np.unique(f) and its inverse, without sorting f
    if len(used) < len(v):
        rank = np.cumsum(present) - 1
        f = rank[f]
        del rank
    del present
    v = np.ascontiguousarray(v[used], dtype=np.float64)
    del used
    bits = v.view(np.int64)
    order = np.lexsort((bits[:, 2], bits[:, 1], bits[:, 0]))   # stable: each group's first is its first use
    new = np.zeros(len(v), dtype=bool)
    new[:1] = True
    for k in range(3):
        col = bits[order, k]
        new[1:] |= col[1:] != col[:-1]
        del col
    first = order[new]                            # per distinct position (sorted by bytes): its first use
    if len(first) == len(v):
        return v, np.asarray(f, dtype=np.int64).reshape(-1, 3)
    group = np.empty(len(v), dtype=np.int64)
    group[order] = np.cumsum(new) - 1
    del order, new
    keep = np.sort(first)                        # distinct positions, in their order in v
    rank = np.empty(len(v), dtype=np.int64)
    rank[keep] = np.arange(len(keep))
    to = rank[first[group]]                      # every vertex -> its position's first occurrence
    return v[keep], to[f]


def _compact(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A mesh file's (vertices, faces) with each position once (:func:`welded`) when every vertex is
    used: a binary STL file gives three vertices per triangle, about six times the vertices of the
    surface, which the Mesh would hold for as long as the world is loaded. The positions are the same
    set (what contact and recognition read of a Mesh); the ray engine's tier welds them so anyway.
    A mesh with unused vertices (their positions count for its extent) is kept as read."""
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    if not used.all():
        return vertices, faces
    del used
    return welded(vertices, faces)


def elevation_grid_mesh(height: tuple[float, ...], x_dimension: int, x_spacing: float, y_dimension: int,
                        y_spacing: float):
    """An ElevationGrid's triangles (``geometry.elevation_grid``) → ``geometry.Terrain``; the loader
    checked its fields and size. Cached on the exact values (the scene, recognition and the viewer
    each ask for it)."""
    return _elevation_grid(tuple(float(h) for h in height), int(x_dimension), float(x_spacing), int(y_dimension),
                           float(y_spacing))


@lru_cache(maxsize=4)      # a grid of the world limit's 4M triangles holds ~300 MB of arrays
def _elevation_grid(height, x_dimension, x_spacing, y_dimension, y_spacing):
    from sensorium.server.world.geometry import Terrain, elevation_grid

    v, f = elevation_grid(height, x_dimension, x_spacing, y_dimension, y_spacing)
    return Terrain(vertices=v, faces=f, closed=False)
