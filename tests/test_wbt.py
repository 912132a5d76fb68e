"""Webots worlds (.wbt): parser positions, conversion, twins read bit for bit, convert round trip."""

from __future__ import annotations

import contextlib
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _serve import serve

from sensorium.cli import main as cli
from sensorium.schemas import world as wm
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world, parse_world
from sensorium.server.world.wbt.parser import MAX_DEPTH

HERE = Path(__file__).parent / "worlds" / "wbt"
ROOT = Path(__file__).resolve().parents[1]
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
    # a YAML world has no file order, nor the nodes inside its robots a Supervisor walks (nor the Solid among
    # them a shape belongs to), nor its Shape and light nodes, nor where a world file writes its nested solids
    def bare(owner):
        update = {"shapes": [p.model_copy(update={"node": None, "in_solid": -1}) for p in owner.shapes],
                  "lights": [lt.model_copy(update={"node": None}) for lt in owner.lights], "written_at": None}
        if hasattr(owner, "children"):     # (nor the Poses and Groups inside its solids)
            update.update(children=[bare(c) for c in owner.children], poses=[], in_pose=-1, seq=None)
        return owner.model_copy(update=update)

    robots = [bare(r).model_copy(update={"nodes": []}) for r in wbt.world.robots]
    solids = [bare(s) for s in wbt.world.solids]
    assert wbt.world.model_copy(update={"top_nodes": [], "robots": robots, "solids": solids}) == yml.world
    a, b = readings_run(Simulation(wbt)), readings_run(Simulation(yml))
    same(a, b)
    # the readings are real: the infra-red, sonar, lidar and both light sensors all saw something
    finite = {p for p, k, v in a if v.dtype.names is None and np.isfinite(v).any() and np.any(v != 0)}
    assert {"bot/ir", "bot/sonar", "bot/lidar", "bot/ls", "watcher/ds", "watcher/ls"} <= finite
    # the robot drove (the drive was recognised) and the watcher's light sensor saw the robot's lamp move
    watcher = [float(v) for p, k, v in a if p == "watcher/ls"]
    assert len(set(watcher)) > 10


def test_a_world_file_with_a_byte_order_mark_loads_as_without(tmp_path: Path) -> None:
    """A UTF-8 byte-order mark, as some Windows editors write, made the header check fail ("not a
    Webots world: the first line must be ...")."""
    body = HEADER + "WorldInfo { basicTimeStep 16 }\nSolid { translation 1 2 3 boundingObject Box { size 1 1 1 } }\n"
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    plain, marked = tmp_path / "a" / "w.wbt", tmp_path / "b" / "w.wbt"
    plain.write_text(body, encoding="utf-8")
    marked.write_bytes(b"\xef\xbb\xbf" + body.encode())
    a, b = load_world(plain).world, load_world(marked).world
    assert b.world_info.basic_time_step == 16 and b.model_dump() == a.model_dump()
    bad = tmp_path / "bad.wbt"      # an invalid byte after the mark is still placed at its own line and column
    bad.write_bytes(b"\xef\xbb\xbf" + HEADER.encode() + b"WorldInfo {}\nSolid { name \"a\xffb\" }\n")
    with pytest.raises(WorldError, match=r"bad.wbt: line 3, column 16: not valid UTF-8$"):
        load_world(bad)


def test_an_indexed_face_set_without_coord_says_so(tmp_path: Path) -> None:
    """It said "vertex index outside 0..-1"."""
    w = tmp_path / "w.wbt"
    w.write_text(HEADER + "WorldInfo {}\nSolid {\n  children [ Shape { geometry IndexedFaceSet { coordIndex [0 1 2 -1] } } ]\n}\n")
    with pytest.raises(WorldError, match=r"line 4, column 31 .*geometry.vertices\): no vertices for its 1 face\(s\) to index"):
        load_world(w)


def test_skipped_nodes_summarised_once(tmp_path: Path) -> None:
    w = load_world(HERE / "full.wbt")
    # its TexturedBackground (a PROTO not read) is said once, in the PROTO note, with what cameras lose
    assert not [x for x in w.warnings if "skipped nodes that do not matter" in x]
    assert sum("TexturedBackground skipped (cameras see the flat sky colour" in x for x in w.warnings) == 1
    world = tmp_path / "w.wbt"
    world.write_text(HEADER + "WorldInfo {}\nBackground { }\nBackground { }\n")
    summary = [x for x in load_world(world).warnings if "skipped nodes that do not matter" in x]
    assert summary == [f"{world}: skipped nodes that do not matter to these sensors: Background x2"]
    # a sky colour is read (cameras see it past everything): only the rest of that Background is skipped
    world.write_text(HEADER + "WorldInfo {}\nBackground { skyColor [ 0.2 0.3 0.4 ] }\n")
    w = load_world(world)
    assert w.world.background.sky_color == (0.2, 0.3, 0.4)
    assert [x for x in w.warnings if "skipped nodes that do not matter" in x] == [
        f"{world}: skipped nodes that do not matter to these sensors: Background (all but its skyColor)"]


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


def test_convert_into_another_folder_keeps_texture_urls_working(tmp_path: Path, capsys) -> None:
    # texture urls were written as in the .wbt (relative to it), so the converted world named files
    # that are not there; mesh urls were already made relative to the output
    from PIL import Image

    (tmp_path / "textures").mkdir()
    Image.new("RGB", (4, 4), (255, 0, 0)).save(tmp_path / "textures" / "floor.png")
    src = write(tmp_path, 'Solid { children [ Shape { appearance PBRAppearance { baseColorMap ImageTexture { url '
                          '"textures/floor.png" } occlusionMap ImageTexture { url "textures/floor.png" } } '
                          'geometry Plane { size 2 2 } } ] }\n')
    out = tmp_path / "out" / "w.yaml"
    out.parent.mkdir()
    assert cli(["convert", str(src), str(out)]) == 0
    assert "note: 1 mesh or texture url(s) leave" in capsys.readouterr().err
    (shape,) = load_world(out, allow_outside_meshes=True).world.solids[0].shapes
    assert shape.appearance.texture.url == shape.appearance.occlusion_map.url == "../textures/floor.png"
    assert (out.parent / shape.appearance.texture.url).resolve() == (tmp_path / "textures" / "floor.png").resolve()
    beside = tmp_path / "w.yaml"                           # converted beside it: the url as written
    assert cli(["convert", str(src), str(beside)]) == 0
    assert load_world(beside).world.solids[0].shapes[0].appearance.texture.url == "textures/floor.png"


def test_convert_that_cannot_write_leaves_no_file_behind(tmp_path: Path, capsys) -> None:
    out = tmp_path / "out.yaml"
    out.mkdir()                      # a folder where the output should go: refused, and no out.yaml.tmp left
    assert cli(["convert", str(HERE / "full.wbt"), str(out), "--force"]) == 1
    assert capsys.readouterr().err.strip().splitlines()[-1] == f"{out}: cannot write: Is a directory"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.yaml"] and not any(out.iterdir())


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
    # a non-finite number is named where it is written (it was read as a field name or node type)
    ("Solid { translation 0 0 nan }\n", 2, 25, "number 'nan' is not finite (a world's numbers must be finite)"),
    ("Solid { translation Inf 0 0 }\n", 2, 21, "number 'Inf' is not finite (a world's numbers must be finite)"),
    ("Solid { translation 0 0 -infinity }\n", 2, 25,
     "number '-infinity' is not finite (a world's numbers must be finite)"),
    ("Robot { children [ DistanceSensor { aperture NaN } ] }\n", 2, 46,
     "number 'NaN' is not finite (a world's numbers must be finite)"),
    ("Solid { name -x }\n", 2, 14, "unexpected character '-'"),
    # an IndexedFaceSet's indices are whole numbers, -1 the only negative one (2.5 was read as 2,
    # -2 as the end of a face)
    ("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2.5 -1 ] } }\n",
     2, 86, "IndexedFaceSet.coordIndex: expected integers, got 2.5"),
    ("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0, 1 1 0 ] } "
     "coordIndex [ 0 1 2 -2 1 3 2 -1 ] } }\n", 2, 93, "IndexedFaceSet.coordIndex: -2 is not a vertex index (-1 ends a face)"),
    ("Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] "
     "texCoord TextureCoordinate { point [ 0 0, 1 0, 0 1 ] } texCoordIndex [ 0 1 1.5 -1 ] } }\n", 2, 165,
     "IndexedFaceSet.texCoordIndex: expected integers, got 1.5"),
    ("PROTO X [ field SFFoo a 1 ] { Group { } }\n", 2, 17, "PROTO X: unknown field type 'SFFoo' (one of SFBool, "
     "SFInt32, SFFloat, SFVec2f, SFVec3f, SFRotation, SFColor, SFString, SFNode, MFBool, MFInt32, MFFloat, MFVec2f, "
     "MFVec3f, MFRotation, MFColor, MFString, MFNode)"),
])
def test_syntax_errors_name_file_line_column(tmp_path: Path, body: str, line: int, col: int, what: str) -> None:
    p = write(tmp_path, body)
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value) == f"{p}: line {line}, column {col}: {what}"


def test_a_node_type_spelt_like_a_number_is_a_node(tmp_path: Path) -> None:
    p = write(tmp_path, "Group { children [ Inf { } ] }\n")        # followed by '{': a node (here unknown)
    (loss,) = load_world(p).report.losses
    assert loss.where == f"{p}:2:20" and loss.why.startswith("Inf: not a built-in node or PROTO here")


def test_header_required_and_old_versions_refused(tmp_path: Path) -> None:
    p = tmp_path / "old.wbt"
    p.write_text("#VRML_SIM R2020a utf8\nWorldInfo { }\n")
    with pytest.raises(WorldError, match=r"old.wbt: line 1, column 1: Webots R2020a world: only R2020b-R2021b \(converted\) and R2021c and later are supported "
                       r"\(open and save it in Webots R2022a or later, .*convert_nue_to_enu_rub_to_flu.py on a copy"):
        load_world(p)
    p.write_text("WorldInfo { }\n")
    with pytest.raises(WorldError, match="not a Webots world"):
        load_world(p)


