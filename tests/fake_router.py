"""A small in-process stand-in for ``sensorium serve``: a ROUTER socket in a thread that speaks
PROTOCOL.md §3 for a toy world, with knobs to delay, silence or shut the lockstep down.

Readings are simple functions of the measurement time so tests can predict them:
light = 100 + t_s, distance = t_ms / 2, lidar range[i] = t_s + i / 4 (2 layers x 4 columns).
Robot r2 also has two wheel motors; motor commands arrive in the step requests' args (see ``log``).
"""

from __future__ import annotations

import itertools
import math
import struct
import threading
import time

import msgpack
import zmq

BASIC = 32
LAYERS, COLUMNS = 2, 4
MAX_VELOCITY = 6.28


def light_value(t_ms: int) -> float:
    return 100.0 + t_ms / 1000.0


def distance_value(t_ms: int) -> float:
    return t_ms / 2.0


def range_image(t_ms: int) -> bytes:
    return struct.pack(f"<{LAYERS * COLUMNS}f", *(t_ms / 1000.0 + i / 4 for i in range(LAYERS * COLUMNS)))


def point_cloud(t_ms: int) -> bytes:
    out = b""
    for i in range(LAYERS * COLUMNS):
        out += struct.pack("<fffif", float(i), -float(i), 0.5, i // COLUMNS, t_ms / 1000.0)
    return out


def descriptions(full: bool) -> dict[str, list[dict]]:
    light = {"name": "ls", "type": "LightSensor"}
    dist = {"name": "ds", "type": "DistanceSensor"}
    lidar = {"name": "lid", "type": "Lidar"}
    if full:
        light.update(lookup_table=[[0.0, 0.0, 0.0], [10.0, 1000.0, 0.01]], sampling_period=0)
        dist.update(lookup_table=[[0.0, 1000.0, 0.0], [0.1, 0.0, 0.0]], min_value=0.0, max_value=1000.0,
                    aperture=0.2, sensor_type=2, sampling_period=0)
        lidar.update(horizontalResolution=COLUMNS, numberOfLayers=LAYERS, fov=1.5, verticalFov=0.2,
                     minRange=0.05, maxRange=6.0, frequency=10.0, minFrequency=1.0, maxFrequency=25.0,
                     sampling_period=0, point_cloud_enabled=False)
    motors = [{"name": n, "type": "RotationalMotor", "maxVelocity": MAX_VELOCITY, "minPosition": 0.0, "maxPosition": 0.0,
               "targetPosition": 0.0, "velocity": 0.0} for n in ("left wheel motor", "right wheel motor")]
    if not full:
        motors = [{"name": m["name"], "type": m["type"]} for m in motors]
    return {"r1": [light, dist, lidar], "r2": [dict(dist), *motors]}


class _Dev:
    def __init__(self, desc: dict):
        self.desc = desc
        self.name = desc["name"]
        self.kind = desc["type"]
        self.period = 0
        self.last = 0
        self.reading: dict | None = None
        self.changed = False
        self.cloud = False
        self.frequency = 10.0


class FakeServer(threading.Thread):
    def __init__(self, full_descriptions: bool = True, heartbeat_ms: int = 100, step_padding: int = 0):
        super().__init__(daemon=True)
        self.ctx = zmq.Context.instance()
        self.sock = self.ctx.socket(zmq.ROUTER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.bind("tcp://127.0.0.1:*")
        self.endpoint = self.sock.getsockopt_string(zmq.LAST_ENDPOINT)
        self.heartbeat_ms = heartbeat_ms
        self.time_ms = 0
        self.robots = {r: {d["name"]: _Dev(d) for d in devs} for r, devs in descriptions(full_descriptions).items()}
        self.desc = descriptions(full_descriptions)
        self.attached: dict[str, tuple[bytes, str]] = {}      # robot -> (identity, session)
        self.pending: dict[str, tuple[bytes, int, int]] = {}  # robot -> (identity, id, wake)
        self.log: list[tuple[str, dict]] = []
        self.pings: list[float] = []
        self.hold = False          # don't advance the lockstep
        self.silent = False        # don't answer anything (a hung server)
        self.quitting = False      # answer steps with status -1
        self.step_padding = step_padding   # bytes of junk added to every step reply (a reply over a client's limit)
        self._sessions = itertools.count(1)
        self._halt = threading.Event()
        self.lock = threading.Lock()

    # -- test helpers
    def services(self) -> list[str]:
        with self.lock:
            return [s for s, _ in self.log]

    def stop(self) -> None:
        self._halt.set()
        self.join(2)

    def release(self) -> None:
        self.hold = False

    # -- loop
    def run(self) -> None:
        try:
            while not self._halt.is_set():
                if self.sock.poll(10):
                    while True:
                        try:
                            frames = self.sock.recv_multipart(zmq.NOBLOCK)
                        except zmq.Again:
                            break
                        if not self.silent:
                            self._handle(frames)
                if not self.hold and not self.silent:
                    self._advance()
        finally:
            self.sock.close(0)

    def _send(self, identity: bytes, rid, result=None, error=None) -> None:
        body = {"id": rid, "ok": error is None}
        if error is None:
            body["result"] = result or {}
        else:
            body["error"] = {"code": error[0], "message": error[1]}
        self.sock.send_multipart([identity, msgpack.packb(body, use_bin_type=True)])

    def _handle(self, frames: list[bytes]) -> None:
        identity, payload = frames[0], frames[-1]
        req = msgpack.unpackb(payload, raw=False)
        rid, service, args = req["id"], req["service"], req.get("args", {})
        with self.lock:
            self.log.append((service, args))
        try:
            result = self._service(identity, rid, service, args)
        except _Err as e:
            self._send(identity, rid, error=(e.code, e.msg))
            return
        if result is not None:
            self._send(identity, rid, result)

    def _service(self, identity: bytes, rid, service: str, args: dict):
        if service == "get_info":
            return {"protocol": 1, "version": "fake", "world": "fake", "basic_time_step": BASIC,
                    "time_ms": self.time_ms, "mode": "fast", "pub_endpoint": "tcp://127.0.0.1:1",
                    "robots": [{"name": r, "synchronization": True, "attached": r in self.attached,
                                "devices": [{"name": d["name"], "type": d["type"]} for d in devs]}
                               for r, devs in self.desc.items()],
                    "topics": [{"name": "/r1/ls/value", "type": "sensor_msgs/msg/Illuminance"},
                               {"name": "/clock", "type": "rosgraph_msgs/msg/Clock"}]}
        if service == "attach":
            robot = args.get("robot")
            if robot not in self.robots:
                raise _Err(3, f"no robot {robot!r}")
            if robot in self.attached and self.attached[robot][0] != identity:
                raise _Err(7, f"robot {robot!r} is taken")
            session = f"s{next(self._sessions)}"
            self.attached[robot] = (identity, session)
            return {"session": session, "robot": robot, "basic_time_step": BASIC, "time_ms": self.time_ms,
                    "synchronization": True, "heartbeat_ms": self.heartbeat_ms, "devices": self.desc[robot]}
        if service == "ping":
            self.pings.append(time.monotonic())
            if not any(s == args.get("session") for _, s in self.attached.values()):
                raise _Err(6, "no such session")
            return {"time_ms": self.time_ms}
        if service == "detach":
            for robot, (_, s) in list(self.attached.items()):
                if s == args.get("session"):
                    del self.attached[robot]
                    self.pending.pop(robot, None)
            return {}
        parts = service.strip("/").split("/")
        if len(parts) != 3 or parts[0] not in self.robots:
            raise _Err(2, f"unknown service {service!r}")
        robot, dev_name, item = parts
        if dev_name == "robot":
            if item == "battery_sensor_enable":          # the fake's robots have no battery: never a value
                return {"success": True}
            if item == "battery_sensor_get_value":
                return {"value": math.nan}
            if item != "step":
                raise _Err(2, service)
            if self.attached.get(robot, (None,))[0] != identity:
                raise _Err(6, "not attached")
            if self.quitting:
                return {"status": -1, "time_ms": self.time_ms, "values": {}}
            duration = args.get("duration", BASIC)
            if not isinstance(duration, int) or duration <= 0 or duration % BASIC:
                raise _Err(5, f"duration {duration!r}")
            if robot in self.pending:
                raise _Err(10, "a step is pending")
            self.pending[robot] = (identity, rid, self.time_ms + duration)
            return None                                  # answered by _advance
        dev = self.robots[robot].get(dev_name)
        if dev is None:
            raise _Err(4, f"no device {dev_name!r}")
        if item == "enable":
            v = args.get("value")
            if not isinstance(v, int) or v < 0:
                raise _Err(5, "value")
            dev.period, dev.last = v, self.time_ms
            return {"success": True}
        if item == "enable_point_cloud":
            dev.cloud = bool(args.get("value"))
            return {"success": True}
        if item == "set_frequency":
            dev.frequency = float(args["value"])
            return {"success": True}
        if item == "get_sampling_period":
            return {"value": dev.period}
        if item == "get_lookup_table":
            return {"value": [0.0, 0.0, 0.0, 10.0, 1000.0, 0.01] if dev.kind == "LightSensor"
                    else [0.0, 1000.0, 0.0, 0.1, 0.0, 0.0]}
        if item in ("get_min_value", "get_max_value", "get_aperture", "get_type"):
            return {"value": {"get_min_value": 0.0, "get_max_value": 1000.0, "get_aperture": 0.2, "get_type": 2}[item]}
        if item == "get_info":
            return {"horizontalResolution": COLUMNS, "numberOfLayers": LAYERS, "fov": 1.5, "verticalFov": 0.2,
                    "minRange": 0.05, "maxRange": 6.0}
        if item == "get_frequency_info":
            return {"frequency": dev.frequency, "minFrequency": 1.0, "maxFrequency": 25.0}
        raise _Err(4, f"{dev_name} has no service {item!r}")

    def _advance(self) -> None:
        while self.pending and all(r in self.pending for r in self.attached):
            self.time_ms += BASIC
            for devs in self.robots.values():
                for dev in devs.values():
                    if dev.period > 0 and self.time_ms - dev.last >= dev.period:
                        dev.last = self.time_ms
                        dev.changed = True
                        if dev.kind == "LightSensor":
                            dev.reading = {"value": light_value(self.time_ms)}
                        elif dev.kind == "DistanceSensor":
                            dev.reading = {"value": distance_value(self.time_ms)}
                        else:
                            dev.reading = {"range_image": range_image(self.time_ms)}
                            if dev.cloud:
                                dev.reading["point_cloud"] = point_cloud(self.time_ms)
            for robot, (identity, rid, wake) in list(self.pending.items()):
                if wake <= self.time_ms:
                    del self.pending[robot]
                    values = {}
                    for dev in self.robots[robot].values():
                        if dev.changed and dev.reading is not None:
                            values[dev.name] = dev.reading
                            dev.changed = False
                    if self.step_padding:
                        values["padding"] = {"value": bytes(self.step_padding)}
                    self._send(identity, rid, {"status": 0, "time_ms": self.time_ms, "values": values})


class _Err(Exception):
    def __init__(self, code: int, msg: str):
        self.code, self.msg = code, msg

