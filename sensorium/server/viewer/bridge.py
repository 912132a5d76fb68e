"""A Foxglove WebSocket server fed by the daemon's topics (or a replay), built on ``foxglove-sdk``.

Channels (all advertised at start):

* every Sensorium topic under its own name, ``cdr`` encoded with its ROS 2 ``ros2msg`` schema —
  the bytes of :class:`sensorium.server.recording.export.CdrEncoder`, i.e. the same bytes as
  ``sensorium export``; a lidar's ``point_cloud`` is offered as ``sensor_msgs/msg/PointCloud2``
  (Foxglove's 3D panel does not draw the old ``PointCloud``);
* ``/tf`` — ``foxglove.FrameTransforms`` (protobuf): ``world → <robot>`` at the robot's pose and
  ``<robot> → <robot>/<device>`` mounts, one message per robot pose, and the mounts of devices
  riding joints, one message per ``/<robot>/joint_states`` (demanded while ``/tf`` is subscribed);
* ``/scene`` — ``foxglove.SceneUpdate`` (protobuf): the world (see :mod:`sensorium.server.recording.scene3d`), sent to each
  client when it subscribes (robot bodies follow ``/tf``).

Demand: a client subscribing to a topic's channel makes that topic demanded exactly like a ZeroMQ
subscriber (``Topics.set_viewer_demand``); ``/tf`` demands every ``/<robot>/pose``; the last
unsubscription (or a disconnect) stops the work. The SDK calls the listener from its own thread;
the events are applied by the step-loop thread in :meth:`FoxgloveBridge.pump` (a transport hook).

Listening: the SDK's server listens on an ephemeral 127.0.0.1 port behind
:class:`~sensorium.server.viewer.front.SubprotocolFront`, which owns the viewer-facing address and
accepts both subprotocol names clients offer (``foxglove.sdk.v1`` and ``foxglove.websocket.v1``).

Telling a viewer why it sees nothing: while the world waits for a controller (no synchronous
controller attached), every viewer gets a Foxglove status message (warning) naming the robots and
how to start a controller (or ``serve --watch``); it is removed once the world steps. The SDK's
own log lines (a viewer that vanished makes it log one per message it could not send) are kept
to one line per viewer connection plus a count (:class:`_SdkLog`).

Never slowing the step loop: :meth:`record` (called by ``Topics`` in the step thread) only appends
the msgpack bytes to a bounded queue (the oldest is dropped when full, ``dropped`` counts it); a
worker thread encodes CDR/protobuf and hands the bytes to the SDK, whose per-client backlog drops
the oldest messages of a slow client. Simulated time is broadcast as the server time (at most every
TIME_EVERY_S: those go through the lossless control queue). When a
supervisor moves, removes or imports a solid or a light, or changes a shape's appearance (a colour,
a transparency, a texture given or taken: ``Scene.appearance_version``), or a reset brings the
loaded appearances back, the scene is sent again to every ``/scene`` subscriber.
"""

from __future__ import annotations

import logging
import math
import re
import sys
import threading
import time
from collections import Counter, deque
from collections.abc import Callable, Iterable
from collections.abc import Set as AbstractSet
from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import msgpack

from sensorium.schemas import world as wm
from sensorium.server.recording.export import CdrEncoder, ExportError
from sensorium.server.recording.ros_views import joint_positions, joint_states_robot, pose_robot

if TYPE_CHECKING:
    from sensorium.server.recording.frames import Appearances

__all__ = ["FoxgloveBridge", "ViewerError", "parse_address", "exposure_warning", "TF_TOPIC", "SCENE_TOPIC", "POSE_TYPE"]

TF_TOPIC = "/tf"
SCENE_TOPIC = "/scene"
POSE_TYPE = "geometry_msgs/msg/PoseStamped"
DEFAULT_PORT = 8765


class ViewerError(Exception):
    """A bad ``--foxglove`` address, a missing SDK or a port that cannot be bound."""


