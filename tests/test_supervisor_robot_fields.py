"""A Supervisor sets a robot's ``customData`` and ``controller`` fields (through the sans-IO core on
tests/worlds/webots_api.yaml): the robot's controller gets the new customData with its next step
reply, as Webots sends it with the step's answer; a new controller name ends the running controller
(its pending step answers -1) and asks ``sensorium run``'s launcher for the named one; under plain
``serve`` the value changes and one line says nothing is started."""

from __future__ import annotations

import itertools

import msgpack
import pytest
from test_supervisor import Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import supervisor
from sensorium.server.daemon.services import Core
from sensorium.server.world.limits import custom_data_chars

A, B = b"A", b"B"


class Logged(Live):
    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []
        n = itertools.count()
        self.core = Core(self.sim, new_token=lambda: f"s{next(n)}", log=self.lines.append)


@pytest.fixture
def live() -> Logged:
    lv = Logged()
    lv.ok(A, "attach", {"robot": "pioneer"})
    lv.ok(B, "attach", {"robot": "rover"})
    return lv


def rover_node(live: Logged) -> int:
    return live.ok(A, "/pioneer/robot/get_from_def", {"name": "rover"})["node"]


def set_field(live: Logged, node: int, field: str, value: object) -> dict:
    return live.ok(A, "/pioneer/robot/set_field", {"node": node, "field": field, "value": value})


def get_field(live: Logged, node: int, field: str) -> object:
    return live.ok(A, "/pioneer/robot/get_field", {"node": node, "field": field})["value"]


def test_custom_data_set_by_a_supervisor_reaches_the_robot_with_its_next_step(live: Logged) -> None:
    rover = rover_node(live)
    assert "custom_data" not in live.step(B, "rover", {"duration": 32})       # nothing new: no key
    set_field(live, rover, "customData", "speed=3")
    assert get_field(live, rover, "customData") == "speed=3"
    assert live.ok(B, "/rover/robot/get_custom_data") == {"value": "speed=3"}
    assert live.step(B, "rover", {"duration": 32})["custom_data"] == "speed=3"
    assert "custom_data" not in live.step(B, "rover", {"duration": 32})       # sent once
    # the robot's own setCustomData and the field are one value; its controller has it already
    live.ok(B, "/rover/robot/set_custom_data", {"value": "mine"})
    assert get_field(live, rover, "customData") == "mine"
    assert "custom_data" not in live.step(B, "rover", {"duration": 32})
    # the supervisor's own field, set through its own node: its own next step reply carries it
    set_field(live, 1, "customData", "")
    assert live.step(A, "pioneer", {"duration": 32})["custom_data"] == ""
    # Webots applies a Supervisor's field set at the start of the next physics step (processImmediateMessages)
    # and sends the value with the answer after it: a step(0) before that step answers without it
    set_field(live, rover, "customData", "now")
    assert "custom_data" not in live.ok(B, "/rover/robot/step", {"duration": 0})
    assert "custom_data" not in live.ok(B, "/rover/robot/step", {"duration": 0})
    assert live.step(B, "rover", {"duration": 32})["custom_data"] == "now"
    assert "custom_data" not in live.ok(B, "/rover/robot/step", {"duration": 0})


def test_a_reset_sends_the_world_files_custom_data_again(live: Logged) -> None:
    set_field(live, 1, "customData", "changed")
    assert live.step(A, "pioneer", {"duration": 32})["custom_data"] == "changed"
    live.ok(A, "/pioneer/robot/simulation_reset")
    assert live.step(A, "pioneer", {"duration": 32})["custom_data"] == "gain=2"


def test_custom_data_takes_a_string_within_the_worlds_limit(live: Logged) -> None:
    rover = rover_node(live)
    msg = live.err(A, "/pioneer/robot/set_field", {"node": rover, "field": "customData", "value": 5},
                   ErrorCode.INVALID_ARGUMENT)
    assert msg == "set_field: field 'customData' is an SFString: takes a string, got 5"
    node = supervisor.node_by_id(live.sim, rover)
    limit = custom_data_chars(live.sim.limits)
    with pytest.raises(ValueError, match=f"{limit + 1} characters, over the world's limit of {limit}"):
        supervisor.set_field(live.sim, node, "customData", "x" * (limit + 1))
    assert get_field(live, rover, "customData") == ""                          # nothing changed
    supervisor.set_field(live.sim, node, "customData", "x" * limit)
    assert len(live.sim.robots["rover"].custom_data) == limit


