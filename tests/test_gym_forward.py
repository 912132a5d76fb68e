"""The gym's heading is the drive's ``forward`` (sensorium/server/sim/frames.py ``heading``), not the robot's
own x axis: ``info["pose"]``'s yaw, ``random_start``'s yaw and ``render()``'s heading line, in the
single and the vector env alike.

Closed form: driven straight (both wheels alike), a robot moves along its forward, so the yaw equals
the atan2 of its displacement (north over east, the world's ENU view). Two NUE robots whose forward
is not their x: one built y-up (Webots' NUE robots) driving along its own -z, one built z-up driving
along its own y (Webots' ``four_wheels`` how-to), and that one in an ENU world; each turned ``TURN``
about the world's up."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.gym import SensoriumEnv, Task
from sensorium.gym.task import random_start
from sensorium.gym.vector import SensoriumVectorEnv
from sensorium.schemas import world as wm
from sensorium.server.world.poses import matrix_quaternion

TURN = 0.7          # each robot's turn about the world's up (y) from its built pose
START = (0.4, 0.1, -0.3)     # NUE: north, up, east


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


Z_UP_IN_NUE = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
"""A robot built z-up stood in a NUE world: its x north, its z up (the world's y), its y west (-z)."""

def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


CASES = {
    # name: (the robot's rotation in the NUE world, its drive's forward, that forward's heading (ENU yaw))
    # y-up: own -z is Ry(TURN) @ (0, 0, -1) = (-sin, 0, -cos): east -cos, north -sin -> TURN - pi
    "y_up_minus_z": (ry(TURN), [0.0, 0.0, -1.0], TURN - math.pi),
    # z-up: own y is Ry(TURN) @ (0, 0, -1), the same direction
    "z_up_y": (ry(TURN) @ Z_UP_IN_NUE, [0.0, 1.0], TURN - math.pi),
    # the same robot in an ENU world (z up): own y is Rz(TURN) @ (0, 1, 0), at TURN + pi/2
    "enu_y": (rz(TURN), [0.0, 1.0], TURN + math.pi / 2.0),
}


def rover_world(rotation: np.ndarray, forward: list[float], system: str = "NUE") -> wm.World:
    """The rover at START (the ENU world's translation the same place in its axes)."""
    at = list(START) if system == "NUE" else [START[2], START[0], START[1]]
    return wm.World.model_validate({
        "world_info": {"coordinate_system": system, "basic_time_step": 16},
        "robots": [{"name": "rover", "pose": {"translation": at, "quaternion": list(matrix_quaternion(rotation))},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 10.0,
                                           "forward": forward},
                    "devices": [{"device": "GPS", "name": "gps"}]}]})


def enu(p) -> np.ndarray:
    """A NUE point's (east, north)."""
    return np.array([p[2], p[0]])


@pytest.mark.parametrize("case", sorted(CASES))
def test_driven_straight_the_yaw_is_the_angle_of_the_displacement(case):
    rotation, forward, yaw = CASES[case]
    world = rover_world(rotation, forward, "ENU" if case.startswith("enu") else "NUE")
    env = SensoriumEnv(world, Task(max_steps=None), precision="exact")
    venv = SensoriumVectorEnv(world, Task(max_steps=None), num_envs=2, precision="exact")
    _, info = env.reset(seed=1)
    _, vinfo = venv.reset(seed=1)
    start = info["pose"].copy()
    assert start[:2] == pytest.approx(list(enu(START)), abs=1e-15)
    assert start[2] == pytest.approx(yaw, abs=1e-12)          # before: the own x's, pi/2 (or -pi/2) off
    for t in range(20):
        _, _, _, _, info = env.step(np.array([1.0, 1.0]))
        _, _, _, _, vinfo = venv.step(np.array([[1.0, 1.0], [1.0, 1.0]]))
        d = info["pose"][:2] - start[:2]
        assert math.hypot(*d) == pytest.approx(0.05 * 10.0 * 0.016 * (t + 1), rel=1e-9)    # straight at r w
        assert info["pose"][2] == pytest.approx(math.atan2(d[1], d[0]), abs=1e-9), t
        for i in range(2):       # every copy reads the single env's pose, bit for bit
            assert vinfo["pose"][i].tobytes() == info["pose"].tobytes(), (t, i)
    env.close()
    venv.close()


@pytest.mark.parametrize("case", sorted(CASES))
def test_random_start_heads_the_drives_forward_at_the_drawn_yaw(case):
    """A start drawn at one yaw: the robot stands upright (its own up axis along the world's y), its
    pose reads that yaw, and driven straight it moves along it."""
    rotation, forward, _ = CASES[case]
    system = "ENU" if case.startswith("enu") else "NUE"
    world = rover_world(rotation, forward, system)
    want = 2.2
    task = Task(max_steps=None, start=random_start(x=(0.5, 0.5), y=(-0.25, -0.25), yaw=(want, want)))
    env = SensoriumEnv(world, task, precision="exact")
    venv = SensoriumVectorEnv(world, task, num_envs=2, precision="exact")
    _, info = env.reset(seed=3)
    _, vinfo = venv.reset(seed=3)
    assert info["pose"] == pytest.approx([0.5, -0.25, want], abs=1e-12)
    for i in range(2):
        assert vinfo["pose"][i] == pytest.approx([0.5, -0.25, want], abs=1e-12)
    up_axis = 1 if case.startswith("y_up") else 2
    assert env.sim.robot("rover").pose.rotation[1 if system == "NUE" else 2, up_axis] == pytest.approx(1.0, abs=1e-12)
    for _ in range(10):
        _, _, _, _, info = env.step(np.array([1.0, 1.0]))
        _, _, _, _, vinfo = venv.step(np.array([[1.0, 1.0], [1.0, 1.0]]))
    d = info["pose"][:2] - np.array([0.5, -0.25])
    assert math.atan2(d[1], d[0]) == pytest.approx(want, abs=1e-9)
    assert vinfo["pose"][1][:2] - np.array([0.5, -0.25]) == pytest.approx(list(d), abs=1e-12)
    env.close()
    venv.close()


def test_render_draws_the_heading_line_along_the_forward():
    """The white heading line leaves the robot toward its forward's heading (TURN - pi, seen from
    above: east right, north up), not its own x's."""
    rotation, forward, yaw = CASES["y_up_minus_z"]
    env = SensoriumEnv(rover_world(rotation, forward), Task(max_steps=None), render_mode="rgb_array", render_size=128)
    env.reset(seed=0)
    img = env.render()
    white = np.argwhere((img == 255).all(axis=2))          # (row, column)
    grey = np.argwhere((img == 200).all(axis=2))           # the robot's disc (no body shapes)
    assert len(white) >= 3 and len(grey)
    centre = grey.mean(axis=0)
    tip = white[np.argmax(((white - centre) ** 2).sum(axis=1))]
    seen = math.atan2(-(tip[0] - centre[0]), tip[1] - centre[1])       # rows grow southward
    assert abs(math.remainder(seen - yaw, 2.0 * math.pi)) < 0.25
    env.close()
