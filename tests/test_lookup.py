"""Lookup table (spec §1.2), resolution rounding (§1.3) and per-device random streams."""

import math

import numpy as np
import pytest

from sensorium.server.devices.lookup import LookupTable, quantize_lidar, quantize_sensor
from sensorium.server.devices.noise import device_rng, device_seed

TABLE = LookupTable([[0.1, 10.0, 0.0], [0.5, 50.0, 0.0], [1.0, 20.0, 0.0]])


def reference_lookup(v, rows):
    """Spec §9.1 written out as a scalar loop (no noise)."""
    if not rows:
        return v
    xs = [r[0] for r in rows]
    ys = [r[1] for r in rows]
    if v <= xs[0]:
        return ys[0]
    if v >= xs[-1]:
        return ys[-1]
    lo, hi = 0, len(rows) - 1
    while lo + 1 < hi:
        mid = (lo + hi) // 2
        if v < xs[mid]:
            hi = mid
        else:
            lo = mid
    u = (v - xs[lo]) / (xs[hi] - xs[lo])
    return (1 - u) * ys[lo] + u * ys[hi]


@pytest.mark.parametrize("v, expected", [
    (-5.0, 10.0), (0.0, 10.0), (0.1, 10.0),          # clamp low, exact x_0
    (0.3, 30.0), (0.5, 50.0), (0.75, 35.0),          # interpolation, exact interior x_k
    (1.0, 20.0), (2.0, 20.0),                        # exact x_last, clamp high
    (1e300, 20.0), (-1e300, 10.0), (math.inf, 20.0), (-math.inf, 10.0), (1e-300, 10.0),
])
def test_lookup_points(v, expected):
    assert TABLE.lookup(v, None) == pytest.approx(expected, rel=1e-15, abs=0.0)
    assert TABLE.lookup(np.array([v]), None)[0] == pytest.approx(expected, rel=1e-15)


def test_shape_and_dtype_follow_input():
    out = TABLE.lookup(np.array([[0.3, 0.75], [2.0, -1.0]]), None)
    assert out.shape == (2, 2) and out.dtype == np.float64
    np.testing.assert_allclose(out, [[30.0, 35.0], [20.0, 10.0]], rtol=1e-15)
    assert TABLE.lookup(0.3, None).shape == ()


def test_equal_outputs_and_single_row():
    flat = LookupTable([[0, 7, 0], [1, 7, 0], [2, 7, 0]])
    np.testing.assert_array_equal(flat.lookup([-1, 0.5, 1, 1.5, 3], None), 7.0)
    single = LookupTable([[0.5, 3.0, 0.0]])
    np.testing.assert_array_equal(single.lookup([-1.0, 0.5, 9.0], None), 3.0)
    assert single.min_metrics_range == single.max_metrics_range == 0.5


def test_empty_table_is_identity():
    empty = LookupTable([])
    v = np.array([-3.0, 0.0, 2.5, np.inf])
    np.testing.assert_array_equal(empty.lookup(v, None), v)
    rng = np.random.default_rng(1)
    state = rng.bit_generator.state
    np.testing.assert_array_equal(empty.lookup(v, rng), v)
    assert rng.bit_generator.state == state
    assert (empty.min_value, empty.max_value, empty.min_metrics_range, empty.max_metrics_range) == (0, 0, 0, 0)
    assert not empty.has_noise and empty.rows == () and len(empty) == 0


def test_getters():
    t = LookupTable([[0, 0, 0], [0.2, 2000, 0]])            # the spec's test table
    assert (t.min_value, t.max_value) == (0.0, 2000.0)
    t = LookupTable([[0.01, 5, 0], [0.5, -3, 0.1], [2, 10, 0]])   # non-monotonic outputs
    assert (t.min_value, t.max_value) == (-3.0, 10.0)
    assert (t.min_metrics_range, t.max_metrics_range) == (0.01, 2.0)
    assert t.rows == ((0.01, 5.0, 0.0), (0.5, -3.0, 0.1), (2.0, 10.0, 0.0))
    assert t.flattened == (0.01, 5.0, 0.0, 0.5, -3.0, 0.1, 2.0, 10.0, 0.0)
    assert t.has_noise and t.inputs_increasing
    assert not LookupTable([[1, 0, 0], [0, 1, 0]]).inputs_increasing
    assert t == LookupTable(t.rows) and hash(t) == hash(LookupTable(t.rows))


