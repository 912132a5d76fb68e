"""COLLADA (.dae) files → triangles, texture coordinates and materials, placed as Webots places them.

Webots reads COLLADA through assimp, which scales the scene by the file's ``<unit meter>`` and turns
its ``<up_axis>`` into +Y; Webots then turns +Y into +Z (a quarter turn about x, for every .dae,
CadShape and Mesh alike). Net: a Z_UP file keeps its coordinates, a Y_UP one (COLLADA's default)
maps (x, y, z) → (x, −z, y), an X_UP one (x, y, z) → (−y, −z, x); all times the unit.

Materials are numbered as assimp numbers them (Webots' ``Mesh.materialIndex``): the file's
materials in the order of their ids, then, if a primitive is bound to none, a default white one.
Each material keeps what Webots' PBRAppearance takes from it: the diffuse colour (white when the
diffuse is a texture), the transparency and the diffuse image's path as written in the file.

This module imports numpy and pycollada only (the mesh worker loads it by path).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

DEFAULT_MATERIAL = "(default)"
MAX_TRIANGLES = 1 << 27     # without a world's limit: a small file can place one geometry many times over


class DaeError(Exception):
    """A COLLADA file that cannot be read, or holds no triangles."""


@dataclass(frozen=True)
class DaeMaterial:
    name: str                                   # the material's id in the file
    diffuse: tuple[float, float, float]         # white when the diffuse is a texture
    transparency: float
    texture: str | None                         # the diffuse image's path as written (relative to the file)


@dataclass(frozen=True)
class DaePart:
    """One primitive (a <triangles>, <polylist> or <polygons>) of one geometry instance."""

    geometry: str                               # the geometry's name (else its id)
    material: int                               # index into Dae.materials
    vertices: np.ndarray                        # (n, 3) float64, placed (metres, +Z up)
    faces: np.ndarray                           # (m, 3) int64 into vertices
    uv: np.ndarray | None                       # (m, 3, 2) corner (s, t) of set 0, as written; None: none


@dataclass(frozen=True)
class Dae:
    materials: tuple[DaeMaterial, ...]
    parts: tuple[DaePart, ...]

    def used(self) -> list[int]:
        """The indices of the materials some part uses, in order."""
        return sorted({p.material for p in self.parts})

    def select(self, material: int = -1, name: str = "") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(vertices, faces, corner uv with v flipped as assimp's FlipUVs; (0.5, 0.5) without UVs) of the
        parts of ``material`` (-1: all) and geometry ``name`` ("": all), merged as Webots' Mesh merges."""
        vs, fs, uvs, n = [], [], [], 0
        for p in self.parts:
            if (material >= 0 and p.material != material) or (name and p.geometry != name):
                continue
            vs.append(p.vertices)
            fs.append(p.faces + n)
            n += len(p.vertices)
            if p.uv is None:
                uvs.append(np.full((len(p.faces), 3, 2), 0.5))
            else:
                uv = p.uv.astype(np.float64, copy=True)
                uv[..., 1] = 1.0 - uv[..., 1]
                uvs.append(uv)
        if not fs:
            return np.empty((0, 3)), np.empty((0, 3), dtype=np.int64), np.empty((0, 3, 2))
        return np.concatenate(vs), np.concatenate(fs), np.concatenate(uvs)


# assimp's up-axis turn followed by Webots' quarter turn about x (see the module's docstring)
_UP = {"Z_UP": np.eye(3),
       "Y_UP": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
       "X_UP": np.array([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])}


def read_dae(path: str, max_triangles: int | None = None) -> Dae:
    """Read ``path`` (cached by path and modification time; DaeError: one line saying what is wrong;
    ``max_triangles``: refuse more)."""
    import os

    try:
        mtime = os.stat(path).st_mtime_ns
    except OSError as exc:
        raise DaeError(f"cannot be read: {exc.strerror or exc}") from None
    return _read(str(path), mtime, MAX_TRIANGLES if max_triangles is None else int(max_triangles))


@lru_cache(maxsize=8)
def _read(path: str, _mtime: int, cap: int) -> Dae:
    with warnings.catch_warnings():     # (pycollada builds numpy.matrix objects)
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        return _parse(path, cap)


