"""Hypothesis properties of the Supervisor's getStaticBalance and getContactPoints (sim/balance.py) and of
exportString (daemon/export.py), against closed forms, on worlds drawn at random:

- a box of any size (1 mm .. 2 m) turned any way about the vertical, resting on the floor, its centre of
  mass anywhere about it (Physics centerOfMass): balanced iff that centre, seen from above, is inside the
  turned footprint; its contact points are the footprint's four corners in world coordinates, each naming
  the box; the same answers 1e5 m from the origin;
- a w x w x h box lying on a ramp of any slope: balanced iff tan(slope) <= w / h;
- a Solid of random fields and children (Pose, Transform, Shape, Box, Sphere, Cylinder, Capsule, Physics)
  exported, imported again and exported again gives the same text."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HEAD = "#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
SUPERVISOR = 'Robot { translation 0 0 -50 name "sup" supervisor TRUE controller "<extern>" }\n'
FLOOR = 'Solid { name "floor" boundingObject Plane { size 400000 400000 } }\n'
EDGE = 1e-6
"""m: centres of mass this close to the footprint's edge are not drawn (either answer is right there)."""


def _live(text: str) -> Live:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "w.wbt"
        path.write_text(text)
        lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "sup"})
    return lv


def _sup(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/sup/robot/{item}", args)


def _node(lv: Live, name: str) -> int:
    return _sup(lv, "get_from_def", {"name": name})["node"]


def _r(v: float) -> str:
    return repr(float(v))


size = st.floats(0.001, 2.0)
boxes = st.tuples(size, size, size, st.floats(-math.pi, math.pi),     # width (x), depth (y), height, yaw
                  st.floats(-1.5, 1.5), st.floats(-1.5, 1.5), st.floats(-1.0, 1.0))   # com in units of half sides


def _footprint_case(box: tuple, at: tuple[float, float], base: float = 0.0) -> tuple[str, bool, np.ndarray] | None:
    """The box's world text (its bottom at height ``base``), whether its centre of mass is over its footprint,
    its bottom corners (None for a centre within EDGE of the footprint's edge)."""
    # rounded: a world's numbers below 1e-30 in magnitude are refused at load (world/limits.py)
    w, d, h, yaw, u, v, k = (round(x, 12) for x in box)
    cx, cy, cz = u * w / 2.0, v * d / 2.0, k * h / 2.0
    if abs(abs(cx) - w / 2.0) <= EDGE or abs(abs(cy) - d / 2.0) <= EDGE:
        return None
    inside = abs(cx) < w / 2.0 and abs(cy) < d / 2.0
    c, s = math.cos(yaw), math.sin(yaw)
    corners = np.array([(at[0] + c * x - s * y, at[1] + s * x + c * y, base)
                        for x in (-w / 2.0, w / 2.0) for y in (-d / 2.0, d / 2.0)])
    text = (f'DEF BOX Solid {{ translation {_r(at[0])} {_r(at[1])} {_r(base + h / 2.0)} rotation 0 0 1 {_r(yaw)} name "box" '
            f'boundingObject Box {{ size {_r(w)} {_r(d)} {_r(h)} }} '
            f'physics Physics {{ mass 1 centerOfMass [ {_r(cx)} {_r(cy)} {_r(cz)} ] }} }}\n')
    return text, inside, corners


def _table(at: tuple[float, float]) -> str:
    """A table 0.5 m high and 6 m square centred under ``at``, no floor."""
    return f'Solid {{ translation {_r(at[0])} {_r(at[1])} 0.25 name "table" boundingObject Box {{ size 6 6 0.5 }} }}\n'


def _check_footprint(box: tuple, at: tuple[float, float], table: bool = False) -> None:
    case = _footprint_case(box, at, 0.5 if table else 0.0)
    assume(case is not None)
    assert case is not None
    text, inside, corners = case
    lv = _live(HEAD + (_table(at) if table else FLOOR) + text + SUPERVISOR)
    box_id = _node(lv, "BOX")
    assert _sup(lv, "get_node_static_balance", {"node": box_id})["value"] is inside
    got = _sup(lv, "get_node_contact_points", {"node": box_id, "include_descendants": False})
    points = np.array(got["points"]).reshape(-1, 3)
    assert got["nodes"] == [box_id] * 4
    scale = max(abs(at[0]), abs(at[1]), 1.0)
    tol = 1e-12 * scale + 1e-12
    # each corner matched by one point (order is the shape's own)
    for corner in corners:
        assert np.min(np.max(np.abs(points - corner), axis=1)) <= tol, (corner, points)
    assert np.all(np.abs(points[:, 2] - corners[0, 2]) <= tol)


@pytest.mark.parametrize("examples", example_counts(200))
def test_a_box_on_the_floor_is_balanced_iff_its_centre_is_over_its_turned_footprint(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(boxes, st.tuples(st.floats(-10.0, 10.0), st.floats(-10.0, 10.0)))
    def run(box, at):
        _check_footprint(box, (round(at[0], 9), round(at[1], 9)))

    run()


@pytest.mark.parametrize("examples", example_counts(200))
def test_the_same_answers_far_from_the_origin_and_on_a_table(examples: int) -> None:
    # on a table's top its corners are found on the ground under them and as its face's corners over the top:
    # each counted once
    far = st.floats(-1e5, 1e5) | st.sampled_from([1e5, -1e5, 99999.999])

    @settings(SETTINGS, max_examples=examples)
    @given(boxes, st.tuples(far, far), st.booleans())
    def run(box, at, table):
        _check_footprint(box, (round(at[0], 9), round(at[1], 9)), table)

    run()


@pytest.mark.parametrize("height", [0.001, 0.0005, 1e-5])
def test_a_plate_1_mm_thick_or_thinner_touches_at_its_four_bottom_corners_only(height: float) -> None:
    # its top corners, within the 1 mm contact tolerance of the floor, lie on no face turned down
    @settings(SETTINGS, max_examples=2)
    @given(st.sampled_from([0.5, 1.2]))
    def run(u):
        _check_footprint((0.3, 0.2, height, 0.4, u, -0.5, 0.0), (1.0, -2.0))

    run()


def _on_ramp(tilt: float, width: float, height: float) -> str:
    """A ramp rising along x at ``tilt`` about y, and a width x width x height box of uniform density lying on its
    top face; the box's Solid origin is 3 m aside, over no ground (it stays as the file puts it)."""
    n = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])                # the ramp's top face's normal
    centre = np.array([0.0, 0.0, 0.5]) + (0.05 + height / 2.0) * n
    origin = np.array([0.0, 3.0 + width, 0.5])
    at = " ".join(_r(v) for v in centre - origin)
    return (f'Solid {{ translation 0 0 0.5 rotation 0 1 0 {_r(-tilt)} name "ramp" '
            'boundingObject Box { size 6 6 0.1 } }\n'
            f'DEF BOX Solid {{ translation {" ".join(_r(v) for v in origin)} name "box" '
            f'boundingObject Pose {{ translation {at} rotation 0 1 0 {_r(-tilt)} children [ Box {{ size {_r(width)} '
            f'{_r(width)} {_r(height)} }} ] }} physics Physics {{ }} }}\n')


