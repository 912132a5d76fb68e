"""Limits on what a world file may ask of the server, checked by the loader (so ``validate``
accepts exactly the worlds ``serve`` can run).

Two kinds of limits:

* **parsing** — file size, YAML/JSON nesting depth, alias expansion, number of values, string
  lengths, and the number of robots, devices per robot, lights and solids: checked while the
  text is read (:mod:`.yamlload`) and on the parsed data *before* the model is validated, so a
  hostile file costs little time and memory and its error quotes only a short prefix;
* **work** — rays per distance sensor, beams per lidar, rays per step, triangles, the memory
  building them takes together (``build_bytes``, at measured costs per triangle and per ray), the
  magnitude of every number: checked on the validated model.

``WorldLimits()`` are the defaults; ``WorldLimits.large()`` (``--allow-large``) raises every limit for
worlds that deliberately ask for more. The table is in README "Security and limits".
"""

from __future__ import annotations

import functools
import itertools
import math
import types
import typing
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from pydantic import BaseModel

from sensorium.schemas.devices import KINDS
from sensorium.schemas.world import Rows

__all__ = ["BYTES_PER_RAY", "BYTES_PER_TRIANGLE", "MAX_COORDINATE_M", "check_pose", "custom_data_chars", "WorldLimits", "LimitError", "check_counts", "check_data", "check_work", "quote", "triangle_count"]

MiB = 1 << 20
GiB = 1 << 30
MAX_COORDINATE_M = 1e5          # |x|, |y|, |z| of a pose set at run time (set_pose, set_field): 100 km
# What building a world costs in the server process, per unit (peak resident memory of `sensorium
# probe WORLD --steps 1 --enable all:32` above a trivial world's, FAST and EXACT, the packet path on
# and off; worlds of ~1M triangles, 2026-12-03). A triangle: worst a binary STL triangle soup
# (three vertices of its own per triangle) without the packet path (embreex copies the vertices),
# ~477 B; with it ~430 B; a flat STL grid under EXACT with edge guards (its Embree scene twice, with
# and without the guards) ~415 B; curved tessellations (spheres) ~256 B EXACT, ~230 B FAST.
# BYTES_PER_TRIANGLE is the worst + 13%. A ray cast per step ~200 B (distance sensor rays, lidar
# beams, light occlusion rays: `sensorium bench --only limits`). With margin:
BYTES_PER_TRIANGLE = 540
BYTES_PER_RAY = 220


def check_pose(translation: Iterable[float] | None = None, rotation: Iterable[float] | None = None,
               quaternion: Iterable[float] | None = None) -> None:
    """Raise ValueError unless every value is finite and the translation lies within the world
    bounds (every pose set at run time: requests and the in-process ``Robot.set_pose``)."""
    for name, values in (("translation", translation), ("rotation", rotation), ("quaternion", quaternion)):
        if values is None:
            continue
        vals = [float(v) for v in values]
        if not all(math.isfinite(v) for v in vals):
            raise ValueError(f"{name} values must be finite, got {vals}")
        if name == "translation" and any(abs(v) > MAX_COORDINATE_M for v in vals):
            raise ValueError(f"translation {vals} is outside the world bounds (|coordinate| <= {MAX_COORDINATE_M:g} m)")


