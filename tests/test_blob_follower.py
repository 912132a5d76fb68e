"""The camera's done-when (issue 23): a Webots-style controller that reads camera images runs
unchanged. ``example:blob_follower`` on the bundled ``blob_chase`` world finds the red ball in its
e-puck camera's images, turns to it (searching first: it starts facing away), drives to it past a
green and a blue distractor and stops in front of it — in process (FAST and EXACT), and as a real
controller process against ``sensorium serve``, bit for bit like the in-process run."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _serve import run_example

from sensorium.client.examples.blob_follower import BlobFollower, red_pixels
from sensorium.server.sim.simulation import Simulation

BALL = np.array([0.6, 0.55])


def chase(precision: str = "exact", steps: int = 700) -> dict:
    sim = Simulation.from_file("blob_chase", precision=precision)
    robot = sim.robot("epuck")
    cam = sim.device("epuck/camera")
    cam.enable(sim.basic_time_step)
    for m in robot.motors.values():
        m.set_position(math.inf)
        m.set_velocity(0.0)
    law = BlobFollower()
    seen, wheels = [], (0.0, 0.0)
    for _ in range(steps):
        sim.step()
        wheels = law.step(cam.image.tobytes(), 52, 39)
        robot.motor("left wheel motor").set_velocity(wheels[0])
        robot.motor("right wheel motor").set_velocity(wheels[1])
        seen.append(law.seen)
    pose = robot.pose
    heading = math.atan2(pose.rotation[1, 0], pose.rotation[0, 0])
    to_ball = BALL - pose.translation[:2]
    return {"xy": pose.translation[:2].copy(), "distance": float(np.linalg.norm(to_ball)),
            "bearing": math.remainder(math.atan2(to_ball[1], to_ball[0]) - heading, 2 * math.pi),
            "seen": seen, "wheels": wheels, "offset": law.offset}


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_the_follower_finds_the_red_ball_and_stops_in_front_of_it(precision):
    run = chase(precision)
    assert run["seen"][0] == 0                         # facing away: nothing red at first, it searches
    first = next(i for i, n in enumerate(run["seen"]) if n)
    assert 5 < first < 60
    assert 0.2 < run["distance"] < 0.3                 # in front of the ball (radius 0.05), not through it
    assert abs(run["bearing"]) < 0.05 and abs(run["offset"]) < 0.05
    left, right = run["wheels"]                        # stopped (no forward speed): the ball fills a
    assert abs(left + right) < 1e-12 and abs(left) < 0.2   # quarter of the image; a last small correction
    assert run["seen"][-1] >= 0.25 * 52 * 39


def test_red_pixels_of_a_bgra_image():
    w, h = 4, 2
    img = bytearray(b"\x10\x10\x10\xff" * (w * h))
    img[4 * 5:4 * 5 + 4] = bytes((20, 30, 200, 255))   # (x=1, y=1): red
    img[4 * 2:4 * 2 + 4] = bytes((20, 150, 200, 255))  # orange-ish: green too high, not red
    assert red_pixels(bytes(img), w, h) == (1, 1.0)
    assert BlobFollower().step(None, w, h) == (0.0, 0.0)


@pytest.mark.slow
def test_the_controller_process_drives_like_the_in_process_run():
    steps = 250
    expected = chase("exact", steps)
    got, proc = run_example("blob_chase", "blob_follower", "epuck", steps)
    assert got["translation"][:2] == expected["xy"].tolist()
    lines = [x for x in proc.out if x.startswith("t=")]
    assert len(lines) == steps // 31 and all("red_pixels=0 " not in x for x in lines[1:])
