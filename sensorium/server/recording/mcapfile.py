"""Recording what a simulation publishes to MCAP, and reading it back.

Writing (``McapRecorder``) is called by the server from inside its step loop for every message it
publishes, with the bytes it published: nothing is dropped and nothing is re-encoded. Layout:

* header ``profile = "x-sensorium"``; zstd-compressed chunks (``chunk_size`` bytes, default 1 MiB,
  and at the latest every ``flush_interval`` wall-clock seconds, so a crashed recorder loses little);
* one schema per ROS type (``name`` = the ROS type, e.g. ``sensor_msgs/msg/Range``, ``encoding``
  ``""``: msgpack is self-describing) and one channel per topic with ``message_encoding =
  "msgpack"``;
* each message: ``data`` = the published body, byte for byte; ``log_time = publish_time`` =
  ``stamp_ns`` of the envelope (simulation time, ns since the simulation started); ``sequence`` =
  the envelope's per-topic ``seq`` (MCAP stores 32 bits; readers unwrap). The envelope
  ``{type, seq, stamp_ns}`` is therefore fully recoverable (:meth:`RecordedMessage.envelope`);
* the world file as an attachment; a metadata record ``sensorium`` (seed, time step, version, ...,
  deterministic) and a metadata record ``session`` (wall-clock start/end, not deterministic).

Foxglove-ready recordings (format 2, the default when the ``foxglove`` extra is installed): the
msgpack bodies go to ``/sensorium/wire<topic>`` channels wrapped as a CDR ``uint8[]`` (still byte
for byte), next to per-topic ROS 2 CDR views, ``/tf`` and ``/scene`` that Foxglove displays; see
:mod:`sensorium.server.recording.foxglove_views`. Readers use only the lossless channels.

Reading (``Recording``) streams messages in time order, and summarises a file for ``sensorium info``.
A file whose writer died without finishing (kill -9, power loss) has no summary or footer: it is
then read sequentially up to its last complete chunk and reported as ``truncated``.
"""

from __future__ import annotations

import datetime as _dt
import fnmatch
import io
import json
import os
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import msgpack
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import (
    Attachment,
    Channel,
    Chunk,
    DataEnd,
    Footer,
    Header,
    Message,
    MessageIndex,
    Metadata,
    Schema,
)
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType, IndexType, Writer

from sensorium.server.recording import foxglove_views as fxv

PROFILE = "x-sensorium"
MESSAGE_ENCODING = "msgpack"
MAGIC = b"\x89MCAP0\r\n"
SEQ_MODULUS = 1 << 32
DEFAULT_CHUNK_SIZE = 1 << 20

__all__ = [
    "McapRecorder",
    "Recording",
    "RecordedMessage",
    "topic_matcher",
    "pack_envelope",
    "iter_messages",
    "summarize",
    "print_info",
    "recorder_for_server",
]


def _version() -> str:
    try:
        from sensorium import __version__

        return __version__
    except Exception:  # pragma: no cover - the package is always importable when installed
        return "unknown"


def pack_envelope(ros_type: str, seq: int, stamp_ns: int) -> bytes:
    """The topic envelope of PROTOCOL.md §4: msgpack ``{"type", "seq", "stamp_ns"}`` in that order."""
    return msgpack.packb({"type": ros_type, "seq": seq, "stamp_ns": stamp_ns})


# --------------------------------------------------------------------------------------------
# topic filters


def topic_matcher(patterns: Iterable[str] | None) -> Callable[[str], bool]:
    """A predicate for ``--topics`` lists. ``None``/empty matches every topic. A pattern matches a
    topic when it is the topic itself, a path prefix of it (``/epuck`` and ``/epuck/`` match
    ``/epuck/ps0/value`` but ``/epuck/ps1`` does not match ``/epuck/ps10/value``), or, when it
    contains ``*``, ``?`` or ``[``, a shell-style glob over the whole topic (``/epuck/ps*``)."""
    pats = [p for p in (patterns or []) if p]
    if not pats:
        return lambda topic: True
    exact: set[str] = set()
    prefixes: list[str] = []
    globs: list[str] = []
    for p in pats:
        if any(c in p for c in "*?["):
            globs.append(p)
        else:
            exact.add(p.rstrip("/") or "/")
            prefixes.append(p if p.endswith("/") else p + "/")
    cache: dict[str, bool] = {}

    def match(topic: str) -> bool:
        hit = cache.get(topic)
        if hit is None:
            hit = (topic in exact or any(topic.startswith(p) for p in prefixes)
                   or any(fnmatch.fnmatchcase(topic, g) for g in globs))
            if len(cache) < 65536:
                cache[topic] = hit
        return hit

    return match


