"""Wheeled robots beyond two wheels (issue 27): a skid-steer robot (several motorised wheels per
side, a Pioneer 3-AT written by us) drives kinematically with the same contact as a two-wheel one;
a car-like robot (steered wheels) maps to the Ackermann drive (tests/test_wbt_car.py) or gets one line saying
why it is not driven. Closed-form checks."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

HEADER = "#VRML_SIM R2023b utf8\n"
R, X, Y = 0.11, 0.133, 0.197          # Pioneer 3-AT-like: wheel radius, half wheelbase, half track


def write(tmp_path: Path, body: str) -> Path:
    p = tmp_path / "w.wbt"
    p.write_text(HEADER + "WorldInfo { basicTimeStep 16 }\n" + body)
    return p


def wheel(name: str, x: float, y: float, axis: str = "0 1 0", joint: str = "HingeJoint") -> str:
    params = "Hinge2JointParameters" if joint == "Hinge2Joint" else "HingeJointParameters"
    return (f'{joint} {{ jointParameters {params} {{ axis {axis} anchor {x} {y} {R} }} '
            f'device [ RotationalMotor {{ name "{name}" maxVelocity 12.3 }} PositionSensor {{ name "{name} sensor" }} ] '
            f'endPoint Solid {{ translation {x} {y} {R} rotation 1 0 0 1.5708 children [ DEF W Shape {{ geometry '
            f'Cylinder {{ radius {R} height 0.095 }} }} ] boundingObject USE W }} }}\n')


def kinematic(y: float) -> dict:
    """The drive fields of a two-wheel robot without Physics, wheels (:func:`wheel`) at (0, ±y, R): Webots'
    kinematic rule (wbt/drive.py ``webots_kinematic_pair``), its axle the sum of the wheels' 3-D distances from
    the robot's origin, 2·|(0, y, R)|, each step along the mid-step heading."""
    return {"axle_length": 2.0 * float(np.linalg.norm([0.0, y, R])), "step_rule": "mid_heading"}


def pioneer(name: str = "p3at", at: str = "0 0 0") -> str:
    return (f'Robot {{ name "{name}" translation {at} children [\n'
            f'  Pose {{ translation 0 0 0.2 children [ Shape {{ geometry Box {{ size 0.5 0.4 0.2 }} }} ] }}\n'
            + wheel("front left wheel", X, Y) + wheel("front right wheel", X, -Y)
            + wheel("back left wheel", -X, Y) + wheel("back right wheel", -X, -Y)
            + '] boundingObject Pose { translation 0 0 0.2 children [ Box { size 0.5 0.4 0.2 } ] } }\n')


def drive(sim: Simulation, robot: str, left: float, right: float) -> None:
    r = sim.robot(robot)
    for side, speed in (("left", left), ("right", right)):
        for end in ("front", "back"):
            m = r.motor(f"{end} {side} wheel")
            m.set_position(math.inf)
            m.set_velocity(speed)


def test_four_wheels_become_a_skid_steer_drive(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, pioneer()))
    (robot,) = w.world.robots
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, axle_length=2 * Y, max_wheel_speed=12.3, left_motor="front left wheel",
        right_motor="front right wheel", skid_steer=wm.SkidSteer(left=["back left wheel"], right=["back right wheel"]))
    names = [(d.name, d.device) for d in robot.devices]       # Webots' tree order: each joint's motor, then sensor
    assert names[:4] == [("front left wheel", "RotationalMotor"), ("front left wheel sensor", "PositionSensor"),
                         ("front right wheel", "RotationalMotor"), ("front right wheel sensor", "PositionSensor")]
    assert [d.motor for d in robot.devices if d.device == "PositionSensor"] == [
        "front left wheel", "front right wheel", "back left wheel", "back right wheel"]
    assert w.warnings == []


def test_skid_steer_straight_line_and_turn_radius_closed_form(tmp_path: Path) -> None:
    sim = Simulation(load_world(write(tmp_path, pioneer())), "fast")
    drive(sim, "p3at", 2.0, 2.0)
    sim.run(125)                                  # 2 s at 2 rad/s on 0.11 m wheels: 0.44 m
    pose = sim.robot("p3at").pose
    assert pose.translation == pytest.approx([0.44, 0.0, 0.0], abs=1e-12)
    # wheels 1 and 3 rad/s: v = r·2, ω = r·2/(2Y), on a circle of radius v/ω = 2Y about (0.44, 2Y)
    drive(sim, "p3at", 1.0, 3.0)
    sim.run(500)                                  # 8 s
    v, w = R * 2.0, R * 2.0 / (2 * Y)
    t = 8.0
    cx, cy = 0.44, v / w
    expect = (cx + (v / w) * math.sin(w * t), cy - (v / w) * math.cos(w * t))
    assert tuple(sim.robot("p3at").pose.translation[:2]) == pytest.approx(expect, abs=1e-9)
    enc = sim.device("p3at/back right wheel sensor")
    enc.enable(16)
    sim.step()
    assert enc.value == pytest.approx(2.0 * 2.0 + 3.0 * (8.0 + 0.016), abs=1e-9)   # its own wheel's angle


def test_right_wheels_turned_by_a_rounded_pi_still_make_the_skid_steer_drive(tmp_path: Path) -> None:
    """Webots' Clearpath Moose: each right wheel's joint, axis 0 -1 0, sits in a Pose turned by 3.14159
    about z (not pi), so it turns about (2.65e-6, 1, 0) in the robot's frame; within AXIS_TOL of +y
    (as a car's axes are taken), the wheels make the drive, where before the robot did not move."""
    def turned(name: str, x: float) -> str:     # our own right wheel, written the Moose's way
        return (f'Pose {{ translation {x} {-Y} 0 rotation 0 0 1 3.14159 children [ '
                + wheel(name, 0, 0, axis="0 -1 0") + '] }\n')
    body = ('Robot { name "p3at" children [\n' + wheel("front left wheel", X, Y) + wheel("back left wheel", -X, Y)
            + turned("front right wheel", X) + turned("back right wheel", -X) + '] }\n')
    w = load_world(write(tmp_path, body))
    (robot,) = w.world.robots
    assert robot.differential_drive is not None and robot.differential_drive.axle_length == pytest.approx(2 * Y)
    assert not [m for m in w.warnings if "not move" in m]
    sim = Simulation(w, "fast")
    drive(sim, "p3at", 2.0, 2.0)
    sim.run(125)                                  # 2 s at 2 rad/s on 0.11 m wheels: 0.44 m straight ahead
    assert sim.robot("p3at").pose.translation == pytest.approx([0.44, 0.0, 0.0], abs=1e-12)


def test_skid_steer_side_speed_is_the_mean_of_its_wheels(tmp_path: Path) -> None:
    """Wheels of one side commanded differently (Webots' physics would skid): the side rolls at their mean."""
    sim = Simulation(load_world(write(tmp_path, pioneer())), "fast")
    r = sim.robot("p3at")
    for name, speed in (("front left wheel", 1.0), ("back left wheel", 3.0),
                        ("front right wheel", 2.0), ("back right wheel", 2.0)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(speed)
    sim.run(125)
    assert r.pose.translation == pytest.approx([0.44, 0.0, 0.0], abs=1e-12)


def test_skid_steer_stops_at_a_wall_like_a_two_wheel_robot(tmp_path: Path) -> None:
    p = write(tmp_path, pioneer() + 'Solid { translation 1 0 0.2 children [ DEF WALL Shape { geometry Box { size 0.1 2 0.4 } } ] '
                                    'boundingObject USE WALL }\n')
    sim = Simulation(load_world(p), "fast")
    drive(sim, "p3at", 5.0, 5.0)
    sim.run(250)
    x = sim.robot("p3at").pose.translation[0]
    # the footprint's front (contact.py: the body's outline): the body box's face or a wheel's
    # outline, which reaches R ahead of its axle (its circumscribed 16-gon's edge faces ahead)
    front = max(0.25, X + R)
    assert x == pytest.approx(0.95 - front, abs=1e-9)
    assert sim.counters["contacts"] > 0


def test_a_car_like_robot_maps_to_the_ackermann_drive_or_gets_one_line(tmp_path: Path) -> None:
    car = ('Robot { name "car" children [\n' + wheel("left rear", 0, Y) + wheel("right rear", 0, -Y)
           + wheel("left steer", 0.3, Y, axis="0 0 1") + wheel("right steer", 0.3, -Y, axis="0 0 1") + '] }\n')
    p = write(tmp_path, car)
    w = load_world(p)
    robot = w.world.robots[0]
    assert robot.differential_drive is None and robot.ackermann_drive == wm.AckermannDrive(
        wheelbase=0.3, track_front=2 * Y, track_rear=2 * Y, front_wheel_radius=R, rear_wheel_radius=R,
        type="propulsion", max_wheel_speed=12.3, max_steering_angle=1.5, max_steering_speed=12.3,
        positive_steers="left", right_steer="right steer", left_steer="left steer", right_rear_wheel="right rear",
        left_rear_wheel="left rear")
    assert not [x for x in w.warnings if "drive" in x]
    hinge2 = ('Robot { name "car" children [\n' + wheel("left rear", 0, Y) + wheel("right rear", 0, -Y)
              + wheel("left front", 0.3, Y, joint="Hinge2Joint") + '] }\n')
    p = write(tmp_path, hinge2)
    w = load_world(p)
    (line,) = [x for x in w.warnings if "Ackermann" in x]
    assert line == (f"{p}:3:1: robot 'car': no Ackermann drive (a car-like robot needs two steered front wheels, it "
                    "has 1 steering motor(s) ('left front')); the robot will not move")


def caster(name: str, x: float, y: float) -> str:
    """A steered caster (a PR2's): a motorised vertical hinge whose end point carries two driven wheels."""
    wheels = "".join(wheel(f"{name} {side} wheel", 0, d) for side, d in (("left", 0.05), ("right", -0.05)))
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor {x} {y} 0 }} '
            f'device [ RotationalMotor {{ name "{name} rotation" }} ] '
            f'endPoint Solid {{ translation {x} {y} 0 name "{name} caster" children [\n{wheels}] }} }}\n')


