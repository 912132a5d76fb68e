"""The lean lidar pipeline gives the general paths' answers bit for bit: the analytic floor under a
lidar, float32 directions kept by the caller, the world beams a fixed lidar keeps while it does not
turn, the float32-first range rule, point coordinates in blocks, point records made on read and
the point-cloud message built from coordinates."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
from _lidar_room import lidar_room

from sensorium.schemas.wire import pack
from sensorium.server.daemon.topics import header, lidar_cloud_msg, point_cloud_msg
from sensorium.server.devices import lidar as lmath
from sensorium.server.raycast import planes as planes_module
from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.sim.sensors import _rotate_columns
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.geometry import Box, Cylinder, Plane, Pose, Sphere
from sensorium.server.world.loader import parse_world

_FLIP_X = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])   # half turn about x: normal -z


def _floor_scene(floor_pose: Pose, precision=Precision.FAST) -> RayEngine:
    eng = RayEngine(precision)
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], floor_pose)
    eng.add_body([ShapeEntry(Box((0.6, 0.4, 1.0)), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([1.5, 0.3, 0.5])))
    eng.add_body([ShapeEntry(Sphere(0.4), Pose.identity(), True, True)], Pose(np.eye(3), np.array([-1.2, 0.8, 0.4])))
    eng.add_body([ShapeEntry(Cylinder(0.2, 1.5), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([0.4, -1.4, 0.75])))
    return eng


def _beams(origin, n_az=256, layers=(-0.7, -0.3, 0.0, 0.2, 0.6)):
    """A lidar fan; the 0.0 layer is exactly horizontal (its z components are exact zeros)."""
    az = np.linspace(-math.pi, math.pi, n_az, endpoint=False)
    el = np.array(layers)
    A, E = np.meshgrid(az, el)
    D = np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], axis=-1).reshape(-1, 3)
    return np.broadcast_to(np.asarray(origin, dtype=np.float64), D.shape), D


@pytest.mark.parametrize("origin", [(0.1, 0.2, 0.9), (0.1, 0.2, 0.0), (0.1, 0.2, -0.5), (0.3, 0.1, 2.5)])
@pytest.mark.parametrize("floor", ["up", "down", "shifted"])
def test_floor_under_a_lidar_gives_the_general_plane_answer(origin, floor):
    """Above, on and below a one-sided floor, a ceiling (normal -z) and a raised floor: the lean
    floor path returns exactly the distances of the general plane pass, with scalar and per-ray
    limits and a t_near."""
    pose = {"up": Pose.identity(), "down": Pose(_FLIP_X, np.array([0.0, 0.0, 2.0])),
            "shifted": Pose(np.eye(3), np.array([0.0, 0.0, 0.25]))}[floor]
    eng = _floor_scene(pose)
    O, D = _beams(origin)
    rng = np.random.default_rng(3)
    seen_plane = False
    for t_near, t_far in ((0.0, np.inf), (0.05, 6.0), (0.0, rng.uniform(0.5, 8.0, len(D)))):
        pl = eng._plane_set("visual")
        assert pl is not None
        eng.cast(O[:1], D[:1], kind=RayKind.VISUAL)   # refreshes the plane data
        with np.errstate(divide="ignore", invalid="ignore"):   # as inside RayEngine.cast
            lean = planes_module.cast_planes(pl, eng._epoch, O, D, t_near, t_far, -1, 1e-9, True)
            axis, pl.axis = pl.axis, -1              # the general pass on the same data
            try:
                general = planes_module.cast_planes(pl, eng._epoch, O, D, t_near, t_far, -1, 1e-9, True)
            finally:
                pl.axis = axis
        assert axis == 2
        if general is None:
            assert lean is None or not np.isfinite(lean[0]).any()
            continue
        seen_plane = True
        assert lean[0].tobytes() == general[0].tobytes()
        # and through the whole engine: distances only (lean) == the full cast
        full = eng.cast(np.ascontiguousarray(O), D, t_near, t_far, kind=RayKind.VISUAL)
        fast = eng.cast(O, D, t_near, t_far, kind=RayKind.VISUAL, distance_only=True)
        assert fast.distance.tobytes() == full.distance.tobytes()
    # the plane is seen only from its front side: above a floor, below the ceiling
    assert seen_plane == {"up": origin[2] > 0.0, "down": origin[2] < 2.0, "shifted": origin[2] > 0.25}[floor]


@pytest.mark.parametrize("yaw", [0.0, 0.3])
def test_sized_floor_under_a_lidar_gives_the_general_plane_answer(yaw):
    """A sized floor (the arena's 4 m x 4 m, its sides along world axes): the lean path tests the
    size on the two horizontal coordinates alone, with the general pass's values bit for bit
    (beams that leave the floor miss it); turned by 0.3 rad it is not along world axes and takes
    the general pass."""
    eng = RayEngine(Precision.FAST)
    eng.add_body([ShapeEntry(Plane((4.0, 3.0)), Pose.identity(), True, True)],
                 Pose.from_axis_angle((0, 0, 1), yaw, [0.3, -0.2, 0.0]))
    O, D = _beams((0.6, 0.4, 0.15), n_az=720, layers=(-0.3, -0.1, -0.05, -0.02, 0.0))
    eng.cast(O[:1], D[:1], kind=RayKind.VISUAL)
    pl = eng._plane_set("visual")
    assert (pl.size_axes is not None) == (yaw != 0.3)
    for t_far in (6.0, 40.0):
        with np.errstate(divide="ignore", invalid="ignore"):
            lean = planes_module.cast_planes(pl, eng._epoch, O, D, 0.02, t_far, -1, 1e-9, True)
            axis, pl.axis = pl.axis, -1
            try:
                general = planes_module.cast_planes(pl, eng._epoch, O, D, 0.02, t_far, -1, 1e-9, True)
            finally:
                pl.axis = axis
        assert lean[0].tobytes() == general[0].tobytes()
        hit = np.isfinite(general[0])
        assert 0 < hit.sum() < len(D) * 0.8          # some beams leave the floor before reaching it
        full = eng.cast(np.ascontiguousarray(O), D, 0.02, t_far, kind=RayKind.VISUAL)
        assert eng.cast(O, D, 0.02, t_far, kind=RayKind.VISUAL, distance_only=True).distance.tobytes() == \
            full.distance.tobytes()


def test_float32_directions_kept_by_the_caller():
    eng = _floor_scene(Pose.identity())
    O, D = _beams((0.1, 0.2, 0.9))
    ref = eng.cast(O, D, 0.02, 7.0, kind=RayKind.VISUAL, distance_only=True)
    kept = eng.cast(O, D, 0.02, 7.0, kind=RayKind.VISUAL, distance_only=True, directions32=D.astype(np.float32))
    assert np.isfinite(ref.distance).mean() > 0.4
    assert kept.distance.tobytes() == ref.distance.tobytes()
    for bad in (D, D.astype(np.float32)[:-1]):
        with pytest.raises(ValueError, match="directions32"):
            eng.cast(O, D, kind=RayKind.VISUAL, distance_only=True, directions32=bad)


def _lidar_world(**lidar) -> dict:
    return lidar_room({"horizontal_resolution": 180, "number_of_layers": 9, "vertical_field_of_view": 0.8,
                       "min_range": 0.05, "max_range": 6.0, **lidar}, wall_x=2.0)


def _reference_image(sim: Simulation, dev) -> np.ndarray:
    """The range image from scratch: beams rotated now, a full cast, the general range rule."""
    pose = dev.world_pose(sim.robots["r"].pose)
    D = lmath.ray_directions(dev.params).reshape(-1, 3) @ pose.rotation.T
    O = np.broadcast_to(pose.translation, D.shape)
    h = sim.scene.engine.cast(np.ascontiguousarray(O), D, dev.params.near, dev._t_far, kind=RayKind.VISUAL)
    L, W = dev.config.number_of_layers, dev.config.horizontal_resolution
    d = h.distance.reshape(L, W)
    lo, hi = dev.params.min_range, dev.params.max_range
    out = np.where(np.isfinite(d) & (d >= lo) & (d < hi), d, np.inf).astype(np.float32)
    out[out >= np.float32(hi)] = np.inf
    return out


def test_a_fixed_lidar_replans_only_when_it_turns():
    sim = Simulation(parse_world(_lidar_world()), precision="fast")
    dev = sim.device("r/l")
    dev.enable(sim.basic_time_step)
    robot = sim.robots["r"]
    seen = []
    for pose in (([0.0, 0.0, 0.05], [0, 0, 1, 0.0]), ([0.3, -0.2, 0.05], [0, 0, 1, 0.0]),   # moved, not turned
                 ([0.3, -0.2, 0.05], [0, 0, 1, 0.7]), ([0.3, -0.2, 0.05], [0, 0, 1, 0.7])):
        robot.set_pose(*pose)
        req = dev.plan(robot.pose, sim.time_ms, sim.basic_time_step)[0]
        seen.append(req)
        sim.step()
        assert dev.range_image.tobytes() == _reference_image(sim, dev).tobytes()
        assert np.isfinite(dev.range_image).mean() > 0.3
    assert seen[1].directions is seen[0].directions                # moving without turning: the same beams
    assert not np.array_equal(seen[1].origins[0], seen[0].origins[0])
    assert seen[2].directions is not seen[1].directions            # turned: new beams, rotated exactly
    assert seen[3].directions is seen[2].directions
    R = dev.world_pose(robot.pose).rotation
    assert seen[2].directions.tobytes() == _rotate_columns(R, dev._dir_columns).tobytes()
    assert seen[2].directions32.tobytes() == seen[2].directions.astype(np.float32).tobytes()
    assert not seen[2].directions.flags.writeable and not seen[2].directions32.flags.writeable


def _old_ranges(params, d, factors):
    """The range rule as first written (validity in float64, then the float32 cast)."""
    v = d * factors
    lo, hi = params.min_range, params.max_range
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(v) & (v >= lo) & (v < hi)
    out = np.where(valid, v, np.inf).astype(np.float32)
    out[out >= np.float32(hi)] = np.inf
    return out


@pytest.mark.parametrize("planar", [False, True])
def test_range_rule_rounding_first_is_the_same_rule(planar):
    p = lmath.LidarParams(horizontal_resolution=64, number_of_layers=4, field_of_view=1.2, min_range=0.3,
                          max_range=5.0, projection="planar" if planar else "cylindrical")
    dirs = lmath.ray_directions(p)
    factors = lmath.value_factors(p, dirs)
    rng = np.random.default_rng(11)
    hi32 = float(np.float32(5.0))
    edge = [0.0, 0.3, np.nextafter(0.3, 0), np.nextafter(0.3, 1), 5.0, np.nextafter(5.0, 0), hi32,
            np.nextafter(hi32, 0), np.nextafter(hi32, 10), 5.0 - 1e-9, 1e300, np.inf, 2.5]
    d = rng.uniform(0.0, 7.0, (4, 64))
    d.flat[:len(edge)] = edge
    if planar:   # distances whose depth lands exactly on the bounds
        d.flat[20:24] = np.array([0.3, 5.0, hi32, np.nextafter(5.0, 0)]) / factors.flat[20:24]
    got = lmath.ranges_from_hits(p, d, dirs, None)
    want = _old_ranges(p, d, factors)
    assert got.dtype == np.float32 and got.tobytes() == want.tobytes()
    assert np.isinf(got).any() and np.isfinite(got).any()


@pytest.mark.parametrize("n", [1, 1000, 16384, 16385, 50001])
def test_point_coordinates_in_blocks(n):
    rng = np.random.default_rng(n)
    r = rng.uniform(0.0, 30.0, n).astype(np.float32)
    r[rng.random(n) < 0.1] = np.inf
    cols = [rng.normal(size=n) for _ in range(3)]
    cols[2][:3] = 0.0                                      # inf x 0 = NaN, as in Webots
    got = lmath.point_xyz(r, cols)
    with np.errstate(invalid="ignore"):
        want = (r.astype(np.float64)[:, None] * np.stack(cols, 1)).astype(np.float32)
    assert got.shape == (n, 3) and got.tobytes() == want.tobytes()


@pytest.mark.parametrize("kw", [{}, {"projection": "planar", "field_of_view": 1.5}, {"tilt_angle": 0.15},
                                {"type": "rotating"}, {"noise": 0.01, "resolution": 0.01}])
def test_point_records_and_cloud_message_match_the_general_path(kw):
    """Records made on read equal lmath.point_cloud of the range image; the message built from the
    coordinates packs to the same bytes as the one built from the records (also before the first
    scan and while a rotating head has not swept every column)."""
    sim = Simulation(parse_world(_lidar_world(**kw)), precision="fast")
    dev = sim.device("r/l")
    dev.enable(3 * sim.basic_time_step)
    dev.enable_point_cloud()
    hdr = header("r/l", 0)
    assert pack(lidar_cloud_msg(hdr, dev)) == pack(point_cloud_msg(hdr, dev.point_cloud))   # all zeros
    for step in range(5):
        sim.robots["r"].set_pose([0.1 * step, 0.0, 0.05], [0, 0, 1, 0.3 * step])
        sim.step()
        msg = lidar_cloud_msg(hdr, dev)
        assert pack(msg) == pack(point_cloud_msg(hdr, dev.point_cloud))
        if dev.measurements and not dev.rotating:
            p = dev.params
            ref = lmath.point_cloud(p, dev.range_image, dev.measured_at_ms / 1000.0, dev.sampling_period / 1000.0)
            assert dev.point_cloud.tobytes() == ref.tobytes()
            assert np.isfinite(dev.point_cloud["x"]).mean() > 0.3
    assert dev.measurements >= 1


def test_counters_and_layers_channel():
    sim = Simulation(parse_world(_lidar_world()), precision="fast")
    dev = sim.device("r/l")
    dev.enable(sim.basic_time_step)
    dev.enable_point_cloud()
    sim.step()
    layers = np.frombuffer(lidar_cloud_msg(header("r/l", 0), dev)["channels"][0]["values"], dtype="<f4")
    assert layers.tolist() == np.repeat(np.arange(9), 180).astype(np.float32).tolist()
    counters: Counter = Counter()
    dev.finish([sim.scene.engine.cast(*_beams((0, 0, 0.45), n_az=180, layers=np.linspace(0.4, -0.4, 9)),
                                      kind=RayKind.VISUAL, distance_only=True)], 16, counters)
    assert counters["points_built"] == 9 * 180


@pytest.mark.parametrize("n", [1, 5000, 16384, 40001])
def test_beams_rotated_in_blocks_with_their_float32_copy(n):
    from sensorium.server.sim.sensors import _rotate

    rng = np.random.default_rng(n)
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    out32 = np.empty((n, 3), dtype=np.float32)
    got = _rotate_columns(R, tuple(np.ascontiguousarray(v[:, k]) for k in range(3)), out32=out32)
    assert got.tobytes() == _rotate(R, v).tobytes()
    assert out32.tobytes() == got.astype(np.float32).tobytes()


@pytest.mark.parametrize("kind", ["fixed", "rotating"])
def test_a_cloud_message_keeps_its_scan_after_the_next_one(kind):
    """The message's buffers are never overwritten by later scans (fixed: fresh coordinates per
    scan; rotating: the records are copied), so a message packed late carries its own scan."""
    sim = Simulation(parse_world(_lidar_world(type=kind)), precision="fast")
    dev = sim.device("r/l")
    dev.enable(sim.basic_time_step)
    dev.enable_point_cloud()
    sim.step()
    msg = lidar_cloud_msg(header("r/l", 0), dev)
    now = pack(msg)
    for step in range(3):
        sim.robots["r"].set_pose([0.2 * (step + 1), 0.1, 0.05], [0, 0, 1, 0.4 * (step + 1)])
        sim.step()
    assert pack(lidar_cloud_msg(header("r/l", 0), dev)) != now      # the scene changed ...
    assert pack(msg) == now                                           # ... the old message did not
