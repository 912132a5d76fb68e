"""A robot on two ``Track``s (a left and a right belt, each driven by its LinearMotor, as Webots'
track sample is built) drives as the differential drive it is: v = (vl + vr)/2, w = (vr - vl)/W,
W between the belts' centre lines. Before, its belts and wheels did not move (one warning per
Track) and the robot stood still. Our own worlds; closed-form poses."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

Y = 0.15                      # the belts' centre lines at y = +-0.15: W = 0.3


def track(side: str, y: float, motor: str = "", rotation: str = "0 0 1 0") -> str:
    return (f'Track {{ translation 0 {y} 0 rotation {rotation} name "{side} track" children [\n'
            '  TrackWheel { position -0.1 0 radius 0.05 children [ Shape { geometry Cylinder { radius 0.05 height 0.03 } } ] }\n'
            '  TrackWheel { position 0.1 -0.01 radius 0.04 }\n'
            f'] device [ LinearMotor {{ name "{side} motor" {motor} }} PositionSensor {{ name "{side} sensor" }} ] }}\n')


def write(tmp_path: Path, tracks: str, place: str = "", extra: str = "", physics: str = "") -> Path:
    p = tmp_path / "tank.wbt"
    p.write_text('#VRML_SIM R2023b utf8\nWorldInfo { basicTimeStep 10 }\n'
                 f'Robot {{ name "tank" {place} children [\n  DEF BODY Shape {{ geometry Box {{ size 0.2 0.2 0.04 }} }}\n'
                 + tracks + f'] boundingObject USE BODY {physics} }}\n' + extra)
    return p


def tank(tmp_path: Path, **kw) -> Path:
    return write(tmp_path, track("left", Y) + track("right", -Y), **kw)


def drive(sim: Simulation, left: float, right: float, seconds: float, robot: str = "tank") -> None:
    r = sim.robot(robot)
    for name, v in ((f"left {'motor' if robot == 'tank' else 'wheel motor'}", left),
                    (f"right {'motor' if robot == 'tank' else 'wheel motor'}", right)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(v)
    sim.run(int(round(seconds * 100)))          # basic steps of 10 ms


def yaw(sim: Simulation, robot: str = "tank") -> float:
    r = sim.robot(robot).pose.rotation
    return math.atan2(r[1, 0], r[0, 0])


def test_two_tracks_are_a_differential_drive(tmp_path: Path) -> None:
    w = load_world(tank(tmp_path))
    assert not [x for x in w.warnings if "Track" in x or "drive" in x], w.warnings
    dd = w.world.robots[0].differential_drive
    assert dd is not None
    assert (dd.wheel_radius, dd.axle_length, dd.left_motor, dd.right_motor) == (1.0, 0.3, "left motor", "right motor")
    assert dd.max_wheel_speed == 10.0 and dd.axle_center == (0.0, 0.0)      # LinearMotor's maxVelocity 10 m/s
    assert dd.wheel_bottom is None          # no physics: the robot stays where it is put, as before

    # both belts at 0.2 m/s for 1 s: 0.2 m straight along the robot's x
    sim = Simulation(w)
    drive(sim, 0.2, 0.2, 1.0)
    assert sim.robot("tank").pose.translation == pytest.approx([0.2, 0.0, 0.0], abs=1e-12)
    assert yaw(sim) == pytest.approx(0.0, abs=1e-12)

    # left -0.1, right +0.1: turning in place (left) at 0.2 / 0.3 rad/s
    sim = Simulation(w)
    drive(sim, -0.1, 0.1, 1.0)
    assert sim.robot("tank").pose.translation == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    assert yaw(sim) == pytest.approx(0.2 / 0.3, abs=1e-12)


def test_the_position_sensor_reads_the_belt_travel_in_metres(tmp_path: Path) -> None:
    sim = Simulation(load_world(tank(tmp_path)))
    left, right = sim.device("tank/left sensor"), sim.device("tank/right sensor")
    left.enable(10)
    right.enable(10)
    drive(sim, 0.2, -0.05, 1.0)
    assert left.value == pytest.approx(0.2, abs=1e-12)
    assert right.value == pytest.approx(-0.05, abs=1e-12)


def test_the_belt_speed_is_clamped_to_the_linear_motors_max_velocity(tmp_path: Path) -> None:
    """Webots clamps a velocity above maxVelocity (m/s for a LinearMotor) to it."""
    w = load_world(write(tmp_path, track("left", Y, "maxVelocity 0.15") + track("right", -Y, "maxVelocity 0.15")))
    assert w.world.robots[0].differential_drive.max_wheel_speed == 0.15
    sim = Simulation(w)
    drive(sim, 0.2, 0.2, 1.0)
    assert sim.robot("tank").pose.translation[0] == pytest.approx(0.15, abs=1e-12)


def test_belts_along_the_robots_y_drive_it_along_y(tmp_path: Path) -> None:
    """A positive velocity moves the robot along its Track's own +x (Webots' track sample drives forward
    so): Tracks turned by 90 degrees about z drive the robot along its +y; the left belt is then the one
    at -x."""
    tracks = track("left", 0, rotation="0 0 1 1.5707963267948966").replace("translation 0 0 0", f"translation {-Y} 0 0") \
        + track("right", 0, rotation="0 0 1 1.5707963267948966").replace("translation 0 0 0", f"translation {Y} 0 0")
    w = load_world(write(tmp_path, tracks))
    dd = w.world.robots[0].differential_drive
    assert (dd.left_motor, dd.right_motor) == ("left motor", "right motor")
    assert dd.forward == pytest.approx((0.0, 1.0), abs=1e-12) and dd.axle_length == pytest.approx(0.3, abs=1e-15)
    sim = Simulation(w)
    drive(sim, 0.2, 0.2, 1.0)
    assert sim.robot("tank").pose.translation == pytest.approx([0.0, 0.2, 0.0], abs=1e-12)


def test_a_tank_with_physics_settles_on_its_belts_lowest_point(tmp_path: Path) -> None:
    """``wheel_bottom``: the TrackWheels' lowest bottom (the rear wheel: 0 - 0.05; the front one
    -0.01 - 0.04), so the robot placed at z 0.3 lands with its origin 0.05 above the floor."""
    floor = 'Solid { name "floor" children [ DEF F Shape { geometry Plane { size 10 10 } } ] boundingObject USE F }\n'
    w = load_world(tank(tmp_path, place="translation 0 0 0.3", physics="physics Physics { }", extra=floor))
    assert w.world.robots[0].differential_drive.wheel_bottom == pytest.approx(-0.05, abs=1e-15)
    sim = Simulation(w)
    sim.step()
    assert sim.robot("tank").pose.translation == pytest.approx([0.0, 0.0, 0.05], abs=1e-12)


def test_a_wall_stops_a_tank_as_it_stops_a_two_wheel_robot(tmp_path: Path) -> None:
    """The same body driven at the same speed into the same wall by two tracks and by two wheels
    (radius 0.05, 4 rad/s: 0.2 m/s) ends at the same place, short of where it would drive free."""
    wall = 'Solid { name "wall" translation 0.3 0 0 children [ DEF WALL Shape { geometry Box { size 0.02 1 0.3 } } ] boundingObject USE WALL }\n'
    w = load_world(tank(tmp_path, extra=wall))
    sim = Simulation(w)
    drive(sim, 0.2, 0.2, 2.0)
    tracked = sim.robot("tank").pose.translation.copy()

    def wheel(name: str, y: float) -> str:
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0 }}\n'
                f'  device [ RotationalMotor {{ name "{name}" }} ]\n'
                f'  endPoint Solid {{ translation 0 {y} 0 children [ Pose {{ rotation 1 0 0 1.5707963267948966 children [\n'
                '    Shape { geometry Cylinder { radius 0.05 height 0.03 } } ] } ] } }\n')
    p = write(tmp_path, wheel("left wheel motor", Y) + wheel("right wheel motor", -Y), extra=wall)
    p.write_text(p.read_text().replace('name "tank"', 'name "wheeled"'))
    sim = Simulation(load_world(p))
    drive(sim, 4.0, 4.0, 2.0, robot="wheeled")
    wheeled = sim.robot("wheeled").pose.translation
    assert tracked[0] < 0.4 - 1e-3                       # stopped by the wall (free: 0.4 m)
    assert tracked == pytest.approx(wheeled, abs=1e-12)


def test_the_batched_simulation_drives_a_tank_as_its_simulation_does(tmp_path: Path) -> None:
    w = load_world(tank(tmp_path, place="translation 0.2 -0.1 0 rotation 0 0 1 0.4"))
    plans = [(-0.1, 0.1), (0.05, 0.2), (0.2, 0.2)]
    batched = BatchedSimulation(w.world, len(plans))
    batched.set_wheels(0, [p[0] for p in plans], [p[1] for p in plans])
    batched.run(80)
    for c, (vl, vr) in enumerate(plans):
        sim = Simulation(w)
        drive(sim, vl, vr, 0.8)
        pose = sim.robot("tank").pose
        assert pose.translation.tobytes() == batched.pos[c, 0].tobytes(), c
        assert pose.rotation.tobytes() == batched.rot[c, 0].tobytes(), c
    # the straight copy: 0.16 m along its heading 0.4
    assert batched.pos[2, 0, :2] == pytest.approx(np.array([0.2, -0.1]) + 0.16 * np.array([math.cos(0.4), math.sin(0.4)]),
                                                  abs=1e-12)


def test_a_tracks_brake_names_the_drives_motor(tmp_path: Path) -> None:
    """A Brake in a Track's device list shares its motor's joint: the drive's wheel, a LinearMotor
    (linear, as in Webots; it was rotational while the drive made its motor a RotationalMotor)."""
    brakes = (track("left", Y) + track("right", -Y)).replace('PositionSensor {', 'Brake { name "b" } PositionSensor {')
    robot = load_world(write(tmp_path, brakes)).world.robots[0]
    assert [(d.name, d.motor, d.joint_type) for d in robot.devices if d.device == "Brake"] == [
        ("b", "left motor", "linear"), ("b(1)", "right motor", "linear")]


def test_the_track_motors_stay_linear_motors_of_the_drive(tmp_path: Path) -> None:
    """The drive's motors keep their LinearMotor entries (Webots' type), at their places in the
    device list, and attach describes them as LinearMotors in m/s."""
    from pydantic import TypeAdapter

    from sensorium.schemas.services import DeviceDescription
    from sensorium.server.daemon.services import Core
    from sensorium.server.sim.summary import device_line

    w = load_world(write(tmp_path, track("left", Y, "maxVelocity 0.15") + track("right", -Y, "maxVelocity 0.15")))
    robot = w.world.robots[0]
    assert [(d.device, d.name) for d in robot.devices] == [
        ("LinearMotor", "left motor"), ("PositionSensor", "left sensor"),
        ("LinearMotor", "right motor"), ("PositionSensor", "right sensor")]
    assert device_line(robot.devices[0]) == "LinearMotor"          # sensorium info's line
    devs = {d["name"]: d for d in Core(Simulation(w))._describe_robot("tank")}
    assert {k: devs["left motor"][k] for k in ("type", "maxVelocity", "minPosition", "maxPosition", "index")} == \
        {"type": "LinearMotor", "maxVelocity": 0.15, "minPosition": 0.0, "maxPosition": 0.0, "index": 0}
    assert devs["right motor"]["type"] == "LinearMotor" and devs["right sensor"]["motor"] == "right motor"
    for d in devs.values():
        TypeAdapter(DeviceDescription).validate_python(d)


def test_a_yaml_drive_may_name_its_linear_motor_entries(tmp_path: Path) -> None:
    """In a YAML world a LinearMotor entry named like a drive motor is that motor (no 'device name
    repeated' refusal); its joint fields are refused as a RotationalMotor entry's are."""
    from sensorium.server.world.loader import WorldError, parse_world

    def robot(extra: dict) -> dict:
        return {"name": "tank", "differential_drive": {
            "wheel_radius": 1.0, "axle_length": 0.3, "left_motor": "l", "right_motor": "r", "max_wheel_speed": 0.5},
            "devices": [{"device": "LinearMotor", "name": "l", **extra}, {"device": "LinearMotor", "name": "r"}]}

    sim = Simulation(parse_world({"world_info": {"basic_time_step": 10}, "robots": [robot({})]}))
    assert [(e.type, e.name) for e in sim.robot("tank").device_list] == [("LinearMotor", "l"), ("LinearMotor", "r")]
    for name in ("l", "r"):
        sim.robot("tank").motor(name).set_position(math.inf)
        sim.robot("tank").motor(name).set_velocity(0.2)
    sim.run(100)
    assert sim.robot("tank").pose.translation == pytest.approx([0.2, 0.0, 0.0], abs=1e-12)
    with pytest.raises(WorldError, match=r"robots\[0\] \(tank\)\.devices\[0\] \(l\)\.max_force: 'l' is a motor of the robot's "
                                         r"drive, which sets its speed and limits: leave out max_force"):
        parse_world({"robots": [robot({"max_force": 5.0})]})


def test_python_controllers_see_linear_motors_and_sensors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A Python controller (a real server in a thread) gets Webots' types for a tracked robot's
    motors and their sensors, and drives it in m/s."""
    from _inproc import inproc_server

    import sensorium.client.webots.controller as controller
    from sensorium.client import wb
    from sensorium.client.nodes import WEBOTS_NODE_TYPES

    with inproc_server(heartbeat_ms=2000, world=tank(tmp_path)) as (core, transport):
        monkeypatch.setenv("SENSORIUM_CONTROLLER_URL", f"{transport.rpc_endpoint}/tank")
        try:
            robot = controller.Robot()
            left, right = robot.getDevice("left motor"), robot.getDevice("right motor")
            sensor = robot.getDevice("left sensor")
            assert isinstance(left, controller.LinearMotor) and isinstance(right, controller.LinearMotor)
            assert left.getType() == controller.Motor.LINEAR == wb.WB_LINEAR
            assert left.getNodeType() == WEBOTS_NODE_TYPES["WB_NODE_LINEAR_MOTOR"] == sensor.getMotor().getNodeType()
            assert sensor.getType() == controller.PositionSensor.LINEAR and sensor.getMotor() is left
            assert (left.getMaxVelocity(), left.getMinPosition(), left.getMaxPosition()) == (10.0, 0.0, 0.0)
            sensor.enable(10)
            for m in (left, right):
                m.setPosition(math.inf)
                m.setVelocity(0.2)
            for _ in range(100):
                robot.step(10)
            assert sensor.getValue() == pytest.approx(0.2, abs=1e-12)
            assert core.sim.robot("tank").pose.translation == pytest.approx([0.2, 0.0, 0.0], abs=1e-12)
        finally:
            wb.wb_robot_cleanup()
            controller.Robot.created = None


def test_one_track_or_tracks_beside_wheels_keep_their_warning(tmp_path: Path) -> None:
    """A single Track (a conveyor belt) drives nothing: its line stays; so do three Tracks."""
    w = load_world(write(tmp_path, track("left", Y)))
    assert w.world.robots[0].differential_drive is None
    assert [x.split(": ", 1)[1] for x in w.warnings if "Track" in x] == [
        "Track 'left track': its motor's position moves kinematically (its sensor reads it); the belt and its "
        "wheels do not move here"]
    w = load_world(write(tmp_path, track("left", Y) + track("right", -Y) + track("mid", 0.0)))
    assert w.world.robots[0].differential_drive is None
    assert len([x for x in w.warnings if "Track '" in x]) == 3


def test_a_tracks_scale_scales_its_wheels_and_the_belts_bottom(tmp_path: Path) -> None:
    """A Solid's ``scale`` before R2023a (Webots' track sample halves its Tracks): it was not read,
    so the Tracks' wheels and bounding objects were twice their size and the robot settled on them."""
    half = (track("left", Y) + track("right", -Y)).replace(' name "left track"', ' scale 0.5 0.5 0.5 name "left track"') \
        .replace(' name "right track"', ' scale 0.5 0.5 0.5 name "right track"')
    floor = 'Solid { name "floor" children [ DEF F Shape { geometry Plane { size 10 10 } } ] boundingObject USE F }\n'
    p = write(tmp_path, half, place="translation 0 0 0.3", physics="physics Physics { }", extra=floor)
    p.write_text(p.read_text().replace("R2023b", "R2022a"))
    w = load_world(p)
    robot = w.world.robots[0]
    assert robot.differential_drive.wheel_bottom == pytest.approx(-0.025, abs=1e-15)
    assert [(s.geometry.radius, s.pose.translation) for s in robot.shapes if s.geometry.type == "cylinder"] == [
        (0.025, (-0.05, Y, 0.0)), (0.025, (-0.05, -Y, 0.0))]
    sim = Simulation(w)
    sim.step()
    assert sim.robot("tank").pose.translation[2] == pytest.approx(0.025, abs=1e-12)


def test_the_gyms_actions_are_belt_speeds(tmp_path: Path) -> None:
    """The gym's normalised action +1 is the LinearMotor's maxVelocity in m/s (0.15 here), so +1 on
    both belts covers 0.15 m/s straight, in the single and the vector env alike; -1/+1 turns in place
    at 2 * 0.15 / 0.3 = 1 rad/s."""
    from sensorium.gym import SensoriumEnv, Task
    from sensorium.gym.vector import SensoriumVectorEnv

    w = load_world(write(tmp_path, track("left", Y, "maxVelocity 0.15") + track("right", -Y, "maxVelocity 0.15")))
    env = SensoriumEnv(w, Task(max_steps=None), precision="exact")
    venv = SensoriumVectorEnv(w, Task(max_steps=None), num_envs=2, precision="exact")
    _, info = env.reset(seed=1)
    venv.reset(seed=1)
    period = env.control_period_ms / 1000.0
    for _ in range(5):
        _, _, _, _, info = env.step(np.array([1.0, 1.0]))
        _, _, _, _, vinfo = venv.step(np.array([[1.0, 1.0], [-1.0, 1.0]]))
    assert info["pose"] == pytest.approx([0.15 * 5 * period, 0.0, 0.0], abs=1e-12)
    assert vinfo["pose"][0].tobytes() == info["pose"].tobytes()
    assert vinfo["pose"][1] == pytest.approx([0.0, 0.0, 1.0 * 5 * period], abs=1e-12)
    env.close()
    venv.close()


@pytest.mark.slow
def test_c_controllers_see_linear_motors_and_sensors(tmp_path_factory: pytest.TempPathFactory) -> None:
    """tests/c/tracks.c (the C library built with AddressSanitizer and UBSan) against ``sensorium serve``:
    wb_device_get_node_type, wb_motor_get_type and wb_position_sensor_get_type answer Webots' linear
    types, and the belts at 0.2 m/s for 1 s travel 0.2 m."""
    from _serve import run_controller
    from test_c_client import SAN_ENV, sanitized_controller

    exe = sanitized_controller(tmp_path_factory, Path(__file__).parent / "c" / "tracks.c")
    lines, err = run_controller(tank(tmp_path_factory.mktemp("tank")), lambda url: [exe], env=SAN_ENV, robot="tank")
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert lines == ["node 1 1 1", "type 1 1 1", "motor 1 limits 10 0 0", "travel 0.200000000000"], err
