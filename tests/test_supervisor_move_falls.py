"""A top-level solid with physics that a Supervisor moves into the air falls from there (sim/falling.py),
in closed form.

A 0.1 m box with physics rests on a floor plane at z = 0 (its centre at 0.05). A Supervisor sets its
translation to (0.2, 0.1, Z0 = 0.55) (its bottom H = 0.5 m up) at simulated time t0: after k steps of 16 ms its
centre is at Z0 − g·(0.016 k)²/2 (x, y, rotation kept) and its velocity −g·0.016 k along z, and from the
first step whose end is past sqrt(2H/g) (the 20th) it rests at exactly ground.land_solid's pose for the
pose it was put at. Moved again mid-fall, it falls from rest from the new pose. Without physics it stays."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.daemon.supervisor import node_by_id, node_velocity, set_field
from sensorium.server.sim.ground import land_solid
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

STEP = 16
H = 0.5                   # m: the box's bottom over the floor where it is put
Z0 = H + 0.05             # its centre
G = 9.81
REPO = Path(__file__).resolve().parents[1]


def _world(physics: bool = True, nue: bool = False) -> Simulation:
    floor = {"name": "floor", "geometry": {"type": "plane"}}
    box = {"name": "load", "pose": {"translation": [0.0, 0.05, 0.0] if nue else [0.0, 0.0, 0.05]},
           "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}, "physics": physics}
    if nue:
        floor["pose"] = {"rotation": [1, 0, 0, -math.pi / 2]}
    info = {"basic_time_step": STEP, **({"coordinate_system": "NUE"} if nue else {})}
    sim = Simulation(parse_world({"world_info": info, "solids": [floor, box]}), precision="exact")
    sim.step()
    return sim


def _node(sim: Simulation) -> object:
    return next(n for i in range(1, 6) if (n := node_by_id(sim, i)).key == "load")


def _set(sim: Simulation, field: str, value: list[float]) -> None:
    set_field(sim, _node(sim), field, value)        # type: ignore[arg-type]


def _touch_steps(height: float) -> int:
    """The first step whose end is past the time a fall of ``height`` takes: ceil(sqrt(2h/g) / step)."""
    return math.ceil(math.sqrt(2.0 * height / G) * 1000.0 / STEP)


def _landing(sim: Simulation, nue: bool = False):
    """Where ground.land_solid rests the box from where it is now (computed before any step of the fall)."""
    model = next(s for s in sim.world.solids if s.name == "load")
    to_enu = None if not nue else np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    return land_solid(model, sim.scene.solid_poses["load"], sim.loaded.base_dir, sim.landing_ground("load"), to_enu)


def _same(a, b) -> bool:
    return bool(np.array_equal(a.translation, b.translation) and np.array_equal(a.rotation, b.rotation))


def test_a_box_moved_half_a_metre_up_falls_in_closed_form_and_rests_on_the_floor() -> None:
    sim = _world()
    _set(sim, "translation", [0.2, 0.1, Z0])
    put = sim.scene.solid_poses["load"]
    assert put.translation.tolist() == [0.2, 0.1, Z0]                 # where it was put, until the next step
    landing = _landing(sim)
    assert landing.translation.tolist() == pytest.approx([0.2, 0.1, 0.05], abs=1e-12)
    node = _node(sim)
    n = _touch_steps(H)
    assert n == 20                                                      # 0.319 s
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation[2] == pytest.approx(Z0 - G * t * t / 2.0, abs=1e-12), k
        assert now.translation[:2].tolist() == [0.2, 0.1] and np.array_equal(now.rotation, put.rotation)
        assert node_velocity(sim, node) == pytest.approx([0.0, 0.0, -G * t, 0.0, 0.0, 0.0], abs=1e-12)  # type: ignore[arg-type]
    sim.step()
    rest = sim.scene.solid_poses["load"]
    assert _same(rest, landing) and not sim.falls
    assert node_velocity(sim, node) == [0.0] * 6                        # type: ignore[arg-type]
    sim.step()
    assert sim.scene.solid_poses["load"] is rest


def test_moved_again_mid_fall_it_falls_from_rest_from_the_new_pose() -> None:
    sim = _world()
    _set(sim, "translation", [0.0, 0.0, Z0])
    for _ in range(5):
        sim.step()
    assert sim.scene.solid_poses["load"].translation[2] == pytest.approx(Z0 - G * 0.08 ** 2 / 2.0, abs=1e-12)
    _set(sim, "translation", [0.3, 0.0, 1.0])                           # its bottom 0.95 m up, from rest
    node = _node(sim)
    assert node_velocity(sim, node) == [0.0] * 6                        # type: ignore[arg-type]
    n = _touch_steps(0.95)
    assert n == 28
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation.tolist() == pytest.approx([0.3, 0.0, 1.0 - G * t * t / 2.0], abs=1e-12), k
    sim.step()
    assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.3, 0.0, 0.05], abs=1e-12)
    assert not sim.falls


def test_a_rotation_set_in_the_air_keeps_its_tilt_while_it_falls_and_tips_flat_at_touch_down() -> None:
    """Turned 30° about x at Z0, its lowest edge is 0.05·(cos 30° + sin 30°) below its centre: it falls
    until that edge reaches the floor and lies flat (land_solid's pose) from then."""
    sim = _world()
    _set(sim, "translation", [0.0, 0.0, Z0])
    _set(sim, "rotation", [1.0, 0.0, 0.0, math.radians(30.0)])        # restarts the fall, from rest
    put = sim.scene.solid_poses["load"]
    landing = _landing(sim)
    reach = 0.05 * (math.cos(math.radians(30.0)) + math.sin(math.radians(30.0)))
    n = _touch_steps(Z0 - reach)
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert np.array_equal(now.rotation, put.rotation), k
        assert now.translation[2] == pytest.approx(Z0 - G * t * t / 2.0, abs=1e-12), k
    sim.step()
    rest = sim.scene.solid_poses["load"]
    assert _same(rest, landing)
    assert rest.translation[2] == pytest.approx(0.05, abs=1e-12) and abs(rest.rotation[2, 2]) == pytest.approx(1.0, abs=1e-12)


def test_in_a_nue_world_a_moved_box_falls_down_the_world_y() -> None:
    sim = _world(nue=True)
    _set(sim, "translation", [0.2, Z0, 0.1])
    landing = _landing(sim, nue=True)
    node = _node(sim)
    n = _touch_steps(H)
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation.tolist() == pytest.approx([0.2, Z0 - G * t * t / 2.0, 0.1], abs=1e-12), k
        assert node_velocity(sim, node) == pytest.approx([0.0, -G * t, 0.0, 0.0, 0.0, 0.0], abs=1e-12)  # type: ignore[arg-type]
    sim.step()
    rest = sim.scene.solid_poses["load"]
    assert _same(rest, landing) and rest.translation[1] == pytest.approx(0.05, abs=1e-12) and not sim.falls


def test_moved_onto_the_floor_it_stays_bit_for_bit_and_sunk_into_it_it_is_raised_at_once() -> None:
    sim = _world()
    _set(sim, "translation", [0.4, 0.0, 0.05])
    on = sim.scene.solid_poses["load"]
    assert not sim.falls
    sim.step()
    assert sim.scene.solid_poses["load"] is on
    _set(sim, "translation", [0.4, 0.0, 0.02])                          # 3 cm into the floor
    assert not sim.falls
    assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.4, 0.0, 0.05], abs=1e-12)


