"""Damaged and truncated recordings (issue 28): a damaged chunk is skipped with one line saying so
and the rest is read; a cut file or a zero-filled tail (what a power loss leaves) ends the readable
part at once; every reader — ``info``, ``replay``, ``export``, ``recover`` and ``Recording`` —
reads the same messages; a failed export leaves nothing behind.

Expected messages are computed independently of our reader, with the ``mcap`` library's own
chunk decoder on the undamaged file."""

from __future__ import annotations

import os
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from _recdata import make_recording
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.reader import make_reader
from mcap.records import Chunk, Message
from mcap.stream_reader import StreamReader, breakup_chunk

from sensorium.server.recording.export import export_ros2
from sensorium.server.recording.reader import Recording, summarize
from sensorium.server.recording.recover import recover

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable
GUARD_S = 30.0        # a hang guard for a busy machine (the zero tail took 66-86 s before), not a speed claim


def cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([PY, "-m", "sensorium", *args], capture_output=True, text=True, env=env, timeout=timeout)


def chunks_of(path: Path) -> list[tuple[int, int]]:
    """(offset, end) of every chunk record, by the records' framing."""
    data = path.read_bytes()
    out, pos = [], 8
    while pos + 9 <= len(data):
        op = data[pos]
        (length,) = struct.unpack_from("<Q", data, pos + 1)
        if op == 0x06:
            out.append((pos, pos + 9 + length))
        if op in (0x0F, 0x02):          # data end, footer
            break
        pos += 9 + length
    return out


def messages_by_chunk(path: Path) -> list[list[tuple[str, int, int, bytes]]]:
    """Per chunk, in file order: (topic, sequence, log time, data) of each recorded body, with the
    mcap library's decoder (Foxglove views left out, as our readers leave them out)."""
    with open(path, "rb") as f:
        channels = make_reader(f).get_summary().channels
    out = []
    with open(path, "rb") as f:
        for record in StreamReader(f, emit_chunks=True).records:
            if isinstance(record, Chunk):
                msgs = []
                for r in breakup_chunk(record, validate_crc=True):
                    if isinstance(r, Message):
                        ch = channels[r.channel_id]
                        if "sensorium.topic" in ch.metadata:     # CDR uint8[]: encapsulation, length, body
                            (n,) = struct.unpack_from("<I", r.data, 4)
                            msgs.append((ch.metadata["sensorium.topic"], r.sequence, r.log_time, r.data[8:8 + n]))
                        elif ch.message_encoding == "msgpack":
                            msgs.append((ch.topic, r.sequence, r.log_time, r.data))
                out.append(msgs)
    return out


def flip_compression_name(src: Path, dst: Path, k: int) -> int:
    """``src`` with one byte of chunk ``k``'s compression name flipped ("zstd" → "\\x85std"); returns
    the chunk's offset."""
    data = bytearray(src.read_bytes())
    offset = chunks_of(src)[k][0]
    name_at = offset + 9 + 8 * 3 + 4 + 4
    assert data[name_at:name_at + 4] == b"zstd"
    data[name_at] ^= 0xFF
    dst.write_bytes(bytes(data))
    return offset


def ours(path: Path, **kw) -> list[tuple[str, int, int, bytes]]:
    with Recording(path, **kw) as rec:
        return [(m.topic, m.seq % (1 << 32), m.stamp_ns, m.data) for m in rec.messages()]


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    """A finished, indexed recording (format 2: bodies and Foxglove views) of about 12 chunks."""
    path = tmp_path_factory.mktemp("damaged") / "run.mcap"
    make_recording(path, steps=120, chunk_size=16384)
    assert 10 <= len(chunks_of(path)) <= 16
    return path


# ------------------------------------------------------------------------------------ a damaged chunk


