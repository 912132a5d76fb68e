"""Motion files played over the wire: a Python controller (Webots' ``Motion`` class), a C controller
(``wbu_motion_*``) and a C++ one (``webots::Motion``), both built with AddressSanitizer and UBSan,
play our own files on the leg of tests/worlds/motion.yaml. The motors' target positions at each
simulated time are the closed-form linear interpolation (forwards, in a loop with a second motion
beside it, in reverse); the hip's sensor follows; a file that is not there, a damaged one and one
naming motors the robot lacks print one line each and the controller runs on; the clients print the
same bits and the same lines."""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from _serve import run_controller
from test_c_client import CLIB, SAN_ENV, TESTS_C, _make, sanitized_controller
from test_motion import BAD, WAVE

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "motion.yaml"
PLAYER_PY = REPO / "tests" / "controllers" / "motion_player.py"
LIFT = b"#WEBOTS_MOTION,V1.0,slide\n0:0,Start,0\n0:320,Top,0.2\n"
UNKNOWN = b"#WEBOTS_MOTION,V1.0,hip,elbow,eye\n0,A,0.1,0.2,0.3\n"
NAMES = ["absent", "unknown", *sorted(BAD)]
DT = 16

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("motions")
    (d / "wave.motion").write_bytes(WAVE)
    (d / "lift.motion").write_bytes(LIFT)
    (d / "unknown.motion").write_bytes(UNKNOWN)
    for name, (data, _) in BAD.items():
        (d / f"{name}.motion").write_bytes(data)
    return d


@pytest.fixture(scope="module")
def cplayer(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, TESTS_C / "motion_player.c")


@pytest.fixture(scope="module")
def cppplayer(tmp_path_factory) -> str:
    """tests/c/motion_cpp.cpp (webots::Motion) linked to the sanitized library."""
    if sys.platform == "win32" or shutil.which("c++") is None:
        pytest.skip("needs a POSIX C++ toolchain")
    build = tmp_path_factory.mktemp("cppbuild")
    _make(f"BUILD={build}", "SANITIZE=1")
    exe = build / "motion_cpp"
    done = subprocess.run(["c++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
                           f"-I{CLIB / 'include'}", str(TESTS_C / "motion_cpp.cpp"), "-o", str(exe),
                           str(build / "libController.a"), *_make("libs").split()],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return str(exe)


def _run(argv: list[str], env: dict[str, str] | None = None) -> tuple[list[str], str]:
    return run_controller(WORLD, lambda _url: argv, env=env, robot="leg", timeout=180)


def _value(bits: str) -> float:
    return struct.unpack("<d", struct.pack("<Q", int(bits, 16)))[0]


def hip(e: int) -> float:
    e = min(max(e, 0), 480)
    return 0.5 * e / 160 if e <= 160 else 0.5 - 0.75 * (e - 160) / 320


def slide(e: int) -> float | None:
    """wave's slide: '*' in its first pose, so nothing up to 160 ms included."""
    return None if e <= 160 else 0.1 if e >= 480 else 0.05 + 0.05 * (e - 160) / 320


def _check(lines: list[str], err: str, folder: Path) -> None:
    assert lines[:len(NAMES)] == [f"{n} {int(n == 'unknown')}" for n in NAMES]
    assert f"Error: wbu_motion_new(): could not open '{folder}/absent.motion' file." in err
    for name, (_, what) in BAD.items():
        assert f"Error: wbu_motion_new(): file '{folder}/{name}.motion'{what}" in err
    assert (f"Warning: wbu_motion_new(): ignoring motor 'elbow' of file '{folder}/unknown.motion': robot 'leg' "
            f"has no such device.") in err
    assert f"Warning: wbu_motion_new(): ignoring 'eye' of file '{folder}/unknown.motion': it is a DistanceSensor, " \
           f"not a motor." in err
    assert "Error: wbu_motion_play() called with NULL 'motion' argument." in err
    rest = lines[len(NAMES):]
    assert rest[0] == "null 0 -1 -1"
    assert rest[1] == "wave 480 0 0"
    rows = [line.split() for line in rest[2:-1]]
    assert rest[-1] == "end 0 1 320"
    assert [r[0] for r in rows] == ["forward"] * 33 + ["loop"] * 36 + ["reverse"] * 15
    assert [int(r[1]) for r in rows] == [DT * k for k in range(1, 85)]          # the simulated time
    knee = 0.0
    slide_target = 0.0
    for k, r in enumerate(rows, start=1):
        phase, motion_time, over = r[0], int(r[2]), int(r[3])
        targets = [_value(b) for b in r[4:7]]
        if phase == "forward":            # step k sets the pose at (k - 1) dt, then moves on by dt
            e = min(DT * (k - 1), 480)
            assert (motion_time, over) == (min(DT * k, 480), int(DT * k >= 480)), k
            set_knee, set_slide = (0.2 if e <= 0 else 0.6 if e >= 480 else None), slide(e)
            # the joint follows: at most 0.05 rad a step, under 10 rad/s x 16 ms
            assert _value(r[7]) == pytest.approx(hip(e), abs=1e-12), k
        elif phase == "loop":             # wraps at the step after the end, which does not move on
            j = k - 33
            e = DT * (j - 1) if j <= 31 else DT * (j - 32)
            assert (motion_time, over) == (DT * j if j <= 30 else 0 if j == 31 else DT * (j - 31), 0), k
            set_knee = 0.2 if e <= 0 else 0.6 if e >= 480 else None
            # lift (newer, stepped first) sets the slide up to its end at 320 ms; wave (older, stepped
            # last) wins wherever it sets it
            lift = 0.2 * DT * (j - 1) / 320 if j <= 21 else None
            set_slide = slide(e) if slide(e) is not None else lift
        else:                             # reverse from 200 ms
            j = k - 69
            e = 200 - DT * (j - 1) if j <= 14 else 0
            assert (motion_time, over) == (200 - DT * j if j <= 13 else 0, int(j >= 13)), k
            set_knee, set_slide = (0.2 if e <= 0 else None), slide(e)
        knee = knee if set_knee is None else set_knee
        slide_target = slide_target if set_slide is None else set_slide
        assert targets[0] == pytest.approx(hip(e), abs=1e-15), k
        assert targets[1] == knee, k
        assert targets[2] == pytest.approx(slide_target, abs=1e-15), k


def _motion_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if "wbu_motion" in line]


def test_python_controller_plays_motion_files(folder) -> None:
    lines, err = _run([sys.executable, "-m", "sensorium", "controller", str(PLAYER_PY), str(folder), *NAMES])
    _check(lines, err, folder)


def test_c_controller_plays_them_alike(folder, cplayer) -> None:
    c_lines, c_err = _run([cplayer, str(folder), *NAMES], env=SAN_ENV)
    _check(c_lines, c_err, folder)
    py_lines, py_err = _run([sys.executable, "-m", "sensorium", "controller", str(PLAYER_PY), str(folder), *NAMES])
    assert c_lines == py_lines
    assert _motion_lines(c_err) == _motion_lines(py_err)


def test_cpp_motion_class_plays_them_alike(folder, cppplayer) -> None:
    lines, err = _run([cppplayer, str(folder)], env=SAN_ENV)
    assert lines[0] == "absent 0"
    assert f"Error: wbu_motion_new(): could not open '{folder}/absent.motion' file." in err
    py_lines, _ = _run([sys.executable, "-m", "sensorium", "controller", str(PLAYER_PY), str(folder)])
    assert lines[1:] == [line for line in py_lines if line.startswith(("wave ", "forward "))]
    assert len(lines) == 2 + 33
