"""Hypothesis fuzz of this round's PROTO services on the sans-IO core: getFromProtoDef with random names
(unicode, very long, dotted, empty, DEFs of other instances) on every node the Supervisor serves in
tests/worlds/proto/supervisor_proto_def.wbt, and random PROTO field sets of a regenerated top-level solid
(tests/worlds/proto/supervisor_proto_regen.wbt: every field, values of every type, NaN and inf, huge and
empty MF items, a value the template refuses), interleaved with steps and simulationReset. Every request
gets one reply; a refusal is one line with a protocol code other than INTERNAL and changes nothing; a field
read back after a set is the value set; a reset keeps the values set (README) with the solid at its file
pose. Many sets in a row of a template that loops or throws: each refused within the template's limits,
the memory kept per set bounded."""

from __future__ import annotations

import gc
import math
import tracemalloc

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS, Fuzzed
from test_fuzz_new_devices import send, values

from sensorium.server.daemon import supervisor as sv
from sensorium.server.world.limits import WorldLimits

R = "/eye/robot/"


DEFS = ["ARM", "BOARD", "BOUND", "BULB", "CHASSIS", "ELBOW", "EYE", "GIVEN", "GRIP", "HULL", "HULL_SHAPE", "INSIDE",
        "LEG", "MASS", "PAINT", "TOOL", "TOP", "WOOD", "ROVER", "SHELF"]


def _all_nodes(sim) -> list[int]:
    """Every node id the Supervisor serves, walking from the root through SFNode and MFNode fields."""
    seen, todo = set(), [0]
    while todo:
        nid = todo.pop()
        if nid in seen or len(seen) > 2000:
            continue
        seen.add(nid)
        node = sv.node_by_id(sim, nid)
        for name in sv.field_names(sim, node):
            got = sv.get_field(sim, node, name, level=0)
            if got["type"] == "SFNode" and got["value"]:
                todo.append(int(got["value"]))
            elif got["type"] == "MFNode":
                todo += [int(v) for v in got["value"]]
        for name in DEFS:            # a PROTO body's nodes
            found, _ = sv.from_proto_def(sim, node, name)
            if found is not None:
                todo.append(found.id)
    return sorted(seen)


@pytest.fixture(scope="module")
def proto_def() -> tuple[Fuzzed, list[int]]:
    f = Fuzzed("proto/supervisor_proto_def.wbt")
    robot = next(iter(f.sim.robots))
    [reply] = send(f, "attach", {"robot": robot})
    assert reply["ok"], reply
    return f, _all_nodes(f.sim)


names = (st.sampled_from(DEFS) | st.text(max_size=20) | st.sampled_from(
    ["", ".", "CHASSIS.EYE", "ROVER.CHASSIS", "é", "\u202e", "\0", "D" * 4096, "D" * 4097, "x" * 100_000,
     "CHASSIS ", " CHASSIS", "chassis", "USE", "DEF"]) | values)


@pytest.mark.parametrize("examples", example_counts(400))
def test_get_from_proto_def_on_every_node_answers_or_refuses_in_one_line(proto_def, examples: int) -> None:
    f, ids = proto_def
    robot = next(iter(f.sim.robots))
    assert len(ids) > 20, ids
    node = st.sampled_from(ids) | st.integers(-2, 100) | st.just((1 << 31) - 1) | values

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(st.tuples(node, names), min_size=1, max_size=6))
    def run(batch):
        for nid, name in batch:
            [reply] = send(f, f"/{robot}/robot/get_from_proto_def", {"node": nid, "name": name})
            if reply["ok"]:
                got = reply["result"]
                if got.get("node"):          # a node found: it reads as any node
                    found = sv.node_by_id(f.sim, got["node"])
                    assert sv.field_names(f.sim, found) is not None
                assert "\n" not in str(got.get("note", "")) and len(str(got.get("note", ""))) < 1000, got
            else:
                assert "\n" not in reply["error"]["message"] and len(reply["error"]["message"]) < 1000, reply
            f.assert_healthy()

    run()


# ------------------------------------------------------------------ regeneration

@pytest.fixture(scope="module")
def regen() -> tuple[Fuzzed, int]:
    f = Fuzzed("proto/supervisor_proto_regen.wbt")
    [reply] = send(f, "attach", {"robot": "eye"})
    assert reply["ok"], reply
    [reply] = send(f, R + "get_from_def", {"name": "OBST"})
    return f, reply["result"]["node"]


number = st.floats(-2.0, 2.0) | st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -0.0, 1e9, 2e9, 60.0, 1e-300])
FIELDS = {"size": st.lists(number, min_size=3, max_size=3), "color": st.lists(st.floats(0, 1) | number, min_size=3,
                                                                                  max_size=3),
          "round": st.booleans(), "material": st.sampled_from(["wood", "stone", "glass", "", "é" * 10]),
          "mass": number, "translation": st.lists(number, min_size=3, max_size=3), "name": st.just("rock")}


