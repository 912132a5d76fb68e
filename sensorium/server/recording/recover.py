"""``sensorium recover``: rewrite a truncated recording (writer killed, disk full) as a complete,
indexed MCAP file that any MCAP reader opens.

A recording whose writer died has no summary, no footer and usually a half-written last chunk (or
a tail of zero bytes, after a power loss): the standard ``mcap`` reader
(``make_reader(f).iter_messages()``) refuses it. :func:`recover` reads every record up to the last
complete one (:meth:`Recording.records`, the scan every reader shares, :mod:`.scan`), skipping
damaged chunks (each reported through ``on_damage``), and writes them again — header, schemas,
channels, messages with their times and sequence numbers, metadata, attachments — through the
standard writer, which adds the indexes, the summary and the footer. A record added by recovery
is a metadata record ``recovered`` (source file, whether it was truncated, where reading stopped,
what was skipped). It counts messages as ``sensorium info`` does (Foxglove views apart).

Never overwrites: the output must not exist (``overwrite=True`` to allow) and must not be the input.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO, cast

from mcap.records import Attachment, Channel, Header, Message, Metadata, Schema
from mcap.writer import CompressionType, Writer

from sensorium.server.recording.reader import Recording, _source
from sensorium.server.recording.scan import Damage, ScanReport

__all__ = ["RecoverResult", "recover", "default_output"]


@dataclass
class RecoverResult:
    out: Path
    messages: int              # as `sensorium info` counts them (published bodies)
    channels: int
    metadata: int
    attachments: int
    truncated: bool            # the input was not a finished file
    stopped: str | None        # why reading the input stopped early (None: it ended cleanly)
    views: int = 0             # Foxglove view messages (/tf, /scene, CDR copies) kept besides
    damaged: tuple[Damage, ...] = ()    # parts of the input skipped
    unnamed: int = 0           # messages dropped: their channel was defined in a damaged chunk


def default_output(path: str | os.PathLike) -> Path:
    """``run.mcap`` → ``run-recovered.mcap`` (next to it)."""
    p = Path(path)
    return p.with_name(f"{p.stem}-recovered{p.suffix or '.mcap'}")


def recover(path: str | os.PathLike, out: str | os.PathLike | None = None, *, overwrite: bool = False,
            chunk_size: int = 1 << 20, on_damage: Callable[[Damage], None] | None = None) -> RecoverResult:
    """Rewrite ``path`` into ``out`` (default :func:`default_output`), written as ``out.part`` and
    renamed when complete (nothing is left behind on failure). Raises ``FileExistsError``,
    ``ValueError`` (same file), ``OSError`` or ``McapError`` (not an MCAP file)."""
    src = Path(path)
    dst = Path(out) if out is not None else default_output(src)
    if dst.exists() and src.exists() and dst.resolve() == src.resolve():
        raise ValueError(f"{dst}: the output must not be the input")
    if dst.exists() and not overwrite:
        raise FileExistsError(f"{dst} exists (choose another output, or --force to overwrite it)")
    report = ScanReport()
    counts = {"messages": 0, "views": 0, "metadata": 0, "attachments": 0, "unnamed": 0}
    views: set[int] = set()
    with Recording(src, on_damage=on_damage) as rec:
        tmp = dst.with_name(dst.name + ".part")
        try:
            with open(tmp, "wb") as f:
                writer = Writer(cast(IO[bytes], f), chunk_size=chunk_size, compression=CompressionType.ZSTD)
                schema_ids: dict[int, int] = {}
                channel_ids: dict[int, int] = {}
                started = False
                for record in rec.records(report):
                    if isinstance(record, Header):
                        if not started:
                            writer.start(profile=record.profile, library=record.library)
                            started = True
                        continue
                    if not started:
                        writer.start(profile="", library="sensorium recover")
                        started = True
                    if isinstance(record, Schema):
                        if record.id not in schema_ids:
                            schema_ids[record.id] = writer.register_schema(record.name, record.encoding, record.data)
                    elif isinstance(record, Channel):
                        if record.id not in channel_ids:
                            if _source(record.topic, "", record.message_encoding, record.metadata) is None:
                                views.add(record.id)
                            channel_ids[record.id] = writer.register_channel(
                                record.topic, record.message_encoding, schema_ids.get(record.schema_id, 0),
                                dict(record.metadata))
                    elif isinstance(record, Message):
                        cid = channel_ids.get(record.channel_id)
                        if cid is None:
                            counts["unnamed"] += 1        # its channel record was lost: nothing to name it by
                            continue
                        writer.add_message(cid, record.log_time, record.data, record.publish_time, record.sequence)
                        counts["views" if record.channel_id in views else "messages"] += 1
                    elif isinstance(record, Metadata):
                        if record.name != "recovered":
                            writer.add_metadata(record.name, dict(record.metadata))
                            counts["metadata"] += 1
                    elif isinstance(record, Attachment):
                        writer.add_attachment(record.create_time, record.log_time, record.name, record.media_type,
                                              record.data)
                        counts["attachments"] += 1
                if not started:
                    writer.start(profile="", library="sensorium recover")
                stopped = report.stopped
                writer.add_metadata("recovered", {"source": src.name, "truncated": str(rec.truncated).lower(),
                                                  "stopped": stopped or "",
                                                  "skipped": "; ".join(d.line() for d in rec.damaged)})
                writer.finish()
            os.replace(tmp, dst)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        return RecoverResult(dst, counts["messages"], len(channel_ids), counts["metadata"], counts["attachments"],
                             rec.truncated, stopped, counts["views"], tuple(rec.damaged), counts["unnamed"])
