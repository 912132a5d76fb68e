"""Webots' C controller API (``wb_*`` functions over opaque device tags) on Sensorium.

    from sensorium.client.wb import *
    wb_robot_init()                                   # URL from SENSORIUM_/WEBOTS_CONTROLLER_URL
    ps0 = wb_robot_get_device("ps0")
    wb_distance_sensor_enable(ps0, 32)
    while wb_robot_step(32) != -1:
        print(wb_distance_sensor_get_value(ps0))

As in libController, readings arrive with the step reply (PROTOCOL.md §3.6) and are cached here:
a ``get_value`` costs no round trip, reads NaN before the first measurement and keeps the last
value after a ``disable``. ``enable``/``disable``/``set_frequency`` are RPCs. Constant getters
(lookup tables, ranges, resolutions…) come from the device descriptions of the ``attach`` reply.
Motor commands (``wb_motor_set_position``/``_velocity``) cost no round trip either: like
libController they are buffered and travel with the next step request (PROTOCOL.md §3.4), and
the motor getters answer from the client's copy.

Differences from Webots' C library, all on error paths: an invalid tag, a negative sampling
period, an out-of-range layer or frequency, a NaN motor command or a negative velocity in position
control raise :class:`SensoriumError` instead of printing and carrying on; reads of a disabled
device print Webots' message to stderr once per disable. A velocity above ``maxVelocity`` is
clamped here with Webots' warning (Webots clamps in the simulator).
One process drives one robot through these functions; :class:`RobotClient` is the same thing as
an object, for programs (and tests) that want several.
"""

from __future__ import annotations

import atexit
import math
import sys
from typing import Any

from sensorium.client import arrays
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

WB_ROTATIONAL = 0
WB_LINEAR = 1

LIGHT_SENSOR = "LightSensor"
DISTANCE_SENSOR = "DistanceSensor"
LIDAR = "Lidar"
ROTATIONAL_MOTOR = "RotationalMotor"

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


