"""First-hour rough edges of the command line (issue 26): each one clear line or fixed."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(*args: str, cwd: Path | None = None, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "sensorium", *args], capture_output=True, text=True, env=env,
                          cwd=cwd, timeout=timeout)


def test_convert_takes_a_bundled_world_name(tmp_path):
    out = tmp_path / "out.yaml"
    r = run("convert", "epuck.wbt", str(out), cwd=tmp_path)               # no epuck.wbt here: the bundled one
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr and "robots:" in out.read_text()
    missing = run("convert", "nope.wbt", str(tmp_path / "x.yaml"), cwd=tmp_path)
    assert missing.returncode == 1 and "Traceback" not in missing.stderr
    assert missing.stderr.strip().splitlines() == [
        f"nope.wbt: no such file (nor a bundled world: {missing.stderr.split('bundled world: ')[1].strip()}"]
    assert "epuck.wbt" in missing.stderr


def test_pytest_says_at_the_end_which_node_tests_it_skipped_and_how_to_run_them(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT), PATH=str(Path(sys.executable).parent))   # no node on PATH
    env.pop("SENSORIUM_REQUIRE_NODE", None)
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-W", "ignore",
                        str(ROOT / "tests" / "test_foxglove_live.py"), "-k", "replay_serves"],
                       capture_output=True, text=True, env=env, cwd=ROOT, timeout=300)
    lines = [line for line in r.stdout.splitlines() if line.startswith("sensorium: ")]
    assert len(lines) == 1, r.stdout[-3000:]
    assert "1 Foxglove/Node test(s) skipped (node is not installed)" in lines[0] and "npm ci" in lines[0]
