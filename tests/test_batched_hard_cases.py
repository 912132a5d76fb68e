"""Hard cases for the batched simulation's C passes (packets.c) and Python paths: a whole arena far
from the origin, origins on the edge of the static tier's sphere, grazing beams, robots exactly
touching walls and each other, zero-length moves, extreme and non-finite actions, the longest basic
time step, degenerate lookup tables, NaN/inf into the C passes, empty/one/1,024 copies, and a
sanitized (-fsanitize=address,undefined) harness of the new sp_* functions on edge inputs. Batched
vs single and C vs numpy compared bit for bit; closed forms where the geometry gives one."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sensorium.schemas import world as wm
from sensorium.server.devices import orientation
from sensorium.server.devices.distance import CombinePlan, combine_planned
from sensorium.server.devices.lookup import LookupTable
from sensorium.server.raycast import packets
from sensorium.server.raycast.kinds import RayKind
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, default_world_path, load_world
from tests.test_batched_sim import EPUCK, SCOUT, _assert_same, _same_value, _wheels_both

HAVE_C = packets.library() is not None
needs_c = pytest.mark.skipif(not HAVE_C, reason=f"no packet path here: {packets.status()}")
SMALL = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
R_EPUCK = 0.035          # the e-puck's body radius (arena.yaml)
WALL_FACE = 2.0          # the inner faces of the arena's walls: |x| or |y| = 2.0


def arena(seed: int, shift=(0.0, 0.0, 0.0), time_step: int | None = None) -> LoadedWorld:
    """The default arena with this seed, every solid, light and robot translated by ``shift``."""
    lw = load_world(default_world_path())
    w = lw.world
    d = np.asarray(shift, dtype=np.float64)

    def moved(p):
        return p.model_copy(update={"translation": (np.asarray(p.translation) + d).tolist()})

    lights = [lt.model_copy(update={"location": (np.asarray(lt.location) + d).tolist()})
              if getattr(lt, "location", None) is not None else lt for lt in w.lights]
    info = {"random_seed": seed} if time_step is None else {"random_seed": seed, "basic_time_step": time_step}
    w = w.model_copy(update={"solids": [s.model_copy(update={"pose": moved(s.pose)}) for s in w.solids],
                             "robots": [r.model_copy(update={"pose": moved(r.pose)}) for r in w.robots],
                             "lights": lights, "world_info": w.world_info.model_copy(update=info)})
    return LoadedWorld(world=w, source=lw.source, base_dir=lw.base_dir)


def _pair(worlds: list[LoadedWorld], seeds: list[int], precision: str = "fast", period: int = 32
          ) -> tuple[BatchedSimulation, list[Simulation]]:
    """A batched simulation of len(seeds) copies of worlds[0] and a Simulation per copy (worlds[c]),
    every device of both robots enabled."""
    bs = BatchedSimulation(worlds[0], len(seeds), precision=precision)
    bs.reset(np.arange(len(seeds)), seeds)
    sims = [Simulation(w, precision=precision) for w in worlds]
    for robot, names in (("epuck", EPUCK), ("scout", SCOUT)):
        for n in names:
            bs.enable(bs.device(robot, n), period)
            for s in sims:
                s.robot(robot).device(n).enable(period)
    return bs, sims


def _set_pose_both(bs, sims, c: int, robot: str, translation, yaw: float) -> None:
    bs.set_pose(c, bs.slot(robot), translation, rotation=[0, 0, 1, yaw])
    sims[c].robot(robot).set_pose(translation, [0, 0, 1, yaw])


def _drive_lockstep(bs, sims, steps: int, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    C = len(sims)
    for step in range(steps):
        if step % 4 == 0:
            for robot in ("epuck", "scout"):
                vmax = float(bs.max_wheel[bs.slot(robot), 0])
                lr = rng.uniform(-vmax, vmax, (C, 2)) if step % 16 else np.full((C, 2), 0.9 * vmax)
                _wheels_both(bs, sims, robot, lr)
        bs.step()
        for s in sims:
            s.step()
        _assert_same(bs, sims, step)


# ------------------------------------------------------------------ far from the origin

@pytest.mark.parametrize("shift", [(1e5, 0.0, 0.0), (-1e5, 1e5, 0.0)])
def test_an_arena_translated_to_the_world_limit_is_the_single_simulation_bit_for_bit(shift):
    """The whole arena at x (and y) = +-1e5 m (limits.MAX_COORDINATE_M): both robots drive into
    walls and each other; every copy equals the Simulation with its seed, bit for bit, and its
    sensors still see the arena (the lidar reads the walls, not nothing)."""
    seeds = [11, 12]
    bs, sims = _pair([arena(s, shift) for s in seeds], seeds)
    _drive_lockstep(bs, sims, 24)
    assert np.all(np.abs(bs.pos[:, :, 0] - shift[0]) < 2.0)
    lidar = bs.range_image(bs.device("scout", "lidar"))
    assert np.isfinite(lidar).mean() > 0.9 and lidar[np.isfinite(lidar)].max() < 6.0


def counterweighted(seed: int, beams: int = 360) -> LoadedWorld:
    """The arena at x = 1e5 m plus a post at x = -1e5 m: the static tier's geometry then lies around
    the origin (unanchored: float32 coordinates of ~1e5, ~8 mm apart), its sphere ~1e5 m; the
    scout's lidar of ``beams`` beams."""
    lw = arena(seed, (1e5, 0.0, 0.0))
    post = wm.World.model_validate({"solids": [{"name": "post", "pose": {"translation": [-1e5, 0.0, 0.5]},
                                                "geometry": {"type": "box", "size": [0.2, 0.2, 1.0]}}]}).solids[0]
    robots = [r.model_copy(update={"devices": [d.model_copy(update={"horizontal_resolution": beams})
                                               if d.device == "Lidar" else d for d in r.devices]})
              for r in lw.world.robots]
    return LoadedWorld(world=lw.world.model_copy(update={"solids": [*lw.world.solids, post], "robots": robots}),
                       source=lw.source, base_dir=lw.base_dir)


