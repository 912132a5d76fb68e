"""``sensorium run`` against a careless or hostile project: controller names that point outside the
folders looked in, NUL bytes, output that is binary, huge or not UTF-8 on a terminal that is not
UTF-8, a broken runtime.ini, controllers that exit at once, never attach, or leave processes
behind. Each ends in one line and a run that ends; nothing it started outlives it (but a process
that left the controller's process group, which is said)."""

from __future__ import annotations

import io
import os
import signal
import stat
import sys
from pathlib import Path

import pytest
from _serve import ANY_PORT, Proc, alive, sensorium, wait_until

from sensorium import launch
from sensorium.launch import ControllerSpec, Launcher, LaunchError, find_controller, name_problem

WORLD = '''#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
{robots}
'''
STEPPER = '''from controller import Robot
robot = Robot()
steps = 0
while robot.step(16) != -1:
    steps += 1
print(robot.getName(), "stepped", steps)
'''


def project(tmp_path: Path, robots: str, controllers: dict[str, str]) -> Path:
    (tmp_path / "worlds").mkdir(parents=True)
    world = tmp_path / "worlds" / "w.wbt"
    world.write_text(WORLD.replace("{robots}", robots))
    for name, text in controllers.items():     # NAME.py, NAME (an executable) or FOLDER/FILE
        path = tmp_path / "controllers" / (name if "/" in name else f"{name.split('.')[0]}/{name}")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        if not name.endswith((".py", ".ini")):
            path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return world


def run(world: Path, *extra: str) -> Proc:
    """``sensorium run`` on free loopback ports (a fixed one may be any process's ephemeral port:
    that made CI fail with 'Address already in use')."""
    return Proc(sensorium("run", str(world), "--rpc", ANY_PORT, "--pub", ANY_PORT, *extra),
                env={"WEBOTS_HOME": None, "WEBOTS_EXTRA_PROJECT_PATH": None})


# ---------------------------------------------------------------------- no process

@pytest.mark.parametrize("name", ["../evil", "/ABS/evil", "sub/evil", "..", ".", "", "ev\0il"])
def test_a_controller_name_that_is_no_folder_name_is_refused_in_one_line(tmp_path: Path, name: str) -> None:
    """A world must not make `run` start a program outside the controllers/ folders it looks in:
    before, '../evil' found PROJECT/evil.py and '/ABS/evil' found /ABS/evil.py."""
    for where in (tmp_path / "evil", tmp_path / "ABS" / "evil", tmp_path / "controllers" / "sub" / "evil"):
        where.mkdir(parents=True)
        (where.parent / "evil.py").write_text("print('outside')\n")
        (where / "evil.py").write_text("print('outside')\n")
    name = name.replace("/ABS", str(tmp_path / "ABS"))
    with pytest.raises(LaunchError) as info:
        find_controller("r", name, [], [tmp_path / "controllers"])
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"robot 'r': controller {name!r} ")
    assert text.endswith(": not looked for (a controller is named by its folder in a controllers/ folder)")
    assert name_problem("avoid") is None and name_problem("e-puck avoid (2)") is None


def test_a_nul_byte_in_controller_args_is_one_line_not_a_traceback(tmp_path: Path) -> None:
    folder = tmp_path / "controllers" / "c"
    folder.mkdir(parents=True)
    (folder / "c").write_text("#!/bin/sh\n")
    (folder / "c").chmod(0o755)
    spec = ControllerSpec("r", "c", folder, folder / "c", False, ("ok", "bad\0arg"))
    err = io.StringIO()
    launcher = Launcher([spec], "tcp://127.0.0.1:48799", err=err)
    try:
        launcher.start("r")
    finally:
        launcher.close()
    assert launcher.failed == {"r": "c"} and not launcher.running
    assert err.getvalue() == ("sensorium run: 'c' controller of robot 'r' failed to start: embedded null byte "
                              f"({str(folder / 'c')!r}): the robot runs without a controller\n")


