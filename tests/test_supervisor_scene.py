"""The Supervisor beyond poses: the scene tree (root, children, ids, DEF, parents, types), fields
by node kind (names, models, custom data, lights' fields), velocities from the kinematic drive and
lights switched and changed by a supervisor — through the sans-IO core on a real simulation and
through a live ``sensorium serve`` with a Webots-style Python supervisor controller
(tests/controllers/supervisor_scene.py). Every number against the closed forms that
tests/worlds/supervisor_scene.yaml explains."""

from __future__ import annotations

import json
import math
import re
import sys

import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world, parse_world

WORLD = REPO / "tests" / "worlds" / "supervisor_scene.yaml"
DT = 0.016
V, W = 0.05 * (2.0 + 4.0) / 2, 0.05 * (4.0 - 2.0) / 0.2        # 0.15 m/s, 0.5 rad/s


def _live() -> Live:
    lv = Live(Simulation(load_world(WORLD)))
    lv.ok(A, "attach", {"robot": "judge"})
    return lv


def judge(lv: Live, item: str, args: dict | None = None):
    return lv.ok(A, f"/judge/robot/{item}", args)


def test_root_children_ids_defs_and_parents():
    lv = _live()
    assert judge(lv, "get_root") == {"node": 0, "type": "Group", "name": "", "def_name": "", "parent": -1, "proto": ""}
    children = judge(lv, "get_field", {"node": 0, "field": "children"})
    # Webots' WorldInfo and Viewpoint first (a YAML world's defaults: ids after its own nodes), then the
    # robots, solids and lights
    assert children == {"type": "MFNode", "value": [6, 7, 1, 2, 3, 4, 5]}
    nodes = [judge(lv, "get_from_id", {"id": i}) for i in children["value"]]
    assert [(n["type"], n["name"], n["def_name"], n["parent"]) for n in nodes] == [
        ("WorldInfo", "", "", 0), ("Viewpoint", "", "", 0),
        ("Robot", "judge", "JUDGE", 0), ("Robot", "runner", "", 0), ("Solid", "crate", "CRATE", 0),
        ("PointLight", "lamp", "", 0), ("DirectionalLight", "sun", "", 0)]
    assert judge(lv, "get_from_id", {"id": 0})["type"] == "Group"
    assert judge(lv, "get_from_id", {"id": 8}) == {"node": 0, "type": "", "name": "", "def_name": "", "parent": -1, "proto": ""}
    assert judge(lv, "get_from_def", {"name": "CRATE"})["node"] == 3
    assert judge(lv, "get_from_def", {"name": "sun"})["node"] == 5     # a light by its world-file name
    assert judge(lv, "get_self")["def_name"] == "JUDGE"
    lv.err(A, "/judge/robot/get_from_id", {"id": -1}, ErrorCode.INVALID_ARGUMENT)


