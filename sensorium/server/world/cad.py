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
diffuse image's path as written in the file (relative to it; OBJ: ``map_Kd``). Texture coordinates
are the lowest-numbered TEXCOORD set's (assimp's channel 0, Webots' texture coordinates).

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
    budget = [EAR_CLIP_WORK]
    try:
        bound = list(doc.scene.objects("geometry")) if doc.scene is not None else []
        skins = list(doc.scene.objects("controller")) if doc.scene is not None else []
        for g in [*bound, *skins]:
            for name, p in _primitives(g):
                if type(p).__name__ in ("BoundPolylist", "BoundPolygons"):
                    p = _triangulated(p, budget)
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
                    k = _first_uv_set(p)
                    st = np.asarray(p.texcoordset[k], dtype=np.float64).reshape(-1, 2)
                    ti = np.asarray(p.texcoord_indexset[k], dtype=np.int64)
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


def _primitives(g):
    """(geometry name, bound primitive) of a scene's geometry instance, or of a skinned mesh's
    (<instance_controller>): as Webots draws one (assimp's mesh without its bone weights), its
    geometry's own vertices placed by the node holding it — the skin's bind shape matrix and joints
    move nothing."""
    if hasattr(g, "original"):
        name = g.original.name or g.original.id or ""
        for p in g.primitives():
            yield name, p
        return
    geometry = getattr(getattr(g, "skin", None), "geometry", None)
    if geometry is None or not hasattr(geometry, "bind") or not hasattr(g, "matrix"):
        return          # (a morph controller)
    name = geometry.name or geometry.id or ""
    for p in geometry.bind(g.matrix, g.materialnodebysymbol).primitives():
        yield name, p


EAR_CLIP_CORNERS = 256      # a concave polygon of more corners is fanned (ear clipping is quadratic)
EAR_CLIP_WORK = 4_000_000   # ... and so are the concave polygons past this sum of corners² in one file


def _triangulated(p, budget: list[int]):
    """A <polylist>'s or <polygons>' triangles, as assimp's Triangulate step cuts its polygons: a
    convex polygon fanned from its first corner, a concave one cut into ears (so no triangle covers
    what lies outside it), while ``budget[0]`` (corners² left for ear clipping in this file) lasts.
    Returns an object with a triangle set's attributes."""
    from types import SimpleNamespace

    vcounts = np.asarray(p.original.vcounts, dtype=np.int64)
    corners_index = np.asarray(p.vertex_index, dtype=np.int64).ravel()
    if p.vertex is None or len(vcounts) == 0 or int(vcounts.sum()) != len(corners_index) or vcounts.min() < 1:
        return p.triangleset()
    starts = np.cumsum(vcounts) - vcounts
    big = vcounts >= 3
    # the fan of every polygon: corners (s, s+k, s+k+1) for k in 1 .. n-2
    n_tri = np.where(big, vcounts - 2, 0)
    first = np.repeat(starts, n_tri)
    k = np.arange(int(n_tri.sum())) - np.repeat(np.cumsum(n_tri) - n_tri, n_tri) + 1
    tris = np.stack([first, first + k, first + k + 1], axis=1)
    positions = np.asarray(p.vertex, dtype=np.float64).reshape(-1, 3)
    if (vcounts > 3).any() and corners_index.max(initial=0) < len(positions):
        concave = concave_polygons(positions[corners_index], vcounts, starts)
        if concave.any():
            tri_start = np.cumsum(n_tri) - n_tri
            for poly in np.flatnonzero(concave & (vcounts <= EAR_CLIP_CORNERS)):
                s, n = int(starts[poly]), int(vcounts[poly])
                if budget[0] < n * n:
                    break
                budget[0] -= n * n
                ears = ear_clip(positions[corners_index[s:s + n]])
                if ears is not None:
                    tris[tri_start[poly]:tri_start[poly] + n - 2] = ears + s
    return SimpleNamespace(vertex=p.vertex, vertex_index=corners_index[tris], material=p.material,
                           texcoordset=p.texcoordset, original=p.original,
                           texcoord_indexset=tuple(np.asarray(t, dtype=np.int64).ravel()[tris]
                                                   for t in p.texcoord_indexset))


