"""A big camera image's work is cut without changing a bit: a camera's shadow rays are chosen on
row blocks on the engine's threads (the same points, segments and casts as one pass over all
points), and a cast of unbounded rays mounted on a moving body skips the mounted rays' broad
phase (every such ray is unbounded: the same pairs, without building its per-ray tables)."""

from __future__ import annotations

import numpy as np

from sensorium.server.devices import light as light_math
from sensorium.server.devices import shading
from sensorium.server.devices.light import Light, LightArrays, LightKind
from sensorium.server.sim.cameras import shadow_rays


def _lights() -> LightArrays:
    return LightArrays.from_lights([
        Light(LightKind.POINT, position=(0.5, -0.5, 1.0), intensity=2.0, radius=1.6),       # cuts some points
        Light(LightKind.DIRECTIONAL, direction=(0.3, 0.2, -1.0), intensity=0.6, ambient_intensity=0.2),
        Light(LightKind.SPOT, position=(-1.0, 0.0, 0.8), direction=(1.0, 0.0, -0.5), intensity=1.0,
              beam_width=0.3, cut_off_angle=0.6, attenuation=(1.0, 0.0, 1.0)),
        Light(LightKind.POINT, position=(2.0, 2.0, 2.0), intensity=1.0),                   # casts no shadow
    ])


def _points(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    P = rng.uniform(-2.0, 2.0, size=(n, 3))
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1)[:, None]
    P[7] = (0.5, -0.5, 1.0)             # a point at the point light: no direct term, length 0
    return P, N


def _one_pass(P, N, lights, shadows):
    """The camera's choice as one pass over every point made it (before the blocks)."""
    direct = light_math.light_terms(P, N, lights)[1]
    unit, length = light_math.occlusion_segments_many(P, lights)
    out = {}
    for j in shadows.nonzero()[0].tolist():
        i = (direct[:, j] > 0.0).nonzero()[0]
        near = shading.within_radius(P[i], lights, j)
        if near is not None:
            i = i[near]
        out[j] = (i, unit[i, j], length[i, j])
    return out


def test_shadow_rays_are_the_one_pass_choice_on_any_threads():
    lights = _lights()
    shadows = np.array([True, True, True, False])
    n = 3 * shading.BLOCK + 123              # three whole blocks and a short one
    P, N = _points(n, 1)
    want = _one_pass(P, N, lights, shadows)
    assert sorted(want) == [0, 1, 2] and all(len(w[0]) for w in want.values())
    v = np.array([0.5, -0.5, 1.0]) - P
    facing = ((N * v).sum(axis=1) > 0.0).sum()
    assert 0 < len(want[0][0]) < facing       # the radius cuts some facing points
    for threads in (1, 2, 3):
        got = shadow_rays(P, N, lights, shadows, threads)
        assert sorted(got) == sorted(want)
        for j, (i, unit, length) in got.items():
            assert i.tobytes() == want[j][0].tobytes()
            assert unit.tobytes() == want[j][1].tobytes() and unit.flags.c_contiguous
            assert length.tobytes() == want[j][2].tobytes()


def test_shadow_rays_of_no_points_and_no_shadow_lights():
    lights = _lights()
    P, N = _points(10, 2)
    assert shadow_rays(P, N, lights, np.zeros(4, dtype=bool), 2) == {}
    got = shadow_rays(P[:0], N[:0], lights, np.array([True, False, False, False]), 2)
    assert list(got) == [0] and len(got[0][0]) == 0 and got[0][1].shape == (0, 3)
