"""The drive judgement's rules for robots built otherwise than an e-puck (README "Wheels"), on .wbt worlds of
our own: a robot built on its side (its own x the world's up) is judged with its x for its z and drives as
its upright twin does; two wheels' axes parallel or opposite within 5e-3 rad make a drive (PROTO authors
write 1.57 for pi/2), farther apart none, in one load line."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _wheeled_wbt import STEP, R, T, Y
from test_sweep19 import rot

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

LEFT, RIGHT = "left wheel motor", "right wheel motor"
X0, Y0 = 0.1, -0.2


def hinge(name: str, anchor: tuple[float, float, float], axis: str) -> str:
    """A motorised wheel hinge through ``anchor`` (the robot's frame) about ``axis``, its end point a
    cylinder of radius R along the robot's y (its boundingObject), its motor ``name`` (maxVelocity 20)."""
    at = " ".join(f"{v:.17g}" for v in anchor)
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {at} }}\n'
            f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} ]\n'
            f'  endPoint Solid {{ translation {at} children [ DEF W Pose {{ rotation 1 0 0 1.5708 children [\n'
            f'    Shape {{ geometry Cylinder {{ radius {R} height 0.003 }} }} ] }} ] boundingObject USE W }} }}\n')


def world(path: Path, rotation: str, wheels: str) -> Path:
    """Robot "bot" at (X0, Y0, 0) turned by ``rotation`` with ``wheels``, Physics on, no floor (nothing to
    settle on: both twins keep their height)."""
    path.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ basicTimeStep {STEP} }}\n'
                    f'Robot {{ name "bot" translation {X0} {Y0} 0 rotation {rotation} children [\n{wheels}]\n'
                    '  boundingObject Box { size 0.01 0.01 0.01 } physics Physics { } }\n')
    return path


def roll(path: Path, speeds: tuple[float, float], steps: int) -> Simulation:
    sim = Simulation(load_world(path))
    for name, w in zip((LEFT, RIGHT), speeds):
        sim.robot("bot").motor(name).set_position(math.inf)
        sim.robot("bot").motor(name).set_velocity(w)
    sim.run(steps)
    return sim


def test_a_robot_built_on_its_side_drives_as_its_upright_twin(tmp_path: Path) -> None:
    """The twin: wheels through (0, ±Y, R) about +y, upright. The robot on its side: turned −π/2 about y,
    its wheels through (R, ±Y, 0) of its own frame (its x up), about +y: the same wheels in the world. Its
    drive is judged with its x for its z: forward y × x = −z (the world's +x), axle 2·Y, radius R, no
    ``wheel_bottom`` (a robot on its side keeps its height). (3, 5) rad/s roll both on the arc of
    v = R·4, ω = R·2 / (2·Y) from heading 0 (1e-12), the one on its side turned by ωt about the world's z."""
    upright = world(tmp_path / "upright.wbt", "0 0 1 0",
                    hinge(LEFT, (0.0, Y, R), "0 1 0") + hinge(RIGHT, (0.0, -Y, R), "0 1 0"))
    on_side = world(tmp_path / "side.wbt", "0 1 0 -1.5707963267948966",
                    hinge(LEFT, (R, Y, 0.0), "0 1 0") + hinge(RIGHT, (R, -Y, 0.0), "0 1 0"))
    lw = load_world(on_side)
    assert not [w for w in lw.warnings if "drive" in w or "motor" in w], lw.warnings
    dd = lw.world.robots[0].differential_drive
    assert dd is not None and (dd.left_motor, dd.right_motor, dd.reversed_motors) == (LEFT, RIGHT, [])
    assert np.asarray(dd.forward) == pytest.approx([0.0, 0.0, -1.0], abs=1e-15)
    assert (dd.wheel_radius, dd.wheel_bottom) == (R, None)
    assert dd.axle_length == pytest.approx(2 * Y, abs=1e-15)
    assert np.asarray(dd.axle_center) == pytest.approx([0.0, 0.0], abs=1e-15)
    n, wl, wr = 40, 3.0, 5.0
    v, om = R * (wl + wr) / 2.0, R * (wr - wl) / (2.0 * Y)
    t = n * T
    expected = [X0 + v / om * math.sin(om * t), Y0 + v / om * (1.0 - math.cos(om * t))]
    base = rot((0, 1, 0), -math.pi / 2)
    for path in (upright, on_side):
        pose = roll(path, (wl, wr), n).robot("bot").pose
        assert pose.translation[:2] == pytest.approx(expected, abs=1e-12), path.name
        assert pose.translation[2] == 0.0
        turned = rot((0, 0, 1), om * t)
        assert pose.rotation == pytest.approx(turned @ (base if path is on_side else np.eye(3)), abs=1e-12)


