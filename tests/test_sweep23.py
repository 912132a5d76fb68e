"""Sweep 23: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep23/: the
sample's poses, sizes, joints and devices, our own text, PROTO meshes stood in for by plain shapes) driven
in process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from _packets import use_packets
from test_sweep19 import rot

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world
from sensorium.server.world.poses import pose_from_model

DATA = Path(__file__).parent / "data" / "sweep23"

# ------------------------------------------------------------------------------------------------ tinkerbots
# braitenberg (kinematics/tinkerbots, R2023b): a robot of Tinkerbots blocks joined by Slots. The base (a
# Robot with Physics, turned −1.5707953 about y at z 0.03: its own x is the world's up, its z the world's
# −x) holds in its down slot the "right motor" block (turned 1.5708 about z), whose hinge (axis −1 0 0
# through 0 0 0.02 of the block) carries an axle and a wheel (radius 0.02625 m) and whose side slot holds
# the "right distance sensor" block; its right slot a cube whose right slot holds the "left motor" block
# (turned −1.5708) with its axle, wheel and "left distance sensor". Webots' `two_wheels_vehicle.py` sets both
# motors in velocity control, its four LEDs, and each 8 ms sets left = −11 − δ + 0.5, right = 11 − δ + 0.5
# (half of maxVelocity 22; δ = (128 − left) − (128 − right) of the readings), so both wheels roll it along
# the world's +x: the left motor turns about −y.
TB = "braitenberg"
TB_BASE = rot((0, 1, 0), -1.5707953071795862)
TB_DOWN = rot((1, 0, 0), -3.1415)                      # the base's down slot
TB_RIGHT = rot((1, 0, 0), -1.57)                       # the base's, and the cube's, right slot


def tb_motor_frames() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each motor block's rotation and origin in the robot's frame, composed from the slots' poses."""
    right = TB_DOWN @ rot((0, 0, 1), 1.5707996938995747)
    cube_at = np.array([0.0, 0.02, 0.0])
    left_at = cube_at + TB_RIGHT @ np.array([0.0, 0.02, 0.02])
    left = TB_RIGHT @ TB_RIGHT @ rot((0, 0, 1), -1.5708)
    return {"right motor": (right, TB_DOWN @ np.zeros(3) + np.array([0.0, 0.0, -0.02])),
            "left motor": (left, left_at)}


def tb_wheel_centre(motor: str) -> np.ndarray:
    """Where a motor's wheel cylinder is centred in the robot's frame: the motor block's end point (at the
    block's origin) → its front slot (0.015 0 0.02, turned −2.09485 about (0.57735, −0.577352, 0.577352)) →
    the axle → its end slot (0 0 0.022, turned −1.5708 about x) → the wheel, its cylinder 0.0085 along y."""
    r, at = tb_motor_frames()[motor]
    slot = rot((0.57735, -0.577352, 0.577352), -2.09485)
    wheel = np.array([0.0, 0.0, 0.022]) + rot((1, 0, 0), -1.5708) @ np.array([0.0, 0.0085, 0.0])
    return at + r @ (np.array([0.015, 0.0, 0.02]) + slot @ wheel)


def tb_drive_geometry() -> dict[str, object]:
    """The drive the wheels make, from the slots' frames: the robot's up its x (the base turned −π/2 about
    y), forward the right wheel's rolling direction (its axis, less its x, × x), left x × forward; each wheel
    where its cylinder's centre is on its hinge's axis; the axle their distance along left, the centre their
    midpoint (along forward and left)."""
    frames = tb_motor_frames()
    up = np.array([1.0, 0.0, 0.0])
    axis = frames["right motor"][0] @ np.array([-1.0, 0.0, 0.0])
    flat = axis - up * axis[0]
    forward = np.cross(flat, up) / np.linalg.norm(np.cross(flat, up))
    left = np.cross(up, forward)
    places = {}
    for motor, (r, at) in frames.items():
        a = r @ np.array([-1.0, 0.0, 0.0])
        anchor = at + r @ np.array([0.0, 0.0, 0.02])
        on = anchor + a * float(np.dot(tb_wheel_centre(motor) - anchor, a))
        places[motor] = np.array([on @ forward, on @ left])
    mid = (places["left motor"] + places["right motor"]) / 2.0
    return {"forward": forward, "left": left, "axle": abs(places["left motor"][1] - places["right motor"][1]),
            "centre": mid, "places": places}


