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
RADIO = CONFORMANCE_DIR / "radio.json"
REQUESTS = CONFORMANCE_DIR / "requests.json"
ROBOT = "rover"

# Sampling periods that are and are not multiples of the basic step (16 ms), a disable and a
# re-enable, the point cloud switched off and on, velocity then position control, steps of 1-3
# basic steps; the kinematic sensors (noise, lookup tables, resolution) while the rover turns.
SCRIPT: list[str] = [
    "enable", "ir", "16", "enable", "sonar", "48", "enable", "eye", "40",
    "enable", "lidar", "32", "pc", "lidar",
    "enable", "left encoder", "16", "enable", "right encoder", "32",
    "enable", "gps", "16", "enable", "imu", "32", "enable", "compass", "16", "enable", "accelerometer", "16",
    "enable", "gyro", "48", "enable", "altimeter", "16", "enable", "bumper", "16",
    "pos", "left wheel motor", "inf", "pos", "right wheel motor", "inf",
    "vel", "left wheel motor", "3.0", "vel", "right wheel motor", "1.5",
    "step", "16", "5",
    "disable", "eye", "nopc", "lidar", "vel", "right wheel motor", "-2.0", "disable", "gps",
    "step", "32", "3",
    "enable", "eye", "16", "pc", "lidar", "pos", "left wheel motor", "0.5", "enable", "gps", "32",
    "step", "48", "3",
]

# Two controllers talking: radio packets both ways (the rover's emitter paced by its baud rate and
# bounded by its buffer, the buddy's receiver with noise and a small buffer), channel and range
# changes, broadcast, packets read and dropped with ``next``; the rover drives away, out of range.
RADIO_SCRIPTS: dict[str, list[str]] = {
    "rover": [
        "enable", "radio in", "16",
        "pos", "left wheel motor", "inf", "pos", "right wheel motor", "inf",
        "vel", "left wheel motor", "6.0", "vel", "right wheel motor", "6.0",
        "send", "radio out", "68656c6c6f", "send", "radio out", "0102030405060708090a",
        "send", "radio out", "ff" * 30, "send", "radio out", "ee" * 30,
        "step", "16", "3",
        "send", "radio out", "0b", "channel", "radio out", "-1", "send", "radio out", "0c",
        "step", "32", "2",
        "next", "radio in", "range", "radio out", "0.7", "send", "radio out", "0d",
        "step", "16", "4",
        "channel", "radio out", "5", "range", "radio out", "-1", "send", "radio out", "0e",
        "step", "48", "2",
    ],
    "buddy": [
        "enable", "radio in", "32",
        "send", "radio out", "6275646479",
        "step", "16", "3",
        "send", "radio out", "01", "send", "radio out", "02", "next", "radio in",
        "step", "32", "2",
        "channel", "radio in", "-1", "next", "radio in", "next", "radio in",
        "step", "16", "4",
        "channel", "radio in", "5", "next", "radio in", "send", "radio out", "03",
        "step", "48", "2",
    ],
}

_ARITY = {"enable": 2, "disable": 1, "pc": 1, "nopc": 1, "pos": 2, "vel": 2, "step": 2, "sleep": 1,
          "send": 2, "channel": 2, "range": 2, "next": 1}


def _bits(value: float) -> str:
    return f"{struct.unpack('<Q', struct.pack('<d', float(value)))[0]:016x}"


def _vector(values: Any) -> str:
    return ",".join(_bits(v) for v in values)


def _parse(script: list[str]) -> list[tuple[str, list[str]]]:
    ops, i = [], 0
    while i < len(script):
        op = script[i]
        ops.append((op, script[i + 1:i + 1 + _ARITY[op]]))
        i += 1 + _ARITY[op]
    return ops


