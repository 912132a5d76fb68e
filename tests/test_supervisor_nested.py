"""The Supervisor's nodes inside robots and solids (tests/worlds/nested_nodes.wbt), through the
sans-IO core on a real simulation: found by DEF anywhere and by dotted path (each further name a
direct child's DEF, Webots' getNodeFromDEF), by device; their parents, type names, read-only fields
(translation and rotation in the parent's frame, name, children); their world pose following the
robot as it drives (closed forms: the robot stands at (1, 2, 0) turned a quarter turn, its wheels
0.05 m, its axle 0.2 m). The same through Python and C controllers (``sensorium serve``)."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.nested import FIRST_ID
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "nested_nodes.wbt"
ROVER, SHELF = 1, 2                                  # robots first, then the top-level solids
MAST, CAM, ARM, TIP, DS, LEFT_JOINT, LEFT_MOTOR, LEFT_ENCODER, LEFT_WHEEL = range(FIRST_ID, FIRST_ID + 9)
RIGHT_JOINT, RIGHT_MOTOR, RIGHT_WHEEL, LID = range(FIRST_ID + 9, FIRST_ID + 13)
LEFT_PARAMETERS, RIGHT_PARAMETERS = FIRST_ID + 13, FIRST_ID + 14   # after every other nested node
W, R, DT = 2.0, 0.05, 0.032                          # wheel speed (rad/s), radius, basic step (s)
AXLE = 2 * math.hypot(0.1, 0.05)   # m; no Physics: Webots' kinematic rule, the wheels' 3-D distances from the origin
HALF_PI = math.pi / 2


def _live() -> Live:
    lv = Live(Simulation(load_world(WORLD)))
    lv.ok(A, "attach", {"robot": "rover"})
    return lv


def rover(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/rover/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return rover(lv, "get_from_def", {"name": name})["node"]


def position(lv: Live, n: int) -> list[float]:
    return rover(lv, "get_node_pose", {"node": n})["position"]


def orientation(lv: Live, n: int) -> np.ndarray:
    return np.array(rover(lv, "get_node_pose", {"node": n})["orientation"]).reshape(3, 3)


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def drive(lv: Live, left: float, right: float, steps: int) -> None:
    bot = lv.sim.robot("rover")
    for name, speed in (("left wheel", left), ("right wheel", right)):
        bot.motor(name).set_position(math.inf)
        bot.motor(name).set_velocity(speed)
    for _ in range(steps):
        lv.step(A, "rover")


def test_nested_defs_are_found_anywhere_and_by_dotted_paths():
    lv = _live()
    assert [node(lv, d) for d in ("MAST", "CAM", "ARM", "TIP", "LEFT_JOINT", "LEFT_WHEEL", "LID")] == \
        [MAST, CAM, ARM, TIP, LEFT_JOINT, LEFT_WHEEL, LID]
    assert rover(lv, "get_from_def", {"name": "CAM"}) == {"node": CAM, "type": "Camera", "name": "cam",
                                                          "def_name": "CAM", "parent": MAST, "proto": ""}
    # a dotted path: each further name a direct child's DEF (in children, a joint's endPoint, ...)
    assert node(lv, "ROVER.MAST.CAM") == CAM
    assert node(lv, "ROVER.ARM.TIP") == node(lv, "ARM.TIP") == TIP
    assert node(lv, "ROVER.LEFT_JOINT.LEFT_WHEEL") == LEFT_WHEEL
    assert node(lv, "SHELF.BOARD.LID") == LID and node(lv, "SHELF.LID") == 0     # through the Pose, as Webots
    assert node(lv, "ROVER.") == ROVER          # nothing after the dot (Webots)
    for missing in ("ROVER.CAM", "ROVER.TIP", "ARM.CAM", "ROVER..ds", ".CAM", "NOPE.TIP", "ROVER.ARM.TIP.X"):
        assert rover(lv, "get_from_def", {"name": missing})["type"] == "", missing
    wheel = rover(lv, "get_from_def", {"name": "WHEEL"})      # a DEF'd Shape: a node after all the others
    assert (wheel["type"], wheel["parent"]) == ("Shape", LEFT_WHEEL) and wheel["node"] > LEFT_PARAMETERS
    assert node(lv, "ROVER.LEFT_JOINT.LEFT_WHEEL.WHEEL") == wheel["node"]
    assert node(lv, "rover") == ROVER           # a top-level node's name still finds it


def test_parents_types_and_the_children_walk():
    lv = _live()

    def ref(n: int) -> dict:
        return rover(lv, "get_from_id", {"id": n})

    def kids(n: int) -> list[int]:
        return rover(lv, "get_field", {"node": n, "field": "children"})["value"]

    board = rover(lv, "get_from_def", {"name": "BOARD"})["node"]     # the Pose inside SHELF: after every other
    assert [ref(n)["parent"] for n in (MAST, CAM, ARM, TIP, DS, LEFT_JOINT, LEFT_MOTOR, LEFT_WHEEL, LID, board)] == \
        [ROVER, MAST, ROVER, ARM, ROVER, ROVER, LEFT_JOINT, LEFT_JOINT, board, SHELF]
    assert [ref(n)["type"] for n in (MAST, DS, LEFT_JOINT, LEFT_MOTOR, LEFT_ENCODER, RIGHT_WHEEL)] == \
        ["Pose", "DistanceSensor", "HingeJoint", "RotationalMotor", "PositionSensor", "Solid"]
    assert ref(DS)["def_name"] == "" and ref(DS)["name"] == "ds"
    # the children (a joint's end point and devices are in its other fields)
    assert kids(ROVER) == [MAST, ARM, DS, LEFT_JOINT, RIGHT_JOINT]
    assert kids(MAST) == [CAM] and kids(ARM) == [TIP] and kids(TIP) == [] and kids(SHELF) == [board]
    assert kids(board) == [LID] and ref(board)["type"] == "Pose"
    assert rover(lv, "get_field", {"node": LEFT_JOINT, "field": "children"}) == {"type": "", "value": [], "absent": True}
    assert ref(RIGHT_MOTOR)["name"] == "right wheel"


def test_get_from_device_gives_the_devices_node():
    lv = _live()
    assert rover(lv, "get_from_device", {"device": "cam"})["node"] == CAM
    assert rover(lv, "get_from_device", {"device": "ds"})["node"] == DS
    assert rover(lv, "get_from_device", {"device": "left wheel"}) == {
        "node": LEFT_MOTOR, "type": "RotationalMotor", "name": "left wheel", "def_name": "", "parent": LEFT_JOINT,
        "proto": ""}
    assert rover(lv, "get_from_device", {"device": "left encoder"})["node"] == LEFT_ENCODER
    assert rover(lv, "get_from_device", {"device": "nothing"})["type"] == ""


def test_fields_are_read_in_the_parents_frame_and_refused_when_set():
    lv = _live()

    def get(n: int, name: str):
        return rover(lv, "get_field", {"node": n, "field": name})

    assert get(TIP, "translation") == {"type": "SFVec3f", "value": pytest.approx([0.0, 0.0, 0.3], abs=1e-12)}
    assert get(CAM, "translation")["value"] == pytest.approx([0.05, 0.0, 0.1], abs=1e-12)
    assert get(CAM, "rotation")["value"] == pytest.approx([0.0, 0.0, 1.0, HALF_PI], abs=1e-12)
    assert get(LEFT_WHEEL, "rotation")["value"] == pytest.approx([1.0, 0.0, 0.0, HALF_PI], abs=1e-12)
    assert get(LID, "translation")["value"] == pytest.approx([0.1, 0.0, 0.0], abs=1e-12)    # in the Pose's frame
    assert get(TIP, "name") == {"type": "SFString", "value": "tip"}
    assert get(CAM, "name") == {"type": "SFString", "value": "cam"}
    assert get(MAST, "name") == {"type": "", "value": [], "absent": True}     # a Pose has no name in Webots either
    assert get(LEFT_MOTOR, "translation") == {"type": "", "value": [], "absent": True}   # no Pose (nor in Webots)
    msg = lv.err(A, "/rover/robot/set_field", {"node": TIP, "field": "translation", "value": [0, 0, 1]},
                 ErrorCode.INVALID_ARGUMENT)
    assert msg == ("set_field: field 'translation' (SFVec3f) of Solid 'tip' is read-only here: a Supervisor moves "
                   "and changes top-level robots, solids and lights only, not the nodes inside them")
    msg = lv.err(A, "/rover/robot/remove_node", {"node": CAM}, ErrorCode.INVALID_ARGUMENT)
    assert msg == (f"remove_node: Camera 'cam' (node {CAM}) cannot be removed here: only top-level solids and "
                   "lights and the Shapes inside robots and solids can, not the other nodes inside a robot or solid")
    # a wheel's joint parameters (SFNode) hold its position: the wheel's angle
    assert get(LEFT_JOINT, "jointParameters") == {"type": "SFNode", "value": LEFT_PARAMETERS}
    assert get(RIGHT_JOINT, "jointParameters") == {"type": "SFNode", "value": RIGHT_PARAMETERS}
    assert rover(lv, "get_from_id", {"id": LEFT_PARAMETERS})["parent"] == LEFT_JOINT
    assert get(LEFT_PARAMETERS, "position") == {"type": "SFFloat", "value": 0.0}
    drive(lv, W, W, 10)
    assert get(LEFT_PARAMETERS, "position")["value"] == pytest.approx(W * 10 * DT, abs=1e-12)
    assert rover(lv, "get_from_id", {"id": FIRST_ID + 15})["type"] == "Shape"    # the shapes come last
    assert rover(lv, "get_from_id", {"id": FIRST_ID + 10**6})["type"] == ""      # past the last nested node
    # a node id that is none says which ids there are, the nested ones too
    end = FIRST_ID + 15
    while rover(lv, "get_from_id", {"id": end})["type"]:       # past the shapes and the nodes inside them
        end += 1
    msg = lv.err(A, "/rover/robot/get_node_pose", {"node": end}, ErrorCode.INVALID_ARGUMENT)
    assert msg.endswith(f"no node with id {end} (ids 0..4: 0 the root, nested {FIRST_ID}..{end - 1})"), msg


def test_world_poses_follow_the_robot_as_it_drives():
    lv = _live()
    yaw = HALF_PI
    assert position(lv, CAM) == pytest.approx([1.0, 2.15, 0.3], abs=1e-12)
    assert orientation(lv, CAM) == pytest.approx(rz(yaw + HALF_PI), abs=1e-12)
    assert position(lv, TIP) == pytest.approx([1.0, 1.9, 0.4], abs=1e-12)
    assert position(lv, DS) == pytest.approx([1.0, 2.15, 0.05], abs=1e-12)
    assert position(lv, LEFT_WHEEL) == pytest.approx([0.9, 2.0, 0.05], abs=1e-12)
    assert position(lv, LID) == pytest.approx([-2.1, 0.0, 0.75], abs=1e-12)     # the shelf is turned half a turn
    assert all(math.isnan(v) for v in position(lv, LEFT_JOINT) + position(lv, LEFT_MOTOR))
    # straight ahead (the robot's +x is the world's +y): 10 steps at W rad/s move it W·R·t
    drive(lv, W, W, 10)
    d = W * R * 10 * DT
    assert position(lv, ROVER)[:2] == pytest.approx([1.0, 2.0 + d], abs=1e-12)
    assert position(lv, CAM) == pytest.approx([1.0, 2.15 + d, 0.3], abs=1e-12)
    assert position(lv, TIP) == pytest.approx([1.0, 1.9 + d, 0.4], abs=1e-12)
    assert rover(lv, "get_node_velocity", {"node": CAM})["value"] == pytest.approx([0, W * R, 0, 0, 0, 0], abs=1e-12)
    # turning on the spot (left back, right forward) about the axle's middle, the robot's origin
    drive(lv, -W, W, 5)
    yaw += 2 * W * R / AXLE * 5 * DT
    x0, y0 = 1.0, 2.0 + d
    assert position(lv, ROVER)[:2] == pytest.approx([x0, y0], abs=1e-12)
    assert position(lv, CAM) == pytest.approx([x0 + 0.15 * math.cos(yaw), y0 + 0.15 * math.sin(yaw), 0.3], abs=1e-12)
    assert orientation(lv, CAM) == pytest.approx(rz(yaw + HALF_PI), abs=1e-12)
    assert position(lv, LEFT_WHEEL) == pytest.approx([x0 - 0.1 * math.sin(yaw), y0 + 0.1 * math.cos(yaw), 0.05],
                                                     abs=1e-12)
    spin = 2 * W * R / AXLE
    assert rover(lv, "get_node_velocity", {"node": CAM})["value"] == pytest.approx(
        [-spin * 0.15 * math.sin(yaw), spin * 0.15 * math.cos(yaw), 0, 0, 0, spin], abs=1e-12)
    # a solid moved by a Supervisor carries its nested solid
    rover(lv, "set_field", {"node": SHELF, "field": "translation", "value": [0.0, 1.0, 0.5]})
    assert position(lv, LID) == pytest.approx([-0.1, 1.0, 0.75], abs=1e-12)


def test_a_removed_solids_nested_nodes_go_with_it():
    lv = _live()
    rover(lv, "remove_node", {"node": SHELF})
    assert node(lv, "LID") == 0
    msg = lv.err(A, "/rover/robot/get_node_pose", {"node": LID}, ErrorCode.INVALID_ARGUMENT)
    assert msg == f"get_node_pose: node {LID} (Solid 'lid') was removed with 'shelf'"


def test_a_use_of_a_nested_def_is_a_copy_without_it(tmp_path):
    """Webots' USE makes a copy that has no DEF: the DEF finds the node the file defines."""
    (tmp_path / "w.wbt").write_text(
        '#VRML_SIM R2023b utf8\nDEF BOT Robot { name "bot" supervisor TRUE children [\n'
        '  Pose { translation 0 0 1 children [ DEF BOX Solid { translation 1 0 0 name "box" } ] }\n'
        '  Pose { translation 0 0 2 children [ USE BOX ] }\n] }\n')
    lv = Live(Simulation(load_world(tmp_path / "w.wbt")))
    lv.ok(A, "attach", {"robot": "bot"})
    box = lv.ok(A, "/bot/robot/get_from_def", {"name": "BOX"})["node"]
    assert lv.ok(A, "/bot/robot/get_node_pose", {"node": box})["position"] == pytest.approx([1.0, 0.0, 1.0])
    second = lv.ok(A, "/bot/robot/get_from_id", {"id": box + 2})
    assert (second["type"], second["name"], second["def_name"]) == ("Solid", "box", "")
    assert lv.ok(A, "/bot/robot/get_node_pose", {"node": box + 2})["position"] == pytest.approx([1.0, 0.0, 2.0])


