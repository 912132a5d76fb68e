"""Omni-wheel robots (``omni_drive``): three wheels 120° apart with passive roller hinges (shaped
like Webots' ``omni_wheels`` how-to) and four wheels turning about four axes at a square's corners
(like the ``four_wheels`` how-to's ``omni_wheels`` robot) drive in every direction in closed form;
the .wbt import finds them, and leaves two-wheel, skid-steer, mecanum and car-like robots alone (their
own tests). The worlds are our own."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

REPO = Path(__file__).resolve().parents[1]
DT = 0.016
R3, L3 = 0.05, 0.1                    # the three-wheeler's wheel radius and the wheels' distance from its centre
THIRD = 2.0 * math.pi / 3.0
HEADER = "#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"


def roller(k: int) -> str:
    """A passive roller hinge on the wheel's rim (the wheel turning about x): at angle k·60° in the
    wheel's y-z plane, its axis across the wheel's, tangent to the rim."""
    t = k * math.pi / 3.0
    y, z = 0.045 * math.cos(t), 0.045 * math.sin(t)
    ay, az = -math.sin(t), math.cos(t)
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 {ay:.12g} {az:.12g} anchor 0 {y:.12g} '
            f'{z:.12g} }} endPoint Solid {{ translation 0 {y:.12g} {z:.12g} name "roller{k}" children [ Shape {{ '
            'geometry Sphere { radius 0.006 } } ] } }\n')


def omni_wheel(i: int, rollers: bool = True) -> str:
    """Wheel i+1 of the three-wheeler: a Solid turned by i·120° about z holding a hinge about -x at
    (-L3, 0, 0), as the how-to builds each wheel."""
    parts = "".join(roller(k) for k in range(6)) if rollers else ""
    return (f'Solid {{ rotation 0 0 1 {i * THIRD!r} name "holder{i + 1}" children [\n'
            f'  HingeJoint {{ jointParameters HingeJointParameters {{ axis -1 0 0 anchor {-L3} 0 0 }}\n'
            f'    device [ RotationalMotor {{ name "wheel{i + 1}" maxVelocity 60 }} '
            f'PositionSensor {{ name "wheel{i + 1} sensor" }} ]\n'
            f'    endPoint Solid {{ translation {-L3} 0 0 children [\n{parts}'
            f'      DEF RIM{i} Pose {{ rotation 0 1 0 1.5707963267948966 children [ Shape {{ geometry Cylinder {{ '
            f'radius {R3} height 0.02 }} }} ] }} ] boundingObject USE RIM{i} }} }} ] }}\n')


def three_wheeler(tmp_path: Path, place: str = "translation 0 0 0.05", rollers: bool = True,
                  extra: str = "") -> Path:
    p = tmp_path / "omni3.wbt"
    p.write_text(HEADER + f'Robot {{ name "omni" {place} children [\n'
                 '  GPS { name "gps" }\n' + "".join(omni_wheel(i, rollers) for i in range(3)) + extra
                 + '] boundingObject Cylinder { radius 0.12 height 0.05 } controller "<extern>" }\n')
    return p


def spin(sim: Simulation, speeds: dict[str, float], name: str = "omni") -> None:
    for motor, omega in speeds.items():
        m = sim.robot(name).motor(motor)
        m.set_position(math.inf)
        m.set_velocity(omega)


def pose2d(sim: Simulation, name: str = "omni") -> tuple[float, float, float]:
    p = sim.robot(name).pose
    return float(p.translation[0]), float(p.translation[1]), math.atan2(p.rotation[1, 0], p.rotation[0, 0])


def three_speeds(vx: float, vy: float, w: float) -> dict[str, float]:
    """The three-wheeler's wheel speeds for a body twist: wheel i at θ_i = π + i·120° (its axis
    pointing out, rolling along (sin θ_i, -cos θ_i)) turns at (sin θ_i·vx − cos θ_i·vy − L·ω)/r."""
    out = {}
    for i in range(3):
        t = math.pi + i * THIRD
        out[f"wheel{i + 1}"] = (math.sin(t) * vx - math.cos(t) * vy - L3 * w) / R3
    return out


# ---------------------------------------------------------------- the .wbt import

def test_three_wheels_with_roller_hinges_are_an_omni_drive(tmp_path: Path) -> None:
    w = load_world(three_wheeler(tmp_path))
    assert w.warnings == []
    (robot,) = w.world.robots
    assert robot.differential_drive is None and robot.mecanum_drive is None
    drive = robot.omni_drive
    assert drive is not None and drive.max_wheel_speed == 60
    for i, wheel in enumerate(drive.wheels):
        t = math.pi + i * THIRD
        assert wheel.motor == f"wheel{i + 1}" and wheel.radius == pytest.approx(R3, abs=1e-15)
        assert wheel.position == pytest.approx((L3 * math.cos(t), L3 * math.sin(t)), abs=1e-12)
        assert wheel.axis == pytest.approx((math.cos(t), math.sin(t)), abs=1e-12)
    assert [d.motor for d in robot.devices if d.device == "PositionSensor"] == ["wheel1", "wheel2", "wheel3"]


def test_wheels_without_rollers_are_taken_as_omni_wheels_with_one_line(tmp_path: Path) -> None:
    p = three_wheeler(tmp_path, rollers=False)
    w = load_world(p)
    assert w.world.robots[0].omni_drive is not None
    lines = [x for x in w.warnings if "omni" in x]
    assert len(lines) == 1 and "\n" not in lines[0] and "show no rollers" in lines[0], w.warnings


def test_sensorium_info_shows_the_omni_drive(tmp_path: Path) -> None:
    p = three_wheeler(tmp_path)
    out = subprocess.run([sys.executable, "-m", "sensorium", "info", str(p)], capture_output=True, text=True,
                         cwd=REPO, env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"}, timeout=120)
    assert out.returncode == 0, out.stderr
    line = next(x for x in out.stdout.splitlines() if "(drive)" in x)
    assert "omni wheels, 3: wheel1 at (-0.1, 0) m about (-1, 0), radius 0.05 m" in line, out.stdout


# ---------------------------------------------------------------- closed-form motion

def test_pure_translation_along_x_and_along_y() -> None:
    for vx, vy in ((0.2, 0.0), (0.0, -0.15)):
        sim = Simulation(load_world_from(three_wheeler_text()))
        spin(sim, three_speeds(vx, vy, 0.0))
        sim.run(100)                                     # 1.6 s
        assert pose2d(sim) == pytest.approx((vx * 1.6, vy * 1.6, 0.0), abs=1e-12)


def test_equal_speeds_turn_it_in_place_clockwise_at_r_omega_over_l() -> None:
    sim = Simulation(load_world_from(three_wheeler_text()))
    spin(sim, {"wheel1": 4.0, "wheel2": 4.0, "wheel3": 4.0})
    enc = sim.device("omni/wheel2 sensor")
    enc.enable(16)
    sim.run(50)                                          # 0.8 s at -r·u/L = -2 rad/s: -1.6 rad
    x, y, yaw = pose2d(sim)
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert yaw == pytest.approx(-1.6, abs=1e-12)
    assert enc.value == pytest.approx(4.0 * 50 * DT, abs=1e-12)     # its own wheel's angle: 4 rad/s for 0.8 s


def test_a_twist_from_a_turned_start_circles_back_to_it() -> None:
    """Body twist (vx, vy, ω) with ω·1.6 s = 2π: the origin runs round a circle of radius |v|/|ω|
    about a centre fixed at p + R(ψ)(−vy/ω, vx/ω), opposite its start after half a turn, back at it
    after a whole one."""
    vx, vy, w = 0.1, 0.05, 2.0 * math.pi / 1.6
    x0, y0, psi = 0.3, -0.2, 0.7
    sim = Simulation(load_world_from(three_wheeler_text(f"translation {x0} {y0} 0.05 rotation 0 0 1 {psi}")))
    spin(sim, three_speeds(vx, vy, w))
    c, s = math.cos(psi), math.sin(psi)
    centre = np.array([x0 + c * (-vy / w) - s * (vx / w), y0 + s * (-vy / w) + c * (vx / w)])
    radius = math.hypot(vx, vy) / w
    for _ in range(10):                                  # 50 steps: half a turn
        sim.run(5)
        x, y, _ = pose2d(sim)
        assert math.hypot(x - centre[0], y - centre[1]) == pytest.approx(radius, abs=1e-12)
    x, y, yaw = pose2d(sim)
    assert (x, y) == pytest.approx(tuple(2 * centre - (x0, y0)), abs=1e-12)
    assert yaw == pytest.approx(psi - math.pi, abs=1e-12)
    sim.run(50)                                          # the other half
    assert pose2d(sim) == pytest.approx((x0, y0, psi), abs=1e-12)


def test_speeds_that_agree_with_no_twist_move_it_by_their_least_squares_fit() -> None:
    """Three wheels always agree with one twist; four need not: the square robot's rear right wheel
    alone at u fits best (pinv(A)·(r·u, 0, 0, 0); AᵀA = diag(2, 2, 8h²) for these wheels) as half its
    roll along its rolling direction d = (−1, −1)/√2 and a turn of its roll · (−√2·h)/(8h²)."""
    sim = Simulation(load_world_from(square_text()))
    spin(sim, {"rear_right_wheel": 5.0}, name="square")
    sim.run(100)
    # rows of A: (d_x, d_y, d · (up × p)) for each wheel, d = a × up
    a = np.array(SQUARE_AXES) / math.sqrt(2)
    rows = np.array([(ay, -ax, ay * -py - ax * px) for (ax, ay), (px, py) in zip(a, SQUARE_PLACES)])
    vx, vy, w = np.linalg.pinv(rows) @ np.array([5.0 * RS, 0, 0, 0])
    assert (vx, vy) == pytest.approx((-RS * 5.0 / 2 / math.sqrt(2), -RS * 5.0 / 2 / math.sqrt(2)), abs=1e-15)
    assert w == pytest.approx(-RS * 5.0 / 4 / (HS * math.sqrt(2)), abs=1e-12)
    x, y, yaw = pose2d(sim, "square")
    half = math.sin(0.5 * w * 1.6)       # twist_step's exact arc over 1.6 s
    ca, cb = math.sin(w * 1.6) / w, 2 * half * half / w
    assert (x, y, yaw) == pytest.approx((ca * vx - cb * vy, cb * vx + ca * vy, w * 1.6), abs=1e-12)


def test_contact_stops_it_at_a_wall_it_slides_into_sideways(tmp_path: Path) -> None:
    wall = ('Solid { translation 0 0.5 0.1 name "wall" children [ DEF WALL Shape { geometry Box { size 2 0.1 0.2 } } ] '
            'boundingObject USE WALL }\n')
    p = tmp_path / "walled.wbt"
    p.write_text(three_wheeler_text().replace(HEADER, HEADER + wall))
    sim = Simulation(load_world(p))
    spin(sim, three_speeds(0.0, 0.3, 0.0))             # to its left (+y) at 0.3 m/s: 0.96 m in 3.2 s unless stopped
    sim.run(200)
    x, y, yaw = pose2d(sim)
    assert (x, yaw) == pytest.approx((0.0, 0.0), abs=1e-12)
    # wheel 3's rim reaches farthest to its left (beyond the body's 0.12): its disc (radius r, 0.02 thick) about
    # the axis (cos 60°, sin 60°) at L·(cos 60°, sin 60°) reaches y = L·sin 60° + r·cos 60° + 0.01·sin 60°
    reach = L3 * math.sin(math.pi / 3) + R3 * 0.5 + 0.01 * math.sin(math.pi / 3)
    assert y == pytest.approx(0.45 - reach, abs=1e-9)
    assert sim.robot("omni").pressing


CONTROLLER = '''
from controller import Robot
robot = Robot()
step = int(robot.getBasicTimeStep())
gps = robot.getDevice("gps")
gps.enable(step)
enc = robot.getDevice("wheel1 sensor")
enc.enable(step)
for name, v in SPEEDS.items():
    m = robot.getDevice(name)
    m.setPosition(float("inf"))
    m.setVelocity(v)
for _ in range(100):
    robot.step(step)
print("gps %.9f %.9f wheel1 %.9f" % tuple(round(v, 9) + 0.0 for v in (*gps.getValues()[:2], enc.getValue())))
'''


@pytest.mark.slow
def test_a_python_controller_drives_it_sideways(tmp_path: Path) -> None:
    from _serve import run_controller, sensorium
    world = three_wheeler(tmp_path)
    speeds = three_speeds(0.0, 0.2, 0.0)
    script = tmp_path / "slide.py"
    script.write_text(CONTROLLER.replace("SPEEDS", repr(speeds)))
    lines, err = run_controller(world, lambda url: sensorium("controller", str(script), "--url", url), robot="omni",
                                cwd=tmp_path)
    # 1.6 s at 0.2 m/s to its left; wheel1 (at θ = π, rolling along (0, 1)) at 0.2/r = 4 rad/s for 1.6 s
    assert speeds["wheel1"] == pytest.approx(4.0, abs=1e-12)
    assert lines[-1:] == ["gps 0.000000000 0.320000000 wheel1 6.400000000"], err


# ---------------------------------------------------------------- the four-wheel robot (four axes)

RS, HS = 0.08, 0.15
SQUARE_PLACES = ((HS, -HS), (-HS, -HS), (HS, HS), (-HS, HS))
SQUARE_AXES = ((1, -1), (-1, -1), (1, 1), (-1, 1))      # each pointing away from the centre
SQUARE_NAMES = ("rear_right_wheel", "rear_left_wheel", "front_right_wheel", "front_left_wheel")


def square_text() -> str:
    parts = []
    for name, (x, y), (ax, ay) in zip(SQUARE_NAMES, SQUARE_PLACES, SQUARE_AXES):
        # the tyre's cylinder (along its z) turned onto the wheel's axis: about (−ay, ax, 0) by 90°
        parts.append(f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {ax} {ay} 0 anchor {x} {y} 0 }}\n'
                     f'  device [ RotationalMotor {{ name "{name}" }} PositionSensor {{ name "{name} sensor" }} ]\n'
                     f'  endPoint Solid {{ translation {x} {y} 0 name "{name}" children [ DEF T{name} Pose {{ rotation '
                     f'{-ay} {ax} 0 1.5707963267948966 children [ Shape {{ geometry Cylinder {{ radius {RS} height '
                     f'0.04 }} }} ] }} ] boundingObject USE T{name} }} }}\n')
    return (HEADER + 'Robot { name "square" translation 0 0 0.08 children [\n'
            '  DEF BODY Shape { geometry Box { size 0.3 0.3 0.1 } }\n' + "".join(parts)
            + '] boundingObject USE BODY controller "<extern>" }\n')


def test_four_wheels_about_four_axes_are_an_omni_drive_and_turn_in_place(tmp_path: Path) -> None:
    p = tmp_path / "square.wbt"
    p.write_text(square_text())
    w = load_world(p)
    drive = w.world.robots[0].omni_drive
    assert drive is not None and [x.motor for x in drive.wheels] == list(SQUARE_NAMES)
    assert [c for x in drive.wheels for c in x.position] == pytest.approx([c for p in SQUARE_PLACES for c in p], abs=1e-12)
    said = [x for x in w.warnings if "show no rollers" in x]        # plain tyres: said once
    assert len(said) == 1, w.warnings
    sim = Simulation(w)
    spin(sim, dict.fromkeys(SQUARE_NAMES, 2.0), name="square")     # the how-to's controller: every wheel at 2
    sim.run(100)
    # each wheel rolls along the circle through the wheels: ω = −r·u/(√2·h), about the centre
    x, y, yaw = pose2d(sim, "square")
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert yaw == pytest.approx(math.remainder(-RS * 2.0 / (math.sqrt(2) * HS) * 1.6, 2 * math.pi), abs=1e-12)


def test_the_square_robot_translates_along_x_and_y() -> None:
    # along +x: wheel i rolls along d_i = a_i × up at d_i · v; along +y likewise
    for v in ((0.1, 0.0), (0.0, 0.1)):
        sim = Simulation(load_world_from(square_text()))
        speeds = {}
        for name, (ax, ay) in zip(SQUARE_NAMES, SQUARE_AXES):
            dx, dy = ay / math.sqrt(2), -ax / math.sqrt(2)
            speeds[name] = (dx * v[0] + dy * v[1]) / RS
        spin(sim, speeds, name="square")
        sim.run(100)
        assert pose2d(sim, "square") == pytest.approx((v[0] * 1.6, v[1] * 1.6, 0.0), abs=1e-12)


# ---------------------------------------------------------------- not omni: left alone; checks

def test_an_arm_hinge_beside_two_wheels_is_no_omni_wheel(tmp_path: Path) -> None:
    """Two wheels about +y and an arm's hinge about +x whose link is a box: no third wheel (nothing
    round turns about its axis), so the two wheels keep their differential drive."""
    wheels = "".join(
        f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0 }} device [ RotationalMotor '
        f'{{ name "{n}" }} ] endPoint Solid {{ translation 0 {y} 0 name "{n}" rotation 1 0 0 1.5707963267948966 '
        f'children [ Shape {{ geometry Cylinder {{ radius 0.03 height 0.01 }} }} ] }} }}\n'
        for n, y in (("left", 0.05), ("right", -0.05)))
    arm = ('HingeJoint { jointParameters HingeJointParameters { axis 1 0 0 anchor -0.05 0 0.05 } device [ '
           'RotationalMotor { name "arm" } ] endPoint Solid { translation -0.05 0 0.1 name "link" children [ Shape { '
           'geometry Box { size 0.02 0.02 0.1 } } ] } }\n')
    p = tmp_path / "arm.wbt"
    p.write_text(HEADER + 'Robot { name "r" children [\n' + wheels + arm + '] }\n')
    robot = load_world(p).world.robots[0]
    assert robot.omni_drive is None
    assert robot.differential_drive is not None and robot.differential_drive.left_motor == "left"


def test_world_file_checks_name_the_field(tmp_path: Path) -> None:
    wheels = [{"motor": f"m{i}", "position": [0.1 * math.cos(i * THIRD), 0.1 * math.sin(i * THIRD)],
               "axis": [math.cos(i * THIRD), math.sin(i * THIRD)], "radius": 0.05} for i in range(3)]
    robot = {"name": "o", "omni_drive": {"wheels": wheels}}
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 16}, "robots": [robot]}, base_dir=tmp_path))
    spin(sim, {"m0": 3.0, "m1": 3.0, "m2": 3.0}, name="o")
    sim.run(10)                                  # 0.16 s at -r·u/L = -1.5 rad/s
    assert pose2d(sim, "o") == pytest.approx((0.0, 0.0, -0.24), abs=1e-12)
    parallel = [{**w, "axis": [0.0, 1.0]} for w in wheels]
    with pytest.raises(WorldError, match=r"robots\[0\] \(o\)\.omni_drive.*cannot move the robot in every direction") as e:
        parse_world({"robots": [{**robot, "omni_drive": {"wheels": parallel}}]})
    assert "\n" not in str(e.value).strip()
    with pytest.raises(WorldError, match=r"omni_drive.*own name"):
        parse_world({"robots": [{**robot, "omni_drive": {"wheels": [wheels[0], wheels[0], wheels[1]]}}]})
    with pytest.raises(WorldError, match=r"omni_drive\.wheels\.0\.axis|omni_drive\.wheels\[0\]\.axis"):
        parse_world({"robots": [{**robot, "omni_drive": {"wheels": [{**wheels[0], "axis": [0, 0]}, *wheels[1:]]}}]})
    with pytest.raises(WorldError, match=r"omni_drive\.wheels"):
        parse_world({"robots": [{**robot, "omni_drive": {"wheels": wheels[:2]}}]})
    with pytest.raises(WorldError, match=r"one drive at most"):
        parse_world({"robots": [{**robot, "differential_drive": {}}]})


def test_the_batched_simulation_drives_it_as_the_single_one(tmp_path: Path) -> None:
    """The batched simulation refused an omni-wheel robot; now each copy of the imported three-wheeler
    (its own twist) ends where its Simulation does, the same bits (tests/test_batched_omni.py has
    the closed forms, contact and the gym)."""
    world = load_world(three_wheeler(tmp_path)).world
    twists = [(0.2, 0.0, 0.0), (0.0, -0.1, 1.5), (0.05, 0.1, -2.0)]
    batched = BatchedSimulation(world, len(twists))
    batched.omni.command(0, [[three_speeds(*t)[f"wheel{i + 1}"] for i in range(3)] for t in twists])
    batched.run(60)
    for c, t in enumerate(twists):
        sim = Simulation(world)
        spin(sim, three_speeds(*t))
        sim.run(60)
        pose = sim.robot("omni").pose
        assert pose.translation.tobytes() == batched.pos[c, 0].tobytes(), c
        assert pose.rotation.tobytes() == batched.rot[c, 0].tobytes(), c
    assert batched.pos[0, 0, :2] == pytest.approx([0.2 * 60 * DT, 0.0], abs=1e-12)


# ---------------------------------------------------------------- helpers

def three_wheeler_text(place: str = "translation 0 0 0.05") -> str:
    return (HEADER + f'Robot {{ name "omni" {place} children [\n'
            + "".join(omni_wheel(i) for i in range(3))
            + '] boundingObject Cylinder { radius 0.12 height 0.05 } controller "<extern>" }\n')


def load_world_from(text: str):
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "w.wbt"
        p.write_text(text)
        return load_world(p)


assert wm.OmniDrive  # the schema's model (sensorium/schemas/world.py)


def test_an_omni_robot_with_a_camera_ball_on_a_tilt_hinge_keeps_its_omni_drive(tmp_path: Path) -> None:
    """The three-wheeler with a tilt hinge on its body whose end point is a ball 0.1 m up: its bottom
    is 0.12 m above the wheels' (more than their diameter, 0.1 m), so it is no fourth omni wheel (before,
    it made the robot lose its drive), and the three wheels still translate it at the closed form."""
    head = ('HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0.05 0 0.1 } device [ '
            'RotationalMotor { name "tilt" } ] endPoint Solid { translation 0.05 0 0.1 name "head" children [ Shape { '
            'geometry Sphere { radius 0.03 } } ] } }\n')
    w = load_world(three_wheeler(tmp_path, extra=head))
    assert [x.split(": ", 1)[1] for x in w.warnings] == [
        "HingeJoint motor 'tilt' is no wheel (its round part's bottom is 0.12 m above the robot's lowest wheels: it "
        "never touches the ground): its joint moves kinematically (Webots' rule without physics; its PositionSensor "
        "reads it), and the shapes and devices past the joint with it"]
    drive = w.world.robots[0].omni_drive
    assert drive is not None and [wh.motor for wh in drive.wheels] == ["wheel1", "wheel2", "wheel3"]
    sim = Simulation(w)
    spin(sim, three_speeds(0.0, 0.2, 0.0))
    for _ in range(50):
        sim.step()
    x, y, yaw = pose2d(sim)
    assert x == pytest.approx(0.0, abs=1e-12) and y == pytest.approx(0.2 * 50 * DT, abs=1e-9) and yaw == pytest.approx(0.0, abs=1e-12)
