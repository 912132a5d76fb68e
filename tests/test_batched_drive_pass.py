"""The batched simulation's C drive pass (packets.c ``sp_drive_step``, ``packets.DriveStep``) steps
two-wheel robots whose wheels' centre is off their origin (``differential_drive.axle_center``) too:
their origin's body twist integrated exactly, the numpy path's float64 operations, so the C pass,
the numpy drive (``_drive_numpy``, what runs with ``SENSORIUM_PACKETS=0``) and each copy's own
single Simulation give the same poses, bit for bit (off-centre and centred two-wheel robots, an
off-centre skid-steer robot, walls, contact on and off, position and velocity control, a set_pose);
and robots with ``step_rule: mid_heading`` (Webots' kinematic rule without Physics: a two-wheel and a
skid-steer one) beside them, in the C pass and among the holonomic robots' numpy drive; and the same
robots with a side mounted mirrored (``reversed_motors``: its speed counts negated), bit for bit too."""

from __future__ import annotations

import numpy as np
import pytest

from sensorium.server.raycast import packets
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world
from tests.test_batched_mecanum import command, wall
from tests.test_batched_omni import STEP, boebot, random_commands

NAMES = ("boe", "boe2", "skid", "dd", "mid", "midskid")


def mid_heading(name: str, x: float, y: float, skid: bool = False) -> dict:
    """A robot moved by Webots' rule without Physics (turning about its origin)."""
    robot = boebot(name, x, y, skid)
    robot["differential_drive"].pop("axle_center")
    robot["differential_drive"]["step_rule"] = "mid_heading"
    return robot


MIRRORED = {"boe": ["left wheel motor"], "boe2": ["right wheel motor"], "skid": ["left wheel motor", "rear left"],
            "dd": ["left wheel motor", "right wheel motor"], "mid": ["right wheel motor"],
            "midskid": ["right wheel motor", "rear right"]}
"""Each robot's wheels mounted mirrored in the mirrored world (a side each, both of one robot)."""


def world(contact: bool, mirrored: bool = False):
    centred = boebot("dd", 0.2, 0.5)
    centred["differential_drive"].pop("axle_center")
    backward = boebot("boe2", -0.3, -0.7)
    backward["differential_drive"]["axle_center"] = [-0.03, 0.012]     # behind and beside its origin
    robots = [boebot("boe", -0.95, 0.9), backward, boebot("skid", 0.6, -0.1, skid=True),
              centred, mid_heading("mid", -0.5, 0.0), mid_heading("midskid", 0.0, -0.8, True)]
    if mirrored:
        for r in robots:
            r["differential_drive"]["reversed_motors"] = MIRRORED[r["name"]]
    return parse_world({"world_info": {"basic_time_step": STEP, "contact": contact, "random_seed": 5},
                        "solids": [wall("north", 0, 1.2, 2.6, 0.2), wall("south", 0, -1.2, 2.6, 0.2),
                                   wall("east", 1.2, 0, 0.2, 2.2), wall("west", -1.2, 0, 0.2, 2.2),
                                   wall("block", 0.5, -0.6, 0.3, 0.3)],
                        "robots": robots})


def _seeded(w, seed: int) -> Simulation:
    return Simulation(w.world.model_copy(update={"world_info": w.world.world_info.model_copy(
        update={"random_seed": seed})}))


def _same_poses(singles, batched, names, t: int) -> None:
    """Every copy's robots in each batched simulation are at their single simulation's pose, bit for bit."""
    for c, single in enumerate(singles):
        for name in names:
            p = single.robot(name).pose
            for k, b in enumerate(batched):
                r = b.slot(name)
                assert b.pos[c, r].tobytes() == p.translation.tobytes(), (t, c, name, k)
                assert b.rot[c, r].tobytes() == p.rotation.tobytes(), (t, c, name, k)


