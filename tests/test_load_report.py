"""Loading is honest (issue 27): what a world loses is said once, grouped and counted, by every
command; ``validate`` fails on losses sensors notice (robots, devices, shapes) and passes on visual-
or physics-only warnings; ``serve`` refuses a world whose robots were all lost; a controller asking
for a lost robot is told why."""

from __future__ import annotations

import warnings
from pathlib import Path

import msgpack
import pytest

from sensorium.cli import main
from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon.serve import refuse_robotless
from sensorium.server.daemon.services import Core
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import WorldError, load_world
from sensorium.server.world.report import WorldLossWarning

HEADER = "#VRML_SIM R2023b utf8\n"


def write(tmp_path: Path, body: str, name: str = "w.wbt") -> Path:
    p = tmp_path / name
    p.write_text(HEADER + body)
    return p


LOSSY = ('WorldInfo { }\n'                                                          # line 2
         'Solid { name "floor" children [ Shape { geometry DEF F Plane { size 2 2 } } ] boundingObject USE F }\n'
         'E-puck { name "e-puck" controller "braitenberg" }\n'                      # line 4: a robot PROTO not found
         'OilBarrel { }\n'                                                          # line 5: unknown, maybe anything
         'Solid { name "pillar" children [ Shape { geometry Mesh { url [ "gone.stl" ] } } ] }\n')   # line 6


def test_validate_fails_naming_each_loss_and_allow_skipped_accepts(tmp_path: Path, capsys) -> None:
    p = write(tmp_path, LOSSY)
    assert main(["validate", str(p)]) == 1
    err = capsys.readouterr().err
    assert f"{p}: 3 losses sensors notice (1 robot, 1 shape, 1 unknown node)" in err
    assert f"lost robot 'e-puck': {p}:4:1: E-puck: not a built-in node or PROTO here" in err
    assert f"lost unknown node 'OilBarrel': {p}:5:1: OilBarrel: not a built-in node or PROTO here" in err
    assert f"lost shape of 'pillar': {p}:6:51: mesh file 'gone.stl' not found" in err
    assert f"{p}: INVALID" in err
    assert main(["validate", str(p), "--allow-skipped"]) == 0
    assert capsys.readouterr().out.strip() == f"{p}: OK"


def test_visual_and_physics_only_differences_are_warnings(tmp_path: Path, capsys) -> None:
    """A Viewpoint, a Physics node, a texture that cannot be read, a joint that does not move: the
    sensors read the same; validate says so and exits 0."""
    p = write(tmp_path, 'Viewpoint { }\nBackground { }\n'
                        'Solid { children [ Shape { appearance Appearance { texture ImageTexture { url [ "no.png" ] } } '
                        'geometry Box { } } ] physics Physics { } }\n'
                        'Robot { name "arm" children [ HingeJoint { device [ RotationalMotor { name "m" } ] '
                        'endPoint Solid { } } ] }\n')
    assert main(["validate", str(p)]) == 0
    out = capsys.readouterr()
    assert out.out.strip() == f"{p}: OK"
    assert "losses" not in out.err and "warnings" in out.err
    assert load_world(p).losses == ()


def test_repeated_messages_are_grouped_with_their_count(tmp_path: Path) -> None:
    body = "".join(f'Solid {{ name "s{i}" children [ Shape {{ geometry Mesh {{ url [ "gone.stl" ] }} }} ] }}\n'
                   for i in range(5))
    report = load_world(write(tmp_path, "WorldInfo { }\n" + body)).report
    assert report.counts() == "5 losses sensors notice (5 shapes)"
    (line,) = report.lines()
    assert line.startswith(f"lost shape (x5, first at {tmp_path / 'w.wbt'}:3:")   # shapes of s0 ... s4
    assert line.endswith("mesh file 'gone.stl' not found (relative to the world file): this shape is left out")
    assert len(report.lines(every=True)) == 5


def test_serve_refuses_a_world_whose_robots_were_all_lost(tmp_path: Path, capsys) -> None:
    p = write(tmp_path, LOSSY)
    assert main(["serve", str(p), "--rpc", "tcp://127.0.0.1:0", "--pub", "tcp://127.0.0.1:0"]) == 1
    err = capsys.readouterr().err
    assert "every robot of this world was lost when it loaded (1 robot, 1 unknown node that may have been one)" in err
    assert f"lost robot 'e-puck': {p}:4:1" in err and "--allow-skipped" in err
    # a world that writes no robot at all is served as before (it runs by itself)
    refuse_robotless(load_world(write(tmp_path, 'WorldInfo { }\nSolid { }\n', "empty.wbt")))
    with pytest.raises(WorldError):
        refuse_robotless(load_world(p))


def _attach(core: Core, robot: str) -> dict:
    body = msgpack.packb({"id": 1, "service": "attach", "args": {"robot": robot}})
    (frames,) = core.handle([b"peer", body], 0.0)
    return msgpack.unpackb(frames[-1])


