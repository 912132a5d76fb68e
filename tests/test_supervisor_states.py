"""A Supervisor's resets: ``setJointPosition`` and ``saveState``/``loadState`` through the sans-IO core
on real simulations (tests/worlds/nested_joints.wbt: an arm; tests/worlds/webots_api.yaml: a driven
robot with LEDs and a wall), then the same through a Python and a C controller (``sensorium serve``).

Closed forms (nested_joints.wbt): the robot stands at (1, 2, 0) turned a quarter turn about z; the
shoulder turns about z through (0.1, 0, 0.2), its link Solid at (0.3, 0, 0.2), so at pi/2 the link is
at (0.1, 0.2, 0.2) in the robot, (0.8, 2.1, 0.2) in the world; the slider (limits 0..1, 10 m/s)
starts at 0.1 and carries its end point along the link's x."""

from __future__ import annotations

import json
import math
import sys

import pytest
from test_c_client import SAN_ENV, TESTS_C, sanitized_controller
from test_multiprocess import run_paused
from test_supervisor import A, Live
from test_supervisor_nested_joints import WORLD as ARM_WORLD
from test_supervisor_nested_joints import Arm, rz, shoulder, world

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.states import MAX_STATES

HALF_PI = math.pi / 2
LINK_UP = [0.8, 2.1, 0.2]                 # the link's world position with the shoulder at pi/2
INVALID = ErrorCode.INVALID_ARGUMENT


def set_joint(arm: Arm, joint: str, position, index: int = 1) -> dict:
    return arm.call("set_joint_position", {"node": arm.node(joint), "position": position, "index": index})


def refused(arm: Arm, item: str, args: dict) -> str:
    return arm.lv.err(A, f"/{arm.robot}/robot/{item}", args, INVALID)


# ---------------------------------------------------------------------- setJointPosition

def test_set_joint_position_moves_the_arm_at_once_and_the_motor_holds_it():
    """WbJoint::setPosition: the joint is there before any step (its link, what the link holds and
    the devices on it with it), the motor targets it (it stays there as the world runs), the
    position sensor reads it at its next sample and the joint's parameters hold it."""
    arm = Arm()
    bot = arm.lv.sim.robot("armbot")
    assert set_joint(arm, "SHOULDER", HALF_PI) == {"success": True}
    assert arm.position("LINK") == pytest.approx(LINK_UP, abs=1e-12)
    assert arm.position("HAND") == pytest.approx([0.6, 2.1, 0.3], abs=1e-12)
    assert arm.position("TOOL") == pytest.approx([0.6, 2.1, 0.2], abs=1e-12)
    assert arm.orientation("LINK") == pytest.approx(rz(HALF_PI) @ rz(HALF_PI), abs=1e-12)
    assert arm.field("LINK", "translation") == pytest.approx([0.1, 0.2, 0.2], abs=1e-12)
    motor = bot.motor("shoulder")
    assert (motor.position, motor.target_position, motor.speed) == (HALF_PI, HALF_PI, 0.0)
    hinge = arm.call("get_field", {"node": arm.node("SHOULDER"), "field": "jointParameters"})["value"]
    assert arm.call("get_field", {"node": hinge, "field": "position"})["value"] == HALF_PI
    arm.lv.ok(A, "/armbot/shoulder sensor/enable", {"value": 32})
    for _ in range(3):
        arm.lv.step(A, "armbot")
    assert bot.device("shoulder sensor").value == HALF_PI          # read at its sample, held by the motor
    assert arm.position("LINK") == pytest.approx(LINK_UP, abs=1e-12)


def test_a_position_past_the_motors_limit_moves_the_joint_then_the_motor_brings_it_back():
    """The slider's motor stops at 1: the joint goes to 1.5 at once, the motor's target is clamped
    to 1 with Webots' warning (the server's log), and the motor slides it back."""
    arm = Arm()
    got = set_joint(arm, "SLIDE", 1.5)
    assert got["success"] is True
    slide = arm.lv.sim.robot("armbot").motor("slide")
    assert (slide.position, slide.target_position) == (1.5, 1.0)
    # the carriage (0.4, 0, 0.25 in the robot at 0.1) slid 1.4 along the link's x
    assert arm.position("CARRIAGE") == pytest.approx(world([1.8, 0.0, 0.25]), abs=1e-12)
    for _ in range(1000):
        if slide.position == 1.0:
            break
        arm.lv.step(A, "armbot")
    assert slide.position == 1.0
    assert arm.position("CARRIAGE") == pytest.approx(world([1.3, 0.0, 0.25]), abs=1e-12)


def test_set_joint_position_logs_webots_warning_when_it_clamps():
    arm = Arm()
    lines: list[str] = []
    arm.lv.core.log = lines.append
    set_joint(arm, "SLIDE", 1.5)
    assert any("too big requested position: 1.5 > 1" in line for line in lines), lines


