"""DistanceSensor layout, weights and per-type reduction (spec §3)."""

import math

import numpy as np
import pytest

from sensorium.server.devices.distance import (
    SENSOR_TYPES,
    SONAR_MAX_INCIDENCE,
    DistanceSensorType,
    combine_distance_batch,
    ray_directions,
    ray_layout,
    ray_weights,
    reflection_factor,
    sonar_incidence,
)
from sensorium.server.devices.lookup import LookupTable, quantize_sensor

PI = math.pi
RING5 = [(k * PI / 3, 1.0) for k in range(1, 6)]
LAYOUTS = {
    1: [(0, 0)],
    2: [(PI / 2, 1), (-PI / 2, 1)],
    3: [(0, 1), (2 * PI / 3, 1), (-2 * PI / 3, 1)],
    4: [(0, 0), (0, 1), (2 * PI / 3, 1), (-2 * PI / 3, 1)],
    5: [(0, 0), (0, 1), (PI / 2, 1), (PI, 1), (-PI / 2, 1)],
    6: [(0, 0), (0, 1), (2 * PI / 5, 1), (4 * PI / 5, 1), (6 * PI / 5, 1), (8 * PI / 5, 1)],
    7: [(0, 0), (0, 1)] + RING5,
    8: [(0, 0), (0, 1)] + [(k * 2 * PI / 7, 1) for k in range(1, 7)],
    9: [(0, 0.3), (2 * PI / 3, 0.3), (-2 * PI / 3, 0.3), (0, 1)] + RING5,
    10: [(0, 0), (0, 0.5), (2 * PI / 3, 0.5), (-2 * PI / 3, 0.5), (0, 1)] + RING5,
    20: [(0, 0)] + [(s * PI / 2, 1 / 3) for s in range(1, 5)] + [(s * 2 * PI / 7, 2 / 3) for s in range(5, 12)]
        + [(s * PI / 4, 1) for s in range(12, 20)],
}
GENERIC, IR, SONAR, LASER = (int(t) for t in DistanceSensorType)


@pytest.mark.parametrize("n", sorted(LAYOUTS))
def test_layouts(n):
    alpha, t = ray_layout(n, 1.5708)
    expected = np.array(LAYOUTS[n], dtype=float)
    np.testing.assert_allclose(alpha, expected[:, 0], rtol=1e-15, atol=0)
    np.testing.assert_allclose(t, expected[:, 1], rtol=1e-15, atol=0)


def test_concentric_cones_for_eleven_rays():
    alpha, t = ray_layout(11, 1.0)        # cones 1, 4, 6
    np.testing.assert_allclose(t, [0] + [0.5] * 4 + [1] * 6)
    np.testing.assert_allclose(alpha[5:], [s * 2 * PI / 6 for s in range(5, 11)])


def test_zero_aperture_gives_a_single_ray():
    for n in (1, 2, 7, 20):
        alpha, t = ray_layout(n, 0.0)
        assert len(t) == 1 and t[0] == 0
        np.testing.assert_array_equal(ray_directions(n, 0.0), [[1, 0, 0]])
        np.testing.assert_array_equal(ray_weights(n, 0.0, 1.0), [1.0])


def test_directions():
    a = 1.2
    np.testing.assert_array_equal(ray_directions(1, a), [[1, 0, 0]])
    np.testing.assert_allclose(ray_directions(2, a), [[math.cos(a / 2), math.sin(a / 2), 0],
                                                      [math.cos(a / 2), -math.sin(a / 2), 0]], atol=1e-16)
    d5 = ray_directions(5, a)   # centre, up, left, down, right
    s, c = math.sin(a / 2), math.cos(a / 2)
    np.testing.assert_allclose(d5, [[1, 0, 0], [c, 0, s], [c, s, 0], [c, 0, -s], [c, -s, 0]], atol=1e-16)
    for n in range(1, 25):
        d = ray_directions(n, a)
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=1e-15)
        _, t = ray_layout(n, a)
        np.testing.assert_allclose(np.arccos(np.clip(d[:, 0], -1, 1)), t * a / 2, atol=1e-7)


