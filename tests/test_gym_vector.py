"""sensorium.gym.vector: the batched VectorEnv -- make_vec, Gymnasium's autoreset modes, sub-envs
bit-identical to the single environment, the checker, resets without rebuilding."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

from gymnasium.utils.env_checker import check_env  # noqa: E402
from gymnasium.vector import AutoresetMode  # noqa: E402

import sensorium.gym  # noqa: E402,F401  (registers the ids)
from sensorium.gym import ReachLight, SensoriumEnv, Task  # noqa: E402
from sensorium.gym.vector import SensoriumVectorEnv  # noqa: E402

IDS = ["sensorium/ReachLight-v0", "sensorium/AvoidObstacles-v0", "sensorium/LidarAvoid-v0"]


def _same_obs(a: dict, b: dict) -> bool:
    return set(a) == set(b) and all(np.asarray(a[k]).tobytes() == np.asarray(b[k]).tobytes() for k in a)


def _row(obs: dict, i: int) -> dict:
    return {k: v[i] for k, v in obs.items()}


def _reset_both(venv, singles, seed: int) -> dict:
    """The vector env reset with ``seed`` and single env i with ``seed + i``: the same first
    observations and poses. Returns the vector env's observations."""
    obs, info = venv.reset(seed=seed)
    for i, env in enumerate(singles):
        o, inf = env.reset(seed=seed + i)
        assert _same_obs(_row(obs, i), o) and inf["pose"].tobytes() == info["pose"][i].tobytes()
    return obs


def _step_both(venv, singles, a: np.ndarray, done: np.ndarray, t: int) -> tuple[int, dict]:
    """One step of the vector env (NEXT_STEP autoreset) and of each single env (reset() after an
    ended episode) with actions ``a``: the same observations, rewards, flags, clocks and poses;
    ``done`` updated. Returns the number of single envs reset and the vector env's observations."""
    resets = 0
    vobs, vr, vte, vtr, vinfo = venv.step(a)
    for i, env in enumerate(singles):
        if done[i]:
            o, inf = env.reset()
            r, te, tr = 0.0, False, False
            resets += 1
        else:
            o, r, te, tr, inf = env.step(a[i])
        assert _same_obs(_row(vobs, i), o), (t, i)
        assert (r, te, tr) == (vr[i], vte[i], vtr[i]), (t, i)
        assert inf["time_ms"] == vinfo["time_ms"][i] and inf["steps"] == vinfo["steps"][i], (t, i)
        assert inf["pose"].tobytes() == vinfo["pose"][i].tobytes(), (t, i)
        done[i] = te or tr
    return resets, vobs


def _random_steps(venv, singles, keys, steps: int, seed: int = 5, before=None) -> int:
    """``steps`` random actions through the vector env and the single envs (:func:`_step_both`), each
    sub-env 0 observation of ``keys`` within its box; ``before(t)`` runs ahead of step t (after its
    actions are drawn). Returns the number of single envs reset."""
    space = venv.single_observation_space
    rng = np.random.default_rng(seed)
    done = np.zeros(venv.num_envs, dtype=bool)
    ended = 0
    for t in range(steps):
        a = rng.uniform(-1, 1, (venv.num_envs, 2)).astype(np.float32)
        if before is not None:
            before(t)
        resets, vobs = _step_both(venv, singles, a, done, t)
        ended += resets
        assert all(space[k].contains(vobs[k][0]) for k in keys)
    return ended