def concave_polygons(points: np.ndarray, vcounts: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Per polygon (corner positions ``points``, grouped by ``vcounts``): whether a corner turns
    against the polygon's normal (Newell's)."""
    out = np.zeros(len(vcounts), dtype=bool)
    np.logical_or.at(out, np.repeat(np.arange(len(vcounts)), vcounts), reflex_corners(points, vcounts, starts))
    return out & (vcounts > 3)


@np.errstate(over="ignore", invalid="ignore")    # corners past 1e154 m: refused later, by value
def reflex_corners(points: np.ndarray, vcounts: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Per corner of polygons (corner positions ``points``, grouped by ``vcounts``, each starting
    at ``starts``): whether it turns against its polygon's normal (Newell's). A corner at the same
    place as the one before it turns nowhere: the turns are read between distinct corners (a
    reflex corner written twice in a row is still reflex, at its first copy)."""
    n = len(points)
    poly = np.repeat(np.arange(len(vcounts)), vcounts)
    local = np.arange(n) - np.repeat(starts, vcounts)
    nxt = np.repeat(starts, vcounts) + (local + 1) % np.repeat(vcounts, vcounts)
    prv = np.repeat(starts, vcounts) + (local - 1) % np.repeat(vcounts, vcounts)
    keep = (points != points[prv]).any(axis=1)
    if not keep.all():                  # once: what is kept has no corner repeating the one before it
        counts = np.bincount(poly[keep], minlength=len(vcounts))
        counts = counts[counts > 0]
        out = np.zeros(n, dtype=bool)
        out[keep] = reflex_corners(points[keep], counts, np.cumsum(counts) - counts)
        return out
    a, b = points, points[nxt]
    newell = np.stack([(a[:, 1] - b[:, 1]) * (a[:, 2] + b[:, 2]), (a[:, 2] - b[:, 2]) * (a[:, 0] + b[:, 0]),
                       (a[:, 0] - b[:, 0]) * (a[:, 1] + b[:, 1])], axis=1)
    normal = np.add.reduceat(newell, starts, axis=0) if len(starts) else np.empty((0, 3))
    turn = np.cross(points - points[prv], points[nxt] - points)
    along = np.einsum("ij,ij->i", turn, normal[poly])
    size = np.linalg.norm(turn, axis=1) * np.linalg.norm(normal[poly], axis=1)
    return along < -1e-9 * size


@np.errstate(over="ignore", invalid="ignore")
def ear_clip(points: np.ndarray) -> np.ndarray | None:
    """Ears of a simple polygon (n, 3) as (n − 2, 3) local corner triples, in the polygon's own
    winding; None when it has none to cut (self-crossing): then it stays fanned. A corner written
    twice in a row, or the tip of a spike out and straight back (its neighbours at one place), is
    cut first as a zero-area triangle; the search for the next ear starts where the last was cut,
    so a polygon whose ears all lie at one end (a spiral) takes quadratic, not cubic, work."""
    n = len(points)
    normal = np.zeros(3)
    for i in range(n):
        a, b = points[i], points[(i + 1) % n]
        normal += ((a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1]))
    drop = int(np.argmax(np.abs(normal)))
    if normal[drop] == 0.0:
        return None
    xy = np.delete(points, drop, axis=1)
    if (drop == 1) == (normal[drop] > 0):      # keep (u, v) counter-clockwise seen along the normal
        xy = xy[:, ::-1]
    scale = float(np.ptp(xy, axis=0).max()) or 1.0
    eps = 1e-12 * scale * scale
    left = np.arange(n)
    out = []
    t = 0                                      # where the search for an ear starts
    # the corners another corner is written at again (a polygon touching itself, a slit's ends)
    twin = (((xy[:, None] - xy[None]) ** 2).sum(axis=2) <= eps).sum(axis=1) > 1 if n <= 4096 else np.ones(n, dtype=bool)

    def cross(o, p, q):
        return (p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1]) - (p[..., 1] - o[..., 1]) * (q[..., 0] - o[..., 0])

    while len(left) > 3:
        m = len(left)
        p = xy[left]
        prv, nxt = np.roll(p, 1, axis=0), np.roll(p, -1, axis=0)
        same = (p == nxt).all(axis=1) | (prv == nxt).all(axis=1) | (p == prv).all(axis=1)
        cut = None
        if same.any():                         # zero area, and what is left is the same outline
            cut = int(np.flatnonzero(same)[0])
        else:
            turn = cross(prv, p, nxt)
            order = (np.arange(m) + t) % m
            for ok in (turn > eps, turn >= -eps):
                for u in order[ok[order]].tolist():
                    a, b, c = p[u - 1], p[u], p[(u + 1) % m]
                    keep = np.ones(m, dtype=bool)
                    keep[[u - 1, u, (u + 1) % m]] = False
                    others = p[keep]
                    # another corner inside the ear or on its edges blocks it (a diagonal through a
                    # corner may leave the polygon), unless it is one of the ear's own corners again
                    inside = (cross(a, b, others) >= -eps) & (cross(b, c, others) >= -eps) & \
                        (cross(c, a, others) >= -eps)
                    twins = twin[left[u - 1]] or twin[left[u]] or twin[left[(u + 1) % m]]
                    if twins:
                        for q in (a, b, c):
                            inside &= ((others - q) ** 2).sum(axis=1) > eps
                    if not inside.any() and not (twins and _enters(p, keep, ((a, b, c), (b, c, a), (c, a, b)), eps, cross)):
                        cut = u
                        break
                if cut is not None:
                    break
        if cut is None:
            return None
        out.append((left[cut - 1], left[cut], left[(cut + 1) % m]))
        left = np.delete(left, cut)
        t = (cut - 1) % (m - 1)
    out.append((left[0], left[1], left[2]))
    return np.asarray(out, dtype=np.int64)


