"""Reading the records of an MCAP file that may be damaged (:class:`McapScan`).

A recording meets the world: a writer killed mid-chunk leaves a cut last record, a power loss
leaves megabytes of zero bytes at the end, a flipped bit leaves a chunk that does not decode. The
``mcap`` library's stream reader stops (or loops, over zeros) at the first of these, and raises
whatever the damaged bytes happen to provoke (``UnicodeDecodeError``, ``MemoryError``, ...). This
module reads what can be read and says what could not:

* every record is framed by its opcode and length; a record whose body does not parse (a chunk
  whose compression name, size, compressed data or CRC is wrong) is **skipped**, reported as a
  :class:`Damage`, and reading goes on at the next record;
* a record cut by the end of the file, or a tail of zero bytes, **ends** the readable part
  (``stopped`` says why and where) — found in one step, not byte by byte;
* bytes that are no record at all (a damaged length) are skipped up to the next chunk that
  decodes completely (CRC checked), and reported as a :class:`Damage`;
* decompression is bounded by the size the chunk declares (at most ``MAX_CHUNK_BYTES``).

Readers of every kind — ``Recording`` (``info``, ``replay``, ``export``) and ``recover`` — go
through here, so they agree on what a damaged or truncated file holds. The file is mapped, not
read: a scan touches each byte once and holds one chunk at a time.
"""

from __future__ import annotations

import io
import mmap
import os
import struct
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.data_stream import ReadDataStream
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
)
from mcap.summary import Summary

__all__ = ["MAGIC", "MAX_CHUNK_BYTES", "ChunkData", "Damage", "DamagedRecord", "McapScan", "ScanReport"]

MAGIC = b"\x89MCAP0\r\n"
MAX_CHUNK_BYTES = 1 << 30          # what one chunk may decompress to (sensorium writes 1 MiB chunks)
_KNOWN = frozenset(int(op) for op in Opcode)
_COMPRESSIONS = ("", "zstd", "lz4")
_CHUNK_FIXED = 8 + 8 + 8 + 4 + 4   # start, end, uncompressed size, crc, compression name length
_U64 = struct.Struct("<Q")
_MSG = struct.Struct("<HIQQ")      # channel id, sequence, log time, publish time
_ZERO_BLOCK = bytes(1 << 20)

_NAMES = {int(op): op.name.lower().replace("_", " ") for op in Opcode}


class DamagedRecord(McapError):
    """A record whose bytes do not parse (raised inside the scan, reported as :class:`Damage`)."""


@dataclass(frozen=True)
class Damage:
    """A part of the file that could not be read and was skipped."""

    offset: int                    # where the damaged record (or the unreadable bytes) start
    length: int                    # how many bytes were skipped
    what: str                      # "chunk", "metadata", "bytes", ...
    reason: str
    messages: int | None = None    # messages lost with it, when the file's indexes say so
    start_ns: int | None = None    # their log times, when the chunk header still says so
    end_ns: int | None = None

    def line(self) -> str:
        """One line: what was skipped, where, why and what was lost."""
        lost = ""
        if self.messages is not None:
            lost = f"{self.messages:,} message{'s' if self.messages != 1 else ''}"
        if self.start_ns is not None and self.end_ns is not None and self.end_ns >= self.start_ns:
            span = f"t={self.start_ns / 1e9:.3f}..{self.end_ns / 1e9:.3f} s"
            lost = f"{lost} at {span}" if lost else f"messages at {span}"
        return (f"{self.what} at byte {self.offset:,} ({self.length:,} bytes) is damaged ({self.reason}): "
                f"skipped{' ' + lost if lost else ''}")


@dataclass
class ScanReport:
    """What a scan found, filled in as it goes."""

    size: int = 0
    readable_bytes: int = 0          # the file is readable (or skipped knowingly) up to here
    chunks: int = 0                  # chunks read intact
    compression: set[str] = field(default_factory=set)
    damaged: list[Damage] = field(default_factory=list)
    stopped: str | None = None       # why reading ended before the data section's end
    complete: bool = False           # the data section ended properly (DataEnd)