class DeviceState:
    """What the client knows about one device: its description, enable state and latest reading."""

    __slots__ = ("tag", "index", "name", "kind", "desc", "sampling_period", "value", "range_bytes",
                 "cloud_bytes", "point_cloud_enabled", "max_velocity", "target_position", "velocity",
                 "_consts", "_range", "_cloud", "_warned")

    def __init__(self, index: int, desc: dict):
        self.index = index
        self.tag = index + 1                     # 0 is "no device", as in Webots
        self.name = str(desc.get("name", f"device{index}"))
        self.kind = str(desc.get("type", ""))
        self.desc = desc
        self.sampling_period = int(desc.get("sampling_period", desc.get("samplingPeriod", 0)) or 0)
        self.value = math.nan
        self.range_bytes: bytes | None = None
        self.cloud_bytes: bytes | None = None
        self.point_cloud_enabled = bool(desc.get("point_cloud_enabled", desc.get("pointCloudEnabled", False)))
        # motors: the commands as last set (the server's at attach, then this controller's)
        self.max_velocity = _float(desc.get("maxVelocity", desc.get("max_velocity")), 10.0)   # Webots' default
        self.target_position = _float(desc.get("targetPosition", desc.get("target_position")), 0.0)
        self.velocity = _float(desc.get("velocity"), self.max_velocity)       # libController starts at maxVelocity
        self._consts: dict[str, Any] = {}
        self._range: Any = None                  # decoded forms, rebuilt when new bytes arrive
        self._cloud: Any = None
        self._warned = False

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
        self.devices = [DeviceState(i, d) for i, d in enumerate(reply.get("devices", []))]
        self.by_name = {d.name: d for d in self.devices}
        self.motor_commands: dict[str, dict[str, float]] = {}   # sent with the next step request
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
        if isinstance(duration, bool) or not isinstance(duration, int):
            if isinstance(duration, float) and float(duration).is_integer():
                duration = int(duration)
            else:
                raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"step duration must be an integer (ms), got {duration!r}")
        args: dict[str, Any] = {"duration": duration}
        if self.motor_commands:
            args["motors"], self.motor_commands = self.motor_commands, {}
        self.pending = self.conn.send(self._prefix + "robot/step", args)
        return 0

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
            self.terminated = True
            return -1
        except SensoriumError as exc:
            if exc.code == ErrorCode.SHUTTING_DOWN:
                self.terminated = True
                return -1
            raise
        status = int(result.get("status", 0))
        self.time_ms = int(result.get("time_ms", self.time_ms))
        values = result.get("values")
        if values:
            self._apply(values)
        if status == -1:
            self.terminated = True
        return status

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
            if "range_image" in reading:
                dev.range_bytes = bytes(reading["range_image"])
                dev._range = None
            if "point_cloud" in reading:
                dev.cloud_bytes = bytes(reading["point_cloud"])
                dev._cloud = None

    # ------------------------------------------------------------------ devices
    def device(self, tag: int, kind: str | None, func: str) -> DeviceState:
        if isinstance(tag, int) and not isinstance(tag, bool) and 1 <= tag <= len(self.devices):
            dev = self.devices[tag - 1]
            if kind is None or dev.kind == kind:
                return dev
            raise SensoriumError(ErrorCode.UNKNOWN_DEVICE, f"{func}(): device tag {tag} is {dev.name!r}, a {dev.kind}, not a {kind}")
        raise SensoriumError(ErrorCode.UNKNOWN_DEVICE, f"{func}(): invalid device tag {tag!r}")

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

    def enable(self, dev: DeviceState, period: int, func: str) -> None:
        if isinstance(period, bool) or not isinstance(period, int):
            if isinstance(period, float) and float(period).is_integer():
                period = int(period)
            else:
                raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): sampling period must be an integer (ms), got {period!r}")
        if period < 0:
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): negative sampling period {period}")
        if not self.terminated:
            self._expect_success(self.rpc(dev, "enable", {"value": period}), func)
        dev.sampling_period = period
        dev._warned = False

    def enable_point_cloud(self, dev: DeviceState, on: bool, func: str) -> None:
        if not self.terminated:
            self._expect_success(self.rpc(dev, "enable_point_cloud", {"value": bool(on)}), func)
        dev.point_cloud_enabled = bool(on)
        dev._warned = False

    def set_frequency(self, dev: DeviceState, frequency: float, func: str) -> None:
        lo, hi = self.constant(dev, "min_frequency"), self.constant(dev, "max_frequency")
        if not (isinstance(frequency, (int, float)) and lo <= frequency <= hi):
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): frequency {frequency!r} outside [{lo:g}, {hi:g}] Hz")
        if not self.terminated:
            self._expect_success(self.rpc(dev, "set_frequency", {"value": float(frequency)}), func)
        dev._consts["frequency"] = float(frequency)

    # -- motors: buffered, sent with the next step request
    @staticmethod
    def _number(value: Any, what: str, func: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): '{what}' must be a number, got {value!r}")
        value = float(value)
        if math.isnan(value):
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}() called with an invalid '{what}' argument (NaN)")
        return value

    def set_motor_position(self, dev: DeviceState, position: float, func: str) -> None:
        """Webots' ``setPosition``: a target (rad), or ±inf for velocity control."""
        position = self._number(position, "position", func)
        dev.target_position = position
        self.motor_commands.setdefault(dev.name, {})["position"] = position

    def set_motor_velocity(self, dev: DeviceState, velocity: float, func: str) -> None:
        """Webots' ``setVelocity``: clamped to ``maxVelocity`` with Webots' warning."""
        velocity = self._number(velocity, "velocity", func)
        if velocity < 0.0 and not math.isinf(dev.target_position):
            raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}() called with negative 'velocity' argument in "
                                                             f"position control mode ({dev.target_position:g})")
        limit = dev.max_velocity
        if abs(velocity) > limit:
            print(f"WARNING: {dev.kind} \"{dev.name}\": The requested velocity {velocity:g} exceeds "
                  f"'maxVelocity' = {limit:g}.", file=sys.stderr)
            velocity = math.copysign(limit, velocity)
        dev.velocity = velocity
        self.motor_commands.setdefault(dev.name, {})["velocity"] = velocity

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


def wb_robot_step(duration: int | None = None) -> int:
    return current().step(duration)


def wb_robot_step_begin(duration: int | None = None) -> int:
    return current().step_begin(duration)


def wb_robot_step_end() -> int:
    return current().step_end()


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
    """The device's tag, 0 if the robot has no such device."""
    return current().tag_of(name)


def wb_robot_get_device_by_index(index: int) -> int:
    devices = current().devices
    return devices[index].tag if 0 <= index < len(devices) else 0


def wb_device_get_name(tag: int) -> str:
    return current().device(tag, None, "wb_device_get_name").name


