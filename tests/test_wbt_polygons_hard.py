"""Numerical hardness of IndexedFaceSet polygon tessellation (``polygon_corners``: convex polygons
fanned, concave ones cut along diagonals). Simple polygons built so by construction (star-shaped,
combs, spirals, slit rings as Webots' curriculum arenas draw a wall's top face) are placed in any
plane, far from the origin, tiny or huge, with nearly collinear, duplicate and repeated corners, and
clockwise or counter-clockwise. The triangles are checked exactly (rational arithmetic on the
polygon as the float64 points place it, projected into its plane): every triangle turns as the
polygon turns, their signed areas add up to the polygon's (so, none turning backwards, they cover it
once), and every triangle's centroid lies inside the polygon."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.server.world.wbt.convert import fan_corners, polygon_corners

FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])

# ---------------------------------------------------------------- simple polygons, by construction


def star(n: int, radii: list[float], jitter: list[float]) -> list[tuple[float, float]]:
    """Corners at increasing angles (gaps below π) around the origin: simple and star-shaped."""
    return [(r * math.cos(2 * math.pi * (k + 0.45 * j) / n), r * math.sin(2 * math.pi * (k + 0.45 * j) / n))
            for k, (r, j) in enumerate(zip(radii, jitter))]


def comb(heights: list[float]) -> list[tuple[float, float]]:
    """A base bar 0 ≤ y ≤ 1 with a tooth per height (width 1, gaps 1) on top, counter-clockwise."""
    m = len(heights)
    out = [(0.0, 0.0), (2.0 * m - 1, 0.0)]
    for i in reversed(range(m)):
        x = 2.0 * i
        out += [(x + 1, 1.0 + heights[i]), (x, 1.0 + heights[i])]
        if i:
            out += [(x, 1.0), (x - 1, 1.0)]
    return out


def spiral(turns: float, n: int) -> list[tuple[float, float]]:
    """A spiral band: out along r = 1.5 + θ/π, back along r = 0.5 + θ/π (a band 1 wide, its
    turns 2 apart): simple, with long runs of reflex corners."""
    theta = [turns * 2 * math.pi * k / (n - 1) for k in range(n)]
    outer = [((1.5 + t / math.pi) * math.cos(t), (1.5 + t / math.pi) * math.sin(t)) for t in theta]
    inner = [((0.5 + t / math.pi) * math.cos(t), (0.5 + t / math.pi) * math.sin(t)) for t in reversed(theta)]
    return outer + inner


def slit_ring(outer_ccw: bool, inner: float) -> list[tuple[float, float]]:
    """A square wall's top face as Webots' curriculum arenas draw it: the outer square, a slit to the
    inner square, the inner square the other way round, back along the slit (corners repeated)."""
    o = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
    i = [(-inner, -inner), (-inner, inner), (inner, inner), (inner, -inner)]
    if not outer_ccw:
        o = [o[0]] + o[1:][::-1]
        i = [i[0]] + i[1:][::-1]
    return o + [o[0]] + i + [i[0]]


# ---------------------------------------------------------------- placing and checking


def frame(a: float, b: float, c: float) -> np.ndarray:
    """An orthonormal frame (rows u, v, n) from three angles."""
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    rz = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rx = np.array([[1, 0, 0], [0, cc, -sc], [0, sc, cc]])
    return (rz @ ry @ rx).T


def place(xy: list[tuple[float, float]], f: np.ndarray, scale: float, offset: float) -> list[float]:
    p = np.asarray(xy, dtype=np.float64) * scale
    xyz = p[:, :1] * f[0] + p[:, 1:] * f[1] + offset
    return xyz.reshape(-1).tolist()


def projected(points: list[float], f: np.ndarray, offset: float) -> list[tuple[Fraction, Fraction]]:
    """The float64 points exactly, less the offset, on the frame's u and v (rationals)."""
    u, v = [Fraction(float(c)) for c in f[0]], [Fraction(float(c)) for c in f[1]]
    o = Fraction(offset)
    out = []
    for k in range(0, len(points), 3):
        q = [Fraction(c) - o for c in points[k:k + 3]]
        out.append((sum(a * b for a, b in zip(q, u)), sum(a * b for a, b in zip(q, v))))
    return out


def twice_area(a, b, c) -> Fraction:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def winding(p, poly) -> int:
    """Winding number of ``poly`` around ``p`` (exact; p on no edge)."""
    w = 0
    for a, b in zip(poly, poly[1:] + poly[:1]):
        if a[1] <= p[1] < b[1] and twice_area(a, b, p) > 0:
            w += 1
        elif b[1] <= p[1] < a[1] and twice_area(a, b, p) < 0:
            w -= 1
    return w


