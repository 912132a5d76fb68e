"""``sensorium serve``: the argparse shell over :mod:`sensorium.server.daemon.serve` (load a world,
bind the RPC and topic sockets, serve until SIGINT/SIGTERM).

Prints one line when ready, with the endpoints actually bound (port 0 or ``*`` picks a free
port), so scripts can wait for it::

    sensorium: serving world 'arena' rpc=tcp://127.0.0.1:5560 pub=tcp://127.0.0.1:5561
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys

__all__ = ["add_arguments", "main", "options"]

# kept equal to sensorium.server.daemon.transport.DEFAULT_*; not imported so that `sensorium --help` stays light
DEFAULT_RPC = "tcp://127.0.0.1:5560"
DEFAULT_PUB = "tcp://127.0.0.1:5561"


def add_world_options(p: argparse.ArgumentParser) -> None:
    """``--allow-large`` and ``--allow-outside-meshes`` (validate, probe, serve)."""
    p.add_argument("--allow-large", action="store_true",
                   help="raise the world limits (rays, beams, triangles, robots, file size, ...; README "
                   "'Security and limits') for a world that deliberately asks for more")
    p.add_argument("--allow-outside-meshes", action="store_true",
                   help="let mesh urls leave the world file's folder (absolute paths, '..')")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", nargs="?", help="world file (default: the embedded arena world)")
    p.add_argument("--rpc", default=DEFAULT_RPC, metavar="URL",
                   help=f"service endpoint (ROUTER), default {DEFAULT_RPC}; port 0 or * picks a free port")
    p.add_argument("--pub", default=DEFAULT_PUB, metavar="URL",
                   help=f"topic endpoint (XPUB), default {DEFAULT_PUB}")
    p.add_argument("--mode", choices=["fast", "realtime", "pause"], default="fast",
                   help="fast: step as soon as every controller allows; realtime: no faster than the wall clock; pause")
    p.add_argument("--precision", choices=["fast", "exact"], default="exact", help="ray engine precision")
    p.add_argument("--heartbeat-ms", type=int, default=1000, metavar="N",
                   help="controllers not heard from for 3*N ms are released (default 1000)")
    p.add_argument("--no-contact", action="store_true",
                   help="robots drive through solids and each other (overrides world_info.contact)")
    p.add_argument("--until", type=int, metavar="MS",
                   help="quit when the simulated time reaches MS milliseconds (pending steps get -1)")
    p.add_argument("--record", metavar="FILE.mcap",
                   help="record the published messages from inside the step loop (nothing dropped)")
    p.add_argument("--force", action="store_true", help="with --record: overwrite FILE if it exists")
    p.add_argument("--record-format", choices=["foxglove", "msgpack"], default="foxglove",
                   help="with --record: foxglove (default; opens in Foxglove, the published bytes kept losslessly "
                   "beside ROS 2 CDR views, /tf and /scene) or msgpack (the published bytes only: ~2.4x smaller)")
    p.add_argument("--foxglove", metavar="[HOST:]PORT",
                   help="also serve the topics, transforms and the world to Foxglove (WebSocket) on PORT, "
                   "host 127.0.0.1 unless given; port 0 picks a free port")
    p.add_argument("--controls", choices=["auto", "open", "supervisor"], default="auto",
                   help="who may use world-wide controls (set_mode): open = any caller; supervisor = only the "
                   "controller of a robot with 'supervisor: true'; auto (default) = open when --rpc is loopback/ipc, "
                   "else supervisor")
    p.add_argument("--curve-keys", metavar="DIR",
                   help="encrypt both sockets with CURVE using DIR/server.key_secret (create it with "
                   "'sensorium keys DIR'); clients need the public key: SENSORIUM_CURVE_SERVERKEY or URL?serverkey=")
    p.add_argument("--watch", nargs="*", metavar="ROBOT",
                   help="run these robots (default: every one) whose controller is \"<extern>\" as \"<none>\": "
                   "nobody controls them and the world steps by itself, so a viewer (--foxglove) or a subscriber "
                   "sees their sensors without starting controllers")
    add_world_options(p)
    p.add_argument("--allow-skipped", action="store_true",
                   help="serve a world even when every robot it writes was lost when it loaded (each is listed)")
    p.add_argument("--cpu", type=int, metavar="N",
                   help="run the server's loop thread and ZeroMQ's I/O threads on CPU N (Linux): a lockstep round "
                   "trip is shorter when they share a core (README 'Lockstep latency'); the ray engine's threads "
                   "still use every core")
    p.add_argument("--topics", nargs="+", metavar="TOPIC",
                   help="with --record: only these topics (names, prefixes, globs); they are computed even "
                   "without subscribers (default: every topic)")


def z85_hex(key: bytes) -> str:
    """A Z85 key as 64 hex digits: safe to paste into a shell (Z85 has $, &, quotes...)."""
    import zmq.utils.z85

    return zmq.utils.z85.decode(key).hex()


def keys(args: argparse.Namespace) -> int:
    """``sensorium keys DIR``: a CURVE key pair for ``serve --curve-keys DIR``."""
    from sensorium.server.daemon.transport import generate_curve_keys

    try:
        public = generate_curve_keys(args.dir, overwrite=args.force)
    except (OSError, ValueError) as exc:
        print(f"sensorium keys: {exc}", file=sys.stderr)
        return 1
    print(f"sensorium: wrote {args.dir}/server.key and {args.dir}/server.key_secret (keep it private); "
          f"serve with --curve-keys {args.dir}; clients need:", flush=True)
    print(f"SENSORIUM_CURVE_SERVERKEY={z85_hex(public)}", flush=True)
    return 0


def options(args: argparse.Namespace):
    """The parsed command line → :class:`sensorium.server.daemon.serve.ServeOptions`."""
    from sensorium.server.daemon.serve import ServeOptions

    return ServeOptions(rpc=args.rpc, pub=args.pub, mode=args.mode, precision=args.precision,
                        heartbeat_ms=args.heartbeat_ms, until=getattr(args, "until", None),
                        allow_large=getattr(args, "allow_large", False),
                        allow_outside_meshes=getattr(args, "allow_outside_meshes", False),
                        contact=False if getattr(args, "no_contact", False) else None,
                        controls=getattr(args, "controls", "auto"), curve_keys=getattr(args, "curve_keys", None),
                        watch=getattr(args, "watch", None), allow_skipped=getattr(args, "allow_skipped", False),
                        cpu=getattr(args, "cpu", None))


def main(args: argparse.Namespace) -> int:
    from sensorium.server.daemon.serve import Server
    from sensorium.server.daemon.transport import BIND_ERRORS, bind_problem
    from sensorium.server.world.loader import WorldError

    try:
        opts = options(args)
        opts.check()
    except ValueError as exc:
        print(f"sensorium serve: {exc}", file=sys.stderr)
        return 2
    record = getattr(args, "record", None)
    if not record:          # options of the recording, given without one, did nothing without a word
        given = [flag for flag, on in (("--topics", getattr(args, "topics", None)), ("--force", getattr(args, "force", False)),
                                       ("--record-format", getattr(args, "record_format", "foxglove") != "foxglove")) if on]
        if given:
            print(f"sensorium serve: {' and '.join(given)} {'is' if len(given) == 1 else 'are'} for --record FILE, "
                  "which is not given", file=sys.stderr)
            return 2
    if record and os.path.exists(record) and not getattr(args, "force", False):
        print(f"sensorium serve: {record} exists already; not overwriting (--force to replace it)", file=sys.stderr)
        return 1
    try:
        server = Server.open(args.world, opts)
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    except BIND_ERRORS as exc:          # address in use, bad endpoint
        print(f"sensorium serve: {bind_problem(exc)}", file=sys.stderr)
        return 1
    report = server.core.sim.loaded.report
    if report:          # what the load left out, once, before the ready line
        print(report.text(), file=sys.stderr, flush=True)
    named = [r for r in server.core.sim.loaded.world.robots if r.controller not in ("<extern>", "<none>")]
    if named:           # Webots would start these; `sensorium run` does
        which = ", ".join(f"robot {r.name!r} ({r.controller!r}"
                          + (f", controllerArgs `{shlex.join(r.controller_args)}`" if r.controller_args else "") + ")"
                          for r in named)
        one = len(named) == 1
        print(f"sensorium serve: {which}: `sensorium run WORLD` starts {'this controller' if one else 'these controllers'}"
              f"; here {'it is' if one else 'they are'} <extern> (start {'it' if one else 'each'} with "
              "`sensorium controller`, its controllerArgs after the script)", file=sys.stderr, flush=True)
    if server.transport.curve:
        from sensorium.server.daemon.transport import load_curve_keys

        public = load_curve_keys(args.curve_keys)[0]
        print(f"sensorium serve: CURVE on; clients need SENSORIUM_CURVE_SERVERKEY={z85_hex(public)}", file=sys.stderr)
    if getattr(args, "record", None):
        from sensorium.server.recording.envelope import unmatched_topics
        from sensorium.server.recording.writer import recorder_for_server

        problem = unmatched_topics(getattr(args, "topics", None), [t.name for t in server.core.topics.topics],
                                   f"world '{server.core.world_name}'")
        if problem:             # a typo would record nothing at all
            server.close()
            print(f"sensorium serve: {problem}", file=sys.stderr)
            return 1
        try:
            want_views = getattr(args, "record_format", "foxglove") == "foxglove"
            server.attach_recorder(recorder_for_server(args.record, server.core, getattr(args, "topics", None),
                                                       foxglove=want_views))
            if want_views and server.recorder.foxglove_unavailable:
                print(f"sensorium serve: recording without Foxglove views: {server.recorder.foxglove_unavailable}",
                      file=sys.stderr)
        except OSError as exc:
            server.close()
            print(f"sensorium serve: cannot record: {exc}", file=sys.stderr)
            return 1
    viewer = None
    if getattr(args, "foxglove", None):
        from sensorium.cli.foxglove_option import start_foxglove
        from sensorium.server.viewer.bridge import FoxgloveBridge

        viewer = start_foxglove("serve", args.foxglove,
                                lambda host, port: FoxgloveBridge.for_core(server.core, server.transport, host, port))
        if viewer is None:
            server.close()
            return 1
    print(server.ready_line + (f" foxglove={viewer.url}" if viewer is not None else ""), flush=True)
    if viewer is not None and viewer.app_url():
        print(f"sensorium: Foxglove web app: {viewer.app_url()}", file=sys.stderr, flush=True)
    try:
        server.run()
    finally:
        if viewer is not None:
            viewer.close()
            print(f"sensorium: {viewer.report()}", file=sys.stderr, flush=True)
        if server.recorder is not None:
            print(f"sensorium: recorded {server.recorder.message_count} messages to {args.record}"
                  + (f" (stopped early: {server.recorder.failed})" if server.recorder.failed else ""),
                  file=sys.stderr, flush=True)
    core = server.core
    print(f"sensorium: stopped at {core.sim.time_ms} ms after {core.lockstep.steps} steps", file=sys.stderr, flush=True)
    return 0 if core.quit_status is None else core.quit_status & 0xFF     # simulationQuit(status), as Webots exits
