"""A solid a VacuumGripper holds is part of its carrier; a solid let go lands on what is under it.

The carrier: a two-wheel robot (wheels of radius 0.05 m, axle through its origin at z = 0.05 on a
floor plane at 0) whose 0.2 m square body spans z 0.03 to 0.11, with a gripper pad (a 0.02 x 0.1 x
0.06 m bounding box) in front, its front face at x = 0.12, against a 0.1 m parcel with physics centred
at (0.17, 0, 0.05). Wheels at 2.5 rad/s drive it 0.125 m/s: 0.3 m in 150 steps of 16 ms. Kinematic
contact would stop it at the parcel it holds; Webots' fixed joint makes the two one body.

The crane: a robot without a drive whose gripper (a bounding cylinder, radius 0.05 m, 0.02 m tall)
holds a 0.1 m parcel under it; turned off, the parcel falls under gravity (sim/falling.py) until its
bottom is on the floor plane at z = 0.013 or on a table's top (a 0.6 x 0.6 x 0.4 m box centred at (1, 0, 0.2))."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.vacuum import _shape_obstacle, prism_depth
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world

STEP = 16
W = 2.5                   # rad/s on wheels of radius 0.05: 0.125 m/s
N = 150                   # steps of 16 ms: 2.4 s, 0.3 m
DRIVE = {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0, "wheel_bottom": -0.05}
PARCEL = {"name": "parcel", "pose": {"translation": [0.17, 0.0, 0.05]}, "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]},
          "physics": True}


def _carrier(with_pump: bool = True) -> dict:
    shapes = [{"pose": {"translation": [0.11, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.02, 0.1, 0.06]},
               "of_device": "cup", "seen_by": "bounding"}] if with_pump else []
    devices = [{"device": "VacuumGripper", "name": "cup", "is_on": True, "pose": {"translation": [0.11, 0.0, 0.0]}}] \
        if with_pump else []
    body = {"pose": {"translation": [0.0, 0.0, 0.02]}, "geometry": {"type": "box", "size": [0.2, 0.2, 0.08]}}
    return {"name": "carrier", "pose": {"translation": [0.0, 0.0, 0.05]},
            "shapes": [body, *shapes], "devices": devices, "differential_drive": DRIVE}


def _other(x: float = 1.0) -> dict:
    """A disc robot (radius 0.1) facing -x, its distance sensor (reading metres) at its front."""
    return {"name": "other", "pose": {"translation": [x, 0.0, 0.05], "rotation": [0, 0, 1, math.pi]},
            "shapes": [{"pose": {"translation": [0.0, 0.0, 0.02]}, "geometry": {"type": "cylinder", "radius": 0.1, "height": 0.08}}],
            "devices": [{"device": "DistanceSensor", "name": "ds", "pose": {"translation": [0.1, 0.0, 0.0]},
                         "lookup_table": [[0.0, 0.0, 0.0], [2.0, 2.0, 0.0]]}],
            "differential_drive": DRIVE}


def _sim(solids: list[dict], robots: list[dict]) -> Simulation:
    return Simulation(parse_world({"world_info": {"basic_time_step": STEP},
                                   "solids": [{"name": "floor", "geometry": {"type": "plane"}}, *solids],
                                   "robots": robots}), precision="exact")


def _drive(sim: Simulation, robot: str, w: float) -> None:
    for m in sim.robot(robot).motors.values():
        m.set_position(math.inf)
        m.set_velocity(w)


def _run(sim: Simulation, n: int) -> None:
    for _ in range(n):
        sim.step()


def test_a_carrier_drives_on_with_its_load_and_keeps_it_where_it_holds_it() -> None:
    sim = _sim([PARCEL], [_carrier()])
    g = sim.device("carrier/cup")
    sim.step()
    assert g.held == "parcel"                                            # type: ignore[attr-defined]
    start = sim.robot("carrier").pose
    _drive(sim, "carrier", W)
    _run(sim, N)
    bare = _sim([], [_carrier(with_pump=False)])                         # the same robot, nothing held
    bare.step()
    _drive(bare, "carrier", W)
    _run(bare, N)
    pose = sim.robot("carrier").pose
    assert pose.translation.tolist() == bare.robot("carrier").pose.translation.tolist()
    assert np.array_equal(pose.rotation, bare.robot("carrier").pose.rotation)
    assert pose.translation[0] == pytest.approx(0.125 * N * STEP / 1000.0, abs=1e-12)      # v·t = 0.3 m
    assert pose.translation[1] == 0.0 and pose.translation[2] == start.translation[2]
    assert sim.counters["contacts"] == 0
    parcel = sim.scene.solid_poses["parcel"]
    held = g.frame().compose(g._offset)                                  # type: ignore[attr-defined]
    assert np.array_equal(parcel.translation, held.translation) and np.array_equal(parcel.rotation, held.rotation)
    assert parcel.translation[0] == pytest.approx(0.17 + 0.3, abs=1e-12)
    assert parcel.translation[1:].tolist() == [0.0, 0.05] and np.array_equal(parcel.rotation, np.eye(3))


def test_a_turning_carrier_swings_its_load_about_itself() -> None:
    """Wheels at -W and W turn it in place by W·0.05/0.1 rad/s: the parcel, 0.17 m ahead, goes round."""
    sim = _sim([PARCEL], [_carrier()])
    sim.step()
    _drive(sim, "carrier", 0.0)
    left, right = sim.robot("carrier").motors.values()
    left.set_velocity(-W)
    right.set_velocity(W)
    _run(sim, 50)
    yaw = math.atan2(sim.robot("carrier").pose.rotation[1, 0], sim.robot("carrier").pose.rotation[0, 0])
    assert yaw == pytest.approx(W * 0.05 / 0.1 * 50 * STEP / 1000.0, abs=1e-12)    # not stopped by its own load
    assert sim.scene.solid_poses["parcel"].translation[:2] == pytest.approx([0.17 * math.cos(yaw), 0.17 * math.sin(yaw)],
                                                                            abs=1e-12)


def test_another_robot_is_stopped_by_the_carried_parcel_and_sees_it_there() -> None:
    sim = _sim([PARCEL], [_carrier(), _other()])
    ds = sim.device("other/ds")
    ds.enable(STEP)
    sim.step()
    _drive(sim, "carrier", W)
    _run(sim, N)
    _drive(sim, "carrier", 0.0)
    sim.step()
    front = sim.scene.solid_poses["parcel"].translation[0] + 0.05        # the parcel's +x face, 0.52
    assert front == pytest.approx(0.52, abs=1e-12)
    assert ds.value == pytest.approx(1.0 - 0.1 - front, abs=1e-12)      # the other's sensor sees it there
    _drive(sim, "other", W)                                             # 0.38 m to go: 190 steps; it stops
    _run(sim, 250)
    x = sim.robot("other").pose.translation[0]
    assert x == pytest.approx(front + 0.1, abs=1e-9) and x >= front + 0.1
    assert sim.counters["contacts"] > 0
    assert sim.scene.solid_poses["parcel"].translation[0] + 0.05 == front         # not pushed


def test_a_bumper_does_not_feel_the_load_it_carries() -> None:
    """A bumper whose pad is the gripper's front face: touching the parcel it holds is no touch."""
    robot = _carrier()
    robot["shapes"].append({"pose": {"translation": [0.115, 0.0, 0.0]}, "geometry": {"type": "box", "size": [0.01, 0.08, 0.04]},
                            "of_device": "bump", "seen_by": "bounding"})
    robot["devices"].append({"device": "TouchSensor", "name": "bump", "type": "bumper",
                             "pose": {"translation": [0.115, 0.0, 0.0]}})
    sim = _sim([PARCEL], [robot])
    bump = sim.device("carrier/bump")
    bump.enable(STEP)
    g = sim.device("carrier/cup")
    g.set_on(False)                                                     # type: ignore[attr-defined]
    _run(sim, 2)
    assert bump.value == 1.0                                            # touching the parcel it does not hold
    g.set_on(True)                                                      # type: ignore[attr-defined]
    _run(sim, 2)
    assert g.held == "parcel" and bump.value == 0.0                     # type: ignore[attr-defined]


