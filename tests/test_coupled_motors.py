"""Webots' coupled motors and the joint motors' setVelocity rule, in process (sim/joints.py).

Motors named ``group::part`` on one robot are a group: a position or velocity given to one reaches
every joint motor of the group, each scaling it by its own ``multiplier`` (WbMotor::handleMessage,
setTargetPosition, setVelocity). As a world loads, the group's first motor sets the others' limits
and maximum velocities (checkMinAndMaxPositionAcrossCoupledMotors, checkMaxVelocityAcrossCoupledMotors).
Every expected value is Webots' kinematic rule in closed form (tests/test_joints.py): with maxTorque
1000 the speed reaches the velocity in the first step, then a target d away is reached after
ceil(d / (v dt)) steps, the readings k·v·dt before it."""

from __future__ import annotations

import math

import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

DT_MS = 16
DT = DT_MS * 0.001


def _world(*devices: dict) -> dict:
    return {"world_info": {"basic_time_step": DT_MS}, "robots": [{"name": "hand", "devices": list(devices)}]}


def _finger(name: str, multiplier: float, **fields) -> list[dict]:
    return [{"device": "RotationalMotor", "name": name, "multiplier": multiplier, "max_torque": 1000.0, **fields},
            {"device": "PositionSensor", "name": f"{name} sensor", "motor": name}]


def _pair(**b_fields) -> Simulation:
    """grip::a (multiplier 1, maxVelocity 1) and grip::b (multiplier -2, maxVelocity 2: consistent)."""
    sim = Simulation(parse_world(_world(*_finger("grip::a", 1.0, max_velocity=1.0),
                                        *_finger("grip::b", -2.0, max_velocity=2.0, **b_fields))))
    for name in ("grip::a", "grip::b"):
        sim.device(f"hand/{name} sensor").enable(DT_MS)
    return sim


def _run(sim: Simulation, steps: int) -> list[tuple[float, float]]:
    out = []
    for _ in range(steps):
        sim.step()
        out.append((sim.device("hand/grip::a sensor").value, sim.device("hand/grip::b sensor").value))
    return out


def test_a_position_given_to_one_motor_moves_the_pair_by_its_multipliers() -> None:
    """p = 0.1 on grip::a: its target 0.1, grip::b's -2p = -0.2. a at 1 rad/s and b at 2 rad/s (each
    one's maxVelocity) both arrive after ceil(0.1 / 0.016) = 7 steps, b's readings -2·k·dt."""
    sim = _pair()
    a, b = sim.robot("hand").motor("grip::a"), sim.robot("hand").motor("grip::b")
    a.set_position(0.1)
    assert (a.target_position, b.target_position) == (0.1, -0.2)
    got = _run(sim, 9)
    steps = math.ceil(0.1 / (1.0 * DT))
    assert steps == 7
    for k, (qa, qb) in enumerate(got[:steps - 1], start=1):
        assert qa == pytest.approx(k * DT, abs=1e-15) and qb == pytest.approx(-2 * k * DT, abs=1e-15)
    assert got[steps - 1:] == [(0.1, -0.2)] * 3


def test_a_velocity_given_to_one_motor_reaches_the_other_scaled() -> None:
    """From (0.1, -0.2), setVelocity(0.5) on a gives b -1 rad/s; back to 0 both take
    ceil(0.1 / (0.5 dt)) = ceil(0.2 / (1 dt)) = 13 steps (b towards its target at the speed's
    magnitude). In velocity control b turns at -1 rad/s while a turns at 0.5."""
    sim = _pair()
    a, b = sim.robot("hand").motor("grip::a"), sim.robot("hand").motor("grip::b")
    a.set_position(0.1)
    _run(sim, 7)
    a.set_velocity(0.5)
    assert (a.velocity, b.velocity) == (0.5, -1.0)
    a.set_position(0.0)
    got = _run(sim, 14)
    for k, (qa, qb) in enumerate(got[:12], start=1):
        assert qa == pytest.approx(0.1 - 0.5 * k * DT, abs=1e-15) and qb == pytest.approx(-0.2 + k * DT, abs=1e-15)
    assert got[12:] == [(0.0, 0.0)] * 2
    a.set_position(math.inf)
    assert b.target_position == math.inf            # +inf stays +inf, whatever the multiplier (Webots)
    got = _run(sim, 3)
    assert [qb for _, qb in got] == pytest.approx([-1.0 * DT * k for k in (1, 2, 3)], abs=1e-15)
    assert [qa for qa, _ in got] == pytest.approx([0.5 * DT * k for k in (1, 2, 3)], abs=1e-15)


def test_the_commanded_motor_scales_by_its_own_multiplier_too() -> None:
    """WbMotor::setTargetPosition scales every motor's target, the commanded one's too: 0.1 given
    to grip::b (multiplier -2) makes its target -0.2 and grip::a's 0.1."""
    sim = _pair()
    a, b = sim.robot("hand").motor("grip::a"), sim.robot("hand").motor("grip::b")
    b.set_position(0.1)
    assert (a.target_position, b.target_position) == (0.1, -0.2)


