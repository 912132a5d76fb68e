"""The gym helpers in NUE worlds (x north, y up, z east; Webots before R2022a): ``info["pose"]``,
``random_start``, ``clearance``, ``ReachLight``, ``AvoidObstacles`` (and their vectorised forms)
and ``render()`` read the world's ENU view (sensorium/gym/frame.py).

Twins: an ENU world and the same world written in NUE axes (every top-level translation, light
location and direction permuted, every rotation turned by the permutation as an exact quaternion
product; the robots' own frames and devices unchanged) give the same episodes."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from sensorium.gym import SensoriumEnv, Task
from sensorium.gym.task import AvoidObstacles, ReachLight, clearance, random_start
from sensorium.gym.vector import SensoriumVectorEnv
from sensorium.gym.views import CopySim
from sensorium.schemas import world as wm
from sensorium.server.sim.batched import BatchedSimulation
from sensorium.server.sim.frames import ENU_AXES, enu_axes
from sensorium.server.sim.motion import _TO_ENU
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import LoadedWorld, default_world_path, load_world
from sensorium.server.world.poses import pose_from_model
from tests.test_gym_vector import _reset_both, _step_both, hills_world

TO_NUE = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])    # ENU -> NUE axes
TO_NUE_Q = (-0.5, -0.5, -0.5, 0.5)     # its quaternion (x, y, z, w): quaternion_matrix gives TO_NUE exactly
IDENTITY_Q = [0.0, 0.0, 0.0, 1.0]


def _qmul(a, b) -> list[float]:
    """Hamilton product a b of quaternions (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def _nue(v) -> list[float]:
    """An ENU vector's NUE components (north, up, east): a permutation, exact."""
    return [v[1], v[2], v[0]]


def nue_twin(world: wm.World) -> wm.World:
    """``world`` (ENU) written in NUE axes: the same place for everything. Checks that every
    top-level pose came out exactly the permuted ENU pose (rotations whose quaternion product with
    TO_NUE_Q is exact: the identity, half turns about z, the (1, 1, 1) third turn)."""
    data = copy.deepcopy(world.model_dump(mode="json", exclude_none=True))
    data["world_info"]["coordinate_system"] = "NUE"
    for item in data.get("solids", []) + data.get("robots", []):
        pose = item.setdefault("pose", {})
        assert "rotation" not in pose, "twins take quaternions (axis-angle rotations are not exact)"
        pose["translation"] = _nue(pose.get("translation", [0.0, 0.0, 0.0]))
        pose["quaternion"] = _qmul(TO_NUE_Q, pose.get("quaternion", IDENTITY_Q))
    for light in data.get("lights", []):
        for key in ("location", "direction"):
            if key in light:
                light[key] = _nue(light[key])
    twin = wm.World.model_validate(data)
    for a, b in zip(world.solids + world.robots, twin.solids + twin.robots):
        pa, pb = pose_from_model(a.pose), pose_from_model(b.pose)
        assert (TO_NUE @ pa.rotation == pb.rotation).all() and (TO_NUE @ pa.translation == pb.translation).all(), a.name
    return twin


def arena_twins() -> tuple[LoadedWorld, LoadedWorld]:
    """The embedded arena with its rotations made exact (the crate turned half a turn, the bollard
    a third turn about (1, 1, 1), the e-puck facing east, the scout west) and its NUE twin."""
    lw = load_world(default_world_path())
    data = lw.world.model_dump(mode="json", exclude_none=True)
    exact = {"crate": [0.0, 0.0, 1.0, 0.0], "bollard": [0.5, 0.5, 0.5, 0.5], "scout": [0.0, 0.0, 1.0, 0.0]}
    for item in data["solids"] + data["robots"]:
        item["pose"].pop("rotation", None)
        if item["name"] in exact:
            item["pose"]["quaternion"] = exact[item["name"]]
    enu = wm.World.model_validate(data)
    return (LoadedWorld(world=enu, source="arena_enu", base_dir=lw.base_dir),
            LoadedWorld(world=nue_twin(enu), source="arena_nue", base_dir=lw.base_dir))


def _goal_task(goal: str, start: bool, max_steps: int | None = None) -> Task:
    if goal == "reach":
        g: ReachLight | AvoidObstacles = ReachLight("lamp", radius=0.2)
        robot, obs = "epuck", ["ls0", "ls1", *[f"ps{i}" for i in range(8)]]
    else:
        g = AvoidObstacles(near=0.3)
        robot, obs = "scout", ["lidar", "sonar_front", "sonar_left", "sonar_right", "sonar_back"]
    return Task(robot=robot, observations=obs, control_period_ms=64, max_steps=max_steps, reward=g,
                terminated=g.terminated, start=random_start((-0.5, 0.5), (-0.3, 0.3)) if start else None)


def _close(a, b, tol: float) -> bool:
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and (np.array_equal(a, b) if tol == 0.0 else bool(np.all(np.abs(a - b) <= tol)))


# ------------------------------------------------------------------------------ the ENU view itself

def test_enu_axes_index_the_simulations_own_world_to_enu_permutation():
    enu, nue = arena_twins()
    assert enu_axes(enu.world) == ENU_AXES == (0, 1, 2)
    axes = enu_axes(nue.world)
    assert axes == (2, 0, 1)                              # east is z, north x, up y
    v = np.array([1.5, -2.25, 3.125])
    assert (v[list(axes)] == _TO_ENU["NUE"] @ v).all()


def _upright_world(rotation: list[float] | None) -> wm.World:
    """A NUE world: a robot whose own frame is y up (Webots before R2022a) at north 1, height 0.04,
    east 2 (``rotation``: its axis-angle, None facing north), a lamp at north 3, height 0.5, east 4;
    a wall whose west face is 0.55 m east of the robot; a floor."""
    return wm.World.model_validate({
        "world_info": {"basic_time_step": 16, "coordinate_system": "NUE"},
        "solids": [{"name": "floor", "pose": {"quaternion": list(TO_NUE_Q)}, "geometry": {"type": "plane"}},
                   {"name": "wall", "pose": {"translation": [1.0, 0.1, 2.6]},
                    "geometry": {"type": "box", "size": [2.0, 0.2, 0.1]}, "appearance": {"base_color": [0.5, 0.5, 0.5]}}],
        "lights": [{"type": "PointLight", "name": "lamp", "location": [3.0, 0.5, 4.0]}],
        "robots": [{"name": "bot", "pose": {"translation": [1.0, 0.04, 2.0],
                                            **({"rotation": rotation} if rotation else {})},
                    "body": {"geometry": {"type": "sphere", "radius": 0.04}},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10.0},
                    "devices": [{"device": "DistanceSensor", "name": "ahead", "lookup_table": [[0, 0, 0], [2, 2, 0]]}]}]})


