"""Kinematic contact with footprints that follow the robot's shape (sensorium/server/sim/contact.py):
a box robot is its rectangle turned with its heading, not the disc around it, so its faces stop
where they touch, it passes beside a wall its disc would have met, its corners cannot be turned
into a wall, and robots meet face to face. Wheels of radius 0.1 m at w rad/s move a robot
w * 0.1 m/s; every stopping point is a distance the geometry gives exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _fuzz import example_counts, seeds
from test_contact import drive, world, xy  # the same world, wheels and positions as the disc tests

from sensorium.server.sim import contact as C
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world

LONG, WIDE = 0.5, 0.2          # the box robot's length (along its heading) and width
STEP = 32


def box_robot(name, x, y, yaw=0.0, size=(LONG, WIDE), **extra):
    return {"name": name, "pose": {"translation": [x, y, 0.1], "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "box", "size": [size[0], size[1], 0.2]}},
            "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000.0}, **extra}


def heading(sim, name):
    r = sim.robot(name).pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


def corners(sim, name, size=(LONG, WIDE)):
    c, h = xy(sim, name), heading(sim, name)
    u, v = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    return np.array([c + sx * size[0] / 2 * u + sy * size[1] / 2 * v for sx in (-1, 1) for sy in (-1, 1)])


def block(name, x0, x1, y0, y1):
    """An upright box solid covering [x0, x1] x [y0, y1], 0.5 m tall."""
    return {"name": name, "pose": {"translation": [(x0 + x1) / 2, (y0 + y1) / 2, 0.25]},
            "geometry": {"type": "box", "size": [x1 - x0, y1 - y0, 0.5]}}


def test_a_box_robot_is_its_rectangle_and_a_centred_cylinder_stays_a_disc():
    foot = C.robot_footprint([(geo.Box((LONG, WIDE, 0.2)), Pose.identity())])
    assert foot is not None and not foot.disc and foot.round == 0.0
    assert sorted(map(tuple, foot.points.tolist())) == [(-0.25, -0.1), (-0.25, 0.1), (0.25, -0.1), (0.25, 0.1)]
    assert foot.radius == math.hypot(LONG, WIDE) / 2.0               # its broad-phase disc, as before
    disc = C.robot_footprint([(geo.Cylinder(0.2, 0.2), Pose.identity())])
    assert disc is not None and disc.disc and disc.radius == 0.2
    # a wheel inside a round body's disc adds nothing: the body's disc is the footprint
    wheel = Pose(np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]), np.array([0.0, 0.1, 0.0]))
    both = C.robot_footprint([(geo.Cylinder(0.2, 0.2), Pose.identity()), (geo.Cylinder(0.05, 0.01), wheel)])
    assert both is not None and both.disc
    # a round body with a part outside its disc: the hull of the part and the body's circumscribed
    # 16-gon, whose edges face ahead, behind and sideways (its front exactly the radius ahead)
    bumper = Pose(np.eye(3), np.array([0.0, 0.25, 0.0]))
    mixed = C.robot_footprint([(geo.Cylinder(0.2, 0.2), Pose.identity()), (geo.Box((0.1, 0.1, 0.1)), bumper)])
    assert mixed is not None and not mixed.disc and mixed.round == 0.0
    assert mixed.points[:, 0].max() == pytest.approx(0.2, abs=1e-15) and mixed.points[:, 1].max() == 0.3
    assert mixed.radius >= float(np.hypot(*mixed.points.T).max())


def test_driving_beside_a_wall_its_disc_would_touch_is_not_stopped():
    # a wall from x = 1 to 3 whose face is 0.15 m from the robot's centre line: its side (0.1 m)
    # passes clear; the disc of radius hypot(0.5, 0.2) / 2 = 0.269 m met the wall's corner and was
    # pushed aside
    wall = block("wall", 1.0, 3.0, 0.15, 0.35)
    sim = world([wall], [box_robot("r", 0.0, 0.0)])
    drive(sim, "r", 10.0)                                            # 1 m/s, 32 mm per step
    for _ in range(100):
        sim.step()
    assert sim.counters["contacts"] == 0
    x, y = xy(sim, "r")
    assert x == pytest.approx(100 * 0.032, abs=1e-9) and y == 0.0


@pytest.mark.parametrize("yaw", [0.0, math.pi / 2, 0.7])
def test_driving_head_on_into_a_wall_stops_with_the_front_face_touching(yaw):
    # the wall's face is 1.9 m ahead along the heading, square to it: the robot's front face stops
    # on it, its centre LONG / 2 short of it
    u = np.array([math.cos(yaw), math.sin(yaw)])
    v = np.array([-u[1], u[0]])
    centre = 2.0 * u
    wall = {"name": "wall", "pose": {"translation": [*centre, 0.25], "rotation": [0, 0, 1, yaw]},
            "geometry": {"type": "box", "size": [0.2, 4.0, 0.5]}}
    sim = world([wall], [box_robot("r", 0.0, 0.0, yaw)])
    drive(sim, "r", 10.0)
    for _ in range(120):
        sim.step()
    p = xy(sim, "r")
    assert float(p @ u) == pytest.approx(1.9 - LONG / 2.0, abs=1e-9)
    assert float(p @ v) == pytest.approx(0.0, abs=1e-9)
    assert sim.counters["contacts"] > 0


PER_STEP = 0.1 * 2 * 1.0 / 0.3 * STEP / 1000      # wheels -1 and +1 rad/s: 0.0213 rad a step


def test_a_long_robot_turning_beside_a_wall_is_pushed_off_it_and_turns_on():
    # a wall 0.15 m from its centre line, along it: turning in place, its corner (0.25, 0.1) reaches
    # 0.25 sin h + 0.1 cos h toward the wall at heading h; once that passes 0.15 the wall pushes the
    # centre off along its normal (-y), the corner left on the face, and the turn goes on (as a
    # Webots robot pivots off a wall), where it used to stop with the corner on the face
    wall = block("wall", -3.0, 3.0, 0.15, 0.35)
    sim = world([wall], [box_robot("r", 0.0, 0.0)])
    drive(sim, "r", -1.0, 1.0)
    for k in range(1, 51):                        # to 1.07 rad, short of the corner's farthest (1.19 rad)
        sim.step()
        h = heading(sim, "r")
        assert h == pytest.approx(k * PER_STEP, abs=1e-12)
        x, y = xy(sim, "r")
        assert abs(x) <= 1e-12
        assert y == pytest.approx(min(0.0, 0.15 - (0.25 * math.sin(h) + 0.1 * math.cos(h))), abs=1e-9)
        assert float(corners(sim, "r")[:, 1].max()) <= 0.15 + 1e-9
    assert y < -0.1 and sim.robot("r").pressing
    drive(sim, "r", 1.0, -1.0)                    # the other way: free, from where it was pushed
    sim.step()
    assert heading(sim, "r") == pytest.approx(h - PER_STEP, abs=1e-12)
    assert (xy(sim, "r") == (x, y)).all() and not sim.robot("r").pressing


def _flush_contact(walls):
    """A Contact of a 0.4 x 0.2 box robot at the origin, heading 0, among upright box ``walls``
    ((x0, x1, y0, y1) each)."""
    solids = [(f"w{i}", geo.Box((x1 - x0, y1 - y0, 0.5)), Pose.identity(),
               Pose(np.eye(3), np.array([(x0 + x1) / 2, (y0 + y1) / 2, 0.25])), True)
              for i, (x0, x1, y0, y1) in enumerate(walls)]
    return C.Contact(solids, [([(geo.Box((0.4, 0.2, 0.2)), Pose.identity())], Pose(np.eye(3), np.array([0.0, 0.0, 0.1])))])


def test_a_box_robot_flush_against_a_wall_turned_a_quarter_in_one_step_ends_half_its_length_off():
    # its long side on the wall's face y = 0.1: the whole quarter turn is kept and the centre pushed
    # along the face's normal until its short side touches the face: 0.2 (half its length) from it
    c = _flush_contact([(-3.0, 3.0, 0.1, 0.3)])
    for turn in (math.pi / 2, -math.pi / 2):
        c.place(0, Pose(np.eye(3), np.array([0.0, 0.0, 0.1])), 0.0)
        p, clipped, kept = c.resolve(0, (0.0, 0.0), (0.0, 0.0), (0.0, turn))
        assert kept == turn and clipped
        assert p[0] == 0.0 and 0.1 - p[1] == pytest.approx(0.2, abs=1e-9)
    assert c.contacts == 2


def test_a_box_robot_flush_against_a_wall_turning_a_quarter_stays_where_its_corner_pushed_it():
    # the same robot in a simulation, the quarter turn in 25 steps: each step's push leaves its corner
    # on the face, so the centre ends as far off as the corner reached at any step's heading h_k
    # (0.2 sin h_k + 0.1 cos h_k: up to hypot(0.2, 0.1) at 63.4°); nothing pulls it back afterwards
    sim = world([block("wall", -3.0, 3.0, 0.1, 0.3)], [box_robot("r", 0.0, 0.0, size=(0.4, 0.2))])
    w = (math.pi / 2 / 25) / PER_STEP
    drive(sim, "r", -w, w)
    reach = 0.1
    for _ in range(25):
        sim.step()
        h = heading(sim, "r")
        reach = max(reach, 0.2 * math.sin(h) + 0.1 * math.cos(h))
        assert 0.1 - xy(sim, "r")[1] == pytest.approx(reach, abs=1e-9)
        assert float(corners(sim, "r", (0.4, 0.2))[:, 1].max()) <= 0.1 + 1e-9
    assert h == pytest.approx(math.pi / 2, abs=1e-9)
    assert reach == pytest.approx(max(0.2 * math.sin(k * math.pi / 50) + 0.1 * math.cos(k * math.pi / 50)
                                      for k in range(26)), abs=1e-12)
    assert abs(xy(sim, "r")[0]) <= 1e-12


def _extent(h, along):
    """The 0.4 x 0.2 rectangle's half-extent at heading h along x (``along`` 0) or y (1)."""
    c, s = abs(math.cos(h)), abs(math.sin(h))
    return 0.2 * c + 0.1 * s if along == 0 else 0.2 * s + 0.1 * c


