"""A Supervisor reads a robot's nodes past its joints where the joints have put them
(tests/worlds/nested_joints.wbt, through the sans-IO core on a real simulation): the world pose of
an arm's link Solid, of what it holds and of a slider's end point after the joints moved, the end
points' ``translation``/``rotation`` fields following their joints as Webots' HingeJoint and
SliderJoint set them, and before any motion the poses the world file gives. Closed forms: the robot
stands at (1, 2, 0) turned a quarter turn about z; the shoulder turns about z through (0.1, 0, 0.2),
the slider slides along the link's x from position 0.1. The same through a Python controller
(``sensorium serve``)."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest
from test_c_client import SAN_ENV, TESTS_C, sanitized_controller
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "nested_joints.wbt"
HALF_PI = math.pi / 2
ROBOT = np.array([1.0, 2.0, 0.0])         # the robot's translation; its rotation: rz(HALF_PI)
ANCHOR = np.array([0.1, 0.0, 0.2])        # the shoulder's, robot frame
SLIDE0, D = 0.1, 0.25                      # the slider's initial position, how far it is moved


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def world(p) -> list[float]:
    """A robot-frame point in the world."""
    return list(rz(HALF_PI) @ np.asarray(p, dtype=np.float64) + ROBOT)


def shoulder(p, q: float) -> np.ndarray:
    """A robot-frame point past the shoulder turned by q."""
    return rz(q) @ (np.asarray(p, dtype=np.float64) - ANCHOR) + ANCHOR


class Arm:
    def __init__(self, path=WORLD, robot: str = "armbot"):
        self.robot = robot
        self.lv = Live(Simulation(load_world(path)))
        self.lv.ok(A, "attach", {"robot": robot})

    def call(self, item: str, args: dict):
        return self.lv.ok(A, f"/{self.robot}/robot/{item}", args)

    def node(self, name: str) -> int:
        return self.call("get_from_def", {"name": name})["node"]

    def position(self, name: str) -> list[float]:
        return self.call("get_node_pose", {"node": self.node(name)})["position"]

    def orientation(self, name: str) -> np.ndarray:
        return np.array(self.call("get_node_pose", {"node": self.node(name)})["orientation"]).reshape(3, 3)

    def field(self, name: str, field: str) -> list[float]:
        got = self.call("get_field", {"node": self.node(name), "field": field})
        assert got["type"] in ("SFVec3f", "SFRotation"), got
        return got["value"]

    def move(self, motor: str, target: float) -> None:
        """Command the joint and step until it is there (generous limit)."""
        m = self.lv.sim.robot(self.robot).motor(motor)
        m.set_position(target)
        for _ in range(1000):
            if m.position == target:
                return
            self.lv.step(A, self.robot)
        raise AssertionError(f"{motor} did not reach {target}: {m.position}")


def test_before_any_motion_the_nodes_are_where_the_world_file_puts_them():
    arm = Arm()
    assert arm.position("LINK") == pytest.approx(world([0.3, 0.0, 0.2]), abs=1e-12)
    assert arm.orientation("LINK") == pytest.approx(rz(HALF_PI), abs=1e-12)
    assert arm.position("HAND") == pytest.approx(world([0.5, 0.0, 0.3]), abs=1e-12)
    assert arm.orientation("FINGER") == pytest.approx(rz(HALF_PI) @ rx(HALF_PI), abs=1e-12)
    assert arm.position("CARRIAGE") == pytest.approx(world([0.4, 0.0, 0.25]), abs=1e-12)
    assert arm.field("LINK", "translation") == pytest.approx([0.3, 0.0, 0.2], abs=1e-12)
    assert arm.field("LINK", "rotation") == pytest.approx([0.0, 0.0, 1.0, 0.0], abs=1e-12)
    assert arm.field("CARRIAGE", "translation") == pytest.approx([0.1, 0.0, 0.05], abs=1e-12)


def test_a_turned_hinge_carries_its_link_and_what_the_link_holds():
    arm = Arm()
    arm.move("shoulder", HALF_PI)
    turned = rz(HALF_PI) @ rz(HALF_PI)
    # the link Solid: (0.3, 0, 0.2) turned a quarter turn about z through the anchor: (0.1, 0.2, 0.2)
    assert list(shoulder([0.3, 0.0, 0.2], HALF_PI)) == pytest.approx([0.1, 0.2, 0.2], abs=1e-15)
    assert arm.position("LINK") == pytest.approx(world([0.1, 0.2, 0.2]), abs=1e-12)
    assert arm.position("LINK") == pytest.approx([0.8, 2.1, 0.2], abs=1e-12)
    assert arm.orientation("LINK") == pytest.approx(turned, abs=1e-12)
    # what it holds, at any depth (through a Pose), and a device on it
    assert arm.position("HAND") == pytest.approx([0.6, 2.1, 0.3], abs=1e-12)
    assert arm.orientation("HAND") == pytest.approx(turned, abs=1e-12)
    assert arm.position("ELBOW") == pytest.approx(world(shoulder([0.5, 0.0, 0.2], HALF_PI)), abs=1e-12)
    assert arm.position("FINGER") == pytest.approx(world(shoulder([0.5, 0.1, 0.2], HALF_PI)), abs=1e-12)
    assert arm.orientation("FINGER") == pytest.approx(turned @ rx(HALF_PI), abs=1e-12)
    assert arm.position("TOOL") == pytest.approx([0.6, 2.1, 0.2], abs=1e-12)
    assert arm.position("CARRIAGE") == pytest.approx(world(shoulder([0.4, 0.0, 0.25], HALF_PI)), abs=1e-12)
    # getPose(from): the hand in the link's frame is as the file places it
    rel = arm.call("get_node_pose", {"node": arm.node("HAND")})
    link = arm.call("get_node_pose", {"node": arm.node("LINK")})
    r_link = np.array(link["orientation"]).reshape(3, 3)
    assert list(r_link.T @ (np.array(rel["position"]) - np.array(link["position"]))) == \
        pytest.approx([0.2, 0.0, 0.1], abs=1e-12)
    # the end point's fields follow the joint (Webots' HingeJoint sets them); the others, in the
    # link's frame, stay
    assert arm.field("LINK", "translation") == pytest.approx([0.1, 0.2, 0.2], abs=1e-12)
    assert arm.field("LINK", "rotation") == pytest.approx([0.0, 0.0, 1.0, HALF_PI], abs=1e-12)
    assert arm.field("HAND", "translation") == pytest.approx([0.0, 0.0, 0.1], abs=1e-12)
    assert arm.field("ELBOW", "translation") == pytest.approx([0.2, 0.0, 0.0], abs=1e-12)
    assert arm.field("FINGER", "rotation") == pytest.approx([1.0, 0.0, 0.0, HALF_PI], abs=1e-12)
    assert arm.field("CARRIAGE", "translation") == pytest.approx([0.1, 0.0, 0.05], abs=1e-12)
    # back where it started: the loaded poses again
    arm.move("shoulder", 0.0)
    assert arm.position("HAND") == pytest.approx(world([0.5, 0.0, 0.3]), abs=1e-12)
    assert arm.field("LINK", "translation") == pytest.approx([0.3, 0.0, 0.2], abs=1e-12)


def test_a_slid_slider_moves_its_end_point_along_its_axis_and_joints_compose():
    arm = Arm()
    arm.move("slide", SLIDE0 + D)
    assert arm.position("CARRIAGE") == pytest.approx(world([0.4 + D, 0.0, 0.25]), abs=1e-12)
    assert arm.position("CARRIAGE") == pytest.approx([1.0, 2.65, 0.25], abs=1e-12)
    assert arm.orientation("CARRIAGE") == pytest.approx(rz(HALF_PI), abs=1e-12)
    assert arm.field("CARRIAGE", "translation") == pytest.approx([0.1 + D, 0.0, 0.05], abs=1e-12)
    assert arm.field("CARRIAGE", "rotation") == pytest.approx([0.0, 0.0, 1.0, 0.0], abs=1e-12)
    assert arm.position("LINK") == pytest.approx(world([0.3, 0.0, 0.2]), abs=1e-12)   # the shoulder did not turn
    # the shoulder turned too: the slid carriage turns with the link
    arm.move("shoulder", HALF_PI)
    assert arm.position("CARRIAGE") == pytest.approx([0.45, 2.1, 0.25], abs=1e-12)
    assert arm.orientation("CARRIAGE") == pytest.approx(rz(math.pi), abs=1e-12)
    assert arm.field("CARRIAGE", "translation") == pytest.approx([0.1 + D, 0.0, 0.05], abs=1e-12)  # in the link


def test_a_joints_parameters_hold_its_position_now():
    """A moving joint's jointParameters (SFNode): a HingeJointParameters / JointParameters node whose
    ``position`` reads the joint's position, loaded then moved, and sets it."""
    arm = Arm()

    def parameters(joint: str) -> int:
        got = arm.call("get_field", {"node": arm.node(joint), "field": "jointParameters"})
        assert got["type"] == "SFNode"
        return got["value"]

    def position(params: int):
        return arm.call("get_field", {"node": params, "field": "position"})

    hinge, slider = parameters("SHOULDER"), parameters("SLIDE")
    assert arm.call("get_from_id", {"id": hinge}) == {"node": hinge, "type": "HingeJointParameters", "name": "",
                                                      "def_name": "", "parent": arm.node("SHOULDER"), "proto": ""}
    assert arm.call("get_from_id", {"id": slider})["type"] == "JointParameters"
    assert position(hinge) == {"type": "SFFloat", "value": 0.0}
    assert position(slider) == {"type": "SFFloat", "value": SLIDE0}
    assert all(math.isnan(v) for v in arm.call("get_node_pose", {"node": hinge})["position"])   # no Pose
    arm.move("shoulder", HALF_PI)
    arm.move("slide", SLIDE0 + D)
    assert position(hinge)["value"] == HALF_PI
    assert position(slider)["value"] == SLIDE0 + D
    assert arm.call("get_field", {"node": arm.node("LINK"), "field": "jointParameters"})["type"] == ""
    # settable, as in Webots: the joint is there at once (tests/test_supervisor_states.py)
    arm.call("set_field", {"node": hinge, "field": "position", "value": 1.0})
    assert position(hinge)["value"] == 1.0
    msg = arm.lv.err(A, "/armbot/robot/set_field", {"node": arm.node("LINK"), "field": "translation",
                                                    "value": [1.0, 0.0, 0.0]}, ErrorCode.INVALID_ARGUMENT)
    assert "field 'translation' (SFVec3f) of Solid" in msg and "read-only here" in msg
    arm.lv.sim.reset()                      # a reset puts the joints back, and their positions
    assert position(hinge)["value"] == 0.0 and position(slider)["value"] == SLIDE0


