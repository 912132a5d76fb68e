"""Joint motors in the batched simulation (batched_joints.py): every copy's joints move by Webots'
kinematic motor control and the distance sensors, light sensors, cameras (images, recognition,
segmentation), range finders and lidars (fixed and rotating) riding them cast from each copy's link, bit for bit as the
copy's own Simulation (a pan hinge carrying a distance sensor, a lidar, a light sensor and a camera on
a driving robot, a slider carrying an infra-red sensor and a nested tilt hinge carrying another, a
light sensor, a range finder and a camera,
coupled motors with a multiplier; random position, velocity, acceleration and torque commands per
copy). Closed form: a pan turned a quarter makes its sensor read the side wall, and its light
sensor face a lamp; a range finder turned back on its pan sees its own robot. What is not
simulated is refused in one line (a bumper's shapes on a link; an LED on a joint;
a link's shapes and lights themselves: tests/test_batched_links.py).
A bumper on a joint without shapes reads its robot's contact, as in Simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

STEP = 16


def wall(name: str, x: float, y: float, sx: float, sy: float, colour=(0.8, 0.5, 0.2)) -> dict:
    return {"name": name, "pose": {"translation": [x, y, 0.5]}, "geometry": {"type": "box", "size": [sx, sy, 1.0]},
            "appearance": {"base_color": list(colour)}, "recognition_colors": [list(colour)]}


def laser(name: str, on_joint: str, translation, kind: str = "laser", noise: float = 0.0) -> dict:
    return {"device": "DistanceSensor", "name": name, "type": kind, "on_joint": on_joint,
            "pose": {"translation": translation},
            "lookup_table": [[0, 0, 0], [3.0, 3000, noise]]}


def pan_robot() -> dict:
    """A two-wheel robot with a pan hinge (axis z through (0.05, 0, 0), acceleration-limited) carrying
    a distance sensor and a fixed 3-layer lidar, and an encoder on the pan."""
    return {"name": "pan", "pose": {"translation": [-0.3, 0.1, 0.05]},
            "body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.1}},
            "differential_drive": {"wheel_radius": 0.03, "axle_length": 0.15, "max_wheel_speed": 10.0},
            "devices": [{"device": "RotationalMotor", "name": "pan motor", "axis": [0, 0, 1], "anchor": [0.05, 0, 0],
                         "max_velocity": 3.0, "acceleration": 20.0, "max_torque": 50.0},
                        {"device": "PositionSensor", "name": "pan enc", "motor": "pan motor", "noise": 0.001},
                        laser("pan ds", "pan motor", [0.12, 0.0, 0.1], noise=0.02),
                        {"device": "Lidar", "name": "pan lidar", "on_joint": "pan motor",
                         "pose": {"translation": [0.1, 0.0, 0.15]}, "horizontal_resolution": 32,
                         "field_of_view": 1.5, "number_of_layers": 3, "vertical_field_of_view": 0.2,
                         "min_range": 0.05, "max_range": 3.0, "noise": 0.01},
                        {"device": "LightSensor", "name": "pan ls", "on_joint": "pan motor", "occlusion": True,
                         "pose": {"translation": [0.1, 0.02, 0.12], "rotation": [0, 0, 1, 0.4]},
                         "lookup_table": [[0, 0, 0], [10, 1000, 0.05]]},
                        {"device": "Camera", "name": "pan cam", "on_joint": "pan motor", "width": 12, "height": 8,
                         "pose": {"translation": [0.11, 0.0, 0.14]}, "field_of_view": 1.2, "noise": 0.02,
                         "recognition": {"occlusion": 1, "segmentation": True}},
                        {"device": "GPS", "name": "pan gps", "on_joint": "pan motor", "accuracy": 0.01,
                         "noise_correlation": 0.5, "speed_noise": 0.02, "pose": {"translation": [0.12, 0.03, 0.1]}},
                        {"device": "Compass", "name": "pan compass", "on_joint": "pan motor",
                         "pose": {"rotation": [1, 0, 0, 0.3]}},
                        {"device": "Gyro", "name": "pan gyro", "on_joint": "pan motor",
                         "pose": {"translation": [0.1, 0, 0.1], "rotation": [0, 1, 0, 0.4]},
                         "lookup_table": [[-100, -100, 0.01], [100, 100, 0.01]]},
                        {"device": "Accelerometer", "name": "pan acc", "on_joint": "pan motor",
                         "pose": {"translation": [0.12, 0.02, 0.1]}},
                        {"device": "TouchSensor", "name": "pan bump", "on_joint": "pan motor"}]}


def lift_robot() -> dict:
    """A robot without a drive: a slider (axis z, 0 .. 0.4 m) carrying an infra-red sensor and a tilt
    hinge (axis y) riding the slider with a laser on it; two coupled hinges (``arm::a`` and ``arm::b``,
    multiplier -0.5) each carrying a sensor."""
    return {"name": "lift", "pose": {"translation": [0.4, -0.3, 0.05], "rotation": [0, 0, 1, 0.6]},
            "body": {"geometry": {"type": "box", "size": [0.2, 0.2, 0.1]}},
            "devices": [{"device": "LinearMotor", "name": "lift motor", "axis": [0, 0, 1], "max_velocity": 0.5,
                         "min_position": 0.0, "max_position": 0.4, "max_force": 100.0},
                        {"device": "RotationalMotor", "name": "tilt", "axis": [0, 1, 0], "anchor": [0, 0, 0.2],
                         "on_joint": "lift motor", "max_velocity": 2.0, "min_position": -0.6, "max_position": 0.6},
                        {"device": "RotationalMotor", "name": "arm::a", "axis": [0, 0, 1], "max_velocity": 2.0},
                        {"device": "RotationalMotor", "name": "arm::b", "axis": [0, 0, 1], "max_velocity": 2.0,
                         "multiplier": -0.5},
                        {"device": "PositionSensor", "name": "lift enc", "motor": "lift motor"},
                        {"device": "PositionSensor", "name": "b enc", "motor": "arm::b", "resolution": 0.01},
                        laser("lift ir", "lift motor", [0.11, 0.0, 0.1], kind="infra-red"),
                        laser("tilt ds", "tilt", [0.11, 0.0, 0.2]),
                        {"device": "LightSensor", "name": "tilt ls", "on_joint": "tilt", "occlusion": True,
                         "pose": {"translation": [0.0, 0.11, 0.2], "rotation": [0, 1, 0, -0.5]},
                         "lookup_table": [[0, 0, 0], [10, 1000, 0]]},
                        {"device": "RangeFinder", "name": "tilt rf", "on_joint": "tilt", "width": 10, "height": 6,
                         "pose": {"translation": [0.11, 0.0, 0.24]}, "field_of_view": 1.0, "max_range": 3.0,
                         "noise": 0.01},
                        {"device": "Camera", "name": "tilt cam", "on_joint": "tilt", "width": 8, "height": 6,
                         "pose": {"translation": [0.11, 0.02, 0.24], "rotation": [0, 1, 0, 0.2]},
                         "field_of_view": 0.9, "recognition": {"occlusion": 2}},
                        {"device": "InertialUnit", "name": "tilt imu", "on_joint": "tilt", "noise": 0.001,
                         "pose": {"translation": [0.05, 0.0, 0.25], "rotation": [0, 0, 1, 0.7]}},
                        {"device": "Altimeter", "name": "lift alt", "on_joint": "lift motor", "accuracy": 0.005,
                         "pose": {"translation": [0.0, 0.05, 0.12]}},
                        {"device": "Accelerometer", "name": "tilt acc", "on_joint": "tilt",
                         "pose": {"translation": [0.1, 0.0, 0.3]}},
                        {"device": "Gyro", "name": "tilt gyro", "on_joint": "tilt"},
                        {"device": "Lidar", "name": "tilt lidar", "on_joint": "tilt", "type": "rotating",
                         "pose": {"translation": [0.05, 0.0, 0.3]}, "horizontal_resolution": 24,
                         "field_of_view": 2 * math.pi, "number_of_layers": 2, "vertical_field_of_view": 0.2,
                         "near": 0.01, "min_range": 0.05, "max_range": 3.0, "noise": 0.01,
                         "default_frequency": 9.0, "min_frequency": 1.0, "max_frequency": 20.0},
                        laser("a ds", "arm::a", [0.0, 0.11, 0.05]),
                        laser("b ds", "arm::b", [0.0, -0.11, 0.05]),
                        laser("fixed ds", "lift motor", [-0.11, 0.0, 0.1])]}


def jointed_world(seed: int = 3):
    return parse_world({"world_info": {"basic_time_step": STEP, "contact": True, "random_seed": seed},
                        "solids": [wall("north", 0, 1.2, 2.6, 0.2), wall("south", 0, -1.2, 2.6, 0.2),
                                   wall("east", 1.2, 0, 0.2, 2.2), wall("west", -1.2, 0, 0.2, 2.2),
                                   wall("block", 0.3, 0.5, 0.3, 0.3, (0.2, 0.4, 0.9)),
                                   wall("post", -0.6, -0.6, 0.15, 0.15, (0.9, 0.9, 0.1))],
                        "lights": [{"type": "PointLight", "location": [0.1, 0.2, 0.6], "intensity": 1.5,
                                    "attenuation": [0, 0, 1]}],
                        "robots": [pan_robot(), lift_robot()]})


MOTORS = {"pan": ["pan motor"], "lift": ["lift motor", "tilt", "arm::a"]}


def random_commands(rng: np.random.Generator) -> dict:
    """Per motor: (position, velocity, acceleration, available force), any of them None."""
    out = {}
    for robot, names in MOTORS.items():
        for name in names:
            mode = rng.integers(4)
            position = math.inf if mode == 0 else float(rng.uniform(-2.5, 2.5))      # limits clamp some
            velocity = float(rng.uniform(-3.0, 3.0)) if mode == 0 else float(rng.uniform(0.1, 4.0))
            acceleration = None if mode < 2 else (-1.0 if mode == 2 else float(rng.uniform(0.5, 30.0)))
            force = float(rng.uniform(1.0, 200.0)) if mode == 3 else None
            out[(robot, name)] = (position, velocity, acceleration, force)
    return out


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_every_copy_moves_its_joints_and_their_sensors_as_its_simulation_bit_for_bit(precision):
    """Three copies and a Simulation per copy (world seeds 3, 4, 5), 300 steps; every 25 steps each
    copy's motors get new random commands and its wheels new speeds; copy 1 reset at step 160 against
    a fresh Simulation: every joint position, every encoder, distance sensor and lidar image and every
    robot pose the same bits every step (light sensors too, their occlusion rays cast from each
    copy's link)."""
    w = jointed_world()
    seeds = (3, 4, 5)
    n = len(seeds)
    batched = BatchedSimulation(w, n, precision=precision)
    batched.reset(np.arange(n), list(seeds))

    def recognise(copies: list[int]) -> None:
        for (robot, name), segment in cameras.items():
            batched.recognition_enable(batched.device(robot, name), 32, copies=copies)
            batched.enable_segmentation(batched.device(robot, name), segment, copies=copies)

    devices = {"pan": ["pan enc", "pan ds", "pan lidar", "pan ls", "pan cam", "pan gps", "pan compass", "pan gyro",
                       "pan acc", "pan bump"],
               "lift": ["lift enc", "b enc", "lift ir", "tilt ds", "tilt ls", "tilt rf", "tilt cam", "tilt imu",
                        "lift alt", "tilt acc", "tilt gyro", "a ds", "b ds", "fixed ds", "tilt lidar"]}
    cameras = {("pan", "pan cam"): True, ("lift", "tilt cam"): False}     # recognition; segmentation
    for robot, names in devices.items():
        for name in names:
            batched.enable(batched.device(robot, name), 32)
    recognise(list(range(n)))
    rng = np.random.default_rng(11)
    pan = batched.slot("pan")
    moved = set()
    seen: set[int] = set()
    bumped: set[int] = set()
    pan_ls_apart = False
    def single(seed: int) -> Simulation:
        sim = Simulation(w.world.model_copy(update={"world_info": w.world.world_info.model_copy(
            update={"random_seed": seed})}), precision=precision)
        for robot, names in devices.items():
            for name in names:
                sim.device(f"{robot}/{name}").enable(32)
        for (robot, name), segment in cameras.items():
            sim.device(f"{robot}/{name}").recognition_enable(32)
            sim.device(f"{robot}/{name}").enable_segmentation(segment)
        return sim

    singles = [single(s) for s in seeds]
    for t in range(300):
        if t == 160:                    # copy 1 reset: a freshly built world, its joints where the file has them
            batched.reset([1], [seeds[1]])
            for robot, names in devices.items():
                for name in names:
                    batched.enable(batched.device(robot, name), 32, copies=[1])
            recognise([1])
            singles[1] = single(seeds[1])
        if t % 25 == 0:
            for c in range(n):
                for (robot, name), (p, v, a, f) in random_commands(rng).items():
                    singles[c].robot(robot).motor(name).command(p, v, a, f)
                    batched.joints.command(batched.slot(robot), name, p, v, a, f, copies=[c])
            wheels = rng.uniform(-2.0, 10.0, size=(n, 2))     # mostly ahead: the robots meet walls (bumper)
            batched.set_wheels(pan, wheels[:, 0], wheels[:, 1])
            for c in range(n):
                motors = singles[c].robot("pan").drive.motors
                for side, m in zip(wheels[c], ("left wheel motor", "right wheel motor")):
                    motors[m].set_position(math.inf)
                    motors[m].set_velocity(float(side))
        for s in singles:
            s.step()
        batched.step()
        for c, s in enumerate(singles):
            for robot in ("pan", "lift"):
                slot = batched.slot(robot)
                for name, motor in s.robot(robot).joints.items():
                    got = batched.joints.position[c, batched.joints.of(slot, name)]
                    assert got.tobytes() == np.float64(motor.position).tobytes(), (t, c, robot, name)
                    if motor.position != motor.initial_position:
                        moved.add(name)
                pose = s.robot(robot).pose
                assert batched.pose(c, slot).translation.tobytes() == pose.translation.tobytes(), (t, c, robot)
                for name in devices[robot]:
                    ref = batched.device(robot, name)
                    dev = s.device(f"{robot}/{name}")
                    if name.endswith("lidar") or name.endswith("rf"):
                        assert batched.range_image(ref)[c].tobytes() == dev.range_image.tobytes(), (t, c, name)
                    elif name.endswith("cam"):
                        assert batched.image(ref)[c].tobytes() == dev.image.tobytes(), (t, c, name)
                        assert batched.recognition_objects(ref, c) == dev.objects, (t, c, name)
                        if cameras[(robot, name)]:
                            assert batched.segmentation_image(ref)[c].tobytes() == dev.segmentation_image.tobytes()
                        seen |= {o.id for o in dev.objects}
                    elif ref.kind in ("GPS", "Compass", "InertialUnit", "Gyro", "Accelerometer"):
                        want = dev.roll_pitch_yaw if ref.kind == "InertialUnit" else dev.values
                        assert batched.value(ref)[c].tobytes() == np.asarray(want).tobytes(), (t, c, name)
                        if ref.kind == "GPS":
                            for what in ("speed", "speed_vector"):
                                want = np.float64(getattr(dev, what)) if what == "speed" else getattr(dev, what)
                                assert batched.reading(ref, what)[c].tobytes() == np.asarray(want).tobytes()
                        if ref.kind == "InertialUnit":
                            assert batched.reading(ref, "quaternion")[c].tobytes() == dev.quaternion.tobytes()
                    else:
                        got = batched.value(ref)[c]
                        if name == "pan bump" and got == 1.0:
                            bumped.add(c)
                        assert np.float64(got).tobytes() == np.float64(dev.value).tobytes(), (t, c, name, got,
                                                                                           dev.value)
        pan_ls_apart |= len({float(v) for v in batched.value(batched.device("pan", "pan ls"))}) == n
    assert moved == {"pan motor", "lift motor", "tilt", "arm::a", "arm::b"}
    assert bumped                 # the bumper on the pan did feel a wall in some copy
    # the joints' sensors did read different things in different copies (each its own link)
    assert len({float(v) for v in batched.value(batched.device("pan", "pan ds"))}) == n
    assert pan_ls_apart            # at some step, each copy's its own value
    assert len({float(v) for v in batched.value(batched.device("lift", "tilt ls"))}) == n
    for name in ("pan cam", "tilt rf", "tilt lidar"):
        ref = batched.device("pan" if name == "pan cam" else "lift", name)
        got = batched.image(ref) if name == "pan cam" else batched.range_image(ref)
        assert len({got[c].tobytes() for c in range(n)}) == n, name
    assert len(seen) >= 2       # the cameras recognised walls
    for name in ("tilt imu", "lift alt", "tilt acc", "tilt gyro"):       # the lift robot never drives: its joints alone tell copies apart
        got = batched.value(batched.device("lift", name))
        assert len({got[c].tobytes() for c in range(n)}) == n, name


def test_a_pan_turned_a_quarter_reads_the_side_wall_in_that_copy_only():
    """A robot at the origin, its sensor 0.1 m ahead of the pan axis, facing a wall whose near face
    is at x = 1 and with one at y = 0.5 to its left. In copy 1 the pan turns to pi/2: the sensor sits
    at (0, 0.1) looking along +y and reads 0.5 - 0.1 = 0.4 m; copy 0 still reads 1 - 0.1 = 0.9 m (the
lookup table gives 1000 per metre)."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": False},
                     "solids": [wall("front", 1.05, 0, 0.1, 8), wall("left", 0, 0.55, 8, 0.1)],
                     "robots": [{"name": "r", "devices": [
                         {"device": "RotationalMotor", "name": "pan", "axis": [0, 0, 1], "max_velocity": 100.0,
                          "max_torque": 1e5},
                         laser("ds", "pan", [0.1, 0.0, 0.3])]}]})
    batched = BatchedSimulation(w, 2)
    ref = batched.device("r", "ds")
    batched.enable(ref, STEP)
    batched.step()
    assert batched.value(ref) == pytest.approx([900.0, 900.0], abs=1e-6)
    batched.joints.command(0, "pan", position=math.pi / 2, copies=[1])
    batched.step()
    assert batched.joints.position[:, 0].tolist() == [0.0, math.pi / 2]
    assert batched.value(ref) == pytest.approx([900.0, 400.0], abs=1e-6)
    batched.reset([1], [0])             # back at its initial position: the front wall again
    batched.enable(ref, STEP, copies=[1])
    batched.step()
    assert batched.value(ref) == pytest.approx([900.0, 900.0], abs=1e-6)


def test_a_rotating_lidar_on_a_pan_turned_a_quarter_sees_the_side_wall_where_it_saw_the_front_one():
    """A one-layer rotating lidar (8 columns round the circle) on a pan axis at the origin, a wall
    whose near face is at x = 1 and one at y = 0.5. After full sweeps, copy 0 reads 1.0 m in the
    column looking along +x; copy 1 turned its pan a quarter first: that column now looks along +y
    and reads the side wall at 0.5 m, and the one that read 0.5 m in copy 0 looks along -x, where
    nothing is within 3 m (inf)."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": False},
                     "solids": [wall("front", 1.05, 0, 0.1, 8), wall("left", 0, 0.55, 8, 0.1)],
                     "robots": [{"name": "r", "devices": [
                         {"device": "RotationalMotor", "name": "pan", "axis": [0, 0, 1], "max_velocity": 100.0,
                          "max_torque": 1e5},
                         {"device": "Lidar", "name": "spin", "on_joint": "pan", "type": "rotating",
                          "pose": {"translation": [0, 0, 0.3]}, "horizontal_resolution": 8,
                          "number_of_layers": 1, "vertical_field_of_view": 0.0,
                          "field_of_view": 2 * math.pi, "near": 0.01, "min_range": 0.01, "max_range": 3.0,
                          "default_frequency": 10.0, "min_frequency": 1.0, "max_frequency": 20.0}]}]})
    batched = BatchedSimulation(w, 2)
    ref = batched.device("r", "spin")
    batched.enable(ref, STEP)
    batched.joints.command(0, "pan", position=math.pi / 2, copies=[1])
    batched.run(30)                     # three turns of the head
    assert batched.joints.position[:, 0].tolist() == [0.0, math.pi / 2]
    img = batched.range_image(ref)[:, 0, :]
    front = int(np.flatnonzero(np.isclose(img[0], 1.0))[0])
    side = int(np.flatnonzero(np.isclose(img[0], 0.5))[0])
    assert img[1, front] == pytest.approx(0.5, abs=1e-9)
    assert np.isinf(img[1, side])


