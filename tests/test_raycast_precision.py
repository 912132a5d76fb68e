"""Precision far from the origin, and watertightness.

Measured and asserted error bounds (distance error vs a float64 closed form computed from the same
float64 inputs; scene extent ~20 m):

    world offset    EXACT (asserted / measured)      FAST (asserted / measured)
    0               1e-12 m  / ~2e-15 m              2e-6 m  / ~8e-7 m   (flat faces)
    1e5 m           1e-12 m  / ~2e-15 m              2e-6 m  / ~9e-7 m
    1e6 m           1e-12 m  / ~2e-15 m              2e-6 m  / ~9e-7 m
FAST does not degrade far away because every scene is anchored at its own centre (and rays are
clipped to the scene's bounding sphere before the float32 conversion).  Curved shapes in FAST
carry the tessellation gap instead (sphere level 3: <= 0.5 % of the radius).

In the lidar-in-a-room test the reference is computed in the room's LOCAL frame, so the error
also includes the float64 rounding of the world-frame inputs at 1e6 m (ulp 1.2e-10 m): EXACT is
asserted within 1e-9 m there.

Watertightness: >= 10,000 rays aimed exactly at vertices and edge midpoints of closed meshes
(icosphere, box), from inside and outside.  EXACT must report the true first hit for every ray
(0 leaks); FAST's leak count is measured and reported, not asserted.
"""

import numpy as np
import pytest
import trimesh

from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.world.geometry import Box, Capsule, Cylinder, Mesh, Plane, Pose, Sphere, tessellate

BOTH = [Precision.FAST, Precision.EXACT]
OFFSETS = [0.0, 1e5, 1e6]
BOUND = {Precision.EXACT: 1e-12, Precision.FAST: 2e-6}


def at(x, y, z, axis=(0, 0, 1), angle=0.0):
    return Pose.from_axis_angle(axis, angle, [x, y, z])


_IDENTITY = Pose.identity()


def entry(p, pose=_IDENTITY):
    return ShapeEntry(p, pose, True, True)


def _unit(v):
    return v / np.linalg.norm(v, axis=1)[:, None]


def _shell_gap(p) -> float:
    """How far the circumscribed tessellation reaches outside the true surface."""
    v, _ = tessellate(p)
    if isinstance(p, Sphere):
        return float(np.linalg.norm(v, axis=1).max() - p.radius)
    if isinstance(p, Cylinder):
        return float(np.hypot(v[:, 0], v[:, 1]).max() - p.radius)
    q = v.copy()
    q[:, 2] = np.sign(q[:, 2]) * np.maximum(np.abs(q[:, 2]) - p.height / 2, 0.0)
    return float(np.linalg.norm(q, axis=1).max() - p.radius)


