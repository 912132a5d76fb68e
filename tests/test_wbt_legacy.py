"""Worlds of Webots R2020b–R2021b (y-up geometries and devices) load as Webots R2022a+ loads them:
its backward-compatibility pass (``WbNodeUtilities::fixBackwardCompatibility``) turns a Cylinder's
Transform by Rx(-pi/2), a Camera by Rx(-pi/2)·Rz(pi/2) with its other children moved into a Transform
turning them back, and leaves a geometry whose parent holds other nodes as written (with a warning).
Our own worlds, checked against closed forms; what Webots' sort order or PROTO files decide is refused."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.wbt.legacy import _matrix
from sensorium.server.world.wbt.parser import read_wbt

NUE = 'WorldInfo { coordinateSystem "NUE" basicTimeStep 16 }\n'


def _write(tmp_path: Path, body: str, version: str = "R2021b") -> Path:
    p = tmp_path / f"{version}.wbt"
    p.write_text(f"#VRML_SIM {version} utf8\n{NUE}{body}")
    return p


_PILLAR = """Solid { children [ Transform { children [ Shape { geometry Cylinder { radius 0.1 height 1 } } ] } ]
  boundingObject Transform { children [ Cylinder { radius 0.1 height 1 } ] } }
Robot { translation -1 0.45 0 name "r" controller "<extern>"
  children [ DistanceSensor { name "d" lookupTable [ 0 0 0, 2 2000 0 ] } ] }
"""


def test_a_cylinder_stands_along_y_as_it_did_and_a_ray_meets_it_where_the_geometry_says(tmp_path: Path) -> None:
    """The pillar (radius 0.1, height 1 along y in R2021b) is turned to stand along y again: a distance
    sensor 0.45 above its middle, 1 m west, looking east (+x, a DistanceSensor's axis in both
    conventions: not turned) meets its side 0.9 m away. Lying along z (the R2022a reading of the same
    text) it would be missed."""
    loaded = load_world(_write(tmp_path, _PILLAR))
    assert loaded.report.warnings[0].endswith("Webots R2021b world: converted as Webots R2022a and later convert it "
                                              "when they open it (2 node(s) turned, 0 PROTO instance(s) met; Webots "
                                              "warns that parts may end up upside down)")
    sim = Simulation(loaded)
    d = sim.device("r/d")
    d.enable(16)
    sim.step()
    assert d.value == pytest.approx(1000 * 0.9, abs=1e-9)
    # the same text read as an R2023b world: the cylinder along z, the ray passes above it
    sim = Simulation(load_world(_write(tmp_path, _PILLAR, "R2023b")))
    d = sim.device("r/d")
    d.enable(16)
    sim.step()
    assert d.value == 2000


_RED_AHEAD = """Background { skyColor [ 0 0 1 ] }
Solid { translation 0 0 -2 children [ Shape { appearance Appearance { material Material { emissiveColor 1 0 0 } }
  geometry Box { size 1 1 1 } } ] }
Robot { name "r" controller "<extern>"
  children [ Camera { name "cam" width 3 height 3 children [ Shape { geometry Box { size 0.01 0.01 0.01 } }
    DistanceSensor { name "ds" translation 0 0.1 0 } ] } ] }
