"""``sensorium run WORLD``: a Webots project of our own (worlds/ and controllers/ in a tmp folder)
runs with one command: its named controllers are found and started as Webots starts them (their
folder, their controllerArgs), their lines come out as ``[ROBOT] ...``, the world ends at ``--until``
with every controller gone; restartController and worldReload restart them, worldLoad starts another world's."""

from __future__ import annotations

import os
import shutil
import signal
import stat
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
from _serve import REPO, Proc, alive, run_controller, sensorium, wait_until

from sensorium import launch
from sensorium.launch import LaunchError, WebotsProjects, find_controller
from sensorium.schemas.world import Robot as WorldRobot

WORLD = '''#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
{robots}
'''

# a controller that says where it runs, with which arguments, counts its steps and writes its pid
COUNTER = '''import os, sys
from controller import Robot
robot = Robot()
with open(f"pid-{robot.getName()}", "a") as f:
    f.write(f"{os.getpid()}\\n")
print(robot.getName(), "args", sys.argv[1:], "in", os.path.basename(os.getcwd()))
steps = 0
while robot.step({step}) != -1:
    steps += 1
print(robot.getName(), "stepped", steps, "until", round(robot.getTime() * 1000))
'''


def project(tmp_path: Path, robots: str, controllers: dict[str, str]) -> Path:
    """worlds/w.wbt with ``robots``, and controllers/NAME/NAME.py (or an executable NAME) for each."""
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "w.wbt"
    world.write_text(WORLD.replace("{robots}", robots))
    for name, text in controllers.items():
        folder = tmp_path / "controllers" / name.split(".")[0]
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / name
        path.write_text(text)
        if not name.endswith(".py"):
            path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return world


def run(world: Path, *extra: str, env: dict | None = None) -> Proc:
    return Proc(sensorium("run", str(world), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0", *extra),
                env=env)


def pids(folder: Path, robot: str) -> list[int]:
    path = folder / f"pid-{robot}"
    return [int(x) for x in path.read_text().split()] if path.exists() else []


# ---------------------------------------------------------------------- finding controllers (no process)

def test_controllers_are_found_in_webots_order_and_others_are_refused(tmp_path: Path) -> None:
    base = tmp_path / "controllers"
    (base / "both").mkdir(parents=True)
    (base / "both" / "both.py").write_text("")
    exe = base / "both" / "both"
    exe.write_text("#!/bin/sh\n")
    exe.chmod(0o755)
    spec = find_controller("r", "both", ["x"], [base])          # an executable comes before NAME.py
    assert (spec.program, spec.python, spec.folder, spec.args) == (exe, False, base / "both", ("x",))
    exe.unlink()
    assert find_controller("r", "both", [], [base]).program == base / "both" / "both.py"

    (base / "java").mkdir()
    (base / "java" / "java.jar").write_text("")
    with pytest.raises(LaunchError, match=r"java\.jar is a Java controller, which Sensorium does not run"):
        find_controller("r", "java", [], [base])
    (base / "src").mkdir()
    (base / "src" / "src.c").write_text("")
    with pytest.raises(LaunchError, match=r"has none of src, src\.py .*its C/C\+\+ source is there"):
        find_controller("r", "src", [], [base])
    other = tmp_path / "more"
    with pytest.raises(LaunchError) as info:
        find_controller("r", "gone", [], [base, other])
    assert str(info.value) == (f"robot 'r': controller 'gone' not found (looked for the folder {base / 'gone'}, "
                               f"{other / 'gone'}; --webots-home DIR also looks in Webots' own projects)")


def robot(name: str, controller: str, *args: str, synchronization: bool = True) -> SimpleNamespace:
    """A loaded world's robot as the planner reads it."""
    return SimpleNamespace(name=name, controller=controller, controller_args=list(args), synchronization=synchronization)


def test_a_world_is_planned_without_a_process(tmp_path: Path) -> None:
    """What run does with a world is data: the controllers to start, the problems, the lines to say
    and the robots waited for, decided before anything starts."""
    base = tmp_path / "controllers"
    (base / "a").mkdir(parents=True)
    (base / "a" / "a.py").write_text("")
    robots = [robot("alpha", "a", "--fast"), robot("ext", "<extern>"), robot("free", "<extern>", synchronization=False),
              robot("gen", "<generic>"), robot("off", "<none>"), robot("lost", "nowhere"),
              WorldRobot(name="bare"), WorldRobot(name="said", controller="<extern>")]
    got = launch.plan_world(robots, [base], "tcp://127.0.0.1:5555", wbt=True)
    assert [(s.robot, s.program, s.args) for s in got.specs] == [("alpha", base / "a" / "a.py", ("--fast",))]
    assert got.problems == (f"robot 'lost': controller 'nowhere' not found (looked for the folder {base / 'nowhere'}; "
                            "--webots-home DIR also looks in Webots' own projects)",)
    assert got.notes == (
        "robot 'ext' is <extern>: attach its controller with `sensorium controller SCRIPT --robot ext --url "
        "tcp://127.0.0.1:5555`",
        "robot 'free' is <extern>: attach its controller with `sensorium controller SCRIPT --robot free --url "
        "tcp://127.0.0.1:5555`",
        "robot 'gen': controller '<generic>' (Webots' one only steps): the robot runs without a controller",
        "robot 'bare': no controller field, so Webots' default '<generic>' (Webots' one only steps): the robot runs "
        "without a controller",
        "robot 'said' is <extern>: attach its controller with `sensorium controller SCRIPT --robot said --url "
        "tcp://127.0.0.1:5555`")
    assert got.extern_waited == {"ext", "said"}
    # not <generic>, not 'lost', not 'bare' (a .wbt robot without a controller field): the world goes on without them
    assert got.extern_synchronous == ("ext", "said")
    assert got.missing == (("lost", "nowhere"),)
    # in a YAML world a robot without a controller is Sensorium's default, <extern>: waited for
    assert launch.plan_world([WorldRobot(name="bare")], [base], "tcp://127.0.0.1:5555").extern_synchronous == ("bare",)


@pytest.mark.parametrize(("reload", "interrupted", "quit_status", "again", "status", "status_missing"), [
    (False, False, None, False, 0, 1),        # --until, or the server stopped
    (True, False, None, True, 0, 1),          # worldReload
    (True, True, None, False, 0, 1),          # a reload asked, then Ctrl-C: no reload
    (True, False, 3, False, 3, 3),            # a reload and a simulationQuit(3): the quit wins
    (False, False, 259, False, 3, 3),         # simulationQuit's low 8 bits, as a process's status
    (False, False, 0, False, 0, 1),           # a supervisor's pass does not hide a robot that ran without its controller
    (False, False, 256, False, 0, 1),
])
def test_after_a_server_stops_the_run_reloads_or_ends_with_a_status(reload: bool, interrupted: bool,
                                                                     quit_status: int | None, again: bool,
                                                                     status: int, status_missing: int) -> None:
    assert launch.after_run(reload, interrupted, quit_status) is again
    assert launch.exit_status(quit_status) == status
    assert launch.exit_status(quit_status, missing=True) == status_missing
    assert launch.exit_status(quit_status, load_refused=True) == status_missing


def test_world_load_names_a_world_from_the_controllers_folder_inside_the_first_worlds_folder(tmp_path: Path) -> None:
    """Webots takes worldLoad's relative name from the Supervisor's controller folder; `run` also keeps
    the new world in the folder of the world it started with (a world from elsewhere would start
    another project's controllers), and it must exist and be a world file."""
    worlds = tmp_path / "worlds"
    (worlds / "more").mkdir(parents=True)
    folder = tmp_path / "controllers" / "boss"
    folder.mkdir(parents=True)
    for name in ("b.wbt", "more/c.yaml", "notes.txt"):
        (worlds / name).write_text("")
    elsewhere = tmp_path / "other" / "worlds"
    elsewhere.mkdir(parents=True)
    (elsewhere / "x.wbt").write_text("")
    (worlds / "link.wbt").symlink_to(elsewhere / "x.wbt")
    assert launch.world_to_load("../../worlds/b.wbt", folder, worlds) == worlds / "b.wbt"
    assert launch.world_to_load(str(worlds / "more" / "c.yaml"), folder, worlds) == worlds / "more" / "c.yaml"
    assert launch.world_to_load(str(worlds / "b.wbt"), None, worlds) == worlds / "b.wbt"   # an <extern> one: absolute
    refused = {
        "b.wbt": f"{folder / 'b.wbt'} is outside {worlds}, the folder of the world `sensorium run` started with (a "
                 "world from elsewhere would start another project's controllers)",    # taken from the controller's
        "../../worlds/gone.wbt": f"no world file {worlds / 'gone.wbt'}",
        "../../worlds/notes.txt": f"{worlds / 'notes.txt'} is not a world file (.wbt; YAML or JSON: .yaml, .yml, .json)",
        "../../other/worlds/x.wbt": f"{elsewhere / 'x.wbt'} is outside {worlds}, the folder of the world `sensorium "
                                    "run` started with (a world from elsewhere would start another project's controllers)",
        "../../worlds/link.wbt": f"{elsewhere / 'x.wbt'} is outside {worlds}, the folder of the world `sensorium "
                                 "run` started with (a world from elsewhere would start another project's controllers)",
        "": "no file named",
    }
    for name, why in refused.items():
        with pytest.raises(LaunchError) as info:
            launch.world_to_load(name, folder, worlds)
        assert str(info.value) == why, name
    with pytest.raises(LaunchError, match=r"^a relative name is taken from the controller's folder, and this robot's "
                                          r"controller was not started by `sensorium run`: give the world file's "
                                          r"absolute path$"):
        launch.world_to_load("../../worlds/b.wbt", None, worlds)


def test_world_load_refusals_stay_one_line_whatever_the_name_holds(tmp_path: Path) -> None:
    """A Supervisor's worldLoad argument is any string: a newline, carriage return, tab or Unicode line
    separator in it (or in a real file's name) is written as its escape in the refusal, never a second
    line in `run`'s output; a symbolic link loop and a 4096-character name are one line too."""
    worlds = tmp_path / "worlds"
    worlds.mkdir()
    folder = tmp_path / "controllers" / "boss"
    folder.mkdir(parents=True)
    (worlds / "a\nb.txt").write_text("")
    (worlds / "loop1").symlink_to("loop2")
    (worlds / "loop2").symlink_to("loop1")
    refused = {
        "../../worlds/a\nb.txt": f"{worlds}/a\\nb.txt is not a world file (.wbt; YAML or JSON: .yaml, .yml, .json)",
        "../../worlds/gone\r\n[boss] fake.wbt": f"no world file {worlds}/gone\\r\\n[boss] fake.wbt",
        "x\tq\u2028.wbt": f"{folder}/x\\tq\\u2028.wbt is outside {worlds}, the folder of the world `sensorium run` "
                          "started with (a world from elsewhere would start another project's controllers)",
    }
    for name, why in refused.items():
        with pytest.raises(LaunchError) as info:
            launch.world_to_load(name, folder, worlds)
        assert str(info.value) == why, name
    for name in ("../../worlds/loop1", "../../worlds/" + "x" * 4083 + "\n"):
        with pytest.raises(LaunchError) as info:
            launch.world_to_load(name, folder, worlds)
        assert str(info.value).isprintable(), (name[:20], str(info.value)[:200])

# ---------------------------------------------------------------------- running a project

def test_two_controllers_run_print_with_their_robot_and_end_at_until(tmp_path: Path) -> None:
    # controllerArgs are the program's arguments one by one, as Webots passes them (no shell: quotes,
    # backslashes, spaces and empty strings arrive as written in the world)
    world = project(tmp_path, 'Robot { name "alpha" controller "a" controllerArgs [ "--say" "hello world" '
                              '"say \\"hi\\" \\\\ $HOME" "" ] }\n'
                              'Robot { name "beta %41" controller "b" }',     # a name a URL must encode
                    {"a.py": COUNTER.replace("{step}", "16"), "b.py": COUNTER.replace("{step}", "32")})
    proc = run(world, "--until", "1600")
    assert proc.wait() == 0, proc.stderr()
    out = proc.stdout().splitlines()
    assert out[0].startswith("sensorium: serving world 'w' rpc=tcp://127.0.0.1:")
    assert """[alpha] alpha args ['--say', 'hello world', 'say "hi" \\\\ $HOME', ''] in a""" in out
    assert "[beta %41] beta %41 args [] in b" in out
    # the world waited for both before it stepped: every step of both, from 0 to --until
    assert "[alpha] alpha stepped 100 until 1600" in out
    assert "[beta %41] beta %41 stepped 50 until 1600" in out
    assert "sensorium: stopped at 1600 ms after 100 steps" in proc.stderr()
    for robot, folder in (("alpha", "a"), ("beta %41", "b")):
        (pid,) = pids(tmp_path / "controllers" / folder, robot)
        assert not alive(pid)


def test_with_require_controllers_a_missing_controller_is_one_line_and_nothing_runs(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "alpha" controller "nowhere" }\nRobot { name "beta" controller "b" }',
                    {"b.py": COUNTER.replace("{step}", "16")})
    proc = run(world, "--require-controllers", env={"WEBOTS_HOME": None, "WEBOTS_EXTRA_PROJECT_PATH": None})
    assert proc.wait() == 1
    assert proc.stderr().strip() == (f"sensorium run: robot 'alpha': controller 'nowhere' not found (looked for the "
                                     f"folder {tmp_path / 'controllers' / 'nowhere'}; --webots-home DIR also looks "
                                     "in Webots' own projects)")
    assert proc.stdout() == "" and not pids(tmp_path / "controllers" / "b", "beta")


