"""When a controller's ``getCustomData()`` sees its robot's ``customData`` field change, as Webots' libController
caches it: its own ``setCustomData`` at once; a Supervisor's ``setSFString`` on the field (its own or another
robot's) and a ``simulationReset`` only once the next physics step has applied them, with the answer to the
step that follows (Webots queues field sets and the reset for the start of the next step, WbRobot::updateData
marks the value and writeAnswer sends it), so a ``step(0)`` before that step brings nothing new. Against a
server in this process, our own world: the Supervisor "boss" with ``customData "a"``."""

from __future__ import annotations

import pytest
from _inproc import inproc_server
from test_run import clib  # noqa: F401  (the fixture: our libController built once)

from sensorium.client import wb
from sensorium.client.webots.controller import Robot

WORLD = """#VRML_SIM R2023b utf8
WorldInfo {
  basicTimeStep 16
}
DEF BOSS Robot {
  name "boss"
  controller "<extern>"
  supervisor TRUE
  customData "a"
}
"""


@pytest.fixture
def boss(tmp_path):
    """The client attached to "boss"; its own customData field."""
    (tmp_path / "w.wbt").write_text(WORLD)
    with inproc_server(heartbeat_ms=5000, world=tmp_path / "w.wbt") as (core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/boss")
        try:
            yield core, wb.wb_supervisor_node_get_field(wb.wb_supervisor_node_get_self(), "customData")
        finally:
            wb.wb_robot_cleanup()
            Robot.created = None                     # (Supervisor() sets it on Robot)


def test_its_own_supervisor_set_reaches_the_cache_with_the_next_steps_answer(boss) -> None:
    core, field = boss
    wb.wb_supervisor_field_set_sf_string(field, "b")
    assert wb.wb_supervisor_field_get_sf_string(field) == "b"    # (Webots answers a pending set's value)
    assert wb.wb_robot_get_custom_data() == "a"
    assert wb.wb_robot_step(0) == 0 and wb.wb_robot_get_custom_data() == "a"    # no physics step yet
    assert wb.wb_robot_step(16) == 0 and wb.wb_robot_get_custom_data() == "b"
    # its own setCustomData: the cache at once, the field with it
    wb.wb_robot_set_custom_data("c")
    assert wb.wb_robot_get_custom_data() == "c" == wb.wb_supervisor_field_get_sf_string(field)
    assert wb.wb_robot_step(16) == 0 and wb.wb_robot_get_custom_data() == "c"
    assert core.sim.robots["boss"].custom_data == "c"


def test_a_supervisors_set_wins_over_its_own_set_custom_data_in_the_same_step(boss) -> None:
    """Webots reads the controller's setCustomData with its step request and applies the Supervisor's queued
    field set after it, at the start of the step: whichever came first here, the field ends with the set."""
    core, field = boss
    wb.wb_supervisor_field_set_sf_string(field, "d")
    wb.wb_robot_set_custom_data("e")
    assert wb.wb_robot_get_custom_data() == "e" and wb.wb_supervisor_field_get_sf_string(field) == "d"
    assert wb.wb_robot_step(16) == 0 and wb.wb_robot_get_custom_data() == "d" == core.sim.robots["boss"].custom_data
    wb.wb_robot_set_custom_data("f")
    wb.wb_supervisor_field_set_sf_string(field, "g")
    assert wb.wb_robot_step(16) == 0 and wb.wb_robot_get_custom_data() == "g"
    wb.wb_robot_set_custom_data("h")                                # no set pending: its own value stays
    assert wb.wb_robot_step(16) == 0 and wb.wb_robot_get_custom_data() == "h" == core.sim.robots["boss"].custom_data


def test_a_reset_brings_the_world_files_value_with_the_next_steps_answer(boss) -> None:
    _, field = boss
    wb.wb_supervisor_field_set_sf_string(field, "b")
    wb.wb_robot_step(16)
    wb.wb_supervisor_simulation_reset()
    assert wb.wb_supervisor_field_get_sf_string(field) == "a"
    assert wb.wb_robot_get_custom_data() == "b"                  # Webots resets at its next step
    assert wb.wb_robot_step(0) == 0 and wb.wb_robot_get_custom_data() == "b"
    assert wb.wb_robot_step(16) == 0 and wb.wb_robot_get_custom_data() == "a"


C_BOSS = r'''#include <stdio.h>
#include <webots/robot.h>
#include <webots/supervisor.h>

int main(void) {
  wb_robot_init();
  WbFieldRef data = wb_supervisor_node_get_field(wb_supervisor_node_get_self(), "customData");
  wb_supervisor_field_set_sf_string(data, "b");
  printf("set %s\n", wb_robot_get_custom_data());
  wb_robot_step(0);
  printf("step(0) %s\n", wb_robot_get_custom_data());
  wb_robot_step(16);
  printf("step %s\n", wb_robot_get_custom_data());
  wb_supervisor_simulation_reset();
  printf("reset %s field %s\n", wb_robot_get_custom_data(), wb_supervisor_field_get_sf_string(data));
  wb_robot_step(16);
  printf("step %s\n", wb_robot_get_custom_data());
  wb_robot_set_custom_data("c");
  printf("own %s field %s\n", wb_robot_get_custom_data(), wb_supervisor_field_get_sf_string(data));
  wb_robot_step(16);
  wb_supervisor_field_set_sf_string(data, "d");
  wb_robot_set_custom_data("e");
  printf("own %s field %s\n", wb_robot_get_custom_data(), wb_supervisor_field_get_sf_string(data));
  wb_robot_step(16);
  printf("step %s\n", wb_robot_get_custom_data());
  wb_robot_cleanup();
  return 0;
}
'''


@pytest.mark.slow
def test_the_c_library_keeps_the_same_cache(tmp_path, clib) -> None:  # noqa: F811
    import os
    import subprocess

    from test_run import compile_controller

    compile_controller(clib, tmp_path / "boss", "boss", C_BOSS)
    (tmp_path / "w.wbt").write_text(WORLD)
    with inproc_server(heartbeat_ms=5000, world=tmp_path / "w.wbt") as (_, transport):
        env = {**os.environ, "SENSORIUM_CONTROLLER_URL": f"{transport.rpc_endpoint}/boss"}
        done = subprocess.run([str(tmp_path / "boss" / "boss")], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["set a", "step(0) a", "step b", "reset b field a", "step a", "own c field c",
                                     "own e field d", "step d"]
