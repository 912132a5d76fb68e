"""Export a native (msgpack) recording as ROS 2 data (CDR) for ``ros2 bag play`` and Foxglove.

Two outputs, both MCAP storage with ``profile = "ros2"`` and ``ros2msg`` schemas:

* a **rosbag2 directory** (``metadata.yaml`` + ``<name>.mcap``), written with ``rosbags``
  (RIHS01 type hashes; metadata version 9 for Jazzy, 8 for Humble);
* a **single ``.mcap`` file**, written with ``mcap-ros2-support`` (what Foxglove opens by drag and
  drop; ``ros2 bag play`` accepts it too).

Every topic carries the QoS profile a live driver would offer (:func:`offered_qos`), so that
``ros2 bag play`` offers it again: ``/tf_static`` and the latched ``/scene`` reliable and
transient-local (tf2's and RViz's late-joining subscriptions get them), sensors the sensor-data
profile (best effort, keep last 5), ``/clock`` rclcpp's clock profile, ``/tf`` tf2's broadcaster
profile, anything else rclcpp's default. How rosbag2 writes them differs per metadata version
(read in rosbag2's ``rosbag2_storage/yaml.hpp`` and ``qos.cpp``): up to version 8 (Humble's reader,
and a single ``.mcap`` file without rosbag2's metadata record) ``offered_qos_profiles`` is one YAML
*string* whose policies are integers (``reliability: 1``); from version 9 (Jazzy) it is a YAML
*list* whose policies are names (``reliability: reliable``); the MCAP channel metadata carries the
same profiles as a string in the version's encoding. Durations are rmw's "infinite"
(``{sec: 9223372036, nsec: 854775807}``), as rosbag2 records them from a live publisher.

Bodies are msgpack maps with ROS field names; typed arrays are little-endian ``bin``
(``float32[]`` → ``<f4``, ``uint8[]`` → bytes) and a PointCloud's ``points`` is one ``<f4``
N×3 bin (PROTOCOL.md §4). The conversion is driven by the chosen distro's message definitions
(from rosbags' type stores): fields the distro lacks are dropped (``Range.variance`` in Humble),
fields the body lacks are zero. ``pointcloud2=True`` turns ``sensor_msgs/msg/PointCloud`` into
``sensor_msgs/msg/PointCloud2`` (x, y, z FLOAT32 and one FLOAT32 field per channel, e.g. ``layer``).
"""

from __future__ import annotations

import array
import os
import struct
import sys
import tempfile
from collections.abc import Callable
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import msgpack
import numpy as np

from sensorium.schemas import world as wm
from sensorium.schemas.devices import KINDS
from sensorium.server.recording import cdr
from sensorium.server.recording.envelope import unmatched_topics
from sensorium.server.recording.reader import Recording, topic_matcher

DISTROS = ("humble", "jazzy")
POINT_CLOUD = "sensor_msgs/msg/PointCloud"
POINT_CLOUD2 = "sensor_msgs/msg/PointCloud2"
FLOAT32 = 7  # sensor_msgs/msg/PointField.FLOAT32

_NP_DTYPES: dict[str, Any] = {
    "bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8, "uint8": np.uint8,
    "int16": "<i2", "uint16": "<u2", "int32": "<i4", "uint32": "<u4", "int64": "<i8", "uint64": "<u8",
    "float32": "<f4", "float64": "<f8",
}
_ARRAY_CODES = {"bool": "B", "byte": "B", "char": "b", "int8": "b", "uint8": "B", "int16": "h", "uint16": "H",
                "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d"}
_INTS = {"byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"}


class ExportError(Exception):
    pass


# --------------------------------------------------------------------------------------------
# QoS: what a live driver offers on each topic

# the message types of device topics declared with SensorDataQoS (schemas/devices.py), and PointCloud2
SENSOR_TYPES = frozenset({t.message for k in KINDS.values() for t in k.topics if t.sensor_qos} | {POINT_CLOUD2})
LATCHED_TOPICS = frozenset({"/tf_static", "/scene"})
INFINITE = (9223372036, 854775807)       # RMW_DURATION_INFINITE as rmw reports it (sec, nsec)


