"""Lookup tables (spec §1.2) and resolution rounding (spec §1.3).

A table maps a measured quantity ``x`` (distance, irradiance) to the returned value ``y`` with a
relative Gaussian noise ``n`` (a fraction of ``y``). Everything here is vectorised: one call maps an
array of measurements.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .noise import gaussian

__all__ = ["LookupTable", "add_noise", "quantize_sensor", "quantize_lidar", "RESOLUTION_OFF"]

RESOLUTION_OFF = -1.0
"""The ``resolution`` field value that disables rounding."""


class LookupTable:
    """An immutable lookup table of rows ``(x, y, n)`` in field order.

    ``lookup`` follows Webots exactly: clamp below ``x_0`` and above ``x_last`` (no extrapolation),
    otherwise the bracketing rows found by bisection (which also defines the result for tables whose
    inputs are not increasing: Webots only warns about those, see :attr:`inputs_increasing`), linear
    interpolation of both ``y`` and ``n``, then ``y * (1 + n * G)`` with ``G ~ N(0, 1)`` where
    ``n != 0``. The noisy result is not clamped. An empty table is the identity.
    """

    __slots__ = ("_x", "_y", "_n", "_rows", "_has_noise", "_increasing")

    def __init__(self, rows: Sequence[Sequence[float]]) -> None:
        if any(len(row) != 3 for row in rows):
            raise ValueError("lookup table rows must have exactly 3 values (input, output, noise)")
        table = np.array([[float(c) for c in row] for row in rows], dtype=np.float64).reshape(-1, 3)
        if not np.all(np.isfinite(table)):
            raise ValueError("lookup table values must be finite")
        self._x = _frozen(table[:, 0])
        self._y = _frozen(table[:, 1])
        self._n = _frozen(table[:, 2])
        self._rows = tuple(tuple(float(c) for c in row) for row in table)
        self._has_noise = bool(np.any(self._n != 0.0))
        self._increasing = bool(np.all(np.diff(self._x) > 0.0))

    # ------------------------------------------------------------------ getters
    @property
    def rows(self) -> tuple[tuple[float, float, float], ...]:
        return self._rows

    @property
    def flattened(self) -> tuple[float, ...]:
        """``[x0, y0, n0, x1, y1, n1, ...]`` as returned by ``get_lookup_table``."""
        return tuple(c for row in self._rows for c in row)

    @property
    def has_noise(self) -> bool:
        return self._has_noise

    @property
    def min_value(self) -> float:
        """Minimum of the output column (0.0 for an empty table)."""
        return float(self._y.min()) if len(self._y) else 0.0

    @property
    def max_value(self) -> float:
        """Maximum of the output column (0.0 for an empty table)."""
        return float(self._y.max()) if len(self._y) else 0.0

    @property
    def min_metrics_range(self) -> float:
        """``x_0`` (0.0 for an empty table)."""
        return float(self._x[0]) if len(self._x) else 0.0

    @property
    def max_metrics_range(self) -> float:
        """``x_last`` (0.0 for an empty table); the ray length of a DistanceSensor."""
        return float(self._x[-1]) if len(self._x) else 0.0

    @property
    def inputs_increasing(self) -> bool:
        """True when the input column is strictly increasing (else Webots logs a warning)."""
        return bool(np.all(np.diff(self._x) > 0.0))

    def __len__(self) -> int:
        return len(self._rows)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, LookupTable) and self._rows == other._rows

    def __hash__(self) -> int:
        return hash(self._rows)

    def __repr__(self) -> str:
        return f"LookupTable({[list(r) for r in self._rows]!r})"

    # ------------------------------------------------------------------ lookup
    def lookup(self, values: np.ndarray | float, rng: np.random.Generator | None) -> np.ndarray:
        """Map measurements to outputs; returns float64 with the shape of ``values``.

        Noise: one standard normal is drawn from ``rng`` for each entry whose interpolated ``n`` is
        non-zero, in C order of those entries; nothing is drawn for the others, nor at all when the
        table has no noise. ``rng=None`` evaluates the noise-free value (no draw).
        """
        v = np.asarray(values, dtype=np.float64)
        if len(self._x) == 0:
            return v.copy()
        out_y, out_n = self.interpolate(v)
        if self._has_noise and rng is not None:
            out_y = add_noise(out_y, out_n, rng)
        return np.asarray(out_y, dtype=np.float64)

    def interpolate(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Noise-free output ``y`` and interpolated relative noise ``n`` for each value (the table
        must not be empty): clamping and Webots' bisection. :meth:`lookup` adds the noise; the
        simulation calls this directly to reduce many sensors sharing a table at once and then
        draws each sensor's noise from its own stream."""
        v = np.asarray(values, dtype=np.float64)
        m = len(self._x)
        x, y, n = self._x, self._y, self._n
        if m == 1:
            return np.full(v.shape, y[0]), np.full(v.shape, n[0])
        if self._increasing:
            # sorted inputs: Webots' bisection lands on the bracket searchsorted finds
            lo = np.minimum(np.maximum(np.searchsorted(x, v, side="right") - 1, 0), m - 2)   # (np.clip's values)
            hi = lo + 1
        else:
            lo = np.zeros(v.shape, dtype=np.intp)
            hi = np.full(v.shape, m - 1, dtype=np.intp)
            active = lo + 1 < hi
            while np.any(active):  # bisection exactly as Webots (also for unsorted inputs)
                mid = (lo + hi) // 2
                below = v < x[mid]
                hi = np.where(active & below, mid, hi)
                lo = np.where(active & ~below, mid, lo)
                active = lo + 1 < hi
        span = x[hi] - x[lo]
        with np.errstate(invalid="ignore", divide="ignore"):  # clamped entries are replaced below
            u = np.where(span != 0.0, (v - x[lo]) / np.where(span != 0.0, span, 1.0), 0.0)
            out_y = (1.0 - u) * y[lo] + u * y[hi]
            out_n = (1.0 - u) * n[lo] + u * n[hi]
        low = v <= x[0]
        high = v >= x[-1]
        return np.where(low, y[0], np.where(high, y[-1], out_y)), np.where(low, n[0], np.where(high, n[-1], out_n))


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=np.float64)
    a.setflags(write=False)
    return a


