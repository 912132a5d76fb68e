"""Kinematic contact of a concave robot (sensorium/server/sim/contact.py): where the convex hull of
its shapes' outlines exceeds their union's area by more than 1 % (``contact.CONCAVE``), its
footprint is its convex pieces, so what fits in a notch between its parts enters it. A U-shaped
robot: a body box 0.2 x 0.3 m about its origin and two finger boxes 0.15 m long reaching ahead of
its front face (x = 0.1 m), 0.05 m wide, 0.1 m apart. Wheels of radius 0.1 m at w rad/s move a
robot w * 0.1 m/s; every stopping point is a distance the geometry gives exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_contact import drive, world, xy
from test_contact_shape import _step_both, batched_and_singles, block, box_robot, drive_randomly, heading

from sensorium.server.sim import contact as C
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world

STEP = 32
FRONT = 0.1            # the body's front face, ahead of the origin
TIP = 0.25             # the fingers' tips
GAP = 0.1              # between the fingers (|y| < 0.05)
POST = 0.025           # the post's radius


def finger(name, y, length=TIP - FRONT):
    return {"name": name, "pose": {"translation": [FRONT + length / 2, y, 0.0]},
            "geometry": {"type": "box", "size": [length, 0.05, 0.2]}}


def u_robot(name, x, y, yaw=0.0, **extra):
    robot = box_robot(name, x, y, yaw, size=(0.2, 0.3), **extra)
    robot["shapes"] = [finger("left", GAP / 2 + 0.025), finger("right", -GAP / 2 - 0.025)]
    return robot


def post(x, y=0.0):
    return {"name": "post", "pose": {"translation": [x, y, 0.25]},
            "geometry": {"type": "cylinder", "radius": POST, "height": 0.5}}


def piece_gaps(sim, name, ob):
    """Each of robot ``name``'s pieces' signed distance to the obstacle ``ob`` where it is now."""
    ct = sim.contact
    i = list(sim.robots).index(name)
    foot = ct.feet[i]
    p, yaw = ct.centres[i], float(ct.yaw[i])
    return [C._gap(p, *C._grown(ob, C._turned(pc.points, yaw), pc.round, p)) for pc in foot.pieces]


def test_the_rule_hull_or_pieces_by_area():
    u = C.robot_footprint([(geo.Box((0.2, 0.3, 0.2)), Pose.identity()),
                           (geo.Box((0.15, 0.05, 0.2)), Pose(np.eye(3), np.array([0.175, 0.075, 0.0]))),
                           (geo.Box((0.15, 0.05, 0.2)), Pose(np.eye(3), np.array([0.175, -0.075, 0.0])))])
    assert u is not None and u.pieces is not None and len(u.pieces) == 3
    # the hull's area 0.06 + 0.15 (0.3 + 0.2) / 2 = 0.0975 against the union's 0.06 + 2 x 0.0075 = 0.075
    outlines = [C._outline((pc.points, pc.round)) for pc in u.pieces]
    assert C._union_area(outlines) == pytest.approx(0.075, abs=1e-15)
    assert C._area(C._hull(np.concatenate(outlines))) == pytest.approx(0.0975, abs=1e-15)
    assert u.points is not None and len(u.points) == 6          # the hull stays the broad phase's
    # convex enough: the hull, as before (one box; wheels inside a round body's disc; a bumper plate
    # as wide as the box body's front face)
    wheel = Pose(np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]), np.array([0.0, 0.1, 0.0]))
    assert C.robot_footprint([(geo.Box((0.5, 0.2, 0.2)), Pose.identity())]).pieces is None
    assert C.robot_footprint([(geo.Cylinder(0.2, 0.2), Pose.identity()), (geo.Cylinder(0.05, 0.01), wheel)]).pieces is None
    plate = Pose(np.eye(3), np.array([0.26, 0.0, 0.0]))
    assert C.robot_footprint([(geo.Box((0.5, 0.2, 0.2)), Pose.identity()),
                              (geo.Box((0.02, 0.2, 0.1)), plate)]).pieces is None
    # a box on a round body's side: the hull adds 7.6 % (the tangents from its corners): pieces
    bumper = Pose(np.eye(3), np.array([0.0, 0.25, 0.0]))
    mixed = C.robot_footprint([(geo.Cylinder(0.2, 0.2), Pose.identity()), (geo.Box((0.1, 0.1, 0.1)), bumper)])
    assert mixed.pieces is not None and len(mixed.pieces) == 2 and mixed.pieces[0].disc
    # two boxes sharing a face: their union is their hull, exactly
    halves = [C._hull(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])),
              C._hull(np.array([[1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]]))]
    assert C._union_area(halves) == pytest.approx(2.0, abs=1e-15)


def test_a_post_enters_the_notch_and_stops_on_the_body_front():
    # driven at 0.5 m/s at a post centred in the gap: the post passes between the fingers and the
    # robot stops with the body's front face touching it (the hull stopped it at the tips, x 0.725)
    sim = world([post(1.0)], [u_robot("r", 0.0, 0.0)])
    drive(sim, "r", 5.0)
    sim.run(100)
    x, y = xy(sim, "r")
    assert x == pytest.approx(1.0 - POST - FRONT, abs=1e-9) and x <= 1.0 - POST - FRONT and y == 0.0
    assert heading(sim, "r") == 0.0 and sim.counters["contacts"] > 0


def test_a_post_in_line_with_a_finger_stops_its_tip():
    sim = world([post(1.0, 0.075)], [u_robot("r", 0.0, 0.0)])
    drive(sim, "r", 5.0)
    sim.run(100)
    x, y = xy(sim, "r")
    assert x == pytest.approx(1.0 - POST - TIP, abs=1e-9) and x <= 1.0 - POST - TIP and y == 0.0


def test_a_post_in_the_notch_is_never_swept_through_by_a_finger():
    # the post against the body's front face, the robot spun both ways: a finger turning into the post
    # pushes the robot off it (the pieces' push), so the post ends in the notch's inner corner, touching
    # the body's front face and that finger's inner face, at (FRONT + POST, -/+(GAP / 2 - POST)) in the
    # robot's frame, and the robot pivots about it keeping its whole turn; no finger ever enters it
    # (the hull, overlapping the post, would not see it)
    sim = world([post(1.0)], [u_robot("r", 1.0 - POST - FRONT - 1e-6, 0.0)])
    ob = next(o for o in sim.contact._obs if o.name == "post")
    for w in (3.0, -3.0, 3.0):
        drive(sim, "r", -w, w)
        for _ in range(40):
            before = heading(sim, "r")
            sim.step()
            assert min(piece_gaps(sim, "r", ob)) >= -1e-9
            turned = math.remainder(heading(sim, "r") - before, math.tau)
            assert turned == pytest.approx(math.copysign(2.0 * 0.1 * 3.0 / 0.3 * STEP / 1000.0, w), abs=1e-12)
        h, (x, y) = heading(sim, "r"), np.array([1.0, 0.0]) - xy(sim, "r")      # to the post, seen from r
        assert x * math.cos(h) + y * math.sin(h) == pytest.approx(FRONT + POST, abs=1e-9)
        assert -x * math.sin(h) + y * math.cos(h) == pytest.approx(-math.copysign(GAP / 2 - POST, w), abs=1e-9)
    assert sim.counters["contacts"] > 0


def test_a_u_robot_flat_against_a_wall_is_pushed_off_as_it_turns():
    # its side flush with a wall: it turns in place, pushed off the wall by its hull's push, every
    # step keeping its whole turn, and no piece ever enters the wall
    sim = world([block("wall", -2.0, 2.0, 0.15, 0.5)], [u_robot("r", 0.0, 0.0)])
    ob = next(o for o in sim.contact._obs if o.name == "wall")
    drive(sim, "r", -2.0, 2.0)                  # 2 x 0.1 x 2 / 0.3 = 1.333 rad/s
    before = heading(sim, "r")
    turn = 2.0 * 0.1 * 2.0 / 0.3 * STEP / 1000.0
    for _ in range(60):
        sim.step()
        now = heading(sim, "r")
        assert math.remainder(now - before, math.tau) == pytest.approx(turn, abs=1e-12)
        assert min(piece_gaps(sim, "r", ob)) >= -1e-9
        before = now
    assert sim.counters["contacts"] > 0


def nosed_robot(name, x, yaw, **extra):
    """A body box 0.2 x 0.3 m with a nose 0.2 m long and 0.05 m wide ahead of its front face."""
    robot = box_robot(name, x, 0.0, yaw, size=(0.2, 0.3), **extra)
    robot["shapes"] = [{"name": "nose", "pose": {"translation": [0.2, 0.0, 0.0]},
                        "geometry": {"type": "box", "size": [0.2, 0.05, 0.2]}}]
    return robot


def test_a_connector_in_a_notch_docks_with_a_nose():
    # a's connector at the bottom of its notch (its body's front face), b's at its nose's tip: driven
    # together, the nose enters the notch and touches the body, the connectors meet and read presence
    # (the hulls stopped them 0.15 m apart: a's tips' line met b's nose)
    dock = [{"device": "Connector", "name": "dock", "pose": {"translation": [FRONT, 0, 0]}}]
    nose = [{"device": "Connector", "name": "dock", "pose": {"translation": [0.3, 0, 0]}}]
    sim = world(robots=[u_robot("a", 0.0, 0.0, devices=dock), nosed_robot("b", 1.0, math.pi, devices=nose)])
    assert all(f.pieces is not None for f in sim.contact.feet)
    dev = sim.device("a/dock")
    dev.enable(STEP)
    drive(sim, "a", 5.0)
    drive(sim, "b", 5.0)
    sim.run(60)
    assert xy(sim, "b")[0] - xy(sim, "a")[0] == pytest.approx(FRONT + 0.3, abs=1e-9)
    assert dev.value == 1


def _notch_world():
    walls = [block("n", -1.1, 1.1, 1.0, 1.1), block("s", -1.1, 1.1, -1.1, -1.0),
             block("e", 1.0, 1.1, -1.0, 1.0), block("w", -1.1, -1.0, -1.0, 1.0)]
    posts = [{**post(x, y), "name": f"post{k}"} for k, (x, y) in enumerate([(0.3, 0.2), (-0.4, -0.5), (0.6, -0.6)])]
    return parse_world({"world_info": {"basic_time_step": STEP},
                        "solids": [{"name": "floor", "geometry": {"type": "plane", "size": None}}, *walls, *posts],
                        "robots": [u_robot("a", -0.5, 0.3, 0.3), nosed_robot("b", 0.4, 2.5),
                                   box_robot("c", 0.0, -0.3, 1.0, size=(0.3, 0.2))]})


@pytest.mark.parametrize("native", [True, False])
def test_the_batched_engine_moves_pieces_robots_as_the_single_simulation_bit_for_bit(native):
    """Concave robots among posts and walls and one another, driven at random: the batched engine
    (its C drive pass and its numpy path) keeps the single simulation's poses and pressing flags
    bit for bit."""
    bs, singles = batched_and_singles(_notch_world, native, 3)
    assert [f.pieces is not None for f in bs.feet] == [True, True, False]        # two concave, one box
    rng = np.random.default_rng(11)
    for step in range(300):
        if step % 25 == 0:
            drive_randomly(bs, singles, rng)
        _step_both(bs, singles, step)
    assert bs.counters["contacts"] == sum(s.counters["contacts"] for s in singles) > 50


def _spin_once(sim, turn):
    """Robot r's wheels set to turn it in place by ``turn`` rad in one step, and that step run."""
    w = turn * 0.3 / (2 * 0.1 * STEP / 1000.0)
    drive(sim, "r", -w, w)
    sim.step()