def check_cover(xy: list[tuple[float, float]], f: np.ndarray, scale: float, offset: float,
                exact: bool = False) -> np.ndarray:
    """Tessellate the placed polygon and check its triangles exactly. Returns the triangles. A
    rotated polygon's float64 corners leave its plane by rounding (~1e-16 of its size, of its
    offset far out): a sliver triangle thinner than that may turn either way, seen along the
    frame's normal; ``exact`` (corners placed exactly, in an axis plane): none may."""
    n = len(xy)
    points = place(xy, f, scale, offset)
    index = list(range(n))
    corners, fanned = polygon_corners(index, points, [10 ** 9])
    assert fanned == 0
    again, _ = polygon_corners(index, points, [10 ** 9])
    assert np.array_equal(corners, again)                       # deterministic
    assert corners.shape == (n - 2, 3) and corners.min() >= 0 and corners.max() < n
    assert sorted(set(corners.reshape(-1).tolist())) == list(range(n))   # every corner used
    poly = projected(points, f, offset)
    total = sum(twice_area(poly[0], poly[k], poly[k + 1]) for k in range(1, n - 1))   # shoelace, exact
    assert total != 0
    sign = 1 if total > 0 else -1
    tol = Fraction(0) if exact else Fraction(64 * 2.2e-16 * (1 + abs(offset) / scale) * scale ** 2)
    got = Fraction(0)
    for a, b, c in corners.tolist():
        t = twice_area(poly[a], poly[b], poly[c])
        assert t * sign >= -tol, f"triangle {(a, b, c)} turns against the polygon"
        got += t
        if t * sign > tol:
            centroid = ((poly[a][0] + poly[b][0] + poly[c][0]) / 3, (poly[a][1] + poly[b][1] + poly[c][1]) / 3)
            assert winding(centroid, poly) == sign, f"triangle {(a, b, c)} lies outside the polygon"
    assert got == total                                          # covered once: the areas agree exactly
    assert np.isfinite(np.asarray(points)).all()
    return corners


ANGLES = st.tuples(*[st.floats(0, 2 * math.pi, allow_nan=False)] * 3)
AXIS = st.sampled_from([np.eye(3)[list(p)] * s for p in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) for s in (1.0, -1.0)])
SCALE = st.sampled_from([1e-6, 1e-3, 1.0, 37.5, 1e4])
OFFSET = st.sampled_from([0.0, -3.25, 1e5, -1e5, 1e7])


def fits(scale: float, offset: float) -> bool:
    """A rotated polygon far out keeps its shape to ~1e-5 of its size (float64 rounds its corners
    to ~1e-16 of the offset): simple polygons stay simple."""
    return abs(offset) * 1e-16 <= scale * 1e-5


@st.composite
def star_polygons(draw):
    n = draw(st.integers(4, 40))
    radii = draw(st.lists(st.floats(0.05, 1.0), min_size=n, max_size=n))
    jitter = draw(st.lists(st.floats(-1.0, 1.0), min_size=n, max_size=n))
    xy = star(n, radii, jitter)
    return xy if draw(st.booleans()) else xy[::-1]


@settings(FAST)
@given(star_polygons(), ANGLES, SCALE, OFFSET)
def test_star_shaped_polygons_in_any_plane_and_place_are_covered_exactly(xy, angles, scale, offset) -> None:
    if fits(scale, offset):
        check_cover(xy, frame(*angles), scale, offset)


@settings(FAST)
@given(star_polygons(), AXIS, st.integers(-20, 13), OFFSET)
def test_star_shaped_polygons_on_a_grid_far_out_and_tiny_are_covered_exactly(xy, axes, e, offset) -> None:
    """In an axis plane with corners on a binary grid, even a micrometre polygon 1e7 m out is placed
    exactly: the check holds with no rounding at all."""
    grid = [(round(x * 4096) / 4096, round(y * 4096) / 4096) for x, y in xy]
    if len(set(grid)) < len(grid) or abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(grid, grid[1:] + grid[:1]))) == 0:
        return
    check_cover(grid, axes, 2.0 ** e, offset, exact=True)


@settings(FAST)
@given(st.lists(st.floats(0.01, 5.0), min_size=2, max_size=12), ANGLES, SCALE, OFFSET, st.booleans())
def test_combs_are_covered_exactly(heights, angles, scale, offset, cw) -> None:
    xy = comb(heights)
    if fits(scale, offset):
        check_cover(xy[::-1] if cw else xy, frame(*angles), scale, offset)