def test_fields_by_node_kind_and_their_types():
    lv = _live()

    def field(node, name):
        return judge(lv, "get_field", {"node": node, "field": name})

    assert field(1, "name") == {"type": "SFString", "value": "judge"}
    assert field(1, "customData") == {"type": "SFString", "value": "team=red"}
    assert field(1, "model") == {"type": "SFString", "value": "referee"}
    assert field(1, "supervisor") == {"type": "SFBool", "value": True}
    assert field(2, "controller") == {"type": "SFString", "value": "<none>"}
    assert field(3, "model") == {"type": "SFString", "value": "WoodenBox"}
    assert field(3, "translation") == {"type": "SFVec3f", "value": [5.0, 5.0, 0.1]}
    assert field(4, "intensity") == {"type": "SFFloat", "value": 3.0}
    assert field(4, "on") == {"type": "SFBool", "value": True}
    assert field(4, "color") == {"type": "SFColor", "value": [1.0, 1.0, 1.0]}
    assert field(4, "location") == {"type": "SFVec3f", "value": [2.0, 0.0, 0.5]}
    assert field(5, "direction") == {"type": "SFVec3f", "value": [0.0, 0.0, -1.0]}
    assert field(5, "on") == {"type": "SFBool", "value": False}
    for node, name in ((5, "location"), (4, "direction"), (0, "translation"), (4, "name"), (3, "customData")):
        got = field(node, name)                                                # not a field of that node kind
        assert (got["type"], got["value"]) == ("", []), (node, name)
        assert got.get("absent", False) == (name in ("translation", "name")), (node, name)   # the root's, a light's
    # wrong value types and read-only fields: one line naming the field, nothing changes
    bad = [({"node": 4, "field": "on", "value": 1.0}, "SFBool"),
           ({"node": 4, "field": "intensity", "value": True}, "SFFloat"),
           ({"node": 4, "field": "color", "value": [1.0, 0.5]}, "SFColor"),
           ({"node": 4, "field": "color", "value": [1.0, 0.5, 2.0]}, "[0, 1]"),
           ({"node": 4, "field": "attenuation", "value": [0.0, 0.0, 0.0]}, "attenuation"),
           ({"node": 4, "field": "intensity", "value": -1.0}, ">= 0"),
           ({"node": 4, "field": "location", "value": [1e6, 0.0, 0.0]}, "100000"),
           ({"node": 5, "field": "direction", "value": [0.0, 0.0, 0.0]}, "direction"),
           ({"node": 5, "field": "location", "value": [0.0, 0.0, 0.0]}, "no field 'location'"),
           ({"node": 1, "field": "name", "value": [0.0, 0.0, 0.0]}, "read-only"),
           ({"node": 0, "field": "children", "value": [0.0, 0.0, 0.0]}, "read-only")]
    for args, words in bad:
        assert words in lv.err(A, "/judge/robot/set_field", args, ErrorCode.INVALID_ARGUMENT), args
    assert field(4, "intensity")["value"] == 3.0 and field(4, "attenuation")["value"] == [1.0, 0.0, 0.0]


def test_light_fields_change_light_sensor_readings_at_the_next_step_and_reset_restores_them():
    lv = _live()
    eye = lv.sim.device("judge/eye")
    eye.enable(16)

    def reading() -> float:
        lv.step(A, "judge", {"duration": 16})
        return eye.value

    assert reading() == pytest.approx(3.0, rel=1e-12)                       # I x 1 / 1 (white, no ambient)
    judge(lv, "set_field", {"node": 4, "field": "on", "value": False})
    assert reading() == 0.0                                                 # an off light adds nothing
    judge(lv, "set_field", {"node": 4, "field": "on", "value": True})
    judge(lv, "set_field", {"node": 4, "field": "attenuation", "value": [0.0, 0.0, 1.0]})
    judge(lv, "set_field", {"node": 4, "field": "intensity", "value": 8.0})
    assert reading() == pytest.approx(8.0 / 4.0, rel=1e-12)                 # 1 / d^2, d = 2 m
    judge(lv, "set_field", {"node": 4, "field": "color", "value": [1.0, 0.0, 0.0]})
    assert reading() == pytest.approx(8.0 / 4.0 / 3.0, rel=1e-12)           # one channel of three
    judge(lv, "set_field", {"node": 4, "field": "location", "value": [-2.0, 0.0, 0.5]})
    assert reading() == 0.0                                                 # behind the sensor: no direct term
    judge(lv, "set_field", {"node": 5, "field": "on", "value": True})       # the sun shines straight down
    judge(lv, "set_field", {"node": 5, "field": "direction", "value": [-1.0, 0.0, 0.0]})
    assert reading() == pytest.approx(0.5, rel=1e-12)                       # now along -x: into the sensor
    judge(lv, "simulation_reset")
    assert judge(lv, "get_field", {"node": 4, "field": "intensity"})["value"] == 3.0
    assert judge(lv, "get_field", {"node": 5, "field": "on"})["value"] is False
    assert reading() == pytest.approx(3.0, rel=1e-12)