def test_weights_match_spec_examples():
    w = ray_weights(10, 1.5708, 0.5)
    np.testing.assert_allclose(w.round(6), [0.180386] + [0.140484] * 3 + [0.066360] * 6, atol=0)
    w = ray_weights(20, 1.5708, 1.0)
    np.testing.assert_allclose(w.round(6), [0.057522] + [0.055946] * 4 + [0.051473] * 7 + [0.044798] * 8, atol=0)
    for n in range(1, 30):
        assert ray_weights(n, 0.7, 0.8).sum() == pytest.approx(1.0, rel=1e-15)
    np.testing.assert_allclose(ray_weights(3, 1.0, 1.0), [1 / 3] * 3)   # all on the rim
    with pytest.raises(ValueError):
        ray_weights(3, 1.0, 0.0)


def test_reflection_factor():
    np.testing.assert_allclose(reflection_factor([1, 0, 1, 1, 0.5], [0, 0, 1, 0, 0.5], [0, 0, 0, 1, 1]),
                               [1.0, 0.2, 0.6, 0.6, 0.2 + 0.8 * 0.5 * 0.75 * 0.5])


def single(sensor_type, r, weights=None, rmax=0.5, directions=None, normals=None, reflection=None, sens=1.0):
    r = np.asarray(r, dtype=float)
    n = len(r)
    directions = np.tile([1.0, 0, 0], (n, 1)) if directions is None else directions
    normals = np.tile([-1.0, 0, 0], (n, 1)) if normals is None else normals
    weights = np.full(n, 1 / n) if weights is None else weights
    return one(sensor_type, r, directions, normals, weights, rmax, reflection, sens)


def one(sensor_type, r, directions, normals, weights, rmax, reflection=None, sens=1.0) -> float:
    """The batch reduction for a batch of one sensor (row 0 of a (1, N) call)."""
    n = len(r)
    as_rows = lambda a, *shape: None if a is None else np.asarray(a, dtype=float).reshape(1, *shape)
    return float(combine_distance_batch(sensor_type, as_rows(r, n), as_rows(directions, n, 3), as_rows(normals, n, 3),
                                        as_rows(weights, n), rmax, as_rows(reflection, n), sens)[0])


def test_generic_weighted_average_with_no_hit_at_max_range():
    w = np.array([0.5, 0.3, 0.2])
    assert single(GENERIC, [0.1, 0.2, 0.3], w) == pytest.approx(0.05 + 0.06 + 0.06)
    assert single(GENERIC, [0.1, math.inf, 0.3], w) == pytest.approx(0.05 + 0.15 + 0.06)
    assert single(GENERIC, [math.inf] * 3, w) == pytest.approx(0.5)
    assert single(GENERIC, [0.1, 0.7, 0.3], w) == pytest.approx(0.05 + 0.15 + 0.06)   # beyond Rmax: no hit
    assert single(GENERIC, [0.5], [1.0]) == 0.5                                         # exactly Rmax: a hit


def test_laser_uses_the_first_ray():
    assert single(LASER, [0.25], [1.0]) == 0.25
    assert single(LASER, [math.inf], [1.0]) == 0.5


def incidence(beta_deg):
    """Ray along +x hitting a surface whose normal (facing the origin) is tilted by beta."""
    b = math.radians(beta_deg)
    return np.array([[-math.cos(b), math.sin(b), 0.0]])


@pytest.mark.parametrize("beta, expected", [(0.0, 0.3), (22.4, 0.3), (22.6, 0.5), (60.0, 0.5), (89.0, 0.5)])
def test_sonar_incidence_rule(beta, expected):
    assert single(SONAR, [0.3], [1.0], normals=incidence(beta)) == expected


