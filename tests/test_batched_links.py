"""A link's shapes in the batched simulation: the shapes riding a joint (``on_joint``) are template
bodies of their own, posed in each copy from its robot's pose and its joints, so every ray of a copy
meets them where that copy's joints hold them, and no other copy's rays do. A robot with a swinging
arm (a hinge carrying a bar, and a nested tilt hinge carrying a hand) in front of another robot's
distance sensors, lidar, camera, range finder and a light sensor the arm shadows from a lamp, and
the arm's own distance sensor, lidar, camera and light sensor (self-collision on) that see the bar,
and a flag on the other robot's own pan, which its generic distance sensor and light sensor are blind
to (their robot excluded: its links too) and its infra-red sensor, lidar and camera see: every copy, with its
own random joint commands, reads bit for bit what Simulation built with that copy's seed reads.
Closed form: the bar swung by a (2.6 deg < a < 9.5 deg) shows its side face to a sensor on its
pivot's axis at 0.025 / sin(a) from the pivot; a light on the swing lights a sensor by 1/d² from
where each copy's joint holds it. A camera recognises the arm with its links where each copy holds
them. Distance sensors, a light sensor, lidars, cameras and range finders (some in domes of their own)
riding the swing see its bar (and planes riding the links) as their Simulation does (closed form: the bar's top face below them at 0.05 / sin of a ray's
pitch). What the copies cannot follow is refused in one line."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from sensorium.server.sim.batched import BatchedError, BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

STEP = 16
WATCHER_X = 0.9          # the watcher's origin; its sensors sit 0.09 ahead of it, looking at the arm (-x)


def wall(name: str, x: float, y: float, sx: float, sy: float) -> dict:
    return {"name": name, "pose": {"translation": [x, y, 0.5]}, "geometry": {"type": "box", "size": [sx, sy, 1.0]},
            "appearance": {"base_color": [0.8, 0.5, 0.2]}}


def arm_robot(seen_by: str = "both", lights: bool = True) -> dict:
    """No drive: a hinge (axis z through its origin) carrying a bar from x = 0.15 to 0.55 (0.05 wide,
    0.1 high, its centre 0.15 above the origin), and a tilt hinge riding it at the bar's end carrying a
    hand; its own distance sensor, lidar, camera and light sensor (facing a lamp behind it) see the bar
    (self_collision). With ``lights``, a point light rides the swing above the bar, 0.45 from the
    pivot, and a spot light the wrist, at the hand."""
    return {"name": "arm", "pose": {"translation": [0.0, 0.0, 0.05]}, "self_collision": True,
            "body": {"geometry": {"type": "box", "size": [0.2, 0.2, 0.2]}},
            "shapes": [{"name": "bar", "on_joint": "swing", "seen_by": seen_by,
                        "pose": {"translation": [0.35, 0.0, 0.15]}, "geometry": {"type": "box", "size": [0.4, 0.05, 0.1]},
                        "appearance": {"base_color": [0.1, 0.7, 0.3]}},
                       {"name": "hand", "on_joint": "wrist", "seen_by": seen_by,
                        "pose": {"translation": [0.6, 0.0, 0.15]}, "geometry": {"type": "sphere", "radius": 0.04},
                        "appearance": {"base_color": [0.9, 0.1, 0.1]}}],
            "lights": [] if not lights else [
                       {"type": "PointLight", "on_joint": "swing", "location": [0.45, 0.0, 0.3], "intensity": 0.8,
                        "attenuation": [0, 0, 1]},
                       {"type": "SpotLight", "on_joint": "wrist", "location": [0.6, 0.0, 0.22], "direction": [1, 0, 0],
                        "light_sensor_direction": [1, 0, -0.2], "cut_off_angle": 0.6, "beam_width": 0.4,
                        "intensity": 1.2, "color": [1.0, 0.6, 0.3]}],
            "devices": [{"device": "RotationalMotor", "name": "swing", "axis": [0, 0, 1], "max_velocity": 8.0},
                        {"device": "RotationalMotor", "name": "wrist", "on_joint": "swing", "axis": [0, 1, 0],
                         "anchor": [0.55, 0.0, 0.15], "max_velocity": 3.0},
                        {"device": "DistanceSensor", "name": "own ds", "pose": {"translation": [0.11, 0.0, 0.12],
                                                                               "rotation": [0, 0, 1, 0.3]},
                         "lookup_table": [[0, 0, 0], [2.0, 2.0, 0]]},
                        {"device": "Lidar", "name": "own lidar", "pose": {"translation": [0.0, 0.0, 0.2]},
                         "horizontal_resolution": 36, "field_of_view": 2 * math.pi, "number_of_layers": 2,
                         "vertical_field_of_view": 0.3, "min_range": 0.05, "max_range": 2.0},
                        {"device": "Camera", "name": "own cam", "pose": {"translation": [0.11, 0.0, 0.14]},
                         "width": 12, "height": 8, "field_of_view": 1.4},
                        {"device": "LightSensor", "name": "own ls", "occlusion": True,
                         "pose": {"translation": [-0.11, 0.0, 0.15], "rotation": [0, 0, 1, math.pi]},
                         "lookup_table": [[0, 0, 0], [10, 1000, 0]]}]}


def watcher_robot(seen_by: str = "both") -> dict:
    """Facing the arm (-x) from WATCHER_X: distance sensors (generic and infra-red, noisy), a lidar, a
    camera, a range finder and a light sensor looking at a lamp behind the arm; a flag on a pan hinge
    of its own, right in front of those sensors when the pan is at 0: they are blind to their robot
    (no self-collision), so to its link too, but its camera is not; a distance sensor and a light
    sensor ride the flag, blind to it."""
    ahead = {"translation": [0.09, 0.0, 0.15]}
    return {"name": "watcher", "pose": {"translation": [WATCHER_X, 0.0, 0.05], "rotation": [0, 0, 1, math.pi]},
            "body": {"geometry": {"type": "cylinder", "radius": 0.08, "height": 0.1}},
            "shapes": [{"name": "flag", "on_joint": "flag pan", "seen_by": seen_by,
                        "pose": {"translation": [0.16, 0.0, 0.15]}, "geometry": {"type": "box", "size": [0.02, 0.1, 0.1]},
                        "appearance": {"base_color": [0.2, 0.2, 0.9]}}],
            "devices": [{"device": "RotationalMotor", "name": "flag pan", "axis": [0, 0, 1], "max_velocity": 4.0},
                        {"device": "DistanceSensor", "name": "flag ds", "on_joint": "flag pan",
                         "pose": {"translation": [0.18, 0.0, 0.15]}, "lookup_table": [[0, 0, 0], [2.0, 2.0, 0]]},
                        {"device": "LightSensor", "name": "flag ls", "on_joint": "flag pan", "occlusion": True,
                         "pose": {"translation": [0.18, 0.03, 0.15]}, "lookup_table": [[0, 0, 0], [10, 1000, 0]]},
                        {"device": "DistanceSensor", "name": "ds", "pose": ahead,
                         "lookup_table": [[0, 0, 0], [2.0, 2.0, 0]]},
                        {"device": "DistanceSensor", "name": "noisy ds", "pose": {"translation": [0.09, 0.02, 0.15]},
                         "lookup_table": [[0, 0, 0], [2.0, 2000, 0.05]]},
                        {"device": "DistanceSensor", "name": "ir", "type": "infra-red",
                         "pose": {"translation": [0.09, -0.02, 0.15], "rotation": [0, 0, 1, 0.05]},
                         "lookup_table": [[0, 0, 0], [2.0, 2000, 0]]},
                        {"device": "Lidar", "name": "lidar", "pose": {"translation": [0.09, 0.0, 0.17]},
                         "horizontal_resolution": 48, "field_of_view": 1.6, "number_of_layers": 3,
                         "vertical_field_of_view": 0.3, "min_range": 0.05, "max_range": 3.0, "noise": 0.01},
                        {"device": "Camera", "name": "cam", "pose": {"translation": [0.09, 0.0, 0.2]}, "width": 16,
                         "height": 10, "field_of_view": 1.2, "noise": 0.02},
                        {"device": "RangeFinder", "name": "rf", "pose": {"translation": [0.09, 0.0, 0.22]},
                         "width": 12, "height": 8, "field_of_view": 1.2, "max_range": 3.0},
                        {"device": "LightSensor", "name": "ls", "pose": ahead, "occlusion": True,
                         "lookup_table": [[0, 0, 0], [10, 1000, 0]]}]}


def arm_world(seed: int = 3, lights: bool = True):
    return parse_world({"world_info": {"basic_time_step": STEP, "contact": False, "random_seed": seed},
                        "solids": [wall("north", 0, 1.2, 2.8, 0.2), wall("south", 0, -1.2, 2.8, 0.2),
                                   wall("east", 1.3, 0, 0.2, 2.2), wall("west", -1.3, 0, 0.2, 2.2)],
                        "lights": [{"type": "PointLight", "location": [-0.9, 0.0, 0.2], "intensity": 1.5,
                                    "attenuation": [0, 0, 1]}],
                        "robots": [arm_robot(lights=lights), watcher_robot()]})


DEVICES = {"arm": ["own ds", "own lidar", "own cam", "own ls"],
           "watcher": ["ds", "noisy ds", "ir", "lidar", "cam", "rf", "ls", "flag ds", "flag ls"]}


def _single(world, seed: int, precision: str) -> Simulation:
    sim = Simulation(world.world.model_copy(update={"world_info": world.world.world_info.model_copy(
        update={"random_seed": seed})}), precision=precision)
    for robot, names in DEVICES.items():
        for name in names:
            sim.device(f"{robot}/{name}").enable(STEP)
    return sim


def _reading(batched: BatchedSimulation, sim: Simulation, c: int, robot: str, name: str) -> tuple[bytes, bytes]:
    ref = batched.device(robot, name)
    dev = sim.device(f"{robot}/{name}")
    if ref.kind in ("Lidar", "RangeFinder"):
        return batched.range_image(ref)[c].tobytes(), dev.range_image.tobytes()
    if ref.kind == "Camera":
        return batched.image(ref)[c].tobytes(), dev.image.tobytes()
    return batched.value(ref)[c].tobytes(), np.float64(dev.value).tobytes()


def _command(batched, singles: list, c: int, robot: str, name: str, target: float) -> None:
    """Copy ``c``'s joint ``name`` of ``robot`` and its Simulation's both sent to ``target``."""
    singles[c].robot(robot).motor(name).set_position(target)
    batched.joints.command(batched.slot(robot), name, position=target, copies=[c])


def _step_together(batched, singles: list, arm: int, t: int) -> None:
    """One step of every Simulation and of the batched one; each copy's swing and wrist at its
    Simulation's positions, bit for bit."""
    for s in singles:
        s.step()
    batched.step()
    for c, s in enumerate(singles):
        for name in ("swing", "wrist"):
            got = batched.joints.position[c, batched.joints.of(arm, name)]
            assert got.tobytes() == np.float64(s.robot("arm").joints[name].position).tobytes(), (t, c, name)


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_every_copy_sees_its_own_links_as_its_simulation_bit_for_bit(precision):
    """Three copies and a Simulation per copy (seeds 3, 4, 5), 200 steps; every 40 steps each copy's
    swing and wrist get new random targets; copy 2 reset at step 110 against a fresh Simulation. Every
    reading of both robots the same bits every step (the light sensors and cameras lit by the lights
    riding the swing and the wrist where each copy holds them); the watcher's sensor saw the bar and
    saw past it."""
    world = arm_world()
    seeds = (3, 4, 5)
    n = len(seeds)
    batched = BatchedSimulation(world, n, precision=precision)
    batched.reset(np.arange(n), list(seeds))
    for robot, names in DEVICES.items():
        for name in names:
            batched.enable(batched.device(robot, name), STEP)
    singles = [_single(world, s, precision) for s in seeds]
    arm = batched.slot("arm")
    rng = np.random.default_rng(7)
    ds_values: set[float] = set()
    light_values: set[float] = set()
    own_light: set[float] = set()
    for t in range(200):
        if t == 110:
            batched.reset([2], [seeds[2]])
            for robot, names in DEVICES.items():
                for name in names:
                    batched.enable(batched.device(robot, name), STEP, copies=[2])
            singles[2] = _single(world, seeds[2], precision)
        if t % 40 == 0:
            for c in range(n):
                for robot, name, span in (("arm", "swing", math.pi), ("arm", "wrist", 1.2),
                                          ("watcher", "flag pan", math.pi)):
                    # (the swing now and then straight ahead or back: the bar between a lamp and a light sensor)
                    pick = rng.integers(3) if name == "swing" else 2
                    target = (0.0, math.pi, float(rng.uniform(-span, span)))[pick]
                    _command(batched, singles, c, robot, name, target)
        _step_together(batched, singles, arm, t)
        for c, s in enumerate(singles):
            for robot, names in DEVICES.items():
                for name in names:
                    got, want = _reading(batched, s, c, robot, name)
                    assert got == want, (t, c, robot, name)
            ds_values.add(float(batched.value(batched.device("watcher", "ds"))[c]))
            light_values.add(float(batched.value(batched.device("watcher", "ls"))[c]))
            own_light.add(float(batched.value(batched.device("arm", "own ls"))[c]))
    assert min(ds_values) < 0.3 and max(ds_values) > 1.5      # the bar in front of it, and out of the way
    assert len(light_values) > 20 and len(own_light) > 20       # lit as the links' lights move


