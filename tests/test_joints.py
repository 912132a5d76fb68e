"""Motors that are no wheels: their joints move kinematically, as Webots moves a joint whose end
point has no physics (WbMotor's kinematic control), and their PositionSensors read the position.

Every expected value is Webots' rule in closed form: per basic step of dt seconds the speed moves
towards the commanded velocity by at most a·dt (a: the acceleration, or the available torque/force
when that is -1 or larger), then the position moves by speed·dt towards the target, never past it;
nothing moves within 1e-6 of the target, nor in velocity control at a limit it pushes against."""

from __future__ import annotations

import math

import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

DT_MS = 16
DT = DT_MS * 0.001


def _arm(*devices: dict, drive: bool = False) -> Simulation:
    robot: dict = {"name": "arm", "devices": list(devices)}
    if drive:
        robot["differential_drive"] = {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10}
    return Simulation(parse_world({"world_info": {"basic_time_step": DT_MS}, "robots": [robot]}))


def _hinge(name: str = "shoulder", **fields) -> list[dict]:
    return [{"device": "RotationalMotor", "name": name, **fields},
            {"device": "PositionSensor", "name": f"{name} sensor", "motor": name}]


def _readings(sim: Simulation, sensor: str, steps: int) -> list[float]:
    out = []
    for _ in range(steps):
        sim.step()
        out.append(sim.device(sensor).value)
    return out


def test_position_control_reaches_the_target_after_ceil_p_over_v_dt_steps() -> None:
    """maxVelocity v = 1 rad/s, maxTorque 1000 (the speed reaches v in the first step: 1000·dt > v):
    target p = 0.1 rad is reached after ceil(p / (v dt)) = ceil(6.25) = 7 steps, the readings
    before it k·v·dt, the last exactly p (Webots clamps at the target); then the joint stays."""
    sim = _arm(*_hinge(max_velocity=1.0, max_torque=1000.0))
    motor = sim.robot("arm").motor("shoulder")
    sim.device("arm/shoulder sensor").enable(DT_MS)
    motor.set_position(0.1)
    steps = math.ceil(0.1 / (1.0 * DT))
    got = _readings(sim, "arm/shoulder sensor", steps + 3)
    assert got[:steps - 1] == pytest.approx([k * DT for k in range(1, steps)], abs=1e-15)
    assert got[steps - 2] < 0.1 and got[steps - 1:] == [0.1] * 4
    assert motor.speed == 0.0                  # within 1e-6 of the target: Webots stops the motor


def test_default_motor_accelerates_at_its_max_torque() -> None:
    """Webots' defaults (maxVelocity 10, acceleration -1, maxTorque 10): without physics the speed
    grows by maxTorque·dt = 0.16 rad/s per step, so after k steps (before the target) the joint has
    turned dt·0.16·k(k+1)/2; a target of 1 rad is reached at the first k where that is >= 1
    (k(k+1) >= 781.25: k = 28), the reading then exactly 1."""
    sim = _arm(*_hinge())
    motor = sim.robot("arm").motor("shoulder")
    sim.device("arm/shoulder sensor").enable(DT_MS)
    motor.set_position(1.0)
    got = _readings(sim, "arm/shoulder sensor", 30)
    closed = [DT * 10.0 * DT * k * (k + 1) / 2 for k in range(1, 31)]
    first = next(k for k, v in enumerate(closed) if v >= 1.0)      # (0-based) step that reaches 1 rad
    assert got[:first] == pytest.approx(closed[:first], rel=1e-12)
    assert got[first:] == [1.0] * (30 - first)
    assert first + 1 == 28


def test_acceleration_field_bounds_the_ramp() -> None:
    """acceleration 5 (below maxTorque 10) bounds the ramp: the speed is min(5·dt·k, 0.4) rad/s
    after k steps (maxVelocity 0.4), the position minus the sum of speed·dt (a negative target)."""
    sim = _arm(*_hinge(max_velocity=0.4, acceleration=5.0))
    motor = sim.robot("arm").motor("shoulder")
    motor.set_position(-0.5)
    speeds = []
    for _ in range(8):
        sim.step()
        speeds.append(motor.speed)
    assert speeds == pytest.approx([min(5.0 * DT * k, 0.4) for k in range(1, 9)], rel=1e-12)
    pos = 0.0
    for s in speeds:
        pos -= s * DT
    assert motor.position == pytest.approx(pos, rel=1e-12)


def test_position_limits_clamp_the_target_with_webots_warning(capsys) -> None:
    """min/maxPosition [-0.5, 0.5]: a target of 2 becomes 0.5 with WbMotor's warning line, -3
    becomes -0.5; the joint stops there."""
    sim = _arm(*_hinge(max_velocity=2.0, max_torque=1000.0, min_position=-0.5, max_position=0.5))
    motor = sim.robot("arm").motor("shoulder")
    motor.set_position(2.0)
    assert capsys.readouterr().err == 'WARNING: RotationalMotor "shoulder": too big requested position: 2 > 0.5\n'
    assert motor.target_position == 0.5
    sim.run(40)
    assert motor.position == 0.5
    motor.set_position(-3.0)
    assert capsys.readouterr().err == 'WARNING: RotationalMotor "shoulder": too low requested position: -3 < -0.5\n'
    sim.run(40)
    assert motor.position == -0.5