def test_a_bumper_on_a_pan_reads_its_robots_contact_in_the_copy_that_drove_into_the_wall():
    """A 0.1 m radius robot at the origin, a wall whose near face is at x = 0.3, a bumper without
    shapes on its pan. Copy 0 drives at 0.3 m/s for 1.6 s: contact stops it at x = 0.2 and its
    bumper reads 1; copy 1 stands still with its pan turned a quarter: 0."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": True},
                     "solids": [wall("front", 0.35, 0, 0.1, 8)],
                     "robots": [{"name": "r", "body": {"geometry": {"type": "cylinder", "radius": 0.1, "height": 0.1}},
                                 "differential_drive": {"wheel_radius": 0.03, "axle_length": 0.15,
                                                        "max_wheel_speed": 10.0},
                                 "devices": [
                         {"device": "RotationalMotor", "name": "pan", "axis": [0, 0, 1], "max_velocity": 100.0,
                          "max_torque": 1e5},
                         {"device": "TouchSensor", "name": "bump", "on_joint": "pan"}]}]})
    batched = BatchedSimulation(w, 2)
    ref = batched.device("r", "bump")
    batched.enable(ref, STEP)
    batched.joints.command(0, "pan", position=math.pi / 2, copies=[1])
    batched.set_wheels(0, np.array([10.0, 0.0]), np.array([10.0, 0.0]))
    batched.run(100)
    assert batched.pose(0, 0).translation[0] == pytest.approx(0.2, abs=2e-3)
    assert batched.pose(1, 0).translation[0] == 0.0
    assert batched.value(ref).tolist() == [1.0, 0.0]


def test_a_light_sensor_on_a_pan_faces_the_lamp_in_the_copy_that_turned_it():
    """A light sensor 0.1 m ahead of a pan axis at the origin, looking along +x; a point light
    (intensity 0.8, attenuation 0 0 1, no ambient) 1 m to its left at its height. Copy 0 keeps the
    lamp behind the sensor's plane (cos < 0: 0); copy 1 turns the pan a quarter, the sensor then
    sits at (0, 0.1) facing the lamp 0.9 m away: 0.8 / 0.81 through the table (x 100)."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": False},
                     "lights": [{"type": "PointLight", "location": [0, 1.0, 0.3], "intensity": 0.8,
                                 "attenuation": [0, 0, 1]}],
                     "robots": [{"name": "r", "devices": [
                         {"device": "RotationalMotor", "name": "pan", "axis": [0, 0, 1], "max_velocity": 100.0,
                          "max_torque": 1e5},
                         {"device": "LightSensor", "name": "ls", "on_joint": "pan", "pose": {"translation": [0.1, 0, 0.3]},
                          "lookup_table": [[0, 0, 0], [10, 1000, 0]]}]}]})
    batched = BatchedSimulation(w, 2)
    ref = batched.device("r", "ls")
    batched.enable(ref, STEP)
    batched.joints.command(0, "pan", position=math.pi / 2, copies=[1])
    batched.step()
    assert batched.value(ref) == pytest.approx([0.0, 100.0 * 0.8 / 0.81], abs=1e-9)


