"""Box floors are ground in a world with terrains (sim/ground.py): a robot rides the top of an upright
Box as it rides a floor plane, from a terrain onto it and back, with continuous heights; a box top
counts for a robot only if it is not above the robot's support ceiling (its band bottom, or the ground
it rides, whichever is higher, plus contact.FLOOR), so a table top above it never becomes its ground
and it is never lifted onto what kinematic contact would stop it at. Closed forms, and the batched
copies bit for bit."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim import contact as cmod
from sensorium.server.sim import ground as gmod
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world import geometry as geo
from sensorium.server.world.geometry import Pose
from sensorium.server.world.loader import parse_world
from tests._copies import drive_and_compare, ground_copies
from tests.test_batched_nue import TO_NUE

SLOPE = 0.25
DX = 0.5
DECK = 0.25 + 0.1 / 2          # the deck's top: its centre plus half its height, as Ground computes it
HALF = 0.04                    # the robots' body: a cylinder 0.08 m tall centred on the origin
DRIVE = {"wheel_radius": 0.05, "axle_length": 0.25, "max_wheel_speed": 12.0}
BODY = {"geometry": {"type": "cylinder", "radius": 0.1, "height": 2 * HALF}}


def _box(name: str, centre, size) -> dict:
    return {"name": name, "pose": {"translation": list(centre)}, "geometry": {"type": "box", "size": list(size)}}


def _shelf(floor: bool = True, extra: tuple = ()) -> list[dict]:
    """A deck (a Box floor, top at 0.3 over x in [-2, 0]) meeting a ramp (a terrain rising along +x
    from 0.3 at x = 0), a table top 0.5 m above the deck (x in [-1.8, -1.2]) and a floor plane at 0."""
    heights = [0.3 + SLOPE * i * DX for j in range(5) for i in range(5)]
    solids = [_box("deck", (-1.0, 0.0, 0.25), (2.0, 2.0, 0.1)),
              {"name": "ramp", "pose": {"translation": [0.0, -1.0, 0.0]},
               "geometry": {"type": "elevation_grid", "height": heights, "x_dimension": 5, "x_spacing": DX,
                            "y_dimension": 5, "y_spacing": DX}},
              _box("table", (-1.5, 0.0, 0.78), (0.6, 1.0, 0.04)), *extra]
    return ([{"name": "floor", "geometry": {"type": "plane"}}] if floor else []) + solids


def _robot(name: str, at, yaw: float = 0.0) -> dict:
    return {"name": name, "pose": {"translation": list(at), "rotation": [0, 0, 1, yaw]}, "body": BODY,
            "differential_drive": DRIVE}


def _sim(solids: list[dict], at, yaw: float = 0.0, contact: bool | None = None) -> Simulation:
    with warnings.catch_warnings():
        warnings.simplefilter("error")                 # no "starts over no ground" warning
        return Simulation(parse_world({"solids": solids, "robots": [_robot("r", at, yaw)]}), precision="exact",
                          contact=contact)


def _drive(sim: Simulation, left: float, right: float) -> None:
    d = sim.robot("r").drive
    for m in (*d.lefts, *d.rights):
        m.set_position(math.inf)
    for m in d.lefts:
        m.set_velocity(left)
    for m in d.rights:
        m.set_velocity(right)


def _ramp_z(x: float) -> float:
    return 0.3 + SLOPE * x


# ---------------------------------------------------------------------- closed forms

def test_a_robot_on_a_box_floor_rides_it_onto_a_terrain_at_its_height_and_back() -> None:
    """Placed on the deck under the table (no warning): its ground is the deck's top; it drives under
    the table at exactly its start height, onto the ramp at 0.3 + slope·x + its clearance (continuous
    at the seam, never more than a step's rise apart), and back onto the deck at its start height."""
    z0 = DECK + HALF
    sim = _sim(_shelf(), at=(-1.9, 0.0, z0))
    r = sim.robot("r")
    assert r.drive.rest == DECK and r.drive.slope is None
    start = r.pose
    _drive(sim, 12.0, 12.0)
    on_deck = on_ramp = 0
    last = z0
    for _ in range(170):
        sim.step()
        x, _, z = r.pose.translation
        assert abs(z - last) <= SLOPE * 0.6 * 0.032 + 1e-12          # continuous: at most a step's rise
        last = z
        if x <= 0.0:
            assert z == z0 and np.array_equal(r.pose.rotation, start.rotation)
            on_deck += 1
        elif x <= 2.0:
            assert abs(z - (_ramp_z(x) + (z0 - DECK))) <= 1e-12
            on_ramp += 1
    assert on_deck > 80 and on_ramp > 60 and not r.pressing
    _drive(sim, -12.0, -12.0)
    for _ in range(170):
        sim.step()
    assert r.pose.translation[0] < -0.5
    assert r.pose.translation[2] == z0 and np.array_equal(r.pose.rotation, start.rotation)


def test_from_a_terrain_onto_a_box_floor_over_a_lower_plane_the_robot_stays_on_the_box() -> None:
    """Started on the ramp and driven back onto the deck, the robot rides the deck's top (0.3) with
    the clearance it had on the ramp; the floor plane 0.3 m below never takes it (it does not drop
    through the box floor)."""
    x0 = 0.8
    z0 = _ramp_z(x0) + HALF
    sim = _sim(_shelf(), at=(x0, 0.0, z0))
    r = sim.robot("r")
    clearance = z0 - r.drive.rest
    _drive(sim, -12.0, -12.0)
    seen = 0
    last = z0
    for _ in range(100):
        sim.step()
        x, _, z = r.pose.translation
        assert abs(z - last) <= SLOPE * 0.6 * 0.032 + 1e-12
        last = z
        if x <= 0.0:
            assert abs(z - (DECK + clearance)) <= 1e-12 and np.array_equal(r.pose.rotation, np.eye(3))
            seen += 1
    assert seen > 20


def test_a_table_top_above_the_robot_never_becomes_its_ground() -> None:
    """The table's top is 0.5 m above the deck: a robot on the deck under it rides the deck; put there
    by a supervisor it rides the deck; only a robot placed on the table itself rides the table."""
    z0 = DECK + HALF
    sim = _sim(_shelf(), at=(-1.5, 0.0, z0))
    r = sim.robot("r")
    assert r.drive.rest == DECK
    r.set_pose([-1.4, 0.2, z0])
    assert r.drive.rest == DECK
    _drive(sim, 3.0, 3.5)
    sim.run(300)
    assert r.pose.translation[2] == z0
    top = 0.78 + 0.04 / 2
    on_table = _sim(_shelf(), at=(-1.5, 0.0, top + HALF))
    assert on_table.robot("r").drive.rest == top


def test_the_support_ceiling_is_the_contact_floor_rule_bit_for_bit() -> None:
    """A box top counts under a point only if it is not above the ceiling given there: a top exactly
    at the ceiling is ground, one ulp above is not; with no box eligible the terrain or plane under
    the point is the ground. The ceiling the robots use is contact's floor line (band bottom + FLOOR),
    computed with the same operations, so a box is either ground for a robot or an obstacle to it."""
    sim = _sim(_shelf(), at=(-1.9, 0.0, DECK + HALF))
    g = sim.ground
    x, y = np.array([-0.5, -0.5]), np.array([0.0, 0.0])
    found, z, _, _ = g.under(x, y, np.array([DECK, np.nextafter(DECK, -math.inf)]))
    assert found.all() and z[0] == DECK and z[1] == 0.0               # the deck; else the floor plane
    band_low = cmod.robot_footprint([(geo.Cylinder(0.1, 2 * HALF), Pose.identity())]).z_low
    assert band_low == -HALF
    zr = DECK + HALF
    ceiling = gmod.support_ceiling(np.array([zr]), np.array([band_low]), np.array([zr]), np.array([DECK]))
    assert ceiling[0] == (zr + band_low) + cmod.FLOOR                    # contact's band_lo + FLOOR


def test_a_step_within_the_floor_tolerance_is_ridden_and_a_kerb_stops_the_robot_on_its_step() -> None:
    """Beyond the deck a step 0.5 mm higher, then a kerb 1 cm above the step. The robot rides onto the
    step (its height rises by the half millimetre: contact takes the step for its floor too) and is
    stopped at the kerb by contact, not lifted onto it; with contact off it passes over the kerb at
    the step's height (the kerb's top is above its ceiling: never ground for it)."""
    step = _box("step", (0.5, 3.0, 0.25025), (1.0, 2.0, 0.1))          # top 0.3005 over x in [0, 1]
    kerb = _box("kerb", (1.5, 3.0, 0.2555), (1.0, 2.0, 0.11))          # top 0.311 over x in [1, 2]
    deck = _box("deck2", (-1.0, 3.0, 0.25), (2.0, 2.0, 0.1))
    solids = _shelf(floor=False, extra=(deck, step, kerb))
    step_top, kerb_top = 0.25025 + 0.05, 0.2555 + 0.055
    z0 = DECK + HALF
    for contact in (True, False):
        sim = _sim(solids, at=(-0.5, 3.0, z0), contact=contact)
        r = sim.robot("r")
        _drive(sim, 8.0, 8.0)
        for _ in range(170):
            sim.step()
            x, _, z = r.pose.translation
            if x <= 0.0:
                assert z == z0
            elif x <= 1.0:
                assert z == step_top + (z0 - DECK)
            else:
                assert not contact and z == step_top + (z0 - DECK)       # over the kerb: not lifted
        x = r.pose.translation[0]
        if contact:
            assert r.pressing and x == pytest.approx(1.0 - 0.1, abs=1e-9)   # its disc against the kerb
        else:
            assert x > 1.5
    assert kerb_top > step_top + cmod.FLOOR


def test_without_a_terrain_box_floors_do_not_make_a_ground() -> None:
    """The rule is the terrain worlds': in a world without a terrain there is no Ground (robots keep
    their heights, as they always did)."""
    sim = Simulation(parse_world({"solids": [_box("deck", (-1.0, 0.0, 0.25), (2.0, 2.0, 0.1))],
                                  "robots": [_robot("r", (-1.0, 0.0, DECK + HALF))]}), precision="exact")
    assert sim.ground is None


def test_a_tilted_box_is_not_ground_and_a_box_turned_on_its_side_is() -> None:
    """A box none of whose faces leans less than 45° from up (standing on a corner: every face 54.7°)
    has no top to ride (a box tilted less is a ramp: test_ground_ramp.py); one turned a quarter about x
    (exactly: its local y is the world's up) has its top at its centre plus half its y size."""
    tilted = _box("tilted", (0.0, 5.0, 0.0), (1.0, 1.0, 0.1))
    tilted["pose"]["rotation"] = [1 / math.sqrt(2), -1 / math.sqrt(2), 0, math.acos(1 / math.sqrt(3))]
    side = _box("side", (3.0, 5.0, 0.0), (1.0, 0.4, 2.0))
    side["pose"]["rotation"] = [1, 0, 0, math.pi / 2]
    sim = _sim(_shelf(extra=(tilted, side)), at=(-1.9, 0.0, DECK + HALF))
    g = sim.ground
    big = np.full(1, 10.0)
    assert g.under(np.array([0.0]), np.array([5.0]), big)[1][0] == 0.0                 # the floor plane
    found, z, _, _ = g.under(np.array([3.0, 3.0, 3.6]), np.array([5.0, 6.2, 5.0]), np.full(3, 10.0))
    assert found.all() and z[0] == pytest.approx(0.2, abs=1e-15) and z[1] == 0.0 and z[2] == 0.0
    assert g.under(np.array([3.0]), np.array([5.0]), np.full(1, 0.2 - 1e-6))[1][0] == 0.0   # above the ceiling


# ---------------------------------------------------------------------- batched

def _world(seed: int) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"random_seed": seed},
        "solids": _shelf(extra=(_box("step", (0.5, 3.0, 0.25025), (1.0, 2.0, 0.1)),
                                _box("kerb", (1.5, 3.0, 0.2555), (1.0, 2.0, 0.11)),
                                _box("deck2", (-1.0, 3.0, 0.25), (2.0, 2.0, 0.1)))),
        "robots": [_robot("a", (-1.6, 0.2, DECK + HALF), 0.1), _robot("b", (0.6, -0.3, _ramp_z(0.6) + HALF), 3.0),
                   _robot("c", (-0.8, 3.1, DECK + HALF), 0.05)]})


