"""Property tests: random poses of boxes / spheres / cylinders and random rays against independent
float64 reference intersectors written here.

* EXACT vs the analytic reference: same shape and |dt| <= 1e-9 * scene scale, for every ray that
  is well conditioned (the reference answer does not change under a 1e-6 * scale perturbation:
  not within that distance of an edge/rim, not tangent, no second surface that close).
* FAST vs a float64 ray/triangle reference over the same tessellation (FAST sees circumscribed
  shells): same shape and |dt| <= 64 float32 ulps of the scene scale / |cos(incidence)|, for
  well-conditioned rays whose origin is outside every curved shell (inside one, FAST switches
  to the analytic surface, which the EXACT property covers).

Hypothesis draws the shapes, poses and world offset; the rays come from a NumPy generator seeded
by hypothesis (continuous values, so aligned degenerate rays are not over-sampled).
"""

import math

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.server.raycast.engine import Precision, RayEngine, ShapeEntry
from sensorium.server.world.geometry import Box, Cylinder, Pose, Sphere, tessellate

N_RAYS = 64
SCALE = 10.0  # scene scale (metres): shapes within +-5 m, rays from within +-7 m

fl = lambda lo, hi: st.floats(lo, hi, allow_nan=False, allow_infinity=False)  # noqa: E731
shape_st = st.one_of(
    st.builds(lambda s: Box(s), st.tuples(fl(0.1, 3), fl(0.1, 3), fl(0.1, 3))),
    st.builds(lambda r, k: Sphere(r, k), fl(0.1, 2), st.integers(1, 3)),
    st.builds(lambda r, h, k: Cylinder(r, h, k), fl(0.1, 2), fl(0.1, 3), st.integers(8, 40)),
)
pose_st = st.builds(lambda t, a, ang: (t, a, ang),
                    st.tuples(fl(-5, 5), fl(-5, 5), fl(-5, 5)), st.tuples(fl(-1, 1), fl(-1, 1), fl(-1, 1)),
                    fl(0, 2 * math.pi))
scene_st = st.lists(st.tuples(shape_st, pose_st), min_size=1, max_size=5)
offset_st = st.sampled_from([0.0, 1e3, 1e6])
small_shape_st = st.one_of(
    st.builds(lambda s: Box(s), st.tuples(fl(0.1, 3), fl(0.1, 3), fl(0.1, 3))),
    st.builds(lambda r, k: Sphere(r, k), fl(0.1, 2), st.integers(0, 2)),
    st.builds(lambda r, h, k: Cylinder(r, h, k), fl(0.1, 2), fl(0.1, 3), st.integers(6, 24)),
)
small_scene_st = st.lists(st.tuples(small_shape_st, pose_st), min_size=1, max_size=4)


def _build(scene, offset, prec):
    e = RayEngine(prec)
    poses = []
    for prim, (t, axis, ang) in scene:
        pose = Pose.from_axis_angle(axis, ang, np.add(t, [offset, -offset, offset / 2]))
        poses.append(pose)
        e.add_body([ShapeEntry(prim, Pose.identity(), True, True)], pose, movable=len(poses) % 2 == 0)
    return e, poses


def _rays(seed, scene, poses, offset):
    rng = np.random.default_rng(seed)
    base = np.array([offset, -offset, offset / 2])
    o = base + rng.uniform(-7, 7, (N_RAYS, 3))
    centres = np.array([p.translation for p in poses])
    target = centres[rng.integers(0, len(poses), N_RAYS)] + rng.normal(scale=1.0, size=(N_RAYS, 3))
    d = target - o
    return o, d / np.linalg.norm(d, axis=1)[:, None]


# ---- analytic float64 reference (shape-local) -------------------------------------------------


def _local(pose, o, d):
    return (o - pose.translation) @ pose.rotation, d @ pose.rotation


