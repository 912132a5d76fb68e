"""An upright Cylinder's top is ground as an upright Box's is (sim/ground.py): a robot rides a drum's
top disc at the height it was placed with, leaves it at its rim for the floor below, never takes a
round table top above its support ceiling for its ground, and the batched copies ride it bit for
bit as the single simulation. Closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from tests._copies import drive_and_compare
from tests.test_ground_box import BODY, HALF, _drive, _robot, _sim

DRUM = 0.25 + 0.1 / 2          # the drum's top: its centre plus half its height
RIM = 0.6                       # its radius
HILL = [0.1 * (i + j) for j in range(3) for i in range(3)]


def _cylinder(name: str, centre, radius: float, height: float, rotation=None) -> dict:
    out = {"name": name, "pose": {"translation": list(centre)},
           "geometry": {"type": "cylinder", "radius": radius, "height": height}}
    if rotation is not None:
        out["pose"]["rotation"] = list(rotation)
    return out


def _solids(extra: tuple = ()) -> list[dict]:
    """A floor plane at 0, a drum (top 0.3, radius 0.6 about (0, 0)), a round table top 0.5 m above
    the drum's top, and a small hill far away (a terrain: worlds without one have no ground)."""
    return [{"name": "floor", "geometry": {"type": "plane"}},
            _cylinder("drum", (0.0, 0.0, 0.25), RIM, 0.1),
            _cylinder("table", (5.0, 0.0, 0.78), 0.4, 0.04),
            {"name": "hill", "pose": {"translation": [20.0, 20.0, 0.0]},
             "geometry": {"type": "elevation_grid", "height": HILL, "x_dimension": 3, "x_spacing": 0.5,
                          "y_dimension": 3, "y_spacing": 0.5}}, *extra]


def test_the_drums_top_is_ground_over_its_closed_disc_and_only_there() -> None:
    g = _sim(_solids(), at=(0.0, 0.0, DRUM + HALF)).ground
    c = RIM / math.sqrt(2.0)
    x = np.array([0.0, RIM, 0.0, -0.3, RIM + 1e-9, c + 1e-9])
    y = np.array([0.0, 0.0, -RIM, 0.2, 0.0, c + 1e-9])
    found, z, gx, gy = g.under(x, y, np.full(6, 10.0))
    assert found.all()
    assert z.tolist() == [DRUM] * 4 + [0.0, 0.0]          # the rim is on it; just past it, the floor
    assert not gx.any() and not gy.any()
    # above the robot's support ceiling it is not its ground: the floor under it is
    assert g.under(np.array([0.0]), np.array([0.0]), np.array([DRUM - 1e-6]))[1][0] == 0.0


def test_a_robot_placed_on_the_drum_rides_its_top_and_drops_to_the_floor_past_its_rim() -> None:
    z0 = DRUM + HALF
    sim = _sim(_solids(), at=(-0.5, 0.0, z0))
    r = sim.robot("r")
    assert r.drive.rest == DRUM and r.drive.slope is None
    _drive(sim, 10.0, 10.0)                       # 0.5 m/s along +x: 0.016 m a step
    on_top = past = 0
    for _ in range(100):
        sim.step()
        x, y, z = r.pose.translation
        assert y == 0.0
        if x <= RIM:
            assert z == z0
            on_top += 1
        else:
            assert z == pytest.approx(HALF, abs=1e-12)     # the floor plus the clearance it was placed with
            past += 1
    assert on_top > 60 and past > 20


def test_a_round_table_top_above_the_robot_is_not_its_ground_and_one_it_is_put_on_is() -> None:
    sim = _sim(_solids(), at=(5.0, 0.0, HALF))
    r = sim.robot("r")
    assert r.drive.rest == 0.0                    # under the table: the floor
    top = 0.78 + 0.04 / 2
    r.set_pose([5.1, 0.0, top + HALF])
    assert r.drive.rest == pytest.approx(top, abs=1e-15)


def test_a_tilted_cylinder_is_not_ground_and_one_upside_down_is() -> None:
    tilted = _cylinder("tilted", (3.0, 3.0, 0.25), 0.5, 0.1, rotation=[1, 0, 0, 0.3])
    flipped = _cylinder("flipped", (-3.0, 3.0, 0.25), 0.5, 0.1, rotation=[1, 0, 0, math.pi])
    g = _sim(_solids(extra=(tilted, flipped)), at=(0.0, 0.0, DRUM + HALF)).ground
    found, z, _, _ = g.under(np.array([3.0, -3.0]), np.array([3.0, 3.0]), np.full(2, 10.0))
    assert found.all() and z[0] == 0.0 and z[1] == DRUM


def test_copies_riding_a_drum_are_the_single_simulation_bit_for_bit() -> None:
    world = wm.World.model_validate({
        "world_info": {"random_seed": 0}, "solids": _solids(),
        "robots": [_robot("a", (-0.4, 0.1, DRUM + HALF), 0.2), _robot("b", (0.9, -0.5, HALF), 2.5)]})
    assert BODY["geometry"]["type"] == "cylinder"
    bs = BatchedSimulation(world, 3)
    sims = [Simulation(world) for _ in range(3)]
    heights = drive_and_compare(bs, sims, ("a", "b"), np.random.default_rng(5), 120, 20)
    assert DRUM + HALF in heights and min(heights) == pytest.approx(HALF, abs=1e-12)   # on the drum, and off it