def test_only_the_first_world_info_counts(tmp_path: Path) -> None:
    # Webots reads the first WorldInfo and warns about the others; the last one silently won
    p = write(tmp_path, 'WorldInfo { basicTimeStep 8 randomSeed 3 }\nSolid { }\nWorldInfo { basicTimeStep 64 }\n')
    w = load_world(p)
    info = w.world.world_info
    assert (info.basic_time_step, info.random_seed) == (8, 3)
    assert w.warnings == [f"{p}:4:1: duplicate WorldInfo node: only the first one counts (as in Webots); this one is "
                          "skipped"]


def test_nesting_depth_bounded(tmp_path: Path) -> None:
    deep = "Group { children [ " * (MAX_DEPTH + 5) + "]  }" * (MAX_DEPTH + 5)
    with pytest.raises(WorldError, match=f"nested deeper than {MAX_DEPTH} levels"):
        load_world(write(tmp_path, deep))


def test_field_errors_point_at_the_node(tmp_path: Path) -> None:
    p = write(tmp_path, 'Solid {\n  children [ Shape { geometry Box { size 1 -2 1 } } ]\n}\nSolid { translation 1 2 }\n')
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value) == f"{p}: line 5, column 9: Solid.translation: expected 3 numbers, got 2 numbers"
    # a value Webots takes but Sensorium cannot (an infinite irradiance): placed at the node it came from
    p = write(tmp_path, 'Solid {\n  children [ PointLight { attenuation 0 0 0 } ]\n}\n')
    with pytest.raises(WorldError) as exc:
        load_world(p)
    assert str(exc.value).startswith(f"{p}: line 3, column 14 (PointLight, converted as solids[0].lights[0].attenuation): ")
    assert "attenuation 0 0 0 would give infinite irradiance" in str(exc.value)


def test_unknown_proto_is_skipped_with_its_position(tmp_path: Path) -> None:
    """An undeclared node type is skipped with a warning; a declared PROTO whose file is nowhere is
    refused (a robot is never dropped in silence) with one line naming the url."""
    p = write(tmp_path, 'E-puck {\n  translation 0 0 0\n}\nSolid { children [ Shape { geometry Sphere { radius 0.1 } } ] }\n')
    w = load_world(p)
    assert [s.name for s in w.world.solids] == ["solid"] and w.world.robots == []
    assert any(x.startswith(f"{p}:2:1: E-puck: not a built-in node or PROTO here; skipped") for x in w.warnings)
    p = write(tmp_path, 'EXTERNPROTO "https://example.org/E-puck.proto"\nE-puck {\n  translation 0 0 0\n}\n')
    with pytest.raises(WorldError, match=r'line 2, column 1: EXTERNPROTO E-puck: "https://example.org/E-puck.proto" not found'):
        load_world(p)
    # a Webots node not read here is said to be one (not a PROTO whose file is missing)
    p = write(tmp_path, 'HingeJointParameters { axis 0 1 0 }\n')
    (loss,) = load_world(p).report.losses
    assert (loss.name, loss.where, loss.why) == (
        "HingeJointParameters", f"{p}:2:1",
        "HingeJointParameters: a Webots node not read here (or not in its place); skipped (with everything inside it)")


def test_billboard_is_seen_by_no_device(tmp_path: Path) -> None:
    """Webots pins a Billboard's children to its 3D view's viewpoint and no Camera sees them: a world
    with one loses nothing a device reads (a skipped-node note, no loss), and the lidar facing where its
    box would be, were it placed as written, reads infinity as in the world without it. A Solid inside one
    is a loss naming it."""
    lidar_robot = ('Robot { children [ Lidar { horizontalResolution 3 fieldOfView 0.2 numberOfLayers 1 '
                   'maxRange 5 } ] }\n')
    p = write(tmp_path, lidar_robot + 'Billboard { children [ Transform { translation 1 0 0 children [\n'
                        '  Shape { appearance PBRAppearance { } geometry Box { size 0.1 2 2 } } ] } ] }\n')
    w = load_world(p)
    assert w.report.losses == ()
    assert f"{p}: skipped nodes that do not matter to these sensors: Billboard" in w.warnings
    assert w.world.solids == []
    sim = Simulation(w)
    lidar = sim.device("robot/lidar")
    lidar.enable(32)
    sim.step()
    assert np.isinf(np.asarray(lidar.range_image)).all()
    p = write(tmp_path, 'Billboard {\n  children [\n    Solid { name "score" }\n  ]\n}\n')
    (loss,) = load_world(p).report.losses
    assert (loss.name, loss.where) == ("Billboard", f"{p}:2:1")
    assert loss.why.startswith("Billboard holding Solid (line 4): only Webots' 3D view shows")


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


_ROLLER = "Solid { children [ Shape { geometry Cylinder { radius 0.03 height 0.01 } } ] }"


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


def test_slots_hold_wheels_and_devices(tmp_path: Path) -> None:
    # Slot is a Webots base node: its endPoint (a Slot again, a wheel, a device) sits in the Slot's
    # parent frame; it was an unknown node, so the wheels' shapes and the devices were lost
    def wheel(side: str, y: float) -> str:
        return (f'HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0.02 }} '
                f'device [ RotationalMotor {{ name "{side}" }} ] endPoint Slot {{ type "wheel" endPoint Solid {{ '
                f'translation 0 {y} 0.02 rotation 1 0 0 1.5707963267948966 name "{side} wheel" '
                f'children [ DEF W{side} Shape {{ geometry Cylinder {{ radius 0.03 height 0.01 }} }} ] '
                f'boundingObject USE W{side} }} }} }}\n')
    p = write(tmp_path, 'Robot { translation 1 0 0 name "r" children [\n' + wheel("left", 0.05) + wheel("right", -0.05)
              + 'Pose { translation 0 0 0.1 rotation 0 0 1 0.5 children [ Slot { type "x" endPoint Slot { type "x" '
                'endPoint DistanceSensor { translation 0.2 0 0 name "ds" } } } ] }\n] }\n'
              + 'Solid { name "post" children [ Slot { endPoint Solid { translation 0 0 1 name "top" '
                'children [ Shape { geometry Box { size 1 1 1 } } ] } } ] }\n')
    w = load_world(p)
    assert not w.report.losses and not w.warnings, w.warnings
    (robot,) = w.world.robots
    # (no Physics: Webots' kinematic rule, the axle the wheels' 3-D distances from the origin, 2·|(0, 0.05, 0.02)|)
    assert robot.differential_drive == wm.DifferentialDrive(
        wheel_radius=0.03, axle_length=2.0 * float(np.linalg.norm([0.0, 0.05, 0.02])), max_wheel_speed=10.0,
        left_motor="left", right_motor="right", step_rule="mid_heading")
    assert [s.pose.translation for s in robot.shapes] == [(0.0, 0.05, 0.02), (0.0, -0.05, 0.02)]
    assert [s.seen_by for s in robot.shapes] == ["both", "both"]
    ds = next(d for d in robot.devices if d.name == "ds")
    assert ds.pose.translation == pytest.approx((0.2 * math.cos(0.5), 0.2 * math.sin(0.5), 0.1), abs=1e-15)
    (post,) = w.world.solids
    (top,) = post.children
    assert top.name == "top" and top.pose.translation == (0.0, 0.0, 1.0) and len(top.shapes) == 1
    # anchors left at their default (0 0 0): the wheels' places come from the Solids inside the Slots,
    # as from end points without Slots (the drive was refused: "both wheels are at the same place")
    p = write(tmp_path, 'Robot { name "r" children [\n' + (wheel("left", 0.05) + wheel("right", -0.05)).replace(
        "anchor 0 0.05 0.02 ", "").replace("anchor 0 -0.05 0.02 ", "") + '] }\n')
    assert "anchor" not in p.read_text()
    w = load_world(p)
    assert not w.warnings, w.warnings
    assert w.world.robots[0].differential_drive == robot.differential_drive


def test_a_propeller_lists_its_motor_and_shows_its_slow_helix(tmp_path: Path) -> None:
    # a drone's controller asks for its propeller motors: they were skipped with the Propeller node
    # (getDevice found nothing), and so were the helices rays see
    def prop(name: str, x: float) -> str:
        return (f'Propeller {{ shaftAxis 0 0 1 centerOfThrust {x} 0 0.1 device RotationalMotor {{ name "{name}" '
                f'maxVelocity 600 }} fastHelix Solid {{ translation {x} 0 0.1 children [ Shape {{ geometry Cylinder '
                f'{{ radius 0.2 height 0.001 }} }} ] }} slowHelix Solid {{ translation {x} 0 0.1 children [ Shape {{ '
                f'geometry Box {{ size 0.2 0.02 0.005 }} }} ] }} }}\n')
    p = write(tmp_path, 'Robot { name "drone" children [\n' + prop("front propeller", 0.2) + 'GPS { }\n'
              + prop("rear propeller", -0.2) + '] }\n')
    w = load_world(p)
    assert not w.report.losses
    assert [x.split(": ", 1)[1] for x in w.warnings] == [
        "Propeller: its motor's position moves kinematically; its thrust and torque are not simulated"] * 2
    (robot,) = w.world.robots
    assert [(d.device, d.name) for d in robot.devices] == [
        ("RotationalMotor", "front propeller"), ("GPS", "gps"), ("RotationalMotor", "rear propeller")]
    assert [(s.geometry.type, s.pose.translation) for s in robot.shapes] == [
        ("box", (0.2, 0.0, 0.1)), ("box", (-0.2, 0.0, 0.1))]       # the slow helices (at rest), not the fast ones
    entries = Simulation(w).robot("drone").device_list     # what a controller's getDevice finds (kinematic motors)
    assert [(e.name, e.simulated) for e in entries if e.name.endswith("propeller")] == [
        ("front propeller", True), ("rear propeller", True)]