@pytest.mark.parametrize("prec", BOTH)
@pytest.mark.parametrize("offset", OFFSETS)
def test_translated_scene_error_bounds(prec, offset):
    base = np.array([offset, -offset / 3, offset / 7])
    e = RayEngine(prec)
    e.add_body([entry(Box((2, 1, 0.5)))], at(*(base + [5, 0, 0])))
    e.add_body([entry(Sphere(1.3))], at(*(base + [0, 5, 0])))
    e.add_body([entry(Box((20, 20, 0.2)))], at(*(base + [0, 0, -3])))
    e.add_body([entry(Cylinder(0.5, 2.0))], at(*(base + [0, -5, 0])))
    e.add_body([entry(Capsule(0.5, 1.0))], at(*(base + [-5, 0, 0])))
    e.add_body([entry(Plane())], at(*(base + [0, 0, 10])))
    rng = np.random.default_rng(0)
    n = 1000
    o = base + rng.uniform(-1, 1, (n, 3))
    # box face x = 4 (flat: both modes)
    T = base + np.c_[np.full(n, 4.0), rng.uniform(-0.45, 0.45, n), rng.uniform(-0.2, 0.2, n)]
    d = T - o
    L = np.linalg.norm(d, axis=1)
    h = e.cast(o, d / L[:, None])
    assert np.all(h.shape == 0)
    assert np.abs(h.distance - L).max() <= BOUND[prec]
    assert np.allclose(h.normal, [-1, 0, 0], atol=1e-12)
    # floor top z = -2.9 and the plane z = 10 (analytic, float64 in both modes)
    d = _unit(np.c_[rng.normal(size=(n, 2)) * 0.3, -np.ones(n)])
    h = e.cast(o, d)
    assert np.all(h.shape == 2)
    assert np.abs(h.distance - (base[2] - 2.9 - o[:, 2]) / d[:, 2]).max() <= BOUND[prec]
    h = e.cast(o, -d)
    assert np.all(h.shape == 5)
    assert np.abs(h.distance - (base[2] + 10 - o[:, 2]) / -d[:, 2]).max() <= 1e-12 * (1 + offset / 1e3)
    # curved: rays at the centre (sphere), at the axis (cylinder side, capsule side)
    for shape, centre, r, gap in ((1, [0, 5, 0], 1.3, _shell_gap(Sphere(1.3))),
                                  (3, [0, -5, 0], 0.5, _shell_gap(Cylinder(0.5, 2.0))),
                                  (4, [-5, 0, 0], 0.5, _shell_gap(Capsule(0.5, 1.0)))):
        c = base + centre
        oc = o.copy()
        if shape != 1:  # horizontal rays at the axis, within the straight part
            oc[:, 2] = base[2] + rng.uniform(-0.45, 0.45, n)
        d = c - oc
        d[:, 2] = 0.0 if shape != 1 else d[:, 2]
        L = np.linalg.norm(d, axis=1)
        h = e.cast(oc, d / L[:, None])
        assert np.all(h.shape == shape)
        err = h.distance - (L - r)
        if prec == Precision.EXACT:
            assert np.abs(err).max() <= 1e-12
        else:
            # shell gap + the few-ulp inflation that keeps float32 rounding outside the surface
            assert err.max() <= BOUND[prec] and err.min() >= -gap - 1e-5


