"""Kinematic contact (sensorium/server/sim/contact.py) against closed forms.

Wheels of radius 0.1 m at w rad/s move a robot w * 0.1 m/s; bodies are upright cylinders (discs
in the plane), so every stopping point is a contact distance that geometry gives exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _fuzz import seeds

from sensorium.server.sim import contact as C
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world

R = 0.2          # robot body radius


def robot(name, x, y, yaw=0.0, radius=R, **extra):
    return {"name": name, "pose": {"translation": [x, y, 0.1], "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "cylinder", "radius": radius, "height": 0.2}},
            "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000.0}, **extra}


def world(solids=(), robots=(), step=32, contact=True):
    return Simulation(parse_world({"world_info": {"basic_time_step": step, "contact": contact},
                                   "solids": [{"name": "floor", "geometry": {"type": "plane", "size": None}},
                                              *solids],
                                   "robots": list(robots)}))


def drive(sim, name, left, right=None):
    for m, w in zip(sim.robot(name).motors.values(), (left, left if right is None else right)):
        m.set_position(math.inf)
        m.set_velocity(w)


def xy(sim, name):
    return sim.robot(name).pose.translation[:2].copy()


WALL = {"name": "wall", "pose": {"translation": [2.0, 0.0, 0.25]}, "geometry": {"type": "box", "size": [0.2, 4.0, 0.5]}}


def test_robot_driven_into_a_wall_stops_at_the_contact_distance():
    sim = world([WALL], [robot("r", 0.0, 0.0)])
    drive(sim, "r", 5.0)                                   # 0.016 m per step
    sim.run(200)
    x, y = xy(sim, "r")
    assert x == pytest.approx(1.9 - R, abs=1e-9) and x <= 1.9 - R and y == 0.0
    assert sim.counters["contacts"] > 0
    before = sim.counters["contacts"]
    sim.run(5)                                             # still pushing: does not move, keeps counting
    assert xy(sim, "r")[0] == x and sim.counters["contacts"] == before + 5
    drive(sim, "r", -5.0)                                  # backing off is free
    sim.step()
    assert xy(sim, "r")[0] == pytest.approx(x - 0.016, abs=1e-12)


def test_switch_off_lets_the_robot_pass_and_counts_nothing():
    sim = world([WALL], [robot("r", 0.0, 0.0)], contact=False)
    drive(sim, "r", 5.0)
    sim.run(200)
    assert xy(sim, "r")[0] == pytest.approx(200 * 0.016) and sim.counters["contacts"] == 0
    sim = Simulation(world([WALL], [robot("r", 0.0, 0.0)]).loaded, contact=False)   # the in-process switch
    drive(sim, "r", 5.0)
    sim.run(200)
    assert xy(sim, "r")[0] > 3.0


def test_two_robots_head_on_stop_apart():
    sim = world([], [robot("a", 0.0, 0.0), robot("b", 1.0, 0.0, yaw=math.pi, radius=0.1)])
    drive(sim, "a", 3.0)
    drive(sim, "b", 7.0)
    sim.run(100)
    a, b = xy(sim, "a"), xy(sim, "b")
    gap = float(np.linalg.norm(b - a))
    assert gap == pytest.approx(R + 0.1, abs=1e-9) and gap >= R + 0.1
    assert abs(a[1]) < 1e-9 and abs(b[1]) < 1e-9         # b heads along pi: sin(pi) = 1.2e-16 makes tiny offsets
    sim.run(10)
    assert xy(sim, "a") == pytest.approx(a, abs=1e-9) and xy(sim, "b") == pytest.approx(b, abs=1e-9)


@pytest.mark.parametrize("angle_deg", [1.0, 5.0, 30.0])
def test_grazing_at_high_speed_with_large_steps_does_not_tunnel(angle_deg):
    # a thin wall (1 cm) along y = 1; the robot heads toward it at a shallow angle, 2.5 m per step
    thin = {"name": "thin", "pose": {"translation": [0.0, 1.0, 0.25]}, "geometry": {"type": "box", "size": [100.0, 0.01, 0.5]}}
    a = math.radians(angle_deg)
    sim = world([thin], [robot("r", -40.0, 1.0 - 0.005 - R - 0.3, yaw=a)], step=500)
    drive(sim, "r", 50.0)                                  # 5 m/s
    face = 1.0 - 0.005
    ys = []
    for _ in range(30):
        sim.step()
        x, y = xy(sim, "r")
        ys.append(y)
        assert y + R <= face + 1e-9, f"penetrated at x={x}"
    assert ys[-1] == pytest.approx(face - R, abs=1e-9)     # slid along the wall, touching it
    assert xy(sim, "r")[0] > -40.0 + 30 * 2.5 * math.cos(a) * 0.5   # and kept moving along it


def test_oblique_contact_slides_along_the_wall():
    sim = world([WALL], [robot("r", 1.0, 0.0, yaw=math.radians(45.0))])
    drive(sim, "r", 5.0)
    sim.run(100)
    x, y = xy(sim, "r")
    assert x == pytest.approx(1.9 - R, abs=1e-9)
    # the tangential part of every step was kept: y advanced as if the wall were not there
    assert y == pytest.approx(100 * 0.016 * math.sin(math.radians(45.0)), abs=1e-9)


def test_round_obstacles_and_height_bands():
    post = {"name": "post", "pose": {"translation": [1.0, 0.0, 0.5]}, "geometry": {"type": "cylinder", "radius": 0.1, "height": 1.0}}
    ball = {"name": "ball", "pose": {"translation": [1.0, 2.0, 0.3]}, "geometry": {"type": "sphere", "radius": 0.25}}
    high = {"name": "shelf", "pose": {"translation": [1.0, 4.0, 1.0]}, "geometry": {"type": "box", "size": [0.5, 0.5, 0.1]}}
    sim = world([post, ball, high], [robot("p", 0.0, 0.0), robot("s", 0.0, 2.0), robot("h", 0.0, 4.0)])
    for name in ("p", "s", "h"):
        drive(sim, name, 5.0)
    sim.run(150)
    assert xy(sim, "p")[0] == pytest.approx(1.0 - 0.1 - R, abs=1e-9)
    # the sphere's widest section within the body's band z in [0, 0.2] is at z = 0.2: sqrt(r^2 - 0.1^2)
    assert xy(sim, "s")[0] == pytest.approx(1.0 - math.sqrt(0.25 ** 2 - 0.1 ** 2) - R, abs=1e-9)
    assert xy(sim, "h")[0] == pytest.approx(150 * 0.016)  # the shelf is above the robot


def test_moved_solid_is_seen_and_set_pose_is_not_checked():
    sim = world([WALL], [robot("r", 0.0, 0.0)])
    sim.set_solid_pose("wall", [1.0, 0.0, 0.25])           # translation alone keeps the rotation
    drive(sim, "r", 5.0)
    sim.run(100)
    assert xy(sim, "r")[0] == pytest.approx(0.9 - R, abs=1e-9)
    sim.robot("r").set_pose([3.0, 0.0, 0.1])               # a supervisor may put it anywhere
    assert xy(sim, "r")[0] == 3.0
    sim.step()
    assert xy(sim, "r")[0] == pytest.approx(3.016, abs=1e-12)


def test_a_robot_placed_overlapping_a_solid_or_a_robot_can_back_out():
    """Contact does not check a pose set from outside (world file, Supervisor move): a robot put
    1-5 cm into a wall used to be held there for good unless one step took it fully clear (at
    3.2 mm per step it never moved again, backing away or sliding along). Now a move that ends
    no deeper than it starts is free, and one going deeper is still stopped."""
    start = 1.9 - R + 0.03                                 # 3 cm into the wall's face x = 1.9
    sim = world([WALL], [robot("r", start, 0.0)])
    drive(sim, "r", -1.0)                                  # backing away, 3.2 mm per step
    sim.run(20)
    assert xy(sim, "r")[0] == pytest.approx(start - 20 * 0.0032, abs=1e-12)
    assert sim.counters["contacts"] == 0
    sim = world([WALL], [robot("r", start, 0.0, yaw=math.pi / 2)])
    drive(sim, "r", 1.0)                                   # sliding along the wall, still in it
    sim.run(20)
    assert xy(sim, "r") == pytest.approx([start, 20 * 0.0032], abs=1e-12)
    sim = world([WALL], [robot("r", start, 0.0)])
    drive(sim, "r", 1.0)                                   # deeper in: stopped where it is
    sim.run(5)
    assert xy(sim, "r")[0] == start and sim.counters["contacts"] == 5
    # two robots placed 5 cm into each other part; a vertical plane (a wall line) lets go too
    sim = world([], [robot("a", 0.0, 0.0), robot("b", 2 * R - 0.05, 0.0, yaw=math.pi)])
    drive(sim, "a", -1.0)
    drive(sim, "b", -1.0)
    sim.run(10)
    assert xy(sim, "b")[0] - xy(sim, "a")[0] == pytest.approx(2 * R - 0.05 + 20 * 0.0032, abs=1e-12)
    plane = {"name": "w", "pose": {"translation": [1.0, 0.0, 0.0], "rotation": [0, 1, 0, math.pi / 2]},
             "geometry": {"type": "plane", "size": [4.0, 4.0]}}
    sim = world([plane], [robot("r", 1.0 - R + 0.03, 0.0)])
    drive(sim, "r", -1.0)
    sim.run(10)
    assert xy(sim, "r")[0] == pytest.approx(1.0 - R + 0.03 - 10 * 0.0032, abs=1e-12)


def test_overlapping_moves_never_go_deeper():
    """From random starts inside a box's grown footprint (up to 10 cm deep), random moves: the
    robot ends no deeper than it started, but for contact's rounding slack (4e-15 of the coordinates,
    contact.deepest_end; 1e-9, the touching tolerance, before), and a move straight out of it is never
    stopped."""
    box = C.obstacle("b", -1, geo.Box((0.6, 0.3, 1.0)), Pose.from_axis_angle((0, 0, 1), 0.4, (0.2, -0.1, 0.0)))
    c = C.Contact([], [], None)
    half, yaw, centre = np.array([0.3, 0.15]), 0.4, np.array([0.2, -0.1])
    rng = np.random.default_rng(3)
    freed = 0
    for _ in range(400):
        p = centre + rng.uniform(-0.5, 0.5, 2)
        depth = R - _rect_distance(p, centre, yaw, half)
        if not 0.0 < depth < 0.1:
            continue
        d = rng.normal(size=2) * 10.0 ** rng.uniform(-4, 0)
        end, clipped = c._clip(p.copy(), d, R, [box])
        assert R - _rect_distance(end, centre, yaw, half) <= depth + 1e-14
        out = C._closest_on_hull(p, box.points)[1]
        end, clipped = c._clip(p.copy(), 0.01 * out, R, [box])
        freed += not clipped
        assert not clipped and end == pytest.approx(p + 0.01 * out, abs=1e-15)
    assert freed > 50
    # moves in by 5e-10 m each (under the 1e-9 m tolerance), across the box's +y face: from 3 cm deep none is
    # taken; from touching they take the robot no further in than the tolerance, however many (before, each
    # was allowed: 2.5e-9 m in after 5)
    up = np.array([-math.sin(yaw), math.cos(yaw)])            # the face's outward normal
    for depth0, most in ((0.03, 0.03), (0.0, C.EPS)):
        p = centre + (half[1] + R - depth0) * up
        for _ in range(5):
            p, _ = c._clip(p, -5e-10 * up, R, [box])
        assert R - _rect_distance(p, centre, yaw, half) <= most + 1e-15, (depth0, R - _rect_distance(p, centre, yaw, half))


def test_time_of_impact_closed_forms():
    box = C.obstacle("b", -1, geo.Box((2.0, 2.0, 1.0)), Pose.identity())
    # a point 0.5 from the box's corner region, moving diagonally in: hits the rounded corner
    s, n = C.time_of_impact(np.array([3.0, 3.0]), np.array([-2.0, -2.0]), box, 0.5)
    corner_hit = 1.0 + 0.5 / math.sqrt(2.0)
    assert 3.0 - 2.0 * s == pytest.approx(corner_hit, abs=1e-12)
    assert n == pytest.approx([1 / math.sqrt(2), 1 / math.sqrt(2)], abs=1e-12)
    # a face: x = 1 + 0.5
    s, n = C.time_of_impact(np.array([4.0, 0.3]), np.array([-4.0, 0.0]), box, 0.5)
    assert 4.0 - 4.0 * s == pytest.approx(1.5, abs=1e-12) and list(n) == [1.0, 0.0]
    # moving away while touching, and missing: no impact
    assert C.time_of_impact(np.array([1.5, 0.0]), np.array([1.0, 0.0]), box, 0.5)[0] == math.inf
    assert C.time_of_impact(np.array([4.0, 3.0]), np.array([-4.0, 0.0]), box, 0.5)[0] == math.inf
    # a vertical infinite plane is a two-sided wall line
    wall = C.obstacle("w", -1, geo.Plane(None), Pose.from_axis_angle((0, 1, 0), math.pi / 2, (5.0, 0.0, 0.0)))
    s, n = C.time_of_impact(np.array([0.0, 0.0]), np.array([10.0, 0.0]), wall, 0.5)
    assert 10.0 * s == pytest.approx(4.5, abs=1e-12)
    s, _ = C.time_of_impact(np.array([9.0, 0.0]), np.array([-10.0, 0.0]), wall, 0.5)
    assert 9.0 - 10.0 * s == pytest.approx(5.5, abs=1e-12)
    # the floor plane never blocks
    assert C.obstacle("f", -1, geo.Plane(None), Pose.identity()) is None


def test_deterministic():
    def run():
        sim = world([WALL], [robot("a", 0.0, 0.0, yaw=0.3), robot("b", 0.5, 0.5, yaw=-2.0)])
        drive(sim, "a", 5.0, 4.0)
        drive(sim, "b", 6.0, 5.5)
        sim.run(300)
        return xy(sim, "a").tolist() + xy(sim, "b").tolist()
    assert run() == run()


def _rect_distance(p, centre, yaw, half):
    """Distance from point p to an upright box's footprint (a rotated rectangle)."""
    c, s = math.cos(yaw), math.sin(yaw)
    d = np.asarray(p) - np.asarray(centre)
    local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
    q = np.abs(local) - np.asarray(half)
    return float(np.hypot(max(q[0], 0.0), max(q[1], 0.0)) + min(max(q[0], q[1]), 0.0))


