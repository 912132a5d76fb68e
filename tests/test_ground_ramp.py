"""A tilted Box whose top face leans less than 45° from the world's up is a ramp (sim/ground.py,
contact.ramp_top): its top face is ground, a plane over a rectangle, ridden as a terrain triangle is
(height under the origin, attitude from the plane's normal), and a ramp whose low edge a robot can
drive on at is its ground, never its obstacle; one whose low edge is above its support ceiling is an
obstacle, never its ground. Closed forms: a robot driving up a ramp of angle A; its accelerometer and
altimeter; settling onto a ramp at load; a robot beside it unaffected; the batched copies bit for bit."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sensorium.schemas import world as wm
from sensorium.server.sim import contact as cmod
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests._copies import drive_and_compare, ground_copies
from tests.test_batched_nue import TO_NUE

A = 0.3                        # the ramp's angle (rad)
HX, HY, HZ = 1.0, 0.5, 0.05    # its half sizes: 2 m long along x, 1 m wide, 0.1 m thick
XLOW = 1.0                     # its top face's low edge, flush with the floor (z = 0) at x = 1
HALF = 0.04                    # the robots' body: a cylinder 0.08 m tall centred on the origin
G = 9.81
DRIVE = {"wheel_radius": 0.05, "axle_length": 0.25, "max_wheel_speed": 12.0}
BODY = {"geometry": {"type": "cylinder", "radius": 0.1, "height": 2 * HALF}}
FLOOR = {"name": "floor", "geometry": {"type": "plane"}}


def _ramp(name: str = "ramp", lift: float = 0.0, y: float = 0.0) -> dict:
    """A box turned by -A about y (its top face rising along +x), its top face's low edge at x = XLOW,
    z = lift."""
    tz = HX * math.sin(A) - HZ * math.cos(A) + lift
    tx = XLOW + HX * math.cos(A) + HZ * math.sin(A)
    return {"name": name, "pose": {"translation": [tx, y, tz], "rotation": [0, 1, 0, -A]},
            "geometry": {"type": "box", "size": [2 * HX, 2 * HY, 2 * HZ]}}


def _ramp_z(x: float, lift: float = 0.0) -> float:
    return lift + (x - XLOW) * math.tan(A)


def _robot(name: str, at, yaw: float = 0.0, **extra) -> dict:
    return {"name": name, "pose": {"translation": list(at), "rotation": [0, 0, 1, yaw]}, "body": BODY,
            "differential_drive": DRIVE, **extra}


def _sim(solids: list[dict], robots: list[dict]) -> Simulation:
    with warnings.catch_warnings():
        warnings.simplefilter("error")                 # no "starts over no ground" warning
        return Simulation(parse_world({"solids": solids, "robots": robots}), precision="exact")


def _drive(sim: Simulation, name: str, speed: float) -> None:
    for m in sim.robot(name).motors.values():
        m.set_position(math.inf)
        m.set_velocity(speed)


# ---------------------------------------------------------------------- closed forms

def test_a_robot_driving_up_a_ramp_climbs_it_pitched_and_its_accelerometer_and_altimeter_say_so() -> None:
    """From the floor at x = 0 it drives at 0.2 m/s (along the ground: its cosine along x on the ramp) onto the ramp at its low edge
    (contact on: the ramp's box never stops it): z = 0.04 before the edge, 0.04 + (x − 1)·tan A over the
    ramp; its forward axis (cos A, 0, sin A) and up axis (−sin A, 0, cos A) (pitch −A); the accelerometer
    reads gravity in that frame, (g·sin A, 0, g·cos A), once two steps were on the ramp; the altimeter z."""
    sim = _sim([FLOOR, _ramp()], [_robot("r", (0.0, 0.0, HALF), devices=[
        {"device": "Accelerometer", "name": "acc"}, {"device": "Altimeter", "name": "alt"}])])
    assert sim.contact is not None and sim.ground is not None
    for d in ("acc", "alt"):
        sim.device(f"r/{d}").enable(16)
    _drive(sim, "r", 4.0)
    on = 0
    for _ in range(300):
        sim.step()
        t, r = sim.robot("r").pose.translation, sim.robot("r").pose.rotation
        x = float(t[0])
        if x < XLOW:
            assert t[2] == HALF and on == 0
            np.testing.assert_array_equal(r, np.eye(3))
            continue
        on += 1
        assert t[2] == pytest.approx(_ramp_z(x) + HALF, abs=1e-12) and t[1] == 0.0
        np.testing.assert_allclose(r[:, 0], [math.cos(A), 0.0, math.sin(A)], atol=1e-12)
        np.testing.assert_allclose(r[:, 2], [-math.sin(A), 0.0, math.cos(A)], atol=1e-12)
        assert sim.device("r/alt").value == t[2]
        if on >= 3:
            np.testing.assert_allclose(sim.device("r/acc").values, [G * math.sin(A), 0.0, G * math.cos(A)],
                                       atol=1e-9)
    assert on > 100 and float(sim.robot("r").pose.translation[0]) < XLOW + 2 * HX * math.cos(A)


def test_a_robot_beside_the_ramp_is_unaffected() -> None:
    """Driving along x 0.2 m to the side of the ramp's footprint (its body clear of it), its poses are those
    of the same robot in the world without the ramp, bit for bit."""
    robot = _robot("r", (0.0, 0.8, HALF))
    sims = [_sim([FLOOR, _ramp()], [robot]), _sim([FLOOR], [robot])]
    for s in sims:
        _drive(s, "r", 4.0)
    for _ in range(400):
        for s in sims:
            s.step()
        a, b = (s.robot("r").pose for s in sims)
        assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes()
    assert float(sims[0].robot("r").pose.translation[0]) > XLOW + 1.0      # it went past the ramp's middle


def test_a_wheeled_robot_placed_over_a_ramp_settles_on_it_at_load_and_takes_its_attitude() -> None:
    """With wheel_bottom −0.03 (axle through its origin) placed 1 m up over x = 1.6: its height becomes
    the ramp's height there + 0.03, and it stands pitched by −A at once."""
    r = 0.03
    robot = {"name": "r", "pose": {"translation": [1.6, 0.1, 1.0]},
             "differential_drive": {"wheel_radius": r, "axle_length": 0.1, "wheel_bottom": -r}}
    sim = _sim([FLOOR, _ramp()], [robot])
    t, rot = sim.robot("r").pose.translation, sim.robot("r").pose.rotation
    assert t[0] == 1.6 and t[1] == 0.1 and t[2] == pytest.approx(_ramp_z(1.6) + r, abs=1e-12)
    np.testing.assert_allclose(rot[:, 2], [-math.sin(A), 0.0, math.cos(A)], atol=1e-12)


def test_a_robot_placed_tilted_as_the_ramp_stands_on_it_and_turning_in_place_reads_gravity_going_round() -> None:
    """Placed on the ramp already pitched by −A (as Webots' accelerometer sample places its robot): it is
    not tilted twice, its pose stays as placed; spun in place, its up axis stays the ramp's normal, its
    height is kept, and its accelerometer's gravity turns round it: z = g·cos A, |(x, y)| = g·sin A, the
    x component going from g·sin A to −g·sin A over half a turn."""
    x0, z0 = 1.5, _ramp_z(1.5) + HALF
    robot = {"name": "r", "pose": {"translation": [x0, 0.0, z0], "rotation": [0, 1, 0, -A]}, "body": BODY,
             "differential_drive": DRIVE, "devices": [{"device": "Accelerometer", "name": "acc"}]}
    sim = _sim([FLOOR, _ramp()], [robot])
    normal = [-math.sin(A), 0.0, math.cos(A)]
    np.testing.assert_allclose(sim.robot("r").pose.rotation[:, 2], normal, atol=1e-12)
    np.testing.assert_allclose(sim.robot("r").pose.rotation[:, 0], [math.cos(A), 0.0, math.sin(A)], atol=1e-12)
    sim.device("r/acc").enable(32)
    d = sim.robot("r").drive
    for m in (*d.lefts, *d.rights):
        m.set_position(math.inf)
    for m in d.lefts:
        m.set_velocity(-2.0)
    for m in d.rights:
        m.set_velocity(2.0)
    xs = []
    for _ in range(150):                                   # 0.8 rad/s: past half a turn
        sim.step()
        pose = sim.robot("r").pose
        np.testing.assert_allclose(pose.rotation[:, 2], normal, atol=1e-12)
        assert pose.translation[2] == pytest.approx(z0, abs=1e-12)
        a = sim.device("r/acc").values
        assert a[2] == pytest.approx(G * math.cos(A), abs=1e-6)
        assert math.hypot(a[0], a[1]) == pytest.approx(G * math.sin(A), abs=1e-6)
        xs.append(float(a[0]))
    assert max(xs) > 0.99 * G * math.sin(A) and min(xs) < -0.99 * G * math.sin(A)


def test_a_ramp_above_the_robots_reach_is_an_obstacle_not_its_ground_and_a_steep_box_is_neither() -> None:
    """A ramp whose low edge is 5 cm above the floor (above the robot's band bottom + 1 mm) stops it, at
    its height; the same in the contact table (its band tops out at the low edge). A box standing on a
    corner (every face 54.7° from up) is no ramp: the floor stays the ground over it."""
    sim = _sim([FLOOR, _ramp(lift=0.05)], [_robot("r", (0.0, 0.0, HALF))])
    _drive(sim, "r", 4.0)
    for _ in range(300):
        sim.step()
    t = sim.robot("r").pose.translation
    assert t[2] == HALF and float(t[0]) < XLOW - 0.1 + 1e-9 and sim.contact.contacts > 0
    ob = sim.contact.solids[("ramp", 0)]
    assert ob.z_range[1] == pytest.approx(0.05, abs=1e-12)
    lo = sim.ground.at(1.5, 0.0, HALF + 1.0)
    assert lo is not None and lo[0] == pytest.approx(_ramp_z(1.5, 0.05), abs=1e-12)   # ground for one up there
    assert sim.ground.at(1.5, 0.0, 0.001) == (0.0, 0.0, 0.0)                           # not for one on the floor

    axis = [1 / math.sqrt(2), -1 / math.sqrt(2), 0.0]          # the cube's diagonal (1, 1, 1) turned to up
    corner = {"name": "corner", "pose": {"translation": [3.0, 0.0, 0.0], "rotation": [*axis, math.acos(1 / math.sqrt(3))]},
              "geometry": {"type": "box", "size": [0.5, 0.5, 0.5]}}
    sim = _sim([FLOOR, _ramp(), corner], [_robot("r", (0.0, 0.0, HALF))])
    assert sim.ground.at(3.0, 0.0, 10.0) == (0.0, 0.0, 0.0)
    assert cmod.ramp_top(sim.scene.solid_poses["corner"].rotation, np.zeros(3), (0.25, 0.25, 0.25)) is None


def test_a_ramp_a_supervisor_imports_is_no_ground_and_so_an_obstacle() -> None:
    """The ground is the world file's (README, Riding terrains): a ramp imported with
    importMFNodeFromString is not ridden, so contact takes its whole box: the robot driving at its low
    edge is stopped there, at its height, as by any tilted box."""
    sim = _sim([FLOOR, _ramp("other", y=5.0)], [_robot("r", (0.0, 0.0, HALF))])
    r = _ramp()
    tx, _, tz = r["pose"]["translation"]
    sim.import_nodes(f"Solid {{ name \"ramp\" translation {tx!r} 0 {tz!r} rotation 0 1 0 {-A!r} "
                     f"children [ Shape {{ geometry Box {{ size {2 * HX} {2 * HY} {2 * HZ} }} }} ] "
                     f"boundingObject Box {{ size {2 * HX} {2 * HY} {2 * HZ} }} }}")
    _drive(sim, "r", 4.0)
    for _ in range(300):
        sim.step()
    t = sim.robot("r").pose.translation
    assert t[2] == HALF and float(t[0]) < XLOW and sim.contact.contacts > 0


# ---------------------------------------------------------------------- batched

def _world(seed: int) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"random_seed": seed},
        "solids": [FLOOR, _ramp(), _ramp("high", lift=0.05, y=3.0)],
        "robots": [_robot("a", (0.2, 0.1, HALF), 0.05), _robot("b", (1.5, -0.2, _ramp_z(1.5) + HALF), 3.0),
                   _robot("c", (0.3, 3.1, HALF), 0.02),
                   {**_robot("d", (2.4, -0.3, 1.0), 1.0), "differential_drive": {**DRIVE, "wheel_bottom": -0.05}},
                   {**_robot("e", (1.2, 0.3, _ramp_z(1.2) + HALF)),
                    "pose": {"translation": [1.2, 0.3, _ramp_z(1.2) + HALF], "rotation": [0, 1, 0, -A]}}]})