def test_the_tinkerbots_robot_loads_its_devices_through_four_levels_of_slots() -> None:
    """The ten devices the controller asks for are found through base → slot → motor block → slot → distance
    sensor block (and cube → motor → sensor for the left side), each motor's hinge axis and anchor where the
    slots' poses put them: the right motor about the robot's +y through (0, 0, −0.04), the left about −y
    through (0, 0.04, −0.04), its wheel where the axle's slots put it (the drive's geometry from them, 1e-12;
    the drive's motors keep no joint fields). The robot's x stands up (the base turned −1.5707953 about y: 1.0e-6 from the
    world's up), so its drive is judged with x for its up: its wheels' axes are horizontal there and opposite
    within 1.6e-3 (the slots' two 1.57 turns; the drive takes axes within 5e-3), the left mounted mirrored
    (``reversed_motors``), the radius the wheels' 0.02625 m cylinders two Solids past each hinge (not the
    motor's own 0.01 m sphere), the axle and its centre where those cylinders are along the hinges' axes,
    forward the robot's −z (the world's +x at load). No load line; no ``wheel_bottom``: a robot built on its
    side keeps its height (its wheels 3.75 mm above the floor, where Webots' physics drops it)."""
    lw = load_world(DATA / "braitenberg.wbt")
    (robot,) = lw.world.robots
    names = {d.name for d in robot.devices}
    assert names == {f"{side} {what}" for side in ("left", "right")
                     for what in ("motor", "motor sensor", "motor led", "distance sensor", "distance sensor led")}
    assert robot.mass is not None and robot.mass.kg == 0.065
    assert not [w for w in lw.warnings if TB in w or "motor" in w]
    frames = tb_motor_frames()
    right_axis, left_axis = (frames[m][0] @ np.array([-1.0, 0.0, 0.0]) for m in ("right motor", "left motor"))
    assert right_axis == pytest.approx([0, 1, 0], abs=1e-4)
    assert 1e-3 < math.acos(-float(np.dot(left_axis, right_axis))) < 5e-3
    drive = robot.differential_drive
    assert drive is not None and robot.steered_drive is None
    geometry = tb_drive_geometry()
    assert (drive.left_motor, drive.right_motor, drive.reversed_motors) == ("left motor", "right motor",
                                                                            ["left motor"])
    assert drive.wheel_radius == 0.02625 and drive.max_wheel_speed == 22.0 and drive.wheel_bottom is None
    assert np.asarray(drive.forward) == pytest.approx(geometry["forward"], abs=1e-12)
    assert TB_BASE @ np.asarray(drive.forward) == pytest.approx([1.0, 0.0, 0.0], abs=1e-4)
    assert drive.axle_length == pytest.approx(geometry["axle"], abs=1e-12)
    assert np.asarray(drive.axle_center) == pytest.approx(geometry["centre"], abs=1e-12)
    # the wheels' centres in the world: x 0.04, y −0.0285 and 0.0686, z 0.03 (the README's), 3.75 mm up
    for motor, y in (("right motor", -0.0285), ("left motor", 0.0686)):
        centre = TB_BASE @ tb_wheel_centre(motor) + np.array([0.0, 0.0, 0.03])
        assert centre == pytest.approx([0.04, y, 0.03], abs=1e-4)
        assert centre[2] - drive.wheel_radius == pytest.approx(0.00375, abs=1e-4)