# --------------------------------------------------------------------------------------------
# writing


class _WriteThrough:
    """A minimal output stream for mcap's Writer that hands every write to the kernel at once.

    mcap's Writer only writes whole records (a finished chunk, its message indexes, a metadata
    record, …), so with no user-space buffering a process killed with SIGKILL leaves a file that is
    complete up to its last written chunk. (The Writer would wrap a ``RawIOBase`` in a
    ``BufferedWriter``, hence this plain class.)"""

    def __init__(self, path: str | os.PathLike):
        self._fd = os.open(os.fspath(path), os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        self._pos = 0

    def write(self, data) -> int:
        view = memoryview(data).cast("B")
        total = len(view)
        while view:
            n = os.write(self._fd, view)
            view = view[n:]
        self._pos += total
        return total

    def tell(self) -> int:
        return self._pos

    def seekable(self) -> bool:
        return False

    def flush(self) -> None:
        pass

    def fsync(self) -> None:
        try:
            os.fsync(self._fd)
        except OSError:
            pass

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


def _media_type(name: str) -> str:
    suffix = Path(name).suffix.lower()
    return {".yaml": "application/yaml", ".yml": "application/yaml", ".json": "application/json",
            ".wbt": "text/plain"}.get(suffix, "application/octet-stream")


def _topic_parts(topic: str) -> dict[str, str]:
    parts = [p for p in topic.split("/") if p]
    if len(parts) >= 3:
        return {"robot": parts[0], "device": parts[1]}
    return {}


class McapRecorder:
    """The recorder sink: ``record()`` is the hook the server calls for every published message.

    ``McapRecorder(path, world_text, world_name, metadata, topics, chunk_size)``; use as a context
    manager or call ``close()`` (idempotent) to finish the file (summary, indexes, footer)."""

    def __init__(self, path: str | os.PathLike, world_text: bytes | str | None = b"",
                 world_name: str = "world.yaml", metadata: dict[str, str] | None = None,
                 topics: list[str] | None = None, chunk_size: int = DEFAULT_CHUNK_SIZE, *,
                 compression: str = "zstd", flush_interval: float | None = 1.0,
                 session: dict[str, str] | None = None, demand: bool = True,
                 background_flush: bool = True, foxglove: bool = True, world: Any = None,
                 base_dir: str | os.PathLike = "."):
        self.path = Path(path)
        # Foxglove views (format 2) when asked for and the extra is installed
        self.foxglove_unavailable = fxv.available() if foxglove else "not requested"
        self._views = fxv.FoxgloveViews(world, base_dir) if self.foxglove_unavailable is None else None
        self._view_schemas: dict[str, int] = {}
        self._view_channels: dict[str, int] = {}
        self._view_seq: dict[str, int] = {}
        self.topics = list(topics) if topics else None
        self.demand = demand
        self._wants = topic_matcher(self.topics)
        self._lock = threading.Lock()
        self._closed = False
        self._flush_interval = flush_interval
        self._last_flush = time.monotonic()
        self._dirty = False
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self.counts: dict[str, int] = {}
        self.message_count = 0
        self._started_wall = time.time()
        comp = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                "none": CompressionType.NONE, "": CompressionType.NONE}[compression]
        self._stream = _WriteThrough(self.path)
        try:
            self._writer = Writer(self._stream, chunk_size=max(1024, int(chunk_size)), compression=comp,
                                  index_types=IndexType.ALL, repeat_channels=True, repeat_schemas=True,
                                  use_chunking=True, use_statistics=True, use_summary_offsets=True,
                                  enable_crcs=True)
            self._writer.start(profile=PROFILE, library=f"sensorium {_version()}")
            if world_text:
                data = world_text.encode() if isinstance(world_text, str) else bytes(world_text)
                self._writer.add_attachment(create_time=0, log_time=0, name=world_name or "world",
                                            media_type=_media_type(world_name or ""), data=data)
            meta = {"version": _version(), "format": "1",
                    "log_time": "simulation time in ns since the simulation started",
                    "message_encoding": MESSAGE_ENCODING,
                    "envelope": "msgpack {type: schema name, seq: sequence, stamp_ns: log_time}"}
            if self._views is not None:
                meta.update({"format": "2", "wire_channels": f"{fxv.WIRE_PREFIX}<topic>: msgpack body as CDR "
                             f"{fxv.WIRE_SCHEMA}; <topic>: ROS 2 CDR view; /tf, /scene: Foxglove"})
            if world_name:
                meta["world_file"] = world_name
            meta.update({str(k): str(v) for k, v in (metadata or {}).items()})
            if self.topics:
                meta["topics"] = " ".join(self.topics)
            self._writer.add_metadata("sensorium", meta)
            sess = {"started_at": _dt.datetime.fromtimestamp(self._started_wall, _dt.timezone.utc).isoformat(),
                    "started_at_ns": str(time.time_ns()), "pid": str(os.getpid())}
            sess.update({str(k): str(v) for k, v in (session or {}).items()})
            self._writer.add_metadata("session", sess)
            scene = self._views.scene() if self._views is not None else None
            if scene is not None:
                self._add_view(scene, 0)
        except BaseException:
            self._stream.close()
            raise
        self._flusher: threading.Thread | None = None
        self._wake = threading.Event()
        if background_flush and flush_interval:
            # pauses of the simulation must not keep the last messages in memory
            self._flusher = threading.Thread(target=self._flush_loop, name="mcap-flush", daemon=True)
            self._flusher.start()

    def _flush_loop(self) -> None:
        while not self._wake.wait(self._flush_interval):
            try:
                self.maybe_flush()
            except Exception:  # the next record() or close() reports I/O errors
                pass

    # -- the hook ---------------------------------------------------------------------------
    def wants(self, topic: str) -> bool:
        """True when ``topic`` passes the recorder's topic filter (every topic without a filter)."""
        return self._wants(topic)

    def demands(self, topic: str) -> bool:
        """True when the server should compute ``topic`` for the recorder even if nobody else asked
        for it: every recorded topic (all of them without a topic list), unless the recorder was
        made with ``demand=False`` (then it only records what is published anyway)."""
        return self.demand and self._wants(topic)

    def record(self, topic: str, ros_type: str, envelope: bytes, body: bytes, stamp_ns: int, seq: int) -> None:
        """Store one published message: ``body`` exactly as published; the envelope's fields are the
        schema name (``ros_type``), ``sequence`` (``seq``) and ``log_time`` (``stamp_ns``)."""
        if not self._wants(topic):
            return
        with self._lock:
            if self._closed:
                return
            cid = self._channels.get(topic)
            if cid is None:
                cid = self._register(topic, ros_type, envelope, body)
            stamp = int(stamp_ns)
            if stamp < 0:
                raise ValueError(f"{topic}: negative stamp_ns {stamp}")
            if self._views is None:
                self._writer.add_message(channel_id=cid, log_time=stamp, publish_time=stamp,
                                         data=bytes(body), sequence=int(seq) % SEQ_MODULUS)
            else:
                self._writer.add_message(channel_id=cid, log_time=stamp, publish_time=stamp,
                                         data=fxv.wire_wrap(bytes(body)), sequence=int(seq) % SEQ_MODULUS)
                for view in self._views.views(topic, ros_type, bytes(body), stamp):
                    self._add_view(view, stamp, int(seq) if view[0] == topic else None)
            self.counts[topic] = self.counts.get(topic, 0) + 1
            self.message_count += 1
            self._dirty = True
            if self._flush_interval is not None:
                now = time.monotonic()
                if now - self._last_flush >= self._flush_interval:
                    self._flush_locked(now)

    __call__ = record

    def _add_view(self, view: tuple[str, str, str, bytes, str, bytes], stamp: int, seq: int | None = None) -> None:
        """One Foxglove view record (caller holds the lock or is the constructor)."""
        topic, schema_name, schema_encoding, schema_data, message_encoding, data = view
        cid = self._view_channels.get(topic)
        if cid is None:
            sid = self._view_schemas.get(schema_name)
            if sid is None:
                sid = self._view_schemas[schema_name] = self._writer.register_schema(
                    name=schema_name, encoding=schema_encoding, data=schema_data)
            cid = self._view_channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding=message_encoding, schema_id=sid, metadata={"sensorium.view": "1"})
        if seq is None:
            seq = self._view_seq.get(topic, 0)
            self._view_seq[topic] = seq + 1
        self._writer.add_message(channel_id=cid, log_time=stamp, publish_time=stamp, data=data,
                                 sequence=seq % SEQ_MODULUS)

    def _register(self, topic: str, ros_type: str, envelope: bytes, body: bytes) -> int:
        meta = _topic_parts(topic)
        if self._views is not None:
            sid = self._schemas.get(fxv.WIRE_SCHEMA)
            if sid is None:
                sid = self._schemas[fxv.WIRE_SCHEMA] = self._writer.register_schema(
                    name=fxv.WIRE_SCHEMA, encoding="ros2msg", data=fxv.WIRE_MSGDEF.encode())
        else:
            sid = self._schemas.get(ros_type)
            if sid is None:
                sid = self._writer.register_schema(name=ros_type, encoding="", data=b"")
                self._schemas[ros_type] = sid
        try:
            decoded = msgpack.unpackb(body, raw=False)
            frame = decoded.get("header", {}).get("frame_id") if isinstance(decoded, dict) else None
            if isinstance(frame, str):
                meta["frame_id"] = frame
        except Exception:
            pass
        try:
            env = msgpack.unpackb(envelope, raw=False) if envelope else None
            if isinstance(env, dict):
                meta["envelope_keys"] = ",".join(str(k) for k in env)
        except Exception:
            pass
        if self._views is not None:
            meta.update({"sensorium.topic": topic, "sensorium.type": ros_type})
            cid = self._writer.register_channel(topic=fxv.WIRE_PREFIX + topic, message_encoding="cdr",
                                                schema_id=sid, metadata=meta)
        else:
            cid = self._writer.register_channel(topic=topic, message_encoding=MESSAGE_ENCODING,
                                                schema_id=sid, metadata=meta)
        self._channels[topic] = cid
        return cid

    # -- life cycle ---------------------------------------------------------------------------
    def _flush_locked(self, now: float) -> None:
        self._writer.flush()
        self._last_flush = now
        self._dirty = False

    def flush(self) -> None:
        """Write the chunk in progress now (it becomes readable even if the process dies)."""
        with self._lock:
            if not self._closed:
                self._flush_locked(time.monotonic())

    def maybe_flush(self) -> None:
        """Flush if messages have waited longer than ``flush_interval``: call it when idle (no
        message for a while), so the last messages before a pause reach the disk too."""
        if not self._dirty or self._flush_interval is None:
            return
        with self._lock:
            now = time.monotonic()
            if not self._closed and self._dirty and now - self._last_flush >= self._flush_interval:
                self._flush_locked(now)

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        with self._lock:
            if not self._closed:
                self._writer.add_metadata(name, {str(k): str(v) for k, v in data.items()})

    def close(self) -> None:
        """Finish the file (summary, indexes, footer). Idempotent."""
        self._wake.set()
        with self._lock:
            if self._closed:
                return
            self._closed = True
            try:
                end = time.time()
                self._writer.add_metadata("session_end", {
                    "ended_at": _dt.datetime.fromtimestamp(end, _dt.timezone.utc).isoformat(),
                    "wall_duration_s": f"{end - self._started_wall:.3f}",
                    "messages": str(self.message_count)})
                self._writer.finish()
                self._stream.fsync()
            finally:
                self._stream.close()

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> McapRecorder:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def recorder_for_server(path: str | os.PathLike, core: Any, topics: list[str] | None = None,
                        chunk_size: int = DEFAULT_CHUNK_SIZE, foxglove: bool = True) -> McapRecorder:
    """``sensorium serve --record``: a recorder for ``core`` (``sensorium.server.daemon.services.Core``)
    with the world file (and its meshes) attached and seed/time step/version as metadata, already
    hooked into ``core.topics``. Without ``topics`` every topic is computed and recorded."""
    sim = core.sim
    loaded = getattr(sim, "loaded", None)
    source = str(getattr(loaded, "source", "") or "")
    text = getattr(loaded, "text", b"") or b""
    if not text and source and Path(source).is_file():
        text = Path(source).read_bytes()
    meta = {"world": str(getattr(core, "world_name", "") or ""), "seed": str(getattr(sim, "seed", "")),
            "basic_time_step_ms": str(getattr(sim, "basic_time_step", "")),
            "precision": str(getattr(getattr(sim, "precision", None), "value", getattr(sim, "precision", "")))}
    rec = McapRecorder(path, text, Path(source).name if source and source != "<memory>" else "world.yaml", meta,
                       topics, chunk_size, session={"mode": "server", "world_path": source},
                       world=getattr(sim, "world", None), base_dir=getattr(loaded, "base_dir", "."),
                       foxglove=foxglove)
    try:
        base = Path(getattr(loaded, "base_dir", "") or ".")
        seen: set[str] = set()
        for solid in getattr(sim.world, "solids", []) or []:
            geom = getattr(solid, "geometry", None)
            url = getattr(geom, "url", None)
            if getattr(geom, "type", None) == "mesh" and url and url not in seen:
                seen.add(url)
                f = base / url
                if f.is_file() and f.stat().st_size <= 64 << 20:
                    with rec._lock:
                        rec._writer.add_attachment(create_time=0, log_time=0, name=url,
                                                   media_type=_media_type(url), data=f.read_bytes())
        core.topics.set_recorder(rec)
    except BaseException:
        rec.close()
        raise
    return rec