def _extent_over(h0, h1, along):
    """Its largest half-extent over the turn from h0 to h1 (< a quarter): at the ends, or at a peak
    between them (headings ±atan(1/2) mod π along x, ±atan(2) mod π along y)."""
    lo, hi = min(h0, h1), max(h0, h1)
    peak = math.atan(0.5) if along == 0 else math.atan(2.0)
    best = max(_extent(h0, along), _extent(h1, along))
    for base in (peak, -peak):
        k = math.ceil((lo - base) / math.pi)
        if base + k * math.pi <= hi:
            best = math.hypot(0.2, 0.1)
    return best


@pytest.mark.parametrize("rate", [1.0, 3.0, 10.0])
@pytest.mark.parametrize("sense", [1.0, -1.0])
@pytest.mark.parametrize("walls", ["wall", "corner"])
def test_a_box_robot_spinning_flush_against_walls_keeps_turning_pushed_off_as_far_as_it_reaches(walls, sense, rate):
    # spinning in place for turns on end, flush against a wall (its face y = 0.1) or in a corner (the
    # wall behind's face x = -0.2 too): every step keeps its whole turn, and the centre's distance
    # from each face follows the rectangle's half-extent along that face's normal. A step whose end
    # heading reaches beyond the distance so far is pushed to touch there; one whose end does not but
    # whose corner passed its farthest reach on the way (the diagonal's half, at atan(2) or atan(1/2)
    # off the face) is pushed off as far as the corner reached; nothing pulls it back. It used to stop
    # turning after a few steps, a corner's arc reaching past the face and no push taken
    solids = [block("n", -3.0, 3.0, 0.1, 0.3)] + ([block("w", -0.4, -0.2, -3.0, 3.0)] if walls == "corner" else [])
    sim = world(solids, [box_robot("r", 0.0, 0.0, size=(0.4, 0.2))])
    drive(sim, "r", -sense * rate, sense * rate)
    faces = [(1, 0.1, -1.0)] + ([(0, -0.2, 1.0)] if walls == "corner" else [])   # (axis, face, side)
    dist = {axis: _extent(0.0, axis) for axis, _, _ in faces}
    h0 = 0.0
    steps = int(3 * math.tau / (rate * PER_STEP)) + 1                             # three turns
    for k in range(1, steps + 1):
        sim.step()
        turned = sense * k * rate * PER_STEP
        h = heading(sim, "r")
        assert h == pytest.approx(math.remainder(turned, math.tau), abs=1e-9)
        c, centre = corners(sim, "r", (0.4, 0.2)), xy(sim, "r")
        for axis, face, side in faces:
            end = _extent(turned, axis)
            dist[axis] = end if end > dist[axis] + 1e-9 else max(dist[axis], _extent_over(h0, turned, axis))
            assert side * (centre[axis] - face) == pytest.approx(dist[axis], abs=1e-9)
            assert float(np.min(side * (c[:, axis] - face))) >= -1e-9
        if walls == "wall":
            assert centre[0] == 0.0
        h0 = turned
    assert all(d == pytest.approx(math.hypot(0.2, 0.1), abs=1e-9) for d in dist.values())


