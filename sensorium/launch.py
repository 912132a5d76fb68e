"""``sensorium run``: open a Webots project headless, the way Webots does: serve the world and start
every robot's controller named in it, print their output with the robot's name, restart them on
``restartController``, reload the world on ``worldReload`` (load another on ``worldLoad``), end them all
at the end.

Where a controller is found, as Webots' WbController does for a project: ``controllers/NAME/`` next to
the world's ``worlds/`` folder (then the robot's PROTO's project, for a PROTO the world declares by
a file path; then each ``--controllers-dir``, then each extra project's
``controllers/NAME/``: ``$WEBOTS_EXTRA_PROJECT_PATH``, ``--extra-project-path``); in that folder the first of
``Dockerfile``, ``NAME`` (an executable), ``build/release/NAME``, ``NAME.class``, ``NAME.jar``,
``NAME.py``, ``NAME.m``, ``NAME.bsg``. Python and executables run (as ``sensorium controller`` runs
them: the controller's folder as working directory, ``controllerArgs`` as arguments, the URL in the
environment); the others are refused with one line. With ``--webots-home`` (or ``$WEBOTS_HOME``) a
controller not found there is looked for in Webots' own projects (:class:`WebotsProjects`).
"""

from __future__ import annotations

import codecs
import dataclasses
import os
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import IO, Any
from urllib.parse import quote

from sensorium import runtime_ini
from sensorium.runtime_ini import RuntimeIni

__all__ = ["ControllerSpec", "LaunchError", "Launcher", "ProjectRun", "RunOptions", "WebotsProjects", "WorldPlan",
           "after_run", "exit_status", "find_controller", "plan", "plan_world", "proto_projects", "robot_protos",
           "run_project"]

WEBOTS_DEPTH = 6         # folders under a Webots installation's projects/ where controllers/ folders are looked for
WEBOTS_MAX_DIRS = 20000  # folders of that tree indexed at most
EXTRA_ENV = "WEBOTS_EXTRA_PROJECT_PATH"   # Webots' extra project folders (each with controllers/, protos/)
LIBRARIES_MAX = 256      # folders of a project's libraries/ put on a controller's library path at most
EXTRA_MAX = 64           # extra project folders read at most (each costs one look-up per controller)
WEBOTS_SKIP = frozenset({"protos", "worlds", "plugins", "libraries", "textures", "meshes", "icons", "docs", "build"})
# Webots' WbController: a controller gets the quit packet (-1), then 1 s to end before it is terminated
GRACE_S = 1.0
ROBOT_WINDOW_ENV = "SENSORIUM_ROBOT_WINDOW_LOG"   # "1": the clients print robot-window text on stderr
CURVE_ENV = "SENSORIUM_CURVE_SERVERKEY"    # the clients' CURVE server key (sensorium.client.connection)
LINE_MAX = 1 << 16       # bytes of a controller's line printed at once
# seconds a controller's output is read on after its process ended: what it wrote is in the pipe by then; a
# process it started that holds the pipe and is out of its process group (a daemon) is not waited for
DRAIN_S = 2.0
# seconds after which a started controller that has not attached is said to be waited for (without --attach-timeout)
ATTACH_NOTE_S = 10.0
C_LIBRARY = Path(__file__).resolve().parent / "client" / "c" / "build"
SPECIAL = ("<extern>", "<none>", "<generic>")
# the kinds Webots runs that Sensorium does not (file in the controller's folder -> what it is)
UNSUPPORTED = {"Dockerfile": "a Docker controller", ".class": "a Java controller", ".jar": "a Java controller",
               ".m": "a MATLAB controller", ".bsg": "a BotStudio controller"}


class LaunchError(Exception):
    """A controller that cannot be started: one line for the user."""


@dataclass(frozen=True)
class ControllerSpec:
    robot: str
    name: str                  # the world's controller field
    folder: Path               # controllers/NAME: the working directory
    program: Path              # NAME.py or the executable
    python: bool
    args: tuple[str, ...] = ()
    webots: bool = False       # found in Webots' own projects (--webots-home)
    runtime: RuntimeIni | None = None      # its folder's runtime.ini (environment variables, [python] COMMAND)
    notes: tuple[str, ...] = ()            # lines to say about it when the world starts
    libraries: tuple[Path, ...] = ()       # the projects' libraries/ folders, for its library path

    def said(self) -> tuple[str, ...]:
        """What ``run`` says of it before starting it: where Webots' own copy was found, its notes
        (runtime.ini's, a library folder left off): at load and when a Supervisor switches to it."""
        found = (f"robot '{self.robot}': controller '{self.name}' found in Webots' projects: {self.program}",)
        return (*(found if self.webots else ()), *self.notes)


def controller_dirs(world: Path, extra: list[Path], projects: Sequence[Path] = ()) -> list[Path]:
    """Where controllers are looked for: the project's ``controllers/`` (the world's folder's parent),
    then ``--controllers-dir`` folders in their order, then each extra project's ``controllers/``."""
    return [world.resolve().parent.parent / "controllers", *(Path(d).resolve() for d in extra),
            *(Path(p).resolve() / "controllers" for p in projects)]


def extra_project_paths(value: str | None, limit: int | None = EXTRA_MAX) -> list[Path]:
    """Webots' extra project paths from ``value`` (``$WEBOTS_EXTRA_PROJECT_PATH``: folders separated
    like ``PATH``, so a folder with ``:`` in its name cannot be one, as in Webots; empty entries are
    none), in their order, each once, at most ``limit`` (None: all)."""
    paths = list(dict.fromkeys(Path(p).expanduser().absolute() for p in (value or "").split(os.pathsep) if p))
    return paths if limit is None else paths[:limit]


