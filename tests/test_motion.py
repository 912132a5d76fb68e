"""Motion files without a server (sensorium/client/wb_motion.py): the parser's answers to damaged
files and to files beyond the bounds, one line each naming the file and line; and the player's
playback rules (interpolation, '*', loop, reverse, is_over, set_time) in closed form.
tests/test_motion_clients.py plays the same files through both clients on a world."""

from __future__ import annotations

import io

import pytest

from sensorium.client import wb_motion
from sensorium.client.wb_motion import MAX_LINE, MAX_VALUES, MotionFileError, MotionPlayer, parse_motion

HEAD = b"#WEBOTS_MOTION,V1.0,hip,knee\n"
WAVE = (b"#WEBOTS_MOTION,V1.0,hip,knee,slide\n"
        b"00:00:000,Up,0,0.2,*\n"
        b"00:00:160,Bend,0.5,*,0.05\n"
        b"00:00:480,Down,-0.25,0.6,0.1\n")

# name: (file bytes, what the one line says after "Error: wbu_motion_new(): file '<path>'")
BAD = {
    "empty": (b"", " is empty."),
    "header": (b"#WEBOTS_MOVES,V1.0,hip\n0,A,0\n",
               ", line 1: expected the header '#WEBOTS_MOTION,V1.0,<motor names>' but found '#WEBOTS_MOVES'."),
    "version": (b"#WEBOTS_MOTION,V2.0,hip\n0,A,0\n", ", line 1: unsupported version 'V2.0' (Sensorium reads V1.0)."),
    "nomotor": (b"#WEBOTS_MOTION,V1.0\n0,A\n", ", line 1: no motor names after the version."),
    "nopose": (HEAD, " has no pose."),
    "time": (HEAD + b"0,A,0,0\n00:0x:100,B,1,1\n", ", line 3: expected a time ([[mm:]ss:]mmm) but found '00:0x:100'."),
    "colons": (HEAD + b"0:0:0:0,A,0,0\n", ", line 2: expected a time ([[mm:]ss:]mmm) but found '0:0:0:0'."),
    "order": (HEAD + b"0:500,A,0,0\n0:0:500,B,1,1\n",
              ", line 3: time '0:0:500' is not after the previous pose's (500 ms)."),
    "late": (HEAD + b"16667:0:0,A,0,0\n", ", line 2: time '16667:0:0' is beyond 1000000000 ms."),
    "noname": (HEAD + b"0\n", ", line 2: pose name expected."),
    "missing": (HEAD + b"0,A,0\n", ", line 2: 1 values for 2 motors."),
    "extra": (HEAD + b"0,A,0,0,7\n", ", line 2: unexpected extra data '7' after 2 values."),
    "damaged": (HEAD + b"00:00:000,A,0,0\n00:00:100,B,0.5,oops\n", ", line 3: expected a number or '*' but found 'oops'."),
    "trailing": (HEAD + b"0,A,0,1.5x\n", ", line 2: expected a number or '*' but found '1.5x'."),
    "infinite": (HEAD + b"0,A,0,1e999\n", ", line 2: expected a number or '*' but found '1e999'."),
    "nan": (HEAD + b"0,A,nan,0\n", ", line 2: expected a number or '*' but found 'nan'."),
    "long": (HEAD + b"0,A,0," + b"1" * MAX_LINE + b"\n", f", line 2: longer than {MAX_LINE} characters."),
    "nul": (HEAD + b"0,A,0,\x001\n", ", line 2: holds a NUL character."),
}


def parse(data: bytes) -> wb_motion.MotionFile:
    return parse_motion(io.BytesIO(data), "f.motion")


@pytest.mark.parametrize("name", sorted(BAD))
def test_a_damaged_file_gives_one_line_naming_the_file_and_line(name: str) -> None:
    data, what = BAD[name]
    with pytest.raises(MotionFileError) as err:
        parse(data)
    assert str(err.value) == "Error: wbu_motion_new(): file 'f.motion'" + what
    assert "\n" not in str(err.value)


def test_the_format_webots_reads() -> None:
    f = parse(WAVE)
    assert f.motors == ("hip", "knee", "slide") and f.times == (0, 160, 480)
    assert list(f.values)[:2] == [0.0, 0.2] and f.values[2] != f.values[2]          # '*': NaN
    # [[mm:]ss:]mmm; empty fields skipped and CR ends a field (Webots' tokenizer); numbers with
    # surrounding blanks, signs, exponents
    f = parse(b"#WEBOTS_MOTION,V1.0,,a,,b,\r\n7,P,, 1.5 ,-2e-1\r\n2:5,Q,+.5,*\n1:02:003,R,3.,*\n")
    assert f.motors == ("a", "b") and f.times == (7, 2005, 62003)
    assert list(f.values[:3]) == [1.5, -0.2, 0.5]