def test_sonar_nearest_qualifying_echo():
    normals = np.concatenate([incidence(40), incidence(10), incidence(0), incidence(5)])
    # ray 0 is nearest but grazing (discarded); ray 3 misses
    d = single(SONAR, [0.1, 0.35, 0.2, math.inf], [0.7, 0.1, 0.1, 0.1], normals=normals)
    assert d == 0.2
    # a ray whose nearest contact is grazing is lost even if it is the only hit
    assert single(SONAR, [0.1, math.inf], normals=np.concatenate([incidence(30), incidence(0)])) == 0.5
    # hits beyond Rmax do not count; weights are ignored
    assert single(SONAR, [0.6, 0.45], [1.0, 0.0], normals=np.concatenate([incidence(0), incidence(0)])) == 0.45


def test_sonar_incidence_uses_world_directions():
    u = np.array([[0.0, 0.0, -1.0]])                # pointing down onto a floor
    floor = np.array([[0.0, 0.0, 1.0]])
    assert single(SONAR, [0.2], [1.0], directions=u, normals=floor) == 0.2
    tilted = np.array([[0.0, math.sin(0.5), -math.cos(0.5)]])   # 28.6 degrees off the floor normal
    assert single(SONAR, [0.2], [1.0], directions=tilted, normals=floor) == 0.5


@pytest.mark.parametrize("red, rough, sens, expected", [
    (1.0, 0.0, 1.0, 0.2),           # red: f = 1
    (0.0, 0.0, 1.0, 0.2 / 0.2),     # black: f = 0.2
    (1.0, 1.0, 1.0, 0.2 / 0.6),     # rough red: f = 0.6
    (0.0, 0.0, 0.0, 0.2),           # sensitivity 0: colour ignored
    (0.0, 0.0, 0.5, 0.2 + (1.0 - 0.2) * 0.5),
])
def test_infra_red_colour(red, rough, sens, expected):
    f = reflection_factor([red], [rough])
    assert single(IR, [0.2], [1.0], reflection=f, rmax=2.0, sens=sens) == pytest.approx(expected, rel=1e-14)


def test_infra_red_no_hit_rays_have_factor_one_and_max_range():
    w = np.array([0.5, 0.5])
    f = np.array([0.2, 0.2])                      # the factor of a no-hit ray is ignored
    D, F = 0.5 * 0.1 + 0.5 * 1.0, 0.5 * 0.2 + 0.5 * 1.0
    assert single(IR, [0.1, math.inf], w, rmax=1.0, reflection=f) == pytest.approx(D / F, rel=1e-15)
    assert single(IR, [math.inf, math.inf], w, rmax=1.0, reflection=f) == 1.0
    assert single(IR, [0.1, 0.3], w, rmax=1.0) == pytest.approx(0.2)    # no colour info: white


def test_batch_mixed_types_and_padding():
    rng = np.random.default_rng(0)
    S, N = 8, 5
    r = rng.uniform(0, 1.2, (S, N))
    r[rng.uniform(size=(S, N)) < 0.3] = np.inf
    u = rng.normal(size=(S, N, 3))
    u /= np.linalg.norm(u, axis=2, keepdims=True)
    nrm = -u + 0.3 * rng.normal(size=(S, N, 3))
    nrm /= np.linalg.norm(nrm, axis=2, keepdims=True)
    w = rng.uniform(size=(S, N))
    w /= w.sum(axis=1, keepdims=True)
    refl = rng.uniform(0.2, 1, (S, N))
    types = np.array([GENERIC, IR, SONAR, LASER] * 2)
    rmax = rng.uniform(0.5, 1.0, S)
    sens = rng.uniform(0, 1, S)
    batch = combine_distance_batch(types, r, u, nrm, w, rmax, refl, sens)
    for s in range(S):
        assert batch[s] == pytest.approx(
            one(types[s], r[s], u[s], nrm[s], w[s], rmax[s], refl[s], sens[s]), rel=1e-15)
    # a 2-ray sensor padded to 3 rays (inf distance, weight 0) gives the same value
    for t in (GENERIC, IR, SONAR, LASER):
        plain = single(t, [0.1, 0.3], [0.6, 0.4], reflection=[0.5, 0.7])
        padded = single(t, [0.1, 0.3, math.inf], [0.6, 0.4, 0.0], reflection=[0.5, 0.7, 0.9])
        assert padded == pytest.approx(plain, rel=1e-15)
    with pytest.raises(ValueError):
        combine_distance_batch([7], np.ones((1, 1)), None, None, [1.0], 1.0)