def test_proto_internal_defs_are_not_found(tmp_path):
    """A PROTO's internal DEF is not found (Webots); a node the world passes into a PROTO field is."""
    from _protos import HEADER

    (tmp_path / "protos").mkdir()
    (tmp_path / "protos" / "Mast.proto").write_text(
        HEADER + "PROTO Mast [ field MFNode extras [] ]\n{\n  Pose { translation 0 0 0.5 children [\n"
        "    DEF INSIDE Solid { name \"inside\" }\n    Group { children IS extras }\n  ] }\n}\n")
    (tmp_path / "w.wbt").write_text(
        '#VRML_SIM R2023b utf8\nEXTERNPROTO "protos/Mast.proto"\n'
        'DEF BOT Robot { name "bot" supervisor TRUE children [\n'
        '  DEF MAST Mast { extras [ DEF GIVEN Solid { translation 1 0 0 name "given" } ] }\n] }\n')
    lv = Live(Simulation(load_world(tmp_path / "w.wbt")))
    lv.ok(A, "attach", {"robot": "bot"})
    bot = lv.ok(A, "/bot/robot/get_from_def", {"name": "MAST"})
    assert (bot["type"], bot["proto"]) == ("Pose", "Mast")
    assert lv.ok(A, "/bot/robot/get_from_def", {"name": "INSIDE"})["type"] == ""
    given = lv.ok(A, "/bot/robot/get_from_def", {"name": "GIVEN"})
    assert given["name"] == "given"
    assert lv.ok(A, "/bot/robot/get_node_pose", {"node": given["node"]})["position"] == \
        pytest.approx([1.0, 0.0, 0.5], abs=1e-12)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_finds_nested_nodes(tmp_path):
    """tests/controllers/nested_nodes.py through ``sensorium serve``, written as for Webots."""
    ctl = run_paused(WORLD, tmp_path, "nested_nodes.py", "rover")
    out = json.loads(ctl.out[-1])
    assert out["found"] == [["Camera", "CAM", "cam"], ["Solid", "TIP", "tip"], ["Solid", "LID", "lid"]]
    assert out["parents"] == ["MAST", "ROVER", "ARM"]
    assert out["device"] == [True, "RotationalMotor", "LEFT_JOINT", True, True, True]
    assert out["children"] == ["Pose", "Solid", "DistanceSensor", "HingeJoint", "HingeJoint"]
    assert out["tip"] == pytest.approx([0.0, 0.0, 0.3], abs=1e-12)
    d = W * R * 10 * DT
    assert out["cam_before"] == pytest.approx([1.0, 2.15, 0.3], abs=1e-9)
    assert out["cam_after"] == pytest.approx([1.0, 2.15 + d, 0.3], abs=1e-9)
    assert out["pose_in_robot"] == pytest.approx([0.15, 0.0, 0.3], abs=1e-9)
    assert out["no_pose"] is True
    # ARM: 2 kg at (-0.1, 0, 0.1) in the robot, TIP 1 kg at (-0.1, 0, 0.5): (-0.1, 0, 0.7/3), turned about z
    assert out["com_before"] == pytest.approx([1.0, 1.9, 0.7 / 3], abs=1e-9)
    assert out["com_after"] == pytest.approx([1.0, 1.9 + d, 0.7 / 3], abs=1e-9)
    assert out["com_robot"] == [0.0, 0.0, 0.0]                  # no Physics (Webots: the zero vector)


