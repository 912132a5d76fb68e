"""The batched vector environment as a Stable-Baselines3 ``VecEnv`` (``pip install '.[train]'``).

    from sensorium.gym.sb3 import SB3VecEnv
    venv = SB3VecEnv(sensorium.gym.tasks.reach_light_task(), num_envs=16, seed=0)   # flattened obs
    venv = SB3VecEnv(task, num_envs=64, seed=0, workers=2)     # the copies in 2 processes
    model = stable_baselines3.PPO("MlpPolicy", venv).learn(200_000)

Stable-Baselines3 has its own vector API: it resets a sub-env inside the step that ends its
episode and passes the ended episode's last observation in ``info["terminal_observation"]``
(with ``info["TimeLimit.truncated"]`` for a truncation). That is Gymnasium's SAME_STEP autoreset,
so this adapter runs a :class:`~sensorium.gym.vector.SensoriumVectorEnv` in that mode and renames
what it returns; each finished episode's info also carries ``"episode": {"r", "l", "reached"}``
(``reached``: it ended by termination, e.g. ReachLight's arrival).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env import VecEnv

from sensorium.gym.task import Task
from sensorium.gym.vector import SensoriumVectorEnv
from sensorium.gym.workers import SensoriumWorkersEnv, check_workers, one_process

__all__ = ["SB3VecEnv"]


class SB3VecEnv(VecEnv):
    """``num_envs`` copies of ``world``/``task`` in one batched simulation, for Stable-Baselines3."""

    def __init__(self, task: Task, num_envs: int, world=None, seed: int | None = None, flatten: bool = True,
                 workers: int = 1, **kw):
        kw.update(flatten=flatten, autoreset_mode=AutoresetMode.SAME_STEP)
        # workers=k > 1: the copies in k worker processes (sensorium.gym.workers; the same episodes)
        self.venv = (SensoriumWorkersEnv(world, task, num_envs, workers=workers, **kw)
                     if check_workers(workers, num_envs) > 1
                     else SensoriumVectorEnv(world, task, num_envs, **one_process(kw)))
        super().__init__(num_envs, self.venv.single_observation_space, self.venv.single_action_space)
        self._seed = seed
        self._actions: np.ndarray | None = None
        self._returns = np.zeros(num_envs)
        self._lengths = np.zeros(num_envs, dtype=np.int64)

    def reset(self):
        seeds = [s for s in self._seeds] if any(s is not None for s in self._seeds) else None
        obs, _ = self.venv.reset(seed=seeds if seeds is not None else self._seed)
        self._seed = None                      # later resets continue each sub-env's sequence
        self._reset_seeds()
        self._returns[:] = 0.0
        self._lengths[:] = 0
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions, dtype=np.float32).reshape(self.num_envs, -1)

    def step_wait(self):
        assert self._actions is not None, "step_async first"
        obs, rewards, terms, truncs, info = self.venv.step(self._actions)
        self._returns += rewards
        self._lengths += 1
        dones = terms | truncs
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for i in np.flatnonzero(dones).tolist():
            final = info["final_obs"]
            infos[i]["terminal_observation"] = final[i] if isinstance(final, np.ndarray) else {k: v[i] for k, v in final.items()}
            infos[i]["TimeLimit.truncated"] = bool(truncs[i] and not terms[i])
            infos[i]["episode"] = {"r": float(self._returns[i]), "l": int(self._lengths[i]), "reached": bool(terms[i])}
            self._returns[i] = 0.0
            self._lengths[i] = 0
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    # the attribute plumbing SB3's VecEnv requires (one process: the sub-envs share the vector env)
    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        return [getattr(self.venv, attr_name)] * len(self._indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *args, indices=None, **kwargs) -> list[Any]:
        if not isinstance(self.venv, SensoriumVectorEnv):
            raise NotImplementedError("env_method: the sub-envs of workers=k > 1 live in other processes")
        return [getattr(self.venv.sub_env(i), method_name)(*args, **kwargs) for i in self._indices(indices)]

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False] * len(self._indices(indices))

    def _indices(self, indices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        return [indices] if isinstance(indices, int) else list(indices)