class _Controller:
    """One robot's conformance runner as a conforming client executes it: the client's caches
    (NaN before the first value, kept after a disable), its emitter and receiver queues with
    libController's rules (bufferSize, baud-rate pacing), and the lines it prints."""

    def __init__(self, sim: Any, robot: str):
        self.sim = sim
        self.robot = robot
        self.rs = sim.robot(robot)
        self.order: list[str] = []                      # devices, in order of first use
        self.cache: dict[str, Any] = {}
        self.cloud: dict[str, bytes] = {}
        self.seen: dict[str, int] = {}
        self.period: dict[str, int] = {}
        self.pc: dict[str, bool] = {}
        self.channel: dict[str, int] = {}
        self.range: dict[str, float] = {}
        self.queue: dict[str, list[Any]] = {}           # emitter: (data, channel, range); receiver: packets
        self.budget: dict[str, float] = {}
        self.sent: dict[str, str] = {}                  # emitter: send results since the last line

    def _device(self, name: str) -> Any:
        dev = self.sim.device(f"{self.robot}/{name}")
        if name not in self.order:
            self.order.append(name)
            self.seen[name] = dev.measurements
            self.queue[name] = []
            self.budget[name] = 0.0
            self.sent[name] = ""
            if dev.kind == "Lidar":
                n = dev.config.horizontal_resolution * dev.config.number_of_layers
                self.cache[name], self.cloud[name] = bytes(4 * n), bytes(20 * n)
            elif dev.kind in ("Emitter", "Receiver"):
                self.channel[name] = dev.channel
                self.range[name] = getattr(dev, "range", -1.0)
            else:
                self.cache[name] = self._reading(dev, nan=True)
        return dev

    @staticmethod
    def _reading(dev: Any, nan: bool = False) -> list[float]:
        """What the client keeps of a device's reading, in the order the line prints it."""
        kind = dev.kind
        if kind == "GPS":
            out = [*dev.values, dev.speed, *dev.speed_vector]
        elif kind == "InertialUnit":
            out = [*dev.roll_pitch_yaw, *dev.quaternion]
        elif kind in ("Compass", "Accelerometer", "Gyro"):
            out = list(dev.values)
        else:
            out = [dev.value]
        return [math.nan] * len(out) if nan else [float(v) for v in out]

    def op(self, op: str, args: list[str]) -> None:
        if op in ("enable", "disable"):
            dev = self._device(args[0])
            self.period[args[0]] = int(args[1]) if op == "enable" else 0
            dev.enable(self.period[args[0]]) if op == "enable" else dev.disable()
        elif op in ("pc", "nopc"):
            dev = self._device(args[0])
            self.pc[args[0]] = op == "pc"
            dev.enable_point_cloud() if op == "pc" else dev.disable_point_cloud()
        elif op in ("pos", "vel"):
            motor = self.rs.motor(args[0])
            motor.set_position(float(args[1])) if op == "pos" else motor.set_velocity(float(args[1]))
        elif op == "send":
            dev = self._device(args[0])
            data, limit = bytes.fromhex(args[1]), dev.config.buffer_size
            q = self.queue[args[0]]
            ok = limit == -1 or len(data) <= limit - sum(len(p[0]) for p in q)
            if ok:
                if not q:
                    self.budget[args[0]] = 0.0
                q.append((data, self.channel[args[0]], self.range[args[0]]))
            self.sent[args[0]] += "1" if ok else "0"
        elif op == "channel":
            dev = self._device(args[0])
            self.channel[args[0]] = int(args[1])
            if dev.kind == "Receiver":
                dev.set_channel(int(args[1]))
        elif op == "range":
            dev = self._device(args[0])
            r, cap = float(args[1]), float(dev.config.max_range)
            self.range[args[0]] = cap if r == -1.0 else (r if cap == -1.0 else min(r, cap))
        elif op == "next":
            self._device(args[0])
            if self.queue[args[0]]:
                self.queue[args[0]].pop(0)
        else:
            raise ValueError(f"conformance script: op {op!r} is not for the simulation")

    def request(self, duration: int) -> None:
        """A step request: the packets each emitter's baud rate lets leave go to the server."""
        for name in self.order:
            dev = self.sim.device(f"{self.robot}/{name}")
            q = self.queue[name]
            if dev.kind != "Emitter" or not q:
                continue
            rate = dev.byte_rate
            if rate != -1.0:
                self.budget[name] += rate * duration
            while q and (rate == -1.0 or len(q[0][0]) <= self.budget[name]):
                data, channel, range_m = q.pop(0)
                self.budget[name] -= len(data)
                dev.send(data, channel=channel, range_m=range_m)

    def reply(self) -> None:
        """The step reply: the readings of devices measured since the last reply."""
        for name in self.order:
            dev = self.sim.device(f"{self.robot}/{name}")
            if dev.measurements == self.seen[name]:
                continue
            self.seen[name] = dev.measurements
            if dev.kind == "Lidar":
                self.cache[name] = dev.range_image.astype("<f4").tobytes()
                if self.pc.get(name):
                    self.cloud[name] = dev.point_cloud.tobytes()
            elif dev.kind == "Receiver":
                limit, q = dev.config.buffer_size, self.queue[name]
                for p in dev.take():
                    if limit == -1 or len(p.data) <= limit - sum(len(x.data) for x in q):
                        q.append(p)
            elif dev.kind != "Emitter":
                self.cache[name] = self._reading(dev)

    def line(self, status: int = 0) -> str:
        out = [f"{self.sim.time_ms} {status}"]
        for name in self.order:
            dev = self.sim.device(f"{self.robot}/{name}")
            if dev.kind == "Lidar":
                out.append(f"{name}.range={self.cache[name].hex()}")
                if self.pc.get(name) and self.period.get(name, 0) > 0:
                    out.append(f"{name}.cloud={self.cloud[name].hex()}")
            elif dev.kind == "Emitter":
                out.append(f"{name}.sent={self.sent[name]}")
                self.sent[name] = ""
            elif dev.kind == "Receiver":
                q = self.queue[name]
                out.append(f"{name}={len(q)}" + "".join(            # the head packet, as the API reads it
                    f":{p.data.hex()}/{_bits(p.signal_strength)}/{_vector(p.direction)}" for p in q[:1]))
            else:
                out.append(f"{name}={_vector(self.cache[name])}")
        return " ".join(out)