def pump(data: bytes, sink: io.TextIOBase) -> None:
    launcher = Launcher([], "tcp://127.0.0.1:48799")
    try:
        launcher._pump("r", io.BufferedReader(io.BytesIO(data)), sink)    # type: ignore[arg-type]
    finally:
        launcher.close()


def test_a_huge_line_comes_out_in_bounded_pieces_without_cutting_a_character() -> None:
    line = "a" * (launch.LINE_MAX - 1) + "é" + "ü" * launch.LINE_MAX + "\x00\x1b[2J end"
    sink = io.StringIO()
    pump(line.encode() + b"\nnext\n\xff\xfe garbage", sink)
    out = sink.getvalue().split("\n")
    assert out[-1] == "" and out[-3:-1] == ["[r] next", "[r] \ufffd\ufffd garbage"]
    pieces = out[:-3]
    assert all(p.startswith("[r] ") and len(p.encode()) <= launch.LINE_MAX + 4 for p in pieces)
    assert "".join(p[4:] for p in pieces) == line           # é (2 bytes) across the first cut is kept whole


def test_output_a_terminal_cannot_encode_is_replaced_and_the_rest_still_comes_out() -> None:
    raw = io.BytesIO()
    sink = io.TextIOWrapper(raw, encoding="ascii", errors="strict", write_through=True)
    pump("température 20 °C\nsecond line\n".encode(), sink)
    assert raw.getvalue() == b"[r] temp?rature 20 ?C\n[r] second line\n"


# ---------------------------------------------------------------------- processes

def test_a_broken_runtime_ini_is_one_line_and_every_controller_runs(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\nRobot { name "beta" controller "b" }',
                    {"a.py": STEPPER, "b.py": STEPPER,
                     "a/runtime.ini": "[environment variables]\nA;B = 1\n",
                     "b/runtime.ini": "[environment variables]\nX = y\n" + "X = $(X)$(X)\n" * 30})
    proc = run(world, "--until", "320")
    assert proc.wait() == 0, proc.stderr()
    out, err = proc.stdout().splitlines(), proc.stderr().splitlines()
    assert "[alpha] alpha stepped 20" in out and "[beta] beta stepped 20" in out
    ini_a, ini_b = tmp_path / "controllers" / "a" / "runtime.ini", tmp_path / "controllers" / "b" / "runtime.ini"
    assert (f"sensorium run: robot 'alpha': {ini_a}: line 2: a ';' before the '=' ('A;B = 1'): Webots reads none "
            "of this file then; the controller starts without it") in err
    assert (f"sensorium run: robot 'beta': {ini_b}: line 25: X's value with its $(...) references replaced makes the "
            "file's values longer than the 4194304 characters set at most; the controller starts without it") in err


def test_a_controller_that_exits_at_once_and_one_that_floods_its_output(tmp_path: Path) -> None:
    """One exits before it attaches: said, the world does not wait for it. One prints 10 MB on one
    line and binary garbage, then steps: its lines come out in 64 KiB pieces, the world goes on."""
    flood = ('import os, sys\nfrom controller import Robot\n'
             'sys.stdout.buffer.write(b"x" * 10_000_000 + b"\\n" + bytes(range(256)) + b"\\n")\n'
             'sys.stdout.flush()\n' + STEPPER.split("\n", 1)[1])
    world = project(tmp_path, 'Robot { name "quick" controller "q" }\nRobot { name "loud" controller "f" }',
                    {"q": "#!/bin/sh\nexit 0\n", "f.py": flood})
    proc = run(world, "--until", "160")
    assert proc.wait() == 0, proc.stderr()
    assert "sensorium run: 'q' controller of robot 'quick' exited successfully." in proc.stderr().splitlines()
    out = proc.stdout().splitlines()
    assert "[loud] loud stepped 10" in out
    xs = [line for line in out if line.startswith("[loud] x")]
    assert sum(len(line) - len("[loud] ") for line in xs) == 10_000_000
    assert max(len(line) for line in xs) == len("[loud] ") + launch.LINE_MAX