@dataclass(frozen=True)
class QosProfile:
    """One offered profile, in rosbag2's terms (``history``/``reliability``/``durability`` names)."""

    reliability: str                     # reliable | best_effort
    durability: str                      # transient_local | volatile
    depth: int
    history: str = "keep_last"


def offered_qos(topic: str, typename: str) -> QosProfile:
    """The profile a ROS 2 driver offers on ``topic`` (of ``typename``)."""
    if topic in LATCHED_TOPICS:                       # tf2 StaticTransformBroadcaster, latched markers
        return QosProfile("reliable", "transient_local", 1)
    if topic == "/tf":                                # tf2 TransformBroadcaster
        return QosProfile("reliable", "volatile", 100)
    if typename == "rosgraph_msgs/msg/Clock":         # rclcpp::ClockQoS
        return QosProfile("best_effort", "volatile", 1)
    if typename in SENSOR_TYPES:                      # rclcpp::SensorDataQoS
        return QosProfile("best_effort", "volatile", 5)
    return QosProfile("reliable", "volatile", 10)     # rclcpp::QoS(10), the default


def rosbags_qos(profile: QosProfile) -> Any:
    """The profile as a ``rosbags.interfaces.Qos`` (for rosbags' writer)."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

    forever = QosTime(*INFINITE)
    return Qos(QosHistory[profile.history.upper()], profile.depth, QosReliability[profile.reliability.upper()],
               QosDurability[profile.durability.upper()], forever, forever, QosLiveliness.AUTOMATIC, forever, False)


def qos_yaml_v8(profile: QosProfile) -> str:
    """The profile as rosbag2 up to metadata version 8 serialises it: a YAML list, policies as
    rmw's integers, in one string (the ``offered_qos_profiles`` value and MCAP channel metadata)."""
    from rosbags.rosbag2.metadata import dump_qos_v8

    return dump_qos_v8([rosbags_qos(profile)])


def typestore_for(distro: str):
    """The rosbags type store of a ROS 2 distro (``humble`` or ``jazzy``)."""
    try:
        from rosbags.typesys import Stores, get_typestore
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ExportError("ROS 2 export needs the 'ros2' extra: pip install 'sensorium[ros2]'") from exc
    stores = {"humble": Stores.ROS2_HUMBLE, "jazzy": Stores.ROS2_JAZZY}
    try:
        store = get_typestore(stores[distro])
    except KeyError:
        raise ExportError(f"unknown distro {distro!r} (choose from {', '.join(DISTROS)})") from None
    store.register(_extra_types())
    return store


# Message types Sensorium publishes that rosbags' stores lack: ROS 2's radar_msgs (a Radar's
# targets), defined here by their fields as that package defines them.
_RADAR_MSGS = {
    "radar_msgs/msg/RadarReturn": "float32 range\nfloat32 azimuth\nfloat32 elevation\nfloat32 doppler_velocity\n"
                                  "float32 amplitude\n",
    "radar_msgs/msg/RadarScan": "std_msgs/Header header\nradar_msgs/RadarReturn[] returns\n",
}


def _extra_types() -> dict:
    from rosbags.typesys import get_types_from_msg
    out: dict = {}
    for name, text in _RADAR_MSGS.items():
        out.update(get_types_from_msg(text, name))
    return out


# --------------------------------------------------------------------------------------------
# msgpack body -> ROS message (plain dicts with numpy arrays), per the distro's definitions


def _base_value(basetype: str, value: Any) -> Any:
    if basetype == "string" or basetype == "wstring":
        if value is None:
            return ""
        return value.decode() if isinstance(value, (bytes, bytearray)) else str(value)
    if basetype == "bool":
        return bool(value) if value is not None else False
    if basetype in _INTS:
        return int(value) if value is not None else 0
    # float32/float64: Python float (float32 rounding happens in CDR)
    return float(value) if value is not None else 0.0