def _lockstep(env_id: str, precision: str, n: int, steps: int, max_steps: int, seed: int = 5):
    """The vector env and n single envs (seeds seed + i) fed the same actions; NEXT_STEP autoreset
    on one side, reset() after an ended episode on the other. Returns the number of resets seen."""
    venv = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", precision=precision,
                        max_steps=max_steps)
    singles = [gym.make(env_id, precision=precision, max_steps=max_steps, engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, seed)
    rng = np.random.default_rng(1)
    done = np.zeros(n, dtype=bool)
    resets = 0
    for t in range(steps):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        if t % 20 < 10:
            a[:, 1] = a[:, 0] = 1.0                       # full speed ahead: walls, contact, terminations
        resets += _step_both(venv, singles, a, done, t)[0]
    venv.close()
    return resets


@pytest.mark.parametrize("precision", ["fast", "exact"])
@pytest.mark.parametrize("env_id", IDS)
def test_sub_env_i_is_the_single_env_with_seed_i_across_autoresets(env_id, precision):
    resets = _lockstep(env_id, precision, n=3, steps=45, max_steps=12)
    assert resets >= 3                                   # every sub-env ended and restarted at least once


def test_threads_split_the_copies_casts_with_the_same_bits():
    """64 copies' lidar beams (23,040 rays) are split over two threads or cast on one: the same
    observations, rewards and poses; a thread count below one is refused."""
    envs = [gym.make_vec("sensorium/LidarAvoid-v0", num_envs=64, vectorization_mode="vector_entry_point",
                         precision="fast", threads=t) for t in (1, 2)]
    assert [e.unwrapped.sim.rays.static.threads for e in envs] == [1, 2]
    outs = [e.reset(seed=3) for e in envs]
    rng = np.random.default_rng(2)
    for _ in range(4):
        a = rng.uniform(-1, 1, (64, 2)).astype(np.float32)
        o1, o2 = (e.step(a) for e in envs)
        assert _same_obs(o1[0], o2[0]) and o1[1].tobytes() == o2[1].tobytes()
        assert o1[4]["pose"].tobytes() == o2[4]["pose"].tobytes()
    assert _same_obs(outs[0][0], outs[1][0])
    for e in envs:
        e.close()
    with pytest.raises(ValueError, match="threads must be an integer >= 1 or None, got 0"):
        SensoriumVectorEnv(None, ReachLight(), 2, threads=0)


@pytest.mark.parametrize("kw, message", [({"num_envs": 2.5}, "num_envs must be an integer >= 1, got 2.5"),
                                         ({"num_envs": 0}, "num_envs must be an integer >= 1, got 0"),
                                         ({"num_envs": True}, "num_envs must be an integer >= 1, got True"),
                                         ({"num_envs": 2, "threads": 1.5}, "threads must be an integer >= 1")])
def test_counts_that_are_not_whole_numbers_are_refused(kw, message):
    """A float count was cut to an integer silently (2.5 copies made 2)."""
    with pytest.raises(ValueError, match=message):
        gym.make_vec("sensorium/ReachLight-v0", vectorization_mode="vector_entry_point", **kw)


def test_seeds_that_are_not_integers_are_refused_and_numpy_integers_are_seeds():
    venv = gym.make_vec("sensorium/ReachLight-v0", num_envs=3, vectorization_mode="vector_entry_point")
    for seed, message in ((1.5, "seed must be an integer, a list"), ([1, 2.5, None], "a seed must be an integer or "
                                                                                        "None, got 2.5"),
                          ("7", "seed must be an integer, a list"), ([1, 2], "2 seeds for num_envs=3")):
        with pytest.raises(ValueError, match=message):
            venv.reset(seed=seed)
    a = venv.reset(seed=np.int64(4))[0]
    b = venv.reset(seed=[4, 5, 6])[0]
    assert all(np.array_equal(a[k], b[k]) for k in a)    # an int s seeds sub-env i with s + i
    venv.close()


def test_make_vec_gives_the_batched_env_with_next_step_autoreset():
    venv = gym.make_vec("sensorium/ReachLight-v0", num_envs=4, vectorization_mode="vector_entry_point")
    assert isinstance(venv.unwrapped, SensoriumVectorEnv)
    assert venv.metadata["autoreset_mode"] is AutoresetMode.NEXT_STEP
    assert venv.num_envs == 4 and venv.observation_space["ps0"].shape == (4, 1)
    assert venv.single_action_space.low.tolist() == [-1.0, -1.0] and venv.action_space.shape == (4, 2)
    obs, info = venv.reset(seed=0)
    assert venv.observation_space.contains(obs)
    assert info["_time_ms"].all() and info["time_ms"].tolist() == [64] * 4     # warm-up: one 64 ms period
    # a vector step is steps_per_action basic steps of every copy
    _, _, _, _, info = venv.step(np.zeros((4, 2), dtype=np.float32))
    assert info["time_ms"].tolist() == [128] * 4
    venv.close()


def test_same_step_autoreset_returns_the_new_episode_and_keeps_the_last_observation():
    n = 2
    venv = SensoriumVectorEnv(None, sensorium.gym.tasks.reach_light_task(max_steps=3), n,
                              autoreset_mode=AutoresetMode.SAME_STEP)
    assert venv.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP
    single = [sensorium.gym.reach_light(max_steps=3, precision="fast", engine="simulation") for _ in range(n)]
    venv.reset(seed=[7, 9])
    for env, s in zip(single, [7, 9]):
        env.reset(seed=s)
    a = np.full((n, 2), 0.5, dtype=np.float32)
    for _ in range(2):
        venv.step(a)
        for env in single:
            env.step(a[0])
    obs, rew, term, trunc, info = venv.step(a)          # the third action truncates both
    assert trunc.all() and not term.any()
    for i, env in enumerate(single):
        last, r, _, tr, _ = env.step(a[i])
        assert tr and r == rew[i]
        assert info["_final_obs"][i] and _same_obs(_row(info["final_obs"], i), last)
        first, first_info = env.reset()
        assert _same_obs(_row(obs, i), first)            # already the next episode's first observation
        assert info["steps"][i] == 0 and info["time_ms"][i] == first_info["time_ms"]


def test_disabled_autoreset_resets_through_the_mask_only():
    venv = SensoriumVectorEnv(None, sensorium.gym.tasks.reach_light_task(max_steps=1), 3,
                              autoreset_mode="Disabled")
    venv.reset(seed=0)
    _, _, _, trunc, _ = venv.step(np.zeros((3, 2), dtype=np.float32))
    assert trunc.all()
    with pytest.raises(RuntimeError, match="autoreset is disabled"):
        venv.step(np.zeros((3, 2), dtype=np.float32))
    mask = np.array([True, False, True])
    _, info = venv.reset(options={"reset_mask": mask})
    assert info["_steps"].tolist() == [True, False, True]
    with pytest.raises(RuntimeError, match=r"sub-envs \[1\]"):
        venv.step(np.zeros((3, 2), dtype=np.float32))


@pytest.mark.parametrize("env_id", IDS)
def test_checker_passes_without_warnings_on_single_envs_and_sub_envs(env_id):
    with warnings.catch_warnings():
        warnings.simplefilter("error")                    # any checker warning fails the test
        check_env(gym.make(env_id).unwrapped)                          # a rebuilt Simulation
        check_env(gym.make(env_id, engine="batched").unwrapped)        # the batched engine (one copy)
        venv = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point", render_mode="rgb_array")
        check_env(venv.unwrapped.sub_env(2), skip_render_check=False)
        check_env(gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point",
                               flatten=True).unwrapped.sub_env(0))


