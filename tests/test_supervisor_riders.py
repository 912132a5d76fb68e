"""A robot riding another (a .wbt Robot with a controller or a device in another robot's children; README "World
files": ``carried_by``) seen by a Supervisor as Webots shows a nested node: its ``translation`` and ``rotation``
fields in its carrier's frame, read and set there (it stays fixed where it is put, as its carrier moves), a
simulationReset putting it back where the world file put it, and saveState/loadState keeping and restoring that
place. Closed forms: the carrier at (1, 0, 0) turned a quarter about z, the rider written at (0.2, 0, 0.1) in it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from test_supervisor import A, Live

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
Robot { name "probe" controller "<extern>" supervisor TRUE }
DEF TRUCK Robot { translation 1 0 0 rotation 0 0 1 1.5707963267948966 name "truck" controller "<extern>"
  children [ DEF RIDER Robot { translation 0.2 0 0.1 name "rider" controller "<extern>" children [ DistanceSensor { } ] } ]
}
"""


@pytest.fixture
def live(tmp_path: Path) -> Live:
    (tmp_path / "riders.wbt").write_text(WORLD)
    lv = Live(Simulation(load_world(tmp_path / "riders.wbt")))
    lv.ok(A, "attach", {"robot": "probe"})
    return lv


def call(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/probe/robot/{item}", args)


def world_position(lv: Live, node: int) -> list[float]:
    return call(lv, "get_node_pose", {"node": node})["position"]


def test_a_riders_fields_are_in_its_carriers_frame_and_a_set_keeps_it_there_as_the_carrier_moves(live) -> None:
    rider, truck = (call(live, "get_from_def", {"name": n})["node"] for n in ("RIDER", "TRUCK"))
    field = {"node": rider, "field": "translation"}
    assert call(live, "get_field", field)["value"] == pytest.approx([0.2, 0.0, 0.1], abs=1e-15)
    assert world_position(live, rider) == pytest.approx([1.0, 0.2, 0.1], abs=1e-12)     # (0.2, 0) turned a quarter
    call(live, "set_field", {**field, "value": [0.0, 0.3, 0.0]})
    call(live, "set_field", {"node": rider, "field": "rotation", "value": [0.0, 0.0, 1.0, math.pi]})
    live.sim.step()
    assert call(live, "get_field", field)["value"] == [0.0, 0.3, 0.0]                   # as set, bit for bit
    assert call(live, "get_field", {"node": rider, "field": "rotation"})["value"] == pytest.approx(
        [0.0, 0.0, 1.0, math.pi], abs=1e-15)
    assert world_position(live, rider) == pytest.approx([0.7, 0.0, 0.0], abs=1e-12)     # (0, 0.3) turned: (-0.3, 0)
    call(live, "set_field", {"node": truck, "field": "translation", "value": [5.0, 5.0, 0.0]})
    live.sim.step()
    assert world_position(live, rider) == pytest.approx([4.7, 5.0, 0.0], abs=1e-12)     # carried where it was put
    live.sim.reset()
    live.sim.step()
    assert call(live, "get_field", field)["value"] == pytest.approx([0.2, 0.0, 0.1], abs=1e-15)
    assert world_position(live, rider) == pytest.approx([1.0, 0.2, 0.1], abs=1e-12)


def test_a_riders_saved_state_is_its_place_on_its_carrier(live) -> None:
    rider = call(live, "get_from_def", {"name": "RIDER"})["node"]
    field = {"node": rider, "field": "translation"}
    call(live, "set_field", {**field, "value": [0.0, 0.3, 0.0]})
    call(live, "save_node_state", {"node": rider, "state": "moved"})
    call(live, "set_field", {**field, "value": [0.5, 0.5, 0.5]})
    call(live, "load_node_state", {"node": rider, "state": "moved"})
    live.sim.step()
    assert call(live, "get_field", field)["value"] == [0.0, 0.3, 0.0]
    assert world_position(live, rider) == pytest.approx([1.0 - 0.3, 0.0, 0.0], abs=1e-12)
    call(live, "load_node_state", {"node": rider, "state": "__init__"})
    live.sim.step()
    assert call(live, "get_field", field)["value"] == pytest.approx([0.2, 0.0, 0.1], abs=1e-15)
    assert world_position(live, rider) == pytest.approx([1.0, 0.2, 0.1], abs=1e-12)


def test_a_rider_put_in_the_world_stays_there_on_its_carrier(live) -> None:
    """set_pose of a riding robot (world coordinates, as the service takes them): it stays where it is put,
    its frame on its carrier that place (carrier at (1, 0, 0) facing +y: (3, 1, 0.5) is (1, -2, 0.5) on it),
    and goes with the carrier after."""
    rider, truck = live.sim.robot("rider"), live.sim.robot("truck")
    rider.set_pose(translation=[3.0, 1.0, 0.5])
    live.sim.step()
    assert rider.pose.translation == pytest.approx([3.0, 1.0, 0.5], abs=1e-12)
    assert live.sim.rider_frame(rider).translation == pytest.approx([1.0, -2.0, 0.5], abs=1e-12)
    truck.set_pose(translation=[2.0, 0.0, 0.0])
    live.sim.step()
    assert rider.pose.translation == pytest.approx([4.0, 1.0, 0.5], abs=1e-12)
