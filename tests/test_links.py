"""What rides on a joint moves with it (README "Joints"): shapes and devices that name a joint motor
in ``on_joint`` are turned by ``q - q0`` about a hinge's axis through its anchor, or moved by
``q - q0`` along a slider's axis, nested joints composed outward.

Every expected value is closed form: a sensor at height h on a pan hinge (axis z through the
robot's origin) looks along +x; turned by 90 degrees it looks along +y, so a wall whose near face is
at y = d reads d minus the sensor's offset along its new axis."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

DT_MS = 16
QUARTER = math.pi / 2


def _pan(**fields) -> dict:
    # maxTorque 1e5 and maxVelocity 100: full speed at once, any target within 1.6 rad reached in one step
    return {"device": "RotationalMotor", "name": "pan", "max_velocity": 100.0, "max_torque": 1e5,
            "axis": [0, 0, 1], **fields}


def _walls(front: float = 2.0, left: float = 1.0) -> list[dict]:
    """A blue wall whose near face is at x = front, a red one whose near face is at y = left."""
    return [{"name": "front", "pose": {"translation": [front + 0.05, 0, 0.5]},
             "geometry": {"type": "box", "size": [0.1, 8, 1]},
             "appearance": {"base_color": [0, 0, 1]}},
            {"name": "left", "pose": {"translation": [0, left + 0.05, 0.5]},
             "geometry": {"type": "box", "size": [8, 0.1, 1]},
             "appearance": {"base_color": [1, 0, 0]}}]


def _sim(robot: dict, solids: list[dict], robots: tuple[dict, ...] = (), lights: bool = False) -> Simulation:
    world: dict = {"world_info": {"basic_time_step": DT_MS, "contact": False}, "solids": solids,
                   "robots": [robot, *robots]}
    if lights:
        world["lights"] = [{"type": "DirectionalLight", "direction": [0, 0, -1], "ambient_intensity": 1.0}]
    return Simulation(parse_world(world))


def _distance_sensor(name: str = "ds", **fields) -> dict:
    # laser: one ray along +x, the lookup table the identity up to 10 m
    return {"device": "DistanceSensor", "name": name, "type": "laser",
            "lookup_table": [[0, 0, 0], [10, 10, 0]], **fields}


def test_a_distance_sensor_on_a_pan_joint_turned_90_degrees_reads_the_wall_to_the_side() -> None:
    """Sensor at (0.1, 0, 0.3) on the pan hinge: at q = 0 it reads the front wall, 2 - 0.1 = 1.9;
    at q = pi/2 it sits at (0, 0.1, 0.3) looking along +y and reads the left wall, 1 - 0.1 = 0.9;
    back at 0 it reads 1.9 again. A sensor on the robot's body (not on the joint) keeps 1.9."""
    robot = {"name": "r", "devices": [_pan(), _distance_sensor(pose={"translation": [0.1, 0, 0.3]}, on_joint="pan"),
                                      _distance_sensor("fixed", pose={"translation": [0.1, 0, 0.3]})]}
    sim = _sim(robot, _walls())
    for d in ("r/ds", "r/fixed"):
        sim.device(d).enable(DT_MS)
    sim.step()
    assert sim.device("r/ds").value == pytest.approx(1.9, abs=1e-9)
    pan = sim.robot("r").motor("pan")
    pan.set_position(QUARTER)
    sim.step()
    assert pan.position == QUARTER
    assert sim.device("r/ds").value == pytest.approx(0.9, abs=1e-9)
    assert sim.device("r/fixed").value == pytest.approx(1.9, abs=1e-9)
    pan.set_position(0.0)
    sim.step()
    assert sim.device("r/ds").value == pytest.approx(1.9, abs=1e-9)