def test_the_two_wheels_vehicle_calls_roll_the_robot_along_x_curving_left_by_the_drive_arc() -> None:
    """Each sensor looks along the world's +x from 0.07 m up, 0.06 m ahead of the base; while it stays within
    0.95·cos(π/60) − 0.1 − 0.5 of the world's origin the ring is farther than the table's 0.5 m, so both read
    128 and the controller asks −10.5 and 11.5 rad/s. The drive takes them: the first step turns both at the
    default (maxVelocity 22, the left mirrored: −22 forward), a spin of 44·r/L·dt about the axle's centre;
    then the left rolls forward at 10.5, the right at 11.5: the centre runs the arc of v = 11·r, ω = r/L
    (r 0.02625, L the axle the wheels' places give), from the world's +x curving left, the origin rigidly
    attached, its height kept (1e-12); each encoder reads its motor's own turn, 22·dt then −10.5·dt and
    11.5·dt a step."""
    lw = load_world(DATA / "braitenberg.wbt")
    geometry = tb_drive_geometry()
    r, axle, dt = 0.02625, float(geometry["axle"]), 0.008
    sensors_at = []
    for d in lw.world.robots[0].devices:
        if d.device == "DistanceSensor":
            p = pose_from_model(d.pose)
            assert TB_BASE @ p.rotation[:, 0] == pytest.approx([1.0, 0.0, 0.0], abs=2e-3), d.name
            at = TB_BASE @ p.translation + np.array([0.0, 0.0, 0.03])
            assert at[[0, 2]] == pytest.approx([0.06, 0.07], abs=2e-5), d.name
            sensors_at.append(p.translation)
    clear = 0.95 * math.cos(math.pi / 60) - 0.1 - 0.5          # a sensor nearer the origin reads 128
    sim = Simulation(lw, "exact")
    robot = sim.robot(TB)
    left, right = robot.motor("left motor"), robot.motor("right motor")
    cruising = 0.5 * left.max_velocity
    for m in (left, right):
        m.set_position(math.inf)
    sensors = [sim.device(f"{TB}/{side} distance sensor") for side in ("left", "right")]
    encoders = [sim.device(f"{TB}/{side} motor sensor") for side in ("left", "right")]
    for s in (*sensors, *encoders):
        s.enable(8)
    origin0 = np.array([0.0, 0.0, 0.03])
    forward0 = TB_BASE @ np.asarray(geometry["forward"])
    yaw0 = math.atan2(forward0[1], forward0[0])
    c = np.asarray(geometry["centre"])
    centre0 = (origin0 + TB_BASE @ (c[0] * np.asarray(geometry["forward"]) + c[1] * np.asarray(geometry["left"])))[:2]
    spun = yaw0 + 44.0 * r / axle * dt
    v, w = 11.0 * r, r / axle
    for n in range(1, 61):
        sim.step()
        t = (n - 1) * dt
        heading = spun + w * t
        centre = centre0 + v / w * np.array([math.sin(heading) - math.sin(spun), math.cos(spun) - math.cos(heading)])
        turn = rot((0, 0, 1), heading - yaw0)
        origin = np.array([*(centre - turn[:2, :2] @ (centre0 - origin0[:2])), 0.03])
        pose = robot.pose
        assert np.array(pose.translation) == pytest.approx(origin, abs=1e-12), n
        assert np.array(pose.rotation) == pytest.approx(turn @ TB_BASE, abs=1e-12), n
        assert all(np.linalg.norm(origin + turn @ TB_BASE @ at) < clear for at in sensors_at), n
        lv, rv = (float(s.value) for s in sensors)
        assert (lv, rv) == (128.0, 128.0), n
        delta = (128 - lv) - (128 - rv)
        left.set_velocity(max(-22.0, min(22.0, -cruising - delta + 0.5)))
        right.set_velocity(max(-22.0, min(22.0, cruising - delta + 0.5)))
        expected = [22.0 * dt - 10.5 * dt * (n - 1), 22.0 * dt + 11.5 * dt * (n - 1)]
        assert [float(e.value) for e in encoders] == pytest.approx(expected, abs=1e-12), n
    assert origin[0] > 0.12 and 0.0 < origin[1] and heading - yaw0 > 0.0      # along +x, curving left


# vision_car (kinematics/tinkerbots, R2023b): the base turned as braitenberg's, one "motor" block in its down
# slot whose hinge carries two axles and wheels (its front and back slots, either side of the block), its
# "distance sensor" block beside it, and two passive wheels on the free hinges of two round-slot cubies on
# the base's top. Webots' `vision_car.py` sets the motor to half its maxVelocity (11 rad/s: the front wheels
# roll the car along +x at 11·0.02625 = 0.289 m/s) and stops it once the sensor reads under 100 (0.39 m).
VC = "vision car"


VC_BASE = rot((0, 1, 0), -1.5708)
TB_FRONT = rot((0.57735, -0.577352, 0.577352), -2.09485)         # a motor's front and back axle slots
TB_BACK = rot((-0.57735, 0.577352, 0.577352), -2.09485)
TB_END = rot((1, 0, 0), -1.5708)                                 # an axle's end slot
TB_WHEEL = np.array([0.0, 0.0, 0.022]) + TB_END @ np.array([0.0, 0.0085, 0.0])   # the wheel's cylinder, axle's frame


