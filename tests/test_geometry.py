"""Shape-local primitives, tessellation and poses (server/geometry.py)."""

import math

import numpy as np
import pytest
import trimesh

from sensorium.server.world.geometry import (
    Box,
    Capsule,
    Cylinder,
    Mesh,
    Plane,
    Pose,
    Sphere,
    capsule_segments,
    tessellate,
    triangle_count,
    valid_faces,
)

PRIMS = [
    Box((1.0, 2.0, 3.0)),
    Sphere(0.7, 0), Sphere(0.7, 1), Sphere(2.0, 3),
    Cylinder(0.5, 2.0), Cylinder(0.5, 0.1, 5), Cylinder(3.0, 0.5, 64),
    Capsule(0.3, 1.0), Capsule(0.3, 0.0, 4), Capsule(1.0, 5.0, 7),
]


def _face_planes(v, f):
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1)[:, None]
    return n, (n * tri[:, 0]).sum(1)


def _support(p, n):
    """Support function h(n) = max over the TRUE shape of n.x (shape-local)."""
    if isinstance(p, Box):
        return (np.abs(n) * np.asarray(p.size) / 2).sum(1)
    if isinstance(p, Sphere):
        return np.full(len(n), p.radius)
    if isinstance(p, Cylinder):
        return p.radius * np.hypot(n[:, 0], n[:, 1]) + p.height / 2 * np.abs(n[:, 2])
    return p.radius + p.height / 2 * np.abs(n[:, 2])


@pytest.mark.parametrize("p", PRIMS, ids=repr)
def test_tessellation_closed_outward_and_counted(p):
    v, f = tessellate(p)
    assert v.dtype == np.float64 and f.dtype == np.int64
    m = trimesh.Trimesh(v, f, process=False)
    assert m.is_watertight and m.is_winding_consistent
    assert m.volume > 0  # outward winding
    assert len(f) == triangle_count(p)


@pytest.mark.parametrize("p", PRIMS, ids=repr)
def test_curved_tessellation_is_circumscribed(p):
    """Every face plane lies at or outside the true surface (support function), so the true shape
    is inside the polyhedron; and the polyhedron is not grossly larger than the shape."""
    v, f = tessellate(p)
    n, d = _face_planes(v, f)
    h = _support(p, n)
    assert np.all(d >= h - 1e-12)
    if not isinstance(p, Box):
        # faces are tangent planes (closest face touches the surface)
        assert np.min(d - h) == pytest.approx(0.0, abs=1e-12)


def test_sphere_tessellation_gap_shrinks_with_level():
    gaps = []
    for level in range(4):
        v, _ = tessellate(Sphere(1.0, level))
        gaps.append(np.linalg.norm(v, axis=1).max() - 1.0)
    assert gaps == sorted(gaps, reverse=True)
    assert gaps[3] < 0.005  # level 3: vertices at most 0.5 % outside the sphere


def test_capsule_segments_and_counts():
    assert capsule_segments(12) == (24, 6)
    assert triangle_count(Capsule(0.1, 0.2)) == 4 * 24 * 6
    assert triangle_count(Cylinder(1, 1)) == 144
    assert triangle_count(Sphere(1)) == 1280
    assert triangle_count(Box((1, 1, 1))) == 12
    assert triangle_count(Plane()) == 0


def test_plane_not_tessellated():
    with pytest.raises(ValueError):
        tessellate(Plane())
    with pytest.raises(ValueError):
        tessellate(Plane((1.0, 2.0)))


@pytest.mark.parametrize("bad", [
    lambda: Box((1, 0, 1)), lambda: Box((1, 1)), lambda: Sphere(-1), lambda: Sphere(1, 9),
    lambda: Cylinder(1, 0), lambda: Cylinder(1, 1, 2), lambda: Capsule(1, -1), lambda: Capsule(0, 1),
    lambda: Plane((1, 0)), lambda: Sphere(float("nan")),
])
def test_invalid_parameters_rejected(bad):
    with pytest.raises(ValueError):
        bad()


