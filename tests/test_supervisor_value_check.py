"""A value a Supervisor sets (``setSF*``, an MF item, a PROTO field that builds its solid again) is checked
by one rule with one line for every path: of the field's type, its numbers finite, an SFInt32 within 32
bits; nothing changes when it is refused. Our own world and PROTO."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world

PROTO = """#VRML_SIM R2023b utf8
PROTO Crate [
  field SFVec3f translation 0 0 0
  field SFVec3f size 0.2 0.2 0.2
  field SFColor tint 1 0 0
  field MFVec3f marks [ 0 0 0 ]
]
{
  Solid { translation IS translation name "crate"
    children [ Shape { appearance PBRAppearance { baseColor IS tint } geometry Box { size IS size } } ] }
}
"""

WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Crate.proto"
WorldInfo { basicTimeStep 16 }
DEF BOX Solid { translation 1 0 0 name "box" }
DEF LAMP PointLight { location 0 0 2 intensity 1 }
DEF CRATE Crate { translation 3 0 0 }
Robot { name "r" supervisor TRUE }
"""


@pytest.fixture
def sim(tmp_path: Path) -> Simulation:
    (tmp_path / "Crate.proto").write_text(PROTO)
    (tmp_path / "w.wbt").write_text(WORLD)
    return Simulation(load_world(tmp_path / "w.wbt"))


WRONG = [
    ("SFVec3f", ["a", 0, 0], "takes 3 finite numbers, got ['a', 0, 0]"),
    ("SFVec3f", [0.0, math.inf, 0.0], "takes 3 finite numbers, got [0.0, inf, 0.0]"),
    ("SFVec3f", [0.0, 1.0], "takes 3 finite numbers, got [0.0, 1.0]"),
    ("SFVec3f", [True, 0.0, 0.0], "takes 3 finite numbers, got [True, 0.0, 0.0]"),
    ("SFColor", "red", "takes 3 finite numbers, got 'red'"),
    ("SFFloat", True, "takes a finite number, got True"),
    ("SFFloat", math.nan, "takes a finite number, got nan"),
    ("SFBool", 1, "takes true or false, got 1"),
    ("SFString", 5, "takes a string, got 5"),
]

TARGETS = {   # a field of each type, on a node whose set goes through set_field's setter, or rebuilds a PROTO
    "SFVec3f": [("BOX", "translation"), ("CRATE", "size")],
    "SFColor": [("LAMP", "color"), ("CRATE", "tint")],
    "SFFloat": [("LAMP", "intensity")],
    "SFBool": [("LAMP", "on")],
    "SFString": [("r", "customData")],
}


@pytest.mark.parametrize(("kind", "value", "line"), WRONG)
def test_a_wrong_value_is_one_line_whatever_path_sets_it(sim: Simulation, kind: str, value, line: str) -> None:
    for name, field in TARGETS[kind]:
        node = sv.find_node(sim, name)
        before = sv.get_field(sim, node, field)["value"]
        with pytest.raises(ValueError) as exc:
            sv.set_field(sim, node, field, value)
        assert str(exc.value) == f"field {field!r} is an {kind}: {line}", (name, field)
        assert sv.get_field(sim, node, field)["value"] == before


def test_an_mf_item_takes_the_same_check_and_line(sim: Simulation) -> None:
    crate = sv.find_node(sim, "CRATE")
    with pytest.raises(ValueError) as exc:
        sv.change_item(sim, crate, "marks", "set", 0, ["a", 0, 0])
    assert str(exc.value) == "field 'marks' is an SFVec3f: takes 3 finite numbers, got ['a', 0, 0]"
    with pytest.raises(ValueError, match=r"^field 'marks' is an MFVec3f: set it item by item \(setMF\*, insertMF\*, "
                                         r"removeMF\)$"):
        sv.set_field(sim, crate, "marks", [[0.0, 0.0, 0.0]])


def test_an_int32_beyond_32_bits_is_refused_before_any_setter(sim: Simulation) -> None:
    with pytest.raises(ValueError) as exc:
        sv._check_value("filtering", "SFInt32", 1 << 40)
    assert str(exc.value) == f"field 'filtering' is an SFInt32: takes a whole number within 32 bits, got {1 << 40}"
    sv._check_value("filtering", "SFInt32", (1 << 31) - 1)


def test_right_values_still_set(sim: Simulation) -> None:
    sv.set_field(sim, sv.find_node(sim, "BOX"), "translation", [2, 0, 0])      # whole numbers are numbers
    assert sv.get_field(sim, sv.find_node(sim, "BOX"), "translation")["value"] == [2.0, 0.0, 0.0]
    sv.set_field(sim, sv.find_node(sim, "LAMP"), "on", False)
    assert sv.get_field(sim, sv.find_node(sim, "LAMP"), "on")["value"] is False