def _base_array(basetype: str, value: Any) -> Any:
    if basetype in ("string", "wstring"):
        return [_base_value(basetype, v) for v in (value or [])]
    dtype = np.dtype(_NP_DTYPES[basetype])
    if value is None:
        return np.zeros(0, dtype=dtype)
    if isinstance(value, (bytes, bytearray, memoryview)):
        raw = bytes(value)
        if len(raw) % dtype.itemsize:
            raise ExportError(f"{len(raw)} bytes is not a whole number of {basetype} items")
        return np.frombuffer(raw, dtype=dtype).astype(dtype.newbyteorder("="), copy=False)
    return np.asarray(value, dtype=dtype.newbyteorder("="))


def points_from_bin(data: Any) -> np.ndarray:
    """A PointCloud ``points`` field (N×3 ``<f4`` bin, or a list of {x, y, z}) → float32 (N, 3)."""
    if isinstance(data, (bytes, bytearray, memoryview)):
        arr = np.frombuffer(bytes(data), dtype="<f4")
        if arr.size % 3:
            raise ExportError(f"points: {arr.size} floats is not a multiple of 3")
        return arr.reshape(-1, 3).astype(np.float32)
    return np.array([[p.get("x", 0.0), p.get("y", 0.0), p.get("z", 0.0)] for p in (data or [])],
                    dtype=np.float32).reshape(-1, 3)


def to_ros(typestore, typename: str, body: dict) -> dict:
    """A msgpack body → nested dicts shaped exactly like ``typename`` in ``typestore`` (extra keys
    dropped, missing ones zero); primitive arrays become numpy arrays."""
    if typename == POINT_CLOUD and isinstance(body.get("points"), (bytes, bytearray, memoryview)):
        pts = points_from_bin(body["points"])
        body = dict(body, points=[{"x": float(x), "y": float(y), "z": float(z)} for x, y, z in pts.tolist()])
    return _convert(typestore, typename, body or {})


def _convert(typestore, typename: str, value: dict) -> dict:
    try:
        _consts, fields = typestore.fielddefs[typename]
    except KeyError:
        raise ExportError(f"type {typename!r} is not known to the type store") from None
    out: dict[str, Any] = {}
    for name, (kind, spec) in fields:
        v = value.get(name) if isinstance(value, dict) else None
        kind = int(kind)
        if kind == 1:  # BASE
            out[name] = _base_value(spec[0], v)
        elif kind == 2:  # NAME
            out[name] = _convert(typestore, spec, v if isinstance(v, dict) else {})
        else:  # 3 ARRAY (fixed) / 4 SEQUENCE
            (sub_kind, sub_spec), size = spec
            if int(sub_kind) == 1:
                arr = _base_array(sub_spec[0], v)
                if kind == 3 and size:
                    arr = _fit(arr, size, sub_spec[0])
                out[name] = arr
            else:
                items = [_convert(typestore, sub_spec, item if isinstance(item, dict) else {}) for item in (v or [])]
                if kind == 3 and size:
                    items = (items + [_convert(typestore, sub_spec, {}) for _ in range(size)])[:size]
                out[name] = items
    return out


def _fit(arr, size: int, basetype: str):
    if isinstance(arr, list):
        return (arr + [_base_value(basetype, None)] * size)[:size]
    fitted = np.zeros(size, dtype=arr.dtype)
    fitted[: min(size, arr.size)] = arr[:size]
    return fitted


def pointcloud2_from_body(body: dict) -> tuple[str, dict]:
    """A PointCloud body → a PointCloud2 message dict: x, y, z and one FLOAT32 field per channel."""
    pts = points_from_bin(body.get("points"))
    n = pts.shape[0]
    channels = [c for c in (body.get("channels") or []) if isinstance(c, dict)]
    names = ["x", "y", "z"] + [str(c.get("name", f"ch{i}")) for i, c in enumerate(channels)]
    cols = [pts[:, 0], pts[:, 1], pts[:, 2]]
    for c in channels:
        vals = _base_array("float32", c.get("values"))
        if vals.size != n:
            raise ExportError(f"channel {c.get('name')!r} has {vals.size} values for {n} points")
        cols.append(vals)
    rec = np.empty(n, dtype=np.dtype({"names": names, "formats": ["<f4"] * len(names)}))
    for nm, col in zip(names, cols):
        rec[nm] = col
    step = 4 * len(names)
    finite = bool(np.isfinite(pts).all()) if n else True
    msg = {"header": body.get("header", {}), "height": 1, "width": n,
           "fields": [{"name": nm, "offset": 4 * i, "datatype": FLOAT32, "count": 1} for i, nm in enumerate(names)],
           "is_bigendian": False, "point_step": step, "row_step": step * n,
           "data": np.frombuffer(rec.tobytes(), dtype=np.uint8), "is_dense": finite}
    return POINT_CLOUD2, msg


