"""Image observations in sensorium.gym (issue 23): a camera named in Task.observations is a uint8
(height, width, 3) RGB Box equal to the device's image, a range finder a float32 (height, width)
Box with "no hit" as max_range; images are not observed unless named; the env passes Gymnasium's
checker and a seed gives the same image bytes."""

from __future__ import annotations

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402

from sensorium.gym import SensoriumEnv, Task  # noqa: E402
from sensorium.schemas import world as wm  # noqa: E402


def world(seed=0) -> wm.World:
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 32, "random_seed": seed},
        "solids": [{"name": "wall", "pose": {"translation": [0.6, 0, 0.1]}, "geometry": {"type": "box", "size": [0.1, 0.4, 0.2]},
                    "appearance": {"base_color": [0.9, 0.2, 0.1]}}],
        "lights": [{"type": "PointLight", "location": [0.3, 0.0, 0.3], "intensity": 1.0}],
        "robots": [{"name": "bot", "pose": {"translation": [0, 0, 0.05]},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 6.28},
                    "devices": [{"device": "Camera", "name": "cam", "width": 16, "height": 12, "noise": 0.02,
                                 "pose": {"translation": [0.04, 0, 0]}},
                                {"device": "RangeFinder", "name": "depth", "width": 8, "height": 6, "max_range": 0.7,
                                 "pose": {"translation": [0.04, 0, 0]}},
                                {"device": "DistanceSensor", "name": "ds", "pose": {"translation": [0.04, 0, 0]}}]}]})


def test_camera_and_range_finder_observations():
    env = SensoriumEnv(world(), Task(robot="bot", observations=["cam", "depth", "ds"], max_steps=5))
    space = env.observation_space
    assert space["cam"].shape == (12, 16, 3) and space["cam"].dtype == np.uint8
    assert space["depth"].shape == (6, 8) and space["depth"].dtype == np.float32
    obs, _ = env.reset(seed=3)
    sim = env.sim
    np.testing.assert_array_equal(obs["cam"], sim.device("bot/cam").image[:, :, [2, 1, 0]])
    assert obs["cam"].std() > 1.0                                  # a picture with a red wall in it
    depth = sim.device("bot/depth").range_image
    np.testing.assert_array_equal(obs["depth"], np.where(np.isinf(depth), np.float32(0.7), depth))
    assert np.isinf(depth).any() and np.isfinite(depth).any()
    obs2, _ = env.reset(seed=3)
    assert obs2["cam"].tobytes() == obs["cam"].tobytes()           # same seed, same image bytes
    check_env(env, skip_render_check=True)
    env.close()


def test_images_are_not_observed_unless_named():
    env = SensoriumEnv(world(), Task(robot="bot", max_steps=5))
    assert set(env.observation_space.spaces) == {"ds"}
    env.reset(seed=0)
    assert env.sim.counters["rays_camera"] == 0 and env.sim.counters["rays_range_finder"] == 0
    env.close()


def test_the_auto_engine_runs_image_tasks_batched_with_the_same_episodes():
    """The batched engine simulates cameras (batched_camera.py):
    engine="auto" (the PettingZoo env's default) runs a task observing one on the one-copy batched
    simulation, giving engine="simulation"'s episode bit for bit; engine="batched" and the batched
    vector env take it, semi-transparent surfaces included."""
    from sensorium.gym import SensoriumParallelEnv
    from sensorium.gym.vector import SensoriumVectorEnv

    task = Task(robot="bot", observations=["cam", "depth", "ds"], max_steps=5)
    auto, ref = SensoriumEnv(world(), task, engine="auto"), SensoriumEnv(world(), task, engine="simulation")
    assert auto.engine == "batched"
    rng = np.random.default_rng(0)
    for seed in (4, None):
        a, _ = auto.reset(seed=seed)
        b, _ = ref.reset(seed=seed)
        for _ in range(3):
            assert all(a[k].tobytes() == b[k].tobytes() for k in ("cam", "depth", "ds"))
            act = rng.uniform(-1, 1, 2).astype(np.float32)
            a, ra, *_ = auto.step(act)
            b, rb, *_ = ref.step(act)
            assert ra == rb
    assert SensoriumParallelEnv(world(), {"bot": task}).engine == "batched"
    # a semi-transparent wall too (tests/test_batched_camera.py compares such images byte for byte)
    wall = world().solids[0]
    glass = wall.model_copy(update={"appearance": wall.appearance.model_copy(update={"transparency": 0.5})})
    glassy = world().model_copy(update={"solids": [glass]})
    assert SensoriumEnv(glassy, Task(robot="bot", observations=["cam"]), engine="batched").engine == "batched"
    assert SensoriumVectorEnv(glassy, Task(robot="bot", observations=["cam"]), 2).num_envs == 2
    assert SensoriumEnv(world(), Task(robot="bot", observations=["depth", "ds"]), engine="auto").engine == "batched"
    # the same robot observed without its images runs batched (its camera is never computed)
    assert SensoriumEnv(world(), Task(robot="bot", observations=["ds"]), engine="auto").engine == "batched"
