"""The Supervisor's getStaticBalance (sim/balance.py): whether a top-level solid's or robot's centre of
mass, seen from above, is over the support polygon of where its bounding shapes touch the ground now,
against closed forms: a box's footprint, a foot under an overhanging arm, a box on a ramp (balanced
while tan θ <= width / height), a two-wheel robot with and without a caster."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HEAD = "#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
SUPERVISOR = 'Robot { translation 9 9 0 name "sup" supervisor TRUE controller "<extern>" }\n'


def _box(name: str, x: float, com: str = "") -> str:
    return (f'DEF {name.upper()} Solid {{ translation {x} 0 0.05 name "{name}" boundingObject Box {{ size 0.1 0.1 0.1 }} '
            f'physics Physics {{ {com} }} }}\n')


FLOOR = (HEAD + 'Solid { name "floor" boundingObject Plane { size 20 20 } }\n' + _box("box", 0.0)
         + _box("inside", 1.0, "mass 1 centerOfMass [ 0.049 0.049 0 ]") + _box("outside", 2.0, "mass 1 centerOfMass [ 0.051 0 0 ]")
         + 'DEF BARE Solid { translation 3 0 0.05 name "bare" boundingObject Box { size 0.1 0.1 0.1 } }\n'
         + 'DEF HOLDER Solid { translation 4 0 0.05 name "holder" children [ DEF INNER Solid { name "inner" '
         'boundingObject Box { size 0.1 0.1 0.1 } physics Physics { } } ] boundingObject Box { size 0.1 0.1 0.1 } '
         'physics Physics { } }\n'
         + 'DEF ROLLER Solid { translation 5 0 0.05 rotation 1 0 0 1.5707963267948966 name "roller" '
         'boundingObject Cylinder { radius 0.05 height 0.3 } physics Physics { } }\n'
         + 'DEF ROLLER_OFF Solid { translation 6 0 0.05 rotation 1 0 0 1.5707963267948966 name "roller off" '
         'boundingObject Cylinder { radius 0.05 height 0.3 } physics Physics { mass 1 centerOfMass [ 0.001 0 0 ] } }\n'
         + 'DEF DRUM Solid { translation 7 0 0.15 name "drum" boundingObject Cylinder { radius 0.05 height 0.3 } '
         'physics Physics { mass 1 centerOfMass [ 0.049 0 0 ] } }\n'
         + 'DEF BALL Solid { translation 8 0 0.05 name "ball" boundingObject Sphere { radius 0.05 } physics Physics { } }\n'
         + SUPERVISOR)


def _live(text: str, tmp_path, name: str = "w.wbt") -> Live:
    path = tmp_path / name
    path.write_text(text)
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "sup"})
    return lv


def sup(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/sup/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return sup(lv, "get_from_def", {"name": name})["node"]


def balance(lv: Live, name: str) -> bool:
    return sup(lv, "get_node_static_balance", {"node": node(lv, name)})["value"]


def test_a_box_on_the_floor_is_balanced_while_its_centre_is_over_its_footprint(tmp_path):
    lv = _live(FLOOR, tmp_path)
    assert balance(lv, "BOX") is True
    assert balance(lv, "INSIDE") is True           # its centre 1 mm inside the 0.1 m square, on the diagonal
    assert balance(lv, "OUTSIDE") is False         # 1 mm beyond its edge (a single box lands by its face alone)
    assert balance(lv, "HOLDER") is True
    assert balance(lv, "ROLLER") is True            # on its side: a line of contact, its centre right above it
    assert balance(lv, "ROLLER_OFF") is False       # its centre 1 mm off that line
    assert balance(lv, "DRUM") is True              # on its end: its rim, the centre 1 mm inside it
    assert balance(lv, "BALL") is True              # one point, its centre right above it


def test_in_the_air_without_physics_or_no_top_solid(tmp_path):
    lv = _live(FLOOR, tmp_path)
    assert balance(lv, "BARE") is False            # no Physics: no contact point (Webots' ODE collides no static solid)
    box = node(lv, "BOX")
    sup(lv, "set_field", {"node": box, "field": "translation", "value": [0.0, 0.0, 0.55]})
    assert balance(lv, "BOX") is False             # in the air: it touches nothing
    for _ in range(20):                            # it falls for 19 steps of 16 ms (tests/test_falling.py)
        lv.step(A, "sup")
    assert sup(lv, "get_node_pose", {"node": box})["position"][2] == pytest.approx(0.05, abs=1e-12)
    assert balance(lv, "BOX") is True
    for target in (node(lv, "INNER"), 0):           # a nested solid; the root: Webots' warning (the client: false)
        message = lv.err(A, "/sup/robot/get_node_static_balance", {"node": target}, ErrorCode.INVALID_ARGUMENT)
        assert "exclusively be used with a top Solid" in message


def _hammer(name: str, y: float, com_x: float) -> str:
    """Two boxes: a 0.1 m foot 0.6 m behind the origin and an arm above it reaching 0.05 m past the
    origin; the origin stands 0.3 m beyond the table's edge (x = 0), over no ground, so it stays as put."""
    return (f'DEF {name.upper()} Solid {{ translation 0.3 {y} 0.5 name "{name}" boundingObject Group {{ children [ '
            'Pose { translation -0.6 0 0.05 children [ Box { size 0.1 0.1 0.1 } ] } '
            'Pose { translation -0.3 0 0.15 children [ Box { size 0.7 0.05 0.05 } ] } ] } '
            f'physics Physics {{ mass 1 centerOfMass [ {com_x} 0 0.15 ] }} }}\n')