def test_the_rule_is_relative_to_the_initial_position_and_turns_about_the_anchor() -> None:
    """A hinge with initial position 0.3 and anchor (0.5, 0, 0): the file places the sensor (at
    (0.6, 0, 0.3), looking +x) for q = 0.3, so at q = 0.3 + pi/2 it has turned a quarter about
    the vertical line through the anchor: at (0.5, 0.1, 0.3) looking +y, reading 1 - 0.1 = 0.9;
    a reset puts it back (2 - 0.6 = 1.4)."""
    robot = {"name": "r", "devices": [_pan(position=0.3, anchor=[0.5, 0, 0]),
                                      _distance_sensor(pose={"translation": [0.6, 0, 0.3]}, on_joint="pan")]}
    sim = _sim(robot, _walls())
    sim.device("r/ds").enable(DT_MS)
    sim.step()
    assert sim.device("r/ds").value == pytest.approx(1.4, abs=1e-9)
    sim.robot("r").motor("pan").set_position(0.3 + QUARTER)
    sim.step()
    assert sim.device("r/ds").value == pytest.approx(0.9, abs=1e-9)
    assert sim.device("r/ds").world_pose(sim.robot("r").pose).translation == pytest.approx([0.5, 0.1, 0.3], abs=1e-12)
    sim.reset()
    sim.step()
    assert sim.device("r/ds").value == pytest.approx(1.4, abs=1e-9)


def test_a_range_finder_and_a_camera_on_a_pan_joint_look_where_it_points_them() -> None:
    """A range finder (planar depth) and a camera at (0, 0, 0.3) on the pan hinge: at q = 0 the
    centre pixel's depth is 2 (the front wall) and the camera sees blue; at q = pi/2 the depth is 1
    (the left wall) and the camera sees red."""
    imager = {"width": 5, "height": 5, "field_of_view": 0.2, "pose": {"translation": [0, 0, 0.3]}, "on_joint": "pan"}
    robot = {"name": "r", "devices": [_pan(), {"device": "RangeFinder", "name": "depth", "max_range": 5.0, **imager},
                                      {"device": "Camera", "name": "cam", **imager}]}
    sim = _sim(robot, _walls(), lights=True)
    depth, cam = sim.device("r/depth"), sim.device("r/cam")
    depth.enable(DT_MS)
    cam.enable(DT_MS)
    sim.step()
    assert float(depth.range_image[2, 2]) == pytest.approx(2.0, abs=1e-6)
    b, g, r = (int(v) for v in cam.image[2, 2, :3])
    assert b > 0 and r == 0 and g == 0
    sim.robot("r").motor("pan").set_position(QUARTER)
    sim.step()
    assert float(depth.range_image[2, 2]) == pytest.approx(1.0, abs=1e-6)
    b, g, r = (int(v) for v in cam.image[2, 2, :3])
    assert r > 0 and b == 0 and g == 0


def test_a_lidar_raised_by_a_slider_sees_over_a_box() -> None:
    """A one-layer lidar at height 0.2 looking along +x, a box 0.5 high whose near face is at
    x = 1, a back wall at x = 3: at q = 0 the centre beam reads 1; the slider (axis z) raised by
    h = 0.4 puts the lidar at 0.6, above the box: it reads 3."""
    robot = {"name": "r", "devices": [
        {"device": "LinearMotor", "name": "lift", "max_velocity": 100.0, "max_force": 1e5, "axis": [0, 0, 1]},
        {"device": "Lidar", "name": "lidar", "horizontal_resolution": 3, "field_of_view": 0.1, "number_of_layers": 1,
         "max_range": 5.0, "pose": {"translation": [0, 0, 0.2]}, "on_joint": "lift"}]}
    solids = [{"name": "box", "pose": {"translation": [1.25, 0, 0.25]}, "geometry": {"type": "box", "size": [0.5, 1, 0.5]}},
              {"name": "wall", "pose": {"translation": [3.05, 0, 1]}, "geometry": {"type": "box", "size": [0.1, 8, 2]}}]
    sim = _sim(robot, solids)
    lidar = sim.device("r/lidar")
    lidar.enable(DT_MS)
    sim.step()
    assert float(lidar.range_image[0, 1]) == pytest.approx(1.0, abs=1e-6)
    sim.robot("r").motor("lift").set_position(0.4)
    sim.step()
    assert float(lidar.range_image[0, 1]) == pytest.approx(3.0, abs=1e-6)