def expected_session(world: Path, scripts: dict[str, list[str]]) -> dict[str, list[str]]:
    """The lines each robot's conforming controller prints for its script on a fresh server of
    ``world``, all controllers stepping together (their scripts must step alike: the same step
    ops in the same order, so the lockstep pairs them one to one)."""
    from sensorium.server.sim.simulation import Simulation

    sim = Simulation.from_file(world)
    controllers = {robot: _Controller(sim, robot) for robot in scripts}
    parsed = {robot: _parse(script) for robot, script in scripts.items()}
    segments: dict[str, list[tuple[list[tuple[str, list[str]]], tuple[int, int]]]] = {}
    for robot, ops in parsed.items():
        segments[robot], pending = [], []
        for op, args in ops:
            if op == "step":
                segments[robot].append((pending, (int(args[0]), int(args[1]))))
                pending = []
            else:
                pending.append((op, args))
    steps = {tuple(s for _, s in segs) for segs in segments.values()}
    if len(steps) != 1:
        raise ValueError(f"conformance scripts must step alike, got {steps}")
    lines: dict[str, list[str]] = {robot: [] for robot in scripts}
    for k, (duration, count) in enumerate(next(iter(steps))):
        for robot, c in controllers.items():
            for op, args in segments[robot][k][0]:
                c.op(op, args)
        for _ in range(count):
            for c in controllers.values():
                c.request(duration)
            for _ in range(-(-duration // sim.basic_time_step)):
                sim.step()
            for robot, c in controllers.items():
                c.reply()
                lines[robot].append(c.line())
    return lines


def expected_lines(world: Path = WORLD, robot: str = ROBOT, script: list[str] = SCRIPT) -> list[str]:
    """The lines a conforming client prints for ``script`` on a fresh server of ``world``."""
    return expected_session(world, {robot: script})[robot]


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
     {"ok": _OK, "result": {"list": ["ir", "sonar", "eye", "lidar", "left encoder", "right encoder", "gps", "imu",
                                     "compass", "accelerometer", "gyro", "altimeter", "bumper", "radio out", "radio in",
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
    ("step_unknown_emitter", {"id": 32, "service": "/rover/robot/step",
                              "args": {"duration": 16, "emitters": {"ir": []}}},
     {"ok": False, "code": 4, "message_has": "ir"}),
    ("step_empty_packet", {"id": 33, "service": "/rover/robot/step", "args": {
        "duration": 16, "emitters": {"radio out": [{"data": {"$bin": ""}, "channel": 1, "range": -1.0}]}}},
     {"ok": False, "code": 5}),
    ("receiver_channel_any", {"id": 34, "service": "/rover/radio in/get_channel", "args": {}},
     {"ok": _OK, "result": {"value": 1}}),
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


def radio_session() -> dict[str, Any]:
    return {"format": 1, "world": WORLD.name, "scripts": RADIO_SCRIPTS,
            "lines": expected_session(WORLD, RADIO_SCRIPTS)}


def radio_text() -> str:
    """radio.json's text: each robot's script on one line, one expected line per line."""
    d = radio_session()
    rows = [f' "{k}": {json.dumps(d[k])}' for k in ("format", "world")]
    rows.append(' "scripts": {\n' + ",\n".join(f"  {json.dumps(r)}: {json.dumps(s)}" for r, s in d["scripts"].items())
                + "\n }")
    rows.append(' "lines": {\n' + ",\n".join(
        f"  {json.dumps(r)}: [\n" + ",\n".join(f"   {json.dumps(line)}" for line in lines) + "\n  ]"
        for r, lines in d["lines"].items()) + "\n }")
    return "{\n" + ",\n".join(rows) + "\n}\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m sensorium.server.sim.conformance", description=__doc__.split("\n\n")[0])
    p.add_argument("--write", action="store_true", help="regenerate session.json, radio.json and requests.json")
    args = p.parse_args(argv)
    outdated = []
    for path, text in ((SESSION, session_text()), (RADIO, radio_text()), (REQUESTS, requests_text())):
        if args.write:
            path.write_text(text)
            print(f"wrote {path}")
        elif not path.is_file() or path.read_text() != text:
            outdated.append(path)
    for path in outdated:
        print(f"{path} is out of date: run python -m sensorium.server.sim.conformance --write", file=sys.stderr)
    if not args.write and not outdated:
        print(f"{SESSION.name}, {RADIO.name} and {REQUESTS.name} are up to date")
    return 1 if outdated else 0


if __name__ == "__main__":
    sys.exit(main())