@settings(FAST)
@given(st.floats(0.6, 2.5), st.integers(8, 40), ANGLES, SCALE, OFFSET, st.booleans())
def test_spirals_are_covered_exactly(turns, n, angles, scale, offset, cw) -> None:
    xy = spiral(turns, max(n, math.ceil(10 * turns) + 1))      # ≥ 10 corners a turn: chords stay in the band
    if fits(scale, offset):
        check_cover(xy[::-1] if cw else xy, frame(*angles), scale, offset)


@settings(FAST)
@given(st.booleans(), st.floats(0.05, 0.99), ANGLES, SCALE, OFFSET, st.integers(0, 9))
def test_slit_rings_either_way_round_cover_the_ring_only(outer_ccw, inner, angles, scale, offset, roll) -> None:
    xy = slit_ring(outer_ccw, inner)
    xy = xy[roll:] + xy[:roll]
    if fits(scale, offset):
        check_cover(xy, frame(*angles), scale, offset)


@settings(FAST)
@given(star_polygons(), ANGLES, SCALE, st.data())
def test_duplicate_consecutive_corners_and_nearly_collinear_ones_are_covered_exactly(xy, angles, scale, data) -> None:
    """A corner written twice in a row, and a corner added on an edge, pushed in or out by 1e-9 to
    1e-3 of the polygon's size, anywhere."""
    xy = list(xy)
    for _ in range(data.draw(st.integers(1, 4))):
        k = data.draw(st.integers(0, len(xy) - 1))
        if data.draw(st.booleans()):
            xy.insert(k, xy[k])
        else:
            (x0, y0), (x1, y1) = xy[k], xy[(k + 1) % len(xy)]
            t = data.draw(st.floats(0.1, 0.9))
            d = data.draw(st.sampled_from([1e-14, -1e-14, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6, -1e-6, 1e-3, -1e-3]))
            xy.insert(k + 1, (x0 + t * (x1 - x0) - d * (y1 - y0), y0 + t * (y1 - y0) + d * (x1 - x0)))
    check_cover(xy, frame(*angles), scale, 0.0)


def test_zero_area_slivers_inside_a_polygon_are_covered() -> None:
    """A spike out and straight back (a zero-area sliver) on a concave polygon, and a polygon of
    all-collinear corners: a defined set of triangles, no NaN, nothing thrown."""
    xy = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0.5, 5), (1, 3), (0, 3)]     # an L with a spike
    corners = check_cover([(float(x), float(y)) for x, y in xy], np.eye(3), 1.0, 0.0)
    assert len(corners) == 6
    flat = [0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 1.5, 0, 0]
    corners, fanned = polygon_corners([0, 1, 2, 3, 4, -1], flat, [10 ** 6])
    assert fanned == 0 and corners.tolist() == fan_corners([0, 1, 2, 3, 4, -1]).tolist()


def test_a_world_of_many_256_corner_spirals_cuts_within_the_budget_and_fans_the_rest(tmp_path) -> None:
    """Ear clipping is bounded per world: 400,000 corners², so of twenty 256-corner concave spirals
    (65,536 each) six are cut and fourteen stay fanned, said in one line (it was a line per
    IndexedFaceSet: a hostile world's thousands of nodes gave thousands of lines)."""
    from sensorium.server.world.wbt import wbt_convert
    from sensorium.server.world.wbt.convert import EAR_CLIP_WORLD

    xy = spiral(6.0, 128)
    assert len(xy) == 256 and EAR_CLIP_WORLD == 400_000
    shapes = []
    for k in range(20):
        points = ", ".join(f"{x + 20 * k} {y} 0" for x, y in xy)
        shapes.append(f"Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point [ {points} ] }} "
                      f"coordIndex [ {' '.join(map(str, range(256)))} -1 ] }} }}")
    p = tmp_path / "spirals.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { }\nSolid { children [ " + "\n".join(shapes) + " ] }\n")
    conv = wbt_convert(p)
    said = [w for w in conv.warnings if "left fanned" in w]
    assert len(said) == 1 and "14 concave polygon(s)" in said[0] and "(14 IndexedFaceSets, the first here)" in said[0]
    assert "spirals.wbt:9:" in said[0], said          # the first one fanned: the 7th shape, on line 9
    fan = [[0, k, k + 1] for k in range(1, 255)]
    geoms = [s["geometry"] for s in conv.data["solids"][0]["shapes"]]
    assert [g["faces"].tolist() != fan for g in geoms] == [True] * 6 + [False] * 14


