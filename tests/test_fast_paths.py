"""The lean paths of the lidar pipeline give the general paths' answers bit for bit: distance-only
casts, one broadcast origin, beams rotated column by column, cached point-cloud directions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensorium.server.devices import lidar as lmath
from sensorium.server.raycast.engine import Precision, RayEngine, RayKind, ShapeEntry
from sensorium.server.sim.sensors import _rotate, _rotate_columns
from sensorium.server.world.geometry import Box, Capsule, Cylinder, Plane, Pose, Sphere


def _rz(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _scene(precision, offset=(0.0, 0.0, 0.0)):
    """Flat and curved solids, an infinite floor and a sized visual plane, two moving bodies (one
    owned), all around ``offset``."""
    off = np.array(offset, dtype=np.float64)
    eng = RayEngine(precision)

    def at(x, y, z, yaw=0.0):
        return Pose(_rz(yaw), off + np.array([x, y, z]))

    eng.add_body([ShapeEntry(Plane(), Pose.identity(), True, True)], at(0, 0, 0))
    eng.add_body([ShapeEntry(Plane((1.0, 0.5)), Pose.identity(), True, True)], Pose(
        np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]), off + np.array([0.0, 2.5, 0.6])))
    eng.add_body([ShapeEntry(Box((0.5, 0.4, 1.0)), Pose.identity(), True, True)], at(1.5, 0.3, 0.5, 0.4))
    eng.add_body([ShapeEntry(Sphere(0.4), Pose.identity(), True, True)], at(-1.2, 0.8, 0.4))
    eng.add_body([ShapeEntry(Cylinder(0.2, 1.5), Pose.identity(), True, True)], at(0.4, -1.4, 0.75))
    eng.add_body([ShapeEntry(Capsule(0.15, 0.8), Pose.identity(), True, True)], at(-0.6, -0.9, 0.6, 0.3))
    eng.add_body([ShapeEntry(Box((0.3, 0.3, 0.3)), Pose.identity(), True, True)], at(-2.0, -0.5, 0.15), owner=0,
                 movable=True)
    eng.add_body([ShapeEntry(Cylinder(0.25, 0.5), Pose.identity(), True, True)], at(2.2, -1.0, 0.25), movable=True)
    return eng, off


def _lidar_rays(origin, n_az=360, n_el=24):
    az = np.linspace(-math.pi, math.pi, n_az, endpoint=False)
    el = np.linspace(-0.6, 0.3, n_el)
    A, E = np.meshgrid(az, el)
    D = np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], axis=-1).reshape(-1, 3)
    return np.broadcast_to(np.asarray(origin, dtype=np.float64), D.shape), D


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (5000.0, -300.0, 0.0)])
@pytest.mark.parametrize("origin", [(0.1, 0.2, 0.9), (-1.2, 0.8, 0.5), (0.4, -1.4, 0.3)])
def test_distance_only_cast_gives_the_full_casts_distances(offset, origin):
    """Origins in free space, inside a sphere and inside a cylinder (the curved pre-pass), a world
    far from the origin (anchored tiers): FAST distance-only == FAST full, bit for bit, with and
    without a broadcast origin, with and without excluded owners and a t_near."""
    eng, off = _scene(Precision.FAST, offset)
    O, D = _lidar_rays(off + np.array(origin))
    for t_near, excl in ((0.0, -1), (0.05, 0)):
        full = eng.cast(np.ascontiguousarray(O), D, t_near, 6.0, kind=RayKind.VISUAL, exclude_owner=excl)
        lean = eng.cast(O, D, t_near, 6.0, kind=RayKind.VISUAL, exclude_owner=excl, distance_only=True)
        assert lean.normal is None and lean.shape is None
        hit = np.isfinite(full.distance)
        assert hit.mean() > 0.3
        shapes = set(np.unique(full.shape[hit]).tolist())
        if origin[2] > 0.8:    # in free space: floor, solids, curved shells, movers
            assert len(shapes) >= 5, shapes
        else:                  # inside a curved solid: every ray meets it from inside
            assert hit.all() and len(shapes) == 1
        np.testing.assert_array_equal(lean.distance, full.distance)
    exact = RayEngine(Precision.EXACT)
    assert exact.cast(O[:3], D[:3], distance_only=True).normal is None   # EXACT too (tests/test_exact_guards.py)


def test_rotating_beams_by_columns_is_bit_identical():
    rng = np.random.default_rng(5)
    v = rng.normal(size=(4096, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    for _ in range(5):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        w, x, y, z = q
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        cols = tuple(np.ascontiguousarray(v[:, k]) for k in range(3))
        a, b = _rotate(R, v), _rotate_columns(R, cols)
        assert a.tobytes() == b.tobytes()


@pytest.mark.parametrize("kw", [dict(projection="cylindrical"), dict(projection="planar", field_of_view=1.2),
                                dict(type="rotating"), dict(tilt_angle=0.2)])
def test_point_cloud_with_cached_directions_is_bit_identical(kw):
    p = lmath.LidarParams(horizontal_resolution=64, number_of_layers=8, field_of_view=kw.get("field_of_view", 2 * math.pi),
                          vertical_field_of_view=0.5, max_range=10.0,
                          **{k: v for k, v in kw.items() if k != "field_of_view"})
    rng = np.random.default_rng(1)
    ranges = rng.uniform(0.1, 9.0, size=(8, 64)).astype(np.float32)
    ranges[rng.random((8, 64)) < 0.2] = np.inf
    cols = np.array([3, 4, 5, 40, 41])
    cached = lmath.point_cloud_directions(p)
    for columns, rng_img, dirs in ((None, ranges, cached), (cols, ranges[:, cols], cached[:, cols, :])):
        a = lmath.point_cloud(p, rng_img, 1.5, 0.1, columns=columns)
        b = lmath.point_cloud(p, rng_img, 1.5, 0.1, columns=columns, directions=dirs)
        assert a.tobytes() == b.tobytes()
        # the record fields hold the float32-rounded float64 products, in layer-major order; a ray
        # without a hit (range inf) gives inf along its direction's non-zero components and NaN
        # where the component is zero (inf * 0, as in Webots), decided here without computing it
        d = lmath.point_cloud_directions(p, columns)
        r64 = rng_img.astype(np.float64)[:, :, None]
        hit = np.isfinite(r64)
        xyz = np.where(hit, np.where(hit, r64, 0.0) * d,
                       np.where(d == 0.0, np.nan, np.copysign(np.inf, d))).astype(np.float32).reshape(-1, 3)
        assert np.isinf(xyz).any() and np.isnan(xyz).any() == bool(np.any(d == 0.0))
        np.testing.assert_array_equal(np.stack([a["x"], a["y"], a["z"]], 1), xyz)
        assert a["layer_id"].tolist() == np.repeat(np.arange(8), rng_img.shape[1]).tolist()


@pytest.mark.parametrize("precision", [Precision.FAST, Precision.EXACT])
def test_large_casts_in_chunks_give_the_same_answers(monkeypatch, precision):
    """A cast larger than the chunk size runs in pieces (bounded temporaries): every output is
    bit-identical to one pass, with per-ray t_near/t_far/exclusion arrays and mounted rays."""
    from sensorium.server.raycast import engine as engine_module

    eng, off = _scene(precision)
    O, D = _lidar_rays(off + np.array((0.1, 0.2, 0.9)), n_az=120, n_el=10)
    O = np.ascontiguousarray(O) + np.linspace(0.0, 0.2, len(O))[:, None]   # distinct origins
    rng = np.random.default_rng(2)
    t_far = rng.uniform(1.0, 6.0, len(O))
    excl = rng.choice([-1, 0], len(O))
    mount = np.where(rng.random(len(O)) < 0.3, 7, -1)        # some rays "mounted" on the second mover
    one = eng.cast(O, D, 0.01, t_far, kind=RayKind.VISUAL, exclude_owner=excl, mount=mount)
    lean = eng.cast(O, D, 0.01, t_far, kind=RayKind.VISUAL, exclude_owner=excl, mount=mount, distance_only=True)
    monkeypatch.setattr(engine_module, "_CHUNK", 97)
    parts = eng.cast(O, D, 0.01, t_far, kind=RayKind.VISUAL, exclude_owner=excl, mount=mount)
    parts_lean = eng.cast(O, D, 0.01, t_far, kind=RayKind.VISUAL, exclude_owner=excl, mount=mount, distance_only=True)
    assert np.isfinite(one.distance).mean() > 0.3 and len(set(one.shape.tolist())) > 4
    for a, b in ((one.distance, parts.distance), (one.normal, parts.normal), (one.shape, parts.shape),
                 (lean.distance, parts_lean.distance), (one.distance, parts_lean.distance)):
        assert a.tobytes() == b.tobytes()