@pytest.mark.parametrize("rate", [1.0, 3.0, 7.0, 10.0])
@pytest.mark.parametrize("sense", [1.0, -1.0])
def test_a_square_robot_spinning_in_a_corner_keeps_turning_off_both_walls_at_once(sense, rate):
    # a 0.2 m square flush in a corner (faces y = 0.1 and x = -0.1): its half-extent along both
    # walls' normals, 0.1 (|cos h| + |sin h|), peaks at 45 degrees for both walls in the same step,
    # so a step passing it ends clear of both but sweeps into both: pushed off each by as far as
    # its corner reached, at once. It used to stop turning there for good, pressed every step (the
    # push off either wall alone left the sweep in the other), as the tutorials' e-puck did in
    # compound_solid.wbt's corner
    sim = world([block("n", -3.0, 3.0, 0.1, 0.3), block("w", -0.3, -0.1, -3.0, 3.0)],
                [box_robot("r", 0.0, 0.0, size=(0.2, 0.2))])
    drive(sim, "r", -sense * rate, sense * rate)
    def extent(h):
        return 0.1 * (abs(math.cos(h)) + abs(math.sin(h)))

    reach, h0 = 0.1, 0.0
    for k in range(1, int(math.tau / (rate * PER_STEP)) + 2):
        sim.step()
        turned = sense * k * rate * PER_STEP
        assert heading(sim, "r") == pytest.approx(math.remainder(turned, math.tau), abs=1e-9)
        # as a wall alone: an end reaching beyond pushes to touch there; else a peak passed (an odd
        # multiple of 45 degrees within the step) pushes as far as the corner reached
        peak = math.floor((max(h0, turned) - math.pi / 4) / (math.pi / 2)) >= math.ceil((min(h0, turned) - math.pi / 4) / (math.pi / 2))
        end = extent(turned)
        reach = end if end > reach + 1e-9 else max(reach, 0.1 * math.sqrt(2.0) if peak else end)
        h0 = turned
        centre, c = xy(sim, "r"), corners(sim, "r", (0.2, 0.2))
        assert centre[0] + 0.1 == pytest.approx(reach, abs=1e-9) and 0.1 - centre[1] == pytest.approx(reach, abs=1e-9)
        assert float(c[:, 0].min()) >= -0.1 - 1e-9 and float(c[:, 1].max()) <= 0.1 + 1e-9
    assert reach == 0.1 * math.sqrt(2.0)                  # a whole turn passes every peak


def test_a_box_robot_that_drove_head_on_into_a_wall_turns_away_and_drives_off():
    # its front face stops on the wall x = 1; turning in place both front corners would go in, so
    # it used to be held there for good; now the wall pushes it back (its centre 1 - (0.25 cos h +
    # 0.1 |sin h|) at most) while it turns a quarter, and it drives off along the wall
    sim = world([block("wall", 1.0, 1.2, -3.0, 3.0)], [box_robot("r", 0.0, 0.0)])
    drive(sim, "r", 10.0)
    for _ in range(40):
        sim.step()
    assert xy(sim, "r")[0] == pytest.approx(1.0 - LONG / 2, abs=1e-9)
    drive(sim, "r", 1.0, -1.0)                     # clockwise
    reach = LONG / 2
    for k in range(1, 75):
        sim.step()
        h = heading(sim, "r")
        assert h == pytest.approx(-k * PER_STEP, abs=1e-12)
        reach = max(reach, 0.25 * math.cos(h) + 0.1 * abs(math.sin(h)))
        x, y = xy(sim, "r")
        assert x == pytest.approx(1.0 - reach, abs=1e-9) and abs(y) <= 1e-12
        assert float(corners(sim, "r")[:, 0].max()) <= 1.0 + 1e-9
    assert h < -math.pi / 2
    drive(sim, "r", 10.0)                          # 32 mm a step, heading just past -90°
    for _ in range(20):
        sim.step()
    assert xy(sim, "r") == pytest.approx((x + 20 * 0.032 * math.cos(h), y + 20 * 0.032 * math.sin(h)), abs=1e-9)
    assert not sim.robot("r").pressing


def test_a_box_robot_turning_beside_another_is_pushed_off_it_and_the_other_stays():
    # two 0.4 x 0.2 robots side by side, long sides touching (y = 0.1): the first turns a quarter in
    # one step and is pushed 0.1 m off the second (its footprint now 0.4 tall, 0.2 wide); the second
    # does not move (robots push nothing: the turning one gives way)
    body = [(geo.Box((0.4, 0.2, 0.2)), Pose.identity())]
    c = C.Contact([], [(body, Pose(np.eye(3), np.array([0.0, 0.0, 0.1]))),
                       (body, Pose(np.eye(3), np.array([0.0, 0.2, 0.1])))])
    p, clipped, kept = c.resolve(0, (0.0, 0.0), (0.0, 0.0), (0.0, math.pi / 2))
    assert clipped and kept == math.pi / 2
    assert p[0] == 0.0 and p[1] == pytest.approx(-0.1, abs=1e-9) and p[1] <= -0.1
    assert (c.centres[1] == (0.0, 0.2)).all() and c.yaw[1] == 0.0


