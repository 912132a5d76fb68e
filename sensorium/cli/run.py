"""``sensorium run WORLD``: the argparse shell over :mod:`sensorium.launch`: serve the world and start
every robot's named controller with it, as Webots opens a project; restart them on
``restartController``, reload on ``worldReload``, load another world on ``worldLoad``; end them all at
``--until``, Ctrl-C or SIGTERM."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from sensorium.cli.serve import DEFAULT_PUB, DEFAULT_RPC, add_world_options

__all__ = ["add_arguments", "main"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", help="world file of a Webots project (worlds/NAME.wbt; YAML or JSON too): its robots' "
                   "controllers are found in the project's controllers/NAME/")
    p.add_argument("--controllers-dir", action="append", default=[], metavar="DIR",
                   help="also look for controllers/NAME/ folders here, after the project's (repeatable); then in "
                   "each extra project's controllers/ (--extra-project-path, $WEBOTS_EXTRA_PROJECT_PATH); then, with "
                   "--webots-home, in Webots' own projects")
    p.add_argument("--until", type=int, metavar="MS",
                   help="quit when the simulated time reaches MS milliseconds (controllers get -1, then end)")
    p.add_argument("--mode", choices=["fast", "realtime", "pause"], default="fast",
                   help="fast (default): step as soon as every controller allows; realtime: no faster than the "
                   "wall clock; pause")
    p.add_argument("--rpc", default=DEFAULT_RPC, metavar="URL",
                   help=f"service endpoint, default {DEFAULT_RPC} (an <extern> robot's `sensorium controller` "
                   "attaches there); port 0 picks a free port")
    p.add_argument("--pub", default=DEFAULT_PUB, metavar="URL", help=f"topic endpoint, default {DEFAULT_PUB}")
    p.add_argument("--precision", choices=["fast", "exact"], default="exact", help="ray engine precision")
    p.add_argument("--heartbeat-ms", type=int, default=1000, metavar="N",
                   help="controllers not heard from for 3*N ms are released (default 1000)")
    p.add_argument("--no-contact", action="store_true", help="robots drive through solids and each other")
    p.add_argument("--grace", type=float, default=1.0, metavar="S",
                   help="seconds a controller has to end after its last step (-1) before it is terminated "
                   "(default 1, as Webots)")
    p.add_argument("--attach-timeout", type=float, metavar="S",
                   help="a started controller that has not attached after S seconds is ended and its robot runs "
                   "without one (run exits 1 at the end); default: the world waits for it, as Webots")
    p.add_argument("--require-controllers", action="store_true",
                   help="a controller that cannot be found or started is an error: exit 1 before the world runs "
                   "(default: as Webots, the robot runs without it and the world goes on; run exits 1 at the end)")
    p.add_argument("--robot-window-log", action="store_true",
                   help="each text a controller sends its robot window (wwiSendText, wb_robot_wwi_send: a "
                   "benchmark's score) printed as a line 'robot window: TEXT' on the controller's stderr")
    add_world_options(p)


def main(args: argparse.Namespace) -> int:
    from sensorium.launch import EXTRA_ENV, RunOptions, extra_project_paths, run_project
    from sensorium.server.daemon.serve import ServeOptions

    home = os.environ.get("WEBOTS_HOME")            # --webots-home sets it (cli/__init__.py)
    options = RunOptions(
        serve=ServeOptions(rpc=args.rpc, pub=args.pub, mode=args.mode, precision=args.precision,
                           heartbeat_ms=args.heartbeat_ms, until=args.until, allow_large=args.allow_large,
                           allow_outside_meshes=args.allow_outside_meshes,
                           contact=False if args.no_contact else None),
        controllers_dirs=tuple(Path(d) for d in args.controllers_dir),
        extra_projects=tuple(extra_project_paths(os.environ.get(EXTRA_ENV))),   # --extra-project-path too
        webots_home=Path(home) if home else None, grace_s=args.grace, require_controllers=args.require_controllers,
        attach_timeout_s=args.attach_timeout, robot_window_log=args.robot_window_log)
    try:
        options.check(Path(args.world))
    except ValueError as exc:
        print(f"sensorium run: {exc}", file=sys.stderr)
        return 2
    return run_project(args.world, options)