@pytest.mark.parametrize("rotation, yaw", [(None, math.pi / 2), ([0.0, 1.0, 0.0, math.pi / 2], math.pi),
                                           ([0.0, 1.0, 0.0, -math.pi / 2], 0.0)])
def test_info_pose_in_a_nue_world_is_east_north_and_the_yaw_about_up(rotation, yaw):
    """Closed form: a robot at north 1, east 2 gives info["pose"] (2, 1, yaw), its heading's angle
    counter-clockwise about up from east -- facing north π/2, turned a quarter about y (its x axis
    to -z) west: π, the other way east: 0 -- in the single env (both engines) and the vector env."""
    world = _upright_world(rotation)
    task = Task(robot="bot", observations=["ahead"], max_steps=None)
    infos = [SensoriumEnv(world, task, engine=engine).reset(seed=0)[1]["pose"] for engine in ("simulation", "batched")]
    venv = SensoriumVectorEnv(world, task, 2)
    infos += list(venv.reset(seed=0)[1]["pose"])
    for pose in infos:
        assert pose[0] == 2.0 and pose[1] == 1.0
        assert abs(math.remainder(pose[2] - yaw, 2.0 * math.pi)) <= 1e-15, pose
    assert len({p.tobytes() for p in infos}) == 1


def test_clearance_in_a_nue_world_casts_on_the_ground_plane():
    """Closed form: the wall's west face is 0.55 m east of the robot (world +z), the floor 0.04 m
    below it: clearance is 0.55 (its rays lie in the x-z plane; rays in the x-y plane would see the
    floor at 0.04 and miss the wall), in a Simulation and in a batched copy, and AvoidObstacles'
    vectorised gap is the single env's."""
    world = _upright_world(None)
    sim = Simulation(LoadedWorld(world=world, source="nue", base_dir=default_world_path().parent))
    view = CopySim(BatchedSimulation(world, 2), 1)
    for s in (sim, view):
        assert clearance(s, s.robot("bot")) == pytest.approx(0.55, abs=1e-12)
        assert clearance(s, s.robot("bot"), max_distance=0.5) == 0.5
    goal = AvoidObstacles(near=1.0)
    gap = goal._gap(sim, sim.robot("bot"))
    # less the body's radius as contact sees it: the y-up sphere turned into ENU, its circumscribed sphere
    assert gap == pytest.approx(0.55 - 0.04 * math.sqrt(2.0), abs=1e-12)
    vec = goal.vectorized(view._s, 0)
    assert vec.gaps(np.array([0, 1])).tolist() == [gap, gap]


