"""Webots' MF item setters and inserters of every type (setMFBool, setMFFloat, setMFVec2f, setMFRotation,
setMFString and their insertMF*) through the one set_field path the line and point sets' items take: on a
field of that type that is not settable here (a robot's PROTO interface fields, on
tests/worlds/proto/supervisor_proto_harden.wbt) the server answers the field's read-only line, nothing changed,
and so do setSFInt32 and setSFString there; on a top-level solid's PROTO fields (Lengthy's corners, turns,
size2) the item changes and the solid is built again (tests/test_supervisor_proto_regen.py); the clients' own
checks (a zero rotation axis, NaN, the wrong type) are Webots' lines without a request. Python and C
(AddressSanitizer, UBSan) print the same."""

from __future__ import annotations

import sys

import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor import A, Live

from sensorium.schemas.wire import ErrorCode
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

HARDEN = REPO / "tests" / "worlds" / "proto" / "supervisor_proto_harden.wbt"
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=1:exitcode=86", "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1:exitcode=87"}
KEEPER = 1
EXPECTED = ["counts 2 2 2 3 2", "values 4 5 a 1 0 3 4 1 0 0 0.5", "sf 3 1 2 keeper"]


def _live() -> Live:
    lv = Live(Simulation(load_world(HARDEN)))
    lv.ok(A, "attach", {"robot": "keeper"})
    return lv


def _node(lv: Live, name: str) -> int:
    return int(lv.ok(A, "/keeper/robot/get_from_def", {"name": name})["node"])


@pytest.mark.parametrize("name, field, index, op, value", [
    ("KEEPER", "gains", 0, "set", 9.0), ("KEEPER", "gains", -1, "insert", 9),
    ("KEEPER", "tags", 0, "set", "z"), ("KEEPER", "tags", 0, "insert", "é中"),
    ("KEEPER", "flags", 1, "set", True), ("KEEPER", "flags", 0, "insert", False)])
def test_an_item_of_each_type_is_one_read_only_line_and_nothing_changes(name, field, index, op, value):
    """A robot's PROTO fields are read-only here (a top-level solid's are built again: below)."""
    lv = _live()
    node = _node(lv, name)
    before = lv.ok(A, "/keeper/robot/get_field", {"node": node, "field": field})
    line = lv.err(A, "/keeper/robot/set_field", {"node": node, "field": field, "index": index, "op": op,
                                                 "value": value}, ErrorCode.INVALID_ARGUMENT)
    proto = "Keeper" if name == "KEEPER" else "Lengthy"
    assert f"field {field!r} ({before['type']}) of PROTO {proto} (" in line and "read-only here" in line, line
    assert "\n" not in line and "not served" not in line
    assert lv.ok(A, "/keeper/robot/get_field", {"node": node, "field": field}) == before


@pytest.mark.parametrize("field, index, op, value, after", [
    ("corners", 0, "set", [3.0, 4.0], [[3.0, 4.0], [-0.0, 5e-324]]),
    ("turns", 0, "insert", [1.0, 0.0, 0.0, 0.5], [[1.0, 0.0, 0.0, 0.5], [0.0, 0.0, 1.0, -3.5]])])
def test_an_item_of_a_top_level_solids_proto_field_builds_it_again(field, index, op, value, after):
    """Lengthy, a top-level solid: the item changes and the solid is built again (test_supervisor_proto_regen.py),
    its other values kept bit for bit."""
    lv = _live()
    node = _node(lv, "LONG")
    lv.ok(A, "/keeper/robot/set_field", {"node": node, "field": field, "index": index, "op": op, "value": value})
    got = lv.ok(A, "/keeper/robot/get_field", {"node": node, "field": field})["value"]
    assert got == after and [str(v) for item in got for v in item] == [str(v) for item in after for v in item]
    assert _node(lv, "LONG") == node


def test_a_string_item_longer_than_the_bound_is_refused_by_the_request_check():
    lv = _live()
    r = lv.call(A, "/keeper/robot/set_field", {"node": KEEPER, "field": "tags", "index": 0, "value": "x" * 4097})
    assert r["ok"] is False and r["error"]["code"] == ErrorCode.INVALID_ARGUMENT, r


def test_an_item_of_a_settable_list_still_takes_only_its_own_type():
    """The line set's lists keep their types: a string or a bool for a point is refused with one line."""
    lv = _live()
    (root,) = lv.ok(A, "/keeper/robot/import_node_from_string", {
        "node": 0, "field": "children", "position": -1,
        "node_string": "Shape { geometry DEF L IndexedLineSet { coord DEF C Coordinate { point [ 0 0 0 ] } "
                       "coordIndex [ 0 0 -1 ] } }"})["value"]
    coord = _node(lv, "C")
    for value in ("1 2 3", True, [1.0, 2.0]):
        line = lv.err(A, "/keeper/robot/set_field", {"node": coord, "field": "point", "index": 0, "value": value},
                      ErrorCode.INVALID_ARGUMENT)
        assert "takes 3 numbers" in line, line
    assert lv.ok(A, "/keeper/robot/get_field", {"node": coord, "field": "point"})["value"] == [[0.0, 0.0, 0.0]]
    assert root > 0


def _check(err: str, func_prefix: str = "wb_supervisor_field_") -> None:
    lines = err.splitlines()
    assert "not served" not in err and "Sanitizer" not in err and "runtime error" not in err, err
    read_only = [x for x in lines if "read-only here" in x]
    assert len(read_only) == 8, err
    for f in ("set_mf_float", "insert_mf_float", "set_mf_string", "insert_mf_string", "set_mf_bool", "insert_mf_bool",
              "set_sf_int32", "set_sf_string"):
        assert any(x.startswith(f"Error: {func_prefix}{f}(): ") for x in read_only), (f, err)
    for f in ("set_mf_vec2f", "insert_mf_vec2f", "insert_mf_rotation", "set_sf_vec2f"):    # Lengthy's: built again
        assert not any(x.startswith(f"Error: {func_prefix}{f}(") for x in lines), (f, err)
    assert f"Error: {func_prefix}set_mf_rotation() called with invalid values for the [x y z] axis (a zero " \
           "vector)." in lines, err
    assert f"Error: {func_prefix}set_mf_float() called with a NaN or infinite value." in lines, err
    assert any(x.startswith(f"Error: {func_prefix}set_mf_bool() called with wrong field type") for x in lines), err
    assert err.count("Error:") == 11, err


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_python_supervisor_gets_the_read_only_lines_of_every_item_setter(tmp_path):
    ctl = run_paused(HARDEN, tmp_path, "supervisor_mf_items.py", "keeper")
    assert ctl.out == EXPECTED
    _check(ctl.stderr())


@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_gets_the_same_lines(tmp_path, tmp_path_factory):
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_mf_items.c")
    ctl = run_paused(HARDEN, tmp_path, exe, "keeper", env=SAN_ENV)
    assert ctl.out == EXPECTED
    _check(ctl.stderr())
