"""Kinematic contact's floor tolerance (sim/contact.py, FLOOR): a solid whose top lies at most FLOOR
above the bottom of a robot's height band is the ground it rests on (or sinks into, as robots in
Webots' saved worlds do, settled by its soft contacts), never an obstacle -- in the single
simulation, the batched one's numpy path and its C passes alike.

Wheels of radius 0.1 m at 5 rad/s move a robot 0.016 m per 32 ms step; bodies are upright
cylinders of radius R, 0.2 m tall about the robot's origin, so every stop is a closed form.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.raycast import packets
from sensorium.server.sim import contact as C
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.scene import robot_bounding_parts
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, parse_world
from tests.test_contact import drive, xy

R = 0.2
STEP = 0.016                     # m per basic step at 5 rad/s
SUNK = 1e-4                      # 0.1 mm into the floor: a settled Webots pose
FLOOR_BOX = {"name": "floor", "pose": {"translation": [0.0, 0.0, -0.05]}, "geometry": {"type": "box", "size": [6.0, 6.0, 0.1]}}
PLANE = {"name": "floor", "geometry": {"type": "plane", "size": None}}


def robot(name, x, y, z, yaw=0.0):
    return {"name": name, "pose": {"translation": [x, y, z], "rotation": [0, 0, 1, yaw]},
            "body": {"geometry": {"type": "cylinder", "radius": R, "height": 0.2}},
            "differential_drive": {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 1000.0}}


def loaded(solids, robots) -> LoadedWorld:
    return parse_world({"world_info": {"basic_time_step": 32}, "solids": list(solids), "robots": list(robots)})


def test_the_tolerance_is_a_millimetre():
    assert C.FLOOR == 1e-3 and C.FLOOR > C.EPS


def test_a_robot_sunk_into_a_floor_box_drives_across_its_centre():
    """Sunk 0.1 mm into a Box floor (its top at z = 0), the robot drove nowhere toward the box's
    centre: its disc started inside the box's footprint and every move went deeper. Now the box is
    its ground: after N steps it has moved N * 0.016 m, through the centre, with no contact."""
    sim = Simulation(loaded([FLOOR_BOX], [robot("r", -1.5, 0.3, 0.1 - SUNK)]))
    drive(sim, "r", 5.0)
    sim.run(150)
    assert xy(sim, "r") == pytest.approx([-1.5 + 150 * STEP, 0.3], abs=1e-9)
    assert sim.counters["contacts"] == 0 and sim.robot("r").pose.translation[2] == 0.1 - SUNK


def test_a_floor_box_carries_the_robot_as_a_plane_floor_does():
    """The same robot and commands (driving, turning) on a Box floor and on a Plane floor: the
    same poses, bit for bit (no terrain in the world: both keep the robot's height)."""
    sims = [Simulation(loaded([floor], [robot("r", -1.0, 0.2, 0.1 - SUNK, yaw=0.3)])) for floor in (FLOOR_BOX, PLANE)]
    for left, right, n in ((5.0, 5.0, 40), (2.0, 6.0, 60), (-3.0, 4.0, 30)):
        for sim in sims:
            drive(sim, "r", left, right)
            sim.run(n)
        a, b = (s.robot("r").pose for s in sims)
        assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes()
    assert all(s.counters["contacts"] == 0 for s in sims)


def test_a_5_cm_box_on_the_floor_box_still_stops_the_robot():
    block = {"name": "block", "pose": {"translation": [1.0, 0.0, 0.025]}, "geometry": {"type": "box", "size": [0.2, 1.0, 0.05]}}
    sim = Simulation(loaded([FLOOR_BOX, block], [robot("r", -1.5, 0.0, 0.1 - SUNK)]))
    drive(sim, "r", 5.0)
    sim.run(200)
    x, y = xy(sim, "r")
    assert x == pytest.approx(1.0 - 0.1 - R, abs=1e-9) and x <= 1.0 - 0.1 - R and y == 0.0
    assert sim.counters["contacts"] > 0


@pytest.mark.parametrize("top, blocks", [(0.999e-3, False), (1.001e-3, True), (0.9e-3, False), (1.5e-3, True)])
def test_a_plate_just_above_the_tolerance_is_an_obstacle(top, blocks):
    """A plate lying on a Plane floor, its top ``top`` above the bottom of the robot's band (the
    robot's body resting on the floor): at most a millimetre, ground; above, an obstacle that
    stops the robot at its edge."""
    plate = {"name": "plate", "pose": {"translation": [1.0, 0.0, top / 2.0]}, "geometry": {"type": "box", "size": [0.6, 1.0, top]}}
    sim = Simulation(loaded([PLANE, plate], [robot("r", 0.0, 0.0, 0.1)]))
    drive(sim, "r", 5.0)
    sim.run(100)
    x = xy(sim, "r")[0]
    if blocks:
        assert x == pytest.approx(0.7 - R, abs=1e-9) and sim.counters["contacts"] > 0
    else:
        assert x == pytest.approx(100 * STEP, abs=1e-9) and sim.counters["contacts"] == 0


def test_a_floor_box_sunk_beyond_the_tolerance_is_still_an_obstacle():
    """1.5 mm into the box: more than a settled pose, the box is in its band and holds it."""
    sim = Simulation(loaded([FLOOR_BOX], [robot("r", -1.5, 0.0, 0.1 - 1.5e-3)]))
    drive(sim, "r", 5.0)
    sim.run(10)
    assert xy(sim, "r")[0] == -1.5 and sim.counters["contacts"] == 10


def test_robots_meeting_on_a_floor_box_still_stop_apart():
    """The tolerance is the ground's: two robots sunk alike into the floor still meet."""
    sim = Simulation(loaded([FLOOR_BOX], [robot("a", -1.0, 0.0, 0.1 - SUNK), robot("b", 1.0, 0.0, 0.1 - SUNK, yaw=math.pi)]))
    drive(sim, "a", 5.0)
    drive(sim, "b", 5.0)
    sim.run(100)
    gap = float(np.linalg.norm(xy(sim, "b") - xy(sim, "a")))
    assert gap == pytest.approx(2 * R, abs=1e-9) and gap >= 2 * R


def _floor_world() -> LoadedWorld:
    block = {"name": "block", "pose": {"translation": [1.2, 0.0, 0.025]}, "geometry": {"type": "box", "size": [0.2, 2.0, 0.05]}}
    thin = {"name": "thin", "pose": {"translation": [-1.0, 1.2, 0.00025]}, "geometry": {"type": "box", "size": [1.0, 0.3, 0.0005]}}
    step = {"name": "step", "pose": {"translation": [-1.0, -1.2, 0.001]}, "geometry": {"type": "box", "size": [1.0, 0.3, 0.002]}}
    return loaded([FLOOR_BOX, block, thin, step],
                  [robot("a", -0.5, 0.0, 0.1 - SUNK), robot("b", 0.4, 0.5, 0.1 - 3e-5, yaw=2.0)])


def _modes():
    """The batched drive three ways: the C pass (DriveStep), the numpy drive with the C broad phase
    (packets.contact_near), and all numpy (the helper's broad phase refused)."""
    n = 6
    out = []
    for mode in ("c", "numpy+c", "numpy"):
        bs = BatchedSimulation(_floor_world(), n)
        if mode != "c":
            bs._drive_step = None
        out.append((mode, bs))
    return n, out


def test_single_and_batched_numpy_and_c_move_alike_on_a_floor_box(monkeypatch):
    """Random wheel commands on a sunk robot pair among a floor box, a 5 cm block, a 0.5 mm plate
    (ground) and a 2 mm step (an obstacle): each copy of the batched simulation -- its C pass, its
    numpy drive with the C broad phase, its numpy broad phase -- is the single simulation with its
    seed, pose for pose, bit for bit; contacts happen, and robots drive deeper into the floor box
    (which the box held them from before it counted as their floor)."""
    n, modes = _modes()
    sims = [Simulation(_floor_world()) for _ in range(n)]
    rng = np.random.default_rng(4)
    for bs in (b for _, b in modes):
        bs.reset(np.arange(n), list(range(n)))
    real_near = packets.contact_near
    deeper = 0                    # single-simulation steps that took a robot deeper into the floor box
    for step in range(160):
        if step % 16 == 0:
            lr = rng.uniform(-3.0, 12.0, (2, n, 2))
            for _, bs in modes:
                for r in range(2):
                    bs.set_wheels(r, lr[r, :, 0], lr[r, :, 1])
            for c, s in enumerate(sims):
                for r, name in enumerate(("a", "b")):
                    drive(s, name, float(lr[r, c, 0]), float(lr[r, c, 1]))
        for mode, bs in modes:
            monkeypatch.setattr(packets, "contact_near", (lambda *a: None) if mode == "numpy" else real_near)
            bs.step()
        monkeypatch.setattr(packets, "contact_near", real_near)
        for s in sims:
            before = [3.0 - np.abs(xy(s, name)).max() for name in ("a", "b")]
            s.step()
            deeper += sum(3.0 - np.abs(xy(s, name)).max() > b + 1e-6 for name, b in zip(("a", "b"), before))
        for mode, bs in modes:
            for c, s in enumerate(sims):
                for r, name in enumerate(("a", "b")):
                    pose = s.robot(name).pose
                    assert pose.translation.tobytes() == bs.pos[c, r].tobytes(), (mode, step, c, name)
                    assert pose.rotation.tobytes() == bs.rot[c, r].tobytes(), (mode, step, c, name)
    contacts = sum(s.counters["contacts"] for s in sims)
    assert contacts > 0 and all(bs.counters["contacts"] == contacts for _, bs in modes)
    assert deeper > 100


def test_the_c_broad_phase_applies_the_floor_tolerance_as_numpy_does():
    """packets.contact_near against BatchedSimulation._contact_near with the robots' heights swept
    across the tolerance's edge above the floor box's top: the same flags, and the floor box is a
    candidate exactly when its top is more than FLOOR above the band's bottom."""
    if packets.library() is None:
        pytest.skip(packets.status())
    n = 8
    bs = BatchedSimulation(_floor_world(), n)
    ct = bs.contact
    assert ct is not None
    floor = [i for i, o in enumerate(ct._obs) if o.name == "floor"][0]
    sinks = np.array([0.0, 3e-5, 1e-4, 0.9e-3, 0.999e-3, 1.001e-3, 1.2e-3, 5e-3])
    bs.heights[:, 0] = 0.1 - sinks
    bs.heights[:, 1] = 0.1 - sinks[::-1]
    copies = np.repeat(np.arange(n), 2)
    slots = np.tile(np.arange(2), n)
    starts = bs.centres[copies, slots].copy()
    reach = np.full(len(copies), 0.01 + C.EPS)
    grow = np.zeros((n, 2))
    grow[copies, slots] = reach
    want = bs._contact_near(copies, slots, starts, reach, grow)
    got = packets.contact_near(copies, slots, starts, reach, bs.foot_radius, bs.foot_low, bs.foot_high,
                               bs.heights, bs.centres, grow, ct._lo, ct._hi, ct._zlo, ct._zhi, C.EPS, C.FLOOR)
    assert got is not None and want[0] is not None
    for w, g in zip(want, got):
        assert g.tobytes() == w.tobytes()
    sunk = np.concatenate([[sinks[c], sinks[::-1][c]] for c in range(n)])
    assert want[0][:, floor].tolist() == (sunk > 1e-3).tolist()


def test_wheels_lying_on_their_side_rest_on_a_floor_box_at_their_radius():
    """A body with wheels among its bounding shapes (Webots' four_wheels how-to: each wheel a
    Cylinder turned onto its side, radius 0.1 m, the robot at z = 0.1 on a Box floor): a turned
    shape's height band is its exact extent, so a wheel reaches down exactly its radius, to the
    floor's top. Bounded by its circumscribed sphere (sqrt(0.1² + 0.02²) m) it reached 2 mm into
    the floor, which stopped the robot where it stood; it drives N * 0.016 m in N steps."""
    wheel = {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.04}}
    shapes = [{"geometry": {"type": "box", "size": [0.3, 0.2, 0.05]}, "pose": {"translation": [0.0, 0.0, 0.05]}},
              *({**wheel, "pose": {"translation": [0.0, y, 0.0], "rotation": [1.0, 0.0, 0.0, math.pi / 2]}}
                for y in (0.17, -0.17))]
    bot = {**robot("r", -1.5, 0.3, 0.1), "shapes": shapes}
    del bot["body"]
    world = loaded([FLOOR_BOX], [bot])
    foot = C.robot_footprint(robot_bounding_parts(world.world.robots[0], world.base_dir))
    assert foot.z_low == pytest.approx(-0.1, abs=1e-15) and foot.z_high == pytest.approx(0.1, abs=1e-15)
    sim = Simulation(world)
    drive(sim, "r", 5.0)
    sim.run(150)
    assert xy(sim, "r") == pytest.approx([-1.5 + 150 * STEP, 0.3], abs=1e-9)
    assert sim.counters["contacts"] == 0
