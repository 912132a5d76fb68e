"""Hypothesis fuzz of the .wbt import's split of a robot's mesh around its devices
(wbt/inside.turn_meshes_away): random meshes (one triangle, zero-area ones, devices exactly on a
triangle's plane, on its edges and corners, coordinates a million metres from the origin, many
devices). The pieces hold every triangle once; a piece is unseen by exactly the devices within the
mesh's box whose origin lies behind the triangle's counter-clockwise front (computed here in plain
Python, one triangle at a time); there are never more pieces than triangles; and the robot's radar
targets, which name their shapes by index, still name theirs after the split."""

from __future__ import annotations

import math
import random
from collections import Counter
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world
from sensorium.server.world.wbt.inside import turn_meshes_away

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


@pytest.mark.parametrize("examples", example_counts(150))
def test_pieces_hold_every_triangle_once_unseen_by_exactly_the_devices_behind_it(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(meshes())
    def run(mesh) -> None:
        _pieces_hold_every_triangle_once_unseen_by_exactly_the_devices_behind_it(mesh)

    run()


def _pieces_hold_every_triangle_once_unseen_by_exactly_the_devices_behind_it(mesh) -> None:
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
    # float64 rounding: a device within ~1e-16 m of a triangle's plane or of the box's faces (~1e-10 m
    # a million metres out, where its place in the shape's frame is rounded) may fall either side of
    # it; a ray from there only grazes the triangle
    slack = 1e-9 if far else 1e-13
    inside = {f"d{k}": p for k, p in enumerate(points) if all(low[i] + slack < p[i] < high[i] - slack for i in range(3))}
    near = {f"d{k}": p for k, p in enumerate(points) if all(low[i] - slack < p[i] < high[i] + slack for i in range(3))}
    rows: list[tuple] = []
    keys = set()
    for piece in robot["shapes"]:
        unseen = set(piece.get("unseen_by", ()))
        key = tuple(sorted(unseen))
        assert key not in keys, key                     # one piece a set of devices
        keys.add(key)
        assert piece["pose"] == shape["pose"]
        assert unseen <= set(near), (unseen, near)
        pts = np.asarray(piece["geometry"]["vertices"], dtype=np.float64).reshape(-1, 3)
        mine = np.asarray(piece["geometry"]["faces"]).reshape(-1, 3)
        # a piece of a split mesh holds its own points and the mesh's box (the default texture mapping's)
        assert pts.min(axis=0).tolist() == np.min(verts, axis=0).tolist()
        assert pts.max(axis=0).tolist() == np.max(verts, axis=0).tolist()
        assert len(pts) <= max(3 * len(mine) + 2, len(verts))
        for row in mine.tolist():
            a, b, c = (pts[i].tolist() for i in row)
            rows.append((tuple(a), tuple(b), tuple(c)))
            for name, p in near.items():
                s = side(p, a, b, c)
                if s < -slack and name in inside:
                    assert name in unseen, (row, name, s)
                elif s > slack:
                    assert name not in unseen, (row, name, s)
    assert Counter(rows) == Counter(tuple(tuple(verts[i]) for i in f) for f in faces)
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


def soup(count: int, seed: int) -> tuple[list[tuple[float, float, float]], str]:
    """``count`` triangles at random in a 0.4 m cube (each its own three points, none shared), written
    as an IndexedFaceSet's points and coordIndex: devices within its box face some and not others."""
    rng = random.Random(seed)
    pts = [(round(rng.uniform(-0.2, 0.2), 6), round(rng.uniform(-0.2, 0.2), 6), round(rng.uniform(-0.2, 0.2), 6))
           for _ in range(3 * count)]
    index = " ".join(f"{3 * t} {3 * t + 1} {3 * t + 2} -1" for t in range(count))
    return pts, index


def soup_robot(tmp_path: Path, count: int, sensors: int, texture: bool = False) -> Path:
    pts, index = soup(count, 1)
    rng = random.Random(2)
    devices = "".join(f'DistanceSensor {{ translation {rng.uniform(-0.18, 0.18):.4f} {rng.uniform(-0.18, 0.18):.4f} '
                      f'{rng.uniform(-0.18, 0.18):.4f} name "d{k}" type "infra-red" '
                      f'lookupTable [ 0 0 0 0.5 500 0 ] }}\n' for k in range(sensors))
    look = "appearance Appearance { texture ImageTexture { url \"tex.png\" } } " if texture else ""
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 "DirectionalLight { direction 0.3 -0.2 -1 }\nPointLight { location 0 0 0 }\n"
                 'Robot { name "r" children [\n'
                 f'Shape {{ {look}geometry IndexedFaceSet {{ coord Coordinate {{ point [ '
                 f'{", ".join(" ".join(map(repr, q)) for q in pts)} ] }} coordIndex [ {index} ] }} }}\n'
                 'Camera { translation 0.01 0.02 0.03 width 64 height 48 }\n' + devices + "] }\n")
    return p


def test_a_mesh_split_in_thousands_of_pieces_loads_about_its_own_size(tmp_path: Path) -> None:
    """2500 triangles at random and 64 infra-red sensors within their box: some 2000 pieces. Each
    piece carried every point of the mesh (7500 of them), so the world went over the values limit
    (2 000 000) and was refused, a 2500-triangle file; now each piece holds the points it uses and
    the whole mesh's two box corners."""
    robot = load_world(soup_robot(tmp_path, 2500, 64)).world.robots[0]
    pieces = [s.geometry for s in robot.shapes if s.geometry.type == "triangles"]
    assert len(pieces) > 1000
    assert sum(len(g.faces) for g in pieces) == 2500
    assert sum(len(g.vertices) for g in pieces) == 3 * 2500 + 2 * len(pieces)