@pytest.mark.parametrize("seed", range(6))
def test_random_crowds_never_penetrate(seed):
    """Random upright boxes and posts, robots with random curvy drives and big steps: after every
    step no robot overlaps an obstacle or another robot by more than 1e-9 m."""
    rng = np.random.default_rng(seed)
    boxes, posts, robots = [], [], []
    for _ in range(10):
        boxes.append((rng.uniform(-2, 2, 2), rng.uniform(0, math.pi), rng.uniform(0.05, 0.5, 2)))
        posts.append((rng.uniform(-2, 2, 2), rng.uniform(0.03, 0.2)))
    while len(robots) < 6:
        p, r = rng.uniform(-2, 2, 2), rng.uniform(0.05, 0.15)
        if all(_rect_distance(p, c, y, h) > r for c, y, h in boxes) and all(np.hypot(*(p - c)) > r + pr for c, pr in posts) \
                and all(np.hypot(*(p - q)) > r + qr for q, qr, _ in robots):
            robots.append((p, r, rng.uniform(0, 2 * math.pi)))
    solids = [{"name": f"b{i}", "pose": {"translation": [*c, 0.25], "rotation": [0, 0, 1, y]},
               "geometry": {"type": "box", "size": [2 * h[0], 2 * h[1], 0.5]}} for i, (c, y, h) in enumerate(boxes)]
    solids += [{"name": f"p{i}", "pose": {"translation": [*c, 0.25]},
                "geometry": {"type": "cylinder", "radius": r, "height": 0.5}} for i, (c, r) in enumerate(posts)]
    sim = world(solids, [robot(f"r{i}", *p, yaw=yaw, radius=r) for i, (p, r, yaw) in enumerate(robots)], step=200)
    for i in range(len(robots)):
        drive(sim, f"r{i}", rng.uniform(5, 40), rng.uniform(5, 40))       # up to 0.8 m per step
    for _ in range(60):
        sim.step()
        pos = [xy(sim, f"r{i}") for i in range(len(robots))]
        for (_, r, _), p in zip(robots, pos):
            for c, y, h in boxes:
                assert _rect_distance(p, c, y, h) >= r - 1e-9
            for c, pr in posts:
                assert np.hypot(*(p - c)) >= r + pr - 1e-9
        for i in range(len(robots)):
            for j in range(i + 1, len(robots)):
                assert np.hypot(*(pos[i] - pos[j])) >= robots[i][1] + robots[j][1] - 1e-9
    assert sim.counters["contacts"] > 0


