"""Kinematic contact's shortcuts give the answers of the long way, bit for bit
(sensorium/server/sim/contact.py; README "Kinematic contact", its cost): the screens that answer the
exact turn test before its arcs (a footprint touching at the start, a vertex inside at the turn's
end, a vertex and an edge nearer than the gap at the end), the grown obstacles made once per
heading, the distance and reach tests done once, the obstacles' bounds and offset edges made in
plain floats, and the moves near nothing ended all at once. Each against the long way on random
and adversarial cases (touching within rounding of EPS / 2 and EPS, overlapping, thin, far from the
origin), and each shown to be taken."""

from __future__ import annotations

import math
from contextlib import contextmanager
from unittest import mock

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.server.sim import contact as C

FUZZ = settings(max_examples=300, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow])
EPS = C.EPS


@contextmanager
def _no_screens():
    """turn_gap_holds without its screens: the arcs answer every case."""
    with mock.patch.object(C, "_start_touching", lambda *a: False), \
            mock.patch.object(C, "_inside_in_turn", lambda *a: False), \
            mock.patch.object(C, "_end_nearer", lambda *a: False):
        yield


def _polygon(rng: np.random.Generator, kind: str, size: float) -> np.ndarray:
    if kind == "box":
        w, h = size * rng.uniform(0.2, 1.0), size * rng.choice([rng.uniform(0.2, 1.0), 1e-12])
        pts = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2.0
        return C._turned(pts, float(rng.uniform(-math.pi, math.pi)))
    if kind == "point":
        return np.zeros((1, 2))
    if kind == "segment":
        return C._hull(np.array([[-size / 2, 0.0], [size / 2, 0.0]]) @ np.array([[0.6, 0.8], [-0.8, 0.6]]))
    return C._hull(rng.normal(size=(int(rng.integers(3, 9)), 2)) * size / 2.0)


def _case(seed: int):
    """A footprint and an obstacle placed at a chosen signed distance (adversarial: around 0, EPS / 2,
    EPS, the back-off, overlapping), a turn and where: (shape, rnd, turn, ob, p, gap)."""
    rng = np.random.default_rng(seed)
    shape = _polygon(rng, str(rng.choice(["box", "box", "poly", "segment"])), float(rng.uniform(0.05, 0.5)))
    rnd = float(rng.choice([0.0, 0.0, 0.0, 1e-3, 0.02]))
    kind = str(rng.choice(["box", "box", "poly", "point", "segment"]))
    far = float(rng.choice([0.0, 0.0, 0.0, 10.0, 1e3, 1e5]))
    centre = rng.uniform(-1.0, 1.0, 2) * far
    q = _polygon(rng, kind, float(rng.uniform(0.05, 1.0))) + centre
    radius = float(rng.choice([0.0, 0.05])) if kind in ("point", "segment") else float(rng.choice([0.0, 0.0, 1e-3]))
    ob = C.Obstacle("ob", -1, q, radius, (0.0, 1.0))
    p = centre + rng.normal(size=2) * 0.3
    g, rho = C._grown(ob, shape, rnd, p)
    gap, normal = C._gap_normal(p, g, rho)
    want = float(rng.choice([0.0, 1e-12, -1e-12, 2e-10, 4.99e-10, 5e-10, 5.01e-10, 9.9e-10, 1e-9, 1.01e-9,
                             3e-9, -3e-10, -2e-9, 1e-6, -1e-4, 1e-3, 0.05, rng.uniform(-0.05, 0.2)]))
    p = p + (want - gap) * normal
    gap = C._gap(p, *C._grown(ob, shape, rnd, p))
    turn = float(rng.choice([1.0, -1.0])) * float(rng.choice([1e-9, 1e-6, 1e-3, 0.03, 0.2, 0.7, 2.0, 3.1]))
    return shape, rnd, turn, ob, p, gap


def _both(shape, rnd, turn, ob, p, gap) -> tuple[bool, bool]:
    target = min(gap, 0.0) - EPS
    screened = C.turn_gap_holds(shape, rnd, turn, ob, p, target, gap)
    with _no_screens():
        exact = C.turn_gap_holds(shape, rnd, turn, ob, p, target)
    return screened, exact


