"""Reading recordings back (``Recording``, ``iter_messages``, ``summarize``).

``Recording`` streams messages in time order and summarises a file for ``sensorium info``. A file
whose writer died without finishing (kill -9, power loss) has no summary or footer: it is then read
in file order up to its last complete record and reported as ``truncated``. A damaged part (a chunk
whose bytes are wrong) is skipped and reported (``damaged``, ``on_damage``); the rest is read. The
records come from :mod:`.scan`, which every reader shares.
"""

from __future__ import annotations

import heapq
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import msgpack
from mcap.exceptions import McapError
from mcap.records import Attachment, Channel, ChunkIndex, Header, Message, MessageIndex, Metadata, Schema
from mcap.summary import Summary

from sensorium.server.recording import foxglove_views as fxv
from sensorium.server.recording.envelope import (
    MESSAGE_ENCODING,
    PROFILE,
    SEQ_MODULUS,
    pack_envelope,
    topic_matcher,
)
from sensorium.server.recording.scan import Damage, DamagedRecord, McapScan, ScanReport

__all__ = ["Recording", "RecordedMessage", "TopicInfo", "Damage", "iter_messages", "summarize", "McapError"]


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


class Recording:
    """A recording opened for reading.

    ``truncated`` is True when the file was not finished (no footer, or a damaged one): it is then
    read in file order up to its last complete record. ``damaged`` lists the parts that could not be
    read and were skipped (:class:`~.scan.Damage`: a chunk whose bytes are wrong, ...); each is
    also passed to ``on_damage`` once, when a reader meets it. Every reader — ``sensorium info``,
    ``replay``, ``export``, ``recover`` and this class — reads the same records (:mod:`.scan`)."""

    def __init__(self, path: str | os.PathLike, on_damage: Callable[[Damage], None] | None = None):
        self.path = Path(path)
        self._file = McapScan(self.path)            # McapError if not an MCAP file
        self.on_damage = on_damage
        self.damaged: list[Damage] = []
        self._reported: set[tuple[str, int]] = set()
        self.truncated = False
        self.error: str | None = None
        self.unnamed = 0          # messages read whose channel record was lost (nothing to name them by)
        self._summary: Summary | None = None
        try:
            self._summary = self._file.summary()
        except DamagedRecord as exc:                # a damaged end: read like a truncated file
            self.error = f"its footer or summary is damaged: {exc}"
        self.truncated = self._summary is None
        # indexed: chunks found through the summary's chunk indexes; else read in file order
        self._indexed = self._summary is not None and bool(self._summary.chunk_indexes)
        self._scan_cache: dict | None = None
        self._checked = False
        self._damaged_chunks: set[int] = set()

    def _index(self) -> Summary:
        assert self._summary is not None
        return self._summary

    # ----- context
    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> Recording:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ----- damage: reported once each
    def _report(self, damage: Damage) -> None:
        key = (damage.what, damage.offset)
        if key in self._reported:
            return
        self._reported.add(key)
        self.damaged.append(damage)
        if damage.what == "chunk":
            self._damaged_chunks.add(damage.offset)
        if self.on_damage is not None:
            self.on_damage(damage)

    def _is_view(self, channel: Channel | None) -> bool:
        """A Foxglove view channel (not a source of published bodies)."""
        if channel is None:
            return False
        schemas = self._summary.schemas if self._summary is not None else {}
        schema = schemas.get(channel.schema_id)
        return _source(channel.topic, schema.name if schema else "", channel.message_encoding,
                       channel.metadata) is None

    def _lost_in_chunk(self, ci: ChunkIndex) -> int:
        """Messages (Foxglove views not counted) in an indexed chunk, from its message indexes."""
        s = self._index()
        lost = 0
        for cid, offset in ci.message_index_offsets.items():
            if self._is_view(s.channels.get(cid)):
                continue
            try:
                lost += len(self._file.record_at(offset, MessageIndex).records)
            except DamagedRecord:
                pass
        return lost

    def _chunk_damage(self, ci: ChunkIndex, exc: DamagedRecord) -> Damage:
        return Damage(ci.chunk_start_offset, ci.chunk_length, "chunk", str(exc), self._lost_in_chunk(ci),
                      ci.message_start_time, ci.message_end_time)

    def check(self) -> list[Damage]:
        """Read every chunk once (decompressed, CRC checked) so that ``damaged`` lists every damaged
        part before anything is read; returns ``damaged``. A file read in order is scanned whole."""
        if self._checked:
            return self.damaged
        self._checked = True
        if not self._indexed:
            self._scan()
            return self.damaged
        for ci in self._index().chunk_indexes:
            try:
                self._file.chunk_at(ci.chunk_start_offset, parse=False)
            except DamagedRecord as exc:
                self._report(self._chunk_damage(ci, exc))
        self.metadata()
        self.attachments()
        return self.damaged

    # ----- sequential scan (truncated files, and recover)
    def records(self, report: ScanReport | None = None) -> Iterator[Any]:
        """Every record in file order, chunks opened, damaged parts skipped and reported; ``report``
        says where and why reading stopped. Channels and schemas the summary repeats are known from
        the start (a damaged chunk may have held their first definition)."""
        report = report if report is not None else ScanReport()
        channels: dict[int, Channel] = dict(self._summary.channels) if self._summary is not None else {}

        def counts(channel_id: int) -> bool:
            return not self._is_view(channels.get(channel_id))

        primed = self._summary is None          # the summary's schemas and channels come after the header
        for record in self._file.records(report, self._report, counts):
            if not primed and not isinstance(record, Header):
                primed = True
                yield from self._index().schemas.values()
                yield from self._index().channels.values()
            if isinstance(record, Channel):
                channels.setdefault(record.id, record)
            yield record
        if not primed:
            yield from self._index().schemas.values()
            yield from self._index().channels.values()
        if not report.complete:
            self.truncated = True

    def _scan(self) -> dict:
        if self._scan_cache is not None:
            return self._scan_cache
        report = ScanReport()
        header = None
        schemas: dict[int, Schema] = {}
        topics: dict[int, TopicInfo] = {}
        metadata: list[Metadata] = []
        attachments: list[Attachment] = []
        unnamed = 0
        for record in self.records(report):
            if isinstance(record, Message):
                info = topics.get(record.channel_id)
                if info is None:
                    unnamed += 1
                    continue
                info.count += 1
                t = record.log_time
                info.first_ns = t if info.first_ns is None else min(info.first_ns, t)
                info.last_ns = t if info.last_ns is None else max(info.last_ns, t)
            elif isinstance(record, Header):
                header = record
            elif isinstance(record, Schema):
                schemas.setdefault(record.id, record)
            elif isinstance(record, Channel):
                if record.id not in topics:
                    schema = schemas.get(record.schema_id)
                    topics[record.id] = TopicInfo(record.topic, schema.name if schema else "",
                                                  record.message_encoding, metadata=dict(record.metadata))
            elif isinstance(record, Metadata):
                metadata.append(record)
            elif isinstance(record, Attachment):
                attachments.append(record)
        self.unnamed = max(self.unnamed, unnamed)
        channels = sorted({info.topic for info in topics.values()})       # before _sources renames them
        self._scan_cache = {"header": header, "topics": _sources(topics.values()), "metadata": metadata,
                            "attachments": attachments, "chunks": report.chunks,
                            "compression": sorted(report.compression), "stopped": report.stopped,
                            "stopped_at": report.readable_bytes, "complete": report.complete,
                            "channels": channels}
        self._checked = True
        return self._scan_cache

    # ----- public reading API
    def header(self) -> Header | None:
        if self._indexed:
            return self._file.header()
        return self._scan()["header"]

    def foreign(self) -> str | None:
        """Why this MCAP file is no Sensorium recording, or None: another profile and channels, but
        none of published bodies (a ROS 2 bag: replay and export would read 0 messages from it)."""
        header = self.header()
        profile = header.profile if header is not None else ""
        channels = self.channel_topics()
        if profile == PROFILE or not channels or self.topics():
            return None
        return (f"{self.path} is not a Sensorium recording (MCAP profile {profile!r}; channels "
                f"{', '.join(channels[:3])}{' ...' if len(channels) > 3 else ''}): it holds no published message "
                "bodies (a ROS 2 bag, such as sensorium export writes, plays with ros2 bag play or in Foxglove)")

    def _indexed_records(self, indexes: list, record: type, what: str) -> list:
        """The records an index points at (metadata or attachments), read at their offsets; a
        damaged one is reported and left out."""
        out = []
        for ix in indexes:
            try:
                out.append(self._file.record_at(ix.offset, record))
            except DamagedRecord as exc:
                self._report(Damage(ix.offset, ix.length, what, str(exc)))
        return out

    def metadata(self) -> dict[str, dict[str, str]]:
        if self._indexed:
            records = self._indexed_records(self._index().metadata_indexes, Metadata, "metadata")
        else:
            records = self._scan()["metadata"]
        out: dict[str, dict[str, str]] = {}
        for m in records:
            out.setdefault(m.name, {}).update(m.metadata)
        return out

    def attachments(self) -> list[Attachment]:
        if self._indexed:
            return self._indexed_records(self._index().attachment_indexes, Attachment, "attachment")
        return list(self._scan()["attachments"])

    def world(self) -> tuple[str, bytes] | None:
        """The attached world file, as ``(name, bytes)``."""
        atts = self.attachments()
        name = self.metadata().get("sensorium", {}).get("world_file")
        for a in atts:
            if a.name == name:
                return a.name, a.data
        return (atts[0].name, atts[0].data) if atts else None

    def channel_topics(self) -> list[str]:
        """Every channel's topic as written, Foxglove views included (``/tf``, ``/scene``, ...)."""
        if self._indexed:
            return sorted({ch.topic for ch in self._index().channels.values()})
        return self._scan()["channels"]

    def topics(self) -> list[TopicInfo]:
        """One entry per recorded topic with its count and first/last log time (the messages of
        chunks found damaged so far are not counted: :meth:`check` finds them all)."""
        if not self._indexed:
            return self._scan()["topics"]
        s = self._index()
        stats = s.statistics
        infos: dict[int, TopicInfo] = {}
        for cid, ch in s.channels.items():
            schema = s.schemas.get(ch.schema_id)
            infos[cid] = TopicInfo(ch.topic, schema.name if schema else "", ch.message_encoding,
                                   count=(stats.channel_message_counts.get(cid, 0) if stats else 0),
                                   metadata=dict(ch.metadata))
        # first/last times from the message indexes (no decompression)
        for ci in s.chunk_indexes:
            damaged = ci.chunk_start_offset in self._damaged_chunks
            for cid, offset in ci.message_index_offsets.items():
                info = infos.get(cid)
                if info is None:
                    continue
                try:
                    index = self._file.record_at(offset, MessageIndex)
                except DamagedRecord:
                    continue
                if not index.records:
                    continue
                if damaged:
                    if stats is not None:
                        info.count -= len(index.records)
                    continue
                times = [t for t, _ in index.records]
                lo, hi = min(times), max(times)
                info.first_ns = lo if info.first_ns is None else min(info.first_ns, lo)
                info.last_ns = hi if info.last_ns is None else max(info.last_ns, hi)
                if stats is None:
                    info.count += len(index.records)
        return _sources(infos.values())

    def messages(self, topics: Iterable[str] | Callable[[str], bool] | None = None,
                 start_ns: int | None = None, end_ns: int | None = None) -> Iterator[RecordedMessage]:
        """Stream messages in log-time order (publication order for equal times). ``topics`` is a
        ``--topics`` list (exact names, path prefixes, globs) or a predicate; ``start_ns`` and
        ``end_ns`` are inclusive bounds on the log time (simulation time). Damaged chunks are
        skipped (``on_damage`` is told)."""
        match = topics if callable(topics) else topic_matcher(topics)
        if self._indexed:
            yield from self._indexed_messages(match, start_ns, end_ns)
            return
        # sequential: file order, which is publication order
        unwrap = _Unwrap()
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        unnamed = 0
        for record in self.records():
            if isinstance(record, Message):
                ch = channels.get(record.channel_id)
                if ch is None:
                    unnamed += 1
                    continue
                schema = schemas.get(ch.schema_id)
                src = _source(ch.topic, schema.name if schema else "", ch.message_encoding, ch.metadata)
                if src is None or not match(src[0]):
                    continue
                t = record.log_time
                if (start_ns is not None and t < start_ns) or (end_ns is not None and t > end_ns):
                    continue
                yield RecordedMessage(src[0], src[1], unwrap(ch.id, record.sequence), t, _body(ch.topic, record.data))
            elif isinstance(record, Schema):
                schemas.setdefault(record.id, record)
            elif isinstance(record, Channel):
                channels.setdefault(record.id, record)
        self.unnamed = max(self.unnamed, unnamed)

    def _indexed_messages(self, match: Callable[[str], bool], start_ns: int | None,
                          end_ns: int | None) -> Iterator[RecordedMessage]:
        """Through the chunk indexes: chunks outside the time range are not read; chunks that
        overlap in time are merged (at most the overlapping ones are held)."""
        s = self._index()
        wanted: dict[int, tuple[str, str, str]] = {}
        for cid, chan in s.channels.items():
            sch = s.schemas.get(chan.schema_id)
            src = _source(chan.topic, sch.name if sch else "", chan.message_encoding, chan.metadata)
            if src is not None and match(src[0]):
                wanted[cid] = (src[0], src[1], chan.topic)
        if not wanted:
            return
        chunks = sorted((ci for ci in s.chunk_indexes
                         if (start_ns is None or ci.message_end_time >= start_ns)
                         and (end_ns is None or ci.message_start_time <= end_ns)
                         and (not ci.message_index_offsets or wanted.keys() & ci.message_index_offsets.keys())),
                        key=lambda ci: (ci.message_start_time, ci.chunk_start_offset))
        unwrap = _Unwrap()
        heap: list[tuple[int, int, int, Message]] = []
        i = 0
        while i < len(chunks) or heap:
            # open every chunk that may hold a message earlier than the earliest one held
            while i < len(chunks) and (not heap or chunks[i].message_start_time <= heap[0][0]):
                ci = chunks[i]
                i += 1
                try:
                    data = self._file.chunk_at(ci.chunk_start_offset)
                except DamagedRecord as exc:
                    self._report(self._chunk_damage(ci, exc))
                    continue
                for k, r in enumerate(data.records):
                    if isinstance(r, Message) and r.channel_id in wanted:
                        t = r.log_time
                        if (start_ns is None or t >= start_ns) and (end_ns is None or t <= end_ns):
                            heapq.heappush(heap, (t, ci.chunk_start_offset, k, r))
            if not heap:
                continue
            t, _o, _k, m = heapq.heappop(heap)
            topic, ros_type, channel_topic = wanted[m.channel_id]
            yield RecordedMessage(topic, ros_type, unwrap(m.channel_id, m.sequence), t, _body(channel_topic, m.data))

    def summary(self) -> dict:
        """What ``sensorium info`` prints (also its ``--json`` form). Every chunk is checked first."""
        self.check()
        topics = sorted(self.topics(), key=lambda t: t.topic)
        header = self.header()
        size = self.path.stat().st_size
        if self._indexed:
            s = self._index()
            chunks = len(s.chunk_indexes) - len(self._damaged_chunks)
            compression = sorted({ci.compression or "none" for ci in s.chunk_indexes
                                  if ci.chunk_start_offset not in self._damaged_chunks})
            stopped, readable = None, None
        else:
            scan = self._scan()
            chunks, compression, stopped, readable = (scan["chunks"], scan["compression"], scan["stopped"],
                                                      scan["stopped_at"])
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
            "readable_bytes": readable if self.truncated else size,
            "profile": header.profile if header else None,
            "library": header.library if header else None,
            "messages": sum(t.count for t in topics),
            "start_ns": start,
            "end_ns": end,
            "duration_s": ((end - start) / 1e9) if start is not None and end is not None else 0.0,
            "chunks": chunks,
            "compression": compression,
            "channels": self.channel_topics(),
            "topics": [{"topic": t.topic, "type": t.ros_type, "encoding": t.encoding, "count": t.count,
                        "first_ns": t.first_ns, "last_ns": t.last_ns,
                        "rate_hz": None if t.rate_hz is None else round(t.rate_hz, 6)} for t in topics],
            "metadata": meta,
            "attachments": [{"name": a.name, "media_type": a.media_type, "size_bytes": len(a.data)} for a in atts],
            "damaged": [d.line() for d in self.damaged],
            "unnamed_messages": self.unnamed,
            "foreign": self.foreign(),        # not a Sensorium recording: why (its messages are not counted)
        }
        if self.truncated:
            why = stopped or self.error
            out["note"] = ("the file was not finished (writer killed?); read up to its last complete record"
                           + (f" ({why})" if why else "")
                           + f"; `sensorium recover {self.path.name}` rewrites it as a complete, indexed file")
        return out


def iter_messages(path: str | os.PathLike, topics=None, start_ns: int | None = None,
                  end_ns: int | None = None) -> Iterator[RecordedMessage]:
    """Stream the messages of a recording (see :meth:`Recording.messages`)."""
    with Recording(path) as rec:
        yield from rec.messages(topics, start_ns, end_ns)


def summarize(path: str | os.PathLike) -> dict:
    with Recording(path) as rec:
        return rec.summary()