@pytest.mark.parametrize("beams", [360, 352])
def test_lidar_copies_far_from_the_origin_in_an_unanchored_tier_are_the_single_simulation(beams):
    """Four copies of the counterweighted world (the lean cast taken at 1e5 m): every copy's lidar
    scan equals its single simulation's bit for bit. With 360 beams (not a multiple of 16) a
    coherent packet used to span two copies' lidars, and at this float32 resolution a beam's answer
    depended on its packet's other beams: copy 3's beam read a curved pillar's tessellated shell
    (1.92 m) where its one-origin cast reads the pillar (1.96 m). Each run is now packed as its own
    cast packs it (352 beams: the runs were already aligned)."""
    seeds = [1, 2, 3, 4]
    bs, sims = _pair([counterweighted(s, beams) for s in seeds], seeds)
    tier = bs.rays.static._static_tier(bs.rays.movers._variant(RayKind.VISUAL, False))
    assert not tier.anchored and tier.radius > 1e5
    _drive_lockstep(bs, sims, 24)
    if HAVE_C:        # the lean cast needs the packet helper (SENSORIUM_PACKETS=0: none)
        assert bs.rays.counters["lean_casts"] > 0


@needs_c
@pytest.mark.parametrize("threads", [1, 2])
def test_coherent_runs_of_many_origins_are_each_runs_one_origin_cast(threads):
    """200 lidar scans of 360 beams (72,000 rays: the engine's blocks) from origins around x = 1e5 m,
    cast at once as coherent runs, on one thread or two: each beam's distance is its scan's
    one-origin cast's, bit for bit."""
    bs = BatchedSimulation(counterweighted(1), 1, precision="fast")
    static = bs.rays.static
    static.threads = threads
    rng = np.random.default_rng(7)
    k, W = 200, 360
    rows = np.column_stack([1e5 + rng.uniform(-1.9, 1.9, k), rng.uniform(-1.9, 1.9, k), np.full(k, 0.15)])
    a = np.pi - (np.arange(W) + 0.5) * (2 * np.pi / W)
    dirs = np.column_stack([np.cos(a), np.sin(a), np.zeros(W)])
    O = np.repeat(rows, W, axis=0)
    D = np.tile(dirs, (k, 1))
    every = static.cast(O, D, 0.02, 6.0, kind=RayKind.VISUAL, distance_only=True, coherent=True, origin_rows=rows,
                        run=W).distance.reshape(k, W)
    for j in range(k):
        one = static.cast(np.broadcast_to(rows[j], (W, 3)), dirs, 0.02, 6.0, kind=RayKind.VISUAL,
                          distance_only=True).distance
        assert one.tobytes() == every[j].tobytes(), (j, np.flatnonzero(one != every[j]))


# ------------------------------------------------------------------ the lean cast's sphere test

def _cast_both(bs, O, D, rows, **kw):
    """The cast with the lean path allowed and without: (allowed's hits, general's, lean taken)."""
    rays = bs.rays
    before = rays.counters["lean_casts"]
    copy = np.zeros(len(O), dtype=np.int64)
    args = (O, D, 0.0, 20.0, RayKind.VISUAL, copy, bs.rot, bs.pos, -1, -1)
    lean = rays.cast(*args, origin_rows=rows, **kw)
    took = rays.counters["lean_casts"] > before
    rays.lean = False
    try:
        general = rays.cast(*args, origin_rows=rows, **kw)
    finally:
        rays.lean = True
    return lean, general, took


