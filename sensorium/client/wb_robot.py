"""The robot side of Webots' C API on Sensorium: the session (:class:`RobotClient`), the
process-wide robot of the flat ``wb_robot_*`` functions, and ``wb_device_*``.

:mod:`sensorium.client.wb` re-exports this module and the device families (``wb_sensors``,
``wb_motor``, ``wb_supervisor``); see it for the overview."""

from __future__ import annotations

import atexit
import functools
import math
import numbers
import sys
from collections import deque
from collections.abc import Callable
from typing import Any, TypeVar

from sensorium.client import arrays, nodes
from sensorium.client.connection import (
    DEFAULT_TIMEOUT,
    Connection,
    ConnectionLost,
    ControllerURL,
    ErrorCode,
    SensoriumError,
    controller_url_from_env,
    parse_controller_url,
)

WB_DISTANCE_SENSOR_GENERIC = 0
WB_DISTANCE_SENSOR_INFRA_RED = 1
WB_DISTANCE_SENSOR_SONAR = 2
WB_DISTANCE_SENSOR_LASER = 3
_DISTANCE_TYPES = {"generic": 0, "infra-red": 1, "infra_red": 1, "sonar": 2, "laser": 3}

MAX_PERIOD_MS = (1 << 31) - 1
"""The greatest sampling period (ms): Webots' C ``int``, the server's bound."""

WB_ROTATIONAL = 0
WB_LINEAR = 1

LIGHT_SENSOR = "LightSensor"
DISTANCE_SENSOR = "DistanceSensor"
LIDAR = "Lidar"
ROTATIONAL_MOTOR = "RotationalMotor"
LINEAR_MOTOR = "LinearMotor"
POSITION_SENSOR = "PositionSensor"
LED = "LED"
EMITTER = "Emitter"
RECEIVER = "Receiver"

WB_CHANNEL_BROADCAST = -1

globals().update(nodes.WEBOTS_NODE_TYPES)      # WB_NODE_GPS, ... (Webots' values)

# wb_robot_get_mode()
WB_MODE_SIMULATION = 0
WB_MODE_CROSS_COMPILATION = 1
WB_MODE_REMOTE_CONTROL = 2

# wb_robot_wait_for_user_input_event()
WB_EVENT_QUIT = -1
WB_EVENT_NO_EVENT = 0
WB_EVENT_MOUSE_CLICK = 1
WB_EVENT_MOUSE_MOVE = 2
WB_EVENT_KEYBOARD = 4
WB_EVENT_JOYSTICK_BUTTON = 8
WB_EVENT_JOYSTICK_AXIS = 16
WB_EVENT_JOYSTICK_POV = 32

# webots/keyboard.h
WB_KEYBOARD_END = 312
WB_KEYBOARD_HOME = 313
WB_KEYBOARD_LEFT = 314
WB_KEYBOARD_UP = 315
WB_KEYBOARD_RIGHT = 316
WB_KEYBOARD_DOWN = 317
WB_KEYBOARD_PAGEUP = 366
WB_KEYBOARD_PAGEDOWN = 367
WB_KEYBOARD_NUMPAD_HOME = 375
WB_KEYBOARD_NUMPAD_LEFT = 376
WB_KEYBOARD_NUMPAD_UP = 377
WB_KEYBOARD_NUMPAD_RIGHT = 378
WB_KEYBOARD_NUMPAD_DOWN = 379
WB_KEYBOARD_NUMPAD_END = 382
WB_KEYBOARD_KEY = 0xFFFF
WB_KEYBOARD_SHIFT = 0x10000
WB_KEYBOARD_CONTROL = 0x20000
WB_KEYBOARD_ALT = 0x40000

# Constant getters: local name -> (keys tried in the attach description, fallback service, its field).
_CONSTANTS: dict[str, tuple[tuple[str, ...], str, str]] = {
    "lookup_table": (("lookup_table", "lookupTable"), "get_lookup_table", "value"),
    "min_value": (("min_value", "minValue"), "get_min_value", "value"),
    "max_value": (("max_value", "maxValue"), "get_max_value", "value"),
    "aperture": (("aperture",), "get_aperture", "value"),
    "distance_type": (("distance_type", "sensor_type", "type_code", "typeCode"), "get_type", "value"),
    "horizontal_resolution": (("horizontal_resolution", "horizontalResolution"), "get_info", "horizontalResolution"),
    "number_of_layers": (("number_of_layers", "numberOfLayers"), "get_info", "numberOfLayers"),
    "fov": (("fov", "field_of_view", "fieldOfView"), "get_info", "fov"),
    "vertical_fov": (("vertical_fov", "verticalFov", "vertical_field_of_view", "verticalFieldOfView"), "get_info", "verticalFov"),
    "min_range": (("min_range", "minRange"), "get_info", "minRange"),
    "max_range": (("max_range", "maxRange"), "get_info", "maxRange"),
    "frequency": (("frequency", "default_frequency", "defaultFrequency"), "get_frequency_info", "frequency"),
    "min_frequency": (("min_frequency", "minFrequency"), "get_frequency_info", "minFrequency"),
    "max_frequency": (("max_frequency", "maxFrequency"), "get_frequency_info", "maxFrequency"),
}


