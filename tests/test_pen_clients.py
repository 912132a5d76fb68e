"""The Pen from a C controller (the C library built with AddressSanitizer and UBSan) and from a
Webots Python controller against ``sensorium serve`` (tests/worlds/pen.yaml): both switch the pen
on and off and recolour it between steps; the infra-red sensor under the pen reads the ink in
closed form, and the two languages read the same values, digit for digit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller

REPO = Path(__file__).resolve().parents[1]
CLIB = REPO / "sensorium" / "client" / "c"
WORLD = REPO / "tests" / "worlds" / "pen.yaml"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}


def reading(red: float, d: float = 0.01) -> float:
    return 1000.0 * (d + (d / (0.2 + 0.8 * red) - d))


def channel(byte: int) -> float:
    return float(np.float32(byte) / np.float32(255.0))


# 0x336699 at density 0.5 over white, then black at density 1 over that: the density caps at 1 and
# the colour keeps 0.5 / 1.5 of the blue-grey (WbPaintTexture::paint)
EXPECTED = [reading(1.0), reading(0.5 + 0.5 * channel(0x33)), reading(0.5 + 0.5 * channel(0x33)),
            reading(channel(0x33) / 3.0)]


def check(lines: list[str]) -> list[str]:
    ink = [line for line in lines if line.startswith("ink ")]
    assert [int(line.split()[1]) for line in ink] == [0, 1, 2, 3]
    got = [float(line.split()[2]) for line in ink]
    assert got == pytest.approx(EXPECTED, rel=1e-6)
    assert got[1] == got[2] and got[3] > got[1] > got[0]        # darker ink: a longer apparent distance
    return ink


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "pen_ink.c")


def test_a_c_and_a_python_controller_ink_and_read_the_same(c_controller: str) -> None:
    c_out, c_err = run_controller(WORLD, lambda url: [c_controller], env=SAN_ENV)
    assert "Sanitizer" not in c_err and "runtime error" not in c_err, c_err
    py_out, py_err = run_controller(
        WORLD, lambda url: sensorium("controller", "--url", url, str(REPO / "tests" / "controllers" / "pen_ink.py")))
    assert check(c_out) == check(py_out)                         # the same 17 digits
    assert "class Pen" in py_out
    for err in (c_err, py_err):
        assert "wb_pen_set_ink_color() called with an invalid 'density' argument (NaN)." in err
    assert "Error: wb_pen_write(): device tag 2 is 'over', a DistanceSensor" in c_err
    assert not math.isnan(EXPECTED[3])
