"""Swarms: a camera on each of many robots.  A camera's pixel rays share one origin, so the broad
phase culls the robots against the cone of its directions and their reach, and pairs its rays with
the robots in view only; the pairs (and so every answer) are those of the grid lookup that rays
from many origins take, in the same order."""

import math

import numpy as np
import pytest

from sensorium.server.raycast import movers
from sensorium.server.raycast.engine import RayKind
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import load_world
from tests._swarm import write_swarm


def _unit(v):
    return v / np.linalg.norm(v, axis=1)[:, None]


def _frustum(n_side: int, yaw: float, half: float) -> np.ndarray:
    """Pixel directions of a square image, heading ``yaw`` in the horizontal plane, half-angle ``half``."""
    u = np.tan(np.linspace(-half, half, n_side))
    x, y = np.meshgrid(u, u)
    d = np.column_stack([np.ones(x.size), x.ravel(), 0.5 * y.ravel()])
    c, s = math.cos(yaw), math.sin(yaw)
    return _unit(d @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]]))


def _pairs(C, radius, owner, O, D, t_near, lim, excl):
    with np.errstate(all="ignore"):
        return movers._grid_pairs(C, radius, radius ** 2, owner, O, D, t_near, lim, excl)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_one_origin_pairs_are_the_grid_pairs(seed, monkeypatch):
    """The same rays from one broadcast origin (culled movers x rays) and from an origin array (the
    grid lookup): the same (ray, mover) pairs in the same order, short, long, unbounded and empty
    segments, t_near > 0 and owner exclusion included."""
    rng = np.random.default_rng(seed)
    M = 400
    C = np.column_stack([rng.uniform(-3, 3, M), rng.uniform(-3, 3, M), np.full(M, 0.025)])
    radius = rng.uniform(0.03, 0.05, M)
    radius[:3] = 0.6                                   # a few big movers
    owner = rng.integers(-1, 40, M)
    D = _frustum(45, rng.uniform(-math.pi, math.pi), 0.45)
    n = len(D)
    o = np.array([rng.uniform(-1, 1), rng.uniform(-1, 1), 0.03])
    t_near = np.where(rng.random(n) < 0.2, 0.01, 0.0)
    lim = rng.uniform(0.05, 2.0, n)
    lim[rng.random(n) < 0.3] = 9.0                     # long rays (beyond the grid's segment cap)
    lim[:20] = np.inf
    lim[20:30] = -1.0                                  # empty segments
    excl = rng.integers(-1, 40, n)
    cells = []
    real = movers._cell_candidates
    monkeypatch.setattr(movers, "_cell_candidates", lambda *a: cells.append(1) or real(*a))
    one = _pairs(C, radius, owner, np.broadcast_to(o, D.shape), D, t_near, lim, excl)
    assert not cells                                   # the one-origin path ran
    grid = _pairs(C, radius, owner, np.repeat(o[None], n, axis=0), D, t_near, lim, excl)
    assert cells
    assert one[0].tolist() == grid[0].tolist() and one[1].tolist() == grid[1].tolist()
    assert len(grid[0]) > 300
    monkeypatch.setattr(movers, "_TABLE", 500)          # the rays x movers table in row blocks: the same
    blocks = _pairs(C, radius, owner, np.broadcast_to(o, D.shape), D, t_near, lim, excl)
    assert blocks[0].tolist() == grid[0].tolist() and blocks[1].tolist() == grid[1].tolist()


def test_origin_cull_keeps_movers_in_view_and_reach():
    """A camera at the origin looking along +x (half-angle 0.3 rad), segments up to 5 m: of spheres
    of radius 0.1 it keeps those within 0.3 + asin(0.1 / d) (+ 1e-3) of +x and nearer than 5.1 m,
    and any sphere holding the origin."""
    D = _frustum(21, 0.0, 0.3)
    th = math.acos(float((D @ _unit(D.sum(axis=0, keepdims=True))[0]).min()))
    C = np.array([[2.0, 0.0, 0.0],                     # straight ahead
                  [-2.0, 0.0, 0.0],                    # behind
                  [0.0, 2.0, 0.0],                     # to the side
                  [2.0, 2.0 * math.tan(th + math.asin(0.1 / 2.0 / math.cos(th)) * 0.5), 0.0],   # in the margin
                  [2.0, 2.0 * math.tan(th + 0.2), 0.0],   # just outside the cone
                  [5.05, 0.0, 0.0],                    # reachable: 5.05 - 0.1 < 5
                  [5.2, 0.0, 0.0],                     # out of reach
                  [0.05, 0.0, 0.0]])                   # holds the origin
    radius = np.full(len(C), 0.1)
    K, near, _, _ = movers._origin_cull(C, radius, radius ** 2, np.zeros(3), D, 5.0)
    assert K.tolist() == [0, 3, 5, 7]
    assert near.tolist() == [False, False, False, True]