PASSIVE = """#VRML_SIM R2023b utf8
Robot {
  name "bot" controller "<extern>" supervisor TRUE
  children [
    DEF PASSIVE HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 } endPoint Solid { translation 1 0 0 } }
    DEF TWO Hinge2Joint {
      device2 [ RotationalMotor { name "pitch" } ]
      endPoint Solid { translation 0 1 0 }
    }
    DEF BALL BallJoint {
      device [ RotationalMotor { name "b1" } ] device2 [ RotationalMotor { name "b2" } ]
      device3 [ RotationalMotor { name "b3" } ]
      endPoint Solid { translation 0 0 1 }
    }
  ]
}
"""


def test_bad_joint_calls_get_webots_line_or_one_of_ours_and_change_nothing(tmp_path):
    arm = Arm()
    before = arm.position("LINK")
    assert "Only values greater than or equal to 1" in refused(arm, "set_joint_position",
                                                                {"node": arm.node("SHOULDER"), "position": 1.0, "index": 0})
    msg = refused(arm, "set_joint_position", {"node": arm.node("SHOULDER"), "position": 1.0, "index": 2})
    assert "SliderJoint and HingeJoint only support index 1" in msg
    msg = refused(arm, "set_joint_position", {"node": arm.node("SHOULDER"), "position": 1.0, "index": 4})
    assert "SliderJoint and HingeJoint only support index 1" in msg
    for name in ("LINK", "ARMBOT", "TOOL"):
        assert "which is not a joint node" in refused(arm, "set_joint_position",
                                                      {"node": arm.node(name), "position": 1.0, "index": 1})
    for bad in (math.nan, math.inf):
        refused(arm, "set_joint_position", {"node": arm.node("SHOULDER"), "position": bad, "index": 1})
    msg = refused(arm, "set_joint_position", {"node": arm.node("SLIDE"), "position": 1e6, "index": 1})
    assert "a joint's 'position' must be a finite number within ±100000, got 1000000.0" in msg
    assert arm.position("LINK") == before
    assert arm.lv.sim.robot("armbot").motor("shoulder").target_position == 0.0

    path = tmp_path / "passive.wbt"
    path.write_text(PASSIVE)
    other = Arm(path, "bot")
    msg = refused(other, "set_joint_position", {"node": other.node("PASSIVE"), "position": 1.0, "index": 1})
    assert "has no motor on its axis 1 here" in msg
    assert "has no motor on its axis 1" in refused(other, "set_joint_position",
                                                   {"node": other.node("TWO"), "position": 1.0, "index": 1})
    assert "Hinge2Joint only supports index 1 or 2" in refused(other, "set_joint_position",
                                                               {"node": other.node("TWO"), "position": 1.0, "index": 3})
    set_joint(other, "TWO", 0.5, 2)
    for k in (1, 2, 3):
        set_joint(other, "BALL", 0.1 * k, k)
    motors = other.lv.sim.robot("bot").motors
    assert [motors[m].position for m in ("pitch", "b1", "b2", "b3")] == [0.5, 0.1, 0.2, 0.1 * 3]


def test_setting_a_joints_parameters_position_moves_it_and_the_motor_keeps_its_target():
    """setSFFloat on jointParameters.position (WbHingeJoint::updatePosition): the joint is there at
    once; the motor keeps its target (0), so it turns the joint back."""
    arm = Arm()
    hinge = arm.call("get_field", {"node": arm.node("SHOULDER"), "field": "jointParameters"})["value"]
    arm.call("set_field", {"node": hinge, "field": "position", "value": HALF_PI})
    assert arm.position("LINK") == pytest.approx(LINK_UP, abs=1e-12)
    motor = arm.lv.sim.robot("armbot").motor("shoulder")
    assert (motor.position, motor.target_position) == (HALF_PI, 0.0)
    for _ in range(1000):                # a generous limit (it accelerates at 10 rad/s^2)
        if motor.position == 0.0:
            break
        arm.lv.step(A, "armbot")
    assert motor.position == 0.0
    assert arm.position("LINK") == pytest.approx(world([0.3, 0.0, 0.2]), abs=1e-12)
    refused(arm, "set_field", {"node": hinge, "field": "position", "value": [1.0, 2.0, 3.0]})


# ---------------------------------------------------------------------- saveState / loadState

def drive(live: Live, steps: int) -> None:
    live.ok(A, "/pioneer/left wheel motor/set_position", {"value": math.inf})
    live.ok(A, "/pioneer/right wheel motor/set_position", {"value": math.inf})
    live.ok(A, "/pioneer/left wheel motor/set_velocity", {"value": 5.0})
    live.ok(A, "/pioneer/right wheel motor/set_velocity", {"value": 3.0})
    for _ in range(steps):
        live.step(A, "pioneer")


