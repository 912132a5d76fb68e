"""A Supervisor's ``resetPhysics`` / ``simulationResetPhysics`` zero a falling solid's velocity: it falls again
from rest from where it is (sim/falling.py ``Falls.stop``), in closed form.

A 0.1 m box with physics rests on a floor plane at z = 0 (its centre at 0.05). A Supervisor puts it at
(0.2, 0.1, 1) at time t0 and resets its physics k1 steps of 16 ms later, when its centre is at
z1 = 1 − g·(0.016 k1)²/2: from then on its centre is at z1 − g·(t − t1)²/2 and its velocity −g·(t − t1)
along z (0 right after the reset), and from the first step whose end is past sqrt(2·(z1 − 0.05)/g) after
the reset it rests at exactly the pose it would have come to without the reset (ground.land_solid's
for the pose it was put at). Nothing that is not falling changes: a resting solid, a robot (Webots keeps
its motors' commands, its motion here), the floor."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from sensorium.server.daemon.supervisor import HANDLERS, ROOT, node_by_id, node_velocity, set_field
from sensorium.server.sim.ground import land_solid
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world

STEP = 16
G = 9.81
REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "reset_falls.wbt"
NUE_TO_ENU = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _world(nue: bool = False, second: bool = False) -> Simulation:
    floor = {"name": "floor", "geometry": {"type": "plane"}}
    boxes = [{"name": "load", "pose": {"translation": [0.0, 0.05, 0.0] if nue else [0.0, 0.0, 0.05]},
              "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}, "physics": True}]
    if second:
        boxes.append({"name": "other", "pose": {"translation": [1.0, 0.0, 0.05]},
                      "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}, "physics": True})
    if nue:
        floor["pose"] = {"rotation": [1, 0, 0, -math.pi / 2]}
    info = {"basic_time_step": STEP, **({"coordinate_system": "NUE"} if nue else {})}
    sim = Simulation(parse_world({"world_info": info, "solids": [floor, *boxes]}), precision="exact")
    sim.step()
    return sim


def _node(sim: Simulation, name: str = "load") -> object:
    return next(n for i in range(1, 8) if (n := node_by_id(sim, i)).key == name)


def _lift(sim: Simulation, translation: list[float], name: str = "load") -> None:
    set_field(sim, _node(sim, name), "translation", translation)     # type: ignore[arg-type]


def _reset(sim: Simulation, node: object) -> None:
    """The ``reset_physics`` service on ``node`` (the root: ``simulationResetPhysics``)."""
    assert HANDLERS["reset_physics"](sim, None, "boss", SimpleNamespace(node=node.id)) == {"success": True}  # type: ignore[attr-defined]


def _landing(sim: Simulation, name: str = "load", nue: bool = False):
    model = next(s for s in sim.world.solids if s.name == name)
    return land_solid(model, sim.scene.solid_poses[name], sim.loaded.base_dir, sim.landing_ground(name),
                      NUE_TO_ENU if nue else None)


def _touch_steps(height: float) -> int:
    """The first step whose end is past the time a fall of ``height`` takes: ceil(sqrt(2h/g) / step)."""
    return math.ceil(math.sqrt(2.0 * height / G) * 1000.0 / STEP)


def _same(a, b) -> bool:
    return bool(np.array_equal(a.translation, b.translation) and np.array_equal(a.rotation, b.rotation))


def test_a_falling_box_reset_falls_again_from_rest_where_it_is_and_lands_where_it_would_have() -> None:
    sim = _world()
    _lift(sim, [0.2, 0.1, 1.0])
    put = sim.scene.solid_poses["load"]
    landing = _landing(sim)
    node = _node(sim)
    for _ in range(10):
        sim.step()
    z1 = sim.scene.solid_poses["load"].translation[2]
    assert z1 == pytest.approx(1.0 - G * 0.16 ** 2 / 2.0, abs=1e-12)                 # 0.874432
    assert node_velocity(sim, node)[2] == pytest.approx(-G * 0.16, abs=1e-12)           # type: ignore[arg-type]
    _reset(sim, node)
    assert node_velocity(sim, node) == [0.0] * 6                                        # type: ignore[arg-type]
    assert sim.scene.solid_poses["load"].translation[2] == z1                           # not moved by the reset
    n = _touch_steps(z1 - 0.05)                   # its bottom, 0.05 below its centre, z1 - 0.05 over the floor
    assert n == 26 and 10 + n > _touch_steps(0.95)       # later than the 28th step it would have landed at
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation.tolist() == pytest.approx([0.2, 0.1, z1 - G * t * t / 2.0], abs=1e-12), k
        assert np.array_equal(now.rotation, put.rotation)
        assert node_velocity(sim, node) == pytest.approx([0.0, 0.0, -G * t, 0.0, 0.0, 0.0], abs=1e-12)  # type: ignore[arg-type]
    sim.step()
    rest = sim.scene.solid_poses["load"]
    assert _same(rest, landing) and not sim.falls
    assert node_velocity(sim, node) == [0.0] * 6                                        # type: ignore[arg-type]
    _reset(sim, node)                                                   # at rest: nothing to stop
    sim.step()
    assert sim.scene.solid_poses["load"] is rest


def test_reset_twice_restarts_twice_and_a_reset_at_the_instant_of_the_lift_changes_nothing() -> None:
    sim, twin = _world(), _world()
    for s in (sim, twin):
        _lift(s, [0.0, 0.0, 1.0])
    _reset(sim, _node(sim))                        # at rest already (put there from rest this instant)
    for _ in range(12):
        sim.step()
        twin.step()
        assert _same(sim.scene.solid_poses["load"], twin.scene.solid_poses["load"])
    z1 = sim.scene.solid_poses["load"].translation[2]
    _reset(sim, _node(sim))
    for _ in range(4):
        sim.step()
    z2 = sim.scene.solid_poses["load"].translation[2]
    assert z2 == pytest.approx(z1 - G * 0.064 ** 2 / 2.0, abs=1e-12)
    _reset(sim, _node(sim))
    for k in range(1, _touch_steps(z2 - 0.05)):
        sim.step()
        t = k * STEP / 1000.0
        assert sim.scene.solid_poses["load"].translation[2] == pytest.approx(z2 - G * t * t / 2.0, abs=1e-12), k
    sim.step()
    assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.0, 0.0, 0.05], abs=1e-12)
    assert not sim.falls


def test_the_roots_reset_stops_every_falling_solid_and_a_solids_own_only_itself() -> None:
    sim = _world(second=True)
    _lift(sim, [0.0, 0.0, 1.0])
    _lift(sim, [1.0, 0.0, 2.0], "other")
    for _ in range(5):
        sim.step()
    _reset(sim, _node(sim, "other"))                 # "load" keeps falling from its lift
    for _ in range(5):
        sim.step()
    load, other = (sim.scene.solid_poses[n].translation[2] for n in ("load", "other"))
    assert load == pytest.approx(1.0 - G * 0.16 ** 2 / 2.0, abs=1e-12)
    z_other = 2.0 - G * 0.08 ** 2 / 2.0
    assert other == pytest.approx(z_other - G * 0.08 ** 2 / 2.0, abs=1e-12)
    _reset(sim, ROOT)                                # simulationResetPhysics
    assert node_velocity(sim, _node(sim)) == [0.0] * 6 == node_velocity(sim, _node(sim, "other"))  # type: ignore[arg-type]
    for k in range(1, 6):
        sim.step()
        t = k * STEP / 1000.0
        assert sim.scene.solid_poses["load"].translation[2] == pytest.approx(load - G * t * t / 2.0, abs=1e-12)
        assert sim.scene.solid_poses["other"].translation[2] == pytest.approx(other - G * t * t / 2.0, abs=1e-12)


def test_in_a_nue_world_the_reset_box_falls_again_down_the_world_y() -> None:
    sim = _world(nue=True)
    _lift(sim, [0.2, 1.0, 0.1])
    landing = _landing(sim, nue=True)
    for _ in range(10):
        sim.step()
    y1 = sim.scene.solid_poses["load"].translation[1]
    _reset(sim, ROOT)
    node = _node(sim)
    n = _touch_steps(y1 - 0.05)
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.2, y1 - G * t * t / 2.0, 0.1],
                                                                                    abs=1e-12), k
        assert node_velocity(sim, node) == pytest.approx([0.0, -G * t, 0.0, 0.0, 0.0, 0.0], abs=1e-12)  # type: ignore[arg-type]
    sim.step()
    assert _same(sim.scene.solid_poses["load"], landing) and not sim.falls


def test_nodes_that_are_not_falling_change_nothing() -> None:
    """A resting solid, the floor, the root with nothing falling: no error, every pose the same object."""
    sim = _world(second=True)
    before = dict(sim.scene.solid_poses)
    for node in (_node(sim), _node(sim, "other"), _node(sim, "floor"), ROOT):
        _reset(sim, node)
    sim.step()
    assert sim.scene.solid_poses == before and not sim.falls


def test_a_robot_keeps_driving_bit_for_bit_as_its_twin_without_the_reset() -> None:
    """Webots keeps a robot's motors' commands on resetPhysics; here they are its whole motion: the
    driving supervisor of tests/worlds/supervisor_scene.yaml, its own node reset (and the root's) every
    step, moves exactly as its twin."""
    world = REPO / "tests" / "worlds" / "supervisor_scene.yaml"
    sims = [Simulation(load_world(world), precision="exact") for _ in range(2)]
    for s in sims:                              # v 0.15 m/s, w 0.5 rad/s (the world file's comment)
        for name, speed in (("left wheel motor", 2.0), ("right wheel motor", 4.0)):
            s.robot("judge").motor(name).set_position(math.inf)
            s.robot("judge").motor(name).set_velocity(speed)
    reset, twin = sims
    me = next(n for i in range(1, 4) if (n := node_by_id(reset, i)).key == "judge")
    for _ in range(20):
        _reset(reset, me)
        _reset(reset, ROOT)
        for s in sims:
            s.step()
        assert _same(reset.scene.robot_poses[reset.robots["judge"].index], twin.scene.robot_poses[twin.robots["judge"].index])
        assert node_velocity(reset, me) == node_velocity(twin, me)                      # type: ignore[arg-type]
    assert node_velocity(reset, me)[:3] != [0.0, 0.0, 0.0]                              # type: ignore[arg-type]


def _closed_forms(out: dict) -> None:
    """tests/controllers/reset_falls.py's (and tests/c/reset_falls.c's) line against the closed forms."""
    a, b = out["a"], out["b"]
    z1 = 1.0 - G * 0.16 ** 2 / 2.0
    assert a["z1"] == pytest.approx(z1, abs=1e-12)
    assert a["v1"] == [0.0] * 6
    n = _touch_steps(z1 - 0.05)
    for k in range(1, n):
        t = k * STEP / 1000.0
        assert a["z"][k - 1] == pytest.approx(z1 - G * t * t / 2.0, abs=1e-12), k
        assert a["vz"][k - 1] == pytest.approx(-G * t, abs=1e-12), k
    assert a["z"][n - 1:] == [pytest.approx(0.05, abs=1e-12)] * (28 - n + 1)
    assert a["vz"][n - 1:] == [0.0] * (28 - n + 1)
    for k in range(1, 7):                       # the floor's and the robot's resets changed nothing
        assert b["z_kept"][k - 1] == pytest.approx(1.0 - G * (k * 0.016) ** 2 / 2.0, abs=1e-12), k
    z1 = b["z1"]
    assert b["v1"] == [0.0] * 6
    n = _touch_steps(z1 - 0.05)
    assert n == 27
    for k in range(1, n):
        t = k * STEP / 1000.0
        assert b["z"][k - 1] == pytest.approx(z1 - G * t * t / 2.0, abs=1e-12), k
    assert b["z"][n - 1:] == [pytest.approx(0.05, abs=1e-12)] * (29 - n + 1)
    c = out["c"]                                # setVelocity(0) is resetPhysics; NaN and sideways change nothing
    z1 = 1.0 - G * 0.08 ** 2 / 2.0
    assert c["z1"] == pytest.approx(z1, abs=1e-12)
    assert c["v1"] == [0.0] * 6
    n = _touch_steps(z1 - 0.05)
    assert n == 28                              # lands in the last two of the 29 steps
    for k in range(1, n):
        t = k * STEP / 1000.0
        assert c["z"][k - 1] == pytest.approx(z1 - G * t * t / 2.0, abs=1e-12), k
    assert c["z"][n - 1:] == [pytest.approx(0.05, abs=1e-12)] * (29 - n + 1)
    assert out["xy"] == [0.2, 0.1] and out["floor"] == "Solid"


SET_VELOCITY_LINES = ["Error: wb_supervisor_node_set_velocity() called with a NaN or infinite value.",
                      "Warning: wb_supervisor_node_set_velocity(): a velocity other than zero is ignored: Sensorium "
                      "has no physics engine (robots move by their wheels' commands, solids only fall straight down "
                      "from rest)."]


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_stops_a_falling_box_and_sees_it_fall_again(tmp_path) -> None:
    from test_multiprocess import run_paused

    ctl = run_paused(WORLD, tmp_path, "reset_falls.py", "boss")
    _closed_forms(json.loads(ctl.out[-1]))
    assert [line for line in ctl.stderr().splitlines() if "set_velocity" in line] == SET_VELOCITY_LINES


@pytest.mark.slow
def test_a_c_supervisor_stops_a_falling_box_and_sees_it_fall_again(tmp_path_factory) -> None:
    """tests/c/reset_falls.c, built with sanitizers, through ``sensorium serve``: the same line."""
    from test_c_client import sanitized_run

    code, out, err = sanitized_run(tmp_path_factory, REPO / "tests" / "c" / "reset_falls.c", WORLD, "boss")
    assert code == 0, err
    _closed_forms(json.loads(out[-1]))
    assert [line for line in err.splitlines() if "set_velocity" in line] == SET_VELOCITY_LINES


def test_set_velocity_zero_asks_reset_physics_and_anything_else_is_one_line(monkeypatch, capsys) -> None:
    """The Python client's ``setVelocity`` without a server: zero (any zeros: ints, -0.0) is the node's
    ``reset_physics`` request; a velocity that is not 6 finite numbers is refused with its line; another
    velocity prints the warning once and asks nothing but the node's type."""
    from test_movie import _FakeSupervisor

    from sensorium.client import wb_supervisor as ws
    fake = _FakeSupervisor()
    monkeypatch.setattr(ws, "_supervisor", lambda func: fake)
    monkeypatch.setattr(ws, "_set_velocity_warned", [])
    func = "wb_supervisor_node_set_velocity"
    ws.wb_supervisor_node_set_velocity(7, [0, 0, 0, -0.0, 0.0, 0])
    assert fake.calls == ["/boss/robot/get_from_id", "/boss/robot/reset_physics"] and capsys.readouterr().err == ""
    for bad, line in (([0.0] * 5, "expected 6 numbers, got 5."), ([0.0] * 7, "expected 6 numbers, got 7."),
                      (None, "expected 6 numbers, got None."), (["x"] * 6, "expected 6 numbers, got ['x', 'x', "
                                                                          "'x', 'x', 'x', 'x']."),
                      ([0.0] * 5 + [math.inf], None), ([math.nan] + [0.0] * 5, None)):
        ws.wb_supervisor_node_set_velocity(7, bad)
        want = f"Error: {func}(): {line}" if line else f"Error: {func}() called with a NaN or infinite value."
        assert capsys.readouterr().err == want + "\n"
    for _ in range(2):
        ws.wb_supervisor_node_set_velocity(7, [0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    assert capsys.readouterr().err == SET_VELOCITY_LINES[1] + "\n"
    assert [c for c in fake.calls if not c.endswith("/get_from_id")] == ["/boss/robot/reset_physics"]