def test_split_readings_equal_the_world_written_with_the_split_and_every_point(tmp_path: Path) -> None:
    """A textured mesh (Webots' default mapping: over the box of all its points) split by a camera
    and 12 infra-red sensors inside its box: the camera's image and the sensors' readings are the
    bits of the same world written with the split explicitly (``unseen_by`` in the world file),
    each piece keeping every point of the mesh and its original indices. Without the box corners
    kept in each piece, the texture's mapping (and so the image) changed with the piece."""
    from PIL import Image

    img = np.zeros((16, 16, 3), dtype=np.uint8)
    img[..., 0] = np.arange(16)[:, None] * 16
    img[..., 1] = np.arange(16)[None, :] * 16
    img[::2, ::3, 2] = 255
    Image.fromarray(img).save(tmp_path / "tex.png")
    split = load_world(soup_robot(tmp_path, 300, 12, texture=True))
    pts, _ = soup(300, 1)
    where = {p: k for k, p in enumerate(pts)}
    data = split.world.model_dump(mode="json", exclude_none=True)
    pieces = 0
    for shape in data["robots"][0]["shapes"]:
        g = shape["geometry"]
        if g["type"] != "triangles":
            continue
        pieces += 1
        corners = [tuple(g["vertices"][i]) for face in g["faces"] for i in face]
        g["vertices"] = [list(p) for p in pts]
        g["faces"] = [[where[c] for c in corners[k:k + 3]] for k in range(0, len(corners), 3)]
    assert pieces > 10
    written = parse_world(data, base_dir=tmp_path)

    def readings(w) -> tuple:
        sim = Simulation(w)
        for d in w.world.robots[0].devices:
            sim.device(f"r/{d.name}").enable(16)
        sim.step()
        return (sim.device("r/camera").image.tobytes(),
                [float(sim.device(f"r/d{k}").value) for k in range(12)])

    got, expect = readings(split), readings(written)
    assert got[1] == expect[1]
    assert got[0] == expect[0]
    assert len(set(got[0])) > 10 and any(0.0 < v < 500.0 for v in got[1])      # the mesh is seen


def test_a_split_mesh_is_one_shape_node_to_a_supervisor(tmp_path: Path) -> None:
    """The body mesh of test_a_radar_target_after_a_split_mesh_still_names_its_own_box, DEF'd, split
    in two by the sensors inside it: a Supervisor sees the robot's children as written (one Shape,
    three sensors), and the DEF'd Shape's transparency set to 1 hides every piece (the sensor beside
    the robot, looking at it, reads nothing)."""
    from sensorium.server.daemon import supervisor as sv

    ring = [(0.15 * math.cos(k * math.pi / 3), 0.15 * math.sin(k * math.pi / 3)) for k in range(6)]
    points = " ".join(f"{x:.6f} {y:.6f} {z}" for z in (-0.035, 0.035) for x, y in ring)
    points += " 0.05 -0.03 0, 0.13 -0.03 0, 0.13 0.03 0, 0.05 0.03 0"
    faces = ("12 13 14 15 -1 5 4 3 2 1 0 -1 6 7 8 9 10 11 -1 "
             + " ".join(f"{k} {(k + 1) % 6} {(k + 1) % 6 + 6} {k + 6} -1" for k in range(6)))
    table = 'lookupTable [ 0 1000 0 0.2 0 0 ] type "infra-red"'
    p = tmp_path / "w.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 'Robot { name "r" translation 0 0 0.05 supervisor TRUE children [\n'
                 f'DEF BODY Shape {{ appearance PBRAppearance {{ }} geometry IndexedFaceSet {{ coord Coordinate {{ '
                 f'point [ {points} ] }} coordIndex [ {faces} ] }} }}\n'
                 f'DistanceSensor {{ translation 0.1 0 0.02 rotation 0 1 0 1.5708 name "over" {table} }}\n'
                 f'DistanceSensor {{ translation -0.1 0 0 rotation 0 1 0 1.5708 name "cliff" {table} }}\n'
                 f'DistanceSensor {{ translation 0.3 0 0 rotation 0 1 0 3.1416 name "side" {table} }}\n] }}\n')
    w = load_world(p)
    assert len(w.world.robots[0].shapes) == 2          # split: the plate facing "over", the rest
    sim = Simulation(w)
    sim.device("r/side").enable(16)
    sim.step()
    assert sim.device("r/side").value == pytest.approx(250.0, abs=1e-6)        # the body's rim 15 cm away
    sv.set_field(sim, sv.node_by_id(sim, sv.get_field(sim, sv.find_node(sim, "BODY"), "appearance")["value"]),
                 "transparency", 1.0)
    sim.step()
    assert sim.device("r/side").value == 0.0
    kids = sv.get_field(sim, sv.find_node(sim, "r"), "children")["value"]
    assert [sv.node_by_id(sim, i).type for i in kids] == ["Shape", "DistanceSensor", "DistanceSensor", "DistanceSensor"]