def test_a_base_on_steered_casters_gets_the_steered_wheel_drive(tmp_path: Path) -> None:
    """Four casters, each steering joint turning its own two wheels (a PR2's base): a steered_drive whose
    wheels stand under their casters' steering axes, each steered by its caster's motor; it drives,
    strafes and turns in place in closed form (it used to get a line saying nothing drives it)."""
    places = {"fl": (0.22, 0.22), "fr": (0.22, -0.22), "bl": (-0.22, 0.22), "br": (-0.22, -0.22)}
    robot = ('Robot { name "base" children [\n' + "".join(caster(k, *xy) for k, xy in places.items())
             + '] controller "<extern>" }\n')
    p = write(tmp_path, robot)
    w = load_world(p)
    r = w.world.robots[0]
    assert r.differential_drive is None and r.ackermann_drive is None and r.mecanum_drive is None
    assert r.steered_drive is not None
    assert [(x.motor, x.steer, x.position, x.radius, x.heading, x.steer_sign) for x in r.steered_drive.wheels] == [
        (f"{k} {side} wheel", f"{k} rotation", xy, R, 0.0, 1) for k, xy in places.items() for side in ("left", "right")]
    assert r.steered_drive.max_wheel_speed == 12.3
    assert not [x for x in w.warnings if "will not move" in x or "drive" in x]
    sim = Simulation(w, "fast")
    base = sim.robot("base")

    def steer_and_roll(angles: dict[str, float], omega: float, steps: int) -> None:
        for k, a in angles.items():
            base.motor(f"{k} rotation").set_position(a)
        for m in [m for m in base.motors if m.endswith(" wheel")]:
            base.motor(m).set_velocity(0.0)
        sim.run(200)                              # the casters turn (the wheels hold: the base stays)
        for k in angles:
            for side in ("left", "right"):
                base.motor(f"{k} {side} wheel").set_position(math.inf)
                base.motor(f"{k} {side} wheel").set_velocity(omega)
        sim.run(steps)

    def pose2d() -> tuple[float, float, float]:
        t, rot = base.pose.translation, base.pose.rotation
        return float(t[0]), float(t[1]), math.atan2(rot[1, 0], rot[0, 0])

    z0 = float(base.pose.translation[2])
    steer_and_roll(dict.fromkeys(places, 0.0), 2.0, 125)          # 2 s forward at r·2
    assert pose2d() == pytest.approx((2 * R * 2.0, 0.0, 0.0), abs=1e-12)
    steer_and_roll(dict.fromkeys(places, math.pi / 2), 1.0, 125)  # 2 s to the left at r·1
    assert pose2d() == pytest.approx((2 * R * 2.0, 2 * R, 0.0), abs=1e-12)
    # tangent to the circle through the casters: a turn in place at r·ω/R, R = 0.22·√2
    steer_and_roll({k: math.atan2(x, -y) for k, (x, y) in places.items()}, 1.5, 50)
    assert pose2d() == pytest.approx((2 * R * 2.0, 2 * R, R * 1.5 * 0.8 / (0.22 * math.sqrt(2))), abs=1e-12)
    assert float(base.pose.translation[2]) == z0
    # three casters, a motorised tilt hinge on the body (a PR2's laser) that rides none: the steered drive
    # with that wheel unsteered (its heading fixed) under its own axle
    robot = ('Robot { name "base" children [\n' + caster("fl", 0.22, 0.22) + caster("fr", 0.22, -0.22)
             + caster("bl", -0.22, 0.22) + wheel("tilt", -0.22, -0.2) + '] }\n')
    p = write(tmp_path, robot)
    loaded = load_world(p)
    drive = loaded.world.robots[0].steered_drive
    assert drive is not None and not [x for x in loaded.warnings if "will not move" in x]
    assert [(x.motor, x.steer, x.position) for x in drive.wheels][-1] == ("tilt", None, (-0.22, -0.2))
    # two steering joints carrying their wheels (a Webots car's front axle) stay the Ackermann drive's case
    robot = ('Robot { name "car" children [\n' + caster("fl", 0.3, 0.2) + caster("fr", 0.3, -0.2)
             + wheel("left rear", 0, Y) + wheel("right rear", 0, -Y) + '] }\n')
    p = write(tmp_path, robot)
    assert load_world(p).world.robots[0].steered_drive is None


def test_skid_steer_in_a_world_file_and_its_checks() -> None:
    data = {"robots": [{"name": "r", "differential_drive": {
        "left_motor": "fl", "right_motor": "fr", "skid_steer": {"left": ["bl"], "right": ["br"]}},
        "devices": [{"device": "PositionSensor", "name": "e", "motor": "bl"}]}]}
    w = parse_world(data)
    assert set(Simulation(w, "fast").robot("r").motors) == {"fl", "fr", "bl", "br"}
    data["robots"][0]["differential_drive"]["skid_steer"]["right"] = ["fl"]
    with pytest.raises(WorldError, match="every wheel motor needs its own name"):
        parse_world(data)


def test_a_devices_own_motorised_joints_are_no_wheels(tmp_path: Path) -> None:
    """A spinning lidar (a turret and its belt wheel turned by motors inside the Lidar's children,
    about the robot's vertical axis) on a two-wheel robot, written as a PROTO of our own: the
    devices' joints move the device, never the robot, so the two wheels still make the drive (they
    were taken for a car's steering joints and the robot lost its drive) and the wheel encoders
    still measure their motors; the turret's motors are listed with one warning."""
    protos = tmp_path / "protos"
    protos.mkdir()
    (protos / "SpinLidar.proto").write_text(
        HEADER + "# template language: javascript\n"
        'PROTO SpinLidar [ field SFString name "spin" ]\n{\n  Lidar {\n    name IS name\n    children [\n'
        '      Pose { rotation 1 0 0 1.5708 children [\n'
        '        HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 }\n'
        "          device [ RotationalMotor { name %<= '\"' + fields.name.value + '_turret\"' >% } ]\n"
        '          endPoint Solid { children [ Shape { geometry Box { size 0.02 0.01 0.02 } } ] } }\n'
        '        HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor -0.04 0 0 }\n'
        "          device [ RotationalMotor { name %<= '\"' + fields.name.value + '_belt\"' >% } ]\n"
        '          endPoint Solid { translation -0.04 0 0 } }\n'
        '      ] }\n    ]\n    horizontalResolution 36\n    fieldOfView 6.28\n    numberOfLayers 1\n  }\n}\n')
    body = ('EXTERNPROTO "protos/SpinLidar.proto"\n'
            'Robot { name "burger" children [\n'
            '  Transform { translation -0.03 0 0.15 children [ SpinLidar { } ] }\n'
            + wheel("left wheel", 0, 0.08) + wheel("right wheel", 0, -0.08) + '] }\n')
    w = load_world(write(tmp_path, body))
    (robot,) = w.world.robots
    assert robot.ackermann_drive is None
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, **kinematic(0.08), max_wheel_speed=12.3, left_motor="left wheel", right_motor="right wheel")
    assert [(d.name, d.device) for d in robot.devices][:3] == [
        ("spin", "Lidar"), ("spin_turret", "RotationalMotor"), ("spin_belt", "RotationalMotor")]
    assert [d.motor for d in robot.devices if d.device == "PositionSensor"] == ["left wheel", "right wheel"]
    assert not [x for x in w.warnings if "drive" in x]
    assert len([x for x in w.warnings if "not part of a wheel (inside a device)" in x]) == 2


def test_a_motorised_arm_on_a_two_wheel_robot_is_no_wheel(tmp_path: Path) -> None:
    """A gripper's lift arm (a motorised hinge along the robot's +y, like the wheels, its end point a
    box with slider fingers: nothing round to roll on) on a two-wheel robot: the robot keeps its
    two-wheel drive (three "wheels", one on the x axis, made no drive at all), the arm's motor moves
    its joint kinematically with one warning at its joint (the slider's names its motor), its sensor
    measures it and the wheel encoders measure their wheels."""
    arm = ('HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor -0.01 0 0.022 }\n'
           '  device [ RotationalMotor { name "lift" } PositionSensor { name "lift sensor" } ]\n'
           '  endPoint Solid { translation -0.01 0 0.022 children [\n'
           '    SliderJoint { jointParameters JointParameters { axis 1 0 0 }\n'
           '      device [ LinearMotor { name "grip" } ] endPoint Solid { translation 0 0 -0.048 } }\n'
           '  ] boundingObject Pose { translation 0 0 -0.021 children [ Box { size 0.068 0.008 0.052 } ] } } }\n')
    body = ('Robot { name "khepera" children [\n' + arm + wheel("left wheel", 0, 0.026)
            + wheel("right wheel", 0, -0.026) + '] }\n')
    p = write(tmp_path, body)
    w = load_world(p)
    (robot,) = w.world.robots
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, **kinematic(0.026), max_wheel_speed=12.3, left_motor="left wheel", right_motor="right wheel")
    assert [(d.name, d.device) for d in robot.devices][:3] == [
        ("lift", "RotationalMotor"), ("lift sensor", "PositionSensor"), ("grip", "LinearMotor")]
    assert [d.motor for d in robot.devices if d.device == "PositionSensor"] == ["lift", "left wheel", "right wheel"]
    assert not [x for x in w.warnings if "drive" in x]
    assert f"{p}:4:1: HingeJoint motor 'lift' is no wheel (its end point has no cylinder or sphere to roll on): " \
           "its joint moves kinematically (Webots' rule without physics; its PositionSensor reads it), and the " \
           "shapes and devices past the joint with it" in w.warnings
    # the finger's slider, never a wheel, is named too (it used to read "SliderJoint motor(s) not part of a wheel")
    assert [x.split(": ", 1)[1] for x in w.warnings if "SliderJoint" in x] == [
        "SliderJoint motor 'grip': its joint moves kinematically (Webots' rule without physics; its PositionSensor "
        "reads it), and the shapes and devices past the joint with it"]
    sim = Simulation(w).robot("khepera")
    assert sorted(sim.drive.motors) == ["left wheel", "right wheel"]    # the lift and the grip are no wheels
    assert sorted(sim.joints) == ["grip", "lift"]


