"""Training on the batched environment: Stable-Baselines3 PPO learns ReachLight (slow), and the
evolution strategy on Ray actors computes exactly what the same workers compute in-process."""

from __future__ import annotations

import numpy as np
import pytest

from tests._ray import ray_or_skip

pytest.importorskip("gymnasium")


def test_ppo_on_the_batched_env_reaches_the_lamp():
    """README "Training and sweeps": PPO, 16 copies, 150k env steps (about a minute and a half
    here); the last rollouts' episodes end at the lamp (ReachLight terminates only on arrival)."""
    pytest.importorskip("stable_baselines3")
    pytest.importorskip("torch")
    from sensorium.gym.examples.train_ppo import train

    curve = train(steps=150_000, envs=16, seed=0, log=lambda _line: None)
    assert curve["reached"][0] == 0.0                          # it starts knowing nothing
    assert np.mean(curve["reached"][-3:]) >= 0.8, curve["reached"]
    assert curve["return"][-1] > curve["return"][0] + 30


@pytest.mark.parametrize("argv, why", [(["--envs", "1", "--workers", "2"], "--workers must be between 1 and --envs (1)"),
                                       (["--envs", "0"], "--steps and --envs must be >= 1")])
def test_train_ppo_refuses_bad_counts_in_one_line(argv, why, capsys):
    from sensorium.gym.examples.train_ppo import main

    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2 and why in capsys.readouterr().err


def test_train_ppo_says_when_no_episode_ended_yet(capsys, monkeypatch, tmp_path):
    """A run too short for any episode to end printed a traceback (IndexError) instead of its summary.
    It leaves nothing in the temporary directory (SB3's default logger made an empty SB3-<date>
    folder there at every run)."""
    pytest.importorskip("stable_baselines3")
    pytest.importorskip("torch")
    import tempfile

    from sensorium.gym.examples.train_ppo import main

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.delenv("SB3_LOGDIR", raising=False)
    assert main(["--steps", "256", "--envs", "4"]) == 0      # (one rollout: 4 x 256 steps, no episode ends)
    assert "no episode ended yet (train longer)" in capsys.readouterr().out
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith("SB3-")] == []


def test_sb3_adapter_passes_sb3s_checker_and_hands_over_terminal_observations():
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env

    from sensorium.gym.sb3 import SB3VecEnv
    from sensorium.gym.tasks import reach_light_task

    check_env(SB3VecEnv(reach_light_task(), 2, seed=0).venv.sub_env(0), warn=True)
    venv = SB3VecEnv(reach_light_task(max_steps=3), 2, seed=1)
    obs = venv.reset()
    assert obs.shape == (2, 10) and obs.dtype == np.float32
    for _ in range(3):
        venv.step_async(np.zeros((2, 2), dtype=np.float32))
        obs, rewards, dones, infos = venv.step_wait()
    assert dones.all()
    for info in infos:
        assert info["TimeLimit.truncated"] and info["terminal_observation"].shape == (10,)
        assert info["episode"]["l"] == 3 and not info["episode"]["reached"]


@pytest.mark.slow      # worker processes
def test_sb3_adapter_with_worker_processes_gives_the_one_process_steps():
    """``SB3VecEnv(..., workers=2)``: the copies in two processes, the same observations, rewards,
    dones and SB3 infos (terminal observations, episodes) as one process, step by step."""
    pytest.importorskip("stable_baselines3")
    from sensorium.gym.sb3 import SB3VecEnv
    from sensorium.gym.tasks import reach_light_task

    envs = [SB3VecEnv(reach_light_task(max_steps=4), 5, seed=2, workers=k) for k in (1, 2)]
    try:
        outs = [e.reset() for e in envs]
        assert outs[0].tobytes() == outs[1].tobytes()
        rng = np.random.default_rng(4)
        ended = 0
        for _ in range(10):
            a = rng.uniform(-1, 1, (5, 2)).astype(np.float32)
            got = []
            for e in envs:
                e.step_async(a)
                got.append(e.step_wait())
            (o1, r1, d1, i1), (o2, r2, d2, i2) = got
            assert o1.tobytes() == o2.tobytes() and r1.tobytes() == r2.tobytes() and (d1 == d2).all()
            for a1, a2 in zip(i1, i2):
                assert a1.keys() == a2.keys() and a1.get("episode") == a2.get("episode")
                if "terminal_observation" in a1:
                    assert a1["terminal_observation"].tobytes() == a2["terminal_observation"].tobytes()
            ended += int(d1.sum())
        assert ended >= 10                       # episodes of 4 steps: every copy ended twice
        with pytest.raises(NotImplementedError, match="other processes"):
            envs[1].env_method("render")
    finally:
        for e in envs:
            e.close()


def test_evolution_strategy_on_ray_actors_equals_the_same_workers_in_process():
    """Two Ray actors (Ray bound to 127.0.0.1), each holding a batched env of 4 copies, feed the
    learner; the parameters and every return equal those of the same workers run in this process."""
    ray_or_skip()
    from sensorium.gym.ray_train import train_es

    kw = dict(task="reach_light", workers=2, copies=4, iterations=2, max_steps=15, seed=3)
    remote = train_es(**kw, use_ray=True)
    local = train_es(**kw, use_ray=False)
    assert remote["theta"].tobytes() == local["theta"].tobytes()
    for a, b in zip(remote["curve"], local["curve"]):
        assert (a["mean_return"], a["best_return"], a["env_steps"]) == (b["mean_return"], b["best_return"], b["env_steps"])
    assert np.count_nonzero(remote["theta"]) > 0               # the learner moved
    assert remote["curve"][0]["env_steps"] == 2 * 4 * 15       # every copy ran one 15-step episode
