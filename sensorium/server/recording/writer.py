"""Writing what a simulation publishes to MCAP (``McapRecorder``, ``recorder_for_server``).

``McapRecorder`` is called by the server from inside its step loop for every message it
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
:mod:`.foxglove_views`. Readers use only the lossless channels. ``/scene`` is written at time 0 and,
when the recorder is given the simulation's scene (``appearances``: ``serve --record``), again at the
stamp of the first message after a Supervisor changed a shape's appearance or a reset restored them.

Reading is :mod:`.reader`; constants, the envelope and topic filters are :mod:`.envelope`.
"""

from __future__ import annotations

import datetime as _dt
import os
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, cast

import msgpack
from mcap.writer import CompressionType, IndexType, Writer

from sensorium.server.recording import foxglove_views as fxv
from sensorium.server.recording.envelope import (
    DEFAULT_CHUNK_SIZE,
    MESSAGE_ENCODING,
    PROFILE,
    SEQ_MODULUS,
    library_version,
    media_type,
    topic_matcher,
)

if TYPE_CHECKING:
    from sensorium.server.recording.frames import Appearances

__all__ = ["McapRecorder", "recorder_for_server", "DEFAULT_CHUNK_SIZE"]


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


def _topic_parts(topic: str) -> dict[str, str]:
    """A device topic's channel metadata: ``/<robot>/<device>/<item>``, where a device's name may
    itself hold '/' (NAO's ``Sonar/Left``) and a robot's may not."""
    parts = [p for p in topic.split("/") if p]
    if len(parts) >= 3:
        return {"robot": parts[0], "device": "/".join(parts[1:-1])}
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
                 base_dir: str | os.PathLike = ".", on_error: Callable[[str], None] | None = None,
                 appearances: Appearances | None = None):
        self.path = Path(path)
        # a write error (disk full, file size limit) stops the recording, never the caller: one line
        # through on_error, ``failed`` says why, record() and close() return quietly from then on
        self.failed: str | None = None
        self._on_error = on_error or (lambda line: print(f"sensorium: {line}", file=sys.stderr, flush=True))
        # Foxglove views (format 2) when asked for and the extra is installed
        self.foxglove_unavailable = fxv.available() if foxglove else "not requested"
        self._views = fxv.FoxgloveViews(world, Path(base_dir)) if self.foxglove_unavailable is None else None
        self._view_schemas: dict[str, int] = {}
        self._view_channels: dict[str, int] = {}
        self._view_seq: dict[str, int] = {}
        # the shapes a Supervisor recoloured: /scene is written again when the version moves
        self._appearances = appearances if self._views is not None and world is not None else None
        self._scene_version = self._appearances.appearance_version if self._appearances is not None else 0
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
            # _WriteThrough implements the write/tell/flush subset of a binary stream that Writer uses
            self._writer = Writer(cast(IO[bytes], self._stream), chunk_size=max(1024, int(chunk_size)), compression=comp,
                                  index_types=IndexType.ALL, repeat_channels=True, repeat_schemas=True,
                                  use_chunking=True, use_statistics=True, use_summary_offsets=True,
                                  enable_crcs=True)
            self._writer.start(profile=PROFILE, library=f"sensorium {library_version()}")
            if world_text:
                data = world_text.encode() if isinstance(world_text, str) else bytes(world_text)
                self._writer.add_attachment(create_time=0, log_time=0, name=world_name or "world",
                                            media_type=media_type(world_name or ""), data=data)
            meta = {"version": library_version(), "format": "1",
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
            drawn = self._appearances.drawn_models() if self._appearances is not None else None
            scene = self._views.scene(drawn) if self._views is not None else None
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
            try:
                self._record_locked(topic, ros_type, envelope, body, stamp_ns, seq)
            except OSError as exc:
                self._fail(exc)

    __call__ = record

    def _fail(self, exc: OSError) -> None:
        """Stop recording after a write error (caller holds the lock): say so once, keep the file
        as it is (readable up to its last complete chunk)."""
        if self.failed is not None:
            return
        self.failed = exc.strerror or str(exc)
        self._closed = True
        try:
            self._stream.close()
        except OSError:
            pass
        self._on_error(f"recording to {self.path} stopped after {self.message_count} messages: {self.failed}; "
                       f"live topics are still published; the file is readable up to its last complete chunk "
                       f"(`sensorium recover {self.path}` rewrites it as a complete file)")

    def _record_locked(self, topic: str, ros_type: str, envelope: bytes, body: bytes, stamp_ns: int,
                       seq: int) -> None:
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
            looks = self._appearances
            if looks is not None and looks.appearance_version != self._scene_version:
                self._scene_version = looks.appearance_version
                scene = self._views.scene(looks.drawn_models())
                if scene is not None:
                    self._add_view(scene, stamp)
        self.counts[topic] = self.counts.get(topic, 0) + 1
        self.message_count += 1
        self._dirty = True
        if self._flush_interval is not None:
            now = time.monotonic()
            if now - self._last_flush >= self._flush_interval:
                self._flush_locked(now)

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
        try:
            self._writer.flush()
        except OSError as exc:
            self._fail(exc)
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
                try:
                    self._writer.add_metadata(name, {str(k): str(v) for k, v in data.items()})
                except OSError as exc:
                    self._fail(exc)

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
                if self._views is not None and self._views.errors:   # bodies kept; only their views missing
                    self._writer.add_metadata("foxglove_view_errors", dict(self._views.errors))
                self._writer.finish()
                self._stream.fsync()
            except OSError as exc:
                self._fail(exc)
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
                       foxglove=foxglove, appearances=getattr(sim, "scene", None))
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
                                                   media_type=media_type(url), data=f.read_bytes())
        core.topics.set_recorder(rec)
    except BaseException:
        rec.close()
        raise
    return rec
