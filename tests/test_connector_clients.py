"""Connectors and Brakes read over the wire by a Webots Python controller and by a C controller (the
C library built with AddressSanitizer and UBSan) against ``sensorium serve`` on
tests/worlds/connector.yaml: -1 before the first value, presence 1 at the first sampling period for
the connector with a passive peer 0.004 m in front of it (Webots' default distanceTolerance 0.01 m),
0 for one facing nobody, -1 for a passive one (which cannot lock), the lock state the server answers,
the last value kept after a disable; the brakes' joint types and neighbours both ways; the same lines
from both clients."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from _serve import run_controller, sensorium, serve
from test_c_client import sanitized_controller

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "connector.yaml"
PY = REPO / "tests" / "controllers" / "connector_reader.py"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
EXPECTED = ["before -1 32 0", "at16 -1 -1 -1", "at32 1 0 -1", "locked 1 0", "unlocked 0", "kept 1 0",
            "arm 0 arm arm_sensor", "slide 1 slide none", "loose 0 none none", "back arm_brake arm_brake slide_brake"]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "connector_reader.c")


def check_stderr(err: str) -> None:
    assert "not simulate" not in err and "no value" not in err, err
    assert err.count("passive connectors cannot lock") == 1, err
    assert err.count("damping constant has no effect") == 1, err          # once per brake


def test_a_python_controller_reads_presence_locks_and_brakes() -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium("controller", "--url", url, str(PY)))
    assert lines == EXPECTED
    check_stderr(err)


def test_a_c_controller_reads_the_same(c_controller: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [c_controller], env=SAN_ENV)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == EXPECTED
    check_stderr(err)


def test_sensorium_services_lists_connectors_and_brakes_as_simulated() -> None:
    with serve(WORLD, "--mode", "pause") as server:
        done = subprocess.run([sys.executable, "-m", "sensorium", "services", "--url", server.rpc, "--robot", "bot"],
                              capture_output=True, text=True, timeout=60, cwd=str(REPO))
    assert done.returncode == 0, done.stderr
    out = done.stdout
    for line in ("bot/dock (Connector):", "/bot/dock/lock", "/bot/dock/is_locked", "bot/arm brake (Brake):",
                 "/bot/arm brake/get_type"):
        assert line in out, out
    assert "not simulated" not in out, out