# ---------------------------------------------------------------------- letting go

FLOOR_Z = 0.013
TABLE = {"name": "table", "pose": {"translation": [1.0, 0.0, 0.2]}, "geometry": {"type": "box", "size": [0.6, 0.6, 0.4]}}


def _crane_world(parcel_bottom: float, x: float = 0.0, yaw: float = 0.4) -> Simulation:
    """The crane's cup (its bottom face at the parcel's top) over a parcel whose bottom is at
    ``parcel_bottom``, turned by ``yaw`` about z, at (x, 0)."""
    top = parcel_bottom + 0.1
    crane = {"name": "crane", "pose": {"translation": [x, 0.0, top]},
             "shapes": [{"pose": {"translation": [0.0, 0.0, 0.01]}, "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.02},
                         "of_device": "cup", "seen_by": "bounding"}],
             "devices": [{"device": "VacuumGripper", "name": "cup", "is_on": True}]}
    parcel = {**PARCEL, "pose": {"translation": [x, 0.0, parcel_bottom + 0.05], "rotation": [0, 0, 1, yaw]}}
    return Simulation(parse_world({"world_info": {"basic_time_step": STEP},
                                   "solids": [{"name": "floor", "pose": {"translation": [0.0, 0.0, FLOOR_Z]},
                                               "geometry": {"type": "plane"}}, TABLE, parcel],
                                   "robots": [crane]}), precision="exact")