def test_an_arm_of_plain_cylinders_on_a_two_wheel_robot_is_no_wheel(tmp_path: Path) -> None:
    """An arm whose shoulder turns about the robot's +y like the wheels and whose link is a plain
    Cylinder standing up from the joint (along z, its centre 0.1 above the axis): something round, but
    it does not turn about the hinge as a wheel does, so the robot keeps its two-wheel drive (three
    "wheels", one on the x axis, made none) and the shoulder moves its joint with its one warning. A
    link that is coaxial with its hinge (a roller) would roll, but its bottom is 0.28 m above the
    wheels' (more than their diameter): it never touches the ground, so it is no wheel either."""
    def body(link: str) -> str:
        arm = ('HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0.05 0 0.3 }\n'
               '  device [ RotationalMotor { name "shoulder" } PositionSensor { name "shoulder sensor" } ]\n'
               f'  endPoint Solid {{ translation 0.05 0 0.3 children [ {link} ] }} }}\n')
        return ('Robot { name "armbot" children [\n' + wheel("left wheel", 0, 0.15) + wheel("right wheel", 0, -0.15)
                + arm + '] }\n')

    upright = 'Pose { translation 0 0 0.1 children [ Shape { geometry Cylinder { radius 0.02 height 0.2 } } ] }'
    p = write(tmp_path, body(upright))
    w = load_world(p)
    (robot,) = w.world.robots
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, **kinematic(0.15), max_wheel_speed=12.3, left_motor="left wheel", right_motor="right wheel")
    assert not [x for x in w.warnings if "drive" in x]
    assert f"{p}:6:1: HingeJoint motor 'shoulder' is no wheel (nothing round at its end point turns about its " \
           "axis as a wheel does): its joint moves kinematically (Webots' rule without physics; its PositionSensor " \
           "reads it), and the shapes and devices past the joint with it" in w.warnings
    sim = Simulation(w).robot("armbot")
    assert sorted(sim.drive.motors) == ["left wheel", "right wheel"] and sorted(sim.joints) == ["shoulder"]
    # the same link lying along the hinge's axis, centred on it, is a roller high above the ground
    roller = 'Pose { rotation 1 0 0 1.5708 children [ Shape { geometry Cylinder { radius 0.02 height 0.2 } } ] }'
    p = write(tmp_path, body(roller))
    w = load_world(p)
    assert w.world.robots[0].differential_drive == wm.DifferentialDrive(
        wheel_radius=R, **kinematic(0.15), max_wheel_speed=12.3, left_motor="left wheel", right_motor="right wheel")
    assert f"{p}:6:1: HingeJoint motor 'shoulder' is no wheel (its round part's bottom is 0.28 m above the robot's " \
           "lowest wheels: it never touches the ground): its joint moves kinematically (Webots' rule without " \
           "physics; its PositionSensor reads it), and the shapes and devices past the joint with it" in w.warnings
    # low enough to reach the ground (its bottom within the wheels' diameter of theirs), it still rolls: no drive
    low = body(roller).replace("anchor 0.05 0 0.3", "anchor 0.05 0 0.1").replace("translation 0.05 0 0.3",
                                                                                 "translation 0.05 0 0.1")
    w = load_world(write(tmp_path, low))
    assert w.world.robots[0].differential_drive is None
    assert [x for x in w.warnings if "no differential drive" in x]


def test_a_robot_whose_motorised_hinges_have_nothing_round_is_no_failed_vehicle(tmp_path: Path) -> None:
    """A fixed pan-tilt head (a pan hinge about z, its end point a box holding a tilt hinge about y
    whose end point holds a camera in a box) and a gripper's two finger hinges about z (Webots'
    coupled_motors sample: motors "motor::left finger" and "motor::right finger", multiplier -1).
    Nothing at any hinge's end is round, so there is no vehicle: each motor is said once as no wheel
    and moves its joint kinematically. They used to be taken for a car's steering (the vertical axes)
    and end in "no Ackermann drive (...); the robot will not move". The fingers are coupled as in
    Webots: a command to one reaches both, each scaled by its multiplier."""
    box = 'children [ Shape { geometry Box { size 0.05 0.05 0.05 } } ]'
    head = ('Robot { name "head" children [\n'
            ' HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 } device [ RotationalMotor { name "pan" '
            f'maxVelocity 100 maxTorque 100000 }} ] endPoint Solid {{ translation 0 0 0.1 {box[:-2]}\n'
            '  HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0 0.1 } device [ RotationalMotor '
            '{ name "tilt" } ] endPoint Solid { translation 0 0 0.1 children [ Camera { translation 0.1 0 0 } ] } } ] } }\n'
            '] }\n'
            'Robot { name "gripper" translation 1 0 0 children [\n'
            + "".join(f' HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor 0 {y} 0 }} device [ '
                      f'RotationalMotor {{ name "motor::{side} finger" {m} }} ] endPoint Solid {{ translation 0 {y} 0 '
                      f'{box} }} }}\n' for side, y, m in (("left", -0.008, ""), ("right", 0.008, "multiplier -1")))
            + '] }\n')
    p = write(tmp_path, head)
    w = load_world(p)
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    for robot in w.world.robots:
        assert robot.differential_drive is None and robot.ackermann_drive is None
    said = sorted(x.split(": ", 1)[1].split(" (")[0] for x in w.warnings if "is no wheel" in x)
    assert said == ["HingeJoint motor 'motor::left finger' is no wheel", "HingeJoint motor 'motor::right finger' is no "
                    "wheel", "HingeJoint motor 'pan' is no wheel", "HingeJoint motor 'tilt' is no wheel"]
    assert not [x for x in w.warnings if "coupled" in x], w.warnings
    sim = Simulation(w)
    left, right = (sim.robot("gripper").motor(f"motor::{side} finger") for side in ("left", "right"))
    assert (left.multiplier, right.multiplier) == (1.0, -1.0)
    left.set_position(0.01)                  # the whole group takes it, each scaled by its multiplier
    assert (left.target_position, right.target_position) == (0.01, -0.01)
    sim.robot("head").motor("pan").set_position(math.pi / 2)
    sim.step()
    cam = sim.device("head/camera").world_pose(sim.robot("head").pose)
    assert cam.translation == pytest.approx([0.0, 0.1, 0.2], abs=1e-12)   # (0.1, 0, 0.2) turned a quarter about z


def test_a_lone_motorised_turntable_is_no_failed_car(tmp_path: Path) -> None:
    """Webots' motor sample: a robot whose one motorised hinge (axis z, position 1.5708) turns a disc
    (a cylinder: round) with a pointer on it. One hinge makes no drive, so it is said once as no
    wheel and turns kinematically; it used to be taken for a car's lone steering joint ("no
    Ackermann drive ...; the robot will not move"). A distance sensor on the disc at (0.05, 0, 0.063)
    rides it: at 1.5708 + pi/2 it is a quarter turn on, at (0, 0.05, 0.063)."""
    p = write(tmp_path, 'Robot { name "turntable" children [\n'
              ' HingeJoint { jointParameters HingeJointParameters { position 1.5708 axis 0 0 1 }\n'
              '  device [ RotationalMotor { name "motor" maxVelocity 100 maxTorque 100000 } ]\n'
              '  endPoint Solid { children [ Pose { translation 0 0 0.063 children [ Shape { geometry Cylinder { '
              'radius 0.04 height 0.005 } } ] }\n'
              '   DistanceSensor { translation 0.05 0 0.063 } ] } }\n] }\n')
    w = load_world(p)
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    assert [x for x in w.warnings if "is no wheel" in x] == [
        f"{p}:4:2: HingeJoint motor 'motor' is no wheel (the robot's only motorised hinge): its joint moves "
        "kinematically (Webots' rule without physics; its PositionSensor reads it), and the shapes and devices past "
        "the joint with it"]
    sim = Simulation(w)
    sim.robot("turntable").motor("motor").set_position(1.5708 + math.pi / 2)
    sim.step()
    ds = sim.device("turntable/distance sensor").world_pose(sim.robot("turntable").pose)
    assert ds.translation == pytest.approx([0.0, 0.05, 0.063], abs=1e-12)


def _two_wheels_and_a_joint(tmp_path: Path, name: str, joint: str, motor: str,
                            why: str = "is no wheel and steers none (its end point holds no wheel)") -> Simulation:
    """A robot of two wheels and ``joint`` (a motorised hinge, ``motor``, that must be no wheel and steer
    nothing): loaded with its differential drive, no drive warning, the joint's one line (``why`` after
    the motor's name), and the simulation's drive and joints so."""
    p = write(tmp_path, f'Robot {{ name "{name}" children [\n' + joint + wheel("left wheel", 0, Y)
              + wheel("right wheel", 0, -Y) + '] }\n')
    w = load_world(p)
    (robot,) = w.world.robots
    assert robot.ackermann_drive is None and robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, **kinematic(Y), max_wheel_speed=12.3, left_motor="left wheel", right_motor="right wheel")
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    assert [x.split(": ", 1)[1] for x in w.warnings if motor in x] == [
        f"HingeJoint motor '{motor}' {why}: its joint moves kinematically (Webots' rule without physics; its "
        "PositionSensor reads it), and the shapes and devices past the joint with it"]
    sim = Simulation(w)
    drive = sim.robot(name)
    assert sorted(drive.drive.motors) == ["left wheel", "right wheel"] and sorted(drive.joints) == [motor]
    return sim


