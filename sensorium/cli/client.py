"""``sensorium controller``: run a Webots-style Python controller (pyzmq + msgpack only); ``echo``,
``hz`` and ``topics`` are in topics.py, ``services`` and ``call`` in services.py."""

from __future__ import annotations

import argparse
import os
import runpy
import sys
import traceback
from pathlib import Path

from sensorium.client.connection import (
    ENV_URL,
    SensoriumError,
    controller_url_from_env,
    parse_controller_url,
)

WEBOTS_DIR = Path(__file__).resolve().parents[1] / "client" / "webots"
EXAMPLES_DIR = Path(__file__).resolve().parents[1] / "client" / "examples"


def _resolve_script(name: str) -> Path:
    """A script path, or ``example:NAME`` for a controller bundled in sensorium/client/examples."""
    if name.startswith("example:"):
        stem = name[len("example:"):].removesuffix(".py")
        return EXAMPLES_DIR / f"{stem}.py"
    return Path(name)


# ---------------------------------------------------------------------- controller

def _exit_code(exc: SystemExit) -> int:
    code = exc.code
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


def _print_script_traceback(exc: BaseException, script: str) -> None:
    """The traceback from the script's first frame on (the launcher's frames are noise)."""
    tb = exc.__traceback__
    target = os.path.realpath(script)
    while tb is not None and os.path.realpath(tb.tb_frame.f_code.co_filename) != target:
        tb = tb.tb_next
    if tb is None and isinstance(exc, SyntaxError) and exc.filename and os.path.realpath(exc.filename) == target:
        # the script did not compile: no frame of it ran, and its file, line and caret are the error's own
        # (what `python script.py` prints), so none of the launcher's frames either
        traceback.print_exception(type(exc), exc, None)
        return
    traceback.print_exception(type(exc), exc, tb or exc.__traceback__)


_LAUNCHER_OPTIONS = ("--robot", "--url")


def _take_launcher_options(args: argparse.Namespace) -> str | None:
    """``--robot``/``--url`` given after SCRIPT (argparse hands them over with the script's
    arguments): move them to ``args``; stop at ``--`` or the first other argument."""
    rest = list(args.args)
    while rest:
        head = rest[0]
        if head == "--":
            rest.pop(0)
            args.args = rest
            return None
        name, eq, value = head.partition("=")
        if name not in _LAUNCHER_OPTIONS:
            break
        if not eq:
            if len(rest) < 2:
                return f"{name} needs a value"
            value = rest[1]
            del rest[:2]
        else:
            rest.pop(0)
        setattr(args, name[2:], value)
    args.args = rest
    late = [a for a in rest[1:] if a.partition("=")[0] in _LAUNCHER_OPTIONS]
    if late:      # `SCRIPT -v --url U` attached to the default URL and timed out there, without a word
        print(f"sensorium controller: note: {late[0].partition('=')[0]} after the script's argument {rest[0]!r} is "
              "passed to the script, not taken by sensorium (give --robot/--url before the script's arguments; "
              "`--` before them keeps them the script's without this note)", file=sys.stderr)
    return None


def _is_binary_controller(path: Path) -> bool | None:
    """False for a Python script, True for an executable (a compiled controller, e.g. against the
    C library in sensorium/client/c), None for neither."""
    if path.suffix == ".py":
        return False
    if os.access(path, os.X_OK):
        return True
    try:
        with open(path, "rb") as f:
            head = f.read(64)
    except OSError:
        return None
    # a Python file without the .py suffix (no NUL bytes, not an ELF image) still runs as Python
    return None if (head.startswith(b"\x7fELF") or b"\0" in head) else False


def _run_binary(path: Path, argv: list[str]) -> int:
    """Run a compiled controller with the URL in its environment, as Webots' launcher does. On
    POSIX the launcher becomes the controller (exec), so signals reach it directly."""
    exe = str(path if path.is_absolute() or path.parent != Path() else Path(".") / path)
    sys.stdout.flush()
    sys.stderr.flush()
    if os.name == "posix":
        try:
            os.execv(exe, [exe, *argv])
        except OSError as exc:
            print(f"sensorium controller: cannot run {path}: {exc.strerror}", file=sys.stderr)
            return 2
    import subprocess

    try:
        return subprocess.call([exe, *argv])
    except OSError as exc:
        print(f"sensorium controller: cannot run {path}: {exc.strerror}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


def controller(args: argparse.Namespace) -> int:
    """Run a Webots-style controller for one robot, as Webots' launcher does: the controller URL in
    the environment, the controller's folder as the working directory; a Python script runs as
    ``__main__`` with ``controller`` importable, an executable (a compiled C/C++ controller) is
    exec'd with the same environment."""
    problem = _take_launcher_options(args)
    if problem:
        print(f"sensorium controller: {problem}", file=sys.stderr)
        return 2
    script = _resolve_script(args.script)
    if not script.is_file():
        print(f"sensorium controller: no such script: {script} (bundled examples: "
              f"{', '.join('example:' + p.stem for p in sorted(EXAMPLES_DIR.glob('[!_]*.py')))})", file=sys.stderr)
        return 2
    binary = _is_binary_controller(script)
    if binary is None:
        print(f"sensorium controller: {script} is neither a Python script (.py) nor an executable "
              f"(a compiled controller needs chmod +x)", file=sys.stderr)
        return 2
    try:
        url = parse_controller_url(args.url) if args.url else controller_url_from_env()
    except SensoriumError as exc:
        print(f"sensorium controller: {exc}", file=sys.stderr)
        return 2
    if args.robot:
        url = url.with_robot(args.robot)
    os.environ[ENV_URL] = str(url)
    # Webots starts a controller in its own folder: the files it opens or saves by a relative name
    # (a display's images, a camera's saveImage) are found and written there
    script = script.resolve()
    os.chdir(script.parent)
    if binary:
        return _run_binary(script, args.args)
    # ``controller`` importable here and in any process the controller starts
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(WEBOTS_DIR), os.environ.get("PYTHONPATH", "")) if p)
    sys.path[:0] = [str(script.resolve().parent), str(WEBOTS_DIR)]
    sys.argv = [str(script), *args.args]
    from sensorium.client import wb

    try:
        runpy.run_path(str(script), run_name="__main__")
        return 0
    except SystemExit as exc:
        return _exit_code(exc)
    except KeyboardInterrupt:
        return 130
    except SensoriumError as exc:
        print(f"{script.name}: {exc}", file=sys.stderr)
        return 1
    except BaseException as exc:  # noqa: BLE001 - the script's crash is reported, not re-raised
        _print_script_traceback(exc, str(script))
        return 1
    finally:
        sys.stdout.flush()
        wb.wb_robot_cleanup()