def _same_hits(a, b) -> None:
    for name in ("distance", "normal", "shape"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.tobytes() == y.tobytes(), name


@needs_c
@pytest.mark.parametrize("axis", [(1.0, 0.0, 0.04), (1.0, 1.0, 0.1), (0.3, -1.0, 0.05)])
def test_the_lean_cast_takes_origins_only_inside_the_static_tiers_sphere_margin(axis):
    """Origins at |o| = r (1 + delta) around the static tier's sphere (radius r, unanchored: the
    arena is around the origin): the lean path's float32 test takes them at delta <= -1e-5 (inside
    its 1e-5 margin on r^2), refuses them from delta = -1e-6 on (on, or beyond, the sphere, where
    trace.py would clip the rays' starts), and the answers equal the general path's every time."""
    bs = BatchedSimulation(arena(3), 2, precision="fast")
    bs.reset(np.arange(2), [3, 3])
    tier = bs.rays.static._static_tier(bs.rays.movers._variant(RayKind.VISUAL, False))
    assert not tier.anchored
    r = tier.radius
    u = np.asarray(axis) / np.linalg.norm(axis)
    n = 256
    a = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    D = np.stack([np.cos(a), np.sin(a), np.full(n, -0.01)], axis=1)
    D /= np.linalg.norm(D, axis=1)[:, None]
    for delta in (-1e-3, -2e-5, -1e-5, -1e-6, -1e-7, 0.0, 1e-7, 1e-6, 1e-3):
        o = u * (r * (1.0 + delta))
        O = np.ascontiguousarray(np.repeat(o[None], n, axis=0))
        lean, general, took = _cast_both(bs, O, D, o[None])
        _same_hits(lean, general)
        assert took == (delta <= -1e-5), delta
        assert np.isfinite(lean.distance).any()     # the beams back into the arena hit it


# ------------------------------------------------------------------ grazing beams

@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_lidar_beams_along_wall_faces_and_top_edges_are_the_single_simulations(precision):
    """The scout's lidar (360 level beams) placed so that beams run exactly in the plane of the
    north wall's inner face (origin y = 2.0), along the walls' top faces (origin z = 0.3) and
    at the corner where the north and east walls meet: every copy's scan equals the single
    simulation's, bit for bit; closed forms for a beam that starts on a wall's face and for the
    beam into the corner."""
    lidar_z = 0.09
    places = [((1.0, WALL_FACE, 0.06), 0.0), ((1.0, WALL_FACE - 0.3, 0.3 - lidar_z), 0.0),
              ((WALL_FACE - 0.5, WALL_FACE - 0.5, 0.06), 1.25 * math.pi), ((0.0, 0.0, 0.3 - lidar_z), 0.0)]
    seeds = list(range(len(places)))
    bs, sims = _pair([arena(s) for s in seeds], seeds, precision)
    for c, (t, yaw) in enumerate(places):
        _set_pose_both(bs, sims, c, "scout", list(t), yaw)
        _set_pose_both(bs, sims, c, "epuck", [-1.5, -1.5 + 0.2 * c, 0.01], 0.0)
    for step in range(2):
        bs.step()
        for s in sims:
            s.step()
        _assert_same(bs, sims, step)
    scan = bs.range_image(bs.device("scout", "lidar")).reshape(len(seeds), -1)
    # beam 0 looks back, half a step into the north wall (pi + pi/360): from (1, 2), on the wall's
    # face, its entry lies before `near`, so it reads the wall's west end face from inside
    assert float(scan[0, 0]) == pytest.approx((1.0 + WALL_FACE + 0.1) / math.cos(math.pi / 360), rel=1e-6)
    # the diagonal copy's beam 0 at pi/4 + pi/360 from (1.5, 1.5), just north of the inner corner
    # (2.0, 2.0): the north wall's face 0.5 m away in y
    assert float(scan[2, 0]) == pytest.approx(0.5 / math.sin(math.pi / 4 + math.pi / 360), rel=1e-6)


@needs_c
def test_rays_through_a_boxs_vertices_and_edges_take_the_same_answer_lean_and_general():
    """Rays aimed exactly at the crate's eight corners and twelve edge midpoints (from origins
    around it): the lean cast and the general path agree bit for bit, and each ray that stops near
    the crate stops at the aimed point (within float32 resolution), or passes it by."""
    bs = BatchedSimulation(arena(3), 2, precision="fast")
    bs.reset(np.arange(2), [3, 3])
    centre, yaw, half = np.array([0.9, -0.6, 0.1]), 0.5, np.array([0.15, 0.15, 0.1])
    Rz = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0, 0, 1]])
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)
    corners = centre + (signs * half) @ Rz.T
    edges = [(corners[i] + corners[j]) / 2 for i in range(8) for j in range(i + 1, 8)
             if np.count_nonzero(signs[i] != signs[j]) == 1]
    targets = np.vstack([corners, edges])
    origins = np.array([[0.2, -0.2, 0.25], [1.6, -1.2, 0.05], [0.3, -1.3, 0.15], [1.5, 0.1, 0.28]])
    O = np.repeat(origins, len(targets), axis=0)
    T = np.tile(targets, (len(origins), 1))
    D = T - O
    reach = np.linalg.norm(D, axis=1)
    D /= reach[:, None]
    lean, general, took = _cast_both(bs, np.ascontiguousarray(O), D, origins)
    assert took
    _same_hits(lean, general)
    d = lean.distance
    at = np.isfinite(d) & (np.abs(d - reach) < 0.02)
    assert at.sum() > len(d) // 4                          # (the corners and edges in sight)
    assert np.abs(d[at] - reach[at]).max() < 1e-5
    # every stop on the crate lies on its surface (the crate's frame: on a face, not inside it)
    local = np.abs(((O + np.where(np.isfinite(d), d, 0.0)[:, None] * D) - centre) @ Rz)
    on = np.isfinite(d) & (local <= half + 1e-3).all(axis=1)
    assert on.sum() > len(d) // 2
    assert np.abs((local[on] - half).max(axis=1)).max() < 1e-5


# ------------------------------------------------------------------ contact and motion extremes

