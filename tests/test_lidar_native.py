"""A fixed lidar's range image and point coordinates in one C pass (packets.c: sp_lidar_scan) give
lidar.py's ``ranges_from_hits`` and ``point_xyz`` bit for bit (``tobytes``: NaN points and signed
zeros included), on distances chosen where the range rule is delicate, on planar depth factors, in
blocks on two threads; and a simulated lidar gives the same image and cloud with and without the
helper."""

from __future__ import annotations

import numpy as np
import pytest
from _lidar_room import lidar_room

from sensorium.server.devices import lidar as lmath
from sensorium.server.raycast import packets
from sensorium.server.sim.simulation import Simulation
from sensorium.server.world.loader import parse_world

pytestmark = pytest.mark.skipif(packets.library() is None, reason=f"no packet path here: {packets.status()}")


def _delicate(n: int, lo: float, hi: float, rng) -> np.ndarray:
    """Distances around the rule's edges: misses, NaN, below, at and above min_range, float64
    values just below max_range that round up to float32(max_range), beyond float32, negatives."""
    hi32 = float(np.float32(hi))
    special = [np.inf, -np.inf, np.nan, 0.0, -0.0, -1.0, lo, np.nextafter(lo, 0.0), np.nextafter(lo, 1.0), hi,
               np.nextafter(hi, 0.0), hi32, np.nextafter(hi32, 0.0), np.nextafter(hi32, 1e9), 1e39, 1e300, 5e-324]
    d = rng.uniform(-0.5, hi * 1.2, n)
    d[rng.integers(0, n, n // 4)] = np.inf
    k = rng.integers(0, n, 2 * len(special))
    d[k] = np.array(special * 2)
    return d


def _columns(n: int, rng) -> tuple[np.ndarray, ...]:
    """Unit directions as three columns, some with exact zeros (inf * 0: NaN points)."""
    d = rng.normal(size=(n, 3))
    d[rng.integers(0, n, n // 8), rng.integers(0, 3, n // 8)] = 0.0
    d[rng.integers(0, n, n // 16)] = [0.0, 0.0, -1.0]
    d[~d.any(axis=1)] = [1.0, 0.0, 0.0]        # a row zeroed three times is no direction
    d /= np.linalg.norm(d, axis=1)[:, None]
    return tuple(np.ascontiguousarray(d[:, k]) for k in range(3))


@pytest.mark.parametrize("n, threads", [(1, 1), (37, 1), (5000, 2), (140_000, 2)])
@pytest.mark.parametrize("planar", [False, True])
def test_ranges_and_points_in_c_are_the_numpy_bits(n, threads, planar):
    rng = np.random.default_rng(n + planar)
    lo, hi = 0.05, 6.0
    params = lmath.LidarParams(horizontal_resolution=n, number_of_layers=1, min_range=lo, max_range=hi,
                               projection="planar" if planar else "cylindrical", field_of_view=1.5 if planar else 6.0)
    dist = _delicate(n, lo, hi, rng)
    cols = _columns(n, rng)
    dirs = np.stack(cols, axis=-1).reshape(1, n, 3)
    factor = np.ascontiguousarray(lmath.value_factors(params, dirs), dtype=np.float64).reshape(-1) if planar else None
    want = lmath.ranges_from_hits(params, dist.reshape(1, n), dirs, None).reshape(-1)
    want_xyz = lmath.point_xyz(want, cols)
    ranges = np.full(n, 7.0, dtype=np.float32)
    xyz = np.full((n, 3), 7.0, dtype=np.float32)
    assert packets.lidar_scan(dist, lo, hi, ranges, cols, xyz, factor, threads)
    assert ranges.tobytes() == want.tobytes()
    assert xyz.tobytes() == want_xyz.tobytes()
    if n > 1000:   # the delicate cases are there
        assert np.isinf(want).any() and np.isnan(want_xyz).any() and np.isfinite(want).any()
    # ranges only (no point cloud)
    only = np.zeros(n, dtype=np.float32)
    assert packets.lidar_scan(dist, lo, hi, only, None, None, factor, threads)
    assert only.tobytes() == want.tobytes()


def test_a_wrong_array_is_refused_not_converted():
    n = 8
    with pytest.raises(TypeError, match="lidar_scan"):
        packets.lidar_scan(np.zeros(n, dtype=np.float32), 0.0, 1.0, np.zeros(n, dtype=np.float32))
    with pytest.raises(TypeError, match="lidar_scan"):
        packets.lidar_scan(np.zeros(n), 0.0, 1.0, np.zeros(n - 1, dtype=np.float32))


def _world(**lidar) -> dict:
    return lidar_room({"horizontal_resolution": 360, "number_of_layers": 16, "vertical_field_of_view": 0.9,
                       "min_range": 0.3, "max_range": 2.5, **lidar}, wall_x=1.5,
                      body={"geometry": {"type": "cylinder", "radius": 0.3, "height": 0.1}})


@pytest.mark.parametrize("kw", [{}, {"projection": "planar", "field_of_view": 2.0},
                                {"tilt_angle": -0.3, "near": 0.0, "min_range": 0.0}])
def test_a_simulated_lidar_gives_the_same_scan_without_the_helper(kw, monkeypatch):
    """Two simulations of one world, one with the C pass refused (the numpy steps): the same range
    image and point coordinates, scan after scan while the robot moves (short ranges: misses,
    below-min and beyond-max beams in every scan)."""
    sims = [Simulation(parse_world(_world(**kw)), precision="fast") for _ in range(2)]
    devs = [s.device("r/l") for s in sims]
    for dev, sim in zip(devs, sims):
        dev.enable(sim.basic_time_step)
        dev.enable_point_cloud()
    real = packets.lidar_scan
    calls = []
    for k in range(4):
        for i, sim in enumerate(sims):
            sim.robots["r"].set_pose([0.1 * k, -0.05 * k, 0.05], [0.0, 0.0, 1.0, 0.4 * k])
            monkeypatch.setattr(packets, "lidar_scan", (lambda *a, **kw: calls.append(1) or real(*a, **kw)) if i == 0
                                else (lambda *a, **kw: False))
            for _ in range(8):
                sim.step()
        a, b = devs
        assert a.range_image.tobytes() == b.range_image.tobytes()
        assert a.cloud_points().tobytes() == b.cloud_points().tobytes()
        assert a.point_cloud.tobytes() == b.point_cloud.tobytes()
        ri = a.range_image
        assert np.isinf(ri).any() and np.isfinite(ri).any()
    assert calls   # the C pass did run
