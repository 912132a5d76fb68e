"""A Radar read over the wire by a Webots Python controller and by a C controller (the C library
built with AddressSanitizer and UBSan) against ``sensorium serve`` on tests/worlds/radar.yaml: the
radar's range and fields of view, no target before its first value, then each target's distance,
received power (the radar equation, by hand), radial speed (NaN at the first value: no previous
position; 0 at rest) and azimuth (Webots' sign: positive to the right), the same bits in both."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller
from test_radar import by_hand_dbm

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "radar.yaml"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "radar_reader.c")


def _bits(hexes: list[str]) -> list[float]:
    return [struct.unpack("<d", struct.pack("<Q", int(x, 16)))[0] for x in hexes]


def check(lines: list[str]) -> None:
    assert lines[0].startswith("fields ") and _bits(lines[0].split()[1:]) == [1.0, 80.0, 0.78, 0.1]
    assert lines[1] == "before 0 0 32"
    # the radar at (1, 0, 0.5): the truck 20 m ahead and 2 m right, the sign 10 m ahead and 3 m left
    truck, sign = (math.sqrt(404.0), by_hand_dbm(math.sqrt(404.0), 10.0), math.atan(0.1)), \
        (math.sqrt(109.0), by_hand_dbm(math.sqrt(109.0), 1.0), -math.atan(0.3))
    assert lines[2] == "targets 2" and lines[5] == "targets 2" and len(lines) == 8
    for k, first in ((3, True), (6, False)):
        for line, (d, p, a) in zip(lines[k:k + 2], (truck, sign)):
            dist, power, speed, azimuth = _bits(line.split()[1:])
            assert dist == pytest.approx(d, rel=1e-14) and azimuth == pytest.approx(a, rel=1e-14)
            assert power == pytest.approx(p, abs=1e-12)
            assert math.isnan(speed) if first else speed == 0.0


def test_a_python_controller_reads_the_targets() -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "radar_reader.py")))
    check(lines)
    assert "not simulate" not in err, err


def test_a_c_controller_reads_the_same_targets(c_controller: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [c_controller], env=SAN_ENV)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    check(lines)
    py, _ = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "radar_reader.py")))
    assert lines == py
