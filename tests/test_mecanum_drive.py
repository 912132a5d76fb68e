"""Mecanum (omnidirectional) drive: four wheels with 45° rollers (a KUKA youBot-like base) move the
robot forward, sideways and round on the spot, in closed form; a .wbt robot whose wheels' friction
a ContactProperties turns (Webots' way of simulating the rollers) is detected as one, without it
it stays skid-steer; a Python controller strafes (the batched simulation: tests/test_batched_mecanum.py)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from _serve import run_controller, sensorium

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

R, LX, LY = 0.05, 0.228, 0.158        # the youBot's wheel radius, half wheelbase, half track
DT = 0.016
# the youBot's wheel names: wheel1 front right, wheel2 front left, wheel3 rear right, wheel4 rear left
FR, FL, RR, RL = "wheel1", "wheel2", "wheel3", "wheel4"


def bot(**drive) -> dict:
    return {"name": "yb", "pose": {"translation": [0.0, 0.0, 0.1]},
            "body": {"geometry": {"type": "box", "size": [0.5, 0.3, 0.1]}},
            "mecanum_drive": {"wheel_radius": R, "lx": LX, "ly": LY, **drive},
            "devices": [{"device": "PositionSensor", "name": "fl sensor", "motor": FL},
                        {"device": "GPS", "name": "gps"}]}


def sim_of(*robots: dict, solids=(), contact: bool = False) -> Simulation:
    return Simulation(parse_world({"world_info": {"basic_time_step": 16, "contact": contact},
                                   "solids": list(solids), "robots": list(robots)}))


def roll(sim: Simulation, speeds: dict[str, float], name: str = "yb") -> None:
    for motor, omega in speeds.items():
        m = sim.robot(name).motor(motor)
        m.set_position(math.inf)
        m.set_velocity(omega)


def pose2d(sim: Simulation, name: str = "yb") -> tuple[float, float, float]:
    p = sim.robot(name).pose
    return float(p.translation[0]), float(p.translation[1]), math.atan2(p.rotation[1, 0], p.rotation[0, 0])


def base_move(vx: float, vy: float, w: float) -> dict[str, float]:
    """The wheel speeds for a body twist (standard mecanum inverse kinematics, rollers as the youBot's)."""
    k = LX + LY
    return {FR: (vx + vy + k * w) / R, FL: (vx - vy - k * w) / R, RR: (vx - vy + k * w) / R,
            RL: (vx + vy - k * w) / R}


def test_all_wheels_forward_drive_straight_at_r_omega() -> None:
    sim = sim_of(bot())
    roll(sim, {FR: 4.0, FL: 4.0, RR: 4.0, RL: 4.0})
    sim.run(100)                                        # 1.6 s at 0.2 m/s
    assert pose2d(sim) == pytest.approx((R * 4.0 * 1.6, 0.0, 0.0), abs=1e-12)
    assert sim.robot("yb").drive.velocity()[:2] == pytest.approx([0.2, 0.0], abs=1e-12)


def test_strafe_pattern_moves_sideways_without_turning() -> None:
    sim = sim_of(bot())
    gps = sim.device("yb/gps")
    gps.enable(16)
    roll(sim, {FR: 4.0, FL: -4.0, RR: -4.0, RL: 4.0})   # the youBot library's base_strafe_left
    sim.run(100)
    x, y, yaw = pose2d(sim)
    assert (x, y, yaw) == pytest.approx((0.0, R * 4.0 * 1.6, 0.0), abs=1e-12)
    assert (sim.robot("yb").pose.rotation == [[1, 0, 0], [0, 1, 0], [0, 0, 1]]).all()
    assert list(gps.values) == pytest.approx([0.0, 0.32, 0.1], abs=1e-12)
    assert sim.robot("yb").drive.velocity()[:2] == pytest.approx([0.0, 0.2], abs=1e-12)
    roll(sim, {FR: -4.0, FL: 4.0, RR: 4.0, RL: -4.0})   # and right, back where it started
    sim.run(100)
    assert pose2d(sim) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)