def test_a_link_shape_moved_by_its_joint_is_seen_where_it_went_by_another_robot() -> None:
    """Robot "arm" has a 0.2 m cube on its pan joint, centred at (0.5, 0, 0.1) (the hinge through
    the origin). Robot "watcher" at (0.5, 2, 0), its sensor at height 0.1 looking along -y, sees the
    cube's far face at y = 0.1: 2 - 0.1 = 1.9. Turned by pi/2 the cube is centred at (0, 0.5, 0):
    the watcher's ray meets nothing (5, the table's end) -- until a second watcher at (0, 2, 0)
    reads 2 - 0.6 = 1.4."""
    arm = {"name": "arm", "devices": [_pan()],
           "shapes": [{"geometry": {"type": "box", "size": [0.2, 0.2, 0.2]}, "pose": {"translation": [0.5, 0, 0.1]},
                       "on_joint": "pan"}]}
    looking = {"rotation": [0, 0, 1, -QUARTER]}
    table = [[0, 0, 0], [5, 5, 0]]
    watcher = {"name": "watcher", "pose": {"translation": [0.5, 2, 0], **looking},
               "devices": [_distance_sensor(lookup_table=table, pose={"translation": [0, 0, 0.1]})]}
    other = {"name": "other", "pose": {"translation": [0, 2, 0], **looking},
             "devices": [_distance_sensor(lookup_table=table, pose={"translation": [0, 0, 0.1]})]}
    sim = _sim(arm, [], (watcher, other))
    sim.device("watcher/ds").enable(DT_MS)
    sim.device("other/ds").enable(DT_MS)
    sim.step()
    assert sim.device("watcher/ds").value == pytest.approx(1.9, abs=1e-9)
    assert sim.device("other/ds").value == 5.0
    sim.robot("arm").motor("pan").set_position(QUARTER)
    sim.step()
    assert sim.device("watcher/ds").value == 5.0
    assert sim.device("other/ds").value == pytest.approx(1.4, abs=1e-9)


def test_nested_joints_compose_outward() -> None:
    """A shoulder (hinge about z through the origin) carrying an elbow (hinge about z through
    (0.5, 0, 0)) carrying a sensor at (1, 0, 0.3) looking +x. Shoulder pi/2 and elbow -pi/2: the
    elbow is at (0, 0.5), the sensor at (0.5, 0.5, 0.3) looking +x again: the front wall at x = 2
    reads 1.5. The sensor's world pose is the composition (checked directly too)."""
    robot = {"name": "r", "devices": [
        _pan(), {**_pan(), "name": "elbow", "anchor": [0.5, 0, 0], "on_joint": "pan"},
        _distance_sensor(pose={"translation": [1, 0, 0.3]}, on_joint="elbow")]}
    sim = _sim(robot, _walls(left=3.0))
    sim.device("r/ds").enable(DT_MS)
    sim.robot("r").motor("pan").set_position(QUARTER)
    sim.robot("r").motor("elbow").set_position(-QUARTER)
    sim.step()
    pose = sim.device("r/ds").world_pose(sim.robot("r").pose)
    assert pose.translation == pytest.approx([0.5, 0.5, 0.3], abs=1e-12)
    assert pose.rotation == pytest.approx(np.eye(3), abs=1e-12)
    assert sim.device("r/ds").value == pytest.approx(1.5, abs=1e-9)
    sim.robot("r").motor("elbow").set_position(0.0)     # the elbow straight: looking +y from (0, 1, 0.3)
    sim.step()
    assert sim.device("r/ds").value == pytest.approx(2.0, abs=1e-9)


@pytest.mark.parametrize("robot, message", [
    ({"devices": [_distance_sensor(on_joint="nope")]},
     r"robots\[0\] \(r\)\.devices\[0\] \(ds\)\.on_joint: 'nope' is not a joint motor of this robot"),
    ({"devices": [_pan(on_joint="elbow"), {**_pan(), "name": "elbow", "on_joint": "pan"}]},
     r"joint 'pan' rides on itself through 'pan'"),
    ({"devices": [_pan(axis=[0, 0, 0])]}, "axis must not be zero"),
    ({"devices": [_pan(), _distance_sensor()],
      "shapes": [{"geometry": {"type": "sphere"}, "of_device": "ds", "on_joint": "pan"}]},
     r"shapes\[0\]\.on_joint: a shape of device 'ds' rides on its device's joint: None, not 'pan'"),
])
def test_bad_joint_links_are_refused_in_one_line(robot: dict, message: str) -> None:
    with pytest.raises(Exception, match=message):
        parse_world({"robots": [{"name": "r", **robot}]})


