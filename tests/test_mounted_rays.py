"""Rays rigidly mounted on moving bodies (``RayEngine.cast(mount=...)`` + ``cast_local``) and the
simulation's use of them for distance sensors: the same hits as the general broad phase, with the
own-body part decided once in the body frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.raycast.engine import Mount, Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Box, Cylinder, Plane, Pose, Sphere
from sensorium.server.world.loader import parse_world

BOTH = [Precision.FAST, Precision.EXACT]


def _rz(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _move_bodies(eng, bodies, xy, yaw, owner, O_loc, D_loc):
    """Place each body at (x, y, 0.025) turned by yaw; return its sensors' rays in the world."""
    poses = [Pose(_rz(a), np.array([x, y, 0.025])) for (x, y), a in zip(xy, yaw)]
    for b, p in zip(bodies, poses):
        eng.set_body_pose(b, p)
    R = np.stack([poses[i].rotation for i in owner])
    T = np.stack([poses[i].translation for i in owner])
    return np.einsum("nij,nj->ni", R, O_loc) + T, np.einsum("nij,nj->ni", R, D_loc)


def _crowd(precision, n=36, spacing=0.08, seed=3):
    """n cylinder robots (r 0.035) packed closely (neighbours within sensor reach), walls, a floor."""
    rng = np.random.default_rng(seed)
    eng = RayEngine(precision)
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    eng.add_body([ShapeEntry(Box((2.0, 0.05, 0.2)), Pose.identity(), True, True)], Pose(np.eye(3), np.array([0.0, 0.6, 0.1])))
    eng.add_body([ShapeEntry(Sphere(0.05), Pose.identity(), True, True)], Pose(np.eye(3), np.array([0.1, -0.1, 0.05])))
    bodies, poses = [], []
    side = int(math.ceil(math.sqrt(n)))
    for i in range(n):
        pose = Pose(_rz(rng.uniform(0, 2 * math.pi)),
                    np.array([-0.2 + spacing * (i % side) + rng.uniform(-0.01, 0.01),
                              -0.2 + spacing * (i // side) + rng.uniform(-0.01, 0.01), 0.025]))
        bodies.append(eng.add_body([ShapeEntry(Cylinder(0.035, 0.05), Pose.identity(), True, True)], pose, owner=i,
                                   movable=True))
        poses.append(pose)
    return eng, bodies, poses


def _mounted_rays(poses, bodies, radius_at, rays_per_body=8, reach=0.07):
    """Per body: rays starting at radius ``radius_at`` in the body frame, fanning outward."""
    O_loc, D_loc, mount, owner = [], [], [], []
    for i, b in enumerate(bodies):
        for k in range(rays_per_body):
            a = 2 * math.pi * k / rays_per_body + 0.1
            O_loc.append([radius_at * math.cos(a), radius_at * math.sin(a), 0.01])
            D_loc.append([math.cos(a + 0.2), math.sin(a + 0.2), 0.0])
            mount.append(b)
            owner.append(i)
    O_loc, D_loc = np.array(O_loc), np.array(D_loc)
    D_loc /= np.linalg.norm(D_loc, axis=1)[:, None]
    R = np.stack([poses[i].rotation for i in owner])
    T = np.stack([poses[i].translation for i in owner])
    O = np.einsum("nij,nj->ni", R, O_loc) + T
    D = np.einsum("nij,nj->ni", R, D_loc)
    return O_loc, D_loc, O, D, np.array(mount), np.array(owner), R


@pytest.mark.parametrize("precision", BOTH)
def test_mounted_rays_outside_their_body_give_the_general_answer_bit_for_bit(precision):
    eng, bodies, poses = _crowd(precision)
    _, _, O, D, mount, owner, _ = _mounted_rays(poses, bodies, radius_at=0.0357)
    t_far = np.full(len(O), 0.07)
    t_far[::5] = np.inf                                   # unbounded rays take the general broad phase
    O = np.vstack([O, [[0.0, 0.0, 0.3]]])                 # plus one unmounted ray, looking down
    D = np.vstack([D, [[0.05, 0.0, -1.0]] / np.linalg.norm([0.05, 0.0, -1.0])])
    t_far = np.append(t_far, 5.0)
    mount = np.append(mount, -1)
    for excl in (-1, np.append(owner, -1)):              # own body seen (infra-red) / excluded
        ref = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, exclude_owner=excl)
        got = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, exclude_owner=excl, mount=mount)
        assert np.count_nonzero(np.isfinite(ref.distance)) > len(O) // 4   # neighbours and walls are hit
        hit_robot = np.isin(ref.shape, np.arange(3, 3 + len(bodies)))
        assert np.count_nonzero(hit_robot) > 10
        np.testing.assert_array_equal(got.distance, ref.distance)
        np.testing.assert_array_equal(got.shape, ref.shape)
        np.testing.assert_array_equal(got.normal, ref.normal)


@pytest.mark.parametrize("precision", BOTH)
def test_own_body_hits_from_cast_local_complete_the_mounted_cast(precision):
    """Rays starting inside their own cylinder: the mounted cast skips the own body, cast_local
    (body frame, once) supplies it; the nearer of the two equals the general cast."""
    eng, bodies, poses = _crowd(precision, n=16, spacing=0.2)
    O_loc, D_loc, O, D, mount, owner, R = _mounted_rays(poses, bodies, radius_at=0.01)
    ref = eng.cast(O, D, 0.0, 0.5, kind=RayKind.VISUAL)
    got = eng.cast(O, D, 0.0, 0.5, kind=RayKind.VISUAL, mount=mount)
    assert np.all(got.distance > ref.distance)            # the own body is not seen by the mounted cast
    own_t = np.full(len(O), np.inf)
    own_s = np.full(len(O), -1)
    own_n = np.zeros((len(O), 3))
    for b in np.unique(mount):
        rows = mount == b
        h = eng.cast_local(int(b), O_loc[rows], D_loc[rows], 0.0, 0.5, kind=RayKind.VISUAL)
        own_t[rows], own_s[rows], own_n[rows] = h.distance, h.shape, h.normal
    # closed form in the body frame: from radius 0.01 outward to the cylinder wall at 0.035
    p, d = O_loc[:, :2], D_loc[:, :2]
    b_ = np.einsum("ij,ij->i", p, d)
    expect = -b_ + np.sqrt(b_ * b_ - (np.einsum("ij,ij->i", p, p) - 0.035 ** 2))
    tol = 1e-12 if precision == Precision.EXACT else 1e-3   # FAST sees the circumscribed shell
    np.testing.assert_allclose(own_t, expect, atol=tol)
    merged_t = np.minimum(own_t, got.distance)
    np.testing.assert_allclose(merged_t, ref.distance, rtol=0, atol=1e-12)
    own_wins = own_t < got.distance
    np.testing.assert_array_equal(np.where(own_wins, own_s, got.shape), ref.shape)
    world_n = np.einsum("nij,nj->ni", R, own_n)
    np.testing.assert_allclose(np.where(own_wins[:, None], world_n, got.normal), ref.normal, atol=1e-12)


def test_mount_and_cast_local_reject_bad_bodies():
    eng, bodies, _ = _crowd(Precision.FAST, n=4)
    with pytest.raises(ValueError, match="mount must hold body indices"):
        eng.cast(np.zeros((2, 3)), np.array([[1.0, 0, 0]] * 2), mount=np.array([0, 99]))
    with pytest.raises(ValueError, match="static"):
        eng.cast_local(1, np.zeros((1, 3)), np.array([[1.0, 0, 0]]))


@pytest.mark.parametrize("precision", BOTH)
def test_a_mount_kept_between_casts_gives_the_plain_answers_bit_for_bit_as_bodies_move(precision):
    """The same rays cast step after step with one Mount: the engine keeps a neighbour list of
    the bodies (redone only when some body moved by more than a margin) and gives exactly the
    answers of the plain mount array and of the general broad phase, through small moves (list
    kept), turns in place, and jumps (list redone)."""
    eng, bodies, poses = _crowd(precision, n=25, spacing=0.08)
    O_loc, D_loc, _, _, mount, owner, _ = _mounted_rays(poses, bodies, radius_at=0.0357)
    m = Mount(mount)
    assert np.asarray(m).tolist() == mount.tolist() and len(m) == len(mount)
    rng = np.random.default_rng(11)
    xy = np.array([p.translation[:2] for p in poses])
    yaw = rng.uniform(0, 2 * math.pi, len(bodies))
    lists, robot_hits = [], 0
    for step in range(14):
        if step == 9:                       # jumps: bodies swap neighbours
            xy[::3] += rng.uniform(-0.15, 0.15, xy[::3].shape)
        elif step:                          # small moves (1 mm) and turns
            xy += 0.001 * np.stack([np.cos(yaw), np.sin(yaw)], 1)
            yaw += rng.uniform(-0.3, 0.3, len(bodies))
        O, D = _move_bodies(eng, bodies, xy, yaw, owner, O_loc, D_loc)
        for excl in (-1, owner):
            ref = eng.cast(O, D, 0.0, 0.07, kind=RayKind.VISUAL, exclude_owner=excl)
            plain = eng.cast(O, D, 0.0, 0.07, kind=RayKind.VISUAL, exclude_owner=excl, mount=mount)
            got = eng.cast(O, D, 0.0, 0.07, kind=RayKind.VISUAL, exclude_owner=excl, mount=m)
            for a, b in ((got, plain), (got, ref)):
                assert a.distance.tobytes() == b.distance.tobytes()
                assert a.shape.tobytes() == b.shape.tobytes()
                assert a.normal.tobytes() == b.normal.tobytes()
            robot_hits += np.count_nonzero(np.isin(ref.shape, np.arange(3, 3 + len(bodies))))
        lists.append(eng.counters["neighbour_lists"])
    assert robot_hits > 100                 # rays do meet the neighbours
    made = np.diff([0] + lists)
    assert made[0] == 1 and made[9] == 1    # first cast, and after the jumps
    assert made[1:9].sum() <= 2             # 1 mm per step: the list is kept for several steps
    # turning in place: the body list holds (the centres stay), the list of rays near a neighbour
    # is kept for a tiny turn and redone for a large one; the answers stay exact
    for turn, redone in ((1e-4, 0), (0.5, 1)):
        before = (eng.counters["neighbour_lists"], eng.counters["ray_lists"])
        yaw += turn
        O, D = _move_bodies(eng, bodies, xy, yaw, owner, O_loc, D_loc)   # same centres, turned
        got = eng.cast(O, D, 0.0, 0.07, kind=RayKind.VISUAL, mount=m)
        ref = eng.cast(O, D, 0.0, 0.07, kind=RayKind.VISUAL)
        assert got.distance.tobytes() == ref.distance.tobytes() and got.normal.tobytes() == ref.normal.tobytes()
        assert (eng.counters["neighbour_lists"], eng.counters["ray_lists"]) == (before[0], before[1] + redone)
    # other limits for the same rays: the Mount's state is remade for them (same answers again)
    far = np.where(np.arange(len(O)) % 2 == 0, 0.05, 0.1)
    for t_far in (0.1, far):
        got = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, mount=m)
        ref = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL)
        assert got.distance.tobytes() == ref.distance.tobytes() and got.shape.tobytes() == ref.shape.tobytes()


