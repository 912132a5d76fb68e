"""Mesh files (STL, OBJ, PLY, GLB) → float64 triangle arrays, via trimesh.

Loaded meshes are cached by (resolved path, modification time, scale): validating a world and then
building its scene reads each file once.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

SUPPORTED = {".stl", ".obj", ".ply", ".glb", ".gltf", ".off"}


class MeshFileError(Exception):
    """A mesh file that is missing, unreadable or not a triangle mesh."""


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


def load_mesh(path: str | Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0), *, display: str | None = None):
    """Load and scale a mesh file (cached). ``display``: how errors name the file (default: its path)."""
    path = Path(path).resolve()
    name = display if display is not None else str(path)
    if not path.is_file():
        raise MeshFileError(f"mesh file not found: {name}")
    if path.suffix.lower() not in SUPPORTED:
        raise MeshFileError(f"unsupported mesh format {path.suffix!r} (expected one of {sorted(SUPPORTED)})")
    try:
        return _load(str(path), path.stat().st_mtime_ns, tuple(float(s) for s in scale))
    except MeshFileError as exc:
        raise MeshFileError(str(exc).replace(str(path), name)) from None


@lru_cache(maxsize=64)
def _load(path: str, _mtime: int, scale: tuple[float, float, float]):
    import trimesh

    from sensorium.server.world.geometry import Mesh

    try:
        loaded = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for bad files
        raise MeshFileError(f"cannot read mesh {path}: {exc}") from None
    vertices = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(loaded, "faces", np.empty((0, 3))), dtype=np.int64)
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise MeshFileError(f"mesh {path} has no triangles")
    if not np.isfinite(vertices).all():
        raise MeshFileError(f"mesh {path} has non-finite vertex coordinates")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshFileError(f"mesh {path} has face indices outside its vertex list")
    vertices = vertices * np.asarray(scale, dtype=np.float64)
    # merge coincident vertices so that watertightness can be judged on the topology
    merged = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
    closed = bool(merged.is_watertight)
    return Mesh(vertices=np.ascontiguousarray(vertices), faces=np.ascontiguousarray(faces), closed=closed)


def triangles_mesh(vertices, faces):
    """Inline triangles (a world's ``triangles`` geometry) → ``geometry.Mesh``; indices are checked
    by the loader. Cached on the exact values, like files."""
    key = (tuple(tuple(float(c) for c in v) for v in vertices), tuple(tuple(int(i) for i in f) for f in faces))
    return _triangles(key)


@lru_cache(maxsize=64)
def _triangles(key):
    import trimesh

    from sensorium.server.world.geometry import Mesh

    vertices = np.asarray(key[0], dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(key[1], dtype=np.int64).reshape(-1, 3)
    merged = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
    return Mesh(vertices=vertices, faces=faces, closed=bool(merged.is_watertight))
