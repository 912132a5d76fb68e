"""The pieces a tier is built of give the values their plain definitions give: the guards' pairs of
overlapping boxes (the sweep along x tests only y and z) against every pair tested, each shape's box
(stacked reductions) against its own min and max, and ``unique_ints`` against ``np.unique``."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from sensorium.server.raycast import guards, tiers
from sensorium.server.world.arrays import unique_ints


def _all_pairs(lo: np.ndarray, hi: np.ndarray) -> set[tuple[int, int]]:
    n = len(lo)
    return {(i, j) for i in range(n) for j in range(n) if np.all(lo[j] <= hi[i]) and np.all(hi[j] >= lo[i])}


@pytest.mark.parametrize("seed", range(12))
def test_overlapping_boxes_are_every_overlapping_pair(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 120))
    centre = rng.normal(size=(n, 3)) * rng.uniform(0.1, 3.0)
    if seed % 3 == 0:
        centre = np.round(centre, 1)           # equal coordinates: boxes touching, ties in the sort
    half = rng.uniform(0.0, 0.4, size=(n, 3))
    lo, hi = centre - half, centre + half
    i, j = guards._overlapping(lo, hi, 10 ** 9)
    assert set(zip(i.tolist(), j.tolist())) == _all_pairs(lo, hi)
    listed = Counter(zip(i.tolist(), j.tolist()))   # each pair once, a box with itself twice (both halves)
    assert all(count == (2 if a == b else 1) for (a, b), count in listed.items())


def test_overlapping_boxes_give_up_past_the_limit():
    lo = np.zeros((50, 3))
    assert guards._overlapping(lo, lo + 1.0, 50 * 51 // 2 - 1) is None
    assert guards._overlapping(lo, lo + 1.0, 50 * 51 // 2) is not None


@pytest.mark.parametrize("seed", range(6))
def test_each_shape_box_is_its_own_min_and_max(seed):
    rng = np.random.default_rng(seed)
    sizes = rng.integers(1, 40, size=int(rng.integers(1, 300))).tolist()
    if seed == 0:
        sizes = [tiers._BLOCK + 3, *sizes, tiers._BLOCK // 2, tiers._BLOCK // 2 + 1]   # blocks split there
    verts = [rng.normal(size=(k, 3)) * 1e4 for k in sizes]
    lo, hi = tiers._boxes(verts)
    assert np.array_equal(lo, np.array([v.min(0) for v in verts]))
    assert np.array_equal(hi, np.array([v.max(0) for v in verts]))


@pytest.mark.parametrize("values", [[], [7], [3, 3], [5, -1, 5, 2, -1], list(range(40, 0, -3)) * 3])
@pytest.mark.parametrize("dtype", [np.int64, np.int32])
def test_unique_ints_is_np_unique(values, dtype):
    a = np.array(values, dtype=dtype)
    got, want = unique_ints(a), np.unique(a)
    assert got.dtype == want.dtype and np.array_equal(got, want)
    grid = np.arange(24, dtype=dtype).reshape(4, 6) % 5
    assert np.array_equal(unique_ints(grid), np.unique(grid))