@pytest.mark.parametrize("kwargs, why", [
    # (an axis opposite the other's is a wheel mounted mirrored, which gets a drive: test_wbt_mirrored.py)
    (dict(axis_left="0 -1 1"), "wheel axis of motor 'left wheel motor' is [0.0, -0.707107, 0.707107], not the robot's +y"),
    # a third motorised hinge that is a wheel (its end point has a cylinder to roll on): a hinge
    # with nothing round at its end is no wheel and leaves the other two their drive (test_wbt_drives.py)
    (dict(extra=f'HingeJoint {{ device [ RotationalMotor {{ name "third" }} ] endPoint {_ROLLER} }}\n'),
     "wheel axis of motor 'third' is [1.0, 0.0, 0.0], not the robot's +y"),
    (dict(extra='HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 } device [ RotationalMotor { name '
                f'"third" }} ] endPoint {_ROLLER} }}\n'),
     "3 motorised wheels, not all on either side of the robot's x axis"),
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


def test_builtin_protos(tmp_path: Path) -> None:
    p = write(tmp_path, 'WorldInfo { }\nTexturedBackgroundLight { texture "noon_sunny_empty" luminosity 2 }\n'
                        'SolidBox { }\nWoodenBox { translation 1 0 0.1 size 0.2 5 0.2 }\nRobot { }\nRobot { }\n')
    w = load_world(p).world
    (sun,) = w.lights
    # the PROTO's NUE direction (0.9, -0.59, 0.28) in ENU axes; ambient 1; luminosity scales the intensity
    assert (sun.type, sun.direction, sun.intensity, sun.ambient_intensity) == ("DirectionalLight", (0.28, 0.9, -0.59), 2.0, 1.0)
    box, wooden = w.solids
    assert box.name == "box" and box.pose.translation == (0.0, 0.0, 1.0)
    assert box.shapes[0].geometry == wm.Box(type="box", size=(2.0, 2.0, 2.0)) and box.shapes[0].seen_by == "both"
    assert box.shapes[0].appearance.roughness == 0.5
    assert wooden.name == "wooden box" and wooden.shapes[0].geometry.size == (0.2, 3.0, 0.2)   # clamped like the PROTO
    assert [r.name for r in w.robots] == ["robot", "robot(1)"]
    # the PROTOs' Solids set a model (what camera recognition reports); SolidBox passes its recognitionColors
    assert (box.model, wooden.model, box.recognition_colors, wooden.recognition_colors) == ("box", "wooden box", [], [])
    p = write(tmp_path, 'WorldInfo { }\nSolidBox { recognitionColors [ 1 0 0, 0 1 0 ] }\n')
    (box,) = load_world(p).world.solids
    assert box.recognition_colors == [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0)] and box.model == "box"


@contextlib.contextmanager
def serving(world: Path, *extra: str):
    """``sensorium serve WORLD`` in a subprocess on free loopback ports; yields its RPC endpoint."""
    with serve(world, "--precision", "fast", *extra, pub="tcp://127.0.0.1:*", stop_signal=signal.SIGTERM) as s:
        yield s.rpc


def test_serve_a_wbt_world(tmp_path: Path) -> None:
    import msgpack
    import zmq

    from sensorium.server.recording.reader import Recording

    ctx = zmq.Context()
    try:
        with serving(HERE / "full.wbt", "--record", str(tmp_path / "run.mcap")) as rpc:
            sock = ctx.socket(zmq.DEALER)
            sock.setsockopt(zmq.LINGER, 0)
            sock.connect(rpc)
            sock.send(msgpack.packb({"id": 1, "service": "attach", "args": {"robot": "bot"}}))
            assert sock.poll(30_000)
            reply = msgpack.unpackb(sock.recv_multipart()[-1], raw=False)
            assert reply["ok"], reply
            assert {"ir", "sonar", "lidar", "ls", "led0", "left wheel sensor"} <= {d["name"] for d in reply["result"]["devices"]}
            sock.close(0)
    finally:
        ctx.destroy(linger=0)
    with Recording(tmp_path / "run.mcap") as rec:   # the world attached as the user wrote it
        assert rec.world() == ("full.wbt", (HERE / "full.wbt").read_bytes())


def test_example_wbt_world_runs_the_braitenberg_controller() -> None:
    """The shipped Webots-style world and the example Webots controller, unchanged."""
    world = ROOT / "sensorium" / "worlds" / "epuck.wbt"
    loaded = load_world(world)
    assert [w for w in loaded.warnings if "skipped nodes" not in w and "built-in stand-ins" not in w] == []
    assert loaded.world.robots[0].differential_drive is not None
    script = ROOT / "sensorium" / "client" / "examples" / "braitenberg.py"
    with serving(world) as rpc:
        out = subprocess.run([sys.executable, "-m", "sensorium", "controller", str(script), "--robot", "epuck",
                              "--url", f"{rpc}/epuck", "60"], capture_output=True, text=True, timeout=300,
                             env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert out.returncode == 0, out.stderr
    lines = [x for x in out.stdout.splitlines() if x.startswith("t=")]
    assert len(lines) == 60
    light = [float(x.split("ls0=")[1].split()[0]) for x in lines]
    assert all(v > 0 for v in light[1:]) and len(set(light)) > 5   # it sees the lamp, and it moves


def test_def_use_expansion_is_bounded(tmp_path: Path, monkeypatch) -> None:
    """Each level USEs the previous one twice: 2**15 boxes if expanded (under the parser's bound on
    DEF/USE copies, tests/test_proto_bounds.py); the converter's own bound stops early."""
    from sensorium.server.world.wbt import convert

    monkeypatch.setattr(convert, "MAX_PARTS", 2000)
    levels = ["DEF L0 Group { children [ Shape { geometry Box { } } ] }"]
    levels += [f"DEF L{i} Group {{ children [ USE L{i - 1} USE L{i - 1} ] }}" for i in range(1, 16)]
    p = write(tmp_path, "Solid { children [\n" + "\n".join(levels) + "\n] }\n")
    with pytest.raises(WorldError, match="more than 2000 shapes, devices and lights after DEF/USE expansion"):
        load_world(p)


def test_contact_with_multi_shape_bodies() -> None:
    """A robot whose body is an offset cylinder (radius 0.05) drives +x into a solid made of two
    shapes; it stops where its disc touches the wall's face: x = 0.95 - 0.05."""
    w = parse_world({
        "solids": [{"name": "wall", "pose": {"translation": [1.0, 0.0, 0.0]},
                    "shapes": [{"pose": {"translation": [0.0, 0.0, 0.1]}, "geometry": {"type": "box", "size": [0.1, 2.0, 0.2]}},
                               {"pose": {"translation": [0.0, 3.0, 0.1]}, "geometry": {"type": "sphere", "radius": 0.1}}]}],
        "robots": [{"name": "r", "shapes": [{"pose": {"translation": [0.0, 0.0, 0.05]},
                                             "geometry": {"type": "cylinder", "radius": 0.05, "height": 0.1}}],
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.1, "max_wheel_speed": 10}}],
    }).world
    sim = Simulation(w)
    r = sim.robot("r")
    for m in r.motors.values():
        m.set_position(math.inf)
        m.set_velocity(10.0)
    sim.run(100)   # 0.5 m/s for 3.2 s: far past the wall without contact
    assert r.pose.translation[0] == pytest.approx(0.9, abs=1e-9)
    assert r.pose.translation[0] < 0.9


def test_robot_inside_groups_gets_the_composed_pose(tmp_path: Path) -> None:
    p = write(tmp_path, 'Pose { translation 1 0 0 rotation 0 0 1 1.5707963267948966 children [\n'
                        '  Group { children [ Robot { translation 0 2 0 rotation 0 0 1 1.5707963267948966 name "r" } ] } ] }\n'
                        'Solid { translation 0 0 1 rotation 0 0 1 1.5707963267948966 children [\n'
                        '  Solid { translation 1 0 0 children [ Pose { translation 0 0.5 0 children [\n'
                        '    Robot { name "inner" rotation 0 0 1 1.5707963267948966 } ] } ] } ] }\n')
    w = load_world(p)
    r, inner = w.world.robots
    from sensorium.server.world.poses import pose_from_model

    pose = pose_from_model(r.pose)
    assert pose.translation == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)      # (0, 2) turned a quarter, plus (1, 0)
    assert pose.rotation[:, 0] == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)   # two quarter turns: facing -x
    # a Robot nested in Solids is a robot of the world; its pose is the solids' poses composed with its own
    pose = pose_from_model(inner.pose)
    assert inner.name == "inner"
    assert pose.translation == pytest.approx([-0.5, 1.0, 1.0], abs=1e-12)       # (1, 0.5) turned a quarter, up 1
    assert pose.rotation[:, 0] == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)
    assert w.warnings == []


def test_a_robot_on_a_robot_rides_it_fixed_in_its_frame(tmp_path: Path) -> None:
    """A Robot with a controller or a device in another robot's children (highway_overtake's radar robot) is a
    robot of the world listed after its carrier, carried in the frame its place writes: here (1, 0, 0.5) on a
    carrier at (2, 0, 0) facing +y, so at (2, 1, 0.5) facing +y, and it goes where the carrier goes."""
    p = write(tmp_path, 'Robot { translation 2 0 0 rotation 0 0 1 1.5707963267948966 name "base" children [ '
                        'Pose { translation 1 0 0 children [ Robot { translation 0 0 0.5 name "rider" '
                        'children [ DistanceSensor { } ] } ] } ] }\n')
    w = load_world(p)
    assert [r.name for r in w.world.robots] == ["base", "rider"] and w.warnings == [] and w.report.losses == ()
    rider = w.world.robots[1]
    assert rider.carried_by is not None and rider.carried_by.robot == "base"
    assert rider.carried_by.frame.translation == pytest.approx((1.0, 0.0, 0.5), abs=1e-12)
    sim = Simulation(w)
    pose = sim.robot("rider").pose
    assert pose.translation == pytest.approx([2.0, 1.0, 0.5], abs=1e-12)
    assert pose.rotation[:, 0] == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)
    sim.robot("base").set_pose(translation=[5.0, 5.0, 0.0], rotation=[0.0, 0.0, 1.0, math.pi])
    sim.step()
    assert sim.robot("rider").pose.translation == pytest.approx([4.0, 5.0, 0.5], abs=1e-12)
    assert sim.robot("rider").pose.rotation[:, 0] == pytest.approx([-1.0, 0.0, 0.0], abs=1e-12)


