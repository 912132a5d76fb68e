"""``sensorium recover``: a kill -9'd recording, which the standard ``mcap`` reader refuses, becomes
a complete, indexed file with every message our reader could read, byte for byte (issue 16)."""

from __future__ import annotations

import subprocess
import sys

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Message
from test_recording import _start_writer, _wait_count

from sensorium.server.recording.reader import Recording
from sensorium.server.recording.recover import default_output, recover

PY = sys.executable


def _killed_recording(tmp_path):
    path = tmp_path / "killed.mcap"
    with _start_writer(path) as proc:
        _wait_count(proc, 600)
        proc.kill()
    return path


def _standard_read(path):
    with open(path, "rb") as f:
        return [(ch.topic, m.sequence, m.log_time, m.data) for _s, ch, m in make_reader(f).iter_messages()]


def test_recover_makes_a_killed_recording_readable_by_the_standard_reader(tmp_path):
    path = _killed_recording(tmp_path)
    with pytest.raises(McapError):                      # the problem: the standard reader refuses it
        _standard_read(path)
    with Recording(path) as rec:
        assert rec.truncated
        ours = [(m.topic, m.seq, m.stamp_ns, m.data) for m in rec.messages()]
        meta, atts = rec.metadata(), [(a.name, a.data) for a in rec.attachments()]
        raw = [(r.channel_id, r.sequence, r.log_time, r.data) for r in rec.records() if isinstance(r, Message)]
    assert ours and len(raw) >= len(ours)              # raw: the msgpack sources and their Foxglove views

    out = subprocess.run([PY, "-m", "sensorium", "info", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and "sensorium recover killed.mcap" in out.stdout, out

    out = subprocess.run([PY, "-m", "sensorium", "recover", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    fixed = default_output(path)
    assert fixed.name == "killed-recovered.mcap"
    # counted as `info` counts them (published bodies), the Foxglove views apart: every message kept
    assert f"recovered {len(ours)} messages (and {len(raw) - len(ours)} Foxglove view messages)" in out.stdout

    got = _standard_read(fixed)                          # the standard reader reads every message
    assert sorted((s, ts, d) for _t, s, ts, d in got) == sorted((s, ts, d) for _c, s, ts, d in raw)
    with open(fixed, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.chunk_indexes            # indexed
        assert summary.statistics.message_count == len(raw)
    with Recording(fixed) as rec:
        assert not rec.truncated
        assert [(m.topic, m.seq, m.stamp_ns, m.data) for m in rec.messages()] == ours
        got_meta = rec.metadata()
        assert [(a.name, a.data) for a in rec.attachments()] == atts
    assert got_meta["recovered"]["truncated"] == "true" and got_meta["recovered"]["source"] == "killed.mcap"
    assert {k: v for k, v in got_meta.items() if k != "recovered"} == meta
    info = subprocess.run([PY, "-m", "sensorium", "info", str(fixed)], capture_output=True, text=True, timeout=60)
    assert "Truncated:         no" in info.stdout


def test_recover_never_overwrites_and_reports_bad_input_in_one_line(tmp_path):
    path = _killed_recording(tmp_path)
    taken = tmp_path / "taken.mcap"
    taken.write_bytes(b"precious")
    r = subprocess.run([PY, "-m", "sensorium", "recover", str(path), str(taken)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 1 and taken.read_bytes() == b"precious"
    assert r.stderr.count("\n") == 1 and "exists" in r.stderr and "Traceback" not in r.stderr
    with pytest.raises(ValueError, match="must not be the input"):
        recover(path, path, overwrite=True)
    res = recover(path, taken, overwrite=True)                        # asked for: allowed
    assert res.out == taken and _standard_read(taken)
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"not an mcap file")
    r = subprocess.run([PY, "-m", "sensorium", "recover", str(bad), str(tmp_path / "o.mcap")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and r.stderr.count("\n") == 1 and "not an MCAP file" in r.stderr
    assert not (tmp_path / "o.mcap").exists() and not (tmp_path / "o.mcap.part").exists()


class _Terminated(Exception):
    """What SIGTERM raises in this test when recover does not handle it."""


def test_sigterm_mid_recover_leaves_no_part_file(tmp_path, monkeypatch, capsys):
    """README: 'recover writes OUT.part and renames it when complete; only SIGKILL or a power loss
    can leave OUT.part behind'. SIGTERM killed recover at once and left OUT.part."""
    import argparse
    import os
    import signal

    from _recdata import make_recording

    from sensorium.cli.recording import recover_cmd
    from sensorium.server.recording import recover as recover_module

    src = tmp_path / "run.mcap"
    make_recording(src, steps=8)

    class SignalAtFirstMessage(recover_module.Writer):
        def add_message(self, *args, **kwargs):
            os.kill(os.getpid(), signal.SIGTERM)
            return super().add_message(*args, **kwargs)

    def terminated(signum, frame):
        raise _Terminated

    monkeypatch.setattr(recover_module, "Writer", SignalAtFirstMessage)
    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        assert recover_cmd(argparse.Namespace(file=str(src), out=str(tmp_path / "out.mcap"), force=False)) == 130
    finally:
        assert signal.signal(signal.SIGTERM, previous) is terminated
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.mcap"]
    assert capsys.readouterr().err.strip().splitlines() == ["sensorium recover: interrupted; nothing written"]