@pytest.fixture
def pioneer():
    lv = Live()
    lv.ok(A, "attach", {"robot": "pioneer"})
    return lv


def state(live: Live, item: str, node: int, name: str) -> dict:
    return live.ok(A, f"/pioneer/robot/{item}", {"node": node, "state": name})


def test_load_init_after_driving_restores_the_pose_bit_for_bit_and_the_clock_keeps_going(pioneer):
    live = pioneer
    start = live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1})
    live.ok(A, "/pioneer/led0/set", {"value": 2})
    drive(live, 10)
    bot = live.sim.robot("pioneer")
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1}) != start
    assert state(live, "load_node_state", 1, "__init__") == {"success": True}
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1}) == start     # bit for bit
    assert live.sim.time_ms == 320                                              # the clock kept its time
    for m in bot.motors.values():       # each wheel at 0, its motor holding it there at maxVelocity
        assert (m.position, m.target_position, m.velocity) == (0.0, 0.0, 10.0)
    assert live.ok(A, "/pioneer/led0/get") == {"value": 0}                     # WbLed::reset
    assert live.ok(A, "/pioneer/robot/get_node_velocity", {"node": 1})["value"] == [0.0] * 6
    live.step(A, "pioneer")                                          # the robot stays, the clock goes on
    assert live.sim.time_ms == 352
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1})["position"] == start["position"]


def test_a_saved_state_comes_back_after_more_driving(pioneer):
    live = pioneer
    drive(live, 5)
    bot = live.sim.robot("pioneer")
    mid = live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1})
    wheels = {n: m.position for n, m in bot.motors.items()}
    assert all(w != 0.0 for w in wheels.values())
    state(live, "save_node_state", 1, "mid")
    drive(live, 5)
    state(live, "load_node_state", 1, "mid")
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1}) == mid
    assert {n: (m.position, m.target_position) for n, m in bot.motors.items()} == {n: (w, w) for n, w in wheels.items()}
    live.step(A, "pioneer")                          # the wheels hold their angles: it does not move
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1})["position"] == mid["position"]
    state(live, "save_node_state", 1, "__init__")    # a node's own "__init__" replaces the loaded one
    drive(live, 3)
    state(live, "load_node_state", 1, "__init__")
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1})["position"] == mid["position"]


def test_a_solids_state_is_its_pose(pioneer):
    live = pioneer
    wall = 4
    assert live.ok(A, "/pioneer/robot/get_from_id", {"id": wall})["name"] == "wall"
    live.ok(A, "/pioneer/robot/set_field", {"node": wall, "field": "translation", "value": [3.0, 1.0, 0.25]})
    state(live, "save_node_state", wall, "moved")
    state(live, "load_node_state", wall, "__init__")
    assert live.sim.scene.solid_poses["wall"].translation.tolist() == [2.0, 0.0, 0.25]
    state(live, "load_node_state", wall, "moved")
    assert live.sim.scene.solid_poses["wall"].translation.tolist() == [3.0, 1.0, 0.25]


def test_an_imported_solids_init_state_is_where_it_was_imported(pioneer):
    live = pioneer
    (box,) = live.ok(A, "/pioneer/robot/import_node_from_string", {
        "node": 0, "field": "children", "position": -1,
        "node_string": "DEF BOX Solid { translation 1 2 0.5 name \"box\" }"})["value"]
    live.ok(A, "/pioneer/robot/set_field", {"node": box, "field": "translation", "value": [5.0, 5.0, 0.5]})
    state(live, "load_node_state", box, "__init__")
    assert live.sim.scene.solid_poses["box"].translation.tolist() == [1.0, 2.0, 0.5]


def test_an_arms_state_holds_its_joints_and_a_joints_own_state_only_what_is_inside_it():
    arm = Arm()
    set_joint(arm, "SHOULDER", HALF_PI)
    set_joint(arm, "SLIDE", 0.6)
    robot = arm.node("ARMBOT")
    arm.call("save_node_state", {"node": robot, "state": "reach"})
    arm.call("save_node_state", {"node": arm.node("SLIDE"), "state": "out"})
    arm.call("load_node_state", {"node": robot, "state": "__init__"})
    motors = arm.lv.sim.robot("armbot").motors
    assert (motors["shoulder"].position, motors["slide"].position) == (0.0, 0.1)
    assert arm.position("LINK") == pytest.approx(world([0.3, 0.0, 0.2]), abs=1e-12)
    assert arm.position("CARRIAGE") == pytest.approx(world([0.4, 0.0, 0.25]), abs=1e-12)
    arm.call("load_node_state", {"node": arm.node("SLIDE"), "state": "out"})      # the slider only
    assert (motors["shoulder"].position, motors["slide"].position) == (0.0, 0.6)
    arm.call("load_node_state", {"node": robot, "state": "reach"})
    assert (motors["shoulder"].target_position, motors["slide"].target_position) == (HALF_PI, 0.6)
    assert arm.position("CARRIAGE") == pytest.approx(world(shoulder([0.9, 0.0, 0.25], HALF_PI)), abs=1e-12)
    arm.call("load_node_state", {"node": arm.node("SHOULDER"), "state": "__init__"})  # the shoulder and past it
    assert (motors["shoulder"].position, motors["slide"].position) == (0.0, 0.1)