def test_resets_reuse_the_built_scene():
    venv = gym.make_vec("sensorium/AvoidObstacles-v0", num_envs=8, vectorization_mode="vector_entry_point",
                        max_steps=2)
    sim = venv.unwrapped.sim
    venv.reset(seed=1)
    venv.step(venv.action_space.sample())                 # every ray kind cast once: every scene built
    builds = sim.scene.engine.counters["bvh_builds"] + sim.rays.movers.counters["bvh_builds"]
    resets = sim.counters["resets"]
    for _ in range(9):                                    # every sub-env ends after 2 actions: 3 rounds of resets
        venv.step(venv.action_space.sample())
    venv.reset()
    assert sim.counters["resets"] - resets >= 3 * 8
    assert sim.scene.engine.counters["bvh_builds"] + sim.rays.movers.counters["bvh_builds"] == builds


def test_flattened_observations_are_the_dict_boxes_in_key_order():
    n = 3
    flat = gym.make_vec("sensorium/LidarAvoid-v0", num_envs=n, vectorization_mode="vector_entry_point", flatten=True)
    boxed = gym.make_vec("sensorium/LidarAvoid-v0", num_envs=n, vectorization_mode="vector_entry_point")
    f, _ = flat.reset(seed=3)
    d, _ = boxed.reset(seed=3)
    assert f.shape == (n, 364) and f.dtype == np.float32 and flat.single_observation_space.shape == (364,)
    keys = list(boxed.single_observation_space.spaces)
    assert keys == sorted(keys)
    np.testing.assert_array_equal(f, np.concatenate([d[k].reshape(n, -1) for k in keys], axis=1))
    single = gym.make("sensorium/LidarAvoid-v0", flatten=True, precision="fast", engine="simulation")
    s, _ = single.reset(seed=4)
    assert s.tobytes() == f[1].tobytes()                 # sub-env 1 had seed 3 + 1