@settings(FAST)
@given(st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-0.3, 0.3)), min_size=4, max_size=40),
       SCALE, OFFSET)
def test_self_crossing_and_non_planar_polygons_get_a_defined_cover_never_a_crash(pts, scale, offset) -> None:
    """Random corners (a polygon crossing itself, folded out of its plane): n − 2 triangles of its own
    corners, the same every time, finite; a quad keeps its fan or is cut along one of its diagonals."""
    n = len(pts)
    flat = [c * scale + offset for p in pts for c in p]
    index = list(range(n)) + [-1]
    corners, fanned = polygon_corners(index, flat, [10 ** 6])
    assert fanned == 0 and corners.shape == (n - 2, 3) and 0 <= corners.min() and corners.max() < n
    assert np.array_equal(corners, polygon_corners(index, flat, [10 ** 6])[0])
    assert (corners[:, 0] != corners[:, 1]).all() and (corners[:, 1] != corners[:, 2]).all()
    if n == 4:
        assert corners.tolist() in ([[0, 1, 2], [0, 2, 3]], [[1, 2, 3], [1, 3, 0]], [[2, 3, 0], [2, 0, 1]],
                                    [[3, 0, 1], [3, 1, 2]])


def test_a_reflex_corner_written_twice_still_makes_the_polygon_concave() -> None:
    """A clockwise pentagon whose one reflex corner (0.25, 0) is written twice in a row: the turn at
    either copy is read between its distinct neighbours (it was read across the zero-length edge,
    turning nowhere, so the polygon was taken as convex and fanned over its notch)."""
    xy = [(0.838670567945424, -0.544639035015027), (-0.5, -0.8660254037844384), (-1.0, 0.0),
          (-0.5, 0.8660254037844387), (0.125, 0.21650635094610965), (0.25, 0.0), (0.25, 0.0)]
    for roll in range(len(xy)):
        check_cover(xy[roll:] + xy[:roll], np.eye(3), 1.0, 0.0, exact=True)