def vc_drive_geometry() -> dict[str, object]:
    """vision_car's wheels from the slots' frames (robot's frame, its x up): the motor block turned 1.5708
    about z in the base's down slot, its hinge (axis −x through 0 0 0.02 of the block) carrying an axle and
    wheel in each of its front (0.015 0 0.02) and back (−0.015 0 0.02) slots; the cubies in the base's upA
    (−0.01 0.01 0.015, turned 3.1415 about z) and upC (0.01 −0.01 0.015) slots, each a free hinge (axis y
    through −0.01 −0.01 0.015) whose Solid (there, turned −1.5708 about x) holds an axle turned 3.1415
    about x and its wheel. Forward: the motor's axis less its x, × x; each wheel where its cylinder's centre
    is on its hinge's axis; the driven wheel midway between the motor's two."""
    up = np.array([1.0, 0.0, 0.0])
    motor = TB_DOWN @ rot((0, 0, 1), 1.5708)
    block = np.array([0.0, 0.0, -0.02])
    axis = motor @ np.array([-1.0, 0.0, 0.0])
    anchor = block + motor @ np.array([0.0, 0.0, 0.02])
    flat = axis - up * axis[0]
    forward = np.cross(flat, up) / np.linalg.norm(np.cross(flat, up))
    left = np.cross(up, forward)

    def on_axis(centre, a, at) -> np.ndarray:
        on = at + a * float(np.dot(centre - at, a))
        return np.array([on @ forward, on @ left])

    driven = [on_axis(block + motor @ (np.array([x, 0.0, 0.02]) + slot @ TB_WHEEL), axis, anchor)
              for x, slot in ((0.015, TB_FRONT), (-0.015, TB_BACK))]
    free = []
    for at, turn in ((np.array([-0.01, 0.01, 0.015]), rot((0, 0, 1), 3.1415)), (np.array([0.01, -0.01, 0.015]), np.eye(3))):
        hinge = at + turn @ np.array([-0.01, -0.01, 0.015])
        a = turn @ np.array([0.0, 1.0, 0.0])
        centre = hinge + turn @ TB_END @ rot((1, 0, 0), 3.1415) @ TB_WHEEL
        free.append((on_axis(centre, a, hinge), math.atan2(-float(a @ forward), float(a @ left))))
    return {"forward": forward, "driven": (driven[0] + driven[1]) / 2.0, "spread": abs(driven[0][1] - driven[1][1]),
            "free": free}