def _slab(o, d, lo, hi):
    """Float64 ray/AABB entry distance (inf if missed), for many boxes at once: (n, k)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo[None] - o[:, None]) / d[:, None]
        t2 = (hi[None] - o[:, None]) / d[:, None]
    tn = np.nanmax(np.minimum(t1, t2), axis=2)
    tf = np.nanmin(np.maximum(t1, t2), axis=2)
    return np.where((tn <= tf) & (tn > 0), tn, np.inf)


@pytest.mark.parametrize("offset", [0.0, 1e6])
@pytest.mark.parametrize("prec", BOTH)
def test_lidar_in_room_far_from_origin(prec, offset):
    rng = np.random.default_rng(5)
    boxes = [((20, 20, 0.2), (0, 0, -0.1)), ((20, 20, 0.2), (0, 0, 3.1)),
             ((0.2, 20.4, 3.4), (10.1, 0, 1.5)), ((0.2, 20.4, 3.4), (-10.1, 0, 1.5)),
             ((20, 0.2, 3), (0, 10.1, 1.5)), ((20, 0.2, 3), (0, -10.1, 1.5))]
    while len(boxes) < 40:  # furniture, not overlapping the lidar
        size = rng.uniform(0.3, 1.5, 3)
        c = np.r_[rng.uniform(-8, 8, 2), size[2] / 2 + rng.uniform(0, 1.0)]
        if np.linalg.norm(c[:2]) > 2.0:
            boxes.append((tuple(size), tuple(c)))
    base = np.array([offset, offset / 2, 0.0])
    e = RayEngine(prec)
    for size, c in boxes:
        e.add_body([entry(Box(size))], at(*(base + c)))
    az = np.linspace(0, 2 * np.pi, 3600, endpoint=False) + 0.0123
    el = np.linspace(-0.3, 0.3, 5)
    A, E = np.meshgrid(az, el)
    d = np.stack([np.cos(A) * np.cos(E), np.sin(A) * np.cos(E), np.sin(E)], -1).reshape(-1, 3)
    lidar = np.array([0.31, -0.17, 1.23])
    h = e.cast(np.tile(base + lidar, (len(d), 1)), d, kind=RayKind.VISUAL)
    lo = np.array([np.subtract(c, np.divide(s, 2)) for s, c in boxes])
    hi = np.array([np.add(c, np.divide(s, 2)) for s, c in boxes])
    t_all = _slab(np.tile(lidar, (len(d), 1)), d, lo, hi)
    ref = np.argmin(t_all, axis=1)
    t_ref = t_all[np.arange(len(d)), ref]
    srt = np.sort(t_all, axis=1)
    clear = srt[:, 1] - srt[:, 0] > 1e-6  # not at a corner where two boxes meet
    assert clear.mean() > 0.98
    assert np.all(np.isfinite(h.distance))
    bound = {Precision.EXACT: 1e-9, Precision.FAST: 2e-5}[prec]
    if prec == Precision.EXACT:
        assert np.array_equal(h.shape[clear], ref[clear])  # the right surface, every ray
    else:
        assert (h.shape[clear] == ref[clear]).mean() > 0.999
    assert np.abs(h.distance - t_ref).max() <= bound


# ---------------------------------------------------------------------------------------------
# watertightness


def _adversarial_rays(vertices, edges, rng, reps):
    """Rays through vertices and edge midpoints of a convex closed mesh centred at the origin,
    from inside (exit there) and from outside (enter there); true first-hit distance known."""
    targets = np.vstack([vertices, vertices[edges].mean(1)])
    scale = np.abs(vertices).max(0)
    os, ds, ts = [], [], []
    for _ in range(reps):
        inner = rng.uniform(-0.4, 0.4, targets.shape) * scale
        d = targets - inner
        ts.append(np.linalg.norm(d, axis=1))
        ds.append(d / ts[-1][:, None])
        os.append(inner)
        inner = rng.uniform(-0.4, 0.4, targets.shape) * scale  # outside: continue toward inside
        d = _unit(inner - targets)
        dist = rng.uniform(0.5, 3.0, len(targets)) * scale.max()
        os.append(targets - d * dist[:, None])
        ds.append(d)
        ts.append(dist)
    return np.vstack(os), np.vstack(ds), np.concatenate(ts)


def _leaks(prec, mesh, offset, reps, rng, perturb=0.0):
    """(leaks, rays, repairs, worst error of the non-leaking rays).  A leak = the reported hit is
    not the true first hit (missed, or farther by more than 1e-6 relative)."""
    e = RayEngine(prec)
    base = np.array([offset, 0.0, 0.0])
    e.add_body([entry(Mesh(mesh.vertices, mesh.faces, closed=bool(mesh.is_watertight)))], at(*base))
    o, d, t = _adversarial_rays(mesh.vertices, mesh.edges_unique, rng, reps)
    if perturb:  # aim 1e-8 (relative) beside the vertex/edge: robust traversal alone can leak there
        target = o + d * t[:, None] + rng.normal(size=o.shape) * perturb * np.abs(mesh.vertices).max()
        d = target - o
        t = np.linalg.norm(d, axis=1)
        d /= t[:, None]
    h = e.cast(o + base, d)
    err = np.abs(h.distance - t)
    leaked = ~(err <= 1e-6 * (1 + t))
    return int(leaked.sum()), len(t), e.counters["leak_repairs"], float(err[~leaked].max() / (1 + t.max()))


WATERTIGHT_CASES = [  # name, mesh, world offset, repetitions, perturbation
    ("icosphere", lambda: trimesh.creation.icosphere(subdivisions=3, radius=1.7), 0.0, 2, 0.0),
    ("icosphere~1e-8", lambda: trimesh.creation.icosphere(subdivisions=3, radius=1.7), 0.0, 1, 1e-8),
    ("box", lambda: trimesh.creation.box(extents=(1.0, 2.0, 3.0)), 0.0, 100, 0.0),
    ("box~1e-8", lambda: trimesh.creation.box(extents=(1.0, 2.0, 3.0)), 0.0, 50, 1e-8),
    ("icosphere@1e5", lambda: trimesh.creation.icosphere(subdivisions=2, radius=0.9), 1e5, 2, 0.0),
]


def test_watertight_exact_zero_leaks_fast_reported(record_property):
    rng = np.random.default_rng(2024)
    total = {p: [0, 0, 0] for p in BOTH}
    for name, make, offset, reps, perturb in WATERTIGHT_CASES:
        mesh = make()
        assert mesh.is_watertight
        for prec in BOTH:
            leaks, n, repairs, worst = _leaks(prec, mesh, offset, reps, np.random.default_rng(rng.integers(1 << 30)), perturb)
            total[prec][0] += leaks
            total[prec][1] += n
            total[prec][2] += repairs
            record_property(f"{name}-{prec.value}", f"{leaks} leaks / {n} rays, {repairs} repairs, worst {worst:.1e}")
            if prec == Precision.EXACT and not perturb:
                # every EXACT hit is float64-accurate (plus the rounding of the offset vertices)
                assert worst <= 1e-12 + 4 * np.spacing(offset)
    n_rays = total[Precision.EXACT][1]
    assert n_rays >= 10_000
    record_property("fast_leaks", f"{total[Precision.FAST][0]} / {n_rays}")
    record_property("exact_leaks", f"{total[Precision.EXACT][0]} / {n_rays} ({total[Precision.EXACT][2]} repaired)")
    print(f"\nwatertightness over {n_rays} adversarial rays: FAST {total[Precision.FAST][0]} leaks, "
          f"EXACT {total[Precision.EXACT][0]} leaks ({total[Precision.EXACT][2]} repairs)")
    assert total[Precision.EXACT][0] == 0


def test_leak_repair_alone_on_a_plain_bvh(monkeypatch):
    """The offset-copy repair on its own (EXACT forced onto a non-robust BVH, which leaks ~5% of
    these rays): it must catch at least 99% of the leaks and count them."""
    from sensorium.server.raycast import tiers
    plain = tiers._Tier.scene
    monkeypatch.setattr(tiers._Tier, "scene", lambda self, robust: plain(self, False))
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=1.7)
    fast_leaks, n, _, _ = _leaks(Precision.FAST, mesh, 0.0, 1, np.random.default_rng(4))
    leaks, n, repairs, _ = _leaks(Precision.EXACT, mesh, 0.0, 1, np.random.default_rng(4))
    assert fast_leaks > 100
    assert repairs >= fast_leaks - leaks and leaks <= 0.01 * fast_leaks


def test_watertight_sphere_primitive_exact():
    """Rays through the circumscribed shell's vertices and edge midpoints must still find the
    TRUE sphere (EXACT): a leak through the shell would lose the hit."""
    sph = Sphere(1.1, 2)
    v, f = tessellate(sph)
    m = trimesh.Trimesh(v, f, process=False)
    rng = np.random.default_rng(9)
    e = RayEngine(Precision.EXACT)
    e.add_body([entry(sph)], Pose.identity())
    o, d, _ = _adversarial_rays(v, m.edges_unique, rng, 1)
    h = e.cast(o, d)
    b = (o * d).sum(1)
    c = (o * o).sum(1) - 1.1 ** 2
    disc = b * b - c
    t_ref = np.where(c < 0, -b + np.sqrt(np.maximum(disc, 0)), -b - np.sqrt(np.maximum(disc, 0)))
    t_ref = np.where(disc >= 0, t_ref, np.inf)
    hit_ref = np.isfinite(t_ref) & (t_ref > 0)
    assert np.array_equal(hit_ref, h.shape == 0)
    assert np.abs(h.distance[hit_ref] - t_ref[hit_ref]).max() <= 1e-12


# ---------------------------------------------------------------------------------------------
# one static world spanning a huge extent: coarse float32 frame, EXACT must stay exact


def _fibonacci_sphere(n):
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(1.0 - z * z)
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    return np.c_[r * np.cos(phi), r * np.sin(phi), z]


@pytest.mark.parametrize("far", [1e4, pytest.param(1e6, marks=pytest.mark.xfail(
    reason="open: at 3 cm float32 resolution Embree can miss a nearer shape's edge outright and hit a "
           "farther shape whose float64 refinement succeeds (~46 of 65,536 rays)", strict=False))])
def test_exact_room_in_huge_static_world(far):
    """A ~10 m room at (far, far/2, 0) plus one box at the origin: ONE static tier spans both, so
    its anchored float32 frame has a resolution of ~1 mm (1e4 m) / ~3 cm (1e6 m) at the room.  Near box edges float32 Embree can
    pick the neighbouring face's triangle; EXACT must still give the float64 answer on the right
    box (before the float64 barycentric check: up to 1.8 mm / 1.4 cm off on 5-30 rays)."""
    boxes = [((10, 10, 0.2), (0, 0, -0.1)), ((10, 10, 0.2), (0, 0, 3.1)),
             ((0.2, 10.4, 3.4), (5.1, 0, 1.5)), ((0.2, 10.4, 3.4), (-5.1, 0, 1.5)),
             ((10, 0.2, 3), (0, 5.1, 1.5)), ((10, 0.2, 3), (0, -5.1, 1.5)),
             ((1.0, 0.6, 0.8), (2.0, 1.5, 0.4)), ((0.7, 1.3, 1.1), (-2.5, -1.0, 0.55)),
             ((0.5, 0.5, 2.0), (1.0, -3.0, 1.0))]
    base = np.array([far, far / 2, 0.0])
    e = RayEngine(Precision.EXACT)
    for size, c in boxes:
        e.add_body([entry(Box(size))], at(*(base + c)))
    e.add_body([entry(Box((1, 1, 1)))], at(0, 0, 0))   # landmark: the tier spans 0..far
    d = _fibonacci_sphere(65536)
    lidar = np.array([0.31, -0.17, 1.23])
    o = np.tile(lidar, (len(d), 1))   # reference in the room's frame (world inputs round by ~1e-10 m)
    h = e.cast(o + base, d)
    lo = np.array([np.subtract(c, np.divide(s, 2)) for s, c in boxes])
    hi = np.array([np.add(c, np.divide(s, 2)) for s, c in boxes])
    t_all = _slab(o, d, lo, hi)
    ref = np.argmin(t_all, axis=1)
    t_ref = t_all[np.arange(len(d)), ref]
    srt = np.sort(t_all, axis=1)
    # not at a seam where two boxes meet within float32 resolution (a documented limit)
    clear = srt[:, 1] - srt[:, 0] > 1e-2
    assert clear.mean() > 0.98
    assert np.all(np.isfinite(t_ref)) and np.all(np.isfinite(h.distance))
    err = np.abs(h.distance - t_ref)
    assert np.array_equal(h.shape[clear], ref[clear]), int((h.shape[clear] != ref[clear]).sum())
    assert err[clear].max() <= 1e-9, (float(err[clear].max()), int((err[clear] > 1e-9).sum()))


@pytest.mark.parametrize("native", [True, False])
@pytest.mark.parametrize("far", [1e4, 1e5, 1e6])
def test_exact_sees_a_surface_nearer_than_a_coarse_tiers_epsilon(far, native):
    """One static tier spanning 0..far (a box at the origin, a room at far): its float32 frame is
    coarse at the room (eps = 8 float32 ulps ~ 4 mm at 1e4 m, 3 cm at 1e5 m, 25 cm at 1e6 m).
    EXACT started its casts eps along the ray, so a wall 1 mm (1e4 m) to 25 cm (1e6 m) in front of
    a sensor was not there: the ray went on to the wall's back face. A ray starting on the face
    still never reports it. The same in packets.c's EXACT pass and in numpy's (``native``)."""
    base = np.array([far, 0.0, 0.0])
    e = RayEngine(Precision.EXACT)
    e.native = native
    e.add_body([entry(Box((1, 4, 4)))], at(*(base + [0.5, 0, 0])))        # faces at x = 0 and 1
    e.add_body([entry(Box((0.5, 4, 4)))], at(*(base + [-2.25, 0, 0])))    # x in [-2.5, -2]
    e.add_body([entry(Sphere(0.5))], at(*(base + [0, 5, 0])))
    e.add_body([entry(Box((1, 1, 1)))], at(0, 0, 0))                        # landmark at the origin
    assert e._static_tier("bounding").eps > 1e-3
    rng = np.random.default_rng(3)
    n = 64
    yz = np.c_[rng.uniform(-1.5, 1.5, n), rng.uniform(-1.5, 1.5, n)]
    plus_x = np.tile([1.0, 0.0, 0.0], (n, 1))
    for gap in (1e-4, 1e-3, 1e-2, 0.05, 0.3):
        o = base + np.c_[np.full(n, -gap), yz]
        h = e.cast(o, plus_x)
        np.testing.assert_allclose(h.distance, gap, rtol=0, atol=1e-9)
        assert np.all(h.shape == 0)
    on = base + np.c_[np.zeros(n), yz]
    np.testing.assert_allclose(e.cast(on, plus_x).distance, 1.0, rtol=0, atol=1e-9)    # from the face: the back
    np.testing.assert_allclose(e.cast(on, -plus_x).distance, 2.0, rtol=0, atol=1e-9)   # away: the next box
    # towards the sphere's centre from 1 mm and 2 cm off its surface: the closed form
    u = _unit(rng.normal(size=(n, 3)))
    for gap in (1e-3, 2e-2):
        h = e.cast(base + [0, 5, 0] + (0.5 + gap) * u, -u)
        np.testing.assert_allclose(h.distance, gap, rtol=0, atol=1e-9)


def test_exact_shadow_rays_from_a_floor_in_a_coarse_tier_are_not_repaired_onto_it():
    """Rays from points on a floor's face towards a light (a camera's shadow rays), in a static tier
    spanning 1e5 m (no edge guards there: the offset-copy repair). Started near their face, the copy
    met the face and "repaired" the ray onto it, to be continued past it: ~2/3 of the rays, a camera
    with shadows ~9x slower. The repair never looks before the accepted minimum now."""
    e = RayEngine(Precision.EXACT)
    e.add_body([entry(Box((20, 20, 0.2)))], at(0, 0, -0.5))       # top face z = -0.4
    e.add_body([entry(Sphere(0.5))], at(3, 0, 0.5))
    e.add_body([entry(Box((1, 1, 1)))], at(1e5, 0, 0))
    rng = np.random.default_rng(1)
    n = 2000
    p = np.c_[rng.uniform(-5, 8, n), rng.uniform(-5, 5, n), np.full(n, -0.4)]
    light = np.array([2.0, 2.0, 3.0])
    d = light - p
    length = np.linalg.norm(d, axis=1)
    d /= length[:, None]
    h = e.cast(p, d, 0.0, length)
    assert not e._static_tier("bounding").guarded
    assert e.counters["leak_repairs"] <= n // 16 and e.counters["continued_rays"] <= n // 16
    oc = p - [3.0, 0.0, 0.5]                                      # the sphere in the way, else nothing
    b = np.einsum("ij,ij->i", oc, d)
    disc = b * b - (np.einsum("ij,ij->i", oc, oc) - 0.25)
    t = np.where(disc >= 0.0, -b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
    want = np.where((t > 0.0) & (t <= length), t, np.inf)
    assert np.isfinite(want).sum() > 20
    np.testing.assert_allclose(h.distance, want, rtol=1e-12)
