"""EXACT's repair rule: one robust Embree cast, then a float64 second look only for the rays that
can be wrong (sensorium/server/raycast/guards.py explains why these are exactly the rays passing
close to a *risky* edge: a boundary edge, or an edge between two faces at an angle).

Every ray here is adversarial: aimed at a shared edge of two triangles (a box face's diagonal), a
box edge (a silhouette for rays that graze it), a corner (vertex), the seam between two separate
boxes that touch, or the boundary of an open mesh, then nudged sideways by 0 to 1e-5 m -- below
float32's resolution at these coordinates.  Each answer is compared with the float64 closed form
(ray/box slabs).  The same rays through a single cast with no repair, and through FAST, do leak
(counted), so these tests can fail; with the guards EXACT leaks none, and it is never farther from
the closed form than the former offset-copy repair (forced on the same rays).
"""

import zlib

import numpy as np
import pytest
import trimesh

from sensorium.server.raycast import tiers
from sensorium.server.raycast.engine import Precision, RayEngine, ShapeEntry
from sensorium.server.raycast.guards import risky_edges
from sensorium.server.world.geometry import Box, Mesh, Pose, tessellate

# (size, centre): a wall with a box in front of it (silhouettes over a nearby surface), two boxes
# side by side sharing a face plane (a seam between separate meshes), a board resting on a post
# (touching at an angle), a free-standing crate, a floor slab under everything
BOXES = [((0.2, 6.0, 3.0), (3.0, 0.0, 1.5)), ((0.6, 0.8, 1.0), (2.2, -0.5, 0.5)),
         ((0.5, 1.0, 0.9), (-2.0, 1.0, 0.45)), ((0.5, 1.0, 0.9), (-2.0, 2.0, 0.45)),
         ((0.1, 0.1, 1.2), (0.5, -2.0, 0.6)), ((1.2, 0.4, 0.05), (0.5, -2.0, 1.225)),
         ((0.7, 0.7, 0.7), (-0.8, -0.4, 0.35)), ((8.0, 8.0, 0.1), (0.0, 0.0, -0.05))]
# an open mesh: a 4x4-quad flat square at z = 2.5, normal +z (interior edges coplanar: safe)
SQUARE = (np.array([-1.5, 0.5]), np.array([-0.5, 1.5]), 2.5)
TAU = 2e-8
SIDE = [0.0, 1e-9, -1e-9, 1e-8, -1e-8, 1e-7, -1e-7, 1e-6, -1e-6, 1e-5, -1e-5]


def _grid_square(n=4):
    (x0, x1), (y0, y1), z = (SQUARE[0][0], SQUARE[0][1]), (SQUARE[1][0], SQUARE[1][1]), SQUARE[2]
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    v = np.array([(x, y, z) for y in ys for x in xs])
    f = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            f += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    return v, np.array(f)


def _engine(base, landmark=False, copies=1, shift=0.0):
    """The scene at ``base``; ``copies`` > 1: pasted again at the same poses, each copy moved by
    ``shift`` m along (1, 1, 1) from the last (0: the same shapes at the same poses)."""
    e = RayEngine(Precision.EXACT)
    v, f = _grid_square()
    square = Mesh(v + base, f, closed=False)
    for k in range(copies):
        at = np.add(base, k * shift)
        for size, c in BOXES:
            e.add_body([ShapeEntry(Box(size), Pose.from_axis_angle((0, 0, 1), 0.0, np.add(at, c)), True, True)],
                       Pose.identity())
        e.add_body([ShapeEntry(square, Pose.from_axis_angle((0, 0, 1), 0.0, at - base), True, True)], Pose.identity())
    if landmark:   # one static tier from the origin to base: a coarse float32 frame (res ~1 mm at 1e4 m)
        e.add_body([ShapeEntry(Box((1, 1, 1)), Pose.identity(), True, True)], Pose.identity())
    return e