SOLID_ONLY = """#VRML_SIM R2023b utf8
Robot {
  name "bare" controller "<extern>" supervisor TRUE
  children [
    HingeJoint {
      jointParameters HingeJointParameters { axis 0 0 1 anchor 0.1 0 0 position 0.5 }
      device [ RotationalMotor { name "turn" maxVelocity 100 } ]
      endPoint DEF END Solid { translation 0.3 0 0 rotation 0 0 1 0.5 children [ DEF KNOB Solid { translation 0.1 0 0 } ] }
    }
    DEF FREE HingeJoint {
      device [ RotationalMotor { name "free" } ]
      endPoint DEF WING Solid { translation 0 0.2 0 }
    }
  ]
}
"""


def test_a_joint_that_carries_nothing_but_solids_moves_them_too(tmp_path):
    """Nothing but Solids past the joint (no shape, device or light rides it): the links are made
    when the Supervisor asks. The joint starts at 0.5 (where the file places the end point)."""
    path = tmp_path / "bare.wbt"
    path.write_text(SOLID_ONLY)
    arm = Arm(path, "bare")
    assert arm.lv.sim.robot("bare").links is None
    assert arm.position("KNOB") == pytest.approx([0.3 + 0.1 * math.cos(0.5), 0.1 * math.sin(0.5), 0.0], abs=1e-12)
    arm.move("turn", 0.5 + HALF_PI)
    assert arm.position("END") == pytest.approx([0.1, 0.2, 0.0], abs=1e-12)
    assert arm.orientation("END") == pytest.approx(rz(0.5 + HALF_PI), abs=1e-12)
    assert arm.position("KNOB") == pytest.approx([0.1 - 0.1 * math.sin(0.5), 0.2 + 0.1 * math.cos(0.5), 0.0],
                                                 abs=1e-12)
    assert arm.field("END", "translation") == pytest.approx([0.1, 0.2, 0.0], abs=1e-12)
    assert arm.field("END", "rotation") == pytest.approx([0.0, 0.0, 1.0, 0.5 + HALF_PI], abs=1e-12)
    assert arm.lv.sim.robot("bare").links is None            # the simulation still moves no link
    # a joint the world file gives no jointParameters: Webots' NULL
    assert arm.call("get_field", {"node": arm.node("FREE"), "field": "jointParameters"}) == {"type": "SFNode",
                                                                                           "value": 0}


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_reads_its_arm_where_the_joints_put_it(tmp_path):
    """tests/controllers/nested_joints.py through ``sensorium serve``, written as for Webots."""
    ctl = run_paused(WORLD, tmp_path, "nested_joints.py", "armbot")
    out = json.loads(ctl.out[-1])
    before, after = out["before"], out["after"]
    assert out["at"] == [HALF_PI, SLIDE0 + D]
    assert before["link"] == pytest.approx(world([0.3, 0.0, 0.2]), abs=1e-12)
    assert before["link_translation"] == pytest.approx([0.3, 0.0, 0.2], abs=1e-12)
    assert before["carriage"] == pytest.approx(world([0.4, 0.0, 0.25]), abs=1e-12)
    assert after["link"] == pytest.approx([0.8, 2.1, 0.2], abs=1e-12)
    assert np.array(after["link_orientation"]).reshape(3, 3) == pytest.approx(rz(math.pi), abs=1e-12)
    assert after["hand"] == pytest.approx([0.6, 2.1, 0.3], abs=1e-12)
    assert after["carriage"] == pytest.approx(world(shoulder([0.4 + D, 0.0, 0.25], HALF_PI)), abs=1e-12)
    assert after["link_translation"] == pytest.approx([0.1, 0.2, 0.2], abs=1e-12)
    assert after["link_rotation"] == pytest.approx([0.0, 0.0, 1.0, HALF_PI], abs=1e-12)
    assert after["carriage_translation"] == pytest.approx([0.1 + D, 0.0, 0.05], abs=1e-12)
    assert out["parameters"] == [["HingeJointParameters", "SHOULDER"], ["JointParameters", "SLIDE"]]
    assert before["positions"] == [0.0, SLIDE0]
    assert after["positions"] == [HALF_PI, SLIDE0 + D]
    for seen in (before, after):            # getPose(link): the hand where the file puts it in the link
        assert seen["hand_in_link"] == pytest.approx([0.2, 0.0, 0.1], abs=1e-12)