def test_a_pan_head_on_a_two_wheel_robot_leaves_it_its_drive(tmp_path: Path) -> None:
    """A two-wheel robot with a pan head (a motorised hinge about z whose end point, a box, holds a
    camera), as a TIAGo's head or an arm's base joint on a mobile robot: the vertical hinge was
    taken for a car's steering and the robot lost its drive ("no Ackermann drive ...; the robot will
    not move"). Its end point neither is nor carries a wheel, so it steers nothing: said once as no
    wheel, it turns the camera, and the two wheels make the differential drive. A car's knuckle
    (a vertical hinge whose end point holds its wheel's hinge) still steers (the four_wheels test)."""
    head = ('HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 anchor 0 0 0.2 }\n'
            '  device [ RotationalMotor { name "head pan" maxVelocity 100 maxTorque 100000 } ]\n'
            '  endPoint Solid { translation 0 0 0.2 children [ Shape { geometry Box { size 0.05 0.05 0.05 } }\n'
            '    Camera { translation 0.1 0 0 } ] } }\n')
    sim = _two_wheels_and_a_joint(tmp_path, "rover", head, "head pan")
    rover = sim.robot("rover")
    rover.motor("head pan").set_position(math.pi / 2)
    sim.step()
    assert sim.device("rover/camera").world_pose(rover.pose).translation == pytest.approx([0.0, 0.1, 0.2], abs=1e-12)


def test_coupled_drive_wheels_are_said_and_turn_on_their_own(tmp_path: Path) -> None:
    """Two wheels named "wheel::left" and "wheel::right" (multiplier -1 on the right): Webots would
    pass a command to both; the drive turns each wheel on its own commands, so the import says so
    for each, and the drive stays the one the geometry makes (bit for bit the uncoupled wheels')."""
    p = write(tmp_path, 'Robot { name "duo" children [\n' + wheel("wheel::left", 0, 0.08)
              + wheel("wheel::right", 0, -0.08).replace('maxVelocity 12.3', 'maxVelocity 12.3 multiplier -1')
              + '] }\n')
    w = load_world(p)
    (robot,) = w.world.robots
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, **kinematic(0.08), max_wheel_speed=12.3, left_motor="wheel::left", right_motor="wheel::right")
    said = [x.split(": ", 1)[1] for x in w.warnings if "coupled" in x]
    assert said == [f"RotationalMotor 'wheel::{side}': a coupled motor (Webots passes a command to every motor whose "
                    f"name shares the part before '::', scaled by its multiplier, here {m}) that is a wheel of the "
                    "robot's drive: not coupled here, it turns on its own commands and getMultiplier answers 1"
                    for side, m in (("left", 1), ("right", -1))]
    assert all(getattr(d, "multiplier", 1.0) == 1.0 for d in robot.devices)


def test_a_joint_motors_multiplier_is_read_and_zero_is_reset_to_one(tmp_path: Path) -> None:
    """A slider's LinearMotor with multiplier 0.5 keeps it; another with multiplier 0 gets 1, with
    a line at its field (Webots: "The value of 'multiplier' cannot be 0")."""
    body = 'Robot { name "lifter" children [\n' + "".join(
        f' SliderJoint {{ device [ LinearMotor {{ name "{name}" multiplier {m} }} ] endPoint Solid {{ }} }}\n'
        for name, m in (("lift", "0.5"), ("tilt", "0"))) + '] }\n'
    w = load_world(write(tmp_path, body))
    (robot,) = w.world.robots
    assert [(d.name, d.multiplier) for d in robot.devices] == [("lift", 0.5), ("tilt", 1.0)]
    assert [x.split(": ", 1)[1] for x in w.warnings if "cannot be 0" in x] == [
        "LinearMotor.multiplier: 0 cannot be 0; using 1 (as Webots does)"]


def test_vertical_finger_hinges_holding_their_axles_are_no_failed_car(tmp_path: Path) -> None:
    """Webots' coupled_motors gripper: two finger hinges about z whose end points hold their axles,
    cylinders coaxial with the hinge (round, but rolling on nothing), on a slider's carriage, and no
    motor driving a wheel. That is no vehicle: each finger motor is said once as no wheel and moves
    its joint (coupled, multiplier -1), the axle and what it holds with it. It used to be taken for
    a car's steering and end in "no Ackermann drive (the driven wheels (none) ...); the robot will
    not move"."""
    fingers = "".join(
        f' HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor 0 {y} 0 }} device [ '
        f'RotationalMotor {{ name "motor::{side} finger" {m} }} ] endPoint Solid {{ translation 0 {y} 0 children [ '
        f'Shape {{ geometry Cylinder {{ height 0.0125 radius 0.0025 }} }} Solid {{ translation 0.03 0 0 name "{side} tip" }} '
        f'] name "{side} axle" }} }}\n' for side, y, m in (("left", -0.008, ""), ("right", 0.008, "multiplier -1")))
    p = write(tmp_path, 'Robot { name "gripper" children [\n SliderJoint { device [ LinearMotor { } ] endPoint Solid { '
                        'translation 0 0 0.01 children [\n' + fingers + '] } }\n] }\n')
    w = load_world(p)
    assert not [x for x in w.warnings if "Ackermann" in x or "will not move" in x], w.warnings
    (robot,) = w.world.robots
    assert robot.differential_drive is None and robot.ackermann_drive is None
    why = ("is no wheel (it turns about a vertical axis and no motor of the robot drives a wheel): its joint moves "
           "kinematically")
    assert [x.split(": ", 1)[1].split(" (Webots")[0] for x in w.warnings if "HingeJoint motor" in x] == [
        f"HingeJoint motor 'motor::left finger' {why}", f"HingeJoint motor 'motor::right finger' {why}"]
    sim = Simulation(w)
    left, right = (sim.robot("gripper").motor(f"motor::{side} finger") for side in ("left", "right"))
    left.set_position(math.pi / 2)
    for _ in range(200):                     # 10 rad/s: a quarter turn within 0.16 s (16 ms steps)
        sim.step()
    assert (left.position, right.position) == (math.pi / 2, -math.pi / 2)
    tip = [e for e in robot.shapes + robot.devices if getattr(e, "on_joint", None) == "motor::left finger"]
    assert tip, "the left finger's end point rides its joint"


ARM = """Solid { translation 0.3 0 0.125 name "crate" children [ Shape { geometry DEF CRATE Box { size 0.2 0.2 0.25 } } ]
  boundingObject USE CRATE physics Physics { } }
Robot { name "arm" children [
 HingeJoint { jointParameters HingeJointParameters { position 2 axis 0 0 1 } device [ RotationalMotor { name "yaw motor" } ]
  endPoint Solid { rotation 0 0 1 2 children [
   Pose { translation 0 0 0.18 children [ Shape { geometry Cylinder { height 0.3 radius 0.04 } } ] }
   HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0 0.33 } device [ RotationalMotor {
     name "pitch motor" minPosition -2.3 maxPosition 1.5 } ]
    endPoint Solid { translation 0 0 0.33 children [
     Pose { rotation 1 0 0 1.5708 children [ Shape { geometry Cylinder { height 0.04 radius 0.06 } } ] }
     HingeJoint { jointParameters HingeJointParameters { position 0.5 axis 1 0 0 anchor 0.3 0 0 } device [
       RotationalMotor { name "roll motor" } ]
      endPoint Solid { translation 0.3 0 0 rotation 1 0 0 0.5 children [
       Pose { rotation 0 1 0 1.5708 children [ Shape { geometry Cylinder { height 0.02 radius 0.04 } } ] }
       SliderJoint { jointParameters JointParameters { axis 0 0 -1 } device [ LinearMotor { name "gripper motor"
         acceleration 1 maxVelocity 0.1 } ]
        endPoint VacuumGripper { children [ InertialUnit { translation 0 0 -0.01 }
          DEF CUP Pose { translation 0 0 -0.02 children [ Shape { geometry Cylinder { height 0.02 radius 0.042 } } ] } ]
         boundingObject USE CUP } }
      ] name "slider" } }
    ] } }
  ] } }
] }
"""


def test_an_arms_chain_of_round_hinges_is_no_failed_car(tmp_path: Path) -> None:
    """Webots' vacuum_gripper sample arm (our own world): a yaw hinge about z holding a pitch hinge
    about y, holding a roll hinge, holding a slider whose end point is the VacuumGripper with an
    InertialUnit; the pitch and roll links hold cylinders (round). No wheel drives anything: each
    motor is said once as no wheel (the pitch and roll hinges as links of a chain, the yaw hinge
    as vertical with nothing driven) and moves its joint. They used to be taken for a car (the yaw
    hinge steering a "wheel", the pitch hinge) and end in "no Ackermann drive (...); the robot will
    not move". As the sample does: with every joint at 0 the unit reads (0, 0, 0); lowering the
    slider puts the cup (its bottom 0.30 m up at travel 0) on the crate's top (0.25 m) and the
    presence turns 1 within 1 mm of it (the crate has physics: the cup holds it, Webots' rule, and
    carries it from then on); any yaw, pitch and roll are read back as the unit's roll, pitch and yaw
    (the links' axes are the world's x, y, z at 0)."""
    w = load_world(write(tmp_path, ARM))
    assert not [x for x in w.warnings if "Ackermann" in x or "will not move" in x], w.warnings
    (robot,) = w.world.robots
    assert robot.differential_drive is None and robot.ackermann_drive is None
    said = sorted(x.split(": ", 1)[1].split(": its joint")[0] for x in w.warnings if "is no wheel" in x)
    assert said == ["HingeJoint motor 'pitch motor' is no wheel (a link of a chain of motorised joints, carrying one "
                    "or carried by one)", "HingeJoint motor 'roll motor' is no wheel (a link of a chain of motorised "
                    "joints, carrying one or carried by one)", "HingeJoint motor 'yaw motor' is no wheel (it turns "
                    "about a vertical axis and no motor of the robot drives a wheel)"]
    sim = Simulation(w)
    arm = sim.robot("arm")
    imu, cup = sim.device("arm/inertial unit"), sim.device("arm/vacuum gripper")
    imu.enable(16)
    cup.set_on(True)                                         # type: ignore[attr-defined]
    cup.enable(16)
    for name in ("yaw motor", "pitch motor", "roll motor"):
        arm.motor(name).set_position(0.0)
    for _ in range(100):                                     # 2 rad at 10 rad/s: 0.2 s and the ramp
        sim.step()
    assert imu.roll_pitch_yaw == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)      # type: ignore[attr-defined]
    assert cup.value == 0.0                                  # type: ignore[attr-defined]   5 cm above the crate
    slider = arm.motor("gripper motor")
    slider.set_position(0.06)
    seen = set()
    for _ in range(100):                                     # 0.1 m/s: 0.05 m within 0.6 s with the ramp
        sim.step()
        gap = 0.05 - float(slider.position)
        if abs(gap - 0.001) > 1e-9:
            assert cup.value == (1.0 if gap <= 0.001 else 0.0), gap      # type: ignore[attr-defined]
        seen.add(cup.value)                                  # type: ignore[attr-defined]
    assert seen == {0.0, 1.0}
    slider.set_position(0.0)
    roll, pitch, yaw = 0.8097, -0.0316, 0.3391
    for name, q in (("roll motor", roll), ("pitch motor", pitch), ("yaw motor", yaw)):
        arm.motor(name).set_position(q)
    for _ in range(100):
        sim.step()
    assert imu.roll_pitch_yaw == pytest.approx([roll, pitch, yaw], abs=1e-6)   # type: ignore[attr-defined]
    assert cup.value == 1.0                                  # type: ignore[attr-defined]   the crate lifted with it
    assert sim.scene.solid_poses["crate"].translation[2] > 0.125 + 0.04


