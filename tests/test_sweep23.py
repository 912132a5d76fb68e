"""Sweep 23: Webots samples not run before, each on a stand-in world of ours (tests/data/sweep23/: the
sample's poses, sizes, joints and devices, our own text, PROTO meshes stood in for by plain shapes) driven
in process by the calls its controller makes and checked against closed forms."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
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


def test_the_tinkerbots_robot_loads_its_devices_through_four_levels_of_slots() -> None:
    """The ten devices the controller asks for are found through base → slot → motor block → slot → distance
    sensor block (and cube → motor → sensor for the left side), each motor's hinge axis and anchor where the
    slots' poses put them (1e-12): the right motor about the robot's +y through (0, 0, −0.04), the left about
    −y through (0, 0.04, −0.04). Its wheels turn about opposite directions, which the drive takes (a wheel
    mounted mirrored: ``reversed_motors``), but the left's axis is 1.6e-3 off −y (the slots' two 1.57 turns),
    beyond the 1e-4 the drive allows, and its own z is not the world's up: Sensorium's drive takes neither
    (a departure from Webots, whose physics rolls the robot on them), so the robot keeps no drive and one
    load line names the left motor's axis."""
    lw = load_world(DATA / "braitenberg.wbt")
    (robot,) = lw.world.robots
    names = {d.name for d in robot.devices}
    assert names == {f"{side} {what}" for side in ("left", "right")
                     for what in ("motor", "motor sensor", "motor led", "distance sensor", "distance sensor led")}
    assert robot.differential_drive is None and robot.mass is not None and robot.mass.kg == 0.065
    (line,) = [w for w in lw.warnings if TB in w]
    assert "no differential drive" in line and "'left motor'" in line and "along +y or -y" in line
    frames = tb_motor_frames()
    for d in robot.devices:
        if d.name in frames:
            r, at = frames[d.name]
            assert np.asarray(d.axis) == pytest.approx(r @ np.array([-1.0, 0.0, 0.0]), abs=1e-12), d.name
            assert np.asarray(d.anchor) == pytest.approx(at + r @ np.array([0.0, 0.0, 0.02]), abs=1e-12), d.name
            assert (d.max_velocity, d.acceleration, d.max_torque) == (22.0, 10.0, 0.5)
    assert np.asarray(next(d for d in robot.devices if d.name == "right motor").axis) == pytest.approx([0, 1, 0], abs=1e-4)
    assert np.asarray(next(d for d in robot.devices if d.name == "left motor").axis) == pytest.approx([0, -1, 0], abs=2e-3)


def test_the_two_wheels_vehicle_calls_read_the_open_ring_and_turn_the_wheels_by_the_kinematic_rule() -> None:
    """Each sensor looks along the world's +x from 0.07 m up (its ray the sensor's x: the block's −z turned
    by the base), 0.06 m ahead of the base; the SolidPipe's inner face is at least 0.95·cos(π/60) − 0.1 −
    0.06 > 0.5 m away, so both read the table's 128 and δ = 0: the controller asks −10.5 and 11.5 rad/s.
    No drive takes the wheels, so each motor turns its hinge by Webots' kinematic rule, its speed growing by
    min(acceleration 10, maxTorque 0.5) rad/s² to what it is asked (for the first step, before any
    setVelocity, the default: maxVelocity): after n steps of 8 ms the right sensor reads
    0.5·0.008²·n(n+1)/2, the left 0.5·0.008²·(2n − n(n+1)/2) (1e-12), the robot staying where the world
    puts it (Webots' rolls along +x)."""
    lw = load_world(DATA / "braitenberg.wbt")
    for d in lw.world.robots[0].devices:
        if d.device == "DistanceSensor":
            p = pose_from_model(d.pose)
            assert TB_BASE @ p.rotation[:, 0] == pytest.approx([1.0, 0.0, 0.0], abs=2e-3), d.name
            at = TB_BASE @ p.translation + np.array([0.0, 0.0, 0.03])
            assert at[[0, 2]] == pytest.approx([0.06, 0.07], abs=2e-5), d.name
            assert 0.95 * math.cos(math.pi / 60) - 0.1 - at[0] > 0.5
    sim = Simulation(lw, "exact")
    robot = sim.robot(TB)
    left, right = robot.motor("left motor"), robot.motor("right motor")
    assert left.max_velocity == 22.0
    cruising = 0.5 * left.max_velocity
    for m in (left, right):
        m.set_position(math.inf)
    sensors = [sim.device(f"{TB}/{side} distance sensor") for side in ("left", "right")]
    encoders = [sim.device(f"{TB}/{side} motor sensor") for side in ("left", "right")]
    for s in (*sensors, *encoders):
        s.enable(8)
    start = np.array(robot.pose.translation)
    wanted = (0.0, 0.0)
    for n in range(1, 301):
        sim.step()
        lv, rv = (float(s.value) for s in sensors)
        assert (lv, rv) == (128.0, 128.0), n
        delta = (128 - lv) - (128 - rv)
        wanted = (max(-22.0, min(22.0, -cruising - delta + 0.5)), max(-22.0, min(22.0, cruising - delta + 0.5)))
        left.set_velocity(wanted[0])
        right.set_velocity(wanted[1])
        # the first step turns both at the default velocity (maxVelocity): +a·dt² each; from the second the
        # left's speed falls by a·dt a step from a·dt, the right's grows on
        unit = 0.5 * 0.008 ** 2
        expected = [unit * (2 * n - n * (n + 1) / 2), unit * n * (n + 1) / 2]
        assert [float(e.value) for e in encoders] == pytest.approx(expected, abs=1e-12), n
        assert np.array(robot.pose.translation) == pytest.approx(start, abs=1e-15)
    assert wanted == (-10.5, 11.5)