@pytest.mark.parametrize("precision,seed", [(Precision.FAST, 0), (Precision.FAST, 1), (Precision.FAST, 2),
                                            (Precision.EXACT, 3)])
def test_a_kept_mount_matches_the_plain_one_under_random_motion(precision, seed):
    """Random crowds, rays (origins around each body, directions with a vertical part, per-ray
    limits) and motions from sub-millimetre drifts to jumps and half turns: the kept lists never
    lose a pair, the answers are the plain mount's bit for bit, every step."""
    rng = np.random.default_rng(seed)
    eng, bodies, poses = _crowd(precision, n=16, spacing=float(rng.uniform(0.075, 0.11)), seed=seed)
    k = 6 * len(bodies)
    owner = np.repeat(np.arange(len(bodies)), 6)
    mount = np.array(bodies)[owner]
    a = rng.uniform(0, 2 * math.pi, k)
    O_loc = np.stack([rng.uniform(0.03, 0.04, k) * np.cos(a), rng.uniform(0.03, 0.04, k) * np.sin(a),
                      rng.uniform(-0.02, 0.02, k)], 1)
    D_loc = np.stack([np.cos(a + rng.uniform(-0.6, 0.6, k)), np.sin(a + rng.uniform(-0.6, 0.6, k)),
                      rng.uniform(-0.3, 0.3, k)], 1)
    D_loc /= np.linalg.norm(D_loc, axis=1)[:, None]
    t_far = rng.uniform(0.02, 0.15, k)
    m = Mount(mount)
    xy = np.array([p.translation[:2] for p in poses])
    yaw = rng.uniform(0, 2 * math.pi, len(bodies))
    pairs = 0
    for _ in range(25):
        scale = rng.choice([0.0, 1e-4, 2e-3, 0.01, 0.1])
        xy += rng.normal(0.0, scale, xy.shape)
        yaw += rng.normal(0.0, rng.choice([0.0, 0.01, 0.2, 1.5]), len(bodies))
        O, D = _move_bodies(eng, bodies, xy, yaw, owner, O_loc, D_loc)
        got = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, mount=m)
        plain = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, mount=mount)
        assert got.distance.tobytes() == plain.distance.tobytes()
        assert got.shape.tobytes() == plain.shape.tobytes() and got.normal.tobytes() == plain.normal.tobytes()
        pairs += np.count_nonzero(np.isin(got.shape, np.arange(3, 3 + len(bodies))))
    assert pairs > 20                       # rays did meet other robots
    assert 1 < eng.counters["neighbour_lists"] <= eng.counters["ray_lists"] < 25   # lists both kept and redone


