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


# ------------------------------------------- a camera inside its own robot's bounding sphere

_A, _WALL = 0.05, 0.95     # the hollow robot's inner half-size; the wall's face (x)


def _hollow_robot_world(precision):
    """A hollow box robot (five plates 1 cm thick around a cube of inner half-size _A, open towards
    +x) turned and moved, a wall facing its opening, and a second robot behind it."""
    eng = RayEngine(precision)
    eng.add_body([ShapeEntry(Box((0.1, 60.0, 60.0)), Pose.identity(), True, True)],
                 Pose(np.eye(3), np.array([_WALL + 0.05, 0.0, 0.0])))
    t, a = 0.01, _A
    plates = [((t, 2 * a + 2 * t, 2 * a + 2 * t), (-a - t / 2, 0.0, 0.0))]            # the back
    plates += [((2 * a + t, t, 2 * a + 2 * t), (-t / 2, s * (a + t / 2), 0.0)) for s in (-1, 1)]
    plates += [((2 * a + t, 2 * a, t), (-t / 2, 0.0, s * (a + t / 2))) for s in (-1, 1)]
    body = eng.add_body([ShapeEntry(Box(size), Pose(np.eye(3), np.array(at)), True, True) for size, at in plates],
                        Pose.identity(), owner=0, movable=True)
    other = eng.add_body([ShapeEntry(Sphere(0.05), Pose.identity(), True, True)],
                         Pose(np.eye(3), np.array([-0.5, 0.0, 0.0])), owner=1, movable=True)
    return eng, body, other


@pytest.mark.parametrize("precision,n", [(Precision.FAST, (1 << 16) + 1000), (Precision.EXACT, MIN_RAYS + 1000)])
def test_a_camera_inside_its_robot_pays_no_pairs_with_it(precision, n, monkeypatch):
    """A camera at the centre of a hollow box robot (inside the robot's bounding sphere, so no cone
    test culls it) casts its unbounded pixel rays mounted on the robot, a cast in blocks (whose
    pairs are listed up to t_far; a smaller cast's mounted broad phase pairs a body with its
    neighbours only): the broad phase never tests
    them against the robot (their pairs were made, then all dropped), and the hits are those of the
    same rays given a plain mount array (the per-ray path) bit for bit, and the closed form: the
    wall through the opening, the robot's own plates from the body-frame cast."""
    from sensorium.server.raycast import engine as engine_module

    eng, body, other = _hollow_robot_world(precision)
    eng.threads = 2
    roll = 0.4                  # about x: the opening still faces the wall
    R = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(roll), -math.sin(roll)], [0.0, math.sin(roll), math.cos(roll)]])
    centre = np.array([0.1, -0.05, 0.02])
    eng.set_body_pose(body, Pose(R, centre))
    rng = np.random.default_rng(21)
    local = rng.normal(size=(n, 3)) * np.array([0.35, 1.0, 1.0])
    local[:, 0] = np.abs(local[:, 0]) + 0.3            # forward (within the wall), many out of the opening, many onto the plates
    local /= np.linalg.norm(local, axis=1)[:, None]
    D = local @ R.T
    O = np.broadcast_to(centre, D.shape)                 # the camera at the robot's centre
    tested = []
    inner = engine_module._sphere_pairs

    def spy(C, r2, owner, O_, D_, t_near, lim, excl, among=None, cone=True):
        tested.append(list(range(len(C))) if among is None else among.tolist())
        return inner(C, r2, owner, O_, D_, t_near, lim, excl, among=among, cone=cone)

    monkeypatch.setattr(engine_module, "_sphere_pairs", spy)
    mount = Mount(np.full(n, body))
    for _ in range(2):          # the same rays cast again, as an image's each step
        tested.clear()
        got = eng.cast(O, D, 0.0, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, mount=mount)
        mt = eng._mover_table("visual")
        row = int(mt.row_of[body])
        assert tested and all(row not in t for t in tested)    # the robot's test skipped
        assert any(int(mt.row_of[other]) in t for t in tested)  # the other robot's still made
        want = eng.cast(O, D, 0.0, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, mount=np.full(n, body))
        assert got.distance.tobytes() == want.distance.tobytes()
        assert got.shape.tobytes() == want.shape.tobytes()
        assert got.normal.tobytes() == want.normal.tobytes()
    # the closed form: in the world the robot is skipped, so every forward ray meets the wall; in the
    # body frame a ray leaves through the opening (x the largest of its components) or meets a plate
    wall = eng._bodies[0].first
    assert (got.shape == wall).all()
    np.testing.assert_allclose(got.distance, (_WALL - centre[0]) / D[:, 0], rtol=1e-6 if precision is Precision.FAST
                               else 1e-12)
    own = eng.cast_local(body, np.zeros((n, 3)), local, 0.0, np.inf, kind=RayKind.VISUAL)
    side = np.maximum(np.abs(local[:, 1]), np.abs(local[:, 2]))
    out = side < local[:, 0]
    assert 0 < out.sum() < n
    assert not np.isfinite(own.distance[out]).any()
    np.testing.assert_allclose(own.distance[~out], _A / side[~out], rtol=1e-6 if precision is Precision.FAST else 1e-12)


