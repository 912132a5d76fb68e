"""The main job end to end: `sensorium demo` (server, two controller processes, recording, picture),
the behaviour of its example controllers, and its refusals of worlds it cannot run."""

from __future__ import annotations

import json
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sensorium.demo.summary import cells_visited, longest_stuck_s, path_length, smoothness, stuck_spans

WORLDS = Path(__file__).parent / "worlds"


def _sensorium(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True, timeout=timeout)


def test_demo_robots_behave_as_described_and_recording_replays(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    res = _sensorium("demo", "--duration", "60", "--out", str(out), "--json")
    assert res.returncode == 0, res.stderr + "".join((out / n).read_text() for n in ("server.log", "epuck.log", "scout.log")
                                                      if (out / n).exists())
    summary = json.loads(res.stdout)
    assert summary["exit_codes"] == {"server": 0, "epuck": 0, "scout": 0}
    steps = 60_000 // 32                              # --until is rounded down to whole basic steps
    assert summary["simulated_s"] == steps * 32 / 1000
    assert summary["messages"]["/clock"] == steps and summary["messages"]["/epuck/pose"] == steps
    assert summary["messages"]["/scout/lidar/laser_scan"] > 0
    # the light follower reaches the lamp (its sensors saturate ~0.45 m from it) and stays there
    assert summary["lamp_distance_start"] > 3.0
    assert summary["lamp_reached_s"] is not None and summary["lamp_reached_s"] < 35      # ~25 s in this world
    assert summary["lamp_distance_end"] < 0.6
    assert summary["lamp_distance_max_after_reached"] <= 0.6
    assert summary["light_end"] > 10 * summary["light_start"]
    # the wanderer keeps exploring: many distinct floor cells, driven distance not back-and-forth
    assert summary["cells_visited"]["scout"] >= 10                                        # of 64
    assert summary["smoothness"]["scout"] > 0.8 and summary["smoothness"]["epuck"] > 0.8
    assert summary["distance_m"]["scout"] > 6.0
    # ... and is never stuck: every 10 s window of the 60 s takes it more than 0.3 m from where the
    # window began (it used to spend the last 21 s wedged between the west wall and the glass pane)
    assert summary["longest_stuck_s"]["scout"] == 0, summary["longest_stuck_s"]
    # the picture: a real PNG of matplotlib's size
    png = (out / "arena.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", png[16:24])
    assert width > 600 and height > 600 and len(png) > 30_000
    # the recording replays: every message republished, as fast as possible
    replay = _sensorium("replay", str(out / "demo.mcap"), "--rate", "0", "--pub", "tcp://127.0.0.1:0",
                        "--rpc", "tcp://127.0.0.1:0", timeout=120)
    assert replay.returncode == 0, replay.stderr
    assert f"{sum(summary['messages'].values())} messages" in replay.stderr + replay.stdout


def test_demo_refuses_a_world_without_the_demo_robots_at_once(tmp_path: Path) -> None:
    res = _sensorium("demo", str(WORLDS / "trio.yaml"), "--out", str(tmp_path / "d"), timeout=60)
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert "trio.yaml" in lines[0] and "no robot 'epuck'" in lines[0] and "no robot 'scout'" in lines[0]
    assert "Traceback" not in res.stderr
    assert not (tmp_path / "d").exists()                # nothing started, nothing written


@pytest.mark.parametrize("text, expected", [
    ("robots: [name: x\n", "bad.yaml"),                                     # YAML syntax error
    ("world_info: {basic_time_step: -5}\n", "basic_time_step"),             # validation error
])
def test_demo_refuses_an_invalid_world_with_one_line(tmp_path: Path, text: str, expected: str) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    res = _sensorium("demo", str(bad), "--out", str(tmp_path / "d"), timeout=60)
    assert res.returncode == 1
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], res.stderr
    assert "Traceback" not in res.stderr


def test_demo_never_replaces_files_no_demo_wrote_unless_forced(tmp_path: Path) -> None:
    """`sensorium demo --out DIR` deleted DIR/demo.mcap and overwrote DIR/server.log (and the other
    logs, arena.png) whoever had written them. A previous demo's own files are still replaced."""
    out = tmp_path / "mine"
    out.mkdir()
    (out / "demo.mcap").write_text("my recording")
    (out / "server.log").write_text("my log")
    res = _sensorium("demo", "--out", str(out), "--duration", "1", timeout=60)
    assert res.returncode == 1 and res.stderr.strip().splitlines() == [
        f"sensorium demo: {out} already holds demo.mcap, server.log, not written by a demo: not overwriting "
        "(--force to replace them, or --out another folder)"]
    assert (out / "demo.mcap").read_text() == "my recording" and (out / "server.log").read_text() == "my log"
    assert sorted(p.name for p in out.iterdir()) == ["demo.mcap", "server.log"]
    forced = _sensorium("demo", "--out", str(out), "--duration", "1", "--force")
    assert forced.returncode == 0, forced.stderr
    assert (out / "demo.mcap").read_bytes().startswith(b"\x89MCAP")
    again = _sensorium("demo", "--out", str(out), "--duration", "1")          # the demo's own files: replaced
    assert again.returncode == 0, again.stderr