Viewpoint { orientation 0 1 0 0 position 0 0 5 }
"""


def test_a_camera_looks_along_minus_z_with_y_up_as_it_did(tmp_path: Path) -> None:
    """An R2021b camera looks along its -z, its up its y. Turned by Rx(-pi/2)·Rz(pi/2), its new view
    axis (+x) is world -z and its up (+z) world +y; the red box 2 m along -z fills its view (BGRA). Its
    Shape child is moved into a Transform turning it back, so it stays where it was."""
    p = _write(tmp_path, _RED_AHEAD)
    loaded = load_world(p)
    cam, ds = sorted(loaded.world.robots[0].devices, key=lambda d: d.name)
    m = np.array(_matrix(tuple(cam.pose.rotation)))
    assert np.abs(m @ [1, 0, 0] - [0, 0, -1]).max() <= 1e-15
    assert np.abs(m @ [0, 0, 1] - [0, 1, 0]).max() <= 1e-15
    # a pose child takes the inverse turn: the distance sensor stays 0.1 above, looking along +x
    assert ds.name == "ds" and np.abs(np.array(ds.pose.translation) - [0, 0.1, 0]).max() <= 1e-15
    assert ds.pose.rotation is None or np.abs(np.array(_matrix(tuple(ds.pose.rotation))) - np.eye(3)).max() <= 1e-15
    # the Viewpoint (A1): its orientation post-turned by the same Rx(-pi/2)·Rz(pi/2)
    (view,) = [n for n in read_wbt(p).nodes if n.type == "Viewpoint"]
    assert np.abs(np.array(_matrix(view.fields["orientation"])) - [[0, -1, 0], [0, 0, 1], [-1, 0, 0]]).max() <= 1e-15
    sim = Simulation(loaded)
    c = sim.device("r/cam")
    c.enable(16)
    sim.step()
    image = np.asarray(c.image)
    assert (image[..., 2] > 150).all() and (image[..., 0] == 0).all()     # red everywhere, no sky
    sim = Simulation(load_world(_write(tmp_path, _RED_AHEAD, "R2023b")))   # not turned: along +x, the sky
    c = sim.device("r/cam")
    c.enable(16)
    sim.step()
    assert (np.asarray(c.image)[..., 0] == 255).all()


R = 0.025
L = 0.1


def _wheel(side: str, x: float) -> str:
    # an R2021b wheel: its cylinder (along its y) laid along the hinge axis x by a Transform turned about z
    lay = "rotation 0 0 1 1.5707963267948966"
    return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 1 0 0 anchor {x} {R} 0 }}\n'
            f'  device [ RotationalMotor {{ name "{side} wheel motor" maxVelocity 10 }} ]\n'
            f'  endPoint Solid {{ translation {x} {R} 0 name "{side} wheel"\n'
            f'    children [ Transform {{ {lay} children [ Shape {{ geometry Cylinder {{ radius {R} height 0.01 }} }} ] }} ]\n'
            f'    boundingObject Transform {{ {lay} children [ Cylinder {{ radius {R} height 0.01 }} ] }}\n'
            '    physics Physics { } } }\n')


def test_a_y_up_robot_drives_along_its_z_by_v_t(tmp_path: Path) -> None:
    """A y-up two-wheel robot (wheels about its x, their cylinders' Transforms turned by B1 so they lie
    along x again, as written for R2021b) drives along its forward x × y = +z: both wheels at 4 rad/s for 50 steps move it
    by exactly 4·R·t, its height kept."""
    body = (f'Robot {{ translation 0 0 0 name "bot" controller "<extern>"\n  children [\n{_wheel("left", L / 2)}'
            f'{_wheel("right", -L / 2)} ]\n  boundingObject Transform {{ translation 0 0.05 0 children [ Box {{ size 0.08 0.04 0.06 }} ] }}\n'
            '  physics Physics { } }\n')
    p = _write(tmp_path, body)
    # each wheel's Transform, Rz(pi/2) as written, post-turned by Rx(-pi/2): its cylinder's axis (z) along -x
    (robot,) = [n for n in read_wbt(p).nodes if n.type == "Robot"]
    for joint in robot.fields["children"]:
        for lay in (joint.fields["endPoint"].fields["children"][0], joint.fields["endPoint"].fields["boundingObject"]):
            assert np.abs(np.array(_matrix(lay.fields["rotation"])) @ [0, 0, 1] - [-1, 0, 0]).max() <= 1e-15
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = load_world(p)
    wheel = loaded.world.robots[0]
    d = wheel.differential_drive
    assert d is not None and tuple(d.forward) == (0.0, 0.0, 1.0) and (d.axle_length, d.wheel_radius) == (L, R)
    sim = Simulation(loaded, precision="exact")
    for name in ("left wheel motor", "right wheel motor"):
        m = sim.robot("bot").motor(name)
        m.set_position(math.inf)
        m.set_velocity(4.0)
    sim.run(50)
    t = 50 * 0.016
    assert np.abs(sim.robot("bot").pose.translation - [0.0, 0.0, 4.0 * R * t]).max() <= 1e-9


def test_a_cylinder_whose_parent_holds_more_stays_as_written_with_webots_warning(tmp_path: Path) -> None:
    """B1 turns only a parent holding the geometry alone: a Solid with a Shape and a boundingObject
    keeps its cylinder along z, as Webots leaves it, and says so."""
    body = 'Solid { children [ Shape { geometry Cylinder { } } ] boundingObject Box { } }\n'
    p = _write(tmp_path, body)
    loaded = load_world(p)
    said = [w for w in loaded.report.warnings if "Cylinder: Webots' conversion" in w]
    assert len(said) == 1 and said[0].startswith(f"{p}:3:37: Cylinder: "), loaded.report.warnings
    assert "converted as Webots R2022a" in loaded.report.warnings[0]


def test_a_turned_devices_group_bounding_object_becomes_its_first_other_node_turned_back(tmp_path: Path) -> None:
    """Webots hands a turned device its boundingObject Group's nodes, sorted geometries first: poses are
    turned back inside the Group until the first other node, which, in a new Transform turning it back,
    replaces the Group. So [Transform, Box 0.2] gives Transform(Fᵀ){Box 0.2}, the Transform dropped; a
    Group of poses alone stays, each pose turned back: (0, 0.1, 0) → Fᵀ·(0, 0.1, 0) = (0, 0, 0.1)."""
    back = np.array([[0, -1, 0], [0, 0, 1], [-1, 0, 0]]).T       # F = Rx(-pi/2)·Rz(pi/2), transposed
    body = ('Robot { children [ Camera { name "a" boundingObject Group { children [\n'
            '  Transform { translation 0 0.1 0 children [ Box { size 0.1 0.1 0.1 } ] } Box { size 0.2 0.2 0.2 } ] } }\n'
            '  Camera { name "b" boundingObject Group { children [ Transform { translation 0 0.1 0 children [ Box { } ] } ] } } ] }\n')
    (robot,) = [n for n in read_wbt(_write(tmp_path, body)).nodes if n.type == "Robot"]
    a, b = robot.fields["children"]
    wrap = a.fields["boundingObject"]
    assert wrap.type == "Transform" and [c.fields["size"] for c in wrap.fields["children"]] == [(0.2, 0.2, 0.2)]
    assert np.abs(np.array(_matrix(wrap.fields["rotation"])) - back).max() <= 1e-15
    group = b.fields["boundingObject"]
    (pose,) = group.fields["children"]
    assert group.type == "Group" and np.abs(np.array(pose.fields["translation"]) - [0, 0, 0.1]).max() <= 1e-15
    assert np.abs(np.array(_matrix(pose.fields["rotation"])) - back).max() <= 1e-15


@pytest.mark.parametrize(("body", "line", "why"), [
    ('Robot { children [ Camera { children [ Group { children [ Emitter { } ] } ] } ] }\n', 3, "it is inside a Group of a turned Camera"),
    ('Robot { children [ Camera { children [' + ' Transform { }' * 16 + ' ] boundingObject Group { children [ Box { } ] } } ] }\n',
     3, "a turned Camera's children and its boundingObject Group hold more than 16 nodes"),
    ('Robot { children [ Camera { children [ SolidBox { } ] } ] }\n', 3, "a PROTO instance held by a turned Camera"),
])
def test_what_webots_sort_order_or_proto_files_decide_is_refused_in_one_line(tmp_path: Path, body: str, line: int,
                                                                             why: str) -> None:
    p = _write(tmp_path, body)
    with pytest.raises(WorldError, match=rf"R2021b.wbt: line {line}, column \d+: \w+ in a Webots R2021b world: {why}"):
        load_world(p)


def test_worlds_before_r2020b_are_refused_naming_the_route(tmp_path: Path) -> None:
    with pytest.raises(WorldError, match=r"Webots R2020a world: only R2020b-R2021b \(converted\) and R2021c and later "
                                         r"are supported \(open and save it in Webots R2022a or later.*on a copy"):
        load_world(_write(tmp_path, "", "R2020a"))


def test_an_r2021c_world_is_read_as_written(tmp_path: Path) -> None:
    """Webots converts worlds up to R2021b revision 1 (``worldFileVersion() > WbVersion(2021, 1, 1)`` is
    read as written): an R2021c world's pillar lies along z as written, the ray passes above it, and
    nothing says it was converted."""
    loaded = load_world(_write(tmp_path, _PILLAR, "R2021c"))
    assert not any("converted" in w for w in loaded.report.warnings), loaded.report.warnings
    sim = Simulation(loaded)
    d = sim.device("r/d")
    d.enable(16)
    sim.step()
    assert d.value == 2000


_ARENA = """TexturedBackground { }
TexturedBackgroundLight { }
RectangleArena { floorSize 4 4 }
Robot { translation 0.3 0.3 0.3 name "r" controller "<extern>"
  children [ DistanceSensor { rotation 0 0 1 -1.5707963267948966 name "down" lookupTable [ 0 0 0, 2 2000 0 ] } ] }