def test_a_robot_whose_controller_cannot_start_runs_without_it_and_the_run_exits_1(tmp_path: Path) -> None:
    """As Webots (which warns and starts its <generic> controller): one line naming the robot and
    the controller, the world and the other controllers go on, and the run's status says it."""
    world = project(tmp_path, 'Robot { name "alpha" controller "nowhere" }\nRobot { name "beta" controller "b" }\n'
                              'Robot { name "java" controller "jv" }',
                    {"b.py": COUNTER.replace("{step}", "16"), "jv.jar": ""})
    proc = run(world, "--until", "800", env={"WEBOTS_HOME": None, "WEBOTS_EXTRA_PROJECT_PATH": None})
    assert proc.wait() == 1, proc.stderr()
    assert "[beta] beta stepped 50 until 800" in proc.stdout().splitlines()
    err = proc.stderr().splitlines()
    assert (f"sensorium run: robot 'alpha': controller 'nowhere' not found (looked for the folder "
            f"{tmp_path / 'controllers' / 'nowhere'}; --webots-home DIR also looks in Webots' own projects): the robot "
            "runs without a controller") in err
    assert (f"sensorium run: robot 'java': controller {tmp_path / 'controllers' / 'jv' / 'jv.jar'} is a Java controller, "
            "which Sensorium does not run (Python controllers and executables run; start it as an <extern> "
            "controller): the robot runs without a controller") in err
    assert err[-2:] == ["sensorium: stopped at 800 ms after 50 steps",
                        "sensorium run: 2 robots ran without the controller the world names: 'alpha' ('nowhere'), "
                        "'java' ('jv') (exit status 1; --require-controllers refuses to start instead)"]


def test_a_generic_robot_runs_without_a_controller_and_is_not_waited_for(tmp_path: Path) -> None:
    """Webots' <generic> controller only steps: here the robot runs without one, and a world of
    <generic> robots alone steps by itself to --until (exit 0: the world asked for it). A robot of a
    .wbt world without a controller field has Webots' default, <generic>, under run."""
    world = project(tmp_path, 'Robot { name "gen" controller "<generic>" }\nRobot { name "bare" }', {})
    proc = run(world, "--until", "320")
    assert proc.wait() == 0, proc.stderr()
    err = proc.stderr().splitlines()
    assert ("sensorium run: robot 'gen': controller '<generic>' (Webots' one only steps): the robot runs without a "
            "controller") in err
    assert ("sensorium run: robot 'bare': no controller field, so Webots' default '<generic>' (Webots' one only "
            "steps): the robot runs without a controller") in err
    assert err[-1] == "sensorium: stopped at 320 ms after 20 steps"


def test_a_webots_home_that_is_not_a_folder_is_said(tmp_path: Path) -> None:
    """A mistyped --webots-home was taken silently, and a controller it should have found was "not
    found ... --webots-home DIR also looks in Webots' own projects": one line now says it is no folder."""
    world = project(tmp_path, 'Robot { name "alpha" controller "nowhere" }', {})
    proc = run(world, "--until", "160", "--webots-home", str(tmp_path / "webot"), env={"WEBOTS_EXTRA_PROJECT_PATH": None})
    assert proc.wait() == 1, proc.stderr()
    assert (f"sensorium run: --webots-home (or WEBOTS_HOME) {tmp_path / 'webot'} is not a folder: Webots' own "
            "projects are not looked in for controllers") in proc.stderr().splitlines()


