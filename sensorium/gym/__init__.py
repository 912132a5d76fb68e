"""Gymnasium environments on Sensorium worlds (``pip install 'sensorium[gym]'``).

    import gymnasium as gym
    env = gym.make("sensorium.gym:sensorium/ReachLight-v0")        # or build your own:
    from sensorium.gym import SensoriumEnv, Task, ReachLight
    env = SensoriumEnv("my_world.yaml", Task(robot="epuck", observations={"ls0": 32}, reward=ReachLight(), ...))

Registered ids (on the embedded arena world): ``sensorium/ReachLight-v0`` (e-puck, light and
infra-red sensors, drive to the lamp), ``sensorium/AvoidObstacles-v0`` (e-puck, infra-red sensors,
explore without contact), ``sensorium/LidarAvoid-v0`` (scout, 360-ray lidar + sonars); on the
car_park world ``sensorium/CarReachLight-v0`` (a car-like robot: (steering, speed) actions, light
sensors and sonars, drive to the lamp).
``SensoriumParallelEnv`` (PettingZoo) runs several robots of one world as agents.

Batched: ``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")`` gives a
:class:`~sensorium.gym.vector.SensoriumVectorEnv`: N copies of the world in one simulation (one
cast per ray kind for all of them), each sub-environment bit-identical to the single one.
"""

from __future__ import annotations

from gymnasium.envs.registration import register, registry

from sensorium.gym.env import SensoriumEnv
from sensorium.gym.task import AvoidObstacles, ReachLight, Task, clearance, never, random_start
from sensorium.gym.tasks import avoid_obstacles, lidar_avoid, reach_light

__all__ = ["SensoriumEnv", "SensoriumParallelEnv", "SensoriumVectorEnv", "Task", "ReachLight", "AvoidObstacles", "clearance", "never", "random_start",
           "reach_light", "avoid_obstacles", "lidar_avoid"]



def __getattr__(name: str):
    if name == "SensoriumParallelEnv":      # needs pettingzoo (the [gym] extra); imported on first use
        from sensorium.gym.multi import SensoriumParallelEnv

        return SensoriumParallelEnv
    if name == "SensoriumVectorEnv":
        from sensorium.gym.vector import SensoriumVectorEnv

        return SensoriumVectorEnv
    raise AttributeError(f"module 'sensorium.gym' has no attribute {name!r}")


for _id, _fn in (("sensorium/ReachLight-v0", "reach_light"),
                 ("sensorium/AvoidObstacles-v0", "avoid_obstacles"),
                 ("sensorium/LidarAvoid-v0", "lidar_avoid"),
                 ("sensorium/CarReachLight-v0", "car_reach_light")):
    if _id not in registry:
        register(id=_id, entry_point=f"sensorium.gym.tasks:{_fn}", vector_entry_point=f"sensorium.gym.tasks:{_fn}_vector")
