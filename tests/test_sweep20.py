"""Sweep 20: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep20/: the
sample's poses, sizes, joints and devices, our own text, PROTO shapes stood in for by plain ones) driven
in process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from test_supervisor import A, Live
from test_sweep19 import KinematicMotor, motor2_targets, rot

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep20"


def supervised(path: Path, tmp_path: Path, robot: str) -> Live:
    """The stand-in with ``supervisor TRUE`` on the robot named ``robot`` (to read the end points' poses
    as Webots' Supervisor does), attached to it."""
    text = path.read_text().replace(f'  name "{robot}"\n', f'  name "{robot}"\n  supervisor TRUE\n', 1)
    assert "supervisor TRUE" in text
    copy = tmp_path / path.name
    copy.write_text(text)
    if (path.parent / "protos").is_dir():
        shutil.copytree(path.parent / "protos", tmp_path / "protos", dirs_exist_ok=True)
    lv = Live(Simulation(load_world(copy), "exact"))
    lv.ok(A, "attach", {"robot": robot})
    return lv


def node_pose(lv: Live, robot: str, name: str) -> tuple[np.ndarray, np.ndarray]:
    node = lv.ok(A, f"/{robot}/robot/get_from_def", {"name": name})["node"]
    got = lv.ok(A, f"/{robot}/robot/get_node_pose", {"node": node})
    return np.array(got["position"]), np.array(got["orientation"]).reshape(3, 3)


# ------------------------------------------------------------------------- hinge_2_joint_with_backlash
# hinge_2_joint_with_backlash: two robots run motor2.c. The first, at x 0.1, is sweep 19's motor2 head; the
# second, at x -0.1 turned by -1.570795 about z, its column turned back by 1.5708 (a net 5e-6 rad), holds a
# Hinge2JointWithBacklash (backlash 0.2 on both axes): a free hinge about -x ("motor 1") holding the first
# gear, a Hinge2Joint about -x within ±0.1 and about -y ("motor 2"), then a hinge about -y within ±0.1
# carrying the head. Each joint's anchor is 0.07 m above its column's centre (z 0.13).
H2_ROBOTS = {"robot without backlash": ("WITHOUT_BACKLASH", np.array([0.1, 0.0, 0.0]), 0.0),
             "robot with backlash": ("WITH_BACKLASH", np.array([-0.1, 0.0, 0.0]), -1.570795 + 1.5708)}
H2_HEAD = rot((0.5773509358554485, 0.5773489358556708, -0.5773509358554485), 2.0944)


def test_the_backlash_head_loads_its_motors_on_the_same_axes_as_the_plain_one() -> None:
    """Our JavaScript stand-in of Hinge2JointWithBacklash expands, for backlashes of 0.2, to a free
    hinge carrying "motor 1" and a Hinge2Joint carrying "motor 2" on its second axis, its first axis
    and the last hinge passive: the robot's two motors are on the axes of the plain robot's, turned with
    its column (in the robot's frame Rz(1.5708)·(−x) and Rz(1.5708)·(−y)), "motor 2" riding on "motor
    1", both through the anchor 0.13 m up. Each motor is one load line (no drive is looked for)."""
    w = load_world(DATA / "hinge_2_joint_with_backlash.wbt")
    assert len(w.warnings) == 4 and all("moves kinematically" in x for x in w.warnings), w.warnings
    robots = {r.name: r for r in w.world.robots}
    assert set(robots) == set(H2_ROBOTS)
    column = {"robot without backlash": np.eye(3), "robot with backlash": rot((0, 0, 1), 1.5708)}
    for name, robot in robots.items():
        assert robot.differential_drive is None and robot.ackermann_drive is None
        d = {m.name: m for m in robot.devices}
        assert set(d) == {"motor 1", "motor 2"}, name
        assert d["motor 1"].axis == pytest.approx(column[name] @ (-1, 0, 0), abs=1e-15), name
        assert d["motor 2"].axis == pytest.approx(column[name] @ (0, -1, 0), abs=1e-15), name
        assert d["motor 2"].on_joint == "motor 1" and d["motor 1"].on_joint is None, name
        for m in d.values():
            assert m.anchor == pytest.approx((0.0, 0.0, 0.13), abs=1e-15), name
            assert (m.min_position, m.max_position) == (0.0, 0.0), name      # no limits: Webots' defaults


def test_both_heads_follow_the_motor2_calls_by_the_kinematic_rule(tmp_path: Path) -> None:
    """motor2.c's calls, made by both robots' controllers, in process for 800 steps of 32 ms: each robot's
    motors follow Webots' kinematic rule (maxVelocity 1, maxTorque 10 as the acceleration) (1e-12), and
    each block (DEF BLOCK_..., read by a Supervisor) is at anchor + R(a1, q1)·R(a2, q2)·(block₀ − anchor)
    and turned by it (1e-12), a1 and a2 the robot's −x and −y turned by its column's net yaw (0, and
    −1.570795 + 1.5708 = 5e-6 rad). The backlash joint's passive stops (±0.1) never move here: its head
    turns with its motors exactly as the plain one, where Webots' physics lets it lag behind them by up
    to 0.1 rad about each axis after each reversal."""
    lv = supervised(DATA / "hinge_2_joint_with_backlash.wbt", tmp_path, "robot without backlash")
    heads = {}
    for name, (tag, origin, yaw) in H2_ROBOTS.items():
        robot = lv.sim.robot(name)
        turn = rot((0, 0, 1), yaw)
        anchor = origin + np.array([0.0, 0.0, 0.13])
        block0 = anchor + turn @ H2_HEAD @ np.array([-0.026, 0.0, 0.0])
        at0, turned0 = node_pose(lv, "robot without backlash", f"BLOCK_{tag}")
        assert at0 == pytest.approx(block0, abs=1e-12), name
        assert turned0 == pytest.approx(turn @ H2_HEAD @ rot((0, 0, 1), 3.14159), abs=1e-12), name
        heads[name] = (tag, anchor, block0, turned0, turn @ (-1, 0, 0), turn @ (0, -1, 0),
                       {n: robot.motor(n) for n in ("motor 1", "motor 2")},
                       {n: KinematicMotor(1.0, 10.0) for n in ("motor 1", "motor 2")})
    for counter in range(1, 801):
        lv.sim.step()
        for name, (tag, anchor, block0, turned0, a1, a2, motors, twin) in heads.items():
            for n, m in twin.items():
                m.step(0.032)
                assert motors[n].position == pytest.approx(m.x, abs=1e-12), (name, counter, n)
            if counter % 10 == 0 or counter > 780:
                turn = rot(a1, twin["motor 1"].x) @ rot(a2, twin["motor 2"].x)
                at, turned = node_pose(lv, "robot without backlash", f"BLOCK_{tag}")
                assert at == pytest.approx(anchor + turn @ (block0 - anchor), abs=1e-12), (name, counter)
                assert turned == pytest.approx(turn @ turned0, abs=1e-12), (name, counter)
            if counter == 500:
                assert (twin["motor 1"].x, twin["motor 2"].x) == (0.0, -1.0)
            for n, q in motor2_targets(counter).items():
                motors[n].set_position(q)
                twin[n].target = q
