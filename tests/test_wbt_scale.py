"""Non-uniform ``scale`` in .wbt worlds (issue 27): what Webots allows over geometry is read (visual
shapes as their exact affine image, bounding shapes as Webots gives them to ODE), what it forbids
(a Solid under a Transform) is said as Webots says it. Hit distances against closed forms."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.raycast.kinds import RayKind
from sensorium.server.sim.scene import Scene
from sensorium.server.world.loader import load_world
from sensorium.server.world.wbt.frames import CURVED_LEVELS, surface_gap

HEADER = "#VRML_SIM R2023b utf8\n"


def write(tmp_path: Path, body: str) -> Path:
    p = tmp_path / "w.wbt"
    p.write_text(HEADER + body)
    return p


def hit(scene: Scene, origin, direction, kind=RayKind.VISUAL) -> float:
    d = np.asarray(direction, dtype=np.float64)
    hits = scene.engine.cast(np.asarray([origin], dtype=np.float64), (d / np.linalg.norm(d))[None], kind=kind)
    return float(hits.distance[0])


def loaded_scene(p: Path):
    w = load_world(p)
    return w, Scene(w.world, w.base_dir, "exact")


def test_a_decorative_non_uniform_scale_loads_with_exact_boxes_and_cylinders(tmp_path: Path) -> None:
    """Once refused whole; now a box scaled along its axes stays an exact box, a cylinder scaled
    alike across its axis an exact cylinder, seen by both kinds of ray (one shape)."""
    p = write(tmp_path, 'Solid { name "s" children [ Transform { translation 0 0 1 scale 1 2 3 children [\n'
                        '  DEF B Shape { geometry Box { size 0.2 0.2 0.2 } } ] }\n'
                        '  Transform { translation 2 0 0 scale 2 2 0.5 children [ DEF C Shape { geometry Cylinder { radius 0.1 height 0.4 } } ] } ]\n'
                        '  boundingObject Group { children [ Transform { translation 0 0 1 scale 1 2 3 children [ USE B ] }\n'
                        '    Transform { translation 2 0 0 scale 2 2 0.5 children [ USE C ] } ] } }\n')
    w, scene = loaded_scene(p)
    box, cyl = w.world.solids[0].shapes
    assert box.geometry.type == "box" and box.geometry.size == pytest.approx((0.2, 0.4, 0.6), rel=1e-15)
    assert (cyl.geometry.type, cyl.geometry.radius, cyl.geometry.height) == ("cylinder", 0.2, 0.2)
    assert box.seen_by == cyl.seen_by == "both" and w.losses == ()
    for kind in (RayKind.VISUAL, RayKind.BOUNDING):
        assert hit(scene, (0, -5, 1), (0, 1, 0), kind) == pytest.approx(5 - 0.2, abs=1e-12)
        assert hit(scene, (0, 0, 5), (0, 0, -1), kind) == pytest.approx(4 - 0.3, abs=1e-12)
        assert hit(scene, (2, -5, 0), (0, 1, 0), kind) == pytest.approx(5 - 0.2, abs=1e-12)


def test_an_ellipsoid_is_seen_within_the_stated_gap(tmp_path: Path) -> None:
    """A visual sphere under scale (1, 2, 3) is the ellipsoid Webots renders (lidars and infra-red
    see it); as triangles its surface is within surface_gap · radius · largest scale."""
    p = write(tmp_path, 'Transform { scale 1 2 3 children [ Shape { geometry Sphere { radius 0.1 } } ] }\n')
    w, scene = loaded_scene(p)
    (shape,) = w.world.solids[0].shapes
    assert shape.geometry.type == "triangles" and len(shape.geometry.faces) == 20 * 4 ** CURVED_LEVELS["sphere"]
    gap = surface_gap("sphere") * 0.1 * 3
    assert gap < 4e-4
    for axis, semi in ((0, 0.1), (1, 0.2), (2, 0.3)):
        o = np.zeros(3)
        o[axis] = -5
        d = np.zeros(3)
        d[axis] = 1
        assert abs(hit(scene, o, d) - (5 - semi)) <= gap
    # an oblique ray: the closed-form hit on x²/a² + y²/b² + z²/c² = 1
    o, d = np.array([1.0, -2.0, 0.5]), np.array([-1.0, 2.0, -0.5]) / math.sqrt(5.25)
    a = np.array([0.1, 0.2, 0.3])
    qa, qb, qc = (d / a) @ (d / a), 2 * (o / a) @ (d / a), (o / a) @ (o / a) - 1
    t = (-qb - math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    assert abs(hit(scene, o, d) - t) <= gap


def test_a_box_turned_between_two_scales_is_its_exact_parallelepiped(tmp_path: Path) -> None:
    """A rotation inside a non-uniform scale shears a box: 12 exact triangles (what Webots renders)."""
    p = write(tmp_path, 'Transform { scale 2 1 1 children [ Pose { rotation 0 0 1 0.7853981633974483 children [\n'
                        '  Shape { geometry Box { size 1 1 0.2 } } ] } ] }\n')
    w, scene = loaded_scene(p)
    (shape,) = w.world.solids[0].shapes
    assert shape.geometry.type == "triangles" and len(shape.geometry.faces) == 12
    # the box's corner (0.5, 0.5)·R45 = (0, 0.7071) maps to (0, 0.7071); the +x corner (0.7071, 0) to (1.4142, 0)
    assert hit(scene, (5, 0, 0), (-1, 0, 0)) == pytest.approx(5 - 2 * math.sqrt(0.5), abs=1e-12)
    assert hit(scene, (0, 5, 0), (0, -1, 0)) == pytest.approx(5 - math.sqrt(0.5), abs=1e-12)


def test_bounding_shapes_are_scaled_as_webots_gives_them_to_ode(tmp_path: Path) -> None:
    """WbSphere::scaledRadius: radius × the largest scale; a Transform in a boundingObject holding a
    Sphere is made uniform and one holding a Cylinder gets x = y, with Webots' warnings."""
    p = write(tmp_path, 'Solid { name "a" boundingObject Transform { scale 1 2 3 children [ Pose { children [\n'
                        '  Sphere { radius 0.1 } ] } ] } }\n'
                        'Solid { name "b" translation 2 0 0 boundingObject Transform { scale 1 2 3 children [ Sphere { radius 0.1 } ] } }\n'
                        'Solid { name "c" translation 4 0 0 boundingObject Transform { scale 2 3 4 children [ Cylinder { radius 0.1 height 0.2 } ] } }\n')
    w, scene = loaded_scene(p)
    a, b, c = (s.shapes[0].geometry for s in w.world.solids)
    assert (a.type, a.radius) == ("sphere", pytest.approx(0.3))      # nested: no constraint, ODE radius × max
    assert (b.type, b.radius) == ("sphere", pytest.approx(0.1))      # made uniform (1 1 1): x != y, x != z → x
    assert (c.type, c.radius, c.height) == ("cylinder", pytest.approx(0.2), pytest.approx(0.8))   # x = y = 2
    assert sum("'scale' was made uniform because of physics constraints inside a 'boundingObject'." in x
               for x in w.warnings) == 1
    assert sum("'scale' were changed so that x = y" in x for x in w.warnings) == 1
    assert hit(scene, (0, -5, 0), (0, 1, 0), RayKind.BOUNDING) == pytest.approx(4.7, abs=1e-12)


