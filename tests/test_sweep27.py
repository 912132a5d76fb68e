"""Sweep 27: Webots `projects/robots` worlds not run before, each on a stand-in world of ours
(tests/data/sweep27/: the sample's poses, sizes, joints and devices, our own text, meshes stood in for by plain
shapes) driven in process by the calls a controller makes and checked against closed forms."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from test_sweep19 import rot

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

DATA = Path(__file__).parent / "data" / "sweep27"

# ------------------------------------------------------------------------------------ robotics_competition
# robotics_competition (projects/robots/generic/trackedRobot, R2022b): Webots' TrackedRobot (R2022a) at
# (−1.92, 8.05, 0.25) turned −1.5707953 rad about z, facing −y down the start lane between two 0.4 m wooden
# blocks; two Tracks scaled 2 at y ±0.35 (x 0.042, z −0.0129), each with its LinearMotor, and a camera head
# on two motorised hinges ("camera_tilt_motor" about z, "camera_pan_motor" about y). The world's controller
# is "void": ours makes the calls a user's would (the track sample's belt speeds, the head's positions).
TRACKED = DATA / "robotics_competition.wbt"
START, HEADING = (-1.92, 8.05), -1.5707953071795862
STEP_MS = 8
AXLE, CENTRE_X = 0.7, 0.042          # between the belts' centre lines; their midpoint on the robot's x
HEAD = (0.54, -0.01, 0.17)           # the camera head's Transform, turned 3.14159 about z


def corner_low(t, axis, angle: float, size) -> float:
    """The lowest z of a Box of ``size`` turned ``angle`` about ``axis`` and put at ``t``."""
    r, h = rot(axis, angle), np.asarray(size) / 2.0
    return min(float((np.asarray(t) + r @ (np.asarray(s) * h))[2]) for s in itertools.product((-1, 1), repeat=3))


# the Track's bounding object, in its own frame before its scale 2: the belt's box, the two end pads (the
# rear one reaches lowest) and the end drums (radius 0.1 at z 0.017: not the lowest)
BELT_LOW = min(corner_low((0, 0, -0.009), (1, 0, 0), 1.570796, (0.39, 0.248, 0.09)),
               corner_low((0.237434, 0, -0.06918), (0.9561247250869316, -0.20715394043734683, 0.20715394043734683),
                          1.615648, (0.13, 0.08, 0.09)),
               corner_low((-0.242803, 0, -0.070833), (0.959691189146035, 0.19873703916918628, -0.19873703916918628),
                          1.611928, (0.13, 0.08, 0.09)),
               0.017 - 0.1)
REST_Z = -(2.0 * BELT_LOW - 0.0129)          # 0.279615: the robot's origin over the belts' lowest corner
WHEELS_Z = -(2.0 * (-0.088 - 0.04) - 0.0129)  # 0.2689: over the small TrackWheels' circles, as it rested before


def arc(x: float, y: float, h: float, vl: float, vr: float, t: float) -> tuple[float, float, float]:
    """The robot's origin and heading after ``t`` s on belts at ``vl``/``vr`` m/s: the belts' midpoint
    (CENTRE_X ahead of the origin) moves on the arc of v = (vl + vr)/2, ω = (vr − vl)/AXLE."""
    mx, my = x + CENTRE_X * math.cos(h), y + CENTRE_X * math.sin(h)
    v, w = (vl + vr) / 2.0, (vr - vl) / AXLE
    if w == 0.0:
        mx, my = mx + v * t * math.cos(h), my + v * t * math.sin(h)
    else:
        mx += v / w * (math.sin(h + w * t) - math.sin(h))
        my -= v / w * (math.cos(h + w * t) - math.cos(h))
    h += w * t
    return mx - CENTRE_X * math.cos(h), my - CENTRE_X * math.sin(h), h


def set_belts(sim: Simulation, vl: float, vr: float) -> None:
    robot = sim.robot("TrackedRobot")
    for name, v in (("left motor", vl), ("right motor", vr)):
        robot.motor(name).set_position(math.inf)
        robot.motor(name).set_velocity(v)


def test_the_tracked_robot_loads_as_a_tracked_drive_beside_its_camera_head_and_rests_on_its_belts() -> None:
    """The TrackedRobot's two Tracks are its drive (belts 0.7 m apart, their midpoint 0.042 m ahead of its
    origin) although its camera head has two motorised hinges: each hinge is said once (no wheel: it moves
    kinematically), and nothing else. Before this sweep the hinges made both Tracks conveyor belts (two
    lines, and two more that they were not level), so the robot never moved. With Physics it rests on its
    Tracks' bounding objects, as Webots' physics rests it: the rear end pad's lowest corner, 2·0.13336 + 0.0129 =
    0.279615 m under its origin (1e-12), where it rested on the TrackWheels' circles (0.2689 m) before."""
    w = load_world(TRACKED)
    assert len(w.warnings) == 2 and all("is no wheel (its end point has no cylinder or sphere to roll on)" in x
                                        for x in w.warnings), w.warnings
    (robot,) = w.world.robots
    assert [d.name for d in robot.devices] == ["left motor", "right motor", "camera_tilt_motor", "camera_pan_motor",
                                               "camera"]
    dd = robot.differential_drive
    assert (dd.wheel_radius, dd.axle_length, dd.axle_center, dd.left_motor, dd.right_motor) == (
        1.0, AXLE, (CENTRE_X, 0.0), "left motor", "right motor")
    assert dd.wheel_bottom == pytest.approx(-REST_Z, abs=1e-12)
    assert REST_Z - WHEELS_Z == pytest.approx(0.0107147, abs=1e-6)
    sim = Simulation(w, "exact")
    assert w.warnings[-1] == (f"{TRACKED}: robot 'TrackedRobot' settled on the ground at load, as Webots' physics "
                              "drops it: its origin's z from 0.2500 to 0.2796 m (its lowest wheel now touches the "
                              "ground under it)")
    pose = sim.robot("TrackedRobot").pose
    assert list(pose.translation) == pytest.approx([*START, REST_Z], abs=1e-12)
    assert np.asarray(pose.rotation) == pytest.approx(rot((0, 0, 1), HEADING), abs=1e-12)


