"""Driven robots ride terrains (sim/ground.py): the clearance they start with above the ElevationGrid
under their origin, the attitude of the triangle under them, in closed form; what every consumer
of the pose reads; edges and grid points; robots that never meet a terrain unchanged, bit for bit."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from sensorium.server.sim import ground as gmod
from sensorium.server.sim.ground import GroundWarning
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

SLOPE = 0.25          # dz/dx of the test ramp
DX = 0.5
CLEAR = 0.05          # the robots' clearance
DRIVE = {"wheel_radius": 0.1, "axle_length": 0.3, "max_wheel_speed": 20.0}


def _ramp(nx: int = 9, ny: int = 9, x0: float = 0.0, y0: float = -2.0, gx: float = SLOPE, gy: float = 0.0,
          z0: float = 0.0) -> dict:
    """A grid whose points lie on the plane z = z0 + gx·(x − x0) + gy·(y − y0) (world axes)."""
    heights = [z0 + gx * i * DX + gy * j * DX for j in range(ny) for i in range(nx)]
    return {"name": "ramp", "pose": {"translation": [x0, y0, 0.0]},
            "geometry": {"type": "elevation_grid", "height": heights, "x_dimension": nx, "x_spacing": DX,
                         "y_dimension": ny, "y_spacing": DX}}


FLOOR = {"name": "floor", "geometry": {"type": "plane"}}


def _sim(solids: list[dict], at=(0.5, 0.0), z: float | None = None, yaw: float = 0.0, devices=(), **extra) -> Simulation:
    robot = {"name": "r", "pose": {"translation": [at[0], at[1], CLEAR if z is None else z],
                                   "rotation": [0, 0, 1, yaw]},
             "differential_drive": DRIVE, "devices": list(devices), **extra}
    return Simulation(parse_world({"solids": solids, "robots": [robot]}), precision="exact")


def _drive(sim: Simulation, left: float, right: float, robot: str = "r") -> None:
    r = sim.robot(robot)
    for m in r.drive.lefts:
        m.set_position(math.inf)
        m.set_velocity(left)
    for m in r.drive.rights:
        m.set_position(math.inf)
        m.set_velocity(right)


def _attitude(gx: float, gy: float, yaw: float) -> np.ndarray:
    """The closed-form rotation on a plane of slope (gx, gy) heading yaw: forward in the plane above
    the heading, up its normal."""
    f = np.array([math.cos(yaw), math.sin(yaw), gx * math.cos(yaw) + gy * math.sin(yaw)])
    f /= np.linalg.norm(f)
    n = np.array([-gx, -gy, 1.0]) / math.sqrt(gx * gx + gy * gy + 1.0)
    return np.column_stack([f, np.cross(n, f), n])


# ---------------------------------------------------------------------- closed forms

def test_a_robot_driving_up_a_uniform_slope_rises_with_it_and_takes_its_attitude() -> None:
    """Straight up the ramp: after every step z = z_start + slope·Δx (1e-12), the rotation is the
    slope's (pitch −atan(slope), 1e-12), and the IMU, GPS, Supervisor velocity read that pose."""
    z_start = SLOPE * 0.5 + CLEAR
    sim = _sim([_ramp()], z=z_start, devices=[{"device": "InertialUnit", "name": "imu"}, {"device": "GPS", "name": "gps"}])
    r = sim.robot("r")
    assert r.pose.translation[2] == z_start and r.drive.rest == SLOPE * 0.5    # placed: its height kept
    imu, gps = r.device("imu"), r.device("gps")
    imu.enable(32)
    gps.enable(32)
    _drive(sim, 20.0, 20.0)
    want = _attitude(SLOPE, 0.0, 0.0)
    for _ in range(40):
        sim.step()
        p = r.pose
        assert abs(p.translation[2] - (z_start + SLOPE * (p.translation[0] - 0.5))) <= 1e-12
        assert np.abs(p.rotation - want).max() <= 1e-12
        assert np.abs(imu.roll_pitch_yaw - [0.0, -math.atan(SLOPE), 0.0]).max() <= 1e-12
        assert np.array_equal(gps.values, p.translation)
    # 2 m/s along the slope for 40 steps of 32 ms: 2.56 m along it, 2.56·cos(atan(slope)) along x
    cos = 1.0 / math.sqrt(1.0 + SLOPE * SLOPE)
    assert p.translation[0] == pytest.approx(0.5 + 2.56 * cos, abs=1e-12)
    vel = r.drive.velocity()                                         # the Supervisor's getVelocity
    assert np.abs(np.array(vel) - [2.0 * cos, 0.0, 2.0 * cos * SLOPE, 0.0, 0.0, 0.0]).max() <= 1e-12