def test_processes_a_controller_leaves_behind_are_ended_or_said(tmp_path: Path) -> None:
    """A child in the controller's process group is ended with it; one that left the group (a new
    session) and holds the controller's output does not hold `run`: one line says it."""
    kid = ('import os, subprocess, sys\nfrom controller import Robot\nrobot = Robot()\n'
           'a = subprocess.Popen(["sleep", "300"])\n'
           'b = subprocess.Popen(["sleep", "301"], start_new_session=True)\n'
           'open("pids", "w").write(f"{a.pid} {b.pid}")\n'
           'while robot.step(16) != -1:\n    pass\n')
    world = project(tmp_path, 'Robot { name "parent" controller "k" }', {"k.py": kid})
    proc = run(world, "--until", "320")
    try:
        assert proc.wait() == 0, proc.stderr()
        a, b = (int(x) for x in (tmp_path / "controllers" / "k" / "pids").read_text().split())
        wait_until(lambda: not alive(a), what="the child in the controller's group to end")
        assert alive(b)
        assert ("sensorium run: 'k' controller of robot 'parent': a process it started outside its process group "
                "still holds its output: not read further, not ended") in proc.stderr().splitlines()
    finally:
        pids = (tmp_path / "controllers" / "k" / "pids")
        if pids.exists():
            for pid in (int(x) for x in pids.read_text().split()):
                if alive(pid):
                    os.kill(pid, signal.SIGKILL)


@pytest.mark.skipif(sys.platform != "linux", reason="Linux process groups")
def test_a_controller_that_exits_leaving_a_child_is_said_at_once(tmp_path: Path) -> None:
    """Its 'exited' line does not wait for the child holding its output (it waited for the end)."""
    world = project(tmp_path, 'Robot { name "alpha" controller "s" }\nRobot { name "beta" controller "b" }',
                    {"s": "#!/bin/sh\nsleep 300 &\necho $! > pid\nexit 4\n", "b.py": STEPPER})
    proc = run(world)
    try:
        wait_until(lambda: "sensorium run: 's' controller of robot 'alpha' exited with status: 4." in proc.stderr(),
                   timeout=60, what="the exited line while its child lives")
        pid = int((tmp_path / "controllers" / "s" / "pid").read_text())
        assert alive(pid)
        proc.stop(signal.SIGTERM)
        wait_until(lambda: not alive(pid), what="the child to end with the run")
    finally:
        proc.stop()


def test_a_controller_that_never_attaches_is_waited_for_or_ended_at_attach_timeout(tmp_path: Path) -> None:
    """As Webots, the world waits for a started controller to attach (no bound by default: a
    controller may import for long); --attach-timeout S ends one that has not attached after S
    seconds: one line, its robot runs without a controller, the world goes on, run exits 1."""
    world = project(tmp_path, 'Robot { name "stuck" controller "hang" }\nRobot { name "beta" controller "b" }',
                    {"hang": "#!/bin/sh\necho $$ > pid\nexec sleep 600\n", "b.py": STEPPER})
    proc = run(world, "--until", "320", "--attach-timeout", "1.5")
    assert proc.wait() == 1, proc.stderr()
    err = proc.stderr().splitlines()
    assert ("sensorium run: 'hang' controller of robot 'stuck' did not attach within 1.5 s (--attach-timeout): "
            "ended; the robot runs without a controller") in err
    assert err[-1] == ("sensorium run: 1 robot ran without the controller the world names: 'stuck' ('hang') (exit "
                       "status 1; --require-controllers refuses to start instead)")
    assert "[beta] beta stepped 20" in proc.stdout().splitlines()
    assert not alive(int((tmp_path / "controllers" / "hang" / "pid").read_text()))