def test_belt_speeds_drive_the_tracked_robot_down_the_lane_and_the_head_turns_its_camera() -> None:
    """Both belts at 0.5 m/s for 2 s (250 steps of 8 ms) carry the robot 1 m along its heading (−y), then
    0.5 and 0.55 m/s for 2 s turn it left on the arc of ω = 0.05/0.7 rad/s about the belts' midpoint, every
    step the closed form's (1e-9), its height kept. Meanwhile the head's motors, set to 0.5 rad (about z)
    and 0.3 rad (about y, its limits ±1.35), reach them at their default 10 rad/s, and the camera they carry
    is where the two turns about their anchors (0, 0, 0.065) and (0, 0, 0.1905) put it (1e-9)."""
    sim = Simulation(load_world(TRACKED), "exact")
    robot = sim.robot("TrackedRobot")
    assert sim.basic_time_step == STEP_MS
    robot.motor("camera_tilt_motor").set_position(0.5)
    robot.motor("camera_pan_motor").set_position(0.3)
    camera = sim.device("TrackedRobot/camera")
    camera.enable(STEP_MS)
    x, y, h = START[0], START[1], HEADING
    for vl, vr in ((0.5, 0.5), (0.5, 0.55)):
        set_belts(sim, vl, vr)
        for _ in range(250):
            sim.step()
            x, y, h = arc(x, y, h, vl, vr, STEP_MS / 1000.0)
            pose = sim.robot("TrackedRobot").pose
            assert list(pose.translation) == pytest.approx([x, y, REST_Z], abs=1e-9)
            assert np.asarray(pose.rotation) == pytest.approx(rot((0, 0, 1), h), abs=1e-9)
    assert (x, y, h) == pytest.approx(arc(*arc(*START, HEADING, 0.5, 0.5, 2.0), 0.5, 0.55, 2.0), abs=1e-9)
    # the camera: head at HEAD turned π about z, the z hinge's 0.5 about (0, 0, 0.065), the y hinge's 0.3 about
    # (0, 0, 0.1905), the camera at (−0.02, 0, 0.188) in the pan's end point, turned 3.14156 about z
    body = rot((0, 0, 1), h)
    head_r = rot((0, 0, 1), 3.14159)
    r1, r2 = rot((0, 0, 1), 0.5), rot((0, 1, 0), 0.3)
    a1, a2 = np.array([0, 0, 0.065]), np.array([0, 0, 0.1905])
    local = r1 @ (a2 + r2 @ (np.array([-0.02, 0.0, 0.188]) - a2) - a1) + a1
    where = np.array([x, y, REST_Z]) + body @ (np.array(HEAD) + head_r @ local)
    turned = body @ head_r @ r1 @ r2 @ rot((0, 0, 1), 3.14156)
    seen = camera.world_pose(robot.pose)
    assert list(seen.translation) == pytest.approx(list(where), abs=1e-9)
    assert np.asarray(seen.rotation) == pytest.approx(turned, abs=1e-9)


def test_batched_copies_of_the_tracked_robot_move_as_the_single_simulation() -> None:
    """Three batched copies on belt speeds (0.5, 0.5), (0.5, 0.55) and (−0.2, 0.2) for 0.8 s move the same bits
    as the single simulation, each at its closed form (1e-9), resting on its belts' bounding objects."""
    w = load_world(TRACKED)
    plans = [(0.5, 0.5), (0.5, 0.55), (-0.2, 0.2)]
    batched = BatchedSimulation(w.world, len(plans))
    batched.set_wheels(0, [p[0] for p in plans], [p[1] for p in plans])
    batched.run(100)
    for c, (vl, vr) in enumerate(plans):
        sim = Simulation(load_world(TRACKED))
        set_belts(sim, vl, vr)
        sim.run(100)
        pose = sim.robot("TrackedRobot").pose
        assert pose.translation.tobytes() == batched.pos[c, 0].tobytes(), c
        assert pose.rotation.tobytes() == batched.rot[c, 0].tobytes(), c
        x, y, _ = arc(*START, HEADING, vl, vr, 0.8)
        assert list(batched.pos[c, 0]) == pytest.approx([x, y, REST_Z], abs=1e-9)
