"""Mesh files with their own materials (a CadShape's formats) → triangles, texture coordinates and
materials: COLLADA (.dae, through pycollada) and Wavefront OBJ with its .mtl files (through trimesh).

Webots reads COLLADA through assimp, which scales the scene by the file's ``<unit meter>`` and turns
its ``<up_axis>`` into +Y; Webots then turns +Y into +Z (a quarter turn about x, for every .dae,
CadShape and Mesh alike). Net: a Z_UP file keeps its coordinates, a Y_UP one (COLLADA's default)
maps (x, y, z) → (x, −z, y), an X_UP one (x, y, z) → (−y, −z, x); all times the unit.

COLLADA materials are numbered as assimp numbers them (Webots' ``Mesh.materialIndex``): the file's
materials in the order of their ids, then, if a primitive is bound to none, a default white one.
An OBJ file's (ours: Webots numbers none) are the names its faces use (``usemtl``), sorted, the
faces without one a default white material after them; OBJ coordinates are kept as written.
Each material keeps what Webots' PBRAppearance takes from it: the diffuse colour (COLLADA: white
when the diffuse is a texture; OBJ: ``Kd``), the transparency (1 − opacity; OBJ: ``d``) and the
diffuse image's path as written in the file (relative to it; OBJ: ``map_Kd``).

This module imports numpy, pycollada and trimesh only (the mesh worker loads it by its path).
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

DEFAULT_MATERIAL = "(default)"
MAX_TRIANGLES = 1 << 27     # without a world's limit: a small file can place one geometry many times over


class CadError(Exception):
    """A file that cannot be read, or holds no triangles."""


@dataclass(frozen=True, slots=True)
class CadMaterial:
    name: str                                   # the material's id in the file (OBJ: its newmtl name)
    diffuse: tuple[float, float, float]         # white when the diffuse is a texture
    transparency: float
    texture: str | None                         # the diffuse image's path as written (relative to the file)


@dataclass(frozen=True, slots=True)
class CadPart:
    """One primitive (a <triangles>, <polylist> or <polygons>) of one geometry instance; an OBJ file's
    faces of one material."""

    geometry: str                               # the geometry's name (else its id); OBJ: ""
    material: int                               # index into CadFile.materials
    vertices: np.ndarray                        # (n, 3) float64, placed (metres, +Z up)
    faces: np.ndarray                           # (m, 3) int64 into vertices
    uv: np.ndarray | None                       # (m, 3, 2) corner (s, t) of set 0, as written; None: none


@dataclass(frozen=True, slots=True)
class CadFile:
    materials: tuple[CadMaterial, ...]
    parts: tuple[CadPart, ...]

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


def read_cad(path: str, kind: str, max_triangles: int | None = None) -> CadFile:
    """Read ``path``, a ``dae`` or ``obj`` file (cached by path and modification time; CadError: one
    line saying what is wrong; ``max_triangles``: refuse more)."""
    import os

    try:
        mtime = os.stat(path).st_mtime_ns
    except OSError as exc:
        raise CadError(f"cannot be read: {exc.strerror or exc}") from None
    if kind not in ("dae", "obj"):
        raise CadError(f"{kind!r} files carry no materials read here")
    return _read(str(path), kind, mtime, MAX_TRIANGLES if max_triangles is None else int(max_triangles))


def read_dae(path: str, max_triangles: int | None = None) -> CadFile:
    """A COLLADA file (``read_cad``)."""
    return read_cad(path, "dae", max_triangles)


@lru_cache(maxsize=8)
def _read(path: str, kind: str, _mtime: int, cap: int) -> CadFile:
    # (pycollada builds numpy.matrix objects; NaN or huge numbers in a file are refused below, not
    # printed as numpy's RuntimeWarnings beside the one line)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        return _parse(path, cap) if kind == "dae" else _parse_obj(path, cap)


def _parse(path: str, cap: int) -> CadFile:
    import collada
    from collada import common

    try:
        doc = collada.Collada(path, ignore=[common.DaeUnsupportedError, common.DaeBrokenRefError])
    except MemoryError:
        raise
    except Exception as exc:     # noqa: BLE001 - pycollada and its XML parser raise many types
        raise CadError(_why(exc)) from None
    unit = doc.assetInfo.unitmeter
    unit = float(unit) if unit is not None else 1.0
    if not np.isfinite(unit) or unit <= 0:
        raise CadError(f"<unit meter={unit!r}>: not a positive number")
    turn = _UP.get(str(doc.assetInfo.upaxis or "Y_UP"), _UP["Y_UP"]) * unit

    effects = sorted((m for m in doc.materials if m.effect is not None), key=lambda m: m.id or "")
    materials = [_material(m) for m in effects]
    index = {id(m): i for i, m in enumerate(effects)}
    default: int | None = None
    parts: list[CadPart] = []
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
                    raise CadError(f"more than {cap:,} triangles in its scene, the world's limit "
                                   "(raise the limits with --allow-large)")
                if _nan_positions(p):
                    raise CadError(f"geometry {name!r}: non-finite vertex coordinates")
                vertices = np.asarray(p.vertex, dtype=np.float64).reshape(-1, 3) @ turn.T
                if faces.min() < 0 or faces.max() >= len(vertices):
                    raise CadError(f"geometry {name!r}: face indices outside its vertex list")
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
                        materials.append(CadMaterial(DEFAULT_MATERIAL, (1.0, 1.0, 1.0), 0.0, None))
                    m = default
                parts.append(CadPart(name, m, vertices, faces, uv))
    except CadError:
        raise
    except MemoryError:
        raise
    except Exception as exc:     # noqa: BLE001
        raise CadError(f"its geometry cannot be read: {_why(exc)}") from None
    if not parts:
        raise CadError("no triangles in its scene")
    for p in parts:
        if not np.isfinite(p.vertices).all():
            raise CadError(f"geometry {p.geometry!r}: non-finite vertex coordinates")
    return CadFile(tuple(materials), tuple(parts))


def _parse_obj(path: str, cap: int) -> CadFile:
    """An OBJ file's faces by material (trimesh groups them) and its .mtl materials (read here: the
    values as written, which trimesh rounds to bytes)."""
    import trimesh

    try:
        loaded = trimesh.load(path, file_type="obj", force="scene", process=False, group_material=True)
        groups: dict[str, list] = {}
        triangles = 0
        for node in loaded.graph.nodes_geometry:
            transform, key = loaded.graph[node]
            g = loaded.geometry[key]
            faces = np.asarray(g.faces, dtype=np.int64).reshape(-1, 3)
            triangles += len(faces)
            if triangles > cap:
                raise CadError(f"more than {cap:,} triangles, the world's limit (raise the limits with --allow-large)")
            vertices = np.asarray(g.vertices, dtype=np.float64).reshape(-1, 3)
            t = np.asarray(transform, dtype=np.float64)
            vertices = vertices @ t[:3, :3].T + t[:3, 3]
            uv = getattr(g.visual, "uv", None)
            corner = None
            if uv is not None and len(uv) == len(vertices) and len(faces):
                corner = np.asarray(uv, dtype=np.float64).reshape(-1, 2)[faces]
            material = getattr(getattr(g.visual, "material", None), "name", None)
            groups.setdefault(material if isinstance(material, str) and material else "", []).append(
                (vertices, faces, corner))
    except CadError:
        raise
    except MemoryError:
        raise
    except Exception as exc:     # noqa: BLE001 - trimesh raises many types for bad files
        raise CadError(_why(exc)) from None
    library = _mtl_library(path)
    names = sorted(n for n in groups if n)
    materials = [library.get(n, CadMaterial(n, (1.0, 1.0, 1.0), 0.0, None)) for n in names]
    if "" in groups:
        names.append("")
        materials.append(CadMaterial(DEFAULT_MATERIAL, (1.0, 1.0, 1.0), 0.0, None))
    parts = [CadPart("", i, v, f, uv) for i, n in enumerate(names) for v, f, uv in groups[n] if len(f)]
    if not parts:
        raise CadError("no triangles")
    for p in parts:
        if not np.isfinite(p.vertices).all():
            raise CadError("non-finite vertex coordinates")
        if p.faces.min() < 0 or p.faces.max() >= len(p.vertices):
            raise CadError("face indices outside its vertex list")
    return CadFile(tuple(materials), tuple(parts))


MTL_BYTES = 1 << 20       # an .mtl file larger than this is not read (its materials are white)
MTL_FILES = 16            # the first this many distinct .mtl files an OBJ file names are read


def _mtl_library(path: str) -> dict[str, CadMaterial]:
    """The materials of the .mtl files an OBJ file names (``mtllib``, relative to it, in its folder or
    below: others are not read): ``Kd``, ``d`` and ``map_Kd`` (its last word: the file; options before
    it are not read). A missing or unreadable .mtl gives no materials (Webots renders such faces white
    too)."""
    import os

    libs: list[str] = []
    with open(path, "rb") as f:
        for raw in f:
            line = raw.strip()
            if line.startswith(b"mtllib"):
                for w in line.split()[1:]:
                    lib = w.decode("utf-8", "replace").replace("\\", "/")
                    if lib not in libs and len(libs) < MTL_FILES:
                        libs.append(lib)
    folder = os.path.realpath(os.path.dirname(path))
    out: dict[str, CadMaterial] = {}
    for lib in libs:
        mtl = os.path.realpath(os.path.join(folder, lib))
        if os.path.commonpath([folder, mtl]) != folder:
            continue
        try:
            if os.path.getsize(mtl) > MTL_BYTES:
                continue
            with open(mtl, encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError:
            continue
        name, values = None, {}
        for line in [*text.splitlines(), "newmtl"]:
            words = line.split()
            if not words:
                continue
            if words[0] == "newmtl":
                if name is not None and name not in out:
                    out[name] = CadMaterial(name, values.get("Kd", (1.0, 1.0, 1.0)),
                                            min(1.0, max(0.0, 1.0 - values.get("d", 1.0))), values.get("map_Kd"))
                name, values = (" ".join(words[1:]) or None), {}
            elif words[0] == "Kd" and len(words) >= 4:
                try:
                    values["Kd"] = tuple(min(1.0, max(0.0, float(w))) for w in words[1:4])
                except ValueError:
                    pass
            elif words[0] == "d" and len(words) >= 2:
                try:
                    d = float(words[1])
                    values["d"] = d if math.isfinite(d) else 1.0
                except ValueError:
                    pass
            elif words[0] == "map_Kd" and len(words) >= 2:
                values["map_Kd"] = words[-1]
    return out


def _material(m) -> CadMaterial:
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
    # opacity as assimp's COLLADA reader gives it (Webots' transparency = 1 − opacity): <transparency>
    # times the <transparent> colour's alpha (A_ONE, the default), or 1 − <transparency> times its
    # luminance (RGB_ZERO); <transparency> alone when there is no <transparent> colour
    opacity = 1.0
    try:
        f = float(e.transparency) if isinstance(e.transparency, (int, float)) else 1.0
        t = e.transparent
        if t is None or isinstance(t, collada.material.Map):
            opacity = f
        else:
            c = [float(v) for v in tuple(t)] + [1.0] * 4
            if e.opaque_mode == "RGB_ZERO":
                opacity = 1.0 - f * (0.212671 * c[0] + 0.715160 * c[1] + 0.072169 * c[2])
            else:
                opacity = f * c[3]
    except (TypeError, ValueError):
        opacity = 1.0
    transparency = min(1.0, max(0.0, 1.0 - opacity)) if math.isfinite(opacity) else 0.0
    return CadMaterial(m.id or "", diffuse, transparency, texture)  # type: ignore[arg-type]


_NAN = re.compile(rb"nan", re.IGNORECASE)


def _nan_positions(p: Any) -> bool:
    """Whether a primitive's positions say NaN, which pycollada reads as 0 (silently moving the
    vertex to the origin; assimp, Webots' reader, keeps it NaN)."""
    for entry in getattr(p.original, "sources", {}).get("VERTEX", ()):
        node = getattr(entry[4], "xmlnode", None)
        for child in node if node is not None else ():
            if str(child.tag).endswith("float_array") and child.text and _NAN.search(child.text.encode()):
                return True
    return False


def _why(exc: BaseException) -> str:
    """An exception's message on one line, bounded (without pycollada's class name in front)."""
    if isinstance(exc, RecursionError):
        return "its elements are nested too deeply"
    text = " ".join(str(exc).split()) or type(exc).__name__
    for prefix in ("DaeMalformedError: ", "DaeIncompleteError: ", "CadError: ", "DaeBrokenRefError: "):
        text = text.removeprefix(prefix)
    return text if len(text) <= 300 else text[:297] + "..."