def test_a_turn_whose_end_is_past_a_thin_post_is_not_pushed_through_it():
    # a 0.5 x 0.04 rod turning 0.5 rad in one step past a post (radius 0.01) 0.2 m out at 0.49 rad:
    # at its end heading the rod lies 0.002 m past the post's centre, and the least push (0.018 m
    # along the rod's normal) would leave the post behind it, the rod through it: refused, the turn
    # is cut short before its face reaches the post (0.2 sin(0.49 - h) = 0.03)
    post = np.array([0.2 * math.cos(0.49), 0.2 * math.sin(0.49), 0.25])
    c = C.Contact([("post", geo.Cylinder(0.01, 0.5), Pose.identity(), Pose(np.eye(3), post), True)],
                  [([(geo.Box((0.5, 0.04, 0.2)), Pose.identity())], Pose(np.eye(3), np.array([0.0, 0.0, 0.1])))])
    p, clipped, kept = c.resolve(0, (0.0, 0.0), (0.0, 0.0), (0.0, 0.5))
    assert clipped and (p == 0.0).all()
    assert 0.0 < kept <= 0.49 - math.asin(0.15)


@pytest.mark.parametrize("sense", [1.0, -1.0])
def test_in_a_corner_a_turn_pushes_the_robot_off_both_walls_at_once(sense):
    # flush against two walls at once (y = -0.1 below, x = -0.2 behind): either way its turn puts a
    # corner into both, and a push off one alone leaves it in the other; the least move out of both
    # is diagonal, to where the turned rectangle touches both: its reach behind, 0.2 cos h + 0.1 sin |h|,
    # and below, 0.2 sin |h| + 0.1 cos h, at heading h. The reach behind grows until |h| = atan(1/2)
    # (22 steps); from there only the wall below pushes, and the centre stays as far off the wall
    # behind as the turn took it (nothing pulls it back)
    corner = [block("s", -3.0, 3.0, -0.3, -0.1), block("w", -0.4, -0.2, -3.0, 3.0)]
    sim = world(corner, [box_robot("r", 0.0, 0.0, size=(0.4, 0.2))])
    drive(sim, "r", -sense, sense)
    furthest = 0.0
    for k in range(1, 31):
        sim.step()
        h = heading(sim, "r")
        assert h == pytest.approx(sense * k * PER_STEP, abs=1e-12) and sim.robot("r").pressing
        a = abs(h)
        furthest = max(furthest, 0.2 * math.cos(a) + 0.1 * math.sin(a))
        x, y = xy(sim, "r")
        assert x == pytest.approx(furthest - 0.2, abs=1e-9)
        assert y == pytest.approx(0.2 * math.sin(a) + 0.1 * math.cos(a) - 0.1, abs=1e-9)
        c = corners(sim, "r", (0.4, 0.2))
        assert float(c[:, 0].min()) >= -0.2 - 1e-9 and float(c[:, 1].min()) >= -0.1 - 1e-9
    assert furthest == pytest.approx(math.hypot(0.2, 0.1), abs=1e-4)    # its diagonal's half, at atan(1/2)


def test_in_a_corridor_narrower_than_the_turn_the_turn_is_cut_short():
    # a corridor 0.21 m wide: the first step's push off the wall below (0.0043 m) fits, the next
    # would push it into the wall above (the footprint 0.4 sin h + 0.2 cos h across): cut short
    sim = world([block("s", -3.0, 3.0, -0.3, -0.1), block("n", -3.0, 3.0, 0.11, 0.3)],
                [box_robot("r", 0.0, 0.0, size=(0.4, 0.2))])
    drive(sim, "r", -1.0, 1.0)
    t = PER_STEP
    for _ in range(6):
        sim.step()
        assert heading(sim, "r") == pytest.approx(t, abs=1e-12)
        assert xy(sim, "r")[1] == pytest.approx(0.2 * math.sin(t) + 0.1 * math.cos(t) - 0.1, abs=1e-9)
        assert sim.robot("r").pressing
        c = corners(sim, "r", (0.4, 0.2))
        assert float(c[:, 1].min()) >= -0.1 - 1e-9 and float(c[:, 1].max()) <= 0.11 + 1e-9


def test_a_box_robot_whose_rear_face_rests_on_a_pane_s_end_turns_the_way_that_lifts_it():
    # a 0.4 x 0.2 robot whose rear face (x = -0.2) rests on the end of a thin pane (y in [-0.06,
    # -0.04], running back from x = -0.2): turning left swings that part of the face forward, off
    # the pane (a face point (-0.2, y < 0) goes to x = -0.2 cos h - y sin h > -0.2), so it turns the
    # whole step's turn each step and stays put; its other rear corner reaches the pane only past
    # 0.6 rad. It used to be held: the swept footprint's hull lay behind the rear face by about
    # lever x turn, "deeper" than touching, however small the turn
    pane = block("pane", -0.5, -0.2, -0.06, -0.04)
    sim = world([pane], [box_robot("r", 0.0, 0.0, size=(0.4, 0.2))])
    drive(sim, "r", -1.0, 1.0)
    for k in range(1, 11):
        sim.step()
        assert heading(sim, "r") == pytest.approx(k * PER_STEP, abs=1e-12)
        assert (xy(sim, "r") == 0.0).all() and not sim.robot("r").pressing
    # turning right swings it into the pane's corner (-0.2, -0.06): the pane pushes it off along the
    # rear face's normal, the least push, 0.2 (1 - cos h) + 0.06 sin h, to touching (as before)
    sim = world([pane], [box_robot("r", 0.0, 0.0, size=(0.4, 0.2))])
    drive(sim, "r", 1.0, -1.0)
    sim.step()
    h = heading(sim, "r")
    assert h == pytest.approx(-PER_STEP, abs=1e-12) and sim.robot("r").pressing
    d = 0.2 * (1.0 - math.cos(h)) + 0.06 * math.sin(-h)
    assert xy(sim, "r") == pytest.approx([d * math.cos(h), d * math.sin(h)], abs=1e-9)
    c = corners(sim, "r", (0.4, 0.2))
    rear = (c[0] + c[1]) / 2 - xy(sim, "r")
    assert float((np.array([-0.2, -0.06]) - xy(sim, "r")) @ rear) / 0.2 == pytest.approx(0.2, abs=1e-9)


