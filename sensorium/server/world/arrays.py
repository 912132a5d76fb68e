"""Array helpers the stages share."""

from __future__ import annotations

import numpy as np


def unique_ints(values: np.ndarray) -> np.ndarray:
    """``np.unique(values)`` of an integer array (flattened, its distinct values ascending), by one sort.
    numpy 2.3+'s ``np.unique`` hashes first and sorts what it found: 13x slower here on 180,000 edge keys
    (48 vs 3.6 ms), 2.8x on 8 values (10.8 vs 3.8 us)."""
    flat = np.sort(values, axis=None)
    if len(flat) < 2:
        return flat
    first = np.empty(len(flat), dtype=bool)
    first[0] = True
    np.not_equal(flat[1:], flat[:-1], out=first[1:])
    return flat[first]
