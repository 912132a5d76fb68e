"""Every README snippet runs, from a directory that is not the repository: the YAML world example
loads and its devices read sensible values, the Python blocks execute, and every `sensorium`
command line parses (the offline ones - validate, info, probe - really run)."""

from __future__ import annotations

import math
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from sensorium.cli import build_parser
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

README = Path(__file__).resolve().parents[1] / "README.md"
OFFLINE = {"validate", "info", "probe"}


def blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", README.read_text(), flags=re.S)


def command_lines() -> list[str]:
    out = []
    for block in blocks("sh"):
        for line in block.splitlines():
            line = re.sub(r"\s+#\s.*$", "", line).strip().removesuffix("&").strip()   # comments, a trailing &
            for part in line.split("&&"):
                part = part.strip()
                if part.startswith(("sensorium ", "python3 -m sensorium ")):
                    out.append(part)
    return out


def test_the_readme_has_snippets_of_each_kind():
    assert blocks("yaml") and blocks("python") and len(command_lines()) >= 20


def test_world_example_loads_and_its_devices_see_the_world(tmp_path):
    (yaml_text,) = [b for b in blocks("yaml") if b.startswith("world_info: {name: demo")]   # the world example
    import yaml

    world = parse_world(yaml.safe_load(yaml_text), source="README", base_dir=tmp_path)
    sim = Simulation(world)
    for d in sim.all_devices():
        d.enable(32)
    sim.step()
    ls, lidar = sim.device("bot/ls"), sim.device("bot/lidar")
    assert ls.value > 0                                                 # it faces the lamp
    ranges = lidar.range_image[0]
    hits = ranges[ranges < math.inf]
    # the wall, not its own body: its near face is 1.0 cos(0.3) - 0.05 m from the lidar along the
    # wall's normal (the wall is turned 0.3 rad); the nearest of 360 one-degree beams is within 1e-3 m
    assert len(hits) > 0 and hits.min() == pytest.approx(math.cos(0.3) - 0.05, abs=1e-3)


def world_blocks() -> list[str]:
    """The YAML blocks of the README's world-file sections (before "## In-process Python API")."""
    text = README.read_text().split("## In-process Python API")[0]
    return re.findall(r"```yaml\n(.*?)```", text, flags=re.S)


@pytest.mark.parametrize("index", range(len(world_blocks())))
def test_every_world_yaml_block_loads_without_a_warning(index):
    """Each YAML block of the world sections, a whole world or a fragment (a device, a list of
    devices, fog and background), loads as it is written, with nothing reset: a reader copies them."""
    import yaml

    data = yaml.safe_load(world_blocks()[index])
    if isinstance(data, dict) and "device" in data:
        data = [data]
    if isinstance(data, list):
        data = {"robots": [{"name": "r", "devices": data}]}
    loaded = parse_world(data, source="README", base_dir=README.parent / "sensorium" / "worlds")
    assert loaded.warnings == []


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_python_blocks_run_from_any_directory(tmp_path, index):
    code = blocks("python")[index].replace("tcp://127.0.0.1:5561", "tcp://127.0.0.1:1")   # no server: recv times out
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=180, cwd=tmp_path)
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize("line", command_lines())
def test_command_lines_parse_and_offline_ones_run(tmp_path, line):
    argv = shlex.split(line)
    argv = argv[3:] if argv[0] == "python3" else argv[1:]
    if any("[" in a or "..." in a or a.isupper() for a in argv):      # a synopsis: [OPTIONAL] PLACEHOLDER
        return
    if argv[0] in ("demo", "bench"):                                  # run by CI / their own tests
        build_parser().parse_args(argv)
        return
    try:
        build_parser().parse_args(argv)
    except SystemExit as exc:                                         # argparse refused the documented line
        pytest.fail(f"README command does not parse: {line} ({exc})")
    if argv[0] in OFFLINE and not any(a.startswith("my_") or a.endswith((".mcap", ".yaml")) for a in argv):
        res = subprocess.run([sys.executable, "-m", "sensorium", *argv], capture_output=True, text=True,
                             timeout=180, cwd=tmp_path)
        assert res.returncode == 0, f"{line}: {res.stderr}"