def _check_resolution(resolution: float) -> float:
    res = float(resolution)
    if res != RESOLUTION_OFF and not res > 0.0:
        raise ValueError(f"resolution must be -1 (off) or > 0, got {resolution!r}")
    return res


def quantize_sensor(v, resolution: float):
    """LightSensor/DistanceSensor rounding ``trunc(v/res + 0.5) * res`` (``res == -1``: unchanged).

    ``trunc`` goes toward zero like the C int cast, so negative values are not rounded
    symmetrically (``-0.7`` with ``res = 1`` gives ``0``). Unlike the C cast, very large ``v/res``
    does not overflow. Scalars give a float, arrays an array.
    """
    return _round(np.trunc, v, resolution)


def quantize_lidar(v, resolution: float):
    """Lidar rounding ``floor(v/res + 0.5) * res`` (``res == -1``: unchanged); ``inf`` stays ``inf``."""
    return _round(np.floor, v, resolution)


def _round(to_integer, v, resolution: float):
    res = _check_resolution(resolution)
    if res == RESOLUTION_OFF:
        return v
    q = to_integer(np.asarray(v, dtype=np.float64) / res + 0.5) * res + 0.0  # + 0.0: no -0.0
    return q if np.ndim(v) else float(q)


def add_noise(y: np.ndarray, n: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Relative Gaussian noise ``y·(1 + n·G)`` where ``n != 0``: one standard normal per such entry,
    in C order, from ``rng``; nothing is drawn for the others."""
    noisy = n != 0.0
    count = int(np.count_nonzero(noisy))
    if not count:
        return y
    out = np.array(y, dtype=np.float64)
    out[noisy] = out[noisy] * (1.0 + n[noisy] * gaussian(rng, count))
    return out
