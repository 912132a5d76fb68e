"""Training on Ray: actors each holding a batched environment, feeding one learner (``pip install '.[gym,ray]'``).

    from sensorium.gym.ray_train import train_es
    result = train_es("reach_light", workers=2, copies=64, iterations=30)      # Ray on 127.0.0.1
    result["curve"]                      # per iteration: mean return, reached fraction, env steps/s

The learner is an evolution strategy (OpenAI-ES: antithetic Gaussian perturbations of a linear
``tanh`` policy, rank-normalised returns, plain gradient steps). It suits the batched environment:
every copy of a worker's :class:`~sensorium.gym.vector.SensoriumVectorEnv` runs one perturbation, so
one vector step advances ``copies`` candidate policies at once, and a population of
``workers x copies`` costs one episode of wall time. Per iteration the learner sends each actor the
parameters and a noise seed (a few kB, never observations), the actors run their copies for one
episode each and send back one return per copy.

Ray is started bound to 127.0.0.1 (``sensorium.sweep.engines.init_ray``) unless ``address`` joins
an existing cluster; an actor per worker, one CPU each. The same functions run without Ray
(:func:`evaluate`), which is how the tests check that the actors compute exactly what a local
process computes.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

__all__ = ["train_es", "evaluate", "Policy", "TASKS"]

TASKS = ("reach_light", "avoid_obstacles", "lidar_avoid")


def _make_env(task: str, copies: int, max_steps: int | None, precision: str):
    from sensorium.gym import tasks
    from sensorium.gym.vector import SensoriumVectorEnv

    if task not in TASKS:
        raise ValueError(f"task must be one of {', '.join(TASKS)}, got {task!r}")
    kw = {} if max_steps is None else {"max_steps": max_steps}
    return SensoriumVectorEnv(None, getattr(tasks, f"{task}_task")(**kw), copies, flatten=True, precision=precision)


class Policy:
    """``a = tanh(W o' + b)``, ``o'`` the observation scaled to [-1, 1] by its box (unbounded
    entries pass through); parameters as one flat vector."""

    def __init__(self, low: np.ndarray, high: np.ndarray, actions: int = 2):
        finite = np.isfinite(low) & np.isfinite(high) & (high > low)
        self.shift = np.where(finite, (high + low) / 2.0, 0.0)
        self.scale = np.where(finite, (high - low) / 2.0, 1.0)
        self.inputs, self.actions = len(low), actions
        self.size = (self.inputs + 1) * actions

    def act(self, theta: np.ndarray, obs: np.ndarray) -> np.ndarray:
        """Actions for a batch: ``theta`` (copies, size) or (size,), ``obs`` (copies, inputs)."""
        th = np.broadcast_to(theta, (len(obs), self.size)).reshape(len(obs), self.actions, self.inputs + 1)
        x = (obs - self.shift) / self.scale
        return np.tanh(np.einsum("cai,ci->ca", th[:, :, :-1], x) + th[:, :, -1]).astype(np.float32)


def evaluate(env, policy: Policy, thetas: np.ndarray, seed: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Each copy runs one episode with its parameters (``thetas`` (copies, size)), reset with
    seeds ``seed + i``: (returns, reached, env steps)."""
    n = env.num_envs
    obs, _ = env.reset(seed=seed)
    returns = np.zeros(n)
    reached = np.zeros(n, dtype=bool)
    running = np.ones(n, dtype=bool)
    steps = 0
    while running.any():
        obs, r, term, trunc, _ = env.step(policy.act(thetas, obs))
        steps += int(running.sum())
        returns += np.where(running, r, 0.0)
        reached |= running & term
        running &= ~(term | trunc)          # a finished copy keeps stepping (autoreset) but no longer counts
    return returns, reached, steps


def _perturbations(seed: int, count: int, size: int) -> np.ndarray:
    """The population's noise: ``count // 2`` Gaussian directions and their negatives."""
    half = np.random.default_rng(seed).standard_normal((count // 2, size))
    return np.concatenate([half, -half])


class _Worker:
    """The actor: one batched environment, its slice of the population."""

    def __init__(self, task: str, copies: int, max_steps: int | None, precision: str, rank: int):
        self.env = _make_env(task, copies, max_steps, precision)
        space = self.env.single_observation_space
        self.policy = Policy(space.low.astype(np.float64), space.high.astype(np.float64))
        self.rank, self.copies = rank, copies

    def size(self) -> int:
        return self.policy.size

    def run(self, theta: np.ndarray, sigma: float, noise_seed: int, population: int, episode_seed: int) -> dict:
        eps = _perturbations(noise_seed, population, self.policy.size)[self.rank * self.copies:(self.rank + 1) * self.copies]
        t0 = time.perf_counter()
        ret, reached, steps = evaluate(self.env, self.policy, theta[None, :] + sigma * eps, episode_seed)
        return {"returns": ret, "reached": reached, "steps": steps, "seconds": time.perf_counter() - t0}


def _ranks(x: np.ndarray) -> np.ndarray:
    r = np.empty(len(x))
    r[np.argsort(x, kind="stable")] = np.arange(len(x))
    return r / (len(x) - 1) - 0.5


def train_es(task: str = "reach_light", workers: int = 2, copies: int = 32, iterations: int = 20,
             sigma: float = 0.1, lr: float = 0.05, seed: int = 0, max_steps: int | None = None,
             precision: str = "fast", address: str | None = None, use_ray: bool = True, log=None) -> dict[str, Any]:
    """Train a linear policy with OpenAI-ES on ``workers`` Ray actors of ``copies`` copies each
    (``use_ray=False``: the same workers in this process, one after the other). Returns the final
    parameters and the curve (per iteration: mean and best return, reached fraction, env steps/s
    across the workers, wall seconds)."""
    if (workers * copies) % 2:
        raise ValueError("workers x copies must be even (antithetic pairs)")
    population = workers * copies
    started = False
    ray = None
    if use_ray:
        import ray as _ray

        from sensorium.sweep.engines import init_ray

        started = not _ray.is_initialized()
        ray = init_ray(address, workers)
        Remote = ray.remote(num_cpus=1)(_Worker)
        actors = [Remote.remote(task, copies, max_steps, precision, k) for k in range(workers)]
        size = ray.get(actors[0].size.remote())
    else:
        local = [_Worker(task, copies, max_steps, precision, k) for k in range(workers)]
        size = local[0].size()
    theta = np.zeros(size)
    curve: list[dict] = []
    try:
        for it in range(iterations):
            noise_seed, episode_seed = seed * 1_000_003 + it, seed * 7919 + it * 104729
            t0 = time.perf_counter()
            if ray is not None:
                parts = ray.get([a.run.remote(theta, sigma, noise_seed, population, episode_seed) for a in actors])
            else:
                parts = [w.run(theta, sigma, noise_seed, population, episode_seed) for w in local]
            wall = time.perf_counter() - t0
            returns = np.concatenate([p["returns"] for p in parts])
            reached = np.concatenate([p["reached"] for p in parts])
            steps = sum(p["steps"] for p in parts)
            eps = _perturbations(noise_seed, population, size)
            theta = theta + lr / (population * sigma) * (_ranks(returns) @ eps)
            row = {"iteration": it, "mean_return": float(returns.mean()), "best_return": float(returns.max()),
                   "reached": float(reached.mean()), "env_steps": steps, "wall_s": wall,
                   "env_steps_per_s": steps / wall}
            curve.append(row)
            if log is not None:
                log(f"  iteration {it:3d}: mean return {row['mean_return']:7.2f}, reached {100 * row['reached']:5.1f} %, "
                    f"{row['env_steps_per_s']:,.0f} env steps/s")
    finally:
        if ray is not None and started:
            ray.shutdown()
    return {"theta": theta, "curve": curve, "workers": workers, "copies": copies, "task": task}
