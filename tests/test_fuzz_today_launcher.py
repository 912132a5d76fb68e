"""Hypothesis fuzz of ``sensorium run``'s launcher switching controllers (launch.Launcher.switch, a
Supervisor setting a robot's ``controller``) interleaved with restartController (Launcher.restart),
on two robots whose controllers are real processes that never attach (they sleep): names found,
not found, ``<extern>`` (synchronous or not), ``<none>``, ``''``. Once the launcher's queue is done,
each robot runs exactly the one process its last controller names (none for the others), every
process it ended has exited, the world waits (``starting``) exactly for the robots whose controller
was started or is an ``<extern>`` one a synchronous robot waits for, and closing leaves no process."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.launch import ControllerSpec, Launcher, LaunchError
from tests._serve import wait_until

pytestmark = pytest.mark.slow

ROBOTS = ("r1", "r2")
FOUND = ("sleeper", "napper")


def specs_in(tmp: Path) -> dict[str, Path]:
    out = {}
    for name in FOUND:
        folder = tmp / "controllers" / name
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{name}.py").write_text("import time\ntime.sleep(120)\n")
        out[name] = folder
    return out


@settings(SETTINGS, max_examples=12)
@given(st.lists(st.one_of(
    st.tuples(st.just("switch"), st.sampled_from(ROBOTS),
              st.sampled_from([*FOUND, "missing", "<extern>", "<none>", ""]), st.booleans()),
    st.tuples(st.just("restart"), st.sampled_from(ROBOTS), st.just(""), st.just(False))), min_size=1, max_size=8))
def test_switches_and_restarts_leave_one_process_per_named_controller(tmp_path_factory, ops):
    folders = specs_in(tmp_path_factory.mktemp("proj"))

    def spec(robot: str, name: str) -> ControllerSpec:
        return ControllerSpec(robot, name, folders[name], folders[name] / f"{name}.py", True)

    def find(robot: str, name: str) -> ControllerSpec:
        if name not in folders:
            raise LaunchError(f"robot {robot!r}: no controller {name!r} found")
        return spec(robot, name)

    lines = io.StringIO()
    launcher = Launcher([spec("r1", "sleeper")], "tcp://127.0.0.1:1", out=lines, err=lines, grace_s=5.0)
    starting: set[str] = set()
    launcher.bind(starting, lambda: None, lambda: False)
    launcher.find = find
    seen = []          # every process the launcher ran
    last = {"r1": "sleeper", "r2": None}      # the name each robot's controller field has (None: none)
    waits = {"r1": True, "r2": False}         # whether the world waits for the robot now
    try:
        launcher.start("r1")

        def settled() -> bool:
            with launcher._lock:
                if launcher._restarts:
                    return False
                for robot in ROBOTS:
                    run = launcher.running.get(robot)
                    want = last[robot] in FOUND
                    if want != (run is not None and run.proc.poll() is None and not run.ending):
                        return False
                    if run is not None and all(run.proc is not p for p in seen):
                        seen.append(run.proc)
            return True

        for op, robot, name, synchronous in ops:
            if op == "switch":
                launcher.switch(robot, name, synchronous)
                last[robot] = name
                waits[robot] = name in FOUND or (name == "<extern>" and synchronous)
            else:
                launcher.restart(robot)
                waits[robot] = waits[robot] or last[robot] in FOUND
            wait_until(settled, timeout=60.0, what=f"the launcher's queue after {op} {robot} {name!r}")
            for robot_ in ROBOTS:
                run = launcher.running.get(robot_)
                if last[robot_] in FOUND:
                    assert run is not None and run.spec.name == last[robot_], (robot_, last, run)
                assert (robot_ in starting) == waits[robot_], (robot_, starting, waits, ops)
            current = [r.proc for r in launcher.running.values() if r.proc.poll() is None]
            # the ones ended are gone (a process ended by a switch or a restart is waited for)
            wait_until(lambda current=current: all(p.poll() is not None for p in seen
                                                   if all(p is not c for c in current)),
                       timeout=30.0, what="ended controllers to exit")
    finally:
        launcher.close()
    assert all(p.poll() is not None for p in seen), "a controller outlived the launcher"
    assert "Traceback" not in lines.getvalue(), lines.getvalue()


def test_a_switch_says_what_the_new_controllers_load_said(tmp_path: Path) -> None:
    """A Supervisor's switch to a controller found with notes (runtime.ini's, a library folder left off)
    or in Webots' projects prints those lines, as ``run`` prints them for the world's controllers."""
    folders = specs_in(tmp_path)
    lines = io.StringIO()
    launcher = Launcher([], "tcp://127.0.0.1:1", out=lines, err=lines, grace_s=5.0)
    launcher.bind(set(), lambda: None, lambda: False)
    launcher.find = lambda robot, name: ControllerSpec(
        robot, name, folders[name], folders[name] / f"{name}.py", True, webots=True,
        notes=(f"robot '{robot}': runtime.ini: a note",))
    try:
        launcher.switch("r2", "sleeper", False)
        assert lines.getvalue().splitlines()[:2] == [
            f"sensorium run: robot 'r2': controller 'sleeper' found in Webots' projects: "
            f"{folders['sleeper'] / 'sleeper.py'}",
            "sensorium run: robot 'r2': runtime.ini: a note"]
    finally:
        launcher.close()