def test_a_controller_asking_for_a_lost_robot_is_told_why(tmp_path: Path) -> None:
    p = write(tmp_path, LOSSY + 'Robot { name "kept" }\n')
    core = Core(Simulation(load_world(p), "fast"), log=lambda line: None)
    reply = _attach(core, "e-puck")
    assert reply["ok"] is False and reply["error"]["code"] == ErrorCode.UNKNOWN_ROBOT
    assert reply["error"]["message"] == (
        f"no robot 'e-puck' (robots: kept); it was dropped when the world loaded: {p}:4:1: E-puck: not a built-in "
        "node or PROTO here; skipped (with everything inside it). Built-in PROTOs: CircleArena, Floor, RectangleArena, "
        "SolidBox, SolidPipe, TexturedBackgroundLight, WoodenBox")
    other = _attach(core, "scout")["error"]["message"]     # a name the world never wrote: the candidates
    assert other.startswith("no robot 'scout' (robots: kept); the world lost 2 nodes that may have been it")
    assert _attach(core, "kept")["ok"] is True


def test_in_process_loads_warn_once_and_keep_the_list(tmp_path: Path) -> None:
    p = write(tmp_path, LOSSY + 'Robot { name "kept" }\n')
    with pytest.warns(WorldLossWarning, match="3 losses sensors notice"):
        sim = Simulation.from_file(p, precision="fast")
    assert [(x.kind, x.name) for x in sim.loaded.losses] == [("robot", "e-puck"), ("node", "OilBarrel"),
                                                             ("shape", "pillar")]
    assert sim.loaded.dropped == [x.text for x in sim.loaded.losses]
    clean = write(tmp_path, 'WorldInfo { }\nRobot { name "r" }\n', "clean.wbt")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Simulation.from_file(clean, precision="fast")       # nothing lost: no warning


def test_a_device_outside_a_robot_keeps_its_shapes(tmp_path: Path) -> None:
    """Webots' devices are Solids: outside a robot they do nothing, but rays still see them."""
    p = write(tmp_path, 'DistanceSensor { translation 1 0 0 name "ds" children [ Shape { geometry Box { size 0.1 0.1 0.1 } } ] }\n'
                        'Camera { translation 2 0 0 children [ Shape { geometry Sphere { radius 0.05 } } ] }\n')
    w = load_world(p)
    assert [(s.name, s.pose.translation, s.shapes[0].geometry.type) for s in w.world.solids] == [
        ("ds", (1.0, 0.0, 0.0), "box"), ("camera", (2.0, 0.0, 0.0), "sphere")]
    assert w.losses == ()
    assert sum("outside a Robot: not a device here" in x for x in w.warnings) == 2