@dataclass
class ChunkData:
    """One chunk decoded: its schemas, channels and messages in file order."""

    records: list[Any]
    start_ns: int
    end_ns: int
    compression: str


class _Strict(ReadDataStream):
    """mcap's stream over a record body, refusing to read past it (the library returns short data)."""

    def read(self, length: int) -> bytes:
        data = super().read(length)
        if len(data) != length:
            raise EndOfFile()
        return data


def _parse(cls: Any, body: bytes | memoryview) -> Any:
    return cls.read(_Strict(io.BytesIO(body)))


def _message(body: memoryview) -> Message:
    if len(body) < _MSG.size:
        raise DamagedRecord(f"a message record of {len(body)} bytes is shorter than its fixed fields")
    channel_id, sequence, log_time, publish_time = _MSG.unpack_from(body)
    return Message(channel_id=channel_id, sequence=sequence, log_time=log_time, publish_time=publish_time,
                   data=bytes(body[_MSG.size:]))


def _chunk_header(body: memoryview) -> tuple[int, int, int, int, str, memoryview]:
    """(start, end, uncompressed size, crc, compression, compressed bytes) of a chunk record's body."""
    if len(body) < _CHUNK_FIXED:
        raise DamagedRecord(f"{len(body)} bytes, shorter than a chunk's fixed fields")
    start, end, usize = struct.unpack_from("<QQQ", body)
    crc, nlen = struct.unpack_from("<II", body, 24)
    if nlen > 16 or _CHUNK_FIXED + nlen + 8 > len(body):
        raise DamagedRecord(f"its compression name claims {nlen:,} bytes")
    raw = bytes(body[_CHUNK_FIXED:_CHUNK_FIXED + nlen])
    try:
        compression = raw.decode()
    except UnicodeDecodeError:
        raise DamagedRecord(f"its compression name {raw!r} is not text") from None
    if compression not in _COMPRESSIONS:
        raise DamagedRecord(f"unknown compression {compression!r}")
    at = _CHUNK_FIXED + nlen
    (dlen,) = _U64.unpack_from(body, at)
    at += 8
    if dlen != len(body) - at:
        raise DamagedRecord(f"its data claims {dlen:,} bytes where the record holds {len(body) - at:,}")
    if usize > MAX_CHUNK_BYTES:
        raise DamagedRecord(f"it claims {usize:,} bytes uncompressed (more than {MAX_CHUNK_BYTES:,})")
    return start, end, usize, crc, compression, body[at:]


def _decompress(compression: str, data: memoryview, size: int) -> bytes:
    if compression == "":
        out = bytes(data)
    elif compression == "zstd":
        import zstandard

        try:
            out = zstandard.ZstdDecompressor().decompress(data, max_output_size=size)
        except zstandard.ZstdError as exc:
            raise DamagedRecord(f"its zstd data does not decompress ({exc})") from None
    else:
        try:
            import lz4.frame
        except ImportError:                      # pragma: no cover - lz4 comes with mcap's extras
            raise DamagedRecord("lz4 compression needs the lz4 package") from None
        try:
            d = lz4.frame.LZ4FrameDecompressor()
            out = d.decompress(bytes(data), max_length=size + 1)
        except RuntimeError as exc:
            raise DamagedRecord(f"its lz4 data does not decompress ({exc})") from None
    if len(out) != size:
        raise DamagedRecord(f"it decompresses to {len(out):,} bytes, not the {size:,} it declares")
    return out