def test_non_monotonic_outputs_interpolate_piecewise():
    t = LookupTable([[0, 0, 0], [1, 100, 0], [2, 0, 0], [3, 50, 0]])
    np.testing.assert_allclose(t.lookup([0.5, 1.0, 1.25, 2.0, 2.5], None), [50, 100, 75, 0, 25])


def test_matches_reference_bisection_including_unsorted_inputs():
    rng = np.random.default_rng(7)
    for m in (2, 3, 4, 5, 8, 13):
        for sort in (True, False):
            x = rng.uniform(-2, 2, m)
            x = np.sort(x) if sort else x
            rows = [[float(a), float(b), 0.0] for a, b in zip(x, rng.uniform(-10, 10, m))]
            v = rng.uniform(-3, 3, 200)
            got = LookupTable(rows).lookup(v, None)
            expected = [reference_lookup(float(a), rows) for a in v]
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_rejects_malformed_rows():
    with pytest.raises(ValueError):
        LookupTable([[0, 1]])
    with pytest.raises(ValueError):
        LookupTable([[0, 1, math.nan]])


def test_relative_noise_statistics():
    t = LookupTable([[0, 100, 0.1], [1, 100, 0.1]])
    out = t.lookup(np.full(100_000, 0.5), np.random.default_rng(123))
    assert out.mean() == pytest.approx(100.0, abs=5 * 10 / math.sqrt(len(out)))
    assert out.std() == pytest.approx(10.0, rel=0.02)


def test_noise_level_is_interpolated():
    t = LookupTable([[0, 100, 0.0], [1, 100, 0.2]])
    out = t.lookup(np.full(100_000, 0.5), np.random.default_rng(5))
    assert out.std() == pytest.approx(10.0, rel=0.02)


def test_no_draw_when_noise_is_zero():
    rng = np.random.default_rng(99)
    state = rng.bit_generator.state
    np.testing.assert_array_equal(TABLE.lookup(np.linspace(0, 2, 50), rng), TABLE.lookup(np.linspace(0, 2, 50), None))
    assert rng.bit_generator.state == state
    # a noisy table draws only for the entries whose interpolated noise is non-zero, in C order
    t = LookupTable([[0, 10, 0], [1, 10, 0], [2, 10, 0.1]])
    rng = np.random.default_rng(3)
    twin = np.random.default_rng(3)
    out = t.lookup(np.array([0.5, 1.5, 0.2, 3.0]), rng)
    g = twin.standard_normal(2)
    np.testing.assert_allclose(out, [10, 10 * (1 + 0.05 * g[0]), 10, 10 * (1 + 0.1 * g[1])], rtol=1e-15)
    assert rng.bit_generator.state == twin.bit_generator.state
    # rng=None: noise-free value, nothing drawn
    np.testing.assert_array_equal(t.lookup(np.array([1.5, 3.0]), None), [10.0, 10.0])


@pytest.mark.parametrize("v, res, expected", [
    (0.26, 0.1, 0.30000000000000004), (0.24, 0.1, 0.2), (2.5, 1, 3.0), (1.5, 1, 2.0),
    (-0.7, 1, 0.0), (-0.2, 1, 0.0), (-1.7, 1, -1.0), (-2.5, 1, -2.0), (333.3, 10, 330.0),
    (0.123, -1, 0.123),
])
def test_quantize_sensor_truncates_toward_zero(v, res, expected):
    got = quantize_sensor(v, res)
    assert got == expected and isinstance(got, float)
    if expected == 0.0:
        assert math.copysign(1.0, got) == 1.0  # +0.0 like the C int cast, never -0.0