def _enters(p: np.ndarray, keep: np.ndarray, corners, eps: float, cross) -> bool:
    """Whether the outline, where it passes again through one of an ear's corners (a polygon
    touching itself there: a figure eight's waist, a hole's corner on the outline), leaves that
    corner into the ear (``corners``: each ear corner with the next and the previous, counter-
    clockwise): the ear would cover what lies between the two visits."""
    m = len(p)
    for x, y, z in corners:
        for j in np.flatnonzero(keep & (((p - x) ** 2).sum(axis=1) <= eps)).tolist():
            for w in (p[j - 1], p[(j + 1) % m]):
                if cross(x, y, w) > eps and cross(x, w, z) > eps:
                    return True
    return False


def _first_uv_set(p) -> int:
    """Which of a primitive's TEXCOORD inputs is assimp's UV channel 0, the one Webots maps textures
    with: assimp files each input under its ``set`` number (0 without one) and packs the sets in
    ascending order, so the lowest set, whatever the order the inputs are written in (the first of
    equal ones)."""
    try:
        inputs = p.original.sources["TEXCOORD"]
    except (AttributeError, KeyError, TypeError):
        return 0
    sets = []
    for entry in inputs:
        try:
            sets.append(int(entry[3]) if entry[3] not in (None, "") else 0)
        except (TypeError, ValueError, IndexError):
            sets.append(0)
    if len(sets) != len(p.texcoordset):
        return 0
    return min(range(len(sets)), key=lambda i: (sets[i], i))


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
    below: others are not read; a name with spaces is read whole, as assimp reads it): ``Kd``, ``d``
    (or ``Tr``, 1 − opacity) and ``map_Kd`` (the file after its options, which are skipped as assimp
    skips them). A missing or unreadable .mtl gives no materials (Webots renders such faces white
    too)."""
    import os

    libs: list[str] = []
    folder = os.path.realpath(os.path.dirname(path))
    with open(path, "rb") as f:
        for raw in f:
            line = raw.strip()
            if line.startswith(b"mtllib"):
                # assimp reads the rest of the line as one file (``My Robot.mtl``); when no such file
                # exists, each word is tried (trimesh, which groups the faces, then finds none either)
                whole = line[len(b"mtllib"):].strip().decode("utf-8", "replace").replace("\\", "/")
                words = [whole] if whole and os.path.isfile(os.path.join(folder, whole)) else \
                    [w.decode("utf-8", "replace").replace("\\", "/") for w in line.split()[1:]]
                for lib in words:
                    if lib not in libs and len(libs) < MTL_FILES:
                        libs.append(lib)
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
            elif words[0] in ("d", "Tr") and len(words) >= 2:
                try:       # opacity; Tr is its complement (assimp: the last of the two written wins)
                    d = float(words[1]) if words[0] == "d" else 1.0 - float(words[1])
                    values["d"] = d if math.isfinite(d) else 1.0
                except ValueError:
                    pass
            elif words[0] == "map_Kd" and len(words) >= 2:
                image = _map_file(line.split(None, 1)[1])
                if image:
                    values["map_Kd"] = image
    return out


# texture options before a map's file name and how many values each takes (as assimp skips them)
_MAP_OPTIONS = {"-clamp": 1, "-type": 1, "-blendu": 1, "-blendv": 1, "-boost": 1, "-texres": 1, "-bm": 1,
                "-imfchan": 1, "-cc": 1, "-mm": 2, "-o": 3, "-s": 3, "-t": 3}


def _map_file(rest: str) -> str:
    """A .mtl map statement's file name: what follows its options, spaces inside kept (a Windows
    export's ``My Textures/wood 1.png``)."""
    text = rest.strip()
    while text.startswith("-"):
        option, _, text = text.partition(" ")
        count = _MAP_OPTIONS.get(option.lower())
        if count is None:
            text = f"{option} {text}".strip()
            break
        for _ in range(count):
            text = text.lstrip().partition(" ")[2] if " " in text.lstrip() else ""
        text = text.lstrip()
    return text.strip()


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
