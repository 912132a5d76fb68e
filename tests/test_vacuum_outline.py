"""A load a VacuumGripper holds is part of its carrier's outline (contact.Contact.hold, _clip_carrying).

The carrier of tests/test_vacuum_load.py: a 0.2 m square body (z 0.03 to 0.11) whose gripper pad's front
face is at x = 0.12, holding a 0.1 m parcel centred 0.17 m ahead (its far face 0.22 m ahead of the
robot's origin, z 0 to 0.1); wheels at 2.5 rad/s drive it 0.125 m/s. A wall: a box whose near face is at
x = 0.6. Closed forms: the carrier stops with the parcel's face on the wall (origin at 0.6 - 0.22); with
nothing held, its pad's face on it (0.6 - 0.12)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from tests.test_vacuum_load import PARCEL, STEP, W, _carrier, _drive, _run, _sim


def _wall(height: float = 0.3) -> dict:
    return {"name": "wall", "pose": {"translation": [0.65, 0.0, height / 2.0]},
            "geometry": {"type": "box", "size": [0.1, 2.0, height]}}


def _high_carrier() -> dict:
    """The carrier with its pad 0.1 m higher (z 0.12 to 0.18): it holds the parcel at z 0.10 to 0.20."""
    robot = _carrier()
    robot["shapes"][1]["pose"]["translation"] = [0.11, 0.0, 0.1]
    robot["devices"][0]["pose"]["translation"] = [0.11, 0.0, 0.1]
    return robot


HIGH_PARCEL = {**PARCEL, "pose": {"translation": [0.17, 0.0, 0.15]}}


def _x(sim: Simulation) -> float:
    return float(sim.robot("carrier").pose.translation[0])


def _yaw(sim: Simulation) -> float:
    r = sim.robot("carrier").pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


def test_a_carrier_stops_where_its_load_meets_the_wall() -> None:
    sim = _sim([_wall(), PARCEL], [_carrier()])
    sim.step()
    assert sim.device("carrier/cup").held == "parcel"                   # type: ignore[attr-defined]
    _drive(sim, "carrier", W)
    _run(sim, 250)                                                      # 0.38 m to go: 190 steps
    x = _x(sim)
    assert x == pytest.approx(0.6 - 0.22, abs=1e-9) and x <= 0.6 - 0.22
    face = sim.scene.solid_poses["parcel"].translation[0] + 0.05
    assert face == pytest.approx(0.6, abs=1e-9) and face <= 0.6          # the parcel's face on the wall, not in it
    assert sim.counters["contacts"] > 0


def test_without_a_load_it_drives_to_its_own_pad() -> None:
    sim = _sim([_wall()], [_carrier()])
    _drive(sim, "carrier", W)
    _run(sim, 300)
    assert _x(sim) == pytest.approx(0.6 - 0.12, abs=1e-9) and _x(sim) <= 0.6 - 0.12


def test_a_load_held_above_the_wall_does_not_stop_it() -> None:
    """The wall 0.09 m tall, the parcel held from z 0.10: the carrier drives until its body (z 0.03 to
    0.11, its front face at x = 0.1) meets the wall, as with nothing held, bit for bit: its pad (z 0.12 to
    0.18) sticks out of the body's square, so the robot's footprint is its pieces (a concave robot's),
    each with its own band, and the pad passes over the wall as the parcel held above it does."""
    loaded = _sim([_wall(0.09), HIGH_PARCEL], [_high_carrier()])
    loaded.step()
    assert loaded.device("carrier/cup").held == "parcel"                # type: ignore[attr-defined]
    bare = _sim([_wall(0.09)], [_high_carrier()])
    bare.step()
    for sim in (loaded, bare):
        _drive(sim, "carrier", W)
        _run(sim, 300)
    assert _x(loaded) == _x(bare)
    assert _x(loaded) == pytest.approx(0.6 - 0.1, abs=1e-9)            # the pad and the parcel over the wall
    assert bare.scene.solid_poses.get("parcel") is None
    assert loaded.scene.solid_poses["parcel"].translation[0] + 0.05 > 0.6 + 0.09


def test_a_high_load_leaves_the_carriers_floor_line_its_own() -> None:
    """The parcel held high reaches no lower than the robot: its band, the one kinematic contact's floor
    rule and the ground's support ceiling use, is the robot's own."""
    sim = _sim([HIGH_PARCEL], [_high_carrier()])
    c = sim.contact
    assert c is not None
    own = c.feet[0]
    sim.step()
    assert c.feet[0] is own and list(c.loads[0]) == ["parcel"]
    (piece,) = c.loads[0]["parcel"]
    assert (piece.z_low, piece.z_high) == pytest.approx((0.05, 0.15), abs=1e-15)   # from the origin at z 0.05
    assert c._z_low[0] == own.z_low


def test_a_turn_that_would_swing_the_load_into_a_wall_is_cut_short() -> None:
    """A wall whose face is at y = 0.15 beside the carrier (its body reaches 0.1414 m, its pad 0.13 m: they
    turn clear); turning in place counter-clockwise, the parcel's far corner (0.22, 0.05) meets it where
    0.22 sin θ + 0.05 cos θ = 0.15. Nothing held, the same robot turns on."""
    wall = {"name": "side", "pose": {"translation": [0.0, 0.2, 0.15]}, "geometry": {"type": "box", "size": [2.0, 0.1, 0.3]}}
    limit = math.asin(0.15 / math.hypot(0.22, 0.05)) - math.atan2(0.05, 0.22)
    per_step = W * 0.05 / 0.1 * STEP / 1000.0
    for parcel, expect in (([PARCEL], limit), ([], per_step * 60)):
        sim = _sim([wall, *parcel], [_carrier()])
        sim.step()
        left, right = sim.robot("carrier").motors.values()
        for m, w in ((left, -W), (right, W)):
            m.set_position(math.inf)
            m.set_velocity(w)
        _run(sim, 60)                                                   # 1.2 rad if free
        yaw = _yaw(sim)
        if parcel:
            assert limit - per_step * 2.0 ** -12 <= yaw <= limit + 1e-9
            t = sim.scene.solid_poses["parcel"]
            corner = t.translation + t.rotation @ np.array([0.05, 0.05, 0.0])
            assert corner[1] == pytest.approx(0.15, abs=1e-6) and corner[1] <= 0.15 + 1e-9
            assert sim.robot("carrier").pose.translation[:2].tolist() == [0.0, 0.0]
        else:
            assert yaw == pytest.approx(expect, abs=1e-12)


def test_let_go_it_backs_off_and_drives_on_as_if_it_never_held_anything() -> None:
    sim = _sim([_wall(), PARCEL], [_carrier()])
    sim.step()
    _drive(sim, "carrier", W)
    _run(sim, 250)
    stop = _x(sim)
    sim.device("carrier/cup").set_on(False)                             # type: ignore[attr-defined]
    sim.step()                                                          # still pressing on: stays
    assert _x(sim) == stop and sim.contact is not None and sim.contact.loads == {}
    twin = _sim([_wall()], [{**_carrier(), "pose": {"translation": [stop, 0.0, 0.05]}}])
    twin.device("carrier/cup").set_on(False)                            # type: ignore[attr-defined]
    twin_foot = twin.contact.feet[0]                                    # type: ignore[union-attr]
    assert sim.contact.feet[0].points.tolist() == twin_foot.points.tolist()       # type: ignore[union-attr]
    plan = [(-W, -W, 100), (-W, W, 40), (W, W, 60), (W, -W, 20), (W, W, 200)]
    for left_w, right_w, n in plan:
        for s in (sim, twin):
            left, right = s.robot("carrier").motors.values()
            for m, w in ((left, left_w), (right, right_w)):
                m.set_position(math.inf)
                m.set_velocity(w)
        for _ in range(n):
            sim.step()
            twin.step()
            a, b = sim.robot("carrier").pose, twin.robot("carrier").pose
            assert a.translation.tolist() == b.translation.tolist() and np.array_equal(a.rotation, b.rotation)
