"""IndexedFaceSet polygons are covered as Webots' tessellator covers them: a concave polygon is cut
into ears, never fanned over space outside its outline (Webots' curriculum arenas draw a wall's top
face as one polygon, the outer square and the inner one joined by a slit: fanned, it roofed the
arena at the wall's height and every camera and range finder inside saw that roof)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.wbt import wbt_convert
from sensorium.server.world.wbt.convert import fan_corners, polygon_corners

HEADER = "#VRML_SIM R2023b utf8\n"

# the top face of a 0.4 m square wall 0.01 m thick at z = 0.05: outer square clockwise, the slit at
# y = 0.19 to the inner square, the inner square counter-clockwise, back along the slit
RING = [(-0.2, -0.2), (-0.2, 0.19), (-0.19, 0.19), (-0.19, -0.19), (0.19, -0.19), (0.19, 0.19),
        (-0.2, 0.19), (-0.2, 0.2), (0.2, 0.2), (0.2, -0.2), (-0.2, -0.2)]


def ring_world(tmp_path: Path) -> Path:
    points = ", ".join(f"{x} {y} 0.05" for x, y in RING)
    look_up = 'rotation 0 1 0 -1.5708 width 1 height 1 fieldOfView 0.01 maxRange 1'
    p = tmp_path / "ring.wbt"
    p.write_text(HEADER + f"""WorldInfo {{ }}
Solid {{
  name "wall top"
  children [ Shape {{ geometry IndexedFaceSet {{
    coord Coordinate {{ point [ {points} ] }}
    coordIndex [ {" ".join(str(i) for i in range(len(RING)))} -1 ]
  }} }} ]
}}
Robot {{
  name "r"
  controller "<extern>"
  children [
    RangeFinder {{ name "centre" translation 0 0 0.01 {look_up} }}
    RangeFinder {{ name "ring" translation -0.195 0 0.01 {look_up} }}
  ]
}}
""")
    return p


def area(vertices: list[list[float]], faces: list[list[int]]) -> float:
    v = np.asarray(vertices, dtype=np.float64)
    a, b, c = (v[np.asarray(faces)[:, k]] for k in range(3))
    return float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


def test_a_slit_ring_covers_the_ring_only_and_cameras_see_through_its_middle(tmp_path: Path) -> None:
    sim = Simulation.from_file(ring_world(tmp_path), precision="exact")
    for name in ("centre", "ring"):
        sim.device(f"r/{name}").enable(32)
    sim.step()
    # fanned, the polygon roofed the whole square: the centre saw it 0.04 m up
    assert np.isinf(sim.device("r/centre").range_image).all()
    assert sim.device("r/ring").range_image[0, 0] == np.float32(0.04)   # the wall's top, 0.05 − 0.01
    tri = sim.world.solids[0].shapes[0].geometry
    assert math.isclose(area(tri.vertices, tri.faces), 0.4 ** 2 - 0.38 ** 2, rel_tol=1e-12)


def test_a_concave_polygon_keeps_its_winding_and_its_texture_corners(tmp_path: Path) -> None:
    """An L (reflex corner at its second vertex, where a fan from the first goes wrong), with a
    texCoordIndex: the triangles cover the L's 5 m² exactly, each turns as the polygon turns, and each
    triangle's texture corners are its coordinate corners' (the two indices differ by 10 here)."""
    xy = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]     # an L, its reflex corner (1, 1)
    xy = xy[3:] + xy[:3]                                       # ... first: a fan from it is right; start after it
    xy = xy[1:] + xy[:1]
    shoelace = sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(xy, xy[1:] + xy[:1])) / 2
    points = ", ".join(f"{x} {y} 0" for x, y in xy)
    tex = ", ".join(f"{x / 3} {y / 3}" for x, y in xy)
    p = tmp_path / "l.wbt"
    p.write_text(HEADER + f"""WorldInfo {{ }}