def test_a_joints_end_point_and_devices_are_its_fields():
    """Webots' HingeJoint/SliderJoint ``endPoint`` (SFNode: the end point Solid) and ``device``
    (MFNode: its motor and position sensor, in the world file's order), read-only, as a Supervisor
    walks a robot's tree down past its joints (children, then each joint's endPoint); a joint with
    no end point here answers NULL (0). Before, a walk stopped at the first joint ("no value")."""
    arm = Arm()

    def field(node: int, name: str):
        return arm.call("get_field", {"node": node, "field": name})

    def info(node: int) -> tuple[str, str, str]:
        got = arm.call("get_from_id", {"id": node})
        return got["type"], got["def_name"], got["name"]

    shoulder, slide = arm.node("SHOULDER"), arm.node("SLIDE")
    assert field(shoulder, "endPoint") == {"type": "SFNode", "value": arm.node("LINK")}
    assert field(slide, "endPoint") == {"type": "SFNode", "value": arm.node("CARRIAGE")}
    got = field(shoulder, "device")
    assert got["type"] == "MFNode"
    assert [info(d) for d in got["value"]] == [("RotationalMotor", "", "shoulder"),
                                               ("PositionSensor", "", "shoulder sensor")]
    assert [info(d) for d in field(slide, "device")["value"]] == [("LinearMotor", "", "slide"),
                                                                  ("PositionSensor", "", "slide sensor")]
    assert field(arm.node("LINK"), "endPoint")["type"] == ""           # a Solid has none
    assert field(shoulder, "device2")["type"] == ""                    # a HingeJoint has one device field
    msg = arm.lv.err(A, "/armbot/robot/set_field", {"node": shoulder, "field": "endPoint", "value": 0},
                     ErrorCode.INVALID_ARGUMENT)
    assert "read-only here" in msg

    def walk(node: int, depth: int, out: list) -> None:     # as a Webots supervisor walks a robot's tree
        kind, def_name, _ = info(node)
        out.append((depth, kind, def_name))
        for name in ("children", "device"):
            kids = field(node, name)
            if kids["type"] == "MFNode":
                for kid in kids["value"]:
                    walk(kid, depth + 1, out)
        end = field(node, "endPoint")
        if end["type"] == "SFNode" and end["value"]:
            walk(end["value"], depth + 1, out)

    seen: list = []
    walk(arm.node("ARMBOT"), 0, seen)
    assert [(d, k, n) for d, k, n in seen if n] == [
        (0, "Robot", "ARMBOT"), (1, "HingeJoint", "SHOULDER"), (2, "Solid", "LINK"), (3, "Pose", "ELBOW"),
        (4, "Solid", "HAND"), (3, "Solid", "FINGER"), (3, "DistanceSensor", "TOOL"), (3, "SliderJoint", "SLIDE"),
        (4, "Solid", "CARRIAGE")]
    assert sum(1 for _, k, _ in seen if k in ("RotationalMotor", "LinearMotor", "PositionSensor")) == 4


