"""The ``sensorium`` command. Each subcommand imports what it needs only when it runs, so that the
client-side commands work with pyzmq + msgpack alone."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

Handler = Callable[[argparse.Namespace], int]
_COMMANDS: dict[str, tuple[str, Callable[[argparse.ArgumentParser], None], str]] = {}


def command(name: str, help: str, target: str):
    """Register a subcommand: ``target`` is 'module:function' taking the parsed args, returning an exit code."""

    def register(add_args: Callable[[argparse.ArgumentParser], None]):
        _COMMANDS[name] = (help, add_args, target)
        return add_args

    return register


@command("validate", "check a world file; exit 1 listing every problem", "sensorium.server.cli_world:validate")
def _validate_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", nargs="+", help="world file(s), YAML or JSON")


@command("info", "summarise a world file (or a .mcap recording)", "sensorium.server.cli_world:info")
def _info_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("path", nargs="?", help="world file or .mcap recording (default: the embedded arena world)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


@command("probe", "run a world in-process and print what enabled devices read", "sensorium.server.cli_world:probe")
def _probe_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", nargs="?", help="world file (default: the embedded arena world)")
    p.add_argument("--steps", type=int, default=3, help="basic steps to run (default 3)")
    p.add_argument("--enable", action="append", default=[], metavar="ROBOT/DEVICE:PERIOD",
                   help="enable a device with a sampling period in ms (repeatable; 'all:PERIOD' enables every device)")
    p.add_argument("--point-cloud", action="append", default=[], metavar="ROBOT/DEVICE",
                   help="also enable a lidar's point cloud")
    p.add_argument("--precision", choices=["fast", "exact"], default="exact")
    p.add_argument("--json", action="store_true", help="JSON lines: step, time, robot, device, value or array summary")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="sensorium", description="Headless sensor simulator with Webots device semantics.")
    from sensorium import __version__

    parser.add_argument("--version", action="version", version=f"sensorium {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (help_text, add_args, target) in _COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        add_args(p)
        p.set_defaults(_target=target)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_target", None):
        parser.print_help()
        return 2
    module_name, func_name = args._target.split(":")
    import importlib

    func: Handler = getattr(importlib.import_module(module_name), func_name)
    try:
        return int(func(args) or 0)
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    sys.exit(main())