def test_a_turn_is_tested_along_each_corner_s_arc_exactly():
    # a 0.4 x 0.2 box at the origin turning left by t; a wall y >= w above it: its corner (0.2, 0.1)
    # reaches 0.2 sin h + 0.1 cos h, largest at h = atan2(0.2, 0.1) (1.107 rad, 0.2236 m). A wall
    # just above the largest reach lets the whole half-turn through, one just below stops it: the
    # arc's top is found where it lies inside the turn, not only at its ends
    top = math.hypot(0.2, 0.1)
    for w, clear in ((top + 2e-9, True), (top - 1e-6, False)):
        c = C.Contact([("wall", geo.Box((6.0, 0.2, 0.5)), Pose.identity(), Pose(np.eye(3), np.array([0.0, w + 0.1, 0.25])), True)],
                      [([(geo.Box((0.4, 0.2, 0.2)), Pose.identity())], Pose(np.eye(3), np.array([0.0, 0.0, 0.1])))])
        foot = c.feet[0]
        ob = c._obs[0]
        p = np.zeros(2)
        now = [C._gap(p, *C._grown(ob, C._turned(foot.points, 0.0), foot.round, p))]
        assert now[0] == pytest.approx(w - 0.1, abs=1e-12)
        assert c._turn_clear(foot, p, 0.0, 2.0, [ob], now) is clear
        # the same turn from its far end back (the arc's top inside it again)
        back = [C._gap(p, *C._grown(ob, C._turned(foot.points, 2.0), foot.round, p))]
        assert c._turn_clear(foot, p, 2.0, -2.0, [ob], back) is clear


def test_two_box_robots_meet_face_to_face_at_the_sum_of_their_half_lengths():
    sim = world(robots=[box_robot("a", 0.0, 0.0), box_robot("b", 2.0, 0.0, math.pi, size=(0.3, 0.6))])
    drive(sim, "a", 10.0)
    drive(sim, "b", 10.0)
    for _ in range(60):
        sim.step()
    assert xy(sim, "b")[0] - xy(sim, "a")[0] == pytest.approx(LONG / 2 + 0.3 / 2, abs=1e-9)
    assert abs(xy(sim, "a")[1]) < 1e-12 and abs(xy(sim, "b")[1]) < 1e-12


def test_wide_robots_drive_their_front_connectors_together_and_dock():
    # Webots' connector sample in spirit: robots wider (0.6 m) than long (0.2 m), each with a
    # connector on its front face; their discs (radius 0.316 m) met 0.43 m before the connectors
    def bot(name, x, yaw):
        return box_robot(name, x, 0.0, yaw, size=(0.2, 0.6),
                         devices=[{"device": "Connector", "name": "dock", "pose": {"translation": [0.1, 0, 0]}}])
    sim = world(robots=[bot("a", 0.0, 0.0), bot("b", 1.0, math.pi)])
    dock = sim.device("a/dock")
    dock.enable(STEP)
    drive(sim, "a", 5.0)
    drive(sim, "b", 5.0)
    for _ in range(60):
        sim.step()
    assert xy(sim, "b")[0] - xy(sim, "a")[0] == pytest.approx(0.2, abs=1e-9)
    assert dock.value == 1


def _pen_world():
    """Three box robots in a 2 m square pen (walls 0.1 m thick), one a cylinder-bodied disc."""
    walls = [block("n", -1.1, 1.1, 1.0, 1.1), block("s", -1.1, 1.1, -1.1, -1.0),
             block("e", 1.0, 1.1, -1.0, 1.0), block("w", -1.1, -1.0, -1.0, 1.0)]
    disc = box_robot("c", 0.0, 0.5, 2.0)
    disc["body"] = {"geometry": {"type": "cylinder", "radius": 0.15, "height": 0.2}}
    return parse_world({"world_info": {"basic_time_step": STEP},
                        "solids": [{"name": "floor", "geometry": {"type": "plane", "size": None}}, *walls],
                        "robots": [box_robot("a", -0.4, 0.0, 0.3), box_robot("b", 0.4, -0.2, 2.5, size=(0.3, 0.6)),
                                   disc]})


def batched_and_singles(make_world, native: bool, n: int):
    """``n`` batched copies of ``make_world()`` (its C drive pass, or its numpy path when not
    ``native``; skipped without the packets helper) reset alike, and ``n`` single simulations of it."""
    from sensorium.server.raycast import packets
    from sensorium.server.sim.batched import BatchedSimulation
    if native and packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    bs = BatchedSimulation(make_world(), n)
    if not native:
        bs._drive_step = None
    bs.reset(np.arange(n), [1] * n)
    return bs, [Simulation(make_world()) for _ in range(n)]


def drive_randomly(bs, singles, rng) -> None:
    """Robots a, b, c of every copy and of its single simulation set to the same random wheel speeds."""
    lr = rng.uniform(-12.0, 12.0, (3, len(singles), 2))
    for r, name in enumerate("abc"):
        bs.set_wheels(r, lr[r, :, 0], lr[r, :, 1])
        for c, sim in enumerate(singles):
            drive(sim, name, lr[r, c, 0], lr[r, c, 1])


def _step_both(bs, singles, step):
    """One step of the batched simulation and of each copy's single one: the same poses, bit for
    bit, and the same pressing flags (robots a, b, c)."""
    bs.step()
    for c, sim in enumerate(singles):
        sim.step()
        for r, name in enumerate("abc"):
            pose = sim.robot(name).pose
            assert bs.pos[c, r].tobytes() == pose.translation.tobytes(), (step, c, name)
            assert bs.rot[c, r].tobytes() == pose.rotation.tobytes(), (step, c, name)
            assert bool(bs.pressing[c, r]) == sim.robot(name).pressing, (step, c, name)