@pytest.mark.parametrize("own_up", ["y", "z"])
def test_avoid_obstacles_takes_the_body_radius_the_nue_contact_takes(own_up):
    """AvoidObstacles' gap is the clearance less the robot's body radius as the kinematic contact
    sees it: in a NUE world the radius of its body turned into ENU (contact.enu_body) -- a box robot
    built y up (0.1 x 0.3 x 0.1, 0.3 tall) or z up (turned by the NUE twin's exact rotation) gets
    the contact's own disc, the single and the vectorised goal alike."""
    size = [0.1, 0.3, 0.1] if own_up == "y" else [0.1, 0.1, 0.3]
    pose = {"translation": [0.0, 0.15, 0.0]} if own_up == "y" else {"translation": [0.0, 0.15, 0.0], "quaternion": list(TO_NUE_Q)}
    world = wm.World.model_validate({
        "world_info": {"coordinate_system": "NUE"},
        "robots": [{"name": "bot", "pose": pose, "body": {"geometry": {"type": "box", "size": size}},
                    "differential_drive": {"wheel_radius": 0.02, "axle_length": 0.05, "max_wheel_speed": 10.0}}]})
    bs = BatchedSimulation(world, 1)
    contact_radius = float(bs.foot_radius[0])
    goal = AvoidObstacles()
    assert goal.vectorized(bs, 0).radius == contact_radius
    sim = Simulation(world)
    free = goal._gap(sim, sim.robot("bot"))                      # nothing around: the clearance is its far end
    assert free == pytest.approx(max(goal.near, goal.contact_distance) + 1e-6, abs=1e-12)
    assert goal._radius == contact_radius
    if own_up == "z":
        assert contact_radius == math.hypot(0.05, 0.05)           # the ENU robot's disc, exactly


def test_reach_light_measures_the_horizontal_distance_in_a_nue_world():
    """Closed form: the lamp is 2 m east and 2 m north of the robot and 0.46 m above it: ReachLight
    measures sqrt(8) (east and north, not north and height), as its vectorised form does."""
    world = _upright_world(None)
    sim = Simulation(world)
    goal = ReachLight("lamp")
    assert goal.distance(sim, sim.robot("bot")) == math.hypot(2.0, 2.0)
    bs = BatchedSimulation(world, 3)
    vec = goal.vectorized(bs, 0)
    vec.reset(np.arange(3))
    assert vec.distance(np.arange(3)).tolist() == [math.hypot(2.0, 2.0)] * 3


# ------------------------------------------------------------------------------ random_start