def test_velocity_control_integrates_v_dt_per_step_and_stops_past_a_limit() -> None:
    """setPosition(inf), setVelocity(1): the joint turns v·dt = 0.016 rad per step; with maxPosition
    0.5 Webots takes the step that crosses the limit (32 steps: 0.512) and none after it; a negative
    velocity then turns it back."""
    sim = _arm(*_hinge(max_velocity=1.0, max_torque=1000.0, min_position=-0.5, max_position=0.5))
    motor = sim.robot("arm").motor("shoulder")
    sim.device("arm/shoulder sensor").enable(DT_MS)
    motor.set_position(math.inf)
    motor.set_velocity(1.0)
    got = _readings(sim, "arm/shoulder sensor", 40)
    assert got[:32] == pytest.approx([k * DT for k in range(1, 33)], abs=1e-14)
    assert got[32:] == [got[31]] * 8 and got[31] > 0.5
    motor.set_velocity(-1.0)
    sim.run(2)                                 # the speed goes from 0 to -1 in one step (1000·dt)
    assert motor.position == pytest.approx(got[31] - 2 * DT, abs=1e-14)


def test_linear_motor_moves_its_slider() -> None:
    """A LinearMotor (metres) follows the same rule: maxVelocity 0.05 m/s, maxForce 100 (the speed
    in one step), a target of 0.01 m reached after ceil(0.01 / (0.05·0.016)) = 13 steps."""
    sim = _arm({"device": "LinearMotor", "name": "lift", "max_velocity": 0.05, "max_force": 100.0,
                "min_position": 0.0, "max_position": 0.2},
               {"device": "PositionSensor", "name": "lift sensor", "motor": "lift"})
    motor = sim.robot("arm").motor("lift")
    sim.device("arm/lift sensor").enable(DT_MS)
    motor.set_position(0.01)
    got = _readings(sim, "arm/lift sensor", 14)
    assert got[:12] == pytest.approx([k * 0.05 * DT for k in range(1, 13)], abs=1e-15)
    assert got[12:] == [0.01, 0.01]


def test_initial_position_reset_and_noise_free_resolution() -> None:
    """The joint starts at its position field (the motor holds it), a sensor's resolution is
    Webots' discretize, and reset puts the joint back."""
    sim = _arm({"device": "RotationalMotor", "name": "wrist", "position": 0.3, "max_torque": 1000.0},
               {"device": "PositionSensor", "name": "wrist sensor", "motor": "wrist", "resolution": 0.25})
    motor = sim.robot("arm").motor("wrist")
    sensor = sim.device("arm/wrist sensor")
    sensor.enable(DT_MS)
    sim.step()
    assert motor.target_position == 0.3 and motor.position == 0.3 and sensor.value == 0.25
    motor.set_position(1.0)
    sim.run(50)
    assert motor.position == 1.0 and sensor.value == 1.0
    sim.reset()
    assert (motor.position, motor.target_position, motor.velocity, motor.speed) == (0.3, 0.3, 10.0, 0.0)


def test_available_torque_zero_holds_the_joint() -> None:
    """setAvailableTorque(0): Webots' acceleration bound is 0, so the joint never starts moving."""
    sim = _arm(*_hinge())
    motor = sim.robot("arm").motor("shoulder")
    motor.set_available_force(0.0)
    motor.set_position(1.0)
    sim.run(10)
    assert motor.position == 0.0


def test_drive_unchanged_by_an_arm_and_device_list() -> None:
    """A robot with a drive and an arm joint: the wheels turn exactly as without the arm, the arm
    moves, and both motors are listed as simulated."""
    plain = _arm(drive=True)
    armed = _arm(*_hinge(max_torque=1000.0), drive=True)
    for sim in (plain, armed):
        for name, v in (("left wheel motor", 3.0), ("right wheel motor", 5.0)):
            m = sim.robot("arm").motor(name)
            m.set_position(math.inf)
            m.set_velocity(v)
    armed.robot("arm").motor("shoulder").set_position(0.5)
    plain.run(50)
    armed.run(50)
    a, b = plain.robot("arm").pose, armed.robot("arm").pose
    assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes()
    assert armed.robot("arm").motor("shoulder").position == 0.5
    entries = {e.name: (e.type, e.simulated) for e in armed.robot("arm").device_list}
    assert entries["shoulder"] == ("RotationalMotor", True) and entries["left wheel motor"] == ("RotationalMotor", True)


@pytest.mark.parametrize("fields, message", [
    ({"acceleration": -2.0}, "acceleration must be >= 0"),
    ({"min_position": 1.0, "max_position": 0.5}, "min_position 1.0 > max_position 0.5"),
    ({"min_position": -1.0, "max_position": 1.0, "position": 2.0}, "position 2.0 outside"),
])
def test_bad_motor_fields_are_refused(fields: dict, message: str) -> None:
    with pytest.raises(Exception, match=message):
        _arm(*_hinge(**fields))