def test_primitives_are_hashable_values():
    assert Box((1, 2, 3)) == Box((1.0, 2.0, 3.0))
    assert hash(Sphere(1.0)) == hash(Sphere(1))
    assert Plane() != Plane((1.0, 1.0))


def test_mesh_validation_and_degenerate_faces():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0], [0, 0, 0]], dtype=float)
    f = np.array([[0, 1, 2], [0, 0, 1], [0, 1, 3], [0, 4, 1], [1, 2, 2]])
    m = Mesh(v, f, closed=False)
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int64
    assert not m.vertices.flags.writeable
    vv, ff = tessellate(m)
    # repeated index, collinear (zero area), coincident vertices: all dropped
    assert ff.tolist() == [[0, 1, 2]]
    assert triangle_count(m) == 1
    assert len(valid_faces(v, np.zeros((0, 3), int))) == 0
    with pytest.raises(ValueError):
        Mesh(v, [[0, 1, 9]], closed=False)
    with pytest.raises(ValueError):
        Mesh([[0, 0, float("nan")]] * 3, [[0, 1, 2]], closed=False)


def _rot(axis, angle):
    return Pose.from_axis_angle(axis, angle).rotation


def test_pose_identity_compose_inverse_apply():
    rng = np.random.default_rng(1)
    a = Pose.from_axis_angle([1, 2, 3], 0.7, [1.0, -2.0, 0.5])
    b = Pose.from_axis_angle([0, 0, 1], -1.2, [0.3, 0.1, 9.0])
    pts = rng.normal(size=(10, 3))
    ab = a.compose(b)
    assert np.allclose(ab.apply(pts), a.apply(b.apply(pts)), atol=1e-14)
    assert np.allclose(a.inverse().apply(a.apply(pts)), pts, atol=1e-14)
    assert np.allclose(a.compose(a.inverse()).rotation, np.eye(3), atol=1e-15)
    assert np.allclose(a.apply_dirs(pts), pts @ a.rotation.T)
    i = Pose.identity()
    assert np.array_equal(i.apply(pts), pts)
    r = a.rotation
    assert np.allclose(r @ r.T, np.eye(3), atol=1e-15) and np.linalg.det(r) == pytest.approx(1.0)
    assert a.rotation.dtype == np.float64 and not a.translation.flags.writeable


def test_pose_axis_angle_convention():
    r = _rot([0, 0, 1], math.pi / 2)  # x -> y (right-handed, Webots axis-angle)
    assert np.allclose(r @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    assert np.allclose(Pose.from_axis_angle([0, 0, 0], 1.0).rotation, np.eye(3))


def test_pose_far_translation_keeps_float64():
    p = Pose(np.eye(3), [1e6 + 0.123456789, 0, 0])
    assert p.apply(np.zeros((1, 3)))[0, 0] == 1e6 + 0.123456789


def test_a_tiny_or_huge_rotation_axis_gives_the_rotation_of_its_direction():
    """An axis whose squares underflow to subnormals (found by test_raycast_properties: a sphere
    turned about (0, 0, 1.55e-158) was scaled by ~1e-8 in EXACT) or overflow: the same matrix as the
    unit axis of its direction, bit for bit."""
    for axis, unit in (((0.0, 0.0, 1.552331975405721e-158), (0.0, 0.0, 1.0)), ((0.0, -1e-320, 0.0), (0.0, -1.0, 0.0)),
                       ((1e300, 1e300, 0.0), (1.0, 1.0, 0.0))):
        got = Pose.from_axis_angle(axis, 1.0).rotation
        assert got.tobytes() == Pose.from_axis_angle(unit, 1.0).rotation.tobytes(), axis
        assert np.abs(got @ got.T - np.eye(3)).max() < 1e-15