@pytest.mark.parametrize("turn", [0.2, -0.25])
def test_a_finger_turned_into_a_post_in_the_notch_is_pushed_off_it_by_its_depth(turn):
    # the post centred in the notch 0.05 m ahead of the body's front face (x 0.15), the robot turned
    # in place by `turn` in one step: a finger's inner face (|y| = 0.05 in the robot's frame) swings
    # into the post; the pieces' push moves the centre along that face's normal by the finger's
    # depth in the post, 0.15 |sin turn| - 0.025, so the face touches it and the post stays in the
    # notch (before: the turn was cut short where the face first touched, asin(0.025 / 0.15))
    sim = world([post(0.15)], [u_robot("r", 0.0, 0.0)])
    ob = next(o for o in sim.contact._obs if o.name == "post")
    _spin_once(sim, turn)
    depth = 0.15 * abs(math.sin(turn)) - POST
    side = math.copysign(1.0, turn)          # turning left, the right finger comes: pushed to its right
    x, y = xy(sim, "r")
    assert heading(sim, "r") == pytest.approx(turn, abs=1e-12)
    assert x == pytest.approx(depth * abs(math.sin(turn)), abs=1e-9)
    assert y == pytest.approx(-side * depth * math.cos(turn), abs=1e-9)
    assert 0.0 <= min(piece_gaps(sim, "r", ob)) <= 1e-9                  # touching, not farther off
    assert sim.counters["contacts"] == 1