def _box_hits(size, p, d):
    """Surface crossings (t, margin) of a box, both entry and exit."""
    h = np.asarray(size) / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (-h - p) / d, (h - p) / d
    tn, tf = np.minimum(t1, t2).max(1), np.maximum(t1, t2).min(1)
    ok = tn <= tf
    out = []
    for t in (tn, tf):
        x = p + np.where(np.isfinite(t), t, 0)[:, None] * d
        # distance from the hit point to the nearest edge of its face + incidence
        slack = h - np.abs(x)
        face = np.argmin(np.abs(slack), axis=1)
        other = np.abs(slack).copy()
        other[np.arange(len(p)), face] = np.inf
        cos = np.abs(d[np.arange(len(p)), face])
        out.append((np.where(ok, t, np.inf), np.minimum(other.min(1), cos * SCALE)))
    return out


def _quad(p, d, r):
    b = (p * d).sum(1)
    q = p - b[:, None] * d
    gap = r * r - (q * q).sum(1)
    s = np.sqrt(np.maximum(gap, 0))
    t1, t2 = -b - s, -b + s
    bad = gap < 0
    return np.where(bad, np.inf, t1), np.where(bad, np.inf, t2), r - np.sqrt(np.maximum((q * q).sum(1), 0))


def _sphere_hits(r, p, d):
    t1, t2, m = _quad(p, d, r)
    return [(t1, np.abs(m)), (t2, np.abs(m))]


def _cylinder_hits(r, height, p, d):
    h = height / 2
    out = []
    dxy = d[:, :2]
    a = np.linalg.norm(dxy, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = dxy / a[:, None]
        t1, t2, m = _quad(p[:, :2], u, r)
        for t in (t1 / a, t2 / a):
            z = p[:, 2] + t * d[:, 2]
            ok = np.isfinite(t) & (np.abs(z) <= h)
            out.append((np.where(ok, t, np.inf), np.minimum(np.abs(m), np.abs(h - np.abs(z)))))
        for zc in (h, -h):
            t = (zc - p[:, 2]) / d[:, 2]
            xy = p[:, :2] + t[:, None] * d[:, :2]
            rho = np.linalg.norm(xy, axis=1)
            ok = np.isfinite(t) & (rho <= r)
            out.append((np.where(ok, t, np.inf), np.minimum(np.abs(r - rho), np.abs(d[:, 2]) * SCALE)))
    return out


def _analytic_reference(scene, poses, o, d, t_min):
    """(t, shape, margin): nearest crossing >= t_min; margin = how far the answer is from changing."""
    cand_t, cand_s, cand_m = [], [], []
    for k, ((prim, _), pose) in enumerate(zip(scene, poses)):
        p, dl = _local(pose, o, d)
        if isinstance(prim, Box):
            hits = _box_hits(prim.size, p, dl)
        elif isinstance(prim, Sphere):
            hits = _sphere_hits(prim.radius, p, dl)
        else:
            hits = _cylinder_hits(prim.radius, prim.height, p, dl)
        for t, m in hits:
            cand_t.append(np.where(t >= t_min, t, np.inf))
            cand_s.append(np.full(len(o), k))
            cand_m.append(m)
    T, S, M = np.stack(cand_t, 1), np.stack(cand_s, 1), np.stack(cand_m, 1)
    order = np.argsort(T, axis=1)
    rows = np.arange(len(o))
    t0, t1 = T[rows, order[:, 0]], T[rows, order[:, 1]]
    shape = np.where(np.isfinite(t0), S[rows, order[:, 0]], -1)
    with np.errstate(invalid="ignore"):
        margin = np.where(np.isfinite(t0), np.minimum(M[rows, order[:, 0]], t1 - t0), np.inf)
    # a near-miss (tangent / just beside an edge) is ill-conditioned too
    near = np.min(np.where(np.isinf(T), M, np.inf), axis=1)
    return t0, shape, np.minimum(margin, near)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=scene_st, offset=offset_st, seed=st.integers(0, 2 ** 32 - 1))
