"""A single and a vector environment of one AvoidObstacles task on one world, for tests that compare
the gym's rewards across them and across the compiled helper's passes and numpy."""

from __future__ import annotations

from pathlib import Path


def avoid_envs(path: Path, helper: bool, monkeypatch, copies: int = 2):
    """``(env, venv)``: ``SensoriumEnv`` and a ``SensoriumVectorEnv`` of ``copies`` copies of the world at
    ``path``, robot "bot" scored by ``AvoidObstacles(near=0.05)`` (no observations), both reset with seed 0;
    without ``helper`` the vector env scores in numpy (the C reward and outcome passes patched out)."""
    from sensorium.gym.env import SensoriumEnv
    from sensorium.gym.task import AvoidObstacles, Task
    from sensorium.gym.vector import SensoriumVectorEnv
    from sensorium.server.raycast import packets
    from sensorium.server.world.loader import load_world

    if not helper:
        monkeypatch.setattr(packets, "avoid_reward", lambda *args: None)
        monkeypatch.setattr(packets, "avoid_outcome", lambda *args: None)
    goal = AvoidObstacles(near=0.05)
    task = Task(robot="bot", observations=[], reward=goal, terminated=goal.terminated)
    env = SensoriumEnv(load_world(path), task)
    env.reset(seed=0)
    venv = SensoriumVectorEnv(load_world(path), task, copies)
    venv.reset(seed=0)
    return env, venv
