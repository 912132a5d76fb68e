"""Hypothesis fuzz of a Supervisor's transparency sets (tests/test_supervisor_transparency.py's
world: a block before a wall, a robot's visor before its own sensors): random sequences of sets on
both shapes, across and within the classes opaque / translucent / invisible (0, 1, values a hair
from them), interleaved with steps and simulation resets. After every step each sensor (cameras,
segmentation and recognition, range finder, lidar, infra-red, sonar, laser, light sensor) reads the
bits of the world file written with the values then in force; the engine's tiers and shapes and the
scene's tables stay bounded."""

from __future__ import annotations

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS
from test_supervisor_transparency import DEVICES, _appearance, _sim, readings, same, world

from sensorium.schemas import world as wm
from sensorium.server.daemon import supervisor as sv

# (a world file takes no magnitude under 1e-30 but 0: limits.py; a Supervisor's set does, see the report)
VALUES = [0.0, 0.5, 1.0, 1e-30, 0.9999999999999999, 1.0 - 1e-9, 1e-9, 0.25]

_refs: dict[tuple[float, float, str], dict] = {}


def reference(block: float, visor: float, precision: str = "exact") -> dict:
    """The readings after one step of the world file written with these transparencies."""
    key = (block, visor, precision)
    if key not in _refs:
        data = world(block, "block").model_dump(mode="json", exclude_none=True)
        data["robots"][0]["shapes"][0]["appearance"]["transparency"] = visor
        sim = _sim(wm.World.model_validate(data), precision)
        sim.run(1)
        _refs[key] = readings(sim)
    return _refs[key]



def _reset(sim) -> dict:
    """A simulation reset, the devices enabled again as the test's world enables them; the appearances."""
    sim.reset()
    for d in DEVICES:
        sim.device(f"r/{d}").enable(16)
    sim.device("r/cam").recognition_enable(16)
    sim.device("r/cam").enable_segmentation(True)
    return {t: _appearance(sim, t) for t in ("block", "visor")}


OPS = st.lists(st.one_of(st.tuples(st.sampled_from(["block", "visor"]), st.sampled_from(VALUES)),
                         st.just(("step", 0.0)), st.just(("reset", 0.0))), min_size=1, max_size=14)


@pytest.mark.parametrize("examples", example_counts(25))
def test_random_sets_steps_and_resets_read_as_the_world_file_and_stay_bounded(examples: int):
    @settings(SETTINGS, max_examples=examples)
    @given(OPS)
    def run(ops):
        _sets_steps_and_resets(ops, "exact")

    run()


@settings(SETTINGS, max_examples=10)
@given(OPS)
def test_under_fast_too_resets_read_as_the_world_file_bit_for_bit(ops):
    """FAST precision: a reset left the distance readings 1 float32 ulp off a fresh world's (every
    static solid became a moving body); see tests/test_fast_reset.py."""
    _sets_steps_and_resets(ops, "fast")


def _sets_steps_and_resets(ops, precision: str) -> None:
    sim = _sim(world(0.0, "block"), precision)
    apps = {t: _appearance(sim, t) for t in ("block", "visor")}
    now = {"block": 0.0, "visor": 0.0}
    engine = sim.scene.engine
    sim.run(1)
    passes = []
    for _ in range(4):          # the same sequence again and again: nothing grows from pass to pass
        for op, value in [*ops, ("step", 0.0)]:
            if op == "reset":
                apps = _reset(sim)
                now = {"block": 0.0, "visor": 0.0}
            elif op == "step":
                sim.run(1)
                assert same(readings(sim), reference(now["block"], now["visor"], precision)) == [], (ops, now)
                assert (engine.shape_count, len(sim.scene.shapes)) == (7, 7)
            else:
                sv.set_field(sim, apps[op], "transparency", value)
                assert sv.get_field(sim, apps[op], "transparency")["value"] == value
                now[op] = value
        passes.append((engine.held_tiers, len(sim.scene.transparency), len(sim.scene.shapes)))
    assert passes[1] == passes[2] == passes[3], passes


BALL = ('Solid {{ translation 0.7 {y} 0 name "ball" children [ Shape {{ appearance PBRAppearance {{ '
        'baseColor 0.9 0.2 0.2 transparency {t} }} geometry Box {{ size 0.05 0.1 0.3 }} }} ] }}')


@settings(SETTINGS, max_examples=20)
@given(st.lists(st.one_of(st.tuples(st.sampled_from(["block", "visor", "import", "imported"]), st.sampled_from(VALUES)),
                          st.tuples(st.sampled_from(["remove", "step", "reset"]), st.just(0.0))),
                min_size=1, max_size=14))
def test_imported_shapes_crossing_and_removed_leave_the_world_files_readings_and_tables(ops):
    """Translucent, invisible and opaque boxes a Supervisor imports between the robot and the block,
    crossing classes themselves, removed again, with resets (which remove them too): whenever none is
    left, every sensor reads the world file written with the block's and visor's values in force and
    the scene's and engine's shape tables are a fresh world's."""
    sim = _sim(world(0.0, "block"), "exact")
    apps = {t: _appearance(sim, t) for t in ("block", "visor")}
    now = {"block": 0.0, "visor": 0.0}
    fresh = (sim.scene.engine.shape_count, len(sim.scene.shapes))
    imported: list[int] = []
    for op, value in [*ops, ("remove_all", 0.0), ("step", 0.0)]:
        if op == "reset":
            apps = _reset(sim)
            now = {"block": 0.0, "visor": 0.0}
            imported = []
        elif op == "import":
            (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, BALL.format(y=0.05 * (len(imported) % 3), t=value))
            imported.append(node)
        elif op == "imported" and imported:
            (shape,) = sv.get_field(sim, sv.node_by_id(sim, imported[-1]), "children")["value"]
            app = sv.node_by_id(sim, sv.get_field(sim, sv.node_by_id(sim, shape), "appearance")["value"])
            sv.set_field(sim, app, "transparency", value)
        elif op == "remove" and imported:
            sv.remove_node(sim, sv.node_by_id(sim, imported.pop()))
        elif op == "remove_all":
            while imported:
                sv.remove_node(sim, sv.node_by_id(sim, imported.pop()))
        elif op == "step":
            sim.run(1)
            if not imported:
                assert same(readings(sim), reference(now["block"], now["visor"])) == [], (ops, now)
                assert (sim.scene.engine.shape_count, len(sim.scene.shapes)) == fresh
        elif op in now:
            sv.set_field(sim, apps[op], "transparency", value)
            now[op] = value
