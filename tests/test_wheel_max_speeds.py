"""Each wheel motor keeps its own maxVelocity (drives' ``motor_max_speeds``): a robot of our own with
two wheels of 133.33 and 140 rad/s (an Elisa-3's), written as a .wbt, clamps each wheel to its own,
drives the closed form of the two clamped speeds (no Physics: Webots' kinematic rule's steps), tells the client each motor's own maximum (the
warning names it), steps batched copies bit for bit and scales the gym's ±1 by each wheel's own."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _gym_avoid import avoid_envs

from sensorium.gym.views import CopySim
from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world

R, HALF_AXLE = 0.0045, 0.0203            # wheel radius, half the track (m)
LEFT_MAX, RIGHT_MAX = 133.33, 140.0
STEP = 16


def _wheel(name: str, y: float, vmax: float) -> str:
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} {R} }} '
            f'device [ RotationalMotor {{ name "{name}" maxVelocity {vmax} }} ] '
            f'endPoint Solid {{ translation 0 {y} {R} rotation 1 0 0 1.5708 children [ DEF W Shape {{ geometry '
            f'Cylinder {{ radius {R} height 0.003 }} }} ] boundingObject USE W }} }}\n')


def _wbt(tmp_path: Path) -> Path:
    p = tmp_path / "two_maxima.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\n"
                 'Robot { name "bot" children [\n'
                 '  Pose { translation 0 0 0.01 children [ Shape { geometry Box { size 0.03 0.03 0.01 } } ] }\n'
                 + _wheel("left wheel motor", HALF_AXLE, LEFT_MAX) + _wheel("right wheel motor", -HALF_AXLE, RIGHT_MAX)
                 + '] }\n')
    return p


def test_the_import_keeps_each_wheels_own_maximum_without_a_warning(tmp_path: Path) -> None:
    loaded = load_world(_wbt(tmp_path))
    drive = loaded.world.robots[0].differential_drive
    assert drive is not None
    assert (drive.max_wheel_speed, drive.motor_max_speeds) == (LEFT_MAX, {"right wheel motor": RIGHT_MAX})
    assert not [w for w in loaded.warnings if "maxVelocity" in w]


def test_a_skid_steer_side_shares_its_smaller_maximum_said_at_load(tmp_path: Path) -> None:
    def wheel(name: str, x: float, y: float, vmax: float) -> str:
        return _wheel(name, y, vmax).replace(f"anchor 0 {y}", f"anchor {x} {y}").replace(
            f"translation 0 {y}", f"translation {x} {y}")

    p = tmp_path / "four.wbt"
    p.write_text("#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 16 }\nRobot { name \"bot\" children [\n"
                 + wheel("fl", 0.03, 0.02, 12.0) + wheel("fr", 0.03, -0.02, 15.0)
                 + wheel("bl", -0.03, 0.02, 9.0) + wheel("br", -0.03, -0.02, 15.0) + "] }\n")
    loaded = load_world(p)
    drive = loaded.world.robots[0].differential_drive
    assert drive is not None and drive.skid_steer is not None
    assert (drive.max_wheel_speed, drive.motor_max_speeds) == (9.0, {"fr": 15.0, "br": 15.0})
    said = [w for w in loaded.warnings if "maxVelocity" in w]
    assert len(said) == 1 and "one side have different maxVelocity [9.0, 12.0]: the side rolls as one, at the smaller" in said[0]


def test_each_wheel_clamps_to_its_own_and_the_robot_drives_their_arc(tmp_path: Path) -> None:
    sim = Simulation(load_world(_wbt(tmp_path)).world, precision="exact")
    robot = sim.robot("bot")
    left, right = robot.motor("left wheel motor"), robot.motor("right wheel motor")
    for m in (left, right):
        m.set_position(math.inf)
        m.set_velocity(150.0)
    assert (left.velocity, right.velocity) == (LEFT_MAX, RIGHT_MAX)
    n = 50
    for _ in range(n):
        sim.step()
    # no Physics: Webots' rule, the axle the wheels' 3-D distances from the origin; each step a chord s along
    # the mid-step heading, turning 2d: after n steps from heading 0, s·sin(nd)/sin(d) along heading nd
    t, axle = STEP / 1000.0, 2.0 * math.hypot(HALF_AXLE, R)
    s, d = R * (LEFT_MAX + RIGHT_MAX) / 2.0 * t, (RIGHT_MAX - LEFT_MAX) * t * R / (2.0 * axle)
    end = robot.pose.translation
    assert end[0] == pytest.approx(s * math.sin(n * d) / math.sin(d) * math.cos(n * d), abs=1e-12)
    assert end[1] == pytest.approx(s * math.sin(n * d) / math.sin(d) * math.sin(n * d), abs=1e-12)


def test_the_client_clamps_and_warns_with_each_motors_own_maximum(tmp_path: Path, capsys) -> None:
    from _inproc import inproc_server

    from sensorium.client import wb
    from sensorium.client.webots.controller import Robot

    with inproc_server(heartbeat_ms=5000, world=_wbt(tmp_path)) as (_core, transport):
        wb.wb_robot_init(f"{transport.rpc_endpoint}/bot")
        try:
            robot = Robot()
            left, right = robot.getDevice("left wheel motor"), robot.getDevice("right wheel motor")
            assert (left.getMaxVelocity(), right.getMaxVelocity()) == (LEFT_MAX, RIGHT_MAX)
            for m in (left, right):
                m.setPosition(math.inf)
            capsys.readouterr()
            right.setVelocity(140.0)                      # its own maximum: no warning
            assert capsys.readouterr().err == ""
            left.setVelocity(140.0)
            right.setVelocity(150.0)
            assert capsys.readouterr().err.splitlines() == [
                'WARNING: RotationalMotor "left wheel motor": The requested velocity 140 exceeds \'maxVelocity\' = 133.33.',
                'WARNING: RotationalMotor "right wheel motor": The requested velocity 150 exceeds \'maxVelocity\' = 140.']
            assert (left.getVelocity(), right.getVelocity()) == (LEFT_MAX, RIGHT_MAX)
        finally:
            wb.wb_robot_cleanup()


def _drive_both(s, speeds: dict[str, float]) -> None:
    for name, u in speeds.items():
        m = s.robot("bot").motors[name]
        m.set_position(math.inf)
        m.set_velocity(u)


MECANUM = {"wheel_radius": 0.05, "lx": 0.1, "ly": 0.12, "max_wheel_speed": 5.0,
           "motor_max_speeds": {"wheel1": 7.0, "wheel4": 9.5}}
OMNI = {"max_wheel_speed": 4.0, "motor_max_speeds": {"b": 6.0},
        "wheels": [{"motor": m, "position": [0.1 * math.cos(a), 0.1 * math.sin(a)],
                    "axis": [math.cos(a), math.sin(a)], "radius": 0.03}
                   for m, a in (("a", 0.0), ("b", 2.0944), ("c", 4.18879))]}


@pytest.mark.parametrize("field,drive,speeds", [
    ("differential_drive", {"wheel_radius": R, "axle_length": 2 * HALF_AXLE, "max_wheel_speed": LEFT_MAX,
                            "motor_max_speeds": {"right wheel motor": RIGHT_MAX}},
     [{"left wheel motor": 150.0, "right wheel motor": 150.0}, {"left wheel motor": -200.0, "right wheel motor": 90.0}]),
    ("mecanum_drive", MECANUM, [{"wheel1": 8.0, "wheel2": 8.0, "wheel3": -8.0, "wheel4": 8.0},
                                {"wheel1": -20.0, "wheel2": 3.0, "wheel3": 6.0, "wheel4": -9.0}]),
    ("omni_drive", OMNI, [{"a": 10.0, "b": 10.0, "c": -10.0}, {"a": -1.0, "b": -7.0, "c": 5.0}]),
    ("ackermann_drive", {"wheelbase": 0.3, "track_front": 0.2, "track_rear": 0.2, "front_wheel_radius": 0.05,
                         "rear_wheel_radius": 0.05, "type": "4x4", "max_wheel_speed": 20.0,
                         "motor_max_speeds": {"left_rear_wheel": 26.0, "right_front_wheel": 23.0}},
     [{"right_front_wheel": 30.0, "left_front_wheel": 30.0, "right_rear_wheel": 30.0, "left_rear_wheel": 30.0},
      {"right_front_wheel": -30.0, "left_front_wheel": 10.0, "right_rear_wheel": 21.0, "left_rear_wheel": -25.0}]),
])
def test_each_wheel_clamps_to_its_own_and_batched_copies_agree_bit_for_bit(field: str, drive: dict,
                                                                          speeds: list[dict]) -> None:
    world = parse_world({"world_info": {"basic_time_step": STEP}, "robots": [{"name": "bot", field: drive}]})
    model = getattr(world.world.robots[0], field)
    single, batched = Simulation(world, precision="exact"), BatchedSimulation(world, 2)
    view = CopySim(batched, 1)
    for t in range(40):
        if t % 20 == 0:
            for s in (single, view):
                _drive_both(s, speeds[t // 20])
            for name, u in speeds[t // 20].items():           # each clamped to its own maximum
                own = wm.wheel_max_speed(model, name)
                assert own == drive["motor_max_speeds"].get(name, drive["max_wheel_speed"])
                for s in (single, view):
                    assert s.robot("bot").motors[name].velocity == min(max(u, -own), own), (name, u)
        single.step()
        view.step()
        a, b = single.robot("bot").pose, view.robot("bot").pose
        assert a.translation.tobytes() == b.translation.tobytes() and a.rotation.tobytes() == b.rotation.tobytes(), t
    assert single.robot("bot").pose.translation[:2].any()


def test_the_gyms_plus_one_is_each_wheels_own_maximum(tmp_path: Path) -> None:
    pytest.importorskip("gymnasium")
    from sensorium.gym.env import SensoriumEnv
    from sensorium.gym.task import Task

    env = SensoriumEnv(load_world(_wbt(tmp_path)), Task(robot="bot", observations=[]))
    env.reset(seed=0)
    motors = env.sim.robot("bot").motors
    for action, wanted in (([1.0, 1.0], [LEFT_MAX, RIGHT_MAX]), ([-0.5, 2.0], [-0.5 * LEFT_MAX, RIGHT_MAX])):
        env.step(np.array(action, dtype=np.float32))
        assert [motors["left wheel motor"].velocity, motors["right wheel motor"].velocity] == wanted
    raw = SensoriumEnv(load_world(_wbt(tmp_path)), Task(robot="bot", observations=[]), actions="wheel")
    assert raw.action_space.high.tolist() == [np.float32(LEFT_MAX), np.float32(RIGHT_MAX)]
    # a car's one speed: the slowest driven wheel's maximum, every driven wheel alike
    car = {"name": "bot", "ackermann_drive": {"wheelbase": 0.3, "track_front": 0.2, "track_rear": 0.2,
                                             "front_wheel_radius": 0.05, "rear_wheel_radius": 0.05,
                                             "max_wheel_speed": 20.0, "motor_max_speeds": {"left_rear_wheel": 26.0}}}
    cars = SensoriumEnv(parse_world({"robots": [car]}), Task(robot="bot", observations=[]))
    cars.reset(seed=0)
    cars.step(np.array([0.0, 1.0], dtype=np.float32))
    assert [m.velocity for name, m in cars.sim.robot("bot").motors.items() if "rear" in name] == [20.0, 20.0]


def test_bad_per_motor_maxima_are_one_clear_line() -> None:
    base = {"wheel_radius": 0.02, "axle_length": 0.05}
    cases = [({"motor_max_speeds": {"nose": 3.0}}, "motor_max_speeds: 'nose' is not one of the drive's wheel motors"),
             ({"motor_max_speeds": {"left wheel motor": -1.0}}, "a maxVelocity must be a number > 0, got -1.0"),
             ({"motor_max_speeds": {"left wheel motor": True}}, "motor_max_speeds: 'left wheel motor': expected a number, got True"),
             ({"skid_steer": {"left": ["back left"], "right": ["back right"]},
               "motor_max_speeds": {"back left": 9.0}}, "the left side's wheels ['left wheel motor', 'back left'] must "
              "share one maxVelocity")]
    for extra, words in cases:
        with pytest.raises(WorldError) as err:
            parse_world({"robots": [{"name": "bot", "differential_drive": {**base, **extra}}]})
        assert words in str(err.value), str(err.value)
        assert "robots[0] (bot).differential_drive" in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("helper", [True, False], ids=["helper", "numpy"])
def test_avoid_obstacles_scores_each_wheel_over_its_own_maximum(tmp_path: Path, helper: bool, monkeypatch) -> None:
    """Both wheels at their own maximum (the gym's (+1, +1)) drive straight at full speed: AvoidObstacles'
    v is 1 and dv 0, so in open space the reward is exactly 1 (the left's maximum for both would give
    1.025 * (1 - sqrt(0.025)) = 0.863); the single env and the vector env's C and numpy passes agree."""
    pytest.importorskip("gymnasium")
    env, venv = avoid_envs(_wbt(tmp_path), helper, monkeypatch)
    for action in ([1.0, 1.0], [0.5, 0.5], [1.0, 0.0]):
        _, reward, *_ = env.step(np.array(action, dtype=np.float32))
        _, rewards, *_ = venv.step(np.array([action, action], dtype=np.float32))
        wl, wr = action
        want = 0.5 * (wl + wr) * (1.0 - math.sqrt(abs(wl - wr) / 2.0))
        assert reward == pytest.approx(want, abs=1e-12)
        assert rewards.tolist() == [reward, reward]
