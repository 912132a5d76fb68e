"""Kinematic contact follows the joints (README "Kinematic contact", "Bumpers"): a robot's footprint
and a bumper's pieces are its bounding shapes where its joints hold them now, not where the world
file put them. Wheels of radius 0.1 m at w rad/s move a robot w * 0.1 m/s; every stopping point is a
distance the geometry gives exactly.

The robot: a 0.4 x 0.2 m box body heading +x, a bumper plate 0.02 m deep and 0.2 m wide whose centre is
0.21 m ahead (its front face 0.22 m ahead of the robot's centre), on a joint. The wall's face is at x = 1."""

from __future__ import annotations

import math

import pytest
from test_contact import drive, world, xy  # the same world, wheels and positions as the other contact tests

FACE = 1.0
WALL = {"name": "wall", "pose": {"translation": [FACE + 0.1, 0.0, 0.25]}, "geometry": {"type": "box", "size": [0.2, 4.0, 0.5]}}


def _motor(kind: str, name: str, axis) -> dict:
    # full speed at once: any target within 3 m (rad) reached in one 32 ms step
    force = {"max_force": 1e5} if kind == "LinearMotor" else {"max_torque": 1e5}
    return {"device": kind, "name": name, "max_velocity": 100.0, "axis": list(axis), **force}


def bumper_robot(kind: str, axis, name: str = "r", x: float = 0.0) -> dict:
    """The robot with its bumper plate on joint ``j`` (a ``kind`` motor along/about ``axis``
    through the robot's origin) and a TouchSensor ``bumper`` of that plate, on the joint too."""
    return {"name": name, "pose": {"translation": [x, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.4, 0.2, 0.2]}},
            "shapes": [{"name": "plate", "of_device": "bumper", "on_joint": "j",
                        "pose": {"translation": [0.21, 0.0, 0.0]},
                        "geometry": {"type": "box", "size": [0.02, 0.2, 0.1]}}],
            "devices": [_motor(kind, "j", axis), {"device": "TouchSensor", "name": "bumper", "on_joint": "j"}],
            "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000.0}}


def _drive_to_rest(sim, name="r", steps=200):
    drive(sim, name, 5.0)                                  # 0.016 m per step
    sim.run(steps)


@pytest.mark.parametrize("push", [0.0, 0.1])
def test_a_bumper_pushed_forward_by_a_slider_stops_the_robot_that_much_earlier(push):
    """The slider holds the plate ``push`` m further ahead: the plate's front face (0.22 + push
    ahead of the centre) stops on the wall, the centre at 1 - 0.22 - push, and the bumper reads 1."""
    sim = world([WALL], [bumper_robot("LinearMotor", (1, 0, 0))])
    sim.device("r/bumper").enable(32)
    sim.robot("r").motor("j").set_position(push)
    sim.step()
    assert sim.robot("r").motor("j").position == push
    _drive_to_rest(sim)
    x, y = xy(sim, "r")
    assert x == pytest.approx(FACE - 0.22 - push, abs=1e-9) and x <= FACE - 0.22 - push and y == 0.0
    assert sim.device("r/bumper").value == 1.0


def test_a_bumper_swung_away_by_a_hinge_stops_touching_and_the_body_drives_on_to_the_wall():
    """Pressed on the wall with the plate (centre at 1 - 0.22), the hinge (about z through the
    robot's origin) swings the plate a quarter turn to the robot's left side: it no longer touches
    (its front is now 0.1 m ahead of the centre, 0.12 m short of the wall), the bumper reads 0, and
    driving on, the body's front face (0.2 m ahead) stops on the wall: the centre at 1 - 0.2."""
    sim = world([WALL], [bumper_robot("RotationalMotor", (0, 0, 1))])
    bumper = sim.device("r/bumper")
    bumper.enable(32)
    _drive_to_rest(sim)
    assert xy(sim, "r")[0] == pytest.approx(FACE - 0.22, abs=1e-9) and bumper.value == 1.0
    drive(sim, "r", 0.0)
    sim.robot("r").motor("j").set_position(math.pi / 2)
    sim.step()
    assert xy(sim, "r")[0] == pytest.approx(FACE - 0.22, abs=1e-9) and bumper.value == 0.0
    _drive_to_rest(sim, steps=20)
    x, y = xy(sim, "r")
    assert x == pytest.approx(FACE - 0.2, abs=1e-9) and y == 0.0 and bumper.value == 0.0
    # swung back, the plate would be 0.02 m into the wall: the robot is placed so from outside
    # (its joint moved it there), goes no deeper and backs out freely, its bumper pressed meanwhile
    sim.robot("r").motor("j").set_position(0.0)
    sim.step()
    assert xy(sim, "r")[0] == pytest.approx(FACE - 0.2, abs=1e-9) and bumper.value == 1.0
    drive(sim, "r", -5.0)
    sim.run(5)
    assert xy(sim, "r")[0] == pytest.approx(FACE - 0.2 - 5 * 0.016, abs=1e-9) and bumper.value == 0.0