def test_a_bar_swung_by_a_shows_its_side_at_the_closed_form_distance_in_its_copy_only():
    """The watcher's generic sensor sits on the swing's axis line (y = 0, 0.81 from the pivot) looking
    at it: with the bar straight (a = 0) it reads the hand past the bar's end (a sphere of radius 0.04
    at 0.6 from the pivot), 0.81 - 0.64; swung by a = 0.1 rad (the hand 0.06 aside, clear of the line), the
    bar's side face (0.025 off its axis) crosses y = 0 at 0.025 / sin(a) from the pivot; swung a
    quarter turn, nothing is in the way but the far wall's face (x = -1.2). Each copy reads its own."""
    batched = BatchedSimulation(arm_world(), 3, precision="exact")
    ref = batched.device("watcher", "ds")
    batched.enable(ref, STEP)
    arm = batched.slot("arm")
    batched.joints.command(arm, "swing", position=np.array([0.0, 0.1, math.pi / 2]))
    batched.run(60)
    assert batched.joints.position[:, batched.joints.of(arm, "swing")].tolist() == [0.0, 0.1, math.pi / 2]
    sensor_x = WATCHER_X - 0.09
    want = [sensor_x - 0.64, sensor_x - 0.025 / math.sin(0.1), min(2.0, sensor_x + 1.2)]
    assert batched.value(ref) == pytest.approx(want, abs=1e-9)


