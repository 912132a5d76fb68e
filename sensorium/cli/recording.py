"""``sensorium record``, ``replay``, ``export``, ``recover`` and ``info FILE.mcap``: argparse shells over
:mod:`sensorium.server.recording` (live.py, replay.py, export.py, recover.py, reader.py).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
from collections.abc import Callable
from contextlib import contextmanager
from pathlib import Path

import zmq

from sensorium.server.recording.live import LiveRecorder
from sensorium.server.recording.reader import McapError, summarize
from sensorium.server.recording.scan import Damage


def file_error(path: str | os.PathLike, exc: BaseException) -> str:
    """One line for a file that cannot be read or written, naming it once (an ``OSError`` names
    its own file when it has one: the output, for a write that failed)."""
    if isinstance(exc, OSError) and exc.strerror:
        return f"{os.fspath(exc.filename)}: {exc.strerror}" if exc.filename is not None else exc.strerror
    name = os.fspath(path)
    text = str(exc)
    return text if text.startswith(name) else f"{name}: {text}"


def damage_printer(command: str, path: str | os.PathLike) -> Callable[[Damage], None]:
    """``on_damage`` for a reader: one warning line on stderr per damaged part skipped."""
    def say(damage: Damage) -> None:
        print(f"sensorium {command}: warning: {os.fspath(path)}: {damage.line()}", file=sys.stderr, flush=True)
    return say


@contextmanager
def _stop_signals(handler: Callable[[int, object], None]):
    """``handler`` for SIGTERM, SIGHUP and SIGINT in the block, the previous handlers put back after. SIGINT
    too because a shell script's background job starts with it ignored (``sensorium replay & ... kill
    -INT $!`` would do nothing), and ``serve`` answers it there as well."""
    previous: dict = {}
    for sig in (signal.SIGTERM, getattr(signal, "SIGHUP", None), signal.SIGINT):
        if sig is not None:
            try:
                previous[sig] = signal.signal(sig, handler)
            except ValueError:  # not the main thread
                pass
    try:
        yield
    finally:
        for sig, h in previous.items():
            signal.signal(sig, h)


@contextmanager
def signals_as_interrupt():
    """SIGTERM, SIGHUP and SIGINT raise KeyboardInterrupt, so files get finished."""
    def handler(signum, frame):
        raise KeyboardInterrupt

    with _stop_signals(handler):
        yield


@contextmanager
def signals_as_stop(stop: Callable[[], None]):
    """SIGTERM, SIGHUP and SIGINT latched: the first calls ``stop`` and the loop ends at its next safe
    point, so a message it wrote is also counted (a KeyboardInterrupt landing between the write and the
    count made ``sensorium record``'s summary one short of its file); a second one raises
    KeyboardInterrupt, for a loop that reaches no safe point (a write that blocks)."""
    stopping = False

    def handler(signum, frame):
        nonlocal stopping
        if stopping:
            raise KeyboardInterrupt
        stopping = True
        stop()

    with _stop_signals(handler):
        yield


def record(args: argparse.Namespace) -> int:
    if Path(args.file).exists() and not args.force:
        print(f"sensorium record: {args.file} exists already; not overwriting (--force to replace it)", file=sys.stderr)
        return 1
    if args.connect:
        print("sensorium record: --connect is deprecated: use --url (the server's RPC endpoint, as for every "
              "client command)", file=sys.stderr)
    connect = args.url or args.connect or "tcp://127.0.0.1:5560"
    ctx: zmq.Context = zmq.Context.instance()
    rec = LiveRecorder(args.file, connect=connect, pub=args.pub, topics=args.topics or None, world=args.world,
                       chunk_size=args.chunk_size, rcvhwm=args.rcvhwm, context=ctx)
    try:
        rec.open()
    except (TimeoutError, RuntimeError, KeyError, ValueError, OSError, zmq.ZMQError) as exc:
        print(f"sensorium record: {exc}", file=sys.stderr)
        return 1
    print(f"sensorium: recording {args.file} from pub={rec.pub_endpoint}"
          + (f" topics={' '.join(args.topics)}" if args.topics else ""), flush=True)
    try:
        with signals_as_stop(rec.stop):     # it stops between two messages (LiveRecorder.run's safe points)
            rec.run(duration=args.duration, max_messages=args.max_messages)
    except KeyboardInterrupt:
        pass
    finally:
        s = rec.close()
    if args.json:
        print(json.dumps(s), flush=True)
    else:
        lost = "" if not s["lost"] else ", " + ", ".join(f"{t}: {n}" for t, n in s["lost_by_topic"].items())
        print(f"sensorium: recorded {s['received']} messages on {s['topics']} topics to {s['file']}; "
              f"{s['gaps']} gaps, {s['lost']} messages lost{lost}"
              + (f"; the server restarted {s['restarts']} time(s): files {', '.join(s['files'])}" if s["restarts"] else ""),
              flush=True)
    return 1 if rec.recorder is not None and rec.recorder.failed else 0


# ------------------------------------------------------------------------------------ replay


def replay_cmd(args: argparse.Namespace) -> int:
    from sensorium.server.recording.replay import Replayer

    try:
        r = Replayer(args.file, pub=args.pub, rpc=args.rpc, rate=args.rate, loop=args.loop,
                     topics=args.topics or None, start_s=args.start, end_s=args.end, clock_hz=args.clock,
                     lockstep=args.lockstep, progress=args.progress, wait_subscriber=args.wait,
                     delay_s=args.delay, sndhwm=args.sndhwm, nodrop=args.nodrop,
                     on_damage=damage_printer("replay", args.file))
    except (OSError, McapError) as exc:
        print(f"sensorium replay: {file_error(args.file, exc)}", file=sys.stderr)
        return 1
    except ValueError as exc:
        print(f"sensorium replay: {exc}", file=sys.stderr)
        return 1
    viewer = None
    try:
        try:
            r.bind()
        except zmq.ZMQError as exc:
            from sensorium.server.daemon.transport import bind_problem
            print(f"sensorium replay: {bind_problem(exc)}", file=sys.stderr)
            return 1
        viewer = None
        if getattr(args, "foxglove", None):
            from sensorium.cli.foxglove_option import start_foxglove
            from sensorium.server.viewer.bridge import FoxgloveBridge

            viewer = start_foxglove("replay", args.foxglove, lambda host, port: FoxgloveBridge.for_replay(r, host, port))
            if viewer is None:
                return 1
            print(f"sensorium: Foxglove viewer at {viewer.url}", flush=True)
            if viewer.app_url():
                print(f"sensorium: Foxglove web app: {viewer.app_url()}", file=sys.stderr, flush=True)
        interrupted = False
        try:                    # Ctrl-C from the announcement on (scripts send it once they read it)
            with signals_as_interrupt():
                print(r.announce(), flush=True)
                if r.recording.truncated:
                    print("sensorium: warning: the recording is truncated; replaying up to its last complete "
                          "record", file=sys.stderr)
                r.run()
        except KeyboardInterrupt:
            interrupted = True
        if interrupted or r.interrupted:
            print(f"sensorium: replay interrupted after {r.emitted} messages", file=sys.stderr, flush=True)
        else:
            print(f"sensorium: replay finished: {r.emitted} messages", file=sys.stderr, flush=True)
        return 0
    finally:
        if viewer is not None:
            viewer.close()
            print(f"sensorium: {viewer.report()}", file=sys.stderr, flush=True)
        r.close()


# ------------------------------------------------------------------------------------ export


def export_cmd(args: argparse.Namespace) -> int:
    """``sensorium export``. Ctrl-C (SIGTERM, SIGHUP) at any moment exits 130 with one line and no
    partial output, also while a library imports (cli/interrupts.py: none can swallow it)."""
    from sensorium.cli.interrupts import Interrupts

    if not args.ros2:
        print("sensorium export: say which format: --ros2 (the only one so far)", file=sys.stderr)
        return 2
    existed = os.path.lexists(args.out)     # with --force: an interrupted export leaves it as it was
    signals = tuple(s for s in (signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGHUP", None)) if s is not None)
    progress = None
    try:
        with Interrupts(signals) as ctrl:   # what was written is removed, as for Ctrl-C
            from sensorium.cli.progress import bar
            from sensorium.server.recording.export import ExportError, export_ros2, print_report, truncation_warning

            progress = bar(None, "export", "msg")

            def advance(done: int, total: int) -> None:
                ctrl.check()                # an interrupt a library caught stops the export here
                if total and getattr(progress, "total", None) != total:
                    progress.total = total
                progress.update(1)

            try:
                report = export_ros2(args.file, args.out, distro=args.distro, fmt=args.format,
                                     pointcloud2=args.pointcloud2, topics=args.topics or None,
                                     views=not getattr(args, "no_views", False),
                                     start_ns=None if args.start is None else int(round(args.start * 1e9)),
                                     end_ns=None if args.end is None else int(round(args.end * 1e9)),
                                     progress=advance, on_damage=damage_printer("export", args.file),
                                     overwrite=getattr(args, "force", False))
            except (OSError, McapError) as exc:
                progress.close()
                print(f"sensorium export: {file_error(args.file, exc)}", file=sys.stderr)
                return 1
            except ExportError as exc:
                progress.close()
                print(f"sensorium export: {exc}", file=sys.stderr)
                return 1
            progress.close()
            if ctrl.received:               # arrived after the last message, or a library caught it
                print(f"sensorium export: interrupted after the export completed; {args.out} is complete",
                      file=sys.stderr)
                return 130
    except KeyboardInterrupt:
        if progress is not None:
            progress.close()
        kept = "left as it was" if existed else "removed"
        print(f"sensorium export: interrupted; {args.out} {kept} (nothing partial is kept)", file=sys.stderr)
        return 130
    warning = truncation_warning(report)
    if warning:
        print(f"sensorium export: {warning}", file=sys.stderr, flush=True)
    print_report(report)
    return 0


# ------------------------------------------------------------------------------------ info


def recover_cmd(args: argparse.Namespace) -> int:
    """``sensorium recover FILE [OUT]``: exit 0 with a one-line summary, or 1 with one error line."""
    from sensorium.server.recording.recover import recover

    try:
        with signals_as_interrupt():    # SIGTERM/SIGHUP too: OUT.part is removed, as for Ctrl-C
            r = recover(args.file, args.out, overwrite=args.force, on_damage=damage_printer("recover", args.file))
    except (FileExistsError, ValueError) as exc:
        print(f"sensorium recover: {exc}", file=sys.stderr)
        return 1
    except (OSError, McapError) as exc:
        print(f"sensorium recover: {file_error(args.file, exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("sensorium recover: interrupted; nothing written", file=sys.stderr)
        return 130
    state = f"truncated, read up to its last complete record ({r.stopped})" if r.stopped else (
        "truncated (no summary or footer)" if r.truncated else "complete")
    if r.damaged:
        state += f"; {len(r.damaged)} damaged part{'s' if len(r.damaged) != 1 else ''} skipped"
    extra = f" (and {r.views} Foxglove view messages)" if r.views else ""
    lost = (f"; {r.unnamed} message records dropped: their channel was defined only in a damaged chunk"
            if r.unnamed else "")
    print(f"sensorium: recovered {r.messages} messages{extra} on {r.channels} channels, {r.metadata} metadata "
          f"records, {r.attachments} attachments from {args.file} ({state}) into {r.out}{lost}", flush=True)
    return 0


def _human_size(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n} B"  # pragma: no cover


def _secs(ns: int | None) -> str:
    return "-" if ns is None else f"{ns / 1e9:.3f} s"


def print_info(path: str | os.PathLike, as_json: bool = False) -> int:
    """``sensorium info FILE.mcap``: like ``ros2 bag info``. Exit 0, or 1 if the file is unreadable."""
    try:
        s = summarize(path)
    except (OSError, McapError) as exc:
        print(f"sensorium info: {file_error(path, exc)}", file=sys.stderr)
        return 1
    if as_json:
        print(json.dumps(s, indent=2))
        return 0
    meta = s["metadata"].get("sensorium", {})
    session = s["metadata"].get("session", {})
    lines = [
        ("Files", s["path"]),
        ("Bag size", _human_size(s["size_bytes"])),
        ("Storage id", f"mcap (profile {s['profile'] or '-'!s}, {s['library'] or '-'})"),
        ("Truncated", "YES: " + s.get("note", "") if s["truncated"] else "no"),
        ("Duration", f"{s['duration_s']:.3f} s"),
        ("Start", f"{_secs(s['start_ns'])} (simulation time)"),
        ("End", f"{_secs(s['end_ns'])} (simulation time)"),
        ("Messages", str(s["messages"])),
        ("Chunks", f"{s['chunks']} ({', '.join(s['compression']) or '-'})"),
    ]
    if meta:
        world = meta.get("world") or meta.get("world_file") or "-"
        lines.append(("World", f"{world}   seed {meta.get('seed', '-')}   time step "
                               f"{meta.get('basic_time_step_ms', '-')} ms   sensorium {meta.get('version', '-')}"))
        scene = [t for t in ("/tf", "/scene") if t in s["channels"]]
        lines.append(("Foxglove", f"ready (ROS 2 CDR views{''.join(', ' + t for t in scene)}; bodies kept byte "
                                  "for byte)" if meta.get("format") == "2" else
                      "no (msgpack only: export with sensorium export --ros2)"))
    if session.get("started_at"):
        lines.append(("Recorded", session["started_at"]))
    if session.get("previous_file"):
        lines.append(("Continues from", f"{session['previous_file']} (the server restarted; record --url)"))
    restart = s["metadata"].get("server_restart", {})
    if restart.get("next_file"):
        lines.append(("Continues in", f"{restart['next_file']} (the server restarted: {restart.get('topic', '?')} "
                                      f"went back to {_secs(int(restart.get('stamp_ns', 0) or 0))})"))
    for a in s["attachments"]:
        lines.append(("Attachment", f"{a['name']} ({a['media_type']}, {_human_size(a['size_bytes'])})"))
    damaged = s["damaged"]
    if damaged:
        lines.insert(4, ("Damaged", f"{len(damaged)} part{'s' if len(damaged) != 1 else ''} skipped by every "
                                    "reader (not counted below):"))
        for k, line in enumerate(damaged):
            lines.insert(5 + k, ("", line))
    if s.get("unnamed_messages"):
        lines.append(("Unnamed", f"{s['unnamed_messages']} message records on channels defined only in a "
                                 "damaged chunk (bodies or Foxglove views: not counted)"))
    if s.get("foreign"):            # a ROS 2 bag: its messages are none of the published bodies counted here
        lines.insert(0, ("Not Sensorium", s["foreign"]))
    for key, value in lines:
        print(f"{key + ':' if key else '':<19}{value}")
    topics = s["topics"]
    width = max((len(t["topic"]) for t in topics), default=0)
    twidth = max((len(t["type"]) for t in topics), default=0)
    print(f"{'Topic information:':<19}{len(topics)} topic{'s' if len(topics) != 1 else ''}")
    for t in topics:
        rate = "-" if t["rate_hz"] is None else f"{t['rate_hz']:.2f} Hz"
        print(f"  Topic: {t['topic']:<{width}} | Type: {t['type']:<{twidth}} | Count: {t['count']:>7} | "
              f"Rate: {rate:>10} | Serialization Format: {t['encoding']}")
    return 0


def bag_summary(path: str | os.PathLike) -> dict:
    """A rosbag2 directory's ``metadata.yaml`` in the shape of a recording summary (raises
    OSError/ValueError when the directory is no bag)."""
    import yaml

    meta_path = Path(path) / "metadata.yaml"
    if not meta_path.is_file():
        raise ValueError(f"{path} is a directory without metadata.yaml: neither a world file, an MCAP "
                         "recording nor a rosbag2 bag")
    try:
        info = (yaml.safe_load(meta_path.read_text()) or {}).get("rosbag2_bagfile_information")
    except yaml.YAMLError as exc:
        raise ValueError(f"{meta_path}: not valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(info, dict):
        raise ValueError(f"{meta_path}: no rosbag2_bagfile_information: not a rosbag2 bag")
    start = (info.get("starting_time") or {}).get("nanoseconds_since_epoch")
    duration = (info.get("duration") or {}).get("nanoseconds", 0)
    topics = [{"topic": t["topic_metadata"]["name"], "type": t["topic_metadata"]["type"],
               "count": t.get("message_count", 0)} for t in info.get("topics_with_message_count", [])]
    return {"path": str(path), "kind": "rosbag2", "version": info.get("version"),
            "storage": info.get("storage_identifier"), "files": info.get("relative_file_paths", []),
            "messages": info.get("message_count", 0), "start_ns": start, "duration_s": duration / 1e9,
            "topics": sorted(topics, key=lambda t: t["topic"]), "custom_data": info.get("custom_data") or {}}


def print_bag_info(path: str | os.PathLike, as_json: bool = False) -> int:
    """``sensorium info BAG_DIR``: a rosbag2 directory (e.g. what ``sensorium export`` wrote)."""
    try:
        s = bag_summary(path)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print(f"sensorium info: {exc}", file=sys.stderr)
        return 1
    if as_json:
        print(json.dumps(s, indent=2))
        return 0
    print(f"rosbag2   {s['path']}  (ROS 2 bag, storage {s['storage']}, version {s['version']}; "
          f"play it with ros2 bag play)")
    print(f"files     {', '.join(s['files'])}")
    print(f"duration  {s['duration_s']:.3f} s   start {_secs(s['start_ns'])}   messages {s['messages']}")
    width = max((len(t["topic"]) for t in s["topics"]), default=0)
    print(f"topics    {len(s['topics'])}")
    for t in s["topics"]:
        print(f"  {t['topic']:<{width}}  {t['count']:>7}  {t['type']}")
    return 0