def test_wbt_robot_keeps_its_drive_bit_identical_and_its_arm_joint_moves(tmp_path) -> None:
    """A .wbt two-wheel robot with a tilt hinge (along the wheels' axis, but a box at its end: no
    wheel; position 0.2, limits [-1, 0.5], maxVelocity 2, maxTorque 1000: full speed in one step)
    and a slider (maxPosition 0.03 below its position 0.05,
    which Webots widens to 0.05 with a warning): its drive turns exactly as the same robot without
    them, the hinge's sensor reads 0.2 + k·2·dt up to 0.5, and the slider starts at 0.05."""
    from test_wbt_drives import wheel, write

    from sensorium.server.world.loader import load_world

    arm = ('HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0 0.2 position 0.2 }\n'
           '  device [ RotationalMotor { name "tilt" maxVelocity 2 maxTorque 1000 minPosition -1 maxPosition 0.5 }\n'
           '           PositionSensor { name "tilt sensor" } ]\n'
           '  endPoint Solid { translation 0 0 0.2 children [ Shape { geometry Box { size 0.02 0.02 0.02 } }\n'
           '    SliderJoint { jointParameters JointParameters { axis 0 0 1 position 0.05 }\n'
           '      device [ LinearMotor { name "lift" maxPosition 0.03 } PositionSensor { name "lift sensor" } ]\n'
           '      endPoint Solid { } } ] } }\n')
    wheels = wheel("left wheel", 0, 0.1) + wheel("right wheel", 0, -0.1)
    sims = []
    for i, extra in enumerate(("", arm)):
        folder = tmp_path / str(i)
        folder.mkdir()
        w = load_world(write(folder, 'Robot { name "rover" children [\n' + extra + wheels + '] }\n'))
        sims.append(Simulation(w))
    plain, armed = sims
    assert any("LinearMotor.maxPosition: 0.03 is below the joint's position; using 0.05 (as Webots does)" in x
               for x in w.warnings)
    for sim in sims:
        for name, v in (("left wheel", 4.0), ("right wheel", 6.0)):
            m = sim.robot("rover").motor(name)
            m.set_position(math.inf)
            m.set_velocity(v)
    robot = armed.robot("rover")
    assert sorted(robot.joints) == ["lift", "tilt"]
    tilt, lift = robot.motor("tilt"), robot.motor("lift")
    assert (tilt.position, tilt.min_position, tilt.max_position, lift.position, lift.max_position) == (0.2, -1, 0.5, 0.05, 0.05)
    armed.device("rover/tilt sensor").enable(DT_MS)
    tilt.set_position(0.5)
    got = []
    for _ in range(12):
        plain.step()
        armed.step()
        got.append(armed.device("rover/tilt sensor").value)
        a, b = plain.robot("rover").pose, armed.robot("rover").pose
        assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes()
    steps = math.ceil((0.5 - 0.2) / (2.0 * DT))          # 9.375: reached at step 10
    assert got[:steps - 1] == pytest.approx([0.2 + k * 2.0 * DT for k in range(1, steps)], abs=1e-14)
    assert got[steps - 1:] == [0.5] * (12 - steps + 1)


def test_the_batched_simulation_moves_a_joint_as_the_single_one() -> None:
    """Each copy's joint and its encoder as the single simulation's (tests/test_batched_joints.py has
    the full comparison); an LED on a joint is refused in one line."""
    from sensorium.server.sim.batched import BatchedError, BatchedSimulation

    world = parse_world({"world_info": {"basic_time_step": DT_MS},
                         "robots": [{"name": "arm", "devices": _hinge(max_velocity=2.0)}]})
    batched, single = BatchedSimulation(world, 2), Simulation(world)
    ref = batched.device("arm", "shoulder sensor")
    batched.enable(ref, DT_MS)
    batched.joints.command(0, "shoulder", position=0.5, copies=[1])
    single.robot("arm").motor("shoulder").set_position(0.5)
    single.device("arm/shoulder sensor").enable(DT_MS)
    got = _readings(single, "arm/shoulder sensor", 12)
    assert 0.0 < got[0] < got[-1] < 0.5          # ramped up at maxTorque 10 rad/s², not there yet
    for want in got:
        batched.step()
        assert batched.value(ref).tolist() == [0.0, want]
    carried = {"name": "arm", "devices": [*_hinge(), {"device": "LED", "name": "lamp", "on_joint": "shoulder"}]}
    with pytest.raises(BatchedError, match=r"robot 'arm': LED 'lamp' rides joint 'shoulder'; the batched simulation "
                                           r"moves distance sensors"):
        BatchedSimulation(parse_world({"world_info": {"basic_time_step": DT_MS}, "robots": [carried]}), 2)


def test_a_drive_motor_entry_with_joint_fields_is_refused_in_one_line() -> None:
    with pytest.raises(Exception, match=r"devices\[0\] \(left wheel motor\)\.max_velocity: 'left wheel motor' is a motor of the robot's "
                                        "drive, which sets its speed and limits: leave out max_velocity"):
        _arm({"device": "RotationalMotor", "name": "left wheel motor", "max_velocity": 3.0}, drive=True)