def wb_device_get_type_name(tag: int) -> str:
    """Sensorium extension: the device's node type name ("LightSensor", "DistanceSensor", "Lidar",
    "RotationalMotor")."""
    return current().device(tag, None, "wb_device_get_type_name").kind


# ---------------------------------------------------------------------- light sensor

def _scalar_value(tag: int, kind: str, func: str, enabler: str) -> float:
    robot = current()
    dev = robot.device(tag, kind, func)
    if dev.sampling_period <= 0:
        robot.warn_disabled(dev, func, enabler)
    return dev.value


def wb_light_sensor_enable(tag: int, sampling_period: int) -> None:
    r = current()
    r.enable(r.device(tag, LIGHT_SENSOR, "wb_light_sensor_enable"), sampling_period, "wb_light_sensor_enable")


def wb_light_sensor_disable(tag: int) -> None:
    r = current()
    r.enable(r.device(tag, LIGHT_SENSOR, "wb_light_sensor_disable"), 0, "wb_light_sensor_disable")


def wb_light_sensor_get_sampling_period(tag: int) -> int:
    return current().device(tag, LIGHT_SENSOR, "wb_light_sensor_get_sampling_period").sampling_period


def wb_light_sensor_get_value(tag: int) -> float:
    return _scalar_value(tag, LIGHT_SENSOR, "wb_light_sensor_get_value", "wb_light_sensor_enable")


def wb_light_sensor_get_lookup_table_size(tag: int) -> int:
    return len(wb_light_sensor_get_lookup_table(tag)) // 3


def wb_light_sensor_get_lookup_table(tag: int) -> list[float]:
    """The N x 3 table flattened: input, output, noise, input, output, noise…"""
    r = current()
    return list(r.constant(r.device(tag, LIGHT_SENSOR, "wb_light_sensor_get_lookup_table"), "lookup_table"))


# ---------------------------------------------------------------------- distance sensor

def wb_distance_sensor_enable(tag: int, sampling_period: int) -> None:
    r = current()
    r.enable(r.device(tag, DISTANCE_SENSOR, "wb_distance_sensor_enable"), sampling_period, "wb_distance_sensor_enable")


def wb_distance_sensor_disable(tag: int) -> None:
    r = current()
    r.enable(r.device(tag, DISTANCE_SENSOR, "wb_distance_sensor_disable"), 0, "wb_distance_sensor_disable")


def wb_distance_sensor_get_sampling_period(tag: int) -> int:
    return current().device(tag, DISTANCE_SENSOR, "wb_distance_sensor_get_sampling_period").sampling_period


def wb_distance_sensor_get_value(tag: int) -> float:
    return _scalar_value(tag, DISTANCE_SENSOR, "wb_distance_sensor_get_value", "wb_distance_sensor_enable")


def _distance_constant(tag: int, key: str, func: str) -> Any:
    r = current()
    return r.constant(r.device(tag, DISTANCE_SENSOR, func), key)


def wb_distance_sensor_get_min_value(tag: int) -> float:
    return _distance_constant(tag, "min_value", "wb_distance_sensor_get_min_value")


def wb_distance_sensor_get_max_value(tag: int) -> float:
    return _distance_constant(tag, "max_value", "wb_distance_sensor_get_max_value")


def wb_distance_sensor_get_aperture(tag: int) -> float:
    return _distance_constant(tag, "aperture", "wb_distance_sensor_get_aperture")


def wb_distance_sensor_get_type(tag: int) -> int:
    """One of WB_DISTANCE_SENSOR_GENERIC, _INFRA_RED, _SONAR, _LASER."""
    return _distance_constant(tag, "distance_type", "wb_distance_sensor_get_type")


def wb_distance_sensor_get_lookup_table_size(tag: int) -> int:
    return len(wb_distance_sensor_get_lookup_table(tag)) // 3


def wb_distance_sensor_get_lookup_table(tag: int) -> list[float]:
    return list(_distance_constant(tag, "lookup_table", "wb_distance_sensor_get_lookup_table"))


# ---------------------------------------------------------------------- lidar

def _lidar(tag: int, func: str) -> DeviceState:
    return current().device(tag, LIDAR, func)


def _lidar_constant(tag: int, key: str, func: str) -> Any:
    return current().constant(_lidar(tag, func), key)


