"""``sensorium run WORLD``: the argparse shell over :mod:`sensorium.launch`: serve the world and start
every robot's named controller with it, as Webots opens a project; restart them on
``restartController``, reload on ``worldReload``; end them all at ``--until``, Ctrl-C or SIGTERM."""

from __future__ import annotations

import argparse
import dataclasses
import os
import signal
import sys
from functools import partial
from pathlib import Path

from sensorium.cli.serve import DEFAULT_PUB, DEFAULT_RPC, add_world_options, bind_problem

__all__ = ["add_arguments", "main"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", help="world file of a Webots project (worlds/NAME.wbt; YAML or JSON too): its robots' "
                   "controllers are found in the project's controllers/NAME/")
    p.add_argument("--controllers-dir", action="append", default=[], metavar="DIR",
                   help="also look for controllers/NAME/ folders here, after the project's (repeatable); then, "
                   "with --webots-home, in Webots' own projects")
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
    add_world_options(p)


def main(args: argparse.Namespace) -> int:
    import zmq

    from sensorium.launch import Launcher, WebotsProjects, controller_dirs, plan, robot_protos
    from sensorium.server.daemon.serve import ServeOptions, Server
    from sensorium.server.world.loader import WorldError

    world = Path(args.world)
    if not world.is_file():
        print(f"sensorium run: no world file {world}", file=sys.stderr)
        return 2
    if not 0 <= args.grace < float("inf"):
        print(f"sensorium run: --grace must be a finite number >= 0, got {args.grace}", file=sys.stderr)
        return 2
    missing = [d for d in args.controllers_dir if not Path(d).is_dir()]
    if missing:
        print(f"sensorium run: --controllers-dir {missing[0]}: no such folder", file=sys.stderr)
        return 2
    opts = ServeOptions(rpc=args.rpc, pub=args.pub, mode=args.mode, precision=args.precision,
                        heartbeat_ms=args.heartbeat_ms, until=args.until, allow_large=args.allow_large,
                        allow_outside_meshes=args.allow_outside_meshes,
                        contact=False if args.no_contact else None)
    try:
        opts.check()
    except ValueError as exc:
        print(f"sensorium run: {exc}", file=sys.stderr)
        return 2

    def open_server(o: ServeOptions) -> Server | None:
        try:
            return Server.open(world, o)
        except WorldError as exc:
            print(str(exc), file=sys.stderr)
        except (OSError, zmq.ZMQError) as exc:
            print(f"sensorium run: {bind_problem(exc)}", file=sys.stderr)
        return None

    dirs = controller_dirs(world, [Path(d) for d in args.controllers_dir])
    home = os.environ.get("WEBOTS_HOME")            # --webots-home sets it (cli/__init__.py)
    webots = WebotsProjects(Path(home)) if home and Path(home).is_dir() else None

    def controllers(s: Server) -> list | None:
        """The controllers to start for ``s``'s world, or None (closed, every problem said)."""
        loaded = s.core.sim.loaded.world
        specs, problems = plan(loaded.robots, dirs, webots, robot_protos(loaded))
        if not problems:
            return specs
        s.close()
        for line in problems:
            print(f"sensorium run: {line}", file=sys.stderr)
        return None

    server = open_server(opts)
    if server is None:
        return 1
    robots = server.core.sim.loaded.world.robots
    specs = controllers(server)
    if specs is None:
        return 1
    report = server.core.sim.loaded.report
    if report:
        print(report.text(), file=sys.stderr, flush=True)
    launcher = Launcher(specs, server.transport.rpc_endpoint, grace_s=args.grace)
    for spec in specs:
        if spec.webots:
            launcher.log(f"robot '{spec.robot}': controller '{spec.name}' found in Webots' projects: {spec.program}")
    for r in robots:
        if r.controller == "<generic>":
            launcher.log(f"robot '{r.name}': Webots' <generic> controller is not here: the robot waits for an "
                         "<extern> controller")
        elif r.controller == "<extern>":
            launcher.log(f"robot '{r.name}' is <extern>: attach its controller with `sensorium controller SCRIPT "
                         f"--robot {r.name} --url {server.transport.rpc_endpoint}`")
    interrupted = False

    def on_signal(signum, frame):  # noqa: ARG001
        nonlocal interrupted
        interrupted = True
        current.stop()

    current = server
    old_handlers = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        while True:
            current.core.launcher = launcher
            lockstep = current.core.lockstep
            launcher.bind(lockstep.starting, current.transport.wake, partial(getattr, lockstep, "shutting_down"))
            # as Webots, the world waits for every synchronous <extern> robot's controller too
            robots = current.core.sim.loaded.world.robots
            lockstep.starting.update(r.name for r in robots if r.controller == "<extern>" and r.synchronization)
            # ... but a robot whose started controller has ended is uncontrolled: the world goes on
            # without it, as Webots' does (only robots left to an <extern> controller are waited for
            # while none is attached: <extern> and, here, <generic> ones)
            lockstep.extern_synchronous = [r.name for r in robots
                                           if r.controller in ("<extern>", "<generic>") and r.synchronization]
            launcher.on_reload = current.stop
            print(current.ready_line, flush=True)
            launcher.start_all()
            current.run(signals=False)
            launcher.end_all()
            if not launcher.reload_requested or interrupted or current.core.quit_status is not None:
                break
            launcher.reload_requested = False          # worldReload: the same file, time 0, the same endpoints
            again = dataclasses.replace(opts, rpc=current.transport.rpc_endpoint, pub=current.transport.pub_endpoint)
            reopened = open_server(again)
            if reopened is None:
                return 1
            specs = controllers(reopened)                # the file may have changed
            if specs is None:
                return 1
            launcher.replan(specs)
            launcher.log(f"world reloaded from {world}")
            current = reopened
    finally:
        launcher.close()
        for sig, handler in old_handlers.items():
            signal.signal(sig, handler)
    core = current.core
    print(f"sensorium: stopped at {core.sim.time_ms} ms after {core.lockstep.steps} steps", file=sys.stderr, flush=True)
    return 0 if core.quit_status is None else core.quit_status & 0xFF     # simulationQuit(status), as Webots exits
