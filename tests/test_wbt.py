"""Webots worlds (.wbt): parser positions, conversion, twins read bit for bit, convert round trip."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sensorium.cli import main as cli
from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world
from sensorium.server.world.wbt.parser import MAX_DEPTH

HERE = Path(__file__).parent / "worlds" / "wbt"
HEADER = "#VRML_SIM R2023b utf8\n"


def write(tmp_path: Path, body: str, name: str = "w.wbt") -> Path:
    p = tmp_path / name
    p.write_text(HEADER + body)
    return p


def readings_run(sim: Simulation, steps: int = 40) -> list:
    """Enable every device, drive 'bot' along an arc, collect every reading of every step."""
    for dev in sim.all_devices():
        dev.enable(sim.basic_time_step)
        if hasattr(dev, "enable_point_cloud"):
            dev.enable_point_cloud()
    bot = sim.robot("bot")
    bot.motor("left wheel motor").set_position(math.inf)
    bot.motor("right wheel motor").set_position(math.inf)
    bot.motor("left wheel motor").set_velocity(3.0)
    bot.motor("right wheel motor").set_velocity(5.0)
    out = []
    for _ in range(steps):
        sim.step()
        for dev in sim.all_devices():
            for key, value in dev.readings().items():
                out.append((dev.path, key, np.array(value, copy=True)))
    return out


def same(a: list, b: list) -> None:
    assert len(a) == len(b)
    for (pa, ka, va), (pb, kb, vb) in zip(a, b):
        assert (pa, ka) == (pb, kb)
        if va.dtype.names:
            for f in va.dtype.names:
                assert np.array_equal(va[f], vb[f], equal_nan=True), (pa, ka, f)
        else:
            assert np.array_equal(va, vb, equal_nan=True), (pa, ka)


def test_full_wbt_is_its_yaml_twin_bit_for_bit() -> None:
    wbt, yml = load_world(HERE / "full.wbt"), load_world(HERE / "full.yaml")
    assert wbt.world == yml.world
    a, b = readings_run(Simulation(wbt)), readings_run(Simulation(yml))
    same(a, b)
    # the readings are real: the infra-red, sonar, lidar and both light sensors all saw something
    finite = {p for p, k, v in a if v.dtype.names is None and np.isfinite(v).any() and np.any(v != 0)}
    assert {"bot/ir", "bot/sonar", "bot/lidar", "bot/ls", "watcher/ds", "watcher/ls"} <= finite
    # the robot drove (the drive was recognised) and the watcher's light sensor saw the robot's lamp move
    watcher = [float(v) for p, k, v in a if p == "watcher/ls"]
    assert len(set(watcher)) > 10


def test_skipped_nodes_summarised_once() -> None:
    w = load_world(HERE / "full.wbt")
    summary = [x for x in w.warnings if "skipped nodes that do not matter" in x]
    assert summary == [f"{HERE / 'full.wbt'}: skipped nodes that do not matter to these sensors: TexturedBackground, Viewpoint"]


def test_convert_round_trip(tmp_path: Path, capsys) -> None:
    out = tmp_path / "sub" / "full.yaml"
    out.parent.mkdir()
    assert cli(["convert", str(HERE / "full.wbt"), str(out)]) == 0
    # its meshes stay where the .wbt has them, outside OUT's folder: loading it needs the flag
    with pytest.raises(WorldError, match="leaves the world's folder"):
        load_world(out)
    assert "--allow-outside-meshes" in capsys.readouterr().err
    converted = load_world(out, allow_outside_meshes=True)
    original = load_world(HERE / "full.wbt")
    # mesh url rewritten relative to the output; everything else identical
    mesh = next(s for s in converted.world.solids if s.name == "mesh").shapes[0].geometry
    assert (out.parent / mesh.url).resolve() == (HERE / "meshes" / "tetra.obj").resolve()
    same(readings_run(Simulation(converted)), readings_run(Simulation(original)))
    # never overwrite without --force
    before = out.read_bytes()
    assert cli(["convert", str(HERE / "full.wbt"), str(out)]) == 1
    assert "exists; not overwriting" in capsys.readouterr().err
    assert out.read_bytes() == before
    assert cli(["convert", str(HERE / "full.wbt"), str(out), "--force"]) == 0


def test_validate_and_info_accept_wbt(capsys) -> None:
    assert cli(["validate", str(HERE / "full.wbt")]) == 0
    assert capsys.readouterr().out.strip().endswith("full.wbt: OK")
    assert cli(["info", str(HERE / "full.wbt")]) == 0
    assert "obstacle (box+sphere, 1 child solid, 1 light)" in capsys.readouterr().out


@pytest.mark.parametrize("body, line, col, what", [
    ('Solid { name "oops }\n', 2, 14, "unterminated string"),
    ("Solid {\n  translation 0 0 0\n  children [ Shape { } \n", 5, 1, "end of file inside the list opened at line 4, column 12"),
    ("Solid { boundingObject USE NOPE }\n", 2, 28, "USE NOPE: no DEF NOPE before this point"),
    ("Solid { translation 1 2 3 } }\n", 2, 29, "expected a node, found '}'"),
    ("Solid { 12 }\n", 2, 9, "expected a field name or '}' in Solid (line 2), found '12'"),
    ("Solid { name 'x' }\n", 2, 14, "unexpected character \"'\""),
    ("PROTO X [ ] { }\n", 2, 1, "PROTO definitions inside a world file are not supported"),
])
def test_syntax_errors_name_file_line_column(tmp_path: Path, body: str, line: int, col: int, what: str) -> None:
    p = write(tmp_path, body)
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value) == f"{p}: line {line}, column {col}: {what}"


def test_header_required_and_old_versions_refused(tmp_path: Path) -> None:
    p = tmp_path / "old.wbt"
    p.write_text("#VRML_SIM R2021b utf8\nWorldInfo { }\n")
    with pytest.raises(WorldError, match=r"old.wbt: line 1, column 1: Webots R2021b world: only R2022a and later"):
        load_world(p)
    p.write_text("WorldInfo { }\n")
    with pytest.raises(WorldError, match="not a Webots world"):
        load_world(p)


def test_nesting_depth_bounded(tmp_path: Path) -> None:
    deep = "Group { children [ " * (MAX_DEPTH + 5) + "]  }" * (MAX_DEPTH + 5)
    with pytest.raises(WorldError, match=f"nested deeper than {MAX_DEPTH} levels"):
        load_world(write(tmp_path, deep))


def test_field_errors_point_at_the_node(tmp_path: Path) -> None:
    p = write(tmp_path, 'Solid {\n  children [ Shape { geometry Box { size 1 -2 1 } } ]\n}\nSolid { translation 1 2 }\n')
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value) == f"{p}: line 5, column 9: Solid.translation: expected 3 numbers, got 2 numbers"
    p = write(tmp_path, 'Solid {\n  children [ Shape { geometry Box { size 1 -2 1 } } ]\n}\n')
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value).startswith(f"{p}: line 3, column 31 (Box, converted as solids[0].shapes[0].geometry.size): ")
    assert "every box size component must be > 0" in str(exc.value)


def test_unknown_proto_is_skipped_with_its_position(tmp_path: Path) -> None:
    p = write(tmp_path, 'EXTERNPROTO "https://example.org/E-puck.proto"\nE-puck {\n  translation 0 0 0\n}\n'
                        'Solid { children [ Shape { geometry Sphere { radius 0.1 } } ] }\n')
    w = load_world(p)
    assert [s.name for s in w.world.solids] == ["solid"] and w.world.robots == []
    assert any(x.startswith(f"{p}:3:1: E-puck: not a built-in node or PROTO here; skipped") for x in w.warnings)


def test_device_through_nested_rotated_poses_closed_form(tmp_path: Path) -> None:
    """The robot faces world +y; its sensor sits 0.1 m to its right (world x = 0.1) behind a quarter
    turn back and two cancelling eighth turns, so it looks along world +x at a wall face at x = 0.45."""
    p = write(tmp_path, """
