"""The engine's alternative code paths must agree with each other.

Small batches take plain-float shortcuts (broad phase, pre-pass, analytic intersection), large
ones vectorised numpy; many movers go through a grid broad phase and shared body-frame tiers with
a bound test pruning candidate rays.  Each pair of paths is checked for the same answers:

* the scalar analytic intersector is bit-identical to the vectorised one;
* the grid broad phase finds exactly the (ray, mover) pairs of the dense test;
* a ray cast alone (tiny paths) gets the same hit as inside a large batch (vectorised paths);
* movers sharing one tier (identical geometry) answer like the same bodies in the static tier;
* uniform per-ray parameter arrays behave like the scalars they collapse to.
"""

import math

import numpy as np
import pytest

from sensorium.server.raycast import exact, movers
from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.world.geometry import Box, Capsule, Cylinder, Plane, Pose, Sphere

BOTH = [Precision.FAST, Precision.EXACT]


def at(x, y, z, axis=(0, 0, 1), angle=0.0):
    return Pose.from_axis_angle(axis, angle, [x, y, z])


def entry(p, pose=None, **kw):
    return ShapeEntry(p, pose or Pose.identity(), kw.get("bounding", True), kw.get("visual", True),
                      kw.get("transparent", False))


def _unit(v):
    return v / np.linalg.norm(v, axis=1)[:, None]


# ---------------------------------------------------------------------------------------------
# scalar twins


@pytest.mark.parametrize("m", [200, 400])    # the vectorised nearest-candidate step differs above 256 rows
@pytest.mark.parametrize("code", [exact._SPHERE, exact._CYLINDER, exact._CAPSULE])
def test_scalar_analytic_is_bit_identical(code, m):
    rng = np.random.default_rng(code)
    r, h = 0.7, 0.45
    p = rng.uniform(-1.5, 1.5, (m, 3))
    p[:40] *= 0.3                                   # some origins inside the shape
    d = _unit(rng.uniform(-0.6, 0.6, (m, 3)) - p)    # mostly aimed at the shape
    d[40:60, 2] = 0.0                               # parallel to the caps
    d[60:70] = [0.0, 0.0, 1.0]                      # along the axis
    d = _unit(d)
    lo = rng.uniform(0.0, 0.3, m)
    hi = lo + rng.uniform(0.0, 3.0, m)
    with np.errstate(all="ignore"):
        t, n = exact._analytic_local(code, p, d, r, h, lo, hi)
    for i in range(m):
        ts, ns = exact._analytic_one(code, tuple(p[i]), tuple(d[i]), r, h, float(lo[i]), float(hi[i]))
        assert ts == t[i] or (math.isinf(ts) and math.isinf(t[i])), i
        if math.isfinite(ts):
            assert np.allclose(ns, n[i], rtol=0, atol=1e-15), i
    assert np.isfinite(t).sum() > m // 5               # the test exercises hits, not just misses


def test_one_pass_over_mixed_kinds_is_bit_identical_to_each_kind_alone():
    """EXACT refines a few curved hits of several kinds (a sphere, a cylinder, a capsule) in one pass:
    every row's t and normal are those of its own kind's intersector, bit for bit (origins inside,
    rays parallel to the caps, along the axis, hits near the rims)."""
    rng = np.random.default_rng(9)
    m = 600
    codes = rng.choice([exact._SPHERE, exact._CYLINDER, exact._CAPSULE], m)
    r = rng.uniform(0.2, 0.9, m)
    h = np.where(codes == exact._SPHERE, 0.0, rng.uniform(0.1, 0.8, m))
    p = rng.uniform(-1.5, 1.5, (m, 3))
    p[:60] *= 0.2                                   # some origins inside
    d = _unit(rng.uniform(-0.6, 0.6, (m, 3)) - p)
    d[60:90, 2] = 0.0                               # parallel to the caps
    d[90:100] = [0.0, 0.0, -1.0]                    # along the axis
    d = _unit(d)
    lo = rng.uniform(0.0, 0.3, m)
    hi = lo + rng.uniform(0.0, 3.0, m)
    with np.errstate(all="ignore"):
        t, n = exact._analytic_mixed(codes, p, d, r, h, lo, hi)
        t_only, _ = exact._analytic_mixed(codes, p, d, r, h, lo, hi, normals=False)
        for code in (exact._SPHERE, exact._CYLINDER, exact._CAPSULE):
            g = codes == code
            tk, nk = exact._analytic_local(code, p[g], d[g], r[g], h[g], lo[g], hi[g])
            assert t[g].tobytes() == tk.tobytes() and n[g].tobytes() == nk.tobytes()
            assert np.isfinite(tk).sum() > g.sum() // 5
    assert t_only.tobytes() == t.tobytes()