# --------------------------------------------------------------------------------------------
# reading


@dataclass
class RecordedMessage:
    topic: str
    ros_type: str
    seq: int
    stamp_ns: int
    data: bytes  # the body exactly as published

    def envelope(self) -> bytes:
        return pack_envelope(self.ros_type, self.seq, self.stamp_ns)

    def frames(self) -> list[bytes]:
        """The three ZeroMQ frames a live server published: ``[topic\\0, envelope, body]``."""
        return [self.topic.encode() + b"\0", self.envelope(), self.data]

    def decode(self) -> Any:
        return msgpack.unpackb(self.data, raw=False)


@dataclass
class TopicInfo:
    topic: str
    ros_type: str
    encoding: str
    count: int = 0
    first_ns: int | None = None
    last_ns: int | None = None
    metadata: dict[str, str] = field(default_factory=dict)

    @property
    def rate_hz(self) -> float | None:
        if self.count < 2 or self.first_ns is None or self.last_ns is None or self.last_ns <= self.first_ns:
            return None
        return (self.count - 1) * 1e9 / (self.last_ns - self.first_ns)


def _source(topic: str, ros_type: str, encoding: str, metadata: Any) -> tuple[str, str] | None:
    """A channel that holds published bodies → (topic, ROS type); ``None`` for a Foxglove view."""
    if topic.startswith(fxv.WIRE_PREFIX) and "sensorium.topic" in metadata:
        return metadata["sensorium.topic"], metadata.get("sensorium.type", "")
    if encoding == MESSAGE_ENCODING:
        return topic, ros_type
    return None