def test_rotate_pattern_turns_on_the_spot_at_r_omega_over_lx_plus_ly() -> None:
    sim = sim_of(bot())
    roll(sim, {FL: -3.0, FR: 3.0, RL: -3.0, RR: 3.0})
    rate = R * 3.0 / (LX + LY)
    for n in (1, 10, 37):
        sim.run(n)
    steps = 48
    x, y, yaw = pose2d(sim)
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert yaw == pytest.approx(math.remainder(rate * steps * DT, math.tau), abs=1e-12)
    assert sim.robot("yb").drive.velocity()[5] == pytest.approx(rate, abs=1e-12)
    enc = sim.device("yb/fl sensor")
    enc.enable(16)
    sim.step()
    assert enc.value == pytest.approx(-3.0 * 49 * DT, abs=1e-12)     # its own wheel's angle


def test_diagonal_two_wheels_move_at_45_degrees() -> None:
    sim = sim_of(bot())
    roll(sim, {FR: 6.0, RL: 6.0})                       # front left and rear right held
    sim.run(50)
    d = R * 6.0 / 2.0 * 50 * DT                         # vx = vy = r·ω/2
    assert pose2d(sim) == pytest.approx((d, d, 0.0), abs=1e-12)


@pytest.mark.parametrize("vx, vy, w", [(0.2, 0.1, 0.5), (-0.05, 0.15, -1.2), (0.0, -0.2, 0.3)])
def test_any_twist_follows_its_closed_form_after_n_steps(vx: float, vy: float, w: float) -> None:
    sim = sim_of(bot())
    roll(sim, base_move(vx, vy, w))
    n = 437
    sim.run(n)
    t = n * DT
    s, c = math.sin(w * t), math.cos(w * t)
    expect = ((vx * s - vy * (1 - c)) / w, (vx * (1 - c) + vy * s) / w, math.remainder(w * t, math.tau))
    assert pose2d(sim) == pytest.approx(expect, abs=1e-9)


def test_mirrored_rollers_strafe_the_other_way() -> None:
    sim = sim_of(bot(rollers=[1, -1, -1, 1]))
    roll(sim, {FR: 4.0, FL: -4.0, RR: -4.0, RL: 4.0})
    sim.run(100)
    assert pose2d(sim) == pytest.approx((0.0, -0.32, 0.0), abs=1e-12)


def test_forward_of_the_drive_turns_its_axes() -> None:
    sim = sim_of(bot(forward=[0, 1]))                  # drives along its own +y, strafes left to -x
    roll(sim, {FR: 4.0, FL: -4.0, RR: -4.0, RL: 4.0})
    sim.run(100)
    assert pose2d(sim) == pytest.approx((-0.32, 0.0, 0.0), abs=1e-12)


def test_nue_world_strafes_to_the_robots_left_on_its_ground_plane() -> None:
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 16, "coordinate_system": "NUE"},
                                  "robots": [{"name": "yb", "mecanum_drive": {"wheel_radius": R, "lx": LX, "ly": LY}}]}))
    roll(sim, {FR: 4.0, FL: -4.0, RR: -4.0, RL: 4.0})
    sim.run(100)
    # x north (the robot's forward), y up, z east: its left is west, -z
    assert list(sim.robot("yb").pose.translation) == pytest.approx([0.0, 0.0, -0.32], abs=1e-12)


def test_contact_stops_a_strafing_robot_at_a_wall() -> None:
    wall = {"name": "wall", "pose": {"translation": [0.0, 1.0, 0.25]}, "geometry": {"type": "box", "size": [4, 0.2, 0.5]}}
    sim = sim_of(bot(), solids=[wall], contact=True)
    roll(sim, {FR: 10.0, FL: -10.0, RR: -10.0, RL: 10.0})
    sim.run(200)                                        # 3.2 s at 0.5 m/s: far past the wall unless stopped
    x, y, yaw = pose2d(sim)
    assert (x, yaw) == (0.0, 0.0)
    assert y == pytest.approx(0.9 - 0.15, abs=1e-9)     # its body's left side against the wall's face
    assert sim.robot("yb").pressing