class WebotsProjects:
    """The ``controllers/NAME/`` folders of a Webots installation's own projects (``--webots-home``,
    else ``$WEBOTS_HOME``), as Webots finds a stock controller for a world that names one: its
    default project (``resources/projects/controllers``) first, then every project under
    ``projects/`` (a robot's PROTO's project among them). The ``projects`` tree is indexed once, on
    the first look-up, at most :data:`WEBOTS_DEPTH` folders deep and :data:`WEBOTS_MAX_DIRS` folders
    in all."""

    def __init__(self, home: Path):
        home = Path(home).resolve()
        self.home = home / "Contents" if (home / "Contents" / "projects").is_dir() else home   # a macOS Webots.app
        self._index: dict[str, list[Path]] | None = None
        self.truncated = False

    def _build(self) -> dict[str, list[Path]]:
        index: dict[str, list[Path]] = {}
        stack = [(self.home / "projects", 0)]
        visited = 0
        while stack:
            folder, depth = stack.pop()
            try:
                entries = sorted((e for e in os.scandir(folder) if e.is_dir(follow_symlinks=False)), key=lambda e: e.name)
            except OSError:
                continue
            visited += 1
            if visited > WEBOTS_MAX_DIRS:
                self.truncated = True
                break
            for e in entries:
                if e.name == "controllers":
                    try:
                        names = sorted(c.name for c in os.scandir(e.path) if c.is_dir())
                    except OSError:
                        continue
                    for n in names:
                        index.setdefault(n, []).append(Path(e.path) / n)
                elif depth + 1 < WEBOTS_DEPTH and not e.name.startswith(".") and e.name not in WEBOTS_SKIP:
                    stack.append((Path(e.path), depth + 1))
        for paths in index.values():
            paths.sort()
        return index

    def find(self, name: str) -> list[Path]:
        """The folders named ``name`` in Webots' controllers folders (the default project's alone
        when it has one)."""
        default = self.home / "resources" / "projects" / "controllers" / name
        if default.is_dir():
            return [default]
        if self._index is None:
            self._index = self._build()
        return list(self._index.get(name, []))

    def where(self) -> str:
        return f"{self.home / 'projects'}" + (f" (indexed only its first {WEBOTS_MAX_DIRS} folders)" if self.truncated else "")


def _has_proto(project: Path, proto: str | None) -> bool:
    """Does ``project`` (a folder holding ``controllers/``) define the PROTO ``proto`` (in its
    ``protos/`` folder or 2 folders below)?"""
    if not proto or not proto.replace("_", "").replace("-", "").isalnum():
        return False
    base = project / "protos"
    return any(any(base.glob(f"{pattern}{proto}.proto")) for pattern in ("", "*/", "*/*/"))


def _in_folder(robot: str, name: str, args: list[str], folder: Path) -> ControllerSpec:
    """The controller in its folder, by Webots' order of files, or LaunchError."""
    candidates: list[tuple[str, Path]] = [
        ("Dockerfile", folder / "Dockerfile"), ("exe", folder / name), ("exe", folder / "build" / "release" / name),
        (".class", folder / f"{name}.class"), (".jar", folder / f"{name}.jar"), ("py", folder / f"{name}.py"),
        (".m", folder / f"{name}.m"), (".bsg", folder / f"{name}.bsg")]
    for kind, path in candidates:
        if not path.is_file():
            continue
        if kind == "exe" and not os.access(path, os.X_OK):
            raise LaunchError(f"robot {robot!r}: controller {path} is not executable (chmod +x)")
        if kind in ("py", "exe"):
            ini, notes = _runtime_ini(robot, folder)
            return ControllerSpec(robot, name, folder, path, kind == "py", tuple(args), runtime=ini, notes=notes)
        raise LaunchError(f"robot {robot!r}: controller {path} is {UNSUPPORTED[kind]}, which Sensorium does not "
                          "run (Python controllers and executables run; start it as an <extern> controller)")
    hint = ""
    if (folder / f"{name}.c").is_file() or (folder / f"{name}.cpp").is_file():
        hint = " (its C/C++ source is there: compile it against sensorium/client/c)"
    raise LaunchError(f"robot {robot!r}: controller {name!r}: {folder} has none of {name}, {name}.py "
                      f"(nor {name}.class, .jar, .m, .bsg, Dockerfile){hint}")


def _runtime_ini(robot: str, folder: Path) -> tuple[RuntimeIni | None, tuple[str, ...]]:
    """The folder's runtime.ini and the lines to say about it (a file Webots would not read is one
    line, and the controller starts without it, as Webots' does)."""
    try:
        ini = runtime_ini.read(folder)
    except runtime_ini.RuntimeIniError as exc:
        return None, (f"robot '{robot}': {exc}; the controller starts without it",)
    if ini is None:
        return None, ()
    try:          # its $(...) references replaced against this environment: too long is said now
        runtime_ini.environment(ini, os.environ)
        ini.python("COMMAND", os.environ)
        ini.python("OPTIONS", os.environ)
    except runtime_ini.RuntimeIniError as exc:
        return None, (f"robot '{robot}': {exc}; the controller starts without it",)
    return ini, tuple(f"robot '{robot}': {folder / runtime_ini.FILE}: {line}" for line in ini.notes())


def find_controller(robot: str, name: str, args: list[str], dirs: list[Path], webots: WebotsProjects | None = None,
                    proto: str | None = None) -> ControllerSpec:
    """The controller ``name`` of ``robot`` in the first of ``dirs`` that has a ``NAME/`` folder, else
    in Webots' own projects (``webots``; where several have it, the one that defines the robot's
    PROTO ``proto``, as Webots looks in the PROTO's project), by Webots' order of files. Raises
    LaunchError naming where it looked or what is not supported, or a ``name`` that is not one
    folder's name (so a world cannot make ``run`` start a program outside the folders it looks in)."""
    problem = name_problem(name)
    if problem:
        raise LaunchError(f"robot {robot!r}: controller {name!r} {problem}: not looked for (a controller is named "
                          "by its folder in a controllers/ folder)")
    for base in dirs:
        folder = base / name
        if folder.is_dir():
            return _in_folder(robot, name, args, folder)
    looked = ", ".join(str(d / name) for d in dirs)
    if webots is None:
        raise LaunchError(f"robot {robot!r}: controller {name!r} not found (looked for the folder {looked}; "
                          "--webots-home DIR also looks in Webots' own projects)")
    found = webots.find(name)
    if len(found) > 1:
        own = [f for f in found if _has_proto(f.parent.parent, proto)]
        if len(own) == 1:
            found = own
        else:
            raise LaunchError(f"robot {robot!r}: controller {name!r} is in several of Webots' projects ("
                              f"{', '.join(str(f) for f in found)}): give the one to use with --controllers-dir "
                              "(its controllers/ folder)")
    if not found:
        raise LaunchError(f"robot {robot!r}: controller {name!r} not found (looked for the folder {looked}, and "
                          f"in Webots' projects under {webots.where()})")
    spec = _in_folder(robot, name, args, found[0])
    return dataclasses.replace(spec, webots=True)


def name_problem(name: str) -> str | None:
    """What makes ``name`` no controller folder's name (None when it is one): empty, ``.``/``..``,
    a path separator or a NUL byte in it."""
    if name in ("", ".", ".."):
        return "is no folder name" if name else "is empty"
    for bad in dict.fromkeys(("/", os.sep, *([os.altsep] if os.altsep else []))):
        if bad in name:
            return f"has a {bad!r} in it"
    return "has a NUL byte in it" if "\0" in name else None


