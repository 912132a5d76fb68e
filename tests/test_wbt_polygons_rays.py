"""Rays through a concave IndexedFaceSet face's cut diagonals and at its reflex corners (EXACT):
no gap and no stray hit. Each face (a slit ring as Webots' curriculum arenas draw a wall's top, a
comb, a star) lies flat at z = h; rays come down onto points of every diagonal the tessellation cut
(shared edges of two triangles inside the face), nudged sideways by 0 to 1e-6 m, straight down,
slanted and grazing (1.6° and 0.2° from the face), and onto points just inside and just outside
each reflex corner. A point inside the polygon is hit at the closed-form distance, one outside is
not hit (the fan's roof over the notches is gone), near the origin and 1e5 m from it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.raycast.kinds import RayKind
from sensorium.server.sim.simulation import Simulation

HEADER = "#VRML_SIM R2023b utf8\n"
H = 0.05
RING = [(-0.2, -0.2), (-0.2, 0.19), (-0.19, 0.19), (-0.19, -0.19), (0.19, -0.19), (0.19, 0.19),
        (-0.2, 0.19), (-0.2, 0.2), (0.2, 0.2), (0.2, -0.2), (-0.2, -0.2)]
COMB = [(0.0, 0.0), (0.7, 0.0)] + [c for i in reversed(range(4)) for c in
                                   [(0.2 * i + 0.1, 0.1 + 0.05 * (i + 1)), (0.2 * i, 0.1 + 0.05 * (i + 1)),
                                    (0.2 * i, 0.1), (0.2 * i - 0.1, 0.1)]][:-2]
STAR = [((0.3 if k % 2 else 0.12) * math.cos(math.pi * k / 7), (0.3 if k % 2 else 0.12) * math.sin(math.pi * k / 7))
        for k in range(14)]
SHAPES = {"ring": (RING, (0.0, 0.0)), "comb": (COMB, (1.0, 0.0)), "star": (STAR, (0.0, 1.0))}
SIDE = [0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-7, -1e-7, 1e-6, -1e-6]


def world(tmp_path: Path, base: float) -> Path:
    solids = []
    for name, (xy, (dx, dy)) in SHAPES.items():
        points = ", ".join(f"{x + dx + base!r} {y + dy + base!r} {H}" for x, y in xy)
        solids.append(f"""Solid {{ name "{name}" children [ Shape {{ geometry IndexedFaceSet {{
  coord Coordinate {{ point [ {points} ] }}
  coordIndex [ {" ".join(map(str, range(len(xy))))} -1 ] }} }} ] }}""")
    p = tmp_path / "faces.wbt"
    p.write_text(HEADER + "WorldInfo { }\n" + "\n".join(solids) + "\n")
    return p


def near_outline(p, poly, tol=1e-5) -> bool:
    for a, b in zip(poly, poly[1:] + poly[:1]):
        a, b = np.asarray(a), np.asarray(b)
        f = np.clip(np.dot(p - a, b - a) / max(np.dot(b - a, b - a), 1e-300), 0.0, 1.0)
        if np.linalg.norm(p - (a + f * (b - a))) < tol:
            return True
    return False


def inside(p, poly) -> bool:
    w = 0
    for (ax, ay), (bx, by) in zip(poly, poly[1:] + poly[:1]):
        cross = (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax)
        if ay <= p[1] < by and cross > 0:
            w += 1
        elif by <= p[1] < ay and cross < 0:
            w -= 1
    return w != 0


@pytest.mark.parametrize("base", [0.0, 1e5])
def test_rays_through_cut_diagonals_and_at_reflex_corners_neither_leak_nor_hit_outside(tmp_path: Path, base: float) -> None:
    sim = Simulation.from_file(world(tmp_path, base), precision="exact")
    engine = sim.scene.engine
    targets, expect = [], []
    for k, (name, (xy, (dx, dy))) in enumerate(SHAPES.items()):
        geom = sim.world.solids[k].shapes[0].geometry
        faces = np.asarray(geom.faces)
        edges: dict[tuple[int, int], int] = {}
        for f in faces.tolist():
            for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
                edges[(min(a, b), max(a, b))] = edges.get((min(a, b), max(a, b)), 0) + 1
        v = np.asarray(geom.vertices, dtype=np.float64)[:, :2] - (dx + base, dy + base)
        diagonals = [e for e, c in edges.items() if c == 2 and abs(e[0] - e[1]) not in (1, len(xy) - 1)]
        assert diagonals, name
        for a, b in diagonals:
            d = v[b] - v[a]
            side = np.array([-d[1], d[0]]) / np.linalg.norm(d)
            for f in (0.25, 1 / 3, 0.5, 0.8):
                for s in SIDE:
                    q = v[a] + f * d + s * side
                    if near_outline(q, xy):
                        continue                         # a cut along collinear outline corners
                    targets.append((q[0] + dx, q[1] + dy))
                    expect.append(inside(tuple(q), xy))
        for i, c in enumerate(xy):                     # reflex corners: just inside hit, just outside not
            prv, nxt = np.subtract(xy[i - 1], c), np.subtract(xy[(i + 1) % len(xy)], c)
            if np.allclose(prv, 0) or np.allclose(nxt, 0):
                continue
            bis = prv / np.linalg.norm(prv) + nxt / np.linalg.norm(nxt)
            if np.linalg.norm(bis) < 1e-9:
                continue
            bis /= np.linalg.norm(bis)
            for s in (1e-7, 1e-6, 1e-4):
                for q in (np.add(c, s * bis), np.subtract(c, s * bis)):
                    if sum(np.allclose(q, np.add(e, 0), atol=1e-3) for e in xy) > 1 or \
                            (name == "ring" and abs(q[1] - 0.19) < 1e-3):
                        continue                         # the slit's doubled corners: on the outline
                    targets.append((q[0] + dx, q[1] + dy))
                    expect.append(inside(tuple(q), xy))
    t = np.asarray(targets) + base
    got = {}
    for slant in ((0.0, 0.0), (0.3, -0.2), (30.0, -20.0), (-300.0, 7.0)):     # down, slanted, grazing (1.6° and 0.2°)
        d = np.array([slant[0], slant[1], -1.0])
        d /= np.linalg.norm(d)
        o = np.column_stack([t, np.full(len(t), H)]) - d * 1.0
        got[slant] = engine.cast(o, np.broadcast_to(d, o.shape).copy(), kind=RayKind.VISUAL).distance
    expect = np.asarray(expect)
    assert expect.sum() > 250 and (~expect).sum() >= 10
    for slant, dist in got.items():
        miss = np.flatnonzero(expect & ~(np.abs(dist - 1.0) <= 1e-9))
        stray = np.flatnonzero(~expect & np.isfinite(dist))
        assert not len(miss), (slant, len(miss), t[miss[:5]] - base, dist[miss[:5]])
        assert not len(stray), (slant, len(stray), t[stray[:5]] - base)
