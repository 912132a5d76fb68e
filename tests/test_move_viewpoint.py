"""Webots' ``Node.moveViewpoint()`` (README "Supervisor"): the Viewpoint keeps its orientation and moves
back from the node's bounding-sphere centre c along its view direction f (+x of its frame) to
``c − d·f``, ``d = 1.05 r / (sin(Φ/2)·min(a, 1/a))`` (a = 640/480, the exportImage picture's aspect),
at least ``near + 1.05 r`` (WbViewpoint::moveViewpointToObject); at once here, where Webots animates
it over about a second. tests/worlds/move_viewpoint.wbt: the Viewpoint at the origin looks along +y
(Φ = π/4); a white ball r = 0.5 at (2, 3, 1); two balls r = 0.5 at ±1 m along x of a solid at
(−4, 6, 0.5) turned 0.3 rad about z (one sphere of radius 1.5 about the solid's origin); a Solid
without shapes; a Solid without shapes inside the ball's (its nearest ancestor with shapes: the ball)."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.server.sim import viewshot
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "move_viewpoint.wbt"
BOSS, BALL, PAIR, EMPTY, VIEWPOINT = 1, 2, 3, 4, 7         # node ids (world order, then the scenery)
FOV = math.pi / 4
ASPECT = min(640 / 480, 480 / 640)


def distance(radius: float, near: float = 0.05) -> float:
    r = 1.05 * radius
    return max(r / (math.sin(FOV / 2) * ASPECT), near + r)


def _live() -> Live:
    lv = Live(Simulation(load_world(WORLD)))
    lv.ok(A, "attach", {"robot": "boss"})
    return lv


def boss(lv: Live, item: str, args: dict) -> dict:
    return lv.ok(A, f"/boss/robot/{item}", args)


def position(lv: Live) -> list[float]:
    return boss(lv, "get_field", {"node": VIEWPOINT, "field": "position"})["value"]


def test_the_viewpoint_backs_off_from_the_ball_along_its_view_direction():
    lv = _live()
    assert boss(lv, "move_viewpoint", {"node": BALL}) == {"success": True}
    np.testing.assert_allclose(position(lv), [2.0, 3.0 - distance(0.5), 1.0], atol=1e-12)
    orientation = boss(lv, "get_field", {"node": VIEWPOINT, "field": "orientation"})["value"]
    assert orientation == [0.0, 0.0, 1.0, math.pi / 2]       # kept
    assert boss(lv, "move_viewpoint", {"node": BALL}) == {"success": True}     # again: the same place
    np.testing.assert_allclose(position(lv), [2.0, 3.0 - distance(0.5), 1.0], atol=1e-12)


def test_after_the_move_the_picture_shows_the_ball_centred_at_its_closed_form_size():
    lv = _live()
    W, H = viewshot.EXPORT_SIZE
    before = viewshot.render(lv.sim, W, H)
    assert not before[H // 2 - 60:H // 2 + 60, W // 2 - 60:W // 2 + 60].any()     # the ball is far off the centre
    boss(lv, "move_viewpoint", {"node": BALL})
    img = viewshot.render(lv.sim, W, H)
    lit = img.any(axis=-1)
    # the ball's silhouette: a disc of radius f·tan(asin(r/d)), f = (W/2)/tan(Φ/2), about the centre
    rho = (W / 2) / math.tan(FOV / 2) * math.tan(math.asin(0.5 / distance(0.5)))
    rows, cols = np.nonzero(lit)
    assert abs((cols.min() + cols.max() + 1) / 2 - W / 2) <= 1 and abs((rows.min() + rows.max() + 1) / 2 - H / 2) <= 1
    assert abs((cols.max() + 1 - cols.min()) / 2 - rho) <= 1.5 and abs((rows.max() + 1 - rows.min()) / 2 - rho) <= 1.5
    assert rho < H / 2 / 1.05 + 1                             # the 1.05 r sphere fits the picture's height


def test_the_bounding_sphere_merges_the_shapes_and_a_nested_node_uses_its_own():
    lv = _live()
    boss(lv, "move_viewpoint", {"node": PAIR})                # the pair: radius 1.5 about the solid's origin
    np.testing.assert_allclose(position(lv), [-4.0, 6.0 - distance(1.5), 0.5], atol=1e-9)
    first = boss(lv, "get_field", {"node": PAIR, "field": "children"})["value"][0]
    boss(lv, "move_viewpoint", {"node": first})               # its Pose at x = 1 of the turned solid: one ball
    c = np.array([-4.0 + math.cos(0.3), 6.0 + math.sin(0.3), 0.5])
    np.testing.assert_allclose(position(lv), c - [0.0, distance(0.5), 0.0], atol=1e-9)


def test_a_node_without_shapes_leaves_the_viewpoint_or_frames_its_ancestor_and_reset_restores_it():
    lv = _live()
    for node in (EMPTY, BOSS):                                # Webots: an empty bounding sphere, no move
        assert boss(lv, "move_viewpoint", {"node": node}) == {"success": True}
        assert position(lv) == [0.0, 0.0, 0.0]
    boss(lv, "move_viewpoint", {"node": BALL})
    text = boss(lv, "node_export_string", {"node": VIEWPOINT})["value"]        # exportString writes where it went
    [line] = [ln.split()[1:] for ln in text.splitlines() if ln.split()[:1] == ["position"]]
    np.testing.assert_allclose([float(c) for c in line], [2.0, 3.0 - distance(0.5), 1.0], atol=1e-12)
    mark = boss(lv, "get_field", {"node": BALL, "field": "children"})["value"][1]
    boss(lv, "simulation_reset", {})
    assert position(lv) == [0.0, 0.0, 0.0]
    boss(lv, "move_viewpoint", {"node": mark})                # inside the ball's solid: its nearest sphere, the ball's
    np.testing.assert_allclose(position(lv), [2.0, 3.0 - distance(0.5), 1.0], atol=1e-12)
    boss(lv, "simulation_reset", {})
    assert position(lv) == [0.0, 0.0, 0.0]
    assert not viewshot.render(lv.sim, 64, 48)[24].any()       # the centre row: sky again


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_python_supervisor_moves_the_viewpoint(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "supervisor_move_viewpoint.py", "boss")
    assert ctl.out == ["before 0.000 0.000 0.000", f"after 2.000 {3 - distance(0.5):.3f} 1.000",
                       "reset 0.000 0.000 0.000"]
    assert "Error" not in ctl.stderr(), ctl.stderr()


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_moves_the_viewpoint_the_same_way(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller
    from test_supervisor_proto_fields import SAN_ENV

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_move_viewpoint.c")
    ctl = run_paused(WORLD, tmp_path, exe, "boss", env=SAN_ENV)
    assert ctl.out == ["before 0.000 0.000 0.000", f"after 2.000 {3 - distance(0.5):.3f} 1.000",
                       "reset 0.000 0.000 0.000"]
    assert "Error" not in ctl.stderr() and "Sanitizer" not in ctl.stderr(), ctl.stderr()


def test_a_world_without_viewpoint_saves_the_moved_one_and_loads_it_back(tmp_path):
    """Webots adds a default Viewpoint (at -10 0 0, looking along +x) to a file without one; moved by
    moveViewpoint, worldSave writes where it went (its orientation, the default, left out) and the saved
    world loads with the Viewpoint there: in front of the ball r = 0.5 at (2, 0, 1), d back along +x."""
    from sensorium.server.daemon.export import world_string

    path = tmp_path / "bare.wbt"
    path.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n'
                    'Robot { name "boss" supervisor TRUE controller "<extern>" }\n'
                    'DEF BALL Solid { translation 2 0 1 children [ Shape { geometry Sphere { radius 0.5 } } ] }\n')
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "boss"})
    assert "Viewpoint {\n}" in world_string(lv.sim)                       # not moved: Webots' empty node
    ball = boss(lv, "get_from_def", {"name": "BALL"})["node"]
    assert boss(lv, "move_viewpoint", {"node": ball}) == {"success": True}
    moved = viewshot.viewpoint_of(lv.sim).position
    np.testing.assert_allclose(moved, [2.0 - distance(0.5), 0.0, 1.0], atol=1e-6)   # the tessellated ball's sphere
    saved = tmp_path / "saved.wbt"
    saved.write_text(world_string(lv.sim))
    text = saved.read_text()
    assert "Viewpoint {\n  position " in text and "orientation" not in text
    again = viewshot.viewpoint_of(Simulation(load_world(saved)))
    assert tuple(again.position) == tuple(moved)                           # every bit: the shortest text of each
    assert tuple(again.orientation) == (0.0, 0.0, 1.0, 0.0)
    lv.sim.reset()                                                          # the reset: the added one as loaded
    assert "Viewpoint {\n}" in world_string(lv.sim)
