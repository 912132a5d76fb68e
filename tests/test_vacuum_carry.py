"""A VacuumGripper carries the solid it holds, kinematically (Webots' fixed joint without forces).

tests/worlds/vacuum_carry.yaml: the gripper rides a lift (a LinearMotor along +z), resting on a 0.1 m
parcel with physics centred at z = 0.05; an eye robot's distance sensor (its value the distance in
metres) looks along -x from x = 1 at z = 0.15, over the parcel until it is lifted by 0.1 m. The held
parcel's pose is the gripper's frame composed with the offset it had when attached, so its height is
0.05 + the lift's position exactly (float64, the robot at the origin, unturned)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.vacuum import GRIP_DISTANCE, _shape_obstacle, may_touch, prism_gap
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import load_world

REPO = Path(__file__).resolve().parents[1]
WORLD = REPO / "tests" / "worlds" / "vacuum_carry.yaml"
STEP = 16


@pytest.fixture
def sim() -> Simulation:
    s = Simulation.from_file(WORLD)
    s.device("arm/gripper").enable(STEP)
    s.device("eye/ds").enable(STEP)
    return s


def _parcel(sim: Simulation) -> np.ndarray:
    return sim.scene.solid_poses["parcel"].translation.copy()


def _lift_to(sim: Simulation, target: float) -> float:
    lift = sim.robot("arm").motors["lift"]
    lift.set_position(target)
    for _ in range(200):                      # 0.1 m at 0.05 m/s: 125 steps and the ramp
        sim.step()
    assert float(lift.position) == pytest.approx(target, abs=1e-12)
    return float(lift.position)


def test_the_lifted_parcel_rises_with_the_gripper_and_sensors_see_it_there(sim: Simulation) -> None:
    g, ds = sim.device("arm/gripper"), sim.device("eye/ds")
    sim.step()
    assert g.value == 0.0 and ds.value == 2.0                # pump off: nothing held; the ray passes over
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    assert g.value == 1.0 and g.held == "parcel"             # type: ignore[attr-defined]
    p = _lift_to(sim, 0.1)
    got = _parcel(sim)
    assert got[0] == 0.0 and got[1] == 0.0 and got[2] == 0.05 + p      # the offset composed, float64
    assert got[2] - 0.05 == pytest.approx(0.1, abs=1e-12)
    assert ds.value == pytest.approx(0.95, abs=1e-12)         # its +x face at x = 0.05, from x = 1
    assert g.value == 1.0
    node = sv.find_node(sim, "PARCEL")                        # a Supervisor reads it there
    assert sv.get_field(sim, node, "translation")["value"] == [0.0, 0.0, 0.05 + p]
    assert sv.node_pose(sim, node)["position"] == [0.0, 0.0, 0.05 + p]


def test_the_parcel_stays_where_the_pump_lets_it_go(sim: Simulation) -> None:
    g, ds = sim.device("arm/gripper"), sim.device("eye/ds")
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    p = _lift_to(sim, 0.1)
    g.set_on(False)                                          # type: ignore[attr-defined]
    assert g.held is None                                    # type: ignore[attr-defined]   let go at once
    _lift_to(sim, 0.0)
    # over no ground it stays (the arm's cup is above it where the lift holds it now, not at its
    # world-file place; tests/test_vacuum_load.py: a parcel over a floor lands on it)
    assert _parcel(sim).tolist() == [0.0, 0.0, 0.05 + p]
    assert g.value == 0.0 and ds.value == pytest.approx(0.95, abs=1e-12)


def test_a_turned_robot_turns_its_parcel_about_the_gripper(sim: Simulation) -> None:
    """The arm put 0.3 m along x and turned by 0.5 rad about z: the parcel (on the gripper's axis)
    goes to x = 0.3, turned by the same rotation."""
    g = sim.device("arm/gripper")
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    sim.robot("arm").set_pose(translation=[0.3, 0.0, 0.0], rotation=[0.0, 0.0, 1.0, 0.5])
    sim.step()
    pose = sim.scene.solid_poses["parcel"]
    c, s = math.cos(0.5), math.sin(0.5)
    assert np.allclose(pose.translation, [0.3, 0.0, 0.05], rtol=0, atol=1e-15)
    assert np.allclose(pose.rotation, [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], rtol=0, atol=1e-15)


def test_a_solid_without_physics_is_never_held(tmp_path: Path) -> None:
    """Webots attaches a solid by a fixed joint to its Physics body; one without moves with nothing:
    here it is never held, so the presence stays 0 (pump on, touching) and it stays on the ground."""
    p = tmp_path / "w.yaml"
    p.write_text(WORLD.read_text().replace("physics: true", "physics: false"))
    sim = Simulation.from_file(p)
    g = sim.device("arm/gripper")
    g.enable(STEP)
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    assert g.value == 0.0 and g.held is None                 # type: ignore[attr-defined]
    _lift_to(sim, 0.1)
    assert _parcel(sim).tolist() == [0.0, 0.0, 0.05]


def test_reset_puts_the_parcel_back_and_holds_nothing(sim: Simulation) -> None:
    g = sim.device("arm/gripper")
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    _lift_to(sim, 0.1)
    sim.reset()
    assert g.held is None and g.is_on is False               # type: ignore[attr-defined]   isOn FALSE in the file
    assert _parcel(sim).tolist() == [0.0, 0.0, 0.05]
    sim.step()
    assert g.value == 0.0 and _parcel(sim).tolist() == [0.0, 0.0, 0.05]


def test_a_removed_parcel_is_let_go(sim: Simulation) -> None:
    g = sim.device("arm/gripper")
    g.set_on(True)                                           # type: ignore[attr-defined]
    sim.step()
    sim.remove_solid("parcel")
    sim.step()
    assert g.held is None and g.value == 0.0                 # type: ignore[attr-defined]


def test_a_wbt_solid_with_physics_is_carried(tmp_path: Path) -> None:
    """From a .wbt: the Solid's Physics node is read (physics: true); a Solid without one is not."""
    p = tmp_path / "w.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nRobot { name "r" supervisor TRUE children [\n'
                 'VacuumGripper { translation 0 0 0.5 name "cup" isOn TRUE '
                 'boundingObject Cylinder { radius 0.05 height 0.02 } }\n] }\n'
                 'Solid { name "crate" translation 0 0 0.2 children [ Shape { geometry DEF B Box { size 0.4 0.4 0.4 } } ] '
                 'boundingObject USE B physics Physics { } }\n'
                 'Solid { name "wall" translation 3 0 0.2 children [ Shape { geometry DEF W Box { size 0.4 0.4 0.4 } } ] '
                 'boundingObject USE W }\n')
    w = load_world(p)
    assert [(s.name, s.physics) for s in w.world.solids] == [("crate", True), ("wall", False)]
    sim = Simulation(w)
    g = sim.device("r/cup")
    g.enable(STEP)
    sim.robot("r").set_pose(translation=[0.0, 0.0, -0.1])    # the cup's bottom on the crate's top (z = 0.4)
    sim.step()
    assert g.value == 1.0                                    # type: ignore[attr-defined]
    sim.robot("r").set_pose(translation=[0.0, 0.0, 0.15])
    sim.step()
    offset = 0.2 + 0.1                                       # the crate's height in the cup's frame when attached
    assert sim.scene.solid_poses["crate"].translation.tolist() == [0.0, 0.0, 0.15 + offset]
    sim.robot("r").set_pose(translation=[3.0, 0.0, -0.1])    # on the wall's top, still holding the crate
    sim.step()
    assert sim.scene.solid_poses["crate"].translation.tolist() == [3.0, 0.0, -0.1 + offset]
    assert sim.scene.solid_poses["wall"].translation.tolist() == [3.0, 0.0, 0.2]