def test_a_mount_must_match_the_rays_and_the_bodies():
    eng, bodies, _ = _crowd(Precision.FAST, n=4)
    with pytest.raises(ValueError, match="one body per ray"):
        eng.cast(np.zeros((2, 3)), np.array([[1.0, 0, 0]] * 2), mount=Mount([bodies[0]] * 3))
    with pytest.raises(ValueError, match="mount must hold body indices"):
        eng.cast(np.zeros((2, 3)), np.array([[1.0, 0, 0]] * 2), mount=Mount([0, 99]))


def _ir_world(yaw: float, x: float) -> dict:
    table = [[0.0, 0.0, 0.0], [1.0, 1000.0, 0.0]]   # value = 1000 x distance (m)
    dev = {"device": "DistanceSensor", "type": "infra-red", "lookup_table": table, "number_of_rays": 1}
    return {"world_info": {"basic_time_step": 8},
            "solids": [{"name": "wall", "pose": {"translation": [x + 0.5, 0.0, 0.025]},
                        "geometry": {"type": "box", "size": [0.05, 1.0, 0.1]}}],
            "robots": [{"name": "r", "pose": {"translation": [x, 0.0, 0.025], "rotation": [0, 0, 1, yaw]},
                        "body": {"geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05}},
                        "devices": [{**dev, "name": "inside", "pose": {"translation": [0.01, 0.0, 0.0]}},
                                    {**dev, "name": "outside", "pose": {"translation": [0.04, 0.0, 0.0],
                                                                        "rotation": [0, 0, 1, math.pi]}},
                                    {**dev, "type": "generic", "name": "generic",
                                     "pose": {"translation": [0.01, 0.0, 0.0]}}]}]}


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_sensor_inside_its_body_sees_the_body_at_every_pose(precision):
    """An infra-red sensor 1 cm from the centre of its 3.5 cm cylinder reads its body's wall 2.5 cm
    away (Webots: infra-red sees its own robot); looking back at the body from outside it reads
    0.5 cm; a generic sensor ignores its own body and reads the wall of the room.  Moving and turning
    the robot changes none of the own-body readings (decided once, in the body frame)."""
    sim = Simulation(parse_world(_ir_world(0.0, 0.0)), precision=precision)
    for d in sim.all_devices():
        d.enable(8)
    tol = 1e-6 if precision == "exact" else 0.2     # in table units (mm); FAST: tessellated shell
    for step, (x, yaw) in enumerate([(0.0, 0.0), (0.3, 0.0), (0.3, math.pi / 2)]):
        if step:
            sim.robot("r").set_pose([x, 0.0, 0.025], [0, 0, 1, yaw])
        sim.step()
        assert sim.device("r/inside").value == pytest.approx(25.0, abs=tol)
        assert sim.device("r/outside").value == pytest.approx(5.0, abs=tol)
        # the wall's near face is at x = 0.475; turned to +y the generic ray misses it (max range 1 m)
        expect = 1000.0 * (0.475 - (x + 0.01)) if yaw == 0.0 else 1000.0
        assert sim.device("r/generic").value == pytest.approx(expect, abs=1e-6 if precision == "exact" else 1e-3)


def test_the_simulation_keeps_one_joined_mount_for_sensor_groups_cast_together():
    """Infra-red sensors with 3 and with 5 rays form two groups cast in one engine call: the
    simulation joins their Mounts once and passes the same joined Mount every step, so the engine's
    neighbour list is made once while the robots stand still, and redone when they move away."""
    table = [[0.0, 0.0, 0.0], [0.07, 70.0, 0.0]]
    robots = []
    for i in range(9):
        robots.append({"name": f"r{i}", "pose": {"translation": [0.09 * (i % 3), 0.09 * (i // 3), 0.025],
                                                 "rotation": [0, 0, 1, 0.4 * i]},
                       "body": {"geometry": {"type": "cylinder", "radius": 0.035, "height": 0.05}},
                       "devices": [{"device": "DistanceSensor", "name": f"ps{k}", "type": "infra-red",
                                    "lookup_table": table, "number_of_rays": 3 if k % 2 else 5, "aperture": 0.3,
                                    "pose": {"translation": [0.036 * math.cos(k), 0.036 * math.sin(k), 0.0],
                                             "rotation": [0, 0, 1, float(k)]}} for k in range(6)]})
    sim = Simulation(parse_world({"world_info": {"basic_time_step": 8}, "robots": robots}), precision="fast")
    for d in sim.all_devices():
        d.enable(8)
    eng = sim.scene.engine
    for _ in range(5):
        sim.step()
    assert eng.counters["neighbour_lists"] == 1
    seen = [d.value for d in sim.all_devices()]
    assert min(seen) < 70.0                      # neighbours are seen (and the robot's own body is not)
    sim.robot("r0").set_pose([-1.0, -1.0, 0.025], [0, 0, 1, 0.0])
    sim.step()
    assert eng.counters["neighbour_lists"] == 2
    assert all(sim.device(f"r0/ps{k}").value == 70.0 for k in range(6))   # nothing in reach any more


def _lidar_beams(W=720, L=24, vfov=0.6):
    az = np.linspace(-math.pi, math.pi, W, endpoint=False)
    el = np.linspace(-vfov / 2, vfov / 2, L)
    A, E = np.meshgrid(az, el)
    return np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)


@pytest.mark.parametrize("precision", BOTH)
def test_a_lidar_mount_that_sees_its_own_body_gives_the_plain_answers_bit_for_bit(precision):
    """A lidar rides a robot whose body its lower beams hit, beside other robots that move and turn:
    Mount(own=True) decides once which beams can reach the own body (in the body frame) and traces
    only those against it, and pairs the other robots per cast; every distance is the one the cast
    without a mount gives (which pairs every beam with the own body), bit for bit."""
    eng = RayEngine(precision)
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    eng.add_body([ShapeEntry(Box((4.0, 0.1, 0.3)), Pose.identity(), True, True)], Pose(np.eye(3), np.array([0.0, 1.5, 0.15])))
    scout = eng.add_body([ShapeEntry(Box((0.3, 0.2, 0.12)), Pose.identity(), True, True)],
                         Pose(_rz(0.4), np.array([0.1, 0.2, 0.06])), owner=0, movable=True)
    others = [eng.add_body([ShapeEntry(Cylinder(0.035, 0.05), Pose.identity(), True, True)],
                           Pose(_rz(0.0), np.array([x, y, 0.025])), owner=k + 1, movable=True)
              for k, (x, y) in enumerate([(0.6, 0.2), (-0.5, -0.4), (0.2, 0.9)])]
    D_loc = _lidar_beams()
    lidar_at = np.array([0.0, 0.0, 0.09])
    mount = Mount(np.full(len(D_loc), scout), own=True)
    rng = np.random.default_rng(4)
    own_rays = []
    for step in range(6):
        pose = Pose(_rz(0.4 + 0.3 * step), np.array([0.1 + 0.05 * step, 0.2 - 0.03 * step, 0.06]))
        eng.set_body_pose(scout, pose)
        for b in others:
            eng.set_body_pose(b, Pose(_rz(rng.uniform(0, 6)), np.array([*rng.uniform(-0.8, 0.8, 2), 0.025])))
        O = np.broadcast_to(pose.apply(lidar_at[None])[0], D_loc.shape)
        D = D_loc @ pose.rotation.T
        plain = eng.cast(O, D, 0.02, 6.0, kind=RayKind.VISUAL, distance_only=True)
        kept = eng.cast(O, D, 0.02, 6.0, kind=RayKind.VISUAL, distance_only=True, mount=mount)
        assert plain.distance.tobytes() == kept.distance.tobytes()
        own_rays.append(len(mount._state.own_pr))
    st = mount._state
    assert 0 < own_rays[0] < 0.3 * len(D_loc) and len(set(own_rays)) == 1   # decided once, a few beams
    assert (D_loc[st.own_pr, 2] < 0.0).all()          # the beams that go down towards the body
    assert np.isfinite(kept.distance[st.own_pr]).mean() > 0.9


@pytest.mark.parametrize("threads", [1, 2])
def test_a_fast_lidars_own_body_hits_traced_once_are_the_per_cast_answers(threads):
    """FAST, distances only: the own-body hits of a lidar's Mount are traced once (in the body frame,
    up to t_far) and kept while the limits stay; as the robot drives and turns, other robots cross
    its beams and a wall comes nearer than its body for some beams, every distance is the plain
    cast's bit for bit, also with limits that cut the own-body hits (t_far just around the body's
    top face) and after the limits change (traced again)."""
    eng = RayEngine(Precision.FAST)
    eng.threads = threads
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    wall = eng.add_body([ShapeEntry(Box((4.0, 0.1, 0.3)), Pose.identity(), True, True)],
                        Pose(np.eye(3), np.array([0.0, 1.5, 0.15])), movable=True)
    scout = eng.add_body([ShapeEntry(Box((0.3, 0.2, 0.12)), Pose.identity(), True, True)],
                         Pose(_rz(0.4), np.array([0.1, 0.2, 0.06])), owner=0, movable=True)
    other = eng.add_body([ShapeEntry(Cylinder(0.035, 0.05), Pose.identity(), True, True)],
                         Pose(np.eye(3), np.array([0.6, 0.2, 0.025])), owner=1, movable=True)
    D_loc = _lidar_beams(W=1440, L=24)          # 34,560 beams: split in blocks on two threads
    lidar_at = np.array([0.0, 0.0, 0.09])
    rng = np.random.default_rng(11)
    for t_far in (6.0, 0.1, 0.12, 6.0):   # the body's top face: 0.1015 away at least (none within 0.1)
        mount = Mount(np.full(len(D_loc), scout), own=True)
        for step in range(5):
            pose = Pose(_rz(0.4 + 0.7 * step), np.array([0.1 + 0.05 * step, 0.2 - 0.03 * step, 0.06]))
            eng.set_body_pose(scout, pose)
            eng.set_body_pose(other, Pose(_rz(rng.uniform(0, 6)), pose.apply(np.array([[0.22, 0.0, -0.035]]))[0]
                                          + [*rng.uniform(-0.05, 0.05, 2), 0.0]))
            # a thin wall just over the body's edge on some steps: nearer than the body for a few beams
            wall_at = pose.apply(np.array([[0.16, 0.0, 0.0]]))[0] + [0.0, 0.0, 0.05] if step % 2 else [0.0, 1.5, 0.15]
            eng.set_body_pose(wall, Pose(pose.rotation @ _rz(math.pi / 2) if step % 2 else np.eye(3), np.array(wall_at)))
            O = np.broadcast_to(pose.apply(lidar_at[None])[0], D_loc.shape)
            D = D_loc @ pose.rotation.T
            plain = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, distance_only=True)
            kept = eng.cast(O, D, 0.0, t_far, kind=RayKind.VISUAL, distance_only=True, mount=mount)
            assert plain.distance.tobytes() == kept.distance.tobytes()
        st = mount._state
        if t_far == 0.1:
            assert len(st.own_pr) == 0 and st.own_hits is None
            continue
        assert st.own_hits is not None and st.own_hits[0] == (0.0, t_far)    # traced once, for these limits
        assert 0 < len(st.own_hits[1]) <= len(st.own_pr) and np.isfinite(kept.distance[st.own_hits[1]]).all()
    # a shorter segment: the state is kept, but its own-body hits were traced up to 6 m (per cast again)
    kept = eng.cast(O, D, 0.0, 0.11, kind=RayKind.VISUAL, distance_only=True, mount=mount)
    assert mount._state is st and st.own_hits[0] == (0.0, 6.0)
    assert kept.distance.tobytes() == eng.cast(O, D, 0.0, 0.11, kind=RayKind.VISUAL, distance_only=True).distance.tobytes()
    # a longer segment than the state was made for: a new state, traced again
    kept = eng.cast(O, D, 0.0, 7.0, kind=RayKind.VISUAL, distance_only=True, mount=mount)
    assert mount._state.own_hits[0] == (0.0, 7.0)
    assert kept.distance.tobytes() == eng.cast(O, D, 0.0, 7.0, kind=RayKind.VISUAL, distance_only=True).distance.tobytes()


def test_the_simulation_mounts_a_fixed_lidar_on_its_robots_body():
    world = {"world_info": {"basic_time_step": 32},
             "solids": [{"name": "floor", "geometry": {"type": "plane"}},
                        {"name": "wall", "pose": {"translation": [1.0, 0, 0.2]}, "geometry": {"type": "box", "size": [0.1, 2, 0.4]}}],
             "robots": [{"name": "scout", "pose": {"translation": [0, 0, 0.06]},
                         "body": {"geometry": {"type": "box", "size": [0.3, 0.2, 0.12]}},
                         "devices": [{"device": "Lidar", "name": "lidar", "pose": {"translation": [0, 0, 0.09]},
                                      "horizontal_resolution": 360, "number_of_layers": 16,
                                      "vertical_field_of_view": 0.6, "field_of_view": 6.283185307179586,
                                      "near": 0.0, "min_range": 0.0, "max_range": 6.0}]}]}
    sims = [Simulation(parse_world(world), precision="fast") for _ in range(2)]
    for sim in sims:
        sim.device("scout/lidar").enable(32)
    sims[1].device("scout/lidar")._mount = (-7, None)   # a body index no cast accepts: replaced at once
    for sim in sims:
        sim.step()
    a, b = (s.device("scout/lidar") for s in sims)
    assert a._mount is not None and a._mount[1].own is not None and a._mount[1]._state is not None
    assert b._mount[0] == a._mount[0]
    assert a.range_image.tobytes() == b.range_image.tobytes()
    plan = a.plan(sims[0].robots["scout"].pose, 64, 32)[0]
    assert plan.mount is None                          # without the body index: no mount
