"""A car written in a .wbt (our own nodes: Robot, Hinge2Joint/HingeJoint, Solid wheels) maps onto the
kinematic ``ackermann_drive`` and drives the closed-form circle; a car whose geometry is not the
drive's gets one line saying why."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sensorium.client.webots.vehicle.driver import ackermann_angles
from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HEADER = "#VRML_SIM R2023b utf8\n"
L, T, R = 2.6, 1.5, 0.35          # wheelbase, track, wheel radius


def write(tmp_path: Path, body: str) -> Path:
    p = tmp_path / "car.wbt"
    p.write_text(HEADER + "WorldInfo { basicTimeStep 16 }\n" + body)
    return p


def solid_wheel(x: float, y: float) -> str:
    return (f'Solid {{ translation {x} {y} {R} rotation 1 0 0 1.5708 children [ DEF W Shape {{ geometry '
            f'Cylinder {{ radius {R} height 0.2 }} }} ] boundingObject USE W }}')


def rear_wheel(name: str, y: float, x: float = 0.0, axis: str = "0 1 0") -> str:
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {x} {y} {R} }} '
            f'device [ RotationalMotor {{ name "{name}" maxVelocity 80 }} '
            f'PositionSensor {{ name "{name.replace("wheel", "sensor")}" }} ] endPoint {solid_wheel(x, y)} }}\n')


def hinge2_front(side: str, y: float, axis: str = "0 0 -1", limit: float = 0.6, x: float = L) -> str:
    return (f'Hinge2Joint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {x} {y} {R} }} '
            f'jointParameters2 JointParameters {{ axis 0 1 0 }} '
            f'device [ RotationalMotor {{ name "{side}_steer" minPosition {-limit} maxPosition {limit} maxVelocity 5 }} '
            f'PositionSensor {{ name "{side}_steer_sensor" }} ] endPoint {solid_wheel(x, y)} }}\n')


def car(front: str, rear: str = rear_wheel("right_rear_wheel", -T / 2) + rear_wheel("left_rear_wheel", T / 2)) -> str:
    return ('Robot { name "car" controller "<extern>" children [\n'
            '  Pose { translation 1.3 0 0.6 children [ Shape { geometry Box { size 4 1.6 0.6 } } ] }\n'
            + front + rear + '] }\n')


HINGE2_CAR = car(hinge2_front("right", -T / 2) + hinge2_front("left", T / 2))


def test_a_hinge2_car_maps_to_the_ackermann_drive_and_drives_the_circle(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, HINGE2_CAR))
    assert not [x for x in w.warnings if "drive" in x]
    (robot,) = w.world.robots
    assert robot.ackermann_drive == wm.AckermannDrive(
        wheelbase=L, track_front=T, track_rear=T, front_wheel_radius=R, rear_wheel_radius=R, type="propulsion",
        max_wheel_speed=80.0, max_steering_angle=0.6, max_steering_speed=5.0, positive_steers="right")
    sensors = {d.name: d.motor for d in robot.devices if d.device == "PositionSensor"}
    assert sensors == {"right_steer_sensor": "right_steer", "left_steer_sensor": "left_steer",
                       "right_rear_sensor": "right_rear_wheel", "left_rear_sensor": "left_rear_wheel"}
    sim = Simulation(w)
    r = sim.robot("car")
    delta = 0.2
    right, left = ackermann_angles(delta, L, T)
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    sim.run(10)
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(30.0)
    n = 500
    sim.run(n)
    radius, phi = L / math.tan(delta), R * 30.0 * n * 0.016 / (L / math.tan(delta))
    p = r.pose.translation
    assert (p[0], p[1]) == pytest.approx((radius * math.sin(phi), -radius + radius * math.cos(phi)), abs=1e-9)


def test_wheels_in_slots_and_turned_joint_frames_as_webots_cars_have_them(tmp_path: Path) -> None:
    # Webots' AckermannVehicle: each joint in a Transform turned about z, its wheel in a Slot, axes in that frame
    def joint(kind: str, x: float, y: float, turn: float, axis: str, device: str, axis2: str = "") -> str:
        params = (f'jointParameters HingeJointParameters {{ axis {axis} }} '
                  + (f'jointParameters2 JointParameters {{ axis {axis2} }} ' if axis2 else ''))
        wheel = (f'Solid {{ rotation 0 1 0 1.5708 children [ DEF S Shape {{ geometry Cylinder {{ radius {R} height 0.2 }} '
                 f'}} ] boundingObject USE S }}')
        return (f'Transform {{ translation {x} {y} 0 rotation 0 0 1 {turn} children [ {kind} {{ {params}'
                f'device [ RotationalMotor {{ name "{device}" minPosition -0.5 maxPosition 0.5 }} ] '
                f'endPoint Slot {{ endPoint {wheel} }} }} ] }}\n')
    front = (joint("Hinge2Joint", L, T / 2, -1.5708, "0 0 -1", "left_steer", "-1 0 0")
             + joint("Hinge2Joint", L, -T / 2, 1.5708, "0 0 -1", "right_steer", "1 0 0"))
    rear = (joint("HingeJoint", 0, T / 2, -1.5708, "-1 0 0", "left_rear_wheel")
            + joint("HingeJoint", 0, -T / 2, 1.5708, "1 0 0", "right_rear_wheel"))
    w = load_world(write(tmp_path, car(front, rear)))
    assert not [x for x in w.warnings if "drive" in x]
    d = w.world.robots[0].ackermann_drive
    assert d is not None
    assert d.wheelbase == pytest.approx(L) and d.track_front == pytest.approx(T) and d.track_rear == pytest.approx(T)
    assert (d.type, d.positive_steers, d.max_steering_angle, d.rear_wheel_radius) == ("propulsion", "right", 0.5, R)


def test_vertical_steering_hinges_carrying_driven_wheels_make_a_front_wheel_drive(tmp_path: Path) -> None:
    def front(side: str, y: float) -> str:         # a steering hinge whose end point holds the motorised wheel hinge
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor {L} {y} {R} }} '
                f'device [ RotationalMotor {{ name "{side} steer" maxVelocity 4 }} ] '
                f'endPoint Solid {{ translation {L} {y} {R} children [ HingeJoint {{ jointParameters '
                f'HingeJointParameters {{ axis 0 1 0 }} device [ RotationalMotor {{ name "{side} wheel" maxVelocity 50 }} ] '
                f'endPoint Solid {{ rotation 1 0 0 1.5708 children [ DEF F Shape {{ geometry Cylinder {{ radius 0.3 '
                f'height 0.2 }} }} ] boundingObject USE F }} }} ] }} }}\n')
    w = load_world(write(tmp_path, car(front("right", -T / 2) + front("left", T / 2), rear="")))
    assert not [x for x in w.warnings if "drive" in x]
    d = w.world.robots[0].ackermann_drive
    assert d is not None and (d.type, d.positive_steers, d.front_wheel_radius, d.rear_wheel_radius) == (
        "traction", "left", 0.3, 0.3)
    assert (d.right_steer, d.left_steer, d.right_front_wheel, d.left_front_wheel) == (
        "right steer", "left steer", "right wheel", "left wheel")
    assert d.max_steering_angle == 1.5 and d.max_steering_speed == 4.0 and d.max_wheel_speed == 50.0


@pytest.mark.parametrize("body, why", [
    (car(hinge2_front("left", T / 2)),
     "a car-like robot needs two steered front wheels, it has 1 steering motor(s) ('left_steer')"),
    (car(hinge2_front("right", -T / 2, axis="0 0.2 -1") + hinge2_front("left", T / 2)),
     "the steering axis of motor 'right_steer' is [0.0, 0.196116, -0.980581], not vertical (the robot's z axis)"),
    (car(hinge2_front("right", -T / 2, axis="0 0 1") + hinge2_front("left", T / 2)),
     "the steering motors 'right_steer', 'left_steer' turn about opposite axes (one +z, one -z)"),
    (car(hinge2_front("right", -T / 2, x=-L) + hinge2_front("left", T / 2, x=-L)),
     "the steering joints are at x=-2.6, not ahead of the rear axle (x=0, its driven wheels')"),
    (car(hinge2_front("right", -T / 2) + hinge2_front("left", T / 2),
         rear_wheel("right_rear_wheel", -T / 2, x=-0.4) + rear_wheel("left_rear_wheel", T / 2)),
     "the driven wheels ('right_rear_wheel' at x=-0.4, 'left_rear_wheel' at x=0) are not a pair on the front axle "
     "(x=2.6), a pair on one rear axle parallel to the robot's y axis, or both"),
    (car(hinge2_front("right", -T / 2) + hinge2_front("left", T / 2),
         rear_wheel("right_rear_wheel", -T / 2, x=3.0) + rear_wheel("left_rear_wheel", T / 2, x=3.0)),
     "the steering joints are at x=2.6, not ahead of the rear axle (x=3, its driven wheels')"),
    (car(hinge2_front("right", -T / 2) + hinge2_front("left", T / 2),
         rear_wheel("right_rear_wheel", -T / 2, axis="0 -1 0") + rear_wheel("left_rear_wheel", T / 2)),
     "wheel axis of motor 'right_rear_wheel' is [0.0, -1.0, 0.0], not the robot's +y (positive wheel speeds must "
     "drive forward)"),
])
def test_a_car_that_is_not_the_drives_gets_one_line(tmp_path: Path, body: str, why: str) -> None:
    p = write(tmp_path, body)
    w = load_world(p)
    assert w.world.robots[0].ackermann_drive is None and w.world.robots[0].differential_drive is None
    (line,) = [x for x in w.warnings if "Ackermann" in x]
    assert line == f"{p}:3:1: robot 'car': no Ackermann drive ({why}); the robot will not move"


def test_a_sensor_on_a_steering_axis_without_a_motor_is_said_once(tmp_path: Path) -> None:
    # the right front Hinge2Joint's steering axis has a PositionSensor but no motor
    bare = hinge2_front("right", -T / 2).replace(
        'RotationalMotor { name "right_steer" minPosition -0.6 maxPosition 0.6 maxVelocity 5 } ', "")
    assert "RotationalMotor" not in bare
    w = load_world(write(tmp_path, car(bare + hinge2_front("left", T / 2))))
    said = [x for x in w.warnings if "PositionSensor" in x]
    assert len(said) == 1 and "Hinge2Joint axis without a motor (jointParameters, a free steering axis)" in said[0]


def free_front(side: str, y: float, position: float, axis: str = "0 1 0") -> str:
    """Webots' Car with rear-wheel drive: the front Hinge2Joints' second axis (device2) has a
    PositionSensor and a Brake but no motor (a free wheel)."""
    return hinge2_front(side, y).replace(
        "jointParameters2 JointParameters { axis 0 1 0 }",
        f"jointParameters2 JointParameters {{ axis {axis} position {position} }} "
        f'device2 [ PositionSensor {{ name "{side}_front_sensor" }} Brake {{ name "{side}_front_brake" }} ]')


def test_a_propulsion_cars_free_front_wheels_roll_from_their_world_file_angles(tmp_path: Path) -> None:
    # the left one's axis is the car's right: rolling forward reads decreasing
    w = load_world(write(tmp_path, car(free_front("right", -T / 2, 0.7) + free_front("left", T / 2, 0.0, "0 -1 0"))))
    assert w.world.robots[0].ackermann_drive is not None
    assert not [x for x in w.warnings if "without a motor" in x], w.warnings
    sensors = {d.name: (d.free_wheel, d.free_wheel_sign, d.position) for d in w.world.robots[0].devices
               if d.device == "PositionSensor" and d.motor is None}
    assert sensors == {"right_front_sensor": ("right_front", 1, 0.7), "left_front_sensor": ("left_front", -1, 0.0)}
    sim = Simulation(w)
    r = sim.robot("car")
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(10.0)
    right, left = r.device("right_front_sensor"), r.device("left_front_sensor")
    right.enable(16)
    left.enable(16)
    n = 20
    sim.run(n)
    travel = R * 10.0 * n * 0.016                    # straight: v t, each free wheel turned by v t / r
    assert r.pose.translation[0] == pytest.approx(travel, rel=1e-12)
    assert (right.value, left.value) == pytest.approx((0.7 + travel / R, -travel / R), rel=1e-12)


def test_a_traction_cars_free_rear_wheels_roll_with_their_own_track_and_radius(tmp_path: Path) -> None:
    def free_rear(side: str, y: float) -> str:          # no motor: an encoder and a brake (Webots' Car)
        wheel = (f'Solid {{ translation 0 {y} 0.4 rotation 1 0 0 1.5708 children [ DEF W Shape {{ geometry '
                 f'Cylinder {{ radius 0.4 height 0.2 }} }} ] boundingObject USE W }}')
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.4 }} '
                f'device [ PositionSensor {{ name "{side}_rear_sensor" }} Brake {{ name "{side}_rear_brake" }} ] '
                f'endPoint {wheel} }}\n')

    def driven_front(side: str, y: float) -> str:
        return hinge2_front(side, y).replace(
            "jointParameters2 JointParameters { axis 0 1 0 }",
            "jointParameters2 JointParameters { axis 0 1 0 } "
            f'device2 [ RotationalMotor {{ name "{side}_front_wheel" maxVelocity 80 }} ]')
    track = 1.6
    w = load_world(write(tmp_path, car(driven_front("right", -T / 2) + driven_front("left", T / 2),
                                       free_rear("right", -track / 2) + free_rear("left", track / 2))))
    assert not [x for x in w.warnings if "without a motor" in x or "drive" in x], w.warnings
    d = w.world.robots[0].ackermann_drive
    assert d is not None and d.type == "traction"
    assert (d.track_rear, d.rear_wheel_radius, d.front_wheel_radius) == (pytest.approx(track), 0.4, R)
    sim = Simulation(w)
    r = sim.robot("car")
    delta = 0.25
    right_angle, left_angle = ackermann_angles(delta, L, T)
    r.motor("right_steer").set_position(right_angle)
    r.motor("left_steer").set_position(left_angle)
    sim.run(10)
    rs, ls = r.device("right_rear_sensor"), r.device("left_rear_sensor")
    rs.enable(16)
    ls.enable(16)
    for name in ("right_front_wheel", "left_front_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(20.0)
    sim.run(1)
    start, before = r.pose.translation.copy(), (rs.value, ls.value)
    sim.run(200)
    radius = L / math.tan(delta)            # the rear axle's centre's circle; each rear wheel's its own
    phi = 2.0 * math.asin(math.hypot(*(r.pose.translation[:2] - start[:2])) / (2.0 * radius))
    assert rs.value - before[0] == pytest.approx((radius - track / 2) * phi / 0.4, rel=1e-9)
    assert ls.value - before[1] == pytest.approx((radius + track / 2) * phi / 0.4, rel=1e-9)


def test_an_unmotorised_axis_on_no_car_keeps_its_line(tmp_path: Path) -> None:
    # a free axis on a robot that is no car (one Hinge2Joint alone): still, and said, as before
    w = load_world(write(tmp_path, car(free_front("right", -T / 2, 0.7), rear="")))
    said = [x for x in w.warnings if "Hinge2Joint axis without a motor" in x]
    assert len(said) == 1 and "and keeps it (nothing turns it here)" in said[0] and "(0.7)" in said[0]


@pytest.mark.parametrize("letter, engine", [("E", "electric"), ("P", "parallel hybrid"), ("S", "power-split hybrid"),
                                            ("C", "combustion")])
def test_a_webots_cars_custom_data_gives_the_drive_its_engine_type(tmp_path: Path, letter: str, engine: str) -> None:
    # the customData Webots' Car PROTO writes for its vehicle library: geometry, brake, damping, the
    # engineType's letter, the engine's figures, the gear count, the sound's length, the gears, the sound
    data = f"2.6 1.5 1.5 0.35 0.35 700 5 {letter} 250 50000 1000 4500 150 0.1 0 0.25 3000 1000 6 17 -12 10 6.5 4.5 " \
           "3.5 2.75 sounds/engine.wav "
    body = HINGE2_CAR.replace('controller "<extern>"', f'controller "<extern>" customData "{data}"')
    d = load_world(write(tmp_path, body)).world.robots[0].ackermann_drive
    assert d is not None and d.engine_type == engine


def test_custom_data_that_is_no_cars_leaves_the_engine_combustion(tmp_path: Path) -> None:
    body = HINGE2_CAR.replace('controller "<extern>"', 'controller "<extern>" customData "2.6 1.5 E"')
    d = load_world(write(tmp_path, body)).world.robots[0].ackermann_drive
    assert d is not None and d.engine_type == "combustion"


def test_free_wheels_in_turned_joint_frames_and_slots_as_webots_cars_hold_them(tmp_path: Path) -> None:
    # Webots' AckermannVehicle layout, a traction car: each joint in a Transform turned about z, its
    # wheel (a Solid with no translation) in nested Slots; the rear HingeJoints have an encoder and a
    # brake, no motor; the front Hinge2Joints' second axes drive
    wheel = ('Slot { endPoint Slot { endPoint Solid { children [ DEF S Shape { geometry Cylinder { radius 0.4 '
             'height 0.2 } } ] boundingObject USE S } } }')

    def front(side: str, y: float, turn: float, axis2: str) -> str:
        return (f'Transform {{ translation {L} {y} 0 rotation 0 0 1 {turn} children [ Hinge2Joint {{ '
                f'jointParameters HingeJointParameters {{ axis 0 0 -1 }} jointParameters2 JointParameters {{ axis {axis2} }} '
                f'device [ RotationalMotor {{ name "{side}_steer" minPosition -0.5 maxPosition 0.5 }} '
                f'PositionSensor {{ name "{side}_steer_sensor" }} ] '
                f'device2 [ RotationalMotor {{ name "{side}_front_wheel" }} PositionSensor {{ name "{side}_front_sensor" }} ] '
                f'endPoint {wheel} }} ] }}\n')

    def rear(side: str, y: float, turn: float, axis: str) -> str:
        return (f'Transform {{ translation 0 {y} 0 rotation 0 0 1 {turn} children [ HingeJoint {{ '
                f'jointParameters HingeJointParameters {{ axis {axis} position 0.25 }} '
                f'device [ PositionSensor {{ name "{side}_rear_sensor" }} Brake {{ name "{side}_rear_brake" }} ] '
                f'endPoint {wheel} }} ] }}\n')
    track = 1.7
    body = car(front("left", T / 2, -1.5708, "-1 0 0") + front("right", -T / 2, 1.5708, "1 0 0"),
               rear("left", track / 2, -1.5708, "-1 0 0") + rear("right", -track / 2, 1.5708, "1 0 0"))
    w = load_world(write(tmp_path, body))
    assert not [x for x in w.warnings if "without a motor" in x or "drive" in x], w.warnings
    d = w.world.robots[0].ackermann_drive
    assert d is not None and d.type == "traction"
    assert d.track_rear == pytest.approx(track) and d.rear_wheel_radius == 0.4
    sensors = {d.name: (d.free_wheel, d.free_wheel_sign, d.position) for d in w.world.robots[0].devices
               if d.device == "PositionSensor" and d.motor is None}
    assert sensors == {"left_rear_sensor": ("left_rear", 1, 0.25), "right_rear_sensor": ("right_rear", 1, 0.25)}
    sim = Simulation(w)
    r = sim.robot("car")
    sensor = r.device("left_rear_sensor")
    sensor.enable(16)
    for name in ("right_front_wheel", "left_front_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(5.0)
    sim.run(100)
    travel = 0.4 * 5.0 * 100 * 0.016                # straight: the front wheels' v t; the rear ones turn v t / r
    assert r.pose.translation[0] == pytest.approx(travel, rel=1e-12)
    assert sensor.value == pytest.approx(0.25 + travel / 0.4, rel=1e-12)


def test_a_car_with_a_spinning_lidar_on_its_roof_keeps_its_ackermann_drive(tmp_path: Path) -> None:
    """A third vertical hinge on the roof spinning a cylinder about its own axis steers no wheel: the
    car keeps its drive (before: 'no Ackermann drive (... 3 steering motor(s) ...)')."""
    lidar = ('HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 anchor 1.3 0 1.0 } device [ '
             'RotationalMotor { name "lidar spin" } ] endPoint Solid { translation 1.3 0 1.0 children [ Shape { '
             'geometry Cylinder { radius 0.1 height 0.1 } } ] } }\n')
    w = load_world(write(tmp_path, car(hinge2_front("right", -T / 2) + hinge2_front("left", T / 2) + lidar)))
    (robot,) = w.world.robots
    assert robot.ackermann_drive is not None and robot.ackermann_drive.wheelbase == pytest.approx(L, abs=1e-12)
    assert [x.split(": ", 1)[1] for x in w.warnings] == [
        "HingeJoint motor 'lidar spin' is no wheel and steers none (it spins its round part in place about its own "
        "axis): its joint moves kinematically (Webots' rule without physics; its PositionSensor reads it), and the "
        "shapes and devices past the joint with it"]
