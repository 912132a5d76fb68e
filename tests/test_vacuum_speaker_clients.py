"""A VacuumGripper and a Speaker used over the wire by a Webots Python controller and by a C
controller (the C library built with AddressSanitizer and UBSan) against ``sensorium serve`` on
tests/worlds/vacuum_speaker.yaml with the gripper resting on the crate: the same lines from both.
The WAV is written here (3200 frames at 32 kHz: 100 ms, so 7 steps of 16 ms); a missing and an
unreadable file give WbSpeaker's one line each and play nothing."""

from __future__ import annotations

from pathlib import Path

import pytest
from _serve import run_controller, sensorium
from test_c_client import sanitized_controller
from test_vacuum_speaker import write_wav

REPO = Path(__file__).resolve().parents[1]
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
EXPECTED = [
    "on 0", "presence off 0", "on 1", "presence on 1 16", "presence off 0 0",
    "played 7", "looping 1 1", "stopped 0 0", "bad files 0 0",
    "engine pico 0 1", "language en-US 1 0 0 fr-FR",
    "spoke 75",                        # 3 words at 0.4 s: 1.2 s = 75 steps of 16 ms
]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "vacuum_speaker.c")


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, list[str]]:
    """The world with the robot lowered onto the crate, and the controller's three file arguments."""
    world = tmp_path / "world.yaml"
    world.write_text((REPO / "tests" / "worlds" / "vacuum_speaker.yaml").read_text().replace(
        "pose: {translation: [0.0, 0.0, 0.0]}", "pose: {translation: [0.0, 0.0, -0.1]}"))
    write_wav(tmp_path / "beep.wav", 3200, 32000)
    (tmp_path / "notes.txt").write_text("not a wave\n")
    return world, [str(tmp_path / "beep.wav"), str(tmp_path / "notes.txt"), str(tmp_path / "gone.wav")]


def check(lines: list[str], err: str, args: list[str]) -> None:
    assert lines == EXPECTED, err
    assert err.count("Sound file") == 1 and f"Sound file '{args[2]}' not found." in err, err
    assert err.count("Impossible to play") == 1 and f"Impossible to play '{args[1]}'." in err, err
    assert err.count("invalid 'language' argument: \"french\"") == 1, err
    assert "not simulate" not in err and "Traceback" not in err, err


def test_a_python_controller_uses_the_gripper_and_the_speaker(files) -> None:
    world, args = files
    lines, err = run_controller(world, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "vacuum_speaker.py"), *args), robot="arm")
    check(lines, err, args)


def test_a_c_controller_gets_the_same_answers(files, c_controller: str, tmp_path: Path) -> None:
    world, args = files
    relative = [Path(a).name for a in args]          # read relative to the controller's folder, as libController
    lines, err = run_controller(world, lambda url: [c_controller, *relative], env=SAN_ENV, robot="arm", cwd=tmp_path)
    assert "Sanitizer" not in err and "runtime error" not in err, err
    check(lines, err, relative)
