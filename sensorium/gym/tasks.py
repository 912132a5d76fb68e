"""Ready-made environments on the embedded arena world and, for a car, the car_park world (the
registered Gymnasium ids).

Each id has a single environment (``entry_point``: :class:`~sensorium.gym.env.SensoriumEnv`) and a
batched vector environment (``vector_entry_point``: :class:`~sensorium.gym.vector.SensoriumVectorEnv`,
what ``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")`` returns;
with ``workers=k`` > 1 a :class:`~sensorium.gym.workers.SensoriumWorkersEnv`, the copies split over
k processes); sub-environment *i* of the vector environment equals the single environment with the
same seed.
"""

from __future__ import annotations

from sensorium.gym.env import SensoriumEnv
from sensorium.gym.task import AvoidObstacles, ReachLight, Task, random_start

IR = [f"ps{i}" for i in range(8)]


def reach_light_task(max_steps: int = 400) -> Task:
    """e-puck: drive to the lamp (1.4, 1.4) from its world pose, seeing two light sensors and eight
    infra-red sensors every 64 ms (two basic steps)."""
    goal = ReachLight("lamp", radius=0.2)
    return Task(robot="epuck", observations={n: 64 for n in ["ls0", "ls1", *IR]}, control_period_ms=64,
                max_steps=max_steps, reward=goal, terminated=goal.terminated)


def avoid_obstacles_task(max_steps: int = 1000) -> Task:
    """e-puck: explore from a random start in the free middle of the arena without touching anything."""
    goal = AvoidObstacles()
    return Task(robot="epuck", observations={n: 32 for n in IR}, control_period_ms=32, max_steps=max_steps,
                reward=goal, terminated=goal.terminated, start=random_start((-0.5, 0.5), (-0.3, 0.3)))


def lidar_avoid_task(max_steps: int = 1000) -> Task:
    """scout: the same exploration task seen through its 360-ray lidar and four sonars."""
    goal = AvoidObstacles(near=0.3)
    return Task(robot="scout", observations={"lidar": 64, "sonar_front": 64, "sonar_left": 64,
                                             "sonar_right": 64, "sonar_back": 64},
                control_period_ms=64, max_steps=max_steps, reward=goal, terminated=goal.terminated,
                start=random_start((-0.3, 0.3), (-0.2, 0.6)))


def car_reach_light_task(max_steps: int = 400) -> Task:
    """car (car_park world): drive the car-like robot (steering, speed) from a random start in the
    west half to the lamp over the free bay in the north-east, seeing two light sensors, three
    sonars and a compass every 64 ms (two basic steps); arrival within 0.6 m ends the episode."""
    goal = ReachLight("lamp", radius=0.6)
    return Task(robot="car", observations={n: 64 for n in CAR_SENSORS}, control_period_ms=64,
                max_steps=max_steps, reward=goal, terminated=goal.terminated,
                start=random_start((-4.0, -1.5), (-3.0, 3.0)))


CAR_SENSORS = ["light_left", "light_right", "sonar_front", "sonar_left", "sonar_right", "compass"]


def reach_light(world=None, render_mode=None, max_steps: int = 400, **kw) -> SensoriumEnv:
    return SensoriumEnv(world, reach_light_task(max_steps), render_mode=render_mode, **kw)


def avoid_obstacles(world=None, render_mode=None, max_steps: int = 1000, **kw) -> SensoriumEnv:
    return SensoriumEnv(world, avoid_obstacles_task(max_steps), render_mode=render_mode, **kw)


def lidar_avoid(world=None, render_mode=None, max_steps: int = 1000, **kw) -> SensoriumEnv:
    return SensoriumEnv(world, lidar_avoid_task(max_steps), render_mode=render_mode, **kw)


def car_reach_light(world=None, render_mode=None, max_steps: int = 400, **kw) -> SensoriumEnv:
    return SensoriumEnv(world or car_park(), car_reach_light_task(max_steps), render_mode=render_mode, **kw)


def car_park():
    from sensorium.worlds import world_path

    return world_path("car_park")


def _vector(task: Task, world, num_envs: int, render_mode, workers: int = 1, **kw):
    """The batched vector env; ``workers=k`` > 1: k processes of it side by side (:mod:`.workers`)."""
    from sensorium.gym.vector import SensoriumVectorEnv  # imported on use: the single envs do not need it
    from sensorium.gym.workers import SensoriumWorkersEnv, check_workers, one_process

    kw.pop("max_episode_steps", None)        # make_vec passes the spec's (None here: tasks truncate themselves)
    if check_workers(workers, num_envs) > 1:
        return SensoriumWorkersEnv(world, task, num_envs, workers=workers, render_mode=render_mode, **kw)
    return SensoriumVectorEnv(world, task, num_envs, render_mode=render_mode, **one_process(kw))


def reach_light_vector(num_envs: int = 1, world=None, render_mode=None, max_steps: int = 400, **kw):
    return _vector(reach_light_task(max_steps), world, num_envs, render_mode, **kw)


def avoid_obstacles_vector(num_envs: int = 1, world=None, render_mode=None, max_steps: int = 1000, **kw):
    return _vector(avoid_obstacles_task(max_steps), world, num_envs, render_mode, **kw)


def lidar_avoid_vector(num_envs: int = 1, world=None, render_mode=None, max_steps: int = 1000, **kw):
    return _vector(lidar_avoid_task(max_steps), world, num_envs, render_mode, **kw)


def car_reach_light_vector(num_envs: int = 1, world=None, render_mode=None, max_steps: int = 400, **kw):
    return _vector(car_reach_light_task(max_steps), world or car_park(), num_envs, render_mode, **kw)


reach_light.__doc__ = reach_light_task.__doc__
car_reach_light.__doc__ = car_reach_light_task.__doc__
avoid_obstacles.__doc__ = avoid_obstacles_task.__doc__
lidar_avoid.__doc__ = lidar_avoid_task.__doc__
