"""Bumpers with bounding shapes of their own read over the wire by a Webots Python controller and by a
C controller (the C library built with AddressSanitizer and UBSan) against ``sensorium serve`` on
tests/worlds/create_bumpers.yaml: driven into a wall at 30° to its left, the Create-like robot's left
bumper reads 1 from the step it touches the wall, the right and rear ones 0, also once it stands
still against it; both controllers print the same lines."""

from __future__ import annotations

from pathlib import Path

import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "create_bumpers.yaml"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
# 0.2 m/s along x; the left bumper reaches 0.17 cos 10° + 0.06 sin 10° = 0.17784 m toward the wall (the
# body and the other bumpers less), so it touches it after (0.5 - 0.17784) / cos 30° = 0.3720 m: 1.86 s,
# the step ending at 1.872 s (k = 116), and stays on it (sliding, then standing still)
EXPECTED = ["0 0 0 0", "116 1 0 0", "type 0 0 0"]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "bumpers.c")


def test_a_python_controller_reads_the_left_bumper_only() -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "bumpers.py")), robot="create")
    assert lines == EXPECTED, err


def test_a_c_controller_reads_the_same(c_controller: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [c_controller], env=SAN_ENV, robot="create")
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == EXPECTED, err
