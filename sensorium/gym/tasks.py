"""Ready-made environments on the embedded arena world (the registered Gymnasium ids)."""

from __future__ import annotations

from sensorium.gym.env import SensoriumEnv
from sensorium.gym.task import AvoidObstacles, ReachLight, Task, random_start

IR = [f"ps{i}" for i in range(8)]


def reach_light(world=None, render_mode=None, max_steps: int = 400, **kw) -> SensoriumEnv:
    """e-puck: drive to the lamp (1.4, 1.4) from its world pose, seeing two light sensors and eight
    infra-red sensors every 64 ms (two basic steps)."""
    goal = ReachLight("lamp", radius=0.2)
    task = Task(robot="epuck", observations={n: 64 for n in ["ls0", "ls1", *IR]}, control_period_ms=64,
                max_steps=max_steps, reward=goal, terminated=goal.terminated)
    return SensoriumEnv(world, task, render_mode=render_mode, **kw)


def avoid_obstacles(world=None, render_mode=None, max_steps: int = 1000, **kw) -> SensoriumEnv:
    """e-puck: explore from a random start in the free middle of the arena without touching anything."""
    goal = AvoidObstacles()
    task = Task(robot="epuck", observations={n: 32 for n in IR}, control_period_ms=32, max_steps=max_steps,
                reward=goal, terminated=goal.terminated, start=random_start((-0.5, 0.5), (-0.3, 0.3)))
    return SensoriumEnv(world, task, render_mode=render_mode, **kw)


def lidar_avoid(world=None, render_mode=None, max_steps: int = 1000, **kw) -> SensoriumEnv:
    """scout: the same exploration task seen through its 360-ray lidar and four sonars."""
    goal = AvoidObstacles(near=0.3)
    task = Task(robot="scout", observations={"lidar": 64, "sonar_front": 64, "sonar_left": 64,
                                             "sonar_right": 64, "sonar_back": 64},
                control_period_ms=64, max_steps=max_steps, reward=goal, terminated=goal.terminated,
                start=random_start((-0.3, 0.3), (-0.2, 0.6)))
    return SensoriumEnv(world, task, render_mode=render_mode, **kw)