def test_sensor_types():
    assert SENSOR_TYPES == {"generic": 0, "infra-red": 1, "sonar": 2, "laser": 3}


def test_distance_value():
    # the output stage of every distance sensor: lookup, then resolution (sim/batches.py)
    table = LookupTable([[0, 0, 0], [0.1, 1000, 0]])
    value = lambda d, res: float(quantize_sensor(float(table.interpolate(np.array([d]))[0][0]), res))
    assert value(0.05, -1) == pytest.approx(500.0)
    assert value(0.0512345, 1) == 512.0
    assert value(0.5, -1) == 1000.0


def test_composed_sensor_rotations_sum_in_the_documented_order():
    """sim/batches.py composes robot and sensor rotations by columns (faster than einsum), summing in
    a fixed order from +0.0 (signed zeros included: yaw-only rotations are full of exact zeros)."""
    from sensorium.server.sim.batches import compose_rotations

    rng = np.random.default_rng(4)
    special = np.array([0.0, -0.0, 1.0, -1.0, 0.5, -2.0, 1e-300, 3.7])
    for trial in range(6):
        if trial % 2:
            a, b = rng.choice(special, (3000, 3, 3)), rng.choice(special, (3000, 3, 3))
        else:
            a = rng.normal(size=(3000, 3, 3)) * 10.0 ** rng.integers(-6, 6, (3000, 3, 3))
            b = rng.normal(size=(3000, 3, 3))
            a[rng.random(a.shape) < 0.2] = -0.0
        # the documented order ((j0 + j1) + j2) from +0.0, written in the plain (S, 3, 3) layout; it is
        # the order einsum used when the golden outputs were captured, but einsum's own order is
        # numpy's choice per CPU and version, so the test pins ours, not einsum's
        want = ((0.0 + a[:, :, 0, None] * b[:, None, 0, :]) + a[:, :, 1, None] * b[:, None, 1, :]) \
            + a[:, :, 2, None] * b[:, None, 2, :]
        got = compose_rotations(a, b)
        assert got.tobytes() == want.tobytes()
        assert np.all(np.abs(got - a @ b) <= 1e-15 * (np.abs(a) @ np.abs(b)))   # and it is the product


