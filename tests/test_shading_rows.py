"""The row helpers of an image's shading (server/devices/shading.py) give numpy's fancy-index
answers bit for bit: gathers, scatters with +=, and the (n,) x (3,) products, with signed
zeros, infinities and NaN among the values."""

from __future__ import annotations

import numpy as np

from sensorium.server.devices import shading


def _values(rng, shape):
    v = rng.normal(size=shape) * 1e3
    flat = v.reshape(-1)
    flat[::97] = -0.0
    flat[5::101] = np.inf
    flat[7::103] = np.nan
    return v


def test_take_rows_is_fancy_indexing():
    rng = np.random.default_rng(4)
    a = _values(rng, (1000, 3))
    rows = rng.choice(1000, 600, replace=False)
    got = shading.take_rows(a, rows)
    assert got.tobytes() == a[rows].tobytes() and got.flags.c_contiguous


def test_add_to_rows_is_fancy_add():
    rng = np.random.default_rng(5)
    out = _values(rng, (1000, 3))
    rows = rng.choice(1000, 700, replace=False)
    values = _values(rng, (700, 3))
    want = out.copy()
    want[rows] += values
    shading.add_to_rows(out, rows, values)
    assert out.tobytes() == want.tobytes()


def test_scaled_rows_is_the_broadcast_product():
    rng = np.random.default_rng(6)
    v = _values(rng, (999,))
    vec = np.array([0.25, -0.0, 3.7])
    with np.errstate(invalid="ignore"):        # inf x 0 is NaN in both
        assert shading.scaled_rows(v, vec).tobytes() == (v[:, None] * vec).tobytes()
