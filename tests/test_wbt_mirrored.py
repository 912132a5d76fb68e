"""A .wbt robot whose wheels turn about opposite axes (one side mounted mirrored, as Webots users build
robots and negate that side's speed in the controller) gets a drive: the mirrored wheels are its
``reversed_motors``, each one's speed counted negated, as Webots' physics rolls each wheel about its own
axis. Our own worlds (an e-puck-like robot, a four-wheel skid-steer one); closed forms: (−w, w) on the
mirrored-left robot drives straight at r·w, (w, w) spins in place at ω = 2·r·w / axle, in the single and
the batched simulation; the encoders read each motor's own turn. Without Physics, Webots' kinematic rule
reads the two velocities as they are (its pair's axes need only be parallel or opposite): there (w, w)
drives straight and (−w, w) spins."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _gym_avoid import avoid_envs
from _wheeled_wbt import H0, STEP, X0, Y0, R, T, Y, heading, robot_world, wheel

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.sim.summary import drive_line
from sensorium.server.world.loader import WorldError, load_world, parse_world

W = 5.0                                   # rad/s
LEFT, RIGHT = "left wheel motor", "right wheel motor"


def write(tmp_path: Path, wheels: str, physics: bool = True) -> Path:
    return robot_world(tmp_path / "mirrored.wbt", wheels, physics)


def two_wheels(mirrored: str = "left", right_y: float = -Y) -> str:
    left_axis, right_axis = ("0 -1 0", "0 1 0") if mirrored == "left" else ("0 1 0", "0 -1 0")
    return wheel(LEFT, 0.0, Y, left_axis) + wheel(RIGHT, 0.0, right_y, right_axis)


def drive(sim: Simulation, speeds: dict[str, float], steps: int) -> None:
    r = sim.robot("bot")
    for name, w in speeds.items():
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(w)
    sim.run(steps)


def test_a_mirrored_left_wheel_is_reversed_and_the_drive_rolls_each_wheel_about_its_axis(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, two_wheels("left")))
    assert not [x for x in w.warnings if "drive" in x], w.warnings
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.step_rule == "arc" and dd.forward == (1.0, 0.0)
    assert (dd.left_motor, dd.right_motor, dd.reversed_motors) == (LEFT, RIGHT, [LEFT])
    assert (dd.wheel_radius, dd.axle_length, dd.axle_center) == (R, 2.0 * Y, (0.0, 0.0))
    assert "mounted mirrored: left wheel motor" in drive_line(w.world.robots[0])

    # (−w, w): straight along the heading at r·w; the encoders read each motor's own turn
    sim = Simulation(w)
    for name in (LEFT, RIGHT):
        sim.robot("bot").device(f"{name} sensor").enable(STEP)
    n = 25
    drive(sim, {LEFT: -W, RIGHT: W}, n)
    pose = sim.robot("bot").pose
    s = R * W * n * T
    assert pose.translation[:2] == pytest.approx([X0 + s * math.cos(H0), Y0 + s * math.sin(H0)], abs=1e-15)
    assert heading(pose.rotation) == pytest.approx(H0, abs=1e-15)
    assert sim.robot("bot").device(f"{LEFT} sensor").value == pytest.approx(-W * n * T, abs=1e-12)
    assert sim.robot("bot").device(f"{RIGHT} sensor").value == pytest.approx(W * n * T, abs=1e-12)

    # (w, w): in place, turning left at ω = 2·r·w / axle
    sim = Simulation(w)
    drive(sim, {LEFT: W, RIGHT: W}, n)
    pose = sim.robot("bot").pose
    assert pose.translation[:2] == pytest.approx([X0, Y0], abs=1e-15)
    om = 2.0 * R * W / (2.0 * Y)
    assert math.remainder(heading(pose.rotation) - (H0 + om * n * T), 2.0 * math.pi) == pytest.approx(0.0, abs=1e-13)


def test_a_mirrored_right_wheel_drives_straight_on_w_minus_w(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, two_wheels("right")))
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.reversed_motors == [RIGHT] and dd.forward == (1.0, 0.0)
    sim = Simulation(w)
    drive(sim, {LEFT: W, RIGHT: -W}, 10)
    pose = sim.robot("bot").pose
    s = R * W * 10 * T
    assert pose.translation[:2] == pytest.approx([X0 + s * math.cos(H0), Y0 + s * math.sin(H0)], abs=1e-15)
    # (w, w) spins it the other way than the mirrored-left robot: right
    sim = Simulation(w)
    drive(sim, {LEFT: W, RIGHT: W}, 10)
    om = -2.0 * R * W / (2.0 * Y)
    assert math.remainder(heading(sim.robot("bot").pose.rotation) - (H0 + om * 10 * T),
                          2.0 * math.pi) == pytest.approx(0.0, abs=1e-13)


def test_the_batched_simulation_rolls_the_mirrored_wheel_backward_as_the_single_one(tmp_path: Path) -> None:
    """set_wheels commands the motors as a controller does: (−w, w) straight in every copy, (w, w) in place,
    each copy the single Simulation's bits."""
    w = load_world(write(tmp_path, two_wheels("left")))
    n = 20
    b = BatchedSimulation(w, 2)
    b.reset(np.arange(2), [0, 0])
    assert b.wheel_sign.tolist() == [[-1.0, 1.0]]
    b.set_wheels(0, np.array([-W, W]), np.array([W, W]))
    for _ in range(n):
        b.step()
    s = R * W * n * T
    assert b.pos[0, 0, :2] == pytest.approx([X0 + s * math.cos(H0), Y0 + s * math.sin(H0)], abs=1e-15)
    assert b.pos[1, 0, :2] == pytest.approx([X0, Y0], abs=1e-15)
    for c, (wl, wr) in enumerate(((-W, W), (W, W))):
        single = Simulation(w)
        drive(single, {LEFT: wl, RIGHT: wr}, n)
        pose = single.robot("bot").pose
        assert b.pos[c, 0].tobytes() == pose.translation.tobytes(), c
        assert b.rot[c, 0].tobytes() == pose.rotation.tobytes(), c


