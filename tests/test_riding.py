"""What a robot carries on a joint is where the joint has put it for everything that looks at it
(README "Joints"): its lights (robot ``lights`` naming the joint in ``on_joint``, an LED's lights when
the LED rides on the joint) light light sensors and cameras from there, a camera's Recognition
reports its shapes there, a Radar finds them there.

Closed forms: a LightSensor at the origin facing +x, a white point light of intensity I and
attenuation 0 0 1 on its axis at distance D reads 1000 · I/D² (the default table); a light at
(0, -D, 0), 90 degrees off the sensor's axis, gives it nothing. A pan hinge (axis z through the
origin) turned by pi/2 carries (0, -D, 0) to (D, 0, 0)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, parse_world

DT_MS = 16
QUARTER = math.pi / 2
D = 2.0
I = 0.5
ON_AXIS = 1000.0 * I / D**2


def _pan(**fields) -> dict:
    # maxTorque 1e5 and maxVelocity 100: full speed at once, any target within 1.6 rad reached in one step
    return {"device": "RotationalMotor", "name": "pan", "max_velocity": 100.0, "max_torque": 1e5,
            "axis": [0, 0, 1], **fields}


def _slider(**fields) -> dict:
    return {"device": "LinearMotor", "name": "slide", "max_velocity": 100.0, "max_force": 1e5, "axis": [1, 0, 0],
            **fields}


def _point(location, **fields) -> dict:
    return {"type": "PointLight", "intensity": I, "attenuation": [0, 0, 1], "location": list(location), **fields}


def _spot(location, direction, **fields) -> dict:
    return {"type": "SpotLight", "intensity": I, "attenuation": [0, 0, 1], "location": list(location),
            "direction": list(direction), "beam_width": 0.3, "cut_off_angle": 0.4, **fields}


def _light_world(lights: list[dict], devices: list[dict] = (), **world) -> Simulation:
    """Robot "bot": a LightSensor at its origin facing +x, a pan hinge, ``lights`` and ``devices``."""
    return Simulation(parse_world({
        "world_info": {"basic_time_step": DT_MS, "contact": False}, **world,
        "robots": [{"name": "bot", "lights": lights,
                    "devices": [{"device": "LightSensor", "name": "ls"}, _pan(), *devices]}]}))


def _read(sim: Simulation) -> float:
    sim.device("bot/ls").enable(DT_MS)
    sim.step()
    return sim.device("bot/ls").value


@pytest.mark.parametrize("light, placed", [
    (_point((0, -D, 0), on_joint="pan"), _point((D, 0, 0))),
    (_spot((0, -D, 0), (0, 1, 0), on_joint="pan"), _spot((D, 0, 0), (-1, 0, 0))),
], ids=["point", "spot"])
def test_a_light_on_a_pan_joint_lights_the_sensor_as_a_light_placed_where_the_joint_turned_it(light, placed) -> None:
    """At q = 0 the light sits 90 degrees off the sensor's axis (a spot light aimed across it):
    nothing. Turned by pi/2 it sits at (D, 0, 0) facing the sensor: 1000 · I/D², as the same light
    placed there by the file; turned back, nothing again."""
    sim = _light_world([light])
    assert _read(sim) == 0.0
    sim.robot("bot").motor("pan").set_position(QUARTER)
    turned = _read(sim)
    static = _read(_light_world([placed]))
    assert static == pytest.approx(ON_AXIS, rel=1e-12)
    assert turned == pytest.approx(static, rel=1e-12)
    sim.robot("bot").motor("pan").set_position(0.0)
    assert _read(sim) == 0.0
    sim.robot("bot").motor("pan").set_position(QUARTER)
    assert _read(sim) == pytest.approx(static, rel=1e-12)
    sim.reset()                                    # the joint back at its initial position, the light with it
    assert _read(sim) == 0.0


def test_an_leds_lights_ride_on_the_leds_joint() -> None:
    """An LED at (0, -D, 0) on the pan joint holding a white point light, switched on: nothing at
    q = 0; at q = pi/2 the LED's light is at (D, 0, 0): 1000 · I/D²."""
    led = {"device": "LED", "name": "led", "color": [[1, 1, 1]], "pose": {"translation": [0, -D, 0]},
           "on_joint": "pan", "lights": [_point((0, 0, 0))]}
    sim = _light_world([], [led])
    sim.device("bot/led").set(1, 0)
    assert _read(sim) == 0.0
    sim.robot("bot").motor("pan").set_position(QUARTER)
    assert _read(sim) == pytest.approx(ON_AXIS, rel=1e-12)


