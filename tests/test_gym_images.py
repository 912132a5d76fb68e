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