@pytest.mark.parametrize("yaw", [0.7, -2.3])
def test_across_a_skewed_slope_the_yaw_stays_the_drives_and_up_is_the_normal(yaw: float) -> None:
    """A plane sloping along x and y, a robot driving a curve on it: its up axis is the normal, its
    forward axis lies in the plane above its heading (the InertialUnit's yaw is the drive's), its
    height the plane's plus the clearance; the Supervisor's angular velocity is about the normal."""
    gx, gy = 0.2, -0.15
    sim = _sim([_ramp(nx=13, ny=13, x0=-3.0, y0=-3.0, gx=gx, gy=gy, z0=1.0)], at=(0.0, 0.0), yaw=yaw,
               devices=[{"device": "InertialUnit", "name": "imu"}])
    r = sim.robot("r")
    imu = r.device("imu")
    imu.enable(32)
    plane = lambda x, y: 1.0 + gx * (x + 3.0) + gy * (y + 3.0)   # noqa: E731
    assert r.pose.translation[2] == CLEAR
    assert np.abs(r.pose.rotation - _attitude(gx, gy, yaw)).max() <= 1e-12   # set on the slope when placed
    _drive(sim, 3.0, 4.0)
    for _ in range(30):
        yaw0 = r.drive.yaw
        sim.step()
        p = r.pose
        assert abs(p.translation[2] - (plane(*p.translation[:2]) - plane(0.0, 0.0) + CLEAR)) <= 1e-12
        assert np.abs(p.rotation - _attitude(gx, gy, r.drive.yaw)).max() <= 1e-12
        assert abs(imu.roll_pitch_yaw[2] - r.drive.yaw) <= 1e-12
    # the wheels turn it at 1/3 rad/s about the normal: its yaw at that times (1 + k0²)/|(-gx, -gy, 1)|
    # (k0 the slope along the heading the step started with), reported about the normal again
    turn = 0.1 * (4.0 - 3.0) / 0.3
    k0 = gx * math.cos(yaw0) + gy * math.sin(yaw0)
    yaw_rate = turn * (1.0 + k0 * k0) / math.sqrt(1.0 + gx * gx + gy * gy)
    k = gx * math.cos(r.drive.yaw) + gy * math.sin(r.drive.yaw)
    ang = np.array(r.drive.velocity()[3:])
    assert np.abs(ang - yaw_rate * np.array([-gx, -gy, 1.0]) / (1.0 + k * k)).max() <= 1e-12


def test_a_distance_sensor_on_the_slope_reads_a_wall_at_the_analytic_distance() -> None:
    """A sensor looking forward from a robot on the ramp: its beam climbs with the slope, so a
    vertical wall x = X is read at (X − x_sensor)·√(1 + slope²) (1e-12)."""
    wall_x = 3.7
    wall = {"name": "wall", "pose": {"translation": [wall_x + 0.05, 0.0, 1.0]},
            "geometry": {"type": "box", "size": [0.1, 4.0, 4.0]}}
    mount = np.array([0.06, 0.0, 0.04])
    sensor = {"device": "DistanceSensor", "name": "d", "pose": {"translation": mount.tolist()},
              "lookup_table": [[0, 0, 0], [10, 10, 0]]}
    sim = _sim([_ramp(), wall], z=SLOPE * 0.5 + CLEAR, devices=[sensor])
    r = sim.robot("r")
    d = r.device("d")
    d.enable(32)
    _drive(sim, 20.0, 20.0)
    seen = 0
    for _ in range(30):
        sim.step()
        p = r.pose
        sx = (p.translation + p.rotation @ mount)[0]
        assert abs(d.value - (wall_x - sx) * math.sqrt(1.0 + SLOPE * SLOPE)) <= 1e-12
        seen += 1
    assert seen and sx > 2.0
    # upright (the old behaviour) the reading would be wall_x - sx: the two differ
    assert (wall_x - sx) * (math.sqrt(1.0 + SLOPE * SLOPE) - 1.0) > 1e-2