def test_a_box_without_physics_stays_where_a_supervisor_puts_it() -> None:
    sim = _world(physics=False)
    _set(sim, "translation", [0.2, 0.1, Z0])
    put = sim.scene.solid_poses["load"]
    for _ in range(30):
        sim.step()
    assert sim.scene.solid_poses["load"] is put and not sim.falls
    assert node_velocity(sim, _node(sim)) == [0.0] * 6                  # type: ignore[arg-type]


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_sees_the_box_it_moved_fall(tmp_path) -> None:
    """tests/controllers/move_falls.py through ``sensorium serve`` on tests/worlds/move_falls.wbt: it
    lifts the box to Z0 after one step, then reads its translation and velocity after each step."""
    from test_multiprocess import run_paused

    ctl = run_paused(REPO / "tests" / "worlds" / "move_falls.wbt", tmp_path, "move_falls.py", "boss")
    out = json.loads(ctl.out[-1])
    n = _touch_steps(H)
    assert len(out["z"]) == n + 2
    for k in range(1, n):
        t = k * STEP / 1000.0
        assert out["z"][k - 1] == pytest.approx(Z0 - G * t * t / 2.0, abs=1e-12), k
        assert out["vz"][k - 1] == pytest.approx(-G * t, abs=1e-12), k
    assert out["z"][n - 1:] == [pytest.approx(0.05, abs=1e-12)] * 3
    assert out["vz"][n - 1:] == [0.0] * 3
    assert out["xy"] == [0.2, 0.1]
