"""The C library's image devices (issue 23) against a live server, built with AddressSanitizer and
UBSan: a C controller reads exactly the bytes the Python client reads on the same world (range
images, camera images), and the save functions answer Webots' codes."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest
from _serve import serve
from test_c_client import ENV, REPO, SAN_ENV, TESTS_C, finish, sanitized_controller

WORLD = REPO / "tests" / "worlds" / "images.yaml"

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(sys.platform == "win32" or shutil.which("cc") is None,
                                 reason="needs a POSIX C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev)")]


@pytest.fixture(scope="module")
def reader(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, TESTS_C / "image_reader.c")


def _run(cmd: list[str], url: str) -> tuple[list[str], str]:
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env={**ENV, "SENSORIUM_CONTROLLER_URL": url}, cwd=str(REPO))
    code, out, err = finish(p)
    assert code == 0, err
    return out, err


def _read_in_c_and_python(reader: str, *args: str) -> tuple[list[str], str, list[str]]:
    """The C image reader's stdout and stderr, and the Python reader's stdout, each run with ``args``
    against a fresh server of the images world."""
    with serve(WORLD, env=SAN_ENV) as s:
        c_out, c_err = _run([reader, *args], s.url("bot"))
    with serve(WORLD, env=SAN_ENV) as s:
        py_out, _ = _run([sys.executable, "-m", "sensorium", "controller", "--url", s.url("bot"),
                          str(REPO / "tests" / "controllers" / "image_reader.py"), *args], s.url("bot"))
    return c_out, c_err, py_out


def test_range_finder_bytes_match_python(reader):
    c_out, c_err, py_out = _read_in_c_and_python(reader, "depth", "3")
    assert c_out == py_out
    assert c_out[-2] == "# info 12 8 1 0.050000000000000003 3" and c_out[-1] == "# save -1"
    first = bytes.fromhex(c_out[0].split("=")[1])
    assert len(first) == 4 * 12 * 8 and first != bytes(len(first))    # an image arrived with the first step
    assert "cannot write" in c_err


def test_camera_bytes_match_python(reader):
    c_out, c_err, py_out = _read_in_c_and_python(reader, "camera", "3")
    assert c_out == py_out
    assert c_out[0] == "# null_before 1" and c_out[-2] == "# exposure 2" and c_out[-1] == "# save -1"
    first = bytes.fromhex(c_out[1].split(" ")[2].split("=")[1])
    assert len(first) == 4 * 16 * 12 and len(set(first[2::4])) > 5      # a picture, not a flat colour
    assert " objects=1 [4 ball " in c_out[1]                             # the ball: robots 1, solids 2.. in order
    assert "wb_camera_get_image() called for a disabled device" in c_err


def _read_hdr(path) -> tuple[int, int, list[float]]:
    """A flat-scanline Radiance picture's size and its pixels' red channel, decoded (``m·2^(e−136)``)."""
    import math
    data = path.read_bytes()
    head, _, body = data.partition(b"\n\n")
    assert head.startswith(b"#?RADIANCE\n") and b"FORMAT=32-bit_rle_rgbe" in head
    size, _, pixels = body.partition(b"\n")
    _, h, _, w = size.split()
    assert len(pixels) == 4 * int(h) * int(w)
    vals = []
    for i in range(0, len(pixels), 4):
        r, g, b, e = pixels[i:i + 4]
        assert r == g == b
        vals.append(0.0 if e == 0 else math.ldexp(r, e - 136))
    return int(w), int(h), vals


def test_range_finder_saves_webots_hdr_in_c_and_python(reader, tmp_path):
    """Webots' sample range_finder controller saves its depth as ``.hdr`` (a float grey Radiance
    picture of (depth − minRange)/maxRange clamped to [0, 1]); ``.tiff`` answers Webots' line and -1."""
    import struct
    c_dir, py_dir = tmp_path / "c", tmp_path / "py"
    c_dir.mkdir()
    py_dir.mkdir()
    with serve(WORLD, env=SAN_ENV) as s:
        c_out, c_err = _run([reader, "depth", "2", str(c_dir)], s.url("bot"))
    with serve(WORLD, env=SAN_ENV) as s:
        py_out, py_err = _run([sys.executable, "-m", "sensorium", "controller", "--url", s.url("bot"),
                               str(REPO / "tests" / "controllers" / "image_reader.py"), "depth", "2", str(py_dir)],
                              s.url("bot"))
    assert c_out == py_out and c_out[-2:] == ["# hdr 0", "# tiff -1"]
    line = "wb_range_finder_save_image(): .tiff image not supported anymore, use .hdr instead."
    assert line in c_err and line in py_err
    assert (c_dir / "depth.hdr").read_bytes() == (py_dir / "depth.hdr").read_bytes()
    w, h, vals = _read_hdr(c_dir / "depth.hdr")
    assert (w, h) == (12, 8)
    depth = struct.unpack(f"<{w * h}f", bytes.fromhex(c_out[-5].split("=")[1]))
    want = [min(max((d - 0.05) / 3.0, 0.0), 1.0) for d in depth]
    assert any(0.0 < v < 1.0 for v in want)                 # the wall and the floor, not a blank picture
    assert vals == pytest.approx(want, rel=1 / 128, abs=1e-30)     # RGBE keeps 8 bits of mantissa
