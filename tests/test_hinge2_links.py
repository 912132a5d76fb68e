"""A Hinge2Joint's end point moves with both of its axes, as Webots moves it without physics
(WbHinge2Joint: the end point turned by R(axis, q1)·R(axis2, q2) about the anchor, axis2 given with
both positions at 0, from where its positions place it). The .wbt loader writes the two axes as
two hinges through the anchor, the second riding on the first.

Closed form: a pan (axis z) and tilt (axis2 y) head with its anchor at (0, 0, 0.1) and a sensor
0.1 m ahead of it, at (0.1, 0, 0.1). At pan pi/2 and tilt pi/4 the sensor is at
a + R_z(pi/2)·R_y(pi/4)·(0.1, 0, 0) = (0, 0.1·cos(pi/4), 0.1 - 0.1·sin(pi/4)), and looks along
R_z(pi/2)·R_y(pi/4)·x = (0, cos(pi/4), -sin(pi/4)). (Turning in the other order, tilt about a fixed
y after the pan, would put it at (0, 0.1, 0.1).)"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_wbt_drives import write

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

Q = math.pi / 4
C = math.cos(Q)


def _head(pan0: float, at: str) -> str:
    """A robot whose Hinge2Joint (pan about z, then tilt about y) holds a box with a distance sensor;
    ``pan0``: the first axis's initial position, ``at``: the end point's translation there."""
    return ('Robot { name "head" children [\n'
            f' Hinge2Joint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor 0 0 0.1 position {pan0} }}\n'
            '  jointParameters2 JointParameters { axis 0 1 0 }\n'
            '  device [ RotationalMotor { name "pan" maxVelocity 100 maxTorque 100000 } ]\n'
            '  device2 [ RotationalMotor { name "tilt" maxVelocity 100 maxTorque 100000 } ]\n'
            f'  endPoint Solid {{ translation {at} rotation 0 0 1 {pan0} children [\n'
            '    DistanceSensor { name "ds" }\n'
            '    Shape { geometry Box { size 0.02 0.02 0.02 } } ] } } ] }\n')


@pytest.mark.parametrize(("pan0", "at"), [(0.0, "0.1 0 0.1"), (math.pi / 2, "0 0.1 0.1")],
                         ids=["from zero", "from a quarter pan"])
def test_a_hinge2_head_turns_its_sensor_about_both_axes(tmp_path: Path, pan0: float, at: str) -> None:
    """Loaded at pan 0 or at pan pi/2 (the end point written where that position places it), the
    head commanded to pan pi/2, tilt pi/4 puts the sensor at the same closed-form pose."""
    w = load_world(write(tmp_path, _head(pan0, at)))
    robot = w.world.robots[0]
    assert robot.differential_drive is None and robot.ackermann_drive is None
    devices = {d.name: d for d in robot.devices}
    pan, tilt = devices["pan"], devices["tilt"]
    assert pan.axis == pytest.approx((0, 0, 1)) and tilt.anchor == pytest.approx((0, 0, 0.1))
    # the second axis as it is with the first at its initial position
    assert tilt.axis == pytest.approx((-math.sin(pan0), math.cos(pan0), 0), abs=1e-15)
    assert (tilt.on_joint, devices["ds"].on_joint) == ("pan", "tilt")
    assert [s.on_joint for s in robot.shapes] == ["tilt"]
    sim = Simulation(w)
    sim.robot("head").motor("pan").set_position(math.pi / 2)
    sim.robot("head").motor("tilt").set_position(Q)
    sim.step()
    pose = sim.device("head/ds").world_pose(sim.robot("head").pose)
    assert pose.translation == pytest.approx([0.0, 0.1 * C, 0.1 - 0.1 * C], abs=1e-12)
    assert pose.rotation[:, 0] == pytest.approx([0.0, C, -C], abs=1e-12)


def test_a_hinge2_with_a_motor_on_its_second_axis_only_tilts(tmp_path: Path) -> None:
    """No motor on the first axis: the end point rides on the second, which turns about y through
    the anchor: at tilt pi/4 the sensor is at a + R_y(pi/4)·(0.1, 0, 0) = (0.1·cos, 0, 0.1 - 0.1·sin)."""
    text = _head(0.0, "0.1 0 0.1").replace(
        '  device [ RotationalMotor { name "pan" maxVelocity 100 maxTorque 100000 } ]\n', '')
    w = load_world(write(tmp_path, text))
    devices = {d.name: d for d in w.world.robots[0].devices}
    assert "pan" not in devices and devices["tilt"].on_joint is None and devices["ds"].on_joint == "tilt"
    sim = Simulation(w)
    sim.robot("head").motor("tilt").set_position(Q)
    sim.step()
    pose = sim.device("head/ds").world_pose(sim.robot("head").pose)
    assert pose.translation == pytest.approx([0.1 * C, 0.0, 0.1 - 0.1 * C], abs=1e-12)


def _rot(axis: tuple[float, float, float], angle: float) -> np.ndarray:
    x, y, z = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def _ball(params: str) -> str:
    return ('Robot { name "wrist" children [\n'
            f' BallJoint {{ jointParameters BallJointParameters {{ anchor 0 0 0.1 }} {params}\n'
            + "".join(f'  {field} [ RotationalMotor {{ name "{name}" maxVelocity 100 maxTorque 100000 }} ]\n'
                      for field, name in (("device", "one"), ("device2", "two"), ("device3", "three")))
            + '  endPoint Solid { translation 0.1 0 0.1 children [\n'
            '    DistanceSensor { name "ds" }\n'
            '    Shape { geometry Box { size 0.02 0.02 0.02 } } ] } } ] }\n')


@pytest.mark.parametrize(("params", "axes"), [
    ("jointParameters2 JointParameters { axis 0 0 1 } jointParameters3 JointParameters { axis 1 0 0 }",
     ((0, 0, 1), (0, -1, 0), (1, 0, 0))),                  # a2 = a3 × a1 = x × z = -y
    ("", ((1, 0, 0), (0, 1, 0), (0, 0, 1)))],              # Webots' defaults: x, z × x = y, z
    ids=["given axes", "default axes"])
def test_a_ball_joint_turns_its_sensor_about_its_three_axes(tmp_path: Path, params: str, axes: tuple) -> None:
    """A BallJoint (anchor (0, 0, 0.1)) with a motor on each axis: at (pi/2, pi/4, pi/3) the sensor,
    0.1 m ahead of the anchor, is at a + R(a1, pi/2)·R(a2, pi/4)·R(a3, pi/3)·(0.1, 0, 0) and turned by
    that rotation (WbBallJoint's axes: a1 from jointParameters2, a3 from jointParameters3,
    a2 = a3 × a1). The second axis's motor is limited to [-pi/2, pi/2], as Webots limits it."""
    w = load_world(write(tmp_path, _ball(params)))
    devices = {d.name: d for d in w.world.robots[0].devices}
    for name, axis in zip(("one", "two", "three"), axes):
        assert devices[name].axis == pytest.approx(axis, abs=1e-15), name
        assert devices[name].anchor == pytest.approx((0, 0, 0.1))
    assert [devices[n].on_joint for n in ("one", "two", "three", "ds")] == [None, "one", "two", "three"]
    assert (devices["two"].min_position, devices["two"].max_position) == (-math.pi / 2, math.pi / 2)
    sim = Simulation(w)
    angles = (math.pi / 2, math.pi / 4, math.pi / 3)
    for name, q in zip(("one", "two", "three"), angles):
        sim.robot("wrist").motor(name).set_position(q)
    sim.step()
    turn = _rot(axes[0], angles[0]) @ _rot(axes[1], angles[1]) @ _rot(axes[2], angles[2])
    pose = sim.device("wrist/ds").world_pose(sim.robot("wrist").pose)
    assert pose.translation == pytest.approx(np.array([0, 0, 0.1]) + turn @ [0.1, 0, 0], abs=1e-12)
    assert pose.rotation == pytest.approx(turn, abs=1e-12)


