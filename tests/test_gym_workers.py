"""``workers=k``: the batched vector env split over k processes equals the one-process env bit for bit."""

from __future__ import annotations

import gc
import inspect
import math
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
from gymnasium.vector import AutoresetMode  # noqa: E402

import sensorium.gym  # noqa: E402,F401  (registers the ids)
from sensorium.gym import ReachLight, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402
from sensorium.gym.workers import (  # noqa: E402
    MAX_POLL_S,
    PARENT_WATCH_S,
    SensoriumWorkersEnv,
    WorkerError,
    check_poll,
    split,
)

slow = pytest.mark.slow        # these start worker processes
REACH, LIDAR = "sensorium/ReachLight-v0", "sensorium/LidarAvoid-v0"
WAIT_S = 120.0                 # a generous bound for a call that must not hang (the machine is shared)


LAMBDA_LINE = inspect.currentframe().f_lineno + 1     # (the line the error message must name)
DIVIDES_BY_ZERO = lambda sim, robot, obs: 1.0 / (float(robot.pose.translation[2]) * 0.0)  # noqa: E731


def _make(env_id: str, n: int, workers: int, **kw):
    return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", workers=workers, **kw)


def _same(a, b, where: str) -> None:
    """Every array equal bit for bit with the same dtype, dicts with the same keys (in order), tuples item
    by item, all the way down."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and list(a) == list(b), f"{where}: keys {list(a)} vs {list(b)}"
        for k in a:
            _same(a[k], b[k], f"{where}[{k}]")
        return
    if isinstance(a, (tuple, list)):
        assert isinstance(b, (tuple, list)) and len(a) == len(b), f"{where}: {len(a)} items vs {len(b)}"
        for k, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{k}]")
        return
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype and a.shape == b.shape, f"{where}: {a.dtype}{a.shape} vs {b.dtype}{b.shape}"
    np.testing.assert_array_equal(a, b, err_msg=where)


def _gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


def _within(call, seconds: float = WAIT_S):
    """Run call() in a thread; its exception (it must raise) once it ends, failing if it does not end in time."""
    got: list[BaseException] = []

    def run():
        try:
            call()
        except BaseException as exc:  # noqa: BLE001
            got.append(exc)

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(seconds)
    assert not t.is_alive(), f"the call did not return within {seconds:g} s"
    assert got, "the call did not raise"
    return got[0]


def test_the_copies_are_split_in_contiguous_slices_differing_by_at_most_one():
    assert split(7, 3) == [(0, 3), (3, 5), (5, 7)]
    assert split(8, 2) == [(0, 4), (4, 8)]
    assert split(3, 3) == [(0, 1), (1, 2), (2, 3)]
    for n in range(1, 40):
        for k in range(1, n + 1):
            s = split(n, k)
            sizes = [hi - lo for lo, hi in s]
            assert s[0][0] == 0 and s[-1][1] == n and all(a[1] == b[0] for a, b in zip(s, s[1:]))
            assert max(sizes) - min(sizes) <= 1 and min(sizes) >= 1


@pytest.mark.parametrize("workers, num_envs, why", [
    (0, 4, "workers must be >= 1, got 0"),
    (-2, 4, "workers must be >= 1, got -2"),
    (2.0, 4, "workers must be a whole number of processes, got 2.0"),
    ("2", 4, "workers must be a whole number of processes, got '2'"),
    (True, 4, "workers must be a whole number of processes, got True"),
    (5, 3, "workers=5 is more than num_envs=3: each worker needs at least one copy"),
    (2, 2.5, "num_envs must be an integer >= 1, got 2.5"),       # (the one-process env's checks)
])
def test_refused_workers_say_why_in_one_line_before_any_process_starts(workers, num_envs, why):
    for make in (lambda: _make(REACH, num_envs, workers),
                 lambda: SensoriumWorkersEnv(None, sensorium.gym.tasks.reach_light_task(), num_envs, workers=workers)):
        with pytest.raises(ValueError) as e:
            make()
        assert str(e.value) == why
    assert mp.active_children() == []


@pytest.mark.parametrize("poll_s", [-1e-6, MAX_POLL_S * 2, float("nan"), "0.001", True, [0.001]])
def test_a_bad_poll_is_refused_in_one_line_before_any_process_starts(poll_s):
    why = f"poll_s must be a number of seconds in [0, {MAX_POLL_S:g}], got {poll_s!r}"
    for make in (lambda: _make(REACH, 4, 2, poll_s=poll_s),
                 lambda: SensoriumWorkersEnv(None, sensorium.gym.tasks.reach_light_task(), 4, workers=2, poll_s=poll_s)):
        with pytest.raises(ValueError) as e:
            make()
        assert str(e.value) == why
    with pytest.raises(ValueError, match=r"^poll_s is the worker processes' poll: it needs workers=k > 1$"):
        _make(REACH, 4, 1, poll_s=0.0)
    assert mp.active_children() == []


def test_stable_baselines3s_env_takes_the_poll_only_with_workers():
    pytest.importorskip("stable_baselines3")
    from sensorium.gym.sb3 import SB3VecEnv

    task = sensorium.gym.tasks.reach_light_task()
    with pytest.raises(ValueError, match=r"^poll_s is the worker processes' poll: it needs workers=k > 1$"):
        SB3VecEnv(task, 4, workers=1, poll_s=0.0)
    with pytest.raises(ValueError, match=r"^poll_s must be a number of seconds in \[0, 0.01\], got -1$"):
        SB3VecEnv(task, 4, workers=2, poll_s=-1)
    assert mp.active_children() == []


def test_a_poll_in_range_is_taken_as_seconds():
    assert check_poll(0) == 0.0 and check_poll(np.float32(0.001)) == pytest.approx(0.001)
    assert check_poll(MAX_POLL_S) == MAX_POLL_S


@slow
@pytest.mark.parametrize("env_id, n, workers, mode, flatten", [
    (REACH, 7, 3, AutoresetMode.NEXT_STEP, False),      # an uneven split
    (LIDAR, 5, 2, AutoresetMode.NEXT_STEP, False),      # range images
    (REACH, 6, 2, AutoresetMode.SAME_STEP, True),       # final_obs / final_info, one flat Box
])
def test_sub_env_i_of_the_workers_env_is_sub_env_i_of_the_one_process_env(env_id, n, workers, mode, flatten):
    kw = {"max_steps": 4, "autoreset_mode": mode, "flatten": flatten, "precision": "fast"}
    ref, envs = _make(env_id, n, 1, **kw), _make(env_id, n, workers, **kw)
    try:
        assert isinstance(ref, SensoriumVectorEnv) and isinstance(envs, SensoriumWorkersEnv)
        assert envs.observation_space == ref.observation_space and envs.action_space == ref.action_space
        assert envs.single_observation_space == ref.single_observation_space
        assert envs.metadata == ref.metadata and envs.num_envs == ref.num_envs
        rng = np.random.default_rng(11)
        ended = np.zeros(n, dtype=np.int64)

        def lockstep(steps: int, what: str) -> None:
            for t in range(steps):
                a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
                got, want = envs.step(a), ref.step(a)
                for name, x, y in zip(("obs", "reward", "terminated", "truncated", "info"), got, want):
                    _same(x, y, f"{what} step {t} {name}")
                ended[:] += got[2] | got[3]

        _same(envs.reset(seed=5), ref.reset(seed=5), "reset(seed=5)")
        lockstep(12, "after reset(seed=5)")
        assert (ended >= 2).all(), ended               # every sub-env went through two autoresets
        seeds = [40 + 3 * i for i in range(n)]
        _same(envs.reset(seed=seeds), ref.reset(seed=seeds), "reset(seed=list)")
        lockstep(6, "after reset(seed=list)")
        mask = np.zeros(n, dtype=bool)
        mask[1] = True                                  # only worker 0's copies reset: the others report as they are
        opts = {"reset_mask": mask}
        _same(envs.reset(seed=9, options=opts), ref.reset(seed=9, options=opts), "reset(reset_mask)")
        lockstep(5, "after a masked reset")
    finally:
        ref.close()
        envs.close()


@slow
def test_a_custom_task_with_lambdas_runs_through_the_workers_with_the_same_values():
    task = Task(robot="epuck", observations={"ls0": 64, "ps0": 64}, control_period_ms=64, max_steps=5,
                reward=lambda sim, robot, obs: -math.hypot(*robot.pose.translation[:2]) + 1e-3 * float(obs["ls0"][0]),
                terminated=lambda sim, robot, obs: bool(robot.pose.translation[0] > 10.0))
    ref = SensoriumVectorEnv(None, task, 3, render_mode="rgb_array", render_size=32)
    envs = SensoriumWorkersEnv(None, task, 3, workers=2, render_mode="rgb_array", render_size=32)
    try:
        _same(envs.reset(seed=[1, 2, 3]), ref.reset(seed=[1, 2, 3]), "reset")
        rng = np.random.default_rng(3)
        for t in range(8):
            a = rng.uniform(-1, 1, (3, 2))
            got, want = envs.step(a), ref.step(a)
            _same(list(got[:4]), list(want[:4]), f"step {t}")
            _same(got[4], want[4], f"step {t} info")
            assert t == 5 or (got[1] != 0).all()           # the lambda's reward (0 only on the autoreset step)
        images, want_images = envs.render(), ref.render()
        assert len(images) == 3 and images[0].shape == (32, 32, 3)
        for i, (x, y) in enumerate(zip(images, want_images)):
            _same(x, y, f"render {i}")
    finally:
        ref.close()
        envs.close()


@slow
def test_render_at_the_default_size_returns_every_image():
    """A worker's render reply (2 x 256x256x3 bytes) is larger than a pipe holds: the worker wrote it
    before signalling its answer and the parent read only after the signal, so render() hung."""
    envs = _make(REACH, 4, 2, render_mode="rgb_array")
    ref = gym.make_vec(REACH, num_envs=4, vectorization_mode="vector_entry_point", render_mode="rgb_array")
    try:
        envs.reset(seed=0)
        ref.reset(seed=0)
        images: list = []
        t = threading.Thread(target=lambda: images.append(envs.render()), daemon=True)
        t.start()
        t.join(WAIT_S)
        assert not t.is_alive(), f"render() did not return within {WAIT_S:g} s"
        assert len(images[0]) == 4 and images[0][0].shape == (256, 256, 3)
        _same(images[0], ref.render(), "render")
    finally:
        ref.close()
        if images:
            envs.close()


@slow
def test_a_workers_exception_and_a_bad_action_are_one_clear_error():
    task = Task(robot="epuck", observations={"ls0": 64}, control_period_ms=64, max_steps=5,
                reward=DIVIDES_BY_ZERO, terminated=ReachLight("lamp").terminated)
    envs = SensoriumWorkersEnv(None, task, 5, workers=2)
    try:
        with pytest.raises(RuntimeError, match="call reset"):
            envs.step(np.zeros((5, 2)))
        envs.reset(seed=0)
        with pytest.raises(ValueError) as bad:              # sub-env 4 (worker 1's second copy), named as one env does
            envs.step(np.array([[0, 0]] * 4 + [[np.nan, 0]], dtype=np.float32))
        assert str(bad.value) == "sub-env 4: action must be 2 finite values, got array([nan,  0.], dtype=float32)"
        with pytest.raises(WorkerError) as e:
            envs.step(np.zeros((5, 2)))
        text = str(e.value)
        assert "\n" not in text
        assert text.startswith(f"worker 0 of 2 (sub-envs 0-2, pid {envs.pids[0]}) failed in step: "
                               "ZeroDivisionError: float division by zero (at ")
        assert f"(at <lambda>, line {LAMBDA_LINE} of the file defining it)" in text   # where the task's callable raised
        assert "(and 1 more worker(s) failed); reset() before stepping again" in text
        with pytest.raises(RuntimeError, match="call reset"):
            envs.step(np.zeros((5, 2)))
        envs.reset(seed=1)                                   # the workers live on
    finally:
        envs.close()


@slow
def test_a_killed_worker_makes_the_next_step_raise_and_takes_the_others_down():
    envs = _make(REACH, 4, 2, max_steps=5)
    pids = envs.pids
    envs.reset(seed=0)
    envs.step(np.zeros((4, 2)))
    os.kill(pids[1], signal.SIGKILL)
    err = _within(lambda: envs.step(np.zeros((4, 2))))
    assert isinstance(err, WorkerError)
    assert str(err) == (f"worker 1 of 2 (sub-envs 2-3, pid {pids[1]}) died during step (killed by signal SIGKILL): "
                        "the environment is closed; build a new one")
    assert all(map(_gone, pids))
    with pytest.raises(WorkerError, match="died during step"):      # and says so again, at once
        envs.reset(seed=0)
    envs.close()


@slow
def test_a_worker_killed_while_the_parent_waits_for_its_step_is_seen_and_named():
    # every copy's reward sleeps, so both workers are inside their step when worker 1 is killed
    slow_reward = lambda sim, robot, obs: time.sleep(1.5) or 0.0  # noqa: E731
    task = Task(robot="epuck", observations={"ls0": 64}, control_period_ms=64, max_steps=5, reward=slow_reward)
    envs = SensoriumWorkersEnv(None, task, 2, workers=2)
    try:
        envs.reset(seed=0)
        pid = envs.pids[1]
        threading.Timer(0.5, os.kill, (pid, signal.SIGKILL)).start()
        err = _within(lambda: envs.step(np.zeros((2, 2))))
        assert isinstance(err, WorkerError)
        assert str(err) == (f"worker 1 of 2 (sub-envs 1-1, pid {pid}) died during step (killed by signal SIGKILL): "
                            "the environment is closed; build a new one")
        assert all(map(_gone, envs.pids))
    finally:
        envs.close()


@slow
@pytest.mark.parametrize("poll_s", [0.0, 200e-6])
def test_workers_asleep_between_steps_wake_for_the_next_one_with_the_same_values(poll_s):
    # past the poll (if any) and past a sleeping worker's check on its parent (PARENT_WATCH_S)
    ref, envs = _make(REACH, 4, 1, max_steps=6), _make(REACH, 4, 2, max_steps=6, poll_s=poll_s)
    try:
        _same(envs.reset(seed=3), ref.reset(seed=3), "reset")
        rng = np.random.default_rng(5)
        for t, pause in enumerate([0.0, 2e-3, 2.5 * PARENT_WATCH_S, 0.0, 2.5 * PARENT_WATCH_S]):
            time.sleep(pause)
            a = rng.uniform(-1, 1, (4, 2)).astype(np.float32)
            _same(envs.step(a), ref.step(a), f"step {t} after {pause:g} s")
        assert not any(map(_gone, envs.pids))
    finally:
        ref.close()
        envs.close()


@slow
def test_close_and_garbage_collection_leave_no_worker_behind():
    envs = _make(LIDAR, 3, 3, max_steps=5)
    pids = envs.pids
    assert len(set(pids)) == 3 and not any(map(_gone, pids))
    envs.reset(seed=0)
    envs.close()
    assert all(map(_gone, pids))
    with pytest.raises(RuntimeError, match="closed"):
        envs.reset(seed=0)
    dropped = _make(REACH, 2, 2)
    pids = dropped.pids
    dropped.reset(seed=0)
    del dropped
    gc.collect()
    assert all(map(_gone, pids))


@pytest.mark.parametrize("ending", ["exit", "SIGKILL"])
def test_no_worker_outlives_its_parent_whether_it_exits_without_close_or_is_killed(ending):
    script = (
        "import os, sys, gymnasium as gym, sensorium.gym\n"
        "envs = gym.make_vec('sensorium/ReachLight-v0', num_envs=2, vectorization_mode='vector_entry_point', workers=2)\n"
        "envs.reset(seed=0)\n"
        "print(*envs.pids, flush=True)\n"
        + ("os.kill(os.getpid(), 9)\n" if ending == "SIGKILL" else "")
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=WAIT_S,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert done.returncode == (-signal.SIGKILL if ending == "SIGKILL" else 0), done.stderr
    pids = [int(p) for p in done.stdout.split()]
    assert len(pids) == 2
    deadline = time.monotonic() + WAIT_S       # (an orphaned worker ends within PARENT_WATCH_S)
    while not all(map(_gone, pids)) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert all(map(_gone, pids))