def test_a_link_hides_a_lamp_in_the_copy_whose_arm_is_in_the_way():
    """The lamp (-0.9, 0, 0.2) and the watcher's light sensor (0.81, 0, 0.2) on one line through the
    bar: copy 0's straight bar shadows the sensor (0), copy 1's bar swung a quarter turn does not."""
    batched = BatchedSimulation(arm_world(lights=False), 2)
    ref = batched.device("watcher", "ls")
    batched.enable(ref, STEP)
    batched.joints.command(batched.slot("arm"), "swing", position=np.array([0.0, math.pi / 2]))
    batched.run(60)
    got = batched.value(ref)
    assert got[0] == 0.0 and got[1] > 0.0


def test_a_light_on_a_link_lights_a_sensor_from_where_its_copy_holds_it():
    """The point light riding the swing (intensity 0.8, 1/d² attenuation) 0.45 from the pivot, 0.35 up:
    swung by a it is at (0.45 cos a, 0.45 sin a, 0.35), and the watcher's light sensor at (0.81, 0, 0.2),
    facing -x, reads 100 x 0.8 cos(theta) / d² through its table (10 -> 1000), the bar clear of the line."""
    w = {"world_info": {"basic_time_step": STEP, "contact": False}, "robots": [arm_robot(), watcher_robot()]}
    w["robots"][0]["lights"] = w["robots"][0]["lights"][:1]
    batched = BatchedSimulation(parse_world(w), 3)
    ref = batched.device("watcher", "ls")
    batched.enable(ref, STEP)
    angles = np.array([0.0, math.pi / 2, -0.7])
    batched.joints.command(batched.slot("arm"), "swing", position=angles)
    batched.joints.command(batched.slot("watcher"), "flag pan", position=2.0)
    batched.run(60)
    want = []
    for a in angles.tolist():
        v = np.array([0.45 * math.cos(a) - 0.81, 0.45 * math.sin(a), 0.35 - 0.2])
        d = float(np.linalg.norm(v))
        want.append(100.0 * 0.8 * (-v[0] / d) / d ** 2)
    assert batched.value(ref) == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("world, message", [
    (lambda: _changed(lambda r: None, contact=True), "robot 'arm': shape 'bar' rides joint 'swing' and bounds the "
     "robot; the batched simulation's kinematic contact does not follow a link"),
    (lambda: _changed(lambda r: (r["devices"].append({"device": "TouchSensor", "name": "bump", "on_joint": "swing"}),
                                 r["shapes"].append({"name": "pad", "of_device": "bump", "on_joint": "swing",
                                                     "geometry": {"type": "box", "size": [0.02, 0.1, 0.05]}}))),
     "robot 'arm': shape 'pad' of 'bump' rides joint 'swing'; the batched simulation moves no bumper's shapes on a link"),
], ids=["bounding link with contact", "bumper's shapes on a link"])
def test_what_a_link_cannot_carry_here_is_refused_in_one_line(world, message):
    with pytest.raises(BatchedError, match=re.escape(message)):
        BatchedSimulation(world(), 2)