def test_a_reward_without_a_vectorised_form_is_called_per_copy_with_the_same_values():
    calls = []

    def closer_to_origin(sim, robot, obs) -> float:     # reads the pose through the copy's view
        calls.append(sim.time_ms)
        x, y = robot.pose.translation[:2]
        return -math.hypot(x, y) + 0.001 * float(obs["ls0"][0])

    task = Task(robot="epuck", observations={"ls0": 64}, control_period_ms=64, max_steps=20, reward=closer_to_origin,
                terminated=ReachLight("lamp").terminated)
    venv = SensoriumVectorEnv(None, task, 2)
    single = SensoriumEnv(None, task, precision="fast", engine="simulation")
    venv.reset(seed=[3, 4])
    single.reset(seed=4)
    rng = np.random.default_rng(2)
    for _ in range(5):
        a = rng.uniform(-1, 1, (2, 2)).astype(np.float32)
        _, r, *_ = venv.step(a)
        _, r1, *_ = single.step(a[1])
        assert r[1] == r1
    assert len(calls) == 5 * 2 + 5
    assert single.engine == "simulation" and SensoriumEnv(None, task, engine="auto").engine == "batched"


def test_bad_actions_and_stepping_before_reset_say_what_is_wrong():
    venv = SensoriumVectorEnv(None, sensorium.gym.tasks.reach_light_task(), 2)
    with pytest.raises(RuntimeError, match="reset"):
        venv.step(np.zeros((2, 2), dtype=np.float32))
    venv.reset(seed=0)
    with pytest.raises(ValueError, match=r"shape \(2, 2\)"):
        venv.step(np.zeros((3, 2), dtype=np.float32))
    with pytest.raises(ValueError, match="sub-env 1"):
        venv.step(np.array([[0.0, 0.0], [np.nan, 0.0]], dtype=np.float32))


def test_pettingzoo_env_on_the_batched_engine_equals_the_rebuilt_simulation(precision="fast"):
    pytest.importorskip("pettingzoo")
    from pettingzoo.test import parallel_api_test

    from sensorium.gym import SensoriumParallelEnv
    from sensorium.gym.tasks import lidar_avoid_task, reach_light_task

    def make(engine):
        return SensoriumParallelEnv(None, {"epuck": reach_light_task(max_steps=25), "scout": lidar_avoid_task(max_steps=40)},
                                    precision=precision, engine=engine)

    batched, rebuilt = make("batched"), make("simulation")
    parallel_api_test(make("batched"), num_cycles=30)
    rng = np.random.default_rng(4)
    for episode in range(2):
        ob, _ = batched.reset(seed=10 + episode)
        orr, _ = rebuilt.reset(seed=10 + episode)
        builds = batched._batched.scene.engine.counters["bvh_builds"]
        while batched.agents:
            assert batched.agents == rebuilt.agents
            for a in batched.agents:
                assert _same_obs(ob[a], orr[a])
            acts = {a: rng.uniform(-1, 1, 2).astype(np.float32) for a in batched.agents}
            ob, rb, tb, trb, ib = batched.step(acts)
            orr, rr, tr_, trr, ir = rebuilt.step(acts)
            assert (rb, tb, trb) == (rr, tr_, trr)
            assert all(ib[a]["pose"].tobytes() == ir[a]["pose"].tobytes() for a in ib)
        assert not rebuilt.agents
        if episode:
            assert batched._batched.scene.engine.counters["bvh_builds"] == builds     # the reset rebuilt nothing