Solid {{ children [ Shape {{ geometry IndexedFaceSet {{
  coord Coordinate {{ point [ {points} ] }}
  texCoord TextureCoordinate {{ point [ 0 0, 0 0, 0 0, 0 0, 0 0, 0 0, 0 0, 0 0, 0 0, 0 0, {tex} ] }}
  coordIndex [ 0 1 2 3 4 5 -1 ]
  texCoordIndex [ 10 11 12 13 14 15 -1 ]
}} }} ] }}
""")
    geom = wbt_convert(p).data["solids"][0]["shapes"][0]["geometry"]
    faces, verts = geom["faces"], geom["vertices"]
    assert math.isclose(area(verts, faces), abs(shoelace), rel_tol=1e-12)
    for a, b, c in faces:
        (xa, ya, _), (xb, yb, _), (xc, yc, _) = verts[a], verts[b], verts[c]
        assert ((xb - xa) * (yc - ya) - (yb - ya) * (xc - xa)) * shoelace > 0
    assert geom["tex_coord_faces"].tolist() == [[i + 10 for i in f] for f in faces.tolist()]


def test_convex_polygons_and_triangles_keep_their_fan_bit_for_bit(tmp_path: Path) -> None:
    """Only concave polygons change: triangles, a square, a regular hexagon and a non-planar but
    convex-looking quad keep the fan from their first corner, exactly as before."""
    hexagon = [(math.cos(k * math.pi / 3), math.sin(k * math.pi / 3)) for k in range(6)]
    pts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)] + [(x + 3, y, 0) for x, y in hexagon] + \
          [(5, 0, 0), (6, 0, 0.1), (6, 1, 0), (5, 1, 0.1)]
    index = [0, 1, 2, -1, 0, 1, 2, 3, -1, *range(4, 10), -1, 10, 11, 12, 13]
    p = tmp_path / "convex.wbt"
    p.write_text(HEADER + "WorldInfo { }\nSolid { children [ Shape { geometry IndexedFaceSet { coord Coordinate { point [ "
                 + ", ".join(" ".join(map(str, q)) for q in pts) + " ] } coordIndex [ "
                 + " ".join(map(str, index)) + " ] } } ] }\n")
    conv = wbt_convert(p)
    faces = conv.data["solids"][0]["shapes"][0]["geometry"]["faces"].tolist()
    assert faces == [[index[c] for c in tri] for tri in fan_corners(index).tolist()]
    assert not [w for w in conv.warnings if "fanned" in w]


def test_a_huge_concave_polygon_stays_fanned_and_says_so(tmp_path: Path) -> None:
    """Ear clipping is quadratic: a concave polygon of over 256 corners keeps the fan, with one line."""
    n = 300
    star = [((1.0 if k % 2 else 0.5) * math.cos(2 * math.pi * k / n), (1.0 if k % 2 else 0.5) * math.sin(2 * math.pi * k / n))
            for k in range(n)]
    p = tmp_path / "star.wbt"
    p.write_text(HEADER + "WorldInfo { }\nSolid { children [ Shape { geometry IndexedFaceSet { coord Coordinate { point [ "
                 + ", ".join(f"{x} {y} 0" for x, y in star) + " ] } coordIndex [ "
                 + " ".join(map(str, range(n))) + " -1 ] } } ] }\n")
    conv = wbt_convert(p)
    assert conv.data["solids"][0]["shapes"][0]["geometry"]["faces"].tolist() == [[0, k, k + 1] for k in range(1, n - 1)]
    said = [w for w in conv.warnings if "left fanned" in w]
    assert len(said) == 1 and "1 concave polygon(s)" in said[0] and "star.wbt:3:" in said[0]


def test_a_quad_with_a_reflex_corner_is_cut_from_that_corner() -> None:
    """A dart (arrowhead) quad, its reflex corner at each of the four places in turn, next to a
    square: the dart is always cut along the diagonal from its reflex corner (a fan from corner 0
    covers space outside it when the reflex corner is 1 or 3), the square keeps its fan."""
    dart = [(0.0, 0.0), (2.0, 1.0), (0.0, 2.0), (0.8, 1.0)]           # reflex at the last corner
    square = [(5.0, 0.0), (6.0, 0.0), (6.0, 1.0), (5.0, 1.0)]
    for shift in range(4):
        quad = dart[shift:] + dart[:shift]
        reflex = (3 - shift) % 4
        points = [c for x, y in quad + square for c in (x, y, 0.0)]
        corners, fanned = polygon_corners([0, 1, 2, 3, -1, 4, 5, 6, 7, -1], points, [10 ** 6])
        assert fanned == 0
        assert corners.tolist()[:2] == [[reflex, (reflex + 1) % 4, (reflex + 2) % 4],
                                        [reflex, (reflex + 2) % 4, (reflex + 3) % 4]]
        assert corners.tolist()[2:] == [[5, 6, 7], [5, 7, 8]]
