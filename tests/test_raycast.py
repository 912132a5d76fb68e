"""Ray engine behaviour against closed-form answers, in both precisions.

Error bounds asserted here (scene extent ~ 10-20 m, near the origin):

    quantity                         EXACT           FAST
    distance, flat faces / planes    1e-12 m         1e-5 m   (float32: ~10 ulps at 10 m)
    distance, sphere/cyl/capsule     1e-12 m         tessellation gap (shell is outside the surface)
    normals (unit, toward origin)    1e-12           1e-6 flat; facet normal for curved shells
"""

import math

import numpy as np
import pytest
import trimesh

from sensorium.server.raycast.engine import Precision, RayEngine, RayHits, RayKind, ShapeEntry
from sensorium.server.world.geometry import Box, Capsule, Cylinder, Mesh, Plane, Pose, Sphere, tessellate

EXACT_TOL = 1e-12
FAST_TOL = 1e-5
BOTH = [Precision.FAST, Precision.EXACT]
I = Pose.identity()


def at(x, y, z, axis=(0, 0, 1), angle=0.0):
    return Pose.from_axis_angle(axis, angle, [x, y, z])


def entry(p, pose=I, bounding=True, visual=True, transparent=False):
    return ShapeEntry(p, pose, bounding, visual, transparent)


def ray(engine, o, d, **kw) -> tuple[float, np.ndarray, int]:
    d = np.asarray(d, dtype=float)
    d = d / np.linalg.norm(d)
    h = engine.cast(np.asarray([o], dtype=float), d[None], **kw)
    return float(h.distance[0]), h.normal[0], int(h.shape[0])


def tol(prec):
    return EXACT_TOL if prec == Precision.EXACT else FAST_TOL


def shell_gap(p) -> float:
    """How far the circumscribed tessellation reaches outside the true surface (FAST error bound
    for rays aimed at the shape's axis/centre)."""
    v, _ = tessellate(p)
    if isinstance(p, Sphere):
        return float(np.linalg.norm(v, axis=1).max() - p.radius)
    if isinstance(p, Cylinder):
        return float(np.hypot(v[:, 0], v[:, 1]).max() - p.radius)
    h = p.height / 2
    q = v.copy()
    q[:, 2] = np.sign(q[:, 2]) * np.maximum(np.abs(q[:, 2]) - h, 0.0)
    return float(np.linalg.norm(q, axis=1).max() - p.radius)


# ---------------------------------------------------------------------------------------------
# primitives


@pytest.mark.parametrize("prec", BOTH)
def test_box_faces_and_inside_exit(prec):
    e = RayEngine(prec)
    e.add_body([entry(Box((2.0, 1.0, 0.5)))], at(5, 0, 0))
    t, n, s = ray(e, (0, 0.1, 0.05), (1, 0, 0))
    assert s == 0 and abs(t - 4.0) <= tol(prec)
    assert np.allclose(n, [-1, 0, 0], atol=1e-12)
    t, n, s = ray(e, (5.2, 0.1, 3.0), (0, 0, -1))  # top face
    assert abs(t - 2.75) <= tol(prec) and np.allclose(n, [0, 0, 1], atol=1e-12)
    # origin inside the box: the exit face is reported (ODE), normal toward the origin
    t, n, s = ray(e, (5.5, 0.0, 0.0), (1, 0, 0))
    assert abs(t - 0.5) <= tol(prec) and np.allclose(n, [-1, 0, 0], atol=1e-12)


@pytest.mark.parametrize("prec", BOTH)
def test_rotated_box_matches_slab_formula(prec):
    pose = at(3, -2, 1, axis=(1, 2, 3), angle=0.8)
    size = np.array([1.5, 0.7, 1.1])
    e = RayEngine(prec)
    e.add_body([entry(Box(tuple(size)))], pose)
    rng = np.random.default_rng(7)
    targets = pose.apply(rng.uniform(-0.3, 0.3, (50, 3)) * size)
    o = np.array([[-4.0, 3.0, 5.0]])
    d = targets - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    h = e.cast(np.repeat(o, 50, 0), d)
    # slab method in the box frame (independent float64 reference)
    ol = pose.inverse().apply(o)[0]
    dl = pose.inverse().apply_dirs(d)
    t1 = (-size / 2 - ol) / dl
    t2 = (size / 2 - ol) / dl
    t_ref = np.minimum(t1, t2).max(1)
    axis = np.argmax(np.minimum(t1, t2), axis=1)
    n_ref = np.zeros((50, 3))
    n_ref[np.arange(50), axis] = -np.sign(dl[np.arange(50), axis])
    n_ref = pose.apply_dirs(n_ref)
    assert np.all(np.abs(h.distance - t_ref) <= tol(prec))
    assert np.allclose(h.normal, n_ref, atol=1e-12)
    assert np.all(h.shape == 0)