def test_a_u_robot_with_a_post_in_its_notch_turning_into_a_wall_is_pushed_off_the_wall_alone():
    # its left side flush with a wall and a post in its notch (x 0.2): turning left by 0.1 rad, the
    # body's front-left corner (0.1, 0.15) swings 0.1 sin 0.1 + 0.15 cos 0.1 - 0.15 into the wall;
    # the pieces are pushed straight off the wall by that much and the post stays where it was in
    # the notch (before: the hull's push was refused, as the hull overlaps the post, and so was the turn)
    sim = world([post(0.2), block("wall", -2.0, 2.0, 0.15, 0.5)], [u_robot("r", 0.0, 0.0)])
    _spin_once(sim, 0.1)
    x, y = xy(sim, "r")
    assert heading(sim, "r") == pytest.approx(0.1, abs=1e-12)
    assert x == 0.0 and y == pytest.approx(-(0.1 * math.sin(0.1) + 0.15 * math.cos(0.1) - 0.15), abs=1e-9)
    gaps = {o.name: min(piece_gaps(sim, "r", o)) for o in sim.contact._obs if o.name in ("post", "wall")}
    assert 0.0 <= gaps["wall"] <= 1e-9 and gaps["post"] > 0.01


def test_an_arm_swung_into_the_notch_stops_the_robot_earlier_by_its_reach():
    # an arm 0.3 x 0.05 m on a hinge about z through the origin, at load behind the body (x -0.4 to
    # -0.1): a piece of its own. Swung half a turn it lies in the notch and reaches 0.4 ahead, 0.15
    # past the fingers' tips: the robot driven at a wall stops with the arm's tip on it, 0.15 m
    # earlier than with the arm behind (the tips on it)
    wall = block("wall", 1.0, 1.2, -2.0, 2.0)
    for swung in (False, True):
        robot = u_robot("r", 0.0, 0.0)
        robot["shapes"].append({"name": "arm", "on_joint": "hinge", "pose": {"translation": [-0.25, 0.0, 0.0]},
                                "geometry": {"type": "box", "size": [0.3, 0.05, 0.1]}})
        robot["devices"] = [{"device": "RotationalMotor", "name": "hinge", "max_velocity": 100.0,
                             "max_torque": 1e5, "axis": [0, 0, 1]}]
        sim = world([wall], [robot])
        assert sim.contact.feet[0].pieces is not None and len(sim.contact.feet[0].pieces) == 4
        if swung:
            sim.robot("r").motor("hinge").set_position(math.pi)
            sim.step()
            assert float(max(pc.points[:, 0].max() for pc in sim.contact.feet[0].pieces)) == pytest.approx(0.4, abs=1e-12)
        drive(sim, "r", 5.0)
        sim.run(100)
        reach = 0.4 if swung else TIP
        x, y = xy(sim, "r")
        assert x == pytest.approx(1.0 - reach, abs=1e-9) and x <= 1.0 - reach and y == 0.0
