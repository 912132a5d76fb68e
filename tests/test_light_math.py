"""LightSensor irradiance (spec §2.2), closed-form cases."""

import math

import numpy as np
import pytest

from sensorium.server.devices.light import (
    DIRECTIONAL_DISTANCE,
    Light,
    LightArrays,
    LightKind,
    irradiance_many,
    light_terms,
    occlusion_segments_many,
)
from sensorium.server.devices.lookup import LookupTable, quantize_sensor

ORIGIN = np.zeros(3)
X = np.array([1.0, 0.0, 0.0])
UP = np.array([0.0, 0.0, 1.0])


def E(lights, p=ORIGIN, n=X, occluded=None, color_filter=(1.0, 1.0, 1.0)):
    arrays = lights if isinstance(lights, LightArrays) else LightArrays.from_lights(lights)
    return one(arrays, p, n, occluded, color_filter)


def one(lights: LightArrays, p, n, occluded=None, color_filter=(1.0, 1.0, 1.0)) -> float:
    """The batch irradiance for a batch of one sensor."""
    occ = None if occluded is None else np.asarray(occluded, dtype=bool).reshape(1, -1)
    return float(irradiance_many(np.reshape(p, (1, 3)), np.reshape(n, (1, 3)), lights, occ,
                                 np.reshape(np.asarray(color_filter, dtype=float), (1, 3)))[0])


def segments(p, lights: LightArrays):
    """Occlusion-segment directions (n,3) and lengths (n,) of one sensor at ``p``."""
    unit, length = occlusion_segments_many(np.reshape(p, (1, 3)), lights)
    return unit[0], length[0]


def point(pos, **kw):
    return Light(LightKind.POINT, position=tuple(pos), **kw)


@pytest.mark.parametrize("attenuation, expected", [
    ((1, 0, 0), 1.0), ((0, 0, 1), 1 / 4), ((1, 2, 3), 1 / (1 + 2 * 2 + 3 * 4)),
])
def test_point_light_attenuation(attenuation, expected):
    assert E([point((2, 0, 0), attenuation=attenuation)]) == pytest.approx(expected, rel=1e-15)


@pytest.mark.parametrize("angle", [0.0, 0.3, math.pi / 3, 1.5])
def test_point_light_cosine(angle):
    d = 3.0
    light = point((d * math.cos(angle), d * math.sin(angle), 0), attenuation=(0, 1, 0), intensity=2.0)
    assert E([light]) == pytest.approx(2.0 * math.cos(angle) / d, rel=1e-14)


def test_intensity_and_ambient_add_and_are_attenuated():
    light = point((0, 0, 2), attenuation=(0, 0, 1), intensity=3.0, ambient_intensity=0.5)
    # sensor facing the light: att (I c + Ia) = (3 + 0.5)/4
    assert E([light], n=UP) == pytest.approx(3.5 / 4, rel=1e-15)
    # facing away: only the attenuated ambient term
    assert E([light], n=-UP) == pytest.approx(0.5 / 4, rel=1e-15)


def test_light_behind_sensor_gives_only_ambient():
    light = point((-2, 0.5, 0), ambient_intensity=0.25)
    assert E([light]) == pytest.approx(0.25, rel=1e-15)
    assert E([point((-2, 0.5, 0))]) == 0.0


def spot(sensor_angle, beam=0.3, cut=0.6, height=2.0):
    """A spot 2 m above the sensor plane pointing down; returns (light, sensor position)."""
    light = Light(LightKind.SPOT, position=(0, 0, height), direction=(0, 0, -1),
                  attenuation=(1, 0, 0), beam_width=beam, cut_off_angle=cut)
    return light, np.array([height * math.tan(sensor_angle), 0.0, 0.0])


@pytest.mark.parametrize("alpha, factor", [
    (0.0, 1.0), (0.1, 1.0), (0.3, 1.0),               # inside the beam, at its edge
    (0.45, 0.5), (0.36, 0.8), (0.6, 0.0),             # linear between beam and cut-off, at cut-off
    (0.7, 0.0), (1.2, 0.0),                           # beyond the cut-off
])
def test_spot_factor(alpha, factor):
    light, p = spot(alpha)
    # the sensor faces straight up: c = cos(alpha)
    assert E([light], p=p, n=UP) == pytest.approx(factor * math.cos(alpha), rel=1e-12, abs=1e-12)


def test_spot_beam_wider_than_cut_off_behaves_like_the_clamped_field():
    for alpha in (0.2, 0.5, 0.59, 0.61, 0.9):
        wide, p = spot(alpha, beam=1.5708, cut=0.6)
        clamped, _ = spot(alpha, beam=0.6, cut=0.6)
        assert E([wide], p=p, n=UP) == E([clamped], p=p, n=UP)