"""


def _down(path: Path, **kw) -> float:
    sim = Simulation(load_world(path, **kw))
    d = sim.device("r/down")
    d.enable(16)
    sim.step()
    return float(d.value)


def test_a_pose_proto_webots_ships_turns_back_to_y_up(tmp_path: Path) -> None:
    """Rule C: Webots' RectangleArena (z-up since R2022a; here the built-in stand-in, Webots' own file
    not found) turns by Rx(-pi/2)·Rz(pi/2), its floor's normal back to world +y: a sensor 0.3 m above it
    looking down reads 0.3 m. The same text read as R2023b stands the floor on its side: no reading."""
    assert _down(_write(tmp_path, _ARENA)) == pytest.approx(300.0, abs=1e-9)
    assert _down(_write(tmp_path, _ARENA, "R2023b")) == 2000


def test_a_pose_proto_found_in_the_installation_turns_too(tmp_path: Path) -> None:
    """The same rule for a PROTO file under the Webots installation (``webots_home``): our own floor,
    a z-up Solid, turned to y-up."""
    home = tmp_path / "home"
    (home / "projects" / "objects" / "protos").mkdir(parents=True)
    (home / "projects" / "objects" / "protos" / "Slab.proto").write_text(
        "#VRML_SIM R2023b utf8\nPROTO Slab [ field SFVec3f translation 0 0 0 field SFRotation rotation 0 0 1 0 ]\n"
        "{ Solid { translation IS translation rotation IS rotation children [ Shape { geometry Box { size 4 4 0.02 } } ]\n"
        "  boundingObject Box { size 4 4 0.02 } } }\n")
    body = _ARENA.replace("RectangleArena { floorSize 4 4 }", "Slab { }")
    assert _down(_write(tmp_path, body), webots_home=home) == pytest.approx(1000 * 0.29, abs=1e-9)
    assert _down(_write(tmp_path, body, "R2023b"), webots_home=home) == 2000


def test_a_proto_of_the_worlds_own_written_before_r2022a_is_converted_and_a_newer_one_kept(tmp_path: Path) -> None:
    """Webots converts the body of a PROTO file up to R2021b at each instance: our disc (a Cylinder, along
    its y in R2021b, in Transforms holding it alone) is turned by B1 to lie flat again, its top at y = 0.31,
    0.19 m under the sensor; no rule C (Webots does not ship it). The same file headed R2023b is left as
    written, by Webots too: the disc stands along z and the ray misses it."""
    (tmp_path / "protos").mkdir()
    (tmp_path / "worlds").mkdir()
    proto = tmp_path / "protos" / "Slab.proto"
    text = ("PROTO Slab [ ]\n{ Solid { translation 0 0.3 0\n"
            "  children [ Transform { children [ Shape { geometry Cylinder { radius 2 height 0.02 } } ] } ]\n"
            "  boundingObject Transform { children [ Cylinder { radius 2 height 0.02 } ] } } }\n")
    world = tmp_path / "worlds" / "w.wbt"
    world.write_text(f"#VRML_SIM R2021b utf8\n{NUE}" + _ARENA.replace("RectangleArena { floorSize 4 4 }", "Slab { }")
                     .replace("0.3 0.3 0.3", "0.3 0.5 0.3"))
    proto.write_text("#VRML_SIM R2021b utf8\n" + text)
    assert _down(world) == pytest.approx(1000 * 0.19, abs=1e-9)
    proto.write_text("#VRML_SIM R2023b utf8\n" + text)
    assert _down(world) == 2000


def _rover(header: str) -> str:
    """Our y-up robot PROTO as written for R2021b: a camera looking along its -z, two wheels about its x
    (each cylinder, along its y, laid along x by a Transform turned about z)."""
    wheels = "".join(_wheel(side, x) for side, x in (("left", L / 2), ("right", -L / 2)))
    return (f"#VRML_SIM {header} utf8\n"
            "PROTO Rover [ field SFVec3f translation 0 0 0 field SFRotation rotation 0 1 0 0 ]\n"
            '{ Robot { translation IS translation rotation IS rotation name "bot" controller "<extern>"\n'
            '  children [ Camera { translation 0 0.05 0 name "cam" width 3 height 3\n'
            '      children [ DistanceSensor { name "ds" translation 0 0.01 0 } ] }\n'
            f"{wheels} ]\n"
            "  boundingObject Transform { translation 0 0.05 0 children [ Box { size 0.08 0.04 0.06 } ] }\n"
            "  physics Physics { } } }\n")


# the robot stood up in a z-up world: its y along world z (Rx(pi/2)), so its -z looks along world +y
_ROVER_WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Rover.proto"
WorldInfo { basicTimeStep 16 }
Background { skyColor [ 0 0 1 ] }
Solid { translation 0 2 0.05 children [ Shape { appearance Appearance { material Material { emissiveColor 1 0 0 } }
  geometry Box { size 1 1 1 } } ] }
Rover { rotation 1 0 0 1.5707963267948966 }
"""


