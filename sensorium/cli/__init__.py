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


@command("validate", "check a world file; exit 1 listing every problem", "sensorium.cli.world:validate")
def _validate_args(p: argparse.ArgumentParser) -> None:
    from sensorium.cli.serve import add_world_options

    p.add_argument("world", nargs="+", help="world file(s): YAML, JSON or Webots .wbt")
    add_world_options(p)
    p.add_argument("--allow-skipped", action="store_true",
                   help="exit 0 although the world lost a robot, a sensor device or a shape sensors see (listed)")
    p.add_argument("--every", action="store_true",
                   help="one line for each loss and warning, where repeats are folded into one line with their count")


@command("convert", "write a Webots world (.wbt) as an equivalent Sensorium world file",
         "sensorium.cli.convert:convert")
def _convert_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", help="Webots world file (.wbt, R2021c or later; R2020b-R2021b converted as Webots does)")
    p.add_argument("out", help="output world file (.yaml, .yml or .json; '-' = YAML on standard output)")
    p.add_argument("--force", action="store_true", help="overwrite OUT if it exists")


@command("info", "summarise a world file (or a .mcap recording)", "sensorium.cli.world:info")
def _info_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("path", nargs="?", help="world file or .mcap recording (default: the embedded arena world)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


@command("snapshot", "picture a world from its Viewpoint on the CPU (PNG or JPEG), with no GPU and no server",
         "sensorium.cli.snapshot:snapshot")
def _snapshot_args(p: argparse.ArgumentParser) -> None:
    from sensorium.cli.serve import add_world_options

    p.add_argument("world", help="world file: YAML, JSON or Webots .wbt")
    p.add_argument("out", help="the picture to write: .png, .jpg or .jpeg")
    p.add_argument("--size", default="640x480", metavar="WxH", help="image size in pixels (default 640x480)")
    p.add_argument("--steps", type=int, default=0, help="basic steps to run first (default 0)")
    p.add_argument("--quality", type=int, default=95, help="JPEG quality 1..100 (default 95)")
    p.add_argument("--force", action="store_true", help="overwrite OUT if it exists")
    add_world_options(p)


@command("probe", "run a world in-process and print what enabled devices read", "sensorium.cli.world:probe")
def _probe_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", nargs="?", help="world file (default: the embedded arena world)")
    p.add_argument("--steps", type=int, default=3, help="basic steps to run (default 3)")
    p.add_argument("--enable", action="append", default=[], metavar="ROBOT/DEVICE:PERIOD",
                   help="enable a device with a sampling period in ms (repeatable; 'all:PERIOD' enables every device)")
    p.add_argument("--point-cloud", action="append", default=[], metavar="ROBOT/DEVICE",
                   help="also enable a lidar's point cloud")
    p.add_argument("--precision", choices=["fast", "exact"], default="exact")
    p.add_argument("--json", action="store_true", help="JSON lines: step, time, robot, device, value or array summary")
    from sensorium.cli.serve import add_world_options

    add_world_options(p)


@command("controller", "run a Webots-style controller (Python script or compiled binary) for a robot of a running server",
         "sensorium.cli.client:controller")
def _controller_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("script", help="controller: a Python script (uses `from controller import Robot`), an executable "
                   "(e.g. a C controller linked against sensorium/client/c), or example:NAME for a bundled example "
                   "(example:light_follower, example:wanderer, example:braitenberg, example:line_follower, "
                   "example:pen_drawer, example:blob_follower)")
    p.add_argument("--robot", help="robot name (default: the URL's robot, or the world's only robot)")
    p.add_argument("--url", help="RPC endpoint or controller URL, e.g. tcp://127.0.0.1:5560 or "
                   "tcp://host:5560/epuck (default: $SENSORIUM_CONTROLLER_URL, $WEBOTS_CONTROLLER_URL, "
                   "tcp://127.0.0.1:5560)")
    p.add_argument("args", nargs=argparse.REMAINDER,
                   help="arguments for the script (sys.argv[1:]); --robot/--url may also follow SCRIPT, "
                   "and '--' ends them")


@command("echo", "print the messages of topics (or of every topic under a PREFIX/) as YAML, in the order published",
         "sensorium.cli.topics:echo")
def _echo_args(p: argparse.ArgumentParser) -> None:
    from sensorium.cli.topics import add_endpoint_args

    p.add_argument("topics", nargs="+", metavar="TOPIC",
                   help="topic, e.g. /epuck/ps0/value; a name ending in '/' is a prefix, '' is all")
    add_endpoint_args(p)
    p.add_argument("--count", type=at_least(1), metavar="N", help="stop after N messages")
    p.add_argument("--full", action="store_true", help="print arrays in full (default: summarised)")
    p.add_argument("--json", action="store_true", help="one JSON object per message (arrays in full)")


@command("hz", "measure the rate of topics (like ros2 topic hz)", "sensorium.cli.topics:hz")
def _hz_args(p: argparse.ArgumentParser) -> None:
    from sensorium.cli.topics import add_endpoint_args

    p.add_argument("topics", nargs="+", metavar="TOPIC", help="topics (a name ending in '/' is a prefix)")
    add_endpoint_args(p)
    p.add_argument("--window", type=at_least(1), default=1000, metavar="N", help="messages per statistic (default 1000)")
    p.add_argument("--every", type=positive_seconds, default=1.0, metavar="S", help="report every S seconds (default 1)")
    p.add_argument("--duration", type=positive_seconds, metavar="S", help="stop after S seconds (default: until Ctrl-C)")
    p.add_argument("--json", action="store_true", help="one JSON object per topic and report")


@command("topics", "list a running server's topics and their types", "sensorium.cli.topics:topics")
def _topics_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--url", help="RPC endpoint (default tcp://127.0.0.1:5560)")
    p.add_argument("--timeout", type=positive_seconds, default=5.0, help="seconds to wait for the server (default 5)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


@command("services", "list a running server's services with their arguments (like ros2 service list -t)",
         "sensorium.cli.services:services")
def _services_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--url", help="RPC endpoint (default tcp://127.0.0.1:5560)")
    p.add_argument("--robot", help="only this robot's services ('server': the server's own)")
    p.add_argument("--timeout", type=positive_seconds, default=5.0, help="seconds to wait for the server (default 5)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


@command("call", "call one service of a running server (like ros2 service call)", "sensorium.cli.services:call")
def _call_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("service", help="service name, e.g. get_info, set_mode, /epuck/robot/get_pose")
    p.add_argument("args", nargs="?", help="arguments as JSON or YAML flow style, e.g. '{mode: fast}'")
    p.add_argument("--url", help="RPC endpoint (default tcp://127.0.0.1:5560)")
    p.add_argument("--timeout", type=positive_seconds, default=5.0, help="seconds to wait for the reply (default 5)")
    p.add_argument("--full", action="store_true", help="print arrays in full (default: summarised)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


@command("window", "send a text to a robot's controller as its robot window would (wwiReceiveText reads it)",
         "sensorium.cli.services:window")
def _window_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("robot", help="the robot whose controller receives the text")
    p.add_argument("text", help="the text (one wwiReceiveText call returns it)")
    p.add_argument("--url", help="RPC endpoint (default tcp://127.0.0.1:5560)")
    p.add_argument("--timeout", type=positive_seconds, default=5.0, help="seconds to wait for the reply (default 5)")


# --- recording: record / replay / export / recover (cli/recording.py) ---
@command("record", "record a running server's topics to MCAP as a subscriber (reports gaps)",
         "sensorium.cli.recording:record")
def _record_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="output .mcap file")
    p.add_argument("--url", metavar="URL",
                   help="the server's RPC endpoint (its topic endpoint comes from get_info; default tcp://127.0.0.1:5560)")
    p.add_argument("--connect", metavar="URL", help=argparse.SUPPRESS)      # deprecated spelling of --url
    p.add_argument("--pub", metavar="URL", help="subscribe to this topic endpoint instead of asking the server")
    p.add_argument("--topics", nargs="+", metavar="TOPIC",
                   help="record only these topics: exact names, path prefixes (/epuck) or globs (/epuck/ps*)")
    p.add_argument("--world", metavar="FILE", help="world file to attach to the recording")
    p.add_argument("--duration", type=positive_seconds, metavar="S", help="stop after S wall-clock seconds")
    p.add_argument("--max-messages", type=at_least(1), metavar="N", help="stop after N messages")
    p.add_argument("--rcvhwm", type=at_least(0), default=1000, help="receive high-water mark, messages (default 1000)")
    p.add_argument("--chunk-size", type=at_least(1), default=1 << 20, help="MCAP chunk size in bytes (default 1 MiB)")
    p.add_argument("--json", action="store_true", help="print the final summary as JSON")
    p.add_argument("--force", action="store_true", help="overwrite FILE if it exists")


def _seconds(text: str) -> float:
    """A finite number >= 0 (seconds, a rate): NaN and inf ended replay and export in a traceback."""
    value = float(text)
    if not 0 <= value < float("inf"):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


def positive_seconds(text: str) -> float:
    """A finite number > 0 (a timeout, a duration, a period, a frequency)."""
    value = float(text)
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def at_least(low: int) -> Callable[[str], int]:
    """An integer >= ``low`` (a count, a window, a size)."""
    def parse(text: str) -> int:
        value = int(text)
        if value < low:
            raise argparse.ArgumentTypeError(f"must be an integer >= {low}, got {text!r}")
        return value
    parse.__name__ = "integer"          # argparse's "invalid integer value: 'x'" for a non-number
    return parse


@command("replay", "republish a recording like a live server (free-running or lockstep)",
         "sensorium.cli.recording:replay_cmd")
def _replay_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="recording (.mcap)")
    p.add_argument("--rate", type=_seconds, default=1.0, help="speed factor (default 1; 0 = as fast as possible)")
    p.add_argument("--loop", action="store_true", help="start over at the end")
    p.add_argument("--topics", nargs="+", metavar="TOPIC", help="replay only these topics (names, prefixes, globs)")
    p.add_argument("--start", type=_seconds, metavar="S", help="start at S seconds of simulation time")
    p.add_argument("--end", type=_seconds, metavar="E", help="stop after E seconds of simulation time")
    p.add_argument("--clock", type=positive_seconds, nargs="?", const=40.0, metavar="HZ",
                   help="publish /clock (rosgraph_msgs/Clock) at HZ wall-clock Hz (default 40) instead of a recorded /clock")
    p.add_argument("--lockstep", action="store_true",
                   help="publish only when a client calls /replay/step {duration} (see PROTOCOL.md, Replay)")
    p.add_argument("--pub", default="tcp://127.0.0.1:5561", help="topic endpoint to bind (default tcp://127.0.0.1:5561)")
    p.add_argument("--rpc", default="tcp://127.0.0.1:5560", help="service endpoint to bind (default tcp://127.0.0.1:5560)")
    p.add_argument("--foxglove", metavar="[HOST:]PORT",
                   help="also serve the replay to Foxglove (WebSocket) on PORT, host 127.0.0.1 unless given")
    p.add_argument("--wait", action="store_true", help="wait for a first subscriber before starting")
    p.add_argument("--delay", type=_seconds, default=0.0, metavar="S", help="wait S seconds before starting (and between loops)")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress line on stderr (default: on a terminal, for long files)")
    p.add_argument("--sndhwm", type=at_least(0), default=1000, help="send high-water mark per subscriber (default 1000)")
    p.add_argument("--nodrop", action="store_true", help="wait for slow subscribers instead of dropping messages")


@command("export", "convert a recording to ROS 2 (CDR, MCAP storage) for ros2 bag play and Foxglove",
         "sensorium.cli.recording:export_cmd")
def _export_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="recording (.mcap)")
    p.add_argument("out", help="output: a rosbag2 directory, or a single file if it ends in .mcap")
    p.add_argument("--ros2", action="store_true", help="export as ROS 2 messages (CDR)")
    p.add_argument("--distro", choices=["humble", "jazzy"], default="jazzy",
                   help="message definitions (humble has no Range.variance; default jazzy)")
    p.add_argument("--format", choices=["bag", "mcap"], help="bag: rosbag2 directory (rosbags); mcap: one file "
                   "(mcap-ros2-support); default from OUT's suffix")
    p.add_argument("--pointcloud2", action="store_true", help="export PointCloud as PointCloud2 (x, y, z, layer)")
    p.add_argument("--no-views", action="store_true",
                   help="only the recorded topics (no /tf_static, /tf and /scene from the recorded world)")
    p.add_argument("--topics", nargs="+", metavar="TOPIC", help="export only these topics")
    p.add_argument("--start", type=_seconds, metavar="S", help="from S seconds of simulation time")
    p.add_argument("--end", type=_seconds, metavar="E", help="up to E seconds of simulation time")
    p.add_argument("--force", action="store_true",
                   help="overwrite OUT if it exists (a file or a rosbag2 directory; replaced only once the new "
                   "export is complete)")


@command("recover", "rewrite a truncated recording (writer killed, disk full) as a complete, indexed MCAP file",
         "sensorium.cli.recording:recover_cmd")
def _recover_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="recording (.mcap), e.g. one whose writer was killed")
    p.add_argument("out", nargs="?", help="output file (default: FILE with -recovered before the suffix)")
    p.add_argument("--force", action="store_true", help="overwrite OUT if it exists")
# --- end recording ---


# --- server: keys, serve, layout, schemas, demo ---
@command("keys", "create a CURVE key pair for serve --curve-keys DIR (encrypted, authenticated tcp)",
         "sensorium.cli.serve:keys")
def _keys_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", help="directory for server.key (public) and server.key_secret (created if missing)")
    p.add_argument("--force", action="store_true", help="replace an existing key pair")


@command("serve", "serve a world to controllers (services) and subscribers (topics) over ZeroMQ",
         "sensorium.cli.serve:main")
def _serve_args(p: argparse.ArgumentParser) -> None:
    from sensorium.cli.serve import add_arguments

    add_arguments(p)


@command("run", "open a Webots project headless: serve the world and start every robot's controller named in it",
         "sensorium.cli.run:main")
def _run_args(p: argparse.ArgumentParser) -> None:
    from sensorium.cli.run import add_arguments

    add_arguments(p)


@command("layout", "write a Foxglove layout (3D, plots, image, raw messages) for a recording or world file",
         "sensorium.cli.viewer:layout_cmd")
def _layout_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("source", nargs="?", help="a recording (.mcap) or a world file (default: the embedded arena world)")
    p.add_argument("-o", "--out", metavar="FILE.json", help="write here instead of standard output")
    p.add_argument("--force", action="store_true", help="replace FILE.json if it exists")


@command("schemas", "write the JSON Schemas of world files, topic messages and services",
         "sensorium.schemas.export:main")
def _schemas_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", metavar="DIR", help="output directory (default: the package's schemas/json)")
    p.add_argument("--check", action="store_true", help="write nothing; exit 1 if the files in DIR are out of date")


@command("demo", "run the server, two example controllers and a recording on the default world",
         "sensorium.cli.demo:main")
def _demo_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("world", nargs="?", help="world file (default: the embedded arena world)")
    p.add_argument("--duration", type=float, default=60.0, metavar="S", help="simulated seconds (default 60)")
    p.add_argument("--out", default="sensorium-demo", metavar="DIR", help="where the recording, picture and logs go "
                   "(a previous demo's are replaced)")
    p.add_argument("--force", action="store_true", help="replace files of the same names in DIR that no demo wrote")
    p.add_argument("--precision", choices=["fast", "exact"], default="exact")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: only on a terminal)")


# --- sweeps: sweep (sensorium/sweep/) ---
@command("sweep", "run many simulations (worlds x parameters x controllers x seeds) on Ray or a process pool",
         "sensorium.cli.sweep:main")
def _sweep_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", help="sweep spec, YAML or JSON (see README 'Training and sweeps')")
    p.add_argument("--out", default="sweep-out", metavar="DIR",
                   help="recordings (DIR/runs/NNNN.mcap) and tables (DIR/summary.csv, .parquet); default sweep-out")
    p.add_argument("--engine", choices=["auto", "local", "ray"], default="auto",
                   help="ray: Ray tasks; local: a process pool; auto (default): ray when installed")
    p.add_argument("--workers", type=int, metavar="N", help="processes / Ray CPUs on this machine (default: all CPUs)")
    p.add_argument("--address", metavar="ADDR", help="join this Ray cluster ('auto', 'HOST:6379', 'ray://HOST:10001') "
                   "instead of starting a local Ray bound to 127.0.0.1")
    p.add_argument("--format", action="append", choices=["csv", "parquet"], metavar="FMT",
                   help="table format, repeatable (csv, parquet; default both, csv only without pyarrow)")
    p.add_argument("--no-record", action="store_true", help="no recordings, summary rows only")
    p.add_argument("--overwrite", action="store_true", help="replace the tables and recordings of an earlier sweep in DIR")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress bar on stderr (default: on a terminal)")
    p.add_argument("--json", action="store_true", help="print the sweep summary as JSON")
# --- end sweeps ---


# --- benchmarks: bench (benchmarks/, installed as sensorium.benchmarks) ---
@command("bench", "measure accuracy vs time of every knob, scaling, peers and transport; write docs/benchmarks.md",
         "sensorium.cli.bench:main")
def _bench_args(p: argparse.ArgumentParser) -> None:
    try:
        from sensorium.cli.bench import add_arguments
    except ImportError:      # benchmarks/ not installed: keep every other command working
        return
    add_arguments(p)
# --- end benchmarks ---


# commands that load a world: where a .wbt world's PROTO files are found (the one place these are declared)
WORLD_COMMANDS = {"validate", "convert", "info", "probe", "snapshot", "serve", "run", "layout", "demo", "sweep", "record",
                  "replay", "export"}


def _add_proto_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--webots-home", metavar="DIR",
                   help="Webots installation whose PROTOs and assets a .wbt world uses (default: $WEBOTS_HOME); "
                   "nothing is ever downloaded")
    p.add_argument("--proto-path", action="append", default=[], metavar="DIR",
                   help="more folders to find PROTO files in (repeatable): a project's protos/, a copy of Webots' "
                   "tree, an unpacked assets-RELEASE.zip (also $SENSORIUM_PROTO_PATH)")
    p.add_argument("--extra-project-path", action="append", default=[], metavar="DIR",
                   help="a Webots project folder whose protos/ (and, for `run`, controllers/) are looked in after "
                   "the world's own, as Webots' extra project paths (repeatable; also $WEBOTS_EXTRA_PROJECT_PATH)")


def _export_proto_args(args: argparse.Namespace) -> None:
    """--webots-home/--proto-path/--extra-project-path become WEBOTS_HOME/SENSORIUM_PROTO_PATH/
    WEBOTS_EXTRA_PROJECT_PATH, so every load of a world in this command (and the processes it starts)
    finds the same PROTOs."""
    import os

    if getattr(args, "webots_home", None):
        os.environ["WEBOTS_HOME"] = args.webots_home
    if getattr(args, "proto_path", None):
        before = [p for p in os.environ.get("SENSORIUM_PROTO_PATH", "").split(os.pathsep) if p]
        os.environ["SENSORIUM_PROTO_PATH"] = os.pathsep.join([*args.proto_path, *before])
    # Webots' extra project paths: the option's first, then $WEBOTS_EXTRA_PROJECT_PATH's; their protos/
    # folders are looked in by PROTO file name after every other proto path folder, as Webots looks there
    from sensorium.launch import EXTRA_ENV, EXTRA_MAX, extra_project_paths

    given = os.pathsep.join([*(getattr(args, "extra_project_path", None) or []), os.environ.get(EXTRA_ENV, "")])
    every = extra_project_paths(given, None)
    projects = every[:EXTRA_MAX]
    if len(every) > EXTRA_MAX:
        print(f"sensorium: {len(every)} extra project paths (--extra-project-path, ${EXTRA_ENV}): the first "
              f"{EXTRA_MAX} are read, not {every[EXTRA_MAX]} and the {len(every) - EXTRA_MAX - 1} after it",
              file=sys.stderr)
    if projects:
        os.environ[EXTRA_ENV] = os.pathsep.join(str(p) for p in projects)
        before = [p for p in os.environ.get("SENSORIUM_PROTO_PATH", "").split(os.pathsep) if p]
        protos = [str(p / "protos") for p in projects if (p / "protos").is_dir()]
        os.environ["SENSORIUM_PROTO_PATH"] = os.pathsep.join(dict.fromkeys([*before, *protos]))


def compiled_paths() -> list[str]:
    """Which optional compiled paths this installation runs, one line each, with why not: the
    lockstep's C step path (built by setup.py at install) and the ray engine's packet helper
    (packets.c, compiled on first use). Without them the same answers come from slower paths."""
    from sensorium.server.daemon.steppath import native_gate_class, step_path_choice
    from sensorium.server.raycast import packets

    gate, why = native_gate_class()
    try:
        if step_path_choice() == "python":
            gate, why = None, "SENSORIUM_STEP_PATH=python"
        step = f"C ({gate.__module__})" if gate is not None else f"Python ({why})"
    except ValueError as exc:
        step = f"none ({exc}: serve refuses to start)"
    return [f"step path: {step}", f"ray traversal: {packets.status()}"]


class _VersionAction(argparse.Action):
    """``--version``: the version, then :func:`compiled_paths` (worked out only when asked)."""

    def __init__(self, option_strings, dest, version: str, **kwargs):
        super().__init__(option_strings, dest, default=argparse.SUPPRESS, **kwargs)
        self.version = version

    def __call__(self, parser, namespace, values, option_string=None):
        print("\n".join([self.version, *compiled_paths()]), flush=True)
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="sensorium", description="Headless sensor simulator with Webots device semantics.")
    from sensorium import __version__

    parser.add_argument("--version", action=_VersionAction, nargs=0, version=f"sensorium {__version__}",
                        help="show the version and which compiled (C) paths are active, and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (help_text, add_args, target) in _COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        add_args(p)
        if name in WORLD_COMMANDS:
            _add_proto_args(p)
        p.set_defaults(_target=target)
    return parser


def one_line_warnings() -> None:
    """Sensorium's own warnings (``GroundWarning``, ``WorldLossWarning``: facts about the user's
    world) print as one line, ``sensorium: warning: ...``, not in Python's form (our source file,
    line and code); other libraries' warnings keep Python's form."""
    import warnings

    python_form = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if category.__module__.startswith("sensorium."):
            print(f"sensorium: warning: {message}", file=sys.stderr if file is None else file, flush=True)
        else:
            python_form(message, category, filename, lineno, file, line)

    warnings.showwarning = show


def main(argv: list[str] | None = None) -> int:
    import importlib

    from sensorium.cli.interrupts import Interrupts

    name = "sensorium"
    try:
        # Ctrl-C while the command line is parsed and the command's modules import (a second or
        # more): 130 and one line, never a traceback from inside an import nor an interrupt a
        # library's import guard swallows
        with Interrupts():
            parser = build_parser()
            args = parser.parse_args(argv)
            if not getattr(args, "_target", None):
                parser.print_help()
                return 2
            name = f"sensorium {args.command}"
            module_name, func_name = args._target.split(":")
            _export_proto_args(args)
            func: Handler = getattr(importlib.import_module(module_name), func_name)
        one_line_warnings()
        return int(func(args) or 0)
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr, flush=True)
        return 130
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    sys.exit(main())