def test_the_vision_car_rolls_straight_on_its_one_motor_and_stops_at_the_ring() -> None:
    """The five devices load through the slots; the one motorised hinge carries both driven wheels (0.02625 m
    cylinders in its front and back axle slots, 2·(0.015 + 0.022 − 0.0085) = 0.057 m apart along its axis), and the cubies' free hinges
    two passive wheels of that radius at the same height behind them: a ``steered_drive`` of one driven wheel
    midway between the motor's two (two wheels at one speed roll their midpoint at r·ω, turning nothing) and
    the two free wheels, which keep the car from turning, its forward the motor wheels' rolling direction
    (the world's +x at load); the places where the frames put them (1e-12). No load line. The controller's
    calls: the motor at 0.5·22 = 11 rad/s, then 0 once the sensor reads under 100: the car rolls straight
    along forward at 11·0.02625 m/s, 11·0.02625·0.008 m a step, its height and rotation kept (1e-12), the
    motor's sensor reading 11·0.008 a step; the reading falls as the ring nears, and from the step after the
    first under 100 the car stays where it is."""
    lw = load_world(DATA / "vision_car.wbt")
    (robot,) = lw.world.robots
    assert {d.name for d in robot.devices} == {"motor", "motor sensor", "motor led", "distance sensor",
                                               "distance sensor led"}
    assert robot.differential_drive is None and not [w for w in lw.warnings if "motor" in w or VC in w]
    drive = robot.steered_drive
    assert drive is not None and drive.wheel_bottom is None and drive.max_wheel_speed == 22.0
    geometry = vc_drive_geometry()
    assert np.asarray(drive.forward) == pytest.approx(geometry["forward"], abs=1e-12)
    assert VC_BASE @ np.asarray(drive.forward) == pytest.approx([1.0, 0.0, 0.0], abs=1e-4)
    (driven, *free) = drive.wheels
    assert (driven.motor, driven.steer, driven.heading, driven.radius) == ("motor", None, 0.0, 0.02625)
    assert np.asarray(driven.position) == pytest.approx(geometry["driven"], abs=1e-12)
    assert geometry["spread"] == pytest.approx(2 * (0.015 + 0.022 - 0.0085), abs=1e-6)     # (1.5708 turns)
    assert len(free) == 2
    for wheel, (place, heading) in zip(free, geometry["free"]):
        assert (wheel.motor, wheel.steer, wheel.radius) == (None, None, 0.02625)
        assert np.asarray(wheel.position) == pytest.approx(place, abs=1e-12)
        assert abs(math.remainder(heading, math.pi)) < 5e-3                # parallel to the motor's axis
        assert wheel.heading == pytest.approx(math.pi * round(heading / math.pi), abs=1e-15)
        assert place[0] < geometry["driven"][0] - 0.05                      # behind the motor's axle
    sim = Simulation(lw, "exact")
    car = sim.robot(VC)
    motor = car.motor("motor")
    motor.set_position(math.inf)
    motor.set_velocity(0.5 * motor.max_velocity)
    sensor, encoder = sim.device(f"{VC}/distance sensor"), sim.device(f"{VC}/motor sensor")
    sensor.enable(8)
    encoder.enable(8)
    start = np.array(car.pose.translation)
    heading = VC_BASE @ np.asarray(geometry["forward"])
    heading = np.array([heading[0], heading[1], 0.0]) / math.hypot(heading[0], heading[1])
    step = 11.0 * 0.02625 * 0.008
    moved, readings = 0, []
    for n in range(1, 400):
        sim.step()
        if not readings or readings[-1] >= 100.0:
            moved += 1
        assert np.array(car.pose.translation) == pytest.approx(start + heading * step * moved, abs=1e-12), n
        assert np.array(car.pose.rotation) == pytest.approx(VC_BASE, abs=1e-12), n
        assert float(encoder.value) == pytest.approx(11.0 * 0.008 * moved, abs=1e-12), n
        readings.append(float(sensor.value))
        if readings[-1] < 100.0:
            motor.set_velocity(0.0)
    stop = next(i for i, value in enumerate(readings) if value < 100.0)
    assert readings[0] == 128.0 and moved == stop + 1 < 399
    falling = [i for i, value in enumerate(readings[:stop + 1]) if value < 128.0]
    assert falling and all(readings[i] < readings[i - 1] for i in falling[1:])
    assert len(set(readings[stop:])) == 1                                   # stopped: it reads the same


@pytest.mark.parametrize("world", ["braitenberg.wbt", "vision_car.wbt"])
def test_webots_rolls_the_tinkerbots_vehicles_on_their_wheels(world: str) -> None:
    """What Webots' physics does with both robots: each rolls on its 0.02625 m wheels (the cylinders two
    Solids past the motor's hinge), so each gets a drive of that radius: braitenberg's two motors a
    differential drive, vision_car's one motor (both its wheels) a steered drive with its two free wheels."""
    (robot,) = load_world(DATA / world).world.robots
    if world == "braitenberg.wbt":
        assert robot.differential_drive is not None and robot.steered_drive is None
        assert robot.differential_drive.wheel_radius == pytest.approx(0.02625, abs=1e-12)
    else:
        assert robot.steered_drive is not None and robot.differential_drive is None
        assert [w.radius for w in robot.steered_drive.wheels] == pytest.approx([0.02625] * 3, abs=1e-12)


@pytest.mark.parametrize("helper", [True, False])
def test_the_batched_simulation_rolls_braitenberg_as_simulation_does_bit_for_bit(helper: bool) -> None:
    """braitenberg's drive (its forward the robot's −z, up its x, the left wheel mirrored, off-centre) in
    the batched simulation: each copy's pose is the single Simulation's, bit for bit, at every step, with
    the C drive pass and without it (numpy: SENSORIUM_PACKETS=0's path)."""
    from sensorium.gym.views import CopySim
    from sensorium.server.raycast import packets
    from sensorium.server.sim.batched import BatchedSimulation

    if helper and packets.library() is None:
        pytest.skip(f"no C helper: {packets.status()}")
    lw = load_world(DATA / "braitenberg.wbt")
    batched = BatchedSimulation(lw, 2)
    if not helper:
        batched._drive_step = None
    assert batched.wheel_sign.tolist() == [[-1.0, 1.0]] and batched.off_centre.tolist() == [True]
    batched.reset(np.arange(2), [1, 2])
    singles = [Simulation(lw, "exact") for _ in range(2)]
    speeds = [(-10.5, 11.5), (22.0, -3.0)]
    for c, single in enumerate(singles):
        for sim in (single, CopySim(batched, c)):
            for m, v in zip(("left motor", "right motor"), speeds[c]):
                motor = sim.robot(TB).motors[m]
                motor.set_position(math.inf)
                motor.set_velocity(v)
    slot = batched.slot(TB)
    for t in range(100):
        batched.step()
        for c, single in enumerate(singles):
            single.step()
            p = single.robot(TB).pose
            assert batched.pos[c, slot].tobytes() == p.translation.tobytes(), (t, c)
            assert batched.rot[c, slot].tobytes() == p.rotation.tobytes(), (t, c)
    assert not batched._numpy_drives
    assert float(singles[0].robot(TB).pose.translation[0]) > 0.2