# vision_car (kinematics/tinkerbots, R2023b): the base turned as braitenberg's, one "motor" block in its down
# slot whose hinge carries two axles and wheels (its front and back slots, either side of the block), its
# "distance sensor" block beside it, and two passive wheels on the free hinges of two round-slot cubies on
# the base's top. Webots' `vision_car.py` sets the motor to half its maxVelocity (11 rad/s: the front wheels
# roll the car along +x at 11·0.02625 = 0.289 m/s) and stops it once the sensor reads under 100 (0.39 m).
VC = "vision car"


def test_the_vision_car_calls_turn_its_one_motor_by_the_kinematic_rule_where_webots_drives_the_car() -> None:
    """The five devices load through the slots; the one motorised hinge, which carries both driven wheels,
    is no drive here (one load line says its joint moves kinematically: a departure from Webots, whose
    physics rolls the car on it). The controller's calls: the motor in velocity control at 0.5·22 = 11
    rad/s, the sensor reading 128 every step (its ray along +x meets the ring about 0.88 m away, past the table's
    0.5 m), so it never stops; the motor's sensor reads 0.5·0.008²·n(n+1)/2 after n steps (its speed growing
    by maxTorque 0.5 rad/s² a second towards 11, 1e-12) and the car stays where the world puts it."""
    lw = load_world(DATA / "vision_car.wbt")
    (robot,) = lw.world.robots
    assert {d.name for d in robot.devices} == {"motor", "motor sensor", "motor led", "distance sensor",
                                               "distance sensor led"}
    assert robot.differential_drive is None
    (line,) = [w for w in lw.warnings if "'motor'" in w]
    assert "only motorised hinge" in line and "moves kinematically" in line
    sim = Simulation(lw, "exact")
    car = sim.robot(VC)
    motor = car.motor("motor")
    motor.set_position(math.inf)
    motor.set_velocity(0.5 * motor.max_velocity)
    sensor, encoder = sim.device(f"{VC}/distance sensor"), sim.device(f"{VC}/motor sensor")
    sensor.enable(8)
    encoder.enable(8)
    start = np.array(car.pose.translation)
    for n in range(1, 301):
        sim.step()
        assert float(sensor.value) == 128.0, n
        assert float(encoder.value) == pytest.approx(0.5 * 0.008 ** 2 * n * (n + 1) / 2, abs=1e-12), n
        assert np.array(car.pose.translation) == pytest.approx(start, abs=1e-15)


@pytest.mark.xfail(strict=True, reason="departures named in the README's twenty-third sweep, left to the drive's "
                   "judgement (world/wbt/drive.py): a robot built on its side, a wheel's axis 1.6e-3 off the "
                   "opposite of the other's (beyond the 1e-4 a mirrored wheel may be), one hinge carrying both "
                   "sides' wheels, the radius taken from the hinge's own sphere")
@pytest.mark.parametrize("world", ["braitenberg.wbt", "vision_car.wbt"])
def test_webots_rolls_the_tinkerbots_vehicles_on_their_wheels(world: str) -> None:
    """What Webots' physics does with both robots: each rolls on its 0.02625 m wheels (the cylinders two
    Solids past the motor's hinge), so each should get a drive of that radius."""
    (robot,) = load_world(DATA / world).world.robots
    assert robot.differential_drive is not None
    assert robot.differential_drive.wheel_radius == pytest.approx(0.02625, abs=1e-12)