def test_component_major_sensor_frames_sum_in_the_documented_order():
    """DistanceBatch computes sensor positions and ray directions component-major (long inner axes),
    in the fixed summation orders it documents (those of the einsum products it replaced)."""
    from sensorium.server.sim.batches import _frames_t, _rotate_t

    rng = np.random.default_rng(5)
    special = np.array([0.0, -0.0, 1.0, -1.0, 0.5, -2.0, 1e-300, 3.7])
    for trial, (S, N) in enumerate([(1, 1), (7, 3), (800, 3), (500, 5), (3000, 1)] * 2):
        if trial % 2:
            rr, lr = rng.choice(special, (S, 3, 3)), rng.choice(special, (S, 3, 3))
            lp, L = rng.choice(special, (S, 3)), rng.choice(special, (S, N, 3))
        else:
            rr = rng.normal(size=(S, 3, 3)) * 10.0 ** rng.integers(-6, 6, (S, 3, 3))
            lr, lp, L = rng.normal(size=(S, 3, 3)), rng.normal(size=(S, 3)), rng.normal(size=(S, N, 3))
        rot_t, pos_t = _frames_t(np.ascontiguousarray(rr.transpose(1, 2, 0)), np.ascontiguousarray(lr.transpose(1, 2, 0)),
                                 np.ascontiguousarray(lp.T))
        # references in the plain layout, in the documented orders (see _frames_t, _rotate_t)
        rot = ((0.0 + rr[:, :, 0, None] * lr[:, None, 0, :]) + rr[:, :, 1, None] * lr[:, None, 1, :]) \
            + rr[:, :, 2, None] * lr[:, None, 2, :]
        pos = ((0.0 + rr[:, :, 0] * lp[:, None, 0]) + rr[:, :, 2] * lp[:, None, 2]) + rr[:, :, 1] * lp[:, None, 1]
        assert np.ascontiguousarray(rot_t.transpose(2, 0, 1)).tobytes() == rot.tobytes()
        assert np.ascontiguousarray(pos_t.T).tobytes() == pos.tobytes()
        dirs = _rotate_t(rot_t, np.ascontiguousarray(L.transpose(2, 1, 0)))
        want = ((0.0 + L[:, :, None, 0] * rot[:, None, :, 0]) + L[:, :, None, 2] * rot[:, None, :, 2]) \
            + L[:, :, None, 1] * rot[:, None, :, 1]
        assert dirs.shape == (S, N, 3) and dirs.tobytes() == want.tobytes()
        assert np.allclose(dirs, np.einsum("sij,snj->sni", rot, L), rtol=1e-15, atol=1e-300)


@pytest.mark.parametrize("mixed", [False, True])
def test_batch_sonar_incidence_is_the_cross_product_formula_bit_for_bit(mixed):
    """The sonar's incidence angle atan2(|u x -n|, u . -n), its components summed as
    np.linalg.norm(np.cross(u, -n)) sums them: the same values bit for bit, all sonars (the arrays
    as they come) and sonars among other types (gathered), with angles around the pi/8 limit."""
    rng = np.random.default_rng(3)
    S, N = 64, 5
    u = rng.normal(size=(S, N, 3))
    u /= np.linalg.norm(u, axis=2, keepdims=True)
    # normals at incidence angles spread around the limit (and some grazing or from behind)
    beta = SONAR_MAX_INCIDENCE + rng.normal(size=(S, N)) * np.where(rng.uniform(size=(S, N)) < 0.5, 1e-9, 0.3)
    side = rng.normal(size=(S, N, 3))
    side -= np.einsum("snk,snk->sn", side, u)[..., None] * u
    side /= np.linalg.norm(side, axis=2, keepdims=True)
    nrm = -(np.cos(beta)[..., None] * u + np.sin(beta)[..., None] * side)
    r = rng.uniform(0.0, 1.2, (S, N))
    r[rng.uniform(size=(S, N)) < 0.2] = np.inf
    rmax = rng.uniform(0.5, 1.0, S)
    types = np.where(rng.uniform(size=S) < 0.5, SONAR, GENERIC) if mixed else np.full(S, SONAR)
    got = combine_distance_batch(types, r, u, nrm, np.full((S, N), 1.0 / N), rmax)
    m = types == SONAR
    ref_beta = np.arctan2(np.linalg.norm(np.cross(u[m], -nrm[m]), axis=2), np.einsum("snk,snk->sn", u[m], -nrm[m]))
    assert sonar_incidence(u[m], -nrm[m]).tobytes() == ref_beta.tobytes()
    hit = np.isfinite(r[m]) & (r[m] <= rmax[m, None])
    echo = hit & (ref_beta < SONAR_MAX_INCIDENCE)
    ref = np.minimum(np.where(echo, r[m], np.inf).min(axis=1), rmax[m])
    assert got[m].tobytes() == ref.tobytes()
    assert 0 < np.count_nonzero(echo) < echo.size                 # the limit decides some rays