def _check_layer(r: RobotClient, dev: DeviceState, layer: int, func: str) -> int:
    layers = r.constant(dev, "number_of_layers")
    if isinstance(layer, bool) or not isinstance(layer, int) or not 0 <= layer < layers:
        raise SensoriumError(ErrorCode.INVALID_ARGUMENT, f"{func}(): layer {layer!r} outside [0, {layers - 1}]")
    return layer


def wb_lidar_enable(tag: int, sampling_period: int) -> None:
    r = current()
    r.enable(_lidar(tag, "wb_lidar_enable"), sampling_period, "wb_lidar_enable")


def wb_lidar_disable(tag: int) -> None:
    r = current()
    r.enable(_lidar(tag, "wb_lidar_disable"), 0, "wb_lidar_disable")


def wb_lidar_get_sampling_period(tag: int) -> int:
    return _lidar(tag, "wb_lidar_get_sampling_period").sampling_period


def wb_lidar_enable_point_cloud(tag: int) -> None:
    current().enable_point_cloud(_lidar(tag, "wb_lidar_enable_point_cloud"), True, "wb_lidar_enable_point_cloud")


def wb_lidar_disable_point_cloud(tag: int) -> None:
    current().enable_point_cloud(_lidar(tag, "wb_lidar_disable_point_cloud"), False, "wb_lidar_disable_point_cloud")


def wb_lidar_is_point_cloud_enabled(tag: int) -> bool:
    return _lidar(tag, "wb_lidar_is_point_cloud_enabled").point_cloud_enabled


def lidar_range_bytes(tag: int, layer: int | None = None, func: str = "wb_lidar_get_range_image") -> bytes | None:
    """The raw ``<f4`` range image (or one layer of it) with Webots' checks: a disabled lidar
    prints an error and still returns the whole cached image, but no layer (``None``)."""
    r = current()
    dev = _lidar(tag, func)
    if layer is not None:
        _check_layer(r, dev, layer, func)
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, "wb_lidar_enable")
        if layer is not None:
            return None
    buf = r.range_bytes(dev)
    if layer is None:
        return buf
    row = 4 * r.constant(dev, "horizontal_resolution")
    return buf[row * layer:row * (layer + 1)]


def lidar_cloud_bytes(tag: int, layer: int | None = None, func: str = "wb_lidar_get_point_cloud") -> bytes | None:
    """The raw point-cloud records (or one layer's); ``None`` with Webots' message unless the
    lidar and its point cloud are enabled."""
    r = current()
    dev = _lidar(tag, func)
    if layer is not None:
        _check_layer(r, dev, layer, func)
    if not _cloud_usable(r, dev, func):
        return None
    buf = r.cloud_bytes(dev)
    if layer is None:
        return buf
    row = arrays.POINT_SIZE * r.constant(dev, "horizontal_resolution")
    return buf[row * layer:row * (layer + 1)]


def _cloud_usable(r: RobotClient, dev: DeviceState, func: str) -> bool:
    if not dev.point_cloud_enabled:
        r.warn_disabled(dev, func, "wb_lidar_enable_point_cloud", "a lidar with point cloud disabled")
        return False
    if dev.sampling_period <= 0:
        r.warn_disabled(dev, func, "wb_lidar_enable")
        return False
    return True


def wb_lidar_get_range_image(tag: int) -> Any:
    """The latest range image, ``layers x horizontal_resolution`` float32 values flattened (left to
    right, first layer to last): a read-only numpy array, or ``array('f')`` without numpy.
    Zeros before the first measurement."""
    buf = lidar_range_bytes(tag)
    if arrays.numpy_module() is None:
        return arrays.float32s(buf or b"")
    r = current()
    return r.range_image(r.devices[tag - 1])


def wb_lidar_get_layer_range_image(tag: int, layer: int) -> Any:
    """One layer of the range image; ``None`` (with Webots' message) while the lidar is disabled."""
    buf = lidar_range_bytes(tag, layer, "wb_lidar_get_layer_range_image")
    return None if buf is None else arrays.float32s(buf)


def wb_lidar_get_point_cloud(tag: int) -> Any:
    """The latest point cloud (records x, y, z, layer_id, time): a read-only numpy structured array,
    or a list of tuples without numpy; ``None`` unless the lidar and its point cloud are enabled."""
    buf = lidar_cloud_bytes(tag)
    if buf is None:
        return None
    if arrays.numpy_module() is None:
        return arrays.points(buf)
    r = current()
    return r.point_cloud(r.devices[tag - 1])