def _rover_world(tmp_path: Path, header: str) -> Path:
    (tmp_path / "Rover.proto").write_text(_rover(header))
    world = tmp_path / "rover.wbt"
    world.write_text(_ROVER_WORLD)
    return world


def test_an_old_robot_proto_is_converted_at_its_instance_in_a_current_world(tmp_path: Path) -> None:
    """Webots converts the body of a PROTO file written up to R2021b at each instance, whatever the
    world's version: the camera turns by Rx(-pi/2)·Rz(pi/2) (looking along the robot's -z: world +y here,
    at the red box; its up the robot's y: world +z), its DistanceSensor child turned back (0.01 above it,
    looking along the robot's x, world +x), and each wheel's Transform by Rx(-pi/2), its cylinder along
    the hinge axis again: a two-wheel drive of radius R and axle L driving along the robot's x × y = +z,
    world -y, by 4·R·t. The same file headed R2022a is read as written: the camera looks along world +x,
    missing the box."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = load_world(_rover_world(tmp_path, "R2021b"))
    said = [w for w in loaded.report.warnings if "PROTO Rover was written for Webots R2021b" in w]
    assert len(said) == 1 and "its body is converted at each instance" in said[0], loaded.report.warnings
    robot = loaded.world.robots[0]
    cam, ds = sorted(robot.devices, key=lambda d: d.name)[:2]
    assert (cam.name, ds.name) == ("cam", "ds")
    stand = np.array(_matrix((1, 0, 0, math.pi / 2)))
    m = stand @ np.array(_matrix(tuple(cam.pose.rotation)))
    assert np.abs(m @ [1, 0, 0] - [0, 1, 0]).max() <= 1e-15 and np.abs(m @ [0, 0, 1] - [0, 0, 1]).max() <= 1e-15
    assert np.abs(np.array(ds.pose.translation) - [0, 0.06, 0]).max() <= 1e-15
    assert ds.pose.rotation is None or np.abs(np.array(_matrix(tuple(ds.pose.rotation))) - np.eye(3)).max() <= 1e-15
    d = robot.differential_drive
    assert d is not None and tuple(d.forward) == (0.0, 0.0, 1.0) and (d.axle_length, d.wheel_radius) == (L, R)
    sim = Simulation(loaded, precision="exact")
    c = sim.device("bot/cam")
    c.enable(16)
    for name in ("left wheel motor", "right wheel motor"):
        motor = sim.robot("bot").motor(name)
        motor.set_position(math.inf)
        motor.set_velocity(4.0)
    sim.step()
    image = np.asarray(c.image)
    assert (image[..., 2] > 150).all() and (image[..., 0] == 0).all()     # red everywhere, no sky
    start = np.array(sim.robot("bot").pose.translation)
    sim.run(50)
    t = 50 * 0.016
    assert np.abs(np.array(sim.robot("bot").pose.translation) - start - [0.0, -4.0 * R * t, 0.0]).max() <= 1e-9
    # the same body headed R2022a: read as written, the camera looks along the robot's x (world +x): sky
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = load_world(_rover_world(tmp_path, "R2022a"))
    assert not any("PROTO Rover was written" in w for w in loaded.report.warnings)
    sim = Simulation(loaded)
    c = sim.device("bot/cam")
    c.enable(16)
    sim.step()
    image = np.asarray(c.image)
    assert not ((image[..., 2] > 150) & (image[..., 0] == 0)).any()     # no red: sky and its own wheel


def _proto_world(tmp_path: Path, protos: dict[str, str], body: str) -> Path:
    for name, text in protos.items():
        (tmp_path / f"{name}.proto").write_text(text)
    world = tmp_path / "w.wbt"
    world.write_text("#VRML_SIM R2023b utf8\n" + "".join(f'EXTERNPROTO "{n}.proto"\n' for n in protos) + body)
    return world


def test_a_device_that_is_the_instance_itself_keeps_its_pose_and_turns_what_it_holds_back(tmp_path: Path) -> None:
    """Webots turns no device that is the converted instance itself (``candidate != node``), yet turns its
    pose children back by the inverse turn: our R2021b camera PROTO keeps its rotation, its DistanceSensor
    (0.01 along y as written) comes out at (Rx(-pi/2)·Rz(pi/2))ᵀ·(0, 0.01, 0) = (0, 0, 0.01), turned by
    that transpose."""
    cam = ('#VRML_SIM R2021b utf8\nPROTO Cam [ ]\n{ Camera { name "cam" width 3 height 3\n'
           '  children [ DistanceSensor { name "ds" translation 0 0.01 0 } ] } }\n')
    loaded = load_world(_proto_world(tmp_path, {"Cam": cam}, 'Robot { name "r" controller "<extern>" children [ Cam { } ] }\n'))
    camera, ds = sorted(loaded.world.robots[0].devices, key=lambda d: d.name)
    assert camera.pose.rotation is None or np.abs(np.array(_matrix(tuple(camera.pose.rotation))) - np.eye(3)).max() <= 1e-15
    assert np.abs(np.array(ds.pose.translation) - [0, 0, 0.01]).max() <= 1e-15
    turn = np.array([[0, -1, 0], [0, 0, 1], [-1, 0, 0]])
    assert np.abs(np.array(_matrix(tuple(ds.pose.rotation))) - turn.T).max() <= 1e-15


_OLD_INNER = '#VRML_SIM R2021b utf8\nPROTO Inner [ ]\n{ Solid { children [ Transform { children [ Shape { geometry Cylinder { } } ] } ] } }\n'


@pytest.mark.parametrize(("protos", "body", "where", "why"), [
    ({"Inner": _OLD_INNER, "Outer": '#VRML_SIM R2021b utf8\nEXTERNPROTO "Inner.proto"\nPROTO Outer [ ]\n'
                                    '{ Solid { children [ Inner { } ] } }\n'},
     "Outer { }\n", r"Outer.proto:4:22: Inner: a PROTO written for Webots R2021b inside another's body",
     "Webots converts its body at its own instance and again within the outer one's"),
    ({"Eye": '#VRML_SIM R2021b utf8\nPROTO Eye [ field MFNode extras [ ] ]\n'
             '{ Robot { controller "<extern>" children [ Camera { children IS extras } ] } }\n'},
     "Eye { extras [ Transform { } ] }\n", r"w.wbt: line 3, column 16: Transform in PROTO Eye \(written for Webots R2021b",
     "it comes from a field of the instance, whose node Webots converts twice"),
    ({"Inner": _OLD_INNER.replace("R2021b", "R2023b"),
      "Derived": '#VRML_SIM R2021b utf8\nEXTERNPROTO "Inner.proto"\nPROTO Derived [ ]\n{ Inner { } }\n'},
     "Derived { }\n", r"Derived.proto:4:3: PROTO Derived \(written for Webots R2021b", "a derived PROTO"),
])
def test_what_an_old_protos_conversion_leaves_unsettled_is_refused_in_one_line(tmp_path: Path, protos: dict[str, str],
                                                                               body: str, where: str, why: str) -> None:
    with pytest.raises(WorldError, match=rf"{where}.*{why}"):
        load_world(_proto_world(tmp_path, protos, body))