@pytest.mark.parametrize("native", [True, False])
def test_the_batched_engine_clips_and_refuses_turns_as_the_single_simulation_bit_for_bit(native):
    """Shaped footprints in the batched engine (its numpy path and its C drive pass): every copy,
    driven with its own random wheel speeds into the walls and one another, keeps the single
    simulation's poses and pressing flags bit for bit, turns refused included."""
    n = 3
    bs, singles = batched_and_singles(_pen_world, native, n)
    rng = np.random.default_rng(7)
    held = 0                                  # steps a robot asked to turn and kept its heading
    for step in range(300):
        if step % 25 == 0:
            drive_randomly(bs, singles, rng)
        yaw_before = bs.yaw.copy()
        _step_both(bs, singles, step)
        held += int(np.count_nonzero((bs.yaw == yaw_before) & (bs.velocity[:, :, 0] != bs.velocity[:, :, 1])))
    assert bs.counters["contacts"] == sum(s.counters["contacts"] for s in singles) > 50
    assert held > 10


def _flush_pen_world():
    """Box robots lying flat against the walls of a 2 m pen and in its corner, and one head-on."""
    walls = [block("n", -1.1, 1.1, 1.0, 1.1), block("s", -1.1, 1.1, -1.1, -1.0),
             block("e", 1.0, 1.1, -1.0, 1.0), block("w", -1.1, -1.0, -1.0, 1.0)]
    return parse_world({"world_info": {"basic_time_step": STEP},
                        "solids": [{"name": "floor", "geometry": {"type": "plane", "size": None}}, *walls],
                        "robots": [box_robot("a", 0.0, 1.0 - WIDE / 2), box_robot("b", 1.0 - LONG / 2, 0.0),
                                   box_robot("c", -1.0 + LONG / 2, -1.0 + WIDE / 2)]})


@pytest.mark.parametrize("native", [True, False])
def test_the_batched_engine_pushes_turning_robots_off_walls_as_the_single_simulation_bit_for_bit(native, monkeypatch):
    """Robots flush against walls, head-on and in a corner, spun and driven at random: the batched
    engine (its C drive pass and its numpy path, whose broad phases grow a turning move by what its
    push may need) keeps the single simulation's poses, pressing flags and contacts bit for bit, the
    corner's pushes off both walls at once included."""
    pushes = []
    push = C.Contact._push

    def counted(self, *args):
        got = push(self, *args)
        pushes.append(got is not None)
        return got
    monkeypatch.setattr(C.Contact, "_push", counted)
    corner_pushes = []                        # pushes off both walls of the pen's corner (robot c's)
    both = C.Contact._push_off_both

    def counted_both(self, *args):
        got = both(self, *args)
        corner_pushes.append(got is not None)
        return got
    monkeypatch.setattr(C.Contact, "_push_off_both", counted_both)
    n = 3
    bs, singles = batched_and_singles(_flush_pen_world, native, n)
    rng = np.random.default_rng(11)
    for step in range(200):
        if step % 20 == 0:
            lr = rng.uniform(-12.0, 12.0, (3, n, 2))
            if step == 0:                     # first spin in place, against the walls
                lr[:, :, 1] = -lr[:, :, 0]
            for r, name in enumerate("abc"):
                bs.set_wheels(r, lr[r, :, 0], lr[r, :, 1])
                for c in range(n):
                    drive(singles[c], name, lr[r, c, 0], lr[r, c, 1])
        _step_both(bs, singles, step)
    assert bs.counters["contacts"] == sum(s.counters["contacts"] for s in singles) > 50
    # (every push is taken: the refusals this world used to see were the spins stuck against a wall
    # or in the corner where a corner's arc passed the peak of its reach, now pushed off that too)
    assert pushes.count(True) > 20 and corner_pushes.count(True) > 0


def test_a_drive_whose_forward_is_the_robot_s_y_axis_stops_with_the_face_along_y():
    # the body is long along the robot's own y, and the drive's forward is y: the footprint turns
    # with the drive's heading (its x axis's heading plus 90°), so the front face stops on the wall
    bot = box_robot("r", 0.0, 0.0, size=(WIDE, LONG))
    bot["differential_drive"]["forward"] = [0.0, 1.0]
    sim = world([block("wall", -2.0, 2.0, 1.9, 2.1)], [bot])
    drive(sim, "r", 10.0)
    for _ in range(120):
        sim.step()
    x, y = xy(sim, "r")
    assert y == pytest.approx(1.9 - LONG / 2.0, abs=1e-9) and abs(x) < 1e-12


def test_in_a_nue_world_a_box_robot_stops_with_its_face_on_the_wall_in_both_engines():
    # NUE (x north, y up, z east): a 0.5 m long box robot heading north at a wall whose face is at
    # x = 0.55 stops with its centre at 0.55 - 0.25, the single simulation and the batched alike
    from sensorium.schemas import world as wm
    from sensorium.server.sim.batched import BatchedSimulation
    w = wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "coordinate_system": "NUE"},
        "solids": [{"name": "wall", "pose": {"translation": [0.6, 0.1, 0.0]},
                    "geometry": {"type": "box", "size": [0.1, 0.2, 2.0]}}],
        "robots": [{"name": "bot", "pose": {"translation": [0.0, 0.1, 0.0]},
                    "body": {"geometry": {"type": "box", "size": [LONG, 0.2, WIDE]}},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10.0}}]})
    sim, bs = Simulation(w), BatchedSimulation(w, 2)
    drive(sim, "bot", 10.0)
    bs.set_wheels(0, np.full(2, 10.0), np.full(2, 10.0))
    for _ in range(200):                                  # 0.64 m asked for
        sim.step()
        bs.step()
    t = sim.robot("bot").pose.translation
    assert t[0] == pytest.approx(0.55 - LONG / 2.0, abs=1e-9) and t[1] == 0.1 and abs(t[2]) < 1e-15
    assert (bs.pos[:, 0] == t).all() and bs.pressing.all()


def test_a_box_robot_placed_into_a_wall_goes_no_deeper_and_backs_out():
    # its front face 5 cm inside the wall (placed so from outside): forward is refused, backward free
    sim = world([block("wall", 1.9, 2.1, -2.0, 2.0)], [box_robot("r", 1.9 - LONG / 2 + 0.05, 0.0)])
    start = xy(sim, "r")
    drive(sim, "r", 10.0)
    for _ in range(10):
        sim.step()
    assert (xy(sim, "r") == start).all() and sim.robot("r").pressing
    drive(sim, "r", -10.0)
    for _ in range(10):
        sim.step()
    assert xy(sim, "r")[0] == pytest.approx(start[0] - 10 * 0.032, abs=1e-9)
    assert not sim.robot("r").pressing


