"""Topics (PROTOCOL.md §4): names, demand, message building, sequence numbers, recorder hook.

Demand decides what is computed. A device is measured while its controller enabled it *or* one
of its topics is demanded — covered by an XPUB subscription prefix (a prefix covers a topic when
``topic + "\\0"`` starts with it; the empty prefix covers everything), recorded by the recorder, or
subscribed by a viewer (a Foxglove client, :meth:`Topics.set_viewer_demand`).
A demanded device whose controller has not enabled it runs at the basic time step; the
controller's own ``enable`` always wins and is never altered (its period, phase and
``get_sampling_period`` stay exactly as requested). A lidar builds its point cloud only while the
controller enabled it or its ``point_cloud`` topic is demanded.

After each basic step :meth:`Topics.publish` builds the messages of every demanded topic whose
device produced a new value (plus ``/clock``, each demanded ``/<robot>/pose``, for a robot with
joints ``/<robot>/joint_states``, and for a robot with a battery ``/<robot>/battery`` when its battery
was sampled: at its controller's sensor period, else every basic step while demanded) as ready-to-send
frames, calls the recorder (and the viewer sink, sensorium.server.viewer) with the very same bytes,
and counts ``seq`` per topic. A text a controller sends its robot window (``wwi_send``) is published
on ``/<robot>/robot_window`` when it arrives, not after a step, and a text sent to the window side
for the controller (``window_send``) on ``/<robot>/robot_window/to_controller`` when it is queued:
:meth:`Topics.robot_window` leaves their frames in :attr:`Topics.outbox`, which the transport sends
after the requests it served. A robot's pose
is read and packed only while its pose topic is demanded (``work["poses_built"]`` counts them).
This module does no I/O.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sensorium.schemas import messages as msgs
from sensorium.schemas.devices import KINDS
from sensorium.schemas.wire import pack, stamp, topic_frame

__all__ = ["Topic", "Topics", "Recorder", "POINT_DTYPE", "header", "image_msg", "point_cloud_msg", "lidar_cloud_msg", "laser_scan_angles",
           "pose_quaternion", "pose_msg", "joint_states_msg", "battery_state_msg"]

MAX_PREFIX = 1024     # bytes: longer subscriptions are refused (topic names are short)

POINT_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("layer_id", "<i4"), ("time", "<f4")])
"""A WbLidarPoint on the wire (20 bytes, little-endian)."""

Recorder = Callable[[str, str, bytes, bytes, int, int], None]
"""``recorder(topic, type, envelope_bytes, body_bytes, stamp_ns, seq)``."""

CLOCK = "/clock"
WORLD_FRAME = "world"
_INFRA_RED = 1
_SONAR = 2


@dataclass(frozen=True, slots=True)
class Topic:
    name: str
    type: str
    kind: str                # value | range_image | laser_scan | point_cloud | clock | pose | joint_states | robot_window
                             # | robot_window_to_controller | battery
    path: str | None         # "robot/device"; the robot's name for pose; None for /clock
    frame: bytes             # name + NUL


@dataclass(eq=False)
class Control:
    """One device as the server drives it: the controller's requests, the demand, publishing state."""

    robot: str
    device: Any
    kind: str                                  # its device kind (schemas/devices.py)
    topics: list[Topic]
    frame_id: str
    controller_period: int = 0                 # what the controller asked (get_sampling_period)
    controller_point_cloud: bool = False       # what the controller asked (is_point_cloud_enabled)
    demanded: set[str] = field(default_factory=set)   # kinds of this device's demanded topics
    seen: int = 0                              # device.measurements at the last publish pass
    _cache_m: int = -1
    _range: bytes = b""
    _cloud: bytes | None = None

    def __post_init__(self) -> None:
        self.topic_types: dict[str, str] = {t.kind: t.type for t in self.topics}   # item -> message type
        # item -> the device attribute it publishes (schemas/devices.py TopicDecl.reading)
        self.topic_readings: dict[str, str] = {t.item: t.reading for t in KINDS[self.kind].topics}

    @property
    def path(self) -> str:
        return f"{self.robot}/{self.device.name}"

    # -- lidar bytes, built once per measurement and shared by topics and step replies
    def range_bytes(self) -> bytes:
        self._refresh()
        return self._range

    def cloud_bytes(self) -> bytes:
        self._refresh()
        if self._cloud is None:
            self._cloud = _cloud_records(self.device.point_cloud)
        return self._cloud

    def _refresh(self) -> None:
        m = self.device.measurements
        if m != self._cache_m:
            self._cache_m = m
            self._range = np.ascontiguousarray(self.device.range_image, dtype="<f4").tobytes()
            self._cloud = None