@dataclass(frozen=True)
class WorldLimits:
    file_bytes: int = 16 * MiB               # the world file
    mesh_file_bytes: int = 256 * MiB         # each mesh file
    mesh_load_bytes: int = 2048 * MiB        # memory reading one mesh file larger than 1 MiB may take (a worker)
    nesting_depth: int = 64                  # nested mappings/sequences in the file
    values: int = 2_000_000                  # scalars + containers after YAML aliases are expanded
    name_chars: int = 256                    # names become topic paths (/<robot>/<device>/value)
    string_chars: int = 4096                 # any other string (urls, ...); custom_data has its own cap
    number_magnitude: float = 1e9            # |x| of every number (0 or in [1e-30, this])
    robots: int = 256
    devices_per_robot: int = 256
    lights: int = 256
    solids: int = 10_000
    rays_per_sensor: int = 1024              # DistanceSensor rays (after Webots' sanitising)
    beams_per_lidar: int = 1 << 20           # horizontal_resolution × number_of_layers
    rays_per_image: int = 1 << 22            # a camera's or range finder's rays: width × height (× 4 anti-aliased)
    rays_per_step: int = 1 << 22             # every device due at once: distance rays + lidar beams + light occlusion rays
    triangles: int = 4_000_000               # tessellated primitives + meshes (planes are analytic)
    build_bytes: int = 2 * GiB               # triangles and rays per step at the costs above, together
    # textures (world/textures.py): each image file, each image's pixels, all images' pixels (3 bytes each)
    texture_file_bytes: int = 64 * MiB
    texture_pixels: int = 1 << 24            # 4096 x 4096
    texture_pixels_total: int = 1 << 25      # ~100 MB decoded

    @classmethod
    def large(cls) -> WorldLimits:
        """``--allow-large``: every limit raised (parsing limits stay finite)."""
        return cls(file_bytes=1024 * MiB, mesh_file_bytes=4096 * MiB, mesh_load_bytes=65536 * MiB, nesting_depth=256, values=100_000_000,
                   name_chars=4096, string_chars=1 * MiB, number_magnitude=1e15, robots=100_000,
                   devices_per_robot=65_536, lights=65_536, solids=10_000_000, rays_per_sensor=1 << 20,
                   beams_per_lidar=1 << 28, rays_per_image=1 << 28, rays_per_step=1 << 30, triangles=1 << 30,
                   build_bytes=1024 * GiB,
                   texture_file_bytes=4096 * MiB, texture_pixels=1 << 30, texture_pixels_total=1 << 32)

    def describe(self) -> list[tuple[str, Any]]:
        return [(f.name, getattr(self, f.name)) for f in fields(self)]


class LimitError(ValueError):
    """Raised by the scans below: ``path`` (field path or "line N") and a message."""

    def __init__(self, path: str, message: str):
        super().__init__(f"{path}: {message}" if path else message)
        self.path = path
        self.message = message


RAISE = "(raise the limits with --allow-large)"


def quote(value: Any, limit: int = 60) -> str:
    """``repr`` of a value, cut to a short prefix (errors never echo a huge input)."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + f"… ({len(text)} characters)"


# ------------------------------------------------------------------------------------ parsing


def custom_data_chars(limits: WorldLimits) -> int:
    """The longest robot customData: the world file's and what a Supervisor sets (Webots has no bound)."""
    return 1 * MiB if limits.string_chars < MiB else limits.string_chars


def _string_limit(key: str, limits: WorldLimits) -> int:
    if key == "custom_data":
        return custom_data_chars(limits)
    if key == "name" or key.endswith("motor"):
        return limits.name_chars
    return limits.string_chars


_SCALAR_TYPES = frozenset({float, int, bool, type(None)})
BLOCK_MIN = 32       # lists shorter than this are walked item by item


def _scalar_block(value: Any) -> int:
    """1 when ``value`` is a long list or tuple (``BLOCK_MIN`` items or more) of numbers, booleans or
    nulls, 2 when it is one of lists/tuples of them (a mesh's points, its faces), else 0 (types
    gathered at C speed: a long run of numbers is counted in one pass, not an item at a time)."""
    if not isinstance(value, (list, tuple)) or len(value) < BLOCK_MIN:
        return 0
    kinds = set(map(type, value))
    if kinds <= _SCALAR_TYPES:
        return 1
    if not kinds <= {list, tuple}:
        return 0
    return 2 if set(map(type, itertools.chain.from_iterable(value))) <= _SCALAR_TYPES else 0