def test_a_lone_hinge2_joint_is_no_failed_car(tmp_path: Path) -> None:
    """Webots' motor2 sample (our own world): one Hinge2Joint on a post, first axis -x, second -y,
    its end point a small cylinder (round) holding a distance sensor 5 cm out. One joint makes no
    vehicle: its two motors are said once each as no wheel and move the end point by
    R(a1, q1) R(a2, q2) about the anchor. It used to be taken for a car with one steered wheel
    ("no Ackermann drive (a car-like robot needs two steered front wheels ...); the robot will not
    move")."""
    p = write(tmp_path, """Robot { name "post" translation 0.1 0 0 children [
 Solid { translation 0 0 0.06 children [
  Shape { geometry Cylinder { height 0.1 radius 0.02 } }
  Hinge2Joint {
   jointParameters HingeJointParameters { axis -1 0 0 anchor 0 0 0.07 }
   jointParameters2 JointParameters { axis 0 -1 0 }
   device [ RotationalMotor { name "motor 1" maxVelocity 1 } ]
   device2 [ RotationalMotor { name "motor 2" maxVelocity 1 } ]
   endPoint Solid { translation 0 0 0.07 children [ DEF C Shape { geometry Cylinder { height 0.03 radius 0.008 } }
     DistanceSensor { translation 0 0 0.05 name "tip" } ] boundingObject USE C } } ] } ] }
""")
    w = load_world(p)
    assert not [x for x in w.warnings if "Ackermann" in x or "will not move" in x], w.warnings
    assert [x.split(": ", 1)[1].split(": its joint")[0] for x in w.warnings if "is no wheel" in x] == [
        "Hinge2Joint motor 'motor 1' is no wheel (the robot's only motorised joint)",
        "Hinge2Joint motor 'motor 2' is no wheel (the robot's only motorised joint)"]
    sim = Simulation(w)
    robot = sim.robot("post")
    q1, q2 = 1.0, -0.5
    robot.motor("motor 1").set_position(q1)
    robot.motor("motor 2").set_position(q2)
    for _ in range(200):                     # 1 rad/s: 1 rad within 1 s and the ramp (16 ms steps)
        sim.step()
    assert (robot.motor("motor 1").position, robot.motor("motor 2").position) == (q1, q2)

    def rot(axis: list[float], q: float) -> np.ndarray:
        k = np.asarray(axis, dtype=np.float64)
        kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        return np.eye(3) + math.sin(q) * kx + (1 - math.cos(q)) * kx @ kx

    turn = rot([-1, 0, 0], q1) @ rot([0, -1, 0], q2)
    tip = sim.device("post/tip").world_pose(robot.pose)
    assert tip.translation == pytest.approx([0.1, 0.0, 0.13] + turn @ [0.0, 0.0, 0.05], abs=1e-12)
    assert np.asarray(tip.rotation) == pytest.approx(turn, abs=1e-12)


def test_gripper_fingers_on_round_axles_are_no_failed_car(tmp_path: Path) -> None:
    """Webots' coupled_motors sample as it is: each finger's end point holds its axle, a plain Cylinder
    (radius 2.5 mm), and a passive hinge to the fingertip. Round end points on vertical hinges were
    taken for a car's two steered wheels, and the gripper ended in "no Ackermann drive (the driven
    wheels (none) ...); the robot will not move". No motorised hinge drives a wheel, so there is no
    vehicle: each finger is said once as no wheel and moves its joint, coupled as in Webots."""
    fingers = "".join(
        f' HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor 0 {y} 0 }} device [ '
        f'RotationalMotor {{ name "motor::{side} finger" {m} }} ] endPoint Solid {{ translation 0 {y} 0 children [ '
        f'DEF AXLE Shape {{ geometry Cylinder {{ height 0.0125 radius 0.0025 }} }}\n'
        f'  HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor 0.02869 {3.5 * y} 0 }} '
        f'endPoint Solid {{ translation 0.02869 {3.5 * y} 0 name "{side} tip" children [ TouchSensor {{ name '
        f'"{side} touch" }} ] }} }} ] name "{side} finger" boundingObject USE AXLE }} }}\n'
        for side, y, m in (("left", -0.008, ""), ("right", 0.008, "multiplier -1")))
    p = write(tmp_path, 'Robot { name "gripper" children [\n' + fingers + '] }\n')
    w = load_world(p)
    assert not [x for x in w.warnings if "Ackermann" in x or "will not move" in x], w.warnings
    (robot,) = w.world.robots
    assert robot.differential_drive is None and robot.ackermann_drive is None
    said = sorted(x.split(": ", 1)[1].split(" (")[0] for x in w.warnings if "is no wheel" in x)
    assert said == ["HingeJoint motor 'motor::left finger' is no wheel",
                    "HingeJoint motor 'motor::right finger' is no wheel"]
    sim = Simulation(w)
    gripper = sim.robot("gripper")
    left, right = (gripper.motor(f"motor::{side} finger") for side in ("left", "right"))
    left.set_position(math.pi / 2)           # the right finger takes -pi/2 (multiplier -1)
    for _ in range(400):
        sim.step()
    assert (left.position, right.position) == (pytest.approx(math.pi / 2), pytest.approx(-math.pi / 2))
    # each tip at (0.02869, 3.5 y) from its finger's anchor (0, y): a quarter turn about ±z puts it at
    # (0, y) + Rz(±pi/2)·(0.02869, 3.5 y)
    for side, y, s in (("left", -0.008, 1.0), ("right", 0.008, -1.0)):
        at = sim.device(f"gripper/{side} touch").world_pose(gripper.pose).translation
        assert at == pytest.approx([-s * 3.5 * y, y + s * 0.02869, 0.0], abs=1e-9)


def test_a_lone_hinge2_joint_with_two_motors_is_no_failed_car(tmp_path: Path) -> None:
    """Webots' hinge_2_joint_with_backlash (motor2) sample: a fixed robot whose one Hinge2Joint has a
    motor on each axis (axis -x, then axis2 -y) and a round end point (a cylinder). Its first motor was
    taken for a car's lone steering joint: "no Ackermann drive (... 1 steering motor(s) ...); the robot
    will not move". One joint makes no vehicle: both motors are said once as no wheel and move the end
    point. A distance sensor at (0, 0.05, 0) in the end point (anchor (0, 0, 0.07)) turned a quarter
    about -x is at (0, 0, 0.07 - 0.05)."""
    p = write(tmp_path, 'Robot { name "wrist" children [\n'
              ' Hinge2Joint { jointParameters HingeJointParameters { axis -1 0 0 anchor 0 0 0.07 }\n'
              '  jointParameters2 JointParameters { axis 0 -1 0 }\n'
              '  device [ RotationalMotor { name "motor 1" maxVelocity 100 maxTorque 100000 } ]\n'
              '  device2 [ RotationalMotor { name "motor 2" maxVelocity 100 maxTorque 100000 } ]\n'
              '  endPoint Solid { translation 0 0 0.07 children [ DEF C Shape { geometry Cylinder { radius 0.008 '
              'height 0.03 } }\n'
              '   DistanceSensor { translation 0 0.05 0 } ] boundingObject USE C } }\n] }\n')
    w = load_world(p)
    assert not [x for x in w.warnings if "Ackermann" in x or "will not move" in x], w.warnings
    said = sorted(x.split(": ", 1)[1].split(": ")[0] for x in w.warnings if "is no wheel" in x)
    assert said == ["Hinge2Joint motor 'motor 1' is no wheel (the robot's only motorised joint)",
                    "Hinge2Joint motor 'motor 2' is no wheel (the robot's only motorised joint)"]
    sim = Simulation(w)
    sim.robot("wrist").motor("motor 1").set_position(math.pi / 2)
    sim.step()
    ds = sim.device("wrist/distance sensor").world_pose(sim.robot("wrist").pose)
    assert ds.translation == pytest.approx([0.0, 0.0, 0.02], abs=1e-12)


