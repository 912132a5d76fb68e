"""Sensorium's controller APIs against the whole of Webots' public controller API, name by name:
tests/webots_api/python.txt lists Webots' Python classes, methods (with their parameters and
defaults), properties and constants, c_functions.txt every function of Webots' C headers and
cpp_methods.txt every public method of its C++ classes (written from Webots' sources and reference
manual). A controller written for Webots must never die on a name Sensorium lacks: each gap fails
here by name."""

from __future__ import annotations

import inspect
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
API = REPO / "tests" / "webots_api"


def test_python_packages_have_every_webots_name_and_signature():
    """check_python.py imports ``controller`` and ``vehicle`` as a controller does (the webots
    folder on the path) and prints one line per gap."""
    run = subprocess.run([sys.executable, str(API / "check_python.py")], capture_output=True, text=True,
                         cwd=REPO, timeout=120)
    assert run.stderr == ""
    assert run.stdout == "", "gaps against Webots' Python API:\n" + run.stdout
    assert run.returncode == 0


def test_the_python_listing_is_read_whole():
    """The listing is not silently short: every class and a sample of lines are there."""
    text = (API / "python.txt").read_text(encoding="utf-8")
    assert text.count("\nclass ") == 44
    for line in ("def step(time_step=None)", "def getPose(fromNode=None)", "def getRangeImage(data_type='list')",
                 "def setLabel(id, label, x, y, size, color, transparency=0, font='Arial')",
                 "static playSound(left, right, sound, volume, pitch, balance, loop)", "prop custom_data rw"):
        assert f"\n{line}\n" in text


def test_a_webots_signature_on_a_stand_in_method():
    """A method Sensorium does not serve takes Webots' parameters: keywords by Webots' names, its
    defaults, and Python's TypeError for a call Webots' method would refuse."""
    from sensorium.client.webots.controller.unsimulated import signed

    calls = []
    method = signed(lambda *args: calls.append(args) or "no value", "filename, quality=80")
    assert str(inspect.signature(method)) == "(self, filename, quality=80)"
    assert method("me", filename="a.png") == "no value"
    assert method("me", "b.png", 3) == "no value"
    assert calls == [("me", "a.png", 80), ("me", "b.png", 3)]
    with pytest.raises(TypeError):
        method("me")
    with pytest.raises(TypeError):
        method("me", "a.png", 1, 2)
    with pytest.raises(TypeError):
        method("me", file="a.png")


def test_check_python_reports_a_dropped_name(tmp_path):
    """The checker itself: a listing naming what Sensorium lacks gives one line per gap."""
    listing = tmp_path / "python.txt"
    listing.write_text("class controller.robot.Robot\ndef step(time_step=None)\ndef flyAway(height)\n"
                       "def getUrdf(prefix='x')\nprop nowhere\nconst EVENT_QUIT = -2\n", encoding="utf-8")
    code = ("import sys; sys.path.insert(0, sys.argv[1]); sys.path.insert(0, sys.argv[2]); import check_python; "
            "print('\\n'.join(check_python.check(check_python.Path(sys.argv[3]))))")
    run = subprocess.run([sys.executable, "-c", code, str(REPO / "sensorium" / "client" / "webots"), str(API),
                          str(listing)], capture_output=True, text=True, cwd=REPO, timeout=120)
    assert run.stdout.splitlines() == [
        "controller.Robot.flyAway: missing",
        "controller.Robot.getUrdf: parameter 'prefix' defaults to '', Webots' to 'x'",
        "controller.Robot.nowhere: missing (a property in Webots)",
        "controller.Robot.EVENT_QUIT = -1, Webots' is -2"], run.stderr


# ---------------------------------------------------------------------- C and C++

sys.path.insert(0, str(API))
import check_c  # noqa: E402

CLIB = REPO / "sensorium" / "client" / "c"
INCLUDE = CLIB / "include"
needs_cc = pytest.mark.skipif(sys.platform == "win32" or shutil.which("cc") is None or shutil.which("c++") is None,
                              reason="needs a POSIX C/C++ toolchain (build-essential, libzmq3-dev, libmsgpack-dev, ...)")