def test_world_file_checks_name_the_field() -> None:
    with pytest.raises(WorldError, match=r"robots\[0\].*one drive at most.*differential_drive and mecanum_drive"):
        parse_world({"robots": [{**bot(), "differential_drive": {}}]})
    with pytest.raises(WorldError, match=r"robots\[0\] \(yb\)\.mecanum_drive.*rollers \[1, 1, 1, 1\]") as err:
        parse_world({"robots": [bot(rollers=[1, 1, 1, 1])]})
    assert "\n" not in str(err.value).strip()
    with pytest.raises(WorldError, match=r"mecanum_drive.*cannot turn"):
        parse_world({"robots": [bot(rollers=[1, -1, -1, 1], lx=0.2, ly=0.2)]})
    with pytest.raises(WorldError, match=r"mecanum_drive.*own name"):
        parse_world({"robots": [bot(front_left_motor="wheel1")]})
    with pytest.raises(WorldError, match=r"mecanum_drive\.lx"):
        parse_world({"robots": [bot(lx=0)]})


# ---------------------------------------------------------------- .wbt worlds we write

HEADER = "#VRML_SIM R2023b utf8\n"
FRICTION = ('contactProperties [\n'
            '  ContactProperties { material1 "inner rollers" coulombFriction [ 0, 2, 0 ] frictionRotation -0.785398 0 }\n'
            '  ContactProperties { material1 "outer rollers" coulombFriction [ 0, 2, 0 ] frictionRotation 0.785398 0 }\n'
            ']')


def wheel(name: str, x: float, y: float, material: str) -> str:
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor {x} {y} 0 }} '
            f'device [ RotationalMotor {{ name "{name}" maxVelocity 14.81 }} PositionSensor {{ name "{name}sensor" }} ] '
            f'endPoint Solid {{ translation {x} {y} 0 rotation 1 0 0 1.5708 contactMaterial "{material}" '
            f'children [ DEF W Shape {{ geometry Cylinder {{ radius {R} height 0.07 }} }} ] boundingObject USE W }} }}\n')


def youbot_like(tmp_path: Path, friction: str = FRICTION) -> Path:
    p = tmp_path / "base.wbt"
    p.write_text(HEADER + f"WorldInfo {{ basicTimeStep 16 {friction} }}\n"
                 'Robot { name "yb" translation 0 0 0.05 children [\n'
                 '  GPS { name "gps" }\n'
                 + wheel(FR, LX, -LY, "inner rollers") + wheel(FL, LX, LY, "outer rollers")
                 + wheel(RR, -LX, -LY, "outer rollers") + wheel(RL, -LX, LY, "inner rollers")
                 + '] boundingObject Box { size 0.5 0.3 0.1 } controller "<extern>" }\n')
    return p


def test_wbt_wheels_with_turned_friction_are_a_mecanum_drive(tmp_path: Path) -> None:
    w = load_world(youbot_like(tmp_path))
    (robot,) = w.world.robots
    assert robot.differential_drive is None
    assert robot.mecanum_drive == wm.MecanumDrive(
        wheel_radius=R, lx=LX, ly=LY, max_wheel_speed=14.81, front_left_motor=FL, front_right_motor=FR,
        rear_left_motor=RL, rear_right_motor=RR, rollers=(-1, 1, 1, -1))
    assert [d.motor for d in robot.devices if d.device == "PositionSensor"] == [FR, FL, RR, RL]
    assert w.warnings == []