def _flat_table(table: Any) -> list[float]:
    out: list[float] = []
    for row in table or ():
        if isinstance(row, (list, tuple)):
            out.extend(float(v) for v in row)
        else:
            out.append(float(row))
    return out


def _float(v: Any, default: float) -> float:
    return default if v is None else float(v)


def whole_ms(v: Any) -> int | None:
    """``v`` as an ``int`` when it is a whole number: an int or a numpy integer (Webots' ctypes
    ``c_int`` takes both), or an integral float (``step(robot.getBasicTimeStep())``); None otherwise
    (a bool, a fraction, not a number)."""
    if type(v) is int:            # the step loop's case, before the slower ABC checks
        return v
    if isinstance(v, bool):
        return None
    if isinstance(v, numbers.Integral):
        return int(v)
    if isinstance(v, numbers.Real) and float(v).is_integer():
        return int(float(v))
    return None


def integer(v: Any) -> int | None:
    """``v`` as an ``int`` when it is an integer (a numpy integer too); None otherwise (a bool, a float)."""
    return int(v) if isinstance(v, numbers.Integral) and not isinstance(v, bool) else None


def real(v: Any) -> float | None:
    """``v`` as a ``float`` when it is a real number (a numpy float32 from an action array too, as
    Webots' ctypes ``c_double`` takes it); None for a bool or anything else."""
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return None
    return float(v)


def c_string(v: Any) -> Any:
    """``v`` as Webots' C API receives a Python ``str``: cut at its first NUL, since Webots' Python
    passes it down as a C string (a received packet's ``getString()`` keeps the sender's terminating
    NUL, and controllers hand such text on); anything else unchanged, for the caller's own checks."""
    return v.split("\0", 1)[0] if isinstance(v, str) else v


class NoValue(Exception):
    """Raised by :meth:`RobotClient.device` for a device Sensorium lists but does not simulate; the
    public function catches it and answers Webots' "no value" (:func:`answers`)."""


F = TypeVar("F", bound=Callable[..., Any])


def answers(no_value: Any) -> Callable[[F], F]:
    """Decorate a device function: for a listed-only device it returns ``no_value`` (a fresh copy
    of a list) after the device's one warning line."""
    def wrap(fn: F) -> F:
        @functools.wraps(fn)
        def call(*args: Any, **kwargs: Any) -> Any:
            try:
                return fn(*args, **kwargs)
            except NoValue:
                return list(no_value) if isinstance(no_value, list) else no_value
        return call  # type: ignore[return-value]
    return wrap


def _nans(n: int) -> list[float]:
    return [math.nan] * n


class DeviceState:
    """What the client knows about one device: its description, enable state and latest reading
    (an emitter's and a receiver's packet queues too)."""

    __slots__ = ("tag", "index", "name", "kind", "desc", "simulated", "node_type", "model", "sampling_period",
                 "value", "values", "speed", "speed_vector", "quaternion", "roll_pitch_yaw", "range_bytes",
                 "cloud_bytes", "point_cloud_enabled", "max_velocity", "target_position", "velocity",
                 "channel", "range", "queue", "queue_bytes", "bytes_to_send", "targets",
                 "_consts", "_range", "_cloud", "_warned", "_warned_unsimulated", "camera", "drawing", "drawing_size", "image_ids")

    def __init__(self, index: int, desc: dict):
        self.index = index
        self.tag = index + 1                     # 0 is "no device", as in Webots
        self.name = str(desc.get("name", f"device{index}"))
        self.kind = str(desc.get("type", ""))
        self.desc = desc
        self.simulated = bool(desc.get("simulated", True))
        self.node_type = nodes.node_type(self.kind)
        self.model = str(desc.get("model", "") or "")
        self.sampling_period = int(desc.get("sampling_period", desc.get("samplingPeriod", 0)) or 0)
        self.value = math.nan
        self.values = _nans(3)                   # GPS, Compass, Accelerometer, Gyro, force-3d TouchSensor
        self.speed = math.nan                    # GPS
        self.speed_vector = _nans(3)
        self.quaternion = _nans(4)               # InertialUnit
        self.roll_pitch_yaw = _nans(3)
        self.range_bytes: bytes | None = None
        self.cloud_bytes: bytes | None = None
        self.point_cloud_enabled = bool(desc.get("point_cloud_enabled", desc.get("pointCloudEnabled", False)))
        # motors: the commands as last set (the server's at attach, then this controller's)
        self.max_velocity = _float(desc.get("maxVelocity", desc.get("max_velocity")), 10.0)   # Webots' default
        self.target_position = _float(desc.get("targetPosition", desc.get("target_position")), 0.0)
        self.velocity = _float(desc.get("velocity"), self.max_velocity)       # libController starts at maxVelocity
        # emitter / receiver: the channel and range as this controller set them, the packet queue
        # (an emitter's: (data, channel, range) waiting for the baud rate; a receiver's: what arrived)
        self.channel = int(desc.get("channel", 0) or 0)
        self.range = _float(desc.get("range"), -1.0)
        self.queue: deque[Any] = deque()
        self.queue_bytes = 0
        self.targets: list[float] | None = None  # Radar: distance, power, speed, azimuth of each target in turn
        self.bytes_to_send = 0.0
        self._consts: dict[str, Any] = {}
        self._range: Any = None                  # decoded forms, rebuilt when new bytes arrive
        self._cloud: Any = None
        self._warned = False
        self.camera: dict[str, Any] = {}         # a camera's latest readings (wb_camera.py): image, recognition
        self._warned_unsimulated = False
        self.drawing: list[list[Any]] = []       # a Display's commands, sent with the next step (wb_display.py)
        self.drawing_size = [0, 0]               # about how many values and bytes they hold
        self.image_ids = 0                       # a Display's image references given out

    def __repr__(self) -> str:
        return f"<{self.kind} {self.name!r} tag={self.tag} period={self.sampling_period}>"