def convert_message(typestore, ros_type: str, body_bytes: bytes, pointcloud2: bool = False) -> tuple[str, dict]:
    """Recorded body bytes → ``(export type, ROS message dict)``."""
    body = msgpack.unpackb(body_bytes, raw=False)
    if not isinstance(body, dict):
        raise ExportError("body is not a msgpack map")
    if pointcloud2 and ros_type == POINT_CLOUD:
        typename, msg = pointcloud2_from_body(body)
        return typename, _convert(typestore, typename, msg)
    return ros_type, to_ros(typestore, ros_type, body)


# --------------------------------------------------------------------------------------------
# dict -> rosbags objects / mcap-ros2 values


def to_rosbags(typestore, typename: str, msg: dict) -> Any:
    """A message dict → the type store's dataclass instance (for ``serialize_cdr``)."""
    _consts, fields = typestore.fielddefs[typename]
    kwargs = {}
    for name, (kind, spec) in fields:
        v = msg[name]
        kind = int(kind)
        if kind == 2:
            kwargs[name] = to_rosbags(typestore, spec, v)
        elif kind in (3, 4) and int(spec[0][0]) == 2:
            kwargs[name] = [to_rosbags(typestore, spec[0][1], item) for item in v]
        else:
            kwargs[name] = v
    return typestore.types[typename](**kwargs)


def _to_mcap_ros2(typestore, typename: str, msg: dict) -> dict:
    """A message dict → values mcap-ros2-support's encoder accepts (lists/array.array/bytes)."""
    _consts, fields = typestore.fielddefs[typename]
    out: dict[str, Any] = {}
    for name, (kind, spec) in fields:
        v = msg[name]
        kind = int(kind)
        if kind == 2:
            out[name] = _to_mcap_ros2(typestore, spec, v)
        elif kind in (3, 4):
            (sub_kind, sub_spec), _size = spec
            if int(sub_kind) == 2:
                out[name] = [_to_mcap_ros2(typestore, sub_spec, item) for item in v]
            elif sub_spec[0] in ("string", "wstring"):
                out[name] = list(v)
            elif sub_spec[0] in ("uint8", "byte"):
                out[name] = np.asarray(v, dtype=np.uint8).tobytes()
            else:
                code = _ARRAY_CODES[sub_spec[0]]
                out[name] = array.array(code, np.asarray(v).astype(np.dtype(code).newbyteorder("=")).tobytes())
        else:
            out[name] = v
    return out


# --------------------------------------------------------------------------------------------
# export


@dataclass
class ExportReport:
    out: Path
    distro: str
    fmt: str
    messages: int = 0
    views: int = 0                                         # /tf, /tf_static, /scene messages added
    topics: dict[str, str] = field(default_factory=dict)  # topic -> exported type
    skipped: dict[str, int] = field(default_factory=dict)  # topic -> messages not exported
    reasons: dict[str, str] = field(default_factory=dict)
    truncated: bool = False                                # the source was not finished (writer killed?)
    readable_bytes: int | None = None                      # ... and only this much of it could be read
    size_bytes: int = 0
    last_stamp_ns: int | None = None                       # the last message exported
    progress: Any = None                                   # callback (done, total), or None
    total: int = 0
    read: int = 0
    damaged: list[Any] = field(default_factory=list)       # parts of the source skipped (scan.Damage)


@dataclass
class _Added:
    """A message the export adds (scene, transforms): what the writers read of a RecordedMessage."""

    topic: str
    stamp_ns: int
    seq: int