@pytest.mark.parametrize("off, drives", [(4e-3, True), (6e-3, False)])
def test_two_wheels_axes_opposite_within_5e_3_make_a_drive_and_farther_none(tmp_path: Path, off: float,
                                                                           drives: bool) -> None:
    """The left wheel mounted mirrored, its axis turned ``off`` rad about the robot's z from −y (toed, as
    slots' 1.57 turns leave it). Within 5e-3: a drive, the left reversed, its frame the right wheel's (the
    robot's own), so (−w, w) rolls it straight along x at R·w, the toe not counted (Webots' wheel would roll
    ``off`` from x: sideways up to sin(off) of the way). Beyond: no drive, one load line naming the axis."""
    axis = f"{math.sin(off):.17g} {-math.cos(off):.17g} 0"
    path = world(tmp_path / "toed.wbt", "0 0 1 0", hinge(LEFT, (0.0, Y, R), axis) + hinge(RIGHT, (0.0, -Y, R), "0 1 0"))
    lw = load_world(path)
    dd = lw.world.robots[0].differential_drive
    lines = [w for w in lw.warnings if "no differential drive" in w]
    if not drives:
        assert dd is None and len(lines) == 1 and f"'{LEFT}'" in lines[0] and "needs every axis along +y or -y" in lines[0]
        return
    assert not lines and dd is not None and dd.reversed_motors == [LEFT] and dd.forward == (1.0, 0.0)
    pose = roll(path, (-5.0, 5.0), 25).robot("bot").pose
    assert pose.translation[:2] == pytest.approx([X0 + R * 5.0 * 25 * T, Y0], abs=1e-15)


def test_a_wheel_two_solids_past_its_hinge_is_the_drives_and_the_robot_settles_on_it(tmp_path: Path) -> None:
    """Each hinge's end point is a hub (a 5 mm sphere on the axis) holding, 0.01 m further out along the axis,
    a Solid whose cylinder of radius R is the wheel (Tinkerbots' motor, axle and wheel, upright). The drive's
    radius is R, not the hub's, its axle the cylinders' places, 2·(Y + 0.01); its ``wheel_bottom`` the
    cylinders' bottom, 0 (their axis R up): placed 0.05 m up over a floor at 0, the robot settles to z 0
    (the hub's bottom would have left it R − 0.005 too low), and (w, w) rolls it straight at R·w."""
    def hub(name: str, y: float) -> str:
        out = 0.01 if y > 0 else -0.01
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} {R} }}\n'
                f'  device [ RotationalMotor {{ name "{name}" maxVelocity 20 }} ]\n'
                f'  endPoint Solid {{ translation 0 {y} {R} children [\n'
                f'    Solid {{ translation 0 {out} 0 children [ DEF W Pose {{ rotation 1 0 0 1.5708 children [\n'
                f'      Shape {{ geometry Cylinder {{ radius {R} height 0.003 }} }} ] }} ] boundingObject USE W }} ]\n'
                f'    boundingObject Sphere {{ radius 0.005 }} }} }}\n')

    path = tmp_path / "hub.wbt"
    path.write_text(f'#VRML_SIM R2023b utf8\nWorldInfo {{ basicTimeStep {STEP} }}\n'
                    'Solid { children [ Shape { geometry DEF FLOOR Plane { size 10 10 } } ] boundingObject USE FLOOR }\n'
                    f'Robot {{ name "bot" translation {X0} {Y0} 0.05 children [\n{hub(LEFT, Y)}{hub(RIGHT, -Y)}]\n'
                    '  boundingObject Box { size 0.01 0.01 0.01 } physics Physics { } }\n')
    lw = load_world(path)
    dd = lw.world.robots[0].differential_drive
    assert dd is not None and dd.wheel_radius == R and dd.forward == (1.0, 0.0)
    assert dd.axle_length == pytest.approx(2 * (Y + 0.01), abs=1e-15)
    assert dd.wheel_bottom == pytest.approx(0.0, abs=1e-15)
    sim = roll(path, (5.0, 5.0), 25)
    pose = sim.robot("bot").pose
    assert np.asarray(pose.translation) == pytest.approx([X0 + R * 5.0 * 25 * T, Y0, 0.0], abs=1e-15)