def test_without_physics_webots_kinematic_rule_reads_the_velocities_as_they_are(tmp_path: Path) -> None:
    """Webots' pair rule takes the two hinges (axes parallel or opposite) and moves the robot by their motors'
    velocities unsigned: (w, w) drives straight at r·w, (−w, w) spins about the origin, each step turning by
    2d, d = 2·w·T·r / (2·axle), the axle the cylinders' distances from the origin."""
    w = load_world(write(tmp_path, two_wheels("left"), physics=False))
    dd = w.world.robots[0].differential_drive
    axle = 2.0 * math.hypot(Y, R)
    assert dd is not None and dd.step_rule == "mid_heading" and dd.reversed_motors == []
    assert dd.axle_length == pytest.approx(axle, abs=1e-15)
    sim = Simulation(w)
    drive(sim, {LEFT: W, RIGHT: W}, 10)
    pose = sim.robot("bot").pose
    s = R * W * 10 * T
    assert pose.translation[:2] == pytest.approx([X0 + s * math.cos(H0), Y0 + s * math.sin(H0)], abs=1e-15)
    sim = Simulation(w)
    drive(sim, {LEFT: -W, RIGHT: W}, 10)
    pose = sim.robot("bot").pose
    d = 2.0 * W * T * R / (2.0 * axle)
    assert pose.translation[:2] == pytest.approx([X0, Y0], abs=1e-15)
    assert math.remainder(heading(pose.rotation) - (H0 + 2.0 * d * 10), 2.0 * math.pi) == pytest.approx(0.0, abs=1e-13)


def test_without_physics_and_without_a_webots_pair_the_arc_with_the_mirrored_wheel_reversed(tmp_path: Path) -> None:
    """Wheels not equally far from the origin: Webots' rule finds no pair; the arc (the drive's own departure,
    README) rolls the mirrored wheel backward, as with Physics: (−w, w) straight."""
    w = load_world(write(tmp_path, two_wheels("left", right_y=-0.027), physics=False))
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.step_rule == "arc" and dd.reversed_motors == [LEFT]
    cy = dd.axle_center[1]
    assert cy == pytest.approx((Y - 0.027) / 2.0, abs=1e-15)
    sim = Simulation(w)
    drive(sim, {LEFT: -W, RIGHT: W}, 10)
    pose = sim.robot("bot").pose
    s = R * W * 10 * T
    assert pose.translation[:2] == pytest.approx([X0 + s * math.cos(H0), Y0 + s * math.sin(H0)], abs=1e-15)
    assert heading(pose.rotation) == pytest.approx(H0, abs=1e-15)


def skid(left_axes: tuple[str, str]) -> str:
    return (wheel(LEFT, 0.05, Y, left_axes[0]) + wheel("rear left", -0.05, Y, left_axes[1])
            + wheel(RIGHT, 0.05, -Y, "0 1 0") + wheel("rear right", -0.05, -Y, "0 1 0"))


