"""Fields by index: a base node's ``getNumberOfFields``/``getFieldByIndex`` and any node's
``getNumberOfBaseNodeFields``/``getBaseNodeFieldByIndex`` (C ``wb_supervisor_node_get_number_of_fields``, ...)
count and list the fields Sensorium serves for the node, in Webots' declaration order (its nodes' .wrl files:
a Solid's translation, rotation, children, name, model, radarCrossSection; a Robot's then controller,
customData, supervisor, synchronization; ...); ``getFromProtoDef`` on a body without that DEF, a base node and
an empty DEF answers NULL (Webots' lines; tests/test_supervisor_proto_def.py for the nodes it finds). Python
and C (AddressSanitizer, UBSan) print the same on tests/worlds/proto/supervisor_proto_harden.wbt."""

from __future__ import annotations

import sys

import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HARDEN = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_harden.wbt"
NESTED = REPO / "tests" / "worlds" / "nested_nodes.wbt"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
SOLID = ["translation", "rotation", "children", "name", "model", "radarCrossSection"]
ROBOT = SOLID + ["controller", "customData", "supervisor", "synchronization", "battery", "cpuConsumption"]
INFO = ["title", "gravity", "basicTimeStep", "inkEvaporation", "coordinateSystem", "gpsCoordinateSystem",
        "gpsReference", "randomSeed"]
EXPECTED = [" ".join(["box", "6", *SOLID]), " ".join(["boxbase", "6", *SOLID]), " ".join(["info", "8", *INFO]),
            " ".join(["keeper", "14", "12", *ROBOT]), "controller SFString <extern>", "translation -1 0 0.1", "bad 1 1", "protodef 1 1 1 1"]


def _live(world=HARDEN) -> Live:
    lv = Live(Simulation(load_world(world)))
    lv.ok(A, "attach", {"robot": "keeper"})
    return lv


def test_the_base_nodes_fields_are_listed_in_webots_declaration_order():
    lv = _live()
    base = lv.ok(A, "/keeper/robot/get_proto", {"node": 1, "level": 0})          # the Keeper PROTO's Robot
    assert base == {"type_name": "Robot", "derived": False, "fields": ROBOT}
    assert lv.ok(A, "/keeper/robot/get_proto", {"node": 4, "level": 0})["fields"] == SOLID     # BOX, a base Solid
    info = lv.ok(A, "/keeper/robot/get_proto", {"node": 5, "level": 0})
    assert (info["type_name"], info["fields"]) == ("WorldInfo", INFO)
    # every name listed is a field get_field answers at level 0
    for node in (1, 4, 5):
        for name in lv.ok(A, "/keeper/robot/get_proto", {"node": node, "level": 0})["fields"]:
            assert lv.ok(A, "/keeper/robot/get_field", {"node": node, "field": name, "level": 0})["type"]
    lv.err(A, "/keeper/robot/get_proto", {"node": 1, "level": -1}, ErrorCode.INVALID_ARGUMENT)


def test_lights_joints_and_nested_nodes_follow_webots_order():
    lights = Simulation(load_world(REPO / "tests" / "worlds" / "root_children.wbt"))
    names = {n.type: sv.field_names(lights, n) for n in sv.root_children(lights)}
    assert names["PointLight"] == ["ambientIntensity", "attenuation", "color", "intensity", "location", "on",
                                   "radius", "castShadows"]
    sim = Simulation(load_world(NESTED))
    rover = sv.find_node(sim, "ROVER")
    assert rover is not None
    seen = {}
    for child in sv.get_field(sim, rover, "children")["value"]:
        node = sv.node_by_id(sim, child)
        seen.setdefault(node.type, sv.field_names(sim, node))
    assert seen["HingeJoint"] == ["jointParameters", "device", "endPoint"]
    assert seen["Pose"] == ["translation", "rotation", "children"]
    assert all(v.index("translation") < v.index("children") < v.index("name") for v in seen.values()
               if "name" in v and "children" in v)


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_lists_fields_by_index(tmp_path):
    ctl = run_paused(HARDEN, tmp_path, "supervisor_field_index.py", "keeper")
    assert ctl.out == EXPECTED
    err = ctl.stderr()
    assert "not served" not in err and err.count("Error:") == 4, err
    _check_proto_def(err)
    assert "Error: wb_supervisor_node_get_field_by_index() called with an invalid 'index' argument: 6 (the node has " \
           "6 fields)." in err.splitlines(), err


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_lists_the_same_fields(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_field_index.c")
    ctl = run_paused(HARDEN, tmp_path, exe, "keeper", env=SAN_ENV)
    assert ctl.out == EXPECTED
    err = ctl.stderr()
    assert "not served" not in err and "Sanitizer" not in err and "runtime error" not in err, err
    assert err.count("Error:") == 4, err
    _check_proto_def(err)


def _check_proto_def(err: str) -> None:
    """Keeper's body has no DEF BODY (NULL, no line); BOX is no PROTO instance and "" no DEF: Webots' lines."""
    func = "wb_supervisor_node_get_from_proto_def"
    lines = err.splitlines()
    assert sorted(x for x in lines if func in x) == [f"Error: {func}() called with NULL or empty 'def' argument.",
                                                     f"Error: {func}(): 'node' is not a PROTO node."], err  # (C: any order)