@pytest.mark.parametrize("prec", BOTH)
def test_sphere_distance_and_normal(prec):
    sph = Sphere(1.3)
    c = np.array([0.4, 4.0, 0.2])
    e = RayEngine(prec)
    e.add_body([entry(sph)], at(*c))
    o = np.zeros(3)
    # radial ray
    t, n, s = ray(e, o, c)
    dist_c = np.linalg.norm(c)
    if prec == Precision.EXACT:
        assert abs(t - (dist_c - 1.3)) <= EXACT_TOL
        assert np.allclose(n, -c / dist_c, atol=1e-12)
    else:  # the shell lies outside the sphere by at most its gap
        assert dist_c - 1.3 - shell_gap(sph) - FAST_TOL <= t <= dist_c - 1.3 + FAST_TOL
        assert np.dot(n, -c / dist_c) > 0.99
    # off-centre rays with impact parameter b: t = s - sqrt(r^2 - b^2)
    rng = np.random.default_rng(3)
    for b in (0.0, 0.5, 1.0, 1.29):
        side = np.cross(c, rng.normal(size=3))
        side /= np.linalg.norm(side)
        target = c + side * b
        d = target / np.linalg.norm(target)
        proj = np.dot(c, d)
        bb = np.linalg.norm(c - proj * d)
        t_ref = proj - math.sqrt(1.3 ** 2 - bb ** 2)
        t, n, _ = ray(e, o, d)
        if prec == Precision.EXACT:
            assert abs(t - t_ref) <= EXACT_TOL
            assert np.allclose(n, (t_ref * d - c) / 1.3, atol=1e-9)
        else:
            assert t <= t_ref + FAST_TOL


@pytest.mark.parametrize("prec", BOTH)
def test_cylinder_side_and_caps(prec):
    cyl = Cylinder(0.5, 2.0)
    e = RayEngine(prec)
    e.add_body([entry(cyl)], at(0, -5, 0))
    t, n, _ = ray(e, (0, 0, 0.3), (0, -1, 0))  # side, aimed at the axis
    if prec == Precision.EXACT:
        assert abs(t - 4.5) <= EXACT_TOL and np.allclose(n, [0, 1, 0], atol=1e-12)
    else:
        assert 4.5 - shell_gap(cyl) - FAST_TOL <= t <= 4.5 + FAST_TOL
    for z0, dz, t_ref, nz in ((10.0, -1, 9.0, 1.0), (-7.0, 1, 6.0, -1.0)):  # top and bottom caps
        t, n, _ = ray(e, (0.2, -5.1, z0), (0, 0, dz))
        assert abs(t - t_ref) <= tol(prec)  # caps are exact planes in both modes
        assert np.allclose(n, [0, 0, nz], atol=1e-12)
    # oblique side hit off the axis: x^2 + y^2 = r^2 in the cylinder frame
    e2 = RayEngine(prec)
    e2.add_body([entry(cyl)], at(0, 0, 0, axis=(1, 0, 0), angle=math.pi / 2))  # axis along -y
    t, n, _ = ray(e2, (0.3, 0.1, 5.0), (0, 0, -1))
    t_ref = 5.0 - math.sqrt(0.25 - 0.09)
    if prec == Precision.EXACT:
        assert abs(t - t_ref) <= EXACT_TOL
        assert np.allclose(n, [0.6, 0, 0.8], atol=1e-12)
    else:
        assert t <= t_ref + FAST_TOL and t >= t_ref - 0.01


