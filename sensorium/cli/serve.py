"""``sensorium serve``: load a world, bind the RPC and topic sockets, serve until SIGINT/SIGTERM.

Prints one line when ready, with the endpoints actually bound (port 0 or ``*`` picks a free
port), so scripts can wait for it::

    sensorium: serving world 'arena' rpc=tcp://127.0.0.1:5560 pub=tcp://127.0.0.1:5561
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["add_arguments", "main", "build"]

# kept equal to sensorium.server.daemon.transport.DEFAULT_*; not imported so that `sensorium --help` stays light
DEFAULT_RPC = "tcp://127.0.0.1:5560"
DEFAULT_PUB = "tcp://127.0.0.1:5561"


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
    p.add_argument("--until", type=int, metavar="MS",
                   help="quit when the simulated time reaches MS milliseconds (pending steps get -1)")
    p.add_argument("--record", metavar="FILE.mcap",
                   help="record the published messages from inside the step loop (nothing dropped)")
    p.add_argument("--record-format", choices=["foxglove", "msgpack"], default="foxglove",
                   help="with --record: foxglove (default; opens in Foxglove, the published bytes kept losslessly "
                   "beside ROS 2 CDR views, /tf and /scene) or msgpack (the published bytes only: ~2.4x smaller, "
                   "~7x cheaper to write)")
    p.add_argument("--foxglove", metavar="[HOST:]PORT",
                   help="also serve the topics, transforms and the world to Foxglove (WebSocket) on PORT, "
                   "host 127.0.0.1 unless given; port 0 picks a free port")
    p.add_argument("--topics", nargs="+", metavar="TOPIC",
                   help="with --record: only these topics (names, prefixes, globs); they are computed even "
                   "without subscribers (default: every topic)")


def build(args: argparse.Namespace):
    """World → simulation → core → bound transport (raises on a bad world or a busy port)."""
    from sensorium.server.daemon.services import Core
    from sensorium.server.daemon.transport import Transport
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import default_world_path

    path = Path(args.world) if args.world else default_world_path()
    sim = Simulation.from_file(path, precision=args.precision)
    core = Core(sim, heartbeat_ms=args.heartbeat_ms, mode=args.mode)
    return core, Transport(core, args.rpc, args.pub, stop_at_ms=getattr(args, "until", None))


def main(args: argparse.Namespace) -> int:
    from sensorium.server.world.loader import WorldError

    if args.heartbeat_ms <= 0:
        print("sensorium serve: --heartbeat-ms must be > 0", file=sys.stderr)
        return 2
    try:
        core, transport = build(args)
    except WorldError as exc:
        print(str(exc), file=sys.stderr)
        return 1
    except OSError as exc:          # zmq.ZMQError is an OSError: address in use, bad endpoint
        print(f"sensorium serve: cannot bind: {exc}", file=sys.stderr)
        return 1
    recorder = None
    if getattr(args, "record", None):                # recording (server/recording.py)
        from sensorium.server.recording.mcapfile import recorder_for_server
        try:
            recorder = recorder_for_server(args.record, core, getattr(args, "topics", None),
                                           foxglove=getattr(args, "record_format", "foxglove") == "foxglove")
            if recorder.foxglove_unavailable and getattr(args, "record_format", "foxglove") == "foxglove":
                print(f"sensorium serve: recording without Foxglove views: {recorder.foxglove_unavailable}",
                      file=sys.stderr)
        except OSError as exc:
            transport.close()
            print(f"sensorium serve: cannot record: {exc}", file=sys.stderr)
            return 1
    viewer = None
    if getattr(args, "foxglove", None):
        from sensorium.server.viewer.bridge import FoxgloveBridge, ViewerError, parse_address
        try:
            host, port = parse_address(args.foxglove)
            viewer = FoxgloveBridge.for_core(core, transport, host, port)
        except ViewerError as exc:
            transport.close()
            if recorder is not None:
                recorder.close()
            print(f"sensorium serve: {exc}", file=sys.stderr)
            return 1
    transport.install_signal_handlers()
    extra = f" foxglove={viewer.url}" if viewer is not None else ""
    print(f"sensorium: serving world '{core.world_name}' rpc={transport.rpc_endpoint} pub={transport.pub_endpoint}{extra}",
          flush=True)
    try:
        transport.run()
    finally:
        if viewer is not None:
            viewer.close()
        if recorder is not None:
            recorder.close()
            print(f"sensorium: recorded {recorder.message_count} messages to {args.record}", file=sys.stderr, flush=True)
    print(f"sensorium: stopped at {core.sim.time_ms} ms after {core.lockstep.steps} steps", file=sys.stderr, flush=True)
    return 0
