"""A controller folder's runtime.ini read as Webots reads it (no process): sections, comments,
quotes, ``$(NAME)`` references, the platform's sections, [python] COMMAND/OPTIONS; and what
`sensorium run`'s launcher makes of it (the controller's command line and environment)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from sensorium import runtime_ini
from sensorium.launch import ControllerSpec, Launcher, find_controller
from sensorium.runtime_ini import RuntimeIni, RuntimeIniError, environment, parse

TEXT = '''; a comment
[environment variables with paths]
PYTHONPATH = $(PYTHONPATH):../../lib        ; a comment after a value
LD_LIBRARY_PATH = $(NOT_SET):lib:$(ALSO_NOT_SET)

[Environment Variables]   ; section names are not case-sensitive
GREETING = "hello; world"  ; quotes keep their semicolon
PLAIN = a=b
REUSE = $(GREETING)!
not a definition

[environment variables for linux]
ONLY_LINUX = yes
[environment variables for Windows]
ONLY_WINDOWS = yes
[environment variables for macos]
ONLY_MAC = yes

[python]
COMMAND = /opt/venv/bin/python
OPTIONS = -X utf8 -B
[java]
COMMAND = java
'''


def test_entries_are_read_as_webots_reads_them() -> None:
    ini = parse(TEXT)
    assert ini.entries[:6] == (
        ("environment variables with paths", "PYTHONPATH", "$(PYTHONPATH):../../lib"),
        ("environment variables with paths", "LD_LIBRARY_PATH", "$(NOT_SET):lib:$(ALSO_NOT_SET)"),
        ("environment variables", "GREETING", "hello; world"),
        ("environment variables", "PLAIN", "a=b"),
        ("environment variables", "REUSE", "$(GREETING)!"),
        ("environment variables for linux", "ONLY_LINUX", "yes"))
    assert (ini.python("COMMAND"), ini.python("OPTIONS")) == ("/opt/venv/bin/python", "-X utf8 -B")
    assert ini.notes() == []
    assert RuntimeIni().python("COMMAND") is None


def test_variables_are_set_in_order_with_references_replaced() -> None:
    base = {"PYTHONPATH": "/mine", "GREETING": "old"}
    linux = environment(parse(TEXT), base, "linux")
    assert {k: v for k, v in linux.items() if k not in base or v != base[k]} == {
        "PYTHONPATH": "/mine:../../lib", "LD_LIBRARY_PATH": "lib",       # empty entries of unset variables dropped
        "GREETING": "hello; world", "PLAIN": "a=b", "REUSE": "hello; world!", "ONLY_LINUX": "yes"}
    assert base == {"PYTHONPATH": "/mine", "GREETING": "old"}                # a copy
    mac = environment(parse(TEXT), {}, "darwin")
    assert "ONLY_MAC" in mac and "ONLY_LINUX" not in mac and "ONLY_WINDOWS" not in mac
    assert environment(parse(TEXT), {}, "linux")["PYTHONPATH"] == "../../lib"


def test_an_invalid_file_is_one_line_and_odd_keys_are_said() -> None:
    with pytest.raises(RuntimeIniError, match=r"^x/runtime.ini: line 2: a ';' before the '=' \('A;B = 1'\)"):
        parse("[environment variables]\nA;B = 1\n", "x/runtime.ini")
    ini = parse("[python]\nCOMAND = python3\n[environment variables with relative paths]\nP = a\n")
    assert ini.notes() == ["unknown key COMAND in its [python] section (COMMAND and OPTIONS are read)",
                           "[environment variables with relative paths] is deprecated: use [environment variables "
                           "with paths]"]
    assert environment(ini, {}, "linux") == {"P": "a"}


def test_python_options_are_split_at_each_space_as_webots_splits_them(tmp_path: Path) -> None:
    """WbController splits [python] OPTIONS at each space and nowhere else: no quoting (a quoted value's
    quotes are the file's, gone once read; quotes inside stay), a tab inside an argument; the empty
    arguments of two spaces in a row are left out (Python would take one for its script)."""
    ini = parse('[python]\nOPTIONS = -X  dev -W "error"\tx\n')
    assert ini.python("OPTIONS") == '-X  dev -W "error"\tx'
    assert ini.python_options() == ["-X", "dev", "-W", '"error"\tx']
    assert parse('[python]\nOPTIONS = "-X utf8" ; quoted\n').python_options() == ["-X", "utf8"]
    assert parse("[python]\nOPTIONS =\n").python_options() == [] and RuntimeIni().python_options() == []
    folder = tmp_path / "controllers" / "c"
    folder.mkdir(parents=True)
    (folder / "c.py").write_text("")
    (folder / "runtime.ini").write_text("[python]\nOPTIONS =  -B   -X\tdev \n")
    spec = find_controller("r", "c", [], [tmp_path / "controllers"])
    launcher = Launcher([spec], "tcp://127.0.0.1:1")
    try:
        assert launcher.command(spec)[:5] == [sys.executable, "-B", "-X\tdev", "-m", "sensorium"]
    finally:
        launcher.close()


def test_python_command_and_options_have_their_references_replaced_as_webots_does(tmp_path: Path) -> None:
    """Webots replaces $(NAME) in every entry, [python] ones too, against its environment (the robot's
    name already in it) with the file's earlier entries applied: a later one is not seen."""
    text = ('[environment variables]\nVENV = /opt/venv\n[python]\nCOMMAND = $(VENV)/bin/python\n'
            'OPTIONS = -X pycache_prefix=$(HOME)/$(WEBOTS_ROBOT_NAME)  -W $(LATER)x\n'
            '[environment variables]\nLATER = late\n')
    ini = parse(text)
    assert ini.python("COMMAND") == "$(VENV)/bin/python"               # as written
    assert ini.python("COMMAND", {}) == "/opt/venv/bin/python"
    assert ini.python_options({"HOME": "/home/me", "WEBOTS_ROBOT_NAME": "r"}) == [
        "-X", "pycache_prefix=/home/me/r", "-W", "x"]
    folder = tmp_path / "controllers" / "c"
    folder.mkdir(parents=True)
    (folder / "c.py").write_text("")
    (folder / "runtime.ini").write_text(text)
    spec = find_controller("bee", "c", [], [tmp_path / "controllers"])
    launcher = Launcher([spec], "tcp://127.0.0.1:1")
    try:
        assert launcher.command(spec, {"HOME": "/h", "WEBOTS_ROBOT_NAME": "stale"})[:5] == [
            "/opt/venv/bin/python", "-X", "pycache_prefix=/h/bee", "-W", "x"]
        env = launcher.environment(spec, {"WEBOTS_ROBOT_NAME": "stale"})
        assert env["LATER"] == "late" and env["WEBOTS_ROBOT_NAME"] == "bee"
    finally:
        launcher.close()
    (folder / "runtime.ini").write_text("[environment variables]\nWHO = $(WEBOTS_ROBOT_NAME)!\n")
    spec = find_controller("bee", "c", [], [tmp_path / "controllers"])
    launcher = Launcher([spec], "tcp://127.0.0.1:1")
    try:
        assert launcher.environment(spec, {})["WHO"] == "bee!"
    finally:
        launcher.close()


def test_the_launcher_runs_a_controller_with_its_runtime_ini(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "controllers" / "c"
    folder.mkdir(parents=True)
    (folder / "c.py").write_text("")
    (folder / "runtime.ini").write_text(TEXT.replace("[python]", "[python]\nCOLOUR = red"))
    spec = find_controller("r", "c", ["--x"], [tmp_path / "controllers"])
    assert spec.runtime is not None and spec.notes == (
        f"robot 'r': {folder / 'runtime.ini'}: unknown key COLOUR in its [python] section (COMMAND and OPTIONS are read)",)
    launcher = Launcher([spec], "tcp://127.0.0.1:1")
    try:
        assert launcher.command(spec) == ["/opt/venv/bin/python", "-X", "utf8", "-B", "-m", "sensorium", "controller",
                                          str(folder / "c.py"), "--", "--x"]
        monkeypatch.setattr(sys, "platform", "linux")
        env = launcher.environment(spec, {"PYTHONPATH": "/mine", "WEBOTS_LIBRARY_PATH": "/wl", "PATH": "/bin"})
        # its variables, then what the controller needs here on top (the URL, Sensorium first on the paths)
        assert env["GREETING"] == "hello; world" and env["ONLY_LINUX"] == "yes"
        assert env["PYTHONPATH"].split(":")[1:] == ["/mine", "../../lib"]
        assert env["LD_LIBRARY_PATH"] == f"/wl:{folder}:lib"
        assert env["SENSORIUM_CONTROLLER_URL"] == "tcp://127.0.0.1:1/r" and env["WEBOTS_ROBOT_NAME"] == "r"
        plain = ControllerSpec("r", "c", folder, folder / "c.py", True)
        assert launcher.command(plain)[:4] == [sys.executable, "-m", "sensorium", "controller"]
    finally:
        launcher.close()
    (folder / "runtime.ini").write_text("[environment variables]\nA;B = 1\n")
    spec = find_controller("r", "c", [], [tmp_path / "controllers"])
    assert spec.runtime is None and spec.notes == (
        f"robot 'r': {folder / 'runtime.ini'}: line 2: a ';' before the '=' ('A;B = 1'): Webots reads none of this file "
        "then; the controller starts without it",)
    monkeypatch.setattr(runtime_ini, "MAX_BYTES", 10)
    (folder / "runtime.ini").write_text("[environment variables]\nA = 1\n")
    assert find_controller("r", "c", [], [tmp_path / "controllers"]).notes == (
        f"robot 'r': {folder / 'runtime.ini'}: 30 bytes, more than the 10 read: not read; the controller starts "
        "without it",)