@pytest.mark.parametrize("prec", BOTH)
def test_capsule_side_and_hemispheres(prec):
    cap = Capsule(0.5, 1.0)
    e = RayEngine(prec)
    e.add_body([entry(cap)], at(-5, 0, 0))
    cases = [
        ((0, 0, 0.2), (-1, 0, 0), 4.5, (1, 0, 0)),            # cylindrical part
        ((-5, 0, 10), (0, 0, -1), 9.0, (0, 0, 1)),            # top pole
        ((-4.7, 0, 10), (0, 0, -1), 9.1, (0.6, 0, 0.8)),      # top hemisphere, off axis
        ((-5, 0.3, -10), (0, 0, 1), 9.1, (0, 0.6, -0.8)),     # bottom hemisphere
    ]
    for o, d, t_ref, n_ref in cases:
        t, n, s = ray(e, o, d)
        assert s == 0
        if prec == Precision.EXACT:
            assert abs(t - t_ref) <= EXACT_TOL
            assert np.allclose(n, n_ref, atol=1e-12)
        else:
            assert t_ref - shell_gap(cap) / 0.8 - FAST_TOL <= t <= t_ref + FAST_TOL


@pytest.mark.parametrize("prec", BOTH)
def test_planes_bounding_infinite_two_sided_visual_one_sided_finite(prec):
    e = RayEngine(prec)
    tilt = at(0, 0, -1, axis=(1, 0, 0), angle=0.2)  # normal (0, -sin .2, cos .2)
    e.add_body([entry(Plane((2.0, 2.0)), tilt)], I)
    nz = tilt.rotation[:, 2]
    for kind in (RayKind.BOUNDING, RayKind.VISUAL):
        # from the +z side, inside the finite size: both kinds hit
        t, n, s = ray(e, (0, 0, 0), (0, 0, -1), kind=kind)
        # the plane passes through (0, 0, -1), which is on the ray: t = 1 whatever the tilt
        assert s == 0 and abs(t - 1.0) <= EXACT_TOL and np.allclose(n, nz, atol=1e-12)
    # outside the finite size: BOUNDING ignores the size (ODE), VISUAL misses
    o, d = np.array([5.0, 0.0, 0.0]), np.array([0.0, 0.0, -1.0])
    t_ref = np.dot(nz, [0, 0, -1] - o) / np.dot(nz, d)
    t, n, _ = ray(e, o, d, kind=RayKind.BOUNDING)
    assert abs(t - t_ref) <= EXACT_TOL
    assert math.isinf(ray(e, o, d, kind=RayKind.VISUAL)[0])
    # from below: BOUNDING is two-sided (normal flipped toward the origin), VISUAL one-sided
    t, n, _ = ray(e, (0, 0, -3), (0, 0, 1), kind=RayKind.BOUNDING)
    assert abs(t - 2.0) <= EXACT_TOL and np.allclose(n, -nz, atol=1e-12)
    assert math.isinf(ray(e, (0, 0, -3), (0, 0, 1), kind=RayKind.VISUAL)[0])
    # infinite visual plane
    e2 = RayEngine(prec)
    e2.add_body([entry(Plane())], at(0, 0, -1))
    assert abs(ray(e2, (1e3, -2e3, 0), (0, 0, -1), kind=RayKind.VISUAL)[0] - 1.0) <= EXACT_TOL
    # parallel ray never hits
    assert math.isinf(ray(e2, (0, 0, 0), (1, 0, 0))[0])