def _changed(change, contact: bool = False, seen_by: str = "both"):
    """The arm world with ``change`` made to the arm; with ``contact``, the watcher on wheels (a
    driven robot: kinematic contact runs, every robot's footprint an obstacle)."""
    w = {"world_info": {"basic_time_step": STEP, "contact": contact}, "robots": [arm_robot(seen_by), watcher_robot(seen_by)]}
    change(w["robots"][0])
    if contact:
        w["robots"][1]["differential_drive"] = {"wheel_radius": 0.03, "axle_length": 0.15, "max_wheel_speed": 10.0}
    return parse_world(w)


def test_a_visual_only_link_runs_with_contact():
    """A link seen only by visual rays does not bound the robot: a world with contact runs it."""
    batched = BatchedSimulation(_changed(lambda r: None, contact=True, seen_by="visual"), 2)
    assert batched.contact is not None
    ref = batched.device("watcher", "ir")          # (infra-red: visual rays, which see the bar)
    batched.enable(ref, STEP)
    batched.joints.command(batched.slot("arm"), "swing", position=np.array([0.0, math.pi / 2]))
    batched.joints.command(batched.slot("watcher"), "flag pan", position=2.0)    # (its own flag out of the way)
    batched.run(60)
    got = batched.value(ref)
    assert got[0] < 600.0 and got[1] == 2000.0      # the hand 0.17 m ahead in copy 0; nothing in copy 1