class RobotClient:
    """A controller's session: attach to one robot, step it, cache its readings.

    ``url`` is a controller URL (see :func:`~sensorium.client.connection.parse_controller_url`)
    or ``None`` for the environment's; ``robot`` overrides the URL's robot name. ``timeout`` is
    the wait for ordinary replies; steps wait as long as the lockstep needs, but give up with
    status -1 when the heartbeat finds the server gone."""

    def __init__(self, url: str | ControllerURL | None = None, *, robot: str | None = None,
                 timeout: float | None = DEFAULT_TIMEOUT, heartbeat_ms: int | None = None,
                 lost_after_s: float | None = None, context: Any = None):
        if isinstance(url, ControllerURL):
            target = url
        elif url is None:
            target = controller_url_from_env()
        else:
            target = parse_controller_url(url)
        if robot is not None:
            target = target.with_robot(robot)
        self.url = target
        self.conn = Connection(target.endpoint, timeout=timeout, context=context)
        self.pending: int | None = None
        self.terminated = False
        self.quit_returned = False              # a step has answered -1 for the termination (wb_robot_step)
        self.closed = False
        try:
            name = target.robot if target.robot is not None else self._only_robot()
            reply = self.conn.call("attach", {"robot": name})
        except BaseException:
            self.conn.close()
            raise
        self.name = str(reply.get("robot", name))
        self.session = str(reply["session"])
        self.basic_time_step = int(reply["basic_time_step"])
        self.time_ms = int(reply.get("time_ms", 0))
        self.synchronization = bool(reply.get("synchronization", True))
        self.heartbeat_ms = int(heartbeat_ms or reply.get("heartbeat_ms") or 1000)
        self.supervisor = bool(reply.get("supervisor", False))
        self.model = str(reply.get("model", ""))
        self.custom_data = str(reply.get("custom_data", ""))
        drive = reply.get("ackermann_drive")          # a car-like robot's geometry (the vehicle library's)
        self.ackermann_drive: dict | None = dict(drive) if isinstance(drive, dict) else None
        self.keyboard_period = 0
        # robot-window texts (wwiReceiveText, libController's rule): those come with step replies wait in
        # window_inbox; the first read after a step takes them all as the batch read one per call, and
        # the next step drops what is left of that batch
        self.window_inbox: list[str] = []
        self.window_batch: list[str] = []
        self.window_fresh = True                 # a step began since the batch was taken
        self._warned_duration = False
        self.devices = [DeviceState(i, d) for i, d in enumerate(reply.get("devices", []))]
        self.by_name = {d.name: d for d in self.devices}
        self._emitters = [d for d in self.devices if d.kind == EMITTER and d.simulated]
        self._displays = [d for d in self.devices if d.kind == "Display" and d.simulated]
        self.motor_commands: dict[str, dict[str, float]] = {}   # sent with the next step request
        # called with each step's duration before its request is built (wb_motion's playing motions)
        self.step_hooks: list[Callable[[int], None]] = []
        # called after each step reply (a Supervisor's movie takes its frames) and before detaching
        self.step_end_hooks: list[Callable[[], None]] = []
        self.close_hooks: list[Callable[[], None]] = []
        self._prefix = f"/{self.name}/"
        self.conn.start_heartbeat(self.session, self.heartbeat_ms, lost_after_s)

    def _only_robot(self) -> str:
        robots = [r.get("name") for r in self.conn.call("get_info").get("robots", [])]
        if len(robots) == 1:
            return str(robots[0])
        raise SensoriumError(ErrorCode.BAD_URL,
                             f"the controller URL names no robot and the world at {self.conn.endpoint} has "
                             f"{len(robots)} ({', '.join(map(str, robots))}): add '/ROBOT' to the URL")

    # ------------------------------------------------------------------ stepping
    def step_begin(self, duration: int | None = None) -> int:
        if self.pending is not None:
            raise SensoriumError(ErrorCode.WRONG_STATE, "a step is already pending: call wb_robot_step_end() first")
        if self.terminated:
            return -1
        if duration is None:
            duration = self.basic_time_step
        whole = whole_ms(duration)
        if whole is None:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"step duration must be an integer (ms), got {duration!r}")
        duration = whole
        if duration < 0:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"step duration must be >= 0 ms, got {duration}")
        if duration % self.basic_time_step and not self._warned_duration:
            # Webots warns once and wakes the controller at the first basic step that ends after it
            self._warned_duration = True
            print(f"Warning: the step duration {duration} ms of robot {self.name!r} is not a multiple of the basic "
                  f"time step ({self.basic_time_step} ms); the server rounds it up.", file=sys.stderr)
        for hook in self.step_hooks:
            hook(duration)
        self.window_fresh = True
        args: dict[str, Any] = {"duration": duration}
        if self.motor_commands:
            args["motors"], self.motor_commands = self.motor_commands, {}
        packets = self._emitted(duration)
        if packets:
            args["emitters"] = packets
        drawn = {d.name: d.drawing for d in self._displays if d.drawing}
        if drawn:
            args["displays"] = drawn
            for d in self._displays:
                d.drawing = []
        self.pending = self.conn.send(self._prefix + "robot/step", args)
        return 0

    def _emitted(self, duration: int) -> dict[str, list[dict]]:
        """The packets each emitter's baud rate lets leave with this step (libController's rule:
        ``byte_rate × duration`` more bytes may go while packets wait; a packet leaves whole)."""
        out: dict[str, list[dict]] = {}
        for dev in self._emitters:
            q = dev.queue
            if not q:
                continue
            rate = float(dev.desc.get("byte_rate", -1.0))
            if rate != -1.0:
                dev.bytes_to_send += rate * duration
            sent = []
            while q and (rate == -1.0 or len(q[0][0]) <= dev.bytes_to_send):
                data, channel, range_m = q.popleft()
                dev.queue_bytes -= len(data)
                dev.bytes_to_send -= len(data)
                sent.append({"data": data, "channel": channel, "range": range_m})
            if sent:
                out[dev.name] = sent
        return out

    def step_end(self) -> int:
        if self.pending is None:
            if self.terminated:
                return -1
            raise SensoriumError(ErrorCode.WRONG_STATE, "no step pending: call wb_robot_step_begin() first")
        rid, self.pending = self.pending, None
        try:
            result = self.conn.wait(rid, timeout=None)
        except ConnectionLost as exc:
            print(f"sensorium: {exc}; ending the controller's steps", file=sys.stderr)
            return self.end_steps()
        except SensoriumError as exc:
            if exc.code == ErrorCode.SHUTTING_DOWN:
                return self.end_steps()
            if exc.code == ErrorCode.NOT_ATTACHED:
                # the session was dropped (3 heartbeats of silence: a network stall, or this
                # process was stopped); like a Webots extern controller whose simulation went
                # away, the controller's step loop ends instead of crashing
                hb = self.conn.heartbeat
                problem = hb.problem() if hb is not None else None
                if problem is None:
                    paused = hb.paused_s if hb is not None else 0.0
                    problem = ("the server released the robot after 3 heartbeats without hearing from this "
                               "controller (" + (f"this process did not run for {paused:.1f} s)" if paused
                                                 else "a network stall, or this process was stopped)"))
                print(f"sensorium: {problem}; ending the controller's steps (start it again to re-attach)",
                      file=sys.stderr)
                return self.end_steps()
            raise
        status = int(result.get("status", 0))
        self.time_ms = int(result.get("time_ms", self.time_ms))
        values = result.get("values")
        if values:
            self._apply(values)
        data = result.get("custom_data")
        if data is not None:            # a Supervisor set the robot's customData field (Webots sends it so too)
            self.custom_data = str(data)
        texts = result.get("robot_window")
        if texts:                       # what the robot's window side sent it (window_send)
            self.window_inbox.extend(str(t) for t in texts)
        if status == -1:
            self.terminated = True
        for hook in self.step_end_hooks:
            hook()
        return status

    def end_steps(self) -> int:
        """The end of this controller's steps without a step's answer (the server quit, stopped or went away;
        this Supervisor's own quit): terminated, the step-end hooks told as after a step answering -1 (a movie
        ends with the world); -1."""
        self.terminated = True
        for hook in self.step_end_hooks:
            hook()
        return -1

    def step(self, duration: int | None = None) -> int:
        if self.step_begin(duration) == -1:
            return -1
        return self.step_end()

    def _apply(self, values: dict) -> None:
        for name, reading in values.items():
            dev = self.by_name.get(name)
            if dev is None or not isinstance(reading, dict):
                continue
            if "value" in reading:
                v = reading["value"]
                dev.value = math.nan if v is None else float(v)
            for key in ("values", "speed_vector", "quaternion", "roll_pitch_yaw"):
                if key in reading:
                    setattr(dev, key, [math.nan if x is None else float(x) for x in reading[key]])
            if "speed" in reading:
                dev.speed = math.nan if reading["speed"] is None else float(reading["speed"])
            if "packets" in reading:
                self._received(dev, reading["packets"])
            if "targets" in reading:
                dev.targets = [math.nan if x is None else float(x) for x in reading["targets"] or ()]
            if "is_on" in reading:                # a VacuumGripper's pump (a simulation reset may change it)
                dev.desc["is_on"] = bool(reading["is_on"])
            if "sounds" in reading:               # a Speaker's: the sounds still playing (wb_speaker.py)
                playing = set(reading["sounds"] or ())
                for name, known in dev.desc.get("_sounds", {}).items():
                    known[2] = known[2] and name in playing
                if not reading.get("speaking", False):
                    dev.desc["_speech"] = None
            if "range_image" in reading:
                dev.range_bytes = bytes(reading["range_image"])
                dev._range = None
            if "point_cloud" in reading:
                dev.cloud_bytes = bytes(reading["point_cloud"])
                dev._cloud = None
            if "fov" in reading:                  # a zoomed camera's (a simulation reset may change it)
                dev.desc["fov"] = float(reading["fov"])
            for key in ("image", "recognition", "segmentation_image"):    # a camera's (wb_camera.py)
                if key in reading:
                    dev.camera[key] = reading[key]

    @staticmethod
    def _received(dev: DeviceState, packets: Any) -> None:
        """A receiver's new packets join its queue while they fit its buffer (libController drops
        a packet larger than the room left)."""
        size = int(dev.desc.get("buffer_size", -1))
        for p in packets or ():
            data = bytes(p.get("data", b""))
            if size == -1 or len(data) <= size - dev.queue_bytes:
                direction = [math.nan if x is None else float(x) for x in p.get("direction", (None,) * 3)]
                dev.queue.append((data, float(p.get("signal_strength", math.nan)), direction))
                dev.queue_bytes += len(data)

    # ------------------------------------------------------------------ devices
    def device(self, tag: int, kind: str | None, func: str, listed: bool = False) -> DeviceState:
        """The device of ``tag`` if it is a ``kind`` (``None``: any). A listed-only device of that
        kind prints its one warning and raises :class:`NoValue` (see :func:`answers`), unless
        ``listed`` (the caller answers from its description: a Display's size)."""
        if isinstance(tag, int) and not isinstance(tag, bool) and 1 <= tag <= len(self.devices):
            dev = self.devices[tag - 1]
            if kind is None:
                return dev
            if dev.kind == kind or (kind == ROTATIONAL_MOTOR and dev.kind == LINEAR_MOTOR):
                if not dev.simulated and not listed:
                    self.warn_unsimulated(dev, func)
                    raise NoValue(func)
                return dev
            raise SensoriumError(ErrorCode.UNKNOWN_DEVICE, f"{func}(): device tag {tag} is {dev.name!r}, a {dev.kind}, not a {kind}")
        raise SensoriumError(ErrorCode.UNKNOWN_DEVICE, f"{func}(): invalid device tag {tag!r}")

    @staticmethod
    def warn_unsimulated(dev: DeviceState, func: str) -> None:
        if not dev._warned_unsimulated:
            dev._warned_unsimulated = True
            print(f"Warning: {func}(): Sensorium does not simulate {dev.kind} '{dev.name}': its functions answer "
                  f"Webots' \"no value\" (NaN, None, 0).", file=sys.stderr)

    def tag_of(self, name: str) -> int:
        dev = self.by_name.get(name)
        return 0 if dev is None else dev.tag

    def rpc(self, dev: DeviceState, item: str, args: dict | None = None) -> dict:
        return self.conn.call(f"{self._prefix}{dev.name}/{item}", args)

    def constant(self, dev: DeviceState, key: str) -> Any:
        if key in dev._consts:
            return dev._consts[key]
        keys, service, field = _CONSTANTS[key]
        for k in keys:
            if k in dev.desc:
                value = dev.desc[k]
                break
        else:
            value = self.rpc(dev, service).get(field)
        if key == "lookup_table":
            value = _flat_table(value)
        elif key == "distance_type" and isinstance(value, str):
            value = _DISTANCE_TYPES.get(value.lower(), WB_DISTANCE_SENSOR_GENERIC)
        elif key in ("distance_type", "horizontal_resolution", "number_of_layers"):
            value = int(value)
        else:
            value = float(value)
        dev._consts[key] = value
        return value

    def device_set(self, dev: DeviceState, item: str, value: Any, func: str) -> None:
        """A setting the server keeps: ``/<robot>/<device>/<item>`` with ``{"value": value}``, unless the
        controller's steps have ended (the caller's local copy is all there is then)."""
        if not self.terminated:
            self._expect_success(self.rpc(dev, item, {"value": value}), func)

    def enable(self, dev: DeviceState, period: int, func: str) -> None:
        whole = whole_ms(period)
        if whole is None:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): sampling period must be an integer (ms), got {period!r}")
        period = whole
        if period < 0:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): negative sampling period {period}")
        if period > MAX_PERIOD_MS:                                  # Webots' C int; msgpack could not even send 1e308
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): sampling period {period:.6g} ms is too large "
                                                             f"(at most {MAX_PERIOD_MS})")
        self.device_set(dev, "enable", period, func)
        dev.sampling_period = period
        dev._warned = False

    def enable_point_cloud(self, dev: DeviceState, on: bool, func: str) -> None:
        self.device_set(dev, "enable_point_cloud", bool(on), func)
        dev.point_cloud_enabled = bool(on)
        dev._warned = False

    def set_frequency(self, dev: DeviceState, frequency: float, func: str) -> None:
        lo, hi = self.constant(dev, "min_frequency"), self.constant(dev, "max_frequency")
        number = real(frequency)
        if number is None or not lo <= number <= hi:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): frequency {frequency!r} outside [{lo:g}, {hi:g}] Hz")
        self.device_set(dev, "set_frequency", number, func)
        dev._consts["frequency"] = number

    # -- motors: buffered, sent with the next step request
    def coupled(self, dev: DeviceState) -> list[DeviceState]:
        """The other motors of a joint motor's coupled group (its attach entry's ``coupled``)."""
        return [self.by_name[n] for n in dev.desc.get("coupled", ()) if n in self.by_name]

    def set_motor_position(self, dev: DeviceState, position: float, func: str) -> None:
        """Webots' ``setPosition``: a target (rad), or ±inf for velocity control; NaN is printed
        and ignored (Webots). A coupled group's other motors take it too, each scaled by its
        multiplier (libController's copy of their targets); each motor whose scaled target is beyond
        its limits prints WbMotor's warning, which names the value asked for."""
        number = real(position)
        if number is None:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'position' must be a number, got {position!r}")
        position = number
        if math.isnan(position):
            print(f"Error: {func}() called with an invalid 'position' argument (NaN).", file=sys.stderr)
            return
        for motor in (dev, *self.coupled(dev)):
            lo, hi = _float(motor.desc.get("minPosition"), 0.0), _float(motor.desc.get("maxPosition"), 0.0)
            target = position * _float(motor.desc.get("multiplier"), 1.0)
            if "maxForce" in motor.desc and lo != hi and not math.isinf(position) and not lo <= target <= hi:
                # a joint's motor: Webots clamps the target to its limits with this warning (WbMotor);
                # libController keeps the requested value as the target position, as here
                print(f'WARNING: {motor.kind} "{motor.name}": too {"big" if target > hi else "low"} requested '
                      f'position: {position:g} {">" if target > hi else "<"} {(hi if target > hi else lo):g}',
                      file=sys.stderr)
            if motor is not dev:
                motor.target_position = position if math.isinf(position) else target
        dev.target_position = position
        self.motor_commands.setdefault(dev.name, {})["position"] = position

    def set_motor_quantity(self, dev: DeviceState, key: str, value: float) -> None:
        """A joint motor's acceleration or available torque/force, sent with the next step."""
        self.motor_commands.setdefault(dev.name, {})[key] = value

    def set_motor_velocity(self, dev: DeviceState, velocity: float, func: str) -> None:
        """Webots' ``setVelocity``: clamped to ``maxVelocity`` with Webots' warning; NaN, and a
        negative velocity in position control, are printed and ignored (Webots). A coupled group's
        other motors take it too, each scaled by its multiplier, with their own warnings."""
        number = real(velocity)
        if number is None:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): 'velocity' must be a number, got {velocity!r}")
        velocity = number
        if math.isnan(velocity):
            print(f"Error: {func}() called with an invalid 'velocity' argument (NaN).", file=sys.stderr)
            return
        if velocity < 0.0 and not math.isinf(dev.target_position):
            print(f"Error: {func}() called with negative 'velocity' argument in position control mode "
                  f"({dev.target_position:g}).", file=sys.stderr)     # libController shows the target position
            return
        sent = velocity
        for motor in (dev, *self.coupled(dev)):
            multiplier = _float(motor.desc.get("multiplier"), 1.0)
            wanted, limit = velocity * multiplier, motor.max_velocity
            if abs(wanted) > limit:
                print(f"WARNING: {motor.kind} \"{motor.name}\": The requested velocity {wanted:g} exceeds "
                      f"'maxVelocity' = {limit:g}.", file=sys.stderr)
                wanted = math.copysign(limit, wanted)
                if motor is dev:
                    sent = wanted / multiplier
            if motor is not dev:
                motor.velocity = wanted
        dev.velocity = sent
        self.motor_commands.setdefault(dev.name, {})["velocity"] = sent

    @staticmethod
    def _expect_success(result: dict, func: str) -> None:
        if result.get("success", True) is False:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): refused by the server ({result!r})")

    def warn_disabled(self, dev: DeviceState, func: str, enabler: str, what: str = "a disabled device") -> None:
        if not dev._warned:
            dev._warned = True
            print(f"Error: {func}() called for {what}! Please use: {enabler}().", file=sys.stderr)

    # -- lidar buffers (zeros before the first measurement, as the server's initial image)
    def range_bytes(self, dev: DeviceState) -> bytes:
        if dev.range_bytes is None:
            n = self.constant(dev, "horizontal_resolution") * self.constant(dev, "number_of_layers")
            return bytes(4 * n)
        return dev.range_bytes

    def cloud_bytes(self, dev: DeviceState) -> bytes:
        if dev.cloud_bytes is None:
            n = self.constant(dev, "horizontal_resolution") * self.constant(dev, "number_of_layers")
            return bytes(arrays.POINT_SIZE * n)
        return dev.cloud_bytes

    def range_image(self, dev: DeviceState) -> Any:
        if dev._range is None:
            dev._range = arrays.float32s(self.range_bytes(dev))
        return dev._range

    def point_cloud(self, dev: DeviceState) -> Any:
        if dev._cloud is None:
            dev._cloud = arrays.points(self.cloud_bytes(dev))
        return dev._cloud

    # ------------------------------------------------------------------ lifecycle
    def close(self) -> None:
        """Detach (best effort, short wait) and close the sockets. Idempotent."""
        if self.closed:
            return
        self.closed = True
        for hook in self.close_hooks:
            hook()
        self.conn.stop_heartbeat()
        if self.pending is not None:
            self.conn.discard(self.pending)
            self.pending = None
        try:
            if not self.conn.closed:
                self.conn.call("detach", {"session": self.session}, timeout=0.5)
        except SensoriumError:
            pass
        finally:
            self.conn.close()

    def __enter__(self) -> RobotClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# ====================================================================== the flat API