@pytest.mark.parametrize("seed", range(3))
def test_the_minkowski_merge_is_the_hull_of_all_differences(seed):
    """contact._minkowski (edges merged by direction) against the convex hull of every difference,
    random polygons and boxes turned alike (parallel edges, whose rounding it cleans): strictly
    convex, counter-clockwise, and the same set to 1e-12."""
    rng = np.random.default_rng(seed)
    box_a = np.array([[-0.3, -0.1], [0.3, -0.1], [0.3, 0.1], [-0.3, 0.1]])
    box_b = np.array([[-0.2, -0.25], [0.2, -0.25], [0.2, 0.25], [-0.2, 0.25]])
    for t in range(300):
        if t % 3 == 0:
            yaw = rng.uniform(-4.0, 4.0)
            a = C._turned(box_a, yaw) + rng.normal(size=2)
            b = C._turned(box_b, yaw + (math.pi if t % 2 else 0.0))
        else:
            a = C._hull(rng.normal(size=(int(rng.integers(3, 12)), 2)) * rng.uniform(0.01, 3.0))
            b = C._hull(rng.normal(size=(int(rng.integers(3, 12)), 2)) * rng.uniform(0.01, 3.0))
        if len(a) < 3 or len(b) < 3:
            continue
        m = np.array(C._minkowski(a.tolist(), (-b).tolist()))
        h = C._hull((a[:, None, :] - b[None]).reshape(-1, 2))
        for i in range(len(m)):
            o, p, q = m[i - 1], m[i], m[(i + 1) % len(m)]
            assert (p - o)[0] * (q - p)[1] - (p - o)[1] * (q - p)[0] > 0.0
        for v, other in [(v, m) for v in h] + [(v, h) for v in m]:
            assert abs(C._closest_on_list(float(v[0]), float(v[1]), other.tolist())[0]) < 1e-12