@pytest.fixture(scope="module")
def clib(tmp_path_factory) -> tuple[Path, list[str]]:
    build = tmp_path_factory.mktemp("libcontroller")
    for args in ([f"BUILD={build}"], ["libs"]):
        done = subprocess.run(["make", "-s", "-C", str(CLIB), *args], capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stdout + done.stderr
    return build, done.stdout.split()


def test_the_c_listing_is_read_whole():
    names = check_c.c_functions()
    assert len(names) == len(set(names)) == 550
    for name in ("wb_robot_init", "wb_supervisor_node_get_pose", "wbu_driver_get_wipers_mode", "wb_radio_send",
                 "wbu_string_replace", "wb_robot_wwi_receive_text", "wb_supervisor_movie_get_status"):
        assert name in names


@needs_cc
def test_every_webots_c_function_is_declared_alike_and_linked(clib, tmp_path):
    """A C controller calling any function of Webots' headers compiles (the same prototype) and
    links against libController.so: the compiler names each function that differs or is missing."""
    build, _ = clib
    src = tmp_path / "api_names.c"
    program = check_c.c_program(INCLUDE)
    src.write_text(program, encoding="utf-8")
    done = subprocess.run(["cc", "-std=c11", "-Wno-deprecated-declarations", f"-I{INCLUDE}", f"-I{API}", str(src),
                           "-o", str(tmp_path / "api_names"), f"-L{build}", "-lController"],
                          capture_output=True, text=True, timeout=300)
    differ = check_c.failing_lines(program, done.stderr, src.name)
    differ += [f"{f}: not in libController" for f in re.findall(r"undefined reference to `(\w+)'", done.stderr)]
    assert differ == [] and done.returncode == 0, done.stderr[-3000:]


@needs_cc
def test_every_webots_cpp_method_is_callable_alike(clib, tmp_path):
    """Each public method of Webots' C++ classes can be called as Webots declares it (const ones on a
    const object, default arguments left out) and answers a value of Webots' return type."""
    build, libs = clib
    src = tmp_path / "api_names.cpp"
    program = check_c.cpp_program(INCLUDE)
    src.write_text(program, encoding="utf-8")
    done = subprocess.run(["c++", "-std=c++11", "-Wall", "-Wextra", f"-I{INCLUDE}", str(src), "-o",
                           str(tmp_path / "api_names_cpp"), str(build / "libController.a"), *libs],
                          capture_output=True, text=True, timeout=300)
    assert check_c.failing_lines(program, done.stderr, src.name) == [] and done.returncode == 0, done.stderr[-3000:]


@needs_cc
def test_the_comparison_names_a_changed_prototype_and_a_dropped_method(tmp_path):
    """The checks themselves: a prototype Sensorium declares otherwise, and a C++ method it lacks,
    come out by name."""
    listing = tmp_path / "c_functions.h"
    listing.write_text((API / "c_functions.h").read_text().replace(
        "void wb_joystick_set_constant_force(int level);", "void wb_joystick_set_constant_force(double level);"))
    program = check_c.c_program(INCLUDE)
    src = tmp_path / "api_names.c"
    src.write_text(program)
    done = subprocess.run(["cc", "-std=c11", "-fsyntax-only", "-Wno-deprecated-declarations", f"-I{INCLUDE}",
                           f"-I{tmp_path}", str(src)], capture_output=True, text=True, timeout=300)
    assert done.returncode != 0 and re.search(r"conflicting types for .wb_joystick_set_constant_force.", done.stderr)
    cpp = tmp_path / "cpp_methods.txt"
    cpp.write_text("class Camera : Device\nint getWidth() const\ndouble getShutterSpeed() const\n")
    program = check_c.cpp_program(INCLUDE, cpp)
    src = tmp_path / "api_names.cpp"
    src.write_text(program)
    done = subprocess.run(["c++", "-std=c++11", "-fsyntax-only", f"-I{INCLUDE}", str(src)], capture_output=True,
                          text=True, timeout=300)
    assert check_c.failing_lines(program, done.stderr, src.name) == ["Camera::getShutterSpeed() const -> double"]


def test_importing_webots_ctypes_handle_ends_with_one_line():
    """``controller.wb`` (Webots' ctypes handle on its libController) is the one name left out: a
    controller importing it ends with status 1 and one line saying so, not a traceback."""
    run = subprocess.run([sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); from controller.wb import wb",
                          str(REPO / "sensorium" / "client" / "webots")], capture_output=True, text=True, timeout=120)
    assert run.returncode == 1 and run.stdout == ""
    assert run.stderr.count("\n") == 1 and run.stderr.startswith("Error: controller.wb (Webots' ctypes handle")