@pytest.mark.parametrize("examples", example_counts(2500, share=2))
def test_the_turn_screens_answer_as_the_arcs_on_adversarial_cases_and_are_taken(examples):
    fired = {"_start_touching": 0, "_inside_in_turn": 0, "_end_nearer": 0}
    real = {name: getattr(C, name) for name in fired}

    def counted(name):
        def f(*a):
            got = real[name](*a)
            fired[name] += got
            return got
        return f

    answers = {True: 0, False: 0}
    with mock.patch.multiple(C, **{name: counted(name) for name in fired}):
        for seed in range(examples):
            case = _case(seed)
            screened, exact = _both(*case)
            assert screened == exact, (seed, case)
            answers[exact] += 1
    # every screen answered many cases, and both answers came up often
    assert min(fired.values()) > 20, fired
    assert min(answers.values()) > 300, answers


@FUZZ
@given(seed=st.integers(0, 2**32 - 1))
def test_the_turn_screens_answer_as_the_arcs(seed):
    case = _case(seed)
    screened, exact = _both(*case)
    assert screened == exact, case


def test_a_box_pressed_on_a_wall_turning_into_it_is_answered_without_the_arcs():
    # a 0.4 x 0.2 m box flush against a wall box, its heading along the wall, turning into it: the
    # turn test is answered by the start screen (touching), the push follows as before
    wall = C.Obstacle("wall", -1, np.array([[-2.0, 0.0], [2.0, 0.0], [2.0, 0.1], [-2.0, 0.1]]), 0.0, (0.0, 1.0))
    foot = C.Footprint(math.hypot(0.2, 0.1), -0.05, 0.05, np.array([[-0.2, -0.1], [0.2, -0.1], [0.2, 0.1], [-0.2, 0.1]]))
    ct = C.Contact([], [])
    ct.feet = [foot]
    p = np.array([0.3, -0.1 - 1e-12])
    arcs = []
    real = C._arc_to_segments
    with mock.patch.object(C, "_arc_to_segments", lambda *a: arcs.append(1) or real(*a)):
        end, clipped, kept = ct._clip_shaped(foot, p.copy(), np.zeros(2), 0.0, 0.1, [wall])
    assert arcs == []
    # pushed off to where the turned box touches the wall: its half-height turned, plus the corner
    want_y = -(0.1 * math.cos(0.1) + 0.2 * math.sin(0.1))
    assert clipped and kept == 0.1
    assert abs(end[0] - 0.3) < 1e-9 and abs(end[1] - want_y) < 1e-9


def test_a_grown_obstacle_is_made_once_per_heading_with_the_same_bits():
    ob = C.Obstacle("crate", -1, C._hull(np.array([[0.0, 0.0], [0.3, 0.05], [0.25, 0.4], [-0.1, 0.3]])), 0.0, (0.0, 1.0))
    shape = C._turned(np.array([[-0.1, -0.05], [0.1, -0.05], [0.1, 0.05], [-0.1, 0.05]]), 0.3)
    made = []
    real = C._minkowski
    with mock.patch.object(C, "_minkowski", lambda a, b: made.append(1) or real(a, b)):
        g1, r1 = C._grown(ob, shape, 0.01, np.array([1.0, 1.0]))
        g2, r2 = C._grown(ob, shape.copy(), 0.01, np.array([-3.0, 2.0]))     # a polygon: where p is does not matter
        g3, _ = C._grown(ob, C._turned(shape, 1e-16 + 0.0), 0.01, np.zeros(2))
    assert g1 is g2 and r1 == r2 == 0.01 and len(made) == 1 + (g3 is not g1)
    fresh = C.Obstacle(ob.name, ob.owner, np.array(real(ob.points.tolist(), (-shape).tolist())), ob.radius, ob.z_range,
                       edge_normals=True)
    assert fresh.points.tobytes() == g1.points.tobytes()
    assert fresh.lo.tobytes() == g1.lo.tobytes() and fresh.hi.tobytes() == g1.hi.tobytes()
    # another heading's bits, another obstacle
    g4, _ = C._grown(ob, C._turned(shape, 1e-3), 0.01, np.zeros(2))
    assert g4 is not g1


def _numpy_bounds(pts: np.ndarray, radius: float):
    """Obstacle.__post_init__'s numpy way (the reference)."""
    same = (pts == np.roll(pts, -1, axis=0)).all(axis=1)
    if same.any():
        pts = pts[:1] if same.all() else pts[~same]
    if len(pts) == 1:
        return pts, pts[0] - radius, pts[0] + radius
    return pts, pts.min(axis=0) - radius, pts.max(axis=0) + radius