@pytest.mark.parametrize("precision", [Precision.FAST, Precision.EXACT])
def test_a_smaller_camera_inside_its_robot_skips_it_for_its_unbounded_rays(precision, monkeypatch):
    """A cast in one part (20,000 rays on one thread) of the same camera, half its rays looking
    back, where nothing bounds them but the robot behind: those unbounded mounted rays take the
    general broad phase, which no longer tests them against their own robot (their pairs with it
    were dropped); the bounded ones pair with the robot's neighbours only, as before. The hits are
    the per-ray mount path's bit for bit and the closed form (wall ahead, plates in the body frame)."""
    from sensorium.server.raycast import engine as engine_module

    eng, body, other = _hollow_robot_world(precision)
    eng.threads = 1
    centre = np.array([0.1, -0.05, 0.02])
    roll = -0.3
    R = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(roll), -math.sin(roll)], [0.0, math.sin(roll), math.cos(roll)]])
    eng.set_body_pose(body, Pose(R, centre))
    n = 20000
    rng = np.random.default_rng(22)
    local = rng.normal(size=(n, 3)) * np.array([0.35, 1.0, 1.0])
    local[:, 0] = np.abs(local[:, 0]) + 0.3
    local[n // 2:, 0] *= -1.0                           # looking back: out of the wall's way
    local /= np.linalg.norm(local, axis=1)[:, None]
    D = local @ R.T
    O = np.broadcast_to(centre, D.shape)
    tested = []
    inner = engine_module._sphere_pairs

    def spy(C, r2, owner, O_, D_, t_near, lim, excl, among=None, cone=True):
        if len(O_) * len(C) > 16384:                    # the test runs mover by mover
            tested.append(list(range(len(C))) if among is None else among.tolist())
        return inner(C, r2, owner, O_, D_, t_near, lim, excl, among=among, cone=cone)

    monkeypatch.setattr(engine_module, "_sphere_pairs", spy)
    mount = Mount(np.full(n, body))
    for _ in range(2):
        tested.clear()
        got = eng.cast(O, D, 0.0, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, mount=mount)
        mt = eng._mover_table("visual")
        assert tested and all(int(mt.row_of[body]) not in t for t in tested)
        assert all(int(mt.row_of[other]) in t for t in tested)
        want = eng.cast(O, D, 0.0, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, mount=np.full(n, body))
        assert got.distance.tobytes() == want.distance.tobytes()
        assert got.shape.tobytes() == want.shape.tobytes()
        assert got.normal.tobytes() == want.normal.tobytes()
    tol = 1e-6 if precision is Precision.FAST else 1e-12
    ahead = slice(0, n // 2)
    assert (got.shape[ahead] == eng._bodies[0].first).all()
    np.testing.assert_allclose(got.distance[ahead], (_WALL - centre[0]) / D[ahead, 0], rtol=tol)
    back = got.shape[n // 2:]
    assert set(back.tolist()) == {-1, eng._bodies[other].first}      # the other robot, else nothing
    own = eng.cast_local(body, np.zeros((n, 3)), local, 0.0, np.inf, kind=RayKind.VISUAL)
    big = np.abs(local).max(axis=1)
    out = local[:, 0] == big                            # out through the opening
    assert 0 < out.sum() < n // 2
    assert not np.isfinite(own.distance[out]).any()
    np.testing.assert_allclose(own.distance[~out], _A / big[~out], rtol=tol)


# ------------------------------------------------- one light's columns (light.lit_segments)

import itertools  # noqa: E402
import platform  # noqa: E402


def _mixed_lights() -> list[Light]:
    """Every path of lit_segments: point lights of intensity above, at, below 1 and 0, one with a
    radius that cuts, directional ones (one dim), a spot."""
    return [
        Light(LightKind.POINT, position=(0.5, -0.5, 1.0), intensity=2.0, radius=1.6),
        Light(LightKind.DIRECTIONAL, direction=(0.3, 0.2, -1.0), intensity=0.6),
        Light(LightKind.SPOT, position=(-1.0, 0.0, 0.8), direction=(1.0, 0.0, -0.5), beam_width=0.3,
              cut_off_angle=0.6),
        Light(LightKind.POINT, position=(0.0, 0.0, 0.0), intensity=1.0, attenuation=(0.0, 0.0, 1.0)),
        Light(LightKind.POINT, position=(-0.4, -1.1, 0.6), intensity=1e-320),       # I·c underflows when c < 5e-4
        Light(LightKind.POINT, position=(1.5, 1.5, 1.5), intensity=0.0),
        Light(LightKind.DIRECTIONAL, direction=(-1e-3, 0.0, -1.0), intensity=3.0),
    ]


def _mixed_points(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Points of every magnitude around the lights, a point at one (the origin), one 1e-170 m from
    it (its distance's squares underflow: length 0 with a direction), normals in every direction."""
    rng = np.random.default_rng(seed)
    P = rng.uniform(-2.0, 2.0, size=(n, 3)) * 10.0 ** rng.integers(-3, 2, size=(n, 1))
    N = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-3, 3, size=(n, 3))
    N /= np.linalg.norm(N, axis=1)[:, None]
    P[5] = 0.0
    P[6] = 1e-170
    N[6] = -np.sqrt(1.0 / 3.0)                              # facing the light at the origin
    P[8:40] = rng.normal(size=(32, 3)) * 1e-9              # very near it
    v = np.array([-0.4, -1.1, 0.6]) - P[40:60]             # grazing the dim light: c about 1e-6
    w = np.cross(v, (0.0, 0.0, 1.0))
    N[40:60] = w / np.linalg.norm(w, axis=1)[:, None] + 1e-6 * v / np.linalg.norm(v, axis=1)[:, None]
    # N·v of the light at the origin cancels: its sign is the order of the sum's terms ((p0 + p2) + p1
    # is 0 at the first point, above 0 at the second; (p0 + p1) + p2 the other way round)
    P[60:62] = ((-1.0, 1.0, -1e-17), (-1.0, -1e-17, 1.0))
    N[60:62] = np.sqrt(1.0 / 3.0)
    return P, N


def test_one_light_s_columns_are_direct_and_segments_column_bit_for_bit():
    """lit_segments' points, units and lengths of each light are those of direct_and_segments'
    column (the general (S, n, 3) path), for every kind of light and every point."""
    lights = LightArrays.from_lights(_mixed_lights())
    P, N = _mixed_points(20000, 21)
    direct, unit, length = light_math.direct_and_segments(P, N, lights)
    for j in range(len(lights)):
        i, got_unit, got_length = light_math.lit_segments(P, N, lights, j)
        want = (direct[:, j] > 0.0).nonzero()[0]
        assert i.tobytes() == want.tobytes(), j
        assert got_unit.tobytes() == np.ascontiguousarray(unit[want, j]).tobytes() and got_unit.flags.c_contiguous
        assert got_length.tobytes() == length[want, j].tobytes()
    i, unit, length = light_math.lit_segments(P, N, lights, 3)
    assert 60 not in i and 61 in i
    assert 5 not in i and unit[i == 6].tolist() == [[1.0, 0.0, 0.0]] and length[i == 6].tolist() == [0.0]
    facing = ((N * (np.array([-0.4, -1.1, 0.6]) - P)).sum(axis=1) > 0.0).sum()
    assert 0 < len(light_math.lit_segments(P, N, lights, 4)[0]) < facing       # grazing points: I·c is 0
    assert len(light_math.lit_segments(P, N, lights, 5)[0]) == 0


def test_the_column_sums_are_numpy_s_on_x86_64():
    """The fast columns are used where numpy sums as they do (x86-64's SSE build: always)."""
    if platform.machine().lower() in ("x86_64", "amd64"):
        assert light_math._COLUMN_SUMS


def test_shadow_rays_of_mixed_lights_in_every_order_are_the_general_choice():
    """Lights that cast no shadow mixed with ones that do, in every order: each casting light's
    points, segments and lengths are the one-pass general path's, bit for bit, on 1 and 2 threads."""
    base = _mixed_lights()
    P, N = _mixed_points(shading.BLOCK + 777, 22)          # over a block boundary: one order, both thread counts
    few = slice(0, 3000)                                   # every order: within one block, one thread
    for order in itertools.permutations([0, 1, 2, 3]):
        lights = LightArrays.from_lights([base[k] for k in order])
        whole = order == (0, 1, 2, 3)
        Po, No = (P, N) if whole else (P[few], N[few])
        for casting in ([0, 2], [1, 3], [0, 1, 2, 3], [3]):
            shadows = np.isin(np.arange(4), casting)
            want = _one_pass(Po, No, lights, shadows)
            for threads in ((1, 2) if whole else (1,)):
                got = shadow_rays(Po, No, lights, shadows, threads)
                assert sorted(got) == casting
                for j in casting:
                    for a, b in zip(got[j], want[j]):
                        assert a.tobytes() == np.ascontiguousarray(b).tobytes(), (order, casting, j)


# ---- a camera without shapes of its own on its robot: which rays can meet the robot, decided once

from sensorium.server.raycast.engine import Riding  # noqa: E402


def _yawed(yaw: float, t) -> Pose:
    R = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    return Pose(R, np.asarray(t, dtype=np.float64))


def _same(got, want) -> None:
    assert got.distance.tobytes() == want.distance.tobytes()
    assert got.shape.tobytes() == want.shape.tobytes()
    assert got.normal.tobytes() == want.normal.tobytes()


@pytest.mark.parametrize("precision,n,threads", [(Precision.FAST, (1 << 16) + 3000, 2), (Precision.FAST, 20000, 1),
                                                 (Precision.EXACT, MIN_RAYS + 3000, 2)])
@pytest.mark.parametrize("local_o", [(0.05, 0.0, 0.03), (0.0, 0.0, 0.2)], ids=["inside", "above"])
def test_rays_riding_their_robot_see_it_as_the_general_cast(precision, n, threads, local_o):
    """A camera's rays from one origin on a moving robot, cast unmounted (they see the robot): with
    a Riding, only the rays that may meet the robot's bound are paired with it (counted), and every
    hit is the general cast's bit for bit as the robot drives and turns -- its own body in view (a
    ray half looking down past it), the other robot and the static world too. From inside the
    robot's bounding sphere (beside the box on its cylinder) and from above it."""
    eng, body = _robot_world(precision)
    eng.threads = threads
    local_o = np.array(local_o)                  # in the body frame
    D_local = _fan(n, 7)
    D_local[: n // 2, 2] = -np.abs(D_local[: n // 2, 2])      # half of them look down past the body
    riding = Riding(body, local_o, D_local, 0.001, np.inf)
    seen_own = 0
    for yaw, t in [(0.0, (0.0, 0.0, 0.04)), (0.7, (0.3, -0.1, 0.04)), (-2.1, (0.25, -0.15, 0.04))]:
        pose = _yawed(yaw, t)
        eng.set_body_pose(body, pose)
        O = np.broadcast_to(pose.translation + pose.rotation @ local_o, D_local.shape)
        D = D_local @ pose.rotation.T
        before = eng.counters["riding_rays"]
        got = eng.cast(O, D, 0.001, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, riding=riding)
        paired = eng.counters["riding_rays"] - before
        assert 0 < paired < n                       # only the rays near the robot are paired with it
        want = eng.cast(O, D, 0.001, np.inf, kind=RayKind.VISUAL, exclude_owner=-1)
        _same(got, want)
        seen_own += int(np.isin(got.shape, [eng._bodies[body].first, eng._bodies[body].first + 1]).sum())
    assert seen_own > 0                              # its own body is in view
    assert len(riding.rows(eng._bodies[body].tiers["visual"])) < n


def test_a_riding_cast_breaks_when_its_rows_miss_the_robot():
    """The check above can fail: rows that leave out rays meeting the robot give other hits."""
    eng, body = _robot_world(Precision.FAST)
    n = 20000
    local_o = np.array([0.05, 0.0, 0.03])
    D_local = _fan(n, 7)
    D_local[: n // 2, 2] = -np.abs(D_local[: n // 2, 2])
    riding = Riding(body, local_o, D_local, 0.001, np.inf)
    eng.cast(np.broadcast_to(local_o + [0, 0, 0.04], D_local.shape), D_local, 0.001, np.inf, kind=RayKind.VISUAL)
    tier = eng._bodies[body].tiers["visual"]
    riding._rows = (tier, riding.rows(tier)[::2])      # half of them forgotten
    O = np.broadcast_to(local_o + [0.0, 0.0, 0.04], D_local.shape)
    got = eng.cast(O, D_local, 0.001, np.inf, kind=RayKind.VISUAL, exclude_owner=-1, riding=riding)
    want = eng.cast(O, D_local, 0.001, np.inf, kind=RayKind.VISUAL, exclude_owner=-1)
    assert got.distance.tobytes() != want.distance.tobytes()


_ROBOT_WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
PointLight { location 0.3 0.5 0.6 intensity 2 castShadows TRUE }
Solid { translation 0 0 -0.05 children [ Shape { geometry Box { size 10 10 0.1 } } ] }
Solid { translation 1 0.3 0.15 children [ Shape { geometry Box { size 0.3 0.3 0.3 } } ] }
Robot {
  rotation 0 0 1 0.25
  controller "<extern>"
  children [
    Transform { translation 0 0 0.0415 children [ Shape { geometry Cylinder { height 0.08 radius 0.045 } } ] }
    Transform { translation 0 0.05 0.025 rotation 1 0 0 1.5708
      children [ Shape { geometry Cylinder { height 0.01 radius 0.025 } } ] }
    Camera { name "cam" translation 0.02 0 0.09 rotation 0 1 0 0.6 width 160 height 120 fieldOfView 1.4
             antiAliasing TRUE }
  ]
}
"""


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_a_camera_without_a_housing_images_its_robot_as_the_general_cast(tmp_path, precision):
    """A camera with no shapes of its own looking down past its robot's body and wheel: its rays
    pair with the robot only where they may meet it (decided once), and its images are the
    general cast's bytes, before and after the robot turns."""
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    path = tmp_path / "robot.wbt"
    path.write_text(_ROBOT_WBT)
    sim = Simulation(load_world(path))
    sim.scene.engine.precision = precision
    cam = sim.device("robot/cam")
    assert not cam.own_shapes
    cam.enable(16)
    robot = sim.robot("robot")
    for turn in (0.0, 0.9):
        if turn:
            sim.place_robot(robot, _yawed(turn, robot.pose.translation))
        pose = cam.world_pose(robot.pose)
        rays = cam._prepare()
        assert rays.riding is not None
        before = sim.scene.engine.counters["riding_rays"]
        got = cam._render(pose, rays, sim._counters)
        assert 0 < sim.scene.engine.counters["riding_rays"] - before < len(rays)
        rays.riding, riding = None, rays.riding            # the general cast
        want = cam._render(pose, rays, sim._counters)
        rays.riding = riding
        assert got.tobytes() == want.tobytes()
        first = cam._scene.engine.cast(np.broadcast_to(pose.translation, rays.world.shape), rays.world, *cam._limits,
                                       kind=RayKind.VISUAL)
        robot_shapes = cam._scene.engine.body_shapes(cam._scene.device_body(cam.robot_index, None))
        assert np.isin(first.shape, robot_shapes).any()     # its robot is in view


_SHADOW_WBT = """#VRML_SIM R2023b utf8
WorldInfo { basicTimeStep 16 }
PointLight { location 0.4 0.3 1.0 intensity 2 castShadows TRUE }
DirectionalLight { direction -0.3 0.2 -1 intensity 0.5 castShadows TRUE }
Solid { translation 0 0 -0.05 children [ Shape { geometry Box { size 10 10 0.1 } } ] }
Solid { translation 1 0.1 0.15 children [ Shape { geometry Box { size 0.3 0.3 0.3 } } ] }
Solid { translation 0.8 -0.4 0.1 children [ Shape { geometry Sphere { radius 0.1 } } ] }
Robot {
  translation 0 0 0.3
  rotation 0 1 0 0.4
  controller "<extern>"
  children [ Camera { name "cam" width 200 height 150 fieldOfView 1.2 antiAliasing TRUE } ]
}
"""


@pytest.mark.parametrize("precision", ["fast", "exact"])
def test_shadow_buffers_kept_between_images_give_each_image_s_own_shadows(tmp_path, monkeypatch, precision):
    """A camera keeps its shadow rays' buffers from image to image (the same arrays, sized once for
    its rays and lights): an image taken after the point light moved, through buffers still
    holding the last image's rays, is the bytes of the general path's (new arrays), which a
    stale row would change (the two light poses give other shadows)."""
    from sensorium.server.sim import cameras
    from sensorium.server.sim.simulation import Simulation
    from sensorium.server.world.loader import load_world

    path = tmp_path / "shadows.wbt"
    path.write_text(_SHADOW_WBT)
    sim = Simulation(load_world(path))
    sim.scene.engine.precision = precision
    cam = sim.device("robot/cam")
    cam.enable(16)
    robot = sim.robot("robot")
    scene = sim.scene

    def image() -> bytes:
        cam._capture_image(cam.world_pose(robot.pose), sim._counters)
        return cam.image.tobytes()

    def general() -> bytes:
        with monkeypatch.context() as m:
            m.setattr(cameras, "shadow_rays", lambda *a: shadows_of(*a[:5]))
            m.setattr(cameras.ShadowBuffers, "origins", lambda self, k, P, i: shading.take_rows(P, i))
            return image()

    shadows_of = cameras.shadow_rays
    first = image()
    out = cam._shadow_out
    assert out is not None and out.rows == 200 * 150 * 4           # sized for every ray of the camera
    kept = [id(a) for s in out._sets for a in s]
    assert len(kept) == 8                                           # two shadow-casting lights
    assert first == general()
    light = scene.top_lights()[0]
    for location in ([-0.3, 0.6, 0.8], [1.4, -0.5, 0.5]):
        scene.set_top_light(0, light.model_copy(update={"location": location}))
        got = image()
        assert cam._shadow_out is out and [id(a) for s in out._sets for a in s] == kept   # not made again
        assert got == general()
        assert got != first


def test_a_small_riding_cast_is_the_general_one_and_bad_riding_is_refused():
    """Under _PRUNE rays the general pairing decides (no pairs counted), with the same hits; a
    Riding for rays of several origins, or of another count, is refused in one line."""
    eng, body = _robot_world(Precision.FAST)
    local_o = np.array([0.05, 0.0, 0.03])
    D = _fan(40, 9)
    D[:20, 2] = -np.abs(D[:20, 2])
    riding = Riding(body, local_o, D, 0.001, np.inf)
    O = np.broadcast_to(local_o + [0.0, 0.0, 0.04], D.shape)
    got = eng.cast(O, D, 0.001, np.inf, kind=RayKind.VISUAL, riding=riding)
    assert eng.counters["riding_rays"] == 0
    _same(got, eng.cast(O, D, 0.001, np.inf, kind=RayKind.VISUAL))
    with pytest.raises(ValueError, match="riding takes one-origin rays"):
        eng.cast(np.ascontiguousarray(O), D, 0.001, np.inf, kind=RayKind.VISUAL, riding=riding)
    with pytest.raises(ValueError, match="riding takes one-origin rays"):
        eng.cast(O[:10], D[:10], 0.001, np.inf, kind=RayKind.VISUAL, riding=riding)