def test_auto_engine_falls_back_to_the_simulation_for_what_the_batched_one_does_not_simulate(monkeypatch):
    """Every kind a task can observe is batched now (NUE worlds too: test_batched_nue.py), so the
    refusal is made here by taking lidars out of the batched kinds: "auto" falls back to a rebuilt
    Simulation, "batched" and the vector env say why in one line."""
    from sensorium.server.sim import batched
    from sensorium.server.sim.batched import BatchedError
    from sensorium.server.world.loader import default_world_path, load_world

    lw = load_world(default_world_path())
    task = Task(robot="scout", observations={"lidar": 64}, control_period_ms=64)
    assert SensoriumEnv(lw, task, engine="auto").engine == "batched"
    monkeypatch.setattr(batched, "SUPPORTED_KINDS", tuple(k for k in batched.SUPPORTED_KINDS if k != "Lidar"))
    env = SensoriumEnv(lw, task, engine="auto")
    assert env.engine == "simulation"
    obs, _ = env.reset(seed=0)
    assert obs["lidar"].shape == (1, 360)
    with pytest.raises(BatchedError, match="device 'lidar' is a Lidar"):
        SensoriumEnv(lw, task, engine="batched")
    with pytest.raises(BatchedError, match="is a Lidar.*the batched vector environment cannot run this task"):
        SensoriumVectorEnv(lw, task, 2).reset(seed=0)


@pytest.mark.parametrize("env_id", ["sensorium/AvoidObstacles-v0", "sensorium/LidarAvoid-v0"])
def test_single_env_on_the_batched_engine_equals_the_rebuilt_simulation(env_id):
    batched = gym.make(env_id, engine="batched", max_steps=10)
    rebuilt = gym.make(env_id, engine="simulation", max_steps=10)
    assert batched.unwrapped.engine == "batched" and rebuilt.unwrapped.engine == "simulation"
    rng = np.random.default_rng(6)
    for seed in (1, None, 2):
        ob, ib = batched.reset(seed=seed)
        orr, ir = rebuilt.reset(seed=seed)
        assert _same_obs(ob, orr) and ib["pose"].tobytes() == ir["pose"].tobytes()
        done = False
        while not done:
            a = rng.uniform(-1, 1, 2).astype(np.float32)
            ob, rb, tb, trb, ib = batched.step(a)
            orr, rr, tr_, trr, ir = rebuilt.step(a)
            assert _same_obs(ob, orr) and (rb, tb, trb) == (rr, tr_, trr) and ib["time_ms"] == ir["time_ms"]
            done = tb or trb


def test_range_image_observations_clip_nan_and_infinities_as_the_box_clip_does():
    """A lidar's observation: its range image with NaN and +inf as the Box's high, -inf as its low,
    clipped to the Box (np.clip of nan_to_num, the single env's steps), bit for bit, for images
    holding NaN, +-inf, signed zeros, subnormals, values below, inside and beyond the range; both
    for the whole batch and one sub-env (fails if the uniform-bounds path changes a value)."""
    venv = gym.make_vec("sensorium/LidarAvoid-v0", num_envs=3, vectorization_mode="vector_entry_point",
                        precision="fast").unwrapped
    venv.reset(seed=0)
    name = next(k for k, ref in venv.refs.items() if ref.kind == "Lidar")
    assert name in venv._image_bounds                      # the lidar's Box: 0 .. max range everywhere
    box = venv.agent.dict_space.spaces[name]
    img = venv.sim.range_image(venv.refs[name])
    rng = np.random.default_rng(2)
    special = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 1e-45, -1e-45, -3.0, 1e30, box.high.flat[0],
                        np.nextafter(box.high.flat[0], np.float32(np.inf))], dtype=np.float32)
    img[...] = rng.uniform(-1.0, 1.5 * float(box.high.flat[0]), img.shape).astype(np.float32)
    flat = img.reshape(-1)
    flat[rng.integers(0, flat.size, 200)] = rng.choice(special, 200)
    hi = box.high.flat[0]
    want = np.clip(np.nan_to_num(img, nan=hi, posinf=hi), box.low, box.high).astype(np.float32)
    got = venv._observe()[name]
    assert got.dtype == np.float32 and got.tobytes() == want.tobytes()
    assert np.isnan(img).any() and np.isinf(img).any()
    one = venv._observe(np.array([1]))[name]
    assert one.tobytes() == want[1:2].tobytes()
    from sensorium.server.raycast import packets
    if packets.library() is not None:   # (the C pass answered, not the numpy steps)
        assert packets.box_clip32(img, *venv._image_bounds[name]).tobytes() == want.tobytes()