def test_a_light_on_a_slider_moves_along_its_axis() -> None:
    """A point light at (D + 1, 0, 0) on a slider along x moved by -1: at D, 1000 · I/D² (before:
    1000 · I/(D + 1)²)."""
    sim = _light_world([_point((D + 1, 0, 0), on_joint="slide")], [_slider()])
    assert _read(sim) == pytest.approx(1000.0 * I / (D + 1) ** 2, rel=1e-12)
    sim.robot("bot").motor("slide").set_position(-1.0)
    assert _read(sim) == pytest.approx(ON_AXIS, rel=1e-12)


def _camera_world(light: dict) -> Simulation:
    """A grey wall at x = 2 (near face), a camera at the origin looking at it; robot "lamp" at
    (1, 0, 0) holds ``light`` on its pan joint (or fixed)."""
    return Simulation(parse_world({
        "world_info": {"basic_time_step": DT_MS, "contact": False},
        "solids": [{"name": "wall", "pose": {"translation": [2.05, 0, 0]}, "geometry": {"type": "box", "size": [0.1, 8, 8]},
                    "appearance": {"base_color": [0.8, 0.8, 0.8]}}],
        "robots": [{"name": "eye", "devices": [{"device": "Camera", "name": "cam", "width": 16, "height": 16,
                                                "field_of_view": 1.2}]},
                   {"name": "lamp", "pose": {"translation": [1, 0, 0]}, "lights": [light], "devices": [_pan()]}]}))


def _image(sim: Simulation) -> np.ndarray:
    sim.device("eye/cam").enable(DT_MS)
    sim.step()
    return np.asarray(sim.device("eye/cam").image, dtype=np.int64)


def test_a_camera_sees_a_light_on_a_joint_where_the_joint_turned_it() -> None:
    """Robot "lamp" holds a point light 0.5 m to its -y on its pan joint; turned by pi/2 it is 0.5 m
    ahead of the lamp (x = 1.5, 0.55 m from the wall): the camera's image is the image of the same
    light placed there by the file, and differs from the image before the turn."""
    sim = _camera_world(_point((0, -0.5, 0), on_joint="pan"))
    before = _image(sim)
    sim.robot("lamp").motor("pan").set_position(QUARTER)
    turned = _image(sim)
    static = _image(_camera_world(_point((0.5, 0, 0))))
    assert not np.array_equal(before, static)
    assert np.abs(turned - static).max() <= 1      # the turned place is (0.5, 3e-17, 0): the last bit may differ


@pytest.mark.parametrize("where, message", [
    ({"lights": [_point((0, 0, 0), on_joint="pan")]}, "lights[0].on_joint: only a robot's lights ride on its joints"),
    ({"led": [_point((0, 0, 0), on_joint="pan")]},
     "devices[2] (led).lights[0].on_joint: an LED's lights ride with the LED (give on_joint to the LED)"),
    ({"robot": [_point((0, 0, 0), on_joint="elbow")]}, "(bot).lights[0].on_joint: 'elbow' is not a joint motor"),
], ids=["world", "led", "unknown"])
def test_a_light_naming_a_joint_where_it_cannot_is_refused_in_one_line(where, message) -> None:
    led = {"device": "LED", "name": "led", "lights": where.get("led", [])}
    world = {"world_info": {"basic_time_step": DT_MS}, "lights": where.get("lights", []),
             "robots": [{"name": "bot", "lights": where.get("robot", []),
                         "devices": [{"device": "LightSensor", "name": "ls"}, _pan(), led]}]}
    with pytest.raises(WorldError) as err:
        parse_world(world)
    assert message in str(err.value)
    assert "Traceback" not in str(err.value)