def test_swarm_cameras_see_as_with_an_origin_array(tmp_path):
    """Every camera of a 30-robot swarm: its cast from one origin gives the bits of the same rays
    given an origin per ray (the grid lookup), distances, normals and shape ids."""
    sim = Simulation(load_world(str(write_swarm(30, tmp_path / "swarm.wbt"))))
    cams = [d for d in sim.all_devices() if d.kind == "Camera"]
    assert len(cams) == 30
    cams[0].enable(32)
    sim.step()      # builds the engine's tiers
    engine = cams[0]._scene.engine
    rng = np.random.default_rng(5)
    hits = 0
    for cam in cams:
        pose = cam.world_pose(cam._robot.pose)
        D = _unit(_frustum(40, 0.0, 0.42) @ np.asarray(pose.rotation).T)
        O = np.broadcast_to(np.asarray(pose.translation, dtype=np.float64), D.shape)
        far = rng.choice([2.0, np.inf])
        a = engine.cast(O, D, 0.005, far, kind=RayKind.VISUAL)
        b = engine.cast(np.array(O), D, 0.005, far, kind=RayKind.VISUAL)
        assert a.distance.tobytes() == b.distance.tobytes()
        assert a.normal.tobytes() == b.normal.tobytes() and a.shape.tobytes() == b.shape.tobytes()
        hits += int(np.isfinite(a.distance).sum())
    assert hits > 10000


@pytest.mark.parametrize("far", [2.0, np.inf])
def test_swarm_cameras_on_their_bodies_see_as_with_an_origin_array(tmp_path, monkeypatch, far):
    """Cameras with shapes of their own (Webots' e-puck's has its housing) cast mounted on their
    robot's body; unbounded (far 0 in the world file) their rays take the per-cast mounted broad
    phase, which pairs a one-origin batch with the body's neighbours in view: the bits of the same
    rays given an origin per ray (every neighbour a candidate of every ray)."""
    sim = Simulation(load_world(str(write_swarm(30, tmp_path / "swarm.wbt", housing=True))))
    cams = [d for d in sim.all_devices() if d.kind == "Camera"]
    cams[0].enable(32)
    sim.step()
    engine = cams[0]._scene.engine
    seen = []
    real = movers._origin_candidates
    monkeypatch.setattr(movers, "_origin_candidates", lambda *a: seen.append(1) or real(*a))
    hits = paired = 0
    for cam in cams:
        body = cam._scene.device_body(cam.robot_index, cam.on_joint)
        assert body is not None
        pose = cam.world_pose(cam._robot.pose)
        D = _unit(_frustum(40, 0.0, 0.42) @ np.asarray(pose.rotation).T)
        O = np.broadcast_to(np.asarray(pose.translation, dtype=np.float64), D.shape)
        mount = np.full(len(D), body)
        del seen[:]
        a = engine.cast(O, D, 0.005, far, kind=RayKind.VISUAL, mount=mount)
        paired += bool(seen)        # the one-origin pairing ran (not for a camera facing a near wall: few neighbours)
        b = engine.cast(np.array(O), D, 0.005, far, kind=RayKind.VISUAL, mount=mount)
        assert a.distance.tobytes() == b.distance.tobytes()
        assert a.normal.tobytes() == b.normal.tobytes() and a.shape.tobytes() == b.shape.tobytes()
        hits += int(np.isfinite(a.distance).sum())
    assert hits > 10000 and paired >= 20


