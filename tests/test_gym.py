"""sensorium.gym: Gymnasium API conformance, exact resets, closed-form observations and rewards."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402
from gymnasium.vector import AsyncVectorEnv, SyncVectorEnv  # noqa: E402

from sensorium.gym import AvoidObstacles, ReachLight, SensoriumEnv, Task  # noqa: E402
from sensorium.gym.tasks import avoid_obstacles, lidar_avoid, reach_light  # noqa: E402
from sensorium.schemas import world as wm  # noqa: E402
from sensorium.server.devices import lidar as lmath  # noqa: E402

IDS = ["sensorium/ReachLight-v0", "sensorium/AvoidObstacles-v0", "sensorium/LidarAvoid-v0"]


def room(robot_pose=((0.0, 0.0, 0.05), (0, 0, 1, 0.0)), half=1.0, devices=(), seed=0) -> wm.World:
    """A square room: inner wall faces at x, y = +-half, walls 0..0.3 m high; one e-puck-sized robot."""
    walls = []
    for name, (x, y, sx, sy) in {"e": (half + 0.05, 0, 0.1, 2 * half + 0.2), "w": (-half - 0.05, 0, 0.1, 2 * half + 0.2),
                                 "n": (0, half + 0.05, 2 * half + 0.2, 0.1), "s": (0, -half - 0.05, 2 * half + 0.2, 0.1)}.items():
        walls.append({"name": f"wall_{name}", "pose": {"translation": [x, y, 0.15]},
                      "geometry": {"type": "box", "size": [sx, sy, 0.3]}})
    t, r = robot_pose
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 32, "random_seed": seed},
        "solids": walls,
        "lights": [{"type": "PointLight", "name": "lamp", "location": [0.5, 0.5, 0.1]}],
        "robots": [{"name": "bot", "pose": {"translation": list(t), "rotation": list(r)},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05},
                             "appearance": {"base_color": [0.0, 1.0, 0.0]}},
                    "differential_drive": {"wheel_radius": 0.0205, "axle_length": 0.052, "max_wheel_speed": 6.28},
                    "devices": list(devices)}],
    })


@pytest.mark.parametrize("env_id", IDS)
def test_registered_envs_pass_the_gymnasium_checker(env_id):
    env = gym.make(f"sensorium.gym:{env_id}", render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    obs, _ = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    env.close()


def _episode(env, seed, actions):
    obs, info = env.reset(seed=seed)
    out = [(obs, 0.0, False, False, info)]
    for a in actions:
        out.append(env.step(a))
    return out


def _same(a, b) -> bool:
    for (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) in zip(a, b, strict=True):
        if set(o1) != set(o2) or any(o1[k].tobytes() != o2[k].tobytes() for k in o1):
            return False
        if (r1, te1, tr1, i1["time_ms"]) != (r2, te2, tr2, i2["time_ms"]) or i1["pose"].tobytes() != i2["pose"].tobytes():
            return False
    return True


@pytest.mark.parametrize("precision", ["exact", "fast"])
def test_same_seed_gives_a_bit_identical_episode_and_reset_restores_the_world(precision):
    env = avoid_obstacles(precision=precision)
    rng = np.random.default_rng(0)
    actions = [rng.uniform(-1, 1, 2).astype(np.float32) for _ in range(40)]
    first = _episode(env, 11, actions)
    other = _episode(env, 12, actions)      # another seed in between: noise and start pose change ...
    again = _episode(env, 11, actions)      # ... and seed 11 comes back exactly
    assert _same(first, again)
    assert not _same(first, other)
    # a fresh environment object reproduces it too
    assert _same(first, _episode(avoid_obstacles(precision=precision), 11, actions))
    # without a seed, episodes continue the seeded sequence: not a repeat of the first
    env.reset(seed=11)
    assert not _same(first, _episode(env, None, actions))


def test_observation_and_action_bounds_come_from_the_world():
    env = reach_light()
    box = env.observation_space["ps0"]
    assert box.shape == (1,) and box.dtype == np.float32
    assert box.low[0] == np.float32(67.19) and box.high[0] == np.float32(4095)
    assert env.observation_space["ls0"].low[0] == 0 and env.observation_space["ls0"].high[0] == 4096
    assert env.action_space.low.tolist() == [-1.0] * 2 and env.action_space.high.tolist() == [1.0] * 2   # normalised
    wheel = reach_light(actions="wheel").action_space
    assert wheel.low.tolist() == [np.float32(-6.28)] * 2 and wheel.high.tolist() == [np.float32(6.28)] * 2
    lid = lidar_avoid().observation_space["lidar"]
    assert lid.shape == (1, 360) and lid.dtype == np.float32 and lid.high.max() == 6.0
    with pytest.raises(ValueError, match="no such device"):
        SensoriumEnv(None, Task(robot="epuck", observations=["nope"]))
    with pytest.raises(ValueError, match="multiple of the world's basic_time_step"):
        SensoriumEnv(None, Task(robot="epuck", control_period_ms=40))
    with pytest.raises(ValueError, match="not in the world"):
        SensoriumEnv(None, Task(robot="ghost"))


@pytest.mark.parametrize("kw, why", [
    ({"precision": "exakt"}, "precision must be one of fast, exact, got 'exakt'"),
    ({"precision": None}, "precision must be one of fast, exact, got None"),
    ({"render_size": 0}, "render_size must be an integer number of pixels from 1 to 4096, got 0"),
    ({"render_size": -5}, "render_size must be an integer number of pixels from 1 to 4096, got -5"),
    ({"render_size": 64.5}, "render_size must be an integer number of pixels from 1 to 4096, got 64.5"),
    ({"render_size": 10**6}, "render_size must be an integer number of pixels from 1 to 4096, got 1000000"),
    ({"task": Task(max_steps=0)}, "task max_steps must be a whole number of actions >= 1, or None (never truncated), got 0"),
    ({"task": Task(max_steps=-1)}, "task max_steps must be a whole number of actions >= 1, or None (never truncated), got -1"),
    ({"task": Task(max_steps=2.5)}, "task max_steps must be a whole number of actions >= 1, or None (never truncated), got 2.5"),
    ({"task": Task(control_period_ms=0)}, "task control_period_ms=0 must be a positive multiple of the world's basic_time_step (32 ms)"),
    ({"task": Task(control_period_ms=64.0)}, "task control_period_ms=64.0 must be a positive multiple of the world's basic_time_step (32 ms)"),
])
def test_bad_options_are_refused_when_the_env_is_made_in_every_kind_of_env(kw, why):
    """Before: a wrong precision failed at the first reset with "'exakt' is not a valid Precision", a
    render_size of 0 with a ZeroDivisionError at the first render (10**6: a 2.7 TiB allocation),
    max_steps=0 or -1 truncated every episode at its first step, 2.5 truncated at the third, and
    control_period_ms=0 silently meant one basic step."""
    from sensorium.gym import SensoriumParallelEnv
    from sensorium.gym.vector import SensoriumVectorEnv
    from sensorium.gym.workers import SensoriumWorkersEnv

    task = kw.pop("task", Task(robot="epuck"))
    makers = [lambda: SensoriumEnv(None, task, **kw), lambda: SensoriumVectorEnv(None, task, 2, **kw),
              lambda: SensoriumWorkersEnv(None, task, 2, workers=2, **kw)]
    if task.robot is not None:
        makers.append(lambda: SensoriumParallelEnv(None, {"epuck": task}, **kw))
    for make in makers:
        with pytest.raises(ValueError) as e:
            make()
        assert str(e.value) == why
    ok = SensoriumEnv(None, Task(robot="epuck", max_steps=1), render_mode="rgb_array", render_size=np.int64(3))
    ok.reset(seed=0)
    assert ok.render().shape == (3, 3, 3)
    assert ok.step(ok.action_space.sample())[3] is True            # max_steps=1: truncated after one action


def test_lidar_observation_matches_the_square_room_in_closed_form():
    # above the body: a Webots lidar sees its own robot
    lidar = {"device": "Lidar", "name": "lidar", "horizontal_resolution": 64, "field_of_view": 2 * math.pi,
             "number_of_layers": 1, "near": 0.01, "pose": {"translation": [0, 0, 0.04]}, "min_range": 0.02, "max_range": 1.3}
    env = SensoriumEnv(room(devices=[lidar]), Task(observations={"lidar": 32}))
    obs, _ = env.reset(seed=0)
    cfg = env.sim.robot("bot").device("lidar").params
    az = lmath.column_azimuths(cfg)
    expected = 1.0 / np.maximum(np.abs(np.cos(az)), np.abs(np.sin(az)))
    expected = np.where(expected < 1.3, expected, 1.3)       # no hit (inf in Webots) -> max_range
    assert (expected == 1.3).any() and (expected < 1.3).any()
    np.testing.assert_allclose(obs["lidar"][0], expected, rtol=0, atol=2e-6)


def test_driving_straight_moves_the_exact_distance_and_ends_on_contact_with_the_wall():
    # robot at the centre facing +x; the wall's inner face is at x = 1: contact when the body
    # (radius 0.035) is within 0.005 m of it, i.e. once x >= 1 - 0.035 - 0.005
    goal = AvoidObstacles(near=0.1, contact_distance=0.005, contact_penalty=10.0)
    env = SensoriumEnv(room(), Task(observations=[], reward=goal, terminated=goal.terminated, max_steps=None),
                       actions="wheel")
    _, info = env.reset(seed=0)
    v = 6.28 * 0.0205                                            # m/s at full wheel speed
    step_m = v * 0.032
    contact_at = math.ceil((1.0 - 0.035 - 0.005) / step_m)
    for k in range(1, contact_at + 1):
        _, reward, terminated, truncated, info = env.step(np.array([6.28, 6.28], dtype=np.float32))
        assert info["pose"][0] == pytest.approx(k * step_m, abs=1e-12)
        gap = 1.0 - 0.035 - k * step_m
        if k < contact_at:
            assert not terminated
            assert reward == pytest.approx(1.0 - min(max(1.0 - gap / 0.1, 0.0), 1.0), abs=1e-6)
    assert terminated and not truncated
    assert reward == pytest.approx(-10.0 + (1.0 - min(max(1.0 - gap / 0.1, 0.0), 1.0)), abs=1e-6)


def test_reach_light_rewards_telescope_to_the_distance_gained():
    goal = ReachLight("lamp", radius=0.2, progress_weight=10.0, bonus=5.0, step_cost=0.01)
    env = SensoriumEnv(room(), Task(observations=[], reward=goal, terminated=goal.terminated, max_steps=200),
                       actions="wheel")
    _, info = env.reset(seed=0)
    d0 = math.hypot(0.5, 0.5)
    total, n, terminated = 0.0, 0, False
    while not terminated and n < 200:
        # turn toward the lamp, then drive straight at it
        x, y, yaw = info["pose"]
        err = math.atan2(0.5 - y, 0.5 - x) - yaw
        err = (err + math.pi) % (2 * math.pi) - math.pi
        a = [6.0, 6.0] if abs(err) < 0.05 else ([-2.0, 2.0] if err > 0 else [2.0, -2.0])
        _, r, terminated, _, info = env.step(np.array(a, dtype=np.float32))
        total += r
        n += 1
    assert terminated
    d_end = math.hypot(0.5 - info["pose"][0], 0.5 - info["pose"][1])
    assert d_end < 0.2
    assert total == pytest.approx(10.0 * (d0 - d_end) - 0.01 * n + 5.0, abs=1e-9)


def test_render_draws_the_robot_and_the_light_where_they_are():
    env = SensoriumEnv(room(), Task(observations=[]), render_mode="rgb_array", render_size=200)
    env.reset(seed=0)
    img = env.render()
    assert img.shape == (200, 200, 3) and img.dtype == np.uint8
    r = env._renderer
    col, row = r._px(np.array([[0.0, 0.0]]))[0]          # robot at the origin: body colour (green)
    assert tuple(img[int(row) + 1, int(col) - 1]) == (0, 255, 0)
    col, row = r._px(np.array([[0.5, 0.5]]))[0]          # lamp
    assert tuple(img[int(row), int(col)]) == (255, 230, 40)
    col, row = r._px(np.array([[1.05, 0.0]]))[0]          # east wall (no appearance: white)
    assert tuple(img[int(row), int(col)]) == (255, 255, 255)
    env.sim.robot("bot").set_pose([-0.5, -0.5, 0.05])     # the robot is drawn where it is now
    img2 = env.render()
    col, row = r._px(np.array([[-0.5, -0.5]]))[0]
    assert tuple(img2[int(row) + 1, int(col) - 1]) == (0, 255, 0)
    col, row = r._px(np.array([[0.0, 0.0]]))[0]
    assert tuple(img2[int(row) + 1, int(col) - 1]) != (0, 255, 0)


def test_render_draws_a_moved_solid_where_it_is_and_a_removed_one_no_more():
    w = room().model_dump(mode="json", exclude_none=True)
    w["lights"] = []
    grey, red, blue = (0.5, 0.5, 0.5), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    w["solids"] += [{"name": "floor", "geometry": {"type": "plane", "size": [2.0, 2.0]},
                     "appearance": {"base_color": list(grey)}},
                    {"name": "crate", "pose": {"translation": [0.5, -0.5, 0.05]},
                     "geometry": {"type": "box", "size": [0.2, 0.2, 0.1]}, "appearance": {"base_color": list(red)}},
                    {"name": "block", "pose": {"translation": [-0.5, -0.5, 0.05]},
                     "geometry": {"type": "box", "size": [0.2, 0.2, 0.1]}, "appearance": {"base_color": list(blue)}}]
    env = SensoriumEnv(wm.World.model_validate(w), Task(observations=[]), render_mode="rgb_array", render_size=200)
    env.reset(seed=0)
    floor, crate, block = (128, 128, 128), (255, 0, 0), (0, 0, 255)

    def at(img, x, y):
        col, row = env._renderer._px(np.array([[x, y]]))[0]
        return tuple(int(v) for v in img[int(row), int(col)])

    img = env.render()
    assert at(img, 0.5, -0.5) == crate and at(img, -0.5, -0.5) == block and at(img, -0.5, 0.5) == floor
    layer = env._renderer._static
    env.render()
    assert env._renderer._static is layer              # nothing changed: the static layer is not drawn again
    env.sim.remove_solid("crate")
    img = env.render()
    assert at(img, 0.5, -0.5) == floor and at(img, -0.5, -0.5) == block
    env.sim.set_solid_pose("block", [-0.5, 0.5, 0.05])
    img = env.render()
    assert at(img, -0.5, -0.5) == floor and at(img, -0.5, 0.5) == block and at(img, 0.5, -0.5) == floor
    # a solid a Supervisor imports is drawn from the next frame (a green box where the crate was)
    env.sim.import_nodes('Solid { name "gift" translation 0.5 -0.5 0.05 children [ Shape { appearance '
                         'PBRAppearance { baseColor 0 1 0 } geometry Box { size 0.2 0.2 0.1 } } ] }')
    img = env.render()
    assert at(img, 0.5, -0.5) == (0, 255, 0) and at(img, -0.5, 0.5) == block


@pytest.mark.parametrize("vector_cls", [SyncVectorEnv, AsyncVectorEnv])
def test_vector_envs_step_in_lockstep_with_single_envs(vector_cls):
    n = 3
    venv = vector_cls([reach_light for _ in range(n)])
    try:
        obs, _ = venv.reset(seed=[5, 6, 7])
        assert obs["ps0"].shape == (n, 1) and obs["ls0"].dtype == np.float32
        rng = np.random.default_rng(1)
        actions = [rng.uniform(-1, 1, (n, 2)).astype(np.float32) for _ in range(10)]
        batched = [venv.step(a) for a in actions]
    finally:
        venv.close()
    # each sub-environment is exactly the single environment with that seed
    for i, seed in enumerate([5, 6, 7]):
        env = reach_light()
        env.reset(seed=seed)
        for a, (vobs, vrew, *_rest) in zip(actions, batched):
            o, r, *_ = env.step(a[i])
            assert r == vrew[i]
            assert all(o[k].tobytes() == vobs[k][i].tobytes() for k in o)


def two_robot_room() -> wm.World:
    w = room().model_dump(mode="json", exclude_none=True)
    other = json.loads(json.dumps(w["robots"][0]))
    other.update(name="bot2", pose={"translation": [0.0, 0.5, 0.05], "rotation": [0, 0, 1, math.pi]})
    w["robots"].append(other)
    return wm.World.model_validate(w)


def test_pettingzoo_parallel_env_passes_the_api_test_and_moves_each_robot_exactly():
    pytest.importorskip("pettingzoo")
    from pettingzoo.test import parallel_api_test

    from sensorium.gym import SensoriumParallelEnv

    tasks = {"bot": Task(observations=[], max_steps=30), "bot2": Task(observations=[], max_steps=20)}
    env = SensoriumParallelEnv(two_robot_room(), tasks, actions="wheel")
    parallel_api_test(env, num_cycles=40)
    obs, infos = env.reset(seed=4)
    assert env.agents == ["bot", "bot2"]
    step_m = 3.0 * 0.0205 * 0.032
    for _ in range(20):
        obs, rewards, terms, truncs, infos = env.step({"bot": np.array([3.0, 3.0], np.float32),
                                                       "bot2": np.array([-3.0, -3.0], np.float32)})
    # bot drives +x; bot2 faces -x and reverses, so it also moves +x
    assert infos["bot"]["pose"][0] == pytest.approx(20 * step_m, abs=1e-12)
    assert infos["bot2"]["pose"][0] == pytest.approx(20 * step_m, abs=1e-12)
    assert truncs["bot2"] and not truncs["bot"] and env.agents == ["bot"]
    obs, rewards, terms, truncs, infos = env.step({"bot": np.array([3.0, 3.0], np.float32)})
    assert env.sim.robot("bot2").pose.translation[0] == pytest.approx(20 * step_m, abs=1e-12)   # stopped
    assert infos["bot"]["pose"][0] == pytest.approx(21 * step_m, abs=1e-12)
    # an action for a name that is no agent (a typo) is refused, not dropped unseen; one for an agent
    # that has ended is ignored, as PettingZoo's loops may still pass it
    with pytest.raises(ValueError, match=r"^an action for 'bott', which is not an agent \(agents: bot, bot2\)$"):
        env.step({"bot": np.zeros(2, np.float32), "bott": np.zeros(2, np.float32)})
    env.step({"bot": np.zeros(2, np.float32), "bot2": np.zeros(2, np.float32)})


@pytest.mark.parametrize("argv, why", [(["--env", "nope"], "--env 'nope' is not a registered sensorium id"),
                                       (["--env", "CartPole-v1"], "is not a registered sensorium id"),
                                       (["--steps", "0"], "--steps and every --envs size must be >= 1"),
                                       (["--envs", "2", "-1"], "--steps and every --envs size must be >= 1")])
def test_random_policy_example_refuses_bad_arguments_in_one_line(argv, why, capsys):
    """An unknown id came out as gymnasium's traceback, --steps 0 as a ZeroDivisionError, a negative
    count as negative rates."""
    from sensorium.gym.examples.random_policy import main

    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2 and why in capsys.readouterr().err


def test_random_policy_example_help_says_what_it_reports(capsys):
    """--help cut its description mid-sentence at the docstring's first line break ('...; reports')."""
    from sensorium.gym.examples.random_policy import main

    with pytest.raises(SystemExit):
        main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "reports environment steps per second" in out