@pytest.mark.parametrize("own_up", ["z", "y"])
def test_random_start_in_a_nue_world_keeps_the_robot_upright_and_at_its_height(own_up):
    """A robot whose own frame is z up (the arena twin's scout, facing west) or y up (Webots before
    R2022a's robots: facing north at the identity): random_start draws east from its x range,
    north from its y range and the yaw, as the ENU world's start draws them (the same generator
    calls); the robot lands at (north, its height, east), its own up axis along the world's y,
    its own x axis level at the drawn yaw about up from east -- in a Simulation and a batched copy."""
    if own_up == "z":
        world, robot, up_col = arena_twins()[1], "scout", 2
    else:
        world, robot, up_col = LoadedWorld(world=_upright_world(None), source="nue", base_dir=default_world_path().parent), "bot", 1
    start = random_start((-0.5, 0.5), (-0.3, 0.3))
    sims = [Simulation(world), CopySim(BatchedSimulation(world, 2), 1)]
    height = float(sims[0].robot(robot).pose.translation[1])
    for seed in range(20):
        want = np.random.default_rng(seed)
        east, north, yaw = want.uniform(-0.5, 0.5), want.uniform(-0.3, 0.3), want.uniform(-math.pi, math.pi)
        for s in sims:
            start(s, s.robot(robot), np.random.default_rng(seed))
            pose = s.robot(robot).pose
            assert pose.translation.tolist() == [north, height, east]
            r = pose.rotation
            assert np.abs(r[:, up_col] - [0.0, 1.0, 0.0]).max() <= 1e-15, (seed, r)
            assert abs(r[1, 0]) <= 1e-15                                   # forward level
            assert abs(math.remainder(math.atan2(r[0, 0], r[2, 0]) - yaw, 2.0 * math.pi)) <= 1e-15
            assert abs(np.linalg.det(r) - 1.0) <= 1e-14                     # a rotation (to rounding)
        assert sims[0].robot(robot).pose.rotation.tobytes() == sims[1].robot(robot).pose.rotation.tobytes()


# ------------------------------------------------------------------------------ twins

@pytest.mark.parametrize("engine", ["simulation", "batched"])
@pytest.mark.parametrize("goal", ["reach", "avoid"])
@pytest.mark.parametrize("start", [False, True])
def test_an_enu_world_and_its_nue_twin_give_the_same_single_env_episode(goal, start, engine):
    """The arena and its NUE twin, the same seed and actions (EXACT rays): info["pose"], rewards,
    terminations, clearance and every observation step by step are the same values -- exactly
    from the world-file start; with random_start within 1e-9 (its NUE rotation is a quaternion,
    the ENU one the axis-angle turn about z: the two agree to rounding, 1e-16)."""
    enu, nue = arena_twins()
    tol = 1e-9 if start else 0.0
    envs = [SensoriumEnv(w, _goal_task(goal, start), precision="exact", engine=engine) for w in (enu, nue)]
    (o1, i1), (o2, i2) = (env.reset(seed=7) for env in envs)
    rng = np.random.default_rng(3)
    moved = 0.0
    for t in range(120):
        assert _close(i1["pose"], i2["pose"], tol), (t, i1["pose"], i2["pose"])
        assert all(_close(o1[k], o2[k], tol) for k in o1), t
        robot = envs[0].agent.robot
        c1, c2 = (clearance(env.sim, env.sim.robot(robot)) for env in envs)
        assert _close(c1, c2, tol), t
        a = rng.uniform(-1.0, 1.0, 2).astype(np.float32)
        a[:] = np.abs(a) if t % 30 < 20 else a          # mostly forward: into walls and obstacles
        (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) = (env.step(a) for env in envs)
        assert _close(r1, r2, tol) and te1 == te2 and tr1 == tr2, (t, r1, r2, te1, te2)
        moved = max(moved, float(np.hypot(*(i1["pose"][:2]))))
        if te1:
            break
    assert moved > 0.1