def decode_chunk(body: memoryview, parse: bool = True) -> ChunkData:
    """A chunk record's body → its records; raises :class:`DamagedRecord` if any part is wrong.
    ``parse=False`` only checks it (header, decompression, CRC) and returns no records."""
    start, end, usize, crc, compression, data = _chunk_header(body)
    raw = _decompress(compression, data, usize)
    if crc and zlib.crc32(raw) != crc:
        raise DamagedRecord("its CRC does not match its contents")
    if not parse:
        return ChunkData([], start, end, compression)
    view = memoryview(raw)
    records: list[Any] = []
    pos, n = 0, len(raw)
    try:
        while pos < n:
            if n - pos < 9:
                raise DamagedRecord(f"a record inside it is cut at byte {pos:,} of {n:,}")
            op = view[pos]
            (length,) = _U64.unpack_from(view, pos + 1)
            stop = pos + 9 + length
            if stop > n:
                raise DamagedRecord(f"a record inside it claims {length:,} bytes, more than the chunk holds")
            inner = view[pos + 9:stop]
            if op == Opcode.MESSAGE:
                records.append(_message(inner))
            elif op == Opcode.CHANNEL:
                records.append(_parse(Channel, inner))
            elif op == Opcode.SCHEMA:
                records.append(_parse(Schema, inner))
            pos = stop
    except (EndOfFile, UnicodeDecodeError, struct.error, ValueError) as exc:
        raise DamagedRecord(f"a record inside it does not parse ({_why(exc)})") from None
    return ChunkData(records, start, end, compression)


def _why(exc: BaseException) -> str:
    if isinstance(exc, EndOfFile):
        return "a field runs past the record's end"
    if isinstance(exc, UnicodeDecodeError):
        return "a string is not UTF-8"
    text = str(exc)
    return type(exc).__name__ + (f": {text[:120]}" if text else "")


_PARSERS: dict[int, Any] = {
    Opcode.HEADER: Header, Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel, Opcode.METADATA: Metadata,
    Opcode.ATTACHMENT: Attachment, Opcode.MESSAGE_INDEX: MessageIndex, Opcode.DATA_END: DataEnd,
    Opcode.FOOTER: Footer, Opcode.CHUNK_INDEX: ChunkIndex,
}


_SUMMARY: dict[int, Any] = {
    Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel, Opcode.CHUNK_INDEX: ChunkIndex,
    Opcode.ATTACHMENT_INDEX: AttachmentIndex, Opcode.METADATA_INDEX: MetadataIndex, Opcode.STATISTICS: Statistics,
}
_FOOTER_RECORD = 9 + 8 + 8 + 4     # opcode, length, summary start, summary offset start, crc