def test_a_wbt_robots_light_past_a_joint_rides_on_it(tmp_path) -> None:
    """A .wbt robot: a LightSensor at its origin facing +x, a pan HingeJoint (axis 0 0 1 through the
    origin) whose end point at (0, -D, 0) holds a PointLight and an LED holding another (its colour
    white). Converted, the light and the LED ride on "pan" (the LED's light with the LED); turned by
    pi/2 both sit at (D, 0, 0): 2 · 1000 · I/D² once the LED is on."""
    from test_wbt_drives import write

    from sensorium.server.world.loader import load_world

    light = f"PointLight {{ intensity {I} attenuation 0 0 1 }}"
    robot = ('Robot { name "bot" children [ LightSensor { name "ls" }\n'
             ' HingeJoint { jointParameters HingeJointParameters { axis 0 0 1 }\n'
             '  device [ RotationalMotor { name "pan" maxVelocity 100 maxTorque 100000 } ]\n'
             f'  endPoint Solid {{ translation 0 {-D} 0 children [ {light}\n'
             f'    LED {{ name "led" color [ 1 1 1 ] children [ {light} ] }} ] }} }} ] }}\n')
    w = load_world(write(tmp_path, robot))
    bot = w.world.robots[0]
    assert [lt.on_joint for lt in bot.lights] == ["pan"]
    led = next(d for d in bot.devices if d.name == "led")
    assert led.on_joint == "pan" and [lt.on_joint for lt in led.lights] == [None]
    sim = Simulation(w)
    sim.device("bot/led").set(1, 0)
    assert _read(sim) == 0.0
    sim.robot("bot").motor("pan").set_position(QUARTER)
    assert _read(sim) == pytest.approx(2 * ON_AXIS, rel=1e-12)


def test_the_viewer_draws_a_light_on_a_joint_in_its_links_frame_which_the_joint_moves() -> None:
    """Recordings and the live viewer: the light is drawn in ``bot/pan/link`` (at its file place,
    that frame being the robot's moved by the joint), a frame that follows the joint: at q = pi/2
    it is the robot frame turned a quarter about z."""
    from sensorium.server.recording.frames import JointFrames, lights, link_frame

    world = parse_world({"world_info": {"basic_time_step": DT_MS}, "robots": [
        {"name": "bot", "lights": [_point((0, -D, 0), on_joint="pan", name="lamp")], "devices": [_pan()]}]}).world
    drawn = {entity: frame for entity, frame, _locked, _lt in lights(world)}
    assert drawn == {"light/lamp": link_frame("bot", "pan")}
    frames = JointFrames(world)
    assert frames.frames("bot") == {link_frame("bot", "pan")}
    [(frame, translation, quaternion)] = frames.update("bot", ["pan"], [QUARTER])
    assert frame == link_frame("bot", "pan") and translation == pytest.approx((0, 0, 0), abs=1e-15)
    assert quaternion == pytest.approx((0, 0, math.sin(QUARTER / 2), math.cos(QUARTER / 2)), abs=1e-15)


# ---------------------------------------------------------------- recognition and radar

def _target(shape_pose: list[float], size: list[float], joint: dict, **robot) -> dict:
    """Robot "arm" at (3, 0, 0) whose only shape, a box of ``size`` at ``shape_pose``, rides on ``joint``."""
    return {"name": "arm", "pose": {"translation": [3, 0, 0]}, "devices": [joint],
            "shapes": [{"geometry": {"type": "box", "size": size}, "pose": {"translation": shape_pose},
                        "on_joint": joint["name"]}], **robot}


def _seen(arm: dict) -> tuple[Simulation, object]:
    sim = Simulation(parse_world({
        "world_info": {"basic_time_step": DT_MS, "contact": False},
        "robots": [{"name": "eye", "devices": [{"device": "Camera", "name": "cam", "width": 64, "height": 48,
                                                "field_of_view": 1.0, "recognition": {}}]},
                   {**arm, "recognition_colors": [[1, 0, 0]]}]}))
    sim.device("eye/cam").recognition_enable(DT_MS)
    return sim, sim.device("eye/cam")


def _recognised(sim: Simulation, cam) -> object:
    sim.step()
    [obj] = cam.objects
    return obj


def test_a_recognised_robots_link_on_a_slider_that_moved_d_is_reported_d_further() -> None:
    """The camera at the origin looks along +x at "arm" (3 m ahead), whose 0.2 m cube rides on a
    slider along y: at rest it is reported at (3, 0, 0); moved by d = 0.5, at (3, 0.5, 0), its size
    (0.2, 0.2) and the robot's orientation unchanged, its box on the image moved left."""
    sim, cam = _seen(_target([0, 0, 0], [0.2, 0.2, 0.2], _slider(axis=[0, 1, 0])))
    before = _recognised(sim, cam)
    assert before.position == pytest.approx((3, 0, 0), abs=1e-12)
    sim.robot("arm").motor("slide").set_position(0.5)
    after = _recognised(sim, cam)
    assert after.position == pytest.approx((3, 0.5, 0), abs=1e-12)
    assert after.size == pytest.approx(before.size, abs=1e-12) == (0.2, 0.2)
    assert after.orientation == before.orientation
    assert after.position_on_image[0] < before.position_on_image[0]


