"""Reading recordings back (``Recording``, ``iter_messages``, ``summarize``).

``Recording`` streams messages in time order and summarises a file for ``sensorium info``. A file
whose writer died without finishing (kill -9, power loss) has no summary or footer: it is then read
sequentially up to its last complete chunk and reported as ``truncated``.
"""

from __future__ import annotations

import io
import os
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
from mcap.summary import Summary

from sensorium.server.recording import foxglove_views as fxv
from sensorium.server.recording.envelope import MAGIC, MESSAGE_ENCODING, SEQ_MODULUS, pack_envelope, topic_matcher

__all__ = ["Recording", "RecordedMessage", "TopicInfo", "iter_messages", "summarize", "McapError"]


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


def _source(topic: str, ros_type: str, encoding: str, metadata: Any) -> tuple[str, str] | None:
    """A channel that holds published bodies → (topic, ROS type); ``None`` for a Foxglove view
    (format 2 keeps the bodies in ``/sensorium/wire<topic>``, format 1 in msgpack channels)."""
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
        self._summary: Summary | None = None
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

    def _indexed(self) -> Summary:
        """The summary of a finished, indexed file (callers check ``self._reader`` first)."""
        assert self._summary is not None
        return self._summary

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
            last_good = f.tell()                # bytes read completely (header, whole chunks)
            while True:
                try:
                    record = next(it)
                    if isinstance(record, Chunk):
                        inner = breakup_chunk(record, validate_crc=record.uncompressed_crc != 0)
                        if stats is not None:
                            stats["chunks"] = stats.get("chunks", 0) + 1
                            stats.setdefault("compression", set()).add(record.compression or "none")
                        yield from inner
                        last_good = f.tell()
                        continue
                except StopIteration:
                    return
                except Exception as exc:  # noqa: BLE001 - a damaged or missing record ends the readable part
                    if stats is not None:
                        stats["stopped"] = type(exc).__name__ + (f": {exc}" if str(exc) else "")
                        stats["stopped_at"] = last_good
                    self.truncated = True
                    return
                last_good = f.tell()
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
                            "stopped": stats.get("stopped"), "stopped_at": stats.get("stopped_at"),
                            "complete": complete}
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
        s = self._indexed()
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
            summary = self._indexed()
            names = []
            for chan in summary.channels.values():
                sch = summary.schemas.get(chan.schema_id)
                src = _source(chan.topic, sch.name if sch else "", chan.message_encoding, chan.metadata)
                if src is not None and match(src[0]):
                    names.append(chan.topic)
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
            s = self._indexed()
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
                           + (f" ({stopped or self.error})" if (stopped or self.error) else "")
                           + f"; `sensorium recover {self.path.name}` rewrites it as a complete, indexed file")
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