def _cloud_records(pc: np.ndarray) -> bytes:
    if pc.dtype != POINT_DTYPE:
        pc = pc.astype(POINT_DTYPE)
    return np.ascontiguousarray(pc).tobytes()


# ---------------------------------------------------------------------- message builders

def header(frame_id: str, ms: int) -> dict:
    return {"stamp": stamp(max(ms, 0) * 1_000_000), "frame_id": frame_id}


def image_msg(hdr: dict, height: int, width: int, data: bytes, encoding: str = "32FC1") -> dict:
    """``sensor_msgs/Image``: 32FC1 (a lidar's or range finder's range image) or bgra8 (a camera's);
    4 bytes a pixel either way."""
    return {"header": hdr, "height": height, "width": width, "encoding": encoding, "is_bigendian": 0,
            "step": 4 * width, "data": data}


def point_cloud_msg(hdr: dict, pc: np.ndarray) -> dict:
    """``sensor_msgs/PointCloud`` from WbLidarPoint records: points N×3 ``<f4`` and a ``layer`` channel."""
    if pc.dtype != POINT_DTYPE:
        pc = pc.astype(POINT_DTYPE)
    pc = np.ascontiguousarray(pc)
    raw = pc.view(np.uint8).reshape(len(pc), POINT_DTYPE.itemsize)
    points = raw[:, :12].tobytes()
    layers = pc["layer_id"].astype("<f4").tobytes()
    return {"header": hdr, "points": points, "channels": [{"name": "layer", "values": layers}]}


def lidar_cloud_msg(hdr: dict, lidar: Any) -> dict:
    """:func:`point_cloud_msg` of a whole lidar scan, from the device's point coordinates and its
    constant layer channel (no record copies: the buffers are handed to msgpack as they are).
    A device with only records (``point_cloud``) goes through :func:`point_cloud_msg`."""
    if not hasattr(lidar, "cloud_points"):
        return point_cloud_msg(hdr, lidar.point_cloud)
    xyz = np.ascontiguousarray(lidar.cloud_points(), dtype="<f4")
    layers = np.ascontiguousarray(lidar.cloud_layers(), dtype="<f4")
    return {"header": hdr, "points": memoryview(xyz).cast("B"),
            "channels": [{"name": "layer", "values": memoryview(layers).cast("B")}]}