def test_wbt_wheels_without_contact_properties_stay_skid_steer(tmp_path: Path) -> None:
    w = load_world(youbot_like(tmp_path, friction=""))
    (robot,) = w.world.robots
    assert robot.mecanum_drive is None
    assert robot.differential_drive is not None and robot.differential_drive.skid_steer is not None
    # symmetric friction (one coefficient) is no roller either
    sym = ('contactProperties [ ContactProperties { material1 "inner rollers" coulombFriction 1 frictionRotation 0.785398 0 }'
           ' ContactProperties { material1 "outer rollers" coulombFriction 1 } ]')
    assert load_world(youbot_like(tmp_path, friction=sym)).world.robots[0].differential_drive is not None


def test_wbt_rollers_at_another_angle_are_taken_at_45_degrees_with_one_line(tmp_path: Path) -> None:
    w = load_world(youbot_like(tmp_path, friction=FRICTION.replace("-0.785398", "-0.6")))
    assert w.world.robots[0].mecanum_drive is not None
    assert [x.split(": ", 1)[1] for x in w.warnings] == [
        f"mecanum wheel {FR!r}: its friction is turned by -0.6 rad; the kinematic drive takes its rollers at 45°"]


def test_wbt_youbot_like_robot_now_strafes(tmp_path: Path) -> None:
    """The silent case: a strafe command moved the robot 0 m (taken for skid steer); now r·ω·t sideways."""
    sim = Simulation(load_world(youbot_like(tmp_path)), "fast")
    roll(sim, {FR: 4.0, FL: -4.0, RR: -4.0, RL: 4.0})
    sim.run(100)
    assert pose2d(sim) == pytest.approx((0.0, 0.32, 0.0), abs=1e-12)


ARM = ('Solid { translation 0.156 0 0 name "arm" children [ HingeJoint { jointParameters HingeJointParameters { '
       'axis 0 0 1 anchor 0 0 0.077 } device [ RotationalMotor { name "arm1" } ] endPoint Solid { translation 0 0 0.077 '
       'children [ HingeJoint { jointParameters HingeJointParameters { axis 0 -1 0 anchor 0.033 0 0.07 } device [ '
       'RotationalMotor { name "arm2" } ] endPoint Solid { translation 0.033 0 0.07 boundingObject Box { size 0.07 0.06 '
       '0.21 } } } ] boundingObject Pose { translation 0.032 0.023 0.07 rotation 1 0 0 -1.5708 children [ Cylinder { '
       'height 0.046 radius 0.036 } ] } } } ] }\n')


def test_wbt_mecanum_base_with_an_arm_keeps_its_drive(tmp_path: Path) -> None:
    """A youBot's arm turns first about the vertical, its link a cylinder: taken for a steered wheel,
    the robot was a failed car that did not move; the arm's joints are no wheels on a mecanum base."""
    p = youbot_like(tmp_path)
    p.write_text(p.read_text().replace('  GPS { name "gps" }\n', '  GPS { name "gps" }\n' + ARM))
    w = load_world(p)
    (robot,) = w.world.robots
    assert robot.ackermann_drive is None and robot.mecanum_drive is not None
    assert robot.mecanum_drive.rollers == (-1, 1, 1, -1)
    assert [x.split(": ", 1)[1].split(":")[0] for x in w.warnings] == [
        f"HingeJoint motor '{m}' is no wheel (an arm's joint on a mecanum base)" for m in ("arm1", "arm2")]
    sim = Simulation(w, "fast")
    roll(sim, {FR: 4.0, FL: -4.0, RR: -4.0, RL: 4.0})
    sim.robot("yb").motor("arm1").set_position(0.5)
    sim.run(100)
    assert pose2d(sim) == pytest.approx((0.0, 0.32, 0.0), abs=1e-12)