@pytest.mark.parametrize("c_drive,nue", [(True, False), (False, False), (True, True)])
def test_copies_riding_ramps_are_the_single_simulation_bit_for_bit(c_drive, nue) -> None:
    """Five robots by the ramps (on the flush one, by the raised one, one settling onto the ramp at load,
    one placed tilted on it), random wheel commands, a supervisor move onto the ramp in one copy: every
    copy's poses equal a Simulation's at load and after every step, bit for bit, through the C drive and
    the numpy one, and in NUE axes."""
    bs, sims, up = ground_copies(_world, nue, c_drive)
    names = ("a", "b", "c", "d", "e")
    for c, s in enumerate(sims):
        for robot in names:
            assert s.robot(robot).pose.translation.tobytes() == bs.pos[c, bs.slot(robot)].tobytes(), robot
            assert s.robot(robot).pose.rotation.tobytes() == bs.rot[c, bs.slot(robot)].tobytes(), robot
    assert float(sims[0].robot("d").pose.translation[up]) == pytest.approx(_ramp_z(2.4) + 0.05, abs=1e-12)
    onto = [1.8, 0.0, _ramp_z(1.8) + HALF]
    onto = (TO_NUE @ np.array(onto)).tolist() if nue else onto
    heights = drive_and_compare(bs, sims, names, np.random.default_rng(11), 150, 15, 30, (70, "a", onto), up)
    assert HALF in heights and len(heights) > 10                # on the floor, and at many heights on the ramp
