"""A solid a VacuumGripper lets go falls under the world's gravity (sim/falling.py), in closed form.

The crane: a robot without a drive whose cup (a bounding cylinder, radius 0.05 m, 0.02 m tall) holds a
0.1 m box with physics by its top, the box's bottom ``H`` = 0.5 m over a floor plane at z = 0, its
centre at z0 = 0.55. Let go at simulated time t0, after k steps of 16 ms its centre is at
z0 − g·(0.016 k)²/2 (x, y, rotation kept), and at the first step whose end is past sqrt(2H/g) it rests at
exactly the pose ground.land_solid gives for the pose it was let go at (the instant landing of before).
A distance sensor on the floor beside its path, looking up at its underside through a gap, reads the
falling face."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.daemon.supervisor import node_by_id, node_velocity
from sensorium.server.sim.ground import land_solid
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

STEP = 16
H = 0.5                   # m: the box's bottom over the floor when let go
Z0 = H + 0.05             # its centre
CUP = {"device": "VacuumGripper", "name": "cup", "is_on": True}


def _crane(x: float = 0.0, top: float = Z0 + 0.05, nue: bool = False) -> dict:
    at = [x, top, 0.0] if nue else [x, 0.0, top]
    offset = [0.0, 0.01, 0.0] if nue else [0.0, 0.0, 0.01]
    geometry = {"type": "box", "size": [0.1, 0.02, 0.1]} if nue else {"type": "cylinder", "radius": 0.05, "height": 0.02}
    return {"name": "crane", "pose": {"translation": at},
            "shapes": [{"pose": {"translation": offset}, "geometry": geometry, "of_device": "cup", "seen_by": "bounding"}],
            "devices": [CUP]}


def _world(gravity: float = 9.81, rotation=(0.0, 0.0, 1.0, 0.3), robots: list[dict] | None = None,
           nue: bool = False) -> Simulation:
    floor = {"name": "floor", "geometry": {"type": "plane"}}
    box = {"name": "load", "pose": {"translation": [0.0, Z0, 0.0] if nue else [0.0, 0.0, Z0], "rotation": list(rotation)},
           "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}, "physics": True}
    if nue:
        floor["pose"] = {"rotation": [1, 0, 0, -math.pi / 2]}
    info = {"basic_time_step": STEP, "gravity": gravity, **({"coordinate_system": "NUE"} if nue else {})}
    return Simulation(parse_world({"world_info": info, "solids": [floor, box], "robots": [_crane(nue=nue), *(robots or [])]}),
                      precision="exact")


def _let_go(sim: Simulation) -> None:
    g = sim.device("crane/cup")
    sim.step()
    assert g.held == "load"                                             # type: ignore[attr-defined]
    g.set_on(False)                                                     # type: ignore[attr-defined]


def _touch_steps(height: float, gravity: float = 9.81) -> int:
    """The first step whose end is past the time a fall of ``height`` takes: ceil(sqrt(2h/g) / step)."""
    return math.ceil(math.sqrt(2.0 * height / gravity) * 1000.0 / STEP)


def _landing(sim: Simulation):
    pose = sim.scene.solid_poses["load"]
    model = next(s for s in sim.world.solids if s.name == "load")
    return land_solid(model, pose, sim.loaded.base_dir, sim.landing_ground("load"), None)


def _node(sim: Simulation, key: str) -> object:
    return next(n for i in range(1, 8) if (n := node_by_id(sim, i)).key == key)


@pytest.mark.parametrize("gravity", [9.81, 3.71])
def test_a_box_let_go_half_a_metre_up_falls_in_closed_form_and_rests_where_it_landed_before(gravity: float) -> None:
    sim = _world(gravity)
    _let_go(sim)
    start = sim.scene.solid_poses["load"]
    before = _landing(sim)                                              # the instant landing of before
    assert before.translation[2] == pytest.approx(0.05, abs=1e-12)
    node = _node(sim, "load")
    n = _touch_steps(H, gravity)
    assert n == (20 if gravity == 9.81 else 33)                         # 0.319 s, 0.519 s
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation[2] == pytest.approx(Z0 - gravity * t * t / 2.0, abs=1e-12), k
        assert now.translation[:2].tolist() == start.translation[:2].tolist() and np.array_equal(now.rotation, start.rotation)
        assert node_velocity(sim, node) == pytest.approx([0.0, 0.0, -gravity * t, 0.0, 0.0, 0.0], abs=1e-12)  # type: ignore[arg-type]
    sim.step()
    rest = sim.scene.solid_poses["load"]
    assert rest is before or (np.array_equal(rest.translation, before.translation) and np.array_equal(rest.rotation, before.rotation))
    assert node_velocity(sim, node) == [0.0] * 6                        # type: ignore[arg-type]
    assert not sim.falls
    sim.step()
    assert sim.scene.solid_poses["load"] is rest


def test_a_tilted_box_falls_untilted_and_tips_onto_its_face_at_touch_down() -> None:
    """Turned 30° about x, its lowest edge is 0.5·(cos 30° + sin 30°)·0.1 below its centre: it falls
    until that edge reaches the floor, keeps its tilt on the way, and lies flat (land_solid's pose) from then."""
    sim = _world(rotation=(1.0, 0.0, 0.0, math.radians(30.0)))
    _let_go(sim)
    start = sim.scene.solid_poses["load"]
    before = _landing(sim)
    reach = 0.05 * (math.cos(math.radians(30.0)) + math.sin(math.radians(30.0)))
    n = _touch_steps(Z0 - reach)
    for k in range(1, n):
        sim.step()
        now = sim.scene.solid_poses["load"]
        assert np.array_equal(now.rotation, start.rotation), k
        assert now.translation[2] - reach > 0.0
    sim.step()
    rest = sim.scene.solid_poses["load"]
    assert np.array_equal(rest.rotation, before.rotation) and np.array_equal(rest.translation, before.translation)
    assert rest.translation[2] == pytest.approx(0.05, abs=1e-12) and abs(rest.rotation[2, 2]) == pytest.approx(1.0, abs=1e-12)


def test_a_distance_sensor_beside_its_path_reads_its_falling_underside() -> None:
    """The sensor at (0, 0.045, 0.01) looks straight up (its x axis turned onto z): inside the box's
    section, 5 mm in from its side, so its ray meets the underside at z0 − g t²/2 − 0.05."""
    eye = {"name": "eye", "pose": {"translation": [0.0, 0.045, 0.01], "rotation": [0, 1, 0, -math.pi / 2]},
           "devices": [{"device": "DistanceSensor", "name": "ds", "lookup_table": [[0.0, 0.0, 0.0], [2.0, 2.0, 0.0]]}]}
    sim = _world(rotation=(0.0, 0.0, 1.0, 0.0), robots=[eye])
    ds = sim.device("eye/ds")
    ds.enable(STEP)                                                     # type: ignore[attr-defined]
    _let_go(sim)
    for k in range(1, _touch_steps(H)):
        sim.step()
        t = k * STEP / 1000.0
        assert ds.value == pytest.approx(Z0 - 9.81 * t * t / 2.0 - 0.05 - 0.01, abs=1e-9), k    # type: ignore[attr-defined]


def test_in_a_nue_world_it_falls_down_the_world_y() -> None:
    sim = _world(nue=True, rotation=(0.0, 1.0, 0.0, 0.3))
    _let_go(sim)
    start = sim.scene.solid_poses["load"]
    node = _node(sim, "load")
    n = _touch_steps(H)
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation[1] == pytest.approx(Z0 - 9.81 * t * t / 2.0, abs=1e-12), k
        assert (now.translation[0], now.translation[2]) == (start.translation[0], start.translation[2])
        assert node_velocity(sim, node) == pytest.approx([0.0, -9.81 * t, 0.0, 0.0, 0.0, 0.0], abs=1e-12)  # type: ignore[arg-type]
    sim.step()
    assert sim.scene.solid_poses["load"].translation[1] == pytest.approx(0.05, abs=1e-12) and not sim.falls


def test_a_supervisor_move_mid_fall_starts_it_over_from_rest_where_it_puts_the_box() -> None:
    """Moved to (0.3, 0, 1) after 5 steps of its fall, it falls from there from rest (its bottom 0.95 m
    over the floor: 28 steps), its rotation kept, and rests on the floor."""
    sim = _world()
    _let_go(sim)
    for _ in range(5):
        sim.step()
    start = sim.scene.solid_poses["load"]
    sim.set_solid_pose("load", [0.3, 0.0, 1.0])
    node = _node(sim, "load")
    assert node_velocity(sim, node) == [0.0] * 6                        # type: ignore[arg-type]
    n = _touch_steps(0.95)
    for k in range(1, n):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["load"]
        assert now.translation.tolist() == pytest.approx([0.3, 0.0, 1.0 - 9.81 * t * t / 2.0], abs=1e-12), k
        assert np.array_equal(now.rotation, start.rotation)
    sim.step()
    assert sim.scene.solid_poses["load"].translation.tolist() == pytest.approx([0.3, 0.0, 0.05], abs=1e-12) and not sim.falls
    assert node_velocity(sim, node) == [0.0] * 6                        # type: ignore[arg-type]


def test_a_box_a_gripper_holds_does_not_fall_when_a_supervisor_moves_it() -> None:
    sim = _world()
    sim.step()
    assert sim.device("crane/cup").held == "load"                       # type: ignore[attr-defined]
    sim.set_solid_pose("load", [0.0, 0.0, 0.8])
    assert not sim.falls


def test_a_gripper_beside_its_path_catches_it_mid_fall() -> None:
    """A second cup (pump on) whose disc reaches 0.02 m into the box's section, its top at z = 0.3:
    the box falling past is held there (where the step it touched ended), and the fall is over."""
    low = {**_crane(x=0.08, top=0.28), "name": "catcher"}
    sim = _world(rotation=(0.0, 0.0, 1.0, 0.0), robots=[low])
    _let_go(sim)
    catcher = sim.device("catcher/cup")
    for _ in range(_touch_steps(H)):
        sim.step()
        if catcher.held is not None:                                   # type: ignore[attr-defined]
            break
    assert catcher.held == "load"                                       # type: ignore[attr-defined]
    held = sim.scene.solid_poses["load"]
    assert 0.3 - 0.05 <= held.translation[2] - 0.05 <= 0.3 + 0.001 + 9.81 * 0.32 * 0.016
    for _ in range(10):
        sim.step()
    assert sim.scene.solid_poses["load"].translation[2] == held.translation[2] and not sim.falls


def test_with_no_gravity_it_floats_where_it_is_let_go() -> None:
    sim = _world(gravity=0.0)
    _let_go(sim)
    start = sim.scene.solid_poses["load"]
    for _ in range(30):
        sim.step()
    assert sim.scene.solid_poses["load"] is start and not sim.falls


def test_a_world_with_nothing_falling_does_no_fall_work() -> None:
    sim = _world()
    for _ in range(5):
        sim.step()
    assert not sim.falls and sim.device("crane/cup").held == "load"     # type: ignore[attr-defined]