def test_a_riding_robots_wheels_and_tracks_are_no_drive_and_its_carrier_carries_it(tmp_path: Path) -> None:
    """A rider is fixed in its carrier's frame (Webots: no joint between them): its two wheels' hinges make no
    drive (one line each, they turn as joints) and its two Tracks none either (one line), where a drive made
    Simulation refuse the world; the carrier, a two-wheel robot of radius 0.05 m at 5 rad/s, rolls 0.25 m/s
    and carries it 0.06 m above its origin."""
    wheel = ('HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0 }} device [ '
             'RotationalMotor {{ name "{side} wheel motor" }} ] endPoint Solid {{ translation 0 {y} 0 rotation 1 0 0 '
             '1.5707963267948966 children [ Shape {{ geometry Cylinder {{ radius {r} height 0.01 }} }} ] '
             'boundingObject Cylinder {{ radius {r} height 0.01 }} physics Physics {{ }} name "{side}" }} }}')
    track = ('Track {{ translation 0 {y} 0 name "{side} track" device [ LinearMotor {{ name "{side} track motor" }} ] '
             'boundingObject Box {{ size 0.1 0.02 0.02 }} children [ TrackWheel {{ radius 0.01 }} ] }}')
    rider_parts = {"wheels": " ".join(wheel.format(y=y, side=side, r=0.03) for y, side in ((0.06, "left"),
                                                                                         (-0.06, "right"))),
                   "tracks": " ".join(track.format(y=y, side=side) for y, side in ((0.06, "left"), (-0.06, "right")))}
    for kind, parts in rider_parts.items():
        p = write(tmp_path, 'Robot { translation 0 0 0.05 name "truck" children [ '
                            + " ".join(wheel.format(y=y, side=side, r=0.05) for y, side in ((0.12, "left"),
                                                                                           (-0.12, "right")))
                            + f' Robot {{ translation 0 0 0.06 name "rider" children [ {parts} ] }} ] '
                            'physics Physics { } }\n', name=f"{kind}.wbt")
        w = load_world(p)
        truck, rider = w.world.robots
        assert truck.differential_drive is not None and rider.carried_by is not None
        assert (rider.differential_drive, rider.steered_drive) == (None, None), kind
        riding = [x for x in w.warnings if "rides robot 'truck', fixed in its frame" in x]
        assert len(riding) == (2 if kind == "wheels" else 1), (kind, w.warnings)
        sim = Simulation(w)
        for m in sim.robot("truck").motors.values():
            m.set_position(math.inf)
            m.set_velocity(5.0)
        sim.run(50)
        at = sim.robot("truck").pose.translation
        assert at[0] == pytest.approx(50 * sim.basic_time_step * 0.001 * 5.0 * 0.05, abs=1e-12)
        assert sim.robot("rider").pose.translation == pytest.approx(at + [0.0, 0.0, 0.06], abs=1e-12)


def test_a_carrier_and_its_rider_are_one_body_for_contact(tmp_path: Path) -> None:
    """A rider's 0.1 m box just ahead of its carrier's 0.4 m body (0.01 m gap): the carrier driving forward is
    not stopped by its own rider (one body in Webots), but stops where the rider meets a wall 1 m ahead,
    the rider's front face at the wall (1e-9); a robot then driven across where the rider was loaded passes
    freely (the rider is met where it is now, not where the world file put it)."""
    wheel = ('HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 {y} 0 }} device [ '
             'RotationalMotor {{ name "{side} wheel motor" }} ] endPoint Solid {{ translation 0 {y} 0 rotation 1 0 0 '
             '1.5707963267948966 children [ Shape {{ geometry Cylinder {{ radius 0.05 height 0.02 }} }} ] '
             'boundingObject Cylinder {{ radius 0.05 height 0.02 }} physics Physics {{ }} name "{side}" }} }}')
    wheels = " ".join(wheel.format(y=y, side=side) for y, side in ((0.12, "left"), (-0.12, "right")))
    p = write(tmp_path, f"""
Robot {{ translation 0 0 0.05 name "truck" children [ {wheels}
  Robot {{ translation 0.26 0 0 name "rider" children [ DistanceSensor {{ }} ] boundingObject Box {{ size 0.1 0.1 0.06 }} }} ]
  boundingObject Box {{ size 0.4 0.2 0.06 }} physics Physics {{ }} }}
Solid {{ translation 1.36 0 0.05 name "wall" boundingObject Box {{ size 0.1 2 0.1 }} }}
Robot {{ translation 0.26 -0.6 0.05 rotation 0 0 1 1.5707963267948966 name "other" children [ {wheels} ]
  boundingObject Box {{ size 0.2 0.2 0.06 }} physics Physics {{ }} }}
""")
    sim = Simulation(load_world(p))
    truck, rider, other = sim.robot("truck"), sim.robot("rider"), sim.robot("other")
    for m in truck.motors.values():
        m.set_position(math.inf)
        m.set_velocity(5.0)
    sim.run(20)                                             # 20 steps at 0.25 m/s: 0.16 m (32 ms steps)
    assert truck.pose.translation[0] == pytest.approx(20 * sim.basic_time_step * 0.001 * 0.25, abs=1e-12)
    sim.run(200)
    # stopped by its rider: the rider's front face (0.26 + 0.05 ahead of the truck) on the wall's face (1.31)
    assert truck.pose.translation[0] + 0.26 + 0.05 == pytest.approx(1.31, abs=1e-9)
    assert rider.pose.translation[0] == pytest.approx(truck.pose.translation[0] + 0.26, abs=1e-12)
    for m in other.motors.values():
        m.set_position(math.inf)
        m.set_velocity(5.0)
    sim.run(100)                                            # 0.8 m along +y, across the rider's loaded place
    assert other.pose.translation[1] == pytest.approx(-0.6 + 100 * sim.basic_time_step * 0.001 * 0.25, abs=1e-9)


def test_a_yaml_robot_carried_by_another_with_a_drive_is_refused_in_a_line() -> None:
    from sensorium.server.world.loader import WorldError, parse_world

    drive = {"left_motor": "l", "right_motor": "r", "wheel_radius": 0.02, "axle_length": 0.1}
    with pytest.raises(WorldError) as caught:
        parse_world({"robots": [{"name": "base"}, {"name": "rider", "carried_by": {"robot": "base"},
                                                    "differential_drive": drive}]})
    assert str(caught.value) == ("<memory>: robots[1] (rider).differential_drive: a robot riding another (carried_by) "
                                 "has no drive of its own: it is fixed in its carrier's frame")


@pytest.mark.parametrize("nest", ['Robot { name "rider" children [ Robot { name "third" controller "x" } ] }',
                                  'HingeJoint { endPoint Solid { children [ Robot { name "third" controller "x" } ] '
                                  '} device [ RotationalMotor { name "m" } ] }'])
def test_a_robot_on_a_riding_robot_or_a_joint_is_dropped_with_a_reason(tmp_path: Path, nest: str) -> None:
    p = write(tmp_path, f'Robot {{ name "base" children [ {nest} ] }}\n')
    w = load_world(p)
    assert "third" not in [r.name for r in w.world.robots]
    (loss,) = w.report.losses
    assert (loss.kind, loss.name) == ("robot", "third")
    assert "a robot riding on another robot's joint, or on a robot that rides itself, is not supported" in loss.why


def test_a_robot_without_controller_or_device_rides_its_robot_as_part_of_its_body(tmp_path: Path) -> None:
    """The shape of Webots' JetBot, whose Jetson Nano board is a Robot with controller "<none>": the
    board is kept as part of the outer robot, where its rotation and translation put it, and a
    sensor sees it. The base faces world +y; the board sits 0.3 m ahead, its box's far face at y =
    0.35; a sensor at y = 1 looking back along -y reads 1 - 0.35 = 0.65 m."""
    box = "Box { size 0.1 0.1 0.1 }"
    p = write(tmp_path, f"""
Robot {{ translation 0.2 0 0 rotation 0 0 1 1.5707963267948966 name "base" children [
  Robot {{ translation 0.3 0 0.05 name "board" controller "<none>" children [
    Pose {{ children [ Shape {{ geometry {box} }} ] }} ]
    boundingObject {box} }} ] }}
Robot {{ translation 0.2 1 0.05 rotation 0 0 1 -1.5707963267948966 name "eye" children [
  DistanceSensor {{ name "d" lookupTable [ 0 0 0, 1 1000 0 ] }} ] }}
""")
    w = load_world(p)
    assert [r.name for r in w.world.robots] == ["base", "eye"]
    assert w.report.losses == ()
    assert w.warnings == [f"{p}:4:3: Robot 'board' inside robot 'base': no controller and no device: its shapes "
                          "and bounding objects are kept as part of 'base''s body (a robot riding on another "
                          "robot is not simulated here)"]
    sim = Simulation(w)
    d = sim.device("eye/d")
    d.enable(32)
    sim.step()
    assert d.value == pytest.approx(1000 * 0.65, abs=1e-9)


@pytest.mark.parametrize("inner", ['controller "<none>" children [ DistanceSensor { } ]',
                                   'controller "rider" children [ Pose { } ]',
                                   'children [ Shape { geometry Box { size 0.1 0.1 0.1 } } ]'])