def test_a_skid_steer_robot_with_its_left_side_mirrored(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, skid(("0 -1 0", "0 -1 0"))))
    dd = w.world.robots[0].differential_drive
    assert dd is not None and dd.skid_steer is not None
    assert sorted(dd.reversed_motors) == sorted([LEFT, "rear left"])
    sim = Simulation(w)
    drive(sim, {LEFT: -W, "rear left": -W, RIGHT: W, "rear right": W}, 10)
    pose = sim.robot("bot").pose
    s = R * W * 10 * T
    assert pose.translation[:2] == pytest.approx([X0 + s * math.cos(H0), Y0 + s * math.sin(H0)], abs=1e-15)
    # one wheel of a side mirrored and not the other: a side rolls as one, so no drive, one line saying so
    (tmp_path / "mixed").mkdir()
    w = load_world(write(tmp_path / "mixed", skid(("0 -1 0", "0 1 0"))))
    assert w.world.robots[0].differential_drive is None
    (line,) = [x for x in w.warnings if "no differential drive" in x]
    assert "the left side's wheels" in line and "turn about opposite axes" in line


def test_a_tilted_axis_is_still_refused(tmp_path: Path) -> None:
    """Neither parallel nor opposite (within 5e-3; this one 1e-2 off): no drive, one load line naming the axis."""
    w = load_world(write(tmp_path, wheel(LEFT, 0.0, Y, "0 -1 0.01") + wheel(RIGHT, 0.0, -Y, "0 1 0")))
    assert w.world.robots[0].differential_drive is None
    (line,) = [x for x in w.warnings if "no differential drive" in x]
    assert f"'{LEFT}'" in line and "needs every axis along +y or -y" in line


@pytest.mark.parametrize("reversed_motors, why", [
    (["front"], "reversed_motors: 'front' is not one of the drive's wheel motors ('l', 'l2', 'r', 'r2')"),
    (["l"], "reversed_motors: the left side's wheels ['l', 'l2'] roll as one, so name all of them or none, got ['l']"),
])
def test_reversed_motors_must_be_the_drives_and_a_sides_all_or_none(reversed_motors, why) -> None:
    data = {"robots": [{"name": "bot", "differential_drive": {
        "left_motor": "l", "right_motor": "r", "skid_steer": {"left": ["l2"], "right": ["r2"]},
        "reversed_motors": reversed_motors}}]}
    with pytest.raises(WorldError) as e:
        parse_world(data)
    assert why in str(e.value)
    assert "\n" not in str(e.value).strip()


@pytest.mark.parametrize("helper", [True, False], ids=["helper", "numpy"])
def test_the_gym_takes_left_and_right_as_the_sides_forward_speeds(tmp_path: Path, helper: bool, monkeypatch) -> None:
    """The gym's (+1, +1) on the mirrored-left robot commands (−20, 20) rad/s: it drives straight ahead at full
    speed, AvoidObstacles' v 1 and dv 0 (reward exactly 1 in open space; the motors' own velocities would give
    0), the single env and the vector env's C and numpy passes alike; (+1, −1) turns it right in place."""
    pytest.importorskip("gymnasium")
    path = write(tmp_path, two_wheels("left"))
    env, venv = avoid_envs(path, helper, monkeypatch)
    start = np.array(env.sim.robot("bot").pose.translation)
    for action, want in (([1.0, 1.0], 1.0), ([1.0, -1.0], 0.0)):
        _, reward, *_ = env.step(np.array(action, dtype=np.float32))
        _, rewards, *_ = venv.step(np.array([action, action], dtype=np.float32))
        motors = env.sim.robot("bot").motors
        assert (motors[LEFT].velocity, motors[RIGHT].velocity) == (-20.0 * action[0], 20.0 * action[1])
        assert reward == want
        assert rewards.tolist() == [reward, reward]
        if action == [1.0, 1.0]:
            moved = np.array(env.sim.robot("bot").pose.translation) - start
            assert moved[:2] / np.linalg.norm(moved[:2]) == pytest.approx([math.cos(H0), math.sin(H0)], abs=1e-12)
            assert heading(env.sim.robot("bot").pose.rotation) == pytest.approx(H0, abs=1e-12)


def test_the_sweeps_spin_spins_the_mirrored_robot_in_place(tmp_path: Path) -> None:
    """The built-in ``spin`` asks the sides for (−v/2, v/2), v = maxVelocity 20: the mirrored left motor is
    commanded +10 rad/s, so the robot turns in place at ω = 2·r·10 / axle (the motors' own (−10, 10) would
    drive it straight)."""
    from sensorium.sweep.controllers import spin

    sim = Simulation(load_world(write(tmp_path, two_wheels("left"))))
    spin(sim)
    motors = sim.robot("bot").motors
    assert (motors[LEFT].velocity, motors[RIGHT].velocity) == (10.0, 10.0)
    sim.run(10)
    pose = sim.robot("bot").pose
    assert pose.translation[:2] == pytest.approx([X0, Y0], abs=1e-15)
    om = 2.0 * R * 10.0 / (2.0 * Y)
    assert math.remainder(heading(pose.rotation) - (H0 + om * 10 * T), 2.0 * math.pi) == pytest.approx(0.0, abs=1e-13)