TABLE = (HEAD + 'Solid { translation -1 0 0.25 name "table" boundingObject Box { size 2 40 0.5 } }\n'
         + _hammer("tipping", 0.0, 0.0) + _hammer("resting", 5.0, -0.6) + SUPERVISOR)


def test_two_boxes_overhanging_a_table_balance_on_their_foot_alone(tmp_path):
    lv = _live(TABLE, tmp_path)
    # the foot's four bottom corners touch the table top: x in [-0.35, -0.25]; the centre over x = 0.3
    assert balance(lv, "TIPPING") is False
    assert balance(lv, "RESTING") is True            # its centre over the foot's middle, x = -0.3
    tipping = node(lv, "TIPPING")
    sup(lv, "set_field", {"node": tipping, "field": "translation", "value": [0.3, 1.0, 0.5]})   # held there
    lv.step(A, "sup")
    assert sup(lv, "get_node_pose", {"node": tipping})["position"] == pytest.approx([0.3, 1.0, 0.5], abs=1e-15)
    assert balance(lv, "TIPPING") is False
    sup(lv, "set_field", {"node": tipping, "field": "translation", "value": [0.3, 1.0, 0.6]})   # its foot in the air
    assert balance(lv, "TIPPING") is False
    assert balance(lv, "RESTING") is True


def _plank(name: str, y: float, x: float) -> str:
    return (f'DEF {name.upper()} Solid {{ translation {x!r} {y} 0.525 name "{name}" boundingObject Box {{ size 1 0.1 0.05 }} '
            'physics Physics { } }\n')


PLANKS = (HEAD + 'Solid { translation -1 0 0.25 name "table" boundingObject Box { size 2 40 0.5 } }\n'
          + _plank("held", 0.0, -0.001) + _plank("over", 1.0, 0.001) + _plank("along", 2.0, -0.45) + SUPERVISOR)


def test_a_plank_over_a_table_edge_is_held_up_to_that_edge(tmp_path):
    lv = _live(PLANKS, tmp_path)
    # a 1 m plank touches the table top over x in [x - 0.5, 0]: balanced while its centre x <= 0
    assert balance(lv, "HELD") is True               # 1 mm on the table's side of its edge
    assert balance(lv, "OVER") is False              # 1 mm beyond it (over no ground at its origin: it stays)
    assert balance(lv, "ALONG") is True
    # its corners over the table are at x = -0.501 alone: the table's edge holds the rest
    assert sup(lv, "get_node_pose", {"node": node(lv, "HELD")})["position"] == pytest.approx([-0.001, 0.0, 0.525], abs=1e-15)