@pytest.mark.parametrize("goal", ["reach", "avoid"])
def test_an_enu_world_and_its_nue_twin_give_the_same_vector_env_episodes(goal):
    """The batched vector env on the arena and on its NUE twin with random starts, ReachLight's or
    AvoidObstacles' vectorised form: the same rewards, flags, poses and observations (within 1e-9,
    random_start's rounding) across autoresets; and on the NUE twin every sub-env is the single
    env with its seed, bit for bit (observations, rewards, flags, clocks, poses)."""
    enu, nue = arena_twins()
    n = 3
    # (each env its own task: a goal keeps its previous distance)
    venvs = [SensoriumVectorEnv(w, _goal_task(goal, True, max_steps=15), n, precision="exact") for w in (enu, nue)]
    (o1, i1), (o2, i2) = (v.reset(seed=5) for v in venvs)
    rng = np.random.default_rng(2)
    ended = 0
    for t in range(45):
        assert _close(i1["pose"], i2["pose"], 1e-9), t
        assert all(_close(o1[k], o2[k], 1e-9) for k in o1), t
        a = rng.uniform(-1.0, 1.0, (n, 2)).astype(np.float32)
        (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) = (v.step(a) for v in venvs)
        assert _close(r1, r2, 1e-9) and (te1 == te2).all() and (tr1 == tr2).all(), (t, r1, r2)
        ended += int((te1 | tr1).sum())
    assert ended >= 3
    venvs[0].close()
    singles = [SensoriumEnv(nue, _goal_task(goal, True, max_steps=15), precision="exact", engine="simulation")
               for _ in range(n)]
    _reset_both(venvs[1], singles, 5)
    rng = np.random.default_rng(2)
    done = np.zeros(n, dtype=bool)
    resets = 0
    for t in range(45):
        resets += _step_both(venvs[1], singles, rng.uniform(-1.0, 1.0, (n, 2)).astype(np.float32), done, t)[0]
    venvs[1].close()
    assert resets >= 3


def _hills() -> wm.World:
    """An ENU world of hills (a random terrain on a floor) and a rover with a distance sensor and a
    two-layer lidar (tests/test_gym_vector.py's hilly world)."""
    return hills_world()


def test_random_starts_on_a_nue_terrain_keep_the_clearance_and_ride_it_as_the_enu_twin():
    """Hills and their NUE twin: random_start in NUE lands the rover at its world-file clearance
    (0.5 m less the ground under its world-file place) above the ground where it lands, measured
    along y; driving over the hills, the twins' poses (heights and attitudes included), lidar and
    distance readings agree within 1e-9 step by step, and the NUE vector env's sub-envs are its
    single envs bit for bit across autoresets."""
    enu = _hills()
    nue = nue_twin(enu)

    def task() -> Task:
        return Task(robot="rover", observations=["ahead", "scan"], max_steps=15,
                    start=random_start((-1.5, 1.5), (-1.5, 1.5)))

    envs = [SensoriumEnv(w, task(), precision="exact") for w in (enu, nue)]
    (o1, _), (o2, _) = (env.reset(seed=9) for env in envs)
    ground = envs[1].sim.ground
    north, up, east = envs[1].sim.robot("rover").pose.translation
    assert abs(up - (ground.at(east, north)[0] + 0.5 - ground.at(0.1, 0.2)[0])) <= 1e-12
    tilted = 0
    for t in range(15):
        a = np.full(2, 0.8, dtype=np.float32)
        (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) = (env.step(a) for env in envs)
        p1, p2 = (env.sim.robot("rover").pose for env in envs)
        assert _close(p1.translation, TO_NUE.T @ p2.translation, 1e-9), t
        assert _close(p1.rotation, TO_NUE.T @ p2.rotation, 1e-9), t
        assert _close(i1["pose"], i2["pose"], 1e-9) and all(_close(o1[k], o2[k], 1e-9) for k in o1), t
        tilted += abs(p2.rotation[1, 2]) < 1.0 - 1e-6          # the rover's own z off the world's up (y)
    assert tilted > 5
    n = 3
    venv = SensoriumVectorEnv(nue, task(), n, precision="exact")
    singles = [SensoriumEnv(nue, task(), precision="exact", engine="simulation") for _ in range(n)]
    _reset_both(venv, singles, 5)
    rng = np.random.default_rng(2)
    done = np.zeros(n, dtype=bool)
    resets = 0
    for t in range(40):
        a = np.repeat(np.abs(rng.uniform(-1.0, 1.0, (n, 1))), 2, axis=1).astype(np.float32)   # straight on
        resets += _step_both(venv, singles, a, done, t)[0]
    venv.close()
    assert resets >= 3