def test_a_robot_with_a_controller_or_a_device_on_a_robot_rides_it(tmp_path: Path, inner: str) -> None:
    # a controller that would run (Webots' default one included) or a device it would read: a robot of its own
    p = write(tmp_path, f'Robot {{ name "base" children [ Robot {{ name "rider" {inner} }} ] }}\n')
    w = load_world(p)
    assert [r.name for r in w.world.robots] == ["base", "rider"] and w.report.losses == ()
    assert w.world.robots[1].carried_by is not None and w.world.robots[1].carried_by.robot == "base"


def test_cameras_in_a_world_without_light_lit_by_a_background_in_webots_are_said_black(tmp_path: Path) -> None:
    """Webots' rosbot.wbt has no light (spot.wbt's only one is off): its renderer lights shapes by the
    TexturedBackground's cube map (image-based lighting, not simulated here), so their cameras would
    see black without a word."""
    robot = 'Robot { name "r" children [ Camera { width 4 height 4 } ] }\n'
    lit_by_maps = 'Background { skyColor [ 0.5 0.5 0.5 ] backUrl [ "sky_back.png" ] }\n'
    p = write(tmp_path, lit_by_maps + robot)
    w = load_world(p)
    said = (f"{p}: no light is on in this world: its cameras (r/camera) see every surface black; Webots' "
            "renderer also lights shapes by the background's image-based lighting (a TexturedBackground's cube "
            "map), which is not simulated here: add a DirectionalLight or TexturedBackgroundLight for them to see")
    assert w.warnings[:1] == [said]
    # a light that is off (spot.wbt's TexturedBackgroundLight of its "factory" background, as in Webots) lights nothing
    w = load_world(write(tmp_path, lit_by_maps + robot + "DirectionalLight { on FALSE }\n"))
    assert w.warnings[:1] == [said]
    # what it says: a surface in view reads black
    floor = 'Solid { translation 0 0 -1 children [ Shape { geometry Box { size 10 10 0.1 } } ] }\n'
    p = write(tmp_path, lit_by_maps + floor + robot.replace("Camera {", "Camera { rotation 0 1 0 1.5707963267948966"))
    sim = Simulation(load_world(p))
    cam = sim.device("r/camera")
    cam.enable(32)
    sim.step()
    image = np.asarray(cam.image)
    assert image.shape[:2] == (4, 4) and not image[..., :3].any()
    # a light on anywhere, an LED's light (off until the LED is set), a background without cube maps, or no
    # camera: nothing to say
    led = 'Robot { name "r" children [ Camera { } LED { children [ PointLight { on FALSE } ] } ] }\n'
    for world in (lit_by_maps + robot + "DirectionalLight { }\n", lit_by_maps + led,
                  "Background { skyColor [ 0.5 0.5 0.5 ] }\n" + robot, lit_by_maps + 'Robot { name "r" }\n'):
        assert not [m for m in load_world(write(tmp_path, world)).warnings if "no light" in m]


def test_unsimulated_devices_keep_their_shapes(tmp_path: Path) -> None:
    p = write(tmp_path, 'Robot { name "r" children [ Camera { translation 0.1 0 0 children [\n'
                        '  Shape { geometry Box { size 0.01 0.02 0.03 } } ] } GPS { } ] }\n')
    w = load_world(p)
    (part,) = w.world.robots[0].shapes
    assert part.geometry == wm.Box(type="box", size=(0.01, 0.02, 0.03)) and part.pose.translation == (0.1, 0.0, 0.0)
    assert part.seen_by == "visual"
    # listed in Webots' device order (indices and getModel match Webots), not simulated
    assert [(d.device, d.name, d.model) for d in w.world.robots[0].devices] == [("Camera", "camera", ""),
                                                                                ("GPS", "gps", "")]
    assert w.world.robots[0].devices[0].pose.translation == (0.1, 0.0, 0.0)
    assert w.warnings == []


def test_devices_are_listed_in_webots_tree_order(tmp_path: Path) -> None:
    p = write(tmp_path, 'Robot { name "r" children [\n'
                        '  DistanceSensor { name "ds" model "GP2D120" children [ Compass { } ] }\n'
                        '  HingeJoint { jointParameters HingeJointParameters { axis 1 0 0 } device [\n'
                        '      Brake { } RotationalMotor { name "arm" } PositionSensor { name "arm sensor" } ]\n'
                        '    endPoint Solid { children [ TouchSensor { name "bumper" model "tactile" } ] } }\n'
                        '  SliderJoint { device [ LinearMotor { } ] }\n'
                        '  Emitter { } ] }\n')
    w = load_world(p)
    devs = w.world.robots[0].devices
    assert [(d.device, d.name) for d in devs] == [
        ("DistanceSensor", "ds"), ("Compass", "compass"), ("Brake", "brake"), ("RotationalMotor", "arm"),
        ("PositionSensor", "arm sensor"), ("TouchSensor", "bumper"), ("LinearMotor", "linear motor"),
        ("Emitter", "emitter")]
    assert devs[0].model == "GP2D120" and devs[5].model == "tactile"
    assert devs[4].motor == "arm"     # the joint's sensor measures the joint its motor moves


def test_named_controllers_are_kept_with_their_args(tmp_path: Path) -> None:
    """A controller's name and controllerArgs are kept (`sensorium run` starts it; `serve` waits for it
    as an <extern> one); a name that is no folder name is Webots' <generic> (a controller it cannot
    run), with one warning: under `run` the robot is not waited for (it was <extern>: run waited forever)."""
    p = write(tmp_path, 'Robot { name "r" controller "e-puck_avoid_collision" controllerArgs [ "-v" "2" ] }\n'
                        'Robot { name "s" controller "../up" }\nRobot { name "t" controller "" }\n')
    w = load_world(p)
    r, s, t = w.world.robots
    assert (r.name, r.controller, r.controller_args) == ("r", "e-puck_avoid_collision", ["-v", "2"])
    assert (s.controller, s.controller_args) == ("<generic>", [])
    assert t.controller == "<none>"
    assert [x for x in w.warnings if "controller" in x] == [
        f"{p}:3:1: Robot 's': controller '../up' is no controller's name (a folder under controllers/): the robot "
        "has Webots' <generic> controller (none under sensorium run, an <extern> one under serve)"]


def test_mesh_losses_load_and_name_their_lines(tmp_path: Path) -> None:
    """A mesh Sensorium cannot read (a format it does not read, a missing file) is a loss naming the
    file and line; the world still loads (the rest of the solid too)."""
    p = write(tmp_path, 'Solid {\n  children [\n    Shape { geometry Mesh { url [ "robot.fbx" ] } }\n'
                        '    Shape { geometry Mesh { url [ "gone.stl" ] } }\n    Shape { geometry Box { } }\n  ]\n}\n')
    (tmp_path / "robot.fbx").write_bytes(b"Kaydara FBX Binary  \x00")
    w = load_world(p)
    assert [s.geometry.type for s in w.world.solids[0].shapes] == ["box"]
    assert [(loss.kind, loss.where) for loss in w.losses] == [("shape", f"{p}:4:22"), ("shape", f"{p}:5:22")]
    assert "the .fbx format is not read here" in w.losses[0].why
    assert "mesh file 'gone.stl' not found (relative to the world file)" in w.losses[1].why


def test_scaled_transform_scales_geometry(tmp_path: Path) -> None:
    p = write(tmp_path, 'Solid { name "s" children [ Transform { translation 0 0 1 scale 2 2 2 children [\n'
                        '  Pose { translation 0.5 0 0 children [ Shape { geometry Cylinder { radius 0.1 height 0.3 } } ] } ] } ] }\n')
    (part,) = load_world(p).world.solids[0].shapes
    assert part.pose.translation == (1.0, 0.0, 1.0)     # the child's offset is scaled too
    assert (part.geometry.radius, part.geometry.height) == (0.2, 0.6)


def test_field_typos_are_reported(tmp_path: Path) -> None:
    p = write(tmp_path, 'Solid {\n  translaton 1 0 0\n  rotationStep 0.1\n  children [ Shape { geometry Box { sise 1 1 1 } '
                        'appearance PBRAppearance { basecolor 1 0 0 } } ]\n}\n')
    w = load_world(p)
    typos = [x for x in w.warnings if "did you mean" in x]
    assert typos == [f"{p}:3:3: Solid.translaton: not a Solid field, ignored (did you mean translation?)",
                     f"{p}:5:37: Box.sise: not a Box field, ignored (did you mean size?)",
                     f"{p}:5:77: PBRAppearance.basecolor: not a PBRAppearance field, ignored (did you mean baseColor?)"]


def test_supervisor_finds_nodes_by_def_name() -> None:
    from sensorium.server.daemon.supervisor import find_node

    sim = Simulation(load_world(ROOT / "sensorium" / "worlds" / "epuck.wbt"))
    assert find_node(sim, "EPUCK").name == "epuck" and find_node(sim, "EPUCK").type == "Robot"
    assert find_node(sim, "LAMP").name == "lamp" and find_node(sim, "LAMP").type == "Solid"
    assert find_node(sim, "epuck").name == "epuck"      # a name still works
    assert find_node(sim, "NOPE") is None


def test_duplicate_def_names_rejected_in_world_files() -> None:
    with pytest.raises(WorldError, match=r"solids\[0\] \(s\).def_name: duplicate DEF name 'A' \(first used at robots\[0\].def_name\)"):
        parse_world({"robots": [{"name": "r", "def_name": "A"}],
                     "solids": [{"name": "s", "def_name": "A", "geometry": {"type": "box"}}]})


