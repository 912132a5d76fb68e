"""``sensorium controller`` starts a controller in its own folder, as Webots' launcher does: the files
a Webots controller opens or saves by a relative name (a display sample's emoticons, a camera's
``saveImage``) are its folder's, whatever folder the launcher was run from."""

from __future__ import annotations

import os
import stat
from pathlib import Path

from _serve import REPO, run_controller, sensorium

WORLD = REPO / "tests" / "worlds" / "display.yaml"

PYTHON_CONTROLLER = '''
import os
from controller import Robot
robot = Robot()
with open("where.txt", "w") as f:       # a relative name, as Webots' samples use
    f.write(os.getcwd())
robot.step(int(robot.getBasicTimeStep()))
print("done")
'''

SHELL_CONTROLLER = '''#!/bin/sh
pwd > where.txt
echo done
'''


def _run(tmp_path: Path, name: str, text: str) -> Path:
    folder = tmp_path / "controllers" / "probe"
    folder.mkdir(parents=True)
    script = folder / name
    script.write_text(text)
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    lines, err = run_controller(WORLD, lambda url: sensorium("controller", str(script.relative_to(tmp_path)),
                                                              "--url", url), cwd=tmp_path)
    assert lines[-1:] == ["done"], err
    assert not (tmp_path / "where.txt").exists()
    return folder


def test_a_python_controller_runs_in_its_own_folder(tmp_path: Path) -> None:
    folder = _run(tmp_path, "probe.py", PYTHON_CONTROLLER)
    assert Path((folder / "where.txt").read_text()).resolve() == folder.resolve()


def test_an_executable_controller_runs_in_its_own_folder(tmp_path: Path) -> None:
    folder = _run(tmp_path, "probe", SHELL_CONTROLLER)
    assert Path((folder / "where.txt").read_text().strip()).resolve() == folder.resolve()
    assert os.access(folder / "probe", os.X_OK)
