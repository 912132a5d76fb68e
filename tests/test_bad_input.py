"""Bad input to the newer devices (Speaker, Brake, Connector, VacuumGripper, coupled motors) from a
Webots Python controller and from a C controller (the C library built with AddressSanitizer and
UBSan) against ``sensorium serve`` on tests/worlds/new_devices.yaml: tests/controllers/bad_input.py
and tests/c/bad_input.c print the same lines for what both can pass, each bad value answered in one
line (Webots' where it has one) with Webots' return value, never a traceback or a sanitizer report.
Then the server stopped under a controller that has stepped (tests/controllers/after_server.py,
tests/c/after_server.c): each call that needs it is one line, the getters answer the controller's
copies, the step -1, and the setters after it keep a local state only.

The WAV is 3200 frames at 32 kHz (100 ms at pitch 1); at the greatest pitch the server takes (1e9,
where an infinite or huger one is clamped with a warning) it is over at the first step. A WAV whose
header says 3e9 frames/s (past the 2**31 the server takes) is a damaged file: WbSpeaker's "Impossible
to play" line, where the server's refusal ended the Python controller."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from _serve import Proc, run_controller, sensorium, serve
from test_c_client import SAN_ENV, sanitized_controller
from test_vacuum_speaker import write_wav

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "new_devices.yaml"
BOTH = ["nan volume 0", "nan pitch 0", "nan balance 0", "nan speak 0",
        "pitch inf 1 1", "pitch 1e+308 1 1",                 # clamped to 1e9 (a warning each): over at once
        "empty sound 0", "damaged rate 0", "empty speech 1 1", "presence 0"]
PYTHON = ["nul sound 0", "huge period INVALID_ARGUMENT True", "surrogate speech INVALID_ARGUMENT True",
          "surrogate stop INVALID_ARGUMENT True", "huge speech TOO_LARGE True", "list sound playing INVALID_ARGUMENT True", "list sound stop INVALID_ARGUMENT True",
          "still 16 0 0"]
C_TAGS = [f"tag {t}: -1 0 0 0 0 0 0 0 0 0 0 0 0 NULL NULL nan" for t in (0, 999, 9)]
C_OWN = [*C_TAGS, "nulls 0 0 0 0", "still 16 0 -2 0"]


@pytest.fixture(scope="module")
def c_controller(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "bad_input.c")


@pytest.fixture
def wavs(tmp_path: Path) -> list[str]:
    """The WAV, and one whose header says 3e9 frames/s (8 bit: its byte rate still fits the header)."""
    return [str(write_wav(tmp_path / "beep.wav", 3200, 32000)), str(write_wav(tmp_path / "fast.wav", 10, 3_000_000_000, 1))]


def check_both(err: str) -> None:
    assert "Traceback" not in err and "Sanitizer" not in err and "runtime error" not in err, err
    assert err.count("wb_speaker_play_sound() called with an invalid argument (a NULL sound or a NaN value).") >= 3, err
    assert err.count("wb_speaker_speak() called with an invalid argument (a NULL text or a NaN volume).") >= 1, err
    assert err.count("Error: wb_brake_set_damping_constant() called with an invalid 'damping_constant' argument "
                     "(NaN).") == 1, err
    for pitch in ("inf", "1e+308"):
        assert (f"Warning: wb_speaker_play_sound() called with a pitch value greater than 1e+09: {pitch}. Setting "
                "pitch to 1e+09.") in err, err
    assert "Sound file '' not found." in err, err
    assert "Impossible to play '" in err and "fast.wav'. Make sure the file format is supported" in err, err
    assert "INVALID_ARGUMENT: /bot/speaker/play_sound" not in err, err


def test_a_python_controller_gets_one_line_for_each_bad_value(wavs: list[str]) -> None:
    lines, err = run_controller(WORLD, lambda url: sensorium(
        "controller", "--url", url, str(REPO / "tests" / "controllers" / "bad_input.py"), *wavs))
    assert lines == BOTH + PYTHON, err
    check_both(err)
    assert "Sound file 'be' not found." in err, err      # a C string: "be\0ep.wav" ends at its NUL, as in Webots


def test_a_c_controller_gets_the_same_lines_and_webots_answers_for_bad_tags(wavs: list[str], c_controller: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [c_controller, *wavs], env=SAN_ENV)
    assert lines == BOTH + C_OWN, err
    check_both(err)
    for t in (0, 999):
        for func in ("wb_connector_enable_presence", "wb_connector_lock", "wb_brake_set_damping_constant",
                     "wb_vacuum_gripper_turn_on", "wb_speaker_stop", "wb_speaker_speak", "wb_motor_get_multiplier"):
            assert f"Error: {func}(): invalid device tag {t}\n" in err, (func, err)
    assert "Error: wb_speaker_get_engine(): device tag 9 is 'ds', a DistanceSensor\n" in err, err
    assert "Error: wb_speaker_play_sound(): invalid 'left' device tag." in err, err
    assert "Error: wb_speaker_play_sound(): invalid 'right' device tag." in err, err


AFTER = ["ready", "refused 4", "copies 0 0 0 0", "brake grip::a 0 -2", "step -1", "after 1 1 1 1"]


def after_server(argv: list[str], env: dict[str, str] | None = None) -> tuple[list[str], str]:
    """``argv`` as bot's controller: stepped once, then the server stopped under it, then let go on."""
    with serve(WORLD, "--mode", "fast") as server:
        proc = Proc(argv, env={**(env or {}), "SENSORIUM_CONTROLLER_URL": server.url("bot")}, stdin=subprocess.PIPE)
        try:
            assert proc.wait_line("ready") == "ready"
            server.stop()
            assert proc.p.stdin is not None
            proc.p.stdin.write("go\n")
            proc.p.stdin.flush()
            code = proc.wait(120)
        finally:
            proc.stop()
    assert code == 0, proc.stderr()
    return ["ready", *proc.stdout().splitlines()[1:]], proc.stderr()


def test_after_the_server_is_gone_each_call_is_one_line_and_the_copies_answer(wavs: list[str]) -> None:
    lines, err = after_server(sensorium("controller", str(REPO / "tests" / "controllers" / "after_server.py"), wavs[0]))
    assert lines[:-1] == [*AFTER[:3], "brake grip::a 0 -2.0", *AFTER[4:]], err
    codes = lines[-1].split()
    assert codes[0] == "codes" and set(codes[1:]) <= {"CONNECTION_LOST", "TIMEOUT"}, lines   # the server gone
    assert "Traceback" not in err, err


def test_after_the_server_is_gone_c_prints_one_line_a_call(wavs: list[str], c_after: str) -> None:
    lines, err = after_server([c_after, wavs[0]], env=SAN_ENV)
    assert lines == AFTER, err
    assert "Sanitizer" not in err and "runtime error" not in err, err
    for func in ("wb_connector_lock", "wb_vacuum_gripper_turn_on", "wb_speaker_speak", "wb_speaker_play_sound"):
        assert sum(line.startswith(f"Error: {func}(): ") for line in err.splitlines()) == 1, (func, err)


@pytest.fixture(scope="module")
def c_after(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "after_server.c")