@pytest.mark.parametrize("v, res, expected", [
    (-0.7, 1, -1.0), (-0.2, 1, 0.0), (-2.5, 1, -2.0), (2.5, 1, 3.0), (0.26, 0.1, 0.30000000000000004),
    (math.inf, 0.5, math.inf), (0.3, -1, 0.3),
])
def test_quantize_lidar_floor_rule(v, res, expected):
    assert quantize_lidar(v, res) == expected


def test_quantize_arrays_and_errors():
    np.testing.assert_array_equal(quantize_sensor(np.array([-0.7, 0.7, 1.2]), 1), [0, 1, 1])
    np.testing.assert_array_equal(quantize_lidar(np.array([-0.7, 0.7, np.inf]), 1), [-1, 1, np.inf])
    with pytest.raises(ValueError):
        quantize_sensor(1.0, 0.0)
    with pytest.raises(ValueError):
        quantize_lidar(1.0, -2.0)


def test_sensor_output_is_lookup_then_rounding():
    # what sim/batches.py does for every light and distance sensor of a step (noise-free here)
    t = LookupTable([[0, 0, 0], [1, 1000, 0]])
    y, n = t.interpolate(np.array([0.33333, 0.1, 0.2]))
    np.testing.assert_array_equal(n, 0.0)
    assert quantize_sensor(float(y[0]), 1) == 333.0
    assert quantize_sensor(float(y[0]), -1) == pytest.approx(333.33)
    np.testing.assert_array_equal(quantize_sensor(y[1:], 100), [100, 200])


def test_device_streams_are_deterministic_and_independent():
    a = device_rng(42, "robot/ds0").standard_normal(5)
    np.testing.assert_array_equal(a, device_rng(42, "robot/ds0").standard_normal(5))
    assert not np.array_equal(a, device_rng(42, "robot/ds1").standard_normal(5))
    assert not np.array_equal(a, device_rng(43, "robot/ds0").standard_normal(5))
    # the documented derivation
    import hashlib
    assert device_seed(42, "robot/ds0") == int.from_bytes(hashlib.sha256(b"42/robot/ds0").digest(), "big")


def test_the_lookup_in_c_is_interpolate_bit_for_bit():
    """packets.lookup (the batched distance sensors' table lookup in one C pass) gives
    LookupTable.interpolate's y and n, bit for bit: values inside the table, on every input, at
    and beyond both ends, infinities, NaN, signed zeros; tables of 2 and of many rows with noise;
    and refuses what it does not handle (unsorted inputs, one row) so the caller interpolates."""
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    rng = np.random.default_rng(4)
    xs = np.sort(rng.uniform(-2.0, 5.0, 40))
    tables = [LookupTable([[0.0, 0.0, 0.0], [3.0, 3.0, 0.0]]), TABLE,
              LookupTable([[float(x), float(y), float(n)] for x, y, n in zip(xs, rng.uniform(-9, 9, 40),
                                                                                 rng.uniform(0, 0.2, 40))])]
    for t in tables:
        knots = np.array([r[0] for r in t.rows])
        v = np.concatenate([rng.uniform(knots[0] - 1.0, knots[-1] + 1.0, 3000), knots, np.nextafter(knots, -9.0),
                            np.nextafter(knots, 9.0), [math.inf, -math.inf, math.nan, 0.0, -0.0]])
        got = packets.lookup(t, v)
        want = t.interpolate(v)
        assert got is not None
        assert got[0].tobytes() == want[0].tobytes() and got[1].tobytes() == want[1].tobytes()
    # closed form: halfway between (0.1, 10) and (0.5, 50) is 30; clamped outside
    y, _ = packets.lookup(TABLE, np.array([0.3, -1.0, 7.0]))
    assert y.tolist() == [pytest.approx(30.0, abs=1e-12), 10.0, 20.0]
    assert packets.lookup(LookupTable([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 5.0, 0.0]]), np.zeros(3)) is None
    assert packets.lookup(LookupTable([[1.0, 2.0, 0.0]]), np.zeros(3)) is None