_robot: RobotClient | None = None
_atexit_registered = False


def current() -> RobotClient:
    """The process's robot session (after :func:`wb_robot_init`)."""
    if _robot is None:
        raise SensoriumError(ErrorCode.WRONG_STATE, "no robot: call wb_robot_init() first")
    return _robot


def sensor_enable(tag: int, kind: str, period: int, func: str) -> None:
    """Every sensor's ``wb_<kind>_enable``/``_disable`` (period 0): the device of ``tag``, if it is a
    ``kind``, enabled on the server and here."""
    r = current()
    r.enable(r.device(tag, kind, func), period, func)


def sensor_period(tag: int, kind: str, func: str) -> int:
    """Every sensor's ``wb_<kind>_get_sampling_period``."""
    return current().device(tag, kind, func).sampling_period


def sensor_reading(tag: int, kind: str, func: str, enabler: str) -> DeviceState:
    """The device for a getter of its readings, with Webots' message (once per disable) when it is
    read while disabled."""
    r = current()
    dev = r.device(tag, kind, func)
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, enabler)
    return dev


def wb_robot_init(url: str | None = None, **options: Any) -> None:
    """Attach this process to its robot (URL from the environment unless given). Idempotent."""
    global _robot, _atexit_registered
    if _robot is not None and not _robot.closed:
        return
    _robot = RobotClient(url, **options)
    if not _atexit_registered:
        atexit.register(wb_robot_cleanup)
        _atexit_registered = True


