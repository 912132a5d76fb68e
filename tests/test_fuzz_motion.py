"""Hypothesis fuzz of motion files through both clients' parsers: random files in Webots' format
(times in every [[mm:]ss:]mmm form, '*', numbers written every way, odd tokens, CRLF, empty fields)
and mutations of them (truncated, bytes flipped or inserted, empty lines, NULs, overlong lines) are
read by the Python client's ``parse_motion`` and by the C library's own parser (src/motion.c,
compiled into the harness tests/c/motion_parse.c with AddressSanitizer and UBSan). Both give the same
verdict, the same one line when they refuse a file, and the same motors, times and value bits when
they take it; nothing crashes, leaks or prints more than the line (and the one warning for poses after
an empty line)."""

from __future__ import annotations

import contextlib
import io
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from test_c_client import CLIB, SAN_ENV, TESTS_C

from sensorium.client.wb_motion import MotionFileError, parse_motion

FUZZ = settings(max_examples=80, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def harness(tmp_path_factory) -> str:
    if sys.platform == "win32" or shutil.which("cc") is None:
        pytest.skip("needs a POSIX C toolchain")
    exe = tmp_path_factory.mktemp("motion_parse") / "motion_parse"
    done = subprocess.run(["cc", "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-Wall", "-Wextra", "-Werror", "-g",
                           "-fsanitize=address,undefined", "-fno-sanitize-recover=undefined",
                           f"-I{CLIB / 'include'}", f"-I{CLIB / 'src'}", str(TESTS_C / "motion_parse.c"),
                           "-o", str(exe), "-lm"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return str(exe)


def python_verdict(path: Path) -> list[str]:
    """What the harness prints for the file, from the Python client."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), path.open("rb") as fh:
        try:
            f = parse_motion(fh, str(path))
        except MotionFileError as exc:
            print(exc, file=sys.stderr)
            f = None
    out = [f"file {path}", *err.getvalue().split("\n")[:-1]]
    if f is not None:
        out.append(f"ok {len(f.motors)} {len(f.times)}")
        out += [f"m {m}" for m in f.motors]
        out += [f"t {t}" for t in f.times]
        out += [f"v {struct.unpack('<Q', struct.pack('<d', v))[0]:016x}" for v in f.values]
    return out


def c_verdicts(harness: str, paths: list[Path]) -> list[str]:
    done = subprocess.run([harness, *map(str, paths)], capture_output=True, env=SAN_ENV, timeout=120)
    assert done.returncode == 0, done.stdout.decode(errors="replace")[-3000:]
    return done.stdout.decode("utf-8", "replace").split("\n")[:-1]


def same(harness: str, tmp_path: Path, files: list[bytes]) -> None:
    paths = []
    for k, data in enumerate(files):
        paths.append(tmp_path / f"f{k}.motion")
        paths[-1].write_bytes(data)
    expected = [line for p in paths for line in python_verdict(p)]
    got = c_verdicts(harness, paths)
    assert got == expected
    for p in paths:              # one line at most per refused file, plus the empty line's warning
        lines = python_verdict(p)
        if not any(line.startswith("ok ") for line in lines):
            assert len([x for x in lines if x.startswith("Error")]) == 1, lines


ODD = ["nan", "NaN", "inf", "-inf", "1e999", "-1e999", "1e-400", "4.9e-324", "1.5x", " 1 ", "\t-2\t", "+.5", "-0",
       "0x10", "1_0", "1e", "1e+", ".", "+", "-.e1", "\u0661", "\uff11", "1,5", "*", " * ", "**", "1e308", "17e307",
       "0.1e-5", "00012", "1.", ".1", "9" * 400, "0." + "0" * 330 + "1", "\xa0" + "1", "1\x0b", "\xff\xfe", "\r"]
name = st.text(st.characters(blacklist_characters=",\r\n\0", blacklist_categories=["Cs"]), min_size=1, max_size=6)
number = (st.floats(allow_nan=False, allow_infinity=False).map(repr)
          | st.floats(allow_nan=False, allow_infinity=False, width=32).map(lambda v: f"{v:.9e}")
          | st.integers(-10 ** 30, 10 ** 30).map(str) | st.sampled_from(ODD) | st.just("*"))


def clock(ms: int, form: int) -> str:
    if form == 0:
        return str(ms)
    if form == 1:
        return f"{ms // 1000}:{ms % 1000:03d}"
    return f"{ms // 60000:02d}:{ms // 1000 % 60:02d}:{ms % 1000:03d}"


@st.composite
def motion_files(draw) -> bytes:
    motors = draw(st.lists(name, min_size=0, max_size=4))
    header = draw(st.sampled_from(["#WEBOTS_MOTION,V1.0", "#WEBOTS_MOTION,V1.0", "#WEBOTS_MOTION,V2.0",
                                   "WEBOTS_MOTION,V1.0", ",#WEBOTS_MOTION,,V1.0"]))
    sep = draw(st.sampled_from([",", ",", ",,"]))
    end = draw(st.sampled_from(["\n", "\r\n", "\r\r\n"]))
    lines = [sep.join([header, *motors])]
    t = draw(st.integers(0, 2000))
    for _ in range(draw(st.integers(0, 6))):
        t += draw(st.sampled_from([1, 16, 500, 0, -1, 60000, 10 ** 9]))
        ms = draw(st.sampled_from([t, max(t, 0)]))
        n = len(motors) + draw(st.sampled_from([0, 0, 0, -1, 1]))
        cells = [clock(abs(ms), draw(st.integers(0, 2))), draw(st.sampled_from(["P", "pose 1", "", "*"]))]
        cells += [draw(number) for _ in range(max(n, 0))]
        lines.append(sep.join(cells) + draw(st.sampled_from(["", "", ",", ",,"])))
    if draw(st.booleans()):
        lines.insert(draw(st.integers(1, len(lines))), draw(st.sampled_from(["", ",,", "\r"])))
    data = (end.join(lines) + draw(st.sampled_from([end, ""]))).encode("utf-8", "surrogatepass")
    return data


@st.composite
def mutated(draw) -> bytes:
    data = bytearray(draw(motion_files()))
    for _ in range(draw(st.integers(0, 3))):
        kind = draw(st.integers(0, 4))
        at = draw(st.integers(0, len(data)))
        if kind == 0:
            del data[at:]
        elif kind == 1 and at < len(data):
            data[at] = draw(st.integers(0, 255))
        elif kind == 2:
            data[at:at] = draw(st.binary(max_size=6))
        elif kind == 3:
            data[at:at] = draw(st.sampled_from([b"\n", b"\n\n", b"\x00", b",", b":", b"\r", b"1" * 4095, b"9" * 5000]))
        else:
            data[at:at] = draw(st.sampled_from([b"\xff", b"\xe2\x82", b"\xc3", b"\xf0\x9f\x98\x80"]))
    return bytes(data)


@FUZZ
@given(files=st.lists(motion_files(), min_size=1, max_size=6))
def test_random_motion_files_same_verdict_in_both_clients(harness, tmp_path, files) -> None:
    same(harness, tmp_path, files)


@FUZZ
@given(files=st.lists(mutated(), min_size=1, max_size=6))
@example(files=[b"#WEBOTS_MOTION,V1.0,a\n0,P,1\n\n\n5,Q,2\n", b"#WEBOTS_MOTION,V1.0,a\n" + b"0" * 4093 + b"1,P,1\n"])
def test_mutated_motion_files_same_verdict_in_both_clients(harness, tmp_path, files) -> None:
    same(harness, tmp_path, files)


def test_a_folder_is_a_file_that_cannot_be_opened_in_both_clients(harness, tmp_path, monkeypatch, capsys) -> None:
    """Found here: C's fopen opens a folder and read nothing from it ('is empty.'), where Python's
    open refuses it ('could not open'); both now say the Python client's line."""
    from sensorium.client import wb_motion

    folder = tmp_path / "wave.motion"
    folder.mkdir()
    line = f"Error: wbu_motion_new(): could not open '{folder}' file."
    assert c_verdicts(harness, [folder]) == [f"file {folder}", line]
    monkeypatch.setattr(wb_motion, "_hooked", lambda: None)
    assert wb_motion.wbu_motion_new(str(folder)) is None
    assert capsys.readouterr().err.splitlines() == [line]