def pose_quaternion(pose: Any) -> list[float]:
    """(x, y, z, w) of a pose: its own ``quaternion`` if it has one, else from its 3×3 rotation."""
    q = getattr(pose, "quaternion", None)
    if q is not None:
        return [float(v) for v in q]
    m = pose.rotation
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, x, y, z = 0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        w, x, y, z = (m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        w, x, y, z = (m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        w, x, y, z = (m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s
    return [float(x), float(y), float(z), float(w)]


def pose_msg(hdr: dict, pose: Any) -> dict:
    """``geometry_msgs/PoseStamped`` of a robot pose (float64; same numbers as ``get_pose``)."""
    t = [float(v) for v in pose.translation]
    q = pose_quaternion(pose)
    return {"header": hdr,
            "pose": {"position": {"x": t[0], "y": t[1], "z": t[2]},
                     "orientation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}}}


def joint_states_msg(hdr: dict, joints: dict[str, Any]) -> dict:
    """``sensor_msgs/JointState`` of a robot's joints (its motors that are no drive's, in device
    order): positions (rad or m) and velocities (over the last basic step, signed); effort empty."""
    motors = list(joints.values())
    return {"header": hdr, "name": [m.name for m in motors],
            "position": np.array([m.position for m in motors], dtype="<f8").tobytes(),
            "velocity": np.array([m.rate for m in motors], dtype="<f8").tobytes(), "effort": b""}


# Battery.state (sim/battery.py) -> sensor_msgs/BatteryState's power_supply_status
_SUPPLY_STATUS = {"charging": msgs.BatteryState.STATUS_CHARGING, "discharging": msgs.BatteryState.STATUS_DISCHARGING,
                  "idle": msgs.BatteryState.STATUS_NOT_CHARGING, "full": msgs.BatteryState.STATUS_FULL}


def battery_state_msg(hdr: dict, energy: float, maximum: float, state: str) -> dict:
    """``sensor_msgs/BatteryState`` of a battery sample: ``percentage`` the energy ÷ the maximum (NaN
    without a positive maximum); what Webots does not model (voltage, current, charge and capacities in
    Ah, temperature, cells) NaN or empty, health and technology unknown (0); ``energy`` the J themselves
    (Webots' sensor value: a battery without a maximum has one too)."""
    nan = math.nan
    return {"header": hdr, "voltage": nan, "temperature": nan, "current": nan, "charge": nan, "capacity": nan,
            "design_capacity": nan, "percentage": energy / maximum if maximum > 0.0 else nan,
            "power_supply_status": _SUPPLY_STATUS[state], "power_supply_health": 0, "power_supply_technology": 0,
            "present": True, "cell_voltage": b"", "cell_temperature": b"", "location": "", "serial_number": "",
            "energy": energy}


def laser_scan_angles(cfg: Any) -> tuple[float, float, float] | None:
    """(angle_min, angle_max, angle_increment) of ranges in range-image order (left to right), or
    ``None`` when the lidar gets no LaserScan (several layers, or planar: unequal angles)."""
    if cfg.number_of_layers != 1 or cfg.projection != "cylindrical":
        return None
    w = cfg.horizontal_resolution
    if cfg.type == "rotating":
        first, inc = math.pi, -2.0 * math.pi / w            # θ_j = π - j·2π/W
    else:
        fov = cfg.field_of_view
        first, inc = fov / 2 - fov / (2 * w), -fov / w      # θ_j = Φ/2 - (j+½)·Φ/W
    return first, first + (w - 1) * inc, inc


def _device_topics(robot: str, name: str, kind: str, cfg: Any, world_info: Any) -> list[Topic]:
    """The device's topics: its kind's declaration (schemas/devices.py)."""
    base = f"/{robot}/{name}/"
    path = f"{robot}/{name}"
    return [Topic(base + t.item, t.message, t.item, path, topic_frame(base + t.item))
            for t in KINDS[kind].topics if t.exists is None or t.exists(cfg, world_info)]


# ---------------------------------------------------------------------- the topic table

class Topics:
    """All topics of a world, what is demanded, and the controller-vs-subscriber device control."""

    def __init__(self, sim: Any):
        self.sim = sim
        self.basic_time_step = int(sim.basic_time_step)
        self.controls: dict[str, Control] = {}
        self.topics: list[Topic] = [Topic(CLOCK, msgs.CLOCK, "clock", None, topic_frame(CLOCK))]
        self.pose_topics: dict[str, Topic] = {}      # robot -> its /<robot>/pose topic
        self.joint_topics: dict[str, Topic] = {}     # robot with joints -> its /<robot>/joint_states topic
        self.window_topics: dict[str, Topic] = {}    # robot -> its /<robot>/robot_window topic
        self.window_in_topics: dict[str, Topic] = {}  # robot -> its /<robot>/robot_window/to_controller topic
        self.battery_topics: dict[str, Topic] = {}   # robot with a battery -> its /<robot>/battery topic
        world_info = getattr(getattr(sim, "world", None), "world_info", None)
        for robot_name, robot in sim.robots.items():
            for dev_name, dev in robot.devices.items():
                kind = dev.config.device
                ts = _device_topics(robot_name, dev_name, kind, dev.config, world_info)
                self.topics.extend(ts)
                self.controls[f"{robot_name}/{dev_name}"] = Control(robot_name, dev, kind, ts,
                                                                    f"{robot_name}/{dev_name}", seen=dev.measurements)
            name = f"/{robot_name}/pose"
            pose_topic = Topic(name, msgs.POSE_STAMPED, "pose", robot_name, topic_frame(name))
            self.topics.append(pose_topic)
            self.pose_topics[robot_name] = pose_topic
            joints = getattr(robot, "joints", None)
            if joints:                                # a robot with joints: their states (robot_state_publisher's input)
                name = f"/{robot_name}/joint_states"
                joint_topic = Topic(name, msgs.JOINT_STATE, "joint_states", robot_name, topic_frame(name))
                self.topics.append(joint_topic)
                self.joint_topics[robot_name] = joint_topic
            name = f"/{robot_name}/robot_window"
            window_topic = Topic(name, msgs.STRING, "robot_window", robot_name, topic_frame(name))
            self.topics.append(window_topic)
            self.window_topics[robot_name] = window_topic
            name = f"/{robot_name}/robot_window/to_controller"
            window_in = Topic(name, msgs.STRING, "robot_window_to_controller", robot_name, topic_frame(name))
            self.topics.append(window_in)
            self.window_in_topics[robot_name] = window_in
            battery = getattr(robot, "battery", None)
            if battery is not None and battery.present:     # a robot without a battery has no battery topic
                name = f"/{robot_name}/battery"
                battery_topic = Topic(name, msgs.BATTERY_STATE, "battery", robot_name, topic_frame(name))
                self.topics.append(battery_topic)
                self.battery_topics[robot_name] = battery_topic
        self.by_name = {t.name: t for t in self.topics}
        self.seq: dict[str, int] = {t.name: 0 for t in self.topics}
        self.prefixes: dict[bytes, int] = {}       # accepted subscription prefix -> subscriptions
        self.subscribed: set[str] = set()
        self.recorded: set[str] = set()
        self._recorder: Recorder | None = None
        self._rec_wants: Callable[[str], bool] | None = None
        self._rec_demands: Callable[[str], bool] | None = None
        self.recorder_demanded: set[str] = set()
        self._viewer: Recorder | None = None
        self.viewer_demanded: set[str] = set()
        self._active: list[Control] = []             # controls with a demanded topic
        self._clock_demanded = False
        self._poses: list[Topic] = []                # demanded pose topics
        self._joint_states: list[Topic] = []         # demanded joint_states topics
        self._batteries: dict[str, int] = {}         # robot of a demanded battery topic -> its samples last published
        self.work: Counter[str] = Counter()          # what publishing computed (poses_built)
        self.outbox: list[list[bytes]] = []          # published between steps (robot-window texts), to send

    # ------------------------------------------------------------------ demand
    @property
    def demanded(self) -> set[str]:
        """Topics computed and published: subscribed, demanded by the recorder or by a viewer."""
        return self.subscribed | self.recorder_demanded | self.viewer_demanded

    def subscription(self, event: bytes) -> bool:
        """An XPUB event (``\\x01`` + prefix subscribes, ``\\x00`` + prefix unsubscribes).
        Returns whether the demanded set changed."""
        if not event or event[0] not in (0, 1):
            return False
        prefix = bytes(event[1:])
        if event[0] == 1:
            if not self.accepts(prefix):
                return False
            self.prefixes[prefix] = self.prefixes.get(prefix, 0) + 1
        else:
            n = self.prefixes.get(prefix, 0) - 1
            if n < 0:
                return False
            if n:
                self.prefixes[prefix] = n
            else:
                del self.prefixes[prefix]
        return self._recompute()

    def accepts(self, prefix: bytes) -> bool:
        """Whether a subscription prefix matches at least one topic (the only ones kept: a prefix
        that can never match costs memory and nothing else, PROTOCOL.md)."""
        return len(prefix) <= MAX_PREFIX and any(t.frame.startswith(prefix) for t in self.topics)

    def set_recorder(self, recorder: Recorder | Any | None, topics: Iterable[str] | None = None) -> None:
        """Attach (``None``: detach) the recorder: a callable ``(topic, type, envelope, body,
        stamp_ns, seq)`` or an object with such a ``record`` method. It receives exactly the
        published bytes of every topic it records.

        Which topics it records: the object's ``wants(topic)`` if it has one, else ``topics``
        (names or prefixes, matched like subscriptions: ``name + "\\0"`` starts with it; ``None`` =
        all). Which of them count as demanded (computed even without a subscriber): the object's
        ``demands(topic)`` if it has one, else every recorded topic."""
        if recorder is None:
            self._recorder = None
            self._rec_wants = self._rec_demands = None
        else:
            self._recorder = getattr(recorder, "record", recorder)
            if not callable(self._recorder):
                raise TypeError("recorder must be callable or have a record() method")
            prefixes = (b"",) if topics is None else tuple(t.encode("utf-8") for t in topics)
            wants = getattr(recorder, "wants", None) or (lambda name: (name.encode("utf-8") + b"\0").startswith(prefixes))
            self._rec_wants = wants
            self._rec_demands = getattr(recorder, "demands", None) or wants
        self._recompute(force=True)

    def set_viewer(self, sink: Recorder | None) -> None:
        """Attach (``None``: detach, dropping its demand) the viewer sink: called like a recorder,
        with the published bytes of every topic in :attr:`viewer_demanded`."""
        self._viewer = sink
        if sink is None:
            self.set_viewer_demand(())

    def set_viewer_demand(self, names: Iterable[str]) -> bool:
        """The topics viewers subscribe to now (unknown names ignored). Returns whether it changed."""
        demanded = {n for n in names if n in self.by_name}
        if demanded == self.viewer_demanded:
            return False
        self.viewer_demanded = demanded
        self._recompute(force=True)
        return True

    def _recompute(self, force: bool = False) -> bool:
        subscribed = {t.name for t in self.topics if any(t.frame.startswith(p) for p in self.prefixes)}
        if not force and subscribed == self.subscribed:
            return False
        self.subscribed = subscribed
        if force:
            rw, rd = self._rec_wants, self._rec_demands
            self.recorded = {t.name for t in self.topics if rw(t.name)} if rw else set()
            self.recorder_demanded = {t.name for t in self.topics if rd(t.name)} if rd else set()
        demanded = self.demanded
        self._clock_demanded = CLOCK in demanded
        self._poses = [t for t in self.pose_topics.values() if t.name in demanded]
        self._joint_states = [t for t in self.joint_topics.values() if t.name in demanded]
        for robot, t in self.battery_topics.items():
            wanted = t.name in demanded
            if wanted != (robot in self._batteries):
                state = self.sim.robots[robot]
                self.sim.demand_battery(state, wanted)
                if wanted:                             # new samples only, never a stale one
                    self._batteries[robot] = state.battery_samples
                else:
                    del self._batteries[robot]
        self._active = []
        for ctl in self.controls.values():
            was = bool(ctl.demanded)
            ctl.demanded = {t.kind for t in ctl.topics if t.name in demanded}
            if ctl.demanded:
                if not was:
                    ctl.seen = ctl.device.measurements     # publish new values only, never a stale one
                self._active.append(ctl)
            self._apply(ctl)
        return True

    # ------------------------------------------------------------------ controller requests
    def control(self, path: str) -> Control:
        return self.controls[path]

    def controller_enable(self, path: str, period_ms: int) -> None:
        """The attached controller's ``enable(period)`` (0 disables): applied exactly as asked; if
        it disables a demanded device, the device keeps running at the basic step for the topics."""
        ctl = self.controls[path]
        ctl.controller_period = int(period_ms)
        if period_ms > 0:
            ctl.device.enable(int(period_ms))
        else:
            self._apply(ctl, controller_disabled=True)

    def controller_point_cloud(self, path: str, on: bool) -> None:
        ctl = self.controls[path]
        ctl.controller_point_cloud = bool(on)
        self._apply(ctl)

    def release_robot(self, robot: str) -> None:
        """The robot's controller left (detached or dropped): forget its requests."""
        for ctl in self.controls.values():
            released = getattr(ctl.device, "controller_released", None)   # a camera's recognition
            if ctl.robot == robot and released is not None:
                released()
            if ctl.robot == robot and (ctl.controller_period or ctl.controller_point_cloud):
                had = ctl.controller_period
                ctl.controller_period = 0
                ctl.controller_point_cloud = False
                self._apply(ctl, controller_disabled=bool(had))

    def _apply(self, ctl: Control, controller_disabled: bool = False) -> None:
        dev = ctl.device
        if ctl.controller_period == 0:
            if ctl.demanded:
                if controller_disabled or dev.sampling_period != self.basic_time_step:
                    dev.enable(self.basic_time_step)
            elif dev.sampling_period != 0:
                dev.disable()
        if "point_cloud" in ctl.topic_types:
            want = ctl.controller_point_cloud or "point_cloud" in ctl.demanded
            if want != dev.point_cloud_enabled:
                if want:
                    dev.enable_point_cloud()
                else:
                    dev.disable_point_cloud()

    # ------------------------------------------------------------------ publishing
    def publish(self, time_ms: int) -> list[list[bytes]]:
        """After a basic step: the frames of every demanded topic with a new value, ``/clock``
        first, then the demanded joint states (every basic step while demanded), then the demanded
        robot poses, then the batteries sampled, then the devices' topics. The recorder gets the same
        bytes."""
        out: list[list[bytes]] = []
        if self._clock_demanded:
            self._emit(self.by_name[CLOCK], time_ms, {"clock": stamp(time_ms * 1_000_000)}, out)
        for t in self._joint_states:
            assert t.path is not None
            self._emit(t, time_ms, joint_states_msg(header(t.path, time_ms), self.sim.robots[t.path].joints), out)
        if self._poses:
            hdr = header(WORLD_FRAME, time_ms)
            for t in self._poses:
                self._emit(t, time_ms, pose_msg(hdr, self.sim.robots[t.path].pose), out)
            self.work["poses_built"] += len(self._poses)
        for robot, seen in self._batteries.items():
            state = self.sim.robots[robot]
            if state.battery_samples != seen:
                self._batteries[robot] = state.battery_samples
                at = state.battery_sampled_at_ms
                self._emit(self.battery_topics[robot], at, battery_state_msg(header(robot, at), *state.battery_sample), out)
        for ctl in self._active:
            m = ctl.device.measurements
            if m == ctl.seen:
                continue
            ctl.seen = m
            at = ctl.device.measured_at_ms
            for t in ctl.topics:
                if t.kind in ctl.demanded:
                    body = self.build(ctl, t.kind, at)
                    if body is not None:
                        self._emit(t, at, body, out)
        return out

    def robot_window(self, robot: str, text: str, time_ms: int, to_controller: bool = False) -> None:
        """A text the robot's controller sent its robot window (``to_controller``: one sent to the
        controller from the window side): published now (subscribers get it from :attr:`outbox`; the
        recorder and the viewer at once), stamped with the time it was sent or queued."""
        topic = (self.window_in_topics if to_controller else self.window_topics)[robot]
        self._emit(topic, time_ms, {"data": text}, self.outbox)

    def _emit(self, t: Topic, ms: int, body: dict, out: list[list[bytes]]) -> None:
        seq = self.seq[t.name]
        self.seq[t.name] = seq + 1
        ns = max(ms, 0) * 1_000_000
        env = pack({"type": t.type, "seq": seq, "stamp_ns": ns})
        data = pack(body)
        if t.name in self.subscribed:
            out.append([t.frame, env, data])
        if self._recorder is not None and t.name in self.recorded:
            self._recorder(t.name, t.type, env, data, ns, seq)
        if self._viewer is not None and t.name in self.viewer_demanded:
            self._viewer(t.name, t.type, env, data, ns, seq)

    def build(self, ctl: Control, kind: str, at_ms: int) -> dict | None:
        """The body of ``ctl``'s topic ``kind`` (its item) from the device's current state: built
        by the builder of the topic's message type (one per type in :data:`MESSAGE_BUILDERS`)."""
        t = ctl.topic_types.get(kind)
        if t is None:
            return None
        frame = getattr(ctl.device, "topic_frames", {}).get(kind, ctl.frame_id)   # a pen's stroke: "world"
        return MESSAGE_BUILDERS[t](self, ctl, header(frame, at_ms), ctl.topic_readings[kind])

    def _illuminance(self, ctl: Control, hdr: dict, reading: str) -> dict:
        return {"header": hdr, "illuminance": float(ctl.device.value), "variance": 0.0}

    def _joint_state(self, ctl: Control, hdr: dict, reading: str) -> dict:
        dev = ctl.device
        return {"header": hdr, "name": [dev.name], "position": np.array([dev.value], dtype="<f8").tobytes(),
                "velocity": b"", "effort": b""}

    def _color(self, ctl: Control, hdr: dict, reading: str) -> dict:
        dev = ctl.device
        if reading != "value":       # a colour kept as (r, g, b, a): a pen's ink and its density
            r, g, b, a = (float(v) for v in getattr(dev, reading))
            return {"r": r, "g": g, "b": b, "a": a}
        r, g, b = dev.rgb()
        return {"r": r, "g": g, "b": b, "a": 1.0 if dev.value else 0.0}

    def _range(self, ctl: Control, hdr: dict, reading: str) -> dict:
        dev = ctl.device
        code = int(dev.type_code)
        return {"header": hdr,
                "radiation_type": 1 if code == _INFRA_RED else 0,
                "field_of_view": float(dev.config.aperture),
                "min_range": float(dev.table.min_value),
                "max_range": float(dev.table.max_value),
                "range": float(dev.value),
                "variance": 0.0}

    def _range_image(self, ctl: Control, hdr: dict, reading: str) -> dict | None:
        if reading != "range_image":         # a camera's own images (bgra8), sim/cameras.py
            data = ctl.device.image_data(reading)
            if data is None:
                return None
            height, width, encoding, raw = data
            return image_msg(hdr, height, width, raw, encoding)
        rows, cols = ctl.device.range_image.shape      # a lidar's layers × columns, a range finder's pixels
        return image_msg(hdr, rows, cols, ctl.range_bytes())

    def _camera_info(self, ctl: Control, hdr: dict, reading: str) -> dict:
        return {"header": hdr, **ctl.device.camera_info()}

    def _laser_scan(self, ctl: Control, hdr: dict, reading: str) -> dict | None:
        dev = ctl.device
        cfg = dev.config
        angles = laser_scan_angles(cfg)
        if angles is None:
            return None
        if cfg.type == "rotating":
            scan = 1.0 / float(dev.frequency)
            t_inc = scan / cfg.horizontal_resolution
        else:
            p = dev.sampling_period
            scan = math.ceil(p / self.basic_time_step) * self.basic_time_step / 1000.0
            t_inc = 0.0          # every ray of a fixed lidar is cast at the same instant
        return {"header": hdr, "angle_min": angles[0], "angle_max": angles[1], "angle_increment": angles[2],
                "time_increment": t_inc, "scan_time": scan,
                "range_min": float(cfg.min_range), "range_max": float(cfg.max_range),
                "ranges": ctl.range_bytes()[: 4 * cfg.horizontal_resolution], "intensities": b""}

    def _point_cloud(self, ctl: Control, hdr: dict, reading: str) -> dict | None:
        if not ctl.device.point_cloud_enabled:
            return None
        return lidar_cloud_msg(hdr, ctl.device)

    def _point_stamped(self, ctl: Control, hdr: dict, reading: str) -> dict:
        x, y, z = (float(v) for v in getattr(ctl.device, reading))
        return {"header": hdr, "point": {"x": x, "y": y, "z": z}}

    def _vector3_stamped(self, ctl: Control, hdr: dict, reading: str) -> dict:
        x, y, z = (float(v) for v in getattr(ctl.device, reading))
        return {"header": hdr, "vector": {"x": x, "y": y, "z": z}}

    def _float64(self, ctl: Control, hdr: dict, reading: str) -> dict:
        return {"data": float(getattr(ctl.device, reading))}

    def _nav_sat_fix(self, ctl: Control, hdr: dict, reading: str) -> dict:
        lat, lon, alt = (float(v) for v in getattr(ctl.device, reading))
        sigma = float(getattr(ctl.device.config, "accuracy", 0.0))
        cov = np.zeros(9)
        cov[[0, 4, 8]] = sigma * sigma
        return {"header": hdr, "status": {"status": 0, "service": 1}, "latitude": lat, "longitude": lon,
                "altitude": alt, "position_covariance": cov.astype("<f8").tobytes(),
                "position_covariance_type": 2 if sigma > 0 else 0}

    def _imu(self, ctl: Control, hdr: dict, reading: str) -> dict:
        x, y, z, w = (float(v) for v in getattr(ctl.device, reading))
        sigma = float(ctl.device.config.noise) * math.pi
        unknown = np.zeros(9)
        unknown[0] = -1.0                                     # REP 145: not provided
        return {"header": hdr, "orientation": {"x": x, "y": y, "z": z, "w": w},
                "orientation_covariance": (np.eye(3) * sigma * sigma).astype("<f8").tobytes(),
                "angular_velocity": {"x": 0.0, "y": 0.0, "z": 0.0},
                "angular_velocity_covariance": unknown.astype("<f8").tobytes(),
                "linear_acceleration": {"x": 0.0, "y": 0.0, "z": 0.0},
                "linear_acceleration_covariance": unknown.astype("<f8").tobytes()}

    def _magnetic_field(self, ctl: Control, hdr: dict, reading: str) -> dict:
        x, y, z = (float(v) for v in getattr(ctl.device, reading))
        return {"header": hdr, "magnetic_field": {"x": x, "y": y, "z": z},
                "magnetic_field_covariance": bytes(72)}

    def _radar_scan(self, ctl: Control, hdr: dict, reading: str) -> dict:
        return {"header": hdr, "returns": [
            {"range": t.distance, "azimuth": -t.azimuth, "elevation": 0.0, "doppler_velocity": t.speed,
             "amplitude": t.received_power} for t in getattr(ctl.device, reading)]}

    # ------------------------------------------------------------------ step-reply readings
    def reading(self, ctl: Control) -> dict:
        """The device's latest reading for a step reply (PROTOCOL §3.6)."""
        if "range_image" not in ctl.topic_types:
            return ctl.device.step_reading()
        out = {"range_image": ctl.range_bytes()}          # a lidar's bytes, shared with its topics
        if ctl.controller_point_cloud:
            out["point_cloud"] = ctl.cloud_bytes()
        return out


MESSAGE_BUILDERS: dict[str, Callable[[Topics, Control, dict, str], dict | None]] = {
    msgs.ILLUMINANCE: Topics._illuminance,
    msgs.RANGE: Topics._range,
    msgs.JOINT_STATE: Topics._joint_state,
    msgs.COLOR_RGBA: Topics._color,
    msgs.IMAGE: Topics._range_image,
    msgs.LASER_SCAN: Topics._laser_scan,
    msgs.POINT_CLOUD: Topics._point_cloud,
    msgs.POINT_STAMPED: Topics._point_stamped,
    msgs.VECTOR3_STAMPED: Topics._vector3_stamped,
    msgs.FLOAT64: Topics._float64,
    msgs.NAV_SAT_FIX: Topics._nav_sat_fix,
    msgs.IMU: Topics._imu,
    msgs.MAGNETIC_FIELD: Topics._magnetic_field,
    msgs.CAMERA_INFO: Topics._camera_info,
    msgs.RADAR_SCAN: Topics._radar_scan,
}
"""Message type -> the builder of a device topic's body (a device kind's topics name their types)."""