def test_a_field_webots_lacks_too_is_absent_and_one_it_has_is_not():
    """get_field of a field the node lacks here: ``absent`` when Webots' node of that type has none
    either (a Solid's ``endPoint``, a joint's ``children``, a motor's pose): the clients then answer
    NULL silently, as libController does; a field Webots has but Sensorium does not serve (a
    Solid's ``boundingObject``, an unmotorised joint's ``jointParameters``) is not absent: the
    clients say it is not served here."""
    arm = Arm()
    link, shoulder = arm.node("LINK"), arm.node("SHOULDER")
    motor = arm.call("get_field", {"node": shoulder, "field": "device"})["value"][0]

    def absent(node: int, field: str) -> bool:
        got = arm.call("get_field", {"node": node, "field": field})
        assert got["type"] == "" and got["value"] == [], got
        return bool(got.get("absent", False))

    for node, field in ((link, "endPoint"), (link, "device"), (link, "jointParameters"), (shoulder, "children"),
                        (shoulder, "translation"), (shoulder, "name"), (shoulder, "device2"), (motor, "children"),
                        (motor, "rotation"), (arm.node("ARMBOT"), "endPoint"), (arm.node("ELBOW"), "name")):
        assert absent(node, field), (node, field)
    for node, field in ((link, "boundingObject"), (link, "physics"), (motor, "maxVelocity"), (shoulder, "nonsense")):
        assert not absent(node, field), (node, field)
    top = {arm.call("get_from_id", {"id": n})["type"]: n for n in arm.call("get_field", {"node": 0, "field": "children"})["value"]}
    assert {"WorldInfo", "Viewpoint"} <= set(top)
    for kind in ("WorldInfo", "Viewpoint"):      # a walk down the whole scene probes them too
        assert all(absent(top[kind], field) for field in ("children", "translation", "rotation", "name", "endPoint"))
    assert not absent(top["WorldInfo"], "northDirection")       # Webots has it, not served here