def _parse(path: str, cap: int) -> Dae:
    import collada
    from collada import common

    try:
        doc = collada.Collada(path, ignore=[common.DaeUnsupportedError, common.DaeBrokenRefError])
    except MemoryError:
        raise
    except Exception as exc:     # noqa: BLE001 - pycollada and its XML parser raise many types
        raise DaeError(_why(exc)) from None
    unit = doc.assetInfo.unitmeter
    unit = float(unit) if unit is not None else 1.0
    if not np.isfinite(unit) or unit <= 0:
        raise DaeError(f"<unit meter={unit!r}>: not a positive number")
    turn = _UP.get(str(doc.assetInfo.upaxis or "Y_UP"), _UP["Y_UP"]) * unit

    effects = sorted((m for m in doc.materials if m.effect is not None), key=lambda m: m.id or "")
    materials = [_material(m) for m in effects]
    index = {id(m): i for i, m in enumerate(effects)}
    default: int | None = None
    parts: list[DaePart] = []
    triangles = 0
    try:
        bound = list(doc.scene.objects("geometry")) if doc.scene is not None else []
        for g in bound:
            name = g.original.name or g.original.id or ""
            for p in g.primitives():
                if type(p).__name__ in ("BoundPolylist", "BoundPolygons"):
                    p = p.triangleset()
                if p.vertex is None or not hasattr(p, "vertex_index") or p.vertex_index is None:
                    continue     # lines, or a primitive without positions
                faces = np.asarray(p.vertex_index, dtype=np.int64)
                if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
                    continue
                triangles += len(faces)
                if triangles > cap:         # counted before each instance's vertices are placed
                    raise DaeError(f"more than {cap:,} triangles in its scene, the world's limit "
                                   "(raise the limits with --allow-large)")
                vertices = np.asarray(p.vertex, dtype=np.float64).reshape(-1, 3) @ turn.T
                if faces.min() < 0 or faces.max() >= len(vertices):
                    raise DaeError(f"geometry {name!r}: face indices outside its vertex list")
                uv = None
                if len(p.texcoordset) > 0 and len(p.texcoord_indexset) > 0:
                    st = np.asarray(p.texcoordset[0], dtype=np.float64).reshape(-1, 2)
                    ti = np.asarray(p.texcoord_indexset[0], dtype=np.int64)
                    if ti.shape == faces.shape and len(st) and ti.min() >= 0 and ti.max() < len(st):
                        uv = st[ti]
                m = index.get(id(p.material)) if p.material is not None else None
                if m is None:
                    if default is None:
                        default = len(materials)
                        materials.append(DaeMaterial(DEFAULT_MATERIAL, (1.0, 1.0, 1.0), 0.0, None))
                    m = default
                parts.append(DaePart(name, m, vertices, faces, uv))
    except DaeError:
        raise
    except MemoryError:
        raise
    except Exception as exc:     # noqa: BLE001
        raise DaeError(f"its geometry cannot be read: {_why(exc)}") from None
    if not parts:
        raise DaeError("no triangles in its scene")
    for p in parts:
        if not np.isfinite(p.vertices).all():
            raise DaeError(f"geometry {p.geometry!r}: non-finite vertex coordinates")
    return Dae(tuple(materials), tuple(parts))


def _material(m) -> DaeMaterial:
    """What Webots' PBRAppearance takes from an assimp material read from a COLLADA effect."""
    import collada

    e = m.effect
    diffuse, texture = (1.0, 1.0, 1.0), None
    if isinstance(e.diffuse, collada.material.Map):
        try:
            texture = str(e.diffuse.sampler.surface.image.path)
        except AttributeError:
            texture = None
    elif e.diffuse is not None:
        diffuse = tuple(min(1.0, max(0.0, float(c))) for c in tuple(e.diffuse)[:3])  # type: ignore[assignment]
    # opacity as assimp reads it: only with a <transparent> colour, its alpha (A_ONE) or one minus its
    # mean (RGB_ZERO), times <transparency>
    opacity = 1.0
    t = e.transparent
    if t is not None and not isinstance(t, collada.material.Map):
        try:
            f = float(e.transparency) if isinstance(e.transparency, (int, float)) else 1.0
            c = [float(v) for v in tuple(t)]
            opacity = (1.0 - sum(c[:3]) / 3.0) * f if e.opaque_mode == "RGB_ZERO" else c[3] * f if len(c) > 3 else f
        except (TypeError, ValueError):
            opacity = 1.0
    transparency = min(1.0, max(0.0, 1.0 - opacity)) if np.isfinite(opacity) else 0.0
    return DaeMaterial(m.id or "", diffuse, transparency, texture)  # type: ignore[arg-type]


def _why(exc: BaseException) -> str:
    """An exception's message on one line, bounded (without pycollada's class name in front)."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    for prefix in ("DaeMalformedError: ", "DaeIncompleteError: ", "DaeError: ", "DaeBrokenRefError: "):
        text = text.removeprefix(prefix)
    return text if len(text) <= 300 else text[:297] + "..."