def _recognising(seed: int) -> object:
    """The arm world with the arm recognisable and the watcher's camera recognising (segmentation on)."""
    def change(w):
        w["robots"][0]["recognition_colors"] = [[0.1, 0.7, 0.3]]
        cam = next(d for d in w["robots"][1]["devices"] if d["name"] == "cam")
        cam["recognition"] = {"segmentation": True, "max_range": 3.0}
    w = {"world_info": {"basic_time_step": STEP, "contact": False, "random_seed": seed},
         "robots": [arm_robot(), watcher_robot()]}
    change(w)
    return parse_world(w)


def test_a_camera_recognises_a_robot_with_its_links_where_each_copy_holds_them():
    """The watcher's camera recognises the arm (its box the union of its body, bar and hand where the
    copy's joints hold them) and segments it: three copies with their own random swings, 120 steps,
    every copy's objects and segmentation image those of its Simulation, bit for bit (copy 0's links
    unmoved for 30 steps, carried by its robot's pose alone as the single scene carries them; the objects'
    sizes change as the bar swings, and differ between copies)."""
    seeds = (3, 4, 5)
    n = len(seeds)
    batched = BatchedSimulation(_recognising(seeds[0]), n)
    batched.reset(np.arange(n), list(seeds))
    cam = batched.device("watcher", "cam")
    batched.enable(cam, STEP)
    batched.recognition_enable(cam, STEP)
    batched.enable_segmentation(cam, True)
    singles = [Simulation(_recognising(s).world) for s in seeds]
    for s in singles:
        dev = s.device("watcher/cam")
        dev.enable(STEP)
        dev.recognition_enable(STEP)
        dev.enable_segmentation(True)
    arm = batched.slot("arm")
    rng = np.random.default_rng(5)
    sizes: set[tuple] = set()
    for t in range(120):
        if t % 30 == 0:
            for c in range(0 if t else 1, n):     # (copy 0's links unmoved until step 30: carried by its robot)
                for name, span in (("swing", 1.2), ("wrist", 1.2)):
                    target = float(rng.uniform(-span, span))
                    singles[c].robot("arm").motor(name).set_position(target)
                    batched.joints.command(arm, name, position=target, copies=[c])
        for s in singles:
            s.step()
        batched.step()
        for c, s in enumerate(singles):
            dev = s.device("watcher/cam")
            got = batched.recognition_objects(cam, c)
            assert got == dev.objects and repr(got) == repr(dev.objects), (t, c)
            assert batched.segmentation_image(cam)[c].tobytes() == dev.segmentation_image.tobytes(), (t, c)
            sizes.update(tuple(o.size) for o in got)
    assert len(sizes) > 10          # the arm's box follows its links