@pytest.mark.parametrize("low", [0.0, -0.0, -2.5, 1.0])
def test_the_range_image_clip_in_c_is_the_numpy_steps_bit_for_bit(low):
    """packets.box_clip32 (the vector env's range-image observation in one C pass) against
    _observe's numpy steps -- np.clip to two float32 bounds, NaN -> high, a zero -> a zero low bound
    -- for NaN, infinities, signed zeros, subnormals, ties at both bounds and values inside and
    beyond, with a zero, a negative zero, a negative and a positive low bound."""
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    lo, hi = np.float32(low), np.float32(4.0)
    rng = np.random.default_rng(7)
    img = rng.uniform(-5.0, 6.0, (4, 3, 50)).astype(np.float32)
    special = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 1e-45, -1e-45, lo, hi, np.nextafter(hi, np.float32(9)),
                        np.nextafter(lo, np.float32(-9))], dtype=np.float32)
    img.reshape(-1)[rng.integers(0, img.size, 300)] = rng.choice(special, 300)
    want = np.clip(img, lo, hi)
    want[np.isnan(want)] = hi
    if lo == 0.0:
        want[want == 0.0] = lo
    got = packets.box_clip32(img, lo, hi)
    assert got is not None and got.dtype == np.float32 and got.tobytes() == want.tobytes()
    assert packets.box_clip32(img[:, :, ::2], lo, hi) is None    # (a strided view: the numpy steps)


def hills_world():
    """An ENU world of hills (a random terrain on a floor) and a rover with a distance sensor and a
    two-layer lidar (also tests/test_gym_nue.py's, turned into NUE there)."""
    from sensorium.schemas import world as wm

    heights = np.random.default_rng(3).uniform(0.0, 0.4, 81)
    return wm.World.model_validate({
        "solids": [{"name": "floor", "geometry": {"type": "plane"}},
                   {"name": "hills", "pose": {"translation": [-2.0, -2.0, 0.0]},
                    "geometry": {"type": "elevation_grid", "height": heights.tolist(), "x_dimension": 9,
                                 "x_spacing": 0.5, "y_dimension": 9, "y_spacing": 0.5}}],
        "robots": [{"name": "rover", "pose": {"translation": [0.1, 0.2, 0.5]},
                    "body": {"geometry": {"type": "cylinder", "radius": 0.08, "height": 0.05}},
                    "differential_drive": {"wheel_radius": 0.05, "axle_length": 0.2, "max_wheel_speed": 15.0},
                    "devices": [{"device": "DistanceSensor", "name": "ahead", "lookup_table": [[0, 0, 0], [3, 3, 0]],
                                 "pose": {"rotation": [0, 1, 0, 0.3]}},
                                {"device": "Lidar", "name": "scan", "horizontal_resolution": 32,
                                 "number_of_layers": 2, "vertical_field_of_view": 0.2, "max_range": 3.0}]}]})