def test_zero_and_negative_scales(tmp_path: Path) -> None:
    """Webots resets a zero component to 1 (its warning) and mirrors with a negative one: a mirrored
    IndexedFaceSet keeps its faces wound outwards."""
    p = write(tmp_path, 'Transform { scale 0 1 1 children [ Shape { geometry Box { size 1 1 1 } } ] }\n'
                        'Transform { translation 3 0 0 scale -1 1 1 children [ Shape { geometry IndexedFaceSet {\n'
                        '  coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } } ] }\n')
    w = load_world(p)
    box, tri = w.world.solids[0].shapes
    assert box.geometry.size == (1.0, 1.0, 1.0)
    assert any("All 'scale' coordinates must be non-zero: x is set to 1.0." in x for x in w.warnings)
    assert tri.geometry.vertices == [(0.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
    assert [list(f) for f in tri.geometry.faces] == [[0, 2, 1]]          # mirrored: wound back


def test_solids_under_a_scale_are_dropped_as_webots_forbids(tmp_path: Path) -> None:
    p = write(tmp_path, 'Transform { scale 1 1 2 children [ Robot { name "r" } Solid { name "s" } ] }\n'
                        'Robot { name "kept" children [ Transform { scale 1 1 2 children [\n'
                        '  DistanceSensor { name "ds" } Shape { geometry Box { size 0.1 0.1 0.1 } } ] } ] }\n')
    w = load_world(p)
    assert [(x.kind, x.name, x.robot) for x in w.losses] == [("robot", "r", ""), ("solid", "s", ""),
                                                             ("device", "ds", "kept")]
    assert all("Webots allows only Transform, Pose, Group and Shape in a Transform's children" in x.why
               for x in w.losses)
    (robot,) = w.world.robots
    assert robot.shapes[0].geometry.size == pytest.approx((0.1, 0.1, 0.2))     # the shape itself is scaled


def test_stated_gaps_hold() -> None:
    """The numbers README quotes for the tessellated curved shapes (relative to the radius)."""
    assert surface_gap("sphere") < 1.2e-3
    assert surface_gap("cylinder") < 1.3e-3
    assert surface_gap("capsule") < 2.5e-3
    assert surface_gap("capsule", height=0.1) < 2.5e-3