PAN_WORLD = """#VRML_SIM R2023b utf8
Robot {
  name "head" controller "<extern>" supervisor TRUE
  children [
    HingeJoint {
      jointParameters HingeJointParameters { axis 0 0 1 anchor 0 0 0.2 }
      device [ RotationalMotor { name "pan" maxVelocity 100 } ]
      endPoint Solid { translation 0 0 0.2 children [ DEF CAM Camera { translation 0.1 0 0 } ] }
    }
  ]
}
"""


def test_a_device_on_a_turned_joint_is_where_the_joint_put_it(tmp_path):
    """A camera on a pan joint (vertical axis through (0, 0, 0.2)) 0.1 m ahead of it: turned a
    quarter turn, its node's world position is 0.1 m to the robot's left and its orientation turned
    with it (closed form), as the camera itself looks."""
    p = tmp_path / "pan.wbt"
    p.write_text(PAN_WORLD)
    lv = Live(Simulation(load_world(p)))
    lv.ok(A, "attach", {"robot": "head"})
    cam = lv.ok(A, "/head/robot/get_from_def", {"name": "CAM"})["node"]

    def pose() -> tuple[list[float], np.ndarray]:
        got = lv.ok(A, "/head/robot/get_node_pose", {"node": cam})
        return got["position"], np.array(got["orientation"]).reshape(3, 3)

    assert pose()[0] == pytest.approx([0.1, 0.0, 0.2], abs=1e-12)
    lv.sim.robot("head").motor("pan").set_position(HALF_PI)
    for _ in range(20):                     # 100 rad/s and Webots' 10 rad/s^2 ramp: there well before
        lv.step(A, "head")
    assert lv.sim.robot("head").motor("pan").position == HALF_PI
    where, turned = pose()
    assert where == pytest.approx([0.0, 0.1, 0.2], abs=1e-12)
    assert turned == pytest.approx(rz(HALF_PI), abs=1e-12)
    assert turned == pytest.approx(lv.sim.device("head/camera").local_pose.rotation, abs=1e-12)
