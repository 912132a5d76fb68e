"""Hypothesis fuzz of the PROTO reader and instantiator: PROTO files and worlds made of mutated
fragments of valid ones load or fail with our one-line error (a WbtSyntaxError, of which ProtoError
is one), never anything else."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from _fuzz import example_counts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.server.world.limits import ProtoLimits
from sensorium.server.world.proto import ProtoSearch, expand
from sensorium.server.world.wbt.convert import Converter
from sensorium.server.world.wbt.parser import WbtSyntaxError, parse_wbt

HEADER = "#VRML_SIM R2023b utf8\n"
PROTO = """# template language: javascript
EXTERNPROTO "Leaf.proto"
PROTO Fuzz [
  field SFVec3f translation 0 0 0
  field SFString{"a", "b"} mode "a"
  field MFNode slot [ Leaf { } ]
  field SFInt32 n 3
  field SFNode look PBRAppearance { }
]
{
  %< import * as wbgeometry from 'wbgeometry.js'; const c = wbgeometry.circle(1, fields.n.value, {x: 0, y: 0}, 0); >%
  Solid {
    translation IS translation
    children [
      %< for (let i = 0; i < c.length && i < 20; ++i) { >%
        Pose { translation %<= c[i].x >% %<= c[i].y >% 0 children [ Shape { appearance IS look geometry Box { } } ] }
      %< } >%
      Group { children IS slot }
      DEF A Shape { geometry Sphere { radius 0.1 } }
      Pose { children [ USE A ] }
    ]
    name "%<= fields.mode.value >%"
  }
}
"""
LEAF = "PROTO Leaf [ field SFFloat r 0.5 ] { Solid { children [ Shape { geometry Sphere { radius IS r } } ] } }\n"
WORLD = """EXTERNPROTO "Fuzz.proto"
EXTERNPROTO "Leaf.proto"
WorldInfo { }
Fuzz { translation 1 2 3 mode "b" n 5 slot [ Leaf { r 0.2 } Solid { } ] }
DEF F Fuzz { }
Group { children [ USE F ] }
PROTO Local [ field SFFloat h 1 ] { Solid { children [ Shape { geometry Box { size 1 1 IS h } } ] } }
"""
JUNK = ["{", "}", "[", "]", '"', "IS", "IS slot", "IS n", "DEF X", "USE X", "USE A", "NULL", "TRUE", "-1", "1e999", "0x",
        "%<", ">%", "%<= 1 >%", "%< for(;;){} >%", "%<= 'x'.repeat(1e9) >%", "field", "field SFFloat z 1", "PROTO",
        "EXTERNPROTO", "EXTERNPROTO \"Fuzz.proto\"", "Fuzz { }", "Leaf { r -1 }", "Local { }", ",", "#", "\n", "\t",
        "'", "\\", "SFNode", "MFNode{Box{}}", "hidden", "Robot {", "Leaf {}"]

LIMITS = ProtoLimits(template_seconds=0.05, template_total_seconds=0.5, template_memory=16 << 20,
                     template_output_chars=100_000, instances=200, nodes=20_000, values=80_000)


def mutate(text: str, cuts: list[tuple[int, int, int]]) -> str:
    for pos, op, pick in cuts:
        k = pos % (len(text) + 1)
        if op == 0:
            text = text[:k] + text[k + 1 + pick % 12:]
        elif op == 1:
            text = text[:k] + " " + JUNK[pick % len(JUNK)] + " " + text[k:]
        else:
            text = text[:k]
    return text


edits = st.lists(st.tuples(st.integers(0, 4000), st.integers(0, 2), st.integers(0, 1000)), min_size=1, max_size=3)


def test_the_unmutated_files_expand(tmp_path: Path) -> None:
    for n, text in {"Fuzz.proto": PROTO, "Leaf.proto": LEAF, "w.wbt": WORLD}.items():
        (tmp_path / n).write_text(HEADER + text)
    world = tmp_path / "w.wbt"
    nodes = expand(parse_wbt(world.read_text(), str(world), LIMITS), ProtoSearch.create(tmp_path), LIMITS).nodes
    assert [(n.type, n.proto) for n in nodes] == [("WorldInfo", None), ("Solid", "Fuzz"), ("Solid", "Fuzz"), ("Group", None)]


@pytest.mark.parametrize("examples", example_counts(200))
def test_mutated_protos_and_worlds_load_or_fail_in_one_line(examples: int) -> None:
    @settings(max_examples=examples, deadline=None, suppress_health_check=[HealthCheck.too_slow])
    @given(which=st.integers(0, 2), cuts=edits)
    def run(which: int, cuts: list) -> None:
        files = {"Fuzz.proto": PROTO, "Leaf.proto": LEAF, "w.wbt": WORLD}
        name = ["Fuzz.proto", "Leaf.proto", "w.wbt"][which]
        files[name] = mutate(files[name], cuts)
        files = {n: HEADER + text for n, text in files.items()}
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            for n, text in files.items():
                (folder / n).write_text(text)
            world = folder / "w.wbt"
            try:
                wbt = parse_wbt(world.read_text(), str(world), LIMITS)
                expansion = expand(wbt, ProtoSearch.create(folder), LIMITS)
                Converter(expansion.as_wbt(), str(world), expansion.search).run()     # the expanded tree converts
            except WbtSyntaxError as exc:
                assert "\n" not in str(exc) and len(str(exc)) < 2600

    run()
