"""Property tests (Hypothesis, derandomized) of round 29's new paths, each failing case found fixed with a
regression test naming it (tests/test_props_round29.py fuzzes whole worlds' numbers; this file the paths).

Batched free wheels (batched_steered.py, packets.c ``sp_constrained_twists``): random steered drives (two to
five wheels at random places, collinear or not, random radii and headings, any number of them free but one
driven, steered or not) in two or three copies, each copy steered and rolled at its own random commands:
the world is refused in one line, or every copy's pose, free wheels' rolled angles and driven wheels' angles
are its Simulation's bits at every step, with the C pass and with numpy's, every pose finite.

GPS degrees text: the Python client, the C library and the C++ class write Webots' text (its rule computed
apart) for any double: NaN, ±inf, −0, subnormals, ±180, values a hair off whole seconds, past int's range.

Display screens: see their section below."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _fuzz import example_counts
from _packets import use_packets
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_sweep18 import clib  # noqa: F401 - a fixture: our libController, built once

from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, parse_world

# ---------------------------------------------------------------- batched free wheels

def _plain(v: float) -> float:
    return v if abs(v) >= 1e-4 else 0.0            # the loader refuses magnitudes under 1e-30: no draws there


coordinate = st.sampled_from([0.0, 0.25, -0.25, 0.5]) | st.floats(-0.6, 0.6).map(_plain)


@st.composite
def steered_robots(draw) -> dict:
    """A steered drive of two to five wheels: places random (or all on the x axis: collinear), radii,
    headings and steering signs random; wheel 0 always driven, the others driven or free, each steered
    or not."""
    count = draw(st.integers(2, 5))
    collinear = draw(st.booleans())
    wheels, devices = [], []
    for i in range(count):
        place = [draw(coordinate), 0.0 if collinear else draw(coordinate)]
        wheel: dict = {"position": place, "radius": draw(st.sampled_from([0.03, 0.05]) | st.floats(0.01, 0.2))}
        if i == 0 or draw(st.booleans()):
            wheel["motor"] = f"w{i}"
        if draw(st.booleans()):
            wheel["steer"] = f"s{i}"
            sign = draw(st.sampled_from([1, -1]))
            wheel["steer_sign"] = sign
            devices.append({"device": "RotationalMotor", "name": f"s{i}", "axis": [0.0, 0.0, float(sign)],
                            "anchor": [place[0], place[1], 0.0], "max_velocity": 100.0})
        if draw(st.booleans()):
            wheel["heading"] = draw(st.sampled_from([0.0, math.pi / 2, math.pi]) | st.floats(-3.0, 3.0).map(_plain))
        wheels.append(wheel)
    return {"name": "bot", "pose": {"translation": [0.0, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.3, 0.3, 0.1]}},
            "steered_drive": {"max_wheel_speed": 20.0, "wheels": wheels}, "devices": devices}


def command_of(robot: dict, rng: np.random.Generator) -> tuple[list[float], dict[str, float]]:
    """Random rolling speeds (the motored wheels in order) and steering targets (sometimes all zero)."""
    wheels = robot["steered_drive"]["wheels"]
    speeds = [float(rng.choice([0.0, rng.uniform(-15.0, 15.0)])) for w in wheels if "motor" in w]
    zero = rng.random() < 0.3
    angles = {w["steer"]: 0.0 if zero else float(rng.uniform(-1.6, 1.6)) for w in wheels if "steer" in w}
    return speeds, angles


def batched_as_single(robot: dict, copies: int, seed: int, contact: bool, steps: int = 40) -> None:
    """The robot in ``copies`` batched copies against as many Simulations, commanded alike (random per
    copy, new commands every 10 steps): loads with a WorldError line (or BatchedError's) or is the same
    bits every step."""
    try:
        loaded = parse_world({"world_info": {"basic_time_step": 16, "contact": contact}, "robots": [robot]})
    except WorldError as e:                     # one line per refused value, each naming the source
        assert str(e) and all(line.startswith("<memory>: ") for line in str(e).splitlines()), str(e)
        return
    try:
        batched = BatchedSimulation(loaded, copies)
    except BatchedError as e:
        assert "\n" not in str(e) and str(e), str(e)
        return
    singles = [Simulation(loaded) for _ in range(copies)]
    wheels = robot["steered_drive"]["wheels"]
    motors = [w["motor"] for w in wheels if "motor" in w]
    rng = np.random.default_rng(seed)
    k = batched.steered.of[0]
    for t in range(steps):
        if t % 10 == 0:
            for c, s in enumerate(singles):
                speeds, angles = command_of(robot, rng)
                batched.steered.command(0, np.array([speeds]), copies=[c])
                for name, omega in zip(motors, speeds):
                    m = s.robot("bot").motor(name)
                    m.set_position(math.inf)
                    m.set_velocity(omega)
                for name, angle in angles.items():
                    s.robot("bot").motor(name).command(angle, 3.0, None, None)
                    batched.joints.command(0, name, position=angle, velocity=3.0, copies=[c])
        for s in singles:
            s.step()
        batched.step()
        for c, s in enumerate(singles):
            pose, got = s.robot("bot").pose, batched.pose(c, 0)
            assert np.isfinite(pose.translation).all() and np.isfinite(pose.rotation).all(), (t, c)
            assert got.translation.tobytes() == pose.translation.tobytes(), (t, c, got.translation, pose.translation)
            assert got.rotation.tobytes() == pose.rotation.tobytes(), (t, c)
            drive = s.robot("bot").drive
            for i, turned in drive.free_turned.items():
                assert np.float64(batched.steered.free_turned[c, k, i]).tobytes() == np.float64(turned).tobytes(), \
                    (t, c, i)
            for name in motors:
                col = batched.steered.column(0, name)
                assert batched.steered.angle[c, col[0], col[1]] == s.robot("bot").motor(name).position, (t, c, name)


@pytest.fixture(params=["helper", "math"])
def native(request, monkeypatch):
    """The batched simulation with the packets helper's C pass or numpy's (``SENSORIUM_PACKETS=0``)."""
    use_packets(request.param == "helper", monkeypatch)
    return request.param


@pytest.mark.parametrize("examples", example_counts(120, 4))
def test_random_steered_drives_with_free_wheels_run_in_copies_as_simulation_bit_for_bit(native, examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(steered_robots(), st.integers(2, 3), st.integers(0, 2**31), st.booleans())
    def check(robot: dict, copies: int, seed: int, contact: bool) -> None:
        batched_as_single(robot, copies, seed, contact)

    check()


# ---------------------------------------------------------------- GPS degrees text
#
# Webots' libController writes "%d° %d′ %d″" of three C (int) conversions: D of the degrees, M of
# (degrees − D)·60 and S of ((degrees − D)·60 − M)·60, each truncated toward zero in float64 (x86-64's
# INT_MIN for NaN, infinities and values past int's range). The reference below computes the rule with
# numpy's float64 and trunc, apart from the clients' code; the Python client, the C library (through ctypes,
# the caller freeing the string) and the C++ class's static method must write its text for every double.

INT_MIN = -(1 << 31)


def dms_reference(value: float) -> str:
    def c_int(x: np.float64) -> int:
        if not np.isfinite(x) or not (-2.0 ** 31 - 1.0 < x < 2.0 ** 31):
            return INT_MIN
        return int(np.trunc(x))

    d = np.float64(value)
    with np.errstate(over="ignore", invalid="ignore"):          # past int's range: inf and NaN, INT_MIN
        degrees = c_int(d)
        part = (d - np.float64(degrees)) * np.float64(60.0)
        minutes = c_int(part)
        seconds = c_int((part - np.float64(minutes)) * np.float64(60.0))
    return f"{degrees}\u00b0 {minutes}\u2032 {seconds}\u2033"


@st.composite
def near_a_whole_second(draw) -> float:
    """A coordinate a hair away from D° M′ S″ (60″ and 60′ included, either sign): where truncation
    and float64 rounding decide the text."""
    whole = draw(st.integers(0, 180)) + draw(st.integers(0, 60)) / 60.0 + draw(st.integers(0, 60)) / 3600.0
    hair = draw(st.sampled_from([0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-9, -1e-9]))
    sign = draw(st.sampled_from([1.0, -1.0]))
    return sign * (whole + hair)


degree_values = (st.floats() | near_a_whole_second()
                 | st.sampled_from([0.0, -0.0, 180.0, -180.0, 90.0, -90.0, 5e-324, -5e-324, -1e-300,
                                    2147483647.5, -2147483648.5, 2147483648.0, -2147483649.0, 1e300, -1e300,
                                    math.inf, -math.inf, math.nan, 40.66999864942021, -73.94])
                 | st.floats(-180.0, 180.0))


@pytest.mark.parametrize("examples", example_counts(4000, 4))
def test_the_python_client_writes_webots_degrees_text_for_every_double(examples: int) -> None:
    from sensorium.client import wb

    @settings(SETTINGS, max_examples=examples)
    @given(degree_values)
    def check(value: float) -> None:
        assert wb.wb_gps_convert_to_degrees_minutes_seconds(value) == dms_reference(value), value

    check()


def test_regression_the_degrees_text_of_values_at_the_edges() -> None:
    """The reference's own closed forms: −0 is 0, a tiny negative 0 everywhere, −1.5° is −1° −30′ 0″ and
    180° 180° 0′ 0″; int's end: 2147483647.5° keeps its degrees, 2147483648° is INT_MIN."""
    assert dms_reference(-0.0) == "0\u00b0 0\u2032 0\u2033"
    assert dms_reference(-1e-300) == "0\u00b0 0\u2032 0\u2033"
    assert dms_reference(-1.5) == "-1\u00b0 -30\u2032 0\u2033"
    assert dms_reference(-180.0) == "-180\u00b0 0\u2032 0\u2033"
    assert dms_reference(2147483647.5).startswith("2147483647\u00b0 30\u2032 0\u2033")
    assert dms_reference(2147483648.0).startswith("-2147483648\u00b0 ")


DMS_CPP = r"""
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <webots/GPS.hpp>
#include <webots/gps.h>
int main() {
  char line[128];
  while (std::fgets(line, sizeof line, stdin)) {
    const double value = std::strtod(line, nullptr);     /* C99's hexadecimal floats: every bit kept */
    const char *text = wb_gps_convert_to_degrees_minutes_seconds(value);
    std::cout << text << '|' << webots::GPS::convertToDegreesMinutesSeconds(value) << '\n';
    std::free((void *)text);
  }
  return 0;
}
"""


@pytest.mark.slow
def test_the_c_library_and_the_cpp_class_write_webots_degrees_text_for_every_double(tmp_path, clib) -> None:  # noqa: F811
    """Built against our libController: for 3000 doubles drawn as above (printed in C's hexadecimal, every
    bit kept) the C function's text and webots::GPS::convertToDegreesMinutesSeconds' are the reference's."""
    import subprocess

    from test_sweep18 import REPO

    if __import__("shutil").which("c++") is None:
        pytest.skip("needs a C++ compiler")
    build, libs = clib
    values: list[float] = []

    @settings(SETTINGS, max_examples=3000)
    @given(degree_values)
    def collect(value: float) -> None:
        values.append(value)

    collect()
    source = tmp_path / "dms.cpp"
    source.write_text(DMS_CPP)
    made = subprocess.run(["c++", f"-I{REPO / 'sensorium' / 'client' / 'c' / 'include'}", str(source), "-o",
                           str(tmp_path / "dms"), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert made.returncode == 0, made.stderr
    ran = subprocess.run([str(tmp_path / "dms")], input="".join(f"{float(v).hex()}\n" for v in values),
                         capture_output=True, text=True, timeout=60)
    assert ran.returncode == 0, ran.stderr
    lines = ran.stdout.splitlines()
    assert len(lines) == len(values)
    for value, line in zip(values, lines):
        want = dms_reference(value)
        assert line == f"{want}|{want}", value