def test_example_loop_reports_steps_per_second_and_is_deterministic():
    from sensorium.gym.examples.random_policy import run

    single = run("sensorium/ReachLight-v0", 0, 6, policy="scripted")
    sync = run("sensorium/ReachLight-v0", 1, 6, "sync", policy="scripted")
    assert single["env_steps"] == 6 and single["env_steps_per_s"] > 0
    assert sync["mean_reward"] == single["mean_reward"]       # same seed, same policy, same episode
    two = run("sensorium/ReachLight-v0", 2, 3, "sync", policy="random")
    assert two["env_steps"] == 6


def test_wheel_encoders_are_observed_and_leds_are_not():
    devices = [{"device": "PositionSensor", "name": "enc", "motor": "left wheel motor"},
               {"device": "LED", "name": "led"}]
    env = SensoriumEnv(room(devices=devices), Task(control_period_ms=32), actions="wheel")
    assert list(env.observation_space.spaces) == ["enc"]
    env.reset(seed=0)
    obs, *_ = env.step(np.array([2.0, 2.0], dtype=np.float32))
    assert obs["enc"][0] == np.float32(2.0 * 0.032)              # rad turned by the left wheel in one step
    with pytest.raises(ValueError, match="not a sensor"):
        SensoriumEnv(room(devices=devices), Task(observations=["led"]))