def test_swarm_cameras_kept_mounts_skip_neighbours_out_of_view(tmp_path, monkeypatch):
    """A bounded camera with shapes of its own casts with a kept Mount (the lidar's one-origin
    pairing: every neighbour's cone tested per cast); the neighbours out of the camera's view are
    skipped, with the same bits as testing all of them."""
    from sensorium.server.raycast.engine import Mount

    sim = Simulation(load_world(str(write_swarm(30, tmp_path / "swarm.wbt", housing=True))))
    cams = [d for d in sim.all_devices() if d.kind == "Camera"]
    cams[0].enable(32)
    sim.step()
    engine = cams[0]._scene.engine
    real = movers._among
    skipped = []

    def spy(C, *a):
        got = real(C, *a)
        skipped.append(0 if got is None else len(C) - len(got))
        return got

    hits = 0
    for cam in cams:
        body = cam._scene.device_body(cam.robot_index, cam.on_joint)
        pose = cam.world_pose(cam._robot.pose)
        D = _unit(_frustum(40, 0.0, 0.42) @ np.asarray(pose.rotation).T)
        O = np.broadcast_to(np.asarray(pose.translation, dtype=np.float64), D.shape)
        monkeypatch.setattr(movers, "_among", spy)
        a = engine.cast(O, D, 0.005, 2.0, kind=RayKind.VISUAL, mount=Mount(np.full(len(D), body)))
        monkeypatch.setattr(movers, "_among", lambda *a: None)
        b = engine.cast(O, D, 0.005, 2.0, kind=RayKind.VISUAL, mount=Mount(np.full(len(D), body)))
        assert a.distance.tobytes() == b.distance.tobytes()
        assert a.normal.tobytes() == b.normal.tobytes() and a.shape.tobytes() == b.shape.tobytes()
        hits += int(np.isfinite(a.distance).sum())
    assert hits > 10000
    assert sum(skipped) > 10 * len(cams)     # most neighbours are out of a 0.84 rad view


def test_work_scan_counts_as_the_walk_with_paths(tmp_path):
    """Loading checks every value of the world once: the scan without paths counts the triangles and
    lights the walk with paths counts, and a number out of bounds is still named by its path."""
    from sensorium.schemas.world import Mesh
    from sensorium.server.world import limits as lim

    loaded = load_world(str(write_swarm(6, tmp_path / "swarm.wbt", housing=True)))
    world, limits = loaded.world, lim.WorldLimits()
    problems: list = []
    walked = lim._walk_work(world, limits, lambda g: 0, problems)
    assert lim._scan_work(world, limits, lambda g: 0) == walked and not problems
    assert walked[0] > 6 * 100 and walked[1] >= 1          # the robots' triangles; the PointLight
    assert not lim.has_model(world, Mesh)
    pose = world.robots[3].pose
    object.__setattr__(pose, "translation", (pose.translation[0], float("nan"), pose.translation[2]))
    assert lim._scan_work(world, limits, lambda g: 0) is None
    found = lim.check_work(world, limits, lambda g: 0)
    assert found == [("robots[3].pose.translation[1]", "expected a finite number, got nan")]


def test_enclosing_shapes_judges_rotated_shapes_after_the_distance_test():
    """Loading says which device sits inside one of its robot's closed shapes (a robot's shapes times
    its devices, so most pairs are ruled out by distance before any rotation is made): a box 10 cm
    long turned a quarter turn about z holds (0, 0.045, 0) and not (0.045, 0, 0); a sphere of radius
    0.02 holds a point 0.0199 from its centre along a diagonal and not one 0.0201 away."""
    from sensorium.server.world.wbt.inside import enclosing_shapes

    box = {"geometry": {"type": "box", "size": [0.1, 0.02, 0.02]},
           "pose": {"translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 1.0, math.pi / 2]}}
    ball = {"geometry": {"type": "sphere", "radius": 0.02}, "pose": {"translation": [1.0, 1.0, 1.0]}}
    robot = {"shapes": [box, ball]}

    def inside(x, y, z):
        dev = {"device": "Camera", "name": "c", "near": 0.0, "pose": {"translation": [x, y, z]}}
        return [p["geometry"]["type"] for p in enclosing_shapes(robot, dev)]

    s = 0.0199 / math.sqrt(3.0)
    t = 0.0201 / math.sqrt(3.0)
    assert inside(0.0, 0.045, 0.0) == ["box"]
    assert inside(0.045, 0.0, 0.0) == []
    assert inside(1.0 + s, 1.0 + s, 1.0 - s) == ["sphere"]
    assert inside(1.0 + t, 1.0 + t, 1.0 - t) == []