def test_demo_refuses_a_missing_world(tmp_path: Path) -> None:
    res = _sensorium("demo", str(tmp_path / "nope.yaml"), "--out", str(tmp_path / "d"), timeout=60)
    assert res.returncode == 1 and "nope.yaml" in res.stderr and len(res.stderr.strip().splitlines()) == 1


# ---------------------------------------------------------------------- the summary's measures

def test_path_measures_tell_exploring_from_jittering() -> None:
    t = np.arange(0, 60_000_000_000, 32_000_000, dtype=np.int64)          # 60 s of 32 ms steps
    straight = np.stack([np.linspace(-1.5, 1.5, len(t)), np.zeros(len(t))], axis=1)
    assert path_length(straight) == pytest.approx(3.0)
    assert smoothness(t, straight) == pytest.approx(1.0)
    assert cells_visited(straight) == 7                                  # x from -1.5 to 1.5 in 0.5 m cells
    # back and forth by 2 cm every step: long "driven" distance, nowhere reached
    jitter = np.stack([-1.9 + 0.02 * (np.arange(len(t)) % 2), np.zeros(len(t))], axis=1)
    assert path_length(jitter) == pytest.approx(0.02 * (len(t) - 1))
    assert smoothness(t, jitter) < 0.1
    assert cells_visited(jitter) == 1
    # a square loop of 1 m sides, once: smooth, 4 cells of 0.5 m around its corners... (closed form)
    side = np.linspace(0, 1, 100, endpoint=False)
    loop = np.concatenate([np.stack([side, 0 * side], 1), np.stack([1 + 0 * side, side], 1),
                           np.stack([1 - side, 1 + 0 * side], 1), np.stack([0 * side, 1 - side], 1)]) + 0.1
    assert path_length(loop) == pytest.approx(4.0 - 0.01)
    assert cells_visited(loop) == 8                                      # the ring of cells around [0.1, 1.1]^2


def test_demo_runs_are_reproducible(tmp_path: Path) -> None:
    """The server waits paused until both controllers are attached: two runs publish the same bytes."""
    import hashlib

    from sensorium.server.recording.reader import iter_messages

    digests = []
    for run in ("a", "b"):
        res = _sensorium("demo", "--duration", "4", "--out", str(tmp_path / run), "--json")
        assert res.returncode == 0, res.stderr
        h = hashlib.sha256()
        for m in iter_messages(tmp_path / run / "demo.mcap"):
            h.update(m.topic.encode() + m.stamp_ns.to_bytes(8, "little") + m.data)
        digests.append(h.hexdigest())
    assert digests[0] == digests[1]


def test_stuck_spans_find_every_10_s_without_progress() -> None:
    t = np.arange(0, 60_000_000_000, 32_000_000, dtype=np.int64)          # 60 s of 32 ms steps
    s = t / 1e9
    moving = np.stack([0.05 * s, np.zeros(len(t))], axis=1)             # 5 cm/s: 0.5 m per 10 s
    assert stuck_spans(t, moving) == [] and longest_stuck_s(t, moving) == 0.0
    # drives for 30 s, then rocks on the spot (2 cm back and forth, turning) for the last 30 s
    x = np.where(s < 30, 0.05 * s, 1.5 + 0.02 * (np.arange(len(t)) % 2))
    rocking = np.stack([x, np.zeros(len(t))], axis=1)
    (span,) = stuck_spans(t, rocking)
    # the first stuck window starts once the 10 s from its start stay within 0.3 m of it (the rocking
    # reaches 1.52 m): at 30 - (0.3 - 0.02) / 0.05 = 24.4 s
    assert span[0] == pytest.approx(24.4, abs=0.05) and span[1] == pytest.approx(s[-1], abs=0.05)
    assert longest_stuck_s(t, rocking) == pytest.approx(s[-1] - 24.4, abs=0.05)


def test_the_demo_logs_stay_readable(tmp_path: Path) -> None:
    """The example controllers printed a line per control step (~350 lines/s in fast mode); by
    default they print one per simulated second plus every change of state (all with -v)."""
    out = tmp_path / "demo"
    res = _sensorium("demo", "--duration", "20", "--out", str(out), "--json")
    assert res.returncode == 0, res.stderr
    for robot, steps in (("scout", 20_000 // 64), ("epuck", 20_000 // 32)):
        lines = (out / f"{robot}.log").read_text().splitlines()
        assert 20 <= len(lines) < steps / 4, (robot, len(lines))