def test_drive_from_wheel_end_points_when_anchors_coincide(tmp_path: Path) -> None:
    """As in Webots' e-puck: both hinge anchors at the axle's centre, the wheels placed by their end points
    (no Physics: Webots' kinematic rule, the axle the wheels' 3-D distances from the origin, 2·|(0, 0.026, 0.02)|)."""
    wheel = ('HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 0 0.02 }} '
             'device [ RotationalMotor {{ name "{0} wheel motor" maxVelocity 6.28 }} ] endPoint Solid {{ translation 0 {1} 0.02 '
             'boundingObject Transform {{ rotation 1 0 0 1.570796 children [ Cylinder {{ height 0.005 radius 0.02 }} ] }} }} }}\n')
    p = write(tmp_path, 'Robot { name "e" children [\n' + wheel.format("left", 0.026) + wheel.format("right", -0.026) + "] }\n")
    dd = load_world(p).world.robots[0].differential_drive
    assert dd == wm.DifferentialDrive(wheel_radius=0.02, axle_length=2.0 * float(np.linalg.norm([0.0, 0.026, 0.02])),
                                      max_wheel_speed=6.28, step_rule="mid_heading")


def test_textures_summarised_once(tmp_path: Path) -> None:
    shape = ('Shape { appearance PBRAppearance { baseColor 0.5 0.2 0.2 baseColorMap ImageTexture { url [ "a.png" ] } } '
             'geometry Box { } }')
    p = write(tmp_path, f"Solid {{ name \"a\" children [ {shape} ] }}\nSolid {{ name \"b\" children [ {shape} ] }}\n")
    w = load_world(p)
    assert w.world.solids[0].shapes[0].appearance.base_color == (0.5, 0.2, 0.2)
    notes = [x for x in w.warnings if "not loaded" in x]
    assert notes == [f"{p}:2:99: 2 textures not loaded (first: texture file 'a.png' not found (urls are relative to "
                     "the world file)); read as Webots reads a texture it cannot load: an Appearance as its material's "
                     "diffuseColor, a PBRAppearance as its baseColor"]


def test_mangled_worlds_fail_cleanly(tmp_path: Path) -> None:
    """Cut, garbled and truncated copies of full.wbt: each loads or raises WorldError, nothing else."""
    import random

    src = (HERE / "full.wbt").read_text()
    rng = random.Random(11)
    junk = ["{", "}", "[", "]", '"', "USE OB", "DEF X", "NULL", "TRUE", "-1", "1e400", "0", "Solid {", "Robot {",
            "#", "\n", ",", "HingeJoint {", "E-puck {}", "size", "Box {}", "'"]
    p = tmp_path / "m.wbt"
    outcomes = set()
    for _ in range(150):
        s = src
        for _ in range(rng.randint(1, 3)):
            k = rng.randrange(len(s)) if s else 0
            op = rng.random()
            s = s[:k] + s[k + rng.randint(1, 20):] if op < 0.35 else s[:k] + f" {rng.choice(junk)} " + s[k:] if op < 0.8 else s[:k]
        p.write_text(s)
        try:
            load_world(p)
            outcomes.add("ok")
        except WorldError as exc:
            assert str(exc).startswith(f"{p}: ") and "\n" not in str(exc).split(": ", 1)[0]
            outcomes.add("error")
    assert outcomes == {"ok", "error"}


def test_repeated_device_names_get_a_suffix(tmp_path: Path) -> None:
    p = write(tmp_path, 'Robot { name "r" children [ DistanceSensor { } DistanceSensor { translation 0 0 0.1 }\n'
                        '  LightSensor { name "distance sensor(1)" } ] }\n')
    w = load_world(p)
    # the third name was taken by the rename of the second: it moves on in turn
    assert [d.name for d in w.world.robots[0].devices] == ["distance sensor", "distance sensor(1)", "distance sensor(1)(1)"]
    assert f"{p}:2:48: device name 'distance sensor' used before in robot 'r': renamed 'distance sensor(1)'" in w.warnings


def test_a_robot_name_with_a_slash_is_one_topic_segment_said_at_load(tmp_path: Path) -> None:
    """ABB's IRB 4600 PROTO names its robot 'IRB 4600/40': a '/' cannot be in a topic path's robot
    segment, so the import renames it (once, said at its line) instead of refusing the world; a second
    one is renamed as any repeated name is."""
    p = write(tmp_path, 'Robot { name "IRB 4600/40" }\nRobot { name "IRB 4600/40" translation 1 0 0 }\n')
    w = load_world(p)
    assert [r.name for r in w.world.robots] == ["IRB 4600_40", "IRB 4600_40(1)"]
    assert (f"{p}:2:1: robot name 'IRB 4600/40' holds '/', which topic paths cannot: renamed 'IRB 4600_40' "
            "(getName() reads it)") in w.warnings
    assert f"{p}:3:1: robot name 'IRB 4600_40' used before: renamed 'IRB 4600_40(1)'" in w.warnings


def test_def_use_walk_is_bounded_without_shapes(tmp_path: Path, monkeypatch) -> None:
    from sensorium.server.world.wbt import convert

    monkeypatch.setattr(convert, "MAX_VISITS", 5000)
    levels = ["DEF L0 Group { }"] + [f"DEF L{i} Group {{ children [ USE L{i - 1} USE L{i - 1} ] }}" for i in range(1, 16)]
    with pytest.raises(WorldError, match="more than 5000 nodes to walk after DEF/USE expansion"):
        load_world(write(tmp_path, "\n".join(levels) + "\n"))
    # the same inside a boundingObject (walked by another path)
    bomb = "Solid { boundingObject Group { children [\n" + "\n".join(levels) + "\n] } }\n"
    with pytest.raises(WorldError, match="more than 5000 nodes to walk"):
        load_world(write(tmp_path, bomb))


def test_simulated_device_kinds_read_their_own_fields(tmp_path: Path) -> None:
    """GPS, Compass, InertialUnit, ... take their .wbt fields (once left at their defaults in
    silence); a field the model does not have is said."""
    p = write(tmp_path, 'Robot { children [ GPS { accuracy 0.5 noiseCorrelation 0.9 speedNoise 0.1 }\n'
                        '  Compass { lookupTable [ -1 -1 0, 1 1 0 ] yAxis FALSE } Altimeter { accuracy 0.2 wobble 3 } ] }\n')
    w = load_world(p)
    gps, compass, alt = w.world.robots[0].devices
    assert (gps.accuracy, gps.noise_correlation, gps.speed_noise) == (0.5, 0.9, 0.1)
    assert compass.lookup_table == [(-1.0, -1.0, 0.0), (1.0, 1.0, 0.0)] and compass.y_axis is False
    assert alt.accuracy == 0.2
    assert any("Altimeter.wobble: not read here" in x for x in w.warnings)


def test_a_track_lists_its_motor_and_places_its_wheels(tmp_path: Path) -> None:
    """A tracked robot written as Webots' Track sample is: each Track's motor is in the Track's
    ``device`` field and its wheels are TrackWheels, placed at (position.x, 0, position.y) in the
    Track's frame (WbTrackWheel). The motors were silently missing (getDevice found nothing) and the
    wheels were dropped as unknown nodes; now the wheels' shapes are where Webots draws them, the
    belt Webots animates along them is in the skipped summary, and the two motors are the robot's
    drive (tests/test_wbt_tracks.py drives it), listed as the LinearMotors they are (Webots' type)."""
    def track(side: str, y: float) -> str:
        return (f'Track {{ translation 0 {y} 0 name "{side} track" children [\n'
                f'  TrackWheel {{ position -0.15 0.0075 radius 0.046 children [ Shape {{ geometry Cylinder {{ '
                f'radius 0.046 height 0.015 }} }} ] }}\n'
                f'  TrackWheel {{ position 0.0925 -0.044 radius 0.02 children [ Pose {{ rotation 1 0 0 1.5708 '
                f'children [ Shape {{ geometry Sphere {{ radius 0.02 }} }} ] }} ] }}\n'
                f'] device [ LinearMotor {{ name "{side} motor" }} PositionSensor {{ name "{side} sensor" }} ]\n'
                f'  animatedGeometry Shape {{ geometry Box {{ size 0.022 0.015 0.0025 }} }} geometriesCount 40 }}\n')
    p = write(tmp_path, 'Robot { name "tank" translation 0 0 0.07 children [\n'
              'Shape { geometry Box { size 0.3 0.13 0.08 } }\n' + track("left", 0.07) + track("right", -0.07) + '] }\n')
    w = load_world(p)
    assert not w.report.losses
    (robot,) = w.world.robots
    assert [(d.device, d.name) for d in robot.devices] == [
        ("LinearMotor", "left motor"), ("PositionSensor", "left sensor"),
        ("LinearMotor", "right motor"), ("PositionSensor", "right sensor")]
    assert [(s.geometry.type, s.pose.translation) for s in robot.shapes] == [
        ("box", (0.0, 0.0, 0.0)), ("cylinder", (-0.15, 0.07, 0.0075)), ("sphere", (0.0925, 0.07, -0.044)),
        ("cylinder", (-0.15, -0.07, 0.0075)), ("sphere", (0.0925, -0.07, -0.044))]
    assert [x for x in w.warnings if "Track" in x] == [
        f"{p}: skipped nodes that do not matter to these sensors: Track.animatedGeometry x2"]
    assert robot.differential_drive is not None and robot.differential_drive.axle_length == 0.14
    entries = Simulation(w).robot("tank").device_list     # what a controller's getDevice finds (the drive's motors)
    assert [(e.name, e.simulated) for e in entries if e.name.endswith("motor")] == [
        ("left motor", True), ("right motor", True)]


def test_a_track_with_a_motor_alone_is_said_without_a_sensor(tmp_path: Path) -> None:
    """A conveyor belt as Webots builds one (a Robot whose Track holds a LinearMotor and no
    PositionSensor): its line said "(its sensor reads it)" of a sensor it does not have. It is now a
    belt that carries (tests/test_conveyor_belt.py): its line says that, of no sensor."""
    p = write(tmp_path, 'Robot { name "belt" children [\n'
              'Track { translation 0 0 0.45 children [ DEF B Shape { geometry Box { size 8 0.7 0.3 } } ] '
              'boundingObject USE B device [ LinearMotor { name "belt_motor" maxVelocity 0.2 } ] }\n] }\n')
    w = load_world(p)
    assert [x.split(": ", 1)[1] for x in w.warnings if "Track" in x] == [
        "Track 'solid': its belt carries the solids with physics lying on its top face at its motor's velocity; "
        "its texture animation and wheels do not move here"]
    assert [(d.device, d.name) for d in w.world.robots[0].devices] == [("LinearMotor", "belt_motor")]