def _iter_converted(rec: Recording, typestore, topics, pointcloud2: bool, report: ExportReport,
                    start_ns: int | None, end_ns: int | None, views: bool = True):
    """``(message, export type, message dict, added)`` in order; ``added`` marks the scene and
    transform messages of :mod:`.ros_views` (when ``views`` and the recorded world has them). The
    recorded world's unpacked files live while the messages are converted."""
    from sensorium.server.recording import ros_views

    with ros_views.recorded_world(rec) if views else nullcontext((None, Path("."))) as (world, base_dir):
        yield from _converted(rec, typestore, topics, pointcloud2, report, start_ns, end_ns, world, base_dir)


def _converted(rec: Recording, typestore, topics, pointcloud2: bool, report: ExportReport,
               start_ns: int | None, end_ns: int | None, world: wm.World | None, base_dir: Path):
    from sensorium.server.recording import ros_views
    from sensorium.server.recording.frames import JointFrames

    started = False
    tf_seq = 0
    joint_frames: JointFrames | None = None
    moving: frozenset[str] = frozenset()
    if world is not None:               # devices riding joints: dynamic frames when the joints' states are exported
        joint_frames = JointFrames(world)
        match = topics if callable(topics) else topic_matcher(topics)
        exported = {t.topic for t in rec.topics() if match(t.topic)}
        moving = frozenset(f for r in joint_frames.robots if f"/{r}/joint_states" in exported
                           for f in joint_frames.frames(r))
    for m, typename, msg in _iter_recorded(rec, typestore, topics, pointcloud2, report, start_ns, end_ns):
        if world is not None and not started:
            started = True
            for topic, typ, value in (("/tf_static", ros_views.TF, ros_views.tf_static(world, m.stamp_ns, moving)),
                                      ("/scene", ros_views.MARKER_ARRAY,
                                       ros_views.marker_array(world, base_dir, m.stamp_ns))):
                if value is not None:
                    report.topics.setdefault(topic, typ)
                    yield _Added(topic, m.stamp_ns, 0), typ, _convert(typestore, typ, value), True
        yield m, typename, msg, False
        robot = ros_views.pose_robot(m.topic, m.ros_type) if world is not None else None
        if robot is not None:
            report.topics.setdefault("/tf", ros_views.TF)
            value = ros_views.tf_pose(robot, m.data, m.stamp_ns)
            yield _Added("/tf", m.stamp_ns, tf_seq), ros_views.TF, _convert(typestore, ros_views.TF, value), True
            tf_seq += 1
        robot = ros_views.joint_states_robot(m.topic, m.ros_type) if joint_frames is not None else None
        if joint_frames is not None and robot is not None and robot in joint_frames.robots:
            report.topics.setdefault("/tf", ros_views.TF)
            value = ros_views.tf_joints(robot, joint_frames.update(robot, *ros_views.joint_positions(m.data)), m.stamp_ns)
            yield _Added("/tf", m.stamp_ns, tf_seq), ros_views.TF, _convert(typestore, ros_views.TF, value), True
            tf_seq += 1


def _iter_recorded(rec: Recording, typestore, topics, pointcloud2: bool, report: ExportReport,
                   start_ns: int | None, end_ns: int | None):
    bad: set[str] = set()
    for m in rec.messages(topics, start_ns, end_ns):
        if report.progress is not None:
            report.read += 1
            report.progress(report.read, report.total)
        if m.topic in bad:
            report.skipped[m.topic] = report.skipped.get(m.topic, 0) + 1
            continue
        if m.ros_type not in typestore.fielddefs:
            bad.add(m.topic)
            report.skipped[m.topic] = report.skipped.get(m.topic, 0) + 1
            report.reasons[m.topic] = f"type {m.ros_type!r} unknown to ROS 2 {report.distro}"
            continue
        try:
            typename, msg = convert_message(typestore, m.ros_type, m.data, pointcloud2)
        except Exception as exc:
            report.skipped[m.topic] = report.skipped.get(m.topic, 0) + 1
            report.reasons.setdefault(m.topic, f"{type(exc).__name__}: {exc}")
            continue
        report.topics.setdefault(m.topic, typename)
        report.last_stamp_ns = m.stamp_ns if report.last_stamp_ns is None else max(report.last_stamp_ns, m.stamp_ns)
        yield m, typename, msg


