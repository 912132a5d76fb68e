"""The Supervisor's getContactPoints (sim/balance.py's contact points, daemon/supervisor.py's
``contact_points``): where a top-level solid's or robot's bounding shapes touch the ground now, in world
coordinates, each with the id of the Solid touching there, against closed forms: a turned box's four
bottom corners, a sphere's one point, a two-wheel robot's wheel rims and caster (its descendants) and
nothing of its own body, a box in the air, on a table, in a NUE world. Webots' C ``simulation_revert``
(its worldReload) is in tests/test_run.py."""

from __future__ import annotations

import math
import shutil
import subprocess

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HEAD = "#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
FLOOR = 'Solid { name "floor" boundingObject Plane { size 40 40 } }\n'
SUPERVISOR = 'Robot { translation 9 9 0 name "sup" supervisor TRUE controller "<extern>" }\n'
TURN = 0.4          # rad about z: the turned box's yaw

WORLD = (HEAD + FLOOR
         + f'DEF BOX Solid {{ translation 1 2 0.05 rotation 0 0 1 {TURN!r} name "box" boundingObject Box {{ size 0.2 0.1 0.1 }} '
         'physics Physics { } }\n'
         + 'DEF BALL Solid { translation 3 0 0.05 name "ball" boundingObject Sphere { radius 0.05 } physics Physics { } }\n'
         + 'DEF BARE Solid { translation 4 0 0.05 name "bare" boundingObject Box { size 0.1 0.1 0.1 } }\n'
         + 'DEF HOLDER Solid { translation 6 0 0.1 name "holder" children [ DEF INNER Solid { translation 0.3 0 -0.05 '
         'name "inner" boundingObject Sphere { radius 0.05 } } ] boundingObject Box { size 0.1 0.1 0.2 } '
         'physics Physics { } }\n'
         + 'DEF CART Robot { translation 0 5 0 rotation 0 0 1 1.5707963267948966 name "cart" children [ '
         + "".join(f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {s}0.1 0.05 }} '
                   f'device [ RotationalMotor {{ name "{side} wheel" }} ] endPoint DEF {side.upper()} Solid {{ translation 0 {s}0.1 0.05 '
                   f'rotation 1 0 0 1.5707963267948966 name "{side}" boundingObject Cylinder {{ radius 0.05 height 0.02 }} }} }} '
                    for s, side in (("", "left"), ("-", "right")))
         + 'DEF CASTER Solid { translation -0.1 0 0.02 name "caster" boundingObject Sphere { radius 0.02 } } ] '
         'boundingObject Pose { translation 0 0 0.1 children [ Box { size 0.1 0.1 0.05 } ] } '
         'physics Physics { mass 1 centerOfMass [ -0.03 0 0.05 ] } }\n'
         + SUPERVISOR)


def _live(text: str, tmp_path) -> Live:
    path = tmp_path / "w.wbt"
    path.write_text(text)
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "sup"})
    return lv