def test_spot_direction_is_normalised():
    light = Light(LightKind.SPOT, position=(0, 0, 2), direction=(0, 0, -10), beam_width=0.3, cut_off_angle=0.6)
    _, p = spot(0.45)
    assert E([light], p=p, n=UP) == pytest.approx(0.5 * math.cos(0.45), rel=1e-12)


def test_directional_light_not_attenuated():
    light = Light(LightKind.DIRECTIONAL, direction=(-1, 0, 0), intensity=0.7)
    assert E([light]) == pytest.approx(0.7, rel=1e-15)
    assert E([light], p=np.array([1e4, -3e3, 50.0])) == pytest.approx(0.7, rel=1e-15)
    oblique = Light(LightKind.DIRECTIONAL, direction=(-1, -1, 0))
    assert E([oblique]) == pytest.approx(math.sqrt(0.5), rel=1e-15)
    L, d = segments(ORIGIN, LightArrays.from_lights([oblique]))
    np.testing.assert_allclose(L, [[math.sqrt(0.5), math.sqrt(0.5), 0]], rtol=1e-15)
    assert d[0] == DIRECTIONAL_DISTANCE


@pytest.mark.parametrize("color, color_filter, expected", [
    ((1, 1, 1), (1, 1, 1), 1.0),
    ((1, 0, 0), (1, 1, 1), 1 / 3),
    ((1, 0, 0), (0, 1, 1), 0.0),
    ((1, 0.5, 0), (0.2, 1, 1), (0.2 + 0.5) / 3),
    ((0.3, 0.6, 0.9), (1, 0, 0.5), (0.3 + 0.45) / 3),
])
def test_colour_filter_and_light_colour(color, color_filter, expected):
    assert E([point((2, 0, 0), color=color)], color_filter=color_filter) == pytest.approx(expected, rel=1e-15)


def test_occlusion_removes_only_the_direct_term():
    lights = [point((2, 0, 0), ambient_intensity=0.2), point((0, 0, 3), attenuation=(0, 0, 1))]
    assert E(lights, n=UP) == pytest.approx(0.2 + 1 / 9, rel=1e-15)
    assert E(lights, n=UP, occluded=[False, True]) == pytest.approx(0.2, rel=1e-15)
    assert E(lights, n=UP, occluded=[True, False]) == pytest.approx(0.2 + 1 / 9, rel=1e-15)


def test_sum_over_lights_and_batch():
    lights = LightArrays.from_lights([
        point((2, 0, 0)), Light(LightKind.DIRECTIONAL, direction=(0, 0, -1), intensity=0.5),
        Light(LightKind.SPOT, position=(0, 0, 2), direction=(0, 0, -1), beam_width=0.3, cut_off_angle=0.6),
    ])
    P = np.array([[0, 0, 0], [0.5, 0.1, 0], [-1, 2, 0.3]], dtype=float)
    N = np.array([X, UP, [0, math.sqrt(0.5), math.sqrt(0.5)]])
    occ = np.array([[False, True, False], [False, False, False], [True, True, True]])
    batch = irradiance_many(P, N, lights, occ, np.array([[1, 1, 1], [0.5, 1, 1], [1, 0, 0]]))
    singles = [one(lights, P[s], N[s], occ[s], f) for s, f in enumerate([(1, 1, 1), (0.5, 1, 1), (1, 0, 0)])]
    np.testing.assert_allclose(batch, singles, rtol=1e-15)
    assert batch[0] == pytest.approx(1.0 + 0.0 + 0.0)  # directional is perpendicular, spot: c = 0


def test_no_lights():
    assert E(LightArrays.empty()) == 0.0
    np.testing.assert_array_equal(irradiance_many(np.zeros((3, 3)), np.tile(X, (3, 1)), LightArrays.empty()), 0.0)


def test_sensor_at_the_light_is_finite():
    # attenuation with a constant term: ambient 1/a1, direct 0 (L undefined)
    assert E([point((0, 0, 0), ambient_intensity=0.5, intensity=3)]) == 0.5
    assert E([point((0, 0, 0), attenuation=(2, 1, 1), ambient_intensity=0.5)]) == 0.25
    # no constant term: att = inf but both terms are 0 -> 0, never NaN
    assert E([point((0, 0, 0), attenuation=(0, 0, 1))]) == 0.0
    assert E([point((0, 0, 0), attenuation=(0, 1, 0)), point((2, 0, 0))]) == 1.0
    # an (unsanitised) ambient term with att = inf: +inf, not NaN, even with zero filter components
    assert E([point((0, 0, 0), attenuation=(0, 0, 1), ambient_intensity=0.1, color=(1, 0, 0))],
             color_filter=(1, 0, 0)) == math.inf
    lights = LightArrays.from_lights([point((0, 0, 0)), point((0, 0, 5))])
    dirs, lengths = segments(ORIGIN, lights)
    np.testing.assert_array_equal(dirs, [[1, 0, 0], [0, 0, 1]])
    np.testing.assert_array_equal(lengths, [0, 5])
    # spot at the sensor: also finite
    s = Light(LightKind.SPOT, position=(1, 2, 3), ambient_intensity=0.4)
    assert E([s], p=np.array([1.0, 2.0, 3.0])) == pytest.approx(0.4)