def _rect(c, yaw, half):
    u, v = np.array([math.cos(yaw), math.sin(yaw)]), np.array([-math.sin(yaw), math.cos(yaw)])
    return np.array([c + sx * half[0] * u + sy * half[1] * v for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def _depth(a, b):
    """How deep two convex polygons overlap (separating axes; <= 0: apart)."""
    best = math.inf
    for poly in (a, b):
        for i in range(len(poly)):
            e = poly[(i + 1) % len(poly)] - poly[i]
            n = np.array([e[1], -e[0]]) / math.hypot(*e)
            pa, pb = a @ n, b @ n
            best = min(best, min(pa.max() - pb.min(), pb.max() - pa.min()))
    return best


def _rect_gap(p, rect):
    """Signed distance from the point p to a rectangle (its 4 corners, counter-clockwise)."""
    c = rect.mean(axis=0)
    u = (rect[1] - rect[0]) / np.linalg.norm(rect[1] - rect[0])
    v = np.array([-u[1], u[0]])
    half = (np.linalg.norm(rect[1] - rect[0]) / 2, np.linalg.norm(rect[2] - rect[1]) / 2)
    q = np.abs([(p - c) @ u, (p - c) @ v]) - np.asarray(half)
    return float(np.hypot(max(q[0], 0.0), max(q[1], 0.0)) + min(max(q[0], q[1]), 0.0))


@pytest.mark.parametrize("seed", seeds(4))
def test_random_crowds_of_box_robots_never_penetrate(seed):
    """Random turned boxes and posts, box robots of random sizes with random curvy and spinning
    drives and big steps (up to 0.8 m and 1.3 rad a step): after every step no robot's rectangle
    overlaps an obstacle or another robot's by more than 1e-9 m (separating axes, independently)."""
    rng = np.random.default_rng(seed)
    boxes, posts, robots = [], [], []
    for _ in range(10):
        boxes.append((rng.uniform(-2, 2, 2), rng.uniform(0, math.pi), rng.uniform(0.05, 0.5, 2)))
        posts.append((rng.uniform(-2, 2, 2), rng.uniform(0.03, 0.2)))
    while len(robots) < 6:
        p, yaw, half = rng.uniform(-2, 2, 2), rng.uniform(-math.pi, math.pi), rng.uniform(0.04, 0.2, 2)
        me = _rect(p, yaw, half)
        if all(_depth(me, _rect(*b)) < -0.01 for b in boxes) and all(_rect_gap(c, me) > r + 0.01 for c, r in posts) \
                and all(_depth(me, _rect(*o)) < -0.01 for o in robots):
            robots.append((p, yaw, half))
    solids = [{"name": f"b{i}", "pose": {"translation": [*c, 0.25], "rotation": [0, 0, 1, y]},
               "geometry": {"type": "box", "size": [2 * h[0], 2 * h[1], 0.5]}} for i, (c, y, h) in enumerate(boxes)]
    solids += [{"name": f"p{i}", "pose": {"translation": [*c, 0.25]},
                "geometry": {"type": "cylinder", "radius": r, "height": 0.5}} for i, (c, r) in enumerate(posts)]
    sim = Simulation(parse_world({
        "world_info": {"basic_time_step": 200},
        "solids": [{"name": "floor", "geometry": {"type": "plane", "size": None}}, *solids],
        "robots": [box_robot(f"r{i}", *p, yaw, size=(2 * h[0], 2 * h[1])) for i, (p, yaw, h) in enumerate(robots)]}))
    held = 0
    for step in range(80):
        if step % 10 == 0:
            for i in range(len(robots)):
                drive(sim, f"r{i}", rng.uniform(-40, 40), rng.uniform(-40, 40))
        sim.step()
        rects = [_rect(xy(sim, f"r{i}"), heading(sim, f"r{i}"), h) for i, (_, _, h) in enumerate(robots)]
        for me in rects:
            for b in boxes:
                assert _depth(me, _rect(*b)) <= 1e-9
            for c, r in posts:
                assert _rect_gap(c, me) >= r - 1e-9
        for i in range(len(rects)):
            for j in range(i + 1, len(rects)):
                assert _depth(rects[i], rects[j]) <= 1e-9
        held += sum(sim.robot(f"r{i}").pressing for i in range(len(robots)))
    assert sim.counters["contacts"] > 0 and held > 0


def test_a_box_robot_meeting_a_wall_obliquely_slides_along_it_on_its_corner():
    # heading 30° into a wall whose face is x = 1.9: its front corner stops on the face, its centre
    # at 1.9 - (0.25 cos 30° + 0.1 sin 30°), and it keeps the part of each step along the wall
    yaw = math.radians(30.0)
    sim = world([block("wall", 1.9, 2.1, -5.0, 5.0)], [box_robot("r", 0.0, 0.0, yaw)])
    drive(sim, "r", 10.0)                                            # 32 mm a step
    for _ in range(100):
        sim.step()
    x, y0 = xy(sim, "r")
    assert x == pytest.approx(1.9 - (LONG / 2 * math.cos(yaw) + WIDE / 2 * math.sin(yaw)), abs=1e-9)
    sim.step()
    x1, y1 = xy(sim, "r")
    assert x1 == pytest.approx(x, abs=1e-12) and y1 - y0 == pytest.approx(0.032 * math.sin(yaw), abs=1e-12)
    assert heading(sim, "r") == pytest.approx(yaw, abs=1e-12) and sim.robot("r").pressing


@pytest.mark.parametrize("examples", example_counts(200))
def test_the_exact_turn_test_agrees_with_the_turn_sampled_densely(examples: int):
    # random footprints and obstacles (points, segments, polygons, round or not, wall lines, near and
    # 1e5 m from the origin, already overlapping or apart) turned by random amounts: where the arcs
    # say the turn holds the signed distance above its target, no sampled heading goes below it;
    # where they say it does not, a sampled heading comes within the sampling's reach (the largest
    # point of the turn missed between samples: 0.6 (pi / 400)^2 / 2 < 2e-5 m) of it: sound, and
    # not pessimistic beyond the sampling's reach
    rng = np.random.default_rng(7)
    for _ in range(examples):
        pts = C._hull(rng.uniform(-0.3, 0.3, (int(rng.integers(1, 6)), 2)))
        off = np.array([1e5, -1e5]) if rng.random() < 0.5 else np.zeros(2)
        q = C._hull(rng.uniform(-0.3, 0.3, (int(rng.integers(1, 6)), 2)) + rng.uniform(-0.5, 0.5, 2) + off)
        rnd, rho = float(rng.choice([0.0, 1e-12, 0.05])), float(rng.choice([0.0, 0.1]))
        if rng.random() < 0.15:
            n = rng.normal(size=2)
            n /= math.hypot(*n)
            ob = C.Obstacle("w", -1, np.zeros((1, 2)), 0.0, (0.0, 1.0), n, -float(n @ (off + rng.uniform(-0.3, 0.3, 2))))
        else:
            ob = C.Obstacle("o", -1, q, rho, (0.0, 1.0))
        yaw, turn = float(rng.uniform(-3, 3)), float(rng.uniform(-math.pi, math.pi))
        shape = C._turned(pts, yaw)
        now = C._gap(off, *C._grown(ob, shape, rnd, off))
        target = min(now, 0.0) - C.EPS
        least = min(C._gap(off, *C._grown(ob, C._turned(pts, yaw + u), rnd, off)) for u in np.linspace(0.0, turn, 401))
        if C.turn_gap_holds(shape, rnd, turn, ob, off, target):
            assert least >= target - 1e-10
        else:
            assert least < target + 2e-5


def test_a_rod_turning_across_a_parallel_segment_is_stopped():
    # a rod (a segment 0.6 m long through the centre) 0.05 m from a parallel segment obstacle: turned
    # by 0.5 rad it crosses it (0.3 sin h passes 0.05 at h = 0.167 rad within the segment's length),
    # the two overlapping as polygons -- once taken as never overlapping, being parallel at the start
    rod = np.array([[-0.3, 0.0], [0.3, 0.0]])
    seg = C.Obstacle("s", -1, np.array([[-0.3, 0.05], [0.3, 0.05]]), 0.0, (0.0, 1.0))
    p = np.zeros(2)
    assert C._gap(p, *C._grown(seg, rod, 0.0, p)) == pytest.approx(0.05, abs=1e-15)
    assert not C.turn_gap_holds(rod, 0.0, 0.5, seg, p, -C.EPS)
    assert C.turn_gap_holds(rod, 0.0, 0.16, seg, p, -C.EPS)      # 0.3 sin 0.16 = 0.0478 < 0.05


@pytest.mark.parametrize("gap", [0.0, 0.0056])
def test_a_box_robot_sliding_flush_along_boards_laid_end_to_end_passes_each_joint(gap):
    # a wall of two 0.1 m thick boards end to end along x (Webots' maze blocks: abutting, or a few mm
    # apart), their faces on y = 0.3; the 0.2 m square robot's left side lies on that line and it drives
    # along +x at 1 m/s: it meets the second board's end face only at its corner, in line with the face it
    # runs along, so nothing stops it (it stalled at x = 0.9 + gap, its corner on the joint)
    first = block("first", 0.0, 1.0, 0.3, 0.4)
    second = block("second", 1.0 + gap, 3.0, 0.3, 0.4)
    sim = world([first, second], [box_robot("r", 0.3, 0.2, size=(0.2, 0.2))])
    drive(sim, "r", 10.0)
    for _ in range(100):
        sim.step()
    x, y = xy(sim, "r")
    assert x == pytest.approx(0.3 + 100 * 0.032, abs=1e-9) and y == 0.2
    assert sim.counters["contacts"] == 0
    # a corner that reaches past the face line still meets the board's end: a robot 1 mm wider stops there
    sim = world([first, second], [box_robot("r", 0.3, 0.2, size=(0.2, 0.202))])
    drive(sim, "r", 10.0)
    for _ in range(100):
        sim.step()
    assert xy(sim, "r")[0] == pytest.approx(0.9 + gap, abs=1e-9)