# ---------------------------------------------------------------------- time_of_impact's skips
# The hull path skips vertex circles and offset edges whose answer is certainly inf or beyond the
# move (s > 1) on float tests with margins (contact._circle_beyond, _edge_beyond) and keeps each
# obstacle's offset edges (_hull_data). _reference_toi is the path as it was before: every feature
# tested with numpy, every call; both must give the same (s, normal), bit for bit.

def _reference_toi(p, d, ob, rho):
    pts = ob.points
    rad = ob.radius + rho
    dist, normal = C._closest_on_hull(p, pts)
    if dist - rad <= C.EPS:                  # touching: an impact when the move goes in by more than EPS
        if float(normal @ d) < -C.EPS:
            return 0.0, normal
        end_dist, _ = C._closest_on_hull(p + d, pts)
        return (0.0, normal) if end_dist - rad < min(dist - rad, 0.0) - C.EPS else (math.inf, None)
    best, best_n = math.inf, None
    n = len(pts)
    for i in range(n):
        s = C._ray_circle(p, d, pts[i], rad)
        if s < best:
            best, best_n = s, (p + s * d - pts[i]) / rad
    if n >= 2:
        for i in range(n):
            a, b = pts[i], pts[(i + 1) % n]
            e = b - a
            out = np.array([e[1], -e[0]]) / math.hypot(e[0], e[1])
            s = C._ray_segment(p, d, a + rad * out, b + rad * out, out)
            if s < best:
                best, best_n = s, out
    if best > 1.0:
        return math.inf, None
    return best, best_n


