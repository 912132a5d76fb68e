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


def test_a_radius_a_hair_inside_the_farthest_point_still_cuts_it():
    """A block whose points all lie well inside a light's radius skips radiance's distances; one
    an ulp inside the farthest point must still cut that point (and only it), on any threads."""
    q = np.array([0.3, -0.2, 0.9])
    P, _ = _points(2 * shading.BLOCK + 77, 3)
    P[7] = (0.0, 0.0, 0.0)
    N = q - P
    N /= np.linalg.norm(N, axis=1)[:, None]          # every point faces the light
    v = q - P
    far = np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])     # radiance's distances
    top = int(np.argmax(far))
    shadows = np.array([True])
    for radius, cut in ((float(np.nextafter(far[top], 0.0)), 1), (float(far[top]), 0), (1e3, 0)):
        lights = LightArrays.from_lights([Light(LightKind.POINT, position=tuple(q), intensity=1.0, radius=radius)])
        want = _one_pass(P, N, lights, shadows)
        assert len(want[0][0]) == len(P) - cut and (cut == 0 or top not in want[0][0])
        for threads in (1, 2):
            got = shadow_rays(P, N, lights, shadows, threads)
            assert got[0][0].tobytes() == want[0][0].tobytes()
            assert got[0][1].tobytes() == want[0][1].tobytes() and got[0][2].tobytes() == want[0][2].tobytes()


def test_shadow_rays_of_no_points_and_no_shadow_lights():
    lights = _lights()
    P, N = _points(10, 2)
    assert shadow_rays(P, N, lights, np.zeros(4, dtype=bool), 2) == {}
    got = shadow_rays(P[:0], N[:0], lights, np.array([True, False, False, False]), 2)
    assert list(got) == [0] and len(got[0][0]) == 0 and got[0][1].shape == (0, 3)


# --------------------------------------------------------------------- the ray engine's part

import math  # noqa: E402

import pytest  # noqa: E402

from sensorium.server.raycast.blocks import MIN_RAYS  # noqa: E402
from sensorium.server.raycast.engine import Mount, Precision, RayEngine, RayKind, ShapeEntry  # noqa: E402
from sensorium.server.world.geometry import Box, Cylinder, Plane, Pose, Sphere  # noqa: E402


def _fan(n: int, seed: int) -> np.ndarray:
    """n unit directions all around (a camera's pixel rays, in any frame)."""
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