def _fallen(sim: Simulation, name: str = "parcel") -> None:
    """Steps until ``name`` has stopped falling (at most 2 s)."""
    for _ in range(125):
        sim.step()
        if name not in sim.falls.falling:
            return
    raise AssertionError(f"{name} still falls")


def test_a_parcel_let_go_above_the_floor_falls_onto_it() -> None:
    """0.2 m of fall at 9.81 m/s²: sqrt(0.4 / 9.81) = 0.2019 s, at rest at the 13th step's end (0.208 s)."""
    sim = _crane_world(FLOOR_Z + 0.2)
    g = sim.device("crane/cup")
    sim.step()
    assert g.held == "parcel"                                           # type: ignore[attr-defined]
    before = sim.scene.solid_poses["parcel"]
    g.set_on(False)                                                     # type: ignore[attr-defined]
    assert sim.scene.solid_poses["parcel"] is before                    # let go where it is
    z0 = float(before.translation[2])
    for k in range(1, 13):
        sim.step()
        t = k * STEP / 1000.0
        now = sim.scene.solid_poses["parcel"]
        assert now.translation[2] == pytest.approx(z0 - 9.81 * t * t / 2.0, abs=1e-12), k
        assert now.translation[:2].tolist() == before.translation[:2].tolist()
        assert np.array_equal(now.rotation, before.rotation)
    sim.step()
    after = sim.scene.solid_poses["parcel"]
    assert "parcel" not in sim.falls.falling
    assert after.translation[2] == pytest.approx(FLOOR_Z + 0.05, abs=1e-12)      # its bottom on the floor
    assert after.translation[:2].tolist() == before.translation[:2].tolist()
    assert np.array_equal(after.rotation, before.rotation)              # turned as it was
    sim.step()
    assert sim.scene.solid_poses["parcel"] is after                     # and it stays


def test_a_parcel_let_go_over_the_table_lands_on_it_and_beside_it_on_the_floor() -> None:
    for x, support in ((1.2, 0.4), (1.35, FLOOR_Z), (0.65, FLOOR_Z)):   # over the table; its centre beside it
        sim = _crane_world(0.6, x=x)
        g = sim.device("crane/cup")
        sim.step()
        g.set_on(False)                                                 # type: ignore[attr-defined]
        _fallen(sim)
        assert sim.scene.solid_poses["parcel"].translation[2] == pytest.approx(support + 0.05, abs=1e-12), x


def test_a_parcel_half_sunk_into_the_table_rises_onto_it_one_sunk_deeper_falls_to_the_floor() -> None:
    """A support is one not above the middle of the parcel's height (+ 1 mm): settling's rule."""
    for bottom, support in ((0.36, 0.4), (0.29, FLOOR_Z)):
        sim = _crane_world(bottom, x=1.0)
        g = sim.device("crane/cup")
        sim.step()
        g.set_on(False)                                                 # type: ignore[attr-defined]
        _fallen(sim)
        assert sim.scene.solid_poses["parcel"].translation[2] == pytest.approx(support + 0.05, abs=1e-12), bottom