def wb_lidar_get_layer_point_cloud(tag: int, layer: int) -> Any:
    buf = lidar_cloud_bytes(tag, layer, "wb_lidar_get_layer_point_cloud")
    return None if buf is None else arrays.points(buf)


def wb_lidar_get_number_of_points(tag: int) -> int:
    """layers x horizontal resolution; 0 (with Webots' message) unless the lidar and its point
    cloud are enabled."""
    r = current()
    func = "wb_lidar_get_number_of_points"
    dev = _lidar(tag, func)
    if not _cloud_usable(r, dev, func):
        return 0
    return r.constant(dev, "horizontal_resolution") * r.constant(dev, "number_of_layers")


def wb_lidar_get_horizontal_resolution(tag: int) -> int:
    return _lidar_constant(tag, "horizontal_resolution", "wb_lidar_get_horizontal_resolution")


def wb_lidar_get_number_of_layers(tag: int) -> int:
    return _lidar_constant(tag, "number_of_layers", "wb_lidar_get_number_of_layers")


def wb_lidar_get_fov(tag: int) -> float:
    return _lidar_constant(tag, "fov", "wb_lidar_get_fov")


def wb_lidar_get_vertical_fov(tag: int) -> float:
    return _lidar_constant(tag, "vertical_fov", "wb_lidar_get_vertical_fov")


def wb_lidar_get_min_range(tag: int) -> float:
    return _lidar_constant(tag, "min_range", "wb_lidar_get_min_range")


def wb_lidar_get_max_range(tag: int) -> float:
    return _lidar_constant(tag, "max_range", "wb_lidar_get_max_range")


def wb_lidar_get_frequency(tag: int) -> float:
    return _lidar_constant(tag, "frequency", "wb_lidar_get_frequency")


def wb_lidar_set_frequency(tag: int, frequency: float) -> None:
    current().set_frequency(_lidar(tag, "wb_lidar_set_frequency"), frequency, "wb_lidar_set_frequency")


def wb_lidar_get_min_frequency(tag: int) -> float:
    return _lidar_constant(tag, "min_frequency", "wb_lidar_get_min_frequency")


def wb_lidar_get_max_frequency(tag: int) -> float:
    return _lidar_constant(tag, "max_frequency", "wb_lidar_get_max_frequency")



# ---------------------------------------------------------------------- motor

def _motor(tag: int, func: str) -> DeviceState:
    return current().device(tag, ROTATIONAL_MOTOR, func)


def wb_motor_set_position(tag: int, position: float) -> None:
    """Target position (rad) sent with the next step; ``float('inf')`` selects velocity control."""
    current().set_motor_position(_motor(tag, "wb_motor_set_position"), position, "wb_motor_set_position")


def wb_motor_set_velocity(tag: int, velocity: float) -> None:
    """Velocity (rad/s) sent with the next step: the wheel speed in velocity control, the speed
    limit in position control. Above ``maxVelocity`` it is clamped (with Webots' warning)."""
    current().set_motor_velocity(_motor(tag, "wb_motor_set_velocity"), velocity, "wb_motor_set_velocity")


def wb_motor_get_velocity(tag: int) -> float:
    return _motor(tag, "wb_motor_get_velocity").velocity


def wb_motor_get_max_velocity(tag: int) -> float:
    return _motor(tag, "wb_motor_get_max_velocity").max_velocity


def wb_motor_get_target_position(tag: int) -> float:
    return _motor(tag, "wb_motor_get_target_position").target_position


def wb_motor_get_min_position(tag: int) -> float:
    """0 with :func:`wb_motor_get_max_position` 0: no position limits (a wheel)."""
    return _float(_motor(tag, "wb_motor_get_min_position").desc.get("minPosition"), 0.0)


def wb_motor_get_max_position(tag: int) -> float:
    return _float(_motor(tag, "wb_motor_get_max_position").desc.get("maxPosition"), 0.0)


def wb_motor_get_type(tag: int) -> int:
    _motor(tag, "wb_motor_get_type")
    return WB_ROTATIONAL


def wb_motor_get_position_sensor(tag: int) -> int:
    """0: Sensorium's wheels have no PositionSensor."""
    _motor(tag, "wb_motor_get_position_sensor")
    return 0


__all__ = [n for n in list(globals()) if n.startswith(("wb_", "WB_"))] + ["SensoriumError", "RobotClient"]
