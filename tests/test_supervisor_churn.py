"""A Supervisor changing the world for days (README "Supervisor", what a long-running randomising Supervisor
costs): importing and removing solids, setting a PROTO field of a top-level solid again and again, keeps the
scene's and the ray engine's tables as long as a fresh world's with the same content (the last removed bodies'
shape numbers are taken again), and every reading -- camera pixels and recognition, range finder, lidar,
distance sensors -- equals, bit for bit, that of a world file written with the final content. Node ids and
solid names are still never reused. The world is the churn benchmark's (sensorium/benchmarks/churn.py)."""

from __future__ import annotations

import numpy as np
import pytest

from sensorium.benchmarks import churn
from sensorium.server.daemon import supervisor as sv
from sensorium.server.sim.imports import ImportRefused

BALL = ('DEF BALL Solid {{ translation {x} 0 0 name "ball" recognitionColors [ 0 1 0 ] '
        'children [ Shape {{ geometry Box {{ size {sx} 0.4 0.3 }} }} ] boundingObject Box {{ size {sx} 0.4 0.3 }} }}')


def ball(x: float, sx: float = 0.2) -> str:
    return BALL.format(x=x, sx=sx)


def tables(sim) -> tuple[int, int, int, int, int]:
    """What grows with each shape or body: the scene's per-shape lists and arrays, the engine's."""
    scene = sim.scene
    return (len(scene.shapes), len(scene.red) - 1, len(scene.colors) - 1, scene.engine.shape_count,
            len(scene.engine._bodies))


def equal_readings(a, b) -> None:
    ra, rb = churn.readings(a), churn.readings(b)
    for name in churn.DEVICES:
        assert np.array_equal(ra[name], rb[name]), name
    assert repr(ra["objects"]) == repr(rb["objects"])


def test_importing_and_removing_a_thousand_times_keeps_a_fresh_worlds_tables_and_readings(tmp_path):
    sim = churn.simulation(churn.world_file(tmp_path))
    fresh = tables(sim)
    ids = []
    for k in range(1000):
        (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.0 + 0.001 * (k % 7), 0.1 + 0.01 * (k % 5)))
        ids.append(node)
        if k % 100 == 0:
            sim.step()
        sv.remove_node(sim, sv.node_by_id(sim, node))
    assert tables(sim) == fresh
    assert ids == list(range(ids[0], ids[0] + 1000))       # ids are still never reused
    assert sv.node_from_id(sim, ids[0]) is None and sv.node_from_id(sim, ids[-1]) is None
    # one more stays: seen exactly as the world file holding it sees it
    (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.2, 0.25))
    assert node == ids[-1] + 1
    assert sim.scene.solid_poses.keys() >= {"ball(1000)"}          # names too: ball, ball(1), ... ball(1000)
    written = churn.simulation(churn.world_file(tmp_path, extra=ball(1.2, 0.25).replace('"ball"', '"ball(1000)"')))
    assert tables(sim) == tables(written)
    equal_readings(sim, written)


def test_a_removed_solid_before_one_still_there_keeps_its_numbers_until_that_one_goes(tmp_path):
    sim = churn.simulation(churn.world_file(tmp_path))
    fresh = tables(sim)
    (a,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.0))
    (b,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.3, 0.3))
    sv.remove_node(sim, sv.node_by_id(sim, a))
    assert tables(sim)[0] == fresh[0] + 4                   # a's two shapes stay numbered, before b's
    written = churn.simulation(churn.world_file(tmp_path, extra=ball(1.3, 0.3).replace('"ball"', '"ball(1)"')))
    equal_readings(sim, written)
    sim.step()
    (c,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.1, 0.15))
    assert tables(sim)[0] == fresh[0] + 6
    sv.remove_node(sim, sv.node_by_id(sim, c))
    sv.remove_node(sim, sv.node_by_id(sim, b))            # the last ones all gone: back to the world's tables
    assert tables(sim) == fresh
    equal_readings(sim, churn.simulation(churn.world_file(tmp_path)))