@pytest.mark.parametrize("k", [0, 5])          # chunk 0 also holds the first definition of every channel
def test_a_chunk_with_a_flipped_byte_is_skipped_and_said_and_the_rest_is_read(tmp_path, finished, k):
    per_chunk = messages_by_chunk(finished)
    damaged = tmp_path / "damaged.mcap"
    offset = flip_compression_name(finished, damaged, k)
    expected = sorted([m for i, msgs in enumerate(per_chunk) if i != k for m in msgs], key=lambda m: m[2])
    seen = []
    got = ours(damaged, on_damage=seen.append)
    assert got == expected                                   # every intact chunk, in time order
    assert len(seen) == 1
    assert (seen[0].what, seen[0].offset, seen[0].messages) == ("chunk", offset, len(per_chunk[k]))
    assert "compression name" in seen[0].reason
    s = summarize(damaged)
    assert s["messages"] == len(expected) and s["truncated"] is False
    assert s["damaged"] == [seen[0].line()] and f"at byte {offset:,}" in seen[0].line()
    assert s["chunks"] == len(per_chunk) - 1


def test_every_command_skips_a_damaged_chunk_with_one_line(tmp_path, finished):
    per_chunk = messages_by_chunk(finished)
    damaged = tmp_path / "damaged.mcap"
    offset = flip_compression_name(finished, damaged, 3)
    n = sum(len(m) for m in per_chunk) - len(per_chunk[3])
    warning = f"{damaged}: chunk at byte {offset:,} "

    info = cli("info", str(damaged))
    assert info.returncode == 0 and info.stderr == "", info.stderr
    assert "Truncated:         no" in info.stdout and f"Messages:          {n}\n" in info.stdout
    assert "Damaged:           1 part skipped by every reader" in info.stdout and warning[len(str(damaged)) + 2:] in info.stdout

    replay = cli("replay", str(damaged), "--rate", "0", "--pub", "tcp://127.0.0.1:0", "--rpc", "tcp://127.0.0.1:0",
                 "--no-progress")
    assert replay.returncode == 0 and "Traceback" not in replay.stderr, replay.stderr
    lines = replay.stderr.splitlines()
    said = [line for line in lines if "damaged" in line]
    assert len(said) == 1 and said[0].startswith(f"sensorium replay: warning: {warning}"), lines
    assert f"sensorium: replay finished: {n} messages" in lines

    out = tmp_path / "out.mcap"
    export = cli("export", str(damaged), str(out), "--ros2")
    assert export.returncode == 0 and "Traceback" not in export.stderr, export.stderr
    assert sum(1 for line in export.stderr.splitlines() if warning in line) == 1
    assert f"exported {n} messages" in export.stdout
    with open(out, "rb") as f:                  # the standard reader reads the export whole
        assert sum(1 for _ in make_reader(f).iter_messages()) >= n

    fixed = tmp_path / "fixed.mcap"
    rec = cli("recover", str(damaged), str(fixed))
    assert rec.returncode == 0 and sum(1 for line in rec.stderr.splitlines() if warning in line) == 1, rec.stderr
    assert f"recovered {n} messages" in rec.stdout and "1 damaged part skipped" in rec.stdout
    assert ours(fixed) == ours(damaged)          # every intact chunk kept (0 of 12 were before)
    with open(fixed, "rb") as f:
        assert make_reader(f).get_summary().statistics.message_count > n       # bodies and their views


def test_a_truncated_file_whose_first_chunk_is_damaged_says_what_it_cannot_name(tmp_path, finished):
    """Without a summary, channels are defined only in the chunk that first used them: messages on
    them cannot be named, and the readers say so instead of counting nothing in silence."""
    chunks = chunks_of(finished)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(finished.read_bytes()[:chunks[6][1]])
    damaged = tmp_path / "damaged.mcap"
    flip_compression_name(cut, damaged, 0)
    with Recording(damaged) as rec:
        assert list(rec.messages()) == [] and rec.truncated
        s = rec.summary()
    with open(finished, "rb") as f:             # every message record of chunks 1..6 (bodies and views)
        raw = [sum(isinstance(r, Message) for r in breakup_chunk(c))
               for c in StreamReader(f, emit_chunks=True).records if isinstance(c, Chunk)]
    assert s["unnamed_messages"] == sum(raw[1:7]) > 0
    info = cli("info", str(damaged))
    assert info.returncode == 0 and f"Unnamed:           {s['unnamed_messages']} message records" in info.stdout


# ------------------------------------------------------------------------------------ cut files