def _body(topic: str, data: bytes) -> bytes:
    return fxv.wire_unwrap(data) if topic.startswith(fxv.WIRE_PREFIX) else data


def _sources(infos: Iterable[TopicInfo]) -> list[TopicInfo]:
    """The topics of a recording: its source channels under their topic names and ROS types."""
    out = []
    for info in infos:
        src = _source(info.topic, info.ros_type, info.encoding, info.metadata)
        if src is not None:
            info.topic, info.ros_type = src
            info.encoding = MESSAGE_ENCODING
            out.append(info)
    return out


class _Unwrap:
    """Undo the 32-bit wrap of MCAP's ``sequence`` per channel (messages come in order)."""

    def __init__(self):
        self._last: dict[int, int] = {}

    def __call__(self, channel_id: int, sequence: int) -> int:
        last = self._last.get(channel_id)
        if last is None:
            value = sequence
        else:
            base = last - (last % SEQ_MODULUS)
            value = base + sequence
            if value < last - (SEQ_MODULUS >> 1):
                value += SEQ_MODULUS
        self._last[channel_id] = value
        return value


def _has_footer(path: Path) -> bool:
    try:
        size = path.stat().st_size
        if size < 2 * len(MAGIC):
            return False
        with open(path, "rb") as f:
            f.seek(-len(MAGIC), io.SEEK_END)
            return f.read(len(MAGIC)) == MAGIC
    except OSError:
        return False