def test_robots_exactly_touching_a_wall_and_each_other_and_standing_still_are_the_single_simulation():
    """Copy 0: the e-puck touching the east wall's face, driven into it; copy 1: the e-puck touching
    the scout's rear face, both driven at each other; copy 2: nothing moves (zero wheel speeds:
    zero-length moves). Bit for bit the single simulations; the e-puck never enters the wall
    (x + r <= 2.0) and copy 2's poses never change."""
    seeds = [5, 6, 7]
    bs, sims = _pair([arena(s) for s in seeds], seeds)
    _set_pose_both(bs, sims, 0, "epuck", [WALL_FACE - R_EPUCK, 0.3, 0.01], 0.0)
    _set_pose_both(bs, sims, 1, "scout", [0.6, 0.4, 0.06], math.pi)
    _set_pose_both(bs, sims, 1, "epuck", [0.6 + 0.15 + R_EPUCK, 0.4, 0.01], math.pi)
    vmax_e, vmax_s = float(bs.max_wheel[bs.slot("epuck"), 0]), float(bs.max_wheel[bs.slot("scout"), 0])
    _wheels_both(bs, sims, "epuck", np.array([[vmax_e, vmax_e], [vmax_e, vmax_e], [0.0, -0.0]]))
    _wheels_both(bs, sims, "scout", np.array([[0.0, 0.0], [-vmax_s, -vmax_s], [0.0, 0.0]]))
    still = bs.pos[2].copy(), bs.rot[2].copy()
    for step in range(24):
        bs.step()
        for s in sims:
            s.step()
        _assert_same(bs, sims, step)
        assert bs.pos[0, bs.slot("epuck"), 0] + R_EPUCK <= WALL_FACE + 1e-9
        assert bs.pos[2].tobytes() == still[0].tobytes() and bs.rot[2].tobytes() == still[1].tobytes()


def test_the_longest_basic_time_step_is_the_single_simulation_bit_for_bit():
    """basic_time_step = 60,000 ms (the schema's maximum): one step drives an e-puck ~7.7 m (across
    the arena, into its walls): every copy equals the single simulation, and no pose leaves the
    arena."""
    seeds = [1, 2]
    bs, sims = _pair([arena(s, time_step=60_000) for s in seeds], seeds, period=60_000)
    _drive_lockstep(bs, sims, 6, seed=3)
    assert np.all(np.abs(bs.pos[:, :, :2]) < WALL_FACE)


# ------------------------------------------------------------------ actions

gym = pytest.importorskip("gymnasium")


def _envs(n: int):
    import sensorium.gym  # noqa: F401 - registers the ids

    venv = gym.make_vec("sensorium/AvoidObstacles-v0", num_envs=n, vectorization_mode="vector_entry_point")
    singles = [gym.make("sensorium/AvoidObstacles-v0", engine="simulation") for _ in range(n)]
    return venv, singles


def test_extreme_finite_actions_clip_alike_and_non_finite_ones_are_refused_by_both_envs():
    """Normalized actions of +-1e308 (whose product with the maximum wheel speed overflows), 5,
    -0.0 and subnormals: the vector env's sub-envs and the single envs give the same observations,
    rewards and poses bit for bit (an action beyond [-1, 1] is the full wheel speed: 1e308 moves
    the robot exactly as 1.0 does). NaN and +-inf: both refuse with one line naming the sub-env or
    the robot, and nothing moved (the next step is still in lockstep)."""
    from tests.test_gym_vector import _reset_both, _step_both

    n = 3
    venv, singles = _envs(n)
    _reset_both(venv, singles, 4)
    done = np.zeros(n, dtype=bool)
    acts = [[1e308, -1e308], [5.0, 5.0], [-0.0, 5e-324], [1.0, -1.0], [-1e308, 1e308]]
    for t in range(10):
        a = np.array([acts[(t + i) % len(acts)] for i in range(n)], dtype=np.float64)
        _step_both(venv, singles, a, done, t)
    # 1e308 is the full speed: two fresh envs, one given 1e308 and one 1.0, stay identical
    one, big = (gym.make("sensorium/AvoidObstacles-v0", engine="simulation") for _ in range(2))
    one.reset(seed=9)
    big.reset(seed=9)
    for _ in range(4):
        assert one.step(np.array([1.0, 1.0]))[4]["pose"].tobytes() == big.step(np.array([1e308, 1e308]))[4][
            "pose"].tobytes()
    for bad in (np.nan, np.inf, -np.inf):
        a = np.zeros((n, 2))
        a[1, 0] = bad
        with pytest.raises(ValueError, match=r"^sub-env 1: action must be 2 finite values"):
            venv.step(a)
        with pytest.raises(ValueError, match=r"^epuck: action must be 2 finite"):
            singles[1].step(a[1])
    _step_both(venv, singles, np.full((n, 2), 0.5), done, 99)
    venv.close()


def test_no_copy_one_copy_and_1024_copies_of_the_vector_env_are_single_envs():
    """A vector env of one sub-env, and of 1,024 (sub-envs 0, 511 and 1,023 checked against single
    envs with their seeds, bit for bit over a few steps); stepping no copy (set_wheels and step
    over an empty selection) changes nothing."""
    from tests.test_gym_vector import _row, _same_obs

    for n, watched in ((1, [0]), (1024, [0, 511, 1023])):
        venv = gym.make_vec("sensorium/AvoidObstacles-v0", num_envs=n, vectorization_mode="vector_entry_point")
        obs, info = venv.reset(seed=100)
        singles = {i: gym.make("sensorium/AvoidObstacles-v0", engine="simulation") for i in watched}
        for i, env in singles.items():
            o, inf = env.reset(seed=100 + i)
            assert _same_obs(_row(obs, i), o) and inf["pose"].tobytes() == info["pose"][i].tobytes()
        rng = np.random.default_rng(n)
        for t in range(3):
            a = rng.uniform(-1, 1, (n, 2))
            obs, r, te, tr, info = venv.step(a)
            for i, env in singles.items():
                o, ri, tei, tri, inf = env.step(a[i])
                assert _same_obs(_row(obs, i), o) and (ri, tei, tri) == (r[i], te[i], tr[i]), (n, t, i)
                assert inf["pose"].tobytes() == info["pose"][i].tobytes()
        sim = venv.unwrapped.sim if hasattr(venv.unwrapped, "sim") else venv.sim
        pos, clock = sim.pos.copy(), sim.time_ms.copy()
        sim.set_wheels(0, np.empty(0), np.empty(0), np.empty(0, dtype=np.int64))
        sim.step(np.zeros(n, dtype=bool))
        assert sim.pos.tobytes() == pos.tobytes() and sim.time_ms.tobytes() == clock.tobytes()
        venv.close()


