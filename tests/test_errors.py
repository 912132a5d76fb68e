"""Bad input gets one clear line and a non-zero exit, never a traceback, and a user's file is never
overwritten without being asked (issue 10's list, one test each)."""

from __future__ import annotations

import socket
import subprocess
import sys
from pathlib import Path

import pytest
from _recdata import make_recording

from sensorium.server.world.loader import WorldError, load_world, with_names


def cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True, timeout=timeout)


def one_line(res: subprocess.CompletedProcess, code: int = 1) -> str:
    assert res.returncode == code, (res.returncode, res.stdout, res.stderr)
    assert "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    return lines[0]


def test_serve_on_a_port_in_use():
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        line = one_line(cli("serve", "--rpc", f"tcp://127.0.0.1:{port}", "--pub", "tcp://127.0.0.1:0"))
    assert f"tcp://127.0.0.1:{port}" in line and "in use" in line


def test_replay_of_a_file_that_is_not_mcap(tmp_path: Path):
    bad = tmp_path / "notes.mcap"
    bad.write_text("hello\n")
    line = one_line(cli("replay", str(bad), "--pub", "tcp://127.0.0.1:0", "--rpc", "tcp://127.0.0.1:0"))
    assert "notes.mcap" in line and "not an MCAP file" in line
    missing = one_line(cli("replay", str(tmp_path / "none.mcap")))
    assert "none.mcap" in missing and "No such file" in missing


@pytest.mark.parametrize("command", [["record"], ["serve", "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0",
                                                  "--record"]])
def test_record_refuses_to_overwrite_without_force(tmp_path: Path, command: list[str]):
    precious = tmp_path / "precious.mcap"
    precious.write_bytes(b"my data")
    line = one_line(cli(*command, str(precious)))
    assert "precious.mcap exists already" in line and "--force" in line
    assert precious.read_bytes() == b"my data"


def test_export_of_a_truncated_recording_warns_with_how_much(tmp_path: Path):
    src = tmp_path / "run.mcap"
    make_recording(src, steps=200, chunk_size=2048)
    data = src.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])                       # the writer was killed half way
    res = cli("export", str(cut), str(tmp_path / "out.mcap"), "--ros2")
    assert res.returncode == 0, res.stderr
    warning = [ln for ln in res.stderr.splitlines() if "truncated" in ln]
    assert len(warning) == 1 and f"of its {len(data) // 2} bytes" in warning[0]
    exported = int(res.stdout.split("exported ")[1].split()[0])
    assert 0 < exported and f"exported {exported} messages, up to t=" in warning[0]
    full = cli("export", str(src), str(tmp_path / "full.mcap"), "--ros2")
    assert "truncated" not in full.stderr and exported < int(full.stdout.split("exported ")[1].split()[0])


def test_info_recognises_a_rosbag2_directory(tmp_path: Path):
    pytest.importorskip("rosbags")
    src = tmp_path / "run.mcap"
    make_recording(src, steps=20)
    bag = tmp_path / "bag"
    assert cli("export", str(src), str(bag), "--ros2").returncode == 0
    res = cli("info", str(bag))
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith(f"rosbag2   {bag}") and "/clock" in res.stdout and "rosgraph_msgs/msg/Clock" in res.stdout
    line = one_line(cli("info", str(tmp_path)))
    assert "directory without metadata.yaml" in line


def test_yaml_syntax_error_names_the_file_and_line(tmp_path: Path):
    bad = tmp_path / "broken.yaml"
    bad.write_text("world_info: {name: x}\nrobots: [name: x\n")
    with pytest.raises(WorldError) as e:
        load_world(bad)
    text = str(e.value)
    assert "<byte string>" not in text and len(text.splitlines()) == 1
    assert text.startswith(f"{bad}: line 3, column 1: not valid YAML") and "line 2, column 9" in text
    res = cli("validate", str(bad))
    assert res.returncode == 1 and "broken.yaml: line 3" in res.stdout + res.stderr


def test_validation_paths_carry_the_names(tmp_path: Path):
    world = tmp_path / "w.yaml"
    world.write_text("robots:\n  - name: ant\n  - name: scout\n    devices:\n"
                     "      - {device: Lidar, name: lidar, horizontal_resolution: 0}\n")
    with pytest.raises(WorldError) as e:
        load_world(world)
    assert "robots[1] (scout).devices[0] (lidar).horizontal_resolution" in str(e.value)
    assert with_names("solids[0].pose.translation[2]", {"solids": [{"name": "crate"}]}) == \
        "solids[0] (crate).pose.translation[2]"
    assert with_names("robots[5].name", {"robots": []}) == "robots[5].name"        # beyond the data: as is
