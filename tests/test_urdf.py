"""getUrdf / wb_robot_get_urdf: the robot's URDF as Webots exports it (sensorium/server/world/urdf.py),
on our own arm (tests/worlds/urdf_arm.wbt; its header gives the closed forms): the links and joints
in Webots' order, their axes, limits and origins, the prefix, a robot of one link; forward kinematics
from the URDF equals the Solids' world poses the simulation gives after the joints moved; the Python
and C clients return the server's string."""

from __future__ import annotations

import math
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from test_c_client import SAN_ENV, TESTS_C, sanitized_controller
from test_multiprocess import REPO, run_paused
from test_supervisor_nested_joints import Arm

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world
from sensorium.server.world.urdf import robot_urdf

WORLD = REPO / "tests" / "worlds" / "urdf_arm.wbt"
ROBOT_T = np.array([1.0, 2.0, 0.5])         # the robot's translation; its rotation: rz(0.7)


def rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot(axis, q: float) -> np.ndarray:
    x, y, z = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(q) * k + (1.0 - math.cos(q)) * (k @ k)


def served_urdf(robot: str = "arm", prefix: str = "") -> str:
    arm = Arm(WORLD, robot)
    return arm.call("get_urdf", {"prefix": prefix})["value"]


def floats(text: str) -> list[float]:
    return [float(v) for v in text.split()]


def joints(root: ET.Element) -> dict[str, ET.Element]:
    return {j.get("name"): j for j in root.iter("joint")}


def test_the_arms_urdf_has_webots_links_joints_axes_limits_and_origins():
    root = ET.fromstring(served_urdf())
    assert root.tag == "robot" and root.get("name") == "arm"
    assert [e.get("name") for e in root.iter("link")] == ["base_link", "upper", "fore", "tip"]
    assert [e.get("name") for e in root.iter("joint")] == ["waist", "elbow", "fore_tip_joint"]
    js = joints(root)
    waist, elbow, fixed = js["waist"], js["elbow"], js["fore_tip_joint"]
    assert waist.get("type") == "revolute" and elbow.get("type") == "continuous" and fixed.get("type") == "fixed"
    assert (waist.find("parent").get("link"), waist.find("child").get("link")) == ("base_link", "upper")
    assert (elbow.find("parent").get("link"), elbow.find("child").get("link")) == ("upper", "fore")
    assert (fixed.find("parent").get("link"), fixed.find("child").get("link")) == ("fore", "tip")
    # the waist: z in UPPER's frame (tilted 0.4 about x), from the robot's origin to its anchor
    assert floats(waist.find("axis").get("xyz")) == pytest.approx([0.0, math.sin(0.4), math.cos(0.4)], abs=1e-15)
    assert floats(waist.find("origin").get("xyz")) == pytest.approx([0.0, 0.0, 0.3], abs=1e-15)
    assert floats(waist.find("origin").get("rpy")) == pytest.approx([0.4, 0.0, 0.0], abs=1e-15)
    assert {k: float(v) for k, v in waist.find("limit").attrib.items()} == {
        "effort": 50.0, "lower": -2.0, "upper": 2.0, "velocity": 5.0}
    # the elbow: its anchor in UPPER's link frame is the Pose's offset plus the anchor, the file's numbers
    assert floats(elbow.find("origin").get("xyz")) == pytest.approx([0.2, 0.1, 0.5], abs=1e-12)
    assert floats(elbow.find("origin").get("rpy")) == pytest.approx([0.0, 0.3, 0.0], abs=1e-12)
    assert floats(elbow.find("axis").get("xyz")) == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    assert {k: float(v) for k, v in elbow.find("limit").attrib.items()} == {"effort": 20.0, "velocity": 3.0}
    # the tip from FORE's link frame, which sits on the elbow's anchor, 0.05 m before FORE's origin
    c, s = math.cos(0.3), math.sin(0.3)
    assert floats(fixed.find("origin").get("xyz")) == pytest.approx([0.4 + 0.05 * c, 0.0, 0.05 * s], abs=1e-12)
    assert floats(fixed.find("origin").get("rpy")) == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)


def test_the_prefix_goes_before_every_link_and_joint_name():
    root = ET.fromstring(served_urdf(prefix="arm1/"))
    assert [e.get("name") for e in root.iter("link")] == ["arm1/base_link", "arm1/upper", "arm1/fore", "arm1/tip"]
    assert [e.get("name") for e in root.iter("joint")] == ["arm1/waist", "arm1/elbow", "arm1/fore_arm1/tip_joint"]
    assert {e.get("link") for e in root.iter("parent")} == {"arm1/base_link", "arm1/upper", "arm1/fore"}


def test_a_robot_without_joints_is_one_link():
    root = ET.fromstring(served_urdf("plain"))
    assert [e.get("name") for e in root.iter("link")] == ["base_link"]
    assert list(root.iter("joint")) == []