def test_cad_shapes_are_visual_meshes_or_said_lost(tmp_path: Path) -> None:
    """A CadShape (Webots' visual mesh) is seen by lidars and infra-red: read as a visual mesh when
    its format is read here, else a loss naming it (it was once skipped as if it did not matter).
    (COLLADA files: tests/test_dae.py.)"""
    (tmp_path / "part.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "part.fbx").write_bytes(b"Kaydara FBX Binary  \x00")
    p = write(tmp_path, 'Solid { name "s" children [ CadShape { url [ "part.obj" ] } CadShape { url [ "part.fbx" ] } ] }\n')
    w = load_world(p)
    (shape,) = w.world.solids[0].shapes
    assert (shape.geometry.type, shape.geometry.url, shape.seen_by) == ("mesh", "part.obj", "visual")
    (loss,) = w.losses
    assert (loss.kind, loss.name, loss.where) == ("shape", "s", f"{p}:2:61")   # the second CadShape
    assert "mesh 'part.fbx': the .fbx format is not read here" in loss.why


def test_a_wbt_load_times_each_stage() -> None:
    """What ``sensorium bench --only loading`` reads: wall seconds per stage of a .wbt load."""
    w = load_world(Path(__file__).parent / "worlds" / "proto" / "minipuck.wbt", proto_path=[])
    assert set(w.timings) == {"parse", "proto files", "instantiate", "template", "convert", "validate"}
    assert all(v >= 0.0 for v in w.timings.values()) and w.timings["template"] > 0.0


# Two wheels on one axle whose motors differ in maxVelocity (an Elisa-3's shape), or, with ``odd``,
# of different radii on two axles: each instance warns once, naming its robot in the second case.
def _duo_proto(odd: bool) -> str:
    z2, r2 = (0.03, 0.03) if odd else (0.02, 0.02)
    return (HEADER + 'PROTO Duo [ field SFVec3f translation 0 0 0 field SFString name "duo" ]\n{\n'
            '  Robot { translation IS translation name IS name children [\n'
            + ('' if odd else '    Shape { geometry Sphere { radius 0 } }\n') +      # one reset per instance
            '    HingeJoint { jointParameters HingeJointParameters { axis 0 1 0 anchor 0 0.03 0.02 }\n'
            '      device [ RotationalMotor { name "left" maxVelocity 10 } ]\n'
            '      endPoint Solid { translation 0 0.03 0.02 rotation 1 0 0 1.5708 children [ Shape { geometry '
            'Cylinder { radius 0.02 height 0.01 } } ] } }\n'
            f'    HingeJoint {{ jointParameters HingeJointParameters {{ axis 0 1 0 anchor 0 -0.03 {z2} }}\n'
            '      device [ RotationalMotor { name "right" maxVelocity 12 } ]\n'
            f'      endPoint Solid {{ translation 0 -0.03 {z2} rotation 1 0 0 1.5708 children [ Shape {{ geometry '
            f'Cylinder {{ radius {r2} height 0.01 }} }} ] }} }}\n'
            '  ] }\n}\n')


def _duos(tmp_path: Path, n: int, odd: bool = False) -> Path:
    (tmp_path / "protos").mkdir(exist_ok=True)
    (tmp_path / "protos" / "Duo.proto").write_text(_duo_proto(odd))
    robots = "".join(f'Duo {{ translation {i} 0 0 name "duo{i}" }}\n' for i in range(n))
    return write(tmp_path, 'EXTERNPROTO "protos/Duo.proto"\nWorldInfo { }\n' + robots)


def test_identical_warnings_of_many_robots_fold_into_one_line_with_their_first_places(tmp_path: Path) -> None:
    p = _duos(tmp_path, 10)
    report = load_world(p).report
    assert report.counts() == "10 warnings"
    proto = tmp_path / "protos" / "Duo.proto"
    (line,) = report.lines()
    assert line == (f"warning (x10, first at {proto}:5:31 (in PROTO Duo at {p}:4:1); then PROTO Duo at {p}:5:1, "
                    f"PROTO Duo at {p}:6:1 and 7 more): Sphere.radius: 0 is not > 0; using 1 (as Webots does)")
    assert len(report.lines(every=True)) == 10 and len(report.warnings) == 10    # every one kept


def test_warnings_the_same_but_for_the_robot_they_name_fold_into_one_line_naming_the_robots(tmp_path: Path) -> None:
    p = _duos(tmp_path, 10, odd=True)
    report = load_world(p).report
    lines = report.lines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("warning (x10, first at ")
    assert lines[0].endswith("): robots 'duo0', 'duo1', 'duo2' and 7 more: no differential drive (the two wheel "
                             "anchors are not on one axle parallel to the robot's y axis); the robot will not move")
    every = report.lines(every=True)
    assert [w.split(": ", 2)[2].split(":")[0] for w in every] == [f"robot 'duo{i}'" for i in range(10)]
    # two robots: both named; a distinct message stays a line of its own
    (tmp_path / "two").mkdir()
    p2 = _duos(tmp_path / "two", 2, odd=True)
    two = load_world(p2).report.lines()
    assert len(two) == 1 and "): robots 'duo0' and 'duo1': no differential drive" in two[0]


def test_distinct_messages_are_never_folded(tmp_path: Path) -> None:
    from sensorium.server.world.report import LoadReport

    report = LoadReport("w", warnings=("a.wbt:1:1: robot 'x': no drive (one)", "a.wbt:2:1: robot 'y': no drive (two)",
                                       "a.wbt:3:1: robot 'z': no drive (one)", "a.wbt:4:1: robot 'y': no drive (one)"))
    assert report.lines() == ["warning (x3, first at a.wbt:1:1; then a.wbt:3:1, a.wbt:4:1): robots 'x', 'z' and 'y': "
                              "no drive (one)", "warning: a.wbt:2:1: robot 'y': no drive (two)"]
    # one PROTO instance repeating a message at several lines of its PROTO: the later lines alone
    inst = " (in PROTO P at w.wbt:9:1)"
    one = LoadReport("w", warnings=tuple(f"P.proto:{n}:5{inst}: a sensor without a motor" for n in (3, 7, 11, 15)))
    assert one.lines() == [f"warning (x4, first at P.proto:3:5{inst}; then P.proto:7:5, P.proto:11:5 and 1 more): "
                           "a sensor without a motor"]
    named_twice = LoadReport("w", warnings=("a.wbt:1:1: robot 'x': a", "a.wbt:2:1: robot 'x': a"))
    assert named_twice.lines() == ["warning (x2, first at a.wbt:1:1; then a.wbt:2:1): robot 'x': a"]


def test_validate_folds_repeats_and_lists_each_with_every(tmp_path: Path, capsys) -> None:
    p = _duos(tmp_path, 10)
    assert main(["validate", str(p)]) == 0
    out = capsys.readouterr()
    assert out.out.strip() == f"{p}: OK"
    assert out.err.splitlines()[0] == f"{p}: 10 warnings" and len(out.err.splitlines()) == 2
    assert "warning (x10, first at " in out.err
    assert main(["validate", "--every", str(p)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 11 and all(line.startswith("  warning: ") for line in err[1:])