def test_a_fixed_arm_of_round_links_is_no_failed_car(tmp_path: Path) -> None:
    """Webots' vacuum_gripper sample: a fixed arm, yaw (axis z) holding pitch (axis y) holding roll,
    each link made of cylinders. The vertical yaw hinge with round parts past it was taken for a car's
    steering and the robot ended in "no Ackermann drive (wheel axis of motor 'roll motor' ...); the robot
    will not move". Motorised hinges all past one of them are an arm: each is said once as no wheel and
    moves its joint. A sensor 0.2 above the pitch anchor (0, 0, 0.33): pitch a quarter turn about y puts
    it at (0.2, 0, 0.33), yaw a quarter about z then at (0, 0.2, 0.33)."""
    link = 'Shape { geometry Cylinder { radius 0.04 height 0.3 } }'
    p = write(tmp_path, 'Robot { name "arm" children [\n'
              ' HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 }\n'
              '  device [ RotationalMotor { name "yaw motor" maxVelocity 100 maxTorque 100000 } ]\n'
              f'  endPoint Solid {{ children [ Pose {{ translation 0 0 0.18 rotation 1 0 0 1.5708 children [ {link} ] }}\n'
              '   HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0 0.33 }\n'
              '    device [ RotationalMotor { name "pitch motor" maxVelocity 100 maxTorque 100000 } ]\n'
              f'    endPoint Solid {{ translation 0 0 0.33 children [ Pose {{ rotation 0 1 0 1.5708 children [ {link} ] }}\n'
              '     DistanceSensor { translation 0 0 0.2 }\n'
              '     HingeJoint { jointParameters HingeJointParameters { axis 0 -1 0 anchor 0 -0.3 0 }\n'
              '      device [ RotationalMotor { name "roll motor" } ]\n'
              f'      endPoint Solid {{ translation 0 -0.3 0 children [ {link} ] }} }} ] }} }} ] }} }}\n] }}\n')
    w = load_world(p)
    assert not [x for x in w.warnings if "Ackermann" in x or "will not move" in x], w.warnings
    said = sorted(x.split(": ", 1)[1].split(" (")[0] for x in w.warnings if "is no wheel" in x)
    assert said == [f"HingeJoint motor '{m} motor' is no wheel" for m in ("pitch", "roll", "yaw")]
    sim = Simulation(w)
    arm = sim.robot("arm")
    arm.motor("pitch motor").set_position(math.pi / 2)
    sim.step()
    assert sim.device("arm/distance sensor").world_pose(arm.pose).translation == pytest.approx([0.2, 0, 0.33], abs=1e-12)
    arm.motor("yaw motor").set_position(math.pi / 2)
    sim.step()
    assert sim.device("arm/distance sensor").world_pose(arm.pose).translation == pytest.approx([0, 0.2, 0.33], abs=1e-12)


def test_a_compass_needle_on_a_two_wheel_robot_leaves_it_its_drive(tmp_path: Path) -> None:
    """Webots' compass sample: a two-wheel robot carries a needle, a motorised hinge about z whose end
    point holds a thin rod (a cylinder 0.1 long, 0.005 in radius, lying across the axis) and a cone.
    The rod was taken for a wheel, so the hinge for a car's lone steering joint, and the robot lost
    its drive ("no Ackermann drive ...; the robot will not move"). A cylinder more than twice as long
    as its diameter is no wheel: the needle steers nothing and turns, and the wheels drive."""
    needle = ('HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 anchor 0 0 0.1 }\n'
              '  device [ RotationalMotor { name "arrow" } ]\n'
              '  endPoint Solid { translation 0 0 0.1 children [\n'
              '    Shape { geometry Cylinder { height 0.1 radius 0.005 } }\n'
              '    Pose { translation 0 0.05 0 children [ Shape { geometry Cone { bottomRadius 0.01 height 0.02 } } ] }\n'
              '    DistanceSensor { translation 0.06 0 0 } ] } }\n')
    sim = _two_wheels_and_a_joint(tmp_path, "compass bot", needle, "arrow")
    bot = sim.robot("compass bot")
    for name in ("left wheel", "right wheel"):
        bot.motor(name).set_position(math.inf)
        bot.motor(name).set_velocity(5.0)
    bot.motor("arrow").set_position(math.pi / 2)
    sim.step()
    assert bot.pose.translation[0] == pytest.approx(5.0 * R * 0.016, rel=1e-9)     # one 16 ms step forward
    for _ in range(199):                 # the needle ramps up (Webots' kinematic rule) and stops on its target
        sim.step()
    assert bot.pose.translation[0] == pytest.approx(200 * 5.0 * R * 0.016, rel=1e-9)  # straight on, at 5 rad/s
    ds = sim.device("compass bot/distance sensor").world_pose(bot.pose)
    assert ds.translation - bot.pose.translation == pytest.approx([0.0, 0.06, 0.1], abs=1e-12)   # turned a quarter


def test_a_ball_robot_on_one_steered_wheel_gets_one_line_naming_its_wheel_not_a_car(tmp_path: Path) -> None:
    """A ball robot of our own (a BB-8's shape): a vertical yaw hinge carrying a pitch hinge whose end
    point is the 0.25 m ball, and a head on a second vertical hinge. One driven wheel inside a
    steering joint is no car: the line says so, where it blamed the car's front axle."""
    body = ('Robot { name "ball" children [\n'
            '  HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 } '
            'device [ RotationalMotor { name "yaw" maxVelocity 8 } ]\n'
            '    endPoint Solid { translation 0 0 0.25 children [\n'
            '      HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 } '
            'device [ RotationalMotor { name "pitch" maxVelocity 8 } ]\n'
            '        endPoint Solid { children [ Shape { geometry Sphere { radius 0.25 } } ] '
            'boundingObject Sphere { radius 0.25 } physics Physics { } } }\n'
            '    ] name "inner" } }\n'
            '  HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 } '
            'device [ RotationalMotor { name "head yaw" maxVelocity 8 } ]\n'
            '    endPoint Solid { translation 0 0 0.525 children [ Shape { geometry Sphere { radius 0.15 } } ] '
            'name "head" } }\n'
            '] physics Physics { } }\n')
    w = load_world(write(tmp_path, body))
    (robot,) = w.world.robots
    assert robot.differential_drive is None and robot.ackermann_drive is None
    drive_lines = [x for x in w.warnings if "will not move" in x]
    assert len(drive_lines) == 1, w.warnings
    assert drive_lines[0].endswith(
        "robot 'ball': no drive (its only driven wheel, 'pitch', turns inside the steering joint 'yaw': a robot on "
        "one wheel (a ball its weight rolls, a unicycle) moves by Webots' physics, and no kinematic drive here rolls "
        "on one wheel); the robot will not move")
    sim = Simulation(w, "fast")
    for m in ("yaw", "pitch"):
        sim.robot("ball").motor(m).set_position(math.inf)
        sim.robot("ball").motor(m).set_velocity(4.0)
    sim.run(62)
    assert sim.robot("ball").pose.translation == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)


def test_a_head_on_a_pan_hinge_high_above_the_wheels_is_no_steered_wheel(tmp_path: Path) -> None:
    """A two-wheel base of our own (a TIAGo's shape) with a pan-tilt head 0.8 m up whose tilt hinge's
    end point is a sphere: the pan hinge carrying a round part about a horizontal axis looked like a
    car's steering and its wheel, and the robot lost its drive ('no Ackermann drive'). A round part
    whose bottom is more than a wheel's diameter above the wheels never touches the ground: the drive
    is the base's two wheels, and the head's joints are said to move as joints."""
    def hub(name: str, y: float) -> str:
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.1 }} '
                f'device [ RotationalMotor {{ name "{name}" maxVelocity 10 }} ] endPoint Solid {{ translation 0 {y} 0.1 '
                f'rotation 1 0 0 1.5708 children [ Shape {{ geometry Cylinder {{ radius 0.1 height 0.04 }} }} ] '
                f'boundingObject Cylinder {{ radius 0.1 height 0.04 }} physics Physics {{ }} }} }}\n')
    body = ('Robot { name "tiagoish" translation 0 0 0.1 children [\n' + hub("wheel_left", 0.2) + hub("wheel_right", -0.2)
            + '  HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 anchor 0.1 0 0.8 } '
            'device [ RotationalMotor { name "head_pan" maxVelocity 3 } ]\n'
            '    endPoint Solid { translation 0.1 0 0.8 children [\n'
            '      HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 } '
            'device [ RotationalMotor { name "head_tilt" maxVelocity 3 } PositionSensor { name "head_tilt_sensor" } ]\n'
            '        endPoint Solid { children [ Shape { geometry Sphere { radius 0.09 } } ] name "head" } }\n'
            '    ] name "neck" } }\n'
            '] boundingObject Pose { translation 0 0 0.3 children [ Box { size 0.4 0.3 0.3 } ] } physics Physics { } }\n')
    w = load_world(write(tmp_path, body))
    (robot,) = w.world.robots
    drive = robot.differential_drive
    assert drive is not None and (drive.left_motor, drive.right_motor) == ("wheel_left", "wheel_right")
    assert drive.wheel_radius == pytest.approx(0.1) and drive.axle_length == pytest.approx(0.4)
    assert not any("Ackermann" in x or "will not move" in x for x in w.warnings), w.warnings
    (tilt,) = [x for x in w.warnings if "'head_tilt'" in x]
    # the sphere's bottom: 0.1 + 0.8 - 0.09 over the wheels' 0.1 - 0.1 = 0.71 m up
    assert "is no wheel (its round part's bottom is 0.71 m above the robot's lowest wheels" in tilt
    assert any("'head_pan' is no wheel and steers none" in x for x in w.warnings), w.warnings
    sim = Simulation(w, "fast")
    drive_robot = sim.robot("tiagoish")
    for m in ("wheel_left", "wheel_right"):
        drive_robot.motor(m).set_position(math.inf)
        drive_robot.motor(m).set_velocity(2.0)
    drive_robot.motor("head_tilt").set_position(0.3)
    sim.run(125)                                        # 2 s at 2 rad/s on 0.1 m wheels: 0.4 m
    assert drive_robot.pose.translation[0] == pytest.approx(0.4, abs=1e-9)
    assert drive_robot.motor("head_tilt").position == pytest.approx(0.3, abs=1e-9)      # 3 rad/s: there in 0.1 s


