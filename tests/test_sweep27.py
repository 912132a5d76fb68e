"""Sweep 27: Webots `projects/robots` worlds not run before, each on a stand-in world of ours
(tests/data/sweep27/: the sample's poses, sizes, joints and devices, our own text, meshes stood in for by plain
shapes) driven in process by the calls a controller makes and checked against closed forms."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from test_sweep19 import KinematicMotor, rot

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


# ------------------------------------------------------------------------------------------------ portal_pe
# portal_pe (projects/robots/a4/portal, R2023b): A4 Technologie's PICAXE-28X2 sliding gate, Webots' Portal
# (R2022b) at the origin, built y-up and turned by its inner Transform (0.5773 0.5773 0.5773 2.0944: the
# model's x, y, z are the world's y, z, x). portal_pe.c talks to the PICAXE editor over a Windows named pipe
# (on Linux its main returns 1); its keyboard path makes the calls below: 'O' held opens the gate (the
# "gate" slider to 0.3 at its 0.05 m/s, the gear at +inf, the "rail" slider dropped 5 mm once the gate reads
# 0.29), a released key stops both where they are, 'C' closes; pinsC, the bits the PICAXE reads, is
# outside button + 2·open + 4·closed + 8·inside button. The gate's bounding box (0.29 m along the world's y)
# spans y ∈ [p − 0.2998, p − 0.0098] at slider position p; the end stops' boxes y ∈ [−0.28, −0.26]
# ("closed") and [0.23, 0.25] ("open"), within the gate's height and width.
PORTAL = DATA / "portal_pe.wbt"
PORTAL_STEP = 25


def pins_c(sim: Simulation) -> int:
    """portal_pe.c's pinsC from the four TouchSensors' readings."""
    return sum(bit * int(sim.device(f"Portal/{name}").value)
               for bit, name in ((1, "outside button"), (2, "open"), (4, "closed"), (8, "inside button")))


def test_the_portal_loads_with_the_devices_portal_pe_asks_for_and_is_refused_by_the_batched_simulation() -> None:
    """The Portal loads with the eleven devices portal_pe.c gets, its three joints one line each (kinematic),
    its selfCollision read; the batched simulation, which does not take a robot's own shapes, refuses it in
    one line rather than leave its end stops never pressed."""
    w = load_world(PORTAL)
    assert len(w.warnings) == 3 and all("moves kinematically" in x for x in w.warnings), w.warnings
    (robot,) = w.world.robots
    assert {d.name for d in robot.devices} == {"gear", "gear_sensor", "gate", "gate_sensor", "rail", "closed", "open",
                                               "outside button", "inside button", "optical barrier", "lamp"}
    assert robot.self_collision
    with pytest.raises(Exception, match=r"robot 'Portal': bumper 'open' touches the robot's own shapes "
                                        r"\(selfCollision\); the batched simulation does not \(use Simulation\)"):
        BatchedSimulation(w.world, 2)


def test_portal_pes_keyboard_calls_open_and_close_the_gate_onto_its_end_stops() -> None:
    """portal_pe.c's calls, 25 ms steps: 3 steps stopped (the gate held at 0.03, the gear at 0), 'L' for 2
    (the lamp on), 'O' held for 230 steps, released for 40, 'C' held for 250. Every step the gate's and the
    gear's sensors read Webots' kinematic motor closed form (maxForce 10 as the acceleration: the gate at
    0.05 m/s from its first step, the gear ramping to 3.16 rad/s by 0.25 rad/s a step; 1e-9), the rail drops
    to −0.005 the step after the gate reads 0.29, and pinsC reads the end stops the gate presses: "closed"
    (4) while p ≤ 0.0398, at load until 0.2 s of opening (p 0.04) and again from 5.225 s of closing (p
    0.03875), "open" (2) while p ≥ 0.2398, from 4.2 s of opening (p 0.24) to 1.225 s of closing (p 0.23875):
    151 and 54 steps. Before this sweep both read 0 always: a bumper touched only solids and other robots,
    and a robot none drives had no contact at all."""
    sim = Simulation(load_world(PORTAL), "exact")
    robot = sim.robot("Portal")
    for name in ("closed", "open", "outside button", "inside button", "gear_sensor", "gate_sensor"):
        sim.device(f"Portal/{name}").enable(PORTAL_STEP)
    gate, gear, rail = KinematicMotor(0.05, 10.0, 0.03), KinematicMotor(3.16, 10.0), KinematicMotor(10.0, 10.0)
    lamp = sim.device("Portal/lamp")
    gate_sensor, gear_sensor = sim.device("Portal/gate_sensor"), sim.device("Portal/gear_sensor")
    seen = {"open": 0, "closed": 0}
    plan = ["stop"] * 3 + ["L"] * 2 + ["O"] * 230 + [None] * 40 + ["C"] * 250
    for key in plan:
        p_read, g_read = gate_sensor.value, gear_sensor.value
        if key == "stop":          # SIMULATION_STATE_STOP: every actuator back to its initial value
            if not math.isnan(g_read):
                gear.target = math.floor(g_read / (math.pi / 7)) * (math.pi / 7)
                robot.motor("gear").set_position(gear.target)
            rail.target, gate.target = 0.0, 0.03
            robot.motor("rail").set_position(0.0)
            robot.motor("gate").set_position(0.03)
            lamp.set(0, sim.time_ms)
        else:
            lamp.set(1 if key == "L" else 0, sim.time_ms)
            if key in ("O", "C"):
                gate.target, gear.target = (0.3, math.inf) if key == "O" else (0.0, -math.inf)
                derail = p_read >= 0.29 if key == "O" else p_read <= 0.01
                rail.target = -0.005 if derail else 0.0
            else:                  # no key ('L' included): the motors stop where their sensors read
                gear.target, gate.target = g_read, p_read
            robot.motor("gate").set_position(gate.target)
            robot.motor("gear").set_position(gear.target)
            robot.motor("rail").set_position(rail.target)
        sim.step()
        for m in (gate, gear, rail):
            m.step(PORTAL_STEP / 1000.0)
        assert gate_sensor.value == pytest.approx(gate.x, abs=1e-9)
        assert gear_sensor.value == pytest.approx(gear.x, abs=1e-9)
        assert lamp.value == (1 if key == "L" else 0)
        pressed_open, pressed_closed = gate.x - 0.0098 >= 0.23, gate.x - 0.2998 <= -0.26
        assert pins_c(sim) == 2 * pressed_open + 4 * pressed_closed, (key, gate.x)
        seen["open"] += pressed_open
        seen["closed"] += pressed_closed
    assert gate.x == pytest.approx(0.0, abs=1e-12) and rail.x == pytest.approx(-0.005, abs=1e-12)
    assert seen == {"open": 63 + 40 + 48, "closed": 3 + 2 + 7 + 42}


def own_stop_world(tmp_path: Path, flag: str) -> Path:
    """A robot (selfCollision ``flag``) with a bumper box at (0.1, 0, 0.05), a slider "a" on its body whose
    end point's box overlaps the bumper, and a slider "b" (along y) on that end point whose box starts 0.3 m
    beside it."""
    box = "boundingObject Box { size 0.02 0.02 0.02 }"
    p = tmp_path / f"own_stop_{flag}.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 32 }\n"
                 f'Robot {{ name "r" selfCollision {flag} children [\n'
                 f'  TouchSensor {{ translation 0.1 0 0.05 name "stop" {box} }}\n'
                 '  SliderJoint { jointParameters JointParameters { axis 1 0 0 } device [ LinearMotor { name "a" } ]\n'
                 f'    endPoint Solid {{ translation 0.1 0 0.05 name "first" {box} children [\n'
                 '      SliderJoint { jointParameters JointParameters { axis 0 1 0 } device [ LinearMotor { name "b" '
                 'minPosition -1 } ]\n'
                 f'        endPoint Solid {{ translation 0 0.3 0 name "second" {box} }} }} ] }} }} ] }}\n')
    return p


@pytest.mark.parametrize("flag", ["TRUE", "FALSE"])
def test_a_bumper_touches_its_robots_own_solids_that_are_not_consecutive_to_it(tmp_path: Path, flag: str) -> None:
    """Webots detects collisions within a robot with selfCollision TRUE between solids that are not
    consecutive (not a joint's end point and the solid it hangs from): the end point of "a", on the body,
    overlaps the bumper on the body and is never touched; the end point of "b", one joint further, touches
    it once "b" brings it over it (its box 0.3 m off, ramping to 10 m/s: from its 7th step of 32 ms); with
    selfCollision FALSE nothing of the robot's own touches it."""
    sim = Simulation(load_world(own_stop_world(tmp_path, flag)), "exact")
    stop = sim.device("r/stop")
    stop.enable(32)
    sim.step()
    assert stop.value == 0.0
    sim.robot("r").motor("b").set_position(-0.3)
    b = KinematicMotor(10.0, 10.0)
    b.target = -0.3
    for _ in range(10):
        sim.step()
        b.step(0.032)
        assert stop.value == (1.0 if flag == "TRUE" and abs(b.x + 0.3) <= 0.02 + 1e-6 else 0.0), b.x
    assert b.x == pytest.approx(-0.3, abs=1e-12)