def test_a_robot_crossing_from_the_floor_onto_a_grid_climbs_it_and_comes_back_down() -> None:
    """A floor plane at 0 and a ramp starting at x = 0 at height 0: off the grid the robot keeps its
    exact start height, upright; on it, z = slope·x + clearance with the slope's attitude; driven
    back off it, it is at its start height again, upright, bit for bit."""
    sim = _sim([FLOOR, _ramp(nx=5)], at=(-0.6, 0.0))
    r = sim.robot("r")
    start = r.pose
    _drive(sim, 20.0, 20.0)
    on = off = 0
    for _ in range(50):
        sim.step()
        p = r.pose
        if p.translation[0] <= 0.0:
            assert p.translation[2] == CLEAR and np.array_equal(p.rotation, start.rotation)
            off += 1
        elif p.translation[0] < 2.0:
            assert abs(p.translation[2] - (SLOPE * p.translation[0] + CLEAR)) <= 1e-12
            assert np.abs(p.rotation - _attitude(SLOPE, 0.0, 0.0)).max() <= 1e-12
            on += 1
        else:                                   # past the grid's far edge: the floor again
            assert p.translation[2] == CLEAR
    assert on > 20 and off > 3 and r.pose.translation[0] > 2.0
    _drive(sim, -20.0, -20.0)
    for _ in range(60):
        sim.step()
    assert r.pose.translation[0] < 0.0
    assert r.pose.translation[2] == CLEAR and np.array_equal(r.pose.rotation, start.rotation)


def test_across_a_ridge_the_attitude_switches_between_the_two_planes() -> None:
    """A ridge along y at x = 1 (up 0.3 before it, down 0.2 after): the robot has one plane's
    attitude before the crest, the other's past it (exactly on it: the +x side's), and its height
    follows both planes."""
    up, down = 0.3, -0.2
    heights = [(up * i * DX if i <= 2 else up * 2 * DX + down * (i - 2) * DX) for j in range(5) for i in range(5)]
    grid = {"name": "ridge", "pose": {"translation": [0.0, -1.0, 0.0]},
            "geometry": {"type": "elevation_grid", "height": heights, "x_dimension": 5, "x_spacing": DX,
                         "y_dimension": 5, "y_spacing": DX}}
    sim = _sim([grid], at=(0.2, 0.0), z=up * 0.2 + CLEAR)
    r = sim.robot("r")
    _drive(sim, 20.0, 20.0)
    sides = set()
    for _ in range(30):
        sim.step()
        x, _, z = r.pose.translation
        if x >= 2.0:
            break
        slope = up if x < 1.0 else down
        crest = up * 1.0
        assert abs(z - (crest + slope * (x - 1.0) + CLEAR)) <= 1e-12
        assert np.abs(r.pose.rotation - _attitude(slope, 0.0, 0.0)).max() <= 1e-12
        sides.add(slope)
    assert sides == {up, down}
    # exactly on the crest: the +x side's plane
    r.set_pose(translation=[1.0, 0.0, 0.5])
    assert np.abs(r.pose.rotation - _attitude(down, 0.0, 0.0)).max() <= 1e-12


# ---------------------------------------------------------------------- edges and grid points

def _random_grid(seed: int = 3, nx: int = 7, ny: int = 5) -> gmod._Grid:
    rng = np.random.default_rng(seed)
    xs = np.arange(nx, dtype=np.float64) * 0.3
    ys = np.arange(ny, dtype=np.float64) * 0.7
    return gmod._Grid(xs, ys, rng.uniform(-1.0, 1.0, (ny, nx)))