WALK = ["0 Robot ARMBOT", "1 HingeJoint SHOULDER 0.500", "2 RotationalMotor ", "2 PositionSensor ", "2 Solid LINK",
        "3 Pose ELBOW", "4 Solid HAND", "3 Solid FINGER", "3 DistanceSensor TOOL", "3 SliderJoint SLIDE 0.100",
        "4 LinearMotor ", "4 PositionSensor ", "4 Solid CARRIAGE"]


def _no_field_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if "has no field" in line]


def test_a_webots_supervisor_walks_its_tree_past_the_joints_in_python(tmp_path):
    """tests/controllers/tree_walker.py through ``sensorium serve``: it reaches every node past the
    joints (their end points and devices), and its probes of fields the nodes lack in Webots too
    print nothing; only the link's boundingObject (Webots has one) is said as not served."""
    ctl = run_paused(WORLD, tmp_path, "tree_walker.py", "armbot")
    assert [line.rstrip() for line in ctl.out[:-1]] == [w.rstrip() for w in WALK]
    assert ctl.out[-1] == "boundingObject None"
    (line,) = _no_field_lines(ctl.stderr())
    assert "has no field 'boundingObject' in Sensorium" in line


@pytest.mark.skipif(sys.platform == "win32", reason="needs a POSIX C toolchain")
def test_a_webots_supervisor_walks_its_tree_past_the_joints_in_c(tmp_path, tmp_path_factory):
    """tests/c/tree_walker.c (AddressSanitizer/UBSan): the same walk and the same one line."""
    exe = sanitized_controller(tmp_path_factory, TESTS_C / "tree_walker.c")
    ctl = run_paused(WORLD, tmp_path, exe, "armbot", env=SAN_ENV)        # (an absolute path: CONTROLLERS / exe is exe)
    assert [line.rstrip() for line in ctl.out[:-1]] == [w.rstrip() for w in WALK]
    assert ctl.out[-1] == "boundingObject None"
    (line,) = _no_field_lines(ctl.stderr())
    assert "has no field 'boundingObject' in Sensorium" in line


