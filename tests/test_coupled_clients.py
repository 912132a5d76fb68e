"""Coupled motors over the wire: a Python controller (Webots' classes) and a C controller (built
with AddressSanitizer and UBSan) command one motor of a coupled pair on tests/worlds/coupled.yaml
(grip::a, multiplier 1; grip::b, multiplier -2) and an elbow. Both read getMultiplier, their copies
of the sibling's target and velocity (libController's), Webots' warnings and the same sensor bits:
the closed forms of Webots' kinematic rule (tests/test_coupled_motors.py)."""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import pytest
from _serve import run_controller
from test_c_client import SAN_ENV, TESTS_C, sanitized_controller

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "coupled.yaml"
COUPLED_PY = REPO / "tests" / "controllers" / "coupled.py"
STEPS = 52
DT = 0.016

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def ccoupled(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, TESTS_C / "coupled.c")


def _run(argv: list[str], env: dict[str, str] | None = None) -> tuple[list[str], str]:
    return run_controller(WORLD, lambda _url: argv, env=env, robot="hand", timeout=180)


def _value(bits: str) -> float:
    return struct.unpack("<d", bytes.fromhex(bits)[::-1])[0]


def _check(lines: list[str], err: str) -> None:
    assert lines[0] == "1 -2 1 -1 1 2"         # multipliers; grip::b's limits and maxVelocity
    assert lines[1] == "0.1 -0.2 1"            # grip::b's target is -2 times grip::a's; the elbow keeps 1 rad/s
    assert err.count("Error: wb_motor_set_velocity() called with negative 'velocity' argument in position "
                     "control mode (0.1).") == 1
    rows = [dict(f.split("=") for f in line.split()[2:]) for line in lines[2:2 + STEPS]]
    for k, row in enumerate(rows, start=1):   # 0.1 / (1 rad/s · 16 ms) = 6.25 (a, elbow), 0.2 / (2 rad/s · dt): 7
        a, b, elbow = (_value(row[n]) for n in ("a", "b", "elbow"))
        if k < 7:
            assert (a, b, elbow) == (pytest.approx(k * DT, abs=1e-15), pytest.approx(-2 * k * DT, abs=1e-15),
                                     pytest.approx(k * DT, abs=1e-15)), k
        else:
            assert (a, b, elbow) == (0.1, -0.2, 0.1), k
    # grip::a's velocity 0.5 gives grip::b -1; the targets as asked (libController's copies), and
    # each motor clamps its own to its limits with Webots' warning, naming the value asked for
    assert lines[2 + STEPS] == "0.5 -1 0.8 -1.6"
    assert err.count('WARNING: RotationalMotor "grip::a": too big requested position: 0.8 > 0.5') == 1
    assert err.count('WARNING: RotationalMotor "grip::b": too low requested position: 0.8 < -1') == 1
    rows = [dict(f.split("=") for f in line.split()[2:]) for line in lines[3 + STEPS:]]
    assert len(rows) == STEPS
    for k, row in enumerate(rows, start=1):   # 0.4 / (0.5 · dt) = 0.8 / (1 · dt) = 50 steps
        a, b = _value(row["a"]), _value(row["b"])
        if k < 50:
            assert (a, b) == (pytest.approx(0.1 + 0.5 * k * DT, abs=1e-14), pytest.approx(-0.2 - k * DT, abs=1e-14)), k
        elif k > 50:
            assert (a, b) == (0.5, -1.0), k


def test_python_controller_moves_a_coupled_pair_and_reads_its_multipliers() -> None:
    lines, err = _run([sys.executable, "-m", "sensorium", "controller", str(COUPLED_PY), str(STEPS)])
    _check(lines, err)


def test_c_controller_reads_what_python_reads(ccoupled) -> None:
    c_lines, c_err = _run([ccoupled, str(STEPS)], env=SAN_ENV)
    _check(c_lines, c_err)
    py_lines, _ = _run([sys.executable, "-m", "sensorium", "controller", str(COUPLED_PY), str(STEPS)])
    assert c_lines == py_lines