def test_a_controller_that_crashes_is_said_and_the_world_goes_on(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\nRobot { name "beta" controller "quitter" }\n'
                              'Robot { name "gamma" controller "segv" }',
                    {"a.py": COUNTER.replace("{step}", "16"), "quitter": "#!/bin/sh\necho leaving\nexit 3\n",
                     "segv": "#!/bin/sh\nkill -SEGV $$\n"})
    proc = run(world, "--until", "800")
    assert proc.wait() == 0, proc.stderr()
    assert "[beta] leaving" in proc.stdout().splitlines()
    assert "sensorium run: 'quitter' controller of robot 'beta' exited with status: 3." in proc.stderr()
    assert "sensorium run: 'segv' controller of robot 'gamma' crashed (SIGSEGV)." in proc.stderr()
    assert "[alpha] alpha stepped 50 until 800" in proc.stdout().splitlines()


def test_a_controller_killed_without_detaching_is_released_at_once_not_after_its_heartbeats(tmp_path: Path) -> None:
    """A controller process that dies without detaching (SIGKILL, SIGSEGV) holds its robot's session,
    and a synchronous one the world, until its heartbeats time out. `run` sees the process end, so the
    session is dropped then: with --heartbeat-ms 20000 (60 s of silence before a drop) the world still
    reaches --until within the test's wait, where it stood still for those 60 s before."""
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\nRobot { name "beta" controller "dies" }',
                    {"a.py": COUNTER.replace("{step}", "16"),
                     "dies.py": "import os, signal\nfrom controller import Robot\nr = Robot()\nfor _ in range(5):\n"
                                "    r.step(16)\nprint('dying at', round(r.getTime() * 1000))\n"
                                "os.kill(os.getpid(), signal.SIGKILL)\n"})
    proc = run(world, "--until", "800", "--heartbeat-ms", "20000")
    assert proc.wait(30) == 0, proc.stderr()
    assert "[beta] dying at 80" in proc.stdout().splitlines()
    err = proc.stderr().splitlines()
    assert "sensorium run: 'dies' controller of robot 'beta' crashed (SIGKILL)." in err
    assert "sensorium: controller of 'beta' ended without detaching: session dropped, robot released" in err
    assert "[alpha] alpha stepped 50 until 800" in proc.stdout().splitlines()
    assert err[-1] == "sensorium: stopped at 800 ms after 50 steps"


def test_the_world_goes_on_to_until_when_every_started_controller_has_ended(tmp_path: Path) -> None:
    """One controller fails right after it attached, the other ends after five steps: nothing is
    left to wait for, so the world runs by itself to --until, as Webots' goes on without them."""
    world = project(tmp_path, 'Robot { name "alpha" controller "boom" }\nRobot { name "beta" controller "brief" }',
                    {"boom.py": 'from controller import Robot\nRobot()\nraise SystemExit("no such device")\n',
                     "brief.py": 'from controller import Robot\nr = Robot()\nfor _ in range(5):\n    r.step(16)\n'
                                 'print("done at", round(r.getTime() * 1000))\n'})
    proc = run(world, "--until", "800")
    assert proc.wait() == 0, proc.stderr()
    assert "[beta] done at 80" in proc.stdout().splitlines()
    assert "[alpha] no such device" in proc.stderr().splitlines()
    # its end is said even when the world, left to itself, reaches --until before the process is reaped
    assert "sensorium run: 'boom' controller of robot 'alpha' exited with status: 1." in proc.stderr()
    assert "sensorium: stopped at 800 ms after 50 steps" in proc.stderr().splitlines()
    assert "steps by itself" not in proc.stderr()            # serve's line, not run's: the world waited for both


def test_an_extern_robot_waits_for_a_controller_started_by_hand(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\nRobot { name "ext" controller "<extern>" }',
                    {"a.py": COUNTER.replace("{step}", "16")})
    hand = tmp_path / "hand.py"
    hand.write_text(COUNTER.replace("{step}", "16"))
    proc = run(world, "--until", "800")
    ready = proc.wait_line("sensorium: serving world")
    url = ready.split("rpc=")[1].split()[0]
    wait_until(lambda: f"--robot ext --url {url}" in proc.stderr(), what="the <extern> hint")
    with Proc(sensorium("controller", str(hand), "--robot", "ext", "--url", url)) as manual:
        assert manual.wait() == 0, manual.stderr()
        assert manual.stdout().splitlines()[-1].startswith("ext stepped ")
    assert proc.wait() == 0, proc.stderr()
    assert "[alpha] alpha stepped 50 until 800" in proc.stdout().splitlines()


def test_sigterm_ends_every_controller_even_one_that_will_not_go(tmp_path: Path) -> None:
    stubborn = ('import os, signal, time\nfrom controller import Robot\nsignal.signal(signal.SIGTERM, signal.SIG_IGN)\n'
                'robot = Robot()\nopen("pid-" + robot.getName(), "w").write(str(os.getpid()))\n'
                'while robot.step(16) != -1:\n    pass\nprint("ignoring the end")\nwhile True:\n    time.sleep(1)\n')
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\nRobot { name "mule" controller "mule" }',
                    {"a.py": COUNTER.replace("{step}", "16"), "mule.py": stubborn})
    proc = run(world, "--grace", "0.2")
    proc.wait_line("sensorium: serving world")
    wait_until(lambda: pids(tmp_path / "controllers" / "mule", "mule") and pids(tmp_path / "controllers" / "a", "alpha"),
               what="both controllers started")
    proc.p.send_signal(signal.SIGTERM)
    assert proc.wait() == 0, proc.stderr()
    assert "[mule] ignoring the end" in proc.stdout().splitlines()
    assert "'mule' controller of robot 'mule': forced termination" in proc.stderr()
    for pid in (*pids(tmp_path / "controllers" / "mule", "mule"), *pids(tmp_path / "controllers" / "a", "alpha")):
        assert not alive(pid)


RESTARTER = '''import os
from controller import Supervisor
boss = Supervisor()
again = os.path.exists("reloaded")
print("boss starts at", boss.getTime(), "after the reload" if again else "")
while boss.step(16) != -1:
    t = round(boss.getTime() * 1000)
    if t == 480:
        boss.getFromDef("ALPHA").restartController()
    if t == 960 and not again:
        open("reloaded", "w").close()
        boss.worldReload()
print("boss ends at", round(boss.getTime() * 1000))
'''

STARTS = '''from controller import Robot
robot = Robot()
with open("starts.txt", "a") as f:
    f.write(f"{round(robot.getTime() * 1000)}\\n")
while robot.step(16) != -1:
    pass
'''


def test_restart_controller_and_world_reload_start_controllers_again(tmp_path: Path) -> None:
    world = project(tmp_path, 'DEF ALPHA Robot { name "alpha" controller "starts" }\n'
                              'Robot { name "boss" controller "boss" supervisor TRUE }',
                    {"starts.py": STARTS, "boss.py": RESTARTER})
    proc = run(world, "--until", "1200")
    assert proc.wait() == 0, proc.stderr()
    # started at 0, restarted at 480; the reload at 960: time 0 again, restarted at 480; ends at 1200
    assert (tmp_path / "controllers" / "starts" / "starts.txt").read_text().split() == ["0", "480", "0", "480"]
    out = proc.stdout().splitlines()
    assert [line for line in out if line.startswith("[boss]")] == [
        "[boss] boss starts at 0.0 ", "[boss] boss ends at 960", "[boss] boss starts at 0.0 after the reload",
        "[boss] boss ends at 1200"]
    assert sum(line.startswith("sensorium: serving world 'w'") for line in out) == 2
    assert "sensorium run: world reloaded from" in proc.stderr()
    assert "sensorium: stopped at 1200 ms" in proc.stderr()


C_STARTS = r'''#include <math.h>
#include <stdio.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  FILE *f = fopen("starts.txt", "a");
  fprintf(f, "%ld\n", lround(wb_robot_get_time() * 1000));
  fclose(f);
  while (wb_robot_step(16) != -1) {
  }
  wb_robot_cleanup();
  return 0;
}
'''