def _on_diagonal(x0: float, x1: float, y0: float, y1: float, a: float) -> tuple[np.ndarray, np.ndarray] | None:
    """A point near ``a`` along a cell's diagonal whose cell coordinates are exactly equal, s == t
    (stepping u by ulps around it), or None."""
    v = np.array([y0 + a * (y1 - y0)])
    t = (v - y0) / (y1 - y0)
    u = x0 + t * (x1 - x0)
    for step in range(-8, 9):
        w = u + step * np.spacing(u)
        if ((w - x0) / (x1 - x0))[0] == t[0]:
            return w, v
    return None


def test_both_triangles_give_the_same_height_on_every_shared_edge_bit_for_bit() -> None:
    """Points on cell diagonals, on cell edges and at grid points: asked of the triangle on either
    side (within a cell, and of the neighbouring cell), the height is the same bits; at a grid point
    it is that point's height exactly; the plane of a triangle is what the rays' vertices span."""
    g = _random_grid()
    rng = np.random.default_rng(4)
    nx, ny = len(g.xs), len(g.ys)
    diagonal = 0
    for _ in range(300):
        i, j = int(rng.integers(0, nx - 1)), int(rng.integers(0, ny - 1))
        a = rng.uniform(0.0, 1.0)
        x0, x1, y0, y1 = g.xs[i], g.xs[i + 1], g.ys[j], g.ys[j + 1]
        ii, jj = np.array([i]), np.array([j])
        # the diagonal, exactly (s == t in the cell's own coordinates)
        point = _on_diagonal(x0, x1, y0, y1, a)
        if point is not None:
            u, v = point
            lo = gmod.triangle_height(g, ii, jj, np.array([True]), u, v)[0]
            hi = gmod.triangle_height(g, ii, jj, np.array([False]), u, v)[0]
            assert lo.tobytes() == hi.tobytes()
            diagonal += 1
        # a vertical edge x = xs[i+1] shared with cell i+1 (when there is one)
        if i + 1 < nx - 1:
            u, v = np.array([x1]), np.array([y0 + a * (y1 - y0)])
            mine = gmod.triangle_height(g, ii, jj, np.array([True]), u, v)[0]        # s = 1: lower
            theirs = gmod.triangle_height(g, ii + 1, jj, np.array([False]), u, v)[0]  # s = 0: upper
            assert mine.tobytes() == theirs.tobytes()
            assert gmod.grid_height(g, u, v)[0].tobytes() == theirs.tobytes()
        # a horizontal edge y = ys[j+1] shared with cell j+1
        if j + 1 < ny - 1:
            u, v = np.array([x0 + a * (x1 - x0)]), np.array([y1])
            mine = gmod.triangle_height(g, ii, jj, np.array([False]), u, v)[0]        # t = 1: upper
            theirs = gmod.triangle_height(g, ii, jj + 1, np.array([True]), u, v)[0]   # t = 0: lower
            assert mine.tobytes() == theirs.tobytes()
    assert diagonal > 50
    # every grid point: its own height, exactly, from every triangle that has it for a corner
    for j in range(ny):
        for i in range(nx):
            u, v = np.array([g.xs[i]]), np.array([g.ys[j]])
            assert gmod.grid_height(g, u, v)[0][0] == g.heights[j, i]
            around = [(i, j, True), (i, j, False), (i - 1, j, True), (i, j - 1, False), (i - 1, j - 1, True),
                      (i - 1, j - 1, False)]
            asked = 0
            for ci, cj, lower in around:
                if 0 <= ci < nx - 1 and 0 <= cj < ny - 1:
                    h = gmod.triangle_height(g, np.array([ci]), np.array([cj]), np.array([lower]), u, v)[0]
                    assert h[0] == g.heights[j, i], (i, j, ci, cj, lower)
                    asked += 1
            assert asked >= 1


