"""``sensorium run``: a Supervisor switches another robot's controller by setting its ``controller``
field (the running one ends, the named one starts; a name not found leaves the robot without one;
``<extern>`` waits for one to attach) and passes it data through its ``customData`` field, which
the robot's controller reads with ``getCustomData`` once its next step returns (Python and C); the same from a C
and from a C++ Supervisor (tests/c/robot_fields_boss*), the robot's controller then C or C++, built with
sanitizers."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from _serve import Proc, sensorium, wait_until
from test_run import CLIB, clib, compile_controller, project, run  # noqa: F401  (clib: the fixture)

pytestmark = pytest.mark.slow
TESTS_C = Path(__file__).resolve().parent / "c"

FIRST = '''from controller import Robot
robot = Robot()
print("first starts at", round(robot.getTime() * 1000))
while robot.step(16) != -1:
    pass
print("first ends at", round(robot.getTime() * 1000))
'''

SECOND = '''from controller import Robot
robot = Robot()
seen = robot.getCustomData()
print("second starts at", round(robot.getTime() * 1000), "with", repr(seen))
while robot.step(16) != -1:
    if robot.getCustomData() != seen:
        seen = robot.getCustomData()
        print("second sees", repr(seen), "at", round(robot.getTime() * 1000))
print("second ends at", round(robot.getTime() * 1000))
'''

C_SECOND = r'''#include <math.h>
#include <stdio.h>
#include <string.h>
#include <webots/robot.h>

int main(void) {
  wb_robot_init();
  char seen[64];
  snprintf(seen, sizeof seen, "%s", wb_robot_get_custom_data());
  printf("second starts at %ld with '%s'\n", lround(wb_robot_get_time() * 1000), seen);
  fflush(stdout);
  while (wb_robot_step(16) != -1) {
    if (strcmp(wb_robot_get_custom_data(), seen) != 0) {
      snprintf(seen, sizeof seen, "%s", wb_robot_get_custom_data());
      printf("second sees '%s' at %ld\n", seen, lround(wb_robot_get_time() * 1000));
      fflush(stdout);
    }
  }
  printf("second ends at %ld\n", lround(wb_robot_get_time() * 1000));
  wb_robot_cleanup();
  return 0;
}
'''

# at 160 alpha runs "second", at 480 it gets data, at 640 a controller that is nowhere, at 800 "first" again
BOSS = '''from controller import Supervisor
boss = Supervisor()
alpha = boss.getFromDef("ALPHA")
controller, data = alpha.getField("controller"), alpha.getField("customData")
plan = {160: (controller, "second"), 480: (data, "go"), 640: (controller, "nowhere"), 800: (controller, "first")}
while boss.step(16) != -1:
    t = round(boss.getTime() * 1000)
    if t in plan:
        field, value = plan[t]
        field.setSFString(value)
        print("boss set", repr(field.getSFString()), "at", t)
'''

WORLD = 'DEF ALPHA Robot { name "alpha" controller "first" }\nRobot { name "boss" controller "boss" supervisor TRUE }'

EXPECTED_ALPHA = ["[alpha] first starts at 0", "[alpha] first ends at 160", "[alpha] second starts at 160 with ''",
                  "[alpha] second sees 'go' at 496", "[alpha] second ends at 640", "[alpha] first starts at 800",
                  "[alpha] first ends at 1200"]


def check(proc: Proc) -> None:
    assert proc.wait() == 1, proc.stderr()          # alpha ran without a controller it was given, as at load
    out = proc.stdout().splitlines()
    assert [line for line in out if line.startswith("[alpha]")] == EXPECTED_ALPHA, proc.stdout()
    assert [line for line in out if line.startswith("[boss]")] == [
        "[boss] boss set 'second' at 160", "[boss] boss set 'go' at 480", "[boss] boss set 'nowhere' at 640",
        "[boss] boss set 'first' at 800"]
    err = proc.stderr()
    assert "sensorium run: robot 'alpha': controller 'nowhere' not found (looked for the folder " in err
    assert "): the robot runs without a controller" in err
    assert "sensorium: stopped at 1200 ms" in err
    assert "ran without the controller the world names: 'alpha' ('nowhere')" in err


def test_a_supervisor_switches_a_robots_controller_and_gives_it_data(tmp_path: Path) -> None:
    world = project(tmp_path, WORLD, {"first.py": FIRST, "second.py": SECOND, "boss.py": BOSS})
    check(run(world, "--until", "1200"))


@pytest.fixture(scope="module")
def sanitized_clib(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """Our libController built with -fsanitize=address,undefined: (its build folder, the libraries to link)."""
    from test_c_client import _make

    if shutil.which("cc") is None or shutil.which("c++") is None or shutil.which("make") is None:
        pytest.skip("needs a C and C++ toolchain (build-essential, libzmq3-dev, libmsgpack-dev, libpng-dev, libjpeg-dev)")
    build = tmp_path_factory.mktemp("sanbuild")
    _make(f"BUILD={build}", "SANITIZE=1")
    return build, _make("libs").split()


def compile_sanitized(library: tuple[Path, list[str]], folder: Path, name: str, source: Path) -> None:
    """controllers/NAME/NAME built from ``source`` (C or C++) with the sanitizers against ``library``."""
    build, libs = library
    folder.mkdir(parents=True, exist_ok=True)
    compiler = ["c++", "-std=c++11"] if source.suffix == ".cpp" else ["cc", "-std=c99"]
    done = subprocess.run([*compiler, "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
                           "-fno-sanitize-recover=undefined", f"-I{CLIB / 'include'}", str(source), "-o",
                           str(folder / name), str(build / "libController.a"), *libs, "-lm"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("language", ["c", "cpp"])
def test_a_c_or_cpp_supervisor_switches_a_c_or_cpp_robots_controller_and_gives_it_data(
        tmp_path: Path, sanitized_clib: tuple[Path, list[str]], language: str) -> None:
    """tests/c/robot_fields_boss.c (or _cpp.cpp) sets what the Python boss sets; alpha's "second" is the C
    controller above (or tests/c/robot_fields_second_cpp.cpp) reading getCustomData: the same lines."""
    from test_c_client import SAN_ENV

    world = project(tmp_path, WORLD, {"first.py": FIRST})
    if language == "c":
        (tmp_path / "second.c").write_text(C_SECOND)
        sources = {"boss": TESTS_C / "robot_fields_boss.c", "second": tmp_path / "second.c"}
    else:
        sources = {"boss": TESTS_C / "robot_fields_boss_cpp.cpp", "second": TESTS_C / "robot_fields_second_cpp.cpp"}
    for name, source in sources.items():
        compile_sanitized(sanitized_clib, tmp_path / "controllers" / name, name, source)
    proc = run(world, "--until", "1200", env=SAN_ENV)
    check(proc)
    assert "Sanitizer" not in proc.stderr() and "runtime error" not in proc.stderr(), proc.stderr()


def test_the_c_library_reads_the_data_a_supervisor_sets(tmp_path: Path, clib: tuple[Path, list[str]]) -> None:  # noqa: F811
    world = project(tmp_path, WORLD, {"first.py": FIRST, "boss.py": BOSS})
    compile_controller(clib, tmp_path / "controllers" / "second", "second", C_SECOND)
    check(run(world, "--until", "1200"))


EXTERN_BOSS = '''from controller import Supervisor
boss = Supervisor()
while boss.step(16) != -1:
    if round(boss.getTime() * 1000) == 160:
        boss.getFromDef("ALPHA").getField("controller").setSFString("<extern>")
'''

HAND = '''from controller import Robot
robot = Robot()
print("hand starts at", round(robot.getTime() * 1000))
while robot.step(16) != -1:
    pass
print("hand ends at", round(robot.getTime() * 1000))
'''


def test_extern_makes_the_world_wait_for_a_controller_to_attach(tmp_path: Path) -> None:
    world = project(tmp_path, WORLD, {"first.py": FIRST, "boss.py": EXTERN_BOSS})
    hand = tmp_path / "hand.py"
    hand.write_text(HAND)
    proc = run(world, "--until", "800")
    url = proc.wait_line("sensorium: serving world").split("rpc=")[1].split()[0]
    wait_until(lambda: f"robot 'alpha' is <extern> now: attach its controller with `sensorium controller SCRIPT "
                       f"--robot alpha --url {url}`" in proc.stderr(), what="the <extern> line")
    with Proc(sensorium("controller", str(hand), "--robot", "alpha", "--url", url)) as manual:
        assert manual.wait() == 0, manual.stderr()
        # the synchronous robot held the world at 160 until its new controller attached
        assert manual.stdout().splitlines() == ["hand starts at 160", "hand ends at 800"]
    assert proc.wait() == 0, proc.stderr()
    assert [line for line in proc.stdout().splitlines() if line.startswith("[alpha]")] == [
        "[alpha] first starts at 0", "[alpha] first ends at 160"]