def _same(got, want) -> bool:
    (s1, n1), (s2, n2) = got, want
    if np.float64(s1).tobytes() != np.float64(s2).tobytes():
        return False
    return (n1 is None and n2 is None) or (n1 is not None and n2 is not None and n1.tobytes() == n2.tobytes())


def _moves_near(rng, ob: C.Obstacle, rho: float, count: int):
    """Moves aimed at the obstacle's grown boundary: random ones, grazing a vertex circle at
    radius (1 + delta), ending on (or a hair before or past) a vertex circle or an offset edge,
    and starting there (within a few EPS: touching or not)."""
    rad = ob.radius + rho
    pts = ob.points
    deltas = (0.0, 1e-16, -1e-16, 1e-13, -1e-13, 1e-10, -1e-10, 1e-7, -1e-7, 1e-5, -1e-5)
    offsets = (0.0, 5e-10, -5e-10, 1e-9, -1e-9, 1.5e-9, -1.5e-9, 3e-9, 1e-8)
    for _ in range(count):
        kind = rng.integers(6)
        u = rng.normal(size=2)
        u /= np.hypot(*u)
        length = 10.0 ** rng.uniform(-4, 0.5)
        if kind == 0:       # anywhere around
            p = pts.mean(axis=0) + rng.uniform(-3, 3, size=2)
            yield p, u * length
            continue
        c = pts[rng.integers(len(pts))]
        if kind == 1:       # a line passing at rad (1 + delta) from a vertex, its closest point near the end
            side = np.array([-u[1], u[0]])
            h = rad * (1.0 + deltas[rng.integers(len(deltas))])
            closest = c + h * side
            t_end = rng.choice([1.0, 1.0 - 1e-12, 1.0 + 1e-12, 0.5, 2.0])
            p = closest - t_end * length * u
            yield p, u * length
            continue
        if kind >= 4:       # starting on the grown boundary, give or take a few EPS
            w = rng.normal(size=2)
            w /= np.hypot(*w)
            start = c + (rad + offsets[rng.integers(len(offsets))]) * w
            if kind == 5 and len(pts) >= 2:     # on an offset edge instead
                i = rng.integers(len(pts))
                a, b = pts[i], pts[(i + 1) % len(pts)]
                e = b - a
                out = np.array([e[1], -e[0]]) / math.hypot(e[0], e[1])
                start = a + rng.uniform(0.0, 1.0) * e + (rad + offsets[rng.integers(len(offsets))]) * out
            yield start, u * length
            continue
        if kind == 2:       # ending on a vertex circle (a hair before or past it)
            w = rng.normal(size=2)
            q = c + rad * (1.0 + deltas[rng.integers(len(deltas))]) * w / np.hypot(*w)
        else:               # ending on an offset edge
            if len(pts) < 2:
                continue
            i = rng.integers(len(pts))
            a, b = pts[i], pts[(i + 1) % len(pts)]
            e = b - a
            out = np.array([e[1], -e[0]]) / math.hypot(e[0], e[1])
            q = a + rng.uniform(-0.01, 1.01) * e + rad * (1.0 + deltas[rng.integers(len(deltas))]) * out
        p = q - u * length
        yield p, u * length


