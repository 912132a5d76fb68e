"""Train Stable-Baselines3 PPO on the batched ReachLight environment; plot its learning curve.

    pip install '.[train]'                       # torch (CPU) and stable-baselines3; see README
    python -m sensorium.gym.examples.train_ppo --steps 150000 --envs 16 --png ppo_reach_light.png

The e-puck starts at its world pose and must reach the lamp (1.4, 1.4), 3 m away, within 400
actions of 64 ms: at the e-puck's top speed that takes ~360 of them, so only a policy that heads
straight for the light and keeps going gets there. The observation is the two light sensors and
eight infra-red sensors (flattened); the action two normalised wheel speeds. Prints the steps/s
and, per rollout, the mean return and the fraction of finished episodes that reached the lamp;
``--png`` writes the learning curve. Deterministic for a seed (one thread).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np


def train(steps: int = 150_000, envs: int = 16, seed: int = 0, precision: str = "fast", log=print,
          workers: int = 1) -> dict:
    """Train and return the learning curve: env steps, mean episode return and reached fraction per
    rollout, plus the wall time and env steps/s. ``workers`` > 1: the copies in that many worker
    processes (the same episodes; wall time gained only where cores are free)."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.logger import Logger

    from sensorium.gym.sb3 import SB3VecEnv
    from sensorium.gym.tasks import reach_light_task

    torch.set_num_threads(1)
    venv = SB3VecEnv(reach_light_task(), envs, seed=seed, precision=precision, workers=workers)
    curve: dict[str, list] = {"steps": [], "return": [], "reached": [], "episodes": []}

    class Curve(BaseCallback):
        def __init__(self):
            super().__init__()
            self.finished: list[dict] = []

        def _on_step(self) -> bool:
            for info in self.locals["infos"]:
                if "episode" in info:
                    self.finished.append(info["episode"])
            return True

        def _on_rollout_end(self) -> None:
            if self.finished:
                curve["steps"].append(int(self.num_timesteps))
                curve["return"].append(float(np.mean([e["r"] for e in self.finished])))
                curve["reached"].append(float(np.mean([e["reached"] for e in self.finished])))
                curve["episodes"].append(len(self.finished))
                log(f"  {self.num_timesteps:>8d} steps: return {curve['return'][-1]:7.2f}, "
                    f"reached {100 * curve['reached'][-1]:5.1f} % of {len(self.finished)} episodes")
                self.finished = []

    model = PPO("MlpPolicy", venv, n_steps=256, batch_size=1024, n_epochs=5, learning_rate=1e-3, gamma=0.995,
                gae_lambda=0.95, ent_coef=0.0, policy_kwargs={"net_arch": [64, 64]}, seed=seed, verbose=0,
                device="cpu")
    # a logger with no outputs: SB3's default (verbose 0) makes an empty SB3-<date> folder in the
    # system's temporary directory at every run; the curve above is what this example reports
    model.set_logger(Logger(folder=None, output_formats=[]))
    t0 = time.perf_counter()
    model.learn(total_timesteps=steps, callback=Curve())
    wall = time.perf_counter() - t0
    venv.close()
    curve["wall_s"] = wall
    curve["steps_per_s"] = steps / wall
    curve["envs"] = envs
    curve["precision"] = precision
    return curve


def plot(curve: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.6), dpi=110)
    steps = np.array(curve["steps"]) / 1000
    ax.plot(steps, np.array(curve["reached"]) * 100, color="tab:green", label="episodes reaching the lamp (%)")
    ax.set_xlabel("env steps (thousands)")
    ax.set_ylabel("reached the lamp (%)", color="tab:green")
    ax.set_ylim(-2, 102)
    ax2 = ax.twinx()
    ax2.plot(steps, curve["return"], color="tab:blue", alpha=0.7, label="mean episode return")
    ax2.set_ylabel("mean episode return", color="tab:blue")
    ax.set_title(f"PPO on batched ReachLight ({curve['envs']} copies, {curve['precision']}): "
                 f"{curve['wall_s'] / 60:.1f} min, {curve['steps_per_s']:.0f} steps/s")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--steps", type=int, default=150_000, help="env steps to train (default 150000)")
    p.add_argument("--envs", type=int, default=16, help="copies in the batched env (default 16)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--precision", choices=["fast", "exact"], default="fast")
    p.add_argument("--workers", type=int, default=1, help="worker processes holding the copies (default 1)")
    p.add_argument("--png", type=Path, help="write the learning curve here")
    p.add_argument("--json", type=Path, help="write the curve as JSON here")
    a = p.parse_args(argv)
    if a.steps < 1 or a.envs < 1:
        p.error(f"--steps and --envs must be >= 1 (got {a.steps} and {a.envs})")
    if not 1 <= a.workers <= a.envs:
        p.error(f"--workers must be between 1 and --envs ({a.envs}), got {a.workers}")
    curve = train(a.steps, a.envs, a.seed, a.precision, workers=a.workers)
    last = (f"last rollout: {100 * curve['reached'][-1]:.0f} % of episodes reached the lamp" if curve["reached"]
            else "no episode ended yet (train longer)")
    print(f"trained {a.steps} env steps in {curve['wall_s']:.0f} s ({curve['steps_per_s']:.0f} env steps/s); {last}")
    if a.png:
        plot(curve, a.png)
        print(f"wrote {a.png}")
    if a.json:
        a.json.write_text(json.dumps(curve, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