def test_a_device_not_simulated_is_said_in_the_load_report(tmp_path: Path) -> None:
    """A Microphone is listed (a controller's getDevice finds it, its functions answer Webots' "no
    value") but not simulated: the load report says so, one line at the device's own place, so
    `validate` no longer answers a plain OK for a world whose microphone hears nothing. A Radar, a
    Display, a Speaker and a VacuumGripper are simulated: nothing is said of them."""
    p = write(tmp_path, 'Robot { name "r" children [\n'
              'Radar { maxRange 1.5 }\nDisplay { name "screen" width 14 height 14 }\nGPS { }\nMicrophone { }\n'
              'Speaker { }\nVacuumGripper { }\n] }\n')
    w = load_world(p)
    assert not w.report.losses
    assert w.warnings == [
        f"{p}:6:1: Microphone 'microphone' of robot 'r': listed (a controller finds it), not simulated here: its functions "
        "answer Webots' \"no value\""]


def test_world_info_gravity_and_gps_coordinates_are_read(tmp_path: Path) -> None:
    """WorldInfo's gravity (what an accelerometer at rest reads), gpsCoordinateSystem and
    gpsReference were left out of a .wbt world without a word: a WGS84 world's GPS read local
    metres and a Mars world's accelerometer read the Earth's gravity."""
    p = write(tmp_path, 'WorldInfo { gravity 3.71 gpsCoordinateSystem "WGS84" gpsReference 40.67 -73.94 10 }\n'
                        'Robot { name "r" children [ GPS { } Accelerometer { } ] }\n')
    w = load_world(p)
    info = w.world.world_info
    assert (info.gravity, info.gps_coordinate_system, info.gps_reference) == (3.71, "WGS84", (40.67, -73.94, 10.0))
    sim = Simulation(w)
    gps, acc = sim.device("r/gps"), sim.device("r/accelerometer")
    gps.enable(32)
    acc.enable(32)
    sim.step()
    assert gps.values == pytest.approx([40.67, -73.94, 10.0], abs=1e-9)    # the reference is the world's origin
    assert acc.values == pytest.approx([0.0, 0.0, 3.71], abs=1e-12)
    # local coordinates: the reference is added; another name is local, as Webots reads it, with a warning
    p = write(tmp_path, 'WorldInfo { gpsCoordinateSystem "UTM" gpsReference 1 2 3 }\nRobot { name "r" children [ GPS { } ] }\n')
    w = load_world(p)
    assert (w.world.world_info.gps_coordinate_system, w.world.world_info.gps_reference) == ("local", (1.0, 2.0, 3.0))
    assert w.warnings == [f"{p}:2:1: WorldInfo.gpsCoordinateSystem 'UTM' is neither \"WGS84\" nor \"local\": local "
                          "coordinates, as Webots returns for any value but \"WGS84\""]
    with pytest.raises(WorldError, match=r"gravity: -9.81 < 0 \(gravity pointing up\) is not supported here"):
        load_world(write(tmp_path, 'WorldInfo { gravity -9.81 }\n'))


def test_a_device_inside_its_robots_body_is_said(tmp_path: Path) -> None:
    """A range finder mounted just under the top of its robot's body cylinder (as Webots' own
    range-finder sample is): Webots culls the cylinder seen from inside and the device sees out;
    here the cylinder is seen from inside (README: a device inside a closed shape), and the load
    report now says so at the device, naming the shape. A device outside the body, an infra-red
    sensor inside a cylinder (Webots' picking sees cylinders from inside too) and the device's own
    housing are not reported."""
    p = write(tmp_path, 'Robot { name "r" children [\n'
              'Pose { translation 0 0 0.0415 children [ Shape { geometry Cylinder { radius 0.045 height 0.08 } } ] }\n'
              'RangeFinder { translation 0.031 0 0.08 children [ Shape { geometry Box { size 0.01 0.01 0.01 } } ] }\n'
              'Camera { translation 0.031 0 0.09 }\n'
              'DistanceSensor { translation 0.03 0 0.05 type "infra-red" }\n'
              '] }\n')
    w = load_world(p)
    assert w.warnings == [
        f"{p}:4:1: RangeFinder 'range-finder' of robot 'r' is inside the robot's cylinder (written at line 3, column 59): "
        "its rays see that shape from inside, where Webots' never do (back faces culled); mount the device outside it "
        "or make the shape part of the device's Solid"]


def test_a_device_inside_its_robots_mesh_body_sees_out(tmp_path: Path) -> None:
    """The iRobot Create's shape: a disc-like body written as an IndexedFaceSet with infra-red cliff
    sensors inside it, pointing down. Webots culls the triangles a ray meets from behind (its
    infra-red picking and its renderer), so they see the floor; here the mesh was seen from inside
    and a sensor 5 cm above the floor read the body's floor plate 3.5 cm below it, with no word.
    Now the mesh is split so that each device inside it is blind to the triangles facing away from
    it: the cliff sensor reads the floor (1000 at 0 m to 0 at 0.2 m: 750), a sensor over a plate
    of the same mesh that faces up reads the plate (900) and one under it looking up sees nothing
    (the plate's back, the body's top from inside: 0), as in Webots; nothing is said."""
    ring = [(0.15 * math.cos(k * math.pi / 3), 0.15 * math.sin(k * math.pi / 3)) for k in range(6)]
    points = " ".join(f"{x:.6f} {y:.6f} {z}" for z in (-0.035, 0.035) for x, y in ring)
    points += " 0.05 -0.03 0, 0.13 -0.03 0, 0.13 0.03 0, 0.05 0.03 0"          # 12-15: a plate facing up
    faces = ("5 4 3 2 1 0 -1 6 7 8 9 10 11 -1 "                               # bottom (seen from below), top
             + " ".join(f"{k} {(k + 1) % 6} {(k + 1) % 6 + 6} {k + 6} -1" for k in range(6)) + " 12 13 14 15 -1")
    table = 'lookupTable [ 0 1000 0 0.2 0 0 ] type "infra-red"'
    p = write(tmp_path, 'Solid { children [ Shape { geometry Plane { size 10 10 } } ] }\n'
              'Robot { name "r" translation 0 0 0.05 children [\n'
              f'Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point [ {points} ] }} coordIndex [ {faces} ] }} }}\n'
              f'DistanceSensor {{ translation -0.1 0 0 rotation 0 1 0 1.5708 name "cliff" {table} }}\n'
              f'DistanceSensor {{ translation 0.1 0 0.02 rotation 0 1 0 1.5708 name "over plate" {table} }}\n'
              f'DistanceSensor {{ translation 0.1 0 -0.02 rotation 0 1 0 -1.5708 name "under plate" {table} }}\n'
              'Camera { translation -0.05 0 0.01 }\n'
              '] }\n')
    w = load_world(p)
    assert w.warnings == []
    sim = Simulation(w)
    for name in ("cliff", "over plate", "under plate"):
        sim.device(f"r/{name}").enable(32)
    sim.step()
    assert sim.device("r/cliff").value == pytest.approx(1000 * (1 - 0.05 / 0.2), abs=1e-6)
    assert sim.device("r/over plate").value == pytest.approx(1000 * (1 - 0.02 / 0.2), abs=1e-6)
    assert sim.device("r/under plate").value == 0.0
    # the body's triangles, split by the devices they face away from (the camera's too)
    split = {tuple(part.unseen_by): len(part.geometry.faces) for part in w.world.robots[0].shapes}
    assert sum(split.values()) == 2 * 4 + 6 * 2 + 2 and ("camera", "cliff", "over plate", "under plate") in split
    # written ccw FALSE, its fronts are not judged: the mesh stays whole, seen from inside (the plate 3.5 cm below)
    w = load_world(write(tmp_path, p.read_text().replace("IndexedFaceSet {", "IndexedFaceSet { ccw FALSE")))
    assert [part.unseen_by for part in w.world.robots[0].shapes] == [[]]
    sim = Simulation(w)
    sim.device("r/cliff").enable(32)
    sim.step()
    assert sim.device("r/cliff").value == pytest.approx(1000 * (1 - 0.035 / 0.2), abs=1e-6)


def test_the_batched_simulation_hides_the_turned_away_faces_too(tmp_path: Path) -> None:
    """The split mesh of the test above, two copies at different poses: each copy's cliff sensor
    reads what the single simulation reads, the floor 5 cm below (750), bit for bit."""
    from sensorium.server.sim.batched import BatchedSimulation

    ring = [(0.15 * math.cos(k * math.pi / 3), 0.15 * math.sin(k * math.pi / 3)) for k in range(6)]
    points = " ".join(f"{x:.6f} {y:.6f} {z}" for z in (-0.035, 0.035) for x, y in ring)
    faces = "5 4 3 2 1 0 -1 6 7 8 9 10 11 -1 " + " ".join(f"{k} {(k + 1) % 6} {(k + 1) % 6 + 6} {k + 6} -1" for k in range(6))
    p = write(tmp_path, 'Solid { children [ Shape { geometry Plane { size 10 10 } } ] }\n'
              'Robot { name "r" translation 0 0 0.05 children [\n'
              f'Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point [ {points} ] }} coordIndex [ {faces} ] }} }}\n'
              'DistanceSensor { translation -0.1 0 0 rotation 0 1 0 1.5708 name "cliff" '
              'lookupTable [ 0 1000 0 0.2 0 0 ] type "infra-red" }\n] }\n')
    bs = BatchedSimulation(load_world(p), 2)
    sims = [Simulation(load_world(p)) for _ in range(2)]
    bs.set_pose(1, 0, [0.5, 0.2, 0.05], rotation=[0, 0, 1, 0.3])
    sims[1].robot("r").set_pose([0.5, 0.2, 0.05], rotation=[0, 0, 1, 0.3])
    bs.enable(bs.device("r", "cliff"), 32)
    for s in sims:
        s.device("r/cliff").enable(32)
    bs.run(2)
    for c, s in enumerate(sims):
        s.run(2)
        assert s.device("r/cliff").value == float(bs.value(bs.device("r", "cliff"))[c]) == pytest.approx(750.0, abs=1e-6)


