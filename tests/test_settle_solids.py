"""Top-level solids with physics settle on the ground at load, as Webots' physics drops them
(sim/ground.py ``settle_world``, ``_settle_solids``): each goes straight down (or up) onto the highest
support under its origin whose top is not above the middle of its height + 1 mm, its lowest point on
that top, x, y and rotation kept; lowest first, each landed solid a support for the next. A solid
without physics never moves. Closed forms, the load lines and their cap, reset and loadState, the
batched simulation bit for bit, a NUE world, a solid a VacuumGripper on at load touches (held, not dropped)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.states import Scope, States
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world

FLOOR = {"name": "floor", "geometry": {"type": "plane"}}
R = 0.0325               # the Pioneer gripper sample's ball radius


def _ball(name: str = "ball", at=(0.4, -0.1, 0.08), physics: bool = True) -> dict:
    return {"name": name, "pose": {"translation": list(at)}, "geometry": {"type": "sphere", "radius": R},
            "physics": physics}


def _box(name: str, centre, size, physics: bool = False, yaw: float = 0.0) -> dict:
    return {"name": name, "pose": {"translation": list(centre), "rotation": [0, 0, 1, yaw]},
            "geometry": {"type": "box", "size": list(size)}, "physics": physics}


def _loaded(solids: list[dict], robots: list[dict] | None = None, source: str = "w.yaml"):
    return parse_world({"solids": solids, "robots": robots or []}, source=source)


def _sim(solids: list[dict], robots: list[dict] | None = None) -> Simulation:
    return Simulation(_loaded(solids, robots), precision="exact")


def _at(sim: Simulation, name: str) -> np.ndarray:
    return sim.scene.solid_poses[name].translation


def _notes(sim: Simulation) -> list[str]:
    return [n for n in sim.loaded.warnings if "settled" in n]


# ---------------------------------------------------------------------- closed forms

def test_a_ball_in_the_air_falls_onto_the_floor() -> None:
    sim = _sim([FLOOR, _ball()])
    t = _at(sim, "ball")
    assert abs(t[2] - R) <= 1e-12 and (t[0], t[1]) == (0.4, -0.1)
    assert np.array_equal(sim.scene.solid_poses["ball"].rotation, np.eye(3))
    assert _notes(sim) == ["w.yaml: solid 'ball' settled on the ground at load, as Webots' physics drops it: "
                           "its origin's z from 0.0800 to 0.0325 m"]


def test_a_box_sunk_into_the_floor_rises_onto_it_and_keeps_its_turn() -> None:
    sim = _sim([{**FLOOR, "pose": {"translation": [0, 0, 0.1]}}, _box("crate", (1.0, 2.0, 0.1), (0.2, 0.3, 0.4), True, 0.6)])
    t = _at(sim, "crate")
    assert abs(t[2] - 0.3) <= 1e-12 and (t[0], t[1]) == (1.0, 2.0)
    rot = sim.scene.solid_poses["crate"].rotation
    assert abs(rot[1, 0] - np.sin(0.6)) <= 1e-15


def test_a_box_on_a_table_lands_on_the_table_and_one_beside_it_on_the_floor() -> None:
    table = _box("table", (0.0, 0.0, 0.35), (1.0, 0.8, 0.7))
    sim = _sim([FLOOR, table, _box("cup", (0.2, 0.1, 0.9), (0.1, 0.1, 0.1), True),
                _box("bin", (0.8, 0.0, 0.5), (0.1, 0.1, 0.2), True)])
    assert abs(_at(sim, "cup")[2] - 0.75) <= 1e-12
    assert abs(_at(sim, "bin")[2] - 0.1) <= 1e-12
    assert _at(sim, "table")[2] == 0.35


def test_a_box_under_a_table_top_stays_under_it() -> None:
    """The support ceiling: a table top above the middle of the box is something it is under, not its floor."""
    top = _box("top", (0.0, 0.0, 0.7), (1.0, 1.0, 0.04))
    sim = _sim([FLOOR, top, _box("crate", (0.0, 0.0, 0.3), (0.2, 0.2, 0.2), True)])
    assert abs(_at(sim, "crate")[2] - 0.1) <= 1e-12


@pytest.mark.parametrize("upper_first", [False, True])
def test_a_stack_of_two_boxes_lands_one_on_the_other(upper_first: bool) -> None:
    lower = _box("lower", (0.0, 0.0, 0.5), (0.4, 0.4, 0.2), True)
    upper = _box("upper", (0.05, 0.0, 1.2), (0.1, 0.1, 0.1), True)
    sim = _sim([FLOOR, *([upper, lower] if upper_first else [lower, upper])])
    assert abs(_at(sim, "lower")[2] - 0.1) <= 1e-12
    assert abs(_at(sim, "upper")[2] - 0.25) <= 1e-12


def test_a_solid_over_nothing_keeps_its_height_and_one_without_physics_never_moves() -> None:
    sim = _sim([_ball("high", at=(0, 0, 3.0)), _box("slab", (5.0, 0, 0.02), (1, 1, 0.04)),
                _ball("still", at=(5.0, 0, 0.5), physics=False), _ball("falls", at=(5.2, 0, 0.5))])
    assert _at(sim, "high")[2] == 3.0 and _at(sim, "still")[2] == 0.5
    assert abs(_at(sim, "falls")[2] - (0.04 + R)) <= 1e-12
    assert [n.split("'")[1] for n in _notes(sim)] == ["falls"]


def test_a_solid_resting_within_a_micrometre_keeps_its_pose_bit_for_bit() -> None:
    z = R + 7e-7
    sim = _sim([FLOOR, _ball(at=(0.1, 0.2, z))])
    assert _at(sim, "ball")[2] == z and not _notes(sim)
    sim = _sim([FLOOR, _ball(at=(0.1, 0.2, R + 2e-6))])
    assert abs(_at(sim, "ball")[2] - R) <= 1e-12 and not _notes(sim)      # moved, but by under 1 mm: no line


def test_a_wheeled_robot_settles_on_a_crate_that_fell() -> None:
    """Solids first, then robots on the world so settled."""
    crate = _box("crate", (0.0, 0.0, 0.6), (0.6, 0.6, 0.2), True)
    robot = {"name": "r", "pose": {"translation": [0.0, 0.0, 1.0]},
             "differential_drive": {"wheel_radius": 0.03, "axle_length": 0.1, "wheel_bottom": -0.03}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = _sim([FLOOR, crate], [robot])
    assert abs(_at(sim, "crate")[2] - 0.1) <= 1e-12
    assert abs(sim.robot("r").pose.translation[2] - 0.23) <= 1e-12


def test_the_load_lines_are_capped_at_eight_then_a_count() -> None:
    sim = _sim([FLOOR, *(_ball(f"b{k}", at=(0.1 * k, 0.0, 0.5)) for k in range(11))])
    notes = _notes(sim)
    assert len(notes) == 9 and notes[-1] == "w.yaml: 3 more solids settled on the ground at load"
    assert notes[0] == ("w.yaml: solid 'b0' settled on the ground at load, as Webots' physics drops it: "
                        "its origin's z from 0.5000 to 0.0325 m")


def test_a_nue_world_settles_along_its_y() -> None:
    from tests.test_batched_nue import _to_nue

    enu = _loaded([{**FLOOR, "pose": {"translation": [0, 0, 0.2]}}, _ball(at=(0.3, -0.2, 0.9))]).world
    sim = Simulation(parse_world(_to_nue(enu), source="n.yaml"), precision="exact")
    t = _at(sim, "ball")
    assert abs(t[1] - (0.2 + R)) <= 1e-12 and (t[0], t[2]) == (-0.2, 0.3)
    assert _notes(sim) == ["n.yaml: solid 'ball' settled on the ground at load, as Webots' physics drops it: "
                           "its origin's y from 0.9000 to 0.2325 m"]


# ---------------------------------------------------------------------- the settled world is the loaded one

def test_reset_and_load_state_init_restore_the_settled_pose() -> None:
    sim = _sim([FLOOR, _ball()])
    settled = sim.scene.solid_poses["ball"]
    assert abs(settled.translation[2] - R) <= 1e-12
    sim.place_solid("ball", Pose(np.eye(3), np.array([1.0, 1.0, 2.0])))
    sim.reset()
    assert np.array_equal(sim.scene.solid_poses["ball"].translation, settled.translation)
    sim.place_solid("ball", Pose(np.eye(3), np.array([1.0, 1.0, 2.0])))
    States().load(sim, 1, Scope("solid 'ball'", solid="ball"), "__init__")
    assert np.array_equal(sim.scene.solid_poses["ball"].translation, settled.translation)


def test_the_batched_copies_take_the_same_settled_world_bit_for_bit() -> None:
    solids = [FLOOR, _box("table", (0.0, 0.0, 0.35), (1.0, 0.8, 0.7)), _box("cup", (0.2, 0.1, 0.9), (0.1, 0.1, 0.1), True),
              _box("lid", (0.21, 0.1, 1.3), (0.05, 0.05, 0.01), True), _ball(at=(2.0, 0.0, 0.3))]
    robots = [{"name": "r", "pose": {"translation": [-2.0, 0.0, 0.1]},
               "differential_drive": {"wheel_radius": 0.03, "axle_length": 0.1}}]
    sim = _sim(solids, robots)
    bs = BatchedSimulation(_loaded(solids, robots), copies=2, precision="exact")
    for name in ("cup", "lid", "ball", "table", "floor"):
        assert np.array_equal(bs.scene.solid_poses[name].translation, sim.scene.solid_poses[name].translation)
        assert np.array_equal(bs.scene.solid_poses[name].rotation, sim.scene.solid_poses[name].rotation)
    assert abs(_at(sim, "lid")[2] - 0.805) <= 1e-12


def test_a_solid_a_gripper_on_at_load_touches_is_held_not_dropped() -> None:
    """Webots' VacuumGripper catches it in its first step; a parcel beside it, touched by no pump, falls."""
    crane = {"name": "crane", "pose": {"translation": [0.0, 0.0, 0.6]},
             "shapes": [{"pose": {"translation": [0.0, 0.0, 0.01]}, "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.02},
                         "of_device": "cup", "seen_by": "bounding"}],
             "devices": [{"device": "VacuumGripper", "name": "cup", "is_on": True}]}
    hung, loose = _box("hung", (0.0, 0.0, 0.55), (0.1, 0.1, 0.1), True), _box("loose", (1.0, 0.0, 0.55), (0.1, 0.1, 0.1), True)
    sim = _sim([FLOOR, hung, loose], [crane])
    assert _at(sim, "hung")[2] == 0.55 and abs(_at(sim, "loose")[2] - 0.05) <= 1e-12
    sim.step()
    assert sim.device("crane/cup").held == "hung"                       # type: ignore[attr-defined]
    off = _sim([FLOOR, hung, loose], [{**crane, "devices": [{"device": "VacuumGripper", "name": "cup", "is_on": False}]}])
    assert abs(_at(off, "hung")[2] - 0.05) <= 1e-12