def test_exact_matches_analytic_reference(scene, offset, seed):
    e, poses = _build(scene, offset, Precision.EXACT)
    o, d = _rays(seed, scene, poses, offset)
    h = e.cast(o, d)
    t_ref, s_ref, margin = _analytic_reference(scene, poses, o, d, 1e-6)
    good = margin > 1e-6 * SCALE
    assert np.array_equal(h.shape[good], s_ref[good])
    hit = good & (s_ref >= 0)
    assert np.all(np.abs(h.distance[hit] - t_ref[hit]) <= 1e-9 * SCALE)
    assert np.all((h.normal[hit] * d[hit]).sum(1) <= 0)


# ---- FAST vs the tessellation ---------------------------------------------------------------


def _triangle_reference(scene, poses, o, d, t_min):
    """Nearest float64 ray/triangle hit over the tessellated shapes: (t, shape, margin, cos)."""
    best_t = np.full(len(o), np.inf)
    best_s = np.full(len(o), -1)
    margin = np.full(len(o), np.inf)
    cos = np.ones(len(o))
    per_shape = []
    for k, ((prim, _), pose) in enumerate(zip(scene, poses)):
        v, f = tessellate(prim)
        tri = pose.apply(v)[f]
        v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        n = np.cross(e1, e2)
        n /= np.linalg.norm(n, axis=1)[:, None]
        pv = np.cross(d[:, None], e2[None])
        det = (e1[None] * pv).sum(2)
        s = o[:, None] - v0[None]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = (s * pv).sum(2) / det
            q = np.cross(s, e1[None])
            w = (d[:, None] * q).sum(2) / det
            t = (e2[None] * q).sum(2) / det
        inside = (u >= 0) & (w >= 0) & (u + w <= 1) & (t >= t_min)
        tt = np.where(inside, t, np.inf)
        j = np.argmin(tt, axis=1)
        tk = tt[np.arange(len(o)), j]
        per_shape.append(tk)
        bary = np.minimum(np.minimum(u, w), 1 - u - w)[np.arange(len(o)), j]
        edge = bary * np.minimum(np.linalg.norm(e1, axis=1), np.linalg.norm(e2, axis=1))[j]
        # near misses of any triangle of this shape also make the answer fragile
        near = np.where(~inside & (t >= t_min), -np.minimum(np.minimum(u, w), 1 - u - w), np.inf).min(1)
        better = tk < best_t
        best_t = np.where(better, tk, best_t)
        best_s = np.where(better, k, best_s)
        margin = np.where(better, edge, margin)
        cos = np.where(better, np.abs((n[j] * d).sum(1)), cos)
        margin = np.minimum(margin, near * 0.1)
    # another shape's surface just as near (coincident or touching shapes) is ambiguous
    T = np.sort(np.stack(per_shape + [np.full(len(o), np.inf)], axis=1), axis=1)
    with np.errstate(invalid="ignore"):
        margin = np.where(np.isfinite(best_t), np.minimum(margin, T[:, 1] - T[:, 0]), margin)
    return best_t, best_s, margin, cos


def _outside_shells(scene, poses, o):
    ok = np.ones(len(o), dtype=bool)
    for (prim, _), pose in zip(scene, poses):
        if isinstance(prim, Box):
            continue
        v, _ = tessellate(prim)
        ok &= np.linalg.norm(o - pose.translation, axis=1) > np.linalg.norm(v, axis=1).max() * 1.001
    return ok


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene=small_scene_st, offset=offset_st, seed=st.integers(0, 2 ** 32 - 1))
def test_fast_matches_tessellation_within_float32_bound(scene, offset, seed):
    e, poses = _build(scene, offset, Precision.FAST)
    o, d = _rays(seed, scene, poses, offset)
    h = e.cast(o, d)
    t_ref, s_ref, margin, cos = _triangle_reference(scene, poses, o, d, 1e-5)
    ulp = float(np.spacing(np.float32(SCALE)))
    good = (margin > 1e-4 * SCALE) & _outside_shells(scene, poses, o)
    assert np.array_equal(h.shape[good], s_ref[good])
    hit = good & (s_ref >= 0)
    bound = 64 * ulp / np.maximum(cos[hit], 0.05)
    assert np.all(np.abs(h.distance[hit] - t_ref[hit]) <= bound)
    assert np.all((h.normal[hit] * d[hit]).sum(1) <= 0)