def export_ros2(src: str | Path, out: str | Path, *, distro: str = "jazzy", fmt: str | None = None,
                pointcloud2: bool = False, topics: list[str] | None = None,
                start_ns: int | None = None, end_ns: int | None = None, views: bool = True,
                progress: Callable[[int, int], None] | None = None,
                on_damage: Callable[[Any], None] | None = None, overwrite: bool = False) -> ExportReport:
    """Export ``src`` to ``out``. ``fmt`` is ``"bag"`` (rosbag2 directory, via rosbags) or
    ``"mcap"`` (single file, via mcap-ros2-support); by default ``.mcap`` outputs are single files.
    ``views``: add ``/tf_static``, ``/tf`` and ``/scene`` from the recorded world (:mod:`.ros_views`).
    ``progress(done, total)`` is called as messages are read (total: the recording's message count).
    A damaged part of ``src`` is skipped and passed to ``on_damage`` (a :class:`~.scan.Damage`).
    ``overwrite``: replace an existing ``out`` (a file, or a directory holding a rosbag2 bag's
    ``metadata.yaml``; never ``src`` itself): the export is written beside it and takes its place
    only when complete, so a failed or interrupted export leaves the old one as it was.
    Never leaves a partial output: if the export fails or is interrupted, what it wrote is removed."""
    out = Path(out)
    if distro not in DISTROS:
        raise ExportError(f"unknown distro {distro!r} (choose from {', '.join(DISTROS)})")
    fmt = fmt or ("mcap" if out.suffix == ".mcap" else "bag")
    if fmt not in ("bag", "mcap"):
        raise ExportError(f"unknown format {fmt!r} (bag or mcap)")
    if start_ns is not None and end_ns is not None and end_ns < start_ns:
        raise ExportError("--end is before --start")          # as replay says: an empty bag is no answer
    replacing = out.exists() or out.is_symlink()
    if replacing:
        _check_replaceable(Path(src), out, overwrite)
    typestore = typestore_for(distro)
    report = ExportReport(out=out, distro=distro, fmt=fmt)
    with Recording(src, on_damage=on_damage) as rec:
        report.progress = progress
        if progress:
            rec.check()                     # damaged chunks found first: the total counts what will be read
        report.total = sum(t.count for t in rec.topics()) if progress else 0
        problem = rec.foreign() or unmatched_topics(topics, [t.topic for t in rec.topics()], str(src))
        if problem:
            raise ExportError(problem)
        meta = rec.metadata().get("sensorium", {})
        world = rec.world()
        # a replacement is written in a fresh directory beside OUT (same file system), under OUT's
        # name (a bag names its files after its directory), and moved over OUT when complete
        staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".export", dir=out.parent)) if replacing else None
        target = out if staging is None else staging / out.name
        try:
            if fmt == "bag":
                _write_rosbag2(rec, target, typestore, distro, topics, pointcloud2, report, meta, start_ns, end_ns,
                               views)
            else:
                _write_single(rec, target, typestore, topics, pointcloud2, report, meta, world, distro, start_ns,
                              end_ns, views)
            if staging is not None:
                if target.is_dir() or (out.is_dir() and not out.is_symlink()):
                    _remove_output(out)             # os.replace moves a file over a file only
                os.replace(target, out)
        except BaseException:
            _remove_output(staging if staging is not None else out)
            raise
        if staging is not None:
            _remove_output(staging)
        report.size_bytes = rec.path.stat().st_size
        report.damaged = list(rec.damaged)
        if rec.truncated:
            report.truncated = True
            report.readable_bytes = rec._scan().get("stopped_at")
    return report


def _check_replaceable(src: Path, out: Path, overwrite: bool) -> None:
    """Raise :class:`ExportError` unless ``overwrite`` allows replacing the existing ``out``: a file
    or a rosbag2 bag (a directory holding ``metadata.yaml``), never the recording being exported."""
    if not overwrite:
        raise ExportError(f"{out} exists already; not overwriting (--force to replace it)")
    if src.exists() and out.resolve() == src.resolve():
        raise ExportError(f"{out} is the recording being exported; not replacing it")
    if out.is_dir() and not out.is_symlink() and not (out / "metadata.yaml").is_file():
        raise ExportError(f"{out} is a directory but no rosbag2 bag (no metadata.yaml); not replacing it")