def test_bad_state_calls_change_nothing_and_say_one_line(pioneer):
    live = pioneer
    drive(live, 2)
    pose = live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1})
    msg = live.err(A, "/pioneer/robot/load_node_state", {"node": 1, "state": "nope"}, INVALID)
    assert "Robot 'pioneer' (node 1) has no saved state 'nope' (saved: '__init__')" in msg
    long = "x" * 5000
    msg = live.err(A, "/pioneer/robot/save_node_state", {"node": 1, "state": long}, INVALID)
    assert len(msg) < 1000 and "1024" in msg
    live.err(A, "/pioneer/robot/load_node_state", {"node": 1, "state": long}, INVALID)
    live.send(A, "/pioneer/robot/save_node_state", {"node": 1, "state": "x" * (1 << 20)})   # a 1 MB name
    (reply,) = live.pending.values()
    assert reply["ok"] is False and reply["error"]["code"] == ErrorCode.TOO_LARGE
    live.pending.clear()
    assert "has no state here" in live.err(A, "/pioneer/robot/save_node_state", {"node": 0, "state": "a"}, INVALID)
    live.err(A, "/pioneer/robot/load_node_state", {"node": 99, "state": "a"}, INVALID)
    assert live.ok(A, "/pioneer/robot/get_node_pose", {"node": 1}) == pose
    for k in range(MAX_STATES - 1):                  # "__init__" is not one of the node's own names here
        state(live, "save_node_state", 1, f"s{k}")
    state(live, "save_node_state", 1, "s63")
    msg = live.err(A, "/pioneer/robot/save_node_state", {"node": 1, "state": "one more"}, INVALID)
    assert f"already has {MAX_STATES} saved states" in msg
    state(live, "save_node_state", 1, "s0")          # saving under a name it has is always allowed
    state(live, "load_node_state", 1, "s63")


# ---------------------------------------------------------------------- the clients

def _check_client_run(out: dict, err: str) -> None:
    assert out["set"] == pytest.approx(LINK_UP, abs=1e-12)
    assert out["sensor"] == HALF_PI
    assert out["reach"] == pytest.approx(world(shoulder([0.4 + 0.25, 0.0, 0.25], HALF_PI)), abs=1e-12)
    assert out["init"] == pytest.approx(world([0.3, 0.0, 0.2]), abs=1e-12)
    assert out["robot"] == [1.0, 2.0, 0.0]
    assert out["times"][1] > out["times"][0]                   # the clock keeps going
    assert out["back"] == pytest.approx(out["reach"], abs=1e-12)
    assert out["after_bad"] == pytest.approx(out["reach"], abs=1e-12)
    lines = [line for line in err.splitlines() if line.startswith("Error:")]
    joint = "Error: wb_supervisor_node_set_joint_position"
    wanted = [f"{joint}() called with an invalid 'index'. Only values greater than or equal to 1 are supported.",
              "SliderJoint and HingeJoint only support index 1",
              "which is not a joint node",
              f"{joint}() called with a 'position' that is not a finite number",
              "Error: wb_supervisor_node_load_state(): ",
              "Error: wb_supervisor_node_load_state() called with a 'state_name' of 1048576"]
    assert len(lines) == len(wanted), err
    for line, part in zip(lines, wanted):
        assert part in line, (line, part)
    assert "has no saved state 'nope'" in lines[4]


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_resets_its_arm_in_python(tmp_path):
    """tests/controllers/arm_resets.py through ``sensorium serve``, written as for Webots."""
    ctl = run_paused(ARM_WORLD, tmp_path, "arm_resets.py", "armbot")
    _check_client_run(json.loads(ctl.out[-1]), ctl.stderr())


@pytest.mark.skipif(sys.platform == "win32", reason="needs a POSIX C toolchain")
def test_a_webots_supervisor_resets_its_arm_in_c(tmp_path, tmp_path_factory):
    """tests/c/arm_resets.c (AddressSanitizer/UBSan): the same run, the same lines."""
    exe = sanitized_controller(tmp_path_factory, TESTS_C / "arm_resets.c")
    ctl = run_paused(ARM_WORLD, tmp_path, exe, "armbot", env=SAN_ENV)
    _check_client_run(json.loads(ctl.out[-1]), ctl.stderr())