@pytest.mark.parametrize("seed", seeds(6))
def test_time_of_impact_skips_give_the_exhaustive_answer_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    finite = skipped_any = touching = clear = swept = 0
    for _ in range(60):
        n = int(rng.integers(1, 14))
        scale = 10.0 ** rng.uniform(-2, 1)
        centre = rng.uniform(-1, 1, size=2) * (1000.0 if rng.random() < 0.2 else 1.0)
        pts = C._hull(centre + rng.normal(size=(n, 2)) * scale)
        ob = C.Obstacle("ob", -1, pts, float(rng.choice([0.0, rng.uniform(0.0, 0.3)])), (0.0, 1.0))
        rho = float(rng.uniform(0.005, 0.5) if rng.random() < 0.85 else rng.uniform(5.0, 100.0))   # (a few huge robots)
        for p, d in _moves_near(rng, ob, rho, 120):
            got = C.time_of_impact(p, d, ob, rho)
            want = _reference_toi(p, d, ob, rho)
            assert _same(got, want), (pts.tolist(), ob.radius, rho, p.tolist(), d.tolist(), got, want)
            finite += math.isfinite(want[0])
            rad = ob.radius + rho
            touching += C._closest_on_hull(p, pts)[0] - (ob.radius + rho) <= C.EPS
            got_clear = C._clear_of(float(p[0]), float(p[1]), float(d[0]), float(d[1]), rad, C._hull_data(ob, rad)[1])
            clear += got_clear == 1
            swept += got_clear == C._SWEPT_CLEAR
            skipped_any += any(C._circle_beyond(float(p[0] - x), float(p[1] - y), float(d[0]), float(d[1]),
                                                float(d @ d), rad) for x, y in pts.tolist())
    # every outcome, many times
    assert finite > 1000 and skipped_any > 1000 and touching > 300 and clear > 300 and swept > 300


def test_time_of_impact_keeps_its_answers_through_a_solid_s_cached_edges():
    box = C.obstacle("box", -1, geo.Box((2.0, 2.0, 1.0)), Pose.identity())
    first = C.time_of_impact(np.array([3.0, 0.3]), np.array([-4.0, 0.0]), box, 0.5)
    again = C.time_of_impact(np.array([3.0, 0.3]), np.array([-4.0, 0.0]), box, 0.5)
    assert first[0] == again[0] == pytest.approx(0.375) and np.array_equal(first[1], [1.0, 0.0])
    first[1][0] = 7.0                       # the caller's normal is its own: the cached edge is unchanged
    assert np.array_equal(C.time_of_impact(np.array([3.0, 0.3]), np.array([-4.0, 0.0]), box, 0.5)[1], [1.0, 0.0])
    assert list(box.grown) == [0.5]         # one entry per grown radius