@pytest.mark.parametrize("c_drive,nue", [(True, False), (False, False), (True, True)])
def test_copies_riding_box_floors_and_terrains_are_the_single_simulation_bit_for_bit(c_drive, nue):
    """Three robots on the deck, the ramp and the step/kerb, random wheel commands, a supervisor move
    onto the table in one copy: every copy's poses equal a Simulation's after every step, bit for
    bit, through the C drive and the numpy one; and the same world written in NUE axes (y up), where
    robot b, starting on the ramp's slope, has its upright footprint in both (its world-file pose)."""
    bs, sims, up = ground_copies(_world, nue, c_drive)
    onto = (TO_NUE @ np.array([-1.5, 0.0, 0.8 + HALF])).tolist() if nue else [-1.5, 0.0, 0.8 + HALF]
    heights = drive_and_compare(bs, sims, ("a", "b", "c"), np.random.default_rng(7), 150, 15, 30, (70, "a", onto), up)
    assert DECK + HALF in heights and len(heights) > 10
    assert sims[1].robot("a").drive.rest == pytest.approx(0.78 + 0.04 / 2, abs=1e-15)   # put on the table: it rides it


def test_random_start_from_under_a_table_keeps_the_robots_clearance_above_its_own_ground() -> None:
    """gym's random_start measures the clearance above the ground the robot rides (the deck under the
    table, not the table top above it) and keeps it where the robot lands on the deck."""
    from sensorium.gym.task import random_start

    z0 = DECK + HALF
    sim = _sim(_shelf(), at=(-1.5, 0.0, z0))
    r = sim.robot("r")
    random_start((-0.9, -0.5), (-0.5, 0.5))(sim, r, np.random.default_rng(2))
    assert -0.9 <= r.pose.translation[0] <= -0.5
    assert r.pose.translation[2] == DECK + (z0 - DECK) and r.drive.rest == DECK