def _closed_form(o, d, grow=0.0, face=False):
    """Float64 first hit over the boxes and the square (all axis-aligned: slabs), each grown by
    ``grow`` on every side (negative: shrunk).  o, d in the scene's local frame.  ``face``: also
    the entry face hit, as box * 3 + axis (-1: none)."""
    lo = [np.subtract(c, np.divide(s, 2)) - grow for s, c in BOXES]
    hi = [np.add(c, np.divide(s, 2)) + grow for s, c in BOXES]
    lo.append(np.array([SQUARE[0][0] - grow, SQUARE[1][0] - grow, SQUARE[2]]))
    hi.append(np.array([SQUARE[0][1] + grow, SQUARE[1][1] + grow, SQUARE[2]]))
    lo, hi = np.array(lo), np.array(hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo[None] - o[:, None]) / d[:, None]
        t2 = (hi[None] - o[:, None]) / d[:, None]
    near = np.where(np.isnan(t1), -np.inf, np.minimum(t1, t2))
    tn = near.max(axis=2)
    tf = np.nanmin(np.maximum(t1, t2), axis=2)
    t = np.where((tn <= tf) & (tn > 1e-9), tn, np.inf)
    if not face:
        return t.min(axis=1)
    box = t.argmin(axis=1)
    axis = near[np.arange(len(o)), box].argmax(axis=1)
    best = t[np.arange(len(o)), box]
    second = np.sort(t, axis=1)[:, 1]
    return best, np.where(np.isfinite(best), box * 3 + axis, -1), second


def _targets():
    """Points on shared edges (face diagonals), box edges, corners, the seam between the two
    touching boxes, and the open square's boundary and interior edges."""
    pts = []
    rng = np.random.default_rng(11)
    for size, c in BOXES:
        v, f = tessellate(Box(size))
        v = v + c
        for a, b in trimesh.Trimesh(v, f, process=False).edges_unique:   # box edges and face diagonals
            for s in (0.0, 1.0, 0.5, *rng.uniform(0, 1, 3)):
                pts.append(v[a] + s * (v[b] - v[a]))
    for s in rng.uniform(0, 1, 24):   # the seam line on the touching boxes' common top face edge
        pts.append([-2.0 + 0.25 * (2 * s - 1), 1.5, 0.9])
        pts.append([-2.25, 1.5, 0.9 * s])
    v, f = _grid_square()
    for a, b in trimesh.Trimesh(v, f, process=False).edges_unique:
        for s in (0.0, 0.5, *rng.uniform(0, 1, 2)):
            pts.append(v[a] + s * (v[b] - v[a]))
    return np.array(pts)


def _rays(seed):
    """Rays from viewpoints around the scene through every target, nudged sideways by SIDE."""
    rng = np.random.default_rng(seed)
    tgt = _targets()
    eyes = np.array([[0.3, 0.2, 1.5], [-3.5, -3.0, 2.8], [2.0, 3.5, 0.9], [-0.5, -3.6, 0.2], [-1.0, 1.0, 3.5]])
    os, ds = [], []
    for eye in eyes:
        d = tgt - eye
        d /= np.linalg.norm(d, axis=1)[:, None]
        for side in SIDE:
            n = rng.normal(size=d.shape)
            n -= (n * d).sum(1)[:, None] * d
            n /= np.linalg.norm(n, axis=1)[:, None]
            p = tgt + side * n
            dd = p - eye
            ds.append(dd / np.linalg.norm(dd, axis=1)[:, None])
            os.append(np.broadcast_to(eye, d.shape))
    return np.vstack(os), np.vstack(ds)