def parse_address(text: str) -> tuple[str, int]:
    """``PORT``, ``HOST:PORT`` or ``[v6]:PORT`` → (host, port); host defaults to 127.0.0.1."""
    text = text.strip()
    host, port_s = "127.0.0.1", text
    if text.startswith("["):
        end = text.find("]")
        if end < 0 or not text[end + 1:].startswith(":"):
            raise ViewerError(f"--foxglove {text!r}: expected [HOST]:PORT")
        host, port_s = text[1:end], text[end + 2:]
    elif ":" in text:
        host, port_s = text.rsplit(":", 1)
    try:
        port = int(port_s)
    except ValueError:
        raise ViewerError(f"--foxglove {text!r}: port {port_s!r} is not a number") from None
    if not 0 <= port <= 65535:
        raise ViewerError(f"--foxglove {text!r}: port must be within 0..65535 (0 picks a free port)")
    if not host:
        raise ViewerError(f"--foxglove {text!r}: empty host")
    return host, port


def exposure_warning(host: str) -> str | None:
    """A warning when ``host`` is not a loopback address (the server has no authentication)."""
    import ipaddress

    if host == "localhost":
        return None
    try:
        if ipaddress.ip_address(host).is_loopback:
            return None
    except ValueError:
        pass                                   # a host name: it may resolve to anything
    return (f"the Foxglove server on {host} is reachable from other machines and has no authentication "
            "(an SSH tunnel to 127.0.0.1 is the safe way: see README, See it in Foxglove)")


WAITING_STATUS_ID = "sensorium-waiting"
STATUS_REPEAT_S = 2.0          # a waiting status is sent again this often (viewers that connected since)
STATUS_CHECK_S = 0.25          # the step loop looks at what the world waits for at most this often
# the simulated time is broadcast at most this often: Time messages go through each viewer's lossless
# control queue (as long as its backlog), whose overflow disconnects the viewer, so one sent each step
# (hundreds a second in fast mode) dropped a viewer that stopped reading for a second or two
TIME_EVERY_S = 0.05


QUEUE_BUDGET_BYTES = 32 << 20     # the bridge's own queue (msgpack bodies waiting for the worker)
VIEWER_BUDGET_BYTES = 8 << 20     # each viewer's queue in the SDK (its backlog, counted in messages)
TRIM_EVERY_S = 1.0            # after viewers left, freed memory is returned at most this often