def test_render_of_a_nue_world_is_its_enu_twins_image():
    """render() looks down the up axis with east to the right and north up: the arena and its NUE
    twin give the same top-down image after the same random start and actions, in the single env
    (both engines) and the vector env; and in a NUE world a lamp east and north of the robot is
    drawn right of and above it."""
    enu, nue = arena_twins()
    images = []
    for w in (enu, nue):
        for engine in ("simulation", "batched"):
            env = SensoriumEnv(w, _goal_task("avoid", True), render_mode="rgb_array", precision="exact", engine=engine)
            env.reset(seed=4)
            for _ in range(6):
                env.step(np.array([0.6, 1.0], dtype=np.float32))
            images.append(env.render())
        venv = SensoriumVectorEnv(w, _goal_task("avoid", True), 2, render_mode="rgb_array", precision="exact")
        venv.reset(seed=4)
        for _ in range(6):
            venv.step(np.tile(np.array([0.6, 1.0], dtype=np.float32), (2, 1)))
        images.append(venv.render()[0])
    assert all(img.tobytes() == images[0].tobytes() for img in images[1:])
    assert len(np.unique(images[0].reshape(-1, 3), axis=0)) > 5           # walls, floor, objects, robots
    env = SensoriumEnv(_upright_world(None), Task(robot="bot", observations=["ahead"]), render_mode="rgb_array")
    env.reset(seed=0)
    img = env.render()
    lamp = np.argwhere((img == (255, 230, 40)).all(axis=2)).mean(axis=0)       # (row, column)
    body = np.argwhere((img == (255, 255, 255)).all(axis=2)).mean(axis=0)      # the (white) robot and its heading
    assert lamp[1] > body[1] + 10 and lamp[0] < body[0] - 10


def test_the_pettingzoo_env_on_a_nue_twin_gives_the_same_agents_episodes():
    """SensoriumParallelEnv with both arena robots as agents (the e-puck to the lamp, the scout
    avoiding obstacles, random starts) on the arena and its NUE twin: every agent's pose info,
    reward, flags and observations agree step by step (within 1e-9, random_start's rounding)."""
    pytest.importorskip("pettingzoo")
    from sensorium.gym.multi import SensoriumParallelEnv

    def tasks() -> dict[str, Task]:
        return {"epuck": _goal_task("reach", True, max_steps=40), "scout": _goal_task("avoid", True, max_steps=40)}

    envs = [SensoriumParallelEnv(w, tasks(), precision="exact") for w in arena_twins()]
    (o1, i1), (o2, i2) = (env.reset(seed=11) for env in envs)
    rng = np.random.default_rng(6)
    steps = 0
    while envs[0].agents:
        assert envs[0].agents == envs[1].agents
        for a in envs[0].agents:
            assert _close(i1[a]["pose"], i2[a]["pose"], 1e-9) and all(_close(o1[a][k], o2[a][k], 1e-9) for k in o1[a])
        acts = {a: rng.uniform(-1.0, 1.0, 2).astype(np.float32) for a in envs[0].agents}
        (o1, r1, te1, tr1, i1), (o2, r2, te2, tr2, i2) = (env.step(acts) for env in envs)
        for a in acts:
            assert _close(r1[a], r2[a], 1e-9) and te1[a] == te2[a] and tr1[a] == tr2[a], (steps, a)
        steps += 1
    assert steps >= 10


def test_render_draws_a_y_up_nue_robots_heading_from_its_horizontal_extent():
    """The heading line of a robot is 1.4 times its body's reach on its own level axes: for a NUE
    robot built y up (a 0.1 x 0.3 x 0.1 box, 0.3 tall, facing north) 1.4 x 0.05 m, not its height."""
    data = _upright_world(None).model_dump(mode="json", exclude_none=True)
    data["robots"][0]["body"] = {"geometry": {"type": "box", "size": [0.1, 0.3, 0.1]},
                                 "appearance": {"base_color": [0.0, 0.0, 1.0]}}
    data["robots"][0]["pose"]["translation"][1] = 0.15
    data["solids"][0]["appearance"] = {"base_color": [0.3, 0.3, 0.3]}        # (a floor without one is white)
    env = SensoriumEnv(wm.World.model_validate(data), Task(robot="bot", observations=["ahead"]), render_mode="rgb_array")
    env.reset(seed=0)
    img = env.render()
    rows, cols = np.nonzero((img == (255, 255, 255)).all(axis=2))   # the heading line alone (the body is blue)
    assert len(set(cols.tolist())) == 1                              # straight up the image: north
    length = rows.max() - rows.min() + 1
    assert abs(length - 1.4 * 0.05 * env._renderer.scale) <= 1.5, (length, env._renderer.scale)