def _reference_under(g: gmod.Ground, x: float, y: float, ceiling: float) -> tuple[bool, float, float, float]:
    """The rule spelled out: every surface in world order, the first of the highest eligible."""
    best, slope, found = -math.inf, (0.0, 0.0), False
    for s in g._surfaces:
        if not s.upright:
            continue
        if s.half is not None:
            ex, ey = x - s.tx, y - s.ty
            u, v = s.r00 * ex + s.r10 * ey, s.r01 * ex + s.r11 * ey
            if abs(u) <= s.hu and abs(v) <= s.hv and s.tz <= ceiling and s.tz > best:
                best, slope, found = s.tz, (0.0, 0.0), True
        else:
            f, z, gx, gy = gmod.Ground([s], g._poses, None).under(np.array([x]), np.array([y]))
            if f[0] and z[0] > best:
                best, slope, found = float(z[0]), (float(gx[0]), float(gy[0])), True
    return found, best, *slope


def test_all_box_tops_at_once_are_the_rule_in_world_order_with_ties_moves_and_removals() -> None:
    """Ground.under takes every box top at once; its answer is the rule taken surface by surface in
    world order (the first of the highest eligible; ties between boxes, the floor plane and the ramp
    at the same height included), at random points and ceilings; a box a supervisor moves or removes
    is ground where it went, or no longer."""
    rng = np.random.default_rng(11)
    boxes = []
    for k in range(25):
        h = float(rng.choice([0.0, 0.3, 0.5, 0.05 * k]))          # ties with the plane and the deck
        box = _box(f"b{k}", (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)), h - 0.05), (0.8, 0.6, 0.1))
        box["pose"]["rotation"] = [0, 0, 1, float(rng.uniform(-3, 3))]
        boxes.append(box)
    sim = _sim(_shelf(extra=tuple(boxes)), at=(-1.9, 0.0, DECK + HALF))
    g = sim.ground
    x, y = rng.uniform(-2.5, 2.5, 400), rng.uniform(-2.5, 2.5, 400)
    ceiling = rng.choice([-1.0, 0.0, 0.3, 0.5, 0.9, math.inf], 400)
    found, z, gx, gy = g.under(x, y, ceiling)
    for k in range(400):
        want = _reference_under(g, float(x[k]), float(y[k]), float(ceiling[k]))
        assert (bool(found[k]), float(z[k]), float(gx[k]), float(gy[k])) == want, k
    sim.set_solid_pose("deck", [4.0, 0.0, 0.35])                    # top 0.4 around x = 4
    assert g.at(4.0, 0.0, 1.0)[0] == 0.35 + 0.05 and g.at(-1.0, 0.0, 1.0)[0] == 0.0
    sim.remove_solid("deck")
    assert g.at(4.0, 0.0, 1.0)[0] == 0.0