def test_a_carried_parcel_let_go_on_the_move_lands_where_it_was_let_go() -> None:
    sim = _sim([{**PARCEL, "pose": {"translation": [0.17, 0.0, 0.05]}}], [_carrier()])
    g = sim.device("carrier/cup")
    sim.step()
    _drive(sim, "carrier", W)
    _run(sim, 20)
    where = sim.scene.solid_poses["parcel"]
    x = sim.robot("carrier").pose.translation[0]
    assert x == pytest.approx(0.125 * 20 * STEP / 1000.0, abs=1e-12) and where.translation[0] == pytest.approx(0.17 + x, abs=1e-12)
    g.set_on(False)                                                     # type: ignore[attr-defined]
    sim.step()
    assert sim.scene.solid_poses["parcel"] is where                     # on the floor already: bit for bit
    _run(sim, 10)
    assert sim.scene.solid_poses["parcel"] is where
    # an obstacle to its carrier again from the moment it is let go: the robot, still driving, stays
    # where it was (the parcel touches its pad)
    assert sim.robot("carrier").pose.translation[0] == x and sim.counters["contacts"] == 11


def test_reset_puts_everything_back() -> None:
    sim = _crane_world(FLOOR_Z + 0.2)
    g = sim.device("crane/cup")
    sim.step()
    initial = Pose(sim._initial["solids"]["parcel"].rotation, sim._initial["solids"]["parcel"].translation)
    g.set_on(False)                                                     # type: ignore[attr-defined]
    sim.step()
    assert sim.scene.solid_poses["parcel"].translation[2] != initial.translation[2]
    sim.reset()
    assert g.is_on and g.held is None                                   # type: ignore[attr-defined]
    assert sim.scene.solid_poses["parcel"].translation.tolist() == initial.translation.tolist()
    sim.step()
    assert g.held == "parcel"                                           # type: ignore[attr-defined]

    car = _sim([PARCEL], [_carrier()])
    car.step()
    _drive(car, "carrier", W)
    _run(car, 30)
    car.reset()
    assert car.device("carrier/cup").held is None                       # type: ignore[attr-defined]
    assert car.contact is not None and car.contact.carried == {}
    assert car.scene.solid_poses["parcel"].translation.tolist() == [0.17, 0.0, 0.05]
    assert car.robot("carrier").pose.translation.tolist() == [0.0, 0.0, 0.05]


# ---------------------------------------------------------------------- which of several

def _two_parcels(depth_a: float, depth_b: float) -> Simulation:
    """The crane's cup (bottom face at z = 0.5) over two 0.1 m parcels, "a" (first in the file) at
    x = -0.055 and "b" at x = 0.055 (0.01 m apart), each pushed ``depth`` into the cup along z (negative: that far below)."""
    crane = {"name": "crane", "pose": {"translation": [0.0, 0.0, 0.5]},
             "shapes": [{"pose": {"translation": [0.0, 0.0, 0.01]}, "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.02},
                         "of_device": "cup", "seen_by": "bounding"}],
             "devices": [{"device": "VacuumGripper", "name": "cup", "is_on": True}]}
    parcels = [{**PARCEL, "name": n, "pose": {"translation": [x, 0.0, 0.45 + d]}} for n, x, d in (("a", -0.055, depth_a),
                                                                                                    ("b", 0.055, depth_b))]
    return Simulation(parse_world({"world_info": {"basic_time_step": STEP}, "solids": parcels, "robots": [crane]}),
                      precision="exact")


@pytest.mark.parametrize(("depth_a", "depth_b", "taken"), [(-0.0005, 0.003, "b"), (0.003, -0.0005, "a"),
                                                           (0.002, 0.004, "b"), (0.004, 0.002, "a"),
                                                           (0.002, 0.002, "a"), (-0.0005, -0.0002, "b")])
def test_of_several_touched_the_deepest_is_taken(depth_a: float, depth_b: float, taken: str) -> None:
    """Webots attaches the solid of the deepest contact: here the larger overlap along z (the parcels'
    sections reach 0.055 m into the cup's disc, deeper than any z overlap), or the smaller gap."""
    sim = _two_parcels(depth_a, depth_b)
    g = sim.device("crane/cup")
    assert g.touched() == taken                                         # type: ignore[attr-defined]
    sim.step()
    assert g.held == taken                                              # type: ignore[attr-defined]


