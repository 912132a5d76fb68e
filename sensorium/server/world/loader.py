"""World file → validated model, with one precise message per problem.

Every problem names the file, the path to the field (``robots[0].devices[2].lookup_table[1]``)
and what was expected. Webots' sanitising rules that silently change a value are applied here and
reported as warnings, so a world behaves as it would in Webots and the user is told why.

Untrusted input: the file size, nesting, values and string lengths are bounded before the model is
built, and the work a world asks for (rays, beams, triangles, robots, ...) afterwards
(:mod:`.limits`); mesh urls must stay inside the world's folder unless ``allow_outside_meshes``.
Every failure is a :class:`WorldError`, never another exception.
"""

from __future__ import annotations

import json
import math
import re
import time
import typing
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import ValidationError

from sensorium.schemas import world as wm
from sensorium.server.world.limits import (
    LimitError,
    ProtoLimits,
    WorldLimits,
    check_counts,
    check_data,
    check_work,
    quote,
)
from sensorium.server.world.report import LoadReport, Loss
from sensorium.server.world.yamlload import load_yaml

DEFAULT_WORLD = Path(__file__).resolve().parents[2] / "worlds" / "arena.yaml"


def default_world_path() -> Path:
    """The embedded default world (``worlds/arena.yaml``), also when installed as a package."""
    if DEFAULT_WORLD.exists():
        return DEFAULT_WORLD
    from importlib.resources import files

    return Path(str(files("sensorium.worlds") / "arena.yaml"))


@dataclass(frozen=True, slots=True)
class Problem:
    path: str                        # robots[1].devices[0].x (stable, for programs)
    message: str
    label: str = ""                  # robots[1] (scout).devices[0] (lidar).x (what the user reads)


class WorldError(Exception):
    """A world file that cannot be used; ``problems`` lists every problem found."""

    def __init__(self, source: str, problems: list[Problem]):
        self.source = source
        self.problems = problems
        lines = [f"{source}: {p.label or p.path}: {p.message}" if p.path else f"{source}: {p.message}" for p in problems]
        super().__init__("\n".join(lines))


@dataclass(frozen=True)
class LoadedWorld:
    world: wm.World
    source: str                      # file path or "<memory>"
    base_dir: Path                   # mesh urls are relative to it
    text: bytes = b""                # the file as read (recordings attach it)
    warnings: list[str] = field(default_factory=list)   # every message of the load, losses included
    losses: tuple[Loss, ...] = ()                        # what sensors would notice was left out (report.py)
    asset_files: frozenset[Path] = frozenset()          # files outside base_dir it may read (PROTO assets)
    timings: dict[str, float] = field(default_factory=dict)   # wall seconds per loading stage (sensorium bench)
    # its texture images as the check read them, each file once (url -> file, image): the scene shows these
    textures: Mapping[str, tuple[Path, Any]] = field(default_factory=dict, repr=False, compare=False)

    @property
    def report(self) -> LoadReport:
        """What the load left out, for printing (``report.text()``) or programs (``report.losses``)."""
        return LoadReport(self.source, self.losses, tuple(self.warnings))

    @property
    def dropped(self) -> list[str]:
        """The losses' messages (``file:line:col: why``)."""
        return [loss.text for loss in self.losses]


def read_world_text(path: str | Path, limits: WorldLimits | None = None) -> bytes:
    """The bytes of a world file, at most ``limits.file_bytes`` of them (else ``WorldError``)."""
    limits = limits or WorldLimits()
    path = Path(path)
    source = str(path)
    try:
        with open(path, "rb") as f:
            text = f.read(limits.file_bytes + 1)
    except (OSError, ValueError) as exc:       # ValueError: a NUL byte in the path
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        if isinstance(exc, FileNotFoundError) and path.parent == Path("."):
            from sensorium import worlds

            reason += f" (nor a bundled world: {', '.join(worlds.names())})"
        raise WorldError(source, [Problem("", f"cannot read world file: {reason}")]) from None
    if len(text) > limits.file_bytes:
        raise WorldError(source, [Problem("", f"file larger than the limit of {limits.file_bytes:,} bytes "
                                              "(raise the limits with --allow-large)")])
    return text