# ------------------------------------------------------------------ lookup tables

def _increasing_tables():
    xs = st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=2, max_size=7, unique=True).map(sorted)
    return xs.flatmap(lambda x: st.lists(st.tuples(st.floats(-1e4, 1e4), st.floats(0.0, 1.0)), min_size=len(x),
                                         max_size=len(x)).map(lambda yn: [[a, b, c] for a, (b, c) in zip(x, yn)]))


EDGE_VALUES = [math.nan, math.inf, -math.inf, 0.0, -0.0, 5e-324, -5e-324, 1e308, -1e308]


@needs_c
@SMALL
@given(rows=_increasing_tables(), values=st.lists(st.floats(-2e3, 2e3) | st.sampled_from(EDGE_VALUES), max_size=20))
def test_the_lookup_pass_is_the_numpy_interpolation_bit_for_bit_on_nan_inf_and_the_table_inputs(rows, values):
    table = LookupTable(rows)
    if not table.inputs_increasing:     # (unique floats can still collide: -0.0 and 0.0)
        return
    v = np.array(values + [r[0] for r in rows], dtype=np.float64)      # every input of the table too
    got = packets.lookup(table, v)
    assert got is not None
    with np.errstate(over="ignore", invalid="ignore"):    # (inf - x) / span: replaced by the clamp
        want = table.interpolate(v)
    assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()
    empty = packets.lookup(table, np.empty(0))
    assert empty is not None and empty[0].shape == (0,) and empty[1].shape == (0,)


def test_degenerate_tables_are_left_to_the_numpy_path_and_read_their_closed_forms():
    """One row: its output everywhere; repeated inputs and decreasing inputs: not given to the C
    pass (its bisection assumes increasing inputs), and the numpy path clamps and interpolates as
    Webots' bisection does."""
    v = np.array([-1.0, 0.0, 0.5, 1.0, 2.0, math.inf, -math.inf, math.nan])
    one = LookupTable([[0.5, 7.0, 0.1]])
    assert packets.lookup(one, v) is None
    y, n = one.interpolate(v)
    assert (y == 7.0).all() and (n == 0.1).all()
    repeated = LookupTable([[0.0, 0.0, 0.0], [1.0, 10.0, 0.0], [1.0, 20.0, 0.0], [2.0, 30.0, 0.0]])
    assert packets.lookup(repeated, v) is None
    y, _ = repeated.interpolate(np.array([0.5, 1.0, 1.5, 2.5]))
    assert y.tolist() == [5.0, 20.0, 25.0, 30.0]
    decreasing = LookupTable([[2.0, 0.0, 0.0], [0.0, 10.0, 0.0]])     # a sonar-like falling table
    assert packets.lookup(decreasing, v) is None
    y, _ = decreasing.interpolate(np.array([3.0, 2.0, 1.0, 0.0, -1.0]))
    # v <= x[0] = 2 takes the first row's output (Webots' clamp reads the first row first)
    assert y.tolist() == [10.0, 0.0, 0.0, 0.0, 0.0]


# ------------------------------------------------------------------ the reward, gap and sonar passes

finite_or_not = st.floats(-10.0, 10.0) | st.sampled_from(EDGE_VALUES)


@needs_c
@SMALL
@given(d=st.lists(finite_or_not, min_size=0, max_size=24), rays=st.sampled_from([1, 2, 3, 4]),
       vel=st.lists(st.floats(-7.0, 7.0) | st.sampled_from([math.nan, math.inf, -0.0]), min_size=8, max_size=8))
def test_the_gap_and_reward_passes_are_task_pys_numpy_on_nan_inf_and_empty_inputs(d, rays, vel):
    n = len(d) // rays
    dist = np.array(d[:n * rays], dtype=np.float64).reshape(n, rays)
    far, radius = 0.08, 0.035
    gap = packets.clearance_gaps(dist, far, radius)
    clear = np.where(np.isfinite(dist), dist, np.inf).min(axis=1, initial=np.inf)
    want = np.where(np.isfinite(clear), clear, far) - radius
    assert gap is not None and gap.tobytes() == want.tobytes()
    velocity = np.array(vel, dtype=np.float64).reshape(4, 1, 2)
    copies = (np.arange(n) % 4).astype(np.int64)
    near, contact, penalty, vmax = 0.05, 0.005, 1.0, (6.28, 7.5)     # each wheel over its own maximum
    got = packets.avoid_reward(copies, 0, velocity, vmax, gap, near, contact, penalty)
    v = velocity[copies, 0]
    with np.errstate(all="ignore"):
        wl, wr = v[:, 0] / vmax[0], v[:, 1] / vmax[1]
        p = np.minimum(np.maximum(1.0 - gap / near, 0.0), 1.0)
        r = 0.5 * (wl + wr) * (1.0 - np.sqrt(np.abs(wl - wr) / 2.0)) * (1.0 - p)
        want_r = np.where(gap < contact, r - penalty, r)
    assert got is not None and got.tobytes() == want_r.tobytes()