# sensors riding the swing, which see the bar they ride (self-collision; infra-red sees its robot anyway)
TIP_BAR_DROP = 0.05       # the sensors sit 0.25 above the arm's origin, the bar's top face 0.2
TIP_DS_TILT = 1.2         # the tip sensor's ray: pitched down by this, onto the bar's top face ahead of it
TIP = [{"device": "DistanceSensor", "name": "tip ds", "on_joint": "swing", "lookup_table": [[0, 0, 0], [2.0, 2.0, 0]],
        "pose": {"translation": [0.3, 0, 0.25], "rotation": [0, 1, 0, TIP_DS_TILT]}},
       {"device": "DistanceSensor", "name": "tip ir", "type": "infra-red", "on_joint": "swing",
        "pose": {"translation": [0.45, 0, 0.25], "rotation": [0, 1, 0, 1.0]}, "lookup_table": [[0, 0, 0], [2.0, 2000, 0.02]]},
       {"device": "DistanceSensor", "name": "tip sonar", "type": "sonar", "on_joint": "swing", "number_of_rays": 4,
        "aperture": 0.5, "pose": {"translation": [0.5, 0, 0.25], "rotation": [0, 1, 0, 0.9]},
        "lookup_table": [[0, 0, 0], [2.0, 2000, 0]]},
       {"device": "DistanceSensor", "name": "tip fan", "on_joint": "swing", "number_of_rays": 3, "aperture": 0.3,
        "pose": {"translation": [0.3, 0, 0.25], "rotation": [0, 1, 0, 0.6]}, "lookup_table": [[0, 0, 0], [2.0, 2.0, 0]]},
       {"device": "LightSensor", "name": "tip ls", "on_joint": "swing", "occlusion": True,
        "pose": {"translation": [0.3, 0, 0.05], "rotation": [0, 0, 1, math.pi]}, "lookup_table": [[0, 0, 0], [10, 1000, 0]]},
       {"device": "Lidar", "name": "tip lidar", "on_joint": "swing", "pose": {"translation": [0.3, 0, 0.25]},
        "horizontal_resolution": 64, "field_of_view": 2 * math.pi, "number_of_layers": 4, "vertical_field_of_view": 1.2,
        "min_range": 0.02, "max_range": 2.5, "noise": 0.01},
       {"device": "Lidar", "name": "tip sweep", "type": "rotating", "on_joint": "swing", "default_frequency": 7.0,
        "pose": {"translation": [0.35, 0, 0.25]}, "horizontal_resolution": 48, "field_of_view": 2 * math.pi,
        "number_of_layers": 3, "vertical_field_of_view": 1.2, "min_range": 0.02, "max_range": 2.5}]
# a camera (noisy, recognising the watcher, segmentation on) and a range finder riding the swing,
# looking down along the bar, the hand beyond it
TIP_PIXELS = [{"device": "Camera", "name": "tip cam", "on_joint": "swing", "width": 24, "height": 16, "field_of_view": 1.4,
               "noise": 0.02, "pose": {"translation": [0.25, 0, 0.27], "rotation": [0, 1, 0, 0.7]},
               "recognition": {"segmentation": True, "max_range": 3.0}},
              {"device": "RangeFinder", "name": "tip rf", "on_joint": "swing", "width": 20, "height": 12,
               "field_of_view": 1.3, "max_range": 3.0, "pose": {"translation": [0.25, 0, 0.28], "rotation": [0, 1, 0, 0.5]}}]
# a fixed and a rotating lidar riding the swing, each in a dome of its own (of_device) it does not see
HOUSED = [{"device": "Lidar", "name": "housed", "on_joint": "swing", "pose": {"translation": [0.3, 0, 0.25]},
           "horizontal_resolution": 64, "field_of_view": 2 * math.pi, "number_of_layers": 4,
           "vertical_field_of_view": 1.2, "min_range": 0.02, "max_range": 2.5},
          {"device": "Lidar", "name": "housed sweep", "type": "rotating", "on_joint": "swing", "default_frequency": 7.0,
           "pose": {"translation": [0.4, 0, 0.25]}, "horizontal_resolution": 48, "field_of_view": 2 * math.pi,
           "number_of_layers": 3, "vertical_field_of_view": 1.2, "min_range": 0.02, "max_range": 2.5, "noise": 0.01}]
# a recognising camera beside the bar looking at its side face (its normal turned by the swing) and a
# range finder looking down on it, each in a hood of its own it does not see
HOUSED_PIXELS = [{"device": "Camera", "name": "housed cam", "on_joint": "swing", "width": 24, "height": 16,
                  "field_of_view": 1.4, "noise": 0.02, "recognition": {"segmentation": True, "max_range": 3.0},
                  "pose": {"translation": [0.35, 0.12, 0.22], "rotation": [0, 0, 1, -math.pi / 2]}},
                 {"device": "RangeFinder", "name": "housed rf", "on_joint": "swing", "width": 20, "height": 12,
                  "field_of_view": 1.3, "max_range": 3.0, "pose": {"translation": [0.35, 0, 0.28], "rotation": [0, 1, 0, 0.5]}}]


def _domes(devices: list[dict]) -> list[dict]:
    """A sphere of radius 0.03 around each device, its own (``of_device``), riding the swing."""
    return [{"name": f"dome of {d['name']}", "of_device": d["name"], "on_joint": "swing", "pose": d["pose"],
             "geometry": {"type": "sphere", "radius": 0.03}, "appearance": {"base_color": [0.5, 0.5, 0.5]}}
            for d in devices]