def test_an_obstacles_bounds_in_plain_floats_are_numpys_bits():
    rng = np.random.default_rng(5)
    specials = [0.0, -0.0, 1e-300, -1e-300, 1e5, -1e5, math.inf, -math.inf, math.nan, 1e308, -1e308]
    for _ in range(4000):
        n = int(rng.integers(2, 20))
        pts = rng.normal(size=(n, 2)) * float(rng.choice([1e-12, 1.0, 1e5]))
        for _ in range(int(rng.integers(0, 3))):
            pts[rng.integers(n), rng.integers(2)] = rng.choice(specials)
        if rng.random() < 0.2:
            k = int(rng.integers(n))
            pts[(k + 1) % n] = pts[k]
        radius = float(rng.choice([0.0, 0.1, 1e-12]))
        ob = C.Obstacle("o", -1, pts.copy(), radius, (0.0, 1.0))
        want_pts, lo, hi = _numpy_bounds(pts, radius)
        assert ob.points.tobytes() == want_pts.tobytes()
        assert ob.lo.tobytes() == lo.tobytes() and ob.hi.tobytes() == hi.tobytes(), (pts.tolist(), radius)
        lx, ly, hx, hy, v = C._flat(C.Obstacle("o", -1, pts.copy(), radius, (0.0, 1.0)))
        assert np.array([lx, ly, hx, hy]).tobytes() == np.concatenate([lo, hi]).tobytes()
        assert np.array(v).tobytes() == want_pts.tobytes()


def _numpy_edges(pts: np.ndarray, rad: float) -> list:
    """_hull_data's edges the numpy way (the reference)."""
    n = len(pts)
    edges = []
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        e = b - a
        out = np.array([e[1], -e[0]]) / math.hypot(e[0], e[1])
        A, B = a + rad * out, b + rad * out
        edges.append((A, B, out, float(A[0]), float(A[1]), float(out[0]), float(out[1])))
    return edges


def test_offset_edges_in_plain_floats_are_numpys_bits():
    rng = np.random.default_rng(9)
    for _ in range(1500):
        scale = float(rng.choice([1e-12, 1e-3, 1.0, 1e5]))
        pts = C._hull(rng.normal(size=(int(rng.integers(2, 9)), 2)) * scale + rng.uniform(-1, 1, 2) * float(rng.choice([0.0, 1e5])))
        if len(pts) < 2:
            continue
        rad = float(rng.choice([0.0, 0.035, 0.1 + 1e-17, 12.5]))
        ob = C.Obstacle("o", -1, pts, 0.0, (0.0, 1.0))
        v, edges = C._hull_data(ob, rad)
        assert v == pts.tolist()
        for got, want in zip(edges, _numpy_edges(pts, rad), strict=True):
            assert all(np.asarray(g).tobytes() == np.asarray(w).tobytes() for g, w in zip(got, want))


def test_distances_and_reach_lists_found_once_are_the_same():
    rng = np.random.default_rng(11)
    obs = [C.Obstacle(f"o{i}", -1, C._hull(rng.normal(size=(int(rng.integers(1, 7)), 2)) * 0.2 + rng.uniform(-1, 1, 2)),
                      float(rng.choice([0.0, 0.05])), (0.0, 1.0)) for i in range(12)]
    obs.append(C.Obstacle("wall", -1, np.zeros((1, 2)), 0.0, (-math.inf, math.inf), np.array([0.6, 0.8]), -0.3))
    for _ in range(800):
        p = rng.uniform(-1.2, 1.2, 2)
        d = rng.normal(size=2) * float(rng.choice([0.0, 0.01, 0.3]))
        for ob in obs:
            if ob.normal is None:
                want = C._closest_on_list(float(p[0]), float(p[1]), ob.points.tolist())[0]
                assert np.float64(C._closest_dist(float(p[0]), float(p[1]), ob.points.tolist())).tobytes() == np.float64(want).tobytes()
        r1 = float(rng.uniform(0.05, 0.4))
        turning = rng.random() < 0.8
        near, reached = C._in_reaches(obs, p, r1 if turning else None, d, 0.1, {})
        assert near == (C._in_reach(obs, p, C._STILL, r1) if turning else [])
        assert reached == C._in_reach(obs, p, d, 0.1)


