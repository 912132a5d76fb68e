"""A tracked robot with Physics rests on its Tracks' bounding objects (world/wbt/convert.py ``bounds_bottom``,
through world/geometry.py ``reach``, which sim/ground.py shares): each Box, Sphere, Cylinder and Capsule,
turned any way, reaches down to its lowest point, checked against the lowest of many points sampled on its
surface (an independent answer). A Cylinder's and a Capsule's axis is their z, as in Webots since R2022a."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS

from sensorium.server.world import geometry as geo
from sensorium.server.world.loader import load_world
from sensorium.server.world.poses import axis_angle_matrix

TRACK_Z = -0.03      # each Track's translation z in the robot
SAMPLES = 4001


def sampled_low(kind: str, size: tuple[float, ...], centre, axis, angle: float) -> float:
    """The lowest z of points sampled densely on the shape's surface (the box's corners; the cylinder's end
    circles; the capsule's and sphere's spheres about their centres: their lowest points in closed form,
    each sphere's centre less its radius), turned ``angle`` about ``axis`` and put at ``centre``."""
    r = axis_angle_matrix(axis, angle)
    c = np.asarray(centre, dtype=np.float64)
    if kind == "Box":
        half = np.asarray(size) / 2.0
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
        return float((c + corners @ r.T)[:, 2].min())
    if kind == "Sphere":
        return float(c[2]) - size[0]
    radius, height = size
    ends = [c + r @ np.array([0.0, 0.0, s * height / 2.0]) for s in (-1, 1)]
    if kind == "Capsule":
        return min(float(e[2]) for e in ends) - radius
    t = np.linspace(0.0, 2.0 * math.pi, SAMPLES)
    ring = np.stack([radius * np.cos(t), radius * np.sin(t), np.zeros_like(t)], axis=1) @ r.T
    return min(float((e + ring)[:, 2].min()) for e in ends)


def geometry_text(kind: str, size: tuple[float, ...]) -> str:
    if kind == "Box":
        return "Box {{ size {!r} {!r} {!r} }}".format(*size)
    if kind == "Sphere":
        return f"Sphere {{ radius {size[0]!r} }}"
    return f"{kind} {{ radius {size[0]!r} height {size[1]!r} }}"


def tracked_world(tmp_path: Path, bounds: str) -> Path:
    track = """Track {
      translation 0 %s %r
      children [ TrackWheel { position 0.1 0 radius 0.02 } TrackWheel { position -0.1 0 radius 0.02 } ]
      name "%s"
      boundingObject %s
      physics Physics { }
      device [ LinearMotor { name "%s" } ]
    }"""
    path = tmp_path / "tracked.wbt"
    path.write_text("#VRML_SIM R2025a utf8\nWorldInfo { basicTimeStep 8 }\n"
                    "Robot {\n  translation 0 0 0.5\n  children [\n    "
                    + track % ("0.2", TRACK_Z, "left track", bounds, "left motor") + "\n    "
                    + track % ("-0.2", TRACK_Z, "right track", bounds, "right motor")
                    + '\n  ]\n  name "tank"\n  physics Physics { }\n  controller "<none>"\n}\n')
    return path


CASES = [
    ("Cylinder", (0.05, 0.3), (0.0, 0.0, 1.0), 0.0),             # upright: h/2 below, not r
    ("Cylinder", (0.05, 0.3), (1.0, 0.0, 0.0), math.pi / 2),     # lying across the track: r below
    ("Cylinder", (0.07, 0.2), (0.3, -0.5, 0.8), 1.1),            # tilted: its end's rim
    ("Capsule", (0.04, 0.25), (0.0, 1.0, 0.0), 0.7),
    ("Sphere", (0.09,), (0.0, 0.0, 1.0), 0.4),
    ("Box", (0.3, 0.08, 0.05), (0.2, 0.9, -0.1), 0.9),
]