def check_data(data: Any, limits: WorldLimits) -> None:
    """The parsed (not yet validated) data: depth, number of values, string lengths. Iterative (a
    deep structure cannot overflow the stack). Raises ``LimitError`` naming the field path."""
    todo: list[tuple[Any, str, str, int]] = [(data, "", "", 0)]
    count = 0
    while todo:
        value, path, key, depth = todo.pop()
        count += 1
        if count > limits.values:
            raise LimitError("", f"more than {limits.values} values {RAISE}")
        if depth > limits.nesting_depth:
            raise LimitError(path, f"nested deeper than {limits.nesting_depth} levels {RAISE}")
        if isinstance(value, dict):
            for k, v in reversed(list(value.items())):
                if isinstance(k, str) and len(k) > limits.name_chars:
                    raise LimitError(path, f"key {quote(k)} longer than {limits.name_chars} characters")
                todo.append((v, f"{path}.{k}" if path else str(k), str(k), depth + 1))
        elif isinstance(value, (list, tuple)):
            levels = _scalar_block(value)
            if levels and depth + levels <= limits.nesting_depth:     # no string, no deeper level
                count += len(value) + (sum(map(len, value)) if levels == 2 else 0)
                if count > limits.values:
                    raise LimitError("", f"more than {limits.values} values {RAISE}")
                continue
            for i in reversed(range(len(value))):
                todo.append((value[i], f"{path}[{i}]", key, depth + 1))
        elif isinstance(value, np.ndarray):        # a converted .wbt mesh's rows: counted as the lists they stand for
            if depth + value.ndim > limits.nesting_depth:
                raise LimitError(path + "[0]" * value.ndim, f"nested deeper than {limits.nesting_depth} levels {RAISE}")
            count += value.size + (len(value) if value.ndim == 2 else 0)
            if count > limits.values:
                raise LimitError("", f"more than {limits.values} values {RAISE}")
        elif isinstance(value, str):
            cap = _string_limit(key, limits)
            if len(value) > cap:
                raise LimitError(path, f"string of {len(value)} characters, longer than {cap} "
                                       f"(starts {quote(value[:40])}) {RAISE}")


def check_counts(data: Any, limits: WorldLimits) -> None:
    """Robots, devices per robot, lights and solids (nested children included) of the parsed, not
    yet validated data: one ``LimitError`` naming the list, before any model is built."""
    if not isinstance(data, dict):
        return

    def items(value: Any) -> list:
        return value if isinstance(value, list) else []

    def over(path: str, n: int, cap: int, what: str) -> None:
        if n > cap:
            raise LimitError(path, f"{n:,} {what}, more than the limit of {cap:,} {RAISE}")

    robots = items(data.get("robots"))
    over("robots", len(robots), limits.robots, "robots")
    for i, robot in enumerate(robots):
        if isinstance(robot, dict):
            over(f"robots[{i}].devices", len(items(robot.get("devices"))), limits.devices_per_robot, "devices")
    lights = len(items(data.get("lights"))) + sum(len(items(r.get("lights"))) for r in robots if isinstance(r, dict))
    lights += sum(len(items(d.get("lights"))) for r in robots if isinstance(r, dict)    # an LED's lights
                  for d in items(r.get("devices")) if isinstance(d, dict))
    solids = 0
    todo = list(items(data.get("solids")))
    while todo and solids <= limits.solids:
        solid = todo.pop()
        solids += 1
        if isinstance(solid, dict):
            todo.extend(items(solid.get("children")))
            lights += len(items(solid.get("lights")))
    over("solids", solids, limits.solids, "solids (nested children included)")
    over("lights", lights, limits.lights, "lights")


# ------------------------------------------------------------------------------------ work


def _walk(model: Any, path: str = "", *, numbers: bool = False) -> Iterator[tuple[str, Any]]:
    """Every (path, value) of a validated model: nested models, lists, tuples (iterative). A long
    list of numbers (a model field typed as one: a mesh's vertices, ...) is yielded but not walked
    into (it holds no model), unless ``numbers``."""
    for p, v, _ in _walk_typed(model, path, numbers=numbers):
        yield p, v


Block = tuple[int, type]     # a model field of numbers: (1, float) a list of floats, (2, int) a list of int rows, ...


def _walk_typed(model: Any, path: str = "", *, numbers: bool = False) -> Iterator[tuple[str, Any, Block | None]]:
    """``_walk``, each value with its ``Block`` when it is a long list of numbers (else None)."""
    todo: list[tuple[str, Any, Block | None]] = [(path, model, None)]
    while todo:
        p, v, block = todo.pop()
        yield p, v, block
        if isinstance(v, BaseModel) and getattr(v, "not_simulated", False):   # (a PROTO's interface values)
            continue
        if isinstance(v, BaseModel):       # pushed in reverse: yielded in file order
            kinds = _number_fields(type(v))
            for name in reversed(type(v).model_fields):
                x = getattr(v, name)
                b = kinds.get(name)
                todo.append((f"{p}.{name}" if p else name, x, b if b is not None and _is_block(x) else None))
        elif isinstance(v, (list, tuple, Rows)) and (numbers or block is None):
            todo.extend((f"{p}[{i}]", v[i], None) for i in reversed(range(len(v))))