def record_ends(path: Path) -> list[int]:
    """Where each record of the data section ends."""
    data = path.read_bytes()
    out, pos = [], 8
    while pos + 9 <= len(data) and data[pos] not in (0x0F, 0x02):
        (length,) = struct.unpack_from("<Q", data, pos + 1)
        pos += 9 + length
        out.append(pos)
    return out


@pytest.mark.parametrize("where", ["after a record", "inside a chunk"])
def test_a_zero_filled_tail_ends_the_readable_part_at_once(tmp_path, finished, where):
    """A power loss leaves the file's length but not its last writes: zeros from the end of the
    last write that reached the disk (the old reader took 66 s over 64 MiB of them, 9 bytes at a time)."""
    data = finished.read_bytes()
    size = len(data) * 6 // 10
    if where == "after a record":
        size = max(end for end in record_ends(finished) if end <= size)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:size])
    zeros = tmp_path / "zeros.mcap"
    with open(zeros, "wb") as f:
        f.write(cut.read_bytes())
        f.truncate(cut.stat().st_size + (64 << 20))             # 64 MiB of zeros
    t0 = time.perf_counter()
    s = summarize(zeros)
    res = recover(zeros)
    assert time.perf_counter() - t0 < GUARD_S
    assert ours(zeros) == ours(cut) and s["messages"] == summarize(cut)["messages"] == res.messages > 0
    assert s["truncated"] and "are zeros, as a power loss leaves them" in s["note"]
    assert ours(res.out) == ours(cut)


@pytest.mark.parametrize("fraction", [0.1, 0.35, 0.6, 0.85, 0.999])
def test_every_reader_of_a_cut_file_reads_up_to_its_last_complete_chunk(tmp_path, finished, fraction):
    per_chunk = messages_by_chunk(finished)
    chunks = chunks_of(finished)
    data = finished.read_bytes()
    size = int(len(data) * fraction)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[:size])
    whole = [i for i, (_o, end) in enumerate(chunks) if end <= size]
    expected = [m for i in whole for m in per_chunk[i]]
    assert ours(cut) == expected                                           # Recording
    assert summarize(cut)["messages"] == len(expected)                     # info
    res = recover(cut, tmp_path / "fixed.mcap")
    assert res.messages == len(expected) and ours(res.out) == expected     # recover
    report = export_ros2(cut, tmp_path / "out.mcap", fmt="mcap", views=False)
    assert report.messages + sum(report.skipped.values()) == len(expected)  # export
    assert report.truncated


# ------------------------------------------------------------------------------------ failures leave nothing


class Stop(Exception):
    pass


@pytest.mark.parametrize("fmt, name", [("bag", "bag"), ("mcap", "out.mcap")])
@pytest.mark.parametrize("error", [KeyboardInterrupt, OSError, Stop])
def test_a_failed_export_leaves_no_partial_output(tmp_path, finished, fmt, name, error):
    out = tmp_path / name

    def fail_midway(done: int, total: int) -> None:
        if done == 50:
            raise error("stopped midway")

    with pytest.raises(error):
        export_ros2(finished, out, fmt=fmt, progress=fail_midway)
    assert not out.exists() and list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------ random damage


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(flips=st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(1, 255)), min_size=1, max_size=6),
       cut=st.one_of(st.none(), st.floats(0.05, 1.0)))
def test_random_damage_is_read_around_never_raised(tmp_path_factory, flips, cut):
    src = tmp_path_factory.getbasetemp() / "fuzz-src.mcap"
    if not src.exists():
        make_recording(src, steps=40, chunk_size=2048)
    data = bytearray(src.read_bytes())
    for where, mask in flips:
        data[8 + int(where * (len(data) - 8))] ^= mask              # the magic stays: otherwise not MCAP
    if cut is not None:
        data = data[: max(8, int(len(data) * cut))]
    d = tmp_path_factory.mktemp("fuzz")
    path = d / "f.mcap"
    path.write_bytes(bytes(data))
    with Recording(path) as rec:
        n = sum(1 for _ in rec.messages())
        s = rec.summary()
    assert s["messages"] >= 0 and n >= 0
    res = recover(path, d / "fixed.mcap")
    with open(res.out, "rb") as f:                                   # what recover writes is a valid file
        assert sum(1 for _ in make_reader(f).iter_messages()) == res.messages + res.views