ROLLED = """#VRML_SIM R2023b utf8
Robot {
  name "roller" controller "<extern>" supervisor TRUE
  children [
    HingeJoint {
      jointParameters HingeJointParameters { axis 0 0 1 position 2 }
      device [ RotationalMotor { name "yaw" maxVelocity 100 } ]
      endPoint Solid { rotation 0 0 1 2 children [
        HingeJoint {
          jointParameters HingeJointParameters { axis 1 0 0 anchor 0.3 0 0 position 0.5 }
          device [ RotationalMotor { name "roll" maxVelocity 100 } ]
          endPoint DEF LINK Solid { translation 0.3 0 0 rotation 1 0 0 0.5 children [ DEF CUP Solid { translation 0 0 -0.1 } ] }
        }
      ] }
    }
  ]
}
"""


def test_an_end_point_turned_back_to_no_rotation_reads_webots_identity(tmp_path):
    """A roll hinge that starts at 0.5 (its end point turned 0.5 about x, as the file writes it) on a
    yaw hinge that starts at 2, both commanded to 0 (Webots' vacuum_gripper arm): the roll link's
    rotation in its parent is then R(x, -0.5) R(x, 0.5),
    the identity up to rounding, and reads Webots' identity 0 0 1 0 (WbRotation: an angle below
    10000 machine epsilons is no turn), not an axis of rounding noise with an angle of ~1e-17."""
    path = tmp_path / "rolled.wbt"
    path.write_text(ROLLED)
    arm = Arm(path, "roller")
    arm.move("yaw", 0.0)
    arm.move("roll", 0.0)
    assert arm.field("LINK", "rotation") == [0.0, 0.0, 1.0, 0.0]
    assert arm.position("CUP") == pytest.approx([0.3, 0.0, -0.1], abs=1e-12)
    arm.move("roll", 0.25)                                   # a real turn keeps its axis and angle
    assert arm.field("LINK", "rotation") == pytest.approx([1.0, 0.0, 0.0, 0.25], abs=1e-12)