@pytest.mark.parametrize("examples", example_counts(120))
def test_a_box_on_a_ramp_is_balanced_iff_tan_tilt_is_at_most_width_over_height(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(st.floats(0.01, 1.0), st.floats(0.01, 1.0), st.floats(0.01, 0.78))   # ramps lean up to 45° (README)
    def run(width, height, tilt):
        width, height, tilt = round(width, 12), round(height, 12), round(tilt, 12)
        # the centre is (h/2) sin θ downhill of the footprint's middle, which reaches (w/2) cos θ
        margin = width / 2.0 * math.cos(tilt) - height / 2.0 * math.sin(tilt)
        assume(abs(margin) > EDGE)
        lv = _live(HEAD + _on_ramp(tilt, width, height) + SUPERVISOR)
        assert _sup(lv, "get_node_static_balance", {"node": _node(lv, "BOX")})["value"] is (margin > 0), \
            (math.tan(tilt), width / height)

    run()


@pytest.mark.parametrize("height", [0.3, 0.001, 0.0005])
@pytest.mark.parametrize("flip", [False, True])
def test_a_standing_disc_touches_at_its_lower_end_s_centre_and_rim_only(height: float, flip: bool) -> None:
    # a cylinder standing on an end: that end's centre and its 32 rim points (README), on the floor; a disc 1 mm
    # thick or less has its upper end within the 1 mm tolerance too, and that end touches nothing
    turn = " rotation 1 0 0 3.141592653589793" if flip else ""
    lv = _live(HEAD + FLOOR + f'DEF DISC Solid {{ translation 2 3 {_r(height / 2.0)}{turn} name "disc" '
               f'boundingObject Cylinder {{ radius 0.2 height {_r(height)} }} physics Physics {{ }} }}\n' + SUPERVISOR)
    disc = _node(lv, "DISC")
    got = _sup(lv, "get_node_contact_points", {"node": disc, "include_descendants": False})
    points = np.array(got["points"]).reshape(-1, 3)
    assert got["nodes"] == [disc] * 33
    assert np.abs(points[:, 2]).max() <= 1e-15
    radii = np.sort(np.hypot(points[:, 0] - 2.0, points[:, 1] - 3.0))
    assert radii[0] <= 1e-15 and radii[1:] == pytest.approx([0.2] * 32, abs=1e-15)
    assert _sup(lv, "get_node_static_balance", {"node": disc})["value"] is True


number = st.floats(-1e3, 1e3, allow_subnormal=False).map(lambda v: round(v, 9))
positive = st.floats(0.001, 100.0).map(lambda v: round(v, 9))
unit = st.floats(0.0, 1.0).map(lambda v: round(v, 6))


def _vec(n: int, part=number):
    return st.lists(part, min_size=n, max_size=n).map(lambda vs: " ".join(_r(v) for v in vs))


geometry = st.one_of(
    _vec(3, positive).map(lambda s: f"Box {{ size {s} }}"),
    st.tuples(positive, st.integers(1, 5)).map(lambda a: f"Sphere {{ radius {_r(a[0])} subdivision {a[1]} }}"),
    st.tuples(positive, positive, st.integers(3, 40), st.booleans()).map(
        lambda a: f"Cylinder {{ radius {_r(a[0])} height {_r(a[1])} subdivision {a[2]} top {'TRUE' if a[3] else 'FALSE'} }}"),
    st.tuples(positive, positive).map(lambda a: f"Capsule {{ radius {_r(a[0])} height {_r(a[1])} }}"),
    st.tuples(positive, positive).map(lambda a: f"Cone {{ bottomRadius {_r(a[0])} height {_r(a[1])} }}"))
appearance = st.one_of(
    st.just(""),
    st.tuples(_vec(3, unit), unit, unit).map(
        lambda a: f"appearance PBRAppearance {{ baseColor {a[0]} roughness {_r(a[1])} metalness {_r(a[2])} }} "),
    st.tuples(_vec(3, unit), unit).map(
        lambda a: f"appearance Appearance {{ material Material {{ diffuseColor {a[0]} transparency {_r(a[1])} }} }} "))
shape = st.tuples(appearance, geometry).map(lambda a: f"Shape {{ {a[0]}geometry {a[1]} }}")
rotation = st.tuples(_vec(3, st.floats(0.1, 1.0).map(lambda v: round(v, 6))), st.floats(-3.0, 3.0).map(lambda v: round(v, 9)))


def _group(children: st.SearchStrategy) -> st.SearchStrategy:
    kids = st.lists(children, max_size=3).map(" ".join)
    return st.one_of(
        st.tuples(_vec(3), rotation, kids).map(
            lambda a: f"Pose {{ translation {a[0]} rotation {a[1][0]} {_r(a[1][1])} children [ {a[2]} ] }}"),
        st.tuples(_vec(3), _vec(3, positive), kids).map(
            lambda a: f"Transform {{ translation {a[0]} scale {a[1]} children [ {a[2]} ] }}"))


node_tree = st.recursive(shape, _group, max_leaves=6)
solids = st.tuples(_vec(3), rotation, st.text("abcxyz _-", min_size=1, max_size=8), st.lists(node_tree, max_size=3),
                   st.one_of(st.just(""), geometry.map(lambda g: f"boundingObject {g} ")),
                   st.one_of(st.just(""), st.tuples(positive, _vec(3)).map(
                       lambda a: f"physics Physics {{ density -1 mass {_r(a[0])} centerOfMass [ {a[1]} ] }} "))).map(
    lambda a: (f'Solid {{ translation {a[0]} rotation {a[1][0]} {_r(a[1][1])} name "{a[2]}" children [ {" ".join(a[3])} ] '
               f'{a[4]}{a[5]}}}'))


@pytest.mark.parametrize("examples", example_counts(160))
def test_an_exported_solid_imported_again_exports_the_same_text(examples: int) -> None:
    @settings(SETTINGS, max_examples=examples)
    @given(solids)
    def run(solid):
        # no ground: nothing lands, so the copy stands where the first did; a world of its own (names once
        # imported stay taken: a copy in a used world is renamed "name(1)")
        empty = _live(HEAD + SUPERVISOR)
        lv = _live(HEAD + "DEF FIRST " + solid + "\n" + SUPERVISOR)
        first = _sup(lv, "node_export_string", {"node": _node(lv, "FIRST")})["value"]
        [again] = _sup(empty, "import_node_from_string", {"node": 0, "field": "children", "position": -1,
                                                           "node_string": first})["value"]
        assert _sup(empty, "node_export_string", {"node": again})["value"] == first

    run()


@pytest.mark.parametrize("examples", example_counts(80))
def test_a_box_reset_at_any_steps_falls_from_rest_at_each_reset_and_lands_on_the_floor(examples: int) -> None:
    """resetPhysics (sim/falling.py Falls.stop) at random steps of a fall from a random height: between resets the
    box's centre is at z_r - g (t - t_r)^2 / 2 (z_r its height at the last reset t_r, the lift a reset at 0); from
    the first step whose end is past the remaining drop's time it rests with its bottom on the floor (z = 0.05)."""
    from test_reset_physics import STEP, G, _lift, _node, _reset, _world

    @settings(SETTINGS, max_examples=examples)
    @given(st.floats(0.06, 30.0).map(lambda v: round(v, 9)), st.lists(st.integers(1, 400), max_size=4, unique=True))
    def run(height, resets):
        sim = _world()
        _lift(sim, [0.3, -0.2, height])
        z_r, k_r, landed = height, 0, False
        for k in range(1, 500):
            if k - 1 in resets and not landed:
                _reset(sim, _node(sim))
                z_r, k_r = sim.scene.solid_poses["load"].translation[2], k - 1
            sim.step()
            t = (k - k_r) * STEP / 1000.0
            closed = z_r - G * t * t / 2.0
            z = sim.scene.solid_poses["load"].translation
            assume(abs(closed - 0.05) > 1e-9)        # (touching within rounding: either answer is right)
            if closed > 0.05:
                assert z.tolist() == pytest.approx([0.3, -0.2, closed], abs=1e-9 * max(height, 1.0)), (k, resets)
            else:
                assert z.tolist() == pytest.approx([0.3, -0.2, 0.05], abs=1e-12), (k, resets)
                assert not sim.falls
                landed = True
                break
        assert landed

    run()


@pytest.mark.parametrize(("shape", "count"), [("Sphere { radius 0.1 }", 1), ("Cylinder { radius 0.1 height 0.2 }", 33),
                                              ("Capsule { radius 0.1 height 0.2 }", 1)])
def test_a_shape_on_a_table_touches_at_each_point_once(shape: str, count: int) -> None:
    # standing (a capsule upright: its lower end's lowest point), its lowest points on the table's top at z = 0.5
    half = {"Sphere": 0.1, "Cylinder": 0.1, "Capsule": 0.2}[shape.split()[0]]
    lv = _live(HEAD + _table((2.0, 1.0)) + f'DEF S Solid {{ translation 2.3 0.8 {_r(0.5 + half)} name "s" '
               f'boundingObject {shape} physics Physics {{ }} }}\n' + SUPERVISOR)
    s = _node(lv, "S")
    got = _sup(lv, "get_node_contact_points", {"node": s, "include_descendants": False})
    points = np.array(got["points"]).reshape(-1, 3)
    assert got["nodes"] == [s] * count and len({(x, y) for x, y, _ in points}) == count
    assert np.abs(points[:, 2] - 0.5).max() <= 1e-15
    radii = np.sort(np.hypot(points[:, 0] - 2.3, points[:, 1] - 0.8))       # its centre's, then its rim's
    assert radii.tolist() == pytest.approx([0.0] + [0.1] * (count - 1), abs=1e-15)