def corner(name: str, x: float, y: float, axis: str = "0 0 1") -> str:
    """A rover's steered corner (a Sojourner's): a motorised vertical hinge whose end point carries one
    driven wheel under its axis."""
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {x} {y} 0 }} '
            f'device [ RotationalMotor {{ name "{name} arm" maxVelocity 5 }} ] '
            f'endPoint Solid {{ translation {x} {y} 0 name "{name} arm" children [\n{wheel(f"{name} wheel", 0, 0)}] '
            '} }\n')


def test_a_rover_on_four_steered_corners_and_two_middle_wheels_drives_by_their_fit(tmp_path: Path) -> None:
    """Four steered corners and two unsteered middle wheels (a Sojourner's six): the corners' wheels
    steered by their arms (one hinge about -z: it steers the other way), the middle ones at their fixed
    heading. Spinning as the rover's 'turn around' does (corner arms at ±0.87, left wheels +ω, right -ω)
    moves it by the least-squares fit of the six wheels' velocities (closed form below)."""
    places = {"front left": (0.3, 0.25), "front right": (0.3, -0.25), "back left": (-0.3, 0.25),
              "back right": (-0.3, -0.25)}
    robot = ('Robot { name "rover" children [\n'
             + "".join(corner(k, *xy, axis="0 0 -1" if k == "back right" else "0 0 1") for k, xy in places.items())
             + wheel("middle left wheel", 0.0, 0.25) + wheel("middle right wheel", 0.0, -0.25)
             + '] controller "<extern>" }\n')
    w = load_world(write(tmp_path, robot))
    drive = w.world.robots[0].steered_drive
    assert drive is not None and not [x for x in w.warnings if "will not move" in x]
    by_motor = {x.motor: x for x in drive.wheels}
    assert by_motor["back right wheel"].steer_sign == -1 and by_motor["front left wheel"].steer_sign == 1
    assert (by_motor["middle left wheel"].steer, by_motor["middle left wheel"].position) == (None, (0.0, 0.25))
    sim = Simulation(w, "fast")
    rover = sim.robot("rover")
    arms = {"front left": -0.87, "front right": 0.87, "back left": 0.87, "back right": -0.87}
    for k, a in arms.items():
        rover.motor(f"{k} arm").set_position(a)
    sim.run(50)                                   # the arms turn (the wheels hold: the rover stays)
    assert rover.pose.translation[:2] == pytest.approx([0.0, 0.0], abs=0.0)
    omega = 3.0
    speeds = {"front left": omega, "back left": omega, "middle left": omega,
              "front right": -omega, "back right": -omega, "middle right": -omega}
    for k, s in speeds.items():
        rover.motor(f"{k} wheel").set_position(math.inf)
        rover.motor(f"{k} wheel").set_velocity(s)
    sim.run(1)
    # the fit: Σx = Σy = 0, so vx = Σux/6, vy = Σuy/6, ωz = Σ(x·uy − y·ux)/Σ(x² + y²)
    where = {**places, "middle left": (0.0, 0.25), "middle right": (0.0, -0.25)}
    heading = {k: (-1.0 if k == "back right" else 1.0) * a for k, a in arms.items()}
    u = {k: (R * s * math.cos(heading.get(k, 0.0)), R * s * math.sin(heading.get(k, 0.0))) for k, s in speeds.items()}
    vx = sum(v[0] for v in u.values()) / 6
    vy = sum(v[1] for v in u.values()) / 6
    wz = sum(x * u[k][1] - y * u[k][0] for k, (x, y) in where.items()) / sum(x * x + y * y for x, y in where.values())
    assert rover.drive.velocity()[5] == pytest.approx(wz, abs=1e-12)
    lin = rover.drive.velocity()[:2]
    dt = 0.016                                    # the origin's velocity at the step's end: the twist turned by ωz·dt
    c, s = math.cos(wz * dt), math.sin(wz * dt)
    assert lin == pytest.approx([vx * c - vy * s, vx * s + vy * c], abs=1e-12)


def rocker_side(side: str, y: float) -> str:
    """One side of a rocker-bogie (a Sojourner's): a motorised rocker hinge on the body carrying the back
    steered corner and a motorised bogie hinge, which carries the front steered corner and the middle
    wheel: every wheel rides two or three motorised hinges."""
    bogie = (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0.15 0 {R} }} '
             f'device [ RotationalMotor {{ name "{side} bogie" }} ] '
             f'endPoint Solid {{ translation 0.15 0 0 name "{side} bogie" children [\n'
             + corner(f"front {side}", 0.15, 0) + wheel(f"middle {side} wheel", -0.15, 0) + '] } }\n')
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} {R} }} '
            f'device [ RotationalMotor {{ name "{side} rocker" }} ] '
            f'endPoint Solid {{ translation 0 {y} 0 name "{side} rocker" children [\n'
            + corner(f"back {side}", -0.3, 0) + bogie + '] } }\n')


def test_a_rocker_bogie_rover_keeps_its_six_wheels_and_drives_by_their_fit(tmp_path: Path) -> None:
    """Six wheels on a rocker-bogie (a Sojourner's): the corners' steering hinges and the middle wheels
    ride motorised rocker and bogie hinges. Those hinges are its suspension, no wheels (one line each);
    the six wheels stay the steered drive's (they used to be dropped as links of a chain of motorised
    joints, leaving the rover without a drive). All wheels at ω roll it straight at r·ω; the rover's
    'turn around' (arms at ±0.87, left +ω, right -ω) moves it by the six wheels' fit, as on a flat base."""
    robot = ('Robot { name "rover" children [\n' + rocker_side("left", 0.25) + rocker_side("right", -0.25)
             + '] controller "<extern>" }\n')
    w = load_world(write(tmp_path, robot))
    drive = w.world.robots[0].steered_drive
    assert drive is not None and not [x for x in w.warnings if "will not move" in x]
    where = {"front left": (0.3, 0.25), "front right": (0.3, -0.25), "back left": (-0.3, 0.25),
             "back right": (-0.3, -0.25), "middle left": (0.0, 0.25), "middle right": (0.0, -0.25)}
    assert {x.motor: (x.steer, x.position, x.radius) for x in drive.wheels} == {
        f"{k} wheel": (None if k.startswith("middle") else f"{k} arm", xy, R) for k, xy in where.items()}
    for hinge, carried in (("left rocker", "'back left wheel', 'front left wheel', 'middle left wheel'"),
                           ("left bogie", "'front left wheel', 'middle left wheel'")):
        assert sum(f"motor '{hinge}' is no wheel (a rocker-bogie's suspension hinge: its end point carries the "
                   f"wheels {carried})" in x for x in w.warnings) == 1
    sim = Simulation(w, "fast")
    rover = sim.robot("rover")
    omega = 3.0
    for k in where:
        rover.motor(f"{k} wheel").set_position(math.inf)
        rover.motor(f"{k} wheel").set_velocity(omega)
    sim.run(125)                                  # 2 s straight ahead at r·ω
    assert rover.pose.translation[:2] == pytest.approx([2 * R * omega, 0.0], abs=1e-12)
    for k in where:
        rover.motor(f"{k} wheel").set_velocity(0.0)
    arms = {"front left": -0.87, "front right": 0.87, "back left": 0.87, "back right": -0.87}
    for k, a in arms.items():
        rover.motor(f"{k} arm").set_position(a)
    sim.run(50)                                   # the arms turn (the wheels hold: the rover stays)
    assert rover.pose.translation[:2] == pytest.approx([2 * R * omega, 0.0], abs=1e-12)
    speeds = {k: omega if k.endswith("left") else -omega for k in where}
    for k, s in speeds.items():
        rover.motor(f"{k} wheel").set_velocity(s)
    sim.run(1)
    u = {k: (R * s * math.cos(arms.get(k, 0.0)), R * s * math.sin(arms.get(k, 0.0))) for k, s in speeds.items()}
    wz = sum(x * u[k][1] - y * u[k][0] for k, (x, y) in where.items()) / sum(x * x + y * y for x, y in where.values())
    assert rover.drive.velocity()[5] == pytest.approx(wz, abs=1e-12)
    assert wz < 0.0                               # the arms at ±0.87 with left +ω, right -ω: clockwise


def test_a_rover_built_y_up_in_a_nue_world_gets_the_steered_drive(tmp_path: Path) -> None:
    """A robot built y-up (a NUE world's: x north, y up, z east) on four steered corners: its steering
    hinges turn about its y, its wheels about ±z. The drive takes places and headings along its x and
    its left (-z), forward its x (it used to get 'no steered-wheel drive (a robot built y-up ...)').
    Every corner steered a quarter turn and rolling at ω moves it to its left, west, at r·ω."""
    def corner_y_up(name: str, x: float, z: float) -> str:
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor {x} 0 {z} }} '
                f'device [ RotationalMotor {{ name "{name} arm" maxVelocity 5 }} ] '
                f'endPoint Solid {{ translation {x} 0 {z} name "{name} arm" children [\n'
                f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 -1 anchor 0 {R} 0 }} '
                f'device [ RotationalMotor {{ name "{name} wheel" maxVelocity 12.3 }} ] '
                f'endPoint Solid {{ translation 0 {R} 0 children [ DEF W Shape {{ geometry '
                f'Cylinder {{ radius {R} height 0.095 }} }} ] boundingObject USE W }} }}\n] }} }}\n')

    places = {"front left": (0.3, -0.25), "front right": (0.3, 0.25), "back left": (-0.3, -0.25),
              "back right": (-0.3, 0.25)}                  # (x, z): the left is -z
    p = tmp_path / "nue.wbt"
    p.write_text(HEADER + 'WorldInfo { coordinateSystem "NUE" basicTimeStep 16 }\nRobot { name "rover" children [\n'
                 + "".join(corner_y_up(k, x, z) for k, (x, z) in places.items()) + '] controller "<extern>" }\n')
    w = load_world(p)
    drive = w.world.robots[0].steered_drive
    assert drive is not None, w.warnings
    assert tuple(drive.forward) == (1.0, 0.0, 0.0)
    assert {x.motor: (x.steer, x.position, x.heading, x.steer_sign) for x in drive.wheels} == {
        f"{k} wheel": (f"{k} arm", (x, -z), 0.0, 1) for k, (x, z) in places.items()}
    sim = Simulation(w, "fast")
    rover = sim.robot("rover")
    for k in places:
        rover.motor(f"{k} arm").set_position(math.pi / 2)
    sim.run(50)                                   # the arms turn (the wheels hold: the rover stays)
    start = rover.pose.translation.copy()
    for k in places:
        rover.motor(f"{k} wheel").set_position(math.inf)
        rover.motor(f"{k} wheel").set_velocity(4.0)
    sim.run(100)                                  # 1.6 s to its left, west (-z), at r·4
    assert list(rover.pose.translation - start) == pytest.approx([0.0, 0.0, -R * 4.0 * 1.6], abs=1e-12)


