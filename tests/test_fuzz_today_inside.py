"""Hypothesis fuzz of the .wbt import's split of a robot's mesh around its devices
(wbt/inside.turn_meshes_away): random meshes (one triangle, zero-area ones, devices exactly on a
triangle's plane, on its edges and corners, coordinates a million metres from the origin, many
devices). The pieces hold every triangle once; a piece is unseen by exactly the devices within the
mesh's box whose origin lies behind the triangle's counter-clockwise front (computed here in plain
Python, one triangle at a time); there are never more pieces than triangles; and the robot's radar
targets, which name their shapes by index, still name theirs after the split."""

from __future__ import annotations

import math
from collections import Counter
from fractions import Fraction
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.server.world.loader import load_world
from sensorium.server.world.wbt.inside import turn_meshes_away

FEW = settings(SETTINGS, max_examples=150)

small = st.sampled_from([-1.0, -0.5, 0.0, 0.5, 1.0]) | st.floats(-1.0, 1.0)


@st.composite
def meshes(draw):
    """(vertices, faces, device points, far offset): a few vertices on a small grid or anywhere in a
    unit cube (so that devices fall on planes, edges and corners), faces among them (repeated
    corners: zero-area triangles), devices on vertices, on edge midpoints or anywhere."""
    nv = draw(st.integers(3, 8))
    verts = [[draw(small), draw(small), draw(small)] for _ in range(nv)]
    idx = st.integers(0, nv - 1)
    faces = draw(st.lists(st.tuples(idx, idx, idx), min_size=1, max_size=12))
    points = []
    for _ in range(draw(st.integers(1, 12))):
        how = draw(st.sampled_from(["vertex", "edge", "free", "centre"]))
        a, b, c = draw(st.sampled_from(faces))
        if how == "vertex":
            points.append(list(verts[a]))
        elif how == "edge":
            points.append([(verts[a][i] + verts[b][i]) / 2.0 for i in range(3)])
        elif how == "centre":
            points.append([(verts[a][i] + verts[b][i] + verts[c][i]) / 3.0 for i in range(3)])
        else:
            points.append([draw(small), draw(small), draw(small)])
    far = draw(st.sampled_from([0.0, 1e6, -1e6]))
    return verts, faces, points, far


def side(p, a, b, c) -> Fraction:
    """(p - a) · ((b - a) × (c - a)) in exact arithmetic: < 0 when p is behind the triangle's
    counter-clockwise front, 0 on its plane (or the triangle has no area)."""
    p, a, b, c = ([Fraction(x) for x in v] for v in (p, a, b, c))
    e1 = [b[i] - a[i] for i in range(3)]
    e2 = [c[i] - a[i] for i in range(3)]
    n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
    return sum(((p[i] - a[i]) * n[i] for i in range(3)), Fraction(0))


@FEW
@given(meshes())
def test_pieces_hold_every_triangle_once_unseen_by_exactly_the_devices_behind_it(mesh):
    verts, faces, points, far = mesh
    # the mesh and its devices moved far from the origin together: the shape's pose carries the offset
    shape = {"seen_by": "visual", "pose": {"translation": [far, -far, far]},
             "geometry": {"type": "triangles", "vertices": [x for v in verts for x in v],
                          "faces": [i for f in faces for i in f]}}
    devices = [{"device": "DistanceSensor", "type": "infra-red", "name": f"d{k}",
                "pose": {"translation": [p[0] + far, p[1] - far, p[2] + far]}} for k, p in enumerate(points)]
    robot = {"name": "r", "shapes": [shape], "devices": devices,
             "radar_targets": [{"name": "t", "shapes": [0]}]}
    turn_meshes_away(robot, set())
    used = [verts[i] for f in faces for i in f]
    low = [min(v[i] for v in used) for i in range(3)]
    high = [max(v[i] for v in used) for i in range(3)]
    inside = {f"d{k}": p for k, p in enumerate(points) if all(low[i] < p[i] < high[i] for i in range(3))}
    # float64 rounding: a device within ~1e-16 m of a triangle's plane (~1e-10 m a million metres
    # out, where its place in the shape's frame is rounded) may fall either side of it; a ray from
    # there only grazes the triangle
    slack = Fraction(1e-9) if far else Fraction(1e-13)
    rows: list[tuple] = []
    keys = set()
    for piece in robot["shapes"]:
        unseen = set(piece.get("unseen_by", ()))
        key = tuple(sorted(unseen))
        assert key not in keys, key                     # one piece a set of devices
        keys.add(key)
        assert piece["pose"] == shape["pose"] and piece["geometry"]["vertices"] is shape["geometry"]["vertices"]
        assert unseen <= set(inside), (unseen, inside)
        for row in np.asarray(piece["geometry"]["faces"]).reshape(-1, 3).tolist():
            rows.append(tuple(row))
            a, b, c = (verts[i] for i in row)
            for name, p in inside.items():
                s = side(p, a, b, c)
                if s < -slack:
                    assert name in unseen, (row, name, s)
                elif s > slack:
                    assert name not in unseen, (row, name, s)
    assert Counter(rows) == Counter(faces)
    assert len(robot["shapes"]) <= len(faces)
    assert robot["radar_targets"][0]["shapes"] == list(range(len(robot["shapes"])))


def test_a_radar_target_after_a_split_mesh_still_names_its_own_box(tmp_path: Path) -> None:
    """A robot's body mesh split in two by the sensors inside it (a plate faces one of them), then a
    Solid with a radarCrossSection holding a box: the target names its shapes by index in the
    robot's shapes, which the split renumbered. It named index 1 — the mesh's second piece, not its
    box (now index 2)."""
    ring = [(0.15 * math.cos(k * math.pi / 3), 0.15 * math.sin(k * math.pi / 3)) for k in range(6)]
    points = " ".join(f"{x:.6f} {y:.6f} {z}" for z in (-0.035, 0.035) for x, y in ring)
    points += " 0.05 -0.03 0, 0.13 -0.03 0, 0.13 0.03 0, 0.05 0.03 0"
    faces = ("12 13 14 15 -1 5 4 3 2 1 0 -1 6 7 8 9 10 11 -1 "
             + " ".join(f"{k} {(k + 1) % 6} {(k + 1) % 6 + 6} {k + 6} -1" for k in range(6)))
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\n" + 'Robot { name "r" translation 0 0 0.05 children [\n'
                 f'Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point [ {points} ] }} '
                 f'coordIndex [ {faces} ] }} }}\n'
                 'DistanceSensor { translation -0.1 0 0 name "cliff" type "infra-red" }\n'
                 'DistanceSensor { translation 0.1 0 0.02 name "over" type "infra-red" }\n'
                 'Solid { translation 1 0 0 name "tgt" radarCrossSection 1 children [\n'
                 '  Shape { geometry Box { size 0.1 0.2 0.3 } } ] }\n] }\n')
    robot = load_world(p).world.robots[0]
    assert [s.geometry.type for s in robot.shapes] == ["triangles", "triangles", "box"]
    [target] = robot.radar_targets
    assert target.shapes == [2]
    assert robot.shapes[2].pose.translation == (1.0, 0.0, 0.0)