DEF_PARAMETERS = """#VRML_SIM R2023b utf8
Robot {
  name "tuner" controller "<extern>" supervisor TRUE
  children [
    HingeJoint {
      jointParameters DEF TURN_PARAMETERS HingeJointParameters { axis 0 0 1 position 0.25 }
      device [ RotationalMotor { name "turn" maxVelocity 100 } ]
      endPoint DEF ARM Solid { translation 0.2 0 0 rotation 0 0 1 0.25 }
    }
    SliderJoint {
      jointParameters DEF SLIDE_PARAMETERS JointParameters { axis 1 0 0 }
      device [ LinearMotor { name "slide" maxPosition 1 } ]
      endPoint Solid { translation 0 0.5 0 }
    }
    HingeJoint {
      jointParameters USE TURN_PARAMETERS
      device [ RotationalMotor { name "twin" } ]
      endPoint Solid { translation 0 -0.5 0 }
    }
  ]
}
"""


def test_a_joints_parameters_are_found_by_their_def(tmp_path):
    """Webots' ziegler_nichols how-to finds its hinge's HingeJointParameters by DEF (getFromDef) and
    sets its ``position`` to start each trial from 0: the node found is the joint's jointParameters,
    its position the joint's, and setting it moves the joint and its end point at once. A USE of the
    DEF is no second DEF (the first joint's is found)."""
    path = tmp_path / "tuner.wbt"
    path.write_text(DEF_PARAMETERS)
    arm = Arm(path, "tuner")
    turn = arm.node("TURN_PARAMETERS")
    joint = arm.call("get_from_id", {"id": turn})["parent"]
    assert arm.call("get_from_id", {"id": turn})["type"] == "HingeJointParameters"
    assert arm.call("get_field", {"node": joint, "field": "jointParameters"})["value"] == turn
    assert arm.call("get_from_id", {"id": turn})["def_name"] == "TURN_PARAMETERS"
    slide = arm.node("SLIDE_PARAMETERS")
    assert arm.call("get_from_id", {"id": slide})["type"] == "JointParameters"
    assert arm.call("get_field", {"node": turn, "field": "position"})["value"] == 0.25
    arm.call("set_field", {"node": turn, "field": "position", "value": HALF_PI})
    assert arm.lv.sim.robot("tuner").motor("turn").position == HALF_PI
    # the file's end point is where the joint at 0.25 puts it: a turn by HALF_PI - 0.25 about z from there
    assert arm.position("ARM") == pytest.approx([0.2 * math.cos(HALF_PI - 0.25), 0.2 * math.sin(HALF_PI - 0.25), 0.0],
                                                abs=1e-12)
    arm.call("set_field", {"node": slide, "field": "position", "value": 0.3})
    assert arm.lv.sim.robot("tuner").motor("slide").position == 0.3