def robot_protos(world: Any) -> dict[str, str]:
    """Each robot that is a top-level PROTO instance of a ``.wbt`` world (Webots looks for its
    controller in the PROTO's project too): robot name -> PROTO name."""
    out: dict[str, str] = {}
    robots = list(getattr(world, "robots", []))
    i = 0
    for node in getattr(world, "top_nodes", None) or []:
        if node.robots == 1 and node.proto and i < len(robots):
            out[robots[i].name] = node.proto
        i += node.robots
    return out


_EXTERNPROTO = re.compile(r'^[ \t]*(?:IMPORTABLE[ \t]+)?EXTERNPROTO[ \t]+"([^"\n]+)"', re.MULTILINE)


def proto_projects(world: Path, text: str, protos: dict[str, str]) -> dict[str, Path]:
    """Each robot whose PROTO (``protos``: robot -> PROTO name) the ``.wbt`` world ``text`` declares
    by a file path (relative to the world's folder, or absolute; not ``webots://`` nor ``https://``)
    -> that PROTO's project: the folder above the nearest ``protos`` folder holding the file, where
    Webots looks for the robot's controller right after the world's own project."""
    files: dict[str, Path] = {}
    for url in _EXTERNPROTO.findall(text):
        if "://" in url or not url.endswith(".proto"):
            continue
        path = Path(os.path.normpath(world.resolve().parent / url))      # the url's own "..", as Webots reads it
        files.setdefault(path.stem, path)
    out: dict[str, Path] = {}
    for robot, proto in protos.items():
        file = files.get(proto)
        if file is None:
            continue
        for folder in file.parents:
            if folder.name == "protos":
                out[robot] = folder.parent
                break
    return out


def plan(robots: list[Any], dirs: list[Path], webots: WebotsProjects | None = None,
         protos: dict[str, str] | None = None,
         projects: dict[str, Path] | None = None) -> tuple[list[ControllerSpec], list[str]]:
    """The controllers to start for the world's robots, and every problem (one line each).
    ``projects``: a robot's PROTO's project (:func:`proto_projects`), looked in right after the
    world's own (``dirs[0]``), as Webots does."""
    specs, problems = [], []
    for r in robots:
        if r.controller in SPECIAL:
            continue
        try:
            specs.append(robot_controller(r.name, r.controller, list(r.controller_args), dirs, webots, protos, projects))
        except LaunchError as exc:
            problems.append(str(exc))
    return specs, problems


def robot_controller(robot: str, name: str, args: list[str], dirs: list[Path], webots: WebotsProjects | None = None,
                     protos: dict[str, str] | None = None, projects: dict[str, Path] | None = None) -> ControllerSpec:
    """The controller ``name`` of ``robot`` as :func:`plan` finds it (the robot's PROTO's project right
    after the world's own), with the projects' libraries; LaunchError (one line) when it is not found."""
    own = (projects or {}).get(robot)
    robot_dirs = list(dict.fromkeys([dirs[0], own / "controllers", *dirs[1:]])) if own is not None and dirs else dirs
    spec = find_controller(robot, name, args, robot_dirs, webots, (protos or {}).get(robot))
    roots = [dirs[0].parent] if dirs else []
    spec = dataclasses.replace(spec, libraries=library_folders([*roots, *([own] if own else [])]))
    unlisted = [p for p in (*spec.libraries, spec.folder) if not _listable(p)]
    if unlisted:
        more = f" and {len(unlisted) - 1} more folder{'s' if len(unlisted) > 2 else ''}" if len(unlisted) > 1 else ""
        spec = dataclasses.replace(spec, notes=(*spec.notes, (
            f"robot '{robot}': {unlisted[0]}{more} left off the controller's library path: a '{os.pathsep}' in a "
            f"folder's path would split it in two there (LD_LIBRARY_PATH's separator), so a shared library in it "
            "is not found")))
    return spec


def _listable(path: Path) -> bool:
    """Can ``path`` be an entry of a ``PATH``-like list (no ``os.pathsep`` in it)? Webots puts a
    folder with a ``:`` on a controller's library path all the same, where it reads as two folders,
    the second relative to the controller's folder."""
    return os.pathsep not in str(path)


def library_folders(projects: list[Path]) -> tuple[Path, ...]:
    """The folders of each project's ``libraries/`` (at most :data:`LIBRARIES_MAX` of each, by name),
    which Webots puts on a controller's library path: the world's project, then the robot's
    PROTO's."""
    out: list[Path] = []
    for project in projects:
        try:
            names = sorted(e.name for e in os.scandir(project / "libraries") if e.is_dir())
        except OSError:
            continue
        out.extend(project / "libraries" / n for n in names[:LIBRARIES_MAX])
    return tuple(dict.fromkeys(out))


@dataclass(frozen=True)
class WorldPlan:
    """What ``run`` does with one load of a world: the controllers to start, the problems (one line
    each) and the robots they leave without a controller, the lines to say when it starts, and
    which robots the world waits for without a controller of ours (as Webots waits for a
    synchronous ``<extern>`` one)."""

    specs: tuple[ControllerSpec, ...]
    problems: tuple[str, ...]
    notes: tuple[str, ...]
    extern_waited: frozenset[str]          # synchronous <extern> robots: waited for until attached
    extern_synchronous: tuple[str, ...]    # robots waited for while none of them is attached
    missing: tuple[tuple[str, str], ...] = ()   # (robot, controller) of each problem: it runs without one


@dataclass(frozen=True)
class _Robot:
    """A robot as ``run`` sees it: its controller as Webots reads the world."""

    name: str
    controller: str
    controller_args: tuple[str, ...]
    synchronization: bool
    default: bool = False          # no controller field in the .wbt: Webots' default, <generic>


def _as_webots(robot: Any, wbt: bool) -> _Robot:
    """``robot`` with Webots' default controller when a ``.wbt`` world gives it none: ``<generic>``
    (Sensorium's loader makes such a robot ``<extern>``, what ``serve`` waits for)."""
    given = getattr(robot, "model_fields_set", None)
    default = wbt and given is not None and "controller" not in given
    return _Robot(robot.name, "<generic>" if default else robot.controller, tuple(robot.controller_args),
                  bool(robot.synchronization), default)