def wb_robot_cleanup() -> None:
    global _robot
    if _robot is not None:
        robot, _robot = _robot, None
        robot.close()


def _ended(r: RobotClient) -> None:
    """libController's end of a controller: once a step has answered -1 because the simulation ended
    for it (the server quit, stopped at ``--until`` or went away, ``simulationQuit``), the next step
    cleans up and ends the process with status 0, so a loop that ignores -1 does not spin forever."""
    if r.terminated and r.pending is None:
        if r.quit_returned:
            wb_robot_cleanup()
            raise SystemExit(0)
        r.quit_returned = True                  # this step's -1 is the first (simulationQuit)


def _noted(r: RobotClient, status: int) -> int:
    if status == -1 and r.terminated:
        r.quit_returned = True
    return status


def wb_robot_step(duration: int | None = None) -> int:
    r = current()
    _ended(r)
    return _noted(r, r.step(duration))


def wb_robot_step_begin(duration: int | None = None) -> int:
    r = current()
    _ended(r)
    return _noted(r, r.step_begin(duration))


def wb_robot_step_end() -> int:
    r = current()
    return _noted(r, r.step_end())


def wb_robot_get_time() -> float:
    return current().time_ms / 1000.0


def wb_robot_get_basic_time_step() -> float:
    return float(current().basic_time_step)