def test_a_housed_sensor_on_a_joint_is_blind_to_its_housing_and_its_robot_keeps_its_rules() -> None:
    """An infra-red sensor at (0.1, 0, 0.3) and a lidar at (0.1, 0, 0.2), each in a 0.1 m cube
    housing of its own (``of_device``) on the pan joint; a 0.1 m block B on the robot's body at
    (0.6, 0, 0.3) and one, L, on the pan joint at (0, -0.4, 0.3), which a quarter turn brings to
    (0.4, 0, 0.3); a generic sensor on the body at (0.1, 0, 0.3) looking +x. The housed devices are
    blind to their housings wherever the joint turns them (their mounts follow the link's body):
    at q = 0 infra-red sees its robot's B (Webots: 0.55 - 0.1 = 0.45), the lidar passes under B
    (1.9); at q = pi/2 both read the left wall, 1 - 0.1 = 0.9. The generic sensor never sees its
    own robot, its link L included (1.9 with L in its way), as it never sees its robot's body."""
    housing = {"geometry": {"type": "box", "size": [0.1, 0.1, 0.1]}}
    at, low = {"translation": [0.1, 0, 0.3]}, {"translation": [0.1, 0, 0.2]}
    robot = {"name": "r",
             "devices": [_pan(), _distance_sensor("ir", type="infra-red", pose=at, on_joint="pan"),
                         {"device": "Lidar", "name": "lidar", "horizontal_resolution": 3, "field_of_view": 0.1,
                          "number_of_layers": 1, "max_range": 5.0, "pose": low, "on_joint": "pan"},
                         _distance_sensor("body", pose=at)],
             "shapes": [{**housing, "pose": at, "of_device": "ir", "on_joint": "pan"},
                        {**housing, "pose": low, "of_device": "lidar", "on_joint": "pan"},
                        {**housing, "pose": {"translation": [0.6, 0, 0.3]}},
                        {**housing, "pose": {"translation": [0, -0.4, 0.3]}, "on_joint": "pan"}]}
    sim = _sim(robot, _walls())
    for d in ("r/ir", "r/lidar", "r/body"):
        sim.device(d).enable(DT_MS)
    sim.step()
    assert sim.device("r/ir").value == pytest.approx(0.45, abs=1e-9)
    assert float(sim.device("r/lidar").range_image[0, 1]) == pytest.approx(1.9, abs=1e-6)
    assert sim.device("r/body").value == pytest.approx(1.9, abs=1e-9)
    sim.robot("r").motor("pan").set_position(QUARTER)
    for _ in range(2):
        sim.step()
        assert sim.device("r/ir").value == pytest.approx(0.9, abs=1e-9)
        assert float(sim.device("r/lidar").range_image[0, 1]) == pytest.approx(0.9, abs=1e-6)
        assert sim.device("r/body").value == pytest.approx(1.9, abs=1e-9)
    assert sim.scene.shape_pose(5).translation == pytest.approx([0.4, 0, 0.3], abs=1e-12)   # L (after B, the body's)