def test_a_supervisor_reads_a_hinge2_end_points_pose_where_both_axes_put_it(tmp_path: Path) -> None:
    """The head's end point Solid (DEF TIP) read through the Supervisor (the sans-IO core): at pan
    pi/2, tilt pi/4 its origin is at a + R_z(pi/2)·R_y(pi/4)·(0.1, 0, 0) and its orientation is
    R_z(pi/2)·R_y(pi/4); before any motion, where the file puts it. (The nested nodes took only a
    HingeJoint's and a SliderJoint's end points for moving.)"""
    from test_supervisor import A, Live

    text = _head(0.0, "0.1 0 0.1").replace("endPoint Solid {", "endPoint DEF TIP Solid {").replace(
        'Robot { name "head"', 'Robot { name "head" supervisor TRUE')
    lv = Live(Simulation(load_world(write(tmp_path, text))))
    lv.ok(A, "attach", {"robot": "head"})

    def pose() -> tuple[list[float], np.ndarray]:
        node = lv.ok(A, "/head/robot/get_from_def", {"name": "TIP"})["node"]
        got = lv.ok(A, "/head/robot/get_node_pose", {"node": node})
        return got["position"], np.array(got["orientation"]).reshape(3, 3)

    at, turned = pose()
    assert at == pytest.approx([0.1, 0.0, 0.1], abs=1e-12) and turned == pytest.approx(np.eye(3), abs=1e-12)
    head = lv.sim.robot("head")
    head.motor("pan").set_position(math.pi / 2)
    head.motor("tilt").set_position(Q)
    for _ in range(1000):                          # until both are there (generous limit)
        if head.motor("pan").position == math.pi / 2 and head.motor("tilt").position == Q:
            break
        lv.sim.step()
    at, turned = pose()
    assert at == pytest.approx([0.0, 0.1 * C, 0.1 - 0.1 * C], abs=1e-12)
    assert turned == pytest.approx(_rot((0, 0, 1), math.pi / 2) @ _rot((0, 1, 0), Q), abs=1e-12)