def _on_ramp(name: str, y: float, tilt: float, width: float, height: float) -> str:
    """A ramp rising along x at ``tilt`` (rad) around y, and a width x width x height box of uniform density
    lying on its top face; the box's Solid origin is 3 m aside, over no ground (it stays as the file puts it)."""
    ramp_centre = np.array([0.0, y, 0.5])
    n = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])                # the ramp's top face's normal
    centre = ramp_centre + (0.05 + height / 2.0) * n
    origin = np.array([0.0, y + 3.0, 0.5])
    at = " ".join(repr(float(v)) for v in centre - origin)
    return (f'Solid {{ translation 0 {y} 0.5 rotation 0 1 0 {-tilt!r} name "ramp {name}" '
            'boundingObject Box { size 2 1 0.1 } }\n'
            f'DEF {name.upper()} Solid {{ translation {" ".join(repr(float(v)) for v in origin)} name "{name}" '
            f'boundingObject Pose {{ translation {at} rotation 0 1 0 {-tilt!r} children [ Box {{ size {width} {width} '
            f'{height} }} ] }} physics Physics {{ }} }}\n')


RAMPS = (HEAD + _on_ramp("cube", 0.0, math.radians(20), 0.2, 0.2) + _on_ramp("tall", 10.0, math.radians(20), 0.1, 0.4)
         + _on_ramp("under", 20.0, math.atan(0.25) - 1e-4, 0.1, 0.4) + _on_ramp("over", 30.0, math.atan(0.25) + 1e-4, 0.1, 0.4)
         + SUPERVISOR)


def test_a_box_on_a_ramp_is_balanced_while_tan_tilt_is_at_most_width_over_height(tmp_path):
    lv = _live(RAMPS, tmp_path)
    # its centre is (h/2) sin θ downhill of its footprint's middle, which reaches (a/2) cos θ: tan θ <= a/h
    assert balance(lv, "CUBE") is True              # tan 20° = 0.364 <= 1
    assert balance(lv, "TALL") is False             # 0.364 > 0.25
    assert balance(lv, "UNDER") is True             # 1e-4 rad either side of atan(0.25)
    assert balance(lv, "OVER") is False


def _robot(name: str, y: float, com_x: float, caster: bool) -> str:
    """A two-wheel robot (wheels 0.05 m in radius on an axle along y, 0.2 m long, under its origin) with
    a 1 kg Physics at (com_x, 0, 0.05), and a 0.02 m caster ball 0.1 m behind the axle or none."""
    wheel = ('HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {s}0.1 0.05 }} '
             'device [ RotationalMotor {{ name "{side} wheel" }} ] endPoint Solid {{ translation 0 {s}0.1 0.05 '
             'rotation 1 0 0 1.5707963267948966 name "{side}" boundingObject Cylinder {{ radius 0.05 height 0.02 }} }} }} ')
    ball = ('Solid { translation -0.1 0 0.02 name "caster" boundingObject Sphere { radius 0.02 } '
            'physics Physics { mass 0.001 centerOfMass [ 0 0 0 ] } } ' if caster else "")
    return (f'DEF {name.upper()} Robot {{ translation 0 {y} 0 name "{name}" children [ '
            + wheel.format(s="", side="left") + wheel.format(s="-", side="right") + ball
            + f'] boundingObject Pose {{ translation 0 0 0.1 children [ Box {{ size 0.1 0.1 0.05 }} ] }} '
            f'physics Physics {{ mass 1 centerOfMass [ {com_x} 0 0.05 ] }} }}\n')


ROBOTS = (HEAD + 'Solid { name "floor" boundingObject Plane { size 40 40 } }\n' + _robot("steady", 0.0, -0.03, True)
          + _robot("twowheel", 2.0, -0.03, False) + _robot("heavy", 4.0, -0.3, True) + SUPERVISOR)