def test_a_range_finder_turned_back_on_its_pan_sees_its_own_robot():
    """A one-pixel range finder 0.4 m ahead of a robot whose body is a 0.2 m box, on a pan hinge
    through (0.3, 0, 0), looking along +x at a wall whose near face is at x = 1: 0.6 m. Copy 1 turns
    the pan half a turn: the device sits at (0.2, 0) looking back along -x and sees its own robot's
    face at x = 0.1 (0.1 m), not the wall behind it at x = -1 (a Webots range finder sees its robot;
    its rays turn in the body frame, so none may skip the robot)."""
    w = parse_world({"world_info": {"basic_time_step": STEP, "contact": False},
                     "solids": [wall("front", 1.05, 0, 0.1, 8), wall("back", -1.05, 0, 0.1, 8)],
                     "robots": [{"name": "r", "body": {"geometry": {"type": "box", "size": [0.2, 0.2, 0.6]}},
                                 "devices": [
                         {"device": "RotationalMotor", "name": "pan", "axis": [0, 0, 1], "anchor": [0.3, 0, 0],
                          "max_velocity": 100.0, "max_torque": 1e5},
                         {"device": "RangeFinder", "name": "rf", "on_joint": "pan", "width": 1, "height": 1,
                          "field_of_view": 0.1, "max_range": 3.0, "pose": {"translation": [0.4, 0, 0.1]}}]}]})
    batched = BatchedSimulation(w, 2)
    ref = batched.device("r", "rf")
    batched.enable(ref, STEP)
    batched.joints.command(0, "pan", position=math.pi, copies=[1])
    batched.run(3)
    assert batched.joints.position[:, 0].tolist() == [0.0, math.pi]
    assert batched.range_image(ref)[:, 0, 0] == pytest.approx([0.6, 0.1], abs=1e-6)


