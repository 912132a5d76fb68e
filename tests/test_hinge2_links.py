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