def test_wbt_wheels_out_of_place_say_why_in_one_line(tmp_path: Path) -> None:
    p = youbot_like(tmp_path)
    p.write_text(p.read_text().replace(f"anchor {-LX} {LY} 0", f"anchor {-LX - 0.1} {LY} 0")
                 .replace(f"translation {-LX} {LY} 0", f"translation {-LX - 0.1} {LY} 0"))
    w = load_world(p)
    assert w.world.robots[0].mecanum_drive is None and w.world.robots[0].differential_drive is None
    lines = [x for x in w.warnings if "no mecanum drive" in x]
    assert len(lines) == 1 and "\n" not in lines[0] and "corners (±lx, ±ly)" in lines[0], w.warnings


CONTROLLER = '''
from controller import Robot
robot = Robot()
step = int(robot.getBasicTimeStep())
gps = robot.getDevice("gps")
gps.enable(step)
wheels = [robot.getDevice(f"wheel{i}") for i in range(1, 5)]
for w, v in zip(wheels, (4.0, -4.0, -4.0, 4.0)):     # the youBot library's base_strafe_left
    w.setPosition(float("inf"))
    w.setVelocity(v)
for _ in range(100):
    robot.step(step)
print("gps %.9f %.9f" % tuple(gps.getValues()[:2]))
'''


@pytest.mark.slow
def test_python_controller_strafes_the_robot(tmp_path: Path) -> None:
    world = youbot_like(tmp_path)
    script = tmp_path / "strafe.py"
    script.write_text(CONTROLLER)
    lines, err = run_controller(world, lambda url: sensorium("controller", str(script), "--url", url), robot="yb",
                                cwd=tmp_path)
    assert lines[-1:] == ["gps 0.000000000 0.320000000"], err      # 1.6 s at r·ω = 0.2 m/s to its left


@pytest.mark.parametrize("speeds, twist", [
    ((-4.0, 4.0, -4.0, 4.0), (0.0, 0.0, -R * 4.0 / (LX + LY))),     # the youBot library's base_turn_left
    ((4.0, -4.0, -4.0, 4.0), (0.0, R * 4.0, 0.0)),                   # its base_strafe_left
    ((1.0 / R * (LX + LY) * 0.3, -1.0 / R * (LX + LY) * 0.3,          # its base_move(0, 0, 0.3)
      1.0 / R * (LX + LY) * 0.3, -1.0 / R * (LX + LY) * 0.3), (0.0, 0.0, 0.3)),
])
def test_the_friction_rollers_move_the_base_as_webots_contact_turns_them(tmp_path: Path, speeds, twist) -> None:
    """Webots' contact joint frees each wheel along its cylinder's axis turned by -frictionRotation
    about the contact normal (up, into the wheel): the 'inner' wheels (-0.785398, front right and rear
    left) slide along (1, -1) and grip along (1, 1), the 'outer' ones the reverse -- the X arrangement
    whose inverse kinematics is the youBot library's base_move. So its fixed base_turn_left pattern
    (wheel1..4 = front right, front left, rear right, rear left at -4, 4, -4, 4 rad/s) turns the base
    clockwise at r·4/(lx + ly), its strafe pattern moves it left at r·4, and base_move(0, 0, 0.3)
    turns it counter-clockwise at 0.3 rad/s (closed forms, 1 s)."""
    sim = Simulation(load_world(youbot_like(tmp_path)))
    r = sim.robot("yb")
    for name, w in zip((FR, FL, RR, RL), speeds):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)
    sim.run(62)                 # 0.992 s: 62 steps of 16 ms
    t = 0.992
    vx, vy, w = twist
    yaw = math.atan2(r.pose.rotation[1, 0], r.pose.rotation[0, 0])
    assert yaw == pytest.approx(w * t, abs=1e-9)
    if w == 0.0:
        assert (r.pose.translation[0], r.pose.translation[1]) == pytest.approx((vx * t, vy * t), abs=1e-9)
    else:                       # turning in place about its centre
        assert (r.pose.translation[0], r.pose.translation[1]) == pytest.approx((0.0, 0.0), abs=1e-9)