def test_sub_envs_riding_a_terrain_are_the_single_envs_bit_for_bit():
    """A hilly world (a random terrain on a floor, a ramp): random starts keep the world-file
    clearance above the ground where they land; the vector env's sub-env i and the single env with
    seed 5 + i agree on observations, rewards and poses (heights and attitudes included) across
    autoresets, and the robots did ride slopes."""
    from sensorium.gym.task import random_start

    world = hills_world()
    task = Task(robot="rover", observations=["ahead", "scan"], max_steps=15, start=random_start((-1.5, 1.5), (-1.5, 1.5)))
    n = 3
    venv = SensoriumVectorEnv(world, task, n, precision="exact")
    singles = [SensoriumEnv(world, task, precision="exact", engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, 5)
    sim = singles[0].sim
    ground = sim.ground
    x, y, z = sim.robot("rover").pose.translation
    assert abs(z - (ground.at(x, y)[0] + 0.5 - ground.at(0.1, 0.2)[0])) <= 1e-12      # the clearance kept
    rng = np.random.default_rng(2)
    done = np.zeros(n, dtype=bool)
    tilted = resets = 0
    for t in range(40):
        a = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        a[:, 0] = np.abs(a[:, 0])
        a[:, 1] = a[:, 0]                                 # straight on: over the hills
        resets += _step_both(venv, singles, a, done, t)[0]
        tilted += sum(abs(env.sim.robot("rover").pose.rotation[2, 2]) < 1.0 - 1e-6 for env in singles)
    venv.close()
    assert resets >= 3 and tilted > 30


def test_the_avoid_obstacles_reward_in_c_is_the_numpy_reward_bit_for_bit(monkeypatch):
    """AvoidObstacles' vectorised reward and termination with their C passes (packets.clearance_gaps,
    packets.avoid_reward, and both in one call: packets.AvoidOutcome) equal the numpy path's, bit for bit, step after step while 16 robots drive
    at full speed, turn and reverse into the arena's walls: free rewards, partial proximity, contact
    penalties and terminations all occur."""
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    n = 16
    venv = gym.make_vec("sensorium/AvoidObstacles-v0", num_envs=n, vectorization_mode="vector_entry_point",
                        precision="fast")
    goal = venv.unwrapped._goals[0]
    copies = np.arange(n)
    venv.reset(seed=4)
    sim = venv.unwrapped.sim
    for c in range(n):        # heading east, 2 cm to 40 cm from the east wall's face (x = 2.0)
        sim.set_pose(c, venv.unwrapped.slot, [1.93 - 0.025 * c, -1.5 + 0.2 * c, 0.01], rotation=[0, 0, 1, 0.0])
    rng = np.random.default_rng(4)
    seen = {"penalty": 0, "partial": 0, "free": 0}
    for step in range(80):
        a = np.ones((n, 2)) if step % 20 < 14 else rng.uniform(-1.0, 1.0, (n, 2))
        venv.step(a.astype(np.float32))
        goal._gap = None
        assert goal._passes is not None     # (gaps, reward and terminations in one C call)
        got = goal.reward(copies), goal.terminated(copies), goal.gaps(copies).copy()
        with monkeypatch.context() as m:     # the two C passes, one call each
            m.setattr(goal, "_passes", None)
            goal._gap = None
            apart = goal.reward(copies), goal.terminated(copies), goal.gaps(copies).copy()
            m.setattr(packets, "clearance_gaps", lambda *args: None)
            m.setattr(packets, "avoid_reward", lambda *args: None)
            goal._gap = None
            want = goal.reward(copies), goal.terminated(copies), goal.gaps(copies).copy()
        for g, a, w in zip(got, apart, want):
            assert g.tobytes() == w.tobytes() and a.tobytes() == w.tobytes(), step
        gap = want[2]
        seen["penalty"] += int(np.count_nonzero(gap < goal.goal.contact_distance))
        seen["partial"] += int(np.count_nonzero((gap > goal.goal.contact_distance) & (gap < goal.goal.near)))
        seen["free"] += int(np.count_nonzero(gap >= goal.goal.near))
    assert min(seen.values()) > 0, seen


def test_a_closed_env_lets_its_simulation_go_and_says_so_when_used():
    """Before: close() kept the batched simulation (its scenes and arrays) and step() went on
    stepping it."""
    import gc
    import weakref

    env = SensoriumVectorEnv(None, Task(robot="epuck", observations=["ls0"]), 2, render_mode="rgb_array")
    env.reset(seed=0)
    sub = env.sub_env(1)
    sim = weakref.ref(env.sim)
    env.close()
    gc.collect()
    assert sim() is None
    for use in (lambda: env.step(np.zeros((2, 2), np.float32)), lambda: env.reset(seed=0), env.render,
                lambda: sub.reset(seed=0), lambda: sub.step(np.zeros(2, np.float32))):
        with pytest.raises(RuntimeError, match="^the environment is closed; build a new one$"):
            use()
    env.close()                                  # a second close is harmless