def test_a_camera_ball_on_a_tilt_hinge_is_no_wheel_of_a_two_wheel_or_omni_robot(tmp_path: Path) -> None:
    """A tilt hinge on the body (riding no pan hinge) whose end point is a ball: something round that
    turns about its axis as a wheel would, but its bottom (0.3 - 0.03 m) is 0.27 m above the wheels'
    (0), more than their diameter (0.22 m). It is no wheel, with its height in its one line, and the
    two wheels keep their drive, whether the hinge is about the wheels' axis or across it. Before, a
    third "wheel" made the robot lose its drive ('no differential drive ...; the robot will not move')."""
    for axis in ("0 1 0", "1 0 0"):
        head = (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor 0.05 0 0.3 }} device [ '
                'RotationalMotor { name "tilt" } ] endPoint Solid { translation 0.05 0 0.3 children [ Shape { '
                'geometry Sphere { radius 0.03 } } ] } }\n')
        _two_wheels_and_a_joint(tmp_path, "cam", head, "tilt", "is no wheel (its round part's bottom is 0.27 m above "
                                "the robot's lowest wheels: it never touches the ground)")


SPINNING_HEAD = ('HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 anchor 0 0 0.3 } device [ '
                 'RotationalMotor { name "spin" } ] endPoint Solid { translation 0 0 0.3 children [ Shape { geometry '
                 'Cylinder { radius 0.04 height 0.05 } } ] } }\n')
"""A lidar's head spinning about the robot's z: a cylinder along its hinge's axis, centred on it."""


def test_a_spinning_lidar_head_steers_no_wheel(tmp_path: Path) -> None:
    """A vertical hinge whose end point is a cylinder along its axis (a spinning lidar head) turns it in
    place: something round that "steers", but it holds no wheel's joint and nothing it holds rolls. It
    is no wheel and steers none (its one line says so), and the two wheels keep their drive. Before,
    the robot was taken for a car with one steering motor ('no Ackermann drive ...; the robot will not
    move'). A vertical hinge carrying a wheel's joint still steers (the cars' tests)."""
    sim = _two_wheels_and_a_joint(tmp_path, "scan", SPINNING_HEAD, "spin", "is no wheel and steers none (it spins "
                                  "its round part in place about its own axis)")
    r = sim.robot("scan")
    for name in ("left wheel", "right wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(2.0)
    sim.run(100)
    assert r.pose.translation[0] == pytest.approx(R * 2.0 * 100 * 0.016, abs=1e-9)


def test_two_steering_hinges_one_behind_the_other_make_a_steered_drive_not_a_car(tmp_path: Path) -> None:
    """A steered front and a steered back wheel on the robot's x axis and two unsteered middle wheels
    (a Shrimp's layout): the two steering hinges are on no front axle, so the robot is no car; it
    gets the steered-wheel drive (before: 'no Ackermann drive (... not on one front axle ...); the
    robot will not move'). Both steered a quarter turn, every wheel rolling at ω while the middle
    ones are held: the fit moves it sideways at 2/4·r·ω (two wheels of four push it left)."""
    robot = ('Robot { name "bogie" children [\n' + corner("front", 0.3, 0.0) + corner("back", -0.3, 0.0)
             + wheel("middle left wheel", 0.0, 0.25) + wheel("middle right wheel", 0.0, -0.25)
             + '] controller "<extern>" }\n')
    w = load_world(write(tmp_path, robot))
    assert not [x for x in w.warnings if "will not move" in x], w.warnings
    drive = w.world.robots[0].steered_drive
    assert drive is not None
    assert {x.motor: (x.steer, x.position) for x in drive.wheels} == {
        "front wheel": ("front arm", (0.3, 0.0)), "back wheel": ("back arm", (-0.3, 0.0)),
        "middle left wheel": (None, (0.0, 0.25)), "middle right wheel": (None, (0.0, -0.25))}
    sim = Simulation(w, "fast")
    rover = sim.robot("bogie")
    for k in ("front", "back"):
        rover.motor(f"{k} arm").set_position(math.pi / 2)
    sim.run(50)
    for k in ("front", "back"):
        rover.motor(f"{k} wheel").set_position(math.inf)
        rover.motor(f"{k} wheel").set_velocity(4.0)
    sim.run(1)
    assert rover.drive.velocity()[:2] == pytest.approx([0.0, R * 4.0 / 2], abs=1e-12)
    assert rover.drive.velocity()[5] == pytest.approx(0.0, abs=1e-12)


def tricycle_wbt(steered_x: float, passive_hinge: bool) -> str:
    """Our tricycle: two driven wheels on the axle at x 0 (y ±Y), a steering hinge ('steer', about z)
    at x ``steered_x`` holding a free wheel of radius 0.08 -- in a passive HingeJoint (no device) or as
    the steering end point's own round part."""
    round_part = ('children [ DEF F Shape { geometry Cylinder { radius 0.08 height 0.04 } } ] boundingObject USE F')
    held = (f'children [ HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 -1 0 }} '
            f'device [ PositionSensor {{ name "front encoder" }} ] endPoint Solid {{ '
            f'rotation 1 0 0 1.5708 {round_part} }} }} ]' if passive_hinge else f'rotation 1 0 0 1.5708 {round_part}')
    return ('Robot { name "trike" children [\n'
            '  Pose { translation 0 0 0.2 children [ Shape { geometry Box { size 0.3 0.3 0.1 } } ] }\n'
            + wheel("left wheel", 0.0, Y) + wheel("right wheel", 0.0, -Y)
            + f'  HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor {steered_x} 0 0.08 }} '
              f'device [ RotationalMotor {{ name "steer" maxVelocity 100 }} ] '
              f'endPoint Solid {{ translation {steered_x} 0 0.08 {held} }} }}\n'
            '] }\n')


@pytest.mark.parametrize("steered_x, passive_hinge", [(0.5, True), (-0.4, False)])
def test_two_driven_wheels_and_a_steered_free_wheel_make_a_tricycle(tmp_path: Path, steered_x: float,
                                                                     passive_hinge: bool) -> None:
    """Two driven wheels on one axle and one steering hinge holding a free wheel (a passive hinge's
    or the end point's own round part), ahead of the axle or behind it: a steered drive with that free
    wheel, no load line; driven at ω with the steering at 0.3 it turns at ωz = R·ω·tan 0.3 / L (L the
    signed distance from the axle to the steering axis: behind it, the other way)."""
    loaded = load_world(write(tmp_path, tricycle_wbt(steered_x, passive_hinge)))
    assert loaded.warnings == []
    wheels = loaded.world.robots[0].steered_drive.wheels
    assert [(w.motor, w.steer, w.position) for w in wheels] == [
        ("left wheel", None, (0.0, Y)), ("right wheel", None, (0.0, -Y)), (None, "steer", (steered_x, 0.0))]
    assert wheels[2].radius == pytest.approx(0.08, abs=1e-12)
    sim = Simulation(loaded)
    sim.robot("trike").motor("steer").set_position(0.3)
    sim.run(60)
    for name in ("left wheel", "right wheel"):
        m = sim.robot("trike").motor(name)
        m.set_position(math.inf)
        m.set_velocity(5.0)
    sim.run(1)
    heading = 0.3 + wheels[2].heading
    assert sim.robot("trike").drive.velocity()[5] == pytest.approx(R * 5.0 * math.tan(heading) / steered_x, abs=1e-12)
    if passive_hinge:               # its encoder (hinge axis the robot's right: rolling forward reads decreasing)
        enc = sim.robot("trike").devices["front encoder"]
        assert (enc.config.free_wheel, enc.config.free_wheel_sign) == (2, -1)
        enc.enable(16)
        sim.run(9)                  # 10 steps rolled: the front wheel's ground speed R·ω / cos δ
        assert enc.value == pytest.approx(-R * 5.0 / math.cos(heading) * 0.16 / 0.08, abs=1e-9)


def test_two_wheels_whose_motors_share_a_name_are_one_line_naming_it(tmp_path: Path) -> None:
    """A copied HingeJoint whose motor kept the other wheel's name ended in "left_motor and right_motor
    must have different names", which named neither the motor nor what to do."""
    p = write(tmp_path, 'Robot { name "r" children [\n' + wheel("right wheel motor", 0, 0.026)
              + wheel("right wheel motor", 0, -0.026) + '] }\n')
    with pytest.raises(WorldError, match=r"line 3, column 1 .*differential_drive\): left_motor and right_motor are "
                                         r"both 'right wheel motor': the left and right wheels each need a motor of "
                                         r"its own name") as exc:
        load_world(p)
    assert "\n" not in str(exc.value)