def urdf_fk(text: str, angles: dict[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each link's pose in the robot frame from the URDF alone, the joints at ``angles``."""
    root = ET.fromstring(text)
    poses = {"base_link": (np.eye(3), np.zeros(3))}
    for j in root.iter("joint"):                        # parents come first in Webots' order
        r_p, t_p = poses[j.find("parent").get("link")]
        o = j.find("origin")
        roll, pitch, yaw = floats(o.get("rpy"))
        r = r_p @ rz(yaw) @ ry(pitch) @ rx(roll)
        t = r_p @ np.array(floats(o.get("xyz"))) + t_p
        if j.get("type") in ("revolute", "continuous"):
            r = r @ rot(floats(j.find("axis").get("xyz")), angles[j.get("name")])
        poses[j.find("child").get("link")] = (r, t)
    return poses


@pytest.mark.parametrize("waist, elbow", [(0.0, 0.0), (1.1, -0.7), (-1.9, 2.5)])
def test_forward_kinematics_from_the_urdf_puts_the_tip_where_the_simulation_does(waist, elbow):
    arm = Arm(WORLD, "arm")
    text = arm.call("get_urdf", {"prefix": ""})["value"]
    arm.move("waist", waist)
    arm.move("elbow", elbow)
    r, t = urdf_fk(text, {"waist": waist, "elbow": elbow})["tip"]
    world_r = rz(0.7)
    assert arm.position("TIP") == pytest.approx(list(world_r @ t + ROBOT_T), abs=1e-9)
    assert arm.orientation("TIP") == pytest.approx(world_r @ r, abs=1e-9)
    # UPPER's link frame is its Solid's (its origin on the waist's anchor)
    r_u, t_u = urdf_fk(text, {"waist": waist, "elbow": elbow})["upper"]
    assert arm.position("UPPER") == pytest.approx(list(world_r @ t_u + ROBOT_T), abs=1e-9)


def test_ikpy_builds_the_chain_webots_samples_build(tmp_path):
    """ikpy (not a dependency: skipped without it) follows base_link's first joints: origin, the two
    hinges, the fixed tip; its forward kinematics matches ours."""
    chain_mod = pytest.importorskip("ikpy.chain")
    path = tmp_path / "arm.urdf"                # as Webots' samples do: written to a file, read by ikpy
    path.write_text(served_urdf(), encoding="utf-8")
    chain = chain_mod.Chain.from_urdf_file(str(path), active_links_mask=[False, True, True, False])
    assert [link.name for link in chain.links][1:] == ["waist", "elbow", "fore_tip_joint"]
    frame = chain.forward_kinematics([0.0, 1.1, -0.7, 0.0])
    _, t = urdf_fk(served_urdf(), {"waist": 1.1, "elbow": -0.7})["tip"]
    assert frame[:3, 3] == pytest.approx(list(t), abs=1e-9)


def test_the_server_module_alone_gives_the_same_string():
    """The service is the module's function on the robot's nodes (nothing else decides)."""
    sim = Simulation(load_world(WORLD))
    robot = sim.robots["arm"]
    assert robot_urdf(robot.model, robot.model.nodes, "p_") == served_urdf(prefix="p_")


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_controller_reads_the_servers_urdf(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "urdf_print.py", "arm")
    assert "\n".join(ctl.out) + "\n" == served_urdf(prefix="p_")


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="needs a POSIX C toolchain")
def test_a_c_controller_reads_the_servers_urdf(tmp_path, tmp_path_factory):
    exe = sanitized_controller(tmp_path_factory, TESTS_C / "urdf_print.c")
    ctl = run_paused(WORLD, tmp_path, exe, "arm", env=SAN_ENV)
    assert ctl.out[-1] == "same 1"
    assert "\n".join(ctl.out[:-1]) + "\n" == served_urdf(prefix="p_")


FREE = REPO / "tests" / "worlds" / "urdf_free_joints.wbt"


def free_urdf() -> ET.Element:
    world = load_world(FREE).world
    rig = next(r for r in world.robots if r.name == "rig")
    return ET.fromstring(robot_urdf(rig, rig.nodes))


def test_joints_no_motor_turns_keep_their_axis_and_anchor():
    """A hinge with a PositionSensor only, a hinge and a slider with no device (urdf_free_joints.wbt's
    header): each joint's own axis and anchor, as Webots exports them (before: x or z and the end point's
    translation)."""
    by_child = {j.find("child").get("link"): j for j in free_urdf().iter("joint")}
    knob, flap, drawer = by_child["knob"], by_child["flap"], by_child["drawer"]
    assert (knob.get("name"), knob.get("type")) == ("knob sensor", "continuous")
    # the Pose turns the axis and anchor into the robot frame; the axis is in the end point's frame
    assert floats(knob.find("axis").get("xyz")) == pytest.approx(list(rx(0.2).T @ [0.0, 1.0, 0.0]), abs=1e-15)
    anchor = rz(0.5) @ [0.3, 0.1, 0.05] + np.array([0.1, 0.0, 0.2])
    assert floats(knob.find("origin").get("xyz")) == pytest.approx(list(anchor), abs=1e-15)
    assert floats(knob.find("origin").get("rpy")) == pytest.approx([0.2, 0.0, 0.5], abs=1e-15)
    assert knob.find("limit") is None and flap.find("limit") is None and drawer.find("limit") is None
    # a passive hinge: its child frame on the anchor, not on the end point 0.05 m past it
    assert (flap.get("name"), flap.get("type")) == ("FLAP", "continuous")
    assert floats(flap.find("axis").get("xyz")) == pytest.approx([0.5 ** 0.5, 0.5 ** 0.5, 0.0], abs=1e-15)
    assert floats(flap.find("origin").get("xyz")) == pytest.approx([-0.2, 0.0, 0.1], abs=1e-15)
    # a passive slider: its axis, its end point's place
    assert (drawer.get("name"), drawer.get("type")) == ("DRAWER", "prismatic")
    assert floats(drawer.find("axis").get("xyz")) == pytest.approx([0.0, 0.6, 0.8], abs=1e-15)
    assert floats(drawer.find("origin").get("xyz")) == pytest.approx([0.0, -0.3, 0.0], abs=1e-15)
