"""getFromProtoDef (C ``wb_supervisor_node_get_from_proto_def``, C++ ``Node::getFromProtoDef``) on Sensorium's
own PROTOs (tests/protos/protodef, tests/worlds/proto/supervisor_proto_def.wbt): a PROTO instance's body nodes
found by their DEF and read as any node (fields, parent, world position), Webots' scope (the instance's own body
and what it holds; a nested PROTO instance's body is that instance's), a DEF used twice (the DEF'd node, not its
USE), and the NULLs: no such DEF, a DEF naming a node Sensorium serves none for (a line saying why), a node that
is no PROTO instance, a NULL or empty DEF. Python and C (AddressSanitizer, UBSan) print the same; the C++ classes
find them too."""

from __future__ import annotations

import sys

import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import nested
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

WORLD = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_def.wbt"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
EXPECTED = ["chassis Pose 1 0 0 0.05", "shape Shape 1", "paint PBRAppearance 0.2 0.4 0.6 0.5", "hull Box 0.2 0.1 0.05",
            "eye DistanceSensor eye 1.1 0 0.05", "arm Arm Solid 1", "tool tool 1 0 0.4 1", "elbow 1 Pose grip 1",
            "given 1", "top Pose Shape 0 1", "none 1 1 1 1 1 1", "board Solid board 0 2 0.5", "leg Shape 0.5 0.3 0.1",
            "bulb PointLight 1 0 0 0.6"]
FUNC = "wb_supervisor_node_get_from_proto_def"


def _sim() -> Simulation:
    return Simulation(load_world(WORLD))


def _found(sim, instance, name):
    node, note = sv.from_proto_def(sim, instance, name)
    return node, note


def test_the_body_nodes_are_found_by_their_def():
    sim = _sim()
    rover, shelf = sv.find_node(sim, "ROVER"), sv.find_node(sim, "SHELF")
    chassis, note = _found(sim, rover, "CHASSIS")
    assert (chassis.type, chassis.def_name, note) == ("Pose", "", "")       # an internal node: getDef is ''
    assert sv.find_node(sim, "CHASSIS") is None                             # getFromDef does not find it (Webots)
    assert sv.node_ref(sim, chassis)["parent"] == rover.id
    eye, _ = _found(sim, rover, "EYE")
    assert (eye.type, eye.name) == ("DistanceSensor", "eye")
    assert sv.node_pose(sim, eye)["position"] == pytest.approx([1.1, 0.0, 0.05], abs=1e-12)
    # a shape and its nodes: the DEF'd Shape (under CHASSIS), not its USE under TOP
    shape, _ = _found(sim, rover, "HULL_SHAPE")
    assert shape.type == "Shape" and sv.node_ref(sim, shape)["parent"] == chassis.id
    paint, _ = _found(sim, rover, "PAINT")
    assert sv.get_field(sim, paint, "roughness")["value"] == 0.5
    hull, _ = _found(sim, rover, "HULL")
    assert sv.get_field(sim, hull, "size")["value"] == [0.2, 0.1, 0.05]
    board, _ = _found(sim, shelf, "BOARD")                                  # a solid inside a top-level solid PROTO
    assert sv.node_pose(sim, board)["position"] == pytest.approx([0.0, 2.0, 0.5], abs=1e-12)
    wood, _ = _found(sim, shelf, "WOOD")
    assert sv.get_field(sim, wood, "diffuseColor")["value"] == [0.5, 0.3, 0.1]


def test_a_nested_proto_instances_body_is_its_own_scope():
    sim = _sim()
    rover = sv.find_node(sim, "ROVER")
    arm, _ = _found(sim, rover, "ARM")            # written in Rover's body: Rover's
    assert (arm.proto, arm.type) == ("Arm", "Solid")
    assert _found(sim, rover, "ELBOW") == (None, "")          # Arm's body: not Rover's scope (Webots)
    assert _found(sim, rover, "GRIP") == (None, "")
    elbow, _ = _found(sim, arm, "ELBOW")
    assert elbow.type == "Pose"
    assert _found(sim, arm, "CHASSIS") == (None, "")          # the outer body is not Arm's scope
    # written in Rover's body, held by Arm's slot: in both scopes, one node here (Webots: Arm's is a copy)
    tool, _ = _found(sim, rover, "TOOL")
    assert tool.id == _found(sim, arm, "TOOL")[0].id and sv.node_ref(sim, tool)["parent"] == elbow.id
    assert sv.node_pose(sim, tool)["position"] == pytest.approx([1.0, 0.0, 0.4], abs=1e-12)
    given, _ = _found(sim, rover, "GIVEN")        # the world's node in Rover's slot: the instance holds it (one node)
    assert given.id == sv.find_node(sim, "GIVEN").id


def test_a_derived_protos_instance_finds_the_defs_of_the_body_it_is_built_on():
    sim = _sim()
    big = sv.find_node(sim, "BIG")                 # BigShelf, built on Shelf: one node (Webots)
    board, note = _found(sim, big, "BOARD")
    assert (board.name, note) == ("board", "")
    assert sv.node_pose(sim, board)["position"] == pytest.approx([3.0, 0.0, 0.5], abs=1e-12)
    assert board.id != _found(sim, sv.find_node(sim, "SHELF"), "BOARD")[0].id


