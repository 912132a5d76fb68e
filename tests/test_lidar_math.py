"""Lidar beams, ranges, point cloud and rotating sweep (spec §4 with the project's departures)."""

import math

import numpy as np
import pytest

from sensorium.server.devices.lidar import (
    POINT_DTYPE,
    LidarParams,
    column_azimuths,
    layer_elevations,
    point_cloud,
    ranges_from_hits,
    ray_directions,
    rotating_sweep,
    value_factors,
)

PI = math.pi


def params(**kw):
    base = dict(horizontal_resolution=8, number_of_layers=1, field_of_view=PI / 2, min_range=0.01, max_range=1.0)
    base.update(kw)
    return LidarParams(**base)


# ------------------------------------------------------------------------------------ angles
def test_fixed_azimuths():
    np.testing.assert_allclose(column_azimuths(params(horizontal_resolution=4)),
                               [3 * PI / 16, PI / 16, -PI / 16, -3 * PI / 16], rtol=1e-15)
    np.testing.assert_allclose(column_azimuths(params(horizontal_resolution=4), [3, 0]),
                               [-3 * PI / 16, 3 * PI / 16], rtol=1e-15)


def test_full_circle_fixed_lidar_has_no_duplicate_column():
    az = column_azimuths(params(horizontal_resolution=8, field_of_view=2 * PI))
    steps = np.diff(np.concatenate([az, [az[0] - 2 * PI]]))
    np.testing.assert_allclose(steps, -2 * PI / 8, rtol=1e-14)       # evenly spaced, wrap included
    wrapped = np.round(np.mod(az, 2 * PI), 9)
    assert len(set(wrapped)) == 8


def test_rotating_azimuths():
    az = column_azimuths(params(type="rotating", horizontal_resolution=8))
    np.testing.assert_allclose(az, [PI, 3 * PI / 4, PI / 2, PI / 4, 0, -PI / 4, -PI / 2, -3 * PI / 4], atol=1e-15)


@pytest.mark.parametrize("layers, vfov, tilt, expected", [
    (1, 0.2, 0.0, [0.0]), (1, 0.2, 0.05, [0.05]),
    (2, 0.2, 0.0, [0.1, -0.1]), (5, 0.4, 0.0, [0.2, 0.1, 0.0, -0.1, -0.2]),
    (3, 0.4, -0.1, [0.1, -0.1, -0.3]),
])
def test_layer_elevations(layers, vfov, tilt, expected):
    p = params(number_of_layers=layers, vertical_field_of_view=vfov, tilt_angle=tilt)
    np.testing.assert_allclose(layer_elevations(p), expected, atol=1e-16)
    np.testing.assert_allclose(layer_elevations(p, include_tilt=False), np.array(expected) - tilt, atol=1e-16)


# -------------------------------------------------------------------------------- directions
@pytest.mark.parametrize("kw", [
    {}, {"number_of_layers": 6, "vertical_field_of_view": 0.5},
    {"number_of_layers": 4, "tilt_angle": 0.2}, {"type": "rotating", "number_of_layers": 3},
    {"projection": "planar", "number_of_layers": 4, "vertical_field_of_view": 0.6},
    {"projection": "planar", "number_of_layers": 3, "tilt_angle": -0.3},
])
def test_directions_are_unit_and_ordered(kw):
    p = params(horizontal_resolution=16, **kw)
    d = ray_directions(p)
    assert d.shape == (p.number_of_layers, 16, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=2), 1.0, rtol=1e-15)
    if not p.rotating:
        assert np.all(np.diff(np.arctan2(d[..., 1], d[..., 0]), axis=1) < 0)   # left -> right
    assert np.all(np.diff(d[..., 2], axis=0) < 0)                               # top -> bottom


def test_cylindrical_directions_closed_form():
    p = params(number_of_layers=3, vertical_field_of_view=0.4)
    d = ray_directions(p)
    e, t = layer_elevations(p)[:, None], column_azimuths(p)[None, :]
    np.testing.assert_allclose(d, np.stack(np.broadcast_arrays(np.cos(e) * np.cos(t), np.cos(e) * np.sin(t),
                                                               np.sin(e)), axis=-1), atol=1e-16)


def test_fixed_tilt_is_a_pitch_raising_z():
    tau = 0.2
    p = params(number_of_layers=3, vertical_field_of_view=0.4, tilt_angle=tau)
    d = ray_directions(p)
    flat = ray_directions(params(number_of_layers=3, vertical_field_of_view=0.4))
    c, s = math.cos(tau), math.sin(tau)
    pitch = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    np.testing.assert_allclose(d, flat @ pitch.T, atol=1e-15)
    # a beam straight ahead would be at elevation e + tau
    ahead = ray_directions(params(horizontal_resolution=1, field_of_view=0.1, number_of_layers=3,
                                  vertical_field_of_view=0.4, tilt_angle=tau))
    np.testing.assert_allclose(np.arcsin(ahead[:, 0, 2]), layer_elevations(p), atol=1e-15)


