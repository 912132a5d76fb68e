"""A youBot-like mobile manipulator built from PROTOs of our own (tests/protos/omnibot, world
tests/worlds/proto/omnibot.wbt), the structure of Webots' Youbot.proto: wheel PROTOs derived from one
wheel PROTO, each fixing its contact material, plain cylinders turned into place as bounding objects,
drawn rollers in templated Transforms, a five-joint arm in a template branch, coupled gripper motors,
a body slot. It loads as a mecanum drive with the wheels' layout and radius, the arm and gripper
joints move kinematically, and a C controller written as Webots' youbot controller drives it (its
library's fixed wheel patterns and base_move): every phase ends where the closed form puts it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from _serve import run_controller
from test_c_client import SAN_ENV, sanitized_controller

from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "proto" / "omnibot.wbt"
R, LX, LY = 0.048, 0.2, 0.15


def test_the_base_is_a_mecanum_drive_with_the_protos_layout() -> None:
    w = load_world(WORLD)
    (robot,) = w.world.robots
    assert robot.differential_drive is None and robot.ackermann_drive is None
    assert robot.mecanum_drive == wm.MecanumDrive(
        wheel_radius=R, lx=LX, ly=LY, max_wheel_speed=12.0, front_left_motor="wheel2", front_right_motor="wheel1",
        wheel_bottom=-0.098,      # the axles 5 cm below the origin, less R: at its 0.098 the robot stands on the floor
        rear_left_motor="wheel4", rear_right_motor="wheel3", rollers=(-1, 1, 1, -1))
    names = [d.name for d in robot.devices]
    assert names[:2] == ["gps", "compass"]                                   # the body slot's devices
    assert {f"arm{i}" for i in range(1, 6)} | {"claw::left", "claw::right"} <= set(names)
    moving = [x.split(": ", 1)[1] for x in w.warnings]
    assert len(moving) == 3 and all("moves kinematically" in x or "move kinematically" in x for x in moving), moving
    assert "its 5 motorised joints are no wheels" in moving[2]


def test_without_its_arm_the_base_keeps_its_drive_and_says_nothing(tmp_path: Path) -> None:
    world = tmp_path / "bare.wbt"
    world.write_text(WORLD.read_text().replace("../../protos/omnibot/", f"{REPO}/tests/protos/omnibot/")
                     .replace("  bodySlot [", "  numberOfArms 0\n  bodySlot ["))
    w = load_world(world)
    assert w.world.robots[0].mecanum_drive is not None and w.warnings == []


def test_the_gripper_fingers_follow_one_command_and_the_arm_reaches_its_targets() -> None:
    sim = Simulation(load_world(WORLD), "fast")
    robot = sim.robot("omnibot")
    robot.motor("claw::left").set_velocity(0.03)
    robot.motor("claw::left").set_position(0.02)
    robot.motor("arm1").set_position(math.pi / 2)
    sim.run(100)                                  # 1.6 s: 0.02 m at 0.03 m/s, pi/2 at 1.5 rad/s
    assert robot.motor("claw::left").position == robot.motor("claw::right").position == 0.02
    assert robot.motor("arm1").position == math.pi / 2
    assert sim.robot("omnibot").pose.translation.tolist() == pytest.approx([0, 0, 0.098], abs=0)


def test_info_says_how_the_robot_drives(capsys) -> None:
    from sensorium.cli import main as cli

    assert cli(["info", str(WORLD)]) == 0
    out = capsys.readouterr().out
    assert ("    (drive)        mecanum: wheels of radius 0.048 m at (±0.2, ±0.15) m, rollers [-1, 1, 1, -1] "
            "(front left, front right, rear left, rear right: wheel2, wheel1, wheel4, wheel3)\n") in out


def arc(x: float, y: float, th: float, vx: float, vy: float, w: float, t: float) -> tuple[float, float, float]:
    """The pose after t seconds of the body twist (vx, vy, w), its velocity in the robot's frame."""
    if w == 0.0:
        return (x + (vx * math.cos(th) - vy * math.sin(th)) * t, y + (vx * math.sin(th) + vy * math.cos(th)) * t, th)
    th1 = th + w * t
    s0, c0, s1, c1 = math.sin(th), math.cos(th), math.sin(th1), math.cos(th1)
    return (x + (vx * (s1 - s0) + vy * (c1 - c0)) / w, y + (vx * (c0 - c1) + vy * (s1 - s0)) / w, th1)


@pytest.fixture(scope="module")
def demo(tmp_path_factory) -> str:
    return sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "omnibot_demo.c")


def test_a_youbot_style_c_controller_moves_the_base_and_arm_as_the_closed_form(demo: str) -> None:
    lines, err = run_controller(WORLD, lambda url: [demo], env=SAN_ENV, robot="omnibot")
    assert "Sanitizer" not in err and "runtime error" not in err, err
    phases = {p: tuple(map(float, rest)) for p, *rest in (line.split() for line in lines[:-1])}
    assert list(phases) == ["start", "forward", "strafe", "turn", "move", "stop"], lines
    # each wait steps 32 ms until its second has passed: 1.024 s a phase (the start after 2.016 s)
    assert [phases[p][0] for p in phases] == [2.016, 3.04, 4.064, 5.088, 6.112, 9.12]
    k = LX + LY
    twists = {"forward": (R * 4, 0.0, 0.0),                     # every wheel at +4 rad/s
              "strafe": (0.0, R * 4, 0.0),                      # (+, -, -, +): left at r·ω
              "turn": (0.0, 0.0, -R * 4 / k),                   # the library's base_turn_left: clockwise
              "move": (0.1, 0.05, 0.3),                         # base_move's inverse kinematics, undone
              "stop": (0.0, 0.0, 0.0)}
    pose, before = (0.0, 0.0, 0.0), phases["start"][0]
    assert phases["start"][1:] == pose
    for phase, twist in twists.items():
        t, *got = phases[phase]
        pose = arc(*pose, *twist, t - before)
        assert got == pytest.approx(pose, abs=1e-9), phase
        before = t
    # the arm at its last targets, both fingers closed by the one command to claw::left
    joints = [float(v) for v in lines[-1].split()[1:]]
    assert joints == pytest.approx([math.pi / 2, 0.0, -0.8, -1.2, 0.0, 0.0, 0.0], abs=1e-12)