@st.composite
def touching_polygons(draw):
    """A polygon touching itself at one corner P = (1, 0), written once per visit: two star-shaped
    lobes either side of P (a figure eight, both turning the same way), or a star-shaped hole inside
    a square, its corner at P on the square's side (turning the other way)."""
    def lobe(centre_x, start, r_max):
        n = draw(st.integers(3, 16))
        radii = draw(st.lists(st.floats(0.2 * r_max, r_max), min_size=n - 1, max_size=n - 1))
        return [(1.0, 0.0)] + [(centre_x + r * math.cos(start + 2 * math.pi * k / n), r * math.sin(start + 2 * math.pi * k / n))
                               for k, r in zip(range(1, n), radii)]
    if draw(st.booleans()):
        xy = lobe(0.0, 0.0, 0.95) + lobe(2.0, math.pi, 0.95)
    else:
        hole = lobe(0.5, 0.0, 0.45)            # P at 0.5 from its centre, the others within 0.45
        xy = [(1.0, 0.0), (1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] + [(1.0, 0.0)] + hole[:0:-1]
    roll = draw(st.integers(0, len(xy) - 1))
    xy = xy[roll:] + xy[:roll]
    return xy[::-1] if draw(st.booleans()) else xy


@settings(FAST)
@given(touching_polygons(), ANGLES, SCALE, OFFSET)
def test_polygons_touching_themselves_at_a_corner_are_covered_exactly(xy, angles, scale, offset) -> None:
    if fits(scale, offset):
        check_cover(xy, frame(*angles), scale, offset)


def test_a_figure_eight_is_not_cut_across_its_waist() -> None:
    """Two lobes touching at P = (1, 0), P written once per visit: an ear from the second lobe's
    last corner through P to the first lobe's was taken (no corner inside it, the second P being
    the ear's own corner again) though the outline, leaving the second P, runs into it."""
    xy = [(1.0, 0.0), (0.15450849718747373, 0.47552825814757677), (-0.40450849718747367, 0.2938926261462366),
          (-0.4045084971874738, -0.2938926261462365), (0.15450849718747361, -0.4755282581475768), (1.0, 0.0),
          (2.2499999999999996, -0.4330127018922195), (2.125, 0.2165063509461096)]
    for roll in range(len(xy)):
        for way in (1, -1):
            check_cover((xy[roll:] + xy[:roll])[::way], np.eye(3), 1.0, 0.0, exact=True)


def test_corners_too_large_to_square_are_refused_by_value_without_numpy_warnings(tmp_path) -> None:
    """A concave face with a corner at 1e308 m: the world limits refuse it in one line; the
    tessellation before them printed four numpy overflow warnings first (its products overflow).
    Read before the limits, that polygon is fanned, silently; ear clipping it says nothing either."""
    import warnings

    from sensorium.server.world.cad import ear_clip
    from sensorium.server.world.wbt import wbt_convert

    p = tmp_path / "far.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { }\nSolid { children [ Shape { geometry IndexedFaceSet { "
                 "coord Coordinate { point [ 0 0 0, 3 0 0, 3 1 0, 1e308 1 0, 1 3 0, 0 3 0 ] } "
                 "coordIndex [ 0 1 2 3 4 5 -1 ] } } ] }\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        faces = wbt_convert(p).data["solids"][0]["shapes"][0]["geometry"]["faces"].tolist()
    assert faces == [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ear_clip(np.array([(0, 0, 0), (3, 0, 0), (3, 1, 0), (1e308, 1, 0), (1, 3, 0), (0, 3, 0)], dtype=np.float64))


@settings(settings(FAST, max_examples=25))
@given(st.lists(st.floats(0.05, 3.0), min_size=2, max_size=8), st.integers(0, 30), st.booleans())
def test_a_read_worlds_texture_corners_follow_its_cut_triangles(heights, roll, cw) -> None:
    """Through the .wbt reader: a comb face with a texCoordIndex (the texture points listed after
    seven unused ones): each triangle's texture corners are its coordinate corners' own, and the
    faces cover the comb exactly."""
    import tempfile
    from pathlib import Path

    from sensorium.server.world.wbt import wbt_convert

    xy = comb(heights)
    xy = xy[::-1] if cw else xy
    roll %= len(xy)
    xy = xy[roll:] + xy[:roll]
    n = len(xy)
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "comb.wbt"
        p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { }\nSolid { children [ Shape { geometry IndexedFaceSet {\n"
                     f"  coord Coordinate {{ point [ {', '.join(f'{x!r} {y!r} 0' for x, y in xy)} ] }}\n"
                     f"  texCoord TextureCoordinate {{ point [ {', '.join(['9 9'] * 7 + [f'{x / 20!r} {y / 9!r}' for x, y in xy])} ] }}\n"
                     f"  coordIndex [ {' '.join(map(str, range(n)))} -1 ]\n"
                     f"  texCoordIndex [ {' '.join(str(k + 7) for k in range(n))} -1 ] }} }} ] }}\n")
        geom = wbt_convert(p).data["solids"][0]["shapes"][0]["geometry"]
    faces = geom["faces"]
    assert geom["tex_coord_faces"].tolist() == [[c + 7 for c in f] for f in faces.tolist()]
    poly = [(Fraction(x), Fraction(y)) for x, y in xy]
    total = sum(twice_area(poly[0], poly[k], poly[k + 1]) for k in range(1, n - 1))
    tris = [twice_area(poly[a], poly[b], poly[c]) for a, b, c in faces]
    assert all(t * total > 0 for t in tris) and sum(tris) == total


def test_a_def_face_used_many_times_is_cut_the_same_at_every_use(tmp_path) -> None:
    """A DEF IndexedFaceSet (a 200-corner concave star) USEd twenty times: every use gets the same
    triangles, and the world's ear-clipping budget is spent on it once (each use was cut again and
    charged again, so past the tenth use the same face was fanned over its notches)."""
    from sensorium.server.world.wbt import wbt_convert

    n = 200
    xy = star(n, [1.0 if k % 2 else 0.6 for k in range(n)], [0.0] * n)
    face = ("DEF STAR IndexedFaceSet { coord Coordinate { point [ " + ", ".join(f"{x!r} {y!r} 0" for x, y in xy)
            + f" ] }} coordIndex [ {' '.join(map(str, range(n)))} -1 ] }}")
    solids = [f'Solid {{ name "s0" children [ Shape {{ geometry {face} }} ] }}'] + \
        [f'Solid {{ name "s{k}" translation {3 * k} 0 0 children [ Shape {{ geometry USE STAR }} ] }}' for k in range(1, 20)]
    p = tmp_path / "stars.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { }\n" + "\n".join(solids) + "\n")
    conv = wbt_convert(p)
    faces = [s["shapes"][0]["geometry"]["faces"].tolist() for s in conv.data["solids"]]
    assert len(faces) == 20 and all(f == faces[0] for f in faces[1:])
    assert faces[0] != [[0, k, k + 1] for k in range(1, n - 1)]
    assert not [w for w in conv.warnings if "left fanned" in w]