C_BOSS = r'''#include <math.h>
#include <stdio.h>
#include <unistd.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(int argc, char **argv) {
  wb_robot_init();
  int again = access("reloaded", F_OK) == 0;
  printf("boss starts (%s) at %g%s\n", argc > 1 ? argv[1] : "", wb_robot_get_time(), again ? " after the reload" : "");
  fflush(stdout);
  while (wb_robot_step(16) != -1) {
    long t = lround(wb_robot_get_time() * 1000);
    if (t == 480)
      wb_supervisor_node_restart_controller(wb_supervisor_node_get_from_def("ALPHA"));
    if (t == 960 && !again) {
      fclose(fopen("reloaded", "w"));
      wb_supervisor_world_reload();
    }
  }
  printf("boss ends at %ld\n", lround(wb_robot_get_time() * 1000));
  wb_robot_cleanup();
  return 0;
}
'''


CLIB = REPO / "sensorium" / "client" / "c"


@pytest.fixture(scope="module")
def clib(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """Our libController built once for this file: (its build folder, the libraries to link)."""
    if shutil.which("cc") is None or shutil.which("make") is None:
        pytest.skip("needs a C toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path_factory.mktemp("cbuild")
    done = subprocess.run(["make", "-s", "-C", str(CLIB), f"BUILD={build}"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    libs = subprocess.run(["make", "-s", "-C", str(CLIB), "libs"], capture_output=True, text=True, timeout=60).stdout.split()
    return build, libs


def compile_controller(clib: tuple[Path, list[str]], folder: Path, name: str, source: str, language: str = "c") -> None:
    """controllers/NAME/NAME.c (``language`` "cpp": NAME.cpp, our C++ layer) compiled to
    controllers/NAME/NAME against our libController."""
    build, libs = clib
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.{language}").write_text(source)
    compiler = ["c++", "-std=c++11"] if language == "cpp" else ["cc", "-std=c99"]
    done = subprocess.run([*compiler, "-Wall", "-Werror", f"-I{CLIB / 'include'}", str(folder / f"{name}.{language}"),
                           "-o", str(folder / name), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_c_controllers_run_and_restart_through_the_c_library(tmp_path: Path, clib: tuple[Path, list[str]]) -> None:
    """Compiled controllers (our libController) are started as executables with their arguments; the
    C restartController and worldReload do what the Python ones do."""
    world = project(tmp_path, 'DEF ALPHA Robot { name "alpha" controller "starts" }\n'
                              'Robot { name "boss" controller "boss" controllerArgs [ "in C" ] supervisor TRUE }', {})
    for name, source in (("starts", C_STARTS), ("boss", C_BOSS)):
        compile_controller(clib, tmp_path / "controllers" / name, name, source)
    proc = run(world, "--until", "1200")
    assert proc.wait() == 0, proc.stderr()
    assert (tmp_path / "controllers" / "starts" / "starts.txt").read_text().split() == ["0", "480", "0", "480"]
    assert [line for line in proc.stdout().splitlines() if line.startswith("[boss]")] == [
        "[boss] boss starts (in C) at 0", "[boss] boss ends at 960", "[boss] boss starts (in C) at 0 after the reload",
        "[boss] boss ends at 1200"]


C_REVERT = r'''#include <math.h>
#include <stdio.h>
#include <unistd.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

#pragma GCC diagnostic ignored "-Wdeprecated-declarations" /* simulation_revert: Webots' deprecated name */

int main(void) {
  wb_robot_init();
  int again = access("reverted", F_OK) == 0;
  printf("boss starts at %g%s\n", wb_robot_get_time(), again ? " after the revert" : "");
  fflush(stdout);
  while (wb_robot_step(16) != -1)
    if (lround(wb_robot_get_time() * 1000) == 320 && !again) {
      fclose(fopen("reverted", "w"));
      wb_supervisor_simulation_revert();
    }
  printf("boss ends at %ld\n", lround(wb_robot_get_time() * 1000));
  wb_robot_cleanup();
  return 0;
}
'''


def test_c_simulation_revert_reloads_the_world(tmp_path: Path, clib: tuple[Path, list[str]]) -> None:
    """Webots' deprecated wb_supervisor_simulation_revert is its worldReload: the simulation ends for
    every controller and `run` loads the world again, its controllers from time 0."""
    world = project(tmp_path, 'Robot { name "boss" controller "boss" supervisor TRUE }', {})
    compile_controller(clib, tmp_path / "controllers" / "boss", "boss", C_REVERT)
    proc = run(world, "--until", "640")
    assert proc.wait() == 0, proc.stderr()
    assert [line for line in proc.stdout().splitlines() if line.startswith("[boss]")] == [
        "[boss] boss starts at 0", "[boss] boss ends at 320", "[boss] boss starts at 0 after the revert",
        "[boss] boss ends at 640"]


LOADER = '''import os
from controller import Supervisor
boss = Supervisor()
print("boss starts at", boss.getTime())
os.chdir("/")          # Webots takes worldLoad's relative name from the controller's folder, not its cwd
while boss.step(16) != -1:
    if round(boss.getTime() * 1000) == 320:
        boss.worldLoad({name!r})
print("boss ends at", round(boss.getTime() * 1000))
'''

ONLY_B = '''from controller import Robot
robot = Robot()
print("only world b has", robot.getName(), "at", robot.getTime())
steps = 0
while robot.step(16) != -1:
    steps += 1
print(robot.getName(), "stepped", steps, "until", round(robot.getTime() * 1000))
'''


def world_b(tmp_path: Path, text: str = 'Robot { name "beta" controller "only_b" }') -> Path:
    """worlds/b.wbt beside the project's w.wbt, its robot's controller only it names."""
    path = tmp_path / "worlds" / "b.wbt"
    path.write_text(WORLD.replace("{robots}", text))
    (tmp_path / "controllers" / "only_b").mkdir(parents=True, exist_ok=True)
    (tmp_path / "controllers" / "only_b" / "only_b.py").write_text(ONLY_B)
    return path


def test_world_load_ends_every_controller_and_starts_the_named_worlds(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\n'
                              'Robot { name "boss" controller "boss" supervisor TRUE }',
                    {"a.py": COUNTER.replace("{step}", "16"), "boss.py": LOADER.format(name="../../worlds/b.wbt")})
    b = world_b(tmp_path)
    proc = run(world, "--until", "640")
    assert proc.wait() == 0, proc.stderr()
    out = proc.stdout().splitlines()
    # world w's controllers end at 320 (their next step answers -1); world b starts at time 0, its controller runs
    assert "[boss] boss ends at 320" in out and "[alpha] alpha stepped 20 until 320" in out
    assert "[beta] only world b has beta at 0.0" in out and "[beta] beta stepped 40 until 640" in out
    assert [line.split(" rpc=")[0] for line in out if line.startswith("sensorium: serving world")] == [
        "sensorium: serving world 'w'", "sensorium: serving world 'b'"]
    # the same endpoints: an <extern> controller's URL stays good
    assert len({line.split(" rpc=")[1] for line in out if line.startswith("sensorium: serving world")}) == 1
    assert sum(line.startswith("[boss] boss starts") for line in out) == 1       # w's controllers do not start again
    assert f"sensorium run: world loaded from {b}" in proc.stderr().splitlines()
    assert proc.stderr().splitlines()[-1] == "sensorium: stopped at 640 ms after 40 steps"
    for pid in pids(tmp_path / "controllers" / "a", "alpha"):
        assert not alive(pid)


def test_a_world_load_that_names_no_world_is_one_line_and_the_run_ends_with_1(tmp_path: Path) -> None:
    """As Webots opens an empty world when worldLoad's file cannot be opened, where nothing runs: one
    line naming the file and why, every controller ends, exit status 1."""
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\n'
                              'Robot { name "boss" controller "boss" supervisor TRUE }',
                    {"a.py": COUNTER.replace("{step}", "16"), "boss.py": LOADER.format(name="../../worlds/gone.wbt")})
    proc = run(world, "--until", "640")
    assert proc.wait() == 1, proc.stderr()
    assert "[boss] boss ends at 320" in proc.stdout().splitlines()
    err = [line for line in proc.stderr().splitlines() if "Traceback" in line or "worldLoad" in line]
    assert err == [f"sensorium run: robot 'boss': worldLoad('../../worlds/gone.wbt'): no world file "
                   f"{tmp_path / 'worlds' / 'gone.wbt'}: the simulation ends (Webots opens an empty world)"]
    assert proc.stderr().splitlines()[-1] == "sensorium: stopped at 320 ms after 20 steps"
    assert sum(line.startswith("sensorium: serving world") for line in proc.stdout().splitlines()) == 1


def test_a_world_load_of_a_file_that_does_not_load_is_its_line_and_exit_1(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "boss" controller "boss" supervisor TRUE }',
                    {"boss.py": LOADER.format(name="../../worlds/b.wbt")})
    b = world_b(tmp_path, 'Robot { name "beta" controller "only_b"')       # its closing brace missing
    proc = run(world, "--until", "640")
    assert proc.wait() == 1, proc.stderr()
    assert "[boss] boss ends at 320" in proc.stdout().splitlines()
    assert proc.stderr().splitlines()[-1] == (f"{b}: line 4, column 1: expected a field name or '}}' in Robot (line 3), "
                                              "found end of file")
    assert "Traceback" not in proc.stderr() and "[beta]" not in proc.stdout()


C_LOADER = r'''#include <math.h>
#include <stdio.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  wb_supervisor_world_load("");
  while (wb_robot_step(16) != -1) {
    if (lround(wb_robot_get_time() * 1000) == 320)
      wb_supervisor_world_load("../../worlds/b.wbt");
  }
  printf("C boss ends at %ld\n", lround(wb_robot_get_time() * 1000));
  wb_robot_cleanup();
  return 0;
}
'''


CPP_LOADER = r'''#include <cmath>
#include <cstdio>
#include <webots/Supervisor.hpp>

int main() {
  webots::Supervisor boss;
  boss.worldLoad("");
  while (boss.step(16) != -1) {
    if (std::lround(boss.getTime() * 1000) == 320)
      boss.worldLoad("../../worlds/b.wbt");
  }
  std::printf("C++ boss ends at %ld\n", std::lround(boss.getTime() * 1000));
  return 0;
}
'''


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_c_and_cpp_world_load_start_the_named_worlds_controllers(tmp_path: Path, clib: tuple[Path, list[str]],
                                                                 language: str) -> None:
    world = project(tmp_path, 'Robot { name "boss" controller "boss" supervisor TRUE }', {})
    compile_controller(clib, tmp_path / "controllers" / "boss", "boss", C_LOADER if language == "c" else CPP_LOADER,
                       language)
    world_b(tmp_path)
    proc = run(world, "--until", "640")
    assert proc.wait() == 0, proc.stderr()
    out = proc.stdout().splitlines()
    assert f"[boss] {'C' if language == 'c' else 'C++'} boss ends at 320" in out
    assert "[beta] only world b has beta at 0.0" in out and "[beta] beta stepped 40 until 640" in out
    # Webots' line for an empty name, nothing done
    assert "[boss] Error: wb_supervisor_world_load() called with NULL or empty 'filename' argument." in \
        proc.stderr().splitlines()


C_NAMER = r'''#include <stdio.h>
#include <stdlib.h>
#include <webots/robot.h>

int main(void) {
  const char *env = getenv("WEBOTS_ROBOT_NAME");
  wb_robot_init();
  printf("WEBOTS_ROBOT_NAME %s, attached to %s\n", env ? env : "(unset)", wb_robot_get_name());
  while (wb_robot_step(16) != -1) {
  }
  wb_robot_cleanup();
  return 0;
}
'''


def test_webots_robot_name_is_set_for_a_controller_and_chooses_the_robot_of_a_url_without_one(
        tmp_path: Path, clib: tuple[Path, list[str]]) -> None:
    """As Webots, run sets WEBOTS_ROBOT_NAME for each controller it starts; a C controller started by
    hand with a URL naming no robot attaches to WEBOTS_ROBOT_NAME's (two robots: "the only robot"
    would be ambiguous)."""
    world = project(tmp_path, 'Robot { name "alpha" controller "namer" }\nRobot { name "ext" controller "<extern>" }',
                    {})
    compile_controller(clib, tmp_path / "controllers" / "namer", "namer", C_NAMER)
    proc = run(world, "--until", "320")
    url = proc.wait_line("sensorium: serving world").split("rpc=")[1].split()[0]
    hand = {"WEBOTS_CONTROLLER_URL": url, "WEBOTS_ROBOT_NAME": "ext", "SENSORIUM_CONTROLLER_URL": None}
    with Proc([str(tmp_path / "controllers" / "namer" / "namer")], env=hand) as manual:
        assert manual.wait() == 0, manual.stderr()
        assert manual.stdout().splitlines() == ["WEBOTS_ROBOT_NAME ext, attached to ext"]
    assert proc.wait() == 0, proc.stderr()
    assert "[alpha] WEBOTS_ROBOT_NAME alpha, attached to alpha" in proc.stdout().splitlines()


def test_a_controller_gets_webots_variables_and_its_folder_on_the_library_path(tmp_path: Path) -> None:
    """WEBOTS_ROBOT_NAME; on LD_LIBRARY_PATH the project's libraries/ folders, WEBOTS_LIBRARY_PATH
    and the controller's folder (a shared library shipped next to a controller loads) before the
    rest, as Webots starts a controller."""
    script = ('import os\nfrom controller import Robot\nrobot = Robot()\n'
              'print(os.environ["WEBOTS_ROBOT_NAME"], *os.environ["LD_LIBRARY_PATH"].split(os.pathsep))\n')
    world = project(tmp_path, 'Robot { name "alpha beta" controller "env" }', {"env.py": script})
    for name in ("b_lib", "a_lib"):
        (tmp_path / "libraries" / name).mkdir(parents=True)
    (tmp_path / "libraries" / "not_a_folder").write_text("")
    proc = run(world, "--until", "160", env={"WEBOTS_ROBOT_NAME": "stale", "LD_LIBRARY_PATH": "/nowhere",
                                             "WEBOTS_LIBRARY_PATH": "/mine"})
    assert proc.wait() == 0, proc.stderr()
    assert (f"[alpha beta] alpha beta {tmp_path / 'libraries' / 'a_lib'} {tmp_path / 'libraries' / 'b_lib'} /mine "
            f"{tmp_path / 'controllers' / 'env'} /nowhere") in proc.stdout().splitlines()


def test_a_project_folder_with_the_path_separator_is_left_off_the_library_path_in_one_line(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A project under a folder with a ':' in its name: its libraries/ folders and the controller's
    folder cannot be entries of LD_LIBRARY_PATH (each would read as two folders, the second relative to
    the controller's folder, as Webots puts them there); they are left off, one line says so, and the
    controller runs with the rest of the list."""
    base = tmp_path / "v1:v2"
    base.mkdir()
    script = ('import os\nfrom controller import Robot\nrobot = Robot()\n'
              'print("path", os.environ.get("LD_LIBRARY_PATH", "<unset>"))\n')
    world = project(base, 'Robot { name "r" controller "env" }', {"env.py": script})
    (base / "libraries" / "lib").mkdir(parents=True)
    folder = base / "controllers" / "env"
    got = launch.plan_world([robot("r", "env")], [base / "controllers"], "tcp://127.0.0.1:5555", wbt=True)
    line = (f"robot 'r': {base / 'libraries' / 'lib'} and 1 more folder left off the controller's library path: "
            "a ':' in a folder's path would split it in two there (LD_LIBRARY_PATH's separator), so a shared "
            "library in it is not found")
    assert got.notes == (line,) and got.problems == ()
    launcher = launch.Launcher(list(got.specs), "tcp://127.0.0.1:1")
    try:
        env = launcher.environment(got.specs[0], {"LD_LIBRARY_PATH": "/a:/b", "WEBOTS_LIBRARY_PATH": "/wl"})
        assert env["LD_LIBRARY_PATH"] == "/wl:/a:/b"
        assert "LD_LIBRARY_PATH" not in launcher.environment(got.specs[0], {})   # no list rather than an empty one
    finally:
        launcher.close()
    plain = launch.plan_world([robot("r", "env")], [tmp_path / "plain" / "controllers"], "tcp://127.0.0.1:5555")
    assert plain.problems and not any("library path" in n for n in plain.notes)
    proc = run(world, "--until", "64", env={"LD_LIBRARY_PATH": "/nowhere"})
    assert proc.wait() == 0, proc.stderr()
    assert f"sensorium run: {line}" in proc.stderr().splitlines()
    assert "[r] path /nowhere" in proc.stdout().splitlines()
    assert str(folder) not in proc.stdout()


UNDER_SERVE = '''from controller import Supervisor
boss = Supervisor()
boss.step(16)
boss.getFromDef("ALPHA").restartController()
boss.worldReload()
boss.worldLoad("w.wbt")
boss.getSelf().restartController()
print("still at", round(boss.getTime() * 1000))
'''


def test_under_serve_restart_reload_and_load_are_one_line_each_and_change_nothing(tmp_path: Path) -> None:
    """Controllers you start yourself (`sensorium serve`) cannot be started again by the server."""
    world = project(tmp_path, 'DEF ALPHA Robot { name "alpha" controller "a" }\n'
                              'Robot { name "boss" controller "<extern>" supervisor TRUE }', {"boss.py": UNDER_SERVE})
    lines, err = run_controller(world, lambda url: sensorium("controller", str(tmp_path / "controllers" / "boss" /
                                                                              "boss.py"), "--url", url), robot="boss")
    assert lines == ["still at 16"]
    assert [line for line in err.splitlines() if line.startswith("Error:")] == [
        "Error: wb_supervisor_node_restart_controller(): restart_controller: only `sensorium run` starts controllers; "
        "an <extern> controller is restarted by whoever started it.",
        "Error: wb_supervisor_world_reload(): world_reload: only `sensorium run` reloads a world (it starts the "
        "controllers again).",
        "Error: wb_supervisor_world_load(): world_load: only `sensorium run` loads another world (it starts the "
        "new world's controllers).",
        "Error: wb_supervisor_node_restart_controller(): restart_controller: only `sensorium run` starts controllers; "
        "an <extern> controller is restarted by whoever started it."]


def test_serve_says_which_robots_name_a_controller(tmp_path: Path) -> None:
    """... with the controllerArgs to give (Webots' youBot world gives its controller "demo", without which
    it only waits for keys)."""
    world = project(tmp_path, 'Robot { name "alpha" controller "a" controllerArgs [ "demo" "two words" ] }\n'
                              'Robot { name "ext" }', {})
    proc = Proc(sensorium("serve", str(world), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"))
    proc.wait_line("sensorium: serving world")
    proc.stop()
    assert proc.stderr().splitlines()[0] == (
        "sensorium serve: robot 'alpha' ('a', controllerArgs `demo 'two words'`): `sensorium run WORLD` starts this "
        "controller; here it is <extern> (start it with `sensorium controller`, its controllerArgs after the script)")


def test_a_world_that_does_not_load_is_its_line_and_exit_1(tmp_path: Path) -> None:
    world = project(tmp_path, 'Robot { name "alpha" controller "a"', {"a.py": COUNTER.replace("{step}", "16")})
    proc = run(world)
    assert proc.wait() == 1
    assert proc.stderr().splitlines() == [f"{world}: line 4, column 1: expected a field name or '}}' in Robot (line 3), "
                                          "found end of file"]
    assert proc.stdout() == "" and not (tmp_path / "controllers" / "a" / "pid-alpha").exists()


# ---------------------------------------------------------------------- simulationQuit ends the whole run

QUITTER = '''from controller import Supervisor
boss = Supervisor()
while boss.step(16) != -1:
    if round(boss.getTime() * 1000) == 480:
        boss.simulationQuit(3)
        print("asked to quit at", round(boss.getTime() * 1000))
print("boss ends at", round(boss.getTime() * 1000))
'''


def test_simulation_quit_ends_every_controller_and_the_run_exits_with_its_status(tmp_path: Path) -> None:
    """As Webots quits: every controller's step answers -1 and it ends (a stubborn one is terminated
    after its grace), the run exits with the status given: a CI job can use it as its verdict."""
    stubborn = ('import os, signal, time\nfrom controller import Robot\nsignal.signal(signal.SIGTERM, signal.SIG_IGN)\n'
                'robot = Robot()\nopen("pid-" + robot.getName(), "w").write(str(os.getpid()))\n'
                'while robot.step(16) != -1:\n    pass\nprint("ignoring the end")\nwhile True:\n    time.sleep(1)\n')
    world = project(tmp_path, 'Robot { name "alpha" controller "a" }\nRobot { name "mule" controller "mule" }\n'
                              'Robot { name "boss" controller "boss" supervisor TRUE }',
                    {"a.py": COUNTER.replace("{step}", "32"), "mule.py": stubborn, "boss.py": QUITTER})
    proc = run(world, "--until", "100000", "--grace", "0.3")
    assert proc.wait() == 3, proc.stderr()
    out = proc.stdout().splitlines()
    assert "[boss] asked to quit at 480" in out and "[boss] boss ends at 480" in out
    assert "[alpha] alpha stepped 15 until 480" in out          # its step to 512 answered -1
    assert "[mule] ignoring the end" in out
    err = proc.stderr()
    assert "sensorium: robot 'boss' quit the simulation (simulationQuit(3)) at 480 ms: every controller ends" in err
    assert "'mule' controller of robot 'mule': forced termination" in err
    assert "exited" not in err                                  # ended by the quit, not by themselves
    assert "sensorium: stopped at 480 ms" in err
    for pid in (*pids(tmp_path / "controllers" / "mule", "mule"), *pids(tmp_path / "controllers" / "a", "alpha")):
        assert not alive(pid)


def test_simulation_quit_of_an_extern_supervisor_stops_serve_with_its_status(tmp_path: Path) -> None:
    """Webots quits for an extern controller's simulationQuit too: `serve` stops and exits with it."""
    world = project(tmp_path, 'Robot { name "boss" controller "<extern>" supervisor TRUE }', {"boss.py": QUITTER})
    with Proc(sensorium("serve", str(world), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0",
                        "--mode", "fast")) as server:
        url = server.wait_line("sensorium: serving world").split("rpc=")[1].split()[0]
        with Proc(sensorium("controller", str(tmp_path / "controllers" / "boss" / "boss.py"), "--robot", "boss",
                            "--url", url)) as boss:
            assert boss.wait() == 0, boss.stderr()
            assert boss.stdout().splitlines() == ["asked to quit at 480", "boss ends at 480"]
            assert "Warning" not in boss.stderr() and "Error" not in boss.stderr()
        assert server.wait() == 3, server.stderr()
        assert "sensorium: stopped at 480 ms" in server.stderr()


C_CHATTY = r'''#include <stdio.h>
#include <webots/robot.h>

int main(void) {
  printf("before init\n");
  wb_robot_init();
  printf("hello from C at %g\n", wb_robot_get_time());
  fprintf(stderr, "a warning from C\n");
  while (wb_robot_step(16) != -1) {
  }
  wb_robot_cleanup();
  return 0;
}
'''


def test_a_c_controllers_lines_come_out_as_it_prints_them(tmp_path: Path, clib: tuple[Path, list[str]]) -> None:
    """wb_robot_init makes stdout and stderr line-buffered, as libController does: a controller that
    prints without fflush and then steps on has its lines seen while it runs (a pipe would otherwise
    hold them until 4 KiB gathered or the process ended)."""
    py = ('import sys\nfrom controller import Robot\nrobot = Robot()\nprint("hello from Python")\n'
          'print("a warning from Python", file=sys.stderr)\nwhile robot.step(16) != -1:\n    pass\n')
    world = project(tmp_path, 'Robot { name "talker" controller "talker" }\nRobot { name "snake" controller "snake" }',
                    {"snake.py": py})
    compile_controller(clib, tmp_path / "controllers" / "talker", "talker", C_CHATTY)
    proc = run(world)                      # no --until: the controllers step until we stop the run
    try:
        proc.wait_line("sensorium: serving world")
        assert proc.wait_line("[talker] ") == "[talker] before init"
        assert proc.wait_line("[talker] ") == "[talker] hello from C at 0"
        assert proc.wait_line("[snake] ") == "[snake] hello from Python"          # PYTHONUNBUFFERED, as Webots
        for line in ("[talker] a warning from C", "[snake] a warning from Python"):
            wait_until(lambda line=line: line in proc.stderr(), what=f"the line {line!r}")
        assert proc.p.poll() is None               # seen while the controller (and the run) go on
    finally:
        proc.p.send_signal(signal.SIGTERM)
    assert proc.wait() == 0, proc.stderr()


# ---------------------------------------------------------------------- Webots' own controllers (--webots-home)

def fake_webots(home: Path) -> Path:
    """A Webots installation of our own: a default project's controller, a robot project whose PROTO
    and controller live together, a sample project, two projects with a controller of one name."""
    def controller(folder: Path, text: str = "") -> None:
        folder.mkdir(parents=True)
        (folder / f"{folder.name}.py").write_text(text)
    controller(home / "resources" / "projects" / "controllers" / "void")
    controller(home / "projects" / "robots" / "maker" / "bee" / "controllers" / "bee_wander",
               COUNTER.replace("{step}", "32"))
    (home / "projects" / "robots" / "maker" / "bee" / "protos").mkdir(parents=True)
    (home / "projects" / "robots" / "maker" / "bee" / "protos" / "Bee.proto").write_text("")
    controller(home / "projects" / "samples" / "devices" / "controllers" / "sampler")
    controller(home / "projects" / "samples" / "devices" / "controllers" / "bee_wander")  # a second one
    controller(home / "projects" / "samples" / "howto" / "twice" / "controllers" / "twin")
    controller(home / "projects" / "samples" / "howto" / "again" / "controllers" / "twin")
    return home


def test_webots_own_controllers_are_found_by_a_bounded_index(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    home = fake_webots(tmp_path / "webots")
    projects = home / "projects"
    webots = WebotsProjects(home)
    mine = tmp_path / "controllers"
    mine.mkdir()
    spec = find_controller("r", "sampler", [], [mine], webots)
    assert (spec.folder, spec.webots) == (projects / "samples" / "devices" / "controllers" / "sampler", True)
    assert find_controller("r", "void", [], [mine], webots).folder == home / "resources" / "projects" / "controllers" / "void"
    # a name two projects have: the one whose protos/ define the robot's PROTO, as Webots looks there
    assert find_controller("r", "bee_wander", [], [mine], webots, "Bee").folder == (
        projects / "robots" / "maker" / "bee" / "controllers" / "bee_wander")
    with pytest.raises(LaunchError) as info:
        find_controller("r", "twin", [], [mine], webots)
    assert str(info.value) == (
        f"robot 'r': controller 'twin' is in several of Webots' projects ({projects / 'samples/howto/again/controllers/twin'}, "
        f"{projects / 'samples/howto/twice/controllers/twin'}): give the one to use with --controllers-dir (its "
        "controllers/ folder)")
    # the project's own folder comes first
    (mine / "sampler").mkdir()
    (mine / "sampler" / "sampler.py").write_text("")
    assert find_controller("r", "sampler", [], [mine], webots).webots is False
    with pytest.raises(LaunchError, match=rf"controller 'none' not found \(looked for the folder {mine / 'none'}, and in "
                                          rf"Webots' projects under {projects}\)"):
        find_controller("r", "none", [], [mine], webots)
    # bounded: deeper than WEBOTS_DEPTH is not looked at, nor more folders than WEBOTS_MAX_DIRS
    deep = projects / "a" / "b" / "c" / "d" / "e" / "f" / "controllers" / "deep"
    deep.mkdir(parents=True)
    (deep / "deep.py").write_text("")
    with pytest.raises(LaunchError, match="not found"):
        find_controller("r", "deep", [], [mine], WebotsProjects(home))
    monkeypatch.setattr(launch, "WEBOTS_MAX_DIRS", 3)
    capped = WebotsProjects(home)
    with pytest.raises(LaunchError, match=r"indexed only its first 3 folders"):
        find_controller("r", "none", [], [mine], capped)


def test_run_with_webots_home_starts_a_stock_controller_of_a_proto_robot(tmp_path: Path) -> None:
    home = fake_webots(tmp_path / "webots")
    (home / "projects" / "robots" / "maker" / "bee" / "protos" / "Bee.proto").write_text(
        '#VRML_SIM R2023b utf8\nPROTO Bee [\n  field SFString name "bee"\n  field SFString controller "bee_wander"\n]\n'
        '{\n  Robot {\n    name IS name\n    controller IS controller\n  }\n}\n')
    (tmp_path / "worlds").mkdir()
    world = tmp_path / "worlds" / "w.wbt"
    world.write_text('#VRML_SIM R2023b utf8\n'
                     'EXTERNPROTO "webots://projects/robots/maker/bee/protos/Bee.proto"\n'
                     'WorldInfo { basicTimeStep 16 }\nBee { }\n')
    proc = run(world, "--until", "320", "--webots-home", str(home))
    assert proc.wait() == 0, proc.stderr()
    folder = home / "projects" / "robots" / "maker" / "bee" / "controllers" / "bee_wander"
    assert f"sensorium run: robot 'bee': controller 'bee_wander' found in Webots' projects: {folder / 'bee_wander.py'}" \
        in proc.stderr().splitlines()
    assert "[bee] bee stepped 10 until 320" in proc.stdout().splitlines()


# ---------------------------------------------------------------------- extra project paths (WEBOTS_EXTRA_PROJECT_PATH)

BEE_PROTO = ('#VRML_SIM R2023b utf8\nPROTO Bee [\n  field SFString name "bee"\n  field SFString controller "bee_ctl"\n]\n'
             '{\n  Robot {\n    name IS name\n    controller IS controller\n  }\n}\n')


def extra_project(root: Path) -> Path:
    """A project of its own elsewhere: protos/Bee.proto (a robot) and controllers/bee_ctl/bee_ctl.py."""
    (root / "protos").mkdir(parents=True)
    (root / "protos" / "Bee.proto").write_text(BEE_PROTO)
    (root / "controllers" / "bee_ctl").mkdir(parents=True)
    (root / "controllers" / "bee_ctl" / "bee_ctl.py").write_text(COUNTER.replace("{step}", "32"))
    return root


def test_extra_projects_are_looked_in_after_the_project_and_controllers_dirs(tmp_path: Path) -> None:
    """As Webots' WbRobot: the project's controllers/, (here: each --controllers-dir), then each
    extra project's controllers/ in the order given, each folder once."""
    extra = [extra_project(tmp_path / "one"), extra_project(tmp_path / "two")]
    value = os.pathsep.join([str(extra[0]), "", str(extra[1]), str(extra[0])])
    assert launch.extra_project_paths(value) == extra
    (tmp_path / "proj").mkdir()
    world = project(tmp_path / "proj", "", {})
    dirs = launch.controller_dirs(world, [tmp_path / "mine"], extra)
    assert dirs == [tmp_path / "proj" / "controllers", tmp_path / "mine", extra[0] / "controllers",
                    extra[1] / "controllers"]
    assert find_controller("r", "bee_ctl", [], dirs).folder == extra[0] / "controllers" / "bee_ctl"
    (tmp_path / "mine" / "bee_ctl").mkdir(parents=True)
    (tmp_path / "mine" / "bee_ctl" / "bee_ctl.py").write_text("")
    assert find_controller("r", "bee_ctl", [], dirs).folder == tmp_path / "mine" / "bee_ctl"
    with pytest.raises(LaunchError) as info:
        find_controller("r", "gone", [], dirs)
    assert f"{extra[1] / 'controllers' / 'gone'};" in str(info.value)
    relative = launch.extra_project_paths("rel")[0]
    assert relative.is_absolute() and relative.name == "rel"          # the controllers' folders differ from ours
    many = os.pathsep.join(str(tmp_path / f"p{i}") for i in range(launch.EXTRA_MAX + 5))
    assert len(launch.extra_project_paths(many)) == launch.EXTRA_MAX


@pytest.mark.parametrize("how", ["env", "option"])
def test_a_robot_proto_and_its_controller_come_from_an_extra_project(tmp_path: Path, how: str) -> None:
    """The world names a PROTO and the PROTO a controller that only another project holds: with
    that project as an extra project path both are found, as Webots finds them there."""
    extra = extra_project(tmp_path / "shared")
    (tmp_path / "proj" / "worlds").mkdir(parents=True)
    world = tmp_path / "proj" / "worlds" / "w.wbt"
    world.write_text('#VRML_SIM R2023b utf8\nEXTERNPROTO "../protos/Bee.proto"\nWorldInfo { basicTimeStep 16 }\n'
                     'Bee { }\n')
    nowhere = tmp_path / "nowhere"
    if how == "env":
        proc = run(world, "--until", "320", env={"WEBOTS_EXTRA_PROJECT_PATH": f"{nowhere}{os.pathsep}{extra}",
                                                 "WEBOTS_HOME": None, "SENSORIUM_PROTO_PATH": None})
    else:
        proc = run(world, "--until", "320", "--extra-project-path", str(nowhere), "--extra-project-path", str(extra),
                   env={"WEBOTS_EXTRA_PROJECT_PATH": None, "WEBOTS_HOME": None, "SENSORIUM_PROTO_PATH": None})
    assert proc.wait() == 0, proc.stderr()
    assert "[bee] bee args [] in bee_ctl" in proc.stdout().splitlines()
    assert "[bee] bee stepped 10 until 320" in proc.stdout().splitlines()
    assert f"sensorium run: extra project path {nowhere} is not a folder: not looked in" in proc.stderr().splitlines()
    # without it neither is found: the PROTO's file is the load's one line
    proc = run(world, env={"WEBOTS_EXTRA_PROJECT_PATH": None, "WEBOTS_HOME": None, "SENSORIUM_PROTO_PATH": None})
    assert proc.wait() == 1
    assert "Bee.proto" in proc.stderr()


def test_a_world_saved_before_r2022b_finds_a_proto_of_an_extra_project_by_name(tmp_path: Path) -> None:
    """R2022a worlds name PROTOs without EXTERNPROTO: Webots found them in extra projects too."""
    extra = extra_project(tmp_path / "shared")
    (tmp_path / "proj" / "worlds").mkdir(parents=True)
    world = tmp_path / "proj" / "worlds" / "w.wbt"
    world.write_text('#VRML_SIM R2022a utf8\nWorldInfo { basicTimeStep 16 }\nBee { }\n')
    clean = {"WEBOTS_EXTRA_PROJECT_PATH": None, "WEBOTS_HOME": None, "SENSORIUM_PROTO_PATH": None}
    with Proc(sensorium("validate", str(world), "--extra-project-path", str(extra)), env=clean) as proc:
        assert proc.wait() == 0, proc.stderr()
        assert proc.stdout().splitlines() == [f"{world}: OK"]
    with Proc(sensorium("validate", str(world)), env=clean) as proc:
        assert proc.wait() == 1
        assert "unknown node 'Bee'" in proc.stderr()


def test_a_project_runs_in_process_and_stop_ends_it(tmp_path: Path) -> None:
    """The library's run (what `sensorium run` calls): in a thread of ours, its lines to our streams;
    stop() ends it as Ctrl-C does (every controller gone, status 0)."""
    import io
    import threading

    from sensorium.server.daemon.serve import ServeOptions

    world = project(tmp_path, 'Robot { name "alpha" controller "a" }', {"a.py": COUNTER.replace("{step}", "16")})
    out, err = io.StringIO(), io.StringIO()
    options = launch.RunOptions(serve=ServeOptions(rpc="tcp://127.0.0.1:0", pub="tcp://127.0.0.1:0"), grace_s=5.0)
    options.check(world)
    project_run = launch.ProjectRun(world, options, out=out, err=err)
    status: list[int] = []
    thread = threading.Thread(target=lambda: status.append(project_run.run()))
    thread.start()
    try:
        wait_until(lambda: "[alpha] alpha args [] in a" in out.getvalue(), what="the controller's first line")
    finally:
        project_run.stop()
        thread.join(120)
    assert not thread.is_alive() and status == [0], err.getvalue()
    assert out.getvalue().startswith("sensorium: serving world 'w' rpc=tcp://127.0.0.1:")
    assert any(line.startswith("[alpha] alpha stepped ") for line in out.getvalue().splitlines())
    (pid,) = pids(tmp_path / "controllers" / "a", "alpha")
    assert not alive(pid)
    with pytest.raises(ValueError, match="--grace must be a finite number >= 0, got -1"):
        launch.RunOptions(grace_s=-1).check(world)
    with pytest.raises(ValueError, match=f"--controllers-dir {tmp_path / 'none'}: no such folder"):
        launch.RunOptions(controllers_dirs=(tmp_path / "none",)).check(world)


def test_a_proto_robots_controller_is_found_in_the_protos_project(tmp_path: Path) -> None:
    """Webots looks for a robot's controller in its PROTO's project right after the world's own: a
    world declaring a PROTO of another project by its path runs that project's controller."""
    shared = extra_project(tmp_path / "robots" / "shared")
    (tmp_path / "proj" / "worlds").mkdir(parents=True)
    world = tmp_path / "proj" / "worlds" / "w.wbt"
    text = ('#VRML_SIM R2023b utf8\nEXTERNPROTO "../../robots/shared/protos/Bee.proto"\n'
            'IMPORTABLE EXTERNPROTO "webots://projects/objects/Other.proto"\nWorldInfo { basicTimeStep 16 }\n'
            'Bee { }\nBee { name "own" controller "mine" }\n')
    world.write_text(text)
    assert launch.proto_projects(world, text, {"bee": "Bee", "x": "Other", "y": "Nowhere"}) == {"bee": shared}
    (tmp_path / "proj" / "controllers" / "mine").mkdir(parents=True)
    (tmp_path / "proj" / "controllers" / "mine" / "mine.py").write_text(COUNTER.replace("{step}", "32"))
    proc = run(world, "--until", "320", env={"WEBOTS_EXTRA_PROJECT_PATH": None, "WEBOTS_HOME": None})
    assert proc.wait() == 0, proc.stderr()
    out = proc.stdout().splitlines()
    assert "[bee] bee args [] in bee_ctl" in out and "[bee] bee stepped 10 until 320" in out
    assert "[own] own stepped 10 until 320" in out
    # the world's own project comes first
    (tmp_path / "proj" / "controllers" / "bee_ctl").mkdir(parents=True)
    (tmp_path / "proj" / "controllers" / "bee_ctl" / "bee_ctl.py").write_text('print("the project\'s own")\n')
    dirs = launch.controller_dirs(world, [])
    got = launch.plan_world([WorldRobot(name="bee", controller="bee_ctl")], dirs, "tcp://127.0.0.1:5555",
                            projects={"bee": shared})
    assert [s.folder for s in got.specs] == [tmp_path / "proj" / "controllers" / "bee_ctl"]
    (tmp_path / "proj" / "controllers" / "bee_ctl" / "bee_ctl.py").unlink()
    (tmp_path / "proj" / "controllers" / "bee_ctl").rmdir()
    got = launch.plan_world([WorldRobot(name="bee", controller="bee_ctl")], dirs, "tcp://127.0.0.1:5555",
                            projects={"bee": shared})
    assert [s.folder for s in got.specs] == [shared / "controllers" / "bee_ctl"]


def test_a_controllers_runtime_ini_sets_its_environment_and_python(tmp_path: Path) -> None:
    """As Webots: the controller folder's runtime.ini adds a shared library folder to PYTHONPATH
    (relative to the controller's folder), sets variables, and names the Python to run it with."""
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "shared_mod.py").write_text('WORD = "shared"\n')
    wrapper = tmp_path / "python-wrapper"
    wrapper.write_text(f'#!/bin/sh\necho "wrapped python" >&2\nexec "{sys.executable}" "$@"\n')
    wrapper.chmod(0o755)
    script = ('import os, sys\nimport shared_mod\nfrom controller import Robot\nrobot = Robot()\n'
              'print(shared_mod.WORD, os.environ["GREETING"], sys.flags.dont_write_bytecode)\n')
    world = project(tmp_path, 'Robot { name "alpha" controller "c" }', {"c.py": script})
    (tmp_path / "controllers" / "c" / "runtime.ini").write_text(
        '[environment variables with paths]\nPYTHONPATH = $(PYTHONPATH):../../lib\n'
        f'[environment variables]\nGREETING = "hello; world" ; a comment\n[python]\nCOMMAND = {wrapper}\nOPTIONS = -B\n')
    proc = run(world, "--until", "160")
    assert proc.wait() == 0, proc.stderr()
    assert "[alpha] shared hello; world 1" in proc.stdout().splitlines()
    assert "[alpha] wrapped python" in proc.stderr().splitlines()


# a benchmark's referee: its score goes to the robot window (Webots' wwiSendText), its stdout its own
SCORER = '''from controller import Robot
robot = Robot()
robot.step(16)
robot.wwiSendText("time:1.500")
robot.wwiSendText("record:0.87\\nsecond line")
robot.wwiSendText("x" * 70000)
print("scored")
'''


def test_robot_window_text_is_printed_on_stderr_with_robot_window_log(tmp_path: Path) -> None:
    """`sensorium run --robot-window-log`: each wwiSendText is one stderr line 'robot window: TEXT' of its
    robot (line breaks shown as \\n, at most 4096 characters shown, the rest counted); stdout keeps the
    controller's own lines; without the option the text goes nowhere."""
    world = project(tmp_path, 'Robot { name "referee" controller "s" }', {"s.py": SCORER})
    proc = run(world, "--until", "64", "--robot-window-log")
    assert proc.wait() == 0, proc.stderr()
    err = [line for line in proc.stderr().splitlines() if "robot window:" in line]
    assert err[0] == "[referee] robot window: time:1.500"
    assert err[1] == "[referee] robot window: record:0.87\\nsecond line"
    assert err[2] == "[referee] robot window: " + "x" * 4096 + " ... (65904 more characters not shown)"
    assert len(err) == 3
    assert "[referee] scored" in proc.stdout().splitlines()
    assert "robot window" not in proc.stdout()
    quiet = run(world, "--until", "64")
    assert quiet.wait() == 0, quiet.stderr()
    assert "robot window" not in quiet.stderr() and "[referee] scored" in quiet.stdout().splitlines()
