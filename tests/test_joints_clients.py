"""Joint motors over the wire: a Python controller (Webots' classes) and a C controller (built with
AddressSanitizer and UBSan) command an arm's hinges and slider on tests/worlds/joints.yaml and read
their PositionSensors; both read the same bits, the closed forms of Webots' kinematic rule
(tests/test_joints.py), and the drive's wheel beside them reads what it always did."""

from __future__ import annotations

import math
import struct
import sys
from pathlib import Path

import pytest
from _serve import run_controller
from test_c_client import SAN_ENV, TESTS_C, sanitized_controller

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "joints.yaml"
JOINTS_PY = REPO / "tests" / "controllers" / "joints.py"
STEPS = 40
DT = 0.016

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cjoints(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, TESTS_C / "joints.c")


def _run(argv: list[str], env: dict[str, str] | None = None) -> tuple[list[str], str]:
    return run_controller(WORLD, lambda _url: argv, env=env, robot="arm", timeout=180)


def _value(bits: str) -> float:
    return struct.unpack("<d", bytes.fromhex(bits)[::-1])[0]


def _check(lines: list[str], err: str) -> None:
    # shoulder: limits, maxVelocity, maxTorque (= the available torque), acceleration -1, target at
    # its initial position; the wrist's default maxTorque, the lift's maxForce; LINEAR and
    # ROTATIONAL; the wheel has no limits
    assert lines[0] == "-0.5 0.5 1 1000 1000 -1 0 10 100 1 0 0 0"
    assert lines[1] == "2 5"                   # libController keeps the requested target
    assert err.count('WARNING: RotationalMotor "shoulder": too big requested position: 2 > 0.5') == 1
    assert lines[-1] == "reset 0.005 0.005 0"   # a reset: the joints back at their initial positions
    rows = [dict(f.split("=") for f in line.split()[2:]) for line in lines[2:-1]]
    assert len(rows) == STEPS
    wrist = 0.0
    for k, row in enumerate(rows, start=1):
        shoulder = _value(row["shoulder"])
        if k < 32:                             # 0.5 / (1 rad/s · 16 ms) = 31.25: reached at step 32
            assert shoulder == pytest.approx(k * DT, abs=1e-14), k
        else:
            assert shoulder == 0.5, k
        lift = _value(row["lift"])
        assert lift == (pytest.approx(0.005 + k * 0.05 * DT, abs=1e-15) if k < 7 else 0.01), k   # 0.005 / 0.0008: 6.25
        # acceleration 5: the speed ramps by 0.08 rad/s a step, the joint stops at its target -1
        wrist = max(wrist - min(5.0 * DT * k, 10.0) * DT, -1.0)
        assert _value(row["wrist"]) == pytest.approx(wrist, rel=1e-12), k
        assert _value(row["wheel"]) == pytest.approx(2.0 * DT * k, abs=1e-12), k


def test_python_controller_moves_the_arm_joints_and_reads_their_sensors() -> None:
    lines, err = _run([sys.executable, "-m", "sensorium", "controller", str(JOINTS_PY), str(STEPS)])
    _check(lines, err)


def test_c_controller_reads_what_python_reads(cjoints) -> None:
    c_lines, c_err = _run([cjoints, str(STEPS)], env=SAN_ENV)
    _check(c_lines, c_err)
    py_lines, _ = _run([sys.executable, "-m", "sensorium", "controller", str(JOINTS_PY), str(STEPS)])
    assert c_lines == py_lines
    assert not math.isnan(_value(dict(f.split("=") for f in c_lines[-2].split()[2:])["shoulder"]))
