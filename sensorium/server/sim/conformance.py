"""The conformance vectors (``sensorium/schemas/conformance/``): the request/reply cases (written
from PROTOCOL.md, checked against the server by tests/test_conformance.py) and the expected readings of the conformance session (``sensorium/schemas/conformance/session.json``),
computed from the in-process :class:`~sensorium.server.sim.simulation.Simulation` alone, so they
do not depend on any client: a client that replays the session's script against ``sensorium serve
sensorium/schemas/conformance/world.yaml`` must print exactly these lines.

    python -m sensorium.server.sim.conformance            # exit 1 if a vector file is out of date
    python -m sensorium.server.sim.conformance --write    # regenerate them

The script language and the line format are described in the conformance README. The client
semantics the lines encode: a sensor's value is NaN (a lidar's buffers zeros) until it has
measured, each value is kept until the next measurement (also after ``disable``), a point cloud
is printed while the controller has it and the lidar enabled, motor commands apply from the next
step.
"""

from __future__ import annotations

import argparse
import json
import math
import struct
import sys
from pathlib import Path
from typing import Any

import sensorium.schemas as _schemas

CONFORMANCE_DIR = Path(_schemas.__file__).resolve().parent / "conformance"
WORLD = CONFORMANCE_DIR / "world.yaml"
SESSION = CONFORMANCE_DIR / "session.json"
REQUESTS = CONFORMANCE_DIR / "requests.json"
ROBOT = "rover"

# Sampling periods that are and are not multiples of the basic step (16 ms), a disable and a
# re-enable, the point cloud switched off and on, velocity then position control, steps of 1-3
# basic steps.
SCRIPT: list[str] = [
    "enable", "ir", "16", "enable", "sonar", "48", "enable", "eye", "40",
    "enable", "lidar", "32", "pc", "lidar",
    "enable", "left encoder", "16", "enable", "right encoder", "32",
    "pos", "left wheel motor", "inf", "pos", "right wheel motor", "inf",
    "vel", "left wheel motor", "3.0", "vel", "right wheel motor", "1.5",
    "step", "16", "5",
    "disable", "eye", "nopc", "lidar", "vel", "right wheel motor", "-2.0",
    "step", "32", "3",
    "enable", "eye", "16", "pc", "lidar", "pos", "left wheel motor", "0.5",
    "step", "48", "3",
]

_ARITY = {"enable": 2, "disable": 1, "pc": 1, "nopc": 1, "pos": 2, "vel": 2, "step": 2, "sleep": 1}


def _bits(value: float) -> str:
    return f"{struct.unpack('<Q', struct.pack('<d', float(value)))[0]:016x}"


