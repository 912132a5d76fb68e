"""Hypothesis fuzz of this round's Supervisor services on the sans-IO core, on
tests/worlds/contact_points.wbt (a box and a ball with physics, a two-wheel robot with nested solids):
reset_physics, get_node_static_balance, get_node_contact_points (with and without descendants),
node_export_string of top-level and nested nodes, move_viewpoint, movie_start/frames/stop and world_load, with node ids
of the root, of nested nodes, of removed nodes, out of range and of every wrong type, movie sizes and
accelerations at and past their bounds, interleaved with steps, a node's removal, a simulation reset
and a world reload. Every request gets one reply; a refusal is one line with a protocol code other
than INTERNAL and leaves the movie as it was; contact points come as finite (x, y, z) triples, one
node id each, balance as a bool, export text as text; every frame is width x height x 3 bytes; the
Viewpoint's position stays finite."""

from __future__ import annotations

import math

import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS, Fuzzed
from test_fuzz_new_devices import send, values

from sensorium.server.sim import viewshot

R = "/sup/robot/"
DEFS = ("BOX", "BALL", "CART", "LEFT", "RIGHT", "CASTER")


def fresh() -> tuple[Fuzzed, list[int]]:
    """A new core each example: every node there at first, so each example can query and then remove."""
    f = Fuzzed("contact_points.wbt", copied=True)
    [reply] = send(f, "attach", {"robot": "sup"})
    assert reply["ok"], reply
    ids = [send(f, R + "get_from_def", {"name": d})[0]["result"]["node"] for d in DEFS]
    return f, [0, *ids]


def _movie(f: Fuzzed) -> tuple | None:
    m = getattr(f.sim, "_movie", None)
    return None if m is None else (m.robot, m.width, m.height, m.step_ms, m.frames)


@pytest.mark.parametrize("examples", example_counts(400))
def test_the_rounds_supervisor_services_answer_or_refuse_in_one_line(examples: int) -> None:
    ids = fresh()[1]
    node = st.one_of(st.sampled_from(ids), st.sampled_from(ids), st.sampled_from(ids), st.integers(-2, 40),
                     st.sampled_from([1 << 24, (1 << 24) + 40, (1 << 25) + 1, (1 << 31) - 1, 1 << 31]), values)
    side = st.sampled_from([2, 4, 16]) | st.sampled_from([2, 4, 16, 1, 3, 0, -2, 4097, 1 << 40, 2.0, math.nan]) | values
    acceleration = st.sampled_from([1, 2, 7, 10_000]) | st.sampled_from([0, -1, 10_001, 1.5, math.inf, True]) | values
    requests = st.one_of(
        st.tuples(st.sampled_from(["reset_physics", "get_node_static_balance", "node_export_string", "move_viewpoint"]),
                  st.fixed_dictionaries({"node": node})),
        st.tuples(st.just("get_node_contact_points"),
                  st.fixed_dictionaries({"node": node}, optional={"include_descendants": st.booleans() | values})),
        st.tuples(st.just("movie_start"),
                  st.fixed_dictionaries({"width": side, "height": side, "acceleration": acceleration},
                                        optional={"caption": st.booleans() | values})),
        st.tuples(st.just("movie_start"), st.fixed_dictionaries({"width": st.sampled_from([2, 4, 16]), "height": st.sampled_from(
            [2, 6, 12]), "acceleration": st.sampled_from([1, 2, 7, 10_000]), "caption": st.booleans()})),
        st.tuples(st.sampled_from(["movie_frames", "movie_frames", "movie_stop"]),
                  st.just({}) | st.dictionaries(st.text(max_size=4), values)),
        st.tuples(st.just("world_load"), st.fixed_dictionaries({"filename": st.sampled_from(
            ["../../worlds/x.wbt", "a\0b", "", "x" * 4097, "/etc/passwd", "w\n.wbt"]) | values})),
        st.tuples(st.sampled_from(["simulation_reset", "world_reload"]), st.just({})),
        st.tuples(st.just("remove_node"), st.fixed_dictionaries({"node": node})),
        st.tuples(st.just("step"), st.fixed_dictionaries({"duration": st.sampled_from([0, 16, 48])})))

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(requests, min_size=1, max_size=8))
    def run(batch):
        f = fresh()[0]
        for item, args in batch:
            movie = _movie(f)
            replies = send(f, R + item, args)
            f.steps()
            if item == "step" and not replies:       # answered when the world has advanced
                continue
            [reply] = replies
            got = reply.get("result")
            if not reply["ok"]:
                assert _movie(f) == movie, (item, args, reply)
                assert "\n" not in reply["error"]["message"], (item, args, reply)
            elif item == "get_node_contact_points":
                points, nodes = got["points"], got["nodes"]
                assert len(points) == 3 * len(nodes) and all(math.isfinite(v) for v in points), got
                assert all(isinstance(n, int) and n >= 0 for n in nodes), got
            elif item == "get_node_static_balance":
                assert isinstance(got["value"], bool), got
            elif item == "node_export_string":
                assert isinstance(got["value"], str) and got["value"], got
            elif item == "movie_frames":
                assert all(len(b) == got["width"] * got["height"] * 3 for b in got["frames"]), got["width"]
            elif item == "move_viewpoint":
                assert got == {"success": True}, got
            assert all(math.isfinite(v) for v in viewshot.viewpoint_of(f.sim).position), (item, args)
            f.assert_healthy()
        f.steps()
        f.assert_healthy()

    run()