def _is_block(x: Any) -> bool:
    """A field's value checked as one block of numbers: a long list or tuple, or ``Rows`` of any
    length (an array, never walked number by number unless one is out of bounds)."""
    return isinstance(x, Rows) or (isinstance(x, (list, tuple)) and len(x) >= BLOCK_MIN)


@functools.cache
def _number_fields(cls: type[BaseModel]) -> dict[str, Block]:
    """The fields of a model class typed as lists of numbers or of fixed rows of numbers (every leaf
    the same type, float or int): what validation guarantees they hold."""
    out: dict[str, Block] = {}
    for name, field in cls.model_fields.items():
        tp = field.annotation
        if typing.get_origin(tp) in (typing.Union, types.UnionType):
            kinds = [a for a in typing.get_args(tp) if a is not type(None)]
            tp = kinds[0] if len(kinds) == 1 else None
        if typing.get_origin(tp) is typing.Annotated:     # (a model's Rows: the list type it stands for)
            tp = typing.get_args(tp)[0]
        origin, args = typing.get_origin(tp), typing.get_args(tp)
        if not (origin is list and len(args) == 1) and not (origin is tuple and len(args) == 2 and args[1] is Ellipsis):
            continue
        item = args[0]
        if item is float or item is int:
            out[name] = (1, item)
        elif typing.get_origin(item) is tuple:
            leaves = set(typing.get_args(item))
            if len(leaves) == 1 and leaves <= {float, int}:
                out[name] = (2, leaves.pop())
    return out


def triangle_count(geom: Any, mesh_triangles: Callable[[Any], int]) -> int:
    """Triangles the ray engine builds for a geometry model (closed forms; meshes by their file)."""
    from sensorium.server.world.geometry import capsule_segments

    kind = getattr(geom, "type", None)
    if kind == "box":
        return 12
    if kind == "sphere":
        return 20 * 4 ** int(geom.subdivision)
    if kind == "cylinder":
        return 4 * int(geom.subdivision)
    if kind == "cone":
        return 2 * int(geom.subdivision)
    if kind == "capsule":
        n_az, n_lat = capsule_segments(int(geom.subdivision))
        return 4 * n_az * n_lat
    if kind == "plane":
        return 0
    if kind == "mesh":
        return mesh_triangles(geom)
    if kind == "elevation_grid":               # two per cell, counted before any is made
        return 2 * (int(geom.x_dimension) - 1) * (int(geom.y_dimension) - 1)
    faces = getattr(geom, "faces", None)      # explicit triangle lists
    return len(faces) if faces is not None else 0


def number_problem(v: float, limits: WorldLimits) -> str | None:
    """Why a world refuses number ``v`` (not finite, over ``number_magnitude``, or nearer 0 than
    1e-30 without being 0), in the loader's words; None when it takes it."""
    mag = abs(v)
    if not math.isfinite(v):
        return f"expected a finite number, got {v!r}"
    if mag > limits.number_magnitude:
        return f"the magnitude of {v:g} exceeds the limit of {limits.number_magnitude:g} {RAISE}"
    if 0.0 < mag < 1e-30:
        return f"{v!r} is too close to 0 (use 0, or a magnitude of at least 1e-30)"
    return None


def _numbers_fine(v: Any, levels: int, cap: float) -> bool:
    """Every number of a list of floats (``levels`` 1) or of rows of floats (2) finite, at most
    ``cap`` in magnitude, and 0 or at least 1e-30; one numpy pass."""
    if isinstance(v, Rows):             # (a model's array of rows: read as it is)
        mag = np.abs(np.asarray(v, dtype=np.float64))
    else:
        mag = np.abs(np.fromiter(itertools.chain.from_iterable(v) if levels == 2 else v, dtype=np.float64))
    return bool(np.all(np.isfinite(mag)) and not np.any(mag > cap) and not np.any((mag > 0.0) & (mag < 1e-30)))