def _judge(o, d, t, tol):
    """(wrong, err): ``wrong`` marks the rays whose distance is not consistent with the geometry to
    within TAU (the float64 test's barycentric tolerance, 1e-9 of a triangle: ~1e-8 m here):
    between the closed form's answers with every surface grown and shrunk by TAU (a miss allowed
    when the shrunk scene misses).  ``err`` = |t - closed form| on the rays whose answer is the
    same face with every surface grown or shrunk by TAU and no other box within 1e-6 m along the
    ray (clear of edges and seams), else 0."""
    ref, f0, _ = _closed_form(o, d, face=True)
    big, f1, second = _closed_form(o, d, TAU, face=True)
    small, f2, _ = _closed_form(o, d, -TAU, face=True)
    with np.errstate(invalid="ignore"):
        ok = (t >= big - tol) & ((t <= small + tol) | np.isinf(small))
        ok |= np.isinf(t) & np.isinf(small)
        clear = (f0 == f1) & (f0 == f2) & (second > big + 1e-6)   # one face, no other box near
        err = np.where(clear & np.isfinite(ref), np.abs(t - ref), 0.0)
    err[clear & (np.isinf(ref) != np.isinf(t))] = np.inf
    return ~ok, err


def _cast(o, d, base, landmark, monkeypatch=None, mode="guards", prec=Precision.EXACT):
    e = _engine(base, landmark)
    e.precision = prec
    if mode != "guards":
        with monkeypatch.context() as m:   # "copy": the former repair; "none": one cast, no repair
            m.setattr(tiers._Tier, "guard", property(lambda self: None))
            m.setattr(tiers._Tier, "guarded", property(lambda self: mode == "none"))
            return e.cast(o + base, d).distance, e.counters
    return e.cast(o + base, d).distance, e.counters


CASES = [(np.zeros(3), False), (np.array([1e4, 5e3, 0.0]), False), (np.array([1e4, 5e3, 0.0]), True)]


@pytest.mark.parametrize("base,landmark", CASES, ids=["origin", "far", "far-coarse-frame"])
def test_guarded_exact_matches_closed_form_on_adversarial_rays(base, landmark, monkeypatch, record_property):
    o, d = _rays(3)
    assert len(o) > 20000
    tol = 1e-12 if not base.any() else 1e-9    # world inputs at 1e4 m round by ~1e-12 m
    t_new, c = _cast(o, d, base, landmark)
    wrong_new, err_new = _judge(o, d, t_new, tol)
    t_none, _ = _cast(o, d, base, landmark, monkeypatch, "none")
    wrong_none, _ = _judge(o, d, t_none, tol)
    t_old, c_old = _cast(o, d, base, landmark, monkeypatch, "copy")
    wrong_old, err_old = _judge(o, d, t_old, tol)
    t_fast, _ = _cast(o, d, base, landmark, prec=Precision.FAST)
    wrong_fast, _ = _judge(o, d, t_fast, 1e-3)
    leaks = {k: int(w.sum()) for k, w in (("guards", wrong_new), ("none", wrong_none), ("copy", wrong_old),
                                           ("fast", wrong_fast))}
    record_property("leaks", f"{leaks} of {len(o)} rays; {c['edge_guard_hits']} guard finds")
    print(f"\n{leaks} of {len(o)} rays; guard finds {c['edge_guard_hits']}, copy repairs {c_old['leak_repairs']}")
    assert leaks["none"] > 0            # a single cast without repair does leak on these rays ...
    assert c["edge_guard_hits"] > 0     # ... the guards find those hits ...
    assert leaks["guards"] == 0, np.flatnonzero(wrong_new)[:10]   # ... and none is left
    assert err_new.max() <= tol, float(err_new.max())
    # never wrong where the former repair was right, and as close to the closed form
    assert not np.any(wrong_new & ~wrong_old)
    assert np.all(err_new <= err_old + tol)