@pytest.mark.parametrize("examples", example_counts(150))
def test_random_proto_field_sets_rebuild_or_refuse_in_one_line(regen, examples: int) -> None:
    f, obst = regen
    sets = st.one_of(
        st.sampled_from(sorted(FIELDS)).flatmap(lambda name: st.tuples(st.just("set"), st.just(name), FIELDS[name])),
        st.tuples(st.just("set"), st.sampled_from(sorted(FIELDS) + ["posts", "nope", ""]), values),
        st.tuples(st.sampled_from(["insert", "set_item", "remove"]), st.integers(-3, 3) | values, number | values),
        st.tuples(st.just("reset"), st.none(), st.none()),
        st.tuples(st.just("proto_def"), names | st.just("BODY"), st.none()),
        st.tuples(st.just("step"), st.none(), st.none()))

    def read(name: str):
        [reply] = send(f, R + "get_field", {"node": obst, "field": name})
        assert reply["ok"], reply
        return reply["result"]["value"]

    def state() -> tuple:
        return tuple(repr(read(n)) for n in ("size", "color", "round", "material", "posts", "mass", "translation")), \
            f.sim.scene.solid_names.index("obstacle"), len(f.sim.scene.shapes)

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(sets, min_size=1, max_size=5))
    def run(batch):
        for kind, a, b in batch:
            before = state()
            if kind == "reset":
                [reply] = send(f, R + "simulation_reset", {})
                assert reply["ok"], reply
                assert read("translation") == [1.0, 0.0, 0.0]       # the file's pose, the values set kept
                assert state()[0][:5] == before[0][:5]
                continue
            if kind == "step":
                f.steps()
                continue
            if kind == "proto_def":        # the body's DEFs (a rebuilt body's: NULL with one line, README)
                [reply] = send(f, R + "get_from_proto_def", {"node": obst, "name": a})
                got = reply.get("result") or reply["error"]
                assert "\n" not in str(got) and len(str(got)) < 2000, reply
                f.assert_healthy()
                continue
            if kind == "set":
                args = {"node": obst, "field": a, "value": b}
            else:
                args = {"node": obst, "field": "posts", "index": a, "op": {"set_item": "set"}.get(kind, kind)}
                if kind != "remove":
                    args["value"] = b
            [reply] = send(f, R + "set_field", args)
            if not reply["ok"]:
                message = reply["error"]["message"]
                assert "\n" not in message and len(message) < 2000, reply
                assert state() == before, (kind, a, b, reply)
            elif kind == "set" and a in FIELDS and a != "translation":
                assert read(a) == (b if not isinstance(b, list) else [float(x) for x in b]), (a, b)
            f.assert_healthy()

    run()
    # not all refused: the sets that build were exercised (more than 30 of 150 examples' sets)
    assert f.sim.counters["regenerations"] > examples // 5


LOOPER = """#VRML_SIM R2023b utf8
# template language: javascript
PROTO Looper [
  field SFVec3f translation 0 0 0
  field SFString name "looper"
  field SFInt32 spin 0
  field SFInt32 count 1
]
{
  %< if (fields.spin.value > 0) { while (true) {} }
     if (fields.count.value < 0) throw new Error('count must not be negative'); >%
  Solid {
    translation IS translation
    name IS name
    children [
      %< for (let i = 0; i < fields.count.value; ++i) { >%
      Pose { translation %<= i >% 0 0 children [ Shape { geometry Box { size 0.1 0.1 0.1 } } ] }
      %< } >%
    ]
  }
}
"""

LOOPER_WORLD = """#VRML_SIM R2023b utf8
EXTERNPROTO "Looper.proto"
WorldInfo {
  basicTimeStep 16
}
DEF LOOP Looper {
}
DEF SUP Robot {
  name "sup"
  supervisor TRUE
  controller "<extern>"
}
"""


def test_many_sets_of_a_template_that_loops_throws_or_grows_are_bounded(tmp_path) -> None:
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    (tmp_path / "Looper.proto").write_text(LOOPER)
    (tmp_path / "w.wbt").write_text(LOOPER_WORLD)
    limits = WorldLimits()
    sim = Simulation(load_world(tmp_path / "w.wbt", limits=limits), limits=limits)
    node = sv.find_node(sim, "LOOP")
    for value, words in ((1, "the template ran longer than 0.25 s of CPU time"), (-1, "count must not be negative")):
        field_name = "spin" if value > 0 else "count"
        with pytest.raises(ValueError) as exc:
            sv.set_field(sim, node, field_name, value)
        assert words in str(exc.value) and "\n" not in str(exc.value), exc.value
    with pytest.raises(ValueError) as exc:     # a template output over the world's limits: one line
        sv.set_field(sim, node, "count", 1 << 30)
    assert "\n" not in str(exc.value), exc.value
    shapes = len(sim.scene.shapes)
    sv.set_field(sim, node, "count", 3)
    sv.set_field(sim, node, "count", 1)
    gc.collect()
    tracemalloc.start()
    first = tracemalloc.get_traced_memory()[0]
    sets = 21                                  # 7 rounds of 1, 2, 3 boxes (measured: under 30 kB kept in all)
    for i in range(sets):
        sv.set_field(sim, node, "count", 1 + i % 3)
    sv.set_field(sim, node, "count", 1)
    gc.collect()
    grown = tracemalloc.get_traced_memory()[0] - first
    tracemalloc.stop()
    assert grown < sets * 20_000, grown        # README: about 5 kB kept per set of a small solid
    assert sim.counters["regenerations"] == sets + 3
    assert sv.get_field(sim, sv.find_node(sim, "LOOP"), "count")["value"] == 1
    assert len(sim.scene.shapes) >= shapes