def plan_world(robots: list[Any], dirs: list[Path], rpc_url: str, webots: WebotsProjects | None = None,
               protos: dict[str, str] | None = None, wbt: bool = False,
               projects: dict[str, Path] | None = None) -> WorldPlan:
    """The plan for ``robots`` (a loaded world's: ``name``, ``controller``, ``controller_args``,
    ``synchronization``) served at ``rpc_url``; no process is started. ``wbt``: the world is a
    ``.wbt`` file, where a robot without a ``controller`` field has Webots' ``<generic>``;
    ``projects``: robots' PROTO projects (:func:`proto_projects`)."""
    robots = [_as_webots(r, wbt) for r in robots]
    specs, problems = plan(robots, dirs, webots, protos, projects)
    started = {s.robot for s in specs}
    missing = tuple((r.name, r.controller) for r in robots if r.controller not in SPECIAL and r.name not in started)
    notes = [line for s in specs for line in s.said()]
    for r in robots:
        if r.controller == "<generic>":
            which = "no controller field, so Webots' default '<generic>'" if r.default else "controller '<generic>'"
            notes.append(f"robot '{r.name}': {which} (Webots' one only steps): the robot runs without a controller")
        elif r.controller == "<extern>":
            notes.append(f"robot '{r.name}' is <extern>: attach its controller with `sensorium controller SCRIPT "
                         f"--robot {r.name} --url {rpc_url}`")
    # as Webots, the world waits for every synchronous <extern> robot's controller too (while none is
    # attached); a robot whose controller ended, could not be found, or is <generic> is uncontrolled:
    # the world goes on without it, as Webots' goes on with its generic controller stepping
    return WorldPlan(tuple(specs), tuple(problems), tuple(notes),
                     frozenset(r.name for r in robots if r.controller == "<extern>" and r.synchronization),
                     tuple(r.name for r in robots if r.controller == "<extern>" and r.synchronization), missing)


def after_run(reload_requested: bool, interrupted: bool, quit_status: int | None) -> bool:
    """Whether the world is loaded again once its server stopped: only for a ``worldReload``, not
    when the run was interrupted (Ctrl-C, SIGTERM, :meth:`ProjectRun.stop`) or quit
    (``simulationQuit``) meanwhile; ``--until`` stops without a reload request."""
    return reload_requested and not interrupted and quit_status is None


def exit_status(quit_status: int | None, missing: bool = False, load_refused: bool = False) -> int:
    """``run``'s exit status: ``simulationQuit(status)``'s low 8 bits, as Webots exits, when not 0;
    else 1 when a robot ran without the controller its world names (``missing``: a CI job must not
    pass by a run that was not the one its world describes) or a ``worldLoad`` named no world it could
    load (``load_refused``); else 0."""
    status = 0 if quit_status is None else quit_status & 0xFF
    return status or (1 if missing or load_refused else 0)


WORLD_SUFFIXES = (".wbt", ".yaml", ".yml", ".json")    # the world files `run` loads (Webots': .wbt only)


def _one_line(value: object) -> str:
    """A path (or an OS error naming one) as text on one line: a control character a file name may hold
    (a newline from a Supervisor's worldLoad argument) written as its escape, so the refusal stays one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(value))


def world_to_load(filename: str, folder: Path | None, worlds: Path) -> Path:
    """The world file a Supervisor's ``worldLoad(filename)`` names: relative to its controller's
    ``folder``, as Webots takes it (None: a controller ``run`` did not start, which has none here),
    symbolic links followed; it must lie in ``worlds``, the folder of the world ``run`` was started
    with (a world from elsewhere would start the controllers of another project), exist and be a
    world file. Raises :class:`LaunchError` saying why (one line)."""
    if not filename or "\0" in filename:
        raise LaunchError("no file named" if not filename else "a NUL byte in the file name")
    path = Path(filename)
    if not path.is_absolute():
        if folder is None:
            raise LaunchError("a relative name is taken from the controller's folder, and this robot's controller "
                              "was not started by `sensorium run`: give the world file's absolute path")
        path = folder / path
    try:
        resolved = path.resolve()
    except (OSError, RuntimeError) as exc:          # a symbolic link loop
        raise LaunchError(f"{_one_line(path)} cannot be resolved: {_one_line(exc)}") from None
    root = worlds.resolve()
    if not resolved.is_relative_to(root):
        raise LaunchError(f"{_one_line(resolved)} is outside {_one_line(root)}, the folder of the world `sensorium run` "
                          "started with (a world from elsewhere would start another project's controllers)")
    try:
        found = resolved.is_file()
    except OSError as exc:               # a folder on the way that may not be read
        raise LaunchError(f"{_one_line(resolved)} cannot be read: {_one_line(exc.strerror or exc)}") from None
    if not found:
        raise LaunchError(f"no world file {_one_line(resolved)}")
    if resolved.suffix.lower() not in WORLD_SUFFIXES:
        raise LaunchError(f"{_one_line(resolved)} is not a world file (.wbt; YAML or JSON: .yaml, .yml, .json)")
    return resolved


def _describe(code: int) -> str:
    """Webots' words for a controller's end."""
    if code == 0:
        return "exited successfully."
    if code < 0:
        try:
            sig = signal.Signals(-code).name
        except ValueError:
            sig = f"signal {-code}"
        return f"crashed ({sig})."
    return f"exited with status: {code}."


def _print_line(text: str, sink: IO[str]) -> None:
    """``text`` on ``sink``; what its encoding cannot write (a controller's bytes on a terminal that is
    not UTF-8) as ``?``, not an error that would end the robot's output."""
    try:
        print(text, file=sink, flush=True)
    except UnicodeEncodeError:
        encoding = getattr(sink, "encoding", None) or "ascii"
        print(text.encode(encoding, errors="replace").decode(encoding, errors="replace"), file=sink, flush=True)


@dataclass
class _Running:
    spec: ControllerSpec
    proc: subprocess.Popen
    readers: list[threading.Thread] = field(default_factory=list)
    ending: bool = False       # ended by us (restart, reload, quit): no "exited" line of its own
    said_held: bool = False    # its pipes outlived its process group: said once
    said_end: bool = False     # its "exited" line said (by the watcher or, at the run's end, by _end)