@pytest.mark.parametrize(("kind", "size", "axis", "angle"), CASES)
def test_a_tracked_robot_rests_on_its_tracks_bounding_geometry_turned_any_way(
        tmp_path: Path, kind: str, size: tuple[float, ...], axis: tuple[float, float, float], angle: float) -> None:
    centre = (0.02, 0.0, -0.01)
    bounds = (f"Transform {{ translation {centre[0]!r} {centre[1]!r} {centre[2]!r} "
              f"rotation {axis[0]!r} {axis[1]!r} {axis[2]!r} {angle!r} children [ {geometry_text(kind, size)} ] }}")
    w = load_world(tracked_world(tmp_path, bounds))
    (robot,) = w.world.robots
    dd = robot.differential_drive
    assert dd is not None and (dd.left_motor, dd.right_motor) == ("left motor", "right motor")
    expected = TRACK_Z + sampled_low(kind, size, centre, np.asarray(axis) / np.linalg.norm(axis), angle)
    tol = 1e-12 if kind != "Cylinder" else size[0] * (math.pi / (SAMPLES - 1)) ** 2
    assert dd.wheel_bottom == pytest.approx(expected, abs=tol)


def test_reach_along_a_direction_is_the_closed_form_for_each_primitive() -> None:
    """geometry.reach on the axes and a diagonal: a box's half sizes, a cylinder's half height along its axis
    and radius across it, a capsule's half height plus radius along its axis."""
    d = np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)
    assert geo.reach(geo.Box((0.2, 0.4, 0.6)), (0.0, 0.0, -1.0)) == 0.3
    assert geo.reach(geo.Box((0.2, 0.4, 0.6)), d) == pytest.approx(0.6 / math.sqrt(3.0), abs=1e-15)
    assert geo.reach(geo.Cylinder(0.1, 0.5), (0.0, 0.0, 1.0)) == 0.25
    assert geo.reach(geo.Cylinder(0.1, 0.5), (0.0, 1.0, 0.0)) == 0.1
    assert geo.reach(geo.Cylinder(0.1, 0.5), d) == pytest.approx(0.25 / math.sqrt(3.0) + 0.1 * math.sqrt(2.0 / 3.0),
                                                               abs=1e-15)
    assert geo.reach(geo.Capsule(0.1, 0.5), (0.0, 0.0, -1.0)) == pytest.approx(0.35, abs=1e-15)
    assert geo.reach(geo.Capsule(0.1, 0.5), (1.0, 0.0, 0.0)) == 0.1
    assert geo.reach(geo.Sphere(0.3), d) == 0.3


size = st.floats(0.01, 3.0)
direction = st.tuples(*(st.floats(-1.0, 1.0),) * 3).filter(lambda d: math.hypot(*d) > 1e-3)


@given(kind=st.sampled_from(["Box", "Sphere", "Cylinder", "Capsule"]), a=size, b=size, c=size, d=direction)
@settings(SETTINGS, max_examples=300)
def test_reach_lies_between_the_true_shape_and_its_circumscribed_tessellation(kind, a, b, c, d) -> None:
    """geometry.reach along any direction is at most the tessellation's furthest vertex (every tessellation
    circumscribes its shape) and at least that vertex shrunk by the tessellation's outward factor: a box's
    equal, a cylinder's rim within 1/cos(π/n), a capsule's and a sphere's within their vertices' radii."""
    p = {"Box": lambda: geo.Box((a, b, c)), "Sphere": lambda: geo.Sphere(a),
         "Cylinder": lambda: geo.Cylinder(a, b), "Capsule": lambda: geo.Capsule(a, b)}[kind]()
    unit = np.asarray(d) / np.linalg.norm(d)
    vertices, _ = geo.tessellate(p)
    furthest = float((vertices @ unit).max())
    exact = geo.reach(p, unit)
    assert exact <= furthest + 1e-12 * (1.0 + furthest)
    if kind == "Box":
        assert exact == pytest.approx(furthest, rel=1e-12)
    elif kind == "Cylinder":
        k = math.hypot(unit[0], unit[1])
        out = b / 2.0 * abs(unit[2]) + a * k / math.cos(math.pi / p.subdivision)
        assert furthest <= out + 1e-12 * out
    else:     # the sphere's or capsule's vertices: at most the largest distance of a vertex to the axis segment
        seg = np.clip(vertices[:, 2], -b / 2.0, b / 2.0) if kind == "Capsule" else np.zeros(len(vertices))
        grow = float(np.linalg.norm(vertices - np.outer(seg, [0.0, 0.0, 1.0]), axis=1).max()) / a
        assert furthest <= exact * grow + 1e-12 * furthest