def test_a_reset_and_a_supervisor_s_joint_move_reshape_the_footprint():
    """The slider pushed 0.1 m out, then the world reset: the footprint is the loaded one again (its
    front 0.22 m ahead); placed at 0.05 by hand (a Supervisor's setJointPosition, Simulation.joints_moved),
    the footprint's front is 0.27 m ahead."""
    sim = world([WALL], [bumper_robot("LinearMotor", (1, 0, 0))])
    loaded = sim.contact.feet[0].points.copy()
    assert float(loaded[:, 0].max()) == pytest.approx(0.22, abs=1e-15)
    sim.robot("r").motor("j").set_position(0.1)
    sim.step()
    assert float(sim.contact.feet[0].points[:, 0].max()) == pytest.approx(0.32, abs=1e-15)
    sim.reset()
    assert (sim.contact.feet[0].points == loaded).all()
    robot = sim.robot("r")
    robot.motor("j").place(0.05)
    sim.joints_moved(robot)
    assert float(sim.contact.feet[0].points[:, 0].max()) == pytest.approx(0.27, abs=1e-15)


def test_another_robot_s_arm_swung_into_the_path_stops_a_robot_at_its_face():
    """A standing robot (no drive) at (1, 0.5) holds a 0.1 x 0.6 m arm on a hinge about z through its
    origin, lying along +x (clear of the path y = 0); turned a quarter turn clockwise it lies along
    -y, across the path, its near face at x = 1 - 0.05. A disc robot (radius 0.1) driving along
    y = 0 stops with its centre 0.1 short of that face."""
    arm = {"name": "gate", "pose": {"translation": [1.0, 0.5, 0.1]},
           "body": {"geometry": {"type": "cylinder", "radius": 0.05, "height": 0.2}},
           "shapes": [{"name": "arm", "on_joint": "hinge", "pose": {"translation": [0.35, 0.0, 0.0]},
                       "geometry": {"type": "box", "size": [0.6, 0.1, 0.2]}}],
           "devices": [_motor("RotationalMotor", "hinge", (0, 0, 1))]}
    mover = {"name": "m", "pose": {"translation": [0.0, 0.0, 0.1]},
             "body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.2}},
             "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000.0}}
    for turned in (False, True):
        sim = world([], [arm, mover])
        if turned:
            sim.robot("gate").motor("hinge").set_position(-math.pi / 2)
        drive(sim, "m", 5.0)
        sim.run(100)                                      # 1.6 m if nothing stops it
        x, y = xy(sim, "m")
        assert abs(y) <= 1e-12
        assert x == (pytest.approx(1.0 - 0.05 - 0.1, abs=1e-9) if turned else pytest.approx(1.6, abs=1e-9))


def test_a_robot_whose_joints_carry_no_bounding_shape_keeps_its_footprint_object():
    """A slider carrying no bounding shape (the plate on the body): the footprint is the one made at
    load, never made again, however the joint moves."""
    robot = bumper_robot("LinearMotor", (1, 0, 0))
    robot["shapes"][0].pop("on_joint")
    robot["devices"][1].pop("on_joint")
    sim = world([WALL], [robot])
    foot = sim.contact.feet[0]
    sim.robot("r").motor("j").set_position(0.1)
    sim.run(3)
    assert sim.contact.feet[0] is foot