@pytest.mark.parametrize("bad", [0.0, -1.0, float("inf"), float("nan")])
def test_a_bad_attach_timeout_is_one_line(tmp_path: Path, bad: float) -> None:
    (tmp_path / "w.yaml").write_text("")
    with pytest.raises(ValueError, match=r"^--attach-timeout must be a finite number of seconds > 0, got "):
        launch.RunOptions(attach_timeout_s=bad).check(tmp_path / "w.yaml")


# ---------------------------------------------------------------------- extra project paths (no process)

def test_extra_project_paths_split_like_path_each_once_at_most_64(tmp_path: Path) -> None:
    value = ":".join(["", "a", "a", "b::c", "", *(f"p{i}" for i in range(100)), ""])
    got = launch.extra_project_paths(value)
    cwd = Path.cwd()
    assert got[:3] == [cwd / "a", cwd / "b", cwd / "c"] and len(got) == launch.EXTRA_MAX
    assert len(launch.extra_project_paths(value, None)) == 103
    assert launch.extra_project_paths("") == launch.extra_project_paths(":::") == []


def test_more_than_64_extra_project_paths_is_one_line(monkeypatch: pytest.MonkeyPatch,
                                                      capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    from argparse import Namespace

    from sensorium.cli import _export_proto_args
    monkeypatch.setenv("WEBOTS_EXTRA_PROJECT_PATH", ":".join(str(tmp_path / f"p{i}") for i in range(70)))
    monkeypatch.delenv("SENSORIUM_PROTO_PATH", raising=False)
    _export_proto_args(Namespace(extra_project_path=[str(tmp_path / "first")]))
    assert capsys.readouterr().err == (
        f"sensorium: 71 extra project paths (--extra-project-path, $WEBOTS_EXTRA_PROJECT_PATH): the first 64 are "
        f"read, not {tmp_path / 'p63'} and the 6 after it\n")
    assert os.environ["WEBOTS_EXTRA_PROJECT_PATH"].split(":")[:2] == [str(tmp_path / "first"), str(tmp_path / "p0")]


def test_extra_projects_that_are_no_folder_or_a_symlink_loop_are_passed_over(tmp_path: Path) -> None:
    world = project(tmp_path / "proj", 'Robot { name "r" controller "c" }', {})
    (tmp_path / "file").write_text("")
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    (tmp_path / "x" / "controllers" / "c").mkdir(parents=True)
    (tmp_path / "x" / "controllers" / "c" / "c.py").write_text("")
    extra = (tmp_path / "file", tmp_path / "loop", tmp_path / "missing", tmp_path / "x")
    runner = launch.ProjectRun(world, launch.RunOptions(extra_projects=extra))
    assert runner.projects == [tmp_path / "x"]
    spec = find_controller("r", "c", [], runner.dirs)
    assert spec.folder == tmp_path / "x" / "controllers" / "c"


def test_the_proto_index_of_a_huge_tree_of_folders_is_bounded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Folders count in the bound as files do: a tree of empty folders (or a deep one) is not
    walked to its end (before, only files counted)."""
    from sensorium.server.world.proto import resolve
    monkeypatch.setattr(resolve, "_INDEX_ENTRIES", 20)
    deep = tmp_path / "protos"
    for i in range(40):
        deep = deep / f"d{i:02}"
    deep.mkdir(parents=True)
    (deep / "Far.proto").write_text("")
    (tmp_path / "protos" / "Near.proto").write_text("")
    (tmp_path / "protos" / "loop").symlink_to(tmp_path / "protos")
    index = resolve.proto_index(tmp_path / "protos")
    assert "Near.proto" in index and "Far.proto" not in index


def test_without_attach_timeout_the_world_waits_and_says_so(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """In process (the library's run; the controller is a subprocess): a controller that never
    attaches is waited for, as Webots waits, with one line after ATTACH_NOTE_S; stop() ends it."""
    import threading

    from sensorium.server.daemon.serve import ServeOptions
    monkeypatch.setattr(launch, "ATTACH_NOTE_S", 0.5)
    world = project(tmp_path, 'Robot { name "stuck" controller "hang" }',
                    {"hang": "#!/bin/sh\necho $$ > pid\nexec sleep 600\n"})
    out, err = io.StringIO(), io.StringIO()
    options = launch.RunOptions(serve=ServeOptions(rpc=ANY_PORT, pub=ANY_PORT))
    project_run = launch.ProjectRun(world, options, out=out, err=err)
    status: list[int] = []
    thread = threading.Thread(target=lambda: status.append(project_run.run(signals=False)))
    thread.start()
    note = ("sensorium run: the world waits for the 'hang' controller of robot 'stuck', started 0.5 s ago, to attach "
            "(as Webots waits; --attach-timeout S ends it instead)")
    try:
        wait_until(lambda: note in err.getvalue(), what="the waiting line")
    finally:
        project_run.stop()
        thread.join(120)
    assert not thread.is_alive() and status == [0], err.getvalue()
    assert "sensorium: stopped at 0 ms after 0 steps" in err.getvalue().splitlines()
    assert not alive(int((tmp_path / "controllers" / "hang" / "pid").read_text()))


def test_a_python_command_with_spaces_and_quotes_is_one_program(tmp_path: Path) -> None:
    """[python] COMMAND names one program, as Webots starts it (no shell): a quoted path with a space
    runs; "python3 -u" is no program: one line naming it, the robot runs without a controller."""
    spaced = tmp_path / "my python" / "py"
    spaced.parent.mkdir()
    spaced.write_text(f'#!/bin/sh\necho "wrapped $1" >&2\nexec "{sys.executable}" "$@"\n')
    spaced.chmod(0o755)
    world = project(tmp_path / "p", 'Robot { name "good" controller "g" }\nRobot { name "bad" controller "b" }',
                    {"g.py": STEPPER, "b.py": STEPPER,
                     "g/runtime.ini": f'[python]\nCOMMAND = "{spaced}" ; a comment\nOPTIONS = -B\n',
                     "b/runtime.ini": '[python]\nCOMMAND = "python3 -u"\n'})
    proc = run(world, "--until", "160")
    assert proc.wait() == 1, proc.stderr()
    err = proc.stderr().splitlines()
    assert "[good] wrapped -B" in err and "[good] good stepped 10" in proc.stdout().splitlines()
    assert ("sensorium run: 'b' controller of robot 'bad' failed to start: No such file or directory ('python3 -u'): "
            "the robot runs without a controller") in err


def test_a_wbt_world_naming_a_controller_outside_its_project_runs_without_it(tmp_path: Path) -> None:
    """The .wbt reader makes such a robot Webots' <generic> (one warning): run starts nothing
    for it and does not wait for it (it was <extern>: run waited forever for a controller)."""
    world = project(tmp_path, 'Robot { name "r" controller "../../../bin/sh" }\nRobot { name "s" controller "x/y" }\n'
                              'Robot { name "u" controller "<unknown>" }\nRobot { name "beta" controller "b" }',
                    {"b.py": STEPPER})
    proc = run(world, "--until", "160")
    assert proc.wait() == 0, proc.stderr()
    err = proc.stderr()
    assert ("Robot 'r': controller '../../../bin/sh' is no controller's name (a folder under controllers/): the robot "
            "has Webots' <generic> controller (none under sensorium run, an <extern> one under serve)") in err
    assert ("sensorium run: robot 's': controller '<generic>' (Webots' one only steps): the robot runs without a "
            "controller") in err.splitlines()
    assert "[beta] beta stepped 10" in proc.stdout().splitlines()
    assert ("Robot 'u': controller '<unknown>' is unknown: the robot has Webots' <generic> controller (none under "
            "sensorium run, an <extern> one under serve)") in err
