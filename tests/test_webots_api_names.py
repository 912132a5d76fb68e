"""Sensorium's controller APIs against the whole of Webots' public controller API, name by name:
tests/webots_api/python.txt lists Webots' Python classes, methods (with their parameters and
defaults), properties and constants, c_functions.txt every function of Webots' C headers and
cpp_methods.txt every public method of its C++ classes (written from Webots' sources and reference
manual). A controller written for Webots must never die on a name Sensorium lacks: each gap fails
here by name."""

from __future__ import annotations

import inspect
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