def test_risky_edges_are_boundaries_and_creases_only():
    # a box: its 12 edges are risky, the 6 face diagonals are not
    v, f = tessellate(Box((1, 2, 3)))
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.linalg.norm(n, axis=1)[:, None]
    edges, ptr, idx = risky_edges(f, np.ones(len(f), bool), n)
    assert len(edges) == 12 and np.all(np.diff(ptr) == 2)
    lengths = np.sort(np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1))
    assert np.allclose(lengths, [1] * 4 + [2] * 4 + [3] * 4)
    # a flat 4x4 grid: only its 16 boundary edges (one triangle each)
    v, f = _grid_square()
    n = np.tile([0.0, 0.0, 1.0], (len(f), 1))
    edges, ptr, _ = risky_edges(f, np.ones(len(f), bool), n)
    assert len(edges) == 16 and np.all(np.diff(ptr) == 1)
    # flipping one triangle's winding makes its shared edges risky (watertightness needs consistency)
    f2 = f.copy()
    f2[5] = f2[5][::-1]
    n2 = n.copy()
    n2[5] = -n2[5]
    assert len(risky_edges(f2, np.ones(len(f), bool), n2)[0]) > 16
    # curved shells are not guarded (their shells are inflated instead): no flat triangle, no edge
    assert len(risky_edges(f, np.zeros(len(f), bool), n)[0]) == 0


def test_tiers_with_many_risky_edges_keep_the_offset_copy():
    """A finely curved mesh (every edge a crease) would need ~18 prism triangles per triangle:
    such a tier keeps the former offset-copy repair, and still leaks nothing on the watertightness
    test (tests/test_raycast_precision.py)."""
    e = RayEngine(Precision.EXACT)
    ico = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    e.add_body([ShapeEntry(Mesh(ico.vertices, ico.faces, closed=True), Pose.identity(), True, True)], Pose.identity())
    e.add_body([ShapeEntry(Box((1, 1, 1)), Pose.from_axis_angle((0, 0, 1), 0.0, [4, 0, 0]), True, True)],
               Pose.identity())
    e.cast(np.zeros((1, 3)) + [0, 0, 5], np.array([[0.0, 0.0, -1.0]]))
    tier = e._static_tier("bounding")
    assert tier.guard is None and not tier.guarded
    e2 = RayEngine(Precision.EXACT)
    e2.add_body([ShapeEntry(Box((1, 1, 1)), Pose.identity(), True, True)], Pose.identity())
    e2.cast(np.zeros((1, 3)) + [0, 0, 5], np.array([[0.0, 0.0, -1.0]]))
    assert e2._static_tier("bounding").guarded



def test_pasted_copies_of_the_solids_cost_one_copy():
    """k copies of the same solids at the same poses (a world whose solids were pasted k times:
    it validates) are one copy to the engine: the `lighting` world x333 took 39 s and 3.4 GB in
    EXACT (every risky edge had k coincident neighbours: the guards' lists grew as k^2)."""
    one, many = _engine(np.zeros(3)), _engine(np.zeros(3), copies=300)
    o, d = _rays(5)
    o, d = o[::8], d[::8]
    t1, t = one.cast(o, d), many.cast(o, d)
    assert len(many._static_tier("bounding").F) == len(one._static_tier("bounding").F)
    assert many._static_tier("bounding").guarded
    assert np.array_equal(t.distance, t1.distance) and np.array_equal(t.shape, t1.shape)   # the first copy
    wrong, err = _judge(o, d, t.distance, 1e-12)
    assert not wrong.any() and err.max() <= 1e-12


