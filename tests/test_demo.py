"""The main job end to end: `sensorium demo` (server, two controller processes, recording)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path


def test_demo_light_follower_gets_closer_and_recording_replays(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    res = subprocess.run([sys.executable, "-m", "sensorium", "demo", "--duration", "20", "--out", str(out), "--json"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr + "".join((out / n).read_text() for n in ("server.log", "epuck.log", "scout.log")
                                                      if (out / n).exists())
    summary = json.loads(res.stdout)
    assert summary["exit_codes"] == {"server": 0, "epuck": 0, "scout": 0}
    assert summary["simulated_s"] == 20.0
    # the Braitenberg e-puck followed the light: nearer the lamp, brighter readings
    assert summary["lamp_distance_end"] < summary["lamp_distance_start"] - 0.5
    assert summary["light_end"] > summary["light_start"]
    assert summary["distance_m"]["epuck"] > 0.5 and summary["distance_m"]["scout"] > 0.5
    steps = 625                                       # 20 s of 32 ms basic steps
    assert summary["messages"]["/clock"] == steps and summary["messages"]["/epuck/pose"] == steps
    assert summary["messages"]["/scout/lidar/laser_scan"] > 0
    assert (out / "arena.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the recording replays: every message republished, as fast as possible
    replay = subprocess.run([sys.executable, "-m", "sensorium", "replay", str(out / "demo.mcap"), "--rate", "0",
                             "--pub", "tcp://127.0.0.1:0", "--rpc", "tcp://127.0.0.1:0"],
                            capture_output=True, text=True, timeout=120)
    assert replay.returncode == 0, replay.stderr
    assert f"{sum(summary['messages'].values())} messages" in replay.stderr + replay.stdout