def sup(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/sup/robot/{item}", args)


def node(lv: Live, name: str) -> int:
    return sup(lv, "get_from_def", {"name": name})["node"]


def contacts(lv: Live, name: str, descendants: bool = False) -> tuple[np.ndarray, list[int]]:
    got = sup(lv, "get_node_contact_points", {"node": node(lv, name), "include_descendants": descendants})
    return np.array(got["points"]).reshape(-1, 3), got["nodes"]


def _sorted(points) -> list[tuple[float, ...]]:
    return sorted(tuple(round(float(v), 12) + 0.0 for v in p) for p in points)


def test_a_turned_box_touches_at_its_four_bottom_corners(tmp_path):
    lv = _live(WORLD, tmp_path)
    points, ids = contacts(lv, "BOX")
    c, s = math.cos(TURN), math.sin(TURN)
    corners = [(1 + c * x - s * y, 2 + s * x + c * y, 0.0) for x in (-0.1, 0.1) for y in (-0.05, 0.05)]
    assert _sorted(points) == _sorted(corners)
    assert ids == [node(lv, "BOX")] * 4
    assert contacts(lv, "BOX", True)[1] == ids                  # nothing inside it


def test_a_sphere_touches_at_one_point_and_a_nested_solid_is_named(tmp_path):
    lv = _live(WORLD, tmp_path)
    points, ids = contacts(lv, "BALL")
    assert points.tolist() == [[3.0, 0.0, 0.0]] and ids == [node(lv, "BALL")]
    points, ids = contacts(lv, "HOLDER")                        # its own box's corners
    assert _sorted(points) == _sorted([(6 + x, y, 0.0) for x in (-0.05, 0.05) for y in (-0.05, 0.05)])
    points, ids = contacts(lv, "HOLDER", True)                  # and its inner ball, 0.3 m aside
    assert points[-1].tolist() == pytest.approx([6.3, 0.0, 0.0], abs=1e-15)
    assert ids == [node(lv, "HOLDER")] * 4 + [node(lv, "INNER")]


def test_a_two_wheel_robot_touches_with_its_wheels_and_caster_only(tmp_path):
    lv = _live(WORLD, tmp_path)
    points, ids = contacts(lv, "CART")
    assert points.shape == (0, 3) and ids == []                 # its own body is 0.075 m up
    points, ids = contacts(lv, "CART", True)
    # turned 90° about z at (0, 5): its y is the world's -x; each wheel's rim bottom at its two ends
    # (0.02 m wide), the caster's ball under its centre
    left, right, caster = (node(lv, n) for n in ("LEFT", "RIGHT", "CASTER"))
    got = sorted((tuple(round(float(v), 12) + 0.0 for v in p), n) for p, n in zip(points, ids, strict=True))
    assert got == sorted([((-0.09, 5.0, 0.0), left), ((-0.11, 5.0, 0.0), left), ((0.09, 5.0, 0.0), right),
                          ((0.11, 5.0, 0.0), right), ((0.0, 4.9, 0.0), caster)])


def test_a_driven_robot_s_contacts_move_with_it(tmp_path):
    lv = _live(WORLD, tmp_path)
    before, ids = contacts(lv, "CART", True)
    robot = lv.sim.robot("cart")
    for name in ("left wheel", "right wheel"):          # straight ahead, along the world's +y
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(4.0)
    for _ in range(10):
        lv.step(A, "sup")
    moved = np.array(sup(lv, "get_node_pose", {"node": node(lv, "CART")})["position"]) - [0.0, 5.0, 0.0]
    assert moved[1] > 0.02 and abs(moved[0]) < 1e-12 and moved[2] == 0.0
    after, same_ids = contacts(lv, "CART", True)
    assert same_ids == ids
    assert after == pytest.approx(before + moved, abs=1e-12)


def test_in_the_air_without_physics_or_no_top_solid(tmp_path):
    lv = _live(WORLD, tmp_path)
    assert contacts(lv, "BARE", True)[1] == []                  # no Physics: Webots' ODE makes no contact for it
    box = node(lv, "BOX")
    sup(lv, "set_field", {"node": box, "field": "translation", "value": [1.0, 2.0, 0.0511]})
    assert contacts(lv, "BOX")[1] == []                         # 1.1 mm up: beyond the 1 mm tolerance
    sup(lv, "set_field", {"node": box, "field": "translation", "value": [1.0, 2.0, 0.0509]})
    assert len(contacts(lv, "BOX")[1]) == 4                     # 0.9 mm up: touching
    for target in (node(lv, "INNER"), node(lv, "LEFT"), 0):
        message = lv.err(A, "/sup/robot/get_node_contact_points", {"node": target}, ErrorCode.INVALID_ARGUMENT)
        assert "exclusively be used with a top Solid" in message


SHELF = (HEAD + FLOOR
         + 'DEF SHELF Solid { translation 2 1 0.5 name "shelf" boundingObject Box { size 0.2 0.2 0.2 } children [ '
         'DEF PUCK Solid { translation 0.5 0 -0.45 name "puck" boundingObject Sphere { radius 0.05 } physics Physics { } '
         'children [ DEF PIN Solid { translation 0 0.3 -0.02 name "pin" boundingObject Sphere { radius 0.03 } } ] } '
         'DEF PEG Solid { translation -0.5 0 -0.45 name "peg" boundingObject Sphere { radius 0.05 } } ] }\n'
         + SUPERVISOR)


def test_a_static_solid_touches_through_its_nested_solids_with_physics(tmp_path):
    """Webots counts, with descendants, every contact of a body whose top solid is the one asked: a static
    shelf's nested puck with Physics (and the pin merged into the puck's body) touch the floor, the shelf's
    own box and its static peg never (ODE makes no contact between static geometries)."""
    lv = _live(SHELF, tmp_path)
    assert contacts(lv, "SHELF") == (pytest.approx(np.zeros((0, 3))), [])
    points, ids = contacts(lv, "SHELF", True)
    got = sorted((tuple(round(float(v), 12) + 0.0 for v in p), n) for p, n in zip(points, ids, strict=True))
    assert got == sorted([((2.5, 1.0, 0.0), node(lv, "PUCK")), ((2.5, 1.3, 0.0), node(lv, "PIN"))])


# a robot without Physics: its own box rests on the floor, a static foot beside it; its DEF ARM Solid with
# Physics holds a box on the floor and, merged into its body, a HAND Solid without Physics holding a sphere
ROVER = (HEAD + FLOOR
         + 'DEF ROVER Robot { translation 2 3 0 name "rover" boundingObject Pose { translation 0 0 0.05 children [ '
         'Box { size 0.1 0.1 0.1 } ] } children [ '
         'DEF FOOT Solid { translation 0 -0.5 0.05 name "foot" boundingObject Box { size 0.1 0.1 0.1 } } '
         'DEF ARM Solid { translation 0.5 0 0.05 name "arm" boundingObject Box { size 0.2 0.1 0.1 } physics Physics { } '
         'children [ DEF HAND Solid { translation 0 0.3 -0.02 name "hand" boundingObject Sphere { radius 0.03 } } ] } ] }\n'
         + SUPERVISOR)


def test_a_robot_without_physics_touches_through_its_nested_solids_with_physics(tmp_path):
    """Webots: a robot without Physics is static geometry (no contact with the floor, its static FOOT neither),
    but its nested ARM with Physics is a body, the HAND merged into it: with descendants their contacts are the
    robot's, named by the ids getFromDef gives them; the ARM's box's four bottom corners, the HAND's lowest point."""
    lv = _live(ROVER, tmp_path)
    assert contacts(lv, "ROVER") == (pytest.approx(np.zeros((0, 3))), [])
    points, ids = contacts(lv, "ROVER", True)
    arm, hand = node(lv, "ARM"), node(lv, "HAND")
    got = sorted((tuple(round(float(v), 12) + 0.0 for v in p), n) for p, n in zip(points, ids, strict=True))
    assert got == sorted([((2.5 + x, 3.0 + y, 0.0), arm) for x in (-0.1, 0.1) for y in (-0.05, 0.05)]
                         + [((2.5, 3.3, 0.0), hand)])
    assert sup(lv, "get_from_id", {"id": arm})["name"] == "arm"
    assert sup(lv, "get_from_id", {"id": hand})["name"] == "hand"


PAIR = (HEAD + FLOOR + "".join(
    f'DEF {top} Solid {{ translation {x} 0 0.5 name "{top.lower()}" children [ '
    f'DEF {top}_A Solid {{ translation 0.3 0 -0.45 name "a" boundingObject Sphere {{ radius 0.05 }} physics Physics {{ }} '
    f'children [ DEF {top}_B Solid {{ translation 0 0.3 -0.02 name "b" boundingObject Sphere {{ radius 0.03 }} }} ] }} '
    f'DEF {top}_C Solid {{ translation -0.3 0 -0.45 name "c" boundingObject Sphere {{ radius 0.05 }} physics Physics {{ }} }} ] }}\n'
    for top, x in (("LEFT", 1), ("RIGHT", 3))) + SUPERVISOR)


def test_nested_solids_are_named_by_the_ids_the_nested_table_gave_them_in_every_top_and_an_import(tmp_path):
    """Two static tops with the same nested tree, then a third imported: each contact names the solid
    getFromDef finds (its own top's, never the other's), an imported top's from the ids its import gave."""
    lv = _live(PAIR, tmp_path)

    def named(top: str) -> dict[tuple[float, ...], int]:
        points, ids = contacts(lv, top, True)
        return {tuple(round(float(v), 12) + 0.0 for v in p): n for p, n in zip(points, ids, strict=True)}

    for top, x in (("LEFT", 1.0), ("RIGHT", 3.0)):
        assert named(top) == {(x + 0.3, 0.0, 0.0): node(lv, f"{top}_A"), (x + 0.3, 0.3, 0.0): node(lv, f"{top}_B"),
                              (x - 0.3, 0.0, 0.0): node(lv, f"{top}_C")}
    text = PAIR.splitlines()[3].replace("LEFT", "THIRD").replace('"third"', '"third"').replace("translation 1 0 0.5",
                                                                                              "translation 5 0 0.5")
    sup(lv, "import_node_from_string", {"node": 0, "field": "children", "position": -1, "node_string": text})
    assert named("THIRD") == {(5.3, 0.0, 0.0): node(lv, "THIRD_A"), (5.3, 0.3, 0.0): node(lv, "THIRD_B"),
                              (4.7, 0.0, 0.0): node(lv, "THIRD_C")}
    assert len({node(lv, f"{t}_A") for t in ("LEFT", "RIGHT", "THIRD")}) == 3


TABLE = (HEAD + 'Solid { translation 0 0 0.25 name "table" boundingObject Box { size 1 1 0.5 } }\n'
         + 'DEF PLANK Solid { translation 0.4 0 0.525 name "plank" boundingObject Box { size 0.4 0.1 0.05 } '
         'physics Physics { } }\n' + SUPERVISOR)


def test_a_plank_over_a_table_edge_touches_up_to_the_edge(tmp_path):
    lv = _live(TABLE, tmp_path)
    points, _ = contacts(lv, "PLANK")
    # x in [0.2, 0.6] over a top reaching x = 0.5: its two corners on the table and the edge's crossing
    assert set(_sorted(points)) == {(0.2, -0.05, 0.5), (0.2, 0.05, 0.5), (0.5, -0.05, 0.5), (0.5, 0.05, 0.5)}


NUE = ('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 coordinateSystem "NUE" }\n'
       'Solid { rotation 1 0 0 -1.5707963267948966 name "floor" boundingObject Plane { size 20 20 } }\n'
       'DEF BALL Solid { translation 1 0.05 2 name "ball" boundingObject Sphere { radius 0.05 } physics Physics { } }\n'
       + SUPERVISOR.replace("translation 9 9 0", "translation 9 0 9"))


def test_a_nue_world_gives_points_in_its_own_axes(tmp_path):
    lv = _live(NUE, tmp_path)
    points, _ = contacts(lv, "BALL")
    assert points.tolist() == [[1.0, 0.0, 2.0]]                 # y is the up: the point under the centre


E2E = REPO / "tests" / "worlds" / "contact_points.wbt"
EXPECTED = ["box 4", "0.9500 -0.0500 0.0000 BOX", "0.9500 0.0500 0.0000 BOX", "1.0500 -0.0500 0.0000 BOX",
            "1.0500 0.0500 0.0000 BOX", "ball 1", "3.0000 0.0000 0.0000 BALL", "cart own 0", "cart all 5",
            "0.0000 2.0900 0.0000 LEFT", "0.0000 2.1100 0.0000 LEFT", "0.0000 1.8900 0.0000 RIGHT",
            "0.0000 1.9100 0.0000 RIGHT", "-0.1000 2.0000 0.0000 CASTER", "count 5 0",
            "last -0.1000 2.0000 0.0000 CASTER", "past nan nan nan None", "air 0", "same step 4", "next step 0", "root 0"]
DEPRECATED = [f"Warning: wb_supervisor_node_{f}() is deprecated, use wb_supervisor_node_get_contact_points() instead."
              for f in ("get_number_of_contact_points", "get_contact_point", "get_contact_point_node")]
ROOT_LINE = "it can exclusively be used with a top Solid, not the root"


@pytest.mark.slow
def test_a_python_controller_reads_the_contact_points(tmp_path):
    ctl = run_paused(E2E, tmp_path, "contact_points.py", "sup")
    assert ctl.out == EXPECTED
    err = ctl.stderr().splitlines()
    assert [line for line in err if "deprecated" in line] == DEPRECATED
    assert any(line.startswith("Error: wb_supervisor_node_get_contact_points(): ") and ROOT_LINE in line for line in err)


@pytest.mark.slow
def test_a_c_controller_reads_the_contact_points(tmp_path_factory):
    from test_c_client import sanitized_run

    code, out, err = sanitized_run(tmp_path_factory, REPO / "tests" / "c" / "contact_points.c", E2E, "sup")
    assert code == 0, err
    assert out == EXPECTED
    assert [line for line in err.splitlines() if "deprecated" in line] == DEPRECATED
    assert "Error: wb_supervisor_node_get_contact_points(): " in err and ROOT_LINE in err


@pytest.mark.slow
def test_a_cpp_controller_reads_the_contact_points(tmp_path_factory):
    """Our C++ layer (webots::Node::getContactPoints and the deprecated per-index methods) over the same C calls."""
    from _serve import serve
    from test_c_client import CLIB, SAN_ENV, TESTS_C, _make, finish, start

    if shutil.which("c++") is None:
        pytest.skip("needs a C++ toolchain")
    build = tmp_path_factory.mktemp("cppbuild")
    _make(f"BUILD={build}", "SANITIZE=1")
    exe = build / "contact_points_cpp"
    done = subprocess.run(["c++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
                           f"-I{CLIB / 'include'}", str(TESTS_C / "contact_points_cpp.cpp"), "-o", str(exe),
                           str(build / "libController.a"), *_make("libs").split()],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    with serve(E2E, env=SAN_ENV) as server:
        code, out, err = finish(start([str(exe)], server.url("sup")))
    assert code == 0, err
    assert out == EXPECTED
    assert "Error: wb_supervisor_node_get_contact_points(): " in err and ROOT_LINE in err


@pytest.mark.parametrize("node", [None, -1, True, 1.0, 1 << 31, 1 << 64, 1 << 70])
def test_a_node_argument_that_is_no_id_is_one_line_and_asks_the_server_nothing(monkeypatch, capsys, node) -> None:
    """Every node function's check (contact points, balance, resetPhysics among them): an id is a
    non-negative 32-bit whole number; past 64 bits the request could not even be packed."""
    from test_movie import _FakeSupervisor

    from sensorium.client import wb_supervisor as ws
    fake = _FakeSupervisor()
    monkeypatch.setattr(ws, "_supervisor", lambda func: fake)
    for func, call in (("wb_supervisor_node_get_contact_points", lambda: ws.wb_supervisor_node_get_contact_points(node)),
                       ("wb_supervisor_node_get_static_balance", lambda: ws.wb_supervisor_node_get_static_balance(node)),
                       ("wb_supervisor_node_reset_physics", lambda: ws.wb_supervisor_node_reset_physics(node))):
        assert call() in ([], False, None)
        assert capsys.readouterr().err == f"Error: {func}() called with a NULL or invalid 'node' argument.\n"
    assert fake.calls == []
