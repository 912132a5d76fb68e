"""Webots' ``Field.getActualField`` (README "Supervisor"): the node's own field -- ``getField``, the field
the scene tree shows and a Supervisor sets -- that a field takes its value from through IS. A PROTO
instance's base-node field and a field of a PROTO it is built on lead to the interface field passing
straight to them; a field no interface field reaches (a constant of a PROTO's body) is NULL; a node's own
field is itself. Sensorium's own PROTOs (tests/protos/supervisor: BigCrate built on Crate, Keeper) on
tests/worlds/proto/supervisor_proto_fields.wbt, through the service, a Python and a C controller."""

from __future__ import annotations

import sys

import pytest
from test_multiprocess import REPO, run_paused
from test_supervisor_proto_fields import BIG, BOX, CRATE, KEEPER, SAN_ENV, WORLD, _live, call, field


def actual(lv, node: int, name: str, level: int) -> str:
    return call(lv, "get_actual_field", {"node": node, "field": name, "level": level})["value"]


def test_a_base_node_field_and_a_parent_protos_field_lead_to_the_interface_field_that_sets_them():
    lv = _live()
    assert actual(lv, BIG, "translation", 0) == "translation"     # Solid.translation IS Crate's IS BigCrate's
    assert actual(lv, BIG, "translation", 2) == "translation"     # Crate's, set by BigCrate's through IS
    assert actual(lv, BIG, "name", 2) == "name"
    assert actual(lv, BIG, "size", 2) == ""                       # BigCrate's body writes Crate's size: no link
    assert actual(lv, KEEPER, "children", 0) == ""                # Keeper's body holds a Pose there
    # a node's own field is its own actual field: an interface field, a base Solid's field
    assert actual(lv, BIG, "translation", 1) == actual(lv, BIG, "translation", -1) == "translation"
    assert actual(lv, CRATE, "size", -1) == "size"
    assert actual(lv, BOX, "translation", 0) == actual(lv, BOX, "translation", -1) == "translation"
    # the link is real: setting the actual field changes the base-node field it names
    call(lv, "set_field", {"node": BIG, "field": "translation", "value": [3.0, -0.5, 0.2]})
    assert field(lv, BIG, "translation", level=0)["value"] == [3.0, -0.5, 0.2]


def test_a_field_the_node_has_not_has_no_actual_field():
    lv = _live()
    assert actual(lv, BIG, "size", 1) == ""                       # not BigCrate's field
    assert actual(lv, BOX, "nosuchfield", 0) == ""


EXPECTED = ["base translation translation 1", "crate translation translation 1", "crate size NULL",
            "own translation 1", "base after set 3 -0.5 0.20000000000000001", "box translation 1",
            "keeper children NULL"]


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_webots_python_supervisor_follows_fields_to_their_actual_field(tmp_path):
    ctl = run_paused(WORLD, tmp_path, "supervisor_actual_field.py", "keeper")
    assert ctl.out == EXPECTED
    assert "Error" not in ctl.stderr(), ctl.stderr()


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="ipc endpoints")
def test_a_c_supervisor_gets_the_same_refs_getfield_gives(tmp_path, tmp_path_factory):
    """tests/c/supervisor_actual_field.c (the library with AddressSanitizer and UBSan)."""
    from test_c_client import sanitized_controller

    exe = sanitized_controller(tmp_path_factory, REPO / "tests" / "c" / "supervisor_actual_field.c")
    ctl = run_paused(WORLD, tmp_path, exe, "keeper", env=SAN_ENV)
    assert ctl.out == EXPECTED
    assert "Error" not in ctl.stderr() and "Sanitizer" not in ctl.stderr(), ctl.stderr()
