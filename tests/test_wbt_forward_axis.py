"""Vehicles whose wheels turn about another horizontal axis than their +y keep their drive: Webots'
``four_wheels`` how-to turns its wheels about -x, so a positive wheel speed rolls it along its +y
(a wheel's centre moves at ω·r·(axis × up)). The worlds here are our own, shaped like that how-to:
a box body, four wheels at (±0.13, ±0.15) of radius 0.08 on hinges about -x; and a car built along its
y the same way (the Ackermann drive). Closed-form checks, the batched copies bit for bit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

R, HX, HY = 0.08, 0.13, 0.15          # wheel radius; the wheels' half track (along x) and half wheelbase (along y)
WHEELS = {"front_right_wheel": (HX, HY), "front_left_wheel": (-HX, HY),
          "rear_right_wheel": (HX, -HY), "rear_left_wheel": (-HX, -HY)}


def wheel(name: str, x: float, y: float, axis: str) -> str:
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {x} {y} 0 }}\n'
            f'  device [ RotationalMotor {{ name "{name}" maxVelocity 9 }} PositionSensor {{ name "{name} sensor" }} ]\n'
            f'  endPoint Solid {{ translation {x} {y} 0 children [ DEF TYRE Pose {{ rotation 0 1 0 1.5708 children [\n'
            f'    Shape {{ geometry Cylinder {{ radius {R} height 0.04 }} }} ] }} ] boundingObject USE TYRE }} }}\n')


def rover(name: str = "rover", place: str = "translation 0 0 0.08", axis: str = "-1 0 0", wheels: dict | None = None,
          extra: str = "") -> str:
    """Our four-wheel rover: the body longer along y, as the how-to's; ``axis`` every wheel's."""
    parts = "".join(wheel(n, x, y, axis) for n, (x, y) in (wheels or WHEELS).items())
    return (f'Robot {{ name "{name}" {place} children [\n'
            '  DEF BODY Shape { geometry Box { size 0.2 0.4 0.05 } }\n' + parts + extra
            + '] boundingObject USE BODY }\n')


def write(tmp_path: Path, *robots: str) -> Path:
    p = tmp_path / "rover.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n" + "".join(robots))
    return p


def go(sim: Simulation, robot: str, left: float, right: float) -> None:
    r = sim.robot(robot)
    for name in WHEELS:
        m = r.motor(name)
        m.set_position(math.inf)
        m.set_velocity(left if "left" in name else right)



def step_alike(sim: Simulation, bs: BatchedSimulation, robot: str, steps: int, compare: bool = True) -> None:
    """``steps`` basic steps of a single simulation and a batched one; with ``compare``, after each
    step every copy's robot of slot 0 is at the single ``robot``'s pose, bit for bit."""
    for _ in range(steps):
        sim.step()
        bs.step()
        if compare:
            pose = sim.robot(robot).pose
            for c in range(bs.copies):
                assert bs.pose(c, 0).translation.tobytes() == pose.translation.tobytes()
                assert bs.pose(c, 0).rotation.tobytes() == pose.rotation.tobytes()

def test_wheels_about_minus_x_make_a_drive_forward_along_y(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, rover(place="translation 0 0 0.08")))
    assert w.warnings == []
    (robot,) = w.world.robots
    # left = up × forward = -x: the wheels at x < 0 are the left side, as the how-to names them
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=R, axle_length=2 * HX, max_wheel_speed=9.0, left_motor="front_left_wheel",
        right_motor="front_right_wheel", forward=(0.0, 1.0),
        skid_steer=wm.SkidSteer(left=["rear_left_wheel"], right=["rear_right_wheel"]))
    assert [d.motor for d in robot.devices if d.device == "PositionSensor"] == list(WHEELS)


def test_it_drives_along_y_at_wheel_radius_times_speed_and_turns_left_when_its_right_wheels_are_faster(
        tmp_path: Path) -> None:
    sim = Simulation(load_world(write(tmp_path, rover(place="translation 0.5 -0.25 0.08"))), "fast")
    r = sim.robot("rover")
    for name in WHEELS:
        r.device(f"{name} sensor").enable(16)
    go(sim, "rover", 2.0, 2.0)
    sim.run(125)                                  # 2 s at 2 rad/s on 0.08 m wheels: 0.32 m along +y
    assert r.pose.translation == pytest.approx([0.5, -0.25 + 0.32, 0.08], abs=1e-12)
    assert r.pose.rotation == pytest.approx(np.eye(3), abs=1e-12)      # it does not turn: still its placed rotation
    assert [r.device(f"{n} sensor").value for n in WHEELS] == pytest.approx([4.0] * 4, abs=1e-12)
    assert sim.robot("rover").drive.velocity()[:3] == pytest.approx([0.0, 2.0 * R, 0.0], abs=1e-12)
    # left 1, right 3 rad/s: v = R·2, ω = R·2/(2·HX) counter-clockwise (to its left, -x), about the
    # point at v/ω = HX on its left: (0.5 - HX, 0.07)
    go(sim, "rover", 1.0, 3.0)
    sim.run(250)                                  # 4 s
    v, om, t = 2.0 * R, 2.0 * R / (2 * HX), 4.0
    cx, cy = 0.5 - v / om, -0.25 + 0.32
    heading = math.pi / 2 + om * t
    assert r.pose.translation[:2] == pytest.approx([cx + v / om * math.cos(heading - math.pi / 2),
                                                    cy + v / om * math.sin(heading - math.pi / 2)], abs=1e-9)
    c, s = math.cos(om * t), math.sin(om * t)     # its own rotation turned by ω·t about up
    assert r.pose.rotation == pytest.approx(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), abs=1e-9)
    assert r.device("front_left_wheel sensor").value == pytest.approx(4.0 + 4.0, abs=1e-12)
    assert r.device("rear_right_wheel sensor").value == pytest.approx(4.0 + 12.0, abs=1e-12)


def test_it_stops_at_a_wall_ahead_along_its_y(tmp_path: Path) -> None:
    wall = ('Solid { translation 0 1 0.1 children [ DEF WALL Shape { geometry Box { size 2 0.1 0.2 } } ] '
            'boundingObject USE WALL }\n')
    sim = Simulation(load_world(write(tmp_path, rover(), wall)), "fast")
    go(sim, "rover", 6.0, 6.0)
    sim.run(250)                                  # 4 s at 0.48 m/s: far beyond the wall, were it not there
    # the footprint's front along its y (contact.py: the body's outline, turned with the drive's
    # heading): the body box's face or a wheel's outline, R ahead of its axle (its circumscribed
    # 16-gon's edge faces ahead)
    front = max(0.2, HY + R)
    assert sim.robot("rover").pose.translation[:2] == pytest.approx([0.0, 0.95 - front], abs=1e-9)
    assert sim.counters["contacts"] > 0


def test_two_wheels_about_plus_x_on_a_turned_robot_drive_along_its_minus_y(tmp_path: Path) -> None:
    """Axis +x: forward is +x × z = -y in the robot's frame; the robot turned by 0.5 rad about up
    drives toward the world's heading 0.5 - π/2."""
    two = {"right": (-HX, 0.0), "left": (HX, 0.0)}
    p = write(tmp_path, rover(place="translation 1 2 0.08 rotation 0 0 1 0.5", axis="1 0 0", wheels=two))
    w = load_world(p)
    assert w.warnings == []
    d = w.world.robots[0].differential_drive
    assert d is not None and (d.left_motor, d.right_motor, d.forward, d.axle_length) == ("left", "right", (0.0, -1.0),
                                                                                          2 * HX)
    sim = Simulation(w)
    r = sim.robot("rover")
    for name, speed in (("left", 3.0), ("right", 3.0)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(speed)
    start = r.pose.rotation.copy()
    sim.run(100)                                  # 1.6 s at 3 rad/s: 0.384 m
    heading = 0.5 - math.pi / 2
    assert r.pose.translation == pytest.approx([1 + 0.384 * math.cos(heading), 2 + 0.384 * math.sin(heading), 0.08],
                                               abs=1e-12)
    assert r.pose.rotation == pytest.approx(start, abs=1e-12)


def test_the_same_drive_in_a_yaml_world_and_its_checks(tmp_path: Path) -> None:
    base = {"world_info": {"basic_time_step": 16},
            "robots": [{"name": "r", "differential_drive": {"wheel_radius": 0.05, "forward": [0, 2]}}]}
    sim = Simulation(parse_world(base, base_dir=tmp_path))
    r = sim.robot("r")
    for m in ("left wheel motor", "right wheel motor"):
        r.motor(m).set_position(math.inf)
        r.motor(m).set_velocity(2.0)
    sim.run(100)                                  # 1.6 s at 2 rad/s on 0.05 m wheels: 0.16 m along +y
    assert r.pose.translation[:2] == pytest.approx([0.0, 0.16], abs=1e-12)
    bad = {"robots": [{"name": "r", "differential_drive": {"forward": [0, 0]}}]}
    with pytest.raises(WorldError, match=r"robots\[0\] \(r\)\.differential_drive\.forward: forward must not be the zero vector"):
        parse_world(bad, base_dir=tmp_path)


@pytest.mark.parametrize("axes, why", [
    # one wheel of a side mounted mirrored and not the other (a whole side may be: tests/test_wbt_mirrored.py)
    ({"front_left_wheel": "1 0 0"}, "the left side's wheels ['front_left_wheel', 'rear_left_wheel'] turn about "
                                    "opposite axes, ['front_left_wheel'] mounted mirrored and not the others: a "
                                    "skid-steer side's wheels roll as one"),
    # a tilted axis is no wheel the kinematic drive rolls
    ({n: "-1 0 1" for n in WHEELS}, "wheel axis of motor 'front_right_wheel' is [-0.707107, 0.0, 0.707107], neither "
                                    "the robot's +y nor horizontal in its frame"),
])
def test_wheels_it_cannot_drive_get_one_line(tmp_path: Path, axes: dict, why: str) -> None:
    parts = "".join(wheel(n, x, y, axes.get(n, "-1 0 0")) for n, (x, y) in WHEELS.items())
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nRobot { name "r" children [\n' + parts + '] }\n')
    w = load_world(p)
    assert w.world.robots[0].differential_drive is None
    said = [x for x in w.warnings if "no differential drive" in x]
    assert len(said) == 1 and said[0].startswith(f"{p}:2:1: robot 'r': no differential drive ({why}"), w.warnings


def test_a_wheel_line_off_the_origin_is_the_drives_centre_in_its_frame(tmp_path: Path) -> None:
    # the wheels 0.05 m ahead along the robot's +y (the drive's forward): the robot turns about them
    # (tests/test_wbt_axle_center.py has the closed forms of a robot driving along its x)
    shifted = {n: (x, y + 0.05) for n, (x, y) in WHEELS.items()}
    w = load_world(write(tmp_path, rover(wheels=shifted)))
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.forward == (0.0, 1.0)
    assert dd.axle_center == pytest.approx((0.05, 0.0), abs=1e-15)
    sim = Simulation(w)
    go(sim, "rover", -1.0, 1.0)            # in place: the centre (robot y = 0.05) stays where it was
    sim.run(50)
    pose = sim.robot("rover").pose
    assert pose.translation[:2] + pose.rotation[:2, :2] @ np.array([0.0, 0.05]) == pytest.approx([0.0, 0.05], abs=1e-12)
    assert not np.allclose(pose.translation[:2], 0.0)


def test_copies_drive_it_as_the_single_simulation_bit_for_bit(tmp_path: Path) -> None:
    world = load_world(write(tmp_path, rover(place="translation 0.3 0.1 0.08 rotation 0 0 1 -2.2"))).world
    bs = BatchedSimulation(world, 2)
    sims = [Simulation(world), Simulation(world)]
    sensors = [f"{n} sensor" for n in WHEELS]
    for n in sensors:
        bs.enable(bs.device("rover", n), 16)
        for s in sims:
            s.robot("rover").device(n).enable(16)
    slot = bs.slot("rover")
    rng = np.random.default_rng(7)
    for step in range(48):
        if step % 12 == 0:
            lr = rng.uniform(-9.0, 9.0, (2, 2))
            bs.set_wheels(slot, lr[:, 0], lr[:, 1])
            for c, s in enumerate(sims):
                go(s, "rover", float(lr[c, 0]), float(lr[c, 1]))
        bs.step()
        for c, s in enumerate(sims):
            s.step()
            pose = s.robot("rover").pose
            assert pose.translation.tobytes() == bs.pos[c, slot].tobytes(), (step, c)
            assert pose.rotation.tobytes() == bs.rot[c, slot].tobytes(), (step, c)
            for n in sensors:
                assert s.robot("rover").device(n).value == float(bs.value(bs.device("rover", n))[c]), (step, c, n)
    moved = bs.pos[:, slot, :2] - np.array([0.3, 0.1])
    assert (np.hypot(moved[:, 0], moved[:, 1]) > 0.05).all()          # they did drive


# ---------------------------------------------------------------------- a car built along its y

L, T = 0.3, 0.26                     # the car's wheelbase (along its y) and track (along its x)


def steered(side: str, x: float) -> str:
    """A front wheel on a Hinge2Joint: steering about -z (positive steers right, as Webots' cars), its
    spin axis -x (not motorised)."""
    return (f'Hinge2Joint {{ jointParameters HingeJointParameters {{ axis 0 0 -1 anchor {x} {L} 0 }}\n'
            f'  jointParameters2 JointParameters {{ axis -1 0 0 }}\n'
            f'  device [ RotationalMotor {{ name "{side}_steer" minPosition -0.6 maxPosition 0.6 maxVelocity 5 }} ]\n'
            f'  endPoint Solid {{ translation {x} {L} 0 children [ USE TYRE ] boundingObject USE TYRE }} }}\n')


def test_a_car_whose_wheels_turn_about_minus_x_drives_along_y_and_circles_right(tmp_path: Path) -> None:
    rear = {"right_rear_wheel": (T / 2, 0.0), "left_rear_wheel": (-T / 2, 0.0)}
    p = write(tmp_path, rover("car", wheels=rear, extra=steered("right", T / 2) + steered("left", -T / 2)))
    w = load_world(p)
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    (robot,) = w.world.robots
    assert robot.ackermann_drive == wm.AckermannDrive(
        wheelbase=L, track_front=T, track_rear=T, front_wheel_radius=R, rear_wheel_radius=R, type="propulsion",
        max_wheel_speed=9.0, max_steering_angle=0.6, max_steering_speed=5.0, positive_steers="right",
        forward=(0.0, 1.0))
    sims = [Simulation(w), BatchedSimulation(w.world, 2)]
    sim, bs = sims
    r = sim.robot("car")
    from sensorium.client.webots.vehicle.driver import ackermann_angles

    delta = 0.2
    right, left = ackermann_angles(delta, L, T)
    r.motor("right_steer").set_position(right)
    r.motor("left_steer").set_position(left)
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(0.0)
    assert bs.cars is not None
    bs.cars.command(0, right, left, 0.0)
    step_alike(sim, bs, "car", 10, compare=False)    # the steering turns there; the car stands
    assert r.pose.translation.tolist() == [0.0, 0.0, 0.08]
    for name in ("right_rear_wheel", "left_rear_wheel"):
        r.motor(name).set_velocity(8.0)
    bs.cars.command(0, right, left, 8.0)
    n = 300
    step_alike(sim, bs, "car", n)
    # clockwise (to its right, +x) on the circle of radius L / tan δ about (L / tan δ, 0)
    radius = L / math.tan(delta)
    phi = R * 8.0 * n * 0.016 / radius
    assert r.pose.translation[:2] == pytest.approx([radius - radius * math.cos(phi), radius * math.sin(phi)], abs=1e-9)