def test_the_batched_simulation_refuses_a_pump_on_at_load(tmp_path: Path) -> None:
    p = tmp_path / "w.yaml"
    p.write_text((REPO / "tests" / "worlds" / "vacuum_speaker.yaml").read_text().replace(
        "{device: VacuumGripper, name: gripper,", "{device: VacuumGripper, name: gripper, is_on: true,"))
    with pytest.raises(BatchedError, match="vacuum gripper 'gripper' is on at load; the batched simulation carries nothing"):
        BatchedSimulation(load_world(p), copies=2)
    BatchedSimulation(load_world(REPO / "tests" / "worlds" / "vacuum_speaker.yaml"), copies=2)    # off: accepted


def test_another_robot_is_never_held(tmp_path: Path) -> None:
    """Webots would join a robot with physics by the fixed joint; here robots are never carried (their
    poses are their drives' and controllers'), so the presence stays 0 on a robot's box as well."""
    p = tmp_path / "w.yaml"
    p.write_text(WORLD.read_text().replace("physics: true", "physics: false").replace(
        "  - name: eye\n", "  - name: other\n    shapes:\n      - {pose: {translation: [0.0, 0.0, 0.05]}, "
        "geometry: {type: box, size: [0.1, 0.1, 0.1]}}\n  - name: eye\n"))
    sim = Simulation.from_file(p)
    g = sim.device("arm/gripper")
    g.enable(STEP)
    g.set_on(True)                                           # type: ignore[attr-defined]
    assert g.touched() is None                               # type: ignore[attr-defined]
    sim.step()
    assert g.value == 0.0 and g.held is None                 # type: ignore[attr-defined]
    assert sim.robot("other").pose.translation.tolist() == [0.0, 0.0, 0.0]


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.floats(-0.5, 0.5), st.floats(-0.3, 0.3), st.floats(0.0, 0.6), st.floats(0.0, math.pi))
def test_the_screen_never_drops_a_touching_pair(x: float, y: float, z: float, turn: float) -> None:
    """may_touch (the bounding boxes' per-axis gap, a lower bound of the prism distance) is False
    only for pairs prism_gap puts farther than GRIP_DISTANCE: a turned cylinder around a 0.4 m crate."""
    crate = _shape_obstacle(geo.Box((0.4, 0.4, 0.4)), Pose(np.eye(3), [0.0, 0.0, 0.2]))
    cup = _shape_obstacle(geo.Cylinder(0.05, 0.02), Pose.from_axis_angle([1.0, 0.0, 0.0], turn, (x, y, z)))
    assert crate is not None and cup is not None
    if prism_gap(cup, crate) <= GRIP_DISTANCE:
        assert may_touch(cup, crate)
    if abs(x) > 0.3 or z > 0.5:         # clearly apart (0.05 m and more)
        assert not may_touch(cup, crate)