def test_velocity_of_a_robot_driving_a_circle_and_of_static_nodes():
    lv = _live()
    motors = {"left wheel motor": {"position": math.inf, "velocity": 2.0},
              "right wheel motor": {"position": math.inf, "velocity": 4.0}}
    assert judge(lv, "get_node_velocity", {"node": 1}) == {"value": [0.0] * 6}   # not moved yet
    lv.step(A, "judge", {"duration": 16, "motors": motors})
    for k in range(2, 41):
        lv.step(A, "judge", {"duration": 16})
        yaw = W * DT * k
        vel = judge(lv, "get_node_velocity", {"node": 1})["value"]
        assert vel == pytest.approx([V * math.cos(yaw), V * math.sin(yaw), 0.0, 0.0, 0.0, W], abs=1e-12)
    # the position moves along the circle of radius V / W about (0, 0.3): the velocity is its tangent
    x, y, _ = judge(lv, "get_node_pose", {"node": 1})["position"]
    assert math.hypot(x, y - V / W) == pytest.approx(V / W, abs=1e-12)
    for node in (0, 2, 3, 4):                                                # root, idle robot, solid, light
        assert judge(lv, "get_node_velocity", {"node": node}) == {"value": [0.0] * 6}
    assert all(math.isnan(v) for v in judge(lv, "get_node_pose", {"node": 4})["position"])   # not a Transform
    judge(lv, "set_field", {"node": 1, "field": "translation", "value": [0.0, 0.0, 0.5]})
    assert judge(lv, "get_node_velocity", {"node": 1}) == {"value": [0.0] * 6}   # a supervisor move: no motion