def test_near_coincident_copies_keep_the_offset_copy_before_any_list_is_made(monkeypatch):
    """Copies a few nm apart are different surfaces (no two are the same shape), so they stay; their
    guards' candidate lists would grow as k^2 and are counted first: past the budget (linear in
    the triangles) the tier keeps the offset-copy repair, linear work, without making them."""
    made = []
    real = tiers.candidates

    def counted(*a, **k):
        out = real(*a, **k)
        made.append(None if out is None else len(out[1]))
        return out

    monkeypatch.setattr(tiers, "candidates", counted)
    few = _engine(np.zeros(3), copies=2, shift=1e-9)
    many = _engine(np.zeros(3), copies=60, shift=1e-9)
    o, d = _rays(5)
    o, d = o[::8], d[::8]
    few.cast(o, d)
    assert few._static_tier("bounding").guarded and made[-1] <= 256 * len(few._static_tier("bounding").F)
    t = many.cast(o, d).distance
    assert made[-1] is None and not many._static_tier("bounding").guarded
    # the closed form of the 60 copies (the nearest over them; surfaces closer than float32's
    # resolution may come out in either order: 1e-6 m); the offset copy is the former repair,
    # which leaves some rays wrong that graze an edge (all of these do: tests/test_raycast_precision.py)
    ref = np.min([_closed_form(o - k * 1e-9, d) for k in range(60)], axis=0)
    with np.errstate(invalid="ignore"):
        right = (np.abs(t - ref) <= 1e-6) | (np.isinf(t) & np.isinf(ref))
    assert np.count_nonzero(right) >= 0.98 * len(t), np.count_nonzero(~right)


def test_a_room_with_an_stl_rock_and_curved_shapes_keeps_its_guards():
    """The arena's kind of scene: boxes, curved shapes and a rock mesh read from STL (every vertex
    repeated per triangle). The rock's vertices are welded (its triangles share edges, so only its
    creases are risky: 1.5 per triangle, not 3), and the tier keeps its guards (prisms adding ~3
    triangles per triangle) instead of the offset copy; rays at the boxes' edges stay exact."""
    from sensorium.server.world.geometry import Cylinder, Sphere

    rock = trimesh.creation.icosphere(subdivisions=2, radius=0.3)
    soup = rock.vertices[rock.faces].reshape(-1, 3)            # an STL: three vertices per triangle
    e = _engine(np.zeros(3))
    e.add_body([ShapeEntry(Mesh(soup + [0.5, 2.0, -2.0], np.arange(len(soup)).reshape(-1, 3), closed=True),
                           Pose.identity(), True, True)], Pose.identity())
    for k in range(4):
        e.add_body([ShapeEntry(Sphere(0.2, subdivision=3) if k % 2 else Cylinder(0.1, 0.5, subdivision=64),
                               Pose.from_axis_angle((0, 0, 1), 0.0, [-3.0 + 0.6 * k, -3.0, -2.0]), True, True)],
                   Pose.identity())
    o, d = _rays(6)
    o, d = o[::8], d[::8]
    t = e.cast(o, d).distance
    tier = e._static_tier("bounding")
    rock_tri = (tier.tri_shape[:-1] == len(BOXES) + 1).nonzero()[0]
    assert len(np.unique(tier.F[rock_tri])) == len(rock.vertices)   # welded: 162 vertices, not 960
    flat = ~tier.tri_curved[:-1]
    assert len(risky_edges(tier.F, flat, tier.normal[:-1])[0]) > 1.2 * flat.sum()   # more than 1.2 per flat triangle
    assert tier.guarded and tier.guard is not None
    wrong, err = _judge(o, d, t, 1e-12)        # (the rock and the shells lie under the floor slab)
    assert not wrong.any() and err.max() <= 1e-12