@pytest.mark.parametrize("prec", BOTH)
def test_trimesh_meshes(prec):
    box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    cyl = trimesh.creation.cylinder(radius=0.5, height=1.0, sections=24)
    e = RayEngine(prec)
    e.add_body([entry(Mesh(box.vertices, box.faces, closed=bool(box.is_watertight)))],
               at(0, 0, 5, axis=(0, 0, 1), angle=math.pi / 6))
    e.add_body([entry(Mesh(cyl.vertices, cyl.faces, closed=True))], at(0, 6, 0))
    t, n, s = ray(e, (0.05, -0.1, 0), (0, 0, 1))  # bottom face of the box mesh at z = 3.5
    assert s == 0 and abs(t - 3.5) <= tol(prec) and np.allclose(n, [0, 0, -1], atol=1e-12)
    t, n, s = ray(e, (0.1, 6.1, -4), (0, 0, 1))  # bottom cap of the cylinder mesh at z = -0.5
    assert s == 1 and abs(t - 3.5) <= tol(prec) and np.allclose(n, [0, 0, -1], atol=1e-12)
    # side of the 24-gon: a facet plane, distance = apothem along the facet normal
    ang = 2 * math.pi * (0.5) / 24  # trimesh puts vertices at k*2pi/24; facet 0 normal at pi/24
    d = -np.array([math.cos(ang), math.sin(ang), 0.0])
    apothem = 0.5 * math.cos(math.pi / 24)
    t, n, s = ray(e, np.array([0, 6, 0.1]) - 3 * d, d)
    assert s == 1 and abs(t - (3 - apothem)) <= tol(prec)
    assert np.allclose(n, -d, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# grazing rays, rays starting on surfaces


@pytest.mark.parametrize("prec", BOTH)
def test_grazing_parallel_to_face(prec):
    e = RayEngine(prec)
    e.add_body([entry(Box((1.0, 1.0, 1.0)))], at(3, 0, 0))     # top face z = 0.5
    e.add_body([entry(Box((0.2, 10.0, 10.0)))], at(8, 0, 0))   # backdrop, face x = 7.9
    t, _, s = ray(e, (0, 0.1, 0.5 + 1e-5), (1, 0, 0))
    assert s == 1 and abs(t - 7.9) <= tol(prec)
    t, n, s = ray(e, (0, 0.1, 0.5 - 1e-5), (1, 0, 0))
    assert s == 0 and abs(t - 2.5) <= tol(prec) and np.allclose(n, [-1, 0, 0])
    # along the plane of a side face from outside, just beside it
    t, _, s = ray(e, (3.5 + 1e-5, -5, 0), (0, 1, 0))
    assert s == -1


def test_tangent_to_sphere_exact():
    e = RayEngine(Precision.EXACT)
    e.add_body([entry(Sphere(1.0))], at(0, 5, 0))
    # line at distance 1 + 1e-7 from the centre misses, 1 - 1e-7 hits near the tangent point
    assert ray(e, (1 + 1e-7, 0, 0), (0, 1, 0))[2] == -1
    t, n, s = ray(e, (1 - 1e-7, 0, 0), (0, 1, 0))
    t_ref = 5 - math.sqrt(1 - (1 - 1e-7) ** 2)
    assert s == 0 and abs(t - t_ref) <= 1e-12
    assert abs(n[0] - (1 - 1e-7)) <= 1e-9 and np.dot(n, [0, 1, 0]) <= 0


def test_tangent_to_sphere_fast_hits_shell_only_nearby():
    """FAST sees the circumscribed shell: a ray passing just outside the sphere may hit the shell,
    but never farther than the shell gap from the sphere."""
    sph = Sphere(1.0)
    e = RayEngine(Precision.FAST)
    e.add_body([entry(sph)], at(0, 5, 0))
    for b in (1 + 1e-7, 1 + shell_gap(sph) / 2, 1 + 2 * shell_gap(sph)):
        t, n, s = ray(e, (b, 0, 0), (0, 1, 0))
        if b > 1 + shell_gap(sph):
            assert s == -1
        elif s == 0:
            assert abs(t - 5) <= 0.2


@pytest.mark.parametrize("prec", BOTH)
def test_rays_starting_on_a_surface(prec):
    e = RayEngine(prec)
    e.add_body([entry(Box((2.0, 2.0, 2.0)))], at(5, 0, 0))      # faces x = 4, 6
    e.add_body([entry(Box((0.2, 10.0, 10.0)))], at(-3, 0, 0))   # wall behind, face x = -2.9
    on = (4.0, 0.3, -0.2)
    t, _, s = ray(e, on, (-1, 0, 0))   # pointing away: the wall, not the face at t = 0
    assert s == 1 and abs(t - 6.9) <= tol(prec)
    t, _, s = ray(e, on, (0, 1, 0))    # along the face
    assert not (s == 0 and t < 1e-3)
    t, _, s = ray(e, on, (-1, 1, 0))   # away at 45 degrees
    assert s != 0
    t, n, s = ray(e, on, (1, 0, 0))    # into the box: its far face (exit)
    assert s == 0 and abs(t - 2.0) <= tol(prec) and np.allclose(n, [-1, 0, 0])
    # on a corner / edge, pointing out
    assert ray(e, (4.0, 1.0, 1.0), (-1, 0, 0))[2] == 1
    assert ray(e, (4.0, 1.0, 0.0), (-1, 1, 0))[2] == -1


@pytest.mark.parametrize("prec", BOTH)
@pytest.mark.parametrize("shape", [Sphere(0.5), Cylinder(0.5, 1.0), Capsule(0.5, 0.4)])
def test_sensor_flush_with_round_body_sees_outward(prec, shape):
    """A sensor on the true curved surface is INSIDE the circumscribed shell; pointing outward
    it must not see the shell (both modes), and must see what is beyond."""
    e = RayEngine(prec)
    e.add_body([entry(shape)], I, owner=0, movable=True)
    e.add_body([entry(Box((0.2, 10, 10)))], at(3, 0, 0))  # wall, face x = 2.9
    for ang in np.linspace(0, 2 * math.pi, 13):
        d = np.array([math.cos(ang), math.sin(ang), 0.0])
        t, _, s = ray(e, 0.5 * d, d, kind=RayKind.VISUAL)
        assert s != 0
        if s == 1:
            assert abs(t - (2.9 / d[0] - 0.5)) <= tol(prec)
        # and pointing inward the body is crossed: exit on the far side
        t, _, s = ray(e, 0.5 * d, -d, kind=RayKind.VISUAL)
        assert s == 0
        if prec == Precision.EXACT:
            assert abs(t - 1.0) <= EXACT_TOL


@pytest.mark.parametrize("prec", BOTH)
def test_origin_on_infinite_plane(prec):
    e = RayEngine(prec)
    e.add_body([entry(Plane())], I)
    assert ray(e, (1, 2, 0), (0, 0, 1))[2] == -1
    assert ray(e, (1, 2, 0), (1, 0, 0))[2] == -1
    assert ray(e, (1, 2, 0), (0, 0, -1))[2] == -1   # t = 0 is a self-hit
    assert abs(ray(e, (1, 2, 1e-3), (0, 0, -1))[0] - 1e-3) <= 1e-15


# ---------------------------------------------------------------------------------------------
# owners, movers, builds


@pytest.mark.parametrize("prec", BOTH)
def test_exclude_owner_scalar_and_per_ray(prec):
    e = RayEngine(prec)
    r0 = e.add_body([entry(Box((1, 1, 1)))], I, owner=0, movable=True)
    r1 = e.add_body([entry(Sphere(0.5))], at(3, 0, 0), owner=1, movable=True)
    e.add_body([entry(Box((0.2, 10, 10)))], at(6, 0, 0))           # static wall x = 5.9
    e.add_body([entry(Box((0.2, 1, 1)))], at(1.5, 0, 2), owner=1)  # static part owned by robot 1
    o = np.zeros((4, 3))
    o[3] = (0, 0, 2)
    d = np.tile([1.0, 0, 0], (4, 1))
    h = e.cast(o, d, exclude_owner=-1)
    assert h.shape.tolist()[:3] == [0, 0, 0] and h.shape[3] == 3
    h = e.cast(o, d, exclude_owner=0)
    assert h.shape[0] == 1 and abs(h.distance[0] - 2.5) <= (1e-12 if prec == Precision.EXACT else 0.01)
    assert h.shape[3] == 3
    h = e.cast(o, d, exclude_owner=np.array([0, 1, -1, 1]))
    assert h.shape.tolist() == [1, 0, 0, 2]
    assert abs(h.distance[3] - 5.9) <= tol(prec)
    assert e.shape_owner(0) == 0 and e.shape_owner(1) == 1 and e.shape_owner(2) == -1
    assert e.shape_body(3) == 3 and (r0, r1) == (0, 1)


@pytest.mark.parametrize("prec", BOTH)
def test_mover_pose_change_moves_hit_without_rebuild(prec):
    e = RayEngine(prec)
    body = e.add_body([entry(Box((1, 1, 1))), entry(Sphere(0.3), at(0, 0, 1))], at(4, 0, 0), owner=2, movable=True)
    e.add_body([entry(Box((0.2, 10, 10)))], at(20, 0, 0))
    o, d = np.zeros((2, 3)), np.array([[1.0, 0, 0], [1.0, 0, 0]])
    o[1, 2] = 1.0
    h = e.cast(o, d)
    assert h.shape.tolist() == [0, 1] and abs(h.distance[0] - 3.5) <= tol(prec)
    builds = e.counters["bvh_builds"]
    assert builds == 2  # static tier + the mover
    for x in (6.0, 9.0, 12.0):
        e.set_body_pose(body, at(x, 0, 0, axis=(0, 0, 1), angle=math.pi / 2))
        h = e.cast(o, d)
        assert abs(h.distance[0] - (x - 0.5)) <= tol(prec)
        if prec == Precision.EXACT:
            assert abs(h.distance[1] - (x - 0.3)) <= EXACT_TOL
        assert np.allclose(h.normal[0], [-1, 0, 0], atol=1e-12)
    assert e.counters["bvh_builds"] == builds
    # moving it out of the way reveals the wall
    e.set_body_pose(body, at(4, 50, 0))
    assert ray(e, (0, 0, 0), (1, 0, 0))[2] == 2
    assert e.counters["bvh_builds"] == builds


@pytest.mark.parametrize("prec", BOTH)
def test_static_to_mover_conversion_counts(prec):
    e = RayEngine(prec)
    walls = [e.add_body([entry(Box((0.2, 1, 1)))], at(x, 0, 0)) for x in (3, 6, 9)]
    for _ in range(10):  # many static bodies cost one build
        e.add_body([entry(Box((1, 1, 1)))], at(0, 30, 0))
    assert e.counters["bvh_builds"] == 0  # lazy
    assert ray(e, (0, 0, 0), (1, 0, 0))[2] == 0
    assert e.counters["bvh_builds"] == 1
    e.set_body_pose(walls[0], at(3, 5, 0))  # first move: static rebuilt once + one mover build
    t, _, s = ray(e, (0, 0, 0), (1, 0, 0))
    assert s == 1 and abs(t - 5.9) <= tol(prec)
    assert e.counters["bvh_builds"] == 3
    for y in (0.0, 5.0, 0.0):
        e.set_body_pose(walls[0], at(3, y, 0))
        ray(e, (0, 0, 0), (1, 0, 0))
    assert ray(e, (0, 0, 0), (1, 0, 0))[2] == 0
    assert e.counters["bvh_builds"] == 3
    ray(e, (0, 0, 0), (1, 0, 0), kind=RayKind.VISUAL)  # the other kind sees the same shapes: the same scenes
    assert e.counters["bvh_builds"] == 3


@pytest.mark.parametrize("prec", BOTH)
def test_t_near_t_far(prec):
    e = RayEngine(prec)
    e.add_body([entry(Box((1, 4, 4)))], at(5, 0, 0))    # faces x = 4.5 (entry) and 5.5 (exit)
    e.add_body([entry(Box((1, 4, 4)))], at(10, 0, 0))   # x = 9.5
    o, d = np.zeros((1, 3)), np.array([[1.0, 0, 0]])
    assert abs(e.cast(o, d, t_far=4.5).distance[0] - 4.5) <= tol(prec)    # exactly at t_far counts
    assert math.isinf(e.cast(o, d, t_far=4.49).distance[0])
    assert abs(e.cast(o, d, t_near=4.6).distance[0] - 5.5) <= tol(prec)   # inside: exit face
    assert abs(e.cast(o, d, t_near=5.6).distance[0] - 9.5) <= tol(prec)
    assert math.isinf(e.cast(o, d, t_near=5.6, t_far=9.0).distance[0])
    oo, dd = np.zeros((4, 3)), np.tile([1.0, 0, 0], (4, 1))
    h = e.cast(oo, dd, t_near=np.array([0, 4.6, 5.6, 0]), t_far=np.array([10, 10, 10, 4.0]))
    assert np.allclose(h.distance[:3], [4.5, 5.5, 9.5], atol=tol(prec)) and math.isinf(h.distance[3])
    assert h.shape.tolist() == [0, 0, 1, -1]


@pytest.mark.parametrize("prec", BOTH)
def test_degenerate_mesh_triangles(prec):
    v = np.array([[0, -1, -1], [0, 1, -1], [0, 0, 1], [0, 0, 0], [0, 0, 0], [0, 5, 5]], dtype=float)
    f = np.array([[0, 1, 2], [3, 4, 5], [0, 0, 1], [2, 2, 2], [0, 3, 4]])
    e = RayEngine(prec)
    e.add_body([entry(Mesh(v, f, closed=False))], at(2, 0, 0))
    only_bad = Mesh(v, f[1:], closed=False)
    e.add_body([entry(only_bad)], at(-2, 0, 0))
    e.add_body([entry(Mesh(np.zeros((0, 3)), np.zeros((0, 3), int), closed=False))], I)
    t, n, s = ray(e, (0, 0, 0), (1, 0, 0))
    assert s == 0 and abs(t - 2.0) <= tol(prec) and np.allclose(n, [-1, 0, 0])
    assert ray(e, (0, 0, 0), (-1, 0, 0))[2] == -1
    rng = np.random.default_rng(0)
    d = rng.normal(size=(500, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    h = e.cast(np.zeros((500, 3)), d)
    assert set(h.shape.tolist()) <= {0, -1}


@pytest.mark.parametrize("prec", BOTH)
def test_transparency_and_kinds(prec):
    e = RayEngine(prec)
    e.add_body([entry(Box((0.2, 2, 2)), transparent=True)], at(2, 0, 0))         # glass, x = 1.9
    e.add_body([entry(Box((0.2, 2, 2)), visual=False)], at(4, 0, 0))             # bounding only, x = 3.9
    e.add_body([entry(Box((0.2, 2, 2)), bounding=False)], at(6, 0, 0))           # visual only, x = 5.9
    o, d = (0, 0, 0), (1, 0, 0)
    assert ray(e, o, d)[2] == 0
    t, _, s = ray(e, o, d, skip_transparent=True)
    assert s == 1 and abs(t - 3.9) <= tol(prec)
    t, _, s = ray(e, o, d, kind=RayKind.VISUAL)
    assert s == 2 and abs(t - 5.9) <= tol(prec)
    assert ray(e, o, d, kind=RayKind.VISUAL, skip_transparent=True)[2] == 2
    # transparent plane too
    e2 = RayEngine(prec)
    e2.add_body([entry(Plane(), transparent=True)], at(0, 0, -1))
    assert ray(e2, o, (0, 0, -1))[2] == 0
    assert ray(e2, o, (0, 0, -1), skip_transparent=True)[2] == -1
    assert ray(e2, o, (0, 0, -1), kind=RayKind.VISUAL)[2] == -1


@pytest.mark.parametrize("prec", BOTH)
def test_counters_lazy_builds_and_empty_cases(prec):
    e = RayEngine(prec)
    h = e.cast(np.zeros((3, 3)), np.tile([1.0, 0, 0], (3, 1)))
    assert isinstance(h, RayHits) and np.all(np.isinf(h.distance)) and np.all(h.shape == -1)
    assert h.normal.shape == (3, 3) and h.distance.dtype == np.float64 and h.shape.dtype == np.int64
    for i in range(20):
        e.add_body([entry(Box((1, 1, 1)))], at(3 * i + 3, 0, 0))
    e.add_body([entry(Plane())], at(0, 0, -5))
    h = e.cast(np.zeros((0, 3)), np.zeros((0, 3)))
    assert len(h.distance) == 0
    h = e.cast(np.zeros((7, 3)), np.tile([1.0, 0, 0], (7, 1)))
    assert e.counters["bvh_builds"] == 1 and e.counters["rays_cast"] == 10
    assert e.counters["embree_calls"] >= 1 and "leak_repairs" in e.counters
    assert np.all(h.shape == 0)
    assert ray(e, (0, 0, 0), (0, 0, -1))[2] == 20


def test_precision_switch_between_casts():
    e = RayEngine()
    assert e.precision == Precision.EXACT
    e.add_body([entry(Sphere(1.0))], at(0, 3, 0))
    exact = ray(e, (0, 0, 0), (0, 1, 0))[0]
    e.precision = "fast"
    assert e.precision == Precision.FAST
    fast = ray(e, (0, 0, 0), (0, 1, 0))[0]
    e.precision = Precision.EXACT
    assert ray(e, (0, 0, 0), (0, 1, 0))[0] == exact == 2.0
    assert abs(fast - 2.0) <= shell_gap(Sphere(1.0)) + FAST_TOL


@pytest.mark.parametrize("prec", BOTH)
def test_normals_face_the_origin_and_are_unit(prec):
    e = RayEngine(prec)
    e.add_body([entry(Box((1, 2, 3)), at(0, 0, 0, (1, 1, 0), 0.4)),
                entry(Sphere(0.8), at(3, 0, 0)), entry(Cylinder(0.4, 1.0), at(0, 3, 0, (1, 0, 0), 1.0)),
                entry(Capsule(0.3, 0.6), at(-3, 0, 0, (0, 1, 0), 0.7))], I)
    rng = np.random.default_rng(11)
    o = rng.uniform(-6, 6, (2000, 3))
    centres = np.array([[0, 0, 0], [3, 0, 0], [0, 3, 0], [-3, 0, 0]])
    d = centres[rng.integers(0, 4, 2000)] + rng.normal(scale=0.6, size=(2000, 3)) - o
    d /= np.linalg.norm(d, axis=1)[:, None]
    h = e.cast(o, d)
    hit = h.shape >= 0
    assert hit.sum() > 1000
    assert np.allclose(np.linalg.norm(h.normal[hit], axis=1), 1.0, atol=1e-12)
    assert np.all((h.normal[hit] * d[hit]).sum(1) <= 1e-12)
    assert np.all(h.normal[~hit] == 0) and np.all(np.isinf(h.distance[~hit]))


@pytest.mark.parametrize("prec", BOTH)
@pytest.mark.parametrize("movable", [False, True])
def test_origin_in_shell_gap_heading_inward_with_short_range(prec, movable):
    """Regression: an origin between the circumscribed shell and the true surface, aimed into the
    shape, must hit the true surface even when t_far (or a nearer hit elsewhere) ends the cast
    before the shell's far side."""
    cyl = Cylinder(1.875, 2.0, 8)  # coarse: the shell reaches ~8 % outside the surface
    e = RayEngine(prec)
    e.add_body([entry(cyl)], I, movable=movable)
    e.add_body([entry(Box((0.2, 4, 4)))], at(-1.5, 0, 0))  # inside the cylinder, face x = -1.4
    # toward a shell vertex (angle 0) the shell reaches r / cos(pi/8) = 1.08 r: rho = 1.03 r is
    # in the gap, outside the true surface but inside the shell
    o = np.array([[1.875 * 1.03, 0.0, 0.3]])
    d = -o / np.linalg.norm(o)
    d[0, 2] = 0.0
    d /= np.linalg.norm(d)
    rho = float(np.hypot(o[0, 0], o[0, 1]))
    for t_far in (np.inf, 0.5):
        h = e.cast(o, d, t_far=t_far)
        assert h.shape[0] == 0
        assert abs(h.distance[0] - (rho - 1.875)) <= 1e-12
        assert np.allclose(h.normal[0], -d[0], atol=1e-12)


@pytest.mark.parametrize("prec", BOTH)
def test_plane_carried_by_a_mover(prec):
    e = RayEngine(prec)
    body = e.add_body([entry(Plane((1.0, 1.0)), at(0, 0, 0.1))], at(0, 0, 0), movable=True)
    for z in (-1.0, -2.5):
        e.set_body_pose(body, at(0.2, 0, z))
        t, n, s = ray(e, (0, 0, 0), (0, 0, -1), kind=RayKind.VISUAL)
        assert s == 0 and abs(t - (-z - 0.1)) <= EXACT_TOL and np.allclose(n, [0, 0, 1])
    e.set_body_pose(body, at(3.0, 0, -1))   # finite visual plane moved aside: missed visually
    assert ray(e, (0, 0, 0), (0, 0, -1), kind=RayKind.VISUAL)[2] == -1
    assert ray(e, (0, 0, 0), (0, 0, -1), kind=RayKind.BOUNDING)[2] == 0   # infinite for ODE