class Recording:
    """A recording opened for reading. ``truncated`` is True when the file was not finished; it is
    then read sequentially up to its last complete chunk."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self._file = open(self.path, "rb")
        head = self._file.read(len(MAGIC))
        self._file.seek(0)
        if head != MAGIC:
            self._file.close()
            raise McapError(f"{self.path}: not an MCAP file")
        self.truncated = False
        self.error: str | None = None
        self._summary = None
        self._reader: SeekingReader | None = None
        if _has_footer(self.path):
            try:
                reader = SeekingReader(self._file)
                self._summary = reader.get_summary()
                reader.get_header()
                self._reader = reader
            except Exception as exc:  # a damaged end: treat like a truncated file
                self.truncated = True
                self.error = f"{type(exc).__name__}: {exc}"
                self._summary = None
        else:
            self.truncated = True
        if self._summary is None or not self._summary.chunk_indexes:
            self._reader = None  # read sequentially (truncated, or finished without a summary)
        self._scan_cache: dict | None = None

    # ----- context
    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> Recording:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ----- sequential scan (truncated files)
    def _records(self, stats: dict | None = None) -> Iterator[Any]:
        """Every record up to the first damaged or missing one; ``stats`` receives chunk counts."""
        with open(self.path, "rb") as f:
            reader = StreamReader(f, emit_chunks=True, validate_crcs=False)
            it = reader.records
            while True:
                try:
                    record = next(it)
                    if isinstance(record, Chunk):
                        inner = breakup_chunk(record, validate_crc=record.uncompressed_crc != 0)
                        if stats is not None:
                            stats["chunks"] = stats.get("chunks", 0) + 1
                            stats.setdefault("compression", set()).add(record.compression or "none")
                        yield from inner
                        continue
                except StopIteration:
                    return
                except Exception as exc:
                    if stats is not None:
                        stats["stopped"] = type(exc).__name__ + (f": {exc}" if str(exc) else "")
                    self.truncated = True
                    return
                yield record

    def _scan(self) -> dict:
        if self._scan_cache is not None:
            return self._scan_cache
        stats: dict = {}
        header = None
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        topics: dict[int, TopicInfo] = {}
        metadata: list[Metadata] = []
        attachments: list[Attachment] = []
        complete = False
        for record in self._records(stats):
            if isinstance(record, Header):
                header = record
            elif isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
                if record.id not in topics:
                    schema = schemas.get(record.schema_id)
                    topics[record.id] = TopicInfo(record.topic, schema.name if schema else "",
                                                  record.message_encoding, metadata=dict(record.metadata))
            elif isinstance(record, Message):
                info = topics.get(record.channel_id)
                if info is None:
                    continue
                info.count += 1
                t = record.log_time
                info.first_ns = t if info.first_ns is None else min(info.first_ns, t)
                info.last_ns = t if info.last_ns is None else max(info.last_ns, t)
            elif isinstance(record, Metadata):
                metadata.append(record)
            elif isinstance(record, Attachment):
                attachments.append(record)
            elif isinstance(record, (DataEnd, Footer)):
                complete = True
        self._scan_cache = {"header": header, "topics": _sources(topics.values()), "metadata": metadata,
                            "attachments": attachments, "chunks": stats.get("chunks", 0),
                            "compression": sorted(stats.get("compression", set())),
                            "stopped": stats.get("stopped"), "complete": complete}
        return self._scan_cache

    # ----- public reading API
    def header(self) -> Header | None:
        if self._reader is not None:
            return self._reader.get_header()
        return self._scan()["header"]

    def metadata(self) -> dict[str, dict[str, str]]:
        if self._reader is not None:
            records = list(self._reader.iter_metadata())
        else:
            records = self._scan()["metadata"]
        out: dict[str, dict[str, str]] = {}
        for m in records:
            out.setdefault(m.name, {}).update(m.metadata)
        return out

    def attachments(self) -> list[Attachment]:
        if self._reader is not None:
            return list(self._reader.iter_attachments())
        return list(self._scan()["attachments"])

    def world(self) -> tuple[str, bytes] | None:
        """The attached world file, as ``(name, bytes)``."""
        atts = self.attachments()
        name = self.metadata().get("sensorium", {}).get("world_file")
        for a in atts:
            if a.name == name:
                return a.name, a.data
        return (atts[0].name, atts[0].data) if atts else None

    def topics(self) -> list[TopicInfo]:
        """One entry per channel with its count and first/last log time."""
        if self._reader is None:
            return self._scan()["topics"]
        s = self._summary
        stats = s.statistics
        infos: dict[int, TopicInfo] = {}
        for cid, ch in s.channels.items():
            schema = s.schemas.get(ch.schema_id)
            infos[cid] = TopicInfo(ch.topic, schema.name if schema else "", ch.message_encoding,
                                   count=(stats.channel_message_counts.get(cid, 0) if stats else 0),
                                   metadata=dict(ch.metadata))
        # first/last times from the message indexes (no decompression)
        for ci in s.chunk_indexes:
            for cid, offset in ci.message_index_offsets.items():
                info = infos.get(cid)
                if info is None:
                    continue
                self._file.seek(offset)
                rec = next(StreamReader(self._file, skip_magic=True).records)
                if isinstance(rec, MessageIndex) and rec.records:
                    times = [t for t, _ in rec.records]
                    lo, hi = min(times), max(times)
                    info.first_ns = lo if info.first_ns is None else min(info.first_ns, lo)
                    info.last_ns = hi if info.last_ns is None else max(info.last_ns, hi)
                    if stats is None:
                        info.count += len(rec.records)
        return _sources(infos.values())

    def messages(self, topics: Iterable[str] | Callable[[str], bool] | None = None,
                 start_ns: int | None = None, end_ns: int | None = None) -> Iterator[RecordedMessage]:
        """Stream messages in log-time order (publication order for equal times). ``topics`` is a
        ``--topics`` list (exact names, path prefixes, globs) or a predicate; ``start_ns`` and
        ``end_ns`` are inclusive bounds on the log time (simulation time)."""
        match = topics if callable(topics) else topic_matcher(topics)
        unwrap = _Unwrap()
        if self._reader is not None:
            names = []
            for ch in self._summary.channels.values():
                sch = self._summary.schemas.get(ch.schema_id)
                src = _source(ch.topic, sch.name if sch else "", ch.message_encoding, ch.metadata)
                if src is not None and match(src[0]):
                    names.append(ch.topic)
            kwargs: dict[str, Any] = {"log_time_order": True}
            try:
                it = self._reader.iter_messages(topics=names, starting_at=start_ns,
                                                ending_at=end_ns, **kwargs)
                first = next(it, None)
            except TypeError:  # mcap < 1.6: start_time inclusive, end_time exclusive
                it = self._reader.iter_messages(topics=names, start_time=start_ns,
                                                end_time=None if end_ns is None else end_ns + 1, **kwargs)
                first = next(it, None)
            if first is None:
                return
            for schema, channel, message in _chain(first, it):
                topic, ros_type = _source(channel.topic, schema.name if schema else "", channel.message_encoding,
                                          channel.metadata) or (channel.topic, "")
                yield RecordedMessage(topic, ros_type, unwrap(channel.id, message.sequence), message.log_time,
                                      _body(channel.topic, message.data))
            return
        # sequential: file order, which is publication order
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        for record in self._records():
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Message):
                ch = channels.get(record.channel_id)
                if ch is None:
                    continue
                schema = schemas.get(ch.schema_id)
                src = _source(ch.topic, schema.name if schema else "", ch.message_encoding, ch.metadata)
                if src is None or not match(src[0]):
                    continue
                t = record.log_time
                if (start_ns is not None and t < start_ns) or (end_ns is not None and t > end_ns):
                    continue
                yield RecordedMessage(src[0], src[1], unwrap(ch.id, record.sequence), t, _body(ch.topic, record.data))

    def summary(self) -> dict:
        """What ``sensorium info`` prints (also its ``--json`` form)."""
        topics = sorted(self.topics(), key=lambda t: t.topic)
        header = self.header()
        size = self.path.stat().st_size
        if self._reader is not None:
            s = self._summary
            chunks = len(s.chunk_indexes)
            compression = sorted({ci.compression or "none" for ci in s.chunk_indexes})
            stopped = None
        else:
            scan = self._scan()
            chunks, compression, stopped = scan["chunks"], scan["compression"], scan["stopped"]
        firsts = [t.first_ns for t in topics if t.first_ns is not None]
        lasts = [t.last_ns for t in topics if t.last_ns is not None]
        start = min(firsts) if firsts else None
        end = max(lasts) if lasts else None
        meta = self.metadata()
        atts = self.attachments()
        out = {
            "path": str(self.path),
            "size_bytes": size,
            "truncated": self.truncated,
            "profile": header.profile if header else None,
            "library": header.library if header else None,
            "messages": sum(t.count for t in topics),
            "start_ns": start,
            "end_ns": end,
            "duration_s": ((end - start) / 1e9) if start is not None and end is not None else 0.0,
            "chunks": chunks,
            "compression": compression,
            "topics": [{"topic": t.topic, "type": t.ros_type, "encoding": t.encoding, "count": t.count,
                        "first_ns": t.first_ns, "last_ns": t.last_ns,
                        "rate_hz": None if t.rate_hz is None else round(t.rate_hz, 6)} for t in topics],
            "metadata": meta,
            "attachments": [{"name": a.name, "media_type": a.media_type, "size_bytes": len(a.data)} for a in atts],
        }
        if self.truncated:
            out["note"] = ("the file was not finished (writer killed?); read up to its last complete chunk"
                           + (f" ({stopped or self.error})" if (stopped or self.error) else ""))
        return out


def _chain(first, rest):
    yield first
    yield from rest


def iter_messages(path: str | os.PathLike, topics=None, start_ns: int | None = None,
                  end_ns: int | None = None) -> Iterator[RecordedMessage]:
    """Stream the messages of a recording (see :meth:`Recording.messages`)."""
    with Recording(path) as rec:
        yield from rec.messages(topics, start_ns, end_ns)


def summarize(path: str | os.PathLike) -> dict:
    with Recording(path) as rec:
        return rec.summary()


# --------------------------------------------------------------------------------------------
# sensorium info FILE.mcap


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
        print(f"sensorium info: {path}: {exc}", file=sys.stderr)
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
    if session.get("started_at"):
        lines.append(("Recorded", session["started_at"]))
    for a in s["attachments"]:
        lines.append(("Attachment", f"{a['name']} ({a['media_type']}, {_human_size(a['size_bytes'])})"))
    for key, value in lines:
        print(f"{key + ':':<19}{value}")
    topics = s["topics"]
    width = max((len(t["topic"]) for t in topics), default=0)
    twidth = max((len(t["type"]) for t in topics), default=0)
    print(f"{'Topic information:':<19}{len(topics)} topic{'s' if len(topics) != 1 else ''}")
    for t in topics:
        rate = "-" if t["rate_hz"] is None else f"{t['rate_hz']:.2f} Hz"
        print(f"  Topic: {t['topic']:<{width}} | Type: {t['type']:<{twidth}} | Count: {t['count']:>7} | "
              f"Rate: {rate:>10} | Serialization Format: {t['encoding']}")
    return 0