@needs_c
@SMALL
@given(S=st.integers(0, 3), N=st.integers(1, 5), data=st.data())
def test_sonars_in_c_are_the_numpy_combine_with_tangent_normals_nan_and_inf_distances(S, N, data):
    """All-sonar combines with and without the C passes, bit for bit: normals perpendicular to the
    ray (a cone tangent to a cylinder: incidence pi/2, no echo), head on, zero normals (a miss's),
    NaN/inf distances, distances at and beyond the range."""
    plan = CombinePlan(2, np.full(N, 1.0 / N), 3.0, 1.0, S, N)
    r = np.array(data.draw(st.lists(st.floats(0.0, 4.0) | st.sampled_from([3.0, math.inf, math.nan, 0.0]),
                                    min_size=S * N, max_size=S * N)), dtype=np.float64).reshape(S, N)
    a = np.array(data.draw(st.lists(st.floats(-math.pi, math.pi), min_size=S * N, max_size=S * N))).reshape(S, N)
    u = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=-1)
    kind = data.draw(st.lists(st.sampled_from(["tangent", "head", "zero", "tilt"]), min_size=S * N,
                              max_size=S * N))
    nrm = np.empty_like(u)
    for k, (s, j) in enumerate(np.ndindex(S, N)):
        uu = u[s, j]
        nrm[s, j] = {"tangent": [-uu[1], uu[0], 0.0], "head": -uu, "zero": [0.0, 0.0, 0.0],
                     "tilt": -uu * math.cos(math.pi / 8) + np.array([-uu[1], uu[0], 0.0]) * math.sin(math.pi / 8)
                     }[kind[k]]
    want = combine_planned(plan, r, u, nrm)
    got = combine_planned(plan, r, u, nrm, native=packets)
    assert got.tobytes() == want.tobytes()
    for k, (s, _) in enumerate(np.ndindex(S, N)):     # a tangent ray never echoes
        if kind[k] == "tangent" and N == 1:
            assert got[s] == 3.0


# ------------------------------------------------------------------ a sanitized harness of the C passes