def wb_robot_get_name() -> str:
    return current().name


def wb_robot_get_synchronization() -> bool:
    return current().synchronization


def wb_robot_get_number_of_devices() -> int:
    return len(current().devices)


def wb_robot_get_device(name: str) -> int:
    """The device's tag; 0, with a warning as in Webots, if the robot has no such device."""
    name = c_string(name)
    r = current()
    if not isinstance(name, str) or not name:
        print(f"Error: wb_robot_get_device() called with a NULL or empty name ({name!r}).", file=sys.stderr)
        return 0
    tag = r.tag_of(name)
    if tag == 0:
        print(f'Warning: wb_robot_get_device(): robot "{r.name}" has no device "{name}".', file=sys.stderr)
    return tag


def wb_robot_get_device_by_index(index: int) -> int:
    """The tag of device ``index`` (Webots' device order); 0, with Webots' error, outside the range."""
    devices = current().devices
    if isinstance(index, int) and not isinstance(index, bool) and 0 <= index < len(devices):
        return devices[index].tag
    print(f"Error: wb_robot_get_device_by_index(): index {index!r} is outside [0, {len(devices) - 1}].",
          file=sys.stderr)
    return 0


def wb_device_get_name(tag: int) -> str:
    return current().device(tag, None, "wb_device_get_name").name