def _robot_world(precision):
    """A floor, a wall, a ball, a moving robot (a cylinder body and a box on it) and another robot."""
    eng = RayEngine(precision)
    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], Pose.identity())
    eng.add_body([ShapeEntry(Box((0.1, 2.0, 1.0)), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([1.5, 0.0, 0.5])))
    eng.add_body([ShapeEntry(Sphere(0.15), Pose.identity(), True, True)], Pose(np.eye(3), np.array([0.8, 0.3, 0.15])))
    body = eng.add_body([ShapeEntry(Cylinder(0.045, 0.08), Pose.identity(), True, True),
                         ShapeEntry(Box((0.02, 0.02, 0.02)), Pose(np.eye(3), np.array([0.03, 0.0, 0.05])), True, True)],
                        Pose(np.eye(3), np.array([0.0, 0.0, 0.04])), owner=0, movable=True)
    eng.add_body([ShapeEntry(Cylinder(0.045, 0.08), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([0.4, -0.2, 0.04])), owner=1, movable=True)
    return eng, body


@pytest.mark.parametrize("precision", [Precision.FAST, Precision.EXACT])
def test_a_large_local_cast_traces_only_the_rays_that_may_meet_the_body(precision):
    eng, body = _robot_world(precision)
    n = MIN_RAYS + 1000
    D = _fan(n, 3)
    O = np.ascontiguousarray(np.broadcast_to(np.array([0.04, 0.0, 0.06]), D.shape))   # above the box, in the body frame
    big = eng.cast_local(body, O, D, 0.001, np.inf, kind=RayKind.VISUAL)
    pruned = eng.counters["local_pruned"]
    assert 0 < pruned < n                   # most rays pass the body by; some meet it
    step = MIN_RAYS // 2                    # batches too small to be pruned: every ray traced
    parts = [eng.cast_local(body, O[a:a + step], D[a:a + step], 0.001, np.inf, kind=RayKind.VISUAL)
             for a in range(0, n, step)]
    assert eng.counters["local_pruned"] == pruned
    assert np.concatenate([p.distance for p in parts]).tobytes() == big.distance.tobytes()
    assert np.concatenate([p.shape for p in parts]).tobytes() == big.shape.tobytes()
    # a hit's normal bit for bit; a miss's is zero (FAST's sign of that zero already follows the
    # batch's path -- mostly missing or mostly hitting -- and nothing reads it)
    hit = np.isfinite(big.distance)
    normals = np.concatenate([p.normal for p in parts])
    assert normals[hit].tobytes() == big.normal[hit].tobytes()
    assert not normals[~hit].any() and not big.normal[~hit].any()
    assert np.isfinite(big.distance).any()


@pytest.mark.parametrize("precision,n", [(Precision.FAST, (1 << 16) + 1000), (Precision.EXACT, MIN_RAYS + 1000)])
def test_unbounded_rays_mounted_on_a_robot_skip_the_mount_tables(precision, n):
    """A camera without a far plane on its robot, a cast in blocks (FAST's packet path takes up
    to 65,536 rays in one C pass): the Mount's cast takes the general broad phase directly
    (counted), with the hits of the same rays given a plain mount array."""
    eng, body = _robot_world(precision)
    eng.threads = 2
    yaw = 0.3
    R = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    eng.set_body_pose(body, Pose(R, np.array([0.0, 0.0, 0.04])))
    D = _fan(n, 4)
    O = np.broadcast_to(np.array([0.03, 0.0, 0.1]), D.shape)       # one origin for every ray (a camera)
    mount = Mount(np.full(n, body))
    for _ in range(2):          # the same rays cast again, as an image's each step
        before = eng.counters["unbounded_mounts"]
        got = eng.cast(O, D, 0.01, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, mount=mount)
        assert eng.counters["unbounded_mounts"] > before
        want = eng.cast(O, D, 0.01, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, mount=np.full(n, body))
        assert got.distance.tobytes() == want.distance.tobytes()
        assert got.shape.tobytes() == want.shape.tobytes()
        assert got.normal.tobytes() == want.normal.tobytes()
        assert (got.shape == eng._bodies[body + 1].first).any()      # the other robot is seen, never its own body
        assert not np.isin(got.shape, [eng._bodies[body].first, eng._bodies[body].first + 1]).any()


def test_direct_and_segments_are_light_terms_and_occlusion_segments():
    lights = _lights()
    P, N = _points(5000, 7)
    direct, unit, length = light_math.direct_and_segments(P, N, lights)
    assert direct.tobytes() == light_math.light_terms(P, N, lights)[1].tobytes()
    want_unit, want_length = light_math.occlusion_segments_many(P, lights)
    assert unit.tobytes() == want_unit.tobytes() and length.tobytes() == want_length.tobytes()


def test_mounted_rays_turn_as_one_pass_on_any_threads():
    from sensorium.server.sim.cameras import MountedRays

    local = _fan(3 * shading.BLOCK + 77, 11)
    yaw = 0.7
    R = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    x, y, z = (np.ascontiguousarray(local[:, k]) for k in range(3))
    want = np.empty(local.shape)
    for k in range(3):          # the one pass the rays were turned with before the blocks
        want[:, k] = x * R[k, 0] + y * R[k, 1] + z * R[k, 2]
    for threads in (1, 2):
        world, world32 = MountedRays(local).at(R, threads)
        assert world.tobytes() == want.tobytes()
        assert world32.tobytes() == want.astype(np.float32).tobytes()
    small = MountedRays(local[:10]).at(R, 2)[0]
    assert small.tobytes() == want[:10].tobytes()


def test_hits_move_into_a_shape_frame_in_blocks_as_in_one_product():
    from sensorium.server.sim.scene import _POSE_ROWS, _in_blocks
    from sensorium.server.world.geometry import Pose as GeoPose

    rng = np.random.default_rng(12)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    pose = GeoPose(q, np.array([0.3, -1.2, 0.05]))
    x = rng.normal(size=(2 * _POSE_ROWS + 999, 3)) * 3.0
    rows = np.sort(rng.choice(len(x), 2 * _POSE_ROWS + 5, replace=False))
    assert _in_blocks(pose, x, rows, True).tobytes() == pose.apply(x[rows]).tobytes()
    assert _in_blocks(pose, x, rows, False).tobytes() == pose.apply_dirs(x[rows]).tobytes()
    one = np.broadcast_to(np.array([0.1, 0.2, 0.3]), x.shape)       # a camera's origin, one row for all
    assert _in_blocks(pose, one, rows, True).tobytes() == pose.apply(one[rows]).tobytes()


def test_an_image_s_rays_turn_into_its_body_frame_in_blocks_as_in_one_product():
    # (own_shapes.OwnBodyRays turns them with the ray engine's row-block product)
    from sensorium.server.raycast.exact import _MATMUL_ROWS, _mat

    rng = np.random.default_rng(13)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    x = _fan(2 * _MATMUL_ROWS + 321, 14)
    assert _mat(x, q.T).tobytes() == np.ascontiguousarray(x @ q.T).tobytes()
    assert _mat(x[:100], q.T).tobytes() == np.ascontiguousarray(x[:100] @ q.T).tobytes()


@pytest.mark.parametrize("casting", [[0], [1], [2], [0, 2], [1, 3]])
def test_shadow_rays_of_some_lights_are_the_one_pass_choice(casting):
    """Only the shadow-casting lights' terms are made (LightArrays.subset): the same values."""
    lights = _lights()
    shadows = np.isin(np.arange(4), casting)
    P, N = _points(shading.BLOCK + 500, 5)
    want = _one_pass(P, N, lights, shadows)
    got = shadow_rays(P, N, lights, shadows, 2)
    assert sorted(got) == sorted(want) == casting
    for j in casting:
        for a, b in zip(got[j], want[j]):
            assert a.tobytes() == b.tobytes()


def test_a_light_subset_keeps_every_value():
    lights = _lights()
    sub = lights.subset([2, 0])
    assert len(sub) == 2
    for name in ("kind", "position", "direction", "attenuation", "intensity", "ambient_intensity", "color",
                 "beam_width", "cut_off_angle", "radius"):
        assert getattr(sub, name).tobytes() == getattr(lights, name)[[2, 0]].tobytes()
        assert not getattr(sub, name).flags.writeable


def test_radiance_channels_stay_apart_after_white_lights_share_their_sums():
    """White (or grey) lights add to one array the three equal channel sums share; a coloured light
    after them gives each channel its own: swapping every light's colour channels and the albedo's
    must swap the radiance's channels, bit for bit, in any order of the lights."""
    rng = np.random.default_rng(5)
    P, N = _points(5000, 6)
    A = rng.random((5000, 3))
    white = Light(LightKind.POINT, position=(0.5, -0.5, 1.0), intensity=2.0, attenuation=(0.0, 0.0, 1.0))
    grey = Light(LightKind.DIRECTIONAL, direction=(0.3, 0.2, -1.0), intensity=0.6, ambient_intensity=0.2,
                 color=(0.5, 0.5, 0.5))
    tint = (1.0, 0.9, 0.8)
    swap = [2, 0, 1]
    def arrays(order, colour):
        return LightArrays.from_lights([Light(LightKind.SPOT, position=(-1.0, 0.0, 0.8), direction=(1.0, 0.0, -0.5),
                                              intensity=1.0, beam_width=0.3, cut_off_angle=0.6, color=colour)
                                        if x == "tinted" else x for x in order])

    for order in ([white, "tinted", grey], [grey, white, "tinted"], ["tinted", white, grey]):
        L = shading.radiance(P, N, A, arrays(order, tint))
        Ls = shading.radiance(P, N, A[:, swap], arrays(order, tuple(tint[k] for k in swap)))
        assert np.ascontiguousarray(L[:, swap]).tobytes() == np.ascontiguousarray(Ls).tobytes()
        assert not np.array_equal(L[:, 0], L[:, 1])