_GEOMETRY_TYPES = {"box", "sphere", "cylinder", "capsule", "cone", "plane", "mesh", "triangles", "elevation_grid"}


def _walk_work(world: Any, limits: WorldLimits, mesh_triangles: Callable[[Any], int],
               problems: list) -> tuple[int, int]:
    """(triangles, lights) of a validated world; every number out of bounds added to ``problems``,
    named by its path (a list of numbers checked in one numpy pass, walked number by number when it
    holds a bad one)."""

    def number(path: str, v: float) -> None:
        problem = number_problem(v, limits)
        if problem is not None:
            problems.append((path, problem))

    triangles = 0
    lights = 0                              # occluding light sensors cast a ray per light
    for path, v, block in _walk_typed(world):
        if isinstance(v, float):
            number(path, v)
        elif block is not None:
            if block[1] is float and not _numbers_fine(v, block[0], limits.number_magnitude):
                for p, x in _walk(v, path, numbers=True):    # one problem per number, as an item-by-item walk finds them
                    if isinstance(x, float):
                        number(p, x)
        elif isinstance(v, BaseModel):
            kind = getattr(v, "type", None)
            if kind in _GEOMETRY_TYPES and path.endswith("geometry"):
                triangles += triangle_count(v, mesh_triangles)
            elif isinstance(kind, str) and kind.endswith("Light"):
                lights += 1
    return triangles, lights


def _scan_work(world: Any, limits: WorldLimits, mesh_triangles: Callable[[Any], int]) -> tuple[int, int] | None:
    """What ``_walk_work`` counts, the same values visited, without making a path for each (a
    200-robot swarm holds about a million values; the paths were most of the walk's time): None
    when some number is out of bounds (the caller then walks again with paths, to name it)."""
    cap = limits.number_magnitude
    triangles = lights = 0
    todo: list[tuple[Any, bool]] = [(world, False)]     # (value, reached as a field named ...geometry)
    pop, push = todo.pop, todo.append
    while todo:
        v, geometry_field = pop()
        if isinstance(v, float):
            mag = abs(v)
            if not mag <= cap or 0.0 < mag < 1e-30:      # (NaN fails the first test)
                return None
        elif isinstance(v, BaseModel):
            if getattr(v, "not_simulated", False):       # (a PROTO's interface values: never simulated)
                continue
            kind = getattr(v, "type", None)
            if kind in _GEOMETRY_TYPES and geometry_field:
                triangles += triangle_count(v, mesh_triangles)
            elif isinstance(kind, str) and kind.endswith("Light"):
                lights += 1
            blocks = _number_fields(type(v))
            for name in type(v).model_fields:
                x = getattr(v, name)
                block = blocks.get(name)
                if block is not None and _is_block(x):   # a mesh's numbers
                    if block[1] is float and not _numbers_fine(x, block[0], cap):
                        return None
                    continue
                push((x, name.endswith("geometry")))
        elif isinstance(v, (list, tuple)):
            for x in v:
                if isinstance(x, float):             # numbers inline: most values are
                    mag = abs(x)
                    if not mag <= cap or 0.0 < mag < 1e-30:
                        return None
                elif isinstance(x, (BaseModel, list, tuple)):
                    push((x, False))
    return triangles, lights


def has_model(world: Any, cls: type) -> bool:
    """Whether some value of a validated model is an instance of ``cls`` (the walk of ``_walk``,
    without paths)."""
    todo: list[Any] = [world]
    nested = (BaseModel, list, tuple)
    while todo:
        v = todo.pop()
        if isinstance(v, cls):
            return True
        if isinstance(v, BaseModel):
            blocks = _number_fields(type(v))
            for name in type(v).model_fields:
                x = getattr(v, name)
                if isinstance(x, nested) and name not in blocks:     # (a field of numbers holds no model)
                    todo.append(x)
        elif isinstance(v, (list, tuple)):
            todo.extend(x for x in v if isinstance(x, nested))
    return False