def test_light_in_the_sensor_plane_gives_exactly_zero():
    assert E([point((0, 3, 1)), point((0, -1e-3, 0)), point((0, 0, 1e9))]) == 0.0
    # a rotated sensor: the plane x + y = 0 through the sensor at (1, 1, 0)
    n = np.array([math.sqrt(0.5), math.sqrt(0.5), 0.0])
    assert E([point((3, -1, 7))], p=np.array([1.0, 1.0, 0.0]), n=n) == 0.0


def test_occlusion_segments():
    lights = LightArrays.from_lights([point((3, 4, 0)), Light(LightKind.DIRECTIONAL, direction=(0, 0, -2))])
    p = np.array([0.0, 0.0, 1.0])
    dirs, lengths = segments(p, lights)
    np.testing.assert_allclose(dirs, [np.array([3, 4, -1]) / math.sqrt(26), [0, 0, 1]], rtol=1e-15)
    np.testing.assert_allclose(lengths, [math.sqrt(26), 1000.0], rtol=1e-15)
    np.testing.assert_allclose(p + dirs * lengths[:, None], [[3, 4, 0], [0, 0, 1001]], rtol=1e-14)
    # a batch of sensors: each row is that sensor's segments
    P = np.array([p, [1.0, 1.0, 0.0]])
    unit, length = occlusion_segments_many(P, lights)
    np.testing.assert_allclose(unit[0], dirs, rtol=1e-15)
    np.testing.assert_allclose(unit[1], [np.array([2, 3, 0]) / math.sqrt(13), [0, 0, 1]], rtol=1e-15)
    np.testing.assert_allclose(length[1], [math.sqrt(13), 1000.0], rtol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0, rtol=1e-15)


def test_validation():
    with pytest.raises(ValueError):
        LightArrays.from_lights([point((0, 0, 1), attenuation=(0, 0, 0))])
    with pytest.raises(ValueError):
        LightArrays.from_lights([point((0, 0, 1), attenuation=(1, -1, 0))])
    with pytest.raises(ValueError):
        LightArrays.from_lights([Light(LightKind.SPOT, direction=(0, 0, 0))])
    # attenuation is irrelevant for directional lights
    LightArrays.from_lights([Light(LightKind.DIRECTIONAL, attenuation=(0, 0, 0))])
    arrays = LightArrays.from_lights([point((0, 0, 1))])
    with pytest.raises(ValueError):
        arrays.position[0, 0] = 5.0


def test_light_value_default_table():
    # the output stage of every light sensor: lookup, then resolution (sim/batches.py)
    table = LookupTable([[0, 0, 0], [1, 1000, 0]])
    value = lambda e, res: float(quantize_sensor(float(table.interpolate(np.array([e]))[0][0]), res))
    e = E([point((0, 0, 2), attenuation=(0, 0, 1))], n=UP)
    assert value(e, -1) == pytest.approx(250.0)
    assert value(5.0, -1) == 1000.0
    assert value(0.12345, 10) == 120.0


def test_direct_mask_marks_lights_with_a_direct_term():
    lights = LightArrays.from_lights([
        point((2, 0, 0)),                                   # in front
        point((-2, 0, 0), ambient_intensity=0.5),           # behind: ambient only
        point((0, 2, 0)),                                   # in the sensor plane
        Light(LightKind.SPOT, position=(3, 0, 0), direction=(0, 0, -1)),   # sensor outside its cone
        point((1, 1, 0), intensity=0.0),                    # no intensity
    ])
    # the batch's occlusion rays go only where the direct term is > 0 (sim/batches.py LightBatch.plan)
    direct_mask = lambda lts: light_terms(ORIGIN.reshape(1, 3), X.reshape(1, 3), lts)[1][0] > 0.0
    np.testing.assert_array_equal(direct_mask(lights), [True, False, False, False, False])
    assert lights.count == len(lights) == 5
    assert direct_mask(LightArrays.empty()).shape == (0,)
