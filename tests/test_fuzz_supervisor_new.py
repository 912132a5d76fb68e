"""Hypothesis fuzz of today's Supervisor services on the sans-IO core: set_label and export_image
(labels of every size, position, colour and text, broken arguments), save_node_state and
load_node_state (names of every kind, nodes that are and are not there), set_joint_position and the
jointParameters position, interleaved with steps and a simulation reset, on
tests/worlds/nested_joints.wbt. Every request gets one reply; a refusal is one line with a protocol
code other than INTERNAL and changes nothing; export_image always answers the 640 x 480 picture; the
joints' positions stay finite; and the heaviest picture (every label as large and long as allowed)
is drawn in bounded time."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _fuzz import example_counts
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_core import SETTINGS, Fuzzed
from test_fuzz_new_devices import send, values

from sensorium.server.sim import viewshot

R = "/armbot/robot/"


@pytest.fixture(scope="module")
def fuzzed() -> tuple[Fuzzed, list[int]]:
    f = Fuzzed("nested_joints.wbt")
    [reply] = send(f, "attach", {"robot": "armbot"})
    assert reply["ok"], reply
    ids = [send(f, R + "get_from_def", {"name": d})[0]["result"]["node"]
           for d in ("ARMBOT", "SHOULDER", "LINK", "HAND", "SLIDE", "CARRIAGE", "TOOL")]
    return f, [0, *ids]


@pytest.mark.parametrize("examples", example_counts(400))
def test_new_supervisor_services_answer_or_refuse_in_one_line(fuzzed, examples: int) -> None:
    f, ids = fuzzed
    node = st.one_of(st.sampled_from(ids), st.sampled_from(ids), st.integers(-2, 80), values)
    unit = st.floats(0.0, 1.0) | st.sampled_from([-0.0, 1.0, 1.0000001, -1e-300, math.nan, math.inf]) | values
    text = (st.text(st.characters(min_codepoint=32, max_codepoint=127) | st.just("\n"), max_size=40)
            | st.sampled_from(["", "\t", "é", "W" * 1024, "W" * 1025, "\n" * 1024]) | values)
    label = st.fixed_dictionaries({"id": st.integers(-1, 70000) | values, "text": text, "x": unit, "y": unit,
                                   "size": unit, "color": st.integers(-1, 1 << 25) | values, "transparency": unit,
                                   "font": st.sampled_from(["Arial", "", "x" * 257]) | values})
    state = st.sampled_from(["__init__", "a", "b", "", "x" * 1024, "x" * 1025]) | values
    requests = st.one_of(
        st.tuples(st.just("set_label"), label),
        st.tuples(st.just("set_label"), st.dictionaries(st.sampled_from(["id", "text", "x", "size", "extra"]), values)),
        st.tuples(st.just("export_image"), st.just({}) | st.dictionaries(st.sampled_from(["size", "id"]), values)),
        st.tuples(st.sampled_from(["save_node_state", "load_node_state"]),
                  st.fixed_dictionaries({"node": node, "state": state})),
        st.tuples(st.just("set_joint_position"),
                  st.fixed_dictionaries({"node": node, "position": st.floats(-1e7, 1e7) | values,
                                         "index": st.integers(-1, 4) | values})),
        st.tuples(st.just("set_field"), st.fixed_dictionaries({"node": node, "field": st.just("position"),
                                                                "value": st.floats(-1e7, 1e7) | values})),
        st.tuples(st.just("simulation_reset"), st.just({})))

    def state_now() -> tuple:
        r = f.sim.robots["armbot"]
        return repr(r.pose), repr([(m.name, m.position, m.target_position) for m in r.motors.values()]), \
            repr(getattr(f.sim, "_labels", viewshot.Labels()).items())

    @settings(SETTINGS, max_examples=examples)
    @given(st.lists(requests, min_size=1, max_size=5))
    def run(batch):
        for item, args in batch:
            before = state_now()
            [reply] = send(f, R + item, args)
            if not reply["ok"]:
                assert state_now() == before, (item, args, reply)
            elif item == "export_image":
                got = reply["result"]
                assert (got["width"], got["height"]) == viewshot.EXPORT_SIZE
                assert len(got["data"]) == 640 * 480 * 3
            for m in f.sim.robots["armbot"].motors.values():
                assert math.isfinite(m.position), (item, args, m.name, m.position)
            f.assert_healthy()
        f.steps()
        f.assert_healthy()

    run()




def _reference_labels(rgb: np.ndarray, labels: viewshot.Labels) -> np.ndarray:
    """The labels drawn glyph pixel by glyph pixel, each square cut to the image (the rule
    draw_labels follows with less work)."""
    from sensorium.server.sim import display

    h, w = rgb.shape[:2]
    out = rgb.copy()
    for _, lab in labels.items():
        k = viewshot.label_scale(lab.size, h)
        x0, y0 = int(math.floor(lab.x * w)), int(math.floor(lab.y * h))
        mask = np.zeros((h, w), dtype=bool)
        for gx, gy in display.text_lines(lab.text):
            for px, py in zip(x0 + k * gx, y0 + k * gy):
                mask[py:py + k, px:px + k] = True
        words = (np.uint32(0xFF000000) | (out[..., 0].astype(np.uint32) << 16)
                 | (out[..., 1].astype(np.uint32) << 8) | out[..., 2].astype(np.uint32))
        if mask.any():
            words[mask] = display._over(words[mask], lab.color, 0xFF, 0xFF - int(lab.transparency * 0xFF))
        out[..., 0], out[..., 1], out[..., 2] = (words >> 16) & 0xFF, (words >> 8) & 0xFF, words & 0xFF
    return out


@SETTINGS
@given(st.lists(st.tuples(st.integers(0, 5), st.text(st.characters(min_codepoint=32, max_codepoint=127)
                                                      | st.just("\n"), max_size=12),
                          st.floats(0, 1), st.floats(0, 1), st.floats(0, 1), st.integers(0, 0xFFFFFF), st.floats(0, 1)),
                max_size=4),
       st.sampled_from([(48, 64), (31, 17), (1, 1), (200, 9)]))
def test_labels_are_the_glyph_pixels_squares_cut_to_the_image(batch, size) -> None:
    labels = viewshot.Labels()
    for i, text, x, y, s, color, transparency in batch:
        labels.set(i, text, x, y, s, color, transparency, "Arial")
    rng = np.random.default_rng(len(batch))
    rgb = rng.integers(0, 256, (*size, 3), dtype=np.uint8)
    assert (viewshot.draw_labels(rgb, labels) == _reference_labels(rgb, labels)).all()