def check_work(world: Any, limits: WorldLimits, mesh_triangles: Callable[[Any], int]) -> list[str | tuple[str, str]]:
    """The work a validated world asks for. Returns problems as ``(path, message)``."""
    problems: list[str | tuple[str, str]] = []

    def over(path: str, what: str, n: float, cap: float) -> None:
        num = (lambda x: f"{x:,}") if isinstance(n, int) else (lambda x: f"{x:g}")
        problems.append((path, f"{what} {num(n)} exceeds the limit of {num(cap)} {RAISE}"))

    counted = _scan_work(world, limits, mesh_triangles)
    if counted is None:        # some number out of bounds: the walk with paths, to name each
        counted = _walk_work(world, limits, mesh_triangles, problems)
    triangles, lights = counted
    # robots, devices, lights and solids: check_counts, on the data before validation
    if triangles > limits.triangles:
        over("", "the world's triangles:", triangles, limits.triangles)
    per_step = 0
    for r_i, robot in enumerate(world.robots):
        rp = f"robots[{r_i}]"
        for d_i, dev in enumerate(robot.devices):
            dp = f"{rp}.devices[{d_i}]"
            kind = KINDS.get(getattr(dev, "device", ""))
            n = kind.rays(dev, lights) if kind is not None and kind.rays is not None else 0
            if kind is not None and kind.ray_bound is not None:     # one device's own bound
                field_name, label, attr = kind.ray_bound
                if n > getattr(limits, attr):
                    over(f"{dp}{field_name}", label, n, getattr(limits, attr))
            per_step += n
    if per_step > limits.rays_per_step:
        over("", "rays in one step (every device due at once):", per_step, limits.rays_per_step)
    need = BYTES_PER_TRIANGLE * triangles + BYTES_PER_RAY * per_step
    if not problems and need > limits.build_bytes:      # each within its limit, too much together
        problems.append(("", f"building this world would take about {need / GiB:.1f} GiB of memory "
                             f"({triangles:,} triangles ≈ {BYTES_PER_TRIANGLE * triangles / GiB:.1f} GiB, "
                             f"{per_step:,} ray{'s' if per_step != 1 else ''} per step ≈ "
                             f"{BYTES_PER_RAY * per_step / GiB:.1f} GiB), more than "
                             f"the limit of {limits.build_bytes / GiB:g} GiB {RAISE}"))
    return problems


# ------------------------------------------------------------------------------------ Webots .wbt and PROTO expansion


@dataclass(frozen=True)
class ProtoLimits:
    """The work reading a ``.wbt`` world and expanding its PROTOs may do. A world file and the PROTO
    files it names are untrusted input: DEF/USE and nested PROTO instances multiply, templates are
    programs. Every bound is checked while the work is done, so a bomb stops at the bound, fast."""

    nodes: int = 1_000_000                  # nodes after DEF/USE reuse and PROTO expansion
    values: int = 4_000_000                 # numbers, strings and booleans after reuse and expansion
    instances: int = 5_000                  # PROTO instances expanded (identical ones share one expansion)
    depth: int = 24                         # PROTO instances nested inside one another
    proto_files: int = 2_000                # distinct PROTO files read
    proto_file_bytes: int = 8 * MiB         # each PROTO file
    template_seconds: float = 0.25          # CPU time of one template run
    template_total_seconds: float = 2.0     # CPU time of every template run of one world
    template_memory: int = 64 * MiB         # JavaScript heap of one template run
    template_output_chars: int = 8 * MiB    # text one template run may generate

    @classmethod
    def large(cls) -> ProtoLimits:
        """``--allow-large``: every bound raised (still finite)."""
        return cls(nodes=100_000_000, values=400_000_000, instances=2_000_000, depth=64, proto_files=100_000,
                   proto_file_bytes=256 * MiB, template_seconds=30.0, template_total_seconds=600.0,
                   template_memory=1024 * MiB, template_output_chars=256 * MiB)

    @classmethod
    def matching(cls, limits: WorldLimits | None) -> ProtoLimits:
        """The PROTO bounds that go with a world's limits (raised with ``--allow-large``)."""
        return cls.large() if limits is not None and limits.values > WorldLimits().values else cls()