def test_off_the_grid_there_is_no_terrain_and_its_closed_extent_is_in() -> None:
    """The ground covers the grid's closed extent exactly: its far edges and corners are on it (the
    last cell), a hair outside is nothing (no floor in this world)."""
    sim = _sim([_ramp(nx=3, ny=3, x0=1.0, y0=2.0)], at=(1.5, 2.5))
    ground = sim.ground
    assert ground is not None
    W = 2 * DX
    for x, y in ((1.0, 2.0), (1.0 + W, 2.0 + W), (1.0 + W, 2.3), (1.2, 2.0 + W)):
        got = ground.at(x, y)
        assert got is not None and abs(got[0] - SLOPE * (x - 1.0)) <= 1e-15 and got[1:] == (SLOPE, 0.0)
    for x, y in ((1.0 - 1e-12, 2.5), (1.0 + W + 1e-12, 2.5), (1.5, 2.0 - 1e-12), (1.5, 2.0 + W + 1e-12)):
        assert ground.at(x, y) is None


def test_off_the_grid_over_nothing_a_robot_keeps_its_height_upright() -> None:
    """No floor: driving off the ramp's top edge, the robot keeps the height it left with (no
    physics: it does not fall), upright, and drives on level."""
    sim = _sim([_ramp(nx=3)], at=(0.3, 0.0), z=SLOPE * 0.3 + CLEAR)
    r = sim.robot("r")
    _drive(sim, 20.0, 20.0)
    top = None
    for _ in range(30):
        sim.step()
        x, _, z = r.pose.translation
        if x > 2 * DX:
            top = top if top is not None else z
            assert z == top and abs(z - (SLOPE * 2 * DX + CLEAR)) <= 0.064 * SLOPE   # within a step's rise
            assert np.array_equal(r.pose.rotation, np.eye(3))
    assert top is not None


# ---------------------------------------------------------------------- unchanged without terrain

def _run(solids: list[dict], at=(-3.0, 0.5), steps: int = 60, **extra) -> list[tuple[bytes, bytes]]:
    sim = _sim(solids, at=at, devices=[{"device": "DistanceSensor", "name": "d"}], **extra)
    sim.device("r/d").enable(32)
    out = []
    for k in range(steps):
        if k % 10 == 0:
            _drive(sim, 3.0 + k / 10.0, 4.0 - k / 20.0)
        sim.step()
        p = sim.robot("r").pose
        out.append((p.rotation.tobytes(), p.translation.tobytes(), np.float64(sim.device("r/d").value).tobytes()))
    return out


def test_a_robot_that_never_meets_the_terrain_is_unchanged_bit_for_bit() -> None:
    """The same robot, commands and sensor in a world with a ramp far away and without it: on a
    floor plane, and with no floor at all (there it starts over nothing: a GroundWarning says it
    keeps its height), every pose and reading is the same bits."""
    far = _ramp(x0=40.0, y0=40.0)
    box = {"name": "box", "pose": {"translation": [-1.0, 2.0, 0.2]}, "geometry": {"type": "box", "size": [0.4, 0.4, 0.4]}}
    assert _run([FLOOR, box, far]) == _run([FLOOR, box])
    with pytest.warns(GroundWarning, match=r"robot 'r' starts over no ground .* it keeps its height"):
        with_terrain = _run([box, far])
    assert with_terrain == _run([box])


def test_a_world_without_terrains_has_no_ground() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim = _sim([FLOOR])
    assert sim.ground is None and sim.robot("r").drive.ground is None


# ---------------------------------------------------------------------- placing and moving

def test_supervisor_moves_on_a_slope_keep_the_clearance_and_never_tilt_twice() -> None:
    """set_pose of the translation alone on the slope: the robot keeps its own (upright) rotation,
    the ground's attitude over it once; the height set is its new clearance's base; a reset puts it
    back where the world file placed it, pose and riding."""
    sim = _sim([_ramp()], z=SLOPE * 0.5 + CLEAR, devices=[{"device": "InertialUnit", "name": "imu"}])
    r = sim.robot("r")
    placed = r.pose
    _drive(sim, 5.0, 5.0)
    sim.run(10)
    r.set_pose(translation=[2.0, 0.5, 1.0])
    assert np.array_equal(r.pose.translation, [2.0, 0.5, 1.0])
    assert np.abs(r.pose.rotation - _attitude(SLOPE, 0.0, 0.0)).max() <= 1e-12
    sim.step()
    x = r.pose.translation[0]
    assert abs(r.pose.translation[2] - (1.0 + SLOPE * (x - 2.0))) <= 1e-12
    r.set_pose(translation=[2.0, 0.5, 1.0], rotation=[0, 0, 1, math.pi / 2])
    assert np.abs(r.pose.rotation - _attitude(SLOPE, 0.0, math.pi / 2)).max() <= 1e-12
    sim.reset()
    assert r.pose.rotation.tobytes() == placed.rotation.tobytes()
    assert r.pose.translation.tobytes() == placed.translation.tobytes()