def test_a_wbt_robot_keeps_its_joints_axes_anchors_and_what_rides_on_them(tmp_path) -> None:
    """A .wbt robot with two wheels and, under a Pose turned a quarter about z, a pan HingeJoint
    (axis 1 0 0, anchor 0 0.1 0.2 in the Pose's frame: in the robot's, axis (0, 1, 0) and anchor
    (-0.1, 0, 0.2)) whose end point (translation 0.1 0 0.3: (0, 0.1, 0.3) in the robot) holds a
    DistanceSensor, a box and a SliderJoint (axis 0 0 1) holding a sphere. Converted: the sensor,
    the box and the slider's motor ride on "pan", the sphere on "lift", the wheels' shapes on the
    body (no on_joint), the drive unchanged. Turned by pi/2 about (0, 1, 0) through the anchor the
    sensor is at (-0.1, 0, 0.2) + R_y(pi/2)·(0.1, 0.1, 0.1) = (0, 0.1, 0.1)."""
    from test_wbt_drives import wheel, write

    from sensorium.server.world.loader import load_world

    arm = ('Pose { rotation 0 0 1 1.5707963267948966 children [\n'
           ' HingeJoint { jointParameters HingeJointParameters { axis 1 0 0 anchor 0 0.1 0.2 }\n'
           '  device [ RotationalMotor { name "pan" maxVelocity 100 maxTorque 100000 } ]\n'
           '  endPoint Solid { translation 0.1 0 0.3 children [\n'
           '    DistanceSensor { name "ds" }\n'
           '    Shape { geometry Box { size 0.02 0.02 0.02 } }\n'
           '    SliderJoint { jointParameters JointParameters { axis 0 0 1 }\n'
           '      device [ LinearMotor { name "lift" } ]\n'
           '      endPoint Solid { children [ Shape { geometry Sphere { radius 0.01 } } ] } } ] } } ] }\n')
    w = load_world(write(tmp_path, 'Robot { name "rover" children [\n' + arm + wheel("left wheel", 0, 0.1)
                         + wheel("right wheel", 0, -0.1) + '] }\n'))
    robot = w.world.robots[0]
    assert robot.differential_drive is not None
    devices = {d.name: d for d in robot.devices}
    pan, lift = devices["pan"], devices["lift"]
    assert pan.axis == pytest.approx((0, 1, 0), abs=1e-15) and pan.anchor == pytest.approx((-0.1, 0, 0.2), abs=1e-15)
    assert (pan.on_joint, lift.on_joint, devices["ds"].on_joint) == (None, "pan", "pan")
    assert lift.axis == pytest.approx((0, 0, 1), abs=1e-15)
    rides = {s.geometry.type: s.on_joint for s in robot.shapes}
    assert rides == {"box": "pan", "sphere": "lift", "cylinder": None}
    assert all(d.on_joint is None for d in robot.devices if d.name.endswith("wheel"))
    sim = Simulation(w)
    sim.robot("rover").motor("pan").set_position(QUARTER)
    sim.step()
    pose = sim.device("rover/ds").world_pose(sim.robot("rover").pose)
    assert pose.translation == pytest.approx([0.0, 0.1, 0.1], abs=1e-12)


def test_a_joint_inside_a_wbt_device_turns_none_of_its_shapes(tmp_path) -> None:
    """A Lidar whose children hold a motorised turret HingeJoint with a cylinder: the cylinder is
    the lidar's own shape (``of_device``) and stays with the lidar (no on_joint), so the lidar stays
    blind to it as before; the turret's motor is still a joint (it turns)."""
    from test_wbt_drives import write

    from sensorium.server.world.loader import load_world

    lidar = ('Lidar { name "lidar" children [ HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 }\n'
             '  device [ RotationalMotor { name "turret" } ]\n'
             '  endPoint Solid { children [ Shape { geometry Cylinder { radius 0.03 height 0.02 } } ] } } ] }\n')
    w = load_world(write(tmp_path, 'Robot { name "r" children [\n' + lidar + '] }\n'))
    robot = w.world.robots[0]
    assert [(s.of_device, s.on_joint) for s in robot.shapes] == [("lidar", None)]
    assert {d.name: d.on_joint for d in robot.devices} == {"lidar": None, "turret": None}