class McapScan:
    """A mapped MCAP file. :meth:`records` walks the data section robustly; :meth:`chunk_at` reads
    one chunk by its offset (the indexed path). Raises ``McapError`` if the file is not MCAP."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        with open(self.path, "rb") as f:
            self.size = os.fstat(f.fileno()).st_size
            if self.size < len(MAGIC) or f.read(len(MAGIC)) != MAGIC:
                raise McapError(f"{self.path}: not an MCAP file")
            self._map = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
        self._view = memoryview(self._map)

    def close(self) -> None:
        view, self._view = self._view, memoryview(b"")
        try:
            view.release()
            self._map.close()
        except BufferError:         # a suspended reader still holds a slice: the map goes with it
            pass

    def __enter__(self) -> McapScan:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # ----- one record

    def _frame(self, pos: int) -> tuple[int, int] | None:
        """(opcode, end) of the record at ``pos``, or None if its length runs past the file."""
        if self.size - pos < 9:
            return None
        op = self._view[pos]
        (length,) = _U64.unpack_from(self._view, pos + 1)
        end = pos + 9 + length
        return (op, end) if end <= self.size else None

    def chunk_at(self, offset: int, parse: bool = True) -> ChunkData:
        """The chunk whose record starts at ``offset`` (from a chunk index); ``parse=False``: only
        check it."""
        frame = self._frame(offset) if 0 <= offset < self.size else None
        if frame is None or frame[0] != Opcode.CHUNK:
            raise DamagedRecord("no chunk record where the file's index says one starts")
        return decode_chunk(self._view[offset + 9:frame[1]], parse)

    def chunk_times(self, offset: int) -> tuple[int, int] | None:
        """The message time range a chunk's header declares (None if unreadable)."""
        if self.size - offset < 9 + 16:
            return None
        return struct.unpack_from("<QQ", self._view, offset + 9)

    def record_at(self, offset: int, cls: Any) -> Any:
        """The record of type ``cls`` at ``offset`` (metadata, attachment, message index)."""
        frame = self._frame(offset) if 0 <= offset < self.size else None
        if frame is None:
            raise DamagedRecord("the record runs past the end of the file")
        try:
            return _parse(cls, self._view[offset + 9:frame[1]])
        except (EndOfFile, UnicodeDecodeError, struct.error, ValueError) as exc:
            raise DamagedRecord(_why(exc)) from None

    def header(self) -> Header | None:
        """The header record (None if damaged)."""
        try:
            return self.record_at(len(MAGIC), Header)
        except DamagedRecord:
            return None

    def summary(self) -> Summary | None:
        """The summary section of a finished file (empty if it has none), or None when the file has
        no footer (not finished). Raises :class:`DamagedRecord` if the footer or summary is damaged."""
        at = self.size - len(MAGIC) - _FOOTER_RECORD
        if at < len(MAGIC) or self._view[self.size - len(MAGIC):] != MAGIC:
            return None
        if self._view[at] != Opcode.FOOTER:
            raise DamagedRecord("the file ends in MCAP's magic bytes without a footer before them")
        footer = self.record_at(at, Footer)
        if footer.summary_start == 0:
            return Summary()
        if not len(MAGIC) <= footer.summary_start <= at:
            raise DamagedRecord(f"the footer places the summary at byte {footer.summary_start:,}, "
                                f"outside the file's {self.size:,} bytes")
        summary = Summary()
        pos = footer.summary_start
        while pos < at:
            frame = self._frame(pos)
            if frame is None or frame[1] > at:
                raise DamagedRecord(f"the summary record at byte {pos:,} runs past the footer")
            op, end = frame
            cls = _SUMMARY.get(op)
            if cls is not None:
                record = self.record_at(pos, cls)
                if isinstance(record, Schema):
                    summary.schemas[record.id] = record
                elif isinstance(record, Channel):
                    summary.channels[record.id] = record
                elif isinstance(record, ChunkIndex):
                    summary.chunk_indexes.append(record)
                elif isinstance(record, AttachmentIndex):
                    summary.attachment_indexes.append(record)
                elif isinstance(record, MetadataIndex):
                    summary.metadata_indexes.append(record)
                elif isinstance(record, Statistics):
                    summary.statistics = record
            pos = end
        return summary

    # ----- the data section, in order

    def records(self, report: ScanReport | None = None,
                on_damage: Callable[[Damage], None] | None = None,
                channel_names: Callable[[int], bool] | None = None) -> Iterator[Any]:
        """Every record of the data section in file order, chunks opened (their schemas, channels
        and messages in place of the chunk). Damage is skipped and reported; the scan ends at the
        data section's end, at a cut record or at a zero-filled tail (``report.stopped``).
        ``channel_names(id)``: which channels' messages count as lost in a damaged chunk (default all)."""
        report = report if report is not None else ScanReport()
        report.size = self.size
        view = self._view
        pos = len(MAGIC)
        pending: Damage | None = None       # a damaged chunk whose message indexes may follow

        def flush_pending() -> None:
            nonlocal pending
            if pending is not None:
                report.damaged.append(pending)
                if on_damage is not None:
                    on_damage(pending)
                pending = None

        while True:
            report.readable_bytes = pos
            if pos >= self.size:
                flush_pending()
                if not report.complete and report.stopped is None:
                    report.stopped = f"the file ends at byte {pos:,} without the end of its data section"
                return
            frame = self._frame(pos)
            op = view[pos]
            if op == 0 and self._zeros_from(pos):
                flush_pending()
                report.stopped = (f"the last {self.size - pos:,} bytes (from byte {pos:,}) are zeros, "
                                  "as a power loss leaves them")
                return
            if frame is None or op == 0 or (op not in _KNOWN and op < 0x80):
                flush_pending()
                nxt = self._next_chunk(pos + 1)
                if nxt is None:
                    report.stopped = (f"the record at byte {pos:,} is cut by the end of the file"
                                      if frame is None and op in _KNOWN else
                                      f"no readable record from byte {pos:,} on")
                    return
                self._damage(report, on_damage, Damage(pos, nxt - pos, "bytes", "not a record: a damaged length "
                                                       "or opcode; reading resumed at the next chunk"))
                pos = nxt
                continue
            end = frame[1]
            if op == Opcode.MESSAGE_INDEX and pending is None:      # the file's own index: not needed here
                pos = end
                continue
            body = view[pos + 9:end]
            if op == Opcode.MESSAGE_INDEX and pending is not None:
                try:
                    index = _parse(MessageIndex, body)
                    if channel_names is None or channel_names(index.channel_id):
                        pending = Damage(pending.offset, pending.length, pending.what, pending.reason,
                                         (pending.messages or 0) + len(index.records), pending.start_ns,
                                         pending.end_ns)
                except (EndOfFile, UnicodeDecodeError, struct.error, ValueError):
                    pass
                pos = end
                continue
            flush_pending()
            if op == Opcode.CHUNK:
                try:
                    chunk = decode_chunk(body)
                except DamagedRecord as exc:
                    times = self.chunk_times(pos)
                    pending = Damage(pos, end - pos, "chunk", str(exc), None,
                                     *(times if times is not None else (None, None)))
                    pos = end
                    continue
                report.chunks += 1
                report.compression.add(chunk.compression or "none")
                pos = end
                report.readable_bytes = pos
                yield from chunk.records
                continue
            if op == Opcode.MESSAGE:
                try:
                    record = _message(body)
                except DamagedRecord as exc:
                    self._damage(report, on_damage, Damage(pos, end - pos, "message", str(exc)))
                    pos = end
                    continue
                pos = end
                yield record
                continue
            cls = _PARSERS.get(op)
            if cls is None:             # unknown (user) records, summary records: skipped as MCAP says
                pos = end
                continue
            try:
                record = _parse(cls, body)
            except (EndOfFile, UnicodeDecodeError, struct.error, ValueError) as exc:
                self._damage(report, on_damage, Damage(pos, end - pos, _NAMES.get(op, f"record 0x{op:02x}"),
                                                       _why(exc)))
                pos = end
                continue
            pos = end
            if op == Opcode.DATA_END or op == Opcode.FOOTER:
                report.readable_bytes = pos
                report.complete = True
                return
            if op in (Opcode.MESSAGE_INDEX, Opcode.CHUNK_INDEX):
                continue
            yield record

    @staticmethod
    def _damage(report: ScanReport, on_damage: Callable[[Damage], None] | None, damage: Damage) -> None:
        report.damaged.append(damage)
        if on_damage is not None:
            on_damage(damage)

    def _zeros_from(self, pos: int) -> bool:
        """Whether every byte from ``pos`` to the end is zero (compared a MiB at a time)."""
        view, size = self._view, self.size
        while pos < size:
            n = min(len(_ZERO_BLOCK), size - pos)
            if view[pos:pos + n] != _ZERO_BLOCK[:n]:
                return False
            pos += n
        return True

    def _next_chunk(self, pos: int) -> int | None:
        """The offset of the next chunk record at or after ``pos`` that decodes completely (its CRC
        checked), found with ``find`` (C speed), or None."""
        mm, op = self._map, bytes([Opcode.CHUNK])
        while True:
            at = mm.find(op, pos)
            if at < 0:
                return None
            pos = at + 1
            frame = self._frame(at)
            if frame is None or frame[1] - at < 9 + _CHUNK_FIXED:
                continue
            nlen = struct.unpack_from("<I", self._view, at + 9 + 28)[0]
            if nlen not in (0, 3, 4):
                continue
            try:
                decode_chunk(self._view[at + 9:frame[1]])
            except DamagedRecord:
                continue
            return at