# ---------------------------------------------------------------------------------------------
# broad phase


def test_grid_pairs_equal_dense_pairs():
    rng = np.random.default_rng(7)
    M = 300
    C = np.column_stack([rng.uniform(-10, 10, M), rng.uniform(-10, 10, M), rng.uniform(0, 0.5, M)])
    radius = rng.uniform(0.03, 0.08, M)
    radius[:5] = 1.5                                 # a few big movers
    owner = rng.integers(-1, 50, M)
    n = 5000
    O = C[rng.integers(0, M, n)] + rng.normal(scale=0.1, size=(n, 3))
    D = _unit(rng.normal(size=(n, 3)))
    t_near = np.where(rng.random(n) < 0.1, 0.02, 0.0)
    lim = rng.uniform(0.0, 0.1, n)
    lim[:50] = 8.0                                  # a few long rays
    lim[50:60] = np.inf
    lim[60:70] = -1.0                               # empty segments
    excl = rng.integers(-1, 50, n)
    r2 = radius ** 2
    with np.errstate(all="ignore"):
        dense = movers._sphere_pairs(C, r2, owner, O, D, t_near, lim, excl)
        grid = movers._grid_pairs(C, radius, r2, owner, O, D, t_near, lim, excl)
    # the dense test may also list rays whose segment is empty (lim < t_near): they find nothing
    dense = {(i, j) for i, j in zip(*map(np.ndarray.tolist, dense)) if lim[i] >= t_near[i]}
    assert dense == set(zip(*map(np.ndarray.tolist, grid)))
    assert len(dense) > 500