def test_a_kept_combine_plan_gives_combine_distance_batch_bit_for_bit():
    """combine_planned with a CombinePlan made once (the batched simulation keeps one while the
    same sensors are due) returns combine_distance_batch's values bit for bit, step after step,
    for a mix of every sensor type with hits, misses and grazing sonar echoes."""
    from sensorium.server.devices.distance import CombinePlan, combine_planned

    rng = np.random.default_rng(8)
    S, N = 40, 5
    types = rng.integers(0, 4, S)
    weights = rng.uniform(0.0, 1.0, (S, N))
    rmax = rng.uniform(0.5, 2.0, S)
    sens = rng.uniform(0.0, 1.0, S)
    plan = CombinePlan(types, weights, rmax, sens, S, N)
    for _ in range(5):
        r = rng.uniform(0.0, 2.5, (S, N))
        r[rng.uniform(size=(S, N)) < 0.2] = np.inf
        u = rng.normal(size=(S, N, 3))
        u /= np.linalg.norm(u, axis=2, keepdims=True)
        nrm = -u + rng.normal(scale=0.5, size=(S, N, 3))
        nrm /= np.linalg.norm(nrm, axis=2, keepdims=True)
        refl = rng.uniform(0.2, 1.0, (S, N))
        want = combine_distance_batch(types, r, u, nrm, weights, rmax, refl, sens)
        assert combine_planned(plan, r, u, nrm, refl).tobytes() == want.tobytes()
    with pytest.raises(ValueError, match="unknown sensor type"):
        CombinePlan(np.array([0, 7]), weights[:2], rmax[:2], sens[:2], 2, N)


def test_sonars_with_the_c_steps_are_the_numpy_combine_bit_for_bit():
    """combine_planned for all-sonar sensors with packets' C steps around the arctan2 (the cross
    products' norms, the nearest echoes) gives the numpy combine's values bit for bit: hits,
    misses, hits beyond the range, echoes at incidences on both sides of pi/8, normals facing the
    ray exactly (a zero cross product); closed form: a head-on echo at 0.7 m reads 0.7."""
    from sensorium.server.devices.distance import CombinePlan, combine_planned
    from sensorium.server.raycast import packets

    if packets.library() is None:
        pytest.skip(f"no packets helper: {packets.status()}")
    rng = np.random.default_rng(9)
    S, N = 64, 5
    plan = CombinePlan(2, np.full(N, 1.0 / N), 3.0, 1.0, S, N)
    for trial in range(20):
        r = rng.uniform(0.0, 3.5, (S, N))
        r[rng.uniform(size=(S, N)) < 0.2] = np.inf
        u = rng.normal(size=(S, N, 3))
        u /= np.linalg.norm(u, axis=2, keepdims=True)
        tilt = rng.uniform(0.3, 0.5) if trial % 2 else rng.uniform(0.0, 1.0)     # around pi/8 = 0.3927
        nrm = -u + tilt * rng.normal(size=(S, N, 3))
        nrm /= np.linalg.norm(nrm, axis=2, keepdims=True)
        nrm[::7] = -u[::7]
        want = combine_planned(plan, r, u, nrm)
        got = combine_planned(plan, r, u, nrm, native=packets)
        assert got.tobytes() == want.tobytes(), trial
        # the C norms themselves: sonar_incidence's (its tangent's numerator), bit for bit
        back = -nrm
        c0 = u[..., 1] * back[..., 2] - u[..., 2] * back[..., 1]
        c1 = u[..., 2] * back[..., 0] - u[..., 0] * back[..., 2]
        c2 = u[..., 0] * back[..., 1] - u[..., 1] * back[..., 0]
        assert packets.cross_norm(u, back).tobytes() == np.sqrt((c0 * c0 + c1 * c1) + c2 * c2).tobytes()
    u = np.tile([1.0, 0.0, 0.0], (1, N, 1))
    assert combine_planned(CombinePlan(2, np.ones(N), 3.0, 1.0, 1, N), np.full((1, N), 0.7), u, -u,
                           native=packets).tolist() == [0.7]