def test_setting_a_proto_field_again_and_again_is_seen_as_the_last_value_written(tmp_path):
    """The recognised object's size is the last body's (the old bodies' shapes, kept under the same name,
    made the box the union of every size set so far)."""
    sim = churn.simulation(churn.world_file(tmp_path))
    fresh = tables(sim)
    sizes = [[0.3, 0.5, 0.3], [0.2, 0.2, 0.3], [0.25, 0.3, 0.3]] * 40
    for size in sizes:
        sv.set_field(sim, sv.find_node(sim, "CRATE"), "size", size)
        sim.step()
    # the world file's first body keeps its numbers (robots' bodies follow it); every later one's are taken again
    assert tables(sim) == (fresh[0] + 2, fresh[1] + 2, fresh[2] + 2, fresh[3] + 2, fresh[4] + 1)
    written = churn.simulation(churn.world_file(tmp_path, size="0.25 0.3 0.3"))
    equal_readings(sim, written)
    (obj,) = [o for o in sim.device("eye/cam").objects if o.colors == ((1.0, 0.0, 0.0),)]
    assert obj.size == pytest.approx((0.3, 0.3))


def test_a_moved_solid_randomised_and_removed_lets_its_engine_scenes_go(tmp_path):
    sim = churn.simulation(churn.world_file(tmp_path))
    sim.step()
    shared = len(sim.scene.engine._shared)
    for k in range(30):
        (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.0, 0.1 + 0.01 * k))
        found = sv.node_by_id(sim, node)
        sim.set_solid_pose(found.key, [1.0 + 0.01 * k, 0.0, 0.0])     # moved: a scene in its own frame
        sim.step()
        sv.remove_node(sim, found)
    assert len(sim.scene.engine._shared) == shared


def test_a_refused_import_does_not_take_a_name():
    """Names are found from a kept count (a Supervisor importing "ball" for days): a string refused after its
    first node was named leaves that name to the next import."""
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        sim = churn.simulation(churn.world_file(Path(tmp)))
        for _ in range(3):
            sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.0))
        with pytest.raises(ImportRefused):
            sim.import_nodes(ball(1.0) + " Robot { }")
        (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.0))
        assert sv.node_by_id(sim, node).key == "ball(3)"
        assert sorted(n for n in sim.scene.solid_poses if n.startswith("ball")) == \
            ["ball", "ball(1)", "ball(2)", "ball(3)"]


def test_the_foxglove_scene_stays_the_size_of_the_world_after_many_removals(tmp_path):
    """Each removal once was one deletion in every later scene update (10,000 removals: 10,000 deletions each
    time the scene changes); past MAX_DELETIONS a scene update deletes everything drawn and draws the world."""
    from test_supervisor_remove import _top_fields

    from sensorium.server.recording.scene3d import MAX_DELETIONS, scene_update

    sim = churn.simulation(churn.world_file(tmp_path))

    def scene() -> tuple[list[bytes], list[bytes]]:
        fields = _top_fields(scene_update(sim.world, sim.loaded.base_dir, 0, dict(sim.scene.solid_poses),
                                          sim.scene.removed_lights).encode())
        return [p for f, p in fields if f == 1], [p for f, p in fields if f == 2]

    _, world_entities = scene()
    for k in range(MAX_DELETIONS + 1):
        (node,) = sv.import_nodes(sim, sv.ROOT, "children", -1, ball(1.0))
        sv.remove_node(sim, sv.node_by_id(sim, node))
        if k == MAX_DELETIONS - 1:
            deletions, entities = scene()
            assert len(deletions) == MAX_DELETIONS and b"solid/ball(63)" in deletions[-1]
    deletions, entities = scene()
    assert len(deletions) == 1 and b"solid/" not in deletions[0]      # one deletion of every entity
    assert entities == world_entities