def test_nested_solids_attached_lights_and_multi_shape_bodies_are_rendered_and_targeted():
    w = room().model_dump(mode="json", exclude_none=True)
    w["lights"] = []
    w["solids"].append({"name": "post", "pose": {"translation": [-0.5, 0.5, 0.0], "rotation": [0, 0, 1, math.pi / 2]},
                        "children": [{"name": "cap", "pose": {"translation": [0.2, 0.0, 0.1]},
                                      "geometry": {"type": "box", "size": [0.1, 0.1, 0.1]},
                                      "appearance": {"base_color": [1.0, 0.0, 1.0]}}],
                        "lights": [{"type": "PointLight", "name": "beacon", "location": [0.4, 0.0, 0.1]}]})
    w["robots"][0]["shapes"] = [{"name": "mast", "pose": {"translation": [-0.1, 0.0, 0.0]},
                                 "geometry": {"type": "box", "size": [0.04, 0.04, 0.04]},
                                 "appearance": {"base_color": [0.0, 0.0, 1.0]}}]
    goal = ReachLight("beacon")
    env = SensoriumEnv(wm.World.model_validate(w), Task(observations=[], reward=goal), render_mode="rgb_array",
                       render_size=300)
    env.reset(seed=0)
    # the post turns its frame by 90 degrees: its child sits at (-0.5, 0.7), its light at (-0.5, 0.9)
    np.testing.assert_allclose(goal.target(env.sim), [-0.5, 0.9], atol=1e-12)
    img = env.render()
    r = env._renderer
    for xy, colour in (((-0.5, 0.7), (255, 0, 255)), ((-0.5, 0.9), (255, 230, 40)), ((-0.1, 0.0), (0, 0, 255))):
        col, row = r._px(np.array([xy]))[0]
        assert tuple(img[int(row), int(col)]) == colour, xy