@pytest.mark.parametrize("offset", [0.0, 5e3])
def test_exact_distance_only_gives_the_full_casts_distances(offset):
    """A lidar's EXACT cast skips shapes and normals (distance_only): the distances are the full
    cast's, bit for bit -- rays through edges, corners and seams, from a broadcast origin, with a
    t_near, plus movers (a box robot) and an infinite floor plane."""
    from sensorium.server.world.geometry import Plane
    base = np.array([offset, -offset / 3, 0.0])
    e = _engine(base)
    e.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.from_axis_angle((0, 0, 1), 0.0, base))
    robot = e.add_body([ShapeEntry(Box((0.4, 0.4, 0.3)), Pose.identity(), True, True)],
                       Pose.from_axis_angle((0, 0, 1), 0.3, base + [1.0, 1.0, 0.15]), movable=True)
    for eye in ([0.3, 0.2, 1.5], [-3.5, -3.0, 2.8]):
        tgt = np.vstack([_targets(), [1.0, 1.0, 0.15] + np.random.default_rng(1).uniform(-0.3, 0.3, (200, 3))])
        d = tgt - eye
        d /= np.linalg.norm(d, axis=1)[:, None]
        o = np.broadcast_to(np.add(eye, base), d.shape)
        for t_near in (0.0, 0.05):
            full = e.cast(np.ascontiguousarray(o), d, t_near, 9.0)
            lean = e.cast(o, d, t_near, 9.0, distance_only=True)
            assert lean.normal is None and lean.shape is None
            assert np.isfinite(full.distance).mean() > 0.5
            assert robot in {e.shape_body(s) for s in full.shape[full.shape >= 0].tolist()}
            np.testing.assert_array_equal(lean.distance, full.distance)


def test_dense_and_gathered_flat_judging_agree_bit_for_bit():
    """A pass where most rays hit flat triangles judges them on whole arrays; mixed with twice as
    many rays that hit nothing, the same rays go through the gathered path: identical answers
    (distances, shapes, normals) on rays through edges, corners and seams."""
    o, d = _rays(7)
    o, d = o[::3], d[::3]
    e = _engine(np.zeros(3))
    dense = e.cast(o, d)
    assert np.isfinite(dense.distance).mean() > 0.5
    up = np.tile([0.0, 0.0, 1.0], (2 * len(o), 1))
    sky = np.tile([0.0, 0.0, 10.0], (2 * len(o), 1))   # above everything, looking up
    mixed = e.cast(np.vstack([o, sky]), np.vstack([d, up]))
    assert not np.isfinite(mixed.distance[len(o):]).any()
    np.testing.assert_array_equal(mixed.distance[:len(o)], dense.distance)
    np.testing.assert_array_equal(mixed.shape[:len(o)], dense.shape)
    np.testing.assert_array_equal(mixed.normal[:len(o)], dense.normal)


def test_a_float32_frame_far_coarser_than_the_geometry_keeps_the_offset_copy():
    """A room 1e6 m from a landmark box at the origin, one static tier: float32 resolution ~6 cm
    there, prisms would be ~2 m wide (most rays would meet one): the offset copy instead.  At 1e4 m
    (3 cm prisms beside 3-10 m edges) the guards stay."""
    for far, guarded in ((1e6, False), (1e4, True)):
        e = _engine(np.array([far, far / 2, 0.0]), landmark=True)
        e.cast(np.array([[far + 0.3, far / 2 + 0.2, 1.5]]), np.array([[1.0, 0.0, 0.0]]))
        tier = e._static_tier("bounding")
        assert (tier.guard is not None) == guarded and tier.guarded == guarded


def _case_rays(case, rng, n=3000):
    """Rays of one named case (see test_each_case_against_its_closed_form), nudged sideways by up to
    1e-6 m (below float32 resolution here), with their aim points."""
    if case == "shared edge (face diagonal)":     # the crate's top face diagonal, from above
        a, b = np.array([-1.15, -0.75, 0.7]), np.array([-0.45, -0.05, 0.7])
        eye = np.array([-0.3, -1.6, 2.9])
    elif case == "vertex (box corner)":           # the crate's top corners, from above and the side
        corners = np.array([[-1.15, -0.75, 0.7], [-0.45, -0.75, 0.7], [-0.45, -0.05, 0.7], [-1.15, -0.05, 0.7]])
        a = b = None
        eye = np.array([0.9, -2.2, 2.4])
    elif case == "silhouette over a wall":        # a vertical silhouette edge of the near box, wall behind
        a, b = np.array([2.5, -0.9, 0.0]), np.array([2.5, -0.9, 1.0])
        eye = np.array([0.3, -1.4, 0.8])
    else:                                         # "seam of two touching boxes": their common top edge
        a, b = np.array([-2.25, 1.5, 0.9]), np.array([-1.75, 1.5, 0.9])
        eye = np.array([-2.6, -0.4, 2.2])
    if a is None:
        tgt = corners[rng.integers(0, 4, n)]
    else:
        tgt = a + rng.uniform(0, 1, (n, 1)) * (b - a)
    tgt = tgt + rng.normal(size=tgt.shape) * rng.choice([0.0, 1e-9, 1e-8, 1e-7, 1e-6], (n, 1))
    d = tgt - eye
    d /= np.linalg.norm(d, axis=1)[:, None]
    return np.broadcast_to(eye, d.shape).copy(), d