# planes on links: a panel on the swing (facing the watcher; a distance sensor riding the swing meets
# its back, and a lidar its edge-on sides), and one on the watcher's flag, facing its sensors: blind to
# their robot, its generic sensors never see it (as bounding rays, an infinite plane), its infra-red
# sensor, lidar and camera do
PANELS = [{"device": "DistanceSensor", "name": "panel ds", "on_joint": "swing", "pose": {"translation": [0.3, 0, 0.25]},
           "lookup_table": [[0, 0, 0], [2.0, 2.0, 0]]},
          {"device": "Lidar", "name": "panel lidar", "on_joint": "swing", "pose": {"translation": [0.3, 0, 0.3]},
           "horizontal_resolution": 64, "field_of_view": 2 * math.pi, "number_of_layers": 2,
           "vertical_field_of_view": 0.4, "min_range": 0.02, "max_range": 2.5}]
PANEL_SHAPES = {0: [{"name": "panel", "on_joint": "swing", "geometry": {"type": "plane", "size": [0.2, 0.3]},
                     "pose": {"translation": [0.45, 0, 0.25], "rotation": [0, 1, 0, math.pi / 2]},
                     "appearance": {"base_color": [0.3, 0.3, 0.3]}}],
                1: [{"name": "flag panel", "on_joint": "flag pan", "geometry": {"type": "plane", "size": [0.1, 0.1]},
                     "pose": {"translation": [0.145, 0, 0.15], "rotation": [0, 1, 0, -math.pi / 2]},
                     "appearance": {"base_color": [0.3, 0.3, 0.3]}}]}
RECOGNISING = {"tip cam", "housed cam"}
STEADY = {"tip ds", "tip fan"}     # their rays meet the bar below them whatever the swing: one reading
RIDERS = {"sensors": (TIP, {0: _domes(TIP[1:2])}, ["tip ds", "tip ir", "tip sonar", "tip fan", "tip ls", "tip lidar", "tip sweep", "own ds"]),
          "pixels": (TIP_PIXELS, {}, ["tip cam", "tip rf", "own cam"]),
          "housed lidars": (HOUSED, {0: _domes(HOUSED)}, ["housed", "housed sweep", "own lidar"]),
          "housed pixels": (HOUSED_PIXELS, {0: _domes(HOUSED_PIXELS)}, ["housed cam", "housed rf"]),
          "planes": (PANELS, PANEL_SHAPES, ["panel ds", "panel lidar", "own ds", "own lidar", "own cam", "watcher/ds",
                                            "watcher/noisy ds", "watcher/ir", "watcher/lidar", "watcher/cam", "watcher/rf"])}


def _at(entry: str) -> tuple[str, str]:
    """(robot, device) of a RIDERS entry: ``robot/device``, or a device of the arm."""
    robot, _, name = entry.rpartition("/")
    return robot or "arm", name


def _riders_world(seed: int, case: str, lidar_noise: bool = True):
    """The arm world (no lights on the arm) with ``case``'s devices on the arm and shapes on its robots;
    the watcher recognisable."""
    devices, shapes, _ = RIDERS[case]
    w = arm_world(seed, lights=False).world.model_dump(mode="json", exclude_defaults=True)
    w["robots"][0]["devices"] += [d if lidar_noise or d["device"] != "Lidar" else {**d, "noise": 0.0} for d in devices]
    for robot, more in shapes.items():
        w["robots"][robot]["shapes"] += more
    w["robots"][1]["recognition_colors"] = [[0.2, 0.2, 0.9]]
    return parse_world(w)


def _riders_single(seed: int, case: str, precision: str) -> Simulation:
    sim = Simulation(_riders_world(seed, case).world, precision=precision)
    for entry in RIDERS[case][2]:
        robot, name = _at(entry)
        dev = sim.device(f"{robot}/{name}")
        dev.enable(STEP)
        if name in RECOGNISING:
            dev.recognition_enable(STEP)
            dev.enable_segmentation(True)
    return sim


