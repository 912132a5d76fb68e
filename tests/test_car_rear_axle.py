"""Car-like robots whose origin is not the centre of their rear axle (``rear_axle_offset``): the
rear axle's centre follows the bicycle model's arc and the origin, rigidly behind or ahead of it,
its own circle about the same turn centre (radius √(R² + a²)), its heading changing as the axle's.

Our own .wbt robot shaped like Webots' ``four_wheels`` how-to's ``ackerman`` (a box body, its origin
at the body's centre; rear wheels at (±0.13, -0.15), steering hinges about +z at (±0.13, 0.15) each
carrying a motorised front wheel, every wheel of radius 0.08 on a hinge about -x, so it drives along
its +y) keeps its drive; a YAML car with an offset, and the batched copies bit for bit. Closed-form
checks."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world
from tests.test_wbt_forward_axis import step_alike

R_W, HX, HY = 0.08, 0.13, 0.15          # wheel radius; half track (along x) and half wheelbase (along y)
WHEELS = ("right_front_wheel", "left_front_wheel", "right_rear_wheel", "left_rear_wheel")


def rolling(name: str, x: float, y: float, anchored: bool = True) -> str:
    """A motorised wheel on a hinge about -x at (x, y) (``anchored``: the hinge's anchor given; a
    wheel carried by a steering hinge sits at its end point's origin, as the how-to's do)."""
    anchor = f" anchor {x} {y} 0" if anchored else ""
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis -1 0 0{anchor} }}\n'
            f'  device [ RotationalMotor {{ name "{name}" }} ]\n'
            f'  endPoint Solid {{ translation {x if anchored else 0} {y if anchored else 0} 0 children [\n'
            f'    DEF TYRE Pose {{ rotation 0 1 0 1.5708 children [ Shape {{ geometry Cylinder {{ radius {R_W} '
            f'height 0.04 }} }} ] }} ] boundingObject USE TYRE }} }}\n')


def steering(side: str, x: float) -> str:
    """A steering hinge about +z (positive steers left) at the front, carrying its motorised wheel."""
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 0 1 anchor {x} {HY} 0 }}\n'
            f'  device [ RotationalMotor {{ name "{side}_steer" minPosition -0.7 maxPosition 0.7 }} ]\n'
            f'  endPoint Solid {{ translation {x} {HY} 0 children [\n'
            f'    {rolling(f"{side}_front_wheel", 0.0, 0.0, anchored=False)} ]\n'
            f'    boundingObject Sphere {{ radius 0.01 }} }} }}\n')


def ackerman(place: str) -> str:
    return (f'Robot {{ name "ackerman" {place} children [\n'
            '  DEF BODY Shape { geometry Box { size 0.2 0.4 0.1 } }\n'
            + rolling("right_rear_wheel", HX, -HY) + rolling("left_rear_wheel", -HX, -HY)
            + steering("right", HX) + steering("left", -HX)
            + '] boundingObject USE BODY }\n')


def write(tmp_path: Path, place: str = "translation -0.5 0.2 0.1 rotation 0 0 1 0.4") -> Path:
    p = tmp_path / "ackerman.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n" + ackerman(place))
    return p


def left_turn_positions(delta: float, wheelbase: float, track: float) -> tuple[float, float]:
    """(right, left) steering positions for a left turn of bicycle angle ``delta`` with Ackermann
    angles: the outer (right) wheel cot δ + t/2L, the inner (left) cot δ - t/2L."""
    cot, half = 1.0 / math.tan(delta), track / (2.0 * wheelbase)
    return math.atan(1.0 / (cot + half)), math.atan(1.0 / (cot - half))


def heading(rot: np.ndarray, forward: tuple[float, float]) -> float:
    f = rot @ np.array([forward[0], forward[1], 0.0])
    return math.atan2(f[1], f[0])


def test_the_how_to_shaped_robot_keeps_its_drive_with_its_rear_axle_behind_the_origin(tmp_path: Path) -> None:
    w = load_world(write(tmp_path))
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    (robot,) = w.world.robots
    assert robot.ackermann_drive == wm.AckermannDrive(
        wheelbase=2 * HY, track_front=2 * HX, track_rear=2 * HX, front_wheel_radius=R_W, rear_wheel_radius=R_W,
        type="4x4", max_wheel_speed=10.0, max_steering_angle=0.7, max_steering_speed=10.0, positive_steers="left",
        forward=(0.0, 1.0), rear_axle_offset=-HY)


def go(sim: Simulation, right: float, left: float, omega: float) -> None:
    r = sim.robot("ackerman")
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    for name in WHEELS:
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(omega)


def test_it_drives_straight_along_its_y_at_wheel_radius_times_speed(tmp_path: Path) -> None:
    sim = Simulation(load_world(write(tmp_path)))
    go(sim, 0.0, 0.0, 6.0)
    n = 100
    sim.run(n)
    p = sim.robot("ackerman").pose
    d = R_W * 6.0 * n * 0.016
    fwd = (-math.sin(0.4), math.cos(0.4))           # its +y, turned by 0.4 about z
    assert p.translation.tolist() == pytest.approx([-0.5 + d * fwd[0], 0.2 + d * fwd[1], 0.1], abs=1e-12)
    assert heading(p.rotation, (0.0, 1.0)) == pytest.approx(0.4 + math.pi / 2, abs=1e-12)


def test_it_turns_on_the_closed_form_circle_and_the_copies_match_bit_for_bit(tmp_path: Path) -> None:
    w = load_world(write(tmp_path))
    sim, bs = Simulation(w), BatchedSimulation(w.world, 2)
    assert bs.cars is not None
    L, T, a, delta, omega = 2 * HY, 2 * HX, -HY, 0.35, 7.0
    right, left = left_turn_positions(delta, L, T)
    go(sim, right, left, 0.0)
    bs.cars.command(0, right, left, 0.0)
    step_alike(sim, bs, "ackerman", 20, compare=False)   # the steering turns there; the car stands
    r = sim.robot("ackerman")
    assert r.pose.translation.tolist() == [-0.5, 0.2, 0.1]
    assert (r.motor("right_steer").position, r.motor("left_steer").position) == (right, left)
    go(sim, right, left, omega)
    bs.cars.command(0, right, left, omega)
    n = 250
    step_alike(sim, bs, "ackerman", n)
    # the rear axle's centre circles the turn centre at R = L / tan δ on its left; each wheel rolls at
    # its distance from the centre over R times the axle's speed v, so four wheels at ω give v
    R = L / math.tan(delta)
    dists = [R - T / 2, R + T / 2, math.hypot(L, R - T / 2), math.hypot(L, R + T / 2)]
    v = 4 * R_W * omega * R / sum(dists)
    phi = v * n * 0.016 / R
    yaw0 = 0.4 + math.pi / 2                         # its forward (+y) in the world
    f0, l0 = np.array([math.cos(yaw0), math.sin(yaw0)]), np.array([-math.sin(yaw0), math.cos(yaw0)])
    o0 = np.array([-0.5, 0.2])
    centre = o0 + a * f0 + R * l0
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    expect = centre + rot @ (o0 - centre)
    p = r.pose
    assert p.translation[:2].tolist() == pytest.approx(expect.tolist(), abs=1e-9)
    assert math.dist(p.translation[:2], centre) == pytest.approx(math.hypot(R, a), abs=1e-9)
    assert heading(p.rotation, (0.0, 1.0)) == pytest.approx(math.remainder(yaw0 + phi, 2 * math.pi), abs=1e-9)
    assert phi > 2.0                                 # it went a good part of the way round


DRIVE = {"wheelbase": 2.0, "track_front": 1.4, "track_rear": 1.5, "front_wheel_radius": 0.3,
         "rear_wheel_radius": 0.35, "max_wheel_speed": 1000.0}


def yaml_car(offset: float | None, yaw: float = -1.1) -> wm.World:
    drive = dict(DRIVE) if offset is None else {**DRIVE, "rear_axle_offset": offset}
    return parse_world({"world_info": {"basic_time_step": 16}, "robots": [
        {"name": "car", "pose": {"translation": [1.0, -2.0, 0.3], "rotation": [0, 0, 1, yaw]},
         "body": {"geometry": {"type": "box", "size": [3.0, 1.6, 0.5]}}, "ackermann_drive": drive}]})


def steer_and_roll(sim: Simulation, right: float, left: float, wheel: float) -> None:
    r = sim.robot("car")
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(wheel)


@pytest.mark.parametrize("a", [-1.2, 0.8])
def test_a_yaml_car_with_an_offset_circles_about_its_rear_axles_turn_centre(a: float) -> None:
    """Its origin 1.2 m behind (or 0.8 m ahead of) the rear axle's centre, turning right (positive
    steering, Webots' Driver): on radius √(R² + a²) about the centre R to the axle's right; its
    velocity (Webots' getVelocity) the origin's on that circle."""
    w = yaml_car(a)
    sim, bs = Simulation(w), BatchedSimulation(w, copies=3)
    assert bs.cars is not None
    L, T, delta, wheel = 2.0, 1.4, 0.3, 9.0
    cot, half = 1.0 / math.tan(delta), T / (2.0 * L)
    right, left = math.atan(1.0 / (cot - half)), math.atan(1.0 / (cot + half))   # inner right, outer left
    steer_and_roll(sim, right, left, 0.0)
    bs.cars.command(0, right, left, 0.0)
    step_alike(sim, bs, "car", 10, compare=False)
    steer_and_roll(sim, right, left, wheel)
    bs.cars.command(0, right, left, wheel)
    n = 300
    step_alike(sim, bs, "car", n)
    R = L / math.tan(delta)
    # the rear wheels at (0, ±tr/2) from the axle's centre roll at (R ± tr/2)/R of its speed v
    v = 2 * 0.35 * wheel * R / ((R - 0.75) + (R + 0.75))
    phi = v * n * 0.016 / R                          # clockwise
    yaw0 = -1.1
    f0, right0 = np.array([math.cos(yaw0), math.sin(yaw0)]), np.array([math.sin(yaw0), -math.cos(yaw0)])
    o0 = np.array([1.0, -2.0])
    centre = o0 + a * f0 + R * right0
    rot = np.array([[math.cos(-phi), -math.sin(-phi)], [math.sin(-phi), math.cos(-phi)]])
    p = sim.robot("car").pose
    assert p.translation[:2].tolist() == pytest.approx((centre + rot @ (o0 - centre)).tolist(), abs=1e-9)
    assert math.dist(p.translation[:2], centre) == pytest.approx(math.hypot(R, a), abs=1e-9)
    assert math.atan2(p.rotation[1, 0], p.rotation[0, 0]) == pytest.approx(
        math.remainder(yaw0 - phi, 2 * math.pi), abs=1e-9)
    drive = sim.robot("car").drive
    assert drive is not None
    vel = drive.velocity()
    w_z = -v / R
    radial = p.translation[:2] - centre               # the origin's velocity: ω × (origin - centre)
    assert vel[:2] == pytest.approx([-w_z * radial[1], w_z * radial[0]], abs=1e-9)
    assert vel[5] == pytest.approx(w_z, abs=1e-12)
    assert math.hypot(vel[0], vel[1]) == pytest.approx(abs(w_z) * math.hypot(R, a), abs=1e-9)


def test_offset_zero_is_the_car_as_it_always_was_bit_for_bit() -> None:
    """``rear_axle_offset: 0`` given is the default: the same poses, bit for bit."""
    sims = [Simulation(yaml_car(None)), Simulation(yaml_car(0.0))]
    for s in sims:
        steer_and_roll(s, 0.2, 0.18, 11.0)
    for _ in range(120):
        for s in sims:
            s.step()
        assert sims[0].robot("car").pose.translation.tobytes() == sims[1].robot("car").pose.translation.tobytes()
        assert sims[0].robot("car").pose.rotation.tobytes() == sims[1].robot("car").pose.rotation.tobytes()
