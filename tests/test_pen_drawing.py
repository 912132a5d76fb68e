"""The bundled pen_drawing world (issue 21): a robot draws a circle with its Pen, then follows the
ink with its infra-red ground sensors - in process (FAST and EXACT) and as a real controller
process (``example:pen_drawer``) against ``sensorium serve``, bit for bit the same."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _serve import run_example
from PIL import Image

from sensorium import worlds
from sensorium.client.examples.pen_drawer import circle_speeds, lap_steps
from sensorium.worlds import pen_drawing


def test_the_committed_paper_is_the_generators_output() -> None:
    paper = np.asarray(Image.open(pen_drawing.IMAGE).convert("RGB"))
    assert np.array_equal(paper, pen_drawing.render()) and paper.shape == (512, 512, 3)
    assert "pen_drawing" in worlds.names()


def test_the_circle_law() -> None:
    left, right = circle_speeds()
    # wheel speeds r·(w_r + w_l)/2 = v and r·(w_r − w_l)/L = v/R
    assert 0.0205 * (left + right) / 2 == pytest.approx(0.08, abs=1e-15)
    assert 0.0205 * (right - left) / 0.052 == pytest.approx(0.08 / 0.5, abs=1e-15)
    assert lap_steps(32) == math.ceil(2 * math.pi * 0.5 / 0.08 / 0.032) == 1228


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_the_robot_draws_a_circle_then_follows_its_ink_once_round(precision: str) -> None:
    run = pen_drawing.run(precision=precision)
    strokes = run["strokes"]
    # one stroke per drawing step, each where the robot's centre was when the step began
    assert len(strokes) == run["draw_steps"] == 1228
    assert np.hypot(strokes[:, 0], strokes[:, 1]) == pytest.approx(0.5, abs=1e-9)
    assert strokes[0].tolist() == pytest.approx([0.5, 0.0], abs=1e-12)
    sim = run["sim"]
    assert sim.counters["ink_strokes"] == 1228 and sim.counters["rays_pen"] == 1228   # the pen is off afterwards
    # following: on the ink (it reads 0 under black ink, 800 on white paper) and round once
    assert run["lapped"] and run["worst"] < 0.01
    assert run["follow_steps"] < 1400
    readings = run["readings"]
    assert readings.min() == pytest.approx(0.0, abs=1e-9) and readings.max() == pytest.approx(800.0, abs=1e-9)
    assert (readings[:, 1] < 400).mean() > 0.9       # the centre sensor is over the ink most of the time
    layer = sim.scene.textures.ink[0]
    assert layer.density.shape == (512, 512)
    assert np.count_nonzero(layer.density) > 1228        # the discs overlap into a 2 cm line


def test_the_controller_process_draws_and_follows_like_the_in_process_run() -> None:
    steps = 1228 + 300
    expected = pen_drawing.run(follow_steps=300)
    got, proc = run_example("pen_drawing", "pen_drawer", "epuck", steps)
    assert got["translation"][:2] == expected["path"][-1].tolist()
    out = proc.stdout()
    assert "the circle is drawn: pen off, following the ink" in out
    assert out.count("drawing ground=") == 1228 // 31 and "following ground=" in out     # a line per 31 steps
