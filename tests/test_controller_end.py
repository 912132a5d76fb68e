"""The end of a controller, as libController ends it: once wb_robot_step has answered -1 because the
simulation ended for the controller (here the server stops at ``--until``), the next step ends the
process with status 0, so a loop that ignores -1 (Webots' khepera_gripper sample loops while the step
is not 1) does not spin forever. The C twin is in tests/test_c_client.py."""

from __future__ import annotations

import subprocess
import sys

from _serve import REPO, child_env, serve

ARENA = REPO / "sensorium" / "worlds" / "arena.yaml"
CONTROLLER = REPO / "tests" / "controllers" / "ignores_minus_one.py"


def test_a_python_loop_that_ignores_minus_one_ends_at_the_next_step():
    with serve(ARENA, "--until", "160") as server:
        done = subprocess.run([sys.executable, "-m", "sensorium", "controller", "--url", server.url("epuck"),
                               str(CONTROLLER)], capture_output=True, text=True, timeout=120, env=child_env(),
                              cwd=str(REPO))
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-1] == "-1" and lines[:-1] and set(lines[:-1]) == {"0"}, lines