@pytest.mark.parametrize("change, message", [
    (lambda r: (r["devices"].append({"device": "TouchSensor", "name": "bump", "on_joint": "tilt"}),
                r.setdefault("shapes", []).append({"name": "pad", "of_device": "bump", "on_joint": "tilt",
                                                   "geometry": {"type": "box", "size": [0.02, 0.1, 0.05]}})),
     "robot 'lift': shape 'pad' of 'bump' rides joint 'tilt'; the batched simulation moves no bumper's shapes on "
     "a link"),
    (lambda r: r["devices"].append({"device": "LED", "name": "lamp", "on_joint": "tilt"}),
     "robot 'lift': LED 'lamp' rides joint 'tilt'; the batched simulation moves distance sensors, light "
     "sensors, cameras, range finders, lidars, GPS, compasses, inertial units, gyros, accelerometers, "
     "altimeters and bumpers without shapes on joints only"),
], ids=["bumper with shapes", "LED"])
def test_what_rides_a_joint_and_is_not_simulated_is_refused_in_one_line(change, message):
    lift = lift_robot()
    change(lift)
    w = parse_world({"world_info": {"basic_time_step": STEP}, "robots": [lift]})
    with pytest.raises(BatchedError) as err:
        BatchedSimulation(w, 2)
    assert message in str(err.value) and "(use Simulation)" in str(err.value) and "\n" not in str(err.value)