@pytest.mark.parametrize("case", ["shared edge (face diagonal)", "vertex (box corner)", "silhouette over a wall",
                                  "seam of two touching boxes"])
def test_each_case_against_its_closed_form(case, monkeypatch):
    """Each kind of ray the repair rule must catch, on its own, vs the slab closed form: a shared
    edge of two coplanar triangles (the watertight cast alone suffices), a vertex, a silhouette with
    a wall behind it, the seam between two separate boxes that touch.  All must be consistent with
    the geometry; flat-face distances exact to 1e-12 m where clear of edges."""
    o, d = _case_rays(case, np.random.default_rng(zlib.crc32(case.encode())))
    t, c = _cast(o, d, np.zeros(3), False)
    wrong, err = _judge(o, d, t, 1e-12)
    assert not wrong.any(), np.flatnonzero(wrong)[:5]
    assert err.max() <= 1e-12
    assert np.isfinite(t).all()     # every case has a surface at or behind its aim point
    t_none, _ = _cast(o, d, np.zeros(3), False, monkeypatch, "none")
    leaks = int(_judge(o, d, t_none, 1e-12)[0].sum())
    print(f"\n{case}: one cast without repair: {leaks} of {len(o)} wrong; with guards 0 "
          f"({c['edge_guard_hits']} guard finds)")
    if case.startswith("shared edge"):   # the premise: Embree's robust cast is watertight there
        assert leaks == 0


def test_the_lighting_world_pasted_333_times_runs_like_the_lighting_world(tmp_path):
    """Issue 28's case, as a world file: the `lighting` example's solids pasted 333 times at the
    same poses (127 KB, within every limit) validates; its first EXACT steps took 39 s and 3.4 GB.
    Now its static scenes are the original's (the copies add no triangle) and every device reads
    what it reads in the original world."""
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import default_world_path

    src = default_world_path().with_name("lighting.yaml").read_text()
    head, rest = src.split("solids:\n", 1)
    solids, tail = rest.split("\nlights:", 1)
    pasted = "".join(solids.replace("name: floor", f"name: floor_{k}").replace("name: screen", f"name: screen_{k}")
                     .replace("name: lamp_shade", f"name: lamp_shade_{k}") for k in range(333))
    (tmp_path / "one.yaml").write_text(src)
    (tmp_path / "pasted.yaml").write_text(head + "solids:\n" + pasted + "\nlights:" + tail)
    assert (tmp_path / "pasted.yaml").stat().st_size > 100_000
    sims = []
    for name in ("one.yaml", "pasted.yaml"):
        sim = Simulation.from_file(tmp_path / name, precision="exact")
        for dev in sim.all_devices():
            dev.enable(sim.basic_time_step)
        sim.step()
        sim.step()
        sims.append(sim)
    assert len(sims[1].world.solids) == 333 * len(sims[0].world.solids)
    for variant in ("bounding", "visual"):
        one, pasted_tier = (s.scene.engine._static_tier(variant) for s in sims)
        assert len(one.F) == len(pasted_tier.F)
    for a, b in zip(sims[0].all_devices(), sims[1].all_devices()):
        assert a.path == b.path and a.value == b.value, a.path