def _remove_output(out: Path) -> None:
    """Remove ``out``, a file or a directory tree: what a failed export wrote (a new output or its
    staging directory), or the output a complete replacement takes the place of."""
    import shutil

    try:
        if out.is_dir() and not out.is_symlink():
            shutil.rmtree(out)
        else:
            out.unlink(missing_ok=True)
    except OSError:
        pass


def _write_rosbag2(rec, out, typestore, distro, topics, pointcloud2, report, meta, start_ns, end_ns, views) -> None:
    try:
        from rosbags.rosbag2 import StoragePlugin, Writer
    except ImportError as exc:  # pragma: no cover
        raise ExportError("rosbag2 export needs rosbags: pip install 'sensorium[ros2]'") from exc
    writer = Writer(out, version=9 if distro == "jazzy" else 8, storage_plugin=StoragePlugin.MCAP)
    writer.open()
    try:
        for key, value in meta.items():
            writer.set_custom_data(f"sensorium.{key}", str(value))
        writer.set_custom_data("sensorium.distro", distro)
        conns: dict[str, Any] = {}
        for m, typename, msg, added in _iter_converted(rec, typestore, topics, pointcloud2, report, start_ns, end_ns,
                                                       views):
            conn = conns.get(m.topic)
            if conn is None:
                conn = conns[m.topic] = writer.add_connection(
                    m.topic, typename, typestore=typestore,
                    offered_qos_profiles=[rosbags_qos(offered_qos(m.topic, typename))])
            data = typestore.serialize_cdr(to_rosbags(typestore, typename, msg), typename)
            writer.write(conn, m.stamp_ns, data)
            if added:
                report.views += 1
            else:
                report.messages += 1
    finally:
        writer.close()


def _write_single(rec, out, typestore, topics, pointcloud2, report, meta, world, distro, start_ns, end_ns,
                  views) -> None:
    try:
        from mcap_ros2.writer import Writer as Ros2Writer
    except ImportError as exc:  # pragma: no cover
        raise ExportError("single-file export needs mcap-ros2-support: pip install 'sensorium[ros2]'") from exc
    with open(out, "wb") as f:
        writer = Ros2Writer(f)
        try:
            schemas: dict[str, Any] = {}
            channels: dict[str, int] = {}
            for m, typename, msg, added in _iter_converted(rec, typestore, topics, pointcloud2, report, start_ns,
                                                           end_ns, views):
                schema = schemas.get(typename)
                if schema is None:
                    text = typestore.generate_msgdef(typename, ros_version=2)[0]
                    schema = schemas[typename] = writer.register_msgdef(typename, text)
                if m.topic not in channels:
                    # registered here (not by write_message) to carry the QoS rosbag2's MCAP plugin reads;
                    # without rosbag2's metadata record it reads them as metadata version 8
                    channels[m.topic] = writer._channel_ids[m.topic] = writer._writer.register_channel(
                        topic=m.topic, message_encoding="cdr", schema_id=schema.id,
                        metadata={"offered_qos_profiles": qos_yaml_v8(offered_qos(m.topic, typename))})
                writer.write_message(topic=m.topic, schema=schema, message=_to_mcap_ros2(typestore, typename, msg),
                                     log_time=m.stamp_ns, publish_time=m.stamp_ns, sequence=m.seq % (1 << 32))
                if added:
                    report.views += 1
                else:
                    report.messages += 1
            if meta:
                writer.add_metadata("sensorium", dict(meta, distro=distro))
            if world:
                name, data = world
                writer.add_attachment(create_time=0, log_time=0, name=name, media_type="application/yaml"
                                      if name.endswith((".yaml", ".yml")) else "application/octet-stream", data=data)
        finally:
            writer.finish()