Solid { translation 0.5 0 0.05 children [ Shape { geometry Box { size 0.1 2 0.1 } } ] boundingObject Box { size 0.1 2 0.1 } }
Robot {
  rotation 0 0 1 1.5707963267948966
  name "r"
  children [
    Pose { translation 0 -0.1 0.05 rotation 0 0 1 -1.5707963267948966
      children [ Solid { name "arm" children [ Pose { rotation 0 0 1 0.7853981633974483 children [
        Pose { rotation 0 0 1 -0.7853981633974483 children [ DistanceSensor { name "d" lookupTable [ 0 0 0, 1 1000 0 ] } ] } ] } ] } ] }
  ]
}
""")
    loaded = load_world(p)
    dev = loaded.world.robots[0].devices[0]
    assert dev.pose.quaternion is not None   # composed of several rotations
    sim = Simulation(loaded)
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    # sensor at world (0.1, 0, 0.05) looking along +x; the wall's near face is at x = 0.45
    assert d.value == pytest.approx(1000 * 0.35, abs=1e-9)


def _two_wheels(axis_left: str = "0 1 0", anchor_x: float = 0.0, extra: str = "") -> str:
    def wheel(side: str, y: float, axis: str) -> str:
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis {axis} anchor {anchor_x} {y} 0.02 }} '
                f'device [ RotationalMotor {{ name "{side} wheel motor" }} ] '
                f'endPoint Solid {{ translation {anchor_x} {y} 0.02 children [ Shape {{ geometry Cylinder {{ radius 0.03 height 0.01 }} }} ] }} }}\n')
    return "Robot { name \"r\" children [\n" + wheel("left", 0.05, axis_left) + wheel("right", -0.05, "0 1 0") + extra + "] }\n"


def test_hinge_wheels_become_a_differential_drive(tmp_path: Path) -> None:
    w = load_world(write(tmp_path, _two_wheels()))
    dd = w.world.robots[0].differential_drive
    assert dd == wm.DifferentialDrive(wheel_radius=0.03, axle_length=0.1, max_wheel_speed=10.0,
                                      left_motor="left wheel motor", right_motor="right wheel motor")


@pytest.mark.parametrize("kwargs, why", [
    (dict(axis_left="0 -1 0"), "wheel axis of motor 'left wheel motor' is [0.0, -1.0, 0.0], not the robot's +y"),
    (dict(anchor_x=0.02), "the axle midpoint is at x=0.02, y=0 in the robot frame, not under the robot's origin"),
    (dict(extra='HingeJoint { device [ RotationalMotor { name "third" } ] }\n'),
     "3 motorised hinge joints; a differential drive needs exactly two wheels"),
])
def test_no_drive_says_why(tmp_path: Path, kwargs: dict, why: str) -> None:
    p = write(tmp_path, _two_wheels(**kwargs))
    w = load_world(p)
    assert w.world.robots[0].differential_drive is None
    assert any(x.startswith(f"{p}:2:1: robot 'r': no differential drive ({why}") and x.endswith("the robot will not move")
               for x in w.warnings), w.warnings


def test_nue_world_drives_on_the_ground_plane(tmp_path: Path) -> None:
    """NUE: y is up. A robot standing up (its z along world y) drives forward along world x."""
    p = write(tmp_path, 'WorldInfo { coordinateSystem "NUE" basicTimeStep 10 }\n'
                        'Robot { rotation 1 0 0 -1.5707963267948966 ' + _two_wheels()[len("Robot { "):])
    w = load_world(p)
    assert w.world.world_info.coordinate_system == "NUE"
    sim = Simulation(w)
    r = sim.robot("r")
    for m in ("left wheel motor", "right wheel motor"):
        r.motor(m).set_position(math.inf)
        r.motor(m).set_velocity(2.0)
    sim.run(100)   # 1 s at 2 rad/s on 0.03 m wheels: 0.06 m forward
    assert r.pose.translation == pytest.approx([0.06, 0.0, 0.0], abs=1e-12)
    assert r.pose.rotation[:, 2] == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)   # still standing up


def _lamp_world(robot_lights: list, world_lights: list, at=(0.0, 0.0, 0.0)) -> wm.World:
    return parse_world({
        "lights": world_lights,
        "robots": [{"name": "lamp", "pose": {"translation": list(at)}, "lights": robot_lights},
                   {"name": "eye", "pose": {"translation": [1.0, 0.0, 0.0]},
                    "devices": [{"name": "ls", "device": "LightSensor", "pose": {"rotation": [0, 0, 1, 3.141592653589793]}}]}],
    }).world


def test_light_on_a_robot_moves_with_it() -> None:
    carried = Simulation(_lamp_world([{"type": "PointLight", "location": [0.0, 0.0, 0.1], "attenuation": [0, 0, 1]}], []))
    ls = carried.device("eye/ls")
    ls.enable(32)
    carried.step()
    near = ls.value
    carried.robot("lamp").set_pose([-0.5, 0.0, 0.0])
    carried.step()
    moved = ls.value
    fixed = Simulation(_lamp_world([], [{"type": "PointLight", "location": [-0.5, 0.0, 0.1], "attenuation": [0, 0, 1]}]))
    fixed.device("eye/ls").enable(32)
    fixed.step()
    assert moved == fixed.device("eye/ls").value   # bit for bit
    assert near > moved > 0


def test_nested_solid_children_compose_and_move_together() -> None:
    w = parse_world({"solids": [{"name": "base", "pose": {"translation": [1.0, 0.0, 0.0]},
                                 "children": [{"name": "top", "pose": {"translation": [0.0, 0.0, 0.5]},
                                               "geometry": {"type": "box", "size": [0.2, 0.2, 0.2]}}]}],
                     "robots": [{"name": "r", "devices": [{"name": "d", "device": "DistanceSensor",
                                                           "pose": {"translation": [0.0, 0.0, 0.5]},
                                                           "lookup_table": [[0, 0, 0], [2, 2000, 0]]}]}]}).world
    sim = Simulation(w)
    d = sim.device("r/d")
    d.enable(32)
    sim.step()
    assert d.value == pytest.approx(1000 * 0.9, abs=1e-9)   # child box face at x = 0.9
    sim.set_solid_pose("base", [1.5, 0.0, 0.0])
    sim.step()
    assert d.value == pytest.approx(1000 * 1.4, abs=1e-9)