HARNESS = r"""
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
void sp_lookup(size_t, const double*, size_t, const double*, const double*, const double*, double*, double*);
void sp_atan2(size_t, const double*, size_t, const double*, size_t, double*, size_t);
void sp_cross_norm(size_t, const double*, const double*, double*);
void sp_sonar_nearest(size_t, size_t, const double*, const double*, const double*, double, double*);
void sp_clearance_gaps(size_t, size_t, const double*, double, double, double*);
void sp_avoid_reward(size_t, const int64_t*, size_t, size_t, const double*, double, double, const double*, double,
                     double, double, double*);
void sp_pose_scatter(size_t, size_t, const int64_t*, const int64_t*, const double*, const double*, const double*,
                     const double*, double*, double*);
void sp_roll_pitch_yaw(size_t, const double*, int, double*);
size_t sp_half_angles(size_t, const double*, double*);
size_t sp_correlation_ratios(size_t, const double*, const double*, double*);
void sp_gyro(size_t, const double*, double, double*);

/* exactly sized heap copies, so that any read or write past an end is caught */
static double* dup(const double* a, size_t n) {
  double* p = malloc(n ? n * sizeof(double) : 1);
  if (n) memcpy(p, a, n * sizeof(double));
  return p;
}
static void put(const char* name, const double* a, size_t n) {
  printf("%s", name);
  for (size_t i = 0; i < n; i++) printf(" %.17g", a[i]);
  printf("\n");
}

int main(void) {
  const double nan = NAN, inf = INFINITY;
  /* a two-row table: NaN, +-inf, the inputs, between; then no values */
  double tx[] = {0.0, 1.0}, ty[] = {10.0, 20.0}, tn[] = {0.0, 0.5};
  double tv[] = {nan, inf, -inf, 0.0, 1.0, 0.25, -1.0, 2.0};
  double *x = dup(tx, 2), *y = dup(ty, 2), *n = dup(tn, 2), *v = dup(tv, 8);
  double *oy = malloc(8 * sizeof(double)), *on = malloc(8 * sizeof(double));
  sp_lookup(8, v, 2, x, y, n, oy, on);
  put("lookup_y", oy, 8);
  put("lookup_n", on, 8);
  sp_lookup(0, NULL, 2, x, y, n, NULL, NULL);
  /* atan2 with a stride: every other value read and written */
  double ay[] = {1.0, 99.0, -0.0, 99.0, nan, 99.0}, ax[] = {0.0, -1.0, 1.0};
  double *a_y = dup(ay, 6), *a_x = dup(ax, 3), *a_o = malloc(5 * sizeof(double));
  for (int i = 0; i < 5; i++) a_o[i] = 7.0;
  sp_atan2(3, a_y, 2, a_x, 1, a_o, 2);
  put("atan2", a_o, 5);
  sp_atan2(0, NULL, 1, NULL, 1, NULL, 1);
  /* cross norms: parallel, perpendicular, NaN */
  double cu[] = {1, 0, 0, 1, 0, 0, nan, 0, 0}, cb[] = {2, 0, 0, 0, 3, 0, 1, 0, 0};
  double *c_u = dup(cu, 9), *c_b = dup(cb, 9), *c_o = malloc(3 * sizeof(double));
  sp_cross_norm(3, c_u, c_b, c_o);
  put("cross", c_o, 3);
  sp_cross_norm(0, NULL, NULL, NULL);
  /* sonars: S = 2 of N = 3 (no echo; one NaN, one beyond, one good), and N = 0 */
  double sr[] = {inf, nan, 1.0, nan, 5.0, 2.0}, sb[] = {0, 0, 1.5, 0, 0, 0.1}, sm[] = {3.0, 3.0};
  double *s_r = dup(sr, 6), *s_b = dup(sb, 6), *s_m = dup(sm, 2), *s_o = malloc(2 * sizeof(double));
  sp_sonar_nearest(2, 3, s_r, s_b, s_m, M_PI / 8, s_o);
  put("sonar", s_o, 2);
  sp_sonar_nearest(2, 0, NULL, NULL, s_m, M_PI / 8, s_o);
  put("sonar0", s_o, 2);
  sp_sonar_nearest(0, 3, NULL, NULL, NULL, M_PI / 8, NULL);
  /* gaps: no ray finite; a NaN among them; no rays at all */
  double gd[] = {inf, nan, 0.04, nan};
  double *g_d = dup(gd, 4), *g_o = malloc(2 * sizeof(double));
  sp_clearance_gaps(2, 2, g_d, 0.08, 0.035, g_o);
  put("gaps", g_o, 2);
  sp_clearance_gaps(2, 0, NULL, 0.08, 0.035, g_o);
  put("gaps0", g_o, 2);
  /* reward: copies 0 and 2 of 3, slot 1 of 2; a NaN gap */
  int64_t rc[] = {0, 2};
  double rv[12] = {0, 0, 6.28, 7.5, 0, 0, 0, 0, 0, 0, -6.28, 6.28}, rg[] = {1.0, nan};   /* both wheels at their maximum */
  int64_t* r_c = malloc(sizeof rc);
  memcpy(r_c, rc, sizeof rc);
  double *r_v = dup(rv, 12), *r_g = dup(rg, 2), *r_o = malloc(2 * sizeof(double));
  sp_avoid_reward(2, r_c, 2, 1, r_v, 6.28, 7.5, r_g, 0.05, 0.005, 1.0, r_o);
  put("reward", r_o, 2);
  sp_avoid_reward(0, NULL, 2, 1, r_v, 6.28, 7.5, NULL, 0.05, 0.005, 1.0, NULL);
  /* the pose scatter into the last copy's last slot */
  int64_t pc[] = {2}, ps[] = {1};
  int64_t *p_c = malloc(sizeof pc), *p_s = malloc(sizeof ps);
  memcpy(p_c, pc, sizeof pc);
  memcpy(p_s, ps, sizeof ps);
  double prot[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}, pxyz[6] = {0, 0, 0, 0, 0, 1e5};
  double *p_r = dup(prot, 9), *p_x = dup(pxyz, 6), *p_y = dup(pxyz, 6), *p_z = dup(pxyz, 6);
  double *rot = calloc(6 * 9, sizeof(double)), *pos = calloc(6 * 3, sizeof(double));
  sp_pose_scatter(1, 2, p_c, p_s, p_r, p_x, p_y, p_z, rot, pos);
  put("scatter_rot", rot + 5 * 9, 9);
  put("scatter_pos", pos + 5 * 3, 3);
  sp_pose_scatter(0, 2, NULL, NULL, NULL, NULL, NULL, NULL, rot, pos);
  /* quaternions: identity, NaN, infinite, a quarter turn about z */
  double q[] = {0, 0, 0, 1, nan, 0, 0, 1, 0, 0, inf, 1, 0, 0, sqrt(0.5), sqrt(0.5)};
  double *q_q = dup(q, 16), *q_o = malloc(12 * sizeof(double)), *h_o = malloc(4 * sizeof(double));
  sp_roll_pitch_yaw(4, q_q, 0, q_o);
  put("rpy", q_o, 12);
  size_t odd = sp_half_angles(4, q_q, h_o);
  printf("half_odd %zu\n", odd);
  double cc[] = {0.0, 0.5, -0.5, 1.0, 0.5}, ce[] = {3.0, 2.0, 2.0, inf, nan};
  double *c_c = dup(cc, 5), *c_e = dup(ce, 5), *c_r = malloc(5 * sizeof(double));
  odd = sp_correlation_ratios(5, c_c, c_e, c_r);
  printf("corr_odd %zu\n", odd);
  put("corr", c_r, 2);
  /* gyro: no turn, a quarter turn about z, over a huge and the least dt */
  double rel[18] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 1, 0, 0, 0, 0, 1};
  double *g_rel = dup(rel, 18), *g_w = malloc(6 * sizeof(double));
  sp_gyro(2, g_rel, 60.0, g_w);
  put("gyro", g_w, 6);
  sp_gyro(2, g_rel, 5e-324, g_w);
  put("gyro_tiny", g_w, 6);
  return 0;
}
"""