def test_under_serve_a_new_controller_name_is_kept_and_said_and_the_controller_runs_on(live: Logged) -> None:
    rover = rover_node(live)
    assert get_field(live, rover, "controller") == "<extern>"
    set_field(live, rover, "controller", "wanderer")
    assert get_field(live, rover, "controller") == "wanderer"
    assert next(r for r in live.ok(B, "get_info")["robots"] if r["name"] == "rover")["controller"] == "wanderer"
    assert live.lines == ["robot 'pioneer': set_field: robot 'rover''s controller is now 'wanderer'; nothing is "
                          "ended or started: only `sensorium run` starts controllers"]
    assert live.step(B, "rover", {"duration": 32})["status"] == 0               # still its controller
    set_field(live, rover, "controller", "wanderer")                            # the same value: no change
    assert len(live.lines) == 1


class Switches:
    """What ``sensorium run``'s launcher is asked (launch.Launcher.switch)."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, str, bool]] = []

    def switch(self, robot: str, name: str, synchronous: bool) -> None:
        self.calls.append((robot, name, synchronous))


def test_under_run_a_new_controller_name_ends_the_running_one_and_asks_for_it(live: Logged) -> None:
    launcher = Switches()
    live.core.launcher = launcher
    rover = rover_node(live)
    pending = live.send(B, "/rover/robot/step", {"duration": 32})    # the world waits for pioneer too
    assert pending not in live.pending
    set_field(live, rover, "controller", "wanderer")
    assert live.pending.pop(pending)["result"]["status"] == -1          # as restartController's
    assert launcher.calls == [("rover", "wanderer", True)]
    live.err(B, "/rover/robot/step", {"duration": 32}, ErrorCode.NOT_ATTACHED)     # ended
    # the rover's slot is free: a new controller attaches and gets the robot's data
    assert live.ok(B, "attach", {"robot": "rover"})["robot"] == "rover"
    set_field(live, rover, "controller", "<extern>")
    assert launcher.calls[-1] == ("rover", "<extern>", True)
    set_field(live, rover, "customData", "x")                                   # no controller change
    assert len(launcher.calls) == 2 and live.lines == []


def test_the_step_reply_schema_has_the_custom_data(live: Logged) -> None:
    from sensorium.schemas.services import StepResult

    set_field(live, rover_node(live), "customData", "abc")
    reply = live.step(B, "rover", {"duration": 32})
    assert StepResult.model_validate(reply).custom_data == "abc"
    assert msgpack.packb(reply)


def test_a_proto_robots_controller_field_passes_to_its_robot(tmp_path) -> None:
    from test_webots_api import REPO

    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    proto = (REPO / "tests" / "protos" / "minipuck" / "MiniPuck.proto").as_posix()
    world = tmp_path / "puck.wbt"
    world.write_text(f'#VRML_SIM R2023b utf8\nEXTERNPROTO "{proto}"\nWorldInfo {{ basicTimeStep 16 }}\n'
                     'MiniPuck { name "puck" supervisor TRUE }\n')
    lv = Logged()
    lv.sim = Simulation(load_world(world))
    lv.core = Core(lv.sim, new_token=lambda: "s", log=lv.lines.append)
    lv.ok(A, "attach", {"robot": "puck"})
    me = lv.ok(A, "/puck/robot/get_self")
    assert me["proto"] == "MiniPuck"
    lv.ok(A, "/puck/robot/set_field", {"node": me["node"], "field": "controller", "value": "roamer"})
    assert lv.ok(A, "/puck/robot/get_field", {"node": me["node"], "field": "controller"})["value"] == "roamer"
    assert lv.ok(A, "get_info")["robots"][0]["controller"] == "roamer"
    assert lv.lines[-1].startswith("robot 'puck': set_field: robot 'puck''s controller is now 'roamer'")


def test_none_refuses_a_controller_and_extern_lets_one_attach_again(live: Logged) -> None:
    rover = rover_node(live)
    live.ok(B, "detach", {"session": "s1"})
    set_field(live, rover, "controller", "<none>")
    msg = live.err(B, "attach", {"robot": "rover"}, ErrorCode.WRONG_STATE)
    assert "has controller \"<none>\" (its world file's or a Supervisor's)" in msg
    assert live.step(A, "pioneer", {"duration": 32})["time_ms"] == 32          # the world does not wait for it
    set_field(live, rover, "controller", "<extern>")
    assert live.ok(B, "attach", {"robot": "rover"})["robot"] == "rover"


def test_a_controller_attaching_after_the_change_has_it_from_attach(live: Logged) -> None:
    rover = rover_node(live)
    live.ok(B, "detach", {"session": "s1"})
    set_field(live, rover, "customData", "later")
    assert live.ok(B, "attach", {"robot": "rover"})["custom_data"] == "later"
    assert "custom_data" not in live.step(B, "rover", {"duration": 32})
    live.ok(B, "/rover/robot/set_custom_data", {"value": "own"})        # a reset brings back the file's ""
    live.ok(A, "/pioneer/robot/simulation_reset")
    assert live.step(B, "rover", {"duration": 32})["custom_data"] == ""