def test_robots_near_nothing_end_at_once_and_skip_the_narrow_phase():
    # four box robots far apart and one pair of robots near each other: the far ones end at start +
    # (end - start) without a narrow phase, the pair goes through it in order
    box = C.Footprint(math.hypot(0.1, 0.05), -0.05, 0.05, np.array([[-0.1, -0.05], [0.1, -0.05], [0.1, 0.05], [-0.1, 0.05]]))
    ct = C.Contact([], [])
    n = 6
    ct.feet = [box] * n
    ct._radius = np.full(n, box.radius)
    ct._spin = C.spin_reach(ct.feet)
    ct._z_low, ct._z_high = np.full(n, box.z_low), np.full(n, box.z_high)
    ct.centres = np.array([[0.0, 0.0], [5.0, 0.0], [0.0, 5.0], [-5.0, 0.0], [3.0, 3.0], [3.3, 3.0]])
    ct.heights = np.zeros(n)
    ct.yaw = np.zeros(n)
    starts = ct.centres.copy()
    ends = starts + np.array([[0.01, 0.003], [-0.02, 0.0], [0.0, 0.013], [0.007, -0.004], [0.08, 0.0], [-0.08, 0.0]])
    yaws = np.array([[0.0, 0.01], [0.0, -0.02], [0.0, 0.0], [0.0, 0.3], [0.0, 0.0], [0.0, 0.0]])
    narrow = []
    real = C.Contact._clip_shaped
    with mock.patch.object(C.Contact, "_clip_shaped", lambda self, *a: narrow.append(1) or real(self, *a)):
        out = ct.resolve_all(list(range(n)), starts, ends, yaws)
    assert len(narrow) == 2                        # the pair only
    for m in range(4):
        p, clipped, kept = out[m]
        assert p.tobytes() == (starts[m] + (ends[m] - starts[m])).tobytes() and not clipped and kept == yaws[m, 1]
        assert ct.centres[m].tobytes() == p.tobytes() and ct.yaw[m] == kept
    # the pair: the first moves on (the second's face is 0.02 m ahead of its end), the second, resolved
    # after it, stops at its new face
    assert not out[4][1] and out[4][0].tobytes() == (starts[4] + (ends[4] - starts[4])).tobytes()
    assert out[5][1] and abs(out[5][0][0] - (3.08 + 0.2)) < 1e-9 and out[5][0][1] == 3.0


def test_a_box_spinning_against_walls_is_answered_without_the_arcs():
    # a 0.4 x 0.2 m box robot spinning in place flush against a wall, and in a corner of two: every
    # turn test it meets is answered by the screens (before: the arcs, about four per step)
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import parse_world

    def world(x, y):
        solids = [{"name": "floor", "geometry": {"type": "plane", "size": None}},
                  {"name": "north", "geometry": {"type": "box", "size": [4, 0.1, 0.3]}, "pose": {"translation": [0, 0.45, 0.15]}},
                  {"name": "east", "geometry": {"type": "box", "size": [0.1, 4, 0.3]}, "pose": {"translation": [0.55, 0, 0.15]}}]
        bots = [{"name": "bot", "pose": {"translation": [x, y, 0.025]}, "differential_drive": {},
                 "body": {"geometry": {"type": "box", "size": [0.4, 0.2, 0.05]}}}]
        return {"world_info": {"basic_time_step": 32}, "solids": solids, "robots": bots}

    arcs = []
    real = C._arc_to_segments
    with mock.patch.object(C, "_arc_to_segments", lambda *a: arcs.append(1) or real(*a)):
        for x, y in ((-0.5, 0.3 - 1e-9), (0.3 - 1e-9, 0.3 - 1e-9)):
            sim = Simulation(parse_world(world(x, y)))
            left, right = sim.robot("bot").motors.values()
            for m, v in ((left, -8.0), (right, 8.0)):
                m.set_position(math.inf)
                m.set_velocity(v)
            sim.run(60)
            # pushed off while its corners pass their farthest reach toward the walls (the first
            # quarter turn or so), then spinning clear of them
            assert sim.counters["contacts"] >= 7 and sim.counters["contact_checks"] > 50
    assert arcs == []