def wb_device_get_model(tag: int) -> str:
    """The device's Webots ``model`` field ("" when the world gives none)."""
    return current().device(tag, None, "wb_device_get_model").model


def wb_device_get_node_type(tag: int) -> int:
    """Webots' ``WB_NODE_*`` value of the device's type (``WB_NODE_GPS``, ...)."""
    return current().device(tag, None, "wb_device_get_node_type").node_type


def wb_robot_get_model() -> str:
    return current().model


def wb_robot_get_custom_data() -> str:
    return current().custom_data


def wb_robot_set_custom_data(data: str) -> None:
    """Stored by the server at once (other clients' ``get_custom_data`` see it)."""
    data = c_string(data)
    if not isinstance(data, str):
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"wb_robot_set_custom_data(): data must be a string, got {data!r}")
    r = current()
    if not r.terminated:
        r.conn.call(f"/{r.name}/robot/set_custom_data", {"value": data})
    r.custom_data = data


def wb_robot_get_supervisor() -> bool:
    return current().supervisor


def wb_robot_get_mode() -> int:
    """Always ``WB_MODE_SIMULATION`` (no remote control or cross-compilation here)."""
    current()
    return WB_MODE_SIMULATION


def wb_robot_get_type() -> str:
    return "Supervisor" if current().supervisor else "Robot"


# ---------------------------------------------------------------------- keyboard (no key is ever pressed)

def wb_keyboard_enable(sampling_period: int) -> None:
    period = whole_ms(sampling_period)
    if period is None or period < 0:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT,
                             f"wb_keyboard_enable(): sampling period must be an integer >= 0 (ms), got {sampling_period!r}")
    current().keyboard_period = period


def wb_keyboard_disable() -> None:
    current().keyboard_period = 0


def wb_keyboard_get_sampling_period() -> int:
    return current().keyboard_period


def wb_keyboard_get_key() -> int:
    """-1: a headless server has no keyboard (Webots' answer when no key is pressed)."""
    r = current()
    if r.keyboard_period <= 0:
        print("Error: wb_keyboard_get_key() called for a disabled device! Please use: wb_keyboard_enable().",
              file=sys.stderr)
    return -1


def wb_device_get_type_name(tag: int) -> str:
    """Sensorium extension: the device's node type name ("LightSensor", "DistanceSensor", "Lidar",
    "RotationalMotor")."""
    return current().device(tag, None, "wb_device_get_type_name").kind