def _fit(budget: int, largest: int, low: int, high: int) -> int:
    """How many messages of ``largest`` bytes fit ``budget`` (within [low, high])."""
    return high if largest <= 0 else max(low, min(high, budget // largest))


def largest_message(world: wm.World | None) -> int:
    """An upper estimate of the largest message a world publishes: a lidar's PointCloud2 (16 bytes
    per point, x y z layer) or range image (4 per pixel)."""
    best = 0
    for robot in (world.robots if world is not None else []):
        for dev in robot.devices:
            cols, layers = getattr(dev, "horizontal_resolution", None), getattr(dev, "number_of_layers", None)
            if isinstance(cols, int) and isinstance(layers, int):
                best = max(best, 16 * cols * layers + 512)
    return best


def _malloc_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim`` (None elsewhere)."""
    try:
        import ctypes

        return cast(Callable[[int], int], ctypes.CDLL("libc.so.6").malloc_trim)
    except (OSError, AttributeError):
        return None


class _SdkLog(logging.Handler):
    """foxglove-sdk's log records (Python logger ``foxglove``): at most one line per viewer address
    (``client HOST:PORT`` in the message), other lines identical to an earlier one at the 1st, 10th,
    100th … time. A viewer that vanished made the SDK log one line per message it could not send
    (~48,000 lines for 200 viewers); now it is one. ``suppressed`` counts the rest."""

    ADDRESS = re.compile(r"client (\[?[0-9A-Fa-f:.]+\]?:\d+)")
    MAX_KEYS = 4096

    def __init__(self, stream: Any = None):
        super().__init__(logging.WARNING)
        self.stream = stream
        self.suppressed = 0
        self._seen: dict[str, int] = {}

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = record.getMessage()
        except Exception:  # noqa: BLE001
            return
        text = " ".join(text.split())               # the SDK's messages may span lines: one line each
        m = self.ADDRESS.search(text)
        key = m.group(1) if m else text
        n = self._seen.get(key, 0) + 1
        if len(self._seen) >= self.MAX_KEYS and key not in self._seen:
            self._seen.clear()                       # bounded: old viewers are forgotten
        self._seen[key] = n
        if (m and n > 1) or (not m and n not in (1, 10, 100, 1000, 10000, 100000)):
            self.suppressed += 1
            return
        extra = f" (seen {n} times)" if n > 1 else ""
        stream = self.stream or sys.stderr
        try:
            print(f"sensorium: Foxglove: {text}{extra}", file=stream, flush=True)
        except (OSError, ValueError):
            pass


_SDK_LOG: _SdkLog | None = None


def sdk_log() -> _SdkLog:
    """The one handler on the ``foxglove`` logger (installed once per process; not propagated)."""
    global _SDK_LOG
    if _SDK_LOG is None:
        _SDK_LOG = _SdkLog()
        logger = logging.getLogger("foxglove")
        logger.addHandler(_SDK_LOG)
        logger.propagate = False
    return _SDK_LOG


def waiting_message(core: Any) -> str | None:
    """What a viewer of ``core``'s world should be told while the world waits for a controller."""
    ls = core.lockstep
    if ls.synchronous_attached:
        return None
    robots = ls.waiting_for()
    if not robots:
        return None
    names = " or ".join(repr(r) for r in robots)
    return (f"The world is not stepping: it waits for a controller to attach to robot {names} (controller "
            f"\"<extern>\"). Start one, e.g. `sensorium controller my_controller.py --robot {robots[0]}` "
            f"(bundled: example:light_follower, example:wanderer, example:braitenberg), or restart with "
            f"`sensorium serve WORLD --watch --foxglove PORT` to run these robots as \"<none>\" and watch "
            f"their sensors without controllers.")


class _Listener:
    """The SDK's ``ServerListener``: counts subscriptions per topic (SDK thread)."""

    def __init__(self, bridge: FoxgloveBridge):
        self._bridge = bridge

    def on_subscribe(self, client: Any, channel: Any) -> None:
        self._bridge._subscribed(int(client.id), str(channel.topic), +1)

    def on_unsubscribe(self, client: Any, channel: Any) -> None:
        self._bridge._subscribed(int(client.id), str(channel.topic), -1)


class FoxgloveBridge:
    """One Foxglove WebSocket server. ``topic_types``: topic → ROS type of its msgpack body;
    ``world``/``base_dir``: for ``/scene`` and the mounts in ``/tf`` (``None``: no scene);
    ``on_demand(topics)``: called by :meth:`pump` with the topics viewers demand now;
    ``wake()``: called from the SDK's thread when :meth:`pump` has something to apply;
    ``appearances``: the simulation's scene, whose shapes are drawn as a Supervisor last set their
    appearance (``None``: as loaded)."""

    def __init__(self, topic_types: dict[str, str], world: wm.World | None = None, base_dir: str | Path = ".", *,
                 host: str = "127.0.0.1", port: int = DEFAULT_PORT, name: str = "sensorium",
                 on_demand: Callable[[set[str]], None] | None = None, wake: Callable[[], None] | None = None,
                 solid_poses: Callable[[], dict[str, Any]] | None = None,
                 removed_lights: Callable[[], AbstractSet[int]] | None = None, queue_size: int | None = None,
                 backlog: int | None = None, distro: str = "jazzy", status: Callable[[], str | None] | None = None,
                 largest_message: int = 0, appearances: Appearances | None = None):
        try:
            import foxglove
            from foxglove.messages import FrameTransforms, SceneUpdate
            from foxglove.websocket import Capability, StatusLevel
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise ViewerError("the Foxglove viewer needs the 'foxglove' extra: pip install 'sensorium[foxglove]'") from exc
        from sensorium.server.recording import scene3d as fxscene
        from sensorium.server.recording.frames import JointFrames, mounts

        self._unpacked = ExitStack()        # a replay's unpacked world files (for_replay), removed at close
        self._scene_mod = fxscene
        self.encoder = CdrEncoder(distro, pointcloud2=True)
        self.world = world
        self.base_dir = Path(base_dir)
        self.on_demand = on_demand
        self.wake = wake or (lambda: None)
        self.solid_poses = solid_poses
        self.removed_lights = removed_lights          # the world's top-level lights a Supervisor removed
        # the shapes a Supervisor recoloured: (the scene's appearance_version, its drawn_models()), taken
        # by the step thread (pump) when the version moves, read whole by the worker (scene_bytes)
        self.appearances = appearances
        self._drawn: tuple[int, dict[int, Any]] = (
            (appearances.appearance_version, appearances.drawn_models()) if appearances is not None else (0, {}))
        self.ctx = foxglove.Context()
        self.types: dict[str, str] = {}            # topic -> channel schema name
        self.unsupported: dict[str, str] = {}      # topic -> its type the distro lacks
        self.channels: dict[str, Any] = {}
        for topic, ros_type in topic_types.items():
            typename = self.encoder.export_type(ros_type)
            if typename is None:
                self.unsupported[topic] = ros_type
                continue
            schema = foxglove.Schema(name=typename, encoding="ros2msg", data=self.encoder.msgdef(typename).encode())
            self.channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self.ctx)
            self.types[topic] = typename
        self.pose_robot = {t: r for t, ty in topic_types.items() if (r := pose_robot(t, ty)) is not None}
        self.mounts = mounts(world) if world is not None else {}
        # robots whose joints carry devices: /tf moves those frames from /<robot>/joint_states
        self.joint_frames = JointFrames(world) if world is not None else None
        self.joint_robot = {t: r for t, ty in topic_types.items() if (r := joint_states_robot(t, ty)) is not None
                            and self.joint_frames is not None and r in self.joint_frames.robots}
        self.tf_channel = None
        if self.pose_robot:
            self.tf_channel = foxglove.Channel(TF_TOPIC, schema=FrameTransforms.get_schema(), message_encoding="protobuf",
                                               context=self.ctx)
        self.scene_channel = None
        if world is not None:
            self.scene_channel = foxglove.Channel(SCENE_TOPIC, schema=SceneUpdate.get_schema(),
                                                  message_encoding="protobuf", context=self.ctx)
        # subscription state (SDK thread writes, step thread reads; guarded by _lock)
        self._lock = threading.Lock()
        self._subs: Counter[str] = Counter()
        self._clients: Counter[tuple[int, str]] = Counter()
        self._dirty = False
        self._scene_for: deque[int | None] = deque()     # client ids to send the scene to (None: all)
        self._scene_bytes: bytes | None = None
        self._scene_key: Any = None
        self._seen_poses: list[Any] = []
        self._seen_removed_lights = (0, len(world.lights) if world is not None else 0)
        # data path
        self._queue: deque[tuple[str, str, bytes, int]] = deque()
        # bounded in bytes, not only in messages: a 16-layer lidar's cloud is ~260 KB, and 256 of
        # them queued for each of 20 viewers held 1.2 GB
        self.queue_size = max(1, int(queue_size)) if queue_size else _fit(QUEUE_BUDGET_BYTES, largest_message, 16, 512)
        backlog = backlog or _fit(VIEWER_BUDGET_BYTES, largest_message, 8, 256)
        self.backlog = backlog
        self.dropped = 0
        self.sent = 0
        self.errors: dict[str, str] = {}
        self._time_ns = 0
        self._sent_time_ns = -1
        self._time_sent_at = -math.inf       # (monotonic) when the last Time message went out
        self._event = threading.Event()
        self._stop = False
        # what viewers are told (status): computed by the step thread, sent by the worker
        self.status_fn = status
        self._status_level = StatusLevel.Warning
        self._status: str | None = None
        self._status_sent: str | None = None
        self._status_sent_at = 0.0
        self._status_checked_at = 0.0
        self.sdk_log = sdk_log()
        self._trim_due = False
        self._trimmed_at = 0.0
        from sensorium.server.viewer.front import SubprotocolFront

        try:
            self.server = foxglove.start_server(name=name, host="127.0.0.1", port=0, capabilities=[Capability.Time],
                                                server_listener=cast(Any, _Listener(self)), context=self.ctx,
                                                message_backlog_size=backlog)
        except Exception as exc:  # the SDK raises RuntimeError on a busy/bad address
            raise ViewerError(f"cannot start the Foxglove server: {exc}") from None
        try:
            self.front = SubprotocolFront(host, port, int(self.server.port), on_connect=self._connected,
                                          on_disconnect=self._disconnected)
        except OSError as exc:
            self.server.stop()
            raise ViewerError(f"cannot start the Foxglove server on {host}:{port}: {exc.strerror or exc}") from None
        self.host, self.port = host, self.front.port
        self._worker = threading.Thread(target=self._run, name="foxglove-bridge", daemon=True)
        self._worker.start()

    # ------------------------------------------------------------------ wiring
    @classmethod
    def for_core(cls, core: Any, transport: Any, host: str = "127.0.0.1", port: int = DEFAULT_PORT,
                 **kw: Any) -> FoxgloveBridge:
        """Serve ``core``'s topics: demand through ``core.topics``, pumped by ``transport``'s loop."""
        topics, sim = core.topics, core.sim
        loaded = getattr(sim, "loaded", None)
        bridge = cls({t.name: t.type for t in topics.topics}, sim.world, getattr(loaded, "base_dir", "."),
                     host=host, port=port, name=f"sensorium {core.world_name}",
                     on_demand=topics.set_viewer_demand, wake=transport.wake,
                     solid_poses=lambda: dict(sim.scene.solid_poses),
                     removed_lights=lambda: frozenset(sim.scene.removed_lights), status=lambda: waiting_message(core),
                     largest_message=largest_message(sim.world), appearances=sim.scene, **kw)
        topics.set_viewer(bridge.record)
        transport.hooks.append(lambda: bridge.pump(sim.time_ms * 1_000_000))
        return bridge

    @classmethod
    def for_replay(cls, replayer: Any, host: str = "127.0.0.1", port: int = DEFAULT_PORT, **kw: Any) -> FoxgloveBridge:
        """Serve a :class:`~sensorium.server.recording.replay.Replayer`'s messages (every replayed
        message is offered; demand does not apply to a replay). The scene comes from the world file
        (and meshes) attached to the recording, when it loads."""
        from sensorium.server.recording.ros_views import recorded_world

        unpacked = ExitStack()                    # the recorded world's files, removed when the bridge closes
        world, base = unpacked.enter_context(recorded_world(replayer.recording))
        try:
            bridge = cls(dict(replayer.topic_types), world, base, host=host, port=port,
                         name=f"sensorium replay {Path(replayer.path).name}", largest_message=largest_message(world),
                         **kw)
        except BaseException:
            unpacked.close()
            raise
        bridge._unpacked = unpacked
        replayer.viewer = bridge.record
        return bridge

    def app_url(self) -> str | None:
        """A Foxglove web-app link that opens this server as the data source (the SDK's), if any."""
        try:
            url = self.server.app_url()
        except Exception:  # noqa: BLE001 - only a convenience
            return None
        if not url:
            return None
        # the SDK names its own (internal) port; viewers connect to the front's
        from urllib.parse import quote

        inner = f"ws://127.0.0.1:{self.server.port}"
        return url.replace(quote(inner, safe=""), quote(self.url, safe="")).replace(inner, self.url)

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    # ------------------------------------------------------------------ SDK thread
    def _connected(self) -> None:
        """A viewer completed its handshake (front thread): send it the status soon."""
        self._status_sent_at = 0.0
        self._event.set()

    def _disconnected(self) -> None:
        """A viewer went away (front thread): give the memory of its queues back soon."""
        self._trim_due = True
        self._event.set()

    def _subscribed(self, client: int, topic: str, delta: int) -> None:
        """O(1) per event: counts change, and the step loop is woken only when it has nothing
        pending yet (10,000 subscribe/unsubscribe pairs cost one demand update per loop pass)."""
        with self._lock:
            key = (client, topic)
            if delta > 0:
                self._clients[key] += 1
                self._subs[topic] += 1
            elif self._clients[key] > 0:
                self._clients[key] -= 1
                self._subs[topic] -= 1
                if not self._clients[key]:
                    del self._clients[key]
                if not self._subs[topic]:
                    del self._subs[topic]
            else:
                return
            was_dirty, self._dirty = self._dirty, True
            if delta > 0 and topic == SCENE_TOPIC and client not in self._scene_for:
                self._scene_for.append(client)
        self._event.set()
        if not was_dirty:
            self.wake()

    def subscriptions(self) -> dict[str, int]:
        """Channel topic → number of client subscriptions now."""
        with self._lock:
            return dict(self._subs)

    def demanded(self) -> set[str]:
        """The Sensorium topics the current subscriptions demand."""
        with self._lock:
            subs = set(self._subs)
        out = {t for t in subs if t in self.channels}
        if TF_TOPIC in subs:
            out.update(self.pose_robot)
            out.update(self.joint_robot)
        return out

    # ------------------------------------------------------------------ step-loop thread
    def pump(self, time_ns: int | None = None) -> None:
        """Apply subscription changes (``on_demand``), note the simulated time, and resend the scene
        when a Supervisor moved, removed or imported something or changed an appearance (or a reset
        restored them). Cheap when idle: a version number and the solids' pose objects compared."""
        if time_ns is not None and time_ns != self._time_ns:
            self._time_ns = int(time_ns)
            self._event.set()
        if self.status_fn is not None:
            now = time.monotonic()
            if now - self._status_checked_at >= STATUS_CHECK_S:
                self._status_checked_at = now
                status = self.status_fn()
                if status != self._status:
                    self._status = status
                    self._event.set()
        resend = False
        appearances = self.appearances
        if appearances is not None and appearances.appearance_version != self._drawn[0]:
            self._drawn = (appearances.appearance_version, appearances.drawn_models())
            resend = True
        watching = self._subs.get(SCENE_TOPIC, 0) > 0
        if self.solid_poses is not None and watching:
            poses = list(self.solid_poses().values())
            # lights removed or imported (a Supervisor's) change the scene too
            removed = (len(self.removed_lights()) if self.removed_lights is not None else 0,
                       len(self.world.lights) if self.world is not None else 0)
            if len(poses) != len(self._seen_poses) or any(a is not b for a, b in zip(poses, self._seen_poses)) \
                    or removed != self._seen_removed_lights:
                resend = resend or bool(self._seen_poses)
                self._seen_poses = poses
                self._seen_removed_lights = removed
        if resend and watching:
            self._scene_for.append(None)
            self._event.set()
        if self._dirty:
            with self._lock:
                self._dirty = False
            if self.on_demand is not None:
                self.on_demand(self.demanded())

    def record(self, topic: str, ros_type: str, envelope: bytes, body: bytes, stamp_ns: int, seq: int) -> None:
        """A published message (``Topics``' recorder signature). Never blocks."""
        q = self._queue
        if len(q) >= self.queue_size:
            try:
                q.popleft()
                self.dropped += 1
            except IndexError:
                pass
        q.append((topic, ros_type, body, stamp_ns))
        if stamp_ns > self._time_ns:
            self._time_ns = stamp_ns
        self._event.set()

    # ------------------------------------------------------------------ worker thread
    def _run(self) -> None:
        while not self._stop:
            self._event.wait(0.05)
            self._event.clear()
            try:
                self._work()
            except Exception as exc:  # noqa: BLE001 - the viewer must never take the server down
                self.errors.setdefault("worker", f"{type(exc).__name__}: {exc}")

    def _send_status(self) -> None:
        status, now = self._status, time.monotonic()
        if status is not None and (status != self._status_sent or now - self._status_sent_at >= STATUS_REPEAT_S):
            self.server.publish_status(status, self._status_level, WAITING_STATUS_ID)
            self._status_sent, self._status_sent_at = status, now
        elif status is None and self._status_sent is not None:
            self.server.remove_status([WAITING_STATUS_ID])
            self._status_sent = None

    def _trim(self) -> None:
        """After viewers left: return the freed memory of their message queues to the system
        (glibc keeps it in per-thread arenas otherwise: RSS stayed at ~850 MB after 200 viewers)."""
        now = time.monotonic()
        if not self._trim_due or now - self._trimmed_at < TRIM_EVERY_S:
            return
        self._trim_due, self._trimmed_at = False, now
        trim = _malloc_trim()
        if trim is not None:
            trim(0)

    def _work(self) -> None:
        self._send_status()
        self._trim()
        while self._scene_for and self.scene_channel is not None:
            client = self._scene_for.popleft()
            if client is None:
                self.scene_channel.log(self.scene_bytes(), log_time=self._time_ns)
            else:
                self.scene_channel.log(self.scene_bytes(), log_time=self._time_ns, sink_id=client)
        q = self._queue
        while q:
            try:
                topic, ros_type, body, ns = q.popleft()
            except IndexError:
                break
            self._forward(topic, ros_type, body, ns)
        if self._time_ns != self._sent_time_ns:         # (else the next pass, within the worker's 0.05 s wait)
            now = time.monotonic()
            if now - self._time_sent_at >= TIME_EVERY_S:
                self._sent_time_ns, self._time_sent_at = self._time_ns, now
                self.server.broadcast_time(self._time_ns)

    def _forward(self, topic: str, ros_type: str, body: bytes, ns: int) -> None:
        subs = self._subs
        ch = self.channels.get(topic)
        if ch is not None and subs.get(topic, 0) > 0:
            try:
                _typename, data = self.encoder.encode(ros_type, body)
            except (ExportError, ValueError, TypeError, KeyError) as exc:
                self.errors.setdefault(topic, f"{type(exc).__name__}: {exc}")
            else:
                ch.log(data, log_time=ns)
                self.sent += 1
        robot = self.pose_robot.get(topic)
        if robot is not None and self.tf_channel is not None and subs.get(TF_TOPIC, 0) > 0:
            self.tf_channel.log(self.transforms_bytes(robot, body, ns), log_time=ns)
            self.sent += 1
        robot = self.joint_robot.get(topic)
        if robot is not None and self.tf_channel is not None and subs.get(TF_TOPIC, 0) > 0:
            self.tf_channel.log(self.joint_transforms_bytes(robot, body, ns), log_time=ns)
            self.sent += 1

    def joint_transforms_bytes(self, robot: str, joint_body: bytes, ns: int) -> bytes:
        """The ``/tf`` message of one JointState body: the frames of the devices riding the robot's
        joints, which the robot's next poses carry too."""
        assert self.joint_frames is not None
        moved = self.joint_frames.update(robot, *joint_positions(joint_body))
        at = {m[0]: m for m in moved}
        self.mounts[robot] = [at.get(m[0], m) for m in self.mounts[robot]]
        return self._scene_mod.mount_transforms(robot, ns, moved).encode()

    def transforms_bytes(self, robot: str, pose_body: bytes, ns: int) -> bytes:
        """The ``/tf`` message (encoded ``FrameTransforms``) of one PoseStamped body."""
        msg = msgpack.unpackb(pose_body, raw=False)
        p = msg["pose"]
        t = (p["position"]["x"], p["position"]["y"], p["position"]["z"])
        q = (p["orientation"]["x"], p["orientation"]["y"], p["orientation"]["z"], p["orientation"]["w"])
        return self._scene_mod.frame_transforms(robot, ns, t, q, self.mounts.get(robot, [])).encode()

    def scene_bytes(self) -> bytes:
        """The encoded ``SceneUpdate`` of the world (solids at their current poses, shapes in their
        current appearances); encoded again only when one of those changed."""
        if self.world is None:
            return b""
        poses = self.solid_poses() if self.solid_poses is not None else None
        removed = frozenset(self.removed_lights()) if self.removed_lights is not None else frozenset()
        version, drawn = self._drawn
        # the scene's solids_version too: a solid built again (a PROTO field set) keeps its name and pose
        key = (tuple((n, p.translation.tobytes(), p.rotation.tobytes()) for n, p in (poses or {}).items()),
               tuple(sorted(removed)), len(self.world.lights), version, getattr(self.appearances, "solids_version", 0))
        if self._scene_bytes is None or key != self._scene_key:
            self._scene_bytes = self._scene_mod.scene_update(self.world, self.base_dir, 0, poses, removed,
                                                             drawn).encode()
            self._scene_key = key
        return self._scene_bytes

    def report(self) -> str:
        """One line for the log: what was sent, dropped, and the first error per topic."""
        front = self.front
        line = (f"Foxglove viewer: {front.accepted} connections ({front.renamed} as foxglove.websocket.v1), "
                f"{self.sent} messages sent, {self.dropped} dropped (queue full)")
        if self.sdk_log.suppressed:
            line += f", {self.sdk_log.suppressed} repeated SDK log lines not shown"
        if self.errors:
            line += "; not converted: " + "; ".join(f"{t}: {e}" for t, e in sorted(self.errors.items()))
        return line

    # ------------------------------------------------------------------ close
    def close(self) -> None:
        self._stop = True
        self._event.set()
        self._worker.join(timeout=5.0)
        self.front.close()
        try:
            self.server.stop()
        except Exception:  # noqa: BLE001 - already stopped
            pass
        self._unpacked.close()

    def __enter__(self) -> FoxgloveBridge:
        return self

    def __exit__(self, *exc: Iterable[Any]) -> None:
        self.close()