def test_a_two_wheel_robot_stands_on_its_wheels_and_caster(tmp_path):
    lv = _live(ROBOTS, tmp_path)
    # wheels touching along y = ±0.1 (each 0.02 m wide) at x = 0, the caster at x = -0.1
    assert balance(lv, "STEADY") is True             # its centre at x ≈ -0.03 over the triangle
    assert balance(lv, "TWOWHEEL") is False          # two wheels alone: a line its centre is off
    assert balance(lv, "HEAVY") is False             # its centre at x ≈ -0.3, behind the caster
    robot = lv.sim.robot("steady")
    for name, speed in (("left wheel", 4.0), ("right wheel", 3.0)):     # driving a curve, its wheels turning
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(speed)
    for _ in range(10):
        lv.step(A, "sup")
    assert sup(lv, "get_node_pose", {"node": node(lv, "STEADY")})["position"][0] > 0.02      # 0.175 m/s for 0.16 s
    assert balance(lv, "STEADY") is True
    sup(lv, "set_field", {"node": node(lv, "STEADY"), "field": "translation", "value": [5.0, 5.0, 0.0]})
    assert balance(lv, "STEADY") is True             # put elsewhere on the floor: it still stands
    sup(lv, "set_field", {"node": node(lv, "STEADY"), "field": "rotation", "value": [1.0, 0.0, 0.0, 0.3]})
    assert balance(lv, "STEADY") is False            # tilted: one wheel's rim touches, at most


WORLD = REPO / "tests" / "worlds" / "static_balance.wbt"
EXPECTED = ["balance 1 0 0", "air 0", "landed 1", "root 0"]
ROOT_LINE = "it can exclusively be used with a top Solid, not the root"   # after the C or Python library's prefix


@pytest.mark.slow
def test_a_python_controller_reads_the_balance(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "static_balance.py", "sup")
    assert ctl.out == EXPECTED
    err = ctl.stderr()
    assert "Error: wb_supervisor_node_get_static_balance(): " in err and f"{ROOT_LINE}.\n" in err


@pytest.mark.slow
def test_a_c_controller_reads_the_balance(tmp_path_factory):
    from test_c_client import sanitized_run

    code, out, err = sanitized_run(tmp_path_factory, REPO / "tests" / "c" / "static_balance.c", WORLD, "sup")
    assert code == 0, err
    assert out == EXPECTED
    assert "Error: wb_supervisor_node_get_static_balance(): " in err and ROOT_LINE in err


NUE = ('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 coordinateSystem "NUE" }\n'
       'Solid { rotation 1 0 0 -1.5707963267948966 name "floor" boundingObject Plane { size 20 20 } }\n'
       + "".join(f'DEF {name} Solid {{ translation {x} 0.05 0 name "{name.lower()}" boundingObject Box {{ size 0.1 0.1 0.1 }} '
                 f'physics Physics {{ mass 1 centerOfMass [ {cx} 0 {cz} ] }} }}\n'
                 for name, x, cx, cz in (("INSIDE", 0, 0.049, -0.049), ("OUTSIDE", 1, 0, 0.051)))
       + SUPERVISOR.replace("translation 9 9 0", "translation 9 0 9"))


def test_a_nue_world_judges_along_its_up_y(tmp_path):
    lv = _live(NUE, tmp_path)
    assert balance(lv, "INSIDE") is True             # 1 mm inside along x and z, the horizontal axes
    assert balance(lv, "OUTSIDE") is False           # 1 mm beyond along z
    sup(lv, "set_field", {"node": node(lv, "INSIDE"), "field": "translation", "value": [0.0, 0.3, 0.0]})
    assert balance(lv, "INSIDE") is False            # lifted along y, the up: in the air


def test_clip_keeps_the_part_of_a_face_a_line_or_a_point_inside_an_outline():
    from sensorium.server.sim.balance import clip

    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    shifted = square + [0.5, 0.25]
    got = clip(shifted, square)                      # the overlap: [0.5, 1] x [0.25, 1]
    assert sorted(map(tuple, got.round(15))) == [(0.5, 0.25), (0.5, 1.0), (1.0, 0.25), (1.0, 1.0)]
    line = clip(np.array([[-1.0, 0.5], [2.0, 0.5]]), square)
    assert line.tolist() == [[0.0, 0.5], [1.0, 0.5]]
    assert clip(np.array([[0.5, 0.5]]), square).tolist() == [[0.5, 0.5]]
    assert clip(np.array([[1.5, 0.5]]), square).shape == (0, 2)
    assert clip(square + [3.0, 0.0], square).shape == (0, 2)