def test_unseen_by_names_devices_of_its_robot(tmp_path: Path) -> None:
    """A world file's ``unseen_by`` (what the .wbt import writes for a split mesh) must name devices
    of the shape's robot, like ``of_device``."""
    p = tmp_path / "w.yaml"
    p.write_text("robots:\n  - name: r\n    devices: [{device: DistanceSensor, name: ds}]\n"
                 "    shapes: [{geometry: {type: box, size: [0.1, 0.1, 0.1]}, seen_by: visual, unseen_by: [ds, dz]}]\n")
    with pytest.raises(WorldError, match=r"robots\[0\] \(r\)\.shapes\[0\]\.unseen_by\[1\]: 'dz' is not a device of this robot \(devices: 'ds'\)"):
        load_world(p)


def test_a_camera_in_a_shape_closer_than_its_near_plane_is_not_said(tmp_path: Path) -> None:
    """Webots' binocular sample: each camera sits at the centre of its neighbouring distance sensor's
    small housing (a cylinder of radius 8 mm, 4 mm high: every point within 8.25 mm of the camera,
    under the camera's near of 1 cm). Its rays start at the near plane, here as in Webots, so the
    image never shows the housing, yet the load report said the camera was "inside the robot's
    cylinder". Now said only when the shape reaches past ``near``: not for the housing, still for the
    same camera with ``near 0.005``, and for a range finder inside the 4.5 cm body."""
    def robot(near: str, housing: bool = True) -> str:
        return ('DirectionalLight { direction 0 0 -1 ambientIntensity 1 }\n'
                'Solid { translation 0.5 0.02 0.063 children [ Shape { appearance PBRAppearance { baseColor 1 0 0 } '
                'geometry Box { size 0.1 0.2 0.2 } } ] }\n'
                'Robot { name "r" children [\n'
                'DistanceSensor { translation 0.042 0.02 0.063 name "ds0" children [ Pose { rotation 1 0 0 1.5708 '
                f'children [ Shape {{ geometry Cylinder {{ radius 0.008 height {0.004 if housing else 0.0001} }} }} ] }} ] }}\n'
                f'Camera {{ translation 0.042 0.02 0.063 name "camera0" {near} }}\n'
                'Pose { translation 0 0 0.0415 children [ Shape { geometry Cylinder { radius 0.045 height 0.08 } } ] }\n'
                'RangeFinder { translation 0.031 0 0.05 }\n] }\n')

    w = load_world(write(tmp_path, robot("")))
    said = [x for x in w.warnings if "is inside the robot's" in x]
    assert [x.split(": ", 1)[1].split(" is inside")[0] for x in said] == ["RangeFinder 'range-finder' of robot 'r'"]
    images = []
    for world in (w, load_world(write(tmp_path, robot("", housing=False)))):
        sim = Simulation(world)
        sim.device("r/camera0").enable(16)
        sim.step()
        sim.step()
        images.append(np.asarray(sim.device("r/camera0").image))
    assert np.array_equal(images[0], images[1])              # the housing is never in the image
    assert np.any(images[0][..., 2] > 2 * images[0][..., 1].astype(int) + 20)   # the red box is (BGRA)
    w = load_world(write(tmp_path, robot("near 0.005")))
    said = [x.split(": ", 1)[1].split(" is inside")[0] for x in w.warnings if "is inside the robot's" in x]
    assert said == ["Camera 'camera0' of robot 'r'", "RangeFinder 'range-finder' of robot 'r'"]


def test_camera_fields_the_renderer_uses_and_rays_do_not_are_said(tmp_path: Path) -> None:
    """Motion blur and the other image effects of Webots' renderer (README: what a rasterising GPU
    gives that this does not) were dropped from a .wbt camera without a word; each one a world
    writes (with a value that does something in Webots) is now one warning. The lens is read
    (tests/test_lens.py), not said, and so is a camera's and a range finder's motion blur
    (tests/test_camera_effects.py); a camera's bloom is said."""
    p = write(tmp_path, 'Robot { name "r" children [\n'
              'Camera { lens Lens { radialCoefficients 0.2 0 } motionBlur 100 bloomThreshold -1 zoom NULL }\n'
              'RangeFinder { motionBlur 40 }\n'
              'Camera { name "bright" bloomThreshold 10 }\n] }\n')
    w = load_world(p)
    assert w.warnings == [
        f"{p}:5:1: Camera 'bright' of robot 'r': {field} is not rendered here; the image is Webots' "
        "without it" for field in ("bloomThreshold (bloom)",)]
    assert w.world.robots[0].devices[0].lens == wm.Lens(radial_coefficients=(0.2, 0.0))
    assert [d.motion_blur for d in w.world.robots[0].devices] == [100.0, 40.0, 0.0]


def test_a_robots_battery_and_a_charger_are_read(tmp_path: Path) -> None:
    """Webots' battery sample: a robot with a ``battery`` (its controller reads the battery sensor)
    and Chargers around it. The battery was dropped without a word, then one line (its sensor read
    NaN); both are now read (README "Battery and Charger"), without a line: the robot has no physics,
    so its motors would consume nothing in Webots either; the Charger's shapes are kept as a solid."""
    p = write(tmp_path, 'Robot { name "r" battery [ 50, 100, 30 ] cpuConsumption 0.5 }\n'
              'Charger { name "charger0" battery [ 100, 100, 3 ] children [ Shape { geometry Cylinder { radius 0.1 '
              'height 0.3 } } ] }\n')
    w = load_world(p)
    assert not w.report.losses and w.warnings == []
    (robot,) = w.world.robots
    assert (robot.battery, robot.cpu_consumption) == ([50.0, 100.0, 30.0], 0.5)
    assert w.world.chargers == [wm.Charger(solid="charger0", battery=[100.0, 100.0, 3.0], radius=0.04)]
    assert [(s.name, [x.geometry.type for x in s.shapes]) for s in w.world.solids] == [("charger0", ["cylinder"])]


def test_robot_self_collision_is_read(tmp_path: Path) -> None:
    """Robot.selfCollision was not read from a .wbt world: a generic distance sensor never saw its
    own robot's bounding objects, as if it were FALSE (README: ODE-style rays skip the whole robot
    unless ``self_collision``)."""
    def world(flag: str) -> str:
        return (f'Robot {{ name "r" selfCollision {flag} children [\n'
                'DistanceSensor { lookupTable [ 0 0 0, 1 1000 0 ] }\n'
                'Solid { translation 0.5 0 0 boundingObject Box { size 0.1 1 1 } }\n] }\n')
    for flag, expected in (("TRUE", 450.0), ("FALSE", 1000.0)):
        w = load_world(write(tmp_path, world(flag)))
        assert w.world.robots[0].self_collision is (flag == "TRUE")
        sim = Simulation(w)
        ds = sim.device("r/distance sensor")
        ds.enable(32)
        sim.step()
        assert ds.value == pytest.approx(expected)


def test_an_open_cylinder_used_twice_is_said_once(tmp_path: Path) -> None:
    """Webots' motor sample: the robot's base is a Group holding a Cylinder with ``bottom FALSE``,
    USEd again as the robot's boundingObject. The warning that rays see it closed is about the one
    node the file writes, so it is said once at its line (it was said twice, the same line)."""
    p = write(tmp_path, 'Robot { name "r" children [ DEF BASE Group { children [ Pose { translation 0 0 0.019 '
              'children [ Shape { geometry Cylinder { bottom FALSE height 0.04 radius 0.1 } } ] } ] } ]\n'
              ' boundingObject USE BASE }\n')
    w = load_world(p)
    assert [x for x in w.warnings if "bottom/side/top" in x] == [
        f"{p}:2:114: Cylinder with bottom/side/top FALSE: rays see the whole closed cylinder"]


def test_a_cameras_zoom_is_read_as_the_range_set_fov_takes(tmp_path: Path) -> None:
    """A Zoom (the e-puck's camera has one, Webots' defaults) is the range a controller's setFov() may
    take. It was not read (one line said so, and setFov took only the field of view); now it is the
    camera's ``zoom``, without a word, and reset as WbZoom resets it (a negative minFieldOfView is 0,
    one above maxFieldOfView is maxFieldOfView, each said)."""
    p = write(tmp_path, 'Robot { name "r" children [\n'
              'Camera { fieldOfView 0.84 zoom Zoom { } }\n'
              'Camera { name "tele" zoom Zoom { minFieldOfView 0.2 maxFieldOfView 1 } }\n'
              'Camera { name "odd" zoom Zoom { minFieldOfView 2 maxFieldOfView 1 } }\n'
              'Camera { name "neg" zoom Zoom { minFieldOfView -1 } }\n] }\n')
    w = load_world(p)
    zooms = [(d.name, d.zoom) for d in w.world.robots[0].devices]
    assert zooms == [("camera", wm.Zoom(min_field_of_view=0.5, max_field_of_view=1.5)),
                     ("tele", wm.Zoom(min_field_of_view=0.2, max_field_of_view=1.0)),
                     ("odd", wm.Zoom(min_field_of_view=1.0, max_field_of_view=1.0)),
                     ("neg", wm.Zoom(min_field_of_view=0.0, max_field_of_view=1.5))]
    assert [x.split(": ", 1)[1] for x in w.warnings] == [
        "Zoom.minFieldOfView: 2 is > maxFieldOfView 1; using 1 (as Webots does)",
        "Zoom.minFieldOfView: -1 is negative; using 0 (as Webots does)"]