def test_bad_joint_commands_name_the_motor():
    batched = BatchedSimulation(jointed_world(), 2)
    slot = batched.slot("lift")
    with pytest.raises(ValueError, match="motor 'tilt': position must be a number"):
        batched.joints.command(slot, "tilt", position=math.nan)
    with pytest.raises(ValueError, match="motor 'tilt': acceleration must be >= 0"):
        batched.joints.command(slot, "tilt", acceleration=-2.0)
    with pytest.raises(ValueError, match=r"motor 'tilt': velocity must be a number or one per copy \(2\), got \(3,\)"):
        batched.joints.command(slot, "tilt", velocity=[1.0, 2.0, 3.0])
    with pytest.raises(KeyError, match="no joint motor 'nope'"):
        batched.joints.command(slot, "nope", position=0.0)


def test_a_task_callable_commands_a_copys_joint_through_its_view():
    """The gym's view of copy 1 (what task callables get): its joint motor takes setPosition in that
    copy alone, coupled motors following (arm::b at -0.5 times arm::a's target); a negative velocity
    in position control is ignored, as the single motor ignores it."""
    from sensorium.gym.views import CopySim

    batched = BatchedSimulation(jointed_world(), 2)
    view = CopySim(batched, 1).robot("lift")
    view.motor("arm::a").set_position(0.8)
    slot = batched.slot("lift")
    a, b = batched.joints.of(slot, "arm::a"), batched.joints.of(slot, "arm::b")
    assert batched.joints.target[:, a].tolist() == [0.0, 0.8] and batched.joints.target[:, b].tolist() == [0.0, -0.4]
    view.motor("arm::a").set_velocity(-1.0)
    assert view.motor("arm::a").velocity == 2.0
    batched.run(40)
    assert view.motor("arm::a").position == 0.8 and view.motor("arm::b").position == -0.4
    assert batched.joints.position[0, a] == 0.0