class Launcher:
    """Start, watch, restart and end the controller processes of one ``sensorium run``.

    ``url`` is the server's RPC endpoint; each controller gets ``url/ROBOT`` in
    ``SENSORIUM_CONTROLLER_URL`` (and ``serverkey``, the server's CURVE public key, in
    ``SENSORIUM_CURVE_SERVERKEY``). ``out``/``err`` receive the controllers' lines, ``[ROBOT] line``,
    and the launcher's own lines (``log``). Thread-safe: ``restart`` and ``reload`` are called from
    the server's loop thread and only queue work."""

    def __init__(self, specs: list[ControllerSpec], url: str, *, out: IO[str] | None = None,
                 err: IO[str] | None = None, grace_s: float = GRACE_S, serverkey: str | None = None,
                 attach_timeout_s: float | None = None, robot_window_log: bool = False):
        self.specs = {s.robot: s for s in specs}
        self.robot_window_log = robot_window_log   # controllers print their robot-window text (ROBOT_WINDOW_ENV)
        self.attach_timeout_s = attach_timeout_s   # None: wait for a started controller to attach, as Webots
        self.url = url
        self.serverkey = serverkey        # the server's CURVE public key (Z85), None for a plain one
        self.out = out or sys.stdout
        self.err = err or sys.stderr
        self.grace_s = grace_s
        self.running: dict[str, _Running] = {}
        self.starts: dict[str, int] = {s.robot: 0 for s in specs}
        self._lock = threading.Lock()            # running, starts
        self._print_lock = threading.Lock()
        self._restarts: list[tuple[str, bool]] = []     # (robot, its controller field changed)
        self._wake = threading.Event()
        self._closed = False
        self.reload_requested = False
        self.world_requested: Path | None = None     # worldLoad's world (None: worldReload's, the same file)
        self.worlds: Path | None = None               # where worldLoad may load from (run's first world's folder)
        self.load_refused = False                     # a worldLoad named no world to load: the run ended (exit 1)
        self.stop_server: Callable[[], None] | None = None     # the server stops (run's loop then reloads or ends)
        # (robot, controller name) -> the controller to start (run's find_controller for this world), or LaunchError
        self.find: Callable[[str, str], ControllerSpec] | None = None
        self._starting: set[str] = set()         # the lockstep's: the world waits until these attach
        self.failed: dict[str, str] = {}          # robot -> controller whose process could not be started
        self._wake_server: Callable[[], None] = lambda: None
        self._exited: dict[str, float] = {}
        self._quitting: Callable[[], bool] = lambda: False
        self._worker = threading.Thread(target=self._work, name="sensorium-launcher", daemon=True)
        self._worker.start()

    def bind(self, starting: set[str], wake: Callable[[], None], quitting: Callable[[], bool],
             exited: dict[str, float] | None = None) -> None:
        """Serve this server (again after a reload): ``starting`` is its lockstep's set of robots
        whose controller was started and has not attached (the world waits for them), ``wake``
        makes its loop look again, ``quitting`` says it is ending (no "exited" lines then),
        ``exited`` its lockstep's robots whose controller process ended by itself, and when
        (``time.monotonic``, the server's clock): their sessions are dropped at once."""
        self._starting, self._wake_server, self._quitting = starting, wake, quitting
        self._exited = exited if exited is not None else {}

    # ------------------------------------------------------------------ output
    def log(self, text: str) -> None:
        with self._print_lock:
            print(f"sensorium run: {text}", file=self.err, flush=True)

    def _pump(self, robot: str, stream: IO[bytes], sink: IO[str]) -> None:
        """Each line of a controller's stream as ``[ROBOT] line`` (Webots' console names the robot);
        a last line without a newline is printed too."""
        sink_open = True
        decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")    # a character cut between pieces
        for raw in iter(lambda: stream.readline(LINE_MAX), b""):      # a longer line comes in pieces
            if not sink_open:
                continue            # read on all the same: a controller blocked on a full pipe would stall the world
            line = decoder.decode(raw, final=raw.endswith(b"\n")).rstrip("\r\n")
            try:
                with self._print_lock:
                    _print_line(f"[{robot}] {line}", sink)
            except (BrokenPipeError, ValueError, OSError):        # `sensorium run | head`: the reader left
                sink_open = False
        stream.close()

    # ------------------------------------------------------------------ processes
    @staticmethod
    def command(spec: ControllerSpec, base: Mapping[str, str] | None = None) -> list[str]:
        """The controller's command line: a Python one as `sensorium controller` runs it (`controller`
        importable, its folder as cwd), with runtime.ini's [python] COMMAND and OPTIONS as Webots
        takes them, their ``$(NAME)`` replaced against ``base`` (this process's environment) and the
        file's entries before them (else this interpreter); an executable as itself."""
        if spec.python:
            ini = spec.runtime
            # as Webots resolves them: its environment, the robot's name already in it
            env = {**(os.environ if base is None else base), "WEBOTS_ROBOT_NAME": spec.robot}
            try:
                python = (ini.python("COMMAND", env) if ini else None) or sys.executable
                options = ini.python_options(env) if ini else []
            except runtime_ini.RuntimeIniError:      # checked when planned; the environment grew since
                python = (ini.python("COMMAND") if ini else None) or sys.executable
                options = ini.python_options() if ini else []
            return [python, *options, "-m", "sensorium", "controller", str(spec.program), "--", *spec.args]
        return [str(spec.program), *spec.args]

    def environment(self, spec: ControllerSpec, base: dict[str, str] | None = None) -> dict[str, str]:
        """The controller's environment: ``base`` (this process's), its runtime.ini's variables, then
        what it needs here: the URL, Webots' variables, Sensorium on the Python and library paths."""
        env = dict(os.environ if base is None else base)
        env["WEBOTS_ROBOT_NAME"] = spec.robot     # Webots sets it before it reads runtime.ini: $(WEBOTS_ROBOT_NAME) there
        if spec.runtime is not None:
            try:
                env = runtime_ini.environment(spec.runtime, env)
            except runtime_ini.RuntimeIniError as exc:       # checked when planned; the environment changed since
                self.log(f"robot '{spec.robot}': {exc}; the controller starts without it")
        env["SENSORIUM_CONTROLLER_URL"] = f"{self.url.rstrip('/')}/{quote(spec.robot, safe='')}"   # both clients decode it
        env.pop("WEBOTS_CONTROLLER_URL", None)
        # the server's CURVE key, or none: a key from this shell or a runtime.ini would make it fail to attach
        if self.serverkey:
            env[CURVE_ENV] = self.serverkey
        else:
            env.pop(CURVE_ENV, None)
        env["WEBOTS_ROBOT_NAME"] = spec.robot     # as Webots sets it for every controller it starts
        env["PYTHONUNBUFFERED"] = "1"            # lines reach the console as they are printed
        if self.robot_window_log:
            env[ROBOT_WINDOW_ENV] = "1"
        env["PYTHONIOENCODING"] = "UTF-8"        # as Webots sets it
        package_root = str(Path(__file__).resolve().parent.parent)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (package_root, env.get("PYTHONPATH", "")) if p)
        # as Webots: the project's libraries/ folders, WEBOTS_LIBRARY_PATH, the controller's folder (a shared
        # library shipped next to the controller loads) first on the library path, then our libController
        # (a folder with the list's separator in its path is left off: robot_controller says so)
        libraries = [*(str(p) for p in spec.libraries if _listable(p)), env.get("WEBOTS_LIBRARY_PATH", ""),
                     *([str(spec.folder)] if _listable(spec.folder) else []),
                     *([str(C_LIBRARY)] if not spec.python and C_LIBRARY.is_dir() else []), env.get("LD_LIBRARY_PATH", "")]
        library_path = os.pathsep.join(dict.fromkeys(p for p in libraries if p))
        if library_path:
            env["LD_LIBRARY_PATH"] = library_path
        else:                  # none left: an empty one is no list to give
            env.pop("LD_LIBRARY_PATH", None)
        return env

    def start(self, robot: str) -> None:
        spec = self.specs[robot]
        with self._lock:
            now = self.running.get(robot)
            if now is not None and now.proc.poll() is None:      # a restart and a reload at once: one process
                return
        self._starting.add(robot)
        argv = self.command(spec)
        try:
            proc = subprocess.Popen(argv, cwd=spec.folder, env=self.environment(spec),
                                    stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    start_new_session=True)    # its own group: ended by us, with its children
        except (OSError, ValueError) as exc:     # ValueError: a NUL byte in an argument or the environment
            why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            self.log(f"'{spec.name}' controller of robot '{robot}' failed to start: {why} ({argv[0]!r}): the robot "
                     "runs without a controller")
            self.failed[robot] = spec.name
            self._starting.discard(robot)
            self._wake_server()
            return
        run = _Running(spec, proc)
        assert proc.stdout is not None and proc.stderr is not None
        for stream, sink in ((proc.stdout, self.out), (proc.stderr, self.err)):
            t = threading.Thread(target=self._pump, args=(robot, stream, sink), daemon=True,
                                 name=f"sensorium-run-{robot}")
            t.start()
            run.readers.append(t)
        with self._lock:
            self.running[robot] = run
            self.starts[robot] += 1
        threading.Thread(target=self._watch, args=(run,), daemon=True, name=f"sensorium-wait-{robot}").start()
        threading.Thread(target=self._attach_watch, args=(run, self.attach_timeout_s), daemon=True,
                         name=f"sensorium-attach-{robot}").start()

    def _attach_watch(self, run: _Running, timeout_s: float | None) -> None:
        """``--attach-timeout``: a controller still running and not attached ``timeout_s`` seconds
        after it started is ended; its robot runs without a controller (said, and in the exit status).
        Without it (None, as Webots waits), one line after :data:`ATTACH_NOTE_S` says what the world
        waits for."""
        try:
            run.proc.wait(ATTACH_NOTE_S if timeout_s is None else timeout_s)
            return                                 # it ended by itself (said by _watch)
        except subprocess.TimeoutExpired:
            pass
        robot = run.spec.robot
        with self._lock:
            if run.ending or self.running.get(robot) is not run or robot not in self._starting:
                return                             # attached, or ended by us meanwhile
            if timeout_s is None:
                self.log(f"the world waits for the '{run.spec.name}' controller of robot '{robot}', started "
                         f"{ATTACH_NOTE_S:g} s ago, to attach (as Webots waits; --attach-timeout S ends it instead)")
                return
            run.ending = True
        self.log(f"'{run.spec.name}' controller of robot '{robot}' did not attach within {timeout_s:g} s "
                 "(--attach-timeout): ended; the robot runs without a controller")
        self.failed[robot] = run.spec.name
        self._starting.discard(robot)
        self._wake_server()
        try:
            os.killpg(run.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass

    def replan(self, specs: list[ControllerSpec]) -> None:
        """The controllers of a reloaded world (its file may name others now)."""
        with self._lock:
            self.specs = {s.robot: s for s in specs}
            for s in specs:
                self.starts.setdefault(s.robot, 0)

    def start_all(self) -> None:
        for robot in self.specs:
            self.start(robot)

    def _watch(self, run: _Running) -> None:
        code = run.proc.wait()
        by_itself = not run.ending
        quitting = self._quitting()         # as it ended (the world may reach its end while its output drains)
        if by_itself:               # it may never have attached (a crash at start): not waited for any more
            self._starting.discard(run.spec.robot)
            if code != 0:           # a crash: nor, attached, for its heartbeats to time out (a status 0 may be
                self._exited[run.spec.robot] = time.monotonic()  # a wrapper whose child attached, left running)
            self._wake_server()
        self._drain(run)
        # it ended by itself: the robot stays uncontrolled, the world goes on; a failure is said even when the
        # world, left to itself, reached its end meanwhile (a clean end told by the world's end is not news)
        if by_itself and (code != 0 or not quitting):
            self._say_end(run, code)

    def _say_end(self, run: _Running, code: int) -> None:
        """Webots' line for a controller that ended by itself, once."""
        with self._lock:
            if run.said_end:
                return
            run.said_end = True
        self.log(f"'{run.spec.name}' controller of robot '{run.spec.robot}' {_describe(code)}")

    def _end(self, run: _Running, grace_s: float) -> None:
        """End one controller: it was told (-1) by the server; after ``grace_s`` its process group
        gets SIGTERM, then SIGKILL. Its output is read to the end; one that had already failed by itself
        (its watcher not yet there) has its line said here."""
        proc = run.proc
        ended = proc.poll() if not run.ending else None
        run.ending = True
        try:
            proc.wait(grace_s)
        except subprocess.TimeoutExpired:
            self.log(f"'{run.spec.name}' controller of robot '{run.spec.robot}': forced termination (it did not "
                     f"end {grace_s:g} s after its last step)")
            for sig, wait_s in ((signal.SIGTERM, 1.0), (signal.SIGKILL, None)):
                try:
                    os.killpg(proc.pid, sig)
                except ProcessLookupError:
                    break
                try:
                    proc.wait(wait_s)
                    break
                except subprocess.TimeoutExpired:
                    continue
        try:     # what it left in its group (a controller's own children) goes too
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        if not self._drain(run) and not run.said_held:
            run.said_held = True
            self.log(f"'{run.spec.name}' controller of robot '{run.spec.robot}': a process it started outside its "
                     "process group still holds its output: not read further, not ended")
        if ended is not None and ended != 0:
            self._say_end(run, ended)

    @staticmethod
    def _drain(run: _Running) -> bool:
        """Read ``run``'s output to its end, at most :data:`DRAIN_S` seconds after its process
        ended; False when something else still holds its pipes (the readers go on by themselves)."""
        deadline = time.monotonic() + DRAIN_S
        for t in run.readers:
            t.join(max(0.0, deadline - time.monotonic()))
        return not any(t.is_alive() for t in run.readers)

    def end_all(self, grace_s: float | None = None) -> None:
        """End every controller (the server already answered their steps with -1)."""
        with self._lock:
            runs = list(self.running.values())
            self.running.clear()
        grace = self.grace_s if grace_s is None else grace_s
        deadline = time.monotonic() + grace
        for run in runs:
            self._end(run, max(0.0, deadline - time.monotonic()))

    # ------------------------------------------------------------------ restart / reload (server's loop thread)
    def restart(self, robot: str) -> None:
        """restartController: the server has ended the session; end the process, start it again."""
        if robot in self.specs:
            self._starting.add(robot)        # the world waits for the new process, as for the first one
        with self._lock:
            self._restarts.append((robot, False))
            run = self.running.get(robot)
            if run is not None:
                run.ending = True
        self._wake.set()

    def switch(self, robot: str, name: str, synchronous: bool) -> None:
        """A Supervisor set the robot's ``controller`` field to ``name`` (the server has ended its
        session): end its process and start the controller ``name`` names, found as the world's are;
        ``<extern>`` waits for one to attach (a synchronous robot holds the world until then, as at
        load), ``""``, ``<none>`` and ``<generic>`` leave the robot without one, as a name not found (one line)."""
        spec = None
        if name == "<extern>":
            self.log(f"robot '{robot}' is <extern> now: attach its controller with `sensorium controller SCRIPT "
                     f"--robot {robot} --url {self.url}`")
        elif name in ("", "<none>", "<generic>"):
            self.log(f"robot '{robot}': controller {name!r} now: the robot runs without a controller")
        else:
            try:
                if self.find is None:
                    raise LaunchError(f"robot {robot!r}: controller {name!r} not looked for (no world to look from)")
                spec = self.find(robot, name)
                for line in spec.said():
                    self.log(line)
            except LaunchError as exc:
                self.log(f"{exc}: the robot runs without a controller")
                self.failed[robot] = name
        with self._lock:
            if spec is None:
                self.specs.pop(robot, None)
            else:
                self.specs[robot] = spec
                self.starts.setdefault(robot, 0)
            self._restarts.append((robot, True))
            run = self.running.get(robot)
            if run is not None:
                run.ending = True
        if spec is not None or (name == "<extern>" and synchronous):
            self._starting.add(robot)        # the world waits for the new controller, as at load
        else:
            self._starting.discard(robot)    # nor for the one it had started
            self._wake_server()
        self._wake.set()

    def reload(self) -> None:
        """worldReload: stop the server (every step -1); ``run`` then reloads and starts all again."""
        self.reload_requested = True
        self._stop()

    def load(self, robot: str, filename: str) -> None:
        """worldLoad: stop the server (every step -1); ``run`` then loads ``filename``
        (:func:`world_to_load`: from the robot's controller folder, within :attr:`worlds`) and starts
        its controllers. A name that gives no world to load is one line and the run ends (exit 1): Webots
        opens an empty world then, where nothing runs."""
        spec = self.specs.get(robot)
        try:
            if self.worlds is None:
                raise LaunchError("no world folder to load from")
            self.world_requested = world_to_load(filename, spec.folder if spec else None, self.worlds)
        except LaunchError as exc:
            self.log(f"robot '{robot}': worldLoad({filename!r}): {exc}: the simulation ends (Webots opens an empty "
                     "world)")
            self.load_refused = True
            self._stop()
            return
        self.reload()

    def _stop(self) -> None:
        self.quit()
        if self.stop_server is not None:
            self.stop_server()

    def quit(self) -> None:
        """simulationQuit (and a reload's first half): the server stops (every step -1); every
        controller ends as at ``--until``, none is said to have exited by itself."""
        with self._lock:
            for run in self.running.values():
                run.ending = True

    def _work(self) -> None:
        while True:
            self._wake.wait()
            self._wake.clear()
            if self._closed:
                return
            while True:
                with self._lock:
                    if not self._restarts:
                        break
                    robot, switched = self._restarts.pop(0)
                    run = self.running.pop(robot, None)
                    spec = self.specs.get(robot)
                if spec is None and not switched:
                    self.log(f"robot '{robot}' has no controller `sensorium run` started (an <extern> one?): "
                             "restartController ended its session only")
                if run is not None:
                    self._end(run, self.grace_s)
                if spec is not None and not self._closed:
                    self.start(robot)

    def close(self) -> None:
        self._closed = True
        self._wake.set()
        self._worker.join()
        self.end_all()


@dataclass(frozen=True)
class RunOptions:
    """What ``sensorium run`` takes besides the world file. ``serve`` is the server's
    :class:`~sensorium.server.daemon.serve.ServeOptions` (None: its defaults); ``webots_home`` the installation whose
    projects hold stock controllers (None: not looked at)."""

    serve: Any = None
    controllers_dirs: tuple[Path, ...] = ()
    extra_projects: tuple[Path, ...] = ()     # Webots' extra project paths (a folder that is none is said, skipped)
    webots_home: Path | None = None
    grace_s: float = GRACE_S
    require_controllers: bool = False          # a controller that cannot be started: exit 1 before the world runs
    attach_timeout_s: float | None = None      # a started controller not attached after this: ended (None: waited for)
    robot_window_log: bool = False             # --robot-window-log: what controllers send their robot window, on stderr

    def check(self, world: Path) -> None:
        """Raise ValueError naming the first bad option (one line)."""
        if not Path(world).is_file():
            raise ValueError(f"no world file {world}")
        if not 0 <= self.grace_s < float("inf"):
            raise ValueError(f"--grace must be a finite number >= 0, got {self.grace_s}")
        if self.attach_timeout_s is not None and not 0 < self.attach_timeout_s < float("inf"):
            raise ValueError(f"--attach-timeout must be a finite number of seconds > 0, got {self.attach_timeout_s}")
        for d in self.controllers_dirs:
            if not Path(d).is_dir():
                raise ValueError(f"--controllers-dir {d}: no such folder")
        if self.serve is not None:
            self.serve.check()


class ProjectRun:
    """One ``sensorium run``: serve ``world``, start its controllers (:class:`Launcher`), reload on
    ``worldReload``, end everything at the end. :meth:`run` blocks and returns the exit status;
    :meth:`stop` (any thread, a signal handler) ends it as Ctrl-C does. Lines go to ``out`` (the
    ready line, the controllers' stdout) and ``err`` (everything else)."""

    def __init__(self, world: str | Path, options: RunOptions, *, out: IO[str] | None = None,
                 err: IO[str] | None = None):
        self.world = Path(world)
        self.options = options
        self.out = out or sys.stdout
        self.err = err or sys.stderr
        self.projects = [p for p in options.extra_projects if p.is_dir()]
        self.dirs = controller_dirs(self.world, list(options.controllers_dirs), self.projects)
        home = options.webots_home
        self.webots = WebotsProjects(home) if home is not None and Path(home).is_dir() else None
        self.interrupted = False
        self.missing: dict[str, str] = {}      # robot -> controller it ran without (every load of the world)
        self._server: Any = None
        self._find: Callable[[str, str], ControllerSpec] | None = None    # the loaded world's (_plan)

    def stop(self) -> None:
        self.interrupted = True
        if self._server is not None:
            self._server.stop()

    def _serverkey(self) -> str | None:
        """The server's CURVE public key when it encrypts (``curve_keys``), for its controllers."""
        keys = getattr(self.options.serve, "curve_keys", None)
        if not keys:
            return None
        from sensorium.server.daemon.transport import load_curve_keys
        return load_curve_keys(keys)[0].decode("ascii")

    def _say(self, text: str) -> None:
        print(text, file=self.err, flush=True)

    def _open(self, serve: Any) -> Any:
        """The world's server, or None (its problem said)."""
        from sensorium.server.daemon.serve import Server
        from sensorium.server.daemon.transport import BIND_ERRORS, bind_problem
        from sensorium.server.world.loader import WorldError
        try:
            return Server.open(self.world, serve)
        except WorldError as exc:
            self._say(str(exc))
        except BIND_ERRORS as exc:
            self._say(f"sensorium run: {bind_problem(exc)}")
        return None

    def _plan(self, server: Any) -> WorldPlan | None:
        """The plan for ``server``'s world, or None (server closed, every problem said)."""
        loaded = server.core.sim.loaded.world
        protos = robot_protos(loaded)
        wbt = self.world.suffix.lower() == ".wbt"
        projects = {}
        if wbt and protos:
            try:
                projects = proto_projects(self.world, self.world.read_text(encoding="utf-8", errors="replace"), protos)
            except OSError:              # it was read a moment ago: gone since, nothing more to learn from it
                pass
        world_plan = plan_world(loaded.robots, self.dirs, server.transport.rpc_endpoint, self.webots, protos, wbt,
                                projects)
        args = {r.name: list(r.controller_args) for r in loaded.robots}
        # a Supervisor's controller field set: the named controller looked for as the world's are
        self._find = lambda robot, name: robot_controller(robot, name, args.get(robot, []), self.dirs, self.webots,
                                                          protos, projects)
        if world_plan.problems and self.options.require_controllers:
            server.close()
            for line in world_plan.problems:
                self._say(f"sensorium run: {line}")
            return None
        for line in world_plan.problems:      # as Webots (which starts its <generic> controller instead)
            self._say(f"sensorium run: {line}: the robot runs without a controller")
        self.missing.update(world_plan.missing)
        return world_plan

    def run(self, *, signals: bool = True) -> int:
        """Run to the end; ``signals``: SIGINT/SIGTERM end it (when called in the main thread; from
        another thread, end it with :meth:`stop`)."""
        if self.options.serve is None:              # serve's defaults
            from sensorium.server.daemon.serve import ServeOptions
            self.options = dataclasses.replace(self.options, serve=ServeOptions())
        server = self._open(self.options.serve)
        if server is None:
            return 1
        world_plan = self._plan(server)
        if world_plan is None:
            return 1
        report = server.core.sim.loaded.report
        if report:
            print(report.text(), file=self.err, flush=True)
        for p in self.options.extra_projects:
            if p not in self.projects:
                self._say(f"sensorium run: extra project path {p} is not a folder: not looked in")
        home = self.options.webots_home
        if home is not None and self.webots is None:      # a mistyped --webots-home would pass unnoticed
            self._say(f"sensorium run: --webots-home (or WEBOTS_HOME) {_one_line(home)} is not a folder: "
                      "Webots' own projects are not looked in for controllers")
        launcher = Launcher(list(world_plan.specs), server.transport.rpc_endpoint, out=self.out, err=self.err,
                            grace_s=self.options.grace_s, serverkey=self._serverkey(),
                            attach_timeout_s=self.options.attach_timeout_s,
                            robot_window_log=self.options.robot_window_log)
        self._server = server
        worlds = self.world.resolve().parent      # worldLoad loads from here (the first world's folder)
        old_handlers = {}
        if signals and threading.current_thread() is threading.main_thread():    # Python's signals: main thread only
            old_handlers = {sig: signal.signal(sig, lambda signum, frame: self.stop())
                            for sig in (signal.SIGINT, signal.SIGTERM)}
        try:
            while True:
                for line in world_plan.notes:
                    launcher.log(line)
                if self.interrupted:       # stopped while the world (re)loaded
                    break
                server.core.launcher = launcher
                lockstep = server.core.lockstep
                launcher.bind(lockstep.starting, server.transport.wake, partial(getattr, lockstep, "shutting_down"),
                              lockstep.exited)
                lockstep.starting.update(world_plan.extern_waited)
                lockstep.extern_synchronous = list(world_plan.extern_synchronous)
                launcher.stop_server = server.stop
                launcher.find = self._find
                launcher.worlds = worlds
                print(server.ready_line, file=self.out, flush=True)
                launcher.start_all()
                server.run(signals=False)
                launcher.end_all()
                if launcher.load_refused or not after_run(launcher.reload_requested, self.interrupted,
                                                          server.core.quit_status):
                    break
                launcher.reload_requested = False          # worldReload: the same file, time 0, the same endpoints
                loaded = launcher.world_requested          # worldLoad: another file, its project's controllers
                launcher.world_requested = None
                if loaded is not None:
                    self.world = loaded
                    self.dirs = controller_dirs(self.world, list(self.options.controllers_dirs), self.projects)
                again = dataclasses.replace(self.options.serve, rpc=server.transport.rpc_endpoint,
                                            pub=server.transport.pub_endpoint)
                reopened = self._open(again)
                if reopened is None:
                    return 1
                world_plan = self._plan(reopened)          # the file may have changed
                if world_plan is None:
                    return 1
                launcher.replan(list(world_plan.specs))
                launcher.log(f"world {'loaded' if loaded is not None else 'reloaded'} from {self.world}")
                server = self._server = reopened
        finally:
            launcher.close()
            for sig, handler in old_handlers.items():
                signal.signal(sig, handler)
        core = server.core
        self._say(f"sensorium: stopped at {core.sim.time_ms} ms after {core.lockstep.steps} steps")
        missing = {**self.missing, **launcher.failed}
        status = exit_status(core.quit_status, bool(missing), launcher.load_refused)
        if missing:
            names = ", ".join(f"'{robot}' ('{name}')" for robot, name in missing.items())
            self._say(f"sensorium run: {len(missing)} robot{'s' if len(missing) > 1 else ''} ran without the "
                      f"controller the world names: {names} (exit status {status}; --require-controllers "
                      "refuses to start instead)")
        return status


def run_project(world: str | Path, options: RunOptions, *, signals: bool = True) -> int:
    """``sensorium run WORLD``: run the project to its end (see :class:`ProjectRun`); the exit status."""
    return ProjectRun(world, options).run(signals=signals)