def expected_lines(world: Path = WORLD, robot: str = ROBOT, script: list[str] = SCRIPT) -> list[str]:
    """The lines a conforming client prints for ``script`` on a fresh server of ``world``."""
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(world)
    rs = sim.robot(robot)
    order: list[str] = []                   # sensors, in order of first enable
    cache: dict[str, Any] = {}
    cloud: dict[str, bytes] = {}
    seen_count: dict[str, int] = {}
    period: dict[str, int] = {}
    pc: dict[str, bool] = {}
    lines: list[str] = []
    dev: Any                                # a sensor of any kind
    i = 0
    while i < len(script):
        op = script[i]
        args = script[i + 1:i + 1 + _ARITY[op]]
        i += 1 + _ARITY[op]
        if op in ("enable", "disable"):
            dev = sim.device(f"{robot}/{args[0]}")
            if args[0] not in order:
                order.append(args[0])
                seen_count[args[0]] = dev.measurements
                if dev.kind == "Lidar":
                    n = dev.config.horizontal_resolution * dev.config.number_of_layers
                    cache[args[0]], cloud[args[0]] = bytes(4 * n), bytes(20 * n)
                else:
                    cache[args[0]] = math.nan
            period[args[0]] = int(args[1]) if op == "enable" else 0
            dev.enable(period[args[0]]) if op == "enable" else dev.disable()
        elif op in ("pc", "nopc"):
            dev = sim.device(f"{robot}/{args[0]}")
            pc[args[0]] = op == "pc"
            dev.enable_point_cloud() if op == "pc" else dev.disable_point_cloud()
        elif op in ("pos", "vel"):
            motor = rs.motor(args[0])
            motor.set_position(float(args[1])) if op == "pos" else motor.set_velocity(float(args[1]))
        elif op == "step":
            duration, count = int(args[0]), int(args[1])
            for _ in range(count):
                for _ in range(-(-duration // sim.basic_time_step)):
                    sim.step()
                out = [f"{sim.time_ms} 0"]
                for name in order:
                    dev = sim.device(f"{robot}/{name}")
                    if dev.measurements != seen_count[name]:           # a new value came with this step
                        seen_count[name] = dev.measurements
                        if dev.kind == "Lidar":
                            cache[name] = dev.range_image.astype("<f4").tobytes()
                            if pc.get(name):
                                cloud[name] = dev.point_cloud.tobytes()
                        else:
                            cache[name] = float(dev.value)
                    if dev.kind == "Lidar":
                        out.append(f"{name}.range={cache[name].hex()}")
                        if pc.get(name) and period[name] > 0:
                            out.append(f"{name}.cloud={cloud[name].hex()}")
                    else:
                        out.append(f"{name}={_bits(cache[name])}")
                lines.append(" ".join(out))
    return lines


# ---------------------------------------------------------------------- request/reply vectors

INF = {"$float": "inf"}
NAN = {"$float": "nan"}
_OK = True

# (name, request, expect[, save]): written from PROTOCOL.md §3, checked against the server by
# tests/test_conformance.py. Ids are explicit; a request that is not a map has no id to echo.
CASES: list[tuple[str, Any, dict[str, Any]]] = [
    ("get_info", {"id": 1, "service": "get_info", "args": {}},
     {"ok": _OK, "result_has": ["protocol", "version", "world", "basic_time_step", "time_ms", "mode",
                                "real_time_factor", "pub_endpoint", "robots", "topics"],
      "result": {"protocol": 1, "world": "conformance", "basic_time_step": 16, "time_ms": 0}}),
    ("not_msgpack", {"$hex": "c1"}, {"ok": False, "id": None, "code": 1}),
    ("not_a_map", {"$hex": "920102"}, {"ok": False, "id": None, "code": 1}),
    ("missing_args", {"id": 4, "service": "get_info"}, {"ok": False, "code": 1, "message_has": "args"}),
    ("unknown_service", {"id": 5, "service": "no_such_service", "args": {}}, {"ok": False, "code": 2}),
    ("unknown_robot", {"id": 6, "service": "attach", "args": {"robot": "nobody"}},
     {"ok": False, "code": 3, "message_has": "nobody"}),
    ("unknown_argument", {"id": 7, "service": "attach", "args": {"robot": "rover", "robott": 1}},
     {"ok": False, "code": 5, "message_has": "robott"}),
    ("step_not_attached", {"id": 8, "service": "/rover/robot/step", "args": {"duration": 16}},
     {"ok": False, "code": 6}),
    ("basic_time_step_any", {"id": 9, "service": "/rover/robot/get_basic_time_step", "args": {}},
     {"ok": _OK, "result": {"value": 16.0}}),
    ("device_list_any", {"id": 10, "service": "/rover/robot/get_device_list", "args": {}},
     {"ok": _OK, "result": {"list": ["ir", "sonar", "eye", "lidar", "left encoder", "right encoder",
                                     "left wheel motor", "right wheel motor"]}}),
    ("lookup_table_any", {"id": 11, "service": "/rover/ir/get_lookup_table", "args": {}},
     {"ok": _OK, "result": {"value": [0.0, 4095.0, 0.01, 0.2, 500.0, 0.05, 0.6, 50.0, 0.1]}}),
    ("unknown_device", {"id": 12, "service": "/rover/nothing/enable", "args": {"value": 16}},
     {"ok": False, "code": 4, "message_has": "nothing"}),
    ("attach", {"id": 13, "service": "attach", "args": {"robot": "rover"}},
     {"ok": _OK, "result_has": ["session", "heartbeat_ms", "devices"],
      "result": {"robot": "rover", "basic_time_step": 16, "time_ms": 0, "synchronization": True}, "save": "session"}),
    ("robot_taken", {"id": 14, "service": "attach", "args": {"robot": "rover"}}, {"ok": False, "code": 7}),
    ("integer_argument_as_float", {"id": 15, "service": "/rover/ir/enable", "args": {"value": 16.0}},
     {"ok": False, "code": 5}),
    ("negative_period", {"id": 16, "service": "/rover/ir/enable", "args": {"value": -16}}, {"ok": False, "code": 5}),
    ("enable", {"id": 17, "service": "/rover/ir/enable", "args": {"value": 16}},
     {"ok": _OK, "result": {"success": True}}),
    ("layer_out_of_range", {"id": 18, "service": "/rover/lidar/get_layer_range_image", "args": {"layer": 2}},
     {"ok": False, "code": 5}),
    ("point_cloud_not_enabled", {"id": 19, "service": "/rover/lidar/get_layer_point_cloud", "args": {"layer": 0}},
     {"ok": False, "code": 10}),
    ("step_unknown_motor", {"id": 20, "service": "/rover/robot/step",
                            "args": {"duration": 16, "motors": {"wheel": {"velocity": 1.0}}}},
     {"ok": False, "code": 4, "message_has": "wheel"}),
    ("step_nan_position", {"id": 21, "service": "/rover/robot/step",
                           "args": {"duration": 16, "motors": {"left wheel motor": {"position": NAN}}}},
     {"ok": False, "code": 5}),
    ("step_infinite_velocity", {"id": 22, "service": "/rover/robot/step",
                                "args": {"duration": 16, "motors": {"left wheel motor": {"velocity": INF}}}},
     {"ok": False, "code": 5}),
    ("step_bool_duration", {"id": 23, "service": "/rover/robot/step", "args": {"duration": True}},
     {"ok": False, "code": 5}),
    ("step_with_motors", {"id": 24, "service": "/rover/robot/step", "args": {
        "duration": 16, "motors": {"left wheel motor": {"position": INF, "velocity": 2.0}}}},
     {"ok": _OK, "result": {"status": 0, "time_ms": 16}, "result_has": ["values.ir.value"]}),
    ("target_position_any", {"id": 25, "service": "/rover/left wheel motor/get_target_position", "args": {}},
     {"ok": _OK, "result": {"value": INF}}),
    ("ping_unknown_session", {"id": 26, "service": "ping", "args": {"session": "bogus"}}, {"ok": False, "code": 6}),
    ("ping", {"id": 27, "service": "ping", "args": {"session": "$session"}}, {"ok": _OK, "result": {"time_ms": 16}}),
    ("too_large", {"id": 28, "service": "get_info", "args": {"pad": {"$zeros": 1100000}}},
     {"ok": False, "id": None, "code": 8}),
    ("detach", {"id": 29, "service": "detach", "args": {"session": "$session"}}, {"ok": _OK, "result": {}}),
    ("detach_twice", {"id": 30, "service": "detach", "args": {"session": "$session"}}, {"ok": False, "code": 6}),
    ("step_after_detach", {"id": 31, "service": "/rover/robot/step", "args": {"duration": 16}},
     {"ok": False, "code": 6}),
]


def decode_value(v: Any, saved: dict[str, str] | None = None) -> Any:
    """A vector's JSON value → the value to msgpack: ``{"$float": "inf"|"-inf"|"nan"}``,
    ``{"$bin": HEX}``, ``{"$zeros": N}`` (bin of N zero bytes), ``"$NAME"`` (a saved result)."""
    if isinstance(v, dict):
        if set(v) == {"$float"}:
            return float(v["$float"])
        if set(v) == {"$bin"}:
            return bytes.fromhex(v["$bin"])
        if set(v) == {"$zeros"}:
            return bytes(int(v["$zeros"]))
        return {k: decode_value(x, saved) for k, x in v.items()}
    if isinstance(v, list):
        return [decode_value(x, saved) for x in v]
    if isinstance(v, str) and v.startswith("$") and saved is not None and v[1:] in saved:
        return saved[v[1:]]
    return v


def _uses(v: Any, what: str) -> bool:
    if isinstance(v, dict):
        return what in v or any(_uses(x, what) for x in v.values())
    if isinstance(v, list):
        return any(_uses(x, what) for x in v)
    return isinstance(v, str) and v.startswith("$") and what == "$saved"


def requests_doc() -> dict[str, Any]:
    import msgpack

    cases = []
    for name, request, expect in CASES:
        case: dict[str, Any] = {"name": name}
        if isinstance(request, dict) and set(request) == {"$hex"}:
            case["request_hex"] = request["$hex"]
        else:
            case["request"] = request
            if not _uses(request, "$zeros") and not _uses(request, "$saved"):
                case["request_hex"] = msgpack.packb(decode_value(request), use_bin_type=True).hex()
        case["expect"] = expect
        cases.append(case)
    return {"format": 1, "world": WORLD.name, "cases": cases}


def requests_text() -> str:
    d = requests_doc()
    rows = [f' "{k}": {json.dumps(d[k])}' for k in ("format", "world")]
    rows.append(' "cases": [\n' + ",\n".join(f"  {json.dumps(c)}" for c in d["cases"]) + "\n ]")
    return "{\n" + ",\n".join(rows) + "\n}\n"


def session() -> dict[str, Any]:
    return {"format": 1, "world": WORLD.name, "robot": ROBOT, "script": SCRIPT, "lines": expected_lines()}


def session_text() -> str:
    """session.json's text: one key per line, the script on one line, one expected line per line."""
    d = session()
    rows = [f' "{k}": {json.dumps(d[k])}' for k in ("format", "world", "robot", "script")]
    rows.append(' "lines": [\n' + ",\n".join(f"  {json.dumps(line)}" for line in d["lines"]) + "\n ]")
    return "{\n" + ",\n".join(rows) + "\n}\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m sensorium.server.sim.conformance", description=__doc__.split("\n\n")[0])
    p.add_argument("--write", action="store_true", help="regenerate session.json and requests.json")
    args = p.parse_args(argv)
    outdated = []
    for path, text in ((SESSION, session_text()), (REQUESTS, requests_text())):
        if args.write:
            path.write_text(text)
            print(f"wrote {path}")
        elif not path.is_file() or path.read_text() != text:
            outdated.append(path)
    for path in outdated:
        print(f"{path} is out of date: run python -m sensorium.server.sim.conformance --write", file=sys.stderr)
    if not args.write and not outdated:
        print(f"{SESSION.name} and {REQUESTS.name} are up to date")
    return 1 if outdated else 0


if __name__ == "__main__":
    sys.exit(main())
