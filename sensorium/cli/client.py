"""Client subcommands: ``sensorium controller``, ``echo`` and ``topics`` (pyzmq + msgpack only)."""

from __future__ import annotations

import argparse
import math
import os
import runpy
import sys
import traceback
from pathlib import Path
from typing import Any

from sensorium.client.connection import (
    DEFAULT_PUB_ENDPOINT,
    ENV_URL,
    Connection,
    SensoriumError,
    controller_url_from_env,
    parse_controller_url,
)

WEBOTS_DIR = Path(__file__).resolve().parents[1] / "client" / "webots"


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
            break
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
    the environment; a Python script runs as ``__main__`` with ``controller`` importable, an
    executable (a compiled C/C++ controller) is exec'd with the same environment."""
    problem = _take_launcher_options(args)
    if problem:
        print(f"sensorium controller: {problem}", file=sys.stderr)
        return 2
    script = Path(args.script)
    if not script.is_file():
        print(f"sensorium controller: no such script: {script}", file=sys.stderr)
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


# ---------------------------------------------------------------------- echo

def summarize(value: Any) -> Any:
    """A printable form of a decoded body: arrays become ``<float32[360] 0.12..5.9 (3 inf)>``."""
    if isinstance(value, dict):
        return {k: summarize(v) for k, v in value.items()}
    if isinstance(value, list):
        return [summarize(v) for v in value]
    if isinstance(value, (bytes, bytearray, memoryview)):
        return _Raw(f"<bytes[{len(value)}]>")
    shape = getattr(value, "shape", None)
    if shape is not None and hasattr(value, "dtype"):                       # numpy
        flat = value.reshape(-1)
        dims = "x".join(str(d) for d in shape)
        return _Raw(_stats(f"{value.dtype}[{dims}]", [float(v) for v in flat] if flat.size <= 200_000 else []))
    typecode = getattr(value, "typecode", None)
    if typecode is not None:                                                # array.array
        return _Raw(_stats(f"float32[{len(value)}]" if typecode == "f" else f"{typecode}[{len(value)}]", list(value)))
    return value


class _Raw(str):
    def __repr__(self) -> str:
        return str(self)


def _stats(head: str, values: list[float]) -> str:
    if not values:
        return f"<{head}>"
    finite = [v for v in values if math.isfinite(v)]
    extras = []
    n_inf = sum(1 for v in values if math.isinf(v))
    n_nan = len(values) - len(finite) - n_inf
    if n_inf:
        extras.append(f"{n_inf} inf")
    if n_nan:
        extras.append(f"{n_nan} nan")
    rng = f" {min(finite):.4g}..{max(finite):.4g}" if finite else ""
    return f"<{head}{rng}{' (' + ', '.join(extras) + ')' if extras else ''}>"


def format_message(msg: Any) -> str:
    body = dict(msg.body)
    body.pop("header", None)
    fields = ", ".join(f"{k}: {summarize(v)!r}" for k, v in body.items())
    return f"{msg.topic} [{msg.type}] seq={msg.seq} t={msg.stamp_ns / 1e9:.3f} {{{fields}}}"


def echo(args: argparse.Namespace) -> int:
    from sensorium.client.topics import Subscriber

    count = 0
    with Subscriber(args.url, args.topic) as sub:
        while args.count is None or count < args.count:
            msg = sub.recv(timeout=args.timeout)
            if msg is None:
                print(f"sensorium echo: nothing on {args.topic!r} from {args.url} for {args.timeout:g} s", file=sys.stderr)
                return 1
            if msg.gap:
                print(f"# {msg.gap} message(s) of {msg.topic} lost before seq {msg.seq}", file=sys.stderr)
            print(format_message(msg), flush=True)
            count += 1
    return 0


# ---------------------------------------------------------------------- topics

def topics(args: argparse.Namespace) -> int:
    try:
        endpoint = parse_controller_url(args.url).endpoint
        with Connection(endpoint, timeout=args.timeout) as conn:
            info = conn.call("get_info")
    except SensoriumError as exc:
        print(f"sensorium topics: {exc}", file=sys.stderr)
        return 1
    rows = [(str(t.get("name")), str(t.get("type"))) for t in info.get("topics", [])]
    print(f"# world {info.get('world')!r}, topics on {info.get('pub_endpoint', DEFAULT_PUB_ENDPOINT)}", file=sys.stderr)
    width = max((len(n) for n, _ in rows), default=0)
    for name, kind in rows:
        print(f"{name:<{width}}  {kind}")
    return 0