def test_flattened_observations_for_libraries_that_need_one_box():
    from gymnasium.wrappers import FlattenObservation

    env = FlattenObservation(gym.make("sensorium/ReachLight-v0"))
    assert env.observation_space.shape == (10,)          # ls0, ls1, ps0..ps7 in key order
    with warnings.catch_warnings():
        warnings.simplefilter("error")                   # what a user runs: no warning to work around
        check_env(env.unwrapped)
    obs, _ = env.reset(seed=2)
    raw, _ = env.unwrapped.reset(seed=2)
    np.testing.assert_array_equal(obs, np.concatenate([raw[k] for k in sorted(raw)]))


def test_example_loop_runs_the_batched_vector_env_with_the_same_episodes():
    from sensorium.gym.examples.random_policy import run

    sync = run("sensorium/ReachLight-v0", 2, 6, "sync", policy="scripted")
    batched = run("sensorium/ReachLight-v0", 2, 6, "batched", policy="scripted")
    assert batched["env_steps"] == 12 and batched["mean_reward"] == sync["mean_reward"]


# -- a skid-steer robot (several wheels per side): an action drives every wheel of its side

R_WHEEL, TRACK, VMAX = 0.11, 0.4, 5.0


def skid_world(per_side: int) -> wm.World:
    left, right = [f"left {i}" for i in range(per_side)], [f"right {i}" for i in range(per_side)]
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "random_seed": 0},
        "robots": [{"name": "rover", "pose": {"translation": [0, 0, R_WHEEL]},
                    "differential_drive": {"wheel_radius": R_WHEEL, "axle_length": TRACK, "max_wheel_speed": VMAX,
                                           "left_motor": left[0], "right_motor": right[0],
                                           "skid_steer": {"left": left[1:], "right": right[1:]}},
                    "devices": [{"device": "PositionSensor", "name": "back left", "motor": left[-1]},
                                {"device": "PositionSensor", "name": "back right", "motor": right[-1]}]}]})