def test_a_recognised_robots_link_turned_by_a_hinge_is_reported_where_and_as_wide_as_it_now_is() -> None:
    """"arm"'s 0.4 x 0.2 x 0.2 box centred 0.5 m to its -y, on a pan hinge through its origin: at rest
    at (3, -0.5, 0), 0.2 wide (its y extent); turned by pi/2 it lies across the view at (3.5, 0, 0),
    0.4 wide; the robot's orientation (its own, not the link's) unchanged."""
    sim, cam = _seen(_target([0, -0.5, 0], [0.4, 0.2, 0.2], _pan()))
    before = _recognised(sim, cam)
    assert before.position == pytest.approx((3, -0.5, 0), abs=1e-12)
    assert before.size == pytest.approx((0.2, 0.2), abs=1e-12)
    sim.robot("arm").motor("pan").set_position(QUARTER)
    after = _recognised(sim, cam)
    assert after.position == pytest.approx((3.5, 0, 0), abs=1e-12)
    assert after.size == pytest.approx((0.4, 0.2), abs=1e-12)
    assert after.orientation == before.orientation


def _radar_targets(arm: dict) -> tuple[Simulation, object]:
    sim = Simulation(parse_world({
        "world_info": {"basic_time_step": DT_MS, "contact": False},
        "robots": [{"name": "car", "devices": [{"device": "Radar", "name": "radar"}]},
                   {**arm, "pose": {"translation": [10, 0, 0]}, "radar_cross_section": 5.0}]}))
    sim.device("car/radar").enable(DT_MS)
    return sim, sim.device("car/radar")


def _distance(sim: Simulation, radar) -> float:
    sim.step()
    [target] = radar.targets
    return target.distance


@pytest.mark.parametrize("joint, shape_pose, motor, q, far", [
    (_slider(), [0, 0, 0], "slide", 1.5, 11.5),                        # moved 1.5 m away along the radar's axis
    (_pan(), [0, 3, 0], "pan", -QUARTER, 13.0),                        # (0, 3, 0) turned to (3, 0, 0)
], ids=["slider", "hinge"])
def test_a_radar_finds_a_targets_link_where_its_joint_put_it(joint, shape_pose, motor, q, far) -> None:
    """The radar at the origin looks along +x at robot "arm" 10 m ahead, whose only shape, a 0.2 m
    cube, rides on a joint: the distance is that of the cube's centre (Webots: of the target's box),
    10 (or sqrt(109), the cube 3 m to the side) at rest, ``far`` after the joint moved."""
    sim, radar = _radar_targets(_target(shape_pose, [0.2, 0.2, 0.2], joint))
    assert _distance(sim, radar) == pytest.approx(math.hypot(10.0, shape_pose[1]), abs=1e-12)
    sim.robot("arm").motor(motor).set_position(q)
    assert _distance(sim, radar) == pytest.approx(far, abs=1e-12)


def test_a_radar_target_solid_on_a_hinge_is_found_at_its_own_origin_where_the_hinge_put_it() -> None:
    """Robot "arm" 10 m ahead (no cross section of its own) carries a target solid on a pan hinge, its
    origin and 0.2 m cube 3 m to the left: at rest at distance sqrt(109), azimuth -atan(0.3) (left:
    negative, Webots' sign); turned by -pi/2 to (13, 0, 0): 13 m straight ahead."""
    arm = _target([0, 3, 0], [0.2, 0.2, 0.2], _pan())
    arm["radar_targets"] = [{"name": "tag", "pose": {"translation": [0, 3, 0]}, "on_joint": "pan",
                             "radar_cross_section": 1.0, "shapes": [0]}]
    sim = Simulation(parse_world({
        "world_info": {"basic_time_step": DT_MS, "contact": False},
        "robots": [{"name": "car", "devices": [{"device": "Radar", "name": "radar"}]},
                   {**arm, "pose": {"translation": [10, 0, 0]}}]}))
    radar = sim.device("car/radar")
    radar.enable(DT_MS)
    sim.step()
    [t] = radar.targets
    assert t.distance == pytest.approx(math.hypot(10.0, 3.0), abs=1e-12)
    assert t.azimuth == pytest.approx(-math.atan2(3.0, 10.0), abs=1e-12)
    sim.robot("arm").motor("pan").set_position(-QUARTER)
    sim.step()
    [t] = radar.targets
    assert t.distance == pytest.approx(13.0, abs=1e-12) and t.azimuth == pytest.approx(0.0, abs=1e-12)