def test_the_nulls_say_why():
    sim = _sim()
    rover, shelf, box = sv.find_node(sim, "ROVER"), sv.find_node(sim, "SHELF"), sv.find_node(sim, "BOX")
    assert _found(sim, rover, "NOPE") == (None, "")           # no such DEF: Webots' NULL, no line
    assert _found(sim, rover, "ROVER") == (None, "")          # the instance's own DEF is the world's, not its body's
    node, why = _found(sim, rover, "MASS")
    assert node is None and "Physics node: physics only" in why and "DEF MASS of PROTO Rover's body" in why
    node, why = _found(sim, rover, "BOUND")
    assert node is None and "a Box geometry of no visible Shape" in why
    bulb, why = _found(sim, shelf, "BULB")        # a light of the body: a node, under the shelf
    assert (bulb.type, why, sv.node_ref(sim, bulb)["parent"]) == ("PointLight", "", shelf.id)
    assert sv.get_field(sim, bulb, "location")["value"] == [0.0, 0.0, 0.6]
    assert _found(sim, box, "INSIDE") == (None, "'node' is not a PROTO node")
    node, why = _found(sim, sv.find_node(sim, "LAMP"), "BULB")
    assert node is None and why.startswith("the body of PROTO Beacon (PointLight 'LAMP' (node 5)) is not searched")
    table = sv._table(sim)
    assert nested.inner_def(table, box.id, "INSIDE") is None


def test_the_service_answers_a_node_ref_and_its_note():
    lv = Live(_sim())
    lv.ok(A, "attach", {"robot": "rover"})
    eye = lv.ok(A, "/rover/robot/get_from_proto_def", {"node": 1, "name": "EYE"})
    assert (eye["type"], eye["name"], eye["def_name"], eye["note"]) == ("DistanceSensor", "eye", "", "")
    mass = lv.ok(A, "/rover/robot/get_from_proto_def", {"node": 1, "name": "MASS"})
    assert mass["type"] == "" and "physics only" in mass["note"]


def test_bad_requests_get_one_line():
    lv = Live(_sim())
    lv.ok(A, "attach", {"robot": "rover"})
    for args in ({"node": 1, "name": "X" * 4097}, {"node": 1, "name": ""}, {"node": 999, "name": "EYE"},
                 {"node": 1}, {"name": "EYE"}):
        lv.err(A, "/rover/robot/get_from_proto_def", args, ErrorCode.INVALID_ARGUMENT)
    dotted = lv.ok(A, "/rover/robot/get_from_proto_def", {"node": 1, "name": "CHASSIS.HULL_SHAPE"})
    assert (dotted["type"], dotted["note"]) == ("", "")       # a DEF name has no dot: none (Webots)
    root = lv.ok(A, "/rover/robot/get_from_proto_def", {"node": 0, "name": "EYE"})
    assert (root["type"], root["note"]) == ("", "'node' is not a PROTO node")


def _check_lines(err: str) -> None:
    lines = [x for x in err.splitlines() if x.startswith("Error:")]
    assert len(lines) == 4, err
    assert f"Error: {FUNC}() called with NULL or empty 'def' argument." in lines, err
    assert f"Error: {FUNC}(): 'node' is not a PROTO node." in lines, err
    assert sum(f"Error: {FUNC}(): DEF {name} of PROTO" in x for x in lines for name in ("MASS", "BOUND")) == 2, err


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_finds_the_body_nodes(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "supervisor_proto_def.py", "rover")
    assert ctl.out == EXPECTED
    _check_lines(ctl.stderr())


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_finds_the_same(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_proto_def.c")
    ctl = run_paused(WORLD, tmp_path, exe, "rover", env=SAN_ENV)
    assert ctl.out == EXPECTED
    err = ctl.stderr()
    assert "Sanitizer" not in err and "runtime error" not in err, err
    _check_lines(err)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_the_cpp_classes_find_them_too(tmp_path, tmp_path_factory):
    import shutil
    import subprocess

    from test_c_client import CLIB, _make

    if shutil.which("c++") is None:
        pytest.skip("needs a C++ toolchain")
    build = tmp_path_factory.mktemp("cppbuild")
    _make(f"BUILD={build}", "SANITIZE=1")
    exe = build / "supervisor_proto_def_cpp"
    done = subprocess.run(["c++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-g", "-fsanitize=address,undefined",
                           f"-I{CLIB / 'include'}", str(REPO / "tests" / "c" / "supervisor_proto_def_cpp.cpp"), "-o",
                           str(exe), str(build / "libController.a"), *_make("libs").split()],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    ctl = run_paused(WORLD, tmp_path, str(exe), "rover", env=SAN_ENV)
    assert ctl.out == ["DistanceSensor eye 1.1 0 0.05", "Arm Pose 1 1 1"]
    err = ctl.stderr()
    assert "Sanitizer" not in err and "runtime error" not in err, err
    assert [x for x in err.splitlines() if x.startswith("Error:")] == [
        f"Error: {FUNC}(): DEF MASS of PROTO Rover's body (Robot 'ROVER' (node 1)) names a Physics node: physics only, "
        "which Sensorium does not simulate (no Supervisor node here)."], err


def test_a_light_of_a_body_cannot_be_removed_with_webots_line():
    """Webots refuses a Supervisor's ``remove()`` of a node internal to a PROTO with one line naming it by
    its usefulName (its DEF and type); the light stays lit (it still reads as before)."""
    sim = _sim()
    bulb, _ = _found(sim, sv.find_node(sim, "SHELF"), "BULB")
    with pytest.raises(ValueError) as err:
        sv.remove_node(sim, bulb)
    assert str(err.value) == ("Node 'DEF BULB PointLight' is internal to a PROTO and therefore cannot be deleted "
                              "from a Supervisor.")
    assert sv.get_field(sim, bulb, "location")["value"] == [0.0, 0.0, 0.6]
    assert len(sim.scene.removed_carried) == 0