@pytest.mark.parametrize("per_side", [2, 3])
@pytest.mark.parametrize("engine", ["simulation", "batched"])
def test_a_skid_steer_robot_drives_straight_and_turns_at_the_closed_form_rates(engine, per_side):
    env = SensoriumEnv(skid_world(per_side), Task(robot="rover", control_period_ms=64, max_steps=None), engine=engine)
    assert env.engine == engine
    t = 10 * 0.064
    env.reset(seed=0)
    for _ in range(10):
        obs, *_, info = env.step(np.array([1.0, 1.0], dtype=np.float32))
    # every wheel at VMAX: v = R VMAX, the back wheels' encoders read VMAX t
    assert info["pose"] == pytest.approx([R_WHEEL * VMAX * t, 0.0, 0.0], abs=1e-12)
    assert obs["back left"][0] == pytest.approx(VMAX * t, rel=1e-7) and obs["back right"][0] == obs["back left"][0]
    env.reset(seed=0)
    for _ in range(10):
        obs, *_, info = env.step(np.array([-1.0, 1.0], dtype=np.float32))
    # turning on the spot: w = R (VMAX - -VMAX) / TRACK
    assert info["pose"] == pytest.approx([0.0, 0.0, R_WHEEL * 2 * VMAX / TRACK * t], abs=1e-12)
    assert obs["back left"][0] == pytest.approx(-VMAX * t, rel=1e-7)
    env.close()