def parse_text(text: bytes, source: str, *, json_format: bool = False, limits: WorldLimits | None = None) -> Any:
    """YAML (1.2 booleans) or JSON text → plain data, bounded (nesting, alias expansion) before it is
    built. Any failure is a ``WorldError``."""
    limits = limits or WorldLimits()
    try:
        if json_format:
            try:
                return json.loads(text, object_pairs_hook=_json_object)
            except _DuplicateKey as dup:
                try:                          # where: the YAML reader (JSON is YAML) names its line and column
                    load_yaml(text, WorldLimits.large())
                except yaml.YAMLError as exc:
                    if "duplicate key" in str(exc):
                        raise WorldError(source, [Problem("", syntax_problem(exc).replace("YAML", "JSON"))]) from None
                except Exception:  # noqa: BLE001 - any other reading: the line is not known, the key is
                    pass
                raise WorldError(source, [Problem("", f"not valid JSON: found duplicate key {dup.args[0]!r} (a "
                                                      "key repeated in one object)")]) from None
        return load_yaml(text, limits)        # bounded while it is read (nesting, aliases, robots, ...)
    except WorldError:
        raise
    except LimitError as exc:
        raise WorldError(source, [Problem(exc.path, exc.message)]) from None
    except RecursionError:
        raise WorldError(source, [Problem("", f"nested deeper than {limits.nesting_depth} levels "
                                              "(raise the limits with --allow-large)")]) from None
    except (yaml.YAMLError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise WorldError(source, [Problem("", syntax_problem(exc))]) from None
    except Exception as exc:  # noqa: BLE001 - yaml/json raise many types (and constructors ValueError) for bad text
        detail = str(exc)
        if len(detail) > 300:
            detail = detail[:300] + "…"
        raise WorldError(source, [Problem("", f"not valid YAML/JSON: {detail}")]) from None


class _DuplicateKey(ValueError):
    """A key repeated in one JSON object (json.loads keeps the last value in silence)."""


def _json_object(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise _DuplicateKey(key)
            seen.add(key)
    return out


def bundled_or_path(path: str | Path) -> Path:
    """``path``, or the bundled world of that bare name (``arena``, ``warehouse.yaml``) when no such
    file exists here: examples then work from any directory."""
    path = Path(path)
    if not path.exists() and path.parent == Path("."):
        from sensorium import worlds

        try:
            return worlds.world_path(path.name)
        except FileNotFoundError:
            pass
    return path


def load_world(path: str | Path, *, limits: WorldLimits | None = None, allow_outside_meshes: bool = False,
               webots_home: str | Path | None = None, proto_path: Sequence[str | Path] = ()) -> LoadedWorld:
    """Read, parse, validate and sanitise a world file (``WorldError`` listing every problem).
    ``limits``: the work it may ask for (default ``WorldLimits()``; ``--allow-large`` is
    ``WorldLimits.large()``); ``allow_outside_meshes``: mesh urls may leave the world's folder.
    A bare name of a bundled world (``arena``) works from any directory. For a ``.wbt`` world,
    PROTO files are found through ``webots_home`` (default ``$WEBOTS_HOME``) and ``proto_path``."""
    path = bundled_or_path(path)
    source = str(path)
    if path.suffix.lower() == ".wbt":
        return load_wbt(path, limits=limits, allow_outside_meshes=allow_outside_meshes, webots_home=webots_home,
                        proto_path=proto_path)
    text = read_world_text(path, limits)
    data = parse_text(text, source, json_format=path.suffix.lower() == ".json", limits=limits)
    return parse_world(data, source=source, base_dir=path.resolve().parent, text=text, limits=limits,
                       allow_outside_meshes=allow_outside_meshes)


def syntax_problem(exc: Exception) -> str:
    """One line for a file that does not parse: where (line, column) and what, without the parser's
    internal names (PyYAML says "<byte string>" for the file)."""
    if isinstance(exc, json.JSONDecodeError):
        return f"line {exc.lineno}, column {exc.colno}: not valid JSON: {exc.msg}"
    if isinstance(exc, UnicodeDecodeError):
        return f"byte {exc.start}: not UTF-8 text ({exc.reason})"
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    context = getattr(exc, "context", None)
    context_mark = getattr(exc, "context_mark", None)
    where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
    also = ""
    if context:
        also = f" ({context}" + (f" at line {context_mark.line + 1}, column {context_mark.column + 1}"
                                 if context_mark is not None else "") + ")"
    return f"{where}not valid YAML: {problem}{also}"


_PATH_PART = re.compile(r"\.?([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")


def with_names(path: str, data: Any) -> str:
    """``robots[1].devices[0].x`` → ``robots[1] (scout).devices[0] (lidar).x``: each list item that
    has a ``name`` in the file is named after its index (what users recognise)."""
    out, pos, node = "", 0, data
    while pos < len(path):
        m = _PATH_PART.match(path, pos)
        if m is None:
            return out + path[pos:]
        key, index = m.group(1), m.group(2)
        if key is not None:
            out += ("." if out else "") + key
            node = node.get(key) if isinstance(node, dict) else None
        else:
            i = int(index)
            out += f"[{i}]"
            node = node[i] if isinstance(node, list) and i < len(node) else None
            name = node.get("name") if isinstance(node, dict) else None
            if isinstance(name, str) and name:
                out += f" ({name})"
        pos = m.end()
    return out


def _named(data: Any, problems: list[Problem]) -> list[Problem]:
    return [Problem(p.path, p.message, with_names(p.path, data)) if p.path else p for p in problems]


def load_wbt(path: Path, *, limits: WorldLimits | None = None, allow_outside_meshes: bool = False,
             webots_home: str | Path | None = None, proto_path: Sequence[str | Path] = ()) -> LoadedWorld:
    """A Webots world, converted (``sensorium.server.world.wbt``); problems point at its lines.
    ``LoadedWorld.text`` is the .wbt file as read (recordings attach it under its own name)."""
    from sensorium.server.world.wbt import WbtSyntaxError, wbt_convert

    source = str(path)
    text = read_world_text(path, limits)           # the size limit (and a readable file)
    try:
        conv = wbt_convert(path, webots_home=webots_home, proto_path=proto_path, limits=ProtoLimits.matching(limits))
        data, warnings, origin = conv.data, conv.warnings, conv.origin
    except WbtSyntaxError as exc:
        if exc.source != source:    # in a PROTO file the world uses
            where = f"{exc.source}:{exc.line}:{exc.col}" if exc.line else exc.source
        else:
            where = f"line {exc.line}, column {exc.col}" if exc.line else ""
        raise WorldError(source, [Problem(where, exc.message)]) from None
    t0 = time.perf_counter()
    try:
        loaded = parse_world(data, source=source, base_dir=path.resolve().parent, text=text, limits=limits,
                             allow_outside_meshes=allow_outside_meshes, asset_files=conv.asset_files)
    except WorldError as exc:
        raise WorldError(source, [_wbt_problem(p, origin) for p in exc.problems]) from None
    placed = [_wbt_warning(w, origin, source) for w in loaded.warnings]
    return LoadedWorld(world=loaded.world, source=source, base_dir=loaded.base_dir, text=text,
                       warnings=[*warnings, *placed], losses=conv.losses, asset_files=conv.asset_files,
                       timings={**conv.timings, "validate": time.perf_counter() - t0}, textures=loaded.textures)


def _origin_of(path: str, origin: dict[str, tuple[int, int, str]]) -> tuple[int, int, str] | None:
    """(line, column, node type) of the .wbt node a converted world path came from."""
    key = path
    while key:
        if key in origin:
            return origin[key]
        cut = max(key.rfind("."), key.rfind("["))
        key = key[:cut] if cut > 0 else ""
    return None


def _wbt_warning(w: str, origin: dict[str, tuple[int, int, str]], source: str) -> str:
    """A warning of the converted world (the loader's resets start with the converted path),
    placed at the .wbt node it came from."""
    where, _, message = w.partition(": ")
    at = _origin_of(where, origin)
    return f"{source}:{at[0]}:{at[1]}: {at[2]} ({where}): {message}" if at else w


def _wbt_problem(p: Problem, origin: dict[str, tuple[int, int, str]]) -> Problem:
    """A problem of the converted world, placed at the .wbt node it came from."""
    at = _origin_of(p.path, origin)
    if at is None:
        return p
    return Problem(f"line {at[0]}, column {at[1]} ({at[2]}, converted as {p.path})", p.message)


def parse_world(data: Any, source: str = "<memory>", base_dir: Path | None = None, text: bytes = b"", *,
                limits: WorldLimits | None = None, allow_outside_meshes: bool = False,
                asset_files: frozenset[Path] = frozenset()) -> LoadedWorld:
    limits = limits or WorldLimits()
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise WorldError(source, [Problem("", f"a world must be a mapping, got {type(data).__name__}")])
    try:
        check_counts(data, limits)          # robots, devices, lights, solids: before anything is built
        check_data(data, limits)
    except LimitError as exc:
        raise WorldError(source, [Problem(exc.path, exc.message)]) from None
    try:
        world = wm.World.model_validate(data)
    except ValidationError as exc:
        raise WorldError(source, _named(data, [_problem_from_pydantic(e) for e in exc.errors()])) from None
    base = base_dir or Path.cwd()
    textures: dict = {}
    problems = check_world(world, base, limits=limits, allow_outside_meshes=allow_outside_meshes,
                           asset_files=asset_files, textures=textures)
    if problems:
        raise WorldError(source, _named(data, problems))
    world, weighed = complete_masses(world, base, limits=limits, allow_outside_meshes=allow_outside_meshes,
                                     asset_files=asset_files)
    world, warnings = sanitize(world)
    return LoadedWorld(world=world, source=source, base_dir=base, text=text, warnings=[*weighed, *warnings],
                       textures=textures)


def from_model(world: wm.World, base_dir: Path | None = None) -> LoadedWorld:
    """A world model built in memory (``<memory>``), checked against its files under ``base_dir``
    (default: the working directory) and sanitised as a world file is; ``WorldError`` if unusable."""
    textures: dict = {}
    problems = check_world(world, base_dir or Path.cwd(), textures=textures)
    if problems:
        raise WorldError("<memory>", problems)
    world, _ = complete_masses(world, base_dir or Path.cwd())
    world, _ = sanitize(world)
    return LoadedWorld(world=world, source="<memory>", base_dir=base_dir or Path.cwd(), textures=textures)


_TAGS = {"box", "sphere", "cylinder", "capsule", "cone", "plane", "triangles", "mesh", "elevation_grid", "PointLight", "SpotLight",
         "DirectionalLight", *wm.DEVICE_TYPES}


def format_path(loc: tuple[Any, ...]) -> str:
    out = ""
    for i, part in enumerate(loc):
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in _TAGS and i > 0 and not isinstance(loc[i - 1], str):
            continue  # pydantic puts the discriminator value in the location; users never wrote it
        elif part in _TAGS and i > 0 and loc[i - 1] in ("geometry",):
            continue
        else:
            out += ("." if out else "") + str(part)
    return out


def _tags(union: Any, key: str) -> tuple[str, ...]:
    """The values of ``key`` a discriminated union of the schema accepts (each model's ``Literal``)."""
    return tuple(typing.get_args(m.model_fields[key].annotation)[0] for m in typing.get_args(typing.get_args(union)[0]))


def _choices(loc: tuple[Any, ...]) -> tuple[str, ...]:
    """The kinds a ``device``/``type`` key accepts where ``loc`` points (a device, geometry or light)."""
    keys = [p for p in loc if isinstance(p, str)]
    if keys and keys[-1] == "geometry":
        return _tags(wm.Geometry, "type")
    if "devices" in keys:
        return tuple(wm.DEVICE_TYPES)
    if keys and keys[-1] == "lights":
        return _tags(wm.Light, "type")
    return ()


def _problem_from_pydantic(err: Mapping[str, Any]) -> Problem:
    loc = tuple(err.get("loc", ()))
    msg = err.get("msg", "invalid")
    kind = err.get("type", "")
    if kind == "extra_forbidden":
        msg = "unknown key (check spelling; field names are Webots' names in snake_case)"
    elif kind in ("finite_number",):
        msg = f"expected a finite number, got {quote(err.get('input'))}"
    elif kind in ("union_tag_not_found", "union_tag_invalid"):     # no (or an unknown) ``device:``/``type:``
        ctx = err.get("ctx") or {}
        key = str(ctx.get("discriminator", "")).strip("'")
        kinds = ", ".join(_choices(loc))
        if kind == "union_tag_not_found":
            msg = f"no {key!r} key: it says what this is" + (f" (one of: {kinds})" if kinds else "")
        else:
            msg = f"{key} {quote(ctx.get('tag'))} is not one of: {kinds or ctx.get('expected_tags', '')}"
    elif ("input" in err and kind not in ("missing", "union_tag_invalid", "union_tag_not_found")
          and not isinstance(err["input"], (dict, list))
          and not (kind == "value_error" and ", got " in msg)):   # our validators' messages say what they got
        msg = f"{msg} (got {quote(err['input'])})"
    if len(msg) > 400:
        msg = msg[:400] + "…"
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    if kind == "value_error" and (bad := _BOOL_FIELD.match(msg)):   # the model's check names its field: in the path
        loc, msg = (*loc, bad[1]), bad[2]
    return Problem(format_path(loc), msg)


_BOOL_FIELD = re.compile(r"(\w+): (expected a number, got (?:True|False))$")   # schemas.world.Strict


def check_world(world: wm.World, base_dir: Path, *, limits: WorldLimits | None = None,
                allow_outside_meshes: bool = False, asset_files: frozenset[Path] = frozenset(),
                textures: dict | None = None) -> list[Problem]:
    """Checks that relate several fields or the file system, and the world's limits; one problem
    per finding. ``textures`` receives the texture images as read (``check_textures``' ``images``)."""
    problems: list[Problem] = []

    def unique(items: Sequence[tuple[str, str | None]], what: str) -> None:
        first: dict[str, str] = {}
        for path, name in items:
            if name is None:
                continue
            if name in first:
                problems.append(Problem(path, f"duplicate {what} name {name!r} (first used at {first[name]})"))
            else:
                first[name] = path

    robot_names = {r.name for r in world.robots}
    carried = {r.name for r in world.robots if r.carried_by is not None}
    for i, r in enumerate(world.robots):
        if r.carried_by is not None and (r.carried_by.robot not in robot_names or r.carried_by.robot in carried
                                         or r.carried_by.robot == r.name):
            problems.append(Problem(f"robots[{i}].carried_by.robot", f"{r.carried_by.robot!r} is no other robot "
                                    "that is not carried itself"))
        drives = [k for k in ("differential_drive", "ackermann_drive", "mecanum_drive", "omni_drive", "steered_drive")
                  if getattr(r, k) is not None]
        if r.carried_by is not None and drives:
            problems.append(Problem(f"robots[{i}].{drives[0]}", "a robot riding another (carried_by) has no drive "
                                    "of its own: it is fixed in its carrier's frame"))

    def name_ok(path: str, name: str, reserved: tuple[str, ...] = ()) -> None:
        # names become topic and service paths (/<robot>/<device>/value): a robot's name is one
        # segment; a device's may hold '/' as Webots' do (NAO: 'Sonar/Left'), one segment or more
        if "/" in name or "\0" in name:
            problems.append(Problem(path, f"name {name!r} must not contain '/' or NUL (names are used in topic paths)"))
        elif name in reserved:
            problems.append(Problem(path, f"name {name!r} is reserved (robot-level services live under /<robot>/robot/)"))

    def device_name_ok(path: str, name: str) -> None:
        if "\0" in name:
            problems.append(Problem(path, f"name {name!r} must not contain NUL (names are used in topic paths)"))
        elif "/" in name and ("" in name.split("/")):
            problems.append(Problem(path, f"name {name!r} must not start or end with '/' nor hold '//' "
                                          "(its topic path would have an empty segment)"))
        elif name.split("/")[0] == "robot":
            problems.append(Problem(path, f"name {name!r} is reserved (robot-level services live under /<robot>/robot/)"))

    solid_names = {s.name for s in world.solids}
    for i, c in enumerate(world.chargers):
        if c.solid not in solid_names:
            problems.append(Problem(f"chargers[{i}].solid", f"no top-level solid named {c.solid!r} (the Charger's "
                                                            "body: its position)"))
    for i, r in enumerate(world.robots):
        name_ok(f"robots[{i}].name", r.name)
        for d_i, d in enumerate(r.devices):
            device_name_ok(f"robots[{i}].devices[{d_i}].name", d.name)
        # a device named like another's path below it ('Sonar' and 'Sonar/value') would share its topics
        device_set = {d.name for d in r.devices}
        for d_i, d in enumerate(r.devices):
            parts = d.name.split("/")
            above = next(("/".join(parts[:k]) for k in range(1, len(parts)) if "/".join(parts[:k]) in device_set), None)
            if above is not None:
                problems.append(Problem(f"robots[{i}].devices[{d_i}].name",
                                        f"name {d.name!r} lies under device {above!r}'s topic and service paths "
                                        f"(/{r.name}/{above}/...): rename one of them"))
    unique([(f"solids[{i}].name", s.name) for i, s in enumerate(world.solids)], "solid")
    unique([(f"robots[{i}].name", r.name) for i, r in enumerate(world.robots)], "robot")
    unique([(p, lt.name) for p, lt in all_lights(world)], "light")
    for path, lt in all_lights(world):     # only a robot's own lights name a joint (an LED's ride with the LED)
        if lt.on_joint is not None and not (path.startswith("robots[") and ".devices[" not in path):
            where = "an LED's lights ride with the LED (give on_joint to the LED)" if ".devices[" in path else \
                "only a robot's lights ride on its joints"
            problems.append(Problem(f"{path}.on_joint", where))
    unique([(f"robots[{i}].def_name", r.def_name) for i, r in enumerate(world.robots)]
           + [(f"solids[{i}].def_name", s.def_name) for i, s in enumerate(world.solids)], "DEF")

    for path, solid in all_solids(world):
        for s_i, part in enumerate(solid.shapes):
            if part.of_device is not None:
                problems.append(Problem(f"{path}.shapes[{s_i}].of_device",
                                        "only a robot's shapes belong to one of its devices"))
            if part.unseen_by:
                problems.append(Problem(f"{path}.shapes[{s_i}].unseen_by", "only a robot's devices see its shapes"))
    for p, geom in all_geometries(world):
        problems += _check_geometry(geom, p, base_dir)
    for r_i, robot in enumerate(world.robots):
        rp = f"robots[{r_i}]"
        names = [(f"{rp}.devices[{d_i}].name", d.name) for d_i, d in enumerate(robot.devices)]
        # a RotationalMotor or LinearMotor entry named like a drive motor is that motor (its place in the
        # device list; a Track's LinearMotor drives a tracked robot)
        listed = {d.name for d in robot.devices if isinstance(d, wm.Motor)}
        names += [(f"{rp}.{field}", m) for field, m in robot.drive_motors if m not in listed]
        unique(names, "device")
        device_names = {d.name for d in robot.devices}
        for s_i, part in enumerate(robot.shapes):
            if part.of_device is not None and part.of_device not in device_names:
                problems.append(Problem(f"{rp}.shapes[{s_i}].of_device",
                                        f"{part.of_device!r} is not a device of this robot "
                                        f"(devices: {', '.join(repr(n) for n in device_names) or 'none'})"))
            for u_i, name in enumerate(part.unseen_by):
                if name not in device_names:
                    problems.append(Problem(f"{rp}.shapes[{s_i}].unseen_by[{u_i}]",
                                            f"{name!r} is not a device of this robot "
                                            f"(devices: {', '.join(repr(n) for n in device_names) or 'none'})"))
        problems += _check_joints(robot, rp)
        for d_i, dev in enumerate(robot.devices):
            dp = f"{rp}.devices[{d_i}]"
            table = getattr(dev, "lookup_table", None)
            if table is not None:
                for k in range(1, len(table)):
                    if not table[k][0] > table[k - 1][0]:
                        problems.append(Problem(
                            f"{dp}.lookup_table[{k}]",
                            f"lookup table inputs must be strictly increasing: input {table[k][0]} "
                            f"follows {table[k - 1][0]}"))
            if isinstance(dev, wm.Motor) and dev.name in {m for _, m in robot.drive_motors}:
                joint = sorted(dev.model_fields_set & set(wm.Motor.model_fields) - set(wm._Device.model_fields)
                               | (dev.model_fields_set & {"max_torque", "max_force"}))
                if joint:
                    problems.append(Problem(f"{dp}.{joint[0]}", f"{dev.name!r} is a motor of the robot's drive, which "
                                                                "sets its speed and limits: leave out "
                                                                + ", ".join(joint)))
            if isinstance(dev, wm.PositionSensor) and dev.motor is not None:
                # a drive's motor, or a RotationalMotor/LinearMotor entry (a joint moved kinematically)
                motors = tuple(dict.fromkeys([*(m for _, m in robot.drive_motors),
                                              *(d.name for d in robot.devices if isinstance(d, wm.Motor))]))
                if dev.motor not in motors:
                    problems.append(Problem(
                        f"{dp}.motor", f"{dev.motor!r} is not a motor of this robot "
                                       f"(motors: {', '.join(repr(m) for m in motors) or 'none'})"))
            if isinstance(dev, wm.Brake):
                problems += _check_brake(robot, dev, dp)
            if isinstance(dev, wm.Lidar) and dev.max_range <= dev.min_range:
                pass  # Webots sanitises this (max_range := min_range + 1); see sanitize()
    problems += _check_meshes_and_work(world, base_dir, limits or WorldLimits(), allow_outside_meshes, asset_files)
    if not problems:    # textures: confined like meshes, within the limits, decoded once (world/textures.py)
        from sensorium.server.world.textures import check_textures

        problems += [Problem(*p) for p in check_textures(world, base_dir, limits or WorldLimits(), allow_outside_meshes,
                                                         asset_files, textures)]
    return problems


def _check_brake(robot: wm.Robot, brake: wm.Brake, dp: str) -> list[Problem]:
    """A Brake's ``motor`` and ``position_sensor`` name devices of its robot (of those kinds), and its
    ``joint_type`` is its motor's."""
    problems = []
    motors: dict[str, wm.Motor | None] = {d.name: d for d in robot.devices if isinstance(d, wm.Motor)}
    motors.update({m: None for _, m in robot.drive_motors if m not in motors})      # a drive's wheel: rotational
    sensors = [d.name for d in robot.devices if isinstance(d, wm.PositionSensor)]
    if brake.motor is not None:
        if brake.motor not in motors:
            problems.append(Problem(f"{dp}.motor", f"{brake.motor!r} is not a motor of this robot "
                                    f"(motors: {', '.join(repr(m) for m in motors) or 'none'})"))
        else:
            kind = "linear" if isinstance(motors[brake.motor], wm.LinearMotor) else "rotational"
            if brake.joint_type != kind:
                problems.append(Problem(f"{dp}.joint_type", f"{brake.joint_type!r}, but its motor {brake.motor!r} "
                                        f"is {kind} (a brake shares its motor's joint)"))
    if brake.position_sensor is not None and brake.position_sensor not in sensors:
        problems.append(Problem(f"{dp}.position_sensor", f"{brake.position_sensor!r} is not a PositionSensor of "
                                f"this robot (position sensors: {', '.join(repr(n) for n in sensors) or 'none'})"))
    return problems


def _check_joints(robot: wm.Robot, rp: str) -> list[Problem]:
    """``on_joint`` names one of the robot's joint motors (a RotationalMotor or LinearMotor that is
    not its drive's), and joints riding on joints never loop back."""
    problems: list[Problem] = []
    drive = {m for _, m in robot.drive_motors}
    joints = {d.name: d for d in robot.devices if isinstance(d, wm.Motor) and d.name not in drive}
    riders = [(f"{rp}.shapes[{i}].on_joint", p.on_joint) for i, p in enumerate(robot.shapes)]
    riders += [(f"{rp}.devices[{i}].on_joint", d.on_joint) for i, d in enumerate(robot.devices)]
    riders += [(f"{rp}.lights[{i}].on_joint", lt.on_joint) for i, lt in enumerate(robot.lights)]
    riders += [(f"{rp}.radar_targets[{i}].on_joint", t.on_joint) for i, t in enumerate(robot.radar_targets)]
    for path, name in riders:
        if name is not None and name not in joints:
            problems.append(Problem(path, f"{name!r} is not a joint motor of this robot (RotationalMotor or LinearMotor "
                                          f"entries, drives' excepted: {', '.join(repr(n) for n in joints) or 'none'})"))
    on = {d.name: d.on_joint for d in robot.devices}
    for i, part in enumerate(robot.shapes):
        if part.of_device is not None and part.of_device in on and part.on_joint != on[part.of_device]:
            problems.append(Problem(f"{rp}.shapes[{i}].on_joint", f"a shape of device {part.of_device!r} rides on "
                                    f"its device's joint: {on[part.of_device]!r}, not {part.on_joint!r}"))
    if problems:
        return problems
    for i, d in enumerate(robot.devices):
        if d.name not in joints:
            continue
        seen, at = {d.name}, d.on_joint
        while at is not None:
            if at in seen:
                problems.append(Problem(f"{rp}.devices[{i}].on_joint",
                                        f"joint {d.name!r} rides on itself through {at!r} (joints must form a tree)"))
                break
            seen.add(at)
            at = joints[at].on_joint
    return problems


def _check_meshes_and_work(world: wm.World, base_dir: Path, limits: WorldLimits,
                           allow_outside_meshes: bool, asset_files: frozenset[Path] = frozenset()) -> list[Problem]:
    """Every mesh url (confined, readable, bounded) and the work the world asks for."""
    from sensorium.server.world.limits import _walk, has_model
    from sensorium.server.world.meshes import MeshFileError, load_mesh, resolve_mesh_url

    problems: list[Problem] = []
    faces: dict[tuple[str, tuple[float, ...], int, str], int] = {}
    failed: set[str] = set()      # a file that failed is said once (a CadShape's materials each name it)
    for path, geom in (_walk(world) if has_model(world, wm.Mesh) else ()):   # (paths only when there are meshes)
        if not isinstance(geom, wm.Mesh):
            continue
        key = (geom.url, tuple(geom.scale), geom.material_index, geom.name)
        if key in faces or geom.url in failed:
            continue
        faces[key] = 0
        try:
            file = resolve_mesh_url(geom.url, base_dir, allow_outside=allow_outside_meshes,
                                    max_bytes=limits.mesh_file_bytes, allowed=asset_files)
            faces[key] = len(load_mesh(file, geom.scale, display=geom.url, memory=limits.mesh_load_bytes,
                                       max_triangles=limits.triangles, material=geom.material_index,
                                       name=geom.name).faces)
        except MeshFileError as exc:
            problems.append(Problem(f"{path}.url", str(exc)))
            failed.add(geom.url)
    if problems:
        return problems
    for item in check_work(world, limits, lambda g: faces.get((g.url, tuple(g.scale), g.material_index, g.name), 0)):
        problems.append(Problem(*item) if isinstance(item, tuple) else Problem("", item))
    return problems


def complete_masses(world: wm.World, base_dir: Path, *, limits: WorldLimits | None = None,
                    allow_outside_meshes: bool = False, asset_files: frozenset[Path] = frozenset()
                    ) -> tuple[wm.World, list[str]]:
    """Every ``pending_mass`` (a Physics whose bounding object holds mesh files) made the node's ``mass``,
    its files read as its shapes' are (checked already by ``check_world``; cached), each weighed as
    Webots weighs it (``wbt.mass``); one warning per mesh Webots gives up on, which counts 1 kg at its
    origin as there."""
    if not has_pending_mass(world):
        return world, []
    from sensorium.server.world.meshes import load_mesh, resolve_mesh_url
    from sensorium.server.world.poses import pose_from_model
    from sensorium.server.world.wbt.mass import REFERENCE_DENSITY, completed_mass, trimesh_volume

    limits = limits or WorldLimits()
    warnings: list[str] = []

    def weigh(path: str, node: Any) -> Any:
        pending = node.pending_mass
        if pending is None:
            return node
        volumes = []
        for i, part in enumerate(pending.meshes):
            g = part.mesh
            file = resolve_mesh_url(g.url, base_dir, allow_outside=allow_outside_meshes,
                                    max_bytes=limits.mesh_file_bytes, allowed=asset_files)
            mesh = load_mesh(file, g.scale, display=g.url, memory=limits.mesh_load_bytes,
                             max_triangles=limits.triangles, material=g.material_index, name=g.name)
            at = pose_from_model(part.pose)
            got = trimesh_volume(mesh.vertices, mesh.faces)
            if got is None:
                warnings.append(f"{path}.pending_mass.meshes[{i}]: mesh {g.url!r} in the boundingObject: Webots' mass "
                                "properties of its triangles fail (no positive mass or inertia: open, or not all "
                                "wound outward), so it counts 1 kg at its origin, as in Webots")
                volumes.append((1.0 / REFERENCE_DENSITY, at.translation))
            else:
                volumes.append((got[0], at.rotation @ got[1] + at.translation))
        return node.model_copy(update={"mass": wm.Mass(**completed_mass(pending, volumes)), "pending_mass": None})

    def solid(path: str, s: wm.Solid) -> wm.Solid:
        children = [solid(f"{path}.children[{i}]", c) for i, c in enumerate(s.children)]
        return weigh(path, s.model_copy(update={"children": children}) if s.children else s)

    solids = [solid(f"solids[{i}]", s) for i, s in enumerate(world.solids)]
    robots = []
    for r_i, r in enumerate(world.robots):
        nodes = [weigh(f"robots[{r_i}].nodes[{n_i}]", n) for n_i, n in enumerate(r.nodes)]
        robots.append(weigh(f"robots[{r_i}]", r.model_copy(update={"nodes": nodes}) if r.nodes else r))
    return world.model_copy(update={"solids": solids, "robots": robots}), warnings


def has_pending_mass(world: wm.World) -> bool:
    return any(s.pending_mass is not None for _, s in all_solids(world)) or any(
        r.pending_mass is not None or any(n.pending_mass is not None for n in r.nodes) for r in world.robots)


def all_solids(world: wm.World) -> Iterator[tuple[str, wm.Solid]]:
    """Every solid, nested children included, with its path in the file."""
    def walk(path: str, solid: wm.Solid) -> Iterator[tuple[str, wm.Solid]]:
        yield path, solid
        for c_i, child in enumerate(solid.children):
            yield from walk(f"{path}.children[{c_i}]", child)

    for i, s in enumerate(world.solids):
        yield from walk(f"solids[{i}]", s)


def all_lights(world: wm.World) -> Iterator[tuple[str, Any]]:
    """Every light (world, solid-attached, robot-attached) with its path in the file."""
    for i, lt in enumerate(world.lights):
        yield f"lights[{i}]", lt
    for path, solid in all_solids(world):
        for i, lt in enumerate(solid.lights):
            yield f"{path}.lights[{i}]", lt
    for r_i, robot in enumerate(world.robots):
        for i, lt in enumerate(robot.lights):
            yield f"robots[{r_i}].lights[{i}]", lt
        for d_i, dev in enumerate(robot.devices):      # an LED's lights
            for i, lt in enumerate(getattr(dev, "lights", ())):
                yield f"robots[{r_i}].devices[{d_i}].lights[{i}]", lt


def all_geometries(world: wm.World) -> Iterator[tuple[str, Any]]:
    for path, solid in all_solids(world):
        if solid.geometry is not None:
            yield f"{path}.geometry", solid.geometry
        for i, part in enumerate(solid.shapes):
            yield f"{path}.shapes[{i}].geometry", part.geometry
    for r_i, robot in enumerate(world.robots):
        if robot.body is not None:
            yield f"robots[{r_i}].body.geometry", robot.body.geometry
        for i, part in enumerate(robot.shapes):
            yield f"robots[{r_i}].shapes[{i}].geometry", part.geometry


def _check_geometry(geom: Any, path: str, base_dir: Path) -> list[Problem]:
    if isinstance(geom, wm.Triangles):
        n = len(geom.vertices)
        if n == 0 and geom.faces:          # (a .wbt IndexedFaceSet without its coord)
            return [Problem(f"{path}.vertices", f"no vertices for its {len(geom.faces)} face(s) to index")]
        try:                        # the first face indexing outside the vertices, found in one numpy pass
            f = np.asarray(geom.faces, dtype=np.int64).reshape(-1, 3)
            bad = ((f < 0) | (f >= n)).any(axis=1)
            first = [int(bad.argmax())] if bad.any() else []
        except OverflowError:       # (an index beyond 64 bits: face by face)
            first = [i for i, face in enumerate(geom.faces) if min(face) < 0 or max(face) >= n][:1]
        return [Problem(f"{path}.faces[{i}]", f"vertex index outside 0..{n - 1}: {list(geom.faces[i])}") for i in first]
    return []      # mesh files: _check_meshes_and_work (url confined to the world's folder, size, triangles)


def _radar_resets(p: str, dev: wm.Radar, warnings: list[str]) -> dict[str, Any]:
    """WbRadar's update functions, in the order its postFinalize calls them: the values it resets."""
    upd: dict[str, Any] = {}

    def reset(field: str, value: float, why: str) -> None:
        warnings.append(f"{p}.{field}: {why}, reset to {value:g}")
        upd[field] = value

    lo, hi = dev.min_range, dev.max_range
    if lo < 0.0:                                             # updateMinRange
        reset("min_range", 0.0, "negative")
        lo = 0.0
    if hi <= lo:
        if hi == 0.0:
            reset("max_range", lo + 1.0, "not greater than min_range")
            hi = lo + 1.0
        else:
            reset("min_range", max(hi - 1.0, 0.0), "not less than max_range")
            lo = max(hi - 1.0, 0.0)
    if hi < 0.0:                                             # updateMaxRange
        reset("max_range", lo + 1.0, "negative")
        hi = lo + 1.0
    if hi <= lo:
        reset("max_range", lo + 1.0, "not greater than min_range")
    if not 0.0 < dev.horizontal_field_of_view < math.pi:
        reset("horizontal_field_of_view", 0.78, "outside (0, pi)")
    if not 0.0 < dev.vertical_field_of_view < math.pi / 2:
        reset("vertical_field_of_view", 0.1, "outside (0, pi/2)")
    if dev.min_absolute_radial_speed < 0.0:
        reset("min_absolute_radial_speed", 0.0, "negative")
    if (dev.min_radial_speed != 0.0 or dev.max_radial_speed != 0.0) and dev.max_radial_speed <= dev.min_radial_speed:
        reset("max_radial_speed", dev.min_radial_speed + 1.0, "not greater than min_radial_speed")
    for name in ("cell_distance", "cell_speed", "range_noise", "speed_noise", "angular_noise"):
        if getattr(dev, name) < 0.0:
            reset(name, 0.0, "negative")
    if dev.frequency < 0.0:
        reset("frequency", 24.0, "negative")
    return upd


def lens_center_reset(lens: wm.Lens) -> tuple[wm.Lens, list[str]]:
    """A Lens' ``center`` as Webots' WbLens::updateCenter leaves it, and what was changed: a negative
    component 0, an x above 1 set to 1 -- and a y above 1 sets x (not y) to 1, its code's slip, kept
    here so the image is Webots' own."""
    x, y = lens.center
    told = []
    if x < 0.0:
        told.append(f"x {x:g} < 0, set to 0")
        x = 0.0
    if y < 0.0:
        told.append(f"y {y:g} < 0, set to 0")
        y = 0.0
    if x > 1.0:
        told.append(f"x {x:g} > 1, set to 1")
        x = 1.0
    if y > 1.0:
        told.append(f"y {y:g} > 1: Webots sets x (not y) to 1 and keeps y {y:g}, done the same here")
        x = 1.0
    if not told:
        return lens, []
    return lens.model_copy(update={"center": (x, y)}), told


def sanitize(world: wm.World) -> tuple[wm.World, list[str]]:
    """Apply Webots' field sanitising (devices.md §2.1, §3.1, §4.1); return warnings for each change."""
    warnings: list[str] = []

    def fix_light(p: str, lt: Any) -> Any:
        # Webots' resets of a value outside its range (wm.LIGHT_RANGES): WbLight::updateAmbientIntensity,
        # updateIntensity, WbSpotLight::updateCutOffAngle, updateBeamWidth
        if lt.name:
            p = f"{p} ({lt.name})"
        upd: dict[str, Any] = {}

        def outside(field: str) -> bool:
            return wm.light_value_problem(field, getattr(lt, field)) is not None

        def reset(field: str, value: float, shown: str) -> None:
            warnings.append(f"{p}.{field}: {wm.light_value_problem(field, getattr(lt, field))}, reset to {shown}")
            upd[field] = value

        if outside("ambient_intensity"):
            value = 1.0 if lt.ambient_intensity > 1 else 0.0
            reset("ambient_intensity", value, f"{value:g}")
        if outside("intensity"):
            reset("intensity", 1.0, "1")
        amb = upd.get("ambient_intensity", lt.ambient_intensity)
        if isinstance(lt, (wm.PointLight, wm.SpotLight)) and tuple(lt.attenuation) != (1.0, 0.0, 0.0) and amb != 0:
            upd["ambient_intensity"] = 0.0
            warnings.append(f"{p}.ambient_intensity: forced to 0 because attenuation is not 1 0 0 (Webots rule)")
        if isinstance(lt, wm.SpotLight):
            if outside("cut_off_angle"):
                reset("cut_off_angle", math.pi / 2, "pi/2")
            cut = upd.get("cut_off_angle", lt.cut_off_angle)
            if lt.beam_width < 0:
                reset("beam_width", 0.0, "0")
            elif lt.beam_width > cut:
                upd["beam_width"] = cut
                if lt.beam_width != wm.SpotLight.model_fields["beam_width"].default:   # Webots' defaults: silent, as there
                    warnings.append(f"{p}.beam_width: {lt.beam_width} > cut_off_angle, set to {cut}")
        return lt.model_copy(update=upd) if upd else lt

    def fix_device(p: str, dev: Any) -> Any:
        upd: dict[str, Any] = {}
        for name in ("resolution", "speed_resolution"):
            res = getattr(dev, name, -1.0)
            if res <= 0 and res != -1:
                upd[name] = -1.0
                warnings.append(f"{p}.{name}: {res} <= 0, reset to -1 (off)")
        if isinstance(dev, wm.Pen) and not 0.0 <= dev.ink_density <= 1.0:     # WbPen::preFinalize
            upd["ink_density"] = min(max(dev.ink_density, 0.0), 1.0)
            warnings.append(f"{p}.ink_density: {dev.ink_density} outside [0, 1], clamped to {upd['ink_density']}")
        if isinstance(dev, wm.TouchSensor) and dev.type != "bumper":
            warnings.append(f"{p}.type: a {dev.type} TouchSensor needs physics; it reads NaN (Webots' no value)")
        if isinstance(dev, wm.DistanceSensor):
            if dev.type == "infrared":
                upd["type"] = "infra-red"
            if dev.aperture < 0:
                upd["aperture"] = -dev.aperture
                warnings.append(f"{p}.aperture: negative, using its absolute value")
            if dev.number_of_rays < 1:
                upd["number_of_rays"] = 1
                warnings.append(f"{p}.number_of_rays: < 1, reset to 1")
            if dev.gaussian_width <= 0:
                upd["gaussian_width"] = 1.0
                warnings.append(f"{p}.gaussian_width: <= 0, reset to 1")
            if dev.red_color_sensitivity < 0:
                upd["red_color_sensitivity"] = -dev.red_color_sensitivity
                warnings.append(f"{p}.red_color_sensitivity: negative, using its absolute value")
            if dev.type == "laser" and upd.get("number_of_rays", dev.number_of_rays) > 1:
                upd["number_of_rays"] = 1
                warnings.append(f"{p}.number_of_rays: a laser sensor has a single ray, reset to 1")
        # WbRangeFinder's and WbLidar's updateNear, updateMinRange, updateMaxRange
        if isinstance(dev, (wm.RangeFinder, wm.Lidar)):
            if dev.near > dev.min_range:
                upd["near"] = dev.min_range
                warnings.append(f"{p}.near: greater than min_range, set to min_range {dev.min_range}")
            if dev.max_range <= dev.min_range:
                upd["max_range"] = dev.min_range + 1.0
                warnings.append(f"{p}.max_range: not greater than min_range, set to min_range + 1")
        if isinstance(dev, wm.Lidar):
            if not 0.0 < dev.vertical_field_of_view <= math.pi:
                upd["vertical_field_of_view"] = min(max(dev.vertical_field_of_view, 1e-6), math.pi)
                warnings.append(f"{p}.vertical_field_of_view: outside (0, pi], clamped")
            lo, hi = dev.min_frequency, dev.max_frequency
            if lo > hi:
                upd["min_frequency"], upd["max_frequency"] = hi, lo
                lo, hi = hi, lo
                warnings.append(f"{p}.min_frequency/max_frequency: swapped to be ordered")
            if not lo <= dev.default_frequency <= hi:
                upd["default_frequency"] = min(max(dev.default_frequency, lo), hi)
                warnings.append(f"{p}.default_frequency: outside [min_frequency, max_frequency], clamped")
        if isinstance(dev, (wm.Camera, wm.RangeFinder)) and dev.lens is not None:
            lens, lens_warnings = lens_center_reset(dev.lens)
            warnings.extend(f"{p}.lens.center: {w}" for w in lens_warnings)
            if lens is not dev.lens:
                upd["lens"] = lens
        if isinstance(dev, wm.LED) and dev.lights:
            upd["lights"] = [fix_light(f"{p}.lights[{i}]", lt) for i, lt in enumerate(dev.lights)]
        if isinstance(dev, wm.Radar):
            upd.update(_radar_resets(p, dev, warnings))
        return dev.model_copy(update=upd) if upd else dev

    def fix_solid(p: str, solid: wm.Solid) -> wm.Solid:
        if not solid.lights and not solid.children:
            return solid
        lights = [fix_light(f"{p}.lights[{i}]", lt) for i, lt in enumerate(solid.lights)]
        children = [fix_solid(f"{p}.children[{i}]", c) for i, c in enumerate(solid.children)]
        return solid.model_copy(update={"lights": lights, "children": children})

    lights = [fix_light(f"lights[{i}]", lt) for i, lt in enumerate(world.lights)]
    solids = [fix_solid(f"solids[{i}]", s) for i, s in enumerate(world.solids)]
    robots = []
    for r_i, robot in enumerate(world.robots):
        devices = [fix_device(f"robots[{r_i}].devices[{d_i}]", d) for d_i, d in enumerate(robot.devices)]
        devices = _coupled_resets(f"robots[{r_i}]", robot, devices, warnings)
        r_lights = [fix_light(f"robots[{r_i}].lights[{i}]", lt) for i, lt in enumerate(robot.lights)]
        robots.append(robot.model_copy(update={"devices": devices, "lights": r_lights}))
    return world.model_copy(update={"lights": lights, "solids": solids, "robots": robots}), warnings


def _coupled_resets(rp: str, robot: wm.Robot, devices: list[Any], warnings: list[str]) -> list[Any]:
    """Webots' checks of coupled motors as a robot loads (WbMotor::updateMultiplier,
    inferMotorCouplings, checkMinAndMaxPositionAcrossCoupledMotors, checkMaxVelocityAcrossCoupledMotors):
    a multiplier of 0 is reset to 1; in each group of joint motors named ``group::...`` the first in
    device order sets the others' limits (its own scaled by the ratio of multipliers, ordered; none if
    it has none) and maximum velocities (scaled by the ratio of the multipliers' magnitudes), each
    change said; a ``group::part`` motor alone in its group is said. A drive's motors are no joints
    and couple with nothing here."""
    drive = {m for _, m in robot.drive_motors}
    out = list(devices)
    groups: dict[str, list[int]] = {}
    for d_i, dev in enumerate(out):
        if not isinstance(dev, wm.Motor) or dev.name in drive:
            continue
        if dev.multiplier == 0.0:
            warnings.append(f"{rp}.devices[{d_i}].multiplier: 0, reset to 1 (Webots: it cannot be 0)")
            out[d_i] = dev = dev.model_copy(update={"multiplier": 1.0})
        group = wm.coupling_group(dev.name)
        if group is not None:
            groups.setdefault(group, []).append(d_i)
    for group, members in groups.items():
        if len(members) == 1:
            warnings.append(f"{rp}.devices[{members[0]}] ({out[members[0]].name}): uses the coupled motor name "
                            f"structure ('{group}::...') but has no sibling: not coupled")
            continue
        ref = out[members[0]]
        limited = ref.min_position != ref.max_position
        for d_i in members[1:]:
            dev = out[d_i]
            p = f"{rp}.devices[{d_i}] ({dev.name})"
            upd: dict[str, Any] = {}
            if limited:
                lo = ref.min_position * dev.multiplier / ref.multiplier
                hi = ref.max_position * dev.multiplier / ref.multiplier
                lo, hi = min(lo, hi), max(lo, hi)
            else:
                lo = hi = 0.0
            for key, value in (("min_position", lo), ("max_position", hi)):
                if getattr(dev, key) != value:
                    upd[key] = value
                    warnings.append(f"{p}.{key}: coupled with {ref.name!r}, whose limits set its own: "
                                    f"{getattr(dev, key):g} set to {value:g}")
            velocity = ref.max_velocity * abs(dev.multiplier) / abs(ref.multiplier)
            if dev.max_velocity != velocity:
                upd["max_velocity"] = velocity
                warnings.append(f"{p}.max_velocity: coupled with {ref.name!r}, whose maximum velocity sets its own: "
                                f"{dev.max_velocity:g} set to {velocity:g}")
            if upd:
                out[d_i] = dev.model_copy(update=upd)
    return out