def test_velocity_in_a_nue_world_is_in_world_axes():
    data = load_world(WORLD).world.model_dump()
    data["world_info"]["coordinate_system"] = "NUE"
    data["robots"][0]["pose"] = {"translation": [0.0, 0.5, 0.0]}
    sim = Simulation(parse_world(data))
    r = sim.robot("judge")
    for name, speed in (("left wheel motor", 2.0), ("right wheel motor", 4.0)):
        r.motor(name).set_position(math.inf)
        r.motor(name).set_velocity(speed)
    sim.step()
    # NUE: x north, y up, z east; the robot faces north (+x) and turns left (about +y), towards west (-z)
    assert r.drive.velocity() == pytest.approx([V * math.cos(W * DT), 0.0, -V * math.sin(W * DT), 0.0, W, 0.0],
                                               abs=1e-12)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_controller_walks_the_tree_switches_a_light_and_reads_velocities(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "supervisor_scene.py", "judge")
    out = {d["tag"]: d for d in (json.loads(line) for line in ctl.out)}
    tree, lights, vel = out["tree"], out["lights"], out["velocity"]
    assert tree["root"] == [0, "Group", True, True] and tree["count"] == 7 and tree["last"] == "DirectionalLight"
    nodes = [(n["id"], n["type"], n["base"], n["def"], n["name"], n["parent"], n["is_robot"]) for n in tree["nodes"]]
    assert nodes == [        # Webots' WorldInfo and Viewpoint first (a YAML world's defaults), no name field
        (6, "WorldInfo", "WorldInfo", "", None, 0, False), (7, "Viewpoint", "Viewpoint", "", None, 0, False),
        (1, "Robot", "Robot", "JUDGE", "judge", 0, True), (2, "Robot", "Robot", "", "runner", 0, True),
        (3, "Solid", "Solid", "CRATE", "crate", 0, False), (4, "PointLight", "PointLight", "", None, 0, False),
        (5, "DirectionalLight", "DirectionalLight", "", None, 0, False)]       # lights have no name field (Webots)
    assert tree["me"] == [1, "JUDGE", True, True] and tree["custom"] == "team=red" and tree["model"] == "referee"
    assert tree["crate_model"] == "WoodenBox" and tree["missing"] == [True, True, True, True]
    assert tree["supervisor_field"] is True
    assert lights["types"] == ["PointLight", "SFBool", True]
    assert lights["values"] == pytest.approx([3.0, 0.0, 8.0 / 4.0], rel=1e-12)
    assert lights["read"] == [True, 8.0, [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]
    assert lights["wrong"] is False
    assert lights["position"] == [None, None, None] or all(v != v for v in lights["position"])   # NaN (json)
    yaw = W * DT * vel["steps"]
    assert vel["velocity"] == pytest.approx([V * math.cos(yaw), V * math.sin(yaw), 0, 0, 0, W], abs=1e-12)
    assert vel["heading"] == pytest.approx([0, 0, 1, yaw], abs=1e-12)
    yaw += W * DT
    assert vel["after_reset"] == pytest.approx([V * math.cos(yaw), V * math.sin(yaw), 0, 0, 0, W], abs=1e-12)
    assert vel["crate"] == [0.0] * 6 and vel["runner"] == [0.0] * 6
    err = ctl.stderr()
    assert "wb_supervisor_field_get_sf_bool() called with wrong field type: SFFloat." in err
    assert "no field 'mass'" in err and "out-of-bound index: 7" in err


def test_a_camera_sees_a_light_switched_and_recoloured_at_its_next_image():
    data = load_world(WORLD).world.model_dump()
    data["solids"].append({"name": "wall", "pose": {"translation": [3.0, 0.0, 0.5]},
                           "geometry": {"type": "box", "size": [0.1, 4.0, 2.0]}})     # lit by the lamp at x = 2
    data["robots"][0]["devices"].append({"device": "Camera", "name": "cam", "width": 8, "height": 8})
    lv = Live(Simulation(parse_world(data)))
    lv.ok(A, "attach", {"robot": "judge"})
    cam = lv.sim.device("judge/cam")
    cam.enable(16)

    def centre() -> list[int]:
        lv.step(A, "judge", {"duration": 16})
        return [int(v) for v in cam.image[4, 4]]          # BGRA

    b, g, r, a = centre()
    assert b == g == r > 0 and a == 255                  # a white light on a white wall
    judge(lv, "set_field", {"node": 5, "field": "on", "value": False})    # after the wall (4), the lamp is 5
    assert lv.sim.scene.top_lights()[0].on is False
    assert centre() == [0, 0, 0, 255]                    # no light on, no ambient: black
    judge(lv, "set_field", {"node": 5, "field": "on", "value": True})
    judge(lv, "set_field", {"node": 5, "field": "color", "value": [0.0, 1.0, 0.0]})
    assert centre() == [0, g, 0, 255]                    # the green channel of the white light's image


def test_velocity_of_a_car_on_its_ackermann_circle():
    """A car (tests/worlds/car.yaml) with its front wheels at Webots' Ackermann angles for δ = 0.2
    (positive right) and its rear wheels at 5 rad/s: v = r_rear·ω along its heading, turning right at
    v·tan δ / L (the steering settles within the first step)."""
    sim = Simulation(load_world(REPO / "tests" / "worlds" / "car.yaml"))
    car = sim.robot("car")
    delta, wheelbase, track, radius = 0.2, 2.6, 1.5, 0.35
    cot = 1.0 / math.tan(delta)
    car.motor("right_steer").set_position(math.atan(1.0 / (cot - track / (2 * wheelbase))))
    car.motor("left_steer").set_position(math.atan(1.0 / (cot + track / (2 * wheelbase))))
    for wheel in ("right_rear_wheel", "left_rear_wheel"):
        car.motor(wheel).set_position(math.inf)
        car.motor(wheel).set_velocity(5.0)
    v = radius * 5.0
    w = -v * math.tan(delta) / wheelbase
    for k in range(1, 31):
        sim.step()
        yaw = w * DT * k
        assert car.drive.velocity() == pytest.approx([v * math.cos(yaw), v * math.sin(yaw), 0, 0, 0, w], abs=1e-12)


def test_a_robot_stopped_by_kinematic_contact_has_no_linear_velocity():
    """tests/worlds/webots_api.yaml: the pioneer drives at 0.5 m/s into the wall and stops with its
    0.2 m body at x = 1.7 (the wall's face at 1.9); pressing on, its velocity is its displacement: 0."""
    lv = Live()
    lv.ok(A, "attach", {"robot": "pioneer"})
    motors = {m: {"position": math.inf, "velocity": 5.0} for m in ("left wheel motor", "right wheel motor")}
    lv.step(A, "pioneer", {"duration": 32, "motors": motors})
    assert lv.ok(A, "/pioneer/robot/get_node_velocity", {"node": 1})["value"] == [0.5, 0.0, 0.0, 0.0, 0.0, 0.0]
    for _ in range(150):
        lv.step(A, "pioneer", {"duration": 32})
    assert lv.sim.robot("pioneer").pose.translation[0] == pytest.approx(1.7, abs=1e-9)
    assert lv.ok(A, "/pioneer/robot/get_node_velocity", {"node": 1})["value"] == [0.0] * 6


def test_a_wbt_light_is_found_by_its_def_and_switched_through_it(tmp_path):
    """A .wbt world's top-level light keeps its DEF (getFromDef finds it, as in Webots); a DEF
    already taken by an earlier node stays with that node. The LightSensor facing the lamp at 2 m
    (attenuation 1 0 0, intensity 3) reads 3, then 0 once the lamp found by DEF is switched off."""
    path = tmp_path / "lamp.wbt"
    path.write_text(
        "#VRML_SIM R2023b utf8\n"
        "DEF LAMP PointLight { location 2 0 0.5 intensity 3 attenuation 1 0 0 }\n"
        "DEF SUN DirectionalLight { direction 0 0 -1 on FALSE }\n"
        "DEF JUDGE Robot { translation 0 0 0.5 name \"judge\" supervisor TRUE controller \"<extern>\"\n"
        "  children [ LightSensor { name \"eye\" lookupTable [ 0 0 0, 100 100 0 ] } ] }\n"
        "DEF LAMP Solid { translation 5 5 0 name \"second\" }\n")
    lv = Live(Simulation(load_world(path)))
    lv.ok(A, "attach", {"robot": "judge"})
    lamp = judge(lv, "get_from_def", {"name": "LAMP"})
    assert (lamp["type"], lamp["def_name"]) == ("PointLight", "LAMP")
    assert judge(lv, "get_from_def", {"name": "SUN"})["type"] == "DirectionalLight"
    assert judge(lv, "get_from_def", {"name": "second"})["def_name"] == ""   # the DEF stayed with the lamp
    eye = lv.sim.device("judge/eye")
    eye.enable(16)
    lv.step(A, "judge", {"duration": 16})
    assert eye.value == pytest.approx(3.0, rel=1e-12)
    judge(lv, "set_field", {"node": lamp["node"], "field": "on", "value": False})
    lv.step(A, "judge", {"duration": 16})
    assert eye.value == 0.0


@pytest.mark.parametrize(("field", "attr", "value"), [("intensity", "intensity", -0.5),
                                                      ("ambientIntensity", "ambient_intensity", 1.5),
                                                      ("ambientIntensity", "ambient_intensity", -0.1),
                                                      ("cutOffAngle", "cut_off_angle", 1.6),
                                                      ("beamWidth", "beam_width", -0.2),
                                                      ("color", "color", [0.0, 1.2, 0.0])])
def test_a_light_setter_refuses_what_the_world_file_flags_with_the_same_words(field, attr, value):
    """One table of Webots' ranges (world.LIGHT_RANGES): the Supervisor's setter refuses a value outside
    with the words the loader's warning (or the file's error) uses, and the light keeps its value. (A
    file's beam_width above pi/2 is above its cut-off: lowered to it, as Webots; a negative radius is
    the schema's own error: both refused by the setter too, test_a_light_setter_refuses_the_rest.)"""
    from sensorium.server.daemon import supervisor
    from sensorium.server.world.loader import WorldError

    spot = {"type": "SpotLight", "name": "spot", "location": [0, 0, 1], "cut_off_angle": 1.0, "beam_width": 0.5}
    sim = Simulation(parse_world({"lights": [spot]}))
    node = supervisor.find_node(sim, "spot")
    with pytest.raises(ValueError) as refused:
        supervisor.set_field(sim, node, field, value)
    try:
        said = parse_world({"lights": [{**spot, attr: value}]}).warnings
    except WorldError as exc:
        said = [str(exc)]
    words = str(refused.value).removeprefix(f"SpotLight {attr}: ")
    assert words.startswith(("must be", "colour components")) and any(words in line for line in said), (words, said)
    assert supervisor.get_field(sim, node, field)["value"] == {"cut_off_angle": 1.0, "beam_width": 0.5}.get(
        attr, {"intensity": 1.0, "ambient_intensity": 0.0, "radius": 100.0, "color": [1.0, 1.0, 1.0]}.get(attr))


def test_a_light_setter_refuses_the_rest_of_webots_ranges():
    from sensorium.server.daemon import supervisor

    sim = Simulation(parse_world({"lights": [{"type": "SpotLight", "name": "spot", "location": [0, 0, 1]}]}))
    node = supervisor.find_node(sim, "spot")
    for field, value, words in (("beamWidth", 1.6, "beam_width: must be within [0, pi/2], got 1.6"),
                                ("radius", -1.0, "radius: must be >= 0, got -1.0")):
        with pytest.raises(ValueError, match=re.escape(words)):
            supervisor.set_field(sim, node, field, value)
    supervisor.set_field(sim, node, "cutOffAngle", math.pi / 2)     # the bounds themselves are taken
    supervisor.set_field(sim, node, "beamWidth", math.pi / 2)
    supervisor.set_field(sim, node, "cutOffAngle", 0.0)
    assert supervisor.get_field(sim, node, "cutOffAngle")["value"] == 0.0


def test_a_spotlights_cut_off_below_its_beam_width_lowers_the_beam_and_a_beam_above_the_cut_off_is_refused():
    """WbSpotLight: a cutOffAngle set below the beamWidth lowers the beam width to it (silently); a
    beamWidth set above the cutOffAngle is reset by Webots with a warning, refused here (one line) as
    every value outside Webots' ranges. The world file's zero-direction error keeps its own words."""
    from sensorium.server.daemon import supervisor

    sim = Simulation(parse_world({"lights": [{"type": "SpotLight", "name": "spot", "location": [0, 0, 1],
                                              "cut_off_angle": 1.0, "beam_width": 0.5}]}))
    node = supervisor.find_node(sim, "spot")
    supervisor.set_field(sim, node, "cutOffAngle", 0.25)
    assert [supervisor.get_field(sim, node, f)["value"] for f in ("cutOffAngle", "beamWidth")] == [0.25, 0.25]
    with pytest.raises(ValueError, match=re.escape("SpotLight beam_width: must be <= cut_off_angle (0.25), got 0.3")):
        supervisor.set_field(sim, node, "beamWidth", 0.3)
    assert supervisor.get_field(sim, node, "beamWidth")["value"] == 0.25
    with pytest.raises(ValueError) as refused:
        supervisor.set_field(sim, node, "direction", [0.0, 0.0, 0.0])
    assert str(refused.value) == "SpotLight direction: direction must not be the zero vector"



def _pose_checks(position: list[float], orientation: list[float], me: list[float], crate_from_me: list[float],
                 me_from_lamp: list[float], crate_from_root: list[float], lamp: list[float]) -> None:
    """Webots' getPose: [R | t; 0 0 0 1] row-major in the world; seen from another node, that node's
    inverse transform first; from a light or the root (no Pose): the world's frame; NaN for a light."""
    r = [orientation[0:3], orientation[3:6], orientation[6:9]]
    assert me == [*r[0], position[0], *r[1], position[1], *r[2], position[2], 0.0, 0.0, 0.0, 1.0]
    assert me_from_lamp == me
    assert crate_from_root == [1, 0, 0, 5.0, 0, 1, 0, 5.0, 0, 0, 1, 0.1, 0, 0, 0, 1]
    d = [5.0 - position[0], 5.0 - position[1], 0.1 - position[2]]
    want = []
    for i in range(3):
        want += [r[0][i], r[1][i], r[2][i], sum(r[k][i] * d[k] for k in range(3))]
    assert crate_from_me == pytest.approx(want + [0, 0, 0, 1], abs=1e-12)
    assert all(math.isnan(v) for v in lamp) and len(lamp) == 16


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_supervisor_reads_poses_with_get_pose(tmp_path):
    """Node.getPose (wb_supervisor_node_get_pose), which Webots' own controllers use for relative
    poses: served from the nodes' positions and orientations, not Webots' "no value"."""
    ctl = run_paused(WORLD, tmp_path, "supervisor_scene.py", "judge")
    pose = {d["tag"]: d for d in (json.loads(line) for line in ctl.out)}["pose"]
    assert pose["position"][2] == pytest.approx(0.5) and abs(pose["orientation"][1]) > 0.1     # it has turned
    _pose_checks(pose["position"], pose["orientation"], pose["me"], pose["crate_from_me"], pose["me_from_lamp"],
                 pose["crate_from_root"], pose["lamp"])
    assert "not served" not in ctl.stderr()
