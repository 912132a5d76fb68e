"""Line following end to end (issue 21): the bundled line_following world's textured floor, its
e-puck-like robot's three infra-red ground sensors, and the Webots-style example controller going
once round the loop - in process (FAST and EXACT) and as a real controller process against
``sensorium serve``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _serve import run_example
from PIL import Image

from sensorium import worlds
from sensorium.server.sim.simulation import Simulation
from sensorium.worlds import line_loop

EXAMPLE = line_loop.HERE.parent / "client" / "examples" / "line_follower.py"


def test_the_committed_floor_is_the_generators_output() -> None:
    committed = np.asarray(Image.open(line_loop.IMAGE).convert("RGB"))
    assert committed.shape == (1024, 1024, 3)
    assert np.array_equal(committed, line_loop.render())
    assert set(np.unique(committed).tolist()) == {line_loop.DARK, line_loop.WHITE}


def test_the_world_is_bundled_and_its_ground_sensors_read_the_texture() -> None:
    assert "line_following" in worlds.names()
    sim = Simulation.from_file("line_following")
    assert not sim.loaded.warnings
    gs = [sim.device(f"epuck/gs{i}") for i in range(3)]
    for s in gs:
        s.enable(32)
    sim.step()
    # 1 cm above the floor, the table 1000 - 20000 x d: white reads 800, the line (red 30/255)
    # 1000 - 20000 x 0.01 / (0.2 + 0.8 x 30/255)
    dark = 1000 - 20000 * 0.01 / (0.2 + 0.8 * 30 / 255)
    assert [s.value for s in gs] == [pytest.approx(800, abs=1e-9), pytest.approx(dark, abs=1e-9),
                                     pytest.approx(800, abs=1e-9)]
    assert sim.counters["texture_lookups"] == 3


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_the_example_controller_follows_the_line_once_round(precision: str) -> None:
    run = line_loop.lap(precision=precision)
    assert run["lapped"], run["progress"]
    assert run["worst"] < 0.03                     # never more than 3 cm from the line's centre
    assert run["length"] == pytest.approx(3.80, abs=0.01)
    assert run["steps"] * 32 == run["time_ms"] and run["time_ms"] < 80_000
    # it went round the loop's centre once, anticlockwise
    path = run["path"]
    angle = np.unwrap(np.arctan2(path[:, 1], path[:, 0]))
    assert angle[-1] - angle[0] == pytest.approx(2 * math.pi, abs=0.1)


def test_a_white_floor_loses_the_line() -> None:
    """The same robot on an untextured floor sees no line and only searches (turns on the spot):
    the texture is what the controller follows."""
    from sensorium.client.examples.line_follower import LineFollower

    law = LineFollower()
    assert law.step([800.0, 800.0, 800.0]) == (-2.0, 2.0)
    assert law.offset([800.0, 320.0, 800.0]) == 0.0 and law.offset([320.0, 800.0, 800.0]) == 1.0


def test_the_controller_process_follows_the_line_like_the_in_process_run(tmp_path) -> None:
    """``sensorium controller example:line_follower`` against ``sensorium serve line_following``:
    after one lap's worth of steps the robot is where the in-process run put it (bit for bit) and
    on the line."""
    steps = line_loop.lap()["steps"]
    expected = line_loop.lap(steps=steps)
    got, proc = run_example("line_following", "line_follower", "epuck", steps)
    assert got["translation"][:2] == expected["path"][-1].tolist()
    assert line_loop.distance_to_line(np.array([got["translation"][:2]]))[0][0] < 0.03
    lines = [x for x in proc.out if x.startswith("t=")]
    assert len(lines) == steps // 31 and all("line=" in x for x in lines)
    assert EXAMPLE.is_file()