def truncation_warning(report: ExportReport) -> str | None:
    """One line saying how much of a truncated recording was exported, or None."""
    if not report.truncated:
        return None
    upto = "no message" if report.last_stamp_ns is None else f"up to t={report.last_stamp_ns / 1e9:.3f} s"
    part = (f", read from the first {report.readable_bytes} of its {report.size_bytes} bytes"
            if report.readable_bytes is not None else "")
    return (f"warning: the recording is truncated (not finished: the writer was killed?): exported "
            f"{report.messages} messages, {upto}{part}; the rest is lost")


def print_report(report: ExportReport, file=sys.stdout) -> None:
    kind = "rosbag2 directory" if report.fmt == "bag" else "ROS 2 MCAP file"
    print(f"sensorium: exported {report.messages} messages on {len(report.topics)} topics to {kind} "
          f"{report.out} (ROS 2 {report.distro})", file=file)
    for topic, typename in sorted(report.topics.items()):
        print(f"  {topic}  {typename}", file=file)
    if report.views:
        print(f"  (+{report.views} scene/transform messages from the recorded world: /tf_static, /tf, /scene)", file=file)
    for topic, n in sorted(report.skipped.items()):
        print(f"  skipped {n} message(s) on {topic}: {report.reasons.get(topic, '?')}", file=file)



# --------------------------------------------------------------------------------------------
# one message at a time: the CDR bytes Foxglove (live viewer, Foxglove-ready recordings) receives


class CdrEncoder:
    """Recorded/published msgpack bodies → ROS 2 CDR bytes with rosbags' ``serialize_cdr`` (the
    encoder of the rosbag2 export, so a live viewer, a Foxglove-ready recording and an exported bag
    carry the same bytes). ``pointcloud2``: ``sensor_msgs/msg/PointCloud`` bodies become
    ``sensor_msgs/msg/PointCloud2`` (Foxglove's 3D panel draws PointCloud2, not the old PointCloud)."""

    def __init__(self, distro: str = "jazzy", pointcloud2: bool = True):
        self.distro = distro
        self.pointcloud2 = pointcloud2
        self.typestore = typestore_for(distro)
        self._defs: dict[str, str] = {}

    def export_type(self, ros_type: str) -> str | None:
        """The type a topic of ``ros_type`` is encoded as, or ``None`` if the distro lacks it."""
        if self.pointcloud2 and ros_type == POINT_CLOUD:
            return POINT_CLOUD2
        return ros_type if ros_type in self.typestore.fielddefs else None

    def msgdef(self, typename: str) -> str:
        """The ``ros2msg`` schema text (the type, then its dependencies after ``=====`` lines)."""
        text = self._defs.get(typename)
        if text is None:
            text = self._defs[typename] = self.typestore.generate_msgdef(typename, ros_version=2)[0]
        return text

    def encode(self, ros_type: str, body_bytes: bytes) -> tuple[str, bytes]:
        """``(export type, CDR bytes)``; raises :class:`ExportError` on a body that does not convert.
        Sensorium's own types are written directly (:mod:`.cdr`, byte-identical to rosbags), others
        through the type store."""
        typename = self.export_type(ros_type)
        if typename is None:
            raise ExportError(f"type {ros_type!r} unknown to ROS 2 {self.distro}")
        if typename in cdr.FAST_TYPES:
            try:
                body = msgpack.unpackb(body_bytes, raw=False)
                if typename == POINT_CLOUD2 and ros_type == POINT_CLOUD:
                    body = pointcloud2_from_body(body)[1]
                return typename, cdr.encode(typename, body, self.distro)
            except (KeyError, TypeError, ValueError, OverflowError, AttributeError, struct.error, ExportError):
                pass                                  # unusual body: the generic path decides
        return typename, self.encode_generic(ros_type, body_bytes)

    def encode_generic(self, ros_type: str, body_bytes: bytes) -> bytes:
        """The same bytes through rosbags' type store and ``serialize_cdr`` (the reference)."""
        typename, msg = convert_message(self.typestore, ros_type, body_bytes, self.pointcloud2)
        return bytes(self.typestore.serialize_cdr(to_rosbags(self.typestore, typename, msg), typename))