def test_a_limit_clamps_each_member_with_webots_warning(capsys) -> None:
    """grip::a limited to [-0.5, 0.5]: grip::b's limits become [-1, 1] (a's scaled by -2/1, ordered)
    and its maxVelocity 2 (|−2|/1 times a's), each change said at load. 0.8 given to a: a's target
    clamps to 0.5, b's -1.6 to -1, each with Webots' warning, which names the value asked for."""
    world = parse_world(_world(
        *_finger("grip::a", 1.0, max_velocity=1.0, min_position=-0.5, max_position=0.5),
        *_finger("grip::b", -2.0, min_position=-0.3, max_position=0.3)))
    assert world.warnings == [
        "robots[0].devices[2] (grip::b).min_position: coupled with 'grip::a', whose limits set its own: -0.3 set to -1",
        "robots[0].devices[2] (grip::b).max_position: coupled with 'grip::a', whose limits set its own: 0.3 set to 1",
        "robots[0].devices[2] (grip::b).max_velocity: coupled with 'grip::a', whose maximum velocity sets its own: "
        "10 set to 2"]
    sim = Simulation(world)
    a, b = sim.robot("hand").motor("grip::a"), sim.robot("hand").motor("grip::b")
    assert (b.min_position, b.max_position, b.max_velocity) == (-1.0, 1.0, 2.0)
    a.set_position(0.8)
    assert (a.target_position, b.target_position) == (0.5, -1.0)
    assert capsys.readouterr().err.splitlines() == [
        'WARNING: RotationalMotor "grip::a": too big requested position: 0.8 > 0.5',
        'WARNING: RotationalMotor "grip::b": too low requested position: 0.8 < -1']
    for name in ("grip::a", "grip::b"):
        sim.device(f"hand/{name} sensor").enable(DT_MS)
    got = _run(sim, 33)           # both at 0.5/(1·dt) = 1/(2·dt) = 31.25: there at step 32
    assert got[30] == (pytest.approx(31 * DT, abs=1e-14), pytest.approx(-62 * DT, abs=1e-14))
    assert got[31:] == [(0.5, -1.0)] * 2


def test_an_unlimited_first_motor_lifts_its_siblings_limits_and_a_zero_multiplier_is_one() -> None:
    world = parse_world(_world(
        *_finger("grip::a", 1.0, max_velocity=1.0), *_finger("grip::b", 0.0, max_velocity=1.0, max_position=0.2),
        *_finger("lone::x", 1.0), *_finger("a::b::c", 1.0)))
    assert world.warnings == [
        "robots[0].devices[2].multiplier: 0, reset to 1 (Webots: it cannot be 0)",
        "robots[0].devices[2] (grip::b).max_position: coupled with 'grip::a', whose limits set its own: 0.2 set to 0",
        "robots[0].devices[4] (lone::x): uses the coupled motor name structure ('lone::...') but has no sibling: "
        "not coupled"]
    sim = Simulation(world)
    b = sim.robot("hand").motor("grip::b")
    assert (b.multiplier, b.min_position, b.max_position) == (1.0, 0.0, 0.0)
    assert sim.robot("hand").motor("lone::x").coupled == () and sim.robot("hand").motor("a::b::c").coupled == ()


def test_a_negative_velocity_in_position_control_is_refused_with_webots_line(capsys) -> None:
    """JointMotor.set_velocity takes the wheels' rule (motion.velocity_accepted): in position control
    -1 is ignored with libController's line, and the joint keeps its speed (1 rad/s: 0.1 in 7 steps)."""
    sim = Simulation(parse_world(_world(*_finger("elbow", 1.0, max_velocity=1.0))))
    motor = sim.robot("hand").motor("elbow")
    sim.device("hand/elbow sensor").enable(DT_MS)
    motor.set_position(0.1)
    motor.set_velocity(-1.0)
    assert capsys.readouterr().err == ("Error: setVelocity() called with negative 'velocity' argument in position "
                                       "control mode (0.1): motor 'elbow' keeps 1.\n")
    assert motor.velocity == 1.0
    got = []
    for _ in range(7):
        sim.step()
        got.append(sim.device("hand/elbow sensor").value)
    assert got[:6] == pytest.approx([k * DT for k in range(1, 7)], abs=1e-15) and got[6] == 0.1
    with pytest.raises(ValueError, match="motor 'elbow': velocity must be a number"):
        motor.set_velocity(math.nan)
    motor.set_position(math.inf)
    motor.set_velocity(-1.0)                 # velocity control: taken
    assert motor.velocity == -1.0


def test_a_negative_velocity_left_from_velocity_control_moves_the_joint_towards_its_new_target() -> None:
    """Three steps at -1 rad/s in velocity control, then setPosition(0): the speed ramps to the
    velocity's magnitude (maxTorque 1000: at once) and the joint goes back, 3 steps of dt, instead
    of running away from its target (Webots' kinematic code; README "Joints", departure)."""
    sim = Simulation(parse_world(_world(*_finger("elbow", 1.0, max_velocity=1.0))))
    motor = sim.robot("hand").motor("elbow")
    sim.device("hand/elbow sensor").enable(DT_MS)
    motor.set_position(math.inf)
    motor.set_velocity(-1.0)
    got = []
    for _ in range(3):
        sim.step()
        got.append(sim.device("hand/elbow sensor").value)
    assert got == pytest.approx([-DT, -2 * DT, -3 * DT], abs=1e-15)
    motor.set_position(0.0)
    got = []
    for _ in range(4):
        sim.step()
        got.append(sim.device("hand/elbow sensor").value)
    assert got[:2] == pytest.approx([-2 * DT, -DT], abs=1e-15) and got[2:] == [0.0, 0.0]