def test_a_moved_robot_carries_its_turned_link() -> None:
    """The arm of the "another robot" test turned by pi/2 (its cube centred at (0, 0.5, 0.1) in
    its frame), then the robot set at (1, 0, 0) turned a quarter about z: the cube is centred at
    (1, 0, 0) + R_z(pi/2)·(0, 0.5, 0.1) = (0.5, 0, 0.1), where the watcher at (0.5, 2) sees its far
    face again: 2 - 0.1 = 1.9 (before the move, nothing: 5)."""
    arm = {"name": "arm", "devices": [_pan()],
           "shapes": [{"geometry": {"type": "box", "size": [0.2, 0.2, 0.2]}, "pose": {"translation": [0.5, 0, 0.1]},
                       "on_joint": "pan"}]}
    watcher = {"name": "watcher", "pose": {"translation": [0.5, 2, 0], "rotation": [0, 0, 1, -QUARTER]},
               "devices": [_distance_sensor(lookup_table=[[0, 0, 0], [5, 5, 0]], pose={"translation": [0, 0, 0.1]})]}
    sim = _sim(arm, [], (watcher,))
    sim.device("watcher/ds").enable(DT_MS)
    sim.robot("arm").motor("pan").set_position(QUARTER)
    sim.step()
    assert sim.device("watcher/ds").value == 5.0
    sim.robot("arm").set_pose(translation=[1, 0, 0], rotation=[0, 0, 1, QUARTER])
    sim.step()
    assert sim.device("watcher/ds").value == pytest.approx(1.9, abs=1e-9)


def test_an_encoder_on_a_joint_without_a_motor_reads_the_joints_position(tmp_path) -> None:
    """A .wbt robot (an inverted pendulum's structure: a motorised SliderJoint whose end point holds a
    passive HingeJoint with only a PositionSensor, position 0.3, and beside it a passive SliderJoint
    at 0.05 m). Webots' PositionSensor reads its joint's position; nothing turns these joints here,
    so they read where the world file puts them, 0.3 rad and 0.05 m (they used to read 0), in the
    simulation and the batched one alike, and stay there while the slider carries the hinge."""
    from test_wbt_drives import write

    from sensorium.server.sim.batched import BatchedSimulation
    from sensorium.server.world.loader import load_world

    w = load_world(write(tmp_path, (
        'Robot { name "cart" children [\n'
        ' SliderJoint { jointParameters JointParameters { axis 1 0 0 }\n'
        '  device [ LinearMotor { name "rail" maxVelocity 100 maxForce 100000 } PositionSensor { name "rail sensor" } ]\n'
        '  endPoint Solid { translation 0 0 0.06 children [\n'
        '   HingeJoint { jointParameters HingeJointParameters { position 0.3 axis 0 1 0 anchor 0 0 0.03 }\n'
        '    device [ PositionSensor { name "hip" } ]\n'
        '    endPoint Solid { translation 0 0 0.33 children [ Shape { geometry Box { size 0.05 0.02 0.6 } } ] } } ] } }\n'
        ' SliderJoint { jointParameters JointParameters { position 0.05 }\n'
        '  device [ PositionSensor { name "idle" } ] endPoint Solid { translation 0 0 0.05 } }\n'
        '] }\n')))
    devices = {d.name: d for d in w.world.robots[0].devices}
    assert (devices["hip"].motor, devices["hip"].position) == (None, 0.3)
    assert (devices["idle"].motor, devices["idle"].position) == (None, 0.05)
    assert any("reads the joint's position, 0.3" in m for m in w.warnings), w.warnings
    sim = Simulation(w)
    names = ("rail sensor", "hip", "idle")
    for n in names:
        sim.device(f"cart/{n}").enable(DT_MS)
    sim.robot("cart").motor("rail").set_position(0.5)
    sim.step()
    assert [sim.device(f"cart/{n}").value for n in names] == [0.5, 0.3, 0.05]
    still = load_world(write(tmp_path, (      # the batched simulation moves no joint: the passive ones alone
        'Robot { name "cart" children [\n'
        ' HingeJoint { jointParameters HingeJointParameters { position 0.3 } device [ PositionSensor { name "hip" } ] }\n'
        ' SliderJoint { jointParameters JointParameters { position 0.05 } device [ PositionSensor { name "idle" } ] }\n'
        '] }\n')))
    bs = BatchedSimulation(still.world, 2)
    for n in ("hip", "idle"):
        bs.enable(bs.device("cart", n), DT_MS)
    bs.step()
    assert bs.value(bs.device("cart", "hip")).tolist() == [0.3, 0.3]
    assert bs.value(bs.device("cart", "idle")).tolist() == [0.05, 0.05]