@pytest.mark.parametrize("helper", [True, False])
def test_the_batched_simulation_rolls_vision_car_on_its_free_wheels_as_simulation_does(helper: bool,
                                                                                        monkeypatch) -> None:
    """vision_car's steered drive (one driven wheel, two free wheels) in four copies, each against its own
    Simulation built with the copy's seed, 300 steps (2.4 s), with the packets helper (libm's cos and sin in
    C) and without it (SENSORIUM_PACKETS=0): the controller's 11 rad/s stopped once the sensor reads under
    100, −7 rad/s, the full 22 rad/s into the ring, new random speeds every 25 steps. Every step each copy's
    pose, its motor sensor, its distance sensor and both free wheels' rolled angles are the single
    simulation's bits; the first 100 steps of the 11 and −7 rad/s copies are the straight roll along
    forward at r·ω, r·ω·0.008 m a step (1e-12)."""
    from sensorium.server.sim.batched import BatchedSimulation

    use_packets(helper, monkeypatch)
    lw = load_world(DATA / "vision_car.wbt")
    n, seeds = 4, [3, 5, 7, 11]
    batched = BatchedSimulation(lw, n)
    batched.reset(np.arange(n), seeds)
    singles = [Simulation(dataclasses.replace(lw, world=lw.world.model_copy(update={
        "world_info": lw.world.world_info.model_copy(update={"random_seed": seed})})), "exact") for seed in seeds]
    slot = batched.slot(VC)
    k = batched.steered.of[slot]
    refs = [batched.device(VC, name) for name in ("distance sensor", "motor sensor")]
    for ref in refs:
        batched.enable(ref, 8)
    for single in singles:
        for name in ("distance sensor", "motor sensor"):
            single.device(f"{VC}/{name}").enable(8)
        single.robot(VC).motor("motor").set_position(math.inf)
    rng = np.random.default_rng(23)
    speeds = np.array([11.0, -7.0, 22.0, 0.0])
    start = batched.pos[:, slot].copy()
    forward = VC_BASE @ np.asarray(lw.world.robots[0].steered_drive.forward)
    forward = np.array([forward[0], forward[1], 0.0]) / math.hypot(forward[0], forward[1])
    for t in range(300):
        if t % 25 == 0:
            speeds[3] = rng.uniform(-22.0, 22.0)
        batched.steered.command(slot, speeds[:, None])
        for c, single in enumerate(singles):
            single.robot(VC).motor("motor").set_velocity(float(speeds[c]))
            single.step()
        batched.step()
        for c, single in enumerate(singles):
            car = single.robot(VC)
            assert batched.pos[c, slot].tobytes() == car.pose.translation.tobytes(), (t, c)
            assert batched.rot[c, slot].tobytes() == car.pose.rotation.tobytes(), (t, c)
            for ref, name in zip(refs, ("distance sensor", "motor sensor")):
                assert np.float64(batched.value(ref)[c]).tobytes() == np.float64(
                    single.device(f"{VC}/{name}").value).tobytes(), (t, c, name)
            assert batched.steered.free_turned[c, k, 1:3].tolist() == [car.drive.free_turned[1],
                                                                       car.drive.free_turned[2]], (t, c)
        if t < 100:
            for c in (0, 1):
                expected = start[c] + forward * 0.02625 * speeds[c] * 0.008 * (t + 1)
                assert batched.pos[c, slot] == pytest.approx(expected, abs=1e-12), (t, c)
        if batched.value(refs[0])[0] < 100.0:
            speeds[0] = 0.0
    assert speeds[0] == 0.0 and batched.steered.free_turned[:, k, 1:3].all()
    assert (batched.value(refs[0]) < 128.0).sum() >= 2
