"""A wheeled robot whose wheels' centre is not under its origin drives, turning about that centre as
Webots' physics turns it (a Parallax Boe-Bot: its axle is 2.5 cm ahead of its origin, its wheels
0.9 mm off-centre). The drive was refused before ("the axle midpoint is ... not under the robot's
origin"): the robot stood still where Webots drives it. Our own worlds; closed-form poses."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.summary import drive_line
from sensorium.server.world.loader import load_world

R = 0.03                                   # wheel radius
CX, YL, YR = 0.025, 0.047, -0.046          # the axle 2.5 cm ahead of the origin, the wheels not symmetric
CY, TRACK = (YL + YR) / 2.0, YL - YR


def wheel(name: str, x: float, y: float) -> str:
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor {x} 0 {R} }}\n'
            f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} ]\n'
            f'  endPoint Solid {{ translation {x} {y} {R} children [ DEF W Pose {{ rotation 1 0 0 1.5708 children [\n'
            f'    Shape {{ geometry Cylinder {{ radius {R} height 0.005 }} }} ] }} ] boundingObject USE W }} }}\n')


def write(tmp_path: Path, wheels: str, place: str = "") -> Path:
    p = tmp_path / "offset.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 10 }\n'
                 f'Robot {{ name "bot" {place} children [\n  DEF BODY Shape {{ geometry Box {{ size 0.1 0.08 0.04 }} }}\n'
                 + wheels + '] boundingObject USE BODY }\n')
    return p


def two_wheels() -> str:
    return wheel("left wheel motor", CX, YL) + wheel("right wheel motor", CX, YR)


def drive(sim: Simulation, speeds: dict[str, float], seconds: float) -> None:
    r = sim.robot("bot")
    for name, w in speeds.items():
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)
    sim.run(int(round(seconds * 100)))          # basic steps of 10 ms


def test_the_drive_turns_about_the_wheels_centre(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, two_wheels()))
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    dd = w.world.robots[0].differential_drive
    assert dd is not None
    assert dd.axle_center == pytest.approx((CX, CY), abs=1e-15)
    assert dd.axle_length == pytest.approx(TRACK, abs=1e-15)
    assert (dd.left_motor, dd.right_motor, dd.wheel_radius) == ("left wheel motor", "right wheel motor", R)
    assert drive_line(w.world.robots[0]).endswith(f"{TRACK:g} m apart, turning about ({CX:g}, {CY:g}) m from its origin")

    # turning in place: the wheels' centre stays where it was, the origin circles it at |c|
    sim = Simulation(w)
    drive(sim, {"left wheel motor": -2.0, "right wheel motor": 2.0}, 1.0)
    theta = R * 4.0 / TRACK * 1.0                              # r (wr - wl) / L over 1 s
    c, s = math.cos(theta), math.sin(theta)
    origin = np.array([CX - (c * CX - s * CY), CY - (s * CX + c * CY)])
    pose = sim.robot("bot").pose
    assert pose.translation[:2] == pytest.approx(origin, abs=1e-12)
    assert math.atan2(pose.rotation[1, 0], pose.rotation[0, 0]) == pytest.approx(theta, abs=1e-12)
    centre = pose.translation[:2] + pose.rotation[:2, :2] @ np.array([CX, CY])
    assert centre == pytest.approx([CX, CY], abs=1e-12)

    # straight on: the origin moves as the wheels roll, 2 rad/s on 0.03 m wheels for 1 s
    sim = Simulation(w)
    drive(sim, {"left wheel motor": 2.0, "right wheel motor": 2.0}, 1.0)
    assert sim.robot("bot").pose.translation[:2] == pytest.approx([0.06, 0.0], abs=1e-12)


def test_an_arc_keeps_the_centre_on_its_circle_from_any_start(tmp_path: Path) -> None:
    # placed turned by 0.7 at (0.3, -0.2): the wheels' centre follows the arc of radius v/w
    yaw0, x0, y0 = 0.7, 0.3, -0.2
    w = load_world(write(tmp_path, two_wheels(), f"translation {x0} {y0} 0 rotation 0 0 1 {yaw0}"))
    sim = Simulation(w)
    wl, wr = 1.0, 3.0
    drive(sim, {"left wheel motor": wl, "right wheel motor": wr}, 2.0)
    v, om = R * (wl + wr) / 2.0, R * (wr - wl) / TRACK
    c0, s0 = math.cos(yaw0), math.sin(yaw0)
    m0 = np.array([x0 + c0 * CX - s0 * CY, y0 + s0 * CX + c0 * CY])    # the centre at the start
    yaw = yaw0 + om * 2.0
    m = m0 + v / om * np.array([math.sin(yaw) - math.sin(yaw0), math.cos(yaw0) - math.cos(yaw)])
    pose = sim.robot("bot").pose
    centre = pose.translation[:2] + pose.rotation[:2, :2] @ np.array([CX, CY])
    assert centre == pytest.approx(m, abs=1e-12)
    assert math.atan2(pose.rotation[1, 0], pose.rotation[0, 0]) == pytest.approx(yaw, abs=1e-12)


def test_a_skid_steer_robot_off_its_origin_drives_too(tmp_path: Path) -> None:
    wheels = "".join(wheel(n, x, y) for n, x, y in (("front left", 0.13, 0.1), ("front right", 0.13, -0.1),
                                                   ("rear left", -0.07, 0.1), ("rear right", -0.07, -0.1)))
    w = load_world(write(tmp_path, wheels))
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.skid_steer is not None
    assert dd.axle_center == pytest.approx((0.03, 0.0), abs=1e-15) and dd.axle_length == pytest.approx(0.2)
    sim = Simulation(w)
    drive(sim, {"front left": -1.0, "rear left": -1.0, "front right": 1.0, "rear right": 1.0}, 0.5)
    theta = R * 2.0 / 0.2 * 0.5
    pose = sim.robot("bot").pose
    assert pose.translation[:2] == pytest.approx([0.03 - 0.03 * math.cos(theta), -0.03 * math.sin(theta)], abs=1e-12)


def test_a_centred_drive_leaves_the_field_out_and_the_batched_simulation_drives_an_offset_one(tmp_path: Path) -> None:
    """The batched simulation refused an offset drive; now each copy (its own wheel speeds: a turn in
    place, an arc, a straight line) ends where its Simulation does, the same bits
    (tests/test_batched_omni.py has the closed forms and contact)."""
    centred = load_world(write(tmp_path, wheel("left wheel motor", 0, 0.05) + wheel("right wheel motor", 0, -0.05)))
    assert centred.world.robots[0].differential_drive.axle_center == (0.0, 0.0)
    assert "axle_center" not in centred.world.robots[0].differential_drive.model_dump(exclude_defaults=True)
    offset = load_world(write(tmp_path, two_wheels(), "translation 0.2 -0.1 0 rotation 0 0 1 0.4"))
    plans = [(-3.0, 3.0), (2.0, 5.0), (4.0, 4.0)]
    batched = BatchedSimulation(offset.world, len(plans))
    batched.set_wheels(0, [p[0] for p in plans], [p[1] for p in plans])
    batched.run(80)
    for c, (wl, wr) in enumerate(plans):
        sim = Simulation(offset)
        drive(sim, {"left wheel motor": wl, "right wheel motor": wr}, 0.8)
        pose = sim.robot("bot").pose
        assert pose.translation.tobytes() == batched.pos[c, 0].tobytes(), c
        assert pose.rotation.tobytes() == batched.rot[c, 0].tobytes(), c
    # the turn in place kept the wheels' centre: the origin moved about it
    centre = batched.pos[0, 0, :2] + batched.rot[0, 0, :2, :2] @ [CX, CY]
    start = np.array([0.2, -0.1]) + np.array([[math.cos(0.4), -math.sin(0.4)], [math.sin(0.4), math.cos(0.4)]]) @ [CX, CY]
    assert centre == pytest.approx(start, abs=1e-12)


def test_the_world_format_takes_an_axle_center() -> None:
    dd = wm.DifferentialDrive(axle_center=(0.025, 0.0))
    assert dd.axle_center == (0.025, 0.0)
    with pytest.raises(ValueError):
        wm.DifferentialDrive(axle_center=(math.nan, 0.0))