@pytest.mark.parametrize("contact, mirrored", [(True, False), (False, False), (True, True)])
def test_off_centre_robots_take_the_c_pass_and_it_gives_the_numpy_and_single_bits(contact, mirrored):
    if packets.library() is None:
        pytest.skip(f"no C helper: {packets.status()}")
    from sensorium.gym.views import CopySim

    w = world(contact, mirrored)
    n, seeds = 3, [5, 6, 7]
    c_pass, numpy_pass = BatchedSimulation(w, n), BatchedSimulation(w, n)
    numpy_pass._drive_step = None          # its _drive_pass: no helper (the SENSORIUM_PACKETS=0 path)
    signs = [[-1.0 if m in MIRRORED[name] else 1.0 for m in ("left wheel motor", "right wheel motor")]
             for name in NAMES]
    assert c_pass.wheel_sign.tolist() == (signs if mirrored else [[1.0, 1.0]] * len(NAMES))
    assert c_pass.off_centre.tolist() == [True, True, True, False, False, False]
    assert c_pass.mid_heading.tolist() == [0, 0, 0, 0, 1, 1]
    singles = [_seeded(w, s) for s in seeds]
    views = {id(b): [CopySim(b, c) for c in range(n)] for b in (c_pass, numpy_pass)}
    for b in (c_pass, numpy_pass):
        b.reset(np.arange(n), seeds)
    rng = np.random.default_rng(11)
    pressed = 0
    start = np.array([[-0.95, 0.9], [-0.3, -0.7], [0.6, -0.1], [0.2, 0.5], [-0.5, 0.0], [0.0, -0.8]])
    farthest = np.zeros((len(NAMES), n))      # each robot's farthest from where it started, per copy
    for t in range(320):
        if t % 40 == 0:
            cmds = [random_commands(rng, w.world) for _ in range(n)]
        if t == 160:
            for s in (singles[1], *(v[1] for v in views.values())):
                s.robot("boe2").set_pose(translation=[0.2, 0.8, 0.04], rotation=[0, 0, 1, -2.0])
        for c in range(n):
            command(singles[c], cmds[c])
            for v in views.values():
                command(v[c], cmds[c])
            singles[c].step()
        c_pass.step()
        numpy_pass.step()
        _same_poses(singles, (c_pass, numpy_pass), NAMES, t)
        pressed += sum(bool(singles[c].robot(name).pressing) for c in range(n) for name in NAMES)
        farthest = np.maximum(farthest, np.hypot(*(c_pass.pos[:, :, :2] - start).T))
    # the C pass did the stepping: made once and used (no numpy drive for these robots)
    assert not c_pass._numpy_drives and isinstance(c_pass.__dict__.get("_drive_step"), packets.DriveStep)
    assert c_pass.counters["contacts"] == numpy_pass.counters["contacts"]
    if contact:
        assert pressed > 0
    assert (farthest > 0.05).all(), farthest


def test_a_world_with_omni_and_mecanum_robots_steps_its_two_wheel_robots_in_c(monkeypatch):
    """tests/test_batched_omni.py's world (a three- and a four-wheel omni robot, a mecanum robot, an
    off-centre two-wheel and an off-centre skid-steer robot, and here a two-wheel robot with step_rule
    mid_heading): its holonomic robots take the numpy
    drive, its two-wheel robots' wheels and moves still the C passes (packets.drive_wheels,
    packets.drive_moves: called with exactly their slots); with those passes refused (no helper)
    every pose is the same bits, and both are each copy's single Simulation."""
    if packets.library() is None:
        pytest.skip(f"no C helper: {packets.status()}")
    from tests.test_batched_omni import NAMES as MIXED
    from tests.test_batched_omni import omni, youbot
    from tests.test_batched_omni import world as mixed_world

    assert [r.name for r in mixed_world(True).world.robots] == list(MIXED)     # its world, and one robot more here
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": True, "random_seed": 5},
                     "solids": [wall("north", 0, 1.2, 2.6, 0.2), wall("south", 0, -1.2, 2.6, 0.2),
                                wall("east", 1.2, 0, 0.2, 2.2), wall("west", -1.2, 0, 0.2, 2.2),
                                wall("block", 0.5, -0.6, 0.3, 0.3)],
                     "robots": [omni("tri", 0.0, 0.0), omni("quad", 0.6, 0.6, 4, 0.4), youbot("yb", -0.6, -0.5),
                                boebot("boe", -0.95, 0.9), boebot("skid", 0.6, -0.1, skid=True),
                                mid_heading("mid", -0.5, 0.2)]})
    MIXED = (*MIXED, "mid")
    n, seeds = 2, [5, 6]
    with_c, without = BatchedSimulation(w, n), BatchedSimulation(w, n)
    assert with_c._numpy_drives
    singles = [_seeded(w, s) for s in seeds]
    from sensorium.gym.views import CopySim

    views = {id(b): [CopySim(b, c) for c in range(n)] for b in (with_c, without)}
    for b in (with_c, without):
        b.reset(np.arange(n), seeds)
    real_wheels, real_moves = packets.drive_wheels, packets.drive_moves
    moved_slots: set[int] = set()

    def moves(slots, *a):
        moved_slots.update(slots.tolist())
        return real_moves(slots, *a)

    rng = np.random.default_rng(3)
    for t in range(160):
        if t % 40 == 0:
            cmds = [random_commands(rng, w.world) for _ in range(n)]
        for c in range(n):
            command(singles[c], cmds[c])
            for v in views.values():
                command(v[c], cmds[c])
            singles[c].step()
        monkeypatch.setattr(packets, "drive_moves", moves)
        with_c.step()
        monkeypatch.setattr(packets, "drive_wheels", lambda *a: None)
        monkeypatch.setattr(packets, "drive_moves", lambda *a: None)
        without.step()
        monkeypatch.setattr(packets, "drive_wheels", real_wheels)
        _same_poses(singles, (with_c, without), MIXED, t)
    assert moved_slots == {with_c.slot("boe"), with_c.slot("skid"), with_c.slot("mid")}