def test_a_moved_terrain_carries_the_robot_from_its_next_move_and_a_removed_one_no_longer() -> None:
    sim = _sim([FLOOR, _ramp()], at=(1.0, 0.0), z=SLOPE * 1.0 + CLEAR)
    r = sim.robot("r")
    sim.set_solid_pose("ramp", [0.0, -2.0, 0.5])          # lifted 0.5 m
    _drive(sim, 2.0, 2.0)
    sim.step()
    x = r.pose.translation[0]
    assert abs(r.pose.translation[2] - (0.5 + SLOPE * x + CLEAR)) <= 1e-12
    sim.remove_solid("ramp")
    sim.step()
    assert abs(r.pose.translation[2] - CLEAR) <= 1e-15 and np.array_equal(r.pose.rotation, np.eye(3))   # the floor


def test_a_tilted_terrain_is_not_ground_and_says_so() -> None:
    ramp = _ramp()
    ramp["pose"]["rotation"] = [1, 0, 0, 0.3]
    with pytest.warns(GroundWarning, match=r"solid 'ramp': its ElevationGrid is tilted"):
        sim = _sim([FLOOR, ramp])
    assert sim.ground is not None and sim.ground.tilted_terrains() == ["ramp"]


def test_a_grid_turned_about_the_vertical_is_ridden_in_its_own_axes() -> None:
    """The ramp turned 90° about z: it rises along world +y; a robot heading +y climbs it."""
    ramp = _ramp(x0=2.0, y0=0.0)
    ramp["pose"]["rotation"] = [0, 0, 1, math.pi / 2]
    sim = _sim([ramp], at=(1.0, 0.5), yaw=math.pi / 2, z=SLOPE * 0.5 + CLEAR)
    r = sim.robot("r")
    _drive(sim, 4.0, 4.0)
    for _ in range(20):
        sim.step()
        x, y, z = r.pose.translation
        assert abs(z - (SLOPE * y + CLEAR)) <= 1e-12
        assert np.abs(r.pose.rotation - _attitude(0.0, SLOPE, r.drive.yaw)).max() <= 1e-12


def test_a_terrain_a_supervisor_imports_is_seen_but_not_ridden() -> None:
    """importMFNodeFromString adds an ElevationGrid that rays see, but the ground is the world file's:
    a robot driving over the imported ramp keeps its height, upright (README, Riding terrains)."""
    sim = _sim([FLOOR], at=(-0.5, 0.0))
    heights = " ".join(str(SLOPE * i * DX) for j in range(5) for i in range(5))
    sim.import_nodes(f"Solid {{ name \"ramp\" translation 0 -1 0 children [ Shape {{ geometry ElevationGrid {{ "
                     f"xDimension 5 xSpacing {DX} yDimension 5 ySpacing {DX} height [ {heights} ] }} }} ] "
                     f"boundingObject ElevationGrid {{ xDimension 5 xSpacing {DX} yDimension 5 ySpacing {DX} "
                     f"height [ {heights} ] }} }}")
    down = sim.scene.engine.cast(np.array([[1.0, 0.0, 5.0]]), np.array([[0.0, 0.0, -1.0]]))
    assert math.isclose(float(down.distance[0]), 5.0 - SLOPE * 1.0, rel_tol=0, abs_tol=1e-9)   # the ramp is there
    before = sim.robot("r").pose
    _drive(sim, 5.0, 5.0)
    sim.run(100)
    after = sim.robot("r").pose
    assert after.translation[0] > 1.0                     # it drove onto the ramp ...
    assert after.translation[2] == before.translation[2]  # ... and kept its height
    np.testing.assert_array_equal(after.rotation, before.rotation)
