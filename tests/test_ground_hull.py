"""Solids that are no single Box or Cylinder tip onto a face of their convex hull (sim/hull.py,
ground._hull_tip): a mesh, a capsule, several shapes; the hull itself checked on random points.

Every world here settles at load (ground.settle_world), a floor plane at z 0 under the solid: the
settled pose is compared with the closed-form face, turn and height."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.server.sim.ground import GroundWarning
from sensorium.server.sim.hull import MAX_POINTS, FlatPoints, beyond, convex_hull, extreme_points
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world
from sensorium.server.world.poses import axis_angle_matrix

FLOOR = {"name": "floor", "geometry": {"type": "plane"}}


def _settled(solid: dict) -> Pose:
    world = {"solids": [FLOOR, {"name": "load", "physics": True, **solid}]}
    return Simulation(parse_world(world, source="w.yaml"), precision="exact").scene.solid_poses["load"]


def _rotation(axis, degrees: float) -> list[float]:
    return [*axis, math.radians(degrees)]


# ---------------------------------------------------------------------- a sheared tetrahedron (a mesh)

# its base O, A, B on local z 0; its apex D far beyond the edge AB, so the centre of its volume, the
# mean of its corners, is not over the base: on its base it tips over AB onto the face A, B, D
TETRA = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [3.0, 0.0, 0.5]])
TETRA_FACES = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]      # counter-clockwise from outside


def test_a_tilted_tetrahedron_tips_over_its_edge_onto_the_face_the_closed_form_gives() -> None:
    o, a, b, d = TETRA
    centre = TETRA.mean(axis=0)
    assert centre[0] + centre[1] > 1.0                      # off its base, beyond the edge AB
    n = np.cross(b - a, d - a)
    n /= np.linalg.norm(n)                                  # the face ABD's outward normal (away from O)
    assert n @ (o - a) < 0.0
    # the centre over ABD once that face is down: its projection on ABD inside the triangle
    foot = centre - ((centre - a) @ n) * n
    edges = [(a, b), (b, d), (d, a)]
    assert all(np.cross(q - p, foot - p) @ n > 0.0 for p, q in edges)
    # the face down by a turn about the edge AB (the line it tips about)
    edge = (b - a) / np.linalg.norm(b - a)
    angle = math.acos(float(n @ [0.0, 0.0, -1.0]))
    turn = next(r for r in (axis_angle_matrix(edge, angle), axis_angle_matrix(edge, -angle))
                if np.allclose(r @ n, [0.0, 0.0, -1.0], atol=1e-12))
    start = axis_angle_matrix((1.0, 0.0, 0.0), math.radians(5.0))       # its base 5° off flat: laid flat first
    t = np.array([0.2, -0.1, 1.0])
    pose = _settled({"pose": {"translation": t.tolist(), "rotation": _rotation((1, 0, 0), 5.0)},
                     "geometry": {"type": "triangles", "vertices": TETRA.tolist(), "faces": TETRA_FACES}})
    np.testing.assert_allclose(pose.rotation, turn, rtol=0, atol=1e-9)
    world = TETRA @ pose.rotation.T + pose.translation
    np.testing.assert_allclose(world[1:, 2], 0.0, rtol=0, atol=1e-9)     # A, B, D on the floor
    assert world[0, 2] > 0.1                                             # O lifted
    # laid flat about its centre (its centre's x, y kept), then tipped with the edge AB staying put
    centre_xy = (start @ centre + t)[:2]
    np.testing.assert_allclose(world[1:3, :2], TETRA[1:3, :2] - centre[:2] + centre_xy, rtol=0, atol=1e-9)


# ---------------------------------------------------------------------- a capsule

@pytest.mark.parametrize("tilt", [10.0, 60.0, 89.0])
def test_a_tilted_capsule_lands_on_its_side(tilt: float) -> None:
    """A capsule's centre is over its lowest point only when it stands exactly upright: tilted, it
    falls onto its side, its axis level and its centre its radius above the floor."""
    pose = _settled({"pose": {"translation": [0.0, 0.0, 1.0], "rotation": _rotation((1, 0, 0), tilt)},
                     "geometry": {"type": "capsule", "radius": 0.1, "height": 0.4}})
    assert abs(pose.rotation[2, 2]) < 1e-12                  # its axis (local z) level
    assert pose.translation[2] == pytest.approx(0.1, abs=1e-12)


def test_an_upright_capsule_is_balanced_and_stays() -> None:
    pose = _settled({"pose": {"translation": [0.0, 0.0, 1.0]}, "geometry": {"type": "capsule", "radius": 0.1, "height": 0.4}})
    assert pose.rotation.tolist() == np.eye(3).tolist()
    assert pose.translation[2] == pytest.approx(0.3, abs=1e-12)


# ---------------------------------------------------------------------- an L of two boxes

# a bar along x (x ±0.3, z ±0.1) and a post on its -x end (x -0.3..-0.1, z 0.1..0.7): equal volumes,
# the centre (-0.1, 0, 0.2); the hull's face from the bar's far top edge (0.3, 0.1) to the post's top
# (-0.1, 0.7) has the outward normal (3, 0, 2)/√13 and lies 1.1/√13 from the origin
L_SHAPE = {"geometry": {"type": "box", "size": [0.6, 0.2, 0.2]},
           "shapes": [{"pose": {"translation": [-0.2, 0.0, 0.4]}, "geometry": {"type": "box", "size": [0.2, 0.2, 0.6]}}]}


def test_an_l_stood_on_its_bar_end_tips_onto_its_slanted_face() -> None:
    """On the bar's end face (+x down) the centre is 0.1 beyond that face's top edge: the L tips about
    it onto the slanted hull face, where the centre is over the face (0.305 of its 0.721 m length)."""
    pose = _settled({"pose": {"translation": [0.0, 0.0, 2.0], "rotation": _rotation((0, 1, 0), 90.0)}, **L_SHAPE})
    turn = axis_angle_matrix((0.0, 1.0, 0.0), math.pi / 2.0 + math.atan2(2.0, 3.0))
    np.testing.assert_allclose(pose.rotation, turn, rtol=0, atol=1e-12)
    assert pose.translation[2] == pytest.approx(1.1 / math.sqrt(13.0), abs=1e-12)


def test_an_l_in_a_nue_world_tips_about_its_horizontal_edge() -> None:
    """The same L in a NUE world (up is the world's y), stood on its bar's end by a turn of -90° about
    the world's z: it tips about its local y (the world's x there) onto the slanted face."""
    world = {"world_info": {"coordinate_system": "NUE"},
             "solids": [{"name": "floor", "pose": {"rotation": [1, 0, 0, -math.pi / 2]}, "geometry": {"type": "plane"}},
                        {"name": "load", "physics": True, "pose": {"translation": [0.0, 2.0, 0.0],
                                                                  "rotation": _rotation((0, 0, 1), -90.0)}, **L_SHAPE}]}
    pose = Simulation(parse_world(world, source="w.yaml"), precision="exact").scene.solid_poses["load"]
    slanted = np.array([3.0, 0.0, 2.0]) / math.sqrt(13.0)
    np.testing.assert_allclose(pose.rotation @ slanted, [0.0, -1.0, 0.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(pose.rotation @ [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], rtol=0, atol=1e-12)
    assert pose.translation[1] == pytest.approx(1.1 / math.sqrt(13.0), abs=1e-12)


def test_an_l_tilted_off_its_bar_lies_back_on_it() -> None:
    """Turned 20° about y its bar's bottom is the face nearest down and holds its centre: it lies flat
    on it, turned back about a horizontal axis through the centre (no yaw)."""
    pose = _settled({"pose": {"translation": [0.0, 0.0, 2.0], "rotation": _rotation((0, 1, 0), 20.0)}, **L_SHAPE})
    np.testing.assert_allclose(pose.rotation, np.eye(3), rtol=0, atol=1e-12)
    assert pose.translation[2] == pytest.approx(0.1, abs=1e-12)


# ---------------------------------------------------------------------- a flat mesh

def test_a_flat_mesh_keeps_its_rotation_with_one_warning() -> None:
    square = {"type": "triangles", "vertices": [[0, 0, 0], [0.4, 0, 0], [0.4, 0.4, 0], [0, 0.4, 0]],
              "faces": [[0, 1, 2], [0, 2, 3]]}
    rotation = _rotation((1, 0, 0), 30.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pose = _settled({"pose": {"translation": [0.0, 0.0, 1.0], "rotation": rotation}, "geometry": square})
    said = [str(w.message) for w in caught if issubclass(w.category, GroundWarning)]
    assert said == ["solid 'load': its bounding shapes lie on one plane, no face to tip onto: it keeps its rotation"]
    np.testing.assert_allclose(pose.rotation, axis_angle_matrix((1, 0, 0), math.radians(30.0)), rtol=0, atol=1e-15)
    assert pose.translation[2] == pytest.approx(0.0, abs=1e-12)     # its lowest edge on the floor


# ---------------------------------------------------------------------- the hull

def _check_hull(points: np.ndarray) -> None:
    try:
        hull = convex_hull(points)
    except FlatPoints as flat:       # then the points really are flat: their spread across is tiny
        centred = points - points.mean(axis=0)
        rank_tol = 1e-6 * max(1.0, float(np.abs(points).max()))
        s = np.linalg.svd(centred, compute_uv=False) if len(points) > 1 else np.zeros(3)
        assert s[-1] <= rank_tol * math.sqrt(len(points)), flat
        return
    p = hull.points
    # every point inside or on the hull
    assert not beyond(p[hull.faces[:, 0]], p[hull.faces[:, 1]], p[hull.faces[:, 2]], p).any()     # exactly
    assert (p @ hull.normals.T - hull.offsets).max() <= hull.tolerance
    # the hull's corners are input points, each on its faces' planes
    assert set(hull.vertices.tolist()) <= set(range(len(points)))
    on = p[hull.faces] @ hull.normals[:, :, None]
    np.testing.assert_allclose(on[..., 0], np.repeat(hull.offsets[:, None], 3, axis=1), rtol=0, atol=hull.tolerance)
    # a closed surface: every edge met once each way, Euler's V − E + F = 2
    edges = {(int(f[j]), int(f[(j + 1) % 3])) for f in hull.faces for j in range(3)}
    assert all((b, a) in edges for a, b in edges) and len(edges) == 3 * len(hull.faces)
    assert len(hull.vertices) - len(edges) // 2 + len(hull.faces) == 2
    volume, _ = hull.volume_centroid()
    extent = float((p.max(axis=0) - p.min(axis=0)).max())
    assert volume > -hull.tolerance * extent ** 2        # (a needle of near-duplicates: about 0)


coordinate = st.integers(-4, 4).map(float) | st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


@pytest.mark.parametrize("examples", example_counts(200))
def test_the_hull_holds_every_point_and_its_corners_are_points(examples: int) -> None:
    """Random points, small integer grids (many coplanar and collinear), each repeated ``copies`` times."""
    @settings(max_examples=examples, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=1, max_size=60),
           st.integers(0, 3))
    def run(rows: list, copies: int) -> None:
        _check_hull(np.array(rows * (copies + 1), dtype=np.float64))

    run()


tiny = st.floats(-1e-8, 1e-8, allow_nan=False)


@pytest.mark.parametrize("examples", example_counts(200))
def test_the_hull_of_near_duplicate_clusters_holds_every_point(examples: int) -> None:
    """Each point repeated a few times 1e-8 or less apart (a mesh's vertices written twice, rounded):
    thin slivers whose float64 normals would be wrong; the sides are decided exactly."""
    @settings(max_examples=examples, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=1, max_size=12),
           st.lists(st.tuples(tiny, tiny, tiny), min_size=2, max_size=4))
    def run(centres: list, offsets: list) -> None:
        _check_hull((np.array(centres)[:, None, :] + np.array(offsets)[None, :, :]).reshape(-1, 3))

    run()


@pytest.mark.parametrize("points, kind", [
    (np.zeros((4, 3)), "point"),
    (np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [0.5, 0.5, 0.5]]), "line"),
    (np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [0.5, 0.5, 1.0]]), "plane"),
])
def test_flat_points_have_no_hull(points: np.ndarray, kind: str) -> None:
    with pytest.raises(FlatPoints) as got:
        convex_hull(points)
    assert got.value.kind == kind


def test_a_cube_sampled_on_its_faces_has_its_eight_corners() -> None:
    g = np.linspace(0.0, 1.0, 5)
    grid = np.array([[x, y, z] for x in g for y in g for z in g])
    hull = convex_hull(grid)
    assert sorted(map(tuple, hull.points[hull.vertices].tolist())) == sorted(
        (x, y, z) for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0))
    volume, centre = hull.volume_centroid()
    assert volume == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(centre, [0.5, 0.5, 0.5], rtol=0, atol=1e-12)


def test_many_points_are_cut_to_extreme_ones_whose_hull_is_exact_for_a_box() -> None:
    """Past MAX_POINTS the hull is built from the points farthest along 1,030 directions (its time
    grows with the square of its corners): a dense 27,000-point grid in a box keeps its eight corners,
    so the hull's volume and centre are the box's exactly; every kept point is an input point, and a
    small cloud is kept whole."""
    g = np.linspace(-1.0, 2.0, 30)
    grid = np.array([[x, y, 0.5 * z] for x in g for y in g for z in g])
    assert len(grid) > MAX_POINTS
    kept = extreme_points(grid)
    assert len(kept) <= 1030 and {tuple(p) for p in kept.tolist()} <= {tuple(p) for p in grid.tolist()}
    assert {(x, y, z) for x in (-1.0, 2.0) for y in (-1.0, 2.0) for z in (-0.5, 1.0)} <= {tuple(p) for p in kept.tolist()}
    volume, centre = convex_hull(kept).volume_centroid()
    assert volume == pytest.approx(3.0 * 3.0 * 1.5, rel=1e-12)
    np.testing.assert_allclose(centre, [0.5, 0.5, 0.25], rtol=0, atol=1e-12)
    small = grid[:MAX_POINTS]
    assert np.array_equal(extreme_points(small), small)


def test_a_physics_centre_of_mass_over_the_face_it_stands_on_keeps_the_l_standing() -> None:
    """The L on its bar's end tips with uniform density (its centre 0.1 beyond the end face); with its
    Physics' centre of mass given at (0, 0, 0.05) in its frame -- 0.05 inside that face, seen from
    above -- it stands as it is, on the face, its bar upright (the centre of mass getCenterOfMass reads)."""
    turned = {"translation": [0.0, 0.0, 2.0], "rotation": _rotation((0, 1, 0), 90.0)}
    pose = _settled({"pose": turned, "mass": {"kg": 2.0, "center": [0.0, 0.0, 0.05]}, **L_SHAPE})
    np.testing.assert_allclose(pose.rotation, axis_angle_matrix((0.0, 1.0, 0.0), math.pi / 2.0), rtol=0, atol=1e-12)
    assert pose.translation[2] == pytest.approx(0.3, abs=1e-12)
    tipped = _settled({"pose": turned, **L_SHAPE})
    assert abs(float(tipped.rotation[2, 0])) < 0.99      # without it: tipped onto the slanted face (above)


def test_a_physics_centre_of_mass_keeps_an_l_with_a_mesh_standing(tmp_path) -> None:
    """The same L, its upright bar a mesh file (a 0.2 × 0.2 × 0.6 box, wound outward): a solid with a mesh
    tips about its Physics' centre of mass too, now that mesh volumes are weighed (given here: it stands)."""
    corners = np.array([[x, y, z] for z in (-0.3, 0.3) for y in (-0.1, 0.1) for x in (-0.1, 0.1)])[[0, 1, 3, 2, 4, 5, 7, 6]]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    facets = []
    for q in quads:
        for k in (1, 2):
            tri = corners[[q[0], q[k], q[k + 1]]]
            facets += ["facet normal 0 0 0", "outer loop", *(f"vertex {x} {y} {z}" for x, y, z in tri), "endloop",
                       "endfacet"]
    (tmp_path / "bar.stl").write_text("\n".join(["solid bar", *facets, "endsolid bar", ""]))
    bar = {"pose": {"translation": [-0.2, 0.0, 0.4]}, "geometry": {"type": "mesh", "url": "bar.stl"}}
    turned = {"translation": [0.0, 0.0, 2.0], "rotation": _rotation((0, 1, 0), 90.0)}

    def settled(extra: dict) -> Pose:
        load = {"name": "load", "physics": True, "pose": turned, "geometry": L_SHAPE["geometry"], "shapes": [bar],
                **extra}
        loaded = parse_world({"solids": [FLOOR, load]}, source="w.yaml", base_dir=tmp_path)
        return Simulation(loaded, precision="exact").scene.solid_poses["load"]

    pose = settled({"mass": {"kg": 2.0, "center": [0.0, 0.0, 0.05]}})
    np.testing.assert_allclose(pose.rotation, axis_angle_matrix((0.0, 1.0, 0.0), math.pi / 2.0), rtol=0, atol=1e-12)
    assert pose.translation[2] == pytest.approx(0.3, abs=1e-12)
    assert abs(float(settled({}).rotation[2, 0])) < 0.99      # uniform density: tipped onto the slanted face
