"""The Gymnasium loop on a Sensorium world, with a random and a scripted policy; reports
environment steps per second for one environment and for Gymnasium's vector environments.

    python -m sensorium.gym.examples.random_policy                  # ReachLight, 300 steps, 1/2/4 envs
    python -m sensorium.gym.examples.random_policy --env sensorium/LidarAvoid-v0 --envs 1 8 --steps 200

Each vector size runs three ways: ``sync`` and ``async`` (Gymnasium's vector envs of single envs)
and ``batched`` (the copies in one batched simulation, ``gymnasium.make_vec(..., "vector_entry_point")``).

Nothing is trained: the point is the loop any Gymnasium-compatible library runs, and its speed.
The scripted policy is a Braitenberg vehicle (turn toward the brighter light sensor) where the
observation has ``ls0``/``ls1``, else it drives straight and turns away from the nearest obstacle.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import sensorium.gym  # noqa: F401  (registers the sensorium/* ids)


def scripted(obs: dict, high: float) -> np.ndarray:
    """A policy without learning, batched or not (arrays with a leading env axis work too)."""
    if "ls0" in obs and "ls1" in obs:
        a, b = obs["ls0"][..., 0].astype(np.float64), obs["ls1"][..., 0].astype(np.float64)
        turn = np.where(a + b > 0, (a - b) / np.maximum(a + b, 1e-9), 0.0)
        left, right = 0.6 - 0.4 * turn, 0.6 + 0.4 * turn
    else:
        left = right = np.full(np.shape(next(iter(obs.values())))[:-1] or (), 0.8)
    return (np.stack([left, right], axis=-1) * high).astype(np.float32)


def run(env_id: str, n_envs: int, steps: int, mode: str = "sync", policy: str = "random", seed: int = 0) -> dict:
    """``steps`` vectorised steps (``steps * n_envs`` env steps; n_envs = 0: one plain env)."""
    if n_envs == 0:
        env = gym.make(env_id)
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        high = float(env.action_space.high[0])
        total_reward, episodes = 0.0, 0
        t0 = time.perf_counter()
        for _ in range(steps):
            a = env.action_space.sample() if policy == "random" else scripted(obs, high)
            obs, r, term, trunc, _ = env.step(a)
            total_reward += r
            if term or trunc:
                episodes += 1
                obs, _ = env.reset()
        dt = time.perf_counter() - t0
        env.close()
        return {"env": env_id, "envs": 1, "mode": "single", "policy": policy, "env_steps": steps, "seconds": dt,
                "env_steps_per_s": steps / dt, "episodes": episodes, "mean_reward": total_reward / steps}
    if mode == "batched":      # n copies in one batched simulation (the ids' vector_entry_point)
        venv = gym.make_vec(env_id, num_envs=n_envs, vectorization_mode="vector_entry_point")
    else:
        cls = gym.vector.AsyncVectorEnv if mode == "async" else gym.vector.SyncVectorEnv
        venv = cls([lambda: gym.make(env_id) for _ in range(n_envs)])
    try:
        obs, _ = venv.reset(seed=seed)
        venv.action_space.seed(seed)
        high = float(venv.single_action_space.high[0])
        total_reward, episodes = 0.0, 0
        t0 = time.perf_counter()
        for _ in range(steps):
            a = venv.action_space.sample() if policy == "random" else scripted(obs, high)
            obs, r, term, trunc, _ = venv.step(a)     # sub-environments reset themselves (next step)
            total_reward += float(np.sum(r))
            episodes += int(np.sum(term | trunc))
        dt = time.perf_counter() - t0
    finally:
        venv.close()
    return {"env": env_id, "envs": n_envs, "mode": mode, "policy": policy, "env_steps": steps * n_envs,
            "seconds": dt, "env_steps_per_s": steps * n_envs / dt, "episodes": episodes,
            "mean_reward": total_reward / (steps * n_envs)}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    p.add_argument("--env", default="sensorium/ReachLight-v0", help="a registered sensorium/* id")
    p.add_argument("--steps", type=int, default=300, help="vector steps per measurement (default 300)")
    p.add_argument("--envs", type=int, nargs="+", default=[1, 2, 4], help="vector sizes (default 1 2 4)")
    p.add_argument("--policy", choices=["random", "scripted"], default="scripted")
    args = p.parse_args(argv)
    if args.steps < 1 or min(args.envs) < 1:
        p.error(f"--steps and every --envs size must be >= 1 (got {args.steps} and {args.envs})")
    if args.env not in gym.registry or not args.env.startswith("sensorium/"):
        ids = ", ".join(sorted(k for k in gym.registry if k.startswith("sensorium/")))
        p.error(f"--env {args.env!r} is not a registered sensorium id ({ids})")
    rows = [run(args.env, 0, args.steps, policy=args.policy)]
    for n in args.envs:
        for mode in ("sync", "async", "batched"):
            rows.append(run(args.env, n, args.steps, mode, args.policy))
    print(f"{args.env}, {args.policy} policy, {args.steps} steps per measurement")
    print(f"{'mode':>7} {'envs':>5} {'env steps/s':>12} {'episodes':>9} {'mean reward':>12}")
    for r in rows:
        print(f"{r['mode']:>7} {r['envs']:>5} {r['env_steps_per_s']:>12.1f} {r['episodes']:>9} {r['mean_reward']:>12.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