def test_rotating_tilt_is_a_cone():
    p = params(type="rotating", number_of_layers=2, vertical_field_of_view=0.2, tilt_angle=0.1)
    d = ray_directions(p)
    np.testing.assert_allclose(np.arcsin(d[..., 2]), np.repeat([[0.2], [0.0]], 8, axis=1), atol=1e-15)
    np.testing.assert_allclose(np.arctan2(d[0, :, 1], d[0, :, 0]) % (2 * PI),
                               column_azimuths(p) % (2 * PI), atol=1e-12)


def test_planar_directions_go_through_pixel_centres():
    p = params(projection="planar", horizontal_resolution=10, field_of_view=1.2,
               number_of_layers=3, vertical_field_of_view=0.5)
    d = ray_directions(p)
    a = (1 - 2 * (np.arange(10) + 0.5) / 10) * math.tan(0.6)
    np.testing.assert_allclose(d[..., 1] / d[..., 0], np.broadcast_to(a, (3, 10)), rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(d[..., 2] / d[..., 0], np.tan(np.repeat([[0.25], [0.0], [-0.25]], 10, axis=1)),
                               atol=1e-15)


# ------------------------------------------------------------------------------------- ranges
def test_validity_rule():
    p = params(horizontal_resolution=1, field_of_view=0.1)
    dist = np.array([[0.005, 0.01, 0.5, 0.999, 1.0, 5.0, np.inf, 0.99999999]]).T.reshape(1, -1)
    p = params(horizontal_resolution=dist.shape[1], field_of_view=0.1)
    out = ranges_from_hits(p, dist, ray_directions(p), None)
    assert out.dtype == np.float32
    # 0.99999999 rounds to 1.0 in float32 = maxRange -> inf
    np.testing.assert_array_equal(out, np.float32([[np.inf, 0.01, 0.5, 0.999, np.inf, np.inf, np.inf, np.inf]]))


def test_planar_value_is_depth():
    p = params(projection="planar", horizontal_resolution=4, number_of_layers=2, vertical_field_of_view=0.4,
               tilt_angle=0.3, max_range=10)
    d = ray_directions(p)
    out = ranges_from_hits(p, np.full((2, 4), 2.0), d, None)
    untilted = ray_directions(params(projection="planar", horizontal_resolution=4, number_of_layers=2,
                                     vertical_field_of_view=0.4))
    np.testing.assert_allclose(out, 2.0 * untilted[..., 0], rtol=1e-7)
    # a hit whose depth is below minRange is inf even though its range is not
    p = params(projection="planar", horizontal_resolution=2, field_of_view=3.0, min_range=0.5, max_range=10)
    out = ranges_from_hits(p, np.full((1, 2), 0.6), ray_directions(p), None)
    assert np.all(np.isinf(out))


def test_value_factors():
    p = params(number_of_layers=2, vertical_field_of_view=0.4, tilt_angle=0.3)
    np.testing.assert_array_equal(value_factors(p, ray_directions(p)), np.ones((2, 8)))
    p = params(projection="planar", number_of_layers=2, vertical_field_of_view=0.4, tilt_angle=0.3, max_range=10)
    d = ray_directions(p)
    f = value_factors(p, d)
    assert np.all((f > 0) & (f <= 1))
    # a ray of length max_range/f reaches exactly the maximum depth
    out = ranges_from_hits(p, 10.0 / f * (1 - 1e-5), d, None)
    np.testing.assert_allclose(out, 10.0 * (1 - 1e-5), rtol=1e-7)


def test_rotating_planar_depth_is_cos_elevation():
    p = params(type="rotating", projection="planar", number_of_layers=3, vertical_field_of_view=0.6,
               tilt_angle=0.2, max_range=10)
    out = ranges_from_hits(p, np.full((3, 2), 3.0), ray_directions(p, [1, 6]), None)
    np.testing.assert_allclose(out, 3.0 * np.cos(np.repeat([[0.3], [0.0], [-0.3]], 2, axis=1)), rtol=1e-7)


def test_resolution_gives_multiples():
    p = params(horizontal_resolution=200, resolution=0.05, max_range=10.0, min_range=0.1)
    dist = np.random.default_rng(1).uniform(0.2, 9.0, (1, 200))
    out = ranges_from_hits(p, dist, ray_directions(p), None)
    np.testing.assert_array_equal(out, np.float32(np.floor(dist / 0.05 + 0.5) * 0.05))
    np.testing.assert_allclose(out / 0.05, np.round(out / 0.05), atol=1e-4)
    # rounding up to maxRange makes the value invalid
    p = params(horizontal_resolution=2, resolution=0.1, max_range=1.0)
    np.testing.assert_array_equal(ranges_from_hits(p, np.array([[0.96, 0.94]]), ray_directions(p), None),
                                  np.float32([[np.inf, 0.9]]))


def test_noise_sigma_and_draws_only_for_finite_values():
    p = params(horizontal_resolution=1000, number_of_layers=40, vertical_field_of_view=0.5,
               noise=0.01, max_range=10.0)
    dist = np.full((40, 1000), 5.0)
    dist[:, ::10] = np.inf          # 4000 no-hit beams get no draw
    rng = np.random.default_rng(11)
    twin = np.random.default_rng(11)
    out = ranges_from_hits(p, dist, ray_directions(p), rng)
    finite = out[np.isfinite(out)].astype(np.float64)
    assert finite.size == 36_000
    assert finite.std() == pytest.approx(0.1, rel=0.02)
    assert finite.mean() == pytest.approx(5.0, abs=5 * 0.1 / math.sqrt(finite.size))
    twin.standard_normal(36_000)
    assert rng.bit_generator.state == twin.bit_generator.state
    assert np.all(np.isinf(out[:, ::10]))


def test_noise_recheck_keeps_values_inside_bounds():
    p = params(horizontal_resolution=1000, noise=0.05, min_range=0.5, max_range=1.0)
    out = ranges_from_hits(p, np.full((1, 1000), 0.98), ray_directions(p), np.random.default_rng(2))
    finite = out[np.isfinite(out)]
    assert 0 < finite.size < 1000
    assert np.all((finite >= 0.5) & (finite < 1.0))
    # without rng the noise is skipped
    assert np.all(ranges_from_hits(p, np.full((1, 1000), 0.98), ray_directions(p), None) == np.float32(0.98))


# -------------------------------------------------------------------------------- point cloud
def test_point_cloud_points_are_range_times_direction():
    p = params(horizontal_resolution=12, number_of_layers=3, vertical_field_of_view=0.3, tilt_angle=0.1,
               max_range=10.0)
    rng = np.random.default_rng(3)
    img = ranges_from_hits(p, rng.uniform(1, 9, (3, 12)), ray_directions(p), None)
    pts = point_cloud(p, img, time_s=2.0, period_s=0.1)
    assert pts.dtype == POINT_DTYPE and POINT_DTYPE.itemsize == 20 and pts.shape == (36,)
    xyz = np.stack([pts["x"], pts["y"], pts["z"]], axis=1).astype(np.float64).reshape(3, 12, 3)
    np.testing.assert_allclose(xyz, img[..., None] * ray_directions(p), rtol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(xyz, axis=2), img, rtol=1e-6)
    np.testing.assert_array_equal(pts["layer_id"].reshape(3, 12), np.repeat([[0], [1], [2]], 12, axis=1))
    np.testing.assert_allclose(pts["time"].reshape(3, 12)[1], 2.0 - np.arange(12) * 0.1 / 12, rtol=1e-7)


def test_point_cloud_laser_scan_consistency():
    W, fov = 16, 3.0
    p = params(horizontal_resolution=W, field_of_view=fov, max_range=10.0)
    img = ranges_from_hits(p, np.random.default_rng(4).uniform(1, 9, (1, W)), ray_directions(p), None)
    pts = point_cloud(p, img, 1.0, 0.1)
    angles = np.arctan2(pts["y"].astype(float), pts["x"].astype(float))
    np.testing.assert_allclose(angles, column_azimuths(p), atol=1e-6)
    np.testing.assert_allclose(np.hypot(pts["x"], pts["y"]), img[0], rtol=1e-6)
    # LaserScan: angle_min = -fov/2, increment fov/W; the row reversed runs from -fov/2 + half a step up
    np.testing.assert_allclose(angles[::-1], -fov / 2 + (np.arange(W) + 0.5) * fov / W, atol=1e-6)


def test_point_cloud_planar_uses_equal_angles():
    p = params(projection="planar", horizontal_resolution=6, field_of_view=1.5, number_of_layers=2,
               vertical_field_of_view=0.4, tilt_angle=0.1, max_range=10.0)
    img = np.full((2, 6), 2.0, dtype=np.float32)
    pts = point_cloud(p, img, 0.0, 0.1)
    e = np.array([0.3, -0.1])[:, None]
    t = column_azimuths(p)[None, :]
    expected = 2.0 * np.stack(np.broadcast_arrays(np.cos(e) * np.cos(t), np.cos(e) * np.sin(t), np.sin(e)), axis=-1)
    got = np.stack([pts["x"], pts["y"], pts["z"]], axis=1).reshape(2, 6, 3)
    np.testing.assert_allclose(got, expected, rtol=1e-6)


def test_point_cloud_infinite_ranges_and_column_subsets():
    p = params(type="rotating", horizontal_resolution=8, number_of_layers=2, vertical_field_of_view=0.2)
    img = np.array([[np.inf, 0.5], [0.25, np.inf]], dtype=np.float32)
    pts = point_cloud(p, img, 3.0, 0.032, columns=[4, 2], times=[2.99, 2.98])
    assert pts.shape == (4,)
    assert not np.isfinite(pts["x"][0]) and not np.isfinite(pts["z"][3])
    np.testing.assert_allclose([pts["x"][1], pts["y"][1], pts["z"][1]], [0, 0.5 * math.cos(0.1), 0.5 * math.sin(0.1)],
                               atol=1e-7)   # column 2 looks left
    np.testing.assert_allclose(pts["time"], [2.99, 2.98, 2.99, 2.98], rtol=1e-7)
    np.testing.assert_array_equal(pts["layer_id"], [0, 0, 1, 1])


# ------------------------------------------------------------------------------ rotating sweep
def sweep_steps(p, frequency, dt_ms, steps, head=0.0):
    out = []
    for k in range(steps):
        s = rotating_sweep(p, head, frequency, dt_ms, (k + 1) * dt_ms / 1000)
        out.append(s)
        head = s.head_angle_after
    return out


@pytest.mark.parametrize("W, frequency, dt_ms", [(360, 10, 1), (512, 10, 32), (1000, 25, 8), (361, 7, 3),
                                                 (100, 1, 16), (7, 13, 5)])
def test_each_column_once_per_revolution(W, frequency, dt_ms):
    p = params(type="rotating", horizontal_resolution=W)
    revolutions = 3
    total_ms = revolutions * 1000 / frequency
    steps = int(total_ms // dt_ms)
    cols = np.concatenate([s.columns for s in sweep_steps(p, frequency, dt_ms, steps)])
    # the sequence is the columns in sweep order, starting ahead (W/2 when W is even), without gaps
    np.testing.assert_array_equal(np.diff(cols) % W, np.ones(len(cols) - 1))
    for r in range(len(cols) // W):
        assert sorted(cols[r * W:(r + 1) * W]) == list(range(W))
    expected = math.ceil(W / 2) + steps * dt_ms / 1000 * frequency * W - math.ceil(W / 2)
    assert abs(len(cols) - expected) <= 1


def test_sector_of_one_step_and_times():
    p = params(type="rotating", horizontal_resolution=8)
    s = rotating_sweep(p, 0.0, 10.0, 50, time_end_s=1.0)    # half a turn clockwise from straight ahead
    np.testing.assert_array_equal(s.columns, [4, 5, 6, 7])
    assert s.head_angle_after == pytest.approx(-PI)
    # column 4 at the start of the step, then every 1/80 s
    np.testing.assert_allclose(s.times, [0.95, 0.9625, 0.975, 0.9875], rtol=1e-14)
    nxt = rotating_sweep(p, s.head_angle_after, 10.0, 50, 1.05)
    np.testing.assert_array_equal(nxt.columns, [0, 1, 2, 3])


def test_times_lie_in_the_step_and_increase_along_the_sweep():
    p = params(type="rotating", horizontal_resolution=1000)
    for k, s in enumerate(sweep_steps(p, 13.0, 8, 40)):
        t_end = (k + 1) * 0.008
        assert np.all((s.times >= t_end - 0.008 - 1e-12) & (s.times < t_end))
        assert np.all(np.diff(s.times) > 0)


def test_fast_head_sweeps_everything_once():
    p = params(type="rotating", horizontal_resolution=64)
    s = rotating_sweep(p, 0.3, 25.0, 100, time_end_s=10.0)     # 2.5 turns in one step
    assert sorted(s.columns) == list(range(64))
    assert np.all(np.diff(s.times) > 0)
    # the last pass: times within the final revolution (1/25 s)
    assert np.all((s.times >= 10.0 - 0.04 - 1e-12) & (s.times < 10.0))


def test_stopped_head_samples_nothing():
    p = params(type="rotating", horizontal_resolution=64)
    s = rotating_sweep(p, 1.0, 0.0, 32)
    assert s.columns.size == 0 and s.head_angle_after == 1.0
    with pytest.raises(ValueError):
        rotating_sweep(p, 0.0, -1.0, 32)


def test_params_validation():
    with pytest.raises(ValueError):
        LidarParams(type="spinning")
    with pytest.raises(ValueError):
        LidarParams(projection="spherical")
    with pytest.raises(ValueError):
        LidarParams(projection="planar", field_of_view=4.0)
    with pytest.raises(ValueError):
        LidarParams(min_range=2.0, max_range=1.0)
    with pytest.raises(ValueError):
        LidarParams(resolution=0.0)
    assert LidarParams(noise=0.1, max_range=20).noise_sigma == pytest.approx(2.0)
    assert LidarParams().number_of_points == 2048