def test_tiny_sphere_pairs_equal_vectorised():
    rng = np.random.default_rng(3)
    C = rng.normal(size=(3, 3))
    r2 = np.array([0.5, 0.2, 1.0])
    owner = np.array([-1, 2, 3])
    n = exact._TINY // 3                       # n x 3 movers: the plain-float path
    for _ in range(100):
        O = rng.normal(size=(n, 3)) * 2
        D = _unit(rng.normal(size=(n, 3)))
        lim = rng.uniform(0, 4, n)
        excl = rng.integers(-1, 4, n)
        with np.errstate(all="ignore"):
            tiny = movers._sphere_pairs(C, r2, owner, O, D, 0.0, lim, excl)
            big = movers._sphere_pairs(np.repeat(C, 12, axis=0), np.repeat(r2, 12), np.repeat(owner, 12),
                                        O, D, 0.0, lim, excl)   # n x 36 > _TINY: vectorised
        assert sorted(zip(tiny[0].tolist(), tiny[1].tolist())) == \
            sorted({(i, j // 12) for i, j in zip(big[0].tolist(), big[1].tolist())})


# ---------------------------------------------------------------------------------------------
# whole engine: tiny vs batched, shared movers vs static


def _world(prec, movable):
    """Round and flat shapes, some rotated, a plane; robots as movers or static bodies."""
    e = RayEngine(prec)
    e.add_body([entry(Plane((8.0, 8.0)))], at(0, 0, 0))
    e.add_body([entry(Box((0.3, 3.0, 0.5)))], at(2.5, 0, 0.25, angle=0.3))
    e.add_body([entry(Sphere(0.3))], at(-1.5, 1.0, 0.3))
    e.add_body([entry(Cylinder(0.2, 0.6))], at(1.0, -1.5, 0.3))
    e.add_body([entry(Capsule(0.1, 0.4), at(0, 0, 0, axis=(1, 0, 0), angle=1.5708))], at(-1.0, -1.0, 0.2))
    robots = []
    rng = np.random.default_rng(11)
    for i in range(40):
        x, y = -3.0 + 0.75 * (i % 8), -2.0 + 1.0 * (i // 8)
        pose = at(x, y, 0.01, angle=float(rng.uniform(-3, 3)))
        if i % 5 == 4:
            shapes = [entry(Box((0.2, 0.12, 0.06)), at(0, 0, 0.03))]
        else:
            shapes = [entry(Cylinder(0.035, 0.05), at(0, 0, 0.025))]
        owner = -1 if i % 7 == 3 else i            # some robots have no owner (never excluded)
        robots.append((e.add_body(shapes, pose, owner=owner, movable=movable), pose))
    e.add_body([entry(Plane((0.6, 0.6)))], at(0.0, -1.0, 0.3), owner=5)   # an owned plane
    return e, robots


def _rays(robots, rng, top=0.06):
    """IR-like rays from just outside each robot's body, one from ``top`` (default: exactly on the
    top face, inside the inflated shell), some long."""
    O, D = [], []
    for _, pose in robots:
        for a in np.linspace(0, 2 * np.pi, 6, endpoint=False):
            local = np.array([0.0357 * math.cos(a), 0.0357 * math.sin(a), 0.035])
            O.append(pose.apply(local[None])[0])
            D.append(pose.apply_dirs(np.array([[math.cos(a), math.sin(a), rng.uniform(-0.3, 0.1)]]))[0])
        O.append(pose.apply(np.array([[0.0, 0.0, top]]))[0])
        D.append(pose.apply_dirs(np.array([[1.0, 0.2, 0.0]]))[0])
    O, D = np.array(O), _unit(np.array(D))
    t_far = np.where(rng.random(len(O)) < 0.2, 5.0, 0.4)
    return O, D, t_far


@pytest.mark.parametrize("prec", BOTH)
@pytest.mark.parametrize("kind", [RayKind.VISUAL, RayKind.BOUNDING])
def test_single_rays_match_the_batch(prec, kind):
    e, robots = _world(prec, movable=True)
    rng = np.random.default_rng(5)
    O, D, t_far = _rays(robots, rng)
    excl = np.where(rng.random(len(O)) < 0.5, -1, np.repeat(np.arange(len(robots)), 7))
    batch = e.cast(O, D, 0.0, t_far, kind=kind, exclude_owner=excl)
    assert np.isfinite(batch.distance).sum() > 20
    tol = 1e-12 if prec == Precision.EXACT else 1e-6
    for i in range(len(O)):
        one = e.cast(O[i:i + 1], D[i:i + 1], 0.0, t_far[i], kind=kind, exclude_owner=int(excl[i]))
        assert one.shape[0] == batch.shape[i], i
        if np.isfinite(batch.distance[i]):
            assert abs(one.distance[0] - batch.distance[i]) <= tol, i
            assert np.allclose(one.normal[0], batch.normal[i], atol=1e-6), i


@pytest.mark.parametrize("prec", BOTH)
def test_shared_mover_tiers_match_static_bodies(prec):
    moving, robots = _world(prec, movable=True)
    still, _ = _world(prec, movable=False)
    rng = np.random.default_rng(9)
    O, D, t_far = _rays(robots, rng, top=0.045)   # inside the body (on its top face: float32 coin toss)
    a = moving.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL)
    b = still.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL)
    assert np.array_equal(a.shape, b.shape)
    hit = np.isfinite(a.distance)
    tol = 1e-12 if prec == Precision.EXACT else 1e-5
    assert np.allclose(a.distance[hit], b.distance[hit], rtol=0, atol=tol)
    assert np.allclose(a.normal[hit], b.normal[hit], atol=1e-6)
    # 40 robots of two geometries: two shared body-frame tiers, plus the static tier
    assert moving.counters["bvh_builds"] == 3
    # moving every robot: no rebuild, hits follow
    for body, pose in robots:
        moving.set_body_pose(body, Pose(pose.rotation, pose.translation + [0.0, 0.0, 0.5]))
    c = moving.cast(O + [0.0, 0.0, 0.5], D, 0.0, t_far, kind=RayKind.VISUAL)
    robot_hits = (a.shape >= 5) & (c.shape >= 5)
    assert robot_hits.sum() > 20
    assert np.allclose(a.distance[robot_hits], c.distance[robot_hits], atol=tol + 1e-9)
    assert moving.counters["bvh_builds"] == 3


@pytest.mark.parametrize("prec", BOTH)
def test_uniform_parameter_arrays_equal_scalars(prec):
    e, robots = _world(prec, movable=True)
    O, D, _ = _rays(robots, np.random.default_rng(1))
    n = len(O)
    a = e.cast(O, D, 0.0, 0.4, kind=RayKind.BOUNDING, exclude_owner=3)
    b = e.cast(O, D, np.zeros(n), np.full(n, 0.4), kind=RayKind.BOUNDING, exclude_owner=np.full(n, 3))
    assert np.array_equal(a.shape, b.shape) and np.array_equal(a.distance, b.distance)
    c = e.cast(O[:4], D[:4], [0.0] * 4, [0.4] * 4, kind=RayKind.BOUNDING, exclude_owner=[3] * 4)
    assert np.array_equal(c.shape, a.shape[:4]) and np.array_equal(c.distance, a.distance[:4])


def test_invalid_ray_kind_is_rejected():
    e = RayEngine()
    with pytest.raises(ValueError):
        e.cast(np.zeros((1, 3)), np.array([[1.0, 0, 0]]), kind=5)


@pytest.mark.parametrize("shape", [Cylinder(0.2, 0.5), Capsule(0.1, 0.3), Box((0.3, 0.2, 0.1)), Sphere(0.2)])
def test_bound_prune_keeps_every_hit(shape):
    """may_hit (the pre-Embree pruning of mover pairs) must keep every ray that hits the body or
    starts inside it, and should drop clear misses, parallel rays beside the body included."""
    local = at(0.05, -0.02, 0.1, axis=(1, 1, 0), angle=0.4)
    e = RayEngine(Precision.EXACT)
    body = e.add_body([entry(shape, local)], Pose.identity(), movable=True)
    tier = e._mover_tier(e._bodies[body], "visual")
    ref = RayEngine(Precision.EXACT)
    ref.add_body([entry(shape, local)], Pose.identity())
    rng = np.random.default_rng(4)
    n = 4000
    O = rng.uniform(-0.6, 0.6, (n, 3))
    D = _unit(rng.uniform(-0.3, 0.3, (n, 3)) - O)
    D[:500, 2] = 0.0                                   # parallel to the axis' normal plane
    D[500:600] = [0.0, 0.0, 1.0]                       # parallel to z
    D = _unit(D)
    hi = rng.uniform(0.0, 1.2, n)
    with np.errstate(all="ignore"):
        keep = tier.may_hit(O, D, 0.0, hi)
    hits = np.isfinite(ref.cast(O, D, 0.0, hi).distance)
    inside = np.isfinite(ref.cast(O, -D, 0.0, 2.0).distance) & np.isfinite(ref.cast(O, D, 0.0, 2.0).distance)
    assert not np.any((hits | inside) & ~keep)
    assert hits.sum() > 200 and (~keep).sum() > n // 4   # real pruning happens
    # explicit clear misses: beside the body, parallel to its faces / axis
    far = np.array([[2.0, 0.0, 0.1], [0.05, 2.0, 0.1], [0.0, 0.0, 2.0]])
    along = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    with np.errstate(all="ignore"):
        assert not tier.may_hit(far, along, 0.0, np.full(3, 5.0)).any()


@pytest.mark.parametrize("seed", range(4))
def test_random_worlds_single_rays_match_the_batch(seed):
    """Random worlds (shared and unique mover geometry, owners, transparency, planes) and random
    rays, exclusions and ranges: each ray cast alone must get the batch's answer."""
    rng = np.random.default_rng(seed)

    def prim():
        k = rng.integers(0, 4)
        if k == 0:
            return Box(tuple(rng.uniform(0.05, 1.0, 3)))
        if k == 1:
            return Sphere(float(rng.uniform(0.05, 0.6)), int(rng.integers(1, 3)))
        if k == 2:
            return Cylinder(float(rng.uniform(0.03, 0.5)), float(rng.uniform(0.05, 0.8)), int(rng.integers(8, 40)))
        return Capsule(float(rng.uniform(0.03, 0.4)), float(rng.uniform(0.0, 0.6)))

    def pose(scale):
        return Pose.from_axis_angle(rng.normal(size=3), rng.uniform(0, 6.3), rng.uniform(-scale, scale, 3))

    protos = [[prim() for _ in range(rng.integers(1, 3))] for _ in range(3)]
    for prec in BOTH:
        e = RayEngine(prec)
        centres = []
        for _b in range(30):
            movable = rng.random() < 0.6
            shapes = protos[rng.integers(0, 3)] if movable and rng.random() < 0.7 else [prim() for _ in range(2)]
            entries = [entry(p, Pose.identity() if rng.random() < 0.5 else pose(0.2), transparent=rng.random() < 0.1)
                       for p in shapes]
            p = pose(3.0)
            centres.append(p.translation)
            e.add_body(entries, p, owner=int(rng.integers(-1, 5)), movable=movable)
        e.add_body([entry(Plane())], pose(0.5), owner=int(rng.integers(-1, 5)))
        n = 160
        O = np.array(centres)[rng.integers(0, len(centres), n)] + rng.normal(scale=0.2, size=(n, 3))
        D = _unit(rng.normal(size=(n, 3)))
        t_far = rng.uniform(0.01, 4.0, n)
        excl = rng.integers(-1, 5, n)
        for kind in (RayKind.BOUNDING, RayKind.VISUAL):
            batch = e.cast(O, D, 0.0, t_far, kind=kind, exclude_owner=excl, skip_transparent=seed % 2 == 1)
            assert np.isfinite(batch.distance).sum() > n // 5
            for i in range(n):
                one = e.cast(O[i], D[i], 0.0, t_far[i], kind=kind, exclude_owner=int(excl[i]),
                             skip_transparent=seed % 2 == 1)
                assert one.shape[0] == batch.shape[i], (prec, kind, i)
                if np.isfinite(one.distance[0]):
                    assert abs(one.distance[0] - batch.distance[i]) <= 1e-6, (prec, kind, i)


@pytest.mark.parametrize("threads", [1, 2])
def test_origin_rows_give_the_cast_without_them_bit_for_bit(threads):
    """RayEngine.cast(origin_rows=...): runs of rays from 40 origins (some inside a sphere and a
    cylinder, so the curved-shell pre-pass finds rays there, others far from every shell) take the
    largest coordinate and the origins' box from the 40 rows instead of the 10,240, with the same
    distances, shapes and normals as the cast without them (FAST and EXACT, scalar and per-ray
    limits); and the inside rays see the true surface from within (closed form: a sphere's radius)."""
    eng = RayEngine(Precision.FAST)
    eng.threads = threads
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    eng.add_body([ShapeEntry(Sphere(0.5), Pose.identity(), True, True)], Pose(np.eye(3), np.array([1.0, 0.0, 0.6])))
    eng.add_body([ShapeEntry(Cylinder(0.3, 1.0), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([-1.0, 1.0, 0.5])))
    eng.add_body([ShapeEntry(Box((0.4, 0.4, 0.4)), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([0.0, -1.5, 0.2])))
    rng = np.random.default_rng(5)
    rows = rng.uniform(-3.0, 3.0, (40, 3))
    rows[:, 2] = rng.uniform(0.05, 1.2, 40)
    rows[0] = [1.0, 0.0, 0.6]             # the sphere's centre
    rows[1] = [-1.0, 1.0, 0.4]            # inside the cylinder
    W = 256
    O = np.repeat(rows, W, axis=0)
    D = rng.normal(size=(len(O), 3))
    D /= np.linalg.norm(D, axis=1)[:, None]
    for precision in (Precision.FAST, Precision.EXACT):
        eng.precision = precision
        for t_near, t_far in ((0.0, np.inf), (0.01, 4.0), (0.0, rng.uniform(0.1, 5.0, len(O)))):
            want = eng.cast(O, D, t_near, t_far, kind=RayKind.VISUAL)
            got = eng.cast(O, D, t_near, t_far, kind=RayKind.VISUAL, origin_rows=rows)
            assert got.distance.tobytes() == want.distance.tobytes()
            assert got.shape.tobytes() == want.shape.tobytes() and got.normal.tobytes() == want.normal.tobytes()
            lone = eng.cast(O, D, t_near, t_far, kind=RayKind.VISUAL, distance_only=True, origin_rows=rows)
            assert lone.distance.tobytes() == want.distance.tobytes()
        # from the sphere's centre its radius every way, even where the limit ends before the shell
        # around it (only the pre-pass, screened by the box, finds those)
        for t_far in (np.inf, 0.5 + 1e-7):
            inside = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, origin_rows=rows).distance[:W]
            assert np.allclose(inside, 0.5, atol=1e-9)


def test_origin_rows_far_from_every_curved_shell_pass_the_pre_pass_by(monkeypatch):
    """A cast whose origin rows all lie beyond reach of every curved shell (the scouts of many
    copies scanning an arena) is screened by those rows alone: the curved-shell pre-pass is not
    run, with the same distances, shapes and normals as the cast without rows; rows whose start
    points (t_near along the ray) can enter a shell -- one just outside the sphere with rays
    starting 0.2 m in -- still run it, and those rays meet the sphere from within (closed form)."""
    eng = RayEngine(Precision.FAST)
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    eng.add_body([ShapeEntry(Sphere(0.5), Pose.identity(), True, True)], Pose(np.eye(3), np.array([1.0, 0.0, 0.6])))
    eng.add_body([ShapeEntry(Cylinder(0.3, 1.0), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([-1.0, 1.0, 0.5])))
    calls = []
    real = eng._contained_prepass

    def counted(*a, **k):
        calls.append(len(a[1]))
        return real(*a, **k)

    monkeypatch.setattr(eng, "_contained_prepass", counted)
    rng = np.random.default_rng(9)
    rows = np.array([[2.5, 2.5, 0.3], [-2.5, -2.0, 0.8], [2.4, -2.2, 0.1], [-0.2, 2.7, 1.0]] * 10)
    rows += rng.uniform(-0.1, 0.1, rows.shape)
    W = 128
    O = np.repeat(rows, W, axis=0)
    D = _unit(rng.normal(size=(len(O), 3)))
    for t_near, t_far in ((0.0, np.inf), (0.02, 6.0)):
        for distance_only in (False, True):
            calls.clear()
            want = eng.cast(O, D, t_near, t_far, kind=RayKind.VISUAL, distance_only=distance_only)
            assert calls                                              # without rows: screened ray by ray
            calls.clear()
            got = eng.cast(O, D, t_near, t_far, kind=RayKind.VISUAL, distance_only=distance_only, origin_rows=rows)
            assert not calls                                          # passed by
            assert got.distance.tobytes() == want.distance.tobytes()
            if not distance_only:
                assert got.shape.tobytes() == want.shape.tobytes() and got.normal.tobytes() == want.normal.tobytes()
            assert 0.3 < np.isfinite(got.distance).mean()
    # one row 0.1 m outside the sphere: rays toward its centre starting 0.2 m along begin inside it
    near_row = np.array([[1.0, -0.6, 0.6]])
    rows2 = np.concatenate([rows, near_row])
    Dn = _unit(np.array([[0.0, 1.0, 0.0]]) + rng.normal(scale=0.05, size=(W, 3)))
    O2 = np.concatenate([O, np.repeat(near_row, W, axis=0)])
    D2 = np.concatenate([D, Dn])
    calls.clear()
    want = eng.cast(O2, D2, 0.2, 6.0, kind=RayKind.VISUAL)
    got = eng.cast(O2, D2, 0.2, 6.0, kind=RayKind.VISUAL, origin_rows=rows2)
    assert calls and got.distance.tobytes() == want.distance.tobytes() and got.normal.tobytes() == want.normal.tobytes()
    # from within: the far side of the sphere, |o + t d - c| = 0.5
    t = got.distance[len(O):]
    p = near_row + t[:, None] * Dn - np.array([1.0, 0.0, 0.6])
    assert np.allclose(np.linalg.norm(p, axis=1), 0.5, atol=1e-9) and (t > 0.6).all()