@pytest.mark.skipif(sys.platform == "win32" or shutil.which("cc") is None, reason="needs a C compiler")
def test_the_c_passes_under_address_and_undefined_behaviour_sanitizers_on_edge_inputs(tmp_path):
    """packets.c and a harness built with -fsanitize=address,undefined: the new passes on NaN, inf,
    empty inputs, strides and the last element of their arrays run clean (any overread, overflow or
    undefined operation aborts the harness), and their values are the closed forms."""
    src = Path(packets.__file__).with_name("packets.c")
    (tmp_path / "harness.c").write_text(HARNESS)
    exe = tmp_path / "harness"
    cmd = ["cc", "-g", "-O1", "-ffp-contract=off", "-fno-fast-math", "-fsanitize=address,undefined",
           "-fno-sanitize-recover=undefined", "-pthread", str(src), str(tmp_path / "harness.c"), "-o", str(exe),
           "-lm", "-ldl"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60,
                         env={"ASAN_OPTIONS": "detect_leaks=0:abort_on_error=1", "UBSAN_OPTIONS": "halt_on_error=1"})
    assert run.returncode == 0 and not run.stderr, run.stderr
    out = {line.split(" ", 1)[0]: [float(t) for t in line.split()[1:]] for line in run.stdout.splitlines()
           if not line.endswith("_odd " + line.split()[-1]) or line.count(" ") > 1}
    odd = dict(line.split() for line in run.stdout.splitlines() if "_odd" in line)

    def same(name, want):
        got = out[name]
        assert len(got) == len(want) and all(_same_value(a, b) for a, b in zip(got, want)), (name, got, want)

    same("lookup_y", [math.nan, 20.0, 10.0, 10.0, 20.0, 12.5, 10.0, 20.0])
    same("lookup_n", [math.nan, 0.5, 0.0, 0.0, 0.5, 0.125, 0.0, 0.5])
    same("atan2", [math.pi / 2, 7.0, math.atan2(-0.0, -1.0), 7.0, math.nan])
    same("cross", [0.0, 3.0, math.nan])
    same("sonar", [3.0, 2.0])
    same("sonar0", [3.0, 3.0])
    same("gaps", [0.08 - 0.035, 0.04 - 0.035])
    same("gaps0", [0.08 - 0.035, 0.08 - 0.035])
    same("reward", [1.0, math.nan])
    same("scatter_rot", list(range(1, 10)))
    same("scatter_pos", [1e5, 1e5, 1e5])
    quarter = math.sqrt(0.5)
    same("rpy", [v for q in ([0, 0, 0, 1], [math.nan, 0, 0, 1], [0, 0, math.inf, 1], [0, 0, quarter, quarter])
                 for v in orientation.roll_pitch_yaw(q).tolist()])
    assert out["rpy"][9:] == pytest.approx([0.0, 0.0, math.pi / 2], abs=1e-15)   # (sqrt(0.5) rounded)
    assert out["rpy"][4] == math.pi / 2        # a NaN quaternion's pitch: asin of Python's clamp of NaN (1.0)
    assert odd == {"half_odd": "2", "corr_odd": "3"}     # (left to the Python way: NaN/inf rows, bases < 0 or 1 ** inf)
    same("corr", [0.0, 0.25])
    angle = math.acos(((0.0 + 0.0 + 1.0) - 1.0) / 2.0)        # a quarter turn: 2 (pi/2) / (2 sin(pi/2)) / dt
    same("gyro", [0.0, 0.0, 0.0, 0.0, 0.0, 2.0 * (angle / (2.0 * math.sin(angle))) / 60.0])
    same("gyro_tiny", [0.0, 0.0, 0.0, 0.0, 0.0, math.inf])


@needs_c
@pytest.mark.parametrize("threads", [1, 2])
def test_coherent_runs_of_any_length_in_one_pass_are_each_runs_own_trace(threads):
    """A lidar's beams that may meet a body come in runs of any length, one per copy (the copies'
    pairs with their links, CopyRays._trace_runs): 200 such runs from origins around x = 1e5 m
    (float32 ~8 mm apart), 1 to 360 beams each, traced in one pass with ``seg_end`` on one thread
    or two: every beam's answer is its run's own one-origin trace's, bit for bit (packed without
    the runs' ends, beams of two runs share packets and some answers change)."""
    bs = BatchedSimulation(counterweighted(1), 1, precision="fast")
    static = bs.rays.static
    static.threads = threads
    tier = static._static_tier(bs.rays.movers._variant(RayKind.VISUAL, False))
    rng = np.random.default_rng(11)
    k, W = 200, 360
    rows = np.column_stack([1e5 + rng.uniform(-1.9, 1.9, k), rng.uniform(-1.9, 1.9, k), np.full(k, 0.15)])
    a = np.pi - (np.arange(W) + 0.5) * (2 * np.pi / W)
    dirs = np.column_stack([np.cos(a), np.sin(a), np.zeros(W)])
    runs = [np.sort(rng.choice(W, int(rng.integers(1, W + 1)), replace=False)) for _ in range(k)]
    O = np.concatenate([np.repeat(rows[j:j + 1], len(r), axis=0) for j, r in enumerate(runs)])
    D = np.concatenate([dirs[r] for r in runs])
    ends = np.cumsum([len(r) for r in runs])
    seg_end = np.repeat(ends, [len(r) for r in runs]).astype(np.int64)
    eps64 = 1e-9 + 1e-14 * float(np.abs(O).max())
    lim = np.full(len(O), 6.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):   # as the engine's casts
        every = static._trace(tier, O, D, 0.02, lim, -1, eps64, False, None, True, coherent=True,
                              seg_end=seg_end)[0]
        mixed = static._trace(tier, O, D, 0.02, lim, -1, eps64, False, None, True, coherent=True)[0]
        for j, r in enumerate(runs):
            got = every[ends[j] - len(r):ends[j]]
            one = static._trace(tier, np.broadcast_to(rows[j], (len(r), 3)), dirs[r], 0.02, np.full(len(r), 6.0),
                                -1, eps64, False, None, True)
            one = np.full(len(r), np.inf) if one is None else one[0]
            assert one.tobytes() == got.tobytes(), (j, np.flatnonzero(one != got))
    assert np.isfinite(every).mean() > 0.9
    assert (mixed != every).any()       # the runs' ends matter here: this test would see them ignored