@pytest.mark.parametrize("precision", ["exact", "fast"])
@pytest.mark.parametrize("case", list(RIDERS))
def test_devices_riding_a_link_see_its_shapes_as_their_simulation_bit_for_bit(case, precision):
    """Devices riding the swing, which they see (its bar below them, the hand on the wrist beyond):
    distance sensors (generic, 3-ray, infra-red in a dome of its own, sonar), a light sensor, a noisy fixed and a rotating
    lidar; a noisy recognising camera and a range finder; a fixed and a noisy rotating lidar in domes
    of their own; a recognising camera (seeing the bar's side) and a range finder in domes of their own;
    planes on the swing and on the watcher's flag (PANELS), seen or not by both robots' devices. Three copies with their own random swings and wrists, copy 2 reset at step 110
    against a fresh Simulation, 200 steps: every reading (value, image, range image, recognised
    objects, segmentation image) the same bits as the copy's Simulation. (A distance sensor's hits on
    its own link are made from its mount, as the single simulation's: met from the world's frame
    instead, EXACT readings differ in the last bits; the sonar's echo and the housed camera's shading read
    the hit's normal, turned by the copy's link: unturned, the camera's images differ.) The sensors whose rays all meet the bar read one value throughout, the range
    finder's and the housed lidar's nearest ranges too (the bar, or the other lidar's dome, never its
    own); every other reading changes as the arm moves."""
    seeds = (3, 4, 5)
    n = len(seeds)
    names = RIDERS[case][2]
    batched = BatchedSimulation(_riders_world(seeds[0], case), n, precision=precision)
    batched.reset(np.arange(n), list(seeds))
    refs = {name: batched.device(*_at(name)) for name in names}

    def enable(copies=None):
        for name, ref in refs.items():
            batched.enable(ref, STEP, copies=copies)
            if name in RECOGNISING:
                batched.recognition_enable(ref, STEP, copies=copies)
                batched.enable_segmentation(ref, True, copies=copies)

    enable()
    singles = [_riders_single(s, case, precision) for s in seeds]
    arm = batched.slot("arm")
    rng = np.random.default_rng(11)
    readings: dict[str, set[bytes]] = {name: set() for name in names}
    nearest: dict[str, set[float]] = {name: set() for name in names}
    objects_seen = 0
    for t in range(200):
        if t == 110:
            batched.reset([2], [seeds[2]])
            enable([2])
            singles[2] = _riders_single(seeds[2], case, precision)
        if t % 40 == 0:
            for c in range(n):
                for robot, name, span in (("arm", "swing", math.pi), ("arm", "wrist", 1.2),
                                          ("watcher", "flag pan", math.pi)):
                    target = float(rng.uniform(-span, span))
                    _command(batched, singles, c, robot, name, target)
        _step_together(batched, singles, arm, t)
        for c, s in enumerate(singles):
            for name, ref in refs.items():
                got, want = _reading(batched, s, c, *_at(name))
                assert got == want, (t, c, name)
                readings[name].add(got)
                if ref.kind in ("Lidar", "RangeFinder") and t >= 20:   # (a rotating head swept once by then)
                    nearest[name].add(float(batched.range_image(ref)[c].min()))
                if name in RECOGNISING:
                    dev = s.device("{}/{}".format(*_at(name)))
                    objects = batched.recognition_objects(ref, c)
                    assert objects == dev.objects and repr(objects) == repr(dev.objects), (t, c)
                    assert batched.segmentation_image(ref)[c].tobytes() == dev.segmentation_image.tobytes(), (t, c)
                    objects_seen += len(objects)
    counts = {name: len(v) for name, v in readings.items()}
    assert all(counts[name] == 1 if name in STEADY else counts[name] > 10 for name in names), counts
    for name in ("tip rf", "housed", "housed rf"):   # the bar below it, or the other lidar's dome: never its own
        if name in nearest:
            assert len(nearest[name]) == 1 and min(nearest[name]) > 0.06, (name, nearest[name])
    assert "pixels" not in case or objects_seen > 0


def test_sensors_riding_a_link_read_its_shape_at_the_closed_form_distance_in_every_copy():
    """Whatever the swing, the bar's top face is TIP_BAR_DROP below the sensors riding it: the tip
    sensor's ray pitched down by TIP_DS_TILT meets it at TIP_BAR_DROP / sin(TIP_DS_TILT), and the tip
    lidar's lowest layer (pitched down by half its vertical field, 0.6; noise off) at TIP_BAR_DROP / sin(0.6),
    its nearest range (float32)."""
    batched = BatchedSimulation(_riders_world(3, "sensors", lidar_noise=False), 3, precision="exact")
    ds, lidar = batched.device("arm", "tip ds"), batched.device("arm", "tip lidar")
    batched.enable(ds, STEP)
    batched.enable(lidar, STEP)
    batched.joints.command(batched.slot("arm"), "swing", position=np.array([0.0, 1.0, -2.5]))
    batched.run(60)
    assert batched.value(ds) == pytest.approx([TIP_BAR_DROP / math.sin(TIP_DS_TILT)] * 3, abs=1e-12)
    assert batched.range_image(lidar).min(axis=(1, 2)) == pytest.approx([TIP_BAR_DROP / math.sin(0.6)] * 3, rel=1e-6)