def test_prism_depth_closed_forms() -> None:
    cup = _shape_obstacle(geo.Cylinder(0.05, 0.02), Pose(np.eye(3), [0.0, 0.0, 0.51]))
    box = _shape_obstacle(geo.Box((0.1, 0.1, 0.1)), Pose(np.eye(3), [0.08, 0.0, 0.46]))    # x from 0.03, z to 0.51
    assert cup is not None and box is not None
    assert prism_depth(cup, box) == pytest.approx(0.01, abs=1e-15)        # z overlap 0.01 < the disc's 0.02 into it
    low = _shape_obstacle(geo.Box((0.1, 0.1, 0.1)), Pose(np.eye(3), [0.08, 0.0, 0.3]))     # top 0.35: 0.15 below
    assert low is not None and prism_depth(cup, low) == pytest.approx(-0.15, abs=1e-15)
    side = _shape_obstacle(geo.Box((0.1, 0.1, 0.1)), Pose(np.eye(3), [0.099, 0.0, 0.51]))  # x from 0.049
    assert side is not None and prism_depth(cup, side) == pytest.approx(0.001, abs=1e-15)  # 1 mm into the disc


def test_in_a_nue_world_it_falls_along_the_world_y() -> None:
    """NUE (x north, y up, z east): the floor Plane turned so its normal is the world's y, at y = 0.2;
    the cup (a box thin along y) holds the parcel by its top at y = 0.9; let go, its y becomes 0.25."""
    floor = {"name": "floor", "pose": {"translation": [0.0, 0.2, 0.0], "rotation": [1, 0, 0, -math.pi / 2]},
             "geometry": {"type": "plane"}}
    crane = {"name": "crane", "pose": {"translation": [0.3, 0.9, -0.2]},
             "shapes": [{"pose": {"translation": [0.0, 0.01, 0.0]}, "geometry": {"type": "box", "size": [0.1, 0.02, 0.1]},
                         "of_device": "cup", "seen_by": "bounding"}],
             "devices": [{"device": "VacuumGripper", "name": "cup", "is_on": True}]}
    parcel = {**PARCEL, "pose": {"translation": [0.3, 0.85, -0.2]}}
    sim = Simulation(parse_world({"world_info": {"basic_time_step": STEP, "coordinate_system": "NUE"},
                                  "solids": [floor, parcel], "robots": [crane]}), precision="exact")
    g = sim.device("crane/cup")
    sim.step()
    assert g.held == "parcel"                                           # type: ignore[attr-defined]
    g.set_on(False)                                                     # type: ignore[attr-defined]
    sim.step()
    t = sim.scene.solid_poses["parcel"].translation                    # falling along -y: 0.6 m in 0.35 s
    assert t[1] == pytest.approx(0.85 - 9.81 * 0.016 ** 2 / 2.0, abs=1e-12) and (t[0], t[2]) == (0.3, -0.2)
    _fallen(sim)
    t = sim.scene.solid_poses["parcel"].translation
    assert t[1] == pytest.approx(0.2 + 0.05, abs=1e-12) and (t[0], t[2]) == (0.3, -0.2)


def test_contact_moves_a_carried_solid_in_place_as_a_rebuild_would() -> None:
    """Contact.update_solid changes a moved solid's rows in place (a carried solid moves every step):
    the arrays and obstacles a full rebuild makes, bit for bit, with other solids around it."""
    boxes = [{"name": f"b{i}", "pose": {"translation": [1.0 + 0.3 * i, 0.5, 0.05]},
              "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}} for i in range(4)]
    sim = _sim([boxes[0], PARCEL, *boxes[1:]], [_carrier(), _other(x=2.5)])
    sim.step()
    _drive(sim, "carrier", W)
    _run(sim, 30)
    c = sim.contact
    assert c is not None
    kept = [a.copy() for a in (c._lo, c._hi, c._zlo, c._zhi)]
    obs = list(c._obs)
    assert obs[1].name == "parcel" and obs[1].lo[0] == pytest.approx(0.17 - 0.05 + 0.125 * 30 * STEP / 1000.0, abs=1e-12)
    c._rebuild()
    assert all(np.array_equal(a, b) for a, b in zip(kept, (c._lo, c._hi, c._zlo, c._zhi)))
    assert all(a is b for a, b in zip(obs, c._obs))