def test_an_empty_line_ends_the_poses_and_what_follows_is_said(capsys) -> None:
    f = parse(HEAD + b"0,A,0,0\n\n\n1000,B,1,1\n")
    assert f.times == (0,)
    assert capsys.readouterr().err == ("Warning: wbu_motion_new(): file 'f.motion', line 5: ignored with every line "
                                       "after the empty line 3 (an empty line ends the poses, as in Webots).\n")
    parse(HEAD + b"0,A,0,0\n\n\r\n")
    assert capsys.readouterr().err == ""


def test_the_bounds_a_file_may_ask_for() -> None:
    line = b"0,A,1." + b"0" * (MAX_LINE - 6) + b"\n"                        # exactly MAX_LINE characters
    assert parse(b"#WEBOTS_MOTION,V1.0,a\n" + line).values[0] == 1.0
    parse(HEAD + b"16666:39:999,A,0,0\n")                                   # 999 999 999 ms
    motors = 500
    header = b"#WEBOTS_MOTION,V1.0," + b",".join(b"m%d" % i for i in range(motors)) + b"\n"
    pose = b",P," + b",".join([b"*"] * motors) + b"\n"
    poses = b"".join(b"%d" % t + pose for t in range(MAX_VALUES // motors + 1))
    with pytest.raises(MotionFileError, match=rf"line {MAX_VALUES // motors + 2}: more than {MAX_VALUES} values"):
        parse(header + poses)


def player(data: bytes = WAVE) -> MotionPlayer:
    f = parse(data)
    return MotionPlayer(f, "f.motion", list(range(1, len(f.motors) + 1)))


def hip(e: int) -> float:
    """wave's hip in closed form: 0 -> 0.5 over 160 ms, -> -0.25 at 480 ms."""
    e = min(max(e, 0), 480)
    return 0.5 * e / 160 if e <= 160 else 0.5 - 0.75 * (e - 160) / 320


def test_positions_interpolate_linearly_and_star_leaves_a_motor_alone() -> None:
    p = player()
    for e in range(-32, 520, 8):
        p.elapsed = e
        got = dict(p.positions())
        assert got[1] == pytest.approx(hip(e), abs=1e-15), e
        # the knee: '*' in the middle pose, so set only at either end
        assert got.get(2) == (0.2 if e <= 0 else 0.6 if e >= 480 else None), e
        # the slide: '*' in the first pose, so unset up to the middle pose (160 ms) included
        want = None if e <= 160 else 0.1 if e >= 480 else 0.05 + 0.05 * (e - 160) / 320
        assert got.get(3) == (None if want is None else pytest.approx(want, abs=1e-15)), e


def test_playback_forwards_loop_and_reverse_and_is_over() -> None:
    p = player()
    p.playing = True
    seen = []
    while p.playing:                      # set at the current time, then move on by the step
        seen.append(p.elapsed)
        p.advance(100)
    assert seen == [0, 100, 200, 300, 400, 500]            # 500: past the end, the last pose's values
    assert p.elapsed == 480 and p.is_over()
    p.loop, p.playing, p.elapsed = True, True, 0
    seen = []
    for _ in range(8):
        seen.append(p.elapsed)
        p.advance(100)
        assert not p.is_over()
    assert seen == [0, 100, 200, 300, 400, 500, 0, 100]    # the step that wraps does not move on
    p.loop, p.reverse, p.elapsed = False, True, 250
    seen = []
    while p.playing:
        seen.append(p.elapsed)
        assert p.is_over() == (p.elapsed <= 0)
        p.advance(100)
    assert seen == [250, 150, 50, -50] and p.elapsed == 0 and p.is_over()


def test_set_time_clamps_to_the_motion() -> None:
    p = player()
    for asked, got in ((-5, 0), (200, 200), (10_000, 480)):
        p.elapsed = 7
        wb_motion.wbu_motion_set_time(p, asked)
        assert wb_motion.wbu_motion_get_time(p) == got


def test_null_motions_print_webots_line_and_answer_no_value(capsys) -> None:
    assert wb_motion.wbu_motion_new("") is None
    wb_motion.wbu_motion_play(None)
    assert wb_motion.wbu_motion_is_over(None) is False
    assert wb_motion.wbu_motion_get_duration(None) == -1 and wb_motion.wbu_motion_get_time(None) == -1
    wb_motion.wbu_motion_delete(None)
    assert capsys.readouterr().err.splitlines() == [
        "Error: wbu_motion_new() called with NULL or empty 'filename' argument.",
        "Error: wbu_motion_play() called with NULL 'motion' argument.",
        "Error: wbu_motion_is_over() called with NULL argument.",
        "Error: wbu_motion_get_duration() called with NULL argument.",
        "Error: wbu_motion_get_time() called with NULL argument."]
